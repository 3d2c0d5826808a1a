// Spherical polygons (bake/sphere/spherical_polygon.h): Lambert's formula and the solid angle against
// independent closed forms (view-factor catalogue formulas, the solid angle of a rectangle on its
// axis, a regular polygon on its axis split into right triangles), tiny polygons, and RQMC
// references; horizon clipping with vertices exactly on the horizon and the exact horizon sign.
#include <bake/sphere/spherical_polygon.h>

#include <sphere_rqmc.h>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <numbers>
#include <random>
#include <vector>

namespace {

using prt::bake::clip_to_horizon;
using prt::bake::clipped_irradiance;
using prt::bake::cosine_integral;
using prt::bake::horizon_side;
using prt::bake::solid_angle;
using prt::bake::vector_irradiance;
using V3 = Eigen::Vector3d;
using Poly = std::vector<V3>;
constexpr double kPi = std::numbers::pi;

// Values are O(1) and every closed form here is a handful of correctly rounded operations, so
// 1e-12 leaves a margin of ~1000 ulps for the polygons' sums of atan2 terms.
constexpr double kExact = 1e-12;

// Regular N-gon at height h above the receiver on its axis, circumradius R, counter-clockwise
// seen from above (positive orientation for the receiver below), first vertex rotated by phase.
Poly regular_polygon(int n, double radius, double h, double phase = 0) {
  Poly p;
  for (int k = 0; k < n; ++k) {
    const double a = phase + 2 * kPi * k / n;
    p.emplace_back(radius * std::cos(a), radius * std::sin(a), h);
  }
  return p;
}

// Σ over the 2N right triangles (apex on the axis, right angle at an edge's midpoint) of the
// regular N-gon: each half edge of length t = r tan(π/N), at distance D = √(h² + r²) from the
// receiver (r = R cos(π/N) the inradius), subtends atan(t/D) in a plane whose normal makes
// cos = r/D with the axis, so ∫ cos dω = N (r/D) atan(t/D).
double regular_polygon_cosine(int n, double radius, double h) {
  const double r = radius * std::cos(kPi / n), d = std::hypot(h, r);
  return n * (r / d) * std::atan(r * std::tan(kPi / n) / d);
}


TEST(SphericalPolygon, ParallelRectangleFromCorner) {
  // View factor from a differential area to a parallel rectangle a × b at distance c, the normal
  // through one corner (Howell, "A Catalog of Radiation Heat Transfer Configuration Factors",
  // C-11): F = 1/(2π) [A/√(1+A²) atan(B/√(1+A²)) + B/√(1+B²) atan(A/√(1+B²))], A = a/c, B = b/c.
  for (auto [a, b, c] : {std::array{1.0, 1.0, 1.0}, {2.0, 0.5, 0.7}, {0.1, 3.0, 2.0}, {10.0, 10.0, 0.1}}) {
    const Poly rect{{0, 0, c}, {a, 0, c}, {a, b, c}, {0, b, c}};
    const double A = a / c, B = b / c;
    const double f = (A / std::sqrt(1 + A * A) * std::atan(B / std::sqrt(1 + A * A)) +
                      B / std::sqrt(1 + B * B) * std::atan(A / std::sqrt(1 + B * B))) / (2 * kPi);
    EXPECT_NEAR(cosine_integral(rect, V3::UnitZ()) / kPi, f, kExact) << a << " " << b << " " << c;
    EXPECT_NEAR(clipped_irradiance(rect, V3::UnitZ()) / kPi, f, kExact);
  }
}

TEST(SphericalPolygon, PerpendicularRectangleOnTheHorizon) {
  // Differential area to a rectangle in a perpendicular plane at distance d, width w along the
  // receiver's plane, height h, one edge on the receiver's plane, the receiver facing a corner
  // (Howell C-14): F = 1/(2π) [atan(1/Y) − Y/√(X²+Y²) atan(1/√(X²+Y²))], X = h/w, Y = d/w.
  // The bottom edge lies exactly on the horizon: clipping must keep the polygon as it is.
  for (auto [d, w, h] : {std::array{1.0, 1.0, 1.0}, {0.3, 2.0, 5.0}, {4.0, 0.5, 0.25}}) {
    const Poly rect{{d, 0, 0}, {d, w, 0}, {d, w, h}, {d, 0, h}};
    const double X = h / w, Y = d / w;
    const double f = (std::atan(1 / Y) - Y / std::hypot(X, Y) * std::atan(1 / std::hypot(X, Y))) / (2 * kPi);
    EXPECT_NEAR(cosine_integral(rect, V3::UnitZ()) / kPi, f, kExact);
    Poly clipped;
    clip_to_horizon(rect, V3::UnitZ(), clipped);
    EXPECT_EQ(clipped, rect);
  }
}

TEST(SphericalPolygon, RegularPolygonOnAxisAndTheDisc) {
  for (int n : {3, 4, 7, 64, 1000})
    for (auto [radius, h] : {std::array{1.0, 1.0}, {0.2, 3.0}, {5.0, 0.5}}) {
      const double expected = regular_polygon_cosine(n, radius, h);
      EXPECT_NEAR(cosine_integral(regular_polygon(n, radius, h, 0.3), V3::UnitZ()), expected, kExact) << n;
    }
  // A disc of angular radius α on the normal axis has ∫ cos = π sin²α; its inscribed and
  // circumscribed regular polygons bracket it (they contain / are contained in the disc).
  const double radius = 0.8, h = 0.6, n = 4096;
  const double disc = kPi * radius * radius / (radius * radius + h * h);
  const double inner = cosine_integral(regular_polygon(int(n), radius, h), V3::UnitZ());
  const double outer = cosine_integral(regular_polygon(int(n), radius / std::cos(kPi / n), h), V3::UnitZ());
  EXPECT_LT(inner, disc);
  EXPECT_GT(outer, disc);
  EXPECT_LT(outer - inner, 1e-5);  // the gap is O(1/N²): ≈ π sin²α · π²/N² · (1 + cos²α)… ≈ 4e-6 here
}

TEST(SphericalPolygon, SolidAngleOfRectangleOnItsAxis) {
  // Ω = 4 asin(ab / √((a² + 4d²)(b² + 4d²))) for an a × b rectangle at distance d on its axis.
  for (auto [a, b, d] : {std::array{1.0, 1.0, 1.0}, {2.0, 0.5, 0.3}, {100.0, 100.0, 1.0}, {0.01, 0.02, 1.0}}) {
    const Poly rect{{-a / 2, -b / 2, d}, {a / 2, -b / 2, d}, {a / 2, b / 2, d}, {-a / 2, b / 2, d}};
    const double expected = 4 * std::asin(a * b / std::sqrt((a * a + 4 * d * d) * (b * b + 4 * d * d)));
    EXPECT_NEAR(solid_angle(rect), expected, kExact);
    Poly reversed(rect.rbegin(), rect.rend());
    EXPECT_NEAR(solid_angle(reversed), -expected, kExact);
    EXPECT_NEAR(cosine_integral(reversed, V3::UnitZ()), -cosine_integral(rect, V3::UnitZ()), kExact);
  }
  // The whole upper hemisphere: three vertices on the horizon.
  EXPECT_NEAR(solid_angle(regular_polygon(3, 1, 0)), 2 * kPi, kExact);
  EXPECT_NEAR(cosine_integral(regular_polygon(3, 1, 0), V3::UnitZ()), kPi, kExact);
}

TEST(SphericalPolygon, TinyPolygonKeepsRelativeAccuracy) {
  // A square of side s = 1e-5 at distance 1 on the axis (Ω ≈ 1e-10), then the same square and
  // normal under random rotations (which perturb each vertex by ~u, i.e. relatively by u/s ≈
  // 1e-11 of its size). The closed forms here are well conditioned (asin and atan of small
  // arguments), so a relative tolerance of 1e-9 allows 100× the expected ~u/s error (measured
  // ≤ 9e-12); the textbook Lambert sum of O(s) edge terms is off by ~1e-8 here and would fail.
  const double s = 1e-5;
  const Poly square{{-s / 2, -s / 2, 1}, {s / 2, -s / 2, 1}, {s / 2, s / 2, 1}, {-s / 2, s / 2, 1}};
  const double omega = 4 * std::asin(s * s / (s * s + 4));
  const double cosine = regular_polygon_cosine(4, s / std::sqrt(2.0), 1);
  ASSERT_NEAR(omega, 1e-10, 1e-19);
  EXPECT_NEAR(solid_angle(square) / omega, 1, 1e-9);
  EXPECT_NEAR(cosine_integral(square, V3::UnitZ()) / cosine, 1, 1e-9);
  std::mt19937_64 rng(7);
  for (int k = 0; k < 20; ++k) {
    const Eigen::Matrix3d r = prt::test::random_rotation(rng);
    EXPECT_NEAR(solid_angle(prt::test::rotated(r, square)) / omega, 1, 1e-9);
    EXPECT_NEAR(cosine_integral(prt::test::rotated(r, square), r * V3::UnitZ()) / cosine, 1, 1e-9);
  }
}

TEST(SphericalPolygon, ChainsAdd) {
  // A quad is the sum of its two triangles: any four points for Lambert's vector (exact for
  // every chain), convex planar quads for the solid angle (its precondition: inside a
  // hemisphere). A non-convex (L-shaped) polygon is the sum of two rectangles. Each value is
  // O(1); 1e-13 covers a few ulps of each sum.
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int k = 0; k < 100; ++k) {
    const Poly q{{u(rng), u(rng), 2 + u(rng)}, {u(rng), u(rng), 2 + u(rng)}, {u(rng), u(rng), 2 + u(rng)},
                 {u(rng), u(rng), 2 + u(rng)}};
    const V3 n = V3(u(rng), u(rng), u(rng)).normalized();
    const Poly t0{q[0], q[1], q[2]}, t1{q[0], q[2], q[3]};
    EXPECT_NEAR(cosine_integral(q, n), cosine_integral(t0, n) + cosine_integral(t1, n), 1e-13);
    std::array<double, 4> angle{};
    for (double& a : angle) a = kPi * (1 + u(rng));
    std::sort(angle.begin(), angle.end());
    const V3 tilt(0.3 * u(rng), 0.3 * u(rng), 0);
    Poly c;
    for (double a : angle) c.push_back(V3(std::cos(a), std::sin(a), 2) + tilt * std::cos(a));
    const Poly c0{c[0], c[1], c[2]}, c1{c[0], c[2], c[3]};
    EXPECT_NEAR(solid_angle(c), solid_angle(c0) + solid_angle(c1), 1e-13);
  }
  const Poly ell{{0, 0, 1}, {2, 0, 1}, {2, 1, 1}, {1, 1, 1}, {1, 2, 1}, {0, 2, 1}};
  const Poly r0{{0, 0, 1}, {2, 0, 1}, {2, 1, 1}, {0, 1, 1}}, r1{{0, 1, 1}, {1, 1, 1}, {1, 2, 1}, {0, 2, 1}};
  EXPECT_NEAR(solid_angle(ell), solid_angle(r0) + solid_angle(r1), 1e-13);
  const V3 n = V3(0.3, -0.2, 1).normalized();
  EXPECT_NEAR(cosine_integral(ell, n), cosine_integral(r0, n) + cosine_integral(r1, n), 1e-13);
}

