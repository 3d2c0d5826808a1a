// prtbake vertex on a mesh far from the origin: /mesh/positions is float64 and holds the file's
// positions (formats/SCHEMA.md, "Positions far from the origin"); an ordinary mesh still gets
// float32; prtdump shows either.
#include <formats/asset.h>
#include <formats/prtfile.h>

#include <gtest/gtest.h>
#include <run_tool.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <variant>
#include <vector>

namespace fs = std::filesystem;
namespace F = prt::formats;

namespace {

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(PRT_TEST_TMP) / "prtbake_far";
  fs::create_directories(dir);
  return dir / name;
}

// Bakes AO of `mesh` (silhouette, small k: only the positions matter here) and reads the file.
F::File bake(const fs::path& mesh) {
  const fs::path out = scratch(mesh.stem().string() + ".prt.h5");
  fs::remove(out);
  const auto run = prt::testing::run_tool(PRT_PRTBAKE, "vertex '" + mesh.string() + "' --ao --samples 64 --report 0 --quiet -o '" +
                                                           out.string() + "'",
                                          scratch("capture"));
  EXPECT_EQ(run.code, 0) << run.err;
  return F::read_file(out);
}

// A tetrahedron translated by (1e5, −2e5, 3e5) and 1e-4 in size, 17 significant digits, with a
// fifth vertex a quarter float ulp (2^-9; ulp(1e5) = 2^-7) from the first in x: float32 would
// move every vertex by up to 0.016 and merge vertices 0 and 4.
std::vector<double> far_positions() {
  const double t[3] = {1e5, -2e5, 3e5}, s = 1e-4;
  const double local[5][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, 0, 0}};
  std::vector<double> p;
  for (const auto& v : local)
    for (int k = 0; k < 3; ++k) p.push_back(t[k] + s * v[k]);
  p[12] += 0x1p-9;
  return p;
}

TEST(PrtbakeFar, FarMeshPositionsAreFloat64AndTheFilesOwn) {
  const std::vector<double> want = far_positions();
  const fs::path obj = scratch("far_tetra.obj");
  {
    std::ofstream out(obj);
    char buf[128];
    for (size_t v = 0; v < want.size() / 3; ++v) {
      std::snprintf(buf, sizeof buf, "v %.17g %.17g %.17g\n", want[3 * v], want[3 * v + 1], want[3 * v + 2]);
      out << buf;
    }
    out << "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\nf 5 2 3\n";
  }
  const F::File file = bake(obj);
  const F::Dataset* d = F::find_dataset(file, "/mesh/positions");
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(F::dtype_name(d->data), "float64");
  ASSERT_TRUE(std::holds_alternative<std::vector<double>>(d->data));
  const auto& got = std::get<std::vector<double>>(d->data);
  ASSERT_EQ(got.size(), want.size());
  // origin + float(x − origin) in double: here the offsets (<= 1e-4, multiples of the input's
  // 2^-37..2^-35 grid) are exact in float, so the file's doubles come back exactly.
  for (size_t i = 0; i < want.size(); ++i) EXPECT_EQ(got[i], want[i]) << i;
  EXPECT_NE(got[0], got[12]) << "vertices 0 and 4 stay two rows";

  // The asset model and prtdump read it.
  const F::Asset a = F::read_asset(scratch("far_tetra.prt.h5"));
  ASSERT_TRUE(a.vertices.positions);
  EXPECT_EQ(a.vertices.positions->values, want);
  const auto dump = prt::testing::run_tool(PRT_PRTDUMP, "'" + scratch("far_tetra.prt.h5").string() + "' --vertex 4",
                                           scratch("capture"));
  EXPECT_EQ(dump.code, 0) << dump.err;
  EXPECT_NE(dump.out.find("100000.001953125"), std::string::npos) << dump.out;
}

TEST(PrtbakeFar, OrdinaryMeshPositionsStayFloat32) {
  const F::File file = bake(fs::path(PRT_DATA_DIR) / "bunny.obj");
  const F::Dataset* d = F::find_dataset(file, "/mesh/positions");
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(F::dtype_name(d->data), "float32");
}

// `prtbake scene` with a ground (receiver) and the bunny on it (both), as given and moved far away
// by the same transform: the scene's one origin keeps receivers and occluders in one frame, so
// the ground's and the bunny's AO equal the near scene's within 1e-6 (why that bound:
// tests/bake/test_far_origin.cpp), and the far positions are float64.
TEST(PrtbakeFar, FarSceneTransformBakesTheNearScenesAo) {
  const fs::path data = PRT_DATA_DIR;
  auto bake_scene = [&](const std::string& name, const std::string& transform) {
    const fs::path scene = scratch(name + ".json"), out = scratch(name + ".prt.h5");
    std::ofstream(scene) << R"({"prtbake_scene": 1, "bake": {"products": ["ao"], "samples": 1024, "report": 0},
      "objects": [
        {"name": "ground", "mesh": ")" << (data / "ground.obj").string() << R"(", "role": "receiver", "transform": )" << transform << R"(},
        {"name": "bunny", "mesh": ")" << (data / "bunny.obj").string() << R"(", "role": "both", "transform": )" << transform << R"(}]})";
    fs::remove(out);
    const auto run = prt::testing::run_tool(PRT_PRTBAKE, "scene '" + scene.string() + "' --quiet -o '" + out.string() + "'",
                                            scratch("capture"));
    EXPECT_EQ(run.code, 0) << run.err;
    return F::read_asset(out);
  };
  const F::Asset near = bake_scene("near_scene", R"({"scale": 1})");
  const F::Asset far = bake_scene("far_scene", R"({"translate": [100000, -200000, 300000], "scale": 0.0001})");
  ASSERT_EQ(near.objects.size(), 2u);
  ASSERT_EQ(far.objects.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    SCOPED_TRACE(near.objects[i].name);
    ASSERT_TRUE(near.objects[i].set.ao && far.objects[i].set.ao);
    const auto& a = near.objects[i].set.ao->values;
    const auto& b = far.objects[i].set.ao->values;
    ASSERT_EQ(a.size(), b.size());
    for (size_t v = 0; v < a.size(); ++v) ASSERT_NEAR(a[v], b[v], 1e-6) << "vertex " << v;
    // World positions: the near ones moved by the transform, up to the float rounding of the
    // offsets from the scene origin (at most half the scene's extent, 40 × 1e-4 / 2, times
    // 2^-24) and the double rounding of the sums (2^-52 × 3e5).
    const auto& p = near.objects[i].set.positions->values;
    const auto& q = far.objects[i].set.positions->values;
    const double shift[3] = {1e5, -2e5, 3e5}, tolerance = 2e-3 * 0x1p-24 + 3e5 * 0x1p-52;
    for (size_t k = 0; k < p.size(); ++k) ASSERT_NEAR(q[k], shift[k % 3] + 1e-4 * p[k], tolerance) << k;
  }
}

} // namespace
