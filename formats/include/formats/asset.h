// formats/asset.h — the typed asset model: plain structs that describe a baked file (vertex sets
// and their products, FIV environment data and occluders, the scene and its objects, error
// reports, the area lights, the root attributes) and write_asset / read_asset. Every path and attribute name
// lives in <formats/names.h>; the schema is formats/SCHEMA.md (docs/ARCHITECTURE.md §5).
//
// Contract
//   * write_asset(path, a) converts `a` to the generic File (to_file) and writes it with
//     write_file: the schema check, temp file + rename and deterministic bytes of prtfile.h.
//     Datasets are written in a fixed order (root vertex set — mesh, products, then its UV set
//     and lightmap (v5) — and its report; then each scene
//     object with its report, the occluder of the same name and that occluder's report; then
//     the FIV environment; then the other occluders; then the lights; then other /report datasets), attributes
//     in the order of the field tables in asset.cpp followed by the extra attributes.
//   * read_asset(path) reads with read_file (full schema check) and converts (to_asset).
//     read_asset(write_asset(a)) == a for every field (std::optional: absent stays absent;
//     root.format_version when it is the version written, RootInfo).
//   * Extra attributes: any attribute the model does not type (another tool's, e.g. h5py's
//     `f.attrs["note"] = "..."`, fixed- or variable-length string, or a list of them) is kept in
//     `extra` of its location (root, /scene, /objects/<name>, each dataset) or, for other groups,
//     in Asset::group_extras; it is written back (strings as fixed-length ones) and never makes a
//     file unreadable. An attribute with a schema name but another type than the model's is kept
//     there too. One the reader cannot hold or read safely (a bool, a compound; a string in a
//     damaged global heap) is left out and named in Asset::skipped_attrs with the reason;
//     write_asset writes nothing for it.
//   * inspect_asset(path) is for inspectors (prtdump): the file as stored (format and version
//     checked only) and, when it passes the schema, the asset; else the schema defect.
// Errors: FormatError "<file>: <defect>" (prtfile.h).
#pragma once

#include <formats/prtfile.h>

#include <array>
#include <optional>

