// bake/products.h — what a per-vertex bake computes, and where each value lives in a row.
//
// The integrands (docs/ARCHITECTURE.md §3; p shade point, n unit normal, V visibility from just above the
// surface, H(ω,n) = [n·ω > 0], y_i the real SH basis of prtshade, index l(l+1)+m, order = number
// of bands L):
//   AO                   A     = (1/π) ∫ V H (n·ω) dω                     ∈ [0,1]
//   diffuse transfer     T_i   = (1/π) ∫ V H (n·ω) y_i dω                 (Sloan et al. 2002)
//   visibility transfer  U_i   = ∫ V H y_i dω                             (triple products, glossy)
//   band-1 radiance      R_c,m = ∫ L_c V H y_1m dω, c ∈ RGB, m = -1,0,1   (paper 001 §4, "All-
//                        Frequency Diffuse Shading"; diffuse irradiance at the baked normal is
//                        E_c = (4π/3) Σ_m y_1m(n) R_c,m, the vector-irradiance form, appendix A)
// Every integrator (QMC now, the silhouette integrator next) produces rows in this layout, so a
// product can be baked by either and compared value by value.
#pragma once

#include <cstddef>

namespace prt::bake {

class EnvMap;

struct ProductRequest {
  bool ao = false;
  int transfer_order = 0;            // L of T (0 = not requested)
  int visibility_order = 0;          // L of U (0 = not requested)
  const EnvMap* radiance = nullptr;  // band-1 radiance under this environment (nullptr = not requested)

  bool empty() const noexcept { return !ao && transfer_order == 0 && visibility_order == 0 && !radiance; }
};

// Offsets of each product inside one row of doubles: [ao | T (Lt²) | U (Lv²) | R ([c][m], 9)].
struct ProductLayout {
  size_t ao = 0, transfer = 0, visibility = 0, radiance = 0;
  size_t ao_count = 0, transfer_count = 0, visibility_count = 0, radiance_count = 0;
  size_t width = 0;  // doubles per row

  explicit ProductLayout(const ProductRequest& r) {
    ao_count = r.ao ? 1 : 0;
    transfer_count = size_t(r.transfer_order) * size_t(r.transfer_order);
    visibility_count = size_t(r.visibility_order) * size_t(r.visibility_order);
    radiance_count = r.radiance ? 9 : 0;
    ao = 0;
    transfer = ao + ao_count;
    visibility = transfer + transfer_count;
    radiance = visibility + visibility_count;
    width = radiance + radiance_count;
  }
};

} // namespace prt::bake
