// A bake's glTF export opened in Blender (tests/tools/blender_roundtrip.py runs Blender's own glTF
// add-on headless and writes what the imported mesh holds), compared with the bake: every vertex
// at its baked position, the same triangles with the same winding, and the AO (COLOR_0) within
// the quantisation of Blender's 8-bit sRGB colour attribute. Found on the way (formats/SCHEMA.md,
// "Exports"): Blender 3.4 (Debian 12) does not import custom attributes (_AO, _PRT_*), and its
// glTF exporter writes a re-saved file's colours in another vertex order than its positions, so a
// file re-saved from that Blender has scrambled AO. Needs `blender` on PATH (the ci preset
// requires it); skipped otherwise.
#include <formats/asset.h>

#include <gtest/gtest.h>
#include <run_tool.h>
#include <scratch.h>

#include <nlohmann/json.hpp>

#include <array>
#include <cmath>
#include <fstream>
#include <map>

namespace fs = std::filesystem;
using prt::testing::run_tool;

namespace {

// sRGB encoding and decoding (IEC 61966-2-1), as Blender's byte colours store linear values.
double srgb_from_linear(double x) { return x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1 / 2.4) - 0.055; }
double linear_from_srgb(double s) { return s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4); }

TEST(BlenderRoundTrip, ImportedGeometryExactAndAoWithinTheColourQuantisation) {
#ifndef PRT_BLENDER
  GTEST_SKIP() << "blender is not installed (the ci preset requires it)";
#else
  const fs::path d = prt::testing::fresh_dir("blender", "bunny");
  const fs::path bake = d / "bunny.prt.h5", ours = d / "bunny.glb", back = d / "bunny_blender.glb";
  auto r = run_tool(PRT_PRTBAKE, "vertex '" + std::string(PRT_DATA_DIR) + "/bunny.obj' --ao --transfer 3 --integrator qmc "
                    "--samples 16 --report 0 -q -o '" + bake.string() + "'", d);
  ASSERT_EQ(r.code, 0) << r.err;
  r = run_tool(PRT_PRTBAKE, "export '" + bake.string() + "' --to glb -o '" + ours.string() + "'", d);
  ASSERT_EQ(r.code, 0) << r.err;
  const fs::path held = d / "blender.json";
  r = run_tool(PRT_BLENDER, "-b --factory-startup --python '" + std::string(PRT_SOURCE_TESTS) +
                                "/tools/blender_roundtrip.py' -- '" + ours.string() + "' '" + held.string() + "'", d);
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  std::ifstream in(held);
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_EQ(j.at("meshes").size(), 1u);
  const nlohmann::json& mesh = j["meshes"][0];
  RecordProperty("blender", j.at("blender").get<std::string>());

  const prt::formats::Asset asset = prt::formats::read_asset(bake);
  const auto& pos = asset.vertices.positions->values;
  const auto& ao = asset.vertices.ao->values;
  const size_t V = ao.size();
  std::map<std::array<float, 3>, size_t> row_of;
  for (size_t v = 0; v < V; ++v) row_of[{float(pos[3 * v]), float(pos[3 * v + 1]), float(pos[3 * v + 2])}] = v;
  ASSERT_EQ(row_of.size(), V) << "the test needs distinct positions";
  ASSERT_EQ(mesh.at("positions").size(), V) << "no vertex split or merged";
  EXPECT_EQ(mesh.at("corners_disagreeing").get<int>(), 0) << "one colour per vertex";

  // Every vertex at a baked position, bit for bit (float positions, exact frame change), each row
  // once; its colour is the AO after Blender's 8-bit sRGB byte colour: within the larger distance
  // from the AO to the two 8-bit codes around it (Blender's rounding mode is not ours to assume),
  // plus float rounding.
  std::vector<size_t> row(V);
  std::vector<bool> seen(V, false);
  double worst = 0;
  for (size_t i = 0; i < V; ++i) {
    const auto& p = mesh["positions"][i];
    const auto it = row_of.find({p[0].get<float>(), p[1].get<float>(), p[2].get<float>()});
    ASSERT_NE(it, row_of.end()) << "vertex " << i << " moved";
    ASSERT_FALSE(seen[it->second]) << "row " << it->second << " twice";
    seen[it->second] = true;
    row[i] = it->second;
    const double a = ao[it->second], code = srgb_from_linear(a) * 255;
    const double bound = std::max(std::abs(linear_from_srgb(std::floor(code) / 255) - a),
                                  std::abs(linear_from_srgb(std::ceil(code) / 255) - a)) + 1e-6;
    const auto& c = mesh.at("colours")[i];
    ASSERT_TRUE(c.is_array()) << "vertex " << i << " has no colour";
    for (size_t k = 0; k < 3; ++k) {
      EXPECT_LE(std::abs(c[k].get<double>() - a), bound) << "vertex " << i << " channel " << k;
      worst = std::max(worst, std::abs(c[k].get<double>() - a));
    }
  }
  RecordProperty("max_ao_error", std::to_string(worst));
  // The same triangles over the same rows, with the same winding (each rotated to start at its
  // smallest row).
  auto canonical = [](std::array<size_t, 3> t) {
    while (t[0] > t[1] || t[0] > t[2]) t = {t[1], t[2], t[0]};
    return t;
  };
  std::vector<std::array<size_t, 3>> want, got;
  const auto& tris = asset.vertices.triangles->values;
  for (size_t t = 0; t + 2 < tris.size(); t += 3) want.push_back(canonical({tris[t], tris[t + 1], tris[t + 2]}));
  for (const auto& poly : mesh.at("polygons")) {
    ASSERT_EQ(poly.size(), 3u);
    got.push_back(canonical({row[poly[0].get<size_t>()], row[poly[1].get<size_t>()], row[poly[2].get<size_t>()]}));
  }
  std::sort(want.begin(), want.end());
  std::sort(got.begin(), got.end());
  EXPECT_EQ(got, want);
#endif
}

} // namespace
