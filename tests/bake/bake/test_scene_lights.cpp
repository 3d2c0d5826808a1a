// Area lights in scene files (bake/bake/scene.h "lights", bake/lights/lights.h shapes): every shape parses into
// its faces with its radiance, and every mistake is refused naming the file and the key.
#include <bake/bake/scene.h>
#include <bake/core/error.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace {

using namespace prt::bake;
namespace fs = std::filesystem;

fs::path write_scene(const std::string& name, const std::string& lights) {
  const fs::path dir = fs::path(PRT_TEST_TMP) / "scene_lights";
  fs::create_directories(dir);
  const fs::path p = dir / name;
  std::ofstream(p) << R"({"prtbake_scene": 1, "lights": )" << lights << R"(, "objects": [{"role": "both", "mesh": ")"
                   << (fs::path(PRT_DATA_DIR) / "bunny.obj").string() << R"("}]})";
  return p;
}

std::string refusal(const std::string& lights) {
  const fs::path p = write_scene("bad.json", lights);
  try {
    load_scene(p);
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), p.string());
    return e.defect();
  }
  return "";
}

TEST(SceneLights, EveryShapeParsesWithItsRadianceAndName) {
  const SceneDescription s = load_scene(write_scene("ok.json", R"([
    {"name": "key", "shape": "quad", "centre": [0, 4, 0], "u": [1, 0, 0], "v": [0, 0, 1], "radiance": [10, 9, 8]},
    {"shape": "polygon", "vertices": [[0, 5, 0], [1, 5, 0], [0, 5, 1]], "radiance": [1, 1, 1], "two_sided": true},
    {"shape": "disc", "centre": [2, 3, 0], "normal": [0, -1, 0], "radius": 0.5, "segments": 12, "radiance": [3, 3, 3]},
    {"shape": "box", "centre": [-3, 2, 0], "size": [1, 2, 0.5], "rotate": [0, 45, 0], "radiance": [0, 1, 0]},
    {"shape": "cylinder", "centre": [0, 2, 3], "radius": 0.2, "height": 1, "segments": 16, "radiance": [2, 2, 2]},
    {"shape": "sphere", "centre": [0, 6, -3], "radius": 0.3, "subdivisions": 2, "radiance": [5, 5, 5]}])"));
  ASSERT_EQ(s.lights.size(), 6u);
  EXPECT_EQ(s.lights[0].name, "key");
  EXPECT_EQ(s.lights[1].name, "light1");  // the default: its index
  EXPECT_EQ(s.lights[0].radiance, (std::array<double, 3>{10, 9, 8}));
  EXPECT_NEAR(s.lights[0].face_normal(0).dot(Eigen::Vector3d(0, -1, 0)), 1.0, 1e-15);  // u × v: facing down
  EXPECT_TRUE(s.lights[1].two_sided);
  EXPECT_EQ(s.lights[2].faces[0].size(), 12u);
  EXPECT_EQ(s.lights[3].faces.size(), 6u);
  EXPECT_NEAR(s.lights[3].area(), 2 * (1 * 2 + 2 * 0.5 + 0.5 * 1), 1e-12);  // a rotation keeps the area
  EXPECT_EQ(s.lights[4].faces.size(), 18u);
  EXPECT_EQ(s.lights[5].faces.size(), 320u);
  const LightShape kinds[] = {LightShape::Quad, LightShape::Polygon, LightShape::Disc,
                              LightShape::Box,  LightShape::Cylinder, LightShape::Sphere};
  for (size_t i = 0; i < 6; ++i) EXPECT_EQ(s.lights[i].shape, kinds[i]) << i;
}

TEST(SceneLights, MistakesAreRefusedNamingTheKey) {
  const std::pair<std::string, std::string> cases[] = {
      {R"({"shape": "quad"})", "lights must be an array"},
      {R"([{"shape": "tube", "radiance": [1, 1, 1]}])", "lights[0].shape must be quad, polygon, disc, box, cylinder, sphere, point, spot or directional, not \"tube\""},
      {R"([{"radiance": [1, 1, 1]}])", "lights[0] lacks \"shape\""},
      {R"([{"shape": "quad", "centre": [0, 1, 0], "u": [1, 0, 0], "v": [0, 0, 1]}])", "lights[0] (quad) lacks \"radiance\""},
      {R"([{"shape": "quad", "centre": [0, 1, 0], "u": [1, 0, 0], "v": [0, 0, 1], "radiance": [1, -1, 1]}])",
       "lights[0].radiance[1] must be in [0, 1e+30], got -1"},
      {R"([{"shape": "quad", "centre": [0, 1, 0], "u": [1, 0, 0], "v": [0, 0, 1], "radius": 2, "radiance": [1, 1, 1]}])",
       "unknown key \"radius\" in lights[0] (a quad light takes name, shape, radiance, two_sided, centre, u, v)"},
      {R"([{"shape": "quad", "centre": [0, 1, 0], "u": [1, 0, 0], "v": [2, 0, 0], "radiance": [1, 1, 1]}])",
       "lights[0]: degenerate (no area)"},
      {R"([{"shape": "polygon", "vertices": [[0, 0, 0], [2, 1, 0], [0, 2, 0], [0.5, 1, 0]], "radiance": [1, 1, 1]}])",
       "lights[0]: not convex"},
      {R"([{"shape": "polygon", "vertices": [[0, 0, 0], [1, 0, 0], [1, 1, 0.1], [0, 1, 0]], "radiance": [1, 1, 1]}])",
       "lights[0]: not planar"},
      {R"([{"shape": "box", "centre": [0, 1, 0], "size": [1, 0, 1], "radiance": [1, 1, 1]}])", "lights[0].size must be > 0"},
      {R"([{"shape": "box", "centre": [0, 1, 0], "size": [1, 1, 1], "radiance": [1, 1, 1], "two_sided": true}])",
       "two_sided is for planar lights"},
      {R"([{"shape": "sphere", "centre": [0, 1, 0], "radius": 1, "subdivisions": 5, "radiance": [1, 1, 1]}])",
       "lights[0].subdivisions must be in [0, 4]"},
      {R"([{"shape": "disc", "centre": [0, 1, 0], "normal": [0, 0, 0], "radius": 1, "radiance": [1, 1, 1]}])",
       "lights[0].normal must not be zero"},
      {R"([{"name": "a", "shape": "sphere", "centre": [0, 1, 0], "radius": 1, "radiance": [1, 1, 1]},
           {"name": "a", "shape": "sphere", "centre": [0, 3, 0], "radius": 1, "radiance": [1, 1, 1]}])",
       "lights[1]: the name \"a\" is already used by another light"},
  };
  for (const auto& [lights, message] : cases) {
    const std::string got = refusal(lights);
    EXPECT_NE(got.find(message), std::string::npos) << "expected '" << message << "' in: " << got;
  }
}

} // namespace
