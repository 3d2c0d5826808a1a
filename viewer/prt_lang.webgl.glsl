// viewer/prt_lang.webgl.glsl — the GLSL ES 3.00 (WebGL 2) spelling of the names the shared shading
// bodies (runtime/shaders/sh.inc, shade.inc) use: the third language beside prt_lang.glsl (GLSL
// 450) and prt_lang.hlsl. The page (viewer.js) compiles this file, then the bodies as they are
// shipped in runtime/shaders (their comments and #include lines removed: WebGL has no #include),
// so the browser evaluates the SH basis and the transfer / band-1 sums with the same code as the
// Vulkan mirrors that tests/shaders holds to the C++ core. The bodies' buffers are not declared
// here: the page defines PRT_TRANSFER(i) and PRT_LIGHT(i) before them (a vertex's row copied from
// its attributes, and a uniform array).
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
