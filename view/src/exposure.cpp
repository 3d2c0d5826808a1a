// exposure.cpp — the fixed exposure of prtview's pictures (view/exposure.h).
#include <view/exposure.h>

#include <bake/core/error.h>
#include <bake/environment/irradiance.h>

#include <Eigen/Geometry>
#include <tbb/parallel_for.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <vector>

namespace prt::view {

using Eigen::Vector3d;

double round_significant(double x, int digits) {
  PRT_CHECK(std::isfinite(x) && x > 0 && digits >= 1 && digits <= 17);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*e", digits - 1, x);
  return std::strtod(buf, nullptr);
}

EnvironmentExposure environment_exposure(const bake::EnvMap& env) {
  const bake::UnshadowedIrradiance irradiance(env);
  const auto brightness = [&](const Vector3d& n) {
    return bake::luminance(irradiance(n)) * std::numbers::inv_pi;
  };
  // A spherical Fibonacci lattice: z uniform in (−1, 1), azimuth by the golden angle.
  constexpr int kLattice = 256;
  std::vector<double> value(kLattice);
  const auto lattice = [](int i) {
    const double z = 1.0 - (2.0 * i + 1.0) / kLattice, r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = i * std::numbers::pi * (3.0 - std::sqrt(5.0));
    return Vector3d(r * std::cos(phi), z, r * std::sin(phi));
  };
  tbb::parallel_for(0, kLattice, [&](int i) { value[size_t(i)] = brightness(lattice(i)); });
  int best = 0;
  for (int i = 1; i < kLattice; ++i)
    if (value[size_t(i)] > value[size_t(best)]) best = i;
  Vector3d n = lattice(best);
  double b = value[size_t(best)];
  int moves = 0;
  // Compass search in the tangent plane (at most 400 steps: it cannot wander).
  for (double step = 0.1; step >= 1e-3 && moves < 400; ++moves) {
    const Vector3d t1 = n.unitOrthogonal(), t2 = n.cross(t1);
    bool moved = false;
    for (int k = 0; k < 8 && !moved; ++k) {
      const double a = k * std::numbers::pi / 4;
      const Vector3d m = (n + step * (std::cos(a) * t1 + std::sin(a) * t2)).normalized();
      const double v = brightness(m);
      if (v > b) b = v, n = m, moved = true;
    }
    if (!moved) step *= 0.5;
  }
  EnvironmentExposure r;
  r.brightest = b;
  r.normal = n;
  r.exposure = b > 0 && std::isfinite(b) ? round_significant(1.0 / b, 4) : 1.0;
  return r;
}

} // namespace prt::view
