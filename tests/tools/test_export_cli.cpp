// `prtbake export` as a user runs it: a real bake exported to each format; bad input gives one
// line naming the file and the problem, exit 1, and leaves nothing behind (no output, no staging
// directory); a bad --to is a command-line error (exit 2); a file h5py annotated exports the
// bytes of the file without its notes. Lightmaps (format v5, a texel bake of a floor in two UV
// charts around a box): the glb's TEXCOORD_1 is the file's UVs at every corner (exact floats),
// vertices split at the seam; its occlusion PNG holds round(255·AO) at every texel (exact); the
// EXR channels equal the file's values to half precision; the Godot directional lightmap equals
// the values computed here from the file and Godot's shader formula; a file without a lightmap
// asked for EXR is one line naming it, exit 1, nothing written.
#include <formats/asset.h>

#include <gtest/gtest.h>
#include <h5py.h>
#include <hdf5_bytes.h>
#include <run_tool.h>
#include <scratch.h>
#include <unit_box_obj.h>

#include <nlohmann/json.hpp>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

namespace fs = std::filesystem;
using prt::testing::run_tool;

namespace {

const fs::path kDir = fs::path(PRT_TEST_TMP) / "export_cli";

using prt::testing::listing;

// An AO-only bake of the ground mesh, made once.
const fs::path& ao_bake() {
  static const fs::path file = [] {
    fs::create_directories(kDir);
    const fs::path f = kDir / "ground_ao.prt.h5";
    const auto r = run_tool(PRT_PRTBAKE, "vertex '" + std::string(PRT_DATA_DIR) + "/ground.obj' --ao --integrator qmc --samples 16 --report 0 -q -o '" + f.string() + "'", kDir);
    EXPECT_EQ(r.code, 0) << r.err;
    return f;
  }();
  return file;
}

fs::path fresh(const std::string& name) { return prt::testing::fresh_dir("export_cli", name); }

std::string export_args(const fs::path& in, const std::string& to, const fs::path& out) {
  return "export '" + in.string() + "' --to " + to + " -o '" + out.string() + "'";
}

TEST(ExportCli, WritesEachGeometryFormatAndNothingElse) {
  const fs::path d = fresh("ok");
  for (const char* to : {"gltf", "glb", "bin"}) {
    const auto r = run_tool(PRT_PRTBAKE, export_args(ao_bake(), to, d / (std::string("g.") + to)), d);
    EXPECT_EQ(r.code, 0) << r.err;
  }
  EXPECT_EQ(listing(d), (std::vector<std::string>{"g.bin", "g.glb", "g.gltf"}));  // g.gltf's buffer is g.bin
}

TEST(ExportCli, ProbesOfAnAoOnlyFileAreRefusedNamingTheFile) {
  const fs::path d = fresh("no_radiance");
  const auto r = run_tool(PRT_PRTBAKE, export_args(ao_bake(), "unity", d / "p.json"), d);
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(ao_bake().string() + ": has no /radiance/band1"), std::string::npos) << r.err;
  EXPECT_TRUE(listing(d).empty());
}

TEST(ExportCli, BadInputIsOneLineExitOneAndNoOutput) {
  const fs::path d = fresh("bad");
  const fs::path not_h5 = d / "not.prt.h5";
  std::ofstream(not_h5) << "not an HDF5 file";
  for (const fs::path& in : {d / "missing.prt.h5", not_h5}) {
    const auto r = run_tool(PRT_PRTBAKE, export_args(in, "glb", d / "x.glb"), d);
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(in.string()), std::string::npos) << r.err;
  }
  const auto r = run_tool(PRT_PRTBAKE, export_args(ao_bake(), "gltf", d / "no_such_dir" / "x.gltf"), d);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("does not exist"), std::string::npos) << r.err;
  EXPECT_EQ(listing(d), (std::vector<std::string>{"not.prt.h5"}));
}

