// Tests of the glTF 2.0 reader behind load_mesh (bake/mesh/mesh.h, libbake/mesh/src/gltf_reader.cpp): tiny
// hand-written glTFs (JSON with base64 data-URI buffers, an external .bin, a .glb) for transforms,
// strips, fans, non-indexed primitives and normals; each defect the reader refuses; and a walk of
// Debian's assimp-testmodels glTF2 folder (good and broken public files) plus 2CylinderEngine.glb.
#include <bake/bake/vertex_bake.h>
#include <bake/core/error.h>
#include <bake/core/sha256.h>
#include <bake/integrators/integrator.h>
#include <bake/mesh/mesh.h>

#include <gltf_builder.h>
#include <mesh_files.h>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <sys/resource.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using nlohmann::json;
using prt::testing::Gltf;
using prt::testing::base64;
using prt::bake::InputError;
using prt::bake::Mesh;
using Tri = std::array<uint32_t, 3>;

namespace {

// Positions are transformed in double and rounded to float once: within half a float ulp of the
// double result, i.e. relative 2^-24 ≈ 6e-8 of the coordinate's magnitude; 1e-6 leaves room for
// the few ulps by which Eigen's TRS product may differ from the test's own composition.
constexpr double kPositionTolerance = 1e-6;
// Normals: one normalisation in double, one rounding to float and build_mesh's float renormalisation.
constexpr double kNormalTolerance = 1e-6;

fs::path tmp_dir() { return prt::testing::test_dir("gltf"); }
fs::path write_file(const std::string& name, const std::string& bytes) { return prt::testing::write_test_file(tmp_dir(), name, bytes); }

using prt::testing::expect_input_error;

Eigen::Vector3f face_normal(const Mesh& m, const Tri& t) {
  return (m.positions[t[1]] - m.positions[t[0]]).cross(m.positions[t[2]] - m.positions[t[0]]);
}

const std::vector<Eigen::Vector3f> kTriangle = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
const std::vector<Eigen::Vector3f> kTriangleNormals = {{0, 0, 1}, {0, 0.6f, 0.8f}, {0.6f, 0, 0.8f}};

TEST(Gltf, NodeTransformsComposeInDoubleAndRowsFollowInstances) {
  Gltf g;
  const int mesh = g.mesh({{"attributes", {{"POSITION", g.vec3(kTriangle)}, {"NORMAL", g.vec3(kTriangleNormals)}}}});
  // Parent: T·R·S; child: a matrix (column-major) with a shear, so the inverse transpose differs from the matrix.
  const std::vector<double> t = {10.0, -2.0, 0.5}, r = {0.0, 0.0, std::sin(0.3), std::cos(0.3)}, s = {2.0, 0.5, 3.0};
  const std::vector<double> matrix = {1, 0, 0, 0, 0.25, 1, 0, 0, 0, 0, 1, 0, 0.125, 7, -3, 1};
  const int child = g.node({{"mesh", mesh}, {"matrix", matrix}}, false);
  g.node({{"mesh", mesh}, {"translation", t}, {"rotation", r}, {"scale", s}, {"children", {child}}}, true);
  const Mesh m = prt::bake::load_mesh(g.write("two_nodes.gltf"));

  Eigen::Affine3d parent = Eigen::Translation3d(t[0], t[1], t[2]) * Eigen::Quaterniond(r[3], r[0], r[1], r[2]) *
                           Eigen::Scaling(s[0], s[1], s[2]);
  const Eigen::Matrix4d child_world = parent.matrix() * Eigen::Map<const Eigen::Matrix4d>(matrix.data());
  const Eigen::Matrix4d worlds[2] = {parent.matrix(), child_world};  // document order of instances: parent first (depth first)
  ASSERT_EQ(m.positions.size(), 6u) << "rows: the 3 vertices of each instance";
  ASSERT_EQ(m.triangles, (std::vector<Tri>{{0, 1, 2}, {3, 4, 5}}));
  EXPECT_EQ(m.normal_source, Mesh::NormalSource::File);
  for (int instance = 0; instance < 2; ++instance)
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d want = (worlds[instance] * kTriangle[k].cast<double>().homogeneous()).head<3>();
      const Eigen::Vector3f got = m.positions[instance * 3 + k];
      EXPECT_LT((got.cast<double>() - want).norm(), kPositionTolerance * want.norm()) << instance << " " << k;
      const Eigen::Vector3d n = (worlds[instance].topLeftCorner<3, 3>().inverse().transpose() * kTriangleNormals[k].cast<double>()).normalized();
      EXPECT_LT((m.normals[instance * 3 + k].cast<double>() - n).norm(), kNormalTolerance) << instance << " " << k;
    }
}

