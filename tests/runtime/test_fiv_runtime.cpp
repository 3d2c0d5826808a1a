// Tests of prtshade/fiv.h (paper 004 §4.3): DifMap lookup (texel centres, bilinear, clamping,
// face selection), the shell lookup (grid points exact, linear between, φ wrap, poles, radius
// clamp and 1/ρ² falloff, invalid-sample renormalisation), cases A/B/C, the overlap correction
// (identical, disjoint, lens area against numerical integration, fast path against the slow
// reference), self-shadows, a receiver that is one of several occluders (C++ and C API),
// validation, and finiteness at extreme inputs.
#include <prtshade/fiv.h>
#include <prtshade/prtshade.h>

#include <Imath/half.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

namespace {

namespace shade = prt::shade;
using shade::DifMap;
using shade::FivOccluder;

constexpr double kPi = 3.14159265358979323846264338327950288;

// An occluder with owned arrays; value(k, i, j, e) fills the shells.
struct Shells {
  int n_rho, n_theta, n_phi;
  std::vector<float> radii, shells;
  std::vector<uint8_t> valid;
  float centre[3] = {0, 0, 0};
  float radius = 1;

  template <class F>
  Shells(int nr, int nt, int np, F value) : n_rho(nr), n_theta(nt), n_phi(np) {
    for (int k = 0; k < nr; ++k) radii.push_back(0.5f * float(1 << k));  // 0.5, 1, 2, 4, ...: exact in float
    for (int k = 0; k < nr; ++k)
      for (int i = 0; i < nt; ++i)
        for (int j = 0; j < np; ++j)
          for (int e = 0; e < 9; ++e) shells.push_back(value(k, i, j, e));
    valid.assign(size_t(nr * nt * np), 1);
  }
  size_t index(int k, int i, int j) const { return (size_t(k) * size_t(n_theta) + size_t(i)) * size_t(n_phi) + size_t(j); }
  float& at(int k, int i, int j, int e) { return shells[index(k, i, j) * 9 + size_t(e)]; }
  FivOccluder view() const {
    return {{centre[0], centre[1], centre[2]}, radius, n_rho, n_theta, n_phi, radii.data(), shells.data(), valid.data()};
  }
};

// Offset s at continuous grid coordinates (t, u) and radius rho (bake/bake/fiv.h grid convention).
void offset_at(const Shells& o, double t, double u, double rho, float s[3]) {
  const double theta = kPi * t / (o.n_theta - 1), phi = 2 * kPi * u / o.n_phi;
  s[0] = float(rho * std::sin(theta) * std::sin(phi));
  s[1] = float(rho * std::cos(theta));
  s[2] = float(rho * std::sin(theta) * std::cos(phi));
}

// A value linear in the grid coordinates (k, i, j), different per component.
float linear_value(int k, int i, int j, int e) { return float(1 + e) + 0.5f * float(k) + 0.25f * float(i) - 0.125f * float(j * (e + 1)); }

// Angles are formed in float (acos/atan2 of float components): t and u come back within a few
// float ulps of π (≤ ~1e-6 grid units at these sizes), times the slope of linear_value (≤ 1.2 per
// grid unit).
constexpr float kAngleRoundTrip = 2e-5f;

TEST(LookupFiv, GridPointsAreExact) {
  Shells o(3, 5, 8, linear_value);
  // Axis-aligned grid points are computed without rounding: θ ∈ {0, π/2, π} and φ ∈ {0, π/2, π,
  // 3π/2} come out of acos/atan2 as the float multiples of π, t and u exactly integral, and ρ ==
  // radii[k] exactly, so the trilinear weights are (1, 0, ...) and the value is the stored one.
  struct P {
    int i, j;
    float dir[3];
  } pts[] = {{2, 0, {0, 0, 1}}, {2, 2, {1, 0, 0}}, {2, 4, {0, 0, -1}}, {2, 6, {-1, 0, 0}}, {0, 0, {0, 1, 0}}, {4, 0, {0, -1, 0}}};
  for (int k = 0; k < o.n_rho; ++k)
    for (const P& p : pts) {
      const float s[3] = {p.dir[0] * o.radii[size_t(k)], p.dir[1] * o.radii[size_t(k)], p.dir[2] * o.radii[size_t(k)]};
      float out[9];
      shade::lookup_fiv(o.view(), s, out);
      // The south pole (θ = π) is reached with t = Nθ − 1 exactly and weight 1 on the last row.
      for (int e = 0; e < 9; ++e) EXPECT_EQ(out[e], o.at(k, p.i, p.j, e)) << "k " << k << " i " << p.i << " j " << p.j;
    }
  // Generic grid points (all angles rounded): equal to float round-trip accuracy.
  for (int k = 0; k < o.n_rho; ++k)
    for (int i = 1; i < o.n_theta - 1; ++i)
      for (int j = 0; j < o.n_phi; ++j) {
        float s[3], out[9];
        offset_at(o, i, j, o.radii[size_t(k)], s);
        shade::lookup_fiv(o.view(), s, out);
        for (int e = 0; e < 9; ++e) EXPECT_NEAR(out[e], o.at(k, i, j, e), kAngleRoundTrip * 8) << k << i << j;
      }
}

TEST(LookupFiv, LinearBetweenGridPoints) {
  Shells o(3, 5, 8, linear_value);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> ut(0, 4), uu(0, 6.99), ur(0, 1);
  for (int trial = 0; trial < 200; ++trial) {
    const double t = ut(rng), u = uu(rng), fr = ur(rng);
    const int k = trial % 2;
    const double rho = o.radii[size_t(k)] + fr * (o.radii[size_t(k + 1)] - o.radii[size_t(k)]);
    float s[3], out[9];
    offset_at(o, t, u, rho, s);
    shade::lookup_fiv(o.view(), s, out);
    // Trilinear interpolation of a function linear in (k, i, j) is exact (away from the φ seam,
    // u < Nφ − 1, where linear_value is not periodic).
    for (int e = 0; e < 9; ++e) {
      const double expect = (1 + e) + 0.5 * (k + fr) + 0.25 * t - 0.125 * u * (e + 1);
      EXPECT_NEAR(out[e], expect, kAngleRoundTrip * (e + 1) + 1e-5) << "t " << t << " u " << u << " rho " << rho;
    }
  }
}

TEST(LookupFiv, WrapsInPhi) {
  // Only j = Nφ − 1 and j = 0 differ; between them (u ∈ (Nφ − 1, Nφ)) the lookup blends the two.
  Shells o(1, 3, 8, [](int, int, int j, int e) { return j == 7 ? 10.0f + float(e) : j == 0 ? 2.0f : 0.0f; });
  for (double u : {7.25, 7.5, 7.9}) {
    float s[3], out[9];
    offset_at(o, 1, u, 0.5, s);  // θ = π/2 (t = 1), on shell 0
    shade::lookup_fiv(o.view(), s, out);
    const double f = u - 7;
    for (int e = 0; e < 9; ++e) EXPECT_NEAR(out[e], (1 - f) * (10 + e) + f * 2, 1e-4 * (10 + e)) << u;
  }
  // φ just below 0 (atan2 negative) wraps to just below 2π: the value of j = 0 blended with a
  // tiny weight of j = 7... i.e. continuous across the seam.
  float a[9], b[9];
  const float s1[3] = {-1e-4f, 0, 0.5f}, s2[3] = {1e-4f, 0, 0.5f};
  shade::lookup_fiv(o.view(), s1, a);
  shade::lookup_fiv(o.view(), s2, b);
  // |Δφ| = 2e-4 rad = 2.5e-4 grid units of φ, times the jump of 8..16 between j = 7 and j = 0.
  for (int e = 0; e < 9; ++e) EXPECT_NEAR(a[e], b[e], 2.5e-4 * 2 * (10 + e) + 1e-5);
}

TEST(LookupFiv, PolesUseTheirRowAndRhoZeroIsNorthPole) {
  // Pole rows constant in φ (as baked: every φ sample of a pole is the same position).
  Shells o(2, 5, 8, [](int k, int i, int j, int e) {
    return i == 0 ? 3.0f + float(k + e) : i == 4 ? -2.0f - float(k) : float(j + e + k);
  });
  for (double u : {0.0, 1.3, 4.5, 7.7}) {
    float s[3], out[9];
    offset_at(o, 0, u, 0.5, s);
    shade::lookup_fiv(o.view(), s, out);
    for (int e = 0; e < 9; ++e) EXPECT_EQ(out[e], 3.0f + float(e)) << u;  // θ = 0: weight 1 on row 0, any φ blend of equal values
    offset_at(o, 4, u, 1.0, s);
    shade::lookup_fiv(o.view(), s, out);
    // θ = π from float rounding of cos: t within ~1e-4 of the last row; rows 3 and 4 differ by ≤ 12.
    for (int e = 0; e < 9; ++e) EXPECT_NEAR(out[e], -3.0f, 2e-3) << u;
  }
  const float zero[3] = {0, 0, 0};
  float out[9];
  shade::lookup_fiv(o.view(), zero, out);  // ρ = 0: d = +Y, clamped to the inner shell
  for (int e = 0; e < 9; ++e) EXPECT_EQ(out[e], 3.0f + float(e));
}

TEST(LookupFiv, NearThePoleAnInvalidPoleSampleStaysIgnored) {
  // s 1e-4 rad from +Y: in float d_y rounds to 1, and θ = acos(d_y) snapped onto the pole, where
  // the invalid pole row then took all the weight (10 instead of 1; found by the GLSL mirror
  // test). With θ = atan2(|d_xz|, d_y) the valid row keeps its small weight and wins the
  // renormalisation: the value is the valid rows' 1 up to rounding.
  Shells o(1, 3, 1, [](int, int i, int, int) { return i == 0 ? 10.0f : 1.0f; });
  o.radii = {1.0f};
  for (int j = 0; j < 1; ++j) o.valid[o.index(0, 0, j)] = 0;
  for (float x : {1e-4f, 3e-4f, 1e-6f}) {
    const float s[3] = {x, 1.0f, 0.0f};
    float out[9];
    shade::lookup_fiv(o.view(), s, out);
    for (int e = 0; e < 9; ++e) EXPECT_NEAR(out[e], 1.0f, 4e-7f) << "x = " << x;  // renormalisation: a few ulps
  }
}

TEST(LookupFiv, RadiusClampsInsideAndFallsOffOutside) {
  Shells o(3, 3, 4, linear_value);  // radii 0.5, 1, 2
  const float dir[3] = {1, 0, 0};     // t = 1, u = 1: a grid point
  auto at_rho = [&](float rho, float out[9]) {
    const float s[3] = {dir[0] * rho, dir[1] * rho, dir[2] * rho};
    shade::lookup_fiv(o.view(), s, out);
  };
  float a[9], b[9];
  at_rho(0.1f, a);
  for (int e = 0; e < 9; ++e) EXPECT_EQ(a[e], o.at(0, 1, 1, e));  // ρ < ρ_0 clamps
  at_rho(8.0f, a);
  // (2/8)² = 1/16: exact in float.
  for (int e = 0; e < 9; ++e) EXPECT_EQ(a[e], o.at(2, 1, 1, e) / 16.0f);
  at_rho(2.0f, a);
  at_rho(2.0f * (1 + 1e-6f), b);  // continuous at the last shell
  for (int e = 0; e < 9; ++e) EXPECT_NEAR(a[e], b[e], 3e-6f * std::abs(a[e]));
  at_rho(1.5f, a);  // halfway between shells 1 and 2
  for (int e = 0; e < 9; ++e) EXPECT_EQ(a[e], 0.5f * (o.at(1, 1, 1, e) + o.at(2, 1, 1, e)));
  // Huge and tiny offsets stay finite.
  for (float rho : {1e30f, 3e38f, 1e-30f, 1e-45f}) {
    at_rho(rho, a);
    for (int e = 0; e < 9; ++e) EXPECT_TRUE(std::isfinite(a[e])) << rho;
  }
  const float huge[3] = {3e38f, -3e38f, 3e38f}, nan[3] = {std::numeric_limits<float>::quiet_NaN(), 0, 1};
  shade::lookup_fiv(o.view(), huge, a);
  for (int e = 0; e < 9; ++e) EXPECT_TRUE(std::isfinite(a[e]));
  shade::lookup_fiv(o.view(), nan, a);
  for (int e = 0; e < 9; ++e) EXPECT_TRUE(std::isfinite(a[e]));
}

TEST(LookupFiv, InvalidSamplesAreDroppedAndTheRestRenormalised) {
  Shells o(2, 3, 4, [](int k, int i, int j, int e) { return float(k * 100 + i * 10 + j) + 0.001f * float(e); });
  // The centre of the cell k ∈ {0,1}, i ∈ {0,1}, j ∈ {0,1}: every neighbour has weight 1/8.
  const double t = 0.5, u = 0.5, rho = 0.75;
  float s[3];
  offset_at(o, t, u, rho, s);
  o.valid[o.index(1, 1, 1)] = 0;
  o.at(1, 1, 1, 0) = 1e6f;  // would dominate if it were used
  float out[9];
  shade::lookup_fiv(o.view(), s, out);
  // The mean of the 7 valid neighbours (the weights are 1/8 up to the float angle round trip).
  double mean = 0;
  for (int k = 0; k < 2; ++k)
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j)
        if (!(k == 1 && i == 1 && j == 1)) mean += (k * 100 + i * 10 + j) / 7.0;
  // Weights off 1/8 by ≤ 1e-6 (angle round trip) times value spread ≤ 111.
  EXPECT_NEAR(out[0], mean, 1e-3);
  // All 8 invalid: the plain trilinear value (here the plain mean of all eight, with the 1e6).
  for (int k = 0; k < 2; ++k)
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j) o.valid[o.index(k, i, j)] = 0;
  shade::lookup_fiv(o.view(), s, out);
  double plain = 0;
  for (int k = 0; k < 2; ++k)
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j) plain += double(o.at(k, i, j, 0)) / 8;
  EXPECT_NEAR(out[0], plain, 1e-6 * plain + 1e-3);
}

