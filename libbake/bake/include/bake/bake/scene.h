// bake/bake/scene.h — scene files: several objects, their roles and materials, one environment, and
// a plan that bakes what the scene needs and nothing else (docs/ARCHITECTURE.md §5: only
// what was asked for, and what the scene needs, is written).
//
// The scene file (JSON, RFC 8259, read with nlohmann-json; documented with an example in
// data/scene_example.json and in README.md "Scene files"):
//   {
//     "prtbake_scene": 1,                        required: the scene-file version
//     "up": "y",                                 optional: "y" (default) or "z"
//     "environment": "sunset.exr",               optional: HDR environment (lat-long or cube EXR)
//     "bake": {                                  optional, every member too:
//       "products": ["ao", "transfer", "radiance", "fiv"],   what may be baked (default: all four)
//       "integrator": "silhouette" | "qmc",  "samples": k or rays,  "seed": 1,  "report": 32,
//       "target_error": 1e-3,                  instead of "samples": per receiver object, the
//                                              integrator (only its samples when "integrator" is
//                                              given) chosen to reach this RMSE (bake/bake/choose.h);
//                                              "report" then defaults to 128. Without "samples"
//                                              and "target_error": target 1e-3, report 32
//       "sh_tolerance": 0.01,                  BRDF energy allowed beyond the chosen SH order
//       "relight": false,                      diffuse receivers also get transfer vectors
//       "bounces": 0, "bounce_rays": 256,      B bounces of diffuse interreflection in the diffuse
//                                              transfer and band-1 radiance (bake/bake/bounce.h;
//                                              the rule below), K gather rays per receiver row
//       "fiv": {"shells": "128x65x30", "cube": 32, "fraction": 0.001, "radial": "surface",
//               "precision": "half",   (bake/bake/fiv.h ShellSpec)
//               "self_shadows": "vertex"}  each FIV occluder's band-1 radiance from itself alone
//                                      at its vertices (/fiv/occluders/<name>/self_band1), or
//                                      "shells": none (the runtime's eq. 12 from the shells)
//       "lightmap": {...}                      every receiver per texel (below), unless its own says
//     },                                       otherwise
//     "lights": [ {                              optional: area lights (bake/lights/lights.h, paper 003)
//       "name": "key",                           optional: default "light<i>"; unique
//       "shape": "quad",  "centre", "u", "v"     the rectangle centre ± u/2 ± v/2, emitting towards u × v
//              | "polygon", "vertices": [[x,y,z], ...]   convex, counter-clockwise seen from its emitting side
//              | "disc", "centre", "normal", "radius", "segments": 64
//              | "box", "centre", "size": [sx,sy,sz], "rotate": [rx,ry,rz]
//              | "cylinder", "centre", "radius", "height", "segments": 64, "rotate"   (axis: its own y)
//              | "sphere", "centre", "radius", "subdivisions": 3                    (an icosphere)
//       "radiance": [r,g,b],                     required, ≥ 0, constant over the surface
//       "two_sided": false                       planar shapes only
//     } | {                                      or a punctual light (bake/lights/punctual.h), hard shadows:
//       "shape": "point",  "position",           with "radius": a sphere light (bulb_light; "subdivisions": 3)
//              | "spot", "position", "direction", "inner_cone_angle": 0, "outer_cone_angle": 45   (degrees)
//              | "directional", "direction",     where the light travels; with "angle" (degrees, the
//                                                angular diameter, "segments": 64): a sun disc (sun_light)
//       "intensity": [r,g,b]                     required, ≥ 0: candela (lux for directional), the
//                                                factor of its E as an area light's radiance is;
//       "range": r                               point (without radius) and spot: > 0, KHR's range
//                                                window (bake/lights/punctual.h); default none
//     } ],                                       (also in a glTF scene's options file)
//     "objects": [ {                             one or more
//       "name": "bunny",                         optional: default the mesh file's stem; unique
//       "mesh": "bunny.obj",                     required; relative paths are relative to the scene file
//       "role": "receiver" | "occluder" | "both",  required
//       "transform": {"translate": [x,y,z], "rotate": [rx,ry,rz] (degrees, about X then Y then Z),
//                     "scale": s | [sx,sy,sz]}  or  {"matrix": [16 numbers, row-major, last row 0 0 0 1]},
//                     its 3×3 part well-conditioned (σ_max/σ_min ≤ 1e8), else refused before any work,
//       "material": {"albedo": [r,g,b], "phong_exponent": s, "specular": [r,g,b]},
//       "moves": true                          optional: it may move at run time (FIV shells, below)
//       "lightmap": {                          optional: a receiver's products per texel of a lightmap
//         "resolution": N | [W, H],            instead of per vertex (bake/bake/lightmap_receivers.h);
//         "density": T,                        one of the two: the atlas, or texels per unit
//         "uv": "TEXCOORD_1",                  the asset's set (default TEXCOORD_1, else its only one)
//         "unwrap": false,                     generate the set even when the mesh has one (a mesh
//                                              without UVs gets one anyway)
//         "gutter": 2, "padding": 2, "stitch": true,   as prtbake texel's --gutter, --padding, --no-stitch
//         "min_chart_texels": 3 }                      and --min-chart-texels
//                 | false                      per vertex, whatever bake.lightmap says
//     } ]
//   }
// Unknown and duplicate keys are errors (a typo must not silently change a bake); every error
// names the file, and the line and column of a syntax error or the key path of any other
// ("objects[2].material.albedo[0] must be in [0, 1]").
//
// glTF SCENES: a .gltf / .glb file is a scene too (load_scene by extension). Each primitive
// instance of its default scene (bake/mesh/mesh.h "glTF scenes": the walk, the node paths, the
// names) is one object, in walk order, already in world space (identity transform), with
//   name      its instance name with '/' replaced by '|' ("root|engine|piston_2#p1"): '/' cannot be
//             part of an object's name in the file (formats/SCHEMA.md); node_path keeps the name;
//   role      "both" (everything casts and receives);
//   material  albedo = the primitive's material's baseColorFactor RGB (linear, as glTF), clamped to
//             [0, 1]; 0.8 grey, as a scene file's default, when it has no material. No glossy
//             lobe (roughness has no exact Phong counterpart), metallic is ignored, no texture is
//             decoded (a base colour texture's colours are not applied).
// LIGHTS: the KHR_lights_punctual lights its default scene's nodes instance (bake/mesh/mesh.h
// GltfLight: the node's world position and −Z) are punctual lights, intensity = color × intensity,
// named by the light's name (else "light<index>"; "_2", ... when a name is taken), after the
// options' own "lights".
// Optional OPTIONS (a JSON file given with the glTF; `prtbake scene --options`), every member too:
//   {
//     "prtbake_gltf_scene": 1,                   required: the options-file version
//     "up", "environment", "bake", "lights":     as in a scene file (relative paths: to the options file)
//     "gltf_lights": {"<light name>": {"radius": r, "subdivisions": 3}   a point light as a sphere light
//                                   | {"angle": degrees, "segments": 64} a directional one as a sun disc
//                                   | {"skip": true}},                   not baked
//     "objects": {"<node path or instance name>": {"role": ..., "material": {...}, "moves": true,
//                                                   "lightmap": {...} | false}}
//   }
// An "objects" key names an instance ("root/engine#p1") or a node path, which covers every
// instance of that node and of the nodes below it ("root/engine"); for each of role, material and moves
// the most specific (longest) key that sets it wins; a material replaces the default one whole
// (and so does a lightmap).
// A key that names no instance is an error (a typo must not silently change a bake); the rest is
// checked as in a scene file.
//
// Roles: a receiver gets per-vertex products; an occluder casts shadows (it is part of every
// receiver's visibility, and gets FIV shells for dynamic use); "both" does both (self-shadowing).
// A receiver-only object casts no shadow, not even on itself.
//
// The rules of plan_scene (each decision is printed with its reason and stored in the file):
//   * occluder-only objects get no per-vertex products (no transfer, AO or radiance);
//   * diffuse lobe (albedo): band-1 shadowed radiance when there is an environment — exact
//     diffuse shading with 3 coefficients per channel (paper 001 §4) — and no higher order; diffuse
//     transfer (relightable) only without an environment or with "relight", at the smallest order
//     whose clamped-cosine energy beyond it is ≤ sh_tolerance (order 3 for 1%, bake/sphere/zonal.h);
//   * glossy lobe (phong_exponent s): one order L, the smallest whose Phong-lobe energy beyond it
//     is ≤ sh_tolerance (Ramamoorthi & Hanrahan 2002; paper 001 §4 glossy), for both of: the
//     shadowed radiance S ("radiance" in bake.products and an environment: paper 001 §4 "material
//     editing", exact shadows under the scene's environment, the lobe applied at run time) and
//     the visibility transfer U ("transfer" in bake.products; kept beside S, with or without
//     "relight": it is what shades under a changed or rotated lighting, at a third of S's size,
//     and scenes baked before S keep it — leave "transfer" out for S alone);
//   * no radiance and no FIV without an environment;
//   * FIV shells only for an occluder that moves (SceneObject::moves: a glTF node an animation
//     moves, or "moves": true) and can shadow some other receiver: its bounding sphere
//     reaches above the tangent plane of at least one vertex of another receiver (paper 004 §4.3.1:
//     case C, wholly below the horizon, occludes nothing);
//   * the environment's FIV and DifMap only when some occluder gets shells;
//   * vertices that see no contour edge get closed forms (bake/integrators/silhouette.h, bake/sphere/zonal.h);
//   * bounces (bake.bounces B ≥ 1; bake/bake/bounce.h): light reflected between the objects'
//     surfaces (Lambertian, each object's material albedo, back faces black) is added to the
//     band-1 radiance and the diffuse transfer of every receiver that has them ("gathers"). A
//     surface reflects when the gather rays can meet it and its light is known: a "both" object
//     with a diffuse albedo and band-1 radiance or transfer. An occluder-only object has no rows,
//     so it casts shadows but reflects nothing; a receiver-only object is not in the union, so no
//     ray meets it (it casts no shadow, and reflects nothing). The transfer bounces only when every
//     reflecting surface's albedo is grey and every gatherer's transfer has one order (it is one
//     vector for all channels), else it stays direct and the plan says why; the band-1 radiance
//     bounces per channel. The area lights' irradiance E_l (at unit radiance, one value for all
//     channels) bounces as the transfer does, with grey albedos only; their SH (area_lights/sh,
//     glossy receivers) stays direct. A glossy receiver's shadowed radiance S bounces per channel
//     (it gathers; it reflects only with a diffuse albedo). Each decision is a line of the plan; the bake then logs the share of
//     gather rays that met a reflecting surface (0: nothing to bounce — a convex object alone);
//   * area lights ("lights"; none: nothing of them is written): every receiver gets each light's
//     irradiance at unit radiance, E = ∫ visible light max(n·ω, 0) dω (area_lights/irradiance,
//     exact diffuse shading for any radiance the runtime gives the light); a receiver that gets
//     transfer/visibility (a glossy lobe, "transfer" in bake.products) also gets each visible
//     light's SH projection at that order (area_lights/sh), what its lobe is shaded with. A
//     diffuse-only receiver gets no SH: E is already exact for it. Soft shadows are exact
//     (bake/lights/area_bake.h) against the union of the occluders, the same as the other products'.
#pragma once

