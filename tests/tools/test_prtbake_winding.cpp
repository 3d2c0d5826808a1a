// prtbake vertex on meshes wound inwards: the warning (numbers and fix) and --flip-normals.
#include <formats/asset.h>

#include <gtest/gtest.h>
#include <run_tool.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace fs = std::filesystem;
namespace F = prt::formats;

namespace {

const std::string kBake = PRT_PRTBAKE;

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(PRT_TEST_TMP) / "prtbake_winding";
  fs::create_directories(dir);
  return dir / name;
}

// The box [0, 1]³ as an OBJ: 8 corners, 6 quads wound outwards (right-handed normals pointing
// out) or, reversed, inwards.
fs::path box_obj(const std::string& name, bool inward) {
  static const int kQuads[6][4] = {{1, 3, 4, 2}, {5, 6, 8, 7}, {1, 2, 6, 5}, {3, 7, 8, 4}, {1, 5, 7, 3}, {2, 4, 8, 6}};
  const fs::path p = scratch(name);
  std::ofstream out(p);
  for (int k = 0; k < 8; ++k) out << "v " << (k & 1) << ' ' << ((k >> 1) & 1) << ' ' << ((k >> 2) & 1) << '\n';
  for (const auto& q : kQuads) {
    out << 'f';
    for (int c = 0; c < 4; ++c) out << ' ' << q[inward ? 3 - c : c];
    out << '\n';
  }
  return p;
}

struct Baked {
  prt::testing::ToolRun run;
  F::Asset asset;
};

Baked bake(const fs::path& mesh, const std::string& extra) {
  const fs::path out = scratch(mesh.stem().string() + ".prt.h5");
  fs::remove(out);
  Baked b{prt::testing::run_tool(kBake, "vertex '" + mesh.string() + "' --ao --report 0 --quiet -o '" + out.string() +
                                            "' " + extra,
                                 scratch("capture")),
          {}};
  if (b.run.code == 0) b.asset = F::read_asset(out);
  return b;
}

const std::string kInwardWarning =
    "prtbake: warning: 1 of 1 closed components (12 triangles) are wound inwards: their normals point inside, so "
    "their vertices see no sky; rerun with --flip-normals\n";

TEST(PrtbakeWinding, InwardBoxWarnsAndBakesNoSky) {
  for (const std::string integrator : {"silhouette", "qmc"}) {
    SCOPED_TRACE(integrator);
    const Baked b = bake(box_obj("inward_" + integrator + ".obj", true), "--integrator " + integrator);
    ASSERT_EQ(b.run.code, 0) << b.run.err;
    // Before the bake, the winding; after it, the share of vertices that saw no sky.
    EXPECT_EQ(b.run.err, kInwardWarning +
                             "prtbake: warning: 100.0% of vertices (8 of 8) see no sky at all: some closed parts are "
                             "wound inwards (see above)\n");
    ASSERT_TRUE(b.asset.vertices.ao);
    ASSERT_EQ(b.asset.vertices.ao->values.size(), 8u);
    // Every vertex's hemisphere is the inside of the box: every ray hits / the point is enclosed.
    for (float a : b.asset.vertices.ao->values) EXPECT_EQ(a, 0.0f);
    EXPECT_EQ(b.asset.vertices.normals->source, "angle-weighted");
  }
}

TEST(PrtbakeWinding, FlipNormalsBakesTheOutsideWithoutWarning) {
  const Baked b = bake(box_obj("inward_flipped.obj", true), "--flip-normals");
  ASSERT_EQ(b.run.code, 0) << b.run.err;
  EXPECT_EQ(b.run.err, "") << "flipped, the box is wound outwards";
  // A convex box's corner: its faces lie on the far side of the tangent plane of the averaged
  // normal, so nothing is above the hemisphere in the limit p + εn: AO = 1 (the silhouette
  // integrator's closed form for a point with no contour edge in view; float32 in the file).
  for (float a : b.asset.vertices.ao->values) EXPECT_EQ(a, 1.0f);
  // Normals point away from the centre (0.5, 0.5, 0.5), and the file says they were flipped.
  const auto& n = b.asset.vertices.normals->values;
  const auto& p = b.asset.vertices.positions->values;
  for (size_t v = 0; v < 8; ++v) {
    double d = 0;
    for (size_t k = 0; k < 3; ++k) d += double(n[3 * v + k]) * (p[3 * v + k] - 0.5);
    EXPECT_GT(d, 0.0) << v;
  }
  EXPECT_EQ(b.asset.vertices.normals->source, "angle-weighted, flipped");
  EXPECT_NE(b.asset.root.command_line.find("--flip-normals"), std::string::npos);
}

TEST(PrtbakeWinding, OutwardBoxAndOpenMeshDoNotWarn) {
  const Baked box = bake(box_obj("outward.obj", false), "");
  ASSERT_EQ(box.run.code, 0) << box.run.err;
  EXPECT_EQ(box.run.err, "");
  for (float a : box.asset.vertices.ao->values) EXPECT_EQ(a, 1.0f);
  const fs::path quad = scratch("quad.obj");
  std::ofstream(quad) << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
  const Baked open = bake(quad, "");
  ASSERT_EQ(open.run.code, 0) << open.run.err;
  EXPECT_EQ(open.run.err, "") << "an open mesh has no inside";
}

