// hot_texels.cpp — the environment's hot texels integrated exactly over their visible part
// (bake/hot_texels.h: clusters, W by paths, the slab decomposition in each texel's gnomonic chart).
#include <bake/hot_texels.h>

#include <bake/error.h>
#include <bake/polygon_sh.h>

#include <prtshade/quadrature.h>
#include <prtshade/sh.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <numeric>
#include <optional>

namespace prt::bake {

using Eigen::Vector2d;
using Eigen::Vector3d;

namespace {

inline int sign_of(double x) { return x > 0 ? 1 : x < 0 ? -1 : 0; }
inline double cross2(const Vector2d& a, const Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }
inline double orient2(const Vector2d& a, const Vector2d& b, const Vector2d& c) { return cross2(b - a, c - a); }

// A straight segment of a texel's gnomonic chart: a texel edge (step 0, toggles "inside") or a
// piece of a W arc, whose line is g(x, y) = g0 + gx·x + gy·y = m·(c + x e1 + y e2) (W steps by
// sign(Δg)·side_sum when crossed).
struct Segment {
  Vector2d p, q;
  bool edge = false;
  double gx = 0, gy = 0;
  int side_sum = 0;
  double y_at(double x) const {
    if (x <= std::min(p.x(), q.x())) return p.x() < q.x() ? p.y() : q.y();
    if (x >= std::max(p.x(), q.x())) return p.x() > q.x() ? p.y() : q.y();
    return p.y() + (x - p.x()) * (q.y() - p.y()) / (q.x() - p.x());
  }
};

struct Scratch {
  std::vector<Segment> segments;
  std::vector<double> xs;
  std::vector<std::pair<double, size_t>> order;
  std::vector<size_t> cluster_arcs, texel_arcs;
  std::vector<double> moments;
  std::vector<double> gx, gw, gy, gwy;
};
thread_local Scratch tl_scratch;

} // namespace

int dcf_path_steps(std::span<const DcfArc> arcs, const Vector3d& P, const Vector3d& Q) {
  const Vector3d m2 = P.cross(Q);
  int w = 0;
  for (const DcfArc& arc : arcs) {
    const Vector3d dir = arc.m.cross(m2);
    if (dir.squaredNorm() == 0) continue;
    for (const Vector3d& c : {dir, Vector3d(-dir)}) {
      if (arc.a.cross(c).dot(arc.m) >= 0 && c.cross(arc.b).dot(arc.m) >= 0 && P.cross(c).dot(m2) >= 0 &&
          c.cross(Q).dot(m2) >= 0)
        w += sign_of(arc.m.dot(m2.cross(c))) * arc.side_sum;
    }
  }
  return w;
}

struct HotTexels::Impl {
  // One hot texel in its gnomonic chart about c (frame coordinates): ω ∝ c + x e1 + y e2,
  // e1 × e2 = c.
  struct Texel {
    int index = 0;
    Vector3d c, e1, e2;
    std::vector<Vector2d> polygon;  // counter-clockwise in the chart
    Vector2d lo, hi;                // the chart box every local arc is clipped to (polygon box + margin)
    // The point W is carried from (chart ref2, direction ref): off the centre by odd fractions of
    // the box, so that no arc of an axis-aligned scene passes through it by symmetry (a W path
    // must not end on an arc).
    Vector2d ref2;
    Vector3d ref;
    double cos_r = 1, sin_r = 0;    // the cap about c that holds the box
    double rgb[3] = {0, 0, 0};
    std::vector<double> moments;    // order² moments of the whole texel (unit radiance)
  };
  struct Cluster {
    Vector3d c, ref;                // centre of the cap; the point W is carried from (see Texel)
    double cos_r = 1, sin_r = 0;
    size_t begin = 0, end = 0;      // texels [begin, end)
    std::vector<double> total;      // 3·order² moments, radiance-weighted
  };

  Eigen::Matrix3d frame_from_world, world_from_frame;
  int order = 1;
  size_t n2 = 1;
  std::optional<PolygonSH> polygon_sh;  // orders ≤ PolygonSH::kMaxOrder
  std::vector<uint8_t> hot_mask;
  std::vector<Texel> texels;
  std::vector<Cluster> clusters;
  std::vector<double> unoccluded;
  mutable std::atomic<uint64_t> texels_cut{0};

