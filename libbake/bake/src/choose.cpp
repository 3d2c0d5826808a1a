// choose.cpp — the target-error chooser (bake/bake/choose.h): a pilot on seeded shade points against a
// reference whose own error is estimated, error models fitted per integrator within stated
// bounds, costs measured, the cheaper prediction chosen and checked; and the error report's
// reference sized for the target.
#include <bake/bake/choose.h>
#include <bake/bake/error_report.h>

#include <bake/core/error.h>
#include <bake/integrators/qmc.h>
#include <bake/integrators/silhouette.h>
#include <bake/sphere/octahedral.h>
#include <bake/sphere/sampling.h>

#include "choose_internal.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <limits>
#include <map>
#include <memory>

#include <unistd.h>

namespace prt::bake {
namespace choose_internal {

// Radiance products (R, S) carry the environment's HDR scale: their errors are relative to their RMS.
bool is_radiance(Product p) { return p == Product::RadianceBand1 || p == Product::RadianceShadowed; }

// The pilot's reference starts at 256 isolines for targets >= 5e-4 (its own AO error, ~6e-5 on
// the bunny, is under a tenth of the aim 0.7·E; its isoline tables take 8 ms to build against
// 190 ms at 512, bench/RESULTS.md bench_integrators), 512 below; it doubles from there while its
// estimated error exceeds E/3 (bake/bake/choose.h step 1).
int reference_isolines(double target) { return target >= 5e-4 ? 256 : 512; }
// Richardson's order, clamped: at least first order (what the integrator shows under HDR suns,
// the slowest it converges), at most second (a ratio of two sampled RMS differences can promise
// more than the integrator delivers).
constexpr double kRichardsonOrderMin = 1.0, kRichardsonOrderMax = 2.0;
// The QMC check (bake/bake/choose.h step 1): over n values with standard errors σ, the mean squared
// difference from an exact reference is σ² with a spread of ~σ²·sqrt(2/n) (Gaussian errors); a
// bias shows only beyond kQmcCheckSigmas of that spread.
constexpr double kQmcCheckSigmas = 3.0;
// The check's rays under an environment: 16,384 (and 4,096) per pilot point, ~0.01 CPU s each.
// On 32 points a band-1 bias from 1.9e-3 (city.exr, a sun of 3·10^4× the mean), 2.5e-3 (sunset)
// and 3.2e-3 (studio) relative up shows (sphereWithHole.stl; sqrt(3 · sd/√K) of the products).
constexpr uint32_t kCheckRays = 16384;
// ... fewer, by octaves down to kCheckRaysMin, where those rays would cost more than
// kCheckBudgetShare × the chosen plan's predicted cost (setup and bake): on a mesh that bakes in
// 0.08 s the check must not be the pilot's largest part (it was 0.35 of 0.64 CPU s on
// sphereWithHole.stl). The detection limit grows as sqrt(kCheckRays / rays) (4× at 1,024), and
// the error report after the bake (bake/bake/target_check.h) verifies the file at E/3 anyway.
constexpr uint32_t kCheckRaysMin = 1024;
constexpr double kCheckBudgetShare = 1.0;
// ... on the first 32 pilot points at most (the seeded sample's order): the bound is a t-test over
// points, whose spread 32 points already estimate, and 128 points would cost 4× the rays.
constexpr size_t kCheckPoints = 32;
constexpr uint64_t kCheckSalt = 0x636865636b736565ull;
// The silhouette levels: 32 and 64 always; 16 only when some product already meets the goal at
// 32 (its bracket is then [16, 32]); doubling levels while some product still misses it (their
// bracket lies above), below the reference level. N_ref/4 and N_ref/2 always run (Richardson).
constexpr int kSilhouetteLow = 16, kSilhouetteFirst[] = {32, 64};
constexpr int kMinIsolines = 8;
// An upper bound on N whatever the memory: N² + N rows must fit size_t arithmetic comfortably
// and int indices in the tables (65,536² ≈ 4.3e9 rows · 8 bytes is 34 GB per component anyway).
constexpr int kMaxIsolinesAbsolute = 65536;
// QMC's levels. 64 first: on the assets the silhouette integrator wins (most), its error there
// (~1-2e-2 AO) already prices QMC out (kQmcBestCaseMargin) at a quarter of 256 rays' cost.
// Beyond 4096 the levels go on by factors of 4 while the goal is missed, as long as the pilot's
// rays (points × rays of the level) stay within kPilotRayBudget: 2^22 rays, ~2-3 CPU s at
// 0.5-0.75 µs per ray — the most a pilot may spend on one level to learn QMC's rate (at 32
// points up to 131,072 rays a level, at 128 points 32,768; the model extrapolates 4× beyond).
constexpr uint32_t kQmcLevels[] = {64, 256, 1024, 4096};
constexpr uint32_t kQmcLevelFactor = 4;
constexpr uint64_t kPilotRayBudget = uint64_t(1) << 22;
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
// The radiance products' RMS over the mesh, which the pilot's relative errors divide by (as the
// error report's do, bake/bake/error_report.h mesh_rms): the silhouette integrator at
// kScaleIsolines on up to kScalePoints seeded points (the pilot's among them). Its own error
// (~1.5e-2 of R at N = 16) moves the scale by as much, and the pilot's 32–128 points alone can
// misjudge it by a factor: on 3DSMaxExport.STL under city.exr the pilot read N = 128 at 1.3e-3
// where the whole mesh is at 6.9e-4, and chose N = 204.
constexpr int kScaleIsolines = 16;
constexpr size_t kScalePoints = 1024;

Rows integrate_pilot(const Integrator& integrator, std::span<const ShadePoint> points,
                     const std::vector<uint32_t>& sample, Task& progress, uint64_t index_offset) {
  const size_t W = integrator.layout().width, K = sample.size();
  Rows rows;
  rows.values.assign(K * W, 0.0);
  rows.std_error.assign(K * W, 0.0);
  std::vector<double> seconds(K, 0.0);
  tbb::parallel_for(size_t(0), K, [&](size_t i) {
    const double t0 = thread_cpu_seconds();
    // The bake's own point index: a QMC pilot row is the row the bake would compute (the report's
    // reference offsets it, compare_points_with_reference).
    integrator.integrate(points[sample[i]], sample[i] + index_offset, std::span(rows.values).subspan(i * W, W),
                         std::span(rows.std_error).subspan(i * W, W));
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
  // The chooser's cost model knows the two kinds it chooses between.
  const auto* silhouette = dynamic_cast<const SilhouetteIntegrator*>(&integrator);
  if (!silhouette) return kCountedUsPerPoint + kCountedUsPerRay * knob;
  const SilhouetteStats st = silhouette->silhouette_stats();
  const double n = double(std::max<uint64_t>(st.points, 1));
  return kCountedUsPerPoint + kCountedUsPerEdge * double(st.contour_edges) / n +
         kCountedUsPerCrossing * double(st.crossings) / n;
}

// Per product: the RMS of value(k) over the product's values k of every row, in the target's
// units (relative to the RMS of `ref` there for the radiance products, bake/bake/choose.h).
template <class Value>
std::vector<double> per_product_rms(const std::vector<double>& ref, size_t W, const std::vector<ProductSlice>& products,
                                    Value value, const std::vector<double>* scale) {
  const size_t K = W ? ref.size() / W : 0;
  std::vector<double> out;
  for (const ProductSlice& p : products) {
    const size_t pi = out.size();
    double e2 = 0, r2 = 0;
    for (size_t i = 0; i < K; ++i)
      for (size_t c = 0; c < p.count; ++c) {
        const size_t k = i * W + p.offset + c;
        const double d = value(k);
        e2 += d * d;
        r2 += ref[k] * ref[k];
      }
    const double n = double(std::max<size_t>(K * p.count, 1));
    double e = std::sqrt(e2 / n);
    if (is_radiance(p.product)) {
      const double rms = scale && (*scale)[pi] > 0 ? (*scale)[pi] : std::sqrt(r2 / n);
      e = rms > 0 ? e / rms : 0.0;
    }
    out.push_back(e);
  }
  return out;
}

// Per product: RMSE of `rows` against `ref` in the target's units.
std::vector<double> pilot_errors(const std::vector<double>& rows, const std::vector<double>& ref, size_t W,
                                 const std::vector<ProductSlice>& products, const std::vector<double>* scale) {
  return per_product_rms(ref, W, products, [&](size_t k) { return rows[k] - ref[k]; }, scale);
}

// Per product: the RMS of `std_error` in the target's units (like pilot_errors).
std::vector<double> pilot_noise(const std::vector<double>& std_error, const std::vector<double>& ref, size_t W,
                                const std::vector<ProductSlice>& products, const std::vector<double>* scale) {
  return per_product_rms(ref, W, products, [&](size_t k) { return std_error[k]; }, scale);
}

double worst_of(const std::vector<double>& v) { return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end()); }

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
  // Faster than the clamp allows (a > hi): the clamped law runs through the lower level, the
  // conservative end (through the upper one it would promise the goal at a knob where the
  // bracket's own line still misses it); model_error() anchors the same way.
  if (std::isfinite(a) && a > hi) return x0 * std::pow(e0 / goal, 1.0 / exponent);
  return x1 * std::pow(e1 / goal, 1.0 / exponent);
}

// The power law's error at `knob` through (x0, e0), (x1, e1), as solve_power_law fits it.
double power_law_error(double x0, double e0, double x1, double e1, double knob, double lo, double hi) {
  double rate = 0;
  solve_power_law(x0, e0, x1, e1, 1.0, lo, hi, rate);
  const double a = e0 > 0 && e1 > 0 ? std::log(e0 / e1) / std::log(x1 / x0) : 0.0;
  if (std::isfinite(a) && a > hi) return e0 * std::pow(x0 / knob, rate);
  return e1 * std::pow(x1 / knob, rate);
}

} // namespace choose_internal

using namespace choose_internal;

namespace detail {
double power_law_knob(double x0, double e0, double x1, double e1, double goal, double lo, double hi) {
  double rate = 0;
  return solve_power_law(x0, e0, x1, e1, goal, lo, hi, rate);
}
double power_law_error_at(double x0, double e0, double x1, double e1, double knob, double lo, double hi) {
  return power_law_error(x0, e0, x1, e1, knob, lo, hi);
}
} // namespace detail

namespace choose_internal {

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
  return power_law_error(xs[i1 - 1], errors[i1 - 1][p], xs[i1], errors[i1][p], knob, lo, hi);
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
                const std::vector<double>& cost_knobs, const std::vector<double>& us,
                const std::vector<double>& offset = {}) {
  pr.knob = knob;
  pr.predicted_error = 0;
  for (size_t p = 0; p < errors.front().size(); ++p)
    pr.predicted_error = std::max(pr.predicted_error, model_error(levels, errors, p, knob, lo, hi) +
                                                          (offset.empty() ? 0.0 : offset[p]));
  double alpha = 0, beta = 0;
  fit_line(cost_knobs, us, alpha, beta);
  pr.predicted_us_per_point = alpha + beta * knob;
}

std::string format(const char* fmt, double a, double b, double c, double d) {
  char buf[256];
  std::snprintf(buf, sizeof buf, fmt, a, b, c, d);
  return buf;
}

std::string knob_text(IntegratorKind kind, uint32_t knob) {
  return kind == IntegratorKind::Qmc ? std::to_string(knob) + " rays" : "N = " + std::to_string(knob);
}

} // namespace choose_internal

