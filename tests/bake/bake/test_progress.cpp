// Progress and cancellation of libbake's long computations (bake/core/progress.h): what a Monitor's
// callback sees from bake_vertices (monotone counts, one final update, never two calls at once),
// how a CancelToken stops bake_vertices and bake_fiv_shells, that watching a bake does not
// change its numbers, and that libbake prints nothing (the link-level half of that check is
// tests/check_silent.cmake).
#include <bake/bake/error_report.h>
#include <bake/bake/fiv.h>
#include <bake/bake/vertex_bake.h>
#include <bake/core/error.h>
#include <bake/core/progress.h>
#include <bake/environment/envmap.h>
#include <bake/integrators/qmc.h>
#include <bake/mesh/mesh.h>
#include <bake/mesh/subdivide.h>

#include <gtest/gtest.h>
#include <progress_recorder.h>
#include <test_scenes.h>

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

using namespace prt::bake;
using prt::testing::Recorder;

namespace {

// A 41 × 41 grid (1681 vertices) under a unit box: occluded, so the values are not all equal.
struct Scene {
  Mesh mesh;
  Topology topo;
  ProductRequest req;
  Scene() {
    const Mesh parts[] = {prt::testing::grid(20, 2.0f), prt::testing::box({-0.5f, -0.5f, 0.1f}, {0.5f, 0.5f, 1.1f})};
    mesh = merge_meshes(parts, "grid+box");
    topo = build_topology(mesh);
    req.ao = true;
    req.transfer_order = 2;
  }
};

// Delegates to another integrator, sleeping `delay` per point (so a bake lasts long enough to
// report between its first and last update without using CPU) and recording the threads.
class Probe final : public Integrator {
public:
  Probe(const Integrator& inner, std::chrono::microseconds delay) : inner_(inner), delay_(delay) {}
  IntegratorKind kind() const override { return inner_.kind(); }
  std::string description() const override { return "probe of " + inner_.description(); }
  const ProductLayout& layout() const override { return inner_.layout(); }
  void integrate(const ShadePoint& p, uint64_t i, std::span<double> out, std::span<double> se) const override {
    std::this_thread::sleep_for(delay_);
    {
      std::lock_guard lock(mutex_);
      threads_.insert(std::this_thread::get_id());
    }
    inner_.integrate(p, i, out, se);
  }
  size_t threads() const {
    std::lock_guard lock(mutex_);
    return threads_.size();
  }

private:
  const Integrator& inner_;
  std::chrono::microseconds delay_;
  mutable std::mutex mutex_;
  mutable std::set<std::thread::id> threads_;
};

// Four worker slots even on a two-core machine, so the bake's advances really race.
template <class F>
void with_four_threads(F&& f) {
  tbb::global_control parallelism(tbb::global_control::max_allowed_parallelism, 4);
  tbb::task_arena arena(4);
  arena.execute(f);
}

bool bitwise_equal(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

} // namespace

TEST(Progress, BakeVerticesReportsMonotoneCountsAndOneFinalUpdate) {
  const Scene s;
  const QmcIntegrator qmc(s.mesh, s.topo, s.req, {64, 3});
  // 1689 points × 1 ms over 4 threads ≈ 0.4 s: several 50 ms reports between the first and last.
  const Probe probe(qmc, std::chrono::microseconds(1000));
  Recorder rec;
  // Longer than the 50 ms between reports: another thread is due to report while one is inside.
  rec.dwell = std::chrono::milliseconds(60);
  VertexBake b;
  with_four_threads([&] { b = bake_vertices(s.mesh, s.topo, probe, rec.monitor(), "stage under test"); });
  const uint64_t V = s.mesh.positions.size();
  EXPECT_GE(probe.threads(), 2u) << "the bake must run on several threads for this test to mean anything";
  ASSERT_GE(rec.updates.size(), 3u) << "expected a first, at least one intermediate and a final update";
  prt::testing::expect_complete_stage(rec, "stage under test", V);
  EXPECT_EQ(b.values.size(), V * qmc.layout().width);
}

TEST(Progress, TheBakeCountsOnlyTheIntegratorsCpuTime) {
  // busy_fraction = CPU time inside the integrator / (wall · threads). A probe that sleeps 1 ms per
  // point does ~30 µs of work in it (64 rays): the sleep is no CPU time, so the fraction stays far
  // below 1/2; and no thread can spend more CPU than the wall time, so it never exceeds 1.
  const Scene s;
  const QmcIntegrator qmc(s.mesh, s.topo, s.req, {64, 3});
  const Probe probe(qmc, std::chrono::microseconds(1000));
  VertexBake b;
  with_four_threads([&] { b = bake_vertices(s.mesh, s.topo, probe); });
  EXPECT_EQ(b.threads, 4);
  EXPECT_GT(b.cpu_seconds, 0.0);
  EXPECT_LT(b.busy_fraction(), 0.5);
  const VertexBake busy = bake_vertices(s.mesh, s.topo, qmc);
  EXPECT_GT(busy.cpu_seconds, 0.0);
  EXPECT_LE(busy.busy_fraction(), 1.0);
}

TEST(Progress, WatchingABakeDoesNotChangeItsValues) {
  const Scene s;
  const QmcIntegrator qmc(s.mesh, s.topo, s.req, {128, 9});
  const VertexBake silent = bake_vertices(s.mesh, s.topo, qmc);
  Recorder rec;
  const CancelToken never;
  VertexBake watched;
  with_four_threads([&] { watched = bake_vertices(s.mesh, s.topo, qmc, rec.monitor(&never)); });
  ASSERT_FALSE(rec.updates.empty());
  EXPECT_TRUE(bitwise_equal(silent.values, watched.values));
  EXPECT_TRUE(bitwise_equal(silent.std_error, watched.std_error));
  // And the values are not trivially equal: the box shadows part of the grid (AO in [0, 1], not all 1).
  double min_ao = 1;
  for (size_t v = 0; v < s.mesh.positions.size(); ++v) min_ao = std::min(min_ao, silent.values[v * qmc.layout().width]);
  EXPECT_LT(min_ao, 0.9);
}

TEST(Progress, TokenRequestedBeforeTheCallCancelsAtOnce) {
  const Scene s;
  const QmcIntegrator qmc(s.mesh, s.topo, s.req, {64, 3});
  const Probe probe(qmc, std::chrono::microseconds(0));
  CancelToken token;
  token.request();
  Recorder rec;
  EXPECT_THROW(bake_vertices(s.mesh, s.topo, probe, rec.monitor(&token)), Cancelled);
  EXPECT_TRUE(rec.updates.empty()) << "a bake cancelled before it started reports nothing";
  EXPECT_EQ(probe.threads(), 0u) << "no point was integrated";

  Monitor silent;  // no callback, only the token
  silent.cancel = &token;
  const EnvMap env = EnvMap::constant({1, 1, 1});
  ShellSpec spec;
  spec.n_phi = 8;
  spec.n_theta = 5;
  spec.n_rho = 4;
  EXPECT_THROW(bake_fiv_shells(s.mesh, s.topo, env, spec, silent), Cancelled);
}

// The error report's reference integration is a stage like the bake: it reports, and a token
// cancels it (prtbake used to write its file after a Ctrl-C during the report).
TEST(Progress, TheReferenceStageReportsAndCancels) {
  const Scene s;
  const QmcIntegrator qmc(s.mesh, s.topo, s.req, {64, 3});
  const VertexBake b = bake_vertices(s.mesh, s.topo, qmc);
  Recorder rec;
  const ErrorReport r = compare_with_reference(s.mesh, s.topo, b, qmc, 40, 7, rec.monitor());
  prt::testing::expect_complete_stage(rec, "reference", 40);
  EXPECT_EQ(r.vertices.size(), 40u);

  CancelToken token;
  token.request();
  Monitor cancelled;
  cancelled.cancel = &token;
  EXPECT_THROW(compare_with_reference(s.mesh, s.topo, b, qmc, 40, 7, cancelled), Cancelled);
  const EnvMap env = EnvMap::constant({1, 1, 1});
  ShellSpec spec;
  spec.n_phi = 8;
  spec.n_theta = 5;
  spec.n_rho = 2;
  const FivShells shells = bake_fiv_shells(s.mesh, s.topo, env, spec);
  EXPECT_THROW(fiv_error_report(s.mesh, s.topo, env, shells, environment_fiv(env), 8, 7, cancelled), Cancelled);
}

TEST(Progress, TokenRequestedFromTheCallbackStopsARunningBake) {
  const Scene s;
  const QmcIntegrator qmc(s.mesh, s.topo, s.req, {64, 3});
  const Probe probe(qmc, std::chrono::microseconds(1000));
  CancelToken token;
  Recorder rec;
  // Cancel at the first update that reports work done (not the opening 0 of the stage).
  rec.then = [&](const ProgressUpdate& u) {
    if (u.done > 0 && !u.finished) token.request();
  };
  const uint64_t V = s.mesh.positions.size();
  with_four_threads([&] {
    EXPECT_THROW(
        {
          const VertexBake b = bake_vertices(s.mesh, s.topo, probe, rec.monitor(&token));
          ADD_FAILURE() << "returned " << b.values.size() << " values";
        },
        Cancelled);
  });
  ASSERT_TRUE(token.requested()) << "the bake ended before an intermediate update";
  ASSERT_GE(rec.updates.size(), 2u);
  EXPECT_EQ(rec.overlaps.load(), 0);
  // The stage still closes with one finished update, short of the total: the bake stopped early
  // (only the blocks of 16 points already in flight complete after the request).
  const ProgressUpdate& last = rec.updates.back();
  EXPECT_TRUE(last.finished);
  EXPECT_LT(last.done, V);
  for (size_t i = 0; i + 1 < rec.updates.size(); ++i) EXPECT_FALSE(rec.updates[i].finished);
}

TEST(Progress, TokenRequestedFromTheCallbackStopsFivShells) {
  const Scene s;
  const EnvMap env = EnvMap::constant({1, 1, 1});
  ShellSpec spec;
  spec.n_phi = 16;
  spec.n_theta = 9;
  spec.n_rho = 8;
  spec.silhouette_k = 16;
  CancelToken token;
  Recorder rec;
  rec.then = [&](const ProgressUpdate&) { token.request(); };  // at the stage's opening update
  EXPECT_THROW(bake_fiv_shells(s.mesh, s.topo, env, spec, rec.monitor(&token)), Cancelled);
  ASSERT_GE(rec.updates.size(), 2u);
  EXPECT_EQ(rec.tasks.front(), "baking FIV shells");
  EXPECT_TRUE(rec.updates.back().finished);
  EXPECT_LT(rec.updates.back().done, rec.updates.back().total);
}

TEST(SilentLibrary, NothingReachesTheTerminalEvenWhenOpenMeshRefusesAFace) {
  // OpenMesh's add_face refuses the last face ("complex vertex") and would say so on omerr;
  // libbake switches OpenMesh's streams off (libbake/mesh/src/openmesh.h) and throws its own
  // InputError. A bake without a monitor reports nothing either.
  const std::vector<Eigen::Vector3f> d = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}, {0, 0, 1}, {1, 0, 1}};
  const Mesh fin = make_mesh(d, {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 1}, {0, 5, 6}}, "disk+fin");
  const Scene s;
  const QmcIntegrator qmc(s.mesh, s.topo, s.req, {16, 3});
  ::testing::internal::CaptureStdout();
  ::testing::internal::CaptureStderr();
  EXPECT_THROW(loop_subdivide(fin, 1), InputError);
  bake_vertices(s.mesh, s.topo, qmc);
  const std::string err = ::testing::internal::GetCapturedStderr(), out = ::testing::internal::GetCapturedStdout();
  EXPECT_EQ(out, "");
  EXPECT_EQ(err, "");
}
