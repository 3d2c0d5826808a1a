// formats/prtfile.h — the baked file (HDF5, schema version 5): the in-memory model, the one
// writer, the one reader and the schema check. No algorithm code lives here; formats/ does not
// depend on libbake. The schema (every path, dtype, shape, attribute and convention) is
// specified in formats/SCHEMA.md (docs/ARCHITECTURE.md §5); every path and attribute
// name is in <formats/names.h>. This is the generic layer under the typed asset model
// (<formats/asset.h>), which is what tools and the runtime loader read and write.
//
// Model
//   A File is a list of root attributes, a list of datasets (each with an absolute path, a
//   row-major shape, typed data and attributes) and a list of group attributes. Groups are not
//   listed: they exist because a dataset lies under them or because they carry attributes.
//   On-disk types: std::vector<float> <-> float32 (IEEE little endian), std::vector<uint32_t>
//   <-> uint32, std::vector<uint8_t> <-> uint8. Attribute values: std::string <-> fixed-length
//   UTF-8 string (the writer's; other tools' strings are read too, fixed- or variable-length:
//   "Which files the reader opens"), int64_t <-> scalar int64, double <-> scalar float64,
//   std::vector<double>, std::vector<int64_t> and std::vector<std::string> <-> 1-D arrays (a
//   one-element vector stays a vector; strings written fixed-length, as long as the longest).
//
// Writer contract (write_file)
//   * Validates the whole File against schema v5 (validate()) before touching the disk.
//   * Adds format="prtbake" and format_version=written_format_version(file) itself: 8 when a
//     dataset is float16 (FIV shells or cones), 7 when the file holds surface-following shells or
//     an FIV cone table (/fiv/occluders/<name>/cones or `proxy`), else 6 with a
//     punctual light, else 5 when the
//     file holds a version-5 dataset (/mesh/uv, /lightmap/..., in any vertex set), else 4, so a
//     file that needs nothing of version 5 keeps the bytes version 4 gave it (SCHEMA.md,
//     "Versioning"). The caller gives every other required root attribute (generator, created,
//     command_line, source, source_sha256, up_axis, sh_convention).
//   * Writes "<dir>/<name>.tmp.<host>.<pid>" and renames it onto the final name: on any error the
//     temporary file is removed, nothing new exists under the final name and a file already
//     there is untouched. A temporary of a bake to the same name that was killed (kill -9) on
//     this machine — its pid no longer alive — is removed first; a live pid's, or another
//     machine's (a shared disk), is never touched.
//   * Deterministic: the same File gives the same bytes (no object time stamps, fixed library
//     format bounds), whatever the thread count. Datasets are chunked along the first axis
//     (~64 KiB chunks), shuffled, deflated (libdeflate, level 6) and fletcher32-checksummed, by
//     the writer itself, chunks in parallel (oneTBB; formats/src/chunk_filters.h).
//
// Reader contract (read_file)
//   * Reads every dataset and every attribute of the root, of each group and of each dataset.
//     Datasets come back sorted by path, attributes sorted by name, group_attrs sorted by path
//     (the writer keeps the caller's order; compare by name, not by position).
//   * Checks format=="prtbake" and format_version 1..kFormatVersion (a newer version is rejected
//     with "written by a newer prtbake (format_version N > 5)"). With ReadCheck::full (the default)
//     it then applies validate(), so callers can trust shapes, index ranges and finiteness.
//   * Damaged, truncated or non-HDF5 files give a FormatError naming the file; never a crash.
//   * An attribute the model cannot hold, or whose text cannot be read safely (a variable-length
//     string in a damaged global heap), is left out and listed in File::skipped_attrs with the
//     reason: another tool's attribute never makes a file unreadable (SCHEMA.md, "Extra
//     attributes"). A schema attribute left out so is then missing, which validate() reports.
//
// Which files the reader opens
//   HDF5 1.10 parses what it reads from a file without bounds checks in several places; a
//   damaged file can crash it (SIGSEGV, heap overflow, SIGFPE). Its newer on-disk structures carry
//   checksums that HDF5 verifies before parsing, so the reader opens only files made of those —
//   what our writer makes — and checks that from the raw bytes BEFORE HDF5 parses a structure:
//   * the superblock: HDF5's signature at byte 0 (no user block), version 2 or 3 (checksummed),
//     8-byte offsets and lengths, base address 0, an end-of-file address within the file;
//   * every object header (the root group, the superblock extension, each hard link's target,
//     by its address, before it is opened): version 2 ("OHDR", checksummed);
//   * once a header is loaded: no old-style symbol-table group, no version-1 B-tree chunk index.
//   Anything else — HDF5's oldest format (superblock 0/1, version-1 object headers, as HDF5 and
//   h5py write by default), user blocks, soft and external links — is refused with a message
//   that says so (`h5repack --latest --filter=FLET IN OUT` rewrites another tool's file into
//   the accepted format; --latest alone copies object headers unchanged). What remains reaches HDF5 only through checksummed metadata: a flipped or truncated
//   byte is a checksum or bounds error, not a crash. Variable-length strings (h5py's default
//   for a str attribute) keep their text in a global heap, which has no checksum and which a
//   flipped byte made HDF5 crash or hang on (docs/RELIABILITY.md): HDF5 never reads it here. It
//   hands back the references stored in the (checksummed) attribute, and the reader's own
//   bounds-checked code reads the text from the raw bytes (formats/src/global_heap.h); a
//   reference or collection it finds damaged leaves the attribute out (File::skipped_attrs).
//   A file crafted on purpose with valid checksums is beyond what checks of this kind can
//   promise; docs/RELIABILITY.md records what was fuzzed.
//
// Errors: every failure is a FormatError whose what() is one line "<file>: <defect>".
// Threads: serial HDF5 is not thread-safe; write_file/read_file serialise their HDF5 calls with
// one process-wide mutex, so they may be called from any thread.
#pragma once

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

