// Lightmap images from texel rows (bake/bake/lightmap.h): rows placed at their texels, padding
// rings with the mean of their known neighbours (exact values), invalid texels filled from their
// own chart only, and the image full after enough padding.
#include <bake/bake/lightmap.h>
#include <bake/mesh/mesh.h>
#include <bake/mesh/texels.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

using namespace prt::bake;
using Eigen::Vector2f;

namespace {

// The unit square (two triangles) with UVs scaled by s: at 8 × 8 texels and s = ½ it covers
// texels x, y <= 4 (bake/mesh/texels.h: conservative).
struct Square {
  Mesh mesh = make_mesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {{{0, 1, 2}}, {{0, 2, 3}}}, "square");
  UvSet uv;
  explicit Square(float s, float second = 1) {
    uv.name = "uv";
    for (size_t t = 0; t < 2; ++t)
      for (uint32_t v : mesh.triangles[t])
        uv.corners.emplace_back((t == 1 ? second : 1.0f) * s * mesh.positions[v].x(),
                                (t == 1 ? second : 1.0f) * s * mesh.positions[v].y());
  }
  TexelAtlas atlas(uint32_t n) const { return texel_atlas(mesh, build_topology(mesh), uv, n, n, "square"); }
};

} // namespace

TEST(Lightmap, RowsLandOnTheirTexelsAndPaddingRingsTakeTheirNeighboursMean) {
  const Square sq(0.5f);
  const TexelAtlas a = sq.atlas(8);
  ASSERT_EQ(a.samples.size(), 25u);
  std::vector<double> rows;
  for (const TexelSample& s : a.samples) rows.push_back(double(s.texel));  // each texel's own index
  const Lightmap none = make_lightmap(a, rows, 1, {}, 0);
  for (const TexelSample& s : a.samples) {
    EXPECT_EQ(none.values[s.texel], double(s.texel));
    EXPECT_EQ(none.state[s.texel], uint8_t(TexelState::Baked));
  }
  EXPECT_EQ(none.padded, 0u);

  const Lightmap one = make_lightmap(a, rows, 1, {}, 1);
  // Ring 1: x or y = 5, both <= 5: 11 texels.
  EXPECT_EQ(one.padded, 11u);
  // (5, 5) has one known neighbour, (4, 4) = texel 36; (5, 0) has (4, 0) and (4, 1): texels 4 and 12.
  EXPECT_EQ(one.values[5 * 8 + 5], 36.0);
  EXPECT_EQ(one.values[0 * 8 + 5], (4.0 + 12.0) / 2);
  EXPECT_EQ(one.state[6 * 8 + 6], uint8_t(TexelState::Empty)) << "one ring only";

  const Lightmap all = make_lightmap(a, rows, 1, {}, 8);
  for (uint8_t s : all.state) EXPECT_NE(s, uint8_t(TexelState::Empty));
  EXPECT_EQ(all.padded, 64u - 25u);
}

TEST(Lightmap, InvalidTexelsAreFilledFromTheirOwnChartOnly) {
  // Two charts: triangle 0 at full scale, triangle 1 moved by scaling its UVs by 0.5 (a seam on
  // the diagonal); at 8 × 8 texels they overlap in UV space near the origin, where texels belong to
  // the first triangle that contains the centre.
  const Square sq(1, 0.5f);
  const TexelAtlas a = sq.atlas(8);
  ASSERT_EQ(a.charts, 2u);
  std::vector<double> rows;
  std::vector<uint8_t> invalid;
  for (const TexelSample& s : a.samples) {
    rows.push_back(s.chart == 0 ? 10.0 : 20.0);
    invalid.push_back(0);
  }
  // Invalidate one texel of each chart that has both charts among its neighbours.
  size_t marked = 0;
  for (size_t i = 0; i < a.samples.size() && marked < 2; ++i) {
    const uint32_t x = a.samples[i].texel % 8, y = a.samples[i].texel / 8;
    if (x > 0 && y > 0 && x < 7 && y < 7 && (marked == 0 ? a.samples[i].chart == 0 : a.samples[i].chart == 1)) {
      invalid[i] = 1;
      rows[i] = -1;  // the enclosed row: never to be seen
      ++marked;
    }
  }
  ASSERT_EQ(marked, 2u);
  const Lightmap m = make_lightmap(a, rows, 1, invalid, 0);
  EXPECT_EQ(m.filled, 2u);
  for (size_t i = 0; i < a.samples.size(); ++i) {
    if (!invalid[i]) continue;
    EXPECT_EQ(m.values[a.samples[i].texel], a.samples[i].chart == 0 ? 10.0 : 20.0) << "filled from its own chart";
  }
}

