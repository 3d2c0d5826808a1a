// bake/contour.cpp — exact ε-limit orientation and the 4D dual-space BVH of contour candidates
// (paper 001 §3.1). See bake/contour.h for the contract.
//
// EXACTNESS.
//  * orient_eps: D0 = det(A, B, C), A = a − p, … is evaluated in double with Shewchuk's orient3d
//    filter: |D0 − D0~| ≤ (7 + 56u)u · permanent (u = 2⁻⁵³, permanent = Σ|adz|(|bdx·cdy| +
//    |cdx·bdy|) + …, computed). When the permanent is exactly 0 every product has a zero factor
//    (no underflow is possible for the inputs we take), so D0 = 0 exactly. Otherwise, when the
//    filter cannot decide, D0 is recomputed exactly with floating-point expansions (two_diff,
//    two_product by FMA, grow/scale expansion with zero elimination; Shewchuk 1997).
//    D1 = −[det(n,B,C) + det(A,n,C) + det(A,B,n)] = −n·(B×C + C×A + A×B) = −n·((b−a)×(c−a)),
//    which does not depend on p; it has the same shape as orient3d with one exact row (n), so
//    the same filter bound holds, with the same exact fallback.
//  * The BVH query. In a centred, power-of-two-scaled frame q = (p − o)·s, each face k of a
//    BVH edge stores ĝ = (n', d'), n' the computed unit normal of N = (b−a)×(c−a) (edge order),
//    d' = −n'·a', a' = (a − o)·s. With η ≥ |n' − N/|N||_∞ (bounded per face from the rounding
//    of N and of the normalisation) and A = max |a'|₁, the value ĝ·(q, 1) evaluated in floating
//    point differs from the exact s·π(p)/|N| by at most
//        δ = 1.01·(η_max + 10u)·(|q|₁ + A)
//    (η|q|₁ + u|q|₁ from q and n', (η + u + γ₃)A from a' and d', γ₄(|q|₁ + A) for the dot
//    product or the box bound; the 1.01 covers computing δ itself). So |v| > δ decides the sign
//    of π exactly; boxes are pruned only when their whole range is beyond ±δ; anything within
//    δ of zero goes to orient_eps. Faces with η > 1e-6 (slivers, collinear corners) and
//    repeated welded corners keep their edge out of the BVH, in the always-tested list.
#include <bake/contour.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <numeric>

namespace prt::bake {

namespace {

constexpr double kU = 0x1p-53;  // unit roundoff
constexpr double kO3dErrBound = (7.0 + 56.0 * kU) * kU;

// ---------------------------------------------------------------- expansion arithmetic
// Non-overlapping expansions in increasing magnitude, zero components eliminated (Shewchuk,
// "Adaptive Precision Floating-Point Arithmetic and Fast Robust Geometric Predicates", 1997).
inline void two_sum(double a, double b, double& x, double& y) {
  x = a + b;
  const double bv = x - a, av = x - bv;
  y = (a - av) + (b - bv);
}
inline void fast_two_sum(double a, double b, double& x, double& y) {  // |a| >= |b|
  x = a + b;
  y = b - (x - a);
}
inline void two_diff(double a, double b, double& x, double& y) {
  x = a - b;
  const double bv = a - x, av = x + bv;
  y = (a - av) + (bv - b);
}
inline void two_product(double a, double b, double& x, double& y) {
  x = a * b;
  y = std::fma(a, b, -x);
}

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

// The second-order tier (bake/contour.h orient_eps): only when D0 = D1 = 0, the ε² coefficient
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

// Outward rounding of a double bound to float.
float round_down(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) > x) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  return f;
}
float round_up(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

constexpr double kMaxNormalError = 1e-6;  // faces with a worse normal bound are always tested
constexpr uint32_t kLeafSize = 4;
constexpr int kMaxStack = 128;

}  // namespace

