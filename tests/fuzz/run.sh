#!/usr/bin/env bash
# tests/fuzz/run.sh — runs the libFuzzer targets of the fuzz build (docs/RELIABILITY.md "Fuzzing").
#   tests/fuzz/run.sh short    [target...]  CI: first replays every input under regressions/<target>/,
#                                           then fuzzes each target for PRT_FUZZ_SECONDS (20) s from
#                                           its seeds with a fixed seed. Fails if any target fails.
#   tests/fuzz/run.sh campaign [target...]  the long runs: each target, one at a time, until
#                                           PRT_FUZZ_RUNS (10^6) executions or PRT_FUZZ_MAX_SECONDS
#                                           (1200) s, in fork mode so that a finding does not stop
#                                           it; findings go to regressions/<target>/; prints one
#                                           line of numbers per target. PRT_FUZZ_FORK=0: in one
#                                           process instead (several times faster; stops at the
#                                           first finding, which goes to regressions/<target>/).
#   tests/fuzz/run.sh list                  the targets.
# Build first: cmake --preset fuzz && cmake --build --preset fuzz. PRT_FUZZ_BUILD names another
# build directory (default build/fuzz). Limits of every run: 10 s per input, 2048 MB of RSS,
# 2048 MB per allocation (a larger one is a finding: memory must stay bounded by the input size).
set -euo pipefail
HERE="$(cd "$(dirname "$0")" && pwd)"
ROOT="$(cd "$HERE/../.." && pwd)"
BUILD="${PRT_FUZZ_BUILD:-$ROOT/build/fuzz}"
BIN="$BUILD/tests/fuzz"
WORK="$BUILD/fuzz-work"
TARGETS=(obj ply off stl gltf glb exr scene gltf_options prt_dump prt_loader capi)
LIMITS=(-timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=2048)
# ASan: exit on the first report, symbolized stacks; the uninstrumented system libraries
# (HDF5, OpenEXR, tinygltf, ...) cannot annotate std::vector containers, so container-overflow
# checks (which need every library instrumented) are off.
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_container_overflow=0:symbolize=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
export LSAN_OPTIONS="${LSAN_OPTIONS:-suppressions=$HERE/lsan.supp:print_suppressions=0}"

dict_of() {  # the dictionary of a target, if it has one
  case "$1" in
    obj|ply|off|stl) echo "$HERE/dict/$1.dict" ;;
    gltf|glb) echo "$HERE/dict/gltf.dict" ;;
    scene|gltf_options) echo "$HERE/dict/scene.dict" ;;
    *) echo "" ;;
  esac
}

seed_dirs() {  # where a target's seeds are: committed, generated at build time, data/
  case "$1" in
    exr) echo "$BIN/seeds/exr" ;;
    prt_dump|prt_loader) echo "$BIN/seeds/prt" ;;
    *) echo "$HERE/seeds/$1" ;;
  esac
}

