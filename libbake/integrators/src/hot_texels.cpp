// hot_texels.cpp — the environment's hot texels integrated exactly over their visible part
// (bake/integrators/hot_texels.h: the cluster tree, W by paths, bands between arc segments in each texel's
// gnomonic chart).
#include <bake/integrators/hot_texels.h>

#include <bake/core/error.h>
#include <bake/sphere/polygon_sh.h>

#include <prtshade/quadrature.h>
#include <prtshade/sh.h>

#include <algorithm>
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

// A piece of a W arc in a texel's gnomonic chart: a straight segment on the line
// g(x, y) = g0 + gx·x + gy·y = m·(c + x e1 + y e2) (W steps by sign(Δg)·side_sum when crossed).
struct Segment {
  Vector2d p, q;  // p.x < q.x
  double gx = 0, gy = 0;
  int side_sum = 0;
  bool spans = false;  // an arc piece that crosses the whole box (both ends cut by its sides)
  size_t arc = 0;      // its arc
  double y_at(double x) const {
    if (x <= std::min(p.x(), q.x())) return p.x() < q.x() ? p.y() : q.y();
    if (x >= std::max(p.x(), q.x())) return p.x() > q.x() ? p.y() : q.y();
    return p.y() + (x - p.x()) * (q.y() - p.y()) / (q.x() - p.x());
  }
};

// A bounding cap of an arc or a path: centre and half-angle (cos, sin); cos_h = −1: the sphere.
struct Cap {
  Vector3d mid = Vector3d::UnitZ();
  double cos_h = -1, sin_h = 0;
};
// The cap of the arc between unit vectors ah and bh.
Cap cap_of_unit(const Vector3d& ah, const Vector3d& bh) {
  const Vector3d sum = ah + bh;
  Cap c;
  const double n = sum.norm();
  if (!(n > 1e-6)) return c;  // (nearly) antipodal ends: no useful bound
  c.mid = sum / n;
  c.cos_h = std::min(1.0, c.mid.dot(ah));
  c.sin_h = std::sqrt(std::max(0.0, 1 - c.cos_h * c.cos_h));
  return c;
}
Cap cap_of(const Vector3d& a, const Vector3d& b) { return cap_of_unit(a.normalized(), b.normalized()); }
// Whether two caps can meet: the angle between their centres is at most the sum of their half
// angles (cos of the sum from the parts; with a margin of 1e-9 for rounding, so it only passes more).
bool caps_meet(const Cap& a, const Cap& b) {
  if (a.cos_h <= -1 || b.cos_h <= -1) return true;
  const double cos_sum = a.cos_h * b.cos_h - a.sin_h * b.sin_h;
  const double sin_sum = a.sin_h * b.cos_h + a.cos_h * b.sin_h;
  if (sin_sum < 0 || cos_sum <= -1 + 1e-9) return true;  // the half angles add up to π or more
  return a.mid.dot(b.mid) >= cos_sum - 1e-9;
}

// Per arc of a call: its bounding cap and unit ends and normal (for the exact cap test).
struct ArcInfo {
  Cap cap;
  Vector3d ah, bh, mh;  // mh = 0: a degenerate arc
};

