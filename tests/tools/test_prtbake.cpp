// End-to-end tests of the prtbake binary: what a user runs, what lands on disk, what a bad input
// does. Values are checked through the formats reader (the same one prtdump uses).
#include <formats/asset.h>
#include <formats/prtfile.h>

#include <gtest/gtest.h>
#include <run_tool.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

namespace fs = std::filesystem;
namespace F = prt::formats;

namespace {

const fs::path kData = PRT_DATA_DIR;
const std::string kBake = PRT_PRTBAKE;

std::string slurp_bytes(const fs::path& p) { return prt::testing::read_bytes(p); }

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(PRT_TEST_TMP) / "prtbake";
  fs::create_directories(dir);
  return dir / name;
}

struct Outcome {
  int code;
  std::string out, err;
};

// Runs prtbake with `args` (already shell-quoted where needed), capturing stdout and stderr.
Outcome run(const std::string& args, const std::string& env = "") {
  const auto r = prt::testing::run_tool(kBake, args, fs::path(PRT_TEST_TMP) / "prtbake", env);
  return {r.code, r.out, r.err};
}

void write_text(const fs::path& p, const std::string& s) { std::ofstream(p) << s; }

// No file under `out` and no temporary beside it.
void expect_no_output(const fs::path& out) {
  EXPECT_FALSE(fs::exists(out)) << out;
  if (!fs::exists(out.parent_path())) return;
  for (auto& e : fs::directory_iterator(out.parent_path())) {
    EXPECT_EQ(e.path().filename().string().find(out.filename().string() + ".tmp"), std::string::npos) << e.path();
  }
}

const std::string kTetra = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n";

// A closed tetrahedron written to the scratch file `name`.
fs::path tetra(const std::string& name) {
  const fs::path p = scratch(name);
  write_text(p, kTetra);
  return p;
}

} // namespace

TEST(Prtbake, BakesEveryProductOfARealMeshInOnePass) {
  const fs::path out = scratch("spider.prt.h5");
  fs::remove(out);
  const Outcome r = run((kData / "spider.obj").string() + " -o " + out.string() +
                    " --ao --transfer 3 --visibility 2 --radiance " + (kData / "sunset.exr").string() +
                    " --samples 64 --report 8 --quiet");
  // ("vertex" is the command; given after the options here on purpose: order is free.)
  ASSERT_NE(r.code, 0) << "no command given must fail";
  const Outcome ok = run("vertex " + (kData / "spider.obj").string() + " -o " + out.string() +
                     " --ao --transfer 3 --visibility 2 --radiance " + (kData / "sunset.exr").string() +
                     " --samples 64 --report 8 --quiet");
  ASSERT_EQ(ok.code, 0) << ok.err;
  EXPECT_TRUE(ok.out.empty()) << "--quiet prints nothing: " << ok.out;
  const F::File f = F::read_file(out);
  const F::Dataset* tri = F::find_dataset(f, "/mesh/triangles");
  const F::Dataset* pos = F::find_dataset(f, "/mesh/positions");
  ASSERT_TRUE(tri && pos);
  EXPECT_EQ(tri->shape[0], 1368u) << "every triangle of spider.obj reaches the file";
  // spider.obj has 762 positions and 918 distinct (position, normal) pairs: rows 0..761 are the
  // file's vertices in file order, the 156 hard-edge splits follow (bake/mesh/mesh.h).
  EXPECT_EQ(pos->shape[0], 918u);
  const size_t V = pos->shape[0];
  const auto& src = std::get<std::vector<uint32_t>>(F::find_dataset(f, "/mesh/source_position")->data);
  ASSERT_EQ(src.size(), V);
  for (uint32_t i = 0; i < 762; ++i) ASSERT_EQ(src[i], i);
  for (size_t i = 762; i < V; ++i) ASSERT_LT(src[i], 762u);
  for (const char* p : {"/ao", "/transfer/diffuse", "/transfer/visibility", "/radiance/band1", "/report/ao"})
    EXPECT_NE(F::find_dataset(f, p), nullptr) << p;
  const auto& ao = std::get<std::vector<float>>(F::find_dataset(f, "/ao")->data);
  ASSERT_EQ(ao.size(), V);
  // Every per-sample estimate is f·V/p ≥ 0, so AO ≥ 0 exactly; with the mixture of strategies
  // it may exceed 1 by noise (it is unbiased, not clamped) — AO alone is bounded, see below.
  for (float a : ao) {
    EXPECT_TRUE(std::isfinite(a));
    EXPECT_GE(a, 0.0f);
  }
  EXPECT_EQ(F::find_dataset(f, "/transfer/diffuse")->shape, (std::vector<uint64_t>{V, 9}));
  EXPECT_EQ(F::find_dataset(f, "/transfer/visibility")->shape, (std::vector<uint64_t>{V, 4}));
  EXPECT_EQ(F::find_dataset(f, "/radiance/band1")->shape, (std::vector<uint64_t>{V, 3, 3}));
  const F::Attr* sha = F::find_attr(f.root_attrs, "source_sha256");
  ASSERT_TRUE(sha);
  EXPECT_EQ(std::get<std::string>(sha->value).size(), 64u);
}

