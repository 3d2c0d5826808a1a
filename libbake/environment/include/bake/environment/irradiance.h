// bake/environment/irradiance.h — the unshadowed irradiance of an environment map for any normal, defined
// once: the DifMap of FIV files (bake/bake/fiv.h, /fiv/irradiance_cube) is this function sampled at the
// cube texel directions, and the reference renderer (view/reference.h) uses it for the part of
// the light nothing occludes. Paper 004 (Michael & Chrysanthou 2010) eq. 5:
//   E_tot(n) = ∫ L(ω) H(ω, n) (n · ω) dω        (H = 1 on the hemisphere around n, else 0)
// for a piecewise-constant environment (bake/environment/envmap.h), evaluated texel by texel:
//   * a texel wholly above the horizon of n adds L_t n · M_t with its moment M_t = ∫_texel ω dω,
//     computed once from a 4 × 4 grid of equal-solid-angle sub-cells (texel_moments below: error
//     O(h²) in the sub-cell size h);
//   * a texel wholly below adds nothing;
//   * a texel the horizon cuts adds L_t Σ_k max(0, n · ω_k) Ω_t / 16 over the same 4 × 4
//     sub-cell centres ω_k (O((h/4)²) per cut texel, instead of the O(h) of max(0, n · M_t)).
// "Wholly above/below" is decided with a cone around the texel's centre direction whose
// half-angle is 1.5 × the largest angle to its corners (+1e-6, at most π/2): the margin covers
// the texel's edges bulging between the probed corners. Black texels are skipped.
// Speed: texels are grouped on a coarse 64 × 32 lat-long grid of cells, each with the sum of its
// texels' L_c M_t and a cone holding every texel's own cone; a cell wholly above the horizon adds
// its sum, wholly below nothing, and only the cells the horizon crosses are visited texel by
// texel — the same numbers as the texel-by-texel sum (`reference`) up to summation order. A
// constant environment (no texels) gives π L exactly.
// Units: radiance × steradian (the environment's radiance times sr). Conventions:
// docs/ARCHITECTURE.md §3.
#pragma once

#include <bake/environment/envmap.h>

#include <Eigen/Core>
#include <vector>

namespace prt::bake {

// ∫_texel ω dω for every texel, from 4 × 4 uniform-in-solid-angle sub-samples
// (EnvMap::sample_texel_grid). Empty for a constant environment.
std::vector<Eigen::Vector3d> texel_moments(const EnvMap& env);

class UnshadowedIrradiance {
public:
  // `env` must outlive this object (cut texels are re-sampled from it). O(texels) to build.
  explicit UnshadowedIrradiance(const EnvMap& env);
  // E_tot(n) (RGB) for a unit normal n, through the cell hierarchy. Thread-safe.
  Rgb operator()(const Eigen::Vector3d& n) const;
  // The same sum texel by texel in the environment's texel order (no cells): the slow reference
  // of operator(), equal to it up to summation order.
  Rgb reference(const Eigen::Vector3d& n) const;

private:
  // One non-black texel: value, moment M_t, centre direction, cone half-angle r and sin r, solid angle.
  struct Texel {
    double L[3], m[3], c[3], r, sin_r, omega;
    int index;
  };
  struct Cell {
    size_t begin = 0, end = 0;  // range of order_
    double axis[3] = {0, 0, 0}, sin_R = 1, S[3][3] = {};  // S[c][xyz] = Σ L_c M_t
    bool bounded = false;  // R < π/2: can be wholly above or below a horizon
  };
  void add_texel(const Eigen::Vector3d& n, const Texel& x, double e[3]) const;

  const EnvMap& env_;
  bool constant_ = false;
  Rgb constant_value_;
  std::vector<Texel> texels_;   // environment texel order
  std::vector<size_t> order_;   // texels_ indices grouped by cell
  std::vector<Cell> cells_;
};

} // namespace prt::bake