struct Scratch {
  std::vector<Segment> segments;
  std::vector<double> strips;
  std::vector<std::pair<double, size_t>> active;
  std::vector<Vector2d> band, clip_tmp;
  std::vector<Vector3d> world;
  std::vector<ArcInfo> info;  // per arc of the current call (computed for the arcs that need it)
  std::vector<uint8_t> has_info;
  std::vector<std::vector<size_t>> node_arcs;  // per depth of the cluster tree
  std::vector<double> xs;
  std::vector<std::pair<double, size_t>> order;
  std::vector<size_t> cluster_arcs, texel_arcs;
  std::vector<uint8_t> spanning;  // per cluster-local arc: it crosses the whole cap
  std::vector<int> side_ref;      // its side at the cluster's reference point
  std::vector<double> moments, texel;  // one projection; one cut texel's moments
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
  // A binary tree of bounding caps over the clusters (node 0 the root): a call finds each arc's
  // clusters by descending it, and carries W from a node's reference point (its first cluster's)
  // to its children's, testing only the arcs that meet the node's cap.
  struct Node {
    Vector3d c = Vector3d::UnitZ(), ref = Vector3d::UnitZ();
    double cos_r = -1, sin_r = 0;  // cos_r = −1: wider than 60°, no cap (its parent's arcs pass)
    int left = -1, right = -1;     // children; a leaf holds cluster `cluster`
    int cluster = -1;
  };
  std::vector<Node> nodes;
  int depth = 0;

  int build_node(std::vector<int>& ids, size_t begin, size_t end, int level) {
    depth = std::max(depth, level + 1);
    const int index = int(nodes.size());
    nodes.emplace_back();
    Vector3d c = Vector3d::Zero();
    for (size_t k = begin; k < end; ++k) c += clusters[size_t(ids[k])].c;
    Node n;
    n.ref = clusters[size_t(ids[begin])].ref;
    if (c.norm() > 1e-9) {
      n.c = c.normalized();
      double r = 0;
      for (size_t k = begin; k < end; ++k) {
        const Cluster& cl = clusters[size_t(ids[k])];
        r = std::max(r, std::atan2(n.c.cross(cl.c).norm(), n.c.dot(cl.c)) + std::atan2(cl.sin_r, cl.cos_r));
      }
      if (r < 1.0) n.cos_r = std::cos(r), n.sin_r = std::sin(r);
    }
    if (end - begin == 1) {
      n.cluster = ids[begin];
      n.cos_r = clusters[size_t(ids[begin])].cos_r, n.sin_r = clusters[size_t(ids[begin])].sin_r;
      n.c = clusters[size_t(ids[begin])].c;
    } else {
      // Split at the median along the axis where the centres spread most.
      Vector3d lo = Vector3d::Constant(2), hi = Vector3d::Constant(-2);
      for (size_t k = begin; k < end; ++k) lo = lo.cwiseMin(clusters[size_t(ids[k])].c), hi = hi.cwiseMax(clusters[size_t(ids[k])].c);
      int axis = 0;
      (hi - lo).maxCoeff(&axis);
      const size_t mid = begin + (end - begin) / 2;
      std::nth_element(ids.begin() + std::ptrdiff_t(begin), ids.begin() + std::ptrdiff_t(mid), ids.begin() + std::ptrdiff_t(end),
                       [&](int a, int b) {
                         const double ka = clusters[size_t(a)].c[axis], kb = clusters[size_t(b)].c[axis];
                         return ka < kb || (ka == kb && a < b);
                       });
      n.ref = clusters[size_t(ids[begin])].ref;  // the first cluster after the split: the left child's ref
      n.left = build_node(ids, begin, mid, level + 1);
      n.right = build_node(ids, mid, end, level + 1);
      n.ref = nodes[size_t(n.left)].ref;
    }
    nodes[size_t(index)] = n;
    return index;
  }

