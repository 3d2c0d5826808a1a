// sh.cpp — SH evaluation and rotation; conventions and papers are in prtshade/sh.h.
#include <prtshade/sh.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>

namespace prt::sh {
namespace {

constexpr double kPi = 3.14159265358979323846264338327950288;

// Always-on precondition check: a broken contract is a caller bug (std::logic_error family).
[[noreturn]] void contract_failure(const char* file, int line, const char* what, const std::string& detail) {
  std::ostringstream os;
  os << file << ":" << line << ": prt::sh precondition failed: " << what;
  if (!detail.empty()) os << " (" << detail << ")";
  throw std::invalid_argument(os.str());
}

#define PRT_SH_REQUIRE(cond, detail)                                                             \
  do {                                                                                           \
    if (!(cond)) contract_failure(__FILE__, __LINE__, #cond, (detail));                          \
  } while (0)

std::string show(long long a) { return std::to_string(a); }
std::string show(long long a, long long b) { return std::to_string(a) + " vs " + std::to_string(b); }

// Coefficients of the normalised associated-Legendre recurrence. With
//   p̄_l^m(z) := N_l^m · P_l^m(z) / sin^m θ      (N_l^m = K_l^m, times √2 for m > 0),
// a polynomial in z, the orthonormal basis is y_{l,±m} = p̄_l^m(z) · {Re, Im}(x + i y)^m, and
//   p̄_0^0 = 1/(2√π),  p̄_1^1 = −√3 p̄_0^0,  p̄_m^m = −sqrt((2m+1)/(2m)) p̄_{m−1}^{m−1}  (m >= 2),
//   p̄_{m+1}^m = sqrt(2m+3) z p̄_m^m,
//   p̄_l^m = a_l^m (z p̄_{l−1}^m − b_l^m p̄_{l−2}^m),
//     a_l^m = sqrt((4l² − 1)/(l² − m²)),  b_l^m = sqrt(((l−1)² − m²)/(4(l−1)² − 1)).
// Every quantity stays O(l^{1/4}) or smaller, so nothing overflows or underflows at any order
// <= kMaxOrder (the sin^m θ factor lives in (x + i y)^m, which is bounded by 1).
struct LegendreTables {
  std::array<double, kMaxOrder> diag{};                              // p̄_m^m
  std::array<double, kMaxOrder * kMaxOrder> a{}, b{};                // indexed by index(l, m), m >= 0
  LegendreTables() {
    diag[0] = 0.5 / std::sqrt(kPi);
    if (kMaxOrder > 1) diag[1] = -std::sqrt(3.0) * diag[0];
    for (int m = 2; m < kMaxOrder; ++m)
      diag[static_cast<std::size_t>(m)] =
          -std::sqrt((2.0 * m + 1.0) / (2.0 * m)) * diag[static_cast<std::size_t>(m - 1)];
    for (int m = 0; m < kMaxOrder; ++m) {
      for (int l = m + 2; l < kMaxOrder; ++l) {
        const double l2 = double(l) * l, m2 = double(m) * m, lm1 = double(l - 1) * (l - 1);
        const auto i = static_cast<std::size_t>(index(l, m));
        a[i] = std::sqrt((4.0 * l2 - 1.0) / (l2 - m2));
        b[i] = std::sqrt((lm1 - m2) / (4.0 * lm1 - 1.0));
      }
    }
  }
};

const LegendreTables& legendre_tables() {
  static const LegendreTables tables;  // thread-safe initialisation (C++11 magic statics)
  return tables;
}

template <typename T>
void eval_impl(int order, double x, double y, double z, std::span<T> out) {
  PRT_SH_REQUIRE(order >= 0 && order <= kMaxOrder, show(order));
  PRT_SH_REQUIRE(out.size() >= static_cast<std::size_t>(num_coeffs(order)),
                 show(static_cast<long long>(out.size()), num_coeffs(order)));
#ifndef NDEBUG
  {
    const double r2 = x * x + y * y + z * z;
    PRT_SH_REQUIRE(std::abs(r2 - 1.0) <= 1e-4, "|d|^2 = " + std::to_string(r2));
  }
#endif
  if (order == 0) return;
  const LegendreTables& t = legendre_tables();
  auto put = [&](int l, int m, double v) { out[static_cast<std::size_t>(index(l, m))] = static_cast<T>(v); };

  double c = 1.0, s = 0.0;  // Re, Im of (x + i y)^m = sin^m θ · (cos mφ, sin mφ)
  for (int m = 0; m < order; ++m) {
    const double pmm = t.diag[static_cast<std::size_t>(m)];
    // l = m
    if (m == 0) {
      put(0, 0, pmm);
    } else {
      put(m, m, pmm * c);
      put(m, -m, pmm * s);
    }
    // l = m + 1
    if (m + 1 < order) {
      double p_prev = pmm;
      double p = std::sqrt(2.0 * m + 3.0) * z * pmm;
      if (m == 0) {
        put(1, 0, p);
      } else {
        put(m + 1, m, p * c);
        put(m + 1, -m, p * s);
      }
      // l >= m + 2
      for (int l = m + 2; l < order; ++l) {
        const auto i = static_cast<std::size_t>(index(l, m));
        const double p_next = t.a[i] * (z * p - t.b[i] * p_prev);
        p_prev = p;
        p = p_next;
        if (m == 0) {
          put(l, 0, p);
        } else {
          put(l, m, p * c);
          put(l, -m, p * s);
        }
      }
    }
    // (x + i y)^{m+1} = (x + i y)^m (x + i y)
    const double c_next = c * x - s * y;
    s = s * x + c * y;
    c = c_next;
  }
}

} // namespace

void eval(int order, double x, double y, double z, std::span<double> out) {
  eval_impl<double>(order, x, y, z, out);
}

void eval(int order, float x, float y, float z, std::span<float> out) {
  eval_impl<float>(order, double(x), double(y), double(z), out);
}

double eval_slow(int l, int m, double x, double y, double z) {
  PRT_SH_REQUIRE(l >= 0 && l <= 30, show(l));
  PRT_SH_REQUIRE(m >= -l && m <= l, show(m, l));
  using R = long double;
  const int am = m < 0 ? -m : m;
  auto fact = [](int n) {
    R f = 1;
    for (int k = 2; k <= n; ++k) f *= R(k);
    return f;
  };
  auto binom = [&](int n, int k) { return fact(n) / (fact(k) * fact(n - k)); };
  // P_l^m(z) = (−1)^m (1 − z²)^{m/2} d^m/dz^m P_l(z), with the explicit Legendre polynomial
  // P_l(z) = 2^{−l} Σ_k (−1)^k C(l, k) C(2l − 2k, l) z^{l−2k}.
  const R zl = z;
  R dsum = 0;
  for (int k = 0; 2 * k <= l - am; ++k) {
    const int p = l - 2 * k;
    const R term = binom(l, k) * binom(2 * l - 2 * k, l) * fact(p) / fact(p - am) *
                   std::pow(zl, R(p - am));
    dsum += (k % 2 == 0) ? term : -term;
  }
  dsum /= std::pow(R(2), R(l));
  const R sin_theta = std::sqrt(R(x) * R(x) + R(y) * R(y));
  const R plm = ((am % 2 == 0) ? R(1) : R(-1)) * std::pow(sin_theta, R(am)) * dsum;
  const R k_lm = std::sqrt(R(2 * l + 1) / (4 * R(kPi)) * fact(l - am) / fact(l + am));
  if (m == 0) return static_cast<double>(k_lm * plm);
  const R phi = std::atan2(R(y), R(x));
  const R azimuth = m > 0 ? std::cos(R(am) * phi) : std::sin(R(am) * phi);
  return static_cast<double>(std::sqrt(R(2)) * k_lm * azimuth * plm);
}

// ---------------------------------------------------------------------------------------------
// Rotation (Ivanic & Ruedenberg 1996, Table 2 as corrected in 1998).

int Rotation::band_offset(int l) noexcept {
  // Σ_{k<l} (2k+1)² = l(4l² − 1)/3
  return l * (4 * l * l - 1) / 3;
}

Rotation::Rotation(const double R[3][3], int order) : order_(order) {
  PRT_SH_REQUIRE(order >= 0 && order <= kMaxOrder, show(order));
  {
    double max_dev = 0.0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        double dot = 0.0;
        for (int k = 0; k < 3; ++k) dot += R[i][k] * R[j][k];
        max_dev = std::max(max_dev, std::abs(dot - (i == j ? 1.0 : 0.0)));
      }
    const double det = R[0][0] * (R[1][1] * R[2][2] - R[1][2] * R[2][1]) -
                       R[0][1] * (R[1][0] * R[2][2] - R[1][2] * R[2][0]) +
                       R[0][2] * (R[1][0] * R[2][1] - R[1][1] * R[2][0]);
    PRT_SH_REQUIRE(max_dev <= 1e-6 && det > 0.0,
                   "max |R R^T - I| = " + std::to_string(max_dev) + ", det = " + std::to_string(det));
  }
  matrices_.assign(static_cast<std::size_t>(band_offset(order)), 0.0);
  if (order == 0) return;
  matrices_[0] = 1.0;
  if (order == 1) return;

