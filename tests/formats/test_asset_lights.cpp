// Area lights in the baked file (format_version 3; formats/asset.h Light, VertexSet::area_irradiance
// and area_sh): the asset model survives write -> read with the lights' geometry and the products'
// column order; an asset without lights writes nothing of them; files of version 2 still read, and
// version-2 files cannot hold lights; validate() refuses every inconsistency naming the dataset or
// group (shapes against the lights listed, unknown and repeated light names, non-finite values,
// broken face lists, bad light attributes).
#include <formats/asset.h>
#include <formats/names.h>
#include <formats/testing.h>

#include <gtest/gtest.h>
#include <schema_refusal.h>

#include <cmath>
#include <functional>
#include <limits>

namespace fs = std::filesystem;
using namespace prt::formats;
using prt::testing::dataset;
using prt::testing::expect_refused;

namespace {

Light quad(const std::string& name, double y, double radiance) {
  Light l;
  l.name = name;
  l.shape = "quad";
  l.radiance = {radiance, radiance / 2, 0};
  l.two_sided = 0;
  l.vertices.values = {-1, y, -1, 1, y, -1, 1, y, 1, -1, y, 1};
  l.face_sizes.values = {4};
  l.face_indices.values = {0, 1, 2, 3};
  return l;
}

Light box(const std::string& name) {  // two faces are enough for the model; geometry is the bake's business
  Light l;
  l.name = name;
  l.shape = "box";
  l.radiance = {1, 1, 1};
  l.two_sided = 0;
  l.vertices.values = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1};
  l.face_sizes.values = {4, 3};
  l.face_indices.values = {0, 3, 2, 1, 0, 1, 4};
  l.vertices.extra = {{"note", std::string("on a light dataset")}};
  l.extra = {{"layer", std::string("lights")}};
  return l;
}

// One scene object with V = 3 receiving two lights, columns in the order "key", "fill" (not the
// sorted order read_asset returns the lights in), SH at order 2.
Asset lit_asset() {
  Asset a;
  a.root = {kFormatVersionWithoutLightmaps, "test", "2024-01-02T03:04:05Z", "prtbake scene s.json", "s.json", std::string(64, 'a'),
            "y", "real orthonormal", {}};
  SceneObject& o = a.objects.emplace_back();
  o.name = "ground";
  o.role = "both";
  o.set.positions = Array<double>{{0, 0, 0, 1, 0, 0, 0, 0, 1}, {}};
  o.set.normals = Normals{{0, 1, 0, 0, 1, 0, 0, 1, 0}, "file", {}};
  o.set.triangles = Array<uint32_t>{{0, 2, 1}, {}};
  Product& e = o.set.area_irradiance.emplace();
  e.values = {0.5f, 0.25f, 0.0f, 0.125f, 1.0f, 2.0f};  // [V = 3][L = 2]
  e.integrand = "E";
  e.lights = join_light_list({"key", "fill"});
  Product& s = o.set.area_sh.emplace();
  for (int i = 0; i < 3 * 2 * 4; ++i) s.values.push_back(0.0625f * float(i) - 0.5f);
  s.sh_order = 2;
  s.lights = e.lights;
  a.lights = {box("fill"), quad("key", 4, 10)};  // sorted by name, as read_asset gives them
  return a;
}


Attr& attr(std::vector<Attr>& attrs, std::string_view name) {
  for (Attr& a : attrs)
    if (a.name == name) return a;
  ADD_FAILURE() << "no attribute " << name;
  return attrs.front();
}

std::vector<Attr>& group(File& f, const std::string& path) {
  for (auto& [g, attrs] : f.group_attrs)
    if (g == path) return attrs;
  ADD_FAILURE() << "no group attributes " << path;
  return f.group_attrs.front().second;
}

const std::string kE = "/objects/ground/area_lights/irradiance", kS = "/objects/ground/area_lights/sh";

} // namespace

