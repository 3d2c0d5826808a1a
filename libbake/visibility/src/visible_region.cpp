// visible_region.cpp — the boundary arcs of a light minus a union of occluders on the sphere
// (bake/visibility/visible_region.h has the method and its predicates).
#include <bake/visibility/visible_region.h>

#include <bake/core/error.h>
#include <bake/visibility/contour.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
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
// A floating-point filter first: det(c, d, x) = (c × d)·x computed in double errs by less than
// 8u |c|₁|d|₁|x|₁ (u = 2⁻⁵³); beyond 1e-14 of that product its sign is the exact one.
int side_filtered(const V3& m, double cd, const V3& c, const V3& d, const V3& x) {
  if (x == c || x == d) return 0;
  const double v = m.dot(x), bound = 1e-14 * cd * x.cwiseAbs().sum();
  if (v > bound) return 1;
  if (v < -bound) return -1;
  return orient3d_exact(c, d, x, V3::Zero());
}

int side(const V3& c, const V3& d, const V3& x) {
  return side_filtered(c.cross(d), c.cwiseAbs().sum() * d.cwiseAbs().sum(), c, d, x);
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
  const double at_hi = abs_det(c, d, hi), at_lo = abs_det(c, d, lo);
  // Both ends within rounding of the circle (a near-degenerate edge (c, d)): the middle, as the
  // parameter 0.5 that inside_intervals then takes.
  if (at_hi == 0 && at_lo == 0) return lo + hi;
  return at_hi * lo + at_lo * hi;
}

// Where the left side [0] and the right side [1] of e = (a, b) are strictly inside the convex
// polygon poly (each edge's half-space, sides decided exactly; see the header). A crossing point
// of e with an edge f is computed the same way whichever of the two is being cut (from the edge
// of the polygon listed first, e's own when e_first), so the pieces of both share it bit for bit
// and the boundary arcs close exactly.
// collinear (if given) gets bit k for each edge k < 32 of poly whose great circle holds e; it is
// left incomplete only when e misses poly's interior, and then e shares no arc with its edges.
// normals (if given): per edge k of poly, c × d and |c|₁|d|₁ (the filter of side_filtered).
struct EdgeNormal {
  V3 m;
  double cd;
};

