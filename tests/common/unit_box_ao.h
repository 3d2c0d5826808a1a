// unit_box_ao.h — the closed-form AO beside the unit box [−½, ½]² × [0, 1] standing on the plane
// z = 0 (unit_box_obj.h): 1 − (1/π) Σ ∫ n·ω over the box faces a floor point sees (Lambert's
// formula for spherical polygons), written here rather than taken from the library
// (bake/sphere/spherical_polygon.h), so the tests of per-texel bakes are independent of it.
#pragma once

#include <array>
#include <cmath>
#include <numbers>
#include <vector>

namespace prt::testing {

// Three doubles, enough vector algebra for the closed form (tools' tests use no Eigen).
struct Vector3d {
  double v[3] = {0, 0, 0};
  Vector3d() = default;
  Vector3d(double x, double y, double z) : v{x, y, z} {}
  double operator[](int i) const { return v[i]; }
  double x() const { return v[0]; }
  double y() const { return v[1]; }
  Vector3d operator-(const Vector3d& o) const { return {v[0] - o.v[0], v[1] - o.v[1], v[2] - o.v[2]}; }
  Vector3d operator+(const Vector3d& o) const { return {v[0] + o.v[0], v[1] + o.v[1], v[2] + o.v[2]}; }
  Vector3d operator/(double s) const { return {v[0] / s, v[1] / s, v[2] / s}; }
  double dot(const Vector3d& o) const { return v[0] * o.v[0] + v[1] * o.v[1] + v[2] * o.v[2]; }
  Vector3d cross(const Vector3d& o) const {
    return {v[1] * o.v[2] - v[2] * o.v[1], v[2] * o.v[0] - v[0] * o.v[2], v[0] * o.v[1] - v[1] * o.v[0]};
  }
  double norm() const { return std::sqrt(dot(*this)); }
  Vector3d normalized() const { return *this / norm(); }
};

// ∫_P (n·ω) dω of a spherical polygon (unit vertices, either orientation): Lambert's formula,
// ½ |Σ_i θ_i n·(v_i × v_{i+1}) / |v_i × v_{i+1}||, θ_i the arc between consecutive vertices —
// written here again so the test does not use the library's (bake/sphere/spherical_polygon.h).
inline double cosine_integral(const std::vector<Vector3d>& v, const Vector3d& n) {
  double sum = 0;
  for (size_t i = 0; i < v.size(); ++i) {
    const Vector3d& a = v[i];
    const Vector3d& b = v[(i + 1) % v.size()];
    const Vector3d c = a.cross(b);
    sum += std::atan2(c.norm(), a.dot(b)) * n.dot(c) / c.norm();
  }
  return std::abs(sum) / 2;
}

inline double ao_closed_form(const Vector3d& p) {
  const std::array<std::array<Vector3d, 4>, 4> faces = {{
      {{{0.5, -0.5, 0}, {0.5, 0.5, 0}, {0.5, 0.5, 1}, {0.5, -0.5, 1}}},
      {{{-0.5, 0.5, 0}, {-0.5, -0.5, 0}, {-0.5, -0.5, 1}, {-0.5, 0.5, 1}}},
      {{{0.5, 0.5, 0}, {-0.5, 0.5, 0}, {-0.5, 0.5, 1}, {0.5, 0.5, 1}}},
      {{{-0.5, -0.5, 0}, {0.5, -0.5, 0}, {0.5, -0.5, 1}, {-0.5, -0.5, 1}}},
  }};
  const std::array<Vector3d, 4> normals = {Vector3d(1, 0, 0), Vector3d(-1, 0, 0), Vector3d(0, 1, 0), Vector3d(0, -1, 0)};
  double blocked = 0;
  for (size_t f = 0; f < 4; ++f) {
    if (normals[f].dot(p - (faces[f][0] + faces[f][2]) / 2) <= 0) continue;
    std::vector<Vector3d> rel;
    for (const Vector3d& v : faces[f]) rel.push_back((v - p).normalized());
    blocked += cosine_integral(rel, Vector3d(0, 0, 1));
  }
  return 1 - blocked / std::numbers::pi;
}

} // namespace prt::testing