TEST(Gltf, StripAndFanBecomeTrianglesWithConsistentWinding) {
  // A zig-zag strip and a fan, both in the plane z = 0 and counter-clockwise seen from +z.
  const std::vector<Eigen::Vector3f> strip = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 2, 0}};
  const std::vector<Eigen::Vector3f> fan = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {-1, 1, 0}};
  for (const bool indexed : {true, false}) {
    SCOPED_TRACE(indexed ? "indexed" : "non-indexed");
    Gltf g;
    json sp = {{"attributes", {{"POSITION", g.vec3(strip)}}}, {"mode", 5}};
    json fp = {{"attributes", {{"POSITION", g.vec3(fan)}}}, {"mode", 6}};
    if (indexed) sp["indices"] = g.indices({0, 1, 2, 3, 4}), fp["indices"] = g.indices({0, 1, 2, 3, 4});
    g.node({{"mesh", g.mesh(sp)}}, true);
    g.node({{"mesh", g.mesh(fp)}}, true);
    const Mesh m = prt::bake::load_mesh(g.write("strip_fan.gltf"));
    ASSERT_EQ(m.positions.size(), 10u);
    // glTF 2.0 specification, "Meshes": strip triangle i = (i, i+1+i%2, i+2−i%2); fan triangle i = (i+1, i+2, 0).
    EXPECT_EQ(m.triangles, (std::vector<Tri>{{0, 1, 2}, {1, 3, 2}, {2, 3, 4}, {6, 7, 5}, {7, 8, 5}, {8, 9, 5}}));
    for (const Tri& t : m.triangles) EXPECT_GT(face_normal(m, t).z(), 0.0f) << "every triangle front-facing +z, as the file's first one";
  }
}

TEST(Gltf, NonIndexedTrianglesAndComputedNormalsWhenAPrimitiveHasNone) {
  Gltf g;
  const std::vector<Eigen::Vector3f> two = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  g.node({{"mesh", g.mesh({{"attributes", {{"POSITION", g.vec3(two)}}}})}}, true);
  g.node({{"mesh", g.mesh({{"attributes", {{"POSITION", g.vec3(kTriangle)}, {"NORMAL", g.vec3(kTriangleNormals)}}}})},
          {"translation", {0.0, 0.0, 1.0}}}, true);
  const Mesh m = prt::bake::load_mesh(g.write("non_indexed.gltf"));
  ASSERT_EQ(m.positions.size(), 9u) << "no welding: every glTF vertex is a row";
  EXPECT_EQ(m.triangles, (std::vector<Tri>{{0, 1, 2}, {3, 4, 5}, {6, 7, 8}}));
  EXPECT_EQ(m.normal_source, Mesh::NormalSource::AngleWeighted) << "one primitive has no NORMAL: all are computed";
  const auto want = prt::bake::welded_angle_weighted_normals(m.positions, m.triangles);
  for (size_t v = 0; v < m.normals.size(); ++v) EXPECT_EQ(m.normals[v], want[v]) << v;
}

TEST(Gltf, MirroringTransformKeepsTheFrontFace) {
  Gltf g;
  const int mesh = g.mesh({{"attributes", {{"POSITION", g.vec3(kTriangle)}}}});
  g.node({{"mesh", mesh}}, true);
  g.node({{"mesh", mesh}, {"scale", {-1.0, 1.0, 1.0}}}, true);
  const Mesh m = prt::bake::load_mesh(g.write("mirror.gltf"));
  ASSERT_EQ(m.triangles.size(), 2u);
  EXPECT_EQ(m.triangles[1], (Tri{3, 5, 4})) << "negative determinant: winding reversed (glTF 2.0 specification, 'Meshes')";
  EXPECT_GT(face_normal(m, m.triangles[0]).z(), 0.0f);
  EXPECT_GT(face_normal(m, m.triangles[1]).z(), 0.0f);
}

