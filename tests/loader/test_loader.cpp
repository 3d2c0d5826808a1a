// Tests of prtshade/loader.h (prt::prtshade_hdf5): a file written by the real writer comes back as
// the same arrays, its views shade exactly like views of the original arrays, scene objects (v2)
// are separate vertex sets, broken occluder data is refused with a message naming the file, and a
// file annotated with h5py (variable-length strings) loads with its notes.
#include <prtshade/loader.h>
#include <prtshade/shade.h>

#include <formats/prtfile.h>
#include <formats/testing.h>

#include <byte_flips.h>
#include <h5py.h>
#include <hdf5_bytes.h>
#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace {

using prt::formats::Attr;
using prt::formats::Dataset;
using prt::formats::File;

std::filesystem::path tmp(const std::string& name) { return std::filesystem::path(PRT_TEST_TMP) / name; }

std::vector<float> ramp(size_t n, float scale) {
  std::vector<float> v(n);
  for (size_t k = 0; k < n; ++k) v[k] = scale * float(k % 97) - 1.0f;
  return v;
}

File make_file(bool with_object) {
  File f;
  f.root_attrs = {{"generator", std::string("test_loader")},
                  {"created", std::string("2024-01-02T03:04:05Z")},
                  {"command_line", std::string("test_loader")},
                  {"source", std::string("synthetic")},
                  {"source_sha256", std::string(64, 'b')},
                  {"up_axis", std::string("y")},
                  {"sh_convention", std::string("real orthonormal, i = l(l+1)+m, Condon-Shortley")}};
  const uint64_t V = 3;
  f.datasets.push_back({"/mesh/positions", {V, 3}, std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}, {}});
  f.datasets.push_back({"/mesh/normals", {V, 3}, std::vector<float>{0, 0, 1, 0, 0, 1, 0.6f, 0, 0.8f}, {}});
  f.datasets.push_back({"/mesh/triangles", {1, 3}, std::vector<uint32_t>{0, 1, 2}, {}});
  f.datasets.push_back({"/ao", {V}, std::vector<float>{1, 0.5f, 0.25f}, {}});
  f.datasets.push_back({"/transfer/diffuse", {V, 9}, ramp(V * 9, 0.01f), {{"sh_order", int64_t{3}}}});
  f.datasets.push_back({"/radiance/band1", {V, 3, 3}, ramp(V * 9, 0.02f), {}});
  f.datasets.push_back({"/fiv/environment", {3, 3}, std::vector<float>{1, 2, 3, 4, 5, 6, 7, 8, 9}, {}});
  f.datasets.push_back({"/fiv/irradiance_cube", {6, 2, 2, 3}, ramp(6 * 2 * 2 * 3, 0.5f), {}});
  const uint64_t nr = 2, nt = 3, np = 4;
  f.datasets.push_back({"/fiv/occluders/rock/shells", {nr, nt, np, 3, 3}, ramp(nr * nt * np * 9, 0.03f),
                        {{"centre", std::vector<double>{0.5, 2.0, -1.0}},
                         {"radius", 0.75},
                         {"radii", std::vector<double>{0.375, 1.5}},
                         {"grid", std::string("theta from +Y, phi from +Z towards +X")}}});
  std::vector<uint8_t> valid(nr * nt * np, 1);
  valid[5] = 0;
  f.datasets.push_back({"/fiv/occluders/rock/valid", {nr, nt, np}, valid, {}});
  if (with_object) {
    f.datasets.push_back({"/objects/tree/mesh/positions", {2, 3}, std::vector<float>{5, 5, 5, 6, 6, 6}, {}});
    f.datasets.push_back({"/objects/tree/mesh/normals", {2, 3}, std::vector<float>{0, 1, 0, 1, 0, 0}, {}});
    f.datasets.push_back({"/objects/tree/ao", {2}, std::vector<float>{0.125f, 1}, {}});
  }
  return f;
}

