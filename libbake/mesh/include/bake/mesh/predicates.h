// bake/mesh/predicates.h — exact geometric predicates: the orientation of a point against a
// triangle's plane, exactly and in the limit p + εn (+ ε²t) from which a shade point sees the
// mesh (docs/ARCHITECTURE.md §3). Every visibility decision of the contour search
// (bake/visibility/contour.h), the ray counts (bake/visibility/raycast.h), the occluder unions
// (bake/visibility/occluder_mesh.h) and the mesh's own degeneracy checks (bake/mesh/mesh.h) rests
// on these signs, so they live below all of them.
//
// Exactness (Shewchuk 1997): D0 = det(A, B, C), A = a − p, … is evaluated in double with the
// orient3d filter |D0 − D0~| ≤ (7 + 56u)u · permanent (u = 2⁻⁵³; the permanent Σ|adz|(|bdx·cdy| +
// |cdx·bdy|) + … is computed). A zero permanent means every product has a zero factor, so D0 = 0
// exactly. When the filter cannot decide, D0 is recomputed exactly with floating-point expansions
// (two_diff, two_product by FMA, grow/scale expansion with zero elimination). D1 = −n·((b−a)×(c−a))
// has the same shape with one exact row (n): the same filter bound, the same exact fallback.
#pragma once

#include <bake/mesh/shade_point.h>

#include <Eigen/Core>

#include <cmath>

namespace prt::bake {

// Exact sign of det(a−p, b−p, c−p) seen from p + εn as ε → 0+: the sign of
// D0 = det(a−p, b−p, c−p) if it is non-zero, else the sign of its ε-derivative
// D1 = −[det(n, B, C) + det(A, n, C) + det(A, B, n)] = −n·((b−a)×(c−a)) (A = a−p, …), else 0.
// A floating-point filter with Shewchuk's proven error bound decides almost every call; when it
// cannot, the determinant is evaluated exactly with floating-point expansions (Shewchuk 1997).
// Exact for any finite double inputs whose products do not overflow or underflow (always true
// for float mesh positions and points of comparable magnitude). Thread-safe, no allocation.
// With a tie-break direction t (ShadePoint::t) the point is p + εn + ε²t: when D0 = D1 = 0 (p + εn
// itself lies in the plane, e.g. a wall's foot on a floor with a horizontal normal) the sign of the
// ε² coefficient, −t·((b−a)×(c−a)), decides; without t, or when that is 0 too, the result is 0.
int orient_eps(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
               const Eigen::Vector3d& p, const Eigen::Vector3d& n, const Eigen::Vector3d* t = nullptr);

// The shade point's tie-break direction, or nullptr when it has none (t = 0).
inline const Eigen::Vector3d* tie_break(const ShadePoint& point) {
  return point.t.isZero(0.0) ? nullptr : &point.t;
}

// The same determinant without the ε rule: the exact sign of D0 (−1, 0, +1).
int orient3d_exact(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                   const Eigen::Vector3d& p);

namespace predicates_detail {
// The filters are inline so the contour search's inner loop decides almost every sign without a
// call; the exact expansions (predicates.cpp) run only when a filter cannot decide.
inline constexpr double kU = 0x1p-53;  // unit roundoff
inline constexpr double kO3dErrBound = (7.0 + 56.0 * kU) * kU;

// Exact sign of det(a−p, b−p, c−p) and of n·((b−a)×(c−a)) by floating-point expansions.
int orient3d_expansion(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                       const Eigen::Vector3d& p);
int normal_dot_expansion(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                         const Eigen::Vector3d& n);

// Filtered D0 sign: +1/−1 when decided, 0 when exactly zero, 2 when undecided.
inline int orient3d_filter(const double* a, const double* b, const double* c, const double* p) {
  const double adx = a[0] - p[0], bdx = b[0] - p[0], cdx = c[0] - p[0];
  const double ady = a[1] - p[1], bdy = b[1] - p[1], cdy = c[1] - p[1];
  const double adz = a[2] - p[2], bdz = b[2] - p[2], cdz = c[2] - p[2];
  const double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy;
  const double cdxady = cdx * ady, adxcdy = adx * cdy;
  const double adxbdy = adx * bdy, bdxady = bdx * ady;
  const double det = adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady);
  const double permanent = (std::abs(bdxcdy) + std::abs(cdxbdy)) * std::abs(adz) +
                           (std::abs(cdxady) + std::abs(adxcdy)) * std::abs(bdz) +
                           (std::abs(adxbdy) + std::abs(bdxady)) * std::abs(cdz);
  if (permanent == 0) return 0;
  const double bound = kO3dErrBound * permanent;
  if (det > bound) return 1;
  if (-det > bound) return -1;
  return 2;
}

// Filtered sign of n·((b−a)×(c−a)); same conventions.
inline int normal_dot_filter(const double* a, const double* b, const double* c, const double* n) {
  const double ux = b[0] - a[0], uy = b[1] - a[1], uz = b[2] - a[2];
  const double wx = c[0] - a[0], wy = c[1] - a[1], wz = c[2] - a[2];
  const double uywz = uy * wz, uzwy = uz * wy, uzwx = uz * wx, uxwz = ux * wz, uxwy = ux * wy, uywx = uy * wx;
  const double dot = n[0] * (uywz - uzwy) + n[1] * (uzwx - uxwz) + n[2] * (uxwy - uywx);
  const double permanent = (std::abs(uywz) + std::abs(uzwy)) * std::abs(n[0]) +
                           (std::abs(uzwx) + std::abs(uxwz)) * std::abs(n[1]) +
                           (std::abs(uxwy) + std::abs(uywx)) * std::abs(n[2]);
  if (permanent == 0) return 0;
  const double bound = kO3dErrBound * permanent;
  if (dot > bound) return 1;
  if (-dot > bound) return -1;
  return 2;
}

inline int orient_eps_raw(const double* a, const double* b, const double* c, const double* p, const double* n) {
  int s = orient3d_filter(a, b, c, p);
  if (s == 2) {
    s = orient3d_expansion(Eigen::Vector3d(a[0], a[1], a[2]), Eigen::Vector3d(b[0], b[1], b[2]),
                           Eigen::Vector3d(c[0], c[1], c[2]), Eigen::Vector3d(p[0], p[1], p[2]));
  }
  if (s != 0) return s;
  // D1 = −n·((b−a)×(c−a))
  int t = normal_dot_filter(a, b, c, n);
  if (t == 2) {
    t = normal_dot_expansion(Eigen::Vector3d(a[0], a[1], a[2]), Eigen::Vector3d(b[0], b[1], b[2]),
                             Eigen::Vector3d(c[0], c[1], c[2]), Eigen::Vector3d(n[0], n[1], n[2]));
  }
  return -t;
}

// The second-order tier (orient_eps above): only when D0 = D1 = 0, the ε² coefficient
// D1 with t in the place of n — orient_eps_raw with t returns exactly that, since D0 = 0.
inline int orient_eps2_raw(const double* a, const double* b, const double* c, const double* p, const double* n,
                           const double* t) {
  const int s = orient_eps_raw(a, b, c, p, n);
  return s != 0 || t == nullptr ? s : orient_eps_raw(a, b, c, p, t);
}

inline int orient_eps_f(const float* a, const float* b, const float* c, const double* p, const double* n,
                        const double* t) {
  const double ad[3] = {a[0], a[1], a[2]}, bd[3] = {b[0], b[1], b[2]}, cd[3] = {c[0], c[1], c[2]};
  return orient_eps2_raw(ad, bd, cd, p, n, t);
}

} // namespace predicates_detail

} // namespace prt::bake