  // ∫ y_i dω (i < order²) over the chart trapezoid x ∈ [x0, x1] between the lines through
  // (x0, ylo0)–(x1, ylo1) and (x0, yhi0)–(x1, yhi1), added to out.
  void trapezoid(const Texel& t, double x0, double x1, double ylo0, double ylo1, double yhi0, double yhi1,
                 double* out, Scratch& s) const {
    // Heights below 0 come from rounding where two segments meet at a slab's end: none there.
    yhi0 = std::max(yhi0, ylo0), yhi1 = std::max(yhi1, ylo1);
    if (!(x1 > x0) || !(yhi0 > ylo0 || yhi1 > ylo1)) return;
    // A sliver of (nearly) no area: its vertices are (nearly) on one great circle, where the
    // closed form's solid angle cannot tell the sliver from a hemisphere. Leaving out slivers
    // under 1e-13 of the texel's chart box costs at most that per sliver.
    const Vector2d box = t.hi - t.lo;
    if (0.5 * (x1 - x0) * ((yhi0 - ylo0) + (yhi1 - ylo1)) <= 1e-13 * box.x() * box.y()) return;
    auto world = [&](double x, double y) { return Vector3d(world_from_frame * (t.c + x * t.e1 + y * t.e2)); };
    if (polygon_sh) {
      const Vector3d v[4] = {world(x0, ylo0), world(x1, ylo1), world(x1, yhi1), world(x0, yhi0)};
      s.moments.assign(n2, 0.0);
      polygon_sh->project(std::span<const Vector3d>(v, 4), s.moments);
      for (size_t i = 0; i < n2; ++i) out[i] += s.moments[i];
      return;
    }
    // Above PolygonSH's orders: Gauss–Legendre in the chart. y_i varies on the angular scale
    // 1/order and the chart is within ~1% of isometric over a texel, so with n ≥ order·size/2 + 6
    // points per axis the rule's error (~(order·size/4)^(2n) / (2n)!) is far below 1e-12.
    const double size = std::max({x1 - x0, std::abs(yhi0 - ylo0), std::abs(yhi1 - ylo1)});
    const int n = std::clamp(int(std::ceil(0.5 * order * size)) + 6, 6, 64);
    shade::gauss_legendre(n, x0, x1, s.gx, s.gw);
    std::vector<double> y(n2);
    for (int a = 0; a < n; ++a) {
      const double x = s.gx[size_t(a)], f = (x - x0) / (x1 - x0);
      const double ylo = ylo0 + f * (ylo1 - ylo0), yhi = yhi0 + f * (yhi1 - yhi0);
      if (!(yhi > ylo)) continue;
      shade::gauss_legendre(n, ylo, yhi, s.gy, s.gwy);
      for (int b = 0; b < n; ++b) {
        const double yy = s.gy[size_t(b)];
        const double r2 = 1 + x * x + yy * yy;
        const double w = s.gw[size_t(a)] * s.gwy[size_t(b)] / (r2 * std::sqrt(r2));
        const Vector3d d = world(x, yy).normalized();
        sh::eval(order, d.x(), d.y(), d.z(), y);
        for (size_t i = 0; i < n2; ++i) out[i] += w * y[i];
      }
    }
  }

