// Tests of the per-shade-point area-light integrals (bake/lights/area_bake.h): unoccluded lights equal
// Lambert's closed form; a one-sided light's back gives nothing and a two-sided one mirrors its
// front; a solid light is the sum of its faces facing the point; an occluder is subtracted as
// the visible-region library computes it; QMC ray casting agrees within 4 standard errors; a
// scene moved far from the origin (the mesh's frame) keeps its values.
#include <bake/lights/area_bake.h>
#include <bake/mesh/mesh.h>
#include <bake/sphere/sampling.h>
#include <bake/sphere/spherical_polygon.h>
#include <bake/visibility/visible_region.h>

#include <gtest/gtest.h>
#include <test_scenes.h>

#include <cmath>
#include <numbers>
#include <vector>

namespace {

using namespace prt::bake;
using Eigen::Vector3d;

ShadePoint at(Vector3d p, Vector3d n) {
  ShadePoint s;
  s.p = p;
  s.n = n.normalized();
  return s;
}

// A mesh with no triangles: nothing occludes.
Mesh nothing() { return prt::testing::grid(1, 0.0f); }

double irradiance_of(const AreaLightIntegrator& a, const ShadePoint& s, size_t light = 0) {
  std::vector<double> row(a.width());
  AreaLightIntegrator::Workspace ws;
  a.integrate(s, row, ws);
  return row[light * a.per_light()];
}

TEST(AreaBake, AnUnoccludedQuadIsLambertsClosedForm) {
  // The quad [−1, 1]² at height 2 facing down onto points below it; the closed form is the
  // horizon-clipped cosine integral of its corners (bake/sphere/spherical_polygon.h), to rounding.
  const AreaLight quad = make_quad_light(Vector3d(0, 0, 2), Vector3d(2, 0, 0), Vector3d(0, -2, 0));  // faces −z
  const Mesh empty = nothing();
  const AreaLightIntegrator a({&quad, 1}, empty, 3);
  EXPECT_EQ(a.width(), 10u);
  for (const ShadePoint& s : {at({0, 0, 0}, {0, 0, 1}), at({1.5, -0.3, 0}, {0.3, 0, 1}), at({2, 2, 1.5}, {-1, -1, 0.2})}) {
    // Counter-clockwise seen from p (the emitting side) is clockwise seen from outside the unit
    // sphere about p: reversed, the polygon is positively oriented for the library.
    std::vector<Vector3d> rel;
    for (auto v = quad.vertices.rbegin(); v != quad.vertices.rend(); ++v) rel.push_back(*v - s.p);
    const double exact = clipped_irradiance(rel, s.n);
    EXPECT_GT(exact, 0);
    EXPECT_NEAR(irradiance_of(a, s), exact, 1e-12 * std::max(1.0, exact)) << s.p.transpose();
  }
  // Straight under the centre of a square of half-side a = 1 at height h = 2, parallel: four
  // corner rectangles of the textbook form factor, F = E/π = (4/π) s atan(s), s = a/√(a² + h²).
  const double h = 2, s1 = 1 / std::sqrt(1 + h * h);
  const double f = 2 / std::numbers::pi * (2 * s1 * std::atan(s1));
  EXPECT_NEAR(irradiance_of(a, at({0, 0, 0}, {0, 0, 1})) / std::numbers::pi, f, 1e-12);
}

TEST(AreaBake, OneSidedLightsAreDarkFromBehindAndTwoSidedOnesMirror) {
  AreaLight quad = make_quad_light(Vector3d(0, 0, 2), Vector3d(2, 0, 0), Vector3d(0, -2, 0));  // faces −z
  const Mesh empty = nothing();
  const AreaLightIntegrator one({&quad, 1}, empty, 0);
  const ShadePoint below = at({0.3, 0.2, 0}, {0, 0.1, 1}), above = at({0.3, 0.2, 4}, {0, 0.1, -1});
  EXPECT_GT(irradiance_of(one, below), 0.1);
  EXPECT_EQ(irradiance_of(one, above), 0.0);
  quad.two_sided = true;
  const AreaLightIntegrator two({&quad, 1}, empty, 0);
  EXPECT_NEAR(irradiance_of(two, above), irradiance_of(one, below), 1e-14);  // the mirror image
  EXPECT_EQ(irradiance_of(two, at({5, 0, 2}, {-1, 0, 0})), 0.0);  // in its plane: no solid angle
}

TEST(AreaBake, ASolidLightIsItsSilhouettePolygon) {
  // A convex solid seen from outside covers exactly its silhouette polygon (bake/visibility/visible_region.h
  // ConvexPolyhedron): the sum over its faces facing p equals the polygon's clipped irradiance.
  const Mesh empty = nothing();
  for (const AreaLight& solid :
       {make_box_light(Vector3d(0.5, 0.2, 3), Vector3d(1, 2, 0.5), Eigen::Matrix3d::Identity()),
        make_sphere_light(Vector3d(-1, 0.5, 2.5), 0.7, 2), make_cylinder_light(Vector3d(0, 1, 2), 0.4, 1.5, 24, Eigen::Matrix3d::Identity())}) {
    const AreaLightIntegrator a({&solid, 1}, empty, 4);
    const ConvexPolyhedron body(solid.vertices, solid.faces);
    for (const ShadePoint& s : {at({0, 0, 0}, {0, 0, 1}), at({2, -1, 1}, {-0.5, 0.2, 1})}) {
      std::vector<Vector3d> sil;
      ASSERT_TRUE(body.silhouette(s.p, sil));
      const double exact = clipped_irradiance(sil, s.n);
      EXPECT_NEAR(irradiance_of(a, s), exact, 1e-12) << light_shape_name(solid.shape) << " " << s.p.transpose();
    }
  }
}

TEST(AreaBake, AnOccluderIsSubtractedAndRayCastingAgrees) {
  // A unit box between the ground point and the quad light hides part of it. Checked against
  // randomised QMC ray casting over the light's solid angle: 2^16 directions uniform in the
  // hemisphere, a direction counting n·ω·2π when it reaches the light's rectangle before the
  // box (an unbiased estimate of E; 4 standard errors from 32 independent replicates).
  const AreaLight quad = make_quad_light(Vector3d(0, 0, 3), Vector3d(3, 0, 0), Vector3d(0, -3, 0));
  const Mesh box = prt::testing::box({-0.25f, -0.5f, 1.0f}, {0.75f, 0.5f, 2.0f});
  const AreaLightIntegrator a({&quad, 1}, box, 0);
  const ShadePoint s = at({0.1, 0.05, 0}, {0, 0, 1});
  const double e = irradiance_of(a, s);
  const Mesh empty = nothing();
  const double unshadowed = irradiance_of(AreaLightIntegrator({&quad, 1}, empty, 0), s);
  EXPECT_LT(e, 0.9 * unshadowed);
  EXPECT_GT(e, 0.1 * unshadowed);
  auto hits_box = [&](const Vector3d& d) {  // slab test against the box
    double t0 = 0, t1 = 1e30;
    const Vector3d lo(-0.25, -0.5, 1.0), hi(0.75, 0.5, 2.0);
    for (int k = 0; k < 3; ++k) {
      if (d[k] == 0) {
        if (s.p[k] < lo[k] || s.p[k] > hi[k]) return false;
        continue;
      }
      double ta = (lo[k] - s.p[k]) / d[k], tb = (hi[k] - s.p[k]) / d[k];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta), t1 = std::min(t1, tb);
    }
    return t0 <= t1;
  };
  constexpr int kReplicates = 32, kPer = 2048;
  double sum = 0, sum2 = 0;
  for (int r = 0; r < kReplicates; ++r) {
    double est = 0;
    for (int i = 0; i < kPer; ++i) {
      const double u1 = to_unit(mix64(uint64_t(r) * 1000003u + uint64_t(i) * 2 + 1)),
                   u2 = to_unit(mix64(uint64_t(r) * 1000003u + uint64_t(i) * 2 + 2));
      const double z = u1, phi = 2 * std::numbers::pi * u2, rr = std::sqrt(std::max(0.0, 1 - z * z));
      const Vector3d d(rr * std::cos(phi), rr * std::sin(phi), z);  // uniform in the upper hemisphere
      const double t = (3 - s.p.z()) / d.z();
      const Vector3d q = s.p + t * d;
      if (std::abs(q.x()) <= 1.5 && std::abs(q.y()) <= 1.5 && !hits_box(d)) est += 2 * std::numbers::pi * z;
    }
    est /= kPer;
    sum += est, sum2 += est * est;
  }
  const double mean = sum / kReplicates, se = std::sqrt((sum2 / kReplicates - mean * mean) / (kReplicates - 1));
  EXPECT_LE(std::abs(e - mean), 4 * se) << "E " << e << " ray casting " << mean << " ± " << se;
}

TEST(AreaBake, FarFromTheOriginTheMeshFrameKeepsTheDigits) {
  // The same light, box and point moved by 10^5 along x, the mesh holding the offset in its
  // origin (positions relative to it, as bake/mesh/mesh.h ORIGIN): the same irradiance to 1e-12.
  const Vector3d far(1e5, 0, 0);
  const AreaLight quad = make_quad_light(Vector3d(0, 0, 3), Vector3d(3, 0, 0), Vector3d(0, -3, 0));
  AreaLight moved = quad;
  for (Vector3d& v : moved.vertices) v += far;
  const Mesh box = prt::testing::box({-0.25f, -0.5f, 1.0f}, {0.75f, 0.5f, 2.0f});
  Mesh box_far = box;
  box_far.origin = far;
  const ShadePoint s = at({0.1, 0.05, 0}, {0, 0, 1});  // in the mesh's frame either way
  const double near_e = irradiance_of(AreaLightIntegrator({&quad, 1}, box, 0), s);
  const double far_e = irradiance_of(AreaLightIntegrator({&moved, 1}, box_far, 0), s);
  EXPECT_NEAR(far_e, near_e, 1e-12);
}

} // namespace
