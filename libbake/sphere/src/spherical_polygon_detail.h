// spherical_polygon_detail.h — private helpers shared by spherical_polygon.cpp and
// polygon_sh.cpp: the unit vertices of a polygon (no heap allocation up to kInline vertices)
// and the integrals on them (formulas in bake/sphere/spherical_polygon.h).
#pragma once

#include <bake/sphere/spherical_polygon.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <utility>

namespace prt::bake::detail {

// The vertices of a spherical polygon scaled to unit length (each must be finite and non-zero:
// PRT_CHECK).
class UnitPolygon {
public:
  explicit UnitPolygon(std::span<const Eigen::Vector3d> vertices);
  UnitPolygon(const UnitPolygon&) = delete;
  UnitPolygon& operator=(const UnitPolygon&) = delete;
  std::span<const Eigen::Vector3d> span() const { return {data(), n_}; }

private:
  static constexpr size_t kInline = 32;
  Eigen::Vector3d* data() { return n_ > kInline ? heap_.data() : inline_.data(); }
  const Eigen::Vector3d* data() const { return n_ > kInline ? heap_.data() : inline_.data(); }
  size_t n_;
  std::array<Eigen::Vector3d, kInline> inline_;
  std::vector<Eigen::Vector3d> heap_;
};

// 2Φ(P) = Σ θ_i u_i for unit vertices (the cancellation-free form of the header).
Eigen::Vector3d twice_vector_irradiance(std::span<const Eigen::Vector3d> unit);

// Ω(P) for unit vertices.
double solid_angle_unit(std::span<const Eigen::Vector3d> unit);

// θ u = (θ/sin θ)(a × b) for the arc between unit a and b (0 for a = b).
Eigen::Vector3d arc_moment(const Eigen::Vector3d& a, const Eigen::Vector3d& b);

// Signed solid angle of the spherical triangle (c, a, b), unit vectors (Van Oosterom & Strackee,
// the determinant from differences).
inline double triangle_solid_angle(const Eigen::Vector3d& c, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double det = c.dot((a - c).cross(b - c));
  const double den = 1.0 + c.dot(a) + a.dot(b) + b.dot(c);
  return 2.0 * std::atan2(det, den);
}

// 2π plus the fan's rounding (each of its terms is correct to a few ulps of 2π): a sum above it
// is the negatively oriented case; a hemisphere (Ω = 2π, a boundary on a great circle) is taken
// with the orientation of Φ, i.e. as +2π.
constexpr double kHemisphere = 2 * std::numbers::pi * (1 + 1e-12);

// The solid angle by the fan about Φ/|Φ| (2Φ = twice_phi) of the n arcs arc(i) → {a, b}, unit
// vectors. The fan counts winding numbers relative to −c: a positively oriented region (around c)
// gives Ω ∈ (0, 2π]; a negatively oriented one lies around −c and gives 4π − |Ω| ∈ [2π, 4π).
template <class ArcAt>
double fan_solid_angle(const Eigen::Vector3d& twice_phi, size_t n, ArcAt&& arc) {
  const double len = twice_phi.norm();
  if (len == 0) return 0;  // a null chain (e.g. fewer than three distinct vertices)
  const Eigen::Vector3d c = twice_phi / len;
  double omega = 0;
  for (size_t i = 0; i < n; ++i) {
    const auto [a, b] = arc(i);
    omega += triangle_solid_angle(c, a, b);
  }
  return omega > kHemisphere ? omega - 4 * std::numbers::pi : omega;
}

} // namespace prt::bake::detail
