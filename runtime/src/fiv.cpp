// fiv.cpp — FIV run-time shading (paper 004 §4.3); conventions in prtshade/fiv.h.
#include <prtshade/fiv.h>

#include "check.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <string>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <cpuid.h>
#include <immintrin.h>  // _mm_cvtph_ps, used only in a function compiled for F16C (decode_stencil_f16c)
#endif

namespace prt::shade {
namespace {

constexpr double kPi = 3.14159265358979323846264338327950288;
constexpr float kPiF = 3.14159265358979323846f;
constexpr float kTwoPiF = 6.28318530717958647692f;
constexpr float kHalfPiF = 1.57079632679489661923f;

// atan2(y, x) in (−π, π] (atan2(0, 0) = 0) by the odd polynomial of Abramowitz & Stegun 4.4.49
// on [0, 1] (|error| <= 2e-8 rad, plus float rounding) and the octant reduction: the shader
// mirrors' prt_atan2 (runtime/shaders/fiv.inc), here without branches. shade_fiv takes its angles
// from it (glibc's atan2f was a quarter of shade_fiv's time); the slow reference keeps std::atan2.
inline float poly_atan2(float y, float x) {
  const float ax = std::fabs(x), ay = std::fabs(y);
  const float mx = std::max(ax, ay), mn = std::min(ax, ay);
  const float a = mn / (mx > 0 ? mx : 1.0f);  // the divisor selected, not the quotient: a division
  const float a2 = a * a;                      // under a condition would keep loops from vectorising
  float q = 0.0028662257f;
  q = q * a2 - 0.0161657367f;
  q = q * a2 + 0.0429096138f;
  q = q * a2 - 0.0752896400f;
  q = q * a2 + 0.1065626393f;
  q = q * a2 - 0.1420889944f;
  q = q * a2 + 0.1999355085f;
  q = q * a2 - 0.3333314528f;
  q = q * a2 + 1.0f;
  float r = a * q;
  r = ay > ax ? kHalfPiF - r : r;
  r = x < 0 ? kPiF - r : r;
  return y < 0 ? -r : r;
}

// Clamp that maps NaN to lo (fmax/fmin ignore a NaN operand), so a float-to-int conversion after
// it is always defined.
// Written as selects (not fmin/fmax calls) so that loops over it vectorise.
inline float clamp_nan_safe(float x, float lo, float hi) {
  const float above = x >= lo ? x : lo;
  return above <= hi ? above : hi;
}

// Bilinear coordinate of one face axis: texel centres at 2(q + ½)/S − 1, clamped to the outer ones.
inline void face_coordinate(float s, int size, int& q0, int& q1, float& f) {
  const float q = clamp_nan_safe((s + 1.0f) * 0.5f * float(size) - 0.5f, 0.0f, float(size - 1));
  q0 = std::min(int(q), size - 1);
  q1 = std::min(q0 + 1, size - 1);
  f = q - float(q0);
}

// Offset of sample (k, i, j) in [n_rho][n_theta][n_phi].
inline size_t sample_index(const FivOccluder& o, int k, int i, int j) {
  return (size_t(k) * size_t(o.n_theta) + size_t(i)) * size_t(o.n_phi) + size_t(j);
}

// Per-channel n·F_c for an FIV [RGB][xyz].
inline void project_fiv(const float f[9], const float n[3], float out[3]) {
  for (int c = 0; c < 3; ++c) out[c] = n[0] * f[3 * c] + n[1] * f[3 * c + 1] + n[2] * f[3 * c + 2];
}

// The receiver's normal as a unit vector (header "Numerics"): n / |n| with |n| formed in double
// (no overflow or underflow for any finite float n); a zero or non-finite n is +Y, the direction
// lookup_difmap gives a zero normal.
struct UnitNormal {
  float v[3];
  explicit UnitNormal(const float n[3]) {
    const double x = n[0], y = n[1], z = n[2];
    const double len = std::sqrt(x * x + y * y + z * z);
    if (len > 0 && std::isfinite(len)) {
      v[0] = float(x / len), v[1] = float(y / len), v[2] = float(z / len);
    } else {
      v[0] = 0, v[1] = 1, v[2] = 0;
    }
  }
};

// Offset s = p − centre in double: finite for any finite p and centre.
inline void offset_from_centre(const FivOccluder& occ, const float p[3], double s[3]) {
  for (int k = 0; k < 3; ++k) s[k] = double(p[k]) - double(occ.centre[k]);
}

// Signed distance of the occluder centre above the receiver's tangent plane (n unit), in double:
// never NaN for finite inputs (in float, centre − p could overflow to ±inf and 0·inf is NaN).
inline float plane_height(const FivOccluder& occ, const float p[3], const float n[3]) {
  double s[3];
  offset_from_centre(occ, p, s);
  return float(-(double(n[0]) * s[0] + double(n[1]) * s[1] + double(n[2]) * s[2]));
}

} // namespace

// ---------------------------------------------------------------------------------------------
// Validation

namespace {
const char* const value_limit_text = ": must be finite with magnitude <= 2^64 (fiv.h \"Numerics\")";
// A float as the shortest text that reads back to it ("3e+38", not 39 digits).
std::string value_text(float x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", double(x));
  return buf;
}
} // namespace

void validate_occluder(const FivOccluder& o) {
  PRT_SHADE_REQUIRE(o.radial_scheme == kFivRadialGeometric || o.radial_scheme == kFivRadialSurface,
                    "occluder radial scheme " + std::to_string(o.radial_scheme) + ": must be 0 (geometric) or 1 (surface)");
  const bool surface = o.radial_scheme == kFivRadialSurface;
  PRT_SHADE_REQUIRE(o.radii != nullptr && (o.shells != nullptr || o.shells_half != nullptr) &&
                        (surface || o.valid != nullptr) && (!surface || o.surface_radius != nullptr),
                    "occluder with a null array");
  PRT_SHADE_REQUIRE(o.shells == nullptr || o.shells_half == nullptr, "occluder with both float and half shells");
  PRT_SHADE_REQUIRE(o.cones == nullptr || o.cones_half == nullptr, "occluder with both a float and a half cone table");
  PRT_SHADE_REQUIRE(o.n_rho >= 1 && o.n_theta >= 2 && o.n_phi >= 1,
                    "occluder grid " + std::to_string(o.n_rho) + "x" + std::to_string(o.n_theta) + "x" +
                        std::to_string(o.n_phi) + " (rho x theta x phi): need n_rho >= 1, n_theta >= 2, n_phi >= 1");
  PRT_SHADE_REQUIRE(int64_t(o.n_rho) * o.n_theta * o.n_phi <= (int64_t(1) << 26),
                    "occluder grid of more than 2^26 samples");
  PRT_SHADE_REQUIRE(std::isfinite(o.centre[0]) && std::isfinite(o.centre[1]) && std::isfinite(o.centre[2]),
                    "occluder centre is not finite");
  PRT_SHADE_REQUIRE(std::isfinite(o.radius) && o.radius > 0,
                    "occluder bounding radius " + std::to_string(o.radius) + ": must be finite and > 0");
  for (int k = 0; k < o.n_rho; ++k) {
    PRT_SHADE_REQUIRE(std::isfinite(o.radii[k]) && o.radii[k] > 0,
                      "shell radius " + std::to_string(k) + " = " + std::to_string(o.radii[k]) + ": must be finite and > 0");
    PRT_SHADE_REQUIRE(k == 0 || o.radii[k] > o.radii[k - 1],
                      "shell radii must increase strictly (radius " + std::to_string(k) + ")");
  }
  const size_t n = sample_index(o, o.n_rho, 0, 0) * 9;
  for (size_t i = 0; i < n; ++i) {
    PRT_SHADE_REQUIRE(o.shells != nullptr || (o.shells_half[i] & 0x7c00u) != 0x7c00u,
                      "shell value " + std::to_string(i) + " (half bits " + std::to_string(o.shells_half[i]) + ") is not finite");
    const float v = o.shells != nullptr ? o.shells[i] : half_to_float(o.shells_half[i]);
    PRT_SHADE_REQUIRE(std::isfinite(v) && std::fabs(v) <= kFivValueLimit,
                      "shell value " + std::to_string(i) + " = " + value_text(v) + value_limit_text);
  }
  if (surface) {
    const size_t directions = size_t(o.n_theta) * size_t(o.n_phi);
    for (size_t i = 0; i < directions; ++i)
      PRT_SHADE_REQUIRE(std::isfinite(o.surface_radius[i]) && o.surface_radius[i] >= 0 &&
                            o.surface_radius[i] <= kFivValueLimit,
                        "surface radius " + std::to_string(i) + " = " + value_text(o.surface_radius[i]) +
                            ": must be finite, >= 0 and <= 2^64");
    // The lookup inverts τ_k = τ_0 g^k in closed form: the offsets must be that grading.
    const int last = o.n_rho - 1;
    for (int k = 1; k < last; ++k) {
      const double expected = double(o.radii[0]) * std::pow(double(o.radii[last]) / o.radii[0], double(k) / last);
      PRT_SHADE_REQUIRE(std::fabs(double(o.radii[k]) - expected) <= 1e-4 * expected,
                        "surface-scheme offset " + std::to_string(k) + " = " + value_text(o.radii[k]) +
                            ": the offsets must grow geometrically (tau_k = tau_0 g^k)");
    }
  }
  if (has_cones(o)) {
    // The bake's rounding; a half table's m and Ω are each rounded by up to 2^-11 of themselves.
    const double kMargin = o.cones != nullptr ? 1.0 + 0x1p-10 : 1.0 + 0x1p-9;
    const size_t samples = sample_index(o, o.n_rho, 0, 0);
    for (size_t i = 0; i < samples; ++i) {
      float v[4];
      for (int e = 0; e < 4; ++e) {
        if (o.cones != nullptr) {
          v[e] = o.cones[4 * i + size_t(e)];
          continue;
        }
        const uint16_t h = o.cones_half[4 * i + size_t(e)];
        PRT_SHADE_REQUIRE((h & 0x7c00u) != 0x7c00u, "cone sample " + std::to_string(i) + " has a non-finite half value");
        v[e] = half_to_float(h);
      }
      const double omega = v[3];
      bool ok = std::isfinite(omega) && omega >= 0 && omega <= 4 * kPi * kMargin;
      for (int e = 0; e < 3 && ok; ++e) ok = std::isfinite(v[e]) && std::fabs(double(v[e])) <= omega * kMargin + 0x1p-20;
      PRT_SHADE_REQUIRE(ok, "cone sample " + std::to_string(i) + " = (" + value_text(v[0]) + ", " + value_text(v[1]) + ", " +
                                value_text(v[2]) + ", " + value_text(v[3]) +
                                "): needs a finite solid angle in [0, 4pi] and |m| components <= it");
    }
  }
}

void validate_difmap(const DifMap& map) {
  PRT_SHADE_REQUIRE(map.texels != nullptr, "DifMap with null texels");
  PRT_SHADE_REQUIRE(map.size >= 1 && map.size <= (1 << 13), "DifMap face size " + std::to_string(map.size) + " outside [1, 8192]");
  const size_t n = size_t(6) * size_t(map.size) * size_t(map.size) * 3;
  for (size_t i = 0; i < n; ++i)
    PRT_SHADE_REQUIRE(std::isfinite(map.texels[i]) && std::fabs(map.texels[i]) <= kFivValueLimit,
                      "DifMap value " + std::to_string(i) + " = " + value_text(map.texels[i]) + value_limit_text);
}

void validate_environment_fiv(const float env_fiv[9]) {
  PRT_SHADE_REQUIRE(env_fiv != nullptr, "environment FIV is null");
  for (int k = 0; k < 9; ++k)
    PRT_SHADE_REQUIRE(std::isfinite(env_fiv[k]) && std::fabs(env_fiv[k]) <= kFivValueLimit,
                      "environment FIV value " + std::to_string(k) + " = " + value_text(env_fiv[k]) + value_limit_text);
}

// ---------------------------------------------------------------------------------------------
// Lookups

void lookup_difmap(const DifMap& map, const float n[3], float out[3]) {
  const float x = n[0], y = n[1], z = n[2];
  const float ax = std::fabs(x), ay = std::fabs(y), az = std::fabs(z);
  int face;
  float s, t, ma;
  if (ax >= ay && ax >= az && ax > 0) {
    ma = ax;
    face = x > 0 ? 0 : 1;
    s = x > 0 ? -z : z;
    t = -y;
  } else if (ay >= az && ay > 0) {
    ma = ay;
    face = y > 0 ? 2 : 3;
    s = x;
    t = y > 0 ? z : -z;
  } else if (az > 0) {
    ma = az;
    face = z > 0 ? 4 : 5;
    s = z > 0 ? x : -x;
    t = -y;
  } else {  // zero (or NaN) normal: +Y, the face centre
    ma = 1, face = 2, s = 0, t = 0;
  }
  s /= ma;
  t /= ma;
  const int S = map.size;
  int q0, q1, r0, r1;
  float fq, fr;
  face_coordinate(s, S, q0, q1, fq);
  face_coordinate(t, S, r0, r1, fr);
  const float* f = map.texels + size_t(face) * size_t(S) * size_t(S) * 3;
  const float* a = f + (size_t(r0) * size_t(S) + size_t(q0)) * 3;
  const float* b = f + (size_t(r0) * size_t(S) + size_t(q1)) * 3;
  const float* c = f + (size_t(r1) * size_t(S) + size_t(q0)) * 3;
  const float* d = f + (size_t(r1) * size_t(S) + size_t(q1)) * 3;
  for (int k = 0; k < 3; ++k) {
    const float top = a[k] + fq * (b[k] - a[k]);
    const float bottom = c[k] + fq * (d[k] - c[k]);
    out[k] = top + fr * (bottom - top);
  }
}

namespace {

// kPolyAngles: θ and φ from poly_atan2 (shade_fiv) instead of std::atan2 (lookup_fiv and the
// slow reference); the two differ by the polynomial's 2e-8 rad and float rounding.
// Grid coordinate along θ (clamped, poles included; last_t = Nθ − 1) and φ (wraps; u == Nφ is
// φ == 2π) of a direction's angles.
inline float theta_coordinate(float theta, float last_t) { return clamp_nan_safe(theta / kPiF * last_t, 0.0f, last_t); }
inline float phi_coordinate(float phi, float n_phi) {
  phi = phi < 0 ? phi + kTwoPiF : phi;
  return clamp_nan_safe(phi / kTwoPiF * n_phi, 0.0f, n_phi);
}

// acc[e] += w · v[e] for the 9 values of an FIV: SSE2 for the first eight where present, the same
// float operations per element either way (so the sums do not depend on it).
inline void add_weighted_fiv(float acc[9], float w, const float* v) {
#if defined(__SSE2__)
  const __m128 wv = _mm_set1_ps(w);
  _mm_storeu_ps(acc, _mm_add_ps(_mm_loadu_ps(acc), _mm_mul_ps(wv, _mm_loadu_ps(v))));
  _mm_storeu_ps(acc + 4, _mm_add_ps(_mm_loadu_ps(acc + 4), _mm_mul_ps(wv, _mm_loadu_ps(v + 4))));
  acc[8] += w * v[8];
#else
  for (int e = 0; e < 9; ++e) acc[e] += w * v[e];
#endif
}

// log2(x) for a positive normal float, within 0.09: the bits of x read as an integer are
// 2^23 (e + 127 + m − 1) for x = 2^e m, m ∈ [1, 2), and m − 1 differs from log2 m by at most
// 0.0861. Only estimates a shell bracket that is then checked against the stored offsets.
inline float approx_log2(float x) { return float(std::bit_cast<int32_t>(x)) * (1.0f / 8388608.0f) - 127.0f; }

// The stencil of a lookup at grid coordinates t (θ), u (φ) and distance ρ (header comment): the
// 8 (4 inside the first shell and beyond the last) neighbours' sample indices and trilinear
// weights, ρ linear between the bracketing radii, clamped inside, 1/ρ² falloff outside. Shared by
// the shells (sample_shells) and the cone table (sample_cones), which live on the same grid.
struct ShellStencil {
  size_t rows[2][2];  // [layer][θ ring]: the first sample of the ring
  size_t js[2];       // the two φ columns
  float wk[2], wi[2], wj[2];
  int layers;         // 1 inside the first shell and beyond the last, else 2
  float falloff;
  size_t index(int a, int b, int c) const { return rows[a][b] + js[c]; }
  float weight(int a, int b, int c) const { return wk[a] * wi[b] * wj[c]; }
};

// The surface scheme's stencil (header comment "Surface-following shells") at grid coordinates
// t (θ) and u (φ) and distance ρ: r_s bilinear, τ = ρ − r_s, the bracket of τ by the closed-form
// inverse of the grading; clamped inside the first shell, (r_s + τ_last)²/ρ² falloff beyond the
// last. Its samples are all valid (extrapolated at bake time): sample_table uses no mask for it.
void surface_stencil(const FivOccluder& occ, float t, float u, double rho, ShellStencil& st) {
  const int i0 = std::min(int(t), occ.n_theta - 2);
  const float ft = t - float(i0);
  const int ju = std::min(int(u), occ.n_phi);
  const float fu = u - float(ju);
  const int j0 = ju % occ.n_phi, j1 = (ju + 1) % occ.n_phi;
  const size_t np = size_t(occ.n_phi);
  const float* rs0 = occ.surface_radius + size_t(i0) * np;
  const float* rs1 = rs0 + np;
  st.wi[0] = 1 - ft, st.wi[1] = ft, st.wj[0] = 1 - fu, st.wj[1] = fu;
  const float r_s = st.wi[0] * (st.wj[0] * rs0[j0] + st.wj[1] * rs0[j1]) + st.wi[1] * (st.wj[0] * rs1[j0] + st.wj[1] * rs1[j1]);
  const double tau = rho - double(r_s);
  const float* tk = occ.radii;
  const int last = occ.n_rho - 1;
  int k0 = 0, k1 = 0;
  float fr = 0, falloff = 1;
  if (!(tau > tk[0]) || last == 0) {  // inside the first shell (NaN too): clamped
    if (last == 0 && tau > tk[0]) falloff = float(((double(r_s) + tk[0]) / rho) * ((double(r_s) + tk[0]) / rho));
  } else if (tau >= tk[last]) {
    k0 = k1 = last;
    const double q = (double(r_s) + tk[last]) / rho;
    falloff = float(q * q);
  } else {
    // τ_k = τ_0 g^k: k = log2(τ/τ_0) / log2(g), log2 g = log2(τ_last/τ_0) / last, each log2 within
    // 0.09 (approx_log2); then the bracket moved against the stored offsets, a step or two at most
    // unless g is within a few percent of 1.
    const float log2_first = approx_log2(tk[0]);
    const float kf = (approx_log2(float(tau)) - log2_first) * float(last) / (approx_log2(tk[last]) - log2_first);
    k0 = int(clamp_nan_safe(kf, 0.0f, float(last - 1)));  // clamped as a float: the int conversion is defined
    while (k0 > 0 && tau < tk[k0]) --k0;
    while (k0 < last - 1 && tau >= tk[k0 + 1]) ++k0;
    k1 = k0 + 1;
    fr = clamp_nan_safe(float((tau - tk[k0]) / (double(tk[k1]) - tk[k0])), 0.0f, 1.0f);
  }
  st.wk[0] = 1 - fr, st.wk[1] = fr;
  const size_t nt = size_t(occ.n_theta);
  st.rows[0][0] = (size_t(k0) * nt + size_t(i0)) * np, st.rows[0][1] = (size_t(k0) * nt + size_t(i0) + 1) * np;
  st.rows[1][0] = (size_t(k1) * nt + size_t(i0)) * np, st.rows[1][1] = (size_t(k1) * nt + size_t(i0) + 1) * np;
  st.js[0] = size_t(j0), st.js[1] = size_t(j1);
  st.layers = k1 == k0 ? 1 : 2;
  st.falloff = falloff;
}

void shell_stencil(const FivOccluder& occ, float t, float u, double rho, ShellStencil& st) {
  if (occ.radial_scheme == kFivRadialSurface) {
    surface_stencil(occ, t, u, rho, st);
    return;
  }
  const int i0 = std::min(int(t), occ.n_theta - 2);
  const float ft = t - float(i0);
  const int ju = std::min(int(u), occ.n_phi);
  const float fu = u - float(ju);
  const int j0 = ju % occ.n_phi, j1 = (ju + 1) % occ.n_phi;
  const int last = occ.n_rho - 1;
  int k0 = 0, k1 = 0;
  float fr = 0, falloff = 1;
  if (rho <= occ.radii[0] || last == 0) {
    if (last == 0 && rho > occ.radii[0]) falloff = float((occ.radii[0] / rho) * (occ.radii[0] / rho));
  } else if (rho >= occ.radii[last]) {
    k0 = k1 = last;
    falloff = float((occ.radii[last] / rho) * (occ.radii[last] / rho));
  } else {
    // The last radius <= ρ by a search without data-dependent branches (the loop runs
    // ceil(log2 Nρ) times for every lookup), then k1 = k0 + 1: std::upper_bound's partition.
    const float r = float(rho);
    const float* base = occ.radii;
    for (int len = occ.n_rho; len > 1;) {
      const int half = len / 2;
      base = base[half] <= r ? base + half : base;
      len -= half;
    }
    k1 = std::clamp(int(base - occ.radii) + 1, 1, last);
    k0 = k1 - 1;
    fr = clamp_nan_safe(float((rho - occ.radii[k0]) / (double(occ.radii[k1]) - occ.radii[k0])), 0.0f, 1.0f);
  }

  st.wk[0] = 1 - fr, st.wk[1] = fr, st.wi[0] = 1 - ft, st.wi[1] = ft, st.wj[0] = 1 - fu, st.wj[1] = fu;
  // Sample (k, i, j) sits at row (k Nθ + i) Nφ + j; rows of the two layers and two θ rings.
  const size_t nt = size_t(occ.n_theta), np = size_t(occ.n_phi);
  st.rows[0][0] = (size_t(k0) * nt + size_t(i0)) * np, st.rows[0][1] = (size_t(k0) * nt + size_t(i0) + 1) * np;
  st.rows[1][0] = (size_t(k1) * nt + size_t(i0)) * np, st.rows[1][1] = (size_t(k1) * nt + size_t(i0) + 1) * np;
  st.js[0] = size_t(j0), st.js[1] = size_t(j1);
  // Inside the first shell and beyond the last, k0 == k1 and fr == 0: the second layer's weights
  // are 0 and skipping it changes no bit.
  st.layers = k1 == k0 ? 1 : 2;
  st.falloff = falloff;
}

#if defined(__SSE2__)
// half_to_float of four halves in the low 16 bits of x's lanes: the same formula, lane by lane.
inline __m128 halves_to_floats(__m128i x) {
  const __m128i sign = _mm_slli_epi32(_mm_and_si128(x, _mm_set1_epi32(0x8000)), 16);
  const __m128i normal = _mm_or_si128(
      _mm_add_epi32(_mm_slli_epi32(_mm_and_si128(x, _mm_set1_epi32(0x7fff)), 13), _mm_set1_epi32(112 << 23)), sign);
  // m·2^-24 with the sign bit: ±0 for m = 0, as −subnormal is.
  const __m128 subnormal = _mm_or_ps(_mm_mul_ps(_mm_cvtepi32_ps(_mm_and_si128(x, _mm_set1_epi32(0x3ff))),
                                                _mm_set1_ps(0x1p-24f)),
                                     _mm_castsi128_ps(sign));
  const __m128 is_normal =
      _mm_castsi128_ps(_mm_cmpgt_epi32(_mm_and_si128(x, _mm_set1_epi32(0x7c00)), _mm_setzero_si128()));
  return _mm_or_ps(_mm_and_ps(is_normal, _mm_castsi128_ps(normal)), _mm_andnot_ps(is_normal, subnormal));
}
#endif
// The kWidth values of the half-float sample at `p` decoded into `buf` with SSE2 (header
// "Half-float tables": exact, so everything after is the float path's arithmetic).
template <int kWidth> inline const float* sample_values(const uint16_t* p, float* buf) {
  int e = 0;
#if defined(__SSE2__)
  if constexpr (kWidth >= 8) {  // 8 halves (16 bytes of the sample) at once
    const __m128i h = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p));
    _mm_storeu_ps(buf, halves_to_floats(_mm_unpacklo_epi16(h, _mm_setzero_si128())));
    _mm_storeu_ps(buf + 4, halves_to_floats(_mm_unpackhi_epi16(h, _mm_setzero_si128())));
    if constexpr (kWidth == 9) _mm_store_ss(buf + 8, halves_to_floats(_mm_cvtsi32_si128(p[8])));
    e = kWidth == 9 ? 9 : 8;
  } else if constexpr (kWidth == 4) {  // the cone table's 4 halves (8 bytes)
    const __m128i h = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(p));
    _mm_storeu_ps(buf, halves_to_floats(_mm_unpacklo_epi16(h, _mm_setzero_si128())));
    e = 4;
  }
