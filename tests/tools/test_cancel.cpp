// Ctrl-C in the middle of a bake, end to end: prtbake started as a user would, SIGINT once it has
// started baking; it must stop with exit 130, say so, and leave nothing in the output directory
// but the chunks a --resume bake committed, which it names with the command that resumes
// (tools/common/tool_main.h, bake/core/progress.h, tools/prtbake/shards.h).
#include <gtest/gtest.h>
#include <run_tool.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <unistd.h>
#include <vector>

namespace fs = std::filesystem;

TEST(PrtbakeCancel, CtrlCDuringABakeExits130AndWritesNothing) {
  const fs::path dir = fs::path(PRT_TEST_TMP) / ("cancel." + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path out = dir / "bunny.h5";
  // Ambient occlusion with 65536 QMC rays at each of the bunny-on-ground's vertices: minutes of work on two threads,
  // so the bake is still running when the signal arrives. stderr is a pipe, so progress comes as
  // plain lines; the first ("baking vertices:   N% ...") is printed once the stage has run 1 s.
  const auto start = std::chrono::steady_clock::now();
  prt::testing::BackgroundTool bake(PRT_PRTBAKE, {"vertex", std::string(PRT_DATA_DIR) + "/bunny_ground.obj", "-o",
                                                  out.string(), "--integrator", "qmc", "--samples", "65536", "--ao",
                                                  "--threads", "2"});
  ASSERT_TRUE(bake.started());
  ASSERT_TRUE(bake.wait_for("baking vertices:", std::chrono::seconds(60))) << bake.err();
  bake.send(SIGINT);
  const int code = bake.wait();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(code, 130) << bake.err();
  EXPECT_NE(bake.err().find("prtbake: cancelled; nothing was written\n"), std::string::npos) << bake.err();
  EXPECT_EQ(bake.err().find("100%"), std::string::npos) << "the bake ran to its end:\n" << bake.err();
  // Stopping takes at most the blocks of 16 points in flight (16 × 65536 rays per thread).
  EXPECT_LT(seconds, 30.0);
  for (const auto& e : fs::directory_iterator(dir)) ADD_FAILURE() << "left behind: " << e.path();
  fs::remove_all(dir);
}

// The bake is written before its error check (tools/prtbake: write, then check, then re-write
// with the report): Ctrl-C during the check keeps the finished bake, says so, and exits 130.
TEST(PrtbakeCancel, CtrlCDuringTheErrorCheckKeepsTheBakeWithoutItsReport) {
  const fs::path dir = fs::path(PRT_TEST_TMP) / ("cancel_check." + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path out = dir / "bunny.h5";
  // A fast bake (silhouette, 32 isolines) and a check of minutes: every vertex (4,240) against a
  // 65,536-ray QMC reference, 2.8e8 rays.
  prt::testing::BackgroundTool bake(PRT_PRTBAKE, {"vertex", std::string(PRT_DATA_DIR) + "/bunny_ground.obj", "-o",
                                                  out.string(), "--integrator", "silhouette", "--samples", "1024",
                                                  "--ao", "--report", "4240", "--threads", "2"});
  ASSERT_TRUE(bake.started());
  ASSERT_TRUE(bake.wait_for("checking the error:", std::chrono::seconds(120))) << bake.err();
  bake.send(SIGINT);
  const int code = bake.wait();
  EXPECT_EQ(code, 130) << bake.err();
  EXPECT_NE(bake.err().find("cancelled during the error check: " + out.string() +
                            " holds the finished bake without its error report"),
            std::string::npos)
      << bake.err();
  ASSERT_TRUE(fs::exists(out)) << bake.err();
  // The file is whole: prtdump reads it, and it has AO and no report.
  const auto dump = prt::testing::run_tool(PRT_PRTDUMP, "--json " + out.string(), dir);
  EXPECT_EQ(dump.code, 0) << dump.err;
  EXPECT_NE(dump.out.find("\"path\": \"/ao\""), std::string::npos) << dump.out;
  EXPECT_EQ(dump.out.find("\"path\": \"/report/ao\""), std::string::npos) << dump.out;
  size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    ++files;
    EXPECT_EQ(e.path(), out) << "left behind: " << e.path();
  }
  EXPECT_EQ(files, 1u);
  fs::remove_all(dir);
}

// Ctrl-C during a --resume bake: the chunks committed so far are kept (rightly), and the message
// says so, where, and the command that resumes; that command, run as printed, reuses them.
TEST(PrtbakeCancel, CtrlCOfAResumableBakeKeepsItsChunksAndSaysHowToResume) {
  const fs::path dir = fs::path(PRT_TEST_TMP) / ("cancel_resume." + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path out = dir / "bunny.prt.h5", chunks = dir / "bunny.prt.h5.chunks";
  // 15 chunks of 128 vertices, a fraction of a second each: the first is committed soon, the
  // signal comes well before the last.
  const std::vector<std::string> args = {"vertex", std::string(PRT_DATA_DIR) + "/bunny.obj", "--ao", "--integrator",
                                         "qmc", "--samples", "4096", "--report", "0", "--threads", "2", "--resume",
                                         "--chunk-rows", "128", "-o", out.string()};
  prt::testing::BackgroundTool bake(PRT_PRTBAKE, args);
  ASSERT_TRUE(bake.started());
  const auto committed = [&] {
    size_t n = 0;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(chunks, ec))
      if (e.path().extension() == ".chunk") ++n;
    return n;
  };
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (committed() == 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_GT(committed(), 0u) << bake.err();
  bake.send(SIGINT);
  ASSERT_EQ(bake.wait(), 130) << bake.err();
  const size_t kept = committed();
  ASSERT_GT(kept, 0u);
  ASSERT_LT(kept, 15u) << "the bake ran to its end before the signal";
  EXPECT_FALSE(fs::exists(out));

  // The one line: what is kept, where, and the command, exactly as it was run.
  std::string command = PRT_PRTBAKE;
  for (const std::string& a : args) command += " " + a;  // no argument here needs quoting
  const std::string expected = "prtbake: cancelled; " + std::to_string(kept) + " of 15 chunks are committed (" +
                               std::to_string(kept) + " by this run) and kept in " + chunks.string() +
                               "/; to resume, rerun: " + command + "\n";
  EXPECT_EQ(bake.err(), expected);

  // Running it resumes: the kept chunks are reused, the file is written, the chunks removed.
  const auto resumed = prt::testing::run_tool(PRT_PRTBAKE, command.substr(std::string(PRT_PRTBAKE).size() + 1), dir);
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  EXPECT_NE(resumed.out.find(std::to_string(kept) + " committed before this run (reused)"), std::string::npos)
      << resumed.out;
  // Its chunks were computed by two runs: the threads of the first are not known, so none is claimed.
  EXPECT_NE(resumed.out.find("summed over the chunks of every worker and run"), std::string::npos) << resumed.out;
  EXPECT_EQ(resumed.out.find(" on 1 thread"), std::string::npos) << resumed.out;
  EXPECT_TRUE(fs::exists(out));
  EXPECT_FALSE(fs::exists(chunks));
  fs::remove_all(dir);
}

// The same for a scene: the file is written once the bake is whole, before its error reports.
TEST(PrtbakeCancel, CtrlCDuringASceneErrorCheckKeepsTheBakeWithoutItsReports) {
  const fs::path dir = fs::path(PRT_TEST_TMP) / ("cancel_scene_check." + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path out = dir / "scene.prt.h5", scene = dir / "scene.json";
  // A fast bake (16 isolines) and a check of minutes (every vertex, 65,536-ray references).
  {
    std::ofstream f(scene);
    f << R"({"prtbake_scene": 1, "bake": {"products": ["ao"], "integrator": "silhouette", "samples": 1024, "report": 4240},
      "objects": [{"name": "bunny", "mesh": ")"
      << std::string(PRT_DATA_DIR) + "/bunny_ground.obj" << R"(", "role": "both"}]})";
  }
  prt::testing::BackgroundTool bake(PRT_PRTBAKE, {"scene", scene.string(), "-o", out.string(), "--threads", "2"});
  ASSERT_TRUE(bake.started());
  ASSERT_TRUE(bake.wait_for("checking the error:", std::chrono::seconds(120))) << bake.err();
  bake.send(SIGINT);
  EXPECT_EQ(bake.wait(), 130) << bake.err();
  EXPECT_NE(bake.err().find("cancelled during the error check: " + out.string() +
                            " holds the finished bake without its error reports"),
            std::string::npos)
      << bake.err();
  ASSERT_TRUE(fs::exists(out)) << bake.err();
  const auto dump = prt::testing::run_tool(PRT_PRTDUMP, "--json " + out.string(), dir);
  EXPECT_EQ(dump.code, 0) << dump.err;
  EXPECT_NE(dump.out.find("\"path\": \"/objects/bunny/ao\""), std::string::npos) << dump.out;
  EXPECT_EQ(dump.out.find("\"path\": \"/report/objects/bunny/ao\""), std::string::npos) << dump.out;
  fs::remove_all(dir);
}