TEST(Gltf, GlbAndExternalBufferReadTheSameAsEmbedded) {
  Gltf g;
  g.node({{"mesh", g.mesh({{"attributes", {{"POSITION", g.vec3(kTriangle)}}}, {"indices", g.indices({0, 1, 2})}})}}, true);
  const Mesh embedded = prt::bake::load_mesh(g.write("same.gltf"));
  const Mesh glb = prt::bake::load_mesh(write_file("same.glb", g.glb()));
  write_file("same_external.bin", g.bin);
  json d = g.doc;
  d["buffers"] = {{{"byteLength", g.bin.size()}, {"uri", "same_external.bin"}}};
  const Mesh external = prt::bake::load_mesh(write_file("same_external.gltf", d.dump()));
  for (const Mesh* m : {&glb, &external}) {
    EXPECT_EQ(m->positions, embedded.positions);
    EXPECT_EQ(m->triangles, embedded.triangles);
  }
}

// A .gltf and its external buffer are one input: a changed .bin must change the source digest
// (a resumed sharded bake compares it), and the digest is defined (bake/mesh/mesh.h) as the .gltf's
// bytes followed by each buffer file's hex digest. Images are neither read nor hashed.
TEST(Gltf, SourceDigestCoversExternalBuffersNotImages) {
  Gltf g;
  g.node({{"mesh", g.mesh({{"attributes", {{"POSITION", g.vec3(kTriangle)}}}, {"indices", g.indices({0, 1, 2})}})}}, true);
  const auto bytes_of = [](const std::string& s) { return std::as_bytes(std::span(s.data(), s.size())); };
  json d = g.doc;
  d["buffers"] = {{{"byteLength", g.bin.size()}, {"uri", "digest_buffer.bin"}}};
  d["images"] = {{{"uri", "digest_texture.png"}}};
  const std::string text = d.dump();
  const fs::path gltf = write_file("digest.gltf", text);
  write_file("digest_buffer.bin", g.bin);
  write_file("digest_texture.png", "not a png");

  const std::string want = [&] {
    prt::bake::Sha256 h;
    h.update(bytes_of(text));
    const std::string bin_digest = prt::bake::sha256_bytes(bytes_of(g.bin));
    h.update(bytes_of(bin_digest));
    return h.hex_digest();
  }();
  const Mesh first = prt::bake::load_mesh(gltf);
  EXPECT_EQ(first.source_sha256, want);
  EXPECT_NE(first.source_sha256, prt::bake::sha256_bytes(bytes_of(text))) << "the buffer is part of the input";
  EXPECT_EQ(prt::bake::load_mesh_instances(gltf).source_sha256, want) << "scene instances: the same digest";

  write_file("digest_texture.png", "another texture, same geometry");
  EXPECT_EQ(prt::bake::load_mesh(gltf).source_sha256, want) << "images are not part of a bake's input";

  std::string changed = g.bin;
  changed[0] = static_cast<char>(changed[0] ^ 1);  // the first position's lowest mantissa bit
  write_file("digest_buffer.bin", changed);
  const Mesh second = prt::bake::load_mesh(gltf);
  EXPECT_NE(second.source_sha256, want) << "a changed buffer changes the digest";
  EXPECT_NE(second.positions[0], first.positions[0]);

  const Mesh embedded = prt::bake::load_mesh(g.write("digest_embedded.gltf"));
  EXPECT_EQ(embedded.source_sha256, prt::bake::sha256_file(tmp_dir() / "digest_embedded.gltf")) << "one file: as sha256sum";
}

TEST(Gltf, PunctualLightsAreNotBakedAndSaySo) {
  Gltf g;
  const int points = g.vec3(kTriangle);
  g.doc["meshes"].push_back({{"primitives", {{{"attributes", {{"POSITION", points}}}}}}});
  g.node({{"mesh", 0}}, true);
  g.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  g.doc["extensions"] = {{"KHR_lights_punctual",
                          {{"lights", {{{"type", "point"}, {"intensity", 10}}, {{"type", "directional"}}}}}}};
  const Mesh m = prt::bake::load_mesh(g.write("lights.gltf"));
  EXPECT_EQ(m.triangles.size(), 1u);
  ASSERT_EQ(m.warnings.size(), 1u);
  EXPECT_NE(m.warnings[0].find("2 punctual light(s) (KHR_lights_punctual) are not baked"), std::string::npos)
      << m.warnings[0];
}