#endif
  for (; e < kWidth; ++e) buf[e] = half_to_float(p[e]);
  return buf;
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
// The stencil's samples decoded with F16C's vcvtph2ps (the same exact values as half_to_float),
// where the CPU has it (every x86-64 CPU since 2012; checked once at run time, so the library
// needs nothing beyond x86-64's SSE2).
#define PRT_FIV_F16C 1
template <int kWidth>
__attribute__((target("f16c"))) void decode_stencil_f16c(const uint16_t* table, const ShellStencil& st,
                                                         float (*out)[kWidth]) {
  for (int a = 0; a < st.layers; ++a)
    for (int b = 0; b < 2; ++b)
      for (int c = 0; c < 2; ++c) {
        const uint16_t* p = table + st.index(a, b, c) * kWidth;
        float* o = out[(a * 2 + b) * 2 + c];
        if constexpr (kWidth >= 8) {
          const __m128i h = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p));
          _mm_storeu_ps(o, _mm_cvtph_ps(h));
          _mm_storeu_ps(o + 4, _mm_cvtph_ps(_mm_srli_si128(h, 8)));
          for (int e = 8; e < kWidth; ++e) o[e] = _mm_cvtss_f32(_mm_cvtph_ps(_mm_cvtsi32_si128(p[e])));
        } else {
          static_assert(kWidth == 4);
          _mm_storeu_ps(o, _mm_cvtph_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p))));
        }
      }
}
// Whether this CPU has F16C and the OS enables the VEX encoding it uses (CPUID.1:ECX F16C, AVX and
// OSXSAVE; XCR0 saves the XMM and YMM state), asked once. (By CPUID, not __builtin_cpu_supports:
// clang 14 does not know "f16c".)
bool has_f16c() {
  static const bool yes = [] {
    unsigned eax = 0, ebx = 0, ecx = 0, edx = 0;
    if (__get_cpuid(1, &eax, &ebx, &ecx, &edx) == 0) return false;
    constexpr unsigned kF16c = 1u << 29, kAvx = 1u << 28, kOsxsave = 1u << 27;
    if ((ecx & (kF16c | kAvx | kOsxsave)) != (kF16c | kAvx | kOsxsave)) return false;
    unsigned xcr0_lo = 0, xcr0_hi = 0;
    __asm__("xgetbv" : "=a"(xcr0_lo), "=d"(xcr0_hi) : "c"(0));
    return (xcr0_lo & 6u) == 6u;
  }();
  return yes;
}
#endif

