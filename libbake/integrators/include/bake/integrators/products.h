// bake/integrators/products.h — what a per-vertex bake computes, and where each value lives in a row.
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
//   shadowed radiance    S_c,i = ∫ L_c V H y_i dω, c ∈ RGB, i < L²         (paper 001 §4, "Material
//                        Editing": the shadowed incident radiance projected once at order L for a
//                        fixed environment; any lobe is applied at run time, prtshade/glossy.h
//                        route B). R is S's band 1: R_c,m = S_c,(2+m), the same integral; a bake
//                        holding both computes them from the same samples (QMC) or the same tables
//                        (silhouette), so they agree to rounding. R stays its own product (its
//                        bytes do not change when S is added; a diffuse receiver needs only R). Like
//                        U, S has no cosine factor: the lobe, cosine included if wanted, is the
//                        run time's (paper 001 §4 notes the cosine-weighted variant; the glossy
//                        lobe of prtshade/glossy.h has none).
// Every integrator (QMC now, the silhouette integrator next) produces rows in this layout, so a
// product can be baked by either and compared value by value.
#pragma once

#include <cstddef>
#include <vector>

namespace prt::bake {

class EnvMap;

struct ProductRequest {
  bool ao = false;
  int transfer_order = 0;            // L of T (0 = not requested)
  int visibility_order = 0;          // L of U (0 = not requested)
  const EnvMap* radiance = nullptr;  // band-1 radiance under this environment (nullptr = not requested)
  // Shadowed radiance S at order `shadowed_order` under `shadowed` (both set, or neither). With R
  // also requested, the two environments must be the same object.
  const EnvMap* shadowed = nullptr;
  int shadowed_order = 0;

  bool empty() const noexcept {
    return !ao && transfer_order == 0 && visibility_order == 0 && !radiance && shadowed_order == 0;
  }
  // S has both its fields or neither, and R and S share one environment.
  bool consistent() const noexcept {
    return shadowed_order >= 0 && (shadowed != nullptr) == (shadowed_order > 0) &&
           (!radiance || !shadowed || radiance == shadowed);
  }
  // The environment the radiance products are taken under (nullptr when neither is requested).
  const EnvMap* environment() const noexcept { return radiance ? radiance : shadowed; }
};

// Offsets of each product inside one row of doubles:
//   [ao | T (Lt²) | U (Lv²) | R ([c][m], 9) | S ([c][i], 3·Ls²)].
// S comes last, so a request without it has the row (and the files) it had before S existed.
struct ProductLayout {
  size_t ao = 0, transfer = 0, visibility = 0, radiance = 0, shadowed = 0;
  size_t ao_count = 0, transfer_count = 0, visibility_count = 0, radiance_count = 0, shadowed_count = 0;
  int shadowed_order = 0;
  size_t width = 0;  // doubles per row

  explicit ProductLayout(const ProductRequest& r) {
    ao_count = r.ao ? 1 : 0;
    transfer_count = size_t(r.transfer_order) * size_t(r.transfer_order);
    visibility_count = size_t(r.visibility_order) * size_t(r.visibility_order);
    radiance_count = r.radiance ? 9 : 0;
    shadowed_order = r.shadowed_order;
    shadowed_count = 3 * size_t(r.shadowed_order) * size_t(r.shadowed_order);
    ao = 0;
    transfer = ao + ao_count;
    visibility = transfer + transfer_count;
    radiance = visibility + visibility_count;
    shadowed = radiance + radiance_count;
    width = shadowed + shadowed_count;
  }
};

// The per-vertex products, as libbake knows them; the file names them through formats/ (the
// baker maps each to its dataset there), libbake only labels them for people.
enum class Product { Ao, TransferDiffuse, TransferVisibility, RadianceBand1, RadianceShadowed };
const char* product_label(Product product);  // "AO", "diffuse transfer", ... (for logs)

// Where each product a layout holds lies in a row, in row order (AO, diffuse transfer,
// visibility transfer, band-1 radiance, shadowed radiance); products the layout does not hold are left out.
struct ProductSlice {
  Product product;
  size_t offset, count;
};
std::vector<ProductSlice> product_slices(const ProductLayout& layout);

} // namespace prt::bake