TEST(Prtbake, QmcAoAloneIsCosineSampledAndLiesInUnitInterval) {
  // With --ao alone every ray is cosine-distributed and weighs exactly 1 (f/p = (c/π)/(c/π)),
  // so each AO is a fraction k/N: in [0, 1] and a multiple of 1/N up to float rounding.
  const fs::path out = scratch("ao.prt.h5");
  ASSERT_EQ(run("vertex " + (kData / "wuson.obj").string() +
                " --ao --integrator qmc --samples 64 --report 0 --quiet -o " + out.string()).code, 0);
  const F::File f = F::read_file(out);
  EXPECT_EQ(F::find_dataset(f, "/mesh/triangles")->shape[0], 3732u);
  EXPECT_EQ(F::find_dataset(f, "/report/ao"), nullptr) << "--report 0 writes no report";
  for (float a : std::get<std::vector<float>>(F::find_dataset(f, "/ao")->data)) {
    EXPECT_GE(a, 0.0f);
    EXPECT_LE(a, 1.0f);
    EXPECT_NEAR(a * 64, std::round(a * 64), 64 * 1e-6);
  }
}

TEST(Prtbake, SameSeedGivesIdenticalBytesWhateverTheThreadCount) {
  // Both runs write the same output name (it is part of the stored command line); the first
  // file is read before the second run replaces it.
  const fs::path out = scratch("det.prt.h5");
  const std::string env = "SOURCE_DATE_EPOCH=1700000000";
  auto bake = [&](const std::string& extra) {
    const Outcome r = run("vertex " + (kData / "bunny.obj").string() + " --ao --transfer 3 --radiance " +
                          (kData / "sunset.exr").string() + " --samples 32 --report 4 --quiet -o " + out.string() +
                          " " + extra, env);
    EXPECT_EQ(r.code, 0) << r.err;
    return slurp_bytes(out);
  };
  const std::string x = bake("--seed 5 --threads 1");
  const std::string y = bake("--seed 5 --threads 2");
  ASSERT_GT(x.size(), 1000u);
  EXPECT_TRUE(x == y) << "files differ between --threads 1 and --threads 2";
  // A different seed changes the numbers (the comparison above would pass vacuously otherwise).
  EXPECT_FALSE(bake("--seed 6 --threads 2") == x);
}

TEST(Prtbake, SceneBakesPrintThePilotTableWithVerbose) {
  // A scene's receivers are chosen for like a vertex bake: one line each, the pilot's table with -v.
  const fs::path dir = scratch("scene_verbose");
  fs::create_directories(dir);
  const fs::path scene = dir / "s.json";
  std::ofstream(scene) << R"({"prtbake_scene": 1, "bake": {"products": ["ao"], "target_error": 0.003, "report": 8},
    "objects": [{"name": "bunny", "mesh": ")" << (kData / "bunny.obj").string() << R"(", "role": "both"}]})";
  const std::string bake = "scene " + scene.string() + " -o " + (dir / "s.prt.h5").string();
  const Outcome r = run(bake);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("bunny: target error 0.003: chosen "), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("model: "), std::string::npos) << "the table is printed only with -v:\n" << r.out;
  const Outcome v = run(bake + " -v");
  ASSERT_EQ(v.code, 0) << v.err;
  for (const char* s : {"bunny: the target-error pilot:", "target error 0.003: pilot on 32 seeded points",
                        "reference N = 256: estimated error ", "model: silhouette", "chosen: ", "report reference: QMC at ",
                        "target 0.003 for AO: met"})
    EXPECT_NE(v.out.find(s), std::string::npos) << "missing '" << s << "' in:\n" << v.out;
}

