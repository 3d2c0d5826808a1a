// Tests of Loop subdivision through OpenMesh (bake/mesh/subdivide.h).
#include <bake/core/error.h>
#include <bake/mesh/mesh.h>
#include <bake/mesh/subdivide.h>

#include <gtest/gtest.h>

#include <cmath>
#include <string>

using namespace prt::bake;
using Eigen::Vector3f;

namespace {

const std::string kData = PRT_DATA_DIR;

// Flat square grid in the z = 0 plane, (m × m) quads split into triangles, consistently wound.
Mesh grid(int m) {
  std::vector<Vector3f> p;
  std::vector<std::array<uint32_t, 3>> t;
  for (int j = 0; j <= m; ++j)
    for (int i = 0; i <= m; ++i) p.emplace_back(float(i) / float(m), float(j) / float(m), 0.0f);
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i) {
      const uint32_t a = uint32_t(j * (m + 1) + i), b = a + 1, c = a + uint32_t(m) + 2, d = a + uint32_t(m) + 1;
      t.push_back({a, b, c});
      t.push_back({a, c, d});
    }
  return make_mesh(std::move(p), std::move(t), "grid");
}

void expect_finite(const Mesh& m) {
  for (const auto& p : m.positions) ASSERT_TRUE(p.allFinite());
  for (const auto& n : m.normals) {
    ASSERT_TRUE(n.allFinite());
    ASSERT_NEAR(n.norm(), 1.0f, 1e-5f);
  }
  for (const auto& t : m.triangles)
    for (uint32_t v : t) ASSERT_LT(v, m.positions.size());
}

} // namespace

TEST(LoopSubdivide, BunnyQuadruplesTrianglesPerLevel) {
  const Mesh bunny = load_mesh(kData + "/bunny.obj");
  ASSERT_EQ(bunny.triangles.size(), 3674u);
  const size_t expected[] = {3674, 14696, 58784, 235136};
  for (int level = 0; level <= 3; ++level) {
    const Mesh s = loop_subdivide(bunny, level);
    EXPECT_EQ(s.triangles.size(), expected[level]) << "level " << level;
    expect_finite(s);
    // Euler characteristic and boundary are preserved: V − E + F is invariant, so with F ×4 and
    // the surface unchanged, V grows by exactly the number of edges of the previous level.
    if (level == 0) {
      EXPECT_EQ(s.positions.size(), bunny.positions.size());  // bunny has no duplicate/unused positions
    }
  }
}

TEST(LoopSubdivide, VertexCountFollowsEdgeCount) {
  const Mesh bunny = load_mesh(kData + "/bunny.obj");
  const Mesh s1 = loop_subdivide(bunny, 1);
  const Topology t0 = build_topology(bunny);
  // Each edge of level 0 adds one vertex.
  EXPECT_EQ(s1.positions.size(), t0.welded_positions.size() + t0.edges.size());
  const Mesh s2 = loop_subdivide(bunny, 2);
  EXPECT_EQ(s2.positions.size(), s1.positions.size() + build_topology(s1).edges.size());
}

TEST(LoopSubdivide, OldVerticesKeepTheirIndexAndStayClose) {
  const Mesh bunny = load_mesh(kData + "/bunny.obj");
  const Mesh s = loop_subdivide(bunny, 2);
  // Bounding-box diagonal of the bunny, for a scale-free bound on how far smoothing moves a vertex.
  Vector3f lo = bunny.positions[0], hi = lo;
  for (const auto& p : bunny.positions) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const float diag = (hi - lo).norm();
  double worst = 0;
  for (size_t v = 0; v < bunny.positions.size(); ++v)
    worst = std::max(worst, double((s.positions[v] - bunny.positions[v]).norm()));
  // Loop smoothing moves a vertex by a fraction of its 1-ring size: far below 5 % of the model.
  EXPECT_LT(worst, 0.05 * diag);
  EXPECT_GT(worst, 0.0);  // but it does move them (an approximating scheme)
}

TEST(LoopSubdivide, FlatGridStaysFlat) {
  const Mesh g = grid(6);
  for (int level = 1; level <= 3; ++level) {
    const Mesh s = loop_subdivide(g, level);
    EXPECT_EQ(s.triangles.size(), g.triangles.size() << (2 * level));
    expect_finite(s);
    for (const auto& p : s.positions) {
      ASSERT_EQ(p.z(), 0.0f);  // every rule is an affine combination of points with z = 0
      ASSERT_GE(p.x(), -1e-6f);
      ASSERT_LE(p.x(), 1 + 1e-6f);
    }
    for (const auto& n : s.normals) ASSERT_NEAR(std::abs(n.z()), 1.0f, 1e-6f);
  }
}

TEST(LoopSubdivide, SeamSplitMeshIsWeldedFirst) {
  // Two triangles sharing an edge, but with the shared corners duplicated (a seam): welding makes
  // them one surface, so the result has the vertex count of the welded square.
  const std::vector<Vector3f> p = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  const Mesh seam = make_mesh(p, {{0, 1, 2}, {3, 4, 5}}, "seam");
  const Mesh s = loop_subdivide(seam, 1);
  EXPECT_EQ(s.triangles.size(), 8u);
  EXPECT_EQ(s.positions.size(), 4u + 5u);  // 4 welded corners + 5 edges
}

TEST(LoopSubdivide, RefusesWhatOpenMeshWouldDropInsteadOfLosingFaces) {
  // Three triangles on one edge (non-manifold edge).
  const std::vector<Vector3f> p = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  EXPECT_THROW(loop_subdivide(make_mesh(p, {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}}, "fin"), 1), InputError);
  // Inconsistent winding across an edge.
  EXPECT_THROW(loop_subdivide(make_mesh(p, {{0, 1, 2}, {0, 1, 3}}, "flip"), 1), InputError);
  // A repeated corner (zero-area "triangle" (a, a, b)).
  EXPECT_THROW(loop_subdivide(make_mesh(p, {{0, 1, 2}, {0, 0, 1}}, "needle"), 1), InputError);
  // The error names the mesh.
  try {
    loop_subdivide(make_mesh(p, {{0, 1, 2}, {0, 1, 3}}, "flip.obj"), 1);
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "flip.obj");
  }
  // A closed disk around vertex 0 plus a triangle touching only vertex 0: every edge is manifold
  // and consistently wound, but OpenMesh's add_face refuses the last face ("complex vertex":
  // vertex 0 is already interior). It must be an error, not a lost face. (OpenMesh prints its
  // own message to omerr first.)
  const std::vector<Vector3f> d = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}, {0, 0, 1}, {1, 0, 1}};
  EXPECT_THROW(loop_subdivide(make_mesh(d, {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 1}, {0, 5, 6}}, "disk+fin"), 1),
               InputError);
  // Two fans sharing only a vertex (a bow-tie) are accepted by OpenMesh and keep every face.
  const std::vector<Vector3f> q = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {-1, 0, 0}, {-1, -1, 0}};
  const Mesh bow = loop_subdivide(make_mesh(q, {{0, 1, 2}, {0, 3, 4}}, "bowtie"), 1);
  EXPECT_EQ(bow.triangles.size(), 8u);
}

TEST(LoopSubdivide, NegativeLevelsIsAContractError) {
  EXPECT_THROW(loop_subdivide(grid(1), -1), prt::bake::ContractError);
}
