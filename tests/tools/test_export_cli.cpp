// `prtbake export` as a user runs it: a real bake exported to each format; bad input gives one
// line naming the file and the problem, exit 1, and leaves nothing behind (no output, no staging
// directory); a bad --to is a command-line error (exit 2); a file h5py annotated exports the
// bytes of the file without its notes.
#include <gtest/gtest.h>
#include <h5py.h>
#include <hdf5_bytes.h>
#include <run_tool.h>
#include <scratch.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>

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
  EXPECT_NE(r.err.find("expects gltf, glb, bin, unity, godot or filament"), std::string::npos) << r.err;
  EXPECT_TRUE(listing(d).empty());
}

} // namespace
