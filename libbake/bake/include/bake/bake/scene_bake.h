// bake/bake/scene_bake.h — baking a scene's plan (bake/bake/scene.h): every receiver's rows against
// the union of the occluders through the bake pipeline (bake/bake/pipeline.h), area lights, FIV
// shells and the environment's FIV, then the error reports (docs/ARCHITECTURE.md §5).
#pragma once

#include <bake/bake/choose.h>
#include <bake/bake/error_report.h>
#include <bake/bake/fiv.h>
#include <bake/bake/lightmap_receivers.h>
#include <bake/bake/scene.h>
#include <bake/bake/vertex_bake.h>
#include <bake/core/progress.h>
#include <bake/environment/envmap.h>
#include <bake/mesh/mesh.h>

#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace prt::bake {

struct ObjectBake {
  // Receivers: one row per vertex of the object's world mesh, in its layout; or, for an object
  // with a lightmap (SceneObject::lightmap), one per valid texel of `lightmap` (its `valid` order).
  std::optional<VertexBake> values;
  std::optional<LightmapReceivers> lightmap;
  std::optional<ErrorReport> report;
  IntegratorSpec integrator;           // what baked the values: the scene's, or the target's choice
  std::optional<IntegratorChoice> choice;  // with a target error
  std::optional<ReferencePlan> reference_plan;  // with a target error and a report (bake/bake/choose.h)
  std::string integrator_description;
  uint64_t closed_form_vertices = 0;  // vertices whose integral took a closed form (VertexBake::closed_form)
  // Occluders with shells (in world space: centre and radii in scene units).
  std::optional<FivShells> shells;
  std::optional<FivErrorReport> fiv_report;
  // Their self-shadows (ShellSpec::vertex_self_shadows): band-1 radiance from the object alone at
  // the vertices of its world mesh.
  std::optional<FivSelfShadows> fiv_self;
  // Receivers with area lights: [V][lights][1 + n²] per vertex and light, E then the SH at
  // order n = area_sh_order (AreaLightIntegrator's rows); per valid texel of `lightmap` for an
  // object baked per texel.
  std::optional<std::vector<double>> area;
  double area_seconds = 0;
  // Interreflections (scene.h rule "bounces"): `values` hold direct + SceneBake::bounces_applied
  // bounces in these products.
  bool bounced_radiance = false, bounced_transfer = false, bounced_area = false;  // `area` too
  bool bounced_shadowed = false;
};

struct SceneBake {
  std::vector<ObjectBake> objects;  // parallel to SceneDescription::objects
  Fiv environment_fiv{};            // when plan.fiv_environment
  std::vector<float> irradiance_cube;
  double setup_seconds = 0, vertex_seconds = 0, fiv_seconds = 0, environment_seconds = 0, area_seconds = 0;
  double report_seconds = 0;  // the error reports' reference integrals (with a target)
  // Interreflections (plan.bounces): the bounces summed, each one's RMS over the direct pass's
  // (BounceResult), the gather rays per receiver row, the gather's and the bounces' wall time,
  // the cached hits' bytes, and the share of gather rays that met a reflecting surface.
  int bounces_applied = 0;
  std::vector<double> bounce_relative_rms;
  double bounce_relative_std_error = 0;  // BounceResult::total_relative_std_error
  uint32_t bounce_rays = 0;
  double gather_seconds = 0, bounce_seconds = 0, reflecting_share = 0;
  size_t gather_bytes = 0;
  uint64_t vertices = 0, texels = 0;  // receiver rows integrated: vertices, and texels of lightmaps
};

// Runs the plan. Visibility for every receiver is the union of the occluders ("occluder" and
// "both" objects) in world space; a "both" receiver's vertices are shade points of that union
// (their own 1-ring occludes in the ε-limit), a receiver-only object's vertices are free points.
// In order: the area lights' rows (exact), the environment's FIV and the occluders' FIV shells,
// then the receivers' per-vertex products through the bake pipeline (bake/bake/pipeline.h: one job
// per distinct product request over the receivers that make it; choose, integrate, check,
// correct) — with plan.bounces, once every receiver's rows are baked, the bounces over all of them
// together (bake/bake/bounce.h: one gather over every gathering receiver's rows against the
// union, a SceneField of their vertices and lightmaps; the error reports measure the direct rows)
// — then the FIV shells' error reports. Every row is the same for any thread count.
// `env` must be the scene's environment (nullptr if none). `log` receives one line per step.
//
// How bake_scene integrates receiver rows, for sharded bakes (bake/core/chunks.h), and what it
// tells its caller. `rows` replaces the row loop for every receiver with per-vertex products:
// `set` numbers those receivers in object order; it returns the rows of all of `points` (or
// none, with rows_only), their VertexBake::closed_form set. With rows_only, bake_scene stops
// there: no area lights, error reports, FIV or environment (what a worker that only computes
// chunks needs). With `rows`, no correction pass (its rows cannot be baked again here).
struct SceneRows {
  std::function<VertexBake(size_t set, std::span<const ShadePoint> points, const Integrator& integrator,
                           const Monitor& monitor)>
      rows;
  bool rows_only = false;
  // The dry run's estimate: nothing is baked; per distinct product request (the receivers that
  // make it), the integrator — with a target, the one the pilot chooses — is timed on 64 seeded
  // vertices and `log` receives its predicted CPU time for all of them (and the error check's
  // bound); the environment's FIV and DifMap and each occluder's shells are timed on 64 seeded
  // samples after their setup (bake/bake/fiv.h FivCost); last, the whole in wall seconds on the
  // threads allowed. Area lights are not estimated.
  bool estimate_only = false;
  // Called once the bake is whole (the receivers' rows, area lights and FIV shells), before any
  // error report is made: a tool writes the file there, so a check cancelled with Ctrl-C (or one
  // that takes longer than the user will wait) never costs the bake. Called again after a
  // correction's rows.
  std::function<void(const SceneBake&)> baked;
  // With a target, when a job's error-report reference is planned (who: as OnChoice's).
  std::function<void(const std::string& who, const ReferencePlan& plan)> check_planned;
};

// With a target error the choice is made once per distinct product request, on the pooled shade
// points of the receivers that make it (the target holds for their values together), before they
// are baked; `on_choice` receives it (who: the receiver, or "N receivers (V vertices, from
// <first>)"); without it, `log` receives choice_summary. The check's reference is planned after
// the bake (SceneRows::check_planned). Each receiver's report then takes its share of the
// report's points by its vertices, and the target's verdict is logged for the pooled reports
// once the job's receivers are checked.
using OnChoice = std::function<void(const std::string& who, const IntegratorChoice& choice)>;
SceneBake bake_scene(const SceneDescription& scene, const ScenePlan& plan, std::span<const Mesh> meshes, const EnvMap* env,
                     const Monitor& monitor, const std::function<void(const std::string&)>& log,
                     const SceneRows& rows = {}, const OnChoice& on_choice = {});

} // namespace prt::bake
