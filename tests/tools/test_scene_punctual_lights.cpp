// `prtbake scene` with punctual lights (issue 32; bake/lights/punctual.h): a point, a spot and a
// directional light beside a quad area light over a ground grid with a box between them. The
// irradiance baked at chosen vertices equals the closed forms (I cosθ / d², the spot's
// KHR_lights_punctual falloff, n·l; 0 in the box's hard shadow); the lights are stored in /lights
// (format_version 6) and named in the products' column order after the area light; 1 and 2
// threads and a sharded bake (--shard I/2 + --merge) write the same bytes; prtdump shows them;
// a glTF's KHR_lights_punctual lights are read with their node transforms, and the options'
// gltf_lights make a point light a sphere light and a directional light a sun disc; bad lights
// are refused naming the file and the light.
#include <bake/lights/punctual.h>
#include <formats/asset.h>

#include <gltf_builder.h>
#include <ground_and_box.h>
#include <gtest/gtest.h>
#include <mesh_files.h>
#include <run_tool.h>
#include <segment_box.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

namespace fs = std::filesystem;
namespace F = prt::formats;
using Eigen::Vector3d;

namespace {

fs::path fresh_dir(const std::string& name) {
  fs::remove_all(fs::path(PRT_TEST_TMP) / "punctual_scenes" / name);
  return prt::testing::test_dir("punctual_scenes/" + name);
}

// Stored as float32: a value of the order of 1 keeps 2^-24 of itself.
constexpr double kFloat = 1e-6;

// The ground and the box (tests/common/ground_and_box.h).
void write_meshes(const fs::path& d) { prt::testing::write_ground_and_box(d); }

const Vector3d kPoint(0.25, 3, 0.125), kSpot(0, 4, 0), kSpotAxis(0, -1, 0), kSun(0.5, -1, 0.25);
const double kInner = 20, kOuter = 40;  // degrees

std::string lights_json(const std::string& extra = "") {
  return R"("lights": [{"name": "key", "shape": "quad", "centre": [0, 4, 0], "u": [2, 0, 0], "v": [0, 0, 2], "radiance": [10, 10, 10]},
    {"name": "bulb", "shape": "point", "position": [0.25, 3, 0.125], "intensity": [5, 4, 3]},
    {"name": "cone", "shape": "spot", "position": [0, 4, 0], "direction": [0, -1, 0], "inner_cone_angle": 20, "outer_cone_angle": 40, "intensity": [100, 100, 100]},
    {"name": "sun", "shape": "directional", "direction": [0.5, -1, 0.25], "intensity": [2, 2, 2]})" +
         extra + "]";
}

std::string scene_text(const std::string& lights) {
  return R"({"prtbake_scene": 1, "bake": {"samples": 256, "report": 0}, )" + lights +
         R"(, "objects": [{"mesh": "ground.obj", "role": "both", "material": {"albedo": [0.5, 0.5, 0.5]}},
                        {"mesh": "box.obj", "role": "occluder"}]})";
}

prt::testing::ToolRun prtbake(const fs::path& d, const std::string& args) {
  return prt::testing::run_tool(PRT_PRTBAKE, args, d / "capture", "SOURCE_DATE_EPOCH=1700000000");
}

fs::path bake(const fs::path& d, int threads = 2, const std::string& lights = lights_json()) {
  write_meshes(d);
  std::ofstream(d / "scene.json") << scene_text(lights);
  const fs::path out = d / "out.prt.h5";
  const auto r = prtbake(d, "scene '" + (d / "scene.json").string() + "' -o '" + out.string() + "' --quiet --threads " +
                                std::to_string(threads));
  EXPECT_EQ(r.code, 0) << r.err;
  return out;
}

size_t vertex_at(const F::VertexSet& s, const Vector3d& p) {
  for (size_t v = 0; v < s.vertex_count(); ++v)
    if (Vector3d(s.positions->values[3 * v], s.positions->values[3 * v + 1], s.positions->values[3 * v + 2]) == p) return v;
  ADD_FAILURE() << "no vertex at " << p.transpose();
  return 0;
}

