// Tests of texture-coordinate sets (bake/mesh/mesh.h UvSet, Polygons::Uvs): every reader that has
// them (OBJ vt, glTF TEXCOORD_n, PLY u/v, s/t, texture_u/texture_v), build_mesh's fan, flip and
// validation, merge_meshes and make_mesh. Each set is per triangle corner, so a UV seam never
// splits a vertex row: every test also checks that the rows are those of the file without UVs.
#include <bake/core/error.h>
#include <bake/mesh/mesh.h>

#include <gltf_builder.h>
#include <mesh_files.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using prt::bake::InputError;
using prt::bake::Mesh;
using prt::bake::UvSet;
using prt::testing::Gltf;
using prt::testing::json;
using prt::testing::expect_input_error;
using Eigen::Vector2f;
using Eigen::Vector3f;
using Tri = std::array<uint32_t, 3>;
using Uvs = std::vector<Vector2f>;

namespace {

fs::path tmp_dir() { return prt::testing::test_dir("uv"); }
fs::path write_file(const std::string& name, const std::string& bytes) { return prt::testing::write_test_file(tmp_dir(), name, bytes); }

// The same rows, normals and triangles, bit for bit (what UVs must not change).
void expect_same_rows(const Mesh& a, const Mesh& b) {
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.normals, b.normals);
  EXPECT_EQ(a.source_position, b.source_position);
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(a.normal_source, b.normal_source);
}

std::vector<std::string> names(const Mesh& m) {
  std::vector<std::string> out;
  for (const UvSet& s : m.uv_sets) out.push_back(s.name);
  return out;
}

// --- OBJ ------------------------------------------------------------------------------------

// Five positions, a quad (fanned into two triangles) and a triangle. Position 2 has vt 2 in the
// quad and vt 5 in the triangle: a UV seam. `corners` is the face lines' corner syntax.
std::string seam_obj(const std::string& quad, const std::string& triangle) {
  return "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\n"
         "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0.25 0\n"
         "vn 0 0 1\nvn 0 0.6 0.8\n"
         "f " + quad + "\nf " + triangle + "\n";
}
// The vt values in glTF's convention (u, 1 − v).
const Vector2f kVt[] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}, {0.5f, 0.75f}};

TEST(UvObj, VtFollowsItsCornerThroughTheFanASeamAndFlipNormals) {
  const Mesh plain = prt::bake::load_mesh(write_file("seam_plain.obj", seam_obj("1 2 3 4", "2 5 3")));
  const Mesh m = prt::bake::load_mesh(write_file("seam.obj", seam_obj("1/1 2/2 3/3 4/4", "2/5 5/2 3/3")));
  expect_same_rows(m, plain);
  EXPECT_EQ(m.positions.size(), 5u) << "a seam splits no row";
  EXPECT_EQ(m.triangles, (std::vector<Tri>{{0, 1, 2}, {0, 2, 3}, {1, 4, 2}}));
  EXPECT_TRUE(m.warnings.empty());
  ASSERT_EQ(names(m), std::vector<std::string>{"vt"});
  EXPECT_EQ(m.uv_sets[0].corners, (Uvs{kVt[0], kVt[1], kVt[2], kVt[0], kVt[2], kVt[3], kVt[4], kVt[1], kVt[2]}));

  // flip_normals reverses each triangle (c0, c1, c2) -> (c0, c2, c1); the UVs go with their corners.
  const Mesh flipped = prt::bake::load_mesh(write_file("seam.obj", seam_obj("1/1 2/2 3/3 4/4", "2/5 5/2 3/3")), {.flip_normals = true});
  EXPECT_EQ(flipped.triangles, (std::vector<Tri>{{0, 2, 1}, {0, 3, 2}, {1, 2, 4}}));
  EXPECT_EQ(flipped.uv_sets[0].corners, (Uvs{kVt[0], kVt[2], kVt[1], kVt[0], kVt[3], kVt[2], kVt[4], kVt[2], kVt[1]}));

  // With normals, rows split by (position, normal) as without vt, and never by vt; relative
  // (negative) vt indices count back from the vt lines so far.
  const Mesh plain_n = prt::bake::load_mesh(write_file("seam_plain_n.obj", seam_obj("1//1 2//1 3//1 4//1", "2//2 5//2 3//2")));
  const Mesh n = prt::bake::load_mesh(write_file("seam_n.obj", seam_obj("1/1/1 2/2/1 3/3/1 4/4/1", "2/-1/2 5/-4/2 3/3/2")));
  expect_same_rows(n, plain_n);
  EXPECT_EQ(n.positions.size(), 7u) << "positions 2 and 3 have two normals each";
  ASSERT_EQ(n.uv_sets.size(), 1u);
  EXPECT_EQ(n.uv_sets[0].corners, m.uv_sets[0].corners);
}

