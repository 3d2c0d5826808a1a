#!/usr/bin/env bash
# bench/default_vs_tuned.sh — issue 27: prtbake's DEFAULT vertex bake (the --target-error chooser,
# E = 1e-3) side by side with hand-tuned plans and a converged independent reference, in one run.
#
# Inputs: every OBJ/PLY/OFF/STL/glTF/GLB of Debian's assimp-testmodels (found as
# bench/sweep_models.sh finds them) that `prtbake vertex --ao` bakes (exit 0; exit 1 = refused,
# listed) and has at most MAX_TRIANGLES triangles (the rest listed as skipped); a file whose rows
# (positions, normals, triangles) equal an earlier file's is listed and not baked again; × the product sets
#   AO                              once per mesh (no environment), and
#   AO + order-3 transfer + band-1  once per mesh and HDRI in HDRIS.
# Per case:
#   default     `prtbake vertex MESH <products> --report 0 -o F`: the default plan (the chooser's
#               pilot included) without the error report a user's run adds after the bake (prtbake
#               does not count it in the bake time either), timed as a whole process. When a
#               product misses E against the reference, the same command without --report 0 runs
#               again, untimed for the ratio, for the verdict of the default's own error report
#               and the error of the file it leaves (re-baked once when its check said NOT met)
#               ("met", "NOT met", "not verifiable here"); the table shows that run's wall time too;
#   hand-tuned  two ladders of pinned plans, each `--report 0`, timed as whole processes:
#               silhouette N = 16, 32, ..., 1024 u-isolines (--samples N^2) and qmc R = 64, 128,
#               ..., 2^18 rays. The rung run next is the one of the ladder whose last rung was
#               cheaper; a ladder stops when its rung meets E (every product), when its last rung
#               took at least as long as the fastest plan found meeting E (its next rungs cost
#               more), after a rung above RUNG_CAP seconds, or at its top. Then, for each ladder
#               that met E within 2x of the fastest, one rung between its last miss and its
#               first hit (the geometric mean: N x 1.41 or R x 1.41), so the grid is ~1.41x.
#               The fastest plan that meets E is the hand-tuned plan;
#   reference   bench_reference_error: prtbake's QMC integrator (bake/integrators/qmc.h) at REF_RAYS rays on
#               POINTS seeded rows of the mesh's own shade points (loaded as prtbake loads them),
#               independent seeds, 4 replicates (their spread is its standard error); rays
#               doubled (to 2^22) while its standard error on some product is above E/3. Every file's error is measured against it in E's units.
#   truth       prtbake's silhouette integrator at N = TRUTH_N isolines (1024: its own error 0.05–0.15 E,
#               its Richardson estimate) on EVERY row of the mesh. With it, every file's error (the
#               default's, each rung's "meets E") is measured over all rows against it, radiance
#               relative to its RMS over all rows: the whole-mesh numbers E is defined on (20 rows'
#               RMSE varies by tens of percent from sample to sample, and their radiance RMS by 3.7x
#               on regr01.obj, where half the vertices see no sky). The truth is itself measured
#               against the independent QMC reference on the POINTS rows (the table's last column:
#               "truth vs QMC"), which must stay within that reference's own noise.
#               TRUTH_N=0: no truth, errors on the sampled rows against the QMC reference (the
#               sweeps before 2026-12-06 evening);
#   ratio       default bake time / hand-tuned time.
# Prints a markdown table (one row per case) and the summary lines; progress goes to stderr.
#
#   bench/default_vs_tuned.sh            the full sweep (~40 min on 2 cores)
#   bench/default_vs_tuned.sh --quick    the issue's three meshes and one box, under city and sunrise
# Environment: PRT_BENCH_BUILD_DIR (default build/release: prtbake, bench_reference_error),
#   MODELS (default /usr/share/assimp/models), FILES (space-separated mesh paths under MODELS:
#   these instead of the search), HDRIS (space-separated EXR paths), MAX_TRIANGLES
#   (default 20000), POINTS (20), REF_RAYS (131072: the first pass), RUNG_CAP (30 s), DEFAULT_CAP
#   (90 s: a default bake still running then is killed and reported as a runaway, its time as
#   the cap, so its ratio is a lower bound), TARGET (1e-3), HDRI_ONCE (below), SMALL_TRIANGLES
#   (32) and SMALL_HDRIS (city, sunrise: the issue's sun cases): a mesh of fewer triangles (a
#   plane, a box: little or nothing occludes) is baked under those HDRIs only; WORK (a directory
#   to keep the cases' logs and rows in; default a temporary one, removed), NO_AO=1 (leave out
#   the AO-only cases).
#   bench/default_vs_tuned.sh --table DIR   prints the table of DIR/rows.tsv (a WORK directory,
#   e.g. of a run stopped early) without baking.
set -uo pipefail
cd "$(dirname "$0")/.."
build=${PRT_BENCH_BUILD_DIR:-build/release}
prtbake=$build/tools/prtbake
refprog=$build/bench/bench_reference_error
models=${MODELS:-/usr/share/assimp/models}
world=/usr/share/blender/datafiles/studiolights/world
E=${TARGET:-1e-3}
max_tris=${MAX_TRIANGLES:-20000}
points=${POINTS:-20}
ref_rays=${REF_RAYS:-131072}
rung_cap=${RUNG_CAP:-30}
default_cap=${DEFAULT_CAP:-90}
truth_n=${TRUTH_N:-1024}
quick=0
[ "${1:-}" = --quick ] && quick=1
if [ $quick = 1 ]; then
  read -r -a hdris <<< "${HDRIS:-$world/city.exr $world/sunrise.exr}"