// KHR_lights_punctual's spot attenuation (its "Inner and Outer Cone Angles"), written here from
// the extension's text, independently of libbake's.
double spot_falloff(double cos_angle, double inner, double outer) {
  const double scale = 1 / std::max(0.001, std::cos(inner) - std::cos(outer)), offset = -std::cos(outer) * scale;
  const double a = std::clamp(cos_angle * scale + offset, 0.0, 1.0);
  return a * a;
}

// A point or spot light's E at ground vertex p (normal +y), unshadowed.
double point_e(const Vector3d& light, const Vector3d& p) {
  const Vector3d to = light - p;
  return std::max(to.y(), 0.0) / to.norm() / to.squaredNorm();
}
double spot_e(const Vector3d& p) {
  const Vector3d to = kSpot - p, l = to.normalized();
  return spot_falloff(kSpotAxis.dot(-l), kInner * std::numbers::pi / 180, kOuter * std::numbers::pi / 180) *
         point_e(kSpot, p);
}

} // namespace

TEST(ScenePunctualLights, IrradianceEqualsClosedFormsWithHardShadows) {
  const fs::path d = fresh_dir("closed");
  const F::Asset a = F::read_asset(bake(d));
  EXPECT_EQ(a.root.format_version, 6);
  const F::SceneObject* ground = a.find_object("ground");
  ASSERT_NE(ground, nullptr);
  ASSERT_TRUE(ground->set.area_irradiance.has_value());
  const F::Product& e = *ground->set.area_irradiance;
  EXPECT_EQ(e.lights.value_or(""), "key\nbulb\ncone\nsun");
  const size_t L = 4;
  const Vector3d sun_l = -kSun.normalized();
  // Lit by all three (the box does not stand between).
  for (const Vector3d& p : {Vector3d(3, 0, 3), Vector3d(-3, 0, 2), Vector3d(1, 0, 1), Vector3d(2, 0, 1)}) {
    const size_t v = vertex_at(ground->set, p);
    EXPECT_NEAR(e.values[v * L + 1], point_e(kPoint, p), kFloat * point_e(kPoint, p)) << p.transpose();
    EXPECT_NEAR(e.values[v * L + 2], spot_e(p), kFloat * std::max(spot_e(p), 1e-3)) << p.transpose();
    EXPECT_NEAR(e.values[v * L + 3], sun_l.y(), kFloat) << p.transpose();
  }
  // Under the box: the point light, the spot and the sun are hidden; the area light too (its
  // whole image lies in the box's).
  const size_t under = vertex_at(ground->set, Vector3d(0, 0, 0));
  for (size_t l = 0; l < L; ++l) EXPECT_EQ(e.values[under * L + l], 0.0f) << l;
  // The sun's shadow: the box's image along −sun_l falls on (x, z) = (x0 + t·0.5, z0 + t·0.25),
  // the ray from (1, 0, 0) along sun_l is at x = 1 − y/2 in [0.25, 0.5] for y in [1, 1.5]: in the box.
  const size_t shadowed = vertex_at(ground->set, Vector3d(1, 0, 0));
  EXPECT_EQ(e.values[shadowed * L + 3], 0.0f);
  EXPECT_NEAR(e.values[shadowed * L + 1], point_e(kPoint, Vector3d(1, 0, 0)), kFloat);  // the bulb still sees it
  // The stored lights: their shapes, intensities and geometry.
  ASSERT_EQ(a.lights.size(), 4u);
  const F::Light* cone = a.find_light("cone");
  ASSERT_NE(cone, nullptr);
  EXPECT_EQ(cone->shape, "spot");
  EXPECT_EQ(cone->radiance, (std::array<double, 3>{100, 100, 100}));
  EXPECT_EQ(*cone->position, (std::vector<double>{0, 4, 0}));
  EXPECT_EQ(*cone->direction, (std::vector<double>{0, -1, 0}));
  EXPECT_NEAR(*cone->inner_cone_angle, kInner * std::numbers::pi / 180, 1e-15);
  EXPECT_NEAR(*cone->outer_cone_angle, kOuter * std::numbers::pi / 180, 1e-15);
  EXPECT_TRUE(cone->vertices.values.empty());
  const F::Light* sun = a.find_light("sun");
  ASSERT_NE(sun, nullptr);
  EXPECT_FALSE(sun->position.has_value());
  EXPECT_NEAR((*sun->direction)[1], kSun.normalized().y(), 1e-15);
  const F::Light* bulb = a.find_light("bulb");
  ASSERT_NE(bulb, nullptr);
  EXPECT_EQ(bulb->radiance, (std::array<double, 3>{5, 4, 3}));
  EXPECT_FALSE(bulb->direction.has_value());
}