TEST(UvObj, ASetSomeCornersLackIsDroppedWithAWarning) {
  const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0.25 0.5\n";
  const Mesh plain = prt::bake::load_mesh(write_file("partial_plain.obj", v + "f 1 2 3\nf 2 4 3\n"));
  const fs::path path = write_file("partial.obj", v + "f 1/1 2/1 3/1\nf 2 4/1 3\n");
  const Mesh m = prt::bake::load_mesh(path);
  expect_same_rows(m, plain);
  EXPECT_TRUE(m.uv_sets.empty());
  ASSERT_EQ(m.warnings.size(), 1u);
  EXPECT_EQ(m.warnings[0], path.string() + ": 2 of 6 face corners have no texture coordinate (f v/vt); the file's texture "
                                           "coordinates are not read");

  // vt lines no corner refers to: no set, and nothing to say.
  const Mesh unused = prt::bake::load_mesh(write_file("unused_vt.obj", v + "f 1 2 3\n"));
  EXPECT_TRUE(unused.uv_sets.empty());
  EXPECT_TRUE(unused.warnings.empty());
  // Defects of vt are the file's, as before: a missing v, a bad number, an index past the last vt.
  expect_input_error(write_file("vt_short.obj", "vt 0.5\n" + v), "line 1: 'vt' needs 2 coordinates");
  expect_input_error(write_file("vt_nan.obj", "vt 0.5 nan\n" + v), "line 1: non-finite coordinate 'nan'");
  expect_input_error(write_file("vt_range.obj", v + "f 1/1 2/2 3/1\n"), "line 6: texcoord index 2 is out of range (the file has 1)");
}

// The shipped spider (data/spider.obj, also assimp-testmodels' OBJ/spider.obj): every corner has
// a vt; each triangle corner's UV is its file corner's vt, read here independently of the library.
TEST(UvObj, SpiderCornersAreTheFilesVt) {
  const fs::path path = fs::path(PRT_DATA_DIR) / "spider.obj";
  const Mesh m = prt::bake::load_mesh(path);
  std::ifstream in(path);
  std::vector<Vector2f> vt;
  Uvs want;
  for (std::string line; std::getline(in, line);) {
    std::istringstream ls(line);
    std::string kw;
    ls >> kw;
    if (kw == "vt") {
      std::string u, v;
      ls >> u >> v;
      vt.emplace_back(std::stof(u), 1.0f - std::stof(v));
    } else if (kw == "f") {
      std::vector<Vector2f> face;
      for (std::string c; ls >> c;) face.push_back(vt[std::stoul(c.substr(c.find('/') + 1)) - 1]);
      for (size_t k = 1; k + 1 < face.size(); ++k) want.insert(want.end(), {face[0], face[k], face[k + 1]});
    }
  }
  EXPECT_EQ(vt.size(), 302u);
  ASSERT_EQ(m.triangles.size(), 1368u);
  ASSERT_EQ(names(m), std::vector<std::string>{"vt"});
  EXPECT_EQ(m.uv_sets[0].corners, want);
  EXPECT_EQ(m.positions.size(), 918u) << "rows as without vt (918 (v, vn) pairs: test_mesh.cpp)";
}

// assimp-testmodels' OBJ files with vt lines: regr01.obj gives 2004 of its 8130 corners a vt (a
// partial set: dropped and said); WusonOBJ.obj (= data/wuson.obj) has one vt that all corners use.
TEST(UvObj, AssimpTestModelsWithVt) {
  const fs::path dir = "/usr/share/assimp/models/OBJ";
  ASSERT_TRUE(fs::is_directory(dir)) << dir << " is missing: install the Debian package assimp-testmodels (tools/run.sh does)";
  const Mesh regr = prt::bake::load_mesh(dir / "regr01.obj");
  EXPECT_TRUE(regr.uv_sets.empty());
  ASSERT_EQ(regr.warnings.size(), 1u);
  EXPECT_EQ(regr.warnings[0], (dir / "regr01.obj").string() +
                                  ": 6126 of 8130 face corners have no texture coordinate (f v/vt); the file's texture "
                                  "coordinates are not read");
  const Mesh wuson = prt::bake::load_mesh(dir / "WusonOBJ.obj");
  ASSERT_EQ(names(wuson), std::vector<std::string>{"vt"});
  EXPECT_EQ(wuson.uv_sets[0].corners, Uvs(3 * 3732, Vector2f(0, 0))) << "'vt 0.000000 1.000000' at every corner";
  EXPECT_EQ(wuson.positions.size(), prt::bake::load_mesh(fs::path(PRT_DATA_DIR) / "wuson.obj").positions.size());
}

