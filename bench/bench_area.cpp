// bench_area — analytic area-light shading per shade point (bake/sphere/spherical_polygon.h,
// bake/sphere/polygon_sh.h; paper 003 §4.1, Fig. 4: its per-core rates are the targets, ≥ 150k shade
// points/s for one quad light with no occluder). One thread; rates are items per CPU second.
//
// Scene: a 1 × 1 quad light at height 1.5 over a 4 × 4 floor; 4096 shade points on the floor
// with normals tilted up to 60° from +z, so a share of them sees the light cross the horizon.
//   BM_QuadIrradiance    horizon clip + Lambert (the diffuse irradiance of the light)
//   BM_QuadIrradianceSH  the same + the SH projection of the clipped polygon at orders 3 and 6
// and with shadows (bake/visibility/visible_region.h; paper 003's target ≥ 17k shade points/s per core for
// 3 lights × 3 occluders): three 1 × 1 quad lights at heights 2.5–3 and three boxes between
// them and the floor (no culling: every box is tested against every light), per shade point the
// boxes' silhouettes, then per light the horizon clip, the visible region and its irradiance:
//   BM_ThreeLightsThreeBoxes/silhouette:1  the boxes as silhouette loops (paper §3.3)
//   BM_ThreeLightsThreeBoxes/silhouette:0  the boxes as their front-facing triangles (§4.4)
// and past a triangle mesh (bake/visibility/occluder_mesh.h: culling by the light's pyramid and plane, then
// the per-triangle union of every kept triangle, both facings):
//   BM_ThreeLightsThreeBoxesMesh/culled:1  the three boxes as one 36-triangle mesh, culled per light
//   BM_ThreeLightsThreeBoxesMesh/culled:0  the same through the unculled reference
//   BM_BunnyQuad  data/bunny.obj (3674 triangles, 0 ≤ y ≤ 9.7) under a 6 × 4 quad light at y = 12;
//                 256 shade points on the ground y = 0 (|x| ≤ 8, |z| ≤ 6, normals tilted ≤ 60°)
//                 (on_bunny:0) or the bunny's own vertices (on_bunny:1: every 8th, 230, at
//                 level 0; ~515 from level 1 on), Loop-subdivided 0–4 times (loop), side by
//                 side by the per-triangle method (method:0), the contour path over every kept
//                 image (method:1, visible_light_kept_images = visible_light) and the cone
//                 path (method:2, visible_light_cone, issue 32)
#include <bake/lights/lights.h>
#include <bake/mesh/mesh.h>
#include <bake/mesh/receivers.h>
#include <bake/mesh/subdivide.h>
#include <bake/sphere/polygon_sh.h>
#include <bake/sphere/spherical_polygon.h>
#include <bake/visibility/occluder_mesh.h>
#include <bake/visibility/visible_region.h>

#include <benchmark/benchmark.h>

#include <Eigen/Geometry>

#include <cmath>
#include <filesystem>
#include <memory>
#include <random>
#include <vector>

