// fiv.cpp — FIV run-time shading (paper 004 §4.3); conventions in prtshade/fiv.h.
#include <prtshade/fiv.h>

#include "check.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <string>
#include <vector>

namespace prt::shade {
namespace {

constexpr double kPi = 3.14159265358979323846264338327950288;
constexpr float kPiF = 3.14159265358979323846f;
constexpr float kTwoPiF = 6.28318530717958647692f;

// Clamp that maps NaN to lo (fmax/fmin ignore a NaN operand), so a float-to-int conversion after
// it is always defined.
inline float clamp_nan_safe(float x, float lo, float hi) { return std::fmin(std::fmax(x, lo), hi); }

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

// Occluder i as seen from p for the overlap correction: axis a, angular radius α (radians) and
// sin/cos of α for the cheap disjointness test.
struct DiscView {
  float axis[3];
  float alpha, sin_alpha, cos_alpha;
};

DiscView disc_view(const FivOccluder& occ, const float p[3], const float n[3]) {
  const double dx = double(occ.centre[0]) - p[0], dy = double(occ.centre[1]) - p[1], dz = double(occ.centre[2]) - p[2];
  const double D = std::sqrt(dx * dx + dy * dy + dz * dz);
  DiscView v{};
  const double R = occ.radius;
  if (!(D > 0)) {  // p at the centre (or NaN): the occluder covers the hemisphere around n
    v.axis[0] = n[0], v.axis[1] = n[1], v.axis[2] = n[2];
    v.sin_alpha = R > 0 ? 1.0f : 0.0f;
  } else {
    v.axis[0] = float(dx / D), v.axis[1] = float(dy / D), v.axis[2] = float(dz / D);
    v.sin_alpha = float(std::min(1.0, R / D));
  }
  v.alpha = std::asin(v.sin_alpha);
  v.cos_alpha = std::sqrt(std::max(0.0f, 1.0f - v.sin_alpha * v.sin_alpha));
  return v;
}

void add_scaled(double acc[3], const float a[3], const float b[3], double w) {
  for (int c = 0; c < 3; ++c) acc[c] += w * (double(a[c]) + double(b[c]));
}

inline bool hides_something(const float I[3]) { return I[0] > 0 || I[1] > 0 || I[2] > 0; }

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
  PRT_SHADE_REQUIRE(o.radii != nullptr && o.shells != nullptr && o.valid != nullptr, "occluder with a null array");
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
  for (size_t i = 0; i < n; ++i)
    PRT_SHADE_REQUIRE(std::isfinite(o.shells[i]) && std::fabs(o.shells[i]) <= kFivValueLimit,
                      "shell value " + std::to_string(i) + " = " + value_text(o.shells[i]) + value_limit_text);
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

void lookup_fiv_at(const FivOccluder& occ, const double s[3], float out[9]) {
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
    if (phi < 0) phi += kTwoPiF;
  } else {
    rho = 0;  // ρ == 0 (or NaN): d = +Y, θ = 0
  }

  // θ: clamped, poles included.
  const float t = clamp_nan_safe(theta / kPiF * float(occ.n_theta - 1), 0.0f, float(occ.n_theta - 1));
  const int i0 = std::min(int(t), occ.n_theta - 2);
  const float ft = t - float(i0);
  // φ: wraps.
  const float u = clamp_nan_safe(phi / kTwoPiF * float(occ.n_phi), 0.0f, float(occ.n_phi));
  const int ju = std::min(int(u), occ.n_phi);
  const float fu = u - float(ju);
  const int j0 = ju % occ.n_phi, j1 = (ju + 1) % occ.n_phi;
  // ρ: linear between the bracketing radii, clamped inside, 1/ρ² falloff outside.
  const int last = occ.n_rho - 1;
  int k0 = 0, k1 = 0;
  float fr = 0, falloff = 1;
  if (rho <= occ.radii[0] || last == 0) {
    if (last == 0 && rho > occ.radii[0]) falloff = float((occ.radii[0] / rho) * (occ.radii[0] / rho));
  } else if (rho >= occ.radii[last]) {
    k0 = k1 = last;
    falloff = float((occ.radii[last] / rho) * (occ.radii[last] / rho));
  } else {
    k1 = int(std::upper_bound(occ.radii, occ.radii + occ.n_rho, float(rho)) - occ.radii);
    k1 = std::clamp(k1, 1, last);
    k0 = k1 - 1;
    fr = clamp_nan_safe(float((rho - occ.radii[k0]) / (double(occ.radii[k1]) - occ.radii[k0])), 0.0f, 1.0f);
  }

