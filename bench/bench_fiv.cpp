// bench_fiv — FIV shell bakes (paper 004 Table 1 sizes) and their accuracy against QMC.
//   bench_fiv [MESH] [ENV]          defaults: data/bunny.obj, data/forest.exr
//   PRT_FIV_SIZES="32x17x15,64x33x30,128x65x30,256x129x30", PRT_FIV_POINTS (32), PRT_FIV_RAYS (10^6)
// Accuracy: at seeded random offsets (radii between 0.5 R and 8 R), the silhouette's occluded FIV
// (k = 128², the bake's default) against F^env − ∫ V L ω dω from QMC (full-sphere mode); RMSE over
// offsets and RGB·xyz, relative to the RMS of |F^env| components.
#include <bake/bake/fiv.h>
#include <bake/environment/envmap.h>
#include <bake/integrators/qmc.h>
#include <bake/mesh/mesh.h>
#include <bake/sphere/sampling.h>

#include <tbb/parallel_for.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>

using namespace prt::bake;
using Eigen::Vector3d;

int main(int argc, char** argv) {
  const std::string data = PRT_DATA_DIR;
  const std::string mesh_path = argc > 1 ? argv[1] : data + "/bunny.obj";
  const std::string env_path = argc > 2 ? argv[2] : data + "/forest.exr";
  const char* sizes_env = std::getenv("PRT_FIV_SIZES");
  const std::string sizes = sizes_env ? sizes_env : "32x17x15,64x33x30,128x65x30,256x129x30";
  const size_t points = std::getenv("PRT_FIV_POINTS") ? size_t(std::atol(std::getenv("PRT_FIV_POINTS"))) : 32;
  const uint32_t rays = std::getenv("PRT_FIV_RAYS") ? uint32_t(std::atol(std::getenv("PRT_FIV_RAYS"))) : 1000000;
  const Mesh mesh = load_mesh(mesh_path, {.use_file_normals = false});
  const Topology topo = build_topology(mesh);
  const EnvMap env = EnvMap::load(env_path, UpAxis::Y);

  std::printf("FIV shells of %s (%zu triangles) under %s, 2 threads, silhouette k = 128^2.\n\n", mesh_path.c_str(),
              mesh.triangles.size(), env_path.c_str());
  std::printf("| shells (phi x theta x rho) | integrals | radii baked | seconds | integrals/s |\n|---|---:|---:|---:|---:|\n");
  std::stringstream ss(sizes);
  for (std::string item; std::getline(ss, item, ',');) {
    ShellSpec spec;
    if (!parse_shell_grid(item, spec)) continue;
    const FivShells s = bake_fiv_shells(mesh, topo, env, spec);
    std::printf("| %s | %llu | %zu | %.2f | %.0f |\n", item.c_str(), (unsigned long long)s.integrals, s.radii.size(),
                s.seconds, double(s.integrals) / s.seconds);
    std::fflush(stdout);
  }

  // Accuracy against QMC at random offsets.
  ProductRequest req;
  req.radiance = &env;
  req.visibility_order = 1;
  const SilhouetteIntegrator sil(mesh, topo, req, {128, 1});
  const QmcIntegrator qmc(mesh, topo, req, {rays, 99});
  const Fiv fenv = environment_fiv(env);
  Vector3d c;
  double R;
  bounding_sphere(mesh, c, R);
  std::vector<double> err2(points, 0.0), se2(points, 0.0);
  tbb::parallel_for(size_t(0), points, [&](size_t i) {
    const uint64_t h = mix64(2026 + i);
    const double z = 2 * to_unit(mix64(h + 1)) - 1, phi = 2 * std::numbers::pi * to_unit(mix64(h + 2));
    const double rho = R * 0.5 * std::pow(16.0, to_unit(mix64(h + 3)));
    const double r = std::sqrt(1 - z * z);
    const Vector3d p = c + rho * Vector3d(r * std::cos(phi), z, r * std::sin(phi));
    const Fiv f = occluded_fiv(sil, p);
    Fiv se;
    const Fiv ref = qmc_occluded_fiv(qmc, fenv, p, i, &se);
    for (int k = 0; k < 9; ++k) {
      err2[i] += (f[size_t(k)] - ref[size_t(k)]) * (f[size_t(k)] - ref[size_t(k)]);
      se2[i] += se[size_t(k)] * se[size_t(k)];
    }
  });
  double e = 0, s2 = 0, n2 = 0;
  for (size_t i = 0; i < points; ++i) {
    e += err2[i];
    s2 += se2[i];
  }
  for (double x : fenv) n2 += x * x;
  const double norm = std::sqrt(n2 / 9);
  std::printf("\nAccuracy at %zu random offsets (0.5 R to 8 R) against QMC with %u rays: RMSE / RMS|F^env| = %.2e "
              "(QMC's own standard error, same scale: %.2e)\n",
              points, rays, std::sqrt(e / double(9 * points)) / norm, std::sqrt(s2 / double(9 * points)) / norm);
  return 0;
}
