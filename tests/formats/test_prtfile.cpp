// Tests of formats/: write→read round trip of every dataset kind, determinism, every schema
// rule, atomic writes (no half files, no stray temp files), hostile inputs for the reader, and
// interoperability with h5dump and h5py.
#include <formats/prtfile.h>

#include <formats/temporaries.h>
#include <formats/testing.h>

#include <gtest/gtest.h>
#include <byte_flips.h>
#include <h5py.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <limits>
#include <thread>

namespace fs = std::filesystem;
using namespace prt::formats;

// HDF5 1.10.8 leaks small internal buffers on some error paths while rejecting corrupted
// metadata (the reader closes every identifier it opened: checked with H5Fget_obj_count).
// Suppress leaks whose allocation is inside libhdf5 only, for sanitizer builds.
extern "C" const char* __lsan_default_suppressions();
extern "C" const char* __lsan_default_suppressions() { return "leak:libhdf5_serial.so\n"; }

namespace {

constexpr uint64_t kV = 4;  // vertices of the synthetic mesh
constexpr int64_t kL = 2;   // SH order (bands) of its transfer

std::vector<Attr> root_attrs() {
  return {{"generator", std::string("prtbake 0.1.0 (test)")},
          {"created", std::string("2024-01-02T03:04:05Z")},
          {"command_line", std::string("prtbake vertex \"a b.obj\" --transfer 2\n-o x")},
          {"source", std::string("data/Düsseldorf ✓.obj")},
          {"source_sha256", std::string(64, 'a')},
          {"up_axis", std::string("y")},
          {"sh_convention", std::string("real orthonormal, i = l(l+1)+m, Condon-Shortley")}};
}

// A small file with every dataset kind of schema v1 and every attribute type.
File make_file() {
  File f;
  f.root_attrs = root_attrs();
  f.datasets.push_back({"/mesh/positions", {kV, 3},
                        std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1}, {}});
  f.datasets.push_back({"/mesh/normals", {kV, 3},
                        std::vector<float>{0, 0, 1, 0, 0, 1, 0, 0, 1, 0.6f, 0, 0.8f}, {}});
  f.datasets.push_back({"/mesh/triangles", {2, 3}, std::vector<uint32_t>{0, 1, 2, 0, 2, 3}, {}});
  f.datasets.push_back({"/mesh/source_position", {kV}, std::vector<uint32_t>{7, 8, 9, 10}, {}});
  f.datasets.push_back({"/ao", {kV}, std::vector<float>{0.25f, 0.5f, 0.75f, 1.0f}, {}});
  std::vector<float> t(kV * kL * kL);
  for (std::size_t i = 0; i < t.size(); ++i) t[i] = 0.01f * static_cast<float>(i) - 0.05f;
  f.datasets.push_back({"/transfer/diffuse", {kV, kL * kL}, t,
                        {{"sh_order", kL}, {"integrand", std::string("diffuse")}, {"k", int64_t{1024}}}});
  f.datasets.push_back({"/transfer/visibility", {kV, kL * kL}, t, {{"sh_order", kL}}});
  std::vector<float> r(kV * 9);
  for (std::size_t i = 0; i < r.size(); ++i) r[i] = static_cast<float>(i) * 0.5f;
  f.datasets.push_back({"/radiance/band1", {kV, 3, 3}, r, {{"environment", std::string("sky.exr")}}});
  f.datasets.push_back({"/fiv/environment", {3, 3}, std::vector<float>{1, 2, 3, 4, 5, 6, 7, 8, 9}, {}});
  f.datasets.push_back({"/fiv/irradiance_cube", {6, 2, 2, 3}, std::vector<float>(6 * 2 * 2 * 3, 0.5f), {}});
  std::vector<float> shells(2 * 2 * 3 * 3 * 3);
  for (std::size_t i = 0; i < shells.size(); ++i) shells[i] = static_cast<float>(i);
  f.datasets.push_back({"/fiv/occluders/rock/shells", {2, 2, 3, 3, 3}, shells,
                        {{"centre", std::vector<double>{0.5, 0.25, -1}},
                         {"radius", 2.5},
                         {"radii", std::vector<double>{3, 5}},
                         {"ids", std::vector<int64_t>{-1, 2}},
                         {"empty", std::vector<double>{}},
                         {"one", std::vector<double>{0.125}},
                         {"labels", std::vector<std::string>{"a", "", "ccc \u2713"}},
                         {"no_labels", std::vector<std::string>{}}}});
  f.datasets.push_back({"/fiv/occluders/rock/valid", {2, 2, 3},
                        std::vector<uint8_t>{1, 0, 1, 1, 1, 1, 0, 0, 1, 1, 1, 1}, {}});
  f.datasets.push_back({"/report/ao_error", {2}, std::vector<float>{1e-3f, 2e-3f}, {{"unit", std::string("1")}}});
  f.group_attrs.push_back({"/report", {{"rmse", 1.5e-3}, {"wall_seconds", 12.25}, {"samples", int64_t{64}}}});
  f.group_attrs.push_back({"/fiv/occluders/rock", {{"mesh", std::string("rock.obj")}}});
  return f;
}