double error_in_target_units(const ProductError& e) {
  if (!is_radiance(e.product)) return e.rmse;
  return relative_scale(e) > 0 ? e.rmse / relative_scale(e) : 0.0;
}

size_t isoline_table_bytes(const ProductRequest& r, int isolines) {
  const int n = std::max(2, isolines + (isolines & 1));
  const oct::Grid grid(n);
  size_t rows = 0;
  for (int i = 0; i < n; ++i) rows += size_t(2 * grid.cells_per_sheet(i) + 1);
  const size_t lt = size_t(r.transfer_order), lv = size_t(r.visibility_order), ls = size_t(r.shadowed_order);
  const size_t F = (r.ao ? 3 : 0) + 3 * lt * lt + lv * lv + (r.radiance ? 9 : 0) + 3 * ls * ls;
  return std::max<size_t>(F, 1) * rows * sizeof(double);
}

size_t default_table_memory_budget() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  const double physical = pages > 0 && page > 0 ? double(pages) * double(page) : 32.0 * (1ull << 30);
  return size_t(ChooserOptions::kTableMemoryShare * physical);
}

int max_isolines_for_memory(const ProductRequest& r, size_t budget_bytes) {
  const size_t budget = budget_bytes ? budget_bytes : default_table_memory_budget();
  // rows = N² + N: start from the root and step down to the largest even N that fits.
  const double per_row = double(isoline_table_bytes(r, 2)) / 6.0;  // N = 2: 6 rows
  int n = int(std::min<double>(kMaxIsolinesAbsolute, std::floor(std::sqrt(double(budget) / per_row))));
  n -= n & 1;
  while (n > kMinIsolines && isoline_table_bytes(r, n) > budget) n -= 2;
  return std::max(n, kMinIsolines);
}

