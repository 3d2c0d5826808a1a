// prtshade/glossy.h — run-time glossy shading from the baked data: a Phong lobe about the
// reflection direction, shadowed, under a rotating or changing environment (route A, from the
// visibility transfer U) or under the fixed environment a bake projected (route B, from the
// shadowed radiance S). The contract shared with the C API (prtshade/prtshade.h) is this header;
// conventions are docs/ARCHITECTURE.md §3 and formats/SCHEMA.md; SH as <prtshade/sh.h> (real,
// orthonormal, Condon–Shortley phase, index l(l+1)+m, "order" L = number of bands).
//
// What is computed, for a vertex with unit normal n, view direction v (towards the eye) and
// reflection direction r = 2(n·v)n − v:
//   L_out(v) = ∫ L(ω) V(ω) H(n·ω) k_s(r·ω) dω,   k_s(t) = (s+1)/(2π) max(t, 0)^s,
// the normalised Phong lobe (∫ k_s dω = 1 over the sphere: a white unshadowed sky of radiance 1
// returns 1 where the lobe stays above the horizon); the caller multiplies by its specular colour.
// (No cosine factor: the classic PRT glossy lobe — Sloan, Kautz, Snyder 2002 §6; Ramamoorthi &
// Hanrahan 2002 §3 — and paper 001 §4 "glossy": the order is chosen from the lobe's SH energy,
// bake/sphere/zonal.h.)
//
// Both routes end the same way. With S_i = ∫ L V H y_i dω (per RGB channel) the shadowed incident
// radiance's SH, the Funk–Hecke theorem turns the lobe into a per-band scale:
//   L_out ≈ Σ_l λ_l Σ_m S_lm y_lm(r),  λ_l = 2π · (s+1)/(2π) · I_l(s) = (s+1) I_l(s),
//   I_l(s) = ∫_0^1 t^s P_l(t) dt   (I_0 = 1/(s+1), I_1 = 1/(s+2), I_{l+2} = I_l (s−l)/(s+l+3):
//   Gradshteyn & Ryzhik 7.126.2; the ratio of two Gamma closed forms, exact, no cancellation).
// The truncation to L bands is the only approximation of the last step: exact for a lobe
// band-limited to L, and the energy beyond is bake/sphere/zonal.h's clamped_power_energy_beyond.
//   route A (relightable): S = P_L(L · U), the SH triple product of the lighting L and the baked
//     visibility transfer U_i = ∫ V H y_i dω (/transfer/visibility), both at order L:
//       S_k = Σ_ij Γ_ijk L_i U_j,   Γ_ijk = ∫ y_i y_j y_k dω   (the real Gaunt coefficients),
//     exact for the product of the two order-L functions projected back to order L (what Sloan,
//     Kautz, Snyder 2002 §6 call the "transfer matrix" times L, applied without forming it).
//     The lighting may change or rotate every frame (prt::sh::Rotation on L).
//   route B (paper 001 §4, "material editing"): the bake stores S itself at order L for a fixed
//     environment (exact all-frequency shadows projected once); the lobe (s, and r with the view)
//     changes at run time for the cost of the last step alone.
//
// Γ is computed once per order by quadrature that is exact for its integrand (a polynomial of
// degree ≤ 3(L−1) on the sphere): Gauss–Legendre in cos θ with ⌈(3L−2)/2⌉ nodes times a uniform
// rule in φ with 3L−2 nodes; entries below 1e-12 in magnitude are the exact zeros of the selection
// rules (|l_i − l_j| ≤ l_k ≤ l_i + l_j, l_i + l_j + l_k even, and the real-basis m rules) and are
// dropped. Γ is symmetric in its indices; the table keeps each non-zero once per k and unordered
// pair i ≤ j, so a product is one pass over it in (k, i, j) order — out_k += Γ (a_i b_j + a_j b_i)
// for i < j, Γ a_i b_i for i = j — accumulated in double.
//
// Errors: constructors and batch functions check their arguments and throw std::invalid_argument;
// the per-vertex functions check nothing. Everything is thread-safe once constructed.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace prt::shade {

