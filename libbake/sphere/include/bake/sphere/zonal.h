// bake/sphere/zonal.h — closed forms for zonal kernels (functions of n·ω only) in the SH basis of
// prtshade/sh.h, used for unoccluded shade points, glossy SH-order selection and tests.
//
// Funk–Hecke theorem: for a zonal kernel k(n·ω),  ∫ k(n·ω) y_lm(ω) dω = λ_l y_lm(n),
// λ_l = 2π ∫_{-1}^{1} k(t) P_l(t) dt  (P_l Legendre polynomials).
// For the clamped power kernel k(t) = max(t, 0)^s (s ≥ 0 real: s = 0 is the hemisphere indicator
// H, s = 1 the clamped cosine, s = Phong exponent for a Phong lobe about n):
//   λ_l = 2π I_l(s),  I_l(s) = ∫_0^1 t^s P_l(t) dt,
// with I_0 = 1/(s+1), I_1 = 1/(s+2) and the two-term ratio recurrence
//   I_{l+2} = I_l · (s − l) / (s + l + 3)
// (from the Gamma-function closed form, Gradshteyn & Ryzhik 7.126.2: I_l(s) =
// √π 2^{−s−1} Γ(1+s) / (Γ(1 + s/2 − l/2) Γ(3/2 + s/2 + l/2)); the ratio of consecutive-parity
// terms is a rational function, so the recurrence is exact and has no cancellation).
// Checks: s = 1 gives I = 1/2, 1/3, 1/8, 0, −1/48 … (λ = π, 2π/3, π/4, 0, −π/24: Ramamoorthi &
// Hanrahan 2001, eq. 8); s = 0 gives ∫_0^1 P_l = 1, 1/2, 0, −1/8 ….
//
// Products of an unoccluded shade point (V = H(ω, n), docs/ARCHITECTURE.md §3 integrands):
//   AO = 1,  T_lm = (1/π) λ_l(1) y_lm(n) = 2 I_l(1) y_lm(n),  U_lm = λ_l(0) y_lm(n) = 2π I_l(0) y_lm(n).
//
// Glossy SH order (paper 001 §4 "glossy" after Ramamoorthi & Hanrahan, "Frequency space environment
// map rendering", SIGGRAPH 2002, §3): the Phong lobe k(t) = max(t,0)^s about its axis has the
// zonal SH coefficients f_l = 2π √((2l+1)/(4π)) I_l(s) and L² energy ||k||² = Σ_l f_l² = 2π/(2s+1),
// so the fraction of its energy in bands ≥ L is   1 − (2s+1)/2 · Σ_{l<L} (2l+1) I_l(s)².
// (Its normalisation (s+1)/(2π) cancels in the fraction.)
// The order chosen for a tolerance ε is the smallest L with that fraction ≤ ε.
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

namespace prt::bake {

// I_l(s) for l = 0 … order−1. s ≥ 0.
std::vector<double> clamped_power_moments(double s, int order);

// Fraction of the L² energy of max(n·ω, 0)^s in bands l ≥ order (0 < result ≤ 1 for order 0).
double clamped_power_energy_beyond(double s, int order);

// Smallest order L in [1, max_order] whose energy beyond is ≤ tolerance; 0 if none is.
int clamped_power_order(double s, double tolerance, int max_order);

// SH projection (order L, L² coefficients) of max(n·ω, 0)^s about the unit normal n:
// out[l(l+1)+m] = 2π I_l(s) y_lm(n).
void clamped_power_sh(double s, int order, const Eigen::Vector3d& n, std::span<double> out);

} // namespace prt::bake
