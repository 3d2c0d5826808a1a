// bake/bake/pipeline.h — the bake pipeline, written once for any receivers (docs/ARCHITECTURE.md §4, step 6):
//
//   receiver sets ─► choose ─► integrate ─► [baked: the caller writes the file] ─► check ─► correct
//
//   choose     with a target error E, the chooser's pilot on the job's pooled shade points picks
//              the integrator and its knob (bake/bake/choose.h); without one, the given spec.
//   integrate  each set's rows through the row loop (bake/bake/vertex_bake.h), or the caller's
//              rows (a sharded bake computes or merges chunks instead, PipelineHooks::rows).
//   check      a QMC reference on seeded rows of each set (bake/bake/error_report.h): with E, its
//              rays planned so that its own noise is within E/3 (plan_report_reference), as two
//              independent halves, the sets sharing the report's points by their rows, and the
//              pooled verdict (target_check_lines); without E, each set's own report.
//   correct    with E: when the check finds a product NOT met (the pilot's points missed where
//              the error sits), the job is baked again at the knob the measured error and the
//              pilot's rate call for (corrected_plan) and checked again; up to max_corrections
//              times, each from the plan the last check measured (the rate is a model, and one
//              step can fall short: spider.obj under studio.exr went 2.28 E → 1.29 E in one).
//
// A job is one product request over one or more receiver sets (bake/mesh/receivers.h):
// `prtbake vertex` runs one job over the mesh's vertices; a scene runs one job per distinct
// product request over its receivers' vertices, against the union of its occluders (bake/bake/
// scene_bake.h). A new receiver kind (the texels of a lightmap) is one more maker of ReceiverSets:
// nothing here and nothing in the integrators changes. The pipeline is silent: what a tool prints
// it prints from the hooks.
#pragma once

#include <bake/bake/choose.h>
#include <bake/bake/error_report.h>
#include <bake/bake/vertex_bake.h>
#include <bake/core/progress.h>
#include <bake/integrators/integrator.h>
#include <bake/mesh/mesh.h>
#include <bake/mesh/receivers.h>
#include <bake/visibility/accel.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace prt::bake {

// What every job of a pipeline shares.
struct PipelineSettings {
  // Without a target: what bakes. With one: the seed, the report's points and the pilot's start.
  IntegratorSpec integrator;
  double target_error = 0;        // E (> 0: choose, plan the check's reference, give the verdict)
  bool integrator_given = false;  // with E: the chooser considers integrator.kind alone
  // With E: the choice and the check's rays from counted work, not measured time, so the same on
  // any machine (--reproducible; sharded bakes).
  bool counted_costs = false;
  bool correct = true;            // with E: bake again while the check finds E missed ...
  // ... at most this many times: each bakes and checks the job again (together about 2× the bake
  // at its knob), so three bound a run at a few times its plan; a product still missed after them
  // is said so by its report (NOT met), not baked on without end.
  int max_corrections = 3;
  // The progress stages (one over every set of every job, so one ETA for the whole bake).
  std::string bake_stage = "baking vertices", check_stage = "checking the error";
};

// One product request over its receiver sets, and what the pipeline made of it.
struct BakeJob {
  std::string name;               // how logs name the job: its set, or its sets together
  ProductRequest request;
  std::vector<ReceiverSet> sets;

  // ---- filled by the pipeline ----
  IntegratorSpec spec;                     // what bakes (after a correction: the corrected plan)
  std::optional<IntegratorChoice> choice;  // with E
  std::shared_ptr<Integrator> integrator;
  std::string integrator_description;
  double setup_seconds = 0;                // making the integrator (its tables; the trees are shared)
  int pass = 0;                            // how many corrections baked it (0: the plan)
  std::optional<CheckedPlan> last_checked; // after a correction: the plan it corrected, as checked
  std::vector<VertexBake> rows;            // per set (empty with PipelineHooks::rows_only)
  std::optional<ReferencePlan> reference_plan;  // with E and a check
  std::vector<std::optional<ErrorReport>> reports;  // per set, when checked
  std::optional<ErrorReport> pooled;       // the sets' reports as one (with E: the verdict's input)

  size_t row_count() const;                // over the sets
  double cpu_seconds() const;              // of the rows, summed over the sets
};

