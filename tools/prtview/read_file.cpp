// prtview/read_file.cpp — what prtview takes from a baked file's asset (read_file.h).
#include "read_file.h"

#include <bake/core/error.h>
#include <bake/core/sha256.h>
#include <formats/names.h>
#include <prtshade/shade.h>

#include <algorithm>
#include <filesystem>
#include <stdexcept>
#include <string_view>

namespace prt::prtview {

namespace F = prt::formats;
namespace N = prt::formats::names;
namespace fs = std::filesystem;
using bake::InputError;

namespace {

std::string cat(std::string_view a, std::string_view b) { return std::string(a) + std::string(b); }
// The path prefix of a vertex set: "" (root layout) or "/objects/<name>".
std::string prefix_of(const std::string& object) { return object.empty() ? std::string() : cat(N::kObjects, "/") + object; }
std::string occluder_dir(const std::string& name) { return cat(N::kOccluders, "/") + name; }
std::string shells_path(const std::string& name) { return cat(occluder_dir(name) + "/", N::kShells); }
std::string quoted(std::string_view name) { return "'" + std::string(name) + "'"; }

// The vertex set of `object` ("" = the root layout).
const F::VertexSet& vertex_set(const F::Asset& f, const std::string& file, const std::string& object) {
  if (object.empty()) return f.vertices;
  const F::SceneObject* o = f.find_object(object);
  if (!o) throw InputError(file, "has no object '" + object + "'");
  return o->set;
}

// The environment the file was baked with must be the one we shade / reference with. `where` names
// the dataset or group whose environment fields say which it was.
template <class Baked>
void check_same_environment(const Baked& baked, const std::string& where, const bake::EnvMap& env, const std::string& file) {
  const std::string sha = baked.environment_sha256.value_or("");
  if (!sha.empty() && sha != env.info().sha256)
    throw InputError(env.info().source, "is not the environment " + file + " was baked with (" + where +
                                            " was baked under '" + baked.environment.value_or("") + "', SHA-256 " +
                                            sha.substr(0, 12) + "...)");
}

// What a per-vertex file can be shown with instead, for the message of a missing product.
std::string root_hint(const F::Asset& f) {
  const std::vector<std::string> kinds = vertex_kinds(f);
  if (kinds.empty()) return " (it holds no per-vertex product prtview shades: AO, diffuse transfer or band-1 radiance)";
  std::string hint = " (it can be shown with";
  for (size_t i = 0; i < kinds.size(); ++i) hint += (i ? i + 1 == kinds.size() ? " or " : ", " : " ") + ("--shade " + kinds[i]);
  return hint + ")";
}

// `name` as given, else next to `beside` (a file), when that exists.
std::string found_beside(const std::string& name, const std::string& beside) {
  if (!fs::exists(name) && fs::exists(fs::path(beside).parent_path() / name)) return (fs::path(beside).parent_path() / name).string();
  return name;
}

} // namespace

bool is_scene_file(const F::Asset& f) { return f.scene || !f.objects.empty(); }
bool has_fiv(const F::Asset& f) { return f.irradiance_cube.has_value(); }
bool has_transfer(const F::Asset& f) { return f.vertices.transfer_diffuse.has_value(); }
namespace {
bool has_band1_in(const F::VertexSet& s) {
  return s.radiance_band1 || (s.radiance_shadowed && s.radiance_shadowed->sh_order.value_or(0) >= 2);
}
} // namespace
bool has_band1(const F::Asset& f) { return has_band1_in(f.vertices); }
bool has_ao(const F::Asset& f) { return f.vertices.ao.has_value(); }
std::vector<std::string> vertex_kinds(const F::Asset& f) {
  std::vector<std::string> kinds;
  if (has_band1(f)) kinds.push_back("band1");
  if (has_transfer(f)) kinds.push_back("transfer");
  if (has_ao(f)) kinds.push_back("ao");
  return kinds;
}
std::string vertex_kind_label(const F::Asset& f, const std::string& kind) {
  const F::VertexSet& s = f.vertices;
  if (kind == "band1")
    return s.radiance_band1 || !s.radiance_shadowed
               ? "band-1 radiance"
               : "band 1 of the shadowed radiance (order " + std::to_string(s.radiance_shadowed->sh_order.value_or(0)) + ")";
  if (kind == "transfer")
    return "diffuse transfer order " + (s.transfer_diffuse && s.transfer_diffuse->sh_order ? std::to_string(*s.transfer_diffuse->sh_order) : std::string("?"));
  if (kind == "ao") return "AO";
  return kind;
}
std::string band1_environment_sha256(const F::Asset& f) {
  const F::VertexSet& s = f.vertices;
  const std::optional<F::Product>& p = s.radiance_band1 ? s.radiance_band1 : s.radiance_shadowed;
  return p ? p->environment_sha256.value_or("") : std::string();
}
bool has_lightmap(const F::Asset& f) { return f.vertices.lightmap.has_value(); }
std::vector<std::string> texel_kinds(const F::Asset& f) {
  std::vector<std::string> kinds;
  if (!f.vertices.lightmap) return kinds;
  const F::Lightmap& m = *f.vertices.lightmap;
  if (m.radiance_band1) kinds.push_back("band1");
  if (m.transfer_diffuse) kinds.push_back("transfer");
  if (m.ao) kinds.push_back("ao");
  return kinds;
}
std::string texel_kind_label(const F::Asset& f, const std::string& kind) {
  if (kind == "band1") return "band-1 radiance";
  if (kind == "transfer") {
    const F::Lightmap* m = f.vertices.lightmap ? &*f.vertices.lightmap : nullptr;
    const bool known = m && m->transfer_diffuse && m->transfer_diffuse->sh_order;
    return "diffuse transfer order " + (known ? std::to_string(*m->transfer_diffuse->sh_order) : std::string("?"));
  }
  if (kind == "ao") return "AO";
  return kind;
}
void require_texel_kind(const F::Asset& f, const std::string& file, const std::string& kind) {
  const std::vector<std::string> kinds = texel_kinds(f);
  if (std::find(kinds.begin(), kinds.end(), kind) != kinds.end()) return;
  const std::string_view path = kind == "transfer" ? N::kLightmapTransferDiffuse : kind == "band1" ? N::kLightmapRadianceBand1 : N::kLightmapAo;
  std::string hint = " (its lightmap holds no product prtview shades: AO, diffuse transfer or band-1 radiance)";
  if (!kinds.empty()) {
    hint = " (its lightmap can be shown with";
    for (size_t i = 0; i < kinds.size(); ++i) hint += (i ? i + 1 == kinds.size() ? " or " : ", " : " ") + ("--shade " + kinds[i]);
    hint += ")";
  }
  throw InputError(file, "no dataset " + std::string(path) + hint);
}
TexelProduct read_texel_product(const F::Asset& f, const std::string& file, const std::string& kind, const bake::EnvMap& env) {
  require_texel_kind(f, file, kind);
  return read_texel_product(f.vertices, "", file, kind, env);
}

TexelProduct read_texel_product(const F::VertexSet& s, const std::string& prefix, const std::string& file,
                                const std::string& kind, const bake::EnvMap& env) {
  const F::Lightmap& m = *s.lightmap;
  if (!s.uv) throw InputError(file, "no dataset " + cat(prefix, N::kUv) + " (the lightmap's UVs)");
  if (!s.triangles || s.uv->values.size() != 2 * s.triangles->values.size())
    throw InputError(file, cat(prefix, N::kUv) + " does not hold one (u, v) per corner of " + cat(prefix, N::kTriangles));
  TexelProduct p;
  p.width = int(m.width);
  p.height = int(m.height);
  p.state = &m.state.values;
  p.corner_uv = &s.uv->values;
  p.uv_set = s.uv->uv_set.value_or("");
  const F::Product* product = nullptr;
  std::string_view path;
  if (kind == "ao") {
    product = &*m.ao, path = N::kLightmapAo, p.channels = 1;
  } else if (kind == "transfer") {
    product = &*m.transfer_diffuse, path = N::kLightmapTransferDiffuse;
    if (!product->sh_order) throw InputError(file, cat(prefix, path) + " lacks the attribute " + quoted(N::kShOrder));
    p.order = int(*product->sh_order);
    p.channels = size_t(p.order) * size_t(p.order);
  } else if (kind == "visibility" || kind == "shadowed") {
    const bool shadowed = kind == "shadowed";
    product = shadowed ? &*m.radiance_shadowed : &*m.transfer_visibility;
    path = shadowed ? N::kLightmapRadianceShadowed : N::kLightmapTransferVisibility;
    if (!product->sh_order) throw InputError(file, cat(prefix, path) + " lacks the attribute " + quoted(N::kShOrder));
    p.order = int(*product->sh_order);
    p.channels = (shadowed ? 3 : 1) * size_t(p.order) * size_t(p.order);
    if (shadowed) check_same_environment(*product, cat(prefix, path), env, file);
  } else {
    product = &*m.radiance_band1, path = N::kLightmapRadianceBand1, p.channels = 9, p.order = 2;
    check_same_environment(*product, cat(prefix, path), env, file);
  }
  p.values = &product->values;
  const size_t texels = m.texel_count();
  if (m.width == 0 || m.height == 0 || m.state.values.size() != texels || product->values.size() != texels * p.channels)
    throw InputError(file, cat(prefix, path) + " does not hold [H][W][" + std::to_string(p.channels) + "] values of the " +
                               std::to_string(m.height) + " x " + std::to_string(m.width) + " lightmap");
  return p;
}
bake::UpAxis up_axis(const F::Asset& f) { return f.root.up_axis == "z" ? bake::UpAxis::Z : bake::UpAxis::Y; }

std::string baked_environment(const F::Asset& f, const std::string& file) {
  std::string env_path;
  if (is_scene_file(f) && f.scene) env_path = f.scene->environment.value_or("");
  if (env_path.empty() && f.irradiance_cube) env_path = f.irradiance_cube->environment.value_or("");
  if (env_path.empty() && f.vertices.radiance_band1) env_path = f.vertices.radiance_band1->environment.value_or("");
  if (env_path.empty() && f.vertices.radiance_shadowed) env_path = f.vertices.radiance_shadowed->environment.value_or("");
  if (const auto& m = f.vertices.lightmap; env_path.empty() && m && m->radiance_band1)  // a texel bake's
    env_path = m->radiance_band1->environment.value_or("");
  if (env_path.empty()) throw InputError(file, "holds no environment name: give one with --env ENV.exr");
  env_path = found_beside(env_path, file);
  if (const std::string sf = f.scene ? f.scene->scene_file.value_or("") : std::string(); !sf.empty())
    env_path = found_beside(env_path, sf);
  if (!fs::exists(env_path))
    throw InputError(env_path, "no such file (the environment " + file + " was baked with): give it with --env ENV.exr");
  return env_path;
}

std::string report_summary(const F::Asset& f, const std::string& kind) {
  const F::ReportRow* row = nullptr;
  std::string where;
  size_t rows = 0;
  const auto relative = [](const F::ReportRow& r) { return r.values[2] > 0 ? double(r.values[0]) / double(r.values[2]) : 0.0; };
  const auto consider = [&](const F::ReportRow& r, const std::string& owner) {
    ++rows;
    if (!row || relative(r) > relative(*row)) row = &r, where = owner;
  };
  if (is_scene_file(f)) {
    for (const F::SceneObject& o : f.objects)
      for (const F::ReportRow& r : o.set.report.rows) consider(r, F::object_label(o) + " ");
  } else if (has_fiv(f)) {
    for (const F::Occluder& o : f.occluders)
      if (o.report) consider(*o.report, "FIV ");
  } else {
    const F::VertexSet& s = f.vertices;
    const std::string product = kind == "band1" ? std::string(s.radiance_band1 ? N::kRadianceBand1 : N::kRadianceShadowed).substr(1)
                                : kind == "transfer" ? std::string(N::kTransferDiffuse).substr(1)
                                                     : std::string(N::kAo).substr(1);
    for (const F::ReportRow& r : s.report.rows)
      if (r.product == product) consider(r, "");
  }
  if (!row) return "no error report (baked with --report 0)";
  char buf[200];
  std::snprintf(buf, sizeof buf, "%s%s%s RMSE %.3g at %lld points (%.2g%% of its RMS)", rows > 1 ? "worst row " : "", where.c_str(),
                row->product.c_str(), double(row->values[0]), (long long)row->points.value_or(0), 100 * relative(*row));
  std::string out = buf;
  if (f.target_error) {
    std::snprintf(buf, sizeof buf, ", target %.3g", *f.target_error);
    out += buf;
  }
  return out;
}

bake::Mesh read_mesh(const F::Asset& f, const std::string& file, const std::string& object) {
  const F::VertexSet& s = vertex_set(f, file, object);
  const std::string prefix = prefix_of(object);
  if (!s.positions) throw InputError(file, "no dataset " + cat(prefix, N::kPositions));
  if (!s.normals) throw InputError(file, "no dataset " + cat(prefix, N::kNormals));
  if (!s.triangles) throw InputError(file, "no dataset " + cat(prefix, N::kTriangles) + " (nothing to rasterize)");
  const auto& pos = s.positions->values;
  const auto& nrm = s.normals->values;
  const auto& tri = s.triangles->values;
  const size_t V = pos.size() / 3;
  std::vector<Eigen::Vector3f> P(V), N(V);
  for (size_t i = 0; i < V; ++i) {
    P[i] = Eigen::Vector3d(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]).cast<float>();  // world, rounded to float once
    N[i] = {nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2]};
  }
  std::vector<std::array<uint32_t, 3>> T(tri.size() / 3);
  for (size_t t = 0; t < T.size(); ++t) T[t] = {tri[3 * t], tri[3 * t + 1], tri[3 * t + 2]};
  return bake::make_mesh(std::move(P), std::move(T), object.empty() ? file : object, std::move(N));
}

