// spherical_polygon.cpp — closed-form integrals over spherical polygons and horizon clipping
// (bake/sphere/spherical_polygon.h has the conventions, the formulas and their numerics).
#include "spherical_polygon_detail.h"

#include <bake/core/error.h>

#include <cmath>

namespace prt::bake {

namespace {

// θ/sin θ − 1 for an edge with s = |a×b| = sin θ and c = a·b (unit a, b), 0 for a null edge.
// atan2(s, c)/s carries no cancellation for small s (it is 1 + s²/6 + …, with relative error ~u),
// so its excess over 1 is accurate to ~u absolutely, which is all the O(θ³) term needs.
double arc_excess(double s, double c) {
  if (s == 0) return 0;  // a = b (antipodal ends are excluded by the preconditions)
  return std::atan2(s, c) / s - 1.0;
}

// Error-free product x·y = h + l (FMA; exact unless the product underflows).
inline void two_product(double x, double y, double& h, double& l) {
  h = x * y;
  l = std::fma(x, y, -h);
}

// Error-free sum a + b = s + e (Knuth's TwoSum).
inline void two_sum(double a, double b, double& s, double& e) {
  s = a + b;
  const double bv = s - a, av = s - bv;
  e = (a - av) + (b - bv);
}

}  // namespace

namespace detail {

UnitPolygon::UnitPolygon(std::span<const Eigen::Vector3d> vertices) : n_(vertices.size()) {
  if (n_ > kInline) heap_.resize(n_);
  Eigen::Vector3d* v = data();
  for (size_t i = 0; i < n_; ++i) {
    const double len = vertices[i].norm();
    PRT_CHECK(std::isfinite(len) && len > 0);
    v[i] = vertices[i] / len;
  }
}

Eigen::Vector3d twice_vector_irradiance(std::span<const Eigen::Vector3d> unit) {
  const size_t n = unit.size();
  if (n < 3) return Eigen::Vector3d::Zero();
  const Eigen::Vector3d& o = unit[0];
  Eigen::Vector3d area = Eigen::Vector3d::Zero(), bend = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& a = unit[i];
    const Eigen::Vector3d& b = unit[i + 1 == n ? 0 : i + 1];
    const Eigen::Vector3d ab = a.cross(b);
    bend += arc_excess(ab.norm(), a.dot(b)) * ab;
    if (i != 0 && i + 1 != n) area += (a - o).cross(b - o);
  }
  return area + bend;
}

}  // namespace detail

Eigen::Vector3d vector_irradiance(std::span<const Eigen::Vector3d> vertices) {
  const detail::UnitPolygon unit(vertices);
  return 0.5 * detail::twice_vector_irradiance(unit.span());
}

double cosine_integral(std::span<const Eigen::Vector3d> vertices, const Eigen::Vector3d& n) {
  return n.dot(vector_irradiance(vertices));
}

double solid_angle(std::span<const Eigen::Vector3d> vertices) {
  const detail::UnitPolygon unit(vertices);
  return detail::solid_angle_unit(unit.span());
}

double detail::solid_angle_unit(std::span<const Eigen::Vector3d> unit) {
  const size_t n = unit.size();
  return fan_solid_angle(twice_vector_irradiance(unit), n, [&](size_t i) {
    return std::pair<const Eigen::Vector3d&, const Eigen::Vector3d&>(unit[i], unit[i + 1 == n ? 0 : i + 1]);
  });
}

Eigen::Vector3d detail::arc_moment(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = a.cross(b);
  return (1.0 + arc_excess(ab.norm(), a.dot(b))) * ab;
}

