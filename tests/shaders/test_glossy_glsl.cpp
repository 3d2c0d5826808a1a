// runtime/shaders/glossy.glsl and glossy.hlsl run as Vulkan compute shaders (lavapipe on CI)
// against prt::shade::shade_glossy_vertices (route A: the lighting's product matrices times the
// visibility row) and prt::shade::shade_glossy_radiance (route B: a shadowed-radiance row), and
// against both routes' formula in double, at orders 3, 7 and 11 and Phong exponents 0 … 128:
// every test once per language (glossy_eval.comp, glossy_eval.hlsl), the same tolerances.
//
// Tolerance per vertex and channel c (ε = 2^-24, n = order², λ_l the band scales, y_k = y_lm(r),
// Y_l = √((2l+1)/(4π)) ≥ |y_lm| on the sphere, S_k the shadowed radiance, A_k = Σ_j |M[j][k] U_j|):
//   2 (n + 2) ε Σ_k |λ_l| ŷ_k A_k        route A's float sums S_k = Σ_j M[j][k] U_j on each side
//                                        (γ_n of n products and partial sums, plus the products);
//   Σ_k |λ_l S_k| (16 (l + 1) + 1) ε Y_l  y_k: sh.inc's bound (test_sh_glsl.cpp) plus the core's
//                                        float rounding of its double evaluation;
//   Σ_k (8 + 5 l) ε |λ_l| ŷ_k |S_k|      λ_l by the float recurrence in the shader (⌊l/2⌋ steps of
//                                        one multiplication, one division of 2.5 ulp and three
//                                        additions, from 1/(s+1) or 1/(s+2); the core's is double);
//   (n + 2) ε Σ_k |λ_l| ŷ_k |S_k|        the final float sum of n terms (the core's is double);
//   2 max |F(r ± δ) − F(r)|              the reflection direction's rounding: both compute
//                                        r = normalize(2(n·v)n − v), v = normalize(eye − p), the
//                                        shader with Vulkan's 2.5-ulp division and sqrt from
//                                        inversesqrt; |Δr| ≤ δ = 128 ε per component (asserted),
//                                        turned into a value bound by F, the double formula, at
//                                        the 8 corners of the box r ± δ (linear at that scale;
//                                        the factor 2 covers the curvature),
// with ŷ_k = |y_k| + (16 (l + 1) + 1) ε Y_l. Both the core and the double formula F(r) at the
// core's r must lie within it.
#include "shader_test.h"

#include <prtshade/glossy.h>
#include <prtshade/sh.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <random>

