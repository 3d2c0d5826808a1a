// Lightmaps in the baked file (format_version 5; formats/asset.h Uvs and Lightmap, /mesh/uv
// [T][3][2] and /lightmap/... [H][W][...]): the asset model survives write -> read in the root
// layout and in a scene object, texel positions are float64 exactly when float32 would round
// them, validate() refuses each broken rule with its message, and a file without a v5 dataset is
// still written as version 4, byte for byte what an explicit version 4 gives.
#include <formats/asset.h>
#include <formats/names.h>
#include <formats/testing.h>

#include <gtest/gtest.h>
#include <quad_light.h>
#include <run_tool.h>
#include <schema_refusal.h>
#include <scratch.h>

#include <cmath>

namespace fs = std::filesystem;
using namespace prt::formats;
using prt::testing::dataset;
using prt::testing::expect_refused;

namespace {

constexpr uint64_t kH = 2, kW = 3;  // not square: a swapped H and W shows

// n distinct values from `first` in steps of 1/8 (exact in float32).
std::vector<float> ramp(std::size_t n, float first) {
  std::vector<float> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = first + 0.125f * float(i);
  return v;
}

Product product(std::size_t per_texel, std::optional<int64_t> sh_order, float first) {
  Product p;
  p.values = ramp(kH * kW * per_texel, first);
  p.sh_order = sh_order;
  p.integrand = "per texel";
  p.integrator = "qmc";
  p.samples = 256;
  p.seed = 0;
  p.extra = {{"note", std::string("kept")}};
  return p;
}

// One triangle (T = 1) with per-vertex AO, its UV set and a 2 x 3 lightmap holding every dataset
// (state: every code once, and baked twice more). `offset` moves every position: 0 keeps them
// float32, 1e5 + 1e-4 needs float64.
VertexSet lightmap_set(double offset = 0) {
  VertexSet v;
  v.positions = Array<double>{{offset, 0, 0, offset + 1, 0, 0, offset, 0, 1}, {}};
  v.normals = Normals{{0, 1, 0, 0, 1, 0, 0, 1, 0}, "file", {}};
  v.triangles = Array<uint32_t>{{0, 2, 1}, {}};
  v.ao.emplace().values = {0.25f, 0.5f, 0.75f};
  v.uv = Uvs{{0.125f, 0.25f, 0.125f, 0.75f, 0.875f, 0.25f}, "TEXCOORD_1", {{"note", std::string("uv kept")}}};
  Lightmap& m = v.lightmap.emplace();
  m.height = kH, m.width = kW;
  m.state = {{1, 2, 3, 0, 1, 1}, {{"note", std::string("state kept")}}};
  m.padding = 2;
  m.positions.emplace();
  for (uint64_t t = 0; t < kH * kW; ++t)
    for (double c : {offset + 0.125 * double(t), 0.0, 0.25 * double(t)}) m.positions->values.push_back(c);
  m.normals = Array<float>{std::vector<float>(kH * kW * 3, 0.0f), {}};
  for (uint64_t t = 0; t < kH * kW; ++t) m.normals->values[3 * t + 1] = 1;
  m.ao = product(1, std::nullopt, 0);
  m.transfer_diffuse = product(4, 2, 1);
  m.transfer_visibility = product(9, 3, 2);
  m.radiance_band1 = product(9, std::nullopt, 3);
  m.radiance_shadowed = product(3 * 4, 2, 4);
  return v;
}

Asset asset(bool scene, double offset = 0) {
  Asset a;
  a.root = {kFormatVersionWithLightmaps, "test", "2024-01-02T03:04:05Z", "prtbake x", "x.obj", std::string(64, 'a'),
            "y", "real orthonormal", {}};
  if (!scene) {
    a.vertices = lightmap_set(offset);
    return a;
  }
  SceneObject& o = a.objects.emplace_back();
  o.name = "floor";
  o.role = "receiver";
  o.set = lightmap_set(offset);
  return a;
}

void erase(File& f, std::string_view path) {
  std::erase_if(f.datasets, [&](const Dataset& d) { return d.path == path; });
}

int64_t stored_version(const fs::path& path) {
  return std::get<int64_t>(find_attr(read_file(path).root_attrs, names::kFormatVersion)->value);
}

} // namespace

