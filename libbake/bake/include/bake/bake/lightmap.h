// bake/bake/lightmap.h — a lightmap image from the baked rows of an atlas's texels (bake/mesh/
// texels.h; issue 30): the rows placed at their texels, invalid texels (inside the geometry,
// bake/visibility/enclosure.h) filled from their chart's valid neighbours, and every chart
// dilated into its gutter so that bilinear filtering and mipmaps never sample an empty texel.
//
// Both steps run in synchronous rounds over the 8-neighbourhood (each round reads only the
// previous round's texels, so the result does not depend on the order of the scan):
//   fill     an invalid texel with at least one known neighbour of ITS chart (baked, or filled in
//            an earlier round) takes their mean; until a round fills nothing. An invalid texel
//            that no valid texel of its chart reaches is counted (`unfilled`) and left to the
//            padding below, as an empty texel (0 without padding).
//   padding  every empty texel within `padding` rings of a chart's texels (Chebyshev distance over
//            the 8-neighbourhood, counted from the covered texels, baked or not), and the unfilled
//            invalid texels, in rounds: one with known neighbours (baked, filled or padded
//            earlier) takes the mean of those of the lowest-numbered chart among them and joins
//            that chart, so a gutter between two charts is split between them, never mixed.
#pragma once

#include <bake/bake/vertex_bake.h>
#include <bake/mesh/texels.h>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace prt::bake {

enum class TexelState : uint8_t { Empty = 0, Baked = 1, Filled = 2, Padded = 3 };

struct Lightmap {
  uint32_t width = 0, height = 0, channels = 0;
  std::vector<double> values;   // [height][width][channels]; 0 where empty
  std::vector<uint8_t> state;   // [height][width] TexelState
  std::vector<uint32_t> chart;  // [height][width]; kNoChart where empty
  size_t filled = 0, padded = 0, unfilled = 0;
  static constexpr uint32_t kNoChart = 0xffffffffu;
};

// The bilinear lookup at UV (u, v) of a width × height image (formats/SCHEMA.md's rule: texel
// coordinates (u·W − ½, v·H − ½)): four texels (row-major indices) and their weights, clamped to
// the image. The runtime's filtering, and what a bounce reads at a hit (bake/bake/bounce.h).
struct BilinearLookup {
  std::array<size_t, 4> texel{};
  std::array<double, 4> weight{};
};
BilinearLookup bilinear_lookup(double u, double v, size_t width, size_t height);

// Seams (issue 30: "texels on the two sides of a UV seam must agree where the surface is
// continuous"). A seam edge is an edge two triangles share through welded corners whose UVs differ
// on the two sides (a cut of the UV set over a continuous surface). Along it, k points (about two
// per texel of its longer image) are looked up bilinearly from both sides (SCHEMA.md's rule: texel
// coordinates (u·W − ½, v·H − ½)); the texels those lookups touch are moved by least squares,
//   minimise Σ_points Σ_channels (L_side0(x) − L_side1(x))² + Σ_touched λ_t² (x − x_baked)²,
// the normal equations (AᵀA + Λ²) x = Λ² x_baked solved once (Eigen's SimplicialLDLT) for every
// channel. λ_t = kSeamLambda for a texel baked at its centre (the exact surface value there), a
// tenth of it for one baked at the nearest point of a chart border (a value from elsewhere, which
// bilinear filtering takes for its centre's) and for a filled or padded one (its chart's mean
// beside it): those follow the seam. Measured at 256², AO (`prtbake texel MESH --resolution 256
// --ao --integrator silhouette --samples 16384`): the bunny's 453 seam edges (generated UVs), mean
// |difference| 1.2e-2 → 1.0e-3 (largest 0.33 → 0.06), a texel baked at its centre moved by 0.10 at
// most; wuson's 997 (--unwrap) 3.9e-2 → 2.7e-3 (0.90 → 0.17), 0.24 at most — where a seam
// crosses AO that changes within a texel, the two sides cannot both be right.
// Only points whose four texels on each side are all baked, filled or padded AND of that side's
// chart are used (a point reaching an empty texel or another chart's — charts closer than two
// texels — is counted, not used: moving a third chart's texel to mend a seam it is not on would
// break it). Hard edges (the two sides' normals differ) are creases of the shading, not seams,
// and are left alone.
struct SeamStitch {
  size_t edges = 0, points = 0, skipped_points = 0, texels = 0;
  double mean_before = 0, max_before = 0, mean_after = 0, max_after = 0;  // |L0 − L1| over points and channels
  double baked_moved_max = 0;  // the most a texel baked at its centre moved
};
constexpr double kSeamLambda = 1;
SeamStitch stitch_seams(Lightmap& image, const TexelAtlas& atlas, const Mesh& mesh, const Topology& topology,
                        const UvSet& uv, double lambda = kSeamLambda);

// Mip levels (issue 30: "no empty texel reached by bilinear filtering at mip levels 0–3"): level
// k halves level k − 1 (sides rounded up), each texel the 2 × 2 box of the level below, so a
// level-k texel holds the 2^k × 2^k texels of level 0 it covers and is EMPTY when any of them is.
// For every point of the surface the atlas samples (each covered texel's sample, and each
// triangle's corners, in UV), the bilinear lookup at level k (SCHEMA's rule at that level's size)
// is made, and points whose footprint gives weight > 0 to an empty level-k texel are counted,
// per level 0 … kMipLevels. Padding (make_lightmap) of at least 2^(k+1) rings keeps level k clean
// wherever the atlas has room (the default kDefaultPadding covers levels 0–3).
inline constexpr int kMipLevels = 3;
inline constexpr uint32_t kDefaultPadding = 16;
std::array<size_t, kMipLevels + 1> mip_empty_hits(const Lightmap& image, const TexelAtlas& atlas, const UvSet& uv);

// `rows`: one row of `channels` values per atlas sample (the pipeline's rows of atlas.receivers);
// `invalid`: one flag per sample (empty: none). Throws ContractError on sizes that disagree.
Lightmap make_lightmap(const TexelAtlas& atlas, std::span<const double> rows, size_t channels,
                       std::span<const uint8_t> invalid, uint32_t padding);

} // namespace prt::bake
