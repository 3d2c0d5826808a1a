// tools/prtbake/run_vertex.cpp — `prtbake vertex` (commands.h): per-vertex products of a mesh.
// With a target error the chooser picks the integrator and its knob; the bake is written, then
// checked against a QMC reference, and baked once more when the check finds the target missed.
#include <bake/bake/choose.h>
#include <bake/bake/diagnostics.h>
#include <bake/bake/error_report.h>
#include <bake/bake/vertex_bake.h>
#include <bake/environment/envmap.h>
#include <bake/integrators/registry.h>
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
#include <chrono>
#include <cstdio>
#include <memory>
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

  bake::IntegratorSpec spec = a.integrator;
  const bake::MeshAccel accel(mesh, topo);  // the mesh's trees, shared by the pilot, the bake and the report
  std::optional<bake::IntegratorChoice> chosen;  // the chooser's, with a target
  if (a.target_error > 0) {
    bake::ChooserOptions copt;
    copt.target = a.target_error;
    if (a.integrator_given) copt.only = a.integrator.kind;
    copt.counted_costs = a.reproducible;  // the same choice, and bytes, on any machine
    const bake::IntegratorChoice choice = bake::choose_integrator(bake::vertex_shade_points(mesh, topo), mesh, topo, req,
                                                                  a.integrator, copt, run.progress, &accel);
    spec = choice.spec;
    chosen = choice;
    if (run.say && a.verbose)
      for (const std::string& line : bake::choice_lines(choice)) std::printf("%s\n", line.c_str());
    else if (run.say)
      std::printf("%s\n", bake::choice_summary(choice).c_str());
    warn_unreached(choice, "");
  }
  // Bake, write, check; when the check finds a product NOT met (the pilot's sample missed where the
  // error sits), bake once more at the knob the measured error and the model's rate call for
  // (bake/bake/choose.h corrected_plan), and check again.
  for (int pass = 0;; ++pass) {
    const auto setup_start = std::chrono::steady_clock::now();
    const std::unique_ptr<bake::Integrator> integrator_ptr =
        bake::make_integrator(spec, mesh, topo, req, &accel);
    const bake::Integrator& integrator = *integrator_ptr;
    const double setup_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - setup_start).count();
    if (run.say) {
      std::printf("baking:");
      if (a.ao) std::printf(" ao");
      if (a.transfer) std::printf(" transfer/diffuse (order %d, %d coefficients)", a.transfer, a.transfer * a.transfer);
      if (a.visibility) std::printf(" transfer/visibility (order %d, %d coefficients)", a.visibility, a.visibility * a.visibility);
      if (env) std::printf(" radiance/band1 (3x3)");
      if (a.shadowed) std::printf(" radiance/shadowed (order %d, 3x%d)", a.shadowed, a.shadowed * a.shadowed);
      std::printf("\nintegrator: %s; %d threads; setup (ray/contour BVHs, tables) %.2f s\n",
                  integrator.description().c_str(), run.threads, setup_seconds);
      std::fflush(stdout);
    }
    const std::vector<bake::ShadePoint> points = bake::vertex_shade_points(mesh, topo);
    bake::VertexBake result;
    if (a.worker) {
      const std::string manifest = tool::manifest_of(
          {"vertex", kToolkitVersion, a.command_line, mesh_sha, env ? env->info().sha256 : "no environment",
           integrator.description(), bake::to_string(spec.kind), std::to_string(spec.samples()),
           std::to_string(spec.seed), std::to_string(integrator.layout().width), std::to_string(a.shard.chunk_rows)});
      shards.emplace(*a.worker, run.mpi, a.shard, a.output, manifest, std::vector<uint64_t>{points.size()},
                     std::vector<uint32_t>{uint32_t(integrator.layout().width)}, a.quiet);
      const bool merges = shards->run([&] {
        shards->work([&](const bake::ChunkRange& r, const bake::Monitor& monitor) {
          return tool::bake_chunk(points, r, integrator, monitor);
        });
      });
      if (!merges) return 0;
      result = shards->merge(0, integrator.layout());
    } else {
      try {
        result = bake::bake_points(points, integrator, run.progress);
      } catch (const bake::Cancelled&) {
        if (pass == 0) throw;  // nothing written yet
        std::fprintf(stderr, "prtbake: cancelled while baking again: %s holds the first bake and its error report\n",
                     a.output.c_str());
        return tool::kExitCancelled;
      }
    }
    warn_no_sky(bake::count_no_sky(result), winding, [&] { return bake::probe_flipped_normals(mesh, topo, result); },
                a.flip_normals);
    if (run.say) {
      std::printf("baked %zu vertices in %.2f s (%.0f integrals/s)\n", mesh.positions.size(), result.seconds,
                  mesh.positions.size() / result.seconds);
      if (const std::string work = integrator.work_summary(); !work.empty()) std::printf("%s\n", work.c_str());
      if (shards && shards->threads_of_chunks() == 0)  // chunks of other workers or runs: their threads are not recorded
        std::printf("chunks: %.2f CPU s in the integrator over %.2f s of chunk wall time, summed over the chunks of "
                    "every worker and run\n",
                    result.cpu_seconds, result.seconds);
      else
        std::printf("threads busy %.0f%% of the bake (%.2f CPU s in the integrator over %.2f s on %d thread%s)\n",
                    100 * result.busy_fraction(), result.cpu_seconds, result.seconds, result.threads,
                    result.threads == 1 ? "" : "s");
    }

    // ---- the file (formats/SCHEMA.md) ----
    namespace F = prt::formats;
    std::optional<bake::ErrorReport> report;
    auto write_bake = [&] {
      F::Asset asset;
      asset.root = root_info(a, mesh_sha);
      tool::set_mesh(asset.vertices, mesh);
      if (a.flip_normals) *asset.vertices.normals->source += ", flipped";
      tool::set_products(asset.vertices, result,
                         {integrator.name(), integrator.description(), spec.samples(), spec.seed, a.transfer, a.visibility,
                          env ? &*env : nullptr, a.environment});
      if (report) asset.vertices.report = tool::report_of(*report, result.seconds, mesh.positions.size(), a.reproducible);
      tool::set_target_error(asset, a.target_error);
      write_file(a, asset);
    };
    if (spec.report_points == 0) {
      write_bake();
      if (shards) shards->finish();
      return 0;
    }
    // The bake is written first and checked after (the check re-writes the file with its report):
    // a check cancelled with Ctrl-C, or one that costs more than the user will wait, never costs the bake.
    write_bake();
    if (run.say) std::printf("checking its error (Ctrl-C keeps the file as written, without its report; --report 0 skips the check)\n");
    std::optional<bake::ReferencePlan> reference_plan;
    try {
      {
        if (a.target_error > 0) {  // a reference whose own noise is within E/3, or a budget that says why not
          // The check may take about as long as the bake (at least kReportMinCpuSeconds of CPU); not
          // with --reproducible, whose rays must not depend on the machine's speed.
          const double check_cpu =
              a.reproducible ? 0.0 : std::max(bake::ReferencePlan::kReportMinCpuSeconds, result.cpu_seconds);
          reference_plan = bake::plan_report_reference(points, mesh, topo, req, spec, a.target_error, run.progress, &accel, 0,
                                                       check_cpu);
          spec.report_rays = reference_plan->rays;
          if (run.say && a.verbose) print_reference_plan(*reference_plan);
        }
        // With a target, the reference is two independent halves: its noise is then measured on the
        // report's own values, and the check can take it out of the RMSE (target_check_lines).
        std::pair<std::unique_ptr<bake::Integrator>, std::unique_ptr<bake::Integrator>> reference;
        if (a.target_error > 0) reference = bake::make_reference_pair(spec, mesh, topo, req, &accel);
        else reference.first = bake::make_reference(spec, mesh, topo, req, &accel);
        report = bake::compare_with_reference(mesh, topo, result, *reference.first, spec.report_points, spec.seed,
                                              run.progress, reference.second.get());
        if (run.say) {
          std::printf("error against a %u-ray QMC reference on %zu seeded vertices (reference took %.2f s, not "
                      "counted in the bake time):\n",
                      spec.reference_rays(), report->vertices.size(), report->reference_seconds);
          // The bake's own standard error is a sampled integrator's estimate; a deterministic one
          // (silhouette: its error is a bias, which only the comparison measures) has none to print.
          const bool sampled = std::any_of(report->products.begin(), report->products.end(),
                                           [](const auto& e) { return e.bake_std_error > 0; });
          for (const auto& e : report->products) {
            std::printf("  %-20s RMSE %.3e  max %.3e  relative RMSE %.3e  (", bake::product_label(e.product), e.rmse,
                        e.max_abs, e.reference_rms > 0 ? e.rmse / e.reference_rms : 0.0);
            if (sampled) std::printf("bake's estimated std. error %.3e; ", e.bake_std_error);
            std::printf("the reference's own std. error %.3e, %s)\n", e.reference_std_error,
                        report->reference_noise_measured ? "measured from its two halves" : "QMC's estimate");
          }
          if (a.target_error > 0)
            for (const std::string& line : bake::target_check_lines(*report, a.target_error, reference_plan ? &*reference_plan : nullptr))
              std::printf("%s\n", line.c_str());
        }
      }
      write_bake();
    } catch (const bake::Cancelled&) {
      std::fprintf(stderr,
                   "prtbake: cancelled during the error check: %s holds the finished bake without its error report "
                   "(--report 0 skips the check)\n",
                   a.output.c_str());
      return tool::kExitCancelled;
    }
    if (pass > 0 || !chosen || a.worker || !report) break;
    const std::optional<bake::IntegratorSpec> better = bake::corrected_plan(
        *chosen, bake::target_verdicts(*report, a.target_error, reference_plan ? &*reference_plan : nullptr));
    if (!better) break;
    if (run.say) {
      std::printf("the check puts the bake's error above the target: baking again with %s at %s (was %s; the "
                  "pilot's rate from the check's measured error; once)\n",
                  bake::to_string(better->kind), better->knob_text().c_str(), spec.knob_text().c_str());
      std::fflush(stdout);
    }
    spec = *better;
    spec.report_rays = 0;
    report.reset();
  }
  if (shards) shards->finish();
  return 0;
}

} // namespace prt::tool
