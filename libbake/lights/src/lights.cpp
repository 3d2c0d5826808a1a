// lights.cpp — area-light shapes and their validity (bake/lights/lights.h).
#include <bake/core/error.h>
#include <bake/lights/lights.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <sstream>
#include <utility>

namespace prt::bake {

const char* light_shape_name(LightShape s) {
  switch (s) {
  case LightShape::Polygon: return "polygon";
  case LightShape::Quad: return "quad";
  case LightShape::Disc: return "disc";
  case LightShape::Box: return "box";
  case LightShape::Cylinder: return "cylinder";
  case LightShape::Sphere: return "sphere";
  }
  return "?";
}

Eigen::Vector3d AreaLight::face_normal(size_t face) const {
  // Newell's method: twice the vector area, exact in direction for a planar polygon and the
  // least-squares plane's normal for a nearly planar one.
  const std::vector<uint32_t>& f = faces[face];
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < f.size(); ++i) n += vertices[f[i]].cross(vertices[f[(i + 1) % f.size()]]);
  const double len = n.norm();
  return len > 0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d::Zero();
}

double AreaLight::area() const {
  double a = 0;
  for (const std::vector<uint32_t>& f : faces) {
    Eigen::Vector3d n = Eigen::Vector3d::Zero();
    for (size_t i = 1; i + 1 < f.size(); ++i)
      n += (vertices[f[i]] - vertices[f[0]]).cross(vertices[f[i + 1]] - vertices[f[0]]);
    a += 0.5 * n.norm();
  }
  return a;
}

namespace {

std::vector<uint32_t> ring(uint32_t first, uint32_t count) {
  std::vector<uint32_t> r(count);
  for (uint32_t i = 0; i < count; ++i) r[i] = first + i;
  return r;
}

// A unit vector perpendicular to n (|n| = 1), from the axis n is least aligned with.
Eigen::Vector3d perpendicular(const Eigen::Vector3d& n) {
  const Eigen::Vector3d a = std::abs(n.x()) <= std::abs(n.y()) && std::abs(n.x()) <= std::abs(n.z()) ? Eigen::Vector3d::UnitX()
                            : std::abs(n.y()) <= std::abs(n.z())                                     ? Eigen::Vector3d::UnitY()
                                                                                                     : Eigen::Vector3d::UnitZ();
  return n.cross(a).normalized();
}

} // namespace

AreaLight make_polygon_light(std::vector<Eigen::Vector3d> corners) {
  AreaLight l;
  l.shape = LightShape::Polygon;
  l.faces.push_back(ring(0, uint32_t(corners.size())));
  l.vertices = std::move(corners);
  return l;
}

AreaLight make_quad_light(const Eigen::Vector3d& c, const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
  // Counter-clockwise about u × v: (−,−), (+,−), (+,+), (−,+) in (u, v).
  AreaLight l = make_polygon_light({c - 0.5 * u - 0.5 * v, c + 0.5 * u - 0.5 * v, c + 0.5 * u + 0.5 * v, c - 0.5 * u + 0.5 * v});
  l.shape = LightShape::Quad;
  return l;
}

AreaLight make_disc_light(const Eigen::Vector3d& centre, const Eigen::Vector3d& normal, double radius, int segments) {
  PRT_CHECK(segments >= kMinSegments && segments <= kMaxSegments);
  const Eigen::Vector3d n = normal.normalized(), t = perpendicular(n), b = n.cross(t);  // t × b = n
  std::vector<Eigen::Vector3d> corners;
  for (int k = 0; k < segments; ++k) {
    const double phi = 2 * std::numbers::pi * k / segments;
    corners.push_back(centre + radius * (std::cos(phi) * t + std::sin(phi) * b));
  }
  AreaLight l = make_polygon_light(std::move(corners));
  l.shape = LightShape::Disc;
  return l;
}

AreaLight make_box_light(const Eigen::Vector3d& centre, const Eigen::Vector3d& size, const Eigen::Matrix3d& rotation) {
  AreaLight l;
  l.shape = LightShape::Box;
  // Corner i has the shape's own coordinates ±size/2 by the bits of i (x: bit 0, y: 1, z: 2).
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d s((i & 1) ? 0.5 : -0.5, (i & 2) ? 0.5 : -0.5, (i & 4) ? 0.5 : -0.5);
    l.vertices.push_back(centre + rotation * s.cwiseProduct(size));
  }
  // Outward, counter-clockwise seen from outside: −x, +x, −y, +y, −z, +z.
  l.faces = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  return l;
}