Transfer read_transfer(const F::Asset& f, const std::string& file, const std::string& object) {
  const std::optional<F::Product>& t = vertex_set(f, file, object).transfer_diffuse;
  const std::string path = cat(prefix_of(object), N::kTransferDiffuse);
  if (!t) throw InputError(file, "no dataset " + path + (object.empty() ? root_hint(f) : ""));
  if (!t->sh_order) throw InputError(file, path + " lacks the attribute " + quoted(N::kShOrder));
  return {int(*t->sh_order), t->values.data()};
}

void require_vertex_kind(const F::Asset& f, const std::string& file, const std::string& kind) {
  const std::vector<std::string> kinds = vertex_kinds(f);
  if (std::find(kinds.begin(), kinds.end(), kind) != kinds.end()) return;
  const std::string_view path = kind == "transfer" ? N::kTransferDiffuse : kind == "band1" ? N::kRadianceBand1 : N::kAo;
  throw InputError(file, "no dataset " + std::string(path) + root_hint(f));
}

const std::vector<float>& read_ao(const F::Asset& f, const std::string& file, const std::string& object) {
  const std::optional<F::Product>& ao = vertex_set(f, file, object).ao;
  if (!ao) throw InputError(file, "no dataset " + cat(prefix_of(object), N::kAo) + (object.empty() ? root_hint(f) : ""));
  return ao->values;
}

