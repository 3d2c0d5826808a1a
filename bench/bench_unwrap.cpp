// bench_unwrap — the lightmap UV unwrapper (bake/mesh/unwrap.h; issue 30: "The unwrapper on the
// engine and on the bunny Loop-subdivided to ~1M triangles: time, utilisation, worst stretch, and
// zero overlapping triangles"). For each mesh and atlas size: triangles, charts (how they were
// flattened, how many were split), wall time of unwrap() (one thread: the unwrapper is serial),
// the density it found, utilisation, worst and mean stretch (Sander's L2), and the checks of the
// result by texel_atlas at the same size (texels touched by two charts, texels inside triangles of
// two charts: both must be 0) and UV triangles whose float corners came out flat or flipped.
//
// Meshes: 2CylinderEngine.glb (CAD, no TEXCOORD; PRT_DATA_DIR, ../../shared/data, or assimp's
// test models) and data/bunny.obj Loop-subdivided (bake/mesh/subdivide.h) 4 times (940,544
// triangles). Environment: PRT_BENCH_SIZES atlas sides (default 1024,2048),
// PRT_BENCH_BUNNY_LEVELS (default 4).
#include <bench_common.h>

#include <bake/mesh/mesh.h>
#include <bake/mesh/subdivide.h>
#include <bake/mesh/texels.h>
#include <bake/mesh/unwrap.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

using namespace prt;

namespace {

void row(const std::string& name, const bake::Mesh& mesh, uint32_t side) {
  const bake::Topology topo = bake::build_topology(mesh);
  bake::UnwrapOptions o;
  o.width = o.height = side;
  const bake::Unwrapped u = bake::unwrap(mesh, topo, o);
  const bake::UnwrapReport& r = u.report;
  const auto t0 = std::chrono::steady_clock::now();
  const bake::TexelAtlas atlas = bake::texel_atlas(mesh, topo, u.uv, side, side, name);
  const double check_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  size_t not_ccw = 0;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Eigen::Vector2d a = u.uv.corners[3 * t].cast<double>(), b = u.uv.corners[3 * t + 1].cast<double>(),
                          c = u.uv.corners[3 * t + 2].cast<double>();
    const Eigen::Vector2d e = b - a, f = c - a;
    not_ccw += !(e.x() * f.y() - e.y() * f.x() > 0);
  }
  std::printf("| %s | %zu | %ux%u | %zu (%zu LSCM, %zu planar, %zu single) | %zu (%zu) | %zu | %.2f | %.3f | %.4f | %.3f | "
              "%.3f | %zu | %zu | %zu | %.1f |\n",
              name.c_str(), mesh.triangles.size(), r.width, r.height, r.charts, r.lscm_charts, r.planar_charts,
              r.single_triangle_charts, r.splits, r.stretch_splits, r.degenerate_triangles, r.seconds, r.density, r.utilisation,
              r.worst_stretch, r.mean_stretch, atlas.overlapping_texels, atlas.shared_texels, not_ccw - r.degenerate_triangles,
              check_s);
  std::fflush(stdout);
}

} // namespace

int main() {
  const std::string data = PRT_DATA_DIR;
  const std::vector<long> sizes = bench::env_list("PRT_BENCH_SIZES", {1024, 2048});
  const int levels = int(bench::env_long("PRT_BENCH_BUNNY_LEVELS", 4));
  std::printf("Lightmap unwrapper, one thread, gutter 2 texels, CPU %s\n\n", bench::cpu_model().c_str());
  std::printf("| mesh | triangles | atlas | charts | split (for stretch) | degenerate | unwrap s | density (texels/unit) | utilisation | "
              "worst stretch | mean stretch | overlapping texels | shared texels | flat or flipped in float | check s |\n"
              "|---|---:|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  std::string engine;
  for (const std::filesystem::path& p : {std::filesystem::path(data) / "2CylinderEngine.glb",
                                        std::filesystem::path(data) / "../../shared/data/2CylinderEngine.glb",
                                        std::filesystem::path("/work/shared/data/2CylinderEngine.glb"),
                                        std::filesystem::path("/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb")})
    if (std::filesystem::exists(p)) {
      engine = p.string();
      break;
    }
  if (engine.empty()) std::printf("| 2CylinderEngine.glb | not found | | | | | | | | | | | | | |\n");
  else {
    const bake::Mesh m = bake::load_mesh(engine);
    for (long side : sizes) row("2CylinderEngine.glb", m, uint32_t(side));
  }
  const bake::Mesh bunny = bake::load_mesh(data + "/bunny.obj");
  for (long side : sizes) row("bunny.obj", bunny, uint32_t(side));
  const auto t0 = std::chrono::steady_clock::now();
  const bake::Mesh fine = bake::loop_subdivide(bunny, levels);
  const double subdivide_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  for (long side : sizes) row("bunny.obj Loop x" + std::to_string(levels), fine, uint32_t(side));
  std::printf("\n(Loop subdivision of the bunny: %.1f s, not in the unwrap time.)\n", subdivide_s);
  return 0;
}
