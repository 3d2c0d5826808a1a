// Tests of the target-error chooser (bake/choose.h): the chosen bake meets the target on points
// the pilot never saw, a tighter target asks for more samples, the knobs are a function of the
// inputs and the seed, a named integrator keeps its kind, and the scene file's "target_error".
#include <bake/choose.h>
#include <bake/error.h>
#include <bake/mesh.h>
#include <bake/scene.h>
#include <bake/silhouette.h>
#include <bake/vertex_bake.h>

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace {

using namespace prt::bake;
namespace fs = std::filesystem;

struct Asset {
  Mesh mesh;
  Topology topology;
  std::vector<ShadePoint> points;
};

Asset load_asset(const char* name) {
  Asset x{load_mesh(fs::path(PRT_DATA_DIR) / name, {.use_file_normals = false}), {}, {}};
  x.topology = build_topology(x.mesh);
  x.points = vertex_shade_points(x.mesh, x.topology);
  return x;
}

const Asset& bunny_ground() {
  static const Asset a = load_asset("bunny_ground.obj");
  return a;
}

// RMSE per product of `integrator` against the 512-isoline silhouette on the points `rows`.
std::vector<double> errors_on(const Asset& a, const ProductRequest& r, const Integrator& integrator,
                              const std::vector<uint32_t>& rows) {
  const SilhouetteIntegrator reference(a.mesh, a.topology, r, SilhouetteOptions{512, 1});
  const ProductLayout L(r);
  std::vector<double> got(L.width), ref(L.width), e2(4, 0.0);
  std::vector<size_t> counts;
  const std::pair<size_t, size_t> slices[] = {{L.ao, L.ao_count}, {L.transfer, L.transfer_count}};
  for (uint32_t v : rows) {
    integrator.integrate(a.points[v], v, got);
    reference.integrate(a.points[v], v, ref);
    for (size_t s = 0; s < 2; ++s)
      for (size_t c = 0; c < slices[s].second; ++c) {
        const double d = got[slices[s].first + c] - ref[slices[s].first + c];
        e2[s] += d * d;
      }
  }
  std::vector<double> out;
  for (size_t s = 0; s < 2; ++s)
    if (slices[s].second) out.push_back(std::sqrt(e2[s] / double(rows.size() * slices[s].second)));
  return out;
}

TEST(Choose, TheChosenBakeMeetsTheTargetOnPointsThePilotNeverSaw) {
  // The target is the tolerance: the chooser promises RMSE <= E per product. Checked on 96 seeded
  // vertices drawn apart from the pilot's (another seed; an overlap of a few is harmless) against
  // a 512-isoline reference (finer than the pilot's 256), whose own error (~3e-5 AO on this asset,
  // bench/RESULTS.md) is a thirtieth of E.
  const Asset& a = bunny_ground();
  ProductRequest r;
  r.ao = true;
  r.transfer_order = 3;
  ChooserOptions opt;
  opt.target = 1e-3;
  const IntegratorChoice c = choose_integrator(a.points, a.mesh, a.topology, r, IntegratorSpec{}, opt);
  EXPECT_EQ(c.pilot_points, 4240u / ChooserOptions::kPilotFraction);  // 66: a 64th of the vertices
  ASSERT_EQ(c.products.size(), 2u);
  // On this asset the silhouette integrator wins by more than 10x (bench/RESULTS.md error against time).
  EXPECT_EQ(c.spec.kind, IntegratorKind::Silhouette);
  // QMC is either priced out by the pilot's first levels or predicted more than twice the cost.
  ASSERT_EQ(c.predictions.size(), 2u);
  EXPECT_TRUE(c.predictions[1].pruned || c.margin > 2.0) << c.reason;
  const auto integrator = make_integrator(c.spec, a.mesh, a.topology, r);
  const std::vector<uint32_t> rows = seeded_sample(uint32_t(a.points.size()), 96, 4242);
  const std::vector<double> e = errors_on(a, r, *integrator, rows);
  for (double x : e) EXPECT_LE(x, opt.target);
  // And the model is not wildly pessimistic: half the samples' isolines would miss the target.
  IntegratorSpec coarse = c.spec;
  coarse.silhouette_k = uint32_t(c.spec.isolines() / 2) * uint32_t(c.spec.isolines() / 2);
  const auto coarse_integrator = make_integrator(coarse, a.mesh, a.topology, r);
  EXPECT_GT(errors_on(a, r, *coarse_integrator, rows)[0], opt.target * opt.safety_silhouette);
}

TEST(Choose, TighterTargetsAskForMoreSamplesAndTheKnobsAreAFunctionOfTheInputs) {
  const Asset& a = bunny_ground();
  ProductRequest r;
  r.ao = true;
  ChooserOptions opt;
  opt.only = IntegratorKind::Qmc;
  opt.target = 3e-3;
  const IntegratorChoice loose = choose_integrator(a.points, a.mesh, a.topology, r, IntegratorSpec{}, opt);
  opt.target = 1e-3;
  const IntegratorChoice tight = choose_integrator(a.points, a.mesh, a.topology, r, IntegratorSpec{}, opt);
  const IntegratorChoice again = choose_integrator(a.points, a.mesh, a.topology, r, IntegratorSpec{}, opt);
  EXPECT_EQ(tight.spec.kind, IntegratorKind::Qmc);
  EXPECT_EQ(tight.predictions.size(), 1u);
  EXPECT_LT(loose.spec.qmc_rays, tight.spec.qmc_rays);
  // Rounded up to an eighth of an octave: a multiple of 2^(⌊log2 R⌋ − 3).
  const uint32_t R = tight.spec.qmc_rays;
  EXPECT_EQ(R % (1u << (int(std::floor(std::log2(double(R)))) - 3)), 0u) << R;
  // Pilot errors and knobs depend only on the inputs and the seed (the times do not enter them).
  EXPECT_EQ(again.spec.qmc_rays, tight.spec.qmc_rays);
  ASSERT_EQ(again.runs.size(), tight.runs.size());
  for (size_t i = 0; i < tight.runs.size(); ++i) EXPECT_EQ(again.runs[i].error, tight.runs[i].error) << i;
  // The predicted error at the chosen knob is within the aim (safety·E), and QMC needs more than
  // 1024 rays here for E = 1e-3 (its pilot RMSE at 1024 rays is ~2.7e-3).
  EXPECT_LE(tight.predictions[0].predicted_error, opt.safety_qmc * opt.target);
  EXPECT_GT(tight.spec.qmc_rays, 1024u);

  opt.only = IntegratorKind::Silhouette;
  const IntegratorChoice s3 = choose_integrator(a.points, a.mesh, a.topology, r, IntegratorSpec{}, opt);
  opt.target = 3e-4;
  const IntegratorChoice s1 = choose_integrator(a.points, a.mesh, a.topology, r, IntegratorSpec{}, opt);
  EXPECT_EQ(s3.spec.kind, IntegratorKind::Silhouette);
  EXPECT_LT(s3.spec.isolines(), s1.spec.isolines());
  EXPECT_EQ(s1.spec.isolines() % 2, 0);
}

TEST(Choose, ThePilotRunsOnlyTheSilhouetteLevelsThatBracketTheGoal) {
  // 32 and 64 always; 16 only when the goal is already met at 32, 128 only when it is missed at
  // 64. On this asset the AO RMSE against the 256-isoline reference is ~2e-3 at N = 32 and ~6e-4
  // at 64 (bench/RESULTS.md, error against time), so: E = 1e-3 (aim 7e-4) needs neither extra
  // level and its knob lies in the bracket (32, 64]; E = 1e-2 (aim 7e-3) is met at 32 and adds
  // 16; E = 2e-4 (aim 1.4e-4) is missed at 64 and adds 128.
  auto silhouette_ao = [](double target) {
    const Asset& a = bunny_ground();
    ProductRequest r;
    r.ao = true;
    return choose_integrator(a.points, a.mesh, a.topology, r, IntegratorSpec{},
                             ChooserOptions{.target = target, .only = IntegratorKind::Silhouette});
  };
  auto levels = [](const IntegratorChoice& c) {
    std::vector<uint32_t> knobs;
    for (size_t i = 1; i < c.runs.size(); ++i) knobs.push_back(c.runs[i].knob);  // runs[0]: the reference
    return knobs;
  };
  const IntegratorChoice mid = silhouette_ao(1e-3);
  EXPECT_EQ(levels(mid), (std::vector<uint32_t>{32, 64}));
  EXPECT_GT(mid.spec.isolines(), 32);
  EXPECT_LE(mid.spec.isolines(), 64);
  const IntegratorChoice loose = silhouette_ao(1e-2);
  EXPECT_EQ(levels(loose), (std::vector<uint32_t>{16, 32, 64}));
  EXPECT_LE(loose.spec.isolines(), 32);
  const IntegratorChoice tight = silhouette_ao(2e-4);
  EXPECT_EQ(levels(tight), (std::vector<uint32_t>{32, 64, 128}));
  EXPECT_GT(tight.spec.isolines(), 64);
  // A run's error does not depend on which other levels ran (it compares the same points with
  // the same 256-isoline reference; E = 2e-4 uses the 512 one): 32 and 64 agree bit for bit.
  EXPECT_EQ(loose.runs[2].error, mid.runs[1].error);
  EXPECT_EQ(loose.runs[3].error, mid.runs[2].error);
}

TEST(Choose, CountedCostsMakeTheWholeChoiceAFunctionOfTheInputs) {
  // With counted costs every number the choice uses is counted work (contour edges, crossings,
  // rays) priced at fixed constants: two runs agree to the bit, costs included, whatever the
  // machine's load or thread count.
  const Asset& a = bunny_ground();
  ProductRequest r;
  r.ao = true;
  ChooserOptions opt;
  opt.counted_costs = true;
  const IntegratorChoice c1 = choose_integrator(a.points, a.mesh, a.topology, r, IntegratorSpec{}, opt);
  const IntegratorChoice c2 = choose_integrator(a.points, a.mesh, a.topology, r, IntegratorSpec{}, opt);
  EXPECT_TRUE(c1.counted_costs);
  EXPECT_EQ(c1.spec.kind, c2.spec.kind);
  EXPECT_EQ(c1.spec.samples(), c2.spec.samples());
  ASSERT_EQ(c1.runs.size(), c2.runs.size());
  for (size_t i = 0; i < c1.runs.size(); ++i) {
    EXPECT_EQ(c1.runs[i].cpu_us_per_point, c2.runs[i].cpu_us_per_point) << i;
    // QMC's counted cost is 3 µs per point plus 0.5 µs per ray (choose.cpp).
    if (c1.runs[i].kind == IntegratorKind::Qmc) {
      EXPECT_EQ(c1.runs[i].cpu_us_per_point, 3.0 + 0.5 * c1.runs[i].knob);
    }
  }
  ASSERT_EQ(c1.predictions.size(), c2.predictions.size());
  for (size_t i = 0; i < c1.predictions.size(); ++i)
    EXPECT_EQ(c1.predictions[i].predicted_us_per_point, c2.predictions[i].predicted_us_per_point) << i;
  EXPECT_EQ(c1.reason, c2.reason);
}

TEST(Choose, ThePilotScalesWithTheBakeAndStopsQmcWhenItsBestCaseCannotWin) {
  // wuson (2117 vertices): the pilot runs on a 64th of them, 33, so that it costs a few percent
  // of the bake. Counted costs make the test a function of the inputs: QMC at 64 rays costs
  // 3 + 0.5·64 = 35 µs counted.
  static const Asset w = load_asset("wuson.obj");
  ProductRequest r;
  r.ao = true;
  ChooserOptions opt;
  opt.counted_costs = true;
  opt.target = 3e-4;
  const IntegratorChoice c = choose_integrator(w.points, w.mesh, w.topology, r, IntegratorSpec{}, opt);
  EXPECT_EQ(c.pilot_points, 2117u / ChooserOptions::kPilotFraction);
  EXPECT_EQ(c.spec.kind, IntegratorKind::Silhouette) << c.reason;
  ASSERT_EQ(c.predictions.size(), 2u);
  const Prediction& sil = c.predictions[0];
  const Prediction& qmc = c.predictions[1];
  // QMC stopped after its first level: 64 rays miss the aim 0.8·E by a factor f (AO RMSE ~2e-2
  // here, f ~ 80), so even at rate 1 it needs 64·f rays, costing ~f times as much: over twice
  // the silhouette prediction.
  std::vector<uint32_t> qmc_levels;
  for (const PilotRun& run : c.runs)
    if (run.kind == IntegratorKind::Qmc) qmc_levels.push_back(run.knob);
  EXPECT_EQ(qmc_levels, std::vector<uint32_t>{64});
  EXPECT_TRUE(qmc.pruned) << c.reason;
  EXPECT_EQ(qmc.knob, 64u);
  const double f = qmc.predicted_error / (opt.safety_qmc * opt.target);
  EXPECT_GE(qmc.predicted_us_per_point * f, 2.0 * sil.predicted_us_per_point);
  // The silhouette integrator needs N ~ 150 here (~176 µs counted), more than QMC's 64 rays
  // cost: the rule "a level that misses and costs more than the rival" alone would have run 256
  // and 1024 rays too. The best case stopped it.
  EXPECT_LT(qmc.predicted_us_per_point, sil.predicted_us_per_point);
  EXPECT_NE(c.reason.find("qmc at 64 rays"), std::string::npos) << c.reason;
}

TEST(Choose, TheOneLineSummarySaysWhatWasChosenAndWhy) {
  const Asset& a = bunny_ground();
  ProductRequest r;
  r.ao = true;
  const IntegratorChoice c = choose_integrator(a.points, a.mesh, a.topology, r, IntegratorSpec{},
                                               ChooserOptions{.target = 2e-3, .only = IntegratorKind::Silhouette});
  const std::string line = choice_summary(c);
  EXPECT_EQ(line.find('\n'), std::string::npos) << line;
  for (const std::string& s : {std::string("target error 0.002: chosen silhouette at N = ") + std::to_string(c.spec.isolines()),
                              std::string("predicted error "), std::string(" µs per integral"),
                              "(pilot on " + std::to_string(c.pilot_points) + " seeded points, "})
    EXPECT_NE(line.find(s), std::string::npos) << "missing '" << s << "' in " << line;
}

TEST(Choose, TheTargetCheckSaysMetNotMetOrNotVerifiable) {
  // E = 1e-3: band-1 is judged relative to the reference's RMS, noise in the same units; a value
  // above E is "not verifiable here" when the reference's own noise is at least E/2.
  ErrorReport report;
  ProductError ao;
  ao.product = Product::Ao, ao.rmse = 9e-4, ao.reference_std_error = 5e-3;  // met, whatever the noise
  ProductError t;
  t.product = Product::TransferDiffuse, t.rmse = 2e-3, t.reference_std_error = 4e-4;  // noise < E/2
  ProductError r;
  r.product = Product::RadianceBand1, r.rmse = 3.0, r.reference_rms = 1000, r.reference_std_error = 0.5;  // 3e-3, noise 5e-4
  report.products = {ao, t, r};
  const std::vector<std::string> lines = target_check_lines(report, 1e-3);
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_NE(lines[0].find("for AO: met (9.000e-04"), std::string::npos) << lines[0];
  EXPECT_NE(lines[1].find("for diffuse transfer: NOT met (2.000e-03"), std::string::npos) << lines[1];
  EXPECT_NE(lines[2].find("for band-1 radiance: not verifiable here (3.000e-03 relative"), std::string::npos) << lines[2];
  EXPECT_NE(lines[2].find("is 5.0e-04: too noisy to tell"), std::string::npos) << lines[2];
}

TEST(Choose, TargetsOutsideTheRangeAreInputErrors) {
  const Asset& a = bunny_ground();
  ProductRequest r;
  r.ao = true;
  for (double t : {0.0, 1e-5, 0.5, std::nan("")}) {
    ChooserOptions opt;
    opt.target = t;
    EXPECT_THROW(choose_integrator(a.points, a.mesh, a.topology, r, IntegratorSpec{}, opt), InputError) << t;
  }
}

TEST(Choose, SceneFilesTakeATargetInsteadOfSamples) {
  const fs::path dir = fs::path(PRT_TEST_TMP) / "choose_scene";
  fs::create_directories(dir);
  auto write = [&](const std::string& name, const std::string& bake) {
    const fs::path p = dir / name;
    std::ofstream(p) << R"({"prtbake_scene": 1, "bake": )" << bake
                     << R"(, "objects": [{"role": "receiver", "mesh": ")" << (fs::path(PRT_DATA_DIR) / "bunny.obj").string()
                     << R"("}]})";
    return p;
  };
  const SceneDescription s = load_scene(write("ok.json", R"({"target_error": 0.002})"), std::nullopt);
  EXPECT_EQ(s.target_error, 0.002);
  EXPECT_FALSE(s.integrator_given);
  EXPECT_EQ(s.integrator.report_points, ChooserOptions::kReportPoints);
  const SceneDescription q =
      load_scene(write("qmc.json", R"({"target_error": 0.002, "integrator": "qmc", "report": 8})"), std::nullopt);
  EXPECT_TRUE(q.integrator_given);
  EXPECT_EQ(q.integrator.kind, IntegratorKind::Qmc);
  EXPECT_EQ(q.integrator.report_points, 8u);
  // Neither samples nor a target: the default target, the default report.
  const SceneDescription d = load_scene(write("default.json", R"({"integrator": "qmc"})"), std::nullopt);
  EXPECT_EQ(d.target_error, ChooserOptions{}.target);
  EXPECT_EQ(d.integrator.report_points, IntegratorSpec{}.report_points);
  const SceneDescription k = load_scene(write("samples.json", R"({"samples": 4096})"), std::nullopt);
  EXPECT_EQ(k.target_error, 0.0);
  EXPECT_EQ(k.integrator.silhouette_k, 4096u);
  for (const char* bad : {R"({"target_error": 0.002, "samples": 1024})", R"({"target_error": 1e-6})",
                          R"({"target_error": "small"})"}) {
    try {
      load_scene(write("bad.json", bad), std::nullopt);
      ADD_FAILURE() << bad << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("target_error"), std::string::npos) << e.what();
    }
  }
}

} // namespace
