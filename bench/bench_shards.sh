#!/usr/bin/env bash
# bench/bench_shards.sh — scaling of sharded bakes (tools/prtbake/shards.h) on this machine: one
# worker against two (one thread each, run at the same time, as two machines would), the merge's
# share of the bake, the slowest worker's busy time against the fastest's, and the bytes of the
# chunks and the file (for an extrapolation to many machines). Checks that both files are
# cmp-identical.
#
#   bench/bench_shards.sh                 bunny_ground, all four products, qmc 2048 rays
#   PRT_SHARDS_SAMPLES=512 PRT_SHARDS_INTEGRATOR=silhouette bench/bench_shards.sh
#   PRT_SHARDS_REPORT=0 bench/bench_shards.sh   no error report: the merge's own cost
#   PRT_BENCH_BUILD_DIR=build/ci bench/bench_shards.sh   another build tree (default build/release)
#   PRT_SHARDS_BAKE=fiv bench/bench_shards.sh   a FIV bake instead: bunny under forest.exr, shells
#       PRT_SHARDS_SHELLS (default 64x33x30), k = PRT_SHARDS_SAMPLES (default 1024), slabs of
#       PRT_SHARDS_CHUNK_ROWS (default 264) samples
# Times: wall (elapsed) and CPU (user + system) from /usr/bin/time; "busy" is the time a worker
# spent integrating its chunks (its "worker ..." line). On a shared machine, compare CPU and busy
# times rather than wall times.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$(cd "${PRT_BENCH_BUILD_DIR:-$root/build/release}" && pwd)"
prtbake="$build/tools/prtbake"
bake="${PRT_SHARDS_BAKE:-vertex}"
report="${PRT_SHARDS_REPORT:-32}"  # the error report's points, integrated by the merge
[[ -x "$prtbake" ]] || { echo "bench_shards.sh: no $prtbake (build the release preset)" >&2; exit 2; }
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
if [[ "$bake" == fiv ]]; then
  samples="${PRT_SHARDS_SAMPLES:-1024}"
  rows="${PRT_SHARDS_CHUNK_ROWS:-264}"
  args=(fiv "$root/data/bunny.obj" --env "$root/data/forest.exr" --shells "${PRT_SHARDS_SHELLS:-64x33x30}"
        --samples "$samples" --chunk-rows "$rows" --report "$report" -o out.prt.h5)
else
  samples="${PRT_SHARDS_SAMPLES:-2048}"
  rows="${PRT_SHARDS_CHUNK_ROWS:-256}"
  args=(vertex "$root/data/bunny_ground.obj" --ao --transfer 3 --visibility 3 --radiance "$root/data/sunset.exr"
        --integrator "${PRT_SHARDS_INTEGRATOR:-qmc}" --samples "$samples" --chunk-rows "$rows" --report "$report"
        -o out.prt.h5)
fi

# run NAME DIR ARGS...: runs prtbake in DIR, its stdout in DIR/NAME.log, "wall cpu" in DIR/NAME.time.
run() {
  local name="$1" dir="$2"
  shift 2
  (cd "$dir" && /usr/bin/time -f "%e %U %S" -o "$name.time" "$prtbake" "${args[@]}" "$@" > "$name.log")
}
wall() { awk '{print $1}' "$1"; }
cpu() { awk '{printf "%.2f", $2 + $3}' "$1"; }
busy() { sed -n 's/.*busy \([0-9.]*\) s.*/\1/p' "$1"; }
busy_cpu() { sed -n 's/.*busy [0-9.]* s (\([0-9.]*\) CPU s).*/\1/p' "$1"; }

mkdir -p "$work/one" "$work/two"
echo "load average at start: $(cut -d' ' -f1-3 /proc/loadavg)"
run w0 "$work/one" --shard 0/1 --threads 1
chunk_bytes=$(du -sb "$work/one/out.prt.h5.chunks" | cut -f1)
chunks=$(ls "$work/one/out.prt.h5.chunks" | grep -c '\.chunk$')
run merge "$work/one" --merge
run w0 "$work/two" --shard 0/2 --threads 1 &
run w1 "$work/two" --shard 1/2 --threads 1 &
wait
run merge "$work/two" --merge
cmp "$work/one/out.prt.h5" "$work/two/out.prt.h5" && identical=yes || identical=NO
file_bytes=$(stat -c %s "$work/one/out.prt.h5")
echo "load average at end: $(cut -d' ' -f1-3 /proc/loadavg)"

w1wall=$(wall "$work/one/w0.time") m1wall=$(wall "$work/one/merge.time")
w2wall=$(awk '{print $1}' "$work/two/w0.time" "$work/two/w1.time" | sort -g | tail -1)
m2wall=$(wall "$work/two/merge.time")
b0=$(busy_cpu "$work/two/w0.log") b1=$(busy_cpu "$work/two/w1.log") bone=$(busy_cpu "$work/one/w0.log")
c1=$(cpu "$work/one/w0.time") c20=$(cpu "$work/two/w0.time") c21=$(cpu "$work/two/w1.time") m2cpu=$(cpu "$work/two/merge.time")
cat <<EOF

prtbake ${args[*]}
$chunks chunks of $rows rows; chunks $chunk_bytes bytes in all, the file $file_bytes bytes; files identical: $identical

| run                 | wall s | CPU s (process) | busy CPU s (integration) |
|---------------------|--------|-----------------|--------------------------|
| 1 worker            | $w1wall | $c1 | $bone |
| merge (1 worker)    | $m1wall | $(cpu "$work/one/merge.time") | - |
| 2 workers: worker 0 | $(wall "$work/two/w0.time") | $c20 | $b0 |
| 2 workers: worker 1 | $(wall "$work/two/w1.time") | $c21 | $b1 |
| merge (2 workers)   | $m2wall | $m2cpu | - |

EOF
# With a core per worker (as on separate machines), a worker's time is its CPU time.
awk -v a="$w1wall" -v b="$w2wall" -v c1="$c1" -v c20="$c20" -v c21="$c21" -v m1="$m1wall" -v m2="$m2wall" \
    -v mc="$m2cpu" -v b0="$b0" -v b1="$b1" 'BEGIN {
  slow = c20 > c21 ? c20 : c21
  printf "speed-up, 2 workers against 1, CPU time of the slowest worker: %.2fx (wall on this shared machine: %.2fx)\n", c1 / slow, a / b
  printf "merge share of the 2-worker bake, CPU: %.1f%% (merge %.2f s after the slowest worker %.2f s; wall %.1f%%)\n", 100 * mc / (slow + mc), mc, slow, 100 * m2 / (b + m2)
  printf "slowest / fastest worker, integration CPU time: %.3f; process CPU time: %.3f\n", (b0 > b1 ? b0 / b1 : b1 / b0), (c20 > c21 ? c20 / c21 : c21 / c20)
}'