TEST(ScenePunctualLights, OneAndTwoThreadsAndShardsWriteTheSameBytes) {
  std::string bytes[2];
  for (int t = 1; t <= 2; ++t) bytes[t - 1] = prt::testing::read_bytes(bake(fresh_dir("threads"), t));
  EXPECT_FALSE(bytes[0].empty());
  EXPECT_TRUE(bytes[0] == bytes[1]) << "files differ between 1 and 2 threads";
  // Sharded: two workers and the merge, against one process (the same command line but the shard).
  const fs::path d = fresh_dir("shards");
  write_meshes(d);
  std::ofstream(d / "scene.json") << scene_text(lights_json());
  const fs::path out = d / "out.prt.h5";
  const std::string base = "scene '" + (d / "scene.json").string() + "' --reproducible -q --threads 1 --chunk-rows 16 -o '" + out.string() + "'";
  ASSERT_EQ(prtbake(d, base).code, 0);
  const std::string one = prt::testing::read_bytes(out);
  fs::remove(out);
  for (int i = 0; i < 2; ++i) {
    const auto w = prtbake(d, base + " --shard " + std::to_string(i) + "/2");
    ASSERT_EQ(w.code, 0) << w.err;
  }
  const auto m = prtbake(d, base + " --merge");
  ASSERT_EQ(m.code, 0) << m.err;
  EXPECT_TRUE(prt::testing::read_bytes(out) == one) << "--shard I/2 + --merge differs from one process";
}

TEST(ScenePunctualLights, PrtdumpShowsThem) {
  const fs::path d = fresh_dir("dump");
  const fs::path out = bake(d);
  const auto r = prt::testing::run_tool(PRT_PRTDUMP, "'" + out.string() + "'", d / "capture");
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* s : {"Lights (world space", "bulb  point, intensity [5, 4, 3], position [0.25, 3, 0.125], hard shadows",
                        "cone  spot, intensity [100, 100, 100], position [0, 4, 0], direction [0, -1, 0], cone 20 to 40 degrees",
                        "sun   directional, intensity [2, 2, 2], direction [", "key   quad, 1 face(s)", "schema   valid"})
    EXPECT_NE(r.out.find(s), std::string::npos) << "prtdump lacks '" << s << "':\n" << r.out;
}

TEST(ScenePunctualLights, BadLightsAreRefusedNamingTheFileAndTheLight) {
  const fs::path d = fresh_dir("bad");
  write_meshes(d);
  struct Case {
    std::string light, message;
  };
  const Case cases[] = {
      {R"({"name": "neg", "shape": "point", "position": [0, 1, 0], "intensity": [1, -2, 1]})",
       "lights[0] (light \"neg\"): intensity[1] must be >= 0"},
      {R"({"name": "cones", "shape": "spot", "position": [0, 1, 0], "direction": [0, -1, 0], "inner_cone_angle": 30, "outer_cone_angle": 10, "intensity": [1, 1, 1]})",
       "lights[0] (light \"cones\"): inner cone angle (0.523599) must be smaller than the outer cone angle (0.174533)"},
      {R"({"name": "wide", "shape": "spot", "position": [0, 1, 0], "direction": [0, -1, 0], "outer_cone_angle": 100, "intensity": [1, 1, 1]})",
       "lights[0] (light \"wide\"): outer_cone_angle must be in [0, 90] degrees, got 100"},
      {R"({"name": "nowhere", "shape": "directional", "direction": [0, 0, 0], "intensity": [1, 1, 1]})",
       "lights[0] (light \"nowhere\"): direction must not be zero"},
      {R"({"name": "typo", "shape": "point", "positon": [0, 1, 0], "intensity": [1, 1, 1]})",
       "unknown key \"positon\" in lights[0] (light \"typo\")"},
      {R"({"name": "near", "shape": "point", "position": [0, 1, 0], "range": 0, "intensity": [1, 1, 1]})",
       "lights[0].range must be > 0"},
      {R"({"name": "bulb", "shape": "point", "position": [0, 1, 0], "radius": 0.1, "range": 5, "intensity": [1, 1, 1]})",
       "lights[0] (light \"bulb\"): \"range\" is for a point light; with \"radius\" it is a sphere light, which has none"},
      {R"({"name": "sunset", "shape": "directional", "direction": [0, -1, 0], "range": 5, "intensity": [1, 1, 1]})",
       "unknown key \"range\" in lights[0] (light \"sunset\")"},
  };
  for (const Case& c : cases) {
    std::ofstream(d / "scene.json") << scene_text("\"lights\": [" + c.light + "]");
    const auto r = prtbake(d, "scene '" + (d / "scene.json").string() + "' -o '" + (d / "x.prt.h5").string() + "' -q");
    EXPECT_NE(r.code, 0) << c.light;
    EXPECT_NE(r.err.find((d / "scene.json").string()), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(d / "x.prt.h5"));
  }
}