int orient3d_exact(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                   const Eigen::Vector3d& p) {
  const int s = orient3d_filter(a.data(), b.data(), c.data(), p.data());
  return s != 2 ? s : orient3d_expansion(a, b, c, p);
}

int orient_eps(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
               const Eigen::Vector3d& p, const Eigen::Vector3d& n, const Eigen::Vector3d* t) {
  return orient_eps2_raw(a.data(), b.data(), c.data(), p.data(), n.data(), t ? t->data() : nullptr);
}

// ---------------------------------------------------------------- ContourFinder

namespace {

struct FaceDual {
  double g[4];
  double eta;  // bound on |n' − N/|N||_∞
  bool ok;     // well-conditioned (η ≤ kMaxNormalError)
};

// Unit normal of (b−a)×(c−a) with its error bound, and the offset in the finder's frame.
FaceDual face_dual(const Eigen::Vector3f& af, const Eigen::Vector3f& bf, const Eigen::Vector3f& cf,
                   const Eigen::Vector3d& origin, double s) {
  FaceDual f{};
  const Eigen::Vector3d a = af.cast<double>(), b = bf.cast<double>(), c = cf.cast<double>();
  const Eigen::Vector3d u = b - a, w = c - a;  // each component within u·|computed| of exact
  const Eigen::Vector3d N = u.cross(w);
  // |N'_i − N_i| ≤ γ₄ (|u_j w_k| + |u_k w_j|) in exact magnitudes; 6u on computed ones.
  const double m = (std::abs(u.y() * w.z()) + std::abs(u.z() * w.y())) +
                   (std::abs(u.z() * w.x()) + std::abs(u.x() * w.z())) +
                   (std::abs(u.x() * w.y()) + std::abs(u.y() * w.x()));
  const double dN = 6 * kU * m * (1 + 8 * kU);  // ‖N' − N‖₂ ≤ ‖·‖₁
  const double len = N.norm();
  const double len_lo = len * (1 - 4 * kU) - dN;  // ≤ |N|
  if (!(len_lo > 0) || !std::isfinite(len)) return f;
  // |N'/|N'| − N/|N|| ≤ 2‖N' − N‖/|N|; the normalisation itself adds ≤ 5u per component.
  f.eta = 2 * dN / len_lo * (1 + 8 * kU) + 6 * kU;
  if (!(f.eta <= kMaxNormalError)) return f;
  const Eigen::Vector3d n = N / len;
  const Eigen::Vector3d ap = (a - origin) * s;
  f.g[0] = n.x();
  f.g[1] = n.y();
  f.g[2] = n.z();
  f.g[3] = -(n.x() * ap.x() + n.y() * ap.y() + n.z() * ap.z());
  f.ok = true;
  return f;
}

struct BuildItem {
  float lo[4], hi[4];
  float centre[4];
  uint32_t record;
};

}  // namespace