TEST(AssetLights, EveryFieldSurvivesWriteRead) {
  const fs::path dir = fs::path(PRT_TEST_TMP) / "asset_lights";
  fs::create_directories(dir);
  const Asset a = lit_asset();
  write_asset(dir / "a.prt.h5", a);
  const Asset b = read_asset(dir / "a.prt.h5");
  EXPECT_EQ(b.root.format_version, kFormatVersionWithoutLightmaps);
  ASSERT_EQ(b.lights.size(), 2u);
  EXPECT_EQ(b.lights[1], a.lights[1]);
  EXPECT_EQ(b.lights[0], a.lights[0]);  // with the extras of its group and its vertices dataset
  EXPECT_EQ(b.objects, a.objects);
  EXPECT_TRUE(b == a);
  EXPECT_EQ(split_light_list(*b.objects[0].set.area_irradiance->lights), (std::vector<std::string>{"key", "fill"}));
  // Where they land: the schema's paths, shapes and dtypes.
  const File f = read_file(dir / "a.prt.h5");
  EXPECT_EQ(find_dataset(f, kE)->shape, (std::vector<uint64_t>{3, 2}));
  EXPECT_EQ(find_dataset(f, kS)->shape, (std::vector<uint64_t>{3, 2, 4}));
  EXPECT_EQ(dtype_name(find_dataset(f, "/lights/key/vertices")->data), "float64");
  EXPECT_EQ(find_dataset(f, "/lights/fill/face_indices")->shape, (std::vector<uint64_t>{7}));
  const std::vector<Attr>* key = find_group_attrs(f, "/lights/key");
  ASSERT_NE(key, nullptr);
  EXPECT_EQ(std::get<std::string>(find_attr(*key, names::kShape)->value), "quad");
  EXPECT_EQ(std::get<std::vector<double>>(find_attr(*key, names::kRadiance)->value), (std::vector<double>{10, 5, 0}));
  EXPECT_EQ(std::get<int64_t>(find_attr(*key, names::kTwoSided)->value), 0);
}

TEST(AssetLights, AnAssetWithoutLightsWritesNothingOfThem) {
  Asset a = lit_asset();
  a.lights.clear();
  a.objects[0].set.area_irradiance.reset();
  a.objects[0].set.area_sh.reset();
  const File f = to_file(a);
  for (const Dataset& d : f.datasets) EXPECT_EQ(d.path.find("light"), std::string::npos) << d.path;
  for (const auto& [g, attrs] : f.group_attrs) EXPECT_EQ(g.find("light"), std::string::npos) << g;
}

TEST(AssetLights, Version2FilesReadAndCannotHoldLights) {
  const fs::path dir = fs::path(PRT_TEST_TMP) / "asset_lights_v2";
  fs::create_directories(dir);
  Asset a = lit_asset();
  File old = to_file(Asset{a.root, {}, {}, {a.objects[0]}, {}, {}, {}, {}, {}, {}});
  std::erase_if(old.datasets, [](const Dataset& d) { return d.path.find("area_lights") != std::string::npos; });
  old.root_attrs.push_back({"format", std::string("prtbake")});
  old.root_attrs.push_back({"format_version", int64_t{2}});
  prt::formats::testing::write_file_unvalidated(dir / "v2.prt.h5", old);
  const Asset b = read_asset(dir / "v2.prt.h5");
  EXPECT_EQ(b.root.format_version, 2);
  EXPECT_TRUE(b.lights.empty());
  EXPECT_FALSE(b.objects.at(0).set.area_irradiance);

  File lit = to_file(a);
  lit.root_attrs.push_back({"format_version", int64_t{2}});
  expect_refused(lit, "which needs format_version 3");
}

