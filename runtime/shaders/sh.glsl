// runtime/shaders/sh.glsl — GLSL 450 mirror of prt::sh::eval (runtime/include/prtshade/sh.h,
// runtime/src/sh.cpp): the real spherical-harmonics basis prtbake bakes with, for shaders that
// evaluate SH at a direction (e.g. to shade a normal against SH lighting).
//   int prt_sh_index(int l, int m)                                   prt::sh::index
//   void prt_sh_eval(int order, vec3 d, inout float y[PRT_SH_MAX_COEFFS])   prt::sh::eval
// Basis, index layout, numerics and the order limit PRT_SH_MAX_ORDER (default 8, at most 16;
// define it before including this file): sh.inc, the body this file shares with sh.hlsl.
#ifndef PRT_SH_GLSL
#define PRT_SH_GLSL
#include "prt_lang.glsl"
#include "sh.inc"
#endif  // PRT_SH_GLSL