TEST(ExportCli, EnvironmentProbeMustBeTheBakesEnvironment) {
  const fs::path d = fresh("env");
  const std::string data = PRT_DATA_DIR;
  const fs::path lit = d / "ground_sunset.prt.h5";
  auto r = run_tool(PRT_PRTBAKE, "vertex '" + data + "/ground.obj' --radiance '" + data + "/sunset.exr' --integrator qmc "
                    "--samples 16 --report 0 -q -o '" + lit.string() + "'", d);
  ASSERT_EQ(r.code, 0) << r.err;
  // The map the file was baked with: per-vertex probes and the environment's.
  r = run_tool(PRT_PRTBAKE, export_args(lit, "unity", d / "lit.json") + " --env '" + data + "/sunset.exr'", d);
  EXPECT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(prt::testing::read_bytes(d / "lit.json"));
  EXPECT_EQ(j["sets"].size(), 1u);
  EXPECT_EQ(j["environment"]["sh"].size(), 27u);
  // Another map: one line naming it, exit 1, nothing written.
  r = run_tool(PRT_PRTBAKE, export_args(lit, "godot", d / "wrong.json") + " --env '" + data + "/forest.exr'", d);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("forest.exr: is not the environment"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(d / "wrong.json"));
  // An AO-only file records no environment: the probe of any map, alone.
  r = run_tool(PRT_PRTBAKE, export_args(ao_bake(), "filament", d / "sky.json") + " --env '" + data + "/forest.exr'", d);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(nlohmann::json::parse(prt::testing::read_bytes(d / "sky.json"))["sets"].empty());
  // Not a probe format: a command-line error.
  r = run_tool(PRT_PRTBAKE, export_args(ao_bake(), "glb", d / "x.glb") + " --env '" + data + "/forest.exr'", d);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("--env writes an environment probe"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(d / "x.glb"));
  // A probe format writes one environment probe.
  r = run_tool(PRT_PRTBAKE, export_args(ao_bake(), "unity", d / "two.json") + " --env '" + data + "/forest.exr' --env '" + data + "/studio.exr'", d);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("give --env once"), std::string::npos) << r.err;
}

// --to web: a folder with the page and every --env as an environment (the browser test,
// viewer/test/browser_test.mjs, looks at it); the line printed says how to open it.
TEST(ExportCli, WebWritesAFolderWithEachEnvironment) {
  const fs::path d = fresh("web");
  const std::string data = PRT_DATA_DIR;
  const auto r = run_tool(PRT_PRTBAKE, export_args(ao_bake(), "web", d / "site") + " --env '" + data + "/forest.exr' --env '" +
                                           data + "/studio.exr'", d);
  if (r.code == 2 && r.err.find("built without the web viewer") != std::string::npos) GTEST_SKIP() << r.err;
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("environments: forest.exr, studio.exr"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("python3 -m http.server -d"), std::string::npos) << r.out;
  const auto info = nlohmann::json::parse(prt::testing::read_bytes(d / "site" / "viewer.json"));
  ASSERT_EQ(info["environments"].size(), 2u);
  EXPECT_EQ(info["environments"][0]["order"], 3);  // an AO-only file: order 3 (AO x the unshadowed irradiance)
  EXPECT_TRUE(fs::is_regular_file(d / "site" / "index.html"));
}