  // Descends from node `index`, whose cap the arcs `list` may meet and where W = W_node.
  void descend(int index, std::span<const DcfArc> arcs, const std::vector<size_t>& list, int W_node, double* out,
               Scratch& s, int level) const {
    const Node& n = nodes[size_t(index)];
    if (n.cluster >= 0) {
      const Cluster& cl = clusters[size_t(n.cluster)];
      s.cluster_arcs.clear();
      for (size_t j : list)
        if (meets_cap(s.info[j], cl.c, cl.cos_r, cl.sin_r)) s.cluster_arcs.push_back(j);
      if (s.cluster_arcs.empty()) {
        if (W_node == 0)
          for (size_t i = 0; i < cl.total.size(); ++i) out[i] += cl.total[i];
        return;
      }
      texel_range(cl, arcs, s.cluster_arcs, W_node, out, s);  // visible() leaves cluster_arcs alone
      return;
    }
    for (const int child : {n.left, n.right}) {
      const Node& ch = nodes[size_t(child)];
      // The leg n.ref → ch.ref lies in n's cap (or its nearest capped ancestor's): `list` holds
      // every arc that can cross it.
      const int W_child = W_node + steps_between(arcs, s.info, n.ref, ch.ref, &list);
      std::vector<size_t>& sub = s.node_arcs[size_t(level + 1)];
      sub.clear();
      Cap cap;
      cap.mid = ch.c, cap.cos_h = ch.cos_r, cap.sin_h = ch.sin_r;
      for (size_t j : list)
        if (ch.cos_r <= -1 || caps_meet(s.info[j].cap, cap)) sub.push_back(j);
      descend(child, arcs, sub, W_child, out, s, level + 1);
    }
  }
  std::vector<double> unoccluded;

