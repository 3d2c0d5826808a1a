// target_check.cpp — the check of a target error (bake/bake/choose.h): the error report's
// reference sized by its measured noise (plan_report_reference), the verdict per product with the
// reference's noise taken out (target_verdicts, target_check_lines), pooled reports of a scene's
// receivers, and the corrected plan when the check finds the target missed.
#include <bake/bake/choose.h>
#include <bake/bake/error_report.h>
#include <bake/core/error.h>
#include <bake/integrators/qmc.h>
#include <bake/sphere/sampling.h>

#include "choose_internal.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

namespace prt::bake {

using namespace choose_internal;

ReferencePlan plan_report_reference(std::span<const ShadePoint> points, const Mesh& mesh, const Topology& topology,
                                    const ProductRequest& request, const IntegratorSpec& spec, double target,
                                    const Monitor& monitor, const MeshAccel* accel, uint64_t ray_budget,
                                    double cpu_seconds) {
  PRT_CHECK(target > 0);
  PRT_CHECK(!request.empty());
  PRT_CHECK(cpu_seconds >= 0);
  ReferencePlan plan;
  plan.target = target;
  IntegratorSpec base = spec;
  base.report_rays = 0;
  // Never fewer than the default reference, or with a CPU bound than the probe's finer level (the
  // rays are then sized by measured noise alone, and the verdict includes that noise).
  const uint32_t floor_rays = cpu_seconds > 0 ? ReferencePlan::kReportProbeRaysFine : base.reference_rays();
  // The report's own points (compare_points_with_reference), their first kReportProbePoints.
  const std::vector<uint32_t> vertices = seeded_sample(uint32_t(points.size()), spec.report_points, spec.seed);
  plan.points = vertices.size();
  plan.rays = floor_rays;
  if (vertices.empty()) return plan;
  const std::vector<uint32_t> probe(vertices.begin(),
                                    vertices.begin() + std::min<size_t>(vertices.size(), ReferencePlan::kReportProbePoints));
  const auto t0 = std::chrono::steady_clock::now();
  constexpr uint32_t R1 = ReferencePlan::kReportProbeRays, R2 = ReferencePlan::kReportProbeRaysFine;
  const QmcIntegrator coarse(mesh, topology, request, QmcOptions{R1, mix64(spec.reference_seed() ^ kProbeSalt)}, accel);
  const QmcIntegrator fine(mesh, topology, request, QmcOptions{R2, spec.reference_seed()}, accel);
  Task progress(monitor, "reference probe", 2 * probe.size());
  // The report's point indices (offset by the point count: the reference's randomisation).
  const Rows a = integrate_pilot(coarse, points, probe, progress, points.size());
  const Rows b = integrate_pilot(fine, points, probe, progress, points.size());
  progress.finish();
  plan.probe_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const std::vector<ProductSlice> products = product_slices(ProductLayout(request));
  const size_t W = coarse.layout().width;
  // d² = σ1² + σ2² with σ ∝ rays^-1/2: σ1² = d² / (1 + R1/R2).
  const std::vector<double> d = pilot_errors(a.values, b.values, W, products);
  const std::vector<double> est = pilot_noise(b.std_error, b.values, W, products);
  const double aim = ChooserOptions::kReferenceShare * target;
  std::vector<double> sigma1(products.size());
  double need = floor_rays;
  for (size_t p = 0; p < products.size(); ++p) {
    plan.products.push_back(products[p].product);
    plan.probe_values.push_back(probe.size() * products[p].count);
    sigma1[p] = d[p] / std::sqrt(1.0 + double(R1) / double(R2));
    // σ(R) = σ1·sqrt(R1/R) ≤ aim  ⇔  R ≥ R1·(σ1/aim)².
    const double r = double(R1) * (sigma1[p] / aim) * (sigma1[p] / aim);
    plan.rays_needed.push_back(uint64_t(std::ceil(std::min(r, 1e18))));
    need = std::max(need, r);
  }
  plan.ray_budget = ray_budget ? ray_budget : ReferencePlan::kReportRayBudget;
  plan.us_per_ray = b.cpu_us_per_point / double(R2);
  if (cpu_seconds > 0) {
    // The rays `cpu_seconds` buys at the probe's measured CPU cost per ray (its finer level), at
    // least the probe's own rays on every report point.
    const double us_per_ray = std::max(b.cpu_us_per_point / double(R2), 1e-6);
    const uint64_t affordable =
        std::max<uint64_t>(uint64_t(std::min(cpu_seconds * 1e6 / us_per_ray, 1e18)), uint64_t(R2) * plan.points);
    if (affordable < plan.ray_budget) plan.ray_budget = affordable, plan.cpu_bound = true;
    plan.cpu_seconds = cpu_seconds;
  }
  const uint64_t cap = std::max<uint64_t>(floor_rays, plan.ray_budget / plan.points);
  uint32_t rays = round_up_rays(need);
  if (rays > cap) rays = uint32_t(std::min<uint64_t>(cap, kMaxRays));
  plan.rays = std::max(rays, floor_rays);
  for (size_t p = 0; p < products.size(); ++p) {
    plan.noise.push_back(sigma1[p] * std::sqrt(double(R1) / double(plan.rays)));
    plan.estimator_noise.push_back(est[p] * std::sqrt(double(R2) / double(plan.rays)));
    if (plan.noise.back() > aim) plan.budget_bound = true;
  }
  return plan;
}

void pool_product_errors(std::vector<ProductError>& into, std::span<const ProductError> add) {
  for (const ProductError& a : add) {
    auto it = std::find_if(into.begin(), into.end(), [&](const ProductError& e) { return e.product == a.product; });
    if (it == into.end()) {
      into.push_back(a);
      continue;
    }
    const double n0 = double(it->values), n1 = double(a.values), n = std::max(n0 + n1, 1.0);
    auto rms = [&](double x0, double x1) { return std::sqrt((n0 * x0 * x0 + n1 * x1 * x1) / n); };
    it->rmse = rms(it->rmse, a.rmse);
    it->reference_rms = rms(it->reference_rms, a.reference_rms);
    it->mesh_rms = 0;  // the pooled rows' own: the caller's (BakePipeline sets it over every row)
    it->bake_std_error = rms(it->bake_std_error, a.bake_std_error);
    it->reference_std_error = rms(it->reference_std_error, a.reference_std_error);
    it->max_abs = std::max(it->max_abs, a.max_abs);
    it->values += a.values;
    if (it->finer != a.finer || it->finer_knob != a.finer_knob) it->finer = 0, it->finer_knob = 0;  // not one level: no extrapolation
    it->finer_points += a.finer_points;
  }
}

std::vector<TargetVerdict> target_verdicts(const ErrorReport& report, double target, const ReferencePlan* plan) {
  std::vector<TargetVerdict> out;
  for (const ProductError& e : report.products) {
    TargetVerdict v;
    v.product = e.product;
    const double m = v.measured = error_in_target_units(e);  // the measured RMSE, the reference's noise in it
    // The reference's own noise σ in the same units. Measured on the report's own values (two
    // independent halves, ErrorReport::reference_noise_measured). m² − σ² is then the difference of
    // two independent estimates of σ² from n draws each (the halves' mean and their difference
    // are uncorrelated), each with a standard deviation σ²·sqrt(2/n) for Gaussian noise: e² is
    // known to ±δσ², δ = 3·sqrt(4/n) (3 standard deviations of the difference). Else an
    // upper bound: the plan's probe scaled at Monte Carlo's rate (the slowest QMC shows), or QMC's
    // estimator (which overstates it) — then it cannot be subtracted, only bound the error below.
    v.noise_measured = report.reference_noise_measured;
    double sigma = is_radiance(e.product) ? (e.reference_std_error > 0 && relative_scale(e) > 0
                                                 ? e.reference_std_error / relative_scale(e)
                                                 : 0.0)
                                          : e.reference_std_error;
    v.noise_kind = v.noise_measured ? "measured on these values" : "QMC's estimate, an upper bound";
    if (!v.noise_measured && plan)
      for (size_t p = 0; p < plan->products.size(); ++p)
        if (plan->products[p] == e.product && p < plan->noise.size())
          sigma = plan->noise[p], v.noise_kind = "the probe's, an upper bound";
    v.noise = sigma;
    if (e.finer > 1) {
      const double f = e.finer;
      v.extrapolated = true, v.finer = f, v.finer_knob = e.finer_knob, v.finer_points = e.finer_points;
      v.noise_measured = false;
      v.noise_kind = "the finer level's own error, at order 1 to 2";
      v.noise = m / (f - 1.0);
      v.error_lo = m / (1.0 - 1.0 / (f * f));
      v.error = v.error_hi = m / (1.0 - 1.0 / f);
      v.met = v.error_hi <= target;
      v.not_met = v.error_lo > target;
      out.push_back(v);
      continue;
    }
    // n counts independent draws: the report's points, not its values (a point's values share its
    // rays — one sun sample moves all nine band-1 numbers — so they are not independent).
    const size_t draws = report.vertices.empty() ? e.values : std::min(e.values, report.vertices.size());
    const double delta = v.noise_measured ? 3.0 * std::sqrt(4.0 / double(std::max<size_t>(draws, 1))) : 0.0;
    // m² = e² + σ² (independent errors): the bake's own error e with the noise removed, and the
    // range it lies in. Met when its top is within E (always when m <= E), NOT met when its
    // bottom exceeds E, else the reference cannot tell.
    auto less_noise = [&](double factor) { return std::sqrt(std::max(0.0, m * m - sigma * sigma * factor)); };
    v.error = v.noise_measured ? less_noise(1.0) : m;
    v.error_hi = v.noise_measured ? less_noise(std::max(0.0, 1.0 - delta)) : m;
    v.error_lo = less_noise(1.0 + delta);
    v.met = v.error_hi <= target;
    v.not_met = v.error_lo > target;
    out.push_back(v);
  }
  return out;
}

namespace {

// What a verdict's numbers are: the bake's own error (the reference's noise taken out) and the
// range it lies in, from what was measured.
std::string verdict_numbers(const TargetVerdict& v) {
  std::string line;
  if (v.extrapolated)
    line += format("the bake's own error %.2e to ", v.error_lo) + format("%.2e, from its RMSE ", v.error_hi) +
            format("%.3e against the same integrator at %.0fx its isolines (N = ", v.measured, v.finer) +
            format("%.0f) on ", double(v.finer_knob)) + format("%.0f points, which converges at order 1 to 2 ", double(v.finer_points)) +
            "(a QMC reference within E/3 would take too many rays)";
  else if (v.noise_measured)
    line += format("the bake's own error %.2e", v.error) + format(" (%.2e to ", v.error_lo) +
            format("%.2e), ", v.error_hi) + format("the measured RMSE %.3e less the reference's own noise ", v.measured) +
            format("%.1e (", v.noise) + v.noise_kind + ") in quadrature";
  else
    line += format("the measured RMSE %.3e, which includes the reference's own noise (", v.measured) +
            format("%.1e, ", v.noise) + v.noise_kind + format("): the bake's own error is %.2e to ", v.error_lo) +
            format("%.2e", v.measured);
  return line;
}

} // namespace

std::vector<std::string> error_estimate_lines(const ErrorReport& report) {
  std::vector<std::string> out;
  // No target: only the numbers of target_verdicts, whose met / NOT met are not used.
  for (const TargetVerdict& v : target_verdicts(report, 1.0))
    out.push_back(std::string("  ") + product_label(v.product) + (is_radiance(v.product) ? " (relative)" : "") + ": " +
                  verdict_numbers(v));
  return out;
}

std::vector<std::string> target_check_lines(const ErrorReport& report, double target, const ReferencePlan* plan) {
  std::vector<std::string> out;
  for (const TargetVerdict& v : target_verdicts(report, target, plan)) {
    const char* verdict = v.met ? "met" : v.not_met ? "NOT met" : "not verifiable here";
    std::string line = format("  target %g for ", target) + product_label(v.product) +
                       (is_radiance(v.product) ? " (relative)" : "") + ": " + verdict + ": " + verdict_numbers(v);
    if (!v.met && !v.not_met) {
      line += ": the reference is too noisy to tell";
      if (plan)
        for (size_t p = 0; p < plan->products.size(); ++p)
          if (plan->products[p] == v.product && plan->rays_needed[p] > plan->rays)
            line += format("; E/3 would need %.3g rays per point, %.3g in all, over the report's budget of %.3g rays",
                           double(plan->rays_needed[p]), double(plan->rays_needed[p]) * double(plan->points),
                           double(plan->ray_budget ? plan->ray_budget : ReferencePlan::kReportRayBudget)) +
                    (plan->cpu_bound ? format(" (what %.3g CPU s buy: the check may take as long as the bake)", plan->cpu_seconds)
                                     : std::string());
    }
    out.push_back(line);
  }
  return out;
}

std::optional<IntegratorSpec> corrected_plan(const IntegratorChoice& choice, const IntegratorSpec& baked,
                                             std::span<const TargetVerdict> verdicts, const CheckedPlan* previous) {
  const ChooserOptions defaults;
  const bool silhouette = choice.spec.kind == IntegratorKind::Silhouette;
  if (!silhouette && choice.spec.kind != IntegratorKind::Qmc) return std::nullopt;
  if (baked.kind != choice.spec.kind) return std::nullopt;
  const auto knob = [&](const IntegratorSpec& s) { return silhouette ? double(s.isolines()) : double(s.qmc_rays); };
  const double aim = (silhouette ? defaults.safety_silhouette : defaults.safety_qmc) * choice.target;
  double ratio = 0;  // the worst product's error over the aim, where it is (likely) above E
  const TargetVerdict* worst = nullptr;
  for (const TargetVerdict& v : verdicts)
    if ((v.not_met || ((v.noise_measured || v.extrapolated) && v.error > choice.target)) && v.error / aim > ratio)
      ratio = v.error / aim, worst = &v;
  if (!(ratio > 1)) return std::nullopt;
  const Prediction* pred = nullptr;
  for (const Prediction& p : choice.predictions)
    if (p.kind == choice.spec.kind) pred = &p;
  if (!pred) return std::nullopt;
  // The model's rate, at least Monte Carlo's 1/2 (a slower one would promise a smaller step) ...
  double rate = std::max(pred->exponent, 0.5);
  // ... or, slower, the rate the last two checks measured on the same product (the model is the
  // worst product's fit on the pilot's points, which can promise more than the check then sees).
  if (previous && previous->spec.kind == baked.kind && knob(previous->spec) < knob(baked))
    for (const TargetVerdict& v : previous->verdicts)
      if (v.product == worst->product && v.error > 0 && worst->error > 0) {
        const double measured = std::log(v.error / worst->error) / std::log(knob(baked) / knob(previous->spec));
        if (std::isfinite(measured)) rate = std::clamp(measured, 0.5, rate);
      }
  const double factor = std::pow(ratio, 1.0 / rate);
  IntegratorSpec spec = baked;
  const double bound = pred->bound > 0 ? double(pred->bound) : std::numeric_limits<double>::infinity();
  if (silhouette) {
    const double N = knob(baked);
    const double raised = std::min(std::ceil(N * factor / 2) * 2, bound);
    if (!(raised > N)) return std::nullopt;
    spec.set_samples(uint32_t(raised) * uint32_t(raised));
  } else {
    const double R = knob(baked);
    const double raised = std::min(std::ceil(R * factor), std::min(bound, double(kMaxRays)));
    if (!(raised > R)) return std::nullopt;
    spec.set_samples(uint32_t(raised));
  }
  return spec;
}

} // namespace prt::bake
