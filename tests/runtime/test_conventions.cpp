// Engine SH conventions (prtshade/conventions.h): known lighting cases evaluated with each
// engine's OWN formula (tests/common/engine_sh.h, written out from the engines' shader code).
// Each formula returns the diffuse lighting E/π. The expected values are closed forms (no SH):
//   * a uniform sky of radiance 1 over the hemisphere around axis a: E(n)/π = (1 + n·a)/2;
//   * radiance (ω·b)²: E(n)/π = (1 + (n·b)²)/4 (Funk–Hecke: λ0 = π, λ2 = π/4);
//   * an unoccluded vertex with its own hemisphere of sky, from its band-1 radiance: E/π = 1.
// The engine-frame axes are written by hand (Unity mirrors X; Z-up files turn (x, z, −y)).
// Tolerance 1e-5: Godot's constants have 6 digits (relative 1e-6); everything else is double.
#include <prtshade/conventions.h>

#include <engine_sh.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>

namespace {

using namespace prt::conventions;
using namespace prt::testing;

constexpr double kPi = 3.14159265358979323846;
constexpr double kTol = 1e-5;

// Our basis constants (Sloan, "Stupid SH Tricks"; sh.h), written out independently.
constexpr std::array<double, 9> kK = {0.28209479177387814, -0.48860251190291992, 0.48860251190291992,
                                      -0.48860251190291992, 1.0925484305920792, -1.0925484305920792,
                                      0.31539156525252005, -1.0925484305920792, 0.54627421529603959};

double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
V3 unit(V3 v) {
  const double n = std::sqrt(dot(v, v));
  return {v[0] / n, v[1] / n, v[2] / n};
}

// A direction of the file, seen in the engine's frame (by hand, not with engine_from_file).
V3 in_engine(Engine e, UpAxis up, const V3& d) {
  V3 y_up = up == UpAxis::Z ? V3{d[0], d[2], -d[1]} : d;
  if (e == Engine::Unity) y_up[0] = -y_up[0];
  return y_up;
}

// Radiance SH (ours) of a unit sky over the hemisphere around a: L0 = 2π k0, band 1 = π k_i p_i(a),
// band 2 = 0 (the even quadratics integrate to half their zero full-sphere integral).
Sh9 hemisphere_sky(const V3& a) {
  Sh9 L{};
  const auto p = poly(a);
  L[0] = 2 * kPi * kK[0];
  for (size_t i = 1; i < 4; ++i) L[i] = kPi * kK[i] * p[i];
  return L;
}

// Radiance SH (ours) of (ω·b)²: L0 = k0 · 4π/3, band 2 = k_i · (8π/15) · bᵀQ_i b (isotropic
// fourth moments; Q_i the traceless quadratic form of p_i on the unit sphere), band 1 = 0.
Sh9 quadratic_lobe(const V3& b) {
  Sh9 L{};
  L[0] = kK[0] * 4 * kPi / 3;
  const double x = b[0], y = b[1], z = b[2];
  const double bQb[5] = {x * y, y * z, 2 * z * z - x * x - y * y, x * z, x * x - y * y};
  for (size_t i = 4; i < 9; ++i) L[i] = kK[i] * (8 * kPi / 15) * bQb[i - 4];
  return L;
}

const V3 kNormals[] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1},
                       unit({0.3, -0.5, 0.8}), unit({-0.7, 0.2, -0.1}), unit({0.1, 0.9, 0.4})};

struct Case {
  Engine engine;
  UpAxis up;
};
class EngineConvention : public ::testing::TestWithParam<Case> {};

TEST_P(EngineConvention, HemisphereSkyGivesHalfCosineFalloff) {
  const auto [engine, up] = GetParam();
  const V3 axes[] = {{0, 1, 0}, {1, 0, 0}, {0, 0, 1}, unit({1, -2, 0.5})};
  for (const V3& a : axes) {
    // Channel c holds the sky of axis a scaled by c + 1: the channels must not mix.
    RgbSh9 L{};
    for (size_t c = 0; c < 3; ++c)
      for (size_t i = 0; i < 9; ++i) L[c][i] = double(c + 1) * hemisphere_sky(a)[i];
    const EngineSh sh = to_engine(engine, up, L);
    const V3 a_e = in_engine(engine, up, a);
    for (const V3& n : kNormals)
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(evaluate(engine, sh, c, n), (c + 1) * (1 + dot(n, a_e)) / 2, kTol)
            << "axis " << a[0] << " " << a[1] << " " << a[2] << ", engine normal " << n[0] << " " << n[1] << " " << n[2];
  }
}

