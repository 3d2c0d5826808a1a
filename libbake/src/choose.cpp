// choose.cpp — the target-error chooser (bake/choose.h): a pilot on seeded shade points, error
// models fitted per integrator, costs measured, the cheaper prediction chosen.
#include <bake/choose.h>

#include <bake/error.h>
#include <bake/qmc.h>
#include <bake/sampling.h>
#include <bake/silhouette.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <memory>

namespace prt::bake {
namespace {

// Radiance products (R, S) carry the environment's HDR scale: their errors are relative to their RMS.
bool is_radiance(Product p) { return p == Product::RadianceBand1 || p == Product::RadianceShadowed; }

// The pilot's reference: 256 isolines for targets >= 5e-4 (its own AO error, ~6e-5 on the bunny,
// is under a tenth of the aim 0.7·E; its isoline tables take 8 ms to build against 190 ms at 512,
// bench/RESULTS.md bench_integrators), 512 below.
int reference_isolines(double target) { return target >= 5e-4 ? 256 : 512; }
// The silhouette levels: 32 and 64 always; 16 only when some product already meets the goal at
// 32 (its bracket is then [16, 32]), 128 only when some product still misses it at 64 (its
// bracket is [64, 128]). Every product's bracket is the one all four levels would give; the
// levels that bracket nothing are not run (on most assets E = 1e-3 falls between 32 and 64).
constexpr int kSilhouetteLow = 16, kSilhouetteFirst[] = {32, 64}, kSilhouetteHigh = 128;
constexpr size_t kSilhouetteMaxLevels = std::size(kSilhouetteFirst) + 2;
constexpr int kMinIsolines = 8;
// QMC's levels. 64 first: on the assets the silhouette integrator wins (most), its error there
// (~1-2e-2 AO) already prices QMC out (kQmcBestCaseMargin) at a quarter of 256 rays' cost.
constexpr uint32_t kQmcLevels[] = {64, 256, 1024, 4096};
constexpr uint32_t kMinRays = 16, kMaxRays = 1u << 20;
// QMC's levels stop when its best case (above) costs this many times the silhouette prediction.
// The per-ray cost at a level over-states the cost of more rays by its fixed part per point
// (~3 µs of ~35 at 64 rays, kCountedUsPerPoint), and a fitted rate above 1 is noise (the fit
// clamps it to 1): 2 leaves room for both.
constexpr double kQmcBestCaseMargin = 2.0;
// Counted costs (ChooserOptions::counted_costs), µs per integral: the silhouette integrator per
// contour edge (search ~0.045, arcs ~0.038) and per isoline crossing, QMC per ray, and setup in
// seconds per triangle. Calibrated on this project's 2-core AMD EPYC machine
// (bench/RESULTS.md: bench_integrators level 0 — contour 24 µs for 528 edges, integration
// 24 → 156 µs from 99 to 3,187 crossings; bench_target_error's QMC sweeps, 0.49–0.58 µs per ray
// on every asset; bench_contour's build, 1.5 s at 240k triangles). Large meshes cost the
// silhouette integrator up to ~2x more per edge (its search is memory-bound there).
constexpr double kCountedUsPerEdge = 0.083, kCountedUsPerCrossing = 0.043, kCountedUsPerRay = 0.5;
constexpr double kCountedUsPerPoint = 3.0;
constexpr double kCountedSetupPerTriangleSilhouette = 6e-6, kCountedSetupPerTriangleQmc = 2e-7;
constexpr uint64_t kPilotSalt = 0x70696c6f74736565ull;  // the pilot's sample, apart from the report's

// Rows of one integrator at the pilot points, and the mean CPU time per integral.
struct Rows {
  std::vector<double> values;
  double cpu_us_per_point = 0;
};

Rows integrate_pilot(const Integrator& integrator, std::span<const ShadePoint> points,
                     const std::vector<uint32_t>& sample, Task& progress) {
  const size_t W = integrator.layout().width, K = sample.size();
  Rows rows;
  rows.values.assign(K * W, 0.0);
  std::vector<double> seconds(K, 0.0);
  tbb::parallel_for(size_t(0), K, [&](size_t i) {
    const double t0 = thread_cpu_seconds();
    // The bake's own point index: a QMC pilot row is the row the bake would compute.
    integrator.integrate(points[sample[i]], sample[i], std::span(rows.values).subspan(i * W, W));
    seconds[i] = thread_cpu_seconds() - t0;
    progress.advance();
  });
  double sum = 0;
  for (double s : seconds) sum += s;  // in index order: the same sum for any thread count
  rows.cpu_us_per_point = K ? 1e6 * sum / double(K) : 0.0;
  return rows;
}

// The cost per integral the choice uses: the measured CPU time, or (counted) the work the
// integrator reports for the pilot points priced at the constants above.
double cost_per_point(const Rows& rows, const Integrator& integrator, uint32_t knob, bool counted) {
  if (!counted) return rows.cpu_us_per_point;
  if (integrator.kind() == IntegratorKind::Qmc) return kCountedUsPerPoint + kCountedUsPerRay * knob;
  const IntegratorStats st = integrator.stats();
  const double n = double(std::max<uint64_t>(st.points, 1));
  return kCountedUsPerPoint + kCountedUsPerEdge * double(st.contour_edges) / n +
         kCountedUsPerCrossing * double(st.crossings) / n;
}

// Per product: RMSE of `rows` against `ref` in the target's units (bake/choose.h).
std::vector<double> pilot_errors(const std::vector<double>& rows, const std::vector<double>& ref, size_t W,
                                 const std::vector<ProductSlice>& products) {
  const size_t K = W ? ref.size() / W : 0;
  std::vector<double> out;
  for (const ProductSlice& p : products) {
    double e2 = 0, r2 = 0;
    for (size_t i = 0; i < K; ++i)
      for (size_t c = 0; c < p.count; ++c) {
        const double d = rows[i * W + p.offset + c] - ref[i * W + p.offset + c];
        e2 += d * d;
        r2 += ref[i * W + p.offset + c] * ref[i * W + p.offset + c];
      }
    const double n = double(std::max<size_t>(K * p.count, 1));
    double e = std::sqrt(e2 / n);
    if (is_radiance(p.product)) e = r2 > 0 ? e / std::sqrt(r2 / n) : 0.0;
    out.push_back(e);
  }
  return out;
}

// The knob x at which a power law through (x0, e0), (x1, e1) (x0 < x1) reaches `goal`, with its
// exponent clamped to [lo, hi]; `exponent` receives it. Errors of exactly 0 need no more than x0.
double solve_power_law(double x0, double e0, double x1, double e1, double goal, double lo, double hi,
                       double& exponent) {
  if (!(e1 > 0)) {
    exponent = hi;
    return e0 > goal ? x1 : x0;  // e1 = 0: x1 is exact enough
  }
  const double a = e0 > 0 ? std::log(e0 / e1) / std::log(x1 / x0) : hi;
  exponent = std::clamp(std::isfinite(a) ? a : hi, lo, hi);
  return x1 * std::pow(e1 / goal, 1.0 / exponent);
}

// Product p's errors `errors[i][p]` at the measured knobs xs (ascending, at least two): the knob
// where its power law reaches `goal` — interpolated between the first level that meets it and
// the level before, extrapolated from the last two when none does (below the first level when
// the first already meets it) — with the rate clamped to [lo, hi] (`rate` receives it).
double knob_for(const std::vector<double>& xs, const std::vector<std::vector<double>>& errors, size_t p, double goal,
                double lo, double hi, double& rate) {
  const size_t L = xs.size();
  size_t hit = L;
  for (size_t i = 0; i < L && hit == L; ++i)
    if (errors[i][p] <= goal) hit = i;
  const size_t i1 = hit == L ? L - 1 : std::max<size_t>(hit, 1), i0 = i1 - 1;
  const double n = solve_power_law(xs[i0], errors[i0][p], xs[i1], errors[i1][p], goal, lo, hi, rate);
  return hit == 0 ? std::min(n, xs[0]) : n;
}

// The same model's error of product p at `knob`, from the levels that bracket it.
double model_error(const std::vector<double>& xs, const std::vector<std::vector<double>>& errors, size_t p, double knob,
                   double lo, double hi) {
  size_t i1 = 1;
  while (i1 + 1 < xs.size() && xs[i1] < knob) ++i1;
  double rate = 0;
  solve_power_law(xs[i1 - 1], errors[i1 - 1][p], xs[i1], errors[i1][p], 1.0, lo, hi, rate);
  return errors[i1][p] * std::pow(xs[i1] / knob, rate);
}

// Rays for a need of `need`: rounded up to an eighth of an octave (a multiple of 2^(⌊log2 need⌋ −
// 3), at least 16), so at most 12.5% more than needed. The QMC integrator's randomised Halton
// points stratify any count; a power of two would cost up to twice the rays.
uint32_t round_up_rays(double need) {
  if (!(need > kMinRays)) return kMinRays;
  if (need >= kMaxRays) return kMaxRays;
  const uint32_t step = std::max<uint32_t>(16, uint32_t(1) << std::max(0, int(std::floor(std::log2(need))) - 3));
  return std::min(kMaxRays, uint32_t(std::ceil(need / step)) * step);
}

// Least-squares line t = α + β x through the points.
void fit_line(const std::vector<double>& x, const std::vector<double>& t, double& alpha, double& beta) {
  const double n = double(x.size());
  double sx = 0, st = 0, sxx = 0, sxt = 0;
  for (size_t i = 0; i < x.size(); ++i) sx += x[i], st += t[i], sxx += x[i] * x[i], sxt += x[i] * t[i];
  const double d = n * sxx - sx * sx;
  beta = d > 0 ? (n * sxt - sx * st) / d : 0.0;
  alpha = (st - beta * sx) / n;
  if (beta < 0) beta = 0, alpha = st / n;  // noise: cost does not fall with the knob
}

// A prediction at `knob`: the worst product's model error (levels/errors, rates in [lo, hi]) and
// the cost per integral from a least-squares line through the measured (cost_knobs, us).
void predict_at(Prediction& pr, uint32_t knob, const std::vector<double>& levels,
                const std::vector<std::vector<double>>& errors, double lo, double hi,
                const std::vector<double>& cost_knobs, const std::vector<double>& us) {
  pr.knob = knob;
  pr.predicted_error = 0;
  for (size_t p = 0; p < errors.front().size(); ++p)
    pr.predicted_error = std::max(pr.predicted_error, model_error(levels, errors, p, knob, lo, hi));
  double alpha = 0, beta = 0;
  fit_line(cost_knobs, us, alpha, beta);
  pr.predicted_us_per_point = alpha + beta * knob;
}

std::string format(const char* fmt, double a, double b = 0, double c = 0, double d = 0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, fmt, a, b, c, d);
  return buf;
}

std::string knob_text(IntegratorKind kind, uint32_t knob) {
  return kind == IntegratorKind::Qmc ? std::to_string(knob) + " rays" : "N = " + std::to_string(knob);
}

} // namespace

