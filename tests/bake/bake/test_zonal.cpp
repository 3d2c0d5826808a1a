// Tests of the zonal closed forms (bake/sphere/zonal.h) and of the silhouette integrator's closed-form
// path for shade points that see no contour edge (docs/ARCHITECTURE.md §5).
#include <bake/bake/vertex_bake.h>
#include <bake/environment/envmap.h>
#include <bake/integrators/qmc.h>
#include <bake/integrators/silhouette.h>
#include <bake/mesh/mesh.h>
#include <bake/sphere/zonal.h>
#include <prtshade/sh.h>

#include <gtest/gtest.h>
#include <test_scenes.h>

#include <cmath>
#include <numbers>

using namespace prt::bake;
using Eigen::Vector3d;
using Eigen::Vector3f;
using std::numbers::pi;

namespace {

// Legendre P_l(t) by Bonnet's recurrence.
double legendre(int l, double t) {
  double p0 = 1, p1 = t;
  if (l == 0) return p0;
  for (int k = 1; k < l; ++k) {
    const double p2 = ((2 * k + 1) * t * p1 - k * p0) / (k + 1);
    p0 = p1;
    p1 = p2;
  }
  return p1;
}

// ∫_0^1 t^s P_l(t) dt by composite Gauss–Legendre (64 panels × 20 points, nodes from Newton)
// after t = r² (which makes t^s smooth at 0 for fractional s): the slow reference of
// clamped_power_moments.
double moment_quadrature(double s, int l) {
  constexpr int N = 20, panels = 64;
  static std::vector<double> x, w;
  if (x.empty()) {
    for (int i = 0; i < N; ++i) {
      double z = std::cos(pi * (i + 0.75) / (N + 0.5)), dp = 0;
      for (int it = 0; it < 100; ++it) {
        const double p = legendre(N, z), pm = legendre(N - 1, z);
        dp = N * (z * p - pm) / (z * z - 1);
        const double dz = p / dp;
        z -= dz;
        if (std::abs(dz) < 1e-16) break;
      }
      const double p = legendre(N, z), pm = legendre(N - 1, z);
      dp = N * (z * p - pm) / (z * z - 1);
      x.push_back(z);
      w.push_back(2 / ((1 - z * z) * dp * dp));
    }
  }
  double sum = 0;
  for (int k = 0; k < panels; ++k) {
    const double a = double(k) / panels, b = double(k + 1) / panels;
    for (int i = 0; i < N; ++i) {
      const double r = 0.5 * (a + b) + 0.5 * (b - a) * x[size_t(i)];  // t = r², dt = 2r dr: smooth at 0
      sum += 0.5 * (b - a) * w[size_t(i)] * 2 * std::pow(r, 2 * s + 1) * legendre(l, r * r);
    }
  }
  return sum;
}

} // namespace

TEST(Zonal, MomentsMatchTheKnownClampedCosineAndHemisphereValues) {
  // Ramamoorthi & Hanrahan 2001 eq. 8: λ_l = 2π I_l(1) = π, 2π/3, π/4, 0, −π/24, 0, π/64.
  const auto I1 = clamped_power_moments(1.0, 7);
  const double want1[7] = {1.0 / 2, 1.0 / 3, 1.0 / 8, 0, -1.0 / 48, 0, 1.0 / 128};
  for (int l = 0; l < 7; ++l) EXPECT_NEAR(I1[size_t(l)], want1[l], 1e-16) << l;
  // ∫_0^1 P_l = 1, 1/2, 0, −1/8, 0, 1/16.
  const auto I0 = clamped_power_moments(0.0, 6);
  const double want0[6] = {1, 0.5, 0, -1.0 / 8, 0, 1.0 / 16};
  for (int l = 0; l < 6; ++l) EXPECT_NEAR(I0[size_t(l)], want0[l], 1e-16) << l;
}

