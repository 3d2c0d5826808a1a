// visible_region.cpp — the boundary arcs of a light minus a union of occluders on the sphere
// (bake/visibility/visible_region.h has the method and its predicates).
#include <bake/visibility/visible_region.h>

#include <bake/core/error.h>
#include <bake/visibility/contour.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace prt::bake {

namespace {

using V3 = Eigen::Vector3d;
using Polygon = std::span<const V3>;

// Exact sign of det(c, d, x): the side of x with respect to the great circle through c and d.
// A shared vertex (x bitwise c or d: adjacent triangles of a mesh, front and back faces of one
// edge) is 0 at once; the floating-point filter cannot decide an exact zero and would evaluate
// the expansion.
int side(const V3& c, const V3& d, const V3& x) {
  if (x == c || x == d) return 0;
  return orient3d_exact(c, d, x, V3::Zero());
}

// A position along the edge being cut: parameter τ ∈ [0, 1] (monotone along the arc) and point.
struct Bound {
  double t;
  V3 x;
};

// The part of an edge where its left (or right) side is inside a polygon: [lo, hi], or empty.
struct Interval {
  Bound lo, hi;
  bool empty = false;
};

// Sign of m_e·m_f for edges e = (a, b) and f = (c, d) on one great circle: q is any vertex of
// f's polygon off that circle, so m_e = λ m_f gives det(a, b, q) = λ det(c, d, q).
int same_direction(const V3& a, const V3& b, const V3& c, const V3& d, Polygon poly) {
  for (const V3& q : poly) {
    const int sq = side(c, d, q);
    if (sq != 0) return side(a, b, q) * sq;
  }
  return 0;  // a polygon on one great circle: no area (excluded by the preconditions)
}

// |det(c, d, x)| with (c, d) taken in lexicographic order, so that an edge and its reverse (two
// triangles sharing it) give the same bits.
double abs_det(const V3& c, const V3& d, const V3& x) {
  const bool swap = std::lexicographical_compare(d.data(), d.data() + 3, c.data(), c.data() + 3);
  return swap ? std::abs(d.dot(c.cross(x))) : std::abs(c.dot(d.cross(x)));
}

// The point where the arc (a, b) meets the great circle of (c, d) (the arc's ends on opposite
// sides): a positive combination of a and b, the same bits for either direction of either edge.
V3 cut_point(const V3& a, const V3& b, const V3& c, const V3& d) {
  const bool swap = std::lexicographical_compare(b.data(), b.data() + 3, a.data(), a.data() + 3);
  const V3& lo = swap ? b : a;
  const V3& hi = swap ? a : b;
  return abs_det(c, d, hi) * lo + abs_det(c, d, lo) * hi;
}

// Where the left side [0] and the right side [1] of e = (a, b) are strictly inside the convex
// polygon poly (each edge's half-space, sides decided exactly; see the header). A crossing point
// of e with an edge f is computed the same way whichever of the two is being cut (from the edge
// of the polygon listed first, e's own when e_first), so the pieces of both share it bit for bit
// and the boundary arcs close exactly.
void inside_intervals(const V3& a, const V3& b, Polygon poly, bool e_first, Interval (&out)[2]) {
  out[0] = out[1] = Interval{{0.0, a}, {1.0, b}, false};
  const size_t n = poly.size();
  for (size_t k = 0; k < n; ++k) {
    const V3& c = poly[k];
    const V3& d = poly[k + 1 == n ? 0 : k + 1];
    const int sa = side(c, d, a), sb = side(c, d, b);
    if (sa == 0 && sb == 0) {  // e lies on f's great circle: the sides are e's two sides
      const int s = same_direction(a, b, c, d, poly);
      out[s > 0 ? 1 : 0].empty = true;
      if (s == 0) out[1].empty = true;
      continue;
    }
    if (sa >= 0 && sb >= 0) continue;  // the open edge is inside this half-space
    if (sa <= 0 && sb <= 0) {          // … or outside it
      out[0].empty = out[1].empty = true;
      return;
    }
    const double da = abs_det(c, d, a), db = abs_det(c, d, b);
    const Bound cut{da + db > 0 ? da / (da + db) : 0.5, e_first ? cut_point(a, b, c, d) : cut_point(c, d, a, b)};
    for (Interval& i : out) {
      if (sa > 0 && cut.t < i.hi.t) i.hi = cut;   // inside before the crossing
      if (sa < 0 && cut.t > i.lo.t) i.lo = cut;   // inside after it
    }
  }
  for (Interval& i : out) i.empty = i.empty || !(i.lo.t < i.hi.t);
}

// The part of e = (a, b) covered by an edge f = (c, d) lying on e's great circle (either
// direction), as an interval along e; parameters in floating point (exact for shared vertices).
Interval collinear_overlap(const V3& a, const V3& b, const V3& c, const V3& d, int direction) {
  const V3 m = a.cross(b);
  const V3& c1 = direction > 0 ? c : d;  // f run in e's direction
  const V3& d1 = direction > 0 ? d : c;
  auto param = [&](const V3& x, bool& within) {
    const double s = a.cross(x).dot(m), t = x.cross(b).dot(m);
    within = s >= 0 && t >= 0;
    return s + t > 0 ? s / (s + t) : 0.0;
  };
  auto in_f = [&](const V3& x) { return c1.cross(x).dot(m) >= 0 && x.cross(d1).dot(m) >= 0; };
  Interval out{{0.0, a}, {1.0, b}, false};
  bool within = false;
  const double tc = param(c1, within);
  if (within) {
    out.lo = {tc, c1};
  } else if (!in_f(a)) {
    out.empty = true;
  }
  const double td = param(d1, within);
  if (within) {
    out.hi = {td, d1};
  } else if (!in_f(b)) {
    out.empty = true;
  }
  out.empty = out.empty || !(out.lo.t < out.hi.t);
  return out;
}

// pieces −= cut (pieces sorted and disjoint).
void subtract(std::vector<Interval>& pieces, const Interval& cut) {
  if (cut.empty) return;
  std::vector<Interval> out;
  for (const Interval& p : pieces) {
    if (!(cut.lo.t < p.hi.t && p.lo.t < cut.hi.t)) {
      out.push_back(p);
      continue;
    }
    if (p.lo.t < cut.lo.t) out.push_back({p.lo, cut.lo, false});
    if (cut.hi.t < p.hi.t) out.push_back({cut.hi, p.hi, false});
  }
  pieces = std::move(out);
}

// A spherical cap {ω : ω̂·c ≥ cos r} holding a polygon or an arc, enlarged by a margin far above
// rounding (1e-12 in cos r); all = true when it would reach a hemisphere (then never separates).
// Two caps with c1·c2 < cos(r1 + r2) − 1e-12 are disjoint, and so are what they hold: the exact
// predicates could only find empty intervals there, so the pair is skipped (a filter, not a
// decision: it changes no result beyond dropping empty cuts).
struct Cap {
  V3 c = V3::Zero();
  double cos_r = 0, sin_r = 1;
  bool all = true;
};

constexpr double kCapMargin = 1e-12;

Cap cap_of(std::span<const V3> points) {
  Cap cap;
  for (const V3& v : points) cap.c += v.normalized();
  const double len = cap.c.norm();
  if (!(len > 0)) return cap;
  cap.c /= len;
  double lo = 1;
  for (const V3& v : points) lo = std::min(lo, cap.c.dot(v.normalized()));
  cap.cos_r = lo - kCapMargin;
  if (!(cap.cos_r > kCapMargin)) return cap;  // a hemisphere or more: no filtering
  cap.sin_r = std::sqrt(std::max(0.0, 1 - cap.cos_r * cap.cos_r));
  cap.all = false;
  return cap;
}

bool disjoint(const Cap& x, const Cap& y) {
  if (x.all || y.all) return false;
  return x.c.dot(y.c) < x.cos_r * y.cos_r - x.sin_r * y.sin_r - kCapMargin;
}

}  // namespace

