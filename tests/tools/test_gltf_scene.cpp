// `prtbake scene` on a glTF (bake/bake/scene.h "glTF scenes"): every primitive instance is an object
// named by its node path, baked exactly as the same geometry in a JSON scene; the options file sets
// roles and materials per node path and refuses a path that names no node; prtdump lists the
// objects by node path and dumps one object's vertex by it; unnamed nodes take their mesh's name.
#include <bake/bake/scene.h>
#include <bake/core/sha256.h>
#include <formats/asset.h>

#include <gltf_builder.h>
#include <run_tool.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
namespace F = prt::formats;
using prt::testing::Gltf;
using prt::testing::json;

namespace {

// An empty scratch directory for one test.
fs::path dir_for(const std::string& name) {
  fs::remove_all(fs::path(PRT_TEST_TMP) / "gltf_scene" / name);
  return prt::testing::test_dir("gltf_scene/" + name);
}

void write_text(const fs::path& p, const std::string& s) { prt::testing::write_test_file(p.parent_path(), p.filename().string(), s); }

using Points = std::vector<Eigen::Vector3f>;
using Triangles = std::vector<uint16_t>;  // 3 per triangle

// The geometry, in object space. A ground grid 9×9 over [-4, 4]² at y = 0 facing +Y; a closed
// box [-1, 1] × [0, 2] × [-1, 1] split into two primitives of three quads each; a small quad.
struct Part {
  Points points;
  Triangles triangles;
};
Part ground() {
  Part g;
  for (int j = 0; j < 9; ++j)
    for (int i = 0; i < 9; ++i) g.points.emplace_back(float(i - 4), 0.0f, float(j - 4));
  for (uint16_t j = 0; j < 8; ++j)
    for (uint16_t i = 0; i < 8; ++i) {
      const uint16_t a = uint16_t(j * 9 + i), b = uint16_t(a + 1), c = uint16_t(a + 10), e = uint16_t(a + 9);
      g.triangles.insert(g.triangles.end(), {a, e, c, a, c, b});
    }
  return g;
}
const Points kBoxPoints = {{-1, 0, -1}, {1, 0, -1}, {-1, 2, -1}, {1, 2, -1}, {-1, 0, 1}, {1, 0, 1}, {-1, 2, 1}, {1, 2, 1}};
// Outward quads (0-based corners), three per primitive, each as two triangles.
const Part kBoxLow = {kBoxPoints, {0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4}};
const Part kBoxHigh = {kBoxPoints, {2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5}};
const Part kQuad = {{{0, 0, 0}, {0.5f, 0, 0}, {0.5f, 0, 0.5f}, {0, 0, 0.5f}}, {0, 2, 1, 0, 3, 2}};

json primitive(Gltf& g, const Part& p) {
  return {{"attributes", {{"POSITION", g.vec3(p.points)}}},
          {"indices", g.indices(p.triangles)}};
}

// Scene root "ground" (mesh: the ground); root "stack" (translation y = 1, no mesh) with children
// "box" (translation y = 1, the two-primitive box, primitive 1 with a material) and an unnamed
// node (translation (2, 0, 2), the quad). Instances in walk order: ground, stack/box,
// stack/box#p1, stack/node2.
fs::path write_gltf(const fs::path& d) {
  Gltf g;
  g.dir = d;
  g.doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorFactor", {0.25, 0.5, 1.0, 1.0}}}}}};
  const int ground_mesh = g.mesh(primitive(g, ground()));
  json high = primitive(g, kBoxHigh);
  high["material"] = 0;
  g.doc["meshes"].push_back({{"primitives", {primitive(g, kBoxLow), high}}});
  const int box_mesh = static_cast<int>(g.doc["meshes"].size() - 1);
  const int quad_mesh = g.mesh(primitive(g, kQuad));
  g.node({{"name", "ground"}, {"mesh", ground_mesh}}, true);
  const int box = g.node({{"name", "box"}, {"mesh", box_mesh}, {"translation", {0.0, 1.0, 0.0}}}, false);
  const int quad = g.node({{"mesh", quad_mesh}, {"translation", {2.0, 0.0, 2.0}}}, false);
  g.node({{"name", "stack"}, {"translation", {0.0, 1.0, 0.0}}, {"children", {box, quad}}}, true);
  EXPECT_EQ(quad, 2) << "the unnamed node's index is in its name";
  return g.write("stack.gltf");
}

void write_obj(const fs::path& p, const Part& part) {
  std::string s;
  for (const auto& v : part.points) s += "v " + std::to_string(v.x()) + " " + std::to_string(v.y()) + " " + std::to_string(v.z()) + "\n";
  for (size_t t = 0; t < part.triangles.size(); t += 3)
    s += "f " + std::to_string(part.triangles[t] + 1) + " " + std::to_string(part.triangles[t + 1] + 1) + " " +
         std::to_string(part.triangles[t + 2] + 1) + "\n";
  write_text(p, s);
}

const std::string kBake = R"("bake": {"products": ["ao"], "samples": 1024, "report": 0})";
const std::vector<std::string> kNodePaths = {"ground", "stack/box", "stack/box#p1", "stack/node2"};
const std::vector<std::string> kObjectNames = {"ground", "stack|box", "stack|box#p1", "stack|node2"};

prt::testing::ToolRun bake(const fs::path& d, const std::string& args, const std::string& out = "out.prt.h5") {
  return prt::testing::run_tool(PRT_PRTBAKE, "scene " + args + " -o '" + (d / out).string() + "'", d);
}

// `options` written beside the glTF and baked with it.
F::Asset bake_with_options(const fs::path& d, const std::string& options) {
  write_text(d / "stack.options.json", options);
  const auto run = bake(d, "'" + write_gltf(d).string() + "' --options '" + (d / "stack.options.json").string() + "'");
  EXPECT_EQ(run.code, 0) << run.err;
  return run.code == 0 ? F::read_asset(d / "out.prt.h5") : F::Asset{};
}

const std::vector<float>& ao_of(const F::Asset& a, const std::string& object) {
  static const std::vector<float> kNone;
  const F::SceneObject* o = a.find_object(object);
  return o && o->set.ao ? o->set.ao->values : kNone;
}

} // namespace

