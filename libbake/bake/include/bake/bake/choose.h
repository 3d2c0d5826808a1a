// bake/bake/choose.h — "ask for an error, not a sample count": the integrator and its knob that reach a
// target RMSE at the lowest cost, chosen from a pilot on the object itself (docs/ARCHITECTURE.md
// §6 "Error reports"; paper 001 §5 and Table 1: the silhouette integrator wins on small and
// medium meshes, ray casting on large ones, and where the crossover lies depends on the asset).
//
// What the target E means (the same numbers the error report prints, bake/bake/vertex_bake.h):
//   AO, diffuse transfer T_i, visibility transfer U_i: the RMSE over the values of the product
//     (every coefficient of every vertex), absolute — these are dimensionless (AO in [0, 1],
//     |T_i| <= 1/√π, |U_i| <= 2√π);
//   band-1 radiance R_c,m and shadowed radiance S_c,i: the RMSE relative to the RMS of the
//     product over the whole mesh (their unit is the environment's, which E cannot know). The
//     error report divides by the bake's own RMS over every row (ProductError::mesh_rms); the
//     pilot by an estimate of it (the integrator at N = 16 on up to 1,024 seeded points, its own
//     among them), since its 32–128 points' RMS can be far from the mesh's.
// Every requested product must meet E.
//
// The pilot (choose_integrator), on a seeded sample of the bake's shade points (a 64th of them,
// 32 to 128):
//  1. reference: the silhouette integrator at N_ref isolines, starting at 256 (E >= 5e-4) or
//     512, exact up to its isoline discretisation. Its own error is ESTIMATED, per product, in
//     E's units, so that "error at N" means error against the truth within a stated margin:
//       Richardson: d = RMSE(R_{N_ref/2} − R_{N_ref}) on the pilot points; the order a from the
//       ratio of d to RMSE(R_{N_ref/4} − R_{N_ref/2}), clamped to [1, 2] (1: first order, the
//       slowest the integrator shows under HDR suns; the clamp's top keeps a lucky ratio from
//       promising too much); e_ref = d / (2^a − 1) — at a = 1 the error of N_ref is taken to be
//       as large as its whole step from N_ref/2;
//       independent check, under an environment (R, S): its hot texels are integrated apart
//       from the isolines, so their error need not shrink with N and Richardson cannot see it.
//       QMC at R and R/4 rays (independent seeds) on the first 32 pilot points, f and c, run after
//       the pick: R = 16,384, or fewer by octaves (down to 1,024) where those rays would cost
//       more than the chosen plan (choose.cpp, kCheckBudgetShare; the detection limit grows as
//       sqrt(16,384/R), and the error report after the bake checks the file at E/3 anyway):
//       their noises are independent of each other and of the reference's error b, so the
//       per-point means x_i of (f − ref)(c − ref) average b² (no convergence rate assumed). The
//       values of one point share its rays, so the points are the independent draws: the bound is
//       sqrt(max(0, mean(x) − 3·sd(x)/√K)) — band-1 biases from ~2–3e-3 relative show (choose.cpp,
//       kCheckRays). (It was a spread over the n values as if independent: a sun sample moves all
//       nine band-1 numbers of a point together, and the check saw a bias of 1.2e-3 under
//       studio.exr where the reference was within 1.6e-4 of QMC at 2^20 rays.) Without an
//       environment, the pilot's finest QMC level with its estimated standard errors (which
//       overstate QMC's noise: only gross biases show), at no extra cost;
//     e_ref = the larger. While the worst product's Richardson estimate exceeds kReferenceShare·E
//     (E/3) the reference level doubles, up to the memory bound below — except in a small bake,
//     where every point at the reference level costs no more CPU than that level's build: there
//     the reference is the plan (step 5), so it stops once its estimate meets the plan's aim
//     (IntegratorChoice::reference_is_plan) and step 2 runs no level but Richardson's two. A bias the QMC check sees
//     is stated, not chased: both integrate the same environment (constant per texel, the
//     silhouette's tables holding each texel's mass exactly), so what Richardson cannot see is not
//     an isoline error that finer isolines remove (chasing it, before the tables held texels
//     exactly, sent a 285-triangle mesh to 147,456 QMC rays, 115 s); if e_ref still exceeds E/3,
//     IntegratorChoice::reference_ok is false and the printed lines say so (the pilot's errors
//     are then only known to within e_ref).
//  2. silhouette at N = 32 and 64, then 16 if a product already meets the goal at 32, and
//     doubling levels (N_ref/4 and N_ref/2 always run: Richardson needs them) while one still
//     misses it: the RMSE against the reference per product; the model RMSE(N) = C N^-a through
//     the two levels that bracket the goal (the first level that meets it and the one before;
//     the last two when none does), a clamped to [0.5, 3], solved for the smallest even N with
//     RMSE <= safety·E. The knob is bounded by the reference level N_ref (whose estimated error
//     is at most E/3) and by memory: the isoline tables hold components × (N² + N) doubles
//     (isoline_table_bytes), which must fit kTableMemoryShare of physical memory
//     (sysconf(_SC_PHYS_PAGES)); the model extrapolates at most kMaxExtrapolation (4×) beyond
//     the last measured level, and the printed model line says when it extrapolates.
//  3. QMC at 64, 256, 1024, 4096 rays and on by factors of 4 while the goal (0.8·E) is missed
//     and the level's rays on the pilot points stay within 2^22 (stopping once two levels are run and the
//     last meets the goal): the same against the reference; RMSE(R) = C R^-b with b fitted between
//     the levels that bracket the goal (the last two when none meets it) and clamped to [0.5, 1]
//     (randomised QMC converges between the Monte Carlo rate 1/2 and 1; ~0.7 on the bunny),
//     solved for the rays, rounded up to an eighth of an octave, at most kMaxExtrapolation × the
//     last measured level (and kMaxRays); the levels stop early once one misses the goal at a
//     cost per integral above the silhouette prediction (QMC cannot win then: more rays cost
//     more), or when even its best case (rate 1: R·e/goal rays at this level's cost per ray)
//     costs twice that prediction;
//  4. costs: the CPU time of every pilot integral (each thread's own CPU clock, so the thread
//     count does not enter), per point; silhouette cost(N) linear in N through the measured
//     levels (the contour search does not depend on N, the walk does), QMC cost linear in rays;
//     with counted_costs, the pilot's counted work priced at fixed constants instead (below).
//  5. the pick. First the reference level as the silhouette plan (Prediction::built): the pilot
//     built its integrator, so it costs no setup and its error is the reference's estimate; it
//     replaces the model's plan where it meets the aim (or errs less than a plan that misses it)
//     at no more than that plan's cost with its setup, and the bake takes the pilot's integrator
//     (IntegratorChoice::integrator) — on a small mesh under an environment the tables' build
//     (524,288 texel masses) is most of a bake, and a lower N would build them again. The pilot's
//     levels share those masses and the hot texels (SilhouetteEnvCache), so a level costs its
//     cells and points, not the map. Then (pick_plan, a pure function of the plans' predicted
//     errors and costs): the cheapest
//     plan predicted to reach its safety·E; if none does, the plan with the lowest predicted
//     error (the cheaper on a tie) — a default never refuses: the choice states the error it
//     expects (IntegratorChoice::expected_error, reaches = false) and how to go further
//     (IntegratorChoice::further). Then the sanity check: when another integrator's plan costs
//     less than a quarter (kSanityCostRatio) of the chosen one and predicts an error within 2×E
//     (kSanityErrorFactor), it is MEASURED on the pilot points against the reference and taken if
//     it meets its safety·E or is no worse than the chosen plan's prediction (the "chosen:" line
//     says so). This is what stops a model that extrapolates "cannot reach" from sending a
//     285-triangle mesh to 122,880 QMC rays (39.7 s) where N = 256 isolines meets E in 0.3 s.
// With `only` set (the user named an integrator), only its knob is chosen. The filter integrator
// (bake/integrators/filter.h) is not modelled: its error depends on the neighbours' rays, which a pilot on
// scattered vertices does not see; only = Filter is an InputError (give its rays), and the
// unrestricted choice is between the other two.
//
// The error report's reference (plan_report_reference): QMC, its rays chosen from its MEASURED
// noise so that its own error is at most E/3 in E's units for every product. Measured, not
// taken from QMC's standard-error estimator: two independent QMC runs on the report's first
// points (4,096 and 16,384 rays, different seeds) differ by d, RMS over the values; with noise
// falling as 1/sqrt(rays) (Monte Carlo's rate, the slowest randomised QMC shows) the coarse run's
// noise is d/sqrt(1 + 1/4) and the reference's at R rays that times sqrt(4096/R). (The estimator,
// an i.i.d. variance, overstates QMC's actual error many times over: 5.5e-4 on AO at 2M rays on
// sphereWithHole.stl where the bake agreed with the reference to 2.5e-5.) Never fewer than the
// spec's default reference rays, at most kReportRayBudget rays in all (a scene shares it among its
// receivers by their vertices); when the budget binds, the
// plan says per product what it would need, and target_check_lines says why it cannot verify.
//
// Determinism: the knobs are functions of the inputs and the seed (the pilot's values are), but
// WHICH integrator wins depends on measured CPU time, so two runs whose predicted costs are close
// may choose differently and then bake different (each correct to E) values. The choice is
// printed and stored in the file (its integrator and samples); pinning it (--integrator K
// --samples N) gives the same bytes on any machine. IntegratorChoice::margin says how close it
// was. With counted_costs (prtbake --reproducible, SOURCE_DATE_EPOCH) every cost is priced
// work instead of time and the memory bound a fixed budget (kCountedTableMemoryBudget), so the
// whole choice is a function of the inputs and the seed. Otherwise the memory bound depends on
// the machine's physical memory when it binds (N in the thousands);
// ChooserOptions::memory_budget_bytes pins it. The report's reference rays are a
// function of the inputs, the seed and E.
#pragma once

