// exports/export.h — a baked asset for consumers that read neither HDF5 nor our schema: glTF 2.0
// with the baked per-vertex data as vertex attributes, a plain binary file with a JSON header,
// and per-vertex light probes in the SH conventions of Unity, Godot and Filament; lightmaps
// (format v5) as glTF's occlusion texture on TEXCOORD_1, half-float EXR images and Godot 4's
// directional (L1 SH) lightmap layout. The layouts
// are formats/SCHEMA.md "Exports" (docs/ARCHITECTURE.md "Schema"); the engine conventions are
// prtshade/conventions.h.
//
// Target prt::exports (exports/): formats' asset model in, tinygltf, nlohmann-json and
// prtshade's conventions out. It is a component of its own so that formats (and the runtime
// loader, which links formats) needs none of the exporters' dependencies.
//
// Contract
//   * Every vertex set with at least one vertex is exported: the root layout, then each scene
//     object in the asset's order (read_asset: by name). Values are the file's, unchanged
//     (float32); positions are float32 or float64 as in the file (glTF: float32 relative to a
//     node translation, see SCHEMA.md).
//   * Outputs are written to a staging directory beside `out` and renamed into place: on any
//     error nothing exists under the final name(s) and files already there are untouched.
//     glTF (.gltf) writes two files: `out` and its buffer `<stem>.bin` beside it.
//   * The engine formats need /radiance/band1 in some vertex set (the only baked product that is
//     lighting; see SCHEMA.md "Exports" for why the others are not probes) or an environment probe
//     (godot: or a lightmap with /lightmap/radiance/band1, written as its directional lightmap).
//     A set without it gets no probes; the summary names it and says why (the caller reports).
//   * Lightmaps: bin carries /mesh/uv and every /lightmap/... array; glTF carries every set's lightmap (TEXCOORD_1 from /mesh/uv, split vertices where
//     corners of one vertex carry different UVs; AO as occlusionTexture; the float datasets as
//     buffer views named in extras). `exr` needs a lightmap (FormatError naming the input
//     otherwise) and writes one file per set with one: `out` names an existing directory
//     (DIR/lightmap.exr, DIR/lightmap.<object>.exr) or a prefix (OUT.exr, OUT.<object>.exr;
//     a trailing ".exr" of OUT is dropped first).
// Errors: formats::FormatError "<file>: <problem>" (the input for what it lacks, the output for I/O).
#pragma once

#include <formats/asset.h>
#include <formats/prtfile.h>

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace prt::exports {

enum class ExportFormat { Gltf, Glb, Binary, Unity, Godot, Filament, Exr, Web };

// "gltf", "glb", "bin", "unity", "godot", "filament", "exr", "web" (nullopt for anything else).
std::optional<ExportFormat> parse_export_format(std::string_view name);
const char* to_string(ExportFormat format) noexcept;
// Unity, Godot, Filament: the light-probe formats (the ones an EnvironmentProbe may join).
constexpr bool is_probe_format(ExportFormat f) noexcept {
  return f == ExportFormat::Unity || f == ExportFormat::Godot || f == ExportFormat::Filament;
}

// The sky as a light probe (the probe formats only): the radiance SH of order 3 of an environment
// map, in our convention and the file's frame ([RGB][i], index l(l+1)+m), with the map's name and
// SHA-256. Written as the export's "environment" probe in the engine's convention — the ambient
// probe for what the bake does not cover (dynamic objects), consistent with the baked lighting.
struct EnvironmentProbe {
  std::array<std::array<double, 9>, 3> radiance{};
  std::string name, sha256;
};

// What an export left out: per vertex set "<name>: <why>" (the probe formats skip the sets without
// /radiance/band1; the other formats export every set); and the files it wrote, in order.
struct ExportSummary {
  std::vector<std::string> left_out;
  std::vector<std::filesystem::path> written;
};

// Writes `asset` (read from `source`, named in messages about what it lacks) as `format` to `out`;
// `environment` adds the environment probe (probe formats only; std::invalid_argument otherwise).
// Web is export_web (std::invalid_argument here: it takes environments).
ExportSummary export_asset(const formats::Asset& asset, const std::filesystem::path& source, ExportFormat format,
                  const std::filesystem::path& out, const std::optional<EnvironmentProbe>& environment = std::nullopt);

// ---- the web viewer (issue 34) ----
// An environment for the viewer: its radiance SH of order `order` in the file's frame, [i*3 + c]
// (index l(l+1)+m, as bake::EnvMap::project_sh gives it), its name and SHA-256, and whether the
// file's lighting was baked with it.
struct WebEnvironment {
  std::string name, sha256;
  int order = 0;
  std::vector<double> radiance;  // [order²][RGB]
  bool baked = false;
};
// Whether this build carries the viewer (three.js was installed by npm when it was built), and
// why not: nullptr when it does.
const char* web_viewer_missing() noexcept;
// Writes the folder `out` (created; a folder holding an earlier web export, i.e. viewer.json, is
// replaced; any other existing path is refused): index.html, viewer.js, the shading bodies of the
// GLSL mirrors under shaders/, three.js under three/, the glb (asset.glb, export_asset's Glb) and
// viewer.json: the file's metadata (root attributes, per vertex set its products with their
// integrator, samples and environment, its error report, the albedo prtview multiplies by), the
// area lights (name, shape, radiance) and per environment the radiance SH
// turned about +Y by every whole degree d in [0, 360) (prt::sh::Rotation of R_y(d): (x, z) →
// (x cos d + z sin d, −x sin d + z cos d)), channel-major [3][order²], each number rounded to 9
// significant digits, the clamped-cosine factors Â_l for the unshadowed view and a default
// exposure: 1 / max over 4,096 normals (spherical Fibonacci) of the luminance of the order-3
// unshadowed irradiance / π, to 4 digits — prtview's rule (view/exposure.h) on the SH-band-limited
// sky. Staged beside `out` and renamed into place. Needs a vertex set with triangles and normals
// and at least one of /ao, /transfer/diffuse, /radiance/band1, /area_lights/irradiance
// (FormatError naming `source`);
// environments are not required (band-1 radiance shades without one). Deterministic: the same
// inputs give the same bytes. FormatError also when the build has no viewer (web_viewer_missing).
std::vector<std::filesystem::path> export_web(const formats::Asset& asset, const std::filesystem::path& source,
                                              const std::filesystem::path& out, const std::vector<WebEnvironment>& environments);

// The binary format's magic (8 bytes) and version (SCHEMA.md "Exports").
inline constexpr char kBinaryMagic[8] = {'P', 'R', 'T', 'B', 'I', 'N', '\0', '\0'};
inline constexpr uint32_t kBinaryVersion = 1;

} // namespace prt::exports