TEST(ExportCli, AFileAnnotatedWithH5pyExportsTheSameBytes) {
  // h5py's str attributes (variable-length strings, issue 28) are read, or left out with a
  // warning when their heap is damaged; no export carries attributes, so every format gives the
  // bytes of the file without them.
  const fs::path d = fresh("h5py");
  const std::string python = prt::testing::python_with_h5py(d);
  if (python.empty()) GTEST_SKIP() << "h5py is not installed (apt-get install python3-h5py to run this test)";
  const fs::path plain = d / "plain.prt.h5", notes = d / "notes.prt.h5";
  const auto bake = run_tool(PRT_PRTBAKE, "vertex '" + std::string(PRT_DATA_DIR) + "/ground.obj' --ao --radiance '" +
                                              std::string(PRT_DATA_DIR) + "/sunset.exr' --integrator qmc --samples 16 --report 0 -q -o '" +
                                              plain.string() + "'",
                             d);
  ASSERT_EQ(bake.code, 0) << bake.err;
  fs::copy_file(plain, notes);
  ASSERT_EQ(prt::testing::add_h5py_notes(python, notes, "mesh", "ao", prt::testing::H5pyStrings::variable_length), "");
  prt::testing::Bytes damaged = prt::testing::file_bytes(notes);
  damaged[prt::testing::only_collection(damaged) + 1] = 'X';  // "GXOL"
  prt::testing::write_file_bytes(d / "damaged.prt.h5", damaged);
  for (const char* to : {"gltf", "glb", "bin", "unity", "godot", "filament"}) {
    SCOPED_TRACE(to);
    for (const char* input : {"plain", "notes", "damaged"}) {
      fs::create_directories(d / input);
      const auto r = run_tool(PRT_PRTBAKE, export_args(d / (std::string(input) + ".prt.h5"), to, d / input / "out"), d);
      ASSERT_EQ(r.code, 0) << input << ": " << r.err;
      const std::size_t warnings = std::string(input) == "damaged" ? 4 : 0;
      EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), warnings) << input << ": " << r.err;
      if (warnings) {
        EXPECT_NE(r.err.find("prtbake: warning: export: " + (d / "damaged.prt.h5").string() +
                             ": attribute 'note' of group '/mesh' skipped: its text cannot be read safely from the HDF5 "
                             "global heap: no global heap collection starts at byte "),
                  std::string::npos)
            << r.err;
      }
    }
    for (const char* input : {"notes", "damaged"})
      for (const char* file : {"out", "out.bin"}) {
        if (!fs::exists(d / "plain" / file)) continue;  // out.bin: the glTF buffer only
        EXPECT_EQ(prt::testing::read_bytes(d / input / file), prt::testing::read_bytes(d / "plain" / file)) << input << "/" << file;
      }
  }
}

TEST(ExportCli, UnknownFormatIsACommandLineError) {
  const fs::path d = fresh("usage");
  const auto r = run_tool(PRT_PRTBAKE, export_args(ao_bake(), "fbx", d / "x.fbx"), d);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("expects gltf, glb, bin, unity, godot, filament, exr or web"), std::string::npos) << r.err;
  EXPECT_TRUE(listing(d).empty());
}

// ---- lightmaps ----

// The floor [−2, 2]² at z = 0 in two UV charts (its triangles apart in UV, so the two vertices of
// its diagonal carry two UVs each: a seam) around the unit box [−½, ½]² × [0, 1] standing on it,
// whose corners sit at vt (3, 3), outside the atlas: it occludes and has no texels.
fs::path seamed_floor_and_box(const fs::path& dir) {
  const fs::path obj = dir / "floor_box.obj";
  std::ofstream out(obj);
  out << "v -2 -2 0\nv 2 -2 0\nv 2 2 0\nv -2 2 0\n";
  out << "vt 0.05 0.95\nvt 0.9 0.95\nvt 0.9 0.1\nvt 0.1 0.9\nvt 0.95 0.05\nvt 0.1 0.05\nvt 3 3\n";
  out << "f 1/1 2/2 3/3\nf 1/4 3/5 4/6\n";
  prt::testing::write_unit_box_obj(out, 5, 7);
  return obj;
}

