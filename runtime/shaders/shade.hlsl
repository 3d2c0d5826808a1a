// runtime/shaders/shade.hlsl — HLSL mirror (glslc -x hlsl, SPIR-V for Vulkan) of the diffuse-PRT
// and band-1 shading of runtime/include/prtshade/shade.h (the contract is <prtshade/shade.h>):
//   float3 prt_shade_transfer(uint first, int order)      prt::shade::shade_transfer
//   float3 prt_shade_band1(float3 n, float radiance[9])   prt::shade::shade_band1
// The formulas, numerics and tolerances are in shade.inc, the body this file shares with
// shade.glsl. Include this file after defining the bindings you want (below).
//
//   Data access: PRT_TRANSFER(i) and PRT_LIGHT(i) are the i-th float of the transfer row and of
//   the lighting. By default this file declares two structured buffers of floats (stride 4, the
//   same bytes and descriptors as shade.glsl's std430 SSBOs):
//     [[vk::binding(PRT_TRANSFER_BINDING, PRT_SHADE_SET)]] StructuredBuffer<float> prt_transfer;
//         vertex v's row at prt_transfer[first … first + order² − 1], first = v · order² for a
//         [vertex][order²] table (the HDF5 dataset as stored);
//     [[vk::binding(PRT_LIGHT_BINDING, PRT_SHADE_SET)]] StructuredBuffer<float> prt_light;
//         3 · order² floats, channel-major;
//   defaults set 0, bindings 0 and 1. To read the transfer from elsewhere (vertex attributes,
//   another buffer), #define PRT_TRANSFER(i) and/or PRT_LIGHT(i) yourself before including this
//   file; the corresponding buffer is then not declared.
#ifndef PRT_SHADE_HLSL
#define PRT_SHADE_HLSL

#include "sh.hlsl"

#include "shade.inc"

#endif  // PRT_SHADE_HLSL