AreaLight make_cylinder_light(const Eigen::Vector3d& centre, double radius, double height, int segments,
                              const Eigen::Matrix3d& rotation) {
  PRT_CHECK(segments >= kMinSegments && segments <= kMaxSegments);
  AreaLight l;
  l.shape = LightShape::Cylinder;
  const uint32_t N = uint32_t(segments);
  // Ring vertex k at angle φ_k in the (z, x) plane, counter-clockwise about the own +y (z × x = y):
  // the bottom ring first (0..N−1), then the top one (N..2N−1).
  for (double y : {-0.5 * height, 0.5 * height})
    for (uint32_t k = 0; k < N; ++k) {
      const double phi = 2 * std::numbers::pi * k / N;
      l.vertices.push_back(centre + rotation * Eigen::Vector3d(radius * std::sin(phi), y, radius * std::cos(phi)));
    }
  std::vector<uint32_t> bottom = ring(0, N);
  std::reverse(bottom.begin(), bottom.end());  // seen from −y
  l.faces.push_back(std::move(bottom));
  l.faces.push_back(ring(N, N));
  for (uint32_t k = 0; k < N; ++k) l.faces.push_back({k, (k + 1) % N, N + (k + 1) % N, N + k});
  return l;
}

AreaLight make_sphere_light(const Eigen::Vector3d& centre, double radius, int subdivisions) {
  PRT_CHECK(subdivisions >= 0 && subdivisions <= kMaxSphereSubdivisions);
  // The icosahedron: the 12 cyclic permutations of (0, ±1, ±φ) on the unit sphere; its faces are
  // the triples of mutually nearest vertices (edge 2 before normalising), turned outward.
  const double g = (1 + std::sqrt(5.0)) / 2;
  std::vector<Eigen::Vector3d> v;
  for (double a : {-1.0, 1.0})
    for (double b : {-g, g}) {
      v.emplace_back(0, a, b);
      v.emplace_back(a, b, 0);
      v.emplace_back(b, 0, a);
    }
  std::vector<std::array<uint32_t, 3>> tri;
  auto adjacent = [&](uint32_t i, uint32_t j) { return std::abs((v[i] - v[j]).squaredNorm() - 4) < 1e-9; };
  for (uint32_t i = 0; i < 12; ++i)
    for (uint32_t j = i + 1; j < 12; ++j)
      for (uint32_t k = j + 1; k < 12; ++k)
        if (adjacent(i, j) && adjacent(j, k) && adjacent(i, k)) {
          const bool outward = (v[j] - v[i]).cross(v[k] - v[i]).dot(v[i] + v[j] + v[k]) > 0;
          tri.push_back(outward ? std::array{i, j, k} : std::array{i, k, j});
        }
  PRT_CHECK(tri.size() == 20);
  for (Eigen::Vector3d& p : v) p.normalize();
  // Loop's 1-to-4 split, each new vertex the normalised midpoint of its edge (shared by both faces).
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
    auto midpoint = [&](uint32_t a, uint32_t b) {
      const auto key = std::minmax(a, b);
      const auto [it, fresh] = mid.emplace(key, uint32_t(v.size()));
      if (fresh) v.push_back((v[a] + v[b]).normalized());
      return it->second;
    };
    std::vector<std::array<uint32_t, 3>> next;
    for (const auto& [a, b, c] : tri) {
      const uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      next.insert(next.end(), {{a, ab, ca}, {ab, b, bc}, {ca, bc, c}, {ab, bc, ca}});
    }
    tri = std::move(next);
  }
  AreaLight l;
  l.shape = LightShape::Sphere;
  for (const Eigen::Vector3d& p : v) l.vertices.push_back(centre + radius * p);
  for (const auto& [a, b, c] : tri) l.faces.push_back({a, b, c});
  return l;
}

