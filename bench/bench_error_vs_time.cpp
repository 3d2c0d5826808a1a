// bench_error_vs_time — error against run time for the QMC baseline and the silhouette
// integrator on the same scene and shade points (docs/ARCHITECTURE.md §6; paper 001 Figure 10 / Table 1).
//
// Scene and points: bench_common.h (bunny_ground.obj, AO + order-3 diffuse transfer, seeded
// vertices). Reference: QMC with R rays per vertex, taken as the mean of two independent
// randomisations (seeds 1001, 1002) of R/2 rays each, so its error can be stated two ways:
//   * the integrator's own standard error (QmcIntegrator std_error, combined for the mean);
//   * empirically, RMS(run1 − run2)/2 — the error of the mean of two independent runs, which for
//     randomised QMC is the honest number (the per-point std_error is a Monte Carlo estimate
//     and ignores the QMC stratification).
// Then each QMC sample count N (seed 1) and each silhouette isoline count (k = N²) integrates
// the same points single-threaded, in order, and is compared with the reference: RMSE and max
// |error| of AO and of the 9 transfer coefficients, and wall / CPU time per integral. Last, the
// speed ratio at equal RMSE (default 1e-3), interpolating log(time) against log(RMSE) between
// the two measurements that bracket it, from wall time and from thread CPU time.
//
// Usage: bench_error_vs_time [--points N] [--seed S] [--ref-rays R] [--qmc a,b,...]
//                            [--isolines a,b,...] [--level L] [--target E]
// Defaults: 64 points, seed 7, R = 2^20, qmc 64,256,1024,4096,16384,65536,
// isolines 16,32,64,128,256,512, level 0 (the file; L > 0 = bunny Loop-subdivided L times),
// target 1e-3. The environment variables PRT_BENCH_POINTS / PRT_BENCH_SEED (bench_common.h),
// PRT_BENCH_REF_RAYS, PRT_BENCH_QMC_SAMPLES and PRT_BENCH_ISOLINES set the same things.
#include <bench_common.h>

#include <bake/bake/vertex_bake.h>
#include <bake/integrators/qmc.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <limits>
#include <memory>
#include <string>
#include <vector>

using namespace prt;

namespace {

struct Row {
  std::string method;
  long param = 0;        // rays (qmc) or isolines (silhouette)
  long k = 0;            // samples per integral: rays, or isolines²
  double wall_us = 0, cpu_us = 0;
  double ao_rmse = 0, ao_max = 0, t_rmse = 0, t_max = 0;
};

// Values [point][width] of one integrator, single-threaded, with wall and thread-CPU time.
std::vector<double> run_serial(const bench::Scene& s, const bake::Integrator& integ, double& wall, double& cpu) {
  const size_t W = integ.layout().width, n = s.points.size();
  std::vector<double> out(n * W);
  const double c0 = bake::thread_cpu_seconds();
  const auto t0 = std::chrono::steady_clock::now();
  for (size_t i = 0; i < n; ++i) integ.integrate(s.points[i], s.vertices[i], std::span<double>(out.data() + i * W, W));
  wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  cpu = bake::thread_cpu_seconds() - c0;
  return out;
}

void errors(const std::vector<double>& v, const std::vector<double>& ref, const bake::ProductLayout& L, size_t n,
            Row& r) {
  double a2 = 0, am = 0, t2 = 0, tm = 0;
  for (size_t i = 0; i < n; ++i) {
    const double* x = v.data() + i * L.width;
    const double* y = ref.data() + i * L.width;
    const double da = x[L.ao] - y[L.ao];
    a2 += da * da;
    am = std::max(am, std::abs(da));
    for (size_t c = 0; c < L.transfer_count; ++c) {
      const double dt = x[L.transfer + c] - y[L.transfer + c];
      t2 += dt * dt;
      tm = std::max(tm, std::abs(dt));
    }
  }
  r.ao_rmse = std::sqrt(a2 / double(n));
  r.ao_max = am;
  r.t_rmse = std::sqrt(t2 / double(n * L.transfer_count));
  r.t_max = tm;
}

// Time per integral at which the method reaches RMSE `target`, interpolated log-log between the
// two cheapest measurements that bracket it; NaN if none does.
double time_at(std::vector<Row> rows, double target, bool transfer, bool cpu) {
  std::sort(rows.begin(), rows.end(), [](const Row& a, const Row& b) { return a.k < b.k; });
  for (size_t i = 0; i + 1 < rows.size(); ++i) {
    const double e0 = transfer ? rows[i].t_rmse : rows[i].ao_rmse;
    const double e1 = transfer ? rows[i + 1].t_rmse : rows[i + 1].ao_rmse;
    if (e0 >= target && e1 <= target && e0 > 0 && e1 > 0) {
      const double t0 = cpu ? rows[i].cpu_us : rows[i].wall_us, t1 = cpu ? rows[i + 1].cpu_us : rows[i + 1].wall_us;
      if (e0 == e1) return t0;
      const double f = (std::log(target) - std::log(e0)) / (std::log(e1) - std::log(e0));
      return std::exp(std::log(t0) + f * (std::log(t1) - std::log(t0)));
    }
  }
  return std::numeric_limits<double>::quiet_NaN();
}

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

std::vector<long> parse_list(const std::string& s) {
  std::vector<long> out;
  size_t pos = 0;
  while (pos <= s.size()) {
    const size_t comma = std::min(s.find(',', pos), s.size());
    const std::string item = s.substr(pos, comma - pos);
    char* end = nullptr;
    const long v = std::strtol(item.c_str(), &end, 10);
    if (item.empty() || *end) throw std::runtime_error("not a list of integers: " + s);
    out.push_back(v);
    pos = comma + 1;
  }
  return out;
}

} // namespace

