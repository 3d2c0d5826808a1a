// bake/lights/punctual.h — punctual lights (glTF KHR_lights_punctual: directional, point, spot) and
// what a shade point receives from each, with exact hard shadows (issue 32).
//
// Per shade point and light, at unit intensity (so a runtime recolours and dims each light by
// multiplying with its RGB `intensity`, as it does an area light's radiance; docs/ARCHITECTURE.md
// §3 "Units": irradiance without 1/π):
//   point, spot    E = V · f_spot(l) · max(n·l, 0) / d²,   l = (x − p)/d, d = |x − p|
//   directional    E = V · max(n·l, 0),                    l = −direction
//   S_i = V · f_spot(l) · [n·l > 0] · y_i(l) / d²  (directional: without f and d²), i < order²:
//          the SH projection of the light as seen from p above the horizon, the same quantity
//          as an area light's S (bake/lights/area_bake.h) for a light of zero extent
// and the diffuse outgoing radiance is albedo/π · Σ intensity · E, as for area lights, so one
// product (area_lights/irradiance and area_lights/sh) holds both kinds, one column per light.
//
// f_spot is KHR_lights_punctual's angular attenuation (its "Inner and Outer Cone Angles"):
//   scale = 1 / max(0.001, cos(inner) − cos(outer)),  offset = −cos(outer) · scale,
//   f = clamp(cos∠(direction, −l) · scale + offset, 0, 1)²
// so f = 0 at and outside the outer cone, 1 inside the inner cone, smooth between.
//
// Range (KHR's optional "range", point and spot lights only): the light "must be considered zero"
// at and beyond it, and within it follows the inverse-square law "as closely as possible"; the
// extension's recommended window is applied, so a baked light matches an engine that follows it:
//   w_range(d) = clamp(1 − (d/range)⁴, 0, 1)   (no range: 1),   E = V · w_range · f_spot · max(n·l, 0) / d²
// (the window is 0.94 at half the range, 0.34 at 0.9 of it, 0 from the range on).
//
// Visibility V is ONE shadow ray from the shade point in direction l, in the ε-limit of the exact
// ray cast (bake/visibility/raycast.h: the point's own 1-ring and its near triangles decided by the
// exact predicates, from p + εn, ε → 0+; no epsilon offset): V = 1 iff no triangle blocks l before
// the light (a point or spot light: the first hit at distance ≥ d; a light on a surface is seen).
// The ray is cast only where n·l > 0 (else E and S are 0 whatever V is), so a sun exactly in the
// receiver's tangent plane gives 0 deterministically and never a float hit test.
//
// Degenerate geometry: a shade point exactly at a point or spot light's position receives 0 (the
// inverse-square law has no value there).
//
// Frames: lights are given in world space; the integrator moves them into the occluder mesh's
// frame (Mesh::origin) once, in double, as AreaLightIntegrator does.
#pragma once

#include <bake/lights/lights.h>
#include <bake/mesh/mesh.h>
#include <bake/mesh/shade_point.h>

#include <Eigen/Core>

#include <array>
#include <numbers>
#include <span>
#include <string>
#include <vector>

