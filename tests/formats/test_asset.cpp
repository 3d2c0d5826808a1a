// Tests of the typed asset model (formats/asset.h): write_asset -> read_asset gives back every
// field, an asset's bytes do not depend on the round trip, datasets and attributes land on the
// schema's paths and names, and attributes another tool added (h5py's variable-length strings on
// the root, a group and a dataset) are kept, written back and never make the file unreadable:
// a damaged global heap (hostile variants, every flipped byte) leaves its attributes out, named.
#include <formats/asset.h>
#include <formats/testing.h>

#include <gtest/gtest.h>
#include <byte_flips.h>
#include <h5py.h>
#include <hdf5_bytes.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <optional>
#include <stdexcept>

namespace fs = std::filesystem;
using namespace prt::formats;

namespace {

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(PRT_TEST_TMP) / "asset" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::vector<float> ramp(std::size_t n, float step) {
  std::vector<float> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = step * static_cast<float>(i) - 0.5f;
  return v;
}

Product product(std::vector<float> values, const std::string& integrand) {
  Product p;
  p.values = std::move(values);
  p.integrand = integrand;
  p.integrator = "silhouette";
  p.integrator_description = "semi-analytic";
  p.samples = 4096;
  p.seed = 0;  // a seed of 0 is a value, not "absent"
  p.visibility = "limit from above";
  return p;
}

ReportRow row(const std::string& product, float base, bool times) {
  ReportRow r;
  r.product = product;
  r.values = {base, 2 * base, 3 * base, 0, 5 * base};
  r.columns = "rmse, max_abs, reference_rms, bake_std_error, reference_std_error";
  r.points = 32;
  r.reference = "qmc 65536";
  if (times) {
    r.reference_seconds = 1.5;
    r.bake_seconds = 0.25;
    r.integrals_per_second = 1e6;
  }
  return r;
}

// A vertex set with V = 2 and every dataset the model has.
VertexSet full_set(float scale) {
  VertexSet s;
  const std::vector<float> p = ramp(6, scale);
  s.positions = Array<double>{{p.begin(), p.end()}, {{"unit", std::string("m")}}};
  s.normals = Normals{{0, 0, 1, 0, 1, 0}, "file", {}};
  s.triangles = Array<uint32_t>{{0, 1, 1}, {}};
  s.source_position = Array<uint32_t>{{7, 3}, {}};
  s.ao = product({0.25f, 1}, "A");
  s.transfer_diffuse = product(ramp(8, 0.125f * scale), "T");
  s.transfer_diffuse->sh_order = 2;
  s.transfer_visibility = product(ramp(18, 0.0625f), "U");
  s.transfer_visibility->sh_order = 3;
  s.radiance_band1 = product(ramp(18, 0.5f), "R");
  Product& r = *s.radiance_band1;
  r.shading = "E = 4pi/3 sum y R";
  r.environment = "sky.exr";
  r.environment_sha256 = std::string(64, 'c');
  r.environment_layout = "lat-long";
  r.negative_pixels_clamped = 3;
  r.extra = {{"k", int64_t{12}}};
  s.report.rows = {row("ao", 1e-3f, true), row("transfer/diffuse", 2e-3f, false)};
  s.report.vertices = Array<uint32_t>{{0, 1}, {}};
  return s;
}

Occluder occluder(const std::string& name, double radius) {
  Occluder o;
  o.name = name;
  o.n_rho = 2, o.n_theta = 2, o.n_phi = 3;
  o.shells = ramp(2 * 2 * 3 * 9, 0.01f);
  o.centre = {0.5, -1, 2};
  o.radius = radius;
  o.radii = {radius, 2 * radius};
  o.environment = "sky.exr";
  o.environment_sha256 = std::string(64, 'd');
  o.integrand = "F";
  o.angular_convention = "theta from +Y";
  o.grid = "theta from +Y, phi from +Z";
  o.fraction = 1e-3;
  o.samples = 16384;
  o.extra = {{"ids", std::vector<int64_t>{-1, 2}}};
  o.valid = OccluderValid{std::vector<uint8_t>(12, 1), "0: inside", {}};
  o.valid->values[4] = 0;
  o.report = row(name, 4e-3f, true);
  return o;
}

// An asset with every field of the model set (and extras at every kind of location).
Asset full_asset() {
  Asset a;
  a.root.format_version = kFormatVersionWithoutLightmaps;  // what the writer writes: no lightmap here
  a.root.generator = "test_asset";
  a.root.created = "2024-01-02T03:04:05Z";
  a.root.command_line = "prtbake scene s.json -o x";
  a.root.source = "data/Düsseldorf ✓.json";
  a.root.source_sha256 = std::string(64, 'a');
  a.root.up_axis = "z";
  a.root.sh_convention = "real orthonormal, i = l(l+1)+m";
  a.root.extra = {{"note", std::string("kept")}};
  a.vertices = full_set(1);
  SceneInfo& s = a.scene.emplace();
  s.scene_file = "s.json";
  s.integrator = "qmc";
  s.samples = 1024;
  s.seed = 7;
  s.sh_tolerance = 0.01;
  s.relight = 0;
  s.environment = "sky.exr";
  s.environment_sha256 = std::string(64, 'e');
  s.plan = "one\ntwo";
  s.options_file = "engine.options.json";
  s.options_sha256 = std::string(64, 'c');
  s.extra = {{"version_note", 2.5}};
  for (const char* name : {"bunny", "ground"}) {
    SceneObject& o = a.objects.emplace_back();
    o.name = name;
    o.role = "both";
    o.mesh = std::string(name) + ".obj";
    o.mesh_sha256 = std::string(64, 'f');
    o.transform = std::vector<double>(16, 0.0);
    (*o.transform)[0] = (*o.transform)[5] = (*o.transform)[10] = (*o.transform)[15] = 1;
    o.albedo = std::vector<double>{0.5, 0.25, 1};
    o.phong_exponent = 24;
    o.sh_order_diffuse = 0;
    o.sh_order_glossy = 3;
    o.baked = "ao: requested\nfiv: it can shadow";
    o.left_out = "-";
    o.specular = std::vector<double>{0.1, 0.1, 0.1};
    o.closed_form_vertices = 1;
    o.extra = {{"layer", std::string("props")}};
    o.set = full_set(2);
  }
  FivEnvironment& e = a.fiv_environment.emplace();
  for (std::size_t k = 0; k < 9; ++k) e.f_env[k] = 0.5f * float(k);
  e.environment = "sky.exr";
  e.environment_sha256 = std::string(64, 'e');
  e.integrand = "F_env";
  IrradianceCube& c = a.irradiance_cube.emplace();
  c.size = 2;
  c.values = ramp(6 * 2 * 2 * 3, 0.25f);
  for (float& x : c.values) x += 10;  // irradiance is positive
  c.environment = "sky.exr";
  c.environment_sha256 = std::string(64, 'e');
  c.integrand = "E";
  c.face_convention = "+X,-X,+Y,-Y,+Z,-Z";
  a.occluders = {occluder("bunny", 1.5), occluder("rock", 0.75)};  // bunny is also an object
  a.other_reports.push_back({"/report/timing", {2}, std::vector<float>{1, 2}, {{"unit", std::string("s")}}});
  a.group_extras = {{"/fiv/occluders/rock", {{"mesh", std::string("rock.obj")}}},
                    {"/mesh", {{"note", std::string("on a group")}}},
                    {"/report", {{"rmse", 1.5e-3}}}};
  a.target_error = 2.5e-3;  // typed, on /report beside the extra above
  return a;
}

} // namespace

