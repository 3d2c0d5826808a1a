// runtime/shaders/fiv.glsl — GLSL 450 mirror of the FIV run-time shading of
// runtime/include/prtshade/fiv.h (Michael & Chrysanthou, "Fullsphere Irradiance Factorization for
// Real-Time All-Frequency Illumination for Dynamic Scenes", CGF 2010; paper 004, §4.3 "Run time").
// The contract is <prtshade/fiv.h>:
//
//   prt_lookup_difmap(n)                 prt::shade::lookup_difmap        E_tot(n), eq. 5 / 11
//   prt_lookup_fiv(o, s)                 prt::shade::lookup_fiv           F(s), §4.3.1–4.3.2
//   prt_partial_factor(o, p, n)          prt::shade::partial_factor       (h + R)/(2R), §4.3.1
//   prt_occluded_irradiance(o, p, n, b)  prt::shade::occluded_irradiance  I = max(0, f·n·F), eq. 10
//   prt_shade_fiv(first, count, p, n,    prt::shade::shade_fiv            eq. 11, 13, 14
//                 partial, overlap)
//   prt_shade_fiv_self(env, o, p, n)     prt::shade::shade_fiv_self       eq. 12
//
// Conventions and numerics: fiv.inc, the body this file shares with fiv.hlsl. prt_lookup_fiv
// returns a mat3 whose column c is channel c's vector, so n·F_c is the GLSL product `n * F`.
//
// Buffers (std430 SSBOs, all readonly; set PRT_FIV_SET, default 0; bindings below, defaults 2–6
// so that shade.glsl's defaults 0–1 fit beside them — #define any of them before including):
//   PRT_FIV_OCCLUDERS_BINDING (2)  PrtFivOccluder prt_fiv_occluders[]   one per occluder, 64 bytes:
//        struct PrtFivOccluder {          // std430 offsets
//          vec4  centre_radius;           //  0: centre xyz (world), w = bounding radius R (> 0)
//          ivec4 dims;                    // 16: n_rho (>= 1), n_theta (>= 2), n_phi (>= 1),
//                                         //     radial scheme (0 geometric, 1 surface: prtshade/fiv.h)
//          uvec4 offsets;                 // 32: first radius in prt_fiv_radii (floats),
//                                         //     first value in prt_fiv_shells (floats), or
//                                         //     in prt_fiv_halves (halves) when extra.z bit 0,
//                                         //     first WORD in prt_fiv_valid (uints),
//                                         //     surface scheme: first r_surf in prt_fiv_radii
//          uvec4 extra;                   // 48: 1 when the occluder has a cone table, else 0,
//                                         //     first value in prt_fiv_cones (floats), or in
//                                         //     prt_fiv_halves (halves) when extra.z bit 1,
//                                         //     half tables: bit 0 shells, bit 1 cones; 0
//        };
//   PRT_FIV_RADII_BINDING (3)      float prt_fiv_radii[]    each occluder's n_rho radii, increasing
//                                  (surface scheme: the offsets τ_k from the surface), and for the
//                                  surface scheme its [n_theta][n_phi] surface_radius (anywhere:
//                                  offsets.w; the valid mask is then not read)
//   PRT_FIV_SHELLS_BINDING (4)     float prt_fiv_shells[]   each occluder's [n_rho][n_theta][n_phi]
//                                  [RGB][xyz] floats exactly as in /fiv/occluders/<name>/shells
//   PRT_FIV_VALID_BINDING (5)      uint prt_fiv_valid[]     each occluder's uint8 valid mask
//        [n_rho][n_theta][n_phi] packed 4 per uint, LITTLE-ENDIAN: byte b of the mask is bits
//        8·(b mod 4) … 8·(b mod 4) + 7 of word offsets.z + b/4. That is the host's byte array as is
//        (memcpy) on a little-endian host; each occluder's mask starts on a word boundary (pad
//        the previous one to a multiple of 4 bytes). (std430 has no 8-bit arrays without
//        GL_EXT_shader_8bit_storage, an optional feature; packing works everywhere.)
//   PRT_FIV_CONES_BINDING (7)      float prt_fiv_cones[]    each cone occluder's [n_rho][n_theta][n_phi]
//                                  [4] floats (m_x, m_y, m_z, Ω) as in /fiv/occluders/<name>/cones
//                                  (prtshade/fiv.h "Tight proxies"; bind a buffer even when no
//                                  occluder has one: it is read only where extra.x == 1)
//   PRT_FIV_HALVES_BINDING (8)     uint prt_fiv_halves[]    half-float tables (float16 files, v8;
//                                  prtshade/fiv.h "Half-float tables"): the shells and cone tables
//                                  whose extra.z bit says so, as binary16 bits, two per uint,
//                                  LITTLE-ENDIAN (value i is bits 16·(i mod 2) … of word i/2: the
//                                  file's uint16 array as is on a little-endian host); bind a
//                                  buffer even when no table is half
//   PRT_FIV_DIFMAP_BINDING (6)     uvec4 prt_difmap_header; float prt_difmap_texels[];
//        header.x = face size S, header.yzw unused; texels from byte 16: /fiv/irradiance_cube
//        [6][S][S][RGB] floats, faces +X, −X, +Y, −Y, +Z, −Z, OpenGL's cube orientation
//        (prtshade/fiv.h; docs/ARCHITECTURE.md §3 "Two cube conventions").
// (An engine may prefer a samplerCube for the DifMap; Vulkan cube sampling is seamless and its
// bilinear weights have only subTexelPrecisionBits (>= 4) bits, so it will not match the C++ core
// to float precision — this mirror reads the texels itself.)
//
#ifndef PRT_FIV_GLSL
#define PRT_FIV_GLSL

#include "prt_lang.glsl"
#include "fiv_bindings.inc"

layout(std430, set = PRT_FIV_SET, binding = PRT_FIV_DIFMAP_BINDING) readonly buffer PrtFivDifMap {
  uvec4 prt_difmap_header;
  float prt_difmap_texels[];
};
#define PRT_FIV_DIFMAP_SIZE int(prt_difmap_header.x)
#define PRT_FIV_DIFMAP_TEXEL(i) prt_difmap_texels[(i)]

#include "fiv.inc"

#endif  // PRT_FIV_GLSL
