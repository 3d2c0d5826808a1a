// The bake pipeline (bake/bake/pipeline.h): a job's rows are the row loop's, whatever its receiver
// sets hold (a mesh's vertices, or free points as a lightmap's texels will be); the steps and the
// hooks come in the documented order; the report's points are shared by the sets' rows with a
// target and given to each set without one; a caller's rows replace the row loop (sharded bakes).
#include <bake/bake/choose.h>
#include <bake/bake/pipeline.h>
#include <bake/environment/envmap.h>
#include <bake/integrators/registry.h>
#include <bake/mesh/mesh.h>
#include <bake/mesh/receivers.h>
#include <bake/visibility/accel.h>

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace prt::bake;

namespace {

struct Ground {
  Mesh mesh = load_mesh(fs::path(PRT_DATA_DIR) / "bunny_ground.obj");
  Topology topology = build_topology(mesh);
  MeshAccel accel{mesh, topology};
};

// A 6 × 6 floor (y = 0, up) and a unit box standing on it at the origin.
Mesh floor_and_box() {
  std::vector<Eigen::Vector3f> c = {{-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, {-3, 0, -3}};
  for (int k = 0; k < 8; ++k) c.emplace_back(k & 1 ? 0.5f : -0.5f, k & 4 ? 1.0f : 0.0f, k & 2 ? -0.5f : 0.5f);
  return make_mesh(c,
                   {{{0, 1, 2}}, {{0, 2, 3}}, {{4, 6, 5}}, {{5, 6, 7}}, {{8, 9, 10}}, {{9, 11, 10}}, {{4, 5, 8}},
                    {{5, 9, 8}}, {{6, 10, 7}}, {{7, 10, 11}}, {{4, 8, 6}}, {{6, 8, 10}}, {{5, 7, 9}}, {{7, 11, 9}}},
                   "floor and box");
}

// The floor and box under data/studio.exr, and one band-1 job over an empty set "floor points".
struct FloorAndBoxUnderStudio {
  Mesh mesh = floor_and_box();
  Topology topo = build_topology(mesh);
  MeshAccel accel{mesh, topo};
  EnvMap env = EnvMap::load(fs::path(PRT_DATA_DIR) / "studio.exr", UpAxis::Y);
  std::vector<BakeJob> one_job() const {
    std::vector<BakeJob> jobs(1);
    jobs[0].request.radiance = &env;
    jobs[0].sets.resize(1);
    jobs[0].sets[0].name = "floor points";
    return jobs;
  }
};

ProductRequest ao() {
  ProductRequest r;
  r.ao = true;
  return r;
}

// QMC at `rays` per point with `report` report points.
PipelineSettings qmc(uint32_t rays, uint32_t report) {
  PipelineSettings settings;
  settings.integrator.kind = IntegratorKind::Qmc;
  settings.integrator.qmc_rays = rays;
  settings.integrator.report_points = report;
  return settings;
}

// Two sets: the first 600 vertices, and 300 free points a little above later vertices along their
// normals (points that are no vertex of the occluders, as a lightmap's texels are not).
std::vector<ReceiverSet> two_sets(const Ground& g);

// One AO job over two_sets(g).
std::vector<BakeJob> one_job(const Ground& g) {
  std::vector<BakeJob> jobs(1);
  jobs[0].name = "two sets";
  jobs[0].request = ao();
  jobs[0].sets = two_sets(g);
  return jobs;
}

std::vector<ReceiverSet> two_sets(const Ground& g) {
  const std::vector<ShadePoint> all = vertex_shade_points(g.mesh, g.topology);
  std::vector<ReceiverSet> sets(2);
  sets[0].name = "vertices";
  sets[0].points.assign(all.begin(), all.begin() + 600);
  sets[1].name = "free points";
  sets[1].tag = 7;
  for (size_t v = 1000; v < 1300; ++v) {
    ShadePoint p;
    p.n = all[v].n;
    p.p = all[v].p + 0.01 * all[v].n;
    sets[1].points.push_back(p);
  }
  return sets;
}

void expect_same_rows(const VertexBake& a, const VertexBake& b, const std::string& what) {
  ASSERT_EQ(a.values.size(), b.values.size()) << what;
  for (size_t k = 0; k < a.values.size(); ++k) ASSERT_EQ(a.values[k], b.values[k]) << what << " value " << k;
  for (size_t k = 0; k < a.std_error.size(); ++k) ASSERT_EQ(a.std_error[k], b.std_error[k]) << what << " std error " << k;
}

} // namespace

TEST(Pipeline, RowsAreTheRowLoopsForAnyReceiversAndHooksComeInOrder) {
  const Ground g;
  const PipelineSettings settings = qmc(64, 8);
  std::vector<BakeJob> jobs = one_job(g);
  const std::vector<ReceiverSet> sets = jobs[0].sets;
  BakePipeline pipeline(g.mesh, g.topology, g.accel, settings, std::move(jobs));

  std::vector<std::string> calls;
  PipelineHooks hooks;
  hooks.chosen = [&](const BakeJob&) { calls.push_back("chosen"); };
  hooks.ready = [&](const BakeJob&) { calls.push_back("ready"); };
  hooks.set_baked = [&](const BakeJob&, size_t s) { calls.push_back("set_baked " + std::to_string(s)); };
  hooks.baked = [&] { calls.push_back("baked"); };
  hooks.checking = [&] { calls.push_back("checking"); };
  hooks.check_planned = [&](const BakeJob&) { calls.push_back("check_planned"); };
  hooks.set_checked = [&](const BakeJob&, size_t s) { calls.push_back("set_checked " + std::to_string(s)); };
  hooks.job_checked = [&](const BakeJob&) { calls.push_back("job_checked"); };
  hooks.correcting = [&](const BakeJob&, const IntegratorSpec&) { calls.push_back("correcting"); };
  pipeline.run({}, hooks);
  // Without a target: no choice, no reference plan, no correction.
  EXPECT_EQ(calls, (std::vector<std::string>{"ready", "set_baked 0", "set_baked 1", "baked", "checking", "set_checked 0",
                                             "set_checked 1", "job_checked"}));

  const BakeJob& job = pipeline.jobs().front();
  const std::unique_ptr<Integrator> alone = make_integrator(settings.integrator, g.mesh, g.topology, ao());
  for (size_t s = 0; s < 2; ++s) {
    // Row i of a set is randomised by i: the same numbers as the row loop on that set alone.
    expect_same_rows(job.rows[s], bake_points(sets[s].points, *alone), sets[s].name);
    for (double x : job.rows[s].values) EXPECT_TRUE(std::isfinite(x) && x >= 0 && x <= 1) << x;
    // Without a target each set gets the report's points.
    ASSERT_TRUE(job.reports[s].has_value());
    EXPECT_EQ(job.reports[s]->vertices.size(), 8u);
  }
  // The pooled report is both sets' values: 16 AO values.
  ASSERT_TRUE(job.pooled.has_value());
  ASSERT_EQ(job.pooled->products.size(), 1u);
  EXPECT_EQ(job.pooled->products[0].values, 16u);
  EXPECT_EQ(job.integrator_description, alone->description());
}

TEST(Pipeline, ATargetSharesTheReportsPointsByRowsAndPoolsTheVerdict) {
  const Ground g;
  PipelineSettings settings;
  settings.target_error = 0.01;     // loose: the pilot is short
  settings.counted_costs = true;    // the same choice on any machine
  settings.integrator.report_points = 40;
  settings.correct = false;
  BakePipeline pipeline(g.mesh, g.topology, g.accel, settings, one_job(g));
  int chosen = 0, planned = 0;
  PipelineHooks hooks;
  hooks.chosen = [&](const BakeJob& j) {
    ++chosen;
    EXPECT_TRUE(j.choice.has_value());
  };
  hooks.check_planned = [&](const BakeJob& j) {
    ++planned;
    ASSERT_TRUE(j.reference_plan.has_value());
    EXPECT_EQ(j.spec.report_rays, j.reference_plan->rays);
  };
  pipeline.run({}, hooks);
  EXPECT_EQ(chosen, 1) << "one pilot for the job, on both sets' points";
  EXPECT_EQ(planned, 1);
  const BakeJob& job = pipeline.jobs().front();
  // 600 and 300 rows of 900 share 40 points: ceil(40·600/900) = 27 and ceil(40·300/900) = 14.
  EXPECT_EQ(pipeline.report_points(job, 0), 27u);
  EXPECT_EQ(pipeline.report_points(job, 1), 14u);
  ASSERT_TRUE(job.reports[0] && job.reports[1]);
  EXPECT_EQ(job.reports[0]->vertices.size(), 27u);
  EXPECT_EQ(job.reports[1]->vertices.size(), 14u);
  EXPECT_TRUE(job.reports[0]->reference_noise_measured) << "with a target: two independent halves";
  ASSERT_TRUE(job.pooled.has_value());
  EXPECT_EQ(job.pooled->vertices.size(), 41u);
  EXPECT_EQ(job.pooled->products[0].values, 41u);
  // The pooled RMSE is the RMS of the sets' over their values.
  const double a = job.reports[0]->products[0].rmse, b = job.reports[1]->products[0].rmse;
  EXPECT_NEAR(job.pooled->products[0].rmse, std::sqrt((27 * a * a + 14 * b * b) / 41), 1e-15);
}

TEST(Pipeline, ACallersRowsReplaceTheRowLoop) {
  const Ground g;
  BakePipeline pipeline(g.mesh, g.topology, g.accel, qmc(32, 0), one_job(g));
  // A worker's run: its rows go elsewhere (here: kept by the test), nothing else happens.
  std::vector<VertexBake> kept(2);
  bool baked = false;
  PipelineHooks work;
  work.rows_only = true;
  work.baked = [&] { baked = true; };
  work.rows = [&](const BakeJob& j, size_t s, const Monitor& m) {
    kept[s] = bake_points(j.sets[s].points, *j.integrator, m);
    return VertexBake{};
  };
  pipeline.run({}, work);
  EXPECT_FALSE(baked);
  // The merge's run: the rows come back through the hook, and the pipeline goes on.
  PipelineHooks merge;
  merge.rows = [&](const BakeJob&, size_t s, const Monitor&) { return kept[s]; };
  merge.baked = [&] { baked = true; };
  pipeline.run({}, merge);
  EXPECT_TRUE(baked);
  for (size_t s = 0; s < 2; ++s) expect_same_rows(pipeline.jobs()[0].rows[s], kept[s], "set " + std::to_string(s));
  // A caller's rows of the wrong size are refused, not written.
  PipelineHooks wrong;
  wrong.rows = [&](const BakeJob&, size_t, const Monitor&) { return VertexBake{}; };
  EXPECT_THROW(pipeline.run({}, wrong), std::exception);
}

TEST(Pipeline, RUnderASunIsCheckedAgainstTheSameIntegratorAtFourTimesItsIsolines) {
  // A floor and a unit box under data/studio.exr (1,084 hot texels in 47 clusters), E = 3e-4: QMC
  // cannot bring band-1 within E/3 = 1e-4 relative in its budget (its noise here is ~6e-4), so the
  // verdict on R comes from the silhouette integrator at 4N on the report's points. Its RMSE is
  // checked against that integrator run independently on the same points (to rounding: the same
  // integrals summed in another order), and the verdict's range is m/(1 − 1/16) to m/(1 − 1/4).
  const FloorAndBoxUnderStudio scene;
  const Mesh& mesh = scene.mesh;
  const Topology& topo = scene.topo;
  const MeshAccel& accel = scene.accel;
  std::vector<BakeJob> jobs = scene.one_job();
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < 12; ++j) {
      ShadePoint p;
      p.p = Eigen::Vector3d(-2.75 + 0.5 * i, 0, -2.75 + 0.5 * j);  // on the floor (y = 0 exactly), off the box
      if (std::abs(p.p.x()) < 0.75 && std::abs(p.p.z()) < 0.75) continue;
      p.n = Eigen::Vector3d::UnitY();
      jobs[0].sets[0].points.push_back(p);
    }
  PipelineSettings settings;
  settings.integrator.report_points = 64;
  settings.target_error = 3e-4;  // E/3 = 1e-4: below what QMC's budget reaches under this sky
  settings.counted_costs = true;  // the reference's rays and the checked points fixed
  settings.correct = false;
  BakePipeline pipeline(mesh, topo, accel, settings, std::move(jobs));
  pipeline.run({});
  const BakeJob& job = pipeline.jobs().front();
  ASSERT_TRUE(job.pooled.has_value());
  const ProductError& r = job.pooled->products.front();
  ASSERT_EQ(r.product, Product::RadianceBand1);
  ASSERT_EQ(r.finer, 4.0) << "QMC could tell: the test's sky is not hard enough: " << target_check_lines(*job.pooled, 3e-4).front();
  ASSERT_TRUE(job.spec.kind == IntegratorKind::Silhouette);
  const uint32_t N = uint32_t(job.spec.isolines());
  EXPECT_EQ(r.finer_knob, 4 * N);
  ASSERT_EQ(r.finer_points, job.pooled->vertices.size());
  IntegratorSpec fine = job.spec;
  fine.set_samples(16 * N * N);
  const auto finer = make_integrator(fine, mesh, topo, job.request, &accel);
  double d2 = 0, r2 = 0;
  std::vector<double> row(9);
  for (const uint32_t v : job.pooled->vertices) {
    finer->integrate(job.sets[0].points[v], v, row);
    for (size_t k = 0; k < 9; ++k) {
      const double d = job.rows[0].values[size_t(v) * 9 + k] - row[k];
      d2 += d * d, r2 += row[k] * row[k];
    }
  }
  const double m = std::sqrt(d2 / r2);
  EXPECT_NEAR(r.rmse / r.reference_rms, m, 1e-12 * m);
  ASSERT_GT(m, 0);
  // The verdict's relative error divides by the bake's RMS over every row (ProductError::mesh_rms).
  double all2 = 0;
  for (const double x : job.rows[0].values) all2 += x * x;
  const double mesh_m = std::sqrt(d2 / double(job.pooled->vertices.size() * 9)) /
                        std::sqrt(all2 / double(job.rows[0].values.size()));
  const TargetVerdict v = target_verdicts(*job.pooled, 3e-4).front();
  EXPECT_TRUE(v.extrapolated);
  EXPECT_NEAR(v.error_lo, mesh_m * 16 / 15, 1e-12 * mesh_m);
  EXPECT_NEAR(v.error_hi, mesh_m * 4 / 3, 1e-12 * mesh_m);
}

