// FIV products (bake/bake/fiv.h, paper 004 §3–4.2) against quadrature, QMC and closed forms.
#include <bake/bake/fiv.h>
#include <bake/bake/scene.h>
#include <bake/core/error.h>
#include <bake/environment/envmap.h>
#include <bake/integrators/qmc.h>
#include <bake/mesh/mesh.h>
#include <bake/sphere/spherical_polygon.h>
#include <prtshade/fiv.h>
#include <prtshade/sh.h>

#include <Imath/half.h>
#include <gtest/gtest.h>
#include <test_scenes.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <random>

using namespace prt::bake;
using prt::testing::box;
using Eigen::Vector3d;
using Eigen::Vector3f;
using std::numbers::pi;

namespace {

// 64×32 map: a dim sky gradient plus a 3×2-texel sun ~2000× brighter.
EnvMap test_env() {
  const int W = 64, H = 32;
  std::vector<float> rgb(size_t(W * H * 3));
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      for (int c = 0; c < 3; ++c) rgb[size_t(3 * (y * W + x) + c)] = 0.2f + 0.5f * float(H - y) / H + 0.1f * float(c);
  for (int y = 9; y <= 10; ++y)
    for (int x = 40; x <= 42; ++x)
      for (int c = 0; c < 3; ++c) rgb[size_t(3 * (y * W + x) + c)] = 2000.f - 300.f * float(c);
  return EnvMap::from_latlong(W, H, rgb, UpAxis::Y, "test-sun");
}

// Quadrature of g(ω) L(ω) over the sphere on an n × n grid in (φ, y): rows are circles of
// latitude, so texel boundaries in latitude are cut at most once per row.
template <class G>
std::array<double, 3> quad(const EnvMap& env, G g, int n = 2048) {
  std::array<double, 3> s{};
  for (int j = 0; j < n; ++j) {
    const double y = -1 + (j + 0.5) * 2.0 / n, r = std::sqrt(1 - y * y);
    for (int i = 0; i < n; ++i) {
      const double ph = (i + 0.5) * 2 * pi / n;
      const Vector3d d(r * std::cos(ph), y, r * std::sin(ph));
      const double w = g(d) * (2.0 / n) * (2 * pi / n);
      if (w == 0) continue;
      const Rgb L = env.radiance(d);
      s[0] += L.r * w;
      s[1] += L.g * w;
      s[2] += L.b * w;
    }
  }
  return s;
}


} // namespace

TEST(Fiv, ShellDirectionConvention) {
  EXPECT_NEAR((shell_direction(0, 65, 17, 128) - Vector3d(0, 1, 0)).norm(), 0, 1e-15);   // θ = 0: +Y
  EXPECT_NEAR((shell_direction(64, 65, 5, 128) - Vector3d(0, -1, 0)).norm(), 0, 1e-15);  // θ = π: −Y
  EXPECT_NEAR((shell_direction(32, 65, 0, 128) - Vector3d(0, 0, 1)).norm(), 0, 1e-15);   // φ = 0: +Z
  EXPECT_NEAR((shell_direction(32, 65, 32, 128) - Vector3d(1, 0, 0)).norm(), 0, 1e-15);  // φ = π/2: +X
}

// Exact ∫_texel ω dω of lat-long texel (x, y) in OpenEXR's convention: centre longitude
// π − 2πx/(W−1), latitude π/2 − πy/(H−1), half-texels at the seam and the poles; direction
// (cos λ sin φ, sin λ, cos λ cos φ).
Vector3d latlong_texel_moment(int x, int y, int W, int H) {
  const double dphi = 2 * pi / (W - 1), dlat = pi / (H - 1);
  const double pc = pi - dphi * x, lc = pi / 2 - dlat * y;
  const double p0 = std::max(-pi, pc - dphi / 2), p1 = std::min(pi, pc + dphi / 2);
  const double l0 = std::max(-pi / 2, lc - dlat / 2), l1 = std::min(pi / 2, lc + dlat / 2);
  const double cos2 = (l1 / 2 + std::sin(2 * l1) / 4) - (l0 / 2 + std::sin(2 * l0) / 4);
  const double sincos = (std::sin(l1) * std::sin(l1) - std::sin(l0) * std::sin(l0)) / 2;
  return {cos2 * (std::cos(p0) - std::cos(p1)), sincos * (p1 - p0), cos2 * (std::sin(p1) - std::sin(p0))};
}

