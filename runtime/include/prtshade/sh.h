// prtshade/sh.h — THE definition of the spherical-harmonics basis in prtbake: evaluation,
// index layout and rotation. libbake and every runtime consumer use this file, so baker and
// runtime cannot disagree on a sign or a normalisation (docs/ARCHITECTURE.md §2, §3).
//
// Basis (P.-P. Sloan, "Stupid Spherical Harmonics (SH) Tricks", GDC 2008, §"Definitions";
// identical to DirectXMath XMSHEvalDirection and to google/spherical-harmonics EvalSH):
//   real, orthonormal over the unit sphere (∫ y_i y_j dω = δ_ij, dω in steradians),
//   Condon–Shortley phase (−1)^m INCLUDED in the associated Legendre function P_l^m, and
//     y_{l,0}  = K_l^0 P_l^0(cos θ)
//     y_{l,m}  = √2 K_l^m  cos(m φ) P_l^m(cos θ)      m > 0
//     y_{l,m}  = √2 K_l^|m| sin(|m| φ) P_l^|m|(cos θ)  m < 0
//   with K_l^m = sqrt((2l+1)/(4π) · (l−m)!/(l+m)!), direction (x, y, z) =
//   (sin θ cos φ, sin θ sin φ, cos θ): θ is measured from +z, φ from +x towards +y. The basis
//   is defined on (x, y, z) directly; nothing here knows about "up" (the scene frame is the
//   caller's business, docs/ARCHITECTURE.md §3 "Environment maps").
//   Bands 0–2 written out (DirectXMath's 6-digit constants):
//     y00 = 0.282095
//     y1-1 = −0.488603 y    y10 = 0.488603 z    y11 = −0.488603 x
//     y2-2 = 1.092548 x y   y2-1 = −1.092548 y z   y20 = 0.315392 (3z² − 1)
//     y21 = −1.092548 x z   y22 = 0.546274 (x² − y²)
//
// Index layout: coefficient i = index(l, m) = l(l+1) + m, bands l = 0 … L−1, m = −l … l.
//
// "Order" L means the NUMBER OF BANDS (as DirectXSH and Filament; google/spherical-harmonics
// calls the highest degree L−1 its "order"). An order-L vector holds L² coefficients.
// Supported orders: 1 … kMaxOrder (0 is accepted and means "no coefficients").
//
// Rotation (J. Ivanic and K. Ruedenberg, "Rotation Matrices for Real Spherical Harmonics.
// Direct Determination by Recursion", J. Phys. Chem. 100 (1996) 6342–6347, Tables 1–2, with
// the corrections of J. Phys. Chem. A 102 (1998) 9099–9100):
//   R is a 3×3 proper rotation (orthonormal, det +1), row-major R[row][col], acting on column
//   vectors: d ↦ R d. Rotating a function f by R gives g(ω) = f(Rᵀ ω) (the lobe of f that
//   pointed along d points along R d in g). Rotation::apply maps the coefficients of f to
//   those of g. Hence, for every unit d:  Σ_i c'_i y_i(R d) = Σ_i c_i y_i(d),
//   and rotations compose as representations: apply(B) after apply(A) == apply(B·A).
//   Each band l is rotated independently by a (2l+1)×(2l+1) orthogonal matrix D^l(R),
//   c'_{l,m} = Σ_{m'} D^l_{m m'} c_{l,m'}.
//   Band 1 (m = −1, 0, 1) is proportional to (−y, z, −x) (see band1_from_direction); so
//   D^1_{m m'} = s_m s_m' R[a_m][a_m'] with axes (a_−1, a_0, a_1) = (y, z, x) and signs
//   (s_−1, s_0, s_1) = (−1, +1, −1). The recurrence builds band l from band l−1 and D^1.
//
// Numerics: eval uses the normalised associated-Legendre recurrence in z with the sin^m θ
// factor carried by cos/sin(mφ)·sin^m θ = Re/Im (x + i y)^m, computed by the complex
// (Chebyshev) recurrence — no factorials, no atan2, no division by sin θ, so it is exact at
// the poles and stays within a few ulps·l of the true values up to kMaxOrder (tests check
// orthonormality by Gauss–Legendre quadrature at order 30 and 64).
// Errors: a broken precondition that is cheap to test (order outside [0, kMaxOrder], a span
// too short, l or m out of range) throws std::invalid_argument (a std::logic_error: it is a
// caller bug, not an input error). Unit length of directions is checked only in debug builds.
#pragma once