// The kWidth floats of each stencil corner (a, b, c) at corner[(a·2 + b)·2 + c]: a float table's
// own samples, or a half table's decoded into `decoded` (exact: header "Half-float tables").
template <int kWidth>
void stencil_samples(const float* table, const ShellStencil& st, float (*)[kWidth], const float* corner[8]) {
  for (int a = 0; a < st.layers; ++a)
    for (int b = 0; b < 2; ++b)
      for (int c = 0; c < 2; ++c) corner[(a * 2 + b) * 2 + c] = table + st.index(a, b, c) * kWidth;
}
template <int kWidth>
void stencil_samples(const uint16_t* table, const ShellStencil& st, float (*decoded)[kWidth], const float* corner[8]) {
#if defined(PRT_FIV_F16C)
  if (has_f16c()) {
    decode_stencil_f16c<kWidth>(table, st, decoded);
  } else
#endif
  {
    for (int a = 0; a < st.layers; ++a)
      for (int b = 0; b < 2; ++b)
        for (int c = 0; c < 2; ++c)
          sample_values<kWidth>(table + st.index(a, b, c) * kWidth, decoded[(a * 2 + b) * 2 + c]);
  }
  for (int k = 0; k < 4 * st.layers; ++k) corner[k] = decoded[k];
}