TEST(Pipeline, ASmallBakeTakesThePilotsReferenceIntegratorAndItsRowsAreAFreshBuildsBytes) {
  // Twenty floor points beside a box under data/studio.exr: baking them at the reference level
  // costs a fraction of a millisecond, building a lower level's tables (524,288 texel masses) tens
  // of milliseconds, so the plan is the reference level the pilot already built (Prediction::built)
  // and the bake takes that integrator. Its rows must be those of the same spec built afresh, bit
  // for bit, and its work summary must count the bake's points, not the pilot's.
  const FloorAndBoxUnderStudio scene;
  const Mesh& mesh = scene.mesh;
  const Topology& topo = scene.topo;
  const MeshAccel& accel = scene.accel;
  std::vector<BakeJob> jobs = scene.one_job();
  jobs[0].request.ao = true;
  for (int i = 0; i < 20; ++i) {
    ShadePoint p;
    p.p = Eigen::Vector3d(-2.9 + 0.29 * i, 0, 0.9);  // on the floor, beside the box
    p.n = Eigen::Vector3d::UnitY();
    jobs[0].sets[0].points.push_back(p);
  }
  PipelineSettings settings;
  settings.integrator.report_points = 0;
  settings.target_error = 1e-3;
  settings.correct = false;
  BakePipeline pipeline(mesh, topo, accel, settings, std::move(jobs));
  pipeline.run({});
  const BakeJob& job = pipeline.jobs().front();
  ASSERT_TRUE(job.choice.has_value());
  const IntegratorChoice& choice = *job.choice;
  ASSERT_TRUE(job.spec.kind == IntegratorKind::Silhouette) << choice.reason;
  ASSERT_EQ(uint32_t(job.spec.isolines()), choice.reference_isolines) << choice.reason;
  bool built = false;
  for (const Prediction& p : choice.predictions) built = built || p.built;
  EXPECT_TRUE(built);
  EXPECT_EQ(choice.integrator, nullptr);  // handed to the bake
  EXPECT_NE(choice.reason.find("reference level"), std::string::npos) << choice.reason;
  EXPECT_EQ(job.integrator->stats().points, 20u);
  const auto fresh = make_integrator(job.spec, mesh, topo, job.request, &accel);
  const size_t W = fresh->layout().width;
  std::vector<double> row(W);
  for (size_t i = 0; i < 20; ++i) {
    fresh->integrate(job.sets[0].points[i], i, row);
    for (size_t k = 0; k < W; ++k) EXPECT_EQ(job.rows[0].values[i * W + k], row[k]) << "point " << i << ", value " << k;
  }
}

