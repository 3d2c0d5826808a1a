// Tests for bake/mesh/mesh.h: the format readers and build_mesh, vertex-order and normal contracts,
// the source digest, welded topology, and hostile inputs.
#include <bake/core/error.h>
#include <bake/core/sha256.h>
#include <bake/mesh/mesh.h>

#include <mesh_files.h>

#include <Eigen/Geometry>

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using prt::bake::InputError;
using prt::bake::Mesh;
using Eigen::Vector3f;
using Tri = std::array<uint32_t, 3>;

namespace {

// Normals are normalised in float: |n| is 1 to a few ulps.
constexpr float kUnitTolerance = 1e-6f;
// Angle-weighted sums are done in double and rounded to float once.
constexpr float kNormalTolerance = 1e-6f;

fs::path tmp_dir() { return prt::testing::test_dir("mesh"); }
fs::path write_file(const std::string& name, const std::string& bytes) { return prt::testing::write_test_file(tmp_dir(), name, bytes); }

template <class T>
void append_raw(std::string& s, const T& v) {
  s.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

bool bits_equal(const Vector3f& a, const Vector3f& b) { return std::memcmp(a.data(), b.data(), sizeof(float) * 3) == 0; }

void expect_unit_finite_normals(const Mesh& m) {
  ASSERT_EQ(m.normals.size(), m.positions.size()) << "one normal per output vertex";
  for (size_t v = 0; v < m.normals.size(); ++v) {
    ASSERT_TRUE(m.normals[v].allFinite()) << m.source << ": normal " << v << " is not finite";
    ASSERT_NEAR(m.normals[v].norm(), 1.0f, kUnitTolerance) << m.source << ": normal " << v << " is not unit";
  }
}

// An OBJ parsed independently of the library (positive indices, as in the shipped data).
struct ObjFile {
  std::vector<Vector3f> v, vn;
  std::vector<std::vector<std::pair<int, int>>> faces;  // (position, normal or -1), 0-based
  size_t triangles = 0;
};

ObjFile parse_obj(const fs::path& p) {
  ObjFile obj;
  std::ifstream in(p);
  for (std::string line; std::getline(in, line);) {
    std::istringstream ls(line);
    std::string kw;
    ls >> kw;
    if (kw == "v" || kw == "vn") {
      std::string x, y, z;
      ls >> x >> y >> z;
      (kw == "v" ? obj.v : obj.vn).emplace_back(std::strtof(x.c_str(), nullptr), std::strtof(y.c_str(), nullptr),
                                                std::strtof(z.c_str(), nullptr));
    } else if (kw == "f") {
      std::vector<std::pair<int, int>> face;
      for (std::string c; ls >> c;) {
        const auto s1 = c.find('/');
        const int pos = std::stoi(c.substr(0, s1)) - 1;
        int nrm = -1;
        if (s1 != std::string::npos) {
          const auto s2 = c.find('/', s1 + 1);
          if (s2 != std::string::npos && s2 + 1 < c.size()) nrm = std::stoi(c.substr(s2 + 1)) - 1;
        }
        face.emplace_back(pos, nrm);
      }
      obj.triangles += face.size() - 2;
      obj.faces.push_back(face);
    }
  }
  return obj;
}

// --- the shipped meshes -----------------------------------------------------------------------

struct RealMesh {
  const char* name;
  size_t positions, triangles;
};

class RealMeshes : public ::testing::TestWithParam<RealMesh> {};

TEST_P(RealMeshes, CountsInEqualCountsOutAndRowsAreTheFilesVertices) {
  const RealMesh expect = GetParam();
  const fs::path path = fs::path(PRT_DATA_DIR) / expect.name;
  const ObjFile obj = parse_obj(path);
  // The data README's numbers, and our independent parse, agree before we test the library.
  ASSERT_EQ(obj.v.size(), expect.positions);
  ASSERT_EQ(obj.triangles, expect.triangles);

  // Without file normals the rows are exactly the file's `v` lines, in order: non-manifold
  // ("complex") vertices must not be duplicated or shifted, and nothing may be printed.
  testing::internal::CaptureStderr();
  const Mesh plain = prt::bake::load_mesh(path, {.use_file_normals = false});
  const std::string chatter = testing::internal::GetCapturedStderr();
  EXPECT_EQ(chatter, "") << "reading must not print (libbake is silent)";
  EXPECT_EQ(plain.file_positions, obj.v.size());
  EXPECT_EQ(plain.file_faces, obj.faces.size());
  ASSERT_EQ(plain.positions.size(), obj.v.size()) << "rows must equal the file's v lines";
  ASSERT_EQ(plain.triangles.size(), obj.triangles) << "every input triangle must reach the output";
  EXPECT_EQ(plain.normal_source, Mesh::NormalSource::AngleWeighted);
  for (size_t i = 0; i < obj.v.size(); ++i) {
    ASSERT_TRUE(bits_equal(plain.positions[i], obj.v[i])) << "row " << i << " is not file vertex " << i;
    ASSERT_EQ(plain.source_position[i], i);
  }
  size_t t = 0;
  for (const auto& f : obj.faces)
    for (size_t k = 1; k + 1 < f.size(); ++k, ++t) {
      const Tri want = {uint32_t(f[0].first), uint32_t(f[k].first), uint32_t(f[k + 1].first)};
      ASSERT_EQ(plain.triangles[t], want) << "triangle " << t << " is not the fan of the file's face";
    }
  expect_unit_finite_normals(plain);

  // With file normals: the first rows are still the file's positions; each further distinct
  // (position, normal value) pair is appended.
  const Mesh withn = prt::bake::load_mesh(path);
  std::set<std::pair<int, std::array<float, 3>>> pairs;
  std::set<int> referenced;
  for (const auto& f : obj.faces)
    for (const auto& [p, n] : f) {
      referenced.insert(p);
      if (n >= 0) pairs.insert({p, {obj.vn[size_t(n)].x(), obj.vn[size_t(n)].y(), obj.vn[size_t(n)].z()}});
    }
  const size_t expected_rows = obj.vn.empty() ? obj.v.size() : obj.v.size() + pairs.size() - referenced.size();
  ASSERT_EQ(withn.positions.size(), expected_rows) << "one row per position plus one per extra (position, normal) pair";
  ASSERT_EQ(withn.triangles.size(), obj.triangles);
  EXPECT_EQ(withn.normal_source, obj.vn.empty() ? Mesh::NormalSource::AngleWeighted : Mesh::NormalSource::File);
  for (size_t v = 0; v < withn.positions.size(); ++v) {
    if (v < obj.v.size()) {
      ASSERT_EQ(withn.source_position[v], v);
    }
    ASSERT_TRUE(bits_equal(withn.positions[v], obj.v[withn.source_position[v]])) << "vertex " << v;
  }
  const auto computed = prt::bake::welded_angle_weighted_normals(withn.positions, withn.triangles);
  t = 0;
  for (const auto& f : obj.faces) {
    for (size_t k = 1; k + 1 < f.size(); ++k, ++t) {
      for (int c = 0; c < 3; ++c) {
        const auto& corner = f[c == 0 ? 0 : k + size_t(c) - 1];
        const uint32_t ov = withn.triangles[t][size_t(c)];
        ASSERT_EQ(withn.source_position[ov], uint32_t(corner.first)) << "triangle " << t;
        if (corner.second >= 0) {
          // A zero-length file normal (spider.obj has one: vn 488) falls back to the welded
          // angle-weighted normal, as documented.
          const Vector3f& file_n = obj.vn[size_t(corner.second)];
          const Vector3f want = file_n.norm() > 0 ? file_n.normalized() : computed[ov];
          ASSERT_LT((withn.normals[ov] - want).norm(), kNormalTolerance) << "triangle " << t << " corner " << c;
        }
      }
    }
  }
  expect_unit_finite_normals(withn);
}

INSTANTIATE_TEST_SUITE_P(Data, RealMeshes,
                         ::testing::Values(RealMesh{"spider.obj", 762, 1368}, RealMesh{"wuson.obj", 2117, 3732},
                                           RealMesh{"bunny.obj", 1839, 3674}),
                         [](const ::testing::TestParamInfo<RealMesh>& p) {
                           return std::string(p.param.name).substr(0, std::strlen(p.param.name) - 4);
                         });

TEST(MeshLoad, SpiderHardEdgesSplitAndItsMissingMtlIsNotReported) {
  const Mesh m = prt::bake::load_mesh(fs::path(PRT_DATA_DIR) / "spider.obj");
  // 918 distinct (v, vn) pairs over 762 positions (counted with awk over the file).
  EXPECT_EQ(m.positions.size(), 918u);
  EXPECT_EQ(m.file_positions, 762u);
  // spider.mtl is missing; materials do not matter to a bake, so nothing is said about it.
  EXPECT_TRUE(m.warnings.empty()) << m.warnings.front();
}

// --- one geometry in every format -------------------------------------------------------------

// A pentagonal prism: 10 positions, two pentagon caps and five quads = 2·3 + 5·2 = 16 triangles.
struct Prism {
  std::vector<Vector3f> v;
  std::vector<std::vector<uint32_t>> faces;
  std::vector<Tri> fan;
  Prism() {
    for (int ring = 0; ring < 2; ++ring)
      for (int i = 0; i < 5; ++i) {
        const double a = 2.0 * M_PI * i / 5.0;
        v.emplace_back(float(std::cos(a)), ring ? 1.5f : -0.25f, float(std::sin(a)));
      }
    faces.push_back({0, 1, 2, 3, 4});  // bottom (normal −y with y up… the winding here is all that matters)
    faces.push_back({9, 8, 7, 6, 5});
    for (uint32_t i = 0; i < 5; ++i) faces.push_back({i, 5 + i, 5 + (i + 1) % 5, (i + 1) % 5});
    for (const auto& f : faces)
      for (size_t k = 1; k + 1 < f.size(); ++k) fan.push_back({f[0], f[k], f[k + 1]});
  }
};

std::string fmt(float x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", double(x));  // round-trips a float exactly
  return buf;
}

std::string prism_obj(const Prism& p) {
  std::string s = "# prism\n";
  for (const auto& v : p.v) s += "v " + fmt(v.x()) + " " + fmt(v.y()) + " " + fmt(v.z()) + "\n";
  for (const auto& f : p.faces) {
    s += "f";
    for (uint32_t i : f) s += " " + std::to_string(i + 1);
    s += "\n";
  }
  return s;
}

std::string prism_off(const Prism& p) {
  std::string s = "OFF\n" + std::to_string(p.v.size()) + " " + std::to_string(p.faces.size()) + " 0\n";
  for (const auto& v : p.v) s += fmt(v.x()) + " " + fmt(v.y()) + " " + fmt(v.z()) + "\n";
  for (const auto& f : p.faces) {
    s += std::to_string(f.size());
    for (uint32_t i : f) s += " " + std::to_string(i);
    s += "\n";
  }
  return s;
}

std::string ply_header(const Prism& p, const char* format) {
  return std::string("ply\nformat ") + format + " 1.0\ncomment prism\nelement vertex " + std::to_string(p.v.size()) +
         "\nproperty float x\nproperty float y\nproperty float z\nelement face " + std::to_string(p.faces.size()) +
         "\nproperty list uchar int vertex_indices\nend_header\n";
}

std::string prism_ply_ascii(const Prism& p) {
  std::string s = ply_header(p, "ascii");
  for (const auto& v : p.v) s += fmt(v.x()) + " " + fmt(v.y()) + " " + fmt(v.z()) + "\n";
  for (const auto& f : p.faces) {
    s += std::to_string(f.size());
    for (uint32_t i : f) s += " " + std::to_string(i);
    s += "\n";
  }
  return s;
}

std::string prism_ply_binary(const Prism& p) {
  std::string s = ply_header(p, "binary_little_endian");
  for (const auto& v : p.v) append_raw(s, v.x()), append_raw(s, v.y()), append_raw(s, v.z());
  for (const auto& f : p.faces) {
    append_raw(s, static_cast<uint8_t>(f.size()));
    for (uint32_t i : f) append_raw(s, static_cast<int32_t>(i));
  }
  return s;
}

std::string stl_ascii(const std::vector<std::array<Vector3f, 3>>& facets) {
  std::string s = "solid prism\n";
  for (const auto& f : facets) {
    s += "  facet normal 0 0 0\n    outer loop\n";
    for (const auto& c : f) s += "      vertex " + fmt(c.x()) + " " + fmt(c.y()) + " " + fmt(c.z()) + "\n";
    s += "    endloop\n  endfacet\n";
  }
  return s + "endsolid prism\n";
}

std::string stl_binary(const std::vector<std::array<Vector3f, 3>>& facets) {
  std::string s(80, ' ');
  append_raw(s, static_cast<uint32_t>(facets.size()));
  for (const auto& f : facets) {
    for (int k = 0; k < 3; ++k) append_raw(s, 0.0f);
    for (const auto& c : f) append_raw(s, c.x()), append_raw(s, c.y()), append_raw(s, c.z());
    append_raw(s, uint16_t{0});
  }
  return s;
}

std::vector<std::array<Vector3f, 3>> facets_of(const std::vector<Vector3f>& v, const std::vector<Tri>& tris) {
  std::vector<std::array<Vector3f, 3>> out;
  for (const auto& t : tris) out.push_back({v[t[0]], v[t[1]], v[t[2]]});
  return out;
}

// Topology summary that does not depend on welded ids: edges and rings by coordinates.
struct Shape {
  std::multiset<std::pair<std::array<float, 3>, std::array<float, 3>>> edges;  // with multiplicity = faces
  std::map<std::array<float, 3>, size_t> ring_sizes;
  bool operator==(const Shape&) const = default;
};

Shape shape_of(const Mesh& m) {
  const prt::bake::Topology topo = prt::bake::build_topology(m);
  auto key = [&](uint32_t w) {
    const Vector3f& p = topo.welded_positions[w];
    return std::array<float, 3>{p.x(), p.y(), p.z()};
  };
  Shape s;
  for (uint32_t e = 0; e < topo.edges.size(); ++e) {
    auto a = key(topo.edges[e][0]), b = key(topo.edges[e][1]);
    if (b < a) std::swap(a, b);
    for (size_t k = 0; k < topo.faces_of_edge(e).size(); ++k) s.edges.insert({a, b});
  }
  for (uint32_t w = 0; w < topo.welded_positions.size(); ++w) s.ring_sizes[key(w)] = topo.ring(w).size();
  return s;
}

TEST(MeshFormats, AllFormatsGiveTheSameGeometry) {
  const Prism prism;
  ASSERT_EQ(prism.fan.size(), 16u);
  const Mesh obj = prt::bake::load_mesh(write_file("prism.obj", prism_obj(prism)));
  ASSERT_EQ(obj.positions.size(), 10u);
  ASSERT_EQ(obj.triangles, prism.fan) << "quads and pentagons fan-triangulated in place, in file order";
  EXPECT_EQ(obj.file_faces, 7u);
  for (size_t i = 0; i < 10; ++i) ASSERT_TRUE(bits_equal(obj.positions[i], prism.v[i]));
  expect_unit_finite_normals(obj);

  const std::pair<const char*, std::string> indexed[] = {
      {"prism.off", prism_off(prism)},
      {"prism_ascii.ply", prism_ply_ascii(prism)},
      {"prism_binary.ply", prism_ply_binary(prism)},
  };
  for (const auto& [name, bytes] : indexed) {
    SCOPED_TRACE(name);
    const Mesh m = prt::bake::load_mesh(write_file(name, bytes));
    ASSERT_EQ(m.positions.size(), obj.positions.size());
    for (size_t i = 0; i < m.positions.size(); ++i) ASSERT_TRUE(bits_equal(m.positions[i], obj.positions[i]));
    EXPECT_EQ(m.triangles, obj.triangles);
    EXPECT_EQ(m.source_position, obj.source_position);
    EXPECT_EQ(m.file_faces, 7u);
    for (size_t i = 0; i < m.normals.size(); ++i) ASSERT_LT((m.normals[i] - obj.normals[i]).norm(), kNormalTolerance);
    EXPECT_TRUE(shape_of(m) == shape_of(obj));
  }

  const auto facets = facets_of(prism.v, prism.fan);
  const std::pair<const char*, std::string> soups[] = {
      {"prism_ascii.stl", stl_ascii(facets)},
      {"prism_binary.stl", stl_binary(facets)},
  };
  for (const auto& [name, bytes] : soups) {
    SCOPED_TRACE(name);
    const Mesh m = prt::bake::load_mesh(write_file(name, bytes));
    // STL has no shared vertices: corner k of facet f is output vertex 3f + k.
    ASSERT_EQ(m.positions.size(), 3 * prism.fan.size());
    ASSERT_EQ(m.triangles.size(), prism.fan.size());
    EXPECT_EQ(m.file_faces, prism.fan.size());
    EXPECT_EQ(m.file_positions, 3 * prism.fan.size());
    for (uint32_t t = 0; t < m.triangles.size(); ++t)
      for (uint32_t k = 0; k < 3; ++k) {
        const uint32_t v = m.triangles[t][k];
        ASSERT_EQ(v, 3 * t + k);
        ASSERT_EQ(m.source_position[v], v);
        ASSERT_TRUE(bits_equal(m.positions[v], prism.v[prism.fan[t][k]]));
        // Normals are angle-weighted over welded positions, so the soup shades like the welded mesh.
        ASSERT_LT((m.normals[v] - obj.normals[prism.fan[t][k]]).norm(), kNormalTolerance);
      }
    EXPECT_TRUE(shape_of(m) == shape_of(obj)) << "welding must reconnect the soup";
  }
}

TEST(MeshFormats, ObjHardEdgesSplitVerticesPerPositionNormalPair) {
  // Unit cube: 8 positions, 6 face normals, `f v//vn` quads.
  std::string s;
  for (int i = 0; i < 8; ++i) s += "v " + std::to_string(i & 1) + " " + std::to_string((i >> 1) & 1) + " " + std::to_string((i >> 2) & 1) + "\n";
  s += "vn -1 0 0\nvn 1 0 0\nvn 0 -1 0\nvn 0 1 0\nvn 0 0 -1\nvn 0 0 1\n";
  const int quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (int f = 0; f < 6; ++f) {
    s += "f";
    for (int k = 0; k < 4; ++k) s += " " + std::to_string(quads[f][k] + 1) + "//" + std::to_string(f + 1);
    s += "\n";
  }
  const fs::path path = write_file("cube_vn.obj", s);
  const Mesh m = prt::bake::load_mesh(path);
  ASSERT_EQ(m.positions.size(), 24u) << "3 normals at each of 8 positions";
  ASSERT_EQ(m.triangles.size(), 12u);
  EXPECT_EQ(m.normal_source, Mesh::NormalSource::File);
  EXPECT_EQ(m.file_positions, 8u);
  const Vector3f face_normal[6] = {-Vector3f::UnitX(), Vector3f::UnitX(), -Vector3f::UnitY(),
                                   Vector3f::UnitY(),  -Vector3f::UnitZ(), Vector3f::UnitZ()};
  // Rows 0..7 are the file positions; the rest are appended in order of first appearance.
  for (uint32_t v = 0; v < 8; ++v) EXPECT_EQ(m.source_position[v], v);
  std::map<uint32_t, int> seen;
  for (uint32_t v = 0; v < 24; ++v) {
    ASSERT_LT(m.source_position[v], 8u);
    ++seen[m.source_position[v]];
    ASSERT_TRUE(m.positions[v] == m.positions[m.source_position[v]]);
  }
  for (const auto& [p, n] : seen) EXPECT_EQ(n, 3) << "position " << p;
  for (uint32_t t = 0; t < 12; ++t)
    for (uint32_t k = 0; k < 3; ++k) {
      const uint32_t v = m.triangles[t][k];
      EXPECT_TRUE(m.normals[v] == face_normal[t / 2]) << "triangle " << t << " corner " << k;
      const int corner = k == 0 ? 0 : int(k) + int(t % 2);
      EXPECT_EQ(m.source_position[v], uint32_t(quads[t / 2][corner])) << "triangle " << t << " corner " << k;
    }
  // Expected order: face 0 claims rows 0,4,6,2; face 1 claims 1,3,7,5; face 2 (0,1,5,4) splits
  // all four → rows 8..11 in that order.
  EXPECT_EQ(m.source_position[8], 0u);
  EXPECT_EQ(m.source_position[9], 1u);
  EXPECT_EQ(m.source_position[10], 5u);
  EXPECT_EQ(m.source_position[11], 4u);

  const Mesh plain = prt::bake::load_mesh(path, {.use_file_normals = false});
  EXPECT_EQ(plain.positions.size(), 8u);
  EXPECT_EQ(plain.normal_source, Mesh::NormalSource::AngleWeighted);
  EXPECT_EQ(shape_of(plain), shape_of(m)) << "welding joins the split rows again";
}

TEST(MeshFormats, DegenerateAndZeroAreaTrianglesAreKept) {
  // OpenMesh's OBJ reader drops `f 1 1 2` and shrinks `f 1 2 1 3`; its STL reader skips facets
  // with two equal corners. All must reach the output as the file has them.
  const std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\n"
                          "f 1 2 3\nf 1 1 2\nf 1 2 1 3\nf 1 2 4\n";  // last one: collinear, zero area
  const Mesh m = prt::bake::load_mesh(write_file("degenerate.obj", obj));
  const std::vector<Tri> want = {{0, 1, 2}, {0, 0, 1}, {0, 1, 0}, {0, 0, 2}, {0, 1, 3}};
  EXPECT_EQ(m.triangles, want);
  EXPECT_EQ(m.file_faces, 4u);
  expect_unit_finite_normals(m);
  // Vertex 3 is only in a zero-area triangle: the documented fallback is +Y.
  EXPECT_TRUE(m.normals[3] == Vector3f::UnitY());

  const std::vector<std::array<Vector3f, 3>> facets = {
      {Vector3f(0, 0, 0), Vector3f(1, 0, 0), Vector3f(0, 1, 0)},
      {Vector3f(0, 0, 0), Vector3f(0, 0, 0), Vector3f(0, 1, 0)},
      {Vector3f(0, 0, 0), Vector3f(1, 0, 0), Vector3f(2, 0, 0)}};
  for (const auto& [name, bytes] : {std::pair{"degenerate_a.stl", stl_ascii(facets)}, std::pair{"degenerate_b.stl", stl_binary(facets)}}) {
    const Mesh s = prt::bake::load_mesh(write_file(name, bytes));
    ASSERT_EQ(s.triangles.size(), 3u) << name;
    EXPECT_TRUE(s.positions[4] == Vector3f(0, 0, 0)) << name;
    expect_unit_finite_normals(s);
  }
}

TEST(MeshFormats, PlyVertexNormalsAreUsed) {
  std::string s = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                  "property float nx\nproperty float ny\nproperty float nz\nelement face 1\n"
                  "property list uchar int vertex_indices\nend_header\n"
                  "0 0 0 0 0 2\n1 0 0 0 0 2\n0 1 0 0 1 1\n3 0 1 2\n";
  const Mesh m = prt::bake::load_mesh(write_file("normals.ply", s));
  EXPECT_EQ(m.normal_source, Mesh::NormalSource::File);
  EXPECT_TRUE(m.normals[0] == Vector3f(0, 0, 1)) << "normalised";
  EXPECT_LT((m.normals[2] - Vector3f(0, 1, 1).normalized()).norm(), kNormalTolerance);
  const Mesh plain = prt::bake::load_mesh(write_file("normals.ply", s), {.use_file_normals = false});
  EXPECT_EQ(plain.normal_source, Mesh::NormalSource::AngleWeighted);
  EXPECT_LT((plain.normals[2] - Vector3f(0, 0, 1)).norm(), kNormalTolerance);
}

TEST(MeshFormats, ValidFilesTheOpenMeshReadersRefusedAreRead) {
  // Each was refused or misread while OpenMesh's readers parsed the files: colours after an OFF
  // face's indices (read as the next face), integer-typed PLY coordinates (read as 0), a list
  // property in a PLY vertex element. NOFF normals and big-endian double PLY are read as before.
  const Prism prism;
  const Mesh obj = prt::bake::load_mesh(write_file("prism.obj", prism_obj(prism)));
  auto expect_prism = [&](const Mesh& m) {
    ASSERT_EQ(m.positions.size(), 10u);
    for (size_t i = 0; i < 10; ++i) ASSERT_TRUE(bits_equal(m.positions[i], prism.v[i])) << "vertex " << i;
    EXPECT_EQ(m.triangles, obj.triangles);
    EXPECT_EQ(m.file_faces, 7u);
  };
  std::string off_colours = "OFF\n10 7 0\n", noff = "NOFF\n10 7 0\n";
  std::string ply_be = "ply\nformat binary_big_endian 1.0\nelement vertex 10\nproperty double x\nproperty double y\n"
                       "property double z\nelement face 7\nproperty list uchar uint vertex_indices\nend_header\n";
  auto append_be = [](std::string& s, auto v) {
    char b[sizeof v];
    std::memcpy(b, &v, sizeof v);
    std::reverse(b, b + sizeof v);
    s.append(b, sizeof v);
  };
  for (const auto& v : prism.v) {
    const std::string xyz = fmt(v.x()) + " " + fmt(v.y()) + " " + fmt(v.z());
    off_colours += xyz + "\n";
    noff += xyz + " " + fmt(v.x()) + " 0 " + fmt(v.z()) + "\n";  // radial normals
    for (int k = 0; k < 3; ++k) append_be(ply_be, double(v[k]));
  }
  for (const auto& f : prism.faces) {
    std::string line = std::to_string(f.size());
    for (uint32_t i : f) line += " " + std::to_string(i);
    off_colours += line + " 255 128 0\n";
    noff += line + "\n";
    append_be(ply_be, uint8_t(f.size()));
    for (uint32_t i : f) append_be(ply_be, i);
  }
  expect_prism(prt::bake::load_mesh(write_file("prism_colours.off", off_colours)));
  expect_prism(prt::bake::load_mesh(write_file("prism_be_double.ply", ply_be)));
  const Mesh n = prt::bake::load_mesh(write_file("prism_normals.off", noff));
  expect_prism(n);
  EXPECT_EQ(n.normal_source, Mesh::NormalSource::File);
  for (size_t i = 0; i < 10; ++i)
    EXPECT_LT((n.normals[i] - Vector3f(prism.v[i].x(), 0, prism.v[i].z()).normalized()).norm(), kNormalTolerance);

  std::string ints = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty short x\nproperty short y\n"
                     "property short z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  for (int16_t c : {0, 0, 0, 2, 0, 0, 0, -3, 0}) append_raw(ints, c);
  append_raw(ints, uint8_t{3});
  for (int32_t i : {0, 1, 2}) append_raw(ints, i);
  const Mesh m = prt::bake::load_mesh(write_file("ints.ply", ints));
  EXPECT_TRUE(m.positions[1] == Vector3f(2, 0, 0));
  EXPECT_TRUE(m.positions[2] == Vector3f(0, -3, 0));
  const std::string vlist = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty list uchar float extra\n"
                            "property float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                            "end_header\n0 2 5 5 0 0\n2 0 0 0\n0 1 9 -3 0\n3 0 1 2\n";
  const Mesh l = prt::bake::load_mesh(write_file("vlist.ply", vlist));
  EXPECT_TRUE(l.positions == m.positions);
}

TEST(MeshFormats, WhatRealExportersWriteIsReadAndSaid) {
  // Found in real files (Debian's assimp test models): numbers with a leading '+' (C's strtof
  // reads them), a UTF-8 byte-order mark before an OBJ or PLY (Windows tools), and a PLY header
  // line without a keyword (Blender 2.47's "Created by Blender3D ..."), read as a comment with a
  // warning naming the line. UTF-16 text is refused naming the encoding.
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  const Mesh plain = prt::bake::load_mesh(write_file("plain.obj", tri));
  const Mesh plus = prt::bake::load_mesh(write_file("plus.obj", "v +0 +0. 0\nv +1 0 +0e0\nv 0 +1.0e+0 0\nf 1 2 3\n"));
  EXPECT_TRUE(plus.positions == plain.positions);
  prt::testing::expect_input_error(write_file("plusminus.obj", "v +-1 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), "line 1: malformed number '+-1'");
  prt::testing::expect_input_error(write_file("plusplus.obj", "v ++1 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), "line 1: malformed number '++1'");
  prt::testing::expect_input_error(write_file("exponent.obj", "v 3.1+e2 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), "line 1: malformed number '3.1+e2'");

  const Mesh bom = prt::bake::load_mesh(write_file("bom.obj", "\xEF\xBB\xBF" + tri));
  EXPECT_TRUE(bom.positions == plain.positions);
  EXPECT_EQ(bom.triangles, plain.triangles);
  const std::string ply = "ply\nformat ascii 1.0\nCreated by Blender3D 247 - www.blender.org\nelement vertex 3\n"
                          "property float x\nproperty float y\nproperty float z\nNot a keyword either\nelement face 1\n"
                          "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  const Mesh blender = prt::bake::load_mesh(write_file("blender247.ply", "\xEF\xBB\xBF" + ply));
  EXPECT_TRUE(blender.positions == plain.positions);
  ASSERT_EQ(blender.warnings.size(), 1u);
  EXPECT_EQ(blender.warnings[0], (tmp_dir() / "blender247.ply").string() + ": line 3: PLY header line 'Created by Blender3D 247 - www.blender.o...' has no keyword "
                                 "(and 1 more header lines); read as a comment");
  prt::testing::expect_input_error(write_file("badelement.ply", "ply\nformat ascii 1.0\nelement vertex\nend_header\n"),
                     "line 3: malformed PLY header line");

  std::string utf16 = "\xFE\xFF";
  for (char c : tri) utf16 += std::string(1, '\0') + c;
  prt::testing::expect_input_error(write_file("utf16.obj", utf16), "UTF-16 or UTF-32 text (byte-order mark FE FF)");
  prt::testing::expect_input_error(write_file("utf16.ply", "\xFF\xFE" + ply), "byte-order mark FF FE");
}

TEST(MeshLoad, SourceSha256IsTheDigestOfTheBytesRead) {
  const fs::path bunny = fs::path(PRT_DATA_DIR) / "bunny.obj";
  const Mesh m = prt::bake::load_mesh(bunny);
  EXPECT_EQ(m.source_sha256, prt::bake::sha256_file(bunny));
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  const Mesh t = prt::bake::load_mesh(write_file("sha.obj", tri));
  EXPECT_EQ(t.source_sha256, prt::bake::sha256_bytes(std::as_bytes(std::span(tri.data(), tri.size()))));
  EXPECT_EQ(prt::bake::make_mesh(t.positions, t.triangles, "memory").source_sha256, "") << "no file, no digest";
}

TEST(MeshLoad, MaterialLibrariesAreNeitherReadNorReported) {
  // Reader chatter about materials ("material file not found") is not a prtbake warning: a bake
  // does not use materials. The geometry is read as usual.
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nmtllib nowhere.mtl\nusemtl a\nf 1 2 3\nusemtl b\nf 1 3 2\n";
  const Mesh m = prt::bake::load_mesh(write_file("mtl.obj", tri));
  EXPECT_TRUE(m.warnings.empty()) << m.warnings.front();
  EXPECT_EQ(m.triangles.size(), 2u);
}

TEST(MeshBuild, PolygonsToMeshIsTheStepEveryReaderShares) {
  prt::bake::Polygons p;
  p.positions = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(1, 1, 0), Eigen::Vector3d(0, 1, 0)};
  p.normals = {Vector3f(0, 0, 2), Vector3f(0, 0, -1)};
  // A quad facing +z, then the triangle (0, 2, 1) with the back normal: its corners split.
  p.corner_position = {0, 1, 2, 3, 0, 2, 1};
  p.corner_normal = {0, 0, 0, 0, 1, 1, 1};
  p.offsets = {0, 4, 7};
  const Mesh m = prt::bake::build_mesh(p, "generated");
  EXPECT_EQ(m.triangles, (std::vector<Tri>{{0, 1, 2}, {0, 2, 3}, {4, 5, 6}}));
  EXPECT_EQ(m.source_position, (std::vector<uint32_t>{0, 1, 2, 3, 0, 2, 1}));
  EXPECT_TRUE(m.normals[0] == Vector3f(0, 0, 1)) << "normalised";
  EXPECT_TRUE(m.normals[4] == Vector3f(0, 0, -1));
  EXPECT_EQ(m.normal_source, Mesh::NormalSource::File);
  EXPECT_EQ(m.file_positions, 4u);
  EXPECT_EQ(m.file_faces, 2u);
  EXPECT_EQ(m.source, "generated");
  const Mesh plain = prt::bake::build_mesh(p, "generated", {.use_file_normals = false});
  EXPECT_EQ(plain.positions.size(), 4u);

  const auto expect_defect = prt::testing::expect_build_defect;
  auto bad = p;
  bad.corner_position[5] = 9;
  expect_defect(bad, "face 1: vertex index 9 is out of range [0, 4)");
  bad = p;
  bad.corner_normal[6] = 2;
  expect_defect(bad, "face 1: normal index 2 is out of range [0, 2)");
  bad = p;
  bad.offsets = {0, 2, 7};
  expect_defect(bad, "face 0 has 2 corners, needs at least 3");
  bad = p;
  bad.positions[1].y() = std::nan("");
  expect_defect(bad, "vertex 1 has a non-finite coordinate");
  bad = p;
  bad.normals[1].x() = INFINITY;
  expect_defect(bad, "vertex 0 has a non-finite normal");
  expect_defect(prt::bake::Polygons{}, "no faces");
}

// --- normals --------------------------------------------------------------------------------

std::vector<Vector3f> cube_positions() {
  std::vector<Vector3f> v;
  for (int i = 0; i < 8; ++i) v.emplace_back(float(i & 1), float((i >> 1) & 1), float((i >> 2) & 1));
  return v;
}
std::vector<Tri> cube_triangles() {  // outward, two triangles per face, split along varying diagonals
  return {{0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}, {0, 1, 5}, {0, 5, 4},
          {2, 6, 7}, {2, 7, 3}, {0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}};
}

TEST(MeshNormals, CubeCornerIsTheDiagonal) {
  const auto v = cube_positions();
  const auto n = prt::bake::angle_weighted_normals(v, cube_triangles());
  for (size_t i = 0; i < 8; ++i) {
    // Each corner sees three faces with a total angle of π/2 each, whatever the diagonal.
    const Vector3f want = (2.0f * v[i] - Vector3f::Ones()).normalized();
    EXPECT_LT((n[i] - want).norm(), kNormalTolerance) << "corner " << i;
  }
  EXPECT_LT((n[7] - Vector3f(1, 1, 1) / std::sqrt(3.0f)).norm(), kNormalTolerance);
}

TEST(MeshNormals, FlatGridIsThePlaneNormal) {
  // A 6×6 grid in a tilted plane with uneven spacing (needle-ish cells) and alternating diagonals.
  // Dyadic coordinates keep every point exactly on the plane z = 0.5x + 0.25y in float, so the
  // only error is the rounding of the normal itself.
  const Vector3f u = Vector3f(1, 0, 0.5f), w = Vector3f(0, 1, 0.25f);
  const Vector3f plane = u.cross(w).normalized();
  std::vector<Vector3f> v;
  const float s[6] = {0, 1.0f / 1024, 1, 1.5f, 4, 4 + 1.0f / 128};
  for (int j = 0; j < 6; ++j)
    for (int i = 0; i < 6; ++i) v.push_back(s[i] * u + s[j] * w);
  std::vector<Tri> t;
  for (uint32_t j = 0; j < 5; ++j)
    for (uint32_t i = 0; i < 5; ++i) {
      const uint32_t a = j * 6 + i, b = a + 1, c = a + 6, d = a + 7;
      if ((i + j) % 2) t.push_back({a, b, d}), t.push_back({a, d, c});
      else t.push_back({a, b, c}), t.push_back({b, d, c});
    }
  const Mesh m = prt::bake::make_mesh(v, t, "grid");
  for (size_t i = 0; i < v.size(); ++i) EXPECT_LT((m.normals[i] - plane).norm(), kNormalTolerance) << "vertex " << i;
  // An unreferenced vertex and one whose triangles cancel get +Y, finite and unit.
  const auto n = prt::bake::angle_weighted_normals(std::vector<Vector3f>{{0, 0, 0}, {1, 0, 0}, {0, 0, 1}, {5, 5, 5}},
                                                   std::vector<Tri>{{0, 1, 2}, {0, 2, 1}});
  EXPECT_TRUE(n[0] == Vector3f::UnitY());
  EXPECT_TRUE(n[3] == Vector3f::UnitY());
}

// --- topology ---------------------------------------------------------------------------------

TEST(MeshTopology, NonManifoldEdgeListsAllThreeFaces) {
  // Three fins sharing edge (0,1), plus a degenerate triangle (0,0,2).
  const std::vector<Vector3f> v = {{0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {-1, 0, 0}, {0, 0, 1}};
  const Mesh m = prt::bake::make_mesh(v, {{0, 1, 2}, {1, 0, 3}, {0, 4, 1}, {0, 0, 2}}, "fins");
  const auto topo = prt::bake::build_topology(m);
  const auto e = topo.find_edge(1, 0);
  ASSERT_TRUE(e.has_value());
  const auto faces = topo.faces_of_edge(*e);
  EXPECT_EQ(std::vector<uint32_t>(faces.begin(), faces.end()), (std::vector<uint32_t>{0, 1, 2}));
  // The degenerate triangle is one face of edge {0,2} (with triangle 0) and listed once in ring 0.
  const auto e02 = topo.faces_of_edge(*topo.find_edge(0, 2));
  EXPECT_EQ(std::vector<uint32_t>(e02.begin(), e02.end()), (std::vector<uint32_t>{0, 3}));
  EXPECT_EQ(topo.ring(0).size(), 4u);
  EXPECT_EQ(topo.ring(2).size(), 2u);
  EXPECT_TRUE(std::is_sorted(topo.edges.begin(), topo.edges.end()));
  for (const auto& ed : topo.edges) EXPECT_LT(ed[0], ed[1]);
  EXPECT_EQ(topo.edge_face_offsets.size(), topo.edges.size() + 1);
}

TEST(MeshTopology, WindingAndSoupDoNotChangeTopology) {
  const auto v = cube_positions();
  auto t = cube_triangles();
  const Mesh clean = prt::bake::make_mesh(v, t, "cube");
  const auto topo = prt::bake::build_topology(clean);
  EXPECT_EQ(topo.edges.size(), 18u) << "12 cube edges + 6 diagonals";
  for (uint32_t e = 0; e < topo.edges.size(); ++e) EXPECT_EQ(topo.faces_of_edge(e).size(), 2u) << "closed manifold";
  for (size_t i = 0; i < t.size(); i += 3) std::swap(t[i][1], t[i][2]);  // flip every third triangle
  const Mesh flipped = prt::bake::make_mesh(v, t, "flipped");
  EXPECT_EQ(shape_of(flipped), shape_of(clean));
  const auto topo_flipped = prt::bake::build_topology(flipped);
  EXPECT_EQ(topo_flipped.edges, topo.edges);
  EXPECT_EQ(topo_flipped.edge_faces, topo.edge_faces);
  EXPECT_EQ(topo_flipped.ring_offsets, topo.ring_offsets);

  std::vector<Vector3f> soup_v;
  std::vector<Tri> soup_t;
  for (const auto& tri : cube_triangles()) {
    const auto b = uint32_t(soup_v.size());
    for (uint32_t c : tri) soup_v.push_back(v[c]);
    soup_t.push_back({b, b + 1, b + 2});
  }
  const Mesh soup = prt::bake::load_mesh(write_file("cube_soup.stl", stl_binary(facets_of(v, cube_triangles()))));
  EXPECT_EQ(soup.positions, soup_v);
  EXPECT_EQ(soup.triangles, soup_t);
  const auto topo_soup = prt::bake::build_topology(soup);
  EXPECT_EQ(topo_soup.welded_positions.size(), 8u);
  EXPECT_EQ(topo_soup.edges.size(), 18u);
  EXPECT_EQ(shape_of(soup), shape_of(clean));
  // -0 welds with +0.
  auto neg = v;
  neg[0] = Vector3f(-0.0f, 0.0f, -0.0f);
  EXPECT_EQ(prt::bake::build_topology(prt::bake::make_mesh(neg, cube_triangles(), "negzero")).welded_positions.size(), 8u);
}

TEST(MeshBuild, MakeAndMergeValidate) {
  EXPECT_THROW(prt::bake::make_mesh({{0, 0, 0}}, {}, "empty"), InputError);
  EXPECT_THROW(prt::bake::make_mesh({{0, 0, 0}, {1, 0, 0}}, {{0, 1, 2}}, "range"), InputError);
  EXPECT_THROW(prt::bake::make_mesh({{0, 0, 0}, {1, 0, NAN}, {0, 1, 0}}, {{0, 1, 2}}, "nan"), InputError);
  try {
    prt::bake::make_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 3}}, "generated-ground");
    FAIL() << "index out of range accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("generated-ground"), std::string::npos) << e.what();
  }
  const Mesh a = prt::bake::make_mesh(cube_positions(), cube_triangles(), "a");
  const Mesh b = prt::bake::load_mesh(write_file("prism_merge.obj", prism_obj(Prism())));
  const Mesh ab = prt::bake::merge_meshes(std::vector<Mesh>{a, b}, "scene");
  ASSERT_EQ(ab.positions.size(), 18u);
  ASSERT_EQ(ab.triangles.size(), 12u + 16u);
  EXPECT_EQ(ab.triangles[12], (Tri{8 + 0, 8 + 1, 8 + 2}));
  EXPECT_EQ(ab.source_position[8], 8u) << "offset by the first part's file positions";
  EXPECT_EQ(ab.file_positions, 18u);
  EXPECT_EQ(ab.file_faces, 12u + 7u);
  EXPECT_EQ(ab.source, "scene");
  expect_unit_finite_normals(ab);
}

// --- hostile input ----------------------------------------------------------------------------

using prt::testing::expect_input_error;

TEST(MeshErrors, BadInputNamesFileAndDefect) {
  const Prism prism;
  const std::string obj = prism_obj(prism);
  expect_input_error(tmp_dir() / "does_not_exist.obj", "no such file");
  expect_input_error(tmp_dir(), "directory");
  expect_input_error(write_file("mesh.xyz", obj), "unknown mesh format");
  expect_input_error(write_file("noext", obj), "unknown mesh format");
  expect_input_error(write_file("zero.obj", ""), "empty file");
  expect_input_error(write_file("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n"), "no faces");
  expect_input_error(write_file("garbage.obj", obj + "this is not obj\n"), "line 19: not an OBJ statement");
  expect_input_error(write_file("binary.obj", std::string("\x7f" "ELF\x02\x01\x01", 7) + obj), "line 1:");
  expect_input_error(write_file("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"), "line 2: non-finite");
  expect_input_error(write_file("inf.obj", "v 0 0 0\nv 1 inf 0\nv 0 1 0\nf 1 2 3\n"), "line 2: non-finite");
  expect_input_error(write_file("huge.obj", "v 0 0 0\nv 1 1e50 0\nv 0 1 0\nf 1 2 3\n"), "line 2: coordinate");
  expect_input_error(write_file("badv.obj", "v 0 0 0\nv 1 2 abc\nv 0 1 0\nf 1 2 3\n"), "line 2: malformed number");
  expect_input_error(write_file("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"), "line 4: vertex index 9 is out of range");
  expect_input_error(write_file("negative.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -9\n"), "line 4: relative index -9");
  expect_input_error(write_file("zeroindex.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"), "line 4: malformed face corner");
  expect_input_error(write_file("twocorners.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n"), "line 4: face has 2 corners");
  expect_input_error(write_file("badcorner.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n"), "line 4: malformed face corner");
  expect_input_error(write_file("badnormal.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//2\n"),
                     "line 5: normal index 2 is out of range");

  const std::string ply = prism_ply_binary(prism);
  expect_input_error(write_file("half.ply", ply.substr(0, ply.size() / 2)), "truncated");
  expect_input_error(write_file("header_only.ply", ply.substr(0, ply.find("end_header"))), "end_header");
  const std::string ascii = prism_ply_ascii(prism);
  expect_input_error(write_file("half_ascii.ply", ascii.substr(0, ascii.size() - 20)), "truncated");
  std::string ply_range = prism_ply_ascii(prism);
  ply_range.replace(ply_range.rfind("4 0"), 3, "4 77");
  expect_input_error(write_file("range.ply", ply_range), "vertex index 77 is out of range");
  std::string ply_neg = ply;  // binary: last index of the last face = −3
  const int32_t minus3 = -3;
  std::memcpy(ply_neg.data() + ply_neg.size() - 4, &minus3, 4);
  expect_input_error(write_file("negative.ply", ply_neg), "vertex index -3 is out of range");
  std::string ply_nan = ply;
  const float nan = std::nanf("");
  std::memcpy(ply_nan.data() + ply.find("end_header\n") + 11 + 4, &nan, 4);
  expect_input_error(write_file("nan.ply", ply_nan), "vertex 0 has a non-finite coordinate");
  expect_input_error(write_file("notply.ply", obj), "not a PLY file");

  const std::string off = prism_off(prism);
  expect_input_error(write_file("range.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"), "line 6: vertex index 3 is out of range");
  expect_input_error(write_file("truncated.off", off.substr(0, off.rfind('\n', off.size() - 2) + 1)),
                     "truncated: the header says 7 faces, the file has 6");
  expect_input_error(write_file("nan.off", "OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n"), "line 4: non-finite");
  expect_input_error(write_file("binary.off", "OFF BINARY\n"), "binary OFF is not supported");
  expect_input_error(write_file("comment.off", "OFF\n# made by hand\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"), "line 2: '#' comments");
  expect_input_error(write_file("oneline.off", "OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"), "line 1: counts on the OFF header line");
  expect_input_error(write_file("empty.off", "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n"), "no faces");

  const auto facets = facets_of(prism.v, prism.fan);
  const std::string stlb = stl_binary(facets);
  expect_input_error(write_file("half.stl", stlb.substr(0, stlb.size() / 2)), "truncated");
  std::string stl_nan = stlb;
  std::memcpy(stl_nan.data() + 84 + 50 * 5 + 12, &nan, 4);
  expect_input_error(write_file("nan.stl", stl_nan), "facet 5 has a non-finite coordinate");
  const std::string stla = stl_ascii(facets);
  expect_input_error(write_file("half_ascii.stl", stla.substr(0, stla.find("outer loop\n", stla.size() / 2) + 11)),
                     "truncated: the file ends inside the loop");
  expect_input_error(write_file("cut_ascii.stl", stla.substr(0, stla.size() / 2)), "line ");
  expect_input_error(write_file("garbage.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0\n"), "line 5: 'vertex' needs 3");
  expect_input_error(write_file("empty.stl", stl_binary({})), "no faces");
}

TEST(MeshErrors, CountsTheFileCannotHoldAreRefusedBeforeAnythingIsAllocated) {
  // 10^12 vertices would be 12 TB of positions: the answer must be an error naming the defect,
  // not an allocation failure.
  const std::string header = "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\nproperty float x\n"
                             "property float y\nproperty float z\nelement face 0\nproperty list uchar int vertex_indices\n"
                             "end_header\n";
  expect_input_error(write_file("huge_count.ply", header + std::string(120, '\0')), "truncated: the header declares 1000000000000 vertex");
  expect_input_error(write_file("huge_count.off", "OFF\n1000000000000 1 0\n0 0 0\n"), "truncated: the header says 1000000000000 vertices");
}

TEST(MeshErrors, PlyHeaderDefectsFailFastNamingTheLine) {
  const std::string tri = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\n"
                          "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  // A version that is not 1.0 (OpenMesh's reader looped forever on this one).
  expect_input_error(write_file("format_x.ply", "ply\nformat ascii x\n" + tri), "line 2: malformed PLY format line");
  // 10^18 items of no property take no bytes: nothing to read, at once (it was 10^18 empty
  // iterations); with a property they are more than the file holds.
  const std::string junk = "ply\nformat ascii 1.0\nelement junk 1000000000000000000\n";
  EXPECT_EQ(prt::bake::load_mesh(write_file("junk_empty.ply", junk + tri)).triangles.size(), 1u);
  expect_input_error(write_file("junk_counted.ply", junk + "property float a\n" + tri),
                     "truncated: the header declares 1000000000000000000 junk items");
  // A second vertex element was indexed with the first one's rows: 5 items written into 3 rows.
  std::string two = "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\n" +
                    tri.substr(0, tri.find("end_header\n") + 11);
  for (int v = 0; v < 8; ++v) two += "0 0 0\n";
  expect_input_error(write_file("two_vertex.ply", two + "3 0 1 2\n"),
                     "line 7: a second 'vertex' element");
}

TEST(MeshErrors, GarbledColourAndNormalOffAreReadOrRefusedNamingTheLine) {
  // COFF: the colour columns after x y z are not read (any number of them, any text).
  const std::string faces = "3 0 1 2\n";
  const Mesh c = prt::bake::load_mesh(write_file("colours.off", "COFF\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 x\n0 1 0\n" + faces));
  EXPECT_EQ(c.positions.size(), 3u);
  EXPECT_TRUE(c.positions[1] == Vector3f(1, 0, 0));
  // NOFF: the three normal columns are required and must be numbers.
  expect_input_error(write_file("noff_short.off", "NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 0\n0 1 0 0 0 1\n" + faces),
                     "line 4: vertex needs 3 coordinates and 3 normal components");
  expect_input_error(write_file("noff_text.off", "NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 zero 1\n0 1 0 0 0 1\n" + faces),
                     "line 4: malformed number 'zero'");
  // Garbled counts: refused at the end of the file, never allocated for.
  expect_input_error(write_file("coff_counts.off", "COFF\n2000000000 2000000000 0\n0 0 0 1 1 1 1\n"),
                     "truncated: the header says 2000000000 vertices, the file has 1");
}

TEST(MeshErrors, UnreadableFile) {
  if (geteuid() == 0) GTEST_SKIP() << "root reads files whatever their mode";
  const fs::path p = write_file("unreadable.obj", prism_obj(Prism()));
  fs::permissions(p, fs::perms::none);
  expect_input_error(p, "cannot be read");
  fs::permissions(p, fs::perms::owner_read | fs::perms::owner_write);
}

} // namespace
