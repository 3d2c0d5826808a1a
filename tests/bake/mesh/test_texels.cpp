// The texels of a lightmap as receivers (bake/mesh/texels.h): conservative coverage, the sample
// at the texel centre or at the nearest point of a covering triangle, shade points on the surface
// interpolated in double, rows in texel order, and bad atlases refused.
#include <bake/core/error.h>
#include <bake/mesh/mesh.h>
#include <bake/mesh/texels.h>

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace prt::bake;
using Eigen::Vector2f;
using Eigen::Vector3d;
using Eigen::Vector3f;

namespace {

// The unit square in the plane z = 0 (normal +z), two triangles, with UVs (s·x, s·y).
Mesh square(float s, UvSet& uv) {
  Mesh m = make_mesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {{{0, 1, 2}}, {{0, 2, 3}}}, "square");
  uv.name = "uv";
  uv.corners.clear();
  for (const auto& t : m.triangles)
    for (uint32_t v : t) uv.corners.emplace_back(s * m.positions[v].x(), s * m.positions[v].y());
  m.uv_sets = {uv};
  return m;
}

} // namespace

TEST(Texels, ASquareFillingTheAtlasGetsEveryCentre) {
  UvSet uv;
  const Mesh m = square(1, uv);
  const TexelAtlas a = texel_atlas(m, build_topology(m), uv, 4, 4, "square");
  ASSERT_EQ(a.samples.size(), 16u);
  EXPECT_EQ(a.texels_off_centre(), 0u);
  EXPECT_STREQ(a.receivers.rows_noun, "texels");
  ASSERT_EQ(a.receivers.points.size(), 16u);
  for (size_t i = 0; i < 16; ++i) {
    EXPECT_EQ(a.samples[i].texel, i) << "rows in texel order";
    EXPECT_EQ(a.coverage[i], 1);
    // Texel (x, y) is centred at ((x + ½)/4, (y + ½)/4): the surface point there, to rounding
    // (positions interpolated in double from floats that hold these values exactly).
    const ShadePoint& p = a.receivers.points[i];
    EXPECT_NEAR(p.p.x(), (double(i % 4) + 0.5) / 4, 1e-15) << i;
    EXPECT_NEAR(p.p.y(), (double(i / 4) + 0.5) / 4, 1e-15) << i;
    EXPECT_EQ(p.p.z(), 0.0);
    EXPECT_NEAR(p.n.z(), 1.0, 1e-15);
    EXPECT_EQ(p.welded, -1) << "a texel point is a free point of the surface";
  }
}

TEST(Texels, CoverageIsConservativeAndOffCentreSamplesLieOnTheTriangle) {
  UvSet uv;
  const Mesh m = square(0.5f, uv);  // UVs fill [0, ½]²: texels 0..3 of an 8 × 8 atlas, plus those touching
  const TexelAtlas a = texel_atlas(m, build_topology(m), uv, 8, 8, "half");
  // Texels x, y in 0..4 meet the closed square [0, 4]²: the 4 × 4 with their centres inside and
  // the 9 of row 4 and column 4, which touch its edges.
  EXPECT_EQ(a.samples.size(), 25u);
  EXPECT_EQ(a.texels_off_centre(), 9u);
  for (size_t i = 0; i < a.samples.size(); ++i) {
    const TexelSample& s = a.samples[i];
    const uint32_t x = s.texel % 8, y = s.texel / 8;
    EXPECT_LE(x, 4u);
    EXPECT_LE(y, 4u);
    EXPECT_EQ(s.centre, x < 4 && y < 4) << x << "," << y;
    EXPECT_GE(s.barycentric.minCoeff(), 0.0);
    EXPECT_NEAR(s.barycentric.sum(), 1.0, 1e-15);
    // The surface point is the centre clamped onto the square: (min(x + ½, 4) / 8 · 2, ...).
    const ShadePoint& p = a.receivers.points[i];
    EXPECT_NEAR(p.p.x(), std::min(double(x) + 0.5, 4.0) / 4, 1e-15) << x << "," << y;
    EXPECT_NEAR(p.p.y(), std::min(double(y) + 0.5, 4.0) / 4, 1e-15) << x << "," << y;
  }
  size_t covered = 0;
  for (uint8_t c : a.coverage) covered += c;
  EXPECT_EQ(covered, 25u);
}