TEST(Gltf, PointAndLinePrimitivesAreSkippedWithACountedWarning) {
  Gltf g;
  const int points = g.vec3(kTriangle);
  g.doc["meshes"].push_back({{"primitives", {{{"attributes", {{"POSITION", points}}}, {"mode", 0}},
                                             {{"attributes", {{"POSITION", points}}}, {"mode", 3}},
                                             {{"attributes", {{"POSITION", points}}}}}}});
  g.node({{"mesh", 0}}, true);
  const fs::path path = g.write("lines.gltf");
  const Mesh m = prt::bake::load_mesh(path);
  EXPECT_EQ(m.triangles.size(), 1u);
  EXPECT_EQ(m.positions.size(), 3u) << "skipped primitives give no rows";
  ASSERT_EQ(m.warnings.size(), 1u);
  EXPECT_EQ(m.warnings[0], path.string() + ": 2 point or line primitive instance(s) skipped (only triangles are baked)")
      << "the file is named once";

  Gltf only;
  only.node({{"mesh", only.mesh({{"attributes", {{"POSITION", only.vec3(kTriangle)}}}, {"mode", 1}})}}, true);
  expect_input_error(only.write("only_lines.gltf"), "no triangles");
}

TEST(Gltf, DefectsAreOneLineInputErrorsNamingFileAndDefect) {
  const auto base = [] {
    Gltf g;
    g.node({{"mesh", g.mesh({{"attributes", {{"POSITION", g.vec3(kTriangle)}}}, {"indices", g.indices({0, 1, 2})}})}}, true);
    return g;
  };
  {
    Gltf g = base();
    g.node({{"mesh", g.mesh({{"attributes", {{"POSITION", 0}}}, {"indices", g.indices({0, 1, 3})}})}}, true);
    expect_input_error(g.write("index_range.gltf"), "index 2 is 3, out of range [0, 3)");
  }
  {
    Gltf g = base();
    json d = g.doc;
    d["buffers"] = {{{"byteLength", g.bin.size()}, {"uri", "no_such_file.bin"}}};
    expect_input_error(write_file("missing_bin.gltf", d.dump()), "no_such_file.bin");
    d["buffers"] = {{{"byteLength", g.bin.size() + 4}, {"uri", "data:application/octet-stream;base64," + base64(g.bin)}}};
    expect_input_error(write_file("short_buffer.gltf", d.dump()), "not a valid glTF");
    g.doc["bufferViews"][0]["byteLength"] = 1000;
    expect_input_error(g.write("view_past_buffer.gltf"), "lies past the end of buffer 0");
  }
  {
    Gltf g = base();
    g.doc["accessors"][0]["byteOffset"] = 4;
    expect_input_error(g.write("accessor_past_view.gltf"), "lies past the end of buffer view 0");
  }
  for (const float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    Gltf g;
    g.node({{"mesh", g.mesh({{"attributes", {{"POSITION", g.vec3({{0, 0, 0}, {1, bad, 0}, {0, 1, 0}})}}}})}}, true);
    expect_input_error(g.write("non_finite.gltf"), "POSITION 1 is not finite");
  }
  {
    Gltf g = base();
    g.doc["nodes"][0]["children"] = {0};
    expect_input_error(g.write("self_child.gltf"), "recursive node graph: node 0");
    g.node({{"children", {0}}}, false);
    g.doc["nodes"][0]["children"] = {1};
    expect_input_error(g.write("cycle.gltf"), "recursive node graph");
    g.doc["nodes"][0]["children"] = json::array();
    g.doc["scenes"][0]["nodes"] = {1};
    g.doc["nodes"].push_back({{"children", {0}}});
    g.doc["nodes"][1]["children"] = {0, 2};
    expect_input_error(g.write("two_parents.gltf"), "node 0 is reached twice");
  }
  {
    Gltf g = base();
    g.doc.erase("scenes");
    g.doc.erase("scene");
    expect_input_error(g.write("no_scene.gltf"), "no scene");
    Gltf h = base();
    h.doc["scene"] = 3;
    expect_input_error(h.write("bad_default_scene.gltf"), "scene 3 does not exist");
  }
  {
    Gltf g = base();
    g.doc["accessors"][1]["componentType"] = 5126;  // FLOAT indices
    expect_input_error(g.write("float_indices.gltf"), "indices (accessor 1) has unsupported componentType 5126");
    Gltf h = base();
    h.doc["accessors"][0]["componentType"] = 5123;  // UNSIGNED_SHORT positions
    expect_input_error(h.write("short_positions.gltf"), "POSITION (accessor 0) has unsupported componentType 5123");
    Gltf v = base();
    v.doc["accessors"][0]["type"] = "VEC2";
    expect_input_error(v.write("vec2_positions.gltf"), "POSITION (accessor 0) is not VEC3");
  }
  {
    Gltf g = base();
    g.doc["nodes"][0]["mesh"] = 9;
    expect_input_error(g.write("no_mesh.gltf"), "refers to mesh 9");
    expect_input_error(write_file("garbage.gltf", "{\"asset\": "), "not a valid glTF");
    expect_input_error(write_file("garbage.glb", std::string("glTF\x02\0\0\0garbage", 15)), "not a valid glTF");
  }
  {
    // glTF 1.0 (Debian's assimp test models hold several): named, not "no scene".
    Gltf g = base();
    g.doc["asset"] = {{"version", "1.0.2"}};
    expect_input_error(g.write("v1.gltf"), "is glTF 1.0.2 (asset.version): only glTF 2.0 is read");
    g.doc["asset"] = {{"version", 1}};
    expect_input_error(g.write("v1_number.gltf"), "is glTF 1 (asset.version)");
    std::string glb1 = base().glb();
    glb1[4] = '\x01';
    expect_input_error(write_file("v1.glb", glb1), "is a glTF 1.0 binary (.glb container version 1)");
  }
}

