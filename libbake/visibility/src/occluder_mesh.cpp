// occluder_mesh.cpp — the visible part of a planar light past a triangle mesh: culling by the
// light's pyramid and plane, exact depth and ε-limit images, then visible_region
// (bake/visibility/occluder_mesh.h has the method).
#include <bake/visibility/occluder_mesh.h>

#include <bake/core/error.h>
#include <bake/visibility/contour.h>
#include <bake/visibility/visible_region.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

namespace prt::bake {

using V3 = Eigen::Vector3d;

namespace {

// Culling margin relative to the scale of a plane value m·(x − o) (see the header): the float
// plane values err by a few ulps of |factors| · |x − o|; 1e-12 is ~4500 ulps.
constexpr double kMargin = 1e-12;
constexpr uint32_t kLeafSize = 4;
constexpr size_t kFanBatch = 64;  // fans walked together (one bit each)
constexpr size_t kConeSides = 8;     // lights of more sides are culled by an octagonal pyramid (header)
constexpr double kConeMinCos = 0.1;  // … while the cone around the light is narrower than 84°

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

// Exact sign of det(c, d, x) (orient3d_exact with the origin), by a filter first: (c × d)·x in
// double errs by less than 8u |c|₁|d|₁|x|₁ (u = 2⁻⁵³); beyond 1e-14 of that product its sign is
// the exact one (visible_region.cpp's side filter).
int det_sign(const V3& c, const V3& d, const V3& x) {
  const double v = c.cross(d).dot(x), bound = 1e-14 * c.cwiseAbs().sum() * d.cwiseAbs().sum() * x.cwiseAbs().sum();
  if (v > bound) return 1;
  if (v < -bound) return -1;
  return orient3d_exact(c, d, x, V3::Zero());
}

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
  // Sorted as (key, slot) pairs with the key packed in 64 bits: the same order as comparing
  // keys, then slots, without looking the key up in every comparison.
  std::vector<std::pair<uint64_t, uint32_t>> keyed(slots);
  for (uint32_t i = 0; i < slots; ++i) {
    const auto [u, v] = key(i);
    keyed[i] = {uint64_t(u) << 32 | v, i};
  }
  std::sort(keyed.begin(), keyed.end());
  edge_slots_.resize(slots);
  slot_group_.resize(slots);
  edge_group_start_.clear();
  for (uint32_t i = 0; i < slots; ++i) {
    edge_slots_[i] = keyed[i].second;
    if (i == 0 || keyed[i].first != keyed[i - 1].first) edge_group_start_.push_back(i);
    slot_group_[edge_slots_[i]] = uint32_t(edge_group_start_.size() - 1);
  }
  edge_group_start_.push_back(uint32_t(slots));