  // ∫ y_i dω (i < order²) over the chart trapezoid x ∈ [x0, x1] between the lines through
  // (x0, ylo0)–(x1, ylo1) and (x0, yhi0)–(x1, yhi1), added to out.
  // ∫ y_i over the chart trapezoid x ∈ [x0, x1] between the lines through (x0, ylo0)–(x1, ylo1)
  // and (x0, yhi0)–(x1, yhi1), added to out, by Gauss–Legendre (orders above PolygonSH's).
  void gauss_trapezoid(const Texel& t, double x0, double x1, double ylo0, double ylo1, double yhi0, double yhi1,
                       double* out, Scratch& s) const {
    if (!(x1 > x0)) return;
    auto world = [&](double x, double y) { return Vector3d(world_from_frame * (t.c + x * t.e1 + y * t.e2)); };
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

  // ∫ y_i over a polygon of t's chart (counter-clockwise, vertices in `poly`), added to out:
  // PolygonSH's closed form on its world vertices, or above its orders the polygon's trapezoids
  // (slabs between its vertices, inside by the parity of its edges) by Gauss–Legendre. A sliver
  // of (nearly) no area is left out: its vertices are (nearly) on one great circle, where the
  // closed form's solid angle cannot tell it from a hemisphere; below 1e-13 of the texel's chart
  // box, that costs at most as much.
  void polygon_moments(const Texel& t, const std::vector<Vector2d>& poly, double* out, Scratch& s) const {
    const size_t nv = poly.size();
    if (nv < 3) return;
    double area2 = 0;
    for (size_t k = 0; k < nv; ++k) area2 += cross2(poly[k], poly[(k + 1) % nv]);
    const Vector2d box = t.hi - t.lo;
    if (0.5 * area2 <= 1e-13 * box.x() * box.y()) return;
    if (polygon_sh) {
      s.world.clear();
      for (const Vector2d& v : poly) s.world.push_back(world_from_frame * (t.c + v.x() * t.e1 + v.y() * t.e2));
      s.moments.assign(n2, 0.0);
      polygon_sh->project(s.world, s.moments);
      for (size_t i = 0; i < n2; ++i) out[i] += s.moments[i];
      return;
    }
    s.xs.clear();
    for (const Vector2d& v : poly) s.xs.push_back(v.x());
    std::sort(s.xs.begin(), s.xs.end());
    s.xs.erase(std::unique(s.xs.begin(), s.xs.end()), s.xs.end());
    for (size_t k = 0; k + 1 < s.xs.size(); ++k) {
      const double x0 = s.xs[k], x1 = s.xs[k + 1], xm = 0.5 * (x0 + x1);
      s.order.clear();
      for (size_t e = 0; e < nv; ++e) {
        const Vector2d &p = poly[e], &q = poly[(e + 1) % nv];
        if (p.x() == q.x() || xm < std::min(p.x(), q.x()) || xm > std::max(p.x(), q.x())) continue;
        s.order.emplace_back(p.y() + (xm - p.x()) * (q.y() - p.y()) / (q.x() - p.x()), e);
      }
      std::sort(s.order.begin(), s.order.end());
      auto y_at = [&](size_t e, double x) {
        const Vector2d &p = poly[e], &q = poly[(e + 1) % nv];
        return p.y() + (x - p.x()) * (q.y() - p.y()) / (q.x() - p.x());
      };
      for (size_t r = 0; r + 1 < s.order.size(); r += 2) {  // inside between edges 2r and 2r + 1
        const size_t lo = s.order[r].second, hi = s.order[r + 1].second;
        gauss_trapezoid(t, x0, x1, y_at(lo, x0), y_at(lo, x1), y_at(hi, x0), y_at(hi, x1), out, s);
      }
    }
  }

  // The moments of the part of texel t where W = 0, given W at t.ref and the arcs `local`
  // (indices into arcs) that may meet its box; added to out (order² values, unit radiance).
  // In the chart: the arcs' pieces in the box are segments. Strips between every segment end
  // and every crossing of two segments; in a strip the segments do not cross, so they cut it into
  // bands, each with one W; each band with W = 0 is the texel's polygon clipped by the strip's
  // sides and the band's two segment lines (straight lines: great circles), integrated exactly.
  void visible(const Texel& t, std::span<const DcfArc> arcs, std::span<const size_t> local, int W_ref,
               double* out, Scratch& s) const {
    s.segments.clear();
    for (size_t j : local) {
      const DcfArc& arc = arcs[j];
      // The part of the arc inside the box's pyramid: x ≥ lo.x ⇔ (e1 − lo.x c)·ω ≥ 0 and so on,
      // and c·ω ≥ 0; each is linear in the chord parameter λ of ω = a + λ(b − a), which runs
      // over the same directions as the arc.
      double l0 = 0, l1 = 1;
      bool cut0 = false, cut1 = false;
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
        if (fd > 0 && root >= l0) l0 = root, cut0 = true;
        else if (fd < 0 && root <= l1) l1 = root, cut1 = true;
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
      if (!(g.p.allFinite() && g.q.allFinite()) || g.p.x() == g.q.x()) continue;  // vertical: a strip side
      if (g.p.x() > g.q.x()) std::swap(g.p, g.q);
      g.gx = arc.m.dot(t.e1);
      g.gy = arc.m.dot(t.e2);
      g.side_sum = arc.side_sum;
      g.spans = cut0 && cut1;
      g.arc = j;
      s.segments.push_back(g);
    }
    const size_t ns = s.segments.size();
    if (ns == 0) {  // nothing crosses the box: W is W_ref throughout
      if (W_ref == 0)
        for (size_t i = 0; i < n2; ++i) out[i] += t.moments[i];
      return;
    }
    // One arc across the whole box: the texel on one side of its great circle (or all, or
    // nothing): the polygon clipped once by the segment's line and projected once.
    if (ns == 1 && s.segments[0].spans) {
      const Segment& g = s.segments[0];
      const double side = orient2(g.p, g.q, t.ref2);  // > 0: ref2 above the line (left of p → q)
      if (side != 0) {
        const int step_up = sign_of(g.gy) * g.side_sum;  // W's step crossing the line upwards
        const int W_above = side > 0 ? W_ref : W_ref + step_up, W_below = W_above - step_up;
        if (W_above == 0 || W_below == 0) {
          s.band = t.polygon;
          if (W_above == 0) clip_half_plane(s.band, g.p, g.q - g.p, s);
          else clip_half_plane(s.band, g.q, g.p - g.q, s);
          polygon_moments(t, s.band, out, s);
        }
        return;
      }
    }
    double xmin = t.polygon[0].x(), xmax = xmin;
    for (const Vector2d& v : t.polygon) xmin = std::min(xmin, v.x()), xmax = std::max(xmax, v.x());
    s.strips.clear();
    s.strips.push_back(xmin);
    s.strips.push_back(xmax);
    for (size_t i = 0; i < ns; ++i) {
      const Segment& a = s.segments[i];
      s.strips.push_back(a.p.x());
      s.strips.push_back(a.q.x());
      for (size_t j = i + 1; j < ns; ++j) {
        const Segment& b = s.segments[j];
        const double d1 = orient2(a.p, a.q, b.p), d2 = orient2(a.p, a.q, b.q);
        const double d3 = orient2(b.p, b.q, a.p), d4 = orient2(b.p, b.q, a.q);
        if (!((d1 > 0) != (d2 > 0) && d1 != 0 && d2 != 0 && (d3 > 0) != (d4 > 0) && d3 != 0 && d4 != 0)) continue;
        const double f = d1 / (d1 - d2);
        s.strips.push_back(b.p.x() + f * (b.q.x() - b.p.x()));
      }
    }
    std::sort(s.strips.begin(), s.strips.end());
    s.strips.erase(std::unique(s.strips.begin(), s.strips.end()), s.strips.end());
    for (size_t k = 0; k + 1 < s.strips.size(); ++k) {
      const double x0 = s.strips[k], x1 = s.strips[k + 1];
      if (x0 < xmin || x1 > xmax || !(x1 > x0)) continue;
      const double xm = 0.5 * (x0 + x1);
      s.active.clear();
      for (size_t i = 0; i < ns; ++i) {
        const Segment& g = s.segments[i];
        if (xm >= g.p.x() && xm <= g.q.x()) s.active.emplace_back(g.y_at(xm), i);
      }
      std::sort(s.active.begin(), s.active.end());
      // W in the lowest band. The strip's sides are events, so every segment spans x = xm or
      // misses it: the middle of the widest gap between the heights at xm (box sides included)
      // is off every segment, and the straight chart path (a great arc) from ref2 to it decides
      // W there by strict orientation tests; the segments below it are then stepped back over.
      size_t below = 0;
      double gap = -1, yB = 0;
      for (size_t r = 0; r <= s.active.size(); ++r) {
        const double ya = r == 0 ? t.lo.y() : s.active[r - 1].first, yb = r == s.active.size() ? t.hi.y() : s.active[r].first;
        if (yb - ya > gap) gap = yb - ya, yB = 0.5 * (ya + yb), below = r;
      }
      const Vector2d A = t.ref2, B(xm, yB), dAB = B - A;
      int W = W_ref;
      for (const Segment& g : s.segments) {
        const double d1 = orient2(A, B, g.p), d2 = orient2(A, B, g.q);
        const double d3 = orient2(g.p, g.q, A), d4 = orient2(g.p, g.q, B);
        if ((d1 > 0) != (d2 > 0) && d1 != 0 && d2 != 0 && (d3 > 0) != (d4 > 0) && d3 != 0 && d4 != 0)
          W += sign_of(dAB.x() * g.gx + dAB.y() * g.gy) * g.side_sum;
      }
      for (size_t r = 0; r < below; ++r) W -= sign_of(s.segments[s.active[r].second].gy) * s.segments[s.active[r].second].side_sum;
      // Bands from the bottom: band r lies above active segment r − 1 and below segment r.
      for (size_t r = 0; r <= s.active.size(); ++r) {
        if (r > 0) W += sign_of(s.segments[s.active[r - 1].second].gy) * s.segments[s.active[r - 1].second].side_sum;
        if (W != 0) continue;
        s.band = t.polygon;
        clip_half_plane(s.band, Vector2d(x0, 0), Vector2d(0, -1), s);  // x ≥ x0: left of downward
        clip_half_plane(s.band, Vector2d(x1, 0), Vector2d(0, 1), s);   // x ≤ x1: left of upward
        if (r > 0) {
          const Segment& g = s.segments[s.active[r - 1].second];
          clip_half_plane(s.band, g.p, g.q - g.p, s);  // above it: left of p → q (p.x < q.x)
        }
        if (r < s.active.size()) {
          const Segment& g = s.segments[s.active[r].second];
          clip_half_plane(s.band, g.q, g.p - g.q, s);  // below it: left of q → p
        }
        polygon_moments(t, s.band, out, s);
      }
    }
  }

  // Sutherland–Hodgman: keeps the part of `poly` left of the directed line through `a` along `d`.
  static void clip_half_plane(std::vector<Vector2d>& poly, const Vector2d& a, const Vector2d& d, Scratch& s) {
    s.clip_tmp.clear();
    const size_t n = poly.size();
    for (size_t k = 0; k < n; ++k) {
      const Vector2d &p = poly[k], &q = poly[(k + 1) % n];
      const double fp = cross2(d, p - a), fq = cross2(d, q - a);
      if (fp >= 0) s.clip_tmp.push_back(p);
      if ((fp > 0 && fq < 0) || (fp < 0 && fq > 0)) s.clip_tmp.push_back(p + (fp / (fp - fq)) * (q - p));
    }
    poly.swap(s.clip_tmp);
  }

  // Whether the arc comes within the cap (c, r) (r < π/2): its nearest point to c is an end or the
  // foot of c on its great circle.
  static bool meets_cap(const ArcInfo& arc, const Vector3d& c, double cos_r, double sin_r) {
    if (c.dot(arc.ah) >= cos_r || c.dot(arc.bh) >= cos_r) return true;
    const double s = c.dot(arc.mh);
    if (arc.mh.squaredNorm() == 0 || std::abs(s) > sin_r) return false;
    const Vector3d foot = c - s * arc.mh;
    return arc.ah.cross(foot).dot(arc.mh) >= 0 && foot.cross(arc.bh).dot(arc.mh) >= 0 && foot.dot(arc.ah + arc.bh) > 0;
  }
  static ArcInfo info_of(const DcfArc& arc) {
    ArcInfo i;
    i.ah = arc.a.normalized(), i.bh = arc.b.normalized();
    i.cap = cap_of_unit(i.ah, i.bh);
    const double nm = arc.m.norm();
    i.mh = nm > 0 ? Vector3d(arc.m / nm) : Vector3d::Zero();
    return i;
  }

  // A point a quarter turn from `from`, off every axis plane: the arcs of an axis-aligned scene and
  // the horizon's quarter arcs (whose ends lie in the frame's axis planes for some normals) must
  // not pass through a W path's corner by symmetry.
  static Vector3d waypoint(const Vector3d& from) {
    const Vector3d generic(0.5466, -0.3719, 0.7503);
    Vector3d m = from.cross(generic);
    if (m.squaredNorm() < 1e-6 * from.squaredNorm()) m = from.cross(Vector3d(-0.2377, 0.8716, 0.4288));
    return m.normalized();
  }

  // The steps of the arcs crossed on the way from `from` to `to` (via a waypoint when the two are
  // nearly opposite), testing only the arcs whose caps meet the leg's.
  // (`subset`: the arcs that may cross it, indices into arcs; empty: all of them.)
  static int steps_between(std::span<const DcfArc> arcs, std::span<const ArcInfo> info, const Vector3d& from,
                           const Vector3d& to, const std::vector<size_t>* subset = nullptr) {
    if (from.dot(to) <= -0.5 * from.norm() * to.norm()) {
      const Vector3d mid = waypoint(from);
      return steps_between(arcs, info, from, mid, subset) + steps_between(arcs, info, mid, to, subset);
    }
    if (from == to) return 0;
    const Cap leg = cap_of(from, to);
    int w = 0;
    auto test = [&](size_t j) {
      if (caps_meet(info[j].cap, leg)) w += dcf_path_steps(arcs.subspan(j, 1), from, to);
    };
    if (subset)
      for (size_t j : *subset) test(j);
    else
      for (size_t j = 0; j < arcs.size(); ++j) test(j);
    return w;
  }

  // W at the frame direction to, from W0 at s0 (via a waypoint when the two are nearly opposite).
  static int W_at(std::span<const DcfArc> arcs, const Vector3d& s0, int W0, const Vector3d& to) {
    if (s0.dot(to) > -0.5 * s0.norm() * to.norm()) return W0 + dcf_path_steps(arcs, s0, to);
    const Vector3d mid = waypoint(s0);
    return W0 + dcf_path_steps(arcs, s0, mid) + dcf_path_steps(arcs, mid, to);
  }

  // Accumulates the radiance-weighted moments of texels [begin, end) of cluster `cl` (W at its
  // centre is Wc, its local arcs `local`).
  void texel_range(const Cluster& cl, std::span<const DcfArc> arcs, std::span<const size_t> local, int Wc, double* out,
                   Scratch& s) const {
    // A local arc with both ends outside the cluster's cap covers its great circle's whole chord
    // of the cap (the cap is convex): there, crossing it is changing sides of that great circle,
    // and meeting a texel's cap is coming within its radius of the circle. Only the arcs that end
    // inside the cap need the path test.
    s.spanning.assign(local.size(), 0);
    s.side_ref.assign(local.size(), 0);
    for (size_t q = 0; q < local.size(); ++q) {
      const ArcInfo& a = s.info[local[q]];
      if (a.mh.squaredNorm() > 0 && cl.c.dot(a.ah) < cl.cos_r && cl.c.dot(a.bh) < cl.cos_r) {
        s.spanning[q] = 1;
        s.side_ref[q] = sign_of(arcs[local[q]].m.dot(cl.ref));
      }
    }
    for (size_t k = cl.begin; k < cl.end; ++k) {
      const Texel& t = texels[k];
      s.texel_arcs.clear();
      // The short arc from the cluster's reference point to the texel's stays in the cluster's
      // cap: only its local arcs can cross it.
      int W = Wc;
      for (size_t q = 0; q < local.size(); ++q) {
        const size_t j = local[q];
        const ArcInfo& a = s.info[j];
        if (s.spanning[q]) {
          if (std::abs(t.c.dot(a.mh)) <= t.sin_r) s.texel_arcs.push_back(j);
          const int side = sign_of(arcs[j].m.dot(t.ref));
          if (side != 0 && s.side_ref[q] != 0 && side != s.side_ref[q]) W += side * arcs[j].side_sum;
        } else {
          if (meets_cap(a, t.c, t.cos_r, t.sin_r)) s.texel_arcs.push_back(j);
          W += dcf_path_steps(arcs.subspan(j, 1), cl.ref, t.ref);
        }
      }
      const double* mom = nullptr;
      if (s.texel_arcs.empty()) {
        if (W != 0) continue;
        mom = t.moments.data();
      } else {
        s.texel.assign(n2, 0.0);
        visible(t, arcs, s.texel_arcs, W, s.texel.data(), s);  // visible() leaves texel_arcs alone
        mom = s.texel.data();
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
    I.polygon_moments(t, t.polygon, t.moments.data(), s);
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
  if (!I.clusters.empty()) {
    std::vector<int> ids(I.clusters.size());
    std::iota(ids.begin(), ids.end(), 0);
    I.nodes.reserve(2 * ids.size());
    I.build_node(ids, 0, ids.size(), 0);
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
  if (I.nodes.empty()) return;
  Scratch& s = tl_scratch;
  s.info.resize(arcs.size());
  s.has_info.assign(arcs.size(), 0);
  s.node_arcs.resize(size_t(I.depth) + 1);
  // An arc's cap and unit vectors only when a test needs them: most arcs of a cluttered scene
  // are dismissed by one of the two plane tests below, which need neither.
  auto info = [&](size_t j) -> const ArcInfo& {
    if (!s.has_info[j]) {
      s.info[j] = Impl::info_of(arcs[j]);
      s.has_info[j] = 1;
    }
    return s.info[j];
  };
  // Relative margin of the plane tests: far above the rounding of a·m and b·m, so an arc they
  // dismiss is dismissed by the exact-arithmetic argument, never by rounding.
  constexpr double kMargin = 1e-7;
  std::vector<size_t>& root = s.node_arcs[0];
  root.clear();
  const Impl::Node& n = I.nodes[0];
  Cap cap;
  cap.mid = n.c, cap.cos_h = n.cos_r, cap.sin_h = n.sin_r;
  const double gc_limit = n.sin_r + kMargin;
  for (size_t j = 0; j < arcs.size(); ++j) {
    if (arcs[j].side_sum == 0) continue;
    if (n.cos_r > -1) {
      // The arc's great circle passes farther than the root cap's radius (< 1 rad) from its
      // centre, |c·m̂| > sin r: the arc cannot meet the cap nor, the cap being convex, any cap
      // or path inside it (every cluster's cap and every leg descend() tests are in it).
      const Vector3d& m = arcs[j].m;
      const double cm = n.c.dot(m), m2 = m.squaredNorm();
      if (m2 > 0 && cm * cm > gc_limit * gc_limit * m2) continue;
    }
    if (caps_meet(info(j).cap, cap)) root.push_back(j);  // (caps_meet passes every arc when cos_r = −1)
  }
  // W at the root's reference point from s0: a long path, the legs of steps_between (via a
  // waypoint when nearly opposite), every arc tested by its cap first, then by dcf_path_steps. An
  // arc with both ends clearly on one side of a leg's great circle cannot cross the leg
  // (dcf_path_steps would add 0): dismissed before its cap is computed.
  int W_root = W0;
  auto leg = [&](auto&& self, const Vector3d& from, const Vector3d& to) -> void {
    if (from.dot(to) <= -0.5 * from.norm() * to.norm()) {
      const Vector3d mid = Impl::waypoint(from);
      self(self, from, mid);
      self(self, mid, to);
      return;
    }
    if (from == to) return;
    const Cap leg_cap = cap_of(from, to);
    const Vector3d m2 = from.cross(to);
    const double m2n = m2.squaredNorm(), k2 = kMargin * kMargin * m2n;
    for (size_t j = 0; j < arcs.size(); ++j) {
      const DcfArc& arc = arcs[j];
      const double da = arc.a.dot(m2), db = arc.b.dot(m2);
      if (((da > 0 && db > 0) || (da < 0 && db < 0)) && da * da > k2 * arc.a.squaredNorm() &&
          db * db > k2 * arc.b.squaredNorm())
        continue;
      if (caps_meet(info(j).cap, leg_cap)) W_root += dcf_path_steps(arcs.subspan(j, 1), from, to);
    }
  };
  leg(leg, s0, n.ref);
  I.descend(0, arcs, root, W_root, out, s, 0);
}

std::vector<double> HotTexels::texel_moments(int texel, std::span<const DcfArc> arcs, const Vector3d& s0, int W0) const {
  const Impl& I = *impl_;
  std::vector<double> out(I.n2, 0.0);
  for (const Impl::Texel& t : I.texels) {
    if (t.index != texel) continue;
    Scratch& s = tl_scratch;
    s.info.resize(arcs.size());
    for (size_t j = 0; j < arcs.size(); ++j) s.info[j] = Impl::info_of(arcs[j]);
    std::vector<size_t> local;
    for (size_t j = 0; j < arcs.size(); ++j)
      if (arcs[j].side_sum != 0 && Impl::meets_cap(s.info[j], t.c, t.cos_r, t.sin_r)) local.push_back(j);
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


} // namespace prt::bake
