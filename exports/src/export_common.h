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
  // Renames every staged file onto its final path, in the order staged. FormatError.
  void commit();

private:
  std::filesystem::path out_, dir_;
  std::vector<std::pair<std::filesystem::path, std::filesystem::path>> files_;  // staged, final
};

// Writes `bytes` to `path` (a staged file); FormatError naming `out` on failure.
void write_bytes(const std::filesystem::path& path, const std::string& bytes, const std::filesystem::path& out);

// The three exporters.
void export_gltf(const Asset& asset, const std::filesystem::path& out, bool glb);
void export_binary(const Asset& asset, const std::filesystem::path& out);
// Returns the sets it skipped (no /radiance/band1), each as "<name>: <why>".
std::vector<std::string> export_probes(const Asset& asset, const std::filesystem::path& source, ExportFormat engine,
                                       const std::filesystem::path& out,
                                       const std::optional<EnvironmentProbe>& environment);

} // namespace prt::exports::detail