// ---- DifMap --------------------------------------------------------------------------------

struct Cube {
  int S;
  std::vector<float> texels;
  explicit Cube(int size) : S(size), texels(size_t(6 * size * size * 3)) {
    for (size_t k = 0; k < texels.size(); ++k) texels[k] = float((k * 37) % 101) * 0.5f;  // distinct values
  }
  float at(int face, int r, int q, int c) const { return texels[((size_t(face) * S + size_t(r)) * S + size_t(q)) * 3 + size_t(c)]; }
  DifMap view() const { return {S, texels.data()}; }
};

// Unnormalised direction of texel (face, r, q) in the OpenGL convention of bake/bake/fiv.h.
void texel_direction(int face, int r, int q, int S, float d[3]) {
  const float s = 2.0f * (float(q) + 0.5f) / float(S) - 1.0f, t = 2.0f * (float(r) + 0.5f) / float(S) - 1.0f;
  const float dirs[6][3] = {{1, -t, -s}, {-1, -t, s}, {s, 1, t}, {s, -1, -t}, {s, -t, 1}, {-s, -t, -1}};
  for (int a = 0; a < 3; ++a) d[a] = dirs[face][a];
}

TEST(LookupDifmap, TexelCentresAreExactAndBetweenIsBilinear) {
  const Cube cube(8);  // S a power of 2: texel-centre coordinates are exact in float
  for (int face = 0; face < 6; ++face)
    for (int r = 0; r < cube.S; ++r)
      for (int q = 0; q < cube.S; ++q) {
        float d[3], out[3];
        texel_direction(face, r, q, cube.S, d);
        shade::lookup_difmap(cube.view(), d, out);
        for (int c = 0; c < 3; ++c) ASSERT_EQ(out[c], cube.at(face, r, q, c)) << face << " " << r << " " << q;
        // Normalised direction: the division by the major component rounds (≤ 2 ulps of s, t),
        // moving the sample by ≤ 1e-6 texels; neighbour values differ by ≤ 50.
        const float len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        const float dn[3] = {d[0] / len, d[1] / len, d[2] / len};
        shade::lookup_difmap(cube.view(), dn, out);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(out[c], cube.at(face, r, q, c), 1e-4f);
      }
  // Halfway between texels (r, q) and (r, q + 1) of face +Z: the mean.
  const float s = 2.0f * 4.0f / 8.0f - 1.0f, t = 2.0f * 2.5f / 8.0f - 1.0f;  // q = 3.5, r = 2
  const float d[3] = {s, -t, 1};
  float out[3];
  shade::lookup_difmap(cube.view(), d, out);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(out[c], 0.5f * (cube.at(4, 2, 3, c) + cube.at(4, 2, 4, c)));
  // A cube corner clamps to the corner texel of the face that wins the tie (X first).
  const float corner[3] = {1, 1, 1};
  shade::lookup_difmap(cube.view(), corner, out);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(out[c], cube.at(0, 0, 0, c));  // +X: s = −z = −1 → q = 0, t = −y → r = 0
  // Zero normal: +Y face centre (finite, documented).
  const float zero[3] = {0, 0, 0};
  shade::lookup_difmap(cube.view(), zero, out);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(out[c], 0.25f * (cube.at(2, 3, 3, c) + cube.at(2, 3, 4, c) + cube.at(2, 4, 3, c) + cube.at(2, 4, 4, c)));
}

// ---- cases A/B/C, shadows, overlap, self-shadows ------------------------------------------------

// An occluder whose FIV is the same F everywhere inside ρ = 64 R (F[c][a] = f[a] · (c + 1)).
Shells constant_occluder(const float f[3], float radius, const float centre[3]) {
  Shells o(2, 3, 4, [f](int, int, int, int e) { return f[e % 3] * float(e / 3 + 1); });
  o.radius = radius;
  for (int a = 0; a < 3; ++a) o.centre[a] = centre[a];
  o.radii = {radius, 64 * radius};  // receivers in the tests lie inside: no 1/ρ² falloff
  return o;
}

TEST(PartialFactor, CasesABC) {
  const float f[3] = {0, 1, 0}, centre[3] = {0, 2, 0};
  const Shells o = constant_occluder(f, 1.0f, centre);
  const float n[3] = {0, 1, 0};
  // h = n·(centre − p) = 2 − p_y; R = 1.
  const struct {
    float py, expect;
  } cases[] = {{0.0f, 1.0f}, {1.0f, 1.0f}, {1.5f, 0.75f}, {2.0f, 0.5f}, {2.5f, 0.25f}, {3.0f, 0.0f}, {5.0f, 0.0f}};
  for (const auto& cs : cases) {
    const float p[3] = {0.3f, cs.py, -0.2f};
    // Closed forms (h + R)/2R with h, R small binary fractions: exact in float.
    EXPECT_EQ(shade::partial_factor(o.view(), p, n), cs.expect) << cs.py;
  }
}

TEST(OccludedIrradiance, FactorTimesProjectedFivClampedAtZero) {
  const float f[3] = {0.5f, 2.0f, -1.0f}, centre[3] = {0, 2, 0};
  const Shells o = constant_occluder(f, 1.0f, centre);
  const float n[3] = {0, 1, 0};
  float out[3];
  const float pa[3] = {0, 0, 0}, pb[3] = {0, 1.5f, 0}, pc[3] = {0, 3.5f, 0};
  shade::occluded_irradiance(o.view(), pa, n, true, out);  // case A: n·F_c = 2 (c + 1)
  for (int c = 0; c < 3; ++c) EXPECT_EQ(out[c], 2.0f * float(c + 1));
  shade::occluded_irradiance(o.view(), pb, n, true, out);  // case B: factor 3/4
  for (int c = 0; c < 3; ++c) EXPECT_EQ(out[c], 1.5f * float(c + 1));
  shade::occluded_irradiance(o.view(), pb, n, false, out);  // partial correction off: factor 1
  for (int c = 0; c < 3; ++c) EXPECT_EQ(out[c], 2.0f * float(c + 1));
  shade::occluded_irradiance(o.view(), pc, n, false, out);  // case C stays 0 even without it
  for (int c = 0; c < 3; ++c) EXPECT_EQ(out[c], 0.0f);
  const float down[3] = {0, 0, 1}, pd[3] = {0, 2, -0.5f};  // n·F = −(c+1) < 0: clamped
  shade::occluded_irradiance(o.view(), pd, down, true, out);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(out[c], 0.0f);
}

// A constant cube map with value e in every texel.
std::vector<float> flat_cube(int S, float e) { return std::vector<float>(size_t(6 * S * S * 3), e); }

TEST(ShadeFiv, SingleIdenticalAndDisjointOccluders) {
  const std::vector<float> cube = flat_cube(4, 10.0f);
  const DifMap map{4, cube.data()};
  const float f[3] = {0, 1, 0}, n[3] = {0, 1, 0}, p[3] = {0, 0, 0};
  const float c1[3] = {0, 3, 0}, c2[3] = {6, 3, 0};  // c2 is 63° from c1 as seen from p; α = 19.5° each
  const Shells a = constant_occluder(f, 1.0f, c1), a2 = constant_occluder(f, 1.0f, c1), b = constant_occluder(f, 1.0f, c2);
  const FivOccluder one[1] = {a.view()}, same[2] = {a.view(), a2.view()}, apart[2] = {a.view(), b.view()};
  float e1[3], e2[3], e3[3], e4[3];
  shade::shade_fiv(map, one, 1, p, n, {}, e1);
  shade::shade_fiv(map, same, 2, p, n, {}, e2);
  shade::shade_fiv(map, same, 2, p, n, {true, false}, e3);
  shade::shade_fiv(map, apart, 2, p, n, {}, e4);
  for (int c = 0; c < 3; ++c) {
    const float I = float(c + 1);  // n·F_c, case A (h = 3 >= R)
    // The lookup renormalises by the float sum of its 8 weights (1 to within 2ε), so I is n·F to
    // a few ε; the sums are in double and rounded once: 4ε · E_tot.
    const float tol = 4 * FLT_EPSILON * 10;
    EXPECT_NEAR(e1[c], 10.0f - I, tol);
    // Identical occluders: O = πα²/(2πα²) = ½, so E = E_tot − 2I + ½·2I = E_tot − I.
    EXPECT_NEAR(e2[c], 10.0f - I, tol);
    EXPECT_NEAR(e3[c], 10.0f - 2 * I, tol);  // without the correction: counted twice
    EXPECT_NEAR(e4[c], 10.0f - 2 * I, tol);  // disjoint discs (γ = 63° > 2α = 39°): I1 + I2
  }
  // Clamped at zero when the occluders hide more than the DifMap holds.
  const std::vector<float> dim = flat_cube(4, 0.5f);
  shade::shade_fiv({4, dim.data()}, apart, 2, p, n, {}, e1);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(e1[c], 0.0f);
}

// Lens area by 1D integration: the vertical chords of both discs are centred on the axis, so the
// overlap at abscissa x is 2 min(h1(x), h2(x)).
double lens_area_numeric(double r1, double r2, double d, int steps) {
  const double x0 = std::max(-r1, d - r2), x1 = std::min(r1, d + r2);
  if (x1 <= x0) return 0;
  const double h = (x1 - x0) / steps;
  double sum = 0;
  for (int i = 0; i < steps; ++i) {
    const double x = x0 + (i + 0.5) * h;
    const double h1 = std::sqrt(std::max(0.0, r1 * r1 - x * x)), h2 = std::sqrt(std::max(0.0, r2 * r2 - (x - d) * (x - d)));
    sum += 2 * std::min(h1, h2);
  }
  return sum * h;
}

