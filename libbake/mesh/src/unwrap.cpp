// unwrap.cpp — a generated lightmap UV set: charts, LSCM, packing (bake/mesh/unwrap.h).
#include <bake/mesh/unwrap.h>
#include <bake/core/error.h>

#include <Eigen/Geometry>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <queue>
#include <span>
#include <unordered_map>
#include <utility>
#include <vector>

namespace prt::bake {
namespace {

constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();
constexpr double kMargin = 1.0 / 64;       // m (header): texels between a chart and its cells' border
constexpr double kPlanarCos = 1 - 1e-9;    // a chart is planar when every n·n_seed is at least this
constexpr int kBisections = 40;            // density steps: 2^-40 of the first bracket
constexpr double kMaxChartStretch = 2;     // a flattened chart with a triangle stretched more is split
constexpr int kSmoothPasses = 4;           // border smoothing passes (grow_charts)
constexpr double kSmoothCos = 0.0872;      // cos 85°: how far a smoothed-in triangle may turn from the seed

using V2 = Eigen::Vector2d;
using V3 = Eigen::Vector3d;

double cross2(const V2& a, const V2& b) { return a.x() * b.y() - a.y() * b.x(); }

// The square of Sander's L2 stretch (header, REPORT) of the map from UV triangle q (world units,
// counter-clockwise) to surface triangle p: (|S_u|² + |S_v|²) / 2, S the map's Jacobian.
double l2_stretch_squared(const std::array<V3, 3>& p, const std::array<V2, 3>& q) {
  const double a2 = cross2(q[1] - q[0], q[2] - q[0]);
  const V3 su = (p[0] * (q[1].y() - q[2].y()) + p[1] * (q[2].y() - q[0].y()) + p[2] * (q[0].y() - q[1].y())) / a2;
  const V3 sv = (p[0] * (q[2].x() - q[1].x()) + p[1] * (q[0].x() - q[2].x()) + p[2] * (q[1].x() - q[0].x())) / a2;
  return (su.squaredNorm() + sv.squaredNorm()) / 2;
}

std::array<V3, 3> corners_of(const Mesh& mesh, uint32_t t) {
  const auto& tri = mesh.triangles[t];
  return {mesh.positions[tri[0]].cast<double>(), mesh.positions[tri[1]].cast<double>(), mesh.positions[tri[2]].cast<double>()};
}

// Per triangle: unit normal and area in double from the float positions; area 0: degenerate.
struct Faces {
  std::vector<V3> normal;
  std::vector<double> area;
};

Faces faces_of(const Mesh& mesh) {
  Faces f;
  f.normal.resize(mesh.triangles.size(), V3::Zero());
  f.area.resize(mesh.triangles.size(), 0.0);
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const V3 a = mesh.positions[tri[0]].cast<double>(), b = mesh.positions[tri[1]].cast<double>(),
             c = mesh.positions[tri[2]].cast<double>();
    const V3 n = (b - a).cross(c - a);
    const double len = n.norm();
    if (len > 0 && std::isfinite(len)) {
      f.normal[t] = n / len;
      f.area[t] = len / 2;
    }
  }
  return f;
}

// +1 when triangle `t` runs from welded a to welded b, −1 from b to a, 0 when it has not both.
int direction(const Mesh& mesh, const Topology& topo, uint32_t t, uint32_t a, uint32_t b) {
  for (int c = 0; c < 3; ++c) {
    const uint32_t w = topo.weld[mesh.triangles[t][size_t(c)]], next = topo.weld[mesh.triangles[t][size_t((c + 1) % 3)]];
    if (w == a && next == b) return 1;
    if (w == b && next == a) return -1;
  }
  return 0;
}

// Neighbours across soft, manifold, consistently wound edges (header, step 1): up to 3 per triangle.
std::vector<std::array<uint32_t, 3>> neighbours(const Mesh& mesh, const Topology& topo, const Faces& f,
                                                double hard_edge_degrees) {
  std::vector<std::array<uint32_t, 3>> nbr(mesh.triangles.size(), {kNone, kNone, kNone});
  const double min_cos = std::cos(hard_edge_degrees * std::numbers::pi / 180);
  auto add = [&](uint32_t t, uint32_t n) {
    for (uint32_t& slot : nbr[t])
      if (slot == kNone) {
        slot = n;
        return;
      }
  };
  for (size_t e = 0; e < topo.edges.size(); ++e) {
    const std::span<const uint32_t> fs = topo.faces_of_edge(uint32_t(e));
    if (fs.size() != 2) continue;
    const uint32_t t0 = fs[0], t1 = fs[1];
    if (f.area[t0] == 0 || f.area[t1] == 0) continue;
    const auto [a, b] = topo.edges[e];
    if (direction(mesh, topo, t0, a, b) * direction(mesh, topo, t1, a, b) != -1) continue;
    if (f.normal[t0].dot(f.normal[t1]) < min_cos) continue;
    add(t0, t1);
    add(t1, t0);
  }
  return nbr;
}

// The connected parts (over `nbr`) of equally labelled triangles among `triangles`, each sorted,
// in order of their first triangle there; kNone labels are left out. Consumes the labels: every
// triangle visited is relabelled kNone.
std::vector<std::vector<uint32_t>> connected_parts(const std::vector<std::array<uint32_t, 3>>& nbr,
                                                   std::span<const uint32_t> triangles, std::vector<uint32_t>& label) {
  std::vector<std::vector<uint32_t>> parts;
  std::vector<uint32_t> stack;
  for (uint32_t start : triangles) {
    const uint32_t mine = label[start];
    if (mine == kNone) continue;
    std::vector<uint32_t>& part = parts.emplace_back();
    stack.assign(1, start);
    label[start] = kNone;
    while (!stack.empty()) {
      const uint32_t t = stack.back();
      stack.pop_back();
      part.push_back(t);
      for (uint32_t n : nbr[t])
        if (n != kNone && label[n] == mine) label[n] = kNone, stack.push_back(n);
    }
    std::sort(part.begin(), part.end());
  }
  return parts;
}

// Region growing (header, step 1), then the borders smoothed: the charts as triangle lists.
std::vector<std::vector<uint32_t>> grow_charts(const Faces& f, const std::vector<std::array<uint32_t, 3>>& nbr,
                                               double cone_degrees) {
  const size_t T = f.area.size();
  const double min_cos = std::cos(cone_degrees * std::numbers::pi / 180);
  std::vector<uint32_t> chart_of(T, kNone);
  std::vector<V3> seed_normal;
  using Item = std::pair<double, uint32_t>;  // (n·n_seed, triangle): larger first, then lower triangle
  auto later = [](const Item& x, const Item& y) { return x.first != y.first ? x.first < y.first : x.second > y.second; };
  std::priority_queue<Item, std::vector<Item>, decltype(later)> queue(later);
  for (uint32_t seed = 0; seed < T; ++seed) {
    if (chart_of[seed] != kNone || f.area[seed] == 0) continue;
    const V3 d = f.normal[seed];
    const uint32_t id = uint32_t(seed_normal.size());
    seed_normal.push_back(d);
    queue.push({1.0, seed});
    while (!queue.empty()) {
      const uint32_t t = queue.top().second;
      queue.pop();
      if (chart_of[t] != kNone) continue;
      chart_of[t] = id;
      for (uint32_t n : nbr[t]) {
        if (n == kNone || chart_of[n] != kNone) continue;
        const double c = f.normal[n].dot(d);
        if (c >= min_cos) queue.push({c, n});
      }
    }
  }
  // Smoothing: on a noisy surface (a scan) the cone's limit runs through single triangles, leaving
  // spikes and one-triangle holes along and inside the borders, which waste atlas space. In
  // synchronous passes, a triangle two of whose neighbours lie in another chart joins that chart
  // when its normal is within kSmoothCos of that chart's seed (still a height field over the
  // seed's plane).
  for (int pass = 0; pass < kSmoothPasses; ++pass) {
    std::vector<uint32_t> next = chart_of;
    for (size_t t = 0; t < T; ++t) {
      if (chart_of[t] == kNone) continue;
      const std::array<uint32_t, 3>& n = nbr[t];
      for (int i = 0; i < 3; ++i) {
        if (n[size_t(i)] == kNone) continue;
        const uint32_t c = chart_of[n[size_t(i)]];
        if (c == chart_of[t]) continue;
        int same = 0;
        for (uint32_t m : n) same += m != kNone && chart_of[m] == c;
        if (same >= 2 && f.normal[t].dot(seed_normal[c]) >= kSmoothCos) {
          next[t] = c;
          break;
        }
      }
    }
    chart_of.swap(next);
  }
  // The charts' connected parts (a smoothed border may cut a chart), by their lowest triangle.
  std::vector<uint32_t> all(T);
  std::iota(all.begin(), all.end(), 0u);
  const std::vector<std::vector<uint32_t>> charts = connected_parts(nbr, all, chart_of);
  return charts;
}

// A chart being flattened: its triangles (ascending), its local vertices (welded ids, in order of
// first appearance over its triangles' corners), each corner's local vertex, and UVs per local
// vertex in world units.
struct Chart {
  std::vector<uint32_t> triangles;
  std::vector<uint32_t> welded;
  std::vector<std::array<uint32_t, 3>> corners;
  std::vector<V2> uv;
  double area = 0;  // surface area
  V2 extent = V2::Zero();
};

// The corner frame of triangle t (header, step 2): corner 0 at (0, 0), corner 1 at (|e|, 0),
// corner 2 at (x, 2A/|e|) — its y is positive whenever the area is, so the winding is kept exactly.
std::array<V2, 3> own_frame(const Mesh& mesh, const Faces& f, uint32_t t) {
  const auto& tri = mesh.triangles[t];
  const V3 a = mesh.positions[tri[0]].cast<double>(), b = mesh.positions[tri[1]].cast<double>(),
           c = mesh.positions[tri[2]].cast<double>();
  const double len = (b - a).norm();
  const V3 x = (b - a) / len;
  return {V2(0, 0), V2(len, 0), V2((c - a).dot(x), 2 * f.area[t] / len)};
}

class Flattener {
public:
  Flattener(const Mesh& mesh, const Topology& topo, const Faces& f, const std::vector<std::array<uint32_t, 3>>& nbr)
      : mesh_(mesh), topo_(topo), f_(f), nbr_(nbr), local_(topo.welded_positions.size(), kNone),
        member_(mesh.triangles.size(), kNone) {}

