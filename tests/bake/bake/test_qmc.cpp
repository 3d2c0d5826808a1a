// Tests of the Embree QMC integrator (bake/integrators/qmc.h) against closed forms, with statistical
// tolerances from the integrator's own standard error.
#include <bake/bake/vertex_bake.h>
#include <bake/environment/envmap.h>
#include <bake/integrators/qmc.h>
#include <bake/mesh/mesh.h>
#include <prtshade/sh.h>

#include <gtest/gtest.h>
#include <test_scenes.h>
#include <tbb/global_control.h>

#include <cmath>
#include <numbers>

using namespace prt::bake;
using prt::testing::grid;
using prt::testing::grid_centre;
using prt::testing::polygon_form_factor;
using Eigen::Vector3d;
using Eigen::Vector3f;
using std::numbers::pi;

namespace {

// A z-score bound for comparing an unbiased estimate with the exact value: |err| <= kZ * se
// fails a correct integrator with probability < 1e-4 per comparison (normal tails), while an
// error of a few standard errors in a biased one is caught at these sample counts.
constexpr double kZ = 4.0;

// Flat square grid in the z = 0 plane, (2n+1)² vertices, half-width h; centre vertex index.


} // namespace

TEST(OccludesFromAbove, FlatRingNeverOccludesUpperHemisphere) {
  const Vector3d p(0, 0, 0), n(0, 0, 1);
  for (int k = 0; k < 100; ++k) {
    const double phi = 0.0628 * k, th = 0.0157 * k;
    const Vector3d d(std::sin(th) * std::cos(phi), std::sin(th) * std::sin(phi), std::cos(th));
    EXPECT_FALSE(occludes_from_above(p, {1, 0, 0}, {0, 1, 0}, n, d));
    EXPECT_FALSE(occludes_from_above(p, {0, 1, 0}, {1, 0, 0}, n, d));  // either winding
  }
}

TEST(OccludesFromAbove, ConcaveWallBlocksWhatIsBehindIt) {
  // A wall rising at 45° over +x, corner at p: directions under it (towards +x, low) are blocked.
  const Vector3d p(0, 0, 0), n(0, 0, 1), a(1, -1, 1), b(1, 1, 1);
  EXPECT_TRUE(occludes_from_above(p, a, b, n, Vector3d(1, 0, 0.5).normalized()));
  EXPECT_FALSE(occludes_from_above(p, a, b, n, Vector3d(1, 0, 2).normalized()));   // above the wall
  EXPECT_FALSE(occludes_from_above(p, a, b, n, Vector3d(-1, 0, 0.5).normalized())); // away from it
  EXPECT_FALSE(occludes_from_above(p, a, a, n, Vector3d(1, 0, 0.5).normalized()));  // zero area
}

TEST(Qmc, UnoccludedVertexClosedForms) {
  // Centre of a flat grid, n = +z: nothing occludes (a flat 1-ring does not).
  const Mesh m = grid(2, 1.0f);
  const Topology topo = build_topology(m);
  ProductRequest req;
  req.ao = true;
  req.transfer_order = 3;
  req.visibility_order = 3;
  QmcIntegrator qmc(m, topo, req, {4096, 7});
  const auto& L = qmc.layout();
  std::vector<double> v(L.width), se(L.width);
  qmc.integrate(vertex_shade_point(m, topo, grid_centre(2)), 0, v, se);
  // Closed forms: T_0 = 0.282095 = 1/(2√π), T_2 = 0.325735 = 1/√(3π)... (∫H cos y_10 / π = √3/(3√π)),
  // T_6 = 0.157696 = √5/(8√π); the other T_i = 0; AO = 1; U_0 = √π; U_i = 0 for m ≠ 0.
  // The closed forms agree with the 6-digit values.
  EXPECT_NEAR(prt::testing::unoccluded_transfer_z(0), 0.282095, 5e-7);
  EXPECT_NEAR(prt::testing::unoccluded_transfer_z(2), 0.325735, 5e-7);
  EXPECT_NEAR(prt::testing::unoccluded_transfer_z(6), 0.157696, 5e-7);
  EXPECT_NEAR(v[L.ao], 1.0, kZ * se[L.ao] + 1e-12);
  for (int i = 0; i < 9; ++i) {
    const double exact = prt::testing::unoccluded_transfer_z(i);
    EXPECT_NEAR(v[L.transfer + i], exact, kZ * se[L.transfer + i] + 1e-12) << "T_" << i;
  }
  EXPECT_NEAR(v[L.visibility + 0], std::sqrt(pi), kZ * se[L.visibility] + 1e-12);
  // Under pure cosine sampling the AO and T_0 estimators are constant: exact to rounding.
  ProductRequest cos_only;
  cos_only.ao = true;
  cos_only.transfer_order = 1;
  QmcIntegrator q2(m, topo, cos_only, {256, 3});
  std::vector<double> v2(2);
  q2.integrate(vertex_shade_point(m, topo, grid_centre(2)), 0, v2);
  EXPECT_NEAR(v2[0], 1.0, 1e-12);
  EXPECT_NEAR(v2[1], prt::testing::unoccluded_transfer_z(0), 1e-12);
}