TEST(Lightmap, SeamStitchMakesBothSidesOfASeamAgree) {
  // A unit square of two triangles whose UVs are cut along the diagonal: triangle 0 in the atlas's
  // left half, triangle 1 in its right half (rotated), 2 texels apart. Each baked texel holds
  // f(p) = 1 + p.x + 2 p.y² at its sample (smooth over the continuous square). Bilinear lookups
  // along the diagonal from the two sides differ (each side's footprint reaches its padding,
  // which holds its chart's mean beside it); stitching must bring them together: the mean
  // |difference| falls at least tenfold, and a baked texel moves less than the largest difference
  // before (it only shares the seam's correction).
  const Mesh square = make_mesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {{{0, 1, 2}}, {{0, 2, 3}}}, "square");
  const Topology topo = build_topology(square);
  UvSet uv;
  uv.name = "cut";
  // Triangle 0 (0,0)-(1,0)-(1,1) at u in [0.05, 0.45]; triangle 1 (0,0)-(1,1)-(0,1) at u in [0.55, 0.95], mirrored.
  uv.corners = {{0.05f, 0.05f}, {0.45f, 0.05f}, {0.45f, 0.45f}, {0.55f, 0.05f}, {0.95f, 0.45f}, {0.55f, 0.45f}};
  const TexelAtlas atlas = texel_atlas(square, topo, uv, 40, 40, "square");
  ASSERT_EQ(atlas.charts, 2u);
  std::vector<double> rows;
  for (const ShadePoint& p : atlas.receivers.points) rows.push_back(1 + p.p.x() + 2 * p.p.y() * p.p.y());
  Lightmap image = make_lightmap(atlas, rows, 1, {}, 2);
  const Lightmap before = image;
  const SeamStitch s = stitch_seams(image, atlas, square, topo, uv);
  EXPECT_EQ(s.edges, 1u);
  EXPECT_GT(s.points, 20u);  // ~2 per texel along a diagonal ~23 texels long
  EXPECT_EQ(s.skipped_points, 0u);
  EXPECT_GT(s.mean_before, 0.0);
  EXPECT_LT(s.mean_after, s.mean_before / 10);
  EXPECT_LT(s.baked_moved_max, s.max_before);
  // Nothing but the seam's texels moved.
  size_t moved = 0;
  for (size_t k = 0; k < image.values.size(); ++k) moved += image.values[k] != before.values[k];
  EXPECT_LE(moved, s.texels);
  EXPECT_GT(moved, 0u);
}

TEST(Lightmap, MipLevelsUpToThreeReachNoEmptyTexelWithTheDefaultPadding) {
  // The square's chart covers texels 0..16 of a 64² atlas (UVs scaled by ¼). At mip level 3 a
  // texel is an 8 × 8 block; the chart's edge at u = ¼ (x = 16) is looked up at level-3
  // coordinate 16/8 − ½ = 1.5, half in block 2 (x 16..23). With 2 rings of padding block 2 still
  // holds empty texels (x 19..23), so the edge's points reach an empty texel at levels 2 and 3;
  // with kDefaultPadding (16) every block those lookups touch is full, at every level 0–3.
  const Square sq(0.25f);
  const TexelAtlas a = sq.atlas(64);
  const std::vector<double> rows(a.samples.size(), 0.5);
  const auto thin = mip_empty_hits(make_lightmap(a, rows, 1, {}, 2), a, sq.uv);
  EXPECT_EQ(thin[0], 0u) << "two rings suffice at level 0";
  EXPECT_GT(thin[3], 0u) << "the premise: two rings do not suffice at level 3";
  const auto full = mip_empty_hits(make_lightmap(a, rows, 1, {}, kDefaultPadding), a, sq.uv);
  for (int k = 0; k <= kMipLevels; ++k) EXPECT_EQ(full[size_t(k)], 0u) << "level " << k;
}

TEST(Lightmap, AnInvalidTexelItsChartCannotFillIsPaddedFromItsNeighbours) {
  // Both charts of the diagonal square, every texel of chart 1 invalid (a chart wholly inside the
  // geometry): nothing of its own chart can fill them. Without padding they stay empty (0); with
  // it they are padded from chart 0 around them, so no lookup or mip level reads an empty texel.
  const Square sq(1, 0.5f);
  const TexelAtlas a = sq.atlas(8);
  std::vector<double> rows;
  std::vector<uint8_t> invalid;
  for (const TexelSample& s : a.samples) rows.push_back(10.0), invalid.push_back(s.chart == 1 ? 1 : 0);
  const size_t chart1 = size_t(std::count(invalid.begin(), invalid.end(), uint8_t(1)));
  ASSERT_GT(chart1, 0u);
  const Lightmap bare = make_lightmap(a, rows, 1, invalid, 0);
  EXPECT_EQ(bare.unfilled, chart1);
  const Lightmap padded = make_lightmap(a, rows, 1, invalid, kDefaultPadding);
  EXPECT_EQ(padded.unfilled, chart1) << "counted as before";
  for (size_t i = 0; i < a.samples.size(); ++i) {
    if (!invalid[i]) continue;
    EXPECT_EQ(bare.state[a.samples[i].texel], uint8_t(TexelState::Empty));
    EXPECT_EQ(padded.state[a.samples[i].texel], uint8_t(TexelState::Padded));
    EXPECT_EQ(padded.values[a.samples[i].texel], 10.0);
  }
}
