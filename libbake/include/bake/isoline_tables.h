// bake/isoline_tables.h — summed-area tables of an integrand along the u-isolines of the
// octahedral grid (paper 001 §3.2 and §4: "we compute a summed area table (SAT) over
// u-isolines, reducing definite integral computation to two lookups and a subtraction").
//
// For each isoline i and each cell boundary b along its loop (bake/octahedral.h), the table holds
//   C_i(b) = Σ_{cells j < b} h · mean_{cell j × strip i}( f(ω(u, v)) · J(u, v) )
// for every component of f, in double precision (HDR suns of 10^4–10^5 × the mean make float
// tables cancel). The mean is a box filter over the cell in v and over the isoline's strip
// [u_i − h/2, u_i + h/2] in u (s × s sub-samples), so a feature narrower than the isoline spacing
// (a sun) keeps its energy instead of being missed or aliased. Between boundaries C is linear
// (f·J constant per cell), so ∫_{t_a}^{t_b} f J dv = C_i(t_b) − C_i(t_a) for any t_a, t_b.
// Then ∫_{S²} V f dω ≈ h Σ_i Σ_{runs with W = 0} [C_i(t_b) − C_i(t_a)] (midpoint rule in u).
#pragma once

#include <bake/octahedral.h>

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

namespace prt::bake {

// The same tables for an integrand with small support (the "hot" texels of an HDR environment:
// suns, lamps), on a finer isoline grid, stored only over the cells the support touches, with
// the same s × s box filter. (Point-sampling u instead was tried: on a 2×2-texel sun cut by the
// horizon it erred −1.7% against +0.9% for the box filter at the same grid.) The
// support is given by sample directions inside it; each isoline keeps one cell range [j_lo, j_hi]
// (plus one cell of margin for the sub-sample box filter). Outside its range C_i is 0 before and
// the range's total after, so accumulate() keeps the dense tables' meaning for any t.
class SparseIsolineTables {
public:
  SparseIsolineTables(const oct::Grid& grid, int components, int subsamples, const IsolineTables::Integrand& f,
                      std::span<const Eigen::Vector3d> support_samples);

  const oct::Grid& grid() const noexcept { return grid_; }
  int components() const noexcept { return components_; }
  int first_isoline() const noexcept { return i_lo_; }  // isolines with a range: [first, last)
  int last_isoline() const noexcept { return i_hi_; }
  bool has(int i) const noexcept { return i >= i_lo_ && i < i_hi_ && range_[size_t(i - i_lo_)].first >= 0; }
  size_t bytes() const noexcept { return table_.size() * sizeof(double); }
  void accumulate(int i, double t, double weight, double* acc) const noexcept;
  const double* loop_total(int i) const noexcept;

private:
  oct::Grid grid_;
  int components_;
  int i_lo_ = 0, i_hi_ = 0;
  std::vector<std::pair<int, int>> range_;  // per isoline in [i_lo, i_hi): cells [first, second], first < 0: none
  std::vector<size_t> offset_;             // first row of each isoline's range
  std::vector<double> table_;
};

} // namespace prt::bake
