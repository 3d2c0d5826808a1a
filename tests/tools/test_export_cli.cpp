// `prtbake export` as a user runs it: a real bake exported to each format; bad input gives one
// line naming the file and the problem, exit 1, and leaves nothing behind (no output, no staging
// directory); a bad --to is a command-line error (exit 2).
#include <gtest/gtest.h>
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

TEST(ExportCli, UnknownFormatIsACommandLineError) {
  const fs::path d = fresh("usage");
  const auto r = run_tool(PRT_PRTBAKE, export_args(ao_bake(), "fbx", d / "x.fbx"), d);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("expects gltf, glb, bin, unity, godot or filament"), std::string::npos) << r.err;
  EXPECT_TRUE(listing(d).empty());
}

} // namespace
