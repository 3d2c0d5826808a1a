// Interreflections through prtbake (bake/bake/bounce.h, formats/SCHEMA.md "Bounces"): albedo 0
// gives the direct bake's values, every bounce adds energy, any thread count gives the same bytes,
// the attributes say what the transfer holds, and bad albedos and missing options are usage
// errors (exit 2) that name the problem and write nothing.
#include "run_tool.h"
#include "scratch.h"

#include <formats/prtfile.h>

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <filesystem>
#include <string>
#include <vector>

namespace fs = std::filesystem;
namespace F = prt::formats;
using prt::testing::run_tool;

namespace {

const std::string kData = PRT_DATA_DIR;
// The bunny on its ground: the ground lights the bunny's underside and the bunny the ground.
const std::string kBake = "vertex " + kData + "/bunny_ground.obj --transfer 3 --integrator qmc --samples 64 --report 0";

fs::path dir_for(const std::string& name) { return prt::testing::fresh_dir("bounces", name); }

const std::string kEnv = " --radiance " + kData + "/sunset.exr";

std::vector<float> dataset(const fs::path& file, const std::string& path) {
  const F::File f = F::read_file(file);
  const F::Dataset* d = F::find_dataset(f, path);
  EXPECT_NE(d, nullptr) << path;
  return d ? std::get<std::vector<float>>(d->data) : std::vector<float>{};
}
std::vector<float> transfer(const fs::path& file) { return dataset(file, "/transfer/diffuse"); }

// The irradiance each vertex's band-1 radiance gives at its baked normal, E_c = (4π/3) Σ_m y_1m(n) R_c,m
// (in double from the file's floats), [V][RGB].
std::vector<double> irradiance(const fs::path& file) {
  const std::vector<float> R = dataset(file, "/radiance/band1"), n = dataset(file, "/mesh/normals");
  std::vector<double> E(n.size());
  const double k = 0.4886025119029199 * 4 * std::acos(-1.0) / 3;  // y_1m(n) = 0.488603 (−n_y, n_z, −n_x)
  for (size_t v = 0; v < n.size() / 3; ++v)
    for (size_t c = 0; c < 3; ++c) {
      const float* r = &R[9 * v + 3 * c];
      E[3 * v + c] = k * (-double(n[3 * v + 1]) * r[0] + double(n[3 * v + 2]) * r[1] - double(n[3 * v]) * r[2]);
    }
  return E;
}

F::AttrValue attr(const fs::path& file, const std::string& name, const std::string& path = "/transfer/diffuse") {
  const F::File f = F::read_file(file);
  const F::Attr* a = F::find_attr(F::find_dataset(f, path)->attrs, name);
  EXPECT_NE(a, nullptr) << name;
  return a ? a->value : F::AttrValue{};
}

fs::path bake(const fs::path& d, const std::string& name, const std::string& extra) {
  const fs::path out = d / (name + ".prt.h5");
  const auto r = run_tool(PRT_PRTBAKE, kBake + " " + extra + " -q -o " + out.string(), d / "capture");
  EXPECT_EQ(r.code, 0) << r.err;
  return out;
}

} // namespace

// (a) Albedo 0: the file's transfer has the direct bake's values exactly (every bounce is zero), and
// its attributes say what was asked.
TEST(Bounces, ZeroAlbedoGivesTheDirectValues) {
  const fs::path d = dir_for("zero");
  const fs::path direct = bake(d, "direct", kEnv), zero = bake(d, "zero", "--bounces 3 --albedo 0" + kEnv);
  EXPECT_TRUE(transfer(zero) == transfer(direct));
  EXPECT_TRUE(dataset(zero, "/radiance/band1") == dataset(direct, "/radiance/band1"));
  EXPECT_EQ(std::get<int64_t>(attr(zero, "bounces", "/radiance/band1")), 1);
  EXPECT_EQ(std::get<int64_t>(attr(zero, "bounces")), 1);  // the first bounce added nothing: stopped
  EXPECT_EQ(std::get<int64_t>(attr(zero, "bounces_requested")), 3);
  EXPECT_EQ(std::get<std::vector<double>>(attr(zero, "albedo")), (std::vector<double>{0, 0, 0}));
  EXPECT_EQ(std::get<int64_t>(attr(zero, "bounce_rays")), 256);
}

