// Tests of the shadowed radiance S_c,i = ∫ L_c V H y_i dω (bake/integrators/products.h; paper 001 §4,
// "Material Editing"): closed forms, an exactly known occluded case, band 1 against the band-1
// radiance R, agreement of the silhouette and QMC integrators within QMC's standard error, and the
// filter integrator's QMC route.
#include <bake/bake/vertex_bake.h>
#include <bake/environment/envmap.h>
#include <bake/integrators/filter.h>
#include <bake/integrators/qmc.h>
#include <bake/integrators/silhouette.h>
#include <bake/mesh/mesh.h>
#include <bake/sphere/polygon_sh.h>
#include <bake/sphere/zonal.h>
#include <prtshade/sh.h>

#include <gtest/gtest.h>
#include <test_scenes.h>

#include <cmath>

using namespace prt::bake;
using prt::testing::grid;
using prt::testing::grid_centre;
using Eigen::Vector3d;
using Eigen::Vector3f;

namespace {

const Rgb kColour{0.7, 1.3, 2.1};  // distinct channels: a channel mix-up shows

std::vector<double> row_of(const Integrator& I, const ShadePoint& p, uint64_t index, std::vector<double>* se = nullptr) {
  std::vector<double> r(I.layout().width);
  if (se) se->assign(r.size(), 0.0);
  I.integrate(p, index, r, se ? std::span<double>(*se) : std::span<double>());
  return r;
}

ProductRequest shadowed(const EnvMap& env, int order, bool band1 = false) {
  ProductRequest r;
  r.shadowed = &env;
  r.shadowed_order = order;
  if (band1) r.radiance = &env;
  return r;
}

// S of a constant environment kColour seen through `visible` (U's values: ∫ V H y_i dω):
// S_c,i = kColour_c · visible_i, the row layout [c][i].
std::vector<double> coloured(const std::vector<double>& visible) {
  std::vector<double> s;
  for (double c : {kColour.r, kColour.g, kColour.b})
    for (double u : visible) s.push_back(c * u);
  return s;
}

} // namespace

TEST(ShadowedRadiance, LayoutPutsSLastWithOrderSquaredPerChannel) {
  const EnvMap env = EnvMap::constant(kColour);
  ProductRequest r = shadowed(env, 5, true);
  r.ao = true;
  r.visibility_order = 3;
  const ProductLayout L(r);
  EXPECT_EQ(L.radiance, 1u + 9u);
  EXPECT_EQ(L.shadowed, L.radiance + 9);
  EXPECT_EQ(L.shadowed_count, 75u);
  EXPECT_EQ(L.width, L.shadowed + 75);
  EXPECT_TRUE(r.consistent());
  ProductRequest bad = r;
  bad.shadowed_order = 0;  // an environment without an order
  EXPECT_FALSE(bad.consistent());
  const EnvMap other = EnvMap::constant(kColour);
  bad = r;
  bad.radiance = &other;  // R and S under two environments
  EXPECT_FALSE(bad.consistent());
}

TEST(ShadowedRadiance, UnoccludedVertexUnderAConstantSkyIsTheClampedConstant) {
  // A lone flat grid: its centre vertex sees the whole upper hemisphere, so with L ≡ c,
  // S_c,i = c ∫ H y_i dω = c · 2π I_l(0) y_i(n) (Funk–Hecke, bake/sphere/zonal.h). Order 18 takes the
  // silhouette tables' path for orders above 16.
  const Mesh m = grid(2, 1.0f);
  const Topology topo = build_topology(m);
  const EnvMap env = EnvMap::constant(kColour);
  const ShadePoint p = vertex_shade_point(m, topo, grid_centre(2));
  for (const int order : {4, 18}) {
    std::vector<double> u(size_t(order * order));
    clamped_power_sh(0.0, order, p.n, u);
    const std::vector<double> exact = coloured(u);
    const ProductRequest req = shadowed(env, order);
    const SilhouetteIntegrator sil(m, topo, req, {128, 1});
    const std::vector<double> s = row_of(sil, p, 0);
    EXPECT_EQ(sil.silhouette_stats().closed_form, 1u) << "no contour edge in view: the horizon-only walk";
    // The horizon walk's discretisation: midpoint rule across isolines, cell-constant f·J along
    // them, O(h²) with h = 2/128 (≈ 2.4e-4), the cells straddling the horizon O(h) each but
    // cancelling along it. Measured (max |ΔS| / c): 2.4e-4 at order 4, 6.4e-4 at order 18, where
    // y_i varies faster; the bounds keep a factor 2–3.
    const double tol = order == 4 ? 5e-4 : 2e-3;
    for (size_t k = 0; k < exact.size(); ++k)
      EXPECT_NEAR(s[k], exact[k], tol * kColour.b) << "order " << order << " S_" << k;
    QmcIntegrator qmc(m, topo, req, {4096, 3});
    std::vector<double> se;
    const std::vector<double> q = row_of(qmc, p, 0, &se);
    for (size_t k = 0; k < exact.size(); ++k)
      EXPECT_NEAR(q[k], exact[k], 5 * se[k] + 1e-12) << "order " << order << " S_" << k;
  }
}