// Random convex planar polygons (a regular polygon of 3–8 vertices, scaled, rotated and moved
// in front of the receiver) against RQMC: 64 rotations × 2^11 points. Tolerance 4 standard
// errors plus 1e-12 for the closed form's rounding.
TEST(SphericalPolygon, AgreesWithRqmc) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  for (int k = 0; k < 12; ++k) {
    const int n = 3 + k % 6;
    const Eigen::Matrix3d r = prt::test::random_rotation(rng);
    const double radius = 0.3 + 2 * u(rng);
    const V3 offset(0.5 * u(rng), 0.5 * u(rng), 0.2 + u(rng));
    Poly p;
    for (const V3& v : regular_polygon(n, radius, 0)) p.push_back(r * v + offset);
    // Orient positively seen from the origin (the plane's normal through the first three points).
    if ((p[1] - p[0]).cross(p[2] - p[0]).dot(p[0]) < 0) std::reverse(p.begin(), p.end());
    const V3 normal = V3(u(rng) - 0.5, u(rng) - 0.5, 0.3).normalized();
    const auto est = prt::test::rqmc_sphere(3, 64, 1 << 11, 100 + k, [&](const V3& w, std::span<double> out) {
      const bool in = prt::test::inside_convex(p, w);
      out[0] = in;
      out[1] = in ? normal.dot(w) : 0;
      out[2] = in ? std::max(0.0, normal.dot(w)) : 0;
    });
    const double values[3] = {solid_angle(p), cosine_integral(p, normal), clipped_irradiance(p, normal)};
    for (int i = 0; i < 3; ++i)
      EXPECT_NEAR(values[i], est.mean[size_t(i)], 4 * est.std_error[size_t(i)] + 1e-12) << k << " " << i;
  }
}

