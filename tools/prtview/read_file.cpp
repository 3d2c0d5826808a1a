// prtview/read_file.cpp — reading a baked file for prtview (read_file.h).
#include "read_file.h"

#include <bake/error.h>
#include <bake/sha256.h>

#include <algorithm>
#include <filesystem>
#include <stdexcept>
#include <string_view>

namespace prt::prtview {

namespace F = prt::formats;
namespace fs = std::filesystem;
using bake::InputError;

namespace {

const std::vector<float>& floats(const F::File& f, const std::string& file, const std::string& path,
                                 const std::vector<uint64_t>& trailing) {
  const F::Dataset* d = F::find_dataset(f, path);
  if (!d) throw InputError(file, "no dataset " + path);
  const auto* v = std::get_if<std::vector<float>>(&d->data);
  if (!v) throw InputError(file, path + " is not float32");
  if (d->shape.size() < trailing.size() ||
      !std::equal(trailing.rbegin(), trailing.rend(), d->shape.rbegin(), [](uint64_t want, uint64_t have) {
        return want == 0 || want == have;
      }))
    throw InputError(file, path + " has an unexpected shape");
  return *v;
}

std::string string_attr(const std::vector<F::Attr>& attrs, std::string_view name) {
  const F::Attr* a = F::find_attr(attrs, name);
  if (!a) return {};
  const auto* s = std::get_if<std::string>(&a->value);
  return s ? *s : std::string();
}

const F::Attr& need_attr(const F::Dataset& d, std::string_view name, const std::string& file) {
  const F::Attr* a = F::find_attr(d.attrs, name);
  if (!a) throw InputError(file, d.path + " lacks the attribute '" + std::string(name) + "'");
  return *a;
}

// The environment the file was baked with must be the one we shade / reference with. `where` names
// the dataset or group whose attributes (environment, environment_sha256) say which it was.
void check_same_environment(const std::vector<F::Attr>& attrs, const std::string& where, const bake::EnvMap& env,
                            const std::string& file) {
  const std::string sha = string_attr(attrs, "environment_sha256");
  if (!sha.empty() && sha != env.info().sha256)
    throw InputError(env.info().source, "is not the environment " + file + " was baked with (" + where +
                                            " was baked under '" + string_attr(attrs, "environment") + "', SHA-256 " +
                                            sha.substr(0, 12) + "...)");
}
void check_same_environment(const F::Dataset& d, const bake::EnvMap& env, const std::string& file) {
  check_same_environment(d.attrs, d.path, env, file);
}

// `name` as given, else next to `beside` (a file), when that exists.
std::string found_beside(const std::string& name, const std::string& beside) {
  if (!fs::exists(name) && fs::exists(fs::path(beside).parent_path() / name)) return (fs::path(beside).parent_path() / name).string();
  return name;
}

} // namespace

bool is_scene_file(const F::File& f) {
  if (F::find_group_attrs(f, "/scene")) return true;
  return std::any_of(f.datasets.begin(), f.datasets.end(), [](const F::Dataset& d) { return d.path.starts_with("/objects/"); });
}
bool has_fiv(const F::File& f) { return F::find_dataset(f, "/fiv/irradiance_cube") != nullptr; }
bool has_transfer(const F::File& f) { return F::find_dataset(f, "/transfer/diffuse") != nullptr; }
bake::UpAxis up_axis(const F::File& f) { return string_attr(f.root_attrs, "up_axis") == "z" ? bake::UpAxis::Z : bake::UpAxis::Y; }

std::string baked_environment(const F::File& f, const std::string& file) {
  std::string env_path;
  const auto* scene_attrs = F::find_group_attrs(f, "/scene");
  if (is_scene_file(f) && scene_attrs) env_path = string_attr(*scene_attrs, "environment");
  for (const char* p : {"/fiv/irradiance_cube", "/radiance/band1"})
    if (const auto* d = F::find_dataset(f, p); d && env_path.empty()) env_path = string_attr(d->attrs, "environment");
  if (env_path.empty()) throw InputError(file, "holds no environment name: give one with --env ENV.exr");
  env_path = found_beside(env_path, file);
  if (const std::string sf = scene_attrs ? string_attr(*scene_attrs, "scene_file") : std::string(); !sf.empty())
    env_path = found_beside(env_path, sf);
  if (!fs::exists(env_path))
    throw InputError(env_path, "no such file (the environment " + file + " was baked with): give it with --env ENV.exr");
  return env_path;
}

bake::Mesh read_mesh(const F::File& f, const std::string& file, const std::string& prefix) {
  const auto& pos = floats(f, file, prefix + "/mesh/positions", {3});
  const auto& nrm = floats(f, file, prefix + "/mesh/normals", {3});
  const F::Dataset* td = F::find_dataset(f, prefix + "/mesh/triangles");
  if (!td) throw InputError(file, "no dataset " + prefix + "/mesh/triangles (nothing to rasterize)");
  const auto& tri = std::get<std::vector<uint32_t>>(td->data);
  const size_t V = pos.size() / 3;
  std::vector<Eigen::Vector3f> P(V), N(V);
  for (size_t i = 0; i < V; ++i) {
    P[i] = {pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]};
    N[i] = {nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2]};
  }
  std::vector<std::array<uint32_t, 3>> T(tri.size() / 3);
  for (size_t t = 0; t < T.size(); ++t) T[t] = {tri[3 * t], tri[3 * t + 1], tri[3 * t + 2]};
  return bake::make_mesh(std::move(P), std::move(T), prefix.empty() ? file : prefix.substr(9), std::move(N));
}

