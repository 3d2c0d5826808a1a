// tools/prtbake/run_fiv.cpp — `prtbake fiv` (commands.h): an occluder's Fullsphere Irradiance
// Vectors on shells around it, the environment's FIV and the DifMap, in one process or sharded
// (shards.h), and their error against a QMC reference.
#include <bake/bake/fiv.h>
#include <bake/bake/vertex_bake.h>
#include <bake/core/error.h>
#include <bake/environment/envmap.h>
#include <bake/environment/irradiance.h>
#include <bake/integrators/registry.h>
#include <bake/mesh/mesh.h>
#include <formats/asset.h>

#include "bakefile.h"
#include "commands.h"
#include "output.h"
#include "shards.h"
#include "tool_main.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace fs = std::filesystem;

namespace prt::tool {
namespace {

// The row sets of a sharded FIV bake (shards.h): the DifMap's texels (3 values each), the
// environment FIV (one row of its 9 values), then shell k's samples (FivShellRows::kRowWidth
// values each) in set kFirstShellSet + k.
constexpr uint32_t kDifMapSet = 0, kEnvironmentFivSet = 1, kFirstShellSet = 2;

// The DifMap, the environment FIV and the FIV shells of a sharded bake. Every worker takes slabs
// of rows set after set and stops past the first complete shell that meets the stopping rule; the
// merging process joins the DifMap, the environment FIV and the shells up to that one. nullopt:
// this process does not merge. `topo` and `env` are needed by a process that computes rows only
// (a merge joins committed rows: the environment's identity `env_info` is all it needs). `sharded`
// is emplaced here; the caller removes the chunks (finish()) once the file is written.
struct ShardedFiv {
  std::vector<float> cube;
  bake::Fiv environment{};
  bake::FivShells shells;
};
std::optional<ShardedFiv> sharded_fiv(const Args& a, const tool::Worker& worker, const tool::MpiSession& mpi,
                                      const bake::Mesh& mesh, const bake::Topology* topo, const bake::EnvMap* env,
                                      const bake::EnvMapInfo& env_info, std::optional<tool::ShardedRows>& sharded) {
  PRT_CHECK(!worker.computes || (topo && env));
  const bake::ShellSpec& sp = a.shell_spec;
  const bake::FivShellRows baker =
      worker.computes ? bake::FivShellRows(mesh, *topo, *env, sp) : bake::FivShellRows(mesh, sp);
  std::vector<uint64_t> set_rows = {uint64_t(6) * uint64_t(sp.cube) * uint64_t(sp.cube), 1};
  std::vector<uint32_t> widths = {3, uint32_t(std::tuple_size_v<bake::Fiv>)};
  for (int k = 0; k < baker.shell_count(); ++k)
    set_rows.push_back(baker.rows_per_shell()), widths.push_back(uint32_t(bake::FivShellRows::kRowWidth));
  // What each set holds, its rows and width: chunks of another layout belong to another bake.
  std::string layout = "sets: DifMap texels, environment FIV, shell samples:";
  for (size_t s = 0; s < set_rows.size(); ++s) layout += " " + std::to_string(set_rows[s]) + "x" + std::to_string(widths[s]);
  char spec[256];
  std::snprintf(spec, sizeof spec, "%dx%dx%d inner %.17g fraction %.17g k %u cube %d", sp.n_phi, sp.n_theta, sp.n_rho,
                sp.inner, sp.fraction, unsigned(sp.silhouette_k), sp.cube);
  // Chunks of the geometric scheme keep their manifest (their bakes resume); the surface scheme's differ.
  std::string spec_text = spec;
  if (sp.radial == bake::RadialScheme::surface) {
    char more[64];
    std::snprintf(more, sizeof more, " radial surface first_offset %.17g", sp.first_offset);
    spec_text += more;
  }
  const std::string manifest = tool::manifest_of({"fiv", kToolkitVersion, a.command_line, mesh.source_sha256, env_info.sha256,
                                                  spec_text, layout, std::to_string(a.shard.chunk_rows)});
  tool::ShardedRows& shards = sharded.emplace(worker, mpi, a.shard, a.output, manifest, set_rows, widths, a.quiet);
  // The set of the first shell, in order, that is complete in the chunk directory and meets the rule.
  int checked = 0;
  bake::ChunkData rows;  // one buffer for every set read back
  const auto last_set = [&]() -> std::optional<uint32_t> {
    for (; checked < baker.shell_count() && shards.complete(kFirstShellSet + uint32_t(checked)); ++checked)
      if (baker.may_stop_after(checked)) {
        shards.join(kFirstShellSet + uint32_t(checked), rows);
        if (baker.stops_after(checked, rows.values)) return kFirstShellSet + uint32_t(checked);
      }
    return std::nullopt;
  };
  std::optional<bake::UnshadowedIrradiance> irradiance;  // built for this worker's first DifMap chunk
  const bool merges = shards.run([&] {
    shards.work(
        [&](const bake::ChunkRange& r, const bake::Monitor& monitor) {
          bake::ChunkData d;
          bake::Task task(monitor, r.set < kFirstShellSet ? "environment FIV and DifMap" : "FIV shell rows", r.rows());
          const double cpu0 = tool::process_cpu_seconds();
          if (r.set == kDifMapSet) {
            if (!irradiance) irradiance.emplace(*env);
            const std::vector<float> texels = bake::irradiance_cube_texels(*irradiance, sp.cube, r.begin, r.end);
            d.values.assign(texels.begin(), texels.end());
            task.advance(r.rows());
          } else if (r.set == kEnvironmentFivSet) {
            const bake::Fiv f = bake::environment_fiv(*env);
            d.values.assign(f.begin(), f.end());
            task.advance(r.rows());
          } else {
            d.values = baker.rows(int(r.set - kFirstShellSet), r.begin, r.end, &task);
          }
          task.finish();
          d.seconds = task.elapsed_seconds();
          d.cpu_seconds = tool::process_cpu_seconds() - cpu0;
          return d;
        },
        std::nullopt, last_set);
  });
  if (!merges) return std::nullopt;
  ShardedFiv out;
  shards.join(kDifMapSet, rows);
  out.cube.assign(rows.values.begin(), rows.values.end());
  shards.join(kEnvironmentFivSet, rows);
  std::copy(rows.values.begin(), rows.values.end(), out.environment.begin());
  out.shells = baker.empty_shells();
  for (int k = 0; k < baker.shell_count(); ++k) {
    shards.join(kFirstShellSet + uint32_t(k), rows);
    baker.append(out.shells, k, rows.values);
    out.shells.seconds += rows.seconds;
    if (baker.stops_after(k, rows.values)) break;
  }
  baker.finish(out.shells);
  return out;
}

} // namespace

int run_fiv(const Args& a, const RunContext& run, std::optional<ShardedRows>& shards) {
  bake::MeshLoadOptions mopt;
  mopt.use_file_normals = false;  // an occluder's normals play no part in its FIVs
  const bake::Mesh mesh = bake::load_mesh(a.input, mopt);
  print_warnings(mesh.warnings);
  // A merge (--merge) joins committed rows: it needs the environment's identity (its SHA-256, in
  // the manifest and the file) but not its pixels, nor the mesh's topology, unless its error
  // report integrates a reference. The workers loaded the same bytes (the manifest holds their
  // SHA-256) and checked the pixels.
  // The self-shadows (--self-shadows vertex) are baked by the process that writes the file, the
  // merge of a sharded bake included: it needs the environment's pixels and the topology too.
  const bool integrates = !a.worker || a.worker->computes || a.integrator.report_points > 0 || a.shell_spec.vertex_self_shadows;
  std::optional<bake::Topology> topo;
  std::optional<bake::EnvMap> env;
  if (integrates) {
    topo = bake::build_topology(mesh);
    env = bake::EnvMap::load(a.environment, a.up);
  }
  const bake::EnvMapInfo env_info = env ? env->info() : bake::EnvMap::identify(a.environment);
  if (run.say)
    std::printf("occluder: %s: %zu triangles; environment: %s (%dx%d %s)\n", a.input.c_str(), mesh.triangles.size(),
                a.environment.c_str(), env_info.width, env_info.height, env_info.layout.c_str());

  std::optional<ShardedFiv> sharded;
  if (a.worker) {
    sharded = sharded_fiv(a, *a.worker, run.mpi, mesh, topo ? &*topo : nullptr, env ? &*env : nullptr, env_info, shards);
    if (!sharded) return 0;
  }
  const auto t0 = std::chrono::steady_clock::now();
  const bake::Fiv fenv = sharded ? sharded->environment : bake::environment_fiv(*env);
  const std::vector<float> cube = sharded ? std::move(sharded->cube) : bake::irradiance_cube(*env, a.shell_spec.cube);
  const double env_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  bake::FivShells shells =
      sharded ? std::move(sharded->shells) : bake::bake_fiv_shells(mesh, *topo, *env, a.shell_spec, run.progress);
  if (run.say) {
    std::printf("environment FIV and %dx%dx6 DifMap in %.2f s%s\n", a.shell_spec.cube, a.shell_spec.cube, env_seconds,
                sharded ? " (both in the chunks)" : "");
    const bool surface = shells.radial == bake::RadialScheme::surface;
    std::printf("shells: %dx%dx%zu (of %d requested; %s scheme: %s %.3g to %.3g%s; bounding radius %.4g) in %.2f s "
                "(%.0f integrals/s)\n",
                a.shell_spec.n_phi, a.shell_spec.n_theta, shells.radii.size(), a.shell_spec.n_rho,
                std::string(bake::radial_scheme_name(shells.radial)).c_str(), surface ? "offsets" : "radii",
                shells.radii.front(), shells.radii.back(), surface ? " from the surface" : "", shells.radius,
                shells.seconds, double(shells.integrals) / shells.seconds);
    if (shells.extrapolated > 0)
      std::printf("%zu samples found inside the occluder, extrapolated along their radial lines\n", shells.extrapolated);
  }

  namespace F = prt::formats;
  F::Asset asset;
  asset.root = root_info(a, mesh.source_sha256);
  tool::set_fiv_environment(asset, env_info, a.environment, fenv, cube, a.shell_spec.cube);
  const std::string name = tool::safe_name(fs::path(a.input).stem().string());
  std::optional<F::ReportRow> report;
  if (a.integrator.report_points > 0) {
    // Error against a QMC reference (65,536 rays, full-sphere mode) at seeded shell samples.
    const bake::FivErrorReport r = bake::fiv_error_report(mesh, *topo, *env, shells, fenv, a.integrator.report_points,
                                                          a.integrator.seed, run.progress);
    if (run.say)
      std::printf("error against a %u-ray QMC reference at %zu seeded shell samples (reference took %.2f s, not "
                  "counted): RMSE %.3e, max %.3e, RMSE / RMS|F_env| %.3e (reference's own std. error %.3e)\n",
                  bake::IntegratorSpec::kSilhouetteReferenceRays, r.points, r.reference_seconds, r.rmse, r.max_abs,
                  r.reference_rms > 0 ? r.rmse / r.reference_rms : 0.0,
                  r.reference_std_error);
    report = tool::fiv_report_of(name, r, shells, a.reproducible);
  }
  // Self-shadows (--self-shadows vertex): the occluder's band-1 radiance at its vertices, by the
  // silhouette integrator at the shells' k and seed (prtshade/fiv.h shade_fiv_member_given_self),
  // here in the process that writes the file (a sharded bake's merge too: the same bytes; an
  // occluder's vertices take a fraction of its shells' time, so they are not cut into chunks).
  if (a.shell_spec.vertex_self_shadows) {
    const bake::FivSelfShadows self = bake::bake_fiv_self_shadows(mesh, *topo, *env, a.shell_spec, a.integrator.seed, run.progress);
    if (run.say)
      std::printf("self-shadows: band-1 radiance at %zu vertices in %.2f s\n", mesh.positions.size(), self.values.seconds);
    tool::set_mesh(asset.vertices, mesh);
    tool::set_products(asset.vertices, self.values,
                       {self.integrator_name, self.integrator_description, self.integrator.samples(), self.integrator.seed, 0, 0,
                        &*env, a.environment});
  }
  // The shells move into the file's occluder (the report above was their last reader).
  asset.occluders.push_back(tool::occluder_of(name, std::move(shells), env_info, a.environment, a.shell_spec.fraction,
                                              a.shell_spec.silhouette_k));
  asset.occluders.back().report = std::move(report);
  write_file(a, asset);
  if (shards) shards->finish();
  return 0;
}

} // namespace prt::tool
