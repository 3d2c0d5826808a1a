// prtdump — inspect a baked file: root attributes, layout, per-dataset statistics, one vertex,
// or the same as JSON. A thin shell: formats/ reads the file; this file only computes summary
// statistics and prints.
#include <formats/prtfile.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace fmt = prt::formats;

namespace {

constexpr std::size_t kMaxColumnsForStats = 16;

const char* const kHelp = R"(prtdump — inspect a prtbake file (HDF5, schema version 1)

Usage:
  prtdump [--json] FILE.prt.h5               summary: attributes, layout, statistics
  prtdump [--json] --vertex I FILE.prt.h5    every per-vertex value of vertex I
  prtdump --help

Options:
  --vertex I   print vertex I (0-based) from every per-vertex dataset (/mesh/positions,
               /mesh/normals, /mesh/source_position, /ao, /transfer/*, /radiance/band1);
               V, the vertex count, is the number of rows of /mesh/positions.
  --json       print the same information as one JSON object (for scripts). Numbers are
               exact (shortest round-trip form); NaN and Inf become null.
  -h, --help   this text.

Example:
  prtbake vertex bunny.obj --transfer 3 -o bunny.prt.h5
  prtdump bunny.prt.h5
  prtdump --vertex 0 bunny.prt.h5
  prtdump --json bunny.prt.h5 | python3 -m json.tool

What the summary shows:
  format / schema  the format version and whether the file passes the schema check
                   (prtdump still shows a file that fails it, so you can see what is wrong;
                   the runtime and other readers reject such files).
  Root attributes  who wrote the file, when, from which source (and its SHA-256), the
                   command line, the up axis and the SH convention (see formats/SCHEMA.md).
  Layout           each dataset: path, element type, shape and its attributes (e.g. sh_order
                   = L, the number of SH bands, so a transfer vector has L*L coefficients).
  Scene            for scene files (prtbake scene): each object's role and what the bake
                   baked and left out, with the reasons.
  Error report     per product: RMSE and max error against the converged reference, the
                   reference's own standard error, bake and reference wall times.
  Group attributes attributes on groups such as /scene and /objects/<name>.
  Statistics       per dataset: min, max and mean over the finite values, and the number of
                   NaN and Inf values (a valid file has none). For a dataset whose last axis is
                   small (<= 16, e.g. xyz, RGB or SH coefficients) also per-column min/max/mean,
                   where column j is [..., j].
  --vertex         values are laid out by the trailing axes: [V, 3] prints one [x, y, z] row;
                   [V, L*L] prints one row per SH band l (index l*(l+1)+m, m = -l..l);
                   [V, 3, 3] (radiance/band1) prints one row per channel R, G, B with
                   m = -1, 0, 1.

Exit status: 0 success, 1 bad file or vertex out of range (one line on stderr naming the
file), 2 usage error.
)";

// ---- number formatting -------------------------------------------------------------------

std::string num(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}
std::string num(float v) {
  if (!std::isfinite(v)) return num(static_cast<double>(v));
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}
// An element of a dataset: float32 in its own shortest form, integers exactly.
std::string element(const fmt::DatasetData& data, std::size_t i) {
  if (const auto* f = std::get_if<std::vector<float>>(&data)) return num((*f)[i]);
  if (const auto* u = std::get_if<std::vector<uint32_t>>(&data)) return std::to_string((*u)[i]);
  return std::to_string(std::get<std::vector<uint8_t>>(data)[i]);
}
double element_value(const fmt::DatasetData& data, std::size_t i) {
  return std::visit([i](const auto& v) { return static_cast<double>(v[i]); }, data);
}

// ---- JSON ----------------------------------------------------------------------------------

std::string json_string(std::string_view s) {
  std::string out = "\"";
  for (char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    switch (ch) {
    case '"': out += "\\\""; break;
    case '\\': out += "\\\\"; break;
    case '\b': out += "\\b"; break;
    case '\f': out += "\\f"; break;
    case '\n': out += "\\n"; break;
    case '\r': out += "\\r"; break;
    case '\t': out += "\\t"; break;
    default:
      if (c < 0x20 || c == 0x7F) {
        char buf[8];
        std::snprintf(buf, sizeof buf, "\\u%04x", c);
        out += buf;
      } else {
        out += ch;
      }
    }
  }
  return out + "\"";
}
std::string json_num(double v) { return std::isfinite(v) ? num(v) : "null"; }
std::string json_element(const fmt::DatasetData& data, std::size_t i) {
  if (const auto* f = std::get_if<std::vector<float>>(&data))
    return std::isfinite((*f)[i]) ? num((*f)[i]) : "null";
  return element(data, i);
}

// A tiny streaming JSON writer: objects/arrays with indentation and comma bookkeeping.
class Json {
public:
  explicit Json(std::ostream& os) : os_(os) {}
  void begin_object() { open('{'); }
  void end_object() { close('}'); }
  void begin_array() { open('['); }
  // An array of scalars on one line: [1, 2, 3].
  void begin_inline_array() {
    item();
    os_ << '[';
    first_.push_back(true);
    inline_.push_back(true);
  }
  void end_array() { close(']'); }
  void key(std::string_view k) {
    item();
    os_ << json_string(k) << ": ";
    after_key_ = true;
  }
  void raw(const std::string& v) {  // an already-encoded JSON value
    item();
    os_ << v;
  }
  void string(std::string_view s) { raw(json_string(s)); }
  void number(double v) { raw(json_num(v)); }
  void integer(int64_t v) { raw(std::to_string(v)); }
  void boolean(bool b) { raw(b ? "true" : "false"); }
  void null() { raw("null"); }

private:
  void item() {
    if (after_key_) {
      after_key_ = false;
      return;
    }
    if (!first_.empty() && inline_.back()) {
      if (!first_.back()) os_ << ", ";
      first_.back() = false;
    } else if (!first_.empty()) {
      if (!first_.back()) os_ << ',';
      first_.back() = false;
      os_ << '\n' << std::string(2 * first_.size(), ' ');
    }
  }
  void open(char c) {
    item();
    os_ << c;
    first_.push_back(true);
    inline_.push_back(false);
  }
  void close(char c) {
    const bool empty = first_.back(), was_inline = inline_.back();
    first_.pop_back();
    inline_.pop_back();
    if (!empty && !was_inline) os_ << '\n' << std::string(2 * first_.size(), ' ');
    os_ << c;
    if (first_.empty()) os_ << '\n';
  }
  std::ostream& os_;
  std::vector<bool> first_, inline_;
  bool after_key_ = false;
};

void json_attr_value(Json& j, const fmt::AttrValue& v) {
  std::visit(
      [&j](const auto& x) {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, std::string>) j.string(x);
        else if constexpr (std::is_same_v<T, int64_t>) j.integer(x);
        else if constexpr (std::is_same_v<T, double>) j.number(x);
        else {
          j.begin_inline_array();
          for (const auto& e : x) {
            if constexpr (std::is_same_v<T, std::vector<double>>) j.number(e);
            else j.integer(e);
          }
          j.end_array();
        }
      },
      v);
}
void json_attrs(Json& j, const std::vector<fmt::Attr>& attrs) {
  j.begin_object();
  for (const fmt::Attr& a : attrs) {
    j.key(a.name);
    json_attr_value(j, a.value);
  }
  j.end_object();
}

// ---- text helpers ------------------------------------------------------------------------

std::string attr_text(const fmt::AttrValue& v) {
  return std::visit(
      [](const auto& x) -> std::string {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, std::string>) return json_string(x);
        else if constexpr (std::is_same_v<T, int64_t>) return std::to_string(x);
        else if constexpr (std::is_same_v<T, double>) return num(x);
        else {
          std::string s = "[";
          for (std::size_t i = 0; i < x.size(); ++i) {
            if (i) s += ", ";
            if constexpr (std::is_same_v<T, std::vector<double>>) s += num(x[i]);
            else s += std::to_string(x[i]);
          }
          return s + "]";
        }
      },
      v);
}
std::string shape_text(const std::vector<uint64_t>& shape) {
  std::string s = "[";
  for (std::size_t i = 0; i < shape.size(); ++i) s += (i ? ", " : "") + std::to_string(shape[i]);
  return s + "]";
}
std::string pad(std::string s, std::size_t width) {
  if (s.size() < width) s.append(width - s.size(), ' ');
  return s;
}

// ---- statistics --------------------------------------------------------------------------

struct Stats {
  uint64_t finite = 0, nan = 0, inf = 0;
  double min = std::numeric_limits<double>::infinity();
  double max = -std::numeric_limits<double>::infinity();
  double sum = 0;
  void add(double v) {
    if (std::isnan(v)) ++nan;
    else if (std::isinf(v)) ++inf;
    else {
      ++finite;
      min = std::min(min, v);
      max = std::max(max, v);
      sum += v;
    }
  }
  std::optional<double> mean() const {
    return finite ? std::optional<double>(sum / static_cast<double>(finite)) : std::nullopt;
  }
};

struct DatasetStats {
  Stats all;
  std::vector<Stats> columns;  // empty unless rank >= 2 and the last axis is small
};

DatasetStats compute_stats(const fmt::Dataset& d) {
  DatasetStats s;
  const std::size_t n = fmt::element_count(d.data);
  const uint64_t last = d.shape.empty() ? 1 : d.shape.back();
  if (d.shape.size() >= 2 && last >= 1 && last <= kMaxColumnsForStats) s.columns.resize(last);
  for (std::size_t i = 0; i < n; ++i) {
    const double v = element_value(d.data, i);
    s.all.add(v);
    if (!s.columns.empty()) s.columns[i % last].add(v);
  }
  return s;
}

// min/max are values of the dataset: print them in the dataset's own precision.
std::string stat_value(const fmt::Dataset& d, double v) {
  if (d.data.index() == 0) return num(static_cast<float>(v));
  return num(v);
}

void print_stats_text(std::ostream& os, const fmt::Dataset& d, const Stats& s, const std::string& label) {
  os << label;
  if (s.finite == 0) os << "min -  max -  mean -";
  else
    os << "min " << stat_value(d, s.min) << "  max " << stat_value(d, s.max) << "  mean "
       << num(*s.mean());
  if (d.data.index() == 0) os << "  nan " << s.nan << "  inf " << s.inf;
  os << '\n';
}

void json_stats(Json& j, const fmt::Dataset& d, const Stats& s, bool counts) {
  j.begin_object();
  j.key("min");
  s.finite ? j.raw(json_num(d.data.index() == 0 ? static_cast<double>(static_cast<float>(s.min)) : s.min)) : j.null();
  j.key("max");
  s.finite ? j.raw(json_num(d.data.index() == 0 ? static_cast<double>(static_cast<float>(s.max)) : s.max)) : j.null();
  j.key("mean");
  s.finite ? j.number(*s.mean()) : j.null();
  if (counts) {
    j.key("finite");
    j.integer(static_cast<int64_t>(s.finite));
    j.key("nan");
    j.integer(static_cast<int64_t>(s.nan));
    j.key("inf");
    j.integer(static_cast<int64_t>(s.inf));
  }
  j.end_object();
}

// ---- summary -----------------------------------------------------------------------------

int64_t version_of(const fmt::File& f) {
  const fmt::Attr* v = fmt::find_attr(f.root_attrs, "format_version");
  return v ? std::get<int64_t>(v->value) : 0;  // read_file checked it is an int64
}

// The plan of a scene file: each object's role, what was baked and what was left out.
void scene_text(std::ostream& os, const fmt::File& f) {
  bool header = false;
  for (const auto& [g, attrs] : f.group_attrs) {
    if (!g.starts_with("/objects/")) continue;
    if (!header) os << "\nScene (objects, what was baked and what was left out)\n";
    header = true;
    const fmt::Attr* role = fmt::find_attr(attrs, "role");
    const auto* role_s = role ? std::get_if<std::string>(&role->value) : nullptr;
    os << "  " << g.substr(9) << " (" << (role_s ? *role_s : std::string("?")) << ")\n";
    for (const char* key : {"baked", "left_out"}) {
      const fmt::Attr* a = fmt::find_attr(attrs, key);
      const auto* text = a ? std::get_if<std::string>(&a->value) : nullptr;
      if (text == nullptr || *text == "-") continue;
      std::size_t start = 0;
      while (start <= text->size()) {
        const std::size_t end = std::min(text->find('\n', start), text->size());
        os << "      " << (key[0] == 'b' ? "baked      " : "left out   ") << text->substr(start, end - start) << '\n';
        start = end + 1;
      }
    }
  }
}

// The error against run time stored under /report: [5] datasets with a 'columns' attribute.
void report_text(std::ostream& os, const fmt::File& f) {
  bool header = false;
  for (const fmt::Dataset& d : f.datasets) {
    if (!d.path.starts_with("/report/") || d.shape != std::vector<uint64_t>{5} || d.data.index() != 0) continue;
    if (!header)
      os << "\nError report (against a converged reference; times are wall seconds)\n"
         << "  " << pad("product", 40) << pad("RMSE", 12) << pad("max", 12) << pad("ref. RMS", 12)
         << pad("ref. s.e.", 12) << pad("bake s", 9) << pad("ref. s", 9) << "integrals/s\n";
    header = true;
    const auto& v = std::get<std::vector<float>>(d.data);
    auto num = [](double x, int w) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%-*.3e", w, x);
      return std::string(buf);
    };
    auto attr_num = [&](const char* name) {
      const fmt::Attr* a = fmt::find_attr(d.attrs, name);
      const auto* x = a ? std::get_if<double>(&a->value) : nullptr;
      char buf[32];
      if (x) std::snprintf(buf, sizeof buf, "%-9.3g", *x);
      else std::snprintf(buf, sizeof buf, "%-9s", "-");
      return std::string(buf);
    };
    os << "  " << pad(d.path.substr(8), 40) << num(v[0], 12) << num(v[1], 12) << num(v[2], 12) << num(v[4], 12)
       << attr_num("bake_seconds") << attr_num("reference_seconds") << attr_num("integrals_per_second") << '\n';
  }
}

void summary_text(std::ostream& os, const std::string& path, const fmt::File& f,
                  const std::optional<std::string>& schema_error) {
  os << "file     " << path << '\n';
  os << "format   prtbake, format_version " << version_of(f) << '\n';
  os << "schema   "
     << (schema_error ? "INVALID: " + *schema_error
                      : "valid (schema v" + std::to_string(version_of(f)) + ", this prtdump reads 1.." +
                            std::to_string(fmt::kFormatVersion) + ")")
     << "\n\nRoot attributes\n";
  std::size_t w = 0;
  for (const fmt::Attr& a : f.root_attrs) w = std::max(w, a.name.size());
  for (const fmt::Attr& a : f.root_attrs) os << "  " << pad(a.name, w + 2) << attr_text(a.value) << '\n';

  os << "\nLayout (" << f.datasets.size() << " datasets)\n";
  w = 0;
  for (const fmt::Dataset& d : f.datasets) w = std::max(w, d.path.size());
  for (const fmt::Dataset& d : f.datasets) {
    os << "  " << pad(d.path, w + 2) << pad(std::string(fmt::dtype_name(d.data)), 9)
       << shape_text(d.shape) << '\n';
    for (const fmt::Attr& a : d.attrs) os << "      " << a.name << " = " << attr_text(a.value) << '\n';
  }
  scene_text(os, f);
  report_text(os, f);
  if (!f.group_attrs.empty()) {
    os << "\nGroup attributes\n";
    for (const auto& [g, attrs] : f.group_attrs) {
      os << "  " << g << '\n';
      for (const fmt::Attr& a : attrs) os << "      " << a.name << " = " << attr_text(a.value) << '\n';
    }
  }
  os << "\nStatistics (min, max, mean over finite values; counts of NaN and Inf)\n";
  for (const fmt::Dataset& d : f.datasets) {
    const DatasetStats s = compute_stats(d);
    print_stats_text(os, d, s.all, "  " + pad(d.path, w + 2));
    for (std::size_t c = 0; c < s.columns.size(); ++c)
      print_stats_text(os, d, s.columns[c], "      [..., " + std::to_string(c) + "]  ");
  }
}

void summary_json(std::ostream& os, const std::string& path, const fmt::File& f,
                  const std::optional<std::string>& schema_error) {
  Json j(os);
  j.begin_object();
  j.key("file");
  j.string(path);
  j.key("format_version");
  j.integer(version_of(f));
  j.key("schema_valid");
  j.boolean(!schema_error);
  j.key("schema_error");
  schema_error ? j.string(*schema_error) : j.null();
  j.key("root_attrs");
  json_attrs(j, f.root_attrs);
  j.key("group_attrs");
  j.begin_object();
  for (const auto& [g, attrs] : f.group_attrs) {
    j.key(g);
    json_attrs(j, attrs);
  }
  j.end_object();
  j.key("datasets");
  j.begin_array();
  for (const fmt::Dataset& d : f.datasets) {
    const DatasetStats s = compute_stats(d);
    j.begin_object();
    j.key("path");
    j.string(d.path);
    j.key("dtype");
    j.string(fmt::dtype_name(d.data));
    j.key("shape");
    j.begin_inline_array();
    for (uint64_t x : d.shape) j.integer(static_cast<int64_t>(x));
    j.end_array();
    j.key("attrs");
    json_attrs(j, d.attrs);
    j.key("stats");
    json_stats(j, d, s.all, true);
    if (!s.columns.empty()) {
      j.key("columns");
      j.begin_array();
      for (const Stats& c : s.columns) json_stats(j, d, c, false);
      j.end_array();
    }
    j.end_object();
  }
  j.end_array();
  j.end_object();
}

// ---- one vertex --------------------------------------------------------------------------

std::vector<const fmt::Dataset*> vertex_datasets(const fmt::File& f, uint64_t V) {
  std::vector<const fmt::Dataset*> out;
  for (const fmt::Dataset& d : f.datasets)
    if (fmt::is_per_vertex_path(d.path) && !d.shape.empty() && d.shape[0] == V) out.push_back(&d);
  return out;
}

std::string row_text(const fmt::Dataset& d, std::size_t begin, std::size_t count) {
  std::string s = "[";
  for (std::size_t i = 0; i < count; ++i) s += (i ? ", " : "") + element(d.data, begin + i);
  return s + "]";
}

void vertex_text(std::ostream& os, const std::string& path, const fmt::File& f, uint64_t vertex, uint64_t V) {
  os << "vertex " << vertex << " of " << V << " (" << path << ")\n";
  const auto list = vertex_datasets(f, V);
  std::size_t w = 0;
  for (const auto* d : list) w = std::max(w, d->path.size());
  for (const fmt::Dataset* d : list) {
    const std::size_t per = fmt::shape_product({d->shape.begin() + 1, d->shape.end()});
    const std::size_t base = vertex * per;
    const std::string head = "  " + pad(d->path, w + 2);
    const std::string cont(head.size(), ' ');
    const fmt::Attr* order = fmt::find_attr(d->attrs, "sh_order");
    if (d->shape.size() == 1) {
      os << head << element(d->data, base) << '\n';
    } else if (order && d->shape.size() == 2 && std::holds_alternative<int64_t>(order->value) &&
               static_cast<uint64_t>(std::get<int64_t>(order->value) * std::get<int64_t>(order->value)) == per) {
      const auto L = static_cast<std::size_t>(std::get<int64_t>(order->value));
      for (std::size_t l = 0; l < L; ++l)
        os << (l ? cont : head) << "l=" << l << "  " << row_text(*d, base + l * l, 2 * l + 1) << '\n';
    } else if (d->shape.size() == 2) {
      os << head << row_text(*d, base, per) << '\n';
    } else {
      // Rows of the last axis, labelled by their leading indices (R/G/B for radiance/band1).
      const std::size_t last = d->shape.back();
      const std::vector<uint64_t> lead(d->shape.begin() + 1, d->shape.end() - 1);
      for (std::size_t r = 0; r * last < per; ++r) {
        std::string label;
        if (d->path == "/radiance/band1") label = std::string(1, "RGB"[r]) + "  ";
        else {
          std::size_t rem = r;
          std::vector<uint64_t> idx(lead.size());
          for (std::size_t k = lead.size(); k-- > 0;) idx[k] = rem % lead[k], rem /= lead[k];
          label = shape_text(idx) + "  ";
        }
        os << (r ? cont : head) << label << row_text(*d, base + r * last, last) << '\n';
      }
    }
  }
}

void json_nested(Json& j, const fmt::Dataset& d, std::size_t base, std::size_t axis) {
  if (axis == d.shape.size()) {
    j.raw(json_element(d.data, base));
    return;
  }
  const std::size_t stride = fmt::shape_product({d.shape.begin() + static_cast<std::ptrdiff_t>(axis) + 1, d.shape.end()});
  axis + 1 == d.shape.size() ? j.begin_inline_array() : j.begin_array();
  for (std::size_t i = 0; i < d.shape[axis]; ++i) json_nested(j, d, base + i * stride, axis + 1);
  j.end_array();
}

void vertex_json(std::ostream& os, const std::string& path, const fmt::File& f, uint64_t vertex, uint64_t V) {
  Json j(os);
  j.begin_object();
  j.key("file");
  j.string(path);
  j.key("vertex");
  j.integer(static_cast<int64_t>(vertex));
  j.key("vertex_count");
  j.integer(static_cast<int64_t>(V));
  j.key("values");
  j.begin_object();
  for (const fmt::Dataset* d : vertex_datasets(f, V)) {
    j.key(d->path);
    const std::size_t per = fmt::shape_product({d->shape.begin() + 1, d->shape.end()});
    json_nested(j, *d, vertex * per, 1);
  }
  j.end_object();
  j.end_object();
}

int usage_error(const std::string& msg) {
  std::cerr << "prtdump: " << msg << "\nusage: prtdump [--json] [--vertex I] FILE.prt.h5 (see prtdump --help)\n";
  return 2;
}

} // namespace

int main(int argc, char** argv) {
  bool json = false;
  std::optional<uint64_t> vertex;
  std::optional<std::string> file;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "-h" || a == "--help") {
      std::cout << kHelp;
      return 0;
    }
    if (a == "--json") {
      json = true;
    } else if (a == "--vertex" || a.starts_with("--vertex=")) {
      std::string v;
      if (a == "--vertex") {
        if (i + 1 >= argc) return usage_error("--vertex needs a vertex index");
        v = argv[++i];
      } else {
        v = a.substr(9);
      }
      uint64_t x = 0;
      const auto r = std::from_chars(v.data(), v.data() + v.size(), x);
      if (v.empty() || r.ec != std::errc() || r.ptr != v.data() + v.size())
        return usage_error("--vertex needs a non-negative integer, not '" + v + "'");
      vertex = x;
    } else if (a.size() > 1 && a[0] == '-') {
      return usage_error("unknown option '" + a + "'");
    } else if (file) {
      return usage_error("one file at a time ('" + *file + "' and '" + a + "' given)");
    } else {
      file = a;
    }
  }
  if (!file) return usage_error("no file given");

  try {
    const fmt::File f = fmt::read_file(*file, fmt::ReadCheck::header);
    std::optional<std::string> schema_error;
    try {
      fmt::validate(f, *file);
    } catch (const fmt::FormatError& e) {
      schema_error = e.defect();
    }
    std::ostringstream out;
    if (vertex) {
      const fmt::Dataset* positions = fmt::find_dataset(f, "/mesh/positions");
      if (positions == nullptr || positions->shape.empty())
        throw fmt::FormatError(*file, "--vertex needs /mesh/positions, which this file does not have");
      const uint64_t V = positions->shape[0];
      if (*vertex >= V)
        throw fmt::FormatError(*file, "vertex " + std::to_string(*vertex) + " is out of range (the mesh has " +
                                          std::to_string(V) + " vertices: 0.." +
                                          (V ? std::to_string(V - 1) : std::string("none")) + ")");
      json ? vertex_json(out, *file, f, *vertex, V) : vertex_text(out, *file, f, *vertex, V);
    } else {
      json ? summary_json(out, *file, f, schema_error) : summary_text(out, *file, f, schema_error);
    }
    std::cout << out.str();
    std::cout.flush();
    if (!std::cout) {
      std::cerr << "prtdump: cannot write to standard output\n";
      return 1;
    }
  } catch (const fmt::FormatError& e) {
    std::cerr << "prtdump: " << e.what() << '\n';
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "prtdump: " << *file << ": " << e.what() << '\n';
    return 1;
  }
  return 0;
}
