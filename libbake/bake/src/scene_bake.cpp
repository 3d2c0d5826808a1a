// scene_bake.cpp — runs a scene plan (bake/bake/scene.h): the receivers' per-vertex products against
// the union of the occluders and the area lights' rows, then FIV shells per occluder that needs them.
#include <bake/bake/error_report.h>
#include <bake/bake/pipeline.h>
#include <bake/bake/scene_bake.h>
#include <bake/bake/bounce.h>
#include <bake/core/error.h>
#include <bake/lights/area_bake.h>
#include <bake/lights/punctual.h>
#include <bake/visibility/raycast.h>

#include <tbb/global_control.h>
#include <tbb/enumerable_thread_specific.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <tuple>
#include <utility>

namespace prt::bake {
namespace {

// Receivers that get a log line each when baked (more: the progress stage and the total only).
constexpr size_t kObjectLinesUpTo = 12;

// The dry run's estimate times each group's integrator on this many seeded vertices.
constexpr size_t kEstimatePoints = 64;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// How the log names an object to people: a glTF instance by its node path ("node0/body"), a
// scene file's object by its name (the "|" spelling of glTF names is for HDF5 paths only).
const std::string& label_of(const SceneObject& o) { return o.node_path.empty() ? o.name : o.node_path; }

// snprintf of one or two numbers into a string (the log lines).
std::string printf_string(const char* f, double a, double b = 0) {
  char buf[160];
  std::snprintf(buf, sizeof buf, f, a, b);
  return buf;
}

// How a job's rows are counted in logs: its sets' noun when they share one, else "rows".
std::string rows_noun_of(const BakeJob& job) {
  for (const ReceiverSet& set : job.sets)
    if (std::string(set.rows_noun) != job.sets.front().rows_noun) return "rows";
  return job.sets.empty() ? "rows" : job.sets.front().rows_noun;
}

// The lights' rows of every point ([point][area.width() + punctual.width()]: the area lights'
// columns, then the punctual lights') through the row loop (bake/bake/vertex_bake.h); each row
// depends on its point only, so any thread count gives the same numbers.
std::vector<double> bake_area_lights(std::span<const ShadePoint> points, const AreaLightIntegrator& area,
                                     const PunctualLightIntegrator& punctual, const Monitor& monitor,
                                     const std::string& label) {
  tbb::enumerable_thread_specific<AreaLightIntegrator::Workspace> workspaces;
  const size_t split = area.width();
  VertexBake rows = bake_rows(
      0, points.size(), split + punctual.width(),
      [&](size_t v, std::span<double> values, std::span<double>) {
        area.integrate(points[v], values.first(split), workspaces.local());
        punctual.integrate(points[v], values.subspan(split));
      },
      monitor, label, "the lights (" + label + ")");
  return std::move(rows.values);
}

} // namespace

SceneBake bake_scene(const SceneDescription& scene, const ScenePlan& plan, std::span<const Mesh> meshes, const EnvMap* env,
                     const Monitor& monitor, const std::function<void(const std::string&)>& log, const SceneRows& rows,
                     const OnChoice& on_choice) {
  PRT_CHECK_OP(meshes.size(), ==, scene.objects.size());
  PRT_CHECK_OP(plan.objects.size(), ==, scene.objects.size());
  for (const PunctualLight& l : scene.punctual_lights)
    PRT_CHECK(l.angular_diameter == 0);  // a sun with an angle is an area light: place_suns first
  SceneBake out;
  out.objects.resize(scene.objects.size());
  const auto t_setup = std::chrono::steady_clock::now();

  // The occluder union, and where each occluder's vertices start in it.
  std::vector<Mesh> parts;
  std::vector<size_t> base(scene.objects.size(), SIZE_MAX);
  size_t offset = 0;
  for (size_t i = 0; i < scene.objects.size(); ++i)
    if (plan.objects[i].occluder) {
      base[i] = offset;
      offset += meshes[i].positions.size();
      parts.push_back(meshes[i]);
    }
  Mesh occluders;  // empty when nothing casts shadows: every receiver point is then unoccluded
  if (!parts.empty()) occluders = merge_meshes(parts, "occluders");
  else if (!meshes.empty()) occluders.origin = meshes[0].origin;  // the scene's frame (scene_origin), for the lights
  parts.clear();
  const Topology topo = build_topology(occluders);
  // The union's trees, built once for every integrator, pilot and reference below (bake/visibility/accel.h).
  const MeshAccel accel(occluders, topo);

  // Each receiver's shade points: a "both" receiver's vertices are shade points of the union
  // (their own 1-ring occludes in the ε-limit), a receiver-only object's are free points.
  auto receivers_of = [&](size_t i) {
    const Mesh& m = meshes[i];
    ReceiverSet set;
    set.name = label_of(scene.objects[i]);
    set.tag = i;
    set.points.resize(m.positions.size());
    for (size_t v = 0; v < set.points.size(); ++v) {
      if (plan.objects[i].occluder) {
        set.points[v] = vertex_shade_point(occluders, topo, uint32_t(base[i] + v));
      } else {
        set.points[v].p = m.positions[v].cast<double>();
        set.points[v].n = m.normals[v].cast<double>().normalized();
      }
    }
    return set;
  };

  // A receiver baked per texel (SceneObject::lightmap): its lightmap's valid texels as the set
  // (bake/bake/lightmap_receivers.h), kept in its ObjectBake for the image. The enclosure test
  // sees the union, and a texel at a corner is that vertex's shade point in the union (its ring
  // decided as the vertex bake decides it); for a receiver-only object, whose triangles are not
  // in the union, every texel is a free point, as its vertices are.
  auto texels_of = [&](size_t i) {
    const Mesh& m = meshes[i];
    const std::string name = label_of(scene.objects[i]);
    const TexelRebase rebase = [&](const TexelSample& sample, ShadePoint& sp) {
      if (sp.welded < 0) return;
      int corner = 0;
      for (int k = 1; k < 3; ++k)
        if (sample.barycentric[k] > sample.barycentric[corner]) corner = k;
      if (plan.objects[i].occluder)
        sp = vertex_shade_point(occluders, topo, uint32_t(base[i] + m.triangles[sample.triangle][size_t(corner)]));
      else
        sp.welded = -1;
    };
    ObjectBake& ob = out.objects[i];
    ob.lightmap = lightmap_receivers(m, build_topology(m), *scene.objects[i].lightmap, *accel.rays(), name,
                                     "object '" + name + "' of " + scene.file.string() + ": ", rebase);
    ReceiverSet set = ob.lightmap->receivers();
    set.tag = i;
    return set;
  };

  // One pipeline job per distinct product request (bake/bake/pipeline.h), over the receivers that
  // make it: with a target, one choice for them on their pooled shade points (bake/bake/scene.h
  // "target error": the target holds for their values together), one pilot and one report
  // reference for the scene rather than one per object (115 pilots of 1-16 s each on an engine
  // of small parts); the report's points are shared among the job's receivers by their vertices,
  // and its verdict is the pooled one.
  using Key = std::tuple<bool, int, int, bool, int>;
  auto key_of = [](const ProductRequest& r) {
    return Key{r.ao, r.transfer_order, r.visibility_order, r.radiance != nullptr, r.shadowed_order};
  };
  std::vector<BakeJob> jobs;
  std::map<Key, size_t> job_of;
  std::vector<size_t> shard_set(scene.objects.size(), SIZE_MAX);  // SceneRows' numbering
  size_t receivers = 0;  // with per-vertex products
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const ObjectPlan& p = plan.objects[i];
    if (!p.receiver || !p.any_vertex_product()) continue;
    const ProductRequest r = product_request(p, env);
    const auto [it, added] = job_of.emplace(key_of(r), jobs.size());
    if (added) jobs.emplace_back().request = r;
    jobs[it->second].sets.push_back(p.texels ? texels_of(i) : receivers_of(i));
    shard_set[i] = receivers++;
  }
  // How the log names a job: its object, or "N receivers (V vertices, from <first>)".
  for (BakeJob& job : jobs)
    job.name = job.sets.size() == 1 ? job.sets.front().name
                                    : std::to_string(job.sets.size()) + " receivers (" + std::to_string(job.row_count()) +
                                          " " + rows_noun_of(job) + ", from " + job.sets.front().name + ")";
  PipelineSettings settings;
  settings.integrator = scene.integrator;
  settings.target_error = scene.target_error;
  settings.integrator_given = scene.integrator_given;
  settings.counted_costs = scene.counted_costs;
  settings.correct = !rows.rows;  // sharded rows cannot be baked again here
  settings.bake_stage = "baking receivers";
  BakePipeline pipeline(occluders, topo, accel, std::move(settings), std::move(jobs));
  const bool target = scene.target_error > 0;