Band1 read_band1(const F::Asset& f, const std::string& file, const std::string& object, const bake::EnvMap& env) {
  const F::VertexSet& s = vertex_set(f, file, object);
  const std::string prefix = prefix_of(object), path = cat(prefix, N::kRadianceBand1);
  if (!has_band1_in(s)) throw InputError(file, "no dataset " + path + (object.empty() ? root_hint(f) : ""));
  if (!s.normals) throw InputError(file, "no dataset " + cat(prefix, N::kNormals));
  Band1 b;
  b.normals = s.normals->values.data();
  if (s.radiance_band1) {
    check_same_environment(*s.radiance_band1, path, env, file);
    b.baked = s.radiance_band1->values.data();
    return b;
  }
  check_same_environment(*s.radiance_shadowed, cat(prefix, N::kRadianceShadowed), env, file);
  const size_t n = size_t(*s.radiance_shadowed->sh_order) * size_t(*s.radiance_shadowed->sh_order), V = s.vertex_count();
  const std::vector<float>& S = s.radiance_shadowed->values;
  if (S.size() != V * 3 * n) throw InputError(file, cat(prefix, N::kRadianceShadowed) + " does not hold [V][3][L*L] values");
  b.shadowed_order = int(*s.radiance_shadowed->sh_order);
  b.copied.resize(V * 9);
  for (size_t v = 0; v < V; ++v)
    for (size_t c = 0; c < 3; ++c)
      for (size_t m = 0; m < 3; ++m) b.copied[9 * v + 3 * c + m] = S[(3 * v + c) * n + 1 + m];
  return b;
}

