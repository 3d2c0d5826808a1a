// ltc_fit — fits the GGX table of linearly transformed cosines that prtshade shades glossy
// polygons with (runtime/include/prtshade/ltc.h; Heitz, Dupuy, Hill, Neubelt, SIGGRAPH 2016, the
// idea; paper 003 §3 eq. 2 uses it) and writes it as C++ source (runtime/src/ltc_ggx_table.cpp).
//
// Per node (√α, θ_v) of an n × n grid (√α uniform in [0.1, 1], θ_v uniform in [0, 1.55 rad]):
//  * the lobe f(v, l)(n·l) of prtshade's GGX (height-correlated Smith masking, F = 1) with
//    v = (sin θ_v, 0, cos θ_v), n = z, by quadrature: l from the GGX normals h drawn with density
//    D(h)(n·h) (l = reflect(v, h), density D (n·h)/(4 v·h); samples with v·h ≤ 0 or l_z ≤ 0
//    weigh 0) at the points of a Fibonacci lattice in [0, 1)² (deterministic, bounded weights);
//    the albedo A = ∫ f cos and the Fresnel term B = ∫ f cos (1 − v·h)⁵;
//  * M = [[a, 0, b], [0, c, 0], [d, 0, 1]] minimising the total variation distance
//      TV(D_M, D̂) = ½ ∫_S² |D_M − D̂| dω = ∫ max(D̂ − D_M, 0) dω   (both have mass 1),
//    D̂ = f cos / A, by Nelder–Mead (restarted from its result until it stops improving), warm-
//    started from the neighbouring node (θ_v − Δ, or the next larger α at θ_v = 0, where the lobe
//    is round and only a = c is fitted, b = d = 0). TV is the quantity that bounds the error of
//    ∫_P D_M for every region P (prtshade/ltc.h), so it is what is minimised and reported.
// Then the table, rounded as written, is measured with the runtime's own lookup (bilinear
// interpolation) at every node, every cell centre and random points, against a 16× finer
// quadrature: ε = (A_true·TV + |ΔA|)/A and ε_F = (B_true·TV_F + |ΔB|)/A for the Fresnel-weighted
// lobe (relative to A: B vanishes at normal incidence); their
// maxima per cell (over its 3 × 3 half-grid points: corners, edge midpoints, centre), times a
// margin of 1.25, go into the table (Table::cell_errors), the global maxima too (Table::max_tv, max_tv_fresnel), and the
// statistics into its comment, with a check of the cell bounds at random points.
//
// Usage: ltc_fit [--size N] [--out FILE]   (default N = 32, FILE = runtime/src/ltc_ggx_table.cpp
// of the source tree). Single-threaded and deterministic.
#include <prtshade/ltc.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <functional>
#include <numbers>
#include <random>
#include <string>
#include <vector>