TEST(GltfScene, InstancesAreObjectsNamedByNodePathAndBakeAsTheSameJsonScene) {
  const fs::path d = dir_for("equivalent");
  const F::Asset gltf = bake_with_options(d, "{\"prtbake_gltf_scene\": 1, " + kBake + "}");
  ASSERT_EQ(gltf.objects.size(), 4u);
  // The options file is an input like the glTF: named and hashed in /scene.
  ASSERT_TRUE(gltf.scene);
  EXPECT_EQ(gltf.scene->options_file, (d / "stack.options.json").string());
  EXPECT_EQ(gltf.scene->options_sha256, prt::bake::sha256_file(d / "stack.options.json"));

  // The same geometry as a JSON scene: the parts as OBJ files, the composed node translations as
  // object transforms. Every coordinate is a small binary fraction, so the world positions are the
  // same floats either way and the AO must be the same bytes.
  write_obj(d / "ground.obj", ground());
  write_obj(d / "box_low.obj", kBoxLow);
  write_obj(d / "box_high.obj", kBoxHigh);
  write_obj(d / "quad.obj", kQuad);
  write_text(d / "scene.json", "{\"prtbake_scene\": 1, " + kBake + R"(, "objects": [
    {"name": "ground", "mesh": "ground.obj", "role": "both"},
    {"name": "box", "mesh": "box_low.obj", "role": "both", "transform": {"translate": [0, 2, 0]}},
    {"name": "box_p1", "mesh": "box_high.obj", "role": "both", "transform": {"translate": [0, 2, 0]}},
    {"name": "quad", "mesh": "quad.obj", "role": "both", "transform": {"translate": [2, 1, 2]}}]})");
  const auto run = bake(d, "'" + (d / "scene.json").string() + "'", "json.prt.h5");
  ASSERT_EQ(run.code, 0) << run.err;
  const F::Asset json_scene = F::read_asset(d / "json.prt.h5");
  const std::vector<std::string> json_names = {"ground", "box", "box_p1", "quad"};
  const std::vector<size_t> rows = {81, 8, 8, 4};

  for (size_t i = 0; i < kObjectNames.size(); ++i) {
    SCOPED_TRACE(kNodePaths[i]);
    const F::SceneObject* o = gltf.find_object(kObjectNames[i]);
    ASSERT_NE(o, nullptr) << "object /objects/" << kObjectNames[i];
    EXPECT_EQ(o->node_path, kNodePaths[i]);
    EXPECT_EQ(o->role, "both") << "the default role";
    ASSERT_TRUE(o->set.ao);
    EXPECT_EQ(o->set.ao->values.size(), rows[i]) << "one row per vertex of the primitive";
    const std::vector<float>& want = ao_of(json_scene, json_names[i]);
    ASSERT_EQ(want.size(), rows[i]);
    EXPECT_EQ(o->set.ao->values, want) << "the same geometry in a JSON scene bakes to the same AO";
    EXPECT_FALSE(o->set.transfer_diffuse) << "the options' bake.products hold only ao";
    EXPECT_EQ(o->set.positions->values, json_scene.find_object(json_names[i])->set.positions->values) << "the same world positions";
  }
  // Materials: baseColorFactor as albedo; 0.8 grey without a material.
  EXPECT_EQ(gltf.find_object("stack|box#p1")->albedo, (std::vector<double>{0.25, 0.5, 1.0}));
  EXPECT_EQ(gltf.find_object("stack|box")->albedo, (std::vector<double>{0.8, 0.8, 0.8}));
  // The ground under the box is shadowed by it: the objects see each other.
  EXPECT_LT(ao_of(gltf, "ground")[4 * 9 + 4], 0.9f);

  // prtdump lists the objects by node path, saying where the file stores them when that differs.
  const auto listing = prt::testing::run_tool(PRT_PRTDUMP, "'" + (d / "out.prt.h5").string() + "'", d);
  ASSERT_EQ(listing.code, 0) << listing.err;
  for (size_t i = 0; i < kNodePaths.size(); ++i)
    EXPECT_NE(listing.out.find("  " + kNodePaths[i] + " (both" +
                               (kNodePaths[i] == kObjectNames[i] ? "" : "; stored as /objects/" + kObjectNames[i]) + ")\n"),
              std::string::npos)
        << listing.out;
  // One spelling in every section: the stored name ('|') only where it is labelled as such.
  std::istringstream lines(listing.out);
  size_t stored_lines = 0;
  for (std::string line; std::getline(lines, line);)
    if (line.find('|') != std::string::npos) {
      EXPECT_NE(line.find("stored as /objects/"), std::string::npos) << "a name spelled with '|': " << line;
      ++stored_lines;
    }
  EXPECT_GE(stored_lines, 3u) << "the three objects under 'stack' say where they are stored:\n" << listing.out;
}

