// runtime/shaders/prt_lang.glsl — the GLSL spelling of the few language-dependent names the
// shared shading bodies (runtime/shaders/*.inc) use, so that each function is written once and
// compiled as GLSL 450 (sh.glsl, shade.glsl, glossy.glsl, fiv.glsl) or as HLSL (the *.hlsl
// beside them, prt_lang.hlsl). Everything else in the bodies (scalar casts float(x), uint(x),
// swizzles, sqrt/clamp/dot/length/cross/isinf, inout/out parameters, local arrays) is spelled
// the same in both languages.
//   prt_vec3/prt_vec4/prt_ivec4/prt_uvec4/prt_mat3   vector and 3×3 matrix types; prt_mat3(a0 … a8)
//       fills m[0] = (a0, a1, a2), m[1] = (a3, a4, a5), m[2] = (a6, a7, a8) in both languages
//       (GLSL: the columns, HLSL: the rows), and every body indexes it only as m[c].
//   PRT_CONST                 a file-scope constant (GLSL const, HLSL static const)
//   PRT_MAT3_ZERO             the zero 3×3 matrix
//   PRT_MAT3_DOTS(v, m)       (dot(v, m[0]), dot(v, m[1]), dot(v, m[2]))
//   PRT_ANY_POSITIVE(v)       whether a component of the vec3 v is > 0
//   PRT_UNPACK_HALF(bits)     the float of the binary16 bits in the low 16 bits of a uint (GLSL
//       unpackHalf2x16(bits).x, HLSL f16tof32(bits)): exact for every finite half
//   PRT_READONLY_BUFFER(block, type, name, set, binding)   a read-only array `name` of `type` at
//       (set, binding): GLSL a std430 SSBO `block { type name[]; }`, HLSL a StructuredBuffer<type>
//       (the same descriptor and bytes; `block` names the GLSL block only)
#ifndef PRT_LANG
#define PRT_LANG
#define PRT_GLSL 1
#define prt_vec3 vec3
#define prt_vec4 vec4
#define prt_ivec4 ivec4
#define prt_uvec4 uvec4
#define prt_mat3 mat3
#define PRT_CONST const
#define PRT_MAT3_ZERO mat3(0.0)
#define PRT_MAT3_DOTS(v, m) ((v) * (m))
#define PRT_ANY_POSITIVE(v) any(greaterThan((v), vec3(0.0)))
#define PRT_UNPACK_HALF(bits) unpackHalf2x16(bits).x
#define PRT_READONLY_BUFFER(block, type, name, set_, binding_) \
  layout(std430, set = set_, binding = binding_) readonly buffer block { type name[]; };
#endif  // PRT_LANG
