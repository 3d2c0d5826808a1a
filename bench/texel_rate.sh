#!/usr/bin/env bash
# bench/texel_rate.sh — issue 30: texels per second per core of the silhouette, QMC and filter
# integrators at equal per-texel AO error (E = 1e-3), and the filter at 8/16/32 pass-1 rays against
# QMC at 256 rays, on bunny_ground, the generated architectural scene and the CAD engine, side by
# side in one run.
#
# Per asset (one lightmap: the same mesh, generated UVs and resolution for every bake, so every file
# has the same texels; `prtbake texel ... --ao --no-stitch --report 0`, the stitch left out so
# that a texel's value is its shade point's integral and nothing else):
#   reference  two QMC bakes of REF_RAYS rays with seeds 1001 and 1002; bench_texel_error compares
#              every file with their mean over the baked texels (state 1) and takes the
#              reference's own noise out (its estimate: (A − B)/2 per texel), so the RMSE printed is
#              the file's error against the exact values, with its standard error;
#   baseline   `--integrator qmc --samples 1`: everything a bake does besides integrating (loading,
#              unwrapping, coverage, the texels inside the geometry, writing), timed to be
#              subtracted;
#   ladders    per integrator, settings ~1.41x apart (QMC rays 256..16384, silhouette N = 8..256
#              isolines (--samples N²), filter pass-1 rays 8..512): from a start rung, down while
#              the rung meets E, else up until one does; a ladder also stops at its top, when a
#              rung's error fell by less than 10% from the rung below (a floor: bias, not noise) or
#              when the next rung would cost more than RUNG_CAP CPU seconds (predicted from this
#              rung's cost). The cheapest rung meeting E is the integrator's row. The filter's
#              8, 16 and 32 rays and QMC 256 are always baked;
#   cost       CPU seconds of the prtbake process (user + sys, /usr/bin/time) minus the
#              baseline's: the integrator's setup (its tables, the contour tree), the filter's
#              pass 1 and every integral; texels / that = texels per second per core. prtbake's
#              own "CPU s in the integrator" (the row loop) is printed too.
# Also the filter at 32 rays again with seed 2: its error split into noise (the two bakes' RMS
# difference over √2) and bias (the rest).
# Output: a markdown table of every rung (WORK/rungs.tsv), the cheapest rung meeting E per
# integrator and asset ("-": none), the filter's split; progress on stderr.
#
#   bench/texel_rate.sh                    all three assets
#   ASSETS="bunny arch" bench/texel_rate.sh
# Environment: PRT_BENCH_BUILD_DIR (build/release), WORK (kept; default a temporary directory,
#   removed), TARGET (1e-3), REF_RAYS (4096), RUNG_CAP (400 CPU s), ENGINE (the glb),
#   BUNNY_RES (256: --resolution), ARCH_CELLS (4: tests/common/arch_scene.h, 9,778 triangles),
#   ARCH_DENSITY (10 texels per metre), ENGINE_DENSITY (0.125 texels per unit), QMC_START (2048)
#   and SIL_START (32): the ladders' first rungs. Bakes already in WORK are reused (not timed
#   again): a run stopped early resumes, and re-running prints the tables again.
set -uo pipefail
cd "$(dirname "$0")/.."
build=${PRT_BENCH_BUILD_DIR:-build/release}
prtbake=$build/tools/prtbake
errprog=$build/bench/bench_texel_error
E=${TARGET:-1e-3}
ref_rays=${REF_RAYS:-4096}
rung_cap=${RUNG_CAP:-400}
engine=${ENGINE:-/work/shared/data/2CylinderEngine.glb}
read -r -a assets <<< "${ASSETS:-bunny arch engine}"
if [ -n "${WORK:-}" ]; then mkdir -p "$WORK"; work=$WORK; else work=$(mktemp -d); trap 'rm -rf "$work"' EXIT; fi
say() { echo "[$(date -u +%H:%M:%S)] $*" >&2; }

qmc_ladder=(256 362 512 724 1024 1448 2048 2896 4096 5793 8192 11585 16384)
sil_ladder=(8 11 16 23 32 45 64 90 128 181 256)
filter_ladder=(8 11 16 23 32 45 64 90 128 181 256 362 512)