TEST(Asset, EveryFieldSurvivesWriteRead) {
  const fs::path dir = scratch("roundtrip");
  const Asset a = full_asset();
  write_asset(dir / "a.prt.h5", a);
  const Asset b = read_asset(dir / "a.prt.h5");
  // Field by field first, for readable failures; then the whole asset.
  EXPECT_EQ(b.root, a.root);
  EXPECT_EQ(b.vertices, a.vertices);
  EXPECT_EQ(b.scene, a.scene);
  ASSERT_EQ(b.objects.size(), 2u);
  EXPECT_EQ(b.objects[0], a.objects[0]);
  EXPECT_EQ(b.objects[1].set.report, a.objects[1].set.report);
  EXPECT_EQ(b.fiv_environment, a.fiv_environment);
  EXPECT_EQ(b.irradiance_cube, a.irradiance_cube);
  ASSERT_EQ(b.occluders.size(), 2u);
  EXPECT_EQ(b.occluders[0], a.occluders[0]);
  EXPECT_EQ(b.occluders[1], a.occluders[1]);
  ASSERT_EQ(b.other_reports.size(), 1u);
  EXPECT_EQ(b.other_reports[0].path, "/report/timing");
  EXPECT_EQ(b.other_reports[0].data, a.other_reports[0].data);
  EXPECT_EQ(b.group_extras, a.group_extras);
  EXPECT_EQ(b.root.format_version, kFormatVersionWithoutLightmaps);
  EXPECT_TRUE(b == a);
  EXPECT_EQ(b.vertices.vertex_count(), 2u);
  EXPECT_EQ(*b.find_object("ground")->set.transfer_diffuse->sh_order, 2);
  EXPECT_EQ(b.find_occluder("nope"), nullptr);
}