PlanPick pick_plan(std::span<const PlanCandidate> c, double target,
                   const std::function<double(const PlanCandidate&)>& measure) {
  PRT_CHECK(!c.empty());
  constexpr size_t none = SIZE_MAX;
  PlanPick pick;
  size_t best = none;
  for (size_t i = 0; i < c.size(); ++i)
    if (c[i].predicted_error <= c[i].aim && (best == none || c[i].cost_seconds < c[best].cost_seconds)) best = i;
  pick.reaches = best != none;
  if (!pick.reaches)  // the lowest predicted error, the cheaper on a tie
    for (size_t i = 0; i < c.size(); ++i)
      if (best == none || c[i].predicted_error < c[best].predicted_error ||
          (c[i].predicted_error == c[best].predicted_error && c[i].cost_seconds < c[best].cost_seconds))
        best = i;
  pick.index = best;
  pick.expected_error = c[best].predicted_error;
  // The sanity check: the cheapest plan of another kind that costs less than 1/kSanityCostRatio
  // of the pick and predicts an error within kSanityErrorFactor·E is measured.
  size_t alt = none;
  for (size_t i = 0; i < c.size(); ++i)
    if (i != best && c[i].kind != c[best].kind &&
        c[i].cost_seconds * ChooserOptions::kSanityCostRatio < c[best].cost_seconds &&
        c[i].predicted_error <= ChooserOptions::kSanityErrorFactor * target &&
        (alt == none || c[i].cost_seconds < c[alt].cost_seconds))
      alt = i;
  if (alt != none && measure) {
    pick.checked = true;
    pick.checked_index = alt;
    pick.checked_error = measure(c[alt]);
    // Taken if it meets its aim, or is no worse than what the pick predicts for itself (at under
    // a quarter of the cost).
    // It reaches if it meets its aim, or if the pick reached and it is no worse than the pick.
    if (pick.checked_error <= c[alt].aim || pick.checked_error <= c[best].predicted_error) {
      pick.switched = true;
      pick.index = alt;
      pick.expected_error = pick.checked_error;
      pick.reaches = pick.checked_error <= c[alt].aim || (pick.reaches && pick.checked_error <= c[best].predicted_error);
    }
  }
  return pick;
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
                         "(its samples) instead of a target error");
  const auto wall0 = std::chrono::steady_clock::now();
  const double E = options.target;
  IntegratorChoice choice;
  choice.target = E;
  choice.spec = base;
  const std::vector<ProductSlice> products = product_slices(ProductLayout(request));
  for (const ProductSlice& p : products) choice.products.push_back(p.product);
  const size_t P = products.size();
  // A 64th of the points, at least 32 and at most pilot_points: the pilot must not cost more than
  // a small part of the bake it tunes (ChooserOptions::kPilotFraction).
  const size_t pilot = std::clamp<size_t>(points.size() / ChooserOptions::kPilotFraction, 32,
                                          std::max<size_t>(options.pilot_points, 32));
  const std::vector<uint32_t> sample = seeded_sample(uint32_t(points.size()), pilot, mix64(base.seed ^ kPilotSalt));
  choice.pilot_points = sample.size();
  const size_t K = sample.size();
  const size_t W = ProductLayout(request).width;
  const double goal_sil = options.safety_silhouette * E, goal_qmc = options.safety_qmc * E;
  const bool want_sil = !options.only || *options.only == IntegratorKind::Silhouette;
  const bool want_qmc = !options.only || *options.only == IntegratorKind::Qmc;
  // Progress: the runs are not known in advance; ~10 is typical (the bar clamps at its total).
  Task progress(monitor, "pilot", 10 * K);

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
  const bool counted = options.counted_costs;
  choice.counted_costs = counted;
  double setup_sil = 0, setup_qmc = 0;

  // Silhouette rows per level, computed once (the reference's levels are also model levels).
  struct SilRun {
    Rows rows;
    double cost = 0;
    std::unique_ptr<SilhouetteIntegrator> integrator;  // kept for the reference level only (Prediction::built)
    double build_seconds = 0;  // its build, wall
    bool fresh = true;         // built as a bake builds it (not from masses another level computed)
  };
  std::map<int, SilRun> sil;
  // The levels share the environment's hot texels and point masses (built once, not per level).
  // A level that read them builds faster than a bake would: a plan's setup is that of the
  // smallest level at or above its N that built its own (sil_setup below).
  const auto env_cache = std::make_shared<SilhouetteEnvCache>();
  // Step 1 keeps its levels' integrators (one of them becomes the reference); only the
  // reference's stays after it, and only when the bake shares the pilot's trees (accel).
  bool keep_integrators = accel != nullptr;
  auto run_sil = [&](int N) -> const SilRun& {
    if (const auto it = sil.find(N); it != sil.end()) return it->second;
    double s = 0;
    SilhouetteOptions so{N, base.seed};
    so.env_cache = env_cache;
    auto integrator = timed_build(
        [&] { return std::make_unique<SilhouetteIntegrator>(mesh, topology, request, so, shared); }, s);
    setup_sil = std::max(setup_sil, s);
    SilRun run;
    run.rows = integrate_pilot(*integrator, points, sample, progress);
    run.cost = cost_per_point(run.rows, *integrator, uint32_t(N), counted);
    run.build_seconds = s, run.fresh = !integrator->masses_from_cache();
    if (keep_integrators) run.integrator = std::move(integrator);
    return sil.emplace(N, std::move(run)).first->second;
  };

  // ---- 1. the reference, and its own error ----
  // With counted costs the whole choice is a function of the inputs: the memory bound too (a fixed
  // budget instead of the machine's share).
  const size_t budget = options.memory_budget_bytes ? options.memory_budget_bytes
                        : options.counted_costs      ? ChooserOptions::kCountedTableMemoryBudget
                                                     : default_table_memory_budget();
  const int mem_max = max_isolines_for_memory(request, budget);
  choice.max_isolines = mem_max;
  choice.max_isolines_reason =
      format("memory: the isoline tables of N = %.0f take %.0f MiB of a %.0f MiB budget", mem_max,
             double(isoline_table_bytes(request, mem_max)) / (1 << 20), double(budget) / (1 << 20)) +
      (options.memory_budget_bytes ? std::string(" (given)")
       : options.counted_costs     ? std::string(" (fixed with counted costs)")
                                   : format(" (%.3g of physical memory)", ChooserOptions::kTableMemoryShare));
  int ref_top = mem_max;
  if (options.max_reference_isolines) ref_top = std::min(ref_top, int(options.max_reference_isolines));
  int N_ref = options.reference_isolines ? int(options.reference_isolines) : reference_isolines(E);
  N_ref = std::max(4 * kMinIsolines, std::min(N_ref + (N_ref & 1), ref_top - (ref_top & 1)));
  std::vector<double> e_ref(P, 0.0), orders(P, kRichardsonOrderMin);
  const double V = double(points.size());
  // The radiance products' RMS over the mesh (kScalePoints above); 0 (the pilot's own points'
  // RMS) where the pilot holds every point or no product is relative.
  std::vector<double> mesh_scale(P, 0.0);
  bool scaled = false;
  auto estimate_scale = [&] {
    if (scaled) return;
    scaled = true;
    if (points.size() <= K || std::none_of(products.begin(), products.end(),
                                           [](const ProductSlice& sl) { return is_radiance(sl.product); }))
      return;
    const std::vector<uint32_t> wide =
        seeded_sample(uint32_t(points.size()), kScalePoints, mix64(base.seed ^ kPilotSalt));  // ⊇ sample
    SilhouetteOptions so{kScaleIsolines, base.seed};
    so.env_cache = env_cache;
    const SilhouetteIntegrator coarse(mesh, topology, request, so, shared);
    const Rows r = integrate_pilot(coarse, points, wide, progress);
    for (size_t p = 0; p < P; ++p) {
      if (!is_radiance(products[p].product)) continue;
      double r2 = 0;
      for (size_t i = 0; i < wide.size(); ++i)
        for (size_t c = 0; c < products[p].count; ++c) r2 += r.values[i * W + products[p].offset + c] * r.values[i * W + products[p].offset + c];
      mesh_scale[p] = std::sqrt(r2 / double(std::max<size_t>(wide.size() * products[p].count, 1)));
    }
  };
  // A small bake: every point at level N costs no more CPU than that level's build (measured, so
  // not with counted costs), so the reference level the pilot built is the cheapest plan there is
  // (Prediction::built). Then the reference stops doubling once it meets the plan's aim — it needs
  // E/3 only to judge other levels, which a small bake does not measure — and no level below it
  // is run but Richardson's two.
  auto small_at = [&](int N) {
    const SilRun& r = sil.at(N);
    return keep_integrators && want_sil && !counted && V * r.cost * 1e-6 <= r.build_seconds;
  };
  bool small = false, reference_is_plan = false;
  for (;;) {
    const std::vector<double>& ref = run_sil(N_ref).rows.values;
    estimate_scale();  // after the first level, which built the environment's masses for the rest
    const std::vector<double>& half = run_sil(N_ref / 2).rows.values;
    const std::vector<double>& quarter = run_sil(N_ref / 4).rows.values;
    const std::vector<double> d = pilot_errors(half, ref, W, products, &mesh_scale), d2 = pilot_errors(quarter, half, W, products, &mesh_scale);
    for (size_t p = 0; p < P; ++p) {
      const double a = d[p] > 0 && d2[p] > 0 ? std::log2(d2[p] / d[p]) : kRichardsonOrderMin;
      orders[p] = std::clamp(std::isfinite(a) ? a : kRichardsonOrderMin, kRichardsonOrderMin, kRichardsonOrderMax);
      e_ref[p] = d[p] / (std::exp2(orders[p]) - 1.0);
    }
    if (worst_of(e_ref) <= ChooserOptions::kReferenceShare * E || 2 * N_ref > ref_top) {
      small = small_at(N_ref);
      break;
    }
    if (worst_of(e_ref) <= goal_sil && small_at(N_ref)) {
      small = reference_is_plan = true;
      break;
    }
    N_ref *= 2;
  }
  choice.reference_is_plan = reference_is_plan;
  choice.reference_isolines = uint32_t(N_ref);
  choice.relative_scale = mesh_scale;
  for (auto& [N, run] : sil)
    if (N != N_ref) run.integrator.reset();
  keep_integrators = false;
  SilRun& ref_run = sil.at(N_ref);
  const std::vector<double>& ref = ref_run.rows.values;
  size_t worst_p = 0;
  for (size_t p = 0; p < P; ++p)
    if (e_ref[p] > e_ref[worst_p]) worst_p = p;
  choice.reference_richardson_order = orders[worst_p];
  const bool ref_capped = worst_of(e_ref) > ChooserOptions::kReferenceShare * E;
  std::string ref_bound;
  if (ref_capped)
    ref_bound = 2 * N_ref > mem_max ? format("N = %.0f would exceed the ", 2 * N_ref) + choice.max_isolines_reason
                                    : format("the reference was held at most at N = %.0f (ChooserOptions)", ref_top);

  // The reference's independent check (bake/bake/choose.h step 1): QMC against it. D² ≈ e_ref² + σ²;
  // an exact reference leaves D² − σ² within kQmcCheckSigmas of its spread σ²·sqrt(2/n).
  std::vector<double> e_qmc(P, 0.0);
  uint32_t qmc_check_rays = 0;
  auto check = [&](const std::vector<double>& qmc_rows, const std::vector<double>& sigma) {
    const std::vector<double> D = pilot_errors(qmc_rows, ref, W, products, &mesh_scale);
    for (size_t p = 0; p < P; ++p) {
      const double n = double(K * products[p].count);
      const double null = sigma[p] * sigma[p] * (1.0 + kQmcCheckSigmas * std::sqrt(2.0 / n));
      e_qmc[p] = std::sqrt(std::max(0.0, D[p] * D[p] - null));
    }
  };
  // (Nothing to check where the reference's radiance is 0 at every pilot point: an enclosed
  // receiver, whose relative errors are 0 by definition.)
  bool any_radiance = false;
  for (const ProductSlice& sl : products)
    if (is_radiance(sl.product))
      for (size_t i = 0; i < K && !any_radiance; ++i)
        for (size_t k = 0; k < sl.count; ++k) any_radiance = any_radiance || ref[i * W + sl.offset + k] != 0.0;
  // A bias the check sees is stated (reference_ok, reference_note), not chased: finer isolines do
  // not remove it, and the QMC reference and the silhouette integrator may differ in how they
  // reconstruct the environment between texels as well as in error; the predictions stay those
  // against the silhouette reference, known only to within it.

  // ---- 2. silhouette levels ----
  std::vector<int> sil_levels;  // ascending, below N_ref
  if (want_sil) {
    auto level_errors = [&](int N) { return pilot_errors(run_sil(N).rows.values, ref, W, products, &mesh_scale); };
    auto misses = [&](int N) { return worst_of(level_errors(N)) > goal_sil; };
    auto meets_any = [&](int N) {
      const std::vector<double> e = level_errors(N);
      return std::any_of(e.begin(), e.end(), [&](double x) { return x <= goal_sil; });
    };
    if (!small) {  // (a small bake's plan is the reference level: Richardson's levels suffice)
      for (int N : kSilhouetteFirst)
        if (N < N_ref) run_sil(N);
      if (N_ref > kSilhouetteLow * 2 && meets_any(std::min(kSilhouetteFirst[0], N_ref / 2))) run_sil(kSilhouetteLow);
      for (int N = kSilhouetteFirst[1]; 2 * N < N_ref && misses(N); N *= 2) run_sil(2 * N);
    }
    for (const auto& [N, run] : sil)
      if (N < N_ref) sil_levels.push_back(N);
    std::vector<double> xs, ts;
    std::vector<std::vector<double>> errors;
    for (int N : sil_levels) {
      choice.runs.push_back({IntegratorKind::Silhouette, uint32_t(N), level_errors(N), sil.at(N).cost});
      xs.push_back(N), ts.push_back(sil.at(N).cost), errors.push_back(choice.runs.back().error);
    }
    Prediction pr;
    pr.kind = IntegratorKind::Silhouette;
    pr.last_measured = uint32_t(xs.back());
    const int extrap = int(ChooserOptions::kMaxExtrapolation * xs.back());
    const int bound = std::min({N_ref, mem_max, extrap});
    pr.bound = uint32_t(bound);
    pr.bound_reason = bound == N_ref ? (ref_capped ? "the reference level (" + ref_bound + ")"
                                                    : std::string("the reference level, whose error is within E/3"))
                      : bound == mem_max ? choice.max_isolines_reason
                                         : format("the extrapolation limit, %.0fx the last measured level",
                                                  ChooserOptions::kMaxExtrapolation);
    double need = kMinIsolines;
    for (size_t p = 0; p < P; ++p) {
      double a = 0;
      const double n = knob_for(xs, errors, p, goal_sil, 0.5, 3.0, a);  // silhouette: rates 0.5 to 3
      if (n > need) need = n, pr.exponent = a;
    }
    pr.reachable = need <= bound;
    if (!pr.reachable) pr.knob_for_target = uint32_t(std::min<double>(need, kMaxIsolinesAbsolute));
    int N = int(std::ceil(std::min<double>(need, bound) - 1e-9));
    N = std::max(kMinIsolines, N + (N & 1));  // even, as the integrator uses it
    N = std::min(N, bound - (bound & 1));
    xs.push_back(N_ref), ts.push_back(ref_run.cost);  // costs: the reference is a measured level too
    predict_at(pr, uint32_t(N), std::vector<double>(xs.begin(), xs.end() - 1), errors, 0.5, 3.0, xs, ts);
    pr.extrapolated = pr.knob > pr.last_measured;
    choice.predictions.push_back(pr);
  }

  // ---- 3. QMC levels ----
  Rows finest_qmc;  // the finest QMC level's rows, for the reference's independent check
  if (want_qmc && !reference_is_plan) {  // (its levels would be judged against a reference above E/3)
    std::vector<double> xs, ts;
    std::vector<std::vector<double>> errors;
    // QMC cannot win once a level that misses the goal already costs more per integral than the
    // silhouette prediction (more rays cost more): the remaining levels are skipped.
    const double rival_us = !choice.predictions.empty() && choice.predictions.front().reachable
                                ? choice.predictions.front().predicted_us_per_point
                                : 0.0;
    bool pruned = false;
    std::vector<uint32_t> levels(std::begin(kQmcLevels), std::end(kQmcLevels));
    for (size_t li = 0; li < levels.size(); ++li) {
      const uint32_t R = levels[li];
      if (!errors.empty()) {
        const double worst = worst_of(errors.back());
        const bool misses = worst > goal_qmc;
        // Or once even the best case its model allows (rate 1, the top of its clamp: R·worst/goal
        // rays at this level's cost per ray) costs kQmcBestCaseMargin times the prediction.
        if (misses && rival_us > 0 && (ts.back() >= rival_us || ts.back() * (worst / goal_qmc) >= kQmcBestCaseMargin * rival_us)) {
          pruned = true;
          break;
        }
        if (!misses && errors.size() >= 2) break;  // two levels and the goal met: enough to interpolate
      }
      if (double(K) * R > double(kPilotRayBudget) && !errors.empty()) break;
      double s = 0;
      const auto integrator =
          timed_build([&] { return std::make_unique<QmcIntegrator>(mesh, topology, request, QmcOptions{R, base.seed}, shared); }, s);
      setup_qmc = std::max(setup_qmc, s);
      Rows r = integrate_pilot(*integrator, points, sample, progress);
      choice.runs.push_back({IntegratorKind::Qmc, R, pilot_errors(r.values, ref, W, products, &mesh_scale),
                             cost_per_point(r, *integrator, R, counted)});
      xs.push_back(R), ts.push_back(choice.runs.back().cpu_us_per_point), errors.push_back(choice.runs.back().error);
      finest_qmc = std::move(r);
      // On past the fixed levels by factors of 4 while the goal is missed (the loop's checks stop it).
      if (li + 1 == levels.size() && uint64_t(R) * kQmcLevelFactor <= kMaxRays) levels.push_back(R * kQmcLevelFactor);
    }
    Prediction pr;
    pr.kind = IntegratorKind::Qmc;
    pr.last_measured = uint32_t(xs.back());
    if (pruned) {
      pr.pruned = true;
      pr.knob = uint32_t(xs.back());
      pr.predicted_error = worst_of(errors.back());
      pr.predicted_us_per_point = ts.back();
      pr.bound = pr.knob;
    } else if (xs.size() < 2) {  // one level only (the pilot's ray budget): its own numbers
      pr.knob = uint32_t(xs.back());
      pr.predicted_error = worst_of(errors.back());
      pr.predicted_us_per_point = ts.back();
      pr.bound = pr.knob;
      pr.bound_reason = "the pilot's ray budget (one level measured)";
      pr.reachable = pr.predicted_error <= goal_qmc;
    } else {
      const double bound = std::min<double>(kMaxRays, ChooserOptions::kMaxExtrapolation * xs.back());
      pr.bound = uint32_t(bound);
      pr.bound_reason = bound == kMaxRays ? std::string("the ray bound 2^26")
                                          : format("the extrapolation limit, %.0fx the last measured level (the pilot's "
                                                   "ray budget stopped its levels)",
                                                   ChooserOptions::kMaxExtrapolation);
      double need = kMinRays;
      for (size_t p = 0; p < P; ++p) {
        double rate = 0;
        const double r = knob_for(xs, errors, p, goal_qmc, 0.5, 1.0, rate);  // QMC: rates 0.5 to 1
        if (r > need) need = r, pr.exponent = rate;
      }
      pr.reachable = need <= bound;
      if (!pr.reachable) pr.knob_for_target = uint32_t(std::min<double>(need, 4294967040.0));
      predict_at(pr, std::min(round_up_rays(std::min(need, bound)), uint32_t(bound)), xs, errors, 0.5, 1.0, xs, ts);
    }
    pr.extrapolated = pr.knob > pr.last_measured;
    choice.predictions.push_back(pr);
  }

  // ---- 5. the pick ----
  if (counted) {
    // Counted setup is the trees' (calibrated on whole builds): none when the bake reuses them.
    setup_sil = accel ? 0.0 : kCountedSetupPerTriangleSilhouette * double(mesh.triangles.size());
    setup_qmc = accel ? 0.0 : kCountedSetupPerTriangleQmc * double(mesh.triangles.size());
  }
  const double trees_sil = counted || accel ? 0.0 : rays_seconds + contours_seconds;
  if (!counted && !accel) setup_qmc += rays_seconds;
  // A silhouette plan's setup: a bake builds its tables afresh, like the smallest pilot level at
  // or above its N that built its own (the first level of each sub-sample count fills the shared
  // masses; its build is what a bake's costs: the masses and a few more cells than N needs).
  // Without one (counted costs), setup_sil: the largest build.
  auto sil_setup = [&](uint32_t N) {
    if (counted) return setup_sil;
    for (const auto& [n, run] : sil)
      if (n >= int(N) && run.fresh) return run.build_seconds + trees_sil;
    return setup_sil + trees_sil;
  };
  auto cost = [&](const Prediction& p) {
    return (p.built ? 0.0 : p.kind == IntegratorKind::Silhouette ? sil_setup(p.knob) : setup_qmc) +
           V * p.predicted_us_per_point * 1e-6;
  };
  // The reference level as the silhouette plan (Prediction::built): no setup, the reference's
  // own estimated error. Taken where it meets the aim (or errs less than a plan that misses it)
  // at no more than the model's plan costs with its setup.
  for (Prediction& p : choice.predictions) {
    if (p.kind != IntegratorKind::Silhouette || !ref_run.integrator) continue;
    Prediction r = p;
    r.knob = uint32_t(N_ref), r.built = true, r.extrapolated = false;
    r.predicted_error = worst_of(e_ref), r.predicted_us_per_point = ref_run.cost;
    r.reachable = r.predicted_error <= goal_sil;
    if (reference_is_plan || ((r.reachable || (!p.reachable && r.predicted_error < p.predicted_error)) && cost(r) <= cost(p)))
      p = r;
  }
  std::vector<PlanCandidate> candidates;
  for (const Prediction& p : choice.predictions)
    candidates.push_back({p.kind, p.knob, p.predicted_error,
                          p.kind == IntegratorKind::Silhouette ? goal_sil : goal_qmc, cost(p)});
  // The sanity check's measurement: a plan's error against the reference on the pilot points; at
  // or above the reference level a silhouette plan is compared with itself, so its error is the
  // reference's own estimate.
  auto measure = [&](const PlanCandidate& c) {
    if (c.kind == IntegratorKind::Silhouette) {
      std::vector<double> e = pilot_errors(run_sil(int(c.knob)).rows.values, ref, W, products, &mesh_scale);
      if (int(c.knob) >= N_ref)
        for (size_t p = 0; p < P; ++p) e[p] = std::max(e[p], e_ref[p]);
      return worst_of(e);
    }
    for (const PilotRun& r : choice.runs)
      if (r.kind == IntegratorKind::Qmc && r.knob == c.knob) return worst_of(r.error);
    const QmcIntegrator integrator(mesh, topology, request, QmcOptions{c.knob, base.seed}, shared);
    return worst_of(pilot_errors(integrate_pilot(integrator, points, sample, progress).values, ref, W, products, &mesh_scale));
  };
  const PlanPick pick = pick_plan(candidates, E, measure);
  if (request.environment() && any_radiance) {
    // Its rays: kCheckRays, fewer (by octaves, at least kCheckRaysMin) where those would cost more
    // than the plan it protects (cost(best), the bake's predicted CPU seconds with its setup): a
    // 285-triangle mesh bakes in 0.08 s, and 32 × 20,480 rays took 0.35 s. The rays' cost: the
    // pilot's QMC levels' per-ray cost (counted: kCountedUsPerRay).
    const Prediction& planned = choice.predictions[pick.index];
    double us_per_ray = kCountedUsPerRay;
    if (!counted)
      for (const PilotRun& r : choice.runs)
        if (r.kind == IntegratorKind::Qmc && r.knob > 0) us_per_ray = r.cpu_us_per_point / double(r.knob);
    const double check_points = double(std::min(K, kCheckPoints));
    uint32_t check_rays = kCheckRays;
    while (check_rays > kCheckRaysMin &&
           check_points * 1.25 * check_rays * us_per_ray * 1e-6 > kCheckBudgetShare * cost(planned))
      check_rays /= 2;
    // Under an environment the hot texels are integrated apart from the isolines (bake/
    // silhouette.h), so their error need not shrink with N and Richardson cannot see it. Two
    // independent QMC runs f, c (kCheckRays and a quarter of it): their noises are independent of
    // each other and of the reference's error b, so the mean of (f − ref)(c − ref) is b² — no
    // convergence rate assumed — with the spread of its per-point means (below).
    const QmcIntegrator fine(mesh, topology, request, QmcOptions{check_rays, mix64(base.seed ^ kCheckSalt)}, shared);
    const QmcIntegrator coarse(mesh, topology, request, QmcOptions{check_rays / 4, mix64(base.seed ^ kCheckSalt ^ 1)},
                               shared);
    const std::vector<uint32_t> check_sample(sample.begin(), sample.begin() + std::min(K, kCheckPoints));
    const size_t Kc = check_sample.size();
    const Rows f = integrate_pilot(fine, points, check_sample, progress);
    const Rows c = integrate_pilot(coarse, points, check_sample, progress);
    for (size_t p = 0; p < P; ++p) {
      const ProductSlice& sl = products[p];
      // Per pilot point i: x_i = the mean over its values of (f − ref)(c − ref). The values of one
      // point share its rays (one sun sample moves all nine band-1 numbers), so the points, not
      // the values, are the independent draws: b² ≥ mean(x) − kQmcCheckSigmas · sd(x)/√K.
      std::vector<double> x(Kc, 0.0);
      double r2 = 0;
      for (size_t i = 0; i < Kc; ++i)
        for (size_t k = 0; k < sl.count; ++k) {
          const size_t j = i * W + sl.offset + k;
          x[i] += (f.values[j] - ref[j]) * (c.values[j] - ref[j]);
          r2 += ref[j] * ref[j];
        }
      const double n = double(std::max<size_t>(Kc * sl.count, 1));
      r2 /= n;
      // Relative, like pilot_errors, for R and S.
      double scale = 1.0 / double(std::max<size_t>(sl.count, 1));
      if (is_radiance(sl.product)) {
        const double s2 = mesh_scale[p] > 0 ? mesh_scale[p] * mesh_scale[p] : r2;
        scale = s2 > 0 ? scale / s2 : 0.0;
      }
      double mean = 0, var = 0;
      for (double& xi : x) xi *= scale, mean += xi;
      mean /= double(std::max<size_t>(Kc, 1));
      for (const double xi : x) var += (xi - mean) * (xi - mean);
      var /= double(std::max<size_t>(Kc, 2) - 1);
      e_qmc[p] = std::sqrt(std::max(0.0, mean - kQmcCheckSigmas * std::sqrt(var / double(std::max<size_t>(Kc, 1)))));
    }
    qmc_check_rays = check_rays;
  }
  if (qmc_check_rays == 0 && !finest_qmc.values.empty()) {
    // Without one, the pilot's finest QMC level with its estimated standard errors (which
    // overstate QMC's noise: a check that sees only gross biases, at no extra cost).
    for (const PilotRun& r : choice.runs)
      if (r.kind == IntegratorKind::Qmc) qmc_check_rays = std::max(qmc_check_rays, r.knob);
    check(finest_qmc.values, pilot_noise(finest_qmc.std_error, ref, W, products, &mesh_scale));
  }
  choice.reference_error.resize(P);
  for (size_t p = 0; p < P; ++p) choice.reference_error[p] = std::max(e_ref[p], e_qmc[p]);
  choice.reference_ok = worst_of(choice.reference_error) <= ChooserOptions::kReferenceShare * E;
  choice.runs.insert(choice.runs.begin(),
                     PilotRun{IntegratorKind::Silhouette, uint32_t(N_ref), choice.reference_error, ref_run.cost});
  choice.reference_note =
      format("estimated error %.2e (Richardson from N = %.0f, order %.2f", worst_of(choice.reference_error), N_ref / 2,
             choice.reference_richardson_order) +
      (qmc_check_rays ? format("; QMC check at %.0f rays: %.2e", qmc_check_rays, worst_of(e_qmc)) : std::string()) + ")" +
      (choice.reference_ok ? format(", within E/3 = %.2e", ChooserOptions::kReferenceShare * E)
       : reference_is_plan ? format(", within the aim %.2e but not E/3: a small bake, whose plan is this level (every "
                                    "point at it costs no more than building a finer one)", goal_sil)
                           : format(", ABOVE E/3 = %.2e: ", ChooserOptions::kReferenceShare * E) +
                                 (worst_of(e_qmc) > worst_of(e_ref)
                                      ? std::string("the QMC check disagrees with the reference by more than finer "
                                                    "isolines would change (a bias, or another reconstruction of the "
                                                    "environment between texels)")
                                      : ref_bound) +
                                 "; the pilot's errors are known only to within it");

  progress.finish();
  const Prediction& best = choice.predictions[pick.index];
  if (best.built) {
    ref_run.integrator->reset_stats();  // the bake's work summary counts the bake's integrals only
    choice.integrator = std::move(ref_run.integrator);
  }
  ref_run.integrator.reset();
  choice.spec.kind = best.kind;
  if (best.kind == IntegratorKind::Silhouette)
    choice.spec.silhouette_k = best.knob * best.knob;
  else
    choice.spec.qmc_rays = best.knob;
  choice.reaches = pick.reaches;
  choice.expected_error = pick.expected_error;
  const Prediction* other = nullptr;
  for (const Prediction& p : choice.predictions)
    if (&p != &best && p.reachable && !p.pruned) other = &p;
  choice.margin = other ? cost(*other) / std::max(cost(best), 1e-12) : 0.0;
  if (pick.checked) {
    const Prediction& alt = choice.predictions[pick.checked_index];
    const Prediction& first = choice.predictions[pick.switched ? 1 - pick.checked_index : pick.index];
    choice.sanity_switched = pick.switched;
    choice.sanity = "sanity check: " + std::string(to_string(alt.kind)) + " at " + knob_text(alt.kind, alt.knob) +
                    format(" costs %.2f CPU s against %.2f for ", cost(alt), cost(first)) + to_string(first.kind) +
                    " at " + knob_text(first.kind, first.knob) +
                    format(" and predicts %.3g; measured on the pilot: %.3g, ", alt.predicted_error, pick.checked_error) +
                    (pick.switched ? "taken" : "not taken (it misses its aim and the other's prediction)");
  }
  const std::string knob = best.kind == IntegratorKind::Silhouette
                               ? format("N = %.0f isolines (k = %.0f)", best.knob, double(best.knob) * best.knob)
                               : format("%.0f rays", best.knob);
  choice.reason = std::string(to_string(best.kind)) + " at " + knob + ": " +
                  (pick.switched ? "measured" : best.built ? "the pilot's reference level, its estimated" : "predicted") +
                  format(" error %.2g (target %g), %.1f µs per integral, %.2f CPU s for the bake", pick.expected_error, E,
                         best.predicted_us_per_point, cost(best)) +
                  (best.built ? " (its tables already built: cheaper than a lower N's fresh build)" : "");
  if (pick.switched)
    choice.reason += "; taken by the sanity check over the " + std::string(to_string(choice.predictions[1 - pick.index].kind)) +
                     format(" plan (%.1fx its cost)", cost(choice.predictions[1 - pick.index]) / std::max(cost(best), 1e-12));
  else if (other)
    choice.reason += format("; %.2fx cheaper than ", choice.margin) + to_string(other->kind) + " at " +
                     (other->kind == IntegratorKind::Silhouette ? format("N = %.0f", other->knob) : format("%.0f rays", other->knob));
  else if (!options.only && choice.predictions.size() > 1 && choice.predictions.back().pruned)
    choice.reason += format("; qmc at %.0f rays costs %.1f µs per integral and misses the target by %.1fx: more rays "
                            "cannot beat it",
                            choice.predictions.back().knob, choice.predictions.back().predicted_us_per_point,
                            choice.predictions.back().predicted_error / E);
  else if (!options.only && choice.predictions.size() > 1)
    choice.reason += "; the other integrator cannot reach the target within its bound";
  if (pick.checked && !pick.switched) {
    const Prediction& alt = choice.predictions[pick.checked_index];
    choice.reason += "; the sanity check measured " + std::string(to_string(alt.kind)) + " at " +
                     knob_text(alt.kind, alt.knob) +
                     format(" (%.1fx cheaper): %.3g, not taken", cost(best) / std::max(cost(alt), 1e-12), pick.checked_error);
  }
  if (!choice.reaches) {
    // A default never refuses: the best plan within the bounds, the error it expects, and the way on.
    choice.reason += format("; the target is NOT reached: expected error %.2g against the aim %.2g (the target times "
                            "its safety factor)",
                            choice.expected_error, best.kind == IntegratorKind::Silhouette ? goal_sil : goal_qmc) +
                     " (" +
                     knob_text(best.kind, best.knob) + " is at its bound: " + best.bound_reason + ")";
    std::string f;
    for (const Prediction& p : choice.predictions) {
      if (p.pruned || !p.knob_for_target) continue;
      if (!f.empty()) f += ", or ";
      if (p.kind == IntegratorKind::Qmc)
        f += format("integrator qmc with samples %.0f (the model's extrapolation to the aim: ~%.0f CPU s)",
                    p.knob_for_target, V * (p.predicted_us_per_point / std::max(1.0, double(p.knob))) * p.knob_for_target * 1e-6);
      else
        f += format("integrator silhouette at N = %.0f (samples %.0f; its tables would take %.0f MiB)", p.knob_for_target,
                    double(p.knob_for_target) * p.knob_for_target,
                    double(isoline_table_bytes(request, int(p.knob_for_target))) / (1 << 20));
    }
    if (!f.empty()) f += ", or ";
    choice.further = "to go further: " + f + format("a target error of %.2g or more", std::max(E, 1.05 * choice.expected_error));
  }
  choice.pilot_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return choice;
}