#include <bake/bake/error_report.h>
#include <bake/bake/vertex_bake.h>
#include <bake/core/progress.h>
#include <bake/integrators/integrator.h>
#include <bake/integrators/products.h>
#include <bake/mesh/mesh.h>

#include <cstdint>
#include <functional>
#include <memory>
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
  // The pilot's reference must be this much more accurate than E (its estimated error <= E/3):
  // the pilot's RMSE against it is then within ~5% of the RMSE against the truth at the goal
  // (errors add in quadrature: sqrt(0.7² + 0.33²) = 0.77 vs 0.7).
  static constexpr double kReferenceShare = 1.0 / 3.0;
  // The sanity check (file comment, step 5): an alternative plan costing less than
  // 1/kSanityCostRatio of the chosen one and predicting at most kSanityErrorFactor·E is measured.
  static constexpr double kSanityCostRatio = 4.0, kSanityErrorFactor = 2.0;
  // A model extrapolates at most this factor beyond the last knob it measured.
  static constexpr double kMaxExtrapolation = 4.0;
  // The isoline tables of one silhouette integrator may take this share of physical memory (the
  // pilot holds two: its reference and a level; the bake's reference is QMC).
  static constexpr double kTableMemoryShare = 0.125;
  // The tables' budget with counted_costs (a function of the inputs, not of the machine): 2 GiB,
  // the share above of a 16 GiB machine.
  static constexpr size_t kCountedTableMemoryBudget = size_t(2) << 30;
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
  // The pilot reference's first level (0: 256 for E >= 5e-4, else 512) and its highest (0: the
  // memory bound). Tests force a coarse reference with these; tools leave them 0.
  uint32_t reference_isolines = 0, max_reference_isolines = 0;
  // The memory the isoline tables may take (0: kTableMemoryShare of physical memory).
  size_t memory_budget_bytes = 0;
};

