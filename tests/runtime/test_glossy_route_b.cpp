// Route B of glossy shading over many vertices (prtshade/glossy.h shade_glossy_radiance_vertices;
// paper 001 §4 "material editing"): orders beyond the triple product's 16 bands, the same numbers
// as the per-vertex function about each vertex's reflected view direction, and its argument checks.
#include <prtshade/glossy.h>
#include <prtshade/sh.h>

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

using namespace prt;
using std::numbers::pi;

TEST(GlossyRouteB, WhiteFurnaceAtOrder25IsOneForAnyLobe) {
  // S = ∫ 1 · y_k over the whole sphere = √(4π) δ_k0 per channel: L_out = λ_0 = 1 for any lobe and
  // view, at an order the triple product does not take (Phong 128 wants ~25 bands).
  const int L = 25, n = L * L;
  std::vector<float> S(3 * n, 0.0f);
  for (int c = 0; c < 3; ++c) S[size_t(c * n)] = float(std::sqrt(4 * pi));
  const float normal[3] = {0, 0, 1}, position[3] = {0, 0, 0}, eye[3] = {3, 1, 2};
  for (const double s : {4.0, 128.0}) {
    float out[3];
    shade::shade_glossy_radiance_vertices(S.data(), L, normal, position, 1, eye, s, out);
    for (float v : out) EXPECT_NEAR(v, 1.0f, 8 * 1.2e-7f) << s;  // a few float roundings of √(4π)
  }
}

TEST(GlossyRouteB, VerticesEqualThePerVertexFunctionAboutTheReflectedView) {
  const int L = 20, n = L * L, V = 4;
  std::vector<float> S(size_t(V) * 3 * n), normals(3 * V), positions(3 * V), out(3 * V);
  uint32_t x = 7;
  auto next = [&] { return float((x = x * 1664525u + 1013904223u) >> 8) / float(1u << 24) - 0.5f; };
  for (float& s : S) s = next();
  for (int v = 0; v < V; ++v) {
    float nn[3] = {next(), next(), next() + 1.0f};
    const float len = std::sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
    for (int c = 0; c < 3; ++c) normals[size_t(3 * v + c)] = nn[c] / len, positions[size_t(3 * v + c)] = next();
  }
  const float eye[3] = {0.5f, -2.0f, 3.0f};
  shade::shade_glossy_radiance_vertices(S.data(), L, normals.data(), positions.data(), V, eye, 64.0, out.data());
  std::vector<double> scales(L);
  shade::phong_band_scales(64.0, L, scales.data());
  for (int v = 0; v < V; ++v) {
    const float* p = &positions[size_t(3 * v)];
    float d[3] = {eye[0] - p[0], eye[1] - p[1], eye[2] - p[2]};
    const float dl = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (float& c : d) c /= dl;
    float r[3];
    shade::reflect(&normals[size_t(3 * v)], d, r);
    const float rl = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    for (float& c : r) c /= rl;
    float expect[3];
    shade::shade_glossy_radiance(&S[size_t(v) * 3 * n], L, scales.data(), r, expect);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(out[size_t(3 * v + c)], expect[c]) << v << " " << c;  // the same operations
  }
}

TEST(GlossyRouteB, BadArgumentsAreRefused) {
  std::vector<float> S(3 * 4, 0.0f);
  const float n[3] = {0, 0, 1}, p[3] = {0, 0, 0}, eye[3] = {0, 0, 1};
  float out[3];
  EXPECT_THROW(shade::shade_glossy_radiance_vertices(S.data(), 0, n, p, 1, eye, 4.0, out), std::invalid_argument);
  EXPECT_THROW(shade::shade_glossy_radiance_vertices(S.data(), shade::kMaxShadowedOrder + 1, n, p, 1, eye, 4.0, out),
               std::invalid_argument);
  EXPECT_THROW(shade::shade_glossy_radiance_vertices(S.data(), 2, n, p, 1, eye, -1.0, out), std::invalid_argument);
  EXPECT_THROW(shade::shade_glossy_radiance_vertices(nullptr, 2, n, p, 1, eye, 4.0, out), std::invalid_argument);
  EXPECT_NO_THROW(shade::shade_glossy_radiance_vertices(nullptr, 2, nullptr, nullptr, 0, nullptr, 4.0, nullptr));
}
