// registry.cpp — the integrators built from a spec (bake/integrators/registry.h).
#include <bake/core/error.h>
#include <bake/integrators/filter.h>
#include <bake/integrators/qmc.h>
#include <bake/integrators/registry.h>
#include <bake/integrators/silhouette.h>
#include <bake/sphere/sampling.h>

namespace prt::bake {

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