TEST(Asset, AbsentStaysAbsent) {
  // A file with only a mesh: every optional of the model comes back empty, not defaulted.
  const fs::path dir = scratch("absent");
  Asset a = full_asset();
  a.scene.reset();
  a.objects.clear();
  a.fiv_environment.reset();
  a.irradiance_cube.reset();
  a.occluders.clear();
  a.other_reports.clear();
  a.group_extras.clear();
  a.target_error.reset();
  a.vertices = VertexSet{};
  a.vertices.positions = Array<double>{{0, 0, 0}, {}};
  write_asset(dir / "a.prt.h5", a);
  const Asset b = read_asset(dir / "a.prt.h5");
  EXPECT_TRUE(b == a);
  EXPECT_FALSE(b.vertices.normals.has_value());
  EXPECT_FALSE(b.vertices.ao.has_value());
  EXPECT_TRUE(b.vertices.report.empty());
  EXPECT_TRUE(b.objects.empty());
  EXPECT_TRUE(b.occluders.empty());
  EXPECT_FALSE(b.target_error.has_value());
  EXPECT_EQ(find_group_attrs(read_file(dir / "a.prt.h5"), "/report"), nullptr) << "no /report attributes without a target";
}

TEST(Asset, TargetErrorIsAnOptionalDoubleOnTheReportGroup) {
  // SCHEMA.md "Error reports": /report's target_error, float64, beside any extra attribute there.
  const fs::path dir = scratch("target_error");
  Asset a = full_asset();
  const File f = to_file(a);
  const std::vector<Attr>* report = find_group_attrs(f, "/report");
  ASSERT_NE(report, nullptr);
  ASSERT_NE(find_attr(*report, "target_error"), nullptr);
  EXPECT_EQ(std::get<double>(find_attr(*report, "target_error")->value), 2.5e-3);
  EXPECT_EQ(std::get<double>(find_attr(*report, "rmse")->value), 1.5e-3) << "the extra stays on the same group";
  EXPECT_EQ(std::count_if(f.group_attrs.begin(), f.group_attrs.end(), [](const auto& g) { return g.first == "/report"; }), 1)
      << "one /report group";
  write_asset(dir / "a.prt.h5", a);
  EXPECT_EQ(read_asset(dir / "a.prt.h5").target_error, 2.5e-3);

  // A target alone, with no report rows (--report 0): the group holds just the attribute.
  Asset alone = a;
  alone.group_extras.clear();
  alone.vertices.report = Report{};
  write_asset(dir / "alone.prt.h5", alone);
  const Asset b = read_asset(dir / "alone.prt.h5");
  EXPECT_EQ(b.target_error, 2.5e-3);
  EXPECT_TRUE(b.group_extras.empty()) << "target_error is typed, not an extra";

  // Not a double (another tool's string): kept as an extra, not misread as a target.
  File g = to_file(alone);
  for (auto& [group, attrs] : g.group_attrs)
    if (group == "/report") attrs = {{"target_error", std::string("1e-3")}};
  write_file(dir / "string.prt.h5", g);
  const Asset c = read_asset(dir / "string.prt.h5");
  EXPECT_FALSE(c.target_error.has_value());
  ASSERT_EQ(c.group_extras.size(), 1u);
  EXPECT_EQ(c.group_extras[0].first, "/report");
}