# A fresh working corpus for target $1 in $2: its seeds, data/'s small file for it, its regressions.
make_corpus() {
  rm -rf "$2" && mkdir -p "$2"
  cp "$(seed_dirs "$1")"/* "$2"/
  [ "$1" = scene ] && cp "$ROOT/data/scene_example.json" "$2"/
  if [ -d "$HERE/regressions/$1" ]; then
    find "$HERE/regressions/$1" -maxdepth 1 -type f ! -name '*.md' -exec cp {} "$2"/ \;
  fi
}

args_of() {  # options every run of target $1 shares
  local dict; dict="$(dict_of "$1")"
  echo "${LIMITS[*]} -print_final_stats=1 ${dict:+-dict=$dict}"
}

check_built() {
  for t in "$@"; do
    [ -x "$BIN/fuzz_$t" ] || { echo "fuzz: $BIN/fuzz_$t is not built (cmake --preset fuzz && cmake --build --preset fuzz)" >&2; exit 2; }
  done
  [ -d "$BIN/seeds/prt" ] || { echo "fuzz: $BIN/seeds is missing (build the prt_fuzz_seeds target)" >&2; exit 2; }
}

short() {
  local seconds="${PRT_FUZZ_SECONDS:-20}" failed=() t log
  mkdir -p "$WORK/logs"
  for t in "$@"; do
    log="$WORK/logs/short_$t.log"
    local regressions=()
    if [ -d "$HERE/regressions/$t" ]; then
      mapfile -t regressions < <(find "$HERE/regressions/$t" -maxdepth 1 -type f ! -name '*.md' | sort)
    fi
    if [ ${#regressions[@]} -gt 0 ] && ! "$BIN/fuzz_$t" $(args_of "$t") "${regressions[@]}" >"$log.replay" 2>&1; then
      echo "fuzz short $t: FAILED replaying regressions/$t/ (log: $log.replay)"
      grep -E "ERROR|FINDING|SUMMARY|Running:" "$log.replay" | tail -n 8 | sed 's/^/    /'
      failed+=("$t"); continue
    fi
    local corpus="$WORK/short/$t"
    make_corpus "$t" "$corpus"
    mkdir -p "$WORK/artifacts/$t"
    if "$BIN/fuzz_$t" $(args_of "$t") -seed=1 -max_total_time="$seconds" -artifact_prefix="$WORK/artifacts/$t/" \
         "$corpus" >"$log" 2>&1; then
      echo "fuzz short $t: ok, ${#regressions[@]} regression inputs, $(grep -o 'stat::number_of_executed_units: [0-9]*' "$log" | grep -o '[0-9]*$') executions in ${seconds} s"
    else
      echo "fuzz short $t: FAILED (log: $log; the input is under $WORK/artifacts/$t/)"
      grep -E "ERROR|FINDING|SUMMARY|Test unit written" "$log" | tail -n 8 | sed 's/^/    /'
      failed+=("$t")
    fi
  done
  if [ ${#failed[@]} -gt 0 ]; then echo "fuzz short: ${#failed[@]} of $# targets failed: ${failed[*]}"; return 1; fi
  echo "fuzz short: all $# targets passed"
}

campaign() {
  local runs="${PRT_FUZZ_RUNS:-1000000}" seconds="${PRT_FUZZ_MAX_SECONDS:-1200}" t
  mkdir -p "$WORK/logs"
  printf '%-13s %10s %8s %7s %7s %7s %7s %8s %9s %7s\n' target executions exec/s wall_s corpus cov ft crashes timeouts/ooms maxRSS_MB
  for t in "$@"; do
    local corpus="$WORK/campaign/$t" log="$WORK/logs/campaign_$t.log" regressions="$HERE/regressions/$t"
    [ -d "$corpus" ] || make_corpus "$t" "$corpus"  # a campaign continues from its previous corpus
    mkdir -p "$regressions"
    local start; start=$(date +%s)
    # fork mode: one child at a time runs the inputs; a crash, leak, timeout or oom is written to
    # regressions/<target>/ and counted, and fuzzing goes on.
    local mode_args=(-fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1) status=0
    [ "${PRT_FUZZ_FORK:-1}" = 0 ] && mode_args=()
    /usr/bin/time -f 'maxrss_kb %M' -o "$log.time" \
      nice "$BIN/fuzz_$t" $(args_of "$t") "${mode_args[@]}" \
        -runs="$runs" -max_total_time="$seconds" -artifact_prefix="$regressions/" "$corpus" >"$log" 2>&1 || status=$?
    local wall=$(( $(date +%s) - start ))
    local last execs cov ft corp eps otc
    if [ ${#mode_args[@]} -gt 0 ]; then
      # The last status line of the fork parent: "#N: cov: C ft: F corp: K exec/s: E oom/timeout/crash: a/b/c time: T job: J"
      last=$(grep -E '^#[0-9]+: cov:' "$log" | tail -n 1 || true)
      execs=$(sed -E 's/^#([0-9]+):.*/\1/' <<<"$last")
      otc=$(sed -E 's#.* oom/timeout/crash: ([0-9]+/[0-9]+/[0-9]+).*#\1#' <<<"$last")
    else
      # One process: "#N <event> cov: C ft: F corp: K/..."; a non-zero exit is one finding.
      last=$(grep -E '^#[0-9]+[[:space:]].* cov: ' "$log" | tail -n 1 || true)
      execs=$(grep -o 'stat::number_of_executed_units: [0-9]*' "$log" | grep -o '[0-9]*$' || true)
      [ -n "$execs" ] || execs=$(sed -E 's/^#([0-9]+).*/\1/' <<<"$last")
      if [ "$status" -eq 0 ]; then otc=0/0/0
      elif grep -q 'ERROR: libFuzzer: timeout' "$log"; then otc=0/1/0
      elif grep -qE 'out-of-memory|malloc\(.*\) exceeds limit' "$log"; then otc=1/0/0
      else otc=0/0/1; fi
    fi
    cov=$(sed -E 's/.* cov: ([0-9]+).*/\1/' <<<"$last"); ft=$(sed -E 's/.* ft: ([0-9]+).*/\1/' <<<"$last")
    corp=$(sed -E 's/.* corp: ([0-9]+).*/\1/' <<<"$last")
    eps=$(( wall > 0 && ${execs:-0} > 0 ? execs / wall : 0 ))
    local rss; rss=$(awk '/maxrss_kb/ {print int($2/1024)}' "$log.time" 2>/dev/null || echo "?")
    printf '%-13s %10s %8s %7s %7s %7s %7s %8s %9s %7s\n' "$t" "${execs:-?}" "$eps" "$wall" "${corp:-?}" "${cov:-?}" "${ft:-?}" \
      "${otc##*/}" "$(cut -d/ -f2 <<<"$otc")/$(cut -d/ -f1 <<<"$otc")" "$rss"
  done
}

mode="${1:-}"; shift || true
selected=("$@"); [ ${#selected[@]} -gt 0 ] || selected=("${TARGETS[@]}")
case "$mode" in
  list) printf '%s\n' "${TARGETS[@]}" ;;
  short) check_built "${selected[@]}"; short "${selected[@]}" ;;
  campaign) check_built "${selected[@]}"; campaign "${selected[@]}" ;;
  *) sed -n '2,15p' "$0" | sed 's/^# \{0,1\}//'; exit 2 ;;
esac