TEST(Prtbake, ASceneChoosesOncePerProductRequestAndJudgesTheTargetOnThePooledReport) {
  // Two receivers with the same products share one pilot (bake/bake/scene.h: the target holds for their
  // values together); the report's 16 points are shared by their vertices (8 each, the same
  // mesh), and the verdict is printed once, on the pooled report.
  const fs::path dir = scratch("scene_pooled");
  fs::create_directories(dir);
  const fs::path scene = dir / "s.json";
  const std::string mesh = (kData / "bunny.obj").string();
  std::ofstream(scene) << R"({"prtbake_scene": 1, "bake": {"products": ["ao"], "target_error": 0.003, "report": 16},
    "objects": [{"name": "a", "mesh": ")" << mesh << R"(", "role": "both"},
                {"name": "b", "mesh": ")" << mesh << R"(", "role": "both", "transform": {"translate": [0.5, 0, 0]}}]})";
  const fs::path out = dir / "s.prt.h5";
  const Outcome r = run("scene " + scene.string() + " -o " + out.string());
  ASSERT_EQ(r.code, 0) << r.err;
  auto count = [&](const std::string& s) {
    size_t n = 0;
    for (size_t at = r.out.find(s); at != std::string::npos; at = r.out.find(s, at + 1)) ++n;
    return n;
  };
  EXPECT_EQ(count("target error 0.003: chosen "), 1u) << r.out;
  EXPECT_NE(r.out.find("2 receivers ("), std::string::npos) << r.out;
  EXPECT_EQ(count("target 0.003 for AO: "), 1u) << r.out;
  EXPECT_NE(r.out.find("(2 objects), their 16 report vertices together (the reference took "), std::string::npos) << r.out;
  const F::Asset a = F::read_asset(out);
  ASSERT_EQ(a.objects.size(), 2u);
  for (const auto& o : a.objects) {
    ASSERT_TRUE(o.set.ao.has_value()) << o.name;
    EXPECT_EQ(o.set.ao->integrator, a.objects[0].set.ao->integrator) << "one choice for both";
    EXPECT_EQ(o.set.ao->samples, a.objects[0].set.ao->samples) << "one choice for both";
  }
}

TEST(Prtbake, TargetErrorChoosesPrintsWhyAndTheReportChecksIt) {
  // The chooser's contract is tested in tests/bake/test_choose.cpp; here what the user sees: one
  // line saying what was chosen and why (the pilot on 1839 / 64 = 28, so at least 32, vertices),
  // with -v the pilot's table instead, and the report's verdict on 128.
  const fs::path out = scratch("target.prt.h5");
  const std::string bake = "vertex " + (kData / "bunny.obj").string() + " --ao --target-error 2e-3 --integrator silhouette -o " +
                           out.string();
  const Outcome r = run(bake);
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* s : {"target error 0.002: chosen silhouette at N = ", "predicted error ", " µs per integral",
                        "(pilot on 32 seeded points, ", "on 128 seeded vertices", "target 0.002 for AO: met"})
    EXPECT_NE(r.out.find(s), std::string::npos) << "missing '" << s << "' in:\n" << r.out;
  for (const char* s : {"model: ", "chosen: ", "µs/integral"})
    EXPECT_EQ(r.out.find(s), std::string::npos) << "the table is printed only with -v:\n" << r.out;
  // The target asked for is recorded (/report target_error, SCHEMA.md "Error reports") and shown.
  EXPECT_EQ(F::read_asset(out).target_error, 2e-3);
  const auto dump = prt::testing::run_tool(PRT_PRTDUMP, "--json " + out.string(), out.parent_path());
  ASSERT_EQ(dump.code, 0) << dump.err;
  EXPECT_NE(dump.out.find("\"target_error\": 0.002,"), std::string::npos) << dump.out;
  const Outcome v = run(bake + " -v");
  ASSERT_EQ(v.code, 0) << v.err;
  for (const char* s : {"target error 0.002: pilot on 32 seeded points", "model: silhouette", "chosen: silhouette at N = ",
                        "target 0.002 for AO: met"})
    EXPECT_NE(v.out.find(s), std::string::npos) << "missing '" << s << "' in:\n" << v.out;
  EXPECT_EQ(v.out.find("model: qmc"), std::string::npos) << "--integrator keeps the kind:\n" << v.out;
  // The reference's own error is stated, and the report's reference is sized for E/3 (its noise
  // measured, not QMC's estimator): the check line says which noise it used.
  for (const char* s : {"reference N = 256: estimated error ", "within E/3 = 6.67e-04", "report reference: QMC at ",
                        "less the reference's own noise ", "(measured on these values) in quadrature"})
    EXPECT_NE(v.out.find(s), std::string::npos) << "missing '" << s << "' in:\n" << v.out;
  EXPECT_EQ(v.out.find("not verifiable"), std::string::npos) << v.out;
  // -v and --quiet contradict each other: a usage error, nothing baked.
  fs::remove(out);
  EXPECT_EQ(run(bake + " -v --quiet").code, 2);
  EXPECT_FALSE(fs::exists(out));
}

// The lines of `out` that begin with `prefix`, in order.
std::vector<std::string> lines_starting(const std::string& out, const std::string& prefix) {
  std::vector<std::string> found;
  std::istringstream in(out);
  for (std::string line; std::getline(in, line);)
    if (line.rfind(prefix, 0) == 0) found.push_back(line);
  return found;
}

