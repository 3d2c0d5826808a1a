// runtime/shaders/glossy.hlsl — HLSL mirror (glslc -x hlsl, SPIR-V for Vulkan) of the glossy
// shading of runtime/include/prtshade/glossy.h (the contract is <prtshade/glossy.h>):
//   void prt_phong_band_scales(float s, int order, out float scales[PRT_SH_MAX_ORDER])
//                                                                prt::shade::phong_band_scales
//   float3 prt_reflect(float3 n, float3 v)                       prt::shade::reflect
//   float3 prt_glossy_reflection(float3 n, float3 p, float3 eye) r of prt::shade::shade_glossy_vertices
//   float3 prt_shade_glossy(uint first, int order, float scales[PRT_SH_MAX_ORDER], float3 r)
//                                                                route A, shade_glossy_vertices per vertex
//   float3 prt_shade_glossy_radiance(uint first, int order, float scales[PRT_SH_MAX_ORDER], float3 r)
//                                                                route B, shade_glossy_radiance
// The formulas, numerics and tolerances are in glossy.inc, the body this file shares with
// glossy.glsl; SH come from sh.hlsl (define PRT_SH_MAX_ORDER ≥ the order before including; the
// glossy core allows up to 16).
//
//   Data access: PRT_GLOSSY_MATRIX(i), PRT_VISIBILITY(i) and PRT_SHADOWED(i) are the i-th float of
//   the lighting's product matrices, of the visibility rows and of the shadowed-radiance rows.
//   By default this file declares three StructuredBuffer<float> (stride 4; the descriptors and
//   bytes of glossy.glsl's SSBOs) at set PRT_GLOSSY_SET (0):
//     [[vk::binding(PRT_GLOSSY_MATRICES_BINDING (7), PRT_GLOSSY_SET)]] prt_glossy_matrices:
//         prt::shade::GlossyLight::matrices() as it is, [3][order²][order²];
//     [[vk::binding(PRT_VISIBILITY_BINDING (8), …)]] prt_visibility: /transfer/visibility
//         [vertex][order²], vertex v's row from first = v · order²;
//     [[vk::binding(PRT_SHADOWED_BINDING (9), …)]] prt_shadowed: shadowed radiance
//         [vertex][RGB][order²], vertex v's from first = v · 3 · order²;
//   the defaults leave shade.hlsl's 0–1 and fiv.hlsl's 2–6 free. #define PRT_GLOSSY_MATRIX(i),
//   PRT_VISIBILITY(i) or PRT_SHADOWED(i) yourself before including this file to read from
//   elsewhere; the corresponding buffer is then not declared.
#ifndef PRT_GLOSSY_HLSL
#define PRT_GLOSSY_HLSL

#include "sh.hlsl"

#include "glossy.inc"

#endif  // PRT_GLOSSY_HLSL