TEST(AssetLights, ValidateRefusesInconsistentAreaLightData) {
  const File good = to_file(lit_asset());
  validate(good, "lit.prt.h5");  // the baseline passes
  const std::vector<std::pair<std::function<void(File&)>, std::string>> cases = {
      {[](File& f) { dataset(f, kE).shape = {3, 1}; dataset(f, kE).data = std::vector<float>{1, 2, 3}; },
       "dataset '" + kE + "' has shape [3, 1]; expected [V, L]"},
      {[](File& f) { attr(dataset(f, kE).attrs, names::kLightOrder).value = std::string("key\nrim"); },
       "dataset '" + kE + "' names light 'rim', which is not in /lights"},
      {[](File& f) { attr(dataset(f, kE).attrs, names::kLightOrder).value = std::string("key\nkey"); },
       "dataset '" + kE + "' names light 'key' twice"},
      {[](File& f) { std::erase_if(dataset(f, kE).attrs, [](const Attr& a) { return a.name == names::kLightOrder; }); },
       "dataset '" + kE + "' lacks the string attribute 'lights'"},
      {[](File& f) { std::get<std::vector<float>>(dataset(f, kE).data)[3] = std::numeric_limits<float>::quiet_NaN(); },
       "dataset '" + kE + "' has a non-finite value (NaN) at index 3 [1, 1]"},
      {[](File& f) { std::get<std::vector<float>>(dataset(f, kS).data)[5] = std::numeric_limits<float>::infinity(); },
       "dataset '" + kS + "' has a non-finite value (Inf)"},
      {[](File& f) { dataset(f, kS).shape = {3, 2, 2, 2}; }, "dataset '" + kS + "' has shape [3, 2, 2, 2]"},
      {[](File& f) { attr(dataset(f, kS).attrs, names::kShOrder).value = int64_t{3}; },
       "dataset '" + kS + "' has shape [3, 2, 4]; expected [V, L, n*n]"},
      {[](File& f) { attr(dataset(f, kS).attrs, names::kLightOrder).value = std::string("fill\nkey"); },
       "dataset '" + kS + "' needs '" + kE + "' beside it, naming the same lights in the same order"},
      {[](File& f) { dataset(f, kE).data = std::vector<uint32_t>(6, 1); }, "dataset '" + kE + "' must be float32"},
      {[](File& f) { std::erase_if(f.datasets, [](const Dataset& d) { return d.path == "/lights/key/face_sizes"; }); },
       "light '/lights/key' lacks the dataset 'face_sizes'"},
      {[](File& f) { std::get<std::vector<uint32_t>>(dataset(f, "/lights/key/face_indices").data)[2] = 4; },
       "dataset '/lights/key/face_indices' has vertex index 4 >= N = 4"},
      {[](File& f) { std::get<std::vector<uint32_t>>(dataset(f, "/lights/fill/face_sizes").data)[1] = 4; },
       "dataset '/lights/fill/face_indices' has 7 indices but the face sizes add up to 8"},
      {[](File& f) { std::get<std::vector<uint32_t>>(dataset(f, "/lights/fill/face_sizes").data)[1] = 2; },
       "dataset '/lights/fill/face_sizes' has a face of 2 vertices"},
      {[](File& f) {
         Dataset& v = dataset(f, "/lights/key/vertices");
         v.data = std::vector<float>(12, 0.0f);
       },
       "dataset '/lights/key/vertices' must be float64, not float32"},
      {[](File& f) { std::get<std::vector<double>>(dataset(f, "/lights/key/vertices").data)[4] = std::nan(""); },
       "dataset '/lights/key/vertices' has a non-finite value (NaN) at index 4 [1, 1]"},
      {[](File& f) { attr(group(f, "/lights/key"), names::kRadiance).value = std::vector<double>{1, -1, 1}; },
       "group '/lights/key' needs attribute 'radiance': 3 doubles >= 0"},
      {[](File& f) { attr(group(f, "/lights/key"), names::kTwoSided).value = int64_t{2}; },
       "group '/lights/key' needs attribute 'two_sided': the integer 0 or 1"},
      {[](File& f) { std::erase_if(group(f, "/lights/key"), [](const Attr& a) { return a.name == names::kShape; }); },
       "group '/lights/key' lacks the required attribute 'shape'"},
      {[](File& f) { f.group_attrs.emplace_back("/lights/rim", std::vector<Attr>{{"shape", std::string("quad")}}); },
       "group '/lights/rim' has no 'vertices' dataset"},
      {[](File& f) { std::erase_if(f.group_attrs, [](const auto& g) { return g.first == "/lights/key"; }); },
       "light '/lights/key' lacks its attributes"},
      {[](File& f) { std::erase_if(f.datasets, [](const Dataset& d) { return d.path == kE; }); },
       "dataset '" + kS + "' needs '" + kE + "' beside it"},
      {[](File& f) { std::erase_if(f.datasets, [](const Dataset& d) { return d.path == "/objects/ground/mesh/normals"; }); },
       "needs /objects/ground/mesh/normals"},
  };
  for (const auto& [mutate, message] : cases) {
    File f = good;
    mutate(f);
    expect_refused(f, message);
  }
}