TEST(Prtbake, TheDefaultTargetGetsTheReportOfTheSameTargetNamed) {
  // Issue 29: the default bake checked 32 vertices and said "not verifiable here" where
  // --target-error 1e-3, the same target named, checked 128 and said "met". The same request must
  // get the same check. --reproducible makes the pilot's choice a function of the inputs, so both
  // bakes are the same bake and their reports can be compared value for value.
  const std::string mesh = (kData / "bunny.obj").string();
  const fs::path def = scratch("default_target.prt.h5"), named = scratch("named_target.prt.h5");
  const Outcome d = run("vertex " + mesh + " --ao --reproducible -o " + def.string());
  const Outcome n = run("vertex " + mesh + " --ao --reproducible --target-error 1e-3 -o " + named.string());
  ASSERT_EQ(d.code, 0) << d.err;
  ASSERT_EQ(n.code, 0) << n.err;
  const F::Asset a = F::read_asset(def), b = F::read_asset(named);
  EXPECT_EQ(a.target_error, 1e-3);
  EXPECT_EQ(b.target_error, 1e-3);
  ASSERT_TRUE(a.vertices.report.vertices.has_value());
  EXPECT_EQ(a.vertices.report.vertices->values.size(), size_t(128)) << "the default checks as many vertices as a target";
  EXPECT_EQ(a.vertices.report, b.vertices.report) << "the same points, values and reference";
  EXPECT_EQ(a.vertices.ao, b.vertices.ao) << "the same bake";
  // What is printed about the check, the verdict included, is the same line for line.
  for (const char* prefix : {"error against a ", "  AO ", "  target "}) {
    const auto ld = lines_starting(d.out, prefix), ln = lines_starting(n.out, prefix);
    EXPECT_FALSE(ld.empty()) << "no line starting '" << prefix << "' in:\n" << d.out;
    if (std::string(prefix) == "error against a ") {  // the reference's time differs run to run
      ASSERT_EQ(ld.size(), ln.size());
      for (size_t i = 0; i < ld.size(); ++i) EXPECT_EQ(ld[i].substr(0, ld[i].find(" (")), ln[i].substr(0, ln[i].find(" (")));
    } else {
      EXPECT_EQ(ld, ln);
    }
  }
  EXPECT_NE(d.out.find("on 128 seeded vertices"), std::string::npos) << d.out;
}

// The number after `label` in `line` (NaN when it is not there).
double number_after(const std::string& line, const std::string& label) {
  const size_t at = line.find(label);
  return at == std::string::npos ? std::nan("") : std::stod(line.substr(at + label.size()));
}

TEST(Prtbake, TheReportSaysWhatEachNumberIsAndNoNumberContradictsAnother) {
  // Issue 29: an accurate bake printed "AO RMSE 3.0e-04 ... (the reference's own std. error
  // 2.4e-03, QMC's estimate)": a reference noisier than the whole difference it is part of. QMC's
  // estimator overstates randomised QMC's noise several times; the reference is now two
  // independent halves whose noise is measured on the report's values, and the bake's own error
  // (the RMSE with that noise taken out, and its range) is said with or without a target.
  const std::string mesh = (kData / "bunny.obj").string();
  const Outcome s = run("vertex " + mesh + " --ao --samples 65536 --report 128 -o " + scratch("sil_report.prt.h5").string());
  ASSERT_EQ(s.code, 0) << s.err;
  const auto table = lines_starting(s.out, "  AO ");
  ASSERT_EQ(table.size(), size_t(1)) << s.out;
  EXPECT_NE(table[0].find("measured from its two halves"), std::string::npos) << table[0];
  const double m = number_after(table[0], "RMSE "), sigma = number_after(table[0], "the reference's own std. error ");
  // m² = e² + σ² in expectation; the measured σ² is known to ±δσ², δ = 3·sqrt(4/n) for n = 128 points
  // (bake/bake/choose.h target_check_lines): σ above m/sqrt(1 − δ) cannot be the reference's noise.
  const double delta = 3 * std::sqrt(4.0 / 128);
  EXPECT_GT(sigma, 0.0) << table[0];
  EXPECT_LE(sigma, m / std::sqrt(1 - delta)) << table[0];
  // A deterministic integrator has no standard error of its own to print (it printed 0.000e+00,
  // which reads as "no error"): its error is a bias, which only the comparison measures.
  EXPECT_EQ(table[0].find("the bake's std. error"), std::string::npos) << table[0];
  const auto own = lines_starting(s.out, "  AO: the bake's own error ");
  ASSERT_EQ(own.size(), size_t(1)) << s.out;
  EXPECT_NE(own[0].find("less the reference's own noise "), std::string::npos) << own[0];
  EXPECT_LE(number_after(own[0], "the bake's own error "), m) << own[0];
  // A QMC bake has a standard error of its own, and it is not zero.
  const Outcome q = run("vertex " + mesh + " --ao --integrator qmc --samples 64 --report 16 -o " +
                        scratch("qmc_report.prt.h5").string());
  ASSERT_EQ(q.code, 0) << q.err;
  const auto qmc = lines_starting(q.out, "  AO ");
  ASSERT_EQ(qmc.size(), size_t(1)) << q.out;
  EXPECT_GT(number_after(qmc[0], "the bake's std. error by QMC's estimator, an upper bound, "), 0.0) << qmc[0];
}

