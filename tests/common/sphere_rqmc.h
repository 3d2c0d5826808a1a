// sphere_rqmc.h — randomised-QMC reference integrals over the unit sphere for tests, with an
// honest standard error: R independent Cranley–Patterson rotations of the same Halton points
// (bake/sphere/sampling.h) give R i.i.d. unbiased estimates; their mean is the estimate and the standard
// deviation of the mean (sample std / √R) its standard error (Owen, "Monte Carlo theory, methods
// and examples", §17.1). The tests use R = 64: the standard error is itself estimated, so the
// deviation in standard errors follows Student's t with R − 1 degrees of freedom, and with 32
// replicates its tail beyond 4 (≈ 3.7e-4 per comparison, over the ~150 comparisons of the suite)
// showed up once; at 64 it is ≈ 1.7e-4. Also the inside test of a convex spherical polygon and a
// random rotation.
#pragma once

#include <bake/sphere/sampling.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <span>
#include <vector>

namespace prt::test {

struct SphereEstimate {
  std::vector<double> mean, std_error;
};

// Estimates ∫_{S²} f_k(ω) dω for k < count, f(ω, out) writing the count values at ω.
template <class F>
SphereEstimate rqmc_sphere(int count, int replicates, uint64_t points, uint64_t seed, F&& f) {
  std::vector<double> values(size_t(count), 0.0), sum(size_t(count), 0.0), sum2(size_t(count), 0.0);
  for (int r = 0; r < replicates; ++r) {
    const bake::RotatedHalton3 halton(seed, uint64_t(r));
    std::vector<double> acc(size_t(count), 0.0);
    for (uint64_t i = 0; i < points; ++i) {
      const auto u = halton(i);
      const Eigen::Vector3d w = bake::uniform_sphere(u[0], u[1]);
      f(w, std::span<double>(values));
      for (int k = 0; k < count; ++k) acc[size_t(k)] += values[size_t(k)];
    }
    for (int k = 0; k < count; ++k) {
      const double est = 4 * std::numbers::pi * acc[size_t(k)] / double(points);
      sum[size_t(k)] += est;
      sum2[size_t(k)] += est * est;
    }
  }
  SphereEstimate out;
  for (int k = 0; k < count; ++k) {
    const double m = sum[size_t(k)] / replicates;
    const double var = std::max(0.0, (sum2[size_t(k)] - replicates * m * m) / (replicates - 1));
    out.mean.push_back(m);
    out.std_error.push_back(std::sqrt(var / replicates));
  }
  return out;
}

// ω inside the convex, positively oriented spherical polygon (every edge plane's inner side).
inline bool inside_convex(std::span<const Eigen::Vector3d> v, const Eigen::Vector3d& w) {
  for (size_t i = 0; i < v.size(); ++i)
    if (v[i].cross(v[(i + 1) % v.size()]).dot(w) < 0) return false;
  return true;
}

// A uniformly random rotation (a normalised Gaussian quaternion).
inline Eigen::Matrix3d random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  return Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix();
}

// r · v for every vertex (a rotated polygon).
inline std::vector<Eigen::Vector3d> rotated(const Eigen::Matrix3d& r, std::span<const Eigen::Vector3d> poly) {
  std::vector<Eigen::Vector3d> out;
  for (const Eigen::Vector3d& v : poly) out.push_back(r * v);
  return out;
}

} // namespace prt::test
