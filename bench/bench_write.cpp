// bench_write — the HDF5 writer's cost: our filtering (formats/src/chunk_filters.h: shuffle →
// libdeflate → Fletcher-32, direct chunk writes) on one thread and on all, against HDF5's own
// filter pipeline (zlib, the slow reference, formats/testing.h), alternating in one run.
//   bench_write FILE.prt.h5 [ROUNDS]   rewrites FILE's contents (read once) ROUNDS times (default 7)
// Prints per writer the median wall and CPU seconds of a write and the file's size. All three
// skip the schema check (write_file adds it, the same for every writer).
#include <formats/prtfile.h>
#include <formats/testing.h>

#include <tbb/global_control.h>
#include <tbb/info.h>

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace fs = std::filesystem;
namespace F = prt::formats;

namespace {

double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

struct Writer {
  std::string name;
  std::function<void(const fs::path&)> write;
  std::vector<double> wall, cpu;
  uintmax_t bytes = 0;
};

} // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_write FILE.prt.h5 [ROUNDS]\n");
    return 2;
  }
  const fs::path input = argv[1];
  const int rounds = argc > 2 ? std::max(1, std::atoi(argv[2])) : 7;
  const F::File file = F::read_file(input);
  const fs::path out = fs::temp_directory_path() / ("bench_write." + std::to_string(::getpid()) + ".h5");
  const int threads = tbb::info::default_concurrency();
  std::vector<Writer> writers;
  writers.push_back({"HDF5 filters (zlib), the reference", [&](const fs::path& p) {
                       F::testing::write_file_library_filters(p, file);
                     }, {}, {}, 0});
  writers.push_back({"ours, 1 thread", [&](const fs::path& p) {
                       const tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
                       F::testing::write_file_unvalidated(p, file);
                     }, {}, {}, 0});
  writers.push_back({"ours, " + std::to_string(threads) + " threads", [&](const fs::path& p) { F::testing::write_file_unvalidated(p, file); },
                     {}, {}, 0});
  for (int r = 0; r < rounds; ++r)
    for (Writer& w : writers) {
      const auto t0 = std::chrono::steady_clock::now();
      const double c0 = cpu_seconds();
      w.write(out);
      w.cpu.push_back(cpu_seconds() - c0);
      w.wall.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      w.bytes = fs::file_size(out);
    }
  fs::remove(out);
  std::printf("bench_write %s, %d rounds (medians)\n\n", input.string().c_str(), rounds);
  std::printf("| writer | wall s | CPU s | file bytes | CPU vs reference |\n|---|---:|---:|---:|---:|\n");
  const double ref = median(writers[0].cpu);
  for (const Writer& w : writers)
    std::printf("| %s | %.3f | %.3f | %ju | %.2fx |\n", w.name.c_str(), median(w.wall), median(w.cpu), w.bytes,
                ref / median(w.cpu));
  return 0;
}