// Bytes of the isoline tables of a silhouette integrator at N u-isolines for `request`:
// components × rows × 8, rows = Σ_i (2·cells_per_sheet(i) + 1) = N² + N (bake/sphere/isoline_tables.h),
// components = 3 (AO) + 3·Lt² + Lv² + 9 (R) + 3·Ls² (bake/integrators/silhouette.h). The hot texels' sparse
// tables are not counted (they are small).
size_t isoline_table_bytes(const ProductRequest& request, int isolines);
// The largest even N whose tables fit `budget_bytes` (0: kTableMemoryShare of physical memory),
// at least 8.
int max_isolines_for_memory(const ProductRequest& request, size_t budget_bytes = 0);
// kTableMemoryShare of sysconf(_SC_PHYS_PAGES) × page size (4 GiB when it cannot be read).
size_t default_table_memory_budget();

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
  bool reachable = false;            // the model reaches its safety·E within the knob's bound
  // QMC only: its pilot stopped at `knob` rays, which missed the goal and already cost more per
  // integral than the silhouette prediction (more rays cost more): it cannot win. The error and
  // cost below are those measured there.
  bool pruned = false;
  uint32_t knob = 0;                 // N (silhouette) or rays (QMC)
  double exponent = 0;               // the fitted convergence rate of the worst product
  double predicted_error = 0;        // of the worst product, in E's units
  double predicted_us_per_point = 0; // CPU µs per integral
  uint32_t last_measured = 0;        // the highest knob the pilot measured
  uint32_t bound = 0;                // the highest knob allowed (see bound_reason)
  std::string bound_reason;          // what bounds it: memory, the reference, the extrapolation limit
  bool extrapolated = false;         // knob > last_measured: the model's value, not a measurement
  uint32_t knob_for_target = 0;      // unbounded model's knob for safety·E (0: not needed / none)
  // Silhouette only: the plan is the pilot's reference level, whose integrator the pilot built and
  // hands to the bake (IntegratorChoice::integrator): it costs no setup, its error is the
  // reference's estimate. Taken where that costs no more than the model's plan with its setup —
  // on a small mesh the tables' build is most of a bake (sphereWithHole.stl: 855 rows at N = 256
  // in 0.05 CPU s against a fresh build of N = 74's tables, 0.05 s, and its rows).
  bool built = false;
};

