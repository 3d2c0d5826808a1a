// prtbake texel end to end (tools/prtbake/run_texel.cpp): an OBJ floor with lightmap UVs (vt)
// and a box standing on it, baked per texel, read back through the asset model (format v5).
// The floor texels outside the box's foot hold the closed-form AO of
// tests/bake/bake/test_texel_bake.cpp (silhouette at N = 1536: within 1e-4 there; plus the
// float32 of the file, 6e-8); the 8 × 8 under the box are inside it and filled; /lightmap/positions are the
// texel centres on the floor; /mesh/uv is the file's vt (v flipped to glTF's convention).
// Mistakes about UVs exit 1 naming the file.
#include <formats/asset.h>

#include <gtest/gtest.h>
#include <run_tool.h>
#include <unit_box_ao.h>
#include <unit_box_obj.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

namespace fs = std::filesystem;
namespace F = prt::formats;
using prt::testing::ao_closed_form;
using prt::testing::Vector3d;

namespace {

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(PRT_TEST_TMP) / "prtbake_texel";
  fs::create_directories(dir);
  return dir / name;
}

// The floor [−2, 2]² at z = 0 with vt ((x + 2)/4, 1 − (y + 2)/4) (so glTF-convention v = (y + 2)/4),
// and the unit box [−½, ½]² × [0, 1] on it, its corners at vt (3, 3): outside the atlas, so it
// occludes and has no texels.
fs::path floor_and_box() {
  const fs::path obj = scratch("floor_box.obj");
  std::ofstream out(obj);
  out << "v -2 -2 0\nv 2 -2 0\nv 2 2 0\nv -2 2 0\n";
  out << "vt 0 1\nvt 1 1\nvt 1 0\nvt 0 0\nvt 3 3\n";
  out << "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
  prt::testing::write_unit_box_obj(out, 5, 5);
  return obj;
}

} // namespace

