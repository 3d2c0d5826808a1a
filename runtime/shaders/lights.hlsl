// runtime/shaders/lights.hlsl — HLSL (glslc -x hlsl, SPIR-V for Vulkan) mirror of the lights of runtime/include/prtshade/lights.h
// and of the LTC GGX polygon integral of runtime/include/prtshade/ltc.h (the contracts):
//   float prt_spot_falloff(float cos_angle, float inner, float outer)      prt::shade::spot_falloff
//   float prt_punctual_irradiance(int kind, float3 position, float3 direction, float inner, float outer,
//                                 float range, float3 p, float3 n)          prt::shade::unshadowed_punctual
//   float prt_ltc_ggx(float3 n, float3 v, float alpha, float f0, uint first_arc, uint arc_count)
//                      ltc::ggx_lobe(ggx_table(), n, v, alpha), ltc::integrate over the arcs, × scale(f0)
// The formulas and numerics are in lights.inc, the body this file shares with lights.glsl.
//
//   Data access: PRT_LTC_TABLE(i) is float i of ltc::pack_table(ggx_table()) ({n_alpha, n_theta,
//   sqrt_alpha_min, theta_max} then the table's values), PRT_LTC_ARC(i, k) float k of arc i
//   ({a, b} world directions from the shade point, 6 floats). By default this file declares two
//   read-only buffers of floats at set PRT_LIGHTS_SET (0): binding PRT_LTC_TABLE_BINDING (10) and
//   PRT_LTC_ARCS_BINDING (11) (after glossy's 7–9); #define either macro first to read from elsewhere.
#ifndef PRT_LIGHTS_HLSL
#define PRT_LIGHTS_HLSL

#include "prt_lang.hlsl"

#include "lights.inc"

#endif  // PRT_LIGHTS_HLSL