// The final pick's input (pick_plan): one plan per kind.
struct PlanCandidate {
  IntegratorKind kind = IntegratorKind::Silhouette;
  uint32_t knob = 0;
  double predicted_error = 0;        // E's units
  double aim = 0;                    // safety·E of this kind
  double cost_seconds = 0;           // the whole bake (setup + integrals)
};
struct PlanPick {
  size_t index = 0;                  // into the candidates
  bool reaches = false;              // its error (measured when checked) is within its aim
  double expected_error = 0;         // predicted, or measured when the sanity check took it
  bool checked = false;              // the sanity check measured an alternative
  size_t checked_index = 0;          // which one
  double checked_error = 0;          // its measured error
  bool switched = false;             // and took it
};
// The pick of the file comment's step 5. `measure(candidate)` returns a candidate's error measured
// on the pilot points (called only by the sanity check). Pure apart from `measure`.
PlanPick pick_plan(std::span<const PlanCandidate> candidates, double target,
                   const std::function<double(const PlanCandidate&)>& measure);

struct IntegratorChoice {
  IntegratorSpec spec;               // the chosen kind and knob; seed and report from `base`
  double target = 0;
  std::vector<Product> products;     // the order of PilotRun::error
  std::vector<PilotRun> runs;        // the reference's run first (error: its estimated error)
  std::vector<Prediction> predictions;
  double margin = 0;                 // predicted cost of the other kind / the chosen one's (0: one kind)
  size_t pilot_points = 0;
  double pilot_seconds = 0;          // wall time of the whole pilot
  bool counted_costs = false;        // PilotRun::cpu_us_per_point holds counted costs
  // The pilot's reference (file comment, step 1): its level, its estimated error per product
  // (E's units) and how (Richardson, the QMC check), whether it is within E/3, and what
  // stopped it from going finer when it is not.
  uint32_t reference_isolines = 0;
  std::vector<double> reference_error;
  double reference_richardson_order = 0;  // the order a used (worst product)
  bool reference_ok = true;
  // A small bake (every point at the reference level costs no more than building a level): the
  // reference stopped doubling once within the plan's aim, and it is the plan (Prediction::built).
  bool reference_is_plan = false;
  // Per product (the order of PilotRun::error): what the pilot's relative errors divide by, the
  // product's RMS over the mesh as estimated (0: the pilot's own points' RMS, or not relative).
  std::vector<double> relative_scale;
  std::string reference_note;
  int max_isolines = 0;              // the memory bound on N
  std::string max_isolines_reason;
  // The pick (step 5): whether the chosen plan is predicted to reach E, the error it expects,
  // and (when it does not reach) how to go further; the sanity check's outcome.
  bool reaches = true;
  double expected_error = 0;
  std::string further;
  std::string sanity;                // empty: no check ran
  bool sanity_switched = false;
  std::string reason;                // one line: why this integrator
  // The chosen plan's integrator when the pilot built it (Prediction::built): the bake takes it
  // (BakePipeline) instead of building the same again. Null otherwise.
  std::shared_ptr<Integrator> integrator;
};

