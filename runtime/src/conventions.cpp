// conventions.cpp — engine SH conventions; the conventions and their sources are in
// prtshade/conventions.h.
#include <prtshade/conventions.h>

#include <prtshade/sh.h>

#include <cmath>

namespace prt::conventions {
namespace {

constexpr double kPi = 3.14159265358979323846264338327950288;

constexpr int band_of(int i) noexcept { return i == 0 ? 0 : i < 4 ? 1 : 2; }

} // namespace

const Sh9& basis_constants() noexcept {
  static const Sh9 k = [] {
    const double k0 = std::sqrt(1 / (4 * kPi)), k1 = std::sqrt(3 / (4 * kPi)), k2 = std::sqrt(15 / (4 * kPi));
    const double k20 = std::sqrt(5 / (16 * kPi)), k22 = std::sqrt(15 / (16 * kPi));
    return Sh9{k0, -k1, k1, -k1, k2, -k2, k20, -k2, k22};
  }();
  return k;
}

double clamped_cosine_band(int l) noexcept { return l == 0 ? kPi : l == 1 ? 2 * kPi / 3 : l == 2 ? kPi / 4 : 0.0; }

Mat3 engine_from_file(Engine engine, UpAxis up) noexcept {
  // Z-up files turn Y-up first: (x, y, z) ↦ (x, z, −y).
  Mat3 m = up == UpAxis::Z ? Mat3{{{1, 0, 0}, {0, 0, 1}, {0, -1, 0}}} : Mat3{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  if (engine == Engine::Unity)
    for (double& v : m[0]) v = 0.0 - v;  // left-handed: mirror X (0 − 0 = +0)
  return m;
}

Sh9 change_frame(const Sh9& f, const Mat3& M) {
  const double det = M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) -
                     M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
                     M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0]);
  // A mirror M = −R: f(M⁻¹ d) = h(R⁻¹ d) with h(ω) = f(−ω), whose band l is (−1)^l f's.
  const double s = det < 0 ? -1.0 : 1.0;
  double R[3][3];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R[r][c] = s * M[size_t(r)][size_t(c)];
  Sh9 h = f;
  if (s < 0)
    for (int i = 1; i < 4; ++i) h[size_t(i)] = -h[size_t(i)];
  Sh9 out{};
  sh::Rotation(R, 3).apply(h, out);
  return out;
}

RgbSh9 radiance_from_band1(const std::array<float, 9>& band1) noexcept {
  RgbSh9 out{};
  for (size_t c = 0; c < 3; ++c)
    for (size_t m = 0; m < 3; ++m) out[c][1 + m] = 2.0 * double(band1[c * 3 + m]);
  return out;
}

EngineSh to_engine(Engine engine, UpAxis up, const RgbSh9& radiance) {
  const Mat3 M = engine_from_file(engine, up);
  const Sh9& k = basis_constants();
  EngineSh out{};
  for (size_t c = 0; c < 3; ++c) {
    const Sh9 L = change_frame(radiance[c], M);
    for (size_t i = 0; i < 9; ++i) {
      if (engine == Engine::Godot)  // radiance / π in the basis without the CS phase; [9][RGB]
        out[i * 3 + c] = std::copysign(1.0, k[i]) * L[i] / kPi;
      else  // Â_l/π · k_i · L_i: the coefficients of the polynomials p_i
        out[engine == Engine::Unity ? c * 9 + i : i * 3 + c] = clamped_cosine_band(band_of(int(i))) / kPi * k[i] * L[i];
    }
  }
  return out;
}

double irradiance_over_pi(const Sh9& c, double x, double y, double z) {
  double y9[9];
  sh::eval(3, x, y, z, y9);
  double e = 0;
  for (int i = 0; i < 9; ++i) e += clamped_cosine_band(band_of(i)) * c[size_t(i)] * y9[i];
  return e / kPi;
}

} // namespace prt::conventions