// A fresh, empty scratch directory for one test.
fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(PRT_TEST_TMP) / "formats" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::vector<std::string> entries(const fs::path& dir) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) out.push_back(e.path().filename().string());
  std::sort(out.begin(), out.end());
  return out;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary | std::ios::ate);
  std::string bytes(static_cast<std::size_t>(std::max<std::streamoff>(in.tellg(), 0)), '\0');
  in.seekg(0);
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return bytes;
}

struct CmdResult {
  int exit_code;
  std::string output;  // stdout and stderr
};
CmdResult run_command(const std::string& cmd) {
  CmdResult r{-1, {}};
  FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  if (p == nullptr) return r;
  char buf[4096];
  std::size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
  const int status = pclose(p);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

void expect_same_attrs(const std::vector<Attr>& want, const std::vector<Attr>& got, const std::string& where) {
  for (const Attr& a : want) {
    const Attr* b = find_attr(got, a.name);
    ASSERT_NE(b, nullptr) << where << ": attribute " << a.name << " missing after read";
    EXPECT_EQ(a.value, b->value) << where << ": attribute " << a.name << " changed";
  }
  EXPECT_EQ(want.size(), got.size()) << where << ": attribute count";
}

} // namespace

TEST(RoundTrip, AllDatasetKindsSurviveWriteRead) {
  const fs::path dir = scratch("roundtrip");
  const File in = make_file();
  write_file(dir / "a.prt.h5", in);
  EXPECT_EQ(entries(dir), std::vector<std::string>{"a.prt.h5"}) << "only the final file remains";

  const File out = read_file(dir / "a.prt.h5");
  // The writer adds format and format_version.
  const Attr* fmt = find_attr(out.root_attrs, "format");
  ASSERT_NE(fmt, nullptr);
  EXPECT_EQ(std::get<std::string>(fmt->value), "prtbake");
  const Attr* ver = find_attr(out.root_attrs, "format_version");
  ASSERT_NE(ver, nullptr);
  EXPECT_EQ(std::get<int64_t>(ver->value), kFormatVersionWithoutLightmaps);  // no version-5 dataset
  std::vector<Attr> want_root = in.root_attrs;
  want_root.push_back({"format", std::string("prtbake")});
  want_root.push_back({"format_version", int64_t{kFormatVersionWithoutLightmaps}});
  expect_same_attrs(want_root, out.root_attrs, "root");

  ASSERT_EQ(out.datasets.size(), in.datasets.size());
  for (const Dataset& d : in.datasets) {
    const Dataset* e = find_dataset(out, d.path);
    ASSERT_NE(e, nullptr) << d.path << " missing after read";
    EXPECT_EQ(e->shape, d.shape) << d.path;
    EXPECT_EQ(e->data, d.data) << d.path << ": values must round-trip bit-exactly";
    expect_same_attrs(d.attrs, e->attrs, d.path);
  }
  ASSERT_EQ(out.group_attrs.size(), in.group_attrs.size());
  for (const auto& [g, attrs] : in.group_attrs) {
    const auto* got = find_group_attrs(out, g);
    ASSERT_NE(got, nullptr) << g;
    expect_same_attrs(attrs, *got, g);
  }
  // A one-element vector stays a vector; an empty vector survives; so do arrays of strings (an
  // empty string among them), written fixed-length.
  const Attr* one = find_attr(find_dataset(out, "/fiv/occluders/rock/shells")->attrs, "one");
  ASSERT_NE(one, nullptr);
  EXPECT_TRUE(std::holds_alternative<std::vector<double>>(one->value));
  const Attr* labels = find_attr(find_dataset(out, "/fiv/occluders/rock/shells")->attrs, "labels");
  ASSERT_NE(labels, nullptr);
  EXPECT_EQ(std::get<std::vector<std::string>>(labels->value), (std::vector<std::string>{"a", "", "ccc \u2713"}));
  const Attr* none = find_attr(find_dataset(out, "/fiv/occluders/rock/shells")->attrs, "no_labels");
  ASSERT_NE(none, nullptr);
  EXPECT_EQ(std::get<std::vector<std::string>>(none->value), std::vector<std::string>{});
  EXPECT_TRUE(out.skipped_attrs.empty());
}

TEST(RoundTrip, OverwritesAnExistingFile) {
  const fs::path dir = scratch("overwrite");
  File f = make_file();
  write_file(dir / "a.prt.h5", f);
  std::get<std::vector<float>>(f.datasets[4].data)[0] = 0.125f;  // /ao[0]
  write_file(dir / "a.prt.h5", f);
  const File out = read_file(dir / "a.prt.h5");
  EXPECT_EQ(std::get<std::vector<float>>(find_dataset(out, "/ao")->data)[0], 0.125f);
  EXPECT_EQ(entries(dir), std::vector<std::string>{"a.prt.h5"});
}