else
  read -r -a hdris <<< "${HDRIS:-data/sunset.exr data/forest.exr data/studio.exr data/interior.exr $world/city.exr $world/sunrise.exr}"
fi
small_tris=${SMALL_TRIANGLES:-32}
read -r -a small_hdris <<< "${SMALL_HDRIS:-$world/city.exr $world/sunrise.exr}"
[ -x "$prtbake" ] && [ -x "$refprog" ] || { echo "build $prtbake and $refprog first" >&2; exit 2; }
table_only=0
if [ "${1:-}" = --table ]; then
  table_only=1
  work=$2
elif [ -n "${WORK:-}" ]; then
  work=$WORK
  mkdir -p "$work"
else
  work=$(mktemp -d)
  tmp_work=$work
  trap 'rm -rf "$tmp_work"' EXIT
fi
sweep_start=$(date +%s.%N)

if [ $table_only = 0 ]; then
# ---- the files (sweep_models.sh's list) ----
if [ -n "${FILES:-}" ]; then
  read -r -a files <<< "$FILES"
elif [ $quick = 1 ]; then
  files=("$models/STL/sphereWithHole.stl" "$models/STL/3DSMaxExport.STL" "$models/OBJ/regr01.obj"
         "$models/glTF2/BoxTextured-glTF-Binary/BoxTextured.glb")
else
  mapfile -t files < <(find "$models" -type f \( -iname '*.obj' -o -iname '*.ply' -o -iname '*.off' -o -iname '*.stl' \
                         -o -iname '*.gltf' -o -iname '*.glb' \) | sort)
fi

# timed LOG CMD...: runs CMD niced under a $limit s timeout (default 600); sets rc, wall, cpu
# (user + sys seconds).
timed() {
  local log=$1
  shift
  /usr/bin/time -f '%e %U %S' -o "$work/time" timeout "${limit:-600}" nice "$@" > "$log" 2>&1
  rc=$?
  local u s
  read -r wall u s < <(tail -1 "$work/time")
  cpu=$(echo "$u + $s" | bc -l)
}

