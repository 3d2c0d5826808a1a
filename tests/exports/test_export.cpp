// Exports (exports/export.h), each re-read by a second, independent reader:
//   * glTF / GLB: tinygltf loads what we wrote; the test checks the structure glTF 2.0 requires
//     (buffer views inside the buffer, accessors inside their views, 4-byte alignment, POSITION
//     min/max equal to the data's bounds, application-specific attributes named "_…" with float
//     SCALAR..VEC4 accessors, indices < vertex count) and reassembles every product from its
//     attributes via asset.extras.prtbake: values equal bit for bit (no arithmetic on them).
//   * PRTBIN: tests/exports/prtbin_reader.py, written from SCHEMA.md with Python's struct/json,
//     checks the layout and returns every array: values equal bit for bit.
//   * Probes: each engine file's SH evaluated with that engine's formula (tests/common/engine_sh.h:
//     Unity's ShadeSH9, Godot's capture formula, Filament's) at each vertex's normal in the
//     engine's frame equals the baked E/π of SCHEMA.md's (4π/3) Σ_m y_1m(n) R_m / π, to 1e-5 of
//     the terms' magnitude (Godot's 6-digit constants; float data, double arithmetic).
//   * Lightmaps (format v5): tinygltf reads a scene whose objects' UVs have seams at every shared
//     vertex — each corner's TEXCOORD_1, position, normal and per-vertex attribute are the file's
//     row's, bit for bit — and decodes the occlusion PNG to round(255·AO) of a non-square
//     lightmap; EXR files are named per object; a value beyond half's range is refused; Godot's
//     directional lightmap of a Z-up file, shaded by Godot's formula at the texel's normal turned
//     into Godot's frame, is the baked E/π.
#include <exports/export.h>

#include <formats/temporaries.h>

#include <engine_sh.h>
#include <gtest/gtest.h>
#include <quad_light.h>
#include <run_tool.h>
#include <scratch.h>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include <cmath>
#include <cstring>
#include <map>
#include <tuple>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>

namespace fs = std::filesystem;
using namespace prt::formats;
using namespace prt::exports;