Transfer read_transfer(const F::File& f, const std::string& file, const std::string& prefix) {
  const std::string path = prefix + "/transfer/diffuse";
  const F::Dataset* d = F::find_dataset(f, path);
  if (!d) throw InputError(file, "no dataset " + path + (prefix.empty() ? " (try --shade band1)" : ""));
  return {int(std::get<int64_t>(need_attr(*d, "sh_order", file).value)), std::get<std::vector<float>>(d->data).data()};
}

Band1 read_band1(const F::File& f, const std::string& file, const std::string& prefix, const bake::EnvMap& env) {
  const std::string path = prefix + "/radiance/band1";
  const F::Dataset* d = F::find_dataset(f, path);
  if (!d) throw InputError(file, "no dataset " + path + (prefix.empty() ? " (try --shade transfer)" : ""));
  check_same_environment(*d, env, file);
  return {floats(f, file, prefix + "/mesh/normals", {3}).data(), std::get<std::vector<float>>(d->data).data()};
}

BakedOccluder read_occluder(const F::File& f, const std::string& file, const std::string& name, const bake::EnvMap& env) {
  const std::string dir = "/fiv/occluders/" + name;
  const F::Dataset* sd = F::find_dataset(f, dir + "/shells");
  if (!sd) throw InputError(file, "no dataset " + dir + "/shells");
  check_same_environment(*sd, env, file);
  const auto& shells = floats(f, file, dir + "/shells", {0, 0, 0, 3, 3});
  const F::Dataset* vd = F::find_dataset(f, dir + "/valid");
  if (!vd) throw InputError(file, "no dataset " + dir + "/valid");
  BakedOccluder b;
  b.centre = std::get<std::vector<double>>(need_attr(*sd, "centre", file).value);
  b.radius = std::get<double>(need_attr(*sd, "radius", file).value);
  const auto& radii_d = std::get<std::vector<double>>(need_attr(*sd, "radii", file).value);
  b.radii.assign(radii_d.begin(), radii_d.end());
  if (b.centre.size() != 3) throw InputError(file, dir + "/shells: 'centre' must hold 3 numbers");
  shade::FivOccluder& o = b.view;
  for (int c = 0; c < 3; ++c) o.centre[c] = float(b.centre[size_t(c)]);
  o.radius = float(b.radius);
  o.n_rho = int(sd->shape[0]);
  o.n_theta = int(sd->shape[1]);
  o.n_phi = int(sd->shape[2]);
  o.radii = b.radii.data();
  o.shells = shells.data();
  o.valid = std::get<std::vector<uint8_t>>(vd->data).data();
  if (b.radii.size() != sd->shape[0]) throw InputError(file, dir + "/shells: 'radii' must hold one radius per shell");
  try {
    shade::validate_occluder(o);
  } catch (const std::invalid_argument& e) {
    throw InputError(file, dir + ": " + e.what());
  }
  return b;  // moving the vector keeps its buffer: view.radii stays valid
}

std::string choose_occluder(const F::File& f, const std::string& file, const std::string& name) {
  std::vector<std::string> names;
  for (const auto& d : f.datasets) {
    const std::string pre = "/fiv/occluders/";
    if (d.path.rfind(pre, 0) == 0 && d.path.size() > pre.size() + 7 && d.path.ends_with("/shells"))
      names.push_back(d.path.substr(pre.size(), d.path.size() - pre.size() - 7));
  }
  if (names.empty()) throw InputError(file, "no /fiv/occluders/<name>/shells");
  if (name.empty()) {
    if (names.size() > 1) throw InputError(file, "holds several occluders: choose one with --occluder NAME");
    return names.front();
  }
  if (std::find(names.begin(), names.end(), name) == names.end()) throw InputError(file, "has no occluder '" + name + "'");
  return name;
}