TEST(Determinism, SameFileGivesIdenticalBytes) {
  const fs::path dir = scratch("determinism");
  const File f = make_file();
  write_file(dir / "a.prt.h5", f);
  // Sleep past a second boundary so any stored time stamp would differ.
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));
  write_file(dir / "b.prt.h5", f);
  const std::string a = slurp(dir / "a.prt.h5"), b = slurp(dir / "b.prt.h5");
  ASSERT_GT(a.size(), 0u);
  EXPECT_EQ(a.size(), b.size());
  EXPECT_TRUE(a == b) << "two writes of the same File must give identical bytes";
}

TEST(Layout, ChunksAreAbout64KiBAlongTheFirstAxisAndFiltered) {
  const fs::path dir = scratch("chunks");
  File f = make_file();
  constexpr uint64_t V = 20000;  // 240 KB of positions: several chunks
  f.datasets.clear();
  f.group_attrs.clear();
  f.datasets.push_back({"/mesh/positions", {V, 3}, std::vector<float>(V * 3, 1.0f), {}});
  write_file(dir / "big.prt.h5", f);
  const CmdResult r = run_command("/usr/bin/h5dump -p -H -d /mesh/positions " + (dir / "big.prt.h5").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // 65536 bytes / (3 * 4 bytes per row) = 5461 rows per chunk.
  EXPECT_NE(r.output.find("CHUNKED ( 5461, 3 )"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("SHUFFLE"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("DEFLATE"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("LEVEL 6"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("CHECKSUM FLETCHER32"), std::string::npos) << r.output;
}

// ---- validation: each defect throws, names the file and the defect, and leaves nothing ------

struct Defect {
  const char* name;
  std::function<void(File&)> mutate;
  const char* expected;  // substring of the message
};

class Validation : public ::testing::TestWithParam<Defect> {};

Dataset& ds(File& f, std::string_view path) {
  for (Dataset& d : f.datasets)
    if (d.path == path) return d;
  throw std::logic_error("test file lacks " + std::string(path));
}
void drop(File& f, std::string_view path) {
  std::erase_if(f.datasets, [&](const Dataset& d) { return d.path == path; });
}
void drop_root(File& f, std::string_view name) {
  std::erase_if(f.root_attrs, [&](const Attr& a) { return a.name == name; });
}

TEST_P(Validation, ThrowsAndLeavesNoFileAndNoTempFile) {
  const Defect& defect = GetParam();
  const fs::path dir = scratch(std::string("validation_") + defect.name);
  const fs::path out = dir / "bad.prt.h5";
  File f = make_file();
  defect.mutate(f);
  try {
    write_file(out, f);
    FAIL() << defect.name << ": write_file accepted an invalid file";
  } catch (const FormatError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(out.string() + ": "), std::string::npos) << "names the file: " << msg;
    EXPECT_NE(msg.find(defect.expected), std::string::npos) << "names the defect: " << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line: " << msg;
  }
  EXPECT_TRUE(entries(dir).empty()) << "no final file and no temporary file may remain";
}

INSTANTIATE_TEST_SUITE_P(
    Schema, Validation,
    ::testing::Values(
        Defect{"nan", [](File& f) { std::get<0>(ds(f, "/ao").data)[2] = std::nanf(""); },
               "dataset '/ao' has a non-finite value (NaN) at index 2"},
        Defect{"inf", [](File& f) { std::get<0>(ds(f, "/transfer/diffuse").data)[5] = INFINITY; },
               "'/transfer/diffuse' has a non-finite value (Inf) at index 5 [1, 1]"},
        Defect{"nan_attr", [](File& f) { ds(f, "/ao").attrs.push_back({"x", std::nan("")}); },
               "attribute 'x' of dataset '/ao' is not finite"},
        Defect{"bad_shape", [](File& f) { ds(f, "/mesh/normals").shape = {6, 2}; },
               "'/mesh/normals' has shape [6, 2]; expected [V, 3]"},
        Defect{"size_mismatch", [](File& f) { std::get<0>(ds(f, "/ao").data).push_back(1); },
               "'/ao' has 5 values but shape [4] needs 4"},
        Defect{"index_out_of_range", [](File& f) { std::get<1>(ds(f, "/mesh/triangles").data)[4] = 4; },
               "vertex index 4 >= V = 4 at index 4 [1, 1]"},
        Defect{"wrong_dtype", [](File& f) { ds(f, "/mesh/triangles").data = std::vector<float>(6, 0.f); },
               "'/mesh/triangles' must be uint32, not float32"},
        Defect{"missing_attr", [](File& f) { drop_root(f, "source_sha256"); },
               "lacks the required attribute 'source_sha256'"},
        Defect{"attr_wrong_type", [](File& f) { drop_root(f, "created"); f.root_attrs.push_back({"created", int64_t{5}}); },
               "attribute 'created' of the root group must be a string"},
        Defect{"bad_up_axis", [](File& f) { drop_root(f, "up_axis"); f.root_attrs.push_back({"up_axis", std::string("Y")}); },
               "'up_axis' must be \"y\" or \"z\""},
        Defect{"bad_sha", [](File& f) { drop_root(f, "source_sha256"); f.root_attrs.push_back({"source_sha256", std::string("abc")}); },
               "'source_sha256' must be 64 lowercase hex digits"},
        Defect{"wrong_version", [](File& f) { f.root_attrs.push_back({"format_version", int64_t{10}}); },
               "'format_version' must be an integer in 1..9"},
        Defect{"object_in_v1_file",
               [](File& f) {
                 f.root_attrs.push_back({"format_version", int64_t{1}});
                 f.datasets.push_back({"/objects/a/mesh/positions", {1, 3}, std::vector<float>{0, 0, 0}, {}});
               },
               "is a scene object's, which needs format_version 2"},
        Defect{"object_ao_without_its_positions",
               [](File& f) { f.datasets.push_back({"/objects/a/ao", {1}, std::vector<float>{1}, {}}); },
               "no /objects/a/mesh/positions to define the vertex count V"},
        Defect{"object_ao_wrong_length",
               [](File& f) {
                 f.datasets.push_back({"/objects/a/mesh/positions", {2, 3}, std::vector<float>(6, 0.f), {}});
                 f.datasets.push_back({"/objects/a/mesh/normals", {2, 3}, std::vector<float>(6, 0.f), {}});
                 f.datasets.push_back({"/objects/a/ao", {3}, std::vector<float>{1, 1, 1}, {}});
               },
               "dataset '/objects/a/ao' has shape [3]; expected [V] = [2]"},
        Defect{"object_triangles_out_of_range",
               [](File& f) {
                 f.datasets.push_back({"/objects/a/mesh/positions", {2, 3}, std::vector<float>(6, 0.f), {}});
                 f.datasets.push_back({"/objects/a/mesh/triangles", {1, 3}, std::vector<uint32_t>{0, 1, 2}, {}});
               },
               "dataset '/objects/a/mesh/triangles' has vertex index 2 >= V = 2"},
        Defect{"object_unknown_product",
               [](File& f) { f.datasets.push_back({"/objects/a/fiv/environment", {3, 3}, std::vector<float>(9, 0.f), {}}); },
               "unknown dataset path '/objects/a/fiv/environment'"},
        Defect{"duplicate_attr", [](File& f) { f.root_attrs.push_back(f.root_attrs[0]); },
               "has attribute 'generator' twice"},
        Defect{"bad_utf8", [](File& f) { f.root_attrs[0].value = std::string("\xff\xfe"); },
               "is not valid UTF-8"},
        Defect{"bad_utf8_in_a_string_array",
               [](File& f) { f.root_attrs.push_back({"tags", std::vector<std::string>{"ok", "\xc0\xaf"}}); },
               "attribute 'tags' of the root group has a string that is not valid UTF-8 (string 1)"},
        Defect{"nul_in_a_string_array",
               [](File& f) { f.root_attrs.push_back({"tags", std::vector<std::string>{std::string("a\0b", 3)}}); },
               "attribute 'tags' of the root group has a NUL character in string 0"},
        Defect{"unknown_top_level", [](File& f) { f.datasets.push_back({"/foo", {1}, std::vector<float>{1}, {}}); },
               "unknown dataset path '/foo'"},
        Defect{"unknown_under_mesh", [](File& f) { f.datasets.push_back({"/mesh/colors", {kV}, std::vector<float>(kV), {}}); },
               "unknown dataset path '/mesh/colors'"},
        Defect{"relative_path", [](File& f) { ds(f, "/ao").path = "ao"; }, "must be absolute"},
        Defect{"duplicate_path", [](File& f) { f.datasets.push_back(ds(f, "/ao")); }, "'/ao' is given twice"},
        Defect{"dataset_under_dataset", [](File& f) { f.datasets.push_back({"/report/ao_error/x", {1}, std::vector<float>{1}, {}}); },
               "lies under dataset '/report/ao_error'"},
        Defect{"missing_sh_order", [](File& f) { ds(f, "/transfer/visibility").attrs.clear(); },
               "lacks the integer attribute 'sh_order'"},
        Defect{"sh_order_mismatch", [](File& f) { ds(f, "/transfer/diffuse").attrs[0].value = int64_t{3}; },
               "expected [V, L*L] with L = sh_order = 3 = [4, 9]"},
        Defect{"no_positions", [](File& f) { drop(f, "/mesh/positions"); },
               "no /mesh/positions to define the vertex count V"},
        Defect{"no_normals", [](File& f) { drop(f, "/mesh/normals"); }, "'/ao' needs /mesh/normals"},
        Defect{"cube_shape", [](File& f) { ds(f, "/fiv/irradiance_cube").shape = {6, 3, 4, 1}; },
               "expected [6, S, S, 3]"},
        Defect{"shells_no_radii", [](File& f) { std::erase_if(ds(f, "/fiv/occluders/rock/shells").attrs, [](const Attr& a) { return a.name == "radii"; }); },
               "needs attribute 'radii'"},
        Defect{"valid_without_shells", [](File& f) { drop(f, "/fiv/occluders/rock/shells"); },
               "has no 'shells' dataset beside it"},
        Defect{"valid_not_boolean", [](File& f) { std::get<2>(ds(f, "/fiv/occluders/rock/valid").data)[3] = 7; },
               "must hold 0 or 1, not 7"},
        Defect{"group_attrs_on_root", [](File& f) { f.group_attrs.push_back({"/", {{"a", 1.0}}}); }, "must be absolute"},
        Defect{"group_attrs_unknown_group", [](File& f) { f.group_attrs.push_back({"/elsewhere", {{"a", 1.0}}}); },
               "attributes on group '/elsewhere' are not allowed"},
        Defect{"rank_zero", [](File& f) { f.datasets.push_back({"/report/s", {}, std::vector<float>{1}, {}}); },
               "must have 1 to 32 dimensions"}),
    [](const ::testing::TestParamInfo<Defect>& p) { return std::string(p.param.name); });

TEST(Atomicity, FailedWriteLeavesExistingFileUntouched) {
  const fs::path dir = scratch("untouched");
  write_file(dir / "a.prt.h5", make_file());
  const std::string before = slurp(dir / "a.prt.h5");
  File bad = make_file();
  std::get<0>(ds(bad, "/ao").data)[0] = std::nanf("");
  EXPECT_THROW(write_file(dir / "a.prt.h5", bad), FormatError);
  EXPECT_EQ(slurp(dir / "a.prt.h5"), before) << "the old file must be untouched";
  EXPECT_EQ(entries(dir), std::vector<std::string>{"a.prt.h5"}) << "no temporary file may remain";
}

TEST(Atomicity, StaleTemporariesOfKilledBakesAreRemovedLiveOnesKept) {
  // A bake killed with SIGKILL leaves "<name>.tmp.<host>.<pid>". The next write to that name
  // removes it when the pid is dead on this machine, and keeps a live pid's (another bake writing
  // now), another machine's, another name's and anything else.
  const fs::path dir = scratch("stale_tmp");
  const std::string h = prt::formats::host_tag();
  const pid_t dead = ::fork();  // a pid that is surely dead once reaped
  if (dead == 0) ::_exit(0);
  ASSERT_GT(dead, 0);
  ::waitpid(dead, nullptr, 0);
  const std::string stale = "a.prt.h5.tmp." + h + "." + std::to_string(dead);
  const std::string live = "a.prt.h5.tmp." + h + "." + std::to_string(::getppid());
  const std::string other_host = "a.prt.h5.tmp.elsewhere-" + h + "." + std::to_string(dead);
  const std::string other_name = "b.prt.h5.tmp." + h + "." + std::to_string(dead);
  for (const std::string& n : {stale, live, other_host, other_name}) std::ofstream(dir / n) << "partial";
  write_file(dir / "a.prt.h5", make_file());
  std::vector<std::string> want = {"a.prt.h5", live, other_host, other_name};
  std::sort(want.begin(), want.end());
  EXPECT_EQ(entries(dir), want);
}

TEST(Atomicity, MissingDirectoryIsAFormatErrorNamingThePath) {
  const fs::path dir = scratch("missing_dir");
  const fs::path out = dir / "no" / "such" / "a.prt.h5";
  try {
    write_file(out, make_file());
    FAIL() << "writing into a missing directory must fail";
  } catch (const FormatError& e) {
    EXPECT_EQ(e.file(), out.string());
    EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(entries(dir).empty());
}

TEST(Atomicity, UnwritableDirectoryIsAFormatErrorNamingThePath) {
  // /proc refuses new files even for root; a 0555 directory is used as well when not root
  // (root bypasses permission bits, so that half only runs for ordinary users).
  std::vector<fs::path> targets = {"/proc/prtbake_test.prt.h5"};
  const fs::path dir = scratch("unwritable");
  if (::geteuid() != 0) {
    fs::permissions(dir, fs::perms::owner_read | fs::perms::owner_exec);
    targets.push_back(dir / "a.prt.h5");
  }
  for (const fs::path& out : targets) {
    try {
      write_file(out, make_file());
      ADD_FAILURE() << "writing into " << out << " must fail";
    } catch (const FormatError& e) {
      EXPECT_EQ(e.file(), out.string());
      EXPECT_NE(std::string(e.what()).find("cannot create temporary file"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(out));
  }
  fs::permissions(dir, fs::perms::owner_all);
  EXPECT_TRUE(entries(dir).empty());
}

// ---- reading hostile and foreign files ---------------------------------------------------

void expect_read_error(const fs::path& p, const std::string& expected) {
  ::testing::internal::CaptureStderr();
  try {
    (void)read_file(p);
    ADD_FAILURE() << p << ": read_file accepted it";
  } catch (const FormatError& e) {
    EXPECT_EQ(e.file(), p.string());
    EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
  }
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(err, "") << "HDF5 must not print its error stack";
}

// Calls `read` on `file` with its byte at each offset `at` XOR-ed by each mask (in place, restored
// after: rewriting a whole file per flip costs more than the read); returns how many reads threw
// a FormatError naming the file. Anything else escaping fails the test.
template <class Offsets>
int flips_refused(const fs::path& file, const Offsets& offsets, std::initializer_list<unsigned char> masks,
                  int* tried = nullptr) {
  int refused = 0;
  for (const unsigned char mask : masks)
    prt::testing::for_each_flipped_byte(file, offsets, mask, [&](std::size_t) {
      if (tried != nullptr) ++*tried;
      try {
        (void)read_file(file);
      } catch (const FormatError& e) {
        ++refused;
        EXPECT_EQ(e.file(), file.string());
      }
    });
  return refused;
}

std::vector<std::size_t> offsets(std::size_t size, std::size_t dense, std::size_t stride) {
  std::vector<std::size_t> out;
  for (std::size_t at = 0; at < size; at += at < dense ? 1 : stride) out.push_back(at);
  return out;
}

TEST(Reader, MissingFile) {
  expect_read_error(scratch("missing") / "none.prt.h5", "no such file");
}

TEST(Reader, TruncatedFileIsAFormatError) {
  const fs::path dir = scratch("truncated");
  write_file(dir / "a.prt.h5", make_file());
  const std::string bytes = slurp(dir / "a.prt.h5");
  for (std::size_t keep : {bytes.size() / 2, bytes.size() - 1, std::size_t{100}, std::size_t{0}}) {
    std::ofstream(dir / "cut.prt.h5", std::ios::binary | std::ios::trunc).write(bytes.data(), static_cast<std::streamsize>(keep));
    SCOPED_TRACE("kept " + std::to_string(keep) + " of " + std::to_string(bytes.size()) + " bytes");
    expect_read_error(dir / "cut.prt.h5", "");
  }
}

TEST(Reader, GarbageFileIsAFormatError) {
  const fs::path dir = scratch("garbage");
  std::string junk(10000, '\0');
  uint32_t x = 12345;
  for (char& c : junk) c = static_cast<char>((x = x * 1664525u + 1013904223u) >> 24);
  std::ofstream(dir / "junk.prt.h5", std::ios::binary).write(junk.data(), static_cast<std::streamsize>(junk.size()));
  expect_read_error(dir / "junk.prt.h5", "not an HDF5 file");
}

TEST(Reader, CorruptedBytesGiveFormatErrorNeverACrash) {
  // Flip every byte (the file is ~9 KB and covers all metadata structures): every
  // outcome must be a clean FormatError or (when the flip hits unused or padding bytes) a
  // successful read; never a crash. Run under the asan preset this also proves no out-of-bounds
  // access (formats/SCHEMA.md, "Storage").
  const fs::path dir = scratch("corrupt");
  write_file(dir / "a.prt.h5", make_file());
  const int errors = flips_refused(dir / "a.prt.h5", offsets(fs::file_size(dir / "a.prt.h5"), 0, 1), {0x5a});
  EXPECT_GT(errors, 0) << "some flipped bytes must be detected";
}

TEST(Reader, NewerVersionIsRejectedClearly) {
  const fs::path dir = scratch("newer");
  File f = make_file();
  f.root_attrs.push_back({"format", std::string("prtbake")});
  f.root_attrs.push_back({"format_version", int64_t{10}});
  prt::formats::testing::write_file_unvalidated(dir / "v10.prt.h5", f);
  expect_read_error(dir / "v10.prt.h5", "written by a newer prtbake (format_version 10 > 9)");
}

TEST(Reader, Version1FilesStayReadable) {
  // Schema v2 only added the /objects/<name>/ layout of scene files; v1 files read unchanged.
  const fs::path dir = scratch("v1");
  File f = make_file();
  f.root_attrs.push_back({"format", std::string("prtbake")});
  f.root_attrs.push_back({"format_version", int64_t{1}});
  prt::formats::testing::write_file_unvalidated(dir / "v1.prt.h5", f);
  const File r = read_file(dir / "v1.prt.h5");
  EXPECT_EQ(std::get<int64_t>(find_attr(r.root_attrs, "format_version")->value), 1);
  EXPECT_EQ(r.datasets.size(), f.datasets.size());
}

TEST(Schema, SceneObjectsHaveTheirOwnVertexSets) {
  // Two objects with different V, each validated against its own mesh/positions; group attributes
  // on the object groups; round trip keeps them.
  const fs::path dir = scratch("objects");
  File f = make_file();
  auto add_object = [&](const std::string& name, uint64_t V) {
    const std::string o = "/objects/" + name;
    f.datasets.push_back({o + "/mesh/positions", {V, 3}, std::vector<float>(3 * V, 0.5f), {}});
    f.datasets.push_back({o + "/mesh/normals", {V, 3}, std::vector<float>(3 * V, 0.f), {}});
    f.datasets.push_back({o + "/ao", {V}, std::vector<float>(V, 1.f), {}});
    f.datasets.push_back({o + "/transfer/visibility", {V, 4}, std::vector<float>(4 * V, 0.25f),
                          {{"sh_order", int64_t{2}}}});
    f.group_attrs.push_back({o, {{"role", std::string("both")}}});
  };
  add_object("ground", 5);
  add_object("bunny", 2);
  write_file(dir / "scene.prt.h5", f);
  const File r = read_file(dir / "scene.prt.h5");
  ASSERT_NE(find_dataset(r, "/objects/ground/ao"), nullptr);
  EXPECT_EQ(find_dataset(r, "/objects/ground/ao")->shape, (std::vector<uint64_t>{5}));
  EXPECT_EQ(find_dataset(r, "/objects/bunny/ao")->shape, (std::vector<uint64_t>{2}));
  ASSERT_NE(find_group_attrs(r, "/objects/bunny"), nullptr);
  EXPECT_EQ(std::get<std::string>(find_attr(*find_group_attrs(r, "/objects/bunny"), "role")->value), "both");
  EXPECT_TRUE(is_per_vertex_path("/objects/bunny/radiance/band1"));
  EXPECT_FALSE(is_per_vertex_path("/objects/bunny/mesh/triangles"));
  EXPECT_EQ(vertex_set_of("/objects/bunny/ao"), "/objects/bunny");
  EXPECT_EQ(vertex_set_of("/ao"), "");
}

TEST(Reader, NonPrtbakeHdf5FileIsRejected) {
  const fs::path dir = scratch("foreign");
  File f = make_file();
  prt::formats::testing::write_file_unvalidated(dir / "none.h5", f);  // no format attribute at all
  expect_read_error(dir / "none.h5", "not a prtbake file (no 'format' attribute)");
  f.root_attrs.push_back({"format", std::string("other")});
  prt::formats::testing::write_file_unvalidated(dir / "other.h5", f);
  expect_read_error(dir / "other.h5", "not a prtbake file (format = \"other\")");
}

// A prtbake-looking file (format attributes set) in HDF5's oldest on-disk format.
File with_format_attrs(File f) {
  f.root_attrs.push_back({"format", std::string("prtbake")});
  f.root_attrs.push_back({"format_version", int64_t{2}});
  return f;
}

TEST(Reader, OldestFormatIsRefusedBeforeHdf5ParsesIt) {
  // Superblock 0, version-1 object headers, symbol-table groups, no checksums: what crashed
  // HDF5 1.10 when damaged. Refused from its superblock, whatever its content.
  const fs::path dir = scratch("oldest");
  using prt::formats::testing::OldestFormat;
  prt::formats::testing::write_file_oldest_format(dir / "old.prt.h5", with_format_attrs(make_file()));
  expect_read_error(dir / "old.prt.h5", "written in HDF5's oldest file format (superblock version 0: no checksums)");
  // Checksummed superblock, unchecksummed objects below it: refused at the root group's header.
  prt::formats::testing::write_file_oldest_format(dir / "mixed.prt.h5", with_format_attrs(make_file()),
                                                  OldestFormat::objects_only);
  expect_read_error(dir / "mixed.prt.h5", "is not a checksummed (version 2) HDF5 object header");
  // The message's advice works: h5repack --latest --filter=FLET (rewriting every dataset: a plain
  // --latest copies object headers as they are) makes it a file the reader opens, with the data.
  const CmdResult r = run_command("/usr/bin/h5repack --latest --filter=FLET " + (dir / "old.prt.h5").string() + " " +
                                  (dir / "repacked.prt.h5").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const File got = read_file(dir / "repacked.prt.h5");
  EXPECT_EQ(std::get<0>(find_dataset(got, "/ao")->data), std::get<0>(find_dataset(make_file(), "/ao")->data));
}

TEST(Reader, EveryFlippedByteOfAnOldFormatFileIsRefused) {
  // Byte flips over unchecksummed files (both old kinds): never a crash, never accepted (a flip
  // cannot make an unchecksummed file a checksummed one: the superblock or header check, or
  // HDF5's checksum of the structure the flip pretends to be, refuses it). Every byte of the
  // superblock, then one byte in 5 (the files are ~50 KB); two masks.
  const fs::path dir = scratch("oldest_flips");
  using prt::formats::testing::OldestFormat;
  for (const OldestFormat which : {OldestFormat::everywhere, OldestFormat::objects_only}) {
    prt::formats::testing::write_file_oldest_format(dir / "old.prt.h5", with_format_attrs(make_file()), which);
    int tried = 0;
    const int refused = flips_refused(dir / "old.prt.h5", offsets(fs::file_size(dir / "old.prt.h5"), 64, 5),
                                      {0x01, 0xff}, &tried);
    EXPECT_EQ(refused, tried) << "every flip of an unchecksummed file is refused";
  }
}

TEST(Reader, UserBlocksAndForeignOffsetSizesAreRefused) {
  const fs::path dir = scratch("user_block");
  write_file(dir / "a.prt.h5", make_file());
  const std::string bytes = slurp(dir / "a.prt.h5");
  std::ofstream(dir / "ub.prt.h5", std::ios::binary).write((std::string(512, ' ') + bytes).data(),
                                                           static_cast<std::streamsize>(512 + bytes.size()));
  expect_read_error(dir / "ub.prt.h5", "an HDF5 file with a 512-byte user block before its data");
  std::string small = bytes;
  small[9] = 4;  // 4-byte offsets
  std::ofstream(dir / "o4.prt.h5", std::ios::binary).write(small.data(), static_cast<std::streamsize>(small.size()));
  expect_read_error(dir / "o4.prt.h5", "HDF5 offsets of 4 and lengths of 8 bytes (prtbake files use 8 and 8)");
}

TEST(Reader, FullCheckRejectsNaNHeaderCheckShowsIt) {
  const fs::path dir = scratch("nan_read");
  File f = make_file();
  f.root_attrs.push_back({"format", std::string("prtbake")});
  f.root_attrs.push_back({"format_version", int64_t{1}});
  std::get<0>(ds(f, "/radiance/band1").data)[10] = std::nanf("");
  prt::formats::testing::write_file_unvalidated(dir / "nan.prt.h5", f);
  expect_read_error(dir / "nan.prt.h5", "'/radiance/band1' has a non-finite value (NaN) at index 10 [1, 0, 1]");
  const File got = read_file(dir / "nan.prt.h5", ReadCheck::header);
  EXPECT_TRUE(std::isnan(std::get<0>(find_dataset(got, "/radiance/band1")->data)[10]));
}

// ---- interoperability -------------------------------------------------------------------

TEST(Interop, H5dumpListsTheLayout) {
  const fs::path dir = scratch("h5dump");
  write_file(dir / "a.prt.h5", make_file());
  const CmdResult r = run_command("/usr/bin/h5dump -H " + (dir / "a.prt.h5").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* s : {"GROUP \"mesh\"", "DATASET \"positions\"", "DATASET \"triangles\"",
                        "DATASET \"diffuse\"", "DATASET \"band1\"", "GROUP \"rock\"", "DATASET \"shells\"",
                        "ATTRIBUTE \"format\"", "ATTRIBUTE \"sh_order\"", "H5T_IEEE_F32LE", "H5T_STD_U32LE",
                        "H5T_STD_U8LE", "CSET H5T_CSET_UTF8"})
    EXPECT_NE(r.output.find(s), std::string::npos) << "h5dump -H output lacks " << s << ":\n" << r.output;
  const CmdResult v = run_command("/usr/bin/h5dump -d /ao " + (dir / "a.prt.h5").string());
  ASSERT_EQ(v.exit_code, 0) << v.output;
  EXPECT_NE(v.output.find("0.25, 0.5, 0.75, 1"), std::string::npos) << v.output;
}

TEST(Interop, H5pyReadsValuesAndAttributes) {
  const fs::path dir = scratch("h5py");
  const std::string python = prt::testing::python_with_h5py(dir);
  if (python.empty())
    GTEST_SKIP() << "h5py is not installed for python3 or /usr/bin/python3 "
                    "(apt-get install python3-h5py to run this test)";
  write_file(dir / "a.prt.h5", make_file());
  const std::string script =
      "import h5py, sys\n"
      "f = h5py.File(sys.argv[1], 'r')\n"
      "a = f.attrs\n"
      "s = lambda v: v.decode('utf-8')  # fixed-length strings come back as bytes\n"
      "assert s(a['format']) == 'prtbake', a['format']\n"
      "assert int(a['format_version']) == 4\n"
      "assert s(a['source']) == 'data/D\\u00fcsseldorf \\u2713.obj', a['source']\n"
      "assert f['ao'][2] == 0.75\n"
      "assert f['mesh/triangles'][1, 2] == 3 and f['mesh/triangles'].dtype == 'uint32'\n"
      "assert int(f['transfer/diffuse'].attrs['sh_order']) == 2\n"
      "assert f['transfer/diffuse'].shape == (4, 4)\n"
      "assert f['transfer/diffuse'].fletcher32 and f['transfer/diffuse'].compression == 'gzip'\n"
      "assert list(f['fiv/occluders/rock/shells'].attrs['radii']) == [3.0, 5.0]\n"
      "assert f['report'].attrs['rmse'] == 1.5e-3\n"
      "print('h5py-ok', float(f['radiance/band1'][1, 2, 0]))\n";
  const fs::path py = dir / "check.py";
  std::ofstream(py) << script;
  const CmdResult r = run_command(python + " " + py.string() + " " + (dir / "a.prt.h5").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  // radiance/band1[1][2][0] = element 1*9 + 2*3 + 0 = 15, times 0.5.
  EXPECT_NE(r.output.find("h5py-ok 7.5"), std::string::npos) << r.output;
}

TEST(Validate, AcceptsTheSyntheticFileAndNamesTheFileInErrors) {
  EXPECT_NO_THROW(validate(make_file(), "x.prt.h5"));
  File f = make_file();
  drop_root(f, "generator");
  try {
    validate(f, "x.prt.h5");
    FAIL() << "missing generator accepted";
  } catch (const FormatError& e) {
    EXPECT_EQ(std::string(e.what()), "x.prt.h5: the root group lacks the required attribute 'generator'");
  }
}

TEST(Model, PerVertexPathsAreTheSchemaOnes) {
  for (const char* p : {"/mesh/positions", "/mesh/normals", "/mesh/source_position", "/ao",
                        "/transfer/diffuse", "/transfer/visibility", "/radiance/band1"})
    EXPECT_TRUE(is_per_vertex_path(p)) << p;
  for (const char* p : {"/mesh/triangles", "/fiv/environment", "/report/ao"})
    EXPECT_FALSE(is_per_vertex_path(p)) << p;
}
