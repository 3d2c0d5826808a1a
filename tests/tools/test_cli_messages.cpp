// What prtbake and prtdump say when the command line is wrong, and what they print while they work,
// as a user meets it (issue 29, "Messages and exit codes"): every command-line mistake is exit 2
// before any file is read, with one line that names the option and the problem; an unknown
// command or option gets the nearest name; each command's help describes what it accepts; the
// probe export names what it leaves out; a log holds a few progress lines per stage.
#include <formats/asset.h>

#include <gtest/gtest.h>
#include <run_tool.h>
#include <scratch.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <string>
#include <vector>

namespace fs = std::filesystem;
namespace F = prt::formats;

namespace {

const fs::path kData = PRT_DATA_DIR;

struct Outcome {
  int code;
  std::string out, err;
};

Outcome prtbake(const fs::path& dir, const std::string& args) {
  const auto r = prt::testing::run_tool(PRT_PRTBAKE, args, dir);
  return {r.code, r.out, r.err};
}
Outcome prtdump(const fs::path& dir, const std::string& args) {
  const auto r = prt::testing::run_tool(PRT_PRTDUMP, args, dir);
  return {r.code, r.out, r.err};
}

std::string q(const fs::path& p) { return "'" + p.string() + "'"; }

size_t lines(const std::string& s) { return size_t(std::count(s.begin(), s.end(), '\n')); }

} // namespace

TEST(CliMessages, CommandLineMistakesExitTwoBeforeAnyFileIsRead) {
  const fs::path d = prt::testing::fresh_dir("cli_messages", "before_work");
  // Inputs that do not exist: a check made after reading them would report them instead (exit 1).
  const fs::path mesh = d / "missing.obj", env = d / "missing.exr", out = d / "out.prt.h5";
  struct Case {
    std::string args, says;
  };
  const Case cases[] = {
      {"vertex " + q(mesh) + " --ao --integrator filter -o " + q(out),
       "prtbake: vertex: --integrator filter needs --samples N, its pass-1 rays per vertex (4-32)"},
      {"vertex " + q(mesh) + " --ao --integrator filter --target-error 1e-3 -o " + q(out),
       "so it cannot take --target-error"},
      {"vertex " + q(mesh) + " --ao --shadowed 3 -o " + q(out), "vertex: --shadowed L needs --radiance ENV"},
      {"vertex " + q(mesh) + " --ao --samples 64 --merge --resume -o " + q(out), "vertex: --merge computes nothing"},
      {"vertex " + q(mesh) + " --ao --samples 64 --shard 0/2 --claim dynamic -o " + q(out),
       "vertex: --claim dynamic with --shard 0/2: give --run-id ID, the same for every worker of this run (try "
       "'prtbake vertex --help')"},
      {"fiv " + q(mesh) + " --env " + q(env) + " --samples 2 -o " + q(out), "fiv: --samples 2: the silhouette"},
      {"scene " + q(kData / "scene_example.json") + " --options " + q(d / "missing.json") + " -o " + q(out),
       "scene: --options " + (d / "missing.json").string() + " applies to a glTF scene (.gltf, .glb) only"},
      {"export " + q(d / "missing.prt.h5") + " --to gltf --env " + q(env) + " -o " + q(d / "x.gltf"),
       "export: --env writes an environment probe: it needs --to unity, godot, filament or web, not gltf"},
  };
  for (const Case& c : cases) {
    const Outcome r = prtbake(d, c.args);
    EXPECT_EQ(r.code, 2) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << c.args << "\n" << r.err;
    EXPECT_EQ(r.err.find("error:"), std::string::npos) << "no input was read: " << r.err;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_EQ(r.out, "") << c.args;
  }
  // With a mesh that exists: nothing is read or printed before the refusal.
  const Outcome real = prtbake(d, "vertex " + q(kData / "bunny.obj") + " --ao --integrator filter -o " + q(out));
  EXPECT_EQ(real.code, 2) << real.err;
  EXPECT_EQ(real.out, "") << "the mesh was read first: " << real.out;
  EXPECT_EQ(prt::testing::listing(d), std::vector<std::string>{});
}

