// runtime/shaders/fiv.glsl — GLSL 450 mirror of the FIV run-time shading of
// runtime/include/prtshade/fiv.h (Michael & Chrysanthou, "Fullsphere Irradiance Factorization for
// Real-Time All-Frequency Illumination for Dynamic Scenes", CGF 2010; paper 004 in
// ../shared/papers, §4.3 "Run time"). The contract is <prtshade/fiv.h>; every convention
// (shell grid, cube faces, cases A/B/C, overlap, self-shadows) is the one in prtshade/fiv.h:
//
//   prt_lookup_difmap(n)                 prt::shade::lookup_difmap        E_tot(n), eq. 5 / 11
//   prt_lookup_fiv(o, s)                 prt::shade::lookup_fiv           F(s), §4.3.1–4.3.2
//   prt_partial_factor(o, p, n)          prt::shade::partial_factor       (h + R)/(2R), §4.3.1
//   prt_occluded_irradiance(o, p, n, b)  prt::shade::occluded_irradiance  I = max(0, f·n·F), eq. 10
//   prt_shade_fiv(first, count, p, n,    prt::shade::shade_fiv            eq. 11, 13, 14
//                 partial, overlap)
//   prt_shade_fiv_self(env, o, p, n)     prt::shade::shade_fiv_self       eq. 12
//
// In short: s = p − centre; ρ = |s|, θ ∈ [0, π] from +Y, φ = atan2(s_x, s_z) wrapped to [0, 2π);
// grid coordinates t = θ/π·(Nθ − 1) (clamped), u = φ/(2π)·Nφ (wraps), ρ linear between the
// bracketing radii (clamped below ρ_0, (ρ_last/ρ)² falloff beyond ρ_last); trilinear over the 8
// neighbours with valid == 0 samples at weight 0 and the rest renormalised, the plain trilinear
// value when the valid neighbours carry no weight. DifMap: face of the largest |component| (ties
// X, then Y, then Z; zero normal → +Y), bilinear, clamped to the outermost texel centres, no
// cross-face filtering. Case C (h = n·(centre − p) <= −R): I = 0; case A (h >= R): factor 1;
// case B: (h + R)/(2R). Overlap: unit bounding discs of angular radius α = asin(min(1, R/D)),
// axis (centre − p)/D (n when D == 0), γ = ∠(a_i, a_j); O_ij = lens(α_i, α_j, γ)/(π α_i² + π α_j²);
// E = E_tot − Σ I_i + Σ_{i<j} O_ij (I_i + I_j), pairs where either I is 0 in all channels skipped,
// clamped to >= 0 per channel. An FIV is returned as a mat3 F with column c = channel c's vector
// (F[c].xyz), so the per-channel irradiance n·F_c is the GLSL product `n * F`.
//
// Buffers (std430 SSBOs, all readonly; set PRT_FIV_SET, default 0; bindings below, defaults 2–6
// so that shade.glsl's defaults 0–1 fit beside them — #define any of them before including):
//   PRT_FIV_OCCLUDERS_BINDING (2)  PrtFivOccluder prt_fiv_occluders[]   one per occluder, 48 bytes:
//        struct PrtFivOccluder {          // std430 offsets
//          vec4  centre_radius;           //  0: centre xyz (world), w = bounding radius R (> 0)
//          ivec4 dims;                    // 16: n_rho (>= 1), n_theta (>= 2), n_phi (>= 1), unused
//          uvec4 offsets;                 // 32: first radius in prt_fiv_radii (floats),
//        };                               //     first value in prt_fiv_shells (floats),
//                                         //     first WORD in prt_fiv_valid (uints), unused
//   PRT_FIV_RADII_BINDING (3)      float prt_fiv_radii[]    each occluder's n_rho radii, increasing
//   PRT_FIV_SHELLS_BINDING (4)     float prt_fiv_shells[]   each occluder's [n_rho][n_theta][n_phi]
//                                  [RGB][xyz] floats exactly as in /fiv/occluders/<name>/shells
//   PRT_FIV_VALID_BINDING (5)      uint prt_fiv_valid[]     each occluder's uint8 valid mask
//        [n_rho][n_theta][n_phi] packed 4 per uint, LITTLE-ENDIAN: byte b of the mask is bits
//        8·(b mod 4) … 8·(b mod 4) + 7 of word offsets.z + b/4. That is the host's byte array as is
//        (memcpy) on a little-endian host; each occluder's mask starts on a word boundary (pad
//        the previous one to a multiple of 4 bytes). (std430 has no 8-bit arrays without
//        GL_EXT_shader_8bit_storage, an optional feature; packing works everywhere.)
//   PRT_FIV_DIFMAP_BINDING (6)     uvec4 prt_difmap_header; float prt_difmap_texels[];
//        header.x = face size S, header.yzw unused; texels from byte 16: /fiv/irradiance_cube
//        [6][S][S][RGB] floats, faces +X, −X, +Y, −Y, +Z, −Z, OpenGL's cube orientation
//        (prtshade/fiv.h; docs/ARCHITECTURE.md §3 "Two cube conventions").
// (An engine may prefer a samplerCube for the DifMap; Vulkan cube sampling is seamless and its
// bilinear weights have only subTexelPrecisionBits (>= 4) bits, so it will not match the C++ core
// to float precision — this mirror reads the texels itself.)
//
// Numerics: float throughout. Angles come from prt_atan2 below (Abramowitz & Stegun 4.4.49,
// |error| <= 2e-8 rad, plus float rounding) instead of the built-ins, whose Vulkan precision is
// only 4096 ulp; θ = atan2(|s_xz|, s_y) and γ = atan2(|a×b|, a·b) stay accurate near the poles and
// for small angles, where acos(·) loses half the digits. The lens area uses the same atan2 form
// (one √k shared by all terms, so its cancellation at tangency is first-order exact). Inputs must
// be finite; ρ = |s| is formed in float (the C++ core uses double: |s| < 1e18 is safe).
// prt_shade_fiv accumulates E in float (the C++ core in double), so its rounding grows like
// (count + 2) ε (E_tot + Σ_i I_i (1 + Σ_j O_ij)) — the bound the test allows.
// Agreement with the C++ core on lavapipe is asserted in tests/shaders/test_fiv_glsl.cpp with
// tolerances from the sensitivity of the result to the angles' and radii's rounding.
//
// Limits: prt_shade_fiv keeps one bit per occluder for the overlap pass in a local mask of
// PRT_FIV_MAX_OCCLUDERS bits (default 128); beyond that the occluder's activity is recomputed
// (one more lookup per pair): any count is correct, large counts are slower. Active occluders
// are looked up twice when overlap correction is on (no per-occluder arrays in registers).
#ifndef PRT_FIV_GLSL
#define PRT_FIV_GLSL