TEST(AssetLightmap, SurvivesWriteReadInTheRootLayoutAndInASceneObject) {
  const fs::path dir = prt::testing::fresh_dir("asset_lightmap", "roundtrip");
  for (const bool scene : {false, true}) {
    SCOPED_TRACE(scene ? "scene object" : "root layout");
    const Asset a = asset(scene);
    const fs::path path = dir / (scene ? "scene.prt.h5" : "root.prt.h5");
    write_asset(path, a);
    const Asset b = read_asset(path);
    const VertexSet& want = scene ? a.objects[0].set : a.vertices;
    const VertexSet& got = scene ? b.objects.at(0).set : b.vertices;
    EXPECT_EQ(got.uv, want.uv);
    EXPECT_EQ(got.lightmap, want.lightmap);
    EXPECT_EQ(b, a);
    EXPECT_EQ(stored_version(path), 5);

    // Where they land: after the set's version-4 datasets, state first, in the schema's shapes.
    const std::string set = scene ? "/objects/floor" : "";
    const File f = to_file(a);
    std::vector<std::string> paths;
    for (const Dataset& d : f.datasets) paths.push_back(d.path);
    std::vector<std::string> expected;
    for (std::string_view p : {names::kPositions, names::kNormals, names::kTriangles, names::kAo, names::kUv,
                               names::kLightmapState, names::kLightmapPositions, names::kLightmapNormals,
                               names::kLightmapAo, names::kLightmapTransferDiffuse, names::kLightmapTransferVisibility,
                               names::kLightmapRadianceBand1, names::kLightmapRadianceShadowed})
      expected.push_back(set + std::string(p));
    EXPECT_EQ(paths, expected);
    const File r = read_file(path);
    auto shape = [&](std::string_view p) { return find_dataset(r, set + std::string(p))->shape; };
    using S = std::vector<uint64_t>;
    EXPECT_EQ(shape(names::kUv), (S{1, 3, 2}));
    EXPECT_EQ(shape(names::kLightmapState), (S{kH, kW}));
    EXPECT_EQ(shape(names::kLightmapPositions), (S{kH, kW, 3}));
    EXPECT_EQ(shape(names::kLightmapNormals), (S{kH, kW, 3}));
    EXPECT_EQ(shape(names::kLightmapAo), (S{kH, kW}));
    EXPECT_EQ(shape(names::kLightmapTransferDiffuse), (S{kH, kW, 4}));
    EXPECT_EQ(shape(names::kLightmapTransferVisibility), (S{kH, kW, 9}));
    EXPECT_EQ(shape(names::kLightmapRadianceBand1), (S{kH, kW, 3, 3}));
    EXPECT_EQ(shape(names::kLightmapRadianceShadowed), (S{kH, kW, 3, 4}));
    const Dataset& state = *find_dataset(r, set + std::string(names::kLightmapState));
    EXPECT_EQ(dtype_name(state.data), "uint8");
    EXPECT_EQ(std::get<int64_t>(find_attr(state.attrs, names::kPadding)->value), 2);
    const Dataset& uv = *find_dataset(r, set + std::string(names::kUv));
    EXPECT_EQ(std::get<std::string>(find_attr(uv.attrs, names::kUvSet)->value), "TEXCOORD_1");
    EXPECT_EQ(dtype_name(find_dataset(r, set + std::string(names::kLightmapPositions))->data), "float32");
    // Per triangle corner and per texel: not per-vertex; each belongs to its vertex set.
    for (const std::string& p : expected) {
      EXPECT_EQ(vertex_set_of(p), set) << p;
      if (p.starts_with(set + std::string(names::kLightmapGroup)) || p == set + std::string(names::kUv)) {
        EXPECT_FALSE(is_per_vertex_path(p)) << p;
        EXPECT_TRUE(is_lightmap_kind(dataset_kind(p))) << p;
      }
    }
  }
}

TEST(AssetLightmap, TexelPositionsAreFloat64ExactlyWhenFloat32WouldRoundThem) {
  const fs::path dir = prt::testing::fresh_dir("asset_lightmap", "far");
  const Asset a = asset(false, 1e5 + 1e-4);
  write_asset(dir / "far.prt.h5", a);
  EXPECT_EQ(read_asset(dir / "far.prt.h5"), a);
  const File r = read_file(dir / "far.prt.h5");
  EXPECT_EQ(dtype_name(find_dataset(r, names::kLightmapPositions)->data), "float64");
  EXPECT_EQ(dtype_name(find_dataset(r, names::kPositions)->data), "float64");
  EXPECT_EQ(dtype_name(find_dataset(r, names::kLightmapNormals)->data), "float32");
}