  // Flattens every chart of `seeds`, splitting where needed; the accepted charts in order of
  // their first triangle.
  std::vector<Chart> run(std::vector<std::vector<uint32_t>> seeds, UnwrapReport& report) {
    std::vector<Chart> done;
    std::vector<std::vector<uint32_t>> work = std::move(seeds);
    std::reverse(work.begin(), work.end());  // popped from the back: in the charts' order
    while (!work.empty()) {
      Chart c;
      c.triangles = std::move(work.back());
      work.pop_back();
      index(c);
      bool ok = false;
      const V3 d = f_.normal[c.triangles.front()];
      if (c.triangles.size() == 1) {
        const std::array<V2, 3> q = own_frame(mesh_, f_, c.triangles[0]);
        for (int k = 0; k < 3; ++k) c.uv[c.corners[0][size_t(k)]] = q[size_t(k)];
        ok = true;
        ++report.single_triangle_charts;
      } else if (planar(c, d)) {
        project(c, d);
        ok = accepted(c);
        report.planar_charts += ok;
      } else {
        ok = lscm(c) && accepted(c);
        report.lscm_charts += ok;
      }
      if (ok) normalise(c);
      if (ok && c.triangles.size() > 1 && worst_stretch(c) > kMaxChartStretch) ok = false, ++report.stretch_splits;
      if (ok) {
        done.push_back(std::move(c));
        continue;
      }
      ++report.splits;
      std::vector<std::vector<uint32_t>> parts = split(c.triangles);
      for (auto it = parts.rbegin(); it != parts.rend(); ++it) work.push_back(std::move(*it));
    }
    std::sort(done.begin(), done.end(), [](const Chart& x, const Chart& y) { return x.triangles[0] < y.triangles[0]; });
    return done;
  }

private:
  const Mesh& mesh_;
  const Topology& topo_;
  const Faces& f_;
  const std::vector<std::array<uint32_t, 3>>& nbr_;
  std::vector<uint32_t> local_;   // welded -> local vertex of the chart at hand (kNone elsewhere)
  std::vector<uint32_t> member_;  // scratch of split(): kNone between calls

  V3 position(uint32_t welded) const { return topo_.welded_positions[welded].cast<double>(); }

  void index(Chart& c) {
    c.welded.clear();
    c.corners.clear();
    c.corners.reserve(c.triangles.size());
    for (uint32_t t : c.triangles) {
      std::array<uint32_t, 3> corner{};
      for (size_t k = 0; k < 3; ++k) {
        const uint32_t w = topo_.weld[mesh_.triangles[t][k]];
        if (local_[w] == kNone) {
          local_[w] = uint32_t(c.welded.size());
          c.welded.push_back(w);
        }
        corner[k] = local_[w];
      }
      c.corners.push_back(corner);
    }
    for (uint32_t w : c.welded) local_[w] = kNone;
    c.uv.assign(c.welded.size(), V2::Zero());
    c.area = 0;
    for (uint32_t t : c.triangles) c.area += f_.area[t];
  }

  bool planar(const Chart& c, const V3& d) const {
    for (uint32_t t : c.triangles)
      if (f_.normal[t].dot(d) < kPlanarCos) return false;
    return true;
  }

  // Orthogonal projection onto the plane of unit d, in the frame (t1, t2 = d × t1): right-handed
  // with d, so a triangle wound counter-clockwise seen from d stays counter-clockwise.
  void project(Chart& c, const V3& d) const {
    const V3 t1 = d.unitOrthogonal(), t2 = d.cross(t1);
    for (size_t i = 0; i < c.welded.size(); ++i) {
      const V3 p = position(c.welded[i]);
      c.uv[i] = V2(p.dot(t1), p.dot(t2));
    }
  }