TEST(Fiv, EnvironmentFivMatchesExactTexelMoments) {
  const EnvMap env = test_env();
  const int W = 64, H = 32;
  double exact[9] = {};
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const Vector3d m = latlong_texel_moment(x, y, W, H);
      const Rgb L = env.texel_value(y * W + x);
      const double c[3] = {L.r, L.g, L.b};
      for (int ch = 0; ch < 3; ++ch)
        for (int a = 0; a < 3; ++a) exact[3 * ch + a] += c[ch] * m[a];
    }
  const Fiv f = environment_fiv(env);
  double scale = 0;
  for (double e : exact) scale = std::max(scale, std::abs(e));
  // 4×4 midpoint sub-samples per texel: O((h/4)²) ≈ 4e-5 of each texel's moment.
  for (int k = 0; k < 9; ++k) EXPECT_NEAR(f[size_t(k)], exact[k], 1e-4 * scale) << k;
  const Fiv zero = environment_fiv(EnvMap::constant({1, 1, 1}));
  for (double x : zero) EXPECT_EQ(x, 0.0);
}

TEST(Fiv, IrradianceCubeIsExactNotSh9) {
  // A smooth environment (no sun): the (φ, y) quadrature is accurate to ~1e-4 here.
  std::vector<float> rgb(size_t(64 * 32 * 3));
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x)
      for (int c = 0; c < 3; ++c)
        rgb[size_t(3 * (y * 64 + x) + c)] = 0.3f + 0.6f * float(32 - y) / 32 + 0.2f * float(c) * float(x) / 64;
  const EnvMap env = EnvMap::from_latlong(64, 32, rgb, UpAxis::Y, "sky");
  const int S = 4;
  const auto cube = irradiance_cube(env, S);
  ASSERT_EQ(cube.size(), size_t(6 * S * S * 3));
  for (int face = 0; face < 6; ++face) {
    const int row = (face * 3) % S, col = (face * 5 + 1) % S;
    const Vector3d n = gl_cube_direction(face, row, col, S);
    const auto q = quad(env, [&](const Vector3d& d) { return std::max(0.0, n.dot(d)); });
    for (int c = 0; c < 3; ++c) {
      const float e = cube[size_t(((face * S + row) * S + col) * 3 + c)];
      EXPECT_NEAR(e, q[size_t(c)], 2e-3 * q[size_t(c)]) << face << " " << c;
    }
  }
  // White furnace: E = π for every normal.
  for (float e : irradiance_cube(EnvMap::constant({1, 1, 1}), 2)) EXPECT_NEAR(e, pi, 1e-6);
}

TEST(Fiv, IrradianceCubeCellsEqualTheTexelByTexelReference) {
  // The cell hierarchy only regroups a sum (cells wholly above a horizon add their texels'
  // moments at once): on a real HDR map with a sun the two agree to float rounding of the
  // output (a few ulps; the doubles differ only by summation order).
  const EnvMap env = EnvMap::load(std::string(PRT_DATA_DIR) + "/sunset.exr", UpAxis::Y);
  const auto fast = irradiance_cube(env, 6), slow = irradiance_cube_reference(env, 6);
  ASSERT_EQ(fast.size(), slow.size());
  for (size_t i = 0; i < fast.size(); ++i) EXPECT_NEAR(fast[i], slow[i], 4e-7 * std::abs(slow[i])) << i;
}

TEST(Fiv, OccludedFivMatchesQmcFullSphere) {
  const EnvMap env = test_env();
  const Mesh m = load_mesh(std::string(PRT_DATA_DIR) + "/bunny.obj", {.use_file_normals = false});
  const Topology topo = build_topology(m);
  ProductRequest req;
  req.radiance = &env;
  req.visibility_order = 1;
  const SilhouetteIntegrator sil(m, topo, req, {256, 1});
  const QmcIntegrator qmc(m, topo, req, {262144, 5});
  const Fiv fenv = environment_fiv(env);
  Vector3d c;
  double R;
  bounding_sphere(m, c, R);
  for (const Vector3d& off : {Vector3d(1.3, 0.2, 0.1), Vector3d(-0.4, 1.1, 0.9), Vector3d(0.2, -1.05, 0.3)}) {
    const Vector3d p = c + R * off;
    const Fiv f = occluded_fiv(sil, p);
    Fiv se;
    const Fiv fq = qmc_occluded_fiv(qmc, fenv, p, 0, &se);
    for (int ch = 0; ch < 3; ++ch) {
      const double scale = std::abs(fenv[size_t(3 * ch)]) + std::abs(fenv[size_t(3 * ch + 1)]) + std::abs(fenv[size_t(3 * ch + 2)]);
      for (int a = 0; a < 3; ++a) {
        const size_t k = size_t(3 * ch + a);
        // 4 standard errors of QMC plus the silhouette's discretisation at k = 256² (2e-3 of |F^env|).
        EXPECT_NEAR(f[k], fq[k], 4 * se[k] + 2e-3 * scale) << "offset " << off.transpose() << " c" << ch << " a" << a;
      }
    }
  }
}