namespace {

// A glTF: the ground grid (y = 0, facing +y, [-3, 3]²) and three lights on nodes: a point light
// translated to (0.5, 2, 0), a spot rotated to point down (−Z turned to −Y: a quarter turn about
// X) at (0, 3, 0), and a directional light rotated the same way.
fs::path write_gltf(const fs::path& d, double inner = 0.2, double outer = 0.6) {
  prt::testing::Gltf g;
  g.dir = d;
  std::vector<Eigen::Vector3f> points;
  std::vector<uint16_t> tris;
  for (int j = 0; j < 7; ++j)
    for (int i = 0; i < 7; ++i) points.emplace_back(float(i - 3), 0.0f, float(j - 3));
  for (uint16_t j = 0; j < 6; ++j)
    for (uint16_t i = 0; i < 6; ++i) {
      const uint16_t a = uint16_t(j * 7 + i), b = uint16_t(a + 1), c = uint16_t(a + 8), e = uint16_t(a + 7);
      tris.insert(tris.end(), {a, e, c, a, c, b});
    }
  const int pos = g.vec3(points), idx = g.indices(tris);
  const int mesh = g.mesh({{"attributes", {{"POSITION", pos}}}, {"indices", idx}, {"mode", 4}});
  g.node({{"name", "ground"}, {"mesh", mesh}}, true);
  const double s = std::sqrt(0.5);  // the quaternion of a -90° turn about X: -Z → -Y
  g.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  g.doc["extensions"] = {{"KHR_lights_punctual",
                          {{"lights",
                            {{{"name", "lamp"}, {"type", "point"}, {"color", {1, 0.5, 0.25}}, {"intensity", 8}, {"range", 3}},
                             {{"name", "cone"}, {"type", "spot"}, {"intensity", 50}, {"spot", {{"innerConeAngle", inner}, {"outerConeAngle", outer}}}},
                             {{"name", "sun"}, {"type", "directional"}, {"intensity", 3}}}}}}};
  g.node({{"name", "lamp_node"}, {"translation", {0.5, 2, 0}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}}, true);
  g.node({{"name", "spot_node"}, {"translation", {0, 3, 0}}, {"rotation", {-s, 0, 0, s}},
          {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}}, true);
  g.node({{"name", "sun_node"}, {"rotation", {-s, 0, 0, s}}, {"extensions", {{"KHR_lights_punctual", {{"light", 2}}}}}}, true);
  return g.write("lit.gltf");
}

} // namespace

