// quadrature.cpp — Gauss–Legendre nodes and weights (prtshade/quadrature.h).
#include <prtshade/quadrature.h>

#include "check.h"

#include <cmath>
#include <numbers>

namespace prt::shade {

void gauss_legendre(int n, double a, double b, std::vector<double>& x, std::vector<double>& w) {
  PRT_SHADE_REQUIRE(n >= 1, "n must be >= 1");
  x.assign(size_t(n), 0.0);
  w.assign(size_t(n), 0.0);
  for (int i = 0; i < n; ++i) {
    double z = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5)), dp = 1;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1, p1 = z;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (z * p1 - p0) / (z * z - 1);  // p1 = P_n(z), p0 = P_{n−1}(z)
      const double step = p1 / dp;
      z -= step;
      if (std::abs(step) < 1e-16) break;
    }
    x[size_t(i)] = 0.5 * (a + b) - 0.5 * (b - a) * z;
    w[size_t(i)] = (b - a) / ((1 - z * z) * dp * dp);
  }
}

} // namespace prt::shade
