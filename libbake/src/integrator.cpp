// integrator.cpp — the integrator kinds' names and the defaults' rules (bake/integrator.h), and
// the integrators built from a spec (bake/vertex_bake.h).
#include <bake/error.h>
#include <bake/filter.h>
#include <bake/integrator.h>
#include <bake/qmc.h>
#include <bake/sampling.h>
#include <bake/silhouette.h>
#include <bake/vertex_bake.h>

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

uint64_t IntegratorSpec::reference_seed() const { return mix64(seed ^ 0x7265666572656e63ull); }

std::unique_ptr<Integrator> make_integrator(const IntegratorSpec& spec, const Mesh& mesh, const Topology& topology,
                                            const ProductRequest& request, const MeshAccel* accel) {
  switch (spec.kind) {
  case IntegratorKind::Qmc:
    return std::make_unique<QmcIntegrator>(mesh, topology, request, QmcOptions{spec.qmc_rays, spec.seed}, accel);
  case IntegratorKind::Filter: {
    FilterOptions options;
    options.rays = spec.filter_rays;
    options.seed = spec.seed;
    return std::make_unique<FilterIntegrator>(mesh, topology, request, options, accel);
  }
  case IntegratorKind::Silhouette:
    return std::make_unique<SilhouetteIntegrator>(mesh, topology, request, SilhouetteOptions{spec.isolines(), spec.seed}, accel);
  }
  PRT_CHECK(false);
  return nullptr;
}

std::unique_ptr<Integrator> make_reference(const IntegratorSpec& spec, const Mesh& mesh, const Topology& topology,
                                           const ProductRequest& request, const MeshAccel* accel) {
  return std::make_unique<QmcIntegrator>(mesh, topology, request, QmcOptions{spec.reference_rays(), spec.reference_seed()},
                                         accel);
}

std::pair<std::unique_ptr<Integrator>, std::unique_ptr<Integrator>> make_reference_pair(
    const IntegratorSpec& spec, const Mesh& mesh, const Topology& topology, const ProductRequest& request,
    const MeshAccel* accel) {
  const uint32_t half = (spec.reference_rays() + 1) / 2;
  return {std::make_unique<QmcIntegrator>(mesh, topology, request, QmcOptions{half, spec.reference_seed()}, accel),
          std::make_unique<QmcIntegrator>(mesh, topology, request,
                                          QmcOptions{half, mix64(spec.reference_seed() ^ 0x68616c66ull)}, accel)};
}

} // namespace prt::bake
