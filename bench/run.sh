#!/usr/bin/env bash
# bench/run.sh — build the `release` preset and run every benchmark, writing bench/RESULTS.md
# (the exact commands, date, machine, and the tables the runs produced) between its markers;
# the sections recorded by hand after the end marker are kept.
#
#   bench/run.sh                 build (cmake --preset release, -j2) and run everything (~2–10 min)
#   bench/run.sh --no-build      run what build/release already holds
#   bench/run.sh --quick         small sizes (16 points, fewer k, 2^18 reference rays) for a smoke test
#   bench/run.sh --out FILE      write FILE instead of bench/RESULTS.md
#   PRT_BENCH_BUILD_DIR=dir bench/run.sh --no-build   run the binaries of another build tree
# Sizes can be set through the environment, as the binaries read it: PRT_BENCH_POINTS,
# PRT_BENCH_SEED, PRT_BENCH_QMC_SAMPLES, PRT_BENCH_ISOLINES, PRT_BENCH_LEVELS (bench_integrators),
# PRT_BENCH_REF_RAYS (bench_error_vs_time), PRT_BENCH_MIN_TIME (Google Benchmark min time, s),
# PRT_AGREE_POINTS, PRT_AGREE_ISOLINES, PRT_AGREE_RAYS (bench_agreement).
# Numbers are CPU time of one thread; other processes on the machine (parallel builds) still
# make them noisy — the load average at start and end is recorded next to them.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build=1
quick=0
out="$root/bench/RESULTS.md"
while (($#)); do
  case "$1" in
    --no-build) build=0 ;;
    --quick) quick=1 ;;
    --out) out="$2"; shift ;;
    *) echo "run.sh: unknown option $1" >&2; exit 2 ;;
  esac
  shift
done
cd "$root"
bindir="${PRT_BENCH_BUILD_DIR:-$root/build/release}"  # override to run another build tree
if ((build)); then
  cmake --preset release >/dev/null
  cmake --build --preset release --target bench_integrators bench_error_vs_time bench_agreement bench_fiv
fi
if ((quick)); then
  export PRT_BENCH_POINTS="${PRT_BENCH_POINTS:-16}"
  export PRT_BENCH_QMC_SAMPLES="${PRT_BENCH_QMC_SAMPLES:-256,1024}"
  export PRT_BENCH_ISOLINES="${PRT_BENCH_ISOLINES:-16,64}"
  export PRT_BENCH_LEVELS="${PRT_BENCH_LEVELS:-0,1}"
  export PRT_BENCH_REF_RAYS="${PRT_BENCH_REF_RAYS:-262144}"
fi
min_time="${PRT_BENCH_MIN_TIME:-0.5}"
env_used="$(env | grep '^PRT_BENCH_' | grep -v '^PRT_BENCH_BUILD_DIR=' | sort | tr '\n' ' ' || true)"

tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
load_start="$(cut -d' ' -f1-3 /proc/loadavg)"
start="$(date -u '+%Y-%m-%d %H:%M:%S UTC')"

cmd1="${bindir#$root/}/bench/bench_integrators --benchmark_min_time=$min_time --benchmark_out=<tmp>/integrators.json --benchmark_out_format=json"
echo "+ ${env_used}$cmd1" >&2
"$bindir/bench/bench_integrators" --benchmark_min_time="$min_time" \
  --benchmark_out="$tmp/integrators.json" --benchmark_out_format=json >&2
cmd2="${bindir#$root/}/bench/bench_error_vs_time"
echo "+ ${env_used}$cmd2" >&2
t0=$(date +%s)
"$bindir/bench/bench_error_vs_time" >"$tmp/error_vs_time.md"
t1=$(date +%s)
cmd3="${bindir#$root/}/bench/bench_agreement"
if [[ -x "$bindir/bench/bench_agreement" ]]; then
  echo "+ $cmd3" >&2
  if ((quick)); then
    PRT_AGREE_POINTS=8 PRT_AGREE_RAYS=100000 "$bindir/bench/bench_agreement" >"$tmp/agreement.md"
  else
    "$bindir/bench/bench_agreement" >"$tmp/agreement.md"
  fi
fi
cmd4="${bindir#$root/}/bench/bench_fiv"
if [[ -x "$bindir/bench/bench_fiv" ]]; then
  echo "+ $cmd4" >&2
  if ((quick)); then
    PRT_FIV_SIZES=32x17x15 PRT_FIV_POINTS=8 PRT_FIV_RAYS=100000 "$bindir/bench/bench_fiv" >"$tmp/fiv.md"
  else
    "$bindir/bench/bench_fiv" >"$tmp/fiv.md"
  fi
fi
load_end="$(cut -d' ' -f1-3 /proc/loadavg)"

cpu="$(grep -m1 '^model name' /proc/cpuinfo | sed 's/^model name[[:space:]]*:[[:space:]]*//' || echo unknown)"
commit="$(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo 'not a git checkout')"
dirty="$(git -C "$root" status --porcelain 2>/dev/null | head -c1 || true)"
[[ -n "$dirty" ]] && commit="$commit (with uncommitted changes)"