// Peak resident memory of this process so far, in bytes (Linux: ru_maxrss is in KiB).
long long peak_rss_bytes() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<long long>(u.ru_maxrss) * 1024;
}

TEST(Gltf, HostileFilesAreRefusedBeforeTinygltfReadsThem) {
  const auto triangle = [] {
    Gltf g;
    g.node({{"mesh", g.mesh({{"attributes", {{"POSITION", g.vec3(kTriangle)}}}})}}, true);
    return g;
  };
  // Draco: the accessors have no buffer view (the data is in the extension's). tinygltf refused it
  // with "accessor[1] invalid bufferView"; the extension is named, in .gltf and .glb alike.
  {
    Gltf g = triangle();
    g.doc["accessors"].push_back({{"componentType", 5123}, {"type", "SCALAR"}, {"count", 3}});
    g.doc["meshes"][0]["primitives"][0]["indices"] = 1;
    g.doc["meshes"][0]["primitives"][0]["extensions"] = {{"KHR_draco_mesh_compression", {{"bufferView", 0}, {"attributes", {{"POSITION", 0}}}}}};
    g.doc["extensionsUsed"] = g.doc["extensionsRequired"] = {"KHR_draco_mesh_compression"};
    expect_input_error(g.write("draco.gltf"), "requires extension 'KHR_draco_mesh_compression', which is not supported");
    expect_input_error(write_file("draco.glb", g.glb()), "requires extension 'KHR_draco_mesh_compression'");
  }
  // 10^6 nested arrays in "extras": tinygltf copied them recursively and overflowed the stack.
  {
    std::string text = triangle().embedded();
    text.pop_back();  // the closing '}'
    text += ",\"extras\": " + std::string(1000000, '[') + std::string(1000000, ']') + "}";
    expect_input_error(write_file("deep.gltf", text), "JSON nested deeper than 128 levels");
  }
  // A 1 GiB file (sparse) named by a 36-byte buffer and by an image: neither is read. The buffer
  // was read whole before tinygltf compared its size; the image was read and discarded.
  {
    const fs::path big = tmp_dir() / "big.bin";
    std::ofstream(big, std::ios::binary).put('\0');
    fs::resize_file(big, size_t{1} << 30);
    const long long rss_before = peak_rss_bytes();
    Gltf g = triangle();
    json d = json::parse(g.embedded());
    d["images"] = {{{"uri", "big.bin"}}};
    EXPECT_EQ(prt::bake::load_mesh(write_file("big_image.gltf", d.dump())).triangles.size(), 1u);
    d.erase("images");
    d["buffers"][0]["uri"] = "big.bin";
    expect_input_error(write_file("big_buffer.gltf", d.dump()), "is 1073741824 bytes, more than the 36 bytes left of what the glTF's buffers declare");
    // The bound: what the buffers declare (36 bytes) and the files' own sizes, not the 1 GiB.
    constexpr long long kSlack = 64ll << 20;  // allocator and page-cache noise, far below 1 GiB
    EXPECT_LT(peak_rss_bytes() - rss_before, kSlack);
    fs::remove(big);
  }
}

