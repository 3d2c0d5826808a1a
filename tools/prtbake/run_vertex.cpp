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
#include "bounces.h"
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
  const bake::Mesh mesh = load_receiver_mesh(a, run.say);
  const bake::Topology topo = bake::build_topology(mesh);
  const std::string mesh_sha = mesh.source_sha256;
  const bake::WindingFacts winding = bake::winding_facts(mesh, topo);
  warn_inward(winding, a.flip_normals);
  const std::optional<bake::EnvMap> env = load_environment(a, run.say);
  const bake::ProductRequest req = product_request(a, env ? &*env : nullptr);

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

  // ---- interreflections (tools/prtbake/bounces.h): over the mesh's vertices.
  ReceiverBounces bounces(a, mesh.triangles.size());
  const bake::VertexField field(mesh);

  // ---- the file (formats/SCHEMA.md): written once the bake is whole, again with its report ----
  namespace F = prt::formats;
  auto write_bake = [&] {
    F::Asset asset;
    asset.root = root_info(a, mesh_sha);
    tool::set_mesh(asset.vertices, mesh);
    if (a.flip_normals) *asset.vertices.normals->source += ", flipped";
    const bake::VertexBake& result = bounces.rows(job.rows.front());
    tool::set_products(asset.vertices, result,
                       {job.integrator->name(), job.integrator_description, job.spec.samples(), job.spec.seed, a.transfer,
                        a.visibility, env ? &*env : nullptr, a.environment});
    F::VertexSet& v = asset.vertices;
    bounces.set_attributes(v.transfer_diffuse ? &*v.transfer_diffuse : nullptr,
                           v.radiance_band1 ? &*v.radiance_band1 : nullptr,
                           v.radiance_shadowed ? &*v.radiance_shadowed : nullptr);
    if (const auto& report = job.reports.front())
      asset.vertices.report = tool::report_of(*report, result.seconds, mesh.positions.size(), a.reproducible);
    tool::set_target_error(asset, a.target_error);
    write_file(a, asset);
  };
  ReceiverConsole console;
  bake::PipelineHooks hooks = console.hooks(a, run, write_bake);
  hooks.set_baked = [&](const bake::BakeJob& j, size_t) {
    const bake::VertexBake& result = j.rows.front();
    warn_no_sky(bake::count_no_sky(result), winding, [&] { return bake::probe_flipped_normals(mesh, topo, result); },
                a.flip_normals);
    // Chunks of other workers or runs: their threads are not recorded.
    if (run.say) print_rows_baked(j, shards && shards->threads_of_chunks() == 0);
    if (bounces.asked())
      bounces.bounce(field, *accel.rays(), result, j.sets.front().points, mesh.source, run, "vertex");
  };

  return console.run(a, run, pipeline, hooks, shards,
                     {"vertex", kToolkitVersion, a.command_line, mesh_sha, env ? env->info().sha256 : "no environment"});
}

} // namespace prt::tool
