// SH projection of spherical polygons (bake/sphere/polygon_sh.h) against exact zonal cases (the
// hemisphere, spherical caps approximated by regular polygons with a rigorous bound), rotation
// equivariance through prtshade's SH rotation, band 1 against Lambert, and RQMC at 2^16 points.
#include <bake/sphere/polygon_sh.h>
#include <bake/sphere/spherical_polygon.h>
#include <bake/sphere/zonal.h>
#include <prtshade/sh.h>

#include <sphere_rqmc.h>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <numbers>
#include <random>
#include <vector>

namespace {

using prt::bake::PolygonSH;
using V3 = Eigen::Vector3d;
using Poly = std::vector<V3>;
constexpr double kPi = std::numbers::pi;

std::vector<double> project(const PolygonSH& sh, const Poly& p) {
  std::vector<double> c(size_t(sh.order() * sh.order()));
  sh.project(p, c);
  return c;
}

// Three vertices on the great circle ⊥ n, counter-clockwise about n: the hemisphere n·ω ≥ 0.
Poly hemisphere(const V3& n) {
  const V3 t = n.unitOrthogonal(), b = n.cross(t);
  Poly p;
  for (int k = 0; k < 3; ++k) p.push_back(std::cos(2 * kPi * k / 3) * t + std::sin(2 * kPi * k / 3) * b);
  return p;
}


// Legendre P_l(x) from prtshade's zonal basis function: y_l0 = √((2l+1)/(4π)) P_l(cos θ)
// (independent of the library's monomial expansion).
double legendre(int l, double x) {
  std::vector<double> y(size_t((l + 1) * (l + 1)));
  prt::sh::eval(l + 1, std::sqrt(1 - x * x), 0.0, x, y);
  return y[size_t(prt::sh::index(l, 0))] / std::sqrt((2 * l + 1) / (4 * kPi));
}

TEST(PolygonSH, HemisphereIsTheZonalClosedForm) {
  // U_lm = 2π I_l(0) y_lm(n) (bake/sphere/zonal.h, Funk–Hecke). The coefficients are O(1); the
  // projection's rounding was measured ≤ 5e-15 up to order 12, so 1e-13 leaves a 20× margin.
  std::mt19937_64 rng(1);
  for (int order : {3, 6, 12}) {
    const PolygonSH sh(order);
    const double tol = 1e-13;
    for (int k = 0; k < 10; ++k) {
      const V3 n = k == 0 ? V3::UnitZ() : V3(prt::test::random_rotation(rng) * V3::UnitZ());
      std::vector<double> expected(size_t(order * order));
      prt::bake::clamped_power_sh(0.0, order, n, expected);
      const auto got = project(sh, hemisphere(n));
      for (size_t i = 0; i < got.size(); ++i) EXPECT_NEAR(got[i], expected[i], tol) << order << " " << i;
    }
  }
}

TEST(PolygonSH, RegularPolygonApproachesTheCap) {
  // A spherical cap of angular radius α about +z has c_l0 = 2π √((2l+1)/(4π)) ∫_{cos α}^1 P_l,
  // ∫_x^1 P_l = (P_{l−1}(x) − P_{l+1}(x))/(2l+1) (l ≥ 1), and c_lm = 0 for m ≠ 0. The inscribed
  // regular N-gon differs from the cap by a region of solid angle ΔΩ = Ω_cap − Ω_N, and
  // |y_lm| ≤ √((2l+1)/(4π)), so |c_lm(N-gon) − c_lm(cap)| ≤ √((2l+1)/(4π)) ΔΩ (+1e-12 rounding).
  const int order = 8;
  const PolygonSH sh(order);
  for (double alpha : {0.3, 1.0, 1.4}) {
    for (int n : {16, 256}) {
      Poly p;
      for (int k = 0; k < n; ++k) {
        const double a = 2 * kPi * k / n;
        p.emplace_back(std::sin(alpha) * std::cos(a), std::sin(alpha) * std::sin(a), std::cos(alpha));
      }
      const double x = std::cos(alpha);
      const double gap = 2 * kPi * (1 - x) - prt::bake::solid_angle(p);
      ASSERT_GT(gap, 0);
      const auto got = project(sh, p);
      for (int l = 0; l < order; ++l) {
        const double norm = std::sqrt((2 * l + 1) / (4 * kPi));
        const double integral = l == 0 ? 1 - x : (legendre(l - 1, x) - legendre(l + 1, x)) / (2 * l + 1);
        for (int m = -l; m <= l; ++m) {
          const double cap = m == 0 ? 2 * kPi * norm * integral : 0;
          EXPECT_NEAR(got[size_t(prt::sh::index(l, m))], cap, norm * gap + 1e-12) << alpha << " " << n << " " << l << " " << m;
        }
      }
    }
  }
}

TEST(PolygonSH, RotationEquivariantAndBand1IsLambert) {
  // project(R P) = D(R) project(P) (prtshade's rotation convention) and the band-1 coefficients
  // reproduce the cosine integral: ∫_P n·ω = (4π/3) Σ_m y_1m(n) c_1m. Values O(1); 1e-12 covers
  // the rotation's and the projection's rounding.
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(-1, 1);
  const int order = 6;
  const PolygonSH sh(order);
  for (int k = 0; k < 20; ++k) {
    Poly p;
    for (int i = 0; i < 5; ++i) p.emplace_back(std::cos(2 * kPi * i / 5) + 0.2 * u(rng), std::sin(2 * kPi * i / 5) + 0.2 * u(rng), 1.5 + 0.3 * u(rng));
    const Eigen::Matrix3d r = prt::test::random_rotation(rng);
    Poly rp;
    for (const V3& v : p) rp.push_back(r * v);
    double rm[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) rm[i][j] = r(i, j);
    const prt::sh::Rotation rot(rm, order);
    const auto c = project(sh, p), rc = project(sh, rp);
    std::vector<double> expected(c.size());
    rot.apply(c, expected);
    for (size_t i = 0; i < c.size(); ++i) EXPECT_NEAR(rc[i], expected[i], 1e-12) << i;
    const V3 n = V3(u(rng), u(rng), u(rng)).normalized();
    std::vector<double> y(4);
    prt::sh::eval(2, n.x(), n.y(), n.z(), y);
    const double band1 = 4 * kPi / 3 * (y[1] * c[1] + y[2] * c[2] + y[3] * c[3]);
    EXPECT_NEAR(band1, prt::bake::cosine_integral(p, n), 1e-13);
  }
}

// RQMC (64 rotations × 2^10 = 2^16 points) at order 6 for convex polygons, a horizon-clipped one
// and a non-convex (L-shaped) one; tolerance 4 standard errors + 1e-12 (closed-form rounding).
TEST(PolygonSH, AgreesWithRqmc) {
  const int order = 6, count = order * order;
  const PolygonSH sh(order);
  const V3 n = V3(0.2, -0.4, 1).normalized();
  const Poly quad{{-1, -0.5, 1}, {1.5, -0.7, 1.2}, {1, 1, 0.8}, {-0.8, 0.6, 1}};
  const Poly crossing{{-1, 1, -1}, {-1, 1, 1}, {1, 1, 1}, {1, 1, -1}};
  Poly clipped;
  prt::bake::clip_to_horizon(crossing, n, clipped);
  const Poly ell{{0, 0, 1}, {2, 0, 1}, {2, 1, 1}, {1, 1, 1}, {1, 2, 1}, {0, 2, 1}};
  const Poly ell0{{0, 0, 1}, {2, 0, 1}, {2, 1, 1}, {0, 1, 1}}, ell1{{0, 1, 1}, {1, 1, 1}, {1, 2, 1}, {0, 2, 1}};
  struct Case {
    const Poly* polygon;
    std::function<bool(const V3&)> inside;
  };
  const std::vector<Case> cases{
      {&quad, [&](const V3& w) { return prt::test::inside_convex(quad, w); }},
      {&clipped, [&](const V3& w) { return prt::test::inside_convex(crossing, w) && n.dot(w) >= 0; }},
      {&ell, [&](const V3& w) { return prt::test::inside_convex(ell0, w) || prt::test::inside_convex(ell1, w); }},
  };
  uint64_t seed = 40;
  for (const Case& c : cases) {
    const auto est = prt::test::rqmc_sphere(count, 64, 1 << 10, seed++, [&](const V3& w, std::span<double> out) {
      if (c.inside(w)) {
        prt::sh::eval(order, w.x(), w.y(), w.z(), out);
      } else {
        std::fill(out.begin(), out.end(), 0.0);
      }
    });
    const auto got = project(sh, *c.polygon);
    for (int i = 0; i < count; ++i)
      EXPECT_NEAR(got[size_t(i)], est.mean[size_t(i)], 4 * est.std_error[size_t(i)] + 1e-12) << seed << " " << i;
  }
}

} // namespace
