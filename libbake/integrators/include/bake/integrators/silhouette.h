// bake/integrators/silhouette.h — the semi-analytic visibility-silhouette integrator (Nowrouzezahrai,
// Baran, Mitchell, Jarosz: "Visibility Silhouettes for Semi-Analytic Spherical Integration",
// CGF 2014, §3; paper 001 in ../shared/papers). The data path, one stage per file:
//
//   mesh ─▶ contour edges (bake/visibility/contour.h: 4D dual-space BVH, eq. 6, orientation-free steps)
//        ─▶ octahedral arcs and isoline buckets (bake/sphere/octahedral.h: §3.3)
//        ─▶ DCF walk along each u-isoline and integrals over runs with W = 0 using
//           summed-area tables of f·J along isolines (bake/sphere/isoline_tables.h: §3.2, §4)
//        ─▶ the same product rows as the QMC baseline (bake/integrators/products.h).
//
// Conventions and choices (see the .cpp for the derivations):
//  * Octahedral map (u, v) = (x, y)/(|x|+|y|+|z|), one sheet per sign of z; dω = J du dv with
//    J = (u² + v² + (1−|u|−|v|)²)^(−3/2). (The paper prints the exponent as +1.5; the solid angle
//    element of q = (u, v, 1−|u|−|v|) is |q·(q_u × q_v)|/|q|³ = 1/|q|³.)
//  * k = N² samples: N u-isolines at u_i = −1 + (i + ½)·2/N; along an isoline, f·J is tabulated
//    in cells of width 2/N in v on both sheets and integrated exactly between crossings
//    (piecewise constant per cell); the u direction is the midpoint rule. Error falls with N.
//  * Each isoline is walked as one closed loop over both sheets; the depth complexity W is
//    propagated along a "spine" (the half equator z = 0, y < 0, where every loop starts) from
//    one direction whose W is counted with an Embree ray. No "minimum W is 0" assumption: fully
//    enclosed points are exact (W > 0 everywhere).
//  * The hemisphere H(ω,n) is a virtual occluder: the horizon great circle is walked like an
//    edge with step +1 into the lower hemisphere (paper §4: clamping is part of visibility), so
//    integrands never carry H and the tables are shared by all shade points.
//  * Contour components below the horizon (hemisphere points): the contour edges form a graph on
//    the welded vertices, and each connected component's arcs are a closed boundary by themselves
//    (every face's projected triangle is balanced at each of its corners, and an edge's faces sum
//    to its side sum S_e), so their step function W_D is single-valued. A component whose every
//    vertex is certainly strictly below the tangent plane (n·(x − p) < 0 beyond its rounding
//    bound; the point's own vertex, seen at −n, counts) lies in the open lower hemisphere, where
//    W_D differs from its value on the upper hemisphere by at most Σ_D |S_e|. Such components
//    are dropped before any per-arc work (arcs, isoline and spine crossings, hot texels) and the
//    horizon's step is raised from 1 to K = 1 + 2·Σ_D |S_e| (paper §4: the hemisphere is a
//    virtual occluder; only W = 0 matters, not W's value): W' = W − W_D + W_D(upper) then equals
//    W on the closed upper hemisphere and is ≥ 1 below it, so the runs with W' = 0 are exactly
//    those with W = 0. The counted start ray is corrected by the dropped arcs it would cross on
//    a path up to n. Only the order in which float crossings are added can change, so results
//    match the unculled path (SilhouetteOptions::cull_below_horizon = false) to rounding.
//  * A hemisphere point with no contour edge in view takes closed forms (bake/sphere/zonal.h) after one
//    ray decides enclosed / open; its band-1 and shadowed radiance (R, S) are the horizon-only
//    walk, once per normal.
//  * Visibility is the limit from p + εn, ε → 0+: every orientation predicate at p is evaluated
//    symbolically at p + εn (sign of the value, else of its ε-derivative), and the shade point's
//    own vertex is seen in direction −n. A flat 1-ring therefore covers exactly the lower
//    hemisphere and a concave one reaches above the horizon — with no ε offset in the numbers.
#pragma once

#include <bake/integrators/integrator.h>
#include <bake/integrators/products.h>
#include <bake/mesh/mesh.h>
#include <bake/visibility/accel.h>

#include <atomic>
#include <memory>

