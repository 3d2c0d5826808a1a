// Glossy shading (prtshade/glossy.h): the Gaunt table against an independent brute-force quadrature
// (no selection rules, more nodes), the Phong band scales against their integral, closed forms of
// the two routes, and the truncated result against the true shadowed lobe integral.
#include <prtshade/glossy.h>
#include <prtshade/sh.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <random>
#include <span>
#include <stdexcept>
#include <tuple>
#include <vector>

using namespace prt;
using std::numbers::pi;

namespace {

// A product rule on the sphere exact for band-limited functions of degree < 2·nt (Gauss–Legendre
// in cos θ by Newton, uniform in φ with np nodes): the test's own, independent of glossy.cpp's.
struct SphereRule {
  std::vector<std::array<double, 3>> dir;
  std::vector<double> w;
};
SphereRule sphere_rule(int nt, int np) {
  SphereRule r;
  for (int a = 0; a < nt; ++a) {
    // Newton on P_nt from a Chebyshev guess (Golub–Welsch would do as well).
    double t = std::cos(pi * (a + 0.75) / (nt + 0.5)), d = 1;
    for (int it = 0; it < 200; ++it) {
      double p0 = 1, p1 = t;
      for (int k = 2; k <= nt; ++k) std::tie(p0, p1) = std::pair(p1, ((2 * k - 1) * t * p1 - (k - 1) * p0) / k);
      d = nt * (t * p1 - p0) / (t * t - 1);
      t -= p1 / d;
    }
    const double wt = 2 / ((1 - t * t) * d * d), st = std::sqrt(1 - t * t);
    for (int b = 0; b < np; ++b) {
      const double phi = 2 * pi * (b + 0.5) / np;  // shifted nodes: another rule than the library's
      r.dir.push_back({st * std::cos(phi), st * std::sin(phi), t});
      r.w.push_back(wt * 2 * pi / np);
    }
  }
  return r;
}

std::vector<double> eval_sh(int order, const std::array<double, 3>& d) {
  std::vector<double> y(size_t(order * order));
  sh::eval(order, d[0], d[1], d[2], y);
  return y;
}

} // namespace

TEST(Glossy, GauntTableEqualsBruteForceQuadratureEntryForEntry) {
  // Every triple (no selection rules), by a finer rule with shifted φ nodes: the library's table
  // must hold exactly the non-zeros, to 1e-13 (double quadrature of O(1) products of ~100 nodes).
  for (int L : {1, 2, 3, 5}) {
    const shade::TripleProduct tp(L);
    const int n = L * L;
    const SphereRule rule = sphere_rule(2 * L + 2, 4 * L + 4);
    std::vector<std::vector<double>> Y;
    for (const auto& d : rule.dir) Y.push_back(eval_sh(L, d));
    std::map<std::tuple<int, int, int>, double> table;
    for (const auto& e : tp.entries()) {
      EXPECT_LE(e.i, e.j);
      table[{e.k, e.i, e.j}] = e.gamma;
    }
    size_t nonzero = 0;
    for (int k = 0; k < n; ++k)
      for (int i = 0; i < n; ++i)
        for (int j = i; j < n; ++j) {
          double g = 0;
          for (size_t q = 0; q < rule.w.size(); ++q) g += rule.w[q] * Y[q][size_t(i)] * Y[q][size_t(j)] * Y[q][size_t(k)];
          const auto it = table.find({k, i, j});
          const double mine = it == table.end() ? 0.0 : it->second;
          EXPECT_NEAR(mine, g, 1e-13) << "L " << L << " (i, j, k) = " << i << ", " << j << ", " << k;
          nonzero += std::abs(g) > 1e-12;
        }
    EXPECT_EQ(tp.entries().size(), nonzero) << L;
  }
  EXPECT_THROW(shade::TripleProduct(0), std::invalid_argument);
  EXPECT_THROW(shade::TripleProduct(shade::kMaxGlossyOrder + 1), std::invalid_argument);
}

TEST(Glossy, MultiplyIsSymmetricAndTheConstantIsItsUnit) {
  const int L = 6, n = L * L;
  const shade::TripleProduct tp(L);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1, 1);
  std::vector<float> a(n), b(n), ab(n), ba(n), one(n, 0.0f), out(n);
  for (int i = 0; i < n; ++i) a[size_t(i)] = u(rng), b[size_t(i)] = u(rng);
  tp.multiply(a.data(), b.data(), ab.data());
  tp.multiply(b.data(), a.data(), ba.data());
  EXPECT_EQ(ab, ba) << "the same terms in the same order";
  // 1 = √(4π) y_00: multiplying by it returns b, to float rounding of b (the sum is one term).
  one[0] = float(std::sqrt(4 * pi));
  tp.multiply(one.data(), b.data(), out.data());
  for (int i = 0; i < n; ++i) EXPECT_NEAR(out[size_t(i)], b[size_t(i)], 2e-7f) << i;
}

