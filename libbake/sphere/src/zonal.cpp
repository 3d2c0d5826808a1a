// zonal.cpp — see bake/sphere/zonal.h for the closed forms and their sources.
#include <bake/core/error.h>
#include <bake/sphere/zonal.h>

#include <prtshade/glossy.h>
#include <prtshade/sh.h>

#include <cmath>
#include <numbers>

namespace prt::bake {

std::vector<double> clamped_power_moments(double s, int order) {
  PRT_CHECK(s >= 0 && std::isfinite(s));
  PRT_CHECK(order >= 0);
  std::vector<double> I(size_t(order), 0.0);
  shade::clamped_power_moments(s, order, I.data());  // the runtime's recurrence: one definition
  return I;
}

double clamped_power_energy_beyond(double s, int order) {
  const std::vector<double> I = clamped_power_moments(s, order);
  double inside = 0;
  for (int l = 0; l < order; ++l) inside += double(2 * l + 1) * I[size_t(l)] * I[size_t(l)];
  // Σ over all l of (2l+1) I_l² equals ∫_0^1 t^{2s} dt · 2 = 2/(2s+1) (Parseval on [−1, 1] with
  // the kernel zero for t < 0), so the fraction inside is (2s+1)/2 · Σ_{l<L}.
  return std::max(0.0, 1.0 - inside * (2.0 * s + 1.0) / 2.0);
}

int clamped_power_order(double s, double tolerance, int max_order) {
  PRT_CHECK(tolerance > 0 && max_order >= 1);
  const std::vector<double> I = clamped_power_moments(s, max_order);
  double inside = 0;
  for (int L = 1; L <= max_order; ++L) {
    inside += double(2 * L - 1) * I[size_t(L - 1)] * I[size_t(L - 1)];
    if (1.0 - inside * (2.0 * s + 1.0) / 2.0 <= tolerance) return L;
  }
  return 0;
}

void clamped_power_sh(double s, int order, const Eigen::Vector3d& n, std::span<double> out) {
  PRT_CHECK_OP(out.size(), >=, size_t(sh::num_coeffs(order)));
  if (order == 0) return;
  const std::vector<double> I = clamped_power_moments(s, order);
  sh::eval(order, n.x(), n.y(), n.z(), out);
  for (int l = 0; l < order; ++l) {
    const double lambda = 2.0 * std::numbers::pi * I[size_t(l)];
    for (int m = -l; m <= l; ++m) out[size_t(sh::index(l, m))] *= lambda;
  }
}

} // namespace prt::bake