TEST(Overlap, LensAreaMatchesNumericalIntegration) {
  const struct {
    double r1, r2, d;
  } cases[] = {{1, 1, 0.5}, {1, 1, 1.9}, {1, 0.3, 0.9}, {0.2, 0.7, 0.6}, {0.5, 0.5, 1e-3}, {1.5, 0.4, 1.2}, {0.3, 0.3, 0.59}};
  for (const auto& cs : cases) {
    const double exact = shade::lens_area(cs.r1, cs.r2, cs.d);
    const double numeric = lens_area_numeric(cs.r1, cs.r2, cs.d, 400000);
    // Midpoint rule on an integrand with square-root ends (and one kink): error O(h^1.5) ≈
    // (2.5e-6)^1.5 · r ≈ 4e-9 per end; 1e-7 of π min(r)² covers it with room.
    EXPECT_NEAR(exact, numeric, 1e-7 * kPi * std::min(cs.r1, cs.r2) * std::min(cs.r1, cs.r2) + 1e-9)
        << cs.r1 << " " << cs.r2 << " " << cs.d;
  }
  EXPECT_EQ(shade::lens_area(1, 0.5, 2), 0.0);                     // disjoint
  EXPECT_DOUBLE_EQ(shade::lens_area(1, 0.5, 0.2), kPi * 0.25);     // contained: the small disc
  EXPECT_DOUBLE_EQ(shade::overlap_fraction(0.3, 0.3, 0.0), 0.5);   // identical discs
  EXPECT_EQ(shade::overlap_fraction(0, 0, 0), 0.0);                // no disc at all
}

TEST(ShadeFiv, FastPathMatchesSlowReference) {
  // Ten occluders with random positions/sizes around a receiver, some overlapping, some below
  // the horizon (case C), some straddling it (case B).
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> pos(-2.5f, 2.5f), rad(0.2f, 1.2f);
  Cube cube(6);
  std::vector<Shells> occ;
  for (int i = 0; i < 10; ++i) {
    const float centre[3] = {pos(rng), pos(rng) + 1.0f, pos(rng)};
    occ.push_back(Shells(3, 9, 16, [&](int k, int ti, int j, int e) {
      return 0.5f + 0.1f * float((k * 7 + ti * 3 + j * 5 + e) % 11) + 0.05f * float(i);
    }));
    occ.back().radius = rad(rng);
    occ.back().radii = {0.5f * occ.back().radius, occ.back().radius, 3 * occ.back().radius};
    for (int a = 0; a < 3; ++a) occ.back().centre[a] = centre[a];
  }
  std::vector<FivOccluder> views;
  for (const Shells& o : occ) views.push_back(o.view());
  std::uniform_real_distribution<float> un(-1, 1);
  int pairs_overlapping = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const float p[3] = {pos(rng) * 0.5f, 0, pos(rng) * 0.5f};
    float n[3] = {un(rng), 1.5f, un(rng)};
    const float len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (float& v : n) v /= len;
    for (const shade::FivShadeOptions opt : {shade::FivShadeOptions{}, shade::FivShadeOptions{false, true}}) {
      float fast[3], slow[3];
      shade::shade_fiv(cube.view(), views.data(), int(views.size()), p, n, opt, fast);
      shade::shade_fiv_reference(cube.view(), views.data(), int(views.size()), p, n, opt, slow);
      for (int c = 0; c < 3; ++c)
        // Float vs double accumulation of ~10 terms of size ≤ 50 and ~45 pair terms (the pair
        // angle in float: ≤ 1e-6 rad, O's slope in γ ≤ 1/α_min ≈ 10): ≤ 1e-4 absolute.
        EXPECT_NEAR(fast[c], slow[c], 1e-4f) << trial << " " << c;
      float no_overlap[3];
      shade::shade_fiv(cube.view(), views.data(), int(views.size()), p, n, {opt.partial_occluders, false}, no_overlap);
      if (fast[0] != no_overlap[0]) ++pairs_overlapping;
    }
  }
  EXPECT_GT(pairs_overlapping, 50);  // the overlap path was exercised
}

// The fast path against the slow reference where it is meant to be fast: 100 and 200 (the heap
// path) instances of one asset scattered over a ground, receivers on the ground with tilted
// normals, cases A, B and C and ~1.5 overlapping pairs per occluder. The two differ in
//  - the shell angles: the fast path's polynomial atan2 (2e-8 rad) on float arguments, within
//    kAngle = 7e-7 rad of the reference's, i.e. <= 7e-7 · 32/(2π) < 4e-6 grid steps here; the
//    shell values change by <= 1 per step, so n·F moves by <= √3 · 4e-6 < kLookup = 1e-5 per
//    occluder (with the float rounding of the 8-sample sum);
//  - O_ij, in float with γ and α within kAngle: the lens area moves by at most its chord (<= 2
//    min α) per radian, so O by <= kAngle / (π min(α_i, α_j)) per pair, times I_i + I_j;
//  - the final rounding of E to float (4 ε E).
// The bound is formed per receiver from the reference's own terms.
TEST(ShadeFiv, ScatteredOccludersMatchTheSlowReference) {
  constexpr double kAngle = 7e-7, kLookup = 1e-5;
  std::mt19937 rng(33);
  std::uniform_real_distribution<float> u01(0, 1);
  Shells asset(12, 17, 32, [&](int, int, int, int) { return u01(rng); });
  const std::vector<float> cube = flat_cube(4, 400.0f);
  for (const int count : {100, 200}) {
    std::vector<FivOccluder> views;
    for (int i = 0; i < count; ++i) {
      FivOccluder v = asset.view();
      v.centre[0] = 40 * u01(rng) - 20, v.centre[1] = 5.5f * u01(rng) - 1.5f, v.centre[2] = 40 * u01(rng) - 20;
      v.radius = 0.5f + u01(rng);
      views.push_back(v);
    }
    double worst = 0;
    int overlapping = 0;
    for (int trial = 0; trial < 100; ++trial) {
      const float p[3] = {40 * u01(rng) - 20, 0, 40 * u01(rng) - 20};
      float n[3] = {u01(rng) - 0.5f, 1.0f, u01(rng) - 0.5f};
      const double len = std::sqrt(double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2]);
      float fast[3], slow[3];
      shade::shade_fiv({4, cube.data()}, views.data(), count, p, n, {}, fast);
      shade::shade_fiv_reference({4, cube.data()}, views.data(), count, p, n, {}, slow);
      // The reference's terms: I_i, and the discs of the occluders that hide something.
      std::vector<std::array<double, 3>> I;
      std::vector<std::array<double, 4>> disc;  // axis, α
      for (const FivOccluder& v : views) {
        float i3[3];
        shade::occluded_irradiance(v, p, n, true, i3);
        if (!(i3[0] > 0 || i3[1] > 0 || i3[2] > 0)) continue;
        I.push_back({i3[0], i3[1], i3[2]});
        const double d[3] = {double(v.centre[0]) - p[0], double(v.centre[1]) - p[1], double(v.centre[2]) - p[2]};
        const double D = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        disc.push_back({d[0] / D, d[1] / D, d[2] / D, std::asin(std::min(1.0, double(v.radius) / D))});
      }
      for (int c = 0; c < 3; ++c) {
        ASSERT_GT(slow[c], 0.0f) << "the scene must not clamp E to 0, or nothing is compared";
        double tolerance = 4 * double(FLT_EPSILON) * slow[c] + kLookup * double(I.size());
        for (size_t i = 0; i < I.size(); ++i)
          for (size_t j = i + 1; j < I.size(); ++j) {
            const double cos_gamma = disc[i][0] * disc[j][0] + disc[i][1] * disc[j][1] + disc[i][2] * disc[j][2];
            if (std::acos(std::clamp(cos_gamma, -1.0, 1.0)) >= disc[i][3] + disc[j][3] + kAngle) continue;
            overlapping += c == 0;
            tolerance += kAngle / (kPi * std::min(disc[i][3], disc[j][3])) * (I[i][size_t(c)] + I[j][size_t(c)]);
          }
        EXPECT_NEAR(fast[c], slow[c], tolerance) << count << " " << trial << " " << c << " " << len;
        worst = std::max(worst, std::fabs(double(fast[c]) - slow[c]) / tolerance);
      }
    }
    EXPECT_GT(overlapping, 100 * count / 4);  // the overlap pass was exercised
    std::printf("%d occluders: %.1f overlapping pairs per receiver, largest |fast - reference| / bound = %.2g\n", count,
                overlapping / 100.0, worst);
  }
}

TEST(ShadeFiv, ManyOccludersUseTheHeapPathAndStayFinite) {
  const std::vector<float> cube = flat_cube(2, 100.0f);
  const float f[3] = {0.1f, 0.2f, 0.05f};
  std::vector<Shells> occ;
  for (int i = 0; i < 200; ++i) {
    const float centre[3] = {float(i % 20) - 10.0f, 2.0f, float(i / 20) - 5.0f};
    occ.push_back(constant_occluder(f, 0.4f, centre));
  }
  std::vector<FivOccluder> views;
  for (const Shells& o : occ) views.push_back(o.view());
  const float p[3] = {0.1f, 0, 0.2f}, n[3] = {0, 1, 0};
  float fast[3], slow[3];
  shade::shade_fiv({2, cube.data()}, views.data(), 200, p, n, {}, fast);
  shade::shade_fiv_reference({2, cube.data()}, views.data(), 200, p, n, {}, slow);
  // Both accumulate in double from the same float I; they differ by the pair angles (float γ vs
  // double acos: ≤ 1e-6 rad, O's slope in γ ≤ 1/α ≈ 10, times I_i + I_j ≤ 1.2) over the overlapping
  // pairs (≤ 8 neighbours each: ≤ 800), plus the final float rounding (ε · 100): ≤ 1e-4.
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(fast[c], slow[c], 1e-4f);
}

TEST(ShadeFiv, ExtremeInputsStayFinite) {
  const std::vector<float> cube = flat_cube(3, 5.0f);
  const float f[3] = {1, 2, 3}, centre[3] = {1, 2, 3};
  const Shells o = constant_occluder(f, 1.0f, centre);
  Shells tiny = constant_occluder(f, 1e-30f, centre);
  const FivOccluder occ[2] = {o.view(), tiny.view()};
  const float inf = std::numeric_limits<float>::infinity();
  const float points[][3] = {{1, 2, 3}, {1e30f, -1e30f, 1e30f}, {3e38f, 3e38f, -3e38f}, {1, 2, 3.0000001f}, {0, 0, 0}};
  const float normals[][3] = {{0, 1, 0}, {0, 0, 0}, {1e-30f, 0, 0}, {1e30f, 1e30f, 0}, {-1, 0, 0}};
  for (const auto& p : points)
    for (const auto& n : normals) {
      float e[3], s[3];
      shade::shade_fiv({3, cube.data()}, occ, 2, p, n, {}, e);
      shade::shade_fiv_self(o.shells.data(), o.view(), p, n, s);
      for (int c = 0; c < 3; ++c) {
        EXPECT_TRUE(std::isfinite(e[c]) && e[c] >= 0 && e[c] != inf) << p[0] << " " << n[0];
        EXPECT_TRUE(std::isfinite(s[c]) && s[c] >= 0);
      }
    }
  // p exactly at the centre: the disc covers the hemisphere (α = π/2), a = n; with two such
  // occluders O = ½ and the result is that of one.
  const FivOccluder two[2] = {o.view(), o.view()};
  float e1[3], e2[3];
  const float n[3] = {0, 1, 0};
  shade::shade_fiv({3, cube.data()}, two, 2, centre, n, {}, e2);
  shade::shade_fiv({3, cube.data()}, occ, 1, centre, n, {}, e1);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(e2[c], e1[c], 1e-5f);
}