  // LSCM (header, step 2). False when the chart has fewer than two distinct positions or the
  // solve fails or gives a non-finite UV.
  bool lscm(Chart& c) const {
    const size_t n = c.welded.size();
    auto farthest = [&](uint32_t from) {
      const V3 p = position(c.welded[from]);
      uint32_t best = from;
      double best_d = -1;
      for (uint32_t i = 0; i < n; ++i)
        if (const double dd = (position(c.welded[i]) - p).squaredNorm(); dd > best_d) best_d = dd, best = i;
      return best;
    };
    const uint32_t pa = farthest(0), pb = farthest(pa);
    const double dist = (position(c.welded[pb]) - position(c.welded[pa])).norm();
    if (pa == pb || !(dist > 0)) return false;
    std::vector<uint32_t> free(n, kNone);
    uint32_t nf = 0;
    for (uint32_t i = 0; i < n; ++i)
      if (i != pa && i != pb) free[i] = nf++;
    std::vector<V2> pinned(n, V2::Zero());
    pinned[pb] = V2(dist, 0);
    std::vector<Eigen::Triplet<double>> entries;
    entries.reserve(c.triangles.size() * 12);
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(Eigen::Index(2 * c.triangles.size()));
    for (size_t k = 0; k < c.triangles.size(); ++k) {
      const uint32_t t = c.triangles[k];
      const std::array<V2, 3> q = own_frame(mesh_, f_, t);
      const double w = 1 / (2 * std::sqrt(f_.area[t]));
      const Eigen::Index rx = Eigen::Index(2 * k), ry = rx + 1;
      for (size_t j = 0; j < 3; ++j) {
        const V2 e = q[(j + 2) % 3] - q[(j + 1) % 3];
        // r_x = Σ u_j e_x − v_j e_y,  r_y = Σ u_j e_y + v_j e_x   (u, v weights of corner j)
        const double ux = w * e.x(), vx = -w * e.y(), uy = w * e.y(), vy = w * e.x();
        const uint32_t i = c.corners[k][j];
        if (free[i] == kNone) {
          rhs[rx] -= ux * pinned[i].x() + vx * pinned[i].y();
          rhs[ry] -= uy * pinned[i].x() + vy * pinned[i].y();
        } else {
          const Eigen::Index cu = Eigen::Index(free[i]), cv = Eigen::Index(nf + free[i]);
          entries.emplace_back(rx, cu, ux);
          entries.emplace_back(rx, cv, vx);
          entries.emplace_back(ry, cu, uy);
          entries.emplace_back(ry, cv, vy);
        }
      }
    }
    Eigen::SparseMatrix<double> a(Eigen::Index(2 * c.triangles.size()), Eigen::Index(2 * nf));
    a.setFromTriplets(entries.begin(), entries.end());
    const Eigen::SparseMatrix<double> at = a.transpose();
    const Eigen::SparseMatrix<double> normal = at * a;
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(normal);
    if (solver.info() != Eigen::Success) return false;
    const Eigen::VectorXd x = solver.solve(at * rhs);
    if (solver.info() != Eigen::Success || !x.allFinite()) return false;
    for (uint32_t i = 0; i < n; ++i)
      c.uv[i] = free[i] == kNone ? pinned[i] : V2(x[Eigen::Index(free[i])], x[Eigen::Index(nf + free[i])]);
    return true;
  }

  // Every triangle keeps its winding (signed UV area > 0) and no two boundary edges without a
  // common vertex meet (header, step 2).
  bool accepted(const Chart& c) const {
    for (const auto& k : c.corners)
      if (!(cross2(c.uv[k[1]] - c.uv[k[0]], c.uv[k[2]] - c.uv[k[0]]) > 0)) return false;
    // Boundary edges: sides of one chart triangle only.
    std::vector<uint64_t> sides;
    sides.reserve(3 * c.corners.size());
    for (const auto& k : c.corners)
      for (size_t j = 0; j < 3; ++j) {
        const uint32_t a = k[j], b = k[(j + 1) % 3];
        sides.push_back(uint64_t(std::min(a, b)) << 32 | std::max(a, b));
      }
    std::sort(sides.begin(), sides.end());
    std::vector<std::array<uint32_t, 2>> boundary;
    for (size_t i = 0; i < sides.size();) {
      size_t j = i;
      while (j < sides.size() && sides[j] == sides[i]) ++j;
      if (j - i == 1) boundary.push_back({uint32_t(sides[i] >> 32), uint32_t(sides[i] & 0xffffffffu)});
      i = j;
    }
    return !boundary_meets_itself(c.uv, boundary);
  }

  // Whether two segments of `edges` without a common endpoint meet (touching counts), through a
  // uniform grid of about one segment per cell.
  static bool boundary_meets_itself(const std::vector<V2>& uv, const std::vector<std::array<uint32_t, 2>>& edges) {
    if (edges.size() < 2) return false;
    Eigen::AlignedBox2d box;
    for (const auto& e : edges) box.extend(uv[e[0]]).extend(uv[e[1]]);
    const size_t side = std::max<size_t>(1, size_t(std::sqrt(double(edges.size()))));
    const V2 size = box.sizes().cwiseMax(1e-300);
    auto cell = [&](double x, double lo, double extent) {
      return std::min(side - 1, size_t(std::max(0.0, (x - lo) / extent * double(side))));
    };
    std::vector<std::vector<uint32_t>> grid(side * side);
    for (uint32_t i = 0; i < edges.size(); ++i) {
      const V2 &p = uv[edges[i][0]], &q = uv[edges[i][1]];
      const size_t x0 = cell(std::min(p.x(), q.x()), box.min().x(), size.x());
      const size_t x1 = cell(std::max(p.x(), q.x()), box.min().x(), size.x());
      const size_t y0 = cell(std::min(p.y(), q.y()), box.min().y(), size.y());
      const size_t y1 = cell(std::max(p.y(), q.y()), box.min().y(), size.y());
      for (size_t y = y0; y <= y1; ++y)
        for (size_t x = x0; x <= x1; ++x) grid[y * side + x].push_back(i);
    }
    auto orient = [](const V2& a, const V2& b, const V2& c) {
      const double o = cross2(b - a, c - a);
      return (o > 0) - (o < 0);
    };
    auto within = [](const V2& a, const V2& b, const V2& p) {  // p on the line ab: inside the segment's box
      return std::min(a.x(), b.x()) <= p.x() && p.x() <= std::max(a.x(), b.x()) && std::min(a.y(), b.y()) <= p.y() &&
             p.y() <= std::max(a.y(), b.y());
    };
    for (const std::vector<uint32_t>& in : grid)
      for (size_t i = 0; i < in.size(); ++i)
        for (size_t j = i + 1; j < in.size(); ++j) {
          const auto &e = edges[in[i]], &g = edges[in[j]];
          if (e[0] == g[0] || e[0] == g[1] || e[1] == g[0] || e[1] == g[1]) continue;
          const V2 &a = uv[e[0]], &b = uv[e[1]], &c = uv[g[0]], &d = uv[g[1]];
          const int o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
          if (o1 * o2 < 0 && o3 * o4 < 0) return true;
          if ((o1 == 0 && within(a, b, c)) || (o2 == 0 && within(a, b, d)) || (o3 == 0 && within(c, d, a)) ||
              (o4 == 0 && within(c, d, b)))
            return true;
        }
    return false;
  }