TEST(Prtbake, PrintsWhatItBakedTheTimeAndTheError) {
  const fs::path out = scratch("talk.prt.h5");
  const Outcome r = run("vertex " + (kData / "bunny.obj").string() + " --ao --samples 32 --report 8 -o " + out.string());
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* s : {"1839 vertices", "3674 triangles", "baked 1839 vertices in", "RMSE", "wrote", "; peak memory "})
    EXPECT_NE(r.out.find(s), std::string::npos) << "missing '" << s << "' in:\n" << r.out;
  EXPECT_FALSE(F::read_asset(out).target_error.has_value()) << "samples given: no target to record";
}

struct BadInput {
  const char* name;
  std::string file_contents;  // written to the mesh path unless empty
  bool mesh_is_env = false;   // the bad file is the environment, the mesh is good
};

TEST(Prtbake, BadInputsFailWithOneLineNamingTheFileAndLeaveNothing) {
  const fs::path good_mesh = scratch("good.obj");
  write_text(good_mesh, kTetra);
  const std::string truncated_exr = slurp_bytes(kData / "sunset.exr").substr(0, 40000);
  const std::vector<BadInput> cases = {
      {"missing.obj", ""},
      {"garbled.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nthis is not a ply file\n"},
      {"truncated.obj", kTetra.substr(0, kTetra.size() - 3)},  // last face cut mid-line: "f 3 1"
      {"nan.obj", "v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n"},
      {"range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n"},
      {"empty.obj", "# nothing here\n"},
      {"missing.exr", "", true},
      {"truncated.exr", truncated_exr, true},
      {"garbled.exr", std::string("v/1\x01 this is not an EXR file at all") + std::string(200, 'x'), true},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path bad = scratch(c.name);
    fs::remove(bad);
    if (!c.file_contents.empty()) {
      std::ofstream f(bad, std::ios::binary);
      f << c.file_contents;
    }
    const fs::path out = scratch(std::string(c.name) + ".prt.h5");
    fs::remove(out);
    const std::string mesh = c.mesh_is_env ? good_mesh.string() : bad.string();
    const std::string env = c.mesh_is_env ? " --radiance " + bad.string() : "";
    const Outcome r = run("vertex " + mesh + " --ao" + env + " --samples 8 -o " + out.string());
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_NE(r.err.find(bad.string()), std::string::npos) << "error must name " << bad << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
    expect_no_output(out);
  }
}

TEST(Prtbake, UnwritableOutputFailsBeforeBaking) {
  const fs::path mesh = scratch("tetra.obj");
  write_text(mesh, kTetra);
  const Outcome r = run("vertex " + mesh.string() + " --ao -o /nonexistent-dir/x.prt.h5");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("/nonexistent-dir/x.prt.h5"), std::string::npos) << r.err;
  // Exists but is read-only (root ignores permissions, so use a path under /proc).
  const Outcome r2 = run("vertex " + mesh.string() + " --ao -o /proc/x.prt.h5");
  EXPECT_EQ(r2.code, 1) << r2.err;
  EXPECT_FALSE(fs::exists("/proc/x.prt.h5"));
}

TEST(Prtbake, ExistingOutputIsUntouchedWhenABakeFails) {
  const fs::path out = scratch("keep.prt.h5");
  write_text(out, "previous contents");
  const Outcome r = run("vertex " + scratch("does-not-exist.obj").string() + " --ao -o " + out.string());
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(slurp_bytes(out), "previous contents");
}