namespace {

using prt::shade::ltc::Vec3;
namespace ltc = prt::shade::ltc;

constexpr double kSqrtAlphaMin = 0.1, kThetaMax = 1.55, kCellMargin = 1.25;

// Quadrature of one lobe: directions l_k with f cos / density (g) and density (pdf), the
// Fresnel factor (1 − v·h)⁵ (s5), over `count` lattice points (zero-weight points omitted).
struct Lobe {
  Vec3 v;
  double alpha = 0, albedo = 0, fresnel = 0;
  size_t count = 0;
  std::vector<Vec3> l;
  std::vector<double> g, pdf, s5;
};

// The Fibonacci lattice (i/F_k, {i F_{k−1}/F_k}) shifted by half a cell.
Lobe sample_lobe(double alpha, double theta, int fib_k) {
  uint64_t f0 = 1, f1 = 1;
  for (int k = 2; k < fib_k; ++k) {
    const uint64_t f2 = f0 + f1;
    f0 = f1;
    f1 = f2;
  }
  Lobe q;
  q.alpha = alpha;
  q.v = {std::sin(theta), 0, std::cos(theta)};
  q.count = f1;
  const Vec3 n = {0, 0, 1};
  for (uint64_t i = 0; i < f1; ++i) {
    const double u1 = (double(i) + 0.5) / double(f1);
    const double u2 = std::fmod((double((i * f0) % f1) + 0.5) / double(f1), 1.0);
    const double tan2 = alpha * alpha * u1 / (1 - u1);
    const double ch = 1 / std::sqrt(1 + tan2), sh = std::sqrt(tan2) * ch, phi = 2 * std::numbers::pi * u2;
    const Vec3 h = {sh * std::cos(phi), sh * std::sin(phi), ch};
    const double vh = q.v[0] * h[0] + q.v[2] * h[2];
    if (!(vh > 0)) continue;
    const Vec3 l = {2 * vh * h[0] - q.v[0], 2 * vh * h[1] - q.v[1], 2 * vh * h[2] - q.v[2]};
    if (!(l[2] > 0)) continue;
    const double pdf = ltc::ggx_ndf(ch, alpha) * ch / (4 * vh);
    const double g = ltc::ggx_brdf(n, q.v, l, alpha, 1.0) * l[2] / pdf;
    q.l.push_back(l);
    q.g.push_back(g);
    q.pdf.push_back(pdf);
    q.s5.push_back(std::pow(1 - vh, 5));
    q.albedo += g;
    q.fresnel += g * q.s5.back();
  }
  q.albedo /= double(f1);
  q.fresnel /= double(f1);
  return q;
}

// TV(D_M, shape) for the lobe's shape (fresnel = false: D̂; true: D̂_F).
double total_variation(const Lobe& q, const ltc::Lobe& m, bool fresnel) {
  const double norm = fresnel ? q.fresnel : q.albedo;
  double sum = 0;
  for (size_t k = 0; k < q.l.size(); ++k) {
    const double target = q.g[k] * (fresnel ? q.s5[k] : 1.0) / norm;
    sum += std::max(target - ltc::density(m, q.l[k]) / q.pdf[k], 0.0);
  }
  return sum / double(q.count);
}

bool valid(const std::array<double, 4>& m) { return m[0] > 0 && m[2] > 0 && m[0] - m[1] * m[3] > 0; }

double objective(const Lobe& q, const std::array<double, 4>& m) {
  if (!valid(m)) return 1e9;
  return total_variation(q, ltc::lobe_from_matrix({0, 0, 1}, q.v, m, 1, 1), false);
}

// Nelder–Mead (reflection 1, expansion 2, contraction ½, shrink ½) over x ∈ R^dim.
std::vector<double> nelder_mead(const std::function<double(const std::vector<double>&)>& f, std::vector<double> x0,
                                int max_evals, double& best) {
  const size_t dim = x0.size();
  std::vector<std::vector<double>> s(dim + 1, x0);
  std::vector<double> fs(dim + 1);
  for (size_t i = 0; i < dim; ++i) s[i + 1][i] += 0.05 * std::abs(x0[i]) + 0.01;
  int evals = 0;
  for (size_t i = 0; i <= dim; ++i) fs[i] = f(s[i]), ++evals;
  std::vector<size_t> order(dim + 1);
  while (evals < max_evals) {
    for (size_t i = 0; i <= dim; ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return fs[a] < fs[b]; });
    const size_t lo = order[0], hi = order[dim], second = order[dim - 1];
    if (fs[hi] - fs[lo] < 1e-9) break;
    std::vector<double> c(dim, 0.0);
    for (size_t i = 0; i <= dim; ++i)
      if (i != hi)
        for (size_t k = 0; k < dim; ++k) c[k] += s[i][k] / double(dim);
    const auto along = [&](double t) {
      std::vector<double> p(dim);
      for (size_t k = 0; k < dim; ++k) p[k] = c[k] + t * (s[hi][k] - c[k]);
      return p;
    };
    const std::vector<double> r = along(-1);
    const double fr = f(r);
    ++evals;
    if (fr < fs[lo]) {
      const std::vector<double> e = along(-2);
      const double fe = f(e);
      ++evals;
      if (fe < fr) s[hi] = e, fs[hi] = fe;
      else s[hi] = r, fs[hi] = fr;
    } else if (fr < fs[second]) {
      s[hi] = r, fs[hi] = fr;
    } else {
      const std::vector<double> k = fr < fs[hi] ? along(-0.5) : along(0.5);
      const double fk = f(k);
      ++evals;
      if (fk < std::min(fr, fs[hi])) {
        s[hi] = k, fs[hi] = fk;
      } else {
        for (size_t i = 0; i <= dim; ++i) {
          if (i == lo) continue;
          for (size_t d = 0; d < dim; ++d) s[i][d] = s[lo][d] + 0.5 * (s[i][d] - s[lo][d]);
          fs[i] = f(s[i]), ++evals;
        }
      }
    }
  }
  const size_t b = size_t(std::min_element(fs.begin(), fs.end()) - fs.begin());
  best = fs[b];
  return s[b];
}