TEST(Glossy, TheLightingMatrixPathMatchesTheGauntReferenceWithinItsFloatBound) {
  // S_fast = M U in float against the double Gaunt pass: |ΔS_k| <= (n² + 2) ε_f Σ_j |M_jk U_j|
  // (glossy.h), with M from the double matrices the test rebuilds (the same sums, independent
  // of the float storage).
  std::mt19937 rng(11);
  std::normal_distribution<float> g;
  for (int L : {3, 7, 11}) {
    const int n = L * L;
    const shade::TripleProduct tp(L);
    std::vector<float> light(3 * n), U(n), fast(3 * n), ref(n);
    for (float& x : light) x = g(rng);
    for (float& x : U) x = g(rng);
    const shade::GlossyLight lit(tp, light.data());
    lit.shadowed_radiance(U.data(), fast.data());
    for (int c = 0; c < 3; ++c) {
      tp.multiply(light.data() + c * n, U.data(), ref.data());
      for (int k = 0; k < n; ++k) {
        double mag = 0;
        for (int j = 0; j < n; ++j) mag += std::abs(double(lit.matrices()[size_t((c * n + j) * n + k)]) * U[size_t(j)]);
        const double bound = (n + 2) * std::ldexp(1.0, -24) * mag + std::ldexp(1.0, -24) * std::abs(ref[size_t(k)]);
        EXPECT_LE(std::abs(double(fast[size_t(c * n + k)]) - double(ref[size_t(k)])), bound) << "L " << L << " c " << c << " k " << k;
      }
    }
  }
}

TEST(Glossy, PhongBandScalesAreTheLobesFunkHeckeIntegrals) {
  // λ_l = 2π ∫_{-1}^{1} k_s(t) P_l(t) dt with k_s(t) = (s+1)/(2π) max(t,0)^s: for integer s the
  // integrand on [0, 1] is a polynomial of degree s + l, integrated exactly by Gauss–Legendre
  // with 80 nodes mapped to [0, 1]; λ_0 = 1 (the lobe is normalised).
  const SphereRule rule = sphere_rule(80, 1);  // only its cos θ nodes and weights are used
  for (double s : {0.0, 1.0, 4.0, 24.0, 128.0}) {
    double lambda[12];
    shade::phong_band_scales(s, 12, lambda);
    EXPECT_NEAR(lambda[0], 1.0, 1e-15) << s;
    for (int l = 0; l < 12; ++l) {
      double integral = 0;
      for (size_t q = 0; q < rule.w.size(); ++q) {
        const double t = 0.5 * (rule.dir[q][2] + 1), w = 0.5 * rule.w[q] / (2 * pi);  // the rule's weights sum to 4π
        double p0 = 1, p1 = t;
        for (int k = 2; k <= l; ++k) std::tie(p0, p1) = std::pair(p1, ((2 * k - 1) * t * p1 - (k - 1) * p0) / k);
        integral += w * (s + 1) * std::pow(t, s) * (l == 0 ? 1.0 : p1);
      }
      EXPECT_NEAR(lambda[l], integral, 1e-12) << "s " << s << " l " << l;
    }
  }
}

