// tools/prtbake/run_scene.cpp — `prtbake scene` (commands.h): a scene file or glTF. Prints the
// plan (what each object gets, and why; --dry-run: and what it would cost), bakes what it asks
// for (sharded: the receivers' rows in chunks, shards.h), writes the file once the bake is whole
// and again with the error reports.
#include <bake/bake/diagnostics.h>
#include <bake/bake/scene.h>
#include <bake/bake/scene_bake.h>
#include <bake/bake/vertex_bake.h>
#include <bake/core/sha256.h>
#include <bake/environment/envmap.h>
#include <bake/mesh/mesh.h>
#include <formats/asset.h>

#include "bakefile.h"
#include "commands.h"
#include "output.h"
#include "shards.h"
#include "tool_main.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace fs = std::filesystem;

namespace prt::tool {
namespace {

// How the tools name a scene object to people: a glTF instance by its node path ("node0/body"),
// a scene file's object by its name (the file's "|" spelling is for HDF5 paths only).
std::string scene_object_label(const bake::SceneObject& o) { return o.node_path.empty() ? o.name : o.node_path; }

} // namespace

int run_scene(const Args& a, const RunContext& run, std::optional<ShardedRows>& shards) {
  bake::SceneDescription scene = bake::load_scene(
      a.input, a.scene_options.empty() ? std::nullopt : std::optional<fs::path>(a.scene_options));
  if (a.report_given) scene.integrator.report_points = a.integrator.report_points;
  scene.counted_costs = a.reproducible;  // a target's choice by counted work: the same on any machine
  Args file_args = a;  // the root attributes follow the scene file
  file_args.up = scene.up;

  std::vector<std::string> warnings = scene.warnings;
  const std::vector<bake::Mesh> meshes = bake::load_scene_meshes(scene, warnings);
  print_warnings(warnings);
  bake::place_suns(scene, meshes);  // directional lights with an "angle": sun discs beyond the scene
  std::optional<bake::EnvMap> env;
  if (scene.environment) env = bake::EnvMap::load(*scene.environment, scene.up);
  const bake::ScenePlan plan = bake::plan_scene(scene, meshes);
  // Receivers with closed parts wound inwards: their vertices would see no sky.
  for (size_t i = 0; i < scene.objects.size(); ++i)
    if (plan.objects[i].receiver && plan.objects[i].any_vertex_product())
      warn_inward(bake::winding_facts(meshes[i], bake::build_topology(meshes[i])), false,
                  scene_object_label(scene.objects[i]), plan.objects[i].occluder);

  if (run.say) {
    std::printf("scene: %s: %zu objects, environment %s, integrator %s, SH tolerance %g\n", a.input.c_str(),
                scene.objects.size(), env ? scene.environment->string().c_str() : "none",
                bake::to_string(scene.integrator.kind),
                scene.sh_tolerance);
    // Every object with its decisions; with many objects (an engine of 115 parts), the objects
    // that share their role and decisions are printed once as a group (-v: every object).
    auto decisions = [&](size_t i) {
      std::string d = std::string(bake::role_name(scene.objects[i].role)) + "\n";
      for (const auto& b : plan.objects[i].baked) d += "      bake       " + b + "\n";
      for (const auto& l : plan.objects[i].left_out) d += "      leave out  " + l + "\n";
      return d;
    };
    auto name_of = [&](size_t i) { return scene_object_label(scene.objects[i]); };
    constexpr size_t kGroupAbove = 12;  // objects; fewer are listed one by one
    if (a.verbose || scene.objects.size() <= kGroupAbove) {
      for (size_t i = 0; i < scene.objects.size(); ++i) {
        const std::string d = decisions(i);
        std::printf("  %s (%s): %s, %zu vertices, %zu triangles\n%s", name_of(i).c_str(), bake::role_name(scene.objects[i].role),
                    scene.objects[i].mesh.string().c_str(), meshes[i].positions.size(), meshes[i].triangles.size(),
                    d.substr(d.find('\n') + 1).c_str());
      }
    } else {
      std::vector<std::pair<std::string, std::vector<size_t>>> sets;  // in order of first appearance
      for (size_t i = 0; i < scene.objects.size(); ++i) {
        const std::string d = decisions(i);
        auto it = std::find_if(sets.begin(), sets.end(), [&](const auto& x) { return x.first == d; });
        if (it == sets.end()) sets.push_back({d, {i}});
        else it->second.push_back(i);
      }
      for (const auto& [d, members] : sets) {
        size_t vertices = 0, triangles = 0;
        for (size_t i : members) vertices += meshes[i].positions.size(), triangles += meshes[i].triangles.size();
        std::string names;
        for (size_t k = 0; k < std::min<size_t>(members.size(), 3); ++k) names += (k ? ", " : "") + name_of(members[k]);
        if (members.size() > 3) names += " and " + std::to_string(members.size() - 3) + " more";
        std::printf("  %zu object%s (%s): %s; %zu vertices, %zu triangles\n%s", members.size(), members.size() == 1 ? "" : "s",
                    d.substr(0, d.find('\n')).c_str(), names.c_str(), vertices, triangles, d.substr(d.find('\n') + 1).c_str());
      }
      std::printf("  (objects with the same role and decisions are grouped; -v lists every object)\n");
    }
    for (const auto& l : scene.lights)
      std::printf("  light %s (%s): %zu face(s), radiance %g %g %g%s\n", l.name.c_str(), bake::light_shape_name(l.shape),
                  l.faces.size(), l.radiance[0], l.radiance[1], l.radiance[2], l.two_sided ? ", two-sided" : "");
    for (const auto& l : scene.punctual_lights)
      std::printf("  light %s (%s): intensity %g %g %g, hard shadows\n", l.name.c_str(), bake::punctual_kind_name(l.kind),
                  l.intensity[0], l.intensity[1], l.intensity[2]);
    for (const auto& n : plan.notes) std::printf("  %s\n", n.c_str());
    std::fflush(stdout);
  }
  if (a.dry_run) {
    // What the bake would cost: each group's integrator timed on seeded vertices (with a target,
    // after the pilot that chooses it), nothing baked or written.
    if (run.say) std::printf("estimated cost (nothing is baked):\n");
    bake::SceneRows estimate;
    estimate.estimate_only = true;
    bake::bake_scene(scene, plan, meshes, env ? &*env : nullptr, run.progress,
                     [&](const std::string& line) {
                       if (run.say) std::printf("  %s\n", line.c_str());
                       std::fflush(stdout);
                     },
                     estimate);
    return 0;
  }

  // Sharded: the receivers' rows in chunks (every worker), then the rest of the bake on the
  // merging process, its rows read back from the chunks (shards.h).
  bake::SceneRows merged_rows;
  if (a.worker) {
    std::vector<uint64_t> set_rows;
    std::vector<uint32_t> widths;
    std::vector<std::string> lines = {"scene", kToolkitVersion, a.command_line, bake::sha256_file(a.input),
                                      a.scene_options.empty() ? "" : bake::sha256_file(a.scene_options),
                                      env ? env->info().sha256 : "no environment", std::to_string(a.shard.chunk_rows)};
    for (size_t i = 0; i < scene.objects.size(); ++i) {
      const bake::ObjectPlan& p = plan.objects[i];
      if (!p.receiver || !p.any_vertex_product()) continue;
      set_rows.push_back(meshes[i].positions.size());
      widths.push_back(uint32_t(bake::ProductLayout(bake::product_request(p, env ? &*env : nullptr)).width));
    }
    // Every object's mesh, occluders included: they shape the receivers' values.
    for (size_t i = 0; i < scene.objects.size(); ++i) lines.push_back(scene.objects[i].name + " " + meshes[i].source_sha256);
    shards.emplace(*a.worker, run.mpi, a.shard, a.output, tool::manifest_of(lines), set_rows, widths, a.quiet);
    const bool merges = shards->run([&] {
      bake::SceneRows work;
      work.rows_only = true;
      work.rows = [&](size_t set, std::span<const bake::ShadePoint> points, const bake::Integrator& integrator,
                      const bake::Monitor&) {
        shards->work(
            [&](const bake::ChunkRange& r, const bake::Monitor& monitor) {
              return tool::bake_chunk(points, r, integrator, monitor);
            },
            uint32_t(set));
        return bake::VertexBake{};
      };
      bake::bake_scene(scene, plan, meshes, env ? &*env : nullptr, run.progress, [](const std::string&) {}, work);
    });
    if (!merges) return 0;
    merged_rows.rows = [&](size_t set, std::span<const bake::ShadePoint>, const bake::Integrator& integrator,
                           const bake::Monitor&) { return shards->merge(uint32_t(set), integrator.layout()); };
  }
  namespace F = prt::formats;
  // The lightmaps of the receivers baked per texel, made (and their seams stitched) once per bake
  // of their rows.
  std::vector<std::optional<bake::Lightmap>> images(scene.objects.size()), area_images(scene.objects.size());
  constexpr size_t kLightmapLines = 5;  // receivers per texel whose atlas and seams are printed without -v
  auto make_images = [&](const bake::SceneBake& result) {
    size_t lightmaps = 0;
    for (const bake::ObjectBake& ob : result.objects) lightmaps += ob.lightmap && (ob.values || ob.area) ? 1 : 0;
    for (size_t i = 0; i < scene.objects.size(); ++i) {
      const bake::ObjectBake& ob = result.objects[i];
      if (!ob.lightmap || !(ob.values || ob.area)) continue;
      bake::SeamStitch seams;
      const bake::Topology topology = bake::build_topology(meshes[i]);
      if (ob.values)
        images[i] = lightmap_image(meshes[i], topology, *ob.lightmap, *scene.objects[i].lightmap, *ob.values, seams);
      if (ob.area) {
        // The area lights' rows per valid texel, filled, padded and stitched as the products are.
        bake::VertexBake area;
        area.layout.width = scene.light_count() * (1 + size_t(plan.objects[i].area_sh_order * plan.objects[i].area_sh_order));
        area.values = *ob.area;
        bake::SeamStitch area_seams;
        area_images[i] = lightmap_image(meshes[i], topology, *ob.lightmap, *scene.objects[i].lightmap, area, area_seams);
      }
      const std::string who = scene_object_label(scene.objects[i]);
      warn_inexact_texels(ob.lightmap->atlas, who);
      if (!run.say || !(lightmaps <= kLightmapLines || a.verbose)) continue;
      const bake::TexelAtlas& atlas = ob.lightmap->atlas;
      if (ob.lightmap->generated)
        print_generated_uvs(who, ob.lightmap->unwrap_asked ? "\"unwrap\": true" : "no UV set", ob.lightmap->uv.name,
                            *ob.lightmap->generated);
      std::printf("%s: lightmap %ux%u texels in UV set %s: %zu covered, %u charts; %zu inside the geometry, filled "
                  "from their charts\n",
                  who.c_str(), atlas.width, atlas.height, ob.lightmap->uv.name.c_str(), atlas.samples.size(), atlas.charts,
                  atlas.samples.size() - ob.lightmap->valid.size());
      if (seams.edges > 0) print_stitch(seams, who);
      if (images[i]) print_mip_check(bake::mip_empty_hits(*images[i], atlas, ob.lightmap->uv), who);
    }
    if (run.say && lightmaps > kLightmapLines && !a.verbose)
      std::printf("%zu receivers baked per texel into lightmaps (-v prints each one's atlas and seams)\n", lightmaps);
  };
  // The file from a bake (with its reports once they are made).
  auto write_scene = [&](const bake::SceneBake& result) {
    F::Asset asset;
    asset.root = root_info(file_args, bake::sha256_file(a.input));
    const std::string env_path = env ? scene.environment->string() : std::string();
    F::SceneInfo& info = asset.scene.emplace();
    info.scene_file = a.input;
    if (!a.scene_options.empty()) {
      info.options_file = a.scene_options;
      info.options_sha256 = bake::sha256_file(a.scene_options);
    }
    info.integrator = std::string(bake::to_string(scene.integrator.kind));
    info.samples = int64_t(scene.integrator.samples());
    info.seed = int64_t(scene.integrator.seed);
    info.sh_tolerance = scene.sh_tolerance;
    info.relight = int64_t(scene.relight);
    if (env) {
      info.environment = env_path;
      info.environment_sha256 = env->info().sha256;
    }
    auto join = [](const std::vector<std::string>& lines, const char* none) {
      std::string s;
      for (const auto& l : lines) s += (s.empty() ? "" : "\n") + l;
      return s.empty() ? std::string(none) : s;
    };
    info.plan = join(plan.notes, "");
    for (size_t i = 0; i < scene.objects.size(); ++i) {
      const auto& o = scene.objects[i];
      const auto& p = plan.objects[i];
      const auto& ob = result.objects[i];
      F::SceneObject& obj = asset.objects.emplace_back();
      obj.name = o.name;
      obj.role = bake::role_name(o.role);
      obj.mesh = o.mesh.string();
      obj.mesh_sha256 = meshes[i].source_sha256;
      if (!o.node_path.empty()) obj.node_path = o.node_path;
      obj.transform.emplace(16);
      for (int k = 0; k < 16; ++k) (*obj.transform)[size_t(k)] = o.world_from_object(k / 4, k % 4);
      obj.albedo = std::vector<double>(o.material.albedo.begin(), o.material.albedo.end());
      obj.phong_exponent = o.material.phong_exponent;
      obj.sh_order_diffuse = int64_t(p.transfer_order);
      obj.sh_order_glossy = int64_t(std::max(p.visibility_order, p.shadowed_order));
      obj.baked = join(p.baked, "-");
      obj.left_out = join(p.left_out, "-");
      if (o.material.glossy()) obj.specular = std::vector<double>(o.material.specular.begin(), o.material.specular.end());
      if (ob.values) obj.closed_form_vertices = int64_t(ob.closed_form_vertices);
      tool::set_mesh(obj.set, meshes[i]);
      const ProductInfo products{std::string(bake::to_string(ob.integrator.kind)), ob.integrator_description,
                                 ob.integrator.samples(), ob.integrator.seed, p.transfer_order, p.visibility_order,
                                 env ? &*env : nullptr, env_path};
      if (ob.lightmap && (images[i] || area_images[i])) {
        // Per texel: the lightmap (made when the rows were baked), its report's rows named by texel;
        // with area lights alone, the texels and no other product.
        tool::set_lightmap(obj.set, meshes[i], ob.lightmap->uv, ob.lightmap->atlas, images[i] ? *images[i] : *area_images[i],
                           images[i] ? ob.values->layout : bake::ProductLayout(bake::ProductRequest{}), products,
                           o.lightmap->padding);
        if (ob.report && ob.values) {
          bake::ErrorReport by_texel = *ob.report;
          for (uint32_t& r : by_texel.vertices) r = ob.lightmap->atlas.samples[ob.lightmap->valid[r]].texel;
          obj.set.report = tool::report_of(by_texel, ob.values->seconds, ob.lightmap->valid.size(), a.reproducible);
        }
      } else if (ob.values) {
        tool::set_products(obj.set, *ob.values, products);
        if (ob.report)
          obj.set.report = tool::report_of(*ob.report, ob.values->seconds, meshes[i].positions.size(), a.reproducible);
      }
      if (ob.bounced_radiance || ob.bounced_transfer || ob.bounced_shadowed) {
        // The bounces (bake/bake/scene.h rule "bounces"); `albedo` is this object's (the others'
        // are their objects' albedo attributes).
        bake::BounceSpec spec;
        spec.bounces = scene.bounces;
        spec.rays = result.bounce_rays;
        F::VertexSet& set = obj.set;
        std::optional<F::Product>& t = set.lightmap ? set.lightmap->transfer_diffuse : set.transfer_diffuse;
        std::optional<F::Product>& r = set.lightmap ? set.lightmap->radiance_band1 : set.radiance_band1;
        if (ob.bounced_transfer && t) tool::set_bounces(*t, Bounced::Transfer, result.bounces_applied, spec, *obj.albedo,
                                                    result.bounce_relative_std_error);
        if (ob.bounced_radiance && r) tool::set_bounces(*r, Bounced::Band1, result.bounces_applied, spec, *obj.albedo,
                                                    result.bounce_relative_std_error);
        std::optional<F::Product>& sh = set.lightmap ? set.lightmap->radiance_shadowed : set.radiance_shadowed;
        if (ob.bounced_shadowed && sh)
          tool::set_bounces(*sh, Bounced::Shadowed, result.bounces_applied, spec, *obj.albedo,
                            result.bounce_relative_std_error);
      }
      if (ob.area && ob.lightmap && area_images[i])
        tool::set_lightmap_area_lights(obj.set, *area_images[i], scene.light_names(), p.area_sh_order,
                                        scene.punctual_lights.size());
      else if (ob.area)
        tool::set_area_lights(obj.set, *ob.area, scene.light_names(), p.area_sh_order, scene.punctual_lights.size());
      if (ob.bounced_area) {
        bake::BounceSpec spec;
        spec.bounces = scene.bounces;
        spec.rays = result.bounce_rays;
        std::optional<F::Product>& e = obj.set.lightmap ? obj.set.lightmap->area_irradiance : obj.set.area_irradiance;
        if (e) tool::set_bounces(*e, Bounced::AreaIrradiance, result.bounces_applied, spec, *obj.albedo,
                                                    result.bounce_relative_std_error);
      }
      if (ob.shells) {
        F::Occluder& occluder =
            asset.occluders.emplace_back(tool::occluder_of(o.name, *ob.shells, env->info(), env_path, scene.fiv.fraction, scene.fiv.silhouette_k));
        if (ob.fiv_report) occluder.report = tool::fiv_report_of(o.name, *ob.fiv_report, *ob.shells, a.reproducible);
        if (ob.fiv_self) occluder.self_band1 = tool::self_band1_of(ob.fiv_self->values);
      }
    }
    for (const bake::AreaLight& light : scene.lights) asset.lights.push_back(tool::light_of(light));
    for (const bake::PunctualLight& light : scene.punctual_lights) asset.lights.push_back(tool::light_of(light));
    if (plan.fiv_environment)
      tool::set_fiv_environment(asset, env->info(), env_path, result.environment_fiv, result.irradiance_cube, scene.fiv.cube);
    tool::set_target_error(asset, scene.target_error);
    write_file(a, asset);
  };
  // Once the bake is whole: its warnings and summary, then the file, written before the error
  // reports are made (bake_scene's SceneRows::baked); the reports re-write it.
  bool written = false, checks = false;
  merged_rows.baked = [&](const bake::SceneBake& result) {
    // A receiver most of whose vertices see no sky: buried in other objects, or turned inside out.
    // One line each for a few; past kNoSkyListed (an engine's internals) one line that counts them
    // and names the first.
    constexpr size_t kNoSkyListed = 5;
    std::vector<std::pair<std::string, bake::NoSkyCount>> no_sky;
    std::vector<const char*> noun;  // of each: its rows (a receiver per texel counts texels)
    for (size_t i = 0; i < scene.objects.size(); ++i)
      if (const auto& values = result.objects[i].values) {
        const bake::NoSkyCount count = bake::count_no_sky(*values);
        if (count.share() > 0.5) {
          no_sky.emplace_back(scene_object_label(scene.objects[i]), count);
          noun.push_back(result.objects[i].lightmap ? "texels" : "vertices");
        }
      }
    if (!no_sky.empty() && (no_sky.size() <= kNoSkyListed || a.verbose)) {
      for (size_t k = 0; k < no_sky.size(); ++k)
        std::fprintf(stderr,
                     "prtbake: warning: %s: %.1f%% of its %s (%zu of %zu) see no sky at all: it is enclosed by "
                     "other objects, or its normals point inside (check its winding)\n",
                     no_sky[k].first.c_str(), 100 * no_sky[k].second.share(), noun[k], no_sky[k].second.vertices,
                     no_sky[k].second.total);
    } else if (!no_sky.empty()) {
      std::string first;
      for (size_t k = 0; k < 3; ++k) {
        char share[32];
        std::snprintf(share, sizeof share, " (%.1f%%)", 100 * no_sky[k].second.share());
        first += (k ? ", " : "") + no_sky[k].first + share;
      }
      std::fprintf(stderr,
                   "prtbake: warning: %zu receivers have more than half their vertices or texels seeing no sky at all (enclosed by "
                   "other objects, or normals pointing inside: check their winding): %s and %zu more (-v names each)\n",
                   no_sky.size(), first.c_str(), no_sky.size() - 3);
    }
    if (run.say)
      std::printf("baked %llu receiver vertices%s in %.2f s (setup %.2f s), FIV %.2f s (environment %.2f s)\n",
                  (unsigned long long)result.vertices,
                  result.texels ? (" and " + std::to_string(result.texels) + " lightmap texels").c_str() : "",
                  result.vertex_seconds, result.setup_seconds, result.fiv_seconds, result.environment_seconds);
    make_images(result);

    write_scene(result);
    written = true;
    // Reports follow for the receivers' rows and the FIV shells when the scene asks for them.
    checks = scene.integrator.report_points > 0 &&
             std::any_of(result.objects.begin(), result.objects.end(),
                         [](const bake::ObjectBake& ob) { return ob.values.has_value() || ob.shells.has_value(); });
    if (run.say && checks)
      std::printf("checking its error (Ctrl-C keeps the file as written, without its reports; \"report\": 0 or --report 0 "
                  "skips the check)\n");
    std::fflush(stdout);
  };
  merged_rows.check_planned = [&](const std::string& who, const bake::ReferencePlan& reference) {
    if (!run.say || !a.verbose) return;
    std::printf("%s: the error check's reference:\n", who.c_str());
    print_reference_plan(reference);
    std::fflush(stdout);
  };
  auto log = [&](const std::string& line) {
    if (run.say) std::printf("%s\n", line.c_str());
    std::fflush(stdout);
  };
  auto on_choice = [&](const std::string& object, const bake::IntegratorChoice& choice) {
    if (run.say && a.verbose) {
      std::printf("%s: the target-error pilot:\n", object.c_str());
      for (const std::string& l : bake::choice_lines(choice)) std::printf("%s\n", l.c_str());
    } else if (run.say) {
      std::printf("%s: %s\n", object.c_str(), bake::choice_summary(choice).c_str());
    }
    std::fflush(stdout);
    warn_unreached(choice, object);
  };
  std::optional<bake::SceneBake> baked;
  try {
    baked = bake::bake_scene(scene, plan, meshes, env ? &*env : nullptr, run.progress, log, merged_rows, on_choice);
  } catch (const bake::Cancelled&) {
    if (!written) throw;
    std::fprintf(stderr,
                 "prtbake: cancelled during the error check: %s holds the finished bake without its error reports "
                 "(--report 0 skips the check)\n",
                 a.output.c_str());
    return tool::kExitCancelled;
  }
  if (checks) write_scene(*baked);
  if (shards) shards->finish();
  return 0;
}

} // namespace prt::tool