// (b) Under a non-negative environment every bounce adds non-negative light: T_00 (a uniform sky's
// transfer) and the irradiance band-1 radiance gives at each vertex's normal never fall from B to
// B + 1, and their means grow. (Exact in the bake; T_00 is compared as stored, since float rounding
// is monotone, and E is formed from the stored floats, so it may fall by their rounding, 1e-6
// relative, no more.)
TEST(Bounces, EveryBounceAddsEnergy) {
  const fs::path d = dir_for("energy");
  const fs::path first = bake(d, "b0", kEnv);
  std::vector<float> before = transfer(first);
  std::vector<double> e_before = irradiance(first);
  const size_t n = 9, V = before.size() / n;
  double mean_before = 0, e_mean_before = 0;
  for (size_t v = 0; v < V; ++v) mean_before += before[v * n];
  for (const double e : e_before) e_mean_before += e;
  for (int B = 1; B <= 3; ++B) {
    const fs::path out =
        bake(d, "b" + std::to_string(B), "--bounces " + std::to_string(B) + " --albedo 0.7 --bounce-rays 64" + kEnv);
    EXPECT_EQ(std::get<int64_t>(attr(out, "bounces")), B);
    const std::vector<float> now = transfer(out);
    const std::vector<double> e_now = irradiance(out);
    ASSERT_EQ(now.size(), before.size());
    ASSERT_EQ(e_now.size(), e_before.size());
    double mean = 0, e_mean = 0;
    for (size_t v = 0; v < V; ++v) {
      EXPECT_GE(now[v * n], before[v * n]) << "vertex " << v << ", B = " << B;
      ASSERT_TRUE(std::isfinite(now[v * n]));
      mean += now[v * n];
    }
    for (size_t i = 0; i < e_now.size(); ++i) {
      EXPECT_GE(e_now[i], e_before[i] - 1e-6 * std::abs(e_before[i])) << "vertex " << i / 3 << ", B = " << B;
      e_mean += e_now[i];
    }
    EXPECT_GT(mean, mean_before) << "B = " << B;
    EXPECT_GT(e_mean, e_mean_before) << "B = " << B;
    mean_before = mean;
    e_mean_before = e_mean;
    before = now;
    e_before = e_now;
  }
}

// Per texel (prtbake texel --bounces): the bounces read the previous bounce's lightmap at each hit
// (bake/bake/bounce.h TexelField). Albedo 0 gives the direct lightmap's bytes; at albedo 0.7 every
// baked texel's T_00 grows (exact in the bake, monotone through float rounding and through the
// lightmap's fill and padding, which are means), and the lightmap's product says how it was made.
TEST(Bounces, PerTexelZeroAlbedoIsDirectAndEachBounceAddsEnergy) {
  const fs::path d = dir_for("texel");
  const std::string texel = "texel " + kData + "/bunny_ground.obj --resolution 64 --transfer 2 --integrator qmc "
                            "--samples 64 --report 0 --no-stitch -q -o ";
  auto bake_texel = [&](const std::string& name, const std::string& extra) {
    const fs::path out = d / (name + ".prt.h5");
    const auto r = run_tool(PRT_PRTBAKE, texel + out.string() + " " + extra, d / "capture");
    EXPECT_EQ(r.code, 0) << r.err;
    return out;
  };
  const std::string lm = "/lightmap/transfer/diffuse";
  const fs::path direct = bake_texel("direct", ""), zero = bake_texel("zero", "--bounces 2 --albedo 0");
  EXPECT_TRUE(dataset(zero, lm) == dataset(direct, lm));
  const std::vector<float> before = dataset(direct, lm);
  const std::vector<uint8_t> state = std::get<std::vector<uint8_t>>(F::find_dataset(F::read_file(direct), "/lightmap/state")->data);
  const fs::path two = bake_texel("two", "--bounces 2 --albedo 0.7 --bounce-rays 64");
  EXPECT_EQ(std::get<int64_t>(attr(two, "bounces", lm)), 2);
  EXPECT_EQ(std::get<std::vector<double>>(attr(two, "albedo", lm)), (std::vector<double>{0.7, 0.7, 0.7}));
  const std::vector<float> after = dataset(two, lm);
  ASSERT_EQ(after.size(), before.size());
  ASSERT_EQ(state.size() * 4, before.size());
  double gained = 0;
  size_t baked = 0;
  for (size_t t = 0; t < state.size(); ++t) {
    ASSERT_TRUE(std::isfinite(after[4 * t]));
    if (state[t] != 1) continue;  // baked texels only (filled and padded ones are means of them)
    ++baked;
    EXPECT_GE(after[4 * t], before[4 * t]) << "texel " << t;
    gained += after[4 * t] - before[4 * t];
  }
  EXPECT_GT(baked, 1000u);
  EXPECT_GT(gained, 0);
}

