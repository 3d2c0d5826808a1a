// Tests of the prtdump binary (PRT_PRTDUMP): summary, statistics, one vertex, JSON, help, and
// one-line errors with the right exit codes. Files are made with formats/ so every expected
// number is known exactly.
#include <formats/prtfile.h>
#include <formats/testing.h>

#include <gtest/gtest.h>
#include <h5py.h>
#include <run_tool.h>

#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <fstream>

namespace fs = std::filesystem;
using namespace prt::formats;

namespace {

struct CmdResult {
  int exit_code = -1;
  std::string out, err;
};

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(PRT_TEST_TMP) / "prtdump" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// Runs prtdump with `args` (already shell-quoted), capturing stdout and stderr separately.
CmdResult prtdump(const fs::path& dir, const std::string& args) {
  const auto r = prt::testing::run_tool(PRT_PRTDUMP, args, dir);
  return {r.code, r.out, r.err};
}

std::string q(const fs::path& p) { return "'" + p.string() + "'"; }

// V = 4 vertices, L = 2 bands; every value chosen so the statistics are exact in print.
File make_file() {
  File f;
  f.root_attrs = {{"generator", std::string("prtbake test")},
                  {"created", std::string("2024-01-02T03:04:05Z")},
                  {"command_line", std::string("prtbake vertex \"q.obj\"\t-o x")},
                  {"source", std::string("q.obj")},
                  {"source_sha256", std::string(64, '0')},
                  {"up_axis", std::string("z")},
                  {"sh_convention", std::string("real, l(l+1)+m, Condon-Shortley")}};
  f.datasets.push_back({"/mesh/positions", {4, 3}, std::vector<float>{0, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0, 3}, {}});
  f.datasets.push_back({"/mesh/normals", {4, 3}, std::vector<float>{0, 0, 1, 0, 0, 1, 0, 1, 0, 1, 0, 0}, {}});
  f.datasets.push_back({"/mesh/triangles", {4, 3}, std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 0, 3, 1, 1, 3, 2}, {}});
  f.datasets.push_back({"/ao", {4}, std::vector<float>{0.25f, 0.5f, 0.75f, 1.0f}, {}});
  std::vector<float> t(16);
  for (std::size_t i = 0; i < t.size(); ++i) t[i] = static_cast<float>(i) * 0.125f;
  f.datasets.push_back({"/transfer/diffuse", {4, 4}, t, {{"sh_order", int64_t{2}}}});
  std::vector<float> r(36);
  for (std::size_t i = 0; i < r.size(); ++i) r[i] = static_cast<float>(i);
  f.datasets.push_back({"/radiance/band1", {4, 3, 3}, r, {}});
  f.group_attrs.push_back({"/report", {{"rmse", 0.0625}}});
  return f;
}

} // namespace

