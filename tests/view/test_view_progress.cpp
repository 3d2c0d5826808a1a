// The reference renderer's progress and cancellation (view/reference.h, bake/core/progress.h): the same
// contract as libbake's bakes, and a watched render gives the same image.
#include <view/camera.h>
#include <view/reference.h>

#include <bake/core/progress.h>
#include <bake/environment/envmap.h>
#include <bake/mesh/mesh.h>

#include <gtest/gtest.h>
#include <progress_recorder.h>
#include <test_scenes.h>

#include <cstring>

using namespace prt::bake;
using namespace prt::view;

namespace {

// A ground grid with a box on it, seen from above: 48 × 48 pixels, a few distinct normals.
struct Shot {
  Mesh mesh;
  Camera camera;
  Shot() {
    const Mesh parts[] = {prt::testing::grid(4, 2.0f), prt::testing::box({-0.5f, -0.5f, 0}, {0.5f, 0.5f, 1})};
    mesh = merge_meshes(parts, "grid+box");
    camera.eye = {0.3, 0.2, 4};
    camera.at = {0, 0, 0};
    camera.fov_y_degrees = 60;
    camera.width = camera.height = 48;
  }
};

ReferenceOptions few_rays() {
  ReferenceOptions o;
  o.samples = 64;
  return o;
}

} // namespace

TEST(ReferenceProgress, OneStageToItsEndAndTheSameImage) {
  const Shot s;
  const EnvMap env = EnvMap::constant({1, 1, 1});
  const ReferenceRenderer rr(s.mesh, env, few_rays());
  const ReferenceImage silent = rr.render(s.camera);
  prt::testing::Recorder rec;
  const CancelToken never;
  const ReferenceImage watched = rr.render(s.camera, rec.monitor(&never));
  ASSERT_FALSE(rec.updates.empty());
  // The stage counts the distinct normals and then the rows.
  const uint64_t total = rec.updates.back().total;
  EXPECT_GT(total, uint64_t(s.camera.height));
  prt::testing::expect_complete_stage(rec, "reference", total);
  ASSERT_EQ(watched.radiance.rgb.size(), silent.radiance.rgb.size());
  EXPECT_EQ(std::memcmp(watched.radiance.rgb.data(), silent.radiance.rgb.data(), silent.radiance.rgb.size() * sizeof(float)), 0);
}

TEST(ReferenceProgress, ATokenCancelsBeforeAndDuringTheRender) {
  const Shot s;
  const EnvMap env = EnvMap::constant({1, 1, 1});
  const ReferenceRenderer rr(s.mesh, env, few_rays());
  CancelToken before;
  before.request();
  Monitor m;
  m.cancel = &before;
  EXPECT_THROW(rr.render(s.camera, m), Cancelled);

  CancelToken during;
  prt::testing::Recorder rec;
  rec.then = [&](const ProgressUpdate&) { during.request(); };  // at the stage's opening update
  EXPECT_THROW(rr.render(s.camera, rec.monitor(&during)), Cancelled);
  ASSERT_GE(rec.updates.size(), 2u);
  EXPECT_TRUE(rec.updates.back().finished);
  EXPECT_LT(rec.updates.back().done, rec.updates.back().total);
}