void visible_region(std::span<const V3> light, std::span<const std::vector<V3>> occluders, std::vector<Arc>& out) {
  out.clear();
  if (light.size() < 3) return;
  std::vector<Polygon> polygons{light};
  for (const auto& o : occluders)
    if (o.size() >= 3) polygons.emplace_back(o);

  std::vector<Cap> caps;
  for (const Polygon poly : polygons) caps.push_back(cap_of(poly));
  std::vector<Interval> pieces;
  for (size_t i = 0; i < polygons.size(); ++i) {
    const Polygon poly = polygons[i];
    for (size_t k = 0; k < poly.size(); ++k) {
      const V3& a = poly[k];
      const V3& b = poly[k + 1 == poly.size() ? 0 : k + 1];
      if (a == b) continue;
      // The side of e that may border V: left for the light, right for an occluder.
      const int which = i == 0 ? 0 : 1;
      Interval in[2];
      const V3 ends[2] = {a, b};
      const Cap edge_cap = cap_of(ends);
      pieces.assign(1, Interval{{0.0, a}, {1.0, b}, false});
      if (i != 0) {  // an occluder edge borders V only inside the light
        if (disjoint(edge_cap, caps[0])) continue;
        inside_intervals(a, b, light, false, in);
        if (in[1].empty) continue;
        pieces.assign(1, in[1]);
      }
      for (size_t j = 1; j < polygons.size() && !pieces.empty(); ++j) {
        if (j == i || disjoint(edge_cap, caps[j])) continue;
        inside_intervals(a, b, polygons[j], i < j, in);
        subtract(pieces, in[which]);
      }
      // Pieces on a great circle shared with an edge of an earlier polygon belong to that edge.
      for (size_t j = 0; j < i && !pieces.empty(); ++j) {
        if (disjoint(edge_cap, caps[j])) continue;
        const Polygon other = polygons[j];
        for (size_t f = 0; f < other.size(); ++f) {
          const V3& c = other[f];
          const V3& d = other[f + 1 == other.size() ? 0 : f + 1];
          if (side(c, d, a) != 0 || side(c, d, b) != 0) continue;
          subtract(pieces, collinear_overlap(a, b, c, d, same_direction(a, b, c, d, other)));
        }
      }
      for (const Interval& p : pieces) {
        if (i == 0) {
          out.push_back({p.lo.x, p.hi.x});
        } else {
          out.push_back({p.hi.x, p.lo.x});
        }
      }
    }
  }
}

