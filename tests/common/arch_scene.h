// A generated architectural scene with the defects of real CAD / architectural exports, for the
// geometry tests and the real-asset benchmark (bench/bench_real_assets.cpp): parts that touch
// without sharing vertices (T-junctions), coplanar overlapping faces, duplicated faces and a
// double-sided panel made of two coincident sheets. Deterministic: the same cells_per_metre gives
// the same mesh, bit for bit.
//
// Layout (metres, +Y up, every part an axis-aligned lattice box or sheet):
//   floor    slab [0, 8] × [−0.2, 0] × [0, 8]; its top face is one quad per room quadrant (2×2
//            quads, 2 triangles each), so everything standing on it has its feet INSIDE a floor
//            face or on a floor edge, never at a floor vertex except at lattice-aligned corners.
//   walls    boxes of thickness 0.2 and height 3 subdivided into cells of ~1/cells_per_metre:
//            wall_south z ∈ [0, 0.2] and wall_north z ∈ [7.8, 8] run the full width; wall_west
//            and wall_east (x ∈ [0, 0.2], [7.8, 8], z ∈ [0.2, 7.8]) butt into them (their end
//            faces are coplanar with, and lie inside, the long walls' inner faces); wall_mid
//            (z ∈ [3.9, 4.1]) runs between them with a door opening x ∈ [2, 3] below y = 2.1
//            (pieces wall_mid_a, wall_mid_b and the lintel, whose end faces lie inside theirs);
//            wall_cross (x ∈ [3.9, 4.1], z ∈ [0.2, 3.9]) butts into wall_south and wall_mid.
//            Every wall's bottom face is coplanar with the floor's top face and overlaps it.
//   cabinet  box [1 + ½ cell, +0.8] × [0, 0.9] × [0.2, 0.7] against wall_south: its corner
//            `junction_corner` = (1 + ½ cell, 0, 0.2) lies inside a floor face AND on the interior
//            of an edge of wall_south's bottom row (no vertex of either there): two T-junctions at
//            once; its back face is coplanar with wall_south's inner face.
//   table    box [5.3, 6.5] × [0, 0.75] × [5.1, 5.9] resting on the floor; its top face's
//            triangles appear twice (`duplicated_faces`: the same three vertex indices again).
//   rug      one-sided sheet y = 0, [4.6, 7] × [4.5, 7.2], facing +Y: coplanar with the floor
//            and overlapping it (and the table's feet stand on it).
//   panel    a double-sided partition x ∈ [5, 7], y ∈ [0, 1.8], z = 2: `panel_front` faces −Z,
//            `panel_back` faces +Z, each with its own vertices at the same positions (so the
//            welded angle-weighted normal sums cancel there).
// Triangles grow as ~640·d² for d = cells_per_metre (d = 2: 2,758 triangles / 1,426 vertices;
// d = 4: 9,778; d = 13, the benchmark's size: 102,354 triangles / 51,206 vertices).
#pragma once