TEST(CliMessages, AScenesFilterIntegratorWithoutSamplesIsRefusedNamingTheFileBeforeAnyMesh) {
  // The scene file's own "bake" settings are input (exit 1): the same mistake as vertex's
  // --integrator filter without --samples, said in the file's terms and found when it is parsed.
  const fs::path d = prt::testing::fresh_dir("cli_messages", "scene_filter");
  std::ofstream(d / "scene.json") << R"({"prtbake_scene": 1, "bake": {"products": ["ao"], "integrator": "filter"},
 "objects": [{"name": "ground", "mesh": ")" << (d / "missing.obj").string() << R"(", "role": "receiver"}]})";
  const Outcome r = prtbake(d, "scene " + q(d / "scene.json") + " -o " + q(d / "s.prt.h5"));
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(r.err, "prtbake: error: " + (d / "scene.json").string() +
                       ": bake.integrator \"filter\" needs bake.samples, its pass-1 rays per vertex (4-32): the "
                       "target-error chooser has no model of the filter integrator\n");
  EXPECT_EQ(r.out, "");
}

TEST(CliMessages, AValueThatIsNotANumberIsCalledSoAndTheOptionNamed) {
  const fs::path d = prt::testing::fresh_dir("cli_messages", "numbers");
  const std::string vertex = "vertex m.obj --ao -o o.prt.h5 ";
  const Outcome samples = prtbake(d, vertex + "--samples abc");
  EXPECT_EQ(samples.code, 2);
  EXPECT_EQ(samples.err, "prtbake: vertex: --samples: 'abc' is not an integer (expects 1 to 16777216) "
                         "(try 'prtbake vertex --help')\n");
  struct Case {
    std::string args, says;
  };
  const Case cases[] = {
      {vertex + "--samples 0", "vertex: --samples: 0 is out of range (expects 1 to 16777216)"},
      {vertex + "--samples 2.5", "vertex: --samples: '2.5' is not an integer"},
      {vertex + "--transfer x", "vertex: --transfer: 'x' is not an integer (expects 1 to "},
      {vertex + "--threads=0", "vertex: --threads: 0 is out of range (expects 1 to 4096)"},
      {vertex + "--seed -3", "vertex: --seed: -3 is out of range (expects an integer >= 0)"},
      {vertex + "--target-error small", "vertex: --target-error: 'small' is not a number (expects 0.0001 to 0.1)"},
      {"fiv m.obj --env e.exr -o o.prt.h5 --fraction 1",
       "fiv: --fraction: 1 is out of range (expects a number strictly between 0 and 1)"},
  };
  for (const Case& c : cases) {
    const Outcome r = prtbake(d, c.args);
    EXPECT_EQ(r.code, 2) << c.args;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << c.args << "\n" << r.err;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
  }
  const Outcome dump = prtdump(d, "--vertex abc f.prt.h5");
  EXPECT_EQ(dump.code, 2);
  EXPECT_NE(dump.err.find("prtdump: --vertex: 'abc' is not an integer"), std::string::npos) << dump.err;
}

