// bake/bake/error_report.h — a bake's error against a converged reference on a seeded sample of
// its shade points (docs/ARCHITECTURE.md §6), per product: RMSE, largest error, and the noise of
// the bake's and the reference's own estimates.
#pragma once

#include <bake/bake/vertex_bake.h>
#include <bake/core/progress.h>
#include <bake/integrators/integrator.h>
#include <bake/integrators/products.h>
#include <bake/mesh/mesh.h>

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace prt::bake {

// Error against a converged reference on a seeded sample of vertices (docs/ARCHITECTURE.md §6).
struct ProductError {
  Product product = Product::Ao;
  size_t values = 0;                // numbers compared
  double rmse = 0, max_abs = 0;     // bake − reference
  double reference_rms = 0;         // RMS of the reference values (for relative errors)
  double bake_std_error = 0;        // RMS of the bake's own estimated standard errors
  double reference_std_error = 0;   // RMS of the reference's standard errors (its own noise)
  // > 1: the reference was the bake's own integrator at `finer` times its knob (the silhouette
  // integrator at finer·N isolines, bake/bake/choose.h "The check"): deterministic, so rmse is the
  // bake's error less the finer level's, both of one sign, and the verdict extrapolates from it at
  // the integrator's order (target_verdicts). 0: an independent reference (QMC).
  double finer = 0;
  uint32_t finer_knob = 0;          // the finer level's isolines
  size_t finer_points = 0;          // the points it compared (every row when that was affordable)
  // The RMS of the bake's own values of this product over every row of the receivers the report
  // covers (0: not known). A relative error (band-1, S) divides by it (relative_scale): E is
  // relative to the RMS of the product over the whole mesh (bake/bake/choose.h), which the bake
  // knows to within E, while the compared points' reference_rms varies from sample to sample — on
  // regr01.obj, where half the vertices see no sky, 20 points read an RMS 3.7× below the mesh's.
  double mesh_rms = 0;
};
// What a relative error divides by: mesh_rms when known, else reference_rms.
inline double relative_scale(const ProductError& e) { return e.mesh_rms > 0 ? e.mesh_rms : e.reference_rms; }
struct ErrorReport {
  std::vector<uint32_t> vertices;
  std::vector<ProductError> products;
  std::string reference;            // the reference integrator's description
  double reference_seconds = 0;     // apart from the bake time
  // The reference was two independent halves: reference_std_error is their measured noise (the
  // RMS of |a − b| / 2), not QMC's estimator (which overstates it).
  bool reference_noise_measured = false;
};

// Picks min(n_points, V) distinct vertices with `seed`, integrates them with `reference`, and
// compares with `bake` (which must have the same layout). The reference integration is a
// "reference" stage of `monitor`: it reports progress and throws Cancelled like a bake.
// With `second` (an independent reference of the same kind, make_reference_pair), the reference
// is the mean of the two and its noise is measured per value as |a − b| / 2
// (ErrorReport::reference_noise_measured).
ErrorReport compare_with_reference(const Mesh& mesh, const Topology& topology, const VertexBake& bake,
                                   const Integrator& reference, size_t n_points, uint64_t seed,
                                   const Monitor& monitor = {}, const Integrator* second = nullptr);

ErrorReport compare_points_with_reference(std::span<const ShadePoint> points, const VertexBake& bake,
                                          const Integrator& reference, size_t n_points, uint64_t seed,
                                          const Monitor& monitor = {}, const Integrator* second = nullptr);

} // namespace prt::bake
