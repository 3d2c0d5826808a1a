#!/usr/bin/env bash
# bench/figures.sh — the pictures and error numbers of issue 5 ("What it must show"), made with the
# release binaries: bakes what it needs (prtbake fiv / vertex / scene), renders each runtime picture next
# to its Embree ray-traced reference with prtview, and writes docs/images/*.png and docs/FIGURES.md
# (NRMSE next to paper 004's numbers, the reference's own noise, the image paths, the exact
# commands).
#
#   bench/figures.sh              build (cmake --preset release, prtbake + prtview, -j2) and run (~5–10 min on 2 cores)
#   bench/figures.sh --no-build   use what build/release already holds
#   bench/figures.sh --quick      256 reference rays per pixel and 128x128 pictures (smoke test, ~1 min);
#                                 writes out/figures/FIGURES.md, never docs/
#
# Scratch files (baked .prt.h5, references, logs) go to out/figures/. Each view's reference is traced
# once per run and shared (prtview --reference-cache), so the shell resolutions of Figure 12 and
# the on/off pairs are compared against one reference each.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
build=1
quick=0
while (($#)); do
  case "$1" in
    --no-build) build=0 ;;
    --quick) quick=1 ;;
    *) echo "figures.sh: unknown option $1" >&2; exit 2 ;;
  esac
  shift
done

if ((build)); then
  cmake --preset release >/dev/null
  cmake --build --preset release --target prtbake prtview sky_exr -j 2
fi
BAKE=build/release/tools/prtbake
VIEW=build/release/tools/prtview
for b in "$BAKE" "$VIEW" build/release/bench/sky_exr; do [ -x "$b" ] || { echo "figures.sh: $b not built (run without --no-build)" >&2; exit 1; }; done

work=out/figures
mkdir -p "$work"
rm -f "$work"/ref_*.exr  # every run traces its references afresh (and shares each within the run)
if ((quick)); then
  SIZE=128x128; RAYS_FIG12=256; RAYS=256; images="$work/images"; md="$work/FIGURES.md"
else
  SIZE=256x256; RAYS_FIG12=4096; RAYS=2048; images=docs/images; md=docs/FIGURES.md
fi
mkdir -p "$images"
start=$(date +%s)
load_start=$(cut -d' ' -f1-3 /proc/loadavg)

rows=()   # markdown table rows
cmds=()   # exact commands, in order
pictures=()  # image file names, in table order

# run CMD...: prints and records the command, runs it.
run() {
  cmds+=("$*")
  echo "+ $*" >&2
  "$@"
}

# view LABEL PAPER IMAGE ARGS...: prtview --triptych to IMAGE, parse its numbers into a table row.
view() {
  local label="$1" paper="$2" image="$3"
  shift 3
  local log="$work/$(basename "$image" .png).log"
  run "$VIEW" "$@" --size "$SIZE" --triptych -o "$image" --quiet >"$log"
  cat "$log"
  local nrmse noise corrected
  nrmse=$(awk '/^NRMSE /{print $2; exit}' "$log")
  noise=$(awk '/^reference noise /{print $3; exit}' "$log")
  corrected=$(awk '/^reference noise /{print $NF; exit}' "$log")
  all=$(awk '/^NRMSE over all covered pixels /{print $6; exit}' "$log")
  rows+=("| $label | $nrmse | $noise | $corrected | ${all:--} | $paper | [$(basename "$image")](images/$(basename "$image")) |")
  pictures+=("$(basename "$image")")
}

FOREST=data/forest.exr
SUNSET=data/sunset.exr
BUNNY=data/bunny.obj

# ---- Figure 12: the bunny's shadow on the ground under forest.exr at three shell resolutions ----
# (prtbake's default radial scheme: shells that follow the surface, issue 33)
for s in 32x17x15 64x33x30 256x129x30; do
  run "$BAKE" fiv "$BUNNY" --env "$FOREST" --shells "$s" --report 0 --quiet -o "$work/bunny_$s.prt.h5"
