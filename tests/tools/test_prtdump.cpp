// Tests of the prtdump binary (PRT_PRTDUMP): summary, statistics, one vertex, JSON, help, and
// one-line errors with the right exit codes. Files are made with formats/ so every expected
// number is known exactly.
#include <formats/asset.h>
#include <formats/prtfile.h>
#include <formats/testing.h>

#include <gtest/gtest.h>
#include <h5py.h>
#include <hdf5_bytes.h>
#include <run_tool.h>

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

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

// A scene file as prtbake writes one (formats' asset model): a glTF object stored as
// "node0|node10|node11" (node path node0/node10/node11) and an object whose name is 120
// characters long, each with V = 2, AO and an error report whose numbers print exactly (against
// a reference of its own: the long-named object's has 4096 rays); the target error asked for is
// 0.002.
const std::string kLongName = "a_very_long_object_name_" + std::string(96, 'x');  // 120 characters
const std::string kStored = "node0|node10|node11", kNodePath = "node0/node10/node11";

Asset make_scene_asset() {
  Asset a;
  a.root = {kFormatVersion, "prtbake test", "2024-01-02T03:04:05Z", "prtbake scene s.json -o s.prt.h5", "s.json",
            std::string(64, '0'), "y", "real, l(l+1)+m, Condon-Shortley", {}};
  a.scene.emplace().integrator = "silhouette";
  auto object = [&](const std::string& name, std::optional<std::string> node_path, float ao0, float rmse,
                    const std::string& reference) {
    SceneObject& o = a.objects.emplace_back();
    o.name = name;
    o.node_path = std::move(node_path);
    o.role = "both";
    o.set.positions = Array<double>{{0, 0, 0, 1, 0.5, 0}, {}};
    o.set.normals = Normals{{0, 1, 0, 0, 1, 0}, "file", {}};
    o.set.ao.emplace().values = {ao0, 0.5f};
    ReportRow r;
    r.product = "ao";
    r.values = {rmse, 0.5f, 0.25f, 0.03125f, 0.0625f};
    r.columns = "rmse, max_abs, reference_rms, bake_std_error, reference_std_error";
    r.points = 32;
    r.reference = reference;
    r.reference_seconds = 1.5;
    r.bake_seconds = 0.5;
    r.integrals_per_second = 1000;
    o.set.report.rows.push_back(r);
    r.product = "transfer/diffuse";
    r.values[0] = rmse / 2;
    o.set.report.rows.push_back(r);
  };
  object(kStored, kNodePath, 0.75f, 0.125f, "qmc 65536 rays");
  object(kLongName, std::nullopt, 0.25f, 0.375f, "qmc 4096 rays");
  a.target_error = 2e-3;
  return a;
}

// The lines of the "Error report" section of a summary.
std::vector<std::string> report_section(const std::string& out) {
  std::vector<std::string> lines;
  std::istringstream in(out.substr(std::min(out.find("\nError report"), out.size())));
  std::string line;
  std::getline(in, line);  // the empty line before the heading
  while (std::getline(in, line) && !line.empty()) lines.push_back(line);
  return lines;
}

} // namespace

