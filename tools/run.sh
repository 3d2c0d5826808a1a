#!/usr/bin/env bash
# tools/run.sh — one command from a fresh Debian 12 machine to a result.
#   tools/run.sh demo   install dependencies, build (release), bake the default scene
#                       (data/bunny_ground.obj under data/sunset.exr) to out/default.prt.h5,
#                       show what was baked, then bake data/scene_example.json to out/scene.prt.h5.
#   tools/run.sh test   install dependencies, build (ci preset: warnings are errors), run every
#                       test with ctest, then build the fuzz targets (fuzz preset: clang 14,
#                       ASan + UBSan) and run each briefly (tests/fuzz/run.sh short: its saved
#                       regression inputs, then 20 s from its seeds). This is what CI runs (.ci/run).
#   tools/run.sh deps   only install the Debian packages (apt-get; needs root or sudo).
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(build-essential cmake pkg-config libembree-dev libopenmesh-dev libhdf5-dev hdf5-tools
          libopenexr-dev openexr libtbb-dev libeigen3-dev libgtest-dev python3-h5py
          glslc libvulkan-dev mesa-vulkan-drivers
          libcli11-dev nlohmann-json3-dev libpng-dev libssl-dev libtinygltf-dev libdeflate-dev zlib1g-dev
          assimp-testmodels
          openmpi-bin libopenmpi-dev blender python3-numpy
          clang-14 libclang-rt-14-dev time)
JOBS=${JOBS:-$(nproc)}

install_deps() {
  local missing=()
  for p in "${PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ ${#missing[@]} -eq 0 ]; then echo "deps: all ${#PACKAGES[@]} packages present"; return; fi
  echo "deps: installing ${missing[*]}"
  local sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
}

build() {  # $1 = preset
  cmake --preset "$1" >/dev/null
  cmake --build --preset "$1" -j "$JOBS"
}

case "${1:-}" in
  deps) install_deps ;;
  demo)
    install_deps
    build release
    mkdir -p out
    ./build/release/tools/prtbake vertex data/bunny_ground.obj --ao --transfer 3 --visibility 3 \
      --radiance data/sunset.exr -o out/default.prt.h5
    ./build/release/tools/prtdump out/default.prt.h5
    # A scene file: several objects, roles and materials; prtbake bakes what the scene needs
    # and prints what it leaves out and why (README "Scene files").
    ./build/release/tools/prtbake scene data/scene_example.json -o out/scene.prt.h5
    ;;
  test)
    install_deps
    build ci
    ctest --preset ci
    build fuzz
    tests/fuzz/run.sh short
    ;;
  *)
    sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'
    exit 2 ;;
esac
