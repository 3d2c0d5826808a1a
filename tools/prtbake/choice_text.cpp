// choice_text.cpp — prtbake's lines about --target-error (choice_text.h).
#include "choice_text.h"

#include <cstdio>

namespace prt::tool {

void print_choice(const bake::IntegratorChoice& c, const std::string& label) {
  const char* l = label.c_str();
  std::printf("%starget error %g: pilot on %zu seeded vertices took %.2f s; error per product against a %u-isoline "
              "silhouette reference:\n",
              l, c.target, c.pilot_points, c.pilot_seconds, c.runs.empty() ? 0u : c.runs.front().knob);
  std::printf("%s  %-10s %10s %12s", l, "integrator", "knob", "µs/integral");
  for (bake::Product p : c.products) std::printf(" %20s", bake::product_label(p));
  std::printf("\n");
  for (size_t i = 1; i < c.runs.size(); ++i) {
    const bake::PilotRun& r = c.runs[i];
    std::printf("%s  %-10s %10s %12.1f", l, bake::to_string(r.kind),
                (std::to_string(r.knob) + (r.kind == bake::IntegratorKind::Qmc ? " rays" : " N")).c_str(),
                r.cpu_us_per_point);
    for (double e : r.error) std::printf(" %20.3e", e);
    std::printf("\n");
  }
  for (const bake::Prediction& p : c.predictions)
    if (p.pruned)
      std::printf("%s  model: %-10s not competitive: at %u rays it misses the target and already costs more\n", l,
                  bake::to_string(p.kind), p.knob);
    else
      std::printf("%s  model: %-10s %s %u: error %.3g (rate N^-%.2f), %.1f µs/integral%s\n", l, bake::to_string(p.kind),
                p.kind == bake::IntegratorKind::Qmc ? "rays" : "N =", p.knob, p.predicted_error, p.exponent,
                p.predicted_us_per_point, p.reachable ? "" : " (cannot reach the target in range)");
  std::printf("%schosen: %s\n", l, c.reason.c_str());
  if (c.margin > 0 && c.margin < 1.25)
    std::printf("%s  (a close call: another run may time it the other way; pin it with --integrator %s --samples %u "
                "for the same bytes everywhere)\n",
                l, bake::to_string(c.spec.kind), c.spec.samples());
}

void print_target_check(const bake::ErrorReport& report, double target, const std::string& label) {
  for (const bake::ProductError& e : report.products) {
    const double err = bake::error_in_target_units(e);
    std::printf("%s  target %g for %s: %s (%.3e%s; the reference's own noise, included, is %.1e)\n", label.c_str(),
                target, bake::product_label(e.product), err <= target ? "met" : "NOT met", err,
                e.product == bake::Product::RadianceBand1 ? " relative" : "", e.reference_std_error);
  }
}

} // namespace prt::tool