namespace prt::formats {

// Attributes at one location that the model does not type: kept, written back, shown.
using ExtraAttrs = std::vector<Attr>;

// A dataset the model holds as a plain array with no typed attributes.
template <class T> struct Array {
  std::vector<T> values;
  ExtraAttrs extra;
  bool operator==(const Array&) const = default;
};

// The root attributes (all required except the extras; format/format_version are the writer's).
struct RootInfo {
  // As read. write_asset ignores it and writes written_format_version (prtfile.h): 5 for an asset
  // with a lightmap or UV set, 6 with a punctual light, 7 with surface-following FIV shells or an
  // FIV cone table, else 4, so a round trip keeps it only when it is that version.
  int64_t format_version = kFormatVersion;
  std::string generator, created, command_line, source, source_sha256, up_axis, sh_convention;
  ExtraAttrs extra;
  bool operator==(const RootInfo&) const = default;
};

// /mesh/normals: the normals the bake used, and where they came from ("file", "angle-weighted").
struct Normals {
  std::vector<float> values;  // [V][3]
  std::optional<std::string> source;
  ExtraAttrs extra;
  bool operator==(const Normals&) const = default;
};

// A baked per-vertex product: /ao [V], /transfer/diffuse and /transfer/visibility [V][L*L]
// (sh_order = L, required there), /radiance/band1 [V][RGB][m = -1, 0, 1] (environment fields),
// /radiance/shadowed [V][RGB][L*L] (v4; sh_order = L required, environment fields),
// /area_lights/irradiance [V][lights] and /area_lights/sh [V][lights][n*n] (sh_order = n; `lights`
// required there: the lights' names in column order, join_light_list).
struct Product {
  std::vector<float> values;
  std::optional<std::string> integrand;
  std::optional<int64_t> sh_order;
  std::optional<std::string> shading, environment, environment_sha256, environment_layout;
  std::optional<int64_t> negative_pixels_clamped;
  std::optional<std::string> integrator, integrator_description;
  std::optional<int64_t> samples, seed;  // samples: rays per vertex (qmc) or k (silhouette)
  std::optional<std::string> visibility;  // the visibility convention in words
  std::optional<std::string> lights;      // area-light products: names::kLightOrder
  // Interreflections (transfer/diffuse; SCHEMA.md "Bounces"): the bounces summed into the values,
  // those asked for, the albedo (RGB) they were bounced with and the gather rays per receiver.
  std::optional<int64_t> bounces, bounces_requested, bounce_rays;
  std::optional<std::vector<double>> albedo;
  std::optional<double> bounce_std_error;  // the bounces' Monte Carlo error relative to the direct RMS
  ExtraAttrs extra;
  bool operator==(const Product&) const = default;
};

// One row of an error report: a [5] float32 dataset (rmse, max_abs, reference_rms,
// bake_std_error, reference_std_error) named after its product ("ao", "transfer/diffuse", ...).
struct ReportRow {
  std::string product;
  std::array<float, 5> values{};
  std::optional<std::string> columns;
  std::optional<int64_t> points;
  std::optional<std::string> reference;
  std::optional<double> reference_seconds, bake_seconds, integrals_per_second;
  // Band-1 and S rows (files from 2026-12-06 on): the product's RMS over every row of the set the
  // report covers, which the relative error divides by (SCHEMA.md "Error reports").
  std::optional<double> mesh_rms;
  ExtraAttrs extra;
  bool operator==(const ReportRow&) const = default;
};

// The error report of one vertex set: /report (root layout) or /report/objects/<name>.
struct Report {
  std::vector<ReportRow> rows;
  std::optional<Array<uint32_t>> vertices;  // the seeded vertices compared
  bool empty() const noexcept { return rows.empty() && !vertices; }
  bool operator==(const Report&) const = default;
};

// /mesh/uv (v5): the UV set a lightmap is baked in, per triangle corner [T][3][2] (u, v; v down
// the image as glTF's TEXCOORD_n), and the set's name in the asset.
struct Uvs {
  std::vector<float> values;
  std::optional<std::string> uv_set;
  ExtraAttrs extra;
  bool operator==(const Uvs&) const = default;
};

// /lightmap/... (v5): a vertex set's surface baked per texel of an H × W image (row 0 at v = 0).
// `state` [H][W]: 0 empty (no triangle covers it), 1 baked, 2 filled (inside the geometry: from
// its chart's valid neighbours), 3 padding (a chart's gutter); products as the per-vertex ones
// with the vertex axis replaced by [H][W]; positions and normals of the texels' shade points
// (world space; 0 where empty or padding).
struct Lightmap {
  uint64_t width = 0, height = 0;
  Array<uint8_t> state;
  std::optional<int64_t> padding;  // attribute of state
  std::optional<Array<double>> positions;  // float32 on disk when exact, else float64 (as /mesh/positions)
  std::optional<Array<float>> normals;
  std::optional<Product> ao, transfer_diffuse, transfer_visibility, radiance_band1, radiance_shadowed;
  std::optional<Product> area_irradiance, area_sh;  // the area lights, as a vertex set's, per texel
  std::size_t texel_count() const noexcept { return std::size_t(width * height); }
  bool operator==(const Lightmap&) const = default;
};

// A vertex set: the root layout or one scene object's /objects/<name>/... (SCHEMA.md).
struct VertexSet {
  // [V][3], world space. Held in double; write_asset stores them as float32 when every
  // coordinate is exactly a float32 (an ordinary mesh: the bytes of a float32 file) and as
  // float64 otherwise (a mesh far from the origin, whose float32 rounding would move or merge
  // vertices). read_asset widens float32 exactly, so read(write(a)) == a either way.
  std::optional<Array<double>> positions;
  std::optional<Normals> normals;                  // [V][3]
  std::optional<Array<uint32_t>> triangles;        // [T][3]
  std::optional<Array<uint32_t>> source_position;  // [V]
  std::optional<Product> ao, transfer_diffuse, transfer_visibility, radiance_band1;
  std::optional<Product> area_irradiance, area_sh;  // v3
  std::optional<Product> radiance_shadowed;         // v4
  std::optional<Uvs> uv;                            // v5
  std::optional<Lightmap> lightmap;                 // v5
  Report report;

