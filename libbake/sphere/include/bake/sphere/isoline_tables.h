// bake/sphere/isoline_tables.h — summed-area tables of an integrand along the u-isolines of the
// octahedral grid (paper 001 §3.2 and §4: "we compute a summed area table (SAT) over
// u-isolines, reducing definite integral computation to two lookups and a subtraction").
//
// For each isoline i and each cell boundary b along its loop (bake/sphere/octahedral.h), the table holds
//   C_i(b) = Σ_{cells j < b} h · mean_{cell j × strip i}( f(ω(u, v)) · J(u, v) )
// for every component of f, in double precision (HDR suns of 10^4–10^5 × the mean make float
// tables cancel). The mean is a box filter over the cell in v and over the isoline's strip
// [u_i − h/2, u_i + h/2] in u (s × s sub-samples), so a feature narrower than the isoline spacing
// (a sun) keeps its energy instead of being missed or aliased. Between boundaries C is linear
// (f·J constant per cell), so ∫_{t_a}^{t_b} f J dv = C_i(t_b) − C_i(t_a) for any t_a, t_b.
// Then ∫_{S²} V f dω ≈ h Σ_i Σ_{runs with W = 0} [C_i(t_b) − C_i(t_a)] (midpoint rule in u).
#pragma once

#include <bake/sphere/octahedral.h>

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace prt::bake {

class IsolineTables {
public:
  // f(ω, out): the integrand's components at unit direction ω (in the octahedral frame).
  using Integrand = std::function<void(const Eigen::Vector3d& omega, std::span<double> out)>;

  IsolineTables(const oct::Grid& grid, int components, int subsamples, const Integrand& f);

  int components() const noexcept { return components_; }
  const oct::Grid& grid() const noexcept { return grid_; }
  size_t bytes() const noexcept { return table_.size() * sizeof(double); }

  // acc[c] += weight · C_i(t)[c], t ∈ [0, 4ℓ_i] the loop parameter.
  void accumulate(int i, double t, double weight, double* acc) const noexcept;
  // C_i at the end of the loop (the integral of f J over the whole loop).
  const double* loop_total(int i) const noexcept {
    return &table_[(offset_[size_t(i)] + size_t(2 * grid_.cells_per_sheet(i))) * size_t(components_)];
  }

private:
  oct::Grid grid_;
  int components_;
  std::vector<size_t> offset_;  // first boundary row of isoline i
  std::vector<double> table_;   // [row][component]
};

} // namespace prt::bake