namespace {

using V3 = Eigen::Vector3d;

struct ShadePoint {
  V3 p, n;
};

const std::vector<ShadePoint>& shade_points() {
  static const std::vector<ShadePoint> points = [] {
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<ShadePoint> out;
    for (int i = 0; i < 4096; ++i) {
      const double tilt = std::acos(1 - u(rng) * 0.5), phi = 2 * 3.141592653589793 * u(rng);
      out.push_back({V3(4 * u(rng) - 2, 4 * u(rng) - 2, 0),
                     V3(std::sin(tilt) * std::cos(phi), std::sin(tilt) * std::sin(phi), std::cos(tilt))});
    }
    return out;
  }();
  return points;
}

const std::vector<V3> kQuad{{-0.5, -0.5, 1.5}, {0.5, -0.5, 1.5}, {0.5, 0.5, 1.5}, {-0.5, 0.5, 1.5}};

// The quad light seen from s, clipped to its horizon, into clipped; returns its irradiance.
double clipped_quad(const ShadePoint& s, std::vector<V3>& rel, std::vector<V3>& clipped) {
  for (size_t k = 0; k < 4; ++k) rel[k] = kQuad[k] - s.p;
  prt::bake::clip_to_horizon(rel, s.n, clipped);
  return prt::bake::cosine_integral(clipped, s.n);
}

void BM_QuadIrradiance(benchmark::State& state) {
  const auto& points = shade_points();
  std::vector<V3> rel(4), clipped;
  for (auto _ : state) {
    double sum = 0;
    for (const ShadePoint& s : points) sum += clipped_quad(s, rel, clipped);
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(points.size()));
}
BENCHMARK(BM_QuadIrradiance)->Unit(benchmark::kMicrosecond);

void BM_QuadIrradianceSH(benchmark::State& state) {
  const auto& points = shade_points();
  const prt::bake::PolygonSH sh(int(state.range(0)));
  std::vector<V3> rel(4), clipped;
  std::vector<double> coeffs(size_t(sh.order() * sh.order()));
  for (auto _ : state) {
    double sum = 0;
    for (const ShadePoint& s : points) {
      sum += clipped_quad(s, rel, clipped);
      sh.project(clipped, coeffs);
      sum += coeffs.back();
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(points.size()));
}
BENCHMARK(BM_QuadIrradianceSH)->Arg(3)->Arg(6)->Unit(benchmark::kMicrosecond);

// A box [lo, hi]: corner k has bit 0 → hi.x, bit 1 → hi.y, bit 2 → hi.z; faces counter-clockwise
// seen from outside.
std::vector<V3> box_corners(const V3& lo, const V3& hi) {
  std::vector<V3> v;
  for (int k = 0; k < 8; ++k) v.emplace_back(k & 1 ? hi.x() : lo.x(), k & 2 ? hi.y() : lo.y(), k & 4 ? hi.z() : lo.z());
  return v;
}
const std::vector<std::vector<uint32_t>> kBoxFaces{{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                                   {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};

// The three lights and the boxes between them and the floor.
const std::vector<std::vector<V3>> kLights{{{-1.5, -0.5, 2.5}, {-0.5, -0.5, 2.5}, {-0.5, 0.5, 2.5}, {-1.5, 0.5, 2.5}},
                                           {{0.5, -1, 3}, {1.5, -1, 3}, {1.5, 0, 3}, {0.5, 0, 3}},
                                           {{-0.5, 1, 2.8}, {0.5, 1, 2.8}, {0.5, 2, 2.8}, {-0.5, 2, 2.8}}};
const std::vector<std::pair<V3, V3>> kBoxes{{V3(-1.2, -0.3, 0.8), V3(-0.6, 0.3, 1.4)},
                                            {V3(0.6, -0.8, 1.2), V3(1.2, -0.2, 1.6)},
                                            {V3(-0.4, 0.9, 0.5), V3(0.4, 1.5, 1.0)}};

void BM_ThreeLightsThreeBoxes(benchmark::State& state) {
  const bool use_silhouette = state.range(0) != 0;
  const auto& points = shade_points();
  const auto& lights = kLights;
  std::vector<prt::bake::ConvexPolyhedron> boxes;
  for (const auto& [lo, hi] : kBoxes) boxes.emplace_back(box_corners(lo, hi), kBoxFaces);
  std::vector<std::vector<V3>> occluders, triangles;
  std::vector<V3> rel(4), clipped;
  std::vector<prt::bake::Arc> arcs;
  // Irradiance at one shade point from the three lights; counts the lights it sees partly hidden.
  auto shade = [&](const ShadePoint& s, size_t& shadowed) {
    occluders.clear();
    for (const auto& b : boxes) {
      if (use_silhouette) {
        occluders.emplace_back();
        if (!b.silhouette(s.p, occluders.back())) return 0.0;  // inside a box
      } else {
        b.front_triangles(s.p, triangles);
        occluders.insert(occluders.end(), triangles.begin(), triangles.end());
      }
    }
    double sum = 0;
    for (const auto& light : lights) {
      for (size_t k = 0; k < 4; ++k) rel[k] = light[k] - s.p;
      prt::bake::clip_to_horizon(rel, s.n, clipped);
      if (clipped.size() < 3) continue;
      prt::bake::visible_region(clipped, occluders, arcs);
      const double e = s.n.dot(prt::bake::vector_irradiance(arcs));
      shadowed += arcs.size() != clipped.size();
      sum += e;
    }
    return sum;
  };
  size_t shadowed = 0;
  for (const ShadePoint& s : points) shade(s, shadowed);  // untimed: the share of shadowed lights
  for (auto _ : state) {
    double sum = 0;
    size_t ignored = 0;
    for (const ShadePoint& s : points) sum += shade(s, ignored);
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(points.size()));
  state.counters["shadowed_lights"] = double(shadowed) / double(points.size() * lights.size());
}
BENCHMARK(BM_ThreeLightsThreeBoxes)->ArgName("silhouette")->Arg(1)->Arg(0)->Unit(benchmark::kMicrosecond);

// Shade points per CPU second for the given points, one call of shade(point) each; the share of
// lights the mesh hides part of and the mean number of triangles kept per light as counters.
template <class Shade>
void run_mesh_bench(benchmark::State& state, const std::vector<ShadePoint>& points, size_t lights, Shade&& shade) {
  size_t kept = 0, shadowed = 0;
  for (const ShadePoint& s : points) shade(s, kept, shadowed);  // untimed: the counters
  for (auto _ : state) {
    double sum = 0;
    size_t k = 0, h = 0;
    for (const ShadePoint& s : points) sum += shade(s, k, h);
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(points.size()));
  state.counters["shadowed_lights"] = double(shadowed) / double(points.size() * lights);
  state.counters["kept_triangles"] = double(kept) / double(points.size() * lights);
}

// Irradiance at s from the lights past the mesh (culled or reference); adds to kept and shadowed.
double shade_past_mesh(const prt::bake::OccluderMesh& mesh, const std::vector<std::vector<V3>>& lights, bool culled,
                       const ShadePoint& s, prt::bake::OccluderMesh::Workspace& ws, std::vector<prt::bake::Arc>& arcs,
                       size_t& kept, size_t& shadowed) {
  const prt::bake::ShadePoint point{.p = s.p, .n = s.n};
  double sum = 0;
  for (const auto& light : lights) {
    kept += culled ? mesh.visible_light(light, point, arcs, ws) : mesh.visible_light_reference(light, point, arcs, ws);
    sum += s.n.dot(prt::bake::vector_irradiance(arcs));
    shadowed += arcs.size() != ws.clipped.size();
  }
  return sum;
}

void BM_ThreeLightsThreeBoxesMesh(benchmark::State& state) {
  const bool culled = state.range(0) != 0;
  std::vector<V3> positions;
  std::vector<std::array<uint32_t, 3>> triangles;
  for (const auto& [lo, hi] : kBoxes) {
    const auto base = uint32_t(positions.size());
    for (const V3& v : box_corners(lo, hi)) positions.push_back(v);
    for (const auto& q : kBoxFaces) {
      triangles.push_back({base + q[0], base + q[1], base + q[2]});
      triangles.push_back({base + q[0], base + q[2], base + q[3]});
    }
  }
  const prt::bake::OccluderMesh mesh(positions, triangles);
  prt::bake::OccluderMesh::Workspace ws;
  std::vector<prt::bake::Arc> arcs;
  run_mesh_bench(state, shade_points(), kLights.size(), [&](const ShadePoint& s, size_t& kept, size_t& shadowed) {
    return shade_past_mesh(mesh, kLights, culled, s, ws, arcs, kept, shadowed);
  });
}
BENCHMARK(BM_ThreeLightsThreeBoxesMesh)->ArgName("culled")->Arg(1)->Arg(0)->Unit(benchmark::kMicrosecond);

// The bunny's quad light and receivers: the 256 ground points (the floor points mapped to y = 0,
// normals about +y), or every max(8, V/512)-th vertex of the (subdivided) bunny itself (ON the
// occluder).
const std::vector<V3> kBunnyLight{{-3, 12, -2}, {3, 12, -2}, {3, 12, 2}, {-3, 12, 2}};

std::vector<ShadePoint> bunny_ground_points() {
  std::vector<ShadePoint> points;
  for (const ShadePoint& s : shade_points()) {
    if (points.size() == 256) break;
    points.push_back({V3(4 * s.p.x(), 0, 3 * s.p.y()), V3(s.n.x(), s.n.z(), s.n.y())});
  }
  return points;
}

const prt::bake::Mesh& bunny(int levels) {
  static std::vector<std::unique_ptr<prt::bake::Mesh>> meshes;
  static const prt::bake::Mesh base = prt::bake::load_mesh(std::filesystem::path(PRT_DATA_DIR) / "bunny.obj");
  while (meshes.size() <= size_t(levels))
    meshes.push_back(std::make_unique<prt::bake::Mesh>(prt::bake::loop_subdivide(base, int(meshes.size()))));
  return *meshes[size_t(levels)];
}

std::vector<V3> positions_of(const prt::bake::Mesh& m) {
  std::vector<V3> p;
  for (const auto& x : m.positions) p.push_back(x.cast<double>());
  return p;
}

// Shade points per CPU second, one quad light over the bunny (Loop-subdivided `levels` times)
// by `method` (see the file comment), receivers on the ground or the bunny's own vertices.
// Counters (untimed pass): triangles whose images were built (kept_triangles) and cut edges
// (image edges reaching into the light) per query; `special`: share of queries with a clipped or
// ε-limit image (the point's own 1-ring: all its edges cut); `uncharted`: share whose light was
// too wide for the chart (caps filter only); `fallback`: share answered by the per-triangle
// method (none); `one_facing`: share of queries answered from one facing's images by the
// closed-mesh rule (occluder_mesh.h "one facing"), `hidden`: of which the light was found hidden
// at once. The cone path's (method 2): `cone`, the share of queries it answered;
// per query it answered, `cone_edges` (welded edges found in the cone), `passed` (images built)
// and `fan_tests`; per query, `edge_nodes` (edge-tree nodes visited).
void BM_BunnyQuad(benchmark::State& state) {
  const int method = int(state.range(0));
  const bool contour = method != 0;
  const bool on_bunny = state.range(1) != 0;
  const int levels = int(state.range(2));
  const prt::bake::Mesh& m = bunny(levels);
  const prt::bake::OccluderMesh mesh(positions_of(m), m.triangles);
  std::vector<ShadePoint> points;
  if (on_bunny) {
    const auto vertices = prt::bake::vertex_shade_points(m, prt::bake::build_topology(m));
    const size_t stride = std::max<size_t>(8, vertices.size() / 512);
    for (size_t v = 0; v < vertices.size(); v += stride) points.push_back({vertices[v].p, vertices[v].n});
  } else {
    points = bunny_ground_points();
  }
  prt::bake::OccluderMesh::Workspace ws;
  std::vector<prt::bake::Arc> arcs;
  auto shade = [&](const ShadePoint& s, size_t& kept, size_t& shadowed) {
    const prt::bake::ShadePoint point{.p = s.p, .n = s.n};
    kept += method == 2   ? mesh.visible_light_cone(kBunnyLight, point, arcs, ws)
            : method == 1 ? mesh.visible_light_kept_images(kBunnyLight, point, arcs, ws)
                          : mesh.visible_light_per_triangle(kBunnyLight, point, arcs, ws);
    shadowed += arcs.size() != ws.clipped.size();
    return s.n.dot(prt::bake::vector_irradiance(arcs));
  };
  run_mesh_bench(state, points, 1, shade);
  if (contour) {
    // The untimed pass's counters only (the workspace's sums over it).
    prt::bake::OccluderMesh::Workspace fresh;
    ws = fresh;
    size_t k = 0, h = 0;
    for (const ShadePoint& s : points) shade(s, k, h);
    const auto& st = ws.stats;
    const double q = double(std::max<size_t>(st.queries, 1));
    state.counters["cut_edges"] = double(st.boundary_edges) / q;
    state.counters["special"] = double(st.special) / q;
    state.counters["uncharted"] = double(st.uncharted) / q;
    state.counters["one_facing"] = double(st.one_facing) / q;
    state.counters["hidden"] = double(st.hidden) / q;
    if (method == 2) {
      // The cone path: share of queries it answered (the rest took the kept-images path), welded
      // edges found in the cone, triangles passed on (meeting a light edge's or a found edge's
      // fan) and edge-tree nodes visited, per query it answered.
      const double c = double(std::max<size_t>(st.cone, 1));
      state.counters["cone"] = double(st.cone) / q;
      state.counters["cone_edges"] = double(st.cone_edges) / c;
      state.counters["passed"] = double(st.cone_candidates) / c;
      state.counters["edge_nodes"] = double(st.edge_nodes) / q;
      state.counters["fan_tests"] = double(st.fan_tests) / c;
    }
  }
  state.counters["fallback"] = 0;
  state.counters["triangles"] = double(m.triangles.size());
  state.counters["points"] = double(points.size());
}
// Rows: per ground level 0–4 and own-vertex level 0–4 the three fast methods side by side; the
// per-triangle method on the ground at levels 0–2 and on the own vertices at level 0 (at level 3
// its O(E²) pairs over ~15k kept triangles would take ~10 min an iteration).
void bunny_rows(benchmark::internal::Benchmark* b) {
  for (int on_bunny = 0; on_bunny < 2; ++on_bunny)
    for (int loop = 0; loop <= 4; ++loop)
      for (int method = 0; method < 3; ++method)
        if (method > 0 || loop <= (on_bunny ? 0 : 2)) b->Args({method, on_bunny, loop});
}
BENCHMARK(BM_BunnyQuad)->ArgNames({"method", "on_bunny", "loop"})->Apply(bunny_rows)->Unit(benchmark::kMicrosecond);

// Cost against the silhouette's size: one quad light (kQuad) and one convex occluder, an N-gon
// prism (radius 0.3, height 0.2, axis +z, centred at height 1), so that its silhouette from the
// floor points has ~N + 2 vertices. silhouette:1 subtracts the silhouette loop (paper 003 §3.3),
// silhouette:0 its front triangles (§4.4: ~2N of them).
void BM_PrismSilhouette(benchmark::State& state) {
  const int segments = int(state.range(0));
  const bool use_silhouette = state.range(1) != 0;
  const prt::bake::AreaLight prism = prt::bake::make_cylinder_light(
      V3(0, 0, 1), 0.3, 0.2, segments, Eigen::AngleAxisd(0.5 * 3.141592653589793, V3::UnitX()).toRotationMatrix());
  const prt::bake::ConvexPolyhedron body(prism.vertices, prism.faces);
  const auto& points = shade_points();
  std::vector<std::vector<V3>> occluders;
  std::vector<V3> rel(4), clipped;
  std::vector<prt::bake::Arc> arcs;
  size_t loop_vertices = 0;
  auto shade = [&](const ShadePoint& s) {
    occluders.clear();
    if (use_silhouette) {
      occluders.emplace_back();
      if (!body.silhouette(s.p, occluders.back())) return 0.0;
      loop_vertices += occluders.back().size();
    } else {
      body.front_triangles(s.p, occluders);
    }
    if (clipped_quad(s, rel, clipped) == 0 || clipped.size() < 3) return 0.0;
    prt::bake::visible_region(clipped, occluders, arcs);
    return s.n.dot(prt::bake::vector_irradiance(arcs));
  };
  for (const ShadePoint& s : points) shade(s);  // untimed: the loop size
  const double mean_loop = double(loop_vertices) / double(points.size());
  for (auto _ : state) {
    double sum = 0;
    for (const ShadePoint& s : points) sum += shade(s);
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(points.size()));
  if (use_silhouette) state.counters["loop_vertices"] = mean_loop;
}
BENCHMARK(BM_PrismSilhouette)
    ->ArgNames({"segments", "silhouette"})
    ->ArgsProduct({{8, 32, 128, 512}, {1, 0}})
    ->Unit(benchmark::kMicrosecond);

} // namespace

BENCHMARK_MAIN();