  const int ks[2] = {k0, k1}, is[2] = {i0, i0 + 1}, js[2] = {j0, j1};
  const float wk[2] = {1 - fr, fr}, wi[2] = {1 - ft, ft}, wj[2] = {1 - fu, fu};
  float plain[9] = {}, masked[9] = {};
  float masked_weight = 0;
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      for (int c = 0; c < 2; ++c) {
        const float w = wk[a] * wi[b] * wj[c];
        const size_t idx = sample_index(occ, ks[a], is[b], js[c]);
        const float* v = occ.shells + idx * 9;
        for (int e = 0; e < 9; ++e) plain[e] += w * v[e];
        if (occ.valid[idx] != 0) {
          masked_weight += w;
          for (int e = 0; e < 9; ++e) masked[e] += w * v[e];
        }
      }
  if (masked_weight > 0) {
    const float inv = 1.0f / masked_weight;
    for (int e = 0; e < 9; ++e) out[e] = masked[e] * inv * falloff;
  } else {
    for (int e = 0; e < 9; ++e) out[e] = plain[e] * falloff;
  }
}

float partial_factor_unit(const FivOccluder& occ, const float p[3], const float n[3]) {
  const float h = plane_height(occ, p, n), R = occ.radius;
  if (!(h > -R)) return 0.0f;  // case C
  if (h >= R) return 1.0f;     // case A
  return clamp_nan_safe((h + R) / (2.0f * R), 0.0f, 1.0f);  // case B
}

// occluded_irradiance for a unit n.
void occluded_irradiance_unit(const FivOccluder& occ, const float p[3], const float n[3], bool partial, float out[3]) {
  const float factor = partial ? partial_factor_unit(occ, p, n) : (plane_height(occ, p, n) > -occ.radius ? 1.0f : 0.0f);
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

} // namespace

void lookup_fiv(const FivOccluder& occ, const float s[3], float out[9]) {
  const double sd[3] = {s[0], s[1], s[2]};
  lookup_fiv_at(occ, sd, out);
}

// ---------------------------------------------------------------------------------------------
// Cases A/B/C, shadows, self-shadows

float partial_factor(const FivOccluder& occ, const float p[3], const float n[3]) {
  return partial_factor_unit(occ, p, UnitNormal(n).v);
}

void occluded_irradiance(const FivOccluder& occ, const float p[3], const float n[3], bool partial, float out[3]) {
  occluded_irradiance_unit(occ, p, UnitNormal(n).v, partial, out);
}

void shade_fiv(const DifMap& map, const FivOccluder* occluders, int count, const float p[3], const float n_in[3],
               const FivShadeOptions& options, float out[3]) {
  const UnitNormal unit(n_in);
  const float* n = unit.v;
  // Accumulated in double: with hundreds of occluders and pair terms, float sums would drift by
  // ~count·ε·E_tot; the per-occluder work stays in float.
  float tot[3];
  lookup_difmap(map, n, tot);
  double acc[3] = {tot[0], tot[1], tot[2]};
  struct State {
    float I[3];
    DiscView disc;
  };
  constexpr int kStack = 128;
  std::array<State, kStack> stack_states;
  std::vector<State> heap_states;
  State* st = stack_states.data();
  if (count > kStack) {
    heap_states.resize(size_t(count));
    st = heap_states.data();
  }
  int active = 0;  // occluders that hide something are compacted to st[0 .. active)
  for (int i = 0; i < count; ++i) {
    State& s = st[active];
    occluded_irradiance_unit(occluders[i], p, n, options.partial_occluders, s.I);
    if (!hides_something(s.I)) continue;
    for (int c = 0; c < 3; ++c) acc[c] -= s.I[c];
    if (options.overlap_correction) s.disc = disc_view(occluders[i], p, n);
    ++active;
  }
  if (options.overlap_correction) {
    for (int i = 0; i < active; ++i) {
      const DiscView& a = st[i].disc;
      for (int j = i + 1; j < active; ++j) {
        const DiscView& b = st[j].disc;
        // Disjoint discs (γ >= α_i + α_j, both angles in [0, π]) have no lens: skip without acos.
        const float cos_gamma = a.axis[0] * b.axis[0] + a.axis[1] * b.axis[1] + a.axis[2] * b.axis[2];
        const float cos_sum = a.cos_alpha * b.cos_alpha - a.sin_alpha * b.sin_alpha;
        if (cos_gamma < cos_sum) continue;
        // γ from atan2(|a×b|, a·b): accurate for small angles, where acos(a·b) loses half the digits.
        const float cx = a.axis[1] * b.axis[2] - a.axis[2] * b.axis[1];
        const float cy = a.axis[2] * b.axis[0] - a.axis[0] * b.axis[2];
        const float cz = a.axis[0] * b.axis[1] - a.axis[1] * b.axis[0];
        const float gamma = std::atan2(std::sqrt(cx * cx + cy * cy + cz * cz), cos_gamma);
        const double o = overlap_fraction(a.alpha, b.alpha, gamma);
        if (o > 0) add_scaled(acc, st[i].I, st[j].I, o);
      }
    }
  }
  for (int c = 0; c < 3; ++c) out[c] = float(std::max(0.0, acc[c]));
}

void shade_fiv_self(const float env_fiv[9], const FivOccluder& occ, const float p[3], const float n[3], float out[3]) {
  shade_fiv_self_unit(env_fiv, occ, p, UnitNormal(n).v, out);
}

void shade_fiv_member(const float env_fiv[9], const FivOccluder* occluders, int count, int self, const float p[3],
                      const float n_in[3], bool partial, float out[3]) {
  const UnitNormal unit(n_in);
  const float* n = unit.v;
  shade_fiv_self_unit(env_fiv, occluders[self], p, n, out);
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

void shade_fiv_reference(const DifMap& map, const FivOccluder* occluders, int count, const float p[3],
                         const float n_in[3], const FivShadeOptions& options, float out[3]) {
  const UnitNormal unit(n_in);
  const float* n = unit.v;
  float tot[3];
  lookup_difmap(map, n, tot);
  double e[3] = {tot[0], tot[1], tot[2]};
  std::vector<std::array<float, 3>> I(size_t(std::max(count, 0)));
  for (int i = 0; i < count; ++i) {
    occluded_irradiance(occluders[i], p, n, options.partial_occluders, I[size_t(i)].data());
    for (int c = 0; c < 3; ++c) e[c] -= I[size_t(i)][size_t(c)];
  }
  auto axis_alpha = [&](const FivOccluder& o, double axis[3]) {
    double v[3] = {double(o.centre[0]) - p[0], double(o.centre[1]) - p[1], double(o.centre[2]) - p[2]};
    const double D = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int k = 0; k < 3; ++k) axis[k] = D > 0 ? v[k] / D : double(n[k]);
    return D > 0 ? std::asin(std::min(1.0, double(o.radius) / D)) : (o.radius > 0 ? kPi / 2 : 0.0);
  };
  if (options.overlap_correction)
    for (int i = 0; i < count; ++i)
      for (int j = i + 1; j < count; ++j) {
        const auto& Ii = I[size_t(i)];
        const auto& Ij = I[size_t(j)];
        if (!hides_something(Ii.data()) || !hides_something(Ij.data())) continue;
        double ai[3], aj[3];
        const double alpha_i = axis_alpha(occluders[i], ai), alpha_j = axis_alpha(occluders[j], aj);
        const double gamma = std::acos(std::clamp(ai[0] * aj[0] + ai[1] * aj[1] + ai[2] * aj[2], -1.0, 1.0));
        const double o = overlap_fraction(alpha_i, alpha_j, gamma);
        for (int c = 0; c < 3; ++c) e[c] += o * (double(Ii[size_t(c)]) + Ij[size_t(c)]);
      }
  for (int c = 0; c < 3; ++c) out[c] = float(std::max(0.0, e[c]));
}

} // namespace prt::shade