  std::size_t vertex_count() const noexcept { return positions ? positions->values.size() / 3 : 0; }
  bool empty() const noexcept {
    return !positions && !normals && !triangles && !source_position && !ao && !transfer_diffuse &&
           !transfer_visibility && !radiance_band1 && !area_irradiance && !area_sh && !radiance_shadowed && !uv &&
           !lightmap && report.empty();
  }
  bool operator==(const VertexSet&) const = default;
};

// /fiv/environment: F_env = Int L_c w dw, [RGB][xyz].
struct FivEnvironment {
  std::array<float, 9> f_env{};
  std::optional<std::string> environment, environment_sha256, integrand;
  ExtraAttrs extra;
  bool operator==(const FivEnvironment&) const = default;
};

// /fiv/irradiance_cube: the DifMap E(n), [face][row][col][RGB], S = size.
struct IrradianceCube {
  int size = 0;
  std::vector<float> values;  // [6][S][S][3]
  std::optional<std::string> environment, environment_sha256, integrand, face_convention;
  ExtraAttrs extra;
  bool operator==(const IrradianceCube&) const = default;
};

// /fiv/occluders/<name>/valid: 1 where the shell sample lies outside the occluder.
struct OccluderValid {
  std::vector<uint8_t> values;  // [Nrho][Ntheta][Nphi]
  std::optional<std::string> meaning;
  ExtraAttrs extra;
  bool operator==(const OccluderValid&) const = default;
};

// /fiv/occluders/<name>/surface_radius (v7): r_surf per shell direction, [Ntheta][Nphi].
struct OccluderSurfaceRadius {
  std::vector<float> values;
  std::optional<std::string> meaning;
  ExtraAttrs extra;
  bool operator==(const OccluderSurfaceRadius&) const = default;
};

// /fiv/occluders/<name>/cones (v7): the tight proxy, per shell sample the occluded moment and solid
// angle (m_x, m_y, m_z, Ω), [Nrho][Ntheta][Nphi][4] (prtshade/fiv.h "Tight proxies").
struct OccluderCones {
  std::vector<float> values;
  std::optional<std::string> integrand;
  ExtraAttrs extra;
  bool float16 = false;  // v8: stored as float16 (values rounded to it on write)
  bool operator==(const OccluderCones&) const = default;
};

// /fiv/occluders/<name>/self_band1 (v9, scene files): the occluder's band-1 radiance from itself
// alone at the vertices of /objects/<name>, [V][RGB][m] (SCHEMA.md "FIV self-shadows").
struct OccluderSelfBand1 {
  std::vector<float> values;
  std::optional<std::string> meaning;
  ExtraAttrs extra;
  bool operator==(const OccluderSelfBand1&) const = default;
};

// /fiv/occluders/<name>: FIVs on shells around an occluder's bounding sphere, and its report.
// radial_scheme (v7) "surface": radii are offsets from the surface and surface_radius is there;
// absent or "geometric": radii are the shell radii (SCHEMA.md).
struct Occluder {
  std::string name;
  int n_rho = 0, n_theta = 0, n_phi = 0;
  std::vector<float> shells;  // [Nrho][Ntheta][Nphi][RGB][xyz]
  // v8: the shells stored as float16 (half the bytes; the writer rounds each value to nearest, the
  // reader gives the float16 values back as floats). false: float32.
  bool float16 = false;
  std::array<double, 3> centre{};
  double radius = 0;
  std::vector<double> radii;  // [Nrho]
  std::optional<std::string> environment, environment_sha256, integrand, angular_convention, grid;
  std::optional<double> fraction;
  std::optional<int64_t> samples;  // silhouette k
  std::optional<std::string> radial_scheme;  // (v7)
  std::optional<double> first_offset;        // (v7) τ_0 / radius of the surface scheme
  ExtraAttrs extra;                // of the shells dataset
  std::optional<OccluderValid> valid;
  std::optional<OccluderSurfaceRadius> surface_radius;  // (v7)
  std::optional<OccluderCones> cones;  // v7
  std::optional<OccluderSelfBand1> self_band1;  // v9 (scene files)
  // v7: the group attribute `proxy` of /fiv/occluders/<name>, "sphere" or "cone" (needs cones);
  // absent (older files): the sphere.
  std::optional<std::string> proxy;
  std::optional<ReportRow> report;  // /report/fiv/<name> (its product is the name)
  bool operator==(const Occluder&) const = default;
};

// /lights/<name> (v3): an area light as the bake saw it, in world space, for a runtime to draw
// and relight: its convex planar faces, counter-clockwise seen from the side they emit to
// (solids: outwards), as face_sizes [F] and face_indices [sum of sizes] into vertices [N][3]
// (float64: far from the origin a light keeps its digits); RGB radiance, constant over the
// surface; two_sided: planar lights emitting from both sides.
//
// Punctual lights (v6): shape "point", "spot" or "directional", no geometry datasets; `radiance`
// holds their intensity per channel (candela; lux for directional), the factor their E columns
// are multiplied by exactly as an area light's radiance is (so a runtime shades every light
// alike: albedo/π · Σ_l radiance_l · E_l); position (point, spot), direction (spot,
// directional: unit, where the light travels), the spot's cone angles in radians.
struct Light {
  std::string name;
  std::string shape;  // "quad", "polygon", "disc", "box", "cylinder", "sphere"; "point", "spot", "directional"
  std::array<double, 3> radiance{};
  std::optional<int64_t> two_sided;  // 0 / 1; required by the schema for area lights
  std::optional<std::vector<double>> position, direction;    // punctual lights: 3 doubles each
  std::optional<double> inner_cone_angle, outer_cone_angle;  // spot lights
  std::optional<double> range;                               // point and spot lights, when given (> 0)
  Array<double> vertices;            // [N][3]; area lights
  Array<uint32_t> face_sizes, face_indices;
  ExtraAttrs extra;  // of the group
  bool operator==(const Light&) const = default;
};

// /scene: the scene-wide settings of a scene file.
struct SceneInfo {
  std::optional<std::string> scene_file, integrator;
  std::optional<int64_t> samples, seed;
  std::optional<double> sh_tolerance;
  std::optional<int64_t> relight;  // 0 / 1
  std::optional<std::string> environment, environment_sha256;
  std::optional<std::string> plan;  // scene-wide decisions, one per line
  std::optional<std::string> options_file, options_sha256;  // a glTF scene's options file, when given
  ExtraAttrs extra;
  bool operator==(const SceneInfo&) const = default;
};

// /objects/<name>: one object of a scene file, its attributes and its vertex set.
struct SceneObject {
  std::string name;
  std::optional<std::string> role;  // "receiver", "occluder", "both"
  std::optional<std::string> mesh, mesh_sha256;
  std::optional<std::vector<double>> transform;  // 16 doubles, row-major world_from_object
  std::optional<std::vector<double>> albedo;     // RGB
  std::optional<double> phong_exponent;          // 0: none
  std::optional<int64_t> sh_order_diffuse, sh_order_glossy;  // 0: not baked
  std::optional<std::string> baked, left_out;    // "product: reason" per line; "-" when none
  std::optional<std::vector<double>> specular;   // RGB, glossy objects
  std::optional<int64_t> closed_form_vertices;
  std::optional<std::string> node_path;          // objects of a glTF scene: the glTF node path
  ExtraAttrs extra;
  VertexSet set;
  bool operator==(const SceneObject&) const = default;
};

struct Asset {
  RootInfo root;
  VertexSet vertices;  // the root layout (empty in fiv and scene files)
  std::optional<SceneInfo> scene;
  std::vector<SceneObject> objects;  // read back sorted by name
  std::optional<FivEnvironment> fiv_environment;
  std::optional<IrradianceCube> irradiance_cube;
  std::vector<Occluder> occluders;  // read back sorted by name
  std::vector<Light> lights;        // read back sorted by name (the products name their order)
  // /report's target_error: the RMSE the bake was asked to reach (bake/bake/choose.h; the default
  // target when neither samples nor a target was given), when it had one. Optional: older files
  // have none.
  std::optional<double> target_error;
  // Datasets under /report the model does not type (/report is free-form in the schema).
  std::vector<Dataset> other_reports;
  // Attributes of groups without typed attributes (/mesh, /report, /fiv/occluders/<name>, ...).
  std::vector<std::pair<std::string, ExtraAttrs>> group_extras;
  // What the reader left out (File::skipped_attrs): shown by the tools, never written.
  std::vector<SkippedAttr> skipped_attrs;

