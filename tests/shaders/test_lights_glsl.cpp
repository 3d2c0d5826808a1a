// runtime/shaders/lights.glsl and lights.hlsl run as Vulkan compute shaders (lavapipe on CI)
// against prtshade's C++ core: prt::shade::ltc (ggx_lobe on ggx_table(), integrate, Lobe::scale)
// over quads around random directions above random normals, seen from random views at
// roughnesses 0.05 … 1 and F0 0 … 1, some crossing the cosine space's horizon (the clipped
// branch); prt::shade::unshadowed_punctual for the three kinds; prt::shade::spot_falloff. Every
// test once per language (lights_eval.comp, lights_eval.hlsl), the same tolerances. The inputs are
// floats; the core evaluates the same floats in double.
//
// Tolerances (ε = 2^-24):
//   LTC    kLtcTolerance · (1 + |value|): float against double through ~60 operations (the
//          table's bilinear weights, the 3×3 transform, normalisations, prt_atan2's 2e-8 rad,
//          the edge sums): 64 ε; measured 1.7e-7 (3 ε) on lavapipe for both languages, far below
//          the approximation's own bound (ltc::error_bound, ~1e-2), which is what a renderer sees;
//   punctual and falloff  64 ε relative to the value and its largest term (a few float operations
//          and the cosines of the cone angles).
#include "shader_test.h"

#include <prtshade/lights.h>
#include <prtshade/ltc.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

namespace {

using prt::test::kFloatEps;
constexpr double kLtcTolerance = 64 * kFloatEps;
constexpr double kPunctualTolerance = 64 * kFloatEps;

class LightsMirror : public prt::test::ShaderMirror {};
PRT_SHADER_MIRROR_LANGUAGES(LightsMirror);

using V3 = std::array<double, 3>;
V3 unit(const V3& a) {
  const double l = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
  return {a[0] / l, a[1] / l, a[2] / l};
}
V3 cross(const V3& a, const V3& b) { return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]}; }
double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
V3 as_float(const V3& a) { return {double(float(a[0])), double(float(a[1])), double(float(a[2]))}; }

struct Case {
  V3 n, v;
  float alpha, f0;
  uint32_t first, count;
  int kind;
  float inner, outer, cos_angle;
  V3 position, direction, p;
  float range = 0;  // point and spot: three in four have a range, from 0.6 to 1.6 times its distance
};

