// runtime/shaders/shade.glsl and shade.hlsl run as Vulkan compute shaders against
// prt::shade::shade_transfer and prt::shade::shade_band1 (and against the formulas in double, built
// on prt::sh::eval): every test once per language (shade_eval.comp, shade_eval.hlsl).
#include "shader_test.h"

#include <prtshade/sh.h>
#include <prtshade/shade.h>

#include <cmath>
#include <cstdio>
#include <random>

namespace {

using prt::test::kFloatEps;
constexpr double kPi = 3.14159265358979323846;

struct Push {
  uint32_t count;
  int32_t order;
};

// Per vertex: a random transfer row and band-1 row, random unit normal; one lighting vector.
// Values span several magnitudes (×10^[-2, 2]) so the summation bound is exercised with
// cancellation, as real transfer rows have.
class ShadeMirror : public prt::test::ShaderMirror {};
PRT_SHADER_MIRROR_LANGUAGES(ShadeMirror);

TEST_P(ShadeMirror, TransferAndBand1MatchCore) {
  std::mt19937 rng(5u);
  std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
  std::uniform_real_distribution<float> expo(-2.0f, 2.0f);
  std::normal_distribution<double> g(0.0, 1.0);
  constexpr uint32_t kCount = 500;
  double worst_transfer = 0, worst_band1 = 0;
  for (int order : {1, 2, 3, 6, 8, 12}) {
    const int n = order * order;
    std::vector<float> transfer(kCount * static_cast<std::size_t>(n)), light(3 * static_cast<std::size_t>(n));
    std::vector<float> normals(4 * kCount), band1(9 * kCount);
    for (float& t : transfer) t = uni(rng) * std::pow(10.0f, expo(rng));
    for (float& l : light) l = uni(rng) * std::pow(10.0f, expo(rng));
    for (uint32_t v = 0; v < kCount; ++v) {
      double x = g(rng), y = g(rng), z = g(rng);
      const double r = std::sqrt(x * x + y * y + z * z);
      normals[4 * v] = float(x / r), normals[4 * v + 1] = float(y / r), normals[4 * v + 2] = float(z / r);
      for (int k = 0; k < 9; ++k) band1[9 * v + static_cast<std::size_t>(k)] = uni(rng) * std::pow(10.0f, expo(rng));
    }
    auto b_transfer = prt::test::to_bytes(transfer), b_light = prt::test::to_bytes(light);
    auto b_normals = prt::test::to_bytes(normals), b_band1 = prt::test::to_bytes(band1);
    std::vector<std::byte> b_out(kCount * 8 * sizeof(float));
    ASSERT_TRUE(prt::test::run_kernel(kernel("shade_eval"), {&b_transfer, &b_light, &b_normals, &b_band1, &b_out},
                                      prt::test::push_bytes(Push{kCount, order}), kCount));
    const auto out = prt::test::from_bytes<float>(b_out);
    double y1[4];
    for (uint32_t v = 0; v < kCount; ++v) {
      // Transfer: tolerance (2n + 4) ulps × Σ|T_i L_i| — the float summation bound γ_n Σ|t l|
      // for each side (GLSL may contract to fma, C++ does not), plus the products' rounding.
      const float* t = &transfer[v * static_cast<std::size_t>(n)];
      float core[3];
      prt::shade::shade_transfer(t, order, light.data(), core);
      for (int c = 0; c < 3; ++c) {
        double exact = 0, mag = 0;
        for (int i = 0; i < n; ++i) {
          const double p = double(t[i]) * light[static_cast<std::size_t>(c * n + i)];
          exact += p;
          mag += std::abs(p);
        }
        const double tol = (2.0 * n + 4.0) * kFloatEps * mag;
        const double got = out[8 * v + static_cast<std::size_t>(c)];
        worst_transfer = std::max(worst_transfer, std::abs(got - core[c]) / tol);
        ASSERT_LE(std::abs(got - core[c]), tol) << "order " << order << " vertex " << v << " channel " << c;
        ASSERT_LE(std::abs(got - exact), tol) << "order " << order << " vertex " << v << " channel " << c;
      }
      // Band 1: E_c = (4π/3) Σ_m y_1m(n) R_cm with y_1m from prt::sh::eval in double. Tolerance
      // 8 ulps × (4π/3) Σ_m |y_1m R_cm|: three products, two sums and one scale on each side.
      const float* nv = &normals[4 * v];
      const float* R = &band1[9 * v];
      float core_b[3];
      prt::shade::shade_band1(nv, R, core_b);
      prt::sh::eval(2, double(nv[0]), double(nv[1]), double(nv[2]), y1);
      for (int c = 0; c < 3; ++c) {
        double exact = 0, mag = 0;
        for (int m = 0; m < 3; ++m) {
          exact += 4.0 * kPi / 3.0 * y1[1 + m] * R[3 * c + m];
          mag += 4.0 * kPi / 3.0 * std::abs(y1[1 + m] * R[3 * c + m]);
        }
        const double tol = 8.0 * kFloatEps * mag;
        const double got = out[8 * v + 4 + static_cast<std::size_t>(c)];
        worst_band1 = std::max(worst_band1, std::abs(got - core_b[c]) / tol);
        ASSERT_LE(std::abs(got - core_b[c]), tol) << "vertex " << v << " channel " << c;
        ASSERT_LE(std::abs(got - exact), tol) << "vertex " << v << " channel " << c;
      }
    }
  }
  std::printf("%s shade vs prt::shade: worst transfer error %.3f x tol, band-1 %.3f x tol\n", language(),
              worst_transfer, worst_band1);
}

// The white furnace through the shader: an unoccluded vertex's transfer under constant radiance
// L returns L. With T_00 = y_00 · ∫_H (n·ω)/π dω = y_00 (and bands 1, 2 of the clamped cosine,
// which meet zero lighting coefficients) and L_00 = L · √(4π): Σ T L = L · y_00 · √(4π) = L, to
// a few float ulps (four roundings of at most 2^-24 each: y_00, √(4π), L·√(4π), the product).
TEST_P(ShadeMirror, WhiteFurnaceTransferReturnsRadiance) {
  const int order = 3;
  std::vector<float> transfer(9, 0.0f), light(27, 0.0f);
  transfer[0] = 0.28209479177387814f;              // y_00
  transfer[2] = 0.32573500793527993f;              // the clamped cosine's band-1 term, n = +z (ignored: L_1 = 0)
  transfer[6] = 0.15769578262626002f;              // band-2 zonal term (ignored)
  const float L[3] = {0.25f, 1.0f, 3.5f};
  for (int c = 0; c < 3; ++c) light[static_cast<std::size_t>(c * 9)] = L[c] * 3.5449077018110320f;  // √(4π)
  std::vector<float> normals = {0, 0, 1, 0}, band1(9, 0.0f);
  auto b_transfer = prt::test::to_bytes(transfer), b_light = prt::test::to_bytes(light);
  auto b_normals = prt::test::to_bytes(normals), b_band1 = prt::test::to_bytes(band1);
  std::vector<std::byte> b_out(8 * sizeof(float));
  ASSERT_TRUE(prt::test::run_kernel(kernel("shade_eval"), {&b_transfer, &b_light, &b_normals, &b_band1, &b_out},
                                    prt::test::push_bytes(Push{1, order}), 1));
  const auto out = prt::test::from_bytes<float>(b_out);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(out[static_cast<std::size_t>(c)], L[c], 5 * kFloatEps * L[c]);
}

} // namespace