ContourFinder::ContourFinder(const Mesh& mesh, const Topology& topology) : mesh_(&mesh), topology_(&topology) {
  const auto& wp = topology.welded_positions;
  const size_t E = topology.edges.size();
  stats_.edges = E;

  // Frame: centre of the bounding box, power-of-two scale bringing the half extent near 1.
  if (!wp.empty()) {
    Eigen::Vector3d lo = wp[0].cast<double>(), hi = lo;
    for (const auto& v : wp) {
      lo = lo.cwiseMin(v.cast<double>());
      hi = hi.cwiseMax(v.cast<double>());
    }
    origin_ = 0.5 * (lo + hi);
    const double half = 0.5 * (hi - lo).maxCoeff();
    if (half > 0 && std::isfinite(half)) {
      int ex = 0;
      std::frexp(half, &ex);
      scale_ = std::ldexp(1.0, -ex);
    }
  }

  std::vector<BuildItem> items;
  items.reserve(E);
  std::vector<Record> recs;
  std::vector<Corners> crs;
  recs.reserve(E);
  crs.reserve(E);
  double eta_max = 0, amax = 0;
  for (uint32_t e = 0; e < E; ++e) {
    const auto [ia, ib] = topology.edges[e];
    const auto faces = topology.faces_of_edge(e);
    bool bvh = faces.size() == 2;
    uint32_t corner[2] = {0, 0};
    for (size_t k = 0; bvh && k < 2; ++k) {
      const auto& t = mesh.triangles[faces[k]];
      const uint32_t w0 = topology.weld[t[0]], w1 = topology.weld[t[1]], w2 = topology.weld[t[2]];
      if (w0 == w1 || w1 == w2 || w0 == w2) {
        bvh = false;
        break;
      }
      corner[k] = (w0 != ia && w0 != ib) ? w0 : (w1 != ia && w1 != ib) ? w1 : w2;
    }
    if (bvh) {
      // A flat edge — both faces exactly coplanar and on opposite sides of it — has σ_1 = −σ_2
      // from every viewpoint (π_2 = −π_1 up to a positive factor, so their ε-limit signs are
      // opposite too): S ≡ 0, never a contour. Interiors of floors, walls and ground planes drop
      // out of the search entirely, which matters most for shade points on the same plane.
      const Eigen::Vector3d a = wp[ia].cast<double>(), b = wp[ib].cast<double>();
      const Eigen::Vector3d c1 = wp[corner[0]].cast<double>(), c2 = wp[corner[1]].cast<double>();
      if (orient3d_exact(a, b, c1, c2) == 0) {
        const Eigen::Vector3d n1 = (b - a).cross(c1 - a), n2 = (b - a).cross(c2 - a);
        // Exactly parallel (coplanar); opposite sides iff the normals point opposite ways. Only
        // a clearly negative dot is trusted (slivers with c on the edge line stay in).
        if (n1.dot(n2) < -1e-6 * n1.norm() * n2.norm()) {
          ++stats_.flat_edges;
          continue;
        }
      }
    }
    FaceDual d1{}, d2{};
    if (bvh) {
      d1 = face_dual(wp[ia], wp[ib], wp[corner[0]], origin_, scale_);
      d2 = face_dual(wp[ia], wp[ib], wp[corner[1]], origin_, scale_);
      bvh = d1.ok && d2.ok;
    }
    if (!bvh) {
      always_.push_back(e);
      continue;
    }
    eta_max = std::max({eta_max, d1.eta, d2.eta});
    const Eigen::Vector3d ap = (wp[ia].cast<double>() - origin_) * scale_;
    amax = std::max(amax, ap.cwiseAbs().sum());
    Record r{};
    for (int i = 0; i < 4; ++i) {
      r.g1[i] = d1.g[i];
      r.g2[i] = -d2.g[i];
    }
    Corners cr{};
    for (int i = 0; i < 3; ++i) {
      cr.a[i] = wp[ia][i];
      cr.b[i] = wp[ib][i];
      cr.c1[i] = wp[corner[0]][i];
      cr.c2[i] = wp[corner[1]][i];
    }
    cr.edge = e;
    crs.push_back(cr);
    BuildItem it{};
    for (int i = 0; i < 4; ++i) {
      it.lo[i] = round_down(std::min(r.g1[i], r.g2[i]));
      it.hi[i] = round_up(std::max(r.g1[i], r.g2[i]));
      it.centre[i] = float(0.5 * (r.g1[i] + r.g2[i]));
    }
    it.record = uint32_t(recs.size());
    recs.push_back(r);
    items.push_back(it);
  }
  // |ap|₁ was computed in floating point: inflate slightly.
  max_a_ = amax * (1 + 8 * kU);
  delta_coef_ = 1.01 * (eta_max + 10 * kU);
  stats_.normal_error = eta_max;
  stats_.bvh_edges = recs.size();
  stats_.always_tested = always_.size();

  // Binned build over the 4D boxes. Cost of a box: the sum of its extents (the mean width, to
  // which the chance of a hyperplane meeting it is proportional). Object-median fallback keeps
  // the depth bounded by the stack.
  records_.reserve(recs.size());
  corners_.reserve(recs.size());
  size_t max_depth = 0;
  constexpr int kBins = 16;
  constexpr float kInf = std::numeric_limits<float>::infinity();
  auto width = [](const float* lo, const float* hi) {
    double w = 0;
    for (int i = 0; i < 4; ++i) w += double(hi[i]) - double(lo[i]);
    return w;
  };
  // Depth-first, so a left child directly follows its parent; depth ≤ 48 + log2(n) (SAH up to
  // depth 48, object median below), well within the query's fixed stack.
  auto build = [&](auto&& self, uint32_t begin, uint32_t end, uint32_t depth) -> uint32_t {
    max_depth = std::max<size_t>(max_depth, depth);
    Node nd{};
    for (int i = 0; i < 4; ++i) {
      nd.lo[i] = kInf;
      nd.hi[i] = -kInf;
    }
    float clo[4] = {kInf, kInf, kInf, kInf}, chi[4] = {-kInf, -kInf, -kInf, -kInf};
    for (uint32_t k = begin; k < end; ++k)
      for (int i = 0; i < 4; ++i) {
        nd.lo[i] = std::min(nd.lo[i], items[k].lo[i]);
        nd.hi[i] = std::max(nd.hi[i], items[k].hi[i]);
        clo[i] = std::min(clo[i], items[k].centre[i]);
        chi[i] = std::max(chi[i], items[k].centre[i]);
      }
    const uint32_t self_index = uint32_t(nodes_.size());
    nodes_.push_back(nd);
    const uint32_t n = end - begin;
    if (n <= kLeafSize) {
      nodes_[self_index].index = uint32_t(records_.size());
      nodes_[self_index].count = n;
      for (uint32_t k = begin; k < end; ++k) {
        records_.push_back(recs[items[k].record]);
        corners_.push_back(crs[items[k].record]);
      }
      return self_index;
    }
    // Binned split on every axis, cost = Σ_children (sum of extents) × count.
    double best_cost = std::numeric_limits<double>::infinity();
    int best_axis = -1, best_bin = -1;
    auto bin_of = [&](const BuildItem& x, int axis) {
      const double ext = double(chi[axis]) - double(clo[axis]);
      return std::clamp(int((double(x.centre[axis]) - double(clo[axis])) / ext * kBins), 0, kBins - 1);
    };
    if (depth < 48) {
      for (int axis = 0; axis < 4; ++axis) {
        if (!(chi[axis] > clo[axis])) continue;
        struct Bin {
          float lo[4], hi[4];
          uint32_t count;
        } bins[kBins];
        for (auto& b : bins) {
          b.count = 0;
          for (int i = 0; i < 4; ++i) {
            b.lo[i] = kInf;
            b.hi[i] = -kInf;
          }
        }
        for (uint32_t k = begin; k < end; ++k) {
          auto& b = bins[bin_of(items[k], axis)];
          ++b.count;
          for (int i = 0; i < 4; ++i) {
            b.lo[i] = std::min(b.lo[i], items[k].lo[i]);
            b.hi[i] = std::max(b.hi[i], items[k].hi[i]);
          }
        }
        double right_cost[kBins] = {};
        float lo[4] = {kInf, kInf, kInf, kInf}, hi[4] = {-kInf, -kInf, -kInf, -kInf};
        uint32_t cnt = 0;
        for (int b = kBins - 1; b > 0; --b) {
          cnt += bins[b].count;
          for (int i = 0; i < 4; ++i) {
            lo[i] = std::min(lo[i], bins[b].lo[i]);
            hi[i] = std::max(hi[i], bins[b].hi[i]);
          }
          right_cost[b] = cnt ? width(lo, hi) * cnt : 0;
        }
        for (int i = 0; i < 4; ++i) {
          lo[i] = kInf;
          hi[i] = -kInf;
        }
        cnt = 0;
        for (int b = 0; b < kBins - 1; ++b) {
          cnt += bins[b].count;
          for (int i = 0; i < 4; ++i) {
            lo[i] = std::min(lo[i], bins[b].lo[i]);
            hi[i] = std::max(hi[i], bins[b].hi[i]);
          }
          if (cnt == 0 || cnt == n) continue;
          const double cost = width(lo, hi) * cnt + right_cost[b + 1];
          if (cost < best_cost) {
            best_cost = cost;
            best_axis = axis;
            best_bin = b;
          }
        }
      }
    }
    uint32_t mid = begin;
    if (best_axis >= 0) {
      mid = uint32_t(std::partition(items.begin() + begin, items.begin() + end,
                                    [&](const BuildItem& x) { return bin_of(x, best_axis) <= best_bin; }) -
                     items.begin());
    }
    if (mid == begin || mid == end) {  // object median on the widest centre axis
      int axis = 0;
      for (int i = 1; i < 4; ++i)
        if (chi[i] - clo[i] > chi[axis] - clo[axis]) axis = i;
      mid = begin + n / 2;
      std::nth_element(items.begin() + begin, items.begin() + mid, items.begin() + end,
                       [axis](const BuildItem& x, const BuildItem& y) { return x.centre[axis] < y.centre[axis]; });
    }
    self(self, begin, mid, depth + 1);
    const uint32_t right = self(self, mid, end, depth + 1);
    nodes_[self_index].index = right;
    nodes_[self_index].count = 0;
    return self_index;
  };
  if (!items.empty()) build(build, 0, uint32_t(items.size()), 1);
  stats_.bvh_nodes = nodes_.size();
  stats_.bvh_depth = max_depth;
}