TEST(CliMessages, UnknownCommandsAndOptionsGetTheNearestName) {
  const fs::path d = prt::testing::fresh_dir("cli_messages", "unknown");
  struct Case {
    std::string args, err;
  };
  const Case exact[] = {
      {"bake m.obj -o o.prt.h5",
       "prtbake: unknown command 'bake': the commands are vertex, texel, fiv, scene and export (try 'prtbake --help')\n"},
      {"vertx m.obj --ao -o o.prt.h5",
       "prtbake: unknown command 'vertx'; did you mean 'vertex'? (the commands are vertex, texel, fiv, scene and export) "
       "(try 'prtbake --help')\n"},
      {"", "prtbake: no command given (the commands are vertex, texel, fiv, scene and export) (try 'prtbake --help')\n"},
      {"vertex m.obj --ao -o o.prt.h5 --radiancee e.exr",
       "prtbake: vertex: unknown option '--radiancee'; did you mean --radiance? (try 'prtbake vertex --help')\n"},
      {"vertex m.obj --ao -o o.prt.h5 --environment=e.exr",
       "prtbake: vertex: unknown option '--environment'; did you mean --env? (try 'prtbake vertex --help')\n"},
      {"vertex m.obj --ao -o o.prt.h5 --shells 8x5x4",
       "prtbake: vertex: unknown option '--shells' (it is an option of prtbake fiv) (try 'prtbake vertex --help')\n"},
      {"fiv m.obj --env e.exr -o o.prt.h5 --sampels 64",
       "prtbake: fiv: unknown option '--sampels'; did you mean --samples? (try 'prtbake fiv --help')\n"},
      {"export f.prt.h5 -o x.glb --too glb",
       "prtbake: export: unknown option '--too'; did you mean --to? (try 'prtbake export --help')\n"},
      {"vertex m.obj --ao -o o.prt.h5 n.obj", "prtbake: vertex: unexpected argument 'n.obj' (try 'prtbake vertex --help')\n"},
      {"vertex m.obj --ao -o o.prt.h5 --radiance",
       "prtbake: vertex: --radiance needs a value (--radiance ENV) (try 'prtbake vertex --help')\n"},
      {"export f.prt.h5 -o x.json --to untiy",
       "prtbake: export: --to: expects gltf, glb, bin, unity, godot, filament, exr or web, got 'untiy'; did you mean unity? "
       "(try 'prtbake export --help')\n"},
      {"vertex m.obj --ao -o o.prt.h5 --integrator qcm",
       "prtbake: vertex: --integrator: unknown integrator 'qcm'; did you mean qmc? (available: silhouette, qmc, "
       "filter) (try 'prtbake vertex --help')\n"},
  };
  for (const Case& c : exact) {
    const Outcome r = prtbake(d, c.args);
    EXPECT_EQ(r.code, 2) << c.args;
    EXPECT_EQ(r.err, c.err) << c.args;
  }
  const Outcome dump = prtdump(d, "--jsn f.prt.h5");
  EXPECT_EQ(dump.code, 2);
  EXPECT_EQ(dump.err.rfind("prtdump: unknown option '--jsn'; did you mean --json?", 0), 0u) << dump.err;
}

TEST(CliMessages, VertexTakesEnvTheNameEveryOtherCommandGivesTheEnvironment) {
  const fs::path d = prt::testing::fresh_dir("cli_messages", "env");
  const std::string common = "vertex " + q(kData / "ground.obj") +
                             " --ao --integrator qmc --samples 16 --report 0 --reproducible -q ";
  const Outcome env = prtbake(d, common + "--env " + q(kData / "sunset.exr") + " -o " + q(d / "env.prt.h5"));
  ASSERT_EQ(env.code, 0) << env.err;
  const Outcome radiance = prtbake(d, common + "--radiance " + q(kData / "sunset.exr") + " -o " + q(d / "rad.prt.h5"));
  ASSERT_EQ(radiance.code, 0) << radiance.err;
  const F::Asset a = F::read_asset(d / "env.prt.h5"), b = F::read_asset(d / "rad.prt.h5");
  ASSERT_TRUE(a.vertices.radiance_band1.has_value()) << "--env bakes band-1 radiance as --radiance does";
  ASSERT_TRUE(b.vertices.radiance_band1.has_value());
  EXPECT_EQ(a.vertices.radiance_band1->values, b.vertices.radiance_band1->values);
  // One option with two names: giving both is giving it twice.
  const Outcome both = prtbake(d, common + "--env a.exr --radiance b.exr -o " + q(d / "x.prt.h5"));
  EXPECT_EQ(both.code, 2);
  EXPECT_NE(both.err.find("vertex: --radiance or --env given more than once: it takes one value"), std::string::npos)
      << both.err;
  // Its help says so.
  const Outcome help = prtbake(d, "vertex --help");
  EXPECT_NE(help.out.find("--radiance,--env ENV"), std::string::npos) << help.out;
}

