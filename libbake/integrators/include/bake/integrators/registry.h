// bake/integrators/registry.h — the integrators built from a spec (IntegratorSpec,
// bake/integrators/integrator.h): the one place that knows every kind, so the interface's own files
// include none of them and the bake pipeline asks for an integrator without naming its class.
#pragma once

#include <bake/integrators/integrator.h>
#include <bake/mesh/mesh.h>
#include <bake/visibility/accel.h>

#include <memory>
#include <utility>

namespace prt::bake {

// The integrator a spec describes (bake/integrators/integrator.h). `mesh`, `topology` and the request's
// environment must outlive it. With `accel` (bake/visibility/accel.h) its trees are shared, not built.
std::unique_ptr<Integrator> make_integrator(const IntegratorSpec& spec, const Mesh& mesh, const Topology& topology,
                                            const ProductRequest& request, const MeshAccel* accel = nullptr);
// The converged reference of the error reports (docs/ARCHITECTURE.md §6): QMC with
// spec.reference_rays() rays per point, seeded apart from the bake's points.
std::unique_ptr<Integrator> make_reference(const IntegratorSpec& spec, const Mesh& mesh, const Topology& topology,
                                           const ProductRequest& request, const MeshAccel* accel = nullptr);
// The same reference as two independent halves (half the rays each, rounded up; seeds apart), for
// compare_points_with_reference's measured noise: the check of a target error.
std::pair<std::unique_ptr<Integrator>, std::unique_ptr<Integrator>> make_reference_pair(
    const IntegratorSpec& spec, const Mesh& mesh, const Topology& topology, const ProductRequest& request,
    const MeshAccel* accel = nullptr);

} // namespace prt::bake