TEST(Zonal, MomentsMatchQuadratureForRealExponents) {
  // The quadrature is exact to rounding for these polynomial-like integrands (degree ≤ 2s+2l+1
  // over 64 panels of 20 points), so the two agree to ~1e-13.
  for (double s : {0.5, 1.0, 2.5, 7.0, 32.0, 200.0}) {
    const auto I = clamped_power_moments(s, 24);
    for (int l = 0; l < 24; ++l)
      EXPECT_NEAR(I[size_t(l)], moment_quadrature(s, l), 1e-13) << "s=" << s << " l=" << l;
  }
}

TEST(Zonal, EnergyBeyondOrderAndGlossyOrderSelection) {
  // Clamped cosine: bands 0–2 hold 127/128 of the energy (1 − 3/2·(1/4 + 1/3 + 5/64)).
  EXPECT_NEAR(clamped_power_energy_beyond(1.0, 3), 1.0 / 128, 1e-15);
  EXPECT_NEAR(clamped_power_energy_beyond(1.0, 0), 1.0, 1e-15);
  EXPECT_EQ(clamped_power_order(1.0, 0.01, 64), 3);   // 1/128 < 1% ≤ energy beyond band 1 (1/8)
  EXPECT_EQ(clamped_power_order(1.0, 0.2, 64), 2);
  // The energy beyond falls monotonically with the order and the chosen order grows with the
  // exponent roughly like √s (Ramamoorthi & Hanrahan 2002: the Phong lobe is a Gaussian in l of
  // width √s).
  int prev = 0;
  for (double s : {1.0, 4.0, 16.0, 64.0, 256.0}) {
    for (int L = 1; L < 40; ++L)
      EXPECT_LE(clamped_power_energy_beyond(s, L + 1), clamped_power_energy_beyond(s, L) + 1e-15);
    const int L = clamped_power_order(s, 0.01, 64);
    ASSERT_GT(L, 0);
    EXPECT_GE(L, prev);
    EXPECT_LE(clamped_power_energy_beyond(s, L), 0.01);
    EXPECT_GT(clamped_power_energy_beyond(s, L - 1), 0.01);
    EXPECT_GT(double(L), 0.5 * std::sqrt(s));
    EXPECT_LT(double(L), 4.0 * std::sqrt(s) + 3);
    prev = L;
  }
  EXPECT_EQ(clamped_power_order(1e6, 1e-3, 64), 0);  // a mirror-like lobe has no order ≤ 64
}

TEST(Zonal, ProjectionIsFunkHeckeForAnyNormal) {
  // Σ_i c_i y_i(ω) reconstructs max(n·ω, 0)^s up to the bands kept; check the exact identity
  // ∫ k(n·ω) y_i(ω) dω = λ_l y_i(n) at a tilted normal against the z-axis case rotated by sh::Rotation.
  const Vector3d n = Vector3d(0.3, -0.5, 0.81).normalized();
  std::vector<double> c(36), z(36);
  clamped_power_sh(3.0, 6, n, c);
  clamped_power_sh(3.0, 6, Vector3d::UnitZ(), z);
  // A rotation taking +z to n.
  const Vector3d a = Vector3d::UnitZ().cross(n).normalized();
  const Eigen::Matrix3d R = Eigen::AngleAxisd(std::acos(n.z()), a).toRotationMatrix();
  double Rm[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) Rm[i][j] = R(i, j);
  std::vector<double> rotated(36);
  prt::sh::Rotation(Rm, 6).apply(z, rotated);
  for (int i = 0; i < 36; ++i) EXPECT_NEAR(c[size_t(i)], rotated[size_t(i)], 1e-12) << i;
  // and the unoccluded diffuse transfer of the existing closed forms (n = +z, 1/π · λ_l(1) y):
  std::vector<double> t(9);
  clamped_power_sh(1.0, 3, Vector3d::UnitZ(), t);
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(t[size_t(i)] / pi, prt::testing::unoccluded_transfer_z(i), 1e-15) << i;
}

