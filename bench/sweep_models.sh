#!/usr/bin/env bash
# bench/sweep_models.sh — bake every OBJ/PLY/OFF/STL/glTF/GLB under a directory (default: Debian's
# assimp-testmodels, /usr/share/assimp/models: real exporters' files and deliberately broken ones)
# and print one line per file: path, exit code, seconds, the first message. What must hold: every
# exit code is 0 or 1 (1 = refused with one line naming the file), never a crash (4, signals) or a
# timeout (124). Usage: bench/sweep_models.sh [DIR] [prtbake options...]
#   PRT_BENCH_BUILD_DIR (default build/release) picks the prtbake; default options: --ao --transfer 3.
set -uo pipefail
cd "$(dirname "$0")/.."
dir=${1:-/usr/share/assimp/models}
shift || true
opts=("$@")
[ ${#opts[@]} -gt 0 ] || opts=(--ao --transfer 3)
prtbake=${PRT_BENCH_BUILD_DIR:-build/release}/tools/prtbake
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
bad=0
while IFS= read -r f; do
  start=$(date +%s.%N)
  timeout 600 "$prtbake" vertex "$f" "${opts[@]}" -q -o "$out/sweep.prt.h5" > "$out/log" 2>&1
  rc=$?
  secs=$(echo "$(date +%s.%N) - $start" | bc)
  printf "%s\t%d\t%.2f\t%s\n" "$f" "$rc" "$secs" "$(head -c 200 "$out/log" | head -1)"
  [ "$rc" -le 1 ] || bad=$((bad + 1))
done < <(find "$dir" -type f \( -iname '*.obj' -o -iname '*.ply' -o -iname '*.off' -o -iname '*.stl' -o -iname '*.gltf' -o -iname '*.glb' \) | sort)
echo "files with an exit code other than 0 or 1: $bad" >&2
[ "$bad" -eq 0 ]