TEST(Prtdump, SummaryListsLayoutAttributesAndExactStatistics) {
  const fs::path dir = scratch("summary");
  write_file(dir / "a.prt.h5", make_file());
  const CmdResult r = prtdump(dir, q(dir / "a.prt.h5"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  for (const char* s : {"/mesh/positions", "/mesh/normals", "/mesh/triangles", "/ao", "/transfer/diffuse",
                        "/radiance/band1", "format_version 4", "schema   valid", "sh_order = 2",
                        "rmse = 0.0625", "up_axis", "\"z\"", "float32  [4, 3]", "uint32   [4, 3]"})
    EXPECT_NE(r.out.find(s), std::string::npos) << "summary lacks '" << s << "':\n" << r.out;
  // /ao = {0.25, 0.5, 0.75, 1}: min 0.25, max 1, mean 0.625, no NaN or Inf.
  EXPECT_NE(r.out.find("min 0.25  max 1  mean 0.625  nan 0  inf 0"), std::string::npos) << r.out;
  // Per-column statistics of /mesh/positions: column 1 (y) is {0, 0, 2, 0}: mean 0.5.
  EXPECT_NE(r.out.find("[..., 1]  min 0  max 2  mean 0.5"), std::string::npos) << r.out;
  // /transfer/diffuse = i/8 for i = 0..15: mean 15/16.
  EXPECT_NE(r.out.find("min 0  max 1.875  mean 0.9375"), std::string::npos) << r.out;
}

TEST(Prtdump, VertexPrintsTheKnownValuesByTrailingAxes) {
  const fs::path dir = scratch("vertex");
  write_file(dir / "a.prt.h5", make_file());
  const CmdResult r = prtdump(dir, "--vertex 2 " + q(dir / "a.prt.h5"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("vertex 2 of 4"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("[0, 2, 0]"), std::string::npos) << "position of vertex 2:\n" << r.out;
  EXPECT_NE(r.out.find("0.75"), std::string::npos) << "ao of vertex 2:\n" << r.out;
  // transfer row 2 = {1, 1.125, 1.25, 1.375}: band 0 then band 1.
  EXPECT_NE(r.out.find("l=0  [1]"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("l=1  [1.125, 1.25, 1.375]"), std::string::npos) << r.out;
  // radiance/band1 of vertex 2 = 18..26, rows R, G, B.
  EXPECT_NE(r.out.find("R  [18, 19, 20]"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("B  [24, 25, 26]"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("/mesh/triangles"), std::string::npos) << "triangles are not per-vertex:\n" << r.out;
}

TEST(Prtdump, JsonHasTheKeyFieldsAndParses) {
  const fs::path dir = scratch("json");
  write_file(dir / "a.prt.h5", make_file());
  const CmdResult r = prtdump(dir, "--json " + q(dir / "a.prt.h5"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* s : {"\"format_version\": 4", "\"schema_valid\": true", "\"path\": \"/ao\"",
                        "\"dtype\": \"uint32\"", "\"sh_order\": 2", "\"min\": 0.25", "\"mean\": 0.625",
                        "\"nan\": 0", "\"/report\": {", "\"rmse\": 0.0625",
                        "\"command_line\": \"prtbake vertex \\\"q.obj\\\"\\t-o x\""})
    EXPECT_NE(r.out.find(s), std::string::npos) << "JSON lacks " << s << ":\n" << r.out;
  const CmdResult v = prtdump(dir, "--json --vertex 3 " + q(dir / "a.prt.h5"));
  ASSERT_EQ(v.exit_code, 0) << v.err;
  EXPECT_NE(v.out.find("\"vertex\": 3"), std::string::npos) << v.out;
  EXPECT_NE(v.out.find("\"/ao\": 1"), std::string::npos) << v.out;

  // A real parser, when there is one (Python's json is in every python3).
  if (std::system("python3 -c 'import json' >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "python3 not available: JSON checked by string search only";
  std::ofstream(dir / "summary.json") << r.out;
  std::ofstream(dir / "vertex.json") << v.out;
  const std::string check =
      "python3 -c 'import json,sys; s=json.load(open(sys.argv[1])); v=json.load(open(sys.argv[2])); "
      "d={x[\"path\"]: x for x in s[\"datasets\"]}; "
      "assert d[\"/ao\"][\"stats\"][\"mean\"] == 0.625; "
      "assert d[\"/mesh/positions\"][\"columns\"][1][\"max\"] == 2; "
      "assert v[\"values\"][\"/radiance/band1\"][2] == [33, 34, 35]; "
      "assert v[\"values\"][\"/mesh/normals\"] == [1, 0, 0]' " +
      q(dir / "summary.json") + " " + q(dir / "vertex.json");
  EXPECT_EQ(std::system(check.c_str()), 0) << "python3 json rejected or disagreed:\n" << r.out << v.out;
}

TEST(Prtdump, ShowsNaNCountsAndSchemaDefectOfABadFile) {
  const fs::path dir = scratch("nan");
  File f = make_file();
  f.root_attrs.push_back({"format", std::string("prtbake")});
  f.root_attrs.push_back({"format_version", int64_t{1}});
  std::get<std::vector<float>>(f.datasets[3].data)[1] = std::nanf("");  // /ao[1]
  std::get<std::vector<float>>(f.datasets[3].data)[2] = INFINITY;       // /ao[2]
  prt::formats::testing::write_file_unvalidated(dir / "nan.prt.h5", f);
  const CmdResult r = prtdump(dir, q(dir / "nan.prt.h5"));
  ASSERT_EQ(r.exit_code, 0) << "prtdump shows an invalid file so you can see what is wrong: " << r.err;
  EXPECT_NE(r.out.find("schema   INVALID: dataset '/ao' has a non-finite value (NaN) at index 1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("min 0.25  max 1  mean 0.625  nan 1  inf 1"), std::string::npos) << r.out;
  const CmdResult j = prtdump(dir, "--json --vertex 1 " + q(dir / "nan.prt.h5"));
  ASSERT_EQ(j.exit_code, 0) << j.err;
  EXPECT_NE(j.out.find("\"/ao\": null"), std::string::npos) << "NaN must be null in JSON:\n" << j.out;
}

TEST(Prtdump, VertexOfAFileThatFailsTheSchemaStaysInBounds) {
  // Attributes that lie about the shape (issue 11): sh_order = -1 on a [V, 1] transfer (-1² = 1
  // matched the row width and the band loop ran 2^64 times), sh_order = 3037000500 (its square
  // overflows), and a band-1 radiance with 4 rows (the R/G/B labels ran off their string). Each
  // is shown by its shape instead, within the dataset.
  for (const int64_t order : {int64_t{-1}, int64_t{3037000500}}) {
    SCOPED_TRACE(order);
    const fs::path dir = scratch("lying_attrs");
    File f = make_file();
    f.root_attrs.push_back({"format", std::string("prtbake")});
    f.root_attrs.push_back({"format_version", int64_t{2}});
    f.datasets[4] = {"/transfer/diffuse", {4, 1}, std::vector<float>{0.5f, 1.5f, 2.5f, 3.5f}, {{"sh_order", order}}};
    std::vector<float> r(48);
    for (std::size_t i = 0; i < r.size(); ++i) r[i] = static_cast<float>(i);
    f.datasets[5] = {"/radiance/band1", {4, 4, 3}, r, {}};
    prt::formats::testing::write_file_unvalidated(dir / "lying.prt.h5", f);
    const CmdResult v = prtdump(dir, "--vertex 1 " + q(dir / "lying.prt.h5"));
    ASSERT_EQ(v.exit_code, 0) << v.err;
    EXPECT_NE(v.out.find("1.5"), std::string::npos) << v.out;       // vertex 1's transfer value
    EXPECT_NE(v.out.find("[3]  [21, 22, 23]"), std::string::npos) << v.out;  // its 4th radiance row, by index
    EXPECT_EQ(v.out.find("l=1"), std::string::npos) << "no band loop past the data:\n" << v.out;
  }
}

TEST(Prtdump, BadInputsGiveOneLineNamingTheFileAndExitCodes) {
  const fs::path dir = scratch("errors");
  write_file(dir / "a.prt.h5", make_file());
  std::ofstream(dir / "junk.prt.h5") << "this is not HDF5\n";
  File foreign = make_file();
  prt::formats::testing::write_file_unvalidated(dir / "foreign.h5", foreign);  // no 'format'

  struct Case {
    std::string args, file, message;
  };
  const std::vector<Case> cases = {
      {q(dir / "missing.prt.h5"), (dir / "missing.prt.h5").string(), "no such file"},
      {q(dir / "junk.prt.h5"), (dir / "junk.prt.h5").string(), "not an HDF5 file"},
      {q(dir / "foreign.h5"), (dir / "foreign.h5").string(), "not a prtbake file"},
      {"--vertex 4 " + q(dir / "a.prt.h5"), (dir / "a.prt.h5").string(), "vertex 4 is out of range"},
  };
  for (const Case& c : cases) {
    const CmdResult r = prtdump(dir, c.args);
    EXPECT_EQ(r.exit_code, 1) << c.args;
    EXPECT_EQ(r.out, "") << c.args;
    EXPECT_NE(r.err.find(c.file + ": "), std::string::npos) << "stderr must name the file: " << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
  }
  for (const std::string& args : {std::string(""), std::string("--vertex x ") + q(dir / "a.prt.h5"),
                                 std::string("--bogus ") + q(dir / "a.prt.h5"),
                                 q(dir / "a.prt.h5") + " " + q(dir / "a.prt.h5")}) {
    const CmdResult r = prtdump(dir, args);
    EXPECT_EQ(r.exit_code, 2) << "usage error for '" << args << "': " << r.err;
    EXPECT_NE(r.err.find("usage: prtdump"), std::string::npos) << r.err;
  }
}

TEST(Prtdump, HelpTeachesUsageOptionsAndSections) {
  const fs::path dir = scratch("help");
  const CmdResult r = prtdump(dir, "--help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* s : {"Usage:", "--vertex I", "--json", "Example:", "Statistics", "Exit status"})
    EXPECT_NE(r.out.find(s), std::string::npos) << "help lacks " << s << ":\n" << r.out;
}

TEST(Prtdump, ShowsAttributesAnotherToolAdded) {
  // Fixed-length string attributes h5py added: prtdump shows them and the file stays valid.
  const fs::path dir = scratch("foreign_attrs");
  const std::string python = prt::testing::python_with_h5py(dir);
  if (python.empty()) GTEST_SKIP() << "h5py is not installed (apt-get install python3-h5py to run this test)";
  write_file(dir / "a.prt.h5", make_file());
  ASSERT_EQ(prt::testing::add_h5py_notes(python, dir / "a.prt.h5", "mesh", "ao"), "");
  const CmdResult r = prtdump(dir, q(dir / "a.prt.h5"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* s : {"schema   valid", "  note            \"root note \u2713\"", "note = \"dataset note\"",
                        "  /mesh\n      note = \"group note\""})
    EXPECT_NE(r.out.find(s), std::string::npos) << "summary lacks '" << s << "':\n" << r.out;
  const CmdResult j = prtdump(dir, "--json " + q(dir / "a.prt.h5"));
  ASSERT_EQ(j.exit_code, 0) << j.err;
  for (const char* s : {"\"note\": \"root note \u2713\"", "\"note\": \"dataset note\"", "\"/mesh\": {"})
    EXPECT_NE(j.out.find(s), std::string::npos) << "JSON lacks " << s << ":\n" << j.out;
}