TEST(Loader, ArraysAndViewsMatchTheFile) {
  const File f = make_file(false);
  const auto path = tmp("loader_roundtrip.prt.h5");
  prt::formats::write_file(path, f);
  const prt::shade::LoadedAsset a = prt::shade::load_prt(path);
  ASSERT_EQ(a.vertex_sets.size(), 1u);
  const prt::shade::LoadedVertexSet* v = a.find_vertex_set("");
  ASSERT_NE(v, nullptr);
  EXPECT_EQ(v->vertex_count(), 3u);
  EXPECT_EQ(a.up_axis, "y");
  // Float data round-trips bit for bit through HDF5 float32.
  EXPECT_EQ(v->positions, std::get<std::vector<float>>(f.datasets[0].data));
  EXPECT_EQ(v->transfer, std::get<std::vector<float>>(f.datasets[4].data));
  EXPECT_EQ(v->transfer_order, 3);
  EXPECT_EQ(v->radiance_band1, std::get<std::vector<float>>(f.datasets[5].data));
  EXPECT_EQ(v->triangles, (std::vector<uint32_t>{0, 1, 2}));
  ASSERT_TRUE(a.has_fiv_environment);
  EXPECT_EQ(a.fiv_environment[8], 9.0f);
  ASSERT_EQ(a.occluders.size(), 1u);
  const prt::shade::LoadedOccluder& o = a.occluders[0];
  EXPECT_EQ(o.name, "rock");
  EXPECT_EQ(o.n_rho, 2);
  EXPECT_EQ(o.n_theta, 3);
  EXPECT_EQ(o.n_phi, 4);
  EXPECT_EQ(o.radius, 0.75f);  // exact binary fractions: the double → float rounding is exact
  EXPECT_EQ(o.centre[1], 2.0f);
  EXPECT_EQ(o.radii, (std::vector<float>{0.375f, 1.5f}));
  EXPECT_EQ(o.grid, "theta from +Y, phi from +Z towards +X");
  EXPECT_EQ(o.valid[5], 0);
  // No radial_scheme attribute (every file before version 7): paper 004's spheres.
  EXPECT_EQ(o.radial_scheme, prt::shade::kFivRadialGeometric);
  EXPECT_TRUE(o.surface_radius.empty());
  EXPECT_EQ(o.view().surface_radius, nullptr);

  // Shading with the loaded views equals shading with views of the original arrays.
  const auto& shells = std::get<std::vector<float>>(f.datasets[8].data);
  const auto& valid = std::get<std::vector<uint8_t>>(f.datasets[9].data);
  const std::vector<float> radii = {0.375f, 1.5f};
  const prt::shade::FivOccluder direct{{0.5f, 2.0f, -1.0f}, 0.75f, 2, 3, 4, radii.data(), shells.data(), valid.data()};
  const auto& cube = std::get<std::vector<float>>(f.datasets[7].data);
  const prt::shade::DifMap map{2, cube.data()};
  const std::vector<prt::shade::FivOccluder> views = a.occluder_views();
  const float p[3] = {0.2f, 0.1f, -0.3f}, n[3] = {0, 1, 0};
  float e_loaded[3], e_direct[3];
  prt::shade::shade_fiv(a.difmap(), views.data(), 1, p, n, {}, e_loaded);
  prt::shade::shade_fiv(map, &direct, 1, p, n, {}, e_direct);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(e_loaded[c], e_direct[c]);  // the same data, the same code
  float b1[3];
  prt::shade::shade_band1(v->normals.data() + 6, v->radiance_band1.data() + 18, b1);
  for (float x : b1) EXPECT_TRUE(std::isfinite(x));
}