// A 16 × 16 texel bake of it with AO, order-3 transfer and band-1 radiance, made once.
const fs::path& texel_bake() {
  static const fs::path file = [] {
    fs::create_directories(kDir);
    const fs::path f = kDir / "floor_box_texel.prt.h5";
    const std::string data = PRT_DATA_DIR;
    const auto r = run_tool(PRT_PRTBAKE, "texel '" + seamed_floor_and_box(kDir).string() + "' --resolution 16 --ao --transfer 3 "
                            "--radiance '" + data + "/sunset.exr' --integrator qmc --samples 16 --report 0 -q -o '" + f.string() + "'", kDir);
    EXPECT_EQ(r.code, 0) << r.err;
    return f;
  }();
  return file;
}

// A binary glTF's JSON and its BIN chunk (glTF 2.0 §4.4: 12-byte header, then chunks of length,
// type, data).
struct Glb {
  nlohmann::json json;
  std::string bin;
  // The bytes of buffer view `view`.
  std::string_view view(int view) const {
    const nlohmann::json& v = json["bufferViews"][size_t(view)];
    return std::string_view(bin).substr(v.value("byteOffset", size_t(0)), v["byteLength"].get<size_t>());
  }
  // Accessor `a` as `T`s (tightly packed, as our exporter writes them).
  template <class T> std::vector<T> accessor(int a) const {
    const std::string_view bytes = view(json["accessors"][size_t(a)]["bufferView"].get<int>());
    std::vector<T> out(bytes.size() / sizeof(T));
    std::memcpy(out.data(), bytes.data(), out.size() * sizeof(T));
    return out;
  }
};

Glb read_glb(const fs::path& path) {
  const std::string bytes = prt::testing::read_bytes(path);
  auto u32 = [&](size_t at) {
    uint32_t x;
    std::memcpy(&x, bytes.data() + at, 4);
    return x;
  };
  EXPECT_EQ(bytes.substr(0, 4), "glTF");
  const uint32_t json_length = u32(12), bin_length = u32(20 + json_length);
  return {nlohmann::json::parse(bytes.substr(20, json_length)), bytes.substr(28 + json_length, bin_length)};
}