TEST(Glossy, ClosedFormsOfBothRoutes) {
  const int L = 8, n = L * L;
  const shade::TripleProduct tp(L);
  double scales[L];
  shade::phong_band_scales(24, L, scales);
  const float r[3] = {0.48f, 0.6f, 0.64f};  // unit
  // White furnace, route B: S = ∫ 1 · y_k over the whole sphere = √(4π) δ_k0, so L_out = λ_0 = 1.
  std::vector<float> S(3 * n, 0.0f);
  for (int c = 0; c < 3; ++c) S[size_t(c * n)] = float(std::sqrt(4 * pi));
  float out[3];
  shade::shade_glossy_radiance(S.data(), L, scales, r, out);
  for (float v : out) EXPECT_NEAR(v, 1.0f, 1e-6f);
  // Route A with nothing in the way (U = √(4π) δ_0, V H ≡ 1) and lighting y_lm, one (l, m) per
  // channel: S = y_lm exactly, L_out = λ_l y_lm(r). Float rounding: a few 1e-7.
  std::vector<float> U(n, 0.0f), light(3 * n, 0.0f);
  U[0] = float(std::sqrt(4 * pi));
  const int lm[3][2] = {{1, -1}, {3, 2}, {7, -5}};
  for (int c = 0; c < 3; ++c) light[size_t(c * n + sh::index(lm[c][0], lm[c][1]))] = 1.0f;
  shade::shade_glossy(tp, light.data(), U.data(), scales, r, out);
  for (int c = 0; c < 3; ++c) {
    const double expect = scales[lm[c][0]] * sh::eval_slow(lm[c][0], lm[c][1], r[0], r[1], r[2]);
    EXPECT_NEAR(out[c], expect, 1e-6) << c;
  }
  // The batch form: v = eye − p reflected about n; eye straight above a vertex with n = +z
  // reflects to r = n. The fast path gives the same closed form (S has one non-zero term).
  const float nrm[3] = {0, 0, 1}, pos[3] = {1, 2, 3}, eye[3] = {1, 2, 10};
  const shade::GlossyLight lit(tp, light.data());
  float batch[3];
  shade::shade_glossy_vertices(lit, U.data(), nrm, pos, 1, eye, 24, batch);
  for (int c = 0; c < 3; ++c) {
    const double expect = scales[lm[c][0]] * sh::eval_slow(lm[c][0], lm[c][1], 0, 0, 1);
    EXPECT_NEAR(batch[c], expect, 1e-6) << c;
  }
  EXPECT_THROW(shade::shade_glossy_vertices(lit, U.data(), nrm, pos, 1, eye, -1, batch), std::invalid_argument);
  EXPECT_THROW(shade::shade_glossy_vertices(lit, nullptr, nrm, pos, 1, eye, 4, batch), std::invalid_argument);
  EXPECT_THROW(shade::GlossyLight(tp, nullptr), std::invalid_argument);
}

TEST(Glossy, TruncatedRouteAConvergesToTheShadowedLobeIntegral) {
  // A vertex with n = +z under a wall that blocks every direction with x > 0.5 (V = [ω_x <= 0.5]),
  // a smooth sky L(ω) = 1 + 0.5 ω_z + 0.3 ω_x, a Phong lobe s = 4 about r tilted 30° from n. The true
  // L_out = ∫ L V H k_s(r·ω) dω by a fine quadrature (2000 × 4000 nodes; V and H are discontinuous,
  // so it is good to ~1e-6). Route A at order L uses U = the quadrature's projection of V H and the
  // exact SH of L. The error is the truncation of U, of the product and of the lobe; it falls with
  // the order until it meets the floor of this test, 1e-5 relative (the fine quadrature of the
  // discontinuous V H, ~1e-6, and float32 coefficients). Measured: 8.3e-2, 1.3e-3, 3.2e-5, 1.8e-6
  // and 3.6e-6 at orders 3, 5, 7, 9, 11.
  const SphereRule fine = sphere_rule(400, 800);
  const double tilt = pi / 6;
  const std::array<double, 3> rr = {std::sin(tilt), 0, std::cos(tilt)};
  const auto sky = [](const std::array<double, 3>& d) { return 1 + 0.5 * d[2] + 0.3 * d[0]; };
  const double s = 4;
  double truth = 0;
  std::vector<double> U(121, 0.0);
  for (size_t q = 0; q < fine.w.size(); ++q) {
    const auto& d = fine.dir[q];
    if (d[2] <= 0 || d[0] > 0.5) continue;
    const double c = d[0] * rr[0] + d[1] * rr[1] + d[2] * rr[2];
    truth += fine.w[q] * sky(d) * (s + 1) / (2 * pi) * std::pow(std::max(c, 0.0), s);
    const std::vector<double> y = eval_sh(11, d);
    for (size_t i = 0; i < 121; ++i) U[i] += fine.w[q] * y[i];
  }
  double previous = 1e9;
  for (int L : {3, 5, 7, 9, 11}) {
    const int n = L * L;
    const shade::TripleProduct tp(L);
    std::vector<float> u(n), light(3 * n, 0.0f);
    for (int i = 0; i < n; ++i) u[size_t(i)] = float(U[size_t(i)]);
    // L = √(4π) y_00 + 0.5 · √(4π/3) y_10 − 0.3 · √(4π/3) y_11 (y_11 = −c x).
    for (int c = 0; c < 3; ++c) {
      light[size_t(c * n + 0)] = float(std::sqrt(4 * pi));
      light[size_t(c * n + sh::index(1, 0))] = float(0.5 * std::sqrt(4 * pi / 3));
      light[size_t(c * n + sh::index(1, 1))] = float(-0.3 * std::sqrt(4 * pi / 3));
    }
    double scales[11];
    shade::phong_band_scales(s, L, scales);
    const float r[3] = {float(rr[0]), float(rr[1]), float(rr[2])};
    float out[3];
    shade::shade_glossy(tp, light.data(), u.data(), scales, r, out);
    const double err = std::abs(out[0] - truth) / truth;
    std::printf("order %2d: L_out %.6f, true %.6f, relative error %.2e\n", L, out[0], truth, err);
    EXPECT_LT(err, std::max(previous, 1e-5)) << "order " << L;
    previous = err;
  }
  EXPECT_LT(previous, 1e-5);
}

