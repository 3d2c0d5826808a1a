// bake/sphere/octahedral.h — the octahedral parameterisation of the sphere and its u-isolines
// (paper 001 §3.3, Figure 6): directions are mapped by (u, v) = (x, y)/(|x|+|y|+|z|), one sheet
// per sign of z. Within an octant the map is projective, so a great-circle arc is a straight
// segment in (u, v): edge/isoline crossings need no trigonometry.
//
// Isoline grid with N isolines (k = N² samples): u_i = −1 + (i + ½) h, h = 2/N. Isoline i has
// half-length ℓ_i = 1 − |u_i| and is walked as ONE closed loop with parameter t ∈ [0, 4ℓ_i):
//   sheet 0 (z ≥ 0): t = v + ℓ_i          (v from −ℓ_i up to +ℓ_i)
//   sheet 1 (z < 0): t = 3ℓ_i − v         (v from +ℓ_i back down to −ℓ_i)
// It starts (t = 0) on the "spine", the half equator z = 0, y < 0, at (u_i, −ℓ_i, 0). Along t it
// is cut in cells of width h: M_i = 2ℓ_i/h = N − |2i + 1 − N| cells per sheet (an integer for
// even N). Sign convention everywhere: a zero coordinate counts as positive (z = 0 is sheet 0).
//
// Solid angle: for q = (u, v, ±(1−|u|−|v|)), dω = du dv / |q|³ (q·(q_u × q_v) = 1), so
// J(u, v) = (u² + v² + (1−|u|−|v|)²)^(−3/2). (Paper 001 prints the exponent as +1.5.)
#pragma once

#include <Eigen/Core>
#include <cmath>

namespace prt::bake::oct {

inline double sgn0(double x) noexcept { return x < 0 ? -1.0 : 1.0; }  // sign with sgn0(0) = +1

// int(std::ceil(x)) for |x| < 2³¹, without the rounding sequence std::ceil compiles to on
// x86-64 without SSE4.1: truncation, then one up when that fell below x.
inline int ceil_int(double x) noexcept {
  const int k = int(x);
  return double(k) < x ? k + 1 : k;
}

// Unnormalised direction of (u, v) on a sheet (0: z ≥ 0, 1: z < 0).
inline Eigen::Vector3d dir_from_uv(double u, double v, int sheet) noexcept {
  const double z = 1.0 - std::abs(u) - std::abs(v);
  return {u, v, sheet == 0 ? z : -z};
}
inline double jacobian(double u, double v) noexcept {
  const double z = 1.0 - std::abs(u) - std::abs(v);
  const double q2 = u * u + v * v + z * z;
  return 1.0 / (q2 * std::sqrt(q2));
}

struct Grid {
  int n = 0;       // isolines
  double h = 0;    // isoline spacing and cell width, 2/n
  explicit Grid(int isolines) : n(isolines), h(2.0 / isolines) {}
  double u(int i) const noexcept { return -1.0 + (i + 0.5) * h; }
  double half_length(int i) const noexcept { return 1.0 - std::abs(u(i)); }
  int cells_per_sheet(int i) const noexcept { return n - std::abs(2 * i + 1 - n); }
  // Loop parameter of (v, sheet) on isoline i, and back.
  double t_of(int i, double v, int sheet) const noexcept {
    const double l = half_length(i);
    return sheet == 0 ? v + l : 3 * l - v;
  }
  // d q / d t along the loop at (v, sheet): the direction of travel, unnormalised.
  static Eigen::Vector3d loop_tangent(double v, int sheet) noexcept {
    return sheet == 0 ? Eigen::Vector3d(0, 1, -sgn0(v) * (v == 0 ? 0 : 1))
                      : Eigen::Vector3d(0, -1, -sgn0(v) * (v == 0 ? 0 : 1));
  }
  // First isoline index with u_i ≥ u.
  int first_at_or_after(double u) const noexcept { return ceil_int((u + 1.0) / h - 0.5); }
};

// The spine (z = 0, y < 0) as a path in u: q(u) = (u, −(1−|u|), 0); its direction of travel.
inline Eigen::Vector3d spine_tangent(double u) noexcept { return {1, u < 0 ? -1.0 : u > 0 ? 1.0 : 0.0, 0}; }

} // namespace prt::bake::oct
