// scene_bake.cpp — runs a scene plan (bake/bake/scene.h): the receivers' per-vertex products against
// the union of the occluders and the area lights' rows, then FIV shells per occluder that needs them.
#include <bake/bake/error_report.h>
#include <bake/bake/scene_bake.h>
#include <bake/core/error.h>
#include <bake/lights/area_bake.h>

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <tuple>

namespace prt::bake {
namespace {

// Receivers that get a log line each when baked (more: the progress stage and the total only).
constexpr size_t kObjectLinesUpTo = 12;

// The dry run's estimate times each group's integrator on this many seeded vertices.
constexpr size_t kEstimatePoints = 64;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// A monitor that folds a sequence of tasks (one per object) into one progress stage `label` of
// `total` units: each task's count is offset by `*before` (the units of the tasks already done,
// which the caller advances), the time runs from `start`, and the stage finishes with the last
// task (or with a cancelled one).
Monitor one_stage(const Monitor& monitor, const char* label, const uint64_t& total, const uint64_t& before,
                  std::chrono::steady_clock::time_point start) {
  Monitor m;
  m.cancel = monitor.cancel;
  if (monitor.on_progress)
    m.on_progress = [&monitor, label, &total, &before, start](const ProgressUpdate& u) {
      ProgressUpdate o = u;
      o.task = label;
      o.done = before + u.done;
      o.total = total;
      o.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      o.finished = u.finished && (o.done == o.total || u.done < u.total);  // the last task, or a cancel
      monitor.on_progress(o);
    };
  return m;
}

// snprintf of one or two numbers into a string (the log lines).
std::string printf_string(const char* f, double a, double b = 0) {
  char buf[160];
  std::snprintf(buf, sizeof buf, f, a, b);
  return buf;
}

// The area lights' rows of every point ([point][integ.width()]), in parallel; each row depends
// on its point only, so any thread count gives the same numbers.
std::vector<double> bake_area_lights(std::span<const ShadePoint> points, const AreaLightIntegrator& integ,
                                     const Monitor& monitor, const std::string& label) {
  const size_t W = integ.width();
  std::vector<double> out(points.size() * W, 0.0);
  Task progress(monitor, label, points.size());
  tbb::enumerable_thread_specific<AreaLightIntegrator::Workspace> workspaces;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, points.size(), 16), [&](const tbb::blocked_range<size_t>& r) {
    AreaLightIntegrator::Workspace& ws = workspaces.local();
    for (size_t v = r.begin(); v != r.end(); ++v) integ.integrate(points[v], std::span(out).subspan(v * W, W), ws);
    progress.advance(r.size());
  });
  progress.finish();
  for (size_t k = 0; k < out.size(); ++k)
    if (!std::isfinite(out[k]))
      throw ContractError("bake_area_lights: non-finite value at vertex " + std::to_string(k / W) + " (" + label + ")");
  return out;
}

} // namespace