TEST(GltfScene, PrtdumpPrintsOneObjectsVertexByNodePathOrStoredName) {
  // Issue 29: `--vertex I` on a scene file needs `--object NAME`, the node path the Scene section
  // prints (or the stored name); the values printed are the file's for that object's vertex I.
  const fs::path d = dir_for("dump_object");
  const F::Asset a = bake_with_options(d, "{\"prtbake_gltf_scene\": 1, " + kBake + "}");
  const F::SceneObject* box = a.find_object("stack|box");
  ASSERT_NE(box, nullptr);
  ASSERT_TRUE(box->set.ao && box->set.positions);
  ASSERT_GT(box->set.ao->values.size(), 5u);
  auto shortest = [](float v) {  // prtdump prints float32 values in their shortest round-trip form
    char buf[32];
    return std::string(buf, std::to_chars(buf, buf + sizeof buf, v).ptr);
  };
  const std::string ao = shortest(box->set.ao->values[5]);
  const std::string position = "[" + shortest(float(box->set.positions->values[15])) + ", " +
                               shortest(float(box->set.positions->values[16])) + ", " +
                               shortest(float(box->set.positions->values[17])) + "]";
  const std::string file = "'" + (d / "out.prt.h5").string() + "'";
  std::string first;
  for (const std::string& name : {std::string("stack/box"), std::string("stack|box")}) {
    SCOPED_TRACE(name);
    const auto v = prt::testing::run_tool(PRT_PRTDUMP, "--vertex 5 --object '" + name + "' " + file, d);
    ASSERT_EQ(v.code, 0) << v.err;
    EXPECT_NE(v.out.find("vertex 5 of 8 ("), std::string::npos) << v.out;
    EXPECT_NE(v.out.find(", object stack/box)\n"), std::string::npos) << v.out;
    std::istringstream lines(v.out);
    bool ao_line = false, position_line = false;
    for (std::string line; std::getline(lines, line);) {
      if (line.starts_with("  /ao ")) ao_line = line.ends_with(" " + ao);
      if (line.starts_with("  /mesh/positions ")) position_line = line.ends_with(" " + position);
    }
    EXPECT_TRUE(ao_line) << "AO of stack/box vertex 5 is " << ao << ":\n" << v.out;
    EXPECT_TRUE(position_line) << "its position is " << position << ":\n" << v.out;
    if (first.empty()) first = v.out;
    else EXPECT_EQ(v.out, first) << "both spellings name the same object";
  }
  // JSON: the object by its node path, the values by their path within the object.
  const auto j = prt::testing::run_tool(PRT_PRTDUMP, "--json --vertex 5 --object stack/box " + file, d);
  ASSERT_EQ(j.code, 0) << j.err;
  EXPECT_NE(j.out.find("\"object\": \"stack/box\""), std::string::npos) << j.out;
  const size_t at = j.out.find("\"/ao\": " + ao);
  ASSERT_NE(at, std::string::npos) << j.out;
  const char after = j.out[at + 7 + ao.size()];
  EXPECT_TRUE(after == ',' || after == '\n') << "the whole number: " << j.out.substr(at, 40);

  // Without --object, or with a name that is no object: one line naming the file and the objects.
  for (const std::string& args : {"--vertex 0 " + file, "--vertex 0 --object stack/bx " + file}) {
    SCOPED_TRACE(args);
    const auto r = prt::testing::run_tool(PRT_PRTDUMP, args, d);
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(r.out, "");
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find((d / "out.prt.h5").string() + ": "), std::string::npos) << r.err;
    for (const std::string& path : kNodePaths) EXPECT_NE(r.err.find(path), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find('|'), std::string::npos) << "objects by node path: " << r.err;
    EXPECT_EQ(r.err.find("needs /mesh/positions"), std::string::npos) << r.err;
  }
  // --object means nothing without --vertex: a command-line error.
  EXPECT_EQ(prt::testing::run_tool(PRT_PRTDUMP, "--object stack/box " + file, d).code, 2);
}

