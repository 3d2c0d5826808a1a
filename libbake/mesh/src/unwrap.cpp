// unwrap.cpp — a generated lightmap UV set: charts, LSCM, packing (bake/mesh/unwrap.h).
#include <bake/mesh/unwrap.h>
#include <bake/core/error.h>

#include <Eigen/Geometry>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <queue>
#include <span>
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

// The span of coordinate 1 − a over the points of triangle t whose coordinate a lies in [lo, hi]
// (its vertices there and its edges' crossings of the two lines); empty: (+inf, −inf).
std::pair<double, double> slab_span(const V2 (&t)[3], int a, double lo, double hi) {
  double mn = std::numeric_limits<double>::infinity(), mx = -mn;
  const int b = 1 - a;
  for (int k = 0; k < 3; ++k) {
    const V2 &p = t[k], &q = t[(k + 1) % 3];
    if (p[a] >= lo && p[a] <= hi) mn = std::min(mn, p[b]), mx = std::max(mx, p[b]);
    for (const double x : {lo, hi})
      if (p[a] != q[a] && (p[a] - x) * (q[a] - x) <= 0) {
        const double w = (x - p[a]) / (q[a] - p[a]), y = p[b] + w * (q[b] - p[b]);
        mn = std::min(mn, y), mx = std::max(mx, y);
      }
  }
  return {mn, mx};
}

// A chart's texels at density s in its box of w × h texels (the chart centred in it, header step
// 3): per column the first and last row it touches, per row the first and last column. A
// superset of texel_atlas's conservative coverage (bake/mesh/texels.h): each texel square is
// widened by kSlack, more than the float rounding of a stored UV (2^-24 of 16384 texels, 1e-3)
// and less than the chart's inset in its box (> kMargin), so the chart stays inside its box.
constexpr double kSlack = 1.0 / 128;
struct Footprint {
  int32_t w = 0, h = 0;
  std::vector<int32_t> top, bottom;  // per column
  std::vector<int32_t> left, right;  // per row
  V2 inset = V2::Zero();             // the chart's corner (0, 0) in its box, in texels
};

Footprint footprint(const Chart& c, double s) {
  Footprint f;
  f.w = int32_t(cells(c.extent.x(), s));
  f.h = int32_t(cells(c.extent.y(), s));
  f.inset = V2((f.w - c.extent.x() * s) / 2, (f.h - c.extent.y() * s) / 2);
  f.top.assign(size_t(f.w), f.h);
  f.bottom.assign(size_t(f.w), -1);
  f.left.assign(size_t(f.h), f.w);
  f.right.assign(size_t(f.h), -1);
  for (const auto& k : c.corners) {
    const V2 t[3] = {f.inset + c.uv[k[0]] * s, f.inset + c.uv[k[1]] * s, f.inset + c.uv[k[2]] * s};
    for (int a = 0; a < 2; ++a) {
      const double lo = std::min({t[0][a], t[1][a], t[2][a]}), hi = std::max({t[0][a], t[1][a], t[2][a]});
      const int32_t n = a == 0 ? f.w : f.h, other = a == 0 ? f.h : f.w;
      const int32_t first = std::max(0, int32_t(std::floor(lo - kSlack)));
      const int32_t last = std::min(n - 1, int32_t(std::floor(hi + kSlack)));
      std::vector<int32_t>& low = a == 0 ? f.top : f.left;
      std::vector<int32_t>& high = a == 0 ? f.bottom : f.right;
      for (int32_t i = first; i <= last; ++i) {
        const auto [mn, mx] = slab_span(t, a, double(i) - kSlack, double(i) + 1 + kSlack);
        if (mn > mx) continue;
        low[size_t(i)] = std::min(low[size_t(i)], std::max(0, int32_t(std::floor(mn - kSlack))));
        high[size_t(i)] = std::max(high[size_t(i)], std::min(other - 1, int32_t(std::floor(mx + kSlack))));
      }
    }
  }
  // A connected chart touches every column and row of its box; fill any gap conservatively.
  for (int32_t col = 0; col < f.w; ++col)
    if (f.bottom[size_t(col)] < 0) f.top[size_t(col)] = 0, f.bottom[size_t(col)] = f.h - 1;
  for (int32_t r = 0; r < f.h; ++r)
    if (f.right[size_t(r)] < 0) f.left[size_t(r)] = 0, f.right[size_t(r)] = f.w - 1;
  return f;
}

// A footprint's column profile turned by rotation r (0°, 90°, 180°, 270° about its box, each
// keeping windings: header step 3): width, height, first and last row per column.
struct Profile {
  int32_t w = 0, h = 0;
  std::vector<int32_t> top, bottom;
};

Profile profile(const Footprint& f, int r) {
  Profile p;
  const bool turned = r % 2 == 1;
  p.w = turned ? f.h : f.w;
  p.h = turned ? f.w : f.h;
  p.top.resize(size_t(p.w));
  p.bottom.resize(size_t(p.w));
  for (int32_t c = 0; c < p.w; ++c) {
    const size_t i = size_t(c), mirrored = size_t(p.w - 1 - c);
    switch (r) {
    case 0: p.top[i] = f.top[i], p.bottom[i] = f.bottom[i]; break;
    case 1: p.top[i] = f.left[mirrored], p.bottom[i] = f.right[mirrored]; break;  // (u, v) -> (h − v, u)
    case 2: p.top[i] = f.h - 1 - f.bottom[mirrored], p.bottom[i] = f.h - 1 - f.top[mirrored]; break;  // (w − u, h − v)
    default: p.top[i] = f.w - 1 - f.right[i], p.bottom[i] = f.w - 1 - f.left[i]; break;  // (v, w − u)
    }
  }
  return p;
}

