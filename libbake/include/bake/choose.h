// bake/choose.h — "ask for an error, not a sample count": the integrator and its knob that reach a
// target RMSE at the lowest cost, chosen from a pilot on the object itself (docs/ARCHITECTURE.md
// §6 "Error reports"; paper 001 §5 and Table 1: the silhouette integrator wins on small and
// medium meshes, ray casting on large ones, and where the crossover lies depends on the asset).
//
// What the target E means (the same numbers the error report prints, bake/vertex_bake.h):
//   AO, diffuse transfer T_i, visibility transfer U_i: the RMSE over the values of the product
//     (every coefficient of every vertex), absolute — these are dimensionless (AO in [0, 1],
//     |T_i| <= 1/√π, |U_i| <= 2√π);
//   band-1 radiance R_c,m and shadowed radiance S_c,i: the RMSE relative to the RMS of the
//     reference values (their unit is the environment's, which E cannot know).
// Every requested product must meet E.
//
// The pilot (choose_integrator), on a seeded sample of the bake's shade points (a 64th of them,
// 32 to 128):
//  1. reference: the silhouette integrator at N_ref = 256 u-isolines for E >= 5e-4, else 512,
//     exact up to its isoline discretisation, which falls as ~N^-1.5..-2 (bench/RESULTS.md,
//     error against time): ~6e-5 AO RMSE on the bunny at 256, ~3e-5 at 512, a tenth or less of
//     the aim (the error report, against QMC, verifies the bake); the silhouette knob is capped
//     at N_ref;
//  2. silhouette at N = 32 and 64, then 16 if a product already meets the goal at 32 and 128 if
//     one still misses it at 64: the RMSE against the reference per product; the model
//     RMSE(N) = C N^-a through the two levels that bracket the goal (the first level that meets
//     it and the one before; the last two when none does), a clamped to [0.5, 3], solved for
//     the smallest even N with RMSE <= 0.7·E
//     (ChooserOptions: the safety factors);
//  3. QMC at 64, 256, 1024 and 4096 rays (stopping once two levels are run and the last meets the
//     goal, 0.8·E for QMC): the same against the reference; RMSE(R) = C R^-b with b fitted between the levels
//     that bracket the goal (the last two when none meets it) and clamped to [0.5, 1]
//     (randomised QMC converges between the Monte Carlo rate 1/2 and 1; ~0.7 on the bunny),
//     solved for the rays, rounded up to an eighth of an octave (randomised Halton points
//     stratify any count);
//     the levels stop early once one misses the goal at a cost per integral above the
//     silhouette prediction (QMC cannot win then: more rays cost more), or when even its best
//     case (rate 1: R·e/goal rays at this level's cost per ray) costs twice that prediction;
//  4. costs: the CPU time of every pilot integral (each thread's own CPU clock, so the thread
//     count does not enter), per point; silhouette cost(N) linear in N through the measured
//     levels (the contour search does not depend on N, the walk does), QMC cost linear in rays;
//     with counted_costs, the pilot's counted work priced at fixed constants instead (below).
// The cheaper prediction wins. With `only` set (the user named an integrator), only its knob is
// chosen. The filter integrator (bake/filter.h) is not modelled: its error depends on the
// neighbours' rays, which a pilot on scattered vertices does not see; only = Filter is an
// InputError (give its rays), and the unrestricted choice is between the other two.
//
// Determinism: the knobs are functions of the inputs and the seed (the pilot's values are), but
// WHICH integrator wins depends on measured CPU time, so two runs whose predicted costs are close
// may choose differently and then bake different (each correct to E) values. The choice is
// printed and stored in the file (its integrator and samples); pinning it (--integrator K
// --samples N) gives the same bytes on any machine. IntegratorChoice::margin says how close it
// was. With counted_costs (prtbake --reproducible, SOURCE_DATE_EPOCH) every cost is priced
// work instead of time and the whole choice is a function of the inputs and the seed.
#pragma once