#ifndef PRT_FIV_SET
#define PRT_FIV_SET 0
#endif
#ifndef PRT_FIV_OCCLUDERS_BINDING
#define PRT_FIV_OCCLUDERS_BINDING 2
#endif
#ifndef PRT_FIV_RADII_BINDING
#define PRT_FIV_RADII_BINDING 3
#endif
#ifndef PRT_FIV_SHELLS_BINDING
#define PRT_FIV_SHELLS_BINDING 4
#endif
#ifndef PRT_FIV_VALID_BINDING
#define PRT_FIV_VALID_BINDING 5
#endif
#ifndef PRT_FIV_DIFMAP_BINDING
#define PRT_FIV_DIFMAP_BINDING 6
#endif
#ifndef PRT_FIV_MAX_OCCLUDERS
#define PRT_FIV_MAX_OCCLUDERS 128
#endif
#define PRT_FIV_MASK_WORDS ((PRT_FIV_MAX_OCCLUDERS + 31) / 32)

struct PrtFivOccluder {
  vec4 centre_radius;
  ivec4 dims;
  uvec4 offsets;
};

layout(std430, set = PRT_FIV_SET, binding = PRT_FIV_OCCLUDERS_BINDING) readonly buffer PrtFivOccluders {
  PrtFivOccluder prt_fiv_occluders[];
};
layout(std430, set = PRT_FIV_SET, binding = PRT_FIV_RADII_BINDING) readonly buffer PrtFivRadii {
  float prt_fiv_radii[];
};
layout(std430, set = PRT_FIV_SET, binding = PRT_FIV_SHELLS_BINDING) readonly buffer PrtFivShells {
  float prt_fiv_shells[];
};
layout(std430, set = PRT_FIV_SET, binding = PRT_FIV_VALID_BINDING) readonly buffer PrtFivValid {
  uint prt_fiv_valid[];
};
layout(std430, set = PRT_FIV_SET, binding = PRT_FIV_DIFMAP_BINDING) readonly buffer PrtFivDifMap {
  uvec4 prt_difmap_header;
  float prt_difmap_texels[];
};

