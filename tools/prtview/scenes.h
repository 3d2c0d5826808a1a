// prtview/scenes.h — the three kinds of baked file as prtview draws them: the scene both renderers
// see (a mesh, which triangles are the receiver, what casts shadows) and the runtime picture,
// shaded by prtshade and rasterized by view/. The data comes from read_file.h; what is drawn is
// documented in prtview's --help ("WHAT IS DRAWN").
#pragma once

#include <view/camera.h>
#include <view/image.h>
#include <view/reference.h>

#include <bake/environment/envmap.h>
#include <bake/mesh/mesh.h>
#include <formats/asset.h>

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>
#include <vector>

namespace prt::prtview {

// What a render needs beyond the pictures: the scene both renderers draw and which triangles form
// the receiver (the ground plane of FIV scenes, the receiver objects of scene files).
struct RenderScene {
  bake::Mesh mesh;
  size_t receiver_triangles = 0;  // triangles [0, receiver_triangles) are the receiver
  std::vector<view::Sphere> spheres;
  std::string what;  // one line: what was drawn
  std::string how;   // how the runtime shaded it
  // Per-vertex and per-texel files: which form was drawn ("per vertex" or "per texel, 512x512
  // lightmap") and, per texel, the covered pixels whose bilinear footprint reached an empty texel
  // (view/lightmap.h's check; 0 when the padding does its job).
  std::string form;
  size_t texel_pixels = 0, empty_texel_pixels = 0;
  // Scene files: the reference's per-triangle shadow casters and albedos (view::ReferenceOptions),
  // and the objects' triangle ranges: object k owns [first_triangle[k], first_triangle[k + 1]).
  std::vector<uint8_t> casts_shadow;
  std::vector<std::array<float, 3>> albedo;
  // ... and, for the bounces, the albedo each triangle reflects with in the bake and whether its
  // pixels show a bounced product (view::ReferenceOptions::reflectance, gathers).
  std::vector<std::array<float, 3>> reflectance;
  std::vector<uint8_t> gathers, area_gathers;  // the environment's products; the area lights' E
  std::vector<std::string> object_names;
  std::vector<bool> object_receiver;
  std::vector<size_t> first_triangle;
  // --shade glossy: per triangle, the Phong exponent (0: not glossy) and specular colour the
  // reference's glossy mode (view::ReferenceOptions::glossy) uses; empty otherwise.
  std::vector<double> phong;
  std::vector<std::array<float, 3>> specular;
  // Area-light views: the luminance of albedo / pi x sum_l radiance_l E_l at every vertex of the
  // objects with baked area_lights/irradiance (both --shade area and area-exact): what the file
  // says about the picture's brightness, the basis of its exposure.
  std::vector<float> baked_luminance;
  // FIV views: the frame's cost, the rasterisation and the shading of every pixel (what an engine
  // spends per frame; the file's reading and the meshes' loading are not in it).
  double frame_seconds = 0;
  double frame_cpu_seconds = 0;  // the same in CPU time over all threads (steady under load)
};

// Log lines stay short whatever the scene: a list of names is cut to about `budget` characters
// ("a, b and 12 more"); per-object lines are printed for at most kObjectLines objects, else one
// line per kind of shading with its count and a cut list of names.
inline constexpr size_t kObjectLines = 12;
std::string name_list(const std::vector<std::string>& names, size_t budget);
// Appends to `how` one line "  name: how" per object, or (more than kObjectLines objects) one line
// "  N x how: names" per distinct how.
void add_grouped(std::string& how, const std::vector<std::string>& names, const std::vector<std::string>& how_of);

// Per-vertex files: kind "transfer", "band1" or "ao". transfer: the environment's SH turned about
// +Y by `env_rotate_degrees` first (turn_light).
view::Image render_vertex_file(const formats::Asset& f, const std::string& file, const std::string& kind,
                               const bake::EnvMap& env, const view::Camera& cam, RenderScene& scene,
                               double env_rotate_degrees = 0);
// SH lighting [3][order²] (channel-major) turned about +Y by `degrees`: prt::sh::Rotation of
// R_y = ((cos, 0, sin), (0, 1, 0), (−sin, 0, cos)), i.e. (x, z) → (x cos + z sin, −x sin + z cos)
// — the rotation `prtbake export --to web` tabulates per degree for the web viewer.
void turn_light(std::vector<float>& light, int order, double degrees);

// Per-texel files (/lightmap, 'prtbake texel'): `kind` "transfer", "band1" or "ao" of the
// lightmap, each pixel sampled bilinearly through its triangle's interpolated UV
// (view::shade_texels, SCHEMA's rule) and shaded by the same prtshade formulas as a vertex, at the
// pixel's interpolated normal where the formula takes one (band1's y_1m(n), AO's unshadowed
// irradiance).
view::Image render_texel_file(const formats::Asset& f, const std::string& file, const std::string& kind,
                              const bake::EnvMap& env, const view::Camera& cam, RenderScene& scene,
                              double env_rotate_degrees = 0);

// FIV files: the occluder (copies at `instances`, default one where it was baked) on a ground square.
// One copy of a baked occluder placed at run time, moved by `offset` from where it was baked
// (paper 004's dynamic occluders: shells travel with their object). `occluder` names
// /fiv/occluders/<name>; empty: --occluder, else the file's only one.
struct FivInstance {
  std::string occluder;
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
};
struct FivView {
  std::string occluder, occluder_mesh;
  std::vector<FivInstance> instances;
  // A scene file drawn as an FIV scene (--shade fiv or --instance/--instances on it): its objects
  // with FIV shells are the occluders (default: each once where it was baked), on a ground plane.
  bool scene = false;
  std::optional<double> ground, ground_size;
  bool overlap = true, partial = true;
  bool sphere_proxy = false;  // --proxy sphere: the paper's bounding sphere even where the file has cones
};
// The camera of a first look when none is given (view::frame_box) and what it frames: the objects
// of a scene file (`glossy`: only its glossy objects, --shade glossy) or the mesh of a per-vertex
// file, without their large flat parts (a ground: view::focus_box states the rule); an FIV file's
// occluder copies (their bounding spheres, widened by R so that their shadows on the ground show).
struct FirstLook {
  view::Camera camera;
  std::string framed;  // a few words: what the box holds
};
FirstLook first_look_camera(const formats::Asset& f, const std::string& file, const FivView& options, int width,
                            int height, bool glossy = false);

view::Image render_fiv_file(const formats::Asset& f, const std::string& file, const FivView& options,
                            const bake::EnvMap& env, const view::Camera& cam, RenderScene& scene);

// Appends one scene object's triangles to the scene's per-triangle roles and albedos and its
// object list (the mesh itself is the caller's to merge, in the same order).
struct SceneObject;
void add_object(RenderScene& scene, const SceneObject& o);

// Scene files (prtbake scene, schema v2): every object with what the file holds for it.
view::Image render_scene_file(const formats::Asset& f, const std::string& file, const bake::EnvMap& env,
                              const view::Camera& cam, RenderScene& scene);

// Scene files, --shade glossy: the glossy objects' specular lobes only, the normalised Phong lobe
// about the reflected view direction from cam.eye times the specular colour, Gouraud, by one of
// prtshade/glossy.h's routes per object: B (shade_glossy_radiance_vertices on the baked
// /radiance/shadowed, paper 001 §4 "material editing": shadows exact under the baked environment,
// any order) when the object has S, else A (the environment's SH at the object's visibility order,
// the triple product with each vertex's /transfer/visibility row). An object baked per texel
// (lightmap/radiance/shadowed or lightmap/transfer/visibility) is shaded per pixel by the same
// routes from the bilinear sample at the pixel's UV (view/lightmap.h), with the pixel's normal and
// position: the lobe is evaluated where it is seen, not interpolated. GlossyRoute::A or ::B forces
// one (an object without its data is an InputError). The glossy objects are the compared
// receivers; the others are drawn black and cast shadows by their roles. `phong`: an exponent that
// replaces every glossy object's own (the lobe may change at run time: neither U nor S depends on
// it; the order stays the baked one).
enum class GlossyRoute { Auto, A, B };
view::Image render_glossy_scene(const formats::Asset& f, const std::string& file, const bake::EnvMap& env,
                                const view::Camera& cam, std::optional<double> phong, GlossyRoute route,
                                RenderScene& scene);

} // namespace prt::prtview