TEST(AssetLightmap, ValidateRefusesWhatTheSchemaForbids) {
  const File good = to_file(asset(false));
  validate(good, "l.prt.h5");  // the baseline passes
  const std::string state(names::kLightmapState), uv(names::kUv), ao(names::kLightmapAo);
  File f = good;
  dataset(f, ao).shape = {kW, kH};  // H and W swapped
  expect_refused(f, "dataset '/lightmap/ao' has shape [3, 2]; expected [H, W] = [2, 3]");
  f = good;
  dataset(f, names::kLightmapTransferDiffuse).shape = {kH, kW, 2, 2};
  expect_refused(f, "expected [H, W, L*L] with L = sh_order = 2 = [2, 3, 4]");
  f = good;
  dataset(f, names::kLightmapRadianceShadowed).shape = {kH * kW, 3, 4};
  expect_refused(f, "expected [H, W, 3 (RGB), L*L] with L = sh_order = 2 = [2, 3, 3, 4]");
  f = good;
  dataset(f, names::kLightmapNormals).shape = {kH, kW * 3};
  expect_refused(f, "expected [H, W, 3] = [2, 3, 3]");
  f = good;
  std::erase_if(dataset(f, names::kLightmapTransferVisibility).attrs, [](const Attr& a) { return a.name == names::kShOrder; });
  expect_refused(f, "dataset '/lightmap/transfer/visibility' lacks the integer attribute 'sh_order'");
  f = good;
  std::get<std::vector<uint8_t>>(dataset(f, state).data)[4] = 4;
  expect_refused(f, "dataset '/lightmap/state' has state 4 at index 4 [1, 1]; a texel is 0 (empty), 1 (baked), "
                    "2 (filled) or 3 (padding)");
  f = good;
  dataset(f, state).shape = {kH * kW};
  expect_refused(f, "dataset '/lightmap/state' has shape [6]; expected [H, W] with H, W >= 1");
  f = good;
  dataset(f, state).data = std::vector<float>(kH * kW, 1.0f);
  expect_refused(f, "dataset '/lightmap/state' must be uint8, not float32");
  f = good;
  erase(f, state);
  expect_refused(f, "dataset '/lightmap/positions' needs /lightmap/state beside it");
  f = good;
  erase(f, uv);
  expect_refused(f, "dataset '/lightmap/state' needs /mesh/uv (the UV set its texels lie in)");
  f = good;
  dataset(f, uv).shape = {2, 3, 1};  // the values of one triangle as two: T must be the triangles'
  expect_refused(f, "dataset '/mesh/uv' has shape [2, 3, 1]; expected [T, 3 (corners), 2 (u, v)] with T = rows of "
                    "/mesh/triangles = [1, 3, 2]");
  f = good;
  erase(f, names::kTriangles);
  expect_refused(f, "dataset '/mesh/uv' needs /mesh/triangles");
  f = good;
  std::get<std::vector<float>>(dataset(f, uv).data)[3] = std::nanf("");
  expect_refused(f, "dataset '/mesh/uv' has a non-finite value (NaN) at index 3");
  f = good;
  std::get<std::vector<float>>(dataset(f, names::kLightmapPositions).data)[5] = INFINITY;
  expect_refused(f, "dataset '/lightmap/positions' has a non-finite value (Inf)");
  f = good;
  std::get<std::vector<float>>(dataset(f, names::kLightmapNormals).data)[0] = std::nanf("");
  expect_refused(f, "dataset '/lightmap/normals' has a non-finite value (NaN)");
  f = good;
  dataset(f, names::kLightmapNormals).data = std::vector<double>(kH * kW * 3, 0.0);
  expect_refused(f, "dataset '/lightmap/normals' must be float32, not float64");
  f = good;
  f.root_attrs.push_back({std::string(names::kFormatVersion), int64_t{4}});
  expect_refused(f, "dataset '/mesh/uv' is a lightmap's, which needs format_version 5 (the file says 4)");
  f = good;
  erase(f, uv);  // the lightmap alone, in a version-4 file: refused for its version first
  f.root_attrs.push_back({std::string(names::kFormatVersion), int64_t{4}});
  expect_refused(f, "dataset '/lightmap/state' is a lightmap's, which needs format_version 5 (the file says 4)");

  // A scene object's lightmap: the same rules inside its own vertex set.
  const File scene = to_file(asset(true));
  validate(scene, "l.prt.h5");
  f = scene;
  erase(f, "/objects/floor" + uv);
  expect_refused(f, "dataset '/objects/floor/lightmap/state' needs /objects/floor/mesh/uv");
  f = scene;
  erase(f, "/objects/floor" + state);
  expect_refused(f, "needs /objects/floor/lightmap/state beside it");
  f = scene;
  f.datasets.push_back(dataset(f, "/objects/floor" + uv));
  f.datasets.back().path = uv;  // the root layout has no triangles
  expect_refused(f, "dataset '/mesh/uv' needs /mesh/triangles");
}

