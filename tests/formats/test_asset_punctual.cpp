// Punctual lights in the baked file (format_version 6; formats/asset.h Light): a point, a spot and
// a directional light survive write -> read beside an area light, as groups without datasets; the
// file is written as version 6 only when it holds one (an area-light file keeps version 4); a
// version-5 file cannot hold one; validate() refuses a punctual light with datasets, a spot with
// its cones crossed, a negative intensity, a missing position or a zero direction, naming the group.
#include <formats/asset.h>
#include <formats/names.h>
#include <formats/testing.h>

#include <gtest/gtest.h>
#include <schema_refusal.h>

#include <filesystem>

namespace fs = std::filesystem;
using namespace prt::formats;
using prt::testing::expect_refused;

namespace {

Light quad() {
  Light l;
  l.name = "key";
  l.shape = "quad";
  l.radiance = {10, 10, 10};
  l.two_sided = 0;
  l.vertices.values = {-1, 4, -1, 1, 4, -1, 1, 4, 1, -1, 4, 1};
  l.face_sizes.values = {4};
  l.face_indices.values = {0, 1, 2, 3};
  return l;
}

Light punctual(const std::string& name, const std::string& shape) {
  Light l;
  l.name = name;
  l.shape = shape;
  l.radiance = {5, 4, 3};
  if (shape != "directional") l.position = std::vector<double>{0.25, 3, 0.125};
  if (shape != "point") l.direction = std::vector<double>{0, -1, 0};
  if (shape == "spot") l.inner_cone_angle = 0.2, l.outer_cone_angle = 0.6, l.range = 7.5;  // KHR's optional range
  return l;
}

Asset lit_asset() {
  Asset a;
  a.root = {kFormatVersion, "test", "2024-01-02T03:04:05Z", "prtbake scene s.json", "s.json", std::string(64, 'a'),
            "y", "real orthonormal", {}};
  SceneObject& o = a.objects.emplace_back();
  o.name = "ground";
  o.role = "both";
  o.set.positions = Array<double>{{0, 0, 0, 1, 0, 0, 0, 0, 1}, {}};
  o.set.normals = Normals{{0, 1, 0, 0, 1, 0, 0, 1, 0}, "file", {}};
  o.set.triangles = Array<uint32_t>{{0, 2, 1}, {}};
  Product& e = o.set.area_irradiance.emplace();
  e.values = {0.5f, 0.25f, 0.0f, 0.125f, 1.0f, 2.0f, 0.5f, 0.25f, 0.0f, 0.125f, 1.0f, 2.0f};  // [V = 3][L = 4]
  e.integrand = "E";
  e.lights = join_light_list({"key", "bulb", "cone", "sun"});
  a.lights = {punctual("bulb", "point"), punctual("cone", "spot"), quad(), punctual("sun", "directional")};  // sorted by name
  return a;
}

std::vector<Attr>& group(File& f, const std::string& path) {
  for (auto& [g, attrs] : f.group_attrs)
    if (g == path) return attrs;
  ADD_FAILURE() << "no group attributes " << path;
  return f.group_attrs.front().second;
}

} // namespace

TEST(AssetPunctual, EveryFieldSurvivesWriteReadAsVersion6) {
  const fs::path dir = fs::path(PRT_TEST_TMP) / "asset_punctual";
  fs::create_directories(dir);
  const Asset a = lit_asset();
  write_asset(dir / "a.prt.h5", a);
  const Asset b = read_asset(dir / "a.prt.h5");
  EXPECT_EQ(b.root.format_version, 6);
  EXPECT_EQ(b.lights, a.lights);
  EXPECT_EQ(b.objects, a.objects);
  const File f = read_file(dir / "a.prt.h5");
  for (const Dataset& d : f.datasets) EXPECT_FALSE(d.path.starts_with("/lights/bulb") || d.path.starts_with("/lights/sun")) << d.path;
  // Without the punctual lights the same asset is an area-light file of version 4, unchanged.
  Asset area = a;
  std::erase_if(area.lights, [](const Light& l) { return names::is_punctual_shape(l.shape); });
  area.objects[0].set.area_irradiance->values.resize(3);
  area.objects[0].set.area_irradiance->lights = "key";
  write_asset(dir / "area.prt.h5", area);
  EXPECT_EQ(read_asset(dir / "area.prt.h5").root.format_version, kFormatVersionWithoutLightmaps);
}

TEST(AssetPunctual, ValidateRefusesBadPunctualLights) {
  const File good = to_file(lit_asset());
  auto with_version = [](File f, int64_t v) {
    f.root_attrs.push_back({std::string(names::kFormatVersion), v});
    return f;
  };
  expect_refused(with_version(good, 5), "which need format_version 6 (the file says 5)");
  {
    File f = good;
    f.datasets.push_back({"/lights/bulb/vertices", {1, 3}, std::vector<double>{0, 0, 0}, {}});
    expect_refused(f, "punctual light '/lights/bulb' has datasets");
  }
  auto edit = [&](const std::string& g, const std::string& name, AttrValue v, const std::string& message) {
    File f = good;
    std::vector<Attr>& attrs = group(f, g);
    std::erase_if(attrs, [&](const Attr& x) { return x.name == name; });
    if (!std::holds_alternative<std::string>(v) || !std::get<std::string>(v).empty()) attrs.push_back({name, v});
    expect_refused(f, message);
  };
  edit("/lights/cone", "inner_cone_angle", 0.7, "group '/lights/cone' needs 0 <= inner_cone_angle < outer_cone_angle <= pi/2");
  edit("/lights/cone", "outer_cone_angle", 2.0, "group '/lights/cone' needs 0 <= inner_cone_angle < outer_cone_angle <= pi/2");
  edit("/lights/bulb", "radiance", std::vector<double>{1, -1, 1}, "group '/lights/bulb' needs attribute 'radiance': 3 doubles >= 0");
  edit("/lights/bulb", "position", std::string(), "group '/lights/bulb' (a point light) needs attribute 'position'");
  edit("/lights/sun", "direction", std::vector<double>{0, 0, 0}, "group '/lights/sun' has a zero direction");
  edit("/lights/cone", "outer_cone_angle", std::string(), "group '/lights/cone' (a spot light) needs attribute 'outer_cone_angle'");
  edit("/lights/cone", "range", 0.0, "group '/lights/cone' has attribute 'range' that is not a finite double > 0");
  edit("/lights/cone", "range", std::string("far"), "group '/lights/cone' has attribute 'range' that is not a finite double > 0");
  edit("/lights/sun", "range", 10.0, "group '/lights/sun' (a directional light) has a 'range': only point and spot lights have one");
}