TEST(HorizonClip, LightCrossingTheHorizon) {
  // A 2 × 2 square in the plane y = 1 centred on the horizon: the part above is two 1 × 1
  // rectangles perpendicular to the receiver, each facing a corner (Howell C-14, X = Y = 1).
  const Poly square{{-1, 1, -1}, {-1, 1, 1}, {1, 1, 1}, {1, 1, -1}};
  const double f = (std::atan(1.0) - std::atan(1 / std::sqrt(2.0)) / std::sqrt(2.0)) / (2 * kPi);
  const double e = clipped_irradiance(square, V3::UnitZ());
  EXPECT_NEAR(e, 2 * kPi * f, kExact);
  Poly clipped;
  clip_to_horizon(square, V3::UnitZ(), clipped);
  ASSERT_EQ(clipped.size(), 4u);
  for (const V3& v : clipped) EXPECT_GE(v.z(), 0.0);
  // The whole square is a chain: its cosine integral counts the lower half negatively.
  EXPECT_NEAR(cosine_integral(square, V3::UnitZ()), 0, kExact);
}

TEST(HorizonClip, WhollyBelowOrAbove) {
  const Poly below{{0, 1, -0.5}, {1, 1, -0.2}, {0, 2, -1}};
  Poly out{{9, 9, 9}};
  clip_to_horizon(below, V3::UnitZ(), out);
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(clipped_irradiance(below, V3::UnitZ()), 0.0);
  const Poly above{{0, 1, 0.5}, {1, 1, 0.2}, {0, 2, 1}};
  clip_to_horizon(above, V3::UnitZ(), out);
  EXPECT_EQ(out, above);
  EXPECT_EQ(clipped_irradiance(above, V3::UnitZ()), cosine_integral(above, V3::UnitZ()));
}