// The best M for the lobe from a start (round: a = c only, b = d = 0).
std::array<double, 4> fit(const Lobe& q, std::array<double, 4> start, bool round) {
  const auto to_m = [&](const std::vector<double>& x) {
    return round ? std::array<double, 4>{x[0], 0, x[0], 0} : std::array<double, 4>{x[0], x[1], x[2], x[3]};
  };
  const auto f = [&](const std::vector<double>& x) { return objective(q, to_m(x)); };
  std::vector<double> x = round ? std::vector<double>{start[0]} : std::vector<double>(start.begin(), start.end());
  double best = f(x);
  for (int restart = 0; restart < 8; ++restart) {
    double value = 0;
    std::vector<double> y = nelder_mead(f, x, 1500, value);
    const bool improved = value < best - 1e-7;
    if (value < best) best = value, x = y;
    if (!improved) break;
  }
  return to_m(x);
}

std::string format(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.10g", x);
  return buf;
}

struct Error {
  double eps = 0, eps_fresnel = 0, tv = 0;
};

// ε, ε_F at (α, θ) with the table's lookup, against a fine quadrature (fib_k).
Error measure(const ltc::Table& table, double alpha, double theta, int fib_k) {
  const Lobe q = sample_lobe(alpha, theta, fib_k);
  const auto e = ltc::lookup(table, alpha, std::cos(theta));
  const ltc::Lobe m = ltc::lobe_from_matrix({0, 0, 1}, q.v, {e[0], e[1], e[2], e[3]}, e[4], e[5]);
  Error out;
  out.tv = total_variation(q, m, false);
  out.eps = (q.albedo * out.tv + std::abs(e[4] - q.albedo)) / e[4];
  out.eps_fresnel = (q.fresnel * total_variation(q, m, true) + std::abs(e[5] - q.fresnel)) / e[4];
  return out;
}

} // namespace