double error_in_target_units(const ProductError& e) {
  if (!is_radiance(e.product)) return e.rmse;
  return e.reference_rms > 0 ? e.rmse / e.reference_rms : 0.0;
}

IntegratorChoice choose_integrator(std::span<const ShadePoint> points, const Mesh& mesh, const Topology& topology,
                                   const ProductRequest& request, const IntegratorSpec& base,
                                   const ChooserOptions& options, const Monitor& monitor, const MeshAccel* accel) {
  if (!(options.target >= ChooserOptions::kMinTarget && options.target <= ChooserOptions::kMaxTarget))
    throw InputError("", format("target error %g outside [%g, %g]", options.target, ChooserOptions::kMinTarget,
                                ChooserOptions::kMaxTarget));
  PRT_CHECK(!request.empty());
  PRT_CHECK(!points.empty());
  if (options.only == IntegratorKind::Filter)
    throw InputError("", "the target-error chooser has no model of the filter integrator: give its pass-1 rays "
                         "(--samples N)");
  const auto wall0 = std::chrono::steady_clock::now();
  IntegratorChoice choice;
  choice.target = options.target;
  choice.spec = base;
  const std::vector<ProductSlice> products = product_slices(ProductLayout(request));
  for (const ProductSlice& p : products) choice.products.push_back(p.product);
  // A 64th of the points, at least 32 and at most pilot_points: the pilot must not cost more than
  // a small part of the bake it tunes (ChooserOptions::kPilotFraction).
  const size_t pilot = std::clamp<size_t>(points.size() / ChooserOptions::kPilotFraction, 32,
                                          std::max<size_t>(options.pilot_points, 32));
  const std::vector<uint32_t> sample = seeded_sample(uint32_t(points.size()), pilot, mix64(base.seed ^ kPilotSalt));
  choice.pilot_points = sample.size();
  const size_t W = ProductLayout(request).width;
  double goal = options.safety_silhouette * options.target;
  const bool want_sil = !options.only || *options.only == IntegratorKind::Silhouette;
  const bool want_qmc = !options.only || *options.only == IntegratorKind::Qmc;
  const size_t runs = 1 + (want_sil ? kSilhouetteMaxLevels : 0) + (want_qmc ? std::size(kQmcLevels) : 0);
  Task progress(monitor, "pilot", runs * sample.size());

  // Setup is part of a bake's cost: measured per integrator build (its tables), wall time. The
  // trees are built once for every pilot integrator, timed apart: a bake given the same `accel`
  // reuses them, one without rebuilds them (the silhouette integrator both, QMC the ray scene).
  auto timed_build = [](auto&& make, double& seconds) {
    const auto t0 = std::chrono::steady_clock::now();
    auto result = make();
    seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return result;
  };
  const MeshAccel own_accel(mesh, topology);
  const MeshAccel* shared = accel ? accel : &own_accel;
  double rays_seconds = 0, contours_seconds = 0;
  timed_build([&] { return shared->rays(); }, rays_seconds);
  timed_build([&] { return shared->contours(); }, contours_seconds);  // the reference is a silhouette integrator
  auto silhouette = [&](int isolines) {
    return std::make_unique<SilhouetteIntegrator>(mesh, topology, request, SilhouetteOptions{isolines, base.seed}, shared);
  };
  double setup_sil = 0, setup_qmc = 0;
  const int ref_isolines = reference_isolines(options.target), max_isolines = ref_isolines;
  const auto reference = timed_build([&] { return silhouette(ref_isolines); }, setup_sil);
  const Rows ref = integrate_pilot(*reference, points, sample, progress);
  const bool counted = options.counted_costs;
  choice.counted_costs = counted;
  const double ref_us = cost_per_point(ref, *reference, uint32_t(ref_isolines), counted);
  choice.runs.push_back({IntegratorKind::Silhouette, uint32_t(ref_isolines), std::vector<double>(products.size(), 0.0), ref_us});

  const double V = double(points.size());
  if (want_sil) {
    std::vector<PilotRun> levels_run;  // ascending N
    auto run_level = [&](int N) {
      double s = 0;
      const auto integrator = timed_build([&] { return silhouette(N); }, s);
      setup_sil = std::max(setup_sil, s);
      const Rows r = integrate_pilot(*integrator, points, sample, progress);
      PilotRun run{IntegratorKind::Silhouette, uint32_t(N), pilot_errors(r.values, ref.values, W, products),
                   cost_per_point(r, *integrator, uint32_t(N), counted)};
      const auto at = std::find_if(levels_run.begin(), levels_run.end(), [&](const PilotRun& x) { return x.knob > run.knob; });
      levels_run.insert(at, std::move(run));
    };
    for (int N : kSilhouetteFirst) run_level(N);
    auto any_product = [&](const PilotRun& r, auto&& test) { return std::any_of(r.error.begin(), r.error.end(), test); };
    if (any_product(levels_run.front(), [&](double e) { return e <= goal; })) run_level(kSilhouetteLow);
    if (any_product(levels_run.back(), [&](double e) { return e > goal; })) run_level(kSilhouetteHigh);
    progress.advance(sample.size() * (kSilhouetteMaxLevels - levels_run.size()));  // the levels not run
    std::vector<double> xs, ts;
    std::vector<std::vector<double>> errors;
    for (const PilotRun& r : levels_run) {
      choice.runs.push_back(r);
      xs.push_back(r.knob), ts.push_back(r.cpu_us_per_point), errors.push_back(r.error);
    }
    xs.push_back(ref_isolines), ts.push_back(ref_us);
    Prediction pr;
    pr.kind = IntegratorKind::Silhouette;
    double need = kMinIsolines;
    const std::vector<double> levels(xs.begin(), xs.end() - 1);  // without the reference
    for (size_t p = 0; p < products.size(); ++p) {
      double a = 0;
      const double n = knob_for(levels, errors, p, goal, 0.5, 3.0, a);  // silhouette: rates 0.5 to 3
      if (n > need) need = n, pr.exponent = a;
    }
    pr.reachable = need <= max_isolines;
    int N = int(std::ceil(std::min<double>(need, max_isolines) - 1e-9));
    N = std::max(kMinIsolines, N + (N & 1));  // even, as the integrator uses it
    predict_at(pr, uint32_t(N), levels, errors, 0.5, 3.0, xs, ts);
    choice.predictions.push_back(pr);
  }
  goal = options.safety_qmc * options.target;
  if (want_qmc) {
    std::vector<double> xs, ts;
    std::vector<std::vector<double>> errors;
    // QMC cannot win once a level that misses the goal already costs more per integral than the
    // silhouette prediction (more rays cost more): the remaining levels are skipped.
    const double rival_us = !choice.predictions.empty() && choice.predictions.front().reachable
                                ? choice.predictions.front().predicted_us_per_point
                                : 0.0;
    bool pruned = false;
    for (uint32_t R : kQmcLevels) {
      if (!errors.empty()) {
        const double worst = *std::max_element(errors.back().begin(), errors.back().end());
        const bool misses = worst > goal;
        // Or once even the best case its model allows (rate 1, the top of its clamp: R·worst/goal
        // rays at this level's cost per ray) costs kQmcBestCaseMargin times the prediction.
        if (misses && rival_us > 0 && (ts.back() >= rival_us || ts.back() * (worst / goal) >= kQmcBestCaseMargin * rival_us)) {
          pruned = true;
          break;
        }
        if (!misses && errors.size() >= 2) break;  // two levels and the goal met: enough to interpolate
      }
      double s = 0;
      const auto integrator =
          timed_build([&] { return std::make_unique<QmcIntegrator>(mesh, topology, request, QmcOptions{R, base.seed}, shared); }, s);
      setup_qmc = std::max(setup_qmc, s);
      const Rows r = integrate_pilot(*integrator, points, sample, progress);
      choice.runs.push_back({IntegratorKind::Qmc, R, pilot_errors(r.values, ref.values, W, products),
                             cost_per_point(r, *integrator, R, counted)});
      xs.push_back(R), ts.push_back(choice.runs.back().cpu_us_per_point), errors.push_back(choice.runs.back().error);
    }
    Prediction pr;
    pr.kind = IntegratorKind::Qmc;
    if (pruned) {
      pr.pruned = true;
      pr.knob = uint32_t(xs.back());
      pr.predicted_error = *std::max_element(errors.back().begin(), errors.back().end());
      pr.predicted_us_per_point = ts.back();
      choice.predictions.push_back(pr);
    }
    progress.advance(sample.size() * (std::size(kQmcLevels) - xs.size()));  // the levels not run
  }
  if (want_qmc && (choice.predictions.empty() || !choice.predictions.back().pruned)) {
    std::vector<double> xs, ts;
    std::vector<std::vector<double>> errors;
    for (const PilotRun& r : choice.runs)
      if (r.kind == IntegratorKind::Qmc) xs.push_back(r.knob), ts.push_back(r.cpu_us_per_point), errors.push_back(r.error);
    Prediction pr;
    pr.kind = IntegratorKind::Qmc;
    double need = kMinRays;
    for (size_t p = 0; p < products.size(); ++p) {
      double rate = 0;
      const double r = knob_for(xs, errors, p, goal, 0.5, 1.0, rate);  // QMC: rates 0.5 to 1
      if (r > need) need = r, pr.exponent = rate;
    }
    pr.reachable = need <= kMaxRays;
    predict_at(pr, round_up_rays(need), xs, errors, 0.5, 1.0, xs, ts);
    choice.predictions.push_back(pr);
  }
  progress.finish();

  // The cheaper reachable prediction, by CPU seconds for the whole bake (setup + V integrals).
  if (counted) {
    // Counted setup is the trees' (calibrated on whole builds): none when the bake reuses them.
    setup_sil = accel ? 0.0 : kCountedSetupPerTriangleSilhouette * double(mesh.triangles.size());
    setup_qmc = accel ? 0.0 : kCountedSetupPerTriangleQmc * double(mesh.triangles.size());
  } else if (!accel) {
    setup_sil += rays_seconds + contours_seconds;
    setup_qmc += rays_seconds;
  }
  auto cost = [&](const Prediction& p) {
    return (p.kind == IntegratorKind::Silhouette ? setup_sil : setup_qmc) + V * p.predicted_us_per_point * 1e-6;
  };
  const Prediction* best = nullptr;
  for (const Prediction& p : choice.predictions)
    if (p.reachable && !p.pruned && (!best || cost(p) < cost(*best))) best = &p;
  if (!best) {
    double closest = 0;
    for (const Prediction& p : choice.predictions) closest = closest == 0 ? p.predicted_error : std::min(closest, p.predicted_error);
    throw InputError("", format("target error %g: no integrator reaches it within its sample range (the closest "
                                "prediction is %.3g at N = 256/512 isolines or 2^20 rays)",
                                options.target, closest));
  }
  choice.spec.kind = best->kind;
  if (best->kind == IntegratorKind::Silhouette)
    choice.spec.silhouette_k = best->knob * best->knob;
  else
    choice.spec.qmc_rays = best->knob;
  const Prediction* other = nullptr;
  for (const Prediction& p : choice.predictions)
    if (&p != best && p.reachable && !p.pruned) other = &p;
  choice.margin = other ? cost(*other) / std::max(cost(*best), 1e-12) : 0.0;
  const std::string knob = best->kind == IntegratorKind::Silhouette
                               ? format("N = %.0f isolines (k = %.0f)", best->knob, double(best->knob) * best->knob)
                               : format("%.0f rays", best->knob);
  choice.reason = std::string(to_string(best->kind)) + " at " + knob +
                  format(": predicted error %.2g (target %g), %.1f µs per integral, %.2f CPU s for the bake", best->predicted_error,
                         options.target, best->predicted_us_per_point, cost(*best));
  if (other)
    choice.reason += format("; %.2fx cheaper than ", choice.margin) + to_string(other->kind) + " at " +
                     (other->kind == IntegratorKind::Silhouette ? format("N = %.0f", other->knob) : format("%.0f rays", other->knob));
  else if (!options.only && choice.predictions.size() > 1 && choice.predictions.back().pruned)
    choice.reason += format("; qmc at %.0f rays costs %.1f µs per integral and misses the target by %.1fx: more rays "
                            "cannot beat it",
                            choice.predictions.back().knob, choice.predictions.back().predicted_us_per_point,
                            choice.predictions.back().predicted_error / options.target);
  else if (!options.only)
    choice.reason += "; the other integrator cannot reach the target within its sample range";
  choice.pilot_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return choice;
}