TEST(HorizonClip, VerticesExactlyOnTheHorizon) {
  // A non-axis-aligned horizon: for n = (x, y, z) the vectors (y, −x, 0), (z, 0, −x), (0, z, −y)
  // have n·v = 0 exactly (x·y − y·x: equal rounded products). Such vertices must be kept as they
  // are (one vertex or a whole edge on the horizon), never cut or duplicated.
  const V3 n = V3(0.3, 0.7, 0.2).normalized();
  const V3 on0(n.y(), -n.x(), 0), on1(n.z(), 0, -n.x()), on2(0, n.z(), -n.y());
  for (const V3& v : {on0, on1, on2}) ASSERT_EQ(horizon_side(n, v), 0);
  const V3 side = n.cross(on0);
  const V3 up = n + 0.5 * on0, up2 = n - 0.3 * on0 + 0.2 * side, down = -n + 0.5 * on0;
  Poly out;
  for (const Poly& p : {Poly{on0, up, up2}, Poly{up, on0, up2}, Poly{on0, on1, up}}) {
    clip_to_horizon(p, n, out);
    EXPECT_EQ(out, p);
  }
  for (const Poly& p : {Poly{on0, down, -n - 0.5 * on0 + 0.1 * side}, Poly{on1, on0, down}}) {
    clip_to_horizon(p, n, out);
    EXPECT_TRUE(out.empty());
    EXPECT_EQ(clipped_irradiance(p, n), 0.0);
  }
  // One vertex on the horizon, one above, one below: one crossing is added, the horizon vertex
  // is kept once. The crossing is on the horizon up to rounding (|n·x̂| of a few ulps).
  clip_to_horizon(Poly{on0, up, down}, n, out);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out[0], on0);
  EXPECT_EQ(out[1], up);
  EXPECT_LT(std::abs(n.dot(out[2].normalized())), 1e-15);
}

TEST(HorizonClip, ExactSign) {
  // n·v = a·(b + ulp(b)) − b·a = a·ulp(b) > 0 exactly; the rounded products are often equal, so
  // the floating-point sum says 0 (or worse). horizon_side must always say +1.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.1, 10);
  int naive_wrong = 0;
  for (int k = 0; k < 10000; ++k) {
    const double a = u(rng), b = u(rng), c = u(rng);
    const V3 n(a, b, c), v(std::nextafter(b, 1e9), -a, 0);
    EXPECT_EQ(horizon_side(n, v), 1);
    EXPECT_EQ(horizon_side(n, -v), -1);
    EXPECT_EQ(horizon_side(n, V3(b, -a, 0)), 0);
    naive_wrong += n.dot(v) <= 0;
  }
  EXPECT_GT(naive_wrong, 100);  // the case is a real one for plain floating point
}

} // namespace
