// schema.cpp — schema v5 (formats/SCHEMA.md) as code: validate() is the single check that the
// writer applies before writing and the reader applies after reading. Names: <formats/names.h>.
#include <formats/names.h>
#include <formats/prtfile.h>

#include "utf8.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <sstream>

namespace prt::formats {
namespace {

using detail::valid_utf8;

namespace N = names;

// Whether a /lights/<name> group's attributes make it a punctual light (v6).
bool is_punctual_group(const std::string& group, const std::vector<Attr>& attrs) {
  const std::string dir = std::string(N::kLights) + "/";
  if (!group.starts_with(dir) || group.find('/', dir.size()) != std::string::npos) return false;
  const Attr* shape = find_attr(attrs, N::kShape);
  const auto* s = shape ? std::get_if<std::string>(&shape->value) : nullptr;
  return s != nullptr && N::is_punctual_shape(*s);
}


constexpr std::array<std::string_view, 7> kRequiredRootStrings = {
    N::kGenerator, N::kCreated, N::kCommandLine, N::kSource, N::kSourceSha256, N::kUpAxis, N::kShConvention};

constexpr int kMaxRank = 32;  // H5S_MAX_RANK

using Kind = DatasetKind;

std::vector<std::string_view> split_path(std::string_view path) {
  std::vector<std::string_view> parts;
  std::size_t i = 1;
  while (i <= path.size()) {
    std::size_t j = path.find('/', i);
    if (j == std::string_view::npos) j = path.size();
    parts.push_back(path.substr(i, j - i));
    i = j + 1;
  }
  return parts;
}

// A link name HDF5 and h5py accept unchanged: non-empty, not "." or "..", no control chars.
bool valid_component(std::string_view c) {
  if (c.empty() || c == "." || c == "..") return false;
  for (char ch : c)
    if (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7F) return false;
  return valid_utf8(c);
}

std::string shape_str(const std::vector<uint64_t>& shape) {
  std::ostringstream os;
  os << '[';
  for (std::size_t i = 0; i < shape.size(); ++i) os << (i ? ", " : "") << shape[i];
  os << ']';
  return os.str();
}

std::string index_str(uint64_t flat, const std::vector<uint64_t>& shape) {
  std::vector<uint64_t> idx(shape.size());
  for (std::size_t d = shape.size(); d-- > 0;) {
    idx[d] = shape[d] ? flat % shape[d] : 0;
    flat = shape[d] ? flat / shape[d] : 0;
  }
  return shape_str(idx);
}

// The dataset paths schema v5 allows, for messages.
std::string allowed_paths() {
  std::string s;
  for (std::string_view p : {N::kPositions, N::kNormals, N::kTriangles, N::kSourcePosition, N::kAo,
                             N::kTransferDiffuse, N::kTransferVisibility, N::kRadianceBand1, N::kRadianceShadowed, N::kAreaIrradiance,
                             N::kAreaSh, N::kUv, N::kLightmapState, N::kLightmapPositions, N::kLightmapNormals,
                             N::kLightmapAo, N::kLightmapTransferDiffuse, N::kLightmapTransferVisibility,
                             N::kLightmapRadianceBand1, N::kLightmapRadianceShadowed})
    s += std::string(p) + ", ";
  return s + "the same under " + std::string(N::kObjects) + "/<name>/, " + std::string(N::kFivEnvironment) + ", " +
         std::string(N::kIrradianceCube) + ", " + std::string(N::kOccluders) + "/<name>/{" +
         std::string(N::kShells) + "," + std::string(N::kValid) + "," + std::string(N::kSurfaceRadius) + "," + std::string(N::kCones) + "," + std::string(N::kSelfBand1) + "}, " + std::string(N::kLights) + "/<name>/{" +
         std::string(N::kLightVertices) + "," + std::string(N::kLightFaceSizes) + "," +
         std::string(N::kLightFaceIndices) + "} and anything under " +
         std::string(N::kReport) + "/";
}

class Checker {
public:
  explicit Checker(const std::filesystem::path& file) : file_(file.string()) {}

  [[noreturn]] void fail(const std::string& defect) const { throw FormatError(file_, defect); }

  void attrs(const std::vector<Attr>& list, const std::string& owner) const {
    std::set<std::string_view> seen;
    for (const Attr& a : list) {
      if (a.name.empty()) fail(owner + " has an attribute with an empty name");
      if (!valid_utf8(a.name) || a.name.find('\0') != std::string::npos)
        fail(owner + " has an attribute name that is not valid UTF-8 text");
      if (!seen.insert(a.name).second) fail(owner + " has attribute '" + a.name + "' twice");
      const std::string what = "attribute '" + a.name + "' of " + owner;
      if (const auto* s = std::get_if<std::string>(&a.value)) {
        if (s->find('\0') != std::string::npos) fail(what + " contains a NUL character");
        if (!valid_utf8(*s)) fail(what + " is not valid UTF-8");
      } else if (const auto* vs = std::get_if<std::vector<std::string>>(&a.value)) {
        for (std::size_t i = 0; i < vs->size(); ++i) {
          if ((*vs)[i].find('\0') != std::string::npos) fail(what + " has a NUL character in string " + std::to_string(i));
          if (!valid_utf8((*vs)[i])) fail(what + " has a string that is not valid UTF-8 (string " + std::to_string(i) + ")");
        }
      } else if (const auto* d = std::get_if<double>(&a.value)) {
        if (!std::isfinite(*d)) fail(what + " is not finite (" + std::to_string(*d) + ")");
      } else if (const auto* v = std::get_if<std::vector<double>>(&a.value)) {
        for (std::size_t i = 0; i < v->size(); ++i)
          if (!std::isfinite((*v)[i]))
            fail(what + " has a non-finite value at index " + std::to_string(i));
      }
    }
  }

  const std::string& required_string(const std::vector<Attr>& list, std::string_view name,
                                     const std::string& owner) const {
    const Attr* a = find_attr(list, name);
    if (a == nullptr) fail(owner + " lacks the required attribute '" + std::string(name) + "'");
    const auto* s = std::get_if<std::string>(&a->value);
    if (s == nullptr) fail("attribute '" + std::string(name) + "' of " + owner + " must be a string");
    return *s;
  }