done
CAM12="eye=0,26,24:at=0,0,1:fov=45"
paper12=(0.023 0.008 0.007)
i=0
for s in 32x17x15 64x33x30 256x129x30; do
  view "Fig. 12: bunny shadow, shells $s following the surface (forest.exr)" "${paper12[$i]}" "$images/fig12_$s.png" \
    "$work/bunny_$s.prt.h5" --camera "$CAM12" --samples "$RAYS_FIG12" --reference-cache "$work/ref_fig12_$SIZE.exr"
  i=$((i + 1))
done
# The same memory with paper 004's spheres (--radial geometric), and the partial-occluder factor's
# share of what is left (the bounding sphere's (h + R)/2R scales the whole ground shadow).
run "$BAKE" fiv "$BUNNY" --env "$FOREST" --shells 64x33x30 --radial geometric --report 0 --quiet \
  -o "$work/bunny_64x33x30_geometric.prt.h5"
view "Fig. 12: shells 64x33x30 on paper 004's spheres (--radial geometric)" "0.008" "$images/fig12_64x33x30_geometric.png" \
  "$work/bunny_64x33x30_geometric.prt.h5" --camera "$CAM12" --samples "$RAYS_FIG12" --reference-cache "$work/ref_fig12_$SIZE.exr"
# Half-float tables (prtbake's default, --precision half): at the memory of paper 004's 64x33x30
# float32 shells (2.17 MiB), 96x49x26 half shells (2.12 MiB with the surface radii), or 84x43x24 half shells and their
# cone table (2.16 MiB with the surface radii); and the 64x33x30 float32 file for the rounding's share.
for s in 96x49x26 84x43x24; do
  run "$BAKE" fiv "$BUNNY" --env "$FOREST" --shells "$s" --report 0 --quiet -o "$work/bunny_$s.prt.h5"
done
run "$BAKE" fiv "$BUNNY" --env "$FOREST" --shells 64x33x30 --precision float --report 0 --quiet \
  -o "$work/bunny_64x33x30_float.prt.h5"
view "Fig. 12 at 64x33x30's memory: shells 96x49x26 in half floats (2.12 MiB)" "0.008" "$images/fig12_96x49x26.png" \
  "$work/bunny_96x49x26.prt.h5" --camera "$CAM12" --samples "$RAYS_FIG12" --reference-cache "$work/ref_fig12_$SIZE.exr"
view "Fig. 12 at 64x33x30's memory: shells and cone table 84x43x24 in half floats (2.16 MiB)" "0.008" \
  "$images/fig12_84x43x24.png" "$work/bunny_84x43x24.prt.h5" --camera "$CAM12" --samples "$RAYS_FIG12" \
  --reference-cache "$work/ref_fig12_$SIZE.exr"
view "Fig. 12 diagnostic: shells 64x33x30 in float32 (--precision float)" "-" "$images/fig12_64x33x30_float.png" \
  "$work/bunny_64x33x30_float.prt.h5" --camera "$CAM12" --samples "$RAYS_FIG12" --reference-cache "$work/ref_fig12_$SIZE.exr"
run "$BAKE" fiv "$BUNNY" --env "$FOREST" --shells 64x33x30 --self-shadows shells --report 0 --quiet \
  -o "$work/bunny_64x33x30_self_shells.prt.h5"
view "Fig. 12 diagnostic: the bunny's self-shadows from the shells (eq. 12, --self-shadows shells)" "-" \
  "$images/fig12_64x33x30_self_shells.png" "$work/bunny_64x33x30_self_shells.prt.h5" --camera "$CAM12" \
  --samples "$RAYS_FIG12" --reference-cache "$work/ref_fig12_$SIZE.exr"
view "Fig. 12 diagnostic: shells 64x33x30 following the surface, partial-occluder factor off" "-" \
  "$images/fig12_64x33x30_no_partial.png" "$work/bunny_64x33x30.prt.h5" --camera "$CAM12" --no-partial \
  --samples "$RAYS_FIG12" --reference-cache "$work/ref_fig12_$SIZE.exr"