// A coloured albedo bounces the band-1 radiance per channel (bake/bake/bounce.h "COLOUR"): each
// channel's bounces see only that channel's light and albedo, so with one bounce at (0.6, 0.3, 0)
// red is bit for bit the grey 0.6 bake's red, blue is the direct bake's, and green's bounce is half
// of the grey bake's green bounce (linear in ρ; to the float rounding of the stored values, a few
// ulps of the largest value: 1e-6 of it).
TEST(Bounces, ColouredAlbedoBouncesEachChannelWithItsOwn) {
  const fs::path d = dir_for("colour");
  const std::string radiance_only = "vertex " + kData + "/bunny_ground.obj --integrator qmc --samples 64 --report 0" + kEnv;
  auto bake_r = [&](const std::string& name, const std::string& extra) {
    const fs::path out = d / (name + ".prt.h5");
    const auto r = run_tool(PRT_PRTBAKE, radiance_only + " " + extra + " -q -o " + out.string(), d / "capture");
    EXPECT_EQ(r.code, 0) << r.err;
    return dataset(out, "/radiance/band1");
  };
  const std::vector<float> direct = bake_r("direct", ""),
                           grey = bake_r("grey", "--bounces 1 --albedo 0.6 --bounce-rays 64"),
                           colour = bake_r("colour", "--bounces 1 --albedo 0.6,0.3,0 --bounce-rays 64");
  ASSERT_EQ(direct.size(), colour.size());
  ASSERT_EQ(grey.size(), colour.size());
  float largest = 0;
  for (const float x : grey) largest = std::max(largest, std::abs(x));
  double green_bounce = 0;
  for (size_t v = 0; v < direct.size() / 9; ++v)
    for (size_t m = 0; m < 3; ++m) {
      const size_t r = 9 * v + m, g = 9 * v + 3 + m, b = 9 * v + 6 + m;
      EXPECT_EQ(colour[r], grey[r]) << v;
      EXPECT_EQ(colour[b], direct[b]) << v;
      EXPECT_NEAR(colour[g] - direct[g], 0.5 * (grey[g] - direct[g]), 1e-6 * largest) << v;
      green_bounce += std::abs(colour[g] - direct[g]);
    }
  EXPECT_GT(green_bounce, 0);
}

