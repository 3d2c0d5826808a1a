// Test kernel for runtime/shaders/lights.hlsl: the HLSL twin of lights_eval.comp (the same
// bindings, push constants and output layout).
#define PRT_LTC_TABLE_BINDING 0
#define PRT_LTC_ARCS_BINDING 1
#include "lights.hlsl"

struct Push {
  uint count;
};
[[vk::push_constant]] ConstantBuffer<Push> pc;
// Per case 6 float4: (n, alpha), (v, f0), (first_arc, arc_count, kind, inner), (position, outer),
// (direction, cos_angle), (p, range).
[[vk::binding(2, 0)]] StructuredBuffer<float4> cases;
// Per case: (ltc, punctual E, falloff at cos_angle, 0).
[[vk::binding(3, 0)]] RWStructuredBuffer<float4> result;

[numthreads(64, 1, 1)]
void main(uint3 id : SV_DispatchThreadID) {
  uint k = id.x;
  if (k >= pc.count) return;
  float4 c0 = cases[6u * k], c1 = cases[6u * k + 1u], c2 = cases[6u * k + 2u];
  float4 c3 = cases[6u * k + 3u], c4 = cases[6u * k + 4u], c5 = cases[6u * k + 5u];
  float ltc = prt_ltc_ggx(c0.xyz, c1.xyz, c0.w, c1.w, uint(c2.x), uint(c2.y));
  float e = prt_punctual_irradiance(int(c2.z), c3.xyz, c4.xyz, c2.w, c3.w, c5.w, c5.xyz, c0.xyz);
  result[k] = float4(ltc, e, prt_spot_falloff(c4.w, c2.w, c3.w), 0.0);
}
