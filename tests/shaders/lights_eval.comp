#version 450
// Test kernel for runtime/shaders/lights.glsl: case k evaluates prt_ltc_ggx over its arcs, an
// unshadowed punctual light and the spot falloff. The LTC buffers are rebound to bindings 0–1 to
// exercise the binding macros.
#define PRT_LTC_TABLE_BINDING 0
#define PRT_LTC_ARCS_BINDING 1
#include "lights.glsl"

layout(local_size_x = 64) in;
layout(push_constant) uniform Push { uint count; } pc;
// Per case 6 vec4: (n, alpha), (v, f0), (first_arc, arc_count, kind, inner), (position, outer),
// (direction, cos_angle), (p, range).
layout(std430, set = 0, binding = 2) readonly buffer Cases { vec4 cases[]; };
// Per case: (ltc, punctual E, falloff at cos_angle, 0).
layout(std430, set = 0, binding = 3) writeonly buffer Out { vec4 result[]; };

void main() {
  uint k = gl_GlobalInvocationID.x;
  if (k >= pc.count) return;
  vec4 c0 = cases[6u * k], c1 = cases[6u * k + 1u], c2 = cases[6u * k + 2u];
  vec4 c3 = cases[6u * k + 3u], c4 = cases[6u * k + 4u], c5 = cases[6u * k + 5u];
  float ltc = prt_ltc_ggx(c0.xyz, c1.xyz, c0.w, c1.w, uint(c2.x), uint(c2.y));
  float e = prt_punctual_irradiance(int(c2.z), c3.xyz, c4.xyz, c2.w, c3.w, c5.w, c5.xyz, c0.xyz);
  result[k] = vec4(ltc, e, prt_spot_falloff(c4.w, c2.w, c3.w), 0.0);
}