size_t ContourFinder::edge_count() const { return topology_->edges.size(); }
size_t ContourFinder::bvh_node_count() const { return nodes_.size(); }

int ContourFinder::side_sum_slow(uint32_t edge, const Eigen::Vector3d& p, const Eigen::Vector3d& n,
                                 const Eigen::Vector3d* tie) const {
  const auto& topo = *topology_;
  const auto [ia, ib] = topo.edges[edge];
  const Eigen::Vector3d a = topo.welded_positions[ia].cast<double>(), b = topo.welded_positions[ib].cast<double>();
  int sum = 0;
  for (const uint32_t f : topo.faces_of_edge(edge)) {
    const auto& t = mesh_->triangles[f];
    const uint32_t w0 = topo.weld[t[0]], w1 = topo.weld[t[1]], w2 = topo.weld[t[2]];
    if (w0 == w1 || w1 == w2 || w0 == w2) continue;
    const uint32_t c = (w0 != ia && w0 != ib) ? w0 : (w1 != ia && w1 != ib) ? w1 : w2;
    sum += orient_eps(a, b, topo.welded_positions[c].cast<double>(), p, n, tie);
  }
  return sum;
}

void ContourFinder::find_brute_force(const ShadePoint& point, std::vector<ContourEdge>& out) const {
  out.clear();
  const uint32_t E = uint32_t(topology_->edges.size());
  for (uint32_t e = 0; e < E; ++e) {
    const int s = side_sum_slow(e, point.p, point.n, tie_break(point));
    if (s != 0) out.push_back({e, s});
  }
}