inline constexpr int kMaxGlossyOrder = 16;  // bands of the triple product (256 coefficients)
// Bands of route B (no triple product: any order of the SH basis, prtshade/sh.h kMaxOrder). A
// Phong exponent of 128 wants ~25 bands at 1% of the lobe's energy (bake/sphere/zonal.h).
inline constexpr int kMaxShadowedOrder = 64;

// I_l(s) = ∫_0^1 t^s P_l(t) dt for l = 0 … order−1 (out[order]); s ≥ 0 finite. Throws
// std::invalid_argument otherwise.
void clamped_power_moments(double s, int order, double* out);

// The Phong lobe's per-band scales λ_l = (s+1) I_l(s), l = 0 … order−1 (out[order]).
void phong_band_scales(double s, int order, double* out);

// GGX (Trowbridge–Reitz; Walter et al. 2007), and how it maps onto the zonal lobe above. With the
// microfacet distribution D(h) = α² / (π ((n·h)²(α² − 1) + 1)²) (∫ D (n·h) dω_h = 1), the
// distribution of the reflected direction ω = 2(v·h)h − v is p_v(ω) = D(h)(n·h) / (4(v·h)) — the
// lobe without G, F and the cosine, normalised like k_s above. At normal incidence (v = n, so
// r = n) p_n is ZONAL about r: θ_ω = 2θ_h, and its Funk–Hecke band scales are
//   λ_l(α) = ∫ p_n(ω) P_l(cos θ_ω) dω = ∫_0^1 P_l(2μ(ξ) − 1) dξ,  μ(ξ) = (1 − ξ)/(1 − (1 − α²)ξ),
// the expectation of P_l(cos θ_ω) under GGX's own sampling map (cos²θ_h = μ(ξ), ξ uniform), so
// λ_0 = 1 and |λ_l| ≤ 1. Route A and route B then shade GGX with these scales in place of Phong's:
// exact at normal incidence for a lighting of at most `order` bands. Away from normal incidence the
// true lobe stretches along the plane of v and n (it is not zonal), which a per-band scale cannot
// carry: the error of the zonal model against the true lobe, as a function of the view angle, is
// measured in tests/runtime/test_glossy.cpp and bench/RESULTS.md "Glossy shading".
// The integral is a composite 24-point Gauss–Legendre rule in u = 1 − ξ on a mesh graded
// geometrically towards u = 0 (μ has a pole at u = −α²/(1 − α²), just beyond the interval): every
// piece lies at least its own length from the pole, so each converges geometrically; the tests
// check λ_0 = 1 and λ_1's closed form to 1e-14 for α in [1e-4, 1].
// The Phong exponent with the same mean cosine λ_1 (the usual single-number mapping) is
// s = (2λ_1 − 1)/(1 − λ_1) (from λ_1 = (s + 1)/(s + 2)); it matches band 1 only — GGX's long tail
// keeps its band 2 and up above Phong's (the tests: band 2 for every α, bands 2–15 for α ≤ 0.1),
// so a Phong stand-in loses GGX's glow around highlights. Where GGX is wider than the widest Phong
// lobe (λ_1 < ½, α > 0.4421), ggx_equivalent_phong_exponent returns 0, the clamped cosine.
// α in [1e-4, 1]; throws std::invalid_argument otherwise.
void ggx_band_scales(double alpha, int order, double* out);
double ggx_equivalent_phong_exponent(double alpha);

