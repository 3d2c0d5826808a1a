// tools/prtbake/run_vertex.cpp — `prtbake vertex` (commands.h): per-vertex products of a mesh, one
// job of the bake pipeline (bake/bake/pipeline.h); this file says what it does and writes the file.
#include <bake/bake/choose.h>
#include <bake/bake/diagnostics.h>
#include <bake/bake/error_report.h>
#include <bake/bake/pipeline.h>
#include <bake/bake/vertex_bake.h>
#include <bake/environment/envmap.h>
#include <bake/mesh/mesh.h>
#include <bake/mesh/receivers.h>
#include <bake/visibility/accel.h>
#include <formats/asset.h>

#include "bakefile.h"
#include "commands.h"
#include "output.h"
#include "shards.h"
#include "tool_main.h"

#include <algorithm>
#include <cstdio>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace prt::tool {

int run_vertex(const Args& a, const RunContext& run, std::optional<ShardedRows>& shards) {
  bake::MeshLoadOptions mopt;
  mopt.use_file_normals = a.file_normals;
  mopt.flip_normals = a.flip_normals;
  const bake::Mesh mesh = bake::load_mesh(a.input, mopt);
  const bake::Topology topo = bake::build_topology(mesh);
  const std::string mesh_sha = mesh.source_sha256;
  print_warnings(mesh.warnings);
  if (run.say)
    std::printf("mesh: %s: %zu vertices, %zu triangles (%zu file positions, %zu faces), normals %s%s\n",
                a.input.c_str(), mesh.positions.size(), mesh.triangles.size(), mesh.file_positions, mesh.file_faces,
                mesh.normal_source == bake::Mesh::NormalSource::File ? "from the file" : "angle-weighted",
                a.flip_normals ? ", flipped" : "");
  if (run.say && mesh.origin != Eigen::Vector3d::Zero())  // far from the world origin (bake/mesh/mesh.h, ORIGIN)
    std::printf("mesh: baked relative to its origin (%.17g, %.17g, %.17g); /mesh/positions holds world coordinates\n",
                mesh.origin.x(), mesh.origin.y(), mesh.origin.z());
  const bake::WindingFacts winding = bake::winding_facts(mesh, topo);
  warn_inward(winding, a.flip_normals);

  std::optional<bake::EnvMap> env;
  if (!a.environment.empty()) {
    env = bake::EnvMap::load(a.environment, a.up);
    const auto& i = env->info();
    if (run.say)
      std::printf("environment: %s: %dx%d %s, luminance max %.4g / mean %.4g (%.0fx), %llu negative pixel values "
                  "clamped to 0 (min seen %.3g)\n",
                  a.environment.c_str(), i.width, i.height, i.layout.c_str(), i.max_luminance, i.mean_luminance,
                  i.mean_luminance > 0 ? i.max_luminance / i.mean_luminance : 0.0,
                  (unsigned long long)i.negative_pixels_clamped, i.min_value_seen);
  }

  bake::ProductRequest req;
  req.ao = a.ao;
  req.transfer_order = a.transfer;
  req.visibility_order = a.visibility;
  req.radiance = env ? &*env : nullptr;
  if (a.shadowed) req.shadowed = req.radiance, req.shadowed_order = a.shadowed;

  const bake::MeshAccel accel(mesh, topo);  // the mesh's trees, shared by the pilot, the bake and the check
  // One pipeline job over the mesh's vertices (bake/bake/pipeline.h): with a target, the chooser
  // picks the integrator and its knob; the bake is written, then checked against a QMC reference,
  // and baked once more when the check finds the target missed.
  bake::PipelineSettings settings;
  settings.integrator = a.integrator;
  settings.target_error = a.target_error;
  settings.integrator_given = a.integrator_given;
  settings.counted_costs = a.reproducible;  // the same choice, and bytes, on any machine
  settings.correct = !a.worker;             // sharded rows cannot be baked again here
  std::vector<bake::BakeJob> jobs(1);
  jobs[0].name = a.input;
  jobs[0].request = req;
  jobs[0].sets.push_back(bake::vertex_receivers(mesh, topo, a.input));
  bake::BakePipeline pipeline(mesh, topo, accel, std::move(settings), std::move(jobs));
  const bake::BakeJob& job = pipeline.jobs().front();
  const std::vector<bake::ShadePoint>& points = job.sets.front().points;

  bake::PipelineHooks hooks;
  hooks.chosen = [&](const bake::BakeJob& j) {
    if (run.say && a.verbose)
      for (const std::string& line : bake::choice_lines(*j.choice)) std::printf("%s\n", line.c_str());
    else if (run.say)
      std::printf("%s\n", bake::choice_summary(*j.choice).c_str());
    warn_unreached(*j.choice, "");
  };
  hooks.ready = [&](const bake::BakeJob& j) {
    if (!run.say) return;
    std::printf("baking:");
    if (a.ao) std::printf(" ao");
    if (a.transfer) std::printf(" transfer/diffuse (order %d, %d coefficients)", a.transfer, a.transfer * a.transfer);
    if (a.visibility) std::printf(" transfer/visibility (order %d, %d coefficients)", a.visibility, a.visibility * a.visibility);
    if (env) std::printf(" radiance/band1 (3x3)");
    if (a.shadowed) std::printf(" radiance/shadowed (order %d, 3x%d)", a.shadowed, a.shadowed * a.shadowed);
    std::printf("\nintegrator: %s; %d threads; setup (ray/contour BVHs, tables) %.2f s\n",
                j.integrator_description.c_str(), run.threads, j.setup_seconds);
    std::fflush(stdout);
  };
  hooks.set_baked = [&](const bake::BakeJob& j, size_t) {
    const bake::VertexBake& result = j.rows.front();
    warn_no_sky(bake::count_no_sky(result), winding, [&] { return bake::probe_flipped_normals(mesh, topo, result); },
                a.flip_normals);
    if (!run.say) return;
    std::printf("baked %zu vertices in %.2f s (%.0f integrals/s)\n", mesh.positions.size(), result.seconds,
                mesh.positions.size() / result.seconds);
    if (const std::string work = j.integrator->work_summary(); !work.empty()) std::printf("%s\n", work.c_str());
    if (shards && shards->threads_of_chunks() == 0)  // chunks of other workers or runs: their threads are not recorded
      std::printf("chunks: %.2f CPU s in the integrator over %.2f s of chunk wall time, summed over the chunks of "
                  "every worker and run\n",
                  result.cpu_seconds, result.seconds);
    else
      std::printf("threads busy %.0f%% of the bake (%.2f CPU s in the integrator over %.2f s on %d thread%s)\n",
                  100 * result.busy_fraction(), result.cpu_seconds, result.seconds, result.threads,
                  result.threads == 1 ? "" : "s");
  };

  // ---- the file (formats/SCHEMA.md): written once the bake is whole, again with its report ----
  namespace F = prt::formats;
  auto write_bake = [&] {
    F::Asset asset;
    asset.root = root_info(a, mesh_sha);
    tool::set_mesh(asset.vertices, mesh);
    if (a.flip_normals) *asset.vertices.normals->source += ", flipped";
    const bake::VertexBake& result = job.rows.front();
    tool::set_products(asset.vertices, result,
                       {job.integrator->name(), job.integrator_description, job.spec.samples(), job.spec.seed, a.transfer,
                        a.visibility, env ? &*env : nullptr, a.environment});
    if (const auto& report = job.reports.front())
      asset.vertices.report = tool::report_of(*report, result.seconds, mesh.positions.size(), a.reproducible);
    tool::set_target_error(asset, a.target_error);
    write_file(a, asset);
  };
  // The bake is written first and checked after (the check re-writes the file with its report):
  // a check cancelled with Ctrl-C, or one that costs more than the user will wait, never costs the bake.
  bool written = false, rebaking = false;  // the file holds a bake; a correction's rows are being made
  hooks.baked = [&] {
    write_bake();
    written = true;
    rebaking = false;
  };
  hooks.checking = [&] {
    if (run.say)
      std::printf("checking its error (Ctrl-C keeps the file as written, without its report; --report 0 skips the check)\n");
  };
  hooks.check_planned = [&](const bake::BakeJob& j) {
    if (run.say && a.verbose) print_reference_plan(*j.reference_plan);
  };
  hooks.set_checked = [&](const bake::BakeJob& j, size_t) {
    if (!run.say) return;
    const bake::ErrorReport& report = *j.reports.front();
    std::printf("error against a %u-ray QMC reference on %zu seeded vertices (reference took %.2f s, not "
                "counted in the bake time):\n",
                j.spec.reference_rays(), report.vertices.size(), report.reference_seconds);
    // The bake's own standard error is a sampled integrator's estimate; a deterministic one
    // (silhouette: its error is a bias, which only the comparison measures) has none to print.
    const bool sampled = std::any_of(report.products.begin(), report.products.end(),
                                     [](const auto& e) { return e.bake_std_error > 0; });
    for (const auto& e : report.products) {
      std::printf("  %-20s RMSE %.3e  max %.3e  relative RMSE %.3e  (", bake::product_label(e.product), e.rmse, e.max_abs,
                  e.reference_rms > 0 ? e.rmse / e.reference_rms : 0.0);
      if (sampled) std::printf("bake's estimated std. error %.3e; ", e.bake_std_error);
      std::printf("the reference's own std. error %.3e, %s)\n", e.reference_std_error,
                  report.reference_noise_measured ? "measured from its two halves" : "QMC's estimate");
    }
  };
  hooks.job_checked = [&](const bake::BakeJob& j) {
    if (run.say && a.target_error > 0)
      for (const std::string& line :
           bake::target_check_lines(*j.pooled, a.target_error, j.reference_plan ? &*j.reference_plan : nullptr))
        std::printf("%s\n", line.c_str());
    write_bake();
  };
  hooks.correcting = [&](const bake::BakeJob& j, const bake::IntegratorSpec& better) {
    rebaking = true;
    if (!run.say) return;
    std::printf("the check puts the bake's error above the target: baking again with %s at %s (was %s; the "
                "pilot's rate from the check's measured error; once)\n",
                bake::to_string(better.kind), better.knob_text().c_str(), j.spec.knob_text().c_str());
    std::fflush(stdout);
  };

  try {
    pipeline.plan(run.progress, hooks);
    if (a.worker) {
      // Sharded: every worker computes chunks of the rows; the merging process reads them back
      // (shards.h). The manifest names the plan, so that chunks of another plan are refused.
      const bake::IntegratorSpec& spec = job.spec;
      const std::string manifest = tool::manifest_of(
          {"vertex", kToolkitVersion, a.command_line, mesh_sha, env ? env->info().sha256 : "no environment",
           job.integrator_description, bake::to_string(spec.kind), std::to_string(spec.samples()),
           std::to_string(spec.seed), std::to_string(job.integrator->layout().width), std::to_string(a.shard.chunk_rows)});
      shards.emplace(*a.worker, run.mpi, a.shard, a.output, manifest, std::vector<uint64_t>{points.size()},
                     std::vector<uint32_t>{uint32_t(job.integrator->layout().width)}, a.quiet);
      bake::PipelineHooks work;
      work.rows_only = true;
      work.rows = [&](const bake::BakeJob& j, size_t, const bake::Monitor&) {
        shards->work([&](const bake::ChunkRange& r, const bake::Monitor& monitor) {
          return tool::bake_chunk(points, r, *j.integrator, monitor);
        });
        return bake::VertexBake{};
      };
      if (!shards->run([&] { pipeline.run(run.progress, work); })) return 0;
      hooks.rows = [&](const bake::BakeJob& j, size_t, const bake::Monitor&) {
        return shards->merge(0, j.integrator->layout());
      };
    }
    pipeline.run(run.progress, hooks);
  } catch (const bake::Cancelled&) {
    if (!written) throw;  // nothing written yet
    if (rebaking)
      std::fprintf(stderr, "prtbake: cancelled while baking again: %s holds the first bake and its error report\n",
                   a.output.c_str());
    else
      std::fprintf(stderr,
                   "prtbake: cancelled during the error check: %s holds the finished bake without its error report "
                   "(--report 0 skips the check)\n",
                   a.output.c_str());
    return tool::kExitCancelled;
  }
  if (shards) shards->finish();
  return 0;
}

} // namespace prt::tool