TEST(Fiv, ConeIsTheBoxsSolidAngleAndMomentInClosedForm) {
  // The cone (m, Ω) of the tight proxy (bake/bake/fiv.h) of a box seen from outside: its front
  // faces tile the occluded set, so Ω = Σ Ω(face) and m = Σ Φ(face) over the faces seen from
  // their front, each a spherical quad (bake/sphere/spherical_polygon.h, exact). The silhouette
  // integral at k = 256 isolines discretises the boundary within cells of ~π/256: 2e-3 of 4π
  // for Ω and of π for each component of m (the FIV test's 2e-3 of its scale above).
  const EnvMap env = test_env();
  const Mesh m = box({-1, -0.5f, -0.25f}, {1, 0.5f, 0.25f});
  const Topology topo = build_topology(m);
  ProductRequest req;
  req.radiance = &env;
  req.visibility_order = 2;
  const SilhouetteIntegrator sil(m, topo, req, {256, 1});
  const Vector3d lo(-1, -0.5, -0.25), hi(1, 0.5, 0.25);
  for (const Vector3d& p : {Vector3d(2.5, 0.3, 0.4), Vector3d(-0.3, 1.7, -1.2), Vector3d(0.1, -0.2, 3.0)}) {
    Cone cone{};
    bool inside = true;
    (void)occluded_fiv(sil, p, &inside, &cone);
    EXPECT_FALSE(inside);
    double omega = 0;
    Vector3d moment(0, 0, 0);
    for (int axis = 0; axis < 3; ++axis)
      for (int side = 0; side < 2; ++side) {
        const double plane = side ? hi[axis] : lo[axis];
        if ((side ? p[axis] - plane : plane - p[axis]) <= 0) continue;  // seen from behind
        const int u = (axis + 1) % 3, v = (axis + 2) % 3;
        std::vector<Vector3d> quad;
        for (const auto& [a, b] : {std::pair{0, 0}, std::pair{1, 0}, std::pair{1, 1}, std::pair{0, 1}}) {
          Vector3d corner;
          corner[axis] = plane, corner[u] = a ? hi[u] : lo[u], corner[v] = b ? hi[v] : lo[v];
          quad.push_back((corner - p).normalized());
        }
        double w = solid_angle(quad);
        Vector3d phi = vector_irradiance(quad);
        if (w < 0) w = -w, phi = -phi;  // the corners' order decides the sign
        omega += w;
        moment += phi;
      }
    EXPECT_NEAR(cone[3], omega, 2e-3 * 4 * std::numbers::pi) << p.transpose();
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(cone[size_t(a)], moment[a], 2e-3 * std::numbers::pi) << p.transpose() << " " << a;
    EXPECT_GT(omega, 0.1);
  }
}

TEST(Fiv, InsideClosedGeometryIsInvalidAndFullyOccluded) {
  const EnvMap env = test_env();
  const Mesh m = box({-1, -1, -1}, {1, 1, 1});
  const Topology topo = build_topology(m);
  ProductRequest req;
  req.radiance = &env;
  req.visibility_order = 1;
  const SilhouetteIntegrator sil(m, topo, req, {64, 1});
  bool inside = false;
  const Fiv f = occluded_fiv(sil, Vector3d(0.1, 0.2, -0.3), &inside);
  EXPECT_TRUE(inside);
  std::vector<double> all(10);
  sil.unoccluded(all);
  for (int c = 0; c < 3; ++c) {
    const double expect[3] = {-all[1 + size_t(3 * c + 2)] / 0.48860251190291992159, -all[1 + size_t(3 * c)] / 0.48860251190291992159,
                              all[1 + size_t(3 * c + 1)] / 0.48860251190291992159};
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(f[size_t(3 * c + a)], expect[a], 1e-12 * (1 + std::abs(expect[a])));
  }
  occluded_fiv(sil, Vector3d(3, 0.2, 0.1), &inside);
  EXPECT_FALSE(inside);
}