// A scene of one "both" object bounces as the single mesh does (bake/bake/scene.h rule "bounces"):
// its vertices are the union's shade points, the gather is seeded alike, the field is its own
// vertices, so with the same integrator, seed, albedo and rays its band-1 radiance is the vertex
// bake's, value for value. And the plan says who reflects and who does not.
TEST(Bounces, ASceneOfOneObjectBouncesAsTheMeshAlone) {
  const fs::path d = dir_for("scene");
  const std::string mesh = kData + "/bunny_ground.obj";
  std::ofstream(d / "scene.json")
      << R"({"prtbake_scene": 1, "environment": ")" << kData << R"(/sunset.exr",
             "bake": {"products": ["radiance"], "integrator": "qmc", "samples": 64, "report": 0, "bounces": 2,
                      "bounce_rays": 64},
             "objects": [{"name": "b", "mesh": ")" << mesh << R"(", "role": "both", "material": {"albedo": [0.6, 0.6, 0.6]}}]})";
  const fs::path scene_out = d / "scene.prt.h5", vertex_out = d / "vertex.prt.h5";
  const auto s = run_tool(PRT_PRTBAKE, "scene " + (d / "scene.json").string() + " -o " + scene_out.string(), d / "capture");
  ASSERT_EQ(s.code, 0) << s.err;
  EXPECT_NE(s.out.find("bounces: radiance/band1 with 2 bounce(s)"), std::string::npos) << s.out;
  EXPECT_NE(s.out.find("bounces: 2 of 2 over 4240 receiver rows"), std::string::npos) << s.out;
  const auto v = run_tool(PRT_PRTBAKE,
                          "vertex " + mesh + kEnv + " --integrator qmc --samples 64 --report 0 --bounces 2 --albedo 0.6 "
                          "--bounce-rays 64 -q -o " + vertex_out.string(),
                          d / "capture");
  ASSERT_EQ(v.code, 0) << v.err;
  const std::vector<float> scene_r = dataset(scene_out, "/objects/b/radiance/band1"),
                           vertex_r = dataset(vertex_out, "/radiance/band1");
  ASSERT_EQ(scene_r.size(), vertex_r.size());
  EXPECT_TRUE(scene_r == vertex_r);
  EXPECT_EQ(std::get<int64_t>(attr(scene_out, "bounces", "/objects/b/radiance/band1")), 2);
}

// The plan says who gathers and who reflects (bake/bake/scene.h rule "bounces"), and refuses an
// albedo of 1 on a reflecting object by name.
TEST(Bounces, TheScenePlanSaysWhoReflects) {
  const fs::path d = dir_for("plan");
  auto scene = [&](const std::string& albedo) {
    std::ofstream(d / "scene.json")
        << R"({"prtbake_scene": 1, "environment": ")" << kData << R"(/sunset.exr", "bake": {"bounces": 3},
               "objects": [{"name": "bunny", "mesh": ")" << kData << R"(/bunny.obj", "role": "both",
                            "material": {"albedo": )" << albedo << R"(}},
                           {"name": "ground", "mesh": ")" << kData << R"(/ground.obj", "role": "receiver"},
                           {"name": "spider", "mesh": ")" << kData << R"(/spider.obj", "role": "occluder"},
                           {"name": "statue", "mesh": ")" << kData << R"(/wuson.obj", "role": "both",
                            "material": {"phong_exponent": 4, "specular": [0.5, 0.5, 0.5]}}]})";
    return run_tool(PRT_PRTBAKE, "scene " + (d / "scene.json").string() + " --dry-run", d / "capture");
  };
  const auto r = scene("[0.6, 0.5, 0.4]");
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* line :
       {"bounces: radiance/band1 with 3 bounce(s) of the light the 1 reflecting object(s) send (this one at albedo "
        "0.6,0.5,0.4)",
        "bounces: receiver only: it is not in the occluders' union, so no ray meets it: it gathers the others' light "
        "but reflects none",
        "bounces: occluder only: it casts shadows but has no rows, so it reflects no light",
        "bounces: 3 of diffuse interreflection, 256 gather rays per receiver row; reflecting: bunny",
        "bounces: radiance/shadowed with 3 bounce(s) of the light the 1 reflecting object(s) send\n"})
    EXPECT_NE(r.out.find(line), std::string::npos) << line << "\n" << r.out;
  const auto one = scene("[1, 0.5, 0.4]");
  EXPECT_NE(one.code, 0);
  EXPECT_NE(one.err.find("object 'bunny': albedo 1,0.5,0.4 with bake.bounces: an albedo must be below 1"),
            std::string::npos)
      << one.err;
}