// --- glTF -----------------------------------------------------------------------------------

const std::vector<Vector3f> kQuad = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
const std::vector<uint16_t> kQuadIndices = {0, 1, 2, 0, 2, 3};
const Uvs kUv0 = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
const std::vector<uint8_t> kUv1Bytes = {0, 0, 255, 0, 255, 255, 51, 102};
const Uvs kUv1 = {{0, 0}, {1, 0}, {1, 1}, {51 / 255.0f, 102 / 255.0f}};  // normalized: c / 255
const std::vector<uint16_t> kUv2Shorts = {0, 65535, 13107, 0, 65535, 65535, 0, 0};
const Uvs kUv2 = {{0, 1}, {13107 / 65535.0f, 0}, {1, 1}, {0, 0}};  // normalized: c / 65535

int vec2(Gltf& g, const Uvs& uv) {
  std::vector<float> flat;
  for (const Vector2f& p : uv) flat.insert(flat.end(), {p.x(), p.y()});
  return g.accessor(flat, 5126, "VEC2", uv.size());
}
template <class T> int normalized_vec2(Gltf& g, const std::vector<T>& values, int component_type) {
  const int a = g.accessor(values, component_type, "VEC2", values.size() / 2);
  g.doc["accessors"][static_cast<size_t>(a)]["normalized"] = true;
  return a;
}

// The corners of triangles `tris` (rows base + index) in a per-vertex set.
Uvs at_corners(const Uvs& per_vertex, const std::vector<Tri>& tris, uint32_t base) {
  Uvs out;
  for (const Tri& t : tris)
    for (uint32_t v : t) out.push_back(per_vertex[v - base]);
  return out;
}

TEST(UvGltf, TexcoordSetsFloatAndNormalizedFollowCornersAndMirrors) {
  // One quad with TEXCOORD_0 (float) and TEXCOORD_1 (normalized unsigned bytes), instanced twice:
  // plainly, and under a mirror (negative determinant: each triangle reversed, bake/mesh/mesh.h).
  Gltf g, plain_g;
  for (Gltf* x : {&g, &plain_g}) {
    json attributes = {{"POSITION", x->vec3(kQuad)}};
    if (x == &g) {
      attributes["TEXCOORD_0"] = vec2(*x, kUv0);
      attributes["TEXCOORD_1"] = normalized_vec2(*x, kUv1Bytes, 5121);
    }
    const int mesh = x->mesh({{"attributes", attributes}, {"indices", x->indices(kQuadIndices)}});
    x->node({{"mesh", mesh}}, true);
    x->node({{"mesh", mesh}, {"scale", {-1.0, 1.0, 1.0}}}, true);
  }
  const Mesh m = prt::bake::load_mesh(g.write("texcoords.gltf"));
  expect_same_rows(m, prt::bake::load_mesh(plain_g.write("no_texcoords.gltf")));
  const std::vector<Tri> tris = {{0, 1, 2}, {0, 2, 3}}, mirrored = {{4, 6, 5}, {4, 7, 6}};
  ASSERT_EQ(m.triangles, (std::vector<Tri>{tris[0], tris[1], mirrored[0], mirrored[1]}));
  ASSERT_EQ(names(m), (std::vector<std::string>{"TEXCOORD_0", "TEXCOORD_1"}));
  Uvs want0 = at_corners(kUv0, tris, 0), want1 = at_corners(kUv1, tris, 0);
  for (const Uvs* per_vertex : {&kUv0, &kUv1}) {
    Uvs& want = per_vertex == &kUv0 ? want0 : want1;
    const Uvs more = at_corners(*per_vertex, mirrored, 4);
    want.insert(want.end(), more.begin(), more.end());
  }
  EXPECT_EQ(m.uv_sets[0].corners, want0);
  EXPECT_EQ(m.uv_sets[1].corners, want1);
  EXPECT_TRUE(m.warnings.empty());

  // The same file as a .glb, and as instances (each its own sets).
  const Mesh glb = prt::bake::load_mesh(write_file("texcoords.glb", g.glb()));
  ASSERT_EQ(glb.uv_sets.size(), 2u);
  EXPECT_EQ(glb.uv_sets[1].corners, want1);
  const prt::bake::MeshInstances instances = prt::bake::load_mesh_instances(g.write("texcoords.gltf"));
  ASSERT_EQ(instances.instances.size(), 2u);
  const Mesh& second = instances.instances[1].mesh;
  ASSERT_EQ(names(second), (std::vector<std::string>{"TEXCOORD_0", "TEXCOORD_1"}));
  EXPECT_EQ(second.uv_sets[0].corners, at_corners(kUv0, {{0, 2, 1}, {0, 3, 2}}, 0));
  EXPECT_EQ(second.uv_sets[1].corners, at_corners(kUv1, {{0, 2, 1}, {0, 3, 2}}, 0));
}

