// bake/mesh/predicates.cpp — the exact fallbacks of the orientation predicates (bake/mesh/predicates.h):
// floating-point expansion arithmetic (Shewchuk 1997), used only when a filter cannot decide.
#include <bake/mesh/predicates.h>

#include "error_free.h"

#include <array>
#include <cmath>
#include <cstddef>

namespace prt::bake {

namespace {

// ---------------------------------------------------------------- expansion arithmetic
// Non-overlapping expansions in increasing magnitude, zero components eliminated (Shewchuk,
// "Adaptive Precision Floating-Point Arithmetic and Fast Robust Geometric Predicates", 1997).
using error_free::fast_two_sum;
using error_free::two_diff;
using error_free::two_product;
using error_free::two_sum;

template <int Cap>
struct Expansion {
  std::array<double, Cap> v;
  int n = 0;
  double sign() const {  // the most significant component carries the sign
    return n == 0 ? 0.0 : (v[size_t(n - 1)] > 0 ? 1.0 : (v[size_t(n - 1)] < 0 ? -1.0 : 0.0));
  }
};

template <int Cap>
Expansion<Cap> exp_diff(double a, double b) {
  Expansion<Cap> e;
  double x, y;
  two_diff(a, b, x, y);
  if (y != 0) e.v[size_t(e.n++)] = y;
  e.v[size_t(e.n++)] = x;
  return e;
}

// h = e + b (grow_expansion_zeroelim).
template <int Cap, int CapE>
void grow(const Expansion<CapE>& e, double b, Expansion<Cap>& h) {
  double q = b;
  int k = 0;
  for (int i = 0; i < e.n; ++i) {
    double qn, hh;
    two_sum(q, e.v[size_t(i)], qn, hh);
    q = qn;
    if (hh != 0) h.v[size_t(k++)] = hh;
  }
  if (q != 0 || k == 0) h.v[size_t(k++)] = q;
  h.n = k;
}

// e + f by repeated growth (O(|e||f|), only on the rare exact path).
template <int Cap, int CapE, int CapF>
Expansion<Cap> exp_sum(const Expansion<CapE>& e, const Expansion<CapF>& f) {
  static_assert(Cap >= CapE + CapF);
  Expansion<Cap> h, t;
  h.n = e.n;
  std::copy(e.v.begin(), e.v.begin() + e.n, h.v.begin());
  if (h.n == 0) h.v[size_t(h.n++)] = 0;
  for (int j = 0; j < f.n; ++j) {
    grow(h, f.v[size_t(j)], t);
    std::swap(h, t);
  }
  return h;
}

// h = e * b (scale_expansion_zeroelim).
template <int Cap, int CapE>
void scale(const Expansion<CapE>& e, double b, Expansion<Cap>& h) {
  static_assert(Cap >= 2 * CapE);
  int k = 0;
  if (e.n == 0 || b == 0) {
    h.n = 0;
    return;
  }
  double q, hh;
  two_product(e.v[0], b, q, hh);
  if (hh != 0) h.v[size_t(k++)] = hh;
  for (int i = 1; i < e.n; ++i) {
    double p1, p0, s;
    two_product(e.v[size_t(i)], b, p1, p0);
    two_sum(q, p0, s, hh);
    if (hh != 0) h.v[size_t(k++)] = hh;
    fast_two_sum(p1, s, q, hh);
    if (hh != 0) h.v[size_t(k++)] = hh;
  }
  if (q != 0 || k == 0) h.v[size_t(k++)] = q;
  h.n = k;
}

template <int Cap, int CapE, int CapF>
Expansion<Cap> exp_mul(const Expansion<CapE>& e, const Expansion<CapF>& f) {
  static_assert(Cap >= 2 * CapE * CapF);
  Expansion<Cap> acc;
  acc.n = 0;
  for (int j = 0; j < f.n; ++j) {
    Expansion<2 * CapE> t;
    scale(e, f.v[size_t(j)], t);
    Expansion<Cap> s;
    grow(acc, 0.0, s);  // copy with zero elimination
    acc = s;
    for (int i = 0; i < t.n; ++i) {
      grow(acc, t.v[size_t(i)], s);
      acc = s;
    }
  }
  if (acc.n == 0) acc.v[size_t(acc.n++)] = 0;
  return acc;
}

template <int Cap>
Expansion<Cap> exp_neg(Expansion<Cap> e) {
  for (int i = 0; i < e.n; ++i) e.v[size_t(i)] = -e.v[size_t(i)];
  return e;
}

template <int Cap>
Expansion<Cap> exp_scalar(double x) {
  Expansion<Cap> e;
  e.v[0] = x;
  e.n = 1;
  return e;
}

// Exact u × w for u, w given as 2-component differences; one component (16 terms max).
using E2 = Expansion<2>;
using E8 = Expansion<8>;
using E16 = Expansion<16>;
inline E16 cross_component(const E2& uy, const E2& uz, const E2& wy, const E2& wz) {
  return exp_sum<16>(exp_mul<8>(uy, wz), exp_neg(exp_mul<8>(uz, wy)));
}

}  // namespace

namespace predicates_detail {

// Exact sign of det(a−p, b−p, c−p).
int orient3d_expansion(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                       const Eigen::Vector3d& p) {
  const E2 ax = exp_diff<2>(a.x(), p.x()), ay = exp_diff<2>(a.y(), p.y()), az = exp_diff<2>(a.z(), p.z());
  const E2 bx = exp_diff<2>(b.x(), p.x()), by = exp_diff<2>(b.y(), p.y()), bz = exp_diff<2>(b.z(), p.z());
  const E2 cx = exp_diff<2>(c.x(), p.x()), cy = exp_diff<2>(c.y(), p.y()), cz = exp_diff<2>(c.z(), p.z());
  // det(A, B, C) = A·(B × C)
  const E16 mx = cross_component(by, bz, cy, cz);
  const E16 my = cross_component(bz, bx, cz, cx);
  const E16 mz = cross_component(bx, by, cx, cy);
  const auto tx = exp_mul<64>(mx, ax), ty = exp_mul<64>(my, ay), tz = exp_mul<64>(mz, az);
  const auto s = exp_sum<192>(exp_sum<128>(tx, ty), tz);
  return int(s.sign());
}

// Exact sign of n·((b−a)×(c−a)).
int normal_dot_expansion(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                         const Eigen::Vector3d& n) {
  const E2 ux = exp_diff<2>(b.x(), a.x()), uy = exp_diff<2>(b.y(), a.y()), uz = exp_diff<2>(b.z(), a.z());
  const E2 wx = exp_diff<2>(c.x(), a.x()), wy = exp_diff<2>(c.y(), a.y()), wz = exp_diff<2>(c.z(), a.z());
  const E16 mx = cross_component(uy, uz, wy, wz);
  const E16 my = cross_component(uz, ux, wz, wx);
  const E16 mz = cross_component(ux, uy, wx, wy);
  Expansion<32> tx, ty, tz;
  scale(mx, n.x(), tx);
  scale(my, n.y(), ty);
  scale(mz, n.z(), tz);
  if (tx.n == 0) tx = exp_scalar<32>(0);
  if (ty.n == 0) ty = exp_scalar<32>(0);
  if (tz.n == 0) tz = exp_scalar<32>(0);
  const auto s = exp_sum<96>(exp_sum<64>(tx, ty), tz);
  return int(s.sign());
}

}  // namespace predicates_detail

using namespace predicates_detail;

int orient3d_exact(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                   const Eigen::Vector3d& p) {
  const int s = orient3d_filter(a.data(), b.data(), c.data(), p.data());
  return s != 2 ? s : orient3d_expansion(a, b, c, p);
}

int orient_eps(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
               const Eigen::Vector3d& p, const Eigen::Vector3d& n, const Eigen::Vector3d* t) {
  return orient_eps2_raw(a.data(), b.data(), c.data(), p.data(), n.data(), t ? t->data() : nullptr);
}

} // namespace prt::bake