  // Unit face normals and flagged edges (the edge tree is built by the first cone query).
  face_normal_.resize(triangles_.size());
  for (size_t t = 0; t < triangles_.size(); ++t) {
    const auto& tri = triangles_[t];
    const V3 n = (positions_[tri[1]] - positions_[tri[0]]).cross(positions_[tri[2]] - positions_[tri[0]]);
    const double len = n.norm();
    face_normal_[t] = len > 0 && std::isfinite(len) ? V3(n / len) : V3::Zero();
  }
  const size_t groups = edge_count();
  edge_flagged_.assign(groups, 0);
  for (size_t g = 0; g < groups; ++g) {
    const uint32_t first = edge_group_start_[g], end = edge_group_start_[g + 1];
    bool flagged = end - first != 2;
    for (uint32_t at = first; at < end; ++at) {
      const auto& tri = triangles_[edge_slots_[at] / 3];
      const uint32_t a = welded_[tri[0]], b = welded_[tri[1]], c = welded_[tri[2]];
      flagged = flagged || a == b || b == c || c == a || face_normal_[edge_slots_[at] / 3] == V3::Zero();
    }
    if (!flagged) {
      const uint32_t s0 = edge_slots_[first], s1 = edge_slots_[first + 1];
      // Two faces of distinct corners running the edge both ways (a consistently wound pair).
      flagged = s0 / 3 == s1 / 3 || welded_[triangles_[s0 / 3][s0 % 3]] == welded_[triangles_[s1 / 3][s1 % 3]];
    }
    edge_flagged_[g] = uint8_t(flagged);
  }
  closed_ = groups > 0 && std::none_of(edge_flagged_.begin(), edge_flagged_.end(), [](uint8_t f) { return f != 0; });
  twin_slot_.assign(slots, kNoTwin);
  for (size_t g = 0; g < groups; ++g)
    if (!edge_flagged_[g]) {
      const uint32_t s0 = edge_slots_[edge_group_start_[g]], s1 = edge_slots_[edge_group_start_[g] + 1];
      twin_slot_[s0] = s1;
      twin_slot_[s1] = s0;
    }
}

void OccluderMesh::edge_tree() const {
  std::call_once(*edge_tree_once_, [this] {
    const size_t groups = edge_count();
    std::vector<V3> centres(groups);
    for (size_t g = 0; g < groups; ++g) {
      const uint32_t slot = edge_slots_[edge_group_start_[g]];
      const auto& tri = triangles_[slot / 3];
      centres[g] = (positions_[tri[slot % 3]] + positions_[tri[(slot % 3 + 1) % 3]]) / 2;
    }
    edge_order_.resize(groups);
    for (uint32_t g = 0; g < groups; ++g) edge_order_[g] = g;
    if (groups > 0) build_edges(0, uint32_t(groups), centres);
    edge_rank_.resize(groups);
    for (uint32_t i = 0; i < groups; ++i) edge_rank_[edge_order_[i]] = i;
  });
}

uint32_t OccluderMesh::build_edges(uint32_t first, uint32_t count, std::vector<V3>& centres) const {
  const uint32_t at = uint32_t(edge_nodes_.size());
  edge_nodes_.push_back({V3::Zero(), V3::Zero(), V3::Zero(), V3::Zero(), 0, 0, 0, 0, count, false});
  V3 lo = V3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  V3 clo = lo, chi = hi, sum = V3::Zero();
  bool flagged = false;
  for (uint32_t i = first; i < first + count; ++i) {
    const uint32_t g = edge_order_[i];
    flagged = flagged || edge_flagged_[g];
    for (uint32_t s = edge_group_start_[g]; s < edge_group_start_[g + 1]; ++s) {
      const uint32_t t = edge_slots_[s] / 3;
      for (uint32_t v : triangles_[t]) {
        lo = lo.cwiseMin(positions_[v]);
        hi = hi.cwiseMax(positions_[v]);
      }
      sum += face_normal_[t];
    }
    clo = clo.cwiseMin(centres[g]);
    chi = chi.cwiseMax(centres[g]);
  }
  EdgeNode& node = edge_nodes_[at];
  node.lo = lo;
  node.hi = hi;
  node.centre = (lo + hi) / 2;
  // Every face point x has |x − centre| ≤ |half| (computed: widened far beyond its rounding).
  node.radius = ((hi - lo) / 2).norm() * (1 + 1e-12);
  node.flagged = flagged;
  const double len = sum.norm();
  node.axis = len > 0 && std::isfinite(len) ? V3(sum / len) : V3::Zero();
  double spread = node.axis == V3::Zero() ? 4.0 : 0.0;
  for (uint32_t i = first; i < first + count && spread < 4; ++i) {
    const uint32_t g = edge_order_[i];
    for (uint32_t s = edge_group_start_[g]; s < edge_group_start_[g + 1]; ++s)
      spread = std::max(spread, (face_normal_[edge_slots_[s] / 3] - node.axis).norm());
  }
  node.spread = spread * (1 + 1e-12) + 1e-12;
  if (count <= kLeafSize) {
    node.index = first;
    node.count = count;
    return at;
  }
  int axis = 0;
  (chi - clo).maxCoeff(&axis);
  const uint32_t half = count / 2;
  std::nth_element(edge_order_.begin() + first, edge_order_.begin() + first + half, edge_order_.begin() + first + count,
                   [&](uint32_t x, uint32_t y) { return centres[x][axis] < centres[y][axis]; });
  build_edges(first, half, centres);
  const uint32_t right = build_edges(first + half, count - half, centres);
  edge_nodes_[at].index = right;
  edge_nodes_[at].count = 0;
  return at;
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

  // A many-sided light's culling pyramid: 8 planes tangent to a cone around it (header).
  ws.cull_planes.clear();
  if (c.size() > kConeSides) {
    V3 axis = V3::Zero();
    for (const V3& u : c) axis += u.normalized();
    const double norm = axis.norm();
    if (norm > 0 && std::isfinite(norm)) {
      axis /= norm;
      double cos_t = 1;
      for (const V3& u : c) cos_t = std::min(cos_t, axis.dot(u.normalized()));
      cos_t -= 1e-9;
      if (cos_t > kConeMinCos) {
        const double sin_t = std::sqrt((1 - cos_t) * (1 + cos_t));
        const V3 e1 = axis.unitOrthogonal(), e2 = axis.cross(e1);
        for (size_t j = 0; j < kConeSides; ++j) {
          const double angle = 2 * std::numbers::pi * double(j) / double(kConeSides);
          const V3 e = std::cos(angle) * e1 + std::sin(angle) * e2;
          ws.cull_planes.push_back({sin_t * axis - cos_t * e, point.p, kMargin});
        }
        ws.cull_planes.push_back(ws.planes.back());
      }
    }
  }
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
    ws.settled = ws.settled && s[k] != 0;
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
  ws.settled = ws.settled && side != 0 && !any_back;
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
  if (method == Method::cone) {
    find_cone_edges(point, frame, ws, false);
    cone_query(point, frame, out, ws);
    return ws.kept.size();
  }
  if (method == Method::reference) {
    for (uint32_t t = 0; t < triangles_.size(); ++t) ws.kept.push_back(t);
  } else {
    cull(ws);
    sort_kept(ws);
  }
  if (method == Method::per_triangle || method == Method::reference) {
    for (uint32_t t : ws.kept) add_image(t, point, frame, ws);
    visible_region(ws.clipped, std::span<const std::vector<V3>>(ws.images.data(), ws.image_count), out);
    return ws.kept.size();
  }

  // The contour path: each kept triangle's image and kind, then the edges that may bound the
  // union (the header's rule), then visible_region_sparse.
  const uint32_t stamp = next_stamp(ws);
  ws.image_kind.clear();
  bool special = false;
  ws.settled = true;
  // The closed-mesh rule's count at a generic direction d (header, "one facing"), taken while
  // each image is at hand: Σ σ_t over the images containing d, and the images facing +1.
  V3 probe = V3::Zero();
  bool probing = closed_ && probe_direction(ws, probe);
  int probe_sum = 0;
  size_t positive = 0;
  for (uint32_t t : ws.kept) {
    const ImageKind kind = add_image(t, point, frame, ws);
    if (probing && kind == ImageKind::triangle) {
      const int inside = probe_image(ws.images[ws.image_count - 1], probe);
      probing = inside >= 0;
      probe_sum += inside > 0 ? ws.last_side : 0;
      positive += ws.last_side > 0;
    }
    ws.image_kind.resize(ws.image_count, uint8_t(kind));
    ws.tri_stamp[t] = stamp;
    ws.tri_side[t] = 0;
    if (kind == ImageKind::triangle) {
      // The image's orientation: det(x0 − p, x1 − p, x2 − p)'s sign (the image was reversed when < 0).
      ws.tri_side[t] = int8_t(ws.last_side);
    }
    special = special || kind == ImageKind::special;
  }
  if (probing && ws.settled && ws.image_count > 0) {
    // A closed mesh with every image whole: one facing's images cover what all do (header,
    // "one facing"; the facing with fewer images), or the light is hidden entirely.
    const int facing = probe_sum != 0 ? 2 : 2 * positive <= ws.image_count ? 1 : -1;
    if (facing == 2) {
      out.clear();
      ++ws.stats.queries;
      ++ws.stats.one_facing;
      ++ws.stats.hidden;
      ws.stats.kept += ws.kept.size();
      return ws.kept.size();
    }
    // Only the images of that facing stay (in index order); the others' triangles count as
    // not kept for the edge masks, so a contour edge is cut on its remaining face.
    size_t kept_images = 0;
    for (size_t i = 0; i < ws.image_count; ++i) {
      const uint32_t t = ws.image_triangle[i];
      if (ws.tri_side[t] != facing) {
        ws.tri_side[t] = 0;
        continue;
      }
      if (kept_images != i) {
        // Copied, not swapped: each slot keeps its own storage, allocated in order (swapping
        // scatters them over queries; at Loop level 4 that cost more than the rule saved).
        ws.images[kept_images].assign(ws.images[i].begin(), ws.images[i].end());
        ws.image_triangle[kept_images] = t;
        ws.image_kind[kept_images] = ws.image_kind[i];
      }
      ++kept_images;
    }
    ws.image_count = kept_images;
    ws.image_triangle.resize(kept_images);
    ws.image_kind.resize(kept_images);
    ++ws.stats.one_facing;
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
      const uint32_t slot = 3 * t + k;
      bool interior = false;
      if (const uint32_t twin = twin_slot_[slot]; twin != kNoTwin) {
        // A consistently wound pair: the twin runs the edge the other way (side2 = −tri_side),
        // the loop below's rule in one step.
        const uint32_t t2 = twin / 3;
        interior = ws.tri_stamp[t2] == stamp && ws.tri_side[t2] != 0 && (ws.tri_side[t2] * sigma > 0 || t2 < t);
        if (!interior) mask = uint8_t(mask | (1u << e));
        continue;
      }
      const uint32_t u = welded_[triangles_[t][k]], group = slot_group_[slot];
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

bool OccluderMesh::probe_direction(const Workspace& ws, V3& d) const {
  // A positive sum of the light's corner directions, strictly inside every light edge (exactly).
  d = V3::Zero();
  for (const V3& c : ws.clipped) d += c.normalized();
  const size_t n = ws.clipped.size();
  for (size_t k = 0; k < n; ++k)
    if (det_sign(ws.clipped[k], ws.clipped[k + 1 == n ? 0 : k + 1], d) <= 0) return false;
  return true;
}

int OccluderMesh::probe_image(std::span<const V3> image, const V3& d) {
  // The image as computed (rounded corner directions) must be oriented as its triangle seen
  // from p (it was reversed by that sign), and d on no edge of it.
  if (image.size() != 3 || det_sign(image[0], image[1], image[2]) <= 0) return -1;
  for (size_t k = 0; k < 3; ++k) {
    const int side = det_sign(image[k], image[k == 2 ? 0 : k + 1], d);
    if (side == 0) return -1;  // d on an image edge's great circle: not a generic direction
    if (side < 0) return 0;    // strictly outside (off its boundary)
  }
  return 1;
}

void OccluderMesh::sort_kept(Workspace& ws) const {
  // Ascending (the walk keeps each triangle once). A few among many (a small light over a large
  // mesh) by std::sort; else by a bitmap over the triangles, read word by word.
  const size_t words = (triangles_.size() + 63) / 64;
  if (ws.kept.size() * 16 < words) {
    std::sort(ws.kept.begin(), ws.kept.end());
    return;
  }
  ws.kept_bits.assign(words, 0);
  for (uint32_t t : ws.kept) ws.kept_bits[t >> 6] |= uint64_t(1) << (t & 63);
  ws.kept.clear();
  for (size_t w = 0; w < words; ++w)
    for (uint64_t bits = ws.kept_bits[w]; bits != 0; bits &= bits - 1)
      ws.kept.push_back(uint32_t(w * 64 + size_t(std::countr_zero(bits))));
}

uint32_t OccluderMesh::next_stamp(Workspace& ws) const {
  if (ws.tri_stamp.size() != triangles_.size()) {
    ws.tri_stamp.assign(triangles_.size(), 0);
    ws.tri_side.assign(triangles_.size(), 0);
    ws.stamp = 0;
  }
  if (ws.stamp == std::numeric_limits<uint32_t>::max()) {
    std::fill(ws.tri_stamp.begin(), ws.tri_stamp.end(), 0);
    ws.stamp = 0;
  }
  return ++ws.stamp;
}

void OccluderMesh::cone_query(const ShadePoint& point, const LightFrame& frame, std::vector<Arc>& out,
                              Workspace& ws) const {
  // The edges found: their images are the only ones cut (every other image edge has its far side
  // covered by its neighbour along the whole edge, or misses the light).
  if (ws.group_stamp.size() != edge_count()) {
    ws.group_stamp.assign(edge_count(), 0);
    ws.group_mark = 0;
  }
  if (ws.group_mark == std::numeric_limits<uint32_t>::max()) {
    std::fill(ws.group_stamp.begin(), ws.group_stamp.end(), 0);
    ws.group_mark = 0;
  }
  const uint32_t mark = ++ws.group_mark;
  for (uint32_t g : ws.cone) ws.group_stamp[g] = mark;
  // The triangles meeting the fan of a light edge or of a found edge (the rays from p through it,
  // inside the pyramid and on p's side of the light's plane): every image that meets an edge
  // visible_region_sparse cuts, so each cut gets the same pieces as with every kept image.
  const uint32_t stamp = next_stamp(ws);
  auto keep = [&ws, stamp](uint32_t t) {
    if (ws.tri_stamp[t] != stamp) ws.tri_stamp[t] = stamp, ws.kept.push_back(t);
  };
  // Each fan is bounded by five planes (the slab first: most boxes miss it; the light's plane
  // last); a light edge's fan is the pyramid's side k between its neighbours k − 1 and k + 1.
  ws.fan.clear();
  auto add_fan = [&ws, &point](const V3& a, const V3& b) {  // the rays from p through a, b (relative to p)
    const double la = a.norm(), lb = b.norm();
    const V3 m = a.cross(b);
    // The plane through p, a and b (both sides), and the wedge between the rays to a and b: the
    // margins cover the rounding of m (≤ a few ulps of |a||b|) and of m × a, b × m.
    const double coef = kMargin * la * lb;
    ws.fan.insert(ws.fan.end(), {{m, point.p, coef}, {-m, point.p, coef}, {m.cross(a), point.p, coef * la},
                                 {b.cross(m), point.p, coef * lb}, ws.planes.back()});
  };
  // A special face (clipped, or p in its plane) has every image edge cut: a fan for each.
  for (uint32_t t : ws.special_faces) {
    ws.image_count = 0;
    add_image(t, point, frame, ws);
    for (size_t i = 0; i < ws.image_count; ++i) {
      const auto& image = ws.images[i];
      for (size_t k = 0; k < image.size(); ++k) add_fan(image[k], image[k + 1 == image.size() ? 0 : k + 1]);
    }
  }
  ws.image_count = 0;
  for (uint32_t t : ws.special_faces) keep(t);
  const size_t sides = ws.planes.size() - 1;
  for (size_t k = 0; k < sides; ++k) {
    const auto& side = ws.planes[k];
    ws.fan.insert(ws.fan.end(), {{-side.m, side.o, side.margin_coef}, side, ws.planes[k == 0 ? sides - 1 : k - 1],
                                 ws.planes[k + 1 == sides ? 0 : k + 1], ws.planes.back()});
  }
  // The found edges' fans in the edge tree's leaf order: neighbouring fans share a batch, and
  // so most of the nodes their walk visits.
  ws.edge_stack.assign(ws.cone.begin(), ws.cone.end());
  std::sort(ws.edge_stack.begin(), ws.edge_stack.end(), [this](uint32_t x, uint32_t y) { return edge_rank_[x] < edge_rank_[y]; });
  for (uint32_t g : ws.edge_stack) {
    const uint32_t slot = edge_slots_[edge_group_start_[g]];
    const auto& tri = triangles_[slot / 3];
    add_fan(positions_[tri[slot % 3]] - point.p, positions_[tri[(slot % 3 + 1) % 3]] - point.p);
  }
  for (size_t first = 0; first < ws.fan.size(); first += 5 * kFanBatch)
    walk_fans(std::span<const Workspace::Plane>(ws.fan).subspan(first, std::min(5 * kFanBatch, ws.fan.size() - first)),
              ws, keep);
  std::sort(ws.kept.begin(), ws.kept.end());
  ws.image_kind.clear();
  ws.boundary.clear();
  for (uint32_t t : ws.kept) {
    const ImageKind kind = add_image(t, point, frame, ws);
    ws.image_kind.resize(ws.image_count, uint8_t(kind));
    ws.tri_side[t] = kind == ImageKind::triangle ? int8_t(ws.last_side) : int8_t(0);
    if (kind != ImageKind::triangle) {  // a clipped or ε-limit image cannot be in the pyramid here; cut all
      ws.boundary.resize(ws.image_count, 0xff);
      continue;
    }
    uint8_t mask = 0;
    for (uint32_t e = 0; e < 3; ++e) {
      const uint32_t k = ws.last_side > 0 ? e : (e == 2 ? 2 : 1 - e);  // as in query()
      const uint32_t group = slot_group_[3 * t + k];
      if (ws.group_stamp[group] != mark) continue;
      // A consistently wound pair whose other face, listed first, has a whole image passed on:
      // on the same side (a fold) its image edge is the same arc and owns it, on the other side
      // its image covers this edge's far side along the whole edge (the kept-images rule).
      if (!edge_flagged_[group]) {
        const uint32_t first = edge_slots_[edge_group_start_[group]] / 3, second = edge_slots_[edge_group_start_[group] + 1] / 3;
        const uint32_t other = first == t ? second : first;
        if (other < t && ws.tri_stamp[other] == stamp && ws.tri_side[other] != 0) continue;
      }
      mask = uint8_t(mask | (1u << e));
    }
    ws.boundary.push_back(mask);
  }
  visible_region_sparse(ws.clipped, std::span<const std::vector<V3>>(ws.images.data(), ws.image_count),
                        std::span<const uint8_t>(ws.boundary.data(), ws.image_count), out, ws.region);
  ++ws.stats.queries;
  ++ws.stats.cone;
  ws.stats.special += !ws.special_faces.empty();
  ws.stats.kept += ws.kept.size();
  ws.stats.boundary_edges += ws.region.boundary_edges;
  ws.stats.uncharted += !ws.region.charted;
  ws.stats.cone_edges += ws.cone.size();
  ws.stats.cone_candidates += ws.kept.size();
}

void OccluderMesh::cull(Workspace& ws) const {
  ws.stats.octagon += !ws.cull_planes.empty();
  walk(ws.cull_planes.empty() ? ws.planes : ws.cull_planes, ws, [&ws](uint32_t t) { ws.kept.push_back(t); });
}

template <class Keep>
void OccluderMesh::walk(std::span<const Workspace::Plane> planes, Workspace& ws, Keep&& keep) const {
  if (nodes_.empty()) return;
  // -1: the box is outside a plane (beyond the margin); +1: inside every plane by more than the
  // margin (so is every triangle in it); 0: neither. `pending` has bit k for the planes k < 32
  // still to test: a box inside plane k by more than the margin has every point strictly inside
  // it, and so has each child's box (it lies in the parent's), whose triangles that plane never
  // culls; the bit is cleared for the subtree (the same triangles are kept as when testing it
  // again). Planes from the 33rd on (a light of many sides) are tested at every node.
  const size_t masked = std::min<size_t>(planes.size(), 32);
  auto plane_test = [&](size_t k, const V3& centre, const V3& half) {
    const auto& plane = planes[k];
    const V3 r = centre - plane.o;
    const double mid = plane.m.dot(r), spread = plane.m.cwiseAbs().dot(half);
    // |r|₁ + |half|₁ ≥ |r| + |half|: a margin at least as large as the header's, without roots.
    const double margin = plane.margin_coef * (r.cwiseAbs().sum() + half.cwiseAbs().sum());
    if (mid + spread < -margin) return -1;
    return mid - spread > margin ? 1 : 0;
  };
  auto box_test = [&](const Node& node, uint32_t& pending) {
    const V3 centre = (node.lo + node.hi) / 2, half = (node.hi - node.lo) / 2;
    for (uint32_t bits = pending; bits != 0; bits &= bits - 1) {
      const auto k = uint32_t(std::countr_zero(bits));
      const int test = plane_test(k, centre, half);
      if (test < 0) return -1;
      if (test > 0) pending &= ~(uint32_t(1) << k);
    }
    bool inside = pending == 0;
    for (size_t k = masked; k < planes.size(); ++k) {
      const int test = plane_test(k, centre, half);
      if (test < 0) return -1;
      inside = inside && test > 0;
    }
    return inside ? 1 : 0;
  };
  // A triangle of a leaf is outside a plane when its highest vertex is below −margin, the
  // leaf's margin for that plane (|x − o| ≤ |centre − o|₁ + |half|₁ for x in the leaf's box).
  std::vector<double>& leaf_margin = ws.margins;
  leaf_margin.assign(planes.size(), 0.0);
  auto outside = [&](uint32_t t, size_t k) {
    const auto& plane = planes[k];
    double top = -std::numeric_limits<double>::infinity();
    for (uint32_t v : triangles_[t]) top = std::max(top, plane.m.dot(positions_[v] - plane.o));
    return top < -leaf_margin[k];
  };
  auto triangle_outside = [&](uint32_t t, uint32_t pending) {
    for (uint32_t bits = pending; bits != 0; bits &= bits - 1)
      if (outside(t, size_t(std::countr_zero(bits)))) return true;
    for (size_t k = masked; k < planes.size(); ++k)
      if (outside(t, k)) return true;
    return false;
  };
  const uint32_t all = masked == 32 ? ~uint32_t(0) : (uint32_t(1) << masked) - 1;
  ws.walk_stack.assign(1, {0, all});
  while (!ws.walk_stack.empty()) {
    auto [at, pending] = ws.walk_stack.back();
    const Node& node = nodes_[at];
    ws.walk_stack.pop_back();
    const int test = box_test(node, pending);
    if (test < 0) continue;
    if (test > 0) {
      for (uint32_t i = node.first; i < node.first + node.total; ++i) keep(order_[i]);
      continue;
    }
    if (node.count == 0) {
      ws.walk_stack.push_back({node.index, pending});
      ws.walk_stack.push_back({at + 1, pending});
      continue;
    }
    const V3 centre = (node.lo + node.hi) / 2, half = (node.hi - node.lo) / 2;
    auto margin = [&](size_t k) {
      leaf_margin[k] = planes[k].margin_coef * ((centre - planes[k].o).cwiseAbs().sum() + half.cwiseAbs().sum());
    };
    for (uint32_t bits = pending; bits != 0; bits &= bits - 1) margin(size_t(std::countr_zero(bits)));
    for (size_t k = masked; k < planes.size(); ++k) margin(k);
    for (uint32_t i = node.index; i < node.index + node.count; ++i)
      if (!triangle_outside(order_[i], pending)) keep(order_[i]);
  }
}

namespace {

// x is strictly outside the culling plane (beyond its margin at x: the exact value is negative).
bool outside_plane(const OccluderMesh::Workspace::Plane& plane, const V3& x) {
  const V3 r = x - plane.o;
  return plane.m.dot(r) < -plane.margin_coef * r.cwiseAbs().sum();
}

}  // namespace

template <class Keep>
void OccluderMesh::walk_fans(std::span<const Workspace::Plane> planes, Workspace& ws, Keep&& keep) const {
  if (nodes_.empty() || planes.empty()) return;
  const std::span<const Workspace::Plane> pyramid(ws.planes);
  const size_t fans = planes.size() / 5;
  // A box is outside a fan when it is outside one of its five planes (beyond the margin, as walk()).
  // Every fan plane but the fifth (the light's) passes through o = planes[0].o (p): the node's
  // offset from it and its |·|₁ are shared. The slab (two opposite planes) is one test.
  const V3 o = planes[0].o;
  auto box_outside = [&](const V3& r, const V3& half, double extent, size_t fan) {
    const auto* plane = &planes[5 * fan];
    const double mid = plane[0].m.dot(r), spread = plane[0].m.cwiseAbs().dot(half);
    if (std::abs(mid) - spread > plane[0].margin_coef * extent) return true;  // both slab planes have this margin
    for (int k = 2; k < 4; ++k) {
      if (plane[k].m.dot(r) + plane[k].m.cwiseAbs().dot(half) < -plane[k].margin_coef * extent) return true;
    }
    const V3 rl = r + (o - plane[4].o);
    const double margin = plane[4].margin_coef * (rl.cwiseAbs().sum() + half.cwiseAbs().sum());
    return plane[4].m.dot(rl) + plane[4].m.cwiseAbs().dot(half) < -margin;
  };
  // A triangle is outside a fan when all three corners are outside one plane (each beyond the
  // margin at that corner: its exact value is negative).
  auto triangle_outside = [&](uint32_t t, size_t fan) {
    const auto& tri = triangles_[t];
    for (size_t k = 5 * fan; k < 5 * fan + 5; ++k) {
      const auto& plane = planes[k];
      bool all = true;
      for (int c = 0; c < 3 && all; ++c) {
        const V3 r = positions_[tri[c]] - plane.o;
        all = plane.m.dot(r) < -plane.margin_coef * r.cwiseAbs().sum();
      }
      if (all) return true;
    }
    return false;
  };
  ws.fan_stack.assign(1, {0, fans == 64 ? ~uint64_t(0) : (uint64_t(1) << fans) - 1});
  while (!ws.fan_stack.empty()) {
    auto [at, live] = ws.fan_stack.back();
    ws.fan_stack.pop_back();
    const Node& node = nodes_[at];
    const V3 half = (node.hi - node.lo) / 2, r = (node.lo + node.hi) / 2 - o;
    const double extent = r.cwiseAbs().sum() + half.cwiseAbs().sum();
    // Outside the pyramid (or behind the light) a triangle's image misses the light: no fan
    // needs it.
    bool out_of_pyramid = false;
    for (size_t k = 0; k < pyramid.size() && !out_of_pyramid; ++k) {
      const auto& plane = pyramid[k];
      const V3 rp = r + (o - plane.o);
      const double margin = plane.margin_coef * (rp.cwiseAbs().sum() + half.cwiseAbs().sum());
      out_of_pyramid = plane.m.dot(rp) + plane.m.cwiseAbs().dot(half) < -margin;
    }
    if (out_of_pyramid) continue;
    for (uint64_t bits = live; bits != 0; bits &= bits - 1) {
      const auto fan = size_t(std::countr_zero(bits));
      ++ws.stats.fan_tests;
      if (box_outside(r, half, extent, fan)) live &= ~(uint64_t(1) << fan);
    }
    if (live == 0) continue;
    if (node.count == 0) {
      ws.fan_stack.push_back({node.index, live});
      ws.fan_stack.push_back({at + 1, live});
      continue;
    }
    for (uint32_t i = node.index; i < node.index + node.count; ++i) {
      const uint32_t t = order_[i];
      if (ws.tri_stamp[t] == ws.stamp) continue;  // already kept by another fan
      bool culled = false;
      for (const auto& plane : pyramid) {
        bool all = true;
        for (int c = 0; c < 3 && all; ++c) all = outside_plane(plane, positions_[triangles_[t][c]]);
        if (all) {
          culled = true;
          break;
        }
      }
      if (culled) continue;
      for (uint64_t bits = live; bits != 0; bits &= bits - 1)
        if (!triangle_outside(t, size_t(std::countr_zero(bits)))) {
          keep(t);
          break;
        }
    }
  }
}

int OccluderMesh::classify_edge(uint32_t group, const ShadePoint& point, const LightFrame& frame, const Workspace& ws,
                                std::vector<uint32_t>& special) const {
  const std::span<const Workspace::Plane> sides(ws.planes.data(), ws.planes.size() - 1);  // the pyramid's sides
  const uint32_t first = edge_group_start_[group], end = edge_group_start_[group + 1];
  int whole = 0, other = 0, facing[2] = {0, 0};
  for (uint32_t at = first; at < end; ++at) {
    const auto& tri = triangles_[edge_slots_[at] / 3];
    const V3* x[3] = {&positions_[tri[0]], &positions_[tri[1]], &positions_[tri[2]]};
    bool outside = false;
    for (const auto& plane : sides)
      outside = outside || (outside_plane(plane, *x[0]) && outside_plane(plane, *x[1]) && outside_plane(plane, *x[2]));
    if (outside) {  // its image misses the closed light
      ++other;
      continue;
    }
    bool any_front = false, any_back = false;
    for (const V3* v : x) {
      const int d = frame.depth_side(*v);
      any_front = any_front || d > 0;
      any_back = any_back || d < 0;
    }
    if (!any_front) {  // dropped (behind the light or in its plane)
      ++other;
      continue;
    }
    const int side = any_back ? 0 : orient3d_exact(*x[0], *x[1], *x[2], point.p);
    if (side == 0) {  // clipped by the light's plane, or p in its plane (ε-limit cones or no image)
      special.push_back(edge_slots_[at] / 3);
      ++other;
      continue;
    }
    if (whole < 2) facing[whole] = side;
    ++whole;
  }
  if (whole == 0) return 0;  // no whole image on this edge (a special face's image edges are all cut)
  const uint32_t slot = edge_slots_[first];
  const auto& tri = triangles_[slot / 3];
  const V3 &a = positions_[tri[slot % 3]], &b = positions_[tri[(slot % 3 + 1) % 3]];
  for (const auto& plane : sides)
    if (outside_plane(plane, a) && outside_plane(plane, b)) return 0;  // its image misses the closed light
  if (edge_flagged_[group] || other > 0) return 1;
  return facing[0] != facing[1] ? 1 : 0;  // a consistently wound pair: a contour edge iff they face apart
}

void OccluderMesh::find_cone_edges(const ShadePoint& point, const LightFrame& frame, Workspace& ws, bool brute) const {
  ws.cone.clear();
  ws.special_faces.clear();
  auto finish = [&ws] {
    std::sort(ws.cone.begin(), ws.cone.end());
    std::sort(ws.special_faces.begin(), ws.special_faces.end());
    ws.special_faces.erase(std::unique(ws.special_faces.begin(), ws.special_faces.end()), ws.special_faces.end());
  };
  edge_tree();
  if (edge_nodes_.empty()) return;
  if (brute) {
    for (uint32_t g = 0; g < edge_count(); ++g) {
      if (classify_edge(g, point, frame, ws, ws.special_faces) > 0) ws.cone.push_back(g);
    }
    finish();
    return;
  }
  const Workspace::Plane& light_plane = ws.planes.back();
  ws.edge_stack.assign(1, 0);
  while (!ws.edge_stack.empty()) {
    const uint32_t at = ws.edge_stack.back();
    ws.edge_stack.pop_back();
    const EdgeNode& node = edge_nodes_[at];
    ++ws.stats.edge_nodes;
    // The box against the pyramid's sides and the light's plane (the same margins as walk()).
    const V3 half = (node.hi - node.lo) / 2;
    bool outside = false, front = false;
    for (const auto& plane : ws.planes) {
      const V3 r = node.centre - plane.o;
      const double mid = plane.m.dot(r), spread = plane.m.cwiseAbs().dot(half);
      const double margin = plane.margin_coef * (r.cwiseAbs().sum() + half.cwiseAbs().sum());
      if (mid + spread < -margin) {
        outside = true;
        break;
      }
      if (&plane == &light_plane) front = mid - spread > margin;
    }
    if (outside) continue;  // every face outside a side (its image misses the light) or behind the light
    if (front && !node.flagged) {
      // Every face strictly on p's side of the light's plane (whole images), every edge a
      // consistently wound pair: none is a contour edge when every face has p strictly on the
      // same side of its plane. For a face point x (|x − centre| ≤ radius) and unit normal n̂
      // (|n̂ − axis| ≤ spread): n̂·(p − x) = axis·d + (n̂ − axis)·d − n̂·(x − centre), d = p − centre.
      const V3 d = point.p - node.centre;
      const double ad = node.axis.dot(d), dn = d.norm();
      const double bound = node.spread * dn + node.radius + 1e-9 * (dn + node.radius);
      if (ad > bound || ad < -bound) {
        continue;
      }
    }
    if (node.count == 0) {
      ws.edge_stack.push_back(node.index);
      ws.edge_stack.push_back(at + 1);
      continue;
    }
    for (uint32_t i = node.index; i < node.index + node.count; ++i) {
      const uint32_t g = edge_order_[i];
      if (classify_edge(g, point, frame, ws, ws.special_faces) > 0) ws.cone.push_back(g);
    }
  }
  finish();
}

void OccluderMesh::cone_edges(std::span<const V3> light, const ShadePoint& point, std::vector<uint32_t>& edges,
                              std::vector<uint32_t>& special, Workspace& ws) const {
  LightFrame frame;
  edges.clear();
  special.clear();
  if (!prepare(light, point, ws, frame)) return;
  find_cone_edges(point, frame, ws, false);
  edges = ws.cone;
  special = ws.special_faces;
}

void OccluderMesh::cone_edges_brute_force(std::span<const V3> light, const ShadePoint& point,
                                          std::vector<uint32_t>& edges, std::vector<uint32_t>& special,
                                          Workspace& ws) const {
  LightFrame frame;
  edges.clear();
  special.clear();
  if (!prepare(light, point, ws, frame)) return;
  find_cone_edges(point, frame, ws, true);
  edges = ws.cone;
  special = ws.special_faces;
}

} // namespace prt::bake