TEST(ShadeFiv, OnlyTheNormalsDirectionCounts) {
  // fiv.h "Numerics": the shading functions use n/|n|. Scaling n by a power of two scales |n| by
  // the same power in double, so n/|n| is the same float vector and every result is bit-equal;
  // a zero or NaN normal is +Y. Before, a non-unit n scaled I = n·F but not E_tot(n̂).
  std::vector<float> cube = flat_cube(3, 5.0f);
  for (size_t i = 0; i < cube.size(); ++i) cube[i] += 0.01f * float(i % 17);  // not constant
  const float f[3] = {0.5f, 1.0f, -0.25f}, c0[3] = {0, 2, 0}, c1[3] = {1.5f, 1, 0.5f};
  const Shells a = constant_occluder(f, 1.0f, c0), b = constant_occluder(f, 0.5f, c1);
  const FivOccluder occ[2] = {a.view(), b.view()};
  const float env[9] = {8, 9, 7, 8.5f, 9.5f, 7.5f, 9, 10, 8};
  const float p[3] = {0.1f, 0.9f, 0.2f}, n[3] = {0.3f, 0.8f, 0.1f};
  auto all = [&](const float nn[3], float out[12]) {
    shade::shade_fiv({3, cube.data()}, occ, 2, p, nn, {}, out);
    shade::shade_fiv_self(env, occ[0], p, nn, out + 3);
    shade::shade_fiv_member(env, occ, 2, 0, p, nn, true, out + 6);
    shade::occluded_irradiance(occ[1], p, nn, true, out + 9);
  };
  float ref[12];
  all(n, ref);
  for (float k : {0x1p100f, 0x1p-100f, 4.0f}) {
    const float scaled[3] = {k * n[0], k * n[1], k * n[2]};
    float got[12];
    all(scaled, got);
    for (int e = 0; e < 12; ++e) EXPECT_EQ(got[e], ref[e]) << "k " << k << " output " << e;
  }
  const float up[3] = {0, 1, 0}, zero[3] = {0, 0, 0}, nan[3] = {std::nanf(""), 0, 0};
  float want[12], got_zero[12], got_nan[12];
  all(up, want);
  all(zero, got_zero);
  all(nan, got_nan);
  for (int e = 0; e < 12; ++e) {
    EXPECT_EQ(got_zero[e], want[e]) << e;
    EXPECT_EQ(got_nan[e], want[e]) << e;
  }
}