// Debian's assimp-testmodels: the public glTF2 test files, good and broken.
const fs::path kAssimpGltf2 = "/usr/share/assimp/models/glTF2";

TEST(Gltf, EveryAssimpTestFileLoadsOrIsRefusedCleanly) {
  ASSERT_TRUE(fs::is_directory(kAssimpGltf2)) << kAssimpGltf2 << " is missing: install the Debian package assimp-testmodels (tools/run.sh does)";
  size_t loaded = 0, refused = 0;
  for (const auto& entry : fs::recursive_directory_iterator(kAssimpGltf2)) {
    const std::string ext = entry.path().extension().string();
    if (!entry.is_regular_file() || (ext != ".gltf" && ext != ".glb")) continue;
    SCOPED_TRACE(entry.path().string());
    try {
      const Mesh m = prt::bake::load_mesh(entry.path());
      ASSERT_FALSE(m.triangles.empty());
      for (const auto& p : m.positions) ASSERT_TRUE(p.allFinite());
      ++loaded;
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
      EXPECT_NE(what.find(entry.path().string()), std::string::npos) << what;
      std::printf("refused: %s\n", what.c_str());
      ++refused;
    }  // any other exception fails the test
  }
  std::printf("assimp-testmodels glTF2: %zu loaded, %zu refused\n", loaded, refused);
  RecordProperty("loaded", static_cast<int>(loaded));
  RecordProperty("refused", static_cast<int>(refused));
  EXPECT_GT(loaded, 0u);
}

TEST(Gltf, AssetGeneratorTriangleModesGiveTheFrontFacingQuad) {
  // glTF-Asset-Generator Mesh_PrimitiveMode: a unit quad facing +z (the generator's camera side)
  // as a strip, a fan and triangles, non-indexed (04–06) and indexed (11–15, the last three with
  // different index component types). 00–03 and 07–10 are points and lines (refused above).
  const fs::path dir = kAssimpGltf2 / "glTF-Asset-Generator" / "Mesh_PrimitiveMode";
  ASSERT_TRUE(fs::is_directory(dir)) << dir << " is missing: install the Debian package assimp-testmodels (tools/run.sh does)";
  for (const char* n : {"04", "05", "06", "11", "12", "13", "14", "15"}) {
    const fs::path path = dir / (std::string("Mesh_PrimitiveMode_") + n + ".gltf");
    SCOPED_TRACE(path.filename().string());
    const Mesh m = prt::bake::load_mesh(path);
    ASSERT_EQ(m.triangles.size(), 2u);
    float area = 0.0f;
    for (const Tri& t : m.triangles) {
      const Eigen::Vector3f fn = face_normal(m, t);
      EXPECT_GT(fn.z(), 0.0f) << "front face +z";
      EXPECT_EQ(fn.x(), 0.0f);
      EXPECT_EQ(fn.y(), 0.0f);
      area += 0.5f * fn.z();
    }
    EXPECT_FLOAT_EQ(area, 1.0f) << "the two triangles cover the unit quad";
  }
}

