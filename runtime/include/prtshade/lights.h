// prtshade/lights.h — run-time shading with the baked lights (formats/SCHEMA.md "Area lights",
// "Punctual lights"): every light of a scene, area or punctual, is one column of E per receiver,
// baked at unit emission (an area light's unit radiance, a punctual light's unit intensity) with
// its exact shadows, so the runtime recolours and dims each light by its RGB emission:
//   L_out,c = albedo_c / π · Σ_l emission_l,c · E_l          (Lambertian, no 1/π in E: §3 "Units")
// An area light's emission is its radiance; a point or spot light's its intensity (candela), a
// directional light's its illuminance (lux), as /lights/<name>'s `radiance` attribute stores them.
//
// For a light the bake did not see (moved, added at run time), unshadowed_punctual gives the
// same E without shadows, KHR_lights_punctual's conventions: E = w_range · f_spot · max(n·l, 0) / d²
// (directional: max(n·l, 0)), f_spot the extension's smooth cone falloff
//   f = clamp((cos∠(axis, −l) − cos outer) / max(0.001, cos inner − cos outer), 0, 1)²
// and w_range its recommended range window clamp(1 − (d/range)⁴, 0, 1) (1 without a range)
// exactly as libbake computes it (bake/lights/punctual.h), so a baked light and one shaded live
// agree wherever nothing shadows.
//
// Thread-safe, no allocation; std-only. The C API (prt_shade_lights, prt_punctual_irradiance)
// and the shader mirrors follow this header.
#pragma once

#include <array>
#include <cstddef>

namespace prt::shade {

enum class PunctualKind { Directional = 0, Point = 1, Spot = 2 };

struct PunctualLight {
  PunctualKind kind = PunctualKind::Point;
  std::array<double, 3> position{0, 0, 0};   // point, spot
  std::array<double, 3> direction{0, -1, 0};  // spot, directional: where the light travels (unit)
  double inner_cone = 0, outer_cone = 0.7853981633974483;  // spot, radians
  double range = 0;                                         // point, spot: > 0, or 0 for none (infinite)
};

// KHR_lights_punctual's angular attenuation at cos_angle = cos∠(axis, −l) (file comment).
double spot_falloff(double cos_angle, double inner_cone, double outer_cone);

// KHR_lights_punctual's recommended range window at distance d ≥ 0 (file comment); 1 when range is 0.
double range_window(double distance, double range);

// E at (p, n) (n unit) from `light` at unit intensity, unshadowed (file comment); 0 at the
// light's own position.
double unshadowed_punctual(const PunctualLight& light, const std::array<double, 3>& p, const std::array<double, 3>& n);

// out[v][c] = albedo[v][c]/π · Σ_l emission[l][c] · E[v][l] for `count` receivers: E [count][lights]
// (an area_lights/irradiance product), emission [lights][3], albedo [count][3] (or one RGB for all
// when albedo_stride = 0; 3 for per receiver), out [count][3]. No checks (hot path; the C API checks).
void shade_lights(const float* E, std::size_t count, std::size_t lights, const float* emission, const float* albedo,
                  std::size_t albedo_stride, float* out);

} // namespace prt::shade
