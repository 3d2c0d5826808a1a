// tools/prtbake/bakefile.h — how baked results (libbake, in memory) become the typed asset model
// (<formats/asset.h>, formats/SCHEMA.md). The one place that joins the two, shared by
// `prtbake vertex`, `prtbake fiv` and `prtbake scene`, so a product has the same layout and
// attributes whichever command baked it (docs/ARCHITECTURE.md §4).
#pragma once

#include <bake/bake/bounce.h>
#include <bake/bake/error_report.h>
#include <bake/bake/fiv.h>
#include <bake/bake/lightmap.h>
#include <bake/bake/lightmap_receivers.h>
#include <bake/mesh/texels.h>
#include <bake/bake/vertex_bake.h>
#include <bake/environment/envmap.h>
#include <bake/lights/lights.h>
#include <bake/lights/punctual.h>
#include <bake/mesh/mesh.h>
#include <formats/asset.h>

#include <string>
#include <vector>

namespace prt::tool {

namespace F = prt::formats;

// The mesh of a vertex set: positions, normals (and their source), triangles, source_position.
void set_mesh(F::VertexSet& set, const bake::Mesh& mesh);

struct ProductInfo {
  std::string integrator, integrator_description;
  uint32_t samples = 0;  // rays per vertex (qmc) or k (silhouette)
  uint64_t seed = 1;
  int transfer_order = 0, visibility_order = 0;
  const bake::EnvMap* env = nullptr;  // for radiance/band1
  std::string env_path;
  std::string rows = "vertex";  // what a row is, as the integrands' layouts name it ("vertex"; lightmaps: "row][col")
};
// ao, transfer_diffuse, transfer_visibility, radiance_band1: whatever the layout holds.
void set_products(F::VertexSet& set, const bake::VertexBake& bake, const ProductInfo& info);

// The attributes of a product with interreflections (formats/SCHEMA.md "Bounces"): the bounces
// applied and asked for, the albedo (RGB) and the gather rays; the integrand says which recursion.
enum class Bounced { Transfer, Band1, Shadowed, AreaIrradiance };
void set_bounces(F::Product& product, Bounced which, int applied, const bake::BounceSpec& spec,
                 const std::vector<double>& albedo, double relative_std_error);

// The lightmap of a texel bake (format v5): /mesh/uv from the UV set, /lightmap/state from the
// image's texel states (its `padding`), the texels' shade points as world positions and normals
// (0 where empty or padding), and the products as images (set_products' layout and attributes,
// rows = texels in row-major order).
void set_lightmap(F::VertexSet& set, const bake::Mesh& mesh, const bake::UvSet& uv, const bake::TexelAtlas& atlas,
                  const bake::Lightmap& image, const bake::ProductLayout& layout, const ProductInfo& info,
                  uint32_t padding);

// area_lights/irradiance and /sh per texel (lightmap/area_lights/...) from the lightmap image of
// the area lights' rows (channels [lights][1 + n²]), into a set whose lightmap set_lightmap wrote;
// the last `punctual` of `lights` are punctual lights (their integrands are said too).
void set_lightmap_area_lights(F::VertexSet& set, const bake::Lightmap& image, const std::vector<std::string>& lights,
                              int sh_order, size_t punctual);

// The lightmap image of the valid texels' rows of `texels` (LightmapReceivers::image: placed,
// filled, padded `spec.padding` rings), its UV seams stitched unless `spec.stitch` is false
// (bake/bake/lightmap.h stitch_seams; `stitch` receives its numbers, edges 0 when not stitched).
bake::Lightmap lightmap_image(const bake::Mesh& mesh, const bake::Topology& topology,
                              const bake::LightmapReceivers& texels, const bake::LightmapSpec& spec,
                              const bake::VertexBake& rows, bake::SeamStitch& stitch);

// An area light as the file stores it (/lights/<name>: world-space faces, radiance, two_sided).
F::Light light_of(const bake::AreaLight& light);
// A punctual light as the file stores it (v6: /lights/<name> attributes: shape, its intensity as
// `radiance`, position, direction, the spot's cone angles in radians).
F::Light light_of(const bake::PunctualLight& light);
// area_lights/irradiance [V][lights] and, when sh_order > 0, area_lights/sh [V][lights][n²] from
// AreaLightIntegrator rows ([V][lights][1 + n²], bake/lights/area_bake.h); `lights` in column order,
// the last `punctual` of them punctual lights (bake/lights/punctual.h; their integrands are said too).
void set_area_lights(F::VertexSet& set, const std::vector<double>& rows, const std::vector<std::string>& lights,
                     int sh_order, size_t punctual);

// The error report of a vertex bake: one row per product (rmse, max_abs, reference_rms,
// bake_std_error, reference_std_error) and the vertices compared. Wall times are kept unless
// `reproducible`.
F::Report report_of(const bake::ErrorReport& report, double bake_seconds, size_t points, bool reproducible);

// Records the target error the bake was asked to reach (/report's target_error; SCHEMA.md) when
// it had one: `target` > 0 (bake/bake/choose.h; the default target counts), else nothing.
void set_target_error(F::Asset& asset, double target);

// F_env and the irradiance cube (DifMap) of the asset, from the environment `env` (its SHA-256).
void set_fiv_environment(F::Asset& asset, const bake::EnvMapInfo& env, const std::string& env_path, const bake::Fiv& fenv,
                         const std::vector<float>& cube, int cube_size);
// An occluder's shells and valid mask (moved from `shells`).
F::Occluder occluder_of(const std::string& name, bake::FivShells shells, const bake::EnvMapInfo& env,
                        const std::string& env_path, double fraction, uint32_t silhouette_k);
// An occluder's self-shadows for /fiv/occluders/<name>/self_band1: the band-1 columns of a
// bake_fiv_self_shadows bake, [V][RGB][m] as float.
F::OccluderSelfBand1 self_band1_of(const bake::VertexBake& self);
// The error report row of an occluder's shells.
F::ReportRow fiv_report_of(const std::string& name, const bake::FivErrorReport& report, const bake::FivShells& shells,
                           bool reproducible);

// "bunny.obj" → "bunny": a dataset-path-safe name.
std::string safe_name(const std::string& stem);

} // namespace prt::tool
