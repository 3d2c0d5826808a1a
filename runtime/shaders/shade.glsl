// runtime/shaders/shade.glsl — GLSL 450 mirror of the diffuse-PRT and band-1 shading of
// runtime/include/prtshade/shade.h (prt::shade::shade_transfer, prt::shade::shade_band1; the
// contract is <prtshade/shade.h>). Include it after defining the bindings you want (below).
//
// prt_shade_transfer(first, order) — diffuse PRT, docs/ARCHITECTURE.md §3 (Sloan, Kautz, Snyder 2002):
//   out_c = Σ_i T_i · L_{c,i},  i = 0 … order² − 1,
// T = the vertex's /transfer/diffuse row (it carries the 1/π, so the caller multiplies by the
// albedo only), L = SH lighting [RGB][order²] channel-major, as prt::shade::project_latlong
// writes it (rotate the LIGHTING with prt::sh::Rotation on the host, not the transfer).
// Accumulated in float in index order, like the C++ core.
//   Data access: PRT_TRANSFER(i) and PRT_LIGHT(i) are the i-th float of the transfer row and of
//   the lighting. By default this file declares two std430 SSBOs (plain float arrays, stride 4):
//     layout(set = PRT_SHADE_SET, binding = PRT_TRANSFER_BINDING) buffer PrtTransfer { float prt_transfer[]; };
//         vertex v's row at prt_transfer[first … first + order² − 1], first = v · order² for a
//         [vertex][order²] table (the HDF5 dataset as stored);
//     layout(set = PRT_SHADE_SET, binding = PRT_LIGHT_BINDING) buffer PrtLight { float prt_light[]; };
//         3 · order² floats, channel-major;
//   defaults set 0, bindings 0 and 1. To read the transfer from elsewhere (vertex attributes,
//   another buffer), #define PRT_TRANSFER(i) and/or PRT_LIGHT(i) yourself before including this
//   file; the corresponding SSBO is then not declared. `first` is passed through to
//   PRT_TRANSFER as PRT_TRANSFER(first + i).
//
// prt_shade_band1(n, R) — band-1 shadowed irradiance (paper 001 §4 "All-Frequency Diffuse
// Shading", appendix A; vector irradiance):
//   E_c = (4π/3) Σ_m y_1m(n) R[c·3 + m + 1] = √(4π/3) · (−n_y R_{c,−1} + n_z R_{c,0} − n_x R_{c,1}),
// R = one /radiance/band1 row [RGB][m = −1, 0, 1], y_1m from sh.glsl (= sh.h: y_1m = √(3/4π)·(−y, z, −x)).
// n unit (a non-unit n scales E by |n|).
//
// Agreement with the C++ core (tests/shaders/test_shade_glsl.cpp, lavapipe): transfer within
// (2n + 4) ulps of Σ|T_i L_i| (float summation bound γ_n for both sides), band-1 within 8 ulps of
// √(4π/3) Σ|b_m R_m|.
#ifndef PRT_SHADE_GLSL
#define PRT_SHADE_GLSL

#include "sh.glsl"

#ifndef PRT_SHADE_SET
#define PRT_SHADE_SET 0
#endif
#ifndef PRT_TRANSFER_BINDING
#define PRT_TRANSFER_BINDING 0
#endif
#ifndef PRT_LIGHT_BINDING
#define PRT_LIGHT_BINDING 1
#endif

#ifndef PRT_TRANSFER
layout(std430, set = PRT_SHADE_SET, binding = PRT_TRANSFER_BINDING) readonly buffer PrtTransfer {
  float prt_transfer[];
};
#define PRT_TRANSFER(i) prt_transfer[(i)]
#endif
#ifndef PRT_LIGHT
layout(std430, set = PRT_SHADE_SET, binding = PRT_LIGHT_BINDING) readonly buffer PrtLight {
  float prt_light[];
};
#define PRT_LIGHT(i) prt_light[(i)]
#endif

// √(4π/3) = (4π/3) · √(3/(4π)): band-1 radiance to irradiance.
const float PRT_BAND1_IRRADIANCE = 2.04665341589297697;

// Σ_i T[first + i] · L[c·order² + i], c = R, G, B (mirrors prt::shade::shade_transfer).
vec3 prt_shade_transfer(uint first, int order) {
  uint n = uint(max(order, 0) * max(order, 0));
  vec3 acc = vec3(0.0);
  for (uint i = 0u; i < n; ++i) {
    float t = PRT_TRANSFER(first + i);
    acc.r += t * PRT_LIGHT(i);
    acc.g += t * PRT_LIGHT(n + i);
    acc.b += t * PRT_LIGHT(2u * n + i);
  }
  return acc;
}

// E_c = (4π/3) Σ_m y_1m(n) R[c·3 + m + 1] (mirrors prt::shade::shade_band1).
vec3 prt_shade_band1(vec3 n, float radiance[9]) {
  vec3 b = vec3(-n.y, n.z, -n.x);  // y_1m / √(3/4π), m = −1, 0, 1
  return PRT_BAND1_IRRADIANCE * vec3(dot(b, vec3(radiance[0], radiance[1], radiance[2])),
                                     dot(b, vec3(radiance[3], radiance[4], radiance[5])),
                                     dot(b, vec3(radiance[6], radiance[7], radiance[8])));
}

#endif  // PRT_SHADE_GLSL