namespace {

// Unit copies of boundary arcs (heap only: a region's boundary is built on the heap anyway).
std::vector<Arc> unit_arcs(std::span<const Arc> boundary) {
  std::vector<Arc> out;
  out.reserve(boundary.size());
  for (const Arc& arc : boundary) {
    const double la = arc.a.norm(), lb = arc.b.norm();
    PRT_CHECK(std::isfinite(la) && la > 0 && std::isfinite(lb) && lb > 0);
    out.push_back({arc.a / la, arc.b / lb});
  }
  return out;
}

// The closed-polygon form of 2Φ on arcs: Σ (a − o)×(b − o) + Σ (θ/sin θ − 1)(a × b), equal to
// Σ θ u when the arcs close (every endpoint is as often a start as an end), o = the first start.
Eigen::Vector3d twice_vector_irradiance_arcs(std::span<const Arc> unit) {
  if (unit.empty()) return Eigen::Vector3d::Zero();
  const Eigen::Vector3d o = unit[0].a;
  Eigen::Vector3d area = Eigen::Vector3d::Zero(), bend = Eigen::Vector3d::Zero();
  for (const Arc& arc : unit) {
    const Eigen::Vector3d ab = arc.a.cross(arc.b);
    bend += arc_excess(ab.norm(), arc.a.dot(arc.b)) * ab;
    area += (arc.a - o).cross(arc.b - o);
  }
  return area + bend;
}

}  // namespace

Eigen::Vector3d vector_irradiance(std::span<const Arc> boundary) {
  return 0.5 * twice_vector_irradiance_arcs(unit_arcs(boundary));
}

double solid_angle(std::span<const Arc> boundary) {
  const std::vector<Arc> unit = unit_arcs(boundary);
  return detail::fan_solid_angle(twice_vector_irradiance_arcs(unit), unit.size(), [&](size_t i) {
    return std::pair<const Eigen::Vector3d&, const Eigen::Vector3d&>(unit[i].a, unit[i].b);
  });
}

int horizon_side(const Eigen::Vector3d& n, const Eigen::Vector3d& v) {
  // Filter: |fl(n·v) − n·v| ≤ γ_3 Σ|n_k v_k| (Higham, "Accuracy and Stability", eq. 3.5), with
  // γ_3 = 3u/(1 − 3u) < 4u.
  const double p0 = n.x() * v.x(), p1 = n.y() * v.y(), p2 = n.z() * v.z();
  const double s = p0 + p1 + p2;
  const double bound = 0x1.0p-51 * (std::abs(p0) + std::abs(p1) + std::abs(p2));
  if (s > bound) return 1;
  if (s < -bound) return -1;
  // Exact: the six parts of the three products, summed into a non-overlapping expansion
  // (Shewchuk 1997, Grow-Expansion); its largest non-zero component has the sign of the sum.
  double terms[6];
  for (int k = 0; k < 3; ++k) two_product(n[k], v[k], terms[2 * k], terms[2 * k + 1]);
  double e[6];
  int m = 0;
  for (double q : terms) {
    for (int i = 0; i < m; ++i) two_sum(q, e[i], q, e[i]);
    e[m++] = q;
  }
  for (int i = m - 1; i >= 0; --i)
    if (e[i] != 0) return e[i] > 0 ? 1 : -1;
  return 0;
}

void clip_to_horizon(std::span<const Eigen::Vector3d> vertices, const Eigen::Vector3d& n,
                     std::vector<Eigen::Vector3d>& out) {
  out.clear();
  const size_t count = vertices.size();
  if (count == 0) return;
  int side_a = horizon_side(n, vertices[count - 1]);
  bool any_above = false;
  for (size_t i = 0; i < count; ++i) {
    const Eigen::Vector3d& a = vertices[i == 0 ? count - 1 : i - 1];
    const Eigen::Vector3d& b = vertices[i];
    const int side_b = horizon_side(n, b);
    if (side_a * side_b < 0) {  // strictly opposite sides: the edge crosses the horizon
      const double da = std::abs(n.dot(a)) / a.norm(), db = std::abs(n.dot(b)) / b.norm();
      out.push_back(db * a.normalized() + da * b.normalized());
    }
    if (side_b >= 0) out.push_back(b);
    any_above |= side_b > 0;
    side_a = side_b;
  }
  if (!any_above) out.clear();  // at most a stretch of the horizon: no area above it
}

double clipped_irradiance(std::span<const Eigen::Vector3d> vertices, const Eigen::Vector3d& n) {
  std::vector<Eigen::Vector3d> clipped;
  clip_to_horizon(vertices, n, clipped);
  return cosine_integral(clipped, n);
}

} // namespace prt::bake