TEST(Qmc, WhiteFurnaceBand1IrradianceIsPi) {
  const Mesh m = grid(1, 1.0f);
  const Topology topo = build_topology(m);
  const EnvMap white = EnvMap::constant({1, 1, 1});
  ProductRequest req;
  req.radiance = &white;
  QmcIntegrator qmc(m, topo, req, {8192, 11});
  std::vector<double> R(9), se(9);
  qmc.integrate(vertex_shade_point(m, topo, grid_centre(1)), 0, R, se);
  double y[4];
  prt::sh::eval(2, 0.0, 0.0, 1.0, y);
  for (int c = 0; c < 3; ++c) {
    double E = 0, seE = 0;
    for (int mm = 0; mm < 3; ++mm) {
      E += (4 * pi / 3) * y[1 + mm] * R[size_t(3 * c + mm)];
      seE += std::pow((4 * pi / 3) * y[1 + mm] * se[size_t(3 * c + mm)], 2);
    }
    EXPECT_NEAR(E, pi, kZ * std::sqrt(seE) + 1e-12) << "channel " << c;
  }
}

// A square occluder of side 2 at height 1 over the centre of a ground grid: AO = 1 − F.
struct SquareScene {
  Mesh mesh;
  uint32_t vertex;
  double exact_ao;
  SquareScene() {
    Mesh g = grid(2, 4.0f);
    vertex = grid_centre(2);
    std::vector<Vector3f> p = {{-0.5f, -1, 1}, {1.5f, -1, 1}, {1.5f, 1, 1}, {-0.5f, 1, 1}};
    Mesh sq = make_mesh(p, {{0, 1, 2}, {0, 2, 3}}, "square");
    std::vector<Mesh> parts{g, sq};
    mesh = merge_meshes(parts, "square-over-grid");
    std::vector<Vector3d> poly;
    for (auto& q : p) poly.push_back(q.cast<double>());
    exact_ao = 1 - polygon_form_factor(Vector3d::Zero(), Vector3d::UnitZ(), poly);
  }
};

TEST(Qmc, SquareOccluderMatchesLambert) {
  SquareScene s;
  const Topology topo = build_topology(s.mesh);
  ProductRequest req;
  req.ao = true;
  QmcIntegrator qmc(s.mesh, topo, req, {16384, 5});
  double ao, se;
  qmc.integrate(vertex_shade_point(s.mesh, topo, s.vertex), 0, std::span(&ao, 1), std::span(&se, 1));
  EXPECT_GT(se, 0);
  EXPECT_NEAR(ao, s.exact_ao, kZ * se) << "exact " << s.exact_ao;
}