TEST(CliMessages, EachCommandsHelpDescribesOnlyWhatItAccepts) {
  const fs::path d = prt::testing::fresh_dir("cli_messages", "help");
  // fiv takes no target error: its help does not offer one (--reproducible's text said it did).
  const Outcome fiv = prtbake(d, "fiv --help");
  ASSERT_EQ(fiv.code, 0);
  for (const char* absent : {"target", "--samples the", "vertices (default"})
    EXPECT_EQ(fiv.out.find(absent), std::string::npos) << absent << " in\n" << fiv.out;
  EXPECT_NE(fiv.out.find("rows per chunk: DifMap texels, or a FIV shell's samples"), std::string::npos) << fiv.out;
  // Each command's examples are its own.
  EXPECT_EQ(fiv.out.find("prtbake vertex "), std::string::npos) << fiv.out;
  const Outcome scene = prtbake(d, "scene --help");
  EXPECT_EQ(scene.out.find("With --samples"), std::string::npos) << "scene has no --samples:\n" << scene.out;
  // The glTF export's attributes: VEC4, the last one shorter when the row needs it.
  const Outcome ex = prtbake(d, "export --help");
  ASSERT_EQ(ex.code, 0);
  EXPECT_EQ(ex.out.find("4 components each"), std::string::npos) << ex.out;
  EXPECT_NE(ex.out.find("the last one SCALAR, VEC2 or VEC3"), std::string::npos) << ex.out;
  // Every tool answers --version.
  const Outcome dump = prtdump(d, "--version");
  EXPECT_EQ(dump.code, 0) << dump.err;
  EXPECT_EQ(dump.out, "prtdump 0.1.0\n");
  const Outcome bake = prtbake(d, "--version");
  EXPECT_EQ(bake.out, "prtbake 0.1.0\n");
}

TEST(CliMessages, ProbeExportOfASceneNamesTheObjectsItLeavesOutAndWhy) {
  const fs::path d = prt::testing::fresh_dir("cli_messages", "probes");
  std::ofstream(d / "scene.json") << R"({
  "prtbake_scene": 1,
  "environment": ")" << (kData / "sunset.exr").string() << R"(",
  "bake": {"products": ["ao", "radiance"], "integrator": "qmc", "samples": 16, "report": 0},
  "objects": [
    {"name": "ground", "mesh": ")" << (kData / "ground.obj").string() << R"(", "role": "receiver",
     "material": {"albedo": [0.6, 0.6, 0.6]}},
    {"name": "spider", "mesh": ")" << (kData / "spider.obj").string() << R"(", "role": "occluder",
     "transform": {"translate": [0, 1.7, 0], "scale": 0.04}}
  ]
})";
  const Outcome bake = prtbake(d, "scene " + q(d / "scene.json") + " -q -o " + q(d / "s.prt.h5"));
  ASSERT_EQ(bake.code, 0) << bake.err;
  const Outcome ex = prtbake(d, "export " + q(d / "s.prt.h5") + " --to unity -o " + q(d / "p.json"));
  ASSERT_EQ(ex.code, 0) << ex.err;
  EXPECT_EQ(ex.err,
            "prtbake: warning: export: no unity probes for spider: no band-1 radiance (the scene's plan left it out: "
            "occluder only (role \"occluder\"): nothing is shaded on it)\n");
  // The glTF export keeps every object: nothing to say.
  const Outcome gltf = prtbake(d, "export " + q(d / "s.prt.h5") + " --to glb -o " + q(d / "s.glb"));
  ASSERT_EQ(gltf.code, 0) << gltf.err;
  EXPECT_EQ(gltf.err, "");
}

