// Tests of prtshade/shade.h: lat-long SH projection (closed forms, OpenEXR direction convention,
// a slow independent reference, pixel policy), transfer · light (white furnace, rotation of the
// lighting vs rotation of the transfer, double reference) and band-1 shading (directional light
// and uniform sky closed forms).
#include <prtshade/sh.h>
#include <prtshade/shade.h>

#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

namespace sh = prt::sh;
namespace shade = prt::shade;

constexpr double kPi = 3.14159265358979323846264338327950288;
// One float rounding of an output (the projection is accumulated in double and rounded once):
// relative 2^-24, with a factor 2 for the rounding of the reference's own float inputs.
constexpr double kFloatRel = 2.0 * FLT_EPSILON / 2;

std::vector<float> constant_image(int w, int h, float r, float g, float b) {
  std::vector<float> img(size_t(w) * size_t(h) * 3);
  for (size_t k = 0; k < img.size(); k += 3) img[k] = r, img[k + 1] = g, img[k + 2] = b;
  return img;
}

// Independent slow reference for project_latlong: OpenEXR's formulas written out per texel,
// the solid angle as the plain difference sin(lat_top) − sin(lat_bottom), and the basis from
// the explicit-formula sh::eval_slow.
std::vector<double> project_reference(const std::vector<float>& img, int w, int h, int order) {
  const int n = order * order;
  std::vector<double> out(size_t(3 * n), 0.0);
  for (int py = 0; py < h; ++py)
    for (int px = 0; px < w; ++px) {
      const double lat = kPi / 2 - kPi * py / (h - 1), lon = kPi - 2 * kPi * px / (w - 1);
      const double y_top = std::min(py + 0.5, double(h - 1)), y_bot = std::max(py - 0.5, 0.0);
      const double x_hi = std::min(px + 0.5, double(w - 1)), x_lo = std::max(px - 0.5, 0.0);
      const double omega = (2 * kPi * (x_hi - x_lo) / (w - 1)) *
                           (std::sin(kPi / 2 - kPi * y_bot / (h - 1)) - std::sin(kPi / 2 - kPi * y_top / (h - 1)));
      const double d[3] = {std::sin(lon) * std::cos(lat), std::sin(lat), std::cos(lon) * std::cos(lat)};
      for (int l = 0; l < order; ++l)
        for (int m = -l; m <= l; ++m) {
          const double y = sh::eval_slow(l, m, d[0], d[1], d[2]);
          for (int c = 0; c < 3; ++c)
            out[size_t(c * n + sh::index(l, m))] +=
                std::max(0.0, double(img[(size_t(py) * size_t(w) + size_t(px)) * 3 + size_t(c)])) * omega * y;
        }
    }
  return out;
}

// True when y_i is odd under the reflection of some axis (x, y or z): its integral over any grid
// with the same mirror symmetries vanishes.
bool odd_in_some_axis(int i, int order) {
  std::vector<double> a(size_t(order * order)), b(a.size());
  const double d[3] = {0.36, 0.48, 0.8};  // unit, no symmetry of its own
  sh::eval(order, d[0], d[1], d[2], a);
  for (int axis = 0; axis < 3; ++axis) {
    double r[3] = {d[0], d[1], d[2]};
    r[axis] = -r[axis];
    sh::eval(order, r[0], r[1], r[2], b);
    if (std::abs(a[size_t(i)] + b[size_t(i)]) < 1e-12 && std::abs(a[size_t(i)]) > 1e-6) return true;
  }
  return false;
}

