// prtdump — inspect a baked file: root attributes, layout, the scene plan, the error report,
// per-dataset statistics, the area lights, one vertex, or the same as JSON. A thin shell: formats/ reads the file
// (formats::inspect_asset: the file as stored, and its typed asset when it passes the schema);
// this file only computes summary statistics and prints. Command line: CLI11; JSON:
// nlohmann-json; exit codes: tools/common (docs/ARCHITECTURE.md §6).
#include <formats/asset.h>
#include <formats/names.h>

#include "cli.h"
#include "tool_main.h"
#include "values.h"
#include "objects.h"
#include "summary.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

namespace pf = prt::formats;
namespace names = prt::formats::names;
using Json = nlohmann::ordered_json;

namespace prt::tool::dump {
namespace {

constexpr const char* kUsage = "usage: prtdump [--json] [--vertex I [--object NAME]] FILE.prt.h5";

constexpr const char* kDescription = R"(prtdump — inspect a prtbake file (HDF5, formats/SCHEMA.md)

  prtdump [--json] FILE.prt.h5               summary: attributes, layout, statistics
  prtdump [--json] --vertex I FILE.prt.h5    every per-vertex value of vertex I
  prtdump [--json] --vertex I --object NAME SCENE.prt.h5
                                             the same for vertex I of a scene object)";

constexpr const char* kFooter = R"(Example:
  prtbake vertex bunny.obj --transfer 3 -o bunny.prt.h5
  prtdump bunny.prt.h5
  prtdump --vertex 0 bunny.prt.h5
  prtdump --json bunny.prt.h5 | python3 -m json.tool
  prtbake scene data/scene_example.json -o scene.prt.h5
  prtdump scene.prt.h5 --vertex 0 --object bunny

Object names: a scene object is named as the Scene section prints it: a glTF object by its
node path (node0/node13/node71, or Piston_123-844_0_Parts_1 where the asset names it), which
the file stores as /objects/node0|node13|node71 (an HDF5 name cannot hold '/'). Every section
and the JSON use the node path; --object takes either spelling.

What the summary shows:
  format / schema  the format version and whether the file passes the schema check
                   (prtdump still shows a file that fails it, so you can see what is wrong;
                   the runtime and other readers reject such files).
  Root attributes  who wrote the file, when, from which source (and its SHA-256), the
                   command line, the up axis and the SH convention (see formats/SCHEMA.md).
  Layout           each dataset: path, element type, shape and its attributes (e.g. sh_order
                   = L, the number of SH bands, so a transfer vector has L*L coefficients).
                   Attributes another tool added (e.g. with h5py) are shown with the rest.
                   A scene object's datasets are listed under its name, by their path within
                   it (mesh/positions, ao, report/ao, fiv/shells); Statistics likewise.
  Scene            for scene files (prtbake scene): each object's role and what the bake
                   baked and left out, with the reasons.
  Area lights      for files with area lights (format_version 3): each light's shape, faces,
                   radiance and sides, and per vertex set the irradiance E at unit radiance
                   each light gives (min, max, mean over the vertices; area_lights/irradiance
                   [V, L], its columns in the order its 'lights' attribute lists).
  Error report     the target error the bake was asked to reach (when it had one), the
                   reference, and per object and product: RMSE and max error against the
                   converged reference, the reference's RMS and own standard error, bake and
                   reference wall times. --json carries every column of every row by name.
  Group attributes attributes on groups such as /scene and each scene object's.
  Skipped attributes
                   attributes another tool added that the reader left out, each with the
                   reason: a type the model does not hold (h5py's bool, a compound), or
                   text in an HDF5 global heap found damaged. The file's data is whole; a
                   file rewritten by prtbake does not keep them. (--json: skipped_attrs.)
  Statistics       per dataset: min, max and mean over the finite values, and the number of
                   NaN and Inf values (a valid file has none). For a dataset whose last axis is
                   small (<= 16, e.g. xyz, RGB or SH coefficients) also per-column min/max/mean,
                   where column j is [..., j].
  --vertex         values are laid out by the trailing axes: [V, 3] prints one [x, y, z] row;
                   [V, L*L] prints one row per SH band l (index l*(l+1)+m, m = -l..l);
                   [V, 3, 3] (radiance/band1) prints one row per channel R, G, B with
                   m = -1, 0, 1; [V, 3, L*L] (radiance/shadowed, the shadowed radiance S of
                   format_version 4) one row per channel and band l.

Exit status 1 also covers a vertex index out of range, an unknown --object, and --vertex on a
scene file without --object (the message lists the objects).
)";

// ---- one vertex --------------------------------------------------------------------------

// The vertex set --vertex prints: the root layout (prefix "") or a scene object's
// ("/objects/<name>", shown as its label).
struct VertexSetRef {
  std::string prefix;
  std::string label;  // empty for the root layout
};

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

// The values of one vertex nested by the trailing axes.
Json json_nested(const pf::Dataset& d, std::size_t base, std::size_t axis) {
  if (axis == d.shape.size()) return json_element(d.data, base);
  const std::size_t stride = pf::shape_product({d.shape.begin() + static_cast<std::ptrdiff_t>(axis) + 1, d.shape.end()});
  Json a = Json::array();
  for (std::size_t i = 0; i < d.shape[axis]; ++i) a.push_back(json_nested(d, base + i * stride, axis + 1));
  return a;
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

// The vertex set --vertex reads: the root layout, or with --object the scene object it names (by
// its node path or its stored name). One line naming the file for every mistake.
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

// V of a vertex set, from its positions.
uint64_t vertex_count(const pf::File& f, const std::string& file, const VertexSetRef& set) {
  for (const pf::Dataset& d : f.datasets)
    if (pf::dataset_kind(d.path) == pf::DatasetKind::positions && pf::vertex_set_of(d.path) == set.prefix &&
        !d.shape.empty())
      return d.shape[0];
  throw pf::FormatError(file, "--vertex needs " + set.prefix + std::string(names::kPositions) +
                                  (set.label.empty() ? "" : " (object " + set.label + ")") +
                                  ", which this file does not have");
}

int prtdump_main(int argc, char** argv) {
  CLI::App app(kDescription, "prtdump");
  app.set_version_flag("--version", std::string("prtdump ") + prt::tool::kToolkitVersion);
  app.footer(std::string(kFooter) + "\n" + prt::tool::kExitStatusHelp);
  app.get_formatter()->column_width(22);
  bool json = false;
  uint64_t vertex = 0;
  std::string file;
  app.add_flag("--json", json,
               "print the same information as one JSON object (for scripts). Numbers are exact (shortest "
               "round-trip form); NaN and Inf become null.");
  CLI::Option* vertex_opt =
      app.add_option("--vertex", vertex,
                     "print vertex I (0-based) from every per-vertex dataset of the root layout, or of the scene "
                     "object --object names (mesh positions, normals and source positions, ao, transfer, radiance, "
                     "area lights); V, the vertex count, is the number of its mesh positions.")
          ->type_name("I")
          ->check(prt::tool::integer_in(0, std::numeric_limits<int64_t>::max()));
  std::string object;
  CLI::Option* object_opt =
      app.add_option("--object", object,
                     "with --vertex, in a scene file: the object whose vertex to print, by the name the Scene "
                     "section shows (a glTF object's node path, e.g. node0/node13/node71) or as stored "
                     "(node0|node13|node71).")
          ->type_name("NAME")
          ->needs(vertex_opt);
  app.add_option("FILE", file, "the .prt.h5 file to inspect")->required()->type_name("FILE.prt.h5");
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help, --version
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    throw prt::tool::UsageError(prt::tool::usage_message(app, e, "prtdump") + "; " + kUsage);
  }

  const pf::Inspection in = pf::inspect_asset(file);
  std::ostringstream out;
  if (vertex_opt->count() > 0) {
    const VertexSetRef set =
        vertex_set(in.file, file, object_opt->count() > 0 ? std::optional<std::string>(object) : std::nullopt);
    const uint64_t V = vertex_count(in.file, file, set);
    if (vertex >= V)
      throw pf::FormatError(file, "vertex " + std::to_string(vertex) + " is out of range (" +
                                      (set.label.empty() ? std::string("the mesh") : "object " + set.label) + " has " +
                                      std::to_string(V) + " vertices: 0.." +
                                      (V ? std::to_string(V - 1) : std::string("none")) + ")");
    if (json) out << vertex_json(file, in.file, set, vertex, V).dump(2) << '\n';
    else vertex_text(out, file, in.file, set, vertex, V);
  } else {
    if (json) out << summary_json(file, in).dump(2) << '\n';
    else summary_text(out, file, in);
  }
  std::cout << out.str();
  std::cout.flush();
  if (!std::cout) throw pf::FormatError("standard output", "cannot write");
  return 0;
}

} // namespace
} // namespace prt::tool::dump

int main(int argc, char** argv) { return prt::tool::run_tool("prtdump", prt::tool::dump::prtdump_main, argc, argv); }
