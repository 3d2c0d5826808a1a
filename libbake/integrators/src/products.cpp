// products.cpp — where each product lies in a row, and its label (bake/integrators/products.h).
#include <bake/integrators/products.h>

namespace prt::bake {

std::vector<ProductSlice> product_slices(const ProductLayout& L) {
  std::vector<ProductSlice> s;
  if (L.ao_count) s.push_back({Product::Ao, L.ao, L.ao_count});
  if (L.transfer_count) s.push_back({Product::TransferDiffuse, L.transfer, L.transfer_count});
  if (L.visibility_count) s.push_back({Product::TransferVisibility, L.visibility, L.visibility_count});
  if (L.radiance_count) s.push_back({Product::RadianceBand1, L.radiance, L.radiance_count});
  if (L.shadowed_count) s.push_back({Product::RadianceShadowed, L.shadowed, L.shadowed_count});
  return s;
}

const char* product_label(Product product) {
  switch (product) {
  case Product::Ao: return "AO";
  case Product::TransferDiffuse: return "diffuse transfer";
  case Product::TransferVisibility: return "visibility transfer";
  case Product::RadianceBand1: return "band-1 radiance";
  case Product::RadianceShadowed: return "shadowed radiance";
  }
  return "?";
}

} // namespace prt::bake