namespace prt::bake {

class RayCaster;

enum class PunctualKind { Directional, Point, Spot };
const char* punctual_kind_name(PunctualKind);  // "directional", "point", "spot"

struct PunctualLight {
  std::string name;
  PunctualKind kind = PunctualKind::Point;
  Eigen::Vector3d position{0, 0, 0};   // world space; point and spot
  Eigen::Vector3d direction{0, -1, 0};  // unit, world space: where the light travels (spot axis, sun rays); glTF: the node's −Z
  // Per channel: colour × intensity, candela (point, spot) or lux (directional) in glTF's units.
  std::array<double, 3> intensity{1, 1, 1};
  double range = 0;                               // point, spot: KHR's "range" (> 0), 0: none (infinite)
  double inner_cone = 0;                          // spot, radians: 0 ≤ inner < outer
  double outer_cone = std::numbers::pi / 4;       // spot, radians: 0 < outer ≤ π/2 (glTF's defaults)
  // A directional light with an angular size (scene files' "angle", glTF options): a sun, baked
  // as an area light (sun_light) once the scene's bounds are known. 0: a punctual sun.
  double angular_diameter = 0;  // radians
  int segments = 64;            // of the sun's disc
};

// KHR_lights_punctual's angular attenuation (the file comment) at cos_angle = cos∠(axis, −l).
double spot_falloff(double cos_angle, double inner_cone, double outer_cone);
// KHR_lights_punctual's recommended range window (the file comment) at distance d ≥ 0; 1 when
// range is 0 (none).
double range_window(double distance, double range);

// Throws InputError(`file`, "<what>: <defect>") unless the light is valid: finite position,
// a non-zero finite direction (normalised by the parsers), intensities finite and ≥ 0, for a
// spot 0 ≤ inner < outer ≤ π/2 (KHR_lights_punctual's ranges), a range finite and ≥ 0 (0: none),
// and none on a directional light.
void validate_punctual_light(const PunctualLight& light, const std::string& file, const std::string& what);

// LIGHTS WITH AN EXTENT: a point light given a radius, a directional light given an angular size,
// baked with exact soft shadows by the area-light machinery (bake/lights/area_bake.h).
//
// A bulb: the sphere light (make_sphere_light: an icosphere with `subdivisions`) of `radius`
// about the position, of radiance I/(π r²) per channel: a sphere of radiance L is seen in every
// direction with intensity π r² L, so beyond the bulb it matches the point light (to the
// icosphere's area deficit, 0.48% at 3 subdivisions). A spot keeps its point: its cone is no
// property of a constant-radiance emitter, nor is a range (the callers say so when one is given).
AreaLight bulb_light(const PunctualLight& point, double radius, int subdivisions);
//
// A sun: a disc light (make_disc_light, `segments`-gon) facing the scene, centred at
// centre − D·direction with D = kSunDistance · radius, of angular radius α/2 as seen from
// `centre` (its polygon's circumradius D·tan(α/2)). Why a finite disc and not the exact "disc at
// infinity" (the same spherical cap from every receiver): the area-light integrator clips FIXED
// world-space emitters by the occluders exactly (the depth test against the emitter's plane, the
// ε-limit at the shade point); a disc placed far beyond every occluder (`centre` and `radius`:
// a ball holding the whole scene) is behind every occluder for every receiver, so its shadows
// are exact for what it is, and it differs from the disc at infinity only by parallax: a
// receiver within `radius` of `centre` sees its direction turned by at most radius/D = 2^-20 rad
// (1e-6 rad, 4.5e-3 apart from the sun's angular radius of 4.6e-3 rad at 0.53 degrees) and its
// solid angle changed by a relative 2^-19 at most. Its radiance per channel is intensity / C,
// C = ∫_disc max(ω·(−direction), 0) dω from `centre`, so a receiver at the centre facing the sun
// unshadowed gets E = intensity, as the punctual sun gives it.
inline constexpr double kSunDistance = 1048576.0;  // 2^20 scene radii
AreaLight sun_light(const PunctualLight& sun, const Eigen::Vector3d& centre, double radius);

class PunctualLightIntegrator {
public:
  // `rays` traces the occluder mesh (nullptr: nothing casts shadows, V ≡ 1); `origin` is that
  // mesh's Mesh::origin. `sh_order` 0: irradiance only. The lights must be valid.
  PunctualLightIntegrator(std::span<const PunctualLight> lights, const RayCaster* rays, const Eigen::Vector3d& origin,
                          int sh_order);

  size_t lights() const noexcept { return lights_.size(); }
  int sh_order() const noexcept { return order_; }
  // Doubles per light in a row: E, then order² SH coefficients (AreaLightIntegrator's layout).
  size_t per_light() const noexcept { return 1 + size_t(order_) * size_t(order_); }
  size_t width() const noexcept { return lights() * per_light(); }

  // out[l·per_light()] = E_l, out[l·per_light() + 1 + i] = S_l,i (file comment). Thread-safe.
  void integrate(const ShadePoint& point, std::span<double> out) const;

  // The unit direction l from the point to light `light` and its unshadowed weight w (w_range ·
  // f_spot / d², or 1; 0 when the point is at the light), so E = V · w · max(n·l, 0). For callers that shade
  // something else with it (a GGX lobe).
  double direction_to(const ShadePoint& point, size_t light, Eigen::Vector3d& l) const;
  // V for that direction (1 without occluders). Thread-safe.
  bool visible(const ShadePoint& point, size_t light, const Eigen::Vector3d& l) const;

private:
  std::vector<PunctualLight> lights_;  // positions in the mesh's frame
  const RayCaster* rays_ = nullptr;
  int order_ = 0;
};

} // namespace prt::bake
