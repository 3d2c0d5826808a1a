// Surface-following FIV shells in the baked file (format_version 7; formats/asset.h Occluder,
// SCHEMA.md "Surface-following shells"): radial_scheme "surface", first_offset and the
// surface_radius [Ntheta][Nphi] dataset survive write -> read; such a file is written as version 7
// and a file without them keeps its old version (an occluder without radial_scheme is the
// geometric scheme, as every version-4..6 file); validate() refuses the data in a version-6 file, a
// surface scheme without its surface_radius (or the other way round), an unknown scheme name, a
// surface_radius of the wrong shape, negative or non-finite, and non-increasing offsets.
#include <formats/asset.h>
#include <formats/names.h>
#include <formats/testing.h>

#include <fiv_asset.h>
#include <gtest/gtest.h>
#include <schema_refusal.h>

#include <filesystem>
#include <limits>

namespace fs = std::filesystem;
using namespace prt::formats;
using prt::testing::dataset;
using prt::testing::expect_refused;
using prt::testing::with_version;

namespace {

Asset fiv_asset(bool surface) {
  Asset a = prt::testing::small_fiv_asset(0.5f, 2, {0.01, 0.04}, "0: extrapolated");
  Occluder& o = a.occluders.front();
  if (surface) {
    o.radial_scheme = "surface";
    o.first_offset = 0.005;
    o.surface_radius = OccluderSurfaceRadius{{1.5f, 1.25f, 1, 0.5f, 0, 2}, "r_surf", {}};
  }
  return a;
}

} // namespace

TEST(AssetSurfaceShells, SurviveWriteReadAsVersion7AndOldOccludersKeepTheirVersion) {
  const fs::path dir = fs::path(PRT_TEST_TMP) / "asset_surface_shells";
  fs::create_directories(dir);
  const Asset a = fiv_asset(true);
  write_asset(dir / "surface.prt.h5", a);
  const Asset b = read_asset(dir / "surface.prt.h5");
  EXPECT_EQ(b.root.format_version, 7);
  ASSERT_EQ(b.occluders.size(), 1u);
  EXPECT_EQ(b.occluders[0], a.occluders[0]);
  EXPECT_EQ(b.occluders[0].radial_scheme, "surface");
  // A geometric occluder (no attribute): the version it had before version 7 existed.
  write_asset(dir / "geometric.prt.h5", fiv_asset(false));
  const Asset g = read_asset(dir / "geometric.prt.h5");
  EXPECT_EQ(g.root.format_version, kFormatVersionWithoutLightmaps);
  EXPECT_FALSE(g.occluders[0].radial_scheme.has_value());
  EXPECT_FALSE(g.occluders[0].surface_radius.has_value());
  // "geometric" spelled out is allowed (version 7).
  Asset spelled = fiv_asset(false);
  spelled.occluders[0].radial_scheme = "geometric";
  write_asset(dir / "spelled.prt.h5", spelled);
  EXPECT_EQ(read_asset(dir / "spelled.prt.h5").root.format_version, 7);
}

TEST(AssetSurfaceShells, ValidateRefusesBrokenSurfaceShells) {
  const File good = to_file(fiv_asset(true));
  expect_refused(with_version(good, 6), "needs format_version 7 (the file says 6)");
  {
    File f = good;
    std::erase_if(f.datasets, [](const Dataset& d) { return d.path == "/fiv/occluders/bunny/surface_radius"; });
    expect_refused(f, "has radial_scheme \"surface\" but no '/fiv/occluders/bunny/surface_radius'");
  }
  {
    File f = good;
    for (Attr& at : dataset(f, "/fiv/occluders/bunny/shells").attrs)
      if (at.name == names::kRadialScheme) at.value = std::string("geometric");
    expect_refused(f, "needs radial_scheme \"surface\"");
  }
  {
    File f = good;
    for (Attr& at : dataset(f, "/fiv/occluders/bunny/shells").attrs)
      if (at.name == names::kRadialScheme) at.value = std::string("spherical");
    expect_refused(f, "must be the string \"geometric\" or \"surface\"");
  }
  {
    File f = good;
    Dataset& d = dataset(f, "/fiv/occluders/bunny/surface_radius");
    d.shape = {3, 2};
    expect_refused(f, "[Ntheta, Nphi] of its shells");
  }
  {
    File f = good;
    std::get<std::vector<float>>(dataset(f, "/fiv/occluders/bunny/surface_radius").data)[4] = -0.5f;
    expect_refused(f, "must hold finite distances >= 0");
    std::get<std::vector<float>>(dataset(f, "/fiv/occluders/bunny/surface_radius").data)[4] =
        std::numeric_limits<float>::infinity();
    expect_refused(f, "has a non-finite value (Inf) at index 4");  // every float dataset's rule
  }
  {
    File f = good;
    for (Attr& at : dataset(f, "/fiv/occluders/bunny/shells").attrs)
      if (at.name == names::kRadii) at.value = std::vector<double>{0.04, 0.01};
    expect_refused(f, "(offsets from the surface) must be finite, > 0 and increasing");
  }
}