# ---- two overlapping occluders, overlap correction on / off (paper 004 eq. 13-14, Fig. 15), with the tight
# proxy (the file's cone table, the default: prtshade/fiv.h "Tight proxies") and the paper's bounding sphere ----
CAM2="eye=0,30,30:at=0,0,1:fov=50"
TWO=(--instance -5.5,0,0 --instance 5.5,0,0)
view "Two overlapping bunnies, overlap correction on (cone proxy)" "0.019 (Fig. 15, on)" "$images/overlap_on.png" \
  "$work/bunny_64x33x30.prt.h5" --camera "$CAM2" "${TWO[@]}" --samples "$RAYS" --reference-cache "$work/ref_overlap_$SIZE.exr"
view "Two overlapping bunnies, overlap correction off (cone proxy)" "0.027 (Fig. 15, off)" "$images/overlap_off.png" \
  "$work/bunny_64x33x30.prt.h5" --camera "$CAM2" "${TWO[@]}" --no-overlap --samples "$RAYS" --reference-cache "$work/ref_overlap_$SIZE.exr"
view "Two overlapping bunnies, overlap correction on (bounding sphere, the paper's)" "0.019 (Fig. 15, on)" "$images/overlap_on_sphere.png" \
  "$work/bunny_64x33x30.prt.h5" --camera "$CAM2" "${TWO[@]}" --proxy sphere --samples "$RAYS" --reference-cache "$work/ref_overlap_$SIZE.exr"
view "Two overlapping bunnies, overlap correction off (bounding sphere)" "0.027 (Fig. 15, off)" "$images/overlap_off_sphere.png" \
  "$work/bunny_64x33x30.prt.h5" --camera "$CAM2" "${TWO[@]}" --proxy sphere --no-overlap --samples "$RAYS" --reference-cache "$work/ref_overlap_$SIZE.exr"

# ---- an occluder partly below the receiver's horizon: sunk 2 units (of 9.65) into the ground; the cone
# proxy's correction (the cap below the horizon, lit from below) and the paper's (h+R)/2R ----
CAMP="eye=0,26,24:at=0,0,1:fov=45"
SINK=(--instance 0,-2,0 --ground 0)
view "Bunny partly below the ground, partial-occluder correction on (cone proxy)" "0.019 (Fig. 17, on)" "$images/partial_on.png" \
  "$work/bunny_64x33x30.prt.h5" --camera "$CAMP" "${SINK[@]}" --samples "$RAYS" --reference-cache "$work/ref_partial_$SIZE.exr"
view "Bunny partly below the ground, partial-occluder correction off" "0.026 (Fig. 17, off)" "$images/partial_off.png" \
  "$work/bunny_64x33x30.prt.h5" --camera "$CAMP" "${SINK[@]}" --no-partial --samples "$RAYS" --reference-cache "$work/ref_partial_$SIZE.exr"
view "Bunny partly below the ground, partial-occluder factor (h+R)/2R on (bounding sphere, the paper's)" "0.019 (Fig. 17, on)" "$images/partial_on_sphere.png" \
  "$work/bunny_64x33x30.prt.h5" --camera "$CAMP" "${SINK[@]}" --proxy sphere --samples "$RAYS" --reference-cache "$work/ref_partial_$SIZE.exr"

