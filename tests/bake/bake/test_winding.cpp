// Winding facts (bake/mesh/mesh.h winding_facts), MeshLoadOptions::flip_normals (build_mesh) and the
// no-sky count of a bake (bake/bake/vertex_bake.h count_no_sky), with both integrators.
#include <bake/bake/diagnostics.h>
#include <bake/bake/vertex_bake.h>
#include <bake/integrators/integrator.h>
#include <bake/mesh/mesh.h>

#include <gtest/gtest.h>
#include <test_scenes.h>

#include <algorithm>
#include <array>
#include <vector>

namespace {

using namespace prt::bake;
using prt::testing::box;
using Eigen::Vector3f;

// `m` with every triangle reversed (normals recomputed): a box wound inwards.
Mesh reversed(const Mesh& m) {
  auto t = m.triangles;
  for (auto& tri : t) std::swap(tri[1], tri[2]);
  return make_mesh(m.positions, std::move(t), m.source + " (reversed)");
}

// The box [lo, lo + side]³ with side 1.5 and lo away from the origin: its volume is exactly
// side³ = 3.375 (every coordinate and product is a dyadic rational exact in double).
const Vector3f kLo(0.5f, 1.0f, 2.0f);
constexpr float kSide = 1.5f;
constexpr double kVolume = double(kSide) * kSide * kSide;

Mesh outward_box() { return box(kLo, kLo + Vector3f::Constant(kSide)); }

// One square, two triangles: an open mesh.
Mesh quad() {
  return make_mesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {{0, 1, 2}, {0, 2, 3}}, "quad");
}

WindingFacts facts_of(const Mesh& m) { return winding_facts(m, build_topology(m)); }

// The meshes of `parts` side by side as one mesh (each part moved along x by 10 × its index).
Mesh side_by_side(std::vector<Mesh> parts) {
  for (size_t i = 0; i < parts.size(); ++i)
    for (auto& p : parts[i].positions) p.x() += 10.0f * float(i);
  return merge_meshes(parts, "parts");
}

TEST(Winding, OutwardBoxIsClosedWithPositiveVolume) {
  const WindingFacts f = facts_of(outward_box());
  EXPECT_EQ(f.components, 1u);
  ASSERT_EQ(f.closed.size(), 1u);
  EXPECT_EQ(f.closed[0].triangles, 12u);
  EXPECT_EQ(f.closed[0].signed_volume, kVolume);
  EXPECT_FALSE(f.closed[0].inward);
  EXPECT_EQ(f.inward_components(), 0u);
  EXPECT_EQ(f.inward_triangles(), 0u);
}

TEST(Winding, InwardBoxHasVolumeMinusSideCubed) {
  const WindingFacts f = facts_of(reversed(outward_box()));
  EXPECT_EQ(f.components, 1u);
  ASSERT_EQ(f.closed.size(), 1u);
  EXPECT_EQ(f.closed[0].signed_volume, -kVolume) << "closed form: -side^3, exact in double here";
  EXPECT_TRUE(f.closed[0].inward);
  EXPECT_EQ(f.inward_components(), 1u);
  EXPECT_EQ(f.inward_triangles(), 12u);
}

TEST(Winding, OpenQuadHasNoClosedComponent) {
  const WindingFacts f = facts_of(quad());
  EXPECT_EQ(f.components, 1u);
  EXPECT_TRUE(f.closed.empty());
  EXPECT_EQ(f.inward_components(), 0u);
}

TEST(Winding, CountsEachComponentApart) {
  // An outward box, an inward box and an open quad, not touching: three components, two closed,
  // one of them (its 12 triangles) inwards; reported in the order of their first triangle.
  const WindingFacts f = facts_of(side_by_side({outward_box(), reversed(outward_box()), quad()}));
  EXPECT_EQ(f.components, 3u);
  ASSERT_EQ(f.closed.size(), 2u);
  EXPECT_EQ(f.closed[0].first_triangle, 0u);
  EXPECT_EQ(f.closed[1].first_triangle, 12u);
  EXPECT_FALSE(f.closed[0].inward);
  EXPECT_TRUE(f.closed[1].inward);
  EXPECT_EQ(f.closed[1].signed_volume, -kVolume) << "translation-invariant: the box moved by 10 in x";
  EXPECT_EQ(f.inward_components(), 1u);
  EXPECT_EQ(f.inward_triangles(), 12u);
}

