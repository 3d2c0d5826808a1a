// FIV cone tables in the baked file (format_version 7; formats/asset.h OccluderCones, SCHEMA.md
// "/fiv/occluders/<name>/cones"): the dataset and the group attribute `proxy` survive a write and a
// read; a file is written as version 7 only when it holds them (an FIV file without keeps version
// 4); the schema refuses them in an older version, a `proxy` other than "sphere" or "cone", "cone"
// without a table, and a table whose grid is not its shells'.
#include <formats/asset.h>
#include <formats/names.h>
#include <formats/testing.h>

#include <fiv_asset.h>
#include <gtest/gtest.h>
#include <schema_refusal.h>

#include <filesystem>

namespace fs = std::filesystem;
using namespace prt::formats;
using prt::testing::expect_refused;

namespace {

Asset fiv_asset() {
  Asset a = prt::testing::small_fiv_asset(0.25f, 1.5, {1.5, 3}, "0: inside");
  Occluder& o = a.occluders.front();
  o.cones = OccluderCones{std::vector<float>(12 * 4, 0.5f), "(m, Omega)", {}};
  o.proxy = "cone";
  return a;
}

std::vector<Attr>* occluder_group(File& f) {
  for (auto& [g, attrs] : f.group_attrs)
    if (g == "/fiv/occluders/bunny") return &attrs;
  return nullptr;
}

} // namespace

TEST(AssetCones, SurviveWriteReadAsVersion7AndOlderFilesStayAsTheyWere) {
  const fs::path dir = fs::path(PRT_TEST_TMP) / "asset_cones";
  fs::create_directories(dir);
  Asset a = fiv_asset();
  a.group_extras = {{"/fiv/occluders/bunny", {{"mesh", std::string("bunny.obj")}}}};  // beside the proxy
  write_asset(dir / "a.prt.h5", a);
  const Asset b = read_asset(dir / "a.prt.h5");
  EXPECT_EQ(b.root.format_version, 7);
  ASSERT_EQ(b.occluders.size(), 1u);
  EXPECT_EQ(b.occluders[0], a.occluders[0]);
  EXPECT_EQ(b.group_extras, a.group_extras);
  // Without cones and proxy (what every file before version 7 holds): version 4, no proxy.
  Asset old = fiv_asset();
  old.occluders[0].cones.reset();
  old.occluders[0].proxy.reset();
  write_asset(dir / "old.prt.h5", old);
  const Asset c = read_asset(dir / "old.prt.h5");
  EXPECT_EQ(c.root.format_version, kFormatVersionWithoutLightmaps);
  EXPECT_FALSE(c.occluders[0].proxy.has_value());
  EXPECT_FALSE(c.occluders[0].cones.has_value());
}

TEST(AssetCones, ValidateRefusesBadConesAndProxies) {
  const File good = to_file(fiv_asset());
  {
    File f = good;
    f.root_attrs.push_back({std::string(names::kFormatVersion), int64_t{6}});
    expect_refused(f, "is an occluder's cone table, which needs format_version 7 (the file says 6)");
  }
  {
    File f = good;
    std::vector<Attr>* group = occluder_group(f);
    ASSERT_TRUE(group != nullptr && !group->empty());
    group->front().value = std::string("box");
    expect_refused(f, "must be the string \"sphere\" or \"cone\"");
  }
  {
    File f = good;
    std::erase_if(f.datasets, [](const Dataset& d) { return d.path == "/fiv/occluders/bunny/cones"; });
    expect_refused(f, "says proxy \"cone\" but has no 'cones' dataset");
  }
  {
    File f = good;
    for (Dataset& d : f.datasets)
      if (d.path == "/fiv/occluders/bunny/cones") d.shape = {2, 2, 3, 3}, std::get<std::vector<float>>(d.data).resize(36);
    expect_refused(f, "/fiv/occluders/bunny/cones");
  }
  {
    File f = good;
    f.group_attrs.push_back({"/fiv", {{std::string(names::kProxy), std::string("cone")}}});
    expect_refused(f, "only /fiv/occluders/<name> has one");
  }
}
