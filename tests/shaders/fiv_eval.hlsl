// Test kernel for runtime/shaders/fiv.hlsl: the HLSL twin of fiv_eval.comp (the same bindings,
// push constants and output layout). One receiver per invocation evaluates every entry point
// (the FIV buffers are rebound to bindings 0-4 to exercise the binding macros).
#define PRT_FIV_OCCLUDERS_BINDING 0
#define PRT_FIV_RADII_BINDING 1
#define PRT_FIV_SHELLS_BINDING 2
#define PRT_FIV_VALID_BINDING 3
#define PRT_FIV_DIFMAP_BINDING 4
// Two mask bits only: the groups of 4 and 5 occluders exercise prt_shade_fiv's path for
// occluders beyond the mask (activity recomputed) as well as the mask.
#define PRT_FIV_MAX_OCCLUDERS 2
#include "fiv.hlsl"

// The GLSL kernel's push block (std430: count at 0, env_fiv[9] at 4 … 36); scalars, because an
// HLSL constant-buffer array would have a 16-byte stride.
struct Push {
  uint count;
  float env0, env1, env2, env3, env4, env5, env6, env7, env8;
};
[[vk::push_constant]] ConstantBuffer<Push> pc;

struct Receiver {
  float4 p;    // xyz
  float4 n;    // xyz
  uint4 info;  // x: occluder for the single-occluder functions, y: first, z: count for prt_shade_fiv
};
[[vk::binding(5, 0)]] StructuredBuffer<Receiver> receivers;
// 36 floats per receiver: F[9] ([RGB][xyz]), difmap[3], partial factor, occluded irradiance
// with / without the partial factor [3 + 3], self [3], shade_fiv for (partial, overlap) =
// (1,1), (1,0), (0,1), (0,0) [4 × 3], 2 unused.
[[vk::binding(6, 0)]] RWStructuredBuffer<float> results;

void put3(uint base, float3 v) {
  results[base] = v.x;
  results[base + 1u] = v.y;
  results[base + 2u] = v.z;
}

[numthreads(64, 1, 1)]
void main(uint3 id : SV_DispatchThreadID) {
  // Invocation 4 r + option: receiver r; option selects the prt_shade_fiv flags (partial, overlap)
  // = (1,1), (1,0), (0,1), (0,0), so prt_shade_fiv is inlined once.
  uint r = id.x / 4u, option = id.x % 4u;
  if (r >= pc.count) return;
  Receiver rc = receivers[r];
  float3 p = rc.p.xyz, n = rc.n.xyz;
  uint o = rc.info.x;
  uint base = 36u * r;
  put3(base + 22u + 3u * option, prt_shade_fiv(rc.info.y, rc.info.z, p, n, option < 2u, option % 2u == 0u));
  if (option != 0u) return;
  float3x3 F = prt_lookup_fiv(o, p - prt_fiv_occluders[o].centre_radius.xyz);
  put3(base + 0u, F[0]);
  put3(base + 3u, F[1]);
  put3(base + 6u, F[2]);
  put3(base + 9u, prt_lookup_difmap(n));
  results[base + 12u] = prt_partial_factor(o, p, n);
  put3(base + 13u, prt_occluded_irradiance(o, p, n, true));
  put3(base + 16u, prt_occluded_irradiance(o, p, n, false));
  float env[9] = {pc.env0, pc.env1, pc.env2, pc.env3, pc.env4, pc.env5, pc.env6, pc.env7, pc.env8};
  put3(base + 19u, prt_shade_fiv_self(env, o, p, n));
  results[base + 34u] = 0.0;
  results[base + 35u] = 0.0;
}