BakedOccluder read_occluder(const F::Asset& f, const std::string& file, const std::string& name, const bake::EnvMap& env) {
  const F::Occluder* baked = f.find_occluder(name);
  if (!baked) throw InputError(file, "no dataset " + shells_path(name));
  check_same_environment(*baked, shells_path(name), env, file);
  if (!baked->valid) throw InputError(file, "no dataset " + cat(occluder_dir(name) + "/", N::kValid));
  BakedOccluder b;
  b.centre = baked->centre;
  b.radius = baked->radius;
  b.radii.assign(baked->radii.begin(), baked->radii.end());
  shade::FivOccluder& o = b.view;
  for (int c = 0; c < 3; ++c) o.centre[c] = float(b.centre[size_t(c)]);
  o.radius = float(b.radius);
  o.n_rho = baked->n_rho;
  o.n_theta = baked->n_theta;
  o.n_phi = baked->n_phi;
  o.radii = b.radii.data();
  o.shells = baked->shells.data();
  if (baked->float16) {  // what an engine holds of a float16 file (v8): the half bits
    b.shells_half = F::float16_bits(baked->shells);
    o.shells = nullptr, o.shells_half = b.shells_half.data();
  }
  o.valid = baked->valid->values.data();
  // Version 7 (formats/SCHEMA.md): no radial_scheme attribute is the geometric scheme.
  if (baked->radial_scheme.value_or("geometric") == "surface") {
    if (!baked->surface_radius) throw InputError(file, "no dataset " + cat(occluder_dir(name) + "/", N::kSurfaceRadius));
    o.radial_scheme = shade::kFivRadialSurface;
    o.surface_radius = baked->surface_radius->values.data();
  }
  // The tight proxy where the file says so (v7; prtshade/fiv.h "Tight proxies"); older files: the sphere.
  if (baked->proxy == std::string(N::kProxyCone)) {
    if (!baked->cones) throw InputError(file, cat(occluder_dir(name), "") + " says proxy \"cone\" without a cone table");
    o.cones = baked->cones->values.data();
    if (baked->cones->float16) {
      b.cones_half = F::float16_bits(baked->cones->values);
      o.cones = nullptr, o.cones_half = b.cones_half.data();
    }
  }
  try {
    shade::validate_occluder(o);
  } catch (const std::invalid_argument& e) {
    throw InputError(file, occluder_dir(name) + ": " + e.what());
  }
  return b;  // moving the vector keeps its buffer: view.radii stays valid
}