// The masked trilinear value of a table of kWidth values per sample (float, or half bits) over a
// stencil: neighbours with valid == 0 at weight 0 and the rest renormalised; the plain trilinear
// value only when no valid neighbour carries weight (so it is summed only then); times the falloff.
template <int kWidth, class T>
void sample_table(const FivOccluder& occ, const ShellStencil& st, const T* table, float out[kWidth]) {
  float decoded[8][kWidth];
  const float* corner[8];
  stencil_samples<kWidth>(table, st, decoded, corner);
  float masked[kWidth] = {};
  float masked_weight = 0;
  if (occ.radial_scheme != kFivRadialSurface)  // the surface scheme's samples are all valid: plain trilinear
  for (int a = 0; a < st.layers; ++a)
    for (int b = 0; b < 2; ++b)
      for (int c = 0; c < 2; ++c) {
        const size_t idx = st.index(a, b, c);
        if (occ.valid[idx] == 0) continue;
        const float w = st.weight(a, b, c);
        masked_weight += w;
        const float* v = corner[(a * 2 + b) * 2 + c];
        if constexpr (kWidth == 9) {
          add_weighted_fiv(masked, w, v);
        } else {
          for (int e = 0; e < kWidth; ++e) masked[e] += w * v[e];
        }
      }
  if (masked_weight > 0) {
    const float inv = 1.0f / masked_weight;
    for (int e = 0; e < kWidth; ++e) out[e] = masked[e] * inv * st.falloff;
    return;
  }
  float plain[kWidth] = {};
  for (int a = 0; a < st.layers; ++a)
    for (int b = 0; b < 2; ++b)
      for (int c = 0; c < 2; ++c) {
        const float w = st.weight(a, b, c);
        const float* v = corner[(a * 2 + b) * 2 + c];
        if constexpr (kWidth == 9) {
          add_weighted_fiv(plain, w, v);  // the same float operations per element as the loop
        } else {
          for (int e = 0; e < kWidth; ++e) plain[e] += w * v[e];
        }
      }
  for (int e = 0; e < kWidth; ++e) out[e] = plain[e] * st.falloff;
}

// Prefetches the samples a stencil reads (shells, valid, and the cone table when `cones`): a hint
// only, no value depends on it.
constexpr int kPrefetchBlock = 8;
inline void prefetch_stencil(const FivOccluder& occ, const ShellStencil& st, bool cones) {
#if defined(__GNUC__)
  for (int a = 0; a < st.layers; ++a)
    for (int b = 0; b < 2; ++b) {  // the φ neighbours j0, j1 of a ring
      const size_t i0 = st.index(a, b, 0), i1 = st.index(a, b, 1);
      if (occ.shells != nullptr) {
        __builtin_prefetch(occ.shells + i0 * 9);
        __builtin_prefetch(occ.shells + i0 * 9 + 8);
        __builtin_prefetch(occ.shells + i1 * 9 + 8);
      } else {
        __builtin_prefetch(occ.shells_half + i0 * 9);
        __builtin_prefetch(occ.shells_half + i1 * 9 + 8);
      }
      if (occ.valid) __builtin_prefetch(occ.valid + i0);
      if (cones && occ.cones) {
        __builtin_prefetch(occ.cones + i0 * 4);
        __builtin_prefetch(occ.cones + i1 * 4 + 3);
      } else if (cones && occ.cones_half) {
        __builtin_prefetch(occ.cones_half + i0 * 4);
        __builtin_prefetch(occ.cones_half + i1 * 4 + 3);
      }
    }
#else
  (void)occ, (void)st, (void)cones;
#endif
}

// The trilinear lookup of the shells (header comment) at a stencil.
inline void sample_shells(const FivOccluder& occ, const ShellStencil& st, float out[9]) {
  if (occ.shells != nullptr) sample_table<9>(occ, st, occ.shells, out);
  else sample_table<9>(occ, st, occ.shells_half, out);
}
// The cone table (m, Ω) at the same stencil (header "Tight proxies").
inline void sample_cones(const FivOccluder& occ, const ShellStencil& st, float out[4]) {
  if (occ.cones != nullptr) sample_table<4>(occ, st, occ.cones, out);
  else sample_table<4>(occ, st, occ.cones_half, out);
}

// Grid coordinates (t, u) of an offset with the angles from std::atan2 and ρ = |s| (ρ = 0 for a
// zero or NaN offset: d = +Y, θ = 0): lookup_fiv, lookup_cone, occluded_irradiance and the slow
// reference. (shade_fiv forms the same coordinates with poly_atan2 for all its occluders at once.)
void stencil_at(const FivOccluder& occ, const double s[3], ShellStencil& st) {
  // Direction and distance, formed in double: |s| never overflows and d is unit to float precision.
  const double sx = s[0], sy = s[1], sz = s[2];
  double rho = std::sqrt(sx * sx + sy * sy + sz * sz);
  float theta = 0, phi = 0;
  if (rho > 0 && std::isfinite(rho)) {
    const float dx = float(sx / rho), dy = float(sy / rho), dz = float(sz / rho);
    // θ from atan2(|d_xz|, d_y), not acos(d_y): within ~3.5e-4 rad of ±Y, d_y rounds to ±1 in
    // float and acos would snap θ onto the pole (and an invalid pole sample would then take all
    // the weight). The GLSL mirror (runtime/shaders/fiv.glsl) computes θ the same way.
    theta = std::atan2(float(std::sqrt(sx * sx + sz * sz) / rho), dy);
    phi = std::atan2(dx, dz);
  } else {
    rho = 0;  // ρ == 0 (or NaN): d = +Y, θ = 0
  }
  shell_stencil(occ, theta_coordinate(theta, float(occ.n_theta - 1)), phi_coordinate(phi, float(occ.n_phi)), rho, st);
}

// F(s) with the angles from std::atan2 (stencil_at).
void lookup_fiv_at(const FivOccluder& occ, const double s[3], float out[9]) {
  ShellStencil st;
  stencil_at(occ, s, st);
  sample_shells(occ, st, out);
}

// Factor of the case an occluder is in at height h = n·(centre − p) over the receiver's plane:
// case C 0; with partial occluders case A 1 and case B (h + R)/(2R), without them 1.
inline float case_factor(float h, float R, bool partial) {
  if (!(h > -R)) return 0.0f;  // case C
  if (!partial || h >= R) return 1.0f;
  return clamp_nan_safe((h + R) / (2.0f * R), 0.0f, 1.0f);
}

float partial_factor_unit(const FivOccluder& occ, const float p[3], const float n[3]) {
  return case_factor(plane_height(occ, p, n), occ.radius, true);
}