ConvexPolyhedron::ConvexPolyhedron(std::vector<V3> vertices, std::vector<std::vector<uint32_t>> faces)
    : vertices_(std::move(vertices)), faces_(std::move(faces)) {
  std::map<std::pair<uint32_t, uint32_t>, uint32_t> edge_face;
  for (size_t f = 0; f < faces_.size(); ++f) {
    const auto& q = faces_[f];
    PRT_CHECK(q.size() >= 3);
    for (size_t k = 0; k < q.size(); ++k) {
      PRT_CHECK(q[k] < vertices_.size());
      PRT_CHECK(edge_face.emplace(std::pair(q[k], q[(k + 1) % q.size()]), uint32_t(f)).second);
    }
  }
  for (const auto& q : faces_) {
    twin_face_.emplace_back();
    for (size_t k = 0; k < q.size(); ++k) {
      const auto twin = edge_face.find({q[(k + 1) % q.size()], q[k]});
      PRT_CHECK(twin != edge_face.end());
      twin_face_.back().push_back(twin->second);
    }
  }
}

bool ConvexPolyhedron::front_facing(size_t face, const V3& p) const {
  const auto& q = faces_[face];
  return orient3d_exact(vertices_[q[0]], vertices_[q[1]], vertices_[q[2]], p) < 0;
}

bool ConvexPolyhedron::silhouette(const V3& p, std::vector<V3>& out) const {
  out.clear();
  std::vector<char> front(faces_.size());
  for (size_t f = 0; f < faces_.size(); ++f) front[f] = front_facing(f, p);
  // next[v] = u for a silhouette edge (u, v) of a front face, taken reversed.
  std::vector<int64_t> next(vertices_.size(), -1);
  int64_t start = -1;
  size_t edges = 0;
  for (size_t f = 0; f < faces_.size(); ++f) {
    if (!front[f]) continue;
    const auto& q = faces_[f];
    for (size_t k = 0; k < q.size(); ++k) {
      if (front[twin_face_[f][k]]) continue;
      next[q[(k + 1) % q.size()]] = q[k];
      start = q[k];
      ++edges;
    }
  }
  if (start < 0) return false;
  int64_t at = start;
  do {
    out.push_back(vertices_[size_t(at)] - p);
    at = next[size_t(at)];
    PRT_CHECK(at >= 0 && out.size() <= edges);  // one loop (the body is convex)
  } while (at != start);
  return true;
}

void ConvexPolyhedron::front_triangles(const V3& p, std::vector<std::vector<V3>>& out) const {
  out.clear();
  for (size_t f = 0; f < faces_.size(); ++f) {
    if (!front_facing(f, p)) continue;
    const auto& q = faces_[f];
    for (size_t k = 1; k + 1 < q.size(); ++k)
      out.push_back({vertices_[q[0]] - p, vertices_[q[k + 1]] - p, vertices_[q[k]] - p});
  }
}

} // namespace prt::bake