  const SceneObject* find_object(std::string_view name) const noexcept;
  const Occluder* find_occluder(std::string_view name) const noexcept;
  const Light* find_light(std::string_view name) const noexcept;
  // The scene object named `name` as the file stores it ("node0|node13") or as people read it:
  // its node path ("node0/node13", object_label); nullptr when there is none.
  const SceneObject* find_object_by_label(std::string_view name) const noexcept;
  bool operator==(const Asset&) const = default;
};

// Object names, one spelling for people. The name people read for a scene object is its glTF
// node path when it has one ("node0/node13/node71"), else its name. The file stores a glTF
// object under the node path with '/' written as '|' ("/objects/node0|node13|node71": an HDF5
// link name cannot hold '/'; bake/mesh/mesh.h NAMES keeps '|' out of node paths, so the two are one to
// one). Tools print the label and accept either spelling (Asset::find_object_by_label).
std::string object_label(std::string_view stored_name, const std::optional<std::string>& node_path);
inline std::string object_label(const SceneObject& object) { return object_label(object.name, object.node_path); }
// True when `query` names the object stored as `stored_name`: that name, its node path, or
// the stored name with '|' read as '/'.
bool names_object(std::string_view query, std::string_view stored_name, const std::optional<std::string>& node_path);

// The generic File of `asset` (dataset order and attribute order as write_asset writes them).
File to_file(const Asset& asset);
// The asset of a file that passed validate(); messages name `file_for_messages`.
Asset to_asset(const File& file, const std::filesystem::path& file_for_messages);

// Writes `asset` to `path` (see the contract above). Throws FormatError.
void write_asset(const std::filesystem::path& path, const Asset& asset);
// Reads and checks the file at `path` (see the contract above). Throws FormatError.
Asset read_asset(const std::filesystem::path& path);

// For inspectors: the file as stored and, when it passes the schema, its asset.
struct Inspection {
  File file;                          // every dataset and attribute as stored
  std::optional<Asset> asset;         // set when the file passes the schema
  std::optional<std::string> schema_error;  // else the first defect (without the file name)
};
// Reads `path` checking only format and format_version (FormatError otherwise).
Inspection inspect_asset(const std::filesystem::path& path);

// The attributes of an occluder's shells dataset, as write_asset writes them.
std::vector<Attr> shells_attrs(const Occluder& occluder);

} // namespace prt::formats