  // Band 1: y_{1,m} ∝ s_m d[a_m], (a_−1, a_0, a_1) = (y, z, x), (s_−1, s_0, s_1) = (−1, 1, −1).
  constexpr int axis[3] = {1, 2, 0};
  constexpr double sign[3] = {-1.0, 1.0, -1.0};
  double r1[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r1[i][j] = sign[i] * sign[j] * R[axis[i]][axis[j]];
  {
    double* d1 = matrices_.data() + band_offset(1);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) d1[3 * i + j] = r1[i][j];
  }

  // The recurrence runs in long double and each entry is rounded once to double. Run in
  // double, its rounding error grows by ~1.2x per band above l ≈ 20 (measured |D Dᵀ − I|:
  // 3e-14 at l = 29, 2e-11 at l = 63, for 90° and generic rotations alike; the coefficients
  // u, v, w reach ~sqrt(l/2) where (l+n)(l−n) is small, and taking each entry from the
  // better-conditioned of the R and Rᵀ recurrences fixed the 90° cases only). With the x87
  // 80-bit format (64-bit mantissa) the same growth stays at the double rounding level through
  // l = 63. Where long double is double (MSVC, some ABIs) this is the plain double recurrence.
  using Real = long double;
  Real r1l[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r1l[i][j] = Real(sign[i]) * Real(sign[j]) * Real(R[axis[i]][axis[j]]);
  std::vector<Real> prev_band(9), cur_band;
  std::vector<Real> inv_sqrt_denom(static_cast<std::size_t>(2 * order + 1)), u_num(inv_sqrt_denom.size()),
      v_num(inv_sqrt_denom.size()), w_num(inv_sqrt_denom.size());
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) prev_band[static_cast<std::size_t>(3 * i + j)] = r1l[i][j];
  for (int l = 2; l < order; ++l) {
    const int wp = 2 * l - 1, wc = 2 * l + 1;
    cur_band.assign(static_cast<std::size_t>(wc * wc), Real(0));
    auto R1 = [&](int i, int j) { return r1l[i + 1][j + 1]; };
    auto M = [&](int a, int b) { return prev_band[static_cast<std::size_t>((a + l - 1) * wp + (b + l - 1))]; };
    // Ivanic & Ruedenberg's function P^l_{i; a, b}, −1 <= i <= 1, |a| <= l−1, |b| <= l.
    auto P = [&](int i, int a, int b) {
      if (b == l) return R1(i, 1) * M(a, l - 1) - R1(i, -1) * M(a, -l + 1);
      if (b == -l) return R1(i, 1) * M(a, -l + 1) + R1(i, -1) * M(a, l - 1);
      return R1(i, 0) * M(a, b);
    };
    const Real sqrt2 = std::sqrt(Real(2));
    // u, v, w = (row factor in m) / sqrt(denominator in n): O(l) square roots per band.
    for (int k = -l; k <= l; ++k) {
      const int ak = k < 0 ? -k : k;
      const auto i = static_cast<std::size_t>(k + l);
      const Real denom = (ak == l) ? Real(2 * l) * (2 * l - 1) : Real(l + k) * (l - k);
      inv_sqrt_denom[i] = 1 / std::sqrt(denom);
      u_num[i] = std::sqrt(Real(l + k) * (l - k));
      v_num[i] = Real(0.5) * std::sqrt(Real(k == 0 ? 2 : 1) * (l + ak - 1) * (l + ak)) * Real(k == 0 ? -1 : 1);
      w_num[i] = k == 0 ? Real(0) : Real(-0.5) * std::sqrt(Real(l - ak - 1) * (l - ak));
    }
    for (int m = -l; m <= l; ++m) {
      const bool m0 = (m == 0);
      const auto im = static_cast<std::size_t>(m + l);
      for (int n = -l; n <= l; ++n) {
        const Real isd = inv_sqrt_denom[static_cast<std::size_t>(n + l)];
        const Real u = u_num[im] * isd, v = v_num[im] * isd, w = w_num[im] * isd;
        Real value = 0;
        if (u != 0) value += u * P(0, m, n);
        if (v != 0) {
          Real V;
          if (m0)
            V = P(1, 1, n) + P(-1, -1, n);
          else if (m > 0)
            V = P(1, m - 1, n) * (m == 1 ? sqrt2 : Real(1)) - (m == 1 ? Real(0) : P(-1, -m + 1, n));
          else
            V = (m == -1 ? Real(0) : P(1, m + 1, n)) + P(-1, -m - 1, n) * (m == -1 ? sqrt2 : Real(1));
          value += v * V;
        }
        if (w != 0) {
          const Real W = (m > 0) ? P(1, m + 1, n) + P(-1, -m - 1, n) : P(1, m - 1, n) - P(-1, -m + 1, n);
          value += w * W;
        }
        cur_band[static_cast<std::size_t>((m + l) * wc + (n + l))] = value;
      }
    }
    double* out = matrices_.data() + band_offset(l);
    for (std::size_t k = 0; k < cur_band.size(); ++k) out[k] = static_cast<double>(cur_band[k]);
    prev_band.swap(cur_band);
  }
}

int Rotation::order() const noexcept { return order_; }

namespace {
template <typename T>
void apply_impl(int order, const std::vector<double>& mats, int (*offset)(int), std::span<const T> in,
                std::span<T> out) {
  const auto n = static_cast<std::size_t>(num_coeffs(order));
  PRT_SH_REQUIRE(in.size() >= n, show(static_cast<long long>(in.size()), static_cast<long long>(n)));
  PRT_SH_REQUIRE(out.size() >= n, show(static_cast<long long>(out.size()), static_cast<long long>(n)));
  const std::less<const T*> before;
  const T* out_begin = out.data();
  PRT_SH_REQUIRE(n == 0 || !before(in.data(), out_begin + n) || !before(out_begin, in.data() + n),
                 "in and out overlap");
  for (int l = 0; l < order; ++l) {
    const double* D = mats.data() + offset(l);
    const int w = 2 * l + 1, base = l * l;
    for (int r = 0; r < w; ++r) {
      double acc = 0.0;
      for (int c = 0; c < w; ++c) acc += D[r * w + c] * double(in[static_cast<std::size_t>(base + c)]);
      out[static_cast<std::size_t>(base + r)] = static_cast<T>(acc);
    }
  }
}
} // namespace

void Rotation::apply(std::span<const double> in, std::span<double> out) const {
  apply_impl<double>(order_, matrices_, &Rotation::band_offset, in, out);
}

void Rotation::apply(std::span<const float> in, std::span<float> out) const {
  apply_impl<float>(order_, matrices_, &Rotation::band_offset, in, out);
}

double Rotation::band_matrix(int l, int m_row, int m_col) const {
  PRT_SH_REQUIRE(l >= 0 && l < order_, show(l, order_));
  PRT_SH_REQUIRE(m_row >= -l && m_row <= l && m_col >= -l && m_col <= l,
                 show(m_row, m_col) + " for l = " + std::to_string(l));
  const int w = 2 * l + 1;
  return matrices_[static_cast<std::size_t>(band_offset(l) + (m_row + l) * w + (m_col + l))];
}

} // namespace prt::sh