TEST(Prtbake, UsageErrorsExitTwoAndHelpTeaches) {
  EXPECT_EQ(run("").code, 2);
  EXPECT_EQ(run("vertex x.obj -o y.prt.h5").code, 2) << "nothing to bake";
  EXPECT_EQ(run("vertex x.obj --ao").code, 2) << "no output";
  EXPECT_EQ(run("vertex x.obj --ao -o y --transfer 0").code, 2);
  EXPECT_EQ(run("vertex x.obj --ao -o y --samples lots").code, 2);
  EXPECT_EQ(run("vertex x.obj --ao -o y --frobnicate").code, 2);
  EXPECT_EQ(run("vertex x.obj --ao -o y.prt.h5 --target-error 1e-3 --samples 64").code, 2) << "target and samples";
  EXPECT_EQ(run("vertex x.obj --ao -o y.prt.h5 --target-error 1e-6").code, 2) << "target below 1e-4";
  // The tool's help lists the commands, one line each, and says where their options are.
  const Outcome h = run("--help");
  EXPECT_EQ(h.code, 0);
  for (const char* s : {"\n  vertex ", "\n  fiv ", "\n  scene ", "\n  export ", "'prtbake COMMAND --help'", "EXAMPLES",
                        "EXIT STATUS"})
    EXPECT_NE(h.out.find(s), std::string::npos) << s;
  EXPECT_EQ(h.out.find("--visibility"), std::string::npos) << "a command's options are in its own help:\n" << h.out;
  EXPECT_LE(std::count(h.out.begin(), h.out.end(), '\n'), 40) << h.out;
  const Outcome vh = run("vertex --help");
  for (const char* s : {"--ao", "--transfer", "--visibility", "--radiance,--env", "--samples", "--seed", "--threads",
                        "--up", "EXAMPLES", "EXIT STATUS"})
    EXPECT_NE(vh.out.find(s), std::string::npos) << s;
  // Each command's help teaches its own options and ends with the exit codes too.
  for (const char* cmd : {"vertex", "fiv", "scene", "export"}) {
    const Outcome c = run(std::string(cmd) + " --help");
    EXPECT_EQ(c.code, 0) << cmd;
    EXPECT_NE(c.out.find("--output"), std::string::npos) << cmd;
    EXPECT_NE(c.out.find("Usage: prtbake " + std::string(cmd) + " [OPTIONS]"), std::string::npos) << c.out;
    EXPECT_NE(c.out.find("EXIT STATUS"), std::string::npos) << cmd;
  }
  const Outcome v = run("--version");
  EXPECT_EQ(v.code, 0);
  EXPECT_EQ(v.out.rfind("prtbake ", 0), 0u) << v.out;
}

TEST(Prtbake, OutputMustBeAnHdf5FileName) {
  // stdout cannot take an HDF5 file, and another extension would silently get HDF5 contents.
  const fs::path mesh = tetra("tetra_out.obj");
  const Outcome dash = run("vertex " + mesh.string() + " --ao -o -");
  EXPECT_EQ(dash.code, 2);
  EXPECT_NE(dash.err.find("standard output"), std::string::npos) << dash.err;
  EXPECT_FALSE(fs::exists(fs::path(PRT_TEST_TMP) / "prtbake" / "-"));
  const fs::path glb = scratch("out.glb");
  fs::remove(glb);
  const Outcome g = run("vertex " + mesh.string() + " --ao -o " + glb.string());
  EXPECT_EQ(g.code, 2);
  EXPECT_NE(g.err.find(".prt.h5 or .h5 expected"), std::string::npos) << g.err;
  expect_no_output(glb);
}

TEST(Prtbake, OptionsBelongToTheirCommand) {
  // An option that has no meaning for a command is refused, not ignored.
  const fs::path mesh = tetra("tetra_cmd.obj");
  const std::string out = scratch("cmd.prt.h5").string();
  EXPECT_EQ(run("scene " + (kData / "scene_example.json").string() + " --samples 64 -o " + out).code, 2);
  EXPECT_EQ(run("scene " + (kData / "scene_example.json").string() + " --up z --dry-run").code, 2);
  EXPECT_EQ(run("fiv " + mesh.string() + " --env " + (kData / "studio.exr").string() + " --ao -o " + out).code, 2);
  EXPECT_EQ(run("vertex " + mesh.string() + " --ao --shells 8x5x4 -o " + out).code, 2);
  EXPECT_EQ(run("vertex " + mesh.string() + " --ao --dry-run -o " + out).code, 2);
}