TEST(ShadeFiv, DataAtTheValueLimitGivesFiniteOutputsAndMoreIsRefused) {
  // The C API fuzz finding (tests/fuzz/regressions/capi/fiv-scene-shade-member-non-finite): an
  // environment FIV near FLT_MAX and a normal of length 2.6 made n·F^env overflow to +inf, and
  // prt_fiv_scene_shade_member returned PRT_OK with it. Now data beyond 2^64 is refused and only
  // n̂ is used: every output is finite at the limit, for positions up to ±3e38.
  const float L = shade::kFivValueLimit;
  std::vector<float> cube = flat_cube(2, L);
  const float f[3] = {L, -L, L}, centre[3] = {-3e38f, 1, 2};
  Shells o = constant_occluder(f, 1e30f, centre);
  for (float& x : o.shells) x = (&x - o.shells.data()) % 2 ? -L : L;
  Shells near = constant_occluder(f, 2.0f, centre);
  for (int a = 0; a < 3; ++a) near.centre[a] = float(a);
  for (float& x : near.shells) x = L;
  EXPECT_NO_THROW(shade::validate_occluder(o.view()));
  EXPECT_NO_THROW(shade::validate_difmap({2, cube.data()}));
  const float env[9] = {L, L, L, -L, L, -L, L, L, L};
  EXPECT_NO_THROW(shade::validate_environment_fiv(env));
  const FivOccluder occ[3] = {o.view(), near.view(), o.view()};
  const float points[][3] = {{-0.5625f, -1.1875f, 1.1875f}, {3e38f, -3e38f, 3e38f}, {0, 1, 2}, {-3e38f, 1, 2}};
  const float normals[][3] = {{2.4375f, 1.0625f, -0.0625f}, {3e38f, 3e38f, -3e38f}, {1e-38f, 0, 0}, {-1, -1, -1}};
  for (const auto& p : points)
    for (const auto& n : normals) {
      float out[12];
      shade::shade_fiv({2, cube.data()}, occ, 3, p, n, {}, out);
      shade::shade_fiv_self(env, occ[0], p, n, out + 3);
      shade::shade_fiv_member(env, occ, 3, 1, p, n, true, out + 6);
      shade::occluded_irradiance(occ[1], p, n, false, out + 9);
      for (int e = 0; e < 12; ++e) EXPECT_TRUE(std::isfinite(out[e]) && out[e] >= 0) << p[0] << " " << n[0] << " " << e;
    }
  // Refused one float above the limit, through each validator and the C API.
  const float over = std::nextafter(L, 2 * L);
  o.shells[7] = over;
  EXPECT_THROW(shade::validate_occluder(o.view()), std::invalid_argument);
  cube[5] = -over;
  EXPECT_THROW(shade::validate_difmap({2, cube.data()}), std::invalid_argument);
  float env_over[9];
  std::copy(env, env + 9, env_over);
  env_over[4] = over;
  EXPECT_THROW(shade::validate_environment_fiv(env_over), std::invalid_argument);
  cube[5] = L;
  prt_fiv_scene* scene = nullptr;
  EXPECT_EQ(prt_fiv_scene_create(2, cube.data(), env_over, &scene), PRT_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(scene, nullptr);
  EXPECT_NE(std::string(prt_last_error()).find("environment FIV value 4"), std::string::npos) << prt_last_error();
}

TEST(ShadeFiv, OffsetsBeyondFloatRangeAreFormedInDouble) {
  // p − centre = 6e38 overflows float; formed in float it became +inf, was taken for ρ = 0 and
  // the inner shell's FIV hid the whole environment. In double it is far beyond the last shell:
  // the 1/ρ² falloff makes the occluded FIV 0 in float, and E is the environment's n·F^env.
  const float f[3] = {1, 2, 3}, centre[3] = {-3e38f, 0, 0};
  const Shells o = constant_occluder(f, 1.0f, centre);
  const float env[9] = {1, 2, 3, 2, 4, 6, 0.5f, 1, 1.5f};
  const float p[3] = {3e38f, 0, 0}, n[3] = {0, 1, 0};
  float e[3];
  shade::shade_fiv_self(env, o.view(), p, n, e);
  EXPECT_EQ(e[0], 2.0f);
  EXPECT_EQ(e[1], 4.0f);
  EXPECT_EQ(e[2], 1.0f);
}

TEST(ShadeFivSelf, EnvironmentMinusOccludedClamped) {
  const float f[3] = {0.25f, 0.5f, 0.0f}, centre[3] = {0, 0, 0};
  const Shells o = constant_occluder(f, 1.0f, centre);
  const float env[9] = {1, 2, 0, 2, 4, 0, 0.1f, 0.2f, 0};
  const float p[3] = {0.3f, 0.4f, 0}, n[3] = {0.6f, 0.8f, 0};
  float e[3];
  shade::shade_fiv_self(env, o.view(), p, n, e);
  // n·F^env = (2.2, 4.4, 0.22); n·F_c = 0.55 (c + 1): E = (1.65, 3.3, 0) with the last clamped.
  EXPECT_NEAR(e[0], 1.65f, 4 * FLT_EPSILON * 2.2f);
  EXPECT_NEAR(e[1], 3.3f, 4 * FLT_EPSILON * 4.4f);
  EXPECT_EQ(e[2], 0.0f);
}

TEST(ShadeFivMember, OwnSelfShadowsMinusTheOtherOccludersShadows) {
  // A receiver on occluder 0 at the origin, normal +Y, among three others: one wholly above its
  // horizon (case A), one partly (case B, h = 0.5, R = 1: factor 3/4) and one wholly below (case
  // C). With constant FIVs, n·F^env_c = 8 (c + 1) and n·F_self = (c + 1), the composition
  // shade_fiv_self − Σ_others occluded_irradiance is 7 − 2 − ¾·1 − 0 = 4.25 per (c + 1), and
  // without the partial factor 7 − 2 − 1 = 4. Every term is a small binary fraction and every
  // dot product has one non-zero product, so float gives these exactly.
  const float up[3] = {0, 1, 0}, down[3] = {0, -1, 0}, self_f[3] = {0, 1, 0}, a_f[3] = {0, 2, 0};
  const float c_self[3] = {0, 0, 0}, c_a[3] = {0, 3, 0}, c_b[3] = {5, 0.5f, 0}, c_c[3] = {0, -5, 0};
  const Shells self = constant_occluder(self_f, 1.0f, c_self), a = constant_occluder(a_f, 1.0f, c_a),
               b = constant_occluder(self_f, 1.0f, c_b), c = constant_occluder(self_f, 1.0f, c_c);
  const FivOccluder occ[4] = {self.view(), a.view(), b.view(), c.view()};
  float env[9] = {};
  for (int ch = 0; ch < 3; ++ch) env[3 * ch + 1] = 8.0f * float(ch + 1);
  const float p[3] = {0, 0, 0};
  float e[3];
  shade::shade_fiv_member(env, occ, 4, 0, p, up, true, e);
  for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(e[ch], 4.25f * float(ch + 1)) << ch;
  shade::shade_fiv_member(env, occ, 4, 0, p, up, false, e);
  for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(e[ch], 4.0f * float(ch + 1)) << ch;
  // Alone it is shade_fiv_self, bit for bit; facing away from everything, both are 0 (clamped).
  float s[3];
  for (const float* n : {up, down}) {
    shade::shade_fiv_member(env, occ, 1, 0, p, n, true, e);
    shade::shade_fiv_self(env, occ[0], p, n, s);
    for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(e[ch], s[ch]);
  }
  // The others' shadows clamp at 0 (an occluder never adds light): occluder a hiding 10 (c + 1).
  const float big_f[3] = {0, 10, 0};
  const Shells big = constant_occluder(big_f, 1.0f, c_a);
  const FivOccluder two[2] = {self.view(), big.view()};
  shade::shade_fiv_member(env, two, 2, 0, p, up, true, e);
  for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(e[ch], 0.0f);
  // The receiver may be any member: on occluder b (index 2) its own term is 7 (c + 1) at
  // p = centre_b, the others seen from there: a (centre (0, 3, 0), h = 2.5 >= R: case A, the
  // constant lookup 2 (c + 1)), self and c (h = −0.5 and −5.5 relative to p: case B with factor
  // ¼ for self (1 (c + 1) · ¼) and case C for c). 7 − 2 − ¼ = 4.75 per (c + 1).
  shade::shade_fiv_member(env, occ, 4, 2, c_b, up, true, e);
  for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(e[ch], 4.75f * float(ch + 1)) << ch;

  // The C API entry computes the same numbers (it copies the occluders into a scene).
  const std::vector<float> difmap(6 * 1 * 1 * 3, 1.0f);
  prt_fiv_scene* scene = nullptr;
  ASSERT_EQ(prt_fiv_scene_create(1, difmap.data(), env, &scene), PRT_OK);
  for (const FivOccluder& o : occ) {
    const prt_fiv_occluder_desc d{{o.centre[0], o.centre[1], o.centre[2]}, o.radius, o.n_rho, o.n_theta, o.n_phi,
                                  o.radii, o.shells, o.valid};
    int index = -1;
    ASSERT_EQ(prt_fiv_scene_add_occluder(scene, &d, &index), PRT_OK);
  }
  const float points[6] = {0, 0, 0, 5, 0.5f, 0}, normals[6] = {0, 1, 0, 0, 1, 0};
  float out[6];
  ASSERT_EQ(prt_fiv_scene_shade_member(scene, 0, points, normals, 2, 1, out), PRT_OK);
  for (int k = 0; k < 2; ++k) {
    shade::shade_fiv_member(env, occ, 4, 0, points + 3 * k, normals + 3 * k, true, e);
    for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(out[3 * k + ch], e[ch]);
  }
  EXPECT_NE(prt_fiv_scene_shade_member(scene, 4, points, normals, 1, 1, out), PRT_OK);  // no occluder 4
  // Given its own self-shadows, shade_fiv_member_given_self subtracts the same others' shadows:
  // shade_fiv_member bit for bit when given shade_fiv_self, 3 − 2 − ¾ = ¼ per (c + 1) given
  // 3 (c + 1), and a negative given value counts as 0. The C API entry computes the same.
  float own[3], given[3] = {3, 6, 9}, negative[3] = {-1, -1, -1};
  shade::shade_fiv_self(env, occ[0], p, up, own);
  shade::shade_fiv_member_given_self(own, occ, 4, 0, p, up, true, s);
  shade::shade_fiv_member(env, occ, 4, 0, p, up, true, e);
  for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(s[ch], e[ch]);
  shade::shade_fiv_member_given_self(given, occ, 4, 0, p, up, true, e);
  // (Within 4 ulps: the lookups' trilinear weights round, which 7 (c + 1) above absorbed.)
  for (int ch = 0; ch < 3; ++ch) EXPECT_FLOAT_EQ(e[ch], 0.25f * float(ch + 1)) << ch;
  shade::shade_fiv_member_given_self(negative, occ, 1, 0, p, up, true, e);
  for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(e[ch], 0.0f);
  const float given2[6] = {3, 6, 9, 3, 6, 9};
  ASSERT_EQ(prt_fiv_scene_shade_member_given_self(scene, 0, points, normals, given2, 2, 1, out), PRT_OK);
  for (int k = 0; k < 2; ++k) {
    shade::shade_fiv_member_given_self(given2 + 3 * k, occ, 4, 0, points + 3 * k, normals + 3 * k, true, e);
    for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(out[3 * k + ch], e[ch]);
  }
  const float nan3[3] = {std::numeric_limits<float>::quiet_NaN(), 0, 0};
  EXPECT_EQ(prt_fiv_scene_shade_member_given_self(scene, 0, points, normals, nan3, 1, 1, out), PRT_ERROR_INVALID_ARGUMENT);
  prt_fiv_scene_destroy(scene);
}

TEST(Validate, RejectsBrokenOccludersAndMaps) {
  const float f[3] = {1, 0, 0}, centre[3] = {0, 0, 0};
  Shells o = constant_occluder(f, 1.0f, centre);
  EXPECT_NO_THROW(shade::validate_occluder(o.view()));
  FivOccluder v = o.view();
  v.radius = 0;
  EXPECT_THROW(shade::validate_occluder(v), std::invalid_argument);
  v = o.view();
  v.n_theta = 1;
  EXPECT_THROW(shade::validate_occluder(v), std::invalid_argument);
  v = o.view();
  v.shells = nullptr;
  EXPECT_THROW(shade::validate_occluder(v), std::invalid_argument);
  o.radii = {1.0f, 1.0f};
  EXPECT_THROW(shade::validate_occluder(o.view()), std::invalid_argument);
  o.radii = {1.0f, 2.0f};
  o.shells[5] = std::numeric_limits<float>::quiet_NaN();
  try {
    shade::validate_occluder(o.view());
    FAIL() << "NaN accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("shell value 5 = "), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("must be finite"), std::string::npos) << e.what();
  }
  const std::vector<float> cube = flat_cube(2, 1.0f);
  EXPECT_NO_THROW(shade::validate_difmap({2, cube.data()}));
  EXPECT_THROW(shade::validate_difmap({0, cube.data()}), std::invalid_argument);
  EXPECT_THROW(shade::validate_difmap({2, nullptr}), std::invalid_argument);
}

// ---- Surface-following shells (radial_scheme = kFivRadialSurface, issue 33) -------------------

// Shells with a surface radius r_surf[i][j]: radii become the offsets τ_k = 0.5·2^k (geometric,
// exact in float) and sample (k, i, j) sits at (r_surf[i][j] + τ_k) d(θ_i, φ_j).
struct SurfaceShells : Shells {
  std::vector<float> surface;
  template <class F, class R>
  SurfaceShells(int nr, int nt, int np, F value, R r_surf) : Shells(nr, nt, np, value) {
    for (int i = 0; i < nt; ++i)
      for (int j = 0; j < np; ++j) surface.push_back(r_surf(i, j));
  }
  float r(int i, int j) const { return surface[size_t(i) * size_t(n_phi) + size_t(j)]; }
  FivOccluder view() const {
    FivOccluder v = Shells::view();
    v.radial_scheme = shade::kFivRadialSurface;
    v.surface_radius = surface.data();
    v.valid = nullptr;  // not read by the surface scheme
    return v;
  }
};

// A bumpy outer surface: r_surf between 0.3 and 1.5, different in every direction.
float bumpy(int i, int j) { return 0.9f + 0.6f * float(std::sin(1.7 * i + 0.3) * std::cos(2.3 * j + 0.1)); }

TEST(LookupFivSurface, GridPointsGiveTheStoredSamples) {
  SurfaceShells o(4, 5, 8, linear_value, bumpy);
  // Away from the poles, where every j is the same direction (a bake stores one value there).
  for (int k = 0; k < o.n_rho; ++k)
    for (int i = 1; i < o.n_theta - 1; ++i)
      for (int j = 0; j < o.n_phi; ++j) {
        float s[3], out[9];
        offset_at(o, i, j, double(o.r(i, j)) + o.radii[size_t(k)], s);
        shade::lookup_fiv(o.view(), s, out);
        // The angles' float round trip (kAngleRoundTrip per unit slope of linear_value) moves r_s
        // by up to 1.2 per grid unit as well: τ and so k move by ≤ 1e-6 · 1.2 / (τ_k+1 − τ_k).
        for (int e = 0; e < 9; ++e) EXPECT_NEAR(out[e], o.at(k, i, j, e), kAngleRoundTrip * 8) << k << i << j;
      }
}

TEST(LookupFivSurface, LinearInTheOffsetAndClampedInsideTheHull) {
  SurfaceShells o(4, 5, 8, linear_value, bumpy);
  const int i = 2, j = 2;  // θ = π/2, φ = π/2: direction +X, exact angles
  auto at_rho = [&](double rho, float out[9]) {
    const float s[3] = {float(rho), 0, 0};
    shade::lookup_fiv(o.view(), s, out);
  };
  const double r = o.r(i, j);
  float a[9];
  // τ halfway between τ_1 = 1 and τ_2 = 2: the mean of the two shells (ρ rounded to float:
  // ≤ 6e-8 · 3 of a 1-wide step, times the 0.5 slope).
  at_rho(r + 1.5, a);
  for (int e = 0; e < 9; ++e) EXPECT_NEAR(a[e], 0.5f * (o.at(1, i, j, e) + o.at(2, i, j, e)), 1e-6f);
  // Inside the outer hull (τ < τ_0): the first shell; at the centre, that of d = +Y (the pole).
  for (double rho : {r + 0.25, r - 0.2}) {
    at_rho(rho, a);
    for (int e = 0; e < 9; ++e) EXPECT_EQ(a[e], o.at(0, i, j, e)) << rho;
  }
  at_rho(0.0, a);
  for (int e = 0; e < 9; ++e) EXPECT_EQ(a[e], o.at(0, 0, 0, e));
  // Beyond the last offset: the last shell times ((r_s + τ_last)/ρ)².
  const double far = r + o.radii.back();
  at_rho(2 * far, a);
  for (int e = 0; e < 9; ++e) EXPECT_NEAR(a[e], o.at(3, i, j, e) / 4.0f, 1e-6f * std::abs(o.at(3, i, j, e)));
}

// The lookup has no jumps: across the (θ, φ) cell edges (where the bilinear r_s changes its
// weights) and across every shell offset, a step of δ changes F by at most a Lipschitz bound times
// δ. linear_value changes by ≤ 1.2 per grid unit in k, i, j; r_s by ≤ 2 per grid unit; k by ≤ 1 / (the
// smallest step 0.5) per unit of τ: |dF| <= (1.2 (1 + 2 / 0.5 · dρ/d(grid)) + …) — a jump of
// a sample's size (≥ 0.125) would exceed the bound 50 δ by far.
TEST(LookupFivSurface, ContinuousAcrossCellsAndShells) {
  SurfaceShells o(5, 9, 16, linear_value, bumpy);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u01(0, 1);
  const double delta = 1e-4;
  double worst = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    // A point on a cell edge in u (integer u) or t, or on a shell (τ = τ_k), and its neighbour δ away.
    double t = 1 + u01(rng) * (o.n_theta - 3), u = u01(rng) * o.n_phi, tau = 0.5 * std::pow(2.0, u01(rng) * 4);
    switch (trial % 3) {
      case 0: u = std::floor(u); break;
      case 1: t = std::floor(t); break;
      default: tau = 0.5 * std::pow(2.0, double(trial % 5)); break;
    }
    const int i0 = std::min(int(t), o.n_theta - 2), j0 = int(u) % o.n_phi, j1 = (j0 + 1) % o.n_phi;
    const double ft = t - i0, fu = u - std::floor(u);
    const double rs = (1 - ft) * ((1 - fu) * o.r(i0, j0) + fu * o.r(i0, j1)) + ft * ((1 - fu) * o.r(i0 + 1, j0) + fu * o.r(i0 + 1, j1));
    float s0[3], s1[3], a[9], b[9];
    offset_at(o, t - delta, u - delta, rs + tau - delta, s0);
    offset_at(o, t + delta, u + delta, rs + tau + delta, s1);
    shade::lookup_fiv(o.view(), s0, a);
    shade::lookup_fiv(o.view(), s1, b);
    for (int e = 0; e < 9; ++e) worst = std::max(worst, std::fabs(double(a[e]) - b[e]));
  }
  EXPECT_LT(worst, 50 * 2 * delta);
  EXPECT_GT(worst, 0.0);
}

TEST(LookupFivSurface, ShadeFivMatchesTheSlowReferenceAndIgnoresValid) {
  std::mt19937 rng(34);
  std::uniform_real_distribution<float> u01(0, 1);
  SurfaceShells asset(12, 17, 32, [&](int, int, int, int) { return u01(rng); }, bumpy);
  const std::vector<float> cube = flat_cube(4, 400.0f);
  std::vector<FivOccluder> views;
  for (int i = 0; i < 30; ++i) {
    FivOccluder v = asset.view();
    v.centre[0] = 20 * u01(rng) - 10, v.centre[1] = 3 * u01(rng) - 0.5f, v.centre[2] = 20 * u01(rng) - 10;
    v.radius = 1.5f + u01(rng);
    views.push_back(v);
  }
  std::vector<uint8_t> zeros(asset.valid.size(), 0);
  for (int trial = 0; trial < 100; ++trial) {
    const float p[3] = {20 * u01(rng) - 10, 0, 20 * u01(rng) - 10}, n[3] = {0.1f, 1, -0.2f};
    float fast[3], slow[3], masked[3];
    shade::shade_fiv({4, cube.data()}, views.data(), int(views.size()), p, n, {}, fast);
    shade::shade_fiv_reference({4, cube.data()}, views.data(), int(views.size()), p, n, {}, slow);
    for (FivOccluder& v : views) v.valid = zeros.data();
    shade::shade_fiv({4, cube.data()}, views.data(), int(views.size()), p, n, {}, masked);
    for (FivOccluder& v : views) v.valid = nullptr;
    for (int c = 0; c < 3; ++c) {
      // ScatteredOccludersMatchTheSlowReference's bounds: 1e-5 per lookup (angles from the
      // polynomial atan2) and 7e-7 rad of the overlap angles over ~α (here ≥ 0.1 rad).
      EXPECT_NEAR(fast[c], slow[c], 4 * FLT_EPSILON * slow[c] + 1e-5 * 30 + 7e-7 / (kPi * 0.1) * 2 * 400 * 30);
      EXPECT_EQ(masked[c], fast[c]) << "the surface scheme reads no valid mask";
    }
  }
}