TEST(ShadowedRadiance, SquareOccluderRemovesItsSphericalPolygonExactly) {
  // A square at height 1 over the centre vertex of a large grid (SquareOccluderMatchesLambert in
  // test_silhouette.cpp): V H = H minus the square's spherical polygon P, so under L ≡ c
  // S_c,i = c (∫ H y_i − ∫_P y_i), the latter in closed form (bake/sphere/polygon_sh.h).
  const int order = 6;
  Mesh g = grid(2, 4.0f);
  std::vector<Vector3f> sq = {{-0.5f, -1, 1}, {1.5f, -1, 1}, {1.5f, 1, 1}, {-0.5f, 1, 1}};
  std::vector<Mesh> parts{g, make_mesh(sq, {{0, 1, 2}, {0, 2, 3}}, "square")};
  const Mesh m = merge_meshes(parts, "scene");
  const Topology topo = build_topology(m);
  const ShadePoint p = vertex_shade_point(m, topo, grid_centre(2));
  std::vector<Vector3d> poly;
  for (const Vector3f& q : sq) poly.push_back(q.cast<double>() - p.p);
  std::vector<double> hemi(size_t(order * order)), cap(size_t(order * order));
  clamped_power_sh(0.0, order, p.n, hemi);
  PolygonSH(order).project(poly, cap);
  if (cap[0] < 0)  // orientation: the polygon's coefficients as a positive region
    for (double& c : cap) c = -c;
  std::vector<double> visible(hemi.size());
  for (size_t i = 0; i < hemi.size(); ++i) visible[i] = hemi[i] - cap[i];
  const std::vector<double> exact = coloured(visible);
  const EnvMap env = EnvMap::constant(kColour);
  const ProductRequest req = shadowed(env, order);
  const SilhouetteIntegrator sil(m, topo, req, {256, 1});
  const std::vector<double> s = row_of(sil, p, 0);
  // O(h²) at h = 2/256 (≈ 6e-5) with the order-6 basis' variation: 2e-4 · c (measured 7.3e-5 · c).
  for (size_t k = 0; k < exact.size(); ++k) EXPECT_NEAR(s[k], exact[k], 2e-4 * kColour.b) << "S_" << k;
  QmcIntegrator qmc(m, topo, req, {8192, 7});
  std::vector<double> se;
  const std::vector<double> q = row_of(qmc, p, 0, &se);
  for (size_t k = 0; k < exact.size(); ++k) EXPECT_NEAR(q[k], exact[k], 5 * se[k] + 1e-12) << "S_" << k;
}

TEST(ShadowedRadiance, BandOneIsTheBand1RadianceExactly) {
  // R_c,m and S_c,(2+m) are the same integral. Baked together they come from the same samples
  // (QMC) or the same table columns' values (silhouette), so they are equal bit for bit; and S
  // at order 2 alone equals R alone on the silhouette integrator (the same integrand values in the
  // same tables). The environment has hot texels (the sun of sunset.exr: the fine grid's path).
  const Mesh m = load_mesh(std::string(PRT_DATA_DIR) + "/bunny_ground.obj", {.use_file_normals = false});
  const Topology topo = build_topology(m);
  const EnvMap env = EnvMap::load(std::string(PRT_DATA_DIR) + "/sunset.exr", UpAxis::Y);
  const ProductRequest both = shadowed(env, 4, true);
  ProductRequest r_only;
  r_only.radiance = &env;
  const SilhouetteIntegrator sil_both(m, topo, both, {128, 1}), sil_r(m, topo, r_only, {128, 1}),
      sil_s2(m, topo, shadowed(env, 2), {128, 1});
  ASSERT_NE(sil_both.description().find("hot environment texels"), std::string::npos) << sil_both.description();
  const QmcIntegrator qmc_both(m, topo, both, {512, 9});
  const ProductLayout L(both);
  for (uint32_t v : seeded_sample(uint32_t(m.positions.size()), 12, 5)) {
    const ShadePoint p = vertex_shade_point(m, topo, v);
    for (const Integrator* I : {static_cast<const Integrator*>(&sil_both), static_cast<const Integrator*>(&qmc_both)}) {
      const std::vector<double> row = row_of(*I, p, v);
      for (size_t c = 0; c < 3; ++c)
        for (size_t mm = 0; mm < 3; ++mm)
          EXPECT_EQ(row[L.radiance + 3 * c + mm], row[L.shadowed + 16 * c + 1 + mm]) << "vertex " << v;
    }
    const std::vector<double> r = row_of(sil_r, p, v), s2 = row_of(sil_s2, p, v);
    for (size_t c = 0; c < 3; ++c)
      for (size_t mm = 0; mm < 3; ++mm) EXPECT_EQ(r[3 * c + mm], s2[4 * c + 1 + mm]) << "vertex " << v;
  }
}