TEST(GltfScene, UnnamedNodesAreNamedAfterTheirMeshes) {
  // CAD exports name meshes, not nodes (2CylinderEngine.glb: "Piston_123-844_0_Parts_1"): an
  // unnamed node's segment is its mesh's name (bake/mesh/mesh.h NAMES), made unique among siblings;
  // a node's own name wins; neither: node<N>.
  const fs::path d = dir_for("mesh_names");
  Gltf g;
  g.dir = d;
  auto named_mesh = [&](const char* name) {
    const int m = g.mesh(primitive(g, kQuad));
    if (name) g.doc["meshes"][size_t(m)]["name"] = name;
    return m;
  };
  const int piston = named_mesh("Piston_123-844_0_Parts_1"), odd = named_mesh("a/b#c|d"), anonymous = named_mesh(nullptr),
            dots = named_mesh("..");
  std::vector<int> children;
  for (const json& n : {json{{"mesh", piston}}, json{{"mesh", piston}}, json{{"name", "rod"}, {"mesh", piston}},
                        json{{"mesh", odd}}, json{{"mesh", anonymous}}, json{{"mesh", dots}}})
    children.push_back(g.node(n, false));
  const int root = g.node({{"children", children}}, true);
  ASSERT_EQ(root, 6);
  const prt::bake::SceneDescription scene = prt::bake::load_scene(g.write("parts.gltf"));
  std::vector<std::string> paths, names;
  for (const auto& o : scene.objects) paths.push_back(o.node_path), names.push_back(o.name);
  EXPECT_EQ(paths, (std::vector<std::string>{"node6/Piston_123-844_0_Parts_1", "node6/Piston_123-844_0_Parts_1~2",
                                             "node6/rod", "node6/a_b_c_d", "node6/node4", "node6/node5"}));
  EXPECT_EQ(names[1], "node6|Piston_123-844_0_Parts_1~2") << "stored with '|' for '/'";
  // Stable: the same file names the same objects again.
  std::vector<std::string> again;
  for (const auto& o : prt::bake::load_scene(d / "parts.gltf").objects) again.push_back(o.node_path);
  EXPECT_EQ(again, paths);
}

