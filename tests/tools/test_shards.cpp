// Sharded and resumable bakes (tools/prtbake/shards.h): every launcher's file is cmp-identical to
// the single-process --reproducible bake; kill -9 and rerun resumes; bad chunks are refused.
// The mpirun cases are compiled when prtbake is linked with MPI (CMake PRT_MPI; ON in the ci
// preset), and then fail — not skip — if mpirun cannot run.
#include "run_tool.h"

#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <unistd.h>
#include <vector>

namespace fs = std::filesystem;
using prt::testing::read_bytes;
using prt::testing::run_tool;

namespace {

const std::string kData = PRT_DATA_DIR;
// All four products of bunny_ground (4240 vertices) at few samples, one thread per process;
// chunks of 512 rows: 9 chunks.
std::string products(const std::string& integrator) {
  return "vertex " + kData + "/bunny_ground.obj --ao --transfer 3 --visibility 3 --radiance " + kData +
         "/sunset.exr --integrator " + integrator + " --samples 64 --threads 1 --chunk-rows 512";
}
constexpr size_t kChunks = 9;

fs::path dir_for(const std::string& name) {
  const fs::path d = fs::path(PRT_TEST_TMP) / ("shards_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

prt::testing::ToolRun prtbake(const std::string& args, const fs::path& dir, const std::string& env = "") {
  return run_tool(PRT_PRTBAKE, args, dir / "capture", env);
}

// The single-process --reproducible bake of `args` written to `out` (the command line stored in
// the file names the output, so every variant writes the same name), moved to OUT.ref.
std::string reference(const std::string& args, const fs::path& out) {
  const auto r = prtbake(args + " --reproducible -q -o " + out.string(), out.parent_path());
  EXPECT_EQ(r.code, 0) << r.err;
  const std::string bytes = read_bytes(out);
  fs::remove(out);
  EXPECT_FALSE(bytes.empty());
  return bytes;
}

// Files left next to the output besides it and the capture directory (temporaries, chunks).
std::vector<std::string> leftovers(const fs::path& dir, const fs::path& out) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path() != out && e.path().filename() != "capture") names.push_back(e.path().filename().string());
  return names;
}

size_t committed_chunks(const fs::path& chunks) {
  size_t n = 0;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(chunks, ec)) n += e.path().extension() == ".chunk" ? 1 : 0;
  return n;
}

// "N committed before this run (reused), M to compute" and "computed K chunks" from stdout.
struct Resumed {
  int reused = -1, to_compute = -1, computed = -1;
};
Resumed resumed_of(const std::string& out) {
  Resumed r;
  std::smatch m;
  if (std::regex_search(out, m, std::regex(R"((\d+) committed before this run \(reused\), (\d+) to compute)")))
    r.reused = std::stoi(m[1]), r.to_compute = std::stoi(m[2]);
  if (std::regex_search(out, m, std::regex(R"(computed (\d+) chunks)"))) r.computed = std::stoi(m[1]);
  return r;
}

void flip_byte(const fs::path& p, size_t at) {
  std::fstream f(p, std::ios::in | std::ios::out | std::ios::binary);
  f.seekg(std::streamoff(at));
  char c = 0;
  f.read(&c, 1);
  c = char(c ^ 0x10);
  f.seekp(std::streamoff(at));
  f.write(&c, 1);
}

// The one stderr line of a failed merge, and that nothing was written.
void expect_refused(const prt::testing::ToolRun& r, const fs::path& out, const std::string& names, const std::string& says) {
  EXPECT_EQ(r.code, 1) << r.out << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(names), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

} // namespace