// The real Gaunt coefficients of one order, as a sparse list.
class TripleProduct {
public:
  struct Entry {
    uint16_t i, j, k;
    double gamma;  // ∫ y_i y_j y_k dω
  };
  // order in [1, kMaxGlossyOrder]; throws std::invalid_argument otherwise.
  explicit TripleProduct(int order);
  int order() const { return order_; }
  const std::vector<Entry>& entries() const { return entries_; }  // i <= j, sorted by (k, i, j)
  // out[k] = Σ_ij Γ_ijk a_i b_j for order² coefficients each (out may not alias a or b).
  void multiply(const float* a, const float* b, float* out) const;

private:
  int order_;
  std::vector<Entry> entries_;
};

// Route B: L_out = Σ_l λ_l Σ_m S_{c,lm} y_lm(r) for c = 0..2. `shadowed` is [3][order²]
// channel-major (a vertex's /radiance/shadowed row), order in [1, kMaxShadowedOrder], `scales`
// the order band scales of phong_band_scales, r a unit direction.
void shade_glossy_radiance(const float* shadowed, int order, const double* scales, const float r[3], float out[3]);

// Route A, the slow reference: S_c = P_L(L_c · U) by one pass over the Gaunt table per channel
// (double accumulation), then shade_glossy_radiance. `light` is [3][order²] channel-major (as
// project_latlong writes it), `visibility` the vertex's [order²] /transfer/visibility row, both at
// tp.order().
void shade_glossy(const TripleProduct& tp, const float* light, const float* visibility, const double* scales,
                  const float r[3], float out[3]);

// Route A, fast: S_c = P_L(L_c · U) is linear in U, S_c = M_c U with the lighting's product
// matrices M_c[j][k] = Σ_i Γ_ijk L_{c,i} (the "transfer matrix" of Sloan, Kautz, Snyder 2002 §6,
// here of the lighting), built once per lighting (one Gaunt pass per channel) and stored in float.
// Per vertex S_{c,k} = Σ_j M_c[j][k] U_j, accumulated in float over j in index order for every k
// (so the loop runs across k, vectorisable, and the result does not depend on the vector width):
// 3 n⁴ multiply-adds, against ~6 × the Gaunt entries for the reference. Error against the
// reference: |ΔS_k| ≤ (n² + 2) ε_f Σ_j |M_c[j][k] U_j| (ε_f = 2^−24; the rounding of M and of each
// partial sum), checked by the tests.
class GlossyLight {
public:
  GlossyLight(const TripleProduct& tp, const float* light);
  int order() const { return order_; }
  // S [3][order²] for one vertex's visibility row [order²].
  void shadowed_radiance(const float* visibility, float* S) const;
  const std::vector<float>& matrices() const { return m_; }  // [3][j = order²][k = order²]

private:
  int order_;
  std::vector<float> m_;
};

// The reflection direction r = 2(n·v)n − v of the unit view direction v (towards the eye) about
// the unit normal n.
void reflect(const float n[3], const float v[3], float r[3]);

// Route A over `count` vertices (GlossyLight::shadowed_radiance, then shade_glossy_radiance):
// visibility [count][order²], normals and positions [count][3], eye [3]; out [count][3]. Each
// vertex's v = normalize(eye − p) (r = n when the eye is on the vertex). Throws
// std::invalid_argument on null pointers (count > 0) or a negative or non-finite exponent.
void shade_glossy_vertices(const GlossyLight& light, const float* visibility, const float* normals,
                           const float* positions, std::size_t count, const float eye[3], double phong_exponent,
                           float* out);

// Route B over `count` vertices (shade_glossy_radiance about each vertex's reflected view
// direction, as shade_glossy_vertices): shadowed [count][3][order²] (/radiance/shadowed), order in
// [1, kMaxShadowedOrder]; the rest as shade_glossy_vertices. Throws std::invalid_argument on null
// pointers (count > 0), an order out of range or a negative or non-finite exponent.
void shade_glossy_radiance_vertices(const float* shadowed, int order, const float* normals, const float* positions,
                                    std::size_t count, const float eye[3], double phong_exponent, float* out);

} // namespace prt::shade