int main(int argc, char** argv) {
  try {
    long ref_rays = bench::env_long("PRT_BENCH_REF_RAYS", 1L << 20);
    std::vector<long> qmc = bench::env_list("PRT_BENCH_QMC_SAMPLES", {64, 256, 1024, 4096, 16384, 65536});
    std::vector<long> isolines = bench::env_list("PRT_BENCH_ISOLINES", {16, 32, 64, 128, 256, 512});
    int level = 0;
    double target = 1e-3;
    std::string cmd = "bench_error_vs_time";
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      cmd += " " + a;
      auto value = [&]() -> std::string {
        if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
        cmd += std::string(" ") + argv[i + 1];
        return argv[++i];
      };
      if (a == "--points") setenv("PRT_BENCH_POINTS", value().c_str(), 1);
      else if (a == "--seed") setenv("PRT_BENCH_SEED", value().c_str(), 1);
      else if (a == "--ref-rays") ref_rays = std::stol(value());
      else if (a == "--qmc") qmc = parse_list(value());
      else if (a == "--isolines") isolines = parse_list(value());
      else if (a == "--level") level = std::stoi(value());
      else if (a == "--target") target = std::stod(value());
      else throw std::runtime_error("unknown option " + a + " (see the comment at the top of bench_error_vs_time.cpp)");
    }
    if (ref_rays < 2) throw std::runtime_error("--ref-rays must be >= 2");

    const bench::Scene& s = bench::scene(level);
    const bake::ProductRequest req = bench::request();
    const bake::ProductLayout L(req);
    const size_t n = s.points.size(), W = L.width;
    std::printf("### Error against time per integral — %s, %zu triangles, %zu shade points (seed %llu), AO + order-3 transfer\n\n",
                s.mesh.source.c_str(), s.mesh.triangles.size(), n, (unsigned long long)bench::sample_seed());
    std::printf("`%s`\n\n", cmd.c_str());
#if !PRT_BENCH_SILHOUETTE
    std::printf("*Silhouette rows missing: libbake/integrators/src/silhouette.cpp did not exist when this was configured.*\n\n");
    (void)isolines;
#endif

    // Reference: two independent halves, in parallel over points (oneTBB).
    const uint32_t half = uint32_t(ref_rays / 2);
    std::vector<double> r1(n * W), r2(n * W), se1(n * W), se2(n * W);
    const auto t0 = std::chrono::steady_clock::now();
    {
      bake::QmcOptions o1, o2;
      o1.rays = o2.rays = half;
      o1.seed = 1001;
      o2.seed = 1002;
      const bake::QmcIntegrator q1(s.mesh, s.topology, req, o1), q2(s.mesh, s.topology, req, o2);
      tbb::parallel_for(size_t(0), 2 * n, [&](size_t j) {
        const size_t i = j % n;
        const bool second = j >= n;
        (second ? q2 : q1).integrate(s.points[i], s.vertices[i], std::span<double>((second ? r2 : r1).data() + i * W, W),
                                     std::span<double>((second ? se2 : se1).data() + i * W, W));
      });
    }
    const double ref_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::vector<double> ref(n * W);
    for (size_t j = 0; j < n * W; ++j) ref[j] = 0.5 * (r1[j] + r2[j]);
    // Reference error, both ways, per product.
    double se_ao = 0, se_t = 0, emp_ao = 0, emp_t = 0;
    for (size_t i = 0; i < n; ++i) {
      const size_t a = i * W + L.ao;
      se_ao += 0.25 * (se1[a] * se1[a] + se2[a] * se2[a]);
      emp_ao += (r1[a] - r2[a]) * (r1[a] - r2[a]) / 4;
      for (size_t c = 0; c < L.transfer_count; ++c) {
        const size_t t = i * W + L.transfer + c;
        se_t += 0.25 * (se1[t] * se1[t] + se2[t] * se2[t]);
        emp_t += (r1[t] - r2[t]) * (r1[t] - r2[t]) / 4;
      }
    }
    se_ao = std::sqrt(se_ao / double(n));
    se_t = std::sqrt(se_t / double(n * L.transfer_count));
    emp_ao = std::sqrt(emp_ao / double(n));
    emp_t = std::sqrt(emp_t / double(n * L.transfer_count));
    std::printf("Reference: QMC, %ld rays per vertex (mean of seeds 1001 and 1002, %u rays each), %.1f s wall on all cores.\n"
                "Reference error (RMS over points): AO std_error %.2e, empirical |run1−run2|/2 %.2e; "
                "transfer std_error %.2e, empirical %.2e.\n\n",
                long(2 * half), half, ref_seconds, se_ao, emp_ao, se_t, emp_t);
    std::fflush(stdout);

    std::vector<Row> q_rows, s_rows;
    // One row: the integrator the spec describes, timed on one thread over the points.
    auto measure = [&](const bake::IntegratorSpec& spec, const char* method, long param, long k) {
      const std::unique_ptr<bake::Integrator> integ = bake::make_integrator(spec, s.mesh, s.topology, req);
      Row r;
      r.method = method;
      r.param = param;
      r.k = k;
      double wall = 0, cpu = 0;
      const auto v = run_serial(s, *integ, wall, cpu);
      r.wall_us = 1e6 * wall / double(n);
      r.cpu_us = 1e6 * cpu / double(n);
      errors(v, ref, L, n, r);
      return r;
    };
    for (long N : qmc) {
      bake::IntegratorSpec spec;
      spec.kind = bake::IntegratorKind::Qmc;
      spec.qmc_rays = uint32_t(N);
      spec.seed = 1;
      q_rows.push_back(measure(spec, "qmc", N, N));
    }
#if PRT_BENCH_SILHOUETTE
    for (long N : isolines) {
      bake::IntegratorSpec spec;
      spec.kind = bake::IntegratorKind::Silhouette;
      spec.silhouette_k = uint32_t(N * N);
      s_rows.push_back(measure(spec, "silhouette", N, N * N));
    }
#endif

    std::printf("| method | parameter | samples k | wall µs / integral | CPU µs / integral | AO RMSE | AO max | transfer RMSE | transfer max |\n");
    std::printf("|---|---|---:|---:|---:|---:|---:|---:|---:|\n");
    for (const auto* rows : {&q_rows, &s_rows})
      for (const Row& r : *rows)
        std::printf("| %s | %s | %ld | %.1f | %.1f | %.2e | %.2e | %.2e | %.2e |\n", r.method.c_str(),
                    (r.method == "qmc" ? "N = " + std::to_string(r.param) : "isolines " + std::to_string(r.param)).c_str(),
                    r.k, r.wall_us, r.cpu_us, r.ao_rmse, r.ao_max, r.t_rmse, r.t_max);
    std::printf("\n");
    // Wall time is what was asked; CPU time of the (single) integrating thread is the same
    // measure without the time other processes took the core away (busy build machines).
    for (const bool cpu : {false, true})
      for (const bool transfer : {false, true}) {
        const double tq = time_at(q_rows, target, transfer, cpu), ts = time_at(s_rows, target, transfer, cpu);
        std::printf("- At %s RMSE %.0e (%s time): QMC %s µs, silhouette %s µs per integral", transfer ? "transfer" : "AO",
                    target, cpu ? "CPU" : "wall", std::isnan(tq) ? "(not bracketed)" : fmt("%.1f", tq).c_str(),
                    std::isnan(ts) ? "(not bracketed)" : fmt("%.1f", ts).c_str());
        if (!std::isnan(tq) && !std::isnan(ts)) std::printf(" — silhouette is %.2f× faster", tq / ts);
        std::printf(".\n");
      }
    std::printf("\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_error_vs_time: %s\n", e.what());
    return 1;
  }
  return 0;
}
