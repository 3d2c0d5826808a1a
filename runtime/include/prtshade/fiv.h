// prtshade/fiv.h — run-time shading with Fullsphere Irradiance Vectors (Michael & Chrysanthou,
// "Fullsphere Irradiance Factorization for Real-Time All-Frequency Illumination for Dynamic
// Scenes", CGF 2010; paper 004 in ../shared/papers, §4.3 "Run time"): DifMap lookup, trilinear
// lookup of an occluder's baked FIV shells, the three occluder cases A/B/C with the partial-
// occluder factor, the overlap correction for several occluders (eq. 13–14) and self-shadows
// (eq. 12). This header is the contract shared with the C API and the GLSL mirrors
// (docs/ARCHITECTURE.md §2); the baked data and its conventions are libbake/bake/include/bake/bake/fiv.h
// and formats/SCHEMA.md.
//
// Quantities (per RGB channel c; an FIV is [RGB][xyz] = 9 floats, row-major):
//   environment FIV  F_c^env = ∫ L_c(ω) ω dω                        (/fiv/environment)
//   occluded FIV     F_c(s)  = ∫ (1 − V_O(s, ω)) L_c(ω) ω dω         at offset s = p − centre
//   DifMap           E_tot(n) = ∫ L(ω) H(ω, n) (n·ω) dω              (/fiv/irradiance_cube)
// A receiver p with normal n shadowed by occluders O_i gets (eq. 11)
//   E(p, n) = E_tot(n) − Σ_i I_i,   I_i = n · F_i(p − centre_i)   (case A, eq. 10),
// an unshadowed irradiance minus what each occluder hides. Units: radiance × steradian, like E.
//
// Shell grid (bake/bake/fiv.h): sample (k, i, j) sits at centre + ρ_k d(θ_i, φ_j) with
//   θ_i = π i / (Nθ − 1) from +Y (poles included), φ_j = 2π j / Nφ from +Z towards +X,
//   d(θ, φ) = (sin θ sin φ, cos θ, sin θ cos φ), radii ρ_k increasing;
//   shells [Nρ][Nθ][Nφ][RGB][xyz], valid [Nρ][Nθ][Nφ] (0 = inside closed geometry).
// Lookup (continuous grid coordinates; φ wraps, θ and ρ clamp):
//   ρ = |s|, d = s/ρ (ρ == 0: d = +Y), θ = acos(d_y), φ = atan2(d_x, d_z) wrapped to [0, 2π),
//   t = θ/π · (Nθ − 1), u = φ/(2π) · Nφ; ρ < ρ_0 clamps to ρ_0; ρ > ρ_last returns the last
//   shell's value times (ρ_last/ρ)² (a distant occluder hides a solid angle ∝ 1/ρ²; continuous at
//   the last shell). Trilinear over the 8 neighbours; neighbours with valid == 0 get weight 0 and
//   the rest are renormalised (§4.3.2: "samples that fall within the geometry of the object are
//   not taken into account"); if the valid neighbours carry no weight (in particular all 8
//   invalid), the plain trilinear value of the stored samples is used.
//
// Surface-following shells (radial_scheme == kFivRadialSurface; issue 33, replacing §4.1's
// spheres): sample (k, i, j) sits at centre + (r_surf(i, j) + τ_k) d(θ_i, φ_j), where
// r_surf(i, j) = surface_radius[i][j] is the largest distance from the centre at which the ray
// centre + t d(θ_i, φ_j) meets the occluder (0 when it misses) and the offsets τ_k = radii[k]
// grow geometrically, τ_k = τ_0 g^k (τ_0 a small fraction of R: the contact shadow within a gap
// of a few hundredths of R is resolved where a sphere shell would pass through the occluder).
// Lookup: the same (t, u) as above; r_s = bilinear of surface_radius at (t, u) (the same weights
// as the shell samples, so r_s is continuous in the direction), τ = ρ − r_s; τ <= τ_0 clamps to
// the first shell (offsets inside the outer hull), τ >= τ_last returns the last shell's value
// times ((r_s + τ_last)/ρ)²; between, k0 = ⌊log(τ/τ_0)/log g⌋ (the closed-form inverse of the
// grading, its log2 estimated from the floats' bits to within 0.09, then the bracket moved against
// the stored radii, so that neither the estimate nor rounding picks a wrong one),
// fr = (τ − τ_k0)/(τ_k0+1 − τ_k0), and plain trilinear over the 8 neighbours: samples the bake found inside the occluder were extrapolated outwards along their
// radial line (bake/bake/fiv.h), so there is no valid mask to renormalise by (valid is not read;
// it may be null). At a grid direction the stored samples come back (up to float rounding of the
// angles and of τ); the lookup is continuous everywhere (r_s and τ ↦ (k, fr) are continuous).
//
// Cube map (DifMap): faces +X, −X, +Y, −Y, +Z, −Z in OpenGL's cube-map convention (not OpenEXR's,
// which input environment cube maps use: docs/ARCHITECTURE.md §3 "Two cube conventions"); texel
// (row r, column q) of a size-S face has s = 2(q + ½)/S − 1, t = 2(r + ½)/S − 1 and direction
//   +X (1, −t, −s)  −X (−1, −t, s)  +Y (s, 1, t)  −Y (s, −1, −t)  +Z (s, −t, 1)  −Z (−s, −t, −1).
// A direction selects the face of its largest |component| (ties: X before Y before Z); bilinear
// inside that face, coordinates clamped to the outermost texel centres (no cross-face filtering).
//
// Occluder cases (§4.3.1, Figure 7; R = bounding-sphere radius, h = n·(centre − p), the signed
// distance of the centre from the receiver's tangent plane):
//   C  h <= −R   the occluder lies wholly below the horizon: I = 0;
//   A  h >=  R   wholly above: I = n·F;
//   B  otherwise partly above: I = (h + R)/(2R) · n·F — the fraction of the occluder above the
//      plane, "(d + R)/2R" in the paper (after Malmer et al. 2007). (For R == 0, h == 0 is C.)
//   Per channel, I is clamped to >= 0 (an occluder never adds light).
// Overlap (eq. 13–14, "Unit Bounding Discs"): occluder i seen from p has axis a_i = (centre_i −
//   p)/D_i, D_i = |centre_i − p|, angular radius α_i = asin(min(1, R_i/D_i)) (α = π/2 when p is
//   inside the bounding sphere, then a_i = n if D_i == 0). Each is replaced by a planar disc of
//   radius α_i; two discs at centre distance γ = ∠(a_i, a_j) overlap in a lens of area A_ij and
//   O_ij = A_ij / (π α_i² + π α_j²). Pairwise inclusion–exclusion (second-order truncation):
//     E = E_tot(n) − Σ_i I_i + Σ_{i<j} O_ij (I_i + I_j),   clamped to >= 0 per channel;
//   pairs where either occluder hides nothing (I = 0 in all channels, e.g. case C) are skipped.
//   Two identical occluders give O = ½, so I_1 + I_2 − ½(2I) = I, not 2I; disjoint discs give
//   O = 0. With three or more mutually overlapping occluders the truncation over-corrects
//   (three identical ones give E_tot − 3I + 3I): the paper's approximation, kept as specified.
// Tight proxies (issue 33; replaces the bounding sphere of §4.3.1 and eq. 13–14 where an occluder
//   has them). The bounding sphere covers far more sky than a non-spherical object (the bunny:
//   R = 6.64 for a 9.65 × 7.5 object), so its disc over-corrects the overlap and its (h + R)/2R
//   scales real shadows down. An occluder may carry a cone table beside its shells,
//   cones [n_rho][n_theta][n_phi][4] = (m_x, m_y, m_z, Ω) with the occluded solid angle and moment
//     Ω(s) = ∫ (1 − V_O(s, ω)) dω,   m(s) = ∫ (1 − V_O(s, ω)) ω dω,
//   baked exactly by the same integrals as the shells (bake/bake/fiv.h), on the same grid and
//   looked up with the same stencil (the valid mask, renormalisation, clamp and (ρ_last/ρ)² falloff
//   of the shells — for surface-following shells their plain trilinear stencil and falloff, no
//   mask: both are integrals over the occluded set, so both fall off like it). From p,
//   occluder i is then the cap (its cone) of axis a = m/|m| (the direction towards the centre
//   when m = 0) and half-angle α with 2π(1 − cos α) = Ω (the cap of the occluded solid angle,
//   centred on the occluded directions' mean). With FivShadeOptions::proxy == cone:
//   - overlap: the disc of eq. 13–14 is that cap, α clamped to π/2 as the sphere's is; and a pair
//     of two tight occluders adds back, per channel, the lens A_ij (eq. 14's lens_area) times the
//     lower of the two irradiance densities, A_ij · min(I_i/(π α_i²), I_j/(π α_j²)), instead of
//     O_ij (I_i + I_j) = A_ij (I_i + I_j)/(π α_i² + π α_j²). What is counted twice is the
//     irradiance through the lens; eq. 14 gives the lens the caps' area-weighted mean density,
//     which an occluder hiding a bright light (a sun) outside the lens inflates; the lens lies in
//     both caps, so the lower density is the one the lens can count on. Never more than eq. 14
//     ((A_i + A_j) min(d_i, d_j) <= A_i d_i + A_j d_j), equal to it for equal densities (two
//     identical occluders still give I, not 2I). Pairs with a sphere keep eq. 14;
//   - partial occluders, instead of the factor (h + R)/2R: n·F over the whole sphere counts the
//     occluded directions below the horizon negatively, ∫_occ L n·ω = I_true − ∫_{occ, n·ω<0} L |n·ω|,
//     so the missing part is added back, estimated as the cap's part below the horizon lit by
//     the receiver's mean radiance from below, L̄_c = E_tot,c(−n)/π (the DifMap at −n is
//     ∫_{n·ω<0} L |n·ω| dω; the mean of L under that weight is it over π):
//       I_c = max(0, n·F_c + L̄_c · K(−n·a, α)),   K(x, α) = ∫_cap max(0, ν·ω) dω, ν·a = x,
//     with K the clamped cosine over a cap cut by a horizon (cap_clamped_cosine below, closed
//     form). An occluder wholly above the horizon (n·a >= sin α) keeps I = n·F exactly (K = 0),
//     one wholly below (n·a <= −sin α) gives 0 — the cap's own cases A and C; the sphere's case
//     C (h <= −R) still drops an occluder before any lookup. Without partial occluders I =
//     max(0, n·F) for both proxies (case C by the sphere).
//   Occluders without a table keep the sphere under either option. proxy == sphere is the paper's
//   formulation for every occluder, for comparison. occluded_irradiance and shade_fiv_member take
//   no DifMap and use the sphere.
//   K(x, α) for α <= π/2 and s = sin α, c = cos α, y = √(1 − x²): x >= s (cap above): π x s²;
//   x <= −s (below): 0; otherwise, with the cap's boundary circle cut by the horizon great
//   circle, integrating ν·ω over the cap's part above it by Lambert's boundary form (the vector
//   irradiance of a region is ½ ∮ of its boundary's tangent-cross terms, here one circle arc and
//   one horizon arc) gives
//     K = (x acos(q) − (c/s) z) s² + atan2(z, c/s),   q = −(c/s)(x/y),  z = y √(1 − q²);
//   for α > π/2 the complement: K(x, α) = π − K(−x, π − α). Continuous at x = ±s; tested against
//   numerical integration (tests/runtime/test_fiv_runtime.cpp CapClampedCosine).
// Half-float tables (issue 33; file dtype float16, schema v8): an occluder's shells and cone table
//   may be held as IEEE 754 binary16 bits (FivOccluder::shells_half, cones_half) instead of floats,
//   half the memory: at the paper's 2.17 MiB for 64x33x30 float shells, 96x49x26 half shells, or
//   84x43x24 shells and cones (docs/FIGURES.md). A lookup decodes each sample it reads exactly
//   (half_to_float: every finite half is a float) and then does what it does for floats, so a
//   half table gives bit for bit what the float table of the decoded values gives. Rounding a
//   value to half moves it by at most 2^-11 of itself (2^-25 absolute below 2^-14).
// Self-shadows (§4.3.2, eq. 12): a receiver ON occluder O sees unoccluded light only in its
//   positive hemisphere, so E = max(0, n·F^env − n·F(p − centre)) per channel.
//
// Numerics: inputs and outputs are float; shade_fiv sums its terms in double (hundreds of
// occluders and pair terms would otherwise drift by count·ε·E_tot); s = p − centre, |s| and the
// plane height n·(centre − p) are formed in double (no overflow for any finite float input), the
// angles in float. shade_fiv takes its angles (θ, φ, α, γ) from the shader mirrors' polynomial
// atan2 (Abramowitz & Stegun 4.4.49, 2e-8 rad) and forms O_ij in float with their lens formula;
// lookup_fiv, occluded_irradiance and shade_fiv_reference use std::atan2 and double. The two stay
// within 7e-7 rad of each other's angles, so n·F differs by at most 7e-7 rad times the shells'
// change per radian (plus float rounding), and O_ij by at most 7e-7 / (π min(α_i, α_j)) per
// overlapping pair (tests/runtime/test_fiv_runtime.cpp ScatteredOccludersMatchTheSlowReference). Only the direction of a normal counts: the shading functions use n/|n| (|n| in
// double), and a zero or non-finite normal is +Y, the direction lookup_difmap gives it.
// Irradiance data (shell values, DifMap texels, the environment FIV) must be finite with
// magnitude <= kFivValueLimit = 2^64 (the validate_* functions refuse more; no light reaches it):
// then every interpolated F and every n·F is below 2·2^64, and every sum, even over 2^30
// occluders and their pairs, stays far below FLT_MAX (2^128). So every output is finite for
// finite inputs, including p at an occluder's centre or 10^38 away, ρ far beyond the last shell,
// normals of any length and NaN offsets given to lookup_fiv (treated as ρ = 0).
// Preconditions: the hot-path functions trust their FivOccluder/DifMap (call validate_occluder /
// validate_difmap once when the data arrives — the C API and the loader do); they allocate
// nothing except shade_fiv for more than 128 occluders. shade_fiv keeps its per-receiver arrays
// on the stack (about 22 KB). Thread-safe (no shared state).
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>

