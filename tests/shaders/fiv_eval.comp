#version 450
// Test kernel for runtime/shaders/fiv.glsl: one receiver per invocation evaluates every entry
// point (the FIV buffers are rebound to bindings 0-4 to exercise the binding macros).
#define PRT_FIV_OCCLUDERS_BINDING 0
#define PRT_FIV_RADII_BINDING 1
#define PRT_FIV_SHELLS_BINDING 2
#define PRT_FIV_VALID_BINDING 3
#define PRT_FIV_DIFMAP_BINDING 4
// Two mask bits only: the groups of 4 and 5 occluders exercise prt_shade_fiv's path for
// occluders beyond the mask (activity recomputed) as well as the mask.
#define PRT_FIV_MAX_OCCLUDERS 2
#include "fiv.glsl"

layout(local_size_x = 64) in;
layout(push_constant) uniform Push {
  uint count;
  float env_fiv[9];
} pc;

struct Receiver {
  vec4 p;       // xyz
  vec4 n;       // xyz
  uvec4 info;   // x: occluder for the single-occluder functions, y: first, z: count for prt_shade_fiv
};
layout(std430, set = 0, binding = 5) readonly buffer Receivers { Receiver receivers[]; };
// 36 floats per receiver: F[9] ([RGB][xyz]), difmap[3], partial factor, occluded irradiance
// with / without the partial factor [3 + 3], self [3], shade_fiv for (partial, overlap) =
// (1,1), (1,0), (0,1), (0,0) [4 × 3], 2 unused.
layout(std430, set = 0, binding = 6) writeonly buffer Results { float results[]; };

void put3(uint base, vec3 v) {
  results[base] = v.x;
  results[base + 1u] = v.y;
  results[base + 2u] = v.z;
}

void main() {
  // Invocation 4 r + option: receiver r; option selects the prt_shade_fiv flags (partial, overlap)
  // = (1,1), (1,0), (0,1), (0,0), so prt_shade_fiv is inlined once (lavapipe compiles faster).
  uint r = gl_GlobalInvocationID.x / 4u, option = gl_GlobalInvocationID.x % 4u;
  if (r >= pc.count) return;
  Receiver rc = receivers[r];
  vec3 p = rc.p.xyz, n = rc.n.xyz;
  uint o = rc.info.x;
  uint base = 36u * r;
  put3(base + 22u + 3u * option, prt_shade_fiv(rc.info.y, rc.info.z, p, n, option < 2u, option % 2u == 0u));
  if (option != 0u) return;
  mat3 F = prt_lookup_fiv(o, p - prt_fiv_occluders[o].centre_radius.xyz);
  put3(base + 0u, F[0]);
  put3(base + 3u, F[1]);
  put3(base + 6u, F[2]);
  put3(base + 9u, prt_lookup_difmap(n));
  results[base + 12u] = prt_partial_factor(o, p, n);
  put3(base + 13u, prt_occluded_irradiance(o, p, n, true));
  put3(base + 16u, prt_occluded_irradiance(o, p, n, false));
  float env[9];
  for (int k = 0; k < 9; ++k) env[k] = pc.env_fiv[k];
  put3(base + 19u, prt_shade_fiv_self(env, o, p, n));
  results[base + 34u] = 0.0;
  results[base + 35u] = 0.0;
}
