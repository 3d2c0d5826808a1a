#version 450
// Test kernel for runtime/shaders/glossy.glsl: vertex v shades route A (product matrices +
// visibility row) and route B (shadowed-radiance row) at its reflection direction, which it also
// returns. The glossy buffers are rebound to bindings 0–2 to exercise the binding macros.
#define PRT_SH_MAX_ORDER 16
#define PRT_GLOSSY_MATRICES_BINDING 0
#define PRT_VISIBILITY_BINDING 1
#define PRT_SHADOWED_BINDING 2
#include "glossy.glsl"

layout(local_size_x = 64) in;
layout(push_constant) uniform Push {
  uint count;
  int order;
  float exponent;  // Phong s
  float unused;
  vec4 eye;        // xyz
} pc;
layout(std430, set = 0, binding = 3) readonly buffer Normals { vec4 normals[]; };      // xyz
layout(std430, set = 0, binding = 4) readonly buffer Positions { vec4 positions[]; };  // xyz
// [count][3]: route A, route B, r (xyz each).
layout(std430, set = 0, binding = 5) writeonly buffer Out { vec4 result[]; };

void main() {
  uint v = gl_GlobalInvocationID.x;
  if (v >= pc.count) return;
  uint n = uint(pc.order * pc.order);
  float scales[PRT_SH_MAX_ORDER];
  prt_phong_band_scales(pc.exponent, pc.order, scales);
  vec3 r = prt_glossy_reflection(normals[v].xyz, positions[v].xyz, pc.eye.xyz);
  result[3u * v] = vec4(prt_shade_glossy(v * n, pc.order, scales, r), 0.0);
  result[3u * v + 1u] = vec4(prt_shade_glossy_radiance(3u * v * n, pc.order, scales, r), 0.0);
  result[3u * v + 2u] = vec4(r, 0.0);
}
