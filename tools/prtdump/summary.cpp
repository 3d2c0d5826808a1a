// tools/prtdump/summary.cpp — prtdump's summary: its text and JSON, the scene plan, the area
// lights and the error report (contract: summary.h).
#include "summary.h"

#include "objects.h"

#include <formats/names.h>

#include <algorithm>
#include <cstdio>
#include <functional>
#include <numbers>
#include <optional>
#include <tuple>
#include <vector>

namespace prt::tool::dump {

namespace names = prt::formats::names;

namespace {

int64_t version_of(const pf::File& f) {
  const pf::Attr* v = pf::find_attr(f.root_attrs, names::kFormatVersion);
  return v ? std::get<int64_t>(v->value) : 0;  // inspect_asset checked it is an int64
}

// The plan of a scene file: each object's role, what was baked and what was left out.
void scene_text(std::ostream& os, const pf::Asset& a) {
  if (a.objects.empty()) return;
  os << "\nScene (objects, what was baked and what was left out)\n";
  for (const pf::SceneObject& o : a.objects) {
    // A glTF scene's object by its node path; where the file stores it when that differs.
    const std::string shown = pf::object_label(o);
    os << "  " << shown << " (" << o.role.value_or("?")
       << (shown != o.name ? "; stored as " + std::string(names::kObjects) + "/" + o.name : "") << ")\n";
    for (const auto& [lines, label] : {std::pair{&o.baked, "baked      "}, std::pair{&o.left_out, "left out   "}}) {
      if (!*lines || **lines == "-") continue;
      const std::string& text = **lines;
      std::size_t start = 0;
      while (start <= text.size()) {
        const std::size_t end = std::min(text.find('\n', start), text.size());
        os << "      " << label << text.substr(start, end - start) << '\n';
        start = end + 1;
      }
    }
  }
}

// The area lights, and the irradiance each gives every vertex set that receives them.
void lights_text(std::ostream& os, const pf::Asset& a) {
  if (a.lights.empty()) return;
  const bool punctual = std::any_of(a.lights.begin(), a.lights.end(), [](const pf::Light& l) { return pf::names::is_punctual_shape(l.shape); });
  os << (punctual ? "\nLights (world space; E at unit radiance or intensity per vertex set: min, max, mean)\n"
                  : "\nArea lights (world space; E at unit radiance per vertex set: min, max, mean)\n");
  std::size_t w = 0;
  for (const pf::Light& l : a.lights) w = std::max(w, l.name.size());
  auto vec = [](const std::optional<std::vector<double>>& v) {
    return v && v->size() == 3 ? "[" + num((*v)[0]) + ", " + num((*v)[1]) + ", " + num((*v)[2]) + "]" : std::string("-");
  };
  for (const pf::Light& l : a.lights) {
    if (pf::names::is_punctual_shape(l.shape)) {
      os << "  " << pad(l.name, w + 2) << l.shape << ", intensity [" << num(l.radiance[0]) << ", " << num(l.radiance[1])
         << ", " << num(l.radiance[2]) << "]";
      if (l.position) os << ", position " << vec(l.position);
      if (l.direction) os << ", direction " << vec(l.direction);
      if (l.inner_cone_angle && l.outer_cone_angle)
        os << ", cone " << num(float(*l.inner_cone_angle * 180 / std::numbers::pi)) << " to "
           << num(float(*l.outer_cone_angle * 180 / std::numbers::pi)) << " degrees";
      if (l.range) os << ", range " << num(*l.range);
      os << ", hard shadows\n";
      continue;
    }
    os << "  " << pad(l.name, w + 2) << l.shape << ", " << l.face_sizes.values.size() << " face(s), "
       << l.vertices.values.size() / 3 << " vertices, radiance [" << num(l.radiance[0]) << ", " << num(l.radiance[1])
       << ", " << num(l.radiance[2]) << "], " << (l.two_sided.value_or(0) ? "two-sided" : "one-sided") << '\n';
  }
  auto set_lines = [&](const std::string& where, const pf::VertexSet& set) {
    if (!set.area_irradiance || !set.area_irradiance->lights) return;
    const std::vector<std::string> order = pf::split_light_list(*set.area_irradiance->lights);
    const std::vector<float>& E = set.area_irradiance->values;
    os << "  " << where << (set.area_sh ? " (and SH at order " + std::to_string(set.area_sh->sh_order.value_or(0)) + ")" : "")
       << '\n';
    for (std::size_t c = 0; c < order.size(); ++c) {
      Stats st;
      for (std::size_t i = c; i < E.size(); i += order.size()) st.add(E[i]);
      os << "      " << pad(order[c], w + 2) << "E min " << num(float(st.min)) << "  max " << num(float(st.max))
         << "  mean " << (st.mean() ? num(*st.mean()) : std::string("-")) << '\n';
    }
  };
  set_lines("/", a.vertices);
  for (const pf::SceneObject& o : a.objects) set_lines("object " + pf::object_label(o), o.set);
}

// One error-report row of the asset: whose it is (an object's label, an FIV occluder's name, or
// empty for the root layout), which product ("ao", "radiance/band1", "fiv shells") and the row.
struct ReportLine {
  std::string object, product, hdf5_path;
  const pf::ReportRow* row = nullptr;
};

// Every error-report row of the asset: the root layout's first, then by object and product.
std::vector<ReportLine> report_lines(const pf::Asset& a) {
  std::vector<ReportLine> lines;
  const std::string report = std::string(names::kReport) + "/";
  for (const pf::ReportRow& r : a.vertices.report.rows) lines.push_back({"", r.product, report + r.product, &r});
  for (const pf::SceneObject& o : a.objects)
    for (const pf::ReportRow& r : o.set.report.rows)
      lines.push_back({pf::object_label(o), r.product,
                       std::string(names::kReport) + std::string(names::kObjects) + "/" + o.name + "/" + r.product, &r});
  for (const pf::Occluder& o : a.occluders) {
    if (!o.report) continue;
    const pf::SceneObject* object = a.find_object(o.name);
    lines.push_back({object ? pf::object_label(*object) : o.name, "fiv shells",
                     std::string(names::kReportFiv) + "/" + o.name, &*o.report});
  }
  std::stable_sort(lines.begin(), lines.end(), [](const ReportLine& x, const ReportLine& y) {
    return std::tie(x.object, x.product) < std::tie(y.object, y.product);
  });
  return lines;
}

// The report's object column is at most this wide; a longer name gets a line of its own above
// its row, so the numbers stay in their columns whatever the names.
constexpr std::size_t kMaxNameColumn = 40;

// The error against run time stored under /report: a table whose columns are as wide as their
// content (names longer than kMaxNameColumn on their own line), and the target asked for.
void report_text(std::ostream& os, const pf::Asset& a) {
  const std::vector<ReportLine> lines = report_lines(a);
  if (lines.empty() && !a.target_error) return;
  os << "\nError report (against a converged reference; times are wall seconds)\n";
  if (a.target_error) os << "  target error asked for: RMSE " << num(*a.target_error) << '\n';
  if (lines.empty()) return;
  std::vector<std::string> references;
  for (const ReportLine& l : lines)
    if (l.row->reference && std::find(references.begin(), references.end(), *l.row->reference) == references.end())
      references.push_back(*l.row->reference);
  // One reference: said once. Several (a scene's AO, FIV shells, glossy objects): numbered, and
  // each row says which in its "ref." column.
  const bool numbered = references.size() > 1;
  for (std::size_t i = 0; i < references.size(); ++i)
    os << "  reference" << (numbered ? " " + std::to_string(i + 1) : std::string()) << ": " << references[i] << '\n';
  auto reference_number = [&](const pf::ReportRow& r) {
    if (!r.reference) return std::string("-");
    return std::to_string(std::find(references.begin(), references.end(), *r.reference) - references.begin() + 1);
  };

  auto sci = [](double x) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3e", x);
    return std::string(buf);
  };
  auto seconds = [](const std::optional<double>& x) {
    char buf[32];
    if (!x) return std::string("-");
    std::snprintf(buf, sizeof buf, "%.3g", *x);
    return std::string(buf);
  };
  const bool objects = std::any_of(lines.begin(), lines.end(), [](const ReportLine& l) { return !l.object.empty(); });
  std::vector<std::vector<std::string>> rows;  // cells; the object's cell first, empty below its first row
  rows.push_back({"object", "product", "ref.", "RMSE", "max", "ref. RMS", "ref. s.e.", "bake s", "ref. s", "integrals/s"});
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const ReportLine& l = lines[i];
    const pf::ReportRow& r = *l.row;
    const bool same = i > 0 && lines[i - 1].object == l.object;
    rows.push_back({same ? std::string() : l.object.empty() ? std::string("-") : l.object, l.product, reference_number(r),
                    sci(r.values[0]),
                    sci(r.values[1]), sci(r.values[2]), sci(r.values[4]), seconds(r.bake_seconds),
                    seconds(r.reference_seconds), seconds(r.integrals_per_second)});
  }
  std::vector<std::size_t> width(rows[0].size(), 0);
  for (const auto& row : rows)
    for (std::size_t c = 0; c < row.size(); ++c)
      if (c != 0 || row[c].size() <= kMaxNameColumn) width[c] = std::max(width[c], row[c].size());
  for (const auto& row : rows) {
    std::string line = "  ";
    for (std::size_t c = objects ? 0 : 1; c < row.size(); ++c) {
      if (c == 2 && !numbered) continue;  // the "ref." column only with several references
      std::string cell = row[c];
      if (c == 0 && cell.size() > width[0]) {  // a long name: its own line, the row below it
        os << "  " << cell << '\n';
        cell.clear();
      }
      line += c + 1 < row.size() ? pad(cell, width[c] + 2) : cell;
    }
    os << line << '\n';
  }
}

