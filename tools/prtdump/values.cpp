// tools/prtdump/values.cpp — prtdump's number formatting, JSON values, text helpers and
// per-dataset statistics (contract: values.h).
#include "values.h"

#include <charconv>
#include <cstdlib>
#include <type_traits>
#include <variant>

namespace prt::tool::dump {

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
std::string element(const pf::DatasetData& data, std::size_t i) {
  if (const auto* f = std::get_if<std::vector<float>>(&data)) return num((*f)[i]);
  if (const auto* f = std::get_if<std::vector<double>>(&data)) return num((*f)[i]);
  if (const auto* u = std::get_if<std::vector<uint32_t>>(&data)) return std::to_string((*u)[i]);
  if (const auto* h = std::get_if<std::vector<pf::Float16>>(&data)) return num(pf::to_float((*h)[i]));
  return std::to_string(std::get<std::vector<uint8_t>>(data)[i]);
}

// ---- JSON values ---------------------------------------------------------------------------

Json json_float(float v) {
  if (!std::isfinite(v)) return nullptr;
  return std::strtod(num(v).c_str(), nullptr);
}
Json json_double(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }
Json json_element(const pf::DatasetData& data, std::size_t i) {
  if (const auto* f = std::get_if<std::vector<float>>(&data)) return json_float((*f)[i]);
  if (const auto* f = std::get_if<std::vector<double>>(&data)) return json_double((*f)[i]);
  if (const auto* u = std::get_if<std::vector<uint32_t>>(&data)) return (*u)[i];
  if (const auto* h = std::get_if<std::vector<pf::Float16>>(&data)) return json_float(pf::to_float((*h)[i]));
  return std::get<std::vector<uint8_t>>(data)[i];
}

namespace {

Json json_attr_value(const pf::AttrValue& v) {
  return std::visit(
      [](const auto& x) -> Json {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, double>) return json_double(x);
        else if constexpr (std::is_same_v<T, std::vector<double>>) {
          Json a = Json::array();
          for (double e : x) a.push_back(json_double(e));
          return a;
        } else return Json(x);
      },
      v);
}

} // namespace

Json json_attrs(const std::vector<pf::Attr>& attrs) {
  Json o = Json::object();
  for (const pf::Attr& a : attrs) o[a.name] = json_attr_value(a.value);
  return o;
}

// ---- text helpers ------------------------------------------------------------------------

std::string attr_text(const pf::AttrValue& v) {
  return std::visit(
      [](const auto& x) -> std::string {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, std::string>) return Json(x).dump();
        else if constexpr (std::is_same_v<T, int64_t>) return std::to_string(x);
        else if constexpr (std::is_same_v<T, double>) return num(x);
        else {
          std::string s = "[";
          for (std::size_t i = 0; i < x.size(); ++i) {
            if (i) s += ", ";
            if constexpr (std::is_same_v<T, std::vector<double>>) s += num(x[i]);
            else if constexpr (std::is_same_v<T, std::vector<std::string>>) s += Json(x[i]).dump();
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
void attrs_text(std::ostream& os, const std::vector<pf::Attr>& attrs) {
  for (const pf::Attr& a : attrs) os << "      " << a.name << " = " << attr_text(a.value) << '\n';
}

// ---- statistics --------------------------------------------------------------------------

namespace {

constexpr std::size_t kMaxColumnsForStats = 16;

double element_value(const pf::DatasetData& data, std::size_t i) {
  return std::visit(
      [i]<class T>(const std::vector<T>& v) {
        if constexpr (std::is_same_v<T, pf::Float16>) return static_cast<double>(pf::to_float(v[i]));
        else return static_cast<double>(v[i]);
      },
      data);
}

// float32 or float16: values a float holds exactly, printed as floats.
bool is_float32(const pf::Dataset& d) {
  return std::holds_alternative<std::vector<float>>(d.data) || std::holds_alternative<std::vector<pf::Float16>>(d.data);
}
bool is_float(const pf::Dataset& d) { return is_float32(d) || std::holds_alternative<std::vector<double>>(d.data); }

// min/max are values of the dataset: print them in the dataset's own precision.
std::string stat_value(const pf::Dataset& d, double v) {
  if (is_float32(d)) return num(static_cast<float>(v));
  return num(v);
}
Json json_stat_value(const pf::Dataset& d, double v) {
  if (!is_float(d)) return static_cast<int64_t>(v);  // a uint32 or uint8 value, exact in a double
  return json_double(is_float32(d) ? static_cast<double>(static_cast<float>(v)) : v);
}

} // namespace

DatasetStats compute_stats(const pf::Dataset& d) {
  DatasetStats s;
  const std::size_t n = pf::element_count(d.data);
  const uint64_t last = d.shape.empty() ? 1 : d.shape.back();
  if (d.shape.size() >= 2 && last >= 1 && last <= kMaxColumnsForStats) s.columns.resize(last);
  for (std::size_t i = 0; i < n; ++i) {
    const double v = element_value(d.data, i);
    s.all.add(v);
    if (!s.columns.empty()) s.columns[i % last].add(v);
  }
  return s;
}

void print_stats_text(std::ostream& os, const pf::Dataset& d, const Stats& s, const std::string& label) {
  os << label;
  if (s.finite == 0) os << "min -  max -  mean -";
  else
    os << "min " << stat_value(d, s.min) << "  max " << stat_value(d, s.max) << "  mean "
       << num(*s.mean());
  if (is_float(d)) os << "  nan " << s.nan << "  inf " << s.inf;
  os << '\n';
}

Json json_stats(const pf::Dataset& d, const Stats& s, bool counts) {
  Json o = Json::object();
  o["min"] = s.finite ? json_stat_value(d, s.min) : Json(nullptr);
  o["max"] = s.finite ? json_stat_value(d, s.max) : Json(nullptr);
  o["mean"] = s.finite ? json_double(*s.mean()) : Json(nullptr);
  if (counts) {
    o["finite"] = s.finite;
    o["nan"] = s.nan;
    o["inf"] = s.inf;
  }
  return o;
}

} // namespace prt::tool::dump
