// Test kernel for runtime/shaders/glossy.hlsl: the HLSL twin of glossy_eval.comp (the same
// bindings, push constants and output layout). Vertex v shades route A and route B at its
// reflection direction, which it also returns; the glossy buffers are rebound to bindings 0–2.
#define PRT_SH_MAX_ORDER 16
#define PRT_GLOSSY_MATRICES_BINDING 0
#define PRT_VISIBILITY_BINDING 1
#define PRT_SHADOWED_BINDING 2
#include "glossy.hlsl"

struct Push {
  uint count;
  int order;
  float exponent;  // Phong s
  float unused;
  float4 eye;      // xyz
};
[[vk::push_constant]] ConstantBuffer<Push> pc;
[[vk::binding(3, 0)]] StructuredBuffer<float4> normals;    // xyz
[[vk::binding(4, 0)]] StructuredBuffer<float4> positions;  // xyz
// [count][3]: route A, route B, r (xyz each).
[[vk::binding(5, 0)]] RWStructuredBuffer<float4> result;

[numthreads(64, 1, 1)]
void main(uint3 id : SV_DispatchThreadID) {
  uint v = id.x;
  if (v >= pc.count) return;
  uint n = uint(pc.order * pc.order);
  float scales[PRT_SH_MAX_ORDER];
  prt_phong_band_scales(pc.exponent, pc.order, scales);
  float3 r = prt_glossy_reflection(normals[v].xyz, positions[v].xyz, pc.eye.xyz);
  result[3u * v] = float4(prt_shade_glossy(v * n, pc.order, scales, r), 0.0);
  result[3u * v + 1u] = float4(prt_shade_glossy_radiance(3u * v * n, pc.order, scales, r), 0.0);
  result[3u * v + 2u] = float4(r, 0.0);
}