  // The moments of the part of texel t where W = 0, given W at t.ref and the arcs `local`
  // (indices into arcs) that may meet its box; added to out (order² values, unit radiance).
  void visible(const Texel& t, std::span<const DcfArc> arcs, std::span<const size_t> local, int W_ref,
               double* out, Scratch& s) const {
    s.segments.clear();
    const size_t nv = t.polygon.size();
    for (size_t k = 0; k < nv; ++k) {
      Segment e;
      e.p = t.polygon[k];
      e.q = t.polygon[(k + 1) % nv];
      e.edge = true;
      if (e.p != e.q) s.segments.push_back(e);
    }
    for (size_t j : local) {
      const DcfArc& arc = arcs[j];
      // The part of the arc inside the box's pyramid: x ≥ lo.x ⇔ (e1 − lo.x c)·ω ≥ 0 and so on,
      // and c·ω ≥ 0; each is linear in the chord parameter λ of ω = a + λ(b − a), which runs
      // over the same directions as the arc.
      double l0 = 0, l1 = 1;
      const Vector3d planes[5] = {t.c, t.e1 - t.lo.x() * t.c, t.hi.x() * t.c - t.e1, t.e2 - t.lo.y() * t.c,
                                  t.hi.y() * t.c - t.e2};
      const Vector3d d = arc.b - arc.a;
      for (const Vector3d& n : planes) {
        const double fa = n.dot(arc.a), fd = n.dot(d);  // f(λ) = fa + λ fd ≥ 0
        if (fd == 0) {
          if (fa < 0) l1 = -1;
          continue;
        }
        const double root = -fa / fd;
        if (fd > 0) l0 = std::max(l0, root);
        else l1 = std::min(l1, root);
      }
      if (!(l1 > l0)) continue;
      auto chart = [&](double l) {
        const Vector3d w = arc.a + l * d;
        const double z = t.c.dot(w);
        return Vector2d(t.e1.dot(w) / z, t.e2.dot(w) / z);
      };
      Segment g;
      g.p = chart(l0);
      g.q = chart(l1);
      if (!(g.p.allFinite() && g.q.allFinite())) continue;
      g.gx = arc.m.dot(t.e1);
      g.gy = arc.m.dot(t.e2);
      g.side_sum = arc.side_sum;
      s.segments.push_back(g);
    }
    // Slab boundaries: every end and every proper crossing inside the polygon's x-range.
    double xmin = t.polygon[0].x(), xmax = xmin;
    for (const Vector2d& v : t.polygon) xmin = std::min(xmin, v.x()), xmax = std::max(xmax, v.x());
    s.xs.clear();
    s.xs.push_back(xmin);
    s.xs.push_back(xmax);
    const size_t ns = s.segments.size();
    for (size_t i = 0; i < ns; ++i) {
      const Segment& a = s.segments[i];
      s.xs.push_back(a.p.x());
      s.xs.push_back(a.q.x());
      for (size_t j = i + 1; j < ns; ++j) {
        const Segment& b = s.segments[j];
        if (a.edge && b.edge) continue;  // the polygon's own edges meet at its vertices only
        const double d1 = orient2(a.p, a.q, b.p), d2 = orient2(a.p, a.q, b.q);
        const double d3 = orient2(b.p, b.q, a.p), d4 = orient2(b.p, b.q, a.q);
        if (!((d1 > 0) != (d2 > 0) && d1 != 0 && d2 != 0 && (d3 > 0) != (d4 > 0) && d3 != 0 && d4 != 0)) continue;
        const double f = d1 / (d1 - d2);
        s.xs.push_back(b.p.x() + f * (b.q.x() - b.p.x()));
      }
    }
    std::sort(s.xs.begin(), s.xs.end());
    s.xs.erase(std::unique(s.xs.begin(), s.xs.end()), s.xs.end());
    for (size_t k = 0; k + 1 < s.xs.size(); ++k) {
      const double x0 = s.xs[k], x1 = s.xs[k + 1];
      if (x0 < xmin || x1 > xmax || !(x1 > x0)) continue;
      const double xm = 0.5 * (x0 + x1);
      s.order.clear();
      for (size_t i = 0; i < ns; ++i) {
        const Segment& g = s.segments[i];
        if (g.p.x() == g.q.x() || xm < std::min(g.p.x(), g.q.x()) || xm > std::max(g.p.x(), g.q.x())) continue;
        s.order.emplace_back(g.y_at(xm), i);
      }
      std::sort(s.order.begin(), s.order.end());
      // W below every segment of the slab. The slab's ends are events, so every segment either
      // spans x = xm or misses it: the middle of the widest gap between the heights at xm (box
      // sides included) is off every segment, and the path from ref2 to it decides W there by
      // strict orientation tests; the segments below it are then stepped back over.
      size_t below = 0;
      double gap = -1, yB = 0;
      for (size_t r = 0; r <= s.order.size(); ++r) {
        const double ya = r == 0 ? t.lo.y() : s.order[r - 1].first, yb = r == s.order.size() ? t.hi.y() : s.order[r].first;
        if (yb - ya > gap) gap = yb - ya, yB = 0.5 * (ya + yb), below = r;
      }
      const Vector2d A = t.ref2, B(xm, yB), d = B - A;
      int W = W_ref;
      for (const Segment& g : s.segments) {
        if (g.edge) continue;
        const double d1 = orient2(A, B, g.p), d2 = orient2(A, B, g.q);
        const double d3 = orient2(g.p, g.q, A), d4 = orient2(g.p, g.q, B);
        if ((d1 > 0) != (d2 > 0) && d1 != 0 && d2 != 0 && (d3 > 0) != (d4 > 0) && d3 != 0 && d4 != 0)
          W += sign_of(d.x() * g.gx + d.y() * g.gy) * g.side_sum;
      }
      for (size_t r = 0; r < below; ++r)
        if (const Segment& g = s.segments[s.order[r].second]; !g.edge) W -= sign_of(g.gy) * g.side_sum;
      bool inside = false;
      for (size_t r = 0; r < s.order.size(); ++r) {
        const Segment& g = s.segments[s.order[r].second];
        if (g.edge) inside = !inside;
        else W += sign_of(g.gy) * g.side_sum;  // travelling +y
        if (r + 1 < s.order.size() && inside && W == 0) {
          const Segment& h = s.segments[s.order[r + 1].second];
          trapezoid(t, x0, x1, g.y_at(x0), g.y_at(x1), h.y_at(x0), h.y_at(x1), out, s);
        }
      }
    }
  }