// A version-7 occluder with surface-following shells (formats/SCHEMA.md): the scheme and the
// surface radii reach the view, which shades exactly like a view of the original arrays.
TEST(Loader, SurfaceFollowingShellsReachTheView) {
  File f = make_file(false);
  for (Dataset& d : f.datasets)
    if (d.path == "/fiv/occluders/rock/shells") {
      d.attrs.push_back({"radial_scheme", std::string("surface")});
      d.attrs.push_back({"first_offset", 0.5});
    }
  const std::vector<float> surface = {0.25f, 0.5f, 0.75f, 1.0f, 0.5f, 0.5f, 0.5f, 0.5f, 1.0f, 0.75f, 0.5f, 0.25f};
  f.datasets.push_back({"/fiv/occluders/rock/surface_radius", {3, 4}, surface, {}});
  const auto path = tmp("loader_surface.prt.h5");
  prt::formats::write_file(path, f);
  const prt::shade::LoadedAsset a = prt::shade::load_prt(path);
  EXPECT_EQ(a.format_version, 7);
  ASSERT_EQ(a.occluders.size(), 1u);
  const prt::shade::LoadedOccluder& o = a.occluders[0];
  EXPECT_EQ(o.radial_scheme, prt::shade::kFivRadialSurface);
  EXPECT_EQ(o.surface_radius, surface);
  const prt::shade::FivOccluder v = o.view();
  EXPECT_EQ(v.radial_scheme, prt::shade::kFivRadialSurface);
  ASSERT_NE(v.surface_radius, nullptr);
  const auto& shells = std::get<std::vector<float>>(f.datasets[8].data);
  const std::vector<float> radii = {0.375f, 1.5f};
  const prt::shade::FivOccluder direct{{0.5f, 2.0f, -1.0f}, 0.75f, 2, 3, 4, radii.data(), shells.data(), nullptr,
                                       prt::shade::kFivRadialSurface, surface.data(), nullptr};
  for (const float s : {0.1f, 0.6f, 1.3f, 2.4f, 9.0f}) {
    const float off[3] = {s, -0.3f * s, 0.2f};
    float loaded[9], expect[9];
    prt::shade::lookup_fiv(v, off, loaded);
    prt::shade::lookup_fiv(direct, off, expect);
    for (int e = 0; e < 9; ++e) EXPECT_EQ(loaded[e], expect[e]) << s;
  }
}

TEST(Loader, SceneObjectsAreSeparateVertexSets) {
  const auto path = tmp("loader_objects.prt.h5");
  prt::formats::write_file(path, make_file(true));
  const prt::shade::LoadedAsset a = prt::shade::load_prt(path);
  ASSERT_EQ(a.vertex_sets.size(), 2u);
  const prt::shade::LoadedVertexSet* tree = a.find_vertex_set("tree");
  ASSERT_NE(tree, nullptr);
  EXPECT_EQ(tree->vertex_count(), 2u);
  EXPECT_EQ(tree->ao, (std::vector<float>{0.125f, 1}));
  EXPECT_EQ(a.find_vertex_set("")->vertex_count(), 3u);
  EXPECT_EQ(a.find_vertex_set("nope"), nullptr);
}

TEST(Loader, SceneOccluderSelfShadowsAreReadBesideTheirVertexSet) {
  // Schema v9: /fiv/occluders/<name>/self_band1, [V][3][3] at the vertices of /objects/<name>.
  File f = make_file(false);
  f.datasets.push_back({"/objects/rock/mesh/positions", {2, 3}, std::vector<float>{5, 5, 5, 6, 6, 6}, {}});
  f.datasets.push_back({"/objects/rock/mesh/normals", {2, 3}, std::vector<float>{0, 1, 0, 1, 0, 0}, {}});
  const std::vector<float> self = ramp(2 * 9, 0.0625f);
  f.datasets.push_back({"/fiv/occluders/rock/self_band1", {2, 3, 3}, self, {}});
  const auto path = tmp("loader_self.prt.h5");
  prt::formats::write_file(path, f);
  const prt::shade::LoadedAsset a = prt::shade::load_prt(path);
  EXPECT_EQ(a.format_version, 9);
  ASSERT_EQ(a.occluders.size(), 1u);
  EXPECT_EQ(a.occluders[0].self_band1, self);
  ASSERT_NE(a.find_vertex_set("rock"), nullptr);
  EXPECT_EQ(a.find_vertex_set("rock")->vertex_count(), 2u);
  // Without it (every older file): empty.
  prt::formats::write_file(tmp("loader_no_self.prt.h5"), make_file(false));
  EXPECT_TRUE(prt::shade::load_prt(tmp("loader_no_self.prt.h5")).occluders.at(0).self_band1.empty());
}

