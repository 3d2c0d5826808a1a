// mesh.cpp — in-memory meshes, normals and welded topology (contracts in bake/mesh/mesh.h).
#include <bake/core/error.h>
#include <bake/mesh/mesh.h>
#include <bake/mesh/predicates.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <sstream>
#include <tuple>
#include <unordered_map>
#include <utility>

namespace prt::bake {
namespace {

// Bitwise key of a position with −0 mapped to +0 (x + 0.0f does exactly that for every finite x).
using PositionKey = std::array<uint32_t, 3>;

PositionKey position_key(const Eigen::Vector3f& p) {
  return {std::bit_cast<uint32_t>(p.x() + 0.0f), std::bit_cast<uint32_t>(p.y() + 0.0f),
          std::bit_cast<uint32_t>(p.z() + 0.0f)};
}

struct PositionKeyHash {
  size_t operator()(const PositionKey& k) const noexcept {
    uint64_t h = 0x9E3779B97F4A7C15ull;
    for (uint32_t c : k) h = (h ^ c) * 0xBF58476D1CE4E5B9ull, h ^= h >> 31;
    return static_cast<size_t>(h);
  }
};

// Welded id per vertex, ids in order of first appearance; returns the number of welded positions.
uint32_t weld_positions(std::span<const Eigen::Vector3f> positions, std::vector<uint32_t>& weld) {
  std::unordered_map<PositionKey, uint32_t, PositionKeyHash> ids;
  ids.reserve(positions.size());
  weld.resize(positions.size());
  for (size_t v = 0; v < positions.size(); ++v) {
    const auto [it, inserted] = ids.try_emplace(position_key(positions[v]), static_cast<uint32_t>(ids.size()));
    weld[v] = it->second;
  }
  return static_cast<uint32_t>(ids.size());
}

// A triangle's angle-weighted contributions α_k n̂ to the normals at its corners k, in double, or
// nullopt for a zero-area (or non-finite) triangle, which contributes nothing.
std::optional<std::array<Eigen::Vector3d, 3>> corner_contributions(std::span<const Eigen::Vector3f> positions,
                                                                   const std::array<uint32_t, 3>& t) {
  for (uint32_t i : t) PRT_CHECK_OP(i, <, positions.size());
  const Eigen::Vector3d p[3] = {positions[t[0]].cast<double>(), positions[t[1]].cast<double>(),
                                positions[t[2]].cast<double>()};
  const Eigen::Vector3d n = (p[1] - p[0]).cross(p[2] - p[0]);
  const double len = n.norm();
  if (!(len > 0.0) || !std::isfinite(len)) return std::nullopt;
  const Eigen::Vector3d unit = n / len;
  std::array<Eigen::Vector3d, 3> c;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d e1 = p[(k + 1) % 3] - p[k], e2 = p[(k + 2) % 3] - p[k];
    // atan2(|e1×e2|, e1·e2) is accurate for needles, where acos of a normalised dot is not.
    c[size_t(k)] = std::atan2(e1.cross(e2).norm(), e1.dot(e2)) * unit;
  }
  return c;
}

Eigen::Vector3f unit_or_up(const Eigen::Vector3d& s) {
  const double len = s.norm();
  if (!(len > 0.0) || !std::isfinite(len)) return Eigen::Vector3f::UnitY();
  return (s / len).cast<float>();
}

} // namespace

Eigen::Vector3d frame_origin(const Eigen::AlignedBox3d& world_bounds) {
  PRT_CHECK(!world_bounds.isEmpty());
  const Eigen::Vector3d lo = world_bounds.min(), hi = world_bounds.max();
  const double reach = lo.cwiseAbs().cwiseMax(hi.cwiseAbs()).maxCoeff();
  const double extent = (hi - lo).maxCoeff();
  if (reach <= kNearOrigin * extent) return Eigen::Vector3d::Zero();
  return lo + (hi - lo) / 2;  // the centre, without overflow
}

std::vector<Eigen::Vector3f> offsets_from(std::span<const Eigen::Vector3d> world, const Eigen::Vector3d& origin,
                                          const std::string& source) {
  std::vector<Eigen::Vector3f> out(world.size());
  for (size_t v = 0; v < world.size(); ++v) {
    out[v] = (world[v] - origin).cast<float>();
    if (!out[v].allFinite())
      throw InputError(source, "vertex " + std::to_string(v) + " is out of float range relative to the mesh origin");
  }
  return out;
}

