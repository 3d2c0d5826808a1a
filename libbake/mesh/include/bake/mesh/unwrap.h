// bake/mesh/unwrap.h — a lightmap UV set generated for a mesh that has none, or to replace a bad
// one (issue 30, "Lightmap UVs"; docs/ARCHITECTURE.md §2, the mesh module's UV sets and texels).
// The result is an ordinary UvSet (bake/mesh/mesh.h), baked through bake/mesh/texels.h like an
// asset's own set. Three steps, all single-threaded and deterministic (the same mesh and options
// give the same bytes on any machine and thread count):
//
// 1. CHARTS (segmentation). Triangles of zero area (their double cross product is 0) are
//    DEGENERATE: they get all three UVs at (0, 0), cover no texel and are counted, never dropped.
//    Two triangles are NEIGHBOURS across a welded edge (Topology) when the edge has exactly these
//    two faces, they traverse it in opposite directions (consistent winding) and their unit
//    normals differ by at most `hard_edge_degrees` (otherwise it is a hard edge, a boundary, a
//    non-manifold edge or a fold: a chart border). Charts grow from seeds, the lowest-numbered
//    unassigned triangle first, over neighbours, flattest first (a priority queue on n·n_seed,
//    ties to the lower triangle), taking only triangles whose normal lies within
//    `cone_degrees` of the seed's: a chart is a height field over its seed's plane, so it can be
//    flattened without folds and with bounded stretch. On a noisy surface (a scan) the cone's
//    limit runs through single triangles, leaving spikes and one-triangle holes; 4 synchronous
//    smoothing passes move a triangle two of whose neighbours lie in another chart into that
//    chart when its normal is within 85° of that chart's seed, and the charts are then cut into
//    their connected parts (numbered by lowest triangle).
// 2. FLATTENING per chart, in world units (chart-local vertices: the chart's copy of each welded
//    position). One triangle: its own plane, exact. A planar chart (every normal within 1e-9 of
//    the seed's in cosine): orthogonal projection onto that plane, exact. Otherwise LSCM — least
//    squares conformal maps (B. Lévy, S. Petitjean, N. Ray, J. Maillot, "Least Squares Conformal
//    Maps for Automatic Texture Atlas Generation", SIGGRAPH 2002, its conformality criterion):
//    on each triangle, in its own orthonormal frame (x along its first edge, y = n × x), the
//    linear map (u, v) is conformal when ∇v = R90 ∇u (Cauchy–Riemann; R90 the +90° rotation,
//    which also makes the map keep the triangle's winding); with ∇φ_j = R90 e_j / (2A) (e_j the edge opposite corner
//    j, counter-clockwise) the residual is r_T = Σ_j (u_j e_j + v_j R90 e_j) / (2A) and the energy
//    Σ_T A_T |r_T|² = Σ_T |Σ_j u_j e_j + v_j R90 e_j|² / (4 A_T). The two chart vertices found by
//    two farthest-point sweeps are pinned at (0, 0) and (d, 0), d their distance; the normal
//    equations of the rest are solved by Eigen::SimplicialLDLT. A chart is ACCEPTED when every
//    triangle's UV signed area is > 0 and no two of its boundary edges that share no vertex meet
//    (double arithmetic; a chart that fails either — a fold, a flip, a boundary overlapping
//    itself — or whose solve fails is SPLIT in two at the median of its triangles' centroids
//    along its longest axis, into connected parts, and each part is flattened again; one triangle
//    always succeeds). Each chart is then scaled so that its UV area equals its surface area, and
//    one whose largest triangle stretch (REPORT below) exceeds 2 is split the same way: LSCM is
//    conformal but lets area drift along a long curved chart.
// 3. PACKING at one density s (texels per world unit) with gutters in texels. Each chart is
//    rotated to its minimal-area bounding rectangle (over the edges of its convex hull; turned
//    by 90° to lie wide). With min_chart_texels = M > 0 a chart whose short side is under M
//    texels at s gets its own density min(M / short side, 4·s) (a fin's rim gets texels of its
//    own instead of sharing them with its neighbours: the engine's per-texel AO NRMSE 0.042 →
//    0.011 at M = 3, bench/RESULTS.md); below, s is the chart's density. Each chart is
//    given a box of whole texels: w = floor(s·width + 2·m) + 1 (m = 1/64
//    texel), likewise h, the chart centred in it, so it lies strictly inside its box and its float
//    UVs cannot reach the next texel. Its FOOTPRINT is the texels it touches, as texel_atlas
//    (bake/mesh/texels.h) counts them, each texel square widened by 1/128 texel (more than the
//    float rounding of a UV at 16384 texels): per column of the box its first and last row, per
//    row its first and last column (in double, per triangle over each column's and row's slab).
//    HORIZON PACKING: charts by box area (largest first, then chart order); each is
//    tried in 4 rotations (multiples of 90°, windings kept) at every integer column x, resting on
//    the horizon — per atlas column one past the lowest texel taken — with its column profile's
//    top dilated by G (over the G columns on either side, less G rows); it goes where its lowest
//    texel ends highest (then leftmost, then the first rotation). So at least G empty texels lie
//    between the texels of two charts (Chebyshev distance > G), and G/2 (G − G/2 at the far
//    sides) between a chart and the atlas border, so a REPEAT sampler does not mix charts either.
//    With a given W × H the largest density that packs is found by bisection (40 steps from
//    sqrt(W·H / surface area), which no packing reaches); with a given density the atlas is the
//    smallest square whose side is a multiple of 4 (block-compression friendly) that packs,
//    found by bisection, at most max_side. UV = texel position / W (/ H), stored as float; v is
//    glTF's (row 0 of the image at v = 0). Charts under another's overhang are not nested: the
//    packing fills about 60% of the atlas with footprints on a scanned mesh (bench/RESULTS.md).
//
// REPORT (UnwrapReport): the chart count (degenerate triangles apart), the density, the
// utilisation Σ chart UV areas / (W·H) (geometric, in texels: the fraction of the atlas that the
// surface covers), and stretch per triangle as P. Sander, J. Snyder, S. Gortler, H. Hoppe,
// "Texture Mapping Progressive Meshes" (SIGGRAPH 2001) define it: for the map S from texture
// (UV in world units, i.e. texels / s) to surface, L2 = sqrt((|S_u|² + |S_v|²) / 2), 1 for an
// isometry, > 1 where the surface gets fewer texels than the density promises; worst = max over
// triangles with area, mean = the area-weighted RMS (Sander's L2 norm). Time is wall time.
//
// ERRORS: InputError(mesh.source, ...) when both or neither of W × H and density are given, a
// side is outside 1..max_side, the density is not finite and > 0, every triangle is degenerate,
// the charts do not fit even at the smallest density (each needs (1 + G)² texels), or the
// density needs an atlas larger than max_side (the message says the largest density that fits).
// Memory O(triangles); time O(T log T) for charts and packing plus the sparse solves.
#pragma once

