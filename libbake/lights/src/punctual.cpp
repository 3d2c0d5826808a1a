// punctual.cpp — punctual lights and their per-point irradiance with exact hard shadows
// (bake/lights/punctual.h).
#include <bake/core/error.h>
#include <bake/lights/punctual.h>
#include <bake/sphere/spherical_polygon.h>
#include <bake/visibility/raycast.h>

#include <prtshade/lights.h>
#include <prtshade/sh.h>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace prt::bake {

const char* punctual_kind_name(PunctualKind k) {
  switch (k) {
  case PunctualKind::Directional: return "directional";
  case PunctualKind::Point: return "point";
  case PunctualKind::Spot: return "spot";
  }
  return "?";
}

// KHR_lights_punctual's falloffs have one home, the runtime's contract (prtshade/lights.h): a baked
// light and one a runtime shades live agree wherever nothing shadows.
double spot_falloff(double cos_angle, double inner_cone, double outer_cone) {
  return shade::spot_falloff(cos_angle, inner_cone, outer_cone);
}

double range_window(double distance, double range) { return shade::range_window(distance, range); }

void validate_punctual_light(const PunctualLight& l, const std::string& file, const std::string& what) {
  auto fail = [&](const std::string& defect) { throw InputError(file, what + ": " + defect); };
  auto number = [](double x) {
    std::ostringstream os;
    os.precision(6);
    os << x;
    return os.str();
  };
  for (double c : l.intensity)
    if (!(std::isfinite(c) && c >= 0)) fail("intensity must be finite and >= 0, got " + number(c));
  if (!l.position.allFinite()) fail("position is not finite");
  if (!l.direction.allFinite() || !(l.direction.norm() > 0)) fail("direction must be a finite non-zero vector");
  if (!(std::isfinite(l.range) && l.range >= 0)) fail("range must be finite and > 0, got " + number(l.range));
  if (l.range > 0 && l.kind == PunctualKind::Directional) fail("a directional light has no range (point and spot lights do)");
  if (l.kind == PunctualKind::Spot) {
    constexpr double kRightAngle = std::numbers::pi / 2;
    if (!(std::isfinite(l.inner_cone) && l.inner_cone >= 0))
      fail("inner cone angle must be finite and >= 0, got " + number(l.inner_cone));
    if (!(std::isfinite(l.outer_cone) && l.outer_cone > 0 && l.outer_cone <= kRightAngle))
      fail("outer cone angle must be in (0, pi/2] radians (0 to 90 degrees), got " + number(l.outer_cone));
    if (!(l.inner_cone < l.outer_cone))
      fail("inner cone angle (" + number(l.inner_cone) + ") must be smaller than the outer cone angle (" +
           number(l.outer_cone) + ")");
  }
}

AreaLight bulb_light(const PunctualLight& point, double radius, int subdivisions) {
  AreaLight light = make_sphere_light(point.position, radius, subdivisions);
  light.name = point.name;
  for (size_t c = 0; c < 3; ++c) light.radiance[c] = point.intensity[c] / (std::numbers::pi * radius * radius);
  return light;
}

AreaLight sun_light(const PunctualLight& sun, const Eigen::Vector3d& centre, double radius) {
  PRT_CHECK(sun.angular_diameter > 0 && radius > 0);
  const Eigen::Vector3d d = sun.direction.normalized();
  const double distance = kSunDistance * radius;
  AreaLight light = make_disc_light(centre - distance * d, d, distance * std::tan(sun.angular_diameter / 2), sun.segments);
  light.name = sun.name;
  std::vector<Eigen::Vector3d> directions;
  for (const Eigen::Vector3d& v : light.vertices) directions.push_back((v - centre).normalized());
  const double c = std::abs(cosine_integral(directions, -d));
  for (size_t k = 0; k < 3; ++k) light.radiance[k] = sun.intensity[k] / c;
  return light;
}

PunctualLightIntegrator::PunctualLightIntegrator(std::span<const PunctualLight> lights, const RayCaster* rays,
                                                 const Eigen::Vector3d& origin, int sh_order)
    : lights_(lights.begin(), lights.end()), rays_(rays), order_(sh_order) {
  PRT_CHECK(sh_order >= 0 && sh_order <= sh::kMaxOrder);
  for (PunctualLight& l : lights_) {
    l.position -= origin;
    l.direction.normalize();
  }
}

double PunctualLightIntegrator::direction_to(const ShadePoint& point, size_t light, Eigen::Vector3d& l) const {
  const PunctualLight& light_ = lights_[light];
  if (light_.kind == PunctualKind::Directional) {
    l = -light_.direction;
    return 1;
  }
  const Eigen::Vector3d to = light_.position - point.p;
  const double d2 = to.squaredNorm();
  if (!(d2 > 0)) {
    l = point.n;
    return 0;
  }
  l = to / std::sqrt(d2);
  double w = range_window(std::sqrt(d2), light_.range) / d2;
  if (light_.kind == PunctualKind::Spot) w *= spot_falloff(light_.direction.dot(-l), light_.inner_cone, light_.outer_cone);
  return w;
}

namespace {

// V for direction l from the point, the light at distance `reach` (+inf: directional), given the
// point's near triangles.
bool seen(const RayCaster& rays, const ShadePoint& point, const NearTriangles& near, const Eigen::Vector3d& l,
          double reach) {
  if (std::isinf(reach)) return rays.visible(point, near, l);
  const std::optional<double> hit = rays.first_hit(point, near, l);
  return !hit || *hit >= reach;
}

double reach_of(const PunctualLight& light, const ShadePoint& point) {
  return light.kind == PunctualKind::Directional ? std::numeric_limits<double>::infinity() : (light.position - point.p).norm();
}

} // namespace

bool PunctualLightIntegrator::visible(const ShadePoint& point, size_t light, const Eigen::Vector3d& l) const {
  if (rays_ == nullptr) return true;
  return seen(*rays_, point, rays_->near_triangles(point), l, reach_of(lights_[light], point));
}

void PunctualLightIntegrator::integrate(const ShadePoint& point, std::span<double> out) const {
  PRT_CHECK(out.size() == width());
  std::fill(out.begin(), out.end(), 0.0);
  std::optional<NearTriangles> near;  // computed once, at the first ray
  double y[sh::kMaxOrder * sh::kMaxOrder];
  for (size_t k = 0; k < lights_.size(); ++k) {
    Eigen::Vector3d l;
    const double w = direction_to(point, k, l);
    const double cosine = point.n.dot(l);
    if (!(w > 0) || !(cosine > 0)) continue;  // no light, or at or below the horizon: no ray
    if (rays_ != nullptr) {
      if (!near) near = rays_->near_triangles(point);
      if (!seen(*rays_, point, *near, l, reach_of(lights_[k], point))) continue;
    }
    const std::span<double> row = out.subspan(k * per_light(), per_light());
    row[0] = w * cosine;
    if (order_ > 0) {
      const std::span<double> ys(y, size_t(order_) * size_t(order_));
      sh::eval(order_, l.x(), l.y(), l.z(), ys);
      for (size_t i = 0; i < ys.size(); ++i) row[1 + i] = w * ys[i];
    }
  }
}

} // namespace prt::bake
