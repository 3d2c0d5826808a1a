// bench_suns — the silhouette integrator's error under HDR skies with suns, against the isoline
// count N (issue 27: the environment's hot texels integrated exactly, bake/integrators/hot_texels.h).
//
// Per (mesh, environment): S seeded vertices (PRT_SUNS_POINTS, default 24; seed 12345), a QMC
// reference with 2^19 rays (PRT_SUNS_REF_RAYS; seed 77) whose own estimated noise is printed
// beside it (its RMS standard error, relative like the errors), then the silhouette integrator at
// N = 64, 128, 256, 512 (PRT_SUNS_LEVELS="a,b,..."): band-1 radiance R and order-3 shadowed
// radiance S, each as the RMSE
// relative to the reference's RMS (bake/bake/choose.h's units), and the CPU µs per integral at N = 256
// (each thread's own clock). An error that stops falling with N at the reference's noise level is
// the reference's; one that grows with N, or stalls well above it, is the integrator's.
//
//   bench_suns [MESH ENV ...]   pairs; default: four meshes (the bunny on its ground and three of
//                               assimp's test models) under six skies (data/ and Blender's studio
//                               lights with suns: city, sunrise)
//
// The same source builds against an older libbake for a before/after comparison (the command is in
// bench/RESULTS.md).
#include <bake/bake/vertex_bake.h>
#include <bake/environment/envmap.h>
#include <bake/integrators/qmc.h>
#include <bake/integrators/silhouette.h>
#include <bake/mesh/mesh.h>

#include <tbb/parallel_for.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

using namespace prt::bake;

namespace {

long env_long(const char* name, long fallback) {
  const char* v = std::getenv(name);
  return v && *v ? std::atol(v) : fallback;
}

struct Rows {
  std::vector<double> values;
  double cpu_us = 0;
};

Rows integrate(const Integrator& I, const std::vector<ShadePoint>& pts, const std::vector<uint32_t>& sample, size_t W,
               std::vector<double>* std_error = nullptr) {
  Rows r;
  r.values.assign(sample.size() * W, 0.0);
  if (std_error) std_error->assign(sample.size() * W, 0.0);
  std::vector<double> seconds(sample.size(), 0.0);
  tbb::parallel_for(size_t(0), sample.size(), [&](size_t i) {
    const double t0 = thread_cpu_seconds();
    std::span<double> se;
    if (std_error) se = std::span(*std_error).subspan(i * W, W);
    I.integrate(pts[sample[i]], sample[i], std::span(r.values).subspan(i * W, W), se);
    seconds[i] = thread_cpu_seconds() - t0;
  });
  double sum = 0;
  for (double s : seconds) sum += s;
  r.cpu_us = 1e6 * sum / double(sample.size());
  return r;
}

// RMSE of the values [offset, offset + count) of each row against the reference, relative to the
// reference's RMS there.
double relative_rmse(const std::vector<double>& a, const std::vector<double>& ref, size_t W, size_t offset, size_t count) {
  double e2 = 0, r2 = 0;
  const size_t K = ref.size() / W;
  for (size_t i = 0; i < K; ++i)
    for (size_t c = 0; c < count; ++c) {
      const double d = a[i * W + offset + c] - ref[i * W + offset + c];
      e2 += d * d;
      r2 += ref[i * W + offset + c] * ref[i * W + offset + c];
    }
  return r2 > 0 ? std::sqrt(e2 / r2) : 0.0;
}

std::string hot_texels(const std::string& description) {
  const size_t at = description.find(" hot environment texels");
  if (at == std::string::npos) return "0";
  size_t b = description.rfind(' ', at - 1);
  return description.substr(b + 1, at - b - 1);
}

} // namespace

