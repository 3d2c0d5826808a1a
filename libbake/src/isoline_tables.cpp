#include <bake/error.h>
#include <bake/isoline_tables.h>

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

namespace prt::bake {

namespace {
// Loop parameter and isoline index of a unit direction on a grid (sgn0 conventions of octahedral.h).
void locate(const oct::Grid& g, const Eigen::Vector3d& w, int& i, double& t) {
  const double d = std::abs(w.x()) + std::abs(w.y()) + std::abs(w.z());
  const double u = w.x() / d, v = w.y() / d;
  const int sheet = oct::sgn0(w.z()) > 0 ? 0 : 1;
  i = std::clamp(int(std::floor((u + 1.0) / g.h)), 0, g.n - 1);
  const double l = g.half_length(i);
  t = g.t_of(i, std::clamp(v, -l, l), sheet);
}
} // namespace

SparseIsolineTables::SparseIsolineTables(const oct::Grid& grid, int components, int subsamples,
                                         const IsolineTables::Integrand& f,
                                         std::span<const Eigen::Vector3d> support_samples)
    : grid_(grid), components_(components) {
  PRT_CHECK(grid.n >= 2 && grid.n % 2 == 0 && components > 0 && subsamples >= 1);
  if (support_samples.empty()) return;
  // Cell ranges per isoline, with one isoline and two cells of margin (a direction's loop
  // parameter moves by one cell between neighbouring isolines, since ℓ changes by h).
  int lo = grid.n, hi = -1;
  std::vector<std::pair<int, int>> r(size_t(grid.n), {-1, -1});
  for (const Eigen::Vector3d& w : support_samples) {
    int i;
    double t;
    locate(grid, w, i, t);
    for (int di = -1; di <= 1; ++di) {
      const int k = i + di;
      if (k < 0 || k >= grid.n) continue;
      const int cells = 2 * grid.cells_per_sheet(k);
      // t on a neighbouring isoline: the same direction's (v, sheet) gives about the same t.
      const int j = std::clamp(int(std::floor(t / grid.h)), 0, cells - 1);
      auto& [a, b] = r[size_t(k)];
      const int ja = std::max(j - 2, 0), jb = std::min(j + 2, cells - 1);
      a = a < 0 ? ja : std::min(a, ja);
      b = b < 0 ? jb : std::max(b, jb);
      lo = std::min(lo, k);
      hi = std::max(hi, k + 1);
    }
  }
  i_lo_ = lo;
  i_hi_ = hi;
  range_.assign(r.begin() + lo, r.begin() + hi);
  offset_.resize(range_.size());
  const size_t F = size_t(components);
  size_t rows = 0;
  for (size_t k = 0; k < range_.size(); ++k) {
    offset_[k] = rows;
    if (range_[k].first >= 0) rows += size_t(range_[k].second - range_[k].first + 2);
  }
  table_.assign(rows * F, 0.0);
  const double h = grid.h;
  const int S = subsamples;
  tbb::parallel_for(size_t(0), range_.size(), [&](size_t k) {
    if (range_[k].first < 0) return;
    const int i = i_lo_ + int(k);
    const int M = grid.cells_per_sheet(i);
    const double l = grid.half_length(i), ui = grid.u(i);
    std::vector<double> g(F), cell(F);
    double* row = &table_[offset_[k] * F];
    for (int j = range_[k].first, rj = 0; j <= range_[k].second; ++j, ++rj) {
      const int sheet = j < M ? 0 : 1;
      const double v_lo = sheet == 0 ? -l + j * h : l - (j - M + 1) * h;
      cell_integral(f, h, ui, v_lo, sheet, S, g, cell);
      for (size_t c = 0; c < F; ++c) row[(size_t(rj) + 1) * F + c] = row[size_t(rj) * F + c] + cell[c];
    }
  });
}

void SparseIsolineTables::accumulate(int i, double t, double weight, double* acc) const noexcept {
  const size_t k = size_t(i - i_lo_);
  const auto [ja, jb] = range_[k];
  const size_t F = size_t(components_);
  const double x = t / grid_.h - ja;  // in cells from the range's start
  if (!(x > 0)) return;              // C = 0 before the range
  const int n = jb - ja + 1;
  const double* base = &table_[offset_[k] * F];
  if (x >= n) {
    for (size_t c = 0; c < F; ++c) acc[c] += weight * base[size_t(n) * F + c];
    return;
  }
  const int j = int(std::floor(x));
  const double frac = x - j;
  const double* r0 = base + size_t(j) * F;
  const double* r1 = r0 + F;
  for (size_t c = 0; c < F; ++c) acc[c] += weight * ((1.0 - frac) * r0[c] + frac * r1[c]);
}

const double* SparseIsolineTables::loop_total(int i) const noexcept {
  const size_t k = size_t(i - i_lo_);
  const int n = range_[k].second - range_[k].first + 1;
  return &table_[(offset_[k] + size_t(n)) * size_t(components_)];
}

} // namespace prt::bake