TEST(ProjectLatlong, ConstantEnvironmentGivesOnlyY00) {
  // W − 1 and H − 1 even: the texel centres are mirror-symmetric in x (lon → −lon), z (lon → π −
  // lon) and y (row mirror), as are the solid angles.
  const int order = 4, n = order * order;
  const float L[3] = {1.0f, 2.5f, 0.125f};
  std::vector<float> coarse(size_t(3 * n)), fine(size_t(3 * n));
  shade::project_latlong(constant_image(65, 33, L[0], L[1], L[2]).data(), 65, 33, order, coarse.data());
  shade::project_latlong(constant_image(129, 65, L[0], L[1], L[2]).data(), 129, 65, order, fine.data());
  int even_terms = 0;
  for (int c = 0; c < 3; ++c) {
    // ∫ L y00 dω = L · 4π/(2√π) = L √(4π): the texel solid angles sum to 4π (to ~1e-15), so only
    // the final float rounding remains.
    const double y00 = double(L[c]) * std::sqrt(4 * kPi);
    EXPECT_NEAR(coarse[size_t(c * n)], y00, kFloatRel * y00) << "channel " << c;
    for (int i = 1; i < n; ++i) {
      const double a = coarse[size_t(c * n + i)], b = fine[size_t(c * n + i)];
      if (odd_in_some_axis(i, order)) {
        // Cancels exactly by symmetry: what is left is double rounding of ~2000 terms of size
        // <= L·0.1, far below this float-level bar.
        EXPECT_NEAR(a, 0.0, 1e-6 * y00) << "i " << i;
      } else {
        // Even in x, y and z (e.g. y20, y22): the one-point rule per texel (the rule of
        // bake::EnvMap::project_sh) has an O(h²) error, so halving h divides it by 4; the next
        // term is O(h⁴), ~h² ≈ 1% of the first at these sizes, hence ±0.2.
        ++even_terms;
        EXPECT_LT(std::abs(a), 0.01 * y00) << "i " << i;
        EXPECT_NEAR(a / b, 4.0, 0.2) << "i " << i << ": " << a << " vs " << b;
      }
    }
  }
  EXPECT_EQ(even_terms, 3 * 2);  // per channel y20 and y22; bands 1 and 3 are odd polynomials
}

TEST(ProjectLatlong, MatchesSlowReferenceOnRandomImage) {
  const int w = 40, h = 21, order = 5, n = order * order;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-0.2f, 3.0f);  // some negative pixels: clamped
  std::vector<float> img(size_t(w * h * 3));
  for (float& v : img) v = u(rng);
  std::vector<float> out(size_t(3 * n));
  shade::project_latlong(img.data(), w, h, order, out.data());
  const std::vector<double> ref = project_reference(img, w, h, order);
  double scale = 0;  // Σ_t |L| Ω |y| ≤ max L · 4π · max |y| (max |y| < 1.2 for l < 5)
  for (float v : img) scale = std::max(scale, double(v));
  scale *= 4 * kPi * 1.2;
  for (int k = 0; k < 3 * n; ++k)
    // Float rounding of the result, plus the reference's plain sin difference near the poles
    // (loses ~1e-13 relative on the polar texels) and eval_slow's ~1e-14: 1e-12 · scale.
    EXPECT_NEAR(out[size_t(k)], ref[size_t(k)], kFloatRel * std::abs(ref[size_t(k)]) + 1e-12 * scale) << k;
}

