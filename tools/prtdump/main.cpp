// prtdump — inspect a baked file: root attributes, layout, the scene plan, the error report,
// per-dataset statistics, the area lights, one vertex, or the same as JSON. A thin shell: formats/ reads the file
// (formats::inspect_asset: the file as stored, and its typed asset when it passes the schema);
// prtdump only computes summary statistics and prints: summary.h (the summary), vertex.h
// (--vertex), objects.h (scene objects), values.h (numbers, JSON values, statistics). This file:
// the usage texts and the command line (CLI11); JSON: nlohmann-json; exit codes: tools/common
// (docs/ARCHITECTURE.md §6).
#include "summary.h"
#include "vertex.h"

#include <formats/asset.h>

#include "cli.h"
#include "tool_main.h"

#include <CLI/CLI.hpp>

#include <cstdint>
#include <iostream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>

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
