// runtime/shaders/glossy.glsl — GLSL 450 mirror of the glossy shading of
// runtime/include/prtshade/glossy.h (the contract is <prtshade/glossy.h>):
//   void prt_phong_band_scales(float s, int order, out float scales[PRT_SH_MAX_ORDER])
//                                                              prt::shade::phong_band_scales
//   vec3 prt_reflect(vec3 n, vec3 v)                           prt::shade::reflect
//   vec3 prt_glossy_reflection(vec3 n, vec3 p, vec3 eye)       r of prt::shade::shade_glossy_vertices
//   vec3 prt_shade_glossy(uint first, int order, float scales[PRT_SH_MAX_ORDER], vec3 r)
//                                                              route A, shade_glossy_vertices per vertex
//   vec3 prt_shade_glossy_radiance(uint first, int order, float scales[PRT_SH_MAX_ORDER], vec3 r)
//                                                              route B, shade_glossy_radiance
// The formulas, numerics and tolerances are in glossy.inc, the body this file shares with
// glossy.hlsl; SH come from sh.glsl (define PRT_SH_MAX_ORDER ≥ the order before including; the
// glossy core allows up to 16).
//
//   Data access: PRT_GLOSSY_MATRIX(i), PRT_VISIBILITY(i) and PRT_SHADOWED(i) are the i-th float of
//   the lighting's product matrices, of the visibility rows and of the shadowed-radiance rows.
//   By default this file declares three std430 SSBOs of floats (stride 4) at set PRT_GLOSSY_SET (0):
//     binding PRT_GLOSSY_MATRICES_BINDING (7)  float prt_glossy_matrices[]:
//         prt::shade::GlossyLight::matrices() as it is, [3][order²][order²];
//     binding PRT_VISIBILITY_BINDING (8)       float prt_visibility[]: /transfer/visibility
//         [vertex][order²], vertex v's row from first = v · order²;
//     binding PRT_SHADOWED_BINDING (9)         float prt_shadowed[]: shadowed radiance
//         [vertex][RGB][order²], vertex v's from first = v · 3 · order²;
//   the defaults leave shade.glsl's 0–1 and fiv.glsl's 2–6 free. #define PRT_GLOSSY_MATRIX(i),
//   PRT_VISIBILITY(i) or PRT_SHADOWED(i) yourself before including this file to read from
//   elsewhere; the corresponding SSBO is then not declared.
#ifndef PRT_GLOSSY_GLSL
#define PRT_GLOSSY_GLSL

#include "sh.glsl"

#include "glossy.inc"

#endif  // PRT_GLOSSY_GLSL
