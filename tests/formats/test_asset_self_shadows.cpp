// A scene file's FIV occluder self-shadows (format_version 9; formats/asset.h OccluderSelfBand1,
// SCHEMA.md "/fiv/occluders/<name>/self_band1"): [V, 3, 3] float32 beside the occluder's shells,
// V the rows of the scene object of the same name; read back as written; such a file is version 9
// and only then; the schema refuses it in an older version, without its object, its normals or its
// shells, with the wrong V, in float64, and non-finite.
#include <formats/asset.h>
#include <formats/names.h>
#include <formats/testing.h>

#include <fiv_asset.h>
#include <gtest/gtest.h>
#include <schema_refusal.h>

#include <cmath>
#include <filesystem>
#include <limits>

namespace fs = std::filesystem;
using namespace prt::formats;
using prt::testing::dataset;
using prt::testing::expect_refused;
using prt::testing::with_version;

namespace {

constexpr std::size_t kV = 4;

// A scene with one object "bunny" (4 vertices, normals) that is also an FIV occluder with
// self-shadows; the root layout has no vertex set.
Asset scene_asset() {
  Asset a = prt::testing::small_fiv_asset(0.1f, 1.5, {1.5, 3}, "0: inside");
  a.root.command_line = "prtbake scene s.json";
  a.scene.emplace().scene_file = "s.json";
  SceneObject& o = a.objects.emplace_back();
  o.name = "bunny";
  o.role = "occluder";
  o.mesh = "bunny.obj";
  o.mesh_sha256 = std::string(64, 'f');
  std::vector<double> p;
  for (std::size_t v = 0; v < kV; ++v) p.insert(p.end(), {double(v), 0.5 * double(v), 1.0});
  o.set.positions = Array<double>{p, {}};
  o.set.normals = Normals{std::vector<float>(3 * kV, 0.0f), "file", {}};
  for (std::size_t v = 0; v < kV; ++v) o.set.normals->values[3 * v + 1] = 1;
  o.set.triangles = Array<uint32_t>{{0, 1, 2, 0, 2, 3}, {}};
  std::vector<float> r(kV * 9);
  for (std::size_t i = 0; i < r.size(); ++i) r[i] = 0.125f * float(i) - 1.0f;
  a.occluders[0].self_band1 = OccluderSelfBand1{r, "band-1 radiance of the occluder alone", {}};
  return a;
}

TEST(AssetSelfShadows, RoundTripAsVersion9) {
  const fs::path dir = fs::path(PRT_TEST_TMP) / "asset_self_shadows";
  fs::create_directories(dir);
  const Asset a = scene_asset();
  write_asset(dir / "a.prt.h5", a);
  const File f = read_file(dir / "a.prt.h5");
  const Dataset* d = find_dataset(f, "/fiv/occluders/bunny/self_band1");
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->shape, (std::vector<uint64_t>{kV, 3, 3}));
  const Asset b = read_asset(dir / "a.prt.h5");
  EXPECT_EQ(b.root.format_version, kFormatVersionWithSelfShadows);
  ASSERT_EQ(b.occluders.size(), 1u);
  ASSERT_TRUE(b.occluders[0].self_band1.has_value());
  EXPECT_EQ(*b.occluders[0].self_band1, *a.occluders[0].self_band1);
  // Without it, the same file is version 6 or older, as before.
  Asset plain = scene_asset();
  plain.occluders[0].self_band1.reset();
  write_asset(dir / "b.prt.h5", plain);
  EXPECT_LT(read_asset(dir / "b.prt.h5").root.format_version, 7);
}

TEST(AssetSelfShadows, ValidateRefusesItWhereItCannotBeRead) {
  const File good = to_file(scene_asset());
  EXPECT_NO_THROW(validate(good, "good.prt.h5"));
  expect_refused(with_version(good, 8), "is an occluder's self-shadows, which needs format_version 9 (the file says 8)");
  {
    File f = good;
    std::erase_if(f.datasets, [](const Dataset& d) { return d.path.starts_with("/objects/bunny/"); });
    expect_refused(f, "holds the self-shadows of scene object 'bunny', but the file has no /objects/bunny/mesh/positions");
  }
  {
    File f = good;
    std::erase_if(f.datasets, [](const Dataset& d) { return d.path == "/objects/bunny/mesh/normals"; });
    expect_refused(f, "needs /objects/bunny/mesh/normals");
  }
  {
    File f = good;
    std::erase_if(f.datasets, [](const Dataset& d) { return d.path == "/fiv/occluders/bunny/shells"; });
    expect_refused(f, "has no 'shells' dataset beside it");
  }
  {
    File f = good;
    Dataset& d = dataset(f, "/fiv/occluders/bunny/self_band1");
    d.shape = {kV - 1, 3, 3};
    std::get<std::vector<float>>(d.data).resize((kV - 1) * 9);
    expect_refused(f, "[V, 3 (RGB), 3 (m)] with V = rows of /objects/bunny/mesh/positions");
  }
  {
    File f = good;
    Dataset& d = dataset(f, "/fiv/occluders/bunny/self_band1");
    const auto& v = std::get<std::vector<float>>(d.data);
    d.data = std::vector<double>(v.begin(), v.end());
    expect_refused(f, "/fiv/occluders/bunny/self_band1");
  }
  {
    File f = good;
    std::get<std::vector<float>>(dataset(f, "/fiv/occluders/bunny/self_band1").data)[5] =
        std::numeric_limits<float>::quiet_NaN();
    expect_refused(f, "has a non-finite value (NaN) at index 5");
  }
}

}  // namespace