std::vector<Eigen::Vector3f> angle_weighted_normals(std::span<const Eigen::Vector3f> positions,
                                                    std::span<const std::array<uint32_t, 3>> triangles) {
  std::vector<Eigen::Vector3d> sum(positions.size(), Eigen::Vector3d::Zero());
  for (const auto& t : triangles)
    if (const auto c = corner_contributions(positions, t))
      for (int k = 0; k < 3; ++k) sum[t[k]] += (*c)[size_t(k)];
  std::vector<Eigen::Vector3f> normals(positions.size());
  for (size_t v = 0; v < positions.size(); ++v) normals[v] = unit_or_up(sum[v]);
  return normals;
}

namespace {

// Union-find over triangle corners (index 3t + k), by size, with path halving.
struct CornerSets {
  std::vector<uint32_t> parent, size;
  explicit CornerSets(size_t n) : parent(n), size(n, 1) { std::iota(parent.begin(), parent.end(), 0u); }
  uint32_t find(uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void join(uint32_t a, uint32_t b) {
    a = find(a), b = find(b);
    if (a == b) return;
    if (size[a] < size[b]) std::swap(a, b);
    parent[b] = a;
    size[a] += size[b];
  }
};

// True when triangles t = (a, b, c) and u share the edge {a, b} folded flat onto each other: u's
// third corner d lies exactly in t's plane on the same side of the edge as c (coincident sheets).
bool folded(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, const Eigen::Vector3d& d) {
  if (orient3d_exact(a, b, c, d) != 0) return false;
  const Eigen::Vector3d e = b - a;
  return e.cross(c - a).dot(e.cross(d - a)) > 0;
}

} // namespace

std::vector<Eigen::Vector3f> welded_angle_weighted_normals(std::span<const Eigen::Vector3f> positions,
                                                           std::span<const std::array<uint32_t, 3>> triangles) {
  std::vector<uint32_t> weld;
  const uint32_t n_welded = weld_positions(positions, weld);
  const size_t T = triangles.size();
  auto pos = [&](uint32_t v) { return Eigen::Vector3d(positions[v].cast<double>()); };
  std::vector<std::optional<std::array<Eigen::Vector3d, 3>>> contribution(T);
  for (size_t t = 0; t < T; ++t) contribution[t] = corner_contributions(positions, triangles[t]);
  // Sheets: the corners at one welded position are joined when they are corners of the same
  // vertex, or when their triangles share a welded edge that has exactly these two triangles,
  // traverses it in opposite directions and is not folded flat (bake/mesh/mesh.h NORMALS).
  CornerSets sets(3 * T);
  std::vector<uint32_t> first_corner(positions.size(), UINT32_MAX);
  struct EdgeUse {
    uint32_t lo, hi;   // welded ids, lo < hi
    uint32_t t, k;     // triangle, and its corner k at the edge's start (k → k+1)
  };
  std::vector<EdgeUse> uses;
  uses.reserve(3 * T);
  for (uint32_t t = 0; t < T; ++t) {
    if (!contribution[t]) continue;
    for (uint32_t k = 0; k < 3; ++k) {
      const uint32_t v = triangles[t][k];
      if (first_corner[v] == UINT32_MAX) first_corner[v] = 3 * t + k;
      else sets.join(first_corner[v], 3 * t + k);
      const uint32_t wa = weld[v], wb = weld[triangles[t][(k + 1) % 3]];
      if (wa != wb) uses.push_back({std::min(wa, wb), std::max(wa, wb), t, k});
    }
  }
  std::sort(uses.begin(), uses.end(), [](const EdgeUse& x, const EdgeUse& y) {
    return std::tie(x.lo, x.hi, x.t, x.k) < std::tie(y.lo, y.hi, y.t, y.k);
  });
  for (size_t i = 0; i < uses.size();) {
    size_t j = i;
    while (j < uses.size() && uses[j].lo == uses[i].lo && uses[j].hi == uses[i].hi) ++j;
    if (j - i == 2) {
      const EdgeUse &x = uses[i], &y = uses[i + 1];
      const auto& tx = triangles[x.t];
      const auto& ty = triangles[y.t];
      const uint32_t xa = tx[x.k], xb = tx[(x.k + 1) % 3], xc = tx[(x.k + 2) % 3];
      const uint32_t ya = ty[y.k], yb = ty[(y.k + 1) % 3], yc = ty[(y.k + 2) % 3];
      // Opposite directions: y runs from x's end to x's start.
      if (weld[ya] == weld[xb] && weld[yb] == weld[xa] && !folded(pos(xa), pos(xb), pos(xc), pos(yc))) {
        sets.join(3 * x.t + x.k, 3 * y.t + (y.k + 1) % 3);  // the corners at x's start
        sets.join(3 * x.t + (x.k + 1) % 3, 3 * y.t + y.k);  // the corners at x's end
      }
    }
    i = j;
  }
  // Angle-weighted sums per sheet (the root of its corner set) and per welded position (the
  // fallback for a vertex with no corner of non-zero area).
  std::vector<Eigen::Vector3d> sheet(3 * T, Eigen::Vector3d::Zero()), welded(n_welded, Eigen::Vector3d::Zero());
  for (uint32_t t = 0; t < T; ++t) {
    if (!contribution[t]) continue;
    for (uint32_t k = 0; k < 3; ++k) {
      sheet[sets.find(3 * t + k)] += (*contribution[t])[k];
      welded[weld[triangles[t][k]]] += (*contribution[t])[k];
    }
  }
  std::vector<Eigen::Vector3f> normals(positions.size());
  for (size_t v = 0; v < positions.size(); ++v)
    normals[v] = unit_or_up(first_corner[v] == UINT32_MAX ? welded[weld[v]] : sheet[sets.find(first_corner[v])]);
  return normals;
}

Mesh make_mesh(std::vector<Eigen::Vector3f> positions, std::vector<std::array<uint32_t, 3>> triangles,
               std::string name, std::vector<Eigen::Vector3f> normals, std::vector<UvSet> uv_sets) {
  if (positions.size() >= std::numeric_limits<uint32_t>::max())
    throw InputError(name, "too many vertices (" + std::to_string(positions.size()) + ") for 32-bit indices");
  if (triangles.empty()) throw InputError(name, "mesh has no triangles");
  for (size_t v = 0; v < positions.size(); ++v) {
    if (!positions[v].allFinite()) {
      std::ostringstream os;
      os << "vertex " << v << " has a non-finite coordinate (" << positions[v].transpose() << ")";
      throw InputError(name, os.str());
    }
  }
  for (size_t t = 0; t < triangles.size(); ++t) {
    for (uint32_t i : triangles[t]) {
      if (i >= positions.size())
        throw InputError(name, "triangle " + std::to_string(t) + " references vertex " + std::to_string(i) +
                                   " but there are " + std::to_string(positions.size()) + " vertices");
    }
  }
  Mesh mesh;
  if (!normals.empty()) {
    if (normals.size() != positions.size())
      throw InputError(name, std::to_string(normals.size()) + " normals for " + std::to_string(positions.size()) +
                                 " vertices");
    for (size_t v = 0; v < normals.size(); ++v) {
      const float len = normals[v].norm();
      if (!std::isfinite(len) || !(len > 0.0f))
        throw InputError(name, "normal " + std::to_string(v) + " is zero or not finite");
      normals[v] /= len;
    }
    mesh.normals = std::move(normals);
    mesh.normal_source = Mesh::NormalSource::File;
  } else {
    mesh.normals = welded_angle_weighted_normals(positions, triangles);
    mesh.normal_source = Mesh::NormalSource::AngleWeighted;
  }
  for (const UvSet& set : uv_sets) {
    if (set.corners.size() != 3 * triangles.size())
      throw InputError(name, "texture coordinate set '" + set.name + "' has " + std::to_string(set.corners.size()) +
                                 " corners for " + std::to_string(triangles.size()) + " triangles (needs 3 per triangle)");
    for (size_t c = 0; c < set.corners.size(); ++c)
      if (!set.corners[c].allFinite())
        throw InputError(name, "texture coordinate set '" + set.name + "': corner " + std::to_string(c) + " is not finite");
  }
  mesh.uv_sets = std::move(uv_sets);
  mesh.source_position.resize(positions.size());
  std::iota(mesh.source_position.begin(), mesh.source_position.end(), 0u);
  mesh.file_positions = positions.size();
  mesh.file_faces = triangles.size();
  mesh.positions = std::move(positions);
  mesh.triangles = std::move(triangles);
  mesh.source = std::move(name);
  return mesh;
}

Mesh merge_meshes(std::span<const Mesh> parts, std::string name) {
  PRT_CHECK(!parts.empty());
  Mesh out;
  out.source = std::move(name);
  out.normal_source = Mesh::NormalSource::File;
  size_t n_vertices = 0, n_triangles = 0;
  for (const Mesh& m : parts) {
    PRT_CHECK_OP(m.normals.size(), ==, m.positions.size());
    PRT_CHECK_OP(m.source_position.size(), ==, m.positions.size());
    n_vertices += m.positions.size();
    n_triangles += m.triangles.size();
  }
  PRT_CHECK_OP(n_vertices, <, size_t{std::numeric_limits<uint32_t>::max()});
  // One frame for all parts: theirs if they share it, else the rule over their world bounds.
  const bool same_origin = std::all_of(parts.begin(), parts.end(), [&](const Mesh& m) { return m.origin == parts[0].origin; });
  out.origin = parts[0].origin;
  if (!same_origin) {
    Eigen::AlignedBox3d bounds;
    for (const Mesh& m : parts)
      for (size_t v = 0; v < m.positions.size(); ++v) bounds.extend(m.world_position(v));
    out.origin = bounds.isEmpty() ? Eigen::Vector3d::Zero() : frame_origin(bounds);
  }
  out.positions.reserve(n_vertices);
  out.normals.reserve(n_vertices);
  out.source_position.reserve(n_vertices);
  out.triangles.reserve(n_triangles);
  for (const Mesh& m : parts) {
    const auto vertex_offset = static_cast<uint32_t>(out.positions.size());
    const size_t position_offset = out.file_positions;
    PRT_CHECK_OP(position_offset + m.file_positions, <, size_t{std::numeric_limits<uint32_t>::max()});
    if (m.origin == out.origin) {
      out.positions.insert(out.positions.end(), m.positions.begin(), m.positions.end());
    } else {
      std::vector<Eigen::Vector3d> world(m.positions.size());
      for (size_t v = 0; v < world.size(); ++v) world[v] = m.world_position(v);
      const auto offsets = offsets_from(world, out.origin, out.source);
      out.positions.insert(out.positions.end(), offsets.begin(), offsets.end());
    }
    out.normals.insert(out.normals.end(), m.normals.begin(), m.normals.end());
    for (uint32_t s : m.source_position) out.source_position.push_back(s + static_cast<uint32_t>(position_offset));
    for (const auto& t : m.triangles)
      out.triangles.push_back({t[0] + vertex_offset, t[1] + vertex_offset, t[2] + vertex_offset});
    if (m.normal_source != Mesh::NormalSource::File) out.normal_source = Mesh::NormalSource::AngleWeighted;
    out.file_positions += m.file_positions;
    out.file_faces += m.file_faces;
    out.warnings.insert(out.warnings.end(), m.warnings.begin(), m.warnings.end());
  }
  // Texture-coordinate sets that every part has (by name, in parts[0]'s order): a set must cover
  // every triangle (bake/mesh/mesh.h UvSet).
  for (const UvSet& first : parts[0].uv_sets) {
    auto set_of = [&](const Mesh& m) {
      return std::find_if(m.uv_sets.begin(), m.uv_sets.end(), [&](const UvSet& s) { return s.name == first.name; });
    };
    if (!std::all_of(parts.begin(), parts.end(), [&](const Mesh& m) { return set_of(m) != m.uv_sets.end(); })) continue;
    UvSet& merged = out.uv_sets.emplace_back();
    merged.name = first.name;
    merged.corners.reserve(3 * n_triangles);
    for (const Mesh& m : parts) {
      const UvSet& set = *set_of(m);
      PRT_CHECK_OP(set.corners.size(), ==, 3 * m.triangles.size());
      merged.corners.insert(merged.corners.end(), set.corners.begin(), set.corners.end());
    }
  }
  return out;
}

std::span<const uint32_t> Topology::ring(uint32_t welded) const {
  PRT_CHECK_OP(size_t{welded} + 1, <, ring_offsets.size());
  return std::span<const uint32_t>(ring_faces).subspan(ring_offsets[welded], ring_offsets[welded + 1] - ring_offsets[welded]);
}

std::span<const uint32_t> Topology::faces_of_edge(uint32_t edge) const {
  PRT_CHECK_OP(size_t{edge} + 1, <, edge_face_offsets.size());
  return std::span<const uint32_t>(edge_faces)
      .subspan(edge_face_offsets[edge], edge_face_offsets[edge + 1] - edge_face_offsets[edge]);
}

std::optional<uint32_t> Topology::find_edge(uint32_t a, uint32_t b) const {
  const std::array<uint32_t, 2> key = {std::min(a, b), std::max(a, b)};
  const auto it = std::lower_bound(edges.begin(), edges.end(), key);
  if (it == edges.end() || *it != key) return std::nullopt;
  return static_cast<uint32_t>(it - edges.begin());
}

Topology build_topology(const Mesh& mesh) {
  Topology topo;
  const uint32_t n_welded = weld_positions(mesh.positions, topo.weld);
  topo.welded_positions.resize(n_welded);
  for (size_t v = mesh.positions.size(); v-- > 0;) topo.welded_positions[topo.weld[v]] = mesh.positions[v];

  // Welded corners per triangle, each distinct corner once.
  const auto n_triangles = static_cast<uint32_t>(mesh.triangles.size());
  std::vector<std::array<uint32_t, 3>> corners(n_triangles);
  for (uint32_t t = 0; t < n_triangles; ++t) {
    for (int k = 0; k < 3; ++k) {
      PRT_CHECK_OP(mesh.triangles[t][k], <, mesh.positions.size());
      corners[t][k] = topo.weld[mesh.triangles[t][k]];
    }
  }

  // Rings: counting sort by welded corner; triangles visited in order, so each ring ascends.
  topo.ring_offsets.assign(size_t{n_welded} + 1, 0);
  auto for_distinct = [&](const std::array<uint32_t, 3>& c, auto&& f) {
    f(c[0]);
    if (c[1] != c[0]) f(c[1]);
    if (c[2] != c[0] && c[2] != c[1]) f(c[2]);
  };
  for (const auto& c : corners) for_distinct(c, [&](uint32_t w) { ++topo.ring_offsets[w + 1]; });
  std::partial_sum(topo.ring_offsets.begin(), topo.ring_offsets.end(), topo.ring_offsets.begin());
  topo.ring_faces.resize(topo.ring_offsets.back());
  {
    std::vector<uint32_t> cursor(topo.ring_offsets.begin(), topo.ring_offsets.end() - 1);
    for (uint32_t t = 0; t < n_triangles; ++t) for_distinct(corners[t], [&](uint32_t w) { topo.ring_faces[cursor[w]++] = t; });
  }

  // Edges: (a, b, face) for each distinct undirected side, sorted; no orientation is used.
  struct EdgeFace {
    uint32_t a, b, face;
    auto operator<=>(const EdgeFace&) const = default;
  };
  std::vector<EdgeFace> sides;
  sides.reserve(size_t{n_triangles} * 3);
  for (uint32_t t = 0; t < n_triangles; ++t) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t u = corners[t][k], w = corners[t][(k + 1) % 3];
      if (u != w) sides.push_back({std::min(u, w), std::max(u, w), t});
    }
  }
  std::sort(sides.begin(), sides.end());
  sides.erase(std::unique(sides.begin(), sides.end()), sides.end());  // (a, a, b) lists its face once
  topo.edge_face_offsets.push_back(0);
  topo.edge_faces.reserve(sides.size());
  for (size_t i = 0; i < sides.size(); ++i) {
    if (i == 0 || sides[i].a != sides[i - 1].a || sides[i].b != sides[i - 1].b) {
      if (i != 0) topo.edge_face_offsets.push_back(static_cast<uint32_t>(topo.edge_faces.size()));
      topo.edges.push_back({sides[i].a, sides[i].b});
    }
    topo.edge_faces.push_back(sides[i].face);
  }
  if (!sides.empty()) topo.edge_face_offsets.push_back(static_cast<uint32_t>(topo.edge_faces.size()));
  return topo;
}