namespace {

using prt::test::kFloatEps;
constexpr double kPi = 3.14159265358979323846;
constexpr double kDirectionTolerance = 128 * kFloatEps;  // |Δr| per component, see the file comment

struct Push {
  uint32_t count;
  int32_t order;
  float exponent;
  float unused;
  float eye[4];
};
static_assert(sizeof(Push) == 32, "the kernels' push constants are 32 bytes");

class GlossyMirror : public prt::test::ShaderMirror {};

// The band l of flat SH index k = l(l+1) + m.
int band_of(std::size_t k) { return int(std::sqrt(double(k))); }
PRT_SHADER_MIRROR_LANGUAGES(GlossyMirror);

// What the kernel returns per vertex: route A, route B, r.
struct Result {
  std::array<float, 3> route_a, route_b, r;
};

struct Scene {
  int order = 0;
  std::vector<float> light, visibility, shadowed, normals, positions;  // normals/positions: vec4 each
  float eye[3] = {0.3f, -0.4f, 4.0f};
};

// The kernel over `scene` with exponent s; false (after a recorded failure) when Vulkan fails.
bool run_glossy(const std::string& kernel, const Scene& scene, const prt::shade::GlossyLight& light, double s,
                std::vector<Result>& out) {
  const auto count = static_cast<uint32_t>(scene.normals.size() / 4);
  auto b_matrices = prt::test::to_bytes(light.matrices()), b_visibility = prt::test::to_bytes(scene.visibility);
  auto b_shadowed = prt::test::to_bytes(scene.shadowed), b_normals = prt::test::to_bytes(scene.normals);
  auto b_positions = prt::test::to_bytes(scene.positions);
  std::vector<std::byte> b_out(count * 12 * sizeof(float));
  const Push push{count, scene.order, float(s), 0.0f, {scene.eye[0], scene.eye[1], scene.eye[2], 0.0f}};
  if (!prt::test::run_kernel(kernel, {&b_matrices, &b_visibility, &b_shadowed, &b_normals, &b_positions, &b_out},
                             prt::test::push_bytes(push), count))
    return false;
  const auto f = prt::test::from_bytes<float>(b_out);
  out.resize(count);
  for (std::size_t v = 0; v < count; ++v)
    for (std::size_t c = 0; c < 3; ++c) {
      out[v].route_a[c] = f[12 * v + c];
      out[v].route_b[c] = f[12 * v + 4 + c];
      out[v].r[c] = f[12 * v + 8 + c];
    }
  return true;
}

// Random SH rows whose bands decay like a smooth environment's (×1/(1 + l)), of both signs.
void random_sh(std::mt19937& rng, int order, std::size_t rows, std::vector<float>& out) {
  std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
  const int n = order * order;
  out.resize(rows * static_cast<std::size_t>(n));
  for (std::size_t r = 0; r < rows; ++r)
    for (int i = 0; i < n; ++i)
      out[r * static_cast<std::size_t>(n) + static_cast<std::size_t>(i)] =
          uni(rng) / (1.0f + std::floor(std::sqrt(float(i))));
}

// Random unit normals and positions around the origin; the last vertex sits on the eye (r = n).
Scene make_scene(int order, uint32_t count, uint32_t seed) {
  std::mt19937 rng(seed);
  Scene sc;
  sc.order = order;
  random_sh(rng, order, 3, sc.light);
  random_sh(rng, order, count, sc.visibility);
  random_sh(rng, order, 3 * static_cast<std::size_t>(count), sc.shadowed);
  std::normal_distribution<double> g(0.0, 1.0);
  for (uint32_t v = 0; v < count; ++v) {
    double n[3] = {g(rng), g(rng), g(rng)};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    sc.normals.insert(sc.normals.end(), {float(n[0] / len), float(n[1] / len), float(n[2] / len), 0.0f});
    if (v + 1 == count) sc.positions.insert(sc.positions.end(), {sc.eye[0], sc.eye[1], sc.eye[2], 0.0f});
    else sc.positions.insert(sc.positions.end(), {float(g(rng)), float(g(rng)), float(g(rng)), 0.0f});
  }
  return sc;
}

// r as the core forms it: v = normalize(eye − p) (0 on the eye), normalize(reflect(n, v)), n if 0.
std::array<float, 3> core_reflection(const float* n, const float* p, const float eye[3]) {
  float v[3] = {eye[0] - p[0], eye[1] - p[1], eye[2] - p[2]};
  const float lv = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  for (float& c : v) c = lv > 0 ? c / lv : 0.0f;
  float r[3];
  prt::shade::reflect(n, v, r);
  const float lr = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
  if (!(lr > 0)) return {n[0], n[1], n[2]};
  return {r[0] / lr, r[1] / lr, r[2] / lr};
}

// F(r) = Σ_l λ_l Σ_m S_{c,lm} y_lm(r) in double; S [3][n].
std::array<double, 3> glossy_formula(int order, const std::vector<double>& lambda, const std::vector<double>& S,
                                     const double r[3]) {
  const auto n = static_cast<std::size_t>(order * order);
  std::vector<double> y(n);
  prt::sh::eval(order, r[0], r[1], r[2], y);
  std::array<double, 3> out{};
  for (std::size_t c = 0; c < 3; ++c)
    for (std::size_t k = 0; k < n; ++k) out[c] += lambda[static_cast<std::size_t>(band_of(k))] * S[c * n + k] * y[k];
  return out;
}

// The tolerance of the file comment for one vertex; `sums` = A_k per channel ([3][n]) for route
// A, empty for route B. Returns F(r_core) in `formula`.
std::array<double, 3> glossy_tolerance(int order, const std::vector<double>& lambda, const std::vector<double>& S,
                                       const std::vector<double>& sums, const std::array<float, 3>& r_core,
                                       std::array<double, 3>& formula) {
  const auto n = static_cast<std::size_t>(order * order);
  const double r[3] = {r_core[0], r_core[1], r_core[2]};
  std::vector<double> y(n);
  prt::sh::eval(order, r[0], r[1], r[2], y);
  formula = glossy_formula(order, lambda, S, r);
  std::array<double, 3> tol{};
  for (std::size_t c = 0; c < 3; ++c)
    for (std::size_t k = 0; k < n; ++k) {
      const int l = band_of(k);
      const double lam = std::abs(lambda[static_cast<std::size_t>(l)]);
      const double y_bound = std::sqrt((2.0 * l + 1.0) / (4.0 * kPi));
      const double dy = (16.0 * (l + 1) + 1.0) * kFloatEps * y_bound;
      const double yhat = std::abs(y[k]) + dy;
      const double s = std::abs(S[c * n + k]);
      if (!sums.empty()) tol[c] += 2.0 * (double(n) + 2.0) * kFloatEps * lam * yhat * sums[c * n + k];
      tol[c] += lam * s * dy + (8.0 + 5.0 * l) * kFloatEps * lam * yhat * s +
                (double(n) + 2.0) * kFloatEps * lam * yhat * s;
    }
  std::array<double, 3> sensitivity{};
  for (int corner = 0; corner < 8; ++corner) {
    const double rc[3] = {r[0] + (corner & 1 ? kDirectionTolerance : -kDirectionTolerance),
                          r[1] + (corner & 2 ? kDirectionTolerance : -kDirectionTolerance),
                          r[2] + (corner & 4 ? kDirectionTolerance : -kDirectionTolerance)};
    const auto f = glossy_formula(order, lambda, S, rc);
    for (std::size_t c = 0; c < 3; ++c) sensitivity[c] = std::max(sensitivity[c], std::abs(f[c] - formula[c]));
  }
  for (std::size_t c = 0; c < 3; ++c) tol[c] += 2.0 * sensitivity[c];
  return tol;
}

// One route's shader result against the core's and the double formula's within `tol`.
void check_route(const char* route, const std::array<float, 3>& got, const float* core,
                 const std::array<double, 3>& formula, const std::array<double, 3>& tol, double& worst) {
  for (std::size_t c = 0; c < 3; ++c) {
    const double g = got[c];
    worst = std::max(worst, std::abs(g - core[c]) / tol[c]);
    ASSERT_LE(std::abs(g - core[c]), tol[c]) << "route " << route << " vs core, channel " << c;
    ASSERT_LE(std::abs(g - formula[c]), tol[c]) << "route " << route << " vs formula, channel " << c;
  }
}

// Both routes at orders 3, 7, 11 for Phong exponents 0 (λ_0 only is 1; the lobe is the
// hemisphere), 4, 24, 128 (the issue's) and 7.25 (a recurrence that never hits zero), against the
// core and the double formula (the tolerance of the file comment).
TEST_P(GlossyMirror, RoutesMatchCore) {
  constexpr uint32_t kCount = 96;
  double worst_a = 0, worst_b = 0, worst_r = 0;
  for (int order : {3, 7, 11}) {
    SCOPED_TRACE(testing::Message() << "order " << order);
    const Scene sc = make_scene(order, kCount, 900u + uint32_t(order));
    const prt::shade::TripleProduct tp(order);
    const prt::shade::GlossyLight light(tp, sc.light.data());
    const auto n = static_cast<std::size_t>(order * order);
    std::vector<float> normals3, positions3;
    for (uint32_t v = 0; v < kCount; ++v)
      for (std::size_t a = 0; a < 3; ++a) {
        normals3.push_back(sc.normals[4 * v + a]);
        positions3.push_back(sc.positions[4 * v + a]);
      }
    for (double s : {0.0, 4.0, 24.0, 128.0, 7.25}) {
      SCOPED_TRACE(testing::Message() << "Phong exponent " << s);
      std::vector<Result> got;
      ASSERT_TRUE(run_glossy(kernel("glossy_eval"), sc, light, s, got));
      std::vector<float> core_a(3 * kCount);
      prt::shade::shade_glossy_vertices(light, sc.visibility.data(), normals3.data(), positions3.data(), kCount, sc.eye,
                                        s, core_a.data());
      std::vector<double> lambda(static_cast<std::size_t>(order));
      prt::shade::phong_band_scales(s, order, lambda.data());
      const std::vector<float>& m = light.matrices();
      for (uint32_t v = 0; v < kCount; ++v) {
        SCOPED_TRACE(testing::Message() << "vertex " << v);
        const std::array<float, 3> r = core_reflection(&normals3[3 * v], &positions3[3 * v], sc.eye);
        for (std::size_t a = 0; a < 3; ++a) {
          worst_r = std::max(worst_r, std::abs(double(got[v].r[a]) - r[a]) / kDirectionTolerance);
          ASSERT_LE(std::abs(double(got[v].r[a]) - r[a]), kDirectionTolerance) << "r component " << a;
        }
        // Route A: S = M U in double from the float M and U, and A_k = Σ_j |M[j][k] U_j|.
        const float* u = &sc.visibility[v * n];
        std::vector<double> S(3 * n, 0.0), sums(3 * n, 0.0);
        for (std::size_t c = 0; c < 3; ++c)
          for (std::size_t j = 0; j < n; ++j)
            for (std::size_t k = 0; k < n; ++k) {
              const double p = double(m[(c * n + j) * n + k]) * u[j];
              S[c * n + k] += p;
              sums[c * n + k] += std::abs(p);
            }
        std::array<double, 3> formula{};
        auto tol = glossy_tolerance(order, lambda, S, sums, r, formula);
        check_route("A", got[v].route_a, &core_a[3 * v], formula, tol, worst_a);
        if (HasFatalFailure()) return;
        // Route B on the vertex's shadowed-radiance row.
        const float* row = &sc.shadowed[3 * n * v];
        std::vector<double> Sb(row, row + 3 * n);
        tol = glossy_tolerance(order, lambda, Sb, {}, r, formula);
        float core_b[3];
        prt::shade::shade_glossy_radiance(row, order, lambda.data(), r.data(), core_b);
        check_route("B", got[v].route_b, core_b, formula, tol, worst_b);
        if (HasFatalFailure()) return;
      }
    }
  }
  std::printf("%s glossy vs prt::shade, orders 3/7/11: worst route A %.3f x tol, route B %.3f x tol, "
              "r %.3f x %.0f eps\n",
              language(), worst_a, worst_b, worst_r, kDirectionTolerance / kFloatEps);
}

// The lobe is normalised (glossy.h: ∫ k_s dω = 1): under a white unoccluded sky of radiance 1
// (L_00 = √(4π), U_00 = √(4π): V H = 1 everywhere, so S = P_L(1) = √(4π) y_00-only) both routes
// return 1 for every exponent and direction, to float rounding: about 15 roundings of at most ε
// each (the two inputs, M_000, the product, λ_0's division and multiplication, y_00, the weight
// and the sum), so 32 ε.
TEST_P(GlossyMirror, WhiteSkyReturnsOne) {
  const int order = 7;
  const auto n = static_cast<std::size_t>(order * order);
  Scene sc = make_scene(order, 64, 77u);
  const float sqrt_4pi = 3.5449077018110320f;
  std::fill(sc.light.begin(), sc.light.end(), 0.0f);
  std::fill(sc.visibility.begin(), sc.visibility.end(), 0.0f);
  std::fill(sc.shadowed.begin(), sc.shadowed.end(), 0.0f);
  for (std::size_t c = 0; c < 3; ++c) sc.light[c * n] = sqrt_4pi;
  for (std::size_t v = 0; v < 64; ++v) {
    sc.visibility[v * n] = sqrt_4pi;
    for (std::size_t c = 0; c < 3; ++c) sc.shadowed[(3 * v + c) * n] = sqrt_4pi;
  }
  const prt::shade::TripleProduct tp(order);
  const prt::shade::GlossyLight light(tp, sc.light.data());
  for (double s : {0.0, 4.0, 24.0, 128.0}) {
    std::vector<Result> got;
    ASSERT_TRUE(run_glossy(kernel("glossy_eval"), sc, light, s, got));
    for (std::size_t v = 0; v < 64; ++v)
      for (std::size_t c = 0; c < 3; ++c) {
        EXPECT_NEAR(got[v].route_a[c], 1.0, 32 * kFloatEps) << "s " << s << " vertex " << v;
        EXPECT_NEAR(got[v].route_b[c], 1.0, 32 * kFloatEps) << "s " << s << " vertex " << v;
      }
  }
}

} // namespace
