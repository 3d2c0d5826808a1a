// bake/bake/lightmap.h — a lightmap image from the baked rows of an atlas's texels (bake/mesh/
// texels.h; issue 30): the rows placed at their texels, invalid texels (inside the geometry,
// bake/visibility/enclosure.h) filled from their chart's valid neighbours, and every chart
// dilated into its gutter so that bilinear filtering and mipmaps never sample an empty texel.
//
// Both steps run in synchronous rounds over the 8-neighbourhood (each round reads only the
// previous round's texels, so the result does not depend on the order of the scan):
//   fill     an invalid texel with at least one known neighbour of ITS chart (baked, or filled in
//            an earlier round) takes their mean; until a round fills nothing. An invalid texel
//            that no valid texel of its chart reaches keeps 0 and is counted (`unfilled`).
//   padding  `padding` rounds: an empty texel with known neighbours (baked, filled or padded
//            earlier) takes the mean of those of the lowest-numbered chart among them and joins
//            that chart, so a gutter between two charts is split between them, never mixed.
#pragma once

#include <bake/bake/vertex_bake.h>
#include <bake/mesh/texels.h>

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

// `rows`: one row of `channels` values per atlas sample (the pipeline's rows of atlas.receivers);
// `invalid`: one flag per sample (empty: none). Throws ContractError on sizes that disagree.
Lightmap make_lightmap(const TexelAtlas& atlas, std::span<const double> rows, size_t channels,
                       std::span<const uint8_t> invalid, uint32_t padding);

} // namespace prt::bake