TEST_P(EngineConvention, QuadraticLobeExercisesBandTwo) {
  const auto [engine, up] = GetParam();
  const V3 b = unit({1, 2, 3});
  const Sh9 lobe = quadratic_lobe(b);
  const EngineSh sh = to_engine(engine, up, RgbSh9{lobe, lobe, lobe});
  const V3 b_e = in_engine(engine, up, b);
  for (const V3& n : kNormals)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(evaluate(engine, sh, c, n), (1 + dot(n, b_e) * dot(n, b_e)) / 4, kTol);
}

TEST_P(EngineConvention, BandOneVertexUnderItsOwnSkyHasIrradiancePi) {
  const auto [engine, up] = GetParam();
  for (const V3& nv : kNormals) {
    // R_{c,m} = ∫ over the vertex's hemisphere of y_1m = π k_m p_m(n), m = −1, 0, 1; red only.
    std::array<float, 9> R{};
    const auto p = poly(nv);
    for (size_t m = 0; m < 3; ++m) R[m] = float(kPi * kK[1 + m] * p[1 + m]);
    const EngineSh sh = to_engine(engine, up, radiance_from_band1(R));
    const V3 n_e = in_engine(engine, up, nv);
    EXPECT_NEAR(evaluate(engine, sh, 0, n_e), 1.0, kTol);  // E = π at the baked normal
    EXPECT_NEAR(evaluate(engine, sh, 1, n_e), 0.0, kTol);
    // The same E as SCHEMA.md's (4π/3) Σ_m y_1m(n) R_m.
    double e = 0;
    for (size_t m = 0; m < 3; ++m) e += kK[1 + m] * p[1 + m] * double(R[m]);
    EXPECT_NEAR(4 * kPi / 3 * e / kPi, 1.0, kTol);
  }
}

INSTANTIATE_TEST_SUITE_P(Engines, EngineConvention,
                         ::testing::Values(Case{Engine::Unity, UpAxis::Y}, Case{Engine::Unity, UpAxis::Z},
                                           Case{Engine::Godot, UpAxis::Y}, Case{Engine::Godot, UpAxis::Z},
                                           Case{Engine::Filament, UpAxis::Y}, Case{Engine::Filament, UpAxis::Z}),
                         [](const ::testing::TestParamInfo<Case>& p) {
                           const char* e = p.param.engine == Engine::Unity   ? "Unity"
                                           : p.param.engine == Engine::Godot ? "Godot"
                                                                             : "Filament";
                           return std::string(e) + (p.param.up == UpAxis::Y ? "_YUp" : "_ZUp");
                         });

// Ours, for reference: the same closed forms from our own convolution (irradiance_over_pi).
TEST(Conventions, OurIrradianceMatchesTheClosedForms) {
  const V3 a = unit({1, -2, 0.5}), b = unit({1, 2, 3});
  for (const V3& n : kNormals) {
    EXPECT_NEAR(irradiance_over_pi(hemisphere_sky(a), n[0], n[1], n[2]), (1 + dot(n, a)) / 2, 1e-12);
    EXPECT_NEAR(irradiance_over_pi(quadratic_lobe(b), n[0], n[1], n[2]), (1 + dot(n, b) * dot(n, b)) / 4, 1e-12);
  }
}

TEST(Conventions, UnityFrameIsAMirrorTheOthersRotations) {
  for (UpAxis up : {UpAxis::Y, UpAxis::Z})
    for (Engine e : {Engine::Unity, Engine::Godot, Engine::Filament}) {
      const Mat3 m = engine_from_file(e, up);
      const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
      EXPECT_EQ(det, e == Engine::Unity ? -1.0 : 1.0);
    }
}

} // namespace
