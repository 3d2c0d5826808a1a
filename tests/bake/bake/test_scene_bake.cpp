// bake_scene's progress (bake/bake/scene.h): the receivers' vertices are one stage, "baking
// receivers", whose count runs over every receiver (one ETA for the scene) and finishes once,
// with the last of them.
#include <bake/bake/scene_bake.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace prt::bake;

TEST(SceneBake, TheReceiversAreOneProgressStageOverAllTheirVertices) {
  SceneDescription scene = load_scene(fs::path(PRT_DATA_DIR) / "scene_example.json");
  scene.integrator.report_points = 0;
  scene.want_fiv = false;
  scene.integrator.set_samples(256);  // 16 isolines: the stage, not the values, is under test
  std::vector<std::string> warnings;
  const std::vector<Mesh> meshes = load_scene_meshes(scene, warnings);
  const EnvMap env = EnvMap::load(*scene.environment, scene.up);
  const ScenePlan plan = plan_scene(scene, meshes);
  uint64_t receivers = 0;
  size_t objects = 0;
  for (size_t i = 0; i < meshes.size(); ++i)
    if (plan.objects[i].receiver && plan.objects[i].any_vertex_product()) receivers += meshes[i].positions.size(), ++objects;
  ASSERT_GE(objects, 2u) << "the stage must span several objects";
  std::vector<ProgressUpdate> seen;
  std::vector<std::string> tasks;
  Monitor monitor;
  monitor.on_progress = [&](const ProgressUpdate& u) {
    if (std::string(u.task).starts_with("baking")) seen.push_back(u), tasks.emplace_back(u.task);
  };
  const SceneBake out = bake_scene(scene, plan, meshes, &env, monitor, [](const std::string&) {});
  EXPECT_EQ(out.vertices, receivers);
  ASSERT_FALSE(seen.empty());
  size_t finished = 0;
  uint64_t last = 0;
  for (size_t k = 0; k < seen.size(); ++k) {
    EXPECT_EQ(tasks[k], "baking receivers");
    EXPECT_EQ(seen[k].total, receivers);
    EXPECT_GE(seen[k].done, last) << "the count never restarts";
    last = seen[k].done;
    finished += seen[k].finished;
  }
  EXPECT_EQ(finished, 1u);
  EXPECT_TRUE(seen.back().finished);
  EXPECT_EQ(seen.back().done, receivers);
}

TEST(SceneBake, EveryOccludersShellsAreOneProgressStage) {
  // Issue 29: each moving occluder's shells were a stage of their own, so a log restarted at 0%
  // per part with no ETA for the scene. They are one stage, "baking FIV shells and self-shadows",
  // over every occluder's share (n_rho shells each; a share that stops early is counted whole once
  // done) and its vertices, which never goes backwards and finishes once, at its total.
  SceneDescription scene = load_scene(fs::path(PRT_DATA_DIR) / "scene_example.json");
  scene.integrator.report_points = 0;
  scene.integrator.set_samples(256);
  scene.fiv.n_phi = 8, scene.fiv.n_theta = 5, scene.fiv.n_rho = 6;  // the stage, not the values, is under test
  scene.fiv.silhouette_k = 256;
  std::vector<std::string> warnings;
  const std::vector<Mesh> meshes = load_scene_meshes(scene, warnings);
  const EnvMap env = EnvMap::load(*scene.environment, scene.up);
  const ScenePlan plan = plan_scene(scene, meshes);
  size_t movers = 0, vertices = 0;
  for (size_t i = 0; i < plan.objects.size(); ++i)
    if (plan.objects[i].fiv) ++movers, vertices += meshes[i].positions.size();
  ASSERT_GE(movers, 2u) << "the stage must span several occluders";
  // The shells' samples, then (by default) each occluder's self-shadows at its vertices.
  ASSERT_TRUE(scene.fiv.vertex_self_shadows);
  const uint64_t total = uint64_t(movers) * 6 * 8 * 5 + vertices;
  std::vector<ProgressUpdate> seen;
  Monitor monitor;
  monitor.on_progress = [&](const ProgressUpdate& u) {
    if (u.task == "baking FIV shells and self-shadows") seen.push_back(u);
  };
  const SceneBake out = bake_scene(scene, plan, meshes, &env, monitor, [](const std::string&) {});
  ASSERT_FALSE(seen.empty());
  size_t finished = 0;
  uint64_t last = 0;
  for (const ProgressUpdate& u : seen) {
    EXPECT_EQ(u.total, total);
    EXPECT_GE(u.done, last) << "the count never restarts";
    last = u.done;
    finished += u.finished;
  }
  EXPECT_EQ(finished, 1u);
  EXPECT_TRUE(seen.back().finished);
  EXPECT_EQ(seen.back().done, total);
  size_t baked = 0;
  for (size_t i = 0; i < out.objects.size(); ++i) {
    const ObjectBake& ob = out.objects[i];
    baked += ob.shells ? 1 : 0;
    EXPECT_EQ(ob.fiv_self.has_value(), ob.shells.has_value()) << i;
    if (ob.fiv_self) {
      EXPECT_EQ(ob.fiv_self->values.values.size(), meshes[i].positions.size() * ob.fiv_self->values.layout.width);
    }
  }
  EXPECT_EQ(baked, movers);
}
