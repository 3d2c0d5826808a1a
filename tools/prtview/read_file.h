// prtview/read_file.h — everything prtview takes from a baked file, read as the typed asset
// (formats::read_asset, <formats/asset.h>; paths and attribute names live in <formats/names.h>,
// the schema in formats/SCHEMA.md, docs/ARCHITECTURE.md §5). It hands the renderers
// (scenes.h) plain meshes, arrays and prtshade views, checked: the environment the data was baked
// with (SHA-256), the occluder mesh's SHA-256, and what prtshade's validate_* demand (shapes are
// the schema's, checked by read_asset). Errors are bake::InputError naming the file. Pointers and
// prtshade views point into the Asset, which must outlive them.
#pragma once

#include <bake/environment/envmap.h>
#include <bake/mesh/mesh.h>
#include <formats/asset.h>
#include <prtshade/fiv.h>

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace prt::prtview {

// What kind of file it is and what it holds at its root.
bool is_scene_file(const formats::Asset& f);
bool has_fiv(const formats::Asset& f);
bool has_transfer(const formats::Asset& f);
// Band-1 radiance at the root: /radiance/band1, or the band-1 part of /radiance/shadowed (order >= 2).
bool has_band1(const formats::Asset& f);
bool has_ao(const formats::Asset& f);
// The --shade kinds a per-vertex file (its root layout) can be shown with, in the first look's
// order of preference — band1 (exact all-frequency shadows under the baked environment), transfer
// (shadows only as sharp as its SH order), ao (the AO approximation): what the first look shows
// and what a hint names when the asked kind is missing.
std::vector<std::string> vertex_kinds(const formats::Asset& f);
// What `kind` shows for the root layout, in a few words ("band-1 radiance", "band 1 of the
// shadowed radiance (order 4)", "diffuse transfer order 3", "AO").
std::string vertex_kind_label(const formats::Asset& f, const std::string& kind);
// The root layout's environment for band1 (its environment_sha256; "" when it names none).
std::string band1_environment_sha256(const formats::Asset& f);
// Throws InputError naming the missing dataset and the kinds the file can be shown with, unless
// the root layout holds `kind`'s product ("transfer", "band1" or "ao").
void require_vertex_kind(const formats::Asset& f, const std::string& file, const std::string& kind);
// Per-texel files (format version 5, 'prtbake texel'): the root layout's /lightmap with its UVs
// (/mesh/uv). texel_kinds: the --shade kinds its lightmap can be shown with, in vertex_kinds'
// order (band1 = /lightmap/radiance/band1, transfer, ao); texel_kind_label names them as
// vertex_kind_label does.
bool has_lightmap(const formats::Asset& f);
std::vector<std::string> texel_kinds(const formats::Asset& f);
std::string texel_kind_label(const formats::Asset& f, const std::string& kind);
// Throws InputError naming the missing /lightmap dataset and the kinds the lightmap holds.
void require_texel_kind(const formats::Asset& f, const std::string& file, const std::string& kind);
// `kind`'s lightmap product of the root layout, checked: shape [H][W][channels] (ao 1, transfer
// order², band1 3x3; the glossy kinds of scene objects: visibility order² (/lightmap/transfer/
// visibility), shadowed 3 x order² (/lightmap/radiance/shadowed)), /mesh/uv holding 6 floats per
// triangle, the state [H][W]; band1 and shadowed baked under `env` (SHA-256). Pointers into the
// asset.
struct TexelProduct {
  int width = 0, height = 0;
  size_t channels = 0;
  int order = 0;  // transfer, visibility, shadowed: the SH order; band1: 2; ao: 0
  const std::vector<float>* values = nullptr;
  const std::vector<uint8_t>* state = nullptr;
  const std::vector<float>* corner_uv = nullptr;
  std::string uv_set;
};
TexelProduct read_texel_product(const formats::Asset& f, const std::string& file, const std::string& kind, const bake::EnvMap& env);
// The same of any vertex set (a scene object's: `prefix` names it in messages, "" for the root).
TexelProduct read_texel_product(const formats::VertexSet& s, const std::string& prefix, const std::string& file,
                                const std::string& kind, const bake::EnvMap& env);
bake::UpAxis up_axis(const formats::Asset& f);
// The environment the file names (the 'environment' of the scene, of the irradiance cube or of
// the root band-1 radiance), found as given, next to the file, or next to the scene file. Throws
// when it names none or the file does not exist.
std::string baked_environment(const formats::Asset& f, const std::string& file);

// The file's own error report (its /report rows: the bake against its reference integrator at a
// few vertices), in one short phrase for what is shown: the row of `kind`'s product for a
// per-vertex file (band1, transfer, ao), the worst row relative to its reference RMS over the
// objects of a scene file, the occluder's row of an FIV file, and the target the bake was asked
// for; "no error report" when the file has none (a bake with --report 0).
std::string report_summary(const formats::Asset& f, const std::string& kind);

// The mesh of a vertex set: object "" (the root layout) or the scene object of that name.
bake::Mesh read_mesh(const formats::Asset& f, const std::string& file, const std::string& object);
// Diffuse transfer [V][order²] of a vertex set.
struct Transfer {
  int order = 0;
  const float* coeffs = nullptr;
};
Transfer read_transfer(const formats::Asset& f, const std::string& file, const std::string& object);
// AO [V] of a vertex set.
const std::vector<float>& read_ao(const formats::Asset& f, const std::string& file, const std::string& object);
// Band-1 radiance [V][3][3] baked under `env` (checked), with the baked normals [V][3]: the
// vertex set's /radiance/band1, else the band-1 coefficients (i = 1, 2, 3) of its
// /radiance/shadowed S [V][3][L*L], L >= 2, which are the same integrals (docs/ARCHITECTURE.md §3:
// R_c,m = S_c,i at i = l(l+1) + m, l = 1), copied out.
struct Band1 {
  const float* normals = nullptr;
  const float* baked = nullptr;  // into the asset (/radiance/band1), or null
  std::vector<float> copied;     // [V][3][3] from /radiance/shadowed
  int shadowed_order = 0;        // L of /radiance/shadowed when copied from it, else 0
  const float* radiance() const { return baked ? baked : copied.data(); }
};
Band1 read_band1(const formats::Asset& f, const std::string& file, const std::string& object, const bake::EnvMap& env);

// One baked FIV occluder, checked (validate_occluder) and viewed by prtshade.
struct BakedOccluder {
  std::array<double, 3> centre{};
  double radius = 0;
  std::vector<float> radii;  // view.radii points here
  // A float16 file's tables as the runtime holds them (prtshade/fiv.h "Half-float tables"):
  // view.shells_half / cones_half point here.
  std::vector<uint16_t> shells_half, cones_half;
  shade::FivOccluder view{};
};
BakedOccluder read_occluder(const formats::Asset& f, const std::string& file, const std::string& name, const bake::EnvMap& env);
// The occluder of an FIV file: `name`, or the only one when empty.
std::string choose_occluder(const formats::Asset& f, const std::string& file, const std::string& name);
// The DifMap (the irradiance cube) and the environment FIV, checked against env; nothing
// (nullopt, nullptr) when the file has none and they are not `required` (else InputError).
std::optional<shade::DifMap> read_difmap(const formats::Asset& f, const std::string& file, const bake::EnvMap& env,
                                         bool required);
const float* read_environment_fiv(const formats::Asset& f, const std::string& file, const bake::EnvMap& env,
                                  bool required);
// The mesh the FIV shells were baked from: `given`, else the file's source (as given or next to
// the file); its SHA-256 must match the file's source SHA-256.
std::string occluder_mesh_path(const formats::Asset& f, const std::string& file, const std::string& given);

// The objects of a scene file (schema v2), with the scene's environment checked against env.
struct SceneObject {
  std::string name, role;
  bool receiver = false, casts_shadow = false;
  std::array<float, 3> albedo{1, 1, 1};  // white when the file's albedo is zero
  // Interreflections (bake/bake/scene.h rule "bounces"): the albedo the object reflects with (0
  // unless it is "both" with a diffuse albedo; in a scene baked with bounces, also 0 when none of
  // its products carries them: the bake left it out), and whether the product it is drawn from
  // carries bounces (AO never does).
  std::array<float, 3> reflectance{0, 0, 0};
  bool drawn_bounced = false;
  bool area_bounced = false;  // its area-light irradiance carries bounces (the area views draw it)
  bake::Mesh mesh;                       // world space
  std::optional<Band1> band1;
  std::optional<Transfer> transfer;
  const std::vector<float>* ao = nullptr;
  // Baked per texel (no per-vertex product): its lightmap's first of band1, transfer, ao.
  std::optional<TexelProduct> texels;
  std::string texel_kind;
  std::optional<BakedOccluder> shells;   // read when the file also holds the environment FIV
  // With shells and /fiv/occluders/<name>/self_band1 (v9): its self-shadowed irradiance E [V][3]
  // at its vertices, from itself alone (shade_band1 at its normals); else empty: eq. 12 from the shells.
  std::vector<float> fiv_self;
  bool glossy_only = false;              // visibility transfer only
  // Glossy objects (a phong_exponent > 0 and /transfer/visibility or /radiance/shadowed): the
  // lobe and its colour, and what shades it: U (route A) and S [V][3][L*L] baked under `env`
  // (checked; route B), whichever the file holds.
  std::optional<Transfer> visibility;
  std::optional<Transfer> shadowed;
  // The same baked per texel (the object's lightmap holds them): shaded per pixel from the
  // bilinear sample at the pixel's UV, with the pixel's normal and position.
  std::optional<TexelProduct> texel_visibility, texel_shadowed;
  double phong = 0;
  std::array<float, 3> specular{1, 1, 1};  // white when the file names none
};
// A glossy object of a scene file: a phong_exponent > 0 and its U or S (/transfer/visibility,
// /radiance/shadowed), per vertex or in its lightmap.
bool is_glossy(const formats::SceneObject& o);
// `env` null: geometry, roles and albedo only (no product that needs the environment, no check
// that the file was baked under it): the area-light views.
std::vector<SceneObject> read_scene_objects(const formats::Asset& f, const std::string& file, const bake::EnvMap* env);

} // namespace prt::prtview
