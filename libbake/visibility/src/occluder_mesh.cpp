// occluder_mesh.cpp — the visible part of a planar light past a triangle mesh: culling by the
// light's pyramid and plane, exact depth and ε-limit images, then visible_region
// (bake/visibility/occluder_mesh.h has the method).
#include <bake/visibility/occluder_mesh.h>

#include <bake/core/error.h>
#include <bake/visibility/contour.h>
#include <bake/visibility/visible_region.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace prt::bake {

using V3 = Eigen::Vector3d;

namespace {

// Culling margin relative to the scale of a plane value m·(x − o) (see the header): the float
// plane values err by a few ulps of |factors| · |x − o|; 1e-12 is ~4500 ulps.
constexpr double kMargin = 1e-12;
constexpr uint32_t kLeafSize = 4;

}  // namespace

// The light's plane as three of its vertices, and p's side of it.
struct OccluderMesh::LightFrame {
  V3 a, b, c;
  int p_side = 0;  // orient3d_exact(a, b, c, p) ≠ 0
  V3 m;            // −p_side·(b − a)×(c − a): m·(x − a) > 0 on p's side
  double bound_coef = 0;

  // orient3d_exact(a, b, c, x)·p_side (> 0: x on p's side), by a filter first: m·(x − a) in
  // double errs by less than 8u |b − a|₁|c − a|₁|x − a|₁ (u = 2⁻⁵³); beyond 1e-14 of that
  // product its sign is the exact one.
  int depth_side(const V3& x) const {
    const V3 r = x - a;
    const double v = m.dot(r), bound = bound_coef * r.cwiseAbs().sum();
    if (v > bound) return 1;
    if (v < -bound) return -1;
    return orient3d_exact(a, b, c, x) * p_side;
  }
};

namespace {

std::vector<V3> world_positions(const Mesh& mesh) {
  std::vector<V3> out;
  out.reserve(mesh.positions.size());
  for (size_t v = 0; v < mesh.positions.size(); ++v) out.push_back(mesh.world_position(v));
  return out;
}

}  // namespace

OccluderMesh::OccluderMesh(const Mesh& mesh) : OccluderMesh(world_positions(mesh), mesh.triangles) {}

OccluderMesh::OccluderMesh(std::vector<V3> positions, std::vector<std::array<uint32_t, 3>> triangles)
    : positions_(std::move(positions)), triangles_(std::move(triangles)) {
  std::vector<V3> centroids;
  for (const auto& t : triangles_) {
    for (uint32_t v : t) PRT_CHECK(v < positions_.size());
    centroids.push_back((positions_[t[0]] + positions_[t[1]] + positions_[t[2]]) / 3);
  }
  order_.resize(triangles_.size());
  for (uint32_t i = 0; i < order_.size(); ++i) order_[i] = i;
  if (!triangles_.empty()) build(0, uint32_t(triangles_.size()), centroids);

  // Edge → faces: the slots 3t + k (edge (t[k], t[k+1]) of triangle t) sorted by their
  // unordered vertex pair; a group of equal pairs is one mesh edge (≥ 3 slots: non-manifold).
  // Vertices are welded by bitwise-equal position first (seams of an OBJ, STL soups), since
  // equal positions give equal image vertices.
  std::vector<uint32_t> by_position(positions_.size());
  for (uint32_t v = 0; v < by_position.size(); ++v) by_position[v] = v;
  auto less = [&](uint32_t x, uint32_t y) {
    const V3 &a = positions_[x], &b = positions_[y];
    return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
  };
  std::stable_sort(by_position.begin(), by_position.end(), less);
  welded_.resize(positions_.size());
  for (size_t i = 0; i < by_position.size(); ++i)
    welded_[by_position[i]] = i > 0 && positions_[by_position[i]] == positions_[by_position[i - 1]]
                                  ? welded_[by_position[i - 1]]
                                  : by_position[i];
  const size_t slots = 3 * triangles_.size();
  auto key = [&](uint32_t slot) {
    const auto& t = triangles_[slot / 3];
    const uint32_t u = welded_[t[slot % 3]], v = welded_[t[(slot % 3 + 1) % 3]];
    return std::pair(std::min(u, v), std::max(u, v));
  };
  edge_slots_.resize(slots);
  for (uint32_t i = 0; i < slots; ++i) edge_slots_[i] = i;
  std::sort(edge_slots_.begin(), edge_slots_.end(), [&](uint32_t x, uint32_t y) {
    const auto kx = key(x), ky = key(y);
    return kx != ky ? kx < ky : x < y;
  });
  slot_group_.resize(slots);
  edge_group_start_.clear();
  for (uint32_t i = 0; i < slots; ++i) {
    if (i == 0 || key(edge_slots_[i]) != key(edge_slots_[i - 1])) edge_group_start_.push_back(i);
    slot_group_[edge_slots_[i]] = uint32_t(edge_group_start_.size() - 1);
  }
  edge_group_start_.push_back(uint32_t(slots));
}

