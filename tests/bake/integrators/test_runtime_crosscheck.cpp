// Cross-checks of the prtshade run-time library (float, std-only) against libbake (double):
// project_latlong vs EnvMap::project_sh on data/forest.exr, and band-1 shading of baked shadowed
// radiance (silhouette integrator, bunny on its ground plane) vs E = (4π/3) Σ y_1m(n) R_m in double.
#include <bake/environment/envmap.h>
#include <bake/integrators/products.h>
#include <bake/integrators/silhouette.h>
#include <bake/mesh/mesh.h>
#include <bake/mesh/receivers.h>
#include <bake/sphere/sampling.h>
#include <prtshade/sh.h>
#include <prtshade/shade.h>

#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace {

using namespace prt::bake;

TEST(RuntimeCrosscheck, ProjectLatlongMatchesEnvMapProjectSh) {
  const EnvMap env = EnvMap::load(std::string(PRT_DATA_DIR) + "/forest.exr", UpAxis::Y);
  ASSERT_EQ(env.info().layout, "latlong");
  const int w = env.info().width, h = env.info().height, order = 6, n = order * order;
  // The pixels EnvMap holds (negatives already clamped, as project_latlong would do itself).
  std::vector<float> rgb(size_t(3) * size_t(w) * size_t(h));
  for (int t = 0; t < w * h; ++t) {
    const Rgb v = env.texel_value(t);
    rgb[size_t(3 * t)] = float(v.r), rgb[size_t(3 * t + 1)] = float(v.g), rgb[size_t(3 * t + 2)] = float(v.b);
  }
  std::vector<float> rt(size_t(3 * n));
  prt::shade::project_latlong(rgb.data(), w, h, order, rt.data());
  const std::vector<double> ref = env.project_sh(order);  // [i*3 + c]
  for (int c = 0; c < 3; ++c) {
    // Same rule, same texel directions and weights, both summed in double (in a different
    // grouping of rows: ~1e-16 · Σ|terms|, Σ|terms| ≤ 1.5 · L00 · 2√π for l < 6); the runtime
    // rounds each coefficient once to float: ε/2 relative.
    const double scale = 1.5 * 2 * std::sqrt(std::numbers::pi) * ref[size_t(c)];
    for (int i = 0; i < n; ++i) {
      const double r = ref[size_t(i * 3 + c)];
      EXPECT_NEAR(rt[size_t(c * n + i)], r, 0.5 * FLT_EPSILON * std::abs(r) + 1e-13 * scale) << "c " << c << " i " << i;
    }
  }
}

TEST(RuntimeCrosscheck, Band1ShadingOfBakedNormalMatchesDouble) {
  const EnvMap env = EnvMap::load(std::string(PRT_DATA_DIR) + "/forest.exr", UpAxis::Y);
  const Mesh mesh = load_mesh(std::string(PRT_DATA_DIR) + "/bunny_ground.obj");
  const Topology topo = build_topology(mesh);
  ProductRequest req;
  req.radiance = &env;
  const SilhouetteIntegrator sil(mesh, topo, req, {64, 1});
  const ProductLayout& layout = sil.layout();
  std::vector<double> row(layout.width);
  const uint32_t V = uint32_t(mesh.positions.size());
  int checked = 0;
  for (uint32_t v = 0; v < V; v += V / 24) {
    const ShadePoint sp = vertex_shade_point(mesh, topo, v);
    sil.integrate(sp, v, row);
    const double* R = row.data() + layout.radiance;  // [c][m]
    double y[4];
    prt::sh::eval(2, sp.n.x(), sp.n.y(), sp.n.z(), y);
    float Rf[9], nf[3] = {float(sp.n.x()), float(sp.n.y()), float(sp.n.z())}, E[3];
    for (int k = 0; k < 9; ++k) Rf[k] = float(R[k]);
    prt::shade::shade_band1(nf, Rf, E);
    for (int c = 0; c < 3; ++c) {
      double e = 0, mag = 0;
      for (int m = 0; m < 3; ++m) {
        e += y[1 + m] * R[3 * c + m];
        mag += std::abs(y[1 + m] * R[3 * c + m]);
      }
      e *= 4 * std::numbers::pi / 3;
      mag *= 4 * std::numbers::pi / 3;
      // Float rounding of n, R, the constant √(4π/3) and the 3-term sum: each ≤ ε/2 relative of
      // a term, so |ΔE| ≤ 4ε · Σ|terms| ("to float precision").
      EXPECT_NEAR(E[c], e, 4 * FLT_EPSILON * mag) << "vertex " << v << " c " << c;
      EXPECT_TRUE(std::isfinite(E[c]));
    }
    ++checked;
  }
  EXPECT_GE(checked, 24);
}

} // namespace