// Sharded (tools/prtbake/shards.h): the workers compute chunks of the direct rows; the bounces need
// every row's previous bounce, so they run where the rows are whole — in the merging process,
// which gathers with the same seed — and the file is the one-process bake's, byte for byte.
TEST(Bounces, ShardedBakesGiveTheOneProcessBytes) {
  const fs::path d = dir_for("shards"), out = d / "out.prt.h5";
  const std::string args = kBake + " --bounces 2 --albedo 0.5 --bounce-rays 32 --reproducible --chunk-rows 1024" + kEnv;
  auto run = [&](const std::string& extra) {
    const auto r = run_tool(PRT_PRTBAKE, args + " " + extra + " -q -o " + out.string(), d / "capture");
    EXPECT_EQ(r.code, 0) << r.err;
  };
  run("");
  const std::string one = prt::testing::read_bytes(out);
  fs::remove(out);
  run("--shard 0/2");
  run("--shard 1/2");
  EXPECT_FALSE(fs::exists(out));
  run("--merge");
  EXPECT_FALSE(one.empty());
  EXPECT_TRUE(prt::testing::read_bytes(out) == one);
}

// The shadowed radiance S bounces by (5') with y_i in place of y_1m (bake/bake/bounce.h): its band 1
// is the band-1 radiance's integral, so what the bounces add to S's band 1 is what they add to R
// (the same rays and products; compared through the stored floats, to 1e-6 of the largest value),
// and S_00 (∫ L V H y_00, every bounce adds ρ E y_00 ≥ 0 to it) grows at every vertex.
TEST(Bounces, ShadowedRadianceBouncesWithBandOneEqualToR) {
  const fs::path d = dir_for("shadowed");
  const std::string args = " --shadowed 3" + kEnv;
  const fs::path direct = bake(d, "direct", args), bounced = bake(d, "bounced", "--bounces 2 --albedo 0.6 --bounce-rays 64" + args);
  const std::vector<float> s0 = dataset(direct, "/radiance/shadowed"), s2 = dataset(bounced, "/radiance/shadowed"),
                           r0 = dataset(direct, "/radiance/band1"), r2 = dataset(bounced, "/radiance/band1");
  ASSERT_EQ(s0.size(), s2.size());
  ASSERT_EQ(s0.size() / 27, r0.size() / 9);
  float largest = 0;
  for (const float x : s2) largest = std::max(largest, std::abs(x));
  double added = 0;
  for (size_t v = 0; v < r0.size() / 9; ++v)
    for (size_t c = 0; c < 3; ++c) {
      const size_t s00 = 27 * v + 9 * c;
      EXPECT_GE(s2[s00], s0[s00]) << "vertex " << v << ", channel " << c;
      added += s2[s00] - s0[s00];
      for (size_t m = 0; m < 3; ++m)
        EXPECT_NEAR(double(s2[s00 + 1 + m]) - s0[s00 + 1 + m], double(r2[9 * v + 3 * c + m]) - r0[9 * v + 3 * c + m],
                    1e-6 * largest)
            << "vertex " << v << ", channel " << c << ", m " << m;
    }
  EXPECT_GT(added, 0);
  EXPECT_EQ(std::get<int64_t>(attr(bounced, "bounces", "/radiance/shadowed")), 2);
}