void validate_light(const AreaLight& l, const std::string& file, const std::string& what) {
  auto fail = [&](const std::string& defect) { throw InputError(file, what + ": " + defect); };
  auto number = [](double x) {
    std::ostringstream os;
    os.precision(3);
    os << x;
    return os.str();
  };
  for (double c : l.radiance)
    if (!(std::isfinite(c) && c >= 0)) fail("radiance must be finite and >= 0, got " + number(c));
  if (l.vertices.size() < 3 || l.faces.empty()) fail("a light needs at least one face of 3 vertices");
  if (l.two_sided && l.solid()) fail("a solid light emits outwards; two_sided is for planar lights");
  if (l.solid() != (l.faces.size() > 1)) fail(l.solid() ? "a solid light has several faces" : "a planar light has one face");
  Eigen::Vector3d lo = l.vertices[0], hi = lo;
  for (const Eigen::Vector3d& p : l.vertices) {
    if (!p.allFinite()) fail("a vertex is not finite");
    lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  }
  // The tolerance also covers float rounding where the light is far from the origin: a float
  // coordinate x is off by up to |x|·2^-24, which moves a vertex off its plane by up to √3 of that
  // and the centroid's plane by as much again (2^-22 > 2√3·2^-24).
  const double diameter = (hi - lo).norm(), reach = std::max(lo.cwiseAbs().maxCoeff(), hi.cwiseAbs().maxCoeff());
  const double tol = kLightShapeTolerance * diameter + std::ldexp(reach, -22);
  if (!(diameter > 0) || !std::isfinite(diameter)) fail("the light has no extent");
  for (size_t fi = 0; fi < l.faces.size(); ++fi) {
    const std::vector<uint32_t>& f = l.faces[fi];
    const std::string face = l.faces.size() > 1 ? "face " + std::to_string(fi) + ": " : "";
    if (f.size() < 3) fail(face + "fewer than 3 vertices");
    for (uint32_t i : f)
      if (i >= l.vertices.size()) fail(face + "vertex index out of range");
    const Eigen::Vector3d n = l.face_normal(fi);
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (uint32_t i : f) centroid += l.vertices[i];
    centroid /= double(f.size());
    if (n.isZero()) fail(face + "degenerate (no area)");
    for (uint32_t i : f)
      if (std::abs(n.dot(l.vertices[i] - centroid)) > tol)
        fail(face + "not planar: a vertex lies " + number(std::abs(n.dot(l.vertices[i] - centroid))) +
             " from its plane (tolerance " + number(tol) + ": 1e-6 of the light's size, plus float rounding)");
    // Convex and counter-clockwise about n: every vertex on the left of every edge (a star polygon,
    // which turns left at every corner, fails this too).
    for (size_t e = 0; e < f.size(); ++e) {
      const Eigen::Vector3d& a = l.vertices[f[e]];
      const Eigen::Vector3d edge = l.vertices[f[(e + 1) % f.size()]] - a;
      const double len = edge.norm();
      if (!(len > tol)) fail(face + "an edge shorter than the tolerance (a repeated vertex)");
      const Eigen::Vector3d inward = n.cross(edge / len);
      for (uint32_t i : f)
        if (inward.dot(l.vertices[i] - a) < -tol)
          fail(face + "not convex (or not counter-clockwise seen from the side it emits to)");
    }
    if (l.solid())
      for (size_t i = 0; i < l.vertices.size(); ++i)
        if (n.dot(l.vertices[i] - centroid) > tol)
          fail(face + "vertex " + std::to_string(i) + " lies in front of it: the solid is not convex, or its faces are not outward");
  }
  if (l.solid()) {
    // Closed: every directed edge once, and its reverse once.
    std::map<std::pair<uint32_t, uint32_t>, int> edges;
    for (const std::vector<uint32_t>& f : l.faces)
      for (size_t e = 0; e < f.size(); ++e) ++edges[{f[e], f[(e + 1) % f.size()]}];
    for (const auto& [e, count] : edges) {
      const auto back = edges.find({e.second, e.first});
      if (count != 1 || back == edges.end() || back->second != 1)
        fail("not closed: edge " + std::to_string(e.first) + "-" + std::to_string(e.second) +
             " is not shared by exactly two faces in opposite directions");
    }
  }
}

} // namespace prt::bake
