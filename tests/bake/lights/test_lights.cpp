// Tests of the area-light shapes (bake/lights/lights.h): each constructor gives a valid light with the
// area of its closed form and faces towards its emitting side, and validate_light refuses every
// kind of broken shape with a message naming the light.
#include <bake/core/error.h>
#include <bake/lights/lights.h>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

namespace {

using namespace prt::bake;
using Eigen::Vector3d;
constexpr double kPi = std::numbers::pi;

// The areas below are sums of a few products of doubles: equal to the closed form within a few
// ulps of the total (1e-12 relative leaves room for the sine and cosine roundings).
constexpr double kRel = 1e-12;

std::string refusal(const AreaLight& l) {
  try {
    validate_light(l, "scene.json", "lights[0]");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

Eigen::Matrix3d some_rotation() {
  return (Eigen::AngleAxisd(0.3, Vector3d::UnitZ()) * Eigen::AngleAxisd(-1.1, Vector3d::UnitY()) *
          Eigen::AngleAxisd(0.7, Vector3d::UnitX())).toRotationMatrix();
}

TEST(Lights, PlanarShapesHaveTheirAreaAndEmitTowardsTheirNormal) {
  const Vector3d c(1, 2, 3), u(2, 0, 0), v(0, 0.5, 0.5);
  const AreaLight q = make_quad_light(c, u, v);
  EXPECT_EQ(refusal(q), "");
  EXPECT_NEAR(q.area(), u.cross(v).norm(), kRel * u.cross(v).norm());
  EXPECT_NEAR(q.face_normal(0).dot(u.cross(v).normalized()), 1.0, 1e-15);

  for (int n : {3, 5, 64, 1024}) {
    const Vector3d normal = Vector3d(1, -2, 0.5).normalized();
    const AreaLight d = make_disc_light(c, normal, 0.25, n);
    EXPECT_EQ(refusal(d), "") << n;
    const double exact = 0.5 * n * 0.25 * 0.25 * std::sin(2 * kPi / n);  // the regular n-gon
    EXPECT_NEAR(d.area(), exact, kRel * exact) << n;
    EXPECT_NEAR(d.face_normal(0).dot(normal), 1.0, 1e-14) << n;
  }
}

TEST(Lights, SolidShapesAreClosedConvexOutwardAndHaveTheirArea) {
  const Vector3d c(-4, 1, 10), size(1, 2, 3);
  const Eigen::Matrix3d R = some_rotation();
  const AreaLight box = make_box_light(c, size, R);
  const double box_area = 2 * (1 * 2 + 2 * 3 + 3 * 1);
  const int N = 48;
  const double r = 0.3, h = 2;
  const AreaLight cyl = make_cylinder_light(c, r, h, N, R);
  const double cyl_area = 2 * (0.5 * N * r * r * std::sin(2 * kPi / N)) + N * (2 * r * std::sin(kPi / N)) * h;
  EXPECT_NEAR(box.area(), box_area, kRel * box_area);
  EXPECT_NEAR(cyl.area(), cyl_area, kRel * cyl_area);
  for (const AreaLight* l : {&box, &cyl}) {
    EXPECT_EQ(refusal(*l), "");
    for (size_t f = 0; f < l->faces.size(); ++f) {
      Vector3d centroid = Vector3d::Zero();
      for (uint32_t i : l->faces[f]) centroid += l->vertices[i];
      centroid /= double(l->faces[f].size());
      EXPECT_GT(l->face_normal(f).dot(centroid - c), 0) << light_shape_name(l->shape) << " face " << f;
    }
  }
  EXPECT_EQ(cyl.faces.size(), size_t(N + 2));
}

TEST(Lights, SpheresAreIcospheresWhoseAreaApproachesTheSpheres) {
  // The icosphere is inscribed: its area is below 4πr² and the gap shrinks ~4x per subdivision
  // (the chord deficit is quadratic in the edge length, which halves; 3.3x from the icosahedron,
  // whose edges are far from small).
  double gap_before = 1;
  for (int s = 0; s <= kMaxSphereSubdivisions; ++s) {
    const AreaLight l = make_sphere_light(Vector3d(0, 5, 0), 2, s);
    EXPECT_EQ(refusal(l), "") << s;
    EXPECT_EQ(l.faces.size(), size_t(20) << (2 * s));
    EXPECT_EQ(l.vertices.size(), size_t(10 * (1 << (2 * s)) + 2));  // Euler: V = F/2 + 2
    for (const Vector3d& p : l.vertices) EXPECT_NEAR((p - Vector3d(0, 5, 0)).norm(), 2.0, 1e-14);
    const double gap = 1 - l.area() / (4 * kPi * 4);
    EXPECT_GT(gap, 0) << s;
    if (s > 0) {
      EXPECT_GT(gap_before / gap, s == 1 ? 3.2 : 3.8) << s;
      EXPECT_LT(gap_before / gap, 4.2) << s;
    }
    gap_before = gap;
  }
  EXPECT_LT(gap_before, 2e-3);  // s = 4
}

TEST(Lights, BrokenShapesAreRefusedNamingTheLight) {
  const Vector3d c(0, 0, 0), u(1, 0, 0), v(0, 1, 0);
  auto expect_refused = [](const AreaLight& l, const std::string& part) {
    const std::string m = refusal(l);
    EXPECT_NE(m.find("scene.json: lights[0]: "), std::string::npos) << m;
    EXPECT_NE(m.find(part), std::string::npos) << m;
  };
  AreaLight q = make_quad_light(c, u, v);
  q.radiance = {1, -1, 1};
  expect_refused(q, "radiance must be finite and >= 0");
  q = make_quad_light(c, u, v);
  q.vertices[2].z() = 1e-4;  // a fold of 1e-4 against the tolerance 1.4e-6
  expect_refused(q, "not planar");
  q = make_quad_light(c, u, v);
  q.vertices[1] = q.vertices[0];
  expect_refused(q, "repeated vertex");
  q = make_quad_light(c, u, v);
  q.vertices[3].x() = std::nan("");
  expect_refused(q, "not finite");
  // A pentagram turns left at every corner but is not convex.
  std::vector<Vector3d> star;
  for (int k = 0; k < 5; ++k) star.emplace_back(std::cos(2 * kPi * 2 * k / 5), std::sin(2 * kPi * 2 * k / 5), 0);
  expect_refused(make_polygon_light(star), "not convex");
  // An arrowhead: a reflex corner.
  expect_refused(make_polygon_light({Vector3d(0, 0, 0), Vector3d(2, 1, 0), Vector3d(0, 2, 0), Vector3d(0.5, 1, 0)}),
                 "not convex");
  AreaLight box = make_box_light(c, Vector3d(1, 1, 1), Eigen::Matrix3d::Identity());
  box.two_sided = true;
  expect_refused(box, "two_sided is for planar lights");
  box = make_box_light(c, Vector3d(1, 1, 1), Eigen::Matrix3d::Identity());
  std::reverse(box.faces[3].begin(), box.faces[3].end());  // one face inward
  expect_refused(box, "lies in front of it");
  box = make_box_light(c, Vector3d(1, 1, 1), Eigen::Matrix3d::Identity());
  box.faces.pop_back();  // open
  expect_refused(box, "not closed");
  // A closed octahedron of triangles (always planar) whose top apex is pushed inside: not convex.
  AreaLight oct;
  oct.shape = LightShape::Sphere;
  oct.vertices = {Vector3d(1, 0, 0), Vector3d(0, 1, 0), Vector3d(-1, 0, 0), Vector3d(0, -1, 0), Vector3d(0, 0, -0.5), Vector3d(0, 0, -1)};
  oct.faces = {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}, {1, 0, 5}, {2, 1, 5}, {3, 2, 5}, {0, 3, 5}};
  expect_refused(oct, "not convex");
}

TEST(Lights, FloatRoundedVerticesPass) {
  // A quad of size ~1 at 2000 units from the origin, rounded to float: off its plane by 2.8e-6
  // (float's spacing there is 1.2e-4), beyond 1e-6 of its size but inside the rounding allowance.
  // A fold of 1e-2 there (its vertices then lie ~2.5e-3 from their plane, against a tolerance of
  // 4.8e-4) is still refused.
  AreaLight q = make_quad_light(Vector3d(1000.1, 2000.3, -500.7), Vector3d(0.7, 0.2, 0.1), Vector3d(-0.1, 0.3, 0.1));
  for (Vector3d& p : q.vertices) p = p.cast<float>().cast<double>();
  EXPECT_EQ(refusal(q), "");
  q.vertices[2] += 1e-2 * q.face_normal(0);
  EXPECT_NE(refusal(q).find("not planar"), std::string::npos);
}

} // namespace