uint32_t OccluderMesh::build(uint32_t first, uint32_t count, std::vector<V3>& centroids) {
  const uint32_t at = uint32_t(nodes_.size());
  nodes_.push_back({V3::Zero(), V3::Zero(), 0, 0, first, count});
  V3 lo = V3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  V3 clo = lo, chi = hi;
  for (uint32_t i = first; i < first + count; ++i) {
    for (uint32_t v : triangles_[order_[i]]) {
      lo = lo.cwiseMin(positions_[v]);
      hi = hi.cwiseMax(positions_[v]);
    }
    clo = clo.cwiseMin(centroids[order_[i]]);
    chi = chi.cwiseMax(centroids[order_[i]]);
  }
  nodes_[at].lo = lo;
  nodes_[at].hi = hi;
  if (count <= kLeafSize) {
    nodes_[at].index = first;
    nodes_[at].count = count;
    return at;
  }
  int axis = 0;
  (chi - clo).maxCoeff(&axis);
  const uint32_t half = count / 2;
  std::nth_element(order_.begin() + first, order_.begin() + first + half, order_.begin() + first + count,
                   [&](uint32_t x, uint32_t y) { return centroids[x][axis] < centroids[y][axis]; });
  build(first, half, centroids);
  const uint32_t right = build(first + half, count - half, centroids);
  nodes_[at].index = right;
  nodes_[at].count = 0;
  return at;
}

bool OccluderMesh::prepare(std::span<const V3> light, const ShadePoint& point, Workspace& ws, LightFrame& frame) const {
  ws.image_count = 0;
  ws.kept.clear();
  ws.clipped.clear();
  if (light.size() < 3) return false;
  // The light's plane: the fan triangle (L_0, L_k, L_k+1) of largest area (any of them for a planar polygon).
  size_t best = 1;
  double best_area = -1;
  for (size_t k = 1; k + 1 < light.size(); ++k) {
    const double area = (light[k] - light[0]).cross(light[k + 1] - light[0]).squaredNorm();
    if (area > best_area) best_area = area, best = k;
  }
  frame.a = light[0];
  frame.b = light[best];
  frame.c = light[best + 1];
  frame.p_side = orient3d_exact(frame.a, frame.b, frame.c, point.p);
  if (frame.p_side == 0) return false;  // p in the light's plane: no solid angle

  // Directions, positively oriented (det(a − p, b − p, c − p) has the sign p_side), clipped.
  ws.rel.resize(light.size());
  for (size_t k = 0; k < light.size(); ++k) ws.rel[k] = light[k] - point.p;
  if (frame.p_side < 0) std::reverse(ws.rel.begin(), ws.rel.end());
  if (point.hemisphere) {
    clip_to_horizon(ws.rel, point.n, ws.clipped);
  } else {
    ws.clipped = ws.rel;
  }
  if (ws.clipped.size() < 3) return false;

  // Culling planes: the pyramid's sides through p and the light's plane (p's side kept).
  ws.planes.clear();
  const auto& c = ws.clipped;
  for (size_t k = 0; k < c.size(); ++k) {
    const V3& u = c[k];
    const V3& v = c[k + 1 == c.size() ? 0 : k + 1];
    ws.planes.push_back({u.cross(v), point.p, kMargin * u.norm() * v.norm()});
  }
  const V3 ab = frame.b - frame.a, ac = frame.c - frame.a;
  // det(a − p, b − p, c − p) = −N·(p − a) with N = (b − a)×(c − a): p's side has −p_side·N·(x − a) > 0.
  ws.planes.push_back({-double(frame.p_side) * ab.cross(ac), frame.a, kMargin * ab.norm() * ac.norm()});
  frame.m = ws.planes.back().m;
  frame.bound_coef = 1e-14 * ab.cwiseAbs().sum() * ac.cwiseAbs().sum();
  return true;
}

