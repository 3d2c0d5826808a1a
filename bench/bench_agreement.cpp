// bench_agreement — the silhouette integrator against the Embree QMC reference on real meshes
// (issue: bunny, wuson, spider, each alone and on a ground plane, k = 256² against 10^6 QMC
// rays: RMSE ≤ 1e-3 for AO and order-3 transfer, relative RMSE ≤ 5e-3 for band-1 radiance under
// sunset.exr). Prints a markdown table; the QMC reference's own standard error is printed beside
// each error (it is the MC bound, which overstates randomised QMC's real error).
//
//   bench_agreement                    defaults: 24 seeded vertices per scene, N = 256, 10^6 rays
//   PRT_AGREE_POINTS, PRT_AGREE_ISOLINES, PRT_AGREE_RAYS override them.
#include <bake/bake/vertex_bake.h>
#include <bake/environment/envmap.h>
#include <bake/integrators/qmc.h>
#include <bake/integrators/silhouette.h>
#include <bake/mesh/mesh.h>

#include <tbb/parallel_for.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using namespace prt::bake;
using Eigen::Vector3f;

namespace {

long env_or(const char* name, long fallback) {
  const char* v = std::getenv(name);
  return v ? std::strtol(v, nullptr, 10) : fallback;
}

// A (2n+1)² ground grid at the mesh's lowest y, three times its largest horizontal extent wide.
Mesh on_ground(const Mesh& m) {
  Vector3f lo = m.positions[0], hi = m.positions[0];
  for (const auto& p : m.positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Vector3f c = 0.5f * (lo + hi);
  const float half = 1.5f * std::max(hi.x() - lo.x(), hi.z() - lo.z());
  const int n = 24, k = 2 * n + 1;
  std::vector<Vector3f> p;
  std::vector<std::array<uint32_t, 3>> t;
  for (int j = 0; j < k; ++j)
    for (int i = 0; i < k; ++i)
      p.emplace_back(c.x() - half + 2 * half * float(i) / float(k - 1), lo.y(), c.z() - half + 2 * half * float(j) / float(k - 1));
  for (int j = 0; j + 1 < k; ++j)
    for (int i = 0; i + 1 < k; ++i) {
      const uint32_t a = uint32_t(j * k + i), b = a + 1, cc = a + uint32_t(k) + 1, d = a + uint32_t(k);
      t.push_back({a, d, cc});  // counter-clockwise from +y
      t.push_back({a, cc, b});
    }
  std::vector<Mesh> parts{m, make_mesh(std::move(p), std::move(t), "ground")};
  return merge_meshes(parts, m.source + " on a ground plane");
}

struct Acc {
  double err2 = 0, ref2 = 0, se2 = 0, max_abs = 0;
  size_t n = 0;
  void add(double a, double b, double se) {
    err2 += (a - b) * (a - b);
    ref2 += b * b;
    se2 += se * se;
    max_abs = std::max(max_abs, std::abs(a - b));
    ++n;
  }
  double rmse() const { return std::sqrt(err2 / double(n)); }
  double rel() const { return std::sqrt(err2 / ref2); }
  double se() const { return std::sqrt(se2 / double(n)); }
};

} // namespace

int main() {
  const size_t points = size_t(env_or("PRT_AGREE_POINTS", 24));
  const int isolines = int(env_or("PRT_AGREE_ISOLINES", 256));
  const uint32_t rays = uint32_t(env_or("PRT_AGREE_RAYS", 1000000));
  const std::string data = PRT_DATA_DIR;
  const EnvMap env = EnvMap::load(data + "/sunset.exr", UpAxis::Y);
  std::printf("Silhouette (k = %d²) against QMC (%u rays/vertex), %zu seeded vertices per scene; AO, order-3 "
              "diffuse transfer, band-1 radiance under sunset.exr.\n\n",
              isolines, rays, points);
  std::printf("| scene | triangles | AO RMSE | AO max | transfer RMSE | transfer max | band-1 rel. RMSE | QMC own std. "
              "error (AO / transfer / band-1 rel.) | silhouette µs/integral (2 threads, wall) |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
  for (const char* name : {"bunny", "wuson", "spider"}) {
    const Mesh alone = load_mesh(data + "/" + name + ".obj", {.use_file_normals = false});
    for (int g = 0; g < 2; ++g) {
      const Mesh m = g ? on_ground(alone) : alone;
      const Topology topo = build_topology(m);
      ProductRequest req;
      req.ao = true;
      req.transfer_order = 3;
      req.radiance = &env;
      const SilhouetteIntegrator sil(m, topo, req, {isolines, 1});
      const QmcIntegrator qmc(m, topo, req, {rays, 77});
      const auto verts = seeded_sample(uint32_t(m.positions.size()), points, 2026);
      const size_t W = sil.layout().width;
      std::vector<double> a(verts.size() * W), b(verts.size() * W), se(verts.size() * W);
      const auto t0 = std::chrono::steady_clock::now();
      tbb::parallel_for(size_t(0), verts.size(), [&](size_t i) {
        sil.integrate(vertex_shade_point(m, topo, verts[i]), verts[i], std::span(a).subspan(i * W, W));
      });
      const double sil_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      tbb::parallel_for(size_t(0), verts.size(), [&](size_t i) {
        qmc.integrate(vertex_shade_point(m, topo, verts[i]), verts[i], std::span(b).subspan(i * W, W),
                      std::span(se).subspan(i * W, W));
      });
      const auto& L = sil.layout();
      Acc ao, tr, rad;
      for (size_t i = 0; i < verts.size(); ++i) {
        const size_t o = i * W;
        ao.add(a[o + L.ao], b[o + L.ao], se[o + L.ao]);
        for (size_t k = 0; k < L.transfer_count; ++k)
          tr.add(a[o + L.transfer + k], b[o + L.transfer + k], se[o + L.transfer + k]);
        for (size_t k = 0; k < L.radiance_count; ++k)
          rad.add(a[o + L.radiance + k], b[o + L.radiance + k], se[o + L.radiance + k]);
      }
      std::printf("| %s%s | %zu | %.2e | %.2e | %.2e | %.2e | %.2e | %.1e / %.1e / %.1e | %.0f |\n", name,
                  g ? " + ground" : "", m.triangles.size(), ao.rmse(), ao.max_abs, tr.rmse(), tr.max_abs, rad.rel(),
                  ao.se(), tr.se(), rad.se() / std::sqrt(rad.ref2 / double(rad.n)), 1e6 * sil_s / double(verts.size()));
      std::fflush(stdout);
    }
  }
  return 0;
}