TEST(GltfScene, OptionsSetRolesAndMaterialsByNodePathTheLongestMatchWinning) {
  const fs::path d = dir_for("options");
  const F::Asset base = bake_with_options(d, "{\"prtbake_gltf_scene\": 1, " + kBake + "}");
  // "stack" covers everything below it; "stack/box#p1" is more specific.
  const F::Asset a = bake_with_options(d, "{\"prtbake_gltf_scene\": 1, " + kBake + R"(, "objects": {
      "stack": {"role": "receiver"},
      "stack/box#p1": {"role": "occluder", "material": {"albedo": [0.1, 0.2, 0.3]}}}})");
  ASSERT_EQ(a.objects.size(), 4u);
  EXPECT_EQ(a.find_object("ground")->role, "both");
  EXPECT_EQ(a.find_object("stack|box")->role, "receiver");
  EXPECT_EQ(a.find_object("stack|node2")->role, "receiver");
  EXPECT_EQ(a.find_object("stack|box#p1")->role, "occluder");
  EXPECT_EQ(a.find_object("stack|box#p1")->albedo, (std::vector<double>{0.1, 0.2, 0.3}));
  EXPECT_TRUE(ao_of(a, "stack|box#p1").empty()) << "an occluder gets no AO";
  // The receiver-only box no longer shadows the ground: only its occluder half (the top and two
  // sides) does, so the ground under it sees more sky than before, and less than without a box.
  const float before = ao_of(base, "ground")[4 * 9 + 4], after = ao_of(a, "ground")[4 * 9 + 4];
  EXPECT_GT(after, before + 0.01f) << "role receiver: the box's lower half casts no shadow";
  EXPECT_LT(after, 0.99f) << "the occluder half still shadows the ground";
}

// Lightmaps by node path (bake/bake/scene.h "lightmap"): bake.lightmap puts every receiver per
// texel (generated UVs: the glTF has no TEXCOORD_1), an entry's false keeps "stack/node2" per
// vertex, and the more specific "stack/box#p1" entry's size wins over "stack"'s.
TEST(GltfScene, OptionsPutReceiversPerTexelByNodePath) {
  const fs::path d = dir_for("lightmaps");
  const F::Asset a = bake_with_options(d, R"({"prtbake_gltf_scene": 1,
      "bake": {"products": ["ao"], "samples": 1024, "report": 0, "lightmap": {"density": 16}},
      "objects": {"stack": {"lightmap": {"resolution": 32}}, "stack/box#p1": {"lightmap": {"resolution": 24}},
                  "stack/node2": {"lightmap": false}}})");
  ASSERT_EQ(a.objects.size(), 4u);
  auto lightmap = [&](const std::string& name) -> const std::optional<F::Lightmap>& { return a.find_object(name)->set.lightmap; };
  ASSERT_TRUE(lightmap("ground") && lightmap("stack|box") && lightmap("stack|box#p1"));
  EXPECT_EQ(lightmap("stack|box")->width, 32u);
  EXPECT_EQ(lightmap("stack|box#p1")->width, 24u) << "the longest key wins";
  EXPECT_FALSE(lightmap("stack|node2")) << "\"lightmap\": false: per vertex";
  EXPECT_FALSE(ao_of(a, "stack|node2").empty());
  EXPECT_TRUE(ao_of(a, "ground").empty()) << "per texel instead of per vertex";
  ASSERT_TRUE(lightmap("ground")->ao);
  for (float x : lightmap("ground")->ao->values) EXPECT_TRUE(std::isfinite(x) && x >= 0 && x <= 1) << x;
  EXPECT_EQ(a.find_object("ground")->set.uv->uv_set, "prtbake_lightmap");
}

