// bench_integrators — cost of one spherical integral (one shade point, AO + order-3 transfer
// on the default scene), single-threaded, for the QMC baseline next to the silhouette
// integrator (docs/ARCHITECTURE.md §4, §6; paper 001 Table 1 is the model).
//
//   BM_Qmc/samples:N                QMC, N rays per integral           (level-0 scene)
//   BM_Silhouette/isolines:N        silhouette, k = N² samples         (level-0 scene)
//   BM_QmcTriangles/level:L         QMC at 1024 rays,  bunny Loop-subdivided L times
//   BM_SilhouetteTriangles/level:L  silhouette at N = 64, the same scenes
//
// One benchmark iteration integrates every shade point of the scene once, in order, on the
// calling thread; the counter `per_integral` is CPU seconds per integral (per core; printed as e.g. 83.6us).
// Integrator construction (BVHs, tables) is outside the timed loop and reported as `setup_s`.
// Silhouette cases also report SilhouetteIntegrator::silhouette_stats() per integral over the timed loop:
// contour-search and integration µs, contour edges and isoline crossings.
//
// After the runs, a table of the triangle sweep: per level the contour edges found, contour
// search µs and CPU µs per integral, and the growth exponents against triangle count (between
// consecutive levels and a least-squares fit over all levels) of edges, contour time and total
// time — contour search is output-sensitive when its exponent is no larger than the edges'.
//
// Sizes (environment; Google Benchmark's own flags such as --benchmark_filter also work):
//   PRT_BENCH_QMC_SAMPLES   default 256,1024,4096,16384
//   PRT_BENCH_ISOLINES      default 16,32,64,128,256,512
//   PRT_BENCH_LEVELS        default 0,1,2,3
//   PRT_BENCH_POINTS, PRT_BENCH_SEED (bench_common.h)
#include <bench_common.h>

#include <bake/bake/vertex_bake.h>
#include <bake/integrators/silhouette.h>

#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <map>
#include <memory>
#include <string>
#include <vector>

using namespace prt;