#include <bake/mesh/mesh.h>

#include <cstddef>
#include <cstdint>
#include <string>

namespace prt::bake {

struct UnwrapOptions {
  uint32_t width = 0, height = 0;  // the atlas in texels; 0 × 0: chosen from `density`
  double density = 0;              // texels per world unit; used when width = height = 0
  uint32_t gutter = 2;             // G: empty texels between two charts
  // M > 0: a chart narrower than M texels across (its short side at the atlas's density) gets its
  // own density, enough for M texels across, at most 4× the atlas's: a fin's rim or a knob's ring
  // gets texels of its own instead of sharing one with its neighbours. 0: one density for all.
  uint32_t min_chart_texels = 0;
  uint32_t max_side = 16384;       // the largest atlas side accepted or chosen
  double hard_edge_degrees = 50;   // neighbours' normals differ by at most this
  double cone_degrees = 65;        // every normal of a chart within this of its seed's
  std::string name = "prtbake_lightmap";
};

struct UnwrapReport {
  uint32_t width = 0, height = 0;
  double density = 0;                 // s, texels per world unit
  size_t charts = 0;                  // charts with area
  size_t degenerate_triangles = 0;    // UVs at (0, 0)
  size_t planar_charts = 0, lscm_charts = 0, single_triangle_charts = 0;
  size_t splits = 0;                  // charts split: their flattening folded, failed or stretched
  size_t stretch_splits = 0;          // of those, because a triangle's L2 stretch exceeded 2
  size_t scaled_charts = 0;           // charts given more than `density` (min_chart_texels)
  double utilisation = 0;             // Σ chart UV area / (W·H)
  double worst_stretch = 1, mean_stretch = 1;  // Sander's L2 (file comment)
  double seconds = 0;                 // wall time of unwrap()
};

struct Unwrapped {
  UvSet uv;  // options.name, 3 corners per triangle
  UnwrapReport report;
};

Unwrapped unwrap(const Mesh& mesh, const Topology& topology, const UnwrapOptions& options);

} // namespace prt::bake