TEST(SilhouetteClosedForm, UnoccludedVerticesSkipTheWalkAndAreExact) {
  // A lone plane y = 0 facing +Y (the environment's up): its boundary edges lie exactly on every
  // vertex's horizon, so no vertex sees a contour edge and every vertex takes the closed form;
  // AO, T and U equal the Funk–Hecke values to rounding, and the band-1 radiance is the
  // hemisphere integral of the environment (checked against QMC within 5 standard errors).
  prt::bake::Mesh m = prt::testing::grid(3, 1.0f);
  for (auto& p : m.positions) p = Vector3f(p.x(), p.z(), -p.y());  // z-up grid → y-up, same winding sense
  for (auto& n : m.normals) n = Vector3f(n.x(), n.z(), -n.y());
  const Topology topo = build_topology(m);
  const EnvMap env = EnvMap::load(std::string(PRT_DATA_DIR) + "/sunset.exr", UpAxis::Y);
  ProductRequest req;
  req.ao = true;
  req.transfer_order = 4;
  req.visibility_order = 3;
  req.radiance = &env;
  const SilhouetteIntegrator sil(m, topo, req, {128, 1});
  const VertexBake b = bake_vertices(m, topo, sil);
  const auto& L = sil.layout();
  const size_t V = m.positions.size();
  EXPECT_EQ(sil.silhouette_stats().closed_form, V);
  EXPECT_EQ(sil.silhouette_stats().enclosed, 0u);
  EXPECT_EQ(sil.silhouette_stats().crossings, 0u);
  for (size_t v = 0; v < V; ++v) {
    const double* row = &b.values[v * L.width];
    const Vector3d n = m.normals[v].cast<double>();
    std::vector<double> t(16), u(9);
    clamped_power_sh(1.0, 4, n, t);
    clamped_power_sh(0.0, 3, n, u);
    EXPECT_EQ(row[L.ao], 1.0);
    for (size_t i = 0; i < 16; ++i) EXPECT_NEAR(row[L.transfer + i], t[i] / pi, 1e-15);
    for (size_t i = 0; i < 9; ++i) EXPECT_NEAR(row[L.visibility + i], u[i], 1e-15);
    for (size_t i = 0; i < 9; ++i) EXPECT_EQ(row[L.radiance + i], b.values[L.radiance + i]) << "same normal, same value";
  }
  QmcOptions q;
  q.rays = 1 << 16;
  q.seed = 5;
  const QmcIntegrator qmc(m, topo, req, q);
  std::vector<double> ref(L.width), se(L.width);
  qmc.integrate(vertex_shade_point(m, topo, 0), 0, ref, se);
  for (size_t i = 0; i < 9; ++i)
    EXPECT_NEAR(b.values[L.radiance + i], ref[L.radiance + i], 5 * se[L.radiance + i] + 1e-4 * std::abs(ref[L.radiance + i]))
        << "R_" << i;
}

TEST(SilhouetteClosedForm, EnclosedPointGetsZerosFromOneRay) {
  // Inside a closed box no edge is a contour edge (both face planes face the point), so the
  // closed-form path runs and its one ray finds W > 0: every product is exactly 0.
  const Mesh m = prt::testing::box({-1, -1, -1}, {1, 1, 1});
  const Topology topo = build_topology(m);
  const EnvMap white = EnvMap::constant({1, 1, 1});
  ProductRequest req;
  req.ao = true;
  req.transfer_order = 3;
  req.radiance = &white;
  const SilhouetteIntegrator sil(m, topo, req, {64, 1});
  ShadePoint sp;
  sp.p = Vector3d(0.2, -0.3, 0.1);
  sp.n = Vector3d(0.1, 0.2, 0.97).normalized();
  std::vector<double> row(sil.layout().width, -1.0);
  sil.integrate(sp, 0, row);
  for (double x : row) EXPECT_EQ(x, 0.0);
  EXPECT_EQ(sil.silhouette_stats().closed_form, 1u);
  EXPECT_EQ(sil.silhouette_stats().enclosed, 1u);
}