TEST(Asset, ObjectsAreFoundByTheirNodePathOrTheirStoredName) {
  // One spelling for people (asset.h): the node path; the file's name has '|' for '/'.
  Asset a;
  a.objects.resize(2);
  a.objects[0].name = "node0|node13|node71";
  a.objects[0].node_path = "node0/node13/node71";
  a.objects[1].name = "bunny";
  EXPECT_EQ(object_label(a.objects[0]), "node0/node13/node71");
  EXPECT_EQ(object_label(a.objects[1]), "bunny");
  EXPECT_EQ(a.find_object_by_label("node0/node13/node71"), &a.objects[0]);
  EXPECT_EQ(a.find_object_by_label("node0|node13|node71"), &a.objects[0]);
  EXPECT_EQ(a.find_object_by_label("bunny"), &a.objects[1]);
  EXPECT_EQ(a.find_object_by_label("node0/node13"), nullptr) << "a prefix is not the object";
  EXPECT_EQ(a.find_object_by_label("node0/node13/node7"), nullptr);
  // Without its node_path attribute (a file that lost it) the '/' spelling still finds it.
  a.objects[0].node_path.reset();
  EXPECT_EQ(a.find_object_by_label("node0/node13/node71"), &a.objects[0]);
}

TEST(Asset, BytesDoNotDependOnTheRoundTrip) {
  // write(read(write(a))) == write(a): the field tables fix the order of datasets and attributes.
  const fs::path dir = scratch("bytes");
  write_asset(dir / "a.prt.h5", full_asset());
  write_asset(dir / "b.prt.h5", read_asset(dir / "a.prt.h5"));
  EXPECT_EQ(prt::testing::read_bytes(dir / "a.prt.h5"), prt::testing::read_bytes(dir / "b.prt.h5"));
}

TEST(Asset, DatasetsAndAttributesAreTheSchemaOnes) {
  // The generic view of an asset: the paths and names of formats/SCHEMA.md.
  const File f = to_file(full_asset());
  for (const char* p : {"/mesh/positions", "/mesh/normals", "/mesh/triangles", "/mesh/source_position", "/ao",
                        "/transfer/diffuse", "/transfer/visibility", "/radiance/band1", "/report/ao",
                        "/report/transfer/diffuse", "/report/vertices", "/objects/bunny/mesh/positions",
                        "/objects/ground/radiance/band1", "/report/objects/ground/ao", "/fiv/environment",
                        "/fiv/irradiance_cube", "/fiv/occluders/rock/shells", "/fiv/occluders/bunny/valid",
                        "/report/fiv/rock", "/report/timing"})
    EXPECT_NE(find_dataset(f, p), nullptr) << p;
  EXPECT_EQ(find_dataset(f, "/transfer/visibility")->shape, (std::vector<uint64_t>{2, 9}));
  EXPECT_EQ(find_dataset(f, "/radiance/band1")->shape, (std::vector<uint64_t>{2, 3, 3}));
  EXPECT_EQ(find_dataset(f, "/fiv/occluders/rock/shells")->shape, (std::vector<uint64_t>{2, 2, 3, 3, 3}));
  EXPECT_EQ(std::get<int64_t>(find_attr(find_dataset(f, "/transfer/diffuse")->attrs, "sh_order")->value), 2);
  EXPECT_EQ(std::get<std::vector<double>>(find_attr(find_dataset(f, "/fiv/occluders/rock/shells")->attrs, "radii")->value),
            (std::vector<double>{0.75, 1.5}));
  EXPECT_EQ(std::get<std::string>(find_attr(*find_group_attrs(f, "/objects/bunny"), "role")->value), "both");
  EXPECT_EQ(std::get<int64_t>(find_attr(*find_group_attrs(f, "/scene"), "seed")->value), 7);
  EXPECT_EQ(std::get<std::string>(find_attr(f.root_attrs, "up_axis")->value), "z");
  EXPECT_EQ(find_attr(f.root_attrs, "format"), nullptr) << "the writer adds format and format_version";
  // Scene objects come first with their occluder (same name); the FIV environment before the
  // occluders of no object (the order prtbake has always written).
  auto index = [&](std::string_view p) { return find_dataset(f, p) - f.datasets.data(); };
  EXPECT_LT(index("/report/objects/bunny/vertices"), index("/fiv/occluders/bunny/shells"));
  EXPECT_LT(index("/fiv/occluders/bunny/shells"), index("/objects/ground/mesh/positions"));
  EXPECT_LT(index("/fiv/irradiance_cube"), index("/fiv/occluders/rock/shells"));
}