# ---- the paper's kind of scene (issue 33): Fig. 15, three bunnies in a row whose occluded cones overlap in
# the sky under an overcast sky (uniform radiance above the horizon, eq. 14's own assumption); Fig. 17, the
# sunk bunny under a bright ground (light from below the receiver's horizon matters). Two-tone
# environments made by bench/sky_exr.cpp (build/release/bench/sky_exr) ----
run build/release/bench/sky_exr "$work/overcast.exr" 1,1,1 0.1,0.1,0.1
run build/release/bench/sky_exr "$work/bright_ground.exr" 0.6,0.7,0.9 2.0,1.8,1.5
run "$BAKE" fiv "$BUNNY" --env "$work/overcast.exr" --shells 64x33x30 --report 0 --quiet -o "$work/bunny_overcast.prt.h5"
run "$BAKE" fiv "$BUNNY" --env "$work/bright_ground.exr" --shells 64x33x30 --report 0 --quiet -o "$work/bunny_bright.prt.h5"
CAMR="eye=34,24,0:at=0,0,0:fov=55"
ROW=(--instance 0,0,-8 --instance 0,0,0 --instance 0,0,8)
view "Paper's kind (Fig. 15): three bunnies in a row, overcast sky, overlap correction on (cone proxy)" "0.019 (Fig. 15, on)" "$images/overcast_on.png" \
  "$work/bunny_overcast.prt.h5" --camera "$CAMR" "${ROW[@]}" --samples "$RAYS" --reference-cache "$work/ref_overcast_$SIZE.exr"
view "Paper's kind (Fig. 15): overlap correction off (cone proxy)" "0.027 (Fig. 15, off)" "$images/overcast_off.png" \
  "$work/bunny_overcast.prt.h5" --camera "$CAMR" "${ROW[@]}" --no-overlap --samples "$RAYS" --reference-cache "$work/ref_overcast_$SIZE.exr"
view "Paper's kind (Fig. 15): overlap correction on (bounding sphere)" "0.019 (Fig. 15, on)" "$images/overcast_on_sphere.png" \
  "$work/bunny_overcast.prt.h5" --camera "$CAMR" "${ROW[@]}" --proxy sphere --samples "$RAYS" --reference-cache "$work/ref_overcast_$SIZE.exr"
view "Paper's kind (Fig. 15): overlap correction off (bounding sphere)" "0.027 (Fig. 15, off)" "$images/overcast_off_sphere.png" \
  "$work/bunny_overcast.prt.h5" --camera "$CAMR" "${ROW[@]}" --proxy sphere --no-overlap --samples "$RAYS" --reference-cache "$work/ref_overcast_$SIZE.exr"
view "Paper's kind (Fig. 17): bunny sunk 2 units, bright ground, partial-occluder correction on (cone proxy)" "0.019 (Fig. 17, on)" "$images/bright_on.png" \
  "$work/bunny_bright.prt.h5" --camera "$CAMP" "${SINK[@]}" --samples "$RAYS" --reference-cache "$work/ref_bright_$SIZE.exr"
view "Paper's kind (Fig. 17): partial-occluder correction off" "0.026 (Fig. 17, off)" "$images/bright_off.png" \
  "$work/bunny_bright.prt.h5" --camera "$CAMP" "${SINK[@]}" --no-partial --samples "$RAYS" --reference-cache "$work/ref_bright_$SIZE.exr"
view "Paper's kind (Fig. 17): factor (h+R)/2R on (bounding sphere)" "0.019 (Fig. 17, on)" "$images/bright_on_sphere.png" \
  "$work/bunny_bright.prt.h5" --camera "$CAMP" "${SINK[@]}" --proxy sphere --samples "$RAYS" --reference-cache "$work/ref_bright_$SIZE.exr"

# ---- the default scene: per-vertex transfer (orders 3 and 8) and band-1 under sunset.exr ----
run "$BAKE" vertex data/bunny_ground.obj --transfer 3 --radiance "$SUNSET" --report 0 --quiet -o "$work/default_t3.prt.h5"
run "$BAKE" vertex data/bunny_ground.obj --transfer 8 --report 0 --quiet -o "$work/default_t8.prt.h5"
CAMD="eye=4,16,28:at=0,3,0:fov=45"
view "Default scene (bunny_ground.obj, sunset.exr): transfer order 3" "-" "$images/default_transfer3.png" \
  "$work/default_t3.prt.h5" --env "$SUNSET" --shade transfer --camera "$CAMD" --samples "$RAYS" --reference-cache "$work/ref_default_$SIZE.exr"
view "Default scene: transfer order 8" "-" "$images/default_transfer8.png" \
  "$work/default_t8.prt.h5" --env "$SUNSET" --shade transfer --camera "$CAMD" --samples "$RAYS" --reference-cache "$work/ref_default_$SIZE.exr"