int main(int argc, char** argv) {
  int n = 32;
  std::string out = std::string(PRT_SOURCE_DIR) + "/runtime/src/ltc_ggx_table.cpp";
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--size")) n = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--out")) out = argv[i + 1];
    else {
      std::fprintf(stderr, "usage: ltc_fit [--size N] [--out FILE]\n");
      return 2;
    }
  }
  if (n < 2 || n > 256) {
    std::fprintf(stderr, "ltc_fit: --size must be in [2, 256]\n");
    return 2;
  }
  constexpr int kFitFib = 19, kMeasureFib = 25;  // 4181 and 75025 quadrature points
  const auto alpha_at = [&](double i) {
    const double r = kSqrtAlphaMin + i * (1 - kSqrtAlphaMin) / (n - 1);
    return r * r;
  };
  const auto theta_at = [&](double j) { return j * kThetaMax / (n - 1); };
  const double c0 = double(std::clock());
  std::vector<double> values(size_t(n) * size_t(n) * ltc::Table::kValuesPerNode);
  std::array<double, 4> row_start = {1, 0, 1, 0};
  for (int i = n - 1; i >= 0; --i) {
    std::array<double, 4> m = row_start;
    for (int j = 0; j < n; ++j) {
      const Lobe q = sample_lobe(alpha_at(i), theta_at(j), kFitFib);
      m = fit(q, m, j == 0);
      if (j == 0) row_start = m;
      double* node = &values[(size_t(i) * size_t(n) + size_t(j)) * ltc::Table::kValuesPerNode];
      const std::array<double, 6> entry = {m[0], m[1], m[2], m[3], q.albedo, q.fresnel};
      for (int k = 0; k < 6; ++k) node[k] = std::strtod(format(entry[k]).c_str(), nullptr);  // as written
    }
    std::fprintf(stderr, "alpha %.4f done (%.0f s CPU)\n", alpha_at(i), (double(std::clock()) - c0) / CLOCKS_PER_SEC);
  }
  const double fit_seconds = (double(std::clock()) - c0) / CLOCKS_PER_SEC;

  ltc::Table table;
  table.n_alpha = table.n_theta = n;
  table.sqrt_alpha_min = kSqrtAlphaMin;
  table.theta_max = kThetaMax;
  table.values = values.data();
  struct Stats {
    double max_eps = 0, max_eps_f = 0, sum_eps = 0, max_tv = 0, sum_tv = 0;
    size_t count = 0;
    void add(const Error& e) {
      max_eps = std::max(max_eps, e.eps), max_eps_f = std::max(max_eps_f, e.eps_fresnel);
      max_tv = std::max(max_tv, e.tv);
      sum_eps += e.eps, sum_tv += e.tv, ++count;
    }
  };
  // The half-grid: nodes, edge midpoints and cell centres; a cell's bound is the maximum over
  // its 3 × 3 half-grid points. Then random points check the bounds of their cells.
  const int h = 2 * n - 1;
  std::vector<Error> half(size_t(h) * size_t(h));
  Stats nodes, centres, random;
  std::vector<Stats> rows(static_cast<size_t>(n));
  for (int i = 0; i < h; ++i)
    for (int j = 0; j < h; ++j) {
      const Error e = measure(table, alpha_at(0.5 * i), theta_at(0.5 * j), kMeasureFib);
      half[size_t(i) * size_t(h) + size_t(j)] = e;
      if (i % 2 == 0 && j % 2 == 0) nodes.add(e), rows[size_t(i / 2)].add(e);
      if (i % 2 == 1 && j % 2 == 1) centres.add(e);
    }
  std::vector<double> cell_errors(size_t(n - 1) * size_t(n - 1) * 2);
  for (int i = 0; i + 1 < n; ++i)
    for (int j = 0; j + 1 < n; ++j) {
      double* c = &cell_errors[(size_t(i) * size_t(n - 1) + size_t(j)) * 2];
      for (int di = 0; di < 3; ++di)
        for (int dj = 0; dj < 3; ++dj) {
          const Error& e = half[size_t(2 * i + di) * size_t(h) + size_t(2 * j + dj)];
          c[0] = std::max(c[0], e.eps), c[1] = std::max(c[1], e.eps_fresnel);
        }
      // The error varies between the sampled points: the bound is 1.25 × their maximum (the
      // random points below check it).
      for (int k = 0; k < 2; ++k) c[k] = std::strtod(format(kCellMargin * c[k]).c_str(), nullptr);
    }
  table.cell_errors = cell_errors.data();
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> u(0, 1);
  double worst_ratio = 0;
  for (int k = 0; k < n * n; ++k) {
    const double a = u(rng) * (n - 1), t = u(rng) * (n - 1);
    const Error e = measure(table, alpha_at(a), theta_at(t), kMeasureFib);
    random.add(e);
    const double* c = &cell_errors[(size_t(std::min(int(a), n - 2)) * size_t(n - 1) + size_t(std::min(int(t), n - 2))) * 2];
    worst_ratio = std::max({worst_ratio, e.eps / c[0], e.eps_fresnel / c[1]});
  }
  const double eps = std::max({nodes.max_eps, centres.max_eps, random.max_eps});
  const double eps_f = std::max({nodes.max_eps_f, centres.max_eps_f, random.max_eps_f});
  const double total_seconds = (double(std::clock()) - c0) / CLOCKS_PER_SEC;

  std::string text;
  text += "// ltc_ggx_table.cpp — GENERATED by tools/ltc_fit (do not edit): the GGX table of\n";
  text += "// linearly transformed cosines of prtshade/ltc.h (height-correlated Smith masking). Regenerate:\n";
  text += "//   cmake --build --preset release --target ltc_fit && build/release/tools/ltc_fit --size " +
          std::to_string(n) + "\n";
  text += "// Grid: " + std::to_string(n) + " x " + std::to_string(n) + " nodes, sqrt(alpha) in [0.1, 1], theta_v in [0, 1.55] rad.\n";
  char buf[512];
  const auto stat_line = [&](const char* what, const Stats& s) {
    std::snprintf(buf, sizeof buf, "//   %-13s %5zu points: TV max %.4f mean %.4f; eps max %.4f mean %.4f; eps_F max %.4f\n", what,
                  s.count, s.max_tv, s.sum_tv / double(s.count), s.max_eps, s.sum_eps / double(s.count), s.max_eps_f);
    text += buf;
  };
  text += "// Measured (75025-point quadrature, the interpolated table; eps = (A TV + |dA|)/A, prtshade/ltc.h):\n";
  stat_line("nodes", nodes);
  stat_line("cell centres", centres);
  stat_line("random", random);
  std::snprintf(buf, sizeof buf,
                "// Per-cell bounds (1.25 x the max over each cell's 3 x 3 half-grid points): the random points' eps reach at most %.3f of their cell's.\n",
                worst_ratio);
  text += buf;
  text += "// Per alpha (nodes): alpha, TV max, TV mean\n";
  for (int i = 0; i < n; ++i) {
    std::snprintf(buf, sizeof buf, "//   %.4f %.4f %.4f\n", alpha_at(i), rows[size_t(i)].max_tv,
                  rows[size_t(i)].sum_tv / double(rows[size_t(i)].count));
    text += buf;
  }
  text += "#include <prtshade/ltc.h>\n\nnamespace prt::shade::ltc {\n\nnamespace {\n\n";
  text += "// {a, b, c, d, A, B} per node, node (i, j) at row i·" + std::to_string(n) + " + j.\n";
  text += "constexpr double kValues[] = {\n";
  for (size_t k = 0; k < values.size(); k += 6) {
    text += "    ";
    for (size_t c = 0; c < 6; ++c) text += format(values[k + c]) + ",";
    text += "\n";
  }
  text += "};\n\n// {eps, eps_F} per cell, cell (i, j) at row i·" + std::to_string(n - 1) + " + j.\n";
  text += "constexpr double kCellErrors[] = {\n";
  for (size_t k = 0; k < cell_errors.size(); k += 2) text += "    " + format(cell_errors[k]) + "," + format(cell_errors[k + 1]) + ",\n";
  text += "};\n\n} // namespace\n\nconst Table& ggx_table() {\n";
  text += "  static const Table table{" + std::to_string(n) + ", " + std::to_string(n) + ", " + format(kSqrtAlphaMin) + ", " +
          format(kThetaMax) + ", kValues, kCellErrors, " + format(eps) + ", " + format(eps_f) + "};\n";
  text += "  return table;\n}\n\n} // namespace prt::shade::ltc\n";
  std::FILE* f = std::fopen(out.c_str(), "w");
  if (!f || std::fwrite(text.data(), 1, text.size(), f) != text.size() || std::fclose(f) != 0) {
    std::fprintf(stderr, "ltc_fit: cannot write %s\n", out.c_str());
    return 1;
  }
  std::printf("fit %.1f s CPU, fit + measurement %.1f s CPU; eps %.4f, eps_F %.4f; wrote %s\n", fit_seconds, total_seconds,
              eps, eps_f, out.c_str());
  std::fputs(text.substr(0, text.find("#include")).c_str(), stdout);
  return 0;
}