namespace {
// A thin 2 × 0.02 × 2 plate (R = 1.4143) under a uniform grey sky, an 8x5x12 grid, fraction 0.02.
struct PlateUnderGreySky {
  EnvMap env = EnvMap::from_latlong(16, 8, std::vector<float>(16 * 8 * 3, 1.0f), UpAxis::Y, "grey");
  Mesh m = box({-1, -0.01f, -1}, {1, 0.01f, 1});
  Topology topo = build_topology(m);
  ShellSpec spec = [] {
    ShellSpec s;
    s.n_phi = 8;
    s.n_theta = 5;
    s.n_rho = 12;
    s.silhouette_k = 64 * 64;  // 64 u-isolines
    s.fraction = 0.02;
    s.radial = RadialScheme::geometric;  // paper 004's spheres (FivSurface tests: the surface scheme)
    return s;
  }();
};
} // namespace

TEST(Fiv, ShellsHaveTheGridTheRadiiAndStopWhenFar) {
  // The plate: radii run geometrically from 0.707 to R / (2√0.02) = 5.0 over 12 shells (… 2.94,
  // 3.51, 4.19, 5.0). Face-on, the plate subtends Ω = 4 atan(1 / (ρ √(2 + ρ²))) and |F| ≈ Ω of
  // ∫ L = 4π: 0.0237 at ρ = 3.51 (go on), 0.0170 at ρ = 4.19 (stop) — 11 shells.
  const PlateUnderGreySky p;
  const FivShells s = bake_fiv_shells(p.m, p.topo, p.env, p.spec);
  EXPECT_NEAR(s.radius, std::sqrt(2.0001), 1e-6);
  ASSERT_EQ(s.radii.size(), 11u) << "stops at the first shell below the fraction";
  for (size_t k = 1; k < s.radii.size(); ++k) EXPECT_GT(s.radii[k], s.radii[k - 1]);
  EXPECT_NEAR(s.radii[0], 0.5 * s.radius, 1e-9);
  ASSERT_EQ(s.values.size(), s.radii.size() * 5 * 8 * 9);
  ASSERT_EQ(s.valid.size(), s.radii.size() * 5 * 8);
  // First shell (ρ = 0.707): the equator row θ = π/2 lies inside the plate (|y| = 0 < 0.01).
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 8; ++j) EXPECT_EQ(s.valid[size_t(i * 8 + j)], i == 2 ? 0 : 1) << i << " " << j;
  for (float x : s.values) EXPECT_TRUE(std::isfinite(x));
}

// A merge's FivShellRows (the mesh and the spec only: no environment, no integrator) has the
// integrating one's frame, radii and stopping rule, and appends the same shells from its rows.
TEST(Fiv, FrameOnlyShellRowsAgreeWithTheIntegratingOnes) {
 for (const RadialScheme scheme : {RadialScheme::geometric, RadialScheme::surface}) {
  PlateUnderGreySky p;
  p.spec.radial = scheme;
  const FivShellRows baker(p.m, p.topo, p.env, p.spec), frame(p.m, p.spec);
  ASSERT_EQ(frame.shell_count(), baker.shell_count());
  ASSERT_EQ(frame.rows_per_shell(), baker.rows_per_shell());
  FivShells a = baker.empty_shells(), b = frame.empty_shells();
  EXPECT_EQ(a.centre, b.centre);
  EXPECT_EQ(a.radius, b.radius);
  for (int k = 0; k < baker.shell_count(); ++k) {
    EXPECT_EQ(frame.radius(k), baker.radius(k));
    const std::vector<double> rows = baker.rows(k, 0, baker.rows_per_shell());
    baker.append(a, k, rows);
    frame.append(b, k, rows);
    ASSERT_EQ(frame.stops_after(k, rows), baker.stops_after(k, rows)) << "shell " << k;
    if (baker.stops_after(k, rows)) break;
  }
  baker.finish(a), frame.finish(b);  // the extrapolation and the rounding to float16 (ShellSpec::float16)
  const FivShells whole = bake_fiv_shells(p.m, p.topo, p.env, p.spec);
  EXPECT_EQ(b.radii, whole.radii);
  EXPECT_EQ(b.values, whole.values);
  EXPECT_EQ(b.valid, whole.valid);
  EXPECT_EQ(a.values, whole.values);
  EXPECT_EQ(b.surface_radius, whole.surface_radius);
  EXPECT_EQ(b.surface_radius.empty(), scheme == RadialScheme::geometric);
  EXPECT_THROW((void)frame.rows(0, 0, 1), ContractError);  // nothing to integrate with
 }
}

