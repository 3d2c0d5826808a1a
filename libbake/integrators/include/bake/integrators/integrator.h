// bake/integrators/integrator.h — the interface every spherical integrator implements, so products can be
// baked by the QMC baseline (bake/integrators/qmc.h), the silhouette integrator (paper 001 §3) or the
// sheared-filter integrator (paper 002, bake/integrators/filter.h) and compared value by value — and the typed configuration that chooses one (IntegratorSpec).
#pragma once

#include <bake/integrators/products.h>
#include <bake/mesh/shade_point.h>

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace prt::bake {

enum class IntegratorKind { Silhouette, Qmc, Filter };

// The names files and tools use ("silhouette", "qmc", "filter"): the one place they are spelled.
const char* to_string(IntegratorKind kind);
std::optional<IntegratorKind> parse_integrator_kind(std::string_view name);  // nullopt for another name

// The silhouette integrator's k → N rule: N = round(√k) u-isolines (at least 2; the integrator
// then rounds N up to even), k = N² spherical samples.
int silhouette_isolines(uint32_t k);

// Which integrator, its sampling knob, its seed and the error report's reference settings; each
// default is spelled here once. Files and tools carry one user-facing "samples" number, which is
// the knob of the chosen kind (samples() / set_samples()).
struct IntegratorSpec {
  static constexpr uint32_t kDefaultSilhouetteK = 16384;  // 128² spherical samples
  static constexpr uint32_t kDefaultQmcRays = 1024;
  static constexpr uint32_t kDefaultFilterRays = 16;     // pass-1 rays (paper 002 §5: 4-32)
  static constexpr uint32_t kMinSilhouetteK = 4;          // 2 u-isolines
  // The converged reference of a silhouette bake (and of FIV shells, bake/bake/fiv.h): QMC rays per point.
  static constexpr uint32_t kSilhouetteReferenceRays = 65536;
  static constexpr uint32_t kQmcReferenceFactor = 10;     // a qmc bake's reference: 10× its rays

  IntegratorKind kind = IntegratorKind::Silhouette;
  uint32_t silhouette_k = kDefaultSilhouetteK;  // silhouette: k spherical samples (silhouette_isolines(k))
  uint32_t qmc_rays = kDefaultQmcRays;          // qmc: rays per shade point
  uint32_t filter_rays = kDefaultFilterRays;    // filter: pass-1 rays per shade point
  uint64_t seed = 1;
  uint32_t report_points = 32;                  // error report: seeded points re-integrated (0: none)
  // error report: the QMC reference's rays per point, sized for a target error
  // (bake/bake/choose.h plan_report_reference); 0: the defaults below.
  uint32_t report_rays = 0;

  // The chosen kind's knob.
  static uint32_t IntegratorSpec::*knob(IntegratorKind k) {
    switch (k) {
    case IntegratorKind::Qmc: return &IntegratorSpec::qmc_rays;
    case IntegratorKind::Filter: return &IntegratorSpec::filter_rays;
    case IntegratorKind::Silhouette: break;
    }
    return &IntegratorSpec::silhouette_k;
  }
  uint32_t samples() const { return this->*knob(kind); }
  // The knob as a reader counts it: "148 isolines", "1024 rays", "16 pass-1 rays".
  std::string knob_text() const;
  void set_samples(uint32_t n) { this->*knob(kind) = n; }
  int isolines() const { return silhouette_isolines(silhouette_k); }
  // Rays per point of the QMC reference the error report compares with.
  uint32_t reference_rays() const {
    if (report_rays > 0) return report_rays;
    return kind == IntegratorKind::Qmc ? qmc_rays * kQmcReferenceFactor : kSilhouetteReferenceRays;
  }
  // The reference's randomisation seed, apart from the bake's points.
  uint64_t reference_seed() const;

};

// What every integrator counts, summed over its integrate() calls (relaxed atomics): the
// integrals made, those given in closed form, and the CPU time inside integrate() (0 when the
// integrator does not keep it). An integrator's own work (contour edges, rays, cells) is its own
// stats type (SilhouetteStats, FilterStats) and its work_summary() line: no caller needs to know
// which kind it holds.
struct IntegratorStats {
  uint64_t points = 0;
  uint64_t closed_form = 0;  // integrals given in closed form, with no numerical integration
  double cpu_seconds = 0;
};

class Integrator {
public:
  virtual ~Integrator() = default;
  virtual IntegratorKind kind() const = 0;
  std::string name() const { return to_string(kind()); }
  virtual std::string description() const = 0;     // one line: method and its parameters
  virtual const ProductLayout& layout() const = 0;
  // Called once before a bake's integrate() calls with ALL its points (bake_points: row i is
  // points[i]), never concurrently with integrate(); integrate(points[i], i) may then use the other
  // points (the filter integrator reuses its neighbours' rays). A later call replaces the earlier
  // set. Default: nothing to prepare.
  virtual void prepare(std::span<const ShadePoint> points) const { (void)points; }
  // Whether prepare() does work that integrate() depends on (a row integrated unprepared costs
  // more, and a few rows timed alone do not predict a bake's cost).
  virtual bool prepares() const { return false; }
  // Writes one row of estimates (layout().width doubles) for the shade point. `point_index`
  // identifies the point for deterministic per-point randomisation. `std_error` (optional, same
  // width) receives each value's estimated standard error (0 for a deterministic integrator).
  // Thread-safe: called concurrently for different points.
  virtual void integrate(const ShadePoint& point, uint64_t point_index, std::span<double> out,
                         std::span<double> std_error = {}) const = 0;
  virtual IntegratorStats stats() const { return {}; }
  // Sets stats() back to zero (an integrator used by a pilot and then handed to the bake counts
  // the bake's work only). Not concurrently with integrate().
  virtual void reset_stats() const {}
  // One line on the work done so far, from stats(), for a tool to print after a bake; empty when
  // the integrator has nothing to add to its rays and time.
  virtual std::string work_summary() const { return {}; }
};

} // namespace prt::bake