# measure FILE: the file's errors against the case's reference; sets errs ("ao=.. transfer=.."),
# meets (1 when every product <= E), plan, and worst (the largest error / E).
measure() {
  local line
  line=$("$refprog" "$mesh" "${refargs[@]}" --target "$E" --points "$points" --rays "$ref_rays" \
           --cache "$case_dir/ref.bin" "${truth_args[@]}" "$1" 2> "$work/referr" | grep '^file')
  if [ -z "$line" ]; then
    errs="?"; meets=0; plan="?"; worst=inf
    echo "  bench_reference_error failed on $1: $(head -c 300 "$work/referr")" >&2
    return
  fi
  plan=$(echo "$line" | tr '\t' '\n' | sed -n 's/^plan=//p')
  errs=$(echo "$line" | cut -f4- | tr '\t' ' ')
  worst=$(echo "$errs" | tr ' ' '\n' | awk -F= -v E="$E" 'BEGIN{w=0} {v=$2+0; if ($2=="nan") v=1e30; if (v/E>w) w=v/E} END{printf "%.3g", w}')
  meets=$(awk -v w="$worst" 'BEGIN{print (w <= 1) ? 1 : 0}')
}

# The same model exported to several formats (its rows differ: split per facet, file normals or
# not): the HDRI cases are run on one of them only, to keep the sweep in its budget; the others
# run the AO case. HDRI_ONCE="file=representative ..." (paths under MODELS).
declare -A also_as
read -r -a once <<< "${HDRI_ONCE:-STL/Wuson.stl=OBJ/WusonOBJ.obj PLY/Wuson.ply=OBJ/WusonOBJ.obj OFF/Wuson.off=OBJ/WusonOBJ.obj STL/Spider_ascii.stl=OBJ/spider.obj STL/Spider_binary.stl=OBJ/spider.obj}"
for o in "${once[@]}"; do also_as[${o%%=*}]=${o#*=}; done
ao_only=()

# ---- which files bake, and how large ----
accepted=() refused=() skipped=() errors=() duplicates=()
declare -A seen  # geometry hash (positions, normals, triangles: the rows) -> the first file with it
for f in "${files[@]}"; do
  timed "$work/probe.log" "$prtbake" vertex "$f" --ao --integrator qmc --samples 1 --report 0 -o "$work/probe.prt.h5"
  name=${f#"$models"/}
  if [ "$rc" = 1 ]; then refused+=("$name: $(grep -v '^mesh:' "$work/probe.log" | head -1 | cut -c1-160)"); continue; fi
  if [ "$rc" != 0 ]; then errors+=("$name: exit $rc: $(head -1 "$work/probe.log" | cut -c1-160)"); continue; fi
  tris=$(sed -n 's/^mesh: .*: \([0-9]*\) vertices, \([0-9]*\) triangles.*/\2/p' "$work/probe.log" | head -1)
  verts=$(sed -n 's/^mesh: .*: \([0-9]*\) vertices, \([0-9]*\) triangles.*/\1/p' "$work/probe.log" | head -1)
  if [ "${tris:-0}" -gt "$max_tris" ]; then skipped+=("$name ($tris triangles)"); continue; fi
  geom=$("$refprog" "$f" --geometry | cut -f2)
  if [ -n "${seen[$geom]:-}" ]; then duplicates+=("$name: the same rows as ${seen[$geom]}"); continue; fi
  seen[$geom]=$name
  accepted+=("$f|$tris|$verts")
done
mapfile -t accepted < <(printf '%s\n' "${accepted[@]}" | sort -t'|' -k2,2nr)  # the larger meshes first
declare -p refused skipped errors duplicates ao_only > "$work/lists.sh"
echo "$sweep_start" > "$work/start"
echo "bench: ${#accepted[@]} meshes to bake, ${#refused[@]} refused, ${#skipped[@]} above $max_tris triangles, ${#duplicates[@]} duplicates, ${#errors[@]} errors" >&2

# lt A B: A < B (decimal numbers).
lt() { awk -v a="$1" -v b="$2" 'BEGIN{exit !(a < b)}'; }

# run_rung KIND KNOB: one pinned plan of the current case, timed and measured; sets rung_t,
# rung_meets, rung_errs and updates best_t / best_plan.
run_rung() {  # kind knob: sets rung_t, rung_meets, rung_errs
  local kind=$1 knob=$2 samples
  [ "$kind" = silhouette ] && samples=$((knob * knob)) || samples=$knob
  timed "$case_dir/rung.log" "$prtbake" vertex "$mesh" "${products[@]}" --integrator "$kind" --samples "$samples" \
    --report 0 -q -o "$case_dir/rung.prt.h5"
  n_rungs=$((n_rungs + 1))
  rung_t=$wall
  if [ "$rc" != 0 ]; then rung_meets=0; rung_errs="exit $rc"; echo "  $kind $knob: exit $rc" >&2; return; fi
  measure "$case_dir/rung.prt.h5"
  rung_meets=$meets; rung_errs=$errs
  echo "  $kind $knob: $wall s, $errs" >&2
  if [ "$meets" = 1 ] && { [ -z "$best_t" ] || awk -v a="$wall" -v b="$best_t" 'BEGIN{exit !(a < b)}'; }; then
    best_t=$wall
    [ "$kind" = silhouette ] && best_plan="silhouette N=$knob" || best_plan="qmc R=$knob"
  fi
}

# ---- the cases ----
rows="$work/rows.tsv"
: > "$rows"
n_case=0
for entry in "${accepted[@]}"; do
  IFS='|' read -r mesh tris verts <<< "$entry"
  name=${mesh#"$models"/}
  sets=()
  [ "${NO_AO:-0}" = 1 ] || sets+=("ao|")
  if [ -n "${also_as[$name]:-}" ]; then
    ao_only+=("$name: AO only; under the HDRIs as ${also_as[$name]}")
  elif [ "$tris" -lt "$small_tris" ]; then
    for h in "${small_hdris[@]}"; do sets+=("full|$h"); done
  else
    for h in "${hdris[@]}"; do sets+=("full|$h"); done
  fi
  for s in "${sets[@]}"; do
    IFS='|' read -r set hdri <<< "$s"
    n_case=$((n_case + 1))
    case_dir="$work/case$n_case"
    mkdir -p "$case_dir"
    if [ "$set" = ao ]; then
      products=(--ao); refargs=(--ao); label="AO"; hname="—"
    else
      products=(--ao --transfer 3 --radiance "$hdri"); refargs=(--ao --transfer 3 --radiance "$hdri")
      label="AO+T3+R"; hname=$(basename "$hdri" .exr)
    fi
    echo "bench: [$n_case] $name ($tris triangles) $label $hname" >&2

    # the truth (every row), when asked for
    truth_args=()
    if [ "$truth_n" -gt 0 ]; then
      limit=$((10 * default_cap)) timed "$case_dir/truth.log" "$prtbake" vertex "$mesh" "${products[@]}" \
        --integrator silhouette --samples $((truth_n * truth_n)) --report 0 -o "$case_dir/truth.prt.h5"
      if [ "$rc" = 0 ]; then truth_args=(--truth "$case_dir/truth.prt.h5")
      else echo "  the truth bake failed (exit $rc): errors on the sampled rows instead" >&2; fi
    fi

    # the default bake
    limit=$default_cap timed "$case_dir/default.log" "$prtbake" vertex "$mesh" "${products[@]}" --report 0 \
      -o "$case_dir/default.prt.h5"
    d_rc=$rc; d_wall=$wall; d_bake=$wall; d_verdicts=""
    if [ "$d_rc" = 0 ]; then
      measure "$case_dir/default.prt.h5"
      d_plan=$(echo "$plan" | awk -F: '$1=="silhouette"{printf "silhouette N=%d", sqrt($2)+0.5; next} $1=="qmc"{printf "qmc R=%s", $2; next} {print}')
      d_errs=$errs; d_worst=$worst
      if [ "$meets" != 1 ]; then  # what the default's own error report says (the same bake, untimed)
        limit=$((4 * default_cap)) timed "$case_dir/report.log" "$prtbake" vertex "$mesh" "${products[@]}" -o "$case_dir/report.prt.h5"
        d_wall=$wall
        d_verdicts=$(grep -E '^ *target [0-9.e+-]+ for ' "$case_dir/report.log" | grep -v ': met' |
                       sed -E 's/^ *target [0-9.e+-]+ for ([^:]*): ([^(]*)\(([0-9.e+-]*).*/\1: \2(\3)/' | tr '\n' ';' | sed 's/;$//')
        [ "$rc" != 0 ] && d_verdicts="the run with its report: exit $rc"
        if [ "$rc" = 0 ]; then  # the file the run with its report left (corrected when the check said NOT met)
          measure "$case_dir/report.prt.h5"
          r_plan=$(echo "$plan" | awk -F: '$1=="silhouette"{printf "silhouette N=%d", sqrt($2)+0.5; next} $1=="qmc"{printf "qmc R=%s", $2; next} {print}')
          r_errs=$(echo "$errs" | tr ' ' '\n' | awk -F= -v E="$E" 'NF==2{printf "%s%s %.2f", sep, $1, $2/E; sep=", "}')
          d_verdicts="${d_verdicts:+$d_verdicts; }its file: $r_plan, $r_errs (/E)"
        fi
      fi
    else
      d_plan="exit $d_rc: $(grep -v '^\(mesh\|environment\|pilot\|baking\|reference\)' "$case_dir/default.log" | head -1 | cut -c1-160)"
      [ "$d_rc" = 124 ] && d_plan="**runaway** (killed after $default_cap s): $(grep -m1 -o 'chosen [a-z]* at [^:]*' "$case_dir/default.log")"
      d_errs="-"; d_worst=nan; d_bake=nan
      [ "$d_rc" = 124 ] && d_bake=$default_cap
      # the reference still has to exist for the ladders
      "$refprog" "$mesh" "${refargs[@]}" --target "$E" --points "$points" --rays "$ref_rays" --cache "$case_dir/ref.bin" > /dev/null 2>&1
    fi
    ref_line=$("$refprog" "$mesh" "${refargs[@]}" --target "$E" --points "$points" --rays "$ref_rays" \
                 --cache "$case_dir/ref.bin" "${truth_args[@]}" 2>/dev/null | grep '^\(reference\|truth\)')
    ref_info=$(echo "$ref_line" | grep '^reference' | awk -F'\t' -v E="$E" '{s=$2 " rays" ($5=="1"?" (raised)":""); for (i=6;i<=NF;i++) {split($i,kv,"="); s=s ", " kv[1] " " sprintf("%.2f", kv[2]/E)} print s}')
    truth_info=$(echo "$ref_line" | grep '^truth' | awk -F'\t' -v E="$E" -v N="$truth_n" '{s="; truth (silhouette N=" N ") vs QMC:"; for (i=4;i<=NF;i++) {split($i,kv,"="); s=s " " kv[1] " " sprintf("%.2f", kv[2]/E)} print s}')
    ref_info="$ref_info$truth_info"

    # the ladders
    sil=(16 32 64 128 256 512 1024); qmc=(64 128 256 512 1024 2048 4096 8192 16384 32768 65536 131072 262144)
    si=0; qi=0; s_last=0; q_last=0; s_stop=0; q_stop=0
    s_hit=""; q_hit=""; s_miss=""; q_miss=""; s_hit_t=""; q_hit_t=""
    best_t=""; best_plan="none"
    n_rungs=0
    while [ $s_stop = 0 ] || [ $q_stop = 0 ]; do
      if [ $s_stop = 0 ] && { [ $q_stop = 1 ] || ! lt "$q_last" "$s_last"; }; then
        run_rung silhouette "${sil[$si]}"
        s_last=$rung_t
        if [ "$rung_meets" = 1 ]; then s_hit=${sil[$si]}; s_hit_t=$rung_t; s_stop=1; else s_miss=${sil[$si]}; fi
        si=$((si + 1))
        [ $si -ge ${#sil[@]} ] && s_stop=1
        lt "$rung_cap" "$s_last" && s_stop=1
        [[ $rung_errs == exit* ]] && s_stop=1
        [ -n "$best_t" ] && ! lt "$s_last" "$best_t" && s_stop=1
      else
        run_rung qmc "${qmc[$qi]}"
        q_last=$rung_t
        if [ "$rung_meets" = 1 ]; then q_hit=${qmc[$qi]}; q_hit_t=$rung_t; q_stop=1; else q_miss=${qmc[$qi]}; fi
        qi=$((qi + 1))
        [ $qi -ge ${#qmc[@]} ] && q_stop=1
        lt "$rung_cap" "$q_last" && q_stop=1
        [[ $rung_errs == exit* ]] && q_stop=1
        [ -n "$best_t" ] && ! lt "$q_last" "$best_t" && q_stop=1
      fi
    done
    # one rung between the last miss and the first hit of each ladder that is within 2x of the best
    if [ -n "$s_hit" ] && [ -n "$s_miss" ] && lt "$s_hit_t" "$(echo "2 * $best_t" | bc -l)"; then
      mid=$(awk -v a="$s_miss" -v b="$s_hit" 'BEGIN{m=sqrt(a*b); m=2*int(m/2+0.5); print m}')
      [ "$mid" -gt "$s_miss" ] && [ "$mid" -lt "$s_hit" ] && run_rung silhouette "$mid"
    fi
    if [ -n "$q_hit" ] && [ -n "$q_miss" ] && lt "$q_hit_t" "$(echo "2 * $best_t" | bc -l)"; then
      mid=$(awk -v a="$q_miss" -v b="$q_hit" 'BEGIN{print int(sqrt(a*b)+0.5)}')
      [ "$mid" -gt "$q_miss" ] && [ "$mid" -lt "$q_hit" ] && run_rung qmc "$mid"
    fi
    ratio=nan
    [ -n "$best_t" ] && [ "$d_bake" != nan ] && ratio=$(awk -v a="$d_bake" -v b="$best_t" 'BEGIN{printf "%.2f", a/b}')
    printf '%s\t%s\t%s\t%s\t%s\t%.2f\t%.2f\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' \
      "$name" "$tris" "$hname" "$label" "$d_plan" "$d_bake" "$d_wall" "$best_plan" "${best_t:-nan}" "$ratio" \
      "$d_errs" "$d_worst" "${d_verdicts:--}" "${ref_info:-?}" "$n_rungs" >> "$rows"
    rm -f "$case_dir"/*.prt.h5
  done
done
sweep_secs=$(echo "$(date +%s.%N) - $sweep_start" | bc -l)
declare -p refused skipped errors duplicates ao_only > "$work/lists.sh"
printf '%.0f\n' "$sweep_secs" > "$work/seconds"
fi
# shellcheck disable=SC1091
. "$work/lists.sh"
if [ -f "$work/seconds" ]; then sweep_secs=$(cat "$work/seconds")
else sweep_secs="$(echo "$(date +%s.%N) - $(cat "$work/start" 2>/dev/null || date +%s)" | bc -l | xargs printf '%.0f') so far (stopped or still running)"; fi

rows="$work/rows.tsv"
# ---- the table ----
echo "| mesh | tris | HDRI | products | default plan | default s (bake / with its report) | fastest hand-tuned meeting E | s | ratio | default error / E per product | verdict | reference (rays, std. error / E) |"
echo "|---|---:|---|---|---|---:|---|---:|---:|---|---|---|"
while IFS=$'\t' read -r name tris hname label dplan dbake dwall bplan bt ratio derrs dworst dverd refinfo nr; do
  per=$(echo "$derrs" | tr ' ' '\n' | awk -F= -v E="$E" 'NF==2{printf "%s%s %.2f", (n++?", ":""), $1, ($2=="nan"?1e30:$2/E)}')
  [ -z "$per" ] && per="—"
  [[ $dplan == \*\*runaway* ]] && [ "$ratio" != nan ] && ratio="≥ $ratio"
  if [[ $dplan == \*\*runaway* ]]; then verdict="runaway: killed, no file to check"
  elif [ "$dworst" = nan ]; then verdict="default did not bake"
  elif awk -v w="$dworst" 'BEGIN{exit !(w <= 1)}'; then verdict="within E"
  else verdict="**above E** ($(echo "$derrs" | tr ' ' '\n' | awk -F= -v E="$E" 'NF==2 && $2/E>1{printf "%s%s", (n++?", ":""), $1}'))"; fi
  [ "$dverd" != - ] && verdict="$verdict; report: $dverd"
  printf '| %s | %s | %s | %s | %s | %s / %s | %s | %s | %s | %s | %s | %s |\n' \
    "$name" "$tris" "$hname" "$label" "$dplan" "$dbake" "$dwall" "$bplan" "$bt" "$ratio" "$per" "$verdict" "$refinfo"
done < "$rows"

echo
n_rated=$(awk -F'\t' '$10 != "nan"' "$rows" | wc -l)
median=$(awk -F'\t' '$10 != "nan" {print $10}' "$rows" | sort -g |
         awk '{r[NR] = $1} END {if (NR == 0) print "nan"; else if (NR % 2) print r[(NR + 1) / 2]; else printf "%.2f\n", (r[NR / 2] + r[NR / 2 + 1]) / 2}')
worst=$(awk -F'\t' '$10 != "nan" {print $10 "\t" $1 " " $3 " " $4}' "$rows" | sort -g -r | head -1)
over=$(awk -F'\t' '$10 != "nan" && $10 + 0 > 2' "$rows" | wc -l)
over_long=$(awk -F'\t' '$10 != "nan" && $10 + 0 > 2 && $6 + 0 >= 0.5' "$rows" | wc -l)
echo "- cases: $(wc -l < "$rows") ($n_rated with a ratio; the rest: the default or every hand-tuned plan failed)"
echo "- ratio default bake / fastest hand-tuned: worst ${worst%%$'\t'*} (${worst#*$'\t'}), median $median; cases above 2x: $over ($over_long of them with a default bake of 0.5 s or more)"
awk -F'\t' -v E="$E" '{ m = split($11, kv, " "); for (i = 1; i <= m; i++) { split(kv[i], p, "="); if (p[2] == "") continue; prods++; if (p[2] == "nan" || p[2] / E > 1) { above++; list = list sprintf("%s%s %s %s %s %.2f", (above > 1 ? "; " : ""), $1, $3, $4, p[1], (p[2] == "nan" ? 1e30 : p[2] / E)) } } }
  END { printf "- default products above E against the reference: %d of %d%s\n", above, prods, (above ? " (" list ")" : "") }' "$rows"
echo "- refused by prtbake (exit 1), ${#refused[@]}:"
for r in "${refused[@]}"; do echo "  - $r"; done
echo "- skipped (above $max_tris triangles), ${#skipped[@]}:"
for r in "${skipped[@]}"; do echo "  - $r"; done
echo "- not baked again (identical positions, normals and triangles: identical bakes), ${#duplicates[@]}:"
for r in "${duplicates[@]}"; do echo "  - $r"; done
echo "- the same model in another format: AO only, ${#ao_only[@]}:"
for r in "${ao_only[@]}"; do echo "  - $r"; done
echo "- errors (exit other than 0/1), ${#errors[@]}:"
for r in "${errors[@]}"; do echo "  - $r"; done
printf -- "- sweep wall time: %s s on %s CPUs (%s)\n" "$sweep_secs" "$(nproc)" "$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