namespace {

constexpr double kPi = 3.14159265358979323846;
fs::path fresh_dir(const std::string& name) { return prt::testing::fresh_dir("export", name); }
using prt::testing::listing;

// Deterministic values with every bit in use (not round numbers).
std::vector<float> values(size_t n, double seed) {
  std::vector<float> v(n);
  for (size_t i = 0; i < n; ++i) v[i] = float(std::sin(seed + 0.731 * double(i)) * 0.9);
  return v;
}

Product product(std::vector<float> v, std::optional<int64_t> sh_order = std::nullopt) {
  Product p;
  p.values = std::move(v);
  p.sh_order = sh_order;
  return p;
}

// A mesh of V vertices on a bumpy strip, `offset` added to its positions; unit normals.
void fill_mesh(VertexSet& s, size_t V, double offset) {
  s.positions.emplace();
  s.normals.emplace();
  s.triangles.emplace();
  for (size_t v = 0; v < V; ++v) {
    const double x = double(v) * 0.37, z = std::sin(double(v)) * 0.3;
    for (double c : {x + offset, 0.25 * double(v % 2) + offset, z + offset}) s.positions->values.push_back(c);
    const double nx = std::sin(double(v) + 1), ny = 1.0, nz = std::cos(double(v) * 2), len = std::sqrt(nx * nx + ny * ny + nz * nz);
    for (double c : {nx / len, ny / len, nz / len}) s.normals->values.push_back(float(c));
  }
  for (uint32_t v = 0; v + 2 < V; ++v) s.triangles->values.insert(s.triangles->values.end(), {v, v + 1, v + 2});
  s.source_position.emplace();
  for (uint32_t v = 0; v < V; ++v) s.source_position->values.push_back(v / 2);
}

RootInfo root(const std::string& up) {
  RootInfo r;
  r.generator = "test_export";
  r.created = "2024-05-01T12:00:00Z";
  r.command_line = "prtbake vertex x.obj";
  r.source = "x.obj";
  r.source_sha256 = std::string(64, 'b');
  r.up_axis = up;
  r.sh_convention = "ours";
  return r;
}

// The root layout: AO, order-3 diffuse and order-2 visibility transfer, band-1 radiance.
Asset vertex_asset() {
  Asset a;
  a.root = root("y");
  const size_t V = 7;
  fill_mesh(a.vertices, V, 0.0);
  a.vertices.ao = product(values(V, 0.1));
  for (float& x : a.vertices.ao->values) x = std::abs(x);
  a.vertices.transfer_diffuse = product(values(V * 9, 0.2), 3);
  a.vertices.transfer_visibility = product(values(V * 4, 0.3), 2);
  a.vertices.radiance_band1 = product(values(V * 9, 0.4));
  a.vertices.radiance_shadowed = product(values(V * 3 * 4, 0.45), 2);  // [RGB][4]: three VEC4 attributes
  return a;
}

// A Z-up scene: one object far from the origin with order-5 transfer (25 = 6 VEC4 + a SCALAR),
// one with area-light data (2 lights, SH order 2: [V][2][4]) and band-1 radiance.
Asset scene_asset() {
  Asset a;
  a.root = root("z");
  a.scene.emplace();
  SceneObject& far = a.objects.emplace_back();
  far.name = "far";
  far.node_path = "root/far";
  fill_mesh(far.set, 5, 1e5 + 1e-4);
  far.set.transfer_diffuse = product(values(5 * 25, 0.5), 5);
  SceneObject& lit = a.objects.emplace_back();
  lit.name = "lit";
  fill_mesh(lit.set, 6, 0.0);
  lit.set.area_irradiance = product(values(6 * 2, 0.6));
  lit.set.area_irradiance->lights = "key\nfill";
  lit.set.area_sh = product(values(6 * 2 * 4, 0.7), 2);
  lit.set.area_sh->lights = "key\nfill";
  lit.set.radiance_band1 = product(values(6 * 9, 0.8));
  return a;
}

// A Y-up scene of two objects ("a", and "b|c" as a glTF node path is stored), each a strip of 6
// vertices (4 triangles) with AO and order-2 transfer per vertex, its corners' UVs all distinct
// (every vertex shared by two triangles is on a seam), and a 4 × 3 lightmap (W ≠ H) with state,
// positions, normals, AO, order-2 transfer and band-1 radiance.
Asset lightmap_asset() {
  Asset a;
  a.root = root("y");
  a.scene.emplace();
  for (const char* name : {"a", "b|c"}) {
    SceneObject& o = a.objects.emplace_back();
    o.name = name;
    const size_t V = 6, W = 4, H = 3, texels = W * H;
    fill_mesh(o.set, V, 0.0);
    for (double& x : o.set.positions->values) x = double(float(x));  // float32 positions: no node translation
    o.set.ao = product(values(V, 1.1));
    o.set.transfer_diffuse = product(values(V * 4, 1.2), 2);
    Uvs& uv = o.set.uv.emplace();
    uv.uv_set = "TEXCOORD_1";
    for (size_t i = 0; i < o.set.triangles->values.size(); ++i) uv.values.insert(uv.values.end(), {float(i) / 16, 1 - float(i) / 32});
    Lightmap& m = o.set.lightmap.emplace();
    m.width = W;
    m.height = H;
    m.padding = 1;
    for (size_t k = 0; k < texels; ++k) m.state.values.push_back(uint8_t(k % 4));
    m.positions.emplace().values.assign(3 * texels, 0.25);
    m.normals.emplace().values.assign(3 * texels, 0.0f);
    for (size_t k = 0; k < texels; ++k) m.normals->values[3 * k + 1] = 1;
    m.ao = product(values(texels, 1.3));
    m.ao->values[0] = -0.2f;  // clamped to code 0
    m.ao->values[1] = 1.5f;   // clamped to 255
    m.transfer_diffuse = product(values(texels * 4, 1.4), 2);
    m.radiance_band1 = product(values(texels * 9, 1.5));
  }
  return a;
}

// Every per-vertex product an export carries, by its dataset name relative to the set.
std::vector<std::pair<std::string, const std::optional<Product>*>> exported_products(const VertexSet& s) {
  return {{"ao", &s.ao},
          {"transfer/diffuse", &s.transfer_diffuse},
          {"transfer/visibility", &s.transfer_visibility},
          {"radiance/band1", &s.radiance_band1},
          {"radiance/shadowed", &s.radiance_shadowed},
          {"area_lights/irradiance", &s.area_irradiance},
          {"area_lights/sh", &s.area_sh}};
}

// ---- glTF: structure checks and reading accessors ----

size_t component_count(int type) {
  switch (type) {
  case TINYGLTF_TYPE_SCALAR: return 1;
  case TINYGLTF_TYPE_VEC2: return 2;
  case TINYGLTF_TYPE_VEC3: return 3;
  case TINYGLTF_TYPE_VEC4: return 4;
  default: return 0;
  }
}

// The elements of accessor `index` (float or uint32 components), after checking its bounds.
template <class T> std::vector<T> read_accessor(const tinygltf::Model& m, int index) {
  const tinygltf::Accessor& acc = m.accessors.at(size_t(index));
  const tinygltf::BufferView& view = m.bufferViews.at(size_t(acc.bufferView));
  const tinygltf::Buffer& buffer = m.buffers.at(size_t(view.buffer));
  const size_t comps = component_count(acc.type);
  EXPECT_GT(comps, 0u);
  EXPECT_EQ(view.byteOffset % 4, 0u);
  EXPECT_EQ(acc.byteOffset % sizeof(T), 0u);
  EXPECT_LE(view.byteOffset + view.byteLength, buffer.data.size());
  const size_t stride = view.byteStride ? view.byteStride : comps * sizeof(T);
  EXPECT_LE(acc.byteOffset + (acc.count - 1) * stride + comps * sizeof(T), view.byteLength);
  std::vector<T> out(acc.count * comps);
  for (size_t e = 0; e < acc.count; ++e)
    std::memcpy(out.data() + e * comps, buffer.data.data() + view.byteOffset + acc.byteOffset + e * stride, comps * sizeof(T));
  return out;
}

tinygltf::Model load(const fs::path& file, bool glb) {
  tinygltf::TinyGLTF loader;
  tinygltf::Model m;
  std::string err, warn;
  const bool ok = glb ? loader.LoadBinaryFromFile(&m, &err, &warn, file.string())
                      : loader.LoadASCIIFromFile(&m, &err, &warn, file.string());
  EXPECT_TRUE(ok) << err;
  EXPECT_EQ(warn, "");
  return m;
}

// Checks every mesh of `m` against the vertex sets of `a` and the glTF rules above.
void check_gltf(const tinygltf::Model& m, const Asset& a) {
  ASSERT_EQ(m.asset.version, "2.0");
  const tinygltf::Value& info = m.asset.extras.Get("prtbake");
  ASSERT_TRUE(info.IsObject());
  EXPECT_EQ(info.Get("up_axis").Get<std::string>(), a.root.up_axis);
  const tinygltf::Value& sets = info.Get("sets");
  ASSERT_EQ(sets.ArrayLen(), a.objects.empty() ? 1u : a.objects.size());
  for (size_t si = 0; si < sets.ArrayLen(); ++si) {
    const tinygltf::Value& entry = sets.Get(int(si));
    const VertexSet& s = a.objects.empty() ? a.vertices : a.objects[si].set;
    const size_t V = s.vertex_count();
    SCOPED_TRACE("set " + entry.Get("name").Get<std::string>());
    const tinygltf::Mesh& mesh = m.meshes.at(size_t(entry.Get("mesh").Get<int>()));
    const tinygltf::Node& node = m.nodes.at(size_t(entry.Get("node").Get<int>()));
    ASSERT_EQ(mesh.primitives.size(), 1u);
    const tinygltf::Primitive& prim = mesh.primitives[0];
    for (const auto& [name, index] : prim.attributes) {
      const tinygltf::Accessor& acc = m.accessors.at(size_t(index));
      EXPECT_EQ(acc.count, V) << name;
      EXPECT_TRUE(name == "POSITION" || name == "NORMAL" || name == "COLOR_0" || name[0] == '_') << name;
      EXPECT_EQ(acc.componentType, TINYGLTF_COMPONENT_TYPE_FLOAT) << name;
      EXPECT_GT(component_count(acc.type), 0u) << name;
      EXPECT_EQ(m.bufferViews.at(size_t(acc.bufferView)).target, TINYGLTF_TARGET_ARRAY_BUFFER) << name;
    }
    // POSITION: float32 + the node's translation; min/max are the data's bounds (required).
    const std::vector<float> pos = read_accessor<float>(m, prim.attributes.at("POSITION"));
    const tinygltf::Accessor& pacc = m.accessors.at(size_t(prim.attributes.at("POSITION")));
    ASSERT_EQ(pacc.minValues.size(), 3u);
    ASSERT_EQ(pacc.maxValues.size(), 3u);
    for (size_t c = 0; c < 3; ++c) {
      double lo = INFINITY, hi = -INFINITY;
      for (size_t v = 0; v < V; ++v) lo = std::min(lo, double(pos[3 * v + c])), hi = std::max(hi, double(pos[3 * v + c]));
      EXPECT_EQ(pacc.minValues[c], lo);
      EXPECT_EQ(pacc.maxValues[c], hi);
    }
    for (size_t i = 0; i < 3 * V; ++i) {
      const double t = node.translation.empty() ? 0.0 : node.translation[i % 3];
      const double want = s.positions->values[i];
      if (t == 0.0) EXPECT_EQ(double(pos[i]), want);  // the file's float32 positions, unchanged
      else EXPECT_NEAR(double(pos[i]) + t, want, std::abs(want - t) * 1e-7 + 1e-12);  // one float32 rounding of p − t
    }
    EXPECT_EQ(read_accessor<float>(m, prim.attributes.at("NORMAL")), s.normals->values);
    // Indices.
    ASSERT_EQ(prim.mode, TINYGLTF_MODE_TRIANGLES);
    const tinygltf::Accessor& iacc = m.accessors.at(size_t(prim.indices));
    EXPECT_EQ(iacc.componentType, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT);
    EXPECT_EQ(iacc.type, TINYGLTF_TYPE_SCALAR);
    EXPECT_EQ(m.bufferViews.at(size_t(iacc.bufferView)).target, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    const std::vector<uint32_t> idx = read_accessor<uint32_t>(m, prim.indices);
    EXPECT_EQ(idx, s.triangles->values);
    for (uint32_t i : idx) EXPECT_LT(i, V);
    // Products: concatenate the listed attributes per vertex, in order.
    std::map<std::string, const Product*> want;
    for (auto [name, p] : exported_products(s))
      if (*p) want[name] = &**p;
    const tinygltf::Value& products = entry.Get("products");
    ASSERT_EQ(products.ArrayLen(), want.size());
    for (size_t k = 0; k < products.ArrayLen(); ++k) {
      const tinygltf::Value& pe = products.Get(int(k));
      const std::string dataset = pe.Get("dataset").Get<std::string>();
      ASSERT_TRUE(want.count(dataset)) << dataset;
      std::vector<std::vector<float>> groups;
      size_t width = 0;
      for (size_t g = 0; g < pe.Get("attributes").ArrayLen(); ++g) {
        const std::string attr = pe.Get("attributes").Get(int(g)).Get<std::string>();
        EXPECT_EQ(attr[0], '_');
        groups.push_back(read_accessor<float>(m, prim.attributes.at(attr)));
        width += groups.back().size() / V;
      }
      std::vector<float> rows;
      for (size_t v = 0; v < V; ++v)
        for (const auto& g : groups) rows.insert(rows.end(), g.begin() + long(v * g.size() / V), g.begin() + long((v + 1) * g.size() / V));
      EXPECT_EQ(rows, want[dataset]->values) << dataset;
      EXPECT_EQ(width * V, want[dataset]->values.size()) << dataset;
    }
    if (s.ao) {  // COLOR_0: the same AO, grey
      const std::vector<float> grey = read_accessor<float>(m, prim.attributes.at("COLOR_0"));
      for (size_t v = 0; v < V; ++v)
        for (size_t c = 0; c < 3; ++c) EXPECT_EQ(grey[3 * v + c], s.ao->values[v]);
    }
  }
}

TEST(ExportGltf, TinygltfReadsBackEveryValueAndTheStructureIsValid) {
  for (const Asset& a : {vertex_asset(), scene_asset()}) {
    const fs::path dir = fresh_dir("gltf");
    export_asset(a, "in.prt.h5", ExportFormat::Gltf, dir / "asset.gltf");
    EXPECT_EQ(listing(dir), (std::vector<std::string>{"asset.bin", "asset.gltf"}));  // no staging left
    check_gltf(load(dir / "asset.gltf", false), a);
    export_asset(a, "in.prt.h5", ExportFormat::Glb, dir / "asset.glb");
    check_gltf(load(dir / "asset.glb", true), a);
  }
}

TEST(Export, StagingLeftByAKilledExportIsRemovedLiveAndOtherHostsKept) {
  // An export killed with SIGKILL leaves ".<name>.export.<host>.<pid>/" with partial files. The
  // next export to that name removes it when the pid is dead on this machine, and keeps a live
  // pid's (an export writing now), another machine's and another name's.
  const fs::path dir = fresh_dir("stale_staging");
  const pid_t dead = ::fork();  // a pid that is surely dead once reaped
  if (dead == 0) ::_exit(0);
  ASSERT_GT(dead, 0);
  ::waitpid(dead, nullptr, 0);
  const std::string h = prt::formats::host_tag();
  const std::string stale = ".a.glb.export." + h + "." + std::to_string(dead);
  const std::string live = ".a.glb.export." + h + "." + std::to_string(::getppid());
  const std::string other_host = ".a.glb.export.elsewhere-" + h + "." + std::to_string(dead);
  const std::string other_name = ".b.glb.export." + h + "." + std::to_string(dead);
  for (const std::string& n : {stale, live, other_host, other_name}) {
    fs::create_directory(dir / n);
    std::ofstream(dir / n / "a.glb") << "partial";
  }
  export_asset(vertex_asset(), "in.prt.h5", ExportFormat::Glb, dir / "a.glb");
  std::vector<std::string> want = {"a.glb", live, other_host, other_name};
  std::sort(want.begin(), want.end());
  EXPECT_EQ(listing(dir), want);
}

TEST(ExportGltf, ZUpBakesHangUnderANodeTurningZToY) {
  const fs::path dir = fresh_dir("gltf_z");
  export_asset(scene_asset(), "in.prt.h5", ExportFormat::Glb, dir / "s.glb");
  const tinygltf::Model m = load(dir / "s.glb", true);
  ASSERT_EQ(m.scenes.at(0).nodes.size(), 1u);
  const tinygltf::Node& up = m.nodes.at(size_t(m.scenes[0].nodes[0]));
  ASSERT_EQ(up.rotation.size(), 4u);  // −90° about X: (x, y, z) ↦ (x, z, −y)
  EXPECT_NEAR(up.rotation[0], -std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(up.rotation[3], std::sqrt(0.5), 1e-15);
  EXPECT_EQ(up.children.size(), 2u);
}

// ---- PRTBIN through the Python reader ----

TEST(ExportBinary, PythonReaderFromTheSpecReadsBackEveryValue) {
  const fs::path dir = fresh_dir("bin");
  if (prt::testing::run_tool("python3", "-c 'import json, struct'", dir).code != 0) GTEST_SKIP() << "no python3";
  for (const Asset& a : {vertex_asset(), scene_asset(), lightmap_asset()}) {
    export_asset(a, "in.prt.h5", ExportFormat::Binary, dir / "a.prtbin");
    const auto run = prt::testing::run_tool("python3", std::string(PRT_SOURCE_TESTS) + "/exports/prtbin_reader.py '" +
                                                           (dir / "a.prtbin").string() + "' '" + (dir / "a.json").string() + "'",
                                            dir);
    ASSERT_EQ(run.code, 0) << run.err;
    const nlohmann::json j = nlohmann::json::parse(prt::testing::read_bytes(dir / "a.json"));
    std::map<std::string, std::pair<std::vector<double>, std::string>> want;  // name -> values, dtype
    auto add = [&](const std::string& prefix, const VertexSet& s) {
      auto name = [&](const std::string& d) { return prefix.empty() ? d : prefix + "/" + d; };
      const bool f32 = std::all_of(s.positions->values.begin(), s.positions->values.end(), [](double x) { return double(float(x)) == x; });
      want[name("mesh/positions")] = {s.positions->values, f32 ? "float32" : "float64"};
      want[name("mesh/normals")] = {{s.normals->values.begin(), s.normals->values.end()}, "float32"};
      want[name("mesh/triangles")] = {{s.triangles->values.begin(), s.triangles->values.end()}, "uint32"};
      want[name("mesh/source_position")] = {{s.source_position->values.begin(), s.source_position->values.end()}, "uint32"};
      for (auto [d, p] : exported_products(s))
        if (*p) want[name(d)] = {{(*p)->values.begin(), (*p)->values.end()}, "float32"};
      if (s.uv) want[name("mesh/uv")] = {{s.uv->values.begin(), s.uv->values.end()}, "float32"};
      if (!s.lightmap) return;
      const Lightmap& m = *s.lightmap;
      want[name("lightmap/state")] = {{m.state.values.begin(), m.state.values.end()}, "uint8"};
      want[name("lightmap/positions")] = {m.positions->values, "float32"};  // 0.25: exactly float
      want[name("lightmap/normals")] = {{m.normals->values.begin(), m.normals->values.end()}, "float32"};
      want[name("lightmap/ao")] = {{m.ao->values.begin(), m.ao->values.end()}, "float32"};
      want[name("lightmap/transfer/diffuse")] = {{m.transfer_diffuse->values.begin(), m.transfer_diffuse->values.end()}, "float32"};
      want[name("lightmap/radiance/band1")] = {{m.radiance_band1->values.begin(), m.radiance_band1->values.end()}, "float32"};
    };
    if (a.objects.empty()) add("", a.vertices);
    for (const SceneObject& o : a.objects) add("objects/" + o.name, o.set);
    ASSERT_EQ(j["header"]["arrays"].size(), want.size());
    for (const auto& h : j["header"]["arrays"]) {
      const std::string name = h["name"];
      ASSERT_TRUE(want.count(name)) << name;
      EXPECT_EQ(h["dtype"], want[name].second) << name;
      EXPECT_EQ(j["arrays"][name].get<std::vector<double>>(), want[name].first) << name;
    }
    // An SH product's attributes: the root's, the far object's, a lightmap's.
    const bool lightmaps = !a.objects.empty() && a.objects[0].set.lightmap;
    const std::string sh_name = a.objects.empty() ? "transfer/diffuse"
                                : lightmaps       ? "objects/a/lightmap/transfer/diffuse"
                                                  : "objects/far/transfer/diffuse";
    const auto sh = std::find_if(j["header"]["arrays"].begin(), j["header"]["arrays"].end(),
                                 [&](const auto& h) { return h["name"] == sh_name; });
    ASSERT_NE(sh, j["header"]["arrays"].end()) << sh_name;
    EXPECT_EQ((*sh)["attrs"]["sh_order"], a.objects.empty() ? 3 : lightmaps ? 2 : 5);
    if (lightmaps) {
      const auto state = std::find_if(j["header"]["arrays"].begin(), j["header"]["arrays"].end(),
                                      [&](const auto& h) { return h["name"] == "objects/a/lightmap/state"; });
      ASSERT_NE(state, j["header"]["arrays"].end());
      EXPECT_EQ((*state)["shape"], nlohmann::json({3, 4})) << "[H][W]";
      EXPECT_EQ((*state)["attrs"]["padding"], 1);
    }
  }
}

// ---- engine probes ----

TEST(ExportProbes, EachEnginesFormulaAtEachVertexNormalIsTheBakedIrradiance) {
  using prt::conventions::Engine;
  const fs::path dir = fresh_dir("probes");
  for (const auto& [format, engine, name] : {std::tuple{ExportFormat::Unity, Engine::Unity, "unity"},
                                             std::tuple{ExportFormat::Godot, Engine::Godot, "godot"},
                                             std::tuple{ExportFormat::Filament, Engine::Filament, "filament"}})
    for (const Asset& a : {vertex_asset(), scene_asset()}) {
      SCOPED_TRACE(std::string(name) + ", up " + a.root.up_axis);
      export_asset(a, "in.prt.h5", format, dir / "p.json");
      const nlohmann::json j = nlohmann::json::parse(prt::testing::read_bytes(dir / "p.json"));
      EXPECT_EQ(j["engine"], name);
      const VertexSet& s = a.objects.empty() ? a.vertices : a.objects[1].set;  // the scene's "lit"
      ASSERT_EQ(j["sets"].size(), 1u);  // only sets with band-1 radiance
      const auto& set = j["sets"][0];
      const std::vector<double> sh = set["sh"], normals = set["normals"], positions = set["positions"];
      const size_t V = s.vertex_count();
      ASSERT_EQ(sh.size(), 27 * V);
      const double k1 = 0.48860251190291992;
      for (size_t v = 0; v < V; ++v) {
        const double nx = s.normals->values[3 * v], ny = s.normals->values[3 * v + 1], nz = s.normals->values[3 * v + 2];
        // The engine's frame by hand: a Z-up file turned Y-up, then Unity mirrors X.
        prt::testing::V3 n_e = a.root.up_axis == "z" ? prt::testing::V3{nx, nz, -ny} : prt::testing::V3{nx, ny, nz};
        if (engine == Engine::Unity) n_e[0] = -n_e[0];
        for (size_t c = 0; c < 3; ++c) EXPECT_NEAR(normals[3 * v + c], n_e[c], 1e-7);
        const double py = s.positions->values[3 * v + 1], pz = s.positions->values[3 * v + 2];
        EXPECT_EQ(positions[3 * v + 1], a.root.up_axis == "z" ? pz : py);
        prt::conventions::EngineSh probe;
        std::copy_n(sh.begin() + long(27 * v), 27, probe.begin());
        for (int c = 0; c < 3; ++c) {
          const float* R = &s.radiance_band1->values[9 * v + 3 * size_t(c)];
          const double E = 4 * kPi / 3 * k1 * (-ny * R[0] + nz * R[1] - nx * R[2]);  // SCHEMA.md
          // Godot's constants have 6 digits: 1e-5 of the terms' magnitude.
          const double scale = 4 * kPi / 3 * k1 * (std::abs(R[0]) + std::abs(R[1]) + std::abs(R[2])) / kPi;
          EXPECT_NEAR(prt::testing::evaluate(engine, probe, c, n_e), E / kPi, 1e-5 * scale + 1e-12);
        }
      }
    }
}

TEST(ExportProbes, TheEnvironmentProbeIsItsIrradianceInEachEnginesFormula) {
  // A full order-3 radiance SH (every coefficient non-zero, distinct per channel): each engine's
  // own formula at normals in its frame must give our E(n)/π at the same direction in the file's
  // frame (conventions::irradiance_over_pi), for both up axes; alone (an AO-only file, which
  // without the environment is refused) and beside the per-vertex probes.
  using prt::conventions::Engine;
  EnvironmentProbe env;
  for (size_t c = 0; c < 3; ++c)
    for (size_t i = 0; i < 9; ++i) env.radiance[c][i] = (i == 0 ? 2.0 : 0.3 * std::sin(1.7 * double(i) + double(c)));
  env.name = "sky.exr";
  env.sha256 = std::string(64, 'e');
  const fs::path dir = fresh_dir("env_probe");
  for (const auto& [format, engine] : {std::pair{ExportFormat::Unity, Engine::Unity}, std::pair{ExportFormat::Godot, Engine::Godot},
                                       std::pair{ExportFormat::Filament, Engine::Filament}})
    for (const std::string up : {"y", "z"}) {
      Asset ao_only = vertex_asset();
      ao_only.root.up_axis = up;
      ao_only.vertices.radiance_band1.reset();
      EXPECT_THROW(export_asset(ao_only, "in.prt.h5", format, dir / "p.json"), FormatError);
      export_asset(ao_only, "in.prt.h5", format, dir / "p.json", env);
      const nlohmann::json j = nlohmann::json::parse(prt::testing::read_bytes(dir / "p.json"));
      EXPECT_TRUE(j["sets"].empty());
      EXPECT_EQ(j["environment"]["sha256"], env.sha256);
      const std::vector<double> sh = j["environment"]["sh"];
      ASSERT_EQ(sh.size(), 27u);
      prt::conventions::EngineSh probe;
      std::copy(sh.begin(), sh.end(), probe.begin());
      for (int k = 0; k < 40; ++k) {
        const double z = 1 - 2 * (k + 0.5) / 40, r = std::sqrt(1 - z * z), phi = 2.39996 * k;
        const double nx = r * std::cos(phi), ny = r * std::sin(phi), nz = z;
        prt::testing::V3 n_e = up == "z" ? prt::testing::V3{nx, nz, -ny} : prt::testing::V3{nx, ny, nz};
        if (engine == Engine::Unity) n_e[0] = -n_e[0];
        for (int c = 0; c < 3; ++c) {
          const double want = prt::conventions::irradiance_over_pi(env.radiance[size_t(c)], nx, ny, nz);
          // Godot's constants have 6 digits: 1e-5 of the coefficients' magnitude.
          EXPECT_NEAR(prt::testing::evaluate(engine, probe, c, n_e), want, 1e-5 * 4) << "up " << up << " k " << k;
        }
      }
    }
  Asset both = vertex_asset();
  export_asset(both, "in.prt.h5", ExportFormat::Unity, dir / "both.json", env);
  const nlohmann::json j = nlohmann::json::parse(prt::testing::read_bytes(dir / "both.json"));
  EXPECT_EQ(j["sets"].size(), 1u);
  EXPECT_EQ(j["environment"]["sh"].size(), 27u);
  EXPECT_THROW(export_asset(both, "in.prt.h5", ExportFormat::Glb, dir / "x.glb", env), std::invalid_argument);
}

TEST(ExportProbes, AFileWithoutBandOneRadianceIsRefusedNamingIt) {
  const fs::path dir = fresh_dir("probes_none");
  Asset a = vertex_asset();
  a.vertices.radiance_band1.reset();
  for (ExportFormat f : {ExportFormat::Unity, ExportFormat::Godot, ExportFormat::Filament}) {
    try {
      export_asset(a, "ao_only.prt.h5", f, dir / "p.json");
      ADD_FAILURE() << "no error";
    } catch (const FormatError& e) {
      EXPECT_EQ(e.file(), "ao_only.prt.h5");
      EXPECT_NE(e.defect().find("/radiance/band1"), std::string::npos) << e.what();
    }
    EXPECT_TRUE(listing(dir).empty());
  }
}

// ---- lightmaps ----

TEST(ExportLightmap, SeamsSplitVerticesCopyingEveryAttributeAndTheOcclusionPngDecodes) {
  const Asset a = lightmap_asset();
  const fs::path dir = fresh_dir("lightmap_gltf");
  export_asset(a, "in.prt.h5", ExportFormat::Glb, dir / "lm.glb");
  const tinygltf::Model m = load(dir / "lm.glb", true);
  const tinygltf::Value& sets = m.asset.extras.Get("prtbake").Get("sets");
  ASSERT_EQ(sets.ArrayLen(), 2u);
  for (size_t si = 0; si < 2; ++si) {
    const VertexSet& s = a.objects[si].set;
    SCOPED_TRACE(a.objects[si].name);
    const tinygltf::Value& entry = sets.Get(int(si));
    const tinygltf::Primitive& prim = m.meshes.at(size_t(entry.Get("mesh").Get<int>())).primitives.at(0);
    const std::vector<uint32_t> idx = read_accessor<uint32_t>(m, prim.indices);
    const std::vector<uint32_t>& tri = s.triangles->values;
    ASSERT_EQ(idx.size(), tri.size());
    // Every corner's UV differs from every other's: each corner is its own export vertex, the
    // file's V rows (at their first corner) and one copy per further corner of a row.
    const size_t V = s.vertex_count(), exported = m.accessors.at(size_t(prim.attributes.at("POSITION"))).count;
    EXPECT_EQ(exported, tri.size()) << "every corner its own vertex here";
    const tinygltf::Value& copies = entry.Get("vertices").Get("copies_of");
    ASSERT_EQ(copies.ArrayLen(), exported - V);
    for (size_t j = 0; j < copies.ArrayLen(); ++j) EXPECT_LT(size_t(copies.Get(int(j)).Get<int>()), V);
    // Each corner's attributes are its file row's, bit for bit.
    const std::vector<float> uv1 = read_accessor<float>(m, prim.attributes.at("TEXCOORD_1"));
    EXPECT_EQ(read_accessor<float>(m, prim.attributes.at("TEXCOORD_0")), uv1);
    const std::vector<float> pos = read_accessor<float>(m, prim.attributes.at("POSITION"));
    const std::vector<float> nrm = read_accessor<float>(m, prim.attributes.at("NORMAL"));
    const std::vector<float> ao = read_accessor<float>(m, prim.attributes.at("_AO"));
    const std::vector<float> tr = read_accessor<float>(m, prim.attributes.at("_PRT_DIFFUSE_0"));
    for (size_t i = 0; i < tri.size(); ++i) {
      const size_t g = idx[i], f = tri[i];
      EXPECT_EQ(uv1[2 * g], s.uv->values[2 * i]);
      EXPECT_EQ(uv1[2 * g + 1], s.uv->values[2 * i + 1]);
      EXPECT_EQ(ao[g], s.ao->values[f]);
      for (size_t c = 0; c < 3; ++c) {
        EXPECT_EQ(pos[3 * g + c], float(s.positions->values[3 * f + c]));
        EXPECT_EQ(nrm[3 * g + c], s.normals->values[3 * f + c]);
      }
      for (size_t c = 0; c < 4; ++c) EXPECT_EQ(tr[4 * g + c], s.transfer_diffuse->values[4 * f + c]);
    }
    // The occlusion texture: texCoord 1, a PNG tinygltf decodes to the AO codes (R channel).
    const tinygltf::Material& mat = m.materials.at(size_t(prim.material));
    EXPECT_EQ(mat.occlusionTexture.texCoord, 1);
    EXPECT_EQ(mat.pbrMetallicRoughness.metallicFactor, 0.0);
    const tinygltf::Image& image = m.images.at(size_t(m.textures.at(size_t(mat.occlusionTexture.index)).source));
    const Lightmap& lm = *s.lightmap;
    ASSERT_EQ(size_t(image.width), lm.width);
    ASSERT_EQ(size_t(image.height), lm.height);
    ASSERT_EQ(image.bits, 8);
    const size_t comps = size_t(image.component);
    for (size_t k = 0; k < lm.texel_count(); ++k)
      EXPECT_EQ(int(image.image.at(k * comps)), int(std::lround(std::clamp(double(lm.ao->values[k]), 0.0, 1.0) * 255.0)))
          << "texel " << k;
    EXPECT_EQ(image.image.at(0), 0);
    EXPECT_EQ(image.image.at(comps), 255);
    // The lightmap datasets as buffer views, bit for bit.
    const tinygltf::Value& datasets = entry.Get("lightmap").Get("datasets");
    ASSERT_EQ(datasets.ArrayLen(), 6u);  // state, positions, normals, ao, transfer/diffuse, radiance/band1
    for (size_t d = 0; d < datasets.ArrayLen(); ++d) {
      const tinygltf::Value& de = datasets.Get(int(d));
      const tinygltf::BufferView& view = m.bufferViews.at(size_t(de.Get("bufferView").Get<int>()));
      const std::string name = de.Get("dataset").Get<std::string>();
      const std::vector<unsigned char>& buf = m.buffers.at(0).data;
      auto floats = [&] {
        std::vector<float> v(view.byteLength / 4);
        std::memcpy(v.data(), buf.data() + view.byteOffset, view.byteLength);
        return v;
      };
      const std::string prefix = "objects/" + a.objects[si].name + "/lightmap/";
      if (name == prefix + "state") EXPECT_EQ(std::vector<uint8_t>(buf.begin() + long(view.byteOffset), buf.begin() + long(view.byteOffset + view.byteLength)), lm.state.values);
      else if (name == prefix + "ao") EXPECT_EQ(floats(), lm.ao->values);
      else if (name == prefix + "transfer/diffuse") EXPECT_EQ(floats(), lm.transfer_diffuse->values);
      else if (name == prefix + "radiance/band1") EXPECT_EQ(floats(), lm.radiance_band1->values);
      else if (name == prefix + "normals") EXPECT_EQ(floats(), lm.normals->values);
      else EXPECT_EQ(name, prefix + "positions");
    }
  }
}

TEST(ExportLightmap, ExrFilesAreNamedPerObjectAndHalfOverflowIsRefused) {
  Asset a = lightmap_asset();
  const fs::path dir = fresh_dir("lightmap_exr");
  export_asset(a, "in.prt.h5", ExportFormat::Exr, dir / "scene.exr");
  EXPECT_EQ(listing(dir), (std::vector<std::string>{"scene.a.exr", "scene.b|c.exr"}));
  const fs::path dir2 = fresh_dir("lightmap_exr_overflow");
  a.objects[1].set.lightmap->radiance_band1->values[5] = 1e5f;  // texel 0, G, m = 1: beyond half's 65504
  try {
    export_asset(a, "in.prt.h5", ExportFormat::Exr, dir2 / "scene");
    ADD_FAILURE() << "no error";
  } catch (const FormatError& e) {
    EXPECT_EQ(e.file(), "in.prt.h5");
    EXPECT_NE(e.defect().find("lightmap of b|c: channel radiance.band1.G.m1 holds 100000"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(listing(dir2).empty()) << "nothing half-written: not even the first object's file";
}

TEST(ExportLightmap, GodotLayersShadeToTheBakedIrradianceAtTheNormalInGodotsFrame) {
  Asset a = lightmap_asset();
  a.root = root("z");
  for (SceneObject& o : a.objects) {
    std::vector<float>& n = o.set.lightmap->normals->values;
    for (size_t k = 0; k < n.size() / 3; ++k) {
      const double v[3] = {std::sin(double(k) + 1), std::cos(2.0 * double(k)), 0.5 + std::sin(3.0 * double(k))};
      const double len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      for (size_t c = 0; c < 3; ++c) n[3 * k + c] = float(v[c] / len);
    }
  }
  const fs::path dir = fresh_dir("lightmap_godot");
  const ExportSummary summary = export_asset(a, "in.prt.h5", ExportFormat::Godot, dir / "g.json");
  EXPECT_EQ(listing(dir), (std::vector<std::string>{"g.json", "g.lightmap.a.exr", "g.lightmap.a.exr.import",
                                                     "g.lightmap.b|c.exr", "g.lightmap.b|c.exr.import"}));
  EXPECT_EQ(summary.written.size(), 5u);
  EXPECT_TRUE(summary.left_out.empty()) << "lit per texel: not left out";
  const Lightmap& m = *a.objects[0].set.lightmap;
  Imf::InputFile file((dir / "g.lightmap.a.exr").c_str());
  const Imath::Box2i w = file.header().dataWindow();
  ASSERT_EQ(size_t(w.max.x - w.min.x + 1), m.width);
  ASSERT_EQ(size_t(w.max.y - w.min.y + 1), 4 * m.height);
  const size_t texels = m.texel_count();
  std::vector<float> rgb[3];
  Imf::FrameBuffer frame;
  for (size_t c = 0; c < 3; ++c) {
    rgb[c].resize(4 * texels);
    frame.insert(std::string(1, "RGB"[c]), Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(rgb[c].data()), sizeof(float), sizeof(float) * m.width));
  }
  file.setFrameBuffer(frame);
  file.readPixels(w.min.y, w.max.y);
  // Half rounding: l0 within 2⁻¹¹ relative; each packed t in [0, 1] within 2⁻¹² absolute, so each
  // unpacked a within 2⁻¹¹ and Godot's 4 l0 (a·n) within 4 l0 · 3 · 2⁻¹¹ of its exact value.
  const double k1 = std::sqrt(3 / (4 * kPi));
  size_t lit = 0;
  for (size_t k = 0; k < texels; ++k) {
    const float* n = &m.normals->values[3 * k];
    const double godot_n[3] = {n[0], n[2], -n[1]};  // Z-up file turned Y-up: (x, y, z) -> (x, z, -y)
    for (size_t c = 0; c < 3; ++c) {
      const float* R = &m.radiance_band1->values[9 * k + 3 * c];
      // E/π = (4/3) Σ_m y_1m(n) R_m, y_1m = k1 (−y, z, −x) (m = −1, 0, 1).
      const double e = 4.0 / 3 * k1 * (-n[1] * R[0] + n[2] * R[1] - n[0] * R[2]);
      const double l0 = rgb[c][k];
      double l1[3];
      for (size_t layer = 1; layer <= 3; ++layer) l1[layer - 1] = (rgb[c][layer * texels + k] - 0.5) * 2;
      if (m.state.values[k] == 0 || e <= 0) {
        EXPECT_EQ(l0, 0.0) << "texel " << k;
        for (double x : l1) EXPECT_EQ(x, 0.0) << "texel " << k;
        continue;
      }
      ++lit;
      EXPECT_NEAR(l0, e, std::ldexp(e, -11)) << "texel " << k << " channel " << c;
      const double shaded = l0 + 4 * l0 * (l1[0] * godot_n[1] + l1[1] * godot_n[2] + l1[2] * godot_n[0]);
      EXPECT_NEAR(shaded, e, std::ldexp(e, -11) + 4 * l0 * 3 * std::ldexp(1.0, -11)) << "texel " << k << " channel " << c;
      for (double x : l1) EXPECT_LE(std::abs(x), 1.0);
    }
  }
  EXPECT_GT(lit, 5u) << "some texels are lit (else the check says little)";
}

TEST(Export, FormatNamesRoundTrip) {
  for (ExportFormat f : {ExportFormat::Gltf, ExportFormat::Glb, ExportFormat::Binary, ExportFormat::Unity,
                         ExportFormat::Godot, ExportFormat::Filament, ExportFormat::Exr, ExportFormat::Web})
    EXPECT_EQ(parse_export_format(to_string(f)), f);
  EXPECT_EQ(parse_export_format("fbx"), std::nullopt);
}

// The web viewer's folder (export_web): the page, three.js, the shading bodies as runtime/shaders
// holds them, the glb and viewer.json, whose environments are turned by R_y per degree. An
// environment that is a lobe along +x (band 1 only: (−y, z, −x)·k, so c = (0, 0, −k)) points along
// −z after 90° ((x, z) → (x cos + z sin, −x sin + z cos)) and along −x after 180°: exact up to the
// 9-digit rounding of the file (half a unit in the 9th digit: 5e-9 relative). The clamped-cosine factors are π, 2π/3, π/4, 0,
// −π/24 (Ramamoorthi & Hanrahan's closed form). The same inputs give the same bytes; a folder
// that is not an earlier export is not replaced; a file without a product the page shades is
// refused naming it.
TEST(ExportWeb, FolderHoldsThePageTheBodiesAndTheTurnedEnvironments) {
  if (const char* why = web_viewer_missing()) GTEST_SKIP() << "this build has no web viewer: " << why;
  const fs::path dir = fresh_dir("web");
  WebEnvironment lobe;
  lobe.name = "lobe.exr";
  lobe.sha256 = std::string(64, 'c');
  lobe.order = 5;
  lobe.radiance.assign(25 * 3, 0.0);
  const double k = 0.75;
  for (size_t c = 0; c < 3; ++c) {
    lobe.radiance[0 * 3 + c] = 1.0 + double(c);
    lobe.radiance[3 * 3 + c] = -k * double(c + 1);  // coefficient (1, 1): -x
  }
  const Asset a = vertex_asset();
  export_web(a, "in.prt.h5", dir / "web", {lobe});
  EXPECT_EQ(listing(dir), (std::vector<std::string>{"web"}));  // no staging left
  for (const char* f : {"index.html", "viewer.js", "asset.glb", "viewer.json", "shaders/prt_lang.glsl", "shaders/sh.inc",
                        "shaders/shade.inc", "shaders/glossy.inc", "three/build/three.module.js", "three/build/three.core.js",
                        "three/examples/jsm/loaders/GLTFLoader.js", "three/LICENSE"})
    EXPECT_TRUE(fs::is_regular_file(dir / "web" / f)) << f;
  auto bytes = [](const fs::path& p) { return prt::testing::read_bytes(p); };
  EXPECT_EQ(bytes(dir / "web/shaders/sh.inc"), bytes(fs::path(PRT_SOURCE_TESTS) / "../runtime/shaders/sh.inc"));
  check_gltf(load(dir / "web/asset.glb", true), a);

  const nlohmann::json info = nlohmann::json::parse(bytes(dir / "web/viewer.json"));
  ASSERT_EQ(info["environments"].size(), 1u);
  const nlohmann::json& e = info["environments"][0];
  EXPECT_EQ(e["order"], 5);
  ASSERT_EQ(e["sh_by_degree"].size(), 360u);
  constexpr double kRounding = 5e-9;  // 9 significant digits
  for (int deg : {0, 90, 180}) {
    const nlohmann::json& row = e["sh_by_degree"][size_t(deg)];
    ASSERT_EQ(row.size(), 75u);
    for (size_t c = 0; c < 3; ++c) {
      const double kc = k * double(c + 1);
      std::vector<double> want(25, 0.0);
      want[0] = 1.0 + double(c);
      if (deg == 0) want[3] = -kc;   // along +x
      if (deg == 90) want[2] = -kc;  // along -z: (-y, z, -x) = (0, -1, 0)
      if (deg == 180) want[3] = kc;  // along -x
      for (size_t i = 0; i < 25; ++i)
        EXPECT_NEAR(row[c * 25 + i].get<double>(), want[i], kRounding * std::max(1.0, std::abs(want[i]))) << deg << " deg, channel " << c << ", i " << i;
    }
  }
  const std::vector<double> cosine = info["clamped_cosine"].get<std::vector<double>>();
  ASSERT_EQ(cosine.size(), 5u);
  for (auto [l, want] : {std::pair{0, kPi}, {1, 2 * kPi / 3}, {2, kPi / 4}, {3, 0.0}, {4, -kPi / 24}})
    EXPECT_NEAR(cosine[size_t(l)], want, 1e-15) << l;
  EXPECT_EQ(info["file"]["vertex_sets"][0]["vertices"], 7);

  // Deterministic: the same inputs, the same bytes (the earlier export is replaced).
  const std::string first = bytes(dir / "web/viewer.json"), glb = bytes(dir / "web/asset.glb");
  export_web(a, "in.prt.h5", dir / "web", {lobe});
  EXPECT_EQ(bytes(dir / "web/viewer.json"), first);
  EXPECT_EQ(bytes(dir / "web/asset.glb"), glb);

  // A folder that is not an earlier export stays as it is.
  fs::create_directories(dir / "mine");
  std::ofstream(dir / "mine/notes.txt") << "keep";
  EXPECT_THROW(export_web(a, "in.prt.h5", dir / "mine", {lobe}), FormatError);
  EXPECT_TRUE(fs::exists(dir / "mine/notes.txt"));

  // Nothing to shade: refused naming the input.
  Asset bare = a;
  bare.vertices.ao.reset();
  bare.vertices.transfer_diffuse.reset();
  bare.vertices.radiance_band1.reset();
  try {
    export_web(bare, "bare.prt.h5", dir / "bare", {});
    FAIL() << "exported a file without a product the page shades";
  } catch (const FormatError& err) {
    EXPECT_NE(std::string(err.what()).find("bare.prt.h5"), std::string::npos) << err.what();
    EXPECT_NE(std::string(err.what()).find("/transfer/diffuse"), std::string::npos) << err.what();
  }
  EXPECT_FALSE(fs::exists(dir / "bare"));
}

} // namespace

// Area lights per texel (lightmap/area_lights/..., a scene object baked per texel) go to the EXR
// lightmap as one half channel per light, named by the light, and per light and SH coefficient:
// each within half's rounding (2^-11 relative) of the file's value.
TEST(ExportLightmap, AreaLightsPerTexelAreExrChannelsNamedByTheirLights) {
  Asset a = lightmap_asset();
  for (const char* name : {"key", "fill"}) a.lights.push_back(prt::testing::quad_light(name));
  Lightmap& m = *a.objects[0].set.lightmap;
  const size_t texels = m.texel_count();
  m.area_irradiance = product(values(texels * 2, 1.6));
  m.area_irradiance->lights = "key\nfill";
  m.area_sh = product(values(texels * 2 * 4, 1.7), 2);
  m.area_sh->lights = "key\nfill";
  const fs::path dir = fresh_dir("lightmap_exr_area");
  export_asset(a, "in.prt.h5", ExportFormat::Exr, dir / "scene.exr");
  Imf::InputFile file((dir / "scene.a.exr").c_str());
  const Imath::Box2i w = file.header().dataWindow();
  ASSERT_EQ(size_t(w.max.x - w.min.x + 1) * size_t(w.max.y - w.min.y + 1), texels);
  // (light, coefficient or -1 for E) → the channel and its column in the file's row.
  const std::vector<std::tuple<std::string, const Product*, size_t, size_t>> want = {
      {"area.irradiance.key", &*m.area_irradiance, 2, 0}, {"area.irradiance.fill", &*m.area_irradiance, 2, 1},
      {"area.sh.key.c0", &*m.area_sh, 8, 0},              {"area.sh.fill.c3", &*m.area_sh, 8, 7}};
  std::vector<std::vector<float>> got(want.size(), std::vector<float>(texels));
  Imf::FrameBuffer frame;
  for (size_t i = 0; i < want.size(); ++i) {
    ASSERT_NE(file.header().channels().findChannel(std::get<0>(want[i]).c_str()), nullptr) << std::get<0>(want[i]);
    frame.insert(std::get<0>(want[i]), Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(got[i].data()), sizeof(float), sizeof(float) * m.width));
  }
  file.setFrameBuffer(frame);
  file.readPixels(w.min.y, w.max.y);
  for (size_t i = 0; i < want.size(); ++i) {
    const auto& [name, product, width, column] = want[i];
    for (size_t k = 0; k < texels; ++k) {
      const double x = product->values[k * width + column];
      EXPECT_NEAR(got[i][k], x, std::abs(x) * std::ldexp(1.0, -11) + std::ldexp(1.0, -25)) << name << " texel " << k;
    }
  }
}