// occluded_irradiance for a unit n.
void occluded_irradiance_unit(const FivOccluder& occ, const float p[3], const float n[3], bool partial, float out[3]) {
  const float factor = case_factor(plane_height(occ, p, n), occ.radius, partial);
  if (factor == 0) {
    out[0] = out[1] = out[2] = 0;
    return;
  }
  double s[3];
  offset_from_centre(occ, p, s);
  float f[9], e[3];
  lookup_fiv_at(occ, s, f);
  project_fiv(f, n, e);
  for (int c = 0; c < 3; ++c) out[c] = std::max(0.0f, factor * e[c]);
}

// shade_fiv_self for a unit n.
void shade_fiv_self_unit(const float env_fiv[9], const FivOccluder& occ, const float p[3], const float n[3], float out[3]) {
  double s[3];
  offset_from_centre(occ, p, s);
  float f[9], occluded[3], total[3];
  lookup_fiv_at(occ, s, f);
  project_fiv(f, n, occluded);
  project_fiv(env_fiv, n, total);
  for (int c = 0; c < 3; ++c) out[c] = std::max(0.0f, total[c] - occluded[c]);
}

// ---------------------------------------------------------------------------------------------
// shade_fiv's fast path, per receiver in four passes:
//   1. per occluder, in double: the offset s = p − centre, the case (A/B/C) and ρ = |s|; occluders
//      in case C are dropped here;
//   2. for all the others at once, in float: the shell coordinates (θ, φ by poly_atan2) and the
//      occluders' discs (axis, α) — a loop over plain arrays, which the compiler vectorises;
//   3. per occluder, the shell samples (prefetched a block ahead), a tight proxy's cone (its disc
//      and partial correction) and I (eq. 10); those that hide nothing are dropped;
//   4. the overlap correction (eq. 13–14): the discs ordered along a tangent by a counting sort of
//      their extents' buckets, each tested four at a time against the later ones whose extent can
//      meet its own (bench/RESULTS.md "Tight FIV proxies"), the O_ij of those that may overlap
//      formed in batches (vectorised), summed per disc in double.

// Lens area of two planar discs of radii r1, r2 whose centres are d apart (lens_area in float):
// r1² θ1 + r2² θ2 − ½√k with the half-angles θ_i = atan2(√k, d² + r_i² − r_j²), the shader
// mirrors' prt_fiv_lens_area. One √k is shared by all terms, so the cancellation at tangency is
// first-order exact: the error stays a few float ε of π min(r)². Branch-free (every case is
// formed, then one is selected) so that a loop over it vectorises.
inline float lens_area_float(float r1, float r2, float d) {
  const float rmin = std::min(r1, r2);
  const float contained = kPiF * rmin * rmin;
  const float k = std::max(0.0f, (-d + r1 + r2) * (d + r1 - r2) * (d - r1 + r2) * (d + r1 + r2));
  const float sk = std::sqrt(k);
  const float area = r1 * r1 * poly_atan2(sk, d * d + r1 * r1 - r2 * r2) +
                     r2 * r2 * poly_atan2(sk, d * d + r2 * r2 - r1 * r1) - 0.5f * sk;
  const float lens = std::min(std::max(area, 0.0f), contained);
  return d >= r1 + r2 ? 0.0f : (d <= std::fabs(r1 - r2) ? contained : lens);
}

// O_ij of eq. 14 for discs of angular radii alpha_i, alpha_j whose axes a, b have a·b = cos_gamma
// and |a×b|² = sin2_gamma; γ = atan2(|a×b|, a·b), accurate for small angles, where acos(a·b)
// loses half the digits.
inline float overlap_float(float alpha_i, float alpha_j, float cos_gamma, float sin2_gamma) {
  const float gamma = poly_atan2(std::sqrt(sin2_gamma), cos_gamma);
  const float denom = kPiF * (alpha_i * alpha_i + alpha_j * alpha_j);
  const float lens = lens_area_float(alpha_i, alpha_j, gamma);
  return denom > 0 ? lens / (denom > 0 ? denom : 1.0f) : 0.0f;
}

// K(x, α) of the header's "Tight proxies" in float with poly_atan2 (acos(q) = atan2(√(1 − q²), q)):
// the fast path's cap_clamped_cosine. x = ν·a, ca = cos α.
inline float cap_clamped_cosine_float(float x, float ca) {
  x = clamp_nan_safe(x, -1.0f, 1.0f), ca = clamp_nan_safe(ca, -1.0f, 1.0f);
  const bool complement = ca < 0;  // α > π/2: π − K(−x, π − α)
  if (complement) x = -x, ca = -ca;
  const float sa2 = (1 - ca) * (1 + ca), sa = std::sqrt(sa2);
  float k;
  if (x >= sa) {
    k = kPiF * x * sa2;
  } else if (x <= -sa) {
    k = 0;
  } else {  // |x| < sa <= 1: sa > 0 and y > 0
    const float y = std::sqrt((1 - x) * (1 + x));
    const float cot = ca / sa;
    const float q = clamp_nan_safe(-cot * x / y, -1.0f, 1.0f);
    const float sq = std::sqrt((1 - q) * (1 + q));
    const float z = y * sq;
    k = std::max(0.0f, (x * poly_atan2(sq, q) - cot * z) * sa2 + poly_atan2(z, cot));
  }
  return complement ? kPiF - k : k;
}

// Four pair tests at once: bit k is set when the disc (x[k], y[k], z[k]) of angular radius α_k
// (cos α_k = c[k], sin α_k = s[k]) may overlap the disc (xi, yi, zi) of radius α_i, i.e. when
// cos γ = a_i·a_k >= cos(α_i + α_k) = ci c[k] − si s[k]. SSE2 (every x86-64) where present, the
// same float operations in the same order otherwise.
inline unsigned disc_pairs_may_overlap(const float* x, const float* y, const float* z, const float* c, const float* s,
                                       float xi, float yi, float zi, float ci, float si) {
#if defined(__SSE2__)
  const __m128 xx = _mm_mul_ps(_mm_set1_ps(xi), _mm_loadu_ps(x));
  const __m128 yy = _mm_mul_ps(_mm_set1_ps(yi), _mm_loadu_ps(y));
  const __m128 zz = _mm_mul_ps(_mm_set1_ps(zi), _mm_loadu_ps(z));
  const __m128 cos_gamma = _mm_add_ps(_mm_add_ps(xx, yy), zz);
  const __m128 cc = _mm_mul_ps(_mm_set1_ps(ci), _mm_loadu_ps(c));
  const __m128 ss = _mm_mul_ps(_mm_set1_ps(si), _mm_loadu_ps(s));
  const __m128 cos_sum = _mm_sub_ps(cc, ss);
  return unsigned(_mm_movemask_ps(_mm_cmpge_ps(cos_gamma, cos_sum)));
#else
  unsigned mask = 0;
  for (int k = 0; k < 4; ++k) mask |= (xi * x[k] + yi * y[k] + zi * z[k] >= ci * c[k] - si * s[k] ? 1u : 0u) << k;
  return mask;
#endif
}

// The per-receiver arrays of the occluders that passed pass 1 ("candidates"), indexed by
// candidate; on the stack up to kStackOccluders occluders, on the heap beyond.
constexpr int kStackOccluders = 128;

struct Candidates {
  enum Field {
    kFactor, kDx, kDy, kDz, kAx, kAy, kAz, kSinAlpha, kLastT, kNPhi, kT, kU, kCosAlpha, kAlpha,  // per candidate
    kI0, kI1, kI2,                                                                              // per candidate
    kPackedAx, kPackedAy, kPackedAz, kPackedCos, kPackedSin, kPackedAlpha, kPackedTight,        // per active disc
    kPackedInvA2,                                                                               // per active disc
    kFields
  };
  static constexpr int kPadding = 4;  // the packed discs are read four at a time
  std::array<float, size_t(kStackOccluders + kPadding) * kFields> stack_floats;
  std::array<double, 2 * kStackOccluders> stack_doubles;
  std::array<int, 6 * kStackOccluders> stack_ints;
  std::vector<float> heap_floats;
  std::vector<double> heap_doubles;
  std::vector<int> heap_ints;
  float* field[kFields];
  double* rho;
  double* weight;  // per active disc: W_i = Σ_j O_ij
  int* index;   // the occluder of candidate c
  int* active;  // the candidates that hide something, in order
  int* lo_bucket;  // per active disc: the buckets of its extent along the sweep's tangent
  int* hi_bucket;  // (indexed by active disc)
  int* at;         // per sweep position: the candidate whose disc sits there
  int* end;        // per sweep position: where that disc's pair tests stop