TEST(Validate, SurfaceSchemeNeedsGeometricOffsetsAndFiniteSurfaceRadii) {
  SurfaceShells o(4, 5, 8, linear_value, bumpy);
  EXPECT_NO_THROW(shade::validate_occluder(o.view()));
  FivOccluder v = o.view();
  v.surface_radius = nullptr;
  EXPECT_THROW(shade::validate_occluder(v), std::invalid_argument);
  v = o.view();
  v.radial_scheme = 2;
  EXPECT_THROW(shade::validate_occluder(v), std::invalid_argument);
  o.radii[2] = 2.5f;  // 0.5, 1, 2.5, 4: increasing but not geometric
  EXPECT_THROW(shade::validate_occluder(o.view()), std::invalid_argument);
  o.radii[2] = 2.0f;
  o.surface[3] = -0.1f;
  EXPECT_THROW(shade::validate_occluder(o.view()), std::invalid_argument);
  o.surface[3] = std::numeric_limits<float>::infinity();
  EXPECT_THROW(shade::validate_occluder(o.view()), std::invalid_argument);
  // The geometric scheme still needs its valid mask.
  v = o.Shells::view();
  v.valid = nullptr;
  EXPECT_THROW(shade::validate_occluder(v), std::invalid_argument);
}

} // namespace

// ---- the tight proxy (prtshade/fiv.h "Tight proxies") -------------------------------------------

namespace cones {

// K(x, α) by the midpoint rule in the cap's own frame (polar angle t from the axis, azimuth q):
// ν·ω = x cos t + √(1 − x²) sin t cos q, weight sin t. The integrand is Lipschitz with constant
// <= 1 and its kink (ν·ω = 0) crosses ~M of the M × 2M cells, each off by <= its area times its
// width: the rule errs by <= π²/M (4e-4 at M = 25,000 would do; 2,000 gives <= 5e-3, and the
// observed error is far below since the kink's errors cancel in sign).
double cap_by_quadrature(double x, double alpha, int M) {
  const double y = std::sqrt(std::max(0.0, 1 - x * x));
  double sum = 0;
  for (int i = 0; i < M; ++i) {
    const double t = (i + 0.5) / M * alpha;
    double ring = 0;
    for (int j = 0; j < 2 * M; ++j) {
      const double q = (j + 0.5) / (2 * M) * 2 * kPi;
      ring += std::max(0.0, x * std::cos(t) + y * std::sin(t) * std::cos(q));
    }
    sum += ring * std::sin(t);
  }
  return sum * (alpha / M) * (2 * kPi / (2 * M));
}

} // namespace cones

TEST(CapClampedCosine, MatchesNumericalIntegration) {
  constexpr int kM = 600;
  constexpr double kQuadrature = kPi * kPi / kM;  // the midpoint rule's bound above
  for (const double alpha : {0.05, 0.4, 1.0, kPi / 2, 2.2, 3.0})
    for (const double x : {-0.99, -0.6, -0.2, 0.0, 0.15, 0.5, 0.93, 1.0}) {
      const double closed = shade::cap_clamped_cosine(x, std::cos(alpha));
      const double numeric = cones::cap_by_quadrature(x, alpha, kM);
      EXPECT_NEAR(closed, numeric, kQuadrature * (1 - std::cos(alpha))) << "x " << x << " alpha " << alpha;
    }
}

TEST(CapClampedCosine, CasesAndLimits) {
  // Wholly above: π x sin²α; wholly below: 0; the hemisphere (α = π/2): π(1 + x)/2; the whole
  // sphere: π; continuous where the horizon starts cutting (x = ±sin α), to double rounding.
  const double a = 0.5, s = std::sin(a), c = std::cos(a);
  EXPECT_NEAR(shade::cap_clamped_cosine(0.9, c), kPi * 0.9 * s * s, 1e-15);
  EXPECT_EQ(shade::cap_clamped_cosine(-0.9, c), 0.0);
  for (const double x : {-0.7, 0.0, 0.4})
    EXPECT_NEAR(shade::cap_clamped_cosine(x, 0.0), kPi * (1 + x) / 2, 1e-14) << x;
  EXPECT_NEAR(shade::cap_clamped_cosine(0.3, -1.0), kPi, 1e-14);
  EXPECT_NEAR(shade::cap_clamped_cosine(s - 1e-9, c), kPi * s * s * s, 1e-7);
  EXPECT_NEAR(shade::cap_clamped_cosine(-s + 1e-9, c), 0.0, 1e-7);
  // The complement: K(x, α) + K(−x, π − α) = π.
  EXPECT_NEAR(shade::cap_clamped_cosine(0.2, std::cos(2.5)) + shade::cap_clamped_cosine(-0.2, std::cos(kPi - 2.5)), kPi, 1e-14);
}

namespace cones {

// The exact cone table of a ball of radius r about the centre, on the shells of `o`: from
// distance ρ > r it hides the cap of sin α = r/ρ around −d, Ω = 2π(1 − cos α), m = π sin²α (−d);
// inside (ρ <= r) the sample is invalid (the whole sphere, Ω = 4π, m = 0).
std::vector<float> ball_cones(Shells& o, double r) {
  std::vector<float> out;
  for (int k = 0; k < o.n_rho; ++k)
    for (int i = 0; i < o.n_theta; ++i)
      for (int j = 0; j < o.n_phi; ++j) {
        const double th = kPi * i / (o.n_theta - 1), ph = 2 * kPi * j / o.n_phi, rho = o.radii[size_t(k)];
        const double d[3] = {std::sin(th) * std::sin(ph), std::cos(th), std::sin(th) * std::cos(ph)};
        if (rho <= r) {
          o.valid[o.index(k, i, j)] = 0;
          out.insert(out.end(), {0.0f, 0.0f, 0.0f, float(4 * kPi)});
          continue;
        }
        const double sa = r / rho, ca = std::sqrt(1 - sa * sa), len = kPi * sa * sa;
        out.insert(out.end(), {float(-len * d[0]), float(-len * d[1]), float(-len * d[2]), float(2 * kPi * (1 - ca))});
      }
  return out;
}

} // namespace cones

TEST(LookupCone, SameStencilAsTheShells) {
  // A cone table holding the shells' first four components: lookup_cone returns lookup_fiv's
  // first four values bit for bit (same weights, mask and falloff; the same float operations).
  Shells o(4, 9, 16, linear_value);
  std::vector<float> table;
  for (size_t s = 0; s < o.shells.size() / 9; ++s)
    for (int e = 0; e < 4; ++e) table.push_back(o.shells[s * 9 + size_t(e)]);
  o.valid[o.index(1, 3, 5)] = 0, o.valid[o.index(2, 4, 7)] = 0;
  FivOccluder v = o.view();
  v.cones = table.data();
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-6, 6);
  for (int trial = 0; trial < 500; ++trial) {
    const float s[3] = {u(rng), u(rng), u(rng)};
    float f[9], c[4];
    shade::lookup_fiv(v, s, f);
    shade::lookup_cone(v, s, c);
    for (int e = 0; e < 4; ++e) EXPECT_EQ(c[e], f[e]) << trial << " " << e;
  }
}

TEST(ShadeFivCone, ABallsConeIsItsBoundingSphere) {
  // Occluders whose cone table is the exact cone of their bounding ball: the cone proxy's discs
  // are the sphere's up to the table's interpolation (Ω and m linear between samples, the cap's α
  // within ~1e-3 rad of asin(R/D) on this 64x33 grid of radii 1.05 R … 20 R), and its overlap
  // term is the lens times the lower density (fiv.h "Tight proxies") — formed here from the
  // spheres' discs in double.
  const std::vector<float> cube = flat_cube(4, 40.0f);
  const DifMap map{4, cube.data()};
  const float f[3] = {0, 1, 0};
  std::vector<Shells> owners;
  std::vector<std::vector<float>> tables;
  const float centres[3][3] = {{0, 3, 0}, {1.2f, 3.2f, 0.4f}, {-0.8f, 2.6f, 1.0f}};
  for (const auto& c : centres) {
    Shells o = constant_occluder(f, 1.0f, c);
    o = Shells(40, 33, 64, [&](int, int, int, int e) { return e % 3 == 1 ? 1.0f : 0.0f; });
    for (int k = 0; k < 40; ++k) o.radii[size_t(k)] = float(1.05 * std::pow(20.0 / 1.05, k / 39.0));
    for (int a = 0; a < 3; ++a) o.centre[a] = c[a];
    tables.push_back(cones::ball_cones(o, 1.0));
    owners.push_back(o);
  }
  std::vector<FivOccluder> views;
  for (size_t k = 0; k < owners.size(); ++k) {
    views.push_back(owners[k].view());
    views.back().cones = tables[k].data();
  }
  const float p[3] = {0.1f, 0, -0.2f}, n[3] = {0, 1, 0};
  float sphere[3], cone[3], none[3];
  shade::shade_fiv(map, views.data(), 3, p, n, {false, true, shade::FivProxy::sphere}, sphere);
  shade::shade_fiv(map, views.data(), 3, p, n, {false, true, shade::FivProxy::cone}, cone);
  shade::shade_fiv(map, views.data(), 3, p, n, {false, false, shade::FivProxy::cone}, none);
  // I = n·F = 1 per occluder (the shells' y components); the expected E from the spheres' discs.
  double axis[3][3], alpha[3];
  for (int i = 0; i < 3; ++i) {
    double d[3], D = 0;
    for (int a = 0; a < 3; ++a) d[a] = double(centres[i][a]) - p[a], D += d[a] * d[a];
    D = std::sqrt(D);
    for (int a = 0; a < 3; ++a) axis[i][a] = d[a] / D;
    alpha[i] = std::asin(1.0 / D);
  }
  double expect = 40.0 - 3.0, sphere_expect = 40.0 - 3.0;
  for (int i = 0; i < 3; ++i)
    for (int j = i + 1; j < 3; ++j) {
      const double g = std::acos(axis[i][0] * axis[j][0] + axis[i][1] * axis[j][1] + axis[i][2] * axis[j][2]);
      expect += shade::lens_area(alpha[i], alpha[j], g) * std::min(1 / (kPi * alpha[i] * alpha[i]), 1 / (kPi * alpha[j] * alpha[j]));
      sphere_expect += 2 * shade::overlap_fraction(alpha[i], alpha[j], g);
    }
  // Each lens term moves by <= (its chord 2 α_min + the density's 2/α_min) Δα per unit I with
  // Δα <= 1e-3 and α_min ≈ 0.3: <= 0.01 per pair, three pairs.
  const double bound = 3 * 0.01;
  EXPECT_GT(sphere[1] - none[1], 0.3f);  // the overlap correction matters here
  EXPECT_NEAR(sphere[1], sphere_expect, 1e-5);
  EXPECT_NEAR(cone[1], expect, bound);
  EXPECT_LT(cone[1], sphere[1]);  // the lower density: never more than eq. 14
}

