// runtime/shaders/sh.hlsl — HLSL mirror of prt::sh::eval (runtime/include/prtshade/sh.h,
// runtime/src/sh.cpp) for glslc's HLSL front end (`glslc -x hlsl`, SPIR-V for Vulkan): the real
// spherical-harmonics basis prtbake bakes with, for shaders that evaluate SH at a direction.
//   int prt_sh_index(int l, int m)                                     prt::sh::index
//   void prt_sh_eval(int order, float3 d, inout float y[PRT_SH_MAX_COEFFS])   prt::sh::eval
// Basis, index layout, numerics and the order limit PRT_SH_MAX_ORDER (default 8, at most 16;
// define it before including this file): sh.inc, the body this file shares with sh.glsl.
#ifndef PRT_SH_HLSL
#define PRT_SH_HLSL
#include "prt_lang.hlsl"
#include "sh.inc"
#endif  // PRT_SH_HLSL