std::string choose_occluder(const F::Asset& f, const std::string& file, const std::string& name) {
  if (f.occluders.empty()) throw InputError(file, "no " + shells_path("<name>"));
  if (name.empty()) {
    if (f.occluders.size() > 1) throw InputError(file, "holds several occluders: choose one with --occluder NAME");
    return f.occluders.front().name;
  }
  if (!f.find_occluder(name)) throw InputError(file, "has no occluder '" + name + "'");
  return name;
}

std::optional<shade::DifMap> read_difmap(const F::Asset& f, const std::string& file, const bake::EnvMap& env, bool required) {
  const std::string path(N::kIrradianceCube);
  if (!f.irradiance_cube) {
    if (required) throw InputError(file, "no dataset " + path);
    return std::nullopt;
  }
  check_same_environment(*f.irradiance_cube, path, env, file);
  const shade::DifMap map{f.irradiance_cube->size, f.irradiance_cube->values.data()};
  shade::validate_difmap(map);
  return map;
}

const float* read_environment_fiv(const F::Asset& f, const std::string& file, const bake::EnvMap& env, bool required) {
  const std::string path(N::kFivEnvironment);
  if (!f.fiv_environment) {
    if (required) throw InputError(file, "no dataset " + path);
    return nullptr;
  }
  check_same_environment(*f.fiv_environment, path, env, file);
  return f.fiv_environment->f_env.data();
}