  void root(const std::vector<Attr>& list) const {
    attrs(list, "the root group");
    if (const Attr* f = find_attr(list, N::kFormat)) {
      const auto* s = std::get_if<std::string>(&f->value);
      if (s == nullptr || *s != kFormatName)
        fail("root attribute '" + std::string(N::kFormat) + "' must be the string \"" + std::string(kFormatName) + "\"");
    }
    if (const Attr* v = find_attr(list, N::kFormatVersion)) {
      const auto* i = std::get_if<int64_t>(&v->value);
      if (i == nullptr || *i < 1 || *i > kFormatVersion)
        fail("root attribute '" + std::string(N::kFormatVersion) + "' must be an integer in 1.." +
             std::to_string(kFormatVersion));
    }
    for (std::string_view name : kRequiredRootStrings) {
      const std::string& s = required_string(list, name, "the root group");
      if (s.empty()) fail("root attribute '" + std::string(name) + "' is empty");
    }
    const std::string& up = required_string(list, N::kUpAxis, "the root group");
    if (up != "y" && up != "z")
      fail("root attribute '" + std::string(N::kUpAxis) + "' must be \"y\" or \"z\", not \"" + up + "\"");
    const std::string& sha = required_string(list, N::kSourceSha256, "the root group");
    bool hex = sha.size() == 64;
    for (char c : sha) hex = hex && ((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'));
    if (!hex) fail("root attribute '" + std::string(N::kSourceSha256) + "' must be 64 lowercase hex digits");
  }

  // The kind of a dataset path; `prefix` receives the vertex set it belongs to: "" for the
  // root layout (one mesh per file), "/objects/<name>" for an object of a scene file (v2).
  static Kind classify(std::string_view path, std::string* prefix = nullptr) {
    if (prefix) prefix->clear();
    const auto p = split_path(path);
    const std::string objects = std::string(N::kObjects) + "/", occluders = std::string(N::kOccluders) + "/";
    if (path.starts_with(std::string(N::kReport) + "/")) return Kind::report;
    std::string_view local = path;  // the path inside its vertex set
    const bool object = path.starts_with(objects);
    if (object) {
      if (p.size() < 3) return Kind::unknown;
      const std::size_t end = objects.size() + p[1].size();
      if (prefix) *prefix = std::string(path.substr(0, end));
      local = path.substr(end);
    }
    static constexpr std::pair<std::string_view, Kind> kVertexSet[] = {
        {N::kPositions, Kind::positions},           {N::kNormals, Kind::normals},
        {N::kTriangles, Kind::triangles},           {N::kSourcePosition, Kind::source_position},
        {N::kAo, Kind::ao},                         {N::kTransferDiffuse, Kind::transfer_diffuse},
        {N::kTransferVisibility, Kind::transfer_visibility}, {N::kRadianceBand1, Kind::radiance_band1},
        {N::kRadianceShadowed, Kind::radiance_shadowed},
        {N::kAreaIrradiance, Kind::area_irradiance}, {N::kAreaSh, Kind::area_sh},
        {N::kUv, Kind::uv},                         {N::kLightmapState, Kind::lightmap_state},
        {N::kLightmapPositions, Kind::lightmap_positions}, {N::kLightmapNormals, Kind::lightmap_normals},
        {N::kLightmapAo, Kind::lightmap_ao},        {N::kLightmapTransferDiffuse, Kind::lightmap_transfer_diffuse},
        {N::kLightmapTransferVisibility, Kind::lightmap_transfer_visibility},
        {N::kLightmapRadianceBand1, Kind::lightmap_radiance_band1},
        {N::kLightmapRadianceShadowed, Kind::lightmap_radiance_shadowed},
        {N::kLightmapAreaIrradiance, Kind::lightmap_area_irradiance}, {N::kLightmapAreaSh, Kind::lightmap_area_sh}};
    for (const auto& [name, kind] : kVertexSet)
      if (local == name) return kind;
    if (object) return Kind::unknown;
    if (path == N::kFivEnvironment) return Kind::fiv_environment;
    if (path == N::kIrradianceCube) return Kind::irradiance_cube;
    if (path.starts_with(occluders) && p.size() == split_path(N::kOccluders).size() + 2) {
      if (p.back() == N::kShells) return Kind::occluder_shells;
      if (p.back() == N::kValid) return Kind::occluder_valid;
      if (p.back() == N::kSurfaceRadius) return Kind::occluder_surface_radius;
      if (p.back() == N::kCones) return Kind::occluder_cones;
      if (p.back() == N::kSelfBand1) return Kind::occluder_self_band1;
    }
    if (path.starts_with(std::string(N::kLights) + "/") && p.size() == split_path(N::kLights).size() + 2) {
      if (p.back() == N::kLightVertices) return Kind::light_vertices;
      if (p.back() == N::kLightFaceSizes) return Kind::light_face_sizes;
      if (p.back() == N::kLightFaceIndices) return Kind::light_face_indices;
    }
    return Kind::unknown;
  }

  void dtype(const Dataset& d, std::size_t want) const {
    static constexpr std::array<std::string_view, 5> names = {"float32", "uint32", "uint8", "float64", "float16"};
    if (d.data.index() != want)
      fail("dataset '" + d.path + "' must be " + std::string(names[want]) + ", not " +
           std::string(dtype_name(d.data)));
  }

  void shape(const Dataset& d, const std::vector<uint64_t>& want, const std::string& rule) const {
    if (d.shape != want)
      fail("dataset '" + d.path + "' has shape " + shape_str(d.shape) + "; expected " + rule +
           " = " + shape_str(want));
  }

  // The integer attribute sh_order (number of bands L) of `d`, in 1..65535.
  uint64_t sh_order(const Dataset& d) const {
    const std::string sh_order(N::kShOrder);
    const Attr* a = find_attr(d.attrs, sh_order);
    const auto* L = a ? std::get_if<int64_t>(&a->value) : nullptr;
    if (L == nullptr)
      fail("dataset '" + d.path + "' lacks the integer attribute '" + sh_order + "' (number of bands L)");
    if (*L < 1 || *L > 65535)
      fail("dataset '" + d.path + "' has " + sh_order + " " + std::to_string(*L) +
           "; the number of bands must be in 1..65535");
    return static_cast<uint64_t>(*L);
  }

  // The texels [H, W] of the lightmap of vertex set `prefix`: the shape of its /lightmap/state,
  // which every lightmap dataset `d` needs beside it.
  std::vector<uint64_t> texels(const File& file, const std::string& prefix, const Dataset& d) const {
    const std::string path = prefix + std::string(N::kLightmapState);
    const Dataset* state = find_dataset(file, path);
    if (state == nullptr) fail("dataset '" + d.path + "' needs " + path + " beside it (it defines the texels H x W)");
    if (state->shape.size() != 2 || state->shape[0] == 0 || state->shape[1] == 0)
      fail("dataset '" + path + "' has shape " + shape_str(state->shape) + "; expected [H, W] with H, W >= 1");
    return state->shape;
  }

  // The lights an area-light dataset names (its `lights` attribute): at least one, each once,
  // each one of the file's /lights.
  std::vector<std::string> light_list(const Dataset& d, const std::set<std::string>& lights) const {
    const std::string attr(N::kLightOrder);
    const Attr* a = find_attr(d.attrs, attr);
    const auto* list = a ? std::get_if<std::string>(&a->value) : nullptr;
    if (list == nullptr)
      fail("dataset '" + d.path + "' lacks the string attribute '" + attr + "' (its lights' names, one per line)");
    const std::vector<std::string> names = split_light_list(*list);
    if (names.empty()) fail("dataset '" + d.path + "' names no light in its attribute '" + attr + "'");
    std::set<std::string_view> seen;
    for (const std::string& name : names) {
      if (!lights.count(name))
        fail("dataset '" + d.path + "' names light '" + name + "', which is not in " + std::string(N::kLights));
      if (!seen.insert(name).second) fail("dataset '" + d.path + "' names light '" + name + "' twice");
    }
    return names;
  }

  // The file's area lights (/lights/<name>): each with its three datasets, faces indexing its
  // vertices, and its group's shape, radiance and two_sided. Returns their names.
  std::set<std::string> lights(const File& file, const std::set<std::string_view>& paths, int64_t version) const {
    std::set<std::string> names;
    const std::string dir = std::string(N::kLights) + "/";
    for (const Dataset& d : file.datasets)
      if (d.path.starts_with(dir)) names.insert(d.path.substr(dir.size(), d.path.find('/', dir.size()) - dir.size()));
    std::set<std::string> punctual;
    for (const auto& [g, list] : file.group_attrs)
      if (g.starts_with(dir) && g.find('/', dir.size()) == std::string::npos) {
        const std::string name = g.substr(dir.size());
        if (is_punctual_group(g, list)) {
          if (names.count(name)) fail("punctual light '" + g + "' has datasets: a point, spot or directional light has none");
          punctual.insert(name);
        } else if (!names.count(name)) {
          fail("group '" + g + "' has no '" + std::string(N::kLightVertices) + "' dataset: a light needs its geometry");
        }
      }
    if ((!names.empty() || !punctual.empty()) && version < 3)
      fail("the file has " + std::string(N::kLights) + ", which needs format_version 3");
    if (!punctual.empty() && version < 6)
      fail("the file has punctual lights in " + std::string(N::kLights) + ", which need format_version 6 (the file says " +
           std::to_string(version) + ")");
    for (const std::string& name : punctual) punctual_light(*find_group_attrs(file, dir + name), dir + name);
    for (const std::string& name : names) {
      const std::string g = dir + name;
      for (std::string_view leaf : {N::kLightVertices, N::kLightFaceSizes, N::kLightFaceIndices})
        if (!paths.count(g + "/" + std::string(leaf)))
          fail("light '" + g + "' lacks the dataset '" + std::string(leaf) + "'");
      const Dataset& vertices = *find_dataset(file, g + "/" + std::string(N::kLightVertices));
      const Dataset& sizes = *find_dataset(file, g + "/" + std::string(N::kLightFaceSizes));
      const Dataset& indices = *find_dataset(file, g + "/" + std::string(N::kLightFaceIndices));
      if (vertices.shape.empty() || sizes.data.index() != 1 || indices.data.index() != 1) continue;  // the dataset rules say why
      uint64_t total = 0;
      for (uint32_t size : std::get<std::vector<uint32_t>>(sizes.data)) {
        if (size < 3) fail("dataset '" + sizes.path + "' has a face of " + std::to_string(size) + " vertices; a face has >= 3");
        total += size;
      }
      if (total != element_count(indices.data))
        fail("dataset '" + indices.path + "' has " + std::to_string(element_count(indices.data)) +
             " indices but the face sizes add up to " + std::to_string(total));
      for (uint32_t i : std::get<std::vector<uint32_t>>(indices.data))
        if (i >= vertices.shape[0])
          fail("dataset '" + indices.path + "' has vertex index " + std::to_string(i) + " >= N = " +
               std::to_string(vertices.shape[0]));
      const std::vector<Attr>* attrs = find_group_attrs(file, g);
      if (attrs == nullptr) fail("light '" + g + "' lacks its attributes (shape, radiance, two_sided)");
      if (required_string(*attrs, N::kShape, "group '" + g + "'").empty())
        fail("attribute '" + std::string(N::kShape) + "' of group '" + g + "' is empty");
      const Attr* radiance = find_attr(*attrs, N::kRadiance);
      const auto* rgb = radiance ? std::get_if<std::vector<double>>(&radiance->value) : nullptr;
      if (rgb == nullptr || rgb->size() != 3 || !std::all_of(rgb->begin(), rgb->end(), [](double x) { return x >= 0; }))
        fail("group '" + g + "' needs attribute '" + std::string(N::kRadiance) + "': 3 doubles >= 0 (RGB)");
      const Attr* two = find_attr(*attrs, N::kTwoSided);
      const auto* t = two ? std::get_if<int64_t>(&two->value) : nullptr;
      if (t == nullptr || (*t != 0 && *t != 1))
        fail("group '" + g + "' needs attribute '" + std::string(N::kTwoSided) + "': the integer 0 or 1");
    }
    names.insert(punctual.begin(), punctual.end());
    return names;
  }

  // A punctual light's attributes (v6): its shape, radiance (its intensity) >= 0, position (point,
  // spot), a non-zero direction (spot, directional), the spot's cones 0 <= inner < outer <= pi/2.
  void punctual_light(const std::vector<Attr>& attrs, const std::string& g) const {
    const std::string shape = required_string(attrs, N::kShape, "group '" + g + "'");
    auto vec3 = [&](std::string_view name, const char* what) {
      const Attr* a = find_attr(attrs, name);
      const auto* v = a ? std::get_if<std::vector<double>>(&a->value) : nullptr;
      if (v == nullptr || v->size() != 3 || !std::all_of(v->begin(), v->end(), [](double x) { return std::isfinite(x); }))
        fail("group '" + g + "' (a " + shape + " light) needs attribute '" + std::string(name) + "': " + what);
      return *v;
    };
    auto number = [&](std::string_view name) {
      const Attr* a = find_attr(attrs, name);
      const auto* v = a ? std::get_if<double>(&a->value) : nullptr;
      if (v == nullptr || !std::isfinite(*v))
        fail("group '" + g + "' (a spot light) needs attribute '" + std::string(name) + "': a finite double (radians)");
      return *v;
    };
    const std::vector<double> rgb = vec3(N::kRadiance, "3 doubles >= 0 (its intensity, RGB)");
    if (!std::all_of(rgb.begin(), rgb.end(), [](double x) { return x >= 0; }))
      fail("group '" + g + "' needs attribute '" + std::string(N::kRadiance) + "': 3 doubles >= 0 (its intensity, RGB)");
    if (shape != "directional") vec3(N::kPosition, "3 finite doubles (world space)");
    if (shape != "point") {
      const std::vector<double> d = vec3(N::kDirection, "3 finite doubles, a unit vector");
      if (!(d[0] * d[0] + d[1] * d[1] + d[2] * d[2] > 0)) fail("group '" + g + "' has a zero direction");
    }
    if (shape == "spot") {
      const double inner = number(N::kInnerConeAngle), outer = number(N::kOuterConeAngle);
      if (!(inner >= 0 && inner < outer && outer <= std::numbers::pi / 2 + 1e-12))
        fail("group '" + g + "' needs 0 <= inner_cone_angle < outer_cone_angle <= pi/2");
    }
    if (const Attr* a = find_attr(attrs, N::kRange)) {
      const auto* v = std::get_if<double>(&a->value);
      if (shape == "directional") fail("group '" + g + "' (a directional light) has a '" + std::string(N::kRange) + "': only point and spot lights have one");
      if (v == nullptr || !std::isfinite(*v) || !(*v > 0))
        fail("group '" + g + "' has attribute '" + std::string(N::kRange) + "' that is not a finite double > 0");
    }
  }

  const std::string file_;
};

bool is_area_light_kind(Kind k) {
  return k == Kind::area_irradiance || k == Kind::area_sh || k == Kind::light_vertices || k == Kind::light_face_sizes ||
         k == Kind::light_face_indices || k == Kind::lightmap_area_irradiance || k == Kind::lightmap_area_sh;
}

} // namespace

std::vector<std::string> split_light_list(std::string_view list) {
  std::vector<std::string> out;
  if (list.empty()) return out;
  for (std::size_t i = 0;;) {
    const std::size_t j = list.find('\n', i);
    out.emplace_back(list.substr(i, j == std::string_view::npos ? std::string_view::npos : j - i));
    if (j == std::string_view::npos) return out;
    i = j + 1;
  }
}

std::string join_light_list(const std::vector<std::string>& names) {
  std::string s;
  for (std::size_t i = 0; i < names.size(); ++i) s += (i ? "\n" : "") + names[i];
  return s;
}

DatasetKind dataset_kind(std::string_view path) {
  return path.size() >= 2 && path[0] == '/' ? Checker::classify(path) : Kind::unknown;
}

bool is_lightmap_kind(DatasetKind kind) {
  switch (kind) {
  case Kind::uv: case Kind::lightmap_state: case Kind::lightmap_positions: case Kind::lightmap_normals:
  case Kind::lightmap_ao: case Kind::lightmap_transfer_diffuse: case Kind::lightmap_transfer_visibility:
  case Kind::lightmap_radiance_band1: case Kind::lightmap_radiance_shadowed:
  case Kind::lightmap_area_irradiance: case Kind::lightmap_area_sh:
    return true;
  default:
    return false;
  }
}

int64_t written_format_version(const File& file) {
  // Version 9: an FIV occluder's self-shadows at its object's vertices.
  if (std::any_of(file.datasets.begin(), file.datasets.end(),
                  [](const Dataset& d) { return dataset_kind(d.path) == Kind::occluder_self_band1; }))
    return kFormatVersionWithSelfShadows;
  // Version 8: float16 datasets (an occluder's shells or cones).
  if (std::any_of(file.datasets.begin(), file.datasets.end(), [](const Dataset& d) { return d.data.index() == 4; }))
    return kFormatVersionWithHalfShells;
  // Version 7: surface-following FIV shells (a surface_radius dataset, or the shells' radial_scheme
  // or first_offset attribute).
  if (std::any_of(file.datasets.begin(), file.datasets.end(), [](const Dataset& d) {
        const Kind k = dataset_kind(d.path);
        return k == Kind::occluder_surface_radius ||
               (k == Kind::occluder_shells &&
                (find_attr(d.attrs, N::kRadialScheme) != nullptr || find_attr(d.attrs, N::kFirstOffset) != nullptr));
      }))
    return kFormatVersionWithCones;
  const bool cones = std::any_of(file.datasets.begin(), file.datasets.end(),
                                 [](const Dataset& d) { return dataset_kind(d.path) == Kind::occluder_cones; }) ||
                     std::any_of(file.group_attrs.begin(), file.group_attrs.end(),
                                 [](const auto& g) { return find_attr(g.second, N::kProxy) != nullptr; });
  if (cones) return kFormatVersionWithCones;
  if (std::any_of(file.group_attrs.begin(), file.group_attrs.end(),
                  [](const auto& g) { return is_punctual_group(g.first, g.second); }))
    return kFormatVersionWithPunctualLights;
  const bool lightmap = std::any_of(file.datasets.begin(), file.datasets.end(),
                                    [](const Dataset& d) { return is_lightmap_kind(dataset_kind(d.path)); });
  return lightmap ? kFormatVersionWithLightmaps : kFormatVersionWithoutLightmaps;
}

bool is_per_vertex_path(std::string_view path) {
  if (path.size() < 2 || path[0] != '/') return false;
  std::string prefix;
  switch (Checker::classify(path, &prefix)) {
  case Kind::positions: case Kind::normals: case Kind::source_position: case Kind::ao:
  case Kind::transfer_diffuse: case Kind::transfer_visibility: case Kind::radiance_band1:
  case Kind::radiance_shadowed: case Kind::area_irradiance: case Kind::area_sh:
    return true;
  default:
    return false;
  }
}

std::string vertex_set_of(std::string_view path) {
  std::string prefix;
  if (path.size() >= 2 && path[0] == '/') (void)Checker::classify(path, &prefix);
  return prefix;
}

void validate(const File& file, const std::filesystem::path& file_for_messages) {
  const Checker c(file_for_messages);
  c.root(file.root_attrs);

  // Paths: absolute, well-formed, unique, known, and no dataset lies under another dataset.
  std::set<std::string_view> paths;
  std::vector<Kind> kinds;
  std::vector<std::string> prefixes;  // vertex set of each dataset ("" or "/objects/<name>")
  int64_t version = kFormatVersion;
  if (const Attr* v = find_attr(file.root_attrs, N::kFormatVersion))
    if (const auto* i = std::get_if<int64_t>(&v->value)) version = *i;
  for (const Dataset& d : file.datasets) {
    if (d.path.size() < 2 || d.path[0] != '/' || d.path.back() == '/')
      c.fail("dataset path '" + d.path + "' must be absolute, like \"" + std::string(N::kPositions) + "\"");
    const auto parts = split_path(d.path);
    for (std::string_view part : parts)
      if (!valid_component(part))
        c.fail("dataset path '" + d.path + "' has an invalid component '" + std::string(part) + "'");
    if (!paths.insert(d.path).second) c.fail("dataset '" + d.path + "' is given twice");
    std::string prefix;
    const Kind k = Checker::classify(d.path, &prefix);
    if (k == Kind::unknown)
      c.fail("unknown dataset path '" + d.path + "' (schema v5 allows " + allowed_paths() + ")");
    if (!prefix.empty() && version < 2)
      c.fail("dataset '" + d.path + "' is a scene object's, which needs format_version 2 (the file says " +
             std::to_string(version) + ")");
    if (is_area_light_kind(k) && version < 3)
      c.fail("dataset '" + d.path + "' is an area light's, which needs format_version 3 (the file says " +
             std::to_string(version) + ")");
    if (k == Kind::radiance_shadowed && version < 4)
      c.fail("dataset '" + d.path + "' is shadowed radiance, which needs format_version 4 (the file says " +
             std::to_string(version) + ")");
    if (is_lightmap_kind(k) && version < 5)
      c.fail("dataset '" + d.path + "' is a lightmap's, which needs format_version 5 (the file says " +
             std::to_string(version) + ")");
    if (k == Kind::occluder_surface_radius && version < 7)
      c.fail("dataset '" + d.path + "' is a surface-following shell grid's, which needs format_version 7 (the file says " +
             std::to_string(version) + ")");
    if (d.data.index() == 4 && k != Kind::occluder_shells && k != Kind::occluder_cones)
      c.fail("dataset '" + d.path + "' is float16, which the schema allows only for an occluder's shells and cones");
    if (d.data.index() == 4 && version < 8)
      c.fail("dataset '" + d.path + "' is float16, which needs format_version 8 (the file says " + std::to_string(version) +
             ")");
    if (k == Kind::occluder_self_band1 && version < 9)
      c.fail("dataset '" + d.path + "' is an occluder's self-shadows, which needs format_version 9 (the file says " +
             std::to_string(version) + ")");
    if (k == Kind::occluder_cones && version < 7)
      c.fail("dataset '" + d.path + "' is an occluder's cone table, which needs format_version 7 (the file says " +
             std::to_string(version) + ")");
    kinds.push_back(k);
    prefixes.push_back(std::move(prefix));
  }
  for (const Dataset& d : file.datasets)
    for (std::size_t slash = d.path.find('/', 1); slash != std::string::npos;
         slash = d.path.find('/', slash + 1))
      if (paths.count(std::string_view(d.path).substr(0, slash)))
        c.fail("dataset '" + d.path + "' lies under dataset '" + d.path.substr(0, slash) + "'");

  // Generic per-dataset rules: rank, size, finiteness, attributes.
  for (const Dataset& d : file.datasets) {
    if (d.shape.empty() || d.shape.size() > kMaxRank)
      c.fail("dataset '" + d.path + "' must have 1 to 32 dimensions, not " +
             std::to_string(d.shape.size()));
    uint64_t n = 0;
    try {
      n = shape_product(d.shape);
    } catch (const FormatError&) {
      c.fail("dataset '" + d.path + "' has a shape whose size overflows: " + shape_str(d.shape));
    }
    if (n != element_count(d.data))
      c.fail("dataset '" + d.path + "' has " + std::to_string(element_count(d.data)) +
             " values but shape " + shape_str(d.shape) + " needs " + std::to_string(n));
    std::visit(
        [&]<class T>(const std::vector<T>& f) {
          if constexpr (std::is_floating_point_v<T>) {
            for (std::size_t i = 0; i < f.size(); ++i)
              if (!std::isfinite(f[i]))
                c.fail("dataset '" + d.path + "' has a non-finite value (" +
                       (std::isnan(f[i]) ? std::string("NaN") : std::string("Inf")) + ") at index " +
                       std::to_string(i) + " " + index_str(i, d.shape));
          } else if constexpr (std::is_same_v<T, Float16>) {
            for (std::size_t i = 0; i < f.size(); ++i)
              if ((f[i].bits & 0x7c00u) == 0x7c00u)  // exponent all ones: ±inf or NaN
                c.fail("dataset '" + d.path + "' has a non-finite value (" +
                       ((f[i].bits & 0x3ffu) != 0 ? std::string("NaN") : std::string("Inf")) + ") at index " +
                       std::to_string(i) + " " + index_str(i, d.shape));
          }
        },
        d.data);
    c.attrs(d.attrs, "dataset '" + d.path + "'");
  }

  // Schema rules per known dataset. Each vertex set (the root layout, or one scene object under
  // /objects/<name>) has its own V = rows of its mesh/positions, and its lightmap its own texels
  // H x W = the shape of its lightmap/state; a product's values run along [V] per vertex and
  // along [H, W] per texel, followed by the same axes of its own.
  struct VertexSet {
    const Dataset* positions = nullptr;
    uint64_t V = 0;
    bool has_normals = false;
  };
  auto vertex_set = [&](const std::string& prefix) {
    VertexSet v;
    v.positions = find_dataset(file, prefix + std::string(N::kPositions));
    v.V = v.positions && !v.positions->shape.empty() ? v.positions->shape[0] : 0;
    v.has_normals = find_dataset(file, prefix + std::string(N::kNormals)) != nullptr;
    return v;
  };
  const std::set<std::string> light_names = c.lights(file, paths, version);
  std::map<std::string, const Dataset*> shells;  // occluder dir -> shells
  for (std::size_t i = 0; i < file.datasets.size(); ++i) {
    const Dataset& d = file.datasets[i];
    const Kind k = kinds[i];
    const std::string& prefix = prefixes[i];
    const VertexSet vs = vertex_set(prefix);
    const Dataset* positions = vs.positions;
    const uint64_t V = vs.V;
    const std::string mesh_positions = prefix + std::string(N::kPositions);
    if (is_per_vertex_path(d.path) && positions == nullptr)
      c.fail("dataset '" + d.path + "' is per-vertex but the file has no " + mesh_positions + " to " +
             "define the vertex count V");
    const bool texel = is_lightmap_kind(k) && k != Kind::uv;
    const std::vector<uint64_t> rows = texel ? c.texels(file, prefix, d) : std::vector<uint64_t>{V};
    const std::string rows_rule = texel ? "H, W" : "V";
    const auto rows_and = [&rows](std::initializer_list<uint64_t> own) {
      std::vector<uint64_t> s = rows;
      s.insert(s.end(), own);
      return s;
    };
    const std::string uv = prefix + std::string(N::kUv);
    if (texel && find_dataset(file, uv) == nullptr)
      c.fail("dataset '" + d.path + "' needs " + uv + " (the UV set its texels lie in)");
    switch (k) {
    case Kind::positions:  // float32, or float64 where float32 would lose precision (SCHEMA.md)
    case Kind::lightmap_positions:
      if (d.data.index() != 3) c.dtype(d, 0);
      c.shape(d, rows_and({3}), "[" + rows_rule + ", 3]");
      break;
    case Kind::normals:
    case Kind::lightmap_normals:
      c.dtype(d, 0);
      c.shape(d, rows_and({3}), "[" + rows_rule + ", 3]");
      break;
    case Kind::uv: {
      const std::string triangles = prefix + std::string(N::kTriangles);
      const Dataset* t = find_dataset(file, triangles);
      if (t == nullptr) c.fail("dataset '" + d.path + "' needs " + triangles + " (it holds a UV per triangle corner)");
      c.dtype(d, 0);
      c.shape(d, {t->shape[0], 3, 2}, "[T, 3 (corners), 2 (u, v)] with T = rows of " + triangles);
      break;
    }
    case Kind::lightmap_state: {  // its shape: texels()
      c.dtype(d, 2);
      const auto& state = std::get<std::vector<uint8_t>>(d.data);
      for (std::size_t j = 0; j < state.size(); ++j)
        if (state[j] > 3)
          c.fail("dataset '" + d.path + "' has state " + std::to_string(state[j]) + " at index " + std::to_string(j) +
                 " " + index_str(j, d.shape) + "; a texel is 0 (empty), 1 (baked), 2 (filled) or 3 (padding)");
      break;
    }
    case Kind::triangles: {
      if (positions == nullptr)
        c.fail("dataset '" + d.path + "' needs " + mesh_positions + " (its indices refer to it)");
      c.dtype(d, 1);
      if (d.shape.size() != 2 || d.shape[1] != 3)
        c.fail("dataset '" + d.path + "' has shape " + shape_str(d.shape) + "; expected [T, 3]");
      const auto& idx = std::get<std::vector<uint32_t>>(d.data);
      for (std::size_t j = 0; j < idx.size(); ++j)
        if (idx[j] >= V)
          c.fail("dataset '" + d.path + "' has vertex index " + std::to_string(idx[j]) +
                 " >= V = " + std::to_string(V) + " at index " + std::to_string(j) + " " +
                 index_str(j, d.shape));
      break;
    }
    case Kind::source_position:
      c.dtype(d, 1);
      c.shape(d, {V}, "[V]");
      break;
    case Kind::ao:
    case Kind::lightmap_ao:
      c.dtype(d, 0);
      c.shape(d, rows, "[" + rows_rule + "]");
      break;
    case Kind::transfer_diffuse:
    case Kind::transfer_visibility:
    case Kind::lightmap_transfer_diffuse:
    case Kind::lightmap_transfer_visibility: {
      c.dtype(d, 0);
      const uint64_t L = c.sh_order(d);
      c.shape(d, rows_and({L * L}), "[" + rows_rule + ", L*L] with L = " + std::string(N::kShOrder) + " = " + std::to_string(L));
      break;
    }
    case Kind::area_irradiance:
    case Kind::area_sh:
    case Kind::lightmap_area_irradiance:
    case Kind::lightmap_area_sh: {
      c.dtype(d, 0);
      const auto L = uint64_t(c.light_list(d, light_names).size());
      if (k == Kind::area_irradiance || k == Kind::lightmap_area_irradiance) {
        c.shape(d, rows_and({L}), "[" + rows_rule + ", L] with L = the lights named in '" + std::string(N::kLightOrder) + "'");
        break;
      }
      const uint64_t n = c.sh_order(d);
      c.shape(d, rows_and({L, n * n}), "[" + rows_rule + ", L, n*n] with L = the lights named in '" +
                                           std::string(N::kLightOrder) + "' and n = " + std::string(N::kShOrder) + " = " +
                                           std::to_string(n));
      const std::string irradiance =
          prefix + std::string(k == Kind::area_sh ? N::kAreaIrradiance : N::kLightmapAreaIrradiance);
      const Dataset* e = find_dataset(file, irradiance);
      const Attr* mine = find_attr(d.attrs, N::kLightOrder);
      const Attr* its = e ? find_attr(e->attrs, N::kLightOrder) : nullptr;
      if (its == nullptr || its->value != mine->value)
        c.fail("dataset '" + d.path + "' needs '" + irradiance + "' beside it, naming the same lights in the same order");
      break;
    }
    case Kind::light_vertices:
      c.dtype(d, 3);
      if (d.shape.size() != 2 || d.shape[1] != 3 || d.shape[0] < 3)
        c.fail("dataset '" + d.path + "' has shape " + shape_str(d.shape) + "; expected [N, 3] with N >= 3");
      break;
    case Kind::light_face_sizes:
      c.dtype(d, 1);
      if (d.shape.size() != 1 || d.shape[0] == 0)
        c.fail("dataset '" + d.path + "' has shape " + shape_str(d.shape) + "; expected [F] with F >= 1");
      break;
    case Kind::light_face_indices:
      c.dtype(d, 1);
      if (d.shape.size() != 1) c.fail("dataset '" + d.path + "' has shape " + shape_str(d.shape) + "; expected [K]");
      break;
    case Kind::radiance_band1:
    case Kind::lightmap_radiance_band1:
      c.dtype(d, 0);
      c.shape(d, rows_and({3, 3}), "[" + rows_rule + ", 3 (RGB), 3 (m = -1, 0, 1)]");
      break;
    case Kind::radiance_shadowed:
    case Kind::lightmap_radiance_shadowed: {
      c.dtype(d, 0);
      const uint64_t L = c.sh_order(d);
      c.shape(d, rows_and({3, L * L}),
              "[" + rows_rule + ", 3 (RGB), L*L] with L = " + std::string(N::kShOrder) + " = " + std::to_string(L));
      break;
    }
    case Kind::fiv_environment:
      c.dtype(d, 0);
      c.shape(d, {3, 3}, "[3 (RGB), 3 (xyz)]");
      break;
    case Kind::irradiance_cube:
      c.dtype(d, 0);
      if (d.shape.size() != 4 || d.shape[0] != 6 || d.shape[1] != d.shape[2] || d.shape[1] == 0 ||
          d.shape[3] != 3)
        c.fail("dataset '" + d.path + "' has shape " + shape_str(d.shape) +
               "; expected [6, S, S, 3] with S >= 1");
      break;
    case Kind::occluder_shells: {
      c.dtype(d, d.data.index() == 4 ? 4 : 0);  // float32, or float16 (v8, checked above)
      if (d.shape.size() != 5 || d.shape[3] != 3 || d.shape[4] != 3 || d.shape[0] == 0 ||
          d.shape[1] == 0 || d.shape[2] == 0)
        c.fail("dataset '" + d.path + "' has shape " + shape_str(d.shape) +
               "; expected [Nr, Ntheta, Nphi, 3 (RGB), 3 (xyz)] with Nr, Ntheta, Nphi >= 1");
      const Attr* centre = find_attr(d.attrs, N::kCentre);
      const auto* cv = centre ? std::get_if<std::vector<double>>(&centre->value) : nullptr;
      if (cv == nullptr || cv->size() != 3)
        c.fail("dataset '" + d.path + "' needs attribute '" + std::string(N::kCentre) + "': 3 doubles (bounding-sphere centre)");
      const Attr* radius = find_attr(d.attrs, N::kRadius);
      const auto* r = radius ? std::get_if<double>(&radius->value) : nullptr;
      if (r == nullptr || !(*r > 0))
        c.fail("dataset '" + d.path + "' needs attribute '" + std::string(N::kRadius) + "': a double > 0 (bounding-sphere radius)");
      const Attr* radii = find_attr(d.attrs, N::kRadii);
      const auto* rv = radii ? std::get_if<std::vector<double>>(&radii->value) : nullptr;
      if (rv == nullptr || rv->size() != d.shape[0])
        c.fail("dataset '" + d.path + "' needs attribute '" + std::string(N::kRadii) + "': Nr = " +
               std::to_string(d.shape[0]) + " doubles (shell radii)");
      shells[d.path.substr(0, d.path.size() - N::kShells.size())] = &d;  // the occluder's directory + "/"
      const Attr* scheme = find_attr(d.attrs, N::kRadialScheme);
      const Attr* first = find_attr(d.attrs, N::kFirstOffset);
      if ((scheme || first) && version < 7)
        c.fail("dataset '" + d.path + "' has attribute '" + std::string(scheme ? N::kRadialScheme : N::kFirstOffset) +
               "', which needs format_version 7 (the file says " + std::to_string(version) + ")");
      const auto* sv = scheme ? std::get_if<std::string>(&scheme->value) : nullptr;
      if (scheme && (sv == nullptr || (*sv != "geometric" && *sv != "surface")))
        c.fail("dataset '" + d.path + "' attribute '" + std::string(N::kRadialScheme) +
               "' must be the string \"geometric\" or \"surface\"");
      const auto* fv = first ? std::get_if<double>(&first->value) : nullptr;
      if (first && (fv == nullptr || !(*fv > 0) || !std::isfinite(*fv)))
        c.fail("dataset '" + d.path + "' attribute '" + std::string(N::kFirstOffset) + "' must be a finite double > 0");
      for (std::size_t q = 0; rv && sv && *sv == "surface" && q < rv->size(); ++q)
        if (!((*rv)[q] > 0) || !std::isfinite((*rv)[q]) || (q > 0 && !((*rv)[q] > (*rv)[q - 1])))
          c.fail("dataset '" + d.path + "' attribute '" + std::string(N::kRadii) +
                 "' (offsets from the surface) must be finite, > 0 and increasing");
      const bool surface = sv && *sv == "surface";
      const std::string surface_path = d.path.substr(0, d.path.size() - N::kShells.size()) + std::string(N::kSurfaceRadius);
      const bool has_surface = std::any_of(file.datasets.begin(), file.datasets.end(),
                                           [&](const Dataset& e) { return e.path == surface_path; });
      if (surface != has_surface)
        c.fail(surface ? "dataset '" + d.path + "' has radial_scheme \"surface\" but no '" + surface_path + "' beside it"
                       : "dataset '" + surface_path + "' needs radial_scheme \"surface\" on '" + d.path + "'");
      break;
    }
    case Kind::occluder_surface_radius:
      break;
    case Kind::occluder_valid:
    case Kind::occluder_cones:
    case Kind::occluder_self_band1:
    case Kind::report:
    case Kind::unknown:
      break;
    }
  }
  for (std::size_t i = 0; i < file.datasets.size(); ++i) {
    const Dataset& d = file.datasets[i];
    if (kinds[i] != Kind::occluder_surface_radius) continue;
    c.dtype(d, 0);
    const auto it = shells.find(d.path.substr(0, d.path.size() - N::kSurfaceRadius.size()));
    if (it == shells.end())
      c.fail("dataset '" + d.path + "' has no '" + std::string(N::kShells) + "' dataset beside it");
    const auto& s = it->second->shape;
    c.shape(d, {s[1], s[2]}, "[Ntheta, Nphi] of its shells");
    const auto& r = std::get<std::vector<float>>(d.data);
    for (std::size_t j = 0; j < r.size(); ++j)
      if (!std::isfinite(r[j]) || r[j] < 0)
        c.fail("dataset '" + d.path + "' must hold finite distances >= 0, not " + std::to_string(r[j]) + " at index " +
               std::to_string(j));
  }
  for (std::size_t i = 0; i < file.datasets.size(); ++i) {
    const Dataset& d = file.datasets[i];
    if (kinds[i] != Kind::occluder_self_band1) continue;
    c.dtype(d, 0);
    const std::string dir = d.path.substr(0, d.path.size() - N::kSelfBand1.size());  // "/fiv/occluders/<name>/"
    if (shells.find(dir) == shells.end())
      c.fail("dataset '" + d.path + "' has no '" + std::string(N::kShells) + "' dataset beside it");
    const std::string name = dir.substr(N::kOccluders.size() + 1, dir.size() - N::kOccluders.size() - 2);
    const std::string object = std::string(N::kObjects) + "/" + name;
    const VertexSet vs = vertex_set(object);
    if (vs.positions == nullptr)
      c.fail("dataset '" + d.path + "' holds the self-shadows of scene object '" + name + "', but the file has no " + object +
             std::string(N::kPositions));
    if (!vs.has_normals)
      c.fail("dataset '" + d.path + "' needs " + object + std::string(N::kNormals) + " (the normals the bake used)");
    c.shape(d, {vs.V, 3, 3}, "[V, 3 (RGB), 3 (m)] with V = rows of " + object + std::string(N::kPositions));
  }
  for (std::size_t i = 0; i < file.datasets.size(); ++i) {
    const Dataset& d = file.datasets[i];
    if (kinds[i] != Kind::occluder_cones) continue;
    c.dtype(d, d.data.index() == 4 ? 4 : 0);  // float32, or float16 (v8, checked above)
    const auto it = shells.find(d.path.substr(0, d.path.size() - N::kCones.size()));
    if (it == shells.end())
      c.fail("dataset '" + d.path + "' has no '" + std::string(N::kShells) + "' dataset beside it");
    const auto& s = it->second->shape;
    c.shape(d, {s[0], s[1], s[2], 4}, "[Nr, Ntheta, Nphi] of its shells, 4 (m_x, m_y, m_z, solid angle)");
  }
  for (std::size_t i = 0; i < file.datasets.size(); ++i) {
    const Dataset& d = file.datasets[i];
    if (kinds[i] != Kind::occluder_valid) continue;
    c.dtype(d, 2);
    const auto it = shells.find(d.path.substr(0, d.path.size() - N::kValid.size()));
    if (it == shells.end())
      c.fail("dataset '" + d.path + "' has no '" + std::string(N::kShells) + "' dataset beside it");
    const auto& s = it->second->shape;
    c.shape(d, {s[0], s[1], s[2]}, "[Nr, Ntheta, Nphi] of its shells");
    for (std::size_t j = 0; j < std::get<std::vector<uint8_t>>(d.data).size(); ++j)
      if (std::get<std::vector<uint8_t>>(d.data)[j] > 1)
        c.fail("dataset '" + d.path + "' must hold 0 or 1, not " +
               std::to_string(std::get<std::vector<uint8_t>>(d.data)[j]) + " at index " +
               std::to_string(j));
  }
  for (std::size_t i = 0; i < file.datasets.size(); ++i)
    if ((kinds[i] == Kind::ao || kinds[i] == Kind::transfer_diffuse || kinds[i] == Kind::transfer_visibility ||
         kinds[i] == Kind::radiance_band1 || kinds[i] == Kind::radiance_shadowed || kinds[i] == Kind::area_irradiance ||
         kinds[i] == Kind::area_sh) &&
        !vertex_set(prefixes[i]).has_normals)
      c.fail("dataset '" + file.datasets[i].path + "' needs " + prefixes[i] + std::string(N::kNormals) +
             " (the normals the bake used)");

  // Group attributes: only on schema groups (or anything under /report), each group once.
  std::set<std::string_view> groups;
  for (const auto& [g, list] : file.group_attrs) {
    if (g.size() < 2 || g[0] != '/' || g.back() == '/')
      c.fail("group path '" + g + "' must be absolute, like \"" + std::string(N::kReport) +
             "\" (root attributes go in root_attrs)");
    const auto parts = split_path(g);
    for (std::string_view part : parts)
      if (!valid_component(part))
        c.fail("group path '" + g + "' has an invalid component '" + std::string(part) + "'");
    auto product_group = [](std::string_view x) {
      return x == N::kMeshGroup || x == N::kTransferGroup || x == N::kRadianceGroup || x == N::kAreaLightsGroup;
    };
    auto under = [&group = g](std::string_view dir) { return group.starts_with(std::string(dir) + "/"); };
    const bool object = g == N::kObjects || under(N::kObjects);
    const bool light = g == N::kLights || under(N::kLights);
    const bool ok = product_group(g) || g == N::kFivGroup || g == N::kScene || g == N::kObjects ||
                    (light && parts.size() <= 2) ||
                    g == N::kOccluders || (parts.size() == 3 && under(N::kOccluders)) ||
                    (object && parts.size() == 2) ||
                    (object && parts.size() == 3 && product_group("/" + std::string(parts[2]))) ||
                    g == N::kReport || under(N::kReport);
    if (!ok)
      c.fail("attributes on group '" + g + "' are not allowed (schema v3 allows them on " +
             std::string(N::kMeshGroup) + ", " + std::string(N::kTransferGroup) + ", " +
             std::string(N::kRadianceGroup) + ", " + std::string(N::kAreaLightsGroup) + ", " + std::string(N::kScene) +
             ", " + std::string(N::kObjects) + ", " + std::string(N::kObjects) + "/<name>[" +
             std::string(N::kMeshGroup) + "|" + std::string(N::kTransferGroup) + "|" + std::string(N::kRadianceGroup) +
             "|" + std::string(N::kAreaLightsGroup) + "], " + std::string(N::kLights) + ", " +
             std::string(N::kLights) + "/<name>, " +
             std::string(N::kFivGroup) + ", " + std::string(N::kOccluders) + ", " + std::string(N::kOccluders) +
             "/<name> and " + std::string(N::kReport) + "...)");
    if (object && version < 2)
      c.fail("group '" + g + "' is a scene object's, which needs format_version 2");
    if ((light || g.ends_with(N::kAreaLightsGroup)) && version < 3)
      c.fail("group '" + g + "' is an area light's, which needs format_version 3");
    if (const Attr* proxy = find_attr(list, N::kProxy)) {
      const bool occluder = under(N::kOccluders) && parts.size() == split_path(N::kOccluders).size() + 1;
      const auto* value = std::get_if<std::string>(&proxy->value);
      if (!occluder)
        c.fail("attribute '" + std::string(N::kProxy) + "' on group '" + g + "': only " + std::string(N::kOccluders) +
               "/<name> has one");
      if (value == nullptr || (*value != N::kProxySphere && *value != N::kProxyCone))
        c.fail("attribute '" + std::string(N::kProxy) + "' on group '" + g + "' must be the string \"" +
               std::string(N::kProxySphere) + "\" or \"" + std::string(N::kProxyCone) + "\"");
      if (version < 7)
        c.fail("attribute '" + std::string(N::kProxy) + "' on group '" + g + "' needs format_version 7 (the file says " +
               std::to_string(version) + ")");
      if (*value == N::kProxyCone && !paths.count(g + "/" + std::string(N::kCones)))
        c.fail("group '" + g + "' says proxy \"cone\" but has no '" + std::string(N::kCones) + "' dataset");
    }
    if (!groups.insert(g).second) c.fail("group '" + g + "' is given twice in group_attrs");
    if (paths.count(g)) c.fail("group '" + g + "' is also a dataset path");
    for (std::size_t slash = g.find('/', 1); slash != std::string::npos;
         slash = g.find('/', slash + 1))
      if (paths.count(std::string_view(g).substr(0, slash)))
        c.fail("group '" + g + "' lies under dataset '" + g.substr(0, slash) + "'");
    c.attrs(list, "group '" + g + "'");
  }
}

} // namespace prt::formats