  // The largest L2 stretch of a chart's triangles (its UVs in world units).
  double worst_stretch(const Chart& c) const {
    double worst = 0;
    for (size_t k = 0; k < c.triangles.size(); ++k)
      worst = std::max(worst, l2_stretch_squared(corners_of(mesh_, c.triangles[k]),
                                                 {c.uv[c.corners[k][0]], c.uv[c.corners[k][1]], c.uv[c.corners[k][2]]}));
    return std::sqrt(worst);
  }

  // UV area = surface area (header, step 2).
  static void normalise(Chart& c) {
    double uv_area = 0;
    for (const auto& k : c.corners) uv_area += cross2(c.uv[k[1]] - c.uv[k[0]], c.uv[k[2]] - c.uv[k[0]]) / 2;
    const double s = std::sqrt(c.area / uv_area);
    for (V2& p : c.uv) p *= s;
  }

  // Two halves at the median centroid along the longest axis of the centroids' box, each cut
  // into its connected parts (over neighbours inside the half); parts by first triangle.
  std::vector<std::vector<uint32_t>> split(const std::vector<uint32_t>& tris) {
    std::vector<std::pair<double, uint32_t>> key;
    Eigen::AlignedBox3d box;
    std::vector<V3> centroid(tris.size());
    for (size_t i = 0; i < tris.size(); ++i) {
      const auto& tri = mesh_.triangles[tris[i]];
      centroid[i] = (mesh_.positions[tri[0]].cast<double>() + mesh_.positions[tri[1]].cast<double>() +
                     mesh_.positions[tri[2]].cast<double>()) / 3;
      box.extend(centroid[i]);
    }
    Eigen::Index axis = 0;
    box.sizes().maxCoeff(&axis);
    for (size_t i = 0; i < tris.size(); ++i) key.push_back({centroid[i][axis], tris[i]});
    std::sort(key.begin(), key.end());
    const size_t half = key.size() / 2;
    for (size_t i = 0; i < key.size(); ++i) member_[key[i].second] = i < half ? 1 : 2;
    std::vector<std::vector<uint32_t>> parts = connected_parts(nbr_, tris, member_);
    return parts;
  }
};

// Turns chart c to its minimal-area bounding rectangle (header, step 3), wide side along u, its
// box's corner at (0, 0); sets c.extent.
void orient_chart(Chart& c) {
  std::vector<V2> pts = c.uv;
  std::sort(pts.begin(), pts.end(), [](const V2& a, const V2& b) { return a.x() != b.x() ? a.x() < b.x() : a.y() < b.y(); });
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  // Convex hull (Andrew's monotone chain), counter-clockwise.
  std::vector<V2> hull;
  if (pts.size() >= 3) {
    hull.resize(2 * pts.size());
    size_t k = 0;
    for (size_t i = 0; i < pts.size(); ++i) {
      while (k >= 2 && cross2(hull[k - 1] - hull[k - 2], pts[i] - hull[k - 2]) <= 0) --k;
      hull[k++] = pts[i];
    }
    for (size_t i = pts.size() - 1, lo = k + 1; i-- > 0;) {
      while (k >= lo && cross2(hull[k - 1] - hull[k - 2], pts[i] - hull[k - 2]) <= 0) --k;
      hull[k++] = pts[i];
    }
    hull.resize(k - 1);
  } else {
    hull = pts;
  }
  V2 axis(1, 0);
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < hull.size(); ++i) {
    const V2 e = hull[(i + 1) % hull.size()] - hull[i];
    if (!(e.norm() > 0)) continue;
    const V2 x = e.normalized(), y(-x.y(), x.x());
    double lx = std::numeric_limits<double>::infinity(), hx = -lx, ly = lx, hy = -lx;
    for (const V2& p : hull) {
      lx = std::min(lx, p.dot(x)), hx = std::max(hx, p.dot(x));
      ly = std::min(ly, p.dot(y)), hy = std::max(hy, p.dot(y));
    }
    if (const double area = (hx - lx) * (hy - ly); area < best) best = area, axis = x;
  }
  V2 y(-axis.y(), axis.x());
  for (V2& p : c.uv) p = V2(p.dot(axis), p.dot(y));  // a rotation: windings kept
  Eigen::AlignedBox2d box;
  for (const V2& p : c.uv) box.extend(p);
  if (box.sizes().y() > box.sizes().x()) {
    for (V2& p : c.uv) p = V2(-p.y(), p.x());  // +90°: windings kept
    box.setEmpty();
    for (const V2& p : c.uv) box.extend(p);
  }
  for (V2& p : c.uv) p -= box.min();
  c.extent = box.sizes();
}

// A chart's own density at the atlas's density s (UnwrapOptions::min_chart_texels): s, or more
// for a chart narrower than `min_texels` texels across its short side, at most kMaxChartScale·s.
constexpr double kMaxChartScale = 4;
double chart_density(const Chart& c, double s, uint32_t min_texels) {
  if (min_texels == 0 || !(c.extent.y() > 0)) return s;
  return std::min(kMaxChartScale * s, std::max(s, double(min_texels) / c.extent.y()));
}

// A chart box's side in texels at density s for an extent in world units (header, step 3).
uint32_t cells(double extent, double s) { return uint32_t(std::floor(extent * s + 2 * kMargin)) + 1; }

// The span of x over the points of triangle t whose y lies in [lo, hi] (its vertices there and its
// edges' crossings of the two lines); empty: (+inf, −inf).
std::pair<double, double> slab_span(const V2 (&t)[3], double lo, double hi) {
  double mn = std::numeric_limits<double>::infinity(), mx = -mn;
  for (int k = 0; k < 3; ++k) {
    const V2 &p = t[k], &q = t[(k + 1) % 3];
    if (p.y() >= lo && p.y() <= hi) mn = std::min(mn, p.x()), mx = std::max(mx, p.x());
    for (const double y : {lo, hi})
      if (p.y() != q.y() && (p.y() - y) * (q.y() - y) <= 0) {
        const double w = (y - p.y()) / (q.y() - p.y()), x = p.x() + w * (q.x() - p.x());
        mn = std::min(mn, x), mx = std::max(mx, x);
      }
  }
  return {mn, mx};
}

// A bit image of w × h texels: texel (c, r) is bit c % 64 of word c / 64 of row r, each row
// `words` words long.
struct Bits {
  int32_t w = 0, h = 0, words = 0;
  std::vector<uint64_t> bits;

