// bench_contour — the contour search alone (bake/contour.h), against triangle count: for each
// subdivision level of the benchmark scene (bench_common.h), CPU µs per ContourFinder::find on
// the benchmark's shade points, the contour edges found and the query counters (nodes visited,
// records tested, exact decisions), and the growth exponents of time and of edge count against
// triangles between consecutive levels. With PRT_BENCH_CHECK=1 every query is also compared with
// find_brute_force (slow at the finest levels).
//
//   PRT_BENCH_LEVELS  default 0,1,2,3     PRT_BENCH_REPEAT  passes over the points (default 20)
//   PRT_BENCH_POINTS, PRT_BENCH_SEED (bench_common.h)
#include <bench_common.h>

#include <bake/contour.h>

#include <cmath>
#include <cstdio>
#include <ctime>
#include <vector>

using namespace prt;

namespace {

double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

struct Row {
  size_t triangles = 0;
  double us = 0, edges = 0;
  bake::ContourQueryStats q;
  double build_s = 0;
};

}  // namespace

int main() {
  try {
    const auto levels = bench::env_list("PRT_BENCH_LEVELS", {0, 1, 2, 3});
    const long repeat = bench::env_long("PRT_BENCH_REPEAT", 20);
    const bool check = bench::env_long("PRT_BENCH_CHECK", 0) != 0;
    std::printf("| level | triangles | find µs | contour edges | nodes visited | records tested | exact tests | "
                "always tested | BVH nodes | build s | time exp. | edges exp. |\n");
    std::printf("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    Row prev;
    for (const long level : levels) {
      const bench::Scene& s = bench::scene(int(level));
      const double b0 = cpu_seconds();
      const bake::ContourFinder finder(s.mesh, s.topology);
      Row row;
      row.build_s = cpu_seconds() - b0;
      row.triangles = s.mesh.triangles.size();
      std::vector<bake::ContourEdge> out, ref;
      size_t found = 0;
      for (const auto& p : s.points) {  // counters and the check, untimed
        finder.find(p, out, &row.q);
        found += out.size();
        if (check) {
          finder.find_brute_force(p, ref);
          if (out != ref) {
            std::fprintf(stderr, "bench_contour: level %ld: find differs from find_brute_force\n", level);
            return 1;
          }
        }
      }
      const double t0 = cpu_seconds();
      for (long r = 0; r < repeat; ++r)
        for (const auto& p : s.points) finder.find(p, out);
      const double n = double(s.points.size());
      row.us = 1e6 * (cpu_seconds() - t0) / (double(repeat) * n);
      row.edges = double(found) / n;
      const auto per = [n](uint64_t v) { return double(v) / n; };
      char exps[64] = "– | –";
      if (prev.triangles) {
        const double lt = std::log(double(row.triangles) / double(prev.triangles));
        std::snprintf(exps, sizeof exps, "%.2f | %.2f", std::log(row.us / prev.us) / lt,
                      std::log(row.edges / prev.edges) / lt);
      }
      std::printf("| %ld | %zu | %.1f | %.0f | %.0f | %.0f | %.0f | %.0f | %zu | %.3f | %s |\n", level, row.triangles,
                  row.us, row.edges, per(row.q.nodes), per(row.q.records), per(row.q.exact), per(row.q.always),
                  finder.stats().bvh_nodes, row.build_s, exps);
      std::fflush(stdout);
      prev = row;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_contour: %s\n", e.what());
    return 1;
  }
  return 0;
}