TEST(ScenePunctualLights, KhrLightsPunctualFromAGltfWithNodeTransforms) {
  const fs::path d = fresh_dir("gltf");
  const fs::path gltf = write_gltf(d), out = d / "out.prt.h5";
  const auto r = prtbake(d, "scene '" + gltf.string() + "' -o '" + out.string() + "' -q --threads 2");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.find("not baked"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("range"), std::string::npos) << "the lamp's range is applied, nothing to warn of\n" << r.err;
  const F::Asset a = F::read_asset(out);
  ASSERT_EQ(a.lights.size(), 3u);
  const F::Light* lamp = a.find_light("lamp");
  ASSERT_NE(lamp, nullptr);
  EXPECT_EQ(lamp->shape, "point");
  EXPECT_EQ(lamp->radiance, (std::array<double, 3>{8, 4, 2}));
  EXPECT_EQ(*lamp->position, (std::vector<double>{0.5, 2, 0}));
  EXPECT_EQ(lamp->range, 3.0);
  const F::Light* cone = a.find_light("cone");
  ASSERT_NE(cone, nullptr);
  EXPECT_NEAR((*cone->direction)[1], -1, 1e-15);
  EXPECT_NEAR(*cone->outer_cone_angle, 0.6, 1e-15);
  const F::Light* sun = a.find_light("sun");
  ASSERT_NE(sun, nullptr);
  EXPECT_NEAR((*sun->direction)[1], -1, 1e-15);
  ASSERT_EQ(a.objects.size(), 1u);
  const F::VertexSet& set = a.objects[0].set;
  ASSERT_TRUE(set.area_irradiance.has_value());
  EXPECT_EQ(set.area_irradiance->lights.value_or(""), "lamp\ncone\nsun");
  EXPECT_NE(set.area_irradiance->integrand.value_or("").find("the last 3 columns (punctual lights"), std::string::npos)
      << set.area_irradiance->integrand.value_or("");
  EXPECT_EQ(set.area_irradiance->integrator.value_or(""), "punctual lights: one exact shadow ray each");
  for (const Vector3d& p : {Vector3d(0, 0, 0), Vector3d(1, 0, -2), Vector3d(-3, 0, 3)}) {
    const size_t v = vertex_at(set, p);
    // The lamp's range of 3 (KHR's window clamp(1 - (d/3)^4, 0, 1)): 0.78 at the origin (d = 2.06),
    // 0.16 at (1, 0, -2) (d = 2.87), 0 at (-3, 0, 3) (d = 5.02, beyond the range).
    const double window = prt::bake::range_window((Vector3d(0.5, 2, 0) - p).norm(), 3);
    EXPECT_NEAR(set.area_irradiance->values[v * 3 + 0], window * point_e(Vector3d(0.5, 2, 0), p), kFloat) << p.transpose();
    const Vector3d l = (Vector3d(0, 3, 0) - p).normalized();
    const double spot = spot_falloff(l.y(), 0.2, 0.6) * point_e(Vector3d(0, 3, 0), p);
    EXPECT_NEAR(set.area_irradiance->values[v * 3 + 1], spot, kFloat) << p.transpose();
    EXPECT_NEAR(set.area_irradiance->values[v * 3 + 2], 1.0, kFloat) << p.transpose();
  }
}

TEST(ScenePunctualLights, GltfOptionsGiveABulbARadiusAndTheSunAnAngle) {
  const fs::path d = fresh_dir("gltf_extent");
  const fs::path gltf = write_gltf(d), out = d / "out.prt.h5";
  std::ofstream(d / "options.json") << R"({"prtbake_gltf_scene": 1, "gltf_lights": {"lamp": {"radius": 0.05}, "sun": {"angle": 0.53}}})";
  const auto r = prtbake(d, "scene '" + gltf.string() + "' --options '" + (d / "options.json").string() + "' -o '" + out.string() + "' -q");
  ASSERT_EQ(r.code, 0) << r.err;
  // The glTF lamp's range cannot window a sphere light: said, not dropped silently.
  EXPECT_NE(r.err.find("\"lamp\" (node lamp_node): its range 3.000000 is not applied: with a radius"), std::string::npos) << r.err;
  const F::Asset a = F::read_asset(out);
  ASSERT_EQ(a.lights.size(), 3u);
  EXPECT_EQ(a.find_light("lamp")->shape, "sphere");
  EXPECT_EQ(a.find_light("sun")->shape, "disc");
  EXPECT_EQ(a.find_light("cone")->shape, "spot");
  const F::VertexSet& set = a.objects[0].set;
  EXPECT_EQ(set.area_irradiance->lights.value_or(""), "lamp\nsun\ncone");  // area lights first
  // The product says which columns are punctual and what their integrand is.
  EXPECT_NE(set.area_irradiance->integrand.value_or("").find("the last column (punctual lights"), std::string::npos)
      << set.area_irradiance->integrand.value_or("");
  EXPECT_EQ(set.area_irradiance->integrator.value_or(""), "area lights: exact visible polygons (paper 003); punctual lights: one exact shadow ray each");
  // Far from the bulb and facing the sun, the extended lights give their punctual limits: the
  // icosphere's area deficit (0.5%) and the sun's disc (its cosine's spread over 0.27°).
  const F::Light& lamp = *a.find_light("lamp");
  const F::Light& sun = *a.find_light("sun");
  const size_t v = vertex_at(set, Vector3d(-3, 0, 3));
  const double e_lamp = set.area_irradiance->values[v * 3 + 0] * lamp.radiance[0];
  EXPECT_NEAR(e_lamp, 8 * point_e(Vector3d(0.5, 2, 0), Vector3d(-3, 0, 3)), 8 * point_e(Vector3d(0.5, 2, 0), Vector3d(-3, 0, 3)) * 6e-3);
  EXPECT_NEAR(set.area_irradiance->values[v * 3 + 1] * sun.radiance[0], 3, 3 * 1e-4);
  // A key that names no light, or an extent on the wrong kind, is refused naming the options file.
  std::ofstream(d / "bad.json") << R"({"prtbake_gltf_scene": 1, "gltf_lights": {"lam": {"radius": 0.05}}})";
  const auto bad = prtbake(d, "scene '" + gltf.string() + "' --options '" + (d / "bad.json").string() + "' -o '" + out.string() + "' -q");
  EXPECT_NE(bad.code, 0);
  EXPECT_NE(bad.err.find("bad.json: gltf_lights: \"lam\" names no KHR_lights_punctual light"), std::string::npos) << bad.err;
  std::ofstream(d / "bad2.json") << R"({"prtbake_gltf_scene": 1, "gltf_lights": {"cone": {"angle": 1}}})";
  const auto bad2 = prtbake(d, "scene '" + gltf.string() + "' --options '" + (d / "bad2.json").string() + "' -o '" + out.string() + "' -q");
  EXPECT_NE(bad2.code, 0);
  EXPECT_NE(bad2.err.find("\"angle\" is for a directional light (this is a spot light)"), std::string::npos) << bad2.err;
}