std::string occluder_mesh_path(const F::Asset& f, const std::string& file, const std::string& given) {
  std::string mesh_path = given;
  if (mesh_path.empty()) {
    mesh_path = found_beside(f.root.source, file);
    if (!fs::exists(mesh_path))
      throw InputError(file, "the occluder mesh '" + mesh_path + "' (the file's " + quoted(N::kSource) +
                                 " attribute) does not exist: give it with --occluder-mesh");
  }
  if (!f.root.source_sha256.empty() && bake::sha256_file(mesh_path) != f.root.source_sha256)
    throw InputError(mesh_path, "is not the mesh " + file + " was baked from (SHA-256 differs from its " +
                                    std::string(N::kSourceSha256) + ")");
  return mesh_path;
}

bool is_glossy(const F::SceneObject& o) {
  const F::VertexSet& s = o.set;
  const bool texels = s.lightmap && (s.lightmap->transfer_visibility || s.lightmap->radiance_shadowed);
  return o.phong_exponent.value_or(0) > 0 && (s.transfer_visibility || s.radiance_shadowed || texels);
}

std::vector<SceneObject> read_scene_objects(const F::Asset& f, const std::string& file, const bake::EnvMap* env) {
  if (env && f.scene) check_same_environment(*f.scene, std::string(N::kScene), *env, file);
  std::vector<SceneObject> objects;
  std::vector<bool> bounced_objects;  // per object: some product of it carries bounces
  for (const F::SceneObject& baked : f.objects) {
    if (!baked.set.positions) continue;  // not a vertex set
    SceneObject o;
    o.name = baked.name;
    const std::string prefix = prefix_of(baked.name);
    o.role = baked.role.value_or("");
    if (o.role != "receiver" && o.role != "occluder" && o.role != "both")
      throw InputError(file, prefix + " has no valid " + quoted(N::kRole) + " attribute (receiver, occluder or both)");
    o.receiver = o.role != "occluder";
    o.casts_shadow = o.role != "receiver";
    if (const auto& v = baked.albedo; F::find_attr(baked.extra, N::kAlbedo) || v) {  // in extra: not RGB doubles
      if (!v || v->size() != 3) throw InputError(file, prefix + ": " + quoted(N::kAlbedo) + " must be 3 numbers");
      if ((*v)[0] > 0 || (*v)[1] > 0 || (*v)[2] > 0)
        for (size_t c = 0; c < 3; ++c) o.albedo[c] = float(std::max(0.0, (*v)[c]));
    }
    o.mesh = read_mesh(f, file, baked.name);
    const F::VertexSet& s = baked.set;
    const auto bounced = [](const std::optional<F::Product>& p) { return p && p->bounces.value_or(0) > 0; };
    const F::Lightmap* m = s.lightmap ? &*s.lightmap : nullptr;
    const bool any_bounced = bounced(s.radiance_band1) || bounced(s.transfer_diffuse) || bounced(s.radiance_shadowed) ||
                             bounced(s.area_irradiance) ||
                             (m && (bounced(m->radiance_band1) || bounced(m->transfer_diffuse) ||
                                    bounced(m->radiance_shadowed) || bounced(m->area_irradiance)));
    o.area_bounced = bounced(s.area_irradiance) || (m && bounced(m->area_irradiance));
    if (o.role == "both" && baked.albedo && baked.albedo->size() == 3)
      for (size_t c = 0; c < 3; ++c) o.reflectance[c] = float(std::max(0.0, (*baked.albedo)[c]));
    bounced_objects.push_back(any_bounced);
    o.glossy_only = s.transfer_visibility && !s.radiance_band1 && !s.transfer_diffuse;
    // The per-vertex product the runtime shades it with: the first of band-1 radiance, transfer, AO.
    if (!env) {
      objects.push_back(std::move(o));
      continue;
    }
    if (has_band1_in(s)) {
      o.band1 = read_band1(f, file, baked.name, *env);
      o.drawn_bounced = s.radiance_band1 ? bounced(s.radiance_band1) : bounced(s.radiance_shadowed);
    } else if (s.transfer_diffuse) {
      o.transfer = read_transfer(f, file, baked.name);
      o.drawn_bounced = bounced(s.transfer_diffuse);
    } else if (s.ao) {
      o.ao = &s.ao->values;
    } else if (m) {
      // Baked per texel (a scene's "lightmap"): the first of band-1 radiance, transfer, AO.
      const char* kind = m->radiance_band1 ? "band1" : m->transfer_diffuse ? "transfer" : m->ao ? "ao" : nullptr;
      if (kind) o.texels = read_texel_product(s, prefix, file, kind, *env), o.texel_kind = kind;
      o.drawn_bounced = m->radiance_band1 ? bounced(m->radiance_band1) : m->transfer_diffuse && bounced(m->transfer_diffuse);
    }
    if (is_glossy(baked)) {
      const F::Lightmap* lightmap = s.lightmap ? &*s.lightmap : nullptr;
      auto sh_product = [&](const F::Product& p, std::string_view name) {
        if (!p.sh_order) throw InputError(file, cat(prefix, name) + " lacks the attribute " + quoted(N::kShOrder));
        return Transfer{int(*p.sh_order), p.values.data()};
      };
      if (s.transfer_visibility) o.visibility = sh_product(*s.transfer_visibility, N::kTransferVisibility);
      if (s.radiance_shadowed) {
        check_same_environment(*s.radiance_shadowed, cat(prefix, N::kRadianceShadowed), *env, file);
        o.shadowed = sh_product(*s.radiance_shadowed, N::kRadianceShadowed);
      }
      if (lightmap && lightmap->transfer_visibility) o.texel_visibility = read_texel_product(s, prefix, file, "visibility", *env);
      if (lightmap && lightmap->radiance_shadowed) o.texel_shadowed = read_texel_product(s, prefix, file, "shadowed", *env);
      o.phong = *baked.phong_exponent;
      if (const auto& c = baked.specular) {
        if (c->size() != 3) throw InputError(file, prefix + ": " + quoted(N::kSpecular) + " must be 3 numbers");
        for (size_t k = 0; k < 3; ++k) o.specular[k] = float(std::max(0.0, (*c)[k]));
      }
    }
    if (f.fiv_environment && f.find_occluder(baked.name)) {
      o.shells = read_occluder(f, file, baked.name, *env);
      if (const F::Occluder* occ = f.find_occluder(baked.name); occ->self_band1) {
        // The schema holds it to the object's V rows and normals.
        const size_t V = s.positions->values.size() / 3;
        if (!s.normals || occ->self_band1->values.size() != 9 * V)
          throw InputError(file, cat(occluder_dir(baked.name) + "/", N::kSelfBand1) + " does not match " + prefix);
        o.fiv_self.resize(3 * V);
        shade::shade_band1_vertices(s.normals->values.data(), occ->self_band1->values.data(), V, o.fiv_self.data());
      }
    }
    objects.push_back(std::move(o));
  }
  if (objects.empty())
    throw InputError(file, "is a scene file without objects (no " + cat(prefix_of("<name>"), N::kPositions) + ")");
  // A scene baked with bounces: an object none of whose products carries them was left out of the
  // bake's reflecting set (no rows to bounce), so it reflects nothing.
  if (std::find(bounced_objects.begin(), bounced_objects.end(), true) != bounced_objects.end())
    for (size_t k = 0; k < objects.size(); ++k)
      if (!bounced_objects[k]) objects[k].reflectance = {0, 0, 0};
  return objects;
}

} // namespace prt::prtview