TEST(ShadowedRadiance, SilhouetteAgreesWithQmcWithinItsStandardError) {
  // Occluded vertices of the bunny on its ground plane under sunset.exr (an HDR sun), order 4.
  const Mesh m = load_mesh(std::string(PRT_DATA_DIR) + "/bunny_ground.obj", {.use_file_normals = false});
  const Topology topo = build_topology(m);
  const EnvMap env = EnvMap::load(std::string(PRT_DATA_DIR) + "/sunset.exr", UpAxis::Y);
  const ProductRequest req = shadowed(env, 4);
  const SilhouetteIntegrator sil(m, topo, req, {256, 1});
  const QmcIntegrator qmc(m, topo, req, {32768, 17});
  double max_z = 0;
  for (uint32_t v : seeded_sample(uint32_t(m.positions.size()), 16, 11)) {
    const ShadePoint p = vertex_shade_point(m, topo, v);
    std::vector<double> se;
    const std::vector<double> a = row_of(sil, p, v), b = row_of(qmc, p, v, &se);
    // Per channel, the scale of the values (the discretisation error of the silhouette
    // tables is relative to it: the sun's energy box-filtered across a shadow edge).
    for (size_t c = 0; c < 3; ++c) {
      double scale = 0;
      for (size_t i = 0; i < 16; ++i) scale = std::max(scale, std::abs(b[16 * c + i]));
      for (size_t i = 0; i < 16; ++i) {
        const size_t k = 16 * c + i;
        // 4 QMC standard errors, plus the silhouette's discretisation: 1e-3 of the channel's
        // largest coefficient (a sun cut by a shadow edge is resolved on the hot texels' fine
        // grid, SunOnTheHorizonIsResolvedBelowTexelSize). Measured: the largest |ΔS| is 0.14 of
        // this bound.
        const double tol = 4 * se[k] + 1e-3 * scale;
        EXPECT_NEAR(a[k], b[k], tol) << "vertex " << v << " S_" << k;
        max_z = std::max(max_z, std::abs(a[k] - b[k]) / tol);
      }
    }
  }
  RecordProperty("max_error_over_tolerance", std::to_string(max_z));
  EXPECT_EQ(sil.silhouette_stats().inconsistent_loops, 0u);
}

TEST(ShadowedRadiance, FilterRoutesItToQmc) {
  // The filter integrator's band limit does not hold for an HDR environment: S, like R, is its
  // QMC integrator's (radiance_rays rays, the filter's seed), value for value.
  const Mesh m = load_mesh(std::string(PRT_DATA_DIR) + "/bunny_ground.obj", {.use_file_normals = false});
  const Topology topo = build_topology(m);
  const EnvMap env = EnvMap::load(std::string(PRT_DATA_DIR) + "/sunset.exr", UpAxis::Y);
  ProductRequest req = shadowed(env, 3, true);
  req.ao = true;
  FilterOptions fo;
  const FilterIntegrator filter(m, topo, req, fo);
  const QmcIntegrator qmc(m, topo, shadowed(env, 3, true), {fo.radiance_rays, fo.seed});
  const std::vector<ShadePoint> points = vertex_shade_points(m, topo);
  const std::vector<uint32_t> picked = seeded_sample(uint32_t(points.size()), 8, 3);
  const VertexBake b = bake_points(points, filter);
  const ProductLayout L(req);
  for (uint32_t v : picked) {
    const std::vector<double> q = row_of(qmc, points[v], v);
    for (size_t k = 0; k < q.size(); ++k) EXPECT_EQ(b.values[size_t(v) * L.width + L.radiance + k], q[k]) << v;
  }
}
