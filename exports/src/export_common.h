// export_common.h (private to exports) — what the exporters share: the vertex sets and products
// of an asset in export order, and the staging directory that makes outputs appear whole
// (contract: exports/export.h).
#pragma once

#include <exports/export.h>

#include <formats/asset.h>
#include <formats/names.h>
#include <formats/prtfile.h>

#include <filesystem>
#include <string>
#include <vector>

namespace prt::exports::detail {

// The baked file's model and names, which every exporter reads.
using formats::Asset;
using formats::FormatError;
using formats::Product;
using formats::RootInfo;
using formats::SceneObject;
using formats::VertexSet;
namespace names = formats::names;

// A vertex set to export: the root layout (prefix "", name from the source file) or a scene
// object (prefix "objects/<name>").
struct SetRef {
  std::string name;    // the root layout: "root"; an object: its node path, else its name
  std::string prefix;  // "" or "objects/<name>" (no leading or trailing '/')
  const VertexSet* set = nullptr;
};
// Every vertex set with at least one vertex, the root layout first, then the objects in the asset's order.
std::vector<SetRef> vertex_sets(const Asset& asset);

// A baked per-vertex product of a set: its dataset name ("ao", "transfer/diffuse", ...) relative
// to the set's prefix, its per-vertex shape after the vertex axis, and the product.
struct ProductRef {
  std::string dataset;
  std::vector<uint64_t> shape;  // e.g. {} for /ao, {L*L} for transfer, {3, 3} for band-1 radiance
  const Product* product = nullptr;
  uint64_t components() const noexcept;  // product of `shape` (1 for a scalar)
};
std::vector<ProductRef> products(const VertexSet& set);

// True when every coordinate is a float32 exactly (the file then stores float32 positions).
bool exactly_float(const std::vector<double>& values) noexcept;

// "<prefix>/<dataset>" or "<dataset>" for the root layout.
std::string join(const std::string& prefix, const std::string& dataset);

// Staged outputs: files are written under a hidden directory beside the final output
// (".<name>.export.<host>.<pid>") and renamed into place by commit(); the destructor removes the
// directory and anything left in it. The constructor first removes the staging directories that
// killed exports to the same name on this machine left (formats/temporaries.h).
class Staging {
public:
  // Checks that `out` can be written (its directory exists, it is not a directory); FormatError.
  explicit Staging(const std::filesystem::path& out);
  ~Staging();
  Staging(const Staging&) = delete;
  Staging& operator=(const Staging&) = delete;

  const std::filesystem::path& directory() const noexcept { return dir_; }
  // The staged path of `final_path` (a file in the output's directory); commit() moves it there.
  std::filesystem::path stage(const std::filesystem::path& final_path);
  // Renames every staged file onto its final path, in the order staged; returns those paths.
  // FormatError.
  std::vector<std::filesystem::path> commit();

private:
  std::filesystem::path out_, dir_;
  std::vector<std::pair<std::filesystem::path, std::filesystem::path>> files_;  // staged, final
};

// Writes `bytes` to `path` (a staged file); FormatError naming `out` on failure.
void write_bytes(const std::filesystem::path& path, const std::string& bytes, const std::filesystem::path& out);

// ---- lightmaps (format v5; lightmap_images.cpp) ----

using formats::Lightmap;

// A vertex set with a lightmap (and its /mesh/uv), in vertex_sets' order.
struct LightmapRef {
  SetRef set;
  const Lightmap* lightmap = nullptr;
};
std::vector<LightmapRef> lightmap_sets(const Asset& asset);

// The products of a lightmap as ProductRefs: dataset relative to the set ("lightmap/ao", ...),
// shape after the [H][W] axes ({} for AO, {L*L} for transfer, {3, 3} / {3, L*L} for radiance).
std::vector<ProductRef> lightmap_products(const Lightmap& m);

// One float image of a lightmap, [H][W] texels: a channel of a product (or the state mask).
// `name` is the EXR channel name (formats/SCHEMA.md "Exports", "Lightmaps"): "state", "ao",
// "transfer.diffuse.c<i>", "transfer.visibility.c<i>", "radiance.band1.<R|G|B>.m<-1|0|1>",
// "radiance.shadowed.<R|G|B>.c<i>"; `dataset` and `component` say where it comes from.
struct LightmapChannel {
  std::string name, dataset;  // dataset relative to the set ("lightmap/ao")
  uint64_t component = 0;     // index in the dataset's per-texel row
  std::vector<float> values;  // [H][W]
};
// The state mask and every product of `m` as channels, in the dataset order of SCHEMA.md.
std::vector<LightmapChannel> lightmap_channels(const Lightmap& m);

// The lightmap files of an export: "<prefix>.exr" for the root layout, "<prefix>.<name>.exr"
// for a scene object (its name as stored: '|' for '/' in glTF node paths).
std::filesystem::path lightmap_file(const std::filesystem::path& prefix, const SetRef& set, std::string_view suffix = "");

// An 8-bit greyscale PNG (libpng, no sRGB chunk: the values are linear data) of `grey`, [H][W],
// row 0 first; FormatError naming `out` when libpng fails.
std::string encode_png_grey(const std::vector<uint8_t>& grey, uint64_t width, uint64_t height,
                            const std::filesystem::path& out);

// A half-float OpenEXR image (scanlines, ZIP, one part) of the channels, each [H][W] floats, row
// 0 at the top (OpenEXR's data window y = 0). Every value must be finite in half (|x| ≤ 65504):
// FormatError naming `source`, the set and the channel otherwise; FormatError naming `out` on
// I/O errors.
struct ExrChannel {
  std::string name;
  const std::vector<float>* values = nullptr;
};
void write_exr_half(const std::filesystem::path& path, uint64_t width, uint64_t height,
                    const std::vector<ExrChannel>& channels, const std::filesystem::path& source, const SetRef& set,
                    const std::filesystem::path& out);

// The exporters; each returns the files it wrote, in the order written.
std::vector<std::filesystem::path> export_gltf(const Asset& asset, const std::filesystem::path& out, bool glb);
// Lightmaps as half-float EXR files (OUT a directory or a prefix, see export.h).
std::vector<std::filesystem::path> export_exr(const Asset& asset, const std::filesystem::path& source,
                                              const std::filesystem::path& out);
std::vector<std::filesystem::path> export_binary(const Asset& asset, const std::filesystem::path& out);
// Returns the sets it skipped (no /radiance/band1), each as "<name>: <why>".
// Godot also writes the directional (L1 SH) lightmap of every set with /lightmap/radiance/band1.
// Fills the summary: the sets it skipped (no /radiance/band1), each as "<name>: <why>", and the
// files written.
void export_probes(const Asset& asset, const std::filesystem::path& source, ExportFormat engine,
                   const std::filesystem::path& out, const std::optional<EnvironmentProbe>& environment,
                   ExportSummary& summary);

} // namespace prt::exports::detail