// The pilot and the choice (file comment). `points` are the bake's shade points (their order and
// count as the bake will see them), `mesh`/`topology` the occluders. Throws InputError only when
// the target is outside [kMinTarget, kMaxTarget] or only = Filter: an unreachable target bakes the
// best plan within the knobs' bounds and says so (reaches, expected_error, further). A "pilot"
// stage of `monitor`. Every pilot integrator shares one set of trees: `accel`'s (bake/visibility/accel.h;
// pass the bake's own, so that the bake reuses them too), else the pilot's own.
IntegratorChoice choose_integrator(std::span<const ShadePoint> points, const Mesh& mesh, const Topology& topology,
                                   const ProductRequest& request, const IntegratorSpec& base,
                                   const ChooserOptions& options, const Monitor& monitor = {},
                                   const MeshAccel* accel = nullptr);

// The error report's QMC reference for target E (file comment): rays per point and, per product,
// the noise measured and expected at them (E's units) and the rays that E/3 would need.
struct ReferencePlan {
  static constexpr uint32_t kReportProbeRays = 4096, kReportProbeRaysFine = 16384;
  static constexpr uint32_t kReportProbePoints = 32;  // of the report's points (its first, seeded)
  // The report's reference rays in all (points × rays): 2^24, ~8-12 CPU s at 0.5-0.75 µs per
  // ray (bench/RESULTS.md, QMC sweeps), 2× the default report's 128 × 65,536. A check that costs
  // more than the bake is a cost users notice (2^26 took 35 s after a 0.01 s bake of
  // sphereWithHole.stl under city.exr); where the budget binds the report says what E/3 would
  // need, and a "met" verdict stays sound (its RMSE includes the reference's noise).
  static constexpr uint64_t kReportRayBudget = uint64_t(1) << 24;
  // The CPU seconds tools give the check at least (plan_report_reference's cpu_seconds).
  static constexpr double kReportMinCpuSeconds = 2.0;
  double target = 0;
  uint32_t rays = 0;                   // per point
  size_t points = 0;                   // the report's points
  std::vector<Product> products;
  std::vector<double> noise;           // measured, scaled to `rays` (E's units)
  std::vector<size_t> probe_values;    // the values each product's noise was measured on
  std::vector<double> estimator_noise; // QMC's own standard-error estimate at `rays` (an upper bound)
  std::vector<uint64_t> rays_needed;   // for noise <= E/3
  uint64_t ray_budget = 0;             // the rays in all it could spend
  double cpu_seconds = 0;              // the CPU time it was given (0: none, rays alone bound it)
  bool cpu_bound = false;              // that time, not kReportRayBudget, set ray_budget
  double us_per_ray = 0;               // the probe's CPU µs per ray (its finer level; counted costs: timed all the same)
  bool budget_bound = false;           // the budget kept some product above E/3
  double probe_seconds = 0;
};
// Measures the QMC reference's noise on the first kReportProbePoints of the report's seeded points
// (compare_points_with_reference with spec.report_points and spec.seed) and sizes the reference:
// at least spec.reference_rays() (its default), rounded up like the chooser's rays. Deterministic
// (seeded QMC). Set spec.report_rays = plan.rays for make_reference.
// `ray_budget`: the rays in all it may spend (0: kReportRayBudget); a scene shares
// kReportRayBudget among its receivers by their vertices. `cpu_seconds` > 0 bounds it further by
// the CPU time the check may take, converted to rays at the probe's measured cost per ray (tools
// give it as long as the bake, at least kReportMinCpuSeconds: a check that costs many times the
// bake is a cost users notice); the floor is then the probe's 16,384 rays, not the default
// reference's. Not with counted costs (the rays would depend on the machine).
ReferencePlan plan_report_reference(std::span<const ShadePoint> points, const Mesh& mesh, const Topology& topology,
                                    const ProductRequest& request, const IntegratorSpec& spec, double target,
                                    const Monitor& monitor = {}, const MeshAccel* accel = nullptr,
                                    uint64_t ray_budget = 0, double cpu_seconds = 0);

// What a tool prints about a choice (libbake prints nothing): the pilot table, each kind's model
// and the choice, one line each, then a hint when the call was close (margin < 1.25).
std::vector<std::string> choice_lines(const IntegratorChoice& choice);
// The same in one line: the target, what was chosen and why (IntegratorChoice::reason: its
// predicted error and µs per integral), and the pilot's size and time.
std::string choice_summary(const IntegratorChoice& choice);