// Where a caller speaks, writes or replaces a step. Every hook is optional.
struct PipelineHooks {
  // With E, after the job's pilot (before its rows).
  std::function<void(const BakeJob&)> chosen;
  // After the job's integrator is made (and before its rows).
  std::function<void(const BakeJob&)> ready;
  // Replaces the row loop for set `s` of `job` (a sharded bake: its worker computes chunks and
  // returns nothing; its merge reads them back). `monitor` is the bake stage's.
  std::function<VertexBake(const BakeJob& job, size_t s, const Monitor& monitor)> rows;
  bool rows_only = false;  // stop after the rows: no `baked`, checks or correction (a worker)
  std::function<void(const BakeJob&, size_t s)> set_baked;
  // Every job's rows are in: the caller writes the file, so that a check cancelled with Ctrl-C
  // (or one that takes longer than the user will wait) never costs the bake. Called again after
  // a correction's rows.
  std::function<void()> baked;
  std::function<void()> checking;                        // before the first check of a round
  std::function<void(const BakeJob&)> check_planned;     // with E: its reference plan is made
  std::function<void(const BakeJob&, size_t s)> set_checked;   // its report is final (after the finer check)
  std::function<void(const BakeJob&)> job_checked;       // its pooled report is made
  std::function<void(const BakeJob&, const IntegratorSpec& better)> correcting;
};

// What a tool says when PipelineHooks::correcting runs: "the check puts the bake's error above the
// target: baking again with KIND at KNOB (was KNOB; correction P: …)".
std::string correction_text(const BakeJob& job, const IntegratorSpec& better);

class BakePipeline {
public:
  // The occluders every job's rows see (a mesh in its own frame, its topology and trees); they
  // must outlive the pipeline.
  BakePipeline(const Mesh& occluders, const Topology& topology, const MeshAccel& accel, PipelineSettings settings,
               std::vector<BakeJob> jobs);

  const PipelineSettings& settings() const { return settings_; }
  std::vector<BakeJob>& jobs() { return jobs_; }
  const std::vector<BakeJob>& jobs() const { return jobs_; }

  // Choose (with E) and make each job's integrator; a job already planned is left as it is, so a
  // caller may plan first (a sharded bake names the plan in its manifest) and run after.
  void plan(const Monitor& monitor, const PipelineHooks& hooks = {});
  // plan, integrate, baked, check, correct (file comment). Run again after a rows_only run (a
  // sharded worker's), it integrates again through the hooks given then.
  void run(const Monitor& monitor, const PipelineHooks& hooks = {});

  // The check's reference for `job` (with E: its plan, with its share of the report's ray budget
  // and `check_cpu` CPU seconds, 0 with counted costs; job.spec.report_rays is set from it).
  void plan_check(BakeJob& job, double check_cpu, const Monitor& monitor);
  // The report points of set `s` of `job`: with E, the job's report_points shared by the sets'
  // rows (at least one each); without, report_points each.
  size_t report_points(const BakeJob& job, size_t s) const;

  // The dry run's estimate of a planned job: its integrator timed on `n` seeded rows of its sets
  // (by their pooled index), the CPU seconds per row. nullopt for an integrator that prepares
  // (Integrator::prepares: the filter, whose cost per row needs every row's pass-1 rays).
  std::optional<double> cpu_seconds_per_row(const BakeJob& job, size_t n) const;

private:
  // `before`: the rows of the stage done before this job's (advanced by its sets').
  void integrate(BakeJob& job, const Monitor& stage, uint64_t& before, const PipelineHooks& hooks);
  void check(const Monitor& monitor, const PipelineHooks& hooks, const std::vector<bool>& which);
  // A silhouette bake's R and S that its QMC reference could not tell (a sun needs ~10^5–10^6 rays
  // per point for E/3): checked again against the same integrator at kFinerFactor × N isolines on
  // the same points (ProductError::finer; bake/bake/choose.h "The check").
  void check_finer(BakeJob& job, const Monitor& monitor);
  // ProductError::mesh_rms of the job's reports: each set's over its rows, the pooled one's over all.
  void set_mesh_rms(BakeJob& job) const;
  static constexpr int kFinerFactor = 4;

  const Mesh& occluders_;
  const Topology& topology_;
  const MeshAccel& accel_;
  PipelineSettings settings_;
  std::vector<BakeJob> jobs_;
};

} // namespace prt::bake