# bake NAME INTEGRATOR SAMPLES [SEED]: bakes $dir/NAME.prt.h5 once (kept across runs of the same
# WORK), leaves "cpu integrator_cpu" in $dir/NAME.cpu.
bake() {
  local name=$1 integrator=$2 samples=$3 seed=${4:-1} out=$dir/$1.prt.h5
  [ -s "$dir/$name.cpu" ] && [ -s "$out" ] && return 0
  say "$asset: $integrator $samples (seed $seed)"
  if ! /usr/bin/time -f "%U %S %e" -o "$dir/$name.time" nice "$prtbake" texel "$mesh" "${size[@]}" --ao --no-stitch \
      --integrator "$integrator" --samples "$samples" --seed "$seed" --report 0 -o "$out" > "$dir/$name.log" 2>&1; then
    say "$asset: $integrator $samples FAILED (exit $?): $dir/$name.log"
    tail -5 "$dir/$name.log" >&2
    return 1
  fi
  local integ
  integ=$(sed -n 's/.*(\([0-9.]*\) CPU s in the integrator.*/\1/p' "$dir/$name.log" | tail -1)
  awk -v i="${integ:-nan}" '{ printf "%.3f %s %.3f\n", $1 + $2, i, $3 }' "$dir/$name.time" > "$dir/$name.cpu"
}

# measure NAME: "rmse se texels nonfinite max" of NAME against the reference.
measure() {
  "$errprog" "$dir/refA.prt.h5" "$dir/refB.prt.h5" "$dir/$1.prt.h5" |
    awk -F'\t' '$1 == "file" { for (i = 3; i <= NF; ++i) { split($i, kv, "="); v[kv[1]] = kv[2] }
                               print v["rmse"], v["se"], v["texels"], v["nonfinite"], v["max"] }'
}

# rung INTEGRATOR SETTING: bakes, measures, appends to rungs.tsv; sets r_err, r_se, r_cpu.
rung() {
  local integrator=$1 setting=$2 samples=$2 name
  [ "$integrator" = silhouette ] && samples=$((setting * setting))
  name=${integrator}_$setting
  bake "$name" "$integrator" "$samples" || { r_err=nan; r_cpu=nan; return 1; }
  read -r r_err r_se r_texels r_nonfinite r_max < <(measure "$name")
  read -r cpu r_integ r_wall < "$dir/$name.cpu"
  r_cpu=$(awk -v c="$cpu" -v b="$base_cpu" 'BEGIN { printf "%.3f", c - b }')
  local summary=""
  [ "$integrator" = filter ] && summary=$(grep -m1 '^per point' "$dir/$name.log" | tr '\t' ' ')
  printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$asset" "$integrator" "$setting" "$r_err" "$r_se" "$r_cpu" \
    "$r_integ" "$r_texels" "$r_nonfinite" "$r_max" "$summary" >> "$work_tsv"
  say "$asset: $integrator $setting: rmse $r_err (se $r_se), $r_cpu CPU s over the baseline"
}

meets() { awk -v e="$1" -v t="$E" 'BEGIN { exit !(e != "nan" && e <= t) }'; }

