// loader.cpp — .prt.h5 → plain arrays for the prtshade core; see prtshade/loader.h. A thin
// adapter: formats::read_asset reads and checks the file, this copies what shading needs.
#include <prtshade/loader.h>

#include <formats/asset.h>
#include <formats/names.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>

namespace prt::shade {
namespace {

using formats::FormatError;

// L of a transfer product, within what the core shades.
int sh_order_of(const formats::Product& p, const std::string& file, const std::string& what) {
  const int64_t L = p.sh_order.value_or(0);
  if (L < 1 || L > 64) throw FormatError(file, what + " has SH order " + std::to_string(L) + " outside [1, 64]");
  return int(L);
}

LoadedVertexSet vertex_set_of(const formats::VertexSet& s, const std::string& name, const std::string& file) {
  LoadedVertexSet v;
  v.name = name;
  v.positions.assign(s.positions->values.begin(), s.positions->values.end());  // float64 rounded once
  if (s.normals) v.normals = s.normals->values;
  if (s.triangles) v.triangles = s.triangles->values;
  if (s.ao) v.ao = s.ao->values;
  if (s.radiance_band1) v.radiance_band1 = s.radiance_band1->values;
  const std::string where = name.empty() ? std::string("the root layout") : "object '" + name + "'";
  if (s.transfer_diffuse) {
    v.transfer_order = sh_order_of(*s.transfer_diffuse, file, "the diffuse transfer of " + where);
    v.transfer = s.transfer_diffuse->values;
  }
  if (s.transfer_visibility) {
    v.visibility_order = sh_order_of(*s.transfer_visibility, file, "the visibility transfer of " + where);
    v.visibility = s.transfer_visibility->values;
  }
  return v;
}

LoadedOccluder occluder_of(const formats::Occluder& o, const std::string& file) {
  if (!o.valid) throw FormatError(file, "occluder '" + o.name + "' needs shells and a valid mask of the same grid");
  LoadedOccluder out;
  out.name = o.name;
  for (int k = 0; k < 3; ++k) out.centre[size_t(k)] = float(o.centre[size_t(k)]);
  out.radius = float(o.radius);
  out.n_rho = o.n_rho, out.n_theta = o.n_theta, out.n_phi = o.n_phi;
  out.radii.assign(o.radii.begin(), o.radii.end());
  if (o.float16) out.shells_half = formats::float16_bits(o.shells);
  else out.shells = o.shells;
  out.valid = o.valid->values;
  // Version 7 (formats/SCHEMA.md): no radial_scheme attribute is the geometric scheme.
  if (o.radial_scheme.value_or("geometric") == "surface") {
    if (!o.surface_radius) throw FormatError(file, "occluder '" + o.name + "' has radial_scheme surface but no surface_radius");
    out.radial_scheme = kFivRadialSurface;
    out.surface_radius = o.surface_radius->values;
  }
  if (o.proxy == std::string(formats::names::kProxyCone)) {
    if (!o.cones) throw FormatError(file, "occluder '" + o.name + "' says proxy \"cone\" without a cone table");
    out.proxy = o.proxy.value();
    if (o.cones->float16) out.cones_half = formats::float16_bits(o.cones->values);
    else out.cones = o.cones->values;
  }
  if (o.self_band1) out.self_band1 = o.self_band1->values;
  out.grid = o.grid.value_or("");
  out.attrs = formats::shells_attrs(o);
  try {
    validate_occluder(out.view());
  } catch (const std::invalid_argument& e) {
    throw FormatError(file, "occluder '" + o.name + "': " + e.what());
  }
  return out;
}

} // namespace

FivOccluder LoadedOccluder::view() const noexcept {
  return FivOccluder{{centre[0], centre[1], centre[2]},
                     radius,
                     n_rho,
                     n_theta,
                     n_phi,
                     radii.data(),
                     shells_half.empty() ? shells.data() : nullptr,
                     valid.data(),
                     radial_scheme,
                     radial_scheme == kFivRadialSurface ? surface_radius.data() : nullptr,
                     cones.empty() ? nullptr : cones.data(),
                     shells_half.empty() ? nullptr : shells_half.data(),
                     cones_half.empty() ? nullptr : cones_half.data()};
}

const LoadedVertexSet* LoadedAsset::find_vertex_set(std::string_view name) const noexcept {
  for (const LoadedVertexSet& v : vertex_sets)
    if (v.name == name) return &v;
  return nullptr;
}

DifMap LoadedAsset::difmap() const noexcept {
  return irradiance_cube_size > 0 ? DifMap{irradiance_cube_size, irradiance_cube.data()} : DifMap{0, nullptr};
}

std::vector<FivOccluder> LoadedAsset::occluder_views() const {
  std::vector<FivOccluder> out;
  out.reserve(occluders.size());
  for (const LoadedOccluder& o : occluders) out.push_back(o.view());
  return out;
}

LoadedAsset load_prt(const std::filesystem::path& path) {
  const std::string file = path.string();
  const formats::Asset a = formats::read_asset(path);  // full schema check: shapes, ranges, finiteness
  LoadedAsset asset;
  asset.path = path;
  asset.format_version = a.root.format_version;
  asset.up_axis = a.root.up_axis;
  asset.skipped_attrs = a.skipped_attrs;
  if (a.vertices.positions) asset.vertex_sets.push_back(vertex_set_of(a.vertices, "", file));
  for (const formats::SceneObject& o : a.objects)
    if (o.set.positions) asset.vertex_sets.push_back(vertex_set_of(o.set, o.name, file));
  if (a.fiv_environment) {
    asset.has_fiv_environment = true;
    asset.fiv_environment = a.fiv_environment->f_env;
    try {
      validate_environment_fiv(asset.fiv_environment.data());
    } catch (const std::invalid_argument& e) {
      throw FormatError(file, "/fiv/environment: " + std::string(e.what()));
    }
  }
  if (a.irradiance_cube) {
    asset.irradiance_cube_size = a.irradiance_cube->size;
    asset.irradiance_cube = a.irradiance_cube->values;
    try {
      validate_difmap(asset.difmap());
    } catch (const std::invalid_argument& e) {
      throw FormatError(file, "the irradiance cube: " + std::string(e.what()));
    }
  }
  for (const formats::Occluder& o : a.occluders) asset.occluders.push_back(occluder_of(o, file));
  return asset;
}

} // namespace prt::shade