TEST(Loader, ConeProxyIsReadWhereTheFileSaysSoAndOlderFilesAreTheSphere) {
  // Schema v7 (formats/SCHEMA.md): /fiv/occluders/<name>/cones with the group attribute proxy.
  // "cone": the view carries the table and shades as the core does with it; "sphere" or no
  // attribute (every older file): no table, the bounding sphere.
  File f = make_file(false);
  const uint64_t nr = 2, nt = 3, np = 4;
  std::vector<float> cones;
  for (uint64_t k = 0; k < nr * nt * np; ++k) cones.insert(cones.end(), {0.0f, 0.25f, 0.5f, 1.0f});  // |m| <= Ω
  f.datasets.push_back({"/fiv/occluders/rock/cones", {nr, nt, np, 4}, cones, {}});
  f.group_attrs.push_back({"/fiv/occluders/rock", {{"proxy", std::string("cone")}}});
  const auto path = tmp("loader_cones.prt.h5");
  prt::formats::write_file(path, f);
  const prt::shade::LoadedAsset a = prt::shade::load_prt(path);
  EXPECT_EQ(a.format_version, 7);
  ASSERT_EQ(a.occluders.size(), 1u);
  EXPECT_EQ(a.occluders[0].proxy, "cone");
  EXPECT_EQ(a.occluders[0].cones, cones);
  const std::vector<prt::shade::FivOccluder> views = a.occluder_views();
  ASSERT_NE(views[0].cones, nullptr);
  const float p[3] = {0.2f, 0.1f, -0.3f}, n[3] = {0, 1, 0};
  float e_cone[3], e_sphere[3], e_old[3];
  prt::shade::shade_fiv(a.difmap(), views.data(), 1, p, n, {}, e_cone);
  prt::shade::shade_fiv(a.difmap(), views.data(), 1, p, n, {true, true, prt::shade::FivProxy::sphere}, e_sphere);
  // The loaded view shades exactly as a view of the original arrays with their cone table.
  const auto& shells = std::get<std::vector<float>>(f.datasets[8].data);
  const auto& valid = std::get<std::vector<uint8_t>>(f.datasets[9].data);
  const std::vector<float> radii = {0.375f, 1.5f};
  const prt::shade::FivOccluder direct{{0.5f, 2.0f, -1.0f}, 0.75f, 2, 3, 4, radii.data(), shells.data(), valid.data(),
                                       prt::shade::kFivRadialGeometric, nullptr, cones.data()};
  float e_direct[3];
  prt::shade::shade_fiv(a.difmap(), &direct, 1, p, n, {}, e_direct);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(e_cone[c], e_direct[c]);
  // The same file saying "sphere": read without the table.
  f.group_attrs.back().second[0].value = std::string("sphere");
  prt::formats::write_file(path, f);
  const prt::shade::LoadedAsset b = prt::shade::load_prt(path);
  EXPECT_EQ(b.occluders[0].proxy, "sphere");
  EXPECT_TRUE(b.occluders[0].cones.empty());
  EXPECT_EQ(b.occluder_views()[0].cones, nullptr);
  // Without cones and proxy (the file ArraysAndViewsMatchTheFile writes): the sphere, version 4.
  prt::formats::write_file(path, make_file(false));
  const prt::shade::LoadedAsset old = prt::shade::load_prt(path);
  EXPECT_EQ(old.format_version, 4);
  EXPECT_EQ(old.occluders[0].proxy, "sphere");
  const std::vector<prt::shade::FivOccluder> old_views = old.occluder_views();
  prt::shade::shade_fiv(old.difmap(), old_views.data(), 1, p, n, {}, e_old);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(e_old[c], e_sphere[c]);  // the sphere, whatever the option
}

// `f` as a version-2 prtbake file at `path`, written without the writer's schema check.
void write_broken(const std::filesystem::path& path, File f) {
  f.root_attrs.push_back({"format", std::string("prtbake")});
  f.root_attrs.push_back({"format_version", int64_t{2}});
  prt::formats::testing::write_file_unvalidated(path, f);
}