TEST_P(LightsMirror, LtcPunctualAndFalloffMatchTheCore) {
  std::mt19937 rng(32);
  std::uniform_real_distribution<double> u(-1, 1), u01(0, 1);
  std::vector<Case> cases;
  std::vector<float> arcs;
  auto random_unit = [&] {
    for (;;) {
      const V3 d{u(rng), u(rng), u(rng)};
      const double l2 = dot(d, d);
      if (l2 > 0.01 && l2 <= 1) return unit(d);
    }
  };
  while (cases.size() < 256) {
    Case c;
    c.n = as_float(random_unit());
    V3 v = random_unit();
    if (dot(v, c.n) < 0.05) continue;
    c.v = as_float(v);
    // A quad of half-size h about a direction d above the horizon, counter-clockwise about d.
    const V3 d = random_unit();
    const double h = 0.05 + 0.6 * u01(rng);
    const V3 t = unit(cross(std::abs(d[0]) < 0.9 ? V3{1, 0, 0} : V3{0, 1, 0}, d)), b = cross(d, t);
    std::array<V3, 4> q;
    const double sx[4] = {-1, 1, 1, -1}, sy[4] = {-1, -1, 1, 1};
    bool above = true;
    for (int k = 0; k < 4; ++k) {
      q[size_t(k)] = as_float({d[0] + h * (sx[k] * t[0] + sy[k] * b[0]), d[1] + h * (sx[k] * t[1] + sy[k] * b[1]),
                               d[2] + h * (sx[k] * t[2] + sy[k] * b[2])});
      above = above && dot(q[size_t(k)], c.n) > 0;
    }
    if (!above) continue;
    c.first = uint32_t(arcs.size() / 6);
    c.count = 4;
    for (int k = 0; k < 4; ++k)
      for (const V3& w : {q[size_t(k)], q[size_t((k + 1) % 4)]})
        for (double x : w) arcs.push_back(float(x));
    c.alpha = float(0.05 + 0.95 * u01(rng) * u01(rng));
    c.f0 = float(u01(rng));
    c.kind = int(cases.size() % 3);
    c.inner = float(0.5 * u01(rng));
    c.outer = float(c.inner + 0.05 + u01(rng));
    c.cos_angle = float(std::cos(1.6 * u01(rng)));
    c.position = as_float({2 * u(rng), 2 + u(rng), 2 * u(rng)});
    c.direction = as_float(random_unit());
    c.p = as_float({u(rng), u(rng), u(rng)});
    if (c.kind != 0 && cases.size() % 4 != 0) {
      const V3 to{c.position[0] - c.p[0], c.position[1] - c.p[1], c.position[2] - c.p[2]};
      c.range = float(std::sqrt(dot(to, to)) * (0.6 + u01(rng)));
    }
    cases.push_back(c);
  }
  const prt::shade::ltc::Table& table = prt::shade::ltc::ggx_table();
  std::vector<float> packed(prt::shade::ltc::packed_table_floats(table));
  prt::shade::ltc::pack_table(table, packed);
  std::vector<float> in;
  for (const Case& c : cases) {
    const float rows[24] = {float(c.n[0]), float(c.n[1]), float(c.n[2]), c.alpha,
                            float(c.v[0]), float(c.v[1]), float(c.v[2]), c.f0,
                            float(c.first), float(c.count), float(c.kind), c.inner,
                            float(c.position[0]), float(c.position[1]), float(c.position[2]), c.outer,
                            float(c.direction[0]), float(c.direction[1]), float(c.direction[2]), c.cos_angle,
                            float(c.p[0]), float(c.p[1]), float(c.p[2]), c.range};
    in.insert(in.end(), rows, rows + 24);
  }
  auto b_table = prt::test::to_bytes(packed), b_arcs = prt::test::to_bytes(arcs), b_in = prt::test::to_bytes(in);
  std::vector<std::byte> b_out(cases.size() * 4 * sizeof(float));
  const uint32_t count = uint32_t(cases.size());
  ASSERT_TRUE(prt::test::run_kernel(kernel("lights_eval"), {&b_table, &b_arcs, &b_in, &b_out}, prt::test::push_bytes(count), count));
  const auto out = prt::test::from_bytes<float>(b_out);
  double worst_ltc = 0;
  size_t clipped = 0, lit = 0, windowed = 0;
  for (size_t k = 0; k < cases.size(); ++k) {
    const Case& c = cases[k];
    namespace ltc = prt::shade::ltc;
    const ltc::Lobe lobe = ltc::ggx_lobe(table, c.n, c.v, c.alpha);
    std::vector<ltc::Arc> region;
    for (uint32_t a = 0; a < c.count; ++a) {
      const float* x = &arcs[6 * (c.first + a)];
      region.push_back({{x[0], x[1], x[2]}, {x[3], x[4], x[5]}});
      clipped += (lobe.to_cosine[2][0] * x[0] + lobe.to_cosine[2][1] * x[1] + lobe.to_cosine[2][2] * x[2]) < 0;
    }
    const double want = lobe.scale(c.f0) * ltc::integrate(lobe, region);
    lit += want > 0.01;
    worst_ltc = std::max(worst_ltc, std::abs(out[4 * k] - want) / (1 + std::abs(want)));
    EXPECT_NEAR(out[4 * k], want, kLtcTolerance * (1 + std::abs(want))) << language() << " LTC case " << k;
    prt::shade::PunctualLight l;
    l.kind = prt::shade::PunctualKind(c.kind);
    l.position = c.position;
    l.direction = c.direction;
    l.inner_cone = c.inner;
    l.outer_cone = c.outer;
    l.range = c.range;
    const double e = prt::shade::unshadowed_punctual(l, c.p, c.n);
    const V3 to{c.position[0] - c.p[0], c.position[1] - c.p[1], c.position[2] - c.p[2]};
    windowed += c.range > 0 && e > 0 && prt::shade::range_window(std::sqrt(dot(to, to)), c.range) < 1;
    const double scale = c.kind == 0 ? 1 : 1 / dot(to, to);
    EXPECT_NEAR(out[4 * k + 1], e, kPunctualTolerance * (e + scale)) << language() << " punctual case " << k;
    const double f = prt::shade::spot_falloff(c.cos_angle, c.inner, c.outer);
    EXPECT_NEAR(out[4 * k + 2], f, kPunctualTolerance * (1 + 1 / std::max(0.001, std::cos(double(c.inner)) - std::cos(double(c.outer)))))
        << language() << " falloff case " << k;
  }
  EXPECT_GT(clipped, 0u) << "no case exercises the clip against the cosine space's horizon";
  EXPECT_GT(lit, cases.size() / 4) << "too few cases with a visible lobe";
  EXPECT_GT(windowed, 16u) << "too few lit cases inside a range window";
  RecordProperty("worst_ltc_relative", std::to_string(worst_ltc));
  std::printf("%s: worst LTC difference %.3g (relative to 1 + |value|), %zu arc endpoints below the cosine horizon\n",
              language(), worst_ltc, clipped);
}

} // namespace