view "Default scene: band-1 radiance (exact at vertices)" "-" "$images/default_band1.png" \
  "$work/default_t3.prt.h5" --env "$SUNSET" --shade band1 --camera "$CAMD" --samples "$RAYS" --reference-cache "$work/ref_default_$SIZE.exr"

# ---- the first look: the same file with no --camera, --shade or --env: prtview shows the best it holds
# (band-1 radiance), framed without the ground, exposed for sunset.exr ----
view "Default scene, first look (no --camera, --shade or --env): band-1 radiance, framed on the bunny" "-" "$images/first_look.png" \
  "$work/default_t3.prt.h5" --samples "$RAYS"

# ---- a scene file (prtbake scene): every object in one z-buffer, each with its own products and albedo ----
run "$BAKE" scene data/scene_example.json --quiet -o "$work/scene.prt.h5"
view "Scene file (data/scene_example.json: ground, bunny, statue, spider), receivers" "-" "$images/scene_example.png" \
  "$work/scene.prt.h5" --camera "eye=0,17,27:at=0.5,1.5,-1:fov=52" --samples "$RAYS"

# ---- 50 dynamic occluders (issue 33): copies of three baked occluders (bunny, spider, statue) placed at
# run time (data/fiv_instances50.json), some on the ground, some floating; tight proxies, and the
# paper's spheres for comparison ----
run "$BAKE" scene data/scene_fiv_occluders.json --quiet -o "$work/fiv_occluders.prt.h5"
CAM50="eye=0,38,62:at=0,0,-2:fov=45"
view "50 dynamic occluders (3 kinds, data/fiv_instances50.json), cone proxy" "-" "$images/fiv50.png" \
  "$work/fiv_occluders.prt.h5" --instances data/fiv_instances50.json --camera "$CAM50" --samples "$RAYS" --reference-cache "$work/ref_fiv50_$SIZE.exr"
view "50 dynamic occluders, cone proxy, overlap correction off" "-" "$images/fiv50_no_overlap.png" \
  "$work/fiv_occluders.prt.h5" --instances data/fiv_instances50.json --camera "$CAM50" --no-overlap --samples "$RAYS" --reference-cache "$work/ref_fiv50_$SIZE.exr"
view "50 dynamic occluders, bounding spheres (paper 004)" "-" "$images/fiv50_sphere.png" \
  "$work/fiv_occluders.prt.h5" --instances data/fiv_instances50.json --camera "$CAM50" --proxy sphere --samples "$RAYS" --reference-cache "$work/ref_fiv50_$SIZE.exr"