// load_prt(path) must throw a FormatError whose message names the file and holds every needle.
void expect_refused(const std::filesystem::path& path, std::initializer_list<const char*> needles) {
  try {
    prt::shade::load_prt(path);
    ADD_FAILURE() << path << " accepted";
  } catch (const prt::formats::FormatError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path.string()), std::string::npos) << what;
    for (const char* n : needles) EXPECT_NE(what.find(n), std::string::npos) << n << " in: " << what;
  }
}

TEST(Loader, BrokenOccluderIsRefusedNamingTheFile) {
  File f = make_file(false);
  for (Dataset& d : f.datasets)
    if (d.path == "/fiv/occluders/rock/shells")
      for (Attr& at : d.attrs)
        if (at.name == "radii") at.value = std::vector<double>{1.5, 0.375};  // decreasing
  const auto path = tmp("loader_bad_radii.prt.h5");
  write_broken(path, f);
  expect_refused(path, {"radi"});
  EXPECT_THROW(prt::shade::load_prt(tmp("no_such_file.prt.h5")), prt::formats::FormatError);
}

TEST(Loader, IrradianceBeyondTheShadingLimitIsRefusedNamingTheDataset) {
  // prtshade/fiv.h "Numerics": FIV data beyond 2^64 could overflow float in n·F; the schema
  // accepts any finite value, the loader refuses it for the shading functions.
  File f = make_file(false);
  for (Dataset& d : f.datasets)
    if (d.path == "/fiv/environment") d.data = std::vector<float>{1, 2, 3, 4, 3e38f, 6, 7, 8, 9};
  const auto path = tmp("loader_env_beyond_limit.prt.h5");
  write_broken(path, f);
  expect_refused(path, {"/fiv/environment: ", "environment FIV value 4 = 3.00000001e+38: must be finite with magnitude <= 2^64"});
}

// What shading reads of a loaded asset, for comparing two loads.
void expect_same_data(const prt::shade::LoadedAsset& a, const prt::shade::LoadedAsset& b) {
  ASSERT_EQ(a.vertex_sets.size(), b.vertex_sets.size());
  for (std::size_t i = 0; i < a.vertex_sets.size(); ++i) {
    EXPECT_EQ(a.vertex_sets[i].name, b.vertex_sets[i].name);
    EXPECT_EQ(a.vertex_sets[i].positions, b.vertex_sets[i].positions);
    EXPECT_EQ(a.vertex_sets[i].ao, b.vertex_sets[i].ao);
    EXPECT_EQ(a.vertex_sets[i].transfer, b.vertex_sets[i].transfer);
    EXPECT_EQ(a.vertex_sets[i].radiance_band1, b.vertex_sets[i].radiance_band1);
  }
  EXPECT_EQ(a.irradiance_cube, b.irradiance_cube);
  ASSERT_EQ(a.occluders.size(), b.occluders.size());
  for (std::size_t i = 0; i < a.occluders.size(); ++i) EXPECT_EQ(a.occluders[i].shells, b.occluders[i].shells);
}

