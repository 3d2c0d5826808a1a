// engine_sh.h — the light-probe formulas of Unity, Godot 4 and Filament, written out from their
// published shader code, for tests that check our engine-convention exports in the engines' OWN
// formulas (prtshade/conventions.h has the table):
//   Unity     UnityCG.cginc ShadeSH9 = SHEvalLinearL0L1 + SHEvalLinearL2 on unity_SHAr..unity_SHC,
//             packed from SphericalHarmonicsL2 sh[rgb, i] as Unity's own Hybrid Renderer packs them
//             (SHA = (sh3, sh1, sh2, sh0 − sh6), SHB = (sh4, sh5, 3·sh6, sh7), SHC = sh8);
//   Godot 4   scene_forward_clustered.glsl, lightmap capture: Ramamoorthi–Hanrahan eq. 13 with
//             c1..c5 = 0.429043, 0.511664, 0.743125, 0.886227, 0.247708 on the probe's sh[9];
//   Filament  Irradiance_SphericalHarmonics: Σ sh[i] · (1, y, z, x, yx, yz, 3z²−1, zx, x²−y²).
// Each returns the diffuse lighting E/π of channel c at the engine-frame unit normal n.
#pragma once

#include <prtshade/conventions.h>

#include <array>
#include <cstddef>

namespace prt::testing {

using V3 = std::array<double, 3>;
using prt::conventions::Engine;
using prt::conventions::EngineSh;

// p_i(d): the basis polynomials.
inline std::array<double, 9> poly(const V3& d) {
  const double x = d[0], y = d[1], z = d[2];
  return {1, y, z, x, x * y, y * z, 3 * z * z - 1, x * z, x * x - y * y};
}

inline double unity_shade_sh9(const EngineSh& sh, int c, const V3& n) {
  auto at = [&](int i) { return sh[std::size_t(c * 9 + i)]; };  // SphericalHarmonicsL2[rgb, i]
  const double SHA[4] = {at(3), at(1), at(2), at(0) - at(6)};
  const double SHB[4] = {at(4), at(5), 3 * at(6), at(7)};
  const double SHC = at(8);
  const double l0l1 = SHA[0] * n[0] + SHA[1] * n[1] + SHA[2] * n[2] + SHA[3] * 1.0;  // dot(SHAr, half4(n, 1))
  const double vB[4] = {n[0] * n[1], n[1] * n[2], n[2] * n[2], n[2] * n[0]};        // normal.xyzz * normal.yzzx
  const double l2 = SHB[0] * vB[0] + SHB[1] * vB[1] + SHB[2] * vB[2] + SHB[3] * vB[3] + SHC * (n[0] * n[0] - n[1] * n[1]);
  return l0l1 + l2;
}

inline double godot_capture(const EngineSh& sh, int c, const V3& w) {
  auto s = [&](int i) { return sh[std::size_t(i * 3 + c)]; };  // probe sh[i].rgb
  const double c1 = 0.429043, c2 = 0.511664, c3 = 0.743125, c4 = 0.886227, c5 = 0.247708;
  return c1 * s(8) * (w[0] * w[0] - w[1] * w[1]) + c3 * s(6) * w[2] * w[2] + c4 * s(0) - c5 * s(6) +
         2 * c1 * s(4) * w[0] * w[1] + 2 * c1 * s(7) * w[0] * w[2] + 2 * c1 * s(5) * w[1] * w[2] +
         2 * c2 * s(3) * w[0] + 2 * c2 * s(1) * w[1] + 2 * c2 * s(2) * w[2];
}

inline double filament_irradiance(const EngineSh& sh, int c, const V3& n) {
  const auto p = poly(n);
  double e = 0;
  for (int i = 0; i < 9; ++i) e += sh[std::size_t(i * 3 + c)] * p[std::size_t(i)];  // float3 iblSH[9]
  return e;
}

inline double evaluate(Engine e, const EngineSh& sh, int c, const V3& n) {
  return e == Engine::Unity ? unity_shade_sh9(sh, c, n) : e == Engine::Godot ? godot_capture(sh, c, n) : filament_irradiance(sh, c, n);
}

} // namespace prt::testing