std::vector<std::string> choice_lines(const IntegratorChoice& c) {
  std::vector<std::string> out;
  out.push_back("target error " + format("%g", c.target) + ": pilot on " + std::to_string(c.pilot_points) +
                " seeded points took " + format("%.2f s", c.pilot_seconds) + "; error per product against a " +
                std::to_string(c.runs.empty() ? 0u : c.runs.front().knob) + "-isoline silhouette reference:");
  char buf[512];
  std::string head;
  std::snprintf(buf, sizeof buf, "  %-10s %10s %12s", "integrator", "knob", c.counted_costs ? "µs counted" : "µs/integral");
  head = buf;
  for (Product p : c.products) {
    std::snprintf(buf, sizeof buf, " %20s", product_label(p));
    head += buf;
  }
  out.push_back(head);
  for (size_t i = 1; i < c.runs.size(); ++i) {
    const PilotRun& r = c.runs[i];
    std::snprintf(buf, sizeof buf, "  %-10s %10s %12.1f", to_string(r.kind), knob_text(r.kind, r.knob).c_str(),
                  r.cpu_us_per_point);
    std::string line = buf;
    for (double e : r.error) {
      std::snprintf(buf, sizeof buf, " %20.3e", e);
      line += buf;
    }
    out.push_back(line);
  }
  for (const Prediction& p : c.predictions) {
    if (p.pruned)
      std::snprintf(buf, sizeof buf, "  model: %-10s not competitive: at %s it misses the target (error %.3g) at %.1f "
                    "µs/integral, and more rays cannot beat the other",
                    to_string(p.kind), knob_text(p.kind, p.knob).c_str(), p.predicted_error, p.predicted_us_per_point);
    else
      std::snprintf(buf, sizeof buf, "  model: %-10s %s: error %.3g (rate knob^-%.2f), %.1f µs/integral%s", to_string(p.kind),
                    knob_text(p.kind, p.knob).c_str(), p.predicted_error, p.exponent, p.predicted_us_per_point,
                    p.reachable ? "" : " (cannot reach the target in range)");
    out.push_back(buf);
  }
  out.push_back("chosen: " + c.reason);
  if (c.counted_costs)
    out.push_back("  (costs counted from the pilot's work, not timed: the choice is a function of the inputs and the seed)");
  else if (c.margin > 0 && c.margin < 1.25)
    out.push_back(std::string("  (a close call: another run may time it the other way; pin it with integrator ") +
                  to_string(c.spec.kind) + ", samples " + std::to_string(c.spec.samples()) + " for the same bytes everywhere)");
  return out;
}