OccluderMesh::ImageKind OccluderMesh::add_image(uint32_t triangle, const ShadePoint& point, const LightFrame& frame,
                                                Workspace& ws) const {
  const auto& t = triangles_[triangle];
  const V3* x[3] = {&positions_[t[0]], &positions_[t[1]], &positions_[t[2]]};
  // Depth, exactly: s > 0 on p's side of the light's plane.
  int s[3];
  bool any_front = false, any_back = false;
  for (int k = 0; k < 3; ++k) {
    s[k] = frame.depth_side(*x[k]);
    any_front = any_front || s[k] > 0;
    any_back = any_back || s[k] < 0;
  }
  if (!any_front) return ImageKind::none;  // behind the light (or in its plane)
  auto& poly = ws.poly;
  poly.clear();
  if (!any_back) {
    for (const V3* v : x) poly.push_back(*v);
  } else {  // straddles the plane: keep p's side (Sutherland–Hodgman, sides exact)
    const V3& m = ws.planes.back().m;
    for (int k = 0; k < 3; ++k) {
      const int k1 = k == 2 ? 0 : k + 1;
      if (s[k] >= 0) poly.push_back(*x[k]);
      if (s[k] * s[k1] < 0) {
        const double da = m.dot(*x[k] - frame.a), db = m.dot(*x[k1] - frame.a);
        const double u = std::clamp(da / (da - db), 0.0, 1.0);
        poly.push_back(*x[k] + u * (*x[k1] - *x[k]));
      }
    }
  }
  auto push = [&ws, triangle](auto&& fill) {
    if (ws.image_count == ws.images.size()) ws.images.emplace_back();
    auto& image = ws.images[ws.image_count++];
    image.clear();
    fill(image);
    ws.image_triangle.resize(ws.image_count);
    ws.image_triangle.back() = triangle;
  };

  const int side = orient3d_exact(*x[0], *x[1], *x[2], point.p);
  ws.last_side = side;
  if (side != 0) {  // p off the plane: the directions to the corners
    push([&](std::vector<V3>& image) {
      for (const V3& v : poly) image.push_back(v - point.p);
      if (side < 0) std::reverse(image.begin(), image.end());
    });
    return any_back ? ImageKind::special : ImageKind::triangle;
  }
  // p in the plane: is it on the (clipped) face? In-plane sides from a point q off the plane.
  V3 q = point.p;
  bool found = false;
  for (int axis = 0; axis < 3 && !found; ++axis) {
    q = point.p + V3::Unit(axis);
    found = orient3d_exact(*x[0], *x[1], *x[2], q) != 0;
  }
  if (!found) return ImageKind::none;  // a zero-area triangle
  const size_t m = poly.size();
  int seen = 0;
  for (size_t k = 0; k < m; ++k) {
    const int sk = orient3d_exact(poly[k], poly[k + 1 == m ? 0 : k + 1], q, point.p);
    if (sk != 0 && seen != 0 && sk != seen) return ImageKind::none;  // outside: no area in the limit
    if (sk != 0) seen = sk;
  }
  // p on the face: the triangles (p, v_k, v_k+1) seen from p + εn are cones (v_k − p, v_k+1 − p, −n).
  const V3 down = -point.n;
  for (size_t k = 0; k < m; ++k) {
    const V3& v0 = poly[k];
    const V3& v1 = poly[k + 1 == m ? 0 : k + 1];
    if (orient3d_exact(v0, v1, q, point.p) == 0) continue;  // p on this edge (or its line)
    const V3 a = v0 - point.p, b = v1 - point.p;
    const int o = orient3d_exact(a, b, down, V3::Zero());
    if (o == 0) continue;  // n in the face's plane: no interior
    push([&](std::vector<V3>& image) {
      if (o > 0) {
        image.assign({a, b, down});
      } else {
        image.assign({b, a, down});
      }
    });
  }
  return ImageKind::special;
}