namespace {
// The dataset at `path`, or nullptr when it is absent and not required.
const F::Dataset* optional_dataset(const F::File& f, const std::string& file, const std::string& path, bool required) {
  const F::Dataset* d = F::find_dataset(f, path);
  if (!d && required) throw InputError(file, "no dataset " + path);
  return d;
}
} // namespace

std::optional<shade::DifMap> read_difmap(const F::File& f, const std::string& file, const bake::EnvMap& env, bool required) {
  const F::Dataset* cd = optional_dataset(f, file, "/fiv/irradiance_cube", required);
  if (!cd) return std::nullopt;
  check_same_environment(*cd, env, file);
  const shade::DifMap map{int(cd->shape[1]), floats(f, file, cd->path, {6, 0, 0, 3}).data()};
  shade::validate_difmap(map);
  return map;
}

const float* read_environment_fiv(const F::File& f, const std::string& file, const bake::EnvMap& env, bool required) {
  const F::Dataset* d = optional_dataset(f, file, "/fiv/environment", required);
  if (!d) return nullptr;
  check_same_environment(*d, env, file);
  return floats(f, file, d->path, {3, 3}).data();
}

std::string occluder_mesh_path(const F::File& f, const std::string& file, const std::string& given) {
  std::string mesh_path = given;
  if (mesh_path.empty()) {
    mesh_path = found_beside(string_attr(f.root_attrs, "source"), file);
    if (!fs::exists(mesh_path))
      throw InputError(file, "the occluder mesh '" + mesh_path +
                                 "' (the file's 'source' attribute) does not exist: give it with --occluder-mesh");
  }
  const std::string want_sha = string_attr(f.root_attrs, "source_sha256");
  if (!want_sha.empty() && bake::sha256_file(mesh_path) != want_sha)
    throw InputError(mesh_path, "is not the mesh " + file + " was baked from (SHA-256 differs from its source_sha256)");
  return mesh_path;
}

std::vector<SceneObject> read_scene_objects(const F::File& f, const std::string& file, const bake::EnvMap& env) {
  if (const auto* sa = F::find_group_attrs(f, "/scene")) check_same_environment(*sa, "/scene", env, file);
  std::vector<std::string> names;
  const std::string pre = "/objects/", post = "/mesh/positions";
  for (const auto& d : f.datasets)
    if (d.path.starts_with(pre) && d.path.ends_with(post) && d.path.size() > pre.size() + post.size())
      names.push_back(d.path.substr(pre.size(), d.path.size() - pre.size() - post.size()));
  if (names.empty()) throw InputError(file, "is a scene file without objects (no /objects/<name>/mesh/positions)");
  const bool env_fiv = F::find_dataset(f, "/fiv/environment") != nullptr;
  std::vector<SceneObject> objects;
  for (const std::string& name : names) {
    SceneObject o;
    o.name = name;
    const std::string prefix = pre + name;
    const auto* attrs = F::find_group_attrs(f, prefix);
    o.role = attrs ? string_attr(*attrs, "role") : std::string();
    if (o.role != "receiver" && o.role != "occluder" && o.role != "both")
      throw InputError(file, prefix + " has no valid 'role' attribute (receiver, occluder or both)");
    o.receiver = o.role != "occluder";
    o.casts_shadow = o.role != "receiver";
    if (const F::Attr* al = F::find_attr(*attrs, "albedo")) {
      const auto* v = std::get_if<std::vector<double>>(&al->value);
      if (!v || v->size() != 3) throw InputError(file, prefix + ": 'albedo' must be 3 numbers");
      if ((*v)[0] > 0 || (*v)[1] > 0 || (*v)[2] > 0)
        for (size_t c = 0; c < 3; ++c) o.albedo[c] = float(std::max(0.0, (*v)[c]));
    }
    o.mesh = read_mesh(f, file, prefix);
    const bool band1 = F::find_dataset(f, prefix + "/radiance/band1"), transfer = F::find_dataset(f, prefix + "/transfer/diffuse");
    o.glossy_only = F::find_dataset(f, prefix + "/transfer/visibility") && !band1 && !transfer;
    // The per-vertex product the runtime shades it with: the first of band-1 radiance, transfer, AO.
    if (band1) o.band1 = read_band1(f, file, prefix, env);
    else if (transfer) o.transfer = read_transfer(f, file, prefix);
    else if (F::find_dataset(f, prefix + "/ao")) o.ao = &floats(f, file, prefix + "/ao", {});
    if (env_fiv && F::find_dataset(f, "/fiv/occluders/" + name + "/shells")) o.shells = read_occluder(f, file, name, env);
    objects.push_back(std::move(o));
  }
  return objects;
}

} // namespace prt::prtview