int main(int argc, char** argv) {
  std::vector<std::pair<std::string, std::string>> cases;
  for (int i = 1; i + 1 < argc; i += 2) cases.emplace_back(argv[i], argv[i + 1]);
  if (cases.empty()) {
    const std::string data = PRT_DATA_DIR, assimp = "/usr/share/assimp/models",
                      blender = "/usr/share/blender/datafiles/studiolights/world";
    const std::vector<std::string> meshes = {data + "/bunny_ground.obj", assimp + "/STL/3DSMaxExport.STL",
                                             assimp + "/OBJ/regr01.obj", assimp + "/STL/sphereWithHole.stl"};
    const std::vector<std::string> envs = {data + "/sunset.exr", data + "/forest.exr", data + "/studio.exr",
                                           data + "/interior.exr", blender + "/city.exr", blender + "/sunrise.exr"};
    for (const auto& m : meshes)
      for (const auto& e : envs)
        if (std::filesystem::exists(m) && std::filesystem::exists(e)) cases.emplace_back(m, e);
  }
  const size_t K = size_t(env_long("PRT_SUNS_POINTS", 24));
  const uint32_t ref_rays = uint32_t(env_long("PRT_SUNS_REF_RAYS", 1 << 19));
  std::vector<int> kLevels;
  {
    const char* v = std::getenv("PRT_SUNS_LEVELS");
    std::string list = v && *v ? v : "64,128,256,512";
    for (size_t at = 0; at < list.size();) {
      const size_t comma = std::min(list.find(',', at), list.size());
      kLevels.push_back(std::atoi(list.substr(at, comma - at).c_str()));
      at = comma + 1;
    }
  }
  std::printf("bench_suns: %zu points per case, reference QMC %u rays (seed 77); errors relative to the reference's RMS; "
              "R = band-1 radiance, S = order-3 shadowed radiance\n\n",
              K, ref_rays);
  std::printf("| mesh | sky | hot texels | reference noise R / S |");
  for (int N : kLevels) std::printf(" N = %d: R / S |", N);
  std::printf(" µs/integral at 256 |\n|---|---|---:|---:|");
  for (size_t i = 0; i < kLevels.size(); ++i) std::printf("---:|");
  std::printf("---:|\n");
  for (const auto& [mesh_path, env_path] : cases) {
    const Mesh mesh = load_mesh(mesh_path);
    const Topology topo = build_topology(mesh);
    const EnvMap env = EnvMap::load(env_path, UpAxis::Y);
    ProductRequest req;
    req.radiance = &env;
    req.shadowed = &env;
    req.shadowed_order = 3;
    const ProductLayout L(req);
    const std::vector<ShadePoint> pts = vertex_shade_points(mesh, topo);
    const std::vector<uint32_t> sample = seeded_sample(uint32_t(pts.size()), K, 12345);
    const QmcIntegrator qmc(mesh, topo, req, {ref_rays, 77});
    std::vector<double> se;
    const Rows ref = integrate(qmc, pts, sample, L.width, &se);
    // The reference's noise: RMS standard error over RMS value, per product.
    auto noise = [&](size_t offset, size_t count) {
      double s2 = 0, r2 = 0;
      for (size_t i = 0; i < sample.size(); ++i)
        for (size_t c = 0; c < count; ++c)
          s2 += se[i * L.width + offset + c] * se[i * L.width + offset + c],
              r2 += ref.values[i * L.width + offset + c] * ref.values[i * L.width + offset + c];
      return r2 > 0 ? std::sqrt(s2 / r2) : 0.0;
    };
    std::string hot;
    std::printf("| %s | %s |", std::filesystem::path(mesh_path).filename().c_str(),
                std::filesystem::path(env_path).stem().c_str());
    std::string row;
    double us256 = 0;
    for (int N : kLevels) {
      const SilhouetteIntegrator sil(mesh, topo, req, {N, 1});
      if (hot.empty()) hot = hot_texels(sil.description());
      const Rows r = integrate(sil, pts, sample, L.width);
      if (N == 256) us256 = r.cpu_us;
      char buf[96];
      std::snprintf(buf, sizeof buf, " %.1e / %.1e |", relative_rmse(r.values, ref.values, L.width, L.radiance, L.radiance_count),
                    relative_rmse(r.values, ref.values, L.width, L.shadowed, L.shadowed_count));
      row += buf;
    }
    std::printf(" %s | %.1e / %.1e |%s %.0f |\n", hot.c_str(), noise(L.radiance, L.radiance_count),
                noise(L.shadowed, L.shadowed_count), row.c_str(), us256);
    std::fflush(stdout);
  }
}
