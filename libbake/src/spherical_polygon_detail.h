// spherical_polygon_detail.h — private helpers shared by spherical_polygon.cpp and
// polygon_sh.cpp: the unit vertices of a polygon (no heap allocation up to kInline vertices)
// and the integrals on them (formulas in bake/spherical_polygon.h).
#pragma once

#include <bake/spherical_polygon.h>

#include <array>
#include <cstddef>

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

} // namespace prt::bake::detail
