// tools/prtbake/run_texel.cpp — `prtbake texel` (commands.h): the products of `prtbake vertex` per
// texel of a lightmap. The mesh's lightmap UV set — or one generated for it (bake/mesh/unwrap.h)
// when it has none, or on --unwrap — gives the atlas's texels and their shade points
// (bake/mesh/texels.h); texels inside the geometry are found (bake/visibility/enclosure.h) and
// left out of the bake; the rest are one job of the bake pipeline (bake/bake/pipeline.h), as a
// vertex bake's vertices are; the rows become a lightmap image, filled and padded
// (bake/bake/lightmap.h), written as /lightmap/... beside the mesh (format v5).
#include <bake/bake/lightmap.h>
#include <bake/bake/pipeline.h>
#include <bake/core/error.h>
#include <bake/environment/envmap.h>
#include <bake/mesh/mesh.h>
#include <bake/mesh/texels.h>
#include <bake/mesh/unwrap.h>
#include <bake/visibility/accel.h>
#include <bake/visibility/enclosure.h>
#include <formats/asset.h>

#include "bakefile.h"
#include "commands.h"
#include "output.h"
#include "tool_main.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <cstdio>
#include <string>
#include <vector>

namespace prt::tool {
namespace {

// The UV set to bake in: --uv's, else TEXCOORD_1 (glTF's lightmap set by convention), else the
// mesh's only set. InputError naming the mesh and its sets otherwise.
const bake::UvSet& lightmap_uvs(const bake::Mesh& mesh, const std::string& wanted) {
  std::string names;
  for (const bake::UvSet& s : mesh.uv_sets) names += (names.empty() ? "" : ", ") + s.name;
  auto find = [&](const std::string& name) -> const bake::UvSet* {
    for (const bake::UvSet& s : mesh.uv_sets)
      if (s.name == name) return &s;
    return nullptr;
  };
  if (!wanted.empty()) {
    if (const bake::UvSet* s = find(wanted)) return *s;
    throw bake::InputError(mesh.source, "has no UV set '" + wanted + "'" +
                                            (names.empty() ? std::string(" (it has none)") : " (it has " + names + ")"));
  }
  if (const bake::UvSet* s = find("TEXCOORD_1")) return *s;
  if (mesh.uv_sets.size() == 1) return mesh.uv_sets.front();
  throw bake::InputError(mesh.source, "has several UV sets (" + names + ") and no TEXCOORD_1: name the lightmap's with --uv");
}

constexpr uint32_t kMaxSide = 8192;  // texel_atlas's limit (bake/mesh/texels.h), as --resolution's

// The side of the square atlas (a multiple of 4, at most kMaxSide) whose texels have `density`
// texels per unit on average over the surface that `uv` maps (triangles with UV area; those
// without cover no texel): N = density · sqrt(their surface area / their UV area), rounded up.
// InputError when that exceeds kMaxSide.
uint32_t side_for_density(const bake::Mesh& mesh, const bake::UvSet& uv, double density) {
  double surface = 0, uv_area = 0;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const Eigen::Vector2d p = uv.corners[3 * t].cast<double>(), q = uv.corners[3 * t + 1].cast<double>() - p,
                          r = uv.corners[3 * t + 2].cast<double>() - p;
    const double mapped = std::abs(q.x() * r.y() - q.y() * r.x()) / 2;
    if (mapped == 0) continue;
    uv_area += mapped;
    const Eigen::Vector3d a = mesh.positions[tri[0]].cast<double>();
    surface += (mesh.positions[tri[1]].cast<double>() - a).cross(mesh.positions[tri[2]].cast<double>() - a).norm() / 2;
  }
  if (!(uv_area > 0)) return 4;  // covers no texel at any size: texel_atlas's caller says so
  const double side = std::ceil(density * std::sqrt(surface / uv_area) / 4) * 4;
  if (!(side <= kMaxSide))
    throw bake::InputError(mesh.source, "at " + std::to_string(density) + " texels per unit its UV set " + uv.name +
                                            " needs a lightmap of " + std::to_string(side) + " texels a side; the most is " +
                                            std::to_string(kMaxSide));
  return std::max<uint32_t>(4, uint32_t(side));
}

} // namespace