TEST(Prtbake, EqualsFormOfOptionsIsTheSameCommand) {
  // --opt=value works and is stored as "--opt value"; --threads and --quiet are not stored.
  const fs::path mesh = tetra("tetra_eq.obj");
  const fs::path out = scratch("eq.prt.h5");
  fs::remove(out);
  const Outcome r = run("vertex " + mesh.string() + " --ao --integrator=qmc --samples=16 --report=0 --threads=1 "
                        "--quiet --output=" + out.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const F::File f = F::read_file(out);
  const F::Attr* cl = F::find_attr(f.root_attrs, "command_line");
  ASSERT_NE(cl, nullptr);
  EXPECT_EQ(std::get<std::string>(cl->value), "prtbake vertex " + mesh.string() +
                                                  " --ao --integrator qmc --samples 16 --report 0 --output " +
                                                  out.string());
  const auto* ao = F::find_dataset(f, "/ao");
  ASSERT_NE(ao, nullptr);
  EXPECT_EQ(std::get<int64_t>(F::find_attr(ao->attrs, "samples")->value), 16) << "--samples=16 reached the qmc integrator";
}

TEST(Prtbake, FivWritesEnvironmentDifMapShellsAndValid) {
  const fs::path out = scratch("fiv.prt.h5");
  fs::remove(out);
  const Outcome r = run("fiv " + (kData / "spider.obj").string() + " --env " + (kData / "studio.exr").string() +
                        " --shells 8x5x4 --cube 2 --samples 1024 --quiet -o " + out.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const F::File f = F::read_file(out);
  EXPECT_EQ(F::find_dataset(f, "/fiv/environment")->shape, (std::vector<uint64_t>{3, 3}));
  EXPECT_EQ(F::find_dataset(f, "/fiv/irradiance_cube")->shape, (std::vector<uint64_t>{6, 2, 2, 3}));
  const F::Dataset* shells = F::find_dataset(f, "/fiv/occluders/spider/shells");
  ASSERT_NE(shells, nullptr);
  ASSERT_EQ(shells->shape.size(), 5u);
  EXPECT_LE(shells->shape[0], 4u);
  EXPECT_EQ(shells->shape[1], 5u);
  EXPECT_EQ(shells->shape[2], 8u);
  EXPECT_NE(F::find_dataset(f, "/fiv/occluders/spider/valid"), nullptr);
  // The vertex set holds the occluder's self-shadows only (--self-shadows vertex, the default).
  EXPECT_NE(F::find_dataset(f, "/radiance/band1"), nullptr);
  EXPECT_EQ(F::find_dataset(f, "/ao"), nullptr) << "no other per-vertex data was asked for";
  EXPECT_EQ(F::find_dataset(f, "/transfer/diffuse"), nullptr);
  const F::Dataset* rep = F::find_dataset(f, "/report/fiv/spider");
  ASSERT_NE(rep, nullptr) << "every bake reports its error (--report defaults to 32)";
  const auto& rv = std::get<std::vector<float>>(rep->data);
  // k = 32² against 65,536 QMC rays at 32 shell samples: the gap is a small fraction of |F_env|.
  EXPECT_LT(rv[0], 0.05f * rv[2]);
  for (float x : std::get<std::vector<float>>(F::find_dataset(f, "/fiv/irradiance_cube")->data)) EXPECT_GT(x, 0.0f);
  // The default radial scheme follows the surface (format_version 7, formats/SCHEMA.md).
  EXPECT_EQ(std::get<std::string>(F::find_attr(shells->attrs, "radial_scheme")->value), "surface");
  const F::Dataset* surface = F::find_dataset(f, "/fiv/occluders/spider/surface_radius");
  ASSERT_NE(surface, nullptr);
  EXPECT_EQ(surface->shape, (std::vector<uint64_t>{5, 8}));
  // ... and the tight proxy's cone table beside the surface-following shells (the default bake).
  const F::Dataset* cones = F::find_dataset(f, "/fiv/occluders/spider/cones");
  ASSERT_NE(cones, nullptr);
  EXPECT_EQ(cones->shape[3], 4u);
  // ... both in half floats (format_version 8, formats/SCHEMA.md "Half-float FIV tables").
  EXPECT_EQ(F::dtype_name(shells->data), "float16");
  EXPECT_EQ(F::dtype_name(cones->data), "float16");
  EXPECT_EQ(std::get<int64_t>(F::find_attr(f.root_attrs, "format_version")->value), 8);
  // --radial geometric: paper 004's spheres (no radial_scheme, no surface_radius); with
  // --precision float the file is version 7 for its cone table (the tight proxy every bake writes).
  ASSERT_EQ(run("fiv " + (kData / "spider.obj").string() + " --env " + (kData / "studio.exr").string() +
                " --shells 8x5x4 --cube 2 --samples 1024 --radial geometric --precision float --report 0 --quiet -o " +
                out.string())
                .code,
            0);
  const F::File g = F::read_file(out);
  EXPECT_EQ(F::find_attr(F::find_dataset(g, "/fiv/occluders/spider/shells")->attrs, "radial_scheme"), nullptr);
  EXPECT_EQ(F::find_dataset(g, "/fiv/occluders/spider/surface_radius"), nullptr);
  EXPECT_NE(F::find_dataset(g, "/fiv/occluders/spider/cones"), nullptr);
  EXPECT_EQ(F::dtype_name(F::find_dataset(g, "/fiv/occluders/spider/shells")->data), "float32");
  EXPECT_EQ(std::get<int64_t>(F::find_attr(g.root_attrs, "format_version")->value), 7);
  EXPECT_EQ(run("fiv " + (kData / "spider.obj").string() + " --env x.exr --precision double -o " + out.string()).code, 2);
  EXPECT_EQ(run("fiv " + (kData / "spider.obj").string() + " --env x.exr --radial spherical -o " + out.string()).code, 2);
  EXPECT_EQ(run("fiv " + (kData / "spider.obj").string() + " -o " + out.string()).code, 2) << "no --env";
  EXPECT_EQ(run("fiv " + (kData / "spider.obj").string() + " --env x.exr --shells 8x1x4 -o " + out.string()).code, 2);
}

// --self-shadows vertex (the default): the occluder's band-1 radiance at its vertices, in the
// file's vertex set, the very rows `prtbake vertex --radiance` bakes with the same integrator;
// --self-shadows shells writes none, and a sharded bake none (it says so).
TEST(Prtbake, FivSelfShadowsAreTheOccludersBand1RadianceAtItsVertices) {
  const fs::path fiv = scratch("self.prt.h5"), vertex = scratch("self_vertex.prt.h5"), shells = scratch("self_shells.prt.h5");
  const std::string env = (kData / "studio.exr").string(), bunny = (kData / "bunny.obj").string();
  const Outcome a = run("fiv " + bunny + " --env " + env + " --shells 8x5x4 --cube 2 --samples 1024 --report 0 -o " + fiv.string());
  ASSERT_EQ(a.code, 0) << a.err;
  EXPECT_NE(a.out.find("self-shadows: band-1 radiance at 1839 vertices"), std::string::npos) << a.out;
  const Outcome b = run("vertex " + bunny + " --radiance " + env + " --integrator silhouette --samples 1024 --report 0 -o " +
                        vertex.string());
  ASSERT_EQ(b.code, 0) << b.err;
  const F::Asset f = F::read_asset(fiv), v = F::read_asset(vertex);
  ASSERT_TRUE(f.vertices.radiance_band1.has_value());
  ASSERT_TRUE(v.vertices.radiance_band1.has_value());
  EXPECT_EQ(f.vertices.radiance_band1->values.size(), 1839u * 9u);
  EXPECT_EQ(f.vertices.radiance_band1->values, v.vertices.radiance_band1->values);
  EXPECT_EQ(f.vertices.positions->values, v.vertices.positions->values);
  EXPECT_EQ(f.vertices.normals->values, v.vertices.normals->values);
  const Outcome c = run("fiv " + bunny + " --env " + env + " --shells 8x5x4 --cube 2 --samples 1024 --report 0 --self-shadows shells -o " +
                        shells.string());
  ASSERT_EQ(c.code, 0) << c.err;
  const F::Asset g = F::read_asset(shells);
  EXPECT_FALSE(g.vertices.radiance_band1.has_value());
  EXPECT_FALSE(g.vertices.positions.has_value());
  EXPECT_EQ(g.occluders.at(0).shells, f.occluders.at(0).shells);  // the shells do not depend on it
  EXPECT_EQ(run("fiv " + bunny + " --env " + env + " --self-shadows faces -o " + shells.string()).code, 2);
}

TEST(Prtbake, TheBand1ReportRowCarriesTheRmsItsRelativeErrorDividesBy) {
  // formats/SCHEMA.md "Error reports": a band-1 row's mesh_rms is the RMS of the file's band-1 over
  // every vertex (the bake's doubles; the file holds floats, within 2^-24 relative of them).
  const fs::path out = scratch("mesh_rms.prt.h5");
  const Outcome r = run("vertex " + (kData / "bunny.obj").string() + " --radiance " + (kData / "sunset.exr").string() +
                        " --integrator silhouette --samples 1024 --report 16 -o " + out.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const F::Asset a = F::read_asset(out);
  ASSERT_TRUE(a.vertices.radiance_band1.has_value());
  double s2 = 0;
  for (const float v : a.vertices.radiance_band1->values) s2 += double(v) * double(v);
  const double rms = std::sqrt(s2 / double(a.vertices.radiance_band1->values.size()));
  const auto row = std::find_if(a.vertices.report.rows.begin(), a.vertices.report.rows.end(),
                                [](const F::ReportRow& x) { return x.product == "radiance/band1"; });
  ASSERT_NE(row, a.vertices.report.rows.end());
  ASSERT_TRUE(row->mesh_rms.has_value());
  EXPECT_NEAR(*row->mesh_rms, rms, 1e-6 * rms);
  EXPECT_GT(rms, 0.0);
}
