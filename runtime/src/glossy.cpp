// glossy.cpp — glossy shading from visibility transfer or shadowed radiance (prtshade/glossy.h).
#include <prtshade/glossy.h>
#include <prtshade/quadrature.h>
#include <prtshade/sh.h>

#include "check.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <span>
#include <string>

namespace prt::shade {

namespace {

int band_of(int i) { return int(std::sqrt(double(i))); }

static_assert(kMaxShadowedOrder == sh::kMaxOrder, "route B takes every order of the SH basis");

// Whether real SH of orders m_i, m_j (signed) can give a non-zero Gaunt coefficient with m_k:
// |m_k| ∈ {|m_i| + |m_j|, ||m_i| − |m_j||} and the sign rule of the real basis (sin·sin and
// cos·cos make cos, sin·cos makes sin: the number of negative m is even).
bool m_rule(int mi, int mj, int mk) {
  const int a = std::abs(mi), b = std::abs(mj), c = std::abs(mk);
  if (c != a + b && c != std::abs(a - b)) return false;
  const int negatives = (mi < 0) + (mj < 0) + (mk < 0);
  return negatives % 2 == 0;
}

} // namespace

void clamped_power_moments(double s, int order, double* out) {
  PRT_SHADE_REQUIRE(s >= 0 && std::isfinite(s), "the exponent must be finite and >= 0");
  PRT_SHADE_REQUIRE(order >= 0 && (order == 0 || out), "order must be >= 0 and out non-null");
  for (int l = 0; l < order; ++l) {
    if (l == 0) out[0] = 1.0 / (s + 1.0);
    else if (l == 1) out[1] = 1.0 / (s + 2.0);
    else out[l] = out[l - 2] * (s - double(l - 2)) / (s + double(l - 2) + 3.0);
  }
}

void phong_band_scales(double s, int order, double* out) {
  clamped_power_moments(s, order, out);
  for (int l = 0; l < order; ++l) out[l] *= s + 1.0;
}

void ggx_band_scales(double alpha, int order, double* out) {
  PRT_SHADE_REQUIRE(alpha >= 1e-4 && alpha <= 1, "the GGX roughness alpha must be in [1e-4, 1]");
  PRT_SHADE_REQUIRE(order >= 0 && (order == 0 || out), "order must be >= 0 and out non-null");
  if (order == 0) return;
  std::vector<double> x, w, acc(size_t(order), 0.0), P(size_t(order), 0.0);
  constexpr int kNodes = 24;
  const double a2 = alpha * alpha, c = 1 - a2;
  // In u = 1 − ξ: μ = u / (α² + c u), cos θ_ω = 2μ − 1 = (u(1 + α²) − α²) / (α² + c u), with the
  // pole at u = −α²/c < 0. Pieces [½, 1], [¼, ½], … each at least its own length from the pole
  // (so the rule converges like 5.8^(−2·24)), then [0, ε] with ε < α² 2⁻¹⁰, far shorter than its
  // distance α²/c to the pole.
  auto integrate = [&](double lo, double hi) {
    gauss_legendre(kNodes, lo, hi, x, w);
    for (size_t q = 0; q < x.size(); ++q) {
      const double u = x[q], t = (u * (1 + a2) - a2) / (a2 + c * u);
      P[0] = 1;
      if (order > 1) P[1] = t;
      for (int l = 2; l < order; ++l) P[size_t(l)] = ((2 * l - 1) * t * P[size_t(l - 1)] - (l - 1) * P[size_t(l - 2)]) / l;
      for (size_t l = 0; l < P.size(); ++l) acc[l] += w[q] * P[l];
    }
  };
  double hi = 1;
  for (; hi >= std::ldexp(a2, -10); hi *= 0.5) integrate(hi * 0.5, hi);
  integrate(0, hi);
  std::copy(acc.begin(), acc.end(), out);
}

double ggx_equivalent_phong_exponent(double alpha) {
  double l[2];
  ggx_band_scales(alpha, 2, l);
  return std::max(0.0, (2 * l[1] - 1) / (1 - l[1]));
}

TripleProduct::TripleProduct(int order) : order_(order) {
  PRT_SHADE_REQUIRE(order >= 1 && order <= kMaxGlossyOrder, "order must be in [1, " + std::to_string(kMaxGlossyOrder) + "]");
  const int n = order * order;
  const int nt = (3 * order - 1) / 2, np = 3 * order - 2;  // ⌈(3L−2)/2⌉ and 3L−2 nodes
  std::vector<double> ct, wt;
  gauss_legendre(nt, -1.0, 1.0, ct, wt);
  const size_t nodes = size_t(nt) * size_t(np);
  std::vector<double> Y(nodes * size_t(n)), W(nodes);
  for (int a = 0; a < nt; ++a)
    for (int b = 0; b < np; ++b) {
      const double phi = 2 * std::numbers::pi * b / np, st = std::sqrt(std::max(0.0, 1 - ct[size_t(a)] * ct[size_t(a)]));
      const size_t q = size_t(a) * size_t(np) + size_t(b);
      sh::eval(order, st * std::cos(phi), st * std::sin(phi), ct[size_t(a)], std::span<double>(&Y[q * size_t(n)], size_t(n)));
      W[q] = wt[size_t(a)] * 2 * std::numbers::pi / np;
    }
  for (int k = 0; k < n; ++k) {
    const int lk = band_of(k), mk = k - lk * (lk + 1);
    for (int i = 0; i < n; ++i) {
      const int li = band_of(i), mi = i - li * (li + 1);
      for (int j = i; j < n; ++j) {
        const int lj = band_of(j), mj = j - lj * (lj + 1);
        if (lk < std::abs(li - lj) || lk > li + lj || (li + lj + lk) % 2 != 0 || !m_rule(mi, mj, mk)) continue;
        double g = 0;
        for (size_t q = 0; q < nodes; ++q) {
          const double* y = &Y[q * size_t(n)];
          g += W[q] * y[i] * y[j] * y[k];
        }
        if (std::abs(g) > 1e-12) entries_.push_back({uint16_t(i), uint16_t(j), uint16_t(k), g});
      }
    }
  }
}

void TripleProduct::multiply(const float* a, const float* b, float* out) const {
  const int n = order_ * order_;
  size_t e = 0;
  for (int k = 0; k < n; ++k) {
    double acc = 0;
    for (; e < entries_.size() && entries_[e].k == k; ++e) {
      const Entry& t = entries_[e];
      acc += t.i == t.j ? t.gamma * double(a[t.i]) * double(b[t.i])
                        : t.gamma * (double(a[t.i]) * double(b[t.j]) + double(a[t.j]) * double(b[t.i]));
    }
    out[k] = float(acc);
  }
}

void shade_glossy_radiance(const float* shadowed, int order, const double* scales, const float r[3], float out[3]) {
  float y[kMaxShadowedOrder * kMaxShadowedOrder];
  const int n = order * order;
  sh::eval(order, r[0], r[1], r[2], std::span<float>(y, size_t(n)));
  for (int c = 0; c < 3; ++c) {
    double acc = 0;
    for (int l = 0; l < order; ++l)
      for (int i = l * l; i < (l + 1) * (l + 1); ++i) acc += scales[l] * double(shadowed[c * n + i]) * double(y[i]);
    out[c] = float(acc);
  }
}

void shade_glossy(const TripleProduct& tp, const float* light, const float* visibility, const double* scales,
                  const float r[3], float out[3]) {
  const int n = tp.order() * tp.order();
  float S[3 * kMaxGlossyOrder * kMaxGlossyOrder];
  for (int c = 0; c < 3; ++c) tp.multiply(light + c * n, visibility, S + c * n);
  shade_glossy_radiance(S, tp.order(), scales, r, out);
}

GlossyLight::GlossyLight(const TripleProduct& tp, const float* light) : order_(tp.order()) {
  PRT_SHADE_REQUIRE(light != nullptr, "light is null");
  const size_t n = size_t(order_) * size_t(order_);
  std::vector<double> m(3 * n * n, 0.0);
  for (size_t c = 0; c < 3; ++c)
    for (const TripleProduct::Entry& e : tp.entries()) {
      // Γ_ijk = Γ_jik: M[j][k] += Γ L_i and, for i ≠ j, M[i][k] += Γ L_j.
      double* mc = &m[c * n * n];
      mc[size_t(e.j) * n + e.k] += e.gamma * double(light[c * n + e.i]);
      if (e.i != e.j) mc[size_t(e.i) * n + e.k] += e.gamma * double(light[c * n + e.j]);
    }
  m_.assign(m.begin(), m.end());
}

void GlossyLight::shadowed_radiance(const float* visibility, float* S) const {
  const size_t n = size_t(order_) * size_t(order_);
  for (size_t c = 0; c < 3; ++c) {
    float* s = S + c * n;
    std::fill(s, s + n, 0.0f);
    const float* mc = &m_[c * n * n];
    for (size_t j = 0; j < n; ++j) {
      const float u = visibility[j];
      const float* row = mc + j * n;
      for (size_t k = 0; k < n; ++k) s[k] += row[k] * u;
    }
  }
}

void reflect(const float n[3], const float v[3], float r[3]) {
  const float d = 2 * (n[0] * v[0] + n[1] * v[1] + n[2] * v[2]);
  for (int c = 0; c < 3; ++c) r[c] = d * n[c] - v[c];
}

namespace {

// The unit reflection of the direction from p to the eye about the unit normal n (n itself when
// the eye is on the vertex).
void view_reflection(const float n[3], const float p[3], const float eye[3], float r[3]) {
  float to_eye[3] = {eye[0] - p[0], eye[1] - p[1], eye[2] - p[2]};
  const float len = std::sqrt(to_eye[0] * to_eye[0] + to_eye[1] * to_eye[1] + to_eye[2] * to_eye[2]);
  for (float& c : to_eye) c = len > 0 ? c / len : 0.0f;
  reflect(n, to_eye, r);
  const float rl = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
  for (int c = 0; c < 3; ++c) r[c] = rl > 0 ? r[c] / rl : n[c];  // n: the eye on the vertex
}

} // namespace

void shade_glossy_vertices(const GlossyLight& light, const float* visibility, const float* normals,
                           const float* positions, std::size_t count, const float eye[3], double phong_exponent,
                           float* out) {
  PRT_SHADE_REQUIRE(count == 0 || (visibility && normals && positions && eye && out), "null pointer");
  PRT_SHADE_REQUIRE(phong_exponent >= 0 && std::isfinite(phong_exponent), "the Phong exponent must be finite and >= 0");
  double scales[kMaxGlossyOrder];
  phong_band_scales(phong_exponent, light.order(), scales);
  const size_t n = size_t(light.order()) * size_t(light.order());
  float S[3 * kMaxGlossyOrder * kMaxGlossyOrder];
  for (size_t v = 0; v < count; ++v) {
    float r[3];
    view_reflection(normals + 3 * v, positions + 3 * v, eye, r);
    light.shadowed_radiance(visibility + n * v, S);
    shade_glossy_radiance(S, light.order(), scales, r, out + 3 * v);
  }
}

void shade_glossy_radiance_vertices(const float* shadowed, int order, const float* normals, const float* positions,
                                    std::size_t count, const float eye[3], double phong_exponent, float* out) {
  PRT_SHADE_REQUIRE(count == 0 || (shadowed && normals && positions && eye && out), "null pointer");
  PRT_SHADE_REQUIRE(order >= 1 && order <= kMaxShadowedOrder,
                    "order must be in [1, " + std::to_string(kMaxShadowedOrder) + "]");
  PRT_SHADE_REQUIRE(phong_exponent >= 0 && std::isfinite(phong_exponent), "the Phong exponent must be finite and >= 0");
  double scales[kMaxShadowedOrder];
  phong_band_scales(phong_exponent, order, scales);
  const size_t row = 3 * size_t(order) * size_t(order);
  for (size_t v = 0; v < count; ++v) {
    float r[3];
    view_reflection(normals + 3 * v, positions + 3 * v, eye, r);
    shade_glossy_radiance(shadowed + row * v, order, scales, r, out + 3 * v);
  }
}

} // namespace prt::shade
