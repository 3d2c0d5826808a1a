// integrator.cpp — the integrator kinds' names and the defaults' rules (bake/integrators/integrator.h).
#include <bake/core/error.h>
#include <bake/integrators/integrator.h>
#include <bake/sphere/sampling.h>

#include <algorithm>
#include <cmath>

namespace prt::bake {

const char* to_string(IntegratorKind kind) {
  switch (kind) {
  case IntegratorKind::Silhouette: return "silhouette";
  case IntegratorKind::Qmc: return "qmc";
  case IntegratorKind::Filter: return "filter";
  }
  return "?";
}

std::optional<IntegratorKind> parse_integrator_kind(std::string_view name) {
  for (IntegratorKind k : {IntegratorKind::Silhouette, IntegratorKind::Qmc, IntegratorKind::Filter})
    if (name == to_string(k)) return k;
  return std::nullopt;
}

int silhouette_isolines(uint32_t k) { return std::max(2, int(std::lround(std::sqrt(double(k))))); }

std::string IntegratorSpec::knob_text() const {
  switch (kind) {
  case IntegratorKind::Silhouette: return std::to_string(isolines()) + " isolines";
  case IntegratorKind::Qmc: return std::to_string(qmc_rays) + " rays";
  case IntegratorKind::Filter: return std::to_string(filter_rays) + " pass-1 rays";
  }
  return "?";
}

uint64_t IntegratorSpec::reference_seed() const { return mix64(seed ^ 0x7265666572656e63ull); }

} // namespace prt::bake
