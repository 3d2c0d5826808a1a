// bench_bounce — the cost of interreflections (bake/bake/bounce.h, issue 31) next to the direct pass
// they add to, in one run: the direct diffuse transfer at order 3 of every vertex (the silhouette
// integrator at its default k and QMC at its default rays), the gather (K cosine rays per vertex,
// cast once), and each bounce after it (a sparse product over the cached hits, no rays), with the
// ratio bounce / direct and the memory of the cached hits. The issue asks each bounce after the
// first for ≤ 0.3× the direct pass.
//
// Scenes: data/bunny_ground.obj and its bunny Loop-subdivided once (bench_common.h). One thread
// (a tbb::task_arena of 1), so the ratios are CPU ratios on a machine shared with other work.
//   PRT_BENCH_LEVELS   subdivision levels (default 0,1)
//   PRT_BENCH_RAYS     gather rays per vertex (default 256)
//   PRT_BENCH_BOUNCES  bounces (default 4; the tolerance is 0 so every one runs)
//   PRT_BENCH_TEXELS   1 (default): also per texel, data/bunny_ground.obj at 8 texels per unit and
//                      data/cornell_room.obj at 32 (generated lightmap UVs; bake/bake/bounce.h TexelField)
#include "bench_common.h"

#include <bake/bake/bounce.h>
#include <bake/bake/lightmap_receivers.h>
#include <bake/bake/vertex_bake.h>
#include <bake/integrators/registry.h>
#include <bake/mesh/receivers.h>
#include <bake/visibility/accel.h>
#include <bake/visibility/raycast.h>

#include <tbb/task_arena.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <vector>

using namespace prt;

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The direct pass, the gather and the bounces over `points` of `mesh` whose rows `field` spreads.
void measure(const bake::Mesh& mesh, const bake::Topology& topology, const bake::MeshAccel& accel,
             const std::vector<bake::ShadePoint>& points, const bake::BounceField& field, const char* noun,
             uint32_t rays, int bounces) {
  bake::ProductRequest request;
  request.transfer_order = 3;

  // The direct pass, both integrators at their defaults (the trees built before the clock starts).
  accel.rays();
  accel.contours();
  double direct_seconds[2] = {0, 0};
  bake::VertexBake direct;
  const bake::IntegratorKind kinds[2] = {bake::IntegratorKind::Silhouette, bake::IntegratorKind::Qmc};
  for (int i = 0; i < 2; ++i) {
    bake::IntegratorSpec spec;
    spec.kind = kinds[i];
    const auto t0 = std::chrono::steady_clock::now();
    const auto integrator = bake::make_integrator(spec, mesh, topology, request, &accel);
    bake::VertexBake rows = bake::bake_points(points, *integrator);
    direct_seconds[i] = seconds_since(t0);
    std::printf("  direct, %-10s (%s %u):  %8.3f s\n", bake::to_string(kinds[i]),
                kinds[i] == bake::IntegratorKind::Qmc ? "rays" : "k", spec.samples(), direct_seconds[i]);
    if (i == 0) direct = std::move(rows);
  }

  bake::BounceSpec spec;
  spec.bounces = bounces;
  spec.rays = rays;
  spec.tolerance = 0;
  const bake::GatherHits hits = bake::gather(*accel.rays(), points, spec, false);
  const std::vector<bake::Albedo> albedo(mesh.triangles.size(), bake::Albedo{0.6, 0.6, 0.6});
  const bake::BounceResult r =
      bake::bounce_rows(field, points, hits, albedo, direct.layout, direct.values, spec, mesh.source);
  double per_bounce = 0;
  for (const double x : r.seconds) per_bounce += x / double(r.seconds.size());
  std::printf("  gather (%u rays per %s, once):   %8.3f s  = %.3fx silhouette, %.3fx qmc\n", rays, noun, hits.seconds,
              hits.seconds / direct_seconds[0], hits.seconds / direct_seconds[1]);
  std::printf("  cached hits: %.2f MB (%.1f bytes per %s; %zu bytes per ray)\n", double(hits.bytes()) / 1e6,
              double(hits.bytes()) / double(points.size()), noun, sizeof(uint32_t) + sizeof(hits.weights[0]));
  for (size_t b = 0; b < r.seconds.size(); ++b)
    std::printf("  bounce %zu (sparse product):          %8.4f s  = %.4fx silhouette, %.4fx qmc  (RMS / direct %.4f)\n",
                b + 1, r.seconds[b], r.seconds[b] / direct_seconds[0], r.seconds[b] / direct_seconds[1],
                r.relative_rms[b]);
  std::printf("  first bounce (gather + product): %.3fx silhouette; each bounce after it: %.4fx silhouette, %.4fx qmc\n",
              (hits.seconds + r.seconds.front()) / direct_seconds[0], per_bounce / direct_seconds[0],
              per_bounce / direct_seconds[1]);
}

void run(int level, uint32_t rays, int bounces) {
  const bench::Scene& s = bench::scene(level);
  const std::vector<bake::ShadePoint> points = bake::vertex_shade_points(s.mesh, s.topology);
  const bake::MeshAccel accel(s.mesh, s.topology);
  std::printf("\nlevel %d: %zu vertices, %zu triangles; transfer order 3\n", level, s.mesh.positions.size(),
              s.mesh.triangles.size());
  measure(s.mesh, s.topology, accel, points, bake::VertexField(s.mesh), "vertex", rays, bounces);
}

// Per texel: `file`'s generated lightmap at `density` texels per unit; a bounce reads the previous
// one's lightmap (filled and padded 2 rings) at each hit's UV.
void run_texels(const std::string& file, double density, uint32_t rays, int bounces) {
  const bake::Mesh mesh = bake::load_mesh(std::string(PRT_DATA_DIR) + "/" + file);
  const bake::Topology topology = bake::build_topology(mesh);
  const bake::MeshAccel accel(mesh, topology);
  bake::LightmapSpec lm;
  lm.density = density;
  const bake::LightmapReceivers texels = bake::lightmap_receivers(mesh, topology, lm, *accel.rays(), file);
  const bake::ReceiverSet set = texels.receivers();
  std::printf("\n%s per texel: %ux%u lightmap at %g texels per unit, %zu texels baked; transfer order 3\n",
              file.c_str(), texels.atlas.width, texels.atlas.height, density, set.points.size());
  measure(mesh, topology, accel, set.points, bake::TexelField(mesh, texels, 2), "texel", rays, bounces);
}

} // namespace

int main() {
  const std::vector<long> levels = bench::env_list("PRT_BENCH_LEVELS", {0, 1});
  const auto rays = uint32_t(bench::env_long("PRT_BENCH_RAYS", 256));
  const int bounces = int(bench::env_long("PRT_BENCH_BOUNCES", 4));
  std::printf("bench_bounce: interreflections vs the direct pass, one thread, %s\n", bench::cpu_model().c_str());
  tbb::task_arena arena(1);
  arena.execute([&] {
    for (const long level : levels) run(int(level), rays, bounces);
    if (bench::env_long("PRT_BENCH_TEXELS", 1)) {
      run_texels("bunny_ground.obj", 8, rays, bounces);
      run_texels("cornell_room.obj", 32, rays, bounces);
    }
  });
  return 0;
}