  explicit Candidates(int count) {
    float* floats = stack_floats.data();
    rho = stack_doubles.data();
    index = stack_ints.data();
    size_t stride = kStackOccluders;
    if (count > kStackOccluders) {
      stride = size_t(count);
      heap_floats.resize((stride + kPadding) * kFields);
      heap_doubles.resize(2 * stride);
      heap_ints.resize(6 * stride);
      floats = heap_floats.data(), rho = heap_doubles.data(), index = heap_ints.data();
    }
    for (int f = 0; f < kFields; ++f) field[f] = floats + size_t(f) * (stride + kPadding);
    active = index + stride;
    lo_bucket = index + 2 * stride, hi_bucket = index + 3 * stride, at = index + 4 * stride, end = index + 5 * stride;
    weight = rho + stride;
  }
  Candidates(const Candidates&) = delete;
  Candidates& operator=(const Candidates&) = delete;
};

// Pairs whose discs may overlap wait in a batch; their O_ij are then formed in one loop over plain
// arrays, which the compiler vectorises, and added in the order they came.
struct PairBatch {
  static constexpr int kSize = 64;
  int count = 0;
  int i[kSize], j[kSize];
  float alpha_i[kSize], alpha_j[kSize], cos_gamma[kSize], sin2_gamma[kSize], o[kSize];

  void overlaps() {
    for (int k = 0; k < count; ++k) o[k] = overlap_float(alpha_i[k], alpha_j[k], cos_gamma[k], sin2_gamma[k]);
  }
};

// prtshade/fiv.h tells engines (fibers, small thread stacks) what shade_fiv keeps on the stack.
static_assert(sizeof(Candidates) + sizeof(PairBatch) <= 22 * 1024, "fiv.h says shade_fiv uses about 22 KB of stack");

// The sweep's buckets over a disc's extent [x − w, x + w] ⊂ [−2.5, 2.5] along a tangent (x in
// [−1, 1], w <= √2 plus a margin), monotone in the coordinate.
constexpr int kSweepBuckets = 64;
constexpr int kSweepMinDiscs = 32;
inline int sweep_bucket(float v) {
  return int(clamp_nan_safe((v + 2.5f) * (float(kSweepBuckets) / 5.0f), 0.0f, float(kSweepBuckets - 1)));
}

// Pass 2 of shade_fiv_fast over the n candidates: shell coordinates t (θ) and u (φ) of the unit
// offsets d, and cos α, α of the discs from sin α. Separate arrays (restrict), so that it vectorises.
void shell_coordinates_and_discs(int n, const float* __restrict dx, const float* __restrict dy, const float* __restrict dz,
                                 const float* __restrict last_t, const float* __restrict n_phi,
                                 const float* __restrict sin_alpha, float* __restrict t, float* __restrict u,
                                 float* __restrict cos_alpha, float* __restrict alpha) {
  for (int k = 0; k < n; ++k) {
    // θ from atan2(|d_xz|, d_y), not acos(d_y) (lookup_fiv_at says why).
    const float theta = poly_atan2(std::sqrt(dx[k] * dx[k] + dz[k] * dz[k]), dy[k]);
    t[k] = theta_coordinate(theta, last_t[k]);
    u[k] = phi_coordinate(poly_atan2(dx[k], dz[k]), n_phi[k]);
    const float c = std::sqrt(std::max(0.0f, (1.0f - sin_alpha[k]) * (1.0f + sin_alpha[k])));
    cos_alpha[k] = c;
    alpha[k] = poly_atan2(sin_alpha[k], c);
  }
}