// The three corner UVs' (u, v) and positions of the file's triangles, and the glTF's, are the same
// floats; vertices split only at the seam; the occlusion texture's pixels are round(255·AO).
TEST(ExportCli, GlbCarriesTheLightmapUvsAndTheAoAsItsOcclusionTexture) {
  const fs::path d = fresh("lightmap_glb");
  const auto r = run_tool(PRT_PRTBAKE, export_args(texel_bake(), "glb", d / "fb.glb"), d);
  ASSERT_EQ(r.code, 0) << r.err;
  const prt::formats::Asset asset = prt::formats::read_asset(texel_bake());
  const prt::formats::VertexSet& s = asset.vertices;
  ASSERT_TRUE(s.uv && s.lightmap && s.lightmap->ao && s.triangles && s.normals);
  const Glb glb = read_glb(d / "fb.glb");
  const nlohmann::json& prim = glb.json["meshes"][0]["primitives"][0];
  const nlohmann::json& attrs = prim["attributes"];
  ASSERT_TRUE(attrs.contains("TEXCOORD_1"));
  const std::vector<float> uv = glb.accessor<float>(attrs["TEXCOORD_1"].get<int>());
  const std::vector<float> pos = glb.accessor<float>(attrs["POSITION"].get<int>());
  const std::vector<float> nrm = glb.accessor<float>(attrs["NORMAL"].get<int>());
  const std::vector<uint32_t> idx = glb.accessor<uint32_t>(prim["indices"].get<int>());
  const std::vector<uint32_t>& tri = s.triangles->values;
  ASSERT_EQ(idx.size(), tri.size()) << "the file's triangles, in order";
  // The diagonal's two vertices (rows 0 and 2) carry another UV in the second chart: 2 copies.
  const size_t V = s.vertex_count();
  ASSERT_EQ(pos.size(), 3 * (V + 2));
  EXPECT_EQ(glb.json["asset"]["extras"]["prtbake"]["sets"][0]["vertices"]["copies_of"], nlohmann::json({0, 2}));
  for (size_t i = 0; i < tri.size(); ++i) {
    const uint32_t g = idx[i], f = tri[i];
    EXPECT_EQ(uv[2 * g], s.uv->values[2 * i]) << "corner " << i;
    EXPECT_EQ(uv[2 * g + 1], s.uv->values[2 * i + 1]) << "corner " << i;
    for (size_t a = 0; a < 3; ++a) {
      EXPECT_EQ(pos[3 * g + a], float(s.positions->values[3 * f + a])) << "corner " << i;
      EXPECT_EQ(nrm[3 * g + a], s.normals->values[3 * f + a]) << "corner " << i;
    }
  }
  // The material's occlusion: texCoord 1, a PNG in the buffer, one code per texel.
  const nlohmann::json& material = glb.json["materials"][prim["material"].get<size_t>()];
  EXPECT_EQ(material["occlusionTexture"]["texCoord"], 1);
  const nlohmann::json& texture = glb.json["textures"][material["occlusionTexture"]["index"].get<size_t>()];
  const nlohmann::json& image = glb.json["images"][texture["source"].get<size_t>()];
  EXPECT_EQ(image["mimeType"], "image/png");
  const std::string_view png = glb.view(image["bufferView"].get<int>());
  png_image im{};
  im.version = PNG_IMAGE_VERSION;
  ASSERT_TRUE(png_image_begin_read_from_memory(&im, png.data(), png.size())) << im.message;
  im.format = PNG_FORMAT_GRAY;
  const prt::formats::Lightmap& m = *s.lightmap;
  ASSERT_EQ(im.width, m.width);
  ASSERT_EQ(im.height, m.height);
  std::vector<uint8_t> grey(m.texel_count());
  ASSERT_TRUE(png_image_finish_read(&im, nullptr, grey.data(), 0, nullptr)) << im.message;
  std::set<int> codes;
  for (size_t k = 0; k < m.texel_count(); ++k) {
    const int want = int(std::lround(std::clamp(double(m.ao->values[k]), 0.0, 1.0) * 255.0));
    EXPECT_EQ(int(grey[k]), want) << "texel " << k;
    codes.insert(want);
  }
  EXPECT_GT(codes.size(), 10u) << "the AO varies around the box (else the check says little)";
  RecordProperty("distinct_codes", std::to_string(codes.size()));
  RecordProperty("vertices", std::to_string(pos.size() / 3) + " of " + std::to_string(V) + " rows");
}

// Half's rounding to nearest: within 2⁻¹¹ of the value relative to it (11 significant bits) for
// |x| ≥ 2⁻¹⁴, within half its subnormal spacing 2⁻²⁴ below that.
double half_tolerance(double x) { return std::max(std::ldexp(std::abs(x), -11), std::ldexp(1.0, -25)); }

// Reads every channel of an EXR as floats: name → [H][W].
std::map<std::string, std::vector<float>> read_exr(const fs::path& path, int& width, int& height) {
  Imf::InputFile file(path.c_str());
  const Imath::Box2i w = file.header().dataWindow();
  width = w.max.x - w.min.x + 1;
  height = w.max.y - w.min.y + 1;
  std::map<std::string, std::vector<float>> out;
  Imf::FrameBuffer frame;
  for (auto it = file.header().channels().begin(); it != file.header().channels().end(); ++it) {
    EXPECT_EQ(it.channel().type, Imf::HALF) << it.name();
    std::vector<float>& v = out[it.name()];
    v.resize(size_t(width) * size_t(height));
    frame.insert(it.name(), Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(v.data()), sizeof(float), sizeof(float) * size_t(width)));
  }
  file.setFrameBuffer(frame);
  file.readPixels(w.min.y, w.max.y);
  return out;
}