namespace {

double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// One row of the triangle-sweep table (the silhouette cases of BM_SilhouetteTriangles).
struct SweepRow {
  double triangles = 0, edges = 0, contour_us = 0, total_us = 0;
};
std::map<int, SweepRow>& sweep() {
  static std::map<int, SweepRow> rows;
  return rows;
}

// The timed loop shared by every case: all shade points once per iteration. Returns CPU µs
// per integral (this thread).
double integrate_all(benchmark::State& state, const bench::Scene& s, const bake::Integrator& integ) {
  std::vector<double> row(integ.layout().width);
  const size_t n = s.points.size();
  const double c0 = bake::thread_cpu_seconds();
  for (auto _ : state) {
    for (size_t i = 0; i < n; ++i) {
      integ.integrate(s.points[i], s.vertices[i], row);
      benchmark::DoNotOptimize(row.data());
    }
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(n));
  // Rate inverted = CPU seconds per integral (the console prints it with an SI prefix: "83.6us").
  state.counters["per_integral"] =
      benchmark::Counter(double(n), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["triangles"] = double(s.mesh.triangles.size());
  state.counters["points"] = double(n);
  return 1e6 * (bake::thread_cpu_seconds() - c0) / (double(state.iterations()) * double(n));
}

bake::IntegratorSpec qmc_spec(long rays) {
  bake::IntegratorSpec spec;
  spec.kind = bake::IntegratorKind::Qmc;
  spec.qmc_rays = uint32_t(rays);
  return spec;
}

bake::IntegratorSpec silhouette_spec(long isolines) {
  bake::IntegratorSpec spec;
  spec.kind = bake::IntegratorKind::Silhouette;
  spec.silhouette_k = uint32_t(isolines * isolines);
  return spec;
}

// One case: the integrator the spec describes (its setup timed apart), every shade point per
// iteration, and the integrator's own per-integral statistics (the silhouette integrator's
// contour and integration split; QMC has none).
void integrator_case(benchmark::State& state, int level, const bake::IntegratorSpec& spec, bool sweep_row = false) {
  const bench::Scene& s = bench::scene(level);
  const auto t0 = std::chrono::steady_clock::now();
  const std::unique_ptr<bake::Integrator> integ = bake::make_integrator(spec, s.mesh, s.topology, bench::request());
  state.counters["setup_s"] = since(t0);
  const auto* silhouette = dynamic_cast<const bake::SilhouetteIntegrator*>(integ.get());
  const bake::SilhouetteStats before = silhouette ? silhouette->silhouette_stats() : bake::SilhouetteStats{};
  const double cpu_us = integrate_all(state, s, *integ);
  if (!silhouette) return;
  const bake::SilhouetteStats after = silhouette->silhouette_stats();
  const double k = double(after.points - before.points);
  if (k > 0) {
    state.counters["contour_us"] = 1e6 * (after.contour_seconds - before.contour_seconds) / k;
    state.counters["integrate_us"] = 1e6 * (after.integrate_seconds - before.integrate_seconds) / k;
    state.counters["contour_edges"] = double(after.contour_edges - before.contour_edges) / k;
    state.counters["crossings"] = double(after.crossings - before.crossings) / k;
    state.counters["start_rays"] = double(after.start_rays - before.start_rays) / k;
    if (sweep_row)
      sweep()[level] = {double(s.mesh.triangles.size()), state.counters["contour_edges"], state.counters["contour_us"],
                        cpu_us};
  }
  state.counters["k"] = double(spec.silhouette_k);
}

// Slope of log y against log x (least squares); NaN with fewer than two points.
double loglog_slope(const std::vector<std::pair<double, double>>& xy) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double n = double(xy.size());
  for (const auto& [x, y] : xy) {
    sx += std::log(x);
    sy += std::log(y);
    sxx += std::log(x) * std::log(x);
    sxy += std::log(x) * std::log(y);
  }
  return xy.size() < 2 ? std::nan("") : (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

void print_sweep_table() {
  const auto& rows = sweep();
  if (rows.empty()) return;
  std::printf("\nContour search against triangle count (silhouette N = 64; exponents: growth against triangles)\n\n");
  std::printf("| level | triangles | contour edges | contour µs | CPU µs / integral | edges exp. | contour exp. | total exp. |\n");
  std::printf("|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  const SweepRow* prev = nullptr;
  std::vector<std::pair<double, double>> edges, contour, total;
  for (const auto& [level, r] : rows) {
    char exps[96] = "– | – | –";
    if (prev) {
      const double lt = std::log(r.triangles / prev->triangles);
      std::snprintf(exps, sizeof exps, "%.2f | %.2f | %.2f", std::log(r.edges / prev->edges) / lt,
                    std::log(r.contour_us / prev->contour_us) / lt, std::log(r.total_us / prev->total_us) / lt);
    }
    std::printf("| %d | %.0f | %.0f | %.1f | %.1f | %s |\n", level, r.triangles, r.edges, r.contour_us, r.total_us, exps);
    edges.emplace_back(r.triangles, r.edges);
    contour.emplace_back(r.triangles, r.contour_us);
    total.emplace_back(r.triangles, r.total_us);
    prev = &r;
  }
  if (rows.size() >= 2)
    std::printf("| fit | | | | | %.2f | %.2f | %.2f |\n", loglog_slope(edges), loglog_slope(contour), loglog_slope(total));
}

} // namespace

int main(int argc, char** argv) {
  try {
    const auto samples = bench::env_list("PRT_BENCH_QMC_SAMPLES", {256, 1024, 4096, 16384});
    const auto isolines = bench::env_list("PRT_BENCH_ISOLINES", {16, 32, 64, 128, 256, 512});
    const auto levels = bench::env_list("PRT_BENCH_LEVELS", {0, 1, 2, 3});
    // Baseline next to the optimised method, accuracy knob first, then the triangle sweep.
    for (long n : samples)
      benchmark::RegisterBenchmark(("BM_Qmc/samples:" + std::to_string(n)).c_str(),
                                   [n](benchmark::State& st) { integrator_case(st, 0, qmc_spec(n)); })
          ->Unit(benchmark::kMillisecond);
#if PRT_BENCH_SILHOUETTE
    for (long n : isolines)
      benchmark::RegisterBenchmark(("BM_Silhouette/isolines:" + std::to_string(n)).c_str(),
                                   [n](benchmark::State& st) { integrator_case(st, 0, silhouette_spec(n)); })
          ->Unit(benchmark::kMillisecond);
#else
    (void)isolines;
    std::fprintf(stderr, "bench_integrators: silhouette cases compiled out (libbake/integrators/src/silhouette.cpp "
                         "did not exist at configure time)\n");
#endif
    for (long l : levels) {
      benchmark::RegisterBenchmark(("BM_QmcTriangles/level:" + std::to_string(l)).c_str(),
                                   [l](benchmark::State& st) { integrator_case(st, int(l), qmc_spec(1024)); })
          ->Unit(benchmark::kMillisecond);
#if PRT_BENCH_SILHOUETTE
      benchmark::RegisterBenchmark(("BM_SilhouetteTriangles/level:" + std::to_string(l)).c_str(),
                                   [l](benchmark::State& st) { integrator_case(st, int(l), silhouette_spec(64), true); })
          ->Unit(benchmark::kMillisecond);
#endif
    }
    benchmark::AddCustomContext("cpu_model", bench::cpu_model());
    benchmark::AddCustomContext("silhouette", PRT_BENCH_SILHOUETTE ? "built" : "not built (silhouette.cpp missing)");
    benchmark::AddCustomContext("points", std::to_string(bench::n_points()));
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    print_sweep_table();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_integrators: %s\n", e.what());
    return 1;
  }
  return 0;
}