// ---- Surface-following shells (RadialScheme::surface, issue 33) --------------------------------

// r_surf of a box [−1, 1]³ from its centre: the ray along d leaves it at t = 1 / max_a |d_a|.
TEST(FivSurface, SurfaceRadiiOfABoxAreExact) {
  const Mesh m = box({-1, -1, -1}, {1, 1, 1});
  const std::vector<double> r = surface_radii(m, Vector3d::Zero(), std::sqrt(3.0), 9, 16);
  ASSERT_EQ(r.size(), 9u * 16u);
  for (int i = 0; i < 9; ++i)
    for (int j = 0; j < 16; ++j) {
      const Vector3d d = shell_direction(i, 9, j, 16);
      // The hit is recomputed in double: a few ulps of the 2R + 1 = 4.5 the ray starts from.
      EXPECT_NEAR(r[size_t(i * 16 + j)], 1 / d.cwiseAbs().maxCoeff(), 1e-14) << i << " " << j;
    }
  // A ray that misses: an off-centre "centre" outside the box, directions pointing away.
  const std::vector<double> away = surface_radii(m, Vector3d(0, 5, 0), 5.0, 3, 4);
  EXPECT_EQ(away[0], 0.0);  // +Y from (0, 5, 0): nothing
  EXPECT_NEAR(away[2 * 4], 6.0, 1e-14);  // −Y: through the box, leaving it at y = −1
}

TEST(FivSurface, ShellsStartJustOutsideThePlateAndNeverInsideIt) {
  PlateUnderGreySky p;
  p.spec.radial = RadialScheme::surface;
  const FivShells s = bake_fiv_shells(p.m, p.topo, p.env, p.spec);
  EXPECT_EQ(s.radial, RadialScheme::surface);
  ASSERT_GE(s.radii.size(), 2u);
  EXPECT_NEAR(s.radii[0], p.spec.first_offset * s.radius, 1e-12);
  for (size_t k = 2; k < s.radii.size(); ++k)  // geometric: the runtime inverts it in closed form
    EXPECT_NEAR(s.radii[k] / s.radii[k - 1], s.radii[1] / s.radii[0], 1e-12);
  ASSERT_EQ(s.surface_radius.size(), 5u * 8u);
  // Poles: the plate's half-thickness 0.01; the equator: its edge (1 or √2 along the diagonals).
  EXPECT_NEAR(s.surface_radius[0], 0.01, 1e-7);
  EXPECT_NEAR(s.surface_radius[2 * 8 + 0], 1.0, 1e-7);
  EXPECT_NEAR(s.surface_radius[2 * 8 + 1], std::sqrt(2.0), 1e-6);
  // Every sample lies outside the plate along its ray: the equator samples the geometric scheme
  // dropped are valid now, and nothing was extrapolated.
  for (uint8_t v : s.valid) EXPECT_EQ(v, 1);
  EXPECT_EQ(s.extrapolated, 0u);
  // Just outside the plate's face, it hides almost half the sky: |F| → π ∫L/(4π)... = π for L = 1.
  const size_t pole = 0;  // k = 0, θ = 0, φ = 0: 0.01 + 0.007 above the plate
  EXPECT_GT(std::abs(s.values[pole * 9 + 1]), 0.9 * pi);
}

TEST(FivSurface, InsideSamplesTakeTheNearestValidOneOutwards) {
  FivShells s;
  s.radial = RadialScheme::surface;
  s.n_theta = 2, s.n_phi = 1;
  s.radii = {0.1, 0.2, 0.4, 0.8};
  s.surface_radius = {1, 1};
  // Direction 0: valid 0 1 0 1 → sample 0 from 1, sample 2 from 3. Direction 1: 1 0 0 0 → from 0.
  // Values: 10 k + direction.
  const uint8_t valid[4][2] = {{0, 1}, {1, 0}, {0, 0}, {1, 0}};
  for (int k = 0; k < 4; ++k)
    for (int d = 0; d < 2; ++d) {
      s.valid.push_back(valid[k][d]);
      for (int e = 0; e < 9; ++e) s.values.push_back(float(10 * k + d));
    }
  FivShells geometric = s;
  geometric.radial = RadialScheme::geometric;
  extrapolate_inside_samples(geometric);
  EXPECT_EQ(geometric.values, s.values) << "the geometric scheme keeps its mask";
  extrapolate_inside_samples(s);
  const float expect[4][2] = {{10, 1}, {10, 1}, {30, 1}, {30, 1}};
  for (int k = 0; k < 4; ++k)
    for (int d = 0; d < 2; ++d)
      for (int e = 0; e < 9; ++e) EXPECT_EQ(s.values[size_t((k * 2 + d) * 9 + e)], expect[k][d]) << k << " " << d;
  EXPECT_EQ(s.extrapolated, 5u);
}