TEST(Loader, FilesAnotherToolAnnotatedWithH5pyLoadWithTheirNotes) {
  // h5py's str attributes are variable-length strings (issue 28): the loader reads them through
  // the reader's own heap code and loads the same arrays; a damaged heap leaves the notes out,
  // named in skipped_attrs, and still loads the same arrays.
  const auto dir = tmp("loader_h5py");
  std::filesystem::create_directories(dir);
  const std::string python = prt::testing::python_with_h5py(dir);
  if (python.empty()) GTEST_SKIP() << "h5py is not installed (apt-get install python3-h5py to run this test)";
  const auto path = dir / "a.prt.h5";
  prt::formats::write_file(path, make_file(true));
  const prt::shade::LoadedAsset plain = prt::shade::load_prt(path);
  ASSERT_EQ(prt::testing::add_h5py_notes(python, path, "objects/tree/mesh", "fiv/occluders/rock/shells",
                                         prt::testing::H5pyStrings::variable_length),
            "");
  const prt::shade::LoadedAsset annotated = prt::shade::load_prt(path);
  expect_same_data(annotated, plain);
  EXPECT_TRUE(annotated.skipped_attrs.empty());
  const Attr* note = prt::formats::find_attr(annotated.occluders.at(0).attrs, "note");
  ASSERT_NE(note, nullptr) << "the shells dataset's attributes, as stored";
  EXPECT_EQ(std::get<std::string>(note->value), "dataset note");

  prt::testing::Bytes bytes = prt::testing::file_bytes(path);
  bytes[prt::testing::only_collection(bytes)] = 'g';  // "gCOL": no collection there any more
  prt::testing::write_file_bytes(path, bytes);
  const prt::shade::LoadedAsset damaged = prt::shade::load_prt(path);
  expect_same_data(damaged, plain);
  EXPECT_EQ(prt::formats::find_attr(damaged.occluders.at(0).attrs, "note"), nullptr);
  std::vector<std::string> skipped;
  for (const prt::formats::SkippedAttr& s : damaged.skipped_attrs) skipped.push_back(prt::formats::describe(s));
  ASSERT_EQ(skipped.size(), 4u);
  EXPECT_EQ(skipped[0].rfind("attribute 'note' of the root group skipped: its text cannot be read safely from the "
                             "HDF5 global heap: no global heap collection starts at byte ",
                             0),
            0u)
      << skipped[0];
  EXPECT_EQ(skipped[1].rfind("attribute 'tags' of the root group skipped: the text of its string 0 ", 0), 0u) << skipped[1];
  EXPECT_EQ(skipped[2].rfind("attribute 'note' of dataset '/fiv/occluders/rock/shells' skipped: ", 0), 0u) << skipped[2];
  EXPECT_EQ(skipped[3].rfind("attribute 'note' of group '/objects/tree/mesh' skipped: ", 0), 0u) << skipped[3];
}

} // namespace

TEST(Loader, DamagedAndOldFormatFilesAreRefusedNeverACrash) {
  // What an engine links must not crash on a damaged file (formats/prtfile.h, "Which files the
  // reader opens"): every third byte of a scene file flipped gives a FormatError naming the file or,
  // when the flip hits padding, a load; the same file in HDF5's oldest (unchecksummed) format is
  // refused before HDF5 parses it.
  const auto path = tmp("loader_flips.prt.h5");
  prt::formats::write_file(path, make_file(true));
  const prt::shade::LoadedAsset good = prt::shade::load_prt(path);
  const auto size = static_cast<std::size_t>(std::filesystem::file_size(path));
  std::vector<std::size_t> offsets;
  for (std::size_t at = 0; at < size; at += 3) offsets.push_back(at);
  int refused = 0, loaded_same = 0, tried = 0;
  prt::testing::for_each_flipped_byte(path, offsets, 0xff, [&](std::size_t) {
    ++tried;
    try {
      const prt::shade::LoadedAsset a = prt::shade::load_prt(path);
      // A flip that passes every check landed in bytes that carry nothing (free space, padding).
      loaded_same += a.vertex_sets.size() == good.vertex_sets.size() && a.vertex_sets[0].ao == good.vertex_sets[0].ao &&
                     a.occluders.size() == good.occluders.size() && a.occluders[0].shells == good.occluders[0].shells;
    } catch (const prt::formats::FormatError& e) {
      ++refused;
      EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
    }
  });
  EXPECT_GT(refused, tried / 2) << "most bytes of a small file are checksummed metadata or data";
  EXPECT_EQ(refused + loaded_same, tried) << "a damaged file either is refused or loads the same values";

  const auto old = tmp("loader_oldest.prt.h5");
  File f = make_file(true);
  f.root_attrs.push_back({"format", std::string("prtbake")});
  f.root_attrs.push_back({"format_version", int64_t{2}});
  prt::formats::testing::write_file_oldest_format(old, f);
  try {
    prt::shade::load_prt(old);
    FAIL() << "an unchecksummed file was loaded";
  } catch (const prt::formats::FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("oldest file format"), std::string::npos) << e.what();
  }
}