// The whole error report: the target asked for, and every /report row with its five columns
// by name, its attributes and whose it is (object as the Scene section names it; null: the
// root layout). null for the JSON of a file without a report.
Json report_json(const pf::Asset& a) {
  const std::vector<ReportLine> lines = report_lines(a);
  Json r = Json::object();
  r["target_error"] = a.target_error ? json_double(*a.target_error) : Json(nullptr);
  Json rows = Json::array();
  // asset.h ReportRow: the five columns of every row, in this order.
  static constexpr const char* kColumnNames[5] = {"rmse", "max_abs", "reference_rms", "bake_std_error",
                                                  "reference_std_error"};
  for (const ReportLine& l : lines) {
    const pf::ReportRow& row = *l.row;
    Json x = Json::object();
    x["object"] = l.object.empty() ? Json(nullptr) : Json(l.object);
    x["product"] = l.product;
    x["path"] = l.hdf5_path;
    for (std::size_t c = 0; c < 5; ++c) x[kColumnNames[c]] = json_float(row.values[c]);
    x["columns"] = row.columns ? Json(*row.columns) : Json(nullptr);
    x["points"] = row.points ? Json(*row.points) : Json(nullptr);
    x["reference"] = row.reference ? Json(*row.reference) : Json(nullptr);
    x["reference_seconds"] = row.reference_seconds ? json_double(*row.reference_seconds) : Json(nullptr);
    x["bake_seconds"] = row.bake_seconds ? json_double(*row.bake_seconds) : Json(nullptr);
    x["integrals_per_second"] = row.integrals_per_second ? json_double(*row.integrals_per_second) : Json(nullptr);
    x["mesh_rms"] = row.mesh_rms ? json_double(*row.mesh_rms) : Json(nullptr);
    if (!row.extra.empty()) x["attrs"] = json_attrs(row.extra);
    rows.push_back(std::move(x));
  }
  r["rows"] = std::move(rows);
  return r;
}

} // namespace