#include <bake/integrator.h>
#include <bake/mesh.h>
#include <bake/products.h>
#include <bake/progress.h>
#include <bake/vertex_bake.h>

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace prt::bake {

struct ChooserOptions {
  static constexpr double kMinTarget = 1e-4;  // below: the pilot reference is not exact enough
  static constexpr double kMaxTarget = 0.1;
  // The error report's points when a target is given and the report size is not: an RMSE over
  // the default 32 is too rough to check a target with.
  static constexpr uint32_t kReportPoints = 128;
  double target = 1e-3;                       // E, see the file comment
  std::optional<IntegratorKind> only;         // choose only this kind's knob
  // Seeded shade points of the pilot: a kPilotFraction-th of the bake's, at least 32 (all of
  // them if fewer) and at most this. A pilot point costs ~4-5 bake integrals (the reference at
  // 256 isolines ~2, the levels 32 and 64 ~2, QMC at 64 rays ~0.5 on small assets), so a 64th
  // keeps the pilot under ~10% of the bake from 2,048 shade points up (bench_target_error: a
  // 16th cost 0.1-0.2 CPU s, 24-73% of the bakes of 1.5k-4k vertices); from 8,192 up it is 128.
  static constexpr uint32_t kPilotFraction = 64;
  uint32_t pilot_points = 128;
  // Aim at safety·E: the pilot's RMSE is itself an estimate from a sample. The silhouette
  // integrator's error is a discretisation error concentrated at a few vertices (a heavy-tailed
  // sample RMSE: measured on 128 other vertices it came out up to 1.36x the pilot's prediction,
  // bench/RESULTS.md "bench_target_error"); QMC's is noise spread over every vertex (0.9-1.05x).
  double safety_silhouette = 0.7, safety_qmc = 0.8;
  // Price each integral by counted work (the silhouette integrator's contour edges and
  // crossings per point, QMC's rays; fixed per-unit costs calibrated on the project's machine,
  // choose.cpp) instead of measured CPU time, so the whole choice is a function of the inputs
  // and the seed: same bytes on any machine (prtbake sets it with --reproducible). Within
  // ~2x of the measured costs (memory-bound searches on large meshes are dearer per edge).
  bool counted_costs = false;
};

// One pilot run: an integrator at one knob on the pilot points.
struct PilotRun {
  IntegratorKind kind = IntegratorKind::Silhouette;
  uint32_t knob = 0;                 // N u-isolines (silhouette) or rays (QMC)
  std::vector<double> error;         // per product (IntegratorChoice::products): RMSE in E's units
  double cpu_us_per_point = 0;       // mean CPU time of one integral (counted: its priced work)
};

// A kind's prediction at the knob the model chose for it.
struct Prediction {
  IntegratorKind kind = IntegratorKind::Silhouette;
  bool reachable = false;            // the model reaches its safety·E within the knob's range
  // QMC only: its pilot stopped at `knob` rays, which missed the goal and already cost more per
  // integral than the silhouette prediction (more rays cost more): it cannot win. The error and
  // cost below are those measured there.
  bool pruned = false;
  uint32_t knob = 0;                 // N (silhouette) or rays (QMC)
  double exponent = 0;               // the fitted convergence rate of the worst product
  double predicted_error = 0;        // of the worst product, in E's units
  double predicted_us_per_point = 0; // CPU µs per integral
};

struct IntegratorChoice {
  IntegratorSpec spec;               // the chosen kind and knob; seed and report from `base`
  double target = 0;
  std::vector<Product> products;     // the order of PilotRun::error
  std::vector<PilotRun> runs;        // the reference's run first (error 0)
  std::vector<Prediction> predictions;
  double margin = 0;                 // predicted cost of the other kind / the chosen one's (0: one kind)
  size_t pilot_points = 0;
  double pilot_seconds = 0;          // wall time of the whole pilot
  bool counted_costs = false;        // PilotRun::cpu_us_per_point holds counted costs
  std::string reason;                // one line: why this integrator
};

// The pilot and the choice (file comment). `points` are the bake's shade points (their order and
// count as the bake will see them), `mesh`/`topology` the occluders. Throws InputError when the
// target is outside [kMinTarget, kMaxTarget] or no integrator is predicted to reach it (naming the
// best reachable error). A "pilot" stage of `monitor`. Every pilot integrator shares one set of
// trees: `accel`'s (bake/accel.h; pass the bake's own, so that the bake reuses them too), else
// the pilot's own.
IntegratorChoice choose_integrator(std::span<const ShadePoint> points, const Mesh& mesh, const Topology& topology,
                                   const ProductRequest& request, const IntegratorSpec& base,
                                   const ChooserOptions& options, const Monitor& monitor = {},
                                   const MeshAccel* accel = nullptr);

// What a tool prints about a choice (libbake prints nothing): the pilot table, each kind's model
// and the choice, one line each, then a hint when the call was close (margin < 1.25).
std::vector<std::string> choice_lines(const IntegratorChoice& choice);
// The same in one line: the target, what was chosen and why (IntegratorChoice::reason: its
// predicted error and µs per integral), and the pilot's size and time.
std::string choice_summary(const IntegratorChoice& choice);

// After the bake, one line per product: its error in the target's units against the target,
// "met", "NOT met", or "not verifiable here" when it is above E but the reference's own estimated
// noise (which the measured RMSE includes, in the same units) is at least E/2.
std::vector<std::string> target_check_lines(const ErrorReport& report, double target);

// The report's error of `product` in the target's units (the file comment): RMSE, or RMSE / RMS of
// the reference for band-1 radiance.
double error_in_target_units(const ProductError& error);

} // namespace prt::bake