namespace {
// The progress lines of a log ("<stage>: NNN% (done/total) rate, T.Ts[, ETA ...]"), per stage in
// order: the seconds each line was printed at.
std::vector<std::pair<std::string, std::vector<double>>> progress_of(const std::string& log) {
  static const std::regex line(R"(^(.+): +(\d+)% \((\d+)/(\d+)\) [^,]*, ([0-9.]+)s(, ETA .*)?$)");
  std::vector<std::pair<std::string, std::vector<double>>> stages;
  for (size_t a = 0, b; (b = log.find('\n', a)) != std::string::npos; a = b + 1) {
    const std::string l = log.substr(a, b - a);
    std::smatch m;
    if (!std::regex_match(l, m, line)) continue;
    const double t = std::atof(m[5].str().c_str());
    // A new stage: another label, or the same label starting again.
    if (stages.empty() || stages.back().first != m[1].str() || t < stages.back().second.back())
      stages.push_back({m[1].str(), {}});
    stages.back().second.push_back(t);
  }
  return stages;
}

// At most a first line, three quarter lines and an end line per stage; lines but the last at
// least 10 s apart; nothing before a stage has run 1 s.
void expect_log_budget(const std::string& log) {
  for (const auto& [stage, times] : progress_of(log)) {
    EXPECT_LE(times.size(), 5u) << stage << " in\n" << log;
    EXPECT_GE(times.front(), 1.0) << stage << ": a line before it ran a second\n" << log;
    for (size_t i = 1; i + 1 < times.size(); ++i)
      EXPECT_GE(times[i] - times[i - 1], 10.0) << stage << ": two lines within 10 s\n" << log;
  }
}
} // namespace

TEST(CliMessages, ALogHoldsAFewProgressLinesPerStage) {
  const fs::path d = prt::testing::fresh_dir("cli_messages", "log");
  // stderr goes to a file: the Lines style. A vertex bake whose stages run for about a second.
  const Outcome v = prtbake(d, "vertex " + q(kData / "bunny_ground.obj") + " --ao --radiance " +
                                   q(kData / "sunset.exr") +
                                   " --integrator qmc --samples 256 --report 16 --threads 2 -o " + q(d / "v.prt.h5"));
  ASSERT_EQ(v.code, 0) << v.err;
  expect_log_budget(v.err);
  // A scene: a stage per object and product, each short: (almost) nothing in the log.
  const Outcome s = prtbake(d, "scene " + q(kData / "scene_example.json") + " --report 4 --threads 2 -o " +
                                   q(d / "s.prt.h5"));
  ASSERT_EQ(s.code, 0) << s.err;
  expect_log_budget(s.err);
  size_t total = 0;
  for (const auto& stage : progress_of(s.err)) total += stage.second.size();
  EXPECT_LE(total, 5 * progress_of(s.err).size());
}

TEST(CliMessages, AResumableBakeReportsTheThreadsItRanOnAndAFewChunkLines) {
  const fs::path d = prt::testing::fresh_dir("cli_messages", "threads");
  const std::string args = "vertex " + q(kData / "bunny.obj") +
                           " --ao --integrator qmc --samples 64 --report 0 --threads 2 --chunk-rows 128 -o " +
                           q(d / "b.prt.h5");
  const Outcome r = prtbake(d, args + " --resume");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("; 2 threads; setup"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" on 2 threads)"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find(" on 1 thread"), std::string::npos) << r.out;
  // 15 chunks in well under 10 s: in a log, the first chunk's line and the last's.
  size_t chunk_lines = 0;
  for (size_t at = 0; (at = r.out.find(" committed: ", at)) != std::string::npos; ++at) ++chunk_lines;
  EXPECT_EQ(chunk_lines, 2u) << r.out;
  EXPECT_NE(r.out.find("committed: 15/15 chunks of all workers"), std::string::npos) << r.out;
}
