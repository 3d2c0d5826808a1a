// texels.cpp — a lightmap atlas's covered texels and their shade points (bake/mesh/texels.h).
#include <bake/mesh/texels.h>
#include <bake/core/error.h>
#include <bake/mesh/predicates.h>
#include <bake/mesh/receivers.h>

#include "error_free.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <span>
#include <utility>
#include <vector>

namespace prt::bake {
namespace {

constexpr uint32_t kMaxSide = 8192;  // texels per side: the per-texel choice below keeps 8 bytes per texel
constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();

using V2 = Eigen::Vector2d;

double cross(const V2& a, const V2& b) { return a.x() * b.y() - a.y() * b.x(); }

// Whether triangle (a, b, c) meets the closed square [x0, x0 + 1] × [y0, y0 + 1]: separating axes
// (the square's two are the caller's bounding-box test; here the triangle's three edge normals).
bool meets_square(const V2 (&t)[3], double x0, double y0) {
  const V2 corners[4] = {{x0, y0}, {x0 + 1, y0}, {x0, y0 + 1}, {x0 + 1, y0 + 1}};
  for (int e = 0; e < 3; ++e) {
    const V2 d = t[(e + 1) % 3] - t[e];
    const V2 normal(-d.y(), d.x());
    // The triangle projects onto [min(edge, third vertex), max(...)] along the edge's normal.
    const double edge = normal.dot(t[e]), third = normal.dot(t[(e + 2) % 3]);
    const double tlo = std::min(edge, third), thi = std::max(edge, third);
    double slo = std::numeric_limits<double>::infinity(), shi = -slo;
    for (const V2& q : corners) {
      const double s = normal.dot(q);
      slo = std::min(slo, s);
      shi = std::max(shi, s);
    }
    if (shi < tlo || slo > thi) return false;
  }
  return true;
}

// The point of segment [p, q] nearest to c, as the parameter s in [0, 1] of p + s (q − p).
double nearest_on_segment(const V2& p, const V2& q, const V2& c) {
  const V2 d = q - p;
  const double len2 = d.squaredNorm();
  if (len2 == 0) return 0;
  return std::clamp((c - p).dot(d) / len2, 0.0, 1.0);
}

// x + y and x · y in double, true when exact (their rounding errors, error_free.h, are 0).
bool exact_sum(double x, double y, double& out) {
  double err;
  error_free::two_sum(x, y, out, err);
  return err == 0.0;
}
bool exact_product(double x, double y, double& out) {
  double err;
  error_free::two_product(x, y, out, err);
  return err == 0.0;
}

// The point o + Σ_k w_k (q_k − o) of a triangle's plane (or an edge's line: one q), computed so that
// every operation is exact in double: then it lies EXACTLY in the plane of o and the q_k (on the line
// through o and q), as a mesh vertex lies in its triangles' planes, and the exact predicates treat it
// as on its own surface (bake/visibility: a point a rounding below its own triangle would see that
// triangle from behind, as a roof over half its hemisphere). The weights are rounded to dyadic
// fractions of 2^-bits, from 30 bits down until every operation is exact (the float corners'
// differences are exact in double for corners within 2^29 of each other's scale; the products and
// sums need the weights' bits to fit beside them). false when none down to 2 bits is.
bool exact_point_on(const Eigen::Vector3d& o, std::span<const Eigen::Vector3d> q, std::span<double> w,
                    Eigen::Vector3d& out) {
  for (int bits = 30; bits >= 2; --bits) {
    const double scale = std::ldexp(1.0, bits);
    bool exact = true;
    std::array<double, 2> wr{};
    // (The weights, all but the largest corner's, sum to at most 2/3: rounded, never past 1.)
    for (size_t k = 0; k < q.size(); ++k) wr[k] = std::round(w[k] * scale) / scale;
    for (int i = 0; i < 3 && exact; ++i) {
      double acc = o[i];
      for (size_t k = 0; k < q.size() && exact; ++k) {
        double d, term;
        exact = exact_sum(q[k][i], -o[i], d) && exact_product(wr[k], d, term) && exact_sum(acc, term, acc);
      }
      out[i] = acc;
    }
    if (exact) {
      for (size_t k = 0; k < q.size(); ++k) w[k] = wr[k];
      return true;
    }
  }
  return false;
}

// A sample that cannot lie exactly on its triangles (exact_point_on failed) is put strictly in
// front of each of them instead: of the doubles within `r` = 1, 2, 3, 4 steps (nextafter) of `p`
// in each coordinate, the nearest to p (ties: the first in x, y, z order) that every triangle of
// `on` sees on the side the normal n points to (orient3d_exact, so the decision is exact; a
// triangle whose winding normal is perpendicular to n asks nothing). The point is then a free
// point a few roundings above its surface: no triangle it was meant to lie on is seen from
// behind, and those of a crease through it are decided exactly as seen from there. False (p
// unchanged) when no such double is that near: a sliver of a crease thinner than the steps.
bool lift_in_front(const Mesh& mesh, std::span<const uint32_t> on, const Eigen::Vector3d& n, Eigen::Vector3d& p) {
  std::vector<std::pair<std::array<Eigen::Vector3d, 3>, int>> want;  // corners, orient3d_exact's sign in front
  for (uint32_t f : on) {
    const auto& tv = mesh.triangles[f];
    const std::array<Eigen::Vector3d, 3> c = {mesh.positions[tv[0]].cast<double>(), mesh.positions[tv[1]].cast<double>(),
                                              mesh.positions[tv[2]].cast<double>()};
    const double facing = (c[1] - c[0]).cross(c[2] - c[0]).dot(n);
    // det(a − p, b − p, c − p) < 0 for p on the side of the winding normal (b − a) × (c − a).
    if (facing != 0 && std::isfinite(facing)) want.push_back({c, facing > 0 ? -1 : 1});
  }
  const auto in_front = [&](const Eigen::Vector3d& q) {
    for (const auto& [c, side] : want)
      if (orient3d_exact(c[0], c[1], c[2], q) != side) return false;
    return true;
  };
  if (in_front(p)) return true;
  const auto step = [](double x, int k) {
    for (; k > 0; --k) x = std::nextafter(x, std::numeric_limits<double>::infinity());
    for (; k < 0; ++k) x = std::nextafter(x, -std::numeric_limits<double>::infinity());
    return x;
  };
  for (int r = 1; r <= 4; ++r) {
    std::optional<Eigen::Vector3d> best;
    double best_d2 = std::numeric_limits<double>::infinity();
    for (int i = -r; i <= r; ++i)
      for (int j = -r; j <= r; ++j)
        for (int k = -r; k <= r; ++k) {
          if (std::max({std::abs(i), std::abs(j), std::abs(k)}) != r) continue;  // the shell of radius r
          const Eigen::Vector3d q(step(p.x(), i), step(p.y(), j), step(p.z(), k));
          const double d2 = (q - p).squaredNorm();
          if (d2 < best_d2 && in_front(q)) best = q, best_d2 = d2;
        }
    if (best) {
      p = *best;
      return true;
    }
  }
  return false;
}

} // namespace

size_t TexelAtlas::texels_off_centre() const {
  return size_t(std::count_if(samples.begin(), samples.end(), [](const TexelSample& s) { return !s.centre; }));
}

// Chart of every triangle (file comment), numbered in order of each chart's first triangle.
std::vector<uint32_t> charts_of(const Mesh& mesh, const Topology& topo, const UvSet& uv) {
  const size_t T = mesh.triangles.size();
  std::vector<uint32_t> parent(T);
  for (size_t t = 0; t < T; ++t) parent[t] = uint32_t(t);
  auto find = [&](uint32_t t) {
    while (parent[t] != t) t = parent[t] = parent[parent[t]];
    return t;
  };
  // The UV of triangle t's corner at welded position w (the first such corner).
  auto uv_at = [&](uint32_t t, uint32_t w) -> const Eigen::Vector2f* {
    for (size_t c = 0; c < 3; ++c)
      if (topo.weld[mesh.triangles[t][c]] == w) return &uv.corners[3 * size_t(t) + c];
    return nullptr;
  };
  for (size_t e = 0; e < topo.edges.size(); ++e) {
    const std::span<const uint32_t> faces = topo.faces_of_edge(uint32_t(e));
    for (size_t i = 1; i < faces.size(); ++i) {
      const uint32_t a = faces[0], b = faces[i];
      bool same = true;
      for (uint32_t w : topo.edges[e]) {
        const Eigen::Vector2f *ua = uv_at(a, w), *ub = uv_at(b, w);
        same = same && ua && ub && (*ua).x() == (*ub).x() && (*ua).y() == (*ub).y();
      }
      if (same) parent[find(a)] = find(b);
    }
  }
  std::vector<uint32_t> chart(T), number(T, kNone);
  uint32_t next = 0;
  for (size_t t = 0; t < T; ++t) {
    uint32_t& n = number[find(uint32_t(t))];
    if (n == kNone) n = next++;
    chart[t] = n;
  }
  return chart;
}

TexelAtlas texel_atlas(const Mesh& mesh, const Topology& topology, const UvSet& uv, uint32_t width, uint32_t height,
                       std::string name) {
  if (width == 0 || height == 0 || width > kMaxSide || height > kMaxSide)
    throw InputError(mesh.source, "a lightmap of " + std::to_string(width) + "x" + std::to_string(height) +
                                      " texels: each side must be 1 to " + std::to_string(kMaxSide));
  if (uv.corners.size() != 3 * mesh.triangles.size())
    throw InputError(mesh.source, "UV set " + uv.name + " has " + std::to_string(uv.corners.size()) + " corners for " +
                                      std::to_string(mesh.triangles.size()) + " triangles (3 each)");
  for (size_t k = 0; k < uv.corners.size(); ++k)
    if (!uv.corners[k].allFinite())
      throw InputError(mesh.source, "UV set " + uv.name + ": corner " + std::to_string(k % 3) + " of triangle " +
                                        std::to_string(k / 3) + " is not finite");
  const size_t texels = size_t(width) * size_t(height);
  // Per texel, the best triangle so far and its squared distance in texel space (−1: the centre
  // lies in it). Triangles come in order and replace only when strictly better: ties keep the first.
  std::vector<uint32_t> best(texels, kNone);
  std::vector<float> best_d2(texels, std::numeric_limits<float>::infinity());
  // The UV set's checks (texels.h): per texel, a chart that touches it and one whose triangle
  // contains its centre; a second chart doing either is counted once per texel.
  const std::vector<uint32_t> chart = charts_of(mesh, topology, uv);
  std::vector<uint32_t> touching(texels, kNone), containing(texels, kNone);
  std::vector<uint8_t> counted(texels, 0);  // bit 0: shared, bit 1: overlapping
  size_t shared = 0, overlapping = 0;
  auto texel_space = [&](size_t t, int c) {
    const Eigen::Vector2f& q = uv.corners[3 * t + size_t(c)];
    return V2(double(q.x()) * width, double(q.y()) * height);
  };
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const V2 tri[3] = {texel_space(t, 0), texel_space(t, 1), texel_space(t, 2)};
    const double area2 = cross(tri[1] - tri[0], tri[2] - tri[0]);
    if (area2 == 0) continue;  // no area in the lightmap: no texel is its
    const double lo_x = std::min({tri[0].x(), tri[1].x(), tri[2].x()}), hi_x = std::max({tri[0].x(), tri[1].x(), tri[2].x()});
    const double lo_y = std::min({tri[0].y(), tri[1].y(), tri[2].y()}), hi_y = std::max({tri[0].y(), tri[1].y(), tri[2].y()});
    // Texels whose closed squares meet the bounding box, clipped to the atlas.
    const double x_first = std::max(std::ceil(lo_x) - 1, 0.0), x_last = std::min(std::floor(hi_x), double(width) - 1);
    const double y_first = std::max(std::ceil(lo_y) - 1, 0.0), y_last = std::min(std::floor(hi_y), double(height) - 1);
    for (double y = y_first; y <= y_last; ++y)
      for (double x = x_first; x <= x_last; ++x) {
        if (!meets_square(tri, x, y)) continue;
        const V2 c(x + 0.5, y + 0.5);
        const double l0 = cross(tri[1] - c, tri[2] - c) / area2, l1 = cross(tri[2] - c, tri[0] - c) / area2;
        const double l2 = 1 - l0 - l1;
        float d2 = -1;
        if (!(l0 >= 0 && l1 >= 0 && l2 >= 0)) {
          double nearest = std::numeric_limits<double>::infinity();
          for (int e = 0; e < 3; ++e) {
            const V2 &p = tri[e], &q = tri[(e + 1) % 3];
            const double s = nearest_on_segment(p, q, c);
            nearest = std::min(nearest, (p + s * (q - p) - c).squaredNorm());
          }
          d2 = float(nearest);
        }
        const size_t k = size_t(y) * width + size_t(x);
        if (d2 < best_d2[k]) best[k] = uint32_t(t), best_d2[k] = d2;
        const uint32_t ct = chart[t];
        if (touching[k] == kNone) touching[k] = ct;
        else if (touching[k] != ct && !(counted[k] & 1)) counted[k] |= 1, ++shared;
        if (d2 < 0) {
          if (containing[k] == kNone) containing[k] = ct;
          else if (containing[k] != ct && !(counted[k] & 2)) counted[k] |= 2, ++overlapping;
        }
      }
  }