TEST(Winding, InconsistentOrHoledBoxesAreNotClosed) {
  Mesh one_flipped = outward_box();
  std::swap(one_flipped.triangles[3][1], one_flipped.triangles[3][2]);
  Mesh holed = outward_box();
  holed.triangles.pop_back();
  for (const Mesh& m : {one_flipped, holed}) {
    const WindingFacts f = facts_of(m);
    EXPECT_EQ(f.components, 1u);
    EXPECT_TRUE(f.closed.empty()) << "an edge traversed twice the same way, or a boundary edge";
  }
  // A triangle repeating a welded corner makes its component not closed either.
  Mesh degenerate = outward_box();
  degenerate.triangles.push_back({0, 0, 1});
  EXPECT_TRUE(facts_of(degenerate).closed.empty());
}

TEST(Winding, DoubleSidedSheetIsClosedButNotInward) {
  // (a, b, c) and (a, c, b): every edge shared by two faces in opposite directions, volume 0.
  const Mesh sheet = make_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}, {0, 2, 1}}, "sheet");
  const WindingFacts f = facts_of(sheet);
  ASSERT_EQ(f.closed.size(), 1u);
  EXPECT_EQ(f.closed[0].signed_volume, 0.0);
  EXPECT_FALSE(f.closed[0].inward);
}

// The outward box as a reader hands it over: six quads (fan-triangulated by build_mesh) with
// optional per-corner file normals (one per face, pointing `sign` × outwards).
Polygons box_polygons(bool with_normals, float sign) {
  const Mesh b = outward_box();
  Polygons poly;
  for (const Vector3f& p : b.positions) poly.positions.push_back(p.cast<double>());
  for (size_t q = 0; q < 6; ++q) {
    const auto& t0 = b.triangles[2 * q];
    const auto& t1 = b.triangles[2 * q + 1];  // (t0[0], t0[2], x): the quad is t0 then x
    const std::array<uint32_t, 4> corners = {t0[0], t0[1], t0[2], t1[2]};
    const Vector3f n = sign * (b.positions[t0[1]] - b.positions[t0[0]]).cross(b.positions[t0[2]] - b.positions[t0[0]]);
    if (with_normals) poly.normals.push_back(n * 3.0f);  // not unit: build_mesh normalises
    for (uint32_t c : corners) {
      poly.corner_position.push_back(c);
      if (with_normals) poly.corner_normal.push_back(uint32_t(q));
    }
    poly.end_polygon();
  }
  return poly;
}

TEST(FlipNormals, ReversesEveryTriangleAndNegatesFileNormals) {
  for (const bool with_normals : {false, true}) {
    SCOPED_TRACE(with_normals ? "file normals" : "angle-weighted normals");
    // Wound inwards, with file normals pointing inwards too: what --flip-normals is for.
    Polygons inward = box_polygons(with_normals, -1.0f);
    for (size_t f = 0; f < inward.polygon_count(); ++f)
      std::reverse(inward.corner_position.begin() + inward.offsets[f], inward.corner_position.begin() + inward.offsets[f + 1]);
    const Mesh plain = build_mesh(inward, "inward");
    MeshLoadOptions flip;
    flip.flip_normals = true;
    const Mesh flipped = build_mesh(inward, "inward", flip);
    // Rows and their order are the same; each triangle is the same fan triangle reversed.
    ASSERT_EQ(flipped.positions, plain.positions);
    ASSERT_EQ(flipped.source_position, plain.source_position);
    ASSERT_EQ(flipped.triangles.size(), plain.triangles.size());
    for (size_t t = 0; t < plain.triangles.size(); ++t) {
      const auto& a = plain.triangles[t];
      EXPECT_EQ(flipped.triangles[t], (std::array<uint32_t, 3>{a[0], a[2], a[1]})) << t;
    }
    EXPECT_EQ(flipped.normal_source, plain.normal_source);
    for (size_t v = 0; v < plain.normals.size(); ++v)
      EXPECT_EQ(flipped.normals[v], Vector3f(-plain.normals[v])) << "exactly negated, row " << v;
    // The flipped box points outwards: positive volume, and each normal away from the centre.
    const WindingFacts before = facts_of(plain), after = facts_of(flipped);
    ASSERT_EQ(before.closed.size(), 1u);
    ASSERT_EQ(after.closed.size(), 1u);
    EXPECT_TRUE(before.closed[0].inward);
    EXPECT_FALSE(after.closed[0].inward);
    EXPECT_EQ(after.closed[0].signed_volume, kVolume);
    const Vector3f centre = kLo + Vector3f::Constant(kSide / 2);
    for (size_t v = 0; v < flipped.positions.size(); ++v)
      EXPECT_GT(flipped.normals[v].dot(flipped.positions[v] - centre), 0.0f) << v;
  }
}

