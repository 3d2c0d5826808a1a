// A bake's glTF export opened in Blender (tests/tools/blender_roundtrip.py runs Blender's own glTF
// add-on headless and writes what the imported mesh holds), compared with the bake: every vertex
// at its baked position, the same triangles with the same winding, and the AO (COLOR_0) within
// the quantisation of Blender's 8-bit sRGB colour attribute. Found on the way (formats/SCHEMA.md,
// "Exports"): Blender 3.4 (Debian 12) does not import custom attributes (_AO, _PRT_*), and its
// glTF exporter writes a re-saved file's colours in another vertex order than its positions, so a
// file re-saved from that Blender has scrambled AO. A texel bake's glb (format v5 lightmap)
// opens with two UV maps and the occlusion texture where Blender's importer puts glTF's
// occlusionTexture — the Occlusion input of its "glTF Material Output" group node (Blender 3.4;
// "glTF Settings" in older add-ons) — fed by the embedded image on the second UV map (TEXCOORD_1),
// whose pixels are the AO codes, and every loop's second UV is the file's corner UV with v
// flipped (Blender's UV origin is the image's bottom-left). Needs `blender` on PATH (the ci
// preset requires it); skipped otherwise.
#include <formats/asset.h>

#include <gtest/gtest.h>
#include <run_tool.h>
#include <scratch.h>
#include <unit_box_obj.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <map>
#include <string>

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

TEST(BlenderRoundTrip, TexelBakedGlbShowsItsOcclusionOnTheSecondUvMap) {
#ifndef PRT_BLENDER
  GTEST_SKIP() << "blender is not installed (the ci preset requires it)";
#else
  const fs::path d = prt::testing::fresh_dir("blender", "lightmap");
  const fs::path obj = d / "floor_box.obj", bake = d / "floor_box.prt.h5", glb = d / "floor_box.glb";
  {
    // The floor [−2, 2]² (one UV chart over the whole atlas) around the unit box (no texels).
    std::ofstream out(obj);
    out << "v -2 -2 0\nv 2 -2 0\nv 2 2 0\nv -2 2 0\nvt 0 1\nvt 1 1\nvt 1 0\nvt 0 0\nvt 3 3\n";
    out << "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
    prt::testing::write_unit_box_obj(out, 5, 5);
  }
  auto r = run_tool(PRT_PRTBAKE, "texel '" + obj.string() + "' --resolution 16 --ao --integrator qmc --samples 16 --report 0 -q -o '" +
                                     bake.string() + "'", d);
  ASSERT_EQ(r.code, 0) << r.err;
  r = run_tool(PRT_PRTBAKE, "export '" + bake.string() + "' --to glb -o '" + glb.string() + "'", d);
  ASSERT_EQ(r.code, 0) << r.err;
  const fs::path held = d / "blender.json";
  r = run_tool(PRT_BLENDER, "-b --factory-startup --python '" + std::string(PRT_SOURCE_TESTS) +
                                "/tools/blender_roundtrip.py' -- '" + glb.string() + "' '" + held.string() + "'", d);
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  std::ifstream in(held);
  const nlohmann::json j = nlohmann::json::parse(in);
  RecordProperty("blender", j.at("blender").get<std::string>());
  ASSERT_EQ(j.at("meshes").size(), 1u);
  const nlohmann::json& mesh = j["meshes"][0];
  const prt::formats::Asset asset = prt::formats::read_asset(bake);
  const prt::formats::VertexSet& s = asset.vertices;
  ASSERT_TRUE(s.uv && s.lightmap && s.lightmap->ao);
  const prt::formats::Lightmap& m = *s.lightmap;

  // Two UV maps (TEXCOORD_0, TEXCOORD_1) and one occlusion texture on the second.
  const nlohmann::json& uv_layers = mesh.at("uv_layers");
  ASSERT_EQ(uv_layers.size(), 2u) << uv_layers;
  ASSERT_EQ(mesh.at("occlusion").size(), 1u) << "no occlusion input fed by an image";
  const nlohmann::json& occ = mesh["occlusion"][0];
  EXPECT_EQ(occ.at("uv_map"), uv_layers[1]) << "the occlusion texture reads the second UV map";
  EXPECT_EQ(occ.at("colorspace"), "Non-Color") << "AO is data, not colour";
  ASSERT_EQ(occ.at("size"), nlohmann::json({m.width, m.height}));
  // Blender's pixel rows run bottom-up: image row y is Blender row H − 1 − y. An 8-bit code c reads
  // as the float c/255: within float rounding (1e-6) of it.
  const nlohmann::json& red = occ.at("red");
  ASSERT_EQ(red.size(), m.texel_count());
  for (size_t y = 0; y < m.height; ++y)
    for (size_t x = 0; x < m.width; ++x) {
      const size_t k = y * m.width + x;
      const double code = std::lround(std::clamp(double(m.ao->values[k]), 0.0, 1.0) * 255.0);
      EXPECT_NEAR(red[(m.height - 1 - y) * m.width + x].get<double>() * 255, code, 1e-6 * 255) << "texel " << k;
    }
  // Every loop's second UV is its file corner's (u, 1 − v): the importer keeps the triangles in
  // order, one loop per corner; 1 − v is one float32 subtraction (within 1e-7 of the double).
  const nlohmann::json& uv1 = mesh.at("uvs")[1];
  ASSERT_EQ(uv1.size(), s.uv->values.size() / 2);
  for (size_t i = 0; i < uv1.size(); ++i) {
    EXPECT_EQ(uv1[i][0].get<float>(), s.uv->values[2 * i]) << "corner " << i;
    EXPECT_NEAR(uv1[i][1].get<double>(), 1.0 - double(s.uv->values[2 * i + 1]), 1e-7) << "corner " << i;
  }
#endif
}

} // namespace