  void reset(int32_t width, int32_t height) {
    w = width, h = height, words = (width + 63) / 64;
    bits.assign(size_t(h) * size_t(words), 0);
  }
  uint64_t* row(int64_t r) { return bits.data() + size_t(r) * size_t(words); }
  const uint64_t* row(int64_t r) const { return bits.data() + size_t(r) * size_t(words); }
  bool operator==(const Bits&) const = default;
};

// Sets columns a … b (a ≤ b) of a bit row.
void set_span(uint64_t* row, int64_t a, int64_t b) {
  const int64_t ka = a >> 6, kb = b >> 6;
  const uint64_t first = ~uint64_t(0) << (a & 63), last = ~uint64_t(0) >> (63 - (b & 63));
  if (ka == kb) {
    row[ka] |= first & last;
    return;
  }
  row[ka] |= first;
  for (int64_t k = ka + 1; k < kb; ++k) row[k] = ~uint64_t(0);
  row[kb] |= last;
}

// The first column at or after `from` whose bit is `value` in a row of `words` words; words·64
// when there is none.
int64_t next_bit(const uint64_t* row, int32_t words, int64_t from, bool value) {
  int64_t k = from >> 6;
  if (k >= words) return int64_t(words) * 64;
  uint64_t v = (value ? row[k] : ~row[k]) & (~uint64_t(0) << (from & 63));
  while (v == 0) {
    if (++k == words) return int64_t(words) * 64;
    v = value ? row[k] : ~row[k];
  }
  return k * 64 + std::countr_zero(v);
}

// The first column of the run of set bits that holds set column c.
int64_t run_start(const uint64_t* row, int64_t c) {
  int64_t k = c >> 6;
  uint64_t v = ~row[k] & ((uint64_t(1) << (c & 63)) - 1);  // clear bits below c in its word
  while (v == 0) {
    if (--k < 0) return 0;
    v = ~row[k];
  }
  return k * 64 + 64 - std::countl_zero(v);
}

// A chart's texels at density s in its box of w × h texels (the chart centred in it, header step
// 3): per row, the union over its triangles of the columns each touches there. A superset of
// texel_atlas's conservative coverage (bake/mesh/texels.h): each texel square is widened by
// kSlack, more than the float rounding of a stored UV (2^-24 of 16384 texels, 1e-3) and less than
// the chart's inset in its box (> kMargin), so the chart stays inside its box.
constexpr double kSlack = 1.0 / 128;
struct Footprint {
  Bits texels;
  V2 inset = V2::Zero();  // the chart's corner (0, 0) in its box, in texels
};

Footprint footprint(const Chart& c, double s) {
  Footprint f;
  const int32_t w = int32_t(cells(c.extent.x(), s)), h = int32_t(cells(c.extent.y(), s));
  f.texels.reset(w, h);
  f.inset = V2((w - c.extent.x() * s) / 2, (h - c.extent.y() * s) / 2);
  for (const auto& k : c.corners) {
    const V2 t[3] = {f.inset + c.uv[k[0]] * s, f.inset + c.uv[k[1]] * s, f.inset + c.uv[k[2]] * s};
    const double lo = std::min({t[0].y(), t[1].y(), t[2].y()}), hi = std::max({t[0].y(), t[1].y(), t[2].y()});
    const int32_t first = std::max(0, int32_t(std::floor(lo - kSlack))), last = std::min(h - 1, int32_t(std::floor(hi + kSlack)));
    for (int32_t r = first; r <= last; ++r) {
      const auto [mn, mx] = slab_span(t, double(r) - kSlack, double(r) + 1 + kSlack);
      if (mn > mx) continue;
      const int32_t a = std::max(0, int32_t(std::floor(mn - kSlack))), b = std::min(w - 1, int32_t(std::floor(mx + kSlack)));
      if (a <= b) set_span(f.texels.row(r), a, b);
    }
  }
  return f;
}

// A footprint turned by rotation r (0°, 90°, 180°, 270° about its box, each keeping windings:
// header step 3; texel (c, q) of a w × h box goes to (c, q), (h − 1 − q, c), (w − 1 − c, h − 1 − q),
// (q, w − 1 − c)), with its KEY: over 2^k rows from key_row (k < the atlas's levels), the longest
// run of columns set in all of them, the one of most texels (then the least k, then the first).
struct Shape {
  Bits texels;
  int32_t key_level = 0, key_row = 0, key_start = 0, key_length = 0;
  // CORE: with k = core_level > 0 (the highest level at most h rows tall), the intersections of
  // rows min(i·2^k, h − 2^k) … + 2^k − 1, i = 0, 1, …: every row is in one, and a core row
  // tested against level k answers for 2^k rows of the shape at once.
  int32_t core_level = 0;
  Bits core;
};

// Bit image b transposed: texel (c, q) to (q, c), 64 × 64 blocks at a time.
Bits transposed(const Bits& b) {
  Bits t;
  t.reset(b.h, b.w);
  uint64_t m[64];
  for (int32_t by = 0; by < (b.h + 63) / 64; ++by)
    for (int32_t bx = 0; bx < b.words; ++bx) {
      for (int32_t i = 0; i < 64; ++i) m[i] = by * 64 + i < b.h ? b.row(by * 64 + i)[bx] : 0;
      uint64_t mask = 0x00000000FFFFFFFFull;  // swap ever smaller blocks across the diagonal
      for (int j = 32; j != 0; j >>= 1, mask ^= mask << j)
        for (int k = 0; k < 64; k = ((k | j) + 1) & ~j) {
          const uint64_t d = ((m[k] >> j) ^ m[k | j]) & mask;
          m[k | j] ^= d;
          m[k] ^= d << j;
        }
      for (int32_t i = 0; i < 64 && bx * 64 + i < t.h; ++i) t.row(bx * 64 + i)[by] = m[i];
    }
  return t;
}

// Bit image b mirrored left to right (texel (c, q) to (w − 1 − c, q)).
void mirror_columns(Bits& b) {
  const int32_t pad = b.words * 64 - b.w;
  std::vector<uint64_t> r(size_t(b.words) + 1);
  for (int32_t y = 0; y < b.h; ++y) {
    uint64_t* row = b.row(y);
    for (int32_t i = 0; i < b.words; ++i) {
      uint64_t v = row[b.words - 1 - i];
      v = (v >> 1 & 0x5555555555555555ull) | (v & 0x5555555555555555ull) << 1;
      v = (v >> 2 & 0x3333333333333333ull) | (v & 0x3333333333333333ull) << 2;
      v = (v >> 4 & 0x0F0F0F0F0F0F0F0Full) | (v & 0x0F0F0F0F0F0F0F0Full) << 4;
      r[size_t(i)] = __builtin_bswap64(v);
    }
    r[size_t(b.words)] = 0;
    for (int32_t i = 0; i < b.words; ++i)  // bit c + pad of the reversed row to bit c
      row[i] = pad == 0 ? r[size_t(i)] : r[size_t(i)] >> pad | r[size_t(i) + 1] << (64 - pad);
  }
}

// Bit image b mirrored top to bottom (texel (c, q) to (c, h − 1 − q)).
void mirror_rows(Bits& b) {
  for (int32_t y = 0; y < b.h / 2; ++y) std::swap_ranges(b.row(y), b.row(y) + b.words, b.row(b.h - 1 - y));
}