TEST(ProjectLatlong, BrightTexelSitsWhereOpenExrSaysItDoes) {
  // W − 1 = 64 and H − 1 = 32: pixel (16, 16) has longitude π − 2π·16/64 = π/2 and latitude 0, so
  // its direction is +X; pixel (32, 0) is the north pole +Y; pixel (0, 16) is on the seam, −Z.
  const int w = 65, h = 33;
  struct Case {
    int px, py;
    double d[3];
  } cases[] = {{16, 16, {1, 0, 0}}, {48, 16, {-1, 0, 0}}, {32, 0, {0, 1, 0}}, {0, 16, {0, 0, -1}}, {32, 16, {0, 0, 1}}};
  for (const Case& cs : cases) {
    std::vector<float> img(size_t(w * h * 3), 0.0f);
    img[(size_t(cs.py) * w + size_t(cs.px)) * 3 + 1] = 1.0f;
    float out[3 * 4];
    shade::project_latlong(img.data(), w, h, 2, out);
    // Green channel, band 1: L_1m = Ω y_1m(d) = Ω √(3/4π) (−d_y, d_z, −d_x).
    const float* g = out + 4;
    const double norm = std::sqrt(double(g[1]) * g[1] + double(g[2]) * g[2] + double(g[3]) * g[3]);
    ASSERT_GT(norm, 0);
    const double d[3] = {-g[3] / norm, -g[1] / norm, g[2] / norm};
    for (int a = 0; a < 3; ++a)
      // Directions from sin/cos of exact multiples of π/2 in double (≤ 1e-16 off-axis), then
      // float rounding of the coefficients.
      EXPECT_NEAR(d[a], cs.d[a], 1e-7) << "pixel (" << cs.px << ", " << cs.py << ") axis " << a;
    // Band 0 carries Ω / (2√π) > 0 and nothing else is lit.
    EXPECT_GT(g[0], 0);
    EXPECT_EQ(out[0], 0.0f);
    EXPECT_EQ(out[8], 0.0f);
  }
}

TEST(ProjectLatlong, NegativePixelsAreClampedToZero) {
  const int w = 16, h = 9;
  std::vector<float> a = constant_image(w, h, 1, 2, 3), b = a;
  a[5] = -0.5f;
  a[100] = -1e-3f;
  b[5] = 0;
  b[100] = 0;
  std::vector<float> oa(27), ob(27);
  shade::project_latlong(a.data(), w, h, 3, oa.data());
  shade::project_latlong(b.data(), w, h, 3, ob.data());
  for (int k = 0; k < 27; ++k) EXPECT_EQ(oa[size_t(k)], ob[size_t(k)]) << k;  // the same sums, bit for bit
}

TEST(ProjectLatlong, BadInputThrowsNamingTheProblem) {
  std::vector<float> img = constant_image(8, 4, 1, 1, 1);
  std::vector<float> out(27);
  img[(2 * 8 + 5) * 3 + 2] = std::numeric_limits<float>::quiet_NaN();
  try {
    shade::project_latlong(img.data(), 8, 4, 3, out.data());
    FAIL() << "NaN pixel accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("(x 5, y 2) channel B"), std::string::npos) << e.what();
  }
  img[(2 * 8 + 5) * 3 + 2] = 1;
  EXPECT_THROW(shade::project_latlong(img.data(), 1, 32, 3, out.data()), std::invalid_argument);
  EXPECT_THROW(shade::project_latlong(img.data(), 8, 4, 0, out.data()), std::invalid_argument);
  EXPECT_THROW(shade::project_latlong(img.data(), 8, 4, 65, out.data()), std::invalid_argument);
  EXPECT_THROW(shade::project_latlong(nullptr, 8, 4, 3, out.data()), std::invalid_argument);
  EXPECT_THROW(shade::project_latlong(img.data(), 8, 4, 3, nullptr), std::invalid_argument);
}

// Unoccluded clamped-cosine transfer for n = +z (docs/ARCHITECTURE.md §3, T has the 1/π):
// T_0 = 1/(2√π), T_2 = √3/(3√π), T_6 = √5/(8√π), every other coefficient 0.
std::vector<float> unoccluded_transfer_z(int order) {
  const double rpi = std::sqrt(kPi);
  std::vector<float> t(size_t(order * order), 0.0f);
  t.at(0) = float(1 / (2 * rpi));
  if (order > 1) t.at(2) = float(std::sqrt(3.0) / (3 * rpi));
  if (order > 2) t.at(6) = float(std::sqrt(5.0) / (8 * rpi));
  return t;
}