TEST(ExportCli, ExrLightmapsHoldEveryValueToHalfPrecision) {
  const fs::path d = fresh("lightmap_exr");
  auto r = run_tool(PRT_PRTBAKE, export_args(texel_bake(), "exr", d / "lm"), d);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(listing(d), (std::vector<std::string>{"lm.exr"}));
  const prt::formats::Asset asset = prt::formats::read_asset(texel_bake());
  const prt::formats::Lightmap& m = *asset.vertices.lightmap;
  int W = 0, H = 0;
  const auto channels = read_exr(d / "lm.exr", W, H);
  ASSERT_EQ(size_t(W), m.width);
  ASSERT_EQ(size_t(H), m.height);
  // The file's values per channel name: the layout of formats/SCHEMA.md, written out here.
  std::map<std::string, std::vector<double>> want;
  const size_t texels = m.texel_count();
  for (size_t k = 0; k < texels; ++k) {
    want["state"].push_back(m.state.values[k]);
    want["ao"].push_back(m.ao->values[k]);
    for (size_t i = 0; i < 9; ++i) want["transfer.diffuse.c" + std::to_string(i)].push_back(m.transfer_diffuse->values[9 * k + i]);
    const char* rgb[3] = {"R", "G", "B"};
    for (size_t c = 0; c < 3; ++c)
      for (int mm = -1; mm <= 1; ++mm)
        want[std::string("radiance.band1.") + rgb[c] + ".m" + std::to_string(mm)].push_back(
            m.radiance_band1->values[9 * k + 3 * c + size_t(mm + 1)]);
  }
  ASSERT_EQ(channels.size(), want.size());
  double worst = 0;  // the largest error in units of the tolerance
  for (const auto& [name, values] : want) {
    ASSERT_TRUE(channels.count(name)) << name;
    const std::vector<float>& got = channels.at(name);
    for (size_t k = 0; k < texels; ++k) {
      EXPECT_LE(std::abs(got[k] - values[k]), half_tolerance(values[k])) << name << " texel " << k;
      worst = std::max(worst, std::abs(got[k] - values[k]) / half_tolerance(values[k]));
    }
  }
  RecordProperty("channels", std::to_string(channels.size()));
  RecordProperty("worst_error_over_tolerance", std::to_string(worst));
  // A directory as -o: DIR/lightmap.exr.
  fs::create_directories(d / "dir");
  r = run_tool(PRT_PRTBAKE, export_args(texel_bake(), "exr", d / "dir"), d);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(listing(d / "dir"), (std::vector<std::string>{"lightmap.exr"}));
}

TEST(ExportCli, ExrOfAFileWithoutALightmapIsRefusedNamingTheFile) {
  const fs::path d = fresh("lightmap_none");
  const auto r = run_tool(PRT_PRTBAKE, export_args(ao_bake(), "exr", d / "lm"), d);
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(ao_bake().string() + ": has no lightmap"), std::string::npos) << r.err;
  EXPECT_TRUE(listing(d).empty()) << "no output, no staging directory";
}