TEST(Pipeline, ARelativeErrorDividesByTheProductsRmsOverEveryRow) {
  // Half the points see the sky, half lie under the box's roof (a lid 0.01 above the floor hides
  // them: band-1 is 0 there), so an RMS over a few compared points can miss the mesh's by a factor;
  // the report's relative error must divide by the RMS of the bake's values over every row of
  // each set (each set's own, the pooled report's over all), and the verdict with it.
  std::vector<Eigen::Vector3f> c = {{-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, {-3, 0, -3}};
  for (int k = 0; k < 4; ++k) c.emplace_back(k & 1 ? 2.9f : -2.9f, 0.01f, k & 2 ? -0.1f : 2.9f);  // a lid over z > -0.1
  const Mesh mesh = make_mesh(c, {{{0, 1, 2}}, {{0, 2, 3}}, {{4, 6, 5}}, {{5, 6, 7}}}, "floor under a half lid");
  const Topology topo = build_topology(mesh);
  const MeshAccel accel(mesh, topo);
  const EnvMap env = EnvMap::load(fs::path(PRT_DATA_DIR) / "studio.exr", UpAxis::Y);
  std::vector<BakeJob> jobs(1);
  jobs[0].request.radiance = &env;
  jobs[0].sets.resize(2);
  for (int s = 0; s < 2; ++s) {
    jobs[0].sets[size_t(s)].name = s ? "open" : "mixed";
    for (int i = 0; i < 40; ++i) {
      ShadePoint p;
      p.p = Eigen::Vector3d(-2.5 + 0.12 * i, 0, s ? -1.0 : (i % 2 ? 1.0 : -1.0));  // under the lid where z = 1
      p.n = Eigen::Vector3d::UnitY();
      jobs[0].sets[size_t(s)].points.push_back(p);
    }
  }
  BakePipeline pipeline(mesh, topo, accel, qmc(256, 8), std::move(jobs));
  pipeline.run({});
  const BakeJob& job = pipeline.jobs().front();
  ASSERT_TRUE(job.pooled.has_value());
  double all2 = 0;
  size_t all_n = 0;
  for (size_t s = 0; s < 2; ++s) {
    double sum2 = 0;
    for (const double v : job.rows[s].values) sum2 += v * v;  // the layout is band-1 only: 9 per row
    all2 += sum2, all_n += job.rows[s].values.size();
    ASSERT_TRUE(job.reports[s].has_value());
    const ProductError& e = job.reports[s]->products.front();
    ASSERT_EQ(e.product, Product::RadianceBand1);
    EXPECT_NEAR(e.mesh_rms, std::sqrt(sum2 / double(job.rows[s].values.size())), 1e-12 * e.mesh_rms);
    EXPECT_GT(e.mesh_rms, 0.0);
  }
  const ProductError& pooled = job.pooled->products.front();
  const double mesh_rms = std::sqrt(all2 / double(all_n));
  EXPECT_NEAR(pooled.mesh_rms, mesh_rms, 1e-12 * mesh_rms);
  EXPECT_LT(job.reports[0]->products.front().mesh_rms, 0.9 * job.reports[1]->products.front().mesh_rms);  // the lid's zeros
  const TargetVerdict v = target_verdicts(*job.pooled, 1e-3).front();
  EXPECT_NEAR(v.measured, pooled.rmse / mesh_rms, 1e-12 * v.measured);
  EXPECT_GT(v.measured, 0.0);
}

TEST(Pipeline, CorrectionsRaiseTheKnobFromTheLastCheckedPlanAtMostMaxCorrectionsTimes) {
  // A planted plan far too coarse for E: silhouette N = 8 for AO over two_sets at E = 3e-3 (AO's
  // error is ~9e-3 at N = 8–14 here), with a model rate of 20 so that the first correction raises
  // N by (e/aim)^(1/20), one step of 2, and E stays missed. The second must start from the plan
  // the first check measured (not the pilot's), and the job stops after max_corrections = 2.
  const Ground g;
  PipelineSettings settings;
  settings.target_error = 3e-3;
  settings.counted_costs = true;  // the check's rays from counted work: the same on any machine
  settings.integrator.report_points = 32;
  settings.max_corrections = 2;
  std::vector<BakeJob> jobs = one_job(g);
  IntegratorChoice c;
  c.target = settings.target_error;
  c.spec.kind = IntegratorKind::Silhouette;
  c.spec.set_samples(8 * 8);
  c.spec.report_points = 32;
  Prediction sil;
  sil.kind = IntegratorKind::Silhouette, sil.exponent = 20.0, sil.bound = 4096;
  c.predictions = {sil};
  jobs[0].choice = c;
  BakePipeline pipeline(g.mesh, g.topology, g.accel, settings, std::move(jobs));
  std::vector<uint32_t> from, to;
  std::vector<std::string> said;
  PipelineHooks hooks;
  hooks.correcting = [&](const BakeJob& j, const IntegratorSpec& better) {
    from.push_back(j.spec.isolines());
    to.push_back(better.isolines());
    said.push_back(correction_text(j, better));
  };
  pipeline.run({}, hooks);
  ASSERT_EQ(from.size(), 2u);
  EXPECT_EQ(from[0], 8u);
  EXPECT_EQ(to[0], 10u) << "8 × (9e-3 / 2.1e-3)^(1/20), up to even";
  EXPECT_EQ(from[1], to[0]) << "the second correction starts from the plan the first check measured";
  EXPECT_GT(to[1], from[1]);
  for (size_t i = 0; i < said.size(); ++i)
    EXPECT_NE(said[i].find("correction " + std::to_string(i + 1) + ":"), std::string::npos) << said[i];
  const BakeJob& job = pipeline.jobs().front();
  EXPECT_EQ(job.pass, 2);
  EXPECT_EQ(job.spec.isolines(), to.back()) << "the rows are the last correction's";
  ASSERT_TRUE(job.last_checked.has_value());
  EXPECT_EQ(job.last_checked->spec.isolines(), from.back());
}