#include <span>
#include <vector>

namespace prt::sh {

// Largest supported order (number of bands); bands 0 … 63.
constexpr int kMaxOrder = 64;

// Flat index of coefficient (l, m), 0 <= l, −l <= m <= l.
constexpr int index(int l, int m) noexcept { return l * (l + 1) + m; }

// Number of coefficients of an order-L (L bands) vector: L².
constexpr int num_coeffs(int order) noexcept { return order * order; }

// Unnormalised band-1 "direction" of the basis: y_{1,m}(d) = sqrt(3/(4π)) · band1[m+1], i.e.
// (y1-1, y10, y11) ∝ (−y, z, −x). Inverse: d = (−b[2], −b[0], b[1]).
struct Band1 {
  double v[3];  // m = −1, 0, 1
};
constexpr Band1 band1_from_direction(double x, double y, double z) noexcept {
  return Band1{{-y, z, -x}};
}
// sqrt(3 / (4π)): y_{1,m} = kBand1Scale · band1_from_direction(d).v[m+1].
constexpr double kBand1Scale = 0.48860251190291992159;

// Evaluates all basis functions of bands 0 … order−1 at the unit direction (x, y, z) into
// out[0 … order²−1] (layout index(l, m)); out[order² …] is left untouched.
// Preconditions: 0 <= order <= kMaxOrder; out.size() >= order²; x² + y² + z² = 1 (checked
// only in debug builds, to 1e-4: for a non-unit vector the result has no meaning).
void eval(int order, double x, double y, double z, std::span<double> out);
// Same basis; computes in double internally and rounds each value once to float.
void eval(int order, float x, float y, float z, std::span<float> out);

// Slow reference for tests: y_{l,m}(x, y, z) from the explicit formulas above — P_l^m by the
// Rodrigues-derived finite sum with factorials (in long double), φ = atan2(y, x). Accurate to
// about 1e-14 for l <= 12 and usable to l ≈ 20; do not use at high l (cancellation and
// factorial overflow). Preconditions: 0 <= l <= 30, |m| <= l, unit direction.
double eval_slow(int l, int m, double x, double y, double z);

// Rotation of SH coefficient vectors of any order <= kMaxOrder by a 3×3 rotation matrix (see
// the header comment for the convention). Construction costs O(order³) time (measured on
// the 2-core dev VM: ~3 µs at order 3, ~0.15 ms at order 10, ~40 ms at order 64) and
// Σ(2l+1)² = order(4·order² − 1)/3 doubles (≈ 2.8 MB at order 64); apply costs Σ(2l+1)²
// multiply-adds. The recurrence runs in long double and rounds each entry once: in plain
// double its rounding error grows ~1.2× per band (|D Dᵀ − I| ≈ 2e-11 at l = 63); with the
// x86-64 80-bit long double every band matrix is orthogonal to ~1e-14 up to kMaxOrder (where
// long double is double, e.g. MSVC, expect the double figure).
// Immutable after construction, so one Rotation may be shared between threads.
class Rotation {
public:
  // R: row-major proper rotation, R[row][col], d ↦ R d. Precondition: R Rᵀ = I and
  // det R = +1 to about 1e-6 (checked always; a reflection has no SH rotation matrices here).
  // 0 <= order <= kMaxOrder.
  Rotation(const double R[3][3], int order);

  // Number of bands this rotation was built for.
  int order() const noexcept;

  // out = D(R) in, band by band. in.size() >= order², out.size() >= order², and in and out
  // must not overlap. Only the first order² entries are read and written.
  void apply(std::span<const double> in, std::span<double> out) const;
  // Same, accumulating in double and rounding each output once to float.
  void apply(std::span<const float> in, std::span<float> out) const;

  // Entry D^l_{m_row, m_col} of band l's matrix; 0 <= l < order(), m_row, m_col in [−l, l].
  double band_matrix(int l, int m_row, int m_col) const;

private:
  // Offset of band l's (2l+1)×(2l+1) row-major block in matrices_.
  static int band_offset(int l) noexcept;

  int order_ = 0;
  std::vector<double> matrices_;
};

} // namespace prt::sh
