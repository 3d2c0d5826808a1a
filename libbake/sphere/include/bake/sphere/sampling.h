// bake/sphere/sampling.h — low-discrepancy points and direction warps for the QMC baseline integrator
// (paper 001 §5: "generate and warp deterministic Halton distributions ... at each shade point").
//
// The Halton points are randomised per shade point by a Cranley–Patterson rotation (a toroidal
// shift by a uniform offset) derived from (seed, shade-point index) with a counter-based hash.
// That makes every per-point estimate unbiased — so its error can be compared with a standard
// error — and independent of which thread computes which point (same seed → same bytes).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>
#include <vector>

namespace prt::bake {

// SplitMix64 finaliser (Steele, Lea & Flood 2014): a bijective 64-bit mixer.
constexpr uint64_t mix64(uint64_t x) noexcept {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}
// Uniform double in [0,1) from the top 53 bits.
constexpr double to_unit(uint64_t x) noexcept { return double(x >> 11) * 0x1.0p-53; }

// Radical inverse of i in a prime base, exact in double for i < 2^53.
inline double radical_inverse(uint64_t i, uint32_t base) noexcept {
  const double inv = 1.0 / base;
  double f = inv, r = 0;
  while (i) {
    r += double(i % base) * f;
    i /= base;
    f *= inv;
  }
  return r < 1.0 ? r : std::nextafter(1.0, 0.0);
}

// A 3D Halton sequence (bases 2, 3, 5) shifted modulo 1 by a per-point offset.
class RotatedHalton3 {
public:
  RotatedHalton3(uint64_t seed, uint64_t point) noexcept {
    const uint64_t h = mix64(seed ^ mix64(point + 0x632be59bd9b4e019ull));
    shift_ = {to_unit(mix64(h + 1)), to_unit(mix64(h + 2)), to_unit(mix64(h + 3))};
  }
  std::array<double, 3> operator()(uint64_t i) const noexcept {
    static constexpr uint32_t kBases[3] = {2, 3, 5};
    std::array<double, 3> u;
    for (int d = 0; d < 3; ++d) {
      double v = radical_inverse(i, kBases[d]) + shift_[d];
      u[d] = v >= 1.0 ? v - 1.0 : v;
    }
    return u;
  }

private:
  std::array<double, 3> shift_;
};

// Orthonormal basis (t, b, n) around a unit n (Duff et al. 2017, "Building an orthonormal basis,
// revisited"), continuous except at n.z = -1 where it stays valid.
struct Frame {
  Eigen::Vector3d t, b, n;
  explicit Frame(const Eigen::Vector3d& nn) : n(nn) {
    const double s = std::copysign(1.0, n.z());
    const double a = -1.0 / (s + n.z());
    const double c = n.x() * n.y() * a;
    t = {1.0 + s * n.x() * n.x() * a, s * c, -s * n.x()};
    b = {c, s + n.y() * n.y() * a, -n.y()};
  }
  Eigen::Vector3d to_world(const Eigen::Vector3d& l) const { return l.x() * t + l.y() * b + l.z() * n; }
};

// Cosine-weighted hemisphere around +z (Malley's method over Shirley's concentric disk map):
// pdf = cos θ / π.
inline Eigen::Vector3d cosine_hemisphere(double u0, double u1) noexcept {
  const double a = 2 * u0 - 1, b = 2 * u1 - 1;
  double r, phi;
  if (a == 0 && b == 0) return {0, 0, 1};
  if (std::abs(a) > std::abs(b)) {
    r = a;
    phi = (std::numbers::pi / 4) * (b / a);
  } else {
    r = b;
    phi = (std::numbers::pi / 2) - (std::numbers::pi / 4) * (a / b);
  }
  const double x = r * std::cos(phi), y = r * std::sin(phi);
  return {x, y, std::sqrt(std::max(0.0, 1 - x * x - y * y))};
}

// Uniform hemisphere around +z: pdf = 1 / 2π.
inline Eigen::Vector3d uniform_hemisphere(double u0, double u1) noexcept {
  const double z = u0, r = std::sqrt(std::max(0.0, 1 - z * z)), phi = 2 * std::numbers::pi * u1;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

// Uniform sphere: pdf = 1 / 4π.
inline Eigen::Vector3d uniform_sphere(double u0, double u1) noexcept {
  const double z = 1 - 2 * u0, r = std::sqrt(std::max(0.0, 1 - z * z)), phi = 2 * std::numbers::pi * u1;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

// Distinct indices in [0, n), min(k, n) of them, chosen by seed (partial Fisher–Yates), sorted.
std::vector<uint32_t> seeded_sample(uint32_t n, size_t k, uint64_t seed);

} // namespace prt::bake
