// tools/prtbake/bakefile.h — how baked results (libbake, in memory) become datasets of the file
// (formats/, formats/SCHEMA.md). The one place that joins the two, shared by `prtbake vertex`,
// `prtbake fiv` and `prtbake scene`, so a product has the same layout and attributes whichever
// command baked it. `prefix` is "" for the root layout and "/objects/<name>" for a scene object.
#pragma once

#include <bake/envmap.h>
#include <bake/fiv.h>
#include <bake/mesh.h>
#include <bake/vertex_bake.h>
#include <formats/prtfile.h>

#include <string>
#include <vector>

namespace prt::tool {

namespace F = prt::formats;

// /mesh/{positions,normals,triangles,source_position} under prefix.
void add_mesh(F::File& file, const std::string& prefix, const bake::Mesh& mesh);

struct ProductInfo {
  std::string integrator, integrator_description;
  uint32_t samples = 0;  // rays per vertex (qmc) or k (silhouette)
  uint64_t seed = 1;
  int transfer_order = 0, visibility_order = 0;
  const bake::EnvMap* env = nullptr;  // for radiance/band1
  std::string env_path;
};
// /ao, /transfer/{diffuse,visibility}, /radiance/band1 under prefix: whatever the layout holds.
void add_products(F::File& file, const std::string& prefix, const bake::VertexBake& bake, const ProductInfo& info);

// Error report datasets under `dir` (e.g. "/report" or "/report/objects/<name>"): one [5] dataset
// per product (rmse, max_abs, reference_rms, bake_std_error, reference_std_error) and `vertices`.
// Wall times are attributes unless `reproducible`.
void add_report(F::File& file, const std::string& dir, const bake::ErrorReport& report, double bake_seconds,
                size_t points, bool reproducible);

// /fiv/environment and /fiv/irradiance_cube.
void add_fiv_environment(F::File& file, const bake::EnvMap& env, const std::string& env_path, const bake::Fiv& fenv,
                         const std::vector<float>& cube, int cube_size);
// /fiv/occluders/<name>/{shells,valid}.
void add_fiv_occluder(F::File& file, const std::string& name, const bake::FivShells& shells, const bake::EnvMap& env,
                      const std::string& env_path, double fraction, uint32_t samples);
// /report/fiv/<name>.
void add_fiv_report(F::File& file, const std::string& name, const bake::FivErrorReport& report,
                    const bake::FivShells& shells, bool reproducible);

// "bunny.obj" → "bunny": a dataset-path-safe name.
std::string safe_name(const std::string& stem);

} // namespace prt::tool