int run_texel(const Args& a, const RunContext& run, std::optional<ShardedRows>& shards) {
  const bake::Mesh mesh = load_receiver_mesh(a, run.say);
  const bake::Topology topo = bake::build_topology(mesh);
  warn_inward(bake::winding_facts(mesh, topo), a.flip_normals);
  // The UV set: generated when the mesh has none (and --uv names none) or on --unwrap.
  std::optional<bake::Unwrapped> generated;
  uint32_t width = a.lightmap_width, height = a.lightmap_height;
  if (a.unwrap || (mesh.uv_sets.empty() && a.uv_set.empty())) {
    bake::UnwrapOptions o;
    o.width = width;
    o.height = height;
    o.density = width == 0 ? a.lightmap_density : 0;
    o.gutter = a.gutter;
    o.max_side = kMaxSide;
    generated = bake::unwrap(mesh, topo, o);
    const bake::UnwrapReport& r = generated->report;
    width = r.width;
    height = r.height;
    if (run.say)
      std::fprintf(stderr,
                   "prtbake: %s: %s: generated lightmap UVs %s: %zu charts%s, utilisation %.2f, worst stretch %.2f "
                   "(mean %.2f), %ux%u texels at %.4g texels per unit, %.1f s\n",
                   a.input.c_str(), a.unwrap ? "--unwrap" : "no UV set", generated->uv.name.c_str(), r.charts,
                   r.degenerate_triangles == 0
                       ? ""
                       : (" (and " + std::to_string(r.degenerate_triangles) + " zero-area triangles at UV (0, 0))").c_str(),
                   r.utilisation, r.worst_stretch, r.mean_stretch, r.width, r.height, r.density, r.seconds);
  }
  const bake::UvSet& uv = generated ? generated->uv : lightmap_uvs(mesh, a.uv_set);
  if (width == 0) width = height = side_for_density(mesh, uv, a.lightmap_density);
  const bake::TexelAtlas atlas = bake::texel_atlas(mesh, topo, uv, width, height, a.input);
  if (atlas.samples.empty()) {
    // Why: every triangle flat in UV space (a set of one repeated vt, as wuson.obj's), or UVs
    // outside the atlas.
    size_t flat = 0;
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
      const Eigen::Vector2f &p = uv.corners[3 * t], &q = uv.corners[3 * t + 1], &r = uv.corners[3 * t + 2];
      flat += (q - p).x() * (r - p).y() - (q - p).y() * (r - p).x() == 0;
    }
    throw bake::InputError(mesh.source, "its UV set " + uv.name + " covers no texel of the " +
                                            std::to_string(width) + "x" + std::to_string(height) +
                                            " lightmap: " +
                                            (flat == mesh.triangles.size()
                                                 ? "every triangle has zero area in it (not a lightmap UV set)"
                                                 : "its UVs lie outside [0, 1]"));
  }
  // The UV set's checks at this resolution (bake/mesh/texels.h).
  if (atlas.overlapping_texels > 0)
    throw bake::InputError(mesh.source, "its UV set " + uv.name + " overlaps itself: " +
                                            std::to_string(atlas.overlapping_texels) +
                                            " texels lie inside triangles of two charts (a texture set that mirrors or "
                                            "reuses parts is no lightmap set); pass --unwrap to bake in generated "
                                            "lightmap UVs instead");
  const std::optional<bake::EnvMap> env = load_environment(a, run.say);
  const bake::ProductRequest req = product_request(a, env ? &*env : nullptr);
  const bake::MeshAccel accel(mesh, topo);

  // Texels inside the geometry: left out of the bake, filled from their chart afterwards.
  std::vector<uint8_t> invalid(atlas.samples.size());
  {
    const std::shared_ptr<const bake::RayCaster> rays = accel.rays();
    tbb::parallel_for(size_t(0), atlas.samples.size(),
                      [&](size_t i) { invalid[i] = bake::enclosed(atlas.receivers.points[i], *rays); });
  }
  std::vector<size_t> valid;
  for (size_t i = 0; i < invalid.size(); ++i)
    if (!invalid[i]) valid.push_back(i);
  if (atlas.shared_texels > atlas.overlapping_texels)
    std::fprintf(stderr,
                 "prtbake: warning: %s: %zu texels of the %ux%u lightmap are touched by two charts of UV set %s: too "
                 "little gutter at this resolution (bilinear filtering bleeds one chart into the other)\n",
                 a.input.c_str(), atlas.shared_texels, atlas.width, atlas.height, uv.name.c_str());
  if (valid.empty())
    throw bake::InputError(mesh.source, "every texel its UV set " + uv.name + " covers lies inside the geometry: nothing "
                                        "to bake (are its normals pointing inside? see --flip-normals)");
  if (run.say)
    std::printf("lightmap: %ux%u texels in UV set %s: %zu covered (%zu by the nearest point of a triangle touching "
                "the texel, not its centre), %u charts; %zu inside the geometry, filled from their charts\n",
                atlas.width, atlas.height, uv.name.c_str(), atlas.samples.size(), atlas.texels_off_centre(), atlas.charts,
                atlas.samples.size() - valid.size());

  bake::PipelineSettings settings;
  settings.integrator = a.integrator;
  settings.target_error = a.target_error;
  settings.integrator_given = a.integrator_given;
  settings.counted_costs = a.reproducible;
  settings.bake_stage = "baking texels";
  std::vector<bake::BakeJob> jobs(1);
  jobs[0].name = a.input;
  jobs[0].request = req;
  bake::ReceiverSet& set = jobs[0].sets.emplace_back();
  set.name = a.input;
  set.rows_noun = "texels";
  for (size_t i : valid) set.points.push_back(atlas.receivers.points[i]);
  bake::BakePipeline pipeline(mesh, topo, accel, std::move(settings), std::move(jobs));
  const bake::BakeJob& job = pipeline.jobs().front();

  namespace F = prt::formats;
  auto write_bake = [&] {
    const bake::VertexBake& result = job.rows.front();
    const size_t W = result.layout.width;
    std::vector<double> rows(atlas.samples.size() * W, 0.0);  // the invalid texels' rows: filled below
    for (size_t r = 0; r < valid.size(); ++r)
      std::copy_n(result.values.begin() + std::ptrdiff_t(r * W), W, rows.begin() + std::ptrdiff_t(valid[r] * W));
    bake::Lightmap image = bake::make_lightmap(atlas, rows, W, invalid, a.padding);
    if (!a.no_stitch) {
      const bake::SeamStitch seams = bake::stitch_seams(image, atlas, mesh, topo, uv);
      if (run.say && seams.edges > 0)
        std::printf("seams: %zu UV seam edges, %zu points looked up from both sides (%zu reach an empty texel or another chart's: "
                    "left out), %zu texels moved (a baked one by %.2e at most): mean |difference| %.2e -> %.2e, "
                    "largest %.2e -> %.2e\n",
                    seams.edges, seams.points, seams.skipped_points, seams.texels, seams.baked_moved_max, seams.mean_before,
                    seams.mean_after, seams.max_before, seams.max_after);
    }
    F::Asset asset;
    asset.root = root_info(a, mesh.source_sha256);
    tool::set_mesh(asset.vertices, mesh);
    if (a.flip_normals) *asset.vertices.normals->source += ", flipped";
    tool::set_lightmap(asset.vertices, mesh, uv, atlas, image, result.layout,
                       {job.integrator->name(), job.integrator_description, job.spec.samples(), job.spec.seed, a.transfer,
                        a.visibility, env ? &*env : nullptr, a.environment},
                       a.padding);
    if (const auto& report = job.reports.front()) {
      bake::ErrorReport by_texel = *report;  // its rows are valid texels: named by their texels
      for (uint32_t& r : by_texel.vertices) r = atlas.samples[valid[r]].texel;
      asset.vertices.report = tool::report_of(by_texel, result.seconds, valid.size(), a.reproducible);
    }
    tool::set_target_error(asset, a.target_error);
    write_file(a, asset);
    if (run.say && image.unfilled > 0)
      std::printf("lightmap: %zu texels inside the geometry had no valid neighbour in their chart: left 0\n", image.unfilled);
  };

  ReceiverConsole console;
  bake::PipelineHooks hooks = console.hooks(a, run, write_bake);
  hooks.set_baked = [&](const bake::BakeJob& j, size_t) {
    if (run.say) print_rows_baked(j, shards && shards->threads_of_chunks() == 0);
  };
  // Sharded, the chunks are the valid texels' rows in texel order; the atlas they belong to is
  // in the manifest (a chunk of another atlas, UV set or texel count is refused).
  return console.run(a, run, pipeline, hooks, shards,
                     {"texel", kToolkitVersion, a.command_line, mesh.source_sha256,
                      env ? env->info().sha256 : "no environment",
                      std::to_string(atlas.width) + "x" + std::to_string(atlas.height) + " texels in UV set " + uv.name +
                          ", " + std::to_string(valid.size()) + " of " + std::to_string(atlas.samples.size()) +
                          " covered texels baked"});
}

} // namespace prt::tool
