// formats/names.h — every dataset path, group and attribute name of the baked file, spelled once.
// The schema (formats/SCHEMA.md, docs/ARCHITECTURE.md §5) is checked with these names
// (schema.cpp), the typed asset model is converted with them (asset.cpp), and generic readers
// that show a file as stored (prtdump) use them instead of literals. Paths of the root layout
// are absolute; a scene object's vertex set is the same layout under "/objects/<name>".
#pragma once

#include <string_view>

namespace prt::formats::names {

// ---- groups and path pieces ----
inline constexpr std::string_view kObjects = "/objects";       // + "/<name>": a scene object
inline constexpr std::string_view kScene = "/scene";
inline constexpr std::string_view kReport = "/report";         // + "/<product>", "/objects/<name>/..."
inline constexpr std::string_view kReportFiv = "/report/fiv";  // + "/<occluder>"
inline constexpr std::string_view kFivGroup = "/fiv";
inline constexpr std::string_view kOccluders = "/fiv/occluders";  // + "/<name>/{shells,valid}"
inline constexpr std::string_view kLights = "/lights";             // + "/<name>/{vertices,face_sizes,face_indices}" (v3)

// ---- datasets of a vertex set (relative to its prefix: "" or "/objects/<name>") ----
inline constexpr std::string_view kMeshGroup = "/mesh";
inline constexpr std::string_view kPositions = "/mesh/positions";  // float32, or float64 where float32 would lose precision (SCHEMA.md)
inline constexpr std::string_view kNormals = "/mesh/normals";
inline constexpr std::string_view kTriangles = "/mesh/triangles";
inline constexpr std::string_view kSourcePosition = "/mesh/source_position";
inline constexpr std::string_view kAo = "/ao";
inline constexpr std::string_view kTransferGroup = "/transfer";
inline constexpr std::string_view kTransferDiffuse = "/transfer/diffuse";
inline constexpr std::string_view kTransferVisibility = "/transfer/visibility";
inline constexpr std::string_view kRadianceGroup = "/radiance";
inline constexpr std::string_view kRadianceBand1 = "/radiance/band1";
inline constexpr std::string_view kRadianceShadowed = "/radiance/shadowed";  // v4: [V][RGB][L*L]
inline constexpr std::string_view kAreaLightsGroup = "/area_lights";           // v3
inline constexpr std::string_view kAreaIrradiance = "/area_lights/irradiance";  // [V][L]
inline constexpr std::string_view kAreaSh = "/area_lights/sh";                  // [V][L][n*n]
// v5: the lightmap of a vertex set (per-texel bakes): the UV set per triangle corner, the texels'
// state, surface points and products, images of H × W texels (row 0 at v = 0).
inline constexpr std::string_view kUv = "/mesh/uv";                                  // float32 [T][3][2]
inline constexpr std::string_view kLightmapGroup = "/lightmap";
inline constexpr std::string_view kLightmapState = "/lightmap/state";                // uint8 [H][W]: 0 empty, 1 baked, 2 filled, 3 padding
inline constexpr std::string_view kLightmapPositions = "/lightmap/positions";        // float32/64 [H][W][3], world space
inline constexpr std::string_view kLightmapNormals = "/lightmap/normals";            // float32 [H][W][3]
inline constexpr std::string_view kLightmapAo = "/lightmap/ao";                      // float32 [H][W]
inline constexpr std::string_view kLightmapTransferDiffuse = "/lightmap/transfer/diffuse";        // [H][W][L*L]
inline constexpr std::string_view kLightmapTransferVisibility = "/lightmap/transfer/visibility";  // [H][W][L*L]
inline constexpr std::string_view kLightmapRadianceBand1 = "/lightmap/radiance/band1";            // [H][W][3][3]
inline constexpr std::string_view kLightmapRadianceShadowed = "/lightmap/radiance/shadowed";      // [H][W][3][L*L]
inline constexpr std::string_view kLightmapAreaIrradiance = "/lightmap/area_lights/irradiance";   // [H][W][L]
inline constexpr std::string_view kLightmapAreaSh = "/lightmap/area_lights/sh";                   // [H][W][L][n*n]
// ---- FIV datasets ----
inline constexpr std::string_view kFivEnvironment = "/fiv/environment";
inline constexpr std::string_view kIrradianceCube = "/fiv/irradiance_cube";
inline constexpr std::string_view kShells = "shells";  // leaf under /fiv/occluders/<name>/
inline constexpr std::string_view kValid = "valid";    // leaf under /fiv/occluders/<name>/
inline constexpr std::string_view kSurfaceRadius = "surface_radius";  // (v7) leaf under /fiv/occluders/<name>/
inline constexpr std::string_view kCones = "cones";    // leaf under /fiv/occluders/<name>/ (v7): the tight proxy
// Leaf under /fiv/occluders/<name>/ (v9, scene files): the occluder's band-1 radiance from itself
// alone at the vertices of /objects/<name> ([V][RGB][m], as /radiance/band1): its self-shadows.
inline constexpr std::string_view kSelfBand1 = "self_band1";
// Attribute of the group /fiv/occluders/<name> (v7): the proxy its corrections use, "sphere" or "cone".
inline constexpr std::string_view kProxy = "proxy";
inline constexpr std::string_view kProxySphere = "sphere";
inline constexpr std::string_view kProxyCone = "cone";
// ---- area-light datasets (leaf under /lights/<name>/) ----
inline constexpr std::string_view kLightVertices = "vertices";          // float64 [N][3], world space
inline constexpr std::string_view kLightFaceSizes = "face_sizes";       // uint32 [F]
inline constexpr std::string_view kLightFaceIndices = "face_indices";   // uint32 [sum of face_sizes]
// ---- report datasets (leaf under a report directory) ----
inline constexpr std::string_view kReportVertices = "vertices";

// ---- root attributes ----
inline constexpr std::string_view kFormat = "format";
inline constexpr std::string_view kFormatVersion = "format_version";
inline constexpr std::string_view kGenerator = "generator";
inline constexpr std::string_view kCreated = "created";
inline constexpr std::string_view kCommandLine = "command_line";
inline constexpr std::string_view kSource = "source";  // also: /mesh/normals' origin
inline constexpr std::string_view kSourceSha256 = "source_sha256";
inline constexpr std::string_view kUpAxis = "up_axis";
inline constexpr std::string_view kShConvention = "sh_convention";

// ---- product attributes (/ao, /transfer/*, /radiance/band1) ----
inline constexpr std::string_view kIntegrand = "integrand";
inline constexpr std::string_view kShOrder = "sh_order";
inline constexpr std::string_view kShading = "shading";
inline constexpr std::string_view kEnvironment = "environment";
inline constexpr std::string_view kEnvironmentSha256 = "environment_sha256";
inline constexpr std::string_view kEnvironmentLayout = "environment_layout";
inline constexpr std::string_view kNegativePixelsClamped = "negative_pixels_clamped";
inline constexpr std::string_view kIntegrator = "integrator";
inline constexpr std::string_view kIntegratorDescription = "integrator_description";
inline constexpr std::string_view kSamples = "samples";
inline constexpr std::string_view kSeed = "seed";
inline constexpr std::string_view kVisibility = "visibility";
inline constexpr std::string_view kBounces = "bounces";                    // interreflections: applied
inline constexpr std::string_view kBouncesRequested = "bounces_requested";
inline constexpr std::string_view kBounceRays = "bounce_rays";
inline constexpr std::string_view kBounceStdError = "bounce_std_error";
// (and kAlbedo, below: RGB)
// ---- lightmap attributes (v5) ----
inline constexpr std::string_view kUvSet = "uv_set";    // on /mesh/uv: the set's name in the asset ("TEXCOORD_1", "vt")
inline constexpr std::string_view kPadding = "padding";  // on /lightmap/state: gutter rings, in texels

// ---- FIV attributes ----
inline constexpr std::string_view kFaceConvention = "face_convention";
inline constexpr std::string_view kCentre = "centre";
inline constexpr std::string_view kRadius = "radius";
inline constexpr std::string_view kRadii = "radii";
inline constexpr std::string_view kAngularConvention = "angular_convention";
inline constexpr std::string_view kGrid = "grid";
inline constexpr std::string_view kFraction = "fraction";
inline constexpr std::string_view kRadialScheme = "radial_scheme";  // (v7) on /fiv/occluders/<name>/shells
inline constexpr std::string_view kFirstOffset = "first_offset";    // (v7) on /fiv/occluders/<name>/shells
inline constexpr std::string_view kMeaning = "meaning";

// ---- area-light attributes ----
inline constexpr std::string_view kShape = "shape";          // /lights/<name>: "quad", "disc", "box", ...
inline constexpr std::string_view kRadiance = "radiance";    // /lights/<name>: RGB, 3 doubles >= 0
inline constexpr std::string_view kTwoSided = "two_sided";   // /lights/<name>: 0 / 1
inline constexpr std::string_view kLightOrder = "lights";    // area_lights/*: the lights' names, one per line, in column order
// ---- punctual-light attributes (v6: /lights/<name> of shape "point", "spot", "directional"; no datasets) ----
inline constexpr std::string_view kPosition = "position";                // point, spot: 3 doubles, world space
inline constexpr std::string_view kDirection = "direction";              // spot, directional: unit, where the light travels
inline constexpr std::string_view kInnerConeAngle = "inner_cone_angle";  // spot: radians
inline constexpr std::string_view kOuterConeAngle = "outer_cone_angle";  // spot: radians, > inner, <= pi/2
inline constexpr std::string_view kRange = "range";                      // point, spot (optional): > 0, KHR's range
// The shapes of punctual lights.
inline constexpr std::string_view kPunctualShapes[] = {"point", "spot", "directional"};
inline bool is_punctual_shape(std::string_view shape) {
  for (std::string_view s : kPunctualShapes)
    if (s == shape) return true;
  return false;
}

// ---- report attributes ----
inline constexpr std::string_view kColumns = "columns";
inline constexpr std::string_view kPoints = "points";
inline constexpr std::string_view kReference = "reference";
inline constexpr std::string_view kReferenceSeconds = "reference_seconds";
inline constexpr std::string_view kBakeSeconds = "bake_seconds";
inline constexpr std::string_view kIntegralsPerSecond = "integrals_per_second";
inline constexpr std::string_view kMeshRms = "mesh_rms";  // band-1 / S rows: what their relative error divides by
inline constexpr std::string_view kTargetError = "target_error";  // on the /report group: the RMSE the bake was asked for

// ---- /scene attributes ----
inline constexpr std::string_view kSceneFile = "scene_file";
inline constexpr std::string_view kOptionsFile = "options_file";
inline constexpr std::string_view kOptionsSha256 = "options_sha256";
inline constexpr std::string_view kShTolerance = "sh_tolerance";
inline constexpr std::string_view kRelight = "relight";
inline constexpr std::string_view kPlan = "plan";

// ---- /objects/<name> attributes ----
inline constexpr std::string_view kRole = "role";
inline constexpr std::string_view kMesh = "mesh";
inline constexpr std::string_view kMeshSha256 = "mesh_sha256";
inline constexpr std::string_view kTransform = "transform";
inline constexpr std::string_view kAlbedo = "albedo";
inline constexpr std::string_view kPhongExponent = "phong_exponent";
inline constexpr std::string_view kSpecular = "specular";
inline constexpr std::string_view kShOrderDiffuse = "sh_order_diffuse";
inline constexpr std::string_view kShOrderGlossy = "sh_order_glossy";
inline constexpr std::string_view kBaked = "baked";
inline constexpr std::string_view kLeftOut = "left_out";
inline constexpr std::string_view kClosedFormVertices = "closed_form_vertices";
inline constexpr std::string_view kNodePath = "node_path";

} // namespace prt::formats::names