const float PRT_FIV_PI = 3.14159265358979323846;
const float PRT_FIV_HALF_PI = 1.57079632679489661923;
const float PRT_FIV_TWO_PI = 6.28318530717958647692;

// atan2(y, x) in (−π, π] (atan2(0, 0) = 0), without the built-in: atan on [0, 1] by the odd
// polynomial of Abramowitz & Stegun 4.4.49 (|error| <= 2e-8 rad), then the octant reduction.
float prt_atan2(float y, float x) {
  float ax = abs(x), ay = abs(y);
  float mx = max(ax, ay), mn = min(ax, ay);
  float a = mx > 0.0 ? mn / mx : 0.0;
  float a2 = a * a;
  float p = 0.0028662257;
  p = p * a2 - 0.0161657367;
  p = p * a2 + 0.0429096138;
  p = p * a2 - 0.0752896400;
  p = p * a2 + 0.1065626393;
  p = p * a2 - 0.1420889944;
  p = p * a2 + 0.1999355085;
  p = p * a2 - 0.3333314528;
  p = p * a2 + 1.0;
  float r = a * p;
  if (ay > ax) r = PRT_FIV_HALF_PI - r;
  if (x < 0.0) r = PRT_FIV_PI - r;
  return y < 0.0 ? -r : r;
}

// asin(x) for x in [0, 1] as atan2(x, √((1 − x)(1 + x))).
float prt_fiv_asin01(float x) { return prt_atan2(x, sqrt(max(0.0, (1.0 - x) * (1.0 + x)))); }

// Bilinear coordinate along one face axis: texel centres at 2(q + ½)/S − 1, clamped to the outer ones.
void prt_fiv_face_coordinate(float s, int size, out int q0, out int q1, out float f) {
  float q = clamp((s + 1.0) * 0.5 * float(size) - 0.5, 0.0, float(size - 1));
  q0 = min(int(q), size - 1);
  q1 = min(q0 + 1, size - 1);
  f = q - float(q0);
}

vec3 prt_fiv_texel(int face, int row, int column, int size) {
  uint base = 3u * uint((face * size + row) * size + column);
  return vec3(prt_difmap_texels[base], prt_difmap_texels[base + 1u], prt_difmap_texels[base + 2u]);
}

// E_tot(n): bilinear in the face n selects (mirrors prt::shade::lookup_difmap).
vec3 prt_lookup_difmap(vec3 n) {
  float ax = abs(n.x), ay = abs(n.y), az = abs(n.z);
  int face;
  float s, t, ma;
  if (ax >= ay && ax >= az && ax > 0.0) {
    ma = ax;
    face = n.x > 0.0 ? 0 : 1;
    s = n.x > 0.0 ? -n.z : n.z;
    t = -n.y;
  } else if (ay >= az && ay > 0.0) {
    ma = ay;
    face = n.y > 0.0 ? 2 : 3;
    s = n.x;
    t = n.y > 0.0 ? n.z : -n.z;
  } else if (az > 0.0) {
    ma = az;
    face = n.z > 0.0 ? 4 : 5;
    s = n.z > 0.0 ? n.x : -n.x;
    t = -n.y;
  } else {  // zero normal: +Y, the face centre
    ma = 1.0;
    face = 2;
    s = 0.0;
    t = 0.0;
  }
  s /= ma;
  t /= ma;
  int size = int(prt_difmap_header.x);
  int q0, q1, r0, r1;
  float fq, fr;
  prt_fiv_face_coordinate(s, size, q0, q1, fq);
  prt_fiv_face_coordinate(t, size, r0, r1, fr);
  vec3 a = prt_fiv_texel(face, r0, q0, size), b = prt_fiv_texel(face, r0, q1, size);
  vec3 c = prt_fiv_texel(face, r1, q0, size), d = prt_fiv_texel(face, r1, q1, size);
  vec3 top = a + fq * (b - a);
  vec3 bottom = c + fq * (d - c);
  return top + fr * (bottom - top);
}