TEST(Gltf, InstancesAreNamedByNodePathAndConcatenateToLoadMesh) {
  Gltf g;
  const int one = g.mesh({{"attributes", {{"POSITION", g.vec3(kTriangle)}}}});
  g.doc["meshes"].push_back({{"primitives", {{{"attributes", {{"POSITION", g.vec3(kTriangle)}, {"NORMAL", g.vec3(kTriangleNormals)}}}},
                                             {{"attributes", {{"POSITION", g.vec3(kTriangle)}}}}}}});
  const int two = static_cast<int>(g.doc["meshes"].size() - 1);
  // Children of "root": "a/b" ('/' is not a separator inside a name), two "wheel"s and a literal
  // "wheel~2" (the repeat takes the first free suffix), an unnamed node with a two-primitive mesh.
  const int ab = g.node({{"name", "a/b"}, {"mesh", one}}, false);
  const int w1 = g.node({{"name", "wheel"}, {"mesh", one}, {"translation", {1.0, 0.0, 0.0}}}, false);
  const int w2 = g.node({{"name", "wheel"}, {"mesh", one}, {"translation", {2.0, 0.0, 0.0}}}, false);
  const int w3 = g.node({{"name", "wheel~2"}, {"mesh", one}}, false);
  const int unnamed = g.node({{"mesh", two}}, false);
  g.node({{"name", "root"}, {"children", {ab, w1, w2, w3, unnamed}}}, true);
  const fs::path path = g.write("named.gltf");
  const prt::bake::MeshInstances m = prt::bake::load_mesh_instances(path);
  std::vector<std::string> names;
  for (const auto& in : m.instances) names.push_back(in.name);
  EXPECT_EQ(names, (std::vector<std::string>{"root/a_b", "root/wheel", "root/wheel~3", "root/wheel~2", "root/node4", "root/node4#p1"}));
  EXPECT_EQ(m.instances[4].mesh.normal_source, Mesh::NormalSource::File) << "an instance keeps its own primitive's normals";
  EXPECT_EQ(m.instances[5].mesh.normal_source, Mesh::NormalSource::AngleWeighted);
  EXPECT_EQ(m.instances[2].mesh.positions[1], Eigen::Vector3f(3, 0, 0)) << "world space";
  // load_mesh's rows are the instances' rows, in the same order (the same walk).
  const Mesh all = prt::bake::load_mesh(path);
  std::vector<Eigen::Vector3f> rows;
  for (const auto& in : m.instances) rows.insert(rows.end(), in.mesh.positions.begin(), in.mesh.positions.end());
  EXPECT_EQ(all.positions, rows);
  EXPECT_EQ(m.source_sha256, all.source_sha256);
}

TEST(Gltf, TwoCylinderEngineLoadsCompletely) {
  const fs::path path = kAssimpGltf2 / "2CylinderEngine-glTF-Binary" / "2CylinderEngine.glb";
  ASSERT_TRUE(fs::exists(path)) << path << " is missing: install the Debian package assimp-testmodels (tools/run.sh does)";
  const Mesh m = prt::bake::load_mesh(path);
  EXPECT_EQ(m.triangles.size(), 121496u);
  EXPECT_EQ(m.normal_source, Mesh::NormalSource::File);
}

// A far glTF node (translation (1e5, −2e5, 3e5), scale 1e-4) over the bunny's positions: kept in
// double through the node transform and baked relative to the mesh origin, so silhouette AO
// equals the original's within 1e-6 (the reason: tests/bake/test_far_origin.cpp).
TEST(Gltf, FarNodeTransformBakesTheOriginalsAo) {
  const Mesh near = prt::bake::load_mesh(fs::path(PRT_DATA_DIR) / "bunny.obj");
  ASSERT_LT(near.positions.size(), 65536u);
  std::vector<uint16_t> idx;
  for (const Tri& t : near.triangles)
    for (uint32_t i : t) idx.push_back(static_cast<uint16_t>(i));
  Gltf g;
  const int mesh = g.mesh({{"attributes", {{"POSITION", g.vec3(near.positions)}}}, {"indices", g.indices(idx)}});
  g.node({{"mesh", mesh}, {"translation", {1e5, -2e5, 3e5}}, {"scale", {1e-4, 1e-4, 1e-4}}}, true);
  const Mesh far = prt::bake::load_mesh(g.write("far_bunny.gltf"));
  ASSERT_EQ(far.positions.size(), near.positions.size());
  EXPECT_NE(far.origin, Eigen::Vector3d::Zero());
  auto ao = [](const Mesh& m) {
    prt::bake::IntegratorSpec spec;
    spec.silhouette_k = 1024;
    prt::bake::ProductRequest request;
    request.ao = true;
    const prt::bake::Topology topo = prt::bake::build_topology(m);
    return prt::bake::bake_vertices(m, topo, *prt::bake::make_integrator(spec, m, topo, request)).values;
  };
  const auto a = ao(near), b = ao(far);
  for (size_t v = 0; v < a.size(); ++v) EXPECT_NEAR(a[v], b[v], 1e-6) << "vertex " << v;
}

} // namespace