SceneBake bake_scene(const SceneDescription& scene, const ScenePlan& plan, std::span<const Mesh> meshes, const EnvMap* env,
                     const Monitor& monitor, const std::function<void(const std::string&)>& log, const SceneRows& rows,
                     const OnChoice& on_choice) {
  PRT_CHECK_OP(meshes.size(), ==, scene.objects.size());
  PRT_CHECK_OP(plan.objects.size(), ==, scene.objects.size());
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

  // One integrator (and one reference) per distinct product request.
  using Key = std::tuple<bool, int, int, bool, int>;
  auto key_of = [](const ProductRequest& r) {
    return Key{r.ao, r.transfer_order, r.visibility_order, r.radiance != nullptr, r.shadowed_order};
  };
  std::map<Key, std::pair<std::unique_ptr<Integrator>, std::unique_ptr<Integrator>>> integrators;
  auto request_of = [&](const ObjectPlan& p) { return product_request(p, env); };
  const bool choose = scene.target_error > 0;  // then one integrator per object, made below
  for (size_t i = 0; i < scene.objects.size() && !choose; ++i) {
    const ObjectPlan& p = plan.objects[i];
    if (!p.receiver || !p.any_vertex_product()) continue;
    const ProductRequest r = request_of(p);
    const Key key = key_of(r);
    if (integrators.count(key)) continue;
    auto integ = make_integrator(scene.integrator, occluders, topo, r, &accel);
    std::unique_ptr<Integrator> ref;
    if (scene.integrator.report_points > 0) ref = make_reference(scene.integrator, occluders, topo, r, &accel);
    integrators.emplace(key, std::make_pair(std::move(integ), std::move(ref)));
  }
  // One area-light integrator per SH order the receivers need (the lights moved into the
  // occluders' frame once).
  std::map<int, std::unique_ptr<AreaLightIntegrator>> area_integrators;
  for (const ObjectPlan& p : plan.objects)
    if (p.receiver && p.area_irradiance && !area_integrators.count(p.area_sh_order))
      area_integrators.emplace(p.area_sh_order, std::make_unique<AreaLightIntegrator>(scene.lights, occluders, p.area_sh_order));
  out.setup_seconds = seconds_since(t_setup);

  // ---- receivers ----
  uint64_t receiver_vertices = 0;  // of the receivers with per-vertex products (the report's budget)
  for (size_t i = 0; i < scene.objects.size(); ++i)
    if (plan.objects[i].receiver && plan.objects[i].any_vertex_product()) receiver_vertices += meshes[i].positions.size();
  // Each receiver's shade points: a "both" receiver's vertices are shade points of the union
  // (their own 1-ring occludes in the ε-limit), a receiver-only object's are free points.
  auto shade_points = [&](size_t i) {
    const Mesh& m = meshes[i];
    std::vector<ShadePoint> points(m.positions.size());
    for (size_t v = 0; v < points.size(); ++v) {
      if (plan.objects[i].occluder) {
        points[v] = vertex_shade_point(occluders, topo, uint32_t(base[i] + v));
      } else {
        points[v].p = m.positions[v].cast<double>();
        points[v].n = m.normals[v].cast<double>().normalized();
      }
    }
    return points;
  };
  // With a target, one choice per distinct product request, made on the pooled shade points of
  // every receiver that makes it (bake/bake/scene.h "target error": the target holds for those
  // receivers' values together): one pilot and one report reference for the scene, not one per
  // object (115 pilots of 1-16 s each on an engine of small parts). The report's points are
  // shared among the group's objects by their vertices, and its verdict is the pooled one.
  struct Group {
    std::vector<size_t> objects;      // in scene order
    std::vector<ShadePoint> points;   // theirs, concatenated
    IntegratorSpec spec;
    IntegratorChoice choice;
    std::optional<ReferencePlan> reference_plan;
    std::unique_ptr<Integrator> integ, ref, ref2;
    std::vector<ProductError> pooled;  // the objects' reports, merged as they come
    size_t report_points = 0, remaining = 0, checked = 0;
    bool chosen = false;
  };
  std::map<Key, Group> groups;
  if (choose || rows.estimate_only) {
    for (size_t i = 0; i < scene.objects.size(); ++i) {
      const ObjectPlan& p = plan.objects[i];
      if (!p.receiver || !p.any_vertex_product()) continue;
      Group& g = groups[key_of(request_of(p))];
      g.objects.push_back(i);
      ++g.remaining;
    }
  }
  // How the log names a group: its object, or "N receivers (V vertices, from <first>)".
  auto group_label = [&](const Group& g) {
    if (g.objects.size() == 1) return scene.objects[g.objects.front()].name;
    uint64_t v = 0;
    for (size_t j : g.objects) v += meshes[j].positions.size();
    return std::to_string(g.objects.size()) + " receivers (" + std::to_string(v) + " vertices, from " +
           scene.objects[g.objects.front()].name + ")";
  };
  auto choose_for = [&](Group& g, const ProductRequest& r) {
    for (size_t j : g.objects) {
      std::vector<ShadePoint> pts = shade_points(j);
      g.points.insert(g.points.end(), pts.begin(), pts.end());
    }
    ChooserOptions copt;
    copt.target = scene.target_error;
    if (scene.integrator_given) copt.only = scene.integrator.kind;
    copt.counted_costs = scene.counted_costs;
    g.choice = choose_integrator(g.points, occluders, topo, r, scene.integrator, copt, monitor, &accel);
    g.spec = g.choice.spec;
    // The report's reference: its noise within E/3 (or the plan says why not), bake/bake/choose.h; the
    // scene's ray budget shared among the groups by their vertices.
    if (g.spec.report_points > 0 && !rows.rows_only) {
      const uint64_t budget = uint64_t(double(ReferencePlan::kReportRayBudget) * double(g.points.size()) /
                                       double(std::max<uint64_t>(receiver_vertices, 1)));
      // The check may take about as long as the group's predicted bake (at least
      // kReportMinCpuSeconds of CPU; not with counted costs, whose rays must not depend on speed).
      double bake_cpu = 0;
      for (const Prediction& pr : g.choice.predictions)
        if (pr.kind == g.spec.kind) bake_cpu = pr.predicted_us_per_point * 1e-6 * double(g.points.size());
      const double check_cpu =
          scene.counted_costs ? 0.0 : std::max(ReferencePlan::kReportMinCpuSeconds, bake_cpu);
      g.reference_plan = plan_report_reference(g.points, occluders, topo, r, g.spec, scene.target_error, monitor, &accel,
                                               std::max<uint64_t>(budget, 1), check_cpu);
      g.spec.report_rays = g.reference_plan->rays;
    }
    g.report_points = g.spec.report_points;
    const std::string who = group_label(g);
    if (on_choice)
      on_choice(who, g.choice, g.reference_plan ? &*g.reference_plan : nullptr);
    else
      log(who + ": " + choice_summary(g.choice));
    g.integ = make_integrator(g.spec, occluders, topo, r, &accel);
    // The check's reference as two independent halves: its noise measured on the report's values.
    if (g.spec.report_points > 0 && !rows.rows_only)
      std::tie(g.ref, g.ref2) = make_reference_pair(g.spec, occluders, topo, r, &accel);
    g.points.clear();
    g.points.shrink_to_fit();
    g.chosen = true;
  };

  if (rows.estimate_only) {
    // The dry run's estimate: per group, its integrator (chosen, with a target: the pilot runs)
    // timed on seeded vertices of the group, scaled to all of them (SceneRows::estimate_only).
    const double threads = double(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
    for (auto& [key, g] : groups) {
      const ProductRequest r = request_of(plan.objects[g.objects.front()]);
      if (choose) choose_for(g, r);
      const Integrator& integ = choose ? *g.integ : *integrators.at(key).first;
      std::vector<ShadePoint> pts;
      for (size_t j : g.objects) {
        std::vector<ShadePoint> o = shade_points(j);
        pts.insert(pts.end(), o.begin(), o.end());
      }
      const std::string who = group_label(g);
      if (integ.kind() == IntegratorKind::Filter) {
        log(who + ": " + std::to_string(pts.size()) + " vertices; the filter integrator's cost is not estimated "
                                                      "(it needs every vertex's rays)");
        continue;
      }
      const std::vector<uint32_t> sample = seeded_sample(uint32_t(pts.size()), kEstimatePoints, scene.integrator.seed);
      std::vector<double> row(integ.layout().width);
      const double t0 = thread_cpu_seconds();
      for (uint32_t v : sample) integ.integrate(pts[v], v, row);
      const double per_point = (thread_cpu_seconds() - t0) / double(std::max<size_t>(sample.size(), 1));
      const double cpu = per_point * double(pts.size());
      const IntegratorSpec& spec = choose ? g.spec : scene.integrator;
      log(who + ": about " + printf_string("%.3g CPU s to bake ", cpu) + std::to_string(pts.size()) + " vertices with " +
          to_string(spec.kind) + " at " + spec.knob_text() +
          printf_string(", %.3g s on ", cpu / threads) + std::to_string(int(threads)) + " threads (timed on " +
          std::to_string(sample.size()) + " seeded vertices)");
      if (g.reference_plan && g.reference_plan->us_per_ray > 0)
        log("  and its error check about " +
            printf_string("%.3g CPU s", double(g.reference_plan->rays) * double(g.reference_plan->points) *
                                            g.reference_plan->us_per_ray * 1e-6) +
            " (a QMC reference of " + std::to_string(g.reference_plan->rays) + " rays on " +
            std::to_string(g.reference_plan->points) + " vertices)");
    }
    return out;
  }

  // One progress stage, "baking receivers", over every receiver's vertices (one ETA for the
  // scene, not a stage per object): each object's bake reports into it, offset by the vertices
  // baked before it; it finishes with the last.
  uint64_t vertices_before = 0;
  const Monitor overall = one_stage(monitor, "baking receivers", receiver_vertices, vertices_before,
                                    std::chrono::steady_clock::now());

  // The error reports to make once every receiver is baked.
  struct Check {
    size_t object;
    const Integrator *ref, *ref2;
    Group* group;
    size_t points;
  };
  std::vector<Check> checks;

  size_t receivers = 0;  // with per-vertex products
  for (size_t i = 0; i < scene.objects.size(); ++i)
    receivers += plan.objects[i].receiver && plan.objects[i].any_vertex_product();

  size_t set = 0;  // receivers with per-vertex products so far (SceneRows)
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const ObjectPlan& p = plan.objects[i];
    if (!p.receiver || (!p.any_vertex_product() && !p.area_irradiance)) continue;
    const ProductRequest r = request_of(p);
    const std::vector<ShadePoint> points = shade_points(i);
    ObjectBake& ob = out.objects[i];
    if (p.area_irradiance && !rows.rows_only) {
      const auto t0 = std::chrono::steady_clock::now();
      ob.area = bake_area_lights(points, *area_integrators.at(p.area_sh_order), monitor,
                                 "area lights on " + scene.objects[i].name);
      ob.area_seconds = seconds_since(t0);
      out.area_seconds += ob.area_seconds;
      log(scene.objects[i].name + ": " + std::to_string(scene.lights.size()) + " area light(s) at " +
          std::to_string(points.size()) + " vertices in " + printf_string("%.2f s", ob.area_seconds) +
          (p.area_sh_order > 0 ? ", SH order " + std::to_string(p.area_sh_order) : std::string()));
    }
    if (!p.any_vertex_product()) continue;
    ob.integrator = scene.integrator;
    const Integrator* integ = nullptr;
    const Integrator* ref = nullptr;
    const Integrator* ref2 = nullptr;
    Group* group = nullptr;
    size_t report_points = scene.integrator.report_points;
    if (choose) {
      group = &groups.at(key_of(r));
      if (!group->chosen) choose_for(*group, r);
      ob.choice = group->choice;
      ob.reference_plan = group->reference_plan;
      ob.integrator = group->spec;
      integ = group->integ.get();
      ref = group->ref.get();
      ref2 = group->ref2.get();
      // This object's share of the group's report points, by its vertices (at least one).
      uint64_t group_vertices = 0;
      for (size_t j : group->objects) group_vertices += meshes[j].positions.size();
      report_points = size_t(std::ceil(double(group->report_points) * double(points.size()) /
                                       double(std::max<uint64_t>(group_vertices, 1))));
      report_points = std::min(std::max<size_t>(report_points, 1), points.size());
    } else {
      const auto& shared = integrators.at(key_of(r));
      integ = shared.first.get();
      ref = shared.second.get();
    }
    PRT_CHECK(integ != nullptr);
    const Integrator& integrator = *integ;
    const std::string label = "baking " + scene.objects[i].name;
    if (rows.rows) {
      ob.values = rows.rows(set++, points, integrator, monitor, label, ob.closed_form_vertices);
      if (rows.rows_only) continue;
    } else {
      const uint64_t closed_before = integrator.stats().closed_form;
      ob.values = bake_points(points, integrator, overall, label);
      vertices_before += points.size();
      ob.closed_form_vertices = integrator.stats().closed_form - closed_before;
    }
    ob.integrator_description = integrator.description();
    out.vertex_seconds += ob.values->seconds;
    out.vertices += points.size();
    // A line per object for a scene of a few; an engine of 115 parts gets the progress stage and
    // the total (the file has every object's time).
    if (receivers <= kObjectLinesUpTo)
      log(scene.objects[i].name + ": " + std::to_string(points.size()) + " vertices in " +
          printf_string("%.2f s", ob.values->seconds) +
          (ob.closed_form_vertices > 0 ? ", " + std::to_string(ob.closed_form_vertices) + " saw no contour edge (closed form)"
                                       : std::string()));
    if (ref && report_points > 0) checks.push_back({i, ref, ref2, group, report_points});
    if (group && --group->remaining == 0) group->integ.reset();  // its references stay for the checks
  }

  // ---- FIV ----
  if (rows.rows_only) return out;
  if (plan.fiv_environment) {
    PRT_CHECK(env != nullptr);
    const auto t0 = std::chrono::steady_clock::now();
    out.environment_fiv = environment_fiv(*env);
    out.irradiance_cube = irradiance_cube(*env, scene.fiv.cube);
    out.environment_seconds = seconds_since(t0);
    log("environment FIV and " + std::to_string(scene.fiv.cube) + "x" + std::to_string(scene.fiv.cube) + "x6 DifMap in " +
        printf_string("%.2f s", out.environment_seconds));
  }
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    if (!plan.objects[i].fiv) continue;
    const Mesh& m = meshes[i];
    const Topology t = build_topology(m);
    ObjectBake& ob = out.objects[i];
    ob.shells = bake_fiv_shells(m, t, *env, scene.fiv, monitor);
    out.fiv_seconds += ob.shells->seconds;
    log(scene.objects[i].name + ": FIV shells " + std::to_string(scene.fiv.n_phi) + "x" + std::to_string(scene.fiv.n_theta) +
        "x" + std::to_string(ob.shells->radii.size()) + " in " + printf_string("%.2f s", ob.shells->seconds));
  }
  // The bake is whole: the caller may write it before the checks below (which may be cancelled).
  if (rows.baked) rows.baked(out);
  // ---- the error reports, once every receiver is baked ----
  // (One "checking the error" progress stage over every report vertex, after the one bake stage.)
  uint64_t check_total = 0, checked_before = 0;
  for (const Check& c : checks) check_total += c.points;
  const Monitor check_monitor =
      one_stage(monitor, "checking the error", check_total, checked_before, std::chrono::steady_clock::now());
  for (Check& c : checks) {
    const size_t i = c.object;
    ObjectBake& ob = out.objects[i];
    const std::vector<ShadePoint> points = shade_points(i);
    Group* group = c.group;
    ob.report = compare_points_with_reference(points, *ob.values, *c.ref, c.points, ob.integrator.seed, check_monitor,
                                              c.ref2);
    checked_before += ob.report->vertices.size();
    out.report_seconds += ob.report->reference_seconds;
    // In a group of receivers, each holds a few of the report's vertices: its own RMSE says
    // little (it is in the file); the pooled lines below say what was met.
    if (!group || group->objects.size() == 1) {
      std::string line = scene.objects[i].name + ": error on " + std::to_string(ob.report->vertices.size()) +
                         " seeded vertices:";
      for (const auto& e : ob.report->products)
        line += " " + std::string(product_label(e.product)) + printf_string(" RMSE %.3e (max %.3e; ", e.rmse, e.max_abs) +
                printf_string("reference's own std. error %.1e)", e.reference_std_error);
      log(line + printf_string("; reference took %.2f s", ob.report->reference_seconds));
    }
    if (!group) continue;
    pool_product_errors(group->pooled, ob.report->products);
    if (++group->checked < group->objects.size()) continue;
    // The group's verdict on its pooled report (bake/bake/choose.h target_check_lines).
    ErrorReport pooled;
    pooled.products = group->pooled;
    pooled.reference_noise_measured = group->ref2 != nullptr;
    size_t n = 0;
    double seconds = 0;
    for (size_t j : group->objects)
      if (out.objects[j].report) n += out.objects[j].report->vertices.size(), seconds += out.objects[j].report->reference_seconds;
    pooled.vertices.resize(n);
    if (group->objects.size() > 1)
      log("receivers from " + scene.objects[group->objects.front()].name + " (" + std::to_string(group->objects.size()) +
          " objects), their " + std::to_string(n) + " report vertices together" +
          printf_string(" (the reference took %.2f s):", seconds));
    for (const std::string& l : target_check_lines(pooled, scene.target_error, group->reference_plan ? &*group->reference_plan : nullptr))
      log(l);
    group->ref.reset();
    group->ref2.reset();
  }

  for (size_t i = 0; i < scene.objects.size(); ++i) {
    ObjectBake& ob = out.objects[i];
    if (!ob.shells || scene.integrator.report_points == 0) continue;
    const Mesh& m = meshes[i];
    const Topology t = build_topology(m);
    ob.fiv_report = fiv_error_report(m, t, *env, *ob.shells, out.environment_fiv, scene.integrator.report_points,
                                     scene.integrator.seed, monitor);
    log(scene.objects[i].name + ": fiv " + printf_string("RMSE %.3e, relative to RMS|F_env| %.3e", ob.fiv_report->rmse,
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
