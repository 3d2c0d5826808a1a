// tools/prtdump/values.h — how prtdump shows what a file stores: numbers in their shortest
// round-trip form, dataset elements and attributes as text and as JSON values (NaN and Inf as
// null), and per-dataset statistics (min, max, mean, NaN and Inf counts; per column when the
// last axis is small). Datasets and attributes are formats/prtfile.h's (formats/SCHEMA.md).
#pragma once

#include <formats/prtfile.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace prt::tool::dump {

namespace pf = prt::formats;
using Json = nlohmann::ordered_json;

// ---- number formatting -------------------------------------------------------------------

// The shortest form that reads back as the same value; "nan", "inf", "-inf".
std::string num(double v);
std::string num(float v);
// An element of a dataset: float32 and float64 in their own shortest form, integers exactly.
std::string element(const pf::DatasetData& data, std::size_t i);

// ---- JSON values ---------------------------------------------------------------------------

// A float32 value for JSON: the double whose shortest form is the float's own shortest form
// (0.1f prints as 0.1, not 0.10000000149011612); NaN and Inf become null.
Json json_float(float v);
Json json_double(double v);
Json json_element(const pf::DatasetData& data, std::size_t i);
// Attributes as one JSON object, by name.
Json json_attrs(const std::vector<pf::Attr>& attrs);

// ---- text helpers ------------------------------------------------------------------------

// An attribute's value as printed: strings quoted, numbers in their shortest form, lists in [].
std::string attr_text(const pf::AttrValue& v);
std::string shape_text(const std::vector<uint64_t>& shape);  // "[V, 3]"
std::string pad(std::string s, std::size_t width);           // s, padded with spaces to width
// One indented "name = value" line per attribute.
void attrs_text(std::ostream& os, const std::vector<pf::Attr>& attrs);

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

DatasetStats compute_stats(const pf::Dataset& d);
// One line of statistics after `label`; the NaN and Inf counts for float datasets only.
void print_stats_text(std::ostream& os, const pf::Dataset& d, const Stats& s, const std::string& label);
// min, max, mean (null when no value is finite) and, with `counts`, finite, nan and inf.
Json json_stats(const pf::Dataset& d, const Stats& s, bool counts);

} // namespace prt::tool::dump