TEST(ScenePunctualLights, AGltfSpotWithItsConesCrossedIsRefusedNamingTheLight) {
  const fs::path d = fresh_dir("gltf_bad");
  const fs::path gltf = write_gltf(d, 0.7, 0.3);
  const auto r = prtbake(d, "scene '" + gltf.string() + "' -o '" + (d / "out.prt.h5").string() + "' -q");
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find(gltf.string() + ": KHR_lights_punctual light 1 \"cone\" (node spot_node): inner cone angle (0.7) must be smaller"),
            std::string::npos)
      << r.err;
}

namespace {

// The exposure prtview prints for --shade area: "(1 / X, the 99th percentile of the baked area
// lighting E/pi ...)"; X, or -1 when the line is missing.
double baked_percentile(const std::string& out) {
  const std::string key = "(1 / ";
  const size_t at = out.find(key);
  if (at == std::string::npos || out.find("the 99th percentile of the baked area lighting", at) == std::string::npos) return -1;
  return std::stod(out.substr(at + key.size()));
}

} // namespace

TEST(ScenePunctualLights, PrtviewShadesThemFromTheBakedIrradianceTimesTheirIntensity) {
  // Only a spot and a sun: prtview draws the baked E times each light's stored intensity, so
  // doubling both intensities doubles what it draws (its exposure's percentile, printed).
  double percentile[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    const fs::path d = fresh_dir("prtview" + std::to_string(k));
    const std::string s = std::to_string(k + 1);
    const fs::path out = bake(d, 2,
                              R"("lights": [{"name": "cone", "shape": "spot", "position": [0, 4, 0], "direction": [0, -1, 0], "outer_cone_angle": 60, "intensity": [)" +
                                  s + ", " + s + ", " + s + R"(]}, {"name": "sun", "shape": "directional", "direction": [0.5, -1, 0.25], "intensity": [)" + s +
                                  ", " + s + ", " + s + "]}]");
    const auto r = prt::testing::run_tool(PRT_PRTVIEW, "'" + out.string() + "' --shade area -o '" + (d / "v.png").string() + "'", d / "capture");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(fs::exists(d / "v.png"));
    percentile[k] = baked_percentile(r.out + r.err);
    ASSERT_GT(percentile[k], 0) << r.out << r.err;
    // Per pixel, exactly (one shadow ray per pixel and light), and against its reference, whose
    // punctual part is the same exact term: the triptych's error is 0 to float rounding.
    const auto exact = prt::testing::run_tool(PRT_PRTVIEW, "'" + out.string() + "' --shade area-exact -o '" + (d / "x.png").string() + "'", d / "capture");
    EXPECT_EQ(exact.code, 0) << exact.err;
    EXPECT_TRUE(fs::exists(d / "x.png"));
  }
  EXPECT_NEAR(percentile[1] / percentile[0], 2.0, 2e-3) << "prtview prints the percentile to 4 digits";
}

