// tools/prtbake/export.cpp — `prtbake export` (contract: export.h).
#include "export.h"

#include "cli.h"
#include "tool_main.h"

#include <bake/core/error.h>
#include <bake/environment/envmap.h>
#include <exports/export.h>
#include <formats/asset.h>

#include <algorithm>
#include <filesystem>
#include <cstdio>
#include <set>
#include <utility>
#include <vector>

namespace prt::tool {
namespace {

constexpr const char* kExportHelp =
    "Writes a baked file (.prt.h5) in a format an engine loads without HDF5 (layouts:\n"
    "formats/SCHEMA.md \"Exports\"). Every vertex set is exported: the root mesh and each scene\n"
    "object; the values are the file's, unchanged.\n"
    "  gltf      glTF 2.0, OUT.gltf + OUT.bin: per vertex set a mesh and a node (POSITION, NORMAL,\n"
    "            indices); AO as COLOR_0 (grey) and _AO; transfer, band-1 radiance and area-light\n"
    "            data as _PRT_<NAME>_<k> attributes: VEC4 holding components 4k..4k+3 of the\n"
    "            row, the last one SCALAR, VEC2 or VEC3 when the row's length is not a multiple\n"
    "            of 4 (concatenate them in order; the mapping is in asset.extras.prtbake).\n"
    "            Loads in Blender and engine importers.\n"
    "  glb       the same as one binary glTF file.\n"
    "  bin       plain binary: magic \"PRTBIN\", version, a JSON header naming each array (HDF5\n"
    "            path, dtype, shape, byte offset), little-endian arrays 16-byte aligned;\n"
    "            a lightmap's mesh/uv and lightmap/* arrays too.\n"
    "  unity     per-vertex light probes (JSON) from /radiance/band1 as SphericalHarmonicsL2\n"
    "            coefficients ([rgb][9], ShadeSH9's pre-scaling, Unity's left-handed frame).\n"
    "  godot     the same as Godot 4 LightmapGI probe SH ([9][rgb], radiance/pi, no CS phase).\n"
    "  filament  the same as Filament/cmgen pre-scaled irradiance SH ([9][rgb]).\n"
    "  exr       lightmaps only (a file from prtbake texel): per vertex set with a lightmap one\n"
    "            half-float OpenEXR image, W x H, row 0 at v = 0, one channel per value:\n"
    "            state (0 empty, 1 baked, 2 filled, 3 padding), ao, transfer.diffuse.c<i>,\n"
    "            transfer.visibility.c<i> (i = l(l+1)+m), radiance.band1.<R|G|B>.m<-1|0|1>,\n"
    "            radiance.shadowed.<R|G|B>.c<i>. -o names a directory (DIR/lightmap.exr,\n"
    "            DIR/lightmap.<object>.exr) or a prefix (OUT.exr, OUT.<object>.exr).\n"
    "Lightmaps (files from prtbake texel) travel with gltf/glb too: the mesh gets the lightmap\n"
    "UVs as TEXCOORD_1 (and TEXCOORD_0; vertices split where a UV seam runs), a material whose\n"
    "occlusionTexture (texCoord 1) is the AO as an 8-bit PNG in the file (round(255*AO)), and\n"
    "every lightmap dataset as a float buffer view listed in asset.extras.prtbake. godot also\n"
    "writes each lightmap with band-1 radiance as a Godot 4.4+ directional lightmap (L1 SH):\n"
    "OUT-stem.lightmap.exr, 4 layers stacked vertically, with its .import (slices/vertical=4).\n"
    "The probe formats evaluate, in each engine's own formula, to the baked irradiance/pi at the\n"
    "baked normal; they need a file baked with --radiance (or a scene with an environment), or\n"
    "--env ENV: the environment's own probe (its order-3 radiance SH, unshadowed), the ambient\n"
    "probe for dynamic objects, consistent with the bake. A vertex set without band-1 radiance\n"
    "(an occluder, a glossy receiver) gets no probes; a warning names each and says why.";

constexpr const char* kExportExamples =
    "EXAMPLES\n"
    "  prtbake export bunny.prt.h5 --to glb -o bunny.glb\n"
    "  prtbake export bunny.prt.h5 --to unity --env data/sunset.exr -o bunny_probes.json\n"
    "  prtbake texel floor.obj --resolution 256 --ao --radiance data/sunset.exr -o floor.prt.h5\n"
    "  prtbake export floor.prt.h5 --to glb -o floor.glb        # AO on TEXCOORD_1\n"
    "  prtbake export floor.prt.h5 --to exr -o floor            # floor.exr\n"
    "  prtbake export floor.prt.h5 --to godot -o floor.json     # + floor.lightmap.exr\n"
    "  prtbake export bunny.prt.h5 --to web --env data/forest.exr --env data/studio.exr -o bunny_web\n\n";

} // namespace

void add_export(CLI::App& app, ExportArgs& args) {
  CLI::App& cmd = *app.add_subcommand("export", kExportHelp);
  cmd.add_option("FILE", args.input, "the baked file (.prt.h5)")->required()->type_name("");
  cmd.add_option("--to", args.format, "gltf, glb, bin, unity, godot, filament, exr or web (see above)")
      ->option_text("FORMAT")
      ->required()
      ->check([](const std::string& s) -> std::string {
        if (exports::parse_export_format(s)) return "";
        const auto near = closest(s, {"gltf", "glb", "bin", "unity", "godot", "filament", "exr", "web"});
        return "expects gltf, glb, bin, unity, godot, filament, exr or web, got '" + s + "'" +
               (near ? "; did you mean " + *near + "?" : std::string());
      });
  cmd.add_option("-o,--output", args.output,
                 "the file to write (gltf: also <stem>.bin beside it; exr: a directory or a\n"
                 "file prefix; web: the folder, replaced when it holds an earlier web export).\n"
                 "Written to a staging directory first and renamed, so OUT is never half-written.")
      ->option_text("OUT")
      ->required();
  cmd.add_option("--env", args.envs,
                 "unity, godot, filament: also write the probe of this environment map (OpenEXR\n"
                 "lat-long or cube, read in the file's up axis) as \"environment\"; it must be the\n"
                 "map the file's lighting was baked with, when the file names one.\n"
                 "web: an environment the viewer offers (repeat for more; SH at the file's\n"
                 "transfer order, at least 3).")
      ->option_text("ENV");
  cmd.footer(std::string(kExportExamples) + kExitStatusHelp);
}

void check_export_args(const ExportArgs& args) {
  const std::optional<exports::ExportFormat> format = exports::parse_export_format(args.format);
  PRT_CHECK(format.has_value());  // the --to check
  if (*format == exports::ExportFormat::Web) {
    if (const char* why = exports::web_viewer_missing())
      throw UsageError(std::string("export: --to web: this prtbake was built without the web viewer: ") + why, "prtbake export");
    return;
  }
  if (!args.envs.empty() && !exports::is_probe_format(*format))
    throw UsageError("export: --env writes an environment probe: it needs --to unity, godot, filament or web, not " +
                         args.format,
                     "prtbake export");
  if (args.envs.size() > 1)
    throw UsageError("export: --to " + args.format + " writes one environment probe: give --env once", "prtbake export");
}

namespace {

// Every environment SHA-256 the file records: band-1 radiance products and the scene's.
std::set<std::string> recorded_environments(const formats::Asset& asset) {
  std::set<std::string> out;
  auto add = [&](const std::optional<formats::Product>& p) {
    if (p && p->environment_sha256) out.insert(*p->environment_sha256);
  };
  add(asset.vertices.radiance_band1);
  for (const formats::SceneObject& o : asset.objects) add(o.set.radiance_band1);
  if (asset.scene && asset.scene->environment_sha256) out.insert(*asset.scene->environment_sha256);
  return out;
}

// The environment probe of `path`, read in the file's up axis, after checking it is the map the
// file's lighting was baked with (when the file records one).
exports::EnvironmentProbe environment_probe(const std::string& path, const formats::Asset& asset, const std::string& input) {
  const bake::UpAxis up = asset.root.up_axis == "z" ? bake::UpAxis::Z : bake::UpAxis::Y;
  const bake::EnvMap env = bake::EnvMap::load(path, up);
  const std::set<std::string> recorded = recorded_environments(asset);
  if (!recorded.empty() && !recorded.count(env.info().sha256))
    throw bake::InputError(path, "is not the environment " + input + " was baked with (its SHA-256 is " + env.info().sha256 +
                                     ", the file records " + *recorded.begin() + ")");
  exports::EnvironmentProbe probe;
  const std::vector<double> sh = env.project_sh(3);  // [i*3 + c]
  for (size_t c = 0; c < 3; ++c)
    for (size_t i = 0; i < 9; ++i) probe.radiance[c][i] = sh[i * 3 + c];
  probe.name = path;
  probe.sha256 = env.info().sha256;
  return probe;
}

// The web viewer's environments: the one the file was baked with (where the file names it, else
// beside the file; a warning when neither exists), then each --env not already among them, each
// projected to SH at the file's largest transfer order (at least 3).
std::vector<exports::WebEnvironment> web_environments(const ExportArgs& args, const formats::Asset& asset) {
  const bake::UpAxis up = asset.root.up_axis == "z" ? bake::UpAxis::Z : bake::UpAxis::Y;
  int order = 3;
  std::optional<std::string> baked_name;
  std::set<std::string> recorded = recorded_environments(asset);
  auto scan_products = [&](const std::optional<formats::Product>& transfer, const std::optional<formats::Product>& band1) {
    if (transfer && transfer->sh_order) order = std::max(order, int(*transfer->sh_order));
    if (band1 && band1->environment && !baked_name) baked_name = *band1->environment;
    if (band1 && band1->environment_sha256) recorded.insert(*band1->environment_sha256);
  };
  auto scan = [&](const formats::VertexSet& s) {
    scan_products(s.transfer_diffuse, s.radiance_band1);
    if (s.lightmap) scan_products(s.lightmap->transfer_diffuse, s.lightmap->radiance_band1);  // per texel
  };
  scan(asset.vertices);
  for (const formats::SceneObject& o : asset.objects) scan(o.set);
  if (!baked_name && asset.scene && asset.scene->environment) baked_name = *asset.scene->environment;
  std::vector<std::string> paths;
  if (baked_name) {
    const std::filesystem::path named(*baked_name), beside = std::filesystem::path(args.input).parent_path() / named.filename();
    if (std::filesystem::exists(named)) paths.push_back(named.string());
    else if (std::filesystem::exists(beside)) paths.push_back(beside.string());
    else
      std::fprintf(stderr, "prtbake: warning: export: %s was baked under %s, which is neither there nor beside the file: "
                   "give it as --env to relight with it\n", args.input.c_str(), baked_name->c_str());
  }
  paths.insert(paths.end(), args.envs.begin(), args.envs.end());
  std::vector<exports::WebEnvironment> out;
  for (const std::string& path : paths) {
    const bake::EnvMap env = bake::EnvMap::load(path, up);
    if (std::any_of(out.begin(), out.end(), [&](const exports::WebEnvironment& e) { return e.sha256 == env.info().sha256; }))
      continue;
    exports::WebEnvironment e;
    e.name = std::filesystem::path(path).filename().string();
    e.sha256 = env.info().sha256;
    e.order = order;
    e.radiance = env.project_sh(order);
    e.baked = recorded.count(e.sha256) > 0;
    out.push_back(std::move(e));
  }
  return out;
}

int run_export_web(const ExportArgs& args, const formats::Asset& asset) {
  const std::vector<exports::WebEnvironment> envs = web_environments(args, asset);
  exports::export_web(asset, args.input, args.output, envs);
  std::string names;
  for (const exports::WebEnvironment& e : envs) names += (names.empty() ? "" : ", ") + e.name + (e.baked ? " (baked with)" : "");
  std::printf("exported %s to %s/ (web; environments: %s)\n  to look at it: python3 -m http.server -d %s 8000, then open http://localhost:8000/\n",
              args.input.c_str(), args.output.c_str(), names.empty() ? "none" : names.c_str(), args.output.c_str());
  return 0;
}

} // namespace

int run_export(const ExportArgs& args) {
  const exports::ExportFormat format = *exports::parse_export_format(args.format);
  const formats::Asset asset = formats::read_asset(args.input);
  for (const formats::SkippedAttr& s : asset.skipped_attrs)  // another tool's; no export carries it
    std::fprintf(stderr, "prtbake: warning: export: %s: %s\n", args.input.c_str(), formats::describe(s).c_str());
  if (format == exports::ExportFormat::Web) return run_export_web(args, asset);
  std::optional<exports::EnvironmentProbe> environment;
  if (!args.envs.empty()) environment = environment_probe(args.envs.front(), asset, args.input);
  const exports::ExportSummary summary = exports::export_asset(asset, args.input, format, args.output, environment);
  // The sets left out, one line per reason naming them ("<name>: <why>" each).
  std::vector<std::pair<std::string, std::vector<std::string>>> by_reason;
  for (const std::string& entry : summary.left_out) {
    const size_t colon = entry.find(": ");
    const std::string name = entry.substr(0, colon), why = colon == std::string::npos ? "" : entry.substr(colon + 2);
    auto it = std::find_if(by_reason.begin(), by_reason.end(), [&](const auto& r) { return r.first == why; });
    if (it == by_reason.end()) it = by_reason.insert(by_reason.end(), {why, {}});
    it->second.push_back(name);
  }
  for (const auto& [why, sets] : by_reason) {
    std::string list;
    for (const std::string& n : sets) list += (list.empty() ? "" : ", ") + n;
    std::fprintf(stderr, "prtbake: warning: export: no %s probes for %s%s: %s\n", exports::to_string(format),
                 sets.size() == 1 ? "" : (std::to_string(sets.size()) + " vertex sets, ").c_str(), list.c_str(),
                 why.c_str());
  }
  std::string files;
  for (const std::filesystem::path& f : summary.written) files += (files.empty() ? "" : ", ") + f.string();
  std::printf("exported %s to %s (%s)\n", args.input.c_str(), files.c_str(), exports::to_string(format));
  return 0;
}

} // namespace prt::tool