// After the bake, one line per product against the target E. The measured RMSE m includes the
// reference's own noise σ (m² = e² + σ², independent errors). When the report's reference was two
// independent halves (ErrorReport::reference_noise_measured), σ is measured on the report's own
// n values and e² is known to ±δσ², δ = 3·sqrt(4/n): the line states the bake's own error
// e = sqrt(m² − σ²) and its range [sqrt(m² − σ²(1+δ)), sqrt(m² − σ²(1−δ))]. Otherwise σ is an
// upper bound (the plan's probe, or QMC's estimate): e lies in [sqrt(m² − σ²), m]. "met" when the
// range's top is within E (always when m <= E), "NOT met" when its bottom exceeds E, else "not
// verifiable here", saying why (the rays E/3 would have needed against the report's budget).
std::vector<std::string> target_check_lines(const ErrorReport& report, double target,
                                            const ReferencePlan* plan = nullptr);
// Without a target, one line per product saying what its RMSE means: the bake's own error with
// the reference's noise taken out, and its range (target_verdicts' numbers, without a verdict).
std::vector<std::string> error_estimate_lines(const ErrorReport& report);
// The numbers behind each line (per product, in E's units).
struct TargetVerdict {
  Product product = Product::Ao;
  double measured = 0;               // m, the RMSE against the reference
  double noise = 0;                  // σ, the reference's own
  bool noise_measured = false;       // σ measured on the report's values (else an upper bound)
  const char* noise_kind = "";
  double error = 0, error_lo = 0, error_hi = 0;  // the bake's own error and its range
  bool met = false, not_met = false; // neither: not verifiable here
  // The reference was the bake's integrator at f = ProductError::finer times its knob: the
  // difference m = R(N) − R(fN) is c·N^-a·(1 − f^-a) at the integrator's order a ∈ [1, 2] (the
  // pilot's clamp), so the bake's own error c·N^-a lies in [m/(1 − f^-2), m/(1 − f^-1)] and the
  // finer level's in [m/(f² − 1), m/(f − 1)]. `error` is the top of the range (what a correction
  // aims from), `noise` the finer level's own error at its top.
  bool extrapolated = false;
  double finer = 0;
  uint32_t finer_knob = 0;
  size_t finer_points = 0;
};
std::vector<TargetVerdict> target_verdicts(const ErrorReport& report, double target, const ReferencePlan* plan = nullptr);

// The correction after a check (the chooser's pilot under-predicts where the error sits on a few
// vertices it did not sample; the check's 128 vertices saw them): when some product is NOT met, or
// its best estimate (noise measured and taken out) is above E though the range straddles it,
// the knob of `baked` (the plan that made the checked rows: the choice's, or an earlier
// correction's) raised by the kind's model rate (Prediction::exponent, at least 1/2) so that the
// worst such product's measured error falls to its safety·E — N·(e/aim)^(1/a) isolines (even) or
// R·(e/aim)^(1/a) rays — within the kind's bound (Prediction::bound). nullopt when nothing is above
// E, `baked` is not the choice's kind, or the knob cannot rise. With `previous` (the plan an
// earlier check measured, below `baked`'s knob), the rate is the slower of the model's and the
// one the two checks measured on the worst product, at least 1/2. The pipeline bakes the plan and
// checks again, at most PipelineSettings::max_corrections times.
struct CheckedPlan {
  IntegratorSpec spec;
  std::vector<TargetVerdict> verdicts;
};
std::optional<IntegratorSpec> corrected_plan(const IntegratorChoice& choice, const IntegratorSpec& baked,
                                             std::span<const TargetVerdict> verdicts,
                                             const CheckedPlan* previous = nullptr);

// Pools reports of disjoint point sets: each of `add`'s products is merged into `into`'s entry of
// the same product (appended when new), as if one report had compared all their values: values
// add, rmse, reference_rms and the standard errors are RMS weighted by values, max_abs the max.
void pool_product_errors(std::vector<ProductError>& into, std::span<const ProductError> add);

// The report's error of `product` in the target's units (the file comment): RMSE, or RMSE / RMS of
// the reference for band-1 radiance.
double error_in_target_units(const ProductError& error);

namespace detail {
// The chooser's power law through two measured levels (x0, e0), (x1, e1), x0 < x1, its rate
// clamped to [lo, hi] (choose.cpp): the knob where it reaches `goal`, and its error at `knob`.
// The two agree (the error at the knob is the goal), also when the measured rate exceeds hi.
double power_law_knob(double x0, double e0, double x1, double e1, double goal, double lo, double hi);
double power_law_error_at(double x0, double e0, double x1, double e1, double knob, double lo, double hi);
} // namespace detail

} // namespace prt::bake
