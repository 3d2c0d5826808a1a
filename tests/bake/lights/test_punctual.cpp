// Tests of punctual lights (bake/lights/punctual.h): closed forms (a point light over a plane
// E = I cosθ / d², a directional light E = n·l), KHR_lights_punctual's spot falloff at its cone
// edges, exact hard shadows on each side of a shadow edge, a sun in the tangent plane, a spot whose
// cone edge passes through a shadow edge, the SH row, validation errors that name the light, and
// the extended lights (a bulb and a sun disc) against their punctual limits.
#include <bake/core/error.h>
#include <bake/lights/area_bake.h>
#include <bake/lights/punctual.h>
#include <bake/mesh/mesh.h>
#include <bake/mesh/receivers.h>
#include <bake/visibility/raycast.h>

#include <prtshade/lights.h>
#include <prtshade/sh.h>

#include <gtest/gtest.h>
#include <test_scenes.h>

#include <cmath>
#include <numbers>
#include <vector>

namespace {

using namespace prt::bake;
using Eigen::Vector3d;

// Values computed by the same formula in another order: a few ulps apart.
constexpr double kRounding = 1e-14;

PunctualLight point_light(Vector3d p) {
  PunctualLight l;
  l.name = "bulb";
  l.kind = PunctualKind::Point;
  l.position = p;
  return l;
}

PunctualLight directional(Vector3d d) {
  PunctualLight l;
  l.name = "sun";
  l.kind = PunctualKind::Directional;
  l.direction = d.normalized();
  return l;
}

PunctualLight spot(Vector3d p, Vector3d d, double inner, double outer) {
  PunctualLight l;
  l.name = "spot";
  l.kind = PunctualKind::Spot;
  l.position = p;
  l.direction = d.normalized();
  l.inner_cone = inner;
  l.outer_cone = outer;
  return l;
}

// A scene (a floor grid of half-size 4, spacing 0.5, plus optional occluders) with its rays, and
// the floor's vertices as shade points of the union (their own flat 1-ring in the ε-limit).
struct Scene {
  Mesh mesh;
  Topology topo;
  std::unique_ptr<RayCaster> rays;
  explicit Scene(std::vector<Mesh> occluders = {}) {
    std::vector<Mesh> parts = {prt::testing::grid(8, 4.0f)};
    for (Mesh& m : occluders) parts.push_back(std::move(m));
    mesh = merge_meshes(parts, "scene");
    topo = build_topology(mesh);
    rays = std::make_unique<RayCaster>(mesh, topo);
  }
  // The floor's vertex at (x, y) (multiples of 0.5 in [-4, 4]).
  ShadePoint floor(double x, double y) const {
    const auto i = uint32_t(std::lround((x + 4) * 2)), j = uint32_t(std::lround((y + 4) * 2));
    const ShadePoint s = vertex_shade_point(mesh, topo, j * 17 + i);
    EXPECT_EQ(s.p, Vector3d(x, y, 0));
    return s;
  }
};

std::vector<double> row_of(const PunctualLightIntegrator& integ, const ShadePoint& s) {
  std::vector<double> row(integ.width());
  integ.integrate(s, row);
  return row;
}

TEST(Punctual, APointLightOverAPlaneIsIntensityCosineOverDistanceSquared) {
  const Scene scene;
  const Vector3d x(0.7, -1.3, 2.5);
  const PunctualLight light = point_light(x);
  const PunctualLightIntegrator integ({&light, 1}, scene.rays.get(), Vector3d::Zero(), 0);
  ASSERT_EQ(integ.width(), 1u);
  for (double px : {-4.0, -2.5, 0.0, 0.5, 3.0})
    for (double py : {-3.5, 0.0, 4.0}) {
      const ShadePoint s = scene.floor(px, py);
      const Vector3d to = x - s.p;
      const double d = to.norm(), cos_theta = to.z() / d;
      EXPECT_NEAR(row_of(integ, s)[0], cos_theta / (d * d), kRounding) << px << " " << py;
    }
  // Below the plane the light is behind every receiver: 0, without a ray.
  const PunctualLight under = point_light(Vector3d(0.2, 0.1, -1));
  const PunctualLightIntegrator below({&under, 1}, scene.rays.get(), Vector3d::Zero(), 0);
  EXPECT_EQ(row_of(below, scene.floor(0, 0))[0], 0.0);
}

TEST(Punctual, ARangeIsKhrLightsPunctualsWindowAndZeroFromTheRangeOn) {
  // KHR_lights_punctual's recommended window clamp(1 - (d/range)^4, 0, 1): the closed form over the
  // plane, exactly 0 at and beyond the range, and the light untouched without one.
  EXPECT_EQ(range_window(5, 0), 1.0);
  EXPECT_EQ(range_window(0, 2), 1.0);
  EXPECT_EQ(range_window(1, 2), 1 - 1.0 / 16);
  EXPECT_EQ(range_window(2, 2), 0.0);
  EXPECT_EQ(range_window(7, 2), 0.0);
  const Scene scene;
  const Vector3d x(0.7, -1.3, 2.5);
  PunctualLight light = point_light(x);
  light.range = 4;
  PunctualLight cone = spot(x, Vector3d(0.1, 0.2, -1), 0.3, 0.9);
  cone.range = 3.5;
  const std::vector<PunctualLight> lights = {light, cone};
  const PunctualLightIntegrator integ(lights, scene.rays.get(), Vector3d::Zero(), 2);
  size_t inside = 0, beyond = 0;
  for (double px : {-4.0, -2.5, 0.0, 0.5, 1.5, 3.0})
    for (double py : {-3.5, -1.0, 0.0, 4.0}) {
      const ShadePoint s = scene.floor(px, py);
      const Vector3d to = x - s.p;
      const double d = to.norm(), cos_theta = to.z() / d;
      const double w = std::clamp(1 - std::pow(d / 4, 4), 0.0, 1.0);
      const std::vector<double> row = row_of(integ, s);
      EXPECT_NEAR(row[0], w * cos_theta / (d * d), kRounding) << px << " " << py;
      const double f = spot_falloff(cone.direction.normalized().dot(-to / d), 0.3, 0.9);
      const double wc = std::clamp(1 - std::pow(d / 3.5, 4), 0.0, 1.0);
      EXPECT_NEAR(row[5], wc * f * cos_theta / (d * d), kRounding) << px << " " << py;
      EXPECT_NEAR(row[1], w * 0.28209479177387814 / (d * d), kRounding) << px << " " << py;  // S_0 = w y_0 / d^2
      inside += w > 0 && w < 1;
      if (d >= 4) {
        ++beyond;
        EXPECT_EQ(row[0], 0.0);
        for (size_t i = 0; i < 4; ++i) EXPECT_EQ(row[1 + i], 0.0);
      }
    }
  EXPECT_GT(inside, 6u);
  EXPECT_GT(beyond, 2u);
}

TEST(Punctual, TheSpotFalloffIsKhrLightsPunctualsAtItsConeEdges) {
  const double inner = 0.3, outer = 0.5;
  EXPECT_EQ(spot_falloff(std::cos(outer), inner, outer), 0.0);
  EXPECT_EQ(spot_falloff(std::cos(outer + 1e-3), inner, outer), 0.0);  // outside: clamped
  EXPECT_EQ(spot_falloff(std::cos(inner - 1e-3), inner, outer), 1.0);  // inside the inner cone
  EXPECT_NEAR(spot_falloff(std::cos(inner), inner, outer), 1.0, kRounding);
  // Between: the square of the linear ramp in cos, as the extension's reference code.
  const double c = std::cos(0.4), t = (c - std::cos(outer)) / (std::cos(inner) - std::cos(outer));
  EXPECT_NEAR(spot_falloff(c, inner, outer), t * t, kRounding);
  // Equal cones would divide by zero: the extension's max(0.001, ...) keeps it finite.
  EXPECT_TRUE(std::isfinite(spot_falloff(std::cos(0.5), 0.5 - 1e-9, 0.5)));
  // Through the integrator, free points (no occluders) on a ring about the spot's axis.
  const PunctualLight s = spot(Vector3d(0, 0, 4), Vector3d(0, 0, -1), inner, outer);
  const PunctualLightIntegrator integ({&s, 1}, nullptr, Vector3d::Zero(), 0);
  for (double angle : {0.0, 0.2, 0.35, 0.45, 0.5, 0.6}) {
    ShadePoint p;
    p.p = Vector3d(4 * std::tan(angle), 0, 0);
    p.n = Vector3d(0, 0, 1);
    const double d2 = p.p.squaredNorm() + 16, cos_n = 4 / std::sqrt(d2);
    const double expected = spot_falloff(cos_n, inner, outer) * cos_n / d2;
    EXPECT_NEAR(row_of(integ, p)[0], expected, kRounding) << angle;
    if (angle >= outer) {
      EXPECT_NEAR(row_of(integ, p)[0], 0.0, 1e-15) << angle;
    }
    if (angle <= inner) {
      EXPECT_NEAR(row_of(integ, p)[0], cos_n / d2, kRounding) << angle;
    }
  }
}

TEST(Punctual, ADirectionalLightCastsAnExactHardShadow) {
  // A box over the floor, x, y in [-1, 1], z in [1, 2]; the sun travels along (1, 0, -1): the
  // floor is shadowed for x in [0, 3] (|y| <= 1), lit on either side.
  const Scene scene({prt::testing::box(Eigen::Vector3f(-1, -1, 1), Eigen::Vector3f(1, 1, 2))});
  const PunctualLight sun = directional(Vector3d(1, 0, -1));
  const PunctualLightIntegrator integ({&sun, 1}, scene.rays.get(), Vector3d::Zero(), 0);
  const double lit = std::sqrt(0.5);
  for (double x : {-4.0, -1.0, -0.5, 3.5, 4.0}) EXPECT_NEAR(row_of(integ, scene.floor(x, 0))[0], lit, kRounding) << x;
  for (double x : {0.5, 1.0, 1.5, 2.5}) EXPECT_EQ(row_of(integ, scene.floor(x, 0))[0], 0.0) << x;
  for (double y : {-1.5, 1.5}) EXPECT_NEAR(row_of(integ, scene.floor(1.5, y))[0], lit, kRounding) << y;
  for (double y : {-0.5, 0.5}) EXPECT_EQ(row_of(integ, scene.floor(1.5, y))[0], 0.0) << y;
  // The box's own top face sees the sun, its bottom face never does.
  EXPECT_TRUE(integ.visible(scene.floor(-2, 0), 0, Vector3d(-1, 0, 1).normalized()));
}

TEST(Punctual, ASunInTheTangentPlaneGivesZeroAndJustAboveItFullLight) {
  // Exactly grazing: n·l = 0, E = 0 without a ray (deterministic); the least tilt above the
  // horizon: the flat floor's own ring and its neighbours decided exactly, nothing blocks.
  const Scene scene;
  for (const Vector3d& d : {Vector3d(1, 0, 0), Vector3d(0, -1, 0), Vector3d(1, 1, 0)}) {
    const PunctualLight sun = directional(d);
    const PunctualLightIntegrator integ({&sun, 1}, scene.rays.get(), Vector3d::Zero(), 0);
    for (double x : {-4.0, 0.0, 1.5}) EXPECT_EQ(row_of(integ, scene.floor(x, 0.5))[0], 0.0);
  }
  const PunctualLight low = directional(Vector3d(1, 0, -1e-9));
  const PunctualLightIntegrator integ({&low, 1}, scene.rays.get(), Vector3d::Zero(), 0);
  for (double x : {-4.0, -0.5, 0.0, 2.0, 4.0}) {
    const ShadePoint s = scene.floor(x, 0.5);
    EXPECT_EQ(row_of(integ, s)[0], s.n.dot(-low.direction)) << x;
    EXPECT_GT(row_of(integ, s)[0], 0.0);
  }
}

TEST(Punctual, ASpotWhoseConeEdgePassesThroughAShadowEdge) {
  // The spot at (0, 0, 4) pointing down, outer cone atan(1/2): its edge meets the floor at x = 2.
  // A slab x in [1, 3], z in [2, 2.5] has its near bottom edge (1, y, 2) on that cone edge, so its
  // shadow on the floor starts at x = 2 too. Inside: lit, with the falloff; beyond: 0; on the
  // common edge: 0 to rounding (the falloff vanishes there whatever the shadow ray says).
  const Scene scene({prt::testing::box(Eigen::Vector3f(1, -3, 2), Eigen::Vector3f(3, 3, 2.5f))});
  const double outer = std::atan(0.5), inner = 0.2;
  const PunctualLight s = spot(Vector3d(0, 0, 4), Vector3d(0, 0, -1), inner, outer);
  const PunctualLightIntegrator integ({&s, 1}, scene.rays.get(), Vector3d::Zero(), 0);
  for (double x : {0.0, 0.5, 1.0, 1.5}) {
    const ShadePoint p = scene.floor(x, 0);
    const double d2 = x * x + 16, c = 4 / std::sqrt(d2);
    EXPECT_NEAR(row_of(integ, p)[0], spot_falloff(c, inner, outer) * c / d2, kRounding) << x;
    EXPECT_GT(row_of(integ, p)[0], 0.0) << x;
  }
  EXPECT_NEAR(row_of(integ, scene.floor(2, 0))[0], 0.0, 1e-15);
  for (double x : {2.5, 3.0, 4.0}) EXPECT_EQ(row_of(integ, scene.floor(x, 0))[0], 0.0) << x;
  // The same spot with a wider cone: x = 2.5 is inside it now but in the slab's shadow, x = 1.5 lit.
  const PunctualLight wide = spot(Vector3d(0, 0, 4), Vector3d(0, 0, -1), inner, 1.2);
  const PunctualLightIntegrator w({&wide, 1}, scene.rays.get(), Vector3d::Zero(), 0);
  EXPECT_EQ(row_of(w, scene.floor(2.5, 0))[0], 0.0);
  EXPECT_GT(row_of(w, scene.floor(1.5, 0))[0], 0.0);
  // A point light beyond an occluder is blocked; an occluder beyond the light is not.
  const PunctualLight under_slab = point_light(Vector3d(2, 0, 1.5));
  const PunctualLight over_slab = point_light(Vector3d(2, 0, 3));
  const PunctualLightIntegrator both(std::vector<PunctualLight>{under_slab, over_slab}, scene.rays.get(), Vector3d::Zero(), 0);
  const std::vector<double> row = row_of(both, scene.floor(2.5, 0));
  EXPECT_GT(row[0], 0.0);
  EXPECT_EQ(row[1], 0.0);
}

TEST(Punctual, TheShRowIsTheLightsDirectionWeighted) {
  const Scene scene;
  const PunctualLight light = point_light(Vector3d(1, 2, 3));
  const int order = 4;
  const PunctualLightIntegrator integ({&light, 1}, scene.rays.get(), Vector3d::Zero(), order);
  ASSERT_EQ(integ.per_light(), 17u);
  const ShadePoint s = scene.floor(-1, 0.5);
  const std::vector<double> row = row_of(integ, s);
  const Vector3d to = light.position - s.p;
  const Vector3d l = to.normalized();
  std::vector<double> y(16);
  prt::sh::eval(order, l.x(), l.y(), l.z(), y);
  for (size_t i = 0; i < y.size(); ++i) EXPECT_NEAR(row[1 + i], y[i] / to.squaredNorm(), kRounding) << i;
  EXPECT_NEAR(row[0], l.z() / to.squaredNorm(), kRounding);
}

TEST(Punctual, TheMeshFrameMovesTheLightsOnce) {
  // A scene whose mesh frame has its origin at (1000, 0, 0): the light given in world space.
  Mesh floor = prt::testing::grid(2, 1.0f);
  floor.origin = Vector3d(1000, 0, 0);
  const Topology topo = build_topology(floor);
  const RayCaster rays(floor, topo);
  const PunctualLight light = point_light(Vector3d(1000.5, 0, 2));
  const PunctualLightIntegrator integ({&light, 1}, &rays, floor.origin, 0);
  const ShadePoint s = vertex_shade_point(floor, topo, prt::testing::grid_centre(2));
  EXPECT_NEAR(row_of(integ, s)[0], 2 / std::pow(4.25, 1.5), kRounding);
}

TEST(Punctual, BadLightsAreInputErrorsNamingTheFileAndTheLight) {
  auto message = [](const PunctualLight& l) {
    try {
      validate_punctual_light(l, "scene.json", "lights[3] (light \"key\")");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  PunctualLight l = spot(Vector3d(0, 0, 1), Vector3d(0, 0, -1), 0.5, 0.3);
  EXPECT_NE(message(l).find("scene.json: lights[3] (light \"key\"): inner cone angle"), std::string::npos) << message(l);
  l.inner_cone = 0.1;
  EXPECT_EQ(message(l), "");
  l.outer_cone = 2;
  EXPECT_NE(message(l).find("outer cone angle must be in (0, pi/2]"), std::string::npos) << message(l);
  l.outer_cone = std::nan("");
  EXPECT_NE(message(l).find("outer cone angle"), std::string::npos) << message(l);
  l.outer_cone = 0.5;
  l.intensity[1] = -1;
  EXPECT_NE(message(l).find("intensity must be finite and >= 0, got -1"), std::string::npos) << message(l);
  l.intensity[1] = std::nan("");
  EXPECT_NE(message(l).find("intensity must be finite and >= 0, got nan"), std::string::npos) << message(l);
  l.intensity[1] = 1;
  l.position.x() = std::nan("");
  EXPECT_NE(message(l).find("position is not finite"), std::string::npos) << message(l);
  l.position.x() = 0;
  l.range = -1;
  EXPECT_NE(message(l).find("range must be finite and > 0, got -1"), std::string::npos) << message(l);
  l.range = std::numeric_limits<double>::infinity();
  EXPECT_NE(message(l).find("range must be finite"), std::string::npos) << message(l);
  PunctualLight d = directional(Vector3d(0, 0, -1));
  d.range = 10;
  EXPECT_NE(message(d).find("a directional light has no range"), std::string::npos) << message(d);
  d.range = 0;
  d.direction = Vector3d::Zero();
  EXPECT_NE(message(d).find("direction must be a finite non-zero vector"), std::string::npos) << message(d);
}

TEST(Punctual, ABulbAndASunDiscApproachTheirPunctualLimits) {
  const Mesh empty = prt::testing::grid(1, 0.0f);
  ShadePoint s;
  s.p = Vector3d(0.3, -0.2, 0);
  s.n = Vector3d(0, 0, 1);
  // A bulb of radius r at height 3: a sphere of radiance I/(πr²) gives E = I cos/d² exactly for an
  // unclipped sphere; the icosphere at 4 subdivisions is 0.12% smaller in area.
  PunctualLight p = point_light(Vector3d(0, 0, 3));
  p.intensity = {2, 2, 2};
  const AreaLight bulb = bulb_light(p, 0.05, 4);
  validate_light(bulb, "test", "bulb");
  const AreaLightIntegrator a({&bulb, 1}, empty, 0);
  std::vector<double> row(a.width());
  AreaLightIntegrator::Workspace ws;
  a.integrate(s, row, ws);
  const Vector3d to = p.position - s.p;
  const double point_e = to.z() / to.norm() / to.squaredNorm();
  EXPECT_NEAR(row[0] * bulb.radiance[0], 2 * point_e, 2 * point_e * 3e-3);
  EXPECT_LT(row[0] * bulb.radiance[0], 2 * point_e);
  // A 0.53-degree sun about the ball (0, 1) facing it at 30 degrees from the zenith: the receiver
  // at the centre gets E = intensity · cos 30° to the parallax bound (2^-19 relative) and the
  // cosine's variation over the disc (its angular radius squared, 2e-5).
  PunctualLight sun = directional(Vector3d(-0.5, 0, -std::sqrt(0.75)));
  sun.angular_diameter = 0.53 * std::numbers::pi / 180;
  sun.intensity = {3, 3, 3};
  const AreaLight disc = sun_light(sun, Vector3d::Zero(), 1);
  validate_light(disc, "test", "sun");
  const AreaLightIntegrator b({&disc, 1}, empty, 0);
  std::vector<double> srow(b.width());
  ShadePoint c;
  c.n = Vector3d(0, 0, 1);
  b.integrate(c, srow, ws);
  EXPECT_NEAR(srow[0] * disc.radiance[0], 3 * std::sqrt(0.75), 3 * 3e-5);
  c.n = -sun.direction;
  b.integrate(c, srow, ws);
  EXPECT_NEAR(srow[0] * disc.radiance[0], 3, 3 * 1e-12);
}

TEST(Punctual, TheRuntimesUnshadowedLightIsTheBakesWhereNothingShadows) {
  // prtshade/lights.h evaluates a light the bake did not see: where nothing occludes it gives the
  // baked E (the same formula, the same falloff), for every kind, at points all around the light.
  std::vector<PunctualLight> lights = {point_light(Vector3d(0.3, 2, -0.4)), point_light(Vector3d(0.3, 2, -0.4)),
                                       spot(Vector3d(-1, 3, 0.5), Vector3d(0.2, -1, 0.1), 0.25, 0.7),
                                       directional(Vector3d(-0.3, -1, 0.6))};
  lights[1].range = 3;  // the same bulb with KHR's range window
  const PunctualLightIntegrator integ(lights, nullptr, Vector3d::Zero(), 0);
  for (int k = 0; k < 64; ++k) {
    ShadePoint s;
    s.p = Vector3d(std::sin(k * 1.3) * 3, std::cos(k * 0.7), std::sin(k * 2.1) * 2);
    s.n = Vector3d(std::sin(k * 0.37), 1 + std::cos(k * 0.9), std::cos(k * 1.7)).normalized();
    const std::vector<double> row = row_of(integ, s);
    for (size_t l = 0; l < lights.size(); ++l) {
      prt::shade::PunctualLight r;
      r.kind = prt::shade::PunctualKind(int(lights[l].kind == PunctualKind::Directional ? 0 : lights[l].kind == PunctualKind::Point ? 1 : 2));
      r.position = {lights[l].position.x(), lights[l].position.y(), lights[l].position.z()};
      r.direction = {lights[l].direction.x(), lights[l].direction.y(), lights[l].direction.z()};
      r.inner_cone = lights[l].inner_cone;
      r.outer_cone = lights[l].outer_cone;
      r.range = lights[l].range;
      const double e = prt::shade::unshadowed_punctual(r, {s.p.x(), s.p.y(), s.p.z()}, {s.n.x(), s.n.y(), s.n.z()});
      EXPECT_NEAR(row[l], e, kRounding * std::max(1.0, e)) << k << " " << l;
    }
  }
}

} // namespace