void shade_fiv_fast(const DifMap& map, const FivOccluder* occluders, int count, const float p[3], const float n_in[3],
                    const FivShadeOptions& options, float out[3]) {
  const UnitNormal unit(n_in);
  const float* n = unit.v;
  // Accumulated in double: with hundreds of occluders and pair terms, float sums would drift by
  // ~count·ε·E_tot; the per-occluder work stays in float.
  float tot[3];
  lookup_difmap(map, n, tot);
  double acc[3] = {tot[0], tot[1], tot[2]};
  Candidates c(count);
  using F = Candidates::Field;
  float* const factor = c.field[F::kFactor];
  float *const dx = c.field[F::kDx], *const dy = c.field[F::kDy], *const dz = c.field[F::kDz];
  float *const ax = c.field[F::kAx], *const ay = c.field[F::kAy], *const az = c.field[F::kAz];
  float *const sin_alpha = c.field[F::kSinAlpha], *const cos_alpha = c.field[F::kCosAlpha];
  float *const alpha = c.field[F::kAlpha];
  float *const last_t = c.field[F::kLastT], *const n_phi = c.field[F::kNPhi];
  float *const t = c.field[F::kT], *const u = c.field[F::kU];
  float* const I[3] = {c.field[F::kI0], c.field[F::kI1], c.field[F::kI2]};

  // The tight proxy's partial correction needs the mean radiance from below, E_tot(−n)/π.
  const bool use_cones = options.proxy == FivProxy::cone;
  float below[3] = {0, 0, 0};
  bool below_looked_up = false;  // looked up at the first tight occluder (a receiver may have none)
  // Pass 1: offset, case and distance in double (finite for any finite input).
  int candidates = 0;
  for (int i = 0; i < count; ++i) {
    const FivOccluder& occ = occluders[i];
    double s[3];
    offset_from_centre(occ, p, s);
    const float h = float(-(double(n[0]) * s[0] + double(n[1]) * s[1] + double(n[2]) * s[2]));
    // A tight occluder's partial correction comes in pass 3; its case C is the sphere's.
    const float f = case_factor(h, occ.radius, options.partial_occluders && !(use_cones && has_cones(occ)));
    if (f == 0) continue;
    const int k = candidates++;
    c.index[k] = i;
    factor[k] = f;
    last_t[k] = float(occ.n_theta - 1);
    n_phi[k] = float(occ.n_phi);
    const double rho = std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    if (rho > 0 && std::isfinite(rho)) {
      const double inv = 1.0 / rho;
      c.rho[k] = rho;
      dx[k] = float(s[0] * inv), dy[k] = float(s[1] * inv), dz[k] = float(s[2] * inv);
      ax[k] = -dx[k], ay[k] = -dy[k], az[k] = -dz[k];  // centre − p = −s
      sin_alpha[k] = float(std::min(1.0, double(occ.radius) * inv));
    } else {  // p at the centre: the lookup's d = +Y; the disc covers the hemisphere around n
      c.rho[k] = 0;
      dx[k] = 0, dy[k] = 1, dz[k] = 0;
      ax[k] = n[0], ay[k] = n[1], az[k] = n[2];
      sin_alpha[k] = 1;
    }
  }
  // Pass 2: shell coordinates and discs for all candidates at once (vectorised).
  shell_coordinates_and_discs(candidates, dx, dy, dz, last_t, n_phi, sin_alpha, t, u, cos_alpha, alpha);
  // Pass 3: shell samples and I; the candidates that hide something become active. In blocks: the
  // block's stencils first, their samples prefetched, then the samples read (the lookups are
  // scattered over megabytes of shells; their cache misses then overlap instead of queueing).
  int active = 0;
  ShellStencil block[kPrefetchBlock];
  for (int k = 0; k < candidates; ++k) {
    const int slot = k % kPrefetchBlock;
    if (slot == 0)
      for (int b = 0; b < kPrefetchBlock && k + b < candidates; ++b) {
        const FivOccluder& o = occluders[c.index[k + b]];
        shell_stencil(o, t[k + b], u[k + b], c.rho[k + b], block[b]);
        prefetch_stencil(o, block[b], use_cones);
      }
    const FivOccluder& occ = occluders[c.index[k]];
    float fv[9], e[3];
    const ShellStencil& st = block[slot];
    sample_shells(occ, st, fv);
    project_fiv(fv, n, e);
    if (use_cones && has_cones(occ)) {
      // The occluder's cone (header "Tight proxies"): axis m/|m| (towards the centre when m = 0).
      float cone[4];
      sample_cones(occ, st, cone);
      const float ml = std::sqrt(cone[0] * cone[0] + cone[1] * cone[1] + cone[2] * cone[2]);
      if (ml > 0) {
        const float inv = 1.0f / ml;
        ax[k] = cone[0] * inv, ay[k] = cone[1] * inv, az[k] = cone[2] * inv;
      }
      const float ca = clamp_nan_safe(1.0f - cone[3] / kTwoPiF, -1.0f, 1.0f);
      if (options.partial_occluders) {
        if (!below_looked_up) {
          const float down[3] = {-n[0], -n[1], -n[2]};
          lookup_difmap(map, down, below);
          for (float& b : below) b /= kPiF;
          below_looked_up = true;
        }
        const float x = n[0] * ax[k] + n[1] * ay[k] + n[2] * az[k];
        const float sa = std::sqrt((1 - ca) * (1 + ca));
        if (ca >= 0 && x <= -sa) {
          e[0] = e[1] = e[2] = 0;  // the cap wholly below the horizon
        } else {
          const float K = cap_clamped_cosine_float(-x, ca);
          for (int ch = 0; ch < 3; ++ch) e[ch] += below[ch] * K;
        }
      }
      // The disc of eq. 13–14: the cap, α clamped to π/2 as the sphere's.
      const float cd = std::max(ca, 0.0f);
      cos_alpha[k] = cd;
      sin_alpha[k] = std::sqrt((1 - cd) * (1 + cd));
      alpha[k] = poly_atan2(sin_alpha[k], cd);
    }
    bool hides = false;
    for (int ch = 0; ch < 3; ++ch) {
      I[ch][k] = std::max(0.0f, factor[k] * e[ch]);
      acc[ch] -= I[ch][k];
      hides = hides || I[ch][k] > 0;
    }
    if (hides) c.active[active++] = k;
  }
  // Pass 4: the overlap correction, Σ_{i<j} O_ij (I_i + I_j) = Σ_i W_i I_i with W_i = Σ_{j≠i} O_ij
  // summed in double.
  if (options.overlap_correction && active > 1) {
    // A sweep along a tangent t of the receiver's plane: disc k covers x = a_k·t ± w_k with
    // w_k = 2 sin(α_k/2) = √(2(1 − cos α_k)) (the chord: |ω·t − a·t| <= |ω − a| for every ω in
    // the disc; with a margin for float rounding). Two discs that overlap have |x_i − x_j| <=
    // |a_i − a_j| = 2 sin(γ/2) < 2 sin((α_i + α_j)/2) <= w_i + w_j (sin is subadditive on [0, π]),
    // so their extents meet. The discs are ordered by the bucket of their left end (a counting
    // sort, no comparisons), and disc i is tested only against the later ones up to the last
    // whose left end's bucket is at most its right end's — every overlapping pair among them.
    // The active discs packed in sweep order, so that the test of one disc against the later ones
    // runs over contiguous arrays (vectorised); end[pos] is where disc pos's tests stop.
    float* const pax = c.field[F::kPackedAx];
    float* const pay = c.field[F::kPackedAy];
    float* const paz = c.field[F::kPackedAz];
    float* const pcos = c.field[F::kPackedCos];
    float* const psin = c.field[F::kPackedSin];
    float* const palpha = c.field[F::kPackedAlpha];
    float* const ptight = c.field[F::kPackedTight];  // 1: a tight proxy (its pairs with others such: the density form)
    float* const pinv = c.field[F::kPackedInvA2];    // 1/α² (0 for α = 0): the density form's I/α² by a product
    int* const end = c.end;
    const auto pack = [&](int pos, int k, int stop) {
      c.at[pos] = k;
      end[pos] = stop;
      pax[pos] = ax[k], pay[pos] = ay[k], paz[pos] = az[k];
      pcos[pos] = cos_alpha[k], psin[pos] = sin_alpha[k], palpha[pos] = alpha[k];
      ptight[pos] = use_cones && has_cones(occluders[c.index[k]]) ? 1.0f : 0.0f;
      pinv[pos] = ptight[pos] != 0 && alpha[k] > 0 ? 1.0f / (alpha[k] * alpha[k]) : 0.0f;
      c.weight[pos] = 0;
    };
    if (active >= kSweepMinDiscs) {
      const int e = std::fabs(n[0]) < std::fabs(n[1]) ? (std::fabs(n[0]) < std::fabs(n[2]) ? 0 : 2)
                                                      : (std::fabs(n[1]) < std::fabs(n[2]) ? 1 : 2);
      float tx = e == 0 ? 0 : (e == 1 ? n[2] : -n[1]), ty = e == 0 ? -n[2] : (e == 1 ? 0 : n[0]),
            tz = e == 0 ? n[1] : (e == 1 ? -n[0] : 0);  // n × (the axis e), ⊥ n
      const float tl = std::sqrt(tx * tx + ty * ty + tz * tz);
      tx /= tl, ty /= tl, tz /= tl;
      int start[kSweepBuckets + 1] = {};
      for (int a = 0; a < active; ++a) {
        const int k = c.active[a];
        const float x = ax[k] * tx + ay[k] * ty + az[k] * tz;
        const float w = std::sqrt(2 * (1 - cos_alpha[k])) * 1.0001f + 1e-4f;
        c.lo_bucket[a] = sweep_bucket(x - w);
        c.hi_bucket[a] = sweep_bucket(x + w);
        ++start[c.lo_bucket[a] + 1];
      }
      for (int b = 0; b < kSweepBuckets; ++b) start[b + 1] += start[b];
      int next[kSweepBuckets];
      std::copy_n(start, kSweepBuckets, next);
      // Each disc's tests stop at the first position whose left end lies in a later bucket than
      // its right end.
      for (int a = 0; a < active; ++a) pack(next[c.lo_bucket[a]]++, c.active[a], start[c.hi_bucket[a] + 1]);
    } else {  // below kSweepMinDiscs the sweep costs more than it saves (bench/RESULTS.md): every pair
      for (int a = 0; a < active; ++a) pack(a, c.active[a], active);
    }
    // Padding that never passes: cos γ = 0 < 4 (cos α_i + sin α_i) <= cos_sum.
    for (int a = active; a < active + Candidates::kPadding; ++a) pax[a] = pay[a] = paz[a] = 0, pcos[a] = 4, psin[a] = -4;
    PairBatch batch;
    // Pairs of two tight proxies add the lens times the lower of the two irradiance densities,
    // O_ij (α_i² + α_j²) min_c(I_i/α_i², I_j/α_j²) (fiv.h "Tight proxies"); the others O_ij (I_i + I_j)
    // as Σ_i W_i I_i.
    double dense[3] = {0, 0, 0};
    const auto flush = [&] {
      batch.overlaps();
      for (int b = 0; b < batch.count; ++b) {
        const int i = batch.i[b], j = batch.j[b];
        if (ptight[i] != 0 && ptight[j] != 0) {
          if (!(pinv[i] > 0 && pinv[j] > 0)) continue;  // a disc of no area: no lens
          const double area = double(batch.o[b]) * (double(palpha[i]) * palpha[i] + double(palpha[j]) * palpha[j]);
          const int ki = c.at[i], kj = c.at[j];
          for (int ch = 0; ch < 3; ++ch)
            dense[ch] += area * std::min(double(I[ch][ki]) * pinv[i], double(I[ch][kj]) * pinv[j]);
          continue;
        }
        c.weight[i] += double(batch.o[b]);
        c.weight[j] += double(batch.o[b]);
      }
      batch.count = 0;
    };
    for (int i = 0; i + 1 < active; ++i) {
      const float xi = pax[i], yi = pay[i], zi = paz[i], ci = pcos[i], si = psin[i];
      for (int j0 = i + 1; j0 < end[i]; j0 += 4) {
        // Disjoint discs (γ >= α_i + α_j, both angles in [0, π/2]) have cos γ < cos(α_i + α_j)
        // and no lens; the few others go to the batch.
        for (unsigned m = disc_pairs_may_overlap(pax + j0, pay + j0, paz + j0, pcos + j0, psin + j0, xi, yi, zi, ci, si);
             m != 0; m &= m - 1) {
          const int j = j0 + std::countr_zero(m);
          const float cx = yi * paz[j] - zi * pay[j];
          const float cy = zi * pax[j] - xi * paz[j];
          const float cz = xi * pay[j] - yi * pax[j];
          const int b = batch.count++;
          batch.i[b] = i, batch.j[b] = j;
          batch.alpha_i[b] = palpha[i], batch.alpha_j[b] = palpha[j];
          batch.cos_gamma[b] = xi * pax[j] + yi * pay[j] + zi * paz[j];
          batch.sin2_gamma[b] = cx * cx + cy * cy + cz * cz;
          if (batch.count == PairBatch::kSize) flush();
        }
      }
    }
    flush();
    for (int pos = 0; pos < active; ++pos)
      for (int ch = 0; ch < 3; ++ch) acc[ch] += c.weight[pos] * double(I[ch][c.at[pos]]);
    for (int ch = 0; ch < 3; ++ch) acc[ch] += dense[ch];
  }
  for (int ch = 0; ch < 3; ++ch) out[ch] = float(std::max(0.0, acc[ch]));
}

} // namespace

void lookup_fiv(const FivOccluder& occ, const float s[3], float out[9]) {
  const double sd[3] = {s[0], s[1], s[2]};
  lookup_fiv_at(occ, sd, out);
}

void halves_to_floats(const uint16_t* halves, float* out, size_t n) {
  size_t i = 0;
  for (; i + 9 <= n; i += 9) sample_values<9>(halves + i, out + i);
  for (; i < n; ++i) out[i] = half_to_float(halves[i]);
}

void lookup_cone(const FivOccluder& occ, const float s[3], float out[4]) {
  const double sd[3] = {s[0], s[1], s[2]};
  ShellStencil st;
  stencil_at(occ, sd, st);
  sample_cones(occ, st, out);
}