void ContourFinder::find(const ShadePoint& point, std::vector<ContourEdge>& out) const {
  out.clear();
  // Results go to a per-thread bitmap over the edges (plus their sums) and are read back in edge
  // order: O(K + E/64) instead of sorting K results found in leaf order. The buffers only grow.
  thread_local std::vector<uint64_t> tl_bits;
  thread_local std::vector<int32_t> tl_sums;
  const size_t E = topology_->edges.size(), words = (E + 63) / 64;
  if (tl_bits.size() < words) tl_bits.resize(words, 0);
  if (tl_sums.size() < E) tl_sums.resize(E);
  uint64_t* bits = tl_bits.data();
  int32_t* sums = tl_sums.data();
  auto emit = [bits, sums](uint32_t e, int s) {
    sums[e] = s;
    bits[e >> 6] |= uint64_t(1) << (e & 63);
  };
  const double p[3] = {point.p.x(), point.p.y(), point.p.z()};
  const double nn[3] = {point.n.x(), point.n.y(), point.n.z()};
  const double* tt = tie_break(point) ? point.t.data() : nullptr;
  for (const uint32_t e : always_) {
    const int s = side_sum_slow(e, point.p, point.n, tie_break(point));
    if (s != 0) emit(e, s);
  }
  if (!nodes_.empty()) {
    const double q[4] = {(p[0] - origin_.x()) * scale_, (p[1] - origin_.y()) * scale_, (p[2] - origin_.z()) * scale_,
                         1.0};
    const double delta = delta_coef_ * ((std::abs(q[0]) + std::abs(q[1]) + std::abs(q[2])) + max_a_);
    // Per axis: which box corner minimises q_i x_i.
    const bool neg[3] = {q[0] < 0, q[1] < 0, q[2] < 0};
    uint32_t stack[kMaxStack];
    int sp = 0;
    uint32_t ni = 0;
    const Node* nodes = nodes_.data();
    const Record* recs = records_.data();
    for (;;) {
      const Node& nd = nodes[ni];
      const double lo0 = neg[0] ? nd.hi[0] : nd.lo[0], hi0 = neg[0] ? nd.lo[0] : nd.hi[0];
      const double lo1 = neg[1] ? nd.hi[1] : nd.lo[1], hi1 = neg[1] ? nd.lo[1] : nd.hi[1];
      const double lo2 = neg[2] ? nd.hi[2] : nd.lo[2], hi2 = neg[2] ? nd.lo[2] : nd.hi[2];
      const double vmin = q[0] * lo0 + q[1] * lo1 + q[2] * lo2 + double(nd.lo[3]);
      const double vmax = q[0] * hi0 + q[1] * hi1 + q[2] * hi2 + double(nd.hi[3]);
      if (vmin <= delta && vmax >= -delta) {
        if (nd.count == 0) {
          stack[sp++] = nd.index;
          ni = ni + 1;
          continue;
        }
        const Record* r = recs + nd.index;
        for (uint32_t k = 0; k < nd.count; ++k, ++r) {
          const double v1 = r->g1[0] * q[0] + r->g1[1] * q[1] + r->g1[2] * q[2] + r->g1[3];
          const double v2 = r->g2[0] * q[0] + r->g2[1] * q[1] + r->g2[2] * q[2] + r->g2[3];
          // v1 ∝ π_1 (σ_1 = −sign v1), v2 ∝ −π_2 (σ_2 = sign v2) whenever |v| > δ.
          if ((v1 > delta && v2 > delta) || (v1 < -delta && v2 < -delta)) continue;
          int s;
          if (v1 > delta && v2 < -delta) {
            s = -2;
          } else if (v1 < -delta && v2 > delta) {
            s = 2;
          } else {
            const Corners& c = corners_[nd.index + k];
            s = orient_eps_f(c.a, c.b, c.c1, p, nn, tt) + orient_eps_f(c.a, c.b, c.c2, p, nn, tt);
          }
          if (s != 0) emit(corners_[nd.index + k].edge, s);
        }
      }
      if (sp == 0) break;
      ni = stack[--sp];
    }
  }
  for (size_t w = 0; w < words; ++w) {
    uint64_t b = bits[w];
    if (b == 0) continue;
    bits[w] = 0;
    do {
      const uint32_t e = uint32_t(w * 64 + size_t(std::countr_zero(b)));
      out.push_back({e, sums[e]});
      b &= b - 1;
    } while (b != 0);
  }
}

}  // namespace prt::bake
