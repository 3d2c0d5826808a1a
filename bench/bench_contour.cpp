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

#include <bake/bake/vertex_bake.h>
#include <bake/visibility/contour.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <iterator>
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
std::vector<int8_t> face_sides(const bench::Scene& s, const bake::ShadePoint& point) {
  const auto& topo = s.topology;
  std::vector<int8_t> sides(s.mesh.triangles.size(), 0);
  for (size_t f = 0; f < sides.size(); ++f) {
    const auto& t = s.mesh.triangles[f];
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
          const std::vector<int8_t> sp = face_sides(s, p), sq = face_sides(s, q);
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

}  // namespace

int main() {
  try {
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
