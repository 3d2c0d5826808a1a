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
//
// With PRT_BENCH_TEXELS=1, instead: the same columns between neighbouring lightmap texels (issue
// 30), and their ratios to the contour set. For each mesh (PRT_BENCH_MESHES, comma-separated,
// names without a '/' in data/; default bunny.obj, bunny_ground.obj and 2CylinderEngine.glb when
// found) and atlas side (PRT_BENCH_SIZES, default 256,512,1024,2048): the lightmap `prtbake texel
// --unwrap` makes (bake::unwrap with LightmapSpec's defaults, bake::texel_atlas; the enclosure
// test is left out), and for PRT_BENCH_POINTS seeded texels per part (bunny_ground: bunny and
// ground apart) the pair of the texel and its right neighbour in the same chart, else the one
// below; first the mesh-edge vertex neighbour on the same mesh, for comparison. A probe that kept
// the tree walk's frontier between texels was measured and removed (bench/RESULTS.md,
// "Coherence between neighbouring texels").
//
//   PRT_BENCH_LEVELS  default 0,1,2,3     PRT_BENCH_REPEAT  passes over the points (default 20)
//   PRT_BENCH_POINTS, PRT_BENCH_SEED (bench_common.h)
#include <bench_common.h>

#include <bake/bake/lightmap_receivers.h>
#include <bake/bake/vertex_bake.h>
#include <bake/mesh/texels.h>
#include <bake/mesh/unwrap.h>
#include <bake/sphere/sampling.h>
#include <bake/visibility/contour.h>

#include <algorithm>
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
      texel_tables(meshes, bench::env_list("PRT_BENCH_SIZES", {256, 512, 1024, 2048}));
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
