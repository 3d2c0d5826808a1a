// Small scenes and closed forms shared by the integrator tests.
#pragma once

#include <bake/mesh/mesh.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace prt::testing {

// Flat square grid in the plane z, (2n+1)² vertices over [-h, h]², two triangles per cell.
inline bake::Mesh grid(int n, float h, float z = 0) {
  std::vector<Eigen::Vector3f> p;
  std::vector<std::array<uint32_t, 3>> t;
  const int m = 2 * n + 1;
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i) p.emplace_back(-h + 2 * h * i / (m - 1), -h + 2 * h * j / (m - 1), z);
  for (int j = 0; j + 1 < m; ++j)
    for (int i = 0; i + 1 < m; ++i) {
      const uint32_t a = uint32_t(j * m + i), b = a + 1, c = a + uint32_t(m) + 1, d = a + uint32_t(m);
      t.push_back({a, b, c});
      t.push_back({a, c, d});
    }
  return bake::make_mesh(std::move(p), std::move(t), "grid");
}
inline uint32_t grid_centre(int n) { return uint32_t((2 * n + 1) * n + n); }

// A closed, consistently wound axis-aligned box [lo, hi]³ (8 vertices, 12 triangles, outward
// normals).
inline bake::Mesh box(Eigen::Vector3f lo, Eigen::Vector3f hi, std::string name = "box") {
  std::vector<Eigen::Vector3f> p;
  for (int k = 0; k < 8; ++k) p.emplace_back(k & 1 ? hi.x() : lo.x(), k & 2 ? hi.y() : lo.y(), k & 4 ? hi.z() : lo.z());
  std::vector<std::array<uint32_t, 3>> t = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                                             {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  return bake::make_mesh(std::move(p), std::move(t), std::move(name));
}

// Lambert's formula: the cosine-weighted fraction of the hemisphere (p, n) covered by a planar
// polygon, F = 1/(2π) Σ_i angle(r_i, r_{i+1}) · (n · unit(r_i × r_{i+1})).
inline double polygon_form_factor(const Eigen::Vector3d& p, const Eigen::Vector3d& n,
                                  const std::vector<Eigen::Vector3d>& poly) {
  double f = 0;
  for (size_t i = 0; i < poly.size(); ++i) {
    const Eigen::Vector3d a = (poly[i] - p).normalized(), b = (poly[(i + 1) % poly.size()] - p).normalized();
    const Eigen::Vector3d c = a.cross(b);
    f += std::atan2(c.norm(), a.dot(b)) * n.dot(c.normalized());
  }
  return std::abs(f) / (2 * std::numbers::pi);
}

// Closed forms for an unoccluded shade point with n = +z (order-3 SH, index l(l+1)+m):
// diffuse transfer T_0 = 1/(2√π) = 0.282095, T_2 = √3/(3√π) = 0.325735, T_6 = √5/(8√π) = 0.157696,
// every other T_i = 0; visibility transfer U_0 = √π; AO = 1.
inline double unoccluded_transfer_z(int i) {
  const double rpi = std::sqrt(std::numbers::pi);
  return i == 0 ? 1 / (2 * rpi) : i == 2 ? std::sqrt(3.0) / (3 * rpi) : i == 6 ? std::sqrt(5.0) / (8 * rpi) : 0.0;
}

} // namespace prt::testing
