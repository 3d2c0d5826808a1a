// The shadowed radiance S (paper 001 §4 "material editing"; bake/integrators/products.h, /radiance/shadowed in
// formats/SCHEMA.md) through the tools: prtbake vertex --shadowed L writes it with band 1 equal to
// /radiance/band1, refuses it without an environment; a sharded bake with it has the bytes of the
// single-process one; a scene's glossy receiver under the environment gets it at the Phong order
// (and keeps transfer/visibility for relighting), and none without "radiance" in bake.products.
#include "run_tool.h"
#include "scratch.h"

#include <formats/prtfile.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace fs = std::filesystem;
namespace F = prt::formats;
using prt::testing::read_bytes;
using prt::testing::run_tool;

namespace {

const std::string kData = PRT_DATA_DIR;

fs::path dir_for(const std::string& name) { return prt::testing::fresh_dir("shadowed", name); }

const std::vector<float>& values(const F::File& f, const std::string& path) {
  const F::Dataset* d = F::find_dataset(f, path);
  static const std::vector<float> none;
  EXPECT_NE(d, nullptr) << path;
  return d ? std::get<std::vector<float>>(d->data) : none;
}

int64_t sh_order(const F::File& f, const std::string& path) {
  const F::Dataset* d = F::find_dataset(f, path);
  return d ? std::get<int64_t>(F::find_attr(d->attrs, "sh_order")->value) : -1;
}

const std::string kVertex = "vertex " + kData + "/bunny_ground.obj --shadowed 3 --radiance " + kData +
                            "/sunset.exr --samples 64 --threads 1";

} // namespace

TEST(Shadowed, VertexBakeWritesSWithBandOneEqualToR) {
  const fs::path d = dir_for("vertex"), out = d / "s.prt.h5";
  const auto r = run_tool(PRT_PRTBAKE, kVertex + " --integrator qmc -q -o " + out.string(), d / "capture");
  ASSERT_EQ(r.code, 0) << r.err;
  const F::File f = F::read_file(out);
  const F::Dataset* s = F::find_dataset(f, "/radiance/shadowed");
  ASSERT_NE(s, nullptr);
  const size_t V = F::find_dataset(f, "/mesh/positions")->shape[0];
  EXPECT_EQ(s->shape, (std::vector<uint64_t>{V, 3, 9}));
  EXPECT_EQ(sh_order(f, "/radiance/shadowed"), 3);
  // The same integral from the same samples, rounded to float the same way.
  const std::vector<float>& S = values(f, "/radiance/shadowed");
  const std::vector<float>& R = values(f, "/radiance/band1");
  for (size_t v = 0; v < V; ++v)
    for (size_t c = 0; c < 3; ++c)
      for (size_t m = 0; m < 3; ++m) ASSERT_EQ(S[(3 * v + c) * 9 + 1 + m], R[(3 * v + c) * 3 + m]) << v;
  const fs::path none = d / "none.prt.h5";
  const auto bad = run_tool(PRT_PRTBAKE, "vertex " + kData + "/bunny_ground.obj --ao --shadowed 3 -o " + none.string(),
                            d / "capture");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("--shadowed L needs --radiance ENV"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(none));
}

TEST(Shadowed, ShardedBakeHasTheBytesOfTheSingleProcessOne) {
  const fs::path d = dir_for("shards"), out = d / "s.prt.h5";
  const std::string args = kVertex + " --integrator silhouette --chunk-rows 1024";
  ASSERT_EQ(run_tool(PRT_PRTBAKE, args + " --reproducible -q -o " + out.string(), d / "capture").code, 0);
  const std::string single = read_bytes(out);
  fs::remove(out);
  const auto r = run_tool(PRT_PRTBAKE, args + " --resume -q -o " + out.string(), d / "capture");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(read_bytes(out) == single);
}

TEST(Shadowed, SceneGlossyReceiverGetsSAtThePhongOrder) {
  const fs::path d = dir_for("scene");
  std::ofstream(d / "box.obj") << "v -1 1 -1\nv 1 1 -1\nv -1 3 -1\nv 1 3 -1\nv -1 1 1\nv 1 1 1\nv -1 3 1\nv 1 3 1\n"
                                  "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
  auto scene = [&](const std::string& products) {
    return "{\"prtbake_scene\": 1, \"environment\": \"" + kData + "/sunset.exr\", \"bake\": {\"samples\": 1024, " +
           "\"report\": 0, \"products\": " + products + "}, \"objects\": [{\"name\": \"box\", \"mesh\": \"box.obj\", " +
           "\"role\": \"both\", \"material\": {\"phong_exponent\": 24}}]}";
  };
  std::ofstream(d / "all.json") << scene(R"(["ao", "transfer", "radiance"])");
  std::ofstream(d / "u.json") << scene(R"(["transfer"])");
  const auto all = run_tool(PRT_PRTBAKE, "scene " + (d / "all.json").string() + " -o " + (d / "all.prt.h5").string(), d / "capture");
  ASSERT_EQ(all.code, 0) << all.err;
  // Phong 24 at the default 1% tolerance: order 11 (test_scene.cpp), for S and U alike.
  EXPECT_NE(all.out.find("bake       radiance/shadowed: order 11 for the Phong exponent 24"), std::string::npos) << all.out;
  const F::File f = F::read_file(d / "all.prt.h5");
  EXPECT_EQ(sh_order(f, "/objects/box/radiance/shadowed"), 11);
  EXPECT_EQ(sh_order(f, "/objects/box/transfer/visibility"), 11);
  EXPECT_EQ(F::find_dataset(f, "/objects/box/radiance/band1"), nullptr) << "no diffuse albedo";
  const auto u = run_tool(PRT_PRTBAKE, "scene " + (d / "u.json").string() + " -o " + (d / "u.prt.h5").string(), d / "capture");
  ASSERT_EQ(u.code, 0) << u.err;
  EXPECT_NE(u.out.find("leave out  radiance/shadowed: not in bake.products"), std::string::npos) << u.out;
  const F::File g = F::read_file(d / "u.prt.h5");
  EXPECT_EQ(F::find_dataset(g, "/objects/box/radiance/shadowed"), nullptr);
  EXPECT_EQ(sh_order(g, "/objects/box/transfer/visibility"), 11);
}
