#!/usr/bin/env bash
# tools/run.sh — one command from a fresh Debian 12 machine to a result.
#   tools/run.sh demo   install what the tools need (TOOLS_PACKAGES), build the libraries and the
#                       three tools only (preset tools: Release, no tests or benchmarks), bake the
#                       default scene (data/bunny_ground.obj under data/sunset.exr) to
#                       out/default.prt.h5, show what was baked, then bake data/scene_example.json
#                       to out/scene.prt.h5 and data/scene_lights.json to out/lights.prt.h5.
#   tools/run.sh test   install everything (TOOLS_PACKAGES and TEST_PACKAGES), build (ci preset:
#                       warnings are errors), run every test with ctest, then build the fuzz
#                       targets (fuzz preset: clang 14, ASan + UBSan) and run each briefly
#                       (tests/fuzz/run.sh short: its saved regression inputs, then 20 s from its
#                       seeds). This is what CI runs (.ci/run).
#   tools/run.sh deps   only install the Debian packages of `test` (apt-get; needs root or sudo) and
#                       the web viewer's npm packages; `tools/run.sh deps tools` only those of `demo`.
set -euo pipefail
cd "$(dirname "$0")/.."

# What the libraries and the three tools need to build and run: each is a find_package or
# pkg-config module of formats/, libbake/, view/ or tools/ (README "From zero to a baked file").
TOOLS_PACKAGES=(build-essential cmake pkg-config libembree-dev libhdf5-dev
                libopenexr-dev libimath-dev libtbb-dev libeigen3-dev libcli11-dev nlohmann-json3-dev libpng-dev
                libssl-dev libtinygltf-dev libdeflate-dev)
# What only the tests, the benchmarks, the fuzz targets and CI need, and who uses it: OpenMesh
# (Loop subdivision makes the tests' and benchmarks' large meshes; libopenmesh-dev pulls in
# OpenSceneGraph and through it GDAL and a MariaDB client, 48 packages); GoogleTest; h5dump and
# h5py (files read by other HDF5 clients); zlib (chunk filter tests); the shader tests' compiler
# and Vulkan device; the public models of the mesh and glTF tests; mpirun for sharded bakes;
# Blender for the glTF round trip; clang 14 and its sanitizer runtimes, and GNU time, for the
# fuzz targets; Node.js and Chromium for the web viewer's browser test (viewer/test: puppeteer-core
# drives the system Chromium, headless; npm installs three.js and puppeteer-core, see npm_deps).
TEST_PACKAGES=(libopenmesh-dev libgtest-dev hdf5-tools openexr python3-h5py python3-numpy zlib1g-dev
               glslc libvulkan-dev mesa-vulkan-drivers
               assimp-testmodels
               openmpi-bin libopenmpi-dev blender
               clang-14 libclang-rt-14-dev time
               nodejs chromium)
JOBS=${JOBS:-$(nproc)}

install_deps() {  # $@ = the packages
  local missing=()
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ ${#missing[@]} -eq 0 ]; then echo "deps: all $# packages present"; return; fi
  echo "deps: installing ${missing[*]}"
  local sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
}

# The web viewer's npm packages (viewer/package-lock.json: three.js, which `prtbake export --to web`
# ships and the build copies in, and puppeteer-core for the browser test) into viewer/node_modules.
# Debian's nodejs comes without npm (NodeSource's includes it): the npm package when it is missing.
npm_deps() {  # $@ = extra npm ci options
  command -v npm >/dev/null || install_deps npm
  (cd viewer && npm ci --no-audit --no-fund "$@")
}

build() {  # $1 = preset
  cmake --preset "$1" >/dev/null
  cmake --build --preset "$1" -j "$JOBS"
}

case "${1:-}" in
  deps)
    if [ "${2:-}" = tools ]; then install_deps "${TOOLS_PACKAGES[@]}"
    else install_deps "${TOOLS_PACKAGES[@]}" "${TEST_PACKAGES[@]}"; npm_deps; fi ;;
  demo)
    install_deps "${TOOLS_PACKAGES[@]}"
    build tools
    B=./build/tools/tools
    mkdir -p out
    $B/prtbake vertex data/bunny_ground.obj --ao --transfer 3 --visibility 3 \
      --radiance data/sunset.exr -o out/default.prt.h5
    $B/prtdump out/default.prt.h5
    # A scene file: several objects, roles and materials; prtbake bakes what the scene needs
    # and prints what it leaves out and why (README "Scene files").
    $B/prtbake scene data/scene_example.json -o out/scene.prt.h5
    # Lights: a quad, a disc, a 0.53-degree sun (soft shadows) and a spot (hard shadows) over
    # the bunny (README "Scene files", punctual lights).
    $B/prtbake scene data/scene_lights.json -o out/lights.prt.h5
    ;;
  test)
    install_deps "${TOOLS_PACKAGES[@]}" "${TEST_PACKAGES[@]}"
    npm_deps
    build ci
    ctest --preset ci
    build fuzz
    tests/fuzz/run.sh short
    ;;
  *)
    sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//'
    exit 2 ;;
esac