// Texel position of point q of a footprint's box after rotation r (Profile), the box at (x, y).
V2 placed(const Footprint& f, int r, const V2& q, int64_t x, int64_t y) {
  V2 p = q;
  switch (r) {
  case 1: p = V2(f.h - q.y(), q.x()); break;
  case 2: p = V2(f.w - q.x(), f.h - q.y()); break;
  case 3: p = V2(q.y(), f.w - q.x()); break;
  default: break;
  }
  return p + V2(double(x), double(y));
}

struct Placement {
  int64_t x = 0, y = 0;
  int rotation = 0;
};

// Horizon packing (header, step 3) at density s into W × H. False when a chart does not fit.
bool pack(const std::vector<Chart>& charts, double s, uint32_t min_texels, uint32_t gutter, uint32_t W, uint32_t H,
          std::vector<Footprint>& prints, std::vector<Placement>& where) {
  const int64_t G = gutter, near = G / 2, far = G - G / 2;  // border margins: near at 0, far at W, H
  const double side = std::max(W, H);
  prints.resize(charts.size());
  std::vector<uint32_t> order(charts.size());
  for (uint32_t i = 0; i < charts.size(); ++i) {
    const double sc = chart_density(charts[i], s, min_texels);
    if (!(charts[i].extent.x() * sc < side)) return false;  // in no rotation
    prints[i] = footprint(charts[i], sc);
    order[i] = i;
  }
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    const int64_t aa = int64_t(prints[a].w) * prints[a].h, ab = int64_t(prints[b].w) * prints[b].h;
    return aa != ab ? aa > ab : a < b;
  });
  where.assign(charts.size(), {});
  std::vector<int64_t> horizon(W, 0);  // per column one past the lowest texel taken; 0: none yet
  std::vector<int64_t> dilated;
  for (uint32_t i : order) {
    int64_t best_bottom = std::numeric_limits<int64_t>::max(), best_x = 0, best_y = 0;
    int best_r = -1;
    for (int r = 0; r < 4; ++r) {
      const Profile p = profile(prints[i], r);
      if (p.w + near + far > int64_t(W) || p.h + near + far > int64_t(H)) continue;
      int64_t top_min = p.h, bottom_max = 0;
      for (int32_t c = 0; c < p.w; ++c) {
        top_min = std::min<int64_t>(top_min, p.top[size_t(c)]);
        bottom_max = std::max<int64_t>(bottom_max, p.bottom[size_t(c)]);
      }
      // The profile's top dilated by G: column d − G (d = 0 … w + 2G − 1) takes the least top of
      // the columns within G of it, less G.
      dilated.assign(size_t(p.w + 2 * G), std::numeric_limits<int64_t>::max());
      for (int32_t c = 0; c < p.w; ++c)
        for (int64_t d = c; d <= c + 2 * G; ++d) dilated[size_t(d)] = std::min(dilated[size_t(d)], int64_t(p.top[size_t(c)]) - G);
      // The lowest bottom any position can give: nothing can beat it, so the scan stops there.
      const int64_t floor_bottom = near - top_min + bottom_max;
      const int64_t probes[3] = {G, G + p.w / 2, G + p.w - 1};  // profile columns for a cheap lower bound
      for (int64_t x = near; x + p.w + far <= int64_t(W) && best_bottom > floor_bottom; ++x) {
        int64_t y = near - top_min;
        for (const int64_t d : probes)
          if (const int64_t h = horizon[size_t(x - G + d)]; h != 0) y = std::max(y, h - dilated[size_t(d)]);
        // A lower bound already no better, or past the atlas's bottom.
        if (y + bottom_max >= best_bottom || y + bottom_max + far >= int64_t(H)) continue;
        const int64_t d0 = std::max<int64_t>(0, G - x), d1 = std::min<int64_t>(p.w + 2 * G, int64_t(W) - x + G);
        for (int64_t d = d0; d < d1; ++d)
          if (const int64_t h = horizon[size_t(x - G + d)]; h != 0) y = std::max(y, h - dilated[size_t(d)]);
        const int64_t bottom = y + bottom_max;
        if (bottom + far >= int64_t(H)) continue;
        if (bottom < best_bottom) best_bottom = bottom, best_x = x, best_y = y, best_r = r;
      }
    }
    if (best_r < 0) return false;
    where[i] = {best_x, best_y, best_r};
    const Profile best = profile(prints[i], best_r);
    for (int32_t c = 0; c < best.w; ++c)
      horizon[size_t(best_x + c)] = std::max(horizon[size_t(best_x + c)], best_y + best.bottom[size_t(c)] + 1);
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
  auto fits = [&](double s, uint32_t W, uint32_t H) {
    return pack(charts, s, o.min_chart_texels, o.gutter, W, H, prints, where);
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
