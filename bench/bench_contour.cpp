// bench_contour — the contour search alone (bake/visibility/contour.h), against triangle count: for each
// subdivision level of the benchmark scene (bench_common.h), CPU µs per ContourFinder::find on
// the benchmark's shade points, the contour edges found and the query counters (nodes visited,
// records tested, exact decisions), and the growth exponents of time and of edge count against
// triangles between consecutive levels. With PRT_BENCH_CHECK=1 every query is also compared with
// find_brute_force (slow at the finest levels).
//
// With PRT_BENCH_NEIGHBOURS=1, a second table: coherence between neighbouring shade points, what
// an exact update of the contour set from a neighbour's would have to redo. A face CHANGES between
// shade points p and p' when orient_eps of its corners differs (its plane separates them, or
// contains one of them and the normals decide otherwise); only the edges of changed faces can
// change their side sums, so they are the edges such an update re-decides. For each shade point
// p (bunny and ground apart) and two neighbours p' — the vertex at the lowest welded neighbour
// along a mesh edge, and the next vertex index (the bake's order) — the mean distance |p − p'|,
// the contour edges at p, the changed faces, the edges re-decided and the size of the symmetric
// difference of the two contour sets.
//
//   PRT_BENCH_LEVELS  default 0,1,2,3     PRT_BENCH_REPEAT  passes over the points (default 20)
//   PRT_BENCH_POINTS, PRT_BENCH_SEED (bench_common.h)
#include <bench_common.h>

#include <bake/bake/lightmap_receivers.h>
#include <bake/bake/vertex_bake.h>
#include <bake/mesh/texels.h>
#include <bake/mesh/unwrap.h>
#include <bake/sphere/sampling.h>
#include <bake/mesh/mesh.h>
#include <bake/mesh/predicates.h>
#include <bake/mesh/shade_point.h>
#include <Eigen/Core>
// The texel probe below reads the finder's tree (bench only: the layout is unchanged; every
// header contour.h includes is included first, so only ContourFinder is opened).
#define private public
#include <bake/visibility/contour.h>
#undef private

#include <algorithm>
#include <bit>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <iterator>
#include <string>
#include <vector>

using namespace prt;