TEST(PrtbakeTexel, AFloorAroundABoxBakesToTheClosedFormPerTexel) {
  const fs::path obj = floor_and_box(), out = scratch("floor_box.prt.h5");
  fs::remove(out);
  const auto run = prt::testing::run_tool(PRT_PRTBAKE,
                                          "texel '" + obj.string() + "' --resolution 32 --ao --integrator silhouette "
                                          "--samples 2359296 --report 0 --padding 0 -o '" + out.string() + "'",
                                          scratch("capture"));
  ASSERT_EQ(run.code, 0) << run.err;
  EXPECT_NE(run.out.find("lightmap: 32x32 texels in UV set vt: 1024 covered"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("64 inside the geometry"), std::string::npos) << run.out;
  const F::Asset a = F::read_asset(out);
  EXPECT_EQ(a.root.format_version, 5);
  ASSERT_TRUE(a.vertices.uv && a.vertices.lightmap);
  EXPECT_EQ(a.vertices.uv->uv_set, "vt");
  ASSERT_EQ(a.vertices.uv->values.size(), 14u * 3 * 2);
  EXPECT_EQ(a.vertices.uv->values[1], 0.0f) << "vt v = 1 is glTF v = 0";
  const F::Lightmap& m = *a.vertices.lightmap;
  ASSERT_EQ(m.width, 32u);
  ASSERT_EQ(m.height, 32u);
  ASSERT_TRUE(m.ao && m.positions);
  size_t filled = 0;
  for (size_t k = 0; k < 32 * 32; ++k) {
    // Texel (x, y) is centred at u = (x + ½)/32, v = (y + ½)/32: x = 4u − 2, y = 4v − 2 on the floor.
    const Vector3d centre(4 * (double(k % 32) + 0.5) / 32 - 2, 4 * (double(k / 32) + 0.5) / 32 - 2, 0);
    const bool under = std::abs(centre.x()) < 0.5 && std::abs(centre.y()) < 0.5;
    EXPECT_EQ(m.state.values[k], under ? 2 : 1) << "texel " << k;
    filled += m.state.values[k] == 2;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(m.positions->values[3 * k + size_t(c)], centre[c], 1e-6) << "texel " << k;
    if (!under) {
      EXPECT_NEAR(m.ao->values[k], ao_closed_form(centre), 1e-4 + 6e-8) << "texel " << k;
    }
  }
  EXPECT_EQ(filled, 64u);
}

TEST(PrtbakeTexel, UvMistakesExit1NamingTheFile) {
  const fs::path out = scratch("x.prt.h5");
  const std::string bunny = std::string(PRT_DATA_DIR) + "/bunny.obj";
  auto run = prt::testing::run_tool(PRT_PRTBAKE, "texel '" + bunny + "' --resolution 16 --ao --samples 64 -o '" + out.string() + "'",
                                    scratch("capture"));
  EXPECT_EQ(run.code, 1) << "the bunny has no UVs: generated ones do not fit 16 x 16 with their gutters";
  EXPECT_NE(run.err.find(" charts do not fit in 16x16 texels even at one texel each plus the gutter of 2"),
            std::string::npos)
      << run.err;
  EXPECT_NE(run.err.find("bunny.obj: "), std::string::npos) << run.err;
  // spider.obj's vt is a texture set that reuses parts: an error that names the cure.
  run = prt::testing::run_tool(PRT_PRTBAKE,
                               "texel '" + std::string(PRT_DATA_DIR) + "/spider.obj' --resolution 64 --ao --samples 64 -o '" +
                                   out.string() + "'",
                               scratch("capture"));
  EXPECT_EQ(run.code, 1);
  EXPECT_NE(run.err.find("spider.obj: its UV set vt overlaps itself: "), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("prtbake texel --unwrap"), std::string::npos) << run.err;
  // wuson.obj's vt is one repeated (0, 0): a set, but no lightmap.
  run = prt::testing::run_tool(PRT_PRTBAKE,
                               "texel '" + std::string(PRT_DATA_DIR) + "/wuson.obj' --resolution 16 --ao --samples 64 -o '" +
                                   out.string() + "'",
                               scratch("capture"));
  EXPECT_EQ(run.code, 1);
  EXPECT_NE(run.err.find("wuson.obj: its UV set vt covers no texel of the 16x16 lightmap: every triangle has zero area"),
            std::string::npos)
      << run.err;
  const fs::path obj = floor_and_box();
  run = prt::testing::run_tool(PRT_PRTBAKE,
                               "texel '" + obj.string() + "' --uv TEXCOORD_1 --resolution 16 --ao --samples 64 -o '" +
                                   out.string() + "'",
                               scratch("capture"));
  EXPECT_EQ(run.code, 1);
  EXPECT_NE(run.err.find("has no UV set 'TEXCOORD_1' (it has vt)"), std::string::npos) << run.err;
  run = prt::testing::run_tool(PRT_PRTBAKE, "texel '" + obj.string() + "' --resolution 0 --ao -o '" + out.string() + "'",
                               scratch("capture"));
  EXPECT_EQ(run.code, 2) << "a command-line mistake";
  run = prt::testing::run_tool(PRT_PRTBAKE, "texel '" + obj.string() + "' --ao -o '" + out.string() + "'", scratch("capture"));
  EXPECT_EQ(run.code, 2) << "no size";
  EXPECT_NE(run.err.find("give --resolution N|WxH (texels) or --density T"), std::string::npos) << run.err;
  EXPECT_FALSE(fs::exists(out));
}

// A mesh without UVs (the bunny) gets generated lightmap UVs (bake/mesh/unwrap.h), said in one
// line on stderr, stored as /mesh/uv under their name; --density picks the atlas; --unwrap
// replaces an asset's own set.
TEST(PrtbakeTexel, AMeshWithoutUvsBakesInGeneratedOnes) {
  const fs::path out = scratch("bunny_unwrapped.prt.h5");
  const std::string bunny = std::string(PRT_DATA_DIR) + "/bunny.obj";
  fs::remove(out);
  auto run = prt::testing::run_tool(PRT_PRTBAKE,
                                    "texel '" + bunny + "' --resolution 64 --ao --integrator qmc --samples 16 --report 0 -o '" +
                                        out.string() + "'",
                                    scratch("capture"));
  ASSERT_EQ(run.code, 0) << run.err;
  EXPECT_NE(run.err.find("bunny.obj: no UV set: generated lightmap UVs prtbake_lightmap: "), std::string::npos) << run.err;
  EXPECT_NE(run.err.find(" charts, utilisation "), std::string::npos) << run.err;
  EXPECT_NE(run.out.find("lightmap: 64x64 texels in UV set prtbake_lightmap"), std::string::npos) << run.out;
  F::Asset a = F::read_asset(out);
  ASSERT_TRUE(a.vertices.uv && a.vertices.lightmap);
  EXPECT_EQ(a.vertices.uv->uv_set, "prtbake_lightmap");
  ASSERT_EQ(a.vertices.uv->values.size(), 3674u * 3 * 2) << "every triangle of the bunny has its three UVs";
  for (float v : a.vertices.uv->values) {
    EXPECT_GE(v, 0.0f);
    EXPECT_LE(v, 1.0f);
  }
  EXPECT_EQ(a.vertices.lightmap->width, 64u);
  // --density: texels per unit; the atlas is the smallest square (a multiple of 4) that holds the charts.
  run = prt::testing::run_tool(PRT_PRTBAKE,
                               "texel '" + bunny + "' --density 10 --ao --integrator qmc --samples 16 --report 0 -o '" +
                                   out.string() + "'",
                               scratch("capture"));
  ASSERT_EQ(run.code, 0) << run.err;
  a = F::read_asset(out);
  ASSERT_TRUE(a.vertices.lightmap);
  EXPECT_EQ(a.vertices.lightmap->width % 4, 0u);
  EXPECT_EQ(a.vertices.lightmap->width, a.vertices.lightmap->height);
  EXPECT_NE(run.err.find("at 10 texels per unit"), std::string::npos) << run.err;
  // --density with the asset's own set: the floor's vt maps 4 × 4 units onto [0, 1]² (the box's
  // corners all at vt (3, 3) map no area and do not count), so 8 texels per unit is 32 × 32.
  run = prt::testing::run_tool(PRT_PRTBAKE,
                               "texel '" + floor_and_box().string() +
                                   "' --density 8 --ao --integrator qmc --samples 16 --report 0 -o '" + out.string() + "'",
                               scratch("capture"));
  ASSERT_EQ(run.code, 0) << run.err;
  EXPECT_NE(run.out.find("lightmap: 32x32 texels in UV set vt"), std::string::npos) << run.out;
  // --unwrap replaces the floor's own vt.
  run = prt::testing::run_tool(PRT_PRTBAKE,
                               "texel '" + floor_and_box().string() +
                                   "' --unwrap --resolution 64 --ao --integrator qmc --samples 16 --report 0 -o '" +
                                   out.string() + "'",
                               scratch("capture"));
  ASSERT_EQ(run.code, 0) << run.err;
  EXPECT_NE(run.err.find("--unwrap: generated lightmap UVs prtbake_lightmap"), std::string::npos) << run.err;
  a = F::read_asset(out);
  ASSERT_TRUE(a.vertices.uv);
  EXPECT_EQ(a.vertices.uv->uv_set, "prtbake_lightmap");
}

// A ring of triangles whose corner at φ = π/2 has x = 0.6 cos(π/2) = 3.7e-17 beside corners of
// x = ±0.42: a texel on an edge from it cannot be put exactly on its triangle (no double lies on
// that segment but its ends; bake/mesh/texels.h), and the rounded point may lie behind its own
// triangle and see it from behind (AO exactly 0 in this open bowl). Such texels are lifted a few
// roundings in front of their triangles instead: the log says how many, nothing is warned, and
// no texel of the bowl is black (each sees the bowl's opening, a quarter of its hemisphere or
// more: with 16 QMC rays the AO of a texel seeing it cannot be 0).
TEST(PrtbakeTexel, TexelsThatCannotLieExactlyOnTheirTrianglesAreLiftedInFront) {
  const fs::path obj = scratch("noisy_ring.obj"), out = scratch("noisy_ring.prt.h5");
  {
    std::ofstream f(obj);
    f.precision(17);
    const double pi = std::acos(-1.0);
    for (int i = 0; i < 8; ++i)
      f << "v " << 0.6 * std::cos(2 * pi * i / 8) << " " << 0.6 * std::sin(2 * pi * i / 8) << " 0.8\n";
    f << "v 0 0 0.2\n";
    for (int i = 0; i < 8; ++i) f << "f " << i + 1 << " 9 " << (i + 1) % 8 + 1 << "\n";
  }
  const auto run = prt::testing::run_tool(
      PRT_PRTBAKE, "texel '" + obj.string() + "' --resolution 64 --ao --integrator qmc --samples 16 --report 0 -o '" +
                       out.string() + "'",
      scratch("capture"));
  ASSERT_EQ(run.code, 0) << run.err;
  EXPECT_EQ(run.err.find("warning"), std::string::npos) << run.err;
  const size_t at = run.out.find(" texels lie a few roundings in front of their triangles");
  ASSERT_NE(at, std::string::npos) << run.out;
  const size_t from = run.out.rfind("lightmap: ", at) + std::string("lightmap: ").size();
  EXPECT_GT(std::stoul(run.out.substr(from, at - from)), 0u) << run.out;
  const F::Asset a = F::read_asset(out);
  ASSERT_TRUE(a.vertices.lightmap && a.vertices.lightmap->ao);
  const auto& ao = a.vertices.lightmap->ao->values;
  const auto& state = a.vertices.lightmap->state.values;  // 1: baked
  size_t black = 0, covered = 0;
  for (size_t k = 0; k < state.size(); ++k)
    if (state[k] == 1) ++covered, black += ao[k] <= 0;
  EXPECT_GT(covered, 100u);
  EXPECT_EQ(black, 0u) << "of " << covered << " covered texels";
}
