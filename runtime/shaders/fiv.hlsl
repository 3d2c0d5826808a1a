// runtime/shaders/fiv.hlsl — HLSL mirror (glslc -x hlsl, SPIR-V for Vulkan) of the FIV run-time
// shading of runtime/include/prtshade/fiv.h (Michael & Chrysanthou, "Fullsphere Irradiance
// Factorization for Real-Time All-Frequency Illumination for Dynamic Scenes", CGF 2010; paper 004,
// §4.3 "Run time"). The contract is <prtshade/fiv.h>:
//
//   prt_lookup_difmap(n)                 prt::shade::lookup_difmap        E_tot(n), eq. 5 / 11
//   prt_lookup_fiv(o, s)                 prt::shade::lookup_fiv           F(s), §4.3.1–4.3.2
//   prt_partial_factor(o, p, n)          prt::shade::partial_factor       (h + R)/(2R), §4.3.1
//   prt_occluded_irradiance(o, p, n, b)  prt::shade::occluded_irradiance  I = max(0, f·n·F), eq. 10
//   prt_shade_fiv(first, count, p, n,    prt::shade::shade_fiv            eq. 11, 13, 14
//                 partial, overlap)
//   prt_shade_fiv_self(env, o, p, n)     prt::shade::shade_fiv_self       eq. 12
//
// Conventions and numerics: fiv.inc, the body this file shares with fiv.glsl. prt_lookup_fiv
// returns a float3x3 whose row c (F[c]) is channel c's vector, so n·F_c is mul(F, n).
//
// Buffers (all read-only, set PRT_FIV_SET, default 0; bindings below, defaults 2–6 so that
// shade.hlsl's defaults 0–1 fit beside them — #define any of them before including). The bytes
// and descriptors are fiv.glsl's (see its header comment for every field):
//   PRT_FIV_OCCLUDERS_BINDING (2)  StructuredBuffer<PrtFivOccluder> prt_fiv_occluders   64 bytes each:
//        struct PrtFivOccluder { float4 centre_radius; int4 dims; uint4 offsets; uint4 extra; }
//        (centre xyz + bounding radius; n_rho, n_theta, n_phi, radial scheme (0 geometric, 1
//        surface); first radius, first shell float (or half: extra.z bit 0), first valid WORD,
//        first surface radius; 1 with a cone table else 0, first cone float (or half: extra.z
//        bit 1), half tables (bit 0 shells, bit 1 cones), 0)
//   PRT_FIV_RADII_BINDING (3)      StructuredBuffer<float> prt_fiv_radii    each occluder's radii
//        (surface scheme: offsets from the surface) and, surface scheme, its surface_radius
//   PRT_FIV_SHELLS_BINDING (4)     StructuredBuffer<float> prt_fiv_shells   [n_rho][n_theta][n_phi][RGB][xyz]
//   PRT_FIV_VALID_BINDING (5)      StructuredBuffer<uint> prt_fiv_valid     the uint8 valid masks
//        packed 4 per uint, little-endian, each occluder's from a word boundary
//   PRT_FIV_CONES_BINDING (7)      StructuredBuffer<float> prt_fiv_cones    [n_rho][n_theta][n_phi][4]
//        (m_x, m_y, m_z, Ω) of each cone occluder (prtshade/fiv.h "Tight proxies"), read where extra.x == 1
//   PRT_FIV_HALVES_BINDING (8)     StructuredBuffer<uint> prt_fiv_halves    half-float shells and
//        cone tables (float16 files, v8), binary16 bits two per uint, little-endian
//   PRT_FIV_DIFMAP_BINDING (6)     StructuredBuffer<float> prt_fiv_difmap   4 header words (word 0:
//        the face size S as a uint, read with asuint) then /fiv/irradiance_cube [6][S][S][RGB]
//        floats from word 4, faces +X, −X, +Y, −Y, +Z, −Z, OpenGL's cube orientation
//        (prtshade/fiv.h; docs/ARCHITECTURE.md §3 "Two cube conventions").
#ifndef PRT_FIV_HLSL
#define PRT_FIV_HLSL

#include "prt_lang.hlsl"
#include "fiv_bindings.inc"

[[vk::binding(PRT_FIV_DIFMAP_BINDING, PRT_FIV_SET)]] StructuredBuffer<float> prt_fiv_difmap;
#define PRT_FIV_DIFMAP_SIZE int(asuint(prt_fiv_difmap[0]))
#define PRT_FIV_DIFMAP_TEXEL(i) prt_fiv_difmap[4u + (i)]

#include "fiv.inc"

#endif  // PRT_FIV_HLSL