  PipelineHooks hooks;
  hooks.chosen = [&](const BakeJob& job) {
    if (on_choice) on_choice(job.name, *job.choice);
    else log(job.name + ": " + choice_summary(*job.choice));
  };
  hooks.check_planned = [&](const BakeJob& job) {
    if (rows.check_planned && job.reference_plan) rows.check_planned(job.name, *job.reference_plan);
  };

  if (rows.estimate_only) {
    // The dry run's estimate: per job, its integrator (chosen, with a target: the pilot runs)
    // timed on seeded vertices of its receivers, scaled to all of them; then the FIV steps the
    // same way, and the whole (SceneRows::estimate_only).
    pipeline.plan(monitor, hooks);
    const double planned = seconds_since(t_setup);  // the occluders' trees, the pilots
    const double threads = double(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
    double total = 0;  // wall seconds on `threads` after the plan
    for (BakeJob& job : pipeline.jobs()) {
      const size_t n = job.row_count();
      const std::optional<double> per_row = pipeline.cpu_seconds_per_row(job, kEstimatePoints);
      if (!per_row) {
        log(job.name + ": " + std::to_string(n) + " " + rows_noun_of(job) + "; the " + to_string(job.spec.kind) +
            " integrator's cost is not estimated (it needs every vertex's rays)");
        continue;
      }
      const double cpu = *per_row * double(n);
      total += cpu / threads;
      log(job.name + ": about " + printf_string("%.3g CPU s to bake ", cpu) + std::to_string(n) + " " + rows_noun_of(job) + " with " +
          to_string(job.spec.kind) + " at " + job.spec.knob_text() + printf_string(", %.3g s on ", cpu / threads) +
          std::to_string(int(threads)) + " threads (timed on " + std::to_string(std::min(kEstimatePoints, n)) +
          " seeded " + rows_noun_of(job) + ")");
      if (!target || job.spec.report_points == 0) continue;
      // The check the bake would plan (bake/bake/pipeline.h: as long as the bake, at least
      // kReportMinCpuSeconds), from the estimate.
      pipeline.plan_check(job, scene.counted_costs ? 0.0 : std::max(ReferencePlan::kReportMinCpuSeconds, cpu), monitor);
      const ReferencePlan& rp = *job.reference_plan;
      if (rp.us_per_ray > 0) {
        const double check = double(rp.rays) * double(rp.points) * rp.us_per_ray * 1e-6;
        total += check / threads;
        log("  and its error check about " + printf_string("%.3g CPU s", check) + " (a QMC reference of " +
            std::to_string(rp.rays) + " rays on " + std::to_string(rp.points) + " vertices)");
      }
    }
    // The FIV steps, each timed on seeded samples after its setup (done for real).
    auto fiv_line = [&](const std::string& what, const FivCost& c) {
      total += c.setup_seconds + c.cpu_seconds / threads;
      log(what + ": about " + printf_string("%.3g CPU s, %.3g s on ", c.cpu_seconds, c.setup_seconds + c.cpu_seconds / threads) +
          std::to_string(int(threads)) + " threads" + printf_string(" (setup %.2f s, then ", c.setup_seconds) +
          std::to_string(c.timed) + " seeded samples timed)");
    };
    if (plan.fiv_environment)
      fiv_line("the environment's FIV and " + std::to_string(scene.fiv.cube) + "x" + std::to_string(scene.fiv.cube) +
                   "x6 DifMap",
               environment_fiv_cost(*env, scene.fiv.cube, kEstimatePoints));
    // Each occluder's shells; with many (an engine whose parts all move), one line for them all.
    const std::string grid = "FIV shells " + std::to_string(scene.fiv.n_phi) + "x" + std::to_string(scene.fiv.n_theta) +
                             "x" + std::to_string(scene.fiv.n_rho);
    const std::string every = " (if every shell is needed)";
    size_t movers = 0;
    for (const ObjectPlan& p : plan.objects) movers += p.fiv ? 1 : 0;
    FivCost all;
    std::string dearest;
    double dearest_cpu = -1;
    for (size_t i = 0; i < scene.objects.size(); ++i)
      if (plan.objects[i].fiv) {
        const Topology t = build_topology(meshes[i]);
        FivCost c = fiv_shells_cost(meshes[i], t, *env, scene.fiv, kEstimatePoints);
        std::optional<FivCost> self;  // the self-shadows at its vertices (ShellSpec::vertex_self_shadows)
        if (scene.fiv.vertex_self_shadows) self = fiv_self_shadows_cost(meshes[i], t, *env, scene.fiv, kEstimatePoints);
        if (movers <= kObjectLinesUpTo) {
          fiv_line(label_of(scene.objects[i]) + ": " + grid + every, c);
          if (self)
            fiv_line(label_of(scene.objects[i]) + ": FIV self-shadows at its " + std::to_string(meshes[i].positions.size()) +
                         " vertices",
                     *self);
          continue;
        }
        if (self) c.setup_seconds += self->setup_seconds, c.cpu_seconds += self->cpu_seconds, c.timed += self->timed;
        all.setup_seconds += c.setup_seconds, all.cpu_seconds += c.cpu_seconds, all.timed += c.timed;
        if (c.cpu_seconds > dearest_cpu) dearest_cpu = c.cpu_seconds, dearest = label_of(scene.objects[i]);
      }
    if (movers > kObjectLinesUpTo)
      fiv_line(std::to_string(movers) + " occluders' " + grid + (scene.fiv.vertex_self_shadows ? " and self-shadows" : "") +
                   ", the dearest " + dearest +
                   printf_string(" at %.3g CPU s", dearest_cpu) + every,
               all);
    log(printf_string("in all about %.3g s on ", total + planned) + std::to_string(int(threads)) +
        printf_string(" threads: %.3g s of setup and choice (done above), ", planned) +
        printf_string("%.3g s after it (area lights and writing the file not counted)", total));
    return out;
  }

  // ---- area lights: exact, no choice or check; the receivers' shade points through the row loop ----
  // One integrator per SH order the receivers need (the lights moved into the occluders' frame once).
  std::map<int, std::unique_ptr<AreaLightIntegrator>> area_integrators;
  std::map<int, std::unique_ptr<PunctualLightIntegrator>> punctual_integrators;
  const RayCaster* shadow_rays = occluders.triangles.empty() ? nullptr : accel.rays().get();
  for (const ObjectPlan& p : plan.objects)
    if (p.receiver && p.area_irradiance && !area_integrators.count(p.area_sh_order)) {
      area_integrators.emplace(p.area_sh_order, std::make_unique<AreaLightIntegrator>(scene.lights, occluders, p.area_sh_order));
      punctual_integrators.emplace(p.area_sh_order, std::make_unique<PunctualLightIntegrator>(
                                                        scene.punctual_lights, shadow_rays, occluders.origin, p.area_sh_order));
    }
  out.setup_seconds = seconds_since(t_setup);
  for (size_t i = 0; i < scene.objects.size() && !rows.rows_only; ++i) {
    const ObjectPlan& p = plan.objects[i];
    if (!p.receiver || !p.area_irradiance) continue;
    ObjectBake& ob = out.objects[i];
    // Per texel for an object with a lightmap (its valid texels' rows, as its other products').
    const ReceiverSet set = !p.texels ? receivers_of(i) : ob.lightmap ? ob.lightmap->receivers() : texels_of(i);
    const auto t0 = std::chrono::steady_clock::now();
    ob.area = bake_area_lights(set.points, *area_integrators.at(p.area_sh_order), *punctual_integrators.at(p.area_sh_order),
                               monitor, "lights on " + set.name);
    ob.area_seconds = seconds_since(t0);
    out.area_seconds += ob.area_seconds;
    log(set.name + ": " + std::to_string(scene.lights.size()) + " area light(s)" +
        (scene.punctual_lights.empty() ? std::string() : " and " + std::to_string(scene.punctual_lights.size()) + " punctual") +
        " at " + std::to_string(set.points.size()) +
        " " + set.rows_noun + " in " + printf_string("%.2f s", ob.area_seconds) +
        (p.area_sh_order > 0 ? ", SH order " + std::to_string(p.area_sh_order) : std::string()));
  }
  area_integrators.clear();
  punctual_integrators.clear();

  // ---- FIV: the environment's, and shells per occluder that needs them ----
  if (plan.fiv_environment && !rows.rows_only) {
    PRT_CHECK(env != nullptr);
    const auto t0 = std::chrono::steady_clock::now();
    out.environment_fiv = environment_fiv(*env);
    out.irradiance_cube = irradiance_cube(*env, scene.fiv.cube);
    out.environment_seconds = seconds_since(t0);
    log("environment FIV and " + std::to_string(scene.fiv.cube) + "x" + std::to_string(scene.fiv.cube) + "x6 DifMap in " +
        printf_string("%.2f s", out.environment_seconds));
  }
  // Every occluder's shells as one progress stage (each may stop before its last shell: its share
  // is counted whole once it is done); a log line per occluder for a few, else the total.
  std::vector<size_t> movers;
  for (size_t i = 0; i < scene.objects.size() && !rows.rows_only; ++i)
    if (plan.objects[i].fiv) movers.push_back(i);
  // With self-shadows, each occluder's vertices follow its shells in the same stage.
  const bool self_shadows = scene.fiv.vertex_self_shadows;
  const uint64_t share = uint64_t(scene.fiv.n_rho) * uint64_t(scene.fiv.n_phi) * uint64_t(scene.fiv.n_theta);
  uint64_t fiv_total = share * movers.size();
  if (self_shadows)
    for (size_t i : movers) fiv_total += meshes[i].positions.size();
  uint64_t fiv_before = 0;
  bool fiv_last = false;
  const Monitor fiv_stage = fold_tasks(monitor, self_shadows ? "baking FIV shells and self-shadows" : "baking FIV shells",
                                       fiv_total, fiv_before, std::chrono::steady_clock::now(), &fiv_last);
  for (size_t k = 0; k < movers.size(); ++k) {
    const size_t i = movers[k];
    const Mesh& m = meshes[i];
    const Topology t = build_topology(m);
    ObjectBake& ob = out.objects[i];
    fiv_last = k + 1 == movers.size() && !self_shadows;
    ob.shells = bake_fiv_shells(m, t, *env, scene.fiv, fiv_stage);
    fiv_before += share;
    if (self_shadows) {
      fiv_last = k + 1 == movers.size();
      ob.fiv_self = bake_fiv_self_shadows(m, t, *env, scene.fiv, scene.integrator.seed, fiv_stage);
      fiv_before += m.positions.size();
      out.fiv_seconds += ob.fiv_self->values.seconds;
    }
    out.fiv_seconds += ob.shells->seconds;
    if (movers.size() <= kObjectLinesUpTo)
      log(label_of(scene.objects[i]) + ": FIV shells " + std::to_string(scene.fiv.n_phi) + "x" +
          std::to_string(scene.fiv.n_theta) + "x" + std::to_string(ob.shells->radii.size()) + " in " +
          printf_string("%.2f s", ob.shells->seconds) +
          (ob.fiv_self ? ", self-shadows at " + std::to_string(m.positions.size()) + " vertices in " +
                             printf_string("%.2f s", ob.fiv_self->values.seconds)
                       : std::string()));
  }
  if (movers.size() > kObjectLinesUpTo)
    log(std::to_string(movers.size()) + " occluders' FIV shells " + std::to_string(scene.fiv.n_phi) + "x" +
        std::to_string(scene.fiv.n_theta) + " in " + printf_string("%.2f s", out.fiv_seconds));

  // ---- receivers: the pipeline (choose, integrate, check, correct) ----
  hooks.ready = [&](const BakeJob& job) { out.setup_seconds += job.setup_seconds; };
  hooks.rows_only = rows.rows_only;
  if (rows.rows)
    hooks.rows = [&](const BakeJob& job, size_t s, const Monitor& stage) {
      const ReceiverSet& set = job.sets[s];
      return rows.rows(shard_set[set.tag], set.points, *job.integrator, stage);
    };
  // ---- interreflections (plan rule "bounces"; bake/bake/bounce.h) ----
  // Every receiver's direct rows are kept: a correction re-bakes some, and the bounces are always
  // made from the direct rows of all of them (never from rows that already carry bounces).
  std::vector<std::optional<VertexBake>> direct_rows(scene.objects.size());
  std::optional<GatherHits> gather_hits;  // cast once, reused after a correction
  // The area lights' direct rows, kept the same way (ObjectBake::area is replaced by the bounced).
  std::vector<std::optional<std::vector<double>>> direct_area(scene.objects.size());
  auto bounce_receivers = [&] {
    const size_t nl = scene.light_count();
    std::vector<size_t> gatherers;
    for (size_t i = 0; i < scene.objects.size(); ++i) {
      const ObjectPlan& p = plan.objects[i];
      if (!p.bounce_radiance && !p.bounce_transfer && !p.bounce_area && !p.bounce_shadowed) continue;
      if ((p.bounce_radiance || p.bounce_transfer || p.bounce_shadowed) && !direct_rows[i]) continue;
      if (p.bounce_area && !direct_area[i]) direct_area[i] = out.objects[i].area;
      if (p.bounce_area && !direct_area[i]) continue;
      gatherers.push_back(i);
    }
    if (gatherers.empty()) return;
    // The union's triangle ranges: occluders in object order (merge_meshes).
    std::vector<uint32_t> first_triangle(scene.objects.size(), 0);
    std::vector<Albedo> albedo(occluders.triangles.size(), Albedo{0, 0, 0});
    for (size_t i = 0, t = 0; i < scene.objects.size(); ++i)
      if (plan.objects[i].occluder) {
        first_triangle[i] = uint32_t(t);
        if (plan.objects[i].bounce_reflects)
          std::fill_n(albedo.begin() + std::ptrdiff_t(t), meshes[i].triangles.size(), scene.objects[i].material.albedo);
        t += meshes[i].triangles.size();
      }
    // The rows side by side, per gatherer in order: T (when it bounces, at its one order) and each
    // light's E_l after it, in the transfer's slot — E_l's recursion is T's, eq. (2) with a scalar
    // for y_i: E^{b+1}_l(p) = ∫ (1 − V) H (ρ/π) E^b_l(h) (n·ω) dω, grey ρ (the plan's rule) — then R.
    // S at the largest order among them; an object of a lower order takes its first L² of each
    // channel's coefficients (the rest are zeros in, dropped out).
    int order = 0, s_order = 0;
    bool radiance = false, area = false;
    for (const size_t i : gatherers) {
      if (plan.objects[i].bounce_transfer) order = plan.objects[i].transfer_order;
      if (plan.objects[i].bounce_shadowed) s_order = std::max(s_order, plan.objects[i].shadowed_order);
      radiance = radiance || plan.objects[i].bounce_radiance;
      area = area || plan.objects[i].bounce_area;
    }
    const size_t nt = size_t(order) * size_t(order), na = area ? nl : 0;
    ProductRequest q;
    q.radiance = radiance ? env : nullptr;
    if (s_order > 0) q.shadowed = env, q.shadowed_order = s_order;
    ProductLayout layout(q);  // R at 0, S after it; then T and E_l put before them
    layout.transfer = 0;
    layout.transfer_count = nt + na;
    layout.visibility = layout.radiance = nt + na;
    layout.shadowed = layout.radiance + layout.radiance_count;
    layout.width = layout.shadowed + layout.shadowed_count;
    const size_t ls2 = size_t(s_order) * size_t(s_order);
    auto s_count = [&](size_t i) { return size_t(plan.objects[i].shadowed_order) * size_t(plan.objects[i].shadowed_order); };
    std::vector<ShadePoint> points;
    std::vector<std::unique_ptr<BounceField>> fields;
    SceneField field;
    for (const size_t i : gatherers) {
      const ObjectBake& ob = out.objects[i];
      const ReceiverSet set = ob.lightmap ? ob.lightmap->receivers() : receivers_of(i);
      points.insert(points.end(), set.points.begin(), set.points.end());
      if (ob.lightmap) fields.push_back(std::make_unique<TexelField>(meshes[i], *ob.lightmap, 2));
      else fields.push_back(std::make_unique<VertexField>(meshes[i]));
      field.add(*fields.back(), first_triangle[i],
                plan.objects[i].occluder ? uint32_t(meshes[i].triangles.size()) : 0u);
    }
    auto area_stride = [&](size_t i) { return 1 + size_t(plan.objects[i].area_sh_order) * size_t(plan.objects[i].area_sh_order); };
    std::vector<double> direct(points.size() * layout.width, 0.0);
    std::vector<uint8_t> shadowed_rows;  // the rows whose S bounces (empty: no S)
    if (s_order > 0)
      for (size_t g = 0; g < gatherers.size(); ++g)
        shadowed_rows.insert(shadowed_rows.end(), fields[g]->rows(), plan.objects[gatherers[g]].bounce_shadowed ? 1 : 0);
    size_t row = 0;
    for (size_t g = 0; g < gatherers.size(); ++g) {
      const size_t i = gatherers[g];
      const ObjectPlan& p = plan.objects[i];
      const size_t n = fields[g]->rows();
      for (size_t r = 0; r < n; ++r, ++row) {
        double* to = &direct[row * layout.width];
        if (p.bounce_transfer || p.bounce_radiance || p.bounce_shadowed) {
          const VertexBake& d = *direct_rows[i];
          const double* from = &d.values[r * d.layout.width];
          if (p.bounce_transfer) std::copy_n(from + d.layout.transfer, nt, to);
          if (p.bounce_radiance) std::copy_n(from + d.layout.radiance, 9, to + layout.radiance);
          if (p.bounce_shadowed)
            for (size_t c = 0; c < 3; ++c)
              std::copy_n(from + d.layout.shadowed + c * s_count(i), s_count(i), to + layout.shadowed + c * ls2);
        }
        if (p.bounce_area)
          for (size_t l = 0; l < nl; ++l) to[nt + l] = (*direct_area[i])[(r * nl + l) * area_stride(i)];
      }
    }
    PRT_CHECK_OP(row, ==, points.size());
    BounceSpec spec;
    spec.bounces = scene.bounces;
    spec.rays = scene.bounce_rays ? scene.bounce_rays : BounceSpec::kDefaultRays;
    spec.seed = scene.integrator.seed;
    if (!gather_hits)
      gather_hits = gather(*accel.rays(), points, spec, radiance || s_order > 0, monitor, "casting bounce rays");
    const BounceResult r = bounce_rows(field, points, *gather_hits, albedo, layout, direct, spec, scene.file.string(),
                                       monitor, "bouncing light", shadowed_rows);
    row = 0;
    for (size_t g = 0; g < gatherers.size(); ++g) {
      const size_t i = gatherers[g];
      ObjectBake& ob = out.objects[i];
      const ObjectPlan& p = plan.objects[i];
      const size_t n = fields[g]->rows();
      if (p.bounce_transfer || p.bounce_radiance || p.bounce_shadowed) ob.values = direct_rows[i];
      if (p.bounce_area) ob.area = direct_area[i];
      for (size_t k = 0; k < n; ++k, ++row) {
        const double* from = &r.values[row * layout.width];
        if (p.bounce_transfer || p.bounce_radiance || p.bounce_shadowed) {
          VertexBake& v = *ob.values;
          double* to = &v.values[k * v.layout.width];
          if (p.bounce_transfer) std::copy_n(from, nt, to + v.layout.transfer);
          if (p.bounce_radiance) std::copy_n(from + layout.radiance, 9, to + v.layout.radiance);
          if (p.bounce_shadowed)
            for (size_t c = 0; c < 3; ++c)
              std::copy_n(from + layout.shadowed + c * ls2, s_count(i), to + v.layout.shadowed + c * s_count(i));
        }
        if (p.bounce_area)
          for (size_t l = 0; l < nl; ++l) (*ob.area)[(k * nl + l) * area_stride(i)] = from[nt + l];
      }
      ob.bounced_radiance = p.bounce_radiance;
      ob.bounced_transfer = p.bounce_transfer;
      ob.bounced_area = p.bounce_area;
      ob.bounced_shadowed = p.bounce_shadowed;
    }
    size_t met = 0;
    for (const uint32_t t : gather_hits->triangle)
      if (t != GatherHits::kNone && (albedo[t][0] > 0 || albedo[t][1] > 0 || albedo[t][2] > 0)) ++met;
    out.bounces_applied = r.applied;
    out.bounce_relative_rms = r.relative_rms;
    out.bounce_relative_std_error = r.total_relative_std_error();
    out.bounce_rays = spec.rays;
    out.gather_seconds = gather_hits->seconds;
    out.bounce_seconds = 0;
    for (const double x : r.seconds) out.bounce_seconds += x;
    out.gather_bytes = gather_hits->bytes();
    out.reflecting_share = gather_hits->triangle.empty() ? 0 : double(met) / double(gather_hits->triangle.size());
    std::string rms;
    for (const double x : r.relative_rms) rms += printf_string(" %.3g", x);
    char line[512];
    std::snprintf(line, sizeof line,
                  "bounces: %d of %d over %zu receiver rows of %zu object(s) (each bounce's RMS / the direct pass's:%s; "
                  "their Monte Carlo error %.2g of it); "
                  "%u gather rays per row in %.2f s (cached hits %.1f MB), %.1f%% of them met a reflecting surface; the "
                  "bounces took %.3f s",
                  r.applied, scene.bounces, points.size(), gatherers.size(), rms.c_str(), out.bounce_relative_std_error,
                  spec.rays, out.gather_seconds,
                  double(out.gather_bytes) / 1e6, 100 * out.reflecting_share, out.bounce_seconds);
    log(std::string(line) +
        (met == 0 ? " — no ray met a reflecting surface: these bounces add nothing (a convex object alone)" : ""));
  };

  hooks.set_baked = [&](const BakeJob& job, size_t s) {
    const ReceiverSet& set = job.sets[s];
    ObjectBake& ob = out.objects[set.tag];
    ob.values = job.rows[s];
    direct_rows[set.tag] = job.rows[s];
    ob.report.reset();
    ob.integrator = job.spec;
    ob.choice = job.choice;
    ob.reference_plan.reset();
    ob.integrator_description = job.integrator_description;
    ob.closed_form_vertices = ob.values->closed_form;
    // A line per object for a scene of a few; an engine of 115 parts gets the progress stage and
    // the total (the file has every object's time).
    if (receivers <= kObjectLinesUpTo)
      log(set.name + ": " + std::to_string(set.points.size()) + " " + set.rows_noun + " in " +
          printf_string("%.2f s", ob.values->seconds) +
          (ob.closed_form_vertices > 0 ? ", " + std::to_string(ob.closed_form_vertices) + " saw no contour edge (closed form)"
                                       : std::string()));
  };
  hooks.baked = [&] {
    if (plan.bounces && !rows.rows_only) bounce_receivers();
    out.vertex_seconds = 0;
    out.vertices = out.texels = 0;
    for (const ObjectBake& ob : out.objects)
      if (ob.values) {
        out.vertex_seconds += ob.values->seconds;
        (ob.lightmap ? out.texels : out.vertices) += ob.values->values.size() / std::max<size_t>(ob.values->layout.width, 1);
      }
    // The bake is whole: the caller may write it before the checks (which may be cancelled).
    if (rows.baked) rows.baked(out);
  };
  hooks.set_checked = [&](const BakeJob& job, size_t s) {
    const ReceiverSet& set = job.sets[s];
    ObjectBake& ob = out.objects[set.tag];
    ob.report = job.reports[s];
    ob.integrator = job.spec;
    ob.reference_plan = job.reference_plan;
    out.report_seconds += ob.report->reference_seconds;
    // In a job of several receivers, each holds a few of the report's vertices: its own RMSE says
    // little (it is in the file); the pooled lines say what was met.
    if (target && job.sets.size() > 1) return;
    std::string line = set.name + ": error on " + std::to_string(ob.report->vertices.size()) + " seeded " + set.rows_noun + ":";
    for (const auto& e : ob.report->products)
      line += " " + std::string(product_label(e.product)) + printf_string(" RMSE %.3e (max %.3e; ", e.rmse, e.max_abs) +
              (ob.report->reference_noise_measured ? "reference's own noise, measured, " : "reference's own std. error ") +
              printf_string("%.1e)", e.reference_std_error);
    log(line + printf_string("; reference took %.2f s", ob.report->reference_seconds));
  };
  hooks.job_checked = [&](const BakeJob& job) {
    // The job's verdict on its pooled report, or without a target what its RMSE means: the bake's
    // own error with the reference's noise taken out (bake/bake/choose.h).
    if (job.sets.size() > 1)
      log("receivers from " + job.sets.front().name + " (" + std::to_string(job.sets.size()) + " objects), their " +
          std::to_string(job.pooled->vertices.size()) + " report vertices together" +
          printf_string(" (the reference took %.2f s):", job.pooled->reference_seconds));
    for (const std::string& l :
         target ? target_check_lines(*job.pooled, scene.target_error, job.reference_plan ? &*job.reference_plan : nullptr)
                : error_estimate_lines(*job.pooled))
      log(l);
  };
  hooks.correcting = [&](const BakeJob& job, const IntegratorSpec& better) {
    log(job.name + ": " + correction_text(job, better));
  };
  pipeline.run(monitor, hooks);
  if (rows.rows_only) return out;

  // ---- FIV error reports ----
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    ObjectBake& ob = out.objects[i];
    if (!ob.shells || scene.integrator.report_points == 0) continue;
    const Mesh& m = meshes[i];
    const Topology t = build_topology(m);
    ob.fiv_report = fiv_error_report(m, t, *env, *ob.shells, out.environment_fiv, scene.integrator.report_points,
                                     scene.integrator.seed, monitor);
    log(label_of(scene.objects[i]) + ": fiv " + printf_string("RMSE %.3e, relative to RMS|F_env| %.3e", ob.fiv_report->rmse,
                        ob.fiv_report->reference_rms > 0 ? ob.fiv_report->rmse / ob.fiv_report->reference_rms : 0.0));
  }
  return out;
}

ProductRequest product_request(const ObjectPlan& p, const EnvMap* env) {
  ProductRequest r;
  r.ao = p.ao;
  r.transfer_order = p.transfer_order;
  r.visibility_order = p.visibility_order;
  r.radiance = p.radiance ? env : nullptr;
  if (p.shadowed_order > 0 && env) r.shadowed = env, r.shadowed_order = p.shadowed_order;
  return r;
}

} // namespace prt::bake
