#include <bake/core/error.h>
#include <bake/sphere/isoline_tables.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace prt::bake {

namespace {
// h · mean of f·J over the cell [v_lo, v_lo + h] of the strip [u_i − h/2, u_i + h/2] on a sheet,
// by s × s midpoint sub-samples (v clamped to the diamond where the strip's u leaves it).
void cell_integral(const IsolineTables::Integrand& f, double h, double ui, double v_lo, int sheet, int S,
                   std::vector<double>& g, std::vector<double>& cell) {
  std::fill(cell.begin(), cell.end(), 0.0);
  for (int a = 0; a < S; ++a) {
    const double u = ui + ((a + 0.5) / S - 0.5) * h;
    const double lu = 1.0 - std::abs(u);
    for (int b = 0; b < S; ++b) {
      const double v = std::clamp(v_lo + (b + 0.5) / S * h, -lu, lu);
      f(oct::dir_from_uv(u, v, sheet).normalized(), g);
      const double J = oct::jacobian(u, v);
      for (size_t c = 0; c < cell.size(); ++c) cell[c] += g[c] * J;
    }
  }
  const double scale = h / double(S * S);
  for (double& c : cell) c *= scale;
}
} // namespace

IsolineTables::IsolineTables(const oct::Grid& grid, int components, int subsamples, const Integrand& f)
    : grid_(grid), components_(components) {
  PRT_CHECK(grid.n >= 2 && grid.n % 2 == 0);
  PRT_CHECK(components > 0 && subsamples >= 1);
  const size_t F = size_t(components);
  offset_.resize(size_t(grid.n));
  size_t rows = 0;
  for (int i = 0; i < grid.n; ++i) {
    offset_[size_t(i)] = rows;
    rows += size_t(2 * grid.cells_per_sheet(i) + 1);
  }
  table_.assign(rows * F, 0.0);
  const double h = grid.h;
  const int S = subsamples;
  tbb::parallel_for(0, grid.n, [&](int i) {
    std::vector<double> g(F), cell(F);
    const int M = grid.cells_per_sheet(i);
    const double l = grid.half_length(i), ui = grid.u(i);
    double* row = &table_[offset_[size_t(i)] * F];  // row 0 = 0
    for (int j = 0; j < 2 * M; ++j) {
      const int sheet = j < M ? 0 : 1;
      // The cell's v-interval (sheet 1 runs downwards in v).
      const double v_lo = sheet == 0 ? -l + j * h : l - (j - M + 1) * h;
      cell_integral(f, h, ui, v_lo, sheet, S, g, cell);
      for (size_t c = 0; c < F; ++c) row[(size_t(j) + 1) * F + c] = row[size_t(j) * F + c] + cell[c];
    }
  });
}

void IsolineTables::accumulate(int i, double t, double weight, double* acc) const noexcept {
  const int cells = 2 * grid_.cells_per_sheet(i);
  const double x = t / grid_.h;
  int j = int(std::floor(x));
  j = std::clamp(j, 0, cells - 1);
  const double frac = std::clamp(x - j, 0.0, 1.0);
  const size_t F = size_t(components_);
  const double* r0 = &table_[(offset_[size_t(i)] + size_t(j)) * F];
  const double* r1 = r0 + F;
  const double w0 = weight * (1.0 - frac), w1 = weight * frac;
  for (size_t c = 0; c < F; ++c) acc[c] += w0 * r0[c] + w1 * r1[c];
}

} // namespace prt::bake
