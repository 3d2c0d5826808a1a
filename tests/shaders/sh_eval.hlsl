// Test kernel for runtime/shaders/sh.hlsl: the HLSL twin of sh_eval.comp (the same bindings,
// push constants and output layout), one direction per invocation, order per direction.
#define PRT_SH_MAX_ORDER 16
#include "sh.hlsl"

struct Push {
  uint count;
};
[[vk::push_constant]] ConstantBuffer<Push> pc;
// dirs[i].xyz = unit direction, dirs[i].w = order (as a float).
[[vk::binding(0, 0)]] StructuredBuffer<float4> dirs;
// values[i * PRT_SH_MAX_COEFFS + k]; entries k >= order² must keep the sentinel.
[[vk::binding(1, 0)]] RWStructuredBuffer<float> values;

static const float kSentinel = -12345.0;

[numthreads(64, 1, 1)]
void main(uint3 id : SV_DispatchThreadID) {
  uint i = id.x;
  if (i >= pc.count) return;
  float y[PRT_SH_MAX_COEFFS];
  for (int k = 0; k < PRT_SH_MAX_COEFFS; ++k) y[k] = kSentinel;
  prt_sh_eval(int(dirs[i].w), dirs[i].xyz, y);
  for (int k = 0; k < PRT_SH_MAX_COEFFS; ++k) values[i * uint(PRT_SH_MAX_COEFFS) + uint(k)] = y[k];
}
