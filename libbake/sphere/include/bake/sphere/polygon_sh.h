// bake/sphere/polygon_sh.h — the spherical-harmonic projection of a spherical polygon in closed form:
// c_i = ∫_P y_i(ω) dω in the basis of prtshade/sh.h (real, orthonormal, index l(l+1)+m, order =
// number of bands), for a light's visible polygon at the receiver's order (paper 003 §2 "PRT with
// polygonal area lights": the SH of a polygonal light; issue 13; docs/ARCHITECTURE.md
// "Conventions"). Polygon conventions (vertex directions, orientation, chains) are those of
// bake/sphere/spherical_polygon.h; no quadrature anywhere.
//
// Method (zonal decomposition as in Belcour, Xie, Hery, Meyer, Jarosz & Nowrouzezahrai,
// "Integrating Clipped Spherical Harmonics Expansions", TOG 2018, and Wang & Ramamoorthi,
// "Analytic Spherical Harmonic Coefficients for Polygonal Area Lights", TOG 2018; the
// recurrences are derived here):
//  * Band 0 and band 1 come from the solid angle and Lambert's vector Φ (spherical_polygon.h):
//    c_00 = Ω/√(4π), (c_1,−1, c_10, c_11) = √(3/(4π)) (−Φ_y, Φ_z, −Φ_x).
//  * Band l ≥ 2: for a unit axis w, Q_l(w) = ∫_P P_l(w·ω) dω. Since Δ_S P_l(w·ω) = −l(l+1) P_l(w·ω)
//    on the sphere, the divergence theorem over P with outward conormal −u_i on edge i gives
//        Q_l(w) = 1/(l(l+1)) Σ_i (w·u_i) ∫_{edge i} P_l'(w·ω(s)) ds,
//    u_i the unit normal of edge i's plane (Lambert's formula is l = 1). On an edge from unit a to
//    b, ω(s) = a cos s + (u×a) sin s, g(s) = w·ω(s), and the arc moments E_j = ∫_0^θ g^j ds obey
//        E_0 = θ,  E_1 = w·(u × (a − b)),
//        j E_j = (j−1) r² E_{j−2} − [g^{j−1} g']_0^θ,   r² = (w·a)² + (w·(u×a))²,
//    with g(0) = w·a, g(θ) = w·b, g'(0) = w·(u×a), g'(θ) = w·(u×b) (from (g^{j−1}g')' =
//    (j−1) g^{j−2}(r² − g²) − g^j, since g'' = −g and g² + g'² = r²). P_l' is expanded in
//    monomials, so no trigonometry beyond θ = atan2(|a×b|, a·b).
//  * By the addition theorem Q_l(w) = 4π/(2l+1) Σ_m y_lm(w) c_lm; with D fixed axes w_k (a
//    Fibonacci set of D = 4·order directions) each band is the least-squares solution
//    c_l = (2l+1)/(4π) Y_l⁺ Q_l, Y_l = [y_lm(w_k)] (D × (2l+1), full column rank; the
//    pseudo-inverse is computed once per order and its conditioning checked).
// Accuracy: measured against the hemisphere's exact coefficients, ~1e-15 absolute up to order 9
// and ~5e-15 at order 12 (the monomial expansion of P_l' has coefficients up to ~10^3 there).
// Bands ≥ 2 of tiny polygons are accurate absolutely (~1e-16), not relatively.
// Cost: O(N · D · order) per polygon of N edges, plus O(order³) to apply the pseudo-inverses.
#pragma once

#include <bake/sphere/spherical_polygon.h>

#include <Eigen/Core>

#include <span>
#include <vector>

namespace prt::bake {

namespace detail {
struct ShEdge;
}

class PolygonSH {
public:
  static constexpr int kMaxOrder = 12;

  // 1 <= order <= kMaxOrder (PRT_CHECK).
  explicit PolygonSH(int order);

  int order() const noexcept { return order_; }

  // out[i] = ∫_P y_i(ω) dω for i < order² (out.size() >= order², PRT_CHECK). P is used as given:
  // clip it to the horizon first (bake/sphere/spherical_polygon.h) for the visible part above a receiver.
  void project(std::span<const Eigen::Vector3d> vertices, std::span<double> out) const;
  // The same for a region given by its boundary arcs (bake/sphere/spherical_polygon.h Arc; e.g. the
  // visible part of a light, bake/visibility/visible_region.h). Bands 0 and 1 by the per-arc formulas.
  void project(std::span<const Arc> boundary, std::span<double> out) const;

private:
  int order_;
  std::vector<Eigen::Vector3d> axes_;    // D unit directions w_k
  std::vector<double> solve_;            // bands 2 … order−1: (2l+1) × D row-major blocks
  std::vector<double> derivative_;       // bands 2 … order−1: monomial coefficients of P_l', l each

  // Bands 2 … order−1 from the edges (out already holds bands 0 and 1).
  void high_bands(std::span<const detail::ShEdge> edges, std::span<double> out) const;
};

} // namespace prt::bake