namespace prt::formats {

// The newest schema version this library reads, and the one it writes for a file that holds a
// float16 FIV shells or cone table (written_format_version; policy: SCHEMA.md "Versioning").
// 9 added /fiv/occluders/<name>/self_band1 (a scene file's FIV occluder's self-shadows at its vertices; issue 33).
// 8 added dtype float16 for /fiv/occluders/<name>/shells and cones (half the memory; issue 33). 7 added surface-following FIV shells (/fiv/occluders/<name>/surface_radius, the
// shells' radial_scheme and first_offset attributes) and the tight occluder proxy
// (/fiv/occluders/<name>/cones and the group attribute `proxy`); 6 punctual lights (/lights/<name>
// of shape point, spot or directional: attributes, no geometry); 5 lightmaps (/mesh/uv,
// /lightmap/...); 4 shadowed radiance (/radiance/shadowed); 3 area lights (/lights,
// area_lights/*); 2 scene objects (/objects). Older files still read.
inline constexpr int kFormatVersion = 9;
// The version written for a file with an FIV occluder's self_band1.
inline constexpr int kFormatVersionWithSelfShadows = 9;
// The version written for a file with float16 FIV shells or cones (and no self_band1).
inline constexpr int kFormatVersionWithHalfShells = 8;
// The version written for a file with FIV cones (/fiv/occluders/<name>/cones or a `proxy`
// attribute: the tight occluder proxy) or surface-following shells.
inline constexpr int kFormatVersionWithCones = 7;
// The version written for a file with a punctual light and no version-7 data.
inline constexpr int kFormatVersionWithPunctualLights = 6;
// The version written for a file with a lightmap and no punctual light.
inline constexpr int kFormatVersionWithLightmaps = 5;
// The version written for a file without any version-5 dataset: such a file is byte for byte
// what this library wrote before version 5 existed, and version-4 readers open it.
inline constexpr int kFormatVersionWithoutLightmaps = 4;
// Value of the root attribute "format".
inline constexpr std::string_view kFormatName = "prtbake";

using AttrValue = std::variant<std::string, int64_t, double, std::vector<double>, std::vector<int64_t>,
                               std::vector<std::string>>;

struct Attr {
  std::string name;
  AttrValue value;
  bool operator==(const Attr&) const = default;
};

// An IEEE 754 binary16 value by its bits: dtype "float16" (v8), the FIV shells and cone tables
// stored compactly (SCHEMA.md "/fiv"). to_float / to_float16 convert (OpenEXR's Imath::half:
// exact one way, round to nearest even the other).
struct Float16 {
  uint16_t bits = 0;
  bool operator==(const Float16&) const = default;
};
float to_float(Float16 h);
Float16 to_float16(float f);  // |f| beyond 65504 rounds to ±inf (the schema refuses it)
// The binary16 bits of each value (to_float16): for a runtime that holds a float16 table as
// read (asset.h gives its values as floats, each one a half).
std::vector<uint16_t> float16_bits(const std::vector<float>& values);

using DatasetData = std::variant<std::vector<float>, std::vector<uint32_t>, std::vector<uint8_t>, std::vector<double>,
                                 std::vector<Float16>>;

struct Dataset {
  std::string path;              // absolute, e.g. "/transfer/diffuse"; parent groups are created
  std::vector<uint64_t> shape;   // row-major; data.size() == product(shape)
  DatasetData data;              // float32 / uint32 / uint8 / float64 / float16 (v8) on disk
  std::vector<Attr> attrs;
  bool operator==(const Dataset&) const = default;
};

// An attribute the reader left out, and why (reader contract above).
struct SkippedAttr {
  std::string path;    // where it is: "/" for the root group, else the group's or dataset's path
  std::string owner;   // the same as messages name it: "the root group", "group '/mesh'", "dataset '/ao'"
  std::string name;    // the attribute's name
  std::string reason;  // why, e.g. "its text is in an HDF5 global heap that cannot be read safely: ..."
  bool operator==(const SkippedAttr&) const = default;
};
// "attribute '<name>' of <owner> skipped: <reason>" (one line).
std::string describe(const SkippedAttr& skipped);

struct File {
  std::vector<Attr> root_attrs;
  std::vector<Dataset> datasets;
  // Attributes of groups, by absolute group path, e.g. {"/report", {{"rmse", 1e-3}, ...}}.
  // Allowed groups: /mesh, /transfer, /radiance, /area_lights, /fiv, /fiv/occluders, /fiv/occluders/<name>,
  // /lights, /lights/<name> (v3: a light's shape, radiance, two_sided),
  // /report and any group under /report. The root's attributes go in root_attrs, not here.
  std::vector<std::pair<std::string, std::vector<Attr>>> group_attrs;
  // Attributes the reader left out (sorted by path, then name); the writer writes none of them.
  std::vector<SkippedAttr> skipped_attrs;
};

// An input error about a baked file: what() == "<file>: <defect>" (one line).
class FormatError : public std::runtime_error {
public:
  FormatError(const std::string& file, const std::string& defect)
      : std::runtime_error(file.empty() ? defect : file + ": " + defect), file_(file),
        defect_(defect) {}
  const std::string& file() const noexcept { return file_; }
  const std::string& defect() const noexcept { return defect_; }

private:
  std::string file_, defect_;
};

// Writes `file` to `final_path` (see the writer contract above). Throws FormatError.
void write_file(const std::filesystem::path& final_path, const File& file);

enum class ReadCheck {
  full,    // format, format_version and the whole schema v5 (validate())
  header,  // format and format_version only: for inspectors (prtdump) that show what is wrong
};

// Reads the whole file at `path` (see the reader contract above). Throws FormatError.
File read_file(const std::filesystem::path& path, ReadCheck check = ReadCheck::full);

// Checks `file` against schema v5 exactly as write_file does; messages name `file_for_messages`.
// Root "format"/"format_version" may be absent (the writer adds them) but, if present, must be
// "prtbake" / 1..kFormatVersion, and every dataset must be one that version has. Throws
// FormatError on the first defect found.
void validate(const File& file, const std::filesystem::path& file_for_messages);

// The format_version write_file gives `file`: kFormatVersionWithSelfShadows when it holds an
// occluder's self_band1, else kFormatVersionWithHalfShells when a dataset is float16, else kFormatVersionWithCones when it holds surface-following FIV shells (an occluder's surface_radius dataset, or a shells dataset
// with a radial_scheme or first_offset attribute) or an FIV cone table (/fiv/occluders/<name>/cones
// or a group attribute `proxy`), else kFormatVersionWithPunctualLights when it holds a punctual
// light (a /lights/<name> group whose shape is_punctual_shape), else kFormatVersionWithLightmaps
// when a dataset of it is of a version-5 kind (is_lightmap_kind), else kFormatVersionWithoutLightmaps.
int64_t written_format_version(const File& file);

// Lookups; nullptr when absent.
const Attr* find_attr(const std::vector<Attr>& attrs, std::string_view name);
const Dataset* find_dataset(const File& file, std::string_view path);
const std::vector<Attr>* find_group_attrs(const File& file, std::string_view group_path);

// True for the schema's per-vertex datasets (first axis = V = rows of the vertex set's
// mesh/positions): /mesh/positions, /mesh/normals, /mesh/source_position, /ao, /transfer/diffuse,
// /transfer/visibility, /radiance/band1, /radiance/shadowed (v4), /area_lights/{irradiance,sh} (v3),
// and the same under
// /objects/<name>/ (scene files, v2). /report datasets are never per-vertex, nor are a
// lightmap's (v5: /mesh/uv is per triangle corner, /lightmap/... per texel).
bool is_per_vertex_path(std::string_view path);
// What a dataset path is in the schema (the same rules under /objects/<name>/ for vertex sets).
enum class DatasetKind {
  positions, normals, triangles, source_position, ao, transfer_diffuse, transfer_visibility,
  radiance_band1, radiance_shadowed, area_irradiance, area_sh, fiv_environment, irradiance_cube, occluder_shells, occluder_valid,
  occluder_surface_radius,  // v7
  occluder_cones,  // v7
  occluder_self_band1,  // v9
  light_vertices, light_face_sizes, light_face_indices,
  uv, lightmap_state, lightmap_positions, lightmap_normals, lightmap_ao, lightmap_transfer_diffuse,  // v5
  lightmap_transfer_visibility, lightmap_radiance_band1, lightmap_radiance_shadowed,                // v5
  lightmap_area_irradiance, lightmap_area_sh,                                                       // v5
  report, unknown
};
DatasetKind dataset_kind(std::string_view path);
// True for the kinds version 5 added: a vertex set's /mesh/uv and its /lightmap/... datasets.
bool is_lightmap_kind(DatasetKind kind);
// The vertex set a dataset path belongs to: "" for the root layout, "/objects/<name>" for a scene
// object (its V is the rows of "<set>/mesh/positions").
std::string vertex_set_of(std::string_view path);

// The names of an area-light dataset's `lights` attribute (names::kLightOrder): one per line, in
// column order. An empty list gives no names.
std::vector<std::string> split_light_list(std::string_view list);
// The inverse: names joined with '\n'.
std::string join_light_list(const std::vector<std::string>& names);

// "float32", "uint32", "uint8", "float64" or "float16".
std::string_view dtype_name(const DatasetData& data);
// Number of elements of `data`.
std::size_t element_count(const DatasetData& data);
// Product of `shape` (1 for an empty shape); throws FormatError("", ...) on overflow.
uint64_t shape_product(const std::vector<uint64_t>& shape);

} // namespace prt::formats
