// The generated lightmap UV set (bake/mesh/unwrap.h): charts at hard edges, exact flat charts,
// LSCM without folds on curved meshes, packing with whole-texel gutters, nothing dropped, the same
// bytes twice. Overlap is checked twice: by texel_atlas (bake/mesh/texels.h: no texel touched or
// contained by two charts) and by an exact triangle–triangle test of the float UVs (exact
// orientation predicates, bake/mesh/predicates.h), which also sees overlap inside one chart.
#include <bake/core/error.h>
#include <bake/mesh/mesh.h>
#include <bake/mesh/predicates.h>
#include <bake/mesh/texels.h>
#include <bake/mesh/unwrap.h>

#include <gtest/gtest.h>
#include <test_scenes.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <string>
#include <vector>

using namespace prt::bake;
using prt::testing::box;
using prt::testing::grid;
using Eigen::Vector2f;
using Eigen::Vector3f;

namespace {

const std::string kData = PRT_DATA_DIR;

// Exact sign of the 2D orientation of float UVs (+1: counter-clockwise in (u, v)), through the
// exact 3D predicate on the points lifted to z = 0 against (0, 0, 1) — calibrated below.
int orient2d(const Vector2f& a, const Vector2f& b, const Vector2f& c) {
  auto lift = [](const Vector2f& p) { return Eigen::Vector3d(p.x(), p.y(), 0); };
  return -orient3d_exact(lift(a), lift(b), lift(c), Eigen::Vector3d(0, 0, 1));
}

// An icosahedron subdivided `levels` times, every vertex pushed onto the unit sphere.
Mesh sphere(int levels) {
  const float g = (1 + std::sqrt(5.0f)) / 2;
  std::vector<Vector3f> p = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                             {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  std::vector<std::array<uint32_t, 3>> t = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                            {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                            {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                            {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (Vector3f& v : p) v.normalize();
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
    auto middle = [&](uint32_t a, uint32_t b) {
      const auto key = std::minmax(a, b);
      auto [it, fresh] = mid.try_emplace({key.first, key.second}, uint32_t(p.size()));
      if (fresh) p.push_back((p[a] + p[b]).normalized());
      return it->second;
    };
    std::vector<std::array<uint32_t, 3>> next;
    for (const auto& f : t) {
      const uint32_t ab = middle(f[0], f[1]), bc = middle(f[1], f[2]), ca = middle(f[2], f[0]);
      next.push_back({f[0], ab, ca});
      next.push_back({f[1], bc, ab});
      next.push_back({f[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    t = std::move(next);
  }
  return make_mesh(std::move(p), std::move(t), "sphere");
}

// Whether the interiors of two counter-clockwise UV triangles meet: they do unless one edge's line
// has the whole other triangle on its outer side or on it (separating axes; for two convex
// polygons in the plane a separating line can be taken through an edge of one of them). Exact.
bool interiors_meet(const std::array<Vector2f, 3>& a, const std::array<Vector2f, 3>& b) {
  auto separates = [](const std::array<Vector2f, 3>& p, const std::array<Vector2f, 3>& q) {
    for (int e = 0; e < 3; ++e) {
      bool all_out = true;
      for (const Vector2f& v : q) all_out = all_out && orient2d(p[size_t(e)], p[size_t((e + 1) % 3)], v) <= 0;
      if (all_out) return true;
    }
    return false;
  };
  return !separates(a, b) && !separates(b, a);
}

std::array<Vector2f, 3> corners(const UvSet& uv, size_t t) { return {uv.corners[3 * t], uv.corners[3 * t + 1], uv.corners[3 * t + 2]}; }

// Every triangle with area: counter-clockwise (exactly), inside [0, 1]², and no two overlapping
// (exactly; pairs culled by their bounding boxes). Returns the number of pairs that overlap.
size_t check_layout(const Mesh& m, const UvSet& uv) {
  std::vector<size_t> live;
  for (size_t t = 0; t < m.triangles.size(); ++t) {
    const auto c = corners(uv, t);
    for (const Vector2f& q : c) {
      EXPECT_GE(q.minCoeff(), 0.0f) << "triangle " << t;
      EXPECT_LE(q.maxCoeff(), 1.0f) << "triangle " << t;
    }
    const Vector3f e = (m.positions[m.triangles[t][1]] - m.positions[m.triangles[t][0]])
                           .cross(m.positions[m.triangles[t][2]] - m.positions[m.triangles[t][0]]);
    if (e.norm() == 0) continue;
    EXPECT_GT(orient2d(c[0], c[1], c[2]), 0) << "triangle " << t << " is flipped or flat in UV";
    live.push_back(t);
  }
  // Sweep over u: pairs whose u ranges meet.
  std::vector<std::pair<float, size_t>> by_u;
  for (size_t t : live) by_u.push_back({std::min({uv.corners[3 * t].x(), uv.corners[3 * t + 1].x(), uv.corners[3 * t + 2].x()}), t});
  std::sort(by_u.begin(), by_u.end());
  size_t overlaps = 0;
  for (size_t i = 0; i < by_u.size(); ++i) {
    const auto a = corners(uv, by_u[i].second);
    const float a_hi = std::max({a[0].x(), a[1].x(), a[2].x()});
    for (size_t j = i + 1; j < by_u.size() && by_u[j].first < a_hi; ++j) {
      const auto b = corners(uv, by_u[j].second);
      const float lo = std::max(std::min({a[0].y(), a[1].y(), a[2].y()}), std::min({b[0].y(), b[1].y(), b[2].y()}));
      const float hi = std::min(std::max({a[0].y(), a[1].y(), a[2].y()}), std::max({b[0].y(), b[1].y(), b[2].y()}));
      if (lo < hi && interiors_meet(a, b)) ++overlaps;
    }
  }
  return overlaps;
}

// texel_atlas's checks of the set at side × side: no texel touched by two charts (gutters) and
// none inside triangles of two charts (overlap). Returns the atlas for further checks.
TexelAtlas expect_clean_atlas(const Mesh& m, const Topology& topo, const UvSet& uv, uint32_t side) {
  TexelAtlas a = texel_atlas(m, topo, uv, side, side, m.source);
  EXPECT_EQ(a.overlapping_texels, 0u) << m.source;
  EXPECT_EQ(a.shared_texels, 0u) << m.source;
  return a;
}

} // namespace

TEST(Unwrap, ExactOrientationIsCalibrated) {
  EXPECT_EQ(orient2d({0, 0}, {1, 0}, {0, 1}), 1);
  EXPECT_EQ(orient2d({0, 0}, {0, 1}, {1, 0}), -1);
  EXPECT_EQ(orient2d({0, 0}, {1, 1}, {2, 2}), 0);
  EXPECT_TRUE(interiors_meet({{{0, 0}, {1, 0}, {0, 1}}}, {{{0.2f, 0.2f}, {2, 0}, {0, 2}}}));
  EXPECT_FALSE(interiors_meet({{{0, 0}, {1, 0}, {0, 1}}}, {{{1, 0}, {1, 1}, {0, 1}}})) << "sharing an edge is no overlap";
}

TEST(Unwrap, APlanarGridIsOneExactChartFillingTheClosedForm) {
  const Mesh m = grid(4, 0.5f);  // [−½, ½]², 8 × 8 cells
  UnwrapOptions o;
  o.width = o.height = 64;
  const Unwrapped u = unwrap(m, build_topology(m), o);
  EXPECT_EQ(u.uv.name, "prtbake_lightmap");
  EXPECT_EQ(u.report.charts, 1u);
  EXPECT_EQ(u.report.planar_charts, 1u);
  EXPECT_EQ(u.report.degenerate_triangles, 0u);
  // Projection of a plane onto itself: stretch 1 up to double rounding of float positions
  // (a few ulps of 1; 1e-12 leaves a wide margin).
  EXPECT_NEAR(u.report.worst_stretch, 1.0, 1e-12);
  EXPECT_NEAR(u.report.mean_stretch, 1.0, 1e-12);
  // Closed form: the unit square at density s occupies floor(s + 2/64) + 1 texels per side plus
  // the gutter G = 2, at most 64: the largest s is 62 − 2/64 (from below), so the utilisation
  // tends to (s / 64)². Bisection stops 2^-40 of the first bracket (64) below it: 1e-9 is ample.
  const double s = 62 - 2.0 / 64;
  EXPECT_NEAR(u.report.density, s, 1e-9);
  EXPECT_NEAR(u.report.utilisation, s * s / (64.0 * 64.0), 1e-9);
  EXPECT_EQ(check_layout(m, u.uv), 0u);
  EXPECT_EQ(expect_clean_atlas(m, build_topology(m), u.uv, 64).charts, 1u);
}

TEST(Unwrap, ACubeIsSixSquaresWithWholeTexelGutters) {
  const Mesh m = box({0, 0, 0}, {1, 1, 1}, "cube");  // triangles 2f, 2f + 1: face f
  const Topology topo = build_topology(m);
  UnwrapOptions o;
  o.width = o.height = 128;
  const Unwrapped u = unwrap(m, topo, o);
  EXPECT_EQ(u.report.charts, 6u) << "every cube edge is a 90° hard edge";
  EXPECT_EQ(u.report.planar_charts, 6u);
  EXPECT_NEAR(u.report.worst_stretch, 1.0, 1e-12);  // planar: as the grid above
  EXPECT_EQ(check_layout(m, u.uv), 0u);
  // Each face (triangles 2f, 2f + 1) is a square in texels: its box's sides equal, and equal to
  // the density (unit faces), to float rounding of UVs (2^-24 · 128 texels per coordinate).
  struct Box {
    float lo[2], hi[2];
  };
  std::vector<Box> boxes;
  for (size_t f = 0; f < 6; ++f) {
    Box b{{1e9f, 1e9f}, {-1e9f, -1e9f}};
    for (size_t k = 6 * f; k < 6 * f + 6; ++k)
      for (int d = 0; d < 2; ++d) {
        b.lo[d] = std::min(b.lo[d], u.uv.corners[k][d] * 128);
        b.hi[d] = std::max(b.hi[d], u.uv.corners[k][d] * 128);
      }
    for (int d = 0; d < 2; ++d) EXPECT_NEAR(b.hi[d] - b.lo[d], u.report.density, 1e-4) << "face " << f;
    boxes.push_back(b);
  }
  // Gutters on the texel grid: the texels a face touches lie in [floor(lo), floor(hi)] (its box
  // is a square, so box and face coincide); between two faces at least G = 2 texels are empty
  // along one axis.
  for (size_t f = 0; f < 6; ++f)
    for (size_t g = f + 1; g < 6; ++g) {
      int gap = -1;
      for (int d = 0; d < 2; ++d) {
        const int f_lo = int(std::floor(boxes[f].lo[d])), f_hi = int(std::floor(boxes[f].hi[d]));
        const int g_lo = int(std::floor(boxes[g].lo[d])), g_hi = int(std::floor(boxes[g].hi[d]));
        gap = std::max({gap, g_lo - f_hi - 1, f_lo - g_hi - 1});
      }
      EXPECT_GE(gap, 2) << "faces " << f << " and " << g;
    }
  EXPECT_EQ(expect_clean_atlas(m, topo, u.uv, 128).charts, 6u);
}

TEST(Unwrap, ASphereHasNoFoldAndNoOverlap) {
  const Mesh m = sphere(3);  // 1,280 triangles
  const Topology topo = build_topology(m);
  UnwrapOptions o;
  o.width = o.height = 512;
  const Unwrapped u = unwrap(m, topo, o);
  EXPECT_GE(u.report.charts, 2u) << "a closed sphere cannot be one chart within a 65° cone";
  EXPECT_EQ(check_layout(m, u.uv), 0u);
  expect_clean_atlas(m, topo, u.uv, 512);
  // The unwrapper splits a chart with a triangle stretched past 2 (unwrap.h), so none may be;
  // exactly 2 is allowed (the split is on "exceeds").
  EXPECT_LE(u.report.worst_stretch, 2.0);
  // A loose floor, not a target: a handful of round caps, each in a square-ish profile, packed
  // by the horizon packer fill about half of the atlas; below 0.3 the packing would be broken.
  EXPECT_GT(u.report.utilisation, 0.3);
}

TEST(Unwrap, TheBunnyHasNoFoldAndNoOverlapAndTheSameBytesTwice) {
  const Mesh m = load_mesh(kData + "/bunny.obj");
  const Topology topo = build_topology(m);
  UnwrapOptions o;
  o.width = o.height = 512;
  const Unwrapped u = unwrap(m, topo, o);
  EXPECT_EQ(u.uv.corners.size(), 3 * m.triangles.size());
  EXPECT_EQ(check_layout(m, u.uv), 0u);
  expect_clean_atlas(m, topo, u.uv, 512);
  const Unwrapped again = unwrap(m, topo, o);
  ASSERT_EQ(again.uv.corners.size(), u.uv.corners.size());
  EXPECT_EQ(std::memcmp(again.uv.corners.data(), u.uv.corners.data(), u.uv.corners.size() * sizeof(Vector2f)), 0);
  EXPECT_EQ(again.report.charts, u.report.charts);
  EXPECT_EQ(again.report.density, u.report.density);
}

TEST(Unwrap, DegenerateAndNonManifoldTrianglesAreKept) {
  // A unit square (0 1 2, 0 2 3); a zero-area triangle on its edge (0, 1 and the edge's
  // midpoint 4); two fins on edge 1–2 (a non-manifold edge of three faces); one triangle with a
  // repeated corner.
  const Mesh m = make_mesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5f, 0, 0}, {1.5f, 0.5f, 1}, {1.5f, 0.5f, -1}},
                           {{{0, 1, 2}}, {{0, 2, 3}}, {{0, 4, 1}}, {{1, 5, 2}}, {{2, 6, 1}}, {{3, 3, 0}}}, "messy");
  const Topology topo = build_topology(m);
  UnwrapOptions o;
  o.width = o.height = 64;
  const Unwrapped u = unwrap(m, topo, o);
  ASSERT_EQ(u.uv.corners.size(), 3 * m.triangles.size());
  EXPECT_EQ(u.report.degenerate_triangles, 2u);
  EXPECT_EQ(u.report.charts, 3u) << "the square, and each fin apart (the non-manifold edge joins nothing)";
  for (size_t k : {6u, 7u, 8u, 15u, 16u, 17u}) EXPECT_EQ(u.uv.corners[k], Vector2f(0, 0)) << "degenerate corner " << k;
  EXPECT_EQ(check_layout(m, u.uv), 0u);
  expect_clean_atlas(m, topo, u.uv, 64);
}

TEST(Unwrap, ADensityChoosesTheSmallestSquareAndRefusesPastTheLimit) {
  const Mesh m = box({0, 0, 0}, {1, 1, 1}, "cube");
  const Topology topo = build_topology(m);
  UnwrapOptions o;
  o.density = 10;  // each face 11 texels + 2 of gutter: six 13 × 13 rectangles
  const Unwrapped u = unwrap(m, topo, o);
  EXPECT_EQ(u.report.width % 4, 0u);
  EXPECT_EQ(u.report.width, u.report.height);
  EXPECT_EQ(u.report.density, 10.0);
  // The smallest square holding six 13 × 13 rectangles is 3 × 2 of them (39 × 26), so 40 (a
  // multiple of 4); a 36 square holds only 2 × 2.
  EXPECT_EQ(u.report.width, 40u);
  EXPECT_EQ(check_layout(m, u.uv), 0u);
  o.density = 1e5;
  try {
    unwrap(m, topo, o);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cube: a lightmap at"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("the largest density that fits is"), std::string::npos) << e.what();
  }
  o.density = 0;
  EXPECT_THROW(unwrap(m, topo, o), InputError) << "neither a size nor a density";
  o.width = o.height = 20000;
  EXPECT_THROW(unwrap(m, topo, o), InputError) << "past max_side";
}

TEST(Unwrap, ThinChartsGetMinChartTexelsAcrossAndStillPackCleanly) {
  // A 4 × 4 × 0.25 slab: two 4 × 4 faces and four 4 × 0.25 sides, each side a chart of its own.
  // At 64² the atlas's density s gives a side 0.25·s ≈ 1.5 texels across; with
  // min_chart_texels = 3 each side gets its own density 3 / 0.25 (under the 4·s cap) and spans 3
  // texels across (to the float rounding of its UVs, 2^-24 · 64), the big faces keep s, and the
  // layout stays exact: no flip, no overlap, whole gutters.
  const Mesh m = box({0, 0, 0}, {4, 4, 0.25f}, "slab");  // triangles 2f, 2f + 1: face f
  const Topology topo = build_topology(m);
  UnwrapOptions o;
  o.width = o.height = 64;
  auto short_side = [&](const Unwrapped& u, size_t f) {  // face f's smaller UV extent, in texels
    float lo[2] = {1e9f, 1e9f}, hi[2] = {-1e9f, -1e9f};
    for (size_t k = 6 * f; k < 6 * f + 6; ++k)
      for (int d = 0; d < 2; ++d) lo[d] = std::min(lo[d], u.uv.corners[k][d] * 64), hi[d] = std::max(hi[d], u.uv.corners[k][d] * 64);
    return std::min(hi[0] - lo[0], hi[1] - lo[1]);
  };
  const Unwrapped uniform = unwrap(m, topo, o);
  o.min_chart_texels = 3;
  const Unwrapped thin = unwrap(m, topo, o);
  EXPECT_EQ(uniform.report.scaled_charts, 0u);
  EXPECT_EQ(thin.report.scaled_charts, 4u);
  EXPECT_LE(thin.report.density, uniform.report.density) << "the thin charts' texels can only cost the rest";
  size_t sides = 0;
  for (size_t f = 0; f < 6; ++f) {
    const float before = short_side(uniform, f), after = short_side(thin, f);
    if (before < 3) {
      ++sides;
      EXPECT_NEAR(after, 3.0f, 1e-4f) << "face " << f;
    } else {
      EXPECT_NEAR(after, 4 * thin.report.density, 1e-4) << "face " << f << " keeps the atlas's density";
    }
  }
  EXPECT_EQ(sides, 4u) << "the premise: the sides were under 3 texels across";
  EXPECT_NEAR(thin.report.worst_stretch, 1.0, 1e-12) << "a chart's own density scales it evenly";
  EXPECT_EQ(check_layout(m, thin.uv), 0u);
  expect_clean_atlas(m, topo, thin.uv, 64);
}