Shape shape(const Bits& f, int r, int levels) {
  Shape s;
  if (r % 2 == 1) s.texels = transposed(f);  // (q, c)
  else s.texels = f;
  if (r == 1 || r == 2) mirror_columns(s.texels);
  if (r == 2 || r == 3) mirror_rows(s.texels);
  // The key and the core: level k's row y is the intersection of rows y … y + 2^k − 1.
  const int32_t h = s.texels.h;
  while (levels > 1 && (int32_t(1) << (levels - 1)) > h) --levels;
  Bits level = s.texels;
  int64_t best = 0;
  for (int k = 0; k < levels; ++k) {
    const int32_t span = int32_t(1) << k, half = span / 2;
    if (k > 0)
      for (int32_t y = 0; y + span <= h; ++y)
        for (int32_t i = 0; i < level.words; ++i) level.row(y)[i] &= level.row(y + half)[i];
    if (k > 0 && k == levels - 1) {
      s.core_level = k;
      s.core.reset(level.w, (h + span - 1) / span);
      for (int32_t i = 0; i < s.core.h; ++i)
        std::copy_n(level.row(std::min(i * span, h - span)), level.words, s.core.row(i));
    }
    for (int32_t y = 0; y + span <= h; ++y)
      for (int64_t a = next_bit(level.row(y), level.words, 0, true); a < level.w;) {
        const int64_t b = std::min<int64_t>(level.w, next_bit(level.row(y), level.words, a, false));
        if ((b - a) * span > best) {
          best = (b - a) * span;
          s.key_level = k, s.key_row = y, s.key_start = int32_t(a), s.key_length = int32_t(b - a);
        }
        a = next_bit(level.row(y), level.words, b, true);
      }
  }
  return s;
}

// Texel position of point q of a footprint's box after rotation r (Shape), the box at (x, y).
V2 placed(const Footprint& f, int r, const V2& q, int64_t x, int64_t y) {
  const double w = f.texels.w, h = f.texels.h;
  V2 p = q;
  switch (r) {
  case 1: p = V2(h - q.y(), q.x()); break;
  case 2: p = V2(w - q.x(), h - q.y()); break;
  case 3: p = V2(q.y(), w - q.x()); break;
  default: break;
  }
  return p + V2(double(x), double(y));
}

struct Placement {
  int64_t x = 0, y = 0;
  int rotation = 0;
};

// The atlas being packed (header, step 3): a bit per texel, set where no chart's texel may go —
// within G of a placed chart's texels (Chebyshev), or within the border margins. Level k holds,
// per row y, the union of rows y … y + 2^k − 1 (rows past the last: all taken), with each row's
// longest free run: a search tests a shape's key (Shape) there before testing the shape itself.
// Levels only skip positions that cannot fit, so the result does not depend on their number.
class Atlas {
public:
  Atlas(uint32_t W, uint32_t H, uint32_t gutter, int levels)
      : W_(W), H_(H), G_(gutter), taken_(size_t(levels)), longest_(size_t(levels), std::vector<int64_t>(H)),
        lowest_(size_t(levels), std::vector<int64_t>(size_t(W) + 1, 0)) {
    for (Bits& b : taken_) b.reset(int32_t(W), int32_t(H));
    const int64_t near = G_ / 2, far = G_ - G_ / 2;
    for (int64_t y = 0; y < H_; ++y) {
      uint64_t* row = taken_[0].row(y);
      if (W_ % 64 != 0) row[taken_[0].words - 1] |= ~uint64_t(0) << (W_ % 64);  // past the last column
      if (y < near || y >= H_ - far) set_span(row, 0, W_ - 1);
      if (near > 0) set_span(row, 0, std::min(near, W_) - 1);
      if (far > 0) set_span(row, std::max<int64_t>(0, W_ - far), W_ - 1);
    }
    update(0, H_ - 1);
  }

  int levels() const { return int(taken_.size()); }

  // The first position (rows, then columns) from (x0, y0) on at which `s`'s box lies in the atlas
  // with its top row at most y_last and none of its texels on a taken one; false when there is
  // none.
  bool find(const Shape& s, int64_t y_last, int64_t y0, int64_t x0, int64_t& fx, int64_t& fy) {
    const Bits& t = s.texels;
    if (t.w > W_ || t.h > H_ || s.key_length == 0) return false;
    const std::vector<int64_t>& longest = longest_[size_t(s.key_level)];
    const Bits& keys = taken_[size_t(s.key_level)];
    int64_t& low = lowest_[size_t(s.key_level)][size_t(s.key_length)];  // no row above has such a run
    while (low < H_ && longest[size_t(low)] < s.key_length) ++low;
    y_last = std::min(y_last, H_ - t.h);
    if (y0 < low - s.key_row) y0 = low - s.key_row, x0 = 0;
    for (int64_t y = std::max<int64_t>(0, y0); y <= y_last; ++y) {
      const int64_t key = y + s.key_row;
      if (longest[size_t(key)] < s.key_length) continue;
      const uint64_t* row = keys.row(key);
      for (int64_t p = next_bit(row, keys.words, 0, false); p < W_;) {
        const int64_t q = next_bit(row, keys.words, p, true);  // free columns p … q − 1
        int64_t x = std::max<int64_t>(y == y0 ? x0 : 0, p - s.key_start);
        const int64_t x_last = std::min(q - s.key_length - s.key_start, W_ - t.w);
        while (x <= x_last) {
          const int64_t next = collision(s, x, y);
          if (next < 0) {
            fx = x, fy = y;
            return true;
          }
          x = std::max(x + 1, next);
        }
        p = next_bit(row, keys.words, q, false);
      }
    }
    return false;
  }

  // Takes `s`'s texels with its box at (x, y), dilated by G.
  void take(const Shape& s, int64_t x, int64_t y) {
    const Bits& t = s.texels;
    for (int64_t j = 0; j < t.h; ++j)
      for (int64_t a = next_bit(t.row(j), t.words, 0, true); a < t.w;) {
        const int64_t b = std::min<int64_t>(t.w, next_bit(t.row(j), t.words, a, false));
        for (int64_t r = std::max<int64_t>(0, y + j - G_); r <= std::min(H_ - 1, y + j + G_); ++r)
          set_span(taken_[0].row(r), std::max<int64_t>(0, x + a - G_), std::min(W_ - 1, x + b - 1 + G_));
        a = next_bit(t.row(j), t.words, b, true);
      }
    update(std::max<int64_t>(0, y - G_), std::min(H_ - 1, y + t.h - 1 + G_));
  }

private:
  int64_t W_, H_, G_;
  std::vector<Bits> taken_;                   // per level
  std::vector<std::vector<int64_t>> longest_;  // per level and row its longest run of free texels
  std::vector<std::vector<int64_t>> lowest_;   // per level and run length n: no row above has n free