TEST(ShadeFivCone, PartialCorrectionAddsTheCapBelowTheHorizon) {
  // One ball occluder straddling the receiver's horizon, a DifMap whose lower half is brighter:
  // with the cone proxy, I = max(0, n·F + L̄ K(−n·a, α)) with L̄ = E_tot(−n)/π (fiv.h "Tight
  // proxies"); wholly above, I = n·F exactly; the sphere's case C still gives 0.
  Cube cube(4);
  const float f[3] = {0.3f, 0.7f, -0.2f};
  const float c[3] = {0, 0.1f, 3.0f};
  Shells o = constant_occluder(f, 1.0f, c);
  o = Shells(40, 33, 64, [&](int, int, int, int e) { return f[e % 3] * float(1 + e / 3); });
  for (int k = 0; k < 40; ++k) o.radii[size_t(k)] = float(1.05 * std::pow(20.0 / 1.05, k / 39.0));
  for (int a = 0; a < 3; ++a) o.centre[a] = c[a];
  const std::vector<float> table = cones::ball_cones(o, 1.0);
  FivOccluder v = o.view();
  v.cones = table.data();
  const float p[3] = {0, 0, 0}, n[3] = {0, 1, 0};
  float e_on[3], e_off[3], tot[3], below[3], F[9], cone[4];
  shade::shade_fiv(cube.view(), &v, 1, p, n, {true, false, shade::FivProxy::cone}, e_on);
  shade::shade_fiv(cube.view(), &v, 1, p, n, {false, false, shade::FivProxy::cone}, e_off);
  shade::lookup_difmap(cube.view(), n, tot);
  const float down[3] = {0, -1, 0};
  shade::lookup_difmap(cube.view(), down, below);
  const float s[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]};
  shade::lookup_fiv(v, s, F);
  shade::lookup_cone(v, s, cone);
  const double ml = std::sqrt(double(cone[0]) * cone[0] + double(cone[1]) * cone[1] + double(cone[2]) * cone[2]);
  const double x = cone[1] / ml;  // n·a
  const double K = shade::cap_clamped_cosine(-x, 1 - cone[3] / (2 * kPi));
  ASSERT_GT(K, 0.01);  // the cap reaches below the horizon (K is small there: |n·ω| <= sin α below it)
  for (int ch = 0; ch < 3; ++ch) {
    const double nF = F[3 * ch + 1];
    const double expect = tot[ch] - std::max(0.0, nF + below[ch] / kPi * K);
    // The fast path's K and a in float with poly_atan2: within ~1e-5 of K; E in float.
    EXPECT_NEAR(e_on[ch], expect, 1e-5 * (1 + below[ch]) + 4 * FLT_EPSILON * tot[ch]) << ch;
    EXPECT_NEAR(e_off[ch], tot[ch] - std::max(0.0, nF), 4 * FLT_EPSILON * tot[ch]) << ch;
  }
  // Raised wholly above the horizon (h = 2.4 > sin α's reach): the correction vanishes exactly.
  v.centre[1] = 2.4f;
  float hi_on[3], hi_off[3];
  shade::shade_fiv(cube.view(), &v, 1, p, n, {true, false, shade::FivProxy::cone}, hi_on);
  shade::shade_fiv(cube.view(), &v, 1, p, n, {false, false, shade::FivProxy::cone}, hi_off);
  for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(hi_on[ch], hi_off[ch]) << ch;
  // Sunk below (h <= −R): case C.
  v.centre[1] = -1.2f;
  float lo[3];
  shade::shade_fiv(cube.view(), &v, 1, p, n, {true, false, shade::FivProxy::cone}, lo);
  for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(lo[ch], tot[ch]) << ch;
}

// The fast path against the slow reference with the cone proxy: 100 scattered instances of one
// asset with an exact ball cone table (r = 0.7 R), receivers on the ground. Besides the sphere
// test's terms (kLookup per occluder, 4 ε E), the cones differ by the grid angles' kAngle: Ω and
// m move by <= their change per grid step (<= |∂Ω/∂θ| ≈ 2π sin α cos α ≤ π per radian of view
// angle, times the lookups' 4e-6 steps) and α, a by <= kCone = 1e-5 rad (with α >= 0.03 here:
// dα = dΩ/(2π sin α)); K then moves by <= π Δx + 2π Δα <= 3π kCone times L̄, and each pair's
// term A_ij min(I_i/A_i, I_j/A_j) (<= O_ij (I_i + I_j)) by <= (2 min α for the lens + 4/min α for the
// densities' α²) kCone times I_i + I_j <= 6 kCone / min α (I_i + I_j) (α <= π/2).
TEST(ShadeFivCone, ScatteredOccludersMatchTheSlowReference) {
  constexpr double kLookup = 1e-5, kCone = 1e-5;
  std::mt19937 rng(34);
  std::uniform_real_distribution<float> u01(0, 1);
  Shells asset(12, 17, 32, [&](int, int, int, int) { return u01(rng); });
  for (int k = 0; k < 12; ++k) asset.radii[size_t(k)] = float(0.75 * std::pow(40.0 / 0.75, k / 11.0));
  const std::vector<float> table = cones::ball_cones(asset, 0.7);
  Cube cube(4);
  for (float& t : cube.texels) t += 300.0f;  // bright enough that E does not clamp to 0
  const int count = 100;
  std::vector<FivOccluder> views;
  for (int i = 0; i < count; ++i) {
    FivOccluder v = asset.view();
    v.cones = table.data();
    v.centre[0] = 40 * u01(rng) - 20, v.centre[1] = 3.0f * u01(rng) - 0.5f, v.centre[2] = 40 * u01(rng) - 20;
    views.push_back(v);
  }
  double worst = 0;
  int overlapping = 0, partial = 0;
  for (int trial = 0; trial < 100; ++trial) {
    const float p[3] = {40 * u01(rng) - 20, 0, 40 * u01(rng) - 20};
    float n[3] = {u01(rng) - 0.5f, 1.0f, u01(rng) - 0.5f};
    float fast[3], slow[3], off[3];
    shade::shade_fiv(cube.view(), views.data(), count, p, n, {}, fast);
    shade::shade_fiv_reference(cube.view(), views.data(), count, p, n, {}, slow);
    shade::shade_fiv_reference(cube.view(), views.data(), count, p, n, {false, true}, off);
    partial += slow[0] != off[0];
    // The reference's discs and I (the cone's axis and α from the table).
    const double len = std::sqrt(double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2]);
    const float nu[3] = {float(n[0] / len), float(n[1] / len), float(n[2] / len)};
    float below[3];
    const float down[3] = {-nu[0], -nu[1], -nu[2]};
    shade::lookup_difmap(cube.view(), down, below);
    std::vector<std::array<double, 4>> disc;
    std::vector<std::array<double, 3>> Ib;  // I_i per channel as the reference forms it
    for (const FivOccluder& v : views) {
      if (!(double(nu[0]) * (v.centre[0] - p[0]) + double(nu[1]) * (v.centre[1] - p[1]) + double(nu[2]) * (v.centre[2] - p[2]) > -v.radius))
        continue;
      const float s[3] = {p[0] - v.centre[0], p[1] - v.centre[1], p[2] - v.centre[2]};
      float c4[4], F[9];
      shade::lookup_cone(v, s, c4);
      shade::lookup_fiv(v, s, F);
      const double ml = std::sqrt(double(c4[0]) * c4[0] + double(c4[1]) * c4[1] + double(c4[2]) * c4[2]);
      disc.push_back({c4[0] / ml, c4[1] / ml, c4[2] / ml, std::acos(std::max(0.0, 1 - c4[3] / (2 * kPi)))});
      const double x = nu[0] * disc.back()[0] + nu[1] * disc.back()[1] + nu[2] * disc.back()[2];
      const double K = shade::cap_clamped_cosine(-x, 1 - c4[3] / (2 * kPi));
      std::array<double, 3> I{};
      for (int c = 0; c < 3; ++c)
        I[size_t(c)] = std::max(0.0, nu[0] * F[3 * c] + nu[1] * F[3 * c + 1] + nu[2] * F[3 * c + 2] + below[c] / kPi * K);
      Ib.push_back(I);
    }
    for (int c = 0; c < 3; ++c) {
      ASSERT_GT(slow[c], 0.0f) << "the scene must not clamp E to 0, or nothing is compared";
      double tolerance = 4 * double(FLT_EPSILON) * slow[c] + kLookup * double(disc.size()) +
                         3 * kPi * kCone * double(below[c]) / kPi * double(disc.size());
      for (size_t i = 0; i < disc.size(); ++i)
        for (size_t j = i + 1; j < disc.size(); ++j) {
          const double cg = disc[i][0] * disc[j][0] + disc[i][1] * disc[j][1] + disc[i][2] * disc[j][2];
          if (std::acos(std::clamp(cg, -1.0, 1.0)) >= disc[i][3] + disc[j][3] + 2 * kCone) continue;
          overlapping += c == 0;
          tolerance += 6 * kCone / std::min(disc[i][3], disc[j][3]) * (Ib[i][size_t(c)] + Ib[j][size_t(c)]);
        }
      EXPECT_NEAR(fast[c], slow[c], tolerance) << trial << " " << c;
      worst = std::max(worst, std::fabs(double(fast[c]) - slow[c]) / tolerance);
    }
  }
  EXPECT_GT(overlapping, 20);  // the overlap pass was exercised
  EXPECT_GT(partial, 20);      // and the partial correction
  std::printf("cones: %.1f overlapping pairs per receiver, largest |fast - reference| / bound = %.2g\n", overlapping / 100.0, worst);
}

TEST(ShadeFivCone, TheCApiCopiesTheConeTableAndHonoursSphereProxy) {
  // prt_fiv_scene_add_occluder copies desc.cones; prt_fiv_options.sphere_proxy selects the sphere.
  Cube cube(4);
  const float f[3] = {0.3f, 0.7f, -0.2f};
  std::vector<Shells> owners;
  std::vector<std::vector<float>> tables;
  const float centres[2][3] = {{0, 0.1f, 3.0f}, {0.8f, 0.6f, 3.4f}};
  for (const auto& c : centres) {
    Shells o(12, 17, 32, [&](int, int, int, int e) { return f[e % 3] * float(1 + e / 3); });
    for (int k = 0; k < 12; ++k) o.radii[size_t(k)] = float(1.05 * std::pow(20.0 / 1.05, k / 11.0));
    for (int a = 0; a < 3; ++a) o.centre[a] = c[a];
    tables.push_back(cones::ball_cones(o, 0.8));
    owners.push_back(o);
  }
  std::vector<FivOccluder> views;
  prt_fiv_scene* scene = nullptr;
  const float env[9] = {};
  ASSERT_EQ(prt_fiv_scene_create(4, cube.texels.data(), env, &scene), PRT_OK);
  for (size_t k = 0; k < owners.size(); ++k) {
    views.push_back(owners[k].view());
    views.back().cones = tables[k].data();
    const FivOccluder& o = views.back();
    const prt_fiv_occluder_desc d{{o.centre[0], o.centre[1], o.centre[2]}, o.radius, o.n_rho, o.n_theta, o.n_phi,
                                  o.radii, o.shells, o.valid, o.radial_scheme, o.surface_radius, o.cones};
    ASSERT_EQ(prt_fiv_scene_add_occluder(scene, &d, nullptr), PRT_OK);
  }
  for (std::vector<float>& t : tables) std::fill(t.begin(), t.end(), 0.0f);  // the scene holds its own copy
  const std::vector<std::vector<float>> copies = {cones::ball_cones(owners[0], 0.8), cones::ball_cones(owners[1], 0.8)};
  for (size_t k = 0; k < views.size(); ++k) views[k].cones = copies[k].data();
  const float points[6] = {0, 0, 0, 0.5f, 0, 0.4f}, normals[6] = {0, 1, 0, 0.1f, 1, 0};
  for (const int sphere : {0, 1}) {
    const prt_fiv_options options{1, 1, sphere};
    float out[6], e[3];
    ASSERT_EQ(prt_fiv_scene_shade(scene, points, normals, 2, &options, out), PRT_OK);
    for (int k = 0; k < 2; ++k) {
      shade::shade_fiv(cube.view(), views.data(), 2, points + 3 * k, normals + 3 * k,
                       {true, true, sphere ? shade::FivProxy::sphere : shade::FivProxy::cone}, e);
      for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(out[3 * k + ch], e[ch]) << sphere << " " << k << " " << ch;
    }
  }
  prt_fiv_scene_destroy(scene);
}