  // Whether the arc comes within the cap (c, r) (r < π/2): its nearest point to c is an end or the
  // foot of c on its great circle.
  static bool meets_cap(const DcfArc& arc, const Vector3d& c, double cos_r, double sin_r) {
    const double na = arc.a.norm(), nb = arc.b.norm();
    if (c.dot(arc.a) >= cos_r * na || c.dot(arc.b) >= cos_r * nb) return true;
    const double nm = arc.m.norm();
    if (!(nm > 0)) return false;
    const double s = c.dot(arc.m) / nm;
    if (std::abs(s) > sin_r) return false;
    const Vector3d foot = c - (s / nm) * arc.m;
    return arc.a.cross(foot).dot(arc.m) >= 0 && foot.cross(arc.b).dot(arc.m) >= 0 && foot.dot(arc.a + arc.b) > 0;
  }

  // W at the frame direction to, from W0 at s0 (via a waypoint when the two are nearly opposite).
  static int W_at(std::span<const DcfArc> arcs, const Vector3d& s0, int W0, const Vector3d& to) {
    if (s0.dot(to) > -0.5 * s0.norm() * to.norm()) return W0 + dcf_path_steps(arcs, s0, to);
    const Vector3d any = std::abs(s0.x()) < 0.9 * s0.norm() ? Vector3d::UnitX() : Vector3d::UnitY();
    const Vector3d mid = s0.cross(any).normalized();
    return W0 + dcf_path_steps(arcs, s0, mid) + dcf_path_steps(arcs, mid, to);
  }