#include <bake/mesh/mesh.h>

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace prt::testing {

struct ArchPart {
  std::string name;
  uint32_t first_vertex = 0, vertex_count = 0;
  uint32_t first_triangle = 0, triangle_count = 0;
  bool has_vertex(uint32_t v) const { return v >= first_vertex && v < first_vertex + vertex_count; }
  bool has_triangle(uint32_t t) const { return t >= first_triangle && t < first_triangle + triangle_count; }
};

struct ArchScene {
  bake::Mesh mesh;
  std::vector<ArchPart> parts;                            // in vertex / triangle order, disjoint
  uint32_t junction_corner = 0;                           // the cabinet corner described above
  std::vector<std::array<uint32_t, 2>> duplicated_faces;  // (triangle, its later copy)
  const ArchPart& part(const std::string& name) const {
    for (const auto& p : parts)
      if (p.name == name) return p;
    throw std::out_of_range("architectural scene: no part " + name);
  }
  size_t part_of_vertex(uint32_t v) const {
    for (size_t i = 0; i < parts.size(); ++i)
      if (parts[i].has_vertex(v)) return i;
    throw std::out_of_range("architectural scene: vertex out of range");
  }
};

namespace detail {

// [lo, hi] cut into max(1, round((hi − lo)·d)) cells; the ends are exactly float(lo), float(hi),
// so parts that meet at a plane share its coordinate bit for bit.
inline std::vector<float> lattice(double lo, double hi, double d) {
  const int n = std::max(1, int(std::lround((hi - lo) * d)));
  std::vector<float> x(size_t(n) + 1);
  for (int i = 0; i <= n; ++i) x[size_t(i)] = i == n ? float(hi) : float(lo + (hi - lo) * i / n);
  return x;
}

class ArchBuilder {
public:
  using Lattice = std::array<std::vector<float>, 3>;

  // A closed box over the lattice L (outward winding), one vertex per surface lattice point.
  void box(const std::string& name, const Lattice& L) {
    begin(name);
    std::map<std::array<size_t, 3>, uint32_t> ids;
    for (int axis = 0; axis < 3; ++axis)
      for (int side = 0; side < 2; ++side) face(L, axis, side ? L[size_t(axis)].size() - 1 : 0, side == 1, ids);
    end();
  }
  // A one-sided sheet: the lattice has one coordinate along `axis`; facing +axis if `up`.
  void sheet(const std::string& name, const Lattice& L, int axis, bool up) {
    begin(name);
    std::map<std::array<size_t, 3>, uint32_t> ids;
    face(L, axis, 0, up, ids);
    end();
  }
  // A part made of copies (same vertex indices) of the triangles in [first, first + count)
  // whose three corners satisfy `keep`.
  template <class Keep>
  void duplicate_triangles(const std::string& name, uint32_t first, uint32_t count, Keep keep) {
    begin(name);
    for (uint32_t t = first; t < first + count; ++t) {
      const auto tri = triangles_[t];
      if (!keep(positions_[tri[0]]) || !keep(positions_[tri[1]]) || !keep(positions_[tri[2]])) continue;
      duplicated_.push_back({t, uint32_t(triangles_.size())});
      triangles_.push_back(tri);
    }
    end();
  }
  uint32_t vertex_at(const Eigen::Vector3f& q) const {
    for (uint32_t v = 0; v < positions_.size(); ++v)
      if (positions_[v] == q) return v;
    throw std::logic_error("architectural scene: no vertex at the requested position");
  }
  const std::vector<ArchPart>& parts() const { return parts_; }

  ArchScene finish(std::string name) {
    ArchScene s;
    s.mesh = bake::make_mesh(std::move(positions_), std::move(triangles_), std::move(name));
    s.parts = std::move(parts_);
    s.duplicated_faces = std::move(duplicated_);
    return s;
  }

private:
  void begin(const std::string& name) {
    parts_.push_back({name, uint32_t(positions_.size()), 0, uint32_t(triangles_.size()), 0});
  }
  void end() {
    parts_.back().vertex_count = uint32_t(positions_.size()) - parts_.back().first_vertex;
    parts_.back().triangle_count = uint32_t(triangles_.size()) - parts_.back().first_triangle;
  }
  // The quads of the lattice face where coordinate `axis` has index `fixed`; u, v are the next two
  // axes cyclically, so (u-step) × (v-step) points along +axis and the winding below faces +axis
  // when `up`, −axis otherwise.
  void face(const Lattice& L, int axis, size_t fixed, bool up, std::map<std::array<size_t, 3>, uint32_t>& ids) {
    const size_t u = size_t(axis + 1) % 3, v = size_t(axis + 2) % 3;
    auto id = [&](size_t i, size_t j) {
      std::array<size_t, 3> k{};
      k[size_t(axis)] = fixed;
      k[u] = i;
      k[v] = j;
      const auto [it, added] = ids.try_emplace(k, uint32_t(positions_.size()));
      if (added) positions_.emplace_back(L[0][k[0]], L[1][k[1]], L[2][k[2]]);
      return it->second;
    };
    for (size_t i = 0; i + 1 < L[u].size(); ++i)
      for (size_t j = 0; j + 1 < L[v].size(); ++j) {
        const uint32_t c0 = id(i, j), c1 = id(i + 1, j), c2 = id(i + 1, j + 1), c3 = id(i, j + 1);
        if (up) {
          triangles_.push_back({c0, c1, c2});
          triangles_.push_back({c0, c2, c3});
        } else {
          triangles_.push_back({c0, c2, c1});
          triangles_.push_back({c0, c3, c2});
        }
      }
  }

  std::vector<Eigen::Vector3f> positions_;
  std::vector<std::array<uint32_t, 3>> triangles_;
  std::vector<ArchPart> parts_;
  std::vector<std::array<uint32_t, 2>> duplicated_;
};

} // namespace detail

// cells_per_metre ≥ 1 sets the wall / furniture subdivision (see the file comment for sizes).
inline ArchScene architectural_scene(int cells_per_metre) {
  if (cells_per_metre < 1) throw std::invalid_argument("architectural_scene: cells_per_metre must be >= 1");
  const double d = cells_per_metre;
  using detail::lattice;
  detail::ArchBuilder b;
  const double t = 0.2, H = 3.0, W = 8.0, mid = 4.0, door_lo = 2.0, door_hi = 3.0, door_top = 2.1;
  auto box = [&](const std::string& name, double x0, double x1, double y0, double y1, double z0, double z1) {
    b.box(name, {lattice(x0, x1, d), lattice(y0, y1, d), lattice(z0, z1, d)});
  };
  // The slab: its top face is 2×2 quads (one per room quadrant) whatever d is.
  b.box("floor", {lattice(0, W, 2 / W), lattice(-t, 0, 1 / t), lattice(0, W, 2 / W)});
  box("wall_south", 0, W, 0, H, 0, t);
  box("wall_north", 0, W, 0, H, W - t, W);
  box("wall_west", 0, t, 0, H, t, W - t);
  box("wall_east", W - t, W, 0, H, t, W - t);
  box("wall_mid_a", t, door_lo, 0, H, mid - t / 2, mid + t / 2);
  box("wall_mid_b", door_hi, W - t, 0, H, mid - t / 2, mid + t / 2);
  box("lintel", door_lo, door_hi, door_top, H, mid - t / 2, mid + t / 2);
  box("wall_cross", mid - t / 2, mid + t / 2, 0, H, t, mid - t / 2);
  const double corner_x = 1.0 + 0.5 / d;  // half a wall cell: between wall_south's lattice points
  box("cabinet", corner_x, corner_x + 0.8, 0, 0.9, t, t + 0.5);
  box("table", 5.3, 6.5, 0, 0.75, 5.1, 5.9);
  {
    // The table's top face: its triangles are the ones whose three corners have y = 0.75.
    const ArchPart& table = b.parts().back();
    const uint32_t first = table.first_triangle, count = table.triangle_count;
    b.duplicate_triangles("table_top_copy", first, count, [](const Eigen::Vector3f& p) { return p.y() == 0.75f; });
  }
  b.sheet("rug", {lattice(4.6, 7.0, d), {0.0f}, lattice(4.5, 7.2, d)}, 1, true);
  const detail::ArchBuilder::Lattice panel = {lattice(5, 7, d), lattice(0, 1.8, d), {2.0f}};
  b.sheet("panel_front", panel, 2, false);
  b.sheet("panel_back", panel, 2, true);
  const uint32_t corner = b.vertex_at({float(corner_x), 0.0f, float(t)});
  ArchScene s = b.finish("architectural scene, " + std::to_string(cells_per_metre) + " cells/m");
  s.junction_corner = corner;
  return s;
}

} // namespace prt::testing
