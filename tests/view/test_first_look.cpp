// view/: what prtview's first look is made of — the framing rule (focus_box: the geometry
// without its large flat parts) and the exposure fixed by the environment (environment_exposure).
// The labels of its panels: test_text.cpp.
#include <view/camera.h>
#include <view/exposure.h>
#include <view/image.h>

#include <bake/environment/envmap.h>
#include <bake/environment/irradiance.h>

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

using namespace prt::view;
using Eigen::Vector3d;

namespace {

const std::string kData = PRT_DATA_DIR;

// A mesh under construction: flat positions [V][3] and triangles [T][3].
struct Soup {
  std::vector<double> p;
  std::vector<uint32_t> t;
  uint32_t vertex(double x, double y, double z) {
    p.insert(p.end(), {x, y, z});
    return uint32_t(p.size() / 3 - 1);
  }
  // An n × n grid of quads over [x0, x0 + size] × [z0, z0 + size] at height y.
  void grid(double x0, double z0, double size, double y, int n) {
    const uint32_t base = uint32_t(p.size() / 3);
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) vertex(x0 + size * i / n, y, z0 + size * j / n);
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const uint32_t a = base + uint32_t(j * (n + 1) + i), b = a + 1, c = a + uint32_t(n) + 2, d = a + uint32_t(n) + 1;
        t.insert(t.end(), {a, d, c, a, c, b});
      }
  }
  // A closed box [lo, hi] (own vertices per face, as a mesh with per-face normals stores it).
  void box(Vector3d lo, Vector3d hi) {
    const auto corner = [&](int k) { return Vector3d(k & 1 ? hi.x() : lo.x(), k & 2 ? hi.y() : lo.y(), k & 4 ? hi.z() : lo.z()); };
    const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const auto& f : faces) {
      uint32_t v[4];
      for (int k = 0; k < 4; ++k) v[k] = vertex(corner(f[k]).x(), corner(f[k]).y(), corner(f[k]).z());
      t.insert(t.end(), {v[0], v[1], v[2], v[0], v[2], v[3]});
    }
  }
};

} // namespace

TEST(FocusBox, AGroundMuchWiderThanTheObjectOnItIsSetAside) {
  // The default scene's proportions: a 30-wide ground grid (48 x 48 quads) under an object 6
  // wide: the ground's diagonal (42.4) is 4x the box's (10.4), far past 1.5x: the box is framed.
  Soup s;
  s.grid(-15, -15, 30, 0, 48);
  s.box({-3, 0, -2}, {3, 7, 2});
  const Focus f = focus_box(s.p, s.t);
  EXPECT_EQ(f.set_aside_parts, 1u);
  EXPECT_EQ(f.set_aside_triangles, size_t(2 * 48 * 48));
  EXPECT_NEAR(f.set_aside_extent, 30 * std::sqrt(2.0), 1e-12);
  EXPECT_EQ(f.lo, Vector3d(-3, 0, -2));
  EXPECT_EQ(f.hi, Vector3d(3, 7, 2));
}

TEST(FocusBox, NothingIsSetAsideWhenNoFlatPartDominates) {
  // A plane alone (nothing else to frame), a box alone (six faces, each narrower than the other
  // five together), and a ground only 1.3x as wide as the box on it: the whole box is framed.
  Soup plane;
  plane.grid(-2, -2, 4, 0, 4);
  Focus f = focus_box(plane.p, plane.t);
  EXPECT_EQ(f.set_aside_parts, 0u);
  EXPECT_EQ(f.lo, Vector3d(-2, 0, -2));
  EXPECT_EQ(f.hi, Vector3d(2, 0, 2));
  Soup box;
  box.box({0, 0, 0}, {1, 2, 3});
  f = focus_box(box.p, box.t);
  EXPECT_EQ(f.set_aside_parts, 0u);
  EXPECT_EQ(f.hi, Vector3d(1, 2, 3));
  Soup small;
  small.grid(-5, -5, 10, 0, 4);  // diagonal 14.1
  small.box({-4, 0, -4}, {4, 6, 4});  // diagonal 12.8: 14.1 < 1.5 x 12.8
  f = focus_box(small.p, small.t);
  EXPECT_EQ(f.set_aside_parts, 0u);
  EXPECT_EQ(f.lo, Vector3d(-5, 0, -5));
}

