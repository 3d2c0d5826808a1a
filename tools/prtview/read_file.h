// prtview/read_file.h — everything prtview reads from a baked file (formats::File): the only part
// of prtview that knows dataset paths and attribute names (formats/SCHEMA.md). It hands the
// renderers (scenes.h) plain meshes, arrays and prtshade views, checked: shapes, the environment
// the data was baked with (SHA-256) and the occluder mesh's SHA-256. Errors are bake::InputError
// naming the file. Pointers and prtshade views point into the File, which must outlive them.
#pragma once

#include <bake/envmap.h>
#include <bake/mesh.h>
#include <formats/prtfile.h>
#include <prtshade/fiv.h>

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace prt::prtview {

// What kind of file it is and what it holds at its root.
bool is_scene_file(const formats::File& f);
bool has_fiv(const formats::File& f);
bool has_transfer(const formats::File& f);
bake::UpAxis up_axis(const formats::File& f);
// The environment the file names ('environment' of /scene, /fiv/irradiance_cube or
// /radiance/band1), found as given, next to the file, or next to the scene file. Throws when it
// names none or the file does not exist.
std::string baked_environment(const formats::File& f, const std::string& file);

// The mesh of a vertex set: prefix "" (root layout) or "/objects/<name>" (scene files).
bake::Mesh read_mesh(const formats::File& f, const std::string& file, const std::string& prefix);
// Diffuse transfer [V][order²] of a vertex set.
struct Transfer {
  int order = 0;
  const float* coeffs = nullptr;
};
Transfer read_transfer(const formats::File& f, const std::string& file, const std::string& prefix);
// Band-1 radiance [V][3][3] baked under `env` (checked), with the baked normals [V][3].
struct Band1 {
  const float* normals = nullptr;
  const float* radiance = nullptr;
};
Band1 read_band1(const formats::File& f, const std::string& file, const std::string& prefix, const bake::EnvMap& env);

// One baked FIV occluder, /fiv/occluders/<name>, checked (validate_occluder) and viewed by prtshade.
struct BakedOccluder {
  std::vector<double> centre;
  double radius = 0;
  std::vector<float> radii;  // view.radii points here
  shade::FivOccluder view{};
};
BakedOccluder read_occluder(const formats::File& f, const std::string& file, const std::string& name, const bake::EnvMap& env);
// The occluder of an FIV file: `name`, or the only one when empty.
std::string choose_occluder(const formats::File& f, const std::string& file, const std::string& name);
// The DifMap (/fiv/irradiance_cube) and the environment FIV (/fiv/environment), checked against env;
// nothing (nullopt, nullptr) when the file has none and they are not `required` (else InputError).
std::optional<shade::DifMap> read_difmap(const formats::File& f, const std::string& file, const bake::EnvMap& env,
                                         bool required);
const float* read_environment_fiv(const formats::File& f, const std::string& file, const bake::EnvMap& env,
                                  bool required);
// The mesh the FIV shells were baked from: `given`, else the file's 'source' (as given or next to
// the file); its SHA-256 must match the file's source_sha256.
std::string occluder_mesh_path(const formats::File& f, const std::string& file, const std::string& given);

// The objects of a scene file (schema v2), with /scene's environment checked against env.
struct SceneObject {
  std::string name, role;
  bool receiver = false, casts_shadow = false;
  std::array<float, 3> albedo{1, 1, 1};  // white when the file's albedo is zero
  bake::Mesh mesh;                       // world space
  std::optional<Band1> band1;
  std::optional<Transfer> transfer;
  const std::vector<float>* ao = nullptr;
  std::optional<BakedOccluder> shells;   // read when the file also holds /fiv/environment
  bool glossy_only = false;              // transfer/visibility only
};
std::vector<SceneObject> read_scene_objects(const formats::File& f, const std::string& file, const bake::EnvMap& env);

} // namespace prt::prtview