void summary_text(std::ostream& os, const std::string& path, const pf::Inspection& in) {
  const pf::File& f = in.file;
  os << "file     " << path << '\n';
  os << "format   prtbake, " << names::kFormatVersion << ' ' << version_of(f) << '\n';
  os << "schema   "
     << (in.schema_error ? "INVALID: " + *in.schema_error
                         : "valid (schema v" + std::to_string(version_of(f)) + ", this prtdump reads 1.." +
                               std::to_string(pf::kFormatVersion) + ")")
     << "\n\nRoot attributes\n";
  std::size_t w = 0;
  for (const pf::Attr& a : f.root_attrs) w = std::max(w, a.name.size());
  for (const pf::Attr& a : f.root_attrs) os << "  " << pad(a.name, w + 2) << attr_text(a.value) << '\n';

  // Datasets of no scene object by their path; each object's under a heading with its name,
  // by their path within it (the HDF5 path is the heading's group + that path).
  const std::vector<FileObject> objects = file_objects(f);
  const DatasetGroups groups = group_datasets(f, objects);
  w = 0;
  for (const pf::Dataset* d : groups.loose) w = std::max(w, d->path.size());
  for (const auto& [o, list] : groups.objects)
    for (const auto& [d, rest] : list) w = std::max(w, rest.size() + 2);
  auto each_dataset = [&](const std::function<void(const pf::Dataset&, const std::string&)>& line) {
    for (const pf::Dataset* d : groups.loose) line(*d, "  " + pad(d->path, w + 2));
    for (const auto& [o, list] : groups.objects) {
      if (list.empty()) continue;
      os << "  " << object_heading(*o) << '\n';
      for (const auto& [d, rest] : list) line(*d, "    " + pad(rest, w));
    }
  };
  os << "\nLayout (" << f.datasets.size() << " datasets)\n";
  each_dataset([&](const pf::Dataset& d, const std::string& head) {
    os << head << pad(std::string(pf::dtype_name(d.data)), 9) << shape_text(d.shape) << '\n';
    attrs_text(os, d.attrs);
  });
  if (in.asset) {
    scene_text(os, *in.asset);
    lights_text(os, *in.asset);
    report_text(os, *in.asset);
  }
  if (!f.group_attrs.empty()) {
    os << "\nGroup attributes\n";
    for (const auto& [g, attrs] : f.group_attrs) {
      // An object's group by the object's name (and where it is stored).
      const ObjectPath op = object_path(objects, g);
      if (op.object) os << "  " << object_heading(*op.object) << (op.rest.empty() ? "" : ": " + op.rest) << '\n';
      else os << "  " << g << '\n';
      attrs_text(os, attrs);
    }
  }
  if (!f.skipped_attrs.empty()) {
    os << "\nSkipped attributes (left out by the reader; the file's data is whole)\n";
    for (const pf::SkippedAttr& s : f.skipped_attrs) os << "  " << pf::describe(s) << '\n';
  }
  os << "\nStatistics (min, max, mean over finite values; counts of NaN and Inf)\n";
  each_dataset([&](const pf::Dataset& d, const std::string& head) {
    const DatasetStats s = compute_stats(d);
    print_stats_text(os, d, s.all, head);
    for (std::size_t c = 0; c < s.columns.size(); ++c)
      print_stats_text(os, d, s.columns[c], "      [..., " + std::to_string(c) + "]  ");
  });
}

