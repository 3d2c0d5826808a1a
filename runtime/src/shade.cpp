// shade.cpp — SH projection of lat-long pixels, transfer · light, band-1 shading; conventions and
// papers in prtshade/shade.h.
#include <prtshade/shade.h>

#include "check.h"

#include <prtshade/sh.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace prt::shade {
namespace {

constexpr double kPi = 3.14159265358979323846264338327950288;
// Largest lat-long image accepted (pixels), as bake::EnvMap: 2^28.
constexpr int64_t kMaxPixels = int64_t(1) << 28;
// √(4π/3) = (4π/3) · √(3/(4π)): band-1 irradiance from the unnormalised band-1 direction.
constexpr float kBand1Irradiance = 2.04665341589297697f;

// Half-pixel bounds of integer position k clipped to [0, n−1].
void half_pixel_bounds(int k, int n, double& lo, double& hi) {
  lo = std::max(k - 0.5, 0.0);
  hi = std::min(k + 0.5, double(n - 1));
}

} // namespace

void project_latlong(const float* rgb, int width, int height, int order, float* out) {
  PRT_SHADE_REQUIRE(rgb != nullptr && out != nullptr, "null pointer");
  PRT_SHADE_REQUIRE(width >= 2 && height >= 2,
                    "lat-long image of " + std::to_string(width) + "x" + std::to_string(height) + " pixels: need at least 2x2");
  PRT_SHADE_REQUIRE(int64_t(width) * height <= kMaxPixels,
                    "lat-long image of " + std::to_string(width) + "x" + std::to_string(height) + " pixels: at most 2^28");
  PRT_SHADE_REQUIRE(order >= 1 && order <= sh::kMaxOrder, "order " + std::to_string(order) + " outside [1, 64]");
  const size_t n = size_t(sh::num_coeffs(order));
  const size_t pixels = size_t(width) * size_t(height);
  for (size_t k = 0; k < 3 * pixels; ++k)
    PRT_SHADE_REQUIRE(std::isfinite(rgb[k]), "non-finite pixel value at (x " + std::to_string((k / 3) % size_t(width)) +
                                                 ", y " + std::to_string((k / 3) / size_t(width)) + ") channel " +
                                                 std::string(1, "RGB"[k % 3]));

  std::vector<double> total(3 * n, 0.0), row(3 * n), y(n);
  const size_t w_count = size_t(width);
  std::vector<double> lon_sin(w_count), lon_cos(w_count), dlon(w_count);
  for (int px = 0; px < width; ++px) {
    const double lon = kPi - 2.0 * kPi * px / (width - 1);
    lon_sin[size_t(px)] = std::sin(lon);
    lon_cos[size_t(px)] = std::cos(lon);
    double lo, hi;
    half_pixel_bounds(px, width, lo, hi);
    dlon[size_t(px)] = 2.0 * kPi * (hi - lo) / (width - 1);
  }
  for (int py = 0; py < height; ++py) {
    const double lat = 0.5 * kPi - kPi * py / (height - 1);
    const double cos_lat = std::cos(lat), sin_lat = std::sin(lat);
    double lo, hi;
    half_pixel_bounds(py, height, lo, hi);
    // sin(top) − sin(bottom) in product form: full relative precision near the poles.
    const double half_dlat = 0.5 * kPi * (hi - lo) / (height - 1);
    const double mid_lat = 0.5 * kPi - 0.5 * kPi * (lo + hi) / (height - 1);
    const double dsin = 2.0 * std::cos(mid_lat) * std::sin(half_dlat);
    std::fill(row.begin(), row.end(), 0.0);
    for (int px = 0; px < width; ++px) {
      const float* v = rgb + (size_t(py) * size_t(width) + size_t(px)) * 3;
      const double r = std::max(v[0], 0.0f), g = std::max(v[1], 0.0f), b = std::max(v[2], 0.0f);
      if (r == 0 && g == 0 && b == 0) continue;
      sh::eval(order, lon_sin[size_t(px)] * cos_lat, sin_lat, lon_cos[size_t(px)] * cos_lat, y);
      const double w = dlon[size_t(px)] * dsin;
      const double wr = w * r, wg = w * g, wb = w * b;
      for (size_t i = 0; i < n; ++i) {
        row[i] += wr * y[i];
        row[n + i] += wg * y[i];
        row[2 * n + i] += wb * y[i];
      }
    }
    for (size_t k = 0; k < 3 * n; ++k) total[k] += row[k];
  }
  for (size_t k = 0; k < 3 * n; ++k) out[k] = float(total[k]);
}

void shade_transfer(const float* transfer, int order, const float* light_rgb, float out[3]) {
  const int n = order * order;
  float r = 0, g = 0, b = 0;
  for (int i = 0; i < n; ++i) {
    const float t = transfer[i];
    r += t * light_rgb[i];
    g += t * light_rgb[n + i];
    b += t * light_rgb[2 * n + i];
  }
  out[0] = r, out[1] = g, out[2] = b;
}

void shade_transfer_vertices(const float* transfer, size_t count, int order, const float* light_rgb, float* out) {
  PRT_SHADE_REQUIRE(order >= 0 && order <= sh::kMaxOrder, "order " + std::to_string(order) + " outside [0, 64]");
  if (count == 0) return;
  PRT_SHADE_REQUIRE(transfer != nullptr && light_rgb != nullptr && out != nullptr, "null pointer");
  const size_t n = size_t(order) * size_t(order);
  for (size_t v = 0; v < count; ++v) shade_transfer(transfer + v * n, order, light_rgb, out + 3 * v);
}

void shade_band1(const float n[3], const float radiance[9], float out[3]) {
  // Band-1 direction of the basis: y_1m ∝ (−y, z, −x) (prtshade/sh.h, band1_from_direction).
  const float bm = -n[1], b0 = n[2], bp = -n[0];
  for (int c = 0; c < 3; ++c) {
    const float* R = radiance + 3 * c;
    out[c] = kBand1Irradiance * (bm * R[0] + b0 * R[1] + bp * R[2]);
  }
}

void shade_band1_vertices(const float* normals, const float* radiance, size_t count, float* out) {
  if (count == 0) return;
  PRT_SHADE_REQUIRE(normals != nullptr && radiance != nullptr && out != nullptr, "null pointer");
  for (size_t v = 0; v < count; ++v) shade_band1(normals + 3 * v, radiance + 9 * v, out + 3 * v);
}

} // namespace prt::shade