namespace prt::bake {

// What integrators of one mesh's pilot share about the environment (SilhouetteOptions::env_cache):
// its hot texels, and its point masses at one sub-sample per texel — the same bytes at every N
// whose cells are wider than the map's texels (N ≤ 290 for a 1024 × 512 map), so the levels
// after the first copy nothing and recompute nothing (the chooser builds five; each spent ~30 ms
// of CPU recomputing 524,288 masses). Filled by the first integrator that uses it; read, never
// changed, by the rest; keyed by the map and the environment's columns (another request or map
// uses none of it). Holds at most kMaxBytes of masses, else only the hot texels. Not for
// concurrent construction of integrators.
class SilhouetteEnvCache {
public:
  static constexpr size_t kMaxBytes = size_t(256) << 20;
  SilhouetteEnvCache();
  ~SilhouetteEnvCache();
  SilhouetteEnvCache(const SilhouetteEnvCache&) = delete;
  SilhouetteEnvCache& operator=(const SilhouetteEnvCache&) = delete;
  struct Impl;
  Impl& impl() const noexcept { return *impl_; }

private:
  std::unique_ptr<Impl> impl_;
};

struct SilhouetteOptions {
  int isolines = 256;  // N; k = N² (IntegratorSpec's k gives N = silhouette_isolines(k), bake/integrators/integrator.h)
  uint64_t seed = 1;   // only for the direction of the counted start ray when the default is degenerate
  // Leave out the contour components that lie wholly below the horizon (see the file comment):
  // the same visible runs, hence the same integrals; false is the unculled reference path.
  bool cull_below_horizon = true;
  // Shared with the integrators built before and after this one (SilhouetteEnvCache); null: none.
  // The integrals are the same bytes with and without it.
  std::shared_ptr<SilhouetteEnvCache> env_cache;
};

// The silhouette integrator's work, summed over its integrate() calls. `closed_form`: hemisphere
// points with no contour edge in view, given closed forms instead of a DCF walk (of which
// `enclosed` saw nothing at all: W > 0 over the whole hemisphere); cpu_seconds = contour_seconds
// + integrate_seconds.
struct SilhouetteStats : IntegratorStats {
  uint64_t contour_edges = 0, crossings = 0, start_rays = 0, start_retries = 0;
  uint64_t inconsistent_loops = 0;  // isoline loops whose W did not return to its start value (should be 0)
  uint64_t enclosed = 0;
  double contour_seconds = 0, integrate_seconds = 0;  // CPU time in contour search / the rest
};

class SilhouetteIntegrator final : public Integrator {
public:
  // `mesh`, `topology` and the request's environment must outlive the integrator. With `accel`
  // (of the same mesh and topology, bake/visibility/accel.h), its contour tree and ray scene are shared
  // instead of built: the same results, bit for bit.
  SilhouetteIntegrator(const Mesh& mesh, const Topology& topology, const ProductRequest& request,
                       const SilhouetteOptions& options, const MeshAccel* accel = nullptr);
  ~SilhouetteIntegrator() override;
  SilhouetteIntegrator(const SilhouetteIntegrator&) = delete;
  SilhouetteIntegrator& operator=(const SilhouetteIntegrator&) = delete;

  IntegratorKind kind() const override { return IntegratorKind::Silhouette; }
  std::string description() const override;
  const ProductLayout& layout() const override;
  // std_error is filled with 0: the integrator is deterministic; its error is discretisation.
  void integrate(const ShadePoint& point, uint64_t point_index, std::span<double> out,
                 std::span<double> std_error = {}) const override;

  // The full-sphere integrals with V ≡ 1 from the same tables (the visibility and radiance rows of
  // the layout; others 0). ∫ (1 − V) f = unoccluded − integrate(full sphere) then shares the
  // discretisation of both terms, so an occluder subtending little keeps its relative accuracy.
  void unoccluded(std::span<double> out) const;

  // Its work counters, kept with relaxed atomics (SilhouetteStats); stats() is their common part.
  SilhouetteStats silhouette_stats() const;
  IntegratorStats stats() const override { return silhouette_stats(); }
  void reset_stats() const override;
  // Whether its tables took the environment's masses from a SilhouetteEnvCache another
  // integrator filled (its build then cost less than a build of its own would).
  bool masses_from_cache() const noexcept;
  // Per integral: contour edges and isoline crossings, and the CPU time split between the contour
  // search and the rest; points that saw no contour edge (closed forms).
  std::string work_summary() const override;
  const SilhouetteOptions& options() const;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

} // namespace prt::bake