  TexelAtlas out;
  out.triangle_chart = chart;
  out.shared_texels = shared;
  out.overlapping_texels = overlapping;
  for (uint32_t c : chart) out.charts = std::max(out.charts, c + 1);
  out.width = width;
  out.height = height;
  out.uv_set = uv.name;
  out.coverage.assign(texels, 0);
  out.receivers.name = std::move(name);
  out.receivers.rows_noun = "texels";
  for (size_t k = 0; k < texels; ++k) {
    if (best[k] == kNone) continue;
    const uint32_t t = best[k];
    const V2 tri[3] = {texel_space(t, 0), texel_space(t, 1), texel_space(t, 2)};
    const double area2 = cross(tri[1] - tri[0], tri[2] - tri[0]);
    const V2 c(double(k % width) + 0.5, double(k / width) + 0.5);
    TexelSample s;
    s.texel = uint32_t(k);
    s.triangle = t;
    s.chart = chart[t];
    s.centre = best_d2[k] < 0;
    if (s.centre) {
      const double l0 = cross(tri[1] - c, tri[2] - c) / area2, l1 = cross(tri[2] - c, tri[0] - c) / area2;
      s.barycentric = {l0, l1, 1 - l0 - l1};
    } else {
      // The nearest point of the triangle's boundary, as barycentric coordinates of its edge.
      double nearest = std::numeric_limits<double>::infinity();
      for (int e = 0; e < 3; ++e) {
        const V2 &p = tri[e], &q = tri[(e + 1) % 3];
        const double sp = nearest_on_segment(p, q, c), d2 = (p + sp * (q - p) - c).squaredNorm();
        if (d2 < nearest) {
          nearest = d2;
          s.barycentric = Eigen::Vector3d::Zero();
          s.barycentric[e] = 1 - sp;
          s.barycentric[(e + 1) % 3] = sp;
        }
      }
    }
    s.barycentric = s.barycentric.cwiseMax(0.0);
    s.barycentric /= s.barycentric.sum();
    const auto& tv = mesh.triangles[t];
    // The surface point EXACTLY on its triangle (exact_point_on): from the corner of largest
    // weight along the edges to the others with weight (two on the face, one on an edge, none at
    // a corner — then the point is that vertex, with its ring decided exactly as a vertex's).
    int o = 0;
    for (int i = 1; i < 3; ++i)
      if (s.barycentric[i] > s.barycentric[o]) o = i;
    std::array<Eigen::Vector3d, 2> q;
    std::array<double, 2> w{};
    std::array<int, 2> qi{};
    size_t nq = 0;
    for (int i = 0; i < 3; ++i)
      if (i != o && s.barycentric[i] > 0) qi[nq] = i, q[nq] = mesh.positions[tv[size_t(i)]].cast<double>(), w[nq] = s.barycentric[i], ++nq;
    const Eigen::Vector3d corner = mesh.positions[tv[size_t(o)]].cast<double>();
    ShadePoint sp;
    Eigen::Vector3d exact_p;
    bool inexact = false;
    if (nq == 0) {
      s.barycentric = Eigen::Vector3d::Zero();
      s.barycentric[o] = 1;
      sp = vertex_shade_point(mesh, topology, tv[size_t(o)]);
    } else {
      if (exact_point_on(corner, std::span(q.data(), nq), std::span(w.data(), nq), exact_p)) {
        s.barycentric = Eigen::Vector3d::Zero();
        double rest = 1;
        for (size_t j = 0; j < nq; ++j) s.barycentric[qi[j]] = w[j], rest -= w[j];
        s.barycentric[o] = rest;
      } else {
        inexact = true;
        exact_p = Eigen::Vector3d::Zero();
        for (int i = 0; i < 3; ++i) exact_p += s.barycentric[i] * mesh.positions[tv[size_t(i)]].cast<double>();
      }
      sp.p = exact_p;
      // The normal: the vertex normals interpolated (the smooth shading the vertex bakes use), or
      // the face normal where they cancel.
      Eigen::Vector3d n = Eigen::Vector3d::Zero(), centroid = Eigen::Vector3d::Zero();
      for (int i = 0; i < 3; ++i) {
        centroid += mesh.positions[tv[size_t(i)]].cast<double>() / 3;
        n += s.barycentric[i] * mesh.normals[tv[size_t(i)]].cast<double>();
      }
      const Eigen::Vector3d face = (mesh.positions[tv[1]] - mesh.positions[tv[0]])
                                       .cast<double>()
                                       .cross((mesh.positions[tv[2]] - mesh.positions[tv[0]]).cast<double>());
      if (n.norm() > 0 && std::isfinite(n.norm())) sp.n = n.normalized();
      else if (face.norm() > 0) sp.n = face.normalized();
      else sp.n = mesh.normals[tv[0]].cast<double>().normalized();
      // The tie-break into its own surface (as a vertex's, bake/mesh/receivers.h): towards the
      // triangle's centroid, in the tangent plane.
      Eigen::Vector3d into = centroid - sp.p;
      into -= sp.n.dot(into) * sp.n;
      if (const double len = into.norm(); len > 0 && std::isfinite(len)) sp.t = into / len;
      if (inexact) {
        // The triangles the intended point lies on: its own and, on an edge, every triangle of that edge.
        std::vector<uint32_t> on = {t};
        if (nq == 1)
          if (const auto e = topology.find_edge(topology.weld[tv[size_t(o)]], topology.weld[tv[size_t(qi[0])]]))
            for (uint32_t f : topology.faces_of_edge(*e))
              if (f != t) on.push_back(f);
        if (lift_in_front(mesh, on, sp.n, sp.p)) ++out.lifted_samples;
        else ++out.inexact_samples;
      }
    }
    out.coverage[k] = 1;
    out.samples.push_back(s);
    out.receivers.points.push_back(sp);
  }
  return out;
}

} // namespace prt::bake
