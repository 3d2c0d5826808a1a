#version 450
// Test kernel for runtime/shaders/sh.glsl: one direction per invocation, order per direction.
#define PRT_SH_MAX_ORDER 16
#include "sh.glsl"

layout(local_size_x = 64) in;
layout(push_constant) uniform Push { uint count; } pc;
// dirs[i].xyz = unit direction, dirs[i].w = order (as a float).
layout(std430, set = 0, binding = 0) readonly buffer Dirs { vec4 dirs[]; };
// values[i * PRT_SH_MAX_COEFFS + k]; entries k >= order² must keep the sentinel.
layout(std430, set = 0, binding = 1) writeonly buffer Values { float values[]; };

const float kSentinel = -12345.0;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.count) return;
  float y[PRT_SH_MAX_COEFFS];
  for (int k = 0; k < PRT_SH_MAX_COEFFS; ++k) y[k] = kSentinel;
  prt_sh_eval(int(dirs[i].w), dirs[i].xyz, y);
  for (int k = 0; k < PRT_SH_MAX_COEFFS; ++k) values[i * uint(PRT_SH_MAX_COEFFS) + uint(k)] = y[k];
}