  // Levels 1… and the longest runs after level 0 changed in rows r0 … r1.
  void update(int64_t r0, int64_t r1) {
    const int32_t words = taken_[0].words;
    for (size_t k = 0; k < taken_.size(); ++k) {
      const int64_t half = k == 0 ? 0 : int64_t(1) << (k - 1), first = std::max<int64_t>(0, r0 - 2 * half + (k == 0 ? 0 : 1));
      for (int64_t r = first; r <= r1; ++r) {
        uint64_t* row = taken_[k].row(r);
        if (k > 0) {
          const uint64_t* a = taken_[k - 1].row(r);
          if (r + half >= H_) std::fill(row, row + words, ~uint64_t(0));
          else
            for (int32_t i = 0; i < words; ++i) row[i] = a[i] | taken_[k - 1].row(r + half)[i];
        }
        int64_t best = 0;
        for (int64_t p = next_bit(row, words, 0, false); p < W_;) {
          const int64_t q = next_bit(row, words, p, true);
          best = std::max(best, q - p);
          p = next_bit(row, words, q, false);
        }
        longest_[k][size_t(r)] = best;
      }
    }
  }

  // −1 when `s` fits with its box at (x, y); otherwise a column x' > x such that it collides at
  // every column x … x' − 1 too: past the run of the shape's (or core's) row that hit a taken
  // texel. The core first: it rejects most positions of a large shape in a few rows.
  int64_t collision(const Shape& s, int64_t x, int64_t y) const {
    const Bits& t = s.texels;
    const int64_t k0 = x >> 6, n = ((x + t.w - 1) >> 6) - k0 + 1;
    const int shift = int(x & 63);
    auto hit = [&](const uint64_t* m, const uint64_t* g) -> int64_t {
      g += k0;
      for (int64_t i = 0; i < n; ++i) {
        uint64_t v = i < t.words ? m[i] << shift : 0;
        if (shift != 0 && i > 0) v |= m[i - 1] >> (64 - shift);
        if (const uint64_t both = v & g[i]; both != 0) {
          const int64_t c = (k0 + i) * 64 + 63 - std::countl_zero(both);  // the last hit in this word
          return c - run_start(m, c - x) + 1;
        }
      }
      return -1;
    };
    if (s.core_level > 0) {
      const int64_t span = int64_t(1) << s.core_level;
      for (int64_t i = 0; i < s.core.h; ++i)
        if (const int64_t next = hit(s.core.row(i), taken_[size_t(s.core_level)].row(y + std::min(i * span, t.h - span)));
            next >= 0)
          return next;
    }
    for (int64_t j = 0; j < t.h; ++j)
      if (const int64_t next = hit(t.row(j), taken_[0].row(y + j)); next >= 0) return next;
    return -1;
  }
};

// The charts' footprints at density s (header, step 3); false when a chart is wider than the
// atlas's larger side in every rotation.
bool footprints(const std::vector<Chart>& charts, double s, uint32_t min_texels, uint32_t W, uint32_t H,
                std::vector<Footprint>& prints) {
  const double side = std::max(W, H);
  prints.resize(charts.size());
  for (size_t i = 0; i < charts.size(); ++i) {
    const double sc = chart_density(charts[i], s, min_texels);
    if (!(charts[i].extent.x() * sc < side)) return false;
    prints[i] = footprint(charts[i], sc);
  }
  return true;
}

// The texels within r of a footprint's (Chebyshev). Two charts' footprints lie more than G apart
// and G/2 or more from the border, so their sets at r = G/2 are disjoint and inside the atlas:
// their sum is at most W·H wherever the charts pack.
int64_t dilated_texels(const Bits& b, int32_t r) {
  const int32_t words = (b.w + 2 * r + 63) / 64;
  std::vector<uint64_t> wide(size_t(b.h + 2 * r) * size_t(words), 0);  // rows widened by r, shifted by r
  for (int32_t y = 0; y < b.h; ++y)
    for (int64_t a = next_bit(b.row(y), b.words, 0, true); a < b.w;) {
      const int64_t e = std::min<int64_t>(b.w, next_bit(b.row(y), b.words, a, false));
      for (int32_t d = 0; d <= 2 * r; ++d) set_span(wide.data() + size_t(y + d) * size_t(words), a, e - 1 + 2 * r);
      a = next_bit(b.row(y), b.words, e, true);
    }
  int64_t n = 0;
  for (const uint64_t v : wide) n += std::popcount(v);
  return n;
}

uint64_t hash(const Bits& b) {
  uint64_t h = 0xcbf29ce484222325ull;
  auto mix = [&](uint64_t v) { h = (h ^ v) * 0x100000001b3ull; };
  mix(uint64_t(b.w)), mix(uint64_t(b.h));
  for (const uint64_t v : b.bits) mix(v);
  return h;
}

// Bitmap packing (header, step 3) of the footprints into W × H. False when a chart does not fit.
bool pack(const std::vector<Footprint>& prints, uint32_t gutter, uint32_t W, uint32_t H, std::vector<Placement>& where) {
  std::vector<uint32_t> order(prints.size());
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    const int64_t aa = int64_t(prints[a].texels.w) * prints[a].texels.h, ab = int64_t(prints[b].texels.w) * prints[b].texels.h;
    return aa != ab ? aa > ab : a < b;
  });
  where.assign(prints.size(), {});
  // Levels of 1 … 32 rows, fewer past 8192² texels (64 MB at most).
  Atlas atlas(W, H, gutter, int(std::clamp<uint64_t>((uint64_t(1) << 29) / (uint64_t(W) * H), 1, 6)));
  // Taken texels are never freed, so a shape fits nowhere before the position where it last fitted
  // or the row after the last that found it none: a search resumes there (many charts repeat).
  struct Resume {
    Bits texels;
    int64_t y = 0, x = 0;
  };
  std::unordered_map<uint64_t, std::vector<Resume>> resume;
  Shape best_shape;
  for (uint32_t i : order) {
    int64_t best_bottom = std::numeric_limits<int64_t>::max(), best_x = 0, best_y = 0;
    int best_r = -1;
    for (int r = 0; r < 4; ++r) {
      Shape sh = shape(prints[i].texels, r, atlas.levels());
      std::vector<Resume>& same = resume[hash(sh.texels)];
      auto it = std::find_if(same.begin(), same.end(), [&](const Resume& m) { return m.texels == sh.texels; });
      if (it == same.end()) it = same.insert(same.end(), {sh.texels, 0, 0});
      int64_t x = 0, y = 0;
      const int64_t y_last = best_r < 0 ? int64_t(H) : best_bottom - sh.texels.h;
      const bool found = atlas.find(sh, y_last, it->y, it->x, x, y);
      it->y = found ? y : std::max(it->y, y_last + 1), it->x = found ? x : 0;
      if (!found) continue;
      const int64_t bottom = y + sh.texels.h;
      if (bottom < best_bottom || (bottom == best_bottom && x < best_x)) {
        best_bottom = bottom, best_x = x, best_y = y, best_r = r;
        best_shape = std::move(sh);
      }
    }
    if (best_r < 0) return false;
    where[i] = {best_x, best_y, best_r};
    atlas.take(best_shape, best_x, best_y);
  }
  return true;
}

} // namespace