// FIV shells are for occluders that move (bake/bake/scene.h): a static glTF gets none; an animation
// channel on "stack" moves its whole subtree (the box's two primitives and the quad), the options'
// "moves" overrides per node path (the longest key wins), and "weights" (morph targets) is no move.
TEST(GltfScene, OnlyAnimatedNodesGetFivShellsAndTheOptionsOverride) {
  const fs::path d = dir_for("moves");
  const std::string env = (fs::path(PRT_DATA_DIR) / "sunset.exr").string();
  const std::string settings = R"({"prtbake_gltf_scene": 1, "environment": ")" + env +
                               R"(", "bake": {"products": ["ao", "fiv"], "samples": 256, "report": 0, "fiv": {"shells": "8x5x3", "cube": 4}})";
  auto shells = [](const F::Asset& a) {
    std::vector<std::string> names;
    for (const F::Occluder& o : a.occluders) names.push_back(o.name);
    return names;
  };
  auto animate = [&](const std::string& path) {
    write_gltf(d);
    std::ifstream in(d / "stack.gltf");
    json doc = json::parse(in);
    // The sampler's accessors need not be valid for the walk: only the channel's target is read.
    doc["animations"] = {{{"channels", {{{"sampler", 0}, {"target", {{"node", 3}, {"path", path}}}}}},
                          {"samplers", {{{"input", 0}, {"output", 0}}}}}};
    std::ofstream(d / "stack.gltf") << doc.dump();
  };
  auto run = [&](const std::string& options) {
    write_text(d / "stack.options.json", options);
    const auto r = bake(d, "'" + (d / "stack.gltf").string() + "' --options '" + (d / "stack.options.json").string() + "'");
    EXPECT_EQ(r.code, 0) << r.err;
    return r.code == 0 ? F::read_asset(d / "out.prt.h5") : F::Asset{};
  };
  write_gltf(d);
  const F::Asset still = run(settings + "}");
  EXPECT_TRUE(shells(still).empty()) << "nothing moves: no shells";
  EXPECT_FALSE(still.fiv_environment.has_value()) << "and no environment FIV";
  EXPECT_NE(still.find_object("stack|box")->left_out.value_or("").find("does not move"), std::string::npos);

  animate("translation");
  EXPECT_EQ(shells(run(settings + "}")), (std::vector<std::string>{"stack|box", "stack|box#p1", "stack|node2"}))
      << "the animated node's subtree moves; the ground does not";
  EXPECT_EQ(shells(run(settings + R"(, "objects": {"stack": {"moves": false}, "stack/box": {"moves": true}}})")),
            (std::vector<std::string>{"stack|box", "stack|box#p1"}))
      << "options override, the longest key winning";

  animate("weights");
  EXPECT_TRUE(shells(run(settings + "}")).empty()) << "morph weights do not move a node";
}

