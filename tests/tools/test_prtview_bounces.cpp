// prtview against the path-traced reference (view/reference.h BOUNCES; issue 31): a file baked
// with bounces is compared with a reference that bounces as often, at the file's albedo, and
// says so; that reference is closer to it than the direct-only one.
#include "run_tool.h"
#include "scratch.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

namespace fs = std::filesystem;
using prt::testing::run_tool;

namespace {

const std::string kData = PRT_DATA_DIR;

// The value printed after `key` at the start of a line of `out` (negative if none).
double printed(const std::string& out, const std::string& key) {
  for (size_t at = 0; at < out.size();) {
    const size_t end = out.find('\n', at);
    const std::string line = out.substr(at, end == std::string::npos ? std::string::npos : end - at);
    double v = 0;
    if (line.rfind(key, 0) == 0 && std::sscanf(line.c_str() + key.size(), "%lf", &v) == 1) return v;
    if (end == std::string::npos) break;
    at = end + 1;
  }
  return -1;
}

} // namespace

TEST(PrtviewBounces, BouncedBakeMatchesThePathTracedReference) {
  // (c) The bunny on its ground, band-1 radiance under sunset.exr with 3 bounces at albedo 0.6
  // (the exact all-frequency product: its only errors are the gather's noise, Gouraud
  // interpolation and the reference's noise), seen from prtview's first look at 64x48.
  // Measured (seed 1, 1,024 reference rays and paths per pixel, 1,765 pixels): NRMSE 0.0119
  // against the 3-bounce path-traced reference (its own noise 0.0071, noise-corrected 0.0096),
  // 0.0907 against the direct-only one (--bounces 0): the bounces lift the bunny's underside and
  // the ground beside it. Bounds on NRMSE: 0.02 (the issue's 2 % bar; the measured value plus the
  // reference's noise fits well below it) and a factor 4 between the two (measured 7.6).
  const fs::path d = prt::testing::fresh_dir("prtview_bounces", "bunny");
  const fs::path file = d / "bounced.prt.h5";
  auto r = run_tool(PRT_PRTBAKE,
                    "vertex " + kData + "/bunny_ground.obj --radiance " + kData +
                        "/sunset.exr --bounces 3 --albedo 0.6 --report 0 -q -o " + file.string(),
                    d / "capture");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string view = file.string() + " --size 64x48 --samples 1024 --error -o " + (d / "e.exr").string();
  r = run_tool(PRT_PRTVIEW, view, d / "capture");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("reference: path traced, 3 bounces, albedo 0.6"), std::string::npos) << r.out;
  const double bounced = printed(r.out, "NRMSE "), relative_l2 = printed(r.out, "relative L2 error ");
  r = run_tool(PRT_PRTVIEW, view + " --bounces 0", d / "capture");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("direct light only, albedo 0.6"), std::string::npos) << r.out;
  const double direct = printed(r.out, "NRMSE ");
  std::printf("NRMSE against the 3-bounce reference %.5f, against the direct-only one %.5f\n", bounced, direct);
  ASSERT_GE(bounced, 0.0);
  EXPECT_LT(bounced, 0.02);
  // The issue's bar itself: relative L2 error ≤ 2 % at 3 bounces (measured 0.0155, 0.0125 with
  // the reference's noise taken out).
  EXPECT_GE(relative_l2, 0.0);
  EXPECT_LE(relative_l2, 0.02);
  EXPECT_GT(direct, 4 * bounced);
  // The triptych of a bounced file gets the direct light first: direct | baked | reference |
  // error, four 64-pixel panels side by side, and prints the direct light's error against the
  // bounced reference (the same pixels: its relative L2 is the bounces' share, several times the
  // bake's own).
  const fs::path png = d / "t.png";
  r = run_tool(PRT_PRTVIEW, file.string() + " --size 64x48 --samples 1024 --triptych -o " + png.string(), d / "capture");
  ASSERT_EQ(r.code, 0) << r.err;
  const double direct_l2 = printed(r.out, "direct light alone (no bounces) against the reference: relative L2 ");
  EXPECT_GT(direct_l2, 3 * relative_l2) << r.out;
  std::ifstream in(png, std::ios::binary);
  unsigned char header[24] = {};
  in.read(reinterpret_cast<char*>(header), sizeof header);
  const uint32_t width = uint32_t(header[16]) << 24 | uint32_t(header[17]) << 16 | uint32_t(header[18]) << 8 | header[19];
  EXPECT_GE(width, 4u * 64u);  // four panels (plus gaps)
  EXPECT_LT(width, 5u * 64u);
}

