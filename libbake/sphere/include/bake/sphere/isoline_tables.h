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
//
// Point masses (PointMasses): components that are a piecewise-constant function — an environment
// map, constant per texel (formats/SCHEMA.md, Conventions, "environment") — are not box
// filtered by sub-samples, which would weigh each texel by the share of sub-samples landing on
// it (an error at every texel edge inside every cell, which does not telescope and does not shrink
// with N while the sub-sample spacing is set by the texel). Instead their integral is given as
// masses m_k at directions ω_k (a texel's value × its exact solid angle, spread over stratified
// sub-samples of the texel), and each mass adds m_k / h to the ONE cell whose strip and v-interval
// hold ω_k. Every mass is counted exactly once, so the tables' total over any union of whole cells
// is exact, and a region's integral errs only in the cells its boundary cuts, by how the masses
// there sit within their cell.
#pragma once

#include <bake/sphere/octahedral.h>

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <span>
#include <utility>
#include <vector>

namespace prt::bake {

class IsolineTables {
public:
  // f(ω, out): the integrand's components at unit direction ω (in the octahedral frame).
  using Integrand = std::function<void(const Eigen::Vector3d& omega, std::span<double> out)>;

  // Point masses for components [first, first + count): emit(b, directions, values) appends the
  // masses of block b ∈ [0, blocks) in a fixed order — each a unit direction ω (in the octahedral
  // frame) and `count` values (the mass of each component, ∫ over the mass's share of the sphere).
  // Blocks may run concurrently; their masses are added block by block in index order, so the
  // tables' bytes do not depend on the thread count. f's values for these components are ignored.
  // `view`, when set and it returns true for block b, gives that block's masses as spans instead
  // (held by the caller for the constructor's duration; the same bytes emit would append).
  struct PointMasses {
    int first = 0, count = 0;
    size_t blocks = 0;
    std::function<void(size_t block, std::vector<Eigen::Vector3d>& directions, std::vector<double>& values)> emit;
    std::function<bool(size_t block, std::span<const Eigen::Vector3d>& directions, std::span<const double>& values)> view;
  };

  IsolineTables(const oct::Grid& grid, int components, int subsamples, const Integrand& f,
                const PointMasses* masses = nullptr);

  int components() const noexcept { return components_; }
  const oct::Grid& grid() const noexcept { return grid_; }
  size_t bytes() const noexcept { return table_.size() * sizeof(double); }

  // acc[c] += weight · C_i(t)[c], t ∈ [0, 4ℓ_i] the loop parameter.
  void accumulate(int i, double t, double weight, double* acc) const noexcept;
  // The cell (isoline i, loop cell j ∈ [0, 2·cells_per_sheet(i))) holding unit direction ω (frame):
  // i the strip [u_i − h/2, u_i + h/2) of its u, j the cell of its loop parameter on its sheet
  // (clamped to the sheet's cells where the strip is wider than isoline i's diamond).
  std::pair<int, int> cell_of(const Eigen::Vector3d& omega) const noexcept;
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