TEST(UvGltf, LoadMeshKeepsASetOnlyWhenEveryPrimitiveHasIt) {
  // Primitive 0: TEXCOORD_0 and TEXCOORD_1; primitive 1: TEXCOORD_0 (normalized unsigned shorts)
  // and TEXCOORD_10 (sets are ordered by n, not by name).
  Gltf g;
  const int quad = g.vec3(kQuad), indices = g.indices(kQuadIndices);
  g.doc["meshes"].push_back(
      {{"primitives",
        {{{"attributes", {{"POSITION", quad}, {"TEXCOORD_0", vec2(g, kUv0)}, {"TEXCOORD_1", normalized_vec2(g, kUv1Bytes, 5121)}}},
          {"indices", indices}},
         {{"attributes", {{"POSITION", quad}, {"TEXCOORD_0", normalized_vec2(g, kUv2Shorts, 5123)}, {"TEXCOORD_10", vec2(g, kUv0)},
                          {"TEXCOORD_2", vec2(g, kUv1)}}},
          {"indices", indices}}}}});
  g.node({{"mesh", 0}}, true);
  const fs::path path = g.write("some_texcoords.gltf");
  const Mesh m = prt::bake::load_mesh(path);
  ASSERT_EQ(names(m), std::vector<std::string>{"TEXCOORD_0"});
  Uvs want = at_corners(kUv0, {{0, 1, 2}, {0, 2, 3}}, 0);
  const Uvs second = at_corners(kUv2, {{4, 5, 6}, {4, 6, 7}}, 4);
  want.insert(want.end(), second.begin(), second.end());
  EXPECT_EQ(m.uv_sets[0].corners, want);
  const std::string because = " primitive instances with triangles; not read (a texture coordinate set must cover every triangle)";
  EXPECT_EQ(m.warnings, (std::vector<std::string>{path.string() + ": TEXCOORD_1 is on 1 of 2" + because,
                                                  path.string() + ": TEXCOORD_2 is on 1 of 2" + because,
                                                  path.string() + ": TEXCOORD_10 is on 1 of 2" + because}));

  const prt::bake::MeshInstances instances = prt::bake::load_mesh_instances(path);
  ASSERT_EQ(instances.instances.size(), 2u);
  EXPECT_TRUE(instances.warnings.empty()) << "each instance keeps its own sets: nothing is dropped";
  EXPECT_EQ(names(instances.instances[0].mesh), (std::vector<std::string>{"TEXCOORD_0", "TEXCOORD_1"}));
  const Mesh& p1 = instances.instances[1].mesh;
  ASSERT_EQ(names(p1), (std::vector<std::string>{"TEXCOORD_0", "TEXCOORD_2", "TEXCOORD_10"}));
  EXPECT_EQ(p1.uv_sets[0].corners, at_corners(kUv2, {{0, 1, 2}, {0, 2, 3}}, 0));
  EXPECT_EQ(p1.uv_sets[1].corners, at_corners(kUv1, {{0, 1, 2}, {0, 2, 3}}, 0));
  EXPECT_EQ(p1.uv_sets[2].corners, at_corners(kUv0, {{0, 1, 2}, {0, 2, 3}}, 0));
}

