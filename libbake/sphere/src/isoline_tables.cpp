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

IsolineTables::IsolineTables(const oct::Grid& grid, int components, int subsamples, const Integrand& f,
                             const PointMasses* masses)
    : grid_(grid), components_(components) {
  PRT_CHECK(grid.n >= 2 && grid.n % 2 == 0);
  PRT_CHECK(components > 0 && subsamples >= 1);
  PRT_CHECK(!masses || (masses->first >= 0 && masses->count >= 0 && masses->first + masses->count <= components));
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
  const size_t m_first = masses ? size_t(masses->first) : 0, m_count = masses ? size_t(masses->count) : 0;
  // 1. Each cell's integral into row j + 1 (summed in step 3).
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
      for (size_t c = m_first; c < m_first + m_count; ++c) cell[c] = 0.0;
      std::copy(cell.begin(), cell.end(), row + (size_t(j) + 1) * F);
    }
  });
  // 2. The point masses, block by block in index order (a wave of blocks at a time runs in
  // parallel into its own lists; a fixed wave size, so the order of additions is the same for
  // every thread count).
  if (masses && m_count > 0 && masses->blocks > 0) {
    struct Block {
      std::vector<Eigen::Vector3d> directions;
      std::vector<double> values;
      std::span<const double> masses;  // values, or the caller's view
      std::vector<size_t> rows;
    };
    constexpr size_t kWave = 4;  // blocks held at once: enough for 2–4 threads, little memory
    std::vector<Block> wave(kWave);
    for (size_t b0 = 0; b0 < masses->blocks; b0 += kWave) {
      const size_t nb = std::min(kWave, masses->blocks - b0);
      tbb::parallel_for(size_t(0), nb, [&](size_t k) {
        Block& blk = wave[k];
        blk.directions.clear(), blk.values.clear(), blk.rows.clear();
        std::span<const Eigen::Vector3d> dirs;
        if (!(masses->view && masses->view(b0 + k, dirs, blk.masses))) {
          masses->emit(b0 + k, blk.directions, blk.values);
          dirs = blk.directions, blk.masses = blk.values;
        }
        PRT_CHECK_OP(blk.masses.size(), ==, dirs.size() * m_count);
        for (const Eigen::Vector3d& omega : dirs) {
          const auto [i, j] = cell_of(omega);
          blk.rows.push_back(offset_[size_t(i)] + size_t(j) + 1);
        }
      });
      const double inv_h = 1.0 / h;  // a cell holds h · mean(f J) = ∫_cell f dω / h
      for (size_t k = 0; k < nb; ++k)
        for (size_t r = 0; r < wave[k].rows.size(); ++r) {
          double* dst = &table_[wave[k].rows[r] * F + m_first];
          const double* src = &wave[k].masses[r * m_count];
          for (size_t c = 0; c < m_count; ++c) dst[c] += src[c] * inv_h;
        }
    }
  }
  // 3. Prefix sums along each loop.
  tbb::parallel_for(0, grid.n, [&](int i) {
    double* row = &table_[offset_[size_t(i)] * F];
    for (int j = 0; j < 2 * grid.cells_per_sheet(i); ++j)
      for (size_t c = 0; c < F; ++c) row[(size_t(j) + 1) * F + c] += row[size_t(j) * F + c];
  });
}

std::pair<int, int> IsolineTables::cell_of(const Eigen::Vector3d& omega) const noexcept {
  const double s = std::abs(omega.x()) + std::abs(omega.y()) + std::abs(omega.z());
  const double u = omega.x() / s, v = omega.y() / s;
  const int sheet = omega.z() < 0 ? 1 : 0;
  // int() truncates towards 0: floor for the non-negative quotients, and a quotient in (−1, 0)
  // (a direction just past the diamond's end of its strip) clamps to the same first cell.
  const int i = std::clamp(int((u + 1.0) / grid_.h), 0, grid_.n - 1);
  const int M = grid_.cells_per_sheet(i);
  const int j = std::clamp(int(grid_.t_of(i, v, sheet) / grid_.h), sheet * M, sheet * M + M - 1);
  return {i, j};
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