Json summary_json(const std::string& path, const pf::Inspection& in) {
  const pf::File& f = in.file;
  Json j = Json::object();
  j["file"] = path;
  j[std::string(names::kFormatVersion)] = version_of(f);
  j["schema_valid"] = !in.schema_error;
  j["schema_error"] = in.schema_error ? Json(*in.schema_error) : Json(nullptr);
  j["root_attrs"] = json_attrs(f.root_attrs);
  Json groups = Json::object();
  for (const auto& [g, attrs] : f.group_attrs) groups[g] = json_attrs(attrs);
  j["group_attrs"] = std::move(groups);
  Json skipped = Json::array();
  for (const pf::SkippedAttr& s : f.skipped_attrs)
    skipped.push_back({{"path", s.path}, {"name", s.name}, {"reason", s.reason}});
  j["skipped_attrs"] = std::move(skipped);
  // Scene objects by the name people read ("name": the node path of a glTF scene's object) and
  // the group the file stores them in; every "object" below spells the name the same way.
  const std::vector<FileObject> objects = file_objects(f);
  Json jobjects = Json::array();
  for (const FileObject& o : objects) {
    Json x = Json::object();
    x["name"] = o.label();
    x["group"] = std::string(names::kObjects) + "/" + o.name;
    if (in.asset)
      if (const pf::SceneObject* so = in.asset->find_object(o.name)) {
        x["role"] = so->role ? Json(*so->role) : Json(nullptr);
        x["baked"] = so->baked ? Json(*so->baked) : Json(nullptr);
        x["left_out"] = so->left_out ? Json(*so->left_out) : Json(nullptr);
      }
    jobjects.push_back(std::move(x));
  }
  j["objects"] = std::move(jobjects);
  j["report"] = in.asset ? report_json(*in.asset) : Json(nullptr);
  Json datasets = Json::array();
  for (const pf::Dataset& d : f.datasets) {
    const DatasetStats s = compute_stats(d);
    Json o = Json::object();
    o["path"] = d.path;
    if (const ObjectPath op = object_path(objects, d.path); op.object) o["object"] = op.object->label();
    o["dtype"] = pf::dtype_name(d.data);
    o["shape"] = d.shape;
    o["attrs"] = json_attrs(d.attrs);
    o["stats"] = json_stats(d, s.all, true);
    if (!s.columns.empty()) {
      Json columns = Json::array();
      for (const Stats& c : s.columns) columns.push_back(json_stats(d, c, false));
      o["columns"] = std::move(columns);
    }
    datasets.push_back(std::move(o));
  }
  j["datasets"] = std::move(datasets);
  return j;
}

} // namespace prt::tool::dump