TEST(Qmc, ErrorFallsAsTheStandardErrorPredicts) {
  // M independent randomisations (seeds) of the square scene at N = 64, 256, 1024, 4096 rays.
  // For each N: (1) the mean over seeds is unbiased: |mean − exact| ≤ kZ·sd/√M; (2) the RMSE over
  // seeds is at most the Monte Carlo standard error the integrator predicts, with a χ² margin:
  // M·RMSE²/σ² ≤ χ²_{M, 0.9999} (for M = 40, 80.1), i.e. RMSE ≤ 1.415·σ. QMC may do better; it
  // must never do worse. (3) the error falls: RMSE(4096) < RMSE(64)/4 (MC predicts /8).
  SquareScene s;
  const Topology topo = build_topology(s.mesh);
  ProductRequest req;
  req.ao = true;
  constexpr int M = 40;
  const double chi2_margin = std::sqrt(80.1 / M);
  std::vector<double> rmse;
  for (uint32_t N : {64u, 256u, 1024u, 4096u}) {
    double sum = 0, sum2 = 0, se2 = 0;
    for (int seed = 0; seed < M; ++seed) {
      QmcIntegrator qmc(s.mesh, topo, req, {N, uint64_t(1000 + seed)});
      double ao, se;
      qmc.integrate(vertex_shade_point(s.mesh, topo, s.vertex), 0, std::span(&ao, 1), std::span(&se, 1));
      sum += ao - s.exact_ao;
      sum2 += (ao - s.exact_ao) * (ao - s.exact_ao);
      se2 += se * se;
    }
    const double mean = sum / M, r = std::sqrt(sum2 / M), sigma = std::sqrt(se2 / M);
    const double sd = std::sqrt(std::max(0.0, sum2 / M - mean * mean));
    EXPECT_LE(std::abs(mean), kZ * sd / std::sqrt(double(M)) + 1e-12) << "N=" << N;
    EXPECT_LE(r, chi2_margin * sigma) << "N=" << N << " RMSE " << r << " predicted " << sigma;
    rmse.push_back(r);
  }
  EXPECT_LT(rmse.back(), rmse.front() / 4);
}

TEST(Qmc, VGrooveCreaseVertexIsOccludedByItsOwnRing) {
  // Two half-planes meeting along the x axis at interior angle α; the crease vertex at the
  // origin has the bisector normal +z. Exact: AO = sin(α/2) (∫ over the lune of cos / π).
  // In the limit from above only the cones of the 1-ring at the vertex matter, and the three
  // triangles of each plane fan out over its whole half-plane, so the expectation is exact and
  // all of the occlusion comes from the analytic 1-ring test (Embree's ring hits are filtered).
  for (double alpha : {pi / 2, 2 * pi / 3, 0.8 * pi}) {
    const double c = std::cos(alpha / 2), s = std::sin(alpha / 2);
    const float S = 1000;
    std::vector<Vector3f> p = {{0, 0, 0}, {S, 0, 0}, {-S, 0, 0},
                               {S, float(s), float(c)}, {-S, float(s), float(c)},
                               {S, float(-s), float(c)}, {-S, float(-s), float(c)}};
    std::vector<std::array<uint32_t, 3>> t = {{0, 1, 3}, {0, 3, 4}, {0, 4, 2}, {0, 5, 1}, {0, 6, 5}, {0, 2, 6}};
    Mesh m = make_mesh(p, t, "vgroove", std::vector<Vector3f>(p.size(), Vector3f(0, 0, 1)));
    const Topology topo = build_topology(m);
    ProductRequest req;
    req.ao = true;
    QmcIntegrator qmc(m, topo, req, {8192, 3});
    double ao, se;
    qmc.integrate(vertex_shade_point(m, topo, 0), 0, std::span(&ao, 1), std::span(&se, 1));
    EXPECT_NEAR(ao, std::sin(alpha / 2), kZ * se + 1e-12) << "alpha " << alpha;
  }
}

TEST(Qmc, SameSeedSameNumbersWhateverTheThreadCount) {
  SquareScene s;
  const Topology topo = build_topology(s.mesh);
  ProductRequest req;
  req.ao = true;
  req.transfer_order = 3;
  req.visibility_order = 2;
  QmcIntegrator qmc(s.mesh, topo, req, {128, 9});
  VertexBake one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = bake_vertices(s.mesh, topo, qmc);
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    two = bake_vertices(s.mesh, topo, qmc);
  }
  ASSERT_EQ(one.values.size(), two.values.size());
  EXPECT_EQ(one.values, two.values);  // bitwise
  for (double x : one.values) EXPECT_TRUE(std::isfinite(x));
}

TEST(SeededSample, DistinctSortedAndDeterministic) {
  const auto a = seeded_sample(1000, 50, 4), b = seeded_sample(1000, 50, 4), c = seeded_sample(1000, 50, 5);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  EXPECT_TRUE(std::is_sorted(a.begin(), a.end()));
  EXPECT_EQ(std::adjacent_find(a.begin(), a.end()), a.end());
  EXPECT_EQ(seeded_sample(10, 50, 1).size(), 10u);
}
