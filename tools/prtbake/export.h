// tools/prtbake/export.h — `prtbake export`: a baked file in formats engines load without HDF5
// (glTF, a plain binary + JSON header, per-vertex light probes in Unity / Godot / Filament SH
// conventions, a folder with the web viewer). The command line only; the formats are exports/export.h and formats/SCHEMA.md
// "Exports".
#pragma once

#include <CLI/CLI.hpp>

#include <string>
#include <vector>

namespace prt::tool {

struct ExportArgs {
  std::string input, output, format;
  // --env: the probe formats' sky probe (one map), or the web viewer's environments (any number).
  std::vector<std::string> envs;
};

// Adds the `export` subcommand to `app`, parsing into `args`.
void add_export(CLI::App& app, ExportArgs& args);
// The checks of parsed arguments that need no file (UsageError: exit 2 before anything is read).
void check_export_args(const ExportArgs& args);
// Runs it: reads the input (FormatError: exit 1), writes the output whole or not at all; a warning
// on stderr names the vertex sets a probe format leaves out, and why.
int run_export(const ExportArgs& args);

} // namespace prt::tool