size_t WindingFacts::inward_components() const {
  return size_t(std::count_if(closed.begin(), closed.end(), [](const ClosedComponent& c) { return c.inward; }));
}

size_t WindingFacts::inward_triangles() const {
  size_t n = 0;
  for (const ClosedComponent& c : closed) n += c.inward ? c.triangles : 0;
  return n;
}

WindingFacts winding_facts(const Mesh& mesh, const Topology& topo) {
  const auto n_triangles = static_cast<uint32_t>(mesh.triangles.size());
  PRT_CHECK_OP(topo.weld.size(), ==, mesh.positions.size());
  auto welded = [&](uint32_t t) {
    const auto& v = mesh.triangles[t];
    return std::array<uint32_t, 3>{topo.weld[v[0]], topo.weld[v[1]], topo.weld[v[2]]};
  };

  // Components: union-find over triangles joined by each edge's faces.
  std::vector<uint32_t> parent(n_triangles);
  std::iota(parent.begin(), parent.end(), 0u);
  auto root = [&](uint32_t t) {
    while (parent[t] != t) t = parent[t] = parent[parent[t]];
    return t;
  };
  for (uint32_t e = 0; e < topo.edges.size(); ++e) {
    const auto faces = topo.faces_of_edge(e);
    for (size_t i = 1; i < faces.size(); ++i) {
      const uint32_t a = root(faces[0]), b = root(faces[i]);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  }
  constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();
  std::vector<uint32_t> component(n_triangles), index_of_root(n_triangles, kNone);
  WindingFacts facts;
  struct Sums {
    bool closed = true;
    double volume = 0, magnitude = 0;
    Eigen::Vector3d origin;
  };
  std::vector<Sums> sums;
  for (uint32_t t = 0; t < n_triangles; ++t) {
    uint32_t& c = index_of_root[root(t)];
    if (c == kNone) {
      c = static_cast<uint32_t>(facts.closed.size());
      facts.closed.push_back({t, 0, 0, false});
      sums.push_back({true, 0, 0, mesh.positions[mesh.triangles[t][0]].cast<double>()});
    }
    component[t] = c;
    ClosedComponent& cc = facts.closed[c];
    Sums& s = sums[c];
    ++cc.triangles;
    const auto w = welded(t);
    if (w[0] == w[1] || w[1] == w[2] || w[2] == w[0]) s.closed = false;
    const auto& v = mesh.triangles[t];
    const Eigen::Vector3d a = mesh.positions[v[0]].cast<double>() - s.origin,
                          b = mesh.positions[v[1]].cast<double>() - s.origin,
                          d = mesh.positions[v[2]].cast<double>() - s.origin;
    const double term = a.dot(b.cross(d));
    s.volume += term;
    s.magnitude += std::abs(term);
  }

  // Closed: every edge has two faces, traversing it in opposite directions.
  auto forward = [&](uint32_t t, uint32_t a, uint32_t b) {  // does t traverse a -> b?
    const auto w = welded(t);
    for (int k = 0; k < 3; ++k)
      if (w[k] == a && w[(k + 1) % 3] == b) return true;
    return false;
  };
  for (uint32_t e = 0; e < topo.edges.size(); ++e) {
    const auto faces = topo.faces_of_edge(e);
    Sums& s = sums[component[faces[0]]];
    const auto [a, b] = topo.edges[e];
    if (faces.size() != 2 || forward(faces[0], a, b) == forward(faces[1], a, b)) s.closed = false;
  }

  facts.components = facts.closed.size();
  std::vector<ClosedComponent> closed;
  for (size_t c = 0; c < facts.closed.size(); ++c) {
    if (!sums[c].closed) continue;
    ClosedComponent cc = facts.closed[c];
    cc.signed_volume = sums[c].volume / 6;
    cc.inward = sums[c].volume < -1e-9 * sums[c].magnitude;
    closed.push_back(cc);
  }
  facts.closed = std::move(closed);
  return facts;
}

} // namespace prt::bake