TEST(Asset, InspectShowsAFileThatFailsTheSchema) {
  const fs::path dir = scratch("inspect");
  write_asset(dir / "ok.prt.h5", full_asset());
  const Inspection ok = inspect_asset(dir / "ok.prt.h5");
  ASSERT_TRUE(ok.asset.has_value());
  EXPECT_FALSE(ok.schema_error.has_value());
  EXPECT_TRUE(*ok.asset == full_asset());
  EXPECT_THROW((void)inspect_asset(dir / "missing.prt.h5"), FormatError);

  File bad = to_file(full_asset());
  bad.root_attrs.push_back({"format", std::string("prtbake")});
  bad.root_attrs.push_back({"format_version", int64_t{2}});
  for (Dataset& d : bad.datasets)
    if (d.path == "/ao") std::get<std::vector<float>>(d.data)[1] = std::nanf("");
  prt::formats::testing::write_file_unvalidated(dir / "nan.prt.h5", bad);
  const Inspection in = inspect_asset(dir / "nan.prt.h5");
  EXPECT_FALSE(in.asset.has_value());
  ASSERT_TRUE(in.schema_error.has_value());
  EXPECT_EQ(*in.schema_error, "dataset '/ao' has a non-finite value (NaN) at index 1 [1]");
  EXPECT_EQ(in.file.datasets.size(), bad.datasets.size());
  EXPECT_THROW((void)read_asset(dir / "nan.prt.h5"), FormatError);
}

TEST(Asset, AttributesAnotherToolAddedAreKeptAndWrittenBack) {
  const fs::path dir = scratch("foreign");
  const std::string python = prt::testing::python_with_h5py(dir);
  if (python.empty()) GTEST_SKIP() << "h5py is not installed (apt-get install python3-h5py to run this test)";
  Asset a = full_asset();
  write_asset(dir / "a.prt.h5", a);
  const std::string failed = prt::testing::add_h5py_notes(python, dir / "a.prt.h5", "objects/ground/mesh", "ao");
  ASSERT_EQ(failed, "");

  const Asset b = read_asset(dir / "a.prt.h5");  // fixed-length strings another tool added
  const Attr* root_note = find_attr(b.root.extra, "note");
  ASSERT_NE(root_note, nullptr);
  EXPECT_EQ(std::get<std::string>(root_note->value), "root note ✓");  // h5py replaced "kept"
  const Attr* ao_note = find_attr(b.vertices.ao->extra, "note");
  ASSERT_NE(ao_note, nullptr);
  EXPECT_EQ(std::get<std::string>(ao_note->value), "dataset note");
  bool group_note = false;
  for (const auto& [g, attrs] : b.group_extras)
    if (g == "/objects/ground/mesh")
      group_note = find_attr(attrs, "note") && std::get<std::string>(find_attr(attrs, "note")->value) == "group note";
  EXPECT_TRUE(group_note);
  // Everything else is as written.
  Asset expected = a;
  expected.root.extra = b.root.extra;
  expected.vertices.ao->extra = b.vertices.ao->extra;
  expected.group_extras = b.group_extras;
  EXPECT_TRUE(b == expected);

  // Written back (as fixed-length strings) and read again: the notes stay.
  write_asset(dir / "b.prt.h5", b);
  EXPECT_TRUE(read_asset(dir / "b.prt.h5") == b);
}

