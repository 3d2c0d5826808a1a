// Running out of memory while reading an input (a mesh, an environment map, a scene file) is a
// SystemError naming the file ("<file>: out of memory while reading the file"; bake/core/error.h
// reading_file), never a bare std::bad_alloc. Each case runs in a forked child whose address space
// is limited (RLIMIT_AS) to what it already uses plus a headroom smaller than the input needs.
// The parent never starts a thread pool before forking (a child of a process with TBB workers
// could deadlock) and writes its inputs as streams (freed heap it kept mapped would be room for
// the child), so this file is its own executable.
#include <bake/bake/scene.h>
#include <bake/core/error.h>
#include <bake/environment/envmap.h>
#include <bake/mesh/mesh.h>

#include <mesh_files.h>

#include <gtest/gtest.h>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

namespace fs = std::filesystem;

namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif
#else
constexpr bool kSanitized = false;
#endif

// The child's verdict on `read`: 0 = a SystemError naming `file` and "out of memory", 1 = another
// exception, 2 = no exception (the headroom was enough), 3 = setrlimit failed; what() on stderr.
int read_with_headroom(const fs::path& file, size_t headroom, const std::function<void()>& read) {
  std::fflush(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    long pages = 0;
    if (std::FILE* f = std::fopen("/proc/self/statm", "r")) {
      if (std::fscanf(f, "%ld", &pages) != 1) pages = 0;
      std::fclose(f);
    }
    const rlim_t limit = static_cast<rlim_t>(pages) * static_cast<rlim_t>(sysconf(_SC_PAGESIZE)) + headroom;
    const rlimit r{limit, limit};
    if (pages == 0 || setrlimit(RLIMIT_AS, &r) != 0) _exit(3);
    try {
      read();
    } catch (const prt::bake::SystemError& e) {
      const std::string what = e.what();
      std::fprintf(stderr, "child: SystemError: %s\n", e.what());
      _exit(what == file.string() + ": out of memory while reading the file" ? 0 : 1);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "child: other exception: %s\n", e.what());
      _exit(1);
    }
    _exit(2);
  }
  int status = 0;
  if (pid < 0 || waitpid(pid, &status, 0) != pid) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// 16 MiB beyond what the process maps: room for a reader's small allocations, not for the inputs
// below, which need 100 MB or more.
constexpr size_t kHeadroom = size_t{16} << 20;

TEST(InputMemory, MeshReadOutOfMemoryNamesTheFile) {
  if (kSanitized) GTEST_SKIP() << "the sanitizers' shadow memory does not fit an address-space limit";
  // 4 M vertices, 32 MB of text: 96 MB of positions in double (and more while the vector grows).
  const fs::path p = prt::testing::test_dir("input_memory") / "large.obj";
  {
    std::ofstream out(p);
    for (int i = 0; i < 4'000'000; ++i) out << "v 0 0 0\n";
    out << "f 1 2 3\n";
  }
  EXPECT_EQ(read_with_headroom(p, kHeadroom + (size_t{32} << 20), [&] { prt::bake::load_mesh(p); }), 0);
  EXPECT_EQ(read_with_headroom(p, size_t{1} << 30, [&] { prt::bake::load_mesh(p); }), 2) << "1 GiB of headroom is enough";
  fs::remove(p);
}

TEST(InputMemory, SceneFileOutOfMemoryNamesTheFile) {
  if (kSanitized) GTEST_SKIP() << "the sanitizers' shadow memory does not fit an address-space limit";
  // 12 MB of JSON read with 4 MiB of headroom: the text itself does not fit. (Running out inside
  // the JSON library cannot be reported, scene_json.cpp kMaxJsonFileBytes: the file limit bounds it.)
  const fs::path p = prt::testing::test_dir("input_memory") / "large.json";
  {
    std::ofstream out(p);
    out << "{\"prtbake_scene\": 1, \"x\": [0";
    for (int i = 0; i < 6'000'000; ++i) out << ",0";
    out << "]}";
  }
  EXPECT_EQ(read_with_headroom(p, size_t{4} << 20, [&] { prt::bake::load_scene(p, std::nullopt); }), 0);
  fs::remove(p);
}

TEST(InputMemory, EnvironmentMapOutOfMemoryNamesTheFile) {
  if (kSanitized) GTEST_SKIP() << "the sanitizers' shadow memory does not fit an address-space limit";
  // sunset.exr: 1024 x 512 texels, ~40 bytes each once built (20 MB), 6 MB of pixels.
  const fs::path p = fs::path(PRT_DATA_DIR) / "sunset.exr";
  // 1 MiB: OpenEXR's own scanline buffers fail (it reports them as an Iex exception); 4 MiB: ours.
  for (const size_t mib : {1, 4})
    EXPECT_EQ(read_with_headroom(p, mib << 20, [&] { prt::bake::EnvMap::load(p, prt::bake::UpAxis::Y); }), 0) << mib << " MiB";
}

} // namespace