// ---- GGX: its band scales at normal incidence, and the zonal model off normal incidence ----

namespace {

double ggx_d(double alpha, double cos_h) {
  const double a2 = alpha * alpha, t = cos_h * cos_h * (a2 - 1) + 1;
  return a2 / (pi * t * t);
}

double legendre(int l, double t) {
  double p0 = 1, p1 = t;
  if (l == 0) return 1;
  for (int k = 2; k <= l; ++k) std::tie(p0, p1) = std::pair(p1, ((2 * k - 1) * t * p1 - (k - 1) * p0) / k);
  return p1;
}

// ∫_0^{π/2} f(θ) dθ by composite Simpson with n (even) intervals: the test's own rule.
template <class F> double simpson_half_pi(int n, F&& f) {
  const double h = pi / 2 / n;
  double s = f(0.0) + f(pi / 2);
  for (int i = 1; i < n; ++i) s += (i % 2 ? 4 : 2) * f(i * h);
  return s * h / 3;
}

} // namespace

TEST(Glossy, GgxBandScalesMatchClosedFormsAndAnIndependentIntegral) {
  constexpr int L = 16;
  for (double alpha : {1e-4, 1e-3, 1e-2, 0.05, 0.1, 0.3, 0.6, 0.9, 1.0}) {
    double lambda[L];
    shade::ggx_band_scales(alpha, L, lambda);
    EXPECT_NEAR(lambda[0], 1.0, 1e-14) << "the lobe is normalised, alpha " << alpha;
    // λ_1 = 2E[μ] − 1 with E[μ] = ∫_0^1 u/(α² + c u) du = 1/c + α² ln(α²)/c², c = 1 − α².
    if (alpha < 1) {
      const double a2 = alpha * alpha, c = 1 - a2;
      EXPECT_NEAR(lambda[1], 2 * (1 / c + a2 * std::log(a2) / (c * c)) - 1, 1e-13) << alpha;
    } else {
      // α = 1: D = 1/π, the reflected lobe is uniform over the sphere: every band above 0 vanishes.
      for (int l = 1; l < L; ++l) EXPECT_NEAR(lambda[l], 0.0, 1e-14) << l;
    }
    for (int l = 1; l < L; ++l) EXPECT_LE(std::abs(lambda[l]), 1.0 + 1e-14) << alpha << " " << l;
    if (alpha < 0.05) continue;  // the Simpson rule below resolves peaks of width ≳ 0.05 rad
    // Independently, in θ_h: λ_l = 2π ∫ D(θ_h) cos θ_h sin θ_h P_l(cos 2θ_h) dθ_h (200,000 Simpson
    // intervals; error ≲ (h/α)⁴ ≈ 1e-15 at α = 0.05).
    std::array<double, L> ref{};
    for (int l = 0; l < L; ++l)
      ref[size_t(l)] = simpson_half_pi(200000, [&](double th) {
        return 2 * pi * ggx_d(alpha, std::cos(th)) * std::cos(th) * std::sin(th) * legendre(l, std::cos(2 * th));
      });
    for (int l = 0; l < L; ++l) EXPECT_NEAR(lambda[l], ref[size_t(l)], 1e-10) << "alpha " << alpha << " l " << l;
    // The equivalent Phong exponent matches band 1 (where one exists, λ_1 ≥ ½); GGX's tail keeps
    // band 2 above Phong's, and every band for a narrow lobe.
    const double s = shade::ggx_equivalent_phong_exponent(alpha);
    double phong[L];
    shade::phong_band_scales(s, L, phong);
    if (lambda[1] < 0.5) {
      EXPECT_EQ(s, 0.0) << "wider than a clamped cosine: the widest Phong lobe, alpha " << alpha;
      EXPECT_GT(alpha, 0.4421);
      continue;
    }
    EXPECT_NEAR(phong[1], lambda[1], 1e-12) << alpha;
    EXPECT_GT(lambda[2], phong[2]) << alpha;
    if (alpha <= 0.1) {
      for (int l = 2; l < L; ++l) EXPECT_GT(lambda[l], phong[l]) << "alpha " << alpha << " l " << l;
    }
  }
  double out[2];
  EXPECT_THROW(shade::ggx_band_scales(0.0, 2, out), std::invalid_argument);
  EXPECT_THROW(shade::ggx_band_scales(1.5, 2, out), std::invalid_argument);
}

