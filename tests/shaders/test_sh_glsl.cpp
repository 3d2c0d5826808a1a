// runtime/shaders/sh.glsl and sh.hlsl run as Vulkan compute shaders (lavapipe on CI) against
// prt::sh::eval: every test once per language (sh_eval.comp, sh_eval.hlsl), the same tolerances.
#include "shader_test.h"

#include <prtshade/sh.h>

#include <cmath>
#include <cstdio>
#include <random>

namespace {

using prt::test::kFloatEps;

constexpr int kOrders = 16;  // PRT_SH_MAX_ORDER of the sh_eval kernels: the limit sh.inc allows
constexpr int kCoeffs = kOrders * kOrders;
constexpr double kPi = 3.14159265358979323846;

// The device the shader tests run on; fails (not skips) when there is none.
TEST(ShaderDevice, EnumeratesAComputeDevice) {
  try {
    auto& vk = prt::test::vk_compute();
    for (const auto& d : vk.all_devices()) std::printf("Vulkan device: %s\n", d.c_str());
    std::printf("shader tests run on: %s\n", vk.device_description().c_str());
    EXPECT_GE(vk.all_devices().size(), 1u);
    EXPECT_FALSE(vk.device_description().empty());
  } catch (const std::exception& e) {
    FAIL() << e.what();
  }
}

struct Dir {
  float x, y, z;
};

// Random unit directions (rounded to float) plus the axes, both poles and seam directions.
std::vector<Dir> test_directions(int random_count, uint32_t seed) {
  std::vector<Dir> dirs = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}};
  const float h = static_cast<float>(std::sqrt(0.5));
  for (Dir d : {Dir{h, 0, h}, Dir{0, -h, h}, Dir{-h, h, 0}, Dir{1e-4f, 0, 1}, Dir{0, -1e-4f, -1}}) {
    const double n = std::sqrt(double(d.x) * d.x + double(d.y) * d.y + double(d.z) * d.z);
    dirs.push_back({float(d.x / n), float(d.y / n), float(d.z / n)});
  }
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  for (int i = 0; i < random_count; ++i) {
    double x = g(rng), y = g(rng), z = g(rng);
    const double n = std::sqrt(x * x + y * y + z * z);
    dirs.push_back({float(x / n), float(y / n), float(z / n)});
  }
  return dirs;
}

// Every order 1 … 16 at 600+ directions: the float recurrence on the device against the
// double recurrence of the C++ core, evaluated on the same float direction (so both evaluate
// the same polynomial of (x, y, z), unit or not).
// Tolerance per band l: 16 ulps × (l + 1) × sqrt((2l+1)/(4π)). Reason: sqrt((2l+1)/(4π)) bounds
// |y_lm| on the sphere (addition theorem: Σ_m y_lm² = (2l+1)/(4π)); the float recurrence reaches
// band l in l steps, each a handful of operations of ≤ 2.5 ulps each under Vulkan's precision
// rules (division 2.5 ulp, sqrt as 1/inversesqrt) on coefficients of size O(1), so the error
// grows at most linearly in l with a per-step constant well under 16 ulps.
class ShMirror : public prt::test::ShaderMirror {};
PRT_SHADER_MIRROR_LANGUAGES(ShMirror);

TEST_P(ShMirror, EvalMatchesCoreAllOrders) {
  const std::vector<Dir> dirs = test_directions(600, 20261123u);
  const auto per_order = static_cast<uint32_t>(dirs.size());
  const uint32_t count = per_order * kOrders;
  std::vector<float> in(4 * static_cast<std::size_t>(count));
  for (int order = 1; order <= kOrders; ++order)
    for (uint32_t i = 0; i < per_order; ++i) {
      const std::size_t k = static_cast<std::size_t>(order - 1) * per_order + i;
      in[4 * k + 0] = dirs[i].x;
      in[4 * k + 1] = dirs[i].y;
      in[4 * k + 2] = dirs[i].z;
      in[4 * k + 3] = static_cast<float>(order);
    }
  auto in_bytes = prt::test::to_bytes(in);
  std::vector<std::byte> out_bytes(static_cast<std::size_t>(count) * kCoeffs * sizeof(float));
  ASSERT_TRUE(prt::test::run_kernel(kernel("sh_eval"), {&in_bytes, &out_bytes}, prt::test::push_bytes(count), count));
  const auto out = prt::test::from_bytes<float>(out_bytes);

  double worst_ratio = 0;  // max |error| / tolerance over everything checked
  std::vector<double> ref(kCoeffs);
  for (int order = 1; order <= kOrders; ++order)
    for (uint32_t i = 0; i < per_order; ++i) {
      const std::size_t k = static_cast<std::size_t>(order - 1) * per_order + i;
      prt::sh::eval(order, double(dirs[i].x), double(dirs[i].y), double(dirs[i].z), ref);
      const float* got = &out[k * kCoeffs];
      for (int l = 0; l < order; ++l) {
        const double tol = 16.0 * (l + 1) * kFloatEps * std::sqrt((2.0 * l + 1.0) / (4.0 * kPi));
        for (int m = -l; m <= l; ++m) {
          const int c = prt::sh::index(l, m);
          const double err = std::abs(double(got[c]) - ref[static_cast<std::size_t>(c)]);
          worst_ratio = std::max(worst_ratio, err / tol);
          ASSERT_LE(err, tol) << "order " << order << " l " << l << " m " << m << " dir (" << dirs[i].x << ", "
                              << dirs[i].y << ", " << dirs[i].z << ")";
        }
      }
      // Entries beyond order² are left untouched (the kernel filled them with −12345).
      for (int c = order * order; c < kCoeffs; ++c) ASSERT_EQ(got[c], -12345.0f) << "order " << order << " wrote " << c;
    }
  std::printf("%s sh vs prt::sh::eval, orders 1..%d, %u directions: worst |error| = %.3f x tolerance\n", language(),
              kOrders, per_order, worst_ratio);
}

// Condon–Shortley signs and normalisation spelled out (sh.h bands 0–2 at 6 digits, DirectXMath):
// a sign error in the shader would flip these whole values, far beyond the 1e-6 of the constants.
TEST_P(ShMirror, BandsZeroToTwoClosedForm) {
  const std::vector<Dir> dirs = test_directions(64, 7u);
  const auto count = static_cast<uint32_t>(dirs.size());
  std::vector<float> in;
  for (const Dir& d : dirs) in.insert(in.end(), {d.x, d.y, d.z, 3.0f});
  auto in_bytes = prt::test::to_bytes(in);
  std::vector<std::byte> out_bytes(static_cast<std::size_t>(count) * kCoeffs * sizeof(float));
  ASSERT_TRUE(prt::test::run_kernel(kernel("sh_eval"), {&in_bytes, &out_bytes}, prt::test::push_bytes(count), count));
  const auto out = prt::test::from_bytes<float>(out_bytes);
  for (uint32_t i = 0; i < count; ++i) {
    const double x = dirs[i].x, y = dirs[i].y, z = dirs[i].z;
    const double expect[9] = {0.282095,          -0.488603 * y,       0.488603 * z,
                              -0.488603 * x,     1.092548 * x * y,    -1.092548 * y * z,
                              0.315392 * (3 * z * z - 1), -1.092548 * x * z, 0.546274 * (x * x - y * y)};
    for (int c = 0; c < 9; ++c)  // constants are rounded to 6 digits: |Δ| <= 5e-7 × (|poly| <= 2)
      EXPECT_NEAR(out[i * kCoeffs + static_cast<std::size_t>(c)], expect[c], 2e-6) << "coefficient " << c;
  }
}

} // namespace