TEST(PrtbakeWinding, FlippingAnOutwardBoxSaysToRerunWithout) {
  const Baked b = bake(box_obj("outward_flipped.obj", false), "--flip-normals");
  ASSERT_EQ(b.run.code, 0) << b.run.err;
  EXPECT_NE(b.run.err.find("1 of 1 closed components (12 triangles) are wound inwards"), std::string::npos) << b.run.err;
  EXPECT_NE(b.run.err.find("rerun without --flip-normals"), std::string::npos) << b.run.err;
}

TEST(PrtbakeWinding, PartsInsidePartsAreCalledEnclosedNotInwards) {
  // Two small boxes inside a big one, all wound outwards (an engine's internals under its
  // housing): 16 of 24 vertices see no sky, and the warning says why instead of suggesting a flip.
  const fs::path p = scratch("nested.obj");
  {
    static const int kQuads[6][4] = {{1, 3, 4, 2}, {5, 6, 8, 7}, {1, 2, 6, 5}, {3, 7, 8, 4}, {1, 5, 7, 3}, {2, 4, 8, 6}};
    std::ofstream out(p);
    const double lo[3] = {-4, 0.2, 0.6}, size[3] = {8, 0.2, 0.3};  // the big box, then two small ones
    for (int b = 0; b < 3; ++b)
      for (int k = 0; k < 8; ++k)
        out << "v " << lo[b] + size[b] * (k & 1) << ' ' << lo[b] + size[b] * ((k >> 1) & 1) << ' '
            << lo[b] + size[b] * ((k >> 2) & 1) << '\n';
    for (int b = 0; b < 3; ++b)
      for (const auto& q : kQuads) out << "f " << 8 * b + q[0] << ' ' << 8 * b + q[1] << ' ' << 8 * b + q[2] << ' ' << 8 * b + q[3] << '\n';
  }
  for (const std::string integrator : {"silhouette", "qmc"}) {
    SCOPED_TRACE(integrator);
    const Baked b = bake(p, "--integrator " + integrator);
    ASSERT_EQ(b.run.code, 0) << b.run.err;
    EXPECT_EQ(b.run.err,
              "prtbake: warning: 66.7% of vertices (16 of 24) see no sky at all: 0 of 16 sampled would see sky with the "
              "opposite normal, so they are enclosed by other geometry (parts inside or pushed into other parts), not "
              "turned inside out; nothing to fix in the normals\n");
    for (size_t v = 8; v < 24; ++v) EXPECT_EQ(b.asset.vertices.ao->values[v], 0.0f) << v;
  }
}

TEST(PrtbakeWinding, InwardNormalsOnANonClosedMeshAreToldToFlip) {
  // The box wound inwards with one face written twice: that face's edges have three triangles,
  // so no part is closed and the winding cannot be judged by volume; with its normals reversed
  // every vertex would see the sky, and the flip probe says so.
  const fs::path p = box_obj("inward_duplicated_face.obj", true);
  std::ofstream(p, std::ios::app) << "f 2 4 3 1\n";
  const Baked b = bake(p, "--integrator qmc");
  ASSERT_EQ(b.run.code, 0) << b.run.err;
  EXPECT_EQ(b.run.err, "prtbake: warning: 100.0% of vertices (8 of 8) see no sky at all: 8 of 8 sampled would see sky "
                       "with the opposite normal, so their normals point inside the geometry; rerun with --flip-normals\n");
}

} // namespace

namespace {

TEST(PrtbakeWinding, SceneReceiversWoundInwardsWarnNamingTheObject) {
  // The same two warnings for a scene's receiver that shadows itself ("both"), naming it; a
  // receiver-only one wound inwards is shaded about inward normals (it casts no shadow, so its
  // vertices do see sky); an occluder-only box wound inwards is not baked and gets no warning.
  const fs::path scene = scratch("inward_scene.json");
  std::ofstream(scene) << R"({"prtbake_scene": 1, "bake": {"products": ["ao"], "integrator": "qmc", "samples": 64,
    "report": 0}, "objects": [
      {"name": "crate", "mesh": ")" << box_obj("scene_inward.obj", true).string() << R"(", "role": "both"},
      {"name": "shell", "mesh": ")" << box_obj("scene_inward_receiver.obj", true).string()
                       << R"(", "role": "receiver", "transform": {"translate": [3, 0, 0]}},
      {"name": "lid", "mesh": ")" << box_obj("scene_inward_occluder.obj", true).string()
                       << R"(", "role": "occluder", "transform": {"translate": [0, 3, 0]}}]})";
  const fs::path out = scratch("inward_scene.prt.h5");
  fs::remove(out);
  const prt::testing::ToolRun r =
      prt::testing::run_tool(kBake, "scene '" + scene.string() + "' --quiet -o '" + out.string() + "'", scratch("capture"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err,
            "prtbake: warning: crate: 1 of 1 closed components (12 triangles) are wound inwards: their normals point "
            "inside, so their vertices see no sky; fix their winding in its mesh file\n"
            "prtbake: warning: shell: 1 of 1 closed components (12 triangles) are wound inwards: their normals point "
            "inside, so their vertices are shaded as if seen from inside; fix their winding in its mesh file\n"
            "prtbake: warning: crate: 100.0% of its vertices (8 of 8) see no sky at all: it is enclosed by other "
            "objects, or its normals point inside (check its winding)\n");
}

} // namespace