TEST(ShadeTransfer, WhiteFurnaceReturnsTheRadiance) {
  // Constant L: light = L √(4π) in y00 only, so Σ T_i L_i = L √(4π)/(2√π) = L for an unoccluded
  // vertex (albedo · L out): three float roundings (T_0, the light and the product).
  for (int order : {1, 3, 6}) {
    const int n = order * order;
    const float L[3] = {0.7f, 1.0f, 5.0f};
    std::vector<float> light(size_t(3 * n), 0.0f);  // the exact projection of a constant L
    for (int c = 0; c < 3; ++c) light[size_t(c * n)] = float(L[c] * std::sqrt(4 * kPi));
    float out[3];
    shade::shade_transfer(unoccluded_transfer_z(order).data(), order, light.data(), out);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(out[c], L[c], 4 * FLT_EPSILON * L[c]) << "order " << order << " c " << c;
  }
}

TEST(ShadeTransfer, RotatingTheLightingEqualsRotatingTheTransfer) {
  // A vertex with normal n = R z has the rotated transfer T_n = D(R) T_z; shading it with L must
  // equal shading T_z with the lighting rotated back, D(Rᵀ) L (orthogonal D, so Σ (D T)·L = Σ T·(Dᵀ L)).
  const int order = 6, n = order * order;
  const double a = 0.7, b = -1.1;
  const double R[3][3] = {{std::cos(a), -std::sin(a) * std::cos(b), std::sin(a) * std::sin(b)},
                          {std::sin(a), std::cos(a) * std::cos(b), -std::cos(a) * std::sin(b)},
                          {0, std::sin(b), std::cos(b)}};
  double Rt[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) Rt[i][j] = R[j][i];
  std::mt19937 rng(3);
  std::normal_distribution<float> g;
  std::vector<float> light(size_t(3 * n)), light_back(size_t(3 * n)), tn(static_cast<size_t>(n));
  for (float& v : light) v = g(rng);
  const sh::Rotation to_n(R, order), back(Rt, order);
  const std::vector<float> tz = unoccluded_transfer_z(order);
  to_n.apply(std::span<const float>(tz), std::span<float>(tn));
  for (int c = 0; c < 3; ++c)
    back.apply(std::span<const float>(light.data() + c * n, size_t(n)), std::span<float>(light_back.data() + c * n, size_t(n)));
  float e1[3], e2[3];
  shade::shade_transfer(tn.data(), order, light.data(), e1);
  shade::shade_transfer(tz.data(), order, light_back.data(), e2);
  for (int c = 0; c < 3; ++c)
    // Two rotations rounded to float (each ~n ulps of O(1) values) and two 36-term float dot
    // products of O(1) terms: ≲ 1e-5 absolute.
    EXPECT_NEAR(e1[c], e2[c], 1e-5) << c;
}

TEST(ShadeTransfer, MatchesDoubleDotProductAndBatch) {
  const int order = 6, n = order * order, V = 5;
  std::mt19937 rng(11);
  std::normal_distribution<float> g;
  std::vector<float> t(size_t(V * n)), light(size_t(3 * n)), out(size_t(3 * V));
  for (float& v : t) v = g(rng);
  for (float& v : light) v = g(rng);
  shade::shade_transfer_vertices(t.data(), V, order, light.data(), out.data());
  for (int v = 0; v < V; ++v)
    for (int c = 0; c < 3; ++c) {
      double ref = 0, mag = 0;
      for (int i = 0; i < n; ++i) {
        ref += double(t[size_t(v * n + i)]) * light[size_t(c * n + i)];
        mag += std::abs(double(t[size_t(v * n + i)]) * light[size_t(c * n + i)]);
      }
      // Float accumulation of n products: |error| ≤ n ε Σ|t l| (standard summation bound).
      EXPECT_NEAR(out[size_t(3 * v + c)], ref, n * FLT_EPSILON * mag) << v << " " << c;
      float one[3];
      shade::shade_transfer(t.data() + v * n, order, light.data(), one);
      EXPECT_EQ(one[c], out[size_t(3 * v + c)]);
    }
  EXPECT_THROW(shade::shade_transfer_vertices(nullptr, 1, order, light.data(), out.data()), std::invalid_argument);
  EXPECT_THROW(shade::shade_transfer_vertices(t.data(), 1, 65, light.data(), out.data()), std::invalid_argument);
  EXPECT_NO_THROW(shade::shade_transfer_vertices(nullptr, 0, order, nullptr, nullptr));
}