namespace {

struct Row {
  size_t triangles = 0;
  double us = 0, edges = 0;
  bake::ContourQueryStats q;
  double build_s = 0;
};

// orient_eps of each face's corners (triangle order) seen from the point; 0 for a face with a
// repeated welded corner (it has σ = 0 on every edge).
std::vector<int8_t> face_sides(const bake::Mesh& mesh, const bake::Topology& topo, const bake::ShadePoint& point) {
  std::vector<int8_t> sides(mesh.triangles.size(), 0);
  for (size_t f = 0; f < sides.size(); ++f) {
    const auto& t = mesh.triangles[f];
    const uint32_t w0 = topo.weld[t[0]], w1 = topo.weld[t[1]], w2 = topo.weld[t[2]];
    if (w0 == w1 || w1 == w2 || w0 == w2) continue;
    sides[f] = int8_t(bake::orient_eps(topo.welded_positions[w0].cast<double>(), topo.welded_positions[w1].cast<double>(),
                                       topo.welded_positions[w2].cast<double>(), point.p, point.n, bake::tie_break(point)));
  }
  return sides;
}

void neighbour_table(const std::vector<long>& levels) {
  std::printf("\n| level | triangles | points | neighbour | mean distance | contour edges | changed faces | "
              "re-decided edges | set difference |\n");
  std::printf("|---:|---:|---|---|---:|---:|---:|---:|---:|\n");
  for (const long level : levels) {
    const bench::Scene& s = bench::scene(int(level));
    const auto& topo = s.topology;
    const bake::ContourFinder finder(s.mesh, topo);
    std::vector<uint32_t> lowest(topo.welded_positions.size(), UINT32_MAX), vertex_of(lowest);
    for (const auto& [a, b] : topo.edges) {
      lowest[a] = std::min(lowest[a], b);
      lowest[b] = std::min(lowest[b], a);
    }
    for (uint32_t v = uint32_t(topo.weld.size()); v-- > 0;) vertex_of[topo.weld[v]] = v;
    const auto by_edge_and_sum = [](const bake::ContourEdge& x, const bake::ContourEdge& y) {
      return x.edge != y.edge ? x.edge < y.edge : x.side_sum < y.side_sum;
    };
    for (const bool ground : {false, true})
      for (const bool along_edge : {true, false}) {
        double distance = 0, contour = 0, changed = 0, redecided = 0, difference = 0;
        size_t pairs = 0;
        std::vector<bake::ContourEdge> at_p, at_q, diff;
        std::vector<uint32_t> edges;
        for (size_t i = 0; i < s.vertices.size(); ++i) {
          const uint32_t v = s.vertices[i];
          if ((v >= s.bunny_vertices) != ground) continue;
          const uint32_t next = along_edge ? vertex_of[lowest[topo.weld[v]]]
                                           : (v + 1 < s.mesh.positions.size() ? v + 1 : v - 1);
          const bake::ShadePoint q = bake::vertex_shade_point(s.mesh, topo, next);
          const bake::ShadePoint& p = s.points[i];
          const std::vector<int8_t> sp = face_sides(s.mesh, topo, p), sq = face_sides(s.mesh, topo, q);
          edges.clear();
          for (size_t f = 0; f < sp.size(); ++f) {
            if (sp[f] == sq[f]) continue;
            changed += 1;
            const auto& t = s.mesh.triangles[f];
            for (int k = 0; k < 3; ++k)
              if (const auto e = topo.find_edge(topo.weld[t[size_t(k)]], topo.weld[t[size_t((k + 1) % 3)]])) edges.push_back(*e);
          }
          std::sort(edges.begin(), edges.end());
          redecided += double(std::unique(edges.begin(), edges.end()) - edges.begin());
          finder.find(p, at_p);
          finder.find(q, at_q);
          diff.clear();
          std::set_symmetric_difference(at_p.begin(), at_p.end(), at_q.begin(), at_q.end(), std::back_inserter(diff),
                                        by_edge_and_sum);
          distance += (q.p - p.p).norm();
          contour += double(at_p.size());
          difference += double(diff.size());
          ++pairs;
        }
        if (pairs == 0) continue;
        const double n = double(pairs);
        std::printf("| %ld | %zu | %s | %s | %.3g | %.0f | %.0f | %.0f | %.0f |\n", level, s.mesh.triangles.size(),
                    ground ? "ground" : "bunny", along_edge ? "mesh edge" : "next index", distance / n, contour / n,
                    changed / n, redecided / n, difference / n);
        std::fflush(stdout);
      }
  }
}


// ---- Texel neighbours (issue 30) ----------------------------------------------------------

struct PairStats {
  double distance = 0, contour = 0, changed = 0, redecided = 0, difference = 0;
  size_t pairs = 0;
};

// The vertex table's columns for one pair (p, p′), added to `acc`.
void measure_pair(const bake::Mesh& mesh, const bake::Topology& topo, const bake::ContourFinder& finder,
                  const bake::ShadePoint& p, const bake::ShadePoint& q, PairStats& acc) {
  const std::vector<int8_t> sp = face_sides(mesh, topo, p), sq = face_sides(mesh, topo, q);
  std::vector<uint32_t> edges;
  for (size_t f = 0; f < sp.size(); ++f) {
    if (sp[f] == sq[f]) continue;
    acc.changed += 1;
    const auto& t = mesh.triangles[f];
    for (int k = 0; k < 3; ++k)
      if (const auto e = topo.find_edge(topo.weld[t[size_t(k)]], topo.weld[t[size_t((k + 1) % 3)]])) edges.push_back(*e);
  }
  std::sort(edges.begin(), edges.end());
  acc.redecided += double(std::unique(edges.begin(), edges.end()) - edges.begin());
  std::vector<bake::ContourEdge> at_p, at_q, diff;
  finder.find(p, at_p);
  finder.find(q, at_q);
  std::set_symmetric_difference(at_p.begin(), at_p.end(), at_q.begin(), at_q.end(), std::back_inserter(diff),
                                [](const bake::ContourEdge& x, const bake::ContourEdge& y) {
                                  return x.edge != y.edge ? x.edge < y.edge : x.side_sum < y.side_sum;
                                });
  acc.distance += (q.p - p.p).norm();
  acc.contour += double(at_p.size());
  acc.difference += double(diff.size());
  ++acc.pairs;
}

void print_pair_row(const std::string& mesh, size_t triangles, const char* neighbour, const std::string& atlas,
                    size_t texels, const char* part, const PairStats& a) {
  if (a.pairs == 0) return;
  const double n = double(a.pairs), c = a.contour;
  std::printf("| %s | %zu | %s | %s | %zu | %s | %zu | %.3g | %.0f | %.1f | %.1f | %.1f | %.3f | %.3f | %.3f |\n",
              mesh.c_str(), triangles, neighbour, atlas.c_str(), texels, part, a.pairs, a.distance / n, c / n,
              a.changed / n, a.redecided / n, a.difference / n, a.changed / c, a.redecided / c, a.difference / c);
  std::fflush(stdout);
}

std::vector<std::string> texel_meshes() {
  const std::string data = PRT_DATA_DIR;
  if (const char* v = std::getenv("PRT_BENCH_MESHES"); v && *v) {
    std::vector<std::string> out;
    std::string cur;
    for (const char* c = v;; ++c) {
      if (*c == ',' || *c == 0) {
        if (!cur.empty()) out.push_back(cur.find('/') == std::string::npos ? data + "/" + cur : cur);
        cur.clear();
        if (*c == 0) break;
      } else {
        cur += *c;
      }
    }
    return out;
  }
  std::vector<std::string> out = {data + "/bunny.obj", data + "/bunny_ground.obj"};
  for (const std::filesystem::path& p : {std::filesystem::path(data) / "2CylinderEngine.glb",
                                        std::filesystem::path("/work/shared/data/2CylinderEngine.glb")})
    if (std::filesystem::exists(p)) {
      out.push_back(p.string());
      break;
    }
  return out;
}

struct TexelMesh {
  std::string name;
  bake::Mesh mesh;
  bake::Topology topology;
  uint32_t bunny_vertices = 0;  // bunny_ground.obj: texels on triangles of vertices below this are the bunny's
};

// A generated lightmap as `prtbake texel --unwrap --size side` makes it (LightmapSpec's defaults:
// gutter 2, thin charts at least 3 texels; the enclosure test, which only drops texels inside the
// geometry, is left out).
bake::TexelAtlas make_atlas(const TexelMesh& m, uint32_t side) {
  bake::UnwrapOptions o;
  o.width = o.height = side;
  o.gutter = bake::LightmapSpec{}.gutter;
  o.min_chart_texels = bake::LightmapSpec{}.min_chart_texels;
  o.max_side = bake::kMaxLightmapSide;
  const bake::Unwrapped u = bake::unwrap(m.mesh, m.topology, o);
  return bake::texel_atlas(m.mesh, m.topology, u.uv, side, side, m.name);
}

// Sample index of each texel (−1: not covered).
std::vector<int32_t> texel_index(const bake::TexelAtlas& atlas) {
  std::vector<int32_t> idx(size_t(atlas.width) * atlas.height, -1);
  for (size_t i = 0; i < atlas.samples.size(); ++i) idx[atlas.samples[i].texel] = int32_t(i);
  return idx;
}

// The right neighbour of sample i in its chart, else the one below, else −1.
int32_t texel_neighbour(const bake::TexelAtlas& atlas, const std::vector<int32_t>& idx, size_t i) {
  const auto& s = atlas.samples[i];
  const uint32_t x = s.texel % atlas.width, y = s.texel / atlas.width;
  if (x + 1 < atlas.width) {
    const int32_t j = idx[s.texel + 1];
    if (j >= 0 && atlas.samples[size_t(j)].chart == s.chart) return j;
  }
  if (y + 1 < atlas.height) {
    const int32_t j = idx[s.texel + atlas.width];
    if (j >= 0 && atlas.samples[size_t(j)].chart == s.chart) return j;
  }
  return -1;
}

void texel_tables(const std::vector<TexelMesh>& meshes, const std::vector<long>& sizes) {
  std::printf("\n| mesh | triangles | neighbour | atlas | texels | part | pairs | mean distance | contour edges | "
              "changed faces | re-decided edges | set difference | changed / contour | re-decided / contour | "
              "difference / contour |\n");
  std::printf("|---|---:|---|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  const size_t want = bench::n_points();
  for (const TexelMesh& m : meshes) {
    const auto& topo = m.topology;
    const bake::ContourFinder finder(m.mesh, topo);
    const bool split = m.bunny_vertices > 0;
    {  // the vertex table's mesh-edge neighbour on the same mesh, for comparison
      std::vector<uint32_t> lowest(topo.welded_positions.size(), UINT32_MAX), vertex_of(lowest);
      for (const auto& [a, b] : topo.edges) {
        lowest[a] = std::min(lowest[a], b);
        lowest[b] = std::min(lowest[b], a);
      }
      for (uint32_t v = uint32_t(topo.weld.size()); v-- > 0;) vertex_of[topo.weld[v]] = v;
      PairStats acc[2];
      for (const uint32_t v : bake::seeded_sample(uint32_t(m.mesh.positions.size()), want, bench::sample_seed())) {
        if (lowest[topo.weld[v]] == UINT32_MAX) continue;
        const bake::ShadePoint p = bake::vertex_shade_point(m.mesh, topo, v);
        const bake::ShadePoint q = bake::vertex_shade_point(m.mesh, topo, vertex_of[lowest[topo.weld[v]]]);
        measure_pair(m.mesh, topo, finder, p, q, acc[split && v >= m.bunny_vertices]);
      }
      print_pair_row(m.name, m.mesh.triangles.size(), "vertex, mesh edge", "–", 0, split ? "bunny" : "all", acc[0]);
      if (split) print_pair_row(m.name, m.mesh.triangles.size(), "vertex, mesh edge", "–", 0, "ground", acc[1]);
    }
    for (const long side : sizes) {
      bake::TexelAtlas atlas;
      try {
        atlas = make_atlas(m, uint32_t(side));
      } catch (const std::exception& e) {
        std::printf("| %s | %zu | texel | %ld² | – | – | 0 | %s | | | | | | | |\n", m.name.c_str(), m.mesh.triangles.size(),
                    side, e.what());
        continue;
      }
      const std::vector<int32_t> idx = texel_index(atlas);
      PairStats acc[2];
      // Up to `want` pairs per part, from one seeded sample of candidate texels.
      const size_t pool = std::min(atlas.samples.size(), 50 * want);
      for (const uint32_t i : bake::seeded_sample(uint32_t(atlas.samples.size()), pool, bench::sample_seed())) {
        const auto& tri = m.mesh.triangles[atlas.samples[i].triangle];
        PairStats& a = acc[split && tri[0] >= m.bunny_vertices];
        if (a.pairs == want) continue;
        const int32_t j = texel_neighbour(atlas, idx, i);
        if (j < 0) continue;
        measure_pair(m.mesh, topo, finder, atlas.receivers.points[i], atlas.receivers.points[size_t(j)], a);
      }
      const std::string a = std::to_string(side) + "²";
      print_pair_row(m.name, m.mesh.triangles.size(), "texel, right or down", a, atlas.samples.size(),
                     split ? "bunny" : "all", acc[0]);
      if (split)
        print_pair_row(m.name, m.mesh.triangles.size(), "texel, right or down", a, atlas.samples.size(), "ground", acc[1]);
    }
  }
}

// ---- Probe (bench only): the contour set kept between neighbouring texels --------------------
//
// The finder's tree walk stops at a FRONTIER: pruned children (every record under them has both
// face values of one sign, beyond the node tolerance) and leaf records (decided from their float
// values, or exactly). Each frontier item carries a MARGIN, a lower bound of how far its exact
// values are from 0 in the finder's frame (contour.cpp: the exact value s·π(p)/|N| is within
// δ_node of a node's float range, within δ_rec of a record's float value): a pruned child
// min(vmin − δ_node, −δ_node − vmax), a record min(|v1|, |v2|) − δ_rec (0 when orient_eps decided
// it), an always-tested edge min over its faces of |v| − δ_a (0 when any face was exact). The exact
// values are 1-Lipschitz in q (unit plane normals), so an item's decision cannot change while the
// path the shade point travels from where it was tested, Σ|q_i − q_{i−1}|₂, stays below its
// margin. The probe keeps the items in a min-heap on margin + path length at the test and, at
// the next point, re-tests only the items whose key the path has reached (a re-tested child
// that now straddles is opened, never closed again), updating a persistent bitmap of contour
// edges; the normal and tie-break only enter exact decisions (margin 0, re-tested every time).
// Restarted (a full walk from the root) whenever the point is not its predecessor's right
// neighbour in the same chart. Checked against find() on every query.
typedef float pf4 __attribute__((vector_size(16)));
typedef int32_t pi4 __attribute__((vector_size(16)));
inline pf4 pload(const float* x) {
  pf4 v;
  std::memcpy(&v, x, sizeof v);
  return v;
}
inline pf4 psplat(float x) { return pf4{x, x, x, x}; }

class CoherentContour {
public:
  explicit CoherentContour(const bake::ContourFinder& f) : f_(f) {
    const size_t E = f.topology_->edges.size();
    bits_.assign((E + 63) / 64, 0);
    sums_.assign(E, 0);
  }
  void find(const bake::ShadePoint& point, bool restart, std::vector<bake::ContourEdge>& out);
  uint64_t restarts = 0, retests = 0, queries = 0, by_kind[3] = {0, 0, 0}, zero = 0;
  uint64_t flips = 0;        // re-tests that changed an edge's decision
  uint64_t local = 0;        // re-tested records with a corner within `near` of the point (world units)
  double near = 0;
  bool in_retest = false;
  size_t heap_size() const {
    size_t n = far_.size();
    for (const auto& b : ring_) n += b.size();
    return n;
  }

private:
  enum Kind : uint32_t { kChild, kRecord, kAlways };
  struct Item {
    double key;
    uint32_t id, kind;
  };
  static bool later(const Item& a, const Item& b) { return a.key > b.key; }
  void push(double margin, uint32_t id, Kind kind) {
    if (!(margin >= 0)) margin = 0;  // NaN: re-test every time
    zero += margin == 0;
    if (margin == std::numeric_limits<double>::infinity()) return;  // never changes (empty slot, padding)
    pending_.push_back({margin + path_, id, kind});
  }
  void set(uint32_t e, int s) {
    if (in_retest) {
      const bool was = bits_[e >> 6] >> (e & 63) & 1;
      flips += was != (s != 0) || (was && sums_[e] != s);
    }
    if (s != 0) {
      sums_[e] = s;
      bits_[e >> 6] |= uint64_t(1) << (e & 63);
    } else {
      bits_[e >> 6] &= ~(uint64_t(1) << (e & 63));
    }
  }
  void child(uint32_t w, int k, float vmin, float vmax);
  void open(uint32_t w);
  void record(uint32_t block, int j);
  void always(uint32_t i);

  const bake::ContourFinder& f_;
  std::vector<uint64_t> bits_;
  std::vector<int32_t> sums_;
  // The items by key: a ring of kRing buckets of width w_ (keys below (next_ + kRing)·w_, bucket
  // ⌊key / w_⌋ mod kRing) and a min-heap of the rest (far_), moved into the ring as the path
  // advances; w_ is the first step's length.
  static constexpr uint64_t kRing = 256;
  void place(const Item& it) {
    const double b = w_ > 0 ? std::floor(it.key / w_) : 1e300;
    if (b < double(next_ + kRing)) ring_[uint64_t(b) % kRing].push_back(it);
    else {
      far_.push_back(it);
      std::push_heap(far_.begin(), far_.end(), later);
    }
  }
  void retest(const Item& it);
  std::vector<Item> ring_[kRing], far_, pending_, keep_;
  uint64_t next_ = 0;
  double w_ = 0;
  double path_ = 0, prev_q_[3] = {0, 0, 0};
  // The query's values (find_impl's).
  double p_[3], n_[3], q_[3];
  const double* t_ = nullptr;
  pf4 qx_, qy_, qz_;
  float dn_ = 0, dr_ = 0, da_ = 0;
};

void CoherentContour::child(uint32_t w, int k, float vmin, float vmax) {
  const uint32_t c = f_.wide_[w].child[k];
  if (vmin <= dn_ && vmax >= -dn_) {  // straddles: open it
    if (c & bake::ContourFinder::kLeafBit)
      for (int j = 0; j < 4; ++j) record(c & ~bake::ContourFinder::kLeafBit, j);
    else
      open(c);
    return;
  }
  push(vmin > dn_ ? double(vmin) - double(dn_) : -double(dn_) - double(vmax), 4 * w + uint32_t(k), kChild);
}

void CoherentContour::open(uint32_t w) {
  const auto& node = f_.wide_[w];
  pf4 vmin = pload(node.dlo), vmax = pload(node.dhi);
  const pf4 q3[3] = {qx_, qy_, qz_};
  for (int i = 0; i < 3; ++i) {
    const pf4 x = q3[i] - pload(node.c[i]);
    const pf4 a = x * pload(node.nlo[i]), b = x * pload(node.nhi[i]);
    vmin += a < b ? a : b;
    vmax += b > a ? b : a;
  }
  for (int k = 0; k < 4; ++k) child(w, k, vmin[k], vmax[k]);
}

void CoherentContour::record(uint32_t block, int j) {
  const auto& blk = f_.blocks_[block];
  const pf4 v1 = pload(blk.g[0]) * qx_ + pload(blk.g[1]) * qy_ + pload(blk.g[2]) * qz_ + pload(blk.g[3]);
  const pf4 v2 = pload(blk.g[4]) * qx_ + pload(blk.g[5]) * qy_ + pload(blk.g[6]) * qz_ + pload(blk.g[7]);
  const float a = v1[j], b = v2[j];
  const uint32_t edge = blk.edge[j] & ~bake::ContourFinder::kFlipBit;
  const int two = (blk.edge[j] & bake::ContourFinder::kFlipBit) ? -2 : 2;
  int s;
  double margin = std::min(std::abs(double(a)), std::abs(double(b))) - double(dr_);
  if ((a > dr_ && b > dr_) || (a < -dr_ && b < -dr_)) s = 0;
  else if (a > dr_ && b < -dr_) s = -two;
  else if (a < -dr_ && b > dr_) s = two;
  else {
    const auto& c = f_.corners_[size_t(block) * 4 + size_t(j)];
    s = bake::predicates_detail::orient_eps_f(c.a, c.b, c.c1, p_, n_, t_) +
        bake::predicates_detail::orient_eps_f(c.a, c.b, c.c2, p_, n_, t_);
    margin = 0;
  }
  if (a == 1e38f && b == 1e38f) return;  // padding lane
  if (in_retest && near > 0) {
    const auto& c = f_.corners_[size_t(block) * 4 + size_t(j)];
    const double d = std::hypot(c.a[0] - p_[0], c.a[1] - p_[1], c.a[2] - p_[2]);
    local += d < near;
  }
  set(edge, s);
  push(margin, 4 * block + uint32_t(j), kRecord);
}

void CoherentContour::always(uint32_t i) {
  int s = 0;
  double margin = std::numeric_limits<double>::max();
  for (uint32_t f = i ? f_.always_end_[i - 1] : 0; f < f_.always_end_[i]; ++f) {
    const auto& fb = f_.always_blocks_[f / 4];
    const int j = int(f % 4);
    const float v = fb.g[0][j] * float(q_[0]) + fb.g[1][j] * float(q_[1]) + fb.g[2][j] * float(q_[2]) + fb.g[3][j];
    if (v > da_) s -= 1;
    else if (v < -da_) s += 1;
    else {
      const auto& af = f_.always_faces_[f];
      s += bake::predicates_detail::orient_eps_f(af.a, af.b, af.c, p_, n_, t_);
      margin = 0;
      continue;
    }
    margin = std::min(margin, std::abs(double(v)) - double(da_));
  }
  set(f_.always_[i], s);
  push(margin, i, kAlways);
}

void CoherentContour::retest(const Item& it) {
  in_retest = true;
  struct Off {
    bool& b;
    ~Off() { b = false; }
  } off{in_retest};
  ++retests;
  ++by_kind[it.kind];
  if (it.kind == kRecord) record(it.id / 4, int(it.id % 4));
  else if (it.kind == kAlways) always(it.id);
  else {  // the child's bound at this point
    const uint32_t w = it.id / 4;
    const int k = int(it.id % 4);
    const auto& node = f_.wide_[w];
    pf4 vmin = pload(node.dlo), vmax = pload(node.dhi);
    const pf4 q3[3] = {qx_, qy_, qz_};
    for (int i = 0; i < 3; ++i) {
      const pf4 x = q3[i] - pload(node.c[i]);
      const pf4 a = x * pload(node.nlo[i]), b = x * pload(node.nhi[i]);
      vmin += a < b ? a : b;
      vmax += b > a ? b : a;
    }
    child(w, k, vmin[k], vmax[k]);
  }
}

void CoherentContour::find(const bake::ShadePoint& point, bool restart, std::vector<bake::ContourEdge>& out) {
  ++queries;
  const auto& o = f_.origin_;
  const double s = f_.scale_;
  p_[0] = point.p.x(), p_[1] = point.p.y(), p_[2] = point.p.z();
  n_[0] = point.n.x(), n_[1] = point.n.y(), n_[2] = point.n.z();
  t_ = bake::tie_break(point) ? point.t.data() : nullptr;
  q_[0] = (p_[0] - o.x()) * s, q_[1] = (p_[1] - o.y()) * s, q_[2] = (p_[2] - o.z()) * s;
  const double aq = std::abs(q_[0]) + std::abs(q_[1]) + std::abs(q_[2]);
  if (!(aq < 1e30)) throw std::runtime_error("probe: point beyond float");
  const double delta = f_.delta_coef_ * (aq + f_.max_a_);
  dr_ = float(delta + f_.record_coef_ * (aq + f_.max_a_));
  dn_ = float(delta + f_.node_coef_ * (aq + f_.node_const_));
  da_ = float(f_.always_coef_ * (aq + f_.always_max_a_));
  qx_ = psplat(float(q_[0])), qy_ = psplat(float(q_[1])), qz_ = psplat(float(q_[2]));
  pending_.clear();
  if (restart || w_ == 0) {
    ++restarts;
    std::fill(bits_.begin(), bits_.end(), 0);
    for (auto& b : ring_) b.clear();
    far_.clear();
    path_ = 0;
    next_ = 0;
    if (!f_.wide_.empty()) open(0);
    for (uint32_t i = 0; i < f_.always_.size(); ++i) always(i);
    if (w_ <= 0) {  // until the first step is known: everything far
      far_.swap(pending_);
      std::make_heap(far_.begin(), far_.end(), later);
    } else {
      for (const Item& it : pending_)
        if (it.key < double(kRing) * w_) ring_[uint64_t(it.key / w_) % kRing].push_back(it);
        else far_.push_back(it);
      std::make_heap(far_.begin(), far_.end(), later);
    }
    w_ = w_ == 0 ? -1 : w_;
  } else {
    // Path length in q (Euclidean: the unit normals make the exact values 1-Lipschitz in it),
    // rounded up: the exact points are within ~u·|q| of the computed ones.
    const double prev = std::abs(prev_q_[0]) + std::abs(prev_q_[1]) + std::abs(prev_q_[2]);
    const double dx = q_[0] - prev_q_[0], dy = q_[1] - prev_q_[1], dz = q_[2] - prev_q_[2];
    const double step = std::sqrt(dx * dx + dy * dy + dz * dz) * (1 + 1e-12) + 1e-14 * (aq + prev);
    path_ += step;
    if (w_ < 0 && step > 0) {  // the first step sets the bucket width; the far heap is sorted into the ring
      w_ = step;
      std::vector<Item> all;
      all.swap(far_);
      for (const Item& it : all) place(it);
    }
    const uint64_t last = w_ > 0 ? uint64_t(std::floor(path_ / w_)) : 0;
    // Buckets before `last` are due entirely; bucket `last` up to path_; far items up to path_.
    for (uint64_t i = next_; w_ > 0 && i <= last && i < next_ + kRing; ++i) {
      auto& b = ring_[i % kRing];
      keep_.clear();
      for (const Item& it : b)
        if (it.key <= path_) retest(it);
        else keep_.push_back(it);
      b.swap(keep_);
    }
    while (!far_.empty() && far_.front().key <= path_) {
      std::pop_heap(far_.begin(), far_.end(), later);
      const Item it = far_.back();
      far_.pop_back();
      retest(it);
    }
    next_ = last;
    while (w_ > 0 && !far_.empty() && far_.front().key < double(next_ + kRing) * w_) {
      std::pop_heap(far_.begin(), far_.end(), later);
      const Item it = far_.back();
      far_.pop_back();
      ring_[uint64_t(std::floor(it.key / w_)) % kRing].push_back(it);
    }
    for (const Item& it : pending_) place(it);
  }
  prev_q_[0] = q_[0], prev_q_[1] = q_[1], prev_q_[2] = q_[2];
  out.clear();
  for (size_t w = 0; w < bits_.size(); ++w)
    for (uint64_t b = bits_[w]; b != 0; b &= b - 1) {
      const uint32_t e = uint32_t(w * 64 + size_t(std::countr_zero(b)));
      out.push_back({e, sums_[e]});
    }
}

// Per-query CPU time of find() and of the probe on `count` consecutive texels (atlas scan order)
// from a seeded start, minimum of `runs` runs each; the probe is first checked against find() on
// every query (a difference is an error).
void texel_timing(const std::vector<TexelMesh>& meshes, const std::vector<long>& sizes) {
  const size_t count = size_t(bench::env_long("PRT_BENCH_WINDOW", 20000));
  const long runs = bench::env_long("PRT_BENCH_REPEAT", 5);
  // PRT_BENCH_RESTART: 0 (default) a full walk whenever the texel is not its predecessor's right
  // neighbour in the same chart; 1 only when the chart changes (the path then includes the jumps
  // back to the next row's start).
  const long policy = bench::env_long("PRT_BENCH_RESTART", 0);
  std::printf("\n| mesh | atlas | texels timed | texels per run (restart) | find µs | probe µs | probe / find | "
              "find: node tests + leaf lanes + always-tested edges | probe: items re-tested | decisions changed | "
              "frontier items | contour edges |\n");
  std::printf("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const TexelMesh& m : meshes) {
    const bake::ContourFinder finder(m.mesh, m.topology);
    for (const long side : sizes) {
      bake::TexelAtlas atlas;
      try {
        atlas = make_atlas(m, uint32_t(side));
      } catch (const std::exception&) {
        continue;  // said in the table
      }
      const size_t n = std::min(count, atlas.samples.size());
      const size_t start = bake::seeded_sample(uint32_t(atlas.samples.size() - n + 1), 1, bench::sample_seed())[0];
      std::vector<uint8_t> restart(n, 1);
      for (size_t k = 1; k < n; ++k) {
        const auto &a = atlas.samples[start + k - 1], &b = atlas.samples[start + k];
        restart[k] = policy == 0 ? !(b.texel == a.texel + 1 && b.texel % atlas.width != 0 && b.chart == a.chart)
                                 : b.chart != a.chart;
      }
      const bake::ShadePoint* pts = atlas.receivers.points.data() + start;
      std::vector<bake::ContourEdge> out, ref;
      double edges = 0;
      CoherentContour check(finder);
      {  // "near": 3 mean edge lengths
        double sum = 0;
        for (const auto& [a, b] : m.topology.edges)
          sum += (m.topology.welded_positions[a] - m.topology.welded_positions[b]).cast<double>().norm();
        check.near = 3 * sum / double(m.topology.edges.size());
      }
      bake::ContourQueryStats fs;
      for (size_t k = 0; k < n; ++k) {
        finder.find(pts[k], ref, &fs);
        check.find(pts[k], restart[k] != 0, out);
        if (out != ref)
          throw std::runtime_error(m.name + " " + std::to_string(side) + ": the probe differs from find() at texel " +
                                   std::to_string(atlas.samples[start + k].texel));
        edges += double(ref.size());
      }
      double best_find = 1e300, best_probe = 1e300;
      for (long r = 0; r < runs; ++r) {
        double t0 = bake::thread_cpu_seconds();
        for (size_t k = 0; k < n; ++k) finder.find(pts[k], out);
        best_find = std::min(best_find, bake::thread_cpu_seconds() - t0);
        CoherentContour probe(finder);
        t0 = bake::thread_cpu_seconds();
        for (size_t k = 0; k < n; ++k) probe.find(pts[k], restart[k] != 0, out);
        best_probe = std::min(best_probe, bake::thread_cpu_seconds() - t0);
      }
      const double nq = double(n);
      std::printf("| %s | %ld² | %zu | %.1f | %.2f | %.2f | %.2f | %.0f + %.0f + %.0f | %.1f | %.2f | %zu | %.0f |\n",
                  m.name.c_str(), side, n, nq / double(check.restarts), 1e6 * best_find / nq, 1e6 * best_probe / nq,
                  best_probe / best_find, double(fs.nodes) / nq, double(fs.records) / nq, double(fs.always) / nq,
                  double(check.retests) / nq, double(check.flips) / nq, check.heap_size(), edges / nq);
      std::fflush(stdout);
      if (bench::env_long("PRT_BENCH_DEBUG", 0) != 0)
        std::printf("debug: retests child %.1f record %.1f (within 3 mean edges %.1f) always %.1f, zero-margin pushes "
                    "%.1f, decisions changed %.2f per query\n",
                    double(check.by_kind[0]) / nq, double(check.by_kind[1]) / nq, double(check.local) / nq,
                    double(check.by_kind[2]) / nq, double(check.zero) / nq, double(check.flips) / nq);
    }
  }
}

}  // namespace

int main() {
  try {
    if (bench::env_long("PRT_BENCH_TEXELS", 0) != 0) {
      std::vector<TexelMesh> meshes;
      for (const std::string& path : texel_meshes()) {
        TexelMesh m;
        m.name = std::filesystem::path(path).filename().string();
        m.mesh = bake::load_mesh(path);
        m.topology = bake::build_topology(m.mesh);
        if (m.name == "bunny_ground.obj") m.bunny_vertices = 1839;
        meshes.push_back(std::move(m));
      }
      const auto sizes = bench::env_list("PRT_BENCH_SIZES", {256, 512, 1024});
      if (bench::env_long("PRT_BENCH_TABLE", 1) != 0) texel_tables(meshes, sizes);
      if (bench::env_long("PRT_BENCH_TIMING", 1) != 0) texel_timing(meshes, sizes);
      return 0;
    }
    const auto levels = bench::env_list("PRT_BENCH_LEVELS", {0, 1, 2, 3});
    const long repeat = bench::env_long("PRT_BENCH_REPEAT", 20);
    const bool check = bench::env_long("PRT_BENCH_CHECK", 0) != 0;
    std::printf("| level | triangles | find µs | contour edges | nodes visited | records tested | exact tests | "
                "always tested | BVH nodes | build s | time exp. | edges exp. |\n");
    std::printf("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    Row prev;
    for (const long level : levels) {
      const bench::Scene& s = bench::scene(int(level));
      const double b0 = prt::bake::thread_cpu_seconds();
      const bake::ContourFinder finder(s.mesh, s.topology);
      Row row;
      row.build_s = prt::bake::thread_cpu_seconds() - b0;
      row.triangles = s.mesh.triangles.size();
      std::vector<bake::ContourEdge> out, ref;
      size_t found = 0;
      for (const auto& p : s.points) {  // counters and the check, untimed
        finder.find(p, out, &row.q);
        found += out.size();
        if (check) {
          finder.find_brute_force(p, ref);
          if (out != ref) {
            std::fprintf(stderr, "bench_contour: level %ld: find differs from find_brute_force\n", level);
            return 1;
          }
        }
      }
      const double t0 = prt::bake::thread_cpu_seconds();
      for (long r = 0; r < repeat; ++r)
        for (const auto& p : s.points) finder.find(p, out);
      const double n = double(s.points.size());
      row.us = 1e6 * (prt::bake::thread_cpu_seconds() - t0) / (double(repeat) * n);
      row.edges = double(found) / n;
      const auto per = [n](uint64_t v) { return double(v) / n; };
      char exps[64] = "– | –";
      if (prev.triangles) {
        const double lt = std::log(double(row.triangles) / double(prev.triangles));
        std::snprintf(exps, sizeof exps, "%.2f | %.2f", std::log(row.us / prev.us) / lt,
                      std::log(row.edges / prev.edges) / lt);
      }
      std::printf("| %ld | %zu | %.1f | %.0f | %.0f | %.0f | %.0f | %.0f | %zu | %.3f | %s |\n", level, row.triangles,
                  row.us, row.edges, per(row.q.nodes), per(row.q.records), per(row.q.exact), per(row.q.always),
                  finder.stats().bvh_nodes, row.build_s, exps);
      std::fflush(stdout);
      prev = row;
    }
    if (bench::env_long("PRT_BENCH_NEIGHBOURS", 0) != 0) neighbour_table(levels);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_contour: %s\n", e.what());
    return 1;
  }
  return 0;
}