// Occluded FIV F(s) at offset s = p − centre of occluder o; column c = channel c
// (mirrors prt::shade::lookup_fiv).
mat3 prt_lookup_fiv(uint o, vec3 s) {
  PrtFivOccluder occ = prt_fiv_occluders[o];
  int n_rho = occ.dims.x, n_theta = occ.dims.y, n_phi = occ.dims.z;
  float rho = length(s);
  float theta = prt_atan2(length(s.xz), s.y);  // [0, π]; s = 0 gives θ = 0 (d = +Y)
  float phi = prt_atan2(s.x, s.z);
  if (phi < 0.0) phi += PRT_FIV_TWO_PI;

  // θ: clamped, poles included.
  float t = clamp(theta / PRT_FIV_PI * float(n_theta - 1), 0.0, float(n_theta - 1));
  int i0 = min(int(t), n_theta - 2);
  float ft = t - float(i0);
  // φ: wraps (u == n_phi is φ == 2π, i.e. column 0).
  float u = clamp(phi / PRT_FIV_TWO_PI * float(n_phi), 0.0, float(n_phi));
  int ju = min(int(u), n_phi);
  float fu = u - float(ju);
  int j0 = ju % n_phi, j1 = (ju + 1) % n_phi;
  // ρ: linear between the bracketing radii, clamped inside, (ρ_last/ρ)² outside.
  uint rb = occ.offsets.x;
  int last = n_rho - 1;
  int k0 = 0, k1 = 0;
  float fr = 0.0, falloff = 1.0;
  float r_first = prt_fiv_radii[rb];
  if (rho <= r_first || last == 0) {
    if (last == 0 && rho > r_first) {
      float q = r_first / rho;
      falloff = q * q;
    }
  } else if (rho >= prt_fiv_radii[rb + uint(last)]) {
    k0 = last;
    k1 = last;
    float q = prt_fiv_radii[rb + uint(last)] / rho;
    falloff = q * q;
  } else {
    int lo = 0, hi = last;  // radii[lo] <= ρ < radii[hi]
    while (hi - lo > 1) {
      int mid = (lo + hi) / 2;
      if (prt_fiv_radii[rb + uint(mid)] <= rho) lo = mid;
      else hi = mid;
    }
    k0 = lo;
    k1 = hi;
    float r0 = prt_fiv_radii[rb + uint(k0)];
    fr = clamp((rho - r0) / (prt_fiv_radii[rb + uint(k1)] - r0), 0.0, 1.0);
  }

  mat3 plain = mat3(0.0), masked = mat3(0.0);
  float masked_weight = 0.0;
  for (int a = 0; a < 2; ++a) {
    for (int b = 0; b < 2; ++b) {
      for (int c = 0; c < 2; ++c) {
        int k = a == 0 ? k0 : k1, i = i0 + b, j = c == 0 ? j0 : j1;
        float w = (a == 0 ? 1.0 - fr : fr) * (b == 0 ? 1.0 - ft : ft) * (c == 0 ? 1.0 - fu : fu);
        uint idx = uint((k * n_theta + i) * n_phi + j);
        uint base = occ.offsets.y + 9u * idx;
        mat3 v = mat3(prt_fiv_shells[base], prt_fiv_shells[base + 1u], prt_fiv_shells[base + 2u],
                      prt_fiv_shells[base + 3u], prt_fiv_shells[base + 4u], prt_fiv_shells[base + 5u],
                      prt_fiv_shells[base + 6u], prt_fiv_shells[base + 7u], prt_fiv_shells[base + 8u]);
        plain += w * v;
        uint word = prt_fiv_valid[occ.offsets.z + (idx >> 2u)];
        if (((word >> (8u * (idx & 3u))) & 0xFFu) != 0u) {
          masked_weight += w;
          masked += w * v;
        }
      }
    }
  }
  if (masked_weight > 0.0) return masked * (1.0 / masked_weight) * falloff;
  return plain * falloff;
}

