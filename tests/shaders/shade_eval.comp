#version 450
// Test kernel for runtime/shaders/shade.glsl: vertex v shades its transfer row (default SSBOs,
// bindings 0 and 1) and its band-1 row.
#include "shade.glsl"

layout(local_size_x = 64) in;
layout(push_constant) uniform Push { uint count; int order; } pc;
layout(std430, set = 0, binding = 2) readonly buffer Normals { vec4 normals[]; };   // xyz
layout(std430, set = 0, binding = 3) readonly buffer Band1 { float band1[]; };      // [count][9]
layout(std430, set = 0, binding = 4) writeonly buffer Out { vec4 result[]; };       // [count][2]

void main() {
  uint v = gl_GlobalInvocationID.x;
  if (v >= pc.count) return;
  result[2u * v] = vec4(prt_shade_transfer(v * uint(pc.order * pc.order), pc.order), 0.0);
  float r[9];
  for (int k = 0; k < 9; ++k) r[k] = band1[9u * v + uint(k)];
  result[2u * v + 1u] = vec4(prt_shade_band1(normals[v].xyz, r), 0.0);
}