std::string choice_summary(const IntegratorChoice& c) {
  return format("target error %g: chosen ", c.target) + c.reason + " (pilot on " + std::to_string(c.pilot_points) +
         format(" seeded points, %.2f s)", c.pilot_seconds);
}

std::vector<std::string> target_check_lines(const ErrorReport& report, double target) {
  std::vector<std::string> out;
  for (const ProductError& e : report.products) {
    const double err = error_in_target_units(e);
    // The reference's own noise in the same units (its estimated standard error; QMC's actual
    // error is often well below it): an RMSE above E with noise that large says nothing.
    const double noise = is_radiance(e.product) ? (e.reference_rms > 0 ? e.reference_std_error / e.reference_rms : 0.0)
                                                             : e.reference_std_error;
    const char* verdict = err <= target ? "met" : noise >= 0.5 * target ? "not verifiable here" : "NOT met";
    out.push_back(format("  target %g for ", target) + product_label(e.product) + ": " + verdict + format(" (%.3e", err) +
                  (is_radiance(e.product) ? " relative" : "") +
                  format("; the reference's own estimated noise, included in it, is %.1e", noise) +
                  (err > target && noise >= 0.5 * target ? ": too noisy to tell)" : ")"));
  }
  return out;
}

} // namespace prt::bake