TEST(UvGltf, MalformedTexcoordAccessorsAreRefused) {
  // A quad whose TEXCOORD_0 is built by `texcoord`; the message names the primitive and attribute.
  const auto refused = [](const std::string& name, const std::string& defect, auto&& texcoord) {
    Gltf g;
    const int positions = g.vec3(kQuad);
    const int uv = texcoord(g);
    g.node({{"mesh", g.mesh({{"attributes", {{"POSITION", positions}, {"TEXCOORD_0", uv}}}})}}, true);
    expect_input_error(g.write(name), defect);
  };
  refused("uv_vec3.gltf", "mesh 0 primitive 0 TEXCOORD_0 (accessor 1) is not VEC2",
          [](Gltf& g) { return g.vec3(kQuad); });
  refused("uv_bytes.gltf", "mesh 0 primitive 0 TEXCOORD_0 (accessor 1) is not normalized; integer components must be",
          [](Gltf& g) { return g.accessor(kUv1Bytes, 5121, "VEC2", 4); });
  refused("uv_signed.gltf", "TEXCOORD_0 (accessor 1) has unsupported componentType 5120",
          [](Gltf& g) { return normalized_vec2(g, kUv1Bytes, 5120); });
  refused("uv_count.gltf", "mesh 0 primitive 0 has 3 TEXCOORD_0 elements for 4 positions",
          [](Gltf& g) { return vec2(g, {{0, 0}, {1, 0}, {1, 1}}); });
  refused("uv_nan.gltf", "mesh 0 primitive 0 TEXCOORD_0 2 is not finite",
          [](Gltf& g) { return vec2(g, {{0, 0}, {1, 0}, {std::numeric_limits<float>::quiet_NaN(), 1}, {0, 1}}); });
  refused("uv_sparse.gltf", "TEXCOORD_0 (accessor 1) is sparse", [](Gltf& g) {
    const int a = vec2(g, kUv0);
    g.doc["accessors"][1]["sparse"] = {{"count", 1}, {"indices", {{"bufferView", 1}, {"componentType", 5123}}},
                                       {"values", {{"bufferView", 1}}}};
    return a;
  });
  refused("uv_missing.gltf", "TEXCOORD_0: accessor 7 does not exist", [](Gltf&) { return 7; });
}

// --- PLY ------------------------------------------------------------------------------------

// A quad (one 4-corner face) with per-vertex texture coordinates under the names `u` and `v`.
std::string ply_quad(const std::string& u, const std::string& v) {
  return "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float " + u +
         "\nproperty float " + v + "\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
         "0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0.25 1\n4 0 1 2 3\n";
}
const Uvs kPlyUv = {{0, 1}, {1, 1}, {1, 0}, {0.25f, 0}};  // (u, 1 − v)

TEST(UvPly, CommonPropertyNamesGiveOneSetWithVFlipped) {
  const std::string plain_ply = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                                "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                                "0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
  const Mesh plain = prt::bake::load_mesh(write_file("quad_plain.ply", plain_ply));
  for (const auto& [u, v] : {std::pair{"u", "v"}, {"s", "t"}, {"texture_u", "texture_v"}}) {
    SCOPED_TRACE(u);
    const Mesh m = prt::bake::load_mesh(write_file(std::string("quad_") + u + ".ply", ply_quad(u, v)));
    expect_same_rows(m, plain);
    ASSERT_EQ(names(m), std::vector<std::string>{"uv"});
    EXPECT_EQ(m.uv_sets[0].corners, at_corners(kPlyUv, {{0, 1, 2}, {0, 2, 3}}, 0));
  }
  // Only one of a pair, or another name: no set.
  EXPECT_TRUE(prt::bake::load_mesh(write_file("quad_ut.ply", ply_quad("u", "t"))).uv_sets.empty());

  // Binary, big endian, with flip_normals: the UVs follow the reversed corners.
  std::string bin = "ply\nformat binary_big_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                    "property float s\nproperty float t\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  auto put = [&](auto value) {
    char b[sizeof value];
    std::memcpy(b, &value, sizeof value);
    for (size_t i = sizeof value; i-- > 0;) bin += b[i];
  };
  const float rows[4][5] = {{0, 0, 0, 0, 0}, {1, 0, 0, 1, 0}, {1, 1, 0, 1, 1}, {0, 1, 0, 0.25f, 1}};
  for (const auto& row : rows)
    for (float x : row) put(x);
  put(uint8_t{4});
  for (int32_t i : {0, 1, 2, 3}) put(i);
  const Mesh flipped = prt::bake::load_mesh(write_file("quad_st.ply", bin), {.flip_normals = true});
  EXPECT_EQ(flipped.triangles, (std::vector<Tri>{{0, 2, 1}, {0, 3, 2}}));
  ASSERT_EQ(names(flipped), std::vector<std::string>{"uv"});
  EXPECT_EQ(flipped.uv_sets[0].corners, at_corners(kPlyUv, {{0, 2, 1}, {0, 3, 2}}, 0));
  expect_input_error(write_file("quad_bad_u.ply", ply_quad("u", "v").replace(ply_quad("u", "v").find("0.25"), 4, "0.2x")),
                     "malformed number '0.2x'");
}

