// runtime/shaders/sh.glsl — GLSL 450 mirror of prt::sh::eval (runtime/include/prtshade/sh.h,
// runtime/src/sh.cpp): the real spherical-harmonics basis prtbake bakes with, for shaders that
// evaluate SH at a direction (e.g. to shade a normal against SH lighting).
//
// Basis — identical to sh.h (P.-P. Sloan, "Stupid Spherical Harmonics (SH) Tricks", GDC 2008,
// §"Definitions"): real, orthonormal over the unit sphere, Condon–Shortley phase (−1)^m INCLUDED,
//   y_{l,0} = K_l^0 P_l^0(z),  y_{l,m} = √2 K_l^m cos(mφ) P_l^m(z),  y_{l,−m} = √2 K_l^m sin(mφ) P_l^m(z)
// on the direction (x, y, z) = (sin θ cos φ, sin θ sin φ, cos θ) (θ from +z, φ from +x towards +y;
// the basis knows nothing about "up"). Hence y1−1 = −0.488603 y, y10 = 0.488603 z, y11 = −0.488603 x.
// Index layout: coefficient i = l(l+1) + m, bands l = 0 … order−1 ("order" = number of bands).
//
// Evaluation — the same recurrence as sh.cpp, in float:
//   p̄_0^0 = 1/(2√π), p̄_m^m = −sqrt((2m+1)/(2m)) p̄_{m−1}^{m−1} (the minus sign is the
//   Condon–Shortley phase), p̄_{m+1}^m = sqrt(2m+3) z p̄_m^m,
//   p̄_l^m = a (z p̄_{l−1}^m − b p̄_{l−2}^m), a = sqrt((4l²−1)/(l²−m²)), b = sqrt(((l−1)²−m²)/(4(l−1)²−1)),
//   y_{l,±m} = p̄_l^m · {Re, Im}(x + i y)^m  (√2 folded into p̄ for m > 0),
// so there are no transcendental functions beyond sqrt of exact small integers' ratios (which
// the Vulkan precision rules bound to a few ulps), no atan2 and no division by sin θ: exact at
// the poles. Each coefficient carries about (l + 1) × a few ulps of error relative to
// sqrt((2l+1)/(4π)), the largest |y_lm| can be (tests/shaders/test_sh_glsl.cpp asserts
// 16 ulps × (l + 1) of that bound against prt::sh::eval in double, orders 1 … 16).
//
// Order limit: PRT_SH_MAX_ORDER (number of bands; default 8, at most 16 — the range the tests
// cover; define it before including this file). prt_sh_eval writes out[0 … order²−1] and
// leaves the rest of the array untouched; order is clamped to [0, PRT_SH_MAX_ORDER].
#ifndef PRT_SH_GLSL
#define PRT_SH_GLSL

#ifndef PRT_SH_MAX_ORDER
#define PRT_SH_MAX_ORDER 8
#endif
#if PRT_SH_MAX_ORDER < 1 || PRT_SH_MAX_ORDER > 16
#error "PRT_SH_MAX_ORDER must be in [1, 16] (the orders tests/shaders/test_sh_glsl.cpp verifies)"
#endif
#define PRT_SH_MAX_COEFFS (PRT_SH_MAX_ORDER * PRT_SH_MAX_ORDER)

// sqrt(3 / (4π)): y_{1,m}(d) = PRT_SH_BAND1_SCALE · (−d.y, d.z, −d.x)[m + 1] (sh.h kBand1Scale).
const float PRT_SH_BAND1_SCALE = 0.48860251190291992159;
// 1 / (2 √π) = y_00.
const float PRT_SH_Y00 = 0.28209479177387814347;

// Flat index of coefficient (l, m).
int prt_sh_index(int l, int m) { return l * (l + 1) + m; }

// All basis functions of bands 0 … order−1 at the unit direction d (mirrors prt::sh::eval).
void prt_sh_eval(int order, vec3 d, inout float y[PRT_SH_MAX_COEFFS]) {
  int n = clamp(order, 0, PRT_SH_MAX_ORDER);
  float c = 1.0, s = 0.0;  // Re, Im of (x + i y)^m = sin^m θ (cos mφ, sin mφ)
  float pmm = PRT_SH_Y00;  // p̄_m^m
  for (int m = 0; m < n; ++m) {
    if (m == 1) pmm = -sqrt(3.0) * pmm;
    else if (m >= 2) pmm = -sqrt(float(2 * m + 1) / float(2 * m)) * pmm;
    // l = m
    if (m == 0) {
      y[0] = pmm;
    } else {
      y[prt_sh_index(m, m)] = pmm * c;
      y[prt_sh_index(m, -m)] = pmm * s;
    }
    if (m + 1 < n) {
      // l = m + 1
      float p_prev = pmm;
      float p = sqrt(float(2 * m + 3)) * d.z * pmm;
      if (m == 0) {
        y[prt_sh_index(1, 0)] = p;
      } else {
        y[prt_sh_index(m + 1, m)] = p * c;
        y[prt_sh_index(m + 1, -m)] = p * s;
      }
      // l >= m + 2
      for (int l = m + 2; l < n; ++l) {
        float l2 = float(l * l), m2 = float(m * m), lm1 = float((l - 1) * (l - 1));
        float a = sqrt((4.0 * l2 - 1.0) / (l2 - m2));
        float b = sqrt((lm1 - m2) / (4.0 * lm1 - 1.0));
        float p_next = a * (d.z * p - b * p_prev);
        p_prev = p;
        p = p_next;
        if (m == 0) {
          y[prt_sh_index(l, 0)] = p;
        } else {
          y[prt_sh_index(l, m)] = p * c;
          y[prt_sh_index(l, -m)] = p * s;
        }
      }
    }
    // (x + i y)^{m+1} = (x + i y)^m (x + i y)
    float c_next = c * d.x - s * d.y;
    s = s * d.x + c * d.y;
    c = c_next;
  }
}

#endif  // PRT_SH_GLSL