// n / |n|; a zero or non-finite normal is +Y (prtshade/fiv.h "Numerics": only a normal's
// direction counts).
vec3 prt_fiv_unit_normal(vec3 n) {
  float l = length(n);
  return (l > 0.0 && !isinf(l)) ? n / l : vec3(0.0, 1.0, 0.0);
}

// h = n·(centre − p): the signed height of the occluder's centre over the receiver's plane.
float prt_fiv_plane_height(uint o, vec3 p, vec3 n) { return dot(n, prt_fiv_occluders[o].centre_radius.xyz - p); }

// prt_partial_factor for a unit n.
float prt_partial_factor_unit(uint o, vec3 p, vec3 n) {
  float h = prt_fiv_plane_height(o, p, n), R = prt_fiv_occluders[o].centre_radius.w;
  if (!(h > -R)) return 0.0;
  if (h >= R) return 1.0;
  return clamp((h + R) / (2.0 * R), 0.0, 1.0);
}

// Case C: 0, case A: 1, case B: (h + R)/(2R), n of any length (mirrors prt::shade::partial_factor).
float prt_partial_factor(uint o, vec3 p, vec3 n) { return prt_partial_factor_unit(o, p, prt_fiv_unit_normal(n)); }

// prt_occluded_irradiance for a unit n.
vec3 prt_occluded_irradiance_unit(uint o, vec3 p, vec3 n, bool partial) {
  float factor = partial ? prt_partial_factor_unit(o, p, n)
                         : (prt_fiv_plane_height(o, p, n) > -prt_fiv_occluders[o].centre_radius.w ? 1.0 : 0.0);
  if (factor == 0.0) return vec3(0.0);
  mat3 F = prt_lookup_fiv(o, p - prt_fiv_occluders[o].centre_radius.xyz);
  return max(vec3(0.0), factor * (n * F));
}

// Per channel max(0, factor · n̂·F_c(p − centre)); factor = partial_factor, or 1 when `partial`
// is false (case C stays 0) (mirrors prt::shade::occluded_irradiance).
vec3 prt_occluded_irradiance(uint o, vec3 p, vec3 n, bool partial) {
  return prt_occluded_irradiance_unit(o, p, prt_fiv_unit_normal(n), partial);
}

// Area of the lens of two planar discs of radii r1, r2 whose centres are d apart (prt::shade::
// lens_area): r1² θ1 + r2² θ2 − ½√k with the half-angles θ_i = atan2(√k, d² + r_i² − r_j²).
float prt_fiv_lens_area(float r1, float r2, float d) {
  if (d >= r1 + r2) return 0.0;
  float rmin = min(r1, r2);
  if (d <= abs(r1 - r2)) return PRT_FIV_PI * rmin * rmin;
  float k = max(0.0, (-d + r1 + r2) * (d + r1 - r2) * (d - r1 + r2) * (d + r1 + r2));
  float sk = sqrt(k);
  float area = r1 * r1 * prt_atan2(sk, d * d + r1 * r1 - r2 * r2) + r2 * r2 * prt_atan2(sk, d * d + r2 * r2 - r1 * r1) -
               0.5 * sk;
  return clamp(area, 0.0, PRT_FIV_PI * rmin * rmin);
}

