// runtime/shaders/prt_lang.hlsl — the HLSL spelling of the language-dependent names of the shared
// shading bodies (runtime/shaders/*.inc); the GLSL spelling and the contract of each name are in
// prt_lang.glsl. HLSL here means what glslc compiles with `-x hlsl` to SPIR-V for Vulkan
// (glslang's HLSL front end; tests/shaders compile with
// `glslc -x hlsl -fshader-stage=compute -fentry-point=main --target-env=vulkan1.1 -Werror`).
#ifndef PRT_LANG
#define PRT_LANG
#define PRT_HLSL 1
#define prt_vec3 float3
#define prt_vec4 float4
#define prt_ivec4 int4
#define prt_uvec4 uint4
#define prt_mat3 float3x3
#define PRT_CONST static const
#define PRT_MAT3_ZERO ((float3x3)0)
#define PRT_MAT3_DOTS(v, m) mul((m), (v))
#define PRT_ANY_POSITIVE(v) any((v) > 0.0)
#define PRT_UNPACK_HALF(bits) f16tof32(bits)
#define PRT_READONLY_BUFFER(block, type, name, set_, binding_) \
  [[vk::binding(binding_, set_)]] StructuredBuffer<type> name;
#endif  // PRT_LANG