namespace prt::shade {

// How an occluder's shells are placed along each direction (header comment; /fiv/occluders/<name>
// attribute radial_scheme, formats/SCHEMA.md).
inline constexpr int kFivRadialGeometric = 0;  // spheres ρ_k around the centre (paper 004 §4.1)
inline constexpr int kFivRadialSurface = 1;    // r_surf(θ, φ) + τ_k, following the surface (issue 33)

// Non-owning view of one baked occluder (/fiv/occluders/<name>): shells [n_rho][n_theta][n_phi]
// [3 RGB][3 xyz], valid [n_rho][n_theta][n_phi], radii[n_rho] increasing, centre in world space,
// radius R of the bounding sphere. Geometric scheme: radii are the shell radii ρ_k. Surface
// scheme: radii are the offsets τ_k from the surface (geometric: τ_k = τ_0 g^k), surface_radius
// [n_theta][n_phi] is r_surf, and valid is not read.
struct FivOccluder {
  float centre[3];
  float radius;
  int n_rho, n_theta, n_phi;
  const float* radii;
  const float* shells;
  const uint8_t* valid;
  int radial_scheme = kFivRadialGeometric;
  const float* surface_radius = nullptr;  // [n_theta][n_phi], surface scheme only
  // The tight proxy (header "Tight proxies"): cones [n_rho][n_theta][n_phi][4] = (m_x, m_y, m_z, Ω),
  // or nullptr: the occluder's proxy is its bounding sphere.
  const float* cones = nullptr;
  // Half-float tables (header comment): the shells as binary16 bits (then shells is nullptr) and
  // the cone table likewise (then cones is nullptr); the same layouts.
  const uint16_t* shells_half = nullptr;
  const uint16_t* cones_half = nullptr;
};

// True when the occluder carries a cone table (float or half).
inline bool has_cones(const FivOccluder& o) { return o.cones != nullptr || o.cones_half != nullptr; }

// The value of finite binary16 bits h, exactly (sign, 5 exponent bits with bias 15, 10 mantissa
// bits; exponent 0: subnormal m·2^-24). Bits with exponent 31 (±inf, NaN) are not finite halves:
// validate_occluder refuses them and the result is unspecified.
inline float half_to_float(uint16_t h) {
  const uint32_t sign = uint32_t(h & 0x8000u) << 16;
  // A normal half: the exponent rebased from 15 to 127, the mantissa moved to the top of float's.
  const uint32_t normal = ((uint32_t(h & 0x7fffu) << 13) + (112u << 23)) | sign;
  const float subnormal = float(h & 0x3ffu) * 0x1p-24f;  // exact: m < 2^10
  return (h & 0x7c00u) != 0 ? std::bit_cast<float>(normal) : (sign != 0 ? -subnormal : subnormal);
}

// Which proxy the corrections use (header "Tight proxies").
enum class FivProxy : int {
  sphere = 0,  // the bounding sphere for every occluder (paper 004 §4.3.1, eq. 13–14)
  cone = 1,    // the cone table where an occluder has one, else the sphere
};

// The DifMap /fiv/irradiance_cube [6][size][size][3], faces +X,−X,+Y,−Y,+Z,−Z, OpenGL orientation
// (header comment).
struct DifMap {
  int size;
  const float* texels;
};

// Largest magnitude of a shell value, DifMap texel or environment FIV value (see "Numerics").
inline constexpr float kFivValueLimit = 0x1p64f;

// Throw std::invalid_argument naming the problem unless: pointers non-null; n_rho >= 1,
// n_theta >= 2, n_phi >= 1 and n_rho·n_theta·n_phi <= 2^26; centre finite; radius finite and > 0;
// radii finite, > 0 and strictly increasing; every shell value finite, |value| <= kFivValueLimit;
// radial_scheme one of the two; for kFivRadialSurface surface_radius non-null, finite and in
// [0, 2^64], radii geometric (each τ_k within 1e-4 relative of τ_0 (τ_last/τ_0)^(k/(n_rho − 1)))
// and valid may be null; cones (when present) finite with Ω in [0, 4π·(1 + 2^-10)] and |m_x|,
// |m_y|, |m_z| <= Ω·(1 + 2^-10) + 2^-20 (a moment is never longer than its solid angle; the margins
// are the bake's rounding). O(size of the shells).
void validate_occluder(const FivOccluder& occ);
// size in [1, 2^13], texels non-null, finite and |texel| <= kFivValueLimit. O(6 size²).
void validate_difmap(const DifMap& map);
// /fiv/environment: 9 finite values of magnitude <= kFivValueLimit. O(1).
void validate_environment_fiv(const float env_fiv[9]);

// Bilinear lookup of E_tot in the face the direction n selects (any length; zero → +Y).
void lookup_difmap(const DifMap& map, const float n[3], float out[3]);

// Occluded FIV F(s) [RGB][xyz] at offset s = p − centre (world units), see the header comment.
void lookup_fiv(const FivOccluder& occ, const float s[3], float out[9]);

// The cone table at offset s = p − centre: (m_x, m_y, m_z, Ω) by the shells' stencil (header
// "Tight proxies"); occ.cones must be non-null.
void lookup_cone(const FivOccluder& occ, const float s[3], float out[4]);

// K(x, α) = ∫_cap max(0, ν·ω) dω over the cap of half-angle α (cos α = cos_alpha) whose axis a has
// ν·a = x (header "Tight proxies"; arguments clamped to [−1, 1]). In double.
double cap_clamped_cosine(double x, double cos_alpha);

// Partial-occluder factor (§4.3.1 "Partial Occluders"): h = n·(centre − p); case C (h <= −R): 0;
// case A (h >= R): 1; case B: (h + R) / (2R). n of any length (its direction, see "Numerics").
float partial_factor(const FivOccluder& occ, const float p[3], const float n[3]);

// Occluded irradiance of one occluder at (p, n): per channel max(0, factor · n·F_c(p − centre)),
// factor = partial_factor, or 1 when `partial` is false (case C stays 0).
void occluded_irradiance(const FivOccluder& occ, const float p[3], const float n[3], bool partial, float out[3]);

struct FivShadeOptions {
  bool partial_occluders = true;
  bool overlap_correction = true;
  FivProxy proxy = FivProxy::cone;
};

// Irradiance at a receiver point (eq. 11, 13, 14), see the header comment. count >= 0.
void shade_fiv(const DifMap& map, const FivOccluder* occluders, int count, const float p[3], const float n[3],
               const FivShadeOptions& options, float out[3]);

// Self-shadows (eq. 12): E_c = max(0, n·F^env_c − n·F_c(p − centre)), env_fiv = /fiv/environment.
void shade_fiv_self(const float env_fiv[9], const FivOccluder& occ, const float p[3], const float n[3], float out[3]);

// A receiver that is itself one of several occluders (paper 004 §4.3.2 with eq. 11): a point on
// occluders[self] (several copies of a baked occluder, or scene objects with FIV shells) gets its
// own self-shadows (shade_fiv_self) minus what each OTHER occluder j hides,
// occluded_irradiance(occluders[j], p, n, partial), clamped to >= 0 after each subtraction. No
// overlap correction (eq. 13–14 pairs occluders against a DifMap; the self term is not one of its
// I_i). count >= 1, 0 <= self < count.
void shade_fiv_member(const float env_fiv[9], const FivOccluder* occluders, int count, int self, const float p[3],
                      const float n[3], bool partial, float out[3]);
// shade_fiv_member with the self-shadowed irradiance given instead of eq. 12's n·(F^env − F(p)):
// max(0, self_irradiance) minus what each other occluder hides, clamped after each subtraction.
// For the occluder's per-vertex band-1 radiance (exact at its vertices, E = (4π/3) Σ_m y_1m(n) R_m
// interpolated across its triangles): eq. 12 needs the FIV just outside the surface at p, which
// the shells hold only where p's surface is the outermost along its ray from the centre
// (surface-following shells) or between valid samples (paper 004's spheres) — not inside an
// ear or a concavity. shade_fiv_member(env, o, count, self, p, n, partial) is this with
// self_irradiance = shade_fiv_self(env, o[self], p, n).
void shade_fiv_member_given_self(const float self_irradiance[3], const FivOccluder* occluders, int count, int self,
                                 const float p[3], const float n[3], bool partial, float out[3]);

// --- pieces and references (tests, mirrors) ----------------------------------------------------

// half_to_float of n halves, 8 at a time with SSE2 where present: the decode lookups use on a CPU
// without F16C (with it they use vcvtph2ps; both give half_to_float's values).
void halves_to_floats(const uint16_t* halves, float* out, size_t n);

// Area of the intersection (lens) of two planar discs of radii r1, r2 >= 0 whose centres are d >= 0
// apart: 0 when d >= r1 + r2, π min(r1, r2)² when d <= |r1 − r2|, else the closed form
// r1² acos((d² + r1² − r2²)/(2 d r1)) + r2² acos((d² + r2² − r1²)/(2 d r2)) − ½ √((−d+r1+r2)(d+r1−r2)(d−r1+r2)(d+r1+r2)).
double lens_area(double r1, double r2, double d);

// O_ij of eq. 14 for discs of angular radii alpha_i, alpha_j at angular distance gamma (0 when
// both radii are 0).
double overlap_fraction(double alpha_i, double alpha_j, double gamma);

// shade_fiv written straight from the formulas (double, every pair, γ = acos(clamp(a_i·a_j)), the
// cones' α = acos(1 − Ω/2π) and K in double): the slow reference the fast path is tested against.
void shade_fiv_reference(const DifMap& map, const FivOccluder* occluders, int count, const float p[3],
                         const float n[3], const FivShadeOptions& options, float out[3]);

} // namespace prt::shade