size_t OccluderMesh::query(std::span<const V3> light, const ShadePoint& point, std::vector<Arc>& out, Workspace& ws,
                           Method method) const {
  LightFrame frame;
  if (!prepare(light, point, ws, frame)) {
    out.clear();
    return 0;
  }
  if (method == Method::reference) {
    for (uint32_t t = 0; t < triangles_.size(); ++t) ws.kept.push_back(t);
  } else {
    cull(ws);
    std::sort(ws.kept.begin(), ws.kept.end());
  }
  if (method != Method::contour) {
    for (uint32_t t : ws.kept) add_image(t, point, frame, ws);
    visible_region(ws.clipped, std::span<const std::vector<V3>>(ws.images.data(), ws.image_count), out);
    return ws.kept.size();
  }

  // The contour path: each kept triangle's image and kind, then the edges that may bound the
  // union (the header's rule), then visible_region_sparse.
  if (ws.tri_stamp.size() != triangles_.size()) {
    ws.tri_stamp.assign(triangles_.size(), 0);
    ws.tri_side.assign(triangles_.size(), 0);
    ws.stamp = 0;
  }
  if (ws.stamp == std::numeric_limits<uint32_t>::max()) {
    std::fill(ws.tri_stamp.begin(), ws.tri_stamp.end(), 0);
    ws.stamp = 0;
  }
  const uint32_t stamp = ++ws.stamp;
  ws.image_kind.clear();
  bool special = false;
  for (uint32_t t : ws.kept) {
    const ImageKind kind = add_image(t, point, frame, ws);
    ws.image_kind.resize(ws.image_count, uint8_t(kind));
    ws.tri_stamp[t] = stamp;
    ws.tri_side[t] = 0;
    if (kind == ImageKind::triangle) {
      // The image's orientation: det(x0 − p, x1 − p, x2 − p)'s sign (the image was reversed when < 0).
      ws.tri_side[t] = int8_t(ws.last_side);
    }
    special = special || kind == ImageKind::special;
  }
  ws.boundary.assign(ws.image_count, 0xff);
  for (size_t i = 0; i < ws.image_count; ++i) {
    if (ws.image_kind[i] != uint8_t(ImageKind::triangle)) continue;
    const uint32_t t = ws.image_triangle[i];
    const int sigma = ws.tri_side[t];
    uint8_t mask = 0;
    for (uint32_t e = 0; e < 3; ++e) {
      // Image edge e runs along the mesh edge of slot k (the image is reversed when sigma < 0).
      const uint32_t k = sigma > 0 ? e : (e == 2 ? 2 : 1 - e);
      const uint32_t slot = 3 * t + k, u = welded_[triangles_[t][k]];
      const uint32_t group = slot_group_[slot];
      bool interior = false;
      for (uint32_t at = edge_group_start_[group]; at < edge_group_start_[group + 1] && !interior; ++at) {
        const uint32_t other = edge_slots_[at], t2 = other / 3;
        if (t2 == t || ws.tri_stamp[t2] != stamp || ws.tri_side[t2] == 0) continue;
        const int side2 = welded_[triangles_[t2][other % 3]] == u ? ws.tri_side[t2] : -ws.tri_side[t2];
        // Opposite sides: t2 covers e's right side. The same side with t2 listed first (a fold:
        // a contour edge): t2's image edge is the same arc and owns it (visible_region's rule).
        interior = side2 * sigma < 0 || t2 < t;
      }
      if (!interior) mask = uint8_t(mask | (1u << e));
    }
    ws.boundary[i] = mask;
  }
  visible_region_sparse(ws.clipped, std::span<const std::vector<V3>>(ws.images.data(), ws.image_count),
                        std::span<const uint8_t>(ws.boundary.data(), ws.image_count), out, ws.region);
  ++ws.stats.queries;
  ws.stats.kept += ws.kept.size();
  ws.stats.boundary_edges += ws.region.boundary_edges;
  ws.stats.special += special;
  ws.stats.uncharted += !ws.region.charted;
  return ws.kept.size();
}