namespace {
// A unit icosphere: the icosahedron subdivided `levels` times, vertices on the unit sphere.
Mesh icosphere(int levels) {
  const double g = (1 + std::sqrt(5.0)) / 2;
  std::vector<Vector3d> v = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                             {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  for (Vector3d& x : v) x.normalize();
  std::vector<std::array<uint32_t, 3>> t = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                                            {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                                            {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
    auto midpoint = [&](uint32_t a, uint32_t b) {
      const auto key = std::minmax(a, b);
      const auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back((v[a] + v[b]).normalized());
      return mid[key] = uint32_t(v.size() - 1);
    };
    std::vector<std::array<uint32_t, 3>> next;
    for (const auto& f : t) {
      const uint32_t a = midpoint(f[0], f[1]), b = midpoint(f[1], f[2]), c = midpoint(f[2], f[0]);
      next.push_back({f[0], a, c}), next.push_back({f[1], b, a}), next.push_back({f[2], c, b}), next.push_back({a, b, c});
    }
    t = std::move(next);
  }
  std::vector<Vector3f> p;
  for (const Vector3d& x : v) p.push_back(x.cast<float>());
  return make_mesh(std::move(p), std::move(t), "icosphere");
}

// ∫_cap ω dω of the cap a sphere of radius a hides from distance ρ > a, under L = 1: π sin²α
// towards the centre, sin α = a/ρ.
Vector3d sphere_cap_fiv(double a, const Vector3d& s) {
  const double rho = s.norm();
  return -std::numbers::pi * (a / rho) * (a / rho) * s / rho;
}
} // namespace

// Closed form: a sphere under a uniform sky (L = 1) hides the cap of half-angle asin(a/ρ), whose
// occluded FIV is π (a/ρ)² towards the centre. The mesh is an icosphere between the spheres of
// its inradius r_in and radius 1, so its hidden set lies between their caps and F differs from
// either cap's by at most the solid angle between them, 2π (cos α_in − cos α_1). Baked samples
// agree within that plus the silhouette integrator's discretisation at k = 128² (3e-3 of ∫L = 4π,
// as OccludedFivMatchesQmcFullSphere's 2e-3 at 256²); the runtime lookup at any offset is a convex
// combination of its 8 neighbours, so it lies within the largest difference between the closed
// form at the offset and at those neighbours, plus the samples' own bound.
TEST(FivSurface, SphereUnderAUniformSkyMatchesTheClosedForm) {
  const Mesh m = icosphere(3);
  const Topology topo = build_topology(m);
  const EnvMap env = EnvMap::from_latlong(16, 8, std::vector<float>(16 * 8 * 3, 1.0f), UpAxis::Y, "grey");
  ShellSpec spec;
  spec.n_phi = 16, spec.n_theta = 9, spec.n_rho = 12;
  spec.silhouette_k = 128 * 128;
  spec.fraction = 0.01;
  const FivShells s = bake_fiv_shells(m, topo, env, spec);
  double r_in = 1;
  for (const auto& f : m.triangles) {
    const Vector3d a = m.positions[f[0]].cast<double>(), b = m.positions[f[1]].cast<double>(), c = m.positions[f[2]].cast<double>();
    r_in = std::min(r_in, std::abs((b - a).cross(c - a).normalized().dot(a)));
  }
  const double discretisation = 3e-3 * 4 * pi;
  auto cap_gap = [&](double rho) {
    return 2 * pi * (std::sqrt(std::max(0.0, 1 - (r_in / rho) * (r_in / rho))) - std::sqrt(std::max(0.0, 1 - 1 / (rho * rho))));
  };
  const size_t per_shell = size_t(s.n_theta) * size_t(s.n_phi);
  double worst_sample = 0;
  for (size_t k = 0; k < s.radii.size(); ++k)
    for (int i = 0; i < s.n_theta; ++i)
      for (int j = 0; j < s.n_phi; ++j) {
        const Vector3d p = s.sample_position(int(k), i, j) - s.centre;
        const Vector3d f = sphere_cap_fiv(1.0, p);
        const size_t idx = k * per_shell + size_t(i * s.n_phi + j);
        for (int a = 0; a < 3; ++a) {
          EXPECT_NEAR(s.values[idx * 9 + size_t(a)], f[a], cap_gap(p.norm()) + discretisation) << k << " " << i << " " << j;
          worst_sample = std::max(worst_sample, std::abs(s.values[idx * 9 + size_t(a)] - f[a]) / (cap_gap(p.norm()) + discretisation));
        }
      }
  std::printf("%zu shells; samples: largest |F - closed form| / bound = %.2g\n", s.radii.size(), worst_sample);
  // The runtime lookup (prtshade/fiv.h) of the baked grid at seeded offsets.
  std::vector<float> radii(s.radii.begin(), s.radii.end()), surface(s.surface_radius.begin(), s.surface_radius.end());
  prt::shade::FivOccluder o{{float(s.centre.x()), float(s.centre.y()), float(s.centre.z())}, float(s.radius), int(s.radii.size()),
                            s.n_theta, s.n_phi, radii.data(), s.values.data(), s.valid.data(),
                            prt::shade::kFivRadialSurface, surface.data()};
  prt::shade::validate_occluder(o);
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> u01(0, 1);
  double worst = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const Vector3d d = Vector3d(u01(rng) - 0.5, u01(rng) - 0.5, u01(rng) - 0.5).normalized();
    const double rho = 1.0 + s.radii.front() + (s.radii.back() - s.radii.front()) * std::pow(u01(rng), 3.0);
    const Vector3d off = rho * d;
    const float sf[3] = {float(off.x()), float(off.y()), float(off.z())};
    float out[9];
    prt::shade::lookup_fiv(o, sf, out);
    // The neighbours: the samples of the (θ, φ) cell of d on the two shells that bracket
    // τ = ρ − r_s (r_s bilinear in the cell; the lookup's float angles may pick the next cell or
    // shell within a few ulps, so both brackets' neighbours around the float ones are counted).
    const double theta = std::atan2(std::hypot(d.x(), d.z()), d.y());
    double phi = std::atan2(d.x(), d.z());
    if (phi < 0) phi += 2 * pi;
    const double t = theta / pi * (s.n_theta - 1), u = phi / (2 * pi) * s.n_phi;
    const int i0 = std::min(int(t), s.n_theta - 2), j0 = int(u) % s.n_phi, j1 = (j0 + 1) % s.n_phi;
    const double ft = t - i0, fu = u - std::floor(u);
    auto rs = [&](int i, int j) { return s.surface_radius[size_t(i * s.n_phi + j)]; };
    const double r_s = (1 - ft) * ((1 - fu) * rs(i0, j0) + fu * rs(i0, j1)) + ft * ((1 - fu) * rs(i0 + 1, j0) + fu * rs(i0 + 1, j1));
    const double tau = rho - r_s;
    size_t k0 = 0;
    while (k0 + 1 < s.radii.size() && s.radii[k0 + 1] <= tau) ++k0;
    const size_t k1 = std::min(k0 + 1, s.radii.size() - 1);
    double spread = 0, bound = 0;
    const Vector3d f = sphere_cap_fiv(1.0, off);
    for (size_t kk : {k0, k1})
      for (int di = 0; di < 2; ++di)
        for (int j : {j0, j1}) {
          const Vector3d q = s.sample_position(int(kk), i0 + di, j) - s.centre;
          spread = std::max(spread, (sphere_cap_fiv(1.0, q) - f).cwiseAbs().maxCoeff());
          bound = std::max(bound, cap_gap(q.norm()));
        }
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(out[a], f[a], spread + bound + discretisation + 1e-5) << trial << " rho " << rho;
      worst = std::max(worst, std::abs(out[a] - f[a]) / (spread + bound + discretisation + 1e-5));
    }
  }
  std::printf("runtime lookup: largest |F - closed form| / bound = %.2g\n", worst);
}

