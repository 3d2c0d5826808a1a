// Half-float FIV tables in the baked file (format_version 8; formats/asset.h Occluder::float16 and
// OccluderCones::float16, SCHEMA.md "/fiv/occluders/<name>/shells"): the writer rounds the values
// to binary16 (to nearest even, Imath::half) and stores dtype float16; the reader gives the halves
// back as floats and says so; such a file is version 8 and only then; the schema refuses float16
// anywhere else, in an older version, and non-finite halves.
#include <formats/asset.h>
#include <formats/names.h>
#include <formats/testing.h>

#include <fiv_asset.h>
#include <gtest/gtest.h>
#include <schema_refusal.h>

#include <cmath>
#include <filesystem>

namespace fs = std::filesystem;
using namespace prt::formats;
using prt::testing::expect_refused;

namespace {

// An FIV asset with a cone table, its values not halves (the writer rounds them).
Asset half_asset() {
  Asset a = prt::testing::small_fiv_asset(0.1f, 1.5, {1.5, 3}, "0: inside");
  Occluder& o = a.occluders.front();
  for (std::size_t i = 0; i < o.shells.size(); ++i) o.shells[i] = 0.1f * float(i) - 3.0f;  // 0.1 is no half
  o.shells[7] = 1e-6f;  // a subnormal half: 2^-24 · 17 (the nearest)
  o.float16 = true;
  o.cones = OccluderCones{std::vector<float>(12 * 4, 0.3f), "(m, Omega)", {}, true};
  o.proxy = "cone";
  return a;
}

const Dataset& dataset(const File& f, const std::string& path) {
  const Dataset* d = find_dataset(f, path);
  EXPECT_NE(d, nullptr) << path;
  return *d;
}

} // namespace

TEST(AssetFloat16, ToFloat16RoundsToNearestEvenAndToFloatIsExact) {
  EXPECT_EQ(to_float16(1.0f).bits, 0x3c00);
  EXPECT_EQ(to_float16(65504.0f).bits, 0x7bff);
  EXPECT_EQ(to_float16(0x1p-24f).bits, 0x0001);                 // the smallest subnormal
  EXPECT_EQ(to_float16(1.0f + 0x1p-11f).bits, 0x3c00);          // a tie: to the even mantissa
  EXPECT_EQ(to_float16(1.0f + 3 * 0x1p-11f).bits, 0x3c02);      // a tie: to the even mantissa
  EXPECT_EQ(to_float(Float16{0x8000}), -0.0f);
  EXPECT_TRUE(std::signbit(to_float(Float16{0x8000})));
  EXPECT_EQ(to_float(Float16{0x03ff}), 1023 * 0x1p-24f);
}

TEST(AssetFloat16, SurviveWriteReadRoundedAsVersion8) {
  const fs::path dir = fs::path(PRT_TEST_TMP) / "asset_float16";
  fs::create_directories(dir);
  const Asset a = half_asset();
  write_asset(dir / "a.prt.h5", a);
  const File f = read_file(dir / "a.prt.h5");
  EXPECT_EQ(dtype_name(dataset(f, "/fiv/occluders/bunny/shells").data), "float16");
  EXPECT_EQ(dtype_name(dataset(f, "/fiv/occluders/bunny/cones").data), "float16");
  EXPECT_EQ(dtype_name(dataset(f, "/fiv/occluders/bunny/valid").data), "uint8");
  const Asset b = read_asset(dir / "a.prt.h5");
  EXPECT_EQ(b.root.format_version, kFormatVersionWithHalfShells);
  ASSERT_EQ(b.occluders.size(), 1u);
  const Occluder& o = b.occluders[0];
  EXPECT_TRUE(o.float16);
  ASSERT_TRUE(o.cones.has_value());
  EXPECT_TRUE(o.cones->float16);
  ASSERT_EQ(o.shells.size(), a.occluders[0].shells.size());
  for (std::size_t i = 0; i < o.shells.size(); ++i) {
    const float v = a.occluders[0].shells[i];
    EXPECT_EQ(o.shells[i], to_float(to_float16(v))) << i;
    // Rounding to nearest: within half a half-ulp, 2^-11 of the value (2^-25 below 2^-14).
    EXPECT_LE(std::fabs(o.shells[i] - v), std::max(std::fabs(v) * 0x1p-11f, 0x1p-25f)) << i;
  }
  EXPECT_EQ(o.shells[7], 17 * 0x1p-24f);
  EXPECT_EQ(o.cones->values.front(), to_float(to_float16(0.3f)));
  // A second write of what was read keeps the values (they are halves now).
  write_asset(dir / "b.prt.h5", b);
  EXPECT_EQ(read_asset(dir / "b.prt.h5").occluders[0], b.occluders[0]);
  // float32 shells beside a float16 cone table, and the other way round.
  Asset mixed = half_asset();
  mixed.occluders[0].float16 = false;
  write_asset(dir / "c.prt.h5", mixed);
  const Asset c = read_asset(dir / "c.prt.h5");
  EXPECT_FALSE(c.occluders[0].float16);
  EXPECT_EQ(c.occluders[0].shells, mixed.occluders[0].shells);
  EXPECT_TRUE(c.occluders[0].cones->float16);
  // Without float16 anywhere the file keeps version 7 (cones) as before.
  Asset plain = half_asset();
  plain.occluders[0].float16 = false;
  plain.occluders[0].cones->float16 = false;
  write_asset(dir / "d.prt.h5", plain);
  EXPECT_EQ(read_asset(dir / "d.prt.h5").root.format_version, kFormatVersionWithCones);
}

TEST(AssetFloat16, ValidateRefusesFloat16ElsewhereInOlderFilesAndNonFinite) {
  const File good = to_file(half_asset());
  EXPECT_NO_THROW(validate(good, "good.prt.h5"));
  {
    File f = good;
    f.root_attrs.push_back({std::string(names::kFormatVersion), int64_t{7}});
    expect_refused(f, "is float16, which needs format_version 8 (the file says 7)");
  }
  {
    File f = good;
    for (Dataset& d : f.datasets)
      if (d.path == "/fiv/occluders/bunny/shells") std::get<std::vector<Float16>>(d.data)[4] = Float16{0x7c00};
    expect_refused(f, "has a non-finite value (Inf) at index 4");
  }
  {
    File f = good;
    for (Dataset& d : f.datasets)
      if (d.path == "/fiv/occluders/bunny/cones") std::get<std::vector<Float16>>(d.data)[0] = Float16{0x7e00};
    expect_refused(f, "has a non-finite value (NaN) at index 0");
  }
  {
    File f = good;
    Dataset& env = f.datasets.emplace_back();
    env.path = "/fiv/environment";
    env.shape = {3, 3};
    env.data = std::vector<Float16>(9, Float16{0x3c00});
    expect_refused(f, "is float16, which the schema allows only for an occluder's shells and cones");
  }
}
