// bench_area — analytic area-light shading per shade point (bake/spherical_polygon.h,
// bake/polygon_sh.h; paper 003 §4.1, Fig. 4: its per-core rates are the targets, ≥ 150k shade
// points/s for one quad light with no occluder). One thread; rates are items per CPU second.
//
// Scene: a 1 × 1 quad light at height 1.5 over a 4 × 4 floor; 4096 shade points on the floor
// with normals tilted up to 60° from +z, so a share of them sees the light cross the horizon.
//   BM_QuadIrradiance    horizon clip + Lambert (the diffuse irradiance of the light)
//   BM_QuadIrradianceSH  the same + the SH projection of the clipped polygon at orders 3 and 6
// and with shadows (bake/visible_region.h; paper 003's target ≥ 17k shade points/s per core for
// 3 lights × 3 occluders): three 1 × 1 quad lights at heights 2.5–3 and three boxes between
// them and the floor (no culling: every box is tested against every light), per shade point the
// boxes' silhouettes, then per light the horizon clip, the visible region and its irradiance:
//   BM_ThreeLightsThreeBoxes/silhouette:1  the boxes as silhouette loops (paper §3.3)
//   BM_ThreeLightsThreeBoxes/silhouette:0  the boxes as their front-facing triangles (§4.4)
#include <bake/polygon_sh.h>
#include <bake/spherical_polygon.h>
#include <bake/visible_region.h>

#include <benchmark/benchmark.h>

#include <Eigen/Geometry>

#include <cmath>
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

// A box [lo, hi] with its faces counter-clockwise seen from outside.
prt::bake::ConvexPolyhedron box(const V3& lo, const V3& hi) {
  std::vector<V3> v;
  for (int k = 0; k < 8; ++k) v.emplace_back(k & 1 ? hi.x() : lo.x(), k & 2 ? hi.y() : lo.y(), k & 4 ? hi.z() : lo.z());
  return prt::bake::ConvexPolyhedron(
      v, {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}});
}

void BM_ThreeLightsThreeBoxes(benchmark::State& state) {
  const bool use_silhouette = state.range(0) != 0;
  const auto& points = shade_points();
  const std::vector<std::vector<V3>> lights{
      {{-1.5, -0.5, 2.5}, {-0.5, -0.5, 2.5}, {-0.5, 0.5, 2.5}, {-1.5, 0.5, 2.5}},
      {{0.5, -1, 3}, {1.5, -1, 3}, {1.5, 0, 3}, {0.5, 0, 3}},
      {{-0.5, 1, 2.8}, {0.5, 1, 2.8}, {0.5, 2, 2.8}, {-0.5, 2, 2.8}}};
  const std::vector<prt::bake::ConvexPolyhedron> boxes{box(V3(-1.2, -0.3, 0.8), V3(-0.6, 0.3, 1.4)),
                                                       box(V3(0.6, -0.8, 1.2), V3(1.2, -0.2, 1.6)),
                                                       box(V3(-0.4, 0.9, 0.5), V3(0.4, 1.5, 1.0))};
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

} // namespace

BENCHMARK_MAIN();
