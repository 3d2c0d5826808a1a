// Writes that meet a full disk: prtbake gives one line naming the file and the cause, exit 1, no
// crash, nothing left under the final name or as a temporary (formats/prtfile.h writer contract).
// The disk is a 64 KiB tmpfs mounted by the test, which needs root (CAP_SYS_ADMIN); elsewhere the
// test is skipped and says why.
#include <gtest/gtest.h>
#include <run_tool.h>

#include <sys/mount.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string>

namespace fs = std::filesystem;

namespace {

struct SmallDisk {
  fs::path dir;
  std::string why_not;  // empty when mounted
  explicit SmallDisk(const fs::path& where) : dir(where) {
    fs::remove_all(dir);
    fs::create_directories(dir);
    if (::geteuid() != 0) {
      why_not = "not root: a tmpfs cannot be mounted";
    } else if (::mount("tmpfs", dir.c_str(), "tmpfs", 0, "size=64k") != 0) {
      why_not = std::string("mount tmpfs failed: ") + std::strerror(errno);
    }
  }
  ~SmallDisk() {
    if (why_not.empty()) ::umount(dir.c_str());
  }
  SmallDisk(const SmallDisk&) = delete;
  SmallDisk& operator=(const SmallDisk&) = delete;
};

} // namespace

TEST(Faults, FullDiskIsOneLineExitOneAndLeavesNothing) {
  const fs::path work = fs::path(PRT_TEST_TMP) / "faults";
  fs::create_directories(work);
  const SmallDisk disk(work / "disk");
  if (!disk.why_not.empty()) GTEST_SKIP() << disk.why_not;
  // bunny with order-3 transfer: about 200 KiB compressed, three times the disk.
  const std::string mesh = std::string(PRT_DATA_DIR) + "/bunny.obj";
  for (int run = 0; run < 3; ++run) {  // a crash after the message was intermittent (5 runs in 6)
    SCOPED_TRACE(run);
    const auto r = prt::testing::run_tool(PRT_PRTBAKE,
                                          "vertex '" + mesh + "' --ao --transfer 3 --samples 256 --report 0 -q -o '" +
                                              (disk.dir / "b.prt.h5").string() + "'",
                                          work);
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_EQ(r.err.rfind("prtbake: error: " + (disk.dir / "b.prt.h5").string() + ": ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find("No space left on device"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_TRUE(fs::is_empty(disk.dir)) << "no file and no temporary may remain";
  }
}