// R_{c,m} for a directional light of radiance·sr L_c from unit ω0 (above the horizon): L_c y_1m(ω0).
void band1_of_direction(const double w[3], const float L[3], float R[9]) {
  for (int c = 0; c < 3; ++c) {
    R[3 * c + 0] = float(L[c] * sh::kBand1Scale * -w[1]);
    R[3 * c + 1] = float(L[c] * sh::kBand1Scale * w[2]);
    R[3 * c + 2] = float(L[c] * sh::kBand1Scale * -w[0]);
  }
}

TEST(ShadeBand1, DirectionalLightGivesCosineLaw) {
  // E = (4π/3) Σ_m y_1m(n) y_1m(ω0) L = (4π/3)(3/4π)(n·ω0) L = L n·ω0 (addition theorem, band 1).
  std::mt19937 rng(5);
  std::normal_distribution<double> g;
  const float L[3] = {1.0f, 3.0f, 0.25f};
  for (int trial = 0; trial < 50; ++trial) {
    double n[3], w[3];
    double nn = 0, ww = 0;
    for (int a = 0; a < 3; ++a) n[a] = g(rng), w[a] = g(rng), nn += n[a] * n[a], ww += w[a] * w[a];
    double cosine = 0;
    for (int a = 0; a < 3; ++a) n[a] /= std::sqrt(nn), w[a] /= std::sqrt(ww), cosine += n[a] * w[a];
    if (cosine <= 0) continue;
    float R[9], E[3];
    const float nf[3] = {float(n[0]), float(n[1]), float(n[2])};
    band1_of_direction(w, L, R);
    shade::shade_band1(nf, R, E);
    for (int c = 0; c < 3; ++c)
      // Float rounding of n, R, the constant and a 3-term sum of terms ≤ L: a few ε · L.
      EXPECT_NEAR(E[c], L[c] * cosine, 8 * FLT_EPSILON * L[c]) << trial << " " << c;
  }
}

TEST(ShadeBand1, UniformSkyGivesPiL) {
  // Unoccluded hemisphere, constant L: R_m = L ∫_H y_1m dω = L √(3/4π) π b_m(n), so
  // E = (4π/3)(3/4π) π L |n|² = π L (the DifMap value of a white furnace).
  const float n[3] = {0.48f, -0.6f, 0.64f};  // unit: 0.2304 + 0.36 + 0.4096 = 1
  const float L[3] = {1, 2, 4};
  float R[9], E[3];
  for (int c = 0; c < 3; ++c) {
    R[3 * c + 0] = float(L[c] * sh::kBand1Scale * kPi * -n[1]);
    R[3 * c + 1] = float(L[c] * sh::kBand1Scale * kPi * n[2]);
    R[3 * c + 2] = float(L[c] * sh::kBand1Scale * kPi * -n[0]);
  }
  shade::shade_band1(n, R, E);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(E[c], kPi * L[c], 8 * FLT_EPSILON * kPi * L[c]) << c;
  float batch[6];
  const float normals[6] = {n[0], n[1], n[2], n[0], n[1], n[2]};
  float R2[18];
  for (int k = 0; k < 18; ++k) R2[k] = R[k % 9];
  shade::shade_band1_vertices(normals, R2, 2, batch);
  for (int k = 0; k < 6; ++k) EXPECT_EQ(batch[k], E[k % 3]);
  EXPECT_THROW(shade::shade_band1_vertices(nullptr, R2, 2, batch), std::invalid_argument);
}

} // namespace