// Scene files choose the scheme with bake.fiv.radial (bake/bake/scene.h); the default follows the
// surface, and anything but "surface" or "geometric" is an input error naming the key.
TEST(FivSurface, SceneFilesChooseTheRadialScheme) {
  const std::filesystem::path dir = std::filesystem::path(PRT_TEST_TMP) / "fiv_scene_radial";
  std::filesystem::create_directories(dir);
  auto write = [&](const std::string& name, const std::string& bake) {
    const std::filesystem::path p = dir / name;
    std::ofstream(p) << R"({"prtbake_scene": 1, "bake": )" << bake << R"(, "objects": [{"role": "receiver", "mesh": ")"
                     << (std::filesystem::path(PRT_DATA_DIR) / "bunny.obj").string() << R"("}]})";
    return p;
  };
  EXPECT_EQ(load_scene(write("default.json", R"({"fiv": {"shells": "8x5x4"}})"), std::nullopt).fiv.radial,
            RadialScheme::surface);
  EXPECT_EQ(load_scene(write("geometric.json", R"({"fiv": {"radial": "geometric"}})"), std::nullopt).fiv.radial,
            RadialScheme::geometric);
  EXPECT_EQ(load_scene(write("surface.json", R"({"fiv": {"radial": "surface"}})"), std::nullopt).fiv.radial,
            RadialScheme::surface);
  // A bad value: an InputError that names the key.
  const auto refused = [&](const std::string& name, const std::string& bake, const std::string& part) {
    try {
      load_scene(write(name, bake), std::nullopt);
      ADD_FAILURE() << bake << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    }
  };
  refused("bad.json", R"({"fiv": {"radial": "spheres"}})", "bake.fiv.radial");
  // bake.fiv.precision: half floats by default (formats/SCHEMA.md "Half-float FIV tables").
  EXPECT_TRUE(load_scene(write("half.json", R"({"fiv": {"shells": "8x5x4"}})"), std::nullopt).fiv.float16);
  EXPECT_FALSE(load_scene(write("float.json", R"({"fiv": {"precision": "float"}})"), std::nullopt).fiv.float16);
  refused("bad_precision.json", R"({"fiv": {"precision": "double"}})", "bake.fiv.precision");
  // bake.fiv.self_shadows: the vertices by default (/fiv/occluders/<name>/self_band1).
  EXPECT_TRUE(load_scene(write("self.json", R"({"fiv": {"shells": "8x5x4"}})"), std::nullopt).fiv.vertex_self_shadows);
  EXPECT_FALSE(load_scene(write("shells.json", R"({"fiv": {"self_shadows": "shells"}})"), std::nullopt).fiv.vertex_self_shadows);
  refused("bad_self.json", R"({"fiv": {"self_shadows": "none"}})",
          "bake.fiv.self_shadows must be \"vertex\" or \"shells\", not \"none\"");
}