namespace {

// The notes add_h5py_notes writes with variable-length strings, as read_asset returns them.
struct Notes {
  std::optional<AttrValue> root, tags, fixed, group, dataset;
};
Notes notes_of(const Asset& a) {
  Notes n;
  auto value = [](const ExtraAttrs& attrs, const char* name) -> std::optional<AttrValue> {
    const Attr* at = find_attr(attrs, name);
    return at ? std::optional<AttrValue>(at->value) : std::nullopt;
  };
  n.root = value(a.root.extra, "note"), n.tags = value(a.root.extra, "tags"), n.fixed = value(a.root.extra, "fixed");
  if (a.vertices.ao) n.dataset = value(a.vertices.ao->extra, "note");
  for (const auto& [g, attrs] : a.group_extras)
    if (g == "/objects/ground/mesh") n.group = value(attrs, "note");
  return n;
}
// `a` without what another tool added: the extras add_h5py_notes writes and what was skipped.
Asset without_notes(Asset a) {
  for (ExtraAttrs* extra : {&a.root.extra, &a.vertices.ao->extra})
    std::erase_if(*extra, [](const Attr& at) { return at.name == "note" || at.name == "tags" || at.name == "fixed"; });
  std::erase_if(a.group_extras, [](const auto& g) { return g.first == "/objects/ground/mesh"; });
  a.skipped_attrs.clear();
  return a;
}
// An h5py-annotated copy of full_asset() (add_h5py_notes, variable-length strings), or "" to skip.
std::string annotated_file(const fs::path& file) {
  const std::string python = prt::testing::python_with_h5py(file.parent_path());
  if (python.empty()) return "";
  write_asset(file, full_asset());
  const std::string failed = prt::testing::add_h5py_notes(python, file, "objects/ground/mesh", "ao",
                                                          prt::testing::H5pyStrings::variable_length);
  if (!failed.empty()) throw std::runtime_error(failed);
  return python;
}

} // namespace

TEST(Asset, VariableLengthStringsAnotherToolAddedAreReadAndWrittenBack) {
  // h5py's default for a str attribute (issue 28): its text is in the unchecksummed global heap,
  // which HDF5 never reads here; the reader's own bounds-checked code does.
  const fs::path dir = scratch("foreign_vlen");
  if (annotated_file(dir / "a.prt.h5").empty())
    GTEST_SKIP() << "h5py is not installed (apt-get install python3-h5py to run this test)";
  const Asset b = read_asset(dir / "a.prt.h5");
  const Notes n = notes_of(b);
  ASSERT_TRUE(n.root && n.tags && n.fixed && n.group && n.dataset);
  EXPECT_EQ(std::get<std::string>(*n.root), "root note ✓");
  EXPECT_EQ(std::get<std::vector<std::string>>(*n.tags), (std::vector<std::string>{"a", "bb", "ccc ✓"}));
  EXPECT_EQ(std::get<std::string>(*n.fixed), "fixed text");
  EXPECT_EQ(std::get<std::string>(*n.group), "group note");
  EXPECT_EQ(std::get<std::string>(*n.dataset), "dataset note");
  EXPECT_TRUE(b.skipped_attrs.empty());
  EXPECT_TRUE(without_notes(b) == without_notes(full_asset()));  // everything else as written

  // Written back (fixed-length strings, the list as an array of them) and read again: the same.
  write_asset(dir / "b.prt.h5", b);
  const Asset c = read_asset(dir / "b.prt.h5");
  EXPECT_TRUE(c == b);
  EXPECT_EQ(std::get<std::vector<std::string>>(*notes_of(c).tags), (std::vector<std::string>{"a", "bb", "ccc ✓"}));
}