#include <bake/bake/fiv.h>
#include <bake/bake/lightmap_receivers.h>
#include <bake/environment/envmap.h>
#include <bake/integrators/integrator.h>
#include <bake/lights/lights.h>
#include <bake/lights/punctual.h>
#include <bake/mesh/mesh.h>

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace prt::bake {

enum class Role { Receiver, Occluder, Both };
const char* role_name(Role);

struct Material {
  std::array<double, 3> albedo{0, 0, 0};    // diffuse lobe (none if all 0)
  double phong_exponent = 0;                // glossy lobe max(r·ω, 0)^s (none if 0)
  std::array<double, 3> specular{0, 0, 0};  // its colour
  bool diffuse() const { return albedo[0] > 0 || albedo[1] > 0 || albedo[2] > 0; }
  bool glossy() const { return phong_exponent > 0; }
};

struct SceneObject {
  std::string name;
  std::string node_path;                          // glTF scenes: the instance's name (bake/mesh/mesh.h); empty in a scene file
  std::filesystem::path mesh;                     // resolved against the scene file's directory
  Role role = Role::Both;
  // Whether it can move at run time: only a moving occluder gets FIV shells (its static shadows
  // are in the receivers' own products). A scene file's "moves" (default true: a scene file lists
  // objects to be placed at run time); a glTF instance: an animation channel moves its node or an
  // ancestor, unless the options' "moves" says otherwise.
  bool moves = true;
  std::string moves_reason = "\"moves\" in the scene file (default true)";
  // The file's "transform": object space → world space, applied to column vectors
  // (docs/ARCHITECTURE.md §3 "Frames").
  Eigen::Matrix4d world_from_object = Eigen::Matrix4d::Identity();
  Material material;
  // "lightmap" (its own, else bake.lightmap's): a receiver's products per texel of this lightmap
  // instead of per vertex (bake/bake/lightmap_receivers.h). nullopt: per vertex.
  std::optional<LightmapSpec> lightmap;
};

// What a scene file describes (load_scene): the objects, their roles and materials, the
// environment and the bake settings. Nothing here is rendered or ray-traced (that is prtview's
// RenderScene and bake/visibility/raycast.h's RayCaster).
struct SceneDescription {
  std::filesystem::path file;  // the scene file itself (or the glTF)
  std::optional<std::filesystem::path> options;  // a glTF scene's options file, if any
  UpAxis up = UpAxis::Y;
  std::optional<std::filesystem::path> environment;
  bool want_ao = true, want_transfer = true, want_radiance = true, want_fiv = true;
  // "integrator", "samples" (the chosen integrator's knob), "seed" and "report".
  IntegratorSpec integrator;
  bool integrator_given = false;  // "integrator" was in the file
  double target_error = 0;        // "target_error" (0: not given; bake/bake/choose.h)
  bool counted_costs = false;     // not in the file: the tool's --reproducible (ChooserOptions)
  double sh_tolerance = 0.01;
  bool relight = false;
  int bounces = 0;           // "bounces": interreflections (the plan rule "bounces")
  uint32_t bounce_rays = 0;  // "bounce_rays" (0: BounceSpec::kDefaultRays)
  // "fiv": shells, cube, fraction, radial ("surface" or "geometric"), precision ("half" or
  // "float": the file's dtype of shells and cones), self_shadows ("vertex" or "shells"); the shells' k is integrator.silhouette_k ("samples" for a
  // silhouette scene, else the default).
  ShellSpec fiv;
  std::optional<LightmapSpec> lightmap;  // bake.lightmap: every object's unless its own says otherwise
  std::vector<AreaLight> lights;  // "lights", in world space (bake/lights/lights.h), validated
  // "lights" of shape point, spot or directional (bake/lights/punctual.h), validated: exact hard
  // shadows. A point light with a "radius" is a sphere light in `lights`; a directional light
  // with an "angle" stays here until place_suns makes it a sun disc in `lights`.
  std::vector<PunctualLight> punctual_lights;
  std::vector<SceneObject> objects;
  // What the reading found worth saying but not refusing, one line each (a glTF light's range on
  // a light the options give a radius); the tools print them.
  std::vector<std::string> warnings;

  // Every light's name in the light products' column order: `lights`, then `punctual_lights`.
  std::vector<std::string> light_names() const;
  size_t light_count() const noexcept { return lights.size() + punctual_lights.size(); }
};

// The directional lights with an angular size become sun discs (bake/lights/punctual.h
// sun_light) about the ball that holds the scene's meshes (the world-space meshes of
// scene.objects: their frame's origin plus their bounds), appended to scene.lights in order.
// The tools call it once the meshes are loaded, before plan_scene.
void place_suns(SceneDescription& scene, std::span<const Mesh> meshes);

// Parses and validates a scene file (InputError naming the file and the line and column or the
// key), or reads a glTF scene and its options file (the "glTF scenes" paragraph above). Options
// with a scene file are an InputError.
SceneDescription load_scene(const std::filesystem::path& file,
                            const std::optional<std::filesystem::path>& gltf_options = std::nullopt);
// Whether load_scene reads `file` as a glTF scene (.gltf, .glb, any case) rather than a scene file:
// the tools check an options file against it before reading anything.
bool is_gltf_scene(const std::filesystem::path& file);

// The world-space meshes of scene.objects, in order: load_scene_mesh of each object of a scene
// file (an error names the object and the scene), or the instances of a glTF scene (the file read
// once). Reader warnings are appended to `warnings`.
std::vector<Mesh> load_scene_meshes(const SceneDescription& scene, std::vector<std::string>& warnings);

// The objects of a scene share one frame (bake/mesh/mesh.h, ORIGIN): visibility traces receivers
// against the union of the occluders. Its origin is frame_origin of the world bounds of every
// object: world_from_object applied in double to each file mesh's world positions (load_mesh).
// Ordinary scenes get origin 0, and then the positions below are exactly what they were when
// the transform was applied to float positions and rounded to float.
Eigen::Vector3d scene_origin(std::span<const Mesh> file_meshes, std::span<const SceneObject> objects);

// An object's mesh in world space, relative to `origin`: world_from_object applied in double to
// the file mesh's world positions, offsets from `origin` rounded to float once (Mesh::origin =
// origin); normals from the file transformed by the inverse transpose, angle-weighted normals
// recomputed on the offsets. InputError (the mesh file) if a position leaves the float range.
Mesh place_scene_object(const Mesh& file_mesh, const SceneObject& object, const Eigen::Vector3d& origin);

// One object on its own: load_mesh, then place_scene_object with scene_origin of this object alone.
Mesh load_scene_mesh(const SceneObject& object);

struct ObjectPlan {
  bool receiver = false, occluder = false;
  bool ao = false, radiance = false, fiv = false;
  int transfer_order = 0;    // diffuse transfer T (0: none)
  int visibility_order = 0;  // visibility transfer U for the glossy lobe (0: none)
  int shadowed_order = 0;    // shadowed radiance S for the glossy lobe under the environment (0: none)
  bool texels = false;           // per texel of SceneObject::lightmap instead of per vertex
  bool area_irradiance = false;  // area_lights/irradiance: E of every light, at unit radiance
  int area_sh_order = 0;         // area_lights/sh: the visible lights' SH at this order (0: none)
  // Interreflections (the rule "bounces"): its band-1 radiance / transfer get the bounces; it
  // reflects light onto the others (and itself).
  bool bounce_radiance = false, bounce_transfer = false, bounce_area = false, bounce_shadowed = false;
  bool bounce_reflects = false;
  std::vector<std::string> baked, left_out;  // "product: reason", one line each
  // The products of a vertex integrator (bake/integrators/integrator.h); the area lights are not among them.
  bool any_vertex_product() const {
    return ao || radiance || transfer_order > 0 || visibility_order > 0 || shadowed_order > 0;
  }
};

// The vertex integrator's request for an object's plan under the scene's environment `env`.
ProductRequest product_request(const ObjectPlan& plan, const EnvMap* env);

struct ScenePlan {
  std::vector<ObjectPlan> objects;  // parallel to SceneDescription::objects
  bool fiv_environment = false;     // /fiv/environment and /fiv/irradiance_cube
  bool bounces = false;             // some receiver gathers and some surface reflects
  std::vector<std::string> notes;   // scene-wide decisions
};

// Decides what to bake (the rules in the file comment). `meshes` are the world-space meshes of
// scene.objects (load_scene_mesh), used by the FIV rule. Throws InputError when a material has no
// SH order within kMaxOrder for the tolerance.
ScenePlan plan_scene(const SceneDescription& scene, std::span<const Mesh> meshes);

} // namespace prt::bake