TEST(PrtviewBounces, ADirectFileNeedsAnAlbedoToBounceWith) {
  // A file baked without bounces names no albedo: --bounces B alone is a usage error (exit 2) that
  // says what to add and writes nothing; with --albedo the reference bounces at it and says so.
  const fs::path d = prt::testing::fresh_dir("prtview_bounces", "direct");
  const fs::path file = d / "direct.prt.h5";
  auto r = run_tool(PRT_PRTBAKE, "vertex " + kData + "/bunny_ground.obj --radiance " + kData + "/sunset.exr --report 0 -q -o " +
                                     file.string(), d / "capture");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string view = file.string() + " --size 24x18 --samples 8 --error -o " + (d / "e.exr").string();
  r = run_tool(PRT_PRTVIEW, view + " --bounces 2", d / "capture");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("give --albedo A"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(d / "e.exr"));
  r = run_tool(PRT_PRTVIEW, view + " --bounces 2 --albedo 0.5", d / "capture");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("reference: path traced, 2 bounces, albedo 0.5 (--bounces and --albedo)"), std::string::npos) << r.out;
}

TEST(PrtviewBounces, AreaLightBouncesMatchThePathTracedReference) {
  // The Cornell-like room per texel (24 texels per unit) under a quad light below its ceiling,
  // albedo 0.6, its area-light irradiance baked with 3 bounces (the gather cache and the
  // lightmap field, bake/bake/bounce.h) against prtview's area reference path-traced with as many
  // (view/area_lights.h: next-event estimation per path vertex; an independent estimator), 128²,
  // 512 rays and paths per pixel. Measured: relative L2 0.0224 (0.0161 with the reference's noise
  // taken out); the direct light alone is off by 0.112. Bounds: 0.035 (the 2 % bar plus the
  // reference's noise, its noise-corrected value below 0.02) and a factor 3 for the direct light.
  const fs::path d = prt::testing::fresh_dir("prtview_bounces", "area");
  const fs::path json = d / "room.json", file = d / "room.prt.h5";
  std::ofstream(json) << R"({"prtbake_scene": 1,
    "bake": {"integrator": "qmc", "samples": 256, "report": 0, "bounces": 3, "products": ["ao"]},
    "lights": [{"name": "ceiling", "shape": "quad", "centre": [0, 0.99, 0], "u": [0.6, 0, 0], "v": [0, 0, 0.6],
                "radiance": [4, 4, 4]}],
    "objects": [{"name": "room", "mesh": ")" << kData << R"(/cornell_room.obj", "role": "both",
                 "material": {"albedo": [0.6, 0.6, 0.6]}, "lightmap": {"density": 24, "unwrap": true}}]})";
  auto r = run_tool(PRT_PRTBAKE, "scene " + json.string() + " -q -o " + file.string(), d / "capture");
  ASSERT_EQ(r.code, 0) << r.err;
  r = run_tool(PRT_PRTVIEW,
               file.string() + " --shade area --camera eye=0,0,4.2:at=0,0,0:up=0,1,0:fov=45 --size 128x128 --samples 512 "
                               "--triptych -o " + (d / "t.png").string(),
               d / "capture");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("3 bounces path traced with 512 paths per pixel"), std::string::npos) << r.out;
  const double l2 = printed(r.out, "relative L2 error ");
  const size_t line = r.out.find("relative L2 error "), at = r.out.find("; noise-corrected ", line);
  ASSERT_NE(at, std::string::npos) << r.out;
  const double corrected = std::stod(r.out.substr(at + std::string("; noise-corrected ").size()));
  const double direct = printed(r.out, "direct light alone (no bounces) against the reference: relative L2 ");
  std::printf("area lights, 3 bounces: relative L2 %.5f (noise-corrected %.5f), direct light alone %.5f\n", l2, corrected, direct);
  ASSERT_GE(l2, 0.0);
  EXPECT_LE(l2, 0.035);
  EXPECT_LE(corrected, 0.02);
  EXPECT_GT(direct, 3 * l2);
}
