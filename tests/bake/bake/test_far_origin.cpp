// Positions far from the origin (bake/mesh/mesh.h, ORIGIN): read in double, baked relative to the mesh's
// own origin, so a mesh translated by ~1e5 and scaled by 1e-4 bakes to the values of the
// original; ordinary meshes keep origin 0 and the floats they always had.
#include <bake/bake/scene.h>
#include <bake/bake/vertex_bake.h>
#include <bake/integrators/integrator.h>
#include <bake/mesh/mesh.h>

#include <gtest/gtest.h>
#include <mesh_files.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

using Eigen::Vector3d;
using Eigen::Vector3f;
using prt::bake::Mesh;
namespace fs = std::filesystem;

const Vector3d kShift(1e5, -2e5, 3e5);
constexpr double kScale = 1e-4;

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// `obj` with every `v x y z` line replaced by kShift + kScale · (x, y, z), written with 17
// significant digits (each double exactly); faces and everything else unchanged, so rows line up.
std::string far_copy(const std::string& obj, std::vector<Vector3d>* world = nullptr) {
  std::istringstream in(obj);
  std::string line, out;
  char buf[160];
  while (std::getline(in, line)) {
    double x, y, z;
    if (line.rfind("v ", 0) == 0 && std::sscanf(line.c_str() + 2, "%lf %lf %lf", &x, &y, &z) == 3) {
      // The original's positions as the bake sees them (float), moved in double.
      const Vector3d p = kShift + kScale * Vector3d(x, y, z).cast<float>().cast<double>();
      if (world) world->push_back(p);
      std::snprintf(buf, sizeof buf, "v %.17g %.17g %.17g", p.x(), p.y(), p.z());
      out += buf;
    } else {
      out += line;
    }
    out += '\n';
  }
  return out;
}

std::vector<double> bake_ao(const Mesh& mesh, prt::bake::IntegratorKind kind) {
  prt::bake::IntegratorSpec spec;
  spec.kind = kind;
  spec.silhouette_k = 1024;
  spec.qmc_rays = 1024;
  prt::bake::ProductRequest request;
  request.ao = true;
  const prt::bake::Topology topo = prt::bake::build_topology(mesh);
  return prt::bake::bake_vertices(mesh, topo, *prt::bake::make_integrator(spec, mesh, topo, request)).values;
}

struct BunnyPair {
  Mesh near, far;
  std::vector<Vector3d> far_world;  // the 17-digit file's positions (exact doubles)
};

const BunnyPair& bunny_pair() {
  static const BunnyPair pair = [] {
    BunnyPair p;
    const fs::path dir = prt::testing::test_dir("far_origin");
    const std::string obj = read_text(fs::path(PRT_DATA_DIR) / "bunny.obj");
    p.near = prt::bake::load_mesh(fs::path(PRT_DATA_DIR) / "bunny.obj");
    p.far = prt::bake::load_mesh(prt::testing::write_test_file(dir, "bunny_far.obj", far_copy(obj, &p.far_world)));
    return p;
  }();
  return pair;
}

TEST(FarOrigin, OrdinaryMeshesKeepOriginZero) {
  const Mesh& near = bunny_pair().near;
  EXPECT_EQ(near.origin, Vector3d::Zero());
  // The rule: 0 while the box reaches at most kNearOrigin × its extent from the world origin.
  const Eigen::AlignedBox3d unit(Vector3d(-1, 0, 0), Vector3d(1, 1, 1));
  EXPECT_EQ(prt::bake::frame_origin(unit), Vector3d::Zero());
  const Eigen::AlignedBox3d edge(Vector3d(7, 0, 0), Vector3d(8, 1, 1));  // reach 8 = 8 × extent 1
  EXPECT_EQ(prt::bake::frame_origin(edge), Vector3d(7.5, 0.5, 0.5));
  const Eigen::AlignedBox3d inside(Vector3d(3, 0, 0), Vector3d(4, 1, 1));  // reach 4 = kNearOrigin × 1
  EXPECT_EQ(prt::bake::frame_origin(inside), Vector3d::Zero());
}