TEST(Texels, ANeedleInsideOneTexelGetsThatTexel) {
  // A needle triangle whose UV image lies inside texel (2, 1) of a 4 × 4 atlas without its centre.
  Mesh m = make_mesh({{0, 0, 0}, {1, 0, 0}, {0, 0.01f, 0}}, {{{0, 1, 2}}}, "needle");
  UvSet uv{"uv", {Vector2f(0.51f, 0.26f), Vector2f(0.56f, 0.26f), Vector2f(0.51f, 0.262f)}};
  const TexelAtlas a = texel_atlas(m, build_topology(m), uv, 4, 4, "needle");
  ASSERT_EQ(a.samples.size(), 1u);
  EXPECT_EQ(a.samples[0].texel, 1u * 4 + 2);
  EXPECT_FALSE(a.samples[0].centre);
  // Its nearest point to the centre (2.5, 1.5) is the needle's corner nearest to it, (0.56·4, 0.262·4)
  // or on its long edge: on the surface in any case, inside the triangle's bounds.
  const ShadePoint& p = a.receivers.points[0];
  EXPECT_GE(p.p.x(), 0.0);
  EXPECT_LE(p.p.x(), 1.0);
  EXPECT_GE(p.p.y(), 0.0);
  EXPECT_LE(p.p.y(), 0.01 + 1e-9);
  EXPECT_EQ(p.p.z(), 0.0);
}

TEST(Texels, BadAtlasesAreRefusedNamingTheProblem) {
  UvSet uv;
  const Mesh m = square(1, uv);
  EXPECT_THROW(texel_atlas(m, build_topology(m), uv, 0, 4, "x"), InputError);
  EXPECT_THROW(texel_atlas(m, build_topology(m), uv, 4, 1 << 20, "x"), InputError);
  UvSet short_set = uv;
  short_set.corners.pop_back();
  try {
    texel_atlas(m, build_topology(m), short_set, 4, 4, "x");
    ADD_FAILURE() << "a UV set of the wrong size accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("5 corners for 2 triangles"), std::string::npos) << e.what();
  }
  UvSet nan_set = uv;
  nan_set.corners[4].x() = std::nanf("");
  EXPECT_THROW(texel_atlas(m, build_topology(m), nan_set, 4, 4, "x"), InputError);
  // UVs outside [0, 1] cover nothing there; a square at [2, 3]² covers no texel at all.
  UvSet away = uv;
  for (Vector2f& c : away.corners) c += Vector2f(2, 2);
  EXPECT_TRUE(texel_atlas(m, build_topology(m), away, 4, 4, "away").samples.empty());
}

TEST(Texels, ChartsJoinTrianglesWhoseSharedEdgeHasTheSameUvs) {
  UvSet uv;
  const Mesh m = square(1, uv);
  const TexelAtlas one = texel_atlas(m, build_topology(m), uv, 4, 4, "one chart");
  EXPECT_EQ(one.charts, 1u);
  for (const TexelSample& s : one.samples) EXPECT_EQ(s.chart, 0u);
  // The second triangle moved in UV space: the diagonal is a seam, two charts.
  UvSet cut = uv;
  for (size_t c = 3; c < 6; ++c) cut.corners[c] = 0.5f * cut.corners[c];
  const TexelAtlas two = texel_atlas(m, build_topology(m), cut, 4, 4, "two charts");
  EXPECT_EQ(two.charts, 2u);
  bool saw[2] = {false, false};
  for (const TexelSample& s : two.samples) {
    saw[s.chart] = true;
    EXPECT_EQ(s.chart, s.triangle);
  }
  EXPECT_TRUE(saw[0] && saw[1]);
}

TEST(Texels, OverlappingChartsAndSharedTexelsAreCounted) {
  // Two separate triangles (two charts) mapped onto the same UV triangle (0, 0), (1, 0), (0, 1)
  // of a 4 × 4 atlas: centres with x + y <= 3 (texel units, 10 texels) lie in both; texels whose
  // closed squares meet it, x + y <= 4 (13 texels), are touched by both.
  Mesh m = make_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {5, 0, 0}, {6, 0, 0}, {5, 1, 0}}, {{{0, 1, 2}}, {{3, 4, 5}}}, "two");
  UvSet uv{"uv", {Vector2f(0, 0), Vector2f(1, 0), Vector2f(0, 1), Vector2f(0, 0), Vector2f(1, 0), Vector2f(0, 1)}};
  const TexelAtlas a = texel_atlas(m, build_topology(m), uv, 4, 4, "two");
  EXPECT_EQ(a.charts, 2u);
  EXPECT_EQ(a.overlapping_texels, 10u);
  EXPECT_EQ(a.shared_texels, 13u);
  for (const TexelSample& s : a.samples) EXPECT_EQ(s.triangle, 0u) << "ties keep the first triangle";
  // One chart alone: neither.
  UvSet one = uv;
  for (size_t c = 3; c < 6; ++c) one.corners[c] += Vector2f(5, 5);  // outside the atlas
  const TexelAtlas b = texel_atlas(m, build_topology(m), one, 4, 4, "one");
  EXPECT_EQ(b.overlapping_texels, 0u);
  EXPECT_EQ(b.shared_texels, 0u);
}