TEST(GltfScene, OptionsNamingNoNodeFailWithOneLineNamingTheFileAndTheName) {
  const fs::path d = dir_for("unknown_node");
  write_text(d / "stack.options.json", R"({"prtbake_gltf_scene": 1, "objects": {"stack/bx": {"role": "receiver"}}})");
  const auto run = bake(d, "'" + write_gltf(d).string() + "' --options '" + (d / "stack.options.json").string() + "'");
  EXPECT_EQ(run.code, 1) << run.out;
  EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
  EXPECT_NE(run.err.find((d / "stack.options.json").string() + ": "), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("\"stack/bx\""), std::string::npos) << run.err;
  EXPECT_FALSE(fs::exists(d / "out.prt.h5"));
}

TEST(GltfScene, TwoCylinderEngineInstancesAreNamedObjects) {
  const fs::path path = "/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb";
  if (!fs::exists(path)) GTEST_SKIP() << path << " is missing (Debian package assimp-testmodels)";
  const prt::bake::SceneDescription scene = prt::bake::load_scene(path);
  std::vector<std::string> warnings;
  const std::vector<prt::bake::Mesh> meshes = prt::bake::load_scene_meshes(scene, warnings);
  ASSERT_EQ(meshes.size(), scene.objects.size());
  size_t triangles = 0;
  std::set<std::string> names;
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const auto& o = scene.objects[i];
    triangles += meshes[i].triangles.size();
    EXPECT_TRUE(names.insert(o.name).second) << "unique: " << o.name;
    EXPECT_EQ(o.name.find('/'), std::string::npos) << o.name;
    EXPECT_EQ(o.role, prt::bake::Role::Both);
  }
  EXPECT_EQ(triangles, 121496u) << "every triangle of the file is in some object";
  // Its nodes have no names, its meshes have: paths of the mesh names, group nodes by index, in
  // walk order (node 0 is the root; nodes 80 and 79 both show mesh "body").
  EXPECT_EQ(scene.objects.size(), 115u);
  EXPECT_EQ(scene.objects[0].node_path, "node0/body");
  EXPECT_EQ(scene.objects[1].node_path, "node0/body~2");
  EXPECT_EQ(scene.objects[3].name, "node0|Lifter_123-923_0_Parts_1#p1");
  EXPECT_TRUE(std::any_of(scene.objects.begin(), scene.objects.end(), [](const auto& o) {
    return o.node_path == "node0/node1/Piston_123-844_0_Parts_1";
  })) << "the piston of issue 29 by its mesh's name";
}

// The engine of issue 29 with only an environment: its dry run groups the 115 parts by their
// decisions (two sets: 113 with band-1 radiance, the 2 without albedo), bakes no FIV shells (no
// animation moves a part) and estimates each group's cost, in a few dozen lines; nothing written.
TEST(GltfScene, TheEngineDryRunGroupsItsPartsAndEstimatesTheCost) {
  const fs::path path = "/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb";
  if (!fs::exists(path)) GTEST_SKIP() << path << " is missing (Debian package assimp-testmodels)";
  const fs::path d = dir_for("engine_dry_run");
  write_text(d / "o.json", R"({"prtbake_gltf_scene": 1, "environment": ")" + (fs::path(PRT_DATA_DIR) / "sunset.exr").string() +
                               R"(", "bake": {"integrator": "qmc", "samples": 64}})");
  const auto r = bake(d, "'" + path.string() + "' --options '" + (d / "o.json").string() + "' --dry-run");
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* s : {"113 objects (both): node0/body, node0/body~2, node0/Lifter_123-923_0_Parts_1 and 110 more; 82065 vertices",
                        "2 objects (both): node0/node4/Piston_123-844_0_Parts_1#p1, node0/node1/Piston_123-844_0_Parts_1#p1",
                        "fiv: the object does not move", "left out, no occluder has shells", "estimated cost (nothing is baked):",
                        "113 receivers (82065 vertices, from node0/body): about ", " CPU s to bake 82065 vertices with qmc at 64 rays"})
    EXPECT_NE(r.out.find(s), std::string::npos) << "missing '" << s << "' in:\n" << r.out;
  EXPECT_LT(std::count(r.out.begin(), r.out.end(), '\n'), 30) << r.out;
  EXPECT_FALSE(fs::exists(d / "out.prt.h5"));
}