TEST(Glossy, GgxZonalModelIsExactAtNormalIncidenceAndItsErrorOffNormalIsMeasured) {
  // A band-limited lighting zonal about d: L(ω) = Σ_{l<8} g_l P_l(ω·d), g_l = (2l+1)/(4π) e^{−l(l+1)/16}
  // (a soft light), whose SH is L_lm = g_l 4π/(2l+1) y_lm(d). The zonal model shades
  // Σ_l λ_l Σ_m L_lm y_lm(r); the true value is ∫ L(ω) p_v(ω) dω = ∫ L(2(v·h)h − v) D(h)(n·h) dω_h
  // (the reflection's Jacobian cancels), integrated by Simpson in θ_h (4,000 intervals) times the
  // trapezoid rule in φ_h (64 nodes; exact for the degree-14 trigonometric polynomial in φ).
  constexpr int L = 8, n = L * L;
  std::printf("GGX zonal model against the true lobe, light centred on r (relative error):\n  alpha  view 0°     30°        60°        75°\n");
  for (double alpha : {0.1, 0.3, 0.6}) {
    double lambda[L];
    shade::ggx_band_scales(alpha, L, lambda);
    std::printf("  %.1f ", alpha);
    for (double view_deg : {0.0, 30.0, 60.0, 75.0}) {
      const double tv = view_deg * pi / 180;
      const std::array<double, 3> v = {std::sin(tv), 0, std::cos(tv)}, r = {-v[0], 0, v[2]};  // n = +z
      const std::array<double, 3>& d = r;
      auto g = [](int l) { return (2 * l + 1) / (4 * pi) * std::exp(-l * (l + 1) / 16.0); };
      auto light = [&](const std::array<double, 3>& w) {
        double sum = 0;
        for (int l = 0; l < L; ++l) sum += g(l) * legendre(l, w[0] * d[0] + w[1] * d[1] + w[2] * d[2]);
        return sum;
      };
      constexpr int kPhi = 64;
      const double truth = simpson_half_pi(4000, [&](double th) {
        double ring = 0;
        for (int b = 0; b < kPhi; ++b) {
          const double ph = 2 * pi * b / kPhi;
          const std::array<double, 3> h = {std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)};
          const double vh = v[0] * h[0] + v[1] * h[1] + v[2] * h[2];
          ring += light({2 * vh * h[0] - v[0], 2 * vh * h[1] - v[1], 2 * vh * h[2] - v[2]});
        }
        return ring * 2 * pi / kPhi * ggx_d(alpha, std::cos(th)) * std::cos(th) * std::sin(th);
      });
      // The zonal model through the library's route-B shading (float S; three equal channels).
      std::vector<float> S(3 * n);
      const std::vector<double> yd = eval_sh(L, d);
      for (int l = 0; l < L; ++l)
        for (int m = -l; m <= l; ++m)
          for (int c = 0; c < 3; ++c) S[size_t(c * n + l * (l + 1) + m)] = float(g(l) * 4 * pi / (2 * l + 1) * yd[size_t(l * (l + 1) + m)]);
      const float rf[3] = {float(r[0]), float(r[1]), float(r[2])};
      float out[3];
      shade::shade_glossy_radiance(S.data(), L, lambda, rf, out);
      const double rel = std::abs(out[0] - truth) / truth;
      std::printf(" %.3e", rel);
      if (view_deg == 0) {
        EXPECT_LT(rel, 1e-6) << "normal incidence: exact up to float S, alpha " << alpha;
      }
    }
    std::printf("\n");
  }
}