void OccluderMesh::cull(Workspace& ws) const {
  if (nodes_.empty()) return;
  // -1: the box is outside a plane (beyond the margin); +1: inside every plane by more than the
  // margin (so is every triangle in it); 0: neither.
  auto box_test = [&](const Node& node) {
    const V3 centre = (node.lo + node.hi) / 2, half = (node.hi - node.lo) / 2;
    bool inside = true;
    for (const auto& plane : ws.planes) {
      const V3 r = centre - plane.o;
      const double mid = plane.m.dot(r), spread = plane.m.cwiseAbs().dot(half);
      // |r|₁ + |half|₁ ≥ |r| + |half|: a margin at least as large as the header's, without roots.
      const double margin = plane.margin_coef * (r.cwiseAbs().sum() + half.cwiseAbs().sum());
      if (mid + spread < -margin) return -1;
      inside = inside && mid - spread > margin;
    }
    return inside ? 1 : 0;
  };
  // A triangle of a leaf is outside a plane when its highest vertex is below −margin, the
  // leaf's margin for that plane (|x − o| ≤ |centre − o|₁ + |half|₁ for x in the leaf's box).
  std::vector<double>& leaf_margin = ws.margins;
  leaf_margin.assign(ws.planes.size(), 0.0);
  auto triangle_outside = [&](uint32_t t) {
    for (size_t k = 0; k < ws.planes.size(); ++k) {
      const auto& plane = ws.planes[k];
      double top = -std::numeric_limits<double>::infinity();
      for (uint32_t v : triangles_[t]) top = std::max(top, plane.m.dot(positions_[v] - plane.o));
      if (top < -leaf_margin[k]) return true;
    }
    return false;
  };
  ws.stack.assign(1, 0);
  while (!ws.stack.empty()) {
    const uint32_t at = ws.stack.back();
    const Node& node = nodes_[at];
    ws.stack.pop_back();
    const int test = box_test(node);
    if (test < 0) continue;
    if (test > 0) {
      ws.kept.insert(ws.kept.end(), order_.begin() + node.first, order_.begin() + node.first + node.total);
      continue;
    }
    if (node.count == 0) {
      ws.stack.push_back(node.index);
      ws.stack.push_back(at + 1);
      continue;
    }
    const V3 centre = (node.lo + node.hi) / 2, half = (node.hi - node.lo) / 2;
    for (size_t k = 0; k < ws.planes.size(); ++k)
      leaf_margin[k] = ws.planes[k].margin_coef * ((centre - ws.planes[k].o).cwiseAbs().sum() + half.cwiseAbs().sum());
    for (uint32_t i = node.index; i < node.index + node.count; ++i)
      if (!triangle_outside(order_[i])) ws.kept.push_back(order_[i]);
  }
}

} // namespace prt::bake
