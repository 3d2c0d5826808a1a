// loader.cpp — .prt.h5 → plain arrays for the prtshade core; see prtshade/loader.h.
#include <prtshade/loader.h>

#include <algorithm>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>

namespace prt::shade {
namespace {

using formats::Dataset;
using formats::FormatError;

template <class T>
const std::vector<T>& data_as(const Dataset& ds, const std::string& file) {
  const auto* v = std::get_if<std::vector<T>>(&ds.data);
  if (v == nullptr) throw FormatError(file, "dataset '" + ds.path + "' has an unexpected type");
  return *v;
}

const formats::AttrValue& attr_value(const Dataset& ds, std::string_view name, const std::string& file) {
  const formats::Attr* a = formats::find_attr(ds.attrs, name);
  if (a == nullptr) throw FormatError(file, "dataset '" + ds.path + "' has no attribute '" + std::string(name) + "'");
  return a->value;
}

template <class T>
const T& attr_as(const Dataset& ds, std::string_view name, const std::string& file) {
  const auto* v = std::get_if<T>(&attr_value(ds, name, file));
  if (v == nullptr) throw FormatError(file, "attribute '" + std::string(name) + "' of '" + ds.path + "' has an unexpected type");
  return *v;
}

int sh_order_of(const Dataset& ds, const std::string& file) {
  const int64_t L = attr_as<int64_t>(ds, "sh_order", file);
  if (L < 1 || L > 64) throw FormatError(file, "'" + ds.path + "' has sh_order " + std::to_string(L) + " outside [1, 64]");
  return int(L);
}

// The part of `path` after its vertex-set prefix, e.g. "/objects/rock/ao" → "/ao".
std::string_view local_path(std::string_view path, std::string_view prefix) { return path.substr(prefix.size()); }

} // namespace

FivOccluder LoadedOccluder::view() const noexcept {
  return FivOccluder{{centre[0], centre[1], centre[2]}, radius, n_rho, n_theta, n_phi,
                     radii.data(), shells.data(), valid.data()};
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
  const formats::File f = formats::read_file(path);  // full schema check: shapes, ranges, finiteness
  LoadedAsset asset;
  asset.path = path;
  if (const formats::Attr* a = formats::find_attr(f.root_attrs, "format_version"))
    if (const auto* v = std::get_if<int64_t>(&a->value)) asset.format_version = *v;
  if (const formats::Attr* a = formats::find_attr(f.root_attrs, "up_axis"))
    if (const auto* v = std::get_if<std::string>(&a->value)) asset.up_axis = *v;

  std::map<std::string, LoadedVertexSet> sets;  // by prefix: "" first, then "/objects/<name>"
  std::map<std::string, LoadedOccluder> occluders;
  for (const Dataset& ds : f.datasets) {
    const std::string& p = ds.path;
    if (p.starts_with("/report/")) continue;
    if (p == "/fiv/environment") {
      const auto& v = data_as<float>(ds, file);
      if (v.size() != 9) throw FormatError(file, "/fiv/environment must hold 9 values");
      std::copy(v.begin(), v.end(), asset.fiv_environment.begin());
      asset.has_fiv_environment = true;
    } else if (p == "/fiv/irradiance_cube") {
      if (ds.shape.size() != 4 || ds.shape[0] != 6 || ds.shape[1] != ds.shape[2] || ds.shape[3] != 3)
        throw FormatError(file, "/fiv/irradiance_cube must be [6][S][S][3]");
      asset.irradiance_cube_size = int(ds.shape[1]);
      asset.irradiance_cube = data_as<float>(ds, file);
    } else if (p.starts_with("/fiv/occluders/")) {
      const std::string rest = p.substr(std::string("/fiv/occluders/").size());
      const size_t slash = rest.find('/');
      const std::string name = rest.substr(0, slash), leaf = rest.substr(slash + 1);
      LoadedOccluder& o = occluders[name];
      o.name = name;
      if (leaf == "shells") {
        if (ds.shape.size() != 5 || ds.shape[3] != 3 || ds.shape[4] != 3)
          throw FormatError(file, "'" + p + "' must be [Nr][Ntheta][Nphi][3][3]");
        o.n_rho = int(ds.shape[0]), o.n_theta = int(ds.shape[1]), o.n_phi = int(ds.shape[2]);
        o.shells = data_as<float>(ds, file);
        o.attrs = ds.attrs;
        const auto& c = attr_as<std::vector<double>>(ds, "centre", file);
        if (c.size() != 3) throw FormatError(file, "attribute 'centre' of '" + p + "' must hold 3 values");
        for (int k = 0; k < 3; ++k) o.centre[size_t(k)] = float(c[size_t(k)]);
        o.radius = float(attr_as<double>(ds, "radius", file));
        const auto& r = attr_as<std::vector<double>>(ds, "radii", file);
        if (r.size() != ds.shape[0])
          throw FormatError(file, "attribute 'radii' of '" + p + "' holds " + std::to_string(r.size()) +
                                      " values for " + std::to_string(ds.shape[0]) + " shells");
        o.radii.assign(r.begin(), r.end());
        if (const formats::Attr* g = formats::find_attr(ds.attrs, "grid"))
          if (const auto* s = std::get_if<std::string>(&g->value)) o.grid = *s;
      } else if (leaf == "valid") {
        o.valid = data_as<uint8_t>(ds, file);
      }
    } else {
      const std::string prefix = formats::vertex_set_of(p);
      LoadedVertexSet& s = sets[prefix];
      s.name = prefix.empty() ? "" : prefix.substr(std::string("/objects/").size());
      const std::string_view leaf = local_path(p, prefix);
      if (leaf == "/mesh/positions") s.positions = data_as<float>(ds, file);
      else if (leaf == "/mesh/normals") s.normals = data_as<float>(ds, file);
      else if (leaf == "/mesh/triangles") s.triangles = data_as<uint32_t>(ds, file);
      else if (leaf == "/ao") s.ao = data_as<float>(ds, file);
      else if (leaf == "/radiance/band1") s.radiance_band1 = data_as<float>(ds, file);
      else if (leaf == "/transfer/diffuse") {
        s.transfer_order = sh_order_of(ds, file);
        s.transfer = data_as<float>(ds, file);
      } else if (leaf == "/transfer/visibility") {
        s.visibility_order = sh_order_of(ds, file);
        s.visibility = data_as<float>(ds, file);
      }
      // Other paths (/mesh/source_position, /scene/...) are not needed for shading.
    }
  }
  for (auto& [prefix, s] : sets)
    if (!s.positions.empty() || !s.transfer.empty() || !s.radiance_band1.empty()) asset.vertex_sets.push_back(std::move(s));
  for (auto& [name, o] : occluders) {
    if (o.shells.empty() || o.valid.size() * 9 != o.shells.size())
      throw FormatError(file, "occluder '" + name + "' needs shells and a valid mask of the same grid");
    try {
      validate_occluder(o.view());
    } catch (const std::invalid_argument& e) {
      throw FormatError(file, "occluder '" + name + "': " + e.what());
    }
    asset.occluders.push_back(std::move(o));
  }
  if (asset.irradiance_cube_size > 0) {
    try {
      validate_difmap(asset.difmap());
    } catch (const std::invalid_argument& e) {
      throw FormatError(file, std::string("/fiv/irradiance_cube: ") + e.what());
    }
  }
  return asset;
}

} // namespace prt::shade
