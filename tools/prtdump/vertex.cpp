// tools/prtdump/vertex.cpp — one vertex's values, and the vertex set --vertex reads
// (contract: vertex.h).
#include "vertex.h"

#include "objects.h"

#include <formats/names.h>

#include <algorithm>
#include <utility>
#include <vector>

namespace prt::tool::dump {

namespace names = prt::formats::names;

namespace {

// The per-vertex datasets of the vertex set (V rows each), in path order, each with its path
// within the set ("/ao", "/mesh/positions": the same keys for the root layout and an object).
std::vector<std::pair<const pf::Dataset*, std::string>> vertex_datasets(const pf::File& f, const VertexSetRef& set,
                                                                        uint64_t V) {
  std::vector<std::pair<const pf::Dataset*, std::string>> out;
  for (const pf::Dataset& d : f.datasets)
    if (pf::is_per_vertex_path(d.path) && pf::vertex_set_of(d.path) == set.prefix && !d.shape.empty() && d.shape[0] == V)
      out.emplace_back(&d, d.path.substr(set.prefix.size()));
  return out;
}

std::string row_text(const pf::Dataset& d, std::size_t begin, std::size_t count) {
  std::string s = "[";
  for (std::size_t i = 0; i < count; ++i) s += (i ? ", " : "") + element(d.data, begin + i);
  return s + "]";
}

std::size_t per_vertex(const pf::Dataset& d) { return pf::shape_product({d.shape.begin() + 1, d.shape.end()}); }

// The values of one vertex nested by the trailing axes.
Json json_nested(const pf::Dataset& d, std::size_t base, std::size_t axis) {
  if (axis == d.shape.size()) return json_element(d.data, base);
  const std::size_t stride = pf::shape_product({d.shape.begin() + static_cast<std::ptrdiff_t>(axis) + 1, d.shape.end()});
  Json a = Json::array();
  for (std::size_t i = 0; i < d.shape[axis]; ++i) a.push_back(json_nested(d, base + i * stride, axis + 1));
  return a;
}

// "a, b, c" for the first names of a list, "... and N more" past kMaxListed (a glTF scene has
// hundreds of objects: the Scene section of `prtdump FILE` lists them all).
std::string name_list(const std::vector<FileObject>& objects) {
  constexpr std::size_t kMaxListed = 12;
  std::string s;
  for (std::size_t i = 0; i < objects.size() && i < kMaxListed; ++i) s += (i ? ", " : "") + objects[i].label();
  if (objects.size() > kMaxListed)
    s += ", ... and " + std::to_string(objects.size() - kMaxListed) + " more ('prtdump FILE' lists them all)";
  return s;
}

} // namespace

void vertex_text(std::ostream& os, const std::string& path, const pf::File& f, const VertexSetRef& set, uint64_t vertex,
                 uint64_t V) {
  os << "vertex " << vertex << " of " << V << " (" << path << (set.label.empty() ? "" : ", object " + set.label)
     << ")\n";
  const auto list = vertex_datasets(f, set, V);
  std::size_t w = 0;
  for (const auto& [d, shown] : list) w = std::max(w, shown.size());
  for (const auto& [d, shown] : list) {
    const std::size_t per = per_vertex(*d);
    const std::size_t base = vertex * per;
    const std::string head = "  " + pad(shown, w + 2);
    const std::string cont(head.size(), ' ');
    const pf::Attr* order = pf::find_attr(d->attrs, names::kShOrder);
    const auto* L = order ? std::get_if<int64_t>(&order->value) : nullptr;
    // Bands only when sh_order is positive and its square (computed without overflow) is the
    // row (per channel): prtdump shows files that fail the schema and stays within the data
    // whatever they claim.
    const std::size_t channels = pf::dataset_kind(d->path) == pf::DatasetKind::radiance_shadowed ? 3 : 1;
    const bool bands = L && *L > 0 && d->shape.size() == channels + 1 && per % channels == 0 &&
                       (per / channels) % uint64_t(*L) == 0 && per / channels / uint64_t(*L) == uint64_t(*L);
    if (d->shape.size() == 1) {
      os << head << element(d->data, base) << '\n';
    } else if (bands) {
      const std::size_t n = per / channels;
      for (std::size_t c = 0; c < channels; ++c)
        for (std::size_t l = 0; l < static_cast<std::size_t>(*L); ++l)
          os << (c + l ? cont : head) << (channels > 1 ? std::string(1, "RGB"[c]) + " " : std::string()) << "l=" << l
             << "  " << row_text(*d, base + c * n + l * l, 2 * l + 1) << '\n';
    } else if (d->shape.size() == 2) {
      os << head << row_text(*d, base, per) << '\n';
    } else {
      // Rows of the last axis, labelled by their leading indices (R/G/B for radiance/band1).
      const std::size_t last = d->shape.back();
      const std::vector<uint64_t> lead(d->shape.begin() + 1, d->shape.end() - 1);
      const bool rgb = pf::dataset_kind(d->path) == pf::DatasetKind::radiance_band1 && per == 3 * last;
      for (std::size_t r = 0; r * last < per; ++r) {
        std::string label;
        if (rgb) label = std::string(1, "RGB"[r]) + "  ";
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

Json vertex_json(const std::string& path, const pf::File& f, const VertexSetRef& set, uint64_t vertex, uint64_t V) {
  Json j = Json::object();
  j["file"] = path;
  j["object"] = set.label.empty() ? Json(nullptr) : Json(set.label);  // null: the root layout
  j["group"] = set.prefix.empty() ? Json("/") : Json(set.prefix);
  j["vertex"] = vertex;
  j["vertex_count"] = V;
  Json values = Json::object();
  for (const auto& [d, shown] : vertex_datasets(f, set, V)) values[shown] = json_nested(*d, vertex * per_vertex(*d), 1);
  j["values"] = std::move(values);
  return j;
}

VertexSetRef vertex_set(const pf::File& f, const std::string& file, const std::optional<std::string>& object) {
  const std::vector<FileObject> objects = file_objects(f);
  if (!object) {
    if (!objects.empty() && std::none_of(f.datasets.begin(), f.datasets.end(), [](const pf::Dataset& d) {
          return pf::dataset_kind(d.path) == pf::DatasetKind::positions && pf::vertex_set_of(d.path).empty();
        }))
      throw pf::FormatError(file, "is a scene file: its vertices belong to its " + std::to_string(objects.size()) +
                                      " objects; give --vertex with --object NAME, one of: " + name_list(objects));
    return {};
  }
  if (objects.empty())
    throw pf::FormatError(file, "has no scene objects (it is not a scene file): --vertex reads its root layout "
                                "without --object");
  for (const FileObject& o : objects)
    if (pf::names_object(*object, o.name, o.node_path))
      return {std::string(names::kObjects) + "/" + o.name, o.label()};
  throw pf::FormatError(file, "has no object '" + *object + "'; its " + std::to_string(objects.size()) +
                                  " objects are: " + name_list(objects));
}

uint64_t vertex_count(const pf::File& f, const std::string& file, const VertexSetRef& set) {
  for (const pf::Dataset& d : f.datasets)
    if (pf::dataset_kind(d.path) == pf::DatasetKind::positions && pf::vertex_set_of(d.path) == set.prefix &&
        !d.shape.empty())
      return d.shape[0];
  throw pf::FormatError(file, "--vertex needs " + set.prefix + std::string(names::kPositions) +
                                  (set.label.empty() ? "" : " (object " + set.label + ")") +
                                  ", which this file does not have");
}

} // namespace prt::tool::dump
