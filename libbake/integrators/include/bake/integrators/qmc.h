// bake/integrators/qmc.h — the baseline and reference integrator: Embree ray casting with importance-
// sampled, randomised quasi-Monte Carlo (paper 001 §5: "we compute a PDF according to the
// environment light then generate and warp deterministic Halton distributions by this PDF, at
// each shade point ... reject directions in the lower hemisphere and launch shadow rays").
//
// One set of N rays per shade point serves every requested product (the visibility work is
// shared). Directions come from a one-sample mixture of the strategies the products want, and
// every product is weighted by the mixture density (the balance heuristic, Veach & Guibas 1995):
//   cosine-weighted hemisphere  p = cos θ / π     — AO, diffuse transfer, radiance
//   uniform hemisphere          p = 1 / 2π        — visibility transfer (∫ V H y_i dω has
//                                                   infinite variance under cosine sampling)
//   environment luminance       p = EnvMap::pdf   — band-1 radiance R and shadowed radiance S
//                                                   (suns of 10^4-10^5 × mean)
// Weights: 1/2 to the environment when R or S is baked; the rest shared equally by the
// hemisphere strategies in use. Every estimator f·V/p is then bounded, so the per-point
// standard error is finite and reported. S_c,i = ∫ L_c V H y_i dω (bake/integrators/products.h; paper 001
// §4 "Material Editing") has no cosine, like U: under cosine sampling alone L y_i / (cos θ/π)
// grows without bound at the horizon wherever the environment's pdf is small against a channel
// (a dim, saturated horizon), so S brings in the uniform hemisphere like U does; with it
// |f/p| ≤ |y_i| L_c / max(w_env pdf_env, w_uni/2π) everywhere. The environment strategy
// carries the variance of bright texels (L_c / pdf_env is at most the channel's share of the
// luminance over its mean), the uniform one that of dim sky near the horizon. R alone keeps the
// mixture it had (its numbers do not change).
//
// Points are a 3D Halton sequence (u0 picks the strategy, u1,u2 warp) with a per-point Cranley–
// Patterson rotation from (seed, point index): unbiased, and identical whatever the thread count.
//
// Visibility at a mesh vertex is the limit from above (bake/integrators/integrator.h): the ray starts at the
// vertex itself (tnear = 0); Embree's hits on the vertex's own 1-ring and on the triangles near it
// (bake/visibility/raycast.h NearTriangles: T-junctions, coplanar overlaps, duplicated and near-duplicate
// sheets) are filtered out and those triangles are decided exactly in the ε-limit instead
// (occludes_from_above, orient_eps). Hits on any other triangle at any t ≥ 0 occlude.
#pragma once

#include <bake/integrators/integrator.h>
#include <bake/integrators/products.h>
#include <bake/mesh/mesh.h>
#include <bake/visibility/accel.h>
#include <bake/visibility/raycast.h>

#include <atomic>
#include <memory>

namespace prt::bake {

struct QmcOptions {
  uint32_t rays = IntegratorSpec::kDefaultQmcRays;  // per shade point
  uint64_t seed = 1;
};

class QmcIntegrator final : public Integrator {
public:
  // `mesh` and `topology` (and the request's environment) must outlive the integrator. With
  // `accel` (of the same mesh and topology, bake/visibility/accel.h), its ray scene is shared instead of built.
  QmcIntegrator(const Mesh& mesh, const Topology& topology, const ProductRequest& request,
                const QmcOptions& options, const MeshAccel* accel = nullptr);
  ~QmcIntegrator() override;
  QmcIntegrator(const QmcIntegrator&) = delete;
  QmcIntegrator& operator=(const QmcIntegrator&) = delete;

  IntegratorKind kind() const override { return IntegratorKind::Qmc; }
  std::string description() const override;
  const ProductLayout& layout() const override { return layout_; }
  void integrate(const ShadePoint& point, uint64_t point_index, std::span<double> out,
                 std::span<double> std_error = {}) const override;

  // Points integrated and the time spent integrating them, summed over threads
  // (IntegratorStats::points, cpu_seconds).
  IntegratorStats stats() const override;
  // Rays per point, and rays per second of that time.
  std::string work_summary() const override;

  // Visibility of direction d (unit) from the shade point, in the limit from above.
  bool visible(const ShadePoint& point, const Eigen::Vector3d& d) const;
  const QmcOptions& options() const { return options_; }

private:
  ProductRequest request_;
  ProductLayout layout_;
  QmcOptions options_;
  double w_cos_ = 0, w_uni_ = 0, w_env_ = 0;  // mixture weights, sum to 1
  int sh_order_ = 0;                          // SH order evaluated per sample
  const EnvMap* env_ = nullptr;               // of R and S (ProductRequest::environment())
  std::shared_ptr<const RayCaster> rays_;
  mutable std::atomic<uint64_t> points_{0}, cpu_ns_{0};  // relaxed counters for stats()
};

} // namespace prt::bake