TEST(Asset, ADamagedGlobalHeapLeavesItsAttributesOutNamingThemTheDataWhole) {
  // Hostile variants of the heap and of the references into it: each attribute whose text cannot
  // be read safely is left out and named with the reason; the file's data reads as written.
  namespace T = prt::testing;
  const fs::path dir = scratch("foreign_vlen_damaged");
  if (annotated_file(dir / "a.prt.h5").empty())
    GTEST_SKIP() << "h5py is not installed (apt-get install python3-h5py to run this test)";
  const T::Bytes original = T::file_bytes(dir / "a.prt.h5");
  const std::size_t gcol = T::only_collection(original);
  const std::string at = "at byte " + std::to_string(gcol);
  const std::size_t object1 = T::heap_object(original, gcol, 1);  // "root note ✓", 13 bytes
  const uint64_t size = T::get_le(original, gcol + 8, 8);
  const std::vector<std::string> all = {"/:note", "/:tags", "/ao:note", "/objects/ground/mesh:note"};
  struct Case {
    std::string what;
    std::function<void(T::Bytes&)> damage;
    std::vector<std::string> skipped;  // "<path>:<name>", sorted as read_file sorts them
    std::string reason;                // in every skipped attribute's reason
  };
  const std::vector<Case> cases = {
      {"a collection without its signature", [](T::Bytes& b) { b[T::only_collection(b) + 3] = 'X'; }, all,
       "no global heap collection starts " + at},
      {"a collection claiming more bytes than the file has (a truncated collection)",
       [&](T::Bytes& b) { T::put_le(b, gcol + 8, original.size() - gcol + 4096, 8); }, all,
       "the global heap collection " + at + " claims " + std::to_string(original.size() - gcol + 4096) +
           " bytes, the file has " + std::to_string(original.size() - gcol) + " from there (truncated?)"},
      {"an object whose size runs past the collection", [&](T::Bytes& b) { T::put_le(b, object1 + 8, uint64_t{1} << 40, 8); },
       all,
       "object 1 of the global heap collection " + at + " claims 1099511627776 bytes, past the collection's end (" +
           std::to_string(size - 32) + " bytes left)"},
      {"a reference to a collection outside the file (in a re-sealed header chunk)",
       [&](T::Bytes& b) { T::replace_heap_id_in_chunk(b, T::heap_id(10, gcol, 2), T::heap_id(10, uint64_t{1} << 40, 2)); },
       {"/objects/ground/mesh:note"},
       "the global heap collection at byte 1099511627776 lies outside the file (" + std::to_string(original.size()) +
           " bytes)"},
      {"a length past its object (in a re-sealed header chunk)",
       [&](T::Bytes& b) { T::replace_heap_id_in_chunk(b, T::heap_id(12, gcol, 3), T::heap_id(4000, gcol, 3)); },
       {"/ao:note"}, "its 4000 bytes run past object 3 of the global heap collection " + at + " (12 bytes)"},
      {"a reference to an object the collection does not hold (in a re-sealed header chunk)",
       [&](T::Bytes& b) { T::replace_heap_id_in_chunk(b, T::heap_id(12, gcol, 3), T::heap_id(12, gcol, 99)); },
       {"/ao:note"}, "the global heap collection " + at + " holds no object 99"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    T::Bytes damaged = original;
    c.damage(damaged);
    T::write_file_bytes(dir / "d.prt.h5", damaged);
    Asset d;
    ASSERT_NO_THROW(d = read_asset(dir / "d.prt.h5"));
    std::vector<std::string> skipped;
    for (const SkippedAttr& s : d.skipped_attrs) {
      skipped.push_back(s.path + ":" + s.name);
      EXPECT_NE(s.reason.find(c.reason), std::string::npos) << s.reason;
      EXPECT_EQ(describe(s).rfind("attribute '" + s.name + "' of ", 0), 0u) << describe(s);
    }
    EXPECT_EQ(skipped, c.skipped);
    const Notes n = notes_of(d);
    EXPECT_EQ(std::get<std::string>(*n.fixed), "fixed text");  // fixed-length: not in the heap
    EXPECT_EQ(n.root.has_value(), !std::count(skipped.begin(), skipped.end(), "/:note"));
    EXPECT_TRUE(without_notes(d) == without_notes(full_asset())) << "the file's data as written";
  }
  // A file cut inside its collection is refused whole: its superblock says it is longer.
  T::Bytes cut = original;
  cut.resize(gcol + 100);
  T::write_file_bytes(dir / "cut.prt.h5", cut);
  try {
    (void)read_asset(dir / "cut.prt.h5");
    FAIL() << "a truncated file was read";
  } catch (const FormatError& e) {
    EXPECT_EQ(e.file(), (dir / "cut.prt.h5").string());
    EXPECT_NE(e.defect().find("truncated"), std::string::npos) << e.what();
  }
}

TEST(Asset, EveryFlippedByteOfTheGlobalHeapIsReadOrLeftOutNeverACrash) {
  // The heap has no checksum: a flipped byte changes a text (read as it now is, or left out when
  // it is no longer UTF-8) or breaks the collection (its attributes left out). HDF5 never parses
  // it, so no flip can crash or hang the reader, and none makes the file unreadable.
  const fs::path dir = scratch("foreign_vlen_flips");
  if (annotated_file(dir / "a.prt.h5").empty())
    GTEST_SKIP() << "h5py is not installed (apt-get install python3-h5py to run this test)";
  const prt::testing::Bytes bytes = prt::testing::file_bytes(dir / "a.prt.h5");
  const std::size_t gcol = prt::testing::only_collection(bytes);
  std::vector<std::size_t> offsets;  // the collection's header, its objects and some free space
  for (std::size_t at = gcol; at < gcol + 512 && at < bytes.size(); ++at) offsets.push_back(at);
  int same = 0, changed = 0, left_out = 0;
  const Notes original = notes_of(read_asset(dir / "a.prt.h5"));
  for (const unsigned char mask : {0xffu, 0x01u})
    prt::testing::for_each_flipped_byte(dir / "a.prt.h5", offsets, mask, [&](std::size_t at) {
      Asset d;
      try {
        d = read_asset(dir / "a.prt.h5");
      } catch (const FormatError& e) {
        ADD_FAILURE() << "flip at " << at << " made the file unreadable: " << e.what();
        return;
      }
      const Notes n = notes_of(d);
      if (!d.skipped_attrs.empty()) ++left_out;
      else if (n.root == original.root && n.tags == original.tags && n.group == original.group && n.dataset == original.dataset) ++same;
      else ++changed;
      EXPECT_TRUE(without_notes(d) == without_notes(full_asset())) << "flip at " << at;
    });
  EXPECT_EQ(same + changed + left_out, int(2 * offsets.size()));
  EXPECT_GT(left_out, 0);
  EXPECT_GT(changed, 0);
  std::printf("global heap flips: %d read the same, %d read with a changed text, %d with attributes left out\n", same,
              changed, left_out);
}

TEST(Asset, AttributesOfATypeTheModelDoesNotHoldAreLeftOutNamingThem) {
  // h5py's bool is an HDF5 enum; a numpy record is a compound: neither is a string, an integer or
  // a float. They never make the file unreadable.
  const fs::path dir = scratch("foreign_types");
  const std::string python = prt::testing::python_with_h5py(dir);
  if (python.empty()) GTEST_SKIP() << "h5py is not installed (apt-get install python3-h5py to run this test)";
  write_asset(dir / "a.prt.h5", full_asset());
  ASSERT_EQ(prt::testing::edit_with_h5py(python, dir / "a.prt.h5",
                                         "f['ao'].attrs['flag'] = True\n"
                                         "f.attrs['pair'] = numpy.array((1, 2.5), dtype=[('a', 'i4'), ('b', 'f8')])"),
            "");
  const Asset a = read_asset(dir / "a.prt.h5");
  ASSERT_EQ(a.skipped_attrs.size(), 2u);
  EXPECT_EQ(describe(a.skipped_attrs[0]),
            "attribute 'pair' of the root group skipped: its type (an HDF5 compound) is not one the model holds "
            "(strings, integers, floats)");
  EXPECT_EQ(describe(a.skipped_attrs[1]),
            "attribute 'flag' of dataset '/ao' skipped: its type (an HDF5 enum, as h5py stores a bool) is not one "
            "the model holds (strings, integers, floats)");
  Asset expected = full_asset();
  expected.skipped_attrs = a.skipped_attrs;
  EXPECT_TRUE(a == expected);
}