namespace {

// Schema v8 (formats/SCHEMA.md "Half-float FIV tables"): a float16 file's shells and cones reach
// the runtime as halves (shells_half, cones_half; the float vectors empty), shade exactly as the
// float tables of their values, and h5py reads them as numpy float16 with those values.
TEST(Loader, HalfFloatTablesReachTheViewAsHalves) {
  File f = make_file(false);
  const uint64_t nr = 2, nt = 3, np = 4;
  std::vector<float> cones;
  for (uint64_t k = 0; k < nr * nt * np; ++k) cones.insert(cones.end(), {0.0f, 0.25f, 0.5f, 1.0f});
  std::vector<float> shells = std::get<std::vector<float>>(f.datasets[8].data);
  std::vector<prt::formats::Float16> shell_halves, cone_halves;
  for (float& v : shells) shell_halves.push_back(prt::formats::to_float16(v)), v = prt::formats::to_float(shell_halves.back());
  for (float v : cones) cone_halves.push_back(prt::formats::to_float16(v));
  f.datasets[8].data = shell_halves;
  f.datasets.push_back({"/fiv/occluders/rock/cones", {nr, nt, np, 4}, cone_halves, {}});
  f.group_attrs.push_back({"/fiv/occluders/rock", {{"proxy", std::string("cone")}}});
  const auto dir = tmp("loader_float16");
  std::filesystem::create_directories(dir);
  const auto path = dir / "a.prt.h5";
  prt::formats::write_file(path, f);
  const prt::shade::LoadedAsset a = prt::shade::load_prt(path);
  EXPECT_EQ(a.format_version, 8);
  const prt::shade::LoadedOccluder& o = a.occluders.at(0);
  EXPECT_TRUE(o.shells.empty());
  EXPECT_TRUE(o.cones.empty());
  ASSERT_EQ(o.shells_half.size(), shell_halves.size());
  for (std::size_t i = 0; i < shell_halves.size(); ++i) EXPECT_EQ(o.shells_half[i], shell_halves[i].bits) << i;
  ASSERT_EQ(o.cones_half.size(), cone_halves.size());
  const std::vector<prt::shade::FivOccluder> views = a.occluder_views();
  EXPECT_EQ(views[0].shells, nullptr);
  EXPECT_EQ(views[0].cones, nullptr);
  ASSERT_NE(views[0].shells_half, nullptr);
  ASSERT_NE(views[0].cones_half, nullptr);
  const auto& valid = std::get<std::vector<uint8_t>>(f.datasets[9].data);
  const std::vector<float> radii = {0.375f, 1.5f};
  const prt::shade::FivOccluder floats{{0.5f, 2.0f, -1.0f}, 0.75f, 2, 3, 4, radii.data(), shells.data(), valid.data(),
                                       prt::shade::kFivRadialGeometric, nullptr, cones.data()};
  const float p[3] = {0.2f, 0.1f, -0.3f}, n[3] = {0, 1, 0};
  float e_half[3], e_float[3];
  prt::shade::shade_fiv(a.difmap(), views.data(), 1, p, n, {}, e_half);
  prt::shade::shade_fiv(a.difmap(), &floats, 1, p, n, {}, e_float);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(e_half[c], e_float[c]) << c;
  const std::string python = prt::testing::python_with_h5py(dir);
  if (python.empty()) GTEST_SKIP() << "h5py is not installed (apt-get install python3-h5py to run this test)";
  std::string expected = "[";
  for (float v : shells) {  // the shortest text that reads back to v (as float32)
    char buf[32];
    expected += std::string(buf, std::to_chars(buf, buf + sizeof buf, v).ptr) + ",";
  }
  EXPECT_EQ(prt::testing::edit_with_h5py(python, path,
                                         "d = f['fiv/occluders/rock/shells']\n"
                                         "assert d.dtype == numpy.float16, d.dtype\n"
                                         "want = numpy.array(" + expected + "], dtype=numpy.float32)\n"
                                         "got = d[...].astype(numpy.float32).ravel()\n"
                                         "assert numpy.array_equal(got, want), (got, want)\n"
                                         "assert f['fiv/occluders/rock/cones'].dtype == numpy.float16\n"),
            "");
}

} // namespace
