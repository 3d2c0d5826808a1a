// tools/prtbake/run_texel.cpp — `prtbake texel` (commands.h): the products of `prtbake vertex` per
// texel of a lightmap. The mesh's lightmap UV set — or one generated for it (bake/mesh/unwrap.h)
// when it has none, or on --unwrap — gives the atlas's texels and their shade points
// (bake/mesh/texels.h); texels inside the geometry are found (bake/visibility/enclosure.h) and
// left out of the bake; the rest are one job of the bake pipeline (bake/bake/pipeline.h), as a
// vertex bake's vertices are; the rows become a lightmap image, filled and padded
// (bake/bake/lightmap.h), written as /lightmap/... beside the mesh (format v5).
#include <bake/bake/lightmap.h>
#include <bake/bake/lightmap_receivers.h>
#include <bake/bake/pipeline.h>
#include <bake/environment/envmap.h>
#include <bake/mesh/mesh.h>
#include <bake/mesh/texels.h>
#include <bake/visibility/accel.h>
#include <formats/asset.h>

#include "bakefile.h"
#include "bounces.h"
#include "commands.h"
#include "output.h"
#include "tool_main.h"

#include <cstdio>
#include <optional>
#include <string>
#include <vector>

namespace prt::tool {
namespace {

bake::LightmapSpec lightmap_spec(const Args& a) {
  bake::LightmapSpec s;
  s.width = a.lightmap_width, s.height = a.lightmap_height;
  s.density = a.lightmap_width == 0 ? a.lightmap_density : 0;
  s.uv_set = a.uv_set;
  s.unwrap = a.unwrap;
  s.gutter = a.gutter, s.padding = a.padding;
  s.min_chart_texels = a.min_chart_texels;
  s.stitch = !a.no_stitch;
  return s;
}

} // namespace

int run_texel(const Args& a, const RunContext& run, std::optional<ShardedRows>& shards) {
  const bake::Mesh mesh = load_receiver_mesh(a, run.say);
  const bake::Topology topo = bake::build_topology(mesh);
  warn_inward(bake::winding_facts(mesh, topo), a.flip_normals);
  const std::optional<bake::EnvMap> env = load_environment(a, run.say);
  const bake::ProductRequest req = product_request(a, env ? &*env : nullptr);
  const bake::MeshAccel accel(mesh, topo);
  // The texels (bake/bake/lightmap_receivers.h): the UV set, generated when the mesh has none (and
  // --uv names none) or on --unwrap; the atlas; the texels inside the geometry, left out.
  const bake::LightmapSpec spec = lightmap_spec(a);
  const bake::LightmapReceivers texels = bake::lightmap_receivers(mesh, topo, spec, *accel.rays(), a.input);
  const bake::TexelAtlas& atlas = texels.atlas;
  const bake::UvSet& uv = texels.uv;
  if (run.say && texels.generated)
    print_generated_uvs(a.input, texels.unwrap_asked ? "--unwrap" : "no UV set", uv.name, *texels.generated);
  if (atlas.shared_texels > atlas.overlapping_texels)
    std::fprintf(stderr,
                 "prtbake: warning: %s: %zu texels of the %ux%u lightmap are touched by two charts of UV set %s: too "
                 "little gutter at this resolution (bilinear filtering bleeds one chart into the other)\n",
                 a.input.c_str(), atlas.shared_texels, atlas.width, atlas.height, uv.name.c_str());
  warn_inexact_texels(atlas, a.input);
  if (run.say) {
    std::printf("lightmap: %ux%u texels in UV set %s: %zu covered (%zu by the nearest point of a triangle touching "
                "the texel, not its centre), %u charts; %zu inside the geometry, filled from their charts\n",
                atlas.width, atlas.height, uv.name.c_str(), atlas.samples.size(), atlas.texels_off_centre(), atlas.charts,
                atlas.samples.size() - texels.valid.size());
    if (atlas.lifted_samples > 0)
      std::printf("lightmap: %zu texels lie a few roundings in front of their triangles, not on them (corners whose "
                  "coordinates differ in scale by more than 2^29 leave no double on the surface there)\n",
                  atlas.lifted_samples);
  }

  bake::PipelineSettings settings;
  settings.integrator = a.integrator;
  settings.target_error = a.target_error;
  settings.integrator_given = a.integrator_given;
  settings.counted_costs = a.reproducible;
  settings.bake_stage = "baking texels";
  std::vector<bake::BakeJob> jobs(1);
  jobs[0].name = a.input;
  jobs[0].request = req;
  jobs[0].sets.push_back(texels.receivers());
  bake::BakePipeline pipeline(mesh, topo, accel, std::move(settings), std::move(jobs));
  const bake::BakeJob& job = pipeline.jobs().front();

  // ---- interreflections (tools/prtbake/bounces.h): over the lightmap's texels. A hit reads the
  // previous bounce's lightmap (filled and padded, 2 rings: all a bilinear lookup at level 0 reaches
  // from a chart's surface) at its UV.
  ReceiverBounces bounces(a, mesh.triangles.size());
  const bake::TexelField field(mesh, texels, 2);

  namespace F = prt::formats;
  auto write_bake = [&] {
    const bake::VertexBake& result = bounces.rows(job.rows.front());
    bake::SeamStitch seams;
    const bake::Lightmap image = lightmap_image(mesh, topo, texels, spec, result, seams);
    if (run.say && seams.edges > 0) print_stitch(seams);
    if (run.say) print_mip_check(bake::mip_empty_hits(image, atlas, uv));
    F::Asset asset;
    asset.root = root_info(a, mesh.source_sha256);
    tool::set_mesh(asset.vertices, mesh);
    if (a.flip_normals) *asset.vertices.normals->source += ", flipped";
    tool::set_lightmap(asset.vertices, mesh, uv, atlas, image, result.layout,
                       {job.integrator->name(), job.integrator_description, job.spec.samples(), job.spec.seed, a.transfer,
                        a.visibility, env ? &*env : nullptr, a.environment},
                       a.padding);
    F::Lightmap& lm = *asset.vertices.lightmap;
    bounces.set_attributes(lm.transfer_diffuse ? &*lm.transfer_diffuse : nullptr,
                           lm.radiance_band1 ? &*lm.radiance_band1 : nullptr,
                           lm.radiance_shadowed ? &*lm.radiance_shadowed : nullptr);
    if (const auto& report = job.reports.front()) {
      bake::ErrorReport by_texel = *report;  // its rows are valid texels: named by their texels
      for (uint32_t& r : by_texel.vertices) r = atlas.samples[texels.valid[r]].texel;
      asset.vertices.report = tool::report_of(by_texel, result.seconds, texels.valid.size(), a.reproducible);
    }
    tool::set_target_error(asset, a.target_error);
    write_file(a, asset);
    if (run.say && image.unfilled > 0)
      std::printf("lightmap: %zu texels inside the geometry had no valid neighbour in their chart: padded from the "
                  "charts around them\n",
                  image.unfilled);
  };

  ReceiverConsole console;
  bake::PipelineHooks hooks = console.hooks(a, run, write_bake);
  hooks.set_baked = [&](const bake::BakeJob& j, size_t) {
    if (run.say) print_rows_baked(j, shards && shards->threads_of_chunks() == 0);
    if (bounces.asked())
      bounces.bounce(field, *accel.rays(), j.rows.front(), j.sets.front().points, mesh.source, run, "texel");
  };
  // Sharded, the chunks are the valid texels' rows in texel order; the atlas they belong to is
  // in the manifest (a chunk of another atlas, UV set or texel count is refused).
  return console.run(a, run, pipeline, hooks, shards,
                     {"texel", kToolkitVersion, a.command_line, mesh.source_sha256,
                      env ? env->info().sha256 : "no environment",
                      std::to_string(atlas.width) + "x" + std::to_string(atlas.height) + " texels in UV set " + uv.name +
                          ", " + std::to_string(texels.valid.size()) + " of " + std::to_string(atlas.samples.size()) +
                          " covered texels baked"});
}

} // namespace prt::tool