// Godot 4.4+'s directional lightmap (exports/src/export_probes.cpp cites the shader): layer 0 is
// E(n0)/π from the band-1 radiance at the texel's normal, layers 1–3 the packed tangential L1
// a/2 + ½; Godot's formula l0 + 4 l0 (a·n) gives back l0 at the baked normal.
TEST(ExportCli, GodotDirectionalLightmapFollowsGodotsL1Layout) {
  const fs::path d = fresh("lightmap_godot");
  const auto r = run_tool(PRT_PRTBAKE, export_args(texel_bake(), "godot", d / "g.json"), d);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(listing(d), (std::vector<std::string>{"g.json", "g.lightmap.exr", "g.lightmap.exr.import"}));
  EXPECT_NE(prt::testing::read_bytes(d / "g.lightmap.exr.import").find("slices/vertical=4"), std::string::npos);
  const nlohmann::json j = nlohmann::json::parse(prt::testing::read_bytes(d / "g.json"));
  ASSERT_EQ(j["lightmaps"].size(), 1u);
  EXPECT_EQ(j["lightmaps"][0]["file"], "g.lightmap.exr");
  const prt::formats::Asset asset = prt::formats::read_asset(texel_bake());
  ASSERT_EQ(asset.root.up_axis, "y") << "the engine frame is the file's (Godot is +Y up, right-handed)";
  const prt::formats::Lightmap& m = *asset.vertices.lightmap;
  int W = 0, H = 0;
  const auto layers = read_exr(d / "g.lightmap.exr", W, H);
  ASSERT_EQ(size_t(W), m.width);
  ASSERT_EQ(size_t(H), 4 * m.height) << "4 layers stacked vertically";
  const size_t texels = m.texel_count();
  const double k1 = std::sqrt(3 / (4 * std::acos(-1.0)));
  size_t lit = 0;
  const char* rgb[3] = {"R", "G", "B"};
  for (size_t k = 0; k < texels; ++k) {
    const float* n = &m.normals->values[3 * k];
    for (size_t c = 0; c < 3; ++c) {
      const float* R = &m.radiance_band1->values[9 * k + 3 * c];
      // E/π = g·n, g = (4/3) k1 (−R_1, −R_−1, R_0): our y_1m = k1 (−y, z, −x).
      const double g[3] = {-4.0 / 3 * k1 * R[2], -4.0 / 3 * k1 * R[0], 4.0 / 3 * k1 * R[1]};
      double e0 = g[0] * n[0] + g[1] * n[1] + g[2] * n[2];
      double a[3] = {0, 0, 0};
      if (e0 > 0 && m.state.values[k] != 0) {
        double largest = 1;
        for (int i = 0; i < 3; ++i) largest = std::max(largest, std::abs(a[i] = (g[i] - e0 * n[i]) / (4 * e0)));
        for (double& x : a) x /= largest;
        ++lit;
      } else {
        e0 = 0;
      }
      const std::vector<float>& L = layers.at(rgb[c]);
      EXPECT_LE(std::abs(L[k] - e0), half_tolerance(e0)) << "l0, texel " << k << " " << rgb[c];
      // Layers 1, 2, 3 hold a_y, a_z, a_x (Godot's l1n1, l1_0, l1p1) as a/2 + ½.
      const double packed[3] = {a[1] / 2 + 0.5, a[2] / 2 + 0.5, a[0] / 2 + 0.5};
      double decoded[3];
      for (size_t layer = 1; layer <= 3; ++layer) {
        const float t = L[layer * texels + k];
        EXPECT_LE(std::abs(t - packed[layer - 1]), half_tolerance(packed[layer - 1])) << "layer " << layer << " texel " << k;
        decoded[layer - 1] = (t - 0.5) * 2;
      }
      // Godot's shading at the baked normal: l0 + 4 l0 (a_y n.y + a_z n.z + a_x n.x) = l0, up to the
      // half rounding of the packed a (each within 2⁻¹² of [0, 1] values, 2⁻¹¹ once unpacked).
      const double shaded = L[k] + 4 * L[k] * (decoded[0] * n[1] + decoded[1] * n[2] + decoded[2] * n[0]);
      EXPECT_NEAR(shaded, L[k], 4 * L[k] * 3 * std::ldexp(1.0, -11)) << "texel " << k;
    }
  }
  EXPECT_GT(lit, texels) << "most texel channels are lit (else the check says little)";
  RecordProperty("lit_texel_channels", std::to_string(lit) + " of " + std::to_string(3 * texels));
}

TEST(ExportCli, HelpTeachesTheLightmapExports) {
  const auto r = run_tool(PRT_PRTBAKE, "export --help", kDir);
  EXPECT_EQ(r.code, 0) << r.err;
  for (const char* s : {"exr", "TEXCOORD_1", "occlusionTexture", "round(255*AO)", "Godot 4.4+ directional lightmap",
                        "--to exr -o floor", "--to godot -o floor.json"})
    EXPECT_NE(r.out.find(s), std::string::npos) << s;
}

} // namespace