// Area lights bounce too (bake/bake/scene.h rule "bounces"): E_l of each receiver row, at unit
// radiance, gets the light the surfaces reflect of that light, by the transfer's recursion with a
// grey albedo. A quad light above the bunny on its ground, no environment: with 2 bounces E never
// falls at any vertex (every bounce adds ρ E ≥ 0; the stored floats are compared), grows in all,
// and the product says so; the plan names it.
TEST(Bounces, AreaLightIrradianceBouncesInScenes) {
  const fs::path d = dir_for("area");
  auto bake_scene = [&](const std::string& name, int bounces) {
    std::ofstream(d / (name + ".json"))
        << R"({"prtbake_scene": 1, "bake": {"integrator": "qmc", "samples": 64, "report": 0, "bounces": )" << bounces
        << R"(, "products": ["radiance"]}, "lights": [{"name": "key", "shape": "quad", "centre": [0, 15, 0],
               "u": [10, 0, 0], "v": [0, 0, 10], "radiance": [10, 10, 10]}],
             "objects": [{"name": "b", "mesh": ")" << kData << R"(/bunny_ground.obj", "role": "both",
                          "material": {"albedo": [0.6, 0.6, 0.6]}}]})";
    const fs::path out = d / (name + ".prt.h5");
    const auto r = run_tool(PRT_PRTBAKE, "scene " + (d / (name + ".json")).string() + " -o " + out.string(), d / "capture");
    EXPECT_EQ(r.code, 0) << r.err;
    return std::pair{out, r.out};
  };
  const auto [direct, direct_log] = bake_scene("direct", 0);
  const auto [bounced, log] = bake_scene("bounced", 2);
  EXPECT_NE(log.find("bounces: area_lights/irradiance with 2 bounce(s)"), std::string::npos) << log;
  const std::vector<float> e0 = dataset(direct, "/objects/b/area_lights/irradiance"),
                           e2 = dataset(bounced, "/objects/b/area_lights/irradiance");
  ASSERT_EQ(e0.size(), e2.size());
  ASSERT_EQ(e0.size(), 4240u);
  double added = 0;
  for (size_t v = 0; v < e0.size(); ++v) {
    EXPECT_GE(e2[v], e0[v]) << "vertex " << v;
    added += e2[v] - e0[v];
  }
  EXPECT_GT(added, 0);
  EXPECT_EQ(std::get<int64_t>(attr(bounced, "bounces", "/objects/b/area_lights/irradiance")), 2);
}

// (d) The same bytes with one thread and with two.
TEST(Bounces, SameBytesWhateverTheThreads) {
  const fs::path d = dir_for("threads");
  const std::string args = "--bounces 2 --albedo 0.5,0.5,0.5 --bounce-rays 32 --reproducible" + kEnv;
  // The same output path both times: the command line, stored in the file, names it.
  const std::string one = prt::testing::read_bytes(bake(d, "x", args + " --threads 1"));
  fs::remove(d / "x.prt.h5");
  const std::string two = prt::testing::read_bytes(bake(d, "x", args + " --threads 2"));
  EXPECT_FALSE(one.empty());
  EXPECT_TRUE(one == two);
}

// (e) Bad albedos, a missing one and what this version does not bounce: exit 2 before any work,
// the message naming the problem, no file.
TEST(Bounces, BadOptionsAreUsageErrors) {
  const fs::path d = dir_for("bad"), out = d / "x.prt.h5";
  const struct {
    std::string args, says;
  } cases[] = {
      {"--bounces 2 --albedo 1", "an albedo must be below 1"},
      {"--bounces 2 --albedo 1.5,1.5,1.5", "an albedo must be below 1"},
      {"--bounces 2 --albedo -0.2", "-0.2 is negative"},
      {"--bounces 2 --albedo grey", "expects R or R,G,B"},
      {"--bounces 2 --albedo 0.5,0.5", "expects R or R,G,B"},
      {"--bounces 2 --albedo 0.8,0.5,0.3", "bounces with a grey albedo only"},
      {"--bounces 2", "--bounces 2 needs --albedo R[,G,B]"},
      {"--albedo 0.5", "--albedo applies with --bounces"},
      {"--bounce-rays 64", "--bounce-rays applies with --bounces"},
  };
  for (const auto& c : cases) {
    const auto r = run_tool(PRT_PRTBAKE, kBake + " " + c.args + " -o " + out.string(), d / "capture");
    EXPECT_EQ(r.code, 2) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << c.args << "\n" << r.err;
    EXPECT_FALSE(fs::exists(out)) << c.args;
  }
  const auto ao = run_tool(PRT_PRTBAKE,
                           "vertex " + kData + "/bunny_ground.obj --ao --bounces 2 --albedo 0.5 -o " + out.string(),
                           d / "capture");
  EXPECT_EQ(ao.code, 2);
  EXPECT_NE(ao.err.find("give --transfer L or --radiance ENV"), std::string::npos) << ao.err;
}