python3 - "$tmp/integrators.json" >"$tmp/integrators.md" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
rows = {b["name"]: b for b in d["benchmarks"] if b.get("run_type", "iteration") == "iteration"}
def us(b): return b["per_integral"] * 1e6
def f(x, fmt="{:.1f}"): return fmt.format(x) if x is not None else "–"
ctx = d["context"]
print(f"Google Benchmark context: {ctx.get('num_cpus')} CPUs at {ctx.get('mhz_per_cpu')} MHz, library_build_type "
      f"{ctx.get('library_build_type')}, silhouette: {ctx.get('silhouette')}, points per iteration: {ctx.get('points')}.\n")
print("#### Cost per integral against the accuracy knob (level-0 scene, one thread)\n")
print("| integrator | knob | samples k | CPU µs / integral | contour µs | integrate µs | contour edges | crossings | setup s | iterations |")
print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|")
for name, b in rows.items():
    if name.startswith("BM_Qmc/"):
        n = int(name.split(":")[1])
        print(f"| qmc | N = {n} | {n} | {us(b):.1f} | – | – | – | – | {b['setup_s']:.3f} | {b['iterations']} |")
for name, b in rows.items():
    if name.startswith("BM_Silhouette/"):
        n = int(name.split(":")[1])
        print(f"| silhouette | isolines {n} | {n*n} | {us(b):.1f} | {b.get('contour_us', 0):.1f} | {b.get('integrate_us', 0):.1f} | "
              f"{b.get('contour_edges', 0):.0f} | {b.get('crossings', 0):.0f} | {b['setup_s']:.3f} | {b['iterations']} |")
print("\n#### Cost per integral against triangle count (bunny Loop-subdivided; QMC 1024 rays next to silhouette N = 64)\n")
print("| level | triangles | QMC µs / integral | silhouette µs / integral | QMC / silhouette | sil. contour µs | sil. integrate µs | sil. contour edges | QMC setup s | sil. setup s |")
print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
levels = sorted({int(n.split(":")[1]) for n in rows if "Triangles/level:" in n})
for l in levels:
    q = rows.get(f"BM_QmcTriangles/level:{l}")
    s = rows.get(f"BM_SilhouetteTriangles/level:{l}")
    tri = int((q or s)["triangles"])
    qt = us(q) if q else None
    st = us(s) if s else None
    ratio = f"{qt/st:.2f}" if qt and st else "–"
    print(f"| {l} | {tri} | {f(qt)} | {f(st)} | {ratio} | {f(s.get('contour_us') if s else None)} | "
          f"{f(s.get('integrate_us') if s else None)} | {f(s.get('contour_edges') if s else None, '{:.0f}')} | "
          f"{f(q['setup_s'] if q else None, '{:.3f}')} | {f(s['setup_s'] if s else None, '{:.3f}')} |")
PY

{
  echo "# Benchmark results"
  echo
  if [[ -n "${PRT_BENCH_BUILD_DIR:-}" ]]; then
    echo "Produced by \`PRT_BENCH_BUILD_DIR=${bindir#$root/} bench/run.sh --no-build\` (a Release build tree other than the preset's)."
  else
    echo "Produced by \`bench/run.sh\` (build: \`cmake --preset release && cmake --build --preset release\`)."
  fi
  echo
  echo "- date: $start (error-vs-time run took $((t1 - t0)) s)"
  echo "- machine: $(nproc) cores (nproc), $cpu"
  echo "- load average (1/5/15 min) at start: $load_start, at end: $load_end — other builds running"
  echo "  concurrently make these numbers noisy; CPU time of the benchmark thread is reported."
  echo "- source: commit $commit"
  echo "- environment: ${env_used:-(defaults)}"
  echo
  echo "## bench_integrators"
  echo
  echo "\`${env_used}$cmd1\`"
  echo
  cat "$tmp/integrators.md"
  echo
  echo "## bench_error_vs_time"
  echo
  echo "\`${env_used}$cmd2\`"
  echo
  cat "$tmp/error_vs_time.md"
  if [[ -f "$tmp/agreement.md" ]]; then
    echo
    echo "## bench_agreement"
    echo
    echo "\`$cmd3\`"
    echo
    cat "$tmp/agreement.md"
  fi
  if [[ -f "$tmp/fiv.md" ]]; then
    echo
    echo "## bench_fiv"
    echo
    echo "\`$cmd4\`"
    echo
    cat "$tmp/fiv.md"
  fi
} >"$tmp/generated.md"
# Splice: only the block between the markers is replaced; the hand-recorded sections after it
# (each with the command that produced it) are kept. A file without markers keeps its old
# content below the new block; a missing file is created.
python3 - "$tmp/generated.md" "$out" <<'PY'
import os, sys
begin = '<!-- bench/run.sh begin: the lines up to "bench/run.sh end" are rewritten by every run; the sections after it are recorded by hand with their commands -->'
end = '<!-- bench/run.sh end -->'
generated = open(sys.argv[1]).read().rstrip() + "\n"
out = sys.argv[2]
old = open(out).read() if os.path.exists(out) else ""
rest = ""
if end in old:
    rest = old.split(end, 1)[1].lstrip("\n")
elif old:
    rest = old
text = begin + "\n" + generated + "\n" + end + "\n" + ("\n" + rest if rest else "")
tmp = out + ".tmp"
with open(tmp, "w") as f:
    f.write(text)
os.replace(tmp, out)
PY
echo "wrote $out (its hand-recorded sections kept)" >&2