TEST(FocusBox, AGroundThenARugOnItAreSetAsideAndRowsOfOnePositionJoin) {
  // A ground 40 wide, a rug 10 wide lying on it (y = 0.01) and a 2-unit box on the rug: the
  // ground is set aside first (56.6 wide against the rug and box, 14.3), then the rug (14.1
  // against the box alone, 3.5). The ground's rows are duplicated (each triangle its own three
  // rows, as a file with split normals): positions, not rows, join triangles.
  Soup s;
  for (int j = 0; j < 8; ++j)
    for (int i = 0; i < 8; ++i) {
      const double x = -20 + 5 * i, z = -20 + 5 * j;
      const uint32_t a = s.vertex(x, 0, z), b = s.vertex(x + 5, 0, z), c = s.vertex(x + 5, 0, z + 5);
      const uint32_t d = s.vertex(x, 0, z), e = s.vertex(x + 5, 0, z + 5), g = s.vertex(x, 0, z + 5);
      s.t.insert(s.t.end(), {a, b, c, d, e, g});
    }
  const uint32_t r0 = s.vertex(-5, 0.01, -5), r1 = s.vertex(5, 0.01, -5), r2 = s.vertex(5, 0.01, 5), r3 = s.vertex(-5, 0.01, 5);
  s.t.insert(s.t.end(), {r0, r2, r1, r0, r3, r2});
  s.box({-1, 0, -1}, {1, 2, 1});
  const Focus f = focus_box(s.p, s.t);
  EXPECT_EQ(f.set_aside_parts, 2u);
  EXPECT_EQ(f.set_aside_triangles, size_t(128 + 2));
  EXPECT_NEAR(f.set_aside_extent, 40 * std::sqrt(2.0), 1e-12);
  EXPECT_EQ(f.lo, Vector3d(-1, 0, -1));
  EXPECT_EQ(f.hi, Vector3d(1, 2, 1));
}

TEST(EnvironmentExposure, AConstantSkyOfRadianceLGivesOneOverL) {
  // E_unocc(n) = π L for every n: B = L, exposure 1/L (a white sky: 1).
  const EnvironmentExposure white = environment_exposure(prt::bake::EnvMap::constant({1, 1, 1}));
  EXPECT_DOUBLE_EQ(white.brightest, 1.0);
  EXPECT_EQ(white.exposure, 1.0);
  const EnvironmentExposure grey = environment_exposure(prt::bake::EnvMap::constant({4, 4, 4}));
  EXPECT_NEAR(grey.brightest, 4.0, 4e-15);
  EXPECT_EQ(grey.exposure, 0.25);
  EXPECT_EQ(round_significant(1.0 / 3.0, 4), 0.3333);
  EXPECT_EQ(round_significant(1361.49, 4), 1361.0);
}

TEST(EnvironmentExposure, IsTheBrightestUnshadowedWhiteSurfaceOfARealSky) {
  // sunset.exr has a sun: the brightest normal faces it. The search's B is a value of
  // E_unocc/π at one normal, so it cannot exceed the true maximum; it must reach the maximum
  // over 5,000 normals (a lattice 2.9° apart, 4.5x finer than the search's own) to 1e-3: the
  // peak of a clamped-cosine blur falls as cos θ at worst (a point sun), and the nearest lattice
  // normal is within 1.7° of any direction: 1 − cos 1.7° = 4.4e-4. Same bits every call.
  const prt::bake::EnvMap env = prt::bake::EnvMap::load(kData + "/sunset.exr", prt::bake::UpAxis::Y);
  const EnvironmentExposure e = environment_exposure(env);
  const prt::bake::UnshadowedIrradiance irradiance(env);
  double fine = 0;
  constexpr int N = 5000;
  for (int i = 0; i < N; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / N, r = std::sqrt(1 - z * z), phi = i * std::numbers::pi * (3 - std::sqrt(5.0));
    fine = std::max(fine, prt::bake::luminance(irradiance(Vector3d(r * std::cos(phi), z, r * std::sin(phi)))) / std::numbers::pi);
  }
  EXPECT_GE(e.brightest, fine * (1 - 1e-3));
  EXPECT_LE(e.brightest, prt::bake::luminance(irradiance(e.normal)) / std::numbers::pi);
  EXPECT_EQ(e.exposure, round_significant(1 / e.brightest, 4));
  const EnvironmentExposure again = environment_exposure(env);
  EXPECT_EQ(again.exposure, e.exposure);
  EXPECT_EQ(again.brightest, e.brightest);
}
