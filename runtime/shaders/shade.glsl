// runtime/shaders/shade.glsl — GLSL 450 mirror of the diffuse-PRT and band-1 shading of
// runtime/include/prtshade/shade.h (the contract is <prtshade/shade.h>):
//   vec3 prt_shade_transfer(uint first, int order)    prt::shade::shade_transfer
//   vec3 prt_shade_band1(vec3 n, float radiance[9])   prt::shade::shade_band1
// The formulas, numerics and tolerances are in shade.inc, the body this file shares with
// shade.hlsl. Include this file after defining the bindings you want (below).
//
//   Data access: PRT_TRANSFER(i) and PRT_LIGHT(i) are the i-th float of the transfer row and of
//   the lighting. By default this file declares two std430 SSBOs (plain float arrays, stride 4):
//     layout(set = PRT_SHADE_SET, binding = PRT_TRANSFER_BINDING) buffer PrtTransfer { float prt_transfer[]; };
//         vertex v's row at prt_transfer[first … first + order² − 1], first = v · order² for a
//         [vertex][order²] table (the HDF5 dataset as stored);
//     layout(set = PRT_SHADE_SET, binding = PRT_LIGHT_BINDING) buffer PrtLight { float prt_light[]; };
//         3 · order² floats, channel-major;
//   defaults set 0, bindings 0 and 1. To read the transfer from elsewhere (vertex attributes,
//   another buffer), #define PRT_TRANSFER(i) and/or PRT_LIGHT(i) yourself before including this
//   file; the corresponding SSBO is then not declared.
#ifndef PRT_SHADE_GLSL
#define PRT_SHADE_GLSL

#include "sh.glsl"

#include "shade.inc"

#endif  // PRT_SHADE_GLSL