double cap_clamped_cosine(double x, double cos_alpha) {
  x = std::clamp(x, -1.0, 1.0), cos_alpha = std::clamp(cos_alpha, -1.0, 1.0);
  if (cos_alpha < 0) return kPi - cap_clamped_cosine(-x, -cos_alpha);
  const double s2 = (1 - cos_alpha) * (1 + cos_alpha), s = std::sqrt(s2);
  if (x >= s) return kPi * x * s2;
  if (x <= -s) return 0.0;
  const double y = std::sqrt((1 - x) * (1 + x)), cot = cos_alpha / s;
  const double q = std::clamp(-cot * x / y, -1.0, 1.0);
  const double z = y * std::sqrt((1 - q) * (1 + q));
  return std::max(0.0, (x * std::acos(q) - cot * z) * s2 + std::atan2(z, cot));
}

// ---------------------------------------------------------------------------------------------
// Cases A/B/C, shadows, self-shadows

float partial_factor(const FivOccluder& occ, const float p[3], const float n[3]) {
  return partial_factor_unit(occ, p, UnitNormal(n).v);
}

void occluded_irradiance(const FivOccluder& occ, const float p[3], const float n[3], bool partial, float out[3]) {
  occluded_irradiance_unit(occ, p, UnitNormal(n).v, partial, out);
}

void shade_fiv(const DifMap& map, const FivOccluder* occluders, int count, const float p[3], const float n[3],
               const FivShadeOptions& options, float out[3]) {
  shade_fiv_fast(map, occluders, count, p, n, options, out);
}

void shade_fiv_self(const float env_fiv[9], const FivOccluder& occ, const float p[3], const float n[3], float out[3]) {
  shade_fiv_self_unit(env_fiv, occ, p, UnitNormal(n).v, out);
}

void shade_fiv_member(const float env_fiv[9], const FivOccluder* occluders, int count, int self, const float p[3],
                      const float n_in[3], bool partial, float out[3]) {
  const UnitNormal unit(n_in);
  const float* n = unit.v;
  float own[3];
  shade_fiv_self_unit(env_fiv, occluders[self], p, n, own);
  shade_fiv_member_given_self(own, occluders, count, self, p, n, partial, out);
}

void shade_fiv_member_given_self(const float self_irradiance[3], const FivOccluder* occluders, int count, int self,
                                 const float p[3], const float n_in[3], bool partial, float out[3]) {
  const UnitNormal unit(n_in);
  const float* n = unit.v;
  for (int c = 0; c < 3; ++c) out[c] = std::max(0.0f, self_irradiance[c]);
  for (int j = 0; j < count; ++j) {
    if (j == self) continue;
    float o[3];
    occluded_irradiance_unit(occluders[j], p, n, partial, o);
    for (int c = 0; c < 3; ++c) out[c] = std::max(0.0f, out[c] - o[c]);
  }
}

// ---------------------------------------------------------------------------------------------
// Overlap pieces and the slow reference

double lens_area(double r1, double r2, double d) {
  r1 = std::max(r1, 0.0), r2 = std::max(r2, 0.0), d = std::max(d, 0.0);
  if (d >= r1 + r2) return 0.0;
  const double rmin = std::min(r1, r2);
  if (d <= std::fabs(r1 - r2)) return kPi * rmin * rmin;
  const double c1 = std::clamp((d * d + r1 * r1 - r2 * r2) / (2 * d * r1), -1.0, 1.0);
  const double c2 = std::clamp((d * d + r2 * r2 - r1 * r1) / (2 * d * r2), -1.0, 1.0);
  const double k = (-d + r1 + r2) * (d + r1 - r2) * (d - r1 + r2) * (d + r1 + r2);
  const double area = r1 * r1 * std::acos(c1) + r2 * r2 * std::acos(c2) - 0.5 * std::sqrt(std::max(0.0, k));
  return std::clamp(area, 0.0, kPi * rmin * rmin);
}

double overlap_fraction(double alpha_i, double alpha_j, double gamma) {
  const double denom = kPi * (alpha_i * alpha_i + alpha_j * alpha_j);
  if (!(denom > 0)) return 0.0;
  return lens_area(alpha_i, alpha_j, gamma) / denom;
}

namespace {
// One occluder's terms in the slow reference, in double: I (eq. 10 with the proxy's partial
// correction) and its disc (axis, α) for eq. 13–14 (header "Tight proxies").
void reference_terms(const FivOccluder& o, const float p[3], const float n[3], const FivShadeOptions& options,
                     const double below[3], double I[3], double axis[3], double& alpha) {
  const bool tight = options.proxy == FivProxy::cone && has_cones(o);
  float Ib[3];
  occluded_irradiance_unit(o, p, n, options.partial_occluders && !tight, Ib);
  for (int c = 0; c < 3; ++c) I[c] = Ib[c];
  double v[3] = {double(o.centre[0]) - p[0], double(o.centre[1]) - p[1], double(o.centre[2]) - p[2]};
  const double D = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  for (int k = 0; k < 3; ++k) axis[k] = D > 0 ? v[k] / D : double(n[k]);
  alpha = D > 0 ? std::asin(std::min(1.0, double(o.radius) / D)) : (o.radius > 0 ? kPi / 2 : 0.0);
  if (!tight) return;
  double s[3];
  offset_from_centre(o, p, s);
  ShellStencil st;
  stencil_at(o, s, st);
  float cone[4];
  sample_cones(o, st, cone);
  const double ml = std::sqrt(double(cone[0]) * cone[0] + double(cone[1]) * cone[1] + double(cone[2]) * cone[2]);
  if (ml > 0)
    for (int k = 0; k < 3; ++k) axis[k] = cone[k] / ml;
  const double ca = std::clamp(1.0 - double(cone[3]) / (2 * kPi), -1.0, 1.0);
  alpha = std::acos(std::max(ca, 0.0));
  if (!options.partial_occluders || !(plane_height(o, p, n) > -o.radius)) return;  // I as the sphere's case C gave it
  float f[9], e[3];
  sample_shells(o, st, f);
  project_fiv(f, n, e);
  const double x = n[0] * axis[0] + n[1] * axis[1] + n[2] * axis[2];
  const bool below_horizon = ca >= 0 && x <= -std::sqrt((1 - ca) * (1 + ca));
  const double K = cap_clamped_cosine(-x, ca);
  for (int c = 0; c < 3; ++c) I[c] = below_horizon ? 0.0 : std::max(0.0, double(e[c]) + below[c] * K);
}
} // namespace

void shade_fiv_reference(const DifMap& map, const FivOccluder* occluders, int count, const float p[3],
                         const float n_in[3], const FivShadeOptions& options, float out[3]) {
  const UnitNormal unit(n_in);
  const float* n = unit.v;
  float tot[3];
  lookup_difmap(map, n, tot);
  double e[3] = {tot[0], tot[1], tot[2]};
  double below[3] = {0, 0, 0};
  {
    const float down[3] = {-n[0], -n[1], -n[2]};
    float b[3];
    lookup_difmap(map, down, b);
    for (int c = 0; c < 3; ++c) below[c] = double(b[c]) / kPi;
  }
  struct Terms {
    double I[3], axis[3], alpha;
    bool tight;
  };
  std::vector<Terms> t(size_t(std::max(count, 0)));
  for (int i = 0; i < count; ++i) {
    Terms& ti = t[size_t(i)];
    reference_terms(occluders[i], p, n, options, below, ti.I, ti.axis, ti.alpha);
    ti.tight = options.proxy == FivProxy::cone && has_cones(occluders[i]);
    for (int c = 0; c < 3; ++c) e[c] -= ti.I[c];
  }
  const auto hides = [](const Terms& x) { return x.I[0] > 0 || x.I[1] > 0 || x.I[2] > 0; };
  if (options.overlap_correction)
    for (int i = 0; i < count; ++i)
      for (int j = i + 1; j < count; ++j) {
        const Terms& ti = t[size_t(i)];
        const Terms& tj = t[size_t(j)];
        if (!hides(ti) || !hides(tj)) continue;
        const double cg = ti.axis[0] * tj.axis[0] + ti.axis[1] * tj.axis[1] + ti.axis[2] * tj.axis[2];
        const double gamma = std::acos(std::clamp(cg, -1.0, 1.0));
        if (ti.tight && tj.tight) {  // the lens times the lower density
          const double Ai = kPi * ti.alpha * ti.alpha, Aj = kPi * tj.alpha * tj.alpha;
          if (!(Ai > 0 && Aj > 0)) continue;
          const double lens = lens_area(ti.alpha, tj.alpha, gamma);
          for (int c = 0; c < 3; ++c) e[c] += lens * std::min(ti.I[c] / Ai, tj.I[c] / Aj);
          continue;
        }
        const double o = overlap_fraction(ti.alpha, tj.alpha, gamma);
        for (int c = 0; c < 3; ++c) e[c] += o * (ti.I[c] + tj.I[c]);
      }
  for (int c = 0; c < 3; ++c) out[c] = float(std::max(0.0, e[c]));
}

} // namespace prt::shade