TEST(FarOrigin, WorldPositionsAreTheFilesToDoubleRounding) {
  const BunnyPair& p = bunny_pair();
  ASSERT_EQ(p.far.positions.size(), p.far_world.size());
  EXPECT_NE(p.far.origin, Vector3d::Zero());
  // world = origin + float(file − origin): one float rounding of the offset (2^-24 of it) and
  // one double rounding of the sum (2^-53 of the coordinate).
  for (size_t v = 0; v < p.far_world.size(); ++v) {
    const Vector3d w = p.far.world_position(v);
    for (int k = 0; k < 3; ++k) {
      const double offset = std::abs(w[k] - p.far.origin[k]);
      const double bound = offset * 0x1p-24 + std::abs(p.far_world[v][k]) * 0x1p-53;
      ASSERT_LE(std::abs(w[k] - p.far_world[v][k]), bound) << v << " " << k;
    }
  }
}

// How two bakes of the same vertices differ: the worst |a − b|, how many vertices differ by more
// than `tolerance`, and the difference of their means. Recorded as test properties.
struct Difference {
  double worst = 0, mean = 0;
  size_t differing = 0;
};
Difference difference(const std::vector<double>& a, const std::vector<double>& b, double tolerance) {
  EXPECT_EQ(a.size(), b.size());
  Difference d;
  double sum = 0;
  for (size_t v = 0; v < std::min(a.size(), b.size()); ++v) {
    d.worst = std::max(d.worst, std::abs(a[v] - b[v]));
    d.differing += std::abs(a[v] - b[v]) > tolerance;
    sum += a[v] - b[v];
  }
  d.mean = std::abs(sum) / double(std::max<size_t>(a.size(), 1));
  char w[32];
  std::snprintf(w, sizeof w, "%.3g", d.worst);
  ::testing::Test::RecordProperty("worst_ao_difference", w);
  ::testing::Test::RecordProperty("differing_vertices", std::to_string(d.differing));
  return d;
}

// Silhouette AO: the far mesh is the original scaled by 1e-4 (AO is scale-invariant) up to
// relative perturbations of its vertices: the 17-digit doubles (2^-53 × 3e5 = 3e-11 against a
// size of 1e-3: 3e-8) and the float offsets (2^-24 = 6e-8 relative): ~1e-7 of the mesh's size.
// The silhouette integrator is a deterministic function of the geometry, continuous in the
// vertices where no contour edge appears or vanishes, and AO moves with a relative vertex
// perturbation δ by O(δ) times how close the geometry a vertex sees is: measured worst 7.7e-7
// (of 1839 vertices), within the 1e-6. Float world coordinates (what the bake had
// before) move vertices by up to 0.016 — 16× the bunny's size — and fail it everywhere.
TEST(FarOrigin, SilhouetteAoEqualsTheOriginalsWithin1e6) {
  const BunnyPair& p = bunny_pair();
  const auto d = difference(bake_ao(p.near, prt::bake::IntegratorKind::Silhouette),
                            bake_ao(p.far, prt::bake::IntegratorKind::Silhouette), 1e-6);
  EXPECT_EQ(d.differing, 0u) << "worst " << d.worst;
}

// QMC AO with the same seed: each vertex casts the same 1024 cosine-distributed directions
// about its normal (which differs by ~1e-7), and the estimate is (rays that escape) / 1024, so
// the two bakes differ only where a ray's hit or miss flips: a ray passing within the
// perturbation (~1e-7 of the size) of an edge or a silhouette. A flip moves that vertex's AO by
// exactly 1/1024; the chance of one per ray is of the order of the perturbation over the
// distances involved, so over 1839 × 1024 rays expect a handful (measured: one vertex, one
// ray). Asserted: at most 1% of the vertices differ by more than 1e-6, none by more than two
// rays, and the means differ by no more than the differing vertices' share of those rays.
TEST(FarOrigin, QmcAoFlipsAtMostAFewGrazingRays) {
  const BunnyPair& p = bunny_pair();
  const auto a = bake_ao(p.near, prt::bake::IntegratorKind::Qmc);
  const auto d = difference(a, bake_ao(p.far, prt::bake::IntegratorKind::Qmc), 1e-6);
  EXPECT_LE(d.differing, a.size() / 100) << "more than 1% of vertices changed";
  EXPECT_LE(d.worst, 2.0 / 1024 + 1e-6) << "more than two rays flipped at one vertex";
  EXPECT_LE(d.mean, 1e-6 + double(d.differing) * 2.0 / 1024 / double(a.size()));
}