TEST(AssetLightmap, OnlyAFileWithAVersion5DatasetIsWrittenAsVersion5) {
  const fs::path dir = prt::testing::fresh_dir("asset_lightmap", "version");
  Asset a = asset(false);
  a.vertices.uv.reset();
  a.vertices.lightmap.reset();
  a.root.format_version = 4;
  const File f = to_file(a);
  EXPECT_EQ(written_format_version(f), 4);
  write_asset(dir / "v4.prt.h5", a);
  EXPECT_EQ(stored_version(dir / "v4.prt.h5"), 4);
  EXPECT_EQ(read_asset(dir / "v4.prt.h5"), a);
  // Byte for byte the file of an explicit version 4: the version is the only thing that changed.
  File explicit4 = f;
  explicit4.root_attrs.insert(explicit4.root_attrs.begin(), {{std::string(names::kFormat), std::string(kFormatName)},
                                                             {std::string(names::kFormatVersion), int64_t{4}}});
  prt::formats::testing::write_file_unvalidated(dir / "explicit4.prt.h5", explicit4);
  EXPECT_EQ(prt::testing::read_bytes(dir / "v4.prt.h5"), prt::testing::read_bytes(dir / "explicit4.prt.h5"));

  // A UV set alone (no lightmap yet) is version 5, in the root layout or a scene object.
  a.vertices.uv = lightmap_set().uv;
  a.root.format_version = 5;
  EXPECT_EQ(written_format_version(to_file(a)), 5);
  write_asset(dir / "uv.prt.h5", a);
  EXPECT_EQ(stored_version(dir / "uv.prt.h5"), 5);
  EXPECT_EQ(read_asset(dir / "uv.prt.h5"), a);
  EXPECT_EQ(written_format_version(to_file(asset(true))), 5);
}

// Area lights per texel (lightmap/area_lights/..., a scene object baked per texel): [H, W, L] and
// [H, W, L, n*n], naming the file's lights; they survive a round trip, and an sh without the
// irradiance beside it, or naming other lights, is refused.
TEST(AssetLightmap, AreaLightsPerTexelSurviveAndFollowTheAreaRules) {
  const fs::path dir = prt::testing::fresh_dir("asset_lightmap", "area");
  Asset a = asset(true);
  for (const char* name : {"key", "fill"}) a.lights.push_back(prt::testing::quad_light(name));
  Lightmap& m = *a.objects[0].set.lightmap;
  m.area_irradiance = product(2, std::nullopt, 5);
  m.area_irradiance->lights = "key\nfill";
  m.area_sh = product(2 * 4, 2, 6);
  m.area_sh->lights = "key\nfill";
  const fs::path path = dir / "area.prt.h5";
  write_asset(path, a);
  const Asset b = read_asset(path);
  EXPECT_EQ(b.objects.at(0).set.lightmap, a.objects[0].set.lightmap);
  EXPECT_EQ(b.lights.size(), a.lights.size());
  EXPECT_EQ(b.objects, a.objects);
  EXPECT_EQ(b.root, a.root);
  const File f = to_file(a);
  EXPECT_EQ(dataset(const_cast<File&>(f), "/objects/floor/lightmap/area_lights/irradiance").shape,
            (std::vector<uint64_t>{kH, kW, 2}));
  EXPECT_EQ(dataset(const_cast<File&>(f), "/objects/floor/lightmap/area_lights/sh").shape,
            (std::vector<uint64_t>{kH, kW, 2, 4}));
  // The sh names other lights than the irradiance beside it: refused.
  Asset other = a;
  other.objects[0].set.lightmap->area_sh->lights = "fill\nkey";
  EXPECT_THROW(write_asset(dir / "other.prt.h5", other), std::exception);
  EXPECT_FALSE(fs::exists(dir / "other.prt.h5"));
}
