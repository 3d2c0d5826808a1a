// bench_common.h — the scene every integrator benchmark uses, so bench_integrators and
// bench_error_vs_time measure the same thing.
//
// Scene: data/bunny_ground.obj (the default scene: bunny, 1,839 vertices / 3,674 triangles,
// on a 48×48-quad ground grid), products AO + order-3 diffuse transfer (ProductRequest{ao,
// transfer_order = 3}: 10 doubles per integral). Finer scenes: the bunny part Loop-subdivided
// (bake/mesh/subdivide.h) `level` times (3,674·4^level triangles) with the same ground grid, so
// level 0 is the file itself and levels 1, 2, 3 have ~15k, ~60k, ~240k bunny triangles.
//
// Shade points: seeded_sample(4,240 vertices of bunny_ground.obj, n, seed) — the same vertices
// at every level: a bunny vertex keeps its index under subdivision (it moves by the Loop rule),
// and a ground vertex is re-indexed past the subdivided bunny.
//
// Sizes come from the environment so a run can be made short or long without rebuilding:
//   PRT_BENCH_POINTS  shade points (default 64)      PRT_BENCH_SEED  sample seed (default 7)
#pragma once

#include <bake/integrators/integrator.h>
#include <bake/integrators/products.h>
#include <bake/mesh/mesh.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace prt::bench {

struct Scene {
  int level = 0;
  bake::Mesh mesh;
  bake::Topology topology;
  uint32_t bunny_vertices = 0;            // vertices [0, bunny_vertices) are the bunny's, the rest the ground's
  std::vector<uint32_t> vertices;         // the shade points' vertex indices in `mesh`
  std::vector<bake::ShadePoint> points;   // vertex_shade_point of each
  double build_seconds = 0;               // load + subdivide + topology
};

bake::ProductRequest request();           // AO + order-3 transfer

// Loads (level 0) or builds (level > 0) the scene once per process and caches it.
const Scene& scene(int level);

// Environment knobs.
long env_long(const char* name, long fallback);
std::vector<long> env_list(const char* name, std::vector<long> fallback);  // "a,b,c"
size_t n_points();
uint64_t sample_seed();

// "Intel(R) Xeon(R) ... @ 2.20GHz" from /proc/cpuinfo ("unknown" if absent).
std::string cpu_model();

} // namespace prt::bench