# ladder INTEGRATOR START_INDEX SETTINGS...: walks as the header says; prints "setting" of the
# cheapest rung meeting E, or "-" (none).
ladder() {
  local integrator=$1 i=$2
  shift 2
  local -a s=("$@")
  local best=- prev_err="" prev_cpu=""
  rung "$integrator" "${s[$i]}" || { echo -; return; }
  if meets "$r_err"; then
    best=${s[$i]}
    while [ "$i" -gt 0 ]; do
      i=$((i - 1))
      rung "$integrator" "${s[$i]}" || break
      meets "$r_err" || break
      best=${s[$i]}
    done
  else
    while [ $((i + 1)) -lt ${#s[@]} ]; do
      prev_err=$r_err prev_cpu=$r_cpu
      # the next rung's predicted cost: this one's scaled by the samples ratio (N² for silhouette)
      local next_cost
      next_cost=$(awk -v c="$prev_cpu" -v a="${s[$i]}" -v b="${s[$((i + 1))]}" -v sil="$([ "$integrator" = silhouette ] && echo 1 || echo 0)" \
                  'BEGIN { r = b / a; if (sil) r = r * r; printf "%.1f", c * r }')
      if awk -v n="$next_cost" -v cap="$rung_cap" 'BEGIN { exit !(n > cap) }'; then
        say "$asset: $integrator: next rung ${s[$((i + 1))]} predicted at $next_cost CPU s > RUNG_CAP: stop"
        break
      fi
      i=$((i + 1))
      rung "$integrator" "${s[$i]}" || break
      if meets "$r_err"; then best=${s[$i]}; break; fi
      if awk -v p="$prev_err" -v e="$r_err" 'BEGIN { exit !(e > 0.9 * p) }'; then
        say "$asset: $integrator: error fell by less than 10% ($prev_err -> $r_err): a floor, stop"
        break
      fi
    done
  fi
  echo "$best"
}

index_of() { local x=$1 i=0; shift; for v in "$@"; do [ "$v" = "$x" ] && { echo $i; return; }; i=$((i + 1)); done; echo 0; }

work_tsv=$work/rungs.tsv
: > "$work_tsv"
: > "$work/best.tsv"
: > "$work/split.tsv"
for asset in "${assets[@]}"; do
  dir=$work/$asset
  mkdir -p "$dir"
  case $asset in
    bunny) mesh=data/bunny_ground.obj; size=(--resolution "${BUNNY_RES:-256}") ;;
    arch)
      mesh=$dir/arch.obj
      [ -s "$mesh" ] || "$errprog" --arch-obj "${ARCH_CELLS:-4}" "$mesh" >&2 || exit 2
      size=(--density "${ARCH_DENSITY:-10}") ;;
    engine) mesh=$engine; size=(--density "${ENGINE_DENSITY:-0.125}") ;;
    *) echo "unknown asset $asset" >&2; exit 2 ;;
  esac
  say "$asset: $mesh ${size[*]}"
  bake base qmc 1 || exit 2
  bake refA qmc "$ref_rays" 1001 || exit 2
  bake refB qmc "$ref_rays" 1002 || exit 2
  read -r base_cpu _ _ < "$dir/base.cpu"
  grep -m1 '^lightmap:' "$dir/base.log" >&2
  "$errprog" "$dir/refA.prt.h5" "$dir/refB.prt.h5" | tee "$dir/reference.txt" >&2
  # QMC 256 and the filter's 8/16/32 for the side-by-side; then the ladders.
  rung qmc 256
  for r in 8 16 32; do rung filter "$r"; done
  # The filter's error at 32 rays split into noise and bias: a second seed's bake; the RMS of the
  # two bakes' difference over √2 is one bake's noise, the rest of its RMSE its bias.
  bake filter_32_seed2 filter 32 2 &&
    "$errprog" "$dir/filter_32.prt.h5" "$dir/filter_32_seed2.prt.h5" | awk -F'\t' -v a="$asset" -v t="$work_tsv" '
      $1 == "reference" { split($4, kv, "="); noise = kv[2] / sqrt(2)
        while ((getline line < t) > 0) { split(line, f, "\t"); if (f[1] == a && f[2] == "filter" && f[3] == 32) e = f[4] }
        bias = e * e - noise * noise
        printf "%s\tfilter 32\tnoise=%.4g\tbias=%.4g\n", a, noise, (bias > 0 ? sqrt(bias) : 0) }' >> "$work/split.tsv"
  q=$(ladder qmc "$(index_of "${QMC_START:-2048}" "${qmc_ladder[@]}")" "${qmc_ladder[@]}")
  s=$(ladder silhouette "$(index_of "${SIL_START:-32}" "${sil_ladder[@]}")" "${sil_ladder[@]}")
  f=$(ladder filter "$(index_of 45 "${filter_ladder[@]}")" "${filter_ladder[@]}")
  printf '%s\tbest\tqmc=%s\tsilhouette=%s\tfilter=%s\n' "$asset" "$q" "$s" "$f" >> "$work/best.tsv"
done

# The tables: every rung, and per asset the cheapest rung meeting E of each integrator.
echo "| asset | integrator | setting | texels | AO RMSE (noise taken out) | its std. error | max \|d\| | CPU s over the baseline | row-loop CPU s | texels / CPU s | meets $E |"
echo "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---|"
sort -t$'\t' -k1,1 -k2,2 -k3,3n -u "$work_tsv" | awk -F'\t' -v E="$E" '{
  rate = ($6 > 0) ? $8 / $6 : 0
  printf "| %s | %s | %s | %s | %.3g | %.1g | %.3g | %.1f | %s | %.0f | %s |\n", $1, $2, $3, $8, $4, $5, $10, $6, $7, rate, ($4 <= E) ? "yes" : "no"
}'
echo
cat "$work/best.tsv"
if [ -s "$work/split.tsv" ]; then cat "$work/split.tsv"; fi
