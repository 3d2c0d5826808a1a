// lights.cpp — shading with the baked lights' irradiance, and unshadowed punctual lights
// (prtshade/lights.h).
#include <prtshade/lights.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace prt::shade {

double spot_falloff(double cos_angle, double inner_cone, double outer_cone) {
  const double cos_outer = std::cos(outer_cone);
  const double scale = 1.0 / std::max(0.001, std::cos(inner_cone) - cos_outer);
  const double a = std::clamp(cos_angle * scale - cos_outer * scale, 0.0, 1.0);
  return a * a;
}

double range_window(double distance, double range) {
  if (!(range > 0)) return 1;
  const double x = distance / range, x2 = x * x;
  return std::clamp(1 - x2 * x2, 0.0, 1.0);
}

double unshadowed_punctual(const PunctualLight& light, const std::array<double, 3>& p, const std::array<double, 3>& n) {
  const auto& d = light.direction;
  const double dn = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  if (light.kind == PunctualKind::Directional) {
    if (!(dn > 0)) return 0;
    return std::max(-(n[0] * d[0] + n[1] * d[1] + n[2] * d[2]) / dn, 0.0);
  }
  const double t[3] = {light.position[0] - p[0], light.position[1] - p[1], light.position[2] - p[2]};
  const double d2 = t[0] * t[0] + t[1] * t[1] + t[2] * t[2];
  if (!(d2 > 0)) return 0;
  const double len = std::sqrt(d2);
  const double l[3] = {t[0] / len, t[1] / len, t[2] / len};
  const double cosine = n[0] * l[0] + n[1] * l[1] + n[2] * l[2];
  if (!(cosine > 0)) return 0;
  double w = range_window(len, light.range) / d2;
  if (light.kind == PunctualKind::Spot) {
    if (!(dn > 0)) return 0;
    w *= spot_falloff(-(d[0] * l[0] + d[1] * l[1] + d[2] * l[2]) / dn, light.inner_cone, light.outer_cone);
  }
  return w * cosine;
}

void shade_lights(const float* E, std::size_t count, std::size_t lights, const float* emission, const float* albedo,
                  std::size_t albedo_stride, float* out) {
  for (std::size_t v = 0; v < count; ++v) {
    const float* e = E + v * lights;
    const float* a = albedo + v * albedo_stride;
    for (int c = 0; c < 3; ++c) {
      double sum = 0;
      for (std::size_t l = 0; l < lights; ++l) sum += double(emission[3 * l + std::size_t(c)]) * double(e[l]);
      out[3 * v + std::size_t(c)] = float(double(a[c]) * sum * std::numbers::inv_pi);
    }
  }
}

} // namespace prt::shade