namespace {

// Whether the segment p → q meets the box [-1/2, 1/2] × [1/2, 3/2] × [-1/2, 1/2], with a margin: a
// texel within `margin` of deciding either way is left out of the comparison.
bool near_or_through_box(const Vector3d& p, const Vector3d& q, double margin) {
  return prt::testing::segment_meets_box(p, q, prt::testing::kGroundBoxLo, prt::testing::kGroundBoxHi, margin);
}

} // namespace

TEST(ScenePunctualLights, PerTexelTheyAreTheClosedFormsToo) {
  // The ground baked per texel of a 24 × 24 lightmap: every texel baked at its own sample (state 1)
  // gets the point light's E = cos/d², or 0 when the box stands between (texels near the shadow's
  // edge, where a texel's sample and the closed form's rounding may disagree, are left out).
  const fs::path d = fresh_dir("texels");
  write_meshes(d);
  std::string scene = scene_text(lights_json());
  const std::string ground = R"("material": {"albedo": [0.5, 0.5, 0.5]}})";
  scene.replace(scene.find(ground), ground.size(), R"("material": {"albedo": [0.5, 0.5, 0.5]}, "lightmap": {"resolution": 24}})");
  std::ofstream(d / "scene.json") << scene;
  const fs::path out = d / "out.prt.h5";
  const auto r = prtbake(d, "scene '" + (d / "scene.json").string() + "' -o '" + out.string() + "' -q");
  ASSERT_EQ(r.code, 0) << r.err;
  const F::Asset a = F::read_asset(out);
  const F::SceneObject* g = a.find_object("ground");
  ASSERT_NE(g, nullptr);
  ASSERT_TRUE(g->set.lightmap.has_value());
  const F::Lightmap& m = *g->set.lightmap;
  ASSERT_TRUE(m.area_irradiance.has_value() && m.positions.has_value());
  EXPECT_EQ(m.area_irradiance->lights.value_or(""), "key\nbulb\ncone\nsun");
  size_t lit = 0, shadowed = 0;
  for (size_t t = 0; t < m.texel_count(); ++t) {
    if (m.state.values[t] != 1) continue;
    const Vector3d p(m.positions->values[3 * t], m.positions->values[3 * t + 1], m.positions->values[3 * t + 2]);
    const float e = m.area_irradiance->values[4 * t + 1];
    if (near_or_through_box(p, kPoint, 0.02)) {
      if (!near_or_through_box(p, kPoint, -0.02)) continue;
      EXPECT_EQ(e, 0.0f) << p.transpose();
      ++shadowed;
    } else {
      EXPECT_NEAR(e, point_e(kPoint, p), kFloat * point_e(kPoint, p) + 1e-7) << p.transpose();
      ++lit;
    }
  }
  EXPECT_GT(lit, 100u);
  EXPECT_GT(shadowed, 3u);
}

// `prtbake scene --help` names the punctual kinds and their keys (the parser's list in
// libbake/bake/src/scene_file.cpp), and how a glTF's lights get an extent.
TEST(ScenePunctualLights, SceneHelpNamesThePunctualKindsAndTheirKeys) {
  const fs::path d = fresh_dir("help");
  const auto r = prtbake(d, "scene --help");
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* s : {"{\"shape\": \"point\", \"position\"}", "\"radius\"", "\"subdivisions\": 3",
                        "{\"shape\": \"spot\", \"position\", \"direction\", \"inner_cone_angle\": 0, \"outer_cone_angle\": 45}",
                        "{\"shape\": \"directional\", \"direction\"}", "\"angle\"", "\"segments\": 64",
                        "\"intensity\": [r,g,b] (required, >= 0: candela, or lux for directional)", "\"gltf_lights\"",
                        "KHR_lights_punctual"})
    EXPECT_NE(r.out.find(s), std::string::npos) << s << "\n" << r.out;
}
