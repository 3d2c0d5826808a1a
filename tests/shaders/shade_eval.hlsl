// Test kernel for runtime/shaders/shade.hlsl: the HLSL twin of shade_eval.comp (the same
// bindings, push constants and output layout). Vertex v shades its transfer row (default
// buffers, bindings 0 and 1) and its band-1 row.
#include "shade.hlsl"

struct Push {
  uint count;
  int order;
};
[[vk::push_constant]] ConstantBuffer<Push> pc;
[[vk::binding(2, 0)]] StructuredBuffer<float4> normals;  // xyz
[[vk::binding(3, 0)]] StructuredBuffer<float> band1;     // [count][9]
[[vk::binding(4, 0)]] RWStructuredBuffer<float4> result; // [count][2]

[numthreads(64, 1, 1)]
void main(uint3 id : SV_DispatchThreadID) {
  uint v = id.x;
  if (v >= pc.count) return;
  result[2u * v] = float4(prt_shade_transfer(v * uint(pc.order * pc.order), pc.order), 0.0);
  float r[9];
  for (int k = 0; k < 9; ++k) r[k] = band1[9u * v + uint(k)];
  result[2u * v + 1u] = float4(prt_shade_band1(normals[v].xyz, r), 0.0);
}