TEST(Shards, ResumeFlagAloneGivesTheReproducibleBytes) {
  const fs::path dir = dir_for("resume"), out = dir / "out.prt.h5";
  const std::string ref = reference(products("qmc"), out);
  const auto r = prtbake(products("qmc") + " --resume -o " + out.string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(read_bytes(out) == ref);
  EXPECT_EQ(resumed_of(r.out).computed, int(kChunks));
  EXPECT_TRUE(leftovers(dir, out).empty());  // OUT.chunks/ removed after the merge
}

// --shard I/N workers (here one after another, as a scheduler may run them) and a --merge step;
// static and dynamic claiming; a SLURM array's variables with --shard auto.
TEST(Shards, ShardWorkersThenMerge) {
  const fs::path dir = dir_for("shard_merge"), out = dir / "out.prt.h5";
  const std::string ref = reference(products("silhouette"), out);
  // Static: three separate workers, each its own chunks.
  for (int i = 0; i < 3; ++i) {
    const auto w = prtbake(products("silhouette") + " --shard " + std::to_string(i) + "/3 -o " + out.string(), dir);
    ASSERT_EQ(w.code, 0) << w.err;
    EXPECT_EQ(resumed_of(w.out).computed, 3) << w.out;
    EXPECT_FALSE(fs::exists(out));  // workers never write the file
  }
  auto m = prtbake(products("silhouette") + " --merge -o " + out.string(), dir);
  ASSERT_EQ(m.code, 0) << m.err;
  EXPECT_TRUE(read_bytes(out) == ref) << "static --shard I/3 + --merge";
  EXPECT_TRUE(leftovers(dir, out).empty());
  fs::remove(out);

  // Dynamic: two workers at once claim chunks through claim files; together they do each once.
  const std::string worker = std::string("'") + PRT_PRTBAKE + "' " + products("silhouette") + " -o " + out.string();
  const std::string both = "(" + worker + " --shard 0/2 --claim dynamic --run-id t1 > " + (dir / "w0").string() +
                           " & " + worker + " --shard 1/2 --claim dynamic --run-id t1 > " + (dir / "w1").string() +
                           " & wait) 2>&1";
  ASSERT_EQ(std::system(both.c_str()), 0);
  const int c0 = resumed_of(read_bytes(dir / "w0")).computed, c1 = resumed_of(read_bytes(dir / "w1")).computed;
  EXPECT_EQ(c0 + c1, int(kChunks)) << c0 << " + " << c1;
  fs::remove(dir / "w0"), fs::remove(dir / "w1");
  m = prtbake(products("silhouette") + " --merge -o " + out.string(), dir);
  ASSERT_EQ(m.code, 0) << m.err;
  EXPECT_TRUE(read_bytes(out) == ref) << "dynamic --shard I/2 + --merge";
  fs::remove(out);

  // A SLURM array (--array=5-7): tasks 5, 6, 7 of 3 with --shard auto.
  for (int id = 5; id <= 7; ++id) {
    const auto w = prtbake(products("silhouette") + " --shard auto -o " + out.string(), dir,
                           "SLURM_ARRAY_JOB_ID=42 SLURM_ARRAY_TASK_MIN=5 SLURM_ARRAY_TASK_COUNT=3 SLURM_ARRAY_TASK_ID=" +
                               std::to_string(id));
    ASSERT_EQ(w.code, 0) << w.err;
    EXPECT_NE(w.out.find("SLURM array task " + std::to_string(id)), std::string::npos) << w.out;
  }
  m = prtbake(products("silhouette") + " --merge -o " + out.string(), dir);
  ASSERT_EQ(m.code, 0) << m.err;
  EXPECT_TRUE(read_bytes(out) == ref) << "SLURM array + --merge";
  EXPECT_TRUE(leftovers(dir, out).empty());
}

// The filter integrator (paper 002) shares rays between neighbouring rows, across chunk borders:
// each row's pass-1 rays are a function of (seed, row), so workers that each trace their
// neighbours' rays again give the single-process bytes.
TEST(Shards, FilterIntegratorAcrossChunkBorders) {
  const fs::path dir = dir_for("filter"), out = dir / "out.prt.h5";
  const std::string args = "vertex " + kData + "/bunny_ground.obj --ao --transfer 3 --integrator filter --samples 8 "
                           "--threads 1 --chunk-rows 512 --report 4";
  const std::string ref = reference(args, out);
  for (int i = 0; i < 2; ++i) {
    const auto w = prtbake(args + " --shard " + std::to_string(i) + "/2 -o " + out.string(), dir);
    ASSERT_EQ(w.code, 0) << w.err;
  }
  const auto m = prtbake(args + " --merge -o " + out.string(), dir);
  ASSERT_EQ(m.code, 0) << m.err;
  EXPECT_TRUE(read_bytes(out) == ref) << "--integrator filter, --shard I/2 + --merge";
  EXPECT_TRUE(leftovers(dir, out).empty());
}

// prtbake texel: the valid texels' rows go through the same chunks. bunny_ground in its own UVs
// at 96 x 96 with AO and order-3 transfer (chunks of 512 texels): --resume, --shard I/2 +
// --merge and the filter integrator (its neighbours are texels, across chunk borders) give the
// single-process --reproducible bytes; chunks of another atlas (another --resolution) are refused.
std::string texels(const std::string& integrator, int resolution = 96) {
  return "texel " + kData + "/bunny_ground.obj --ao --transfer 3 --resolution " + std::to_string(resolution) +
         " --integrator " + integrator + " --samples " + (integrator == "filter" ? "8" : "64") +
         " --threads 1 --chunk-rows 512 --report 4";
}

TEST(ShardsTexel, ResumeAndWorkersGiveTheReproducibleBytes) {
  const fs::path dir = dir_for("texel"), out = dir / "out.prt.h5";
  for (const std::string integrator : {"silhouette", "filter"}) {
    const std::string ref = reference(texels(integrator), out);
    const auto r = prtbake(texels(integrator) + " --resume -o " + out.string(), dir);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(read_bytes(out) == ref) << integrator << ", --resume";
    EXPECT_GT(resumed_of(r.out).computed, 2) << r.out;
    EXPECT_TRUE(leftovers(dir, out).empty());
    fs::remove(out);
    for (int i = 0; i < 2; ++i) {
      const auto w = prtbake(texels(integrator) + " --shard " + std::to_string(i) + "/2 -o " + out.string(), dir);
      ASSERT_EQ(w.code, 0) << w.err;
      EXPECT_NE(w.out.find("texels"), std::string::npos) << w.out;
      EXPECT_FALSE(fs::exists(out));
    }
    const auto m = prtbake(texels(integrator) + " --merge -o " + out.string(), dir);
    ASSERT_EQ(m.code, 0) << m.err;
    EXPECT_TRUE(read_bytes(out) == ref) << integrator << ", --shard I/2 + --merge";
    EXPECT_TRUE(leftovers(dir, out).empty());
    fs::remove(out);
  }
  // A worker's chunks of a 96 x 96 atlas, then a merge of a 64 x 64 one: refused, nothing written.
  ASSERT_EQ(prtbake(texels("silhouette") + " --shard 0/1 -o " + out.string(), dir).code, 0);
  const auto m = prtbake(texels("silhouette", 64) + " --merge -o " + out.string(), dir);
  EXPECT_EQ(m.code, 1) << m.out << m.err;
  EXPECT_NE(m.err.find("another bake"), std::string::npos) << m.err;
  EXPECT_FALSE(fs::exists(out));
}

namespace {
// Chunk `name` of the bake `args` (which writes dir/out.prt.h5; its chunks committed in
// dir/out.prt.h5.chunks, another bake's in dir/other) flipped, then replaced by the other bake's,
// then removed: each refused by the merge in one line naming it, nothing written. A rerun of the
// worker then recomputes exactly that chunk, and the merge gives `ref`.
void expect_bad_chunk_refused(const std::string& args, const fs::path& dir, const std::string& name, const std::string& ref) {
  const fs::path out = dir / "out.prt.h5", chunk = dir / "out.prt.h5.chunks" / name;
  flip_byte(chunk, fs::file_size(chunk) / 2);
  expect_refused(prtbake(args + " --merge", dir), out, name, "corrupt");
  // A worker refuses it too, before computing anything.
  expect_refused(prtbake(args + " --shard 0/1", dir), out, name, "corrupt");

  fs::copy_file(dir / "other" / name, chunk, fs::copy_options::overwrite_existing);
  expect_refused(prtbake(args + " --merge", dir), out, name, "another bake");

  fs::remove(chunk);
  expect_refused(prtbake(args + " --merge", dir), out, name, "missing");

  const auto w = prtbake(args + " --shard 0/1", dir);
  ASSERT_EQ(w.code, 0) << w.err;
  EXPECT_EQ(resumed_of(w.out).computed, 1) << w.out;
  ASSERT_EQ(prtbake(args + " --merge", dir).code, 0);
  EXPECT_TRUE(read_bytes(out) == ref);
}
} // namespace

// A flipped byte, a chunk of another bake, a missing chunk: one line naming it, exit 1, no file.
TEST(Shards, MergeRefusesBadChunks) {
  const fs::path dir = dir_for("refuse"), out = dir / "out.prt.h5", chunks = dir / "out.prt.h5.chunks";
  const std::string ref = reference(products("qmc"), out);
  const std::string args = products("qmc") + " -o " + out.string();
  ASSERT_EQ(prtbake(args + " --shard 0/1", dir).code, 0);
  ASSERT_EQ(committed_chunks(chunks), kChunks);
  // Another bake's chunks (another seed) in a directory of their own.
  ASSERT_EQ(prtbake(args + " --seed 7 --shard 0/1 --chunks " + (dir / "other").string(), dir).code, 0);
  expect_bad_chunk_refused(args, dir, "c000002.chunk", ref);
}

namespace {
// kill -9 at random moments of `bake` --resume (at least 5 kills), then the same command again:
// the bytes of `bake` --reproducible, only the chunks that were not committed recomputed (the
// bake needs `needed` chunks), no temporary left.
void kill_nine_and_rerun(const std::string& bake, const fs::path& dir, int needed) {
  const fs::path out = dir / "out.prt.h5", chunks = dir / "out.prt.h5.chunks";
  const std::string args = bake + " --resume";
  const auto t0 = std::chrono::steady_clock::now();
  const std::string ref = reference(bake, out);
  const double full = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::mt19937 rng(std::random_device{}());
  std::uniform_real_distribution<double> moment(0.1 * full, 0.9 * full);
  std::vector<std::string> argv;
  {
    std::istringstream words(args + " -o " + out.string());
    for (std::string w; words >> w;) argv.push_back(w);
  }
  int kills = 0;
  std::string moments;  // for the messages
  for (int trial = 0; trial < 12 && kills < 6; ++trial) {
    // Two kills in a row (the second one of a resumed run), then a run to the end.
    for (int k = 0; k < 2; ++k) {
      prt::testing::BackgroundTool tool(PRT_PRTBAKE, argv);
      ASSERT_TRUE(tool.started());
      const double at = moment(rng);
      std::this_thread::sleep_for(std::chrono::duration<double>(at));
      tool.send(SIGKILL);
      const bool killed = tool.wait() == -1;
      kills += killed ? 1 : 0;
      moments += (killed ? " killed at " : " finished before ") + std::to_string(at) + " s;";
    }
    SCOPED_TRACE("trial " + std::to_string(trial) + " of a " + std::to_string(full) + " s bake:" + moments);
    const size_t committed = committed_chunks(chunks);
    if (fs::exists(out)) {  // the second run finished before its kill: start the next trial afresh
      fs::remove(out);
      continue;
    }
    const auto r = prtbake(args + " -o " + out.string(), dir);
    ASSERT_EQ(r.code, 0) << r.err;
    const Resumed re = resumed_of(r.out);
    EXPECT_EQ(re.reused, int(committed)) << r.out;
    EXPECT_EQ(re.computed, needed - int(committed)) << r.out;  // recomputed: only the uncommitted chunks
    EXPECT_TRUE(read_bytes(out) == ref);
    EXPECT_TRUE(leftovers(dir, out).empty()) << "stray files after the resumed bake";
    fs::remove(out);
  }
  EXPECT_GE(kills, 5);
}
} // namespace

// kill -9 at random moments, then the same command again: the same bytes, only the chunks that
// were not committed recomputed, no temporary left.
TEST(Shards, KillNineAndRerunResumes) {
  // More samples and smaller chunks than above: a bake of ~1-2 s in 17 chunks, room to land kills.
  kill_nine_and_rerun("vertex " + kData + "/bunny_ground.obj --ao --transfer 3 --visibility 3 --radiance " + kData +
                          "/sunset.exr --integrator qmc --samples 256 --threads 1 --chunk-rows 256",
                      dir_for("kill"), 17);
}

// ---- FIV bakes: each shell's samples cut into slabs; the shells stop where the rule says ----

namespace {
// An occluder much smaller than its bounding sphere, so that the stopping rule ends the shells
// well before the last radius: the spider scaled by 1/1000 (radius ~0.12) and a 0.01-sized
// triangle 2 away. Written once (temporary name and rename: test processes run in parallel).
std::string speck_mesh() {
  const fs::path dir = fs::path(PRT_TEST_TMP) / "shards_fiv_mesh", path = dir / "spider_and_speck.obj";
  if (fs::exists(path)) return path.string();
  fs::create_directories(dir);
  std::istringstream in(read_bytes(kData + "/spider.obj"));
  std::ostringstream out;
  out.precision(9);
  size_t vertices = 0;
  for (std::string line; std::getline(in, line);) {
    std::istringstream words(line);
    std::string tag;
    words >> tag;
    if (tag == "v") {
      double x = 0, y = 0, z = 0;
      words >> x >> y >> z;
      out << "v " << 1e-3 * x << " " << 1e-3 * y << " " << 1e-3 * z << "\n";
      ++vertices;
    } else if (tag == "f") {
      out << "f";
      for (std::string corner; words >> corner;) out << " " << corner.substr(0, corner.find('/'));
      out << "\n";
    }
  }
  out << "v 2 0 0\nv 2.01 0 0\nv 2 0.01 0\nf " << vertices + 1 << " " << vertices + 2 << " " << vertices + 3 << "\n";
  const fs::path temp = path.string() + ".tmp." + std::to_string(::getpid());
  std::ofstream(temp) << out.str();
  fs::rename(temp, path);
  return path.string();
}

// That occluder under studio.exr: the 2x2x6 DifMap's 24 texels in one chunk, the environment FIV
// in one, then 24x13 = 312 samples per shell in slabs of 80 (4 chunks a shell); the rule ends the
// bake at shell kFivShells of 16 (shells that follow the surface, the default: offsets from 0.005 R,
// so more of them lie near the occluder than paper 004's spheres from 0.5 R, which stopped at 7).
// An error report of `report` points (a merge without one reads
// the environment's identity only, not its pixels).
std::string fiv_bake(int samples = 256, int report = 4) {
  return "fiv " + speck_mesh() + " --env " + kData + "/studio.exr --shells 24x13x16 --fraction 0.01 --cube 2 --samples " +
         std::to_string(samples) + " --threads 1 --chunk-rows 80 --report " + std::to_string(report);
}
constexpr int kFivShells = 13;
constexpr int kFivChunks = 2 + 4 * kFivShells;

// The shells a FIV bake printed it used ("shells: 24x13xK (of 16 ...").
int shells_used(const std::string& out) {
  std::smatch m;
  return std::regex_search(out, m, std::regex(R"(shells: \d+x\d+x(\d+) \(of)")) ? std::stoi(m[1]) : -1;
}
} // namespace

TEST(ShardsFiv, ResumeShardWorkersAndMergeGiveTheSingleProcessBytes) {
  const fs::path dir = dir_for("fiv"), out = dir / "out.prt.h5";
  const auto single = prtbake(fiv_bake() + " --reproducible -o " + out.string(), dir);
  ASSERT_EQ(single.code, 0) << single.err;
  ASSERT_EQ(shells_used(single.out), kFivShells) << single.out;  // the rule stops it before the last radius
  const std::string ref = read_bytes(out);
  fs::remove(out);

  const auto r = prtbake(fiv_bake() + " --resume -o " + out.string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(read_bytes(out) == ref) << "--resume";
  EXPECT_EQ(resumed_of(r.out).computed, kFivChunks) << r.out;  // one process stops where the rule does
  EXPECT_EQ(shells_used(r.out), kFivShells) << r.out;
  EXPECT_TRUE(leftovers(dir, out).empty());
  fs::remove(out);

  // Static: three workers one after another (the first cannot see the others' shells, so it
  // computes its chunks of every shell); the merge ignores the shells past the rule's.
  for (int i = 0; i < 3; ++i) {
    const auto w = prtbake(fiv_bake() + " --shard " + std::to_string(i) + "/3 -o " + out.string(), dir);
    ASSERT_EQ(w.code, 0) << w.err;
    EXPECT_FALSE(fs::exists(out));
  }
  auto m = prtbake(fiv_bake() + " --merge -o " + out.string(), dir);
  ASSERT_EQ(m.code, 0) << m.err;
  EXPECT_TRUE(read_bytes(out) == ref) << "static --shard I/3 + --merge";
  EXPECT_TRUE(leftovers(dir, out).empty());
  fs::remove(out);

  // Dynamic: two workers at once; together they compute every needed chunk once. Past the last
  // shell a worker that runs ahead computes chunks until that shell is complete (shards.h): about
  // one chunk each when they keep pace, but more when one is descheduled (seen: 8 + 25 = 33 on
  // a loaded 2-core machine), so the bound that holds is the claims': no chunk twice, at most
  // every chunk of the 16 shells.
  const std::string worker = std::string("'") + PRT_PRTBAKE + "' " + fiv_bake() + " -o " + out.string();
  const std::string both = "(" + worker + " --shard 0/2 --claim dynamic --run-id f1 > " + (dir / "w0").string() +
                           " & " + worker + " --shard 1/2 --claim dynamic --run-id f1 > " + (dir / "w1").string() +
                           " & wait) 2>&1";
  ASSERT_EQ(std::system(both.c_str()), 0);
  const int c0 = resumed_of(read_bytes(dir / "w0")).computed, c1 = resumed_of(read_bytes(dir / "w1")).computed;
  EXPECT_GE(c0 + c1, kFivChunks) << c0 << " + " << c1;
  EXPECT_LE(c0 + c1, 2 + 4 * 16) << c0 << " + " << c1;
  fs::remove(dir / "w0"), fs::remove(dir / "w1");
  m = prtbake(fiv_bake() + " --merge -o " + out.string(), dir);
  ASSERT_EQ(m.code, 0) << m.err;
  EXPECT_TRUE(read_bytes(out) == ref) << "dynamic --shard I/2 + --merge";
  EXPECT_TRUE(leftovers(dir, out).empty());
}

namespace {
// expect_bad_chunk_refused on chunk `name` of fiv_bake(256, report), committed by one worker in
// dir_for(`test`).
void expect_bad_fiv_chunk_refused(const std::string& test, const std::string& name, int report) {
  const fs::path dir = dir_for(test), out = dir / "out.prt.h5", chunks = dir / "out.prt.h5.chunks";
  const std::string ref = reference(fiv_bake(256, report), out);
  const std::string args = fiv_bake(256, report) + " -o " + out.string();
  ASSERT_EQ(prtbake(args + " --shard 0/1", dir).code, 0);
  ASSERT_EQ(committed_chunks(chunks), size_t(kFivChunks));
  // Another bake's chunks (another k) in a directory of their own.
  ASSERT_EQ(prtbake(fiv_bake(144, report) + " -o " + out.string() + " --shard 0/1 --chunks " + (dir / "other").string(), dir).code,
            0);
  expect_bad_chunk_refused(args, dir, name, ref);
}
} // namespace

// A flipped byte, a chunk of another bake, a missing chunk of a used shell: one line naming it,
// exit 1, no file.
TEST(ShardsFiv, MergeRefusesBadChunks) {
  expect_bad_fiv_chunk_refused("fiv_refuse", "c000006.chunk", 4);  // shell 1's first slab
}

// The environment FIV is a chunk of its own, computed by a worker: flipped, foreign or missing it
// is refused like any other, and recomputed alone it gives the same bytes. Without an error
// report, the merge reads no pixels of the environment.
TEST(ShardsFiv, EnvironmentFivChunkIsVerifiedAndRecomputed) {
  expect_bad_fiv_chunk_refused("fiv_environment", "c000001.chunk", 0);
}

// A longer FIV bake (40x21 samples, 12 of 16 shells, k = 1024; 4 chunks a shell, 1 for the DifMap,
// 1 for the environment FIV). (13 shells before studio.exr's hot texels were integrated exactly:
// the stopping rule's count depends on the baked values.)
TEST(ShardsFiv, KillNineAndRerunResumes) {
  kill_nine_and_rerun("fiv " + speck_mesh() + " --env " + kData + "/studio.exr --shells 40x21x16 --fraction 0.01 --cube 2 "
                      "--samples 1024 --threads 1 --chunk-rows 210 --report 0",
                      dir_for("fiv_kill"), 2 + 4 * 15);  // 15 of the 16 surface-following shells, 4 chunks each
}

#ifdef PRT_MPIRUN
namespace {
// `mpirun -n N prtbake ARGS --claim CLAIM -o OUT` in `dir`: its bytes equal `ref`, every rank
// said it was a worker, nothing left next to the file.
void expect_mpirun_bytes(const std::string& args, const std::string& ref, int n, const std::string& claim,
                         const fs::path& dir) {
  const fs::path out = dir / "out.prt.h5";
  const std::string cmd = std::string("OMPI_MCA_btl_vader_single_copy_mechanism=none '") + PRT_MPIRUN +
                          "' --allow-run-as-root --oversubscribe -n " + std::to_string(n) + " '" + PRT_PRTBAKE + "' " +
                          args + " --claim " + claim + " -o " + out.string() + " > " + (dir / "log").string() + " 2>&1";
  const int status = std::system(cmd.c_str());
  const std::string log = read_bytes(dir / "log");
  ASSERT_EQ(status, 0) << cmd << "\n" << log;
  EXPECT_TRUE(read_bytes(out) == ref) << args << ", mpirun -n " << n << ", " << claim << " claiming\n" << log;
  for (int r = 0; r < n; ++r)
    EXPECT_NE(log.find("worker " + std::to_string(r) + "/" + std::to_string(n) + " (mpirun rank"), std::string::npos)
        << log;
  fs::remove(out);
  fs::remove(dir / "log");
  EXPECT_TRUE(leftovers(dir, out).empty());
}
} // namespace

// mpirun -n 1..4, both integrators, static and dynamic claiming: cmp-identical to the
// single-process --reproducible bake.
TEST(Shards, MpirunMatrixIsByteIdentical) {
  const fs::path dir = dir_for("mpirun"), out = dir / "out.prt.h5";
  for (const std::string integrator : {"qmc", "silhouette"}) {
    const std::string ref = reference(products(integrator), out);
    for (int n = 1; n <= 4; ++n)
      for (const std::string claim : {"static", "dynamic"}) expect_mpirun_bytes(products(integrator), ref, n, claim, dir);
  }
}

// scene_example.json (three receivers, FIV shells, reports): the receivers' rows sharded under
// mpirun -n 2 (static claiming) and -n 4 (dynamic); the vertex matrix above covers 1-4 each way.
// A FIV bake under mpirun -n 1..4, static and dynamic claiming.
TEST(ShardsFiv, MpirunMatrixIsByteIdentical) {
  const fs::path dir = dir_for("fiv_mpirun");
  const std::string ref = reference(fiv_bake(), dir / "out.prt.h5");
  for (int n = 1; n <= 4; ++n)
    for (const std::string claim : {"static", "dynamic"}) expect_mpirun_bytes(fiv_bake(), ref, n, claim, dir);
}

TEST(ShardsTexel, MpirunIsByteIdentical) {
  const fs::path dir = dir_for("mpirun_texel"), out = dir / "out.prt.h5";
  const std::string ref = reference(texels("silhouette"), out);
  for (const int n : {2, 3}) expect_mpirun_bytes(texels("silhouette"), ref, n, n == 2 ? "static" : "dynamic", dir);
}

TEST(Shards, MpirunSceneIsByteIdentical) {
  const fs::path dir = dir_for("mpirun_scene"), out = dir / "out.prt.h5";
  const std::string args = "scene " + kData + "/scene_example.json --report 4 --threads 1 --chunk-rows 400";
  const std::string ref = reference(args, out);
  for (const int n : {2, 4}) expect_mpirun_bytes(args, ref, n, n == 2 ? "static" : "dynamic", dir);
}
#endif