void inside_intervals(const V3& a, const V3& b, Polygon poly, bool e_first, Interval (&out)[2],
                      uint32_t* collinear = nullptr, const EdgeNormal* normals = nullptr) {
  out[0] = out[1] = Interval{{0.0, a}, {1.0, b}, false};
  const size_t n = poly.size();
  if (collinear) *collinear = 0;
  for (size_t k = 0; k < n; ++k) {
    const V3& c = poly[k];
    const V3& d = poly[k + 1 == n ? 0 : k + 1];
    int sa = 0, sb = 0;
    if (normals) {
      sa = side_filtered(normals[k].m, normals[k].cd, c, d, a);
      sb = side_filtered(normals[k].m, normals[k].cd, c, d, b);
    } else {
      sa = side(c, d, a);
      sb = side(c, d, b);
    }
    if (sa == 0 && sb == 0) {  // e lies on f's great circle: the sides are e's two sides
      if (collinear && k < 32) *collinear |= 1u << k;
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

// pieces −= cut (pieces sorted and disjoint); out is scratch.
void subtract(std::vector<Interval>& pieces, const Interval& cut, std::vector<Interval>& out) {
  if (cut.empty) return;
  out.clear();
  for (const Interval& p : pieces) {
    if (!(cut.lo.t < p.hi.t && p.lo.t < cut.hi.t)) {
      out.push_back(p);
      continue;
    }
    if (p.lo.t < cut.lo.t) out.push_back({p.lo, cut.lo, false});
    if (cut.hi.t < p.hi.t) out.push_back({cut.hi, p.hi, false});
  }
  std::swap(pieces, out);
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

namespace {

constexpr uint32_t kUnknownSides = ~0u;

// Scratch of edge_pieces.
struct EdgeScratch {
  std::vector<Interval> pieces, tmp;
  std::vector<std::pair<uint32_t, uint32_t>> collinear;  // (occluder j < i, its edges on e's circle)
};

// The pieces of edge e = (a, b) of polygons[i] that bound V, appended to out (the per-edge step
// of the header's method). for_others(f) calls f(j) for the occluders j ≥ 1, j ≠ i, ascending,
// that may overlap e, and may stop once f returns false (nothing of e is left to cut): every
// other one must give an empty interval (up to rounding) and share no piece of e's great circle
// with e. Occluder edges are first clipped to the light (the caller has found in[1] of the light
// when i ≠ 0: passed as `in_light`). normals_of(j) gives polygon j's EdgeNormals (j = 0: the
// light's) or nullptr (then side() computes them).
template <class ForOthers, class NormalsOf>
void edge_pieces(std::span<const Polygon> polygons, size_t i, const V3& a, const V3& b, const Interval* in_light,
                 ForOthers&& for_others, NormalsOf&& normals_of, EdgeScratch& s, std::vector<Arc>& out) {
  // The side of e that may border V: left for the light, right for an occluder.
  const int which = i == 0 ? 0 : 1;
  Interval in[2];
  std::vector<Interval>& pieces = s.pieces;
  pieces.assign(1, i == 0 ? Interval{{0.0, a}, {1.0, b}, false} : *in_light);
  s.collinear.clear();
  for_others([&](size_t j) {
    if (pieces.empty()) return false;
    uint32_t collinear = 0;
    inside_intervals(a, b, polygons[j], i < j, in, &collinear, normals_of(j));
    subtract(pieces, in[which], s.tmp);
    if ((collinear != 0 || polygons[j].size() > 32) && j < i) s.collinear.emplace_back(uint32_t(j), collinear);
    return !pieces.empty();
  });
  // Pieces on a great circle shared with an edge of an earlier polygon belong to that edge.
  auto collinear = [&](size_t j, uint32_t mask) {
    const Polygon other = polygons[j];
    const EdgeNormal* normals = nullptr;
    for (size_t f = 0; f < other.size() && !pieces.empty(); ++f) {
      const bool unknown = mask == kUnknownSides || f >= 32;  // else mask says it
      if (!unknown && !(mask & (1u << f))) continue;
      const V3& c = other[f];
      const V3& d = other[f + 1 == other.size() ? 0 : f + 1];
      if (unknown) {  // the same exact signs as side(), with the normals already computed
        if (!normals) normals = normals_of(j);
        const int sa = normals ? side_filtered(normals[f].m, normals[f].cd, c, d, a) : side(c, d, a);
        if (sa != 0 || (normals ? side_filtered(normals[f].m, normals[f].cd, c, d, b) : side(c, d, b)) != 0) continue;
      }
      subtract(pieces, collinear_overlap(a, b, c, d, same_direction(a, b, c, d, other)), s.tmp);
    }
  };
  if (i != 0 && !pieces.empty()) collinear(0, kUnknownSides);
  for (const auto& [j, mask] : s.collinear) collinear(j, mask);
  for (const Interval& p : pieces) {
    if (i == 0) {
      out.push_back({p.lo.x, p.hi.x});
    } else {
      out.push_back({p.hi.x, p.lo.x});
    }
  }
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
  EdgeScratch scratch;
  for (size_t i = 0; i < polygons.size(); ++i) {
    const Polygon poly = polygons[i];
    for (size_t k = 0; k < poly.size(); ++k) {
      const V3& a = poly[k];
      const V3& b = poly[k + 1 == poly.size() ? 0 : k + 1];
      if (a == b) continue;
      const V3 ends[2] = {a, b};
      const Cap edge_cap = cap_of(ends);
      Interval in[2];
      if (i != 0) {  // an occluder edge borders V only inside the light
        if (disjoint(edge_cap, caps[0])) continue;
        inside_intervals(a, b, light, false, in);
        if (in[1].empty) continue;
      }
      edge_pieces(polygons, i, a, b, &in[1], [&](auto&& f) {
        for (size_t j = 1; j < polygons.size(); ++j)
          if (j != i && !disjoint(edge_cap, caps[j]) && !f(j)) return;
      }, [](size_t) { return static_cast<const EdgeNormal*>(nullptr); }, scratch, out);
    }
  }
}

// ---- the sparse variant: chosen boundary edges, a grid over the light's gnomonic chart --------

namespace {

// Chart margin: the gnomonic coordinates of a direction err by a few ulps of their magnitude
// (divided by c·ω̂ > kFrontCos); 1e-9 of the chart's scale is far above that.
constexpr double kChartMargin = 1e-9;
constexpr double kFrontCos = 1e-3;  // a polygon with a vertex at c·ω̂ ≤ this is not charted
constexpr double kChartCos = 0.1;   // the chart is used when every light vertex has c·ω̂ > this
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr uint32_t kMaxGrid = 48;
constexpr double kGridDensity = 1.0;  // cells per side / √(charted occluders) (bench_area: 0.5–1 alike)

// The gnomonic chart about c (ω ↦ (e1·ω, e2·ω)/(c·ω)): great circles map to lines, so an arc
// maps to the chord of its end points and a convex polygon in c's open hemisphere to the convex
// hull of its vertices' points. A uniform grid of cells over the light's box.
struct Chart {
  V3 c, e1, e2;
  double lo[2] = {0, 0}, hi[2] = {0, 0}, cell[2] = {1, 1}, inverse[2] = {1, 1}, margin = 0;
  uint32_t n[2] = {1, 1};

  void at(const V3& w, double g[2]) const {
    const double z = 1 / c.dot(w);
    g[0] = e1.dot(w) * z;
    g[1] = e2.dot(w) * z;
  }
  // Cells [c0, c1] along axis for coordinates [x0, x1] (with margins), clamped; false when the
  // range misses the grid. Monotone in x0 and x1, so overlapping ranges share a cell.
  bool cells(int axis, double x0, double x1, uint32_t& c0, uint32_t& c1) const {
    if (x1 < lo[axis] || x0 > hi[axis]) return false;
    const double top = double(n[axis] - 1);
    // Clamped to [0, top] first, so truncation is the floor.
    c0 = uint32_t(std::clamp((x0 - lo[axis]) * inverse[axis], 0.0, top));
    c1 = uint32_t(std::clamp((x1 - lo[axis]) * inverse[axis], 0.0, top));
    return true;
  }
};

struct Box {
  double lo[2], hi[2];
  bool in = false;    // charted and meeting the chart's box
  uint32_t first = 0;  // its vertices' chart points: RegionScratch::Impl::points[first, first + size)
  uint32_t cells[4];   // x0, x1, y0, y1 (when in and not wide)
};

}  // namespace

struct RegionScratch::Impl {
  Chart chart;
  std::vector<Polygon> polygons;
  std::vector<Cap> caps;
  std::vector<Box> boxes;
  std::vector<std::array<double, 2>> points;
  // Per polygon vertex k: its edge (k, k + 1), from boxes[j].first; computed when polygon j is
  // first cut against (normal_stamp[j] == normal_mark); light_normals: the light's edges.
  std::vector<EdgeNormal> normals, light_normals;
  std::vector<uint32_t> wide, cell_start, cell_fill, cell_items, near, stamp, normal_stamp;
  uint32_t mark = 0, normal_mark = 0;
  // The chord's filter of near() (see there), for the edge being cut.
  double box_lo[2] = {0, 0}, box_hi[2] = {0, 0}, nx = 0, ny = 0, nz = 0, slack = 0;
  EdgeScratch edge;
};

RegionScratch::RegionScratch() : impl_(std::make_unique<Impl>()) {}
RegionScratch::~RegionScratch() = default;
RegionScratch::RegionScratch(const RegionScratch&) : impl_(std::make_unique<Impl>()) {}
RegionScratch& RegionScratch::operator=(const RegionScratch&) { return *this; }

void visible_region_sparse(std::span<const V3> light, std::span<const std::vector<V3>> occluders,
                           std::span<const uint8_t> boundary, std::vector<Arc>& out, RegionScratch& scratch) {
  out.clear();
  scratch.boundary_edges = 0;
  scratch.charted = false;
  if (light.size() < 3) return;
  PRT_CHECK(boundary.size() == occluders.size());
  RegionScratch::Impl& s = *scratch.impl_;
  // Polygon numbering as visible_region's: the light, then the occluders (one with < 3 vertices
  // an empty span that meets nothing), so the "listed first" rules decide alike.
  s.polygons.clear();
  s.polygons.emplace_back(light);
  for (const auto& o : occluders) s.polygons.emplace_back(o.size() >= 3 ? Polygon(o) : Polygon());
  const std::span<const Polygon> polygons(s.polygons);
  const size_t count = polygons.size();

  // The chart about the light's cap centre: every light vertex at c·ω̂ > 0.1, so every point of
  // the (convex) light has c·ω > 0.
  Chart& chart = s.chart;
  const Cap light_cap = cap_of(light);
  bool charted = !light_cap.all;
  for (const V3& v : light) charted = charted && light_cap.c.dot(v.normalized()) > kChartCos;
  s.wide.clear();
  s.caps.clear();
  if (s.stamp.size() < count) s.stamp.resize(count, 0);
  if (s.normal_stamp.size() < count) s.normal_stamp.resize(count, 0);
  if (s.normal_mark == std::numeric_limits<uint32_t>::max()) {
    std::fill(s.normal_stamp.begin(), s.normal_stamp.end(), 0);
    s.normal_mark = 0;
  }
  ++s.normal_mark;
  s.light_normals.clear();
  for (size_t k = 0; k < light.size(); ++k) {
    const V3& c = light[k];
    const V3& d = light[k + 1 == light.size() ? 0 : k + 1];
    s.light_normals.push_back({c.cross(d), c.cwiseAbs().sum() * d.cwiseAbs().sum()});
  }
  double scale = 1;  // the chart's: 1 + the largest |coordinate| of the light's points
  if (charted) {
    chart.c = light_cap.c;
    chart.e1 = chart.c.unitOrthogonal();
    chart.e2 = chart.c.cross(chart.e1);
    for (int a = 0; a < 2; ++a) chart.lo[a] = kInf, chart.hi[a] = -kInf;
    for (const V3& v : light) {
      double g[2];
      chart.at(v, g);
      for (int a = 0; a < 2; ++a) {
        chart.lo[a] = std::min(chart.lo[a], g[a]);
        chart.hi[a] = std::max(chart.hi[a], g[a]);
        scale = std::max(scale, 1 + std::abs(g[a]));
      }
    }
    chart.margin = kChartMargin * scale;
    for (int a = 0; a < 2; ++a) chart.lo[a] -= 2 * chart.margin, chart.hi[a] += 2 * chart.margin;
    // Occluder boxes; an occluder reaching out of c's front hemisphere is `wide` (always tested)
    // unless its cap misses the light's.
    s.boxes.resize(count);
    s.points.clear();
    s.normals.clear();
    size_t in_chart = 0;
    for (size_t j = 1; j < count; ++j) {
      const Polygon poly = polygons[j];
      Box& box = s.boxes[j];
      box.in = false;
      if (poly.empty()) continue;
      // Points and normals share the index base: one slot per vertex (points only for charted;
      // normals filled by normals_of when first needed).
      box.first = uint32_t(s.normals.size());
      s.normals.resize(s.normals.size() + poly.size());
      s.points.resize(s.normals.size());
      bool front = true;
      for (const V3& v : poly) front = front && chart.c.dot(v) > kFrontCos * v.cwiseAbs().sum();  // |v|₁ ≥ |v|
      if (!front) {
        if (!disjoint(cap_of(poly), light_cap)) s.wide.push_back(uint32_t(j));
        continue;
      }
      for (int a = 0; a < 2; ++a) box.lo[a] = kInf, box.hi[a] = -kInf;
      for (size_t k = 0; k < poly.size(); ++k) {
        const V3& v = poly[k];
        auto& g = s.points[box.first + k];
        chart.at(v, g.data());
        for (int a = 0; a < 2; ++a) box.lo[a] = std::min(box.lo[a], g[a]), box.hi[a] = std::max(box.hi[a], g[a]);
      }
      box.in = true;
      for (int a = 0; a < 2; ++a) {
        box.lo[a] -= chart.margin;
        box.hi[a] += chart.margin;
        box.in = box.in && box.hi[a] >= chart.lo[a] && box.lo[a] <= chart.hi[a];
      }
      in_chart += box.in;
    }
    const auto side_cells =
        uint32_t(std::clamp(std::ceil(kGridDensity * std::sqrt(double(in_chart))), 1.0, double(kMaxGrid)));
    for (int a = 0; a < 2; ++a) {
      chart.n[a] = side_cells;
      chart.cell[a] = (chart.hi[a] - chart.lo[a]) / side_cells;
      chart.inverse[a] = 1 / chart.cell[a];
      charted = charted && chart.cell[a] > 0 && std::isfinite(chart.inverse[a]);
    }
  }
  if (charted) {
    // Counting sort of (cell, occluder) pairs, occluders ascending within a cell; an occluder
    // over more than a quarter of the cells is `wide`.
    const size_t cells = size_t(chart.n[0]) * chart.n[1];
    const size_t wide_limit = std::max<size_t>(cells / 4, 4);
    s.cell_start.assign(cells + 1, 0);
    for (size_t j = 1; j < count; ++j) {
      Box& box = s.boxes[j];
      if (!box.in) continue;
      uint32_t* c = box.cells;
      chart.cells(0, box.lo[0], box.hi[0], c[0], c[1]);
      chart.cells(1, box.lo[1], box.hi[1], c[2], c[3]);
      if (size_t(c[1] - c[0] + 1) * (c[3] - c[2] + 1) > wide_limit) {
        s.wide.push_back(uint32_t(j));
        c[0] = c[2] = 1, c[1] = c[3] = 0;  // no cells
      }
    }
    for (int pass = 0; pass < 2; ++pass) {
      for (size_t j = 1; j < count; ++j) {
        const Box& box = s.boxes[j];
        if (!box.in) continue;
        const uint32_t x0 = box.cells[0], x1 = box.cells[1], y0 = box.cells[2], y1 = box.cells[3];
        for (uint32_t y = y0; y <= y1; ++y)
          for (uint32_t x = x0; x <= x1; ++x) {
            const size_t cell = size_t(y) * chart.n[0] + x;
            if (pass == 0) {
              ++s.cell_start[cell + 1];
            } else {
              s.cell_items[s.cell_fill[cell]++] = uint32_t(j);
            }
          }
      }
      if (pass == 0) {
        for (size_t c = 0; c < cells; ++c) s.cell_start[c + 1] += s.cell_start[c];
        s.cell_items.resize(s.cell_start[cells]);
        s.cell_fill.assign(s.cell_start.begin(), s.cell_start.end() - 1);
      }
    }
    std::sort(s.wide.begin(), s.wide.end());
  } else {
    s.caps.clear();
    for (const Polygon poly : polygons) s.caps.push_back(poly.empty() ? Cap{} : cap_of(poly));
  }
  scratch.charted = charted;

  // Polygon j's edge normals (charted polygons, and the light as j = 0), computed once per call.
  auto normals_of = [&](size_t j) -> const EdgeNormal* {
    if (j == 0) return s.light_normals.data();
    EdgeNormal* normals = s.normals.data() + s.boxes[j].first;
    if (s.normal_stamp[j] != s.normal_mark) {
      s.normal_stamp[j] = s.normal_mark;
      const Polygon poly = polygons[j];
      for (size_t k = 0; k < poly.size(); ++k) {
        const V3& c = poly[k];
        const V3& d = poly[k + 1 == poly.size() ? 0 : k + 1];
        normals[k] = {c.cross(d), c.cwiseAbs().sum() * d.cwiseAbs().sum()};
      }
    }
    return normals;
  };

  // s.near = the occluders that may meet the arc from x to y (both in the light, so c·ω > 0):
  // those in the cells the chord of their chart points passes (row by row, with margins) and
  // the wide ones, in that order; near_keep(i, j) then filters each (below), only while e is
  // not yet covered.
  auto near = [&](const V3& a, const V3& b, const V3& x, const V3& y) {
    s.near.clear();
    if (s.mark == std::numeric_limits<uint32_t>::max()) {
      std::fill(s.stamp.begin(), s.stamp.end(), 0);
      s.mark = 0;
    }
    const uint32_t mark = ++s.mark;
    double gx[2], gy[2];
    chart.at(x, gx);
    chart.at(y, gy);
    const double m = chart.margin, dy = gy[1] - gx[1];
    uint32_t r0 = 0, r1 = 0;
    if (chart.cells(1, std::min(gx[1], gy[1]) - m, std::max(gx[1], gy[1]) + m, r0, r1)) {
      for (uint32_t r = r0; r <= r1; ++r) {
        // The chord's part with its y in this row (± margin; the outer rows unbounded outwards).
        const double ylo = r == 0 ? -kInf : chart.lo[1] + r * chart.cell[1] - m;
        const double yhi = r + 1 == chart.n[1] ? kInf : chart.lo[1] + (r + 1) * chart.cell[1] + m;
        double t0 = 0, t1 = 1;
        if (dy != 0) {
          double ta = (ylo - gx[1]) / dy, tb = (yhi - gx[1]) / dy;
          if (ta > tb) std::swap(ta, tb);
          t0 = std::max(0.0, ta);
          t1 = std::min(1.0, tb);
          if (t0 > t1) continue;
        } else if (gx[1] < ylo || gx[1] > yhi) {
          continue;
        }
        const double xa = gx[0] + t0 * (gy[0] - gx[0]), xb = gx[0] + t1 * (gy[0] - gx[0]);
        uint32_t c0 = 0, c1 = 0;
        if (!chart.cells(0, std::min(xa, xb) - m, std::max(xa, xb) + m, c0, c1)) continue;
        const size_t row = size_t(r) * chart.n[0];
        for (size_t cell = row + c0; cell <= row + c1; ++cell)
          for (uint32_t at = s.cell_start[cell]; at < s.cell_start[cell + 1]; ++at) {
            const uint32_t j = s.cell_items[at];
            if (s.stamp[j] != mark) s.stamp[j] = mark, s.near.push_back(j);
          }
      }
    }
    for (uint32_t j : s.wide)
      if (s.stamp[j] != mark) s.stamp[j] = mark, s.near.push_back(j);
    // Keep those whose box meets the chord's box along both axes and whose vertices' chart
    // points may lie on the side of e's great circle that matters (the light's left, an
    // occluder edge's right) and on or across it; or, for an earlier occluder, two of them on
    // it (a shared arc). The circle m·ω = 0 (m = a × b) is the chart line f(g) = 0 with
    // f(g) = m·(g₀e1 + g₁e2 + c) = m·ω/(c·ω): f > 0 is det(a, b, ω) > 0, left of e. A point
    // within the slack (the chart points' margin and the rounding of m, both far above their
    // errors) may be on either side or on it.
    s.box_lo[0] = std::min(gx[0], gy[0]) - m, s.box_lo[1] = std::min(gx[1], gy[1]) - m;
    s.box_hi[0] = std::max(gx[0], gy[0]) + m, s.box_hi[1] = std::max(gx[1], gy[1]) + m;
    const V3 normal = a.cross(b);
    s.nx = normal.dot(chart.e1), s.ny = normal.dot(chart.e2), s.nz = normal.dot(chart.c);
    s.slack = 4 * m * normal.cwiseAbs().sum() + 1e-13 * a.cwiseAbs().sum() * b.cwiseAbs().sum() * scale;
  };
  auto near_keep = [&](size_t i, uint32_t j) {
    if (j == i) return false;
    const Box& box = s.boxes[j];
    if (!box.in) return true;
    if (!(box.lo[0] <= s.box_hi[0] && box.hi[0] >= s.box_lo[0] && box.lo[1] <= s.box_hi[1] && box.hi[1] >= s.box_lo[1]))
      return false;
    int left = 0, right = 0, unsure = 0;
    for (size_t k = 0; k < polygons[j].size(); ++k) {
      const auto& g = s.points[box.first + k];
      const double f = s.nx * g[0] + s.ny * g[1] + s.nz;
      left += f > s.slack;
      right += f < -s.slack;
      unsure += !(f > s.slack) && !(f < -s.slack);
    }
    // (an occluder's right side: a point right and one left or on; the light's left likewise)
    return i == 0 ? left + unsure > 0 && right + unsure > 0
                  : (right + unsure > 0 && left + unsure > 0) || (j < i && unsure >= 2);
  };

  auto run = [&](size_t i, const V3& a, const V3& b, const Interval* in_light) {
    // The chord of e's part in the light, from its parameters (the point at t is
    // (1 − t)·a + t·b, as inside_intervals orders cuts): the cut points' own x may lie on the
    // other edge when that one is near-degenerate (e.g. a horizon-clipped light vertex pair).
    V3 x = a, y = b;
    if (in_light) {
      x = (1 - in_light->lo.t) * a + in_light->lo.t * b;
      y = (1 - in_light->hi.t) * a + in_light->hi.t * b;
    }
    const bool chord_in_chart = charted && chart.c.dot(x) > kFrontCos * x.cwiseAbs().sum() &&
                                chart.c.dot(y) > kFrontCos * y.cwiseAbs().sum();
    if (chord_in_chart) {
      near(a, b, x, y);
      edge_pieces(polygons, i, a, b, in_light, [&](auto&& f) {
        for (uint32_t j : s.near)
          if (near_keep(i, j) && !f(j)) return;
      }, normals_of, s.edge, out);
      return;
    }
    // Not charted (or this chord leaves the chart's hemisphere): caps only.
    if (charted && s.caps.size() != count) {
      s.caps.clear();
      for (const Polygon poly : polygons) s.caps.push_back(poly.empty() ? Cap{} : cap_of(poly));
    }
    const V3 ends[2] = {a, b};
    const Cap edge_cap = cap_of(ends);
    edge_pieces(polygons, i, a, b, in_light, [&](auto&& f) {
      for (size_t j = 1; j < count; ++j)
        if (j != i && !polygons[j].empty() && !disjoint(edge_cap, s.caps[j]) && !f(j)) return;
    }, [](size_t) { return static_cast<const EdgeNormal*>(nullptr); }, s.edge, out);
  };
  for (size_t k = 0; k < light.size(); ++k) {
    const V3& a = light[k];
    const V3& b = light[k + 1 == light.size() ? 0 : k + 1];
    if (a != b) run(0, a, b, nullptr);
  }
  for (size_t i = 1; i < count; ++i) {
    const Polygon poly = polygons[i];
    const unsigned mask = boundary[i - 1];
    for (size_t k = 0; k < poly.size(); ++k) {
      if (k < 8 && !(mask & (1u << k))) continue;
      const V3& a = poly[k];
      const V3& b = poly[k + 1 == poly.size() ? 0 : k + 1];
      if (a == b) continue;
      // Both ends strictly right of one light edge (the float filter of side_filtered, deciding
      // only beyond its bound): inside_intervals would find e outside the light.
      bool outside = false;
      const double la = 1e-14 * a.cwiseAbs().sum(), lb = 1e-14 * b.cwiseAbs().sum();
      for (const EdgeNormal& edge : s.light_normals) {
        if (edge.m.dot(a) < -la * edge.cd && edge.m.dot(b) < -lb * edge.cd) {
          outside = true;
          break;
        }
      }
      if (outside) continue;
      const V3 ends[2] = {a, b};
      if (disjoint(cap_of(ends), light_cap)) continue;
      Interval in[2];
      inside_intervals(a, b, light, false, in, nullptr, s.light_normals.data());
      if (in[1].empty) continue;
      ++scratch.boundary_edges;
      run(i, a, b, &in[1]);
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