std::vector<std::string> choice_lines(const IntegratorChoice& c) {
  std::vector<std::string> out;
  out.push_back("target error " + format("%g", c.target) + ": pilot on " + std::to_string(c.pilot_points) +
                " seeded points took " + format("%.2f s", c.pilot_seconds) + "; error per product against a " +
                std::to_string(c.reference_isolines) + "-isoline silhouette reference:");
  out.push_back("  reference N = " + std::to_string(c.reference_isolines) + ": " + c.reference_note);
  char buf[512];
  std::string head;
  std::snprintf(buf, sizeof buf, "  %-10s %10s %12s", "integrator", "knob", c.counted_costs ? "µs counted" : "µs/integral");
  head = buf;
  for (Product p : c.products) {
    std::snprintf(buf, sizeof buf, " %20s", product_label(p));
    head += buf;
  }
  out.push_back(head);
  for (size_t i = 0; i < c.runs.size(); ++i) {
    const PilotRun& r = c.runs[i];
    std::snprintf(buf, sizeof buf, "  %-10s %10s %12.1f", i == 0 ? "reference" : to_string(r.kind),
                  knob_text(r.kind, r.knob).c_str(), r.cpu_us_per_point);
    std::string line = buf;
    for (double e : r.error) {
      std::snprintf(buf, sizeof buf, " %20.3e", e);
      line += buf;
    }
    if (i == 0) line += "  (its estimated own error)";
    out.push_back(line);
  }
  for (const Prediction& p : c.predictions) {
    if (p.pruned)
      std::snprintf(buf, sizeof buf, "  model: %-10s not competitive: at %s it misses the target (error %.3g) at %.1f "
                    "µs/integral, and more rays cannot beat the other",
                    to_string(p.kind), knob_text(p.kind, p.knob).c_str(), p.predicted_error, p.predicted_us_per_point);
    else {
      std::string note;
      if (p.extrapolated) note += "; extrapolated beyond the last measured " + knob_text(p.kind, p.last_measured);
      if (!p.reachable)
        note += "; cannot reach the target within its bound " + knob_text(p.kind, p.bound) + ": " + p.bound_reason;
      if (p.built)
        std::snprintf(buf, sizeof buf, "  model: %-10s %s: the reference level itself, already built (no setup): its "
                      "estimated error %.3g, %.1f µs/integral", to_string(p.kind), knob_text(p.kind, p.knob).c_str(),
                      p.predicted_error, p.predicted_us_per_point);
      else
        std::snprintf(buf, sizeof buf, "  model: %-10s %s: error %.3g (rate knob^-%.2f), %.1f µs/integral", to_string(p.kind),
                      knob_text(p.kind, p.knob).c_str(), p.predicted_error, p.exponent, p.predicted_us_per_point);
      out.push_back(buf + note);
      continue;
    }
    out.push_back(buf);
  }
  if (!c.sanity.empty()) out.push_back("  " + c.sanity);
  out.push_back("chosen: " + c.reason);
  if (!c.further.empty()) out.push_back("  " + c.further);
  if (!c.reference_ok && !c.reference_is_plan)
    out.push_back(format("  (the pilot's reference is not within E/3: its estimated error is %.2e, so the errors above "
                         "are only known to within it)",
                         c.reference_error.empty() ? 0.0 : *std::max_element(c.reference_error.begin(), c.reference_error.end())));
  if (c.counted_costs)
    out.push_back("  (costs counted from the pilot's work, not timed: the choice is a function of the inputs and the seed)");
  else if (c.margin > 0 && c.margin < 1.25)
    out.push_back(std::string("  (a close call: another run may time it the other way; pin it with integrator ") +
                  to_string(c.spec.kind) + ", samples " + std::to_string(c.spec.samples()) + " for the same bytes everywhere)");
  return out;
}

std::string choice_summary(const IntegratorChoice& c) {
  std::string line = format("target error %g: chosen ", c.target) + c.reason;
  if (!c.further.empty()) line += "; " + c.further;
  if (!c.reference_ok) line += "; the pilot's reference N = " + std::to_string(c.reference_isolines) + " is not within E/3";
  return line + " (pilot on " + std::to_string(c.pilot_points) + format(" seeded points, %.2f s)", c.pilot_seconds);
}

} // namespace prt::bake