// The same bunny moved by a scene transform (translation · scale, applied in double to the
// file's positions): the same values as the 17-digit file, to the same tolerance and reason.
TEST(FarOrigin, SceneTransformBakesTheOriginalsAo) {
  const BunnyPair& p = bunny_pair();
  prt::bake::SceneObject object;
  object.name = "bunny";
  object.mesh = fs::path(PRT_DATA_DIR) / "bunny.obj";
  object.world_from_object.topLeftCorner<3, 3>() *= kScale;
  object.world_from_object.topRightCorner<3, 1>() = kShift;
  const Eigen::Vector3d origin = prt::bake::scene_origin(std::span(&p.near, 1), std::span(&object, 1));
  EXPECT_NE(origin, Vector3d::Zero());
  const Mesh placed = prt::bake::place_scene_object(p.near, object, origin);
  EXPECT_EQ(placed.origin, origin);
  for (size_t v = 0; v < placed.positions.size(); ++v)
    ASSERT_LE((placed.world_position(v) - p.far_world[v]).norm(), 1e-10) << v;
  const auto d = difference(bake_ao(p.near, prt::bake::IntegratorKind::Silhouette),
                            bake_ao(placed, prt::bake::IntegratorKind::Silhouette), 1e-6);
  EXPECT_EQ(d.differing, 0u) << "worst " << d.worst;
  // An ordinary scene (identity) keeps origin 0 and the file's floats bit for bit.
  prt::bake::SceneObject plain = object;
  plain.world_from_object.setIdentity();
  EXPECT_EQ(prt::bake::scene_origin(std::span(&p.near, 1), std::span(&plain, 1)), Vector3d::Zero());
  EXPECT_EQ(prt::bake::place_scene_object(p.near, plain, Vector3d::Zero()).positions, p.near.positions);
}

// Reading in double never changes the float a coordinate had: the text just above the float
// midpoint 1 + 2^-24 has that midpoint as its nearest double, which rounds (ties to even) down to
// 1, while the text's own correctly rounded float is 1 + 2^-23; the reader moves the double one
// ulp up so the mesh keeps 1 + 2^-23, as when it read floats.
TEST(FarOrigin, DoubleReadingKeepsTheCorrectlyRoundedFloat) {
  const std::string obj = "v 0 0 0\nv 1.0000000596046447753906250001 0 0\nv 0 1 0\nf 1 2 3\n";
  const Mesh m = prt::bake::load_mesh(prt::testing::write_test_file(prt::testing::test_dir("far_origin"), "midpoint.obj", obj));
  EXPECT_EQ(m.origin, Vector3d::Zero());
  EXPECT_EQ(m.positions[1].x(), std::nextafter(1.0f, 2.0f));
}

// Two vertices a quarter float ulp apart at 1e5 (float32 would merge them): distinct offsets,
// distinct welded positions, distinct world positions.
TEST(FarOrigin, VerticesCloserThanAFloatUlpStayApart) {
  const double x = 1e5, d = 0x1p-9;  // ulp(float(1e5)) = 2^-7
  ASSERT_EQ(float(x), float(x + d));
  const std::string obj = "v 100000 0 0\nv 100000.001953125 0 0\nv 100000 0.001 0\nv 100000 0 0.001\n"
                          "f 1 3 4\nf 2 4 3\n";
  const Mesh m = prt::bake::load_mesh(prt::testing::write_test_file(prt::testing::test_dir("far_origin"), "close.obj", obj));
  ASSERT_EQ(m.positions.size(), 4u);
  EXPECT_NE(m.positions[0], m.positions[1]);
  EXPECT_EQ(m.world_position(0).x(), x);
  EXPECT_EQ(m.world_position(1).x(), x + d);
  EXPECT_EQ(prt::bake::build_topology(m).welded_positions.size(), 4u);
}

// merge_meshes: parts with different origins are re-expressed in one frame, in double.
TEST(FarOrigin, MergeReexpressesPartsInOneFrame) {
  const BunnyPair& p = bunny_pair();
  const Mesh parts[] = {p.far, p.near};
  const Mesh merged = prt::bake::merge_meshes(parts, "both");
  const size_t n = p.far.positions.size();
  // The union reaches 3e5 with an extent of 3e5: near the origin by the rule, origin 0.
  EXPECT_EQ(merged.origin, Vector3d::Zero());
  for (size_t v = 0; v < n; ++v)
    ASSERT_EQ(merged.positions[v], p.far.world_position(v).cast<float>()) << v;
  const Mesh same[] = {p.far, p.far};
  const Mesh twice = prt::bake::merge_meshes(same, "twice");
  EXPECT_EQ(twice.origin, p.far.origin);
  EXPECT_TRUE(std::equal(p.far.positions.begin(), p.far.positions.end(), twice.positions.begin() + std::ptrdiff_t(n)));
}

} // namespace