seconds=$(($(date +%s) - start))
load_end=$(cut -d' ' -f1-3 /proc/loadavg)
{
  echo "# Figures: runtime shading against ray-traced ground truth"
  echo
  echo "Generated by \`bench/figures.sh$( ((quick)) && echo ' --quick')\` on $(date -u +%Y-%m-%d) in ${seconds} s"
  echo "($(nproc) cores, load average ${load_start} at start, ${load_end} at end; git $(git rev-parse --short HEAD))."
  echo "Do not edit by hand: rerun the script."
  echo
  echo "Each picture is a triptych, its panels labelled in the picture: **baked** (prtshade, what an engine"
  echo "shows) | **reference** (Embree ray tracing, same view, same exposure) | **error** (false colour of"
  echo "|runtime − reference|: black 0, pale yellow ≥ 10 % of the reference's range, grey = not compared;"
  echo "its colour scale under it). Under the panels: the RMSE and NRMSE of the picture, the exposure, and"
  echo "the file's own error report. Values are the outgoing radiance of a white diffuse surface, E/π,"
  echo "${SIZE} pixels. The exposure is fixed by the environment, not by the pixels: 1 / the brightest"
  echo "unshadowed white surface under it (\`prtview --help\`, OUTPUT), so the pictures of one environment"
  echo "compare by eye."
  echo
  echo "**NRMSE** = RMSE / (max − min of the reference) over the compared pixels and the three channels"
  echo "(paper 004 §5 reports NRMSE without printing its normalisation; this is the usual range-normalised"
  echo "one). FIV scenes compare the receiver (the ground plane, where the paper measures the shadow);"
  echo "the default scene compares every pixel that shows geometry. **NRMSE over every pixel** adds the"
  echo "pixels of the occluders themselves (their self-shadows; not noise-corrected). **Reference noise** is the reference's"
  echo "own standard error (RMS over the compared pixels, from 8 independent randomised-QMC replicates per"
  echo "pixel) divided by the same range; since E[RMSE²] = RMSE²_true + σ², **noise-corrected** is"
  echo "sqrt(RMSE² − σ²)/range, the error of the runtime alone. Reference rays per pixel: ${RAYS_FIG12}"
  echo "(Figure 12), ${RAYS} (the rest), on top of the exact unshadowed irradiance (bake/environment/irradiance.h)."
  echo
  echo "| experiment | NRMSE | reference noise | noise-corrected NRMSE | NRMSE over every pixel | paper 004 | image |"
  echo "|---|---|---|---|---|---|---|"
  printf '%s\n' "${rows[@]}"
  echo
  cat <<'NOTES'
## Reading the numbers

- **Figure 12.** The shells follow the surface (issue 33; prtshade/fiv.h "Surface-following
  shells"): each direction's samples start 0.005 R outside the bunny's outer surface along the
  ray and grow geometrically, so the contact shadow within the 0.07-unit gap is sampled where
  paper 004's spheres (~0.6 units apart there, their samples inside the bunny dropped, §4.3.2)
  could not; the error falls with resolution again (32x17x15, 64x33x30, 256x129x30). At equal
  memory the spheres' row (64x33x30, --radial geometric, same cone proxy) shows the gain. With the
  cone proxy the partial-occluder correction no longer scales the shadow down (the paper's
  (h + R)/2R did: 0.86 for every ground receiver); the diagnostic row without it is the same
  error. What is left at 64x33x30 is mostly the ears' thin shadows at 64x33 directions: the
  finer angular grid takes it further down.
- **The bunny's own pixels** (the column "over every pixel"): its self-shadows come from its
  band-1 radiance at its vertices, which `prtbake fiv` bakes by default (exact at the vertices).
  Eq. 12 from the shells (the diagnostic row, `--self-shadows shells`) needs the FIV just outside
  the surface, which surface-following shells hold only where the surface is the outermost along
  its ray from the centre: not on the ears' inner faces or in the concavities, which it draws
  black or blue. Under the bright ground (Fig. 17's kind) the bunny's own pixels are off by 0.15
  with either (0.148 from the vertices, 0.151 from the shells: the ground plane hides the bright
  lower sky from the bunny in the reference, and paper 004's model has no occluder for a receiver
  plane).
- **Figure 12 at the paper's memory.** prtbake stores the shells and cones in half floats by
  default (prtshade/fiv.h "Half-float tables"): each value moves by at most 2^-11 of itself, and
  the 64x33x30 float32 diagnostic row gives the same error as the half-float 64x33x30 row to the
  digits shown. In the paper's 2.17 MiB for 64x33x30 float32 shells, half floats hold 96x49x26
  shells, or 84x43x24 shells with their cone table; both rows are below 0.004. The DifMap is
  32x32 per face by default (bake/bake/fiv.h ShellSpec::cube): at 16 its bilinear lookup between
  the texels 1/16 off the zenith darkened every ground pixel by 0.4 % (a uniform bias, 0.0039 of
  NRMSE on its own, measured on the error image: the mean signed error equals its RMS far from
  the bunny), 0.1 % at 32.
- **Overlap correction (eq. 13-14) and the occluder proxy.** The paper's unit bounding discs are
  the bounding spheres (R = 6.64 for the 9.65 x 7.5 bunny): from the ground between two bunnies
  they overlap far more than the occluded parts of the sky do, and the correction adds back light
  that is blocked (the "bounding sphere" rows). The baked files carry a tight proxy (issue 33,
  prtshade/fiv.h "Tight proxies"): per shell sample the occluded solid angle and its mean
  direction, integrated exactly with the shells; its cap is the disc, and a pair of such caps adds
  back the lens times the lower of the two irradiance densities instead of eq. 14's area-weighted
  mean. With it the correction lowers the error on both the two bunnies under forest.exr and the
  paper's kind of scene (three bunnies whose cones overlap under an overcast sky).
- **Partial occluders.** The paper's (h + R)/2R scales the whole shadow by the bounding sphere's
  fraction above the plane, which both under forest.exr (dark below) and under a bright ground
  takes the wrong direction: n.F over the full sphere already counts the occluded light below the
  horizon negatively, so the true shadow is n.F plus that part. The cone proxy adds it back: the
  cap's part below the horizon (a closed-form clamped cosine) lit by the receiver's mean radiance
  from below, E_tot(-n)/pi from the DifMap — small under forest.exr, large under a bright ground
  (the paper's kind of scene, Fig. 17's chess queen).
- **50 dynamic occluders.** Copies of three baked occluders (20 bunnies, 15 spiders, 15 statues;
  data/fiv_instances50.json) placed at run time on one ground, 36 touching it and 14 floating:
  many overlapping shadows from occluders of three shapes. The paper's bounding spheres
  over-correct the overlaps (their discs cover far more sky than a spider's legs do); the cone
  proxy's caps follow the objects, and its overlap correction lowers the error a little more.
  Each copy's self-shadows come from its baked vertices (the scene file's
  /fiv/occluders/<name>/self_band1, `bake.fiv.self_shadows` "vertex" by default; issue 33): over
  every pixel 0.0179 with them against 0.0274 from the shells (eq. 12), the run before.
  The frame's cost at 1080p on one core is in bench/RESULTS.md ("50 dynamic occluders").
- **Default scene.** Order-3 transfer cannot hold sunset.exr's sun (a lobe 4,000x the mean):
  NRMSE 0.03, mostly in the contact and self-shadows; order 8 and band-1 radiance (exact at the
  vertices; what is left is Gouraud interpolation between vertices) are within 0.006-0.008.
- **First look.** `prtview FILE -o look.png` (here with `--triptych`) on the order-3 file, which
  also holds band-1 radiance: prtview shows band-1 radiance (the best it holds) and frames the
  bunny without the 30 x 30 ground (view/camera.h `focus_box`). Closer, the Gouraud interpolation
  of the contact shadow between the bunny's vertices takes more of the picture, hence a larger
  NRMSE than the same product seen from afar.

## Scene file

`prtbake scene data/scene_example.json` bakes what each object needs (README "Scene files"):
band-1 radiance for the diffuse ground and bunny, AO, visibility transfer and shadowed radiance
for the glossy statue, FIV shells for the occluders. prtview draws every object in one z-buffer,
each times its albedo: the ground, the bunny and the statue with shade_band1 (the statue's
band-1 radiance is band 1 of its shadowed radiance S, the same integrals: its diffuse response
with exact shadows; its glossy lobe is drawn by `prtview --shade glossy`, bench/RESULTS.md
"Glossy shading"), the spider (occluder only, no per-vertex data) with its FIV self-shadows.
The reference traces the same objects: the bunny, statue and spider cast shadows, the ground
("receiver") does not. The NRMSE compares the receivers (ground, bunny, statue); prtview also
prints each one's share (its RMSE over the same range). The error is the Gouraud interpolation
of the contact shadows across the ground's 1.7-unit cells (under the bunny and the statue's
feet) and of the statue's sun shadows between its vertices.

NOTES
  echo
  for img in "${pictures[@]}"; do
    echo "![${img%.png}](images/$img)"
    echo
  done
  echo "## Commands"
  echo
  echo '```sh'
  printf '%s\n' "${cmds[@]}"
  echo '```'
} >"$md"
echo "wrote $md (${seconds} s)"