// --- build_mesh, make_mesh, merge_meshes -----------------------------------------------------

prt::bake::Polygons quad_polygons() {
  prt::bake::Polygons p;
  p.positions = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(1, 1, 0), Eigen::Vector3d(0, 1, 0)};
  p.corner_position = {0, 1, 2, 3, 0, 2, 1};
  p.offsets = {0, 4, 7};
  p.uv_sets.push_back({"a", {{0, 0}, {1, 0}, {1, 1}, {0, 1}}, {0, 1, 2, 3, 3, 2, 1}});
  return p;
}

TEST(UvBuild, BuildMeshFansAndValidatesTheSets) {
  const Mesh m = prt::bake::build_mesh(quad_polygons(), "generated");
  ASSERT_EQ(names(m), std::vector<std::string>{"a"});
  EXPECT_EQ(m.uv_sets[0].corners, (Uvs{{0, 0}, {1, 0}, {1, 1}, {0, 0}, {1, 1}, {0, 1}, {0, 1}, {1, 1}, {1, 0}}));

  const auto expect_defect = prt::testing::expect_build_defect;
  auto bad = quad_polygons();
  bad.uv_sets[0].corner[5] = 4;
  expect_defect(bad, "texture coordinate set 'a': face 1: index 4 is out of range [0, 4)");
  bad = quad_polygons();
  bad.uv_sets[0].values[2].y() = INFINITY;
  expect_defect(bad, "texture coordinate set 'a': value 2 is not finite");
  bad = quad_polygons();
  bad.uv_sets[0].corner.pop_back();  // a reader's bug, not the file's
  EXPECT_THROW((void)prt::bake::build_mesh(bad, "generated"), prt::bake::ContractError);
}

TEST(UvBuild, MergeKeepsASetOnlyWhenEveryPartHasIt) {
  const std::vector<Vector3f> tri = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const Uvs a = {{0, 0}, {1, 0}, {0, 1}}, b = {{0.5f, 0.5f}, {0.25f, 0.5f}, {0.5f, 0.25f}};
  const Mesh one = prt::bake::make_mesh(tri, {{0, 1, 2}}, "one", {}, {{"TEXCOORD_0", a}, {"TEXCOORD_1", b}});
  const Mesh two = prt::bake::make_mesh(tri, {{0, 2, 1}}, "two", {}, {{"TEXCOORD_1", a}, {"TEXCOORD_0", b}});
  const Mesh bare = prt::bake::make_mesh(tri, {{0, 1, 2}}, "bare");
  EXPECT_TRUE(bare.uv_sets.empty());

  const Mesh both = prt::bake::merge_meshes(std::vector<Mesh>{one, two}, "both");
  ASSERT_EQ(names(both), (std::vector<std::string>{"TEXCOORD_0", "TEXCOORD_1"})) << "by name, in the first part's order";
  EXPECT_EQ(both.uv_sets[0].corners, (Uvs{a[0], a[1], a[2], b[0], b[1], b[2]}));
  EXPECT_EQ(both.uv_sets[1].corners, (Uvs{b[0], b[1], b[2], a[0], a[1], a[2]}));
  const Mesh with_ground = prt::bake::merge_meshes(std::vector<Mesh>{one, bare, two}, "with ground");
  EXPECT_TRUE(with_ground.uv_sets.empty());
  EXPECT_TRUE(with_ground.warnings.empty());
  EXPECT_EQ(with_ground.triangles.size(), 3u);

  // make_mesh checks what it is given.
  try {
    (void)prt::bake::make_mesh(tri, {{0, 1, 2}}, "short", {}, {{"s", {a[0], a[1]}}});
    ADD_FAILURE() << "a set of 2 corners for 1 triangle was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "short: texture coordinate set 's' has 2 corners for 1 triangles (needs 3 per triangle)");
  }
  try {
    (void)prt::bake::make_mesh(tri, {{0, 1, 2}}, "nan", {}, {{"s", {a[0], a[1], Vector2f(NAN, 0)}}});
    ADD_FAILURE() << "a NaN corner was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "nan: texture coordinate set 's': corner 2 is not finite");
  }
}

} // namespace