// AO (and, unless `ao_only`, T and U) of every vertex of `mesh` with the integrator `kind` (a
// small k or N suffices: the values asserted below are exact for both, see there).
VertexBake bake_box(const Mesh& mesh, IntegratorKind kind, bool ao_only = false) {
  const Topology topo = build_topology(mesh);
  IntegratorSpec spec;
  spec.kind = kind;
  spec.set_samples(kind == IntegratorKind::Qmc ? 256 : 32 * 32);
  ProductRequest req;
  req.ao = true;
  req.transfer_order = ao_only ? 0 : 2;
  req.visibility_order = ao_only ? 0 : 2;
  return bake_vertices(mesh, topo, *make_integrator(spec, mesh, topo, req));
}

class NoSky : public ::testing::TestWithParam<IntegratorKind> {};

TEST_P(NoSky, InwardBoxSeesNoSkyAtAnyVertex) {
  // Every vertex's normal points into the closed box, so its whole hemisphere is the box's
  // inside: every QMC ray hits, the silhouette integrator finds the point enclosed; AO, T and
  // U are exactly 0 (the estimate is a sum over escaped rays / visible cells, and there are none).
  const VertexBake b = bake_box(reversed(outward_box()), GetParam());
  for (double x : b.values) EXPECT_EQ(x, 0.0);
  const NoSkyCount c = count_no_sky(b);
  EXPECT_EQ(c.total, 8u);
  EXPECT_EQ(c.vertices, 8u);
  EXPECT_EQ(c.share(), 1.0);
}

TEST_P(NoSky, FlippedBoxSeesTheWholeSky) {
  // The outward box is convex: at a corner the three faces lie in planes through it, on the far
  // side of the tangent plane of the averaged normal (their directions d satisfy n·d ≤ 0), so
  // nothing is above any vertex's hemisphere in the limit p + εn: AO = 1. The silhouette integrator
  // sees no contour edge and returns the closed form 1; the QMC estimate of AO alone samples the
  // cosine only and weighs each escaped ray (c/π)/(c/π) = 1 up to rounding (hence 1e-9).
  const VertexBake b = bake_box(outward_box(), GetParam(), /*ao_only=*/true);
  const size_t W = b.layout.width;
  for (size_t v = 0; v < 8; ++v) EXPECT_NEAR(b.values[v * W + b.layout.ao], 1.0, 1e-9) << v;
  EXPECT_EQ(count_no_sky(b).vertices, 0u);
}

TEST_P(NoSky, CountsOnlyTheEnclosedVertices) {
  // An outward and an inward box side by side: the inward box's 8 vertices see no sky; the
  // outward box's 8 see sky (the other box, 10 away, hides a small part of it at most).
  const VertexBake b = bake_box(side_by_side({outward_box(), reversed(outward_box())}), GetParam());
  const NoSkyCount c = count_no_sky(b);
  EXPECT_EQ(c.total, 16u);
  EXPECT_EQ(c.vertices, 8u);
  EXPECT_EQ(c.share(), 0.5);
}

INSTANTIATE_TEST_SUITE_P(BothIntegrators, NoSky, ::testing::Values(IntegratorKind::Silhouette, IntegratorKind::Qmc),
                         [](const auto& p) { return std::string(to_string(p.param)); });

TEST(NoSkyCount, UsesTheFirstSkyMeasureOfTheLayout) {
  // AO when baked; else T_0; else U_0 (each a positive-weight integral over the visible sky);
  // a radiance-only row counts when every value is 0. Rows here are synthetic.
  ProductRequest transfer_only;
  transfer_only.transfer_order = 2;
  VertexBake b{ProductLayout{transfer_only}, {}, {}, 0};
  // Row 0: T_0 = 0 (the others are whatever); row 1: T_0 > 0; row 2: -0 counts as 0.
  b.values = {0, 0.1, 0, 0, /**/ 0.2, 0, 0, 0, /**/ -0.0, 0, 0, 0};
  const NoSkyCount c = count_no_sky(b);
  EXPECT_EQ(c.total, 3u);
  EXPECT_EQ(c.vertices, 2u);
}

} // namespace
