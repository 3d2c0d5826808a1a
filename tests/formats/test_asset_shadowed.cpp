// Shadowed radiance in the baked file (format_version 4; formats/asset.h
// VertexSet::radiance_shadowed, /radiance/shadowed [V][RGB][L*L]; paper 001 §4 "Material
// Editing"): the asset model survives write -> read in the root layout and in a scene object, the
// dataset has the schema's shape and dtype, and validate() refuses a wrong shape, a missing
// sh_order, a missing normals dataset and a file of version 3 holding it.
#include <formats/asset.h>
#include <formats/names.h>
#include <formats/testing.h>

#include <gtest/gtest.h>
#include <schema_refusal.h>

namespace fs = std::filesystem;
using namespace prt::formats;
using prt::testing::expect_refused;

namespace {

// S at order 2 for V = 3 vertices: 3 × 3 × 4 values, each distinct.
Product shadowed_product() {
  Product s;
  for (int i = 0; i < 3 * 3 * 4; ++i) s.values.push_back(0.125f * float(i) - 1.0f);
  s.sh_order = 2;
  s.integrand = "S_c,i = Int L_c V H y_i dw";
  s.environment = "sunset.exr";
  s.environment_sha256 = std::string(64, 'b');
  s.environment_layout = "latlong";
  s.integrator = "silhouette";
  s.samples = 16384;
  return s;
}

VertexSet vertex_set() {
  VertexSet v;
  v.positions = Array<double>{{0, 0, 0, 1, 0, 0, 0, 0, 1}, {}};
  v.normals = Normals{{0, 1, 0, 0, 1, 0, 0, 1, 0}, "file", {}};
  v.triangles = Array<uint32_t>{{0, 2, 1}, {}};
  v.radiance_shadowed = shadowed_product();
  return v;
}

Asset asset(bool scene) {
  Asset a;
  a.root = {kFormatVersionWithoutLightmaps, "test", "2024-01-02T03:04:05Z", "prtbake x", "x.obj", std::string(64, 'a'),
            "y", "real orthonormal", {}};
  if (!scene) {
    a.vertices = vertex_set();
    return a;
  }
  SceneObject& o = a.objects.emplace_back();
  o.name = "statue";
  o.role = "both";
  o.set = vertex_set();
  return a;
}

Dataset& shadowed_dataset(File& f) {
  for (Dataset& d : f.datasets)
    if (d.path.ends_with(names::kRadianceShadowed)) return d;
  ADD_FAILURE() << "no shadowed radiance dataset";
  return f.datasets.front();
}

} // namespace

TEST(AssetShadowed, SurvivesWriteReadInTheRootLayoutAndInASceneObject) {
  const fs::path dir = fs::path(PRT_TEST_TMP) / "asset_shadowed";
  fs::create_directories(dir);
  for (const bool scene : {false, true}) {
    const Asset a = asset(scene);
    const fs::path path = dir / (scene ? "scene.prt.h5" : "root.prt.h5");
    write_asset(path, a);
    const Asset b = read_asset(path);
    EXPECT_EQ(b, a);
    EXPECT_EQ(b.root.format_version, 4);
    File f = to_file(a);
    const Dataset& d = shadowed_dataset(f);
    EXPECT_EQ(d.path, (scene ? std::string("/objects/statue") : std::string()) + std::string(names::kRadianceShadowed));
    EXPECT_EQ(d.shape, (std::vector<uint64_t>{3, 3, 4}));
    EXPECT_EQ(dtype_name(d.data), "float32");
    EXPECT_TRUE(is_per_vertex_path(d.path));
  }
}

TEST(AssetShadowed, ValidateRefusesWhatTheSchemaForbids) {
  const File good = to_file(asset(false));
  validate(good, "s.prt.h5");
  File f = good;
  shadowed_dataset(f).shape = {3, 3, 2, 2};  // order 2 in another shape
  expect_refused(f, "[V, 3 (RGB), L*L] with L = sh_order = 2");
  f = good;
  std::erase_if(shadowed_dataset(f).attrs, [](const Attr& a) { return a.name == names::kShOrder; });
  expect_refused(f, "sh_order");
  f = good;
  std::erase_if(f.datasets, [](const Dataset& d) { return d.path == names::kNormals; });
  expect_refused(f, "needs /mesh/normals");
  f = good;
  f.root_attrs.push_back({std::string(names::kFormatVersion), int64_t{3}});
  expect_refused(f, "which needs format_version 4");
}