TEST(Validate, RejectsBrokenConeTables) {
  const float f[3] = {1, 0, 0}, centre[3] = {0, 0, 0};
  Shells o = constant_occluder(f, 1.0f, centre);
  std::vector<float> table(o.shells.size() / 9 * 4, 0.0f);
  for (size_t s = 0; s < table.size() / 4; ++s) table[4 * s + 2] = 0.5f, table[4 * s + 3] = 1.0f;  // |m| <= Ω
  FivOccluder v = o.view();
  v.cones = table.data();
  EXPECT_NO_THROW(shade::validate_occluder(v));
  for (const auto& [index, value] : std::vector<std::pair<size_t, float>>{
           {3, -0.5f}, {3, 13.0f}, {3, std::numeric_limits<float>::quiet_NaN()}, {2, 1.5f}, {0, -std::numeric_limits<float>::infinity()}}) {
    std::vector<float> bad = table;
    bad[4 + index] = value;  // sample 1
    v.cones = bad.data();
    EXPECT_THROW(shade::validate_occluder(v), std::invalid_argument) << index << " " << value;
  }
}

// ---------------------------------------------------------------------------------------------
// Half-float tables (prtshade/fiv.h "Half-float tables")

namespace halves {

std::vector<uint16_t> bits_of(const std::vector<float>& values) {
  std::vector<uint16_t> out;
  for (float v : values) out.push_back(Imath::half(v).bits());
  return out;
}
void round_to_half(std::vector<float>& values) {
  for (float& v : values) v = float(Imath::half(v));
}

} // namespace halves

// half_to_float against OpenEXR's Imath::half for every finite binary16 value, bit for bit
// (subnormals, ±0 and 65504 among them).
TEST(HalfTables, HalfToFloatIsExactForEveryFiniteHalf) {
  int checked = 0;
  for (uint32_t b = 0; b < 0x10000u; ++b) {
    if ((b & 0x7c00u) == 0x7c00u) continue;  // ±inf, NaN: not finite halves
    const float want = float(Imath::half(Imath::half::FromBits, uint16_t(b)));
    const float got = shade::half_to_float(uint16_t(b));
    ASSERT_EQ(std::bit_cast<uint32_t>(got), std::bit_cast<uint32_t>(want)) << "half bits " << b;
    ++checked;
  }
  EXPECT_EQ(checked, 63488);
  // The SSE2 decode of lookups on CPUs without F16C (halves_to_floats), on the same values in
  // runs of 9 and a tail.
  std::vector<uint16_t> finite;
  for (uint32_t b = 0; b < 0x10000u; ++b)
    if ((b & 0x7c00u) != 0x7c00u) finite.push_back(uint16_t(b));
  std::vector<float> decoded(finite.size());
  shade::halves_to_floats(finite.data(), decoded.data(), finite.size());
  for (size_t i = 0; i < finite.size(); ++i)
    ASSERT_EQ(std::bit_cast<uint32_t>(decoded[i]), std::bit_cast<uint32_t>(shade::half_to_float(finite[i])))
        << "half bits " << finite[i];
}

// A half table shades bit for bit as the float table of its values: lookups, the fast path and
// the slow reference, with both proxies, the geometric and the surface scheme, 100 scattered
// occluders (so the overlap sweep and the partial correction run on them).
TEST(HalfTables, ShadeExactlyAsTheFloatTableOfTheirValues) {
  std::mt19937 rng(77);
  std::uniform_real_distribution<float> u01(0, 1);
  Shells asset(12, 17, 32, [&](int, int, int, int) { return u01(rng) - 0.2f; });
  for (int k = 0; k < 12; ++k) asset.radii[size_t(k)] = float(0.75 * std::pow(40.0 / 0.75, k / 11.0));
  std::vector<float> table = cones::ball_cones(asset, 0.7);
  halves::round_to_half(asset.shells);
  halves::round_to_half(table);
  for (size_t i = 0; i < 40; ++i) asset.shells[9 * i] = float(i) * 0x1p-24f;  // subnormal halves
  const std::vector<uint16_t> shell_bits = halves::bits_of(asset.shells), cone_bits = halves::bits_of(table);
  Cube cube(4);
  for (float& t : cube.texels) t += 300.0f;
  std::vector<FivOccluder> floats, halfs;
  for (int i = 0; i < 100; ++i) {
    FivOccluder v = asset.view();
    v.cones = table.data();
    v.centre[0] = 40 * u01(rng) - 20, v.centre[1] = 3.0f * u01(rng) - 0.5f, v.centre[2] = 40 * u01(rng) - 20;
    floats.push_back(v);
    v.shells = nullptr, v.cones = nullptr, v.shells_half = shell_bits.data(), v.cones_half = cone_bits.data();
    ASSERT_NO_THROW(shade::validate_occluder(v));
    halfs.push_back(v);
  }
  const auto same = [](const float* a, const float* b, int n) {
    for (int e = 0; e < n; ++e)
      if (std::bit_cast<uint32_t>(a[e]) != std::bit_cast<uint32_t>(b[e])) return false;
    return true;
  };
  int nonzero = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const float p[3] = {40 * u01(rng) - 20, 0, 40 * u01(rng) - 20};
    const float n[3] = {u01(rng) - 0.5f, 1.0f, u01(rng) - 0.5f};
    const float s[3] = {p[0] - floats[0].centre[0], p[1] - floats[0].centre[1], p[2] - floats[0].centre[2]};
    float a[9], b[9];
    shade::lookup_fiv(floats[0], s, a), shade::lookup_fiv(halfs[0], s, b);
    ASSERT_TRUE(same(a, b, 9)) << trial;
    shade::lookup_cone(floats[0], s, a), shade::lookup_cone(halfs[0], s, b);
    ASSERT_TRUE(same(a, b, 4)) << trial;
    for (const shade::FivShadeOptions options :
         {shade::FivShadeOptions{}, shade::FivShadeOptions{true, true, shade::FivProxy::sphere}}) {
      shade::shade_fiv(cube.view(), floats.data(), 100, p, n, options, a);
      shade::shade_fiv(cube.view(), halfs.data(), 100, p, n, options, b);
      ASSERT_TRUE(same(a, b, 3)) << trial;
      nonzero += a[0] != 0;
      shade::shade_fiv_reference(cube.view(), floats.data(), 100, p, n, options, a);
      shade::shade_fiv_reference(cube.view(), halfs.data(), 100, p, n, options, b);
      ASSERT_TRUE(same(a, b, 3)) << trial;
    }
  }
  EXPECT_GT(nonzero, 60);  // not a comparison of clamped zeros
  // The surface scheme (plain trilinear, no mask) likewise.
  SurfaceShells surf(6, 9, 12, [&](int, int, int, int) { return u01(rng); }, bumpy);
  halves::round_to_half(surf.shells);
  const std::vector<uint16_t> surf_bits = halves::bits_of(surf.shells);
  FivOccluder f = surf.view(), h = f;
  h.shells = nullptr, h.shells_half = surf_bits.data();
  for (int trial = 0; trial < 200; ++trial) {
    const float s[3] = {4 * u01(rng) - 2, 4 * u01(rng) - 2, 4 * u01(rng) - 2};
    float a[9], b[9];
    shade::lookup_fiv(f, s, a), shade::lookup_fiv(h, s, b);
    ASSERT_TRUE(same(a, b, 9)) << trial;
  }
}

TEST(HalfTables, ValidateRefusesNonFiniteHalvesAndTwoTables) {
  Shells asset(2, 3, 4, [](int, int, int, int) { return 0.5f; });
  std::vector<uint16_t> bits = halves::bits_of(asset.shells);
  FivOccluder v = asset.view();
  v.shells = nullptr, v.shells_half = bits.data();
  EXPECT_NO_THROW(shade::validate_occluder(v));
  bits[5] = 0x7c00;  // +inf
  EXPECT_THROW(shade::validate_occluder(v), std::invalid_argument);
  bits[5] = 0xfe00;  // NaN
  EXPECT_THROW(shade::validate_occluder(v), std::invalid_argument);
  bits[5] = 0x7bff;  // 65504, the largest finite half
  EXPECT_NO_THROW(shade::validate_occluder(v));
  v.shells = asset.shells.data();  // both tables
  EXPECT_THROW(shade::validate_occluder(v), std::invalid_argument);
  v.shells = nullptr, v.shells_half = nullptr;  // neither
  EXPECT_THROW(shade::validate_occluder(v), std::invalid_argument);
}

// The C API takes half tables (prt_fiv_occluder_desc::shells_half, cones_half), copies them and
// shades what the C++ core shades on them (and on the float tables of their values).
TEST(HalfTables, TheCApiCopiesHalfTables) {
  Cube cube(4);
  for (float& t : cube.texels) t += 50.0f;
  const float f[3] = {0.3f, 0.7f, -0.2f};
  Shells o(12, 17, 32, [&](int, int, int, int e) { return f[e % 3] * float(1 + e / 3); });
  for (int k = 0; k < 12; ++k) o.radii[size_t(k)] = float(1.05 * std::pow(20.0 / 1.05, k / 11.0));
  o.centre[2] = 3.0f;
  std::vector<float> table = cones::ball_cones(o, 0.8);
  halves::round_to_half(o.shells);
  halves::round_to_half(table);
  std::vector<uint16_t> shell_bits = halves::bits_of(o.shells), cone_bits = halves::bits_of(table);
  FivOccluder v = o.view();
  v.cones = table.data();  // the float tables of the same values
  prt_fiv_scene* scene = nullptr;
  const float env[9] = {};
  ASSERT_EQ(prt_fiv_scene_create(4, cube.texels.data(), env, &scene), PRT_OK);
  prt_fiv_occluder_desc d{{v.centre[0], v.centre[1], v.centre[2]}, v.radius, v.n_rho, v.n_theta, v.n_phi,
                          v.radii, nullptr, v.valid, 0, nullptr, nullptr, shell_bits.data(), cone_bits.data()};
  ASSERT_EQ(prt_fiv_scene_add_occluder(scene, &d, nullptr), PRT_OK);
  std::fill(shell_bits.begin(), shell_bits.end(), uint16_t(0));  // the scene holds its own copy
  std::fill(cone_bits.begin(), cone_bits.end(), uint16_t(0));
  d.shells = o.shells.data();  // both a float and a half table: refused
  EXPECT_EQ(prt_fiv_scene_add_occluder(scene, &d, nullptr), PRT_ERROR_INVALID_ARGUMENT);
  const float points[6] = {0, 0, 0, 0.5f, 0, 0.4f}, normals[6] = {0, 1, 0, 0.1f, 1, 0};
  const prt_fiv_options options{1, 1, 0};
  float out[6], e[3];
  ASSERT_EQ(prt_fiv_scene_shade(scene, points, normals, 2, &options, out), PRT_OK);
  for (int k = 0; k < 2; ++k) {
    shade::shade_fiv(cube.view(), &v, 1, points + 3 * k, normals + 3 * k, {}, e);
    for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(out[3 * k + ch], e[ch]) << k << " " << ch;
    float tot[3];
    shade::lookup_difmap(cube.view(), normals + 3 * k, tot);
    EXPECT_LT(e[1], tot[1] - 0.1f);  // in the occluder's shadow: the comparison is not of E_tot alone
  }
  prt_fiv_scene_destroy(scene);
}