TEST(Prtdump, ReportTableKeepsItsColumnsForA120CharacterName) {
  // Issue 29: "objects/node0|node10|node11/radiance/band15.225e-02" ran the name into the
  // number. Every value must start exactly under its column's heading, names spelled as the
  // Scene section spells them, and a name longer than the column on a line of its own.
  const fs::path dir = scratch("report_table");
  write_asset(dir / "s.prt.h5", make_scene_asset());
  const CmdResult r = prtdump(dir, q(dir / "s.prt.h5"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::vector<std::string> lines = report_section(r.out);
  ASSERT_GE(lines.size(), 8u) << r.out;
  EXPECT_EQ(lines[0], "Error report (against a converged reference; times are wall seconds)");
  EXPECT_EQ(lines[1], "  target error asked for: RMSE 0.002");
  // Two references: numbered, each row naming its own in the "ref." column.
  EXPECT_EQ(lines[2], "  reference 1: qmc 4096 rays");
  EXPECT_EQ(lines[3], "  reference 2: qmc 65536 rays");
  const std::string& head = lines[4];
  ASSERT_TRUE(head.starts_with("  object ")) << head;
  const std::size_t product = head.find("product"), ref = head.find("ref."), rmse = head.find("RMSE"),
                    max = head.find("max"), ref_rms = head.find("ref. RMS"), ref_se = head.find("ref. s.e."),
                    bake_s = head.find("bake s"), ips = head.find("integrals/s");
  ASSERT_TRUE(product < ref && ref < rmse && rmse < max && max < ref_rms && ref_rms < ref_se && ref_se < bake_s &&
              bake_s < ips)
      << head;
  // Rows by object: the long name's ao and transfer/diffuse (the name on its own line first),
  // then node0/node10/node11's; an object's name in the first of its rows only.
  const std::vector<std::pair<std::string, std::string>> want = {
      {"", "ao"}, {"", "transfer/diffuse"}, {kNodePath, "ao"}, {"", "transfer/diffuse"}};
  const std::vector<std::string> want_rmse = {"3.750e-01", "1.875e-01", "1.250e-01", "6.250e-02"};
  std::size_t row = 0, long_lines = 0;
  for (std::size_t i = 5; i < lines.size(); ++i) {
    const std::string& line = lines[i];
    if (line == "  " + kLongName) {  // the long name alone; the rows under it are its
      EXPECT_EQ(row, 0u) << "before its rows";
      ++long_lines;
      continue;
    }
    ASSERT_LT(row, want.size()) << line;
    SCOPED_TRACE(line);
    ASSERT_GE(line.size(), ips + 1);
    if (!want[row].first.empty()) EXPECT_EQ(line.substr(2, kNodePath.size() + 1), kNodePath + " ");
    else EXPECT_EQ(line.find_first_not_of(' '), product) << "the object's cell is empty";
    EXPECT_EQ(line.substr(product, want[row].second.size() + 1), want[row].second + " ");
    EXPECT_EQ(line.substr(ref, 2), row < 2 ? "1 " : "2 ");
    EXPECT_EQ(line[rmse - 1], ' ');
    EXPECT_EQ(line.substr(rmse, 10), want_rmse[row] + " ");
    EXPECT_EQ(line.substr(max, 10), "5.000e-01 ");
    EXPECT_EQ(line.substr(ref_rms, 10), "2.500e-01 ");
    EXPECT_EQ(line.substr(ref_se, 10), "6.250e-02 ");
    EXPECT_EQ(line.substr(bake_s, 4), "0.5 ");
    EXPECT_EQ(line.substr(ips), "1e+03");
    ++row;
  }
  EXPECT_EQ(row, want.size());
  EXPECT_EQ(long_lines, 1u) << "the 120-character name once, on its own line";
  EXPECT_LE(head.size(), 120u) << "the columns do not grow with the long name";
}

TEST(Prtdump, JsonCarriesTheWholeReportAndTheTarget) {
  // Issue 29: --json had only a 'columns' string and min/max/mean of each 5-number row.
  const fs::path dir = scratch("report_json");
  write_asset(dir / "s.prt.h5", make_scene_asset());
  const CmdResult r = prtdump(dir, "--json " + q(dir / "s.prt.h5"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  write_file(dir / "old.prt.h5", make_file());  // no report rows, no target: an older file
  const CmdResult old = prtdump(dir, "--json " + q(dir / "old.prt.h5"));
  ASSERT_EQ(old.exit_code, 0) << old.err;
  EXPECT_NE(r.out.find("\"target_error\": 0.002"), std::string::npos) << r.out;
  EXPECT_NE(old.out.find("\"target_error\": null"), std::string::npos) << old.out;

  if (std::system("python3 -c 'import json' >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "python3 not available: JSON checked by string search only";
  std::ofstream(dir / "s.json") << r.out;
  std::ofstream(dir / "old.json") << old.out;
  // Every column of every row by name (float32 values exactly), its attributes and times, the
  // object spelled as the Scene section spells it, in the rows, the objects and the datasets.
  const std::string check =
      "python3 -c 'import json,sys; s=json.load(open(sys.argv[1])); o=json.load(open(sys.argv[2])); "
      "R=s[\"report\"]; assert R[\"target_error\"] == 0.002, R; rows=R[\"rows\"]; assert len(rows) == 4, rows; "
      "x=[r for r in rows if r[\"object\"] == \"node0/node10/node11\" and r[\"product\"] == \"transfer/diffuse\"]; "
      "assert len(x) == 1, rows; x=x[0]; "
      "assert (x[\"rmse\"], x[\"max_abs\"], x[\"reference_rms\"], x[\"bake_std_error\"], x[\"reference_std_error\"]) "
      "== (0.0625, 0.5, 0.25, 0.03125, 0.0625), x; "
      "assert x[\"points\"] == 32 and x[\"reference\"] == \"qmc 65536 rays\", x; "
      "assert (x[\"bake_seconds\"], x[\"reference_seconds\"], x[\"integrals_per_second\"]) == (0.5, 1.5, 1000), x; "
      "assert x[\"path\"] == \"/report/objects/node0|node10|node11/transfer/diffuse\", x; "
      "assert x[\"columns\"].startswith(\"rmse, max_abs\"), x; "
      "L=[r for r in rows if r[\"object\"] == \"" + kLongName + "\" and r[\"product\"] == \"ao\"]; "
      "assert len(L) == 1 and L[0][\"rmse\"] == 0.375, rows; "
      "assert [b[\"name\"] for b in s[\"objects\"]] == [\"" + kLongName + "\", \"node0/node10/node11\"], s[\"objects\"]; "
      "d={b[\"path\"]: b for b in s[\"datasets\"]}; "
      "assert d[\"/objects/node0|node10|node11/ao\"][\"object\"] == \"node0/node10/node11\"; "
      "assert d[\"/report/objects/node0|node10|node11/ao\"][\"object\"] == \"node0/node10/node11\"; "
      "assert o[\"report\"] == {\"target_error\": None, \"rows\": []}, o[\"report\"]' " +
      q(dir / "s.json") + " " + q(dir / "old.json");
  EXPECT_EQ(std::system(check.c_str()), 0) << "python3 json rejected or disagreed:\n" << r.out;
}

TEST(Prtdump, SceneObjectsByNodePathInEverySectionAndVertexByEitherSpelling) {
  const fs::path dir = scratch("objects");
  write_asset(dir / "s.prt.h5", make_scene_asset());
  const CmdResult r = prtdump(dir, q(dir / "s.prt.h5"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // The stored name only where it is labelled as such; the node path everywhere else.
  std::istringstream lines(r.out);
  std::size_t headings = 0;
  for (std::string line; std::getline(lines, line);) {
    if (line.find('|') != std::string::npos) {
      EXPECT_NE(line.find("stored as /objects/node0|node10|node11"), std::string::npos) << line;
    }
    headings += line == "  object node0/node10/node11 (stored as /objects/node0|node10|node11)";
  }
  EXPECT_EQ(headings, 3u) << "its datasets in Layout and Statistics, its group in Group attributes:\n" << r.out;
  EXPECT_NE(r.out.find("\n  node0/node10/node11 (both; stored as /objects/node0|node10|node11)\n"), std::string::npos)
      << r.out;

  for (const std::string& name : {kNodePath, kStored}) {
    const CmdResult v = prtdump(dir, "--vertex 1 --object '" + name + "' " + q(dir / "s.prt.h5"));
    ASSERT_EQ(v.exit_code, 0) << v.err;
    EXPECT_NE(v.out.find("vertex 1 of 2 (" + (dir / "s.prt.h5").string() + ", object node0/node10/node11)\n"),
              std::string::npos) << v.out;
    EXPECT_NE(v.out.find("  /mesh/positions  [1, 0.5, 0]\n"), std::string::npos) << v.out;
    EXPECT_NE(v.out.find("  /ao              0.5\n"), std::string::npos) << v.out;
  }
  const CmdResult first = prtdump(dir, "--vertex 0 --object " + kLongName + " " + q(dir / "s.prt.h5"));
  ASSERT_EQ(first.exit_code, 0) << first.err;
  EXPECT_NE(first.out.find("0.25\n"), std::string::npos) << "the long-named object's AO[0]:\n" << first.out;

  struct Case {
    std::string args, message;
  };
  const fs::path plain = dir / "plain.prt.h5";
  write_file(plain, make_file());
  for (const Case& c : std::vector<Case>{
           {"--vertex 0 " + q(dir / "s.prt.h5"), "is a scene file: its vertices belong to its 2 objects; give --vertex "
                                                  "with --object NAME, one of: " + kLongName + ", node0/node10/node11"},
           {"--vertex 0 --object node0/node10 " + q(dir / "s.prt.h5"), "has no object 'node0/node10'; its 2 objects are: "},
           {"--vertex 2 --object node0/node10/node11 " + q(dir / "s.prt.h5"),
            "vertex 2 is out of range (object node0/node10/node11 has 2 vertices: 0..1)"},
           {"--vertex 0 --object x " + q(plain), "has no scene objects"}}) {
    SCOPED_TRACE(c.args);
    const CmdResult e = prtdump(dir, c.args);
    EXPECT_EQ(e.exit_code, 1);
    EXPECT_EQ(e.out, "");
    EXPECT_NE(e.err.find(c.message), std::string::npos) << e.err;
    EXPECT_EQ(std::count(e.err.begin(), e.err.end(), '\n'), 1) << e.err;
  }
}

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

TEST(Prtdump, AVersion5FileShowsItsUvSetAndLightmap) {
  // make_file() plus a UV set (4 triangles) and a 2 x 3 lightmap: the writer makes it version 5;
  // the layout, attributes and statistics are generic, and --vertex stays per-vertex.
  const fs::path dir = scratch("v5");
  File f = make_file();
  f.datasets.push_back({"/mesh/uv", {4, 3, 2}, std::vector<float>(24, 0.5f), {{"uv_set", std::string("TEXCOORD_1")}}});
  f.datasets.push_back({"/lightmap/state", {2, 3}, std::vector<uint8_t>{1, 1, 2, 3, 0, 1}, {{"padding", int64_t{2}}}});
  f.datasets.push_back({"/lightmap/ao", {2, 3}, std::vector<float>{0.25f, 0.5f, 0.75f, 1, 0, 0.5f}, {}});
  write_file(dir / "l.prt.h5", f);
  const CmdResult r = prtdump(dir, q(dir / "l.prt.h5"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  for (const char* s : {"format_version 5", "schema   valid (schema v5", "/mesh/uv", "float32  [4, 3, 2]",
                        "uv_set = \"TEXCOORD_1\"", "/lightmap/state", "uint8    [2, 3]", "padding = 2",
                        "/lightmap/ao", "min 0  max 1  mean 0.5  nan 0  inf 0"})
    EXPECT_NE(r.out.find(s), std::string::npos) << "summary lacks '" << s << "':\n" << r.out;
  const CmdResult v = prtdump(dir, "--vertex 2 " + q(dir / "l.prt.h5"));
  ASSERT_EQ(v.exit_code, 0) << v.err;
  EXPECT_NE(v.out.find("vertex 2 of 4"), std::string::npos) << v.out;
  EXPECT_EQ(v.out.find("/lightmap"), std::string::npos) << "texels are not per-vertex:\n" << v.out;
  EXPECT_EQ(v.out.find("/mesh/uv"), std::string::npos) << "UVs are per triangle corner:\n" << v.out;
  const CmdResult j = prtdump(dir, "--json " + q(dir / "l.prt.h5"));
  ASSERT_EQ(j.exit_code, 0) << j.err;
  for (const char* s : {"\"format_version\": 5", "\"schema_valid\": true", "\"path\": \"/lightmap/state\"",
                        "\"dtype\": \"uint8\"", "\"padding\": 2", "\"uv_set\": \"TEXCOORD_1\""})
    EXPECT_NE(j.out.find(s), std::string::npos) << "JSON lacks " << s << ":\n" << j.out;
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

TEST(Prtdump, ShowsVariableLengthStringsAnotherToolAddedAndWhatADamagedHeapLeftOut) {
  // h5py's defaults (issue 28): str attributes and a list of str are variable-length strings,
  // read by the reader's own heap code. A damaged heap leaves them out: exit 0, the data whole,
  // each one named with the reason (text and --json).
  const fs::path dir = scratch("foreign_vlen_attrs");
  const std::string python = prt::testing::python_with_h5py(dir);
  if (python.empty()) GTEST_SKIP() << "h5py is not installed (apt-get install python3-h5py to run this test)";
  write_file(dir / "a.prt.h5", make_file());
  ASSERT_EQ(prt::testing::add_h5py_notes(python, dir / "a.prt.h5", "mesh", "ao", prt::testing::H5pyStrings::variable_length), "");
  const CmdResult r = prtdump(dir, q(dir / "a.prt.h5"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* s : {"schema   valid", "  note            \"root note \u2713\"", "  tags            [\"a\", \"bb\", \"ccc \u2713\"]",
                        "  fixed           \"fixed text\"", "note = \"dataset note\"", "  /mesh\n      note = \"group note\""})
    EXPECT_NE(r.out.find(s), std::string::npos) << "summary lacks '" << s << "':\n" << r.out;
  EXPECT_EQ(r.out.find("Skipped attributes"), std::string::npos) << r.out;
  const CmdResult j = prtdump(dir, "--json " + q(dir / "a.prt.h5"));
  ASSERT_EQ(j.exit_code, 0) << j.err;
  for (const char* s : {"\"note\": \"root note \u2713\"", "\"note\": \"dataset note\"", "\"note\": \"group note\"",
                        "\"fixed\": \"fixed text\"", "\"skipped_attrs\": []"})
    EXPECT_NE(j.out.find(s), std::string::npos) << "JSON lacks " << s << ":\n" << j.out;
  EXPECT_NE(j.out.find("\"tags\": [\n"), std::string::npos) << "tags is an array:\n" << j.out;

  prt::testing::Bytes bytes = prt::testing::file_bytes(dir / "a.prt.h5");
  const std::size_t gcol = prt::testing::only_collection(bytes);
  bytes[gcol + 4] = 7;  // a collection version HDF5 never wrote
  prt::testing::write_file_bytes(dir / "a.prt.h5", bytes);
  const std::string why = "cannot be read safely from the HDF5 global heap: the global heap collection at byte " +
                          std::to_string(gcol) + " has version 7 (HDF5 writes version 1)";
  const CmdResult d = prtdump(dir, q(dir / "a.prt.h5"));
  ASSERT_EQ(d.exit_code, 0) << d.err;
  for (const std::string& s : {std::string("schema   valid"), std::string("  fixed           \"fixed text\""),
                               "\nSkipped attributes (left out by the reader; the file's data is whole)\n"
                               "  attribute 'note' of the root group skipped: its text " + why + "\n"
                               "  attribute 'tags' of the root group skipped: the text of its string 0 " + why + "\n"
                               "  attribute 'note' of dataset '/ao' skipped: its text " + why + "\n"
                               "  attribute 'note' of group '/mesh' skipped: its text " + why + "\n"})
    EXPECT_NE(d.out.find(s), std::string::npos) << "summary lacks '" << s << "':\n" << d.out;
  EXPECT_EQ(d.out.find("root note"), std::string::npos) << d.out;
  const CmdResult dj = prtdump(dir, "--json " + q(dir / "a.prt.h5"));
  ASSERT_EQ(dj.exit_code, 0) << dj.err;
  for (const std::string& s : {"\"path\": \"/\",\n      \"name\": \"tags\",\n      \"reason\": \"the text of its string 0 " + why + "\"",
                               "\"path\": \"/mesh\",\n      \"name\": \"note\",\n      \"reason\": \"its text " + why + "\""})
    EXPECT_NE(dj.out.find(s), std::string::npos) << "JSON lacks " << s << ":\n" << dj.out;
}