// The unit bounding disc of occluder o seen from p: xyz = axis, w = angular radius α.
vec4 prt_fiv_disc(uint o, vec3 p, vec3 n) {
  vec4 cr = prt_fiv_occluders[o].centre_radius;
  vec3 v = cr.xyz - p;
  float D = length(v);
  if (!(D > 0.0)) return vec4(n, cr.w > 0.0 ? PRT_FIV_HALF_PI : 0.0);  // p at the centre
  return vec4(v / D, prt_fiv_asin01(min(1.0, cr.w / D)));
}

// O_ij of eq. 14: lens area over the sum of the two disc areas.
float prt_fiv_overlap(vec4 disc_i, vec4 disc_j) {
  float denom = PRT_FIV_PI * (disc_i.w * disc_i.w + disc_j.w * disc_j.w);
  if (!(denom > 0.0)) return 0.0;
  float gamma = prt_atan2(length(cross(disc_i.xyz, disc_j.xyz)), dot(disc_i.xyz, disc_j.xyz));
  return prt_fiv_lens_area(disc_i.w, disc_j.w, gamma) / denom;
}

// Irradiance at receiver (p, n) shadowed by occluders first … first + count − 1 (eq. 11, 13, 14;
// mirrors prt::shade::shade_fiv). Σ_{i<j} O_ij (I_i + I_j) is summed as Σ_i I_i Σ_{j≠i} O_ij over
// the occluders that hide something.
vec3 prt_shade_fiv(uint first, uint count, vec3 p, vec3 n_in, bool partial, bool overlap) {
  vec3 n = prt_fiv_unit_normal(n_in);
  vec3 e = prt_lookup_difmap(n);
  uint hides[PRT_FIV_MASK_WORDS];
  for (int w = 0; w < PRT_FIV_MASK_WORDS; ++w) hides[w] = 0u;
  for (uint i = 0u; i < count; ++i) {
    vec3 I = prt_occluded_irradiance_unit(first + i, p, n, partial);
    if (!any(greaterThan(I, vec3(0.0)))) continue;
    e -= I;
    if (i < uint(PRT_FIV_MAX_OCCLUDERS)) hides[i >> 5u] |= 1u << (i & 31u);
  }
  if (overlap) {
    for (uint i = 0u; i < count; ++i) {
      bool hides_i = i < uint(PRT_FIV_MAX_OCCLUDERS) ? (hides[i >> 5u] & (1u << (i & 31u))) != 0u : true;
      if (!hides_i) continue;
      vec3 I = prt_occluded_irradiance_unit(first + i, p, n, partial);
      if (!any(greaterThan(I, vec3(0.0)))) continue;
      vec4 disc_i = prt_fiv_disc(first + i, p, n);
      float weight = 0.0;  // Σ_{j ≠ i, j hides something} O_ij
      for (uint j = 0u; j < count; ++j) {
        if (j == i) continue;
        if (j < uint(PRT_FIV_MAX_OCCLUDERS)) {
          if ((hides[j >> 5u] & (1u << (j & 31u))) == 0u) continue;
        }
        float o = prt_fiv_overlap(disc_i, prt_fiv_disc(first + j, p, n));
        if (o > 0.0 && j >= uint(PRT_FIV_MAX_OCCLUDERS) &&
            !any(greaterThan(prt_occluded_irradiance_unit(first + j, p, n, partial), vec3(0.0))))
          continue;
        weight += o;
      }
      e += weight * I;
    }
  }
  return max(e, vec3(0.0));
}

// Self-shadows (eq. 12): max(0, n·F^env_c − n·F_c(p − centre)); env_fiv = /fiv/environment
// [RGB][xyz] (mirrors prt::shade::shade_fiv_self).
vec3 prt_shade_fiv_self(float env_fiv[9], uint o, vec3 p, vec3 n_in) {
  vec3 n = prt_fiv_unit_normal(n_in);
  mat3 env = mat3(env_fiv[0], env_fiv[1], env_fiv[2], env_fiv[3], env_fiv[4], env_fiv[5], env_fiv[6], env_fiv[7],
                  env_fiv[8]);
  mat3 F = prt_lookup_fiv(o, p - prt_fiv_occluders[o].centre_radius.xyz);
  return max(vec3(0.0), n * env - n * F);
}

#endif  // PRT_FIV_GLSL