// ShellSpec::float16: the bake rounds the shells and the cones to the nearest float16 (what the
// file stores, so the error report measures it), and the float bake's values round to them.
TEST(FivSurface, HalfPrecisionRoundsTheShellsAndConesToFloat16) {
  ShellSpec spec;
  spec.n_phi = 8, spec.n_theta = 5, spec.n_rho = 4;
  const Mesh m = load_mesh(std::string(PRT_DATA_DIR) + "/spider.obj", {.use_file_normals = false});
  const Topology topo = build_topology(m);
  const EnvMap env = EnvMap::load(std::string(PRT_DATA_DIR) + "/studio.exr", UpAxis::Y);
  spec.float16 = false;
  const FivShells full = bake_fiv_shells(m, topo, env, spec);
  spec.float16 = true;
  const FivShells rounded = bake_fiv_shells(m, topo, env, spec);
  EXPECT_FALSE(full.float16);
  EXPECT_TRUE(rounded.float16);
  ASSERT_EQ(rounded.values.size(), full.values.size());
  ASSERT_EQ(rounded.cones.size(), full.cones.size());
  size_t changed = 0;
  for (size_t i = 0; i < full.values.size(); ++i) {
    EXPECT_EQ(rounded.values[i], float(Imath::half(full.values[i]))) << i;
    changed += rounded.values[i] != full.values[i] ? 1 : 0;
  }
  for (size_t i = 0; i < full.cones.size(); ++i) EXPECT_EQ(rounded.cones[i], float(Imath::half(full.cones[i]))) << i;
  EXPECT_GT(changed, full.values.size() / 2);  // the values were rounded, not left as floats
}