  // Accumulates the radiance-weighted moments of texels [begin, end) of cluster `cl` (W at its
  // centre is Wc, its local arcs `local`).
  void texel_range(const Cluster& cl, std::span<const DcfArc> arcs, std::span<const size_t> local, int Wc, double* out,
                   Scratch& s) const {
    std::vector<double> m;
    for (size_t k = cl.begin; k < cl.end; ++k) {
      const Texel& t = texels[k];
      s.texel_arcs.clear();
      for (size_t j : local)
        if (meets_cap(arcs[j], t.c, t.cos_r, t.sin_r)) s.texel_arcs.push_back(j);
      // The short arc from the cluster's reference point to the texel's stays in the cluster's
      // cap: only its local arcs can cross it.
      int W = Wc;
      for (size_t j : local) W += dcf_path_steps(arcs.subspan(j, 1), cl.ref, t.ref);
      const double* mom = nullptr;
      if (s.texel_arcs.empty()) {
        if (W != 0) continue;
        mom = t.moments.data();
      } else {
        texels_cut.fetch_add(1, std::memory_order_relaxed);
        m.assign(n2, 0.0);
        visible(t, arcs, s.texel_arcs, W, m.data(), s);  // visible() leaves texel_arcs alone
        mom = m.data();
      }
      for (int c = 0; c < 3; ++c)
        for (size_t i = 0; i < n2; ++i) out[size_t(c) * n2 + i] += t.rgb[c] * mom[i];
    }
  }
};

HotTexels::HotTexels(const EnvMap& env, const Eigen::Matrix3d& frame_from_world, int order, double hot_factor,
                     size_t max_texels)
    : impl_(std::make_unique<Impl>()) {
  PRT_CHECK(order >= 1);
  Impl& I = *impl_;
  I.frame_from_world = frame_from_world;
  I.world_from_frame = frame_from_world.transpose();
  I.order = order;
  I.n2 = size_t(order * order);
  if (order <= PolygonSH::kMaxOrder) I.polygon_sh.emplace(order);
  I.unoccluded.assign(3 * I.n2, 0.0);
  const int T = env.texel_count();
  if (T <= 0) return;
  std::vector<double> lum(static_cast<size_t>(T));
  for (int tx = 0; tx < T; ++tx) lum[size_t(tx)] = luminance(env.texel_value(tx));
  double threshold = hot_factor * env.info().mean_luminance;
  if (size_t(T) > max_texels && max_texels > 0) {
    std::vector<double> sorted = lum;
    std::nth_element(sorted.begin(), sorted.begin() + std::ptrdiff_t(max_texels - 1), sorted.end(), std::greater<>());
    threshold = std::max(threshold, std::nextafter(sorted[max_texels - 1], std::numeric_limits<double>::infinity()));
  }
  I.hot_mask.assign(size_t(T), 0);
  // Clusters: 8 × 8 tiles of the image, in tile order (a function of the map alone).
  const int width = env.info().width, kTile = 8;
  std::map<std::pair<int, int>, std::vector<int>> tiles;
  for (int tx = 0; tx < T; ++tx)
    if (lum[size_t(tx)] > threshold && lum[size_t(tx)] > 0) {
      I.hot_mask[size_t(tx)] = 1;
      tiles[{(tx / width) / kTile, (tx % width) / kTile}].push_back(tx);
    }
  Scratch& s = tl_scratch;
  auto make_texel = [&](int tx) {
    Impl::Texel t;
    t.index = tx;
    std::vector<Vector3d> poly = env.texel_polygon(tx);
    for (Vector3d& v : poly) v = frame_from_world * v;
    Vector3d c = Vector3d::Zero();
    for (const Vector3d& v : poly) c += v;
    t.c = c.normalized();
    const Vector3d any = std::abs(t.c.x()) < 0.9 ? Vector3d::UnitX() : Vector3d::UnitY();
    t.e1 = any.cross(t.c).normalized();
    t.e2 = t.c.cross(t.e1);
    for (const Vector3d& v : poly) {
      const double z = t.c.dot(v);
      PRT_CHECK(z > 0);
      t.polygon.emplace_back(t.e1.dot(v) / z, t.e2.dot(v) / z);
    }
    t.lo = t.hi = t.polygon[0];
    for (const Vector2d& v : t.polygon) t.lo = t.lo.cwiseMin(v), t.hi = t.hi.cwiseMax(v);
    const Vector2d half = 0.5 * (t.hi - t.lo);
    t.ref2 = 0.5 * (t.lo + t.hi) + Vector2d(0.1236 * half.x(), 0.2847 * half.y());
    t.ref = (t.c + t.ref2.x() * t.e1 + t.ref2.y() * t.e2).normalized();
    const double margin = 0.25 * (t.hi - t.lo).maxCoeff();
    t.lo -= Vector2d(margin, margin);
    t.hi += Vector2d(margin, margin);
    const double rho = std::max({t.lo.norm(), t.hi.norm(), Vector2d(t.lo.x(), t.hi.y()).norm(), Vector2d(t.hi.x(), t.lo.y()).norm()});
    const double r = std::atan(rho);
    t.cos_r = std::cos(r), t.sin_r = std::sin(r);
    const Rgb L = env.texel_value(tx);
    t.rgb[0] = L.r, t.rgb[1] = L.g, t.rgb[2] = L.b;
    t.moments.assign(I.n2, 0.0);
    I.visible(t, {}, {}, 0, t.moments.data(), s);
    return t;
  };
  for (auto& [key, members] : tiles) {
    const size_t begin = I.texels.size();
    for (int tx : members) I.texels.push_back(make_texel(tx));
    Impl::Cluster cl;
    cl.begin = begin;
    cl.end = I.texels.size();
    Vector3d c = Vector3d::Zero();
    for (size_t k = cl.begin; k < cl.end; ++k) c += I.texels[k].c;
    cl.c = c.normalized();
    const Vector3d any = std::abs(cl.c.x()) < 0.9 ? Vector3d::UnitX() : Vector3d::UnitY();
    const Vector3d u1 = any.cross(cl.c).normalized(), u2 = cl.c.cross(u1);
    double r = 0;
    for (size_t k = cl.begin; k < cl.end; ++k) {
      const Impl::Texel& t = I.texels[k];
      r = std::max(r, std::atan2(cl.c.cross(t.c).norm(), cl.c.dot(t.c)) + std::atan2(t.sin_r, t.cos_r));
    }
    if (r < 1.0) {  // a cap well inside a hemisphere; else one cluster per texel
      cl.cos_r = std::cos(r), cl.sin_r = std::sin(r);
      cl.ref = (cl.c + std::tan(0.3 * r) * (0.3719 * u1 + 0.6173 * u2)).normalized();  // inside the cap
      I.clusters.push_back(cl);
    } else {
      for (size_t k = begin; k < cl.end; ++k) {
        Impl::Cluster one;
        one.begin = k, one.end = k + 1, one.c = I.texels[k].c, one.ref = I.texels[k].ref;
        one.cos_r = I.texels[k].cos_r, one.sin_r = I.texels[k].sin_r;
        I.clusters.push_back(one);
      }
    }
  }
  for (Impl::Cluster& cl : I.clusters) {
    cl.total.assign(3 * I.n2, 0.0);
    for (size_t k = cl.begin; k < cl.end; ++k)
      for (int c = 0; c < 3; ++c)
        for (size_t i = 0; i < I.n2; ++i) cl.total[size_t(c) * I.n2 + i] += I.texels[k].rgb[c] * I.texels[k].moments[i];
    for (size_t i = 0; i < cl.total.size(); ++i) I.unoccluded[i] += cl.total[i];
  }
}

HotTexels::~HotTexels() = default;

size_t HotTexels::texels() const noexcept { return impl_->texels.size(); }
size_t HotTexels::clusters() const noexcept { return impl_->clusters.size(); }
int HotTexels::order() const noexcept { return impl_->order; }
bool HotTexels::is_hot(int texel) const noexcept {
  return texel >= 0 && size_t(texel) < impl_->hot_mask.size() && impl_->hot_mask[size_t(texel)] != 0;
}
const std::vector<double>& HotTexels::unoccluded() const noexcept { return impl_->unoccluded; }

void HotTexels::accumulate(std::span<const DcfArc> arcs, const Vector3d& s0, int W0, double* out) const {
  const Impl& I = *impl_;
  Scratch& s = tl_scratch;
  for (const Impl::Cluster& cl : I.clusters) {
    s.cluster_arcs.clear();
    for (size_t j = 0; j < arcs.size(); ++j)
      if (arcs[j].side_sum != 0 && Impl::meets_cap(arcs[j], cl.c, cl.cos_r, cl.sin_r)) s.cluster_arcs.push_back(j);
    const int Wc = Impl::W_at(arcs, s0, W0, cl.ref);
    if (s.cluster_arcs.empty()) {
      if (Wc == 0)
        for (size_t i = 0; i < cl.total.size(); ++i) out[i] += cl.total[i];
      continue;
    }
    I.texel_range(cl, arcs, s.cluster_arcs, Wc, out, s);  // visible() leaves cluster_arcs alone
  }
}

std::vector<double> HotTexels::texel_moments(int texel, std::span<const DcfArc> arcs, const Vector3d& s0, int W0) const {
  const Impl& I = *impl_;
  std::vector<double> out(I.n2, 0.0);
  for (const Impl::Texel& t : I.texels) {
    if (t.index != texel) continue;
    std::vector<size_t> local;
    for (size_t j = 0; j < arcs.size(); ++j)
      if (arcs[j].side_sum != 0 && Impl::meets_cap(arcs[j], t.c, t.cos_r, t.sin_r)) local.push_back(j);
    const int W = Impl::W_at(arcs, s0, W0, t.ref);
    if (local.empty()) {
      if (W == 0) out = t.moments;
    } else {
      I.visible(t, arcs, local, W, out.data(), tl_scratch);
    }
    return out;
  }
  PRT_CHECK(!"texel_moments: not a hot texel");
  return out;
}

HotTexels::Stats HotTexels::stats() const { return {impl_->texels_cut.load()}; }

} // namespace prt::bake
