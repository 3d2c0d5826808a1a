// tools/prtbake/export.cpp — `prtbake export` (contract: export.h).
#include "export.h"

#include <formats/export.h>

#include <cstdio>

namespace prt::tool {
namespace {

constexpr const char* kExportHelp =
    "Writes a baked file (.prt.h5) in a format an engine loads without HDF5 (layouts:\n"
    "formats/SCHEMA.md \"Exports\"). Every vertex set is exported: the root mesh and each scene\n"
    "object; the values are the file's, unchanged.\n"
    "  gltf      glTF 2.0, OUT.gltf + OUT.bin: per vertex set a mesh and a node (POSITION, NORMAL,\n"
    "            indices); AO as COLOR_0 (grey) and _AO; transfer, band-1 radiance and area-light\n"
    "            data as _PRT_<NAME>_<k> attributes (4 components each: reassemble in order; the\n"
    "            mapping is in asset.extras.prtbake). Loads in Blender and engine importers.\n"
    "  glb       the same as one binary glTF file.\n"
    "  bin       plain binary: magic \"PRTBIN\", version, a JSON header naming each array (HDF5\n"
    "            path, dtype, shape, byte offset), little-endian arrays 16-byte aligned.\n"
    "  unity     per-vertex light probes (JSON) from /radiance/band1 as SphericalHarmonicsL2\n"
    "            coefficients ([rgb][9], ShadeSH9's pre-scaling, Unity's left-handed frame).\n"
    "  godot     the same as Godot 4 LightmapGI probe SH ([9][rgb], radiance/pi, no CS phase).\n"
    "  filament  the same as Filament/cmgen pre-scaled irradiance SH ([9][rgb]).\n"
    "The probe formats evaluate, in each engine's own formula, to the baked irradiance/pi at the\n"
    "baked normal; they need a file baked with --radiance (or a scene with an environment).";

} // namespace

void add_export(CLI::App& app, ExportArgs& args) {
  CLI::App& cmd = *app.add_subcommand("export", kExportHelp);
  cmd.add_option("FILE", args.input, "the baked file (.prt.h5)")->required()->type_name("");
  cmd.add_option("--to", args.format, "gltf, glb, bin, unity, godot or filament (see above)")
      ->option_text("FORMAT")
      ->required()
      ->check([](const std::string& s) -> std::string {
        return formats::parse_export_format(s) ? "" : "expects gltf, glb, bin, unity, godot or filament, got '" + s + "'";
      });
  cmd.add_option("-o,--output", args.output,
                 "the file to write (gltf: also <stem>.bin beside it). Written to a\n"
                 "staging directory first and renamed, so OUT is never half-written.")
      ->option_text("OUT")
      ->required();
}

int run_export(const ExportArgs& args) {
  const formats::ExportFormat format = *formats::parse_export_format(args.format);
  const formats::Asset asset = formats::read_asset(args.input);
  formats::export_asset(asset, args.input, format, args.output);
  std::printf("exported %s to %s (%s)\n", args.input.c_str(), args.output.c_str(), formats::to_string(format));
  return 0;
}

} // namespace prt::tool