Unwrapped unwrap(const Mesh& mesh, const Topology& topo, const UnwrapOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  const bool sized = o.width != 0 || o.height != 0;
  if (sized == (o.density != 0))
    throw InputError(mesh.source, "a generated lightmap needs either its size in texels or a density in texels per "
                                  "unit, not both and not neither");
  if (sized && (o.width < 1 || o.height < 1 || o.width > o.max_side || o.height > o.max_side))
    throw InputError(mesh.source, "a generated lightmap of " + std::to_string(o.width) + "x" + std::to_string(o.height) +
                                      " texels: each side must be 1 to " + std::to_string(o.max_side));
  if (!sized && !(std::isfinite(o.density) && o.density > 0))
    throw InputError(mesh.source, "a lightmap density of " + std::to_string(o.density) +
                                      " texels per unit: it must be finite and > 0");
  if (topo.weld.size() != mesh.positions.size())
    throw ContractError("unwrap: the topology is not the mesh's");

  Unwrapped out;
  UnwrapReport& r = out.report;
  const Faces f = faces_of(mesh);
  const auto nbr = neighbours(mesh, topo, f, o.hard_edge_degrees);
  Flattener flattener(mesh, topo, f, nbr);
  std::vector<Chart> charts = flattener.run(grow_charts(f, nbr, o.cone_degrees), r);
  r.degenerate_triangles = size_t(std::count(f.area.begin(), f.area.end(), 0.0));
  if (charts.empty())
    throw InputError(mesh.source, "every triangle has zero area: there is no surface to give lightmap UVs");
  r.charts = charts.size();
  double area = 0;
  for (Chart& c : charts) {
    orient_chart(c);
    area += c.area;
  }

  // The density and the atlas (header, step 3).
  std::vector<Footprint> prints;
  std::vector<Placement> where;
  // The packing is a function of the footprints and W × H alone, so a density whose footprints
  // equal those of the last one that packed (or failed) in the same atlas is not packed again:
  // late bisection steps rarely move a texel.
  struct Known {
    uint32_t W = 0, H = 0;
    std::vector<Footprint> prints;
    std::vector<Placement> where;
  } packed, failed;
  auto same = [](const Known& k, uint32_t W, uint32_t H, const std::vector<Footprint>& p) {
    if (k.W != W || k.H != H || k.prints.size() != p.size()) return false;
    for (size_t i = 0; i < p.size(); ++i)
      if (!(k.prints[i].texels == p[i].texels)) return false;
    return true;
  };
  auto fits = [&](double s, uint32_t W, uint32_t H) {
    if (!footprints(charts, s, o.min_chart_texels, W, H, prints)) return false;
    if (same(packed, W, H, prints)) {
      where = packed.where;
      return true;
    }
    if (same(failed, W, H, prints)) return false;
    int64_t least = 0;  // a bound that fails a density without packing (dilated_texels)
    for (const Footprint& print : prints) least += dilated_texels(print.texels, int32_t(o.gutter / 2));
    if (least > int64_t(W) * H) return false;
    const bool ok = pack(prints, o.gutter, W, H, where);
    Known& k = ok ? packed : failed;
    k.W = W, k.H = H, k.prints = prints, k.where = where;
    return ok;
  };
  auto largest_density = [&](uint32_t W, uint32_t H) {
    double lo = 0, hi = std::sqrt(double(W) * double(H) / area);
    while (fits(hi, W, H)) lo = hi, hi *= 2;  // never in practice: the charts' cells exceed their area
    for (int i = 0; i < kBisections; ++i) {
      const double mid = (lo + hi) / 2;
      (fits(mid, W, H) ? lo : hi) = mid;
    }
    return lo;
  };
  const std::string tiny = std::to_string(charts.size()) + " charts do not fit in ";
  if (sized) {
    r.width = o.width;
    r.height = o.height;
    if (!fits(0, r.width, r.height))
      throw InputError(mesh.source, tiny + std::to_string(r.width) + "x" + std::to_string(r.height) +
                                        " texels even at one texel each plus the gutter of " + std::to_string(o.gutter) +
                                        ": use a larger lightmap");
    r.density = largest_density(r.width, r.height);
  } else {
    r.density = o.density;
    const uint32_t top = o.max_side / 4 * 4;
    if (top == 0 || !fits(r.density, top, top)) {
      const double most = top == 0 ? 0 : largest_density(top, top);
      throw InputError(mesh.source, "a lightmap at " + std::to_string(o.density) + " texels per unit needs more than " +
                                        std::to_string(o.max_side) + "x" + std::to_string(o.max_side) +
                                        " texels; the largest density that fits is " + std::to_string(most));
    }
    uint32_t lo = 0, hi = top / 4;  // sides 4·k: hi fits, lo does not
    while (hi - lo > 1) {
      const uint32_t mid = (lo + hi) / 2;
      (fits(r.density, 4 * mid, 4 * mid) ? hi : lo) = mid;
    }
    r.width = r.height = 4 * hi;
  }
  if (!fits(r.density, r.width, r.height)) throw ContractError("unwrap: the chosen atlas does not pack");

  // UVs and the report.
  const double s = r.density, W = r.width, H = r.height;
  out.uv.name = o.name;
  out.uv.corners.assign(3 * mesh.triangles.size(), Eigen::Vector2f::Zero());
  double weighted = 0, uv_area = 0;
  r.worst_stretch = 0;
  for (size_t i = 0; i < charts.size(); ++i) {
    const Chart& c = charts[i];
    const Footprint& box = prints[i];
    const double sc = chart_density(c, s, o.min_chart_texels);
    r.scaled_charts += sc > s ? 1 : 0;
    std::vector<V2> texel(c.uv.size());
    for (size_t v = 0; v < c.uv.size(); ++v)
      texel[v] = placed(box, where[i].rotation, box.inset + c.uv[v] * sc, where[i].x, where[i].y);
    for (size_t k = 0; k < c.triangles.size(); ++k) {
      const uint32_t t = c.triangles[k];
      for (size_t j = 0; j < 3; ++j) {
        const V2& q = texel[c.corners[k][j]];
        out.uv.corners[3 * size_t(t) + j] = Eigen::Vector2f(float(q.x() / W), float(q.y() / H));
      }
      // Sander's L2 stretch, the texture in world units (texels / the chart's density).
      const std::array<V2, 3> q = {texel[c.corners[k][0]] / sc, texel[c.corners[k][1]] / sc, texel[c.corners[k][2]] / sc};
      uv_area += cross2(q[1] - q[0], q[2] - q[0]) / 2 * sc * sc;
      const double l2sq = l2_stretch_squared(corners_of(mesh, t), q);
      r.worst_stretch = std::max(r.worst_stretch, std::sqrt(l2sq));
      weighted += l2sq * f.area[t];
    }
  }
  r.mean_stretch = std::sqrt(weighted / area);
  r.utilisation = uv_area / (W * H);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

} // namespace prt::bake
