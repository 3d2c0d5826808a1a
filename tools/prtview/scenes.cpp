// prtview/scenes.cpp — the scenes prtview draws and their runtime pictures (scenes.h).
#include "scenes.h"

#include "read_file.h"

#include <view/lightmap.h>
#include <view/raster.h>

#include <bake/bake/fiv.h>
#include <bake/core/error.h>
#include <bake/environment/irradiance.h>
#include <prtshade/fiv.h>
#include <formats/names.h>
#include <prtshade/glossy.h>
#include <prtshade/shade.h>
#include <prtshade/sh.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <numbers>
#include <set>
#include <span>

namespace prt::prtview {

namespace F = prt::formats;
using Eigen::Vector3d;

namespace {

// The environment's SH coefficients [3][order²] (channel-major, as prtshade wants them).
std::vector<float> environment_sh(const bake::EnvMap& env, int order, std::string& how) {
  const size_t n = size_t(order) * size_t(order);
  std::vector<float> light(3 * n);
  if (env.info().layout == "latlong" && env.up() == bake::UpAxis::Y) {
    // The runtime path: the pixels as an engine holds them (after libbake's load policy).
    const int W = env.info().width, H = env.info().height;
    std::vector<float> px(size_t(W) * size_t(H) * 3);
    for (int t = 0; t < W * H; ++t) {
      const bake::Rgb c = env.texel_value(t);
      px[3 * size_t(t)] = float(c.r);
      px[3 * size_t(t) + 1] = float(c.g);
      px[3 * size_t(t) + 2] = float(c.b);
    }
    shade::project_latlong(px.data(), W, H, order, light.data());
    how = "prt::shade::project_latlong (order " + std::to_string(order) + ") + shade_transfer per vertex, Gouraud";
  } else {  // cube maps and Z-up scenes: libbake's projection (same quadrature, any layout)
    const auto L = env.project_sh(order);
    for (size_t i = 0; i < n; ++i)
      for (size_t c = 0; c < 3; ++c) light[c * n + i] = float(L[i * 3 + c]);
    how = "EnvMap::project_sh (order " + std::to_string(order) + ", cube map or Z-up) + prt::shade::shade_transfer, Gouraud";
  }
  return light;
}

// Per-vertex E/pi from diffuse transfer (any environment, turned about +Y by `degrees`) or band-1
// radiance (the baked one).
std::vector<float> transfer_colours(const Transfer& t, const bake::EnvMap& env, size_t V, std::string& how, double degrees = 0) {
  std::vector<float> light = environment_sh(env, t.order, how);
  if (degrees != 0) {
    turn_light(light, t.order, degrees);
    char buf[64];
    std::snprintf(buf, sizeof buf, ", the environment turned %g degrees about +Y", degrees);
    how += buf;
  }
  std::vector<float> colour(3 * V);
  shade::shade_transfer_vertices(t.coeffs, V, t.order, light.data(), colour.data());
  return colour;
}
std::vector<float> band1_colours(const Band1& b, size_t V, std::string& how) {
  std::vector<float> colour(3 * V);
  shade::shade_band1_vertices(b.normals, b.radiance(), V, colour.data());
  for (float& c : colour) c *= float(std::numbers::inv_pi);
  how = std::string("prt::shade::shade_band1 per vertex (E/pi") +
        (b.shadowed_order ? ", band 1 of radiance/shadowed" : "") + "), Gouraud";
  return colour;
}

// AO x the unshadowed irradiance at the vertex normal / pi: the runtime's DifMap when there is one
// (lookup_difmap), else the exact texel sum (bake::UnshadowedIrradiance) — the ambient-occlusion
// approximation of E/pi.
std::vector<float> ao_colours(const std::vector<float>& ao, const bake::Mesh& mesh, const shade::DifMap* difmap,
                              const bake::UnshadowedIrradiance* exact, std::string& how) {
  const size_t V = mesh.positions.size();
  std::vector<float> colour(3 * V);
  for (size_t v = 0; v < V; ++v) {
    const float n[3] = {mesh.normals[v].x(), mesh.normals[v].y(), mesh.normals[v].z()};
    float e[3];
    if (difmap) {
      shade::lookup_difmap(*difmap, n, e);
    } else {
      const bake::Rgb u = (*exact)(mesh.normals[v].cast<double>());
      e[0] = float(u.r), e[1] = float(u.g), e[2] = float(u.b);
    }
    for (size_t c = 0; c < 3; ++c) colour[3 * v + c] = ao[v] * e[c] * float(std::numbers::inv_pi);
  }
  how = std::string("AO x ") + (difmap ? "DifMap (lookup_difmap)" : "exact unshadowed irradiance") + " / pi";
  return colour;
}

} // namespace

std::string name_list(const std::vector<std::string>& names, size_t budget) {
  std::string out;
  size_t k = 0;
  for (; k < names.size(); ++k) {
    const std::string next = (k ? ", " : "") + names[k];
    const size_t more = k + 1 < names.size() ? 16 : 0;  // room for " and N more"
    if (k > 0 && out.size() + next.size() + more > budget) break;
    out += next;
  }
  if (k < names.size()) out += " and " + std::to_string(names.size() - k) + " more";
  return out;
}

void add_grouped(std::string& how, const std::vector<std::string>& names, const std::vector<std::string>& how_of) {
  if (names.size() <= kObjectLines) {
    for (size_t k = 0; k < names.size(); ++k) how += "\n  " + names[k] + ": " + how_of[k];
    return;
  }
  std::vector<std::pair<std::string, std::vector<std::string>>> groups;  // in order of first use
  for (size_t k = 0; k < names.size(); ++k) {
    auto it = std::find_if(groups.begin(), groups.end(), [&](const auto& g) { return g.first == how_of[k]; });
    if (it == groups.end()) it = groups.insert(groups.end(), {how_of[k], {}});
    it->second.push_back(names[k]);
  }
  for (const auto& [h, n] : groups) how += "\n  " + std::to_string(n.size()) + " x " + h + ": " + name_list(n, 60);
}

void turn_light(std::vector<float>& light, int order, double degrees) {
  const double a = degrees * std::numbers::pi / 180, c = std::cos(a), s = std::sin(a);
  const double R[3][3] = {{c, 0, s}, {0, 1, 0}, {-s, 0, c}};
  const sh::Rotation rotation(R, order);
  const size_t n = size_t(order) * size_t(order);
  std::vector<float> in(n);
  for (size_t ch = 0; ch < 3; ++ch) {
    std::copy_n(light.begin() + std::ptrdiff_t(ch * n), n, in.begin());
    rotation.apply(std::span<const float>(in), std::span<float>(light.data() + ch * n, n));
  }
}

view::Image render_vertex_file(const F::Asset& f, const std::string& file, const std::string& kind, const bake::EnvMap& env,
                               const view::Camera& cam, RenderScene& scene, double env_rotate_degrees) {
  scene.mesh = read_mesh(f, file, "");
  const size_t V = scene.mesh.positions.size();
  scene.what = "mesh: " + std::to_string(V) + " vertices, " + std::to_string(scene.mesh.triangles.size()) + " triangles";
  std::vector<float> colour;
  if (kind == "transfer") {
    colour = transfer_colours(read_transfer(f, file, ""), env, V, scene.how, env_rotate_degrees);
  } else if (kind == "band1") {
    colour = band1_colours(read_band1(f, file, "", env), V, scene.how);
  } else {
    const bake::UnshadowedIrradiance exact(env);
    colour = ao_colours(read_ao(f, file, ""), scene.mesh, nullptr, &exact, scene.how);
    scene.how += " per vertex, Gouraud";
  }
  scene.form = "per vertex";
  return view::interpolate_vertices(scene.mesh, view::rasterize(scene.mesh, cam), colour);
}

view::Image render_texel_file(const F::Asset& f, const std::string& file, const std::string& kind, const bake::EnvMap& env,
                              const view::Camera& cam, RenderScene& scene, double env_rotate_degrees) {
  scene.mesh = read_mesh(f, file, "");
  const TexelProduct p = read_texel_product(f, file, kind, env);
  const view::LightmapImage map{p.width, p.height, p.channels, *p.values, *p.state};
  scene.form = "per texel, " + std::to_string(p.width) + "x" + std::to_string(p.height) + " lightmap";
  scene.what = "mesh: " + std::to_string(scene.mesh.positions.size()) + " vertices, " + std::to_string(scene.mesh.triangles.size()) +
               " triangles; " + scene.form + " (UV set " + (p.uv_set.empty() ? std::string("unnamed") : p.uv_set) + ")";
  const auto to_float = [](const Vector3d& n, float* out) {
    for (int c = 0; c < 3; ++c) out[c] = float(n[c]);
  };
  std::function<void(const view::Fragment&, const float*, float*)> shade;
  std::vector<float> light;
  std::unique_ptr<bake::UnshadowedIrradiance> exact;
  if (kind == "transfer") {
    light = environment_sh(env, p.order, scene.how);
    if (env_rotate_degrees != 0) turn_light(light, p.order, env_rotate_degrees);
    shade = [&](const view::Fragment&, const float* t, float* rgb) { shade::shade_transfer_vertices(t, 1, p.order, light.data(), rgb); };
  } else if (kind == "band1") {
    scene.how = "prt::shade::shade_band1 (E/pi) at the pixel's interpolated normal";
    shade = [&](const view::Fragment& fr, const float* r, float* rgb) {
      float n[3];
      to_float(fr.n, n);
      shade::shade_band1_vertices(n, r, 1, rgb);
      for (int c = 0; c < 3; ++c) rgb[c] *= float(std::numbers::inv_pi);
    };
  } else {
    exact = std::make_unique<bake::UnshadowedIrradiance>(env);
    scene.how = "AO x exact unshadowed irradiance at the pixel's interpolated normal / pi";
    shade = [&](const view::Fragment& fr, const float* ao, float* rgb) {
      const bake::Rgb u = (*exact)(fr.n);
      const double e[3] = {u.r, u.g, u.b};
      for (int c = 0; c < 3; ++c) rgb[c] = float(double(ao[0]) * e[c] * std::numbers::inv_pi);
    };
  }
  // The sample is shaded per pixel; the text says so in place of "per vertex, Gouraud".
  const std::string gouraud = " per vertex, Gouraud";
  if (const size_t at = scene.how.find(gouraud); at != std::string::npos) scene.how.erase(at);
  if (const size_t at = scene.how.find(", Gouraud"); at != std::string::npos) scene.how.erase(at);
  view::TexelRender r = view::shade_texels(scene.mesh, view::rasterize(scene.mesh, cam), *p.corner_uv, map, shade);
  scene.texel_pixels = r.pixels;
  scene.empty_texel_pixels = r.empty_hits;
  scene.how += ", " + scene.form + ", bilinear through /mesh/uv; " + std::to_string(r.empty_hits) + " of " +
               std::to_string(r.pixels) + " pixels reached an empty texel";
  return std::move(r.image);
}

namespace {

// The occluders an FIV view can place: name → its shells and the mesh they were baked from (world
// space, where the shells' centre is). An FIV file: its occluder with the mesh of --occluder-mesh
// or the file's source; a scene file: its objects that have shells, with their meshes.
struct PlaceableOccluder {
  BakedOccluder baked;
  bake::Mesh mesh;
  std::string mesh_from;  // where the mesh came from, for the summary
  double lowest = 0;      // the mesh's lowest y
  // Its self-shadowed irradiance E [V][3] at the mesh's vertices, from an FIV file's band-1
  // radiance (prtbake fiv --self-shadows vertex: the occluder alone), or empty: then eq. 12 from
  // the shells (prtshade/fiv.h shade_fiv_member_given_self says why the vertices are better).
  std::vector<float> self;
};

// E at each vertex of a band-1 product (shade_band1 at the baked normals), checked against the mesh.
std::vector<float> self_irradiance(const Band1& b, const bake::Mesh& mesh, size_t vertices, const std::string& file,
                                   const std::string& what) {
  if (vertices != mesh.positions.size())
    throw bake::InputError(file, what + " holds band-1 radiance for " + std::to_string(vertices) + " vertices, but its mesh has " +
                                     std::to_string(mesh.positions.size()));
  std::vector<float> e(3 * vertices);
  shade::shade_band1_vertices(b.normals, b.radiance(), vertices, e.data());
  return e;
}

std::map<std::string, PlaceableOccluder> placeable_occluders(const F::Asset& f, const std::string& file, const FivView& options,
                                                              const bake::EnvMap& env, const std::set<std::string>& wanted) {
  std::map<std::string, PlaceableOccluder> out;
  if (options.scene) {
    for (SceneObject& o : read_scene_objects(f, file, &env)) {
      if (!o.shells || !wanted.count(o.name)) continue;
      // (A scene object's band1, if any, holds the other objects' shadows where they were baked:
      // not its self-shadows once copies move. Its self-shadows come from its self_band1 when the
      // file has it (v9), else from its shells.)
      PlaceableOccluder p{std::move(*o.shells), std::move(o.mesh), "/objects/" + o.name, 0, std::move(o.fiv_self)};
      out.emplace(o.name, std::move(p));
    }
  } else {
    const std::string name = choose_occluder(f, file, options.occluder);
    const std::string mesh_path = occluder_mesh_path(f, file, options.occluder_mesh);
    bake::MeshLoadOptions mopt;
    mopt.use_file_normals = false;
    for (const std::string& w : wanted)
      if (w != name) throw bake::InputError(file, "has no occluder '" + w + "' to place (it holds '" + name + "')");
    PlaceableOccluder p{read_occluder(f, file, name, env), bake::load_mesh(mesh_path, mopt), mesh_path, 0, {}};
    if (has_band1(f) && f.vertices.positions)
      p.self = self_irradiance(read_band1(f, file, "", env), p.mesh, f.vertices.positions->values.size() / 3, file,
                               "its vertex set");
    out.emplace(name, std::move(p));
  }
  for (const std::string& w : wanted)
    if (!out.count(w)) {
      std::string names;
      for (const F::Occluder& o : f.occluders) names += (names.empty() ? "" : ", ") + o.name;
      throw bake::InputError(file, "has no FIV occluder '" + w + "' to place (" + (names.empty() ? "it holds none" : "it holds: " + names) +
                                 ")");
    }
  for (auto& [name, p] : out) {
    p.lowest = std::numeric_limits<double>::infinity();
    for (const auto& v : p.mesh.positions) p.lowest = std::min(p.lowest, double(v.y()));
  }
  return out;
}

// The copies an FIV view draws, each with its occluder's name resolved: the given ones, else each
// placeable occluder once where it was baked.
std::vector<FivInstance> resolved_instances(const F::Asset& f, const std::string& file, const FivView& options) {
  std::vector<FivInstance> inst = options.instances;
  if (inst.empty()) {
    if (options.scene) {
      for (const F::Occluder& o : f.occluders) inst.push_back({o.name, Vector3d::Zero()});
      if (inst.empty()) throw bake::InputError(file, "holds no FIV occluder to draw: no object of it has FIV shells");
    } else {
      inst.push_back({});
    }
  }
  std::string fallback;
  for (FivInstance& i : inst)
    if (i.occluder.empty()) {
      if (fallback.empty()) fallback = choose_occluder(f, file, options.occluder);
      i.occluder = fallback;
    }
  return inst;
}

} // namespace

FirstLook first_look_camera(const F::Asset& f, const std::string& file, const FivView& options, int width, int height,
                            bool glossy) {
  const Vector3d up = up_axis(f) == bake::UpAxis::Z ? Vector3d::UnitZ() : Vector3d::UnitY();
  if (has_fiv(f) && (!is_scene_file(f) || options.scene)) {  // the occluder copies, widened by R so that their shadows show
    Vector3d lo = Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (const FivInstance& t : resolved_instances(f, file, options)) {
      const F::Occluder* o = f.find_occluder(t.occluder);
      if (!o) throw bake::InputError(file, "has no FIV occluder '" + t.occluder + "' to place");
      const Vector3d c(o->centre[0], o->centre[1], o->centre[2]);
      lo = lo.cwiseMin(c + t.offset - Vector3d::Constant(2 * o->radius));
      hi = hi.cwiseMax(c + t.offset + Vector3d::Constant(2 * o->radius));
    }
    return {view::frame_box(lo, hi, up, width, height), options.scene ? "the occluders and their shadows" : "the occluder and its shadow"};
  }
  // Per-vertex files: the mesh; scene files: every object (--shade glossy: the glossy ones), in
  // world space, as one mesh; framed without their large flat parts (view::focus_box).
  std::vector<double> positions;
  std::vector<uint32_t> triangles;
  const auto add = [&](const F::VertexSet& s) {
    if (!s.positions) return;
    const uint32_t base = uint32_t(positions.size() / 3);
    positions.insert(positions.end(), s.positions->values.begin(), s.positions->values.end());
    if (s.triangles)
      for (uint32_t v : s.triangles->values) triangles.push_back(base + v);
  };
  if (is_scene_file(f)) {
    for (const F::SceneObject& o : f.objects)
      if (!glossy || is_glossy(o)) add(o.set);
    if (glossy && positions.empty())  // no glossy object: frame them all (the render says what is missing)
      for (const F::SceneObject& o : f.objects) add(o.set);
  } else {
    add(f.vertices);
  }
  if (positions.empty()) throw bake::InputError(file, "holds no geometry to look at (no vertex positions)");
  for (uint32_t v : triangles)
    if (size_t(v) >= positions.size() / 3) throw bake::InputError(file, "a triangle names a vertex the file does not hold");
  const view::Focus focus = view::focus_box(positions, triangles);
  char what[160];
  if (focus.set_aside_parts > 0)
    std::snprintf(what, sizeof what, "the geometry without its large flat part%s (%zu triangles, %.3g wide; the rest %.3g)",
                  focus.set_aside_parts > 1 ? "s" : "", focus.set_aside_triangles, focus.set_aside_extent, focus.rest_extent);
  else
    std::snprintf(what, sizeof what, "all the geometry (no flat part %.3gx as wide as the rest)", view::kFlatPartRatio);
  return {view::frame_box(focus.lo, focus.hi, up, width, height), what};
}

view::Image render_fiv_file(const F::Asset& f, const std::string& file, const FivView& options, const bake::EnvMap& env,
                            const view::Camera& cam, RenderScene& scene) {
  const std::vector<FivInstance> inst = resolved_instances(f, file, options);
  std::set<std::string> wanted;
  for (const FivInstance& i : inst) wanted.insert(i.occluder);
  const std::map<std::string, PlaceableOccluder> kinds = placeable_occluders(f, file, options, env, wanted);
  const float* env_fiv = read_environment_fiv(f, file, env, true);
  const shade::DifMap difmap = *read_difmap(f, file, env, true);

  // The ground: 1% of the lowest copy's bounding radius below it, a square around the copies'
  // centres reaching 4R past each.
  double ground_y = std::numeric_limits<double>::infinity(), gap = 0;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const FivInstance& i : inst) {
    const PlaceableOccluder& k = kinds.at(i.occluder);
    if (k.lowest + i.offset.y() < ground_y) ground_y = k.lowest + i.offset.y(), gap = 0.01 * k.baked.radius;
    mean += Eigen::Vector2d(k.baked.centre[0] + i.offset.x(), k.baked.centre[2] + i.offset.z());
  }
  mean /= double(inst.size());
  double half = 0;
  for (const FivInstance& i : inst) {
    const PlaceableOccluder& k = kinds.at(i.occluder);
    const Eigen::Vector2d c(k.baked.centre[0] + i.offset.x(), k.baked.centre[2] + i.offset.z());
    half = std::max(half, (c - mean).norm() + 4 * k.baked.radius);
  }
  ground_y = options.ground ? *options.ground : ground_y - gap;
  half = options.ground_size ? *options.ground_size : half;

  std::vector<bake::Mesh> parts = {view::ground_quad(ground_y, mean.x(), mean.y(), half)};
  std::vector<shade::FivOccluder> occluders;
  std::vector<size_t> first_triangle;  // copy k owns [first_triangle[k], first_triangle[k + 1]) past the ground
  size_t triangles = 0;
  for (size_t k = 0; k < inst.size(); ++k) {
    const PlaceableOccluder& kind = kinds.at(inst[k].occluder);
    parts.push_back(view::translated(kind.mesh, inst[k].offset, inst[k].occluder + "#" + std::to_string(k)));
    shade::FivOccluder o = kind.baked.view;
    for (int c = 0; c < 3; ++c) o.centre[c] = float(kind.baked.centre[size_t(c)] + inst[k].offset[c]);
    occluders.push_back(o);
    const Vector3d c0(kind.baked.centre[0], kind.baked.centre[1], kind.baked.centre[2]);
    scene.spheres.push_back({c0 + inst[k].offset, kind.baked.radius});
    first_triangle.push_back(triangles);
    triangles += kind.mesh.triangles.size();
  }
  first_triangle.push_back(triangles);
  scene.receiver_triangles = parts.front().triangles.size();
  scene.mesh = bake::merge_meshes(parts, "fiv scene");
  char buf[512];
  if (kinds.size() == 1) {
    const auto& [name, kind] = *kinds.begin();
    std::snprintf(buf, sizeof buf, "FIV occluder '%s' (%s, shells %dx%dx%d, R %.4g), %zu cop%s, ground y = %.4g, half-size %.4g",
                  name.c_str(), kind.mesh_from.c_str(), kind.baked.view.n_phi, kind.baked.view.n_theta, kind.baked.view.n_rho,
                  kind.baked.radius, inst.size(), inst.size() == 1 ? "y" : "ies", ground_y, half);
  } else {
    std::string list;
    for (const auto& [name, kind] : kinds) {
      const size_t copies = size_t(std::count_if(inst.begin(), inst.end(), [&](const FivInstance& i) { return i.occluder == name; }));
      char one[160];
      std::snprintf(one, sizeof one, "%s'%s' x%zu (shells %dx%dx%d, R %.4g)", list.empty() ? "" : ", ", name.c_str(), copies,
                    kind.baked.view.n_phi, kind.baked.view.n_theta, kind.baked.view.n_rho, kind.baked.radius);
      list += one;
    }
    std::snprintf(buf, sizeof buf, "FIV scene: %zu copies of %zu occluders (%s), ground y = %.4g, half-size %.4g", inst.size(),
                  kinds.size(), list.c_str(), ground_y, half);
  }
  scene.what = buf;
  const bool cones = !options.sphere_proxy && std::any_of(occluders.begin(), occluders.end(), [](const shade::FivOccluder& o) { return shade::has_cones(o); });
  scene.how = std::string("prt::shade::shade_fiv per pixel (overlap correction ") + (options.overlap ? "on" : "off") +
              ", partial-occluder correction " + (options.partial ? "on" : "off") + ", proxy " +
              (cones ? "cone (tight)" : "bounding sphere") +
              "), on the occluders their self-shadows (" +
              (std::all_of(kinds.begin(), kinds.end(), [](const auto& k) { return !k.second.self.empty(); })
                   ? std::string("per-vertex band-1 radiance, Gouraud")
                   : std::any_of(kinds.begin(), kinds.end(), [](const auto& k) { return !k.second.self.empty(); })
                         ? std::string("per-vertex band-1 radiance where baked, else eq. 12 from the shells")
                         : std::string("eq. 12 from the shells")) +
              ") minus the other copies' shadows (shade_fiv_member_given_self)";

  const shade::FivShadeOptions opts{options.partial, options.overlap,
                                    options.sphere_proxy ? shade::FivProxy::sphere : shade::FivProxy::cone};
  const auto frame_start = std::chrono::steady_clock::now();
  const std::clock_t cpu_start = std::clock();
  const view::GBuffer g = view::rasterize(scene.mesh, cam);
  view::Image image = view::shade_pixels(scene.mesh, g, [&](const view::Fragment& fr, float* out) {
    const float p[3] = {float(fr.p.x()), float(fr.p.y()), float(fr.p.z())};
    const float n[3] = {float(fr.n.x()), float(fr.n.y()), float(fr.n.z())};
    float e[3];
    if (size_t(fr.triangle) < scene.receiver_triangles) {
      shade::shade_fiv(difmap, occluders.data(), int(occluders.size()), p, n, opts, e);
    } else {
      const size_t t = size_t(fr.triangle) - scene.receiver_triangles;
      const size_t k = size_t(std::upper_bound(first_triangle.begin(), first_triangle.end(), t) - first_triangle.begin()) - 1;
      const PlaceableOccluder& kind = kinds.at(inst[k].occluder);
      if (kind.self.empty()) {
        shade::shade_fiv_member(env_fiv, occluders.data(), int(occluders.size()), int(k), p, n, options.partial, e);
      } else {  // the per-vertex self-shadows, Gouraud across the triangle
        const auto& tri = kind.mesh.triangles[t - first_triangle[k]];
        float own[3] = {0, 0, 0};
        for (int c = 0; c < 3; ++c)
          for (int v = 0; v < 3; ++v) own[c] += fr.bary[size_t(v)] * kind.self[3 * size_t(tri[v]) + size_t(c)];
        shade::shade_fiv_member_given_self(own, occluders.data(), int(occluders.size()), int(k), p, n, options.partial, e);
      }
    }
    for (int c = 0; c < 3; ++c) out[c] = e[c] * float(std::numbers::inv_pi);
  });
  scene.frame_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - frame_start).count();
  scene.frame_cpu_seconds = double(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  return image;
}

void add_object(RenderScene& scene, const SceneObject& o) {
  const size_t T = o.mesh.triangles.size();
  if (scene.first_triangle.empty()) scene.first_triangle = {0};
  scene.casts_shadow.insert(scene.casts_shadow.end(), T, o.casts_shadow ? 1 : 0);
  scene.albedo.insert(scene.albedo.end(), T, o.albedo);
  scene.reflectance.insert(scene.reflectance.end(), T, o.reflectance);
  scene.gathers.insert(scene.gathers.end(), T, o.drawn_bounced ? 1 : 0);
  scene.area_gathers.insert(scene.area_gathers.end(), T, o.area_bounced ? 1 : 0);
  scene.object_names.push_back(o.name);
  scene.object_receiver.push_back(o.receiver);
  scene.first_triangle.push_back(scene.first_triangle.back() + T);
  if (o.receiver) scene.receiver_triangles += T;
}

view::Image render_scene_file(const F::Asset& f, const std::string& file, const bake::EnvMap& env, const view::Camera& cam,
                              RenderScene& scene) {
  std::vector<SceneObject> objects = read_scene_objects(f, file, &env);
  // What the runtime has beside the per-vertex data: the DifMap (unshadowed irradiance) and the
  // environment FIV, when some occluder got shells.
  const std::optional<shade::DifMap> difmap = read_difmap(f, file, env, false);
  const float* env_fiv = read_environment_fiv(f, file, env, false);
  std::optional<bake::UnshadowedIrradiance> exact;  // AO without a DifMap
  // Flat grey: half the outgoing radiance of a white surface under a uniform sky of the
  // environment's mean radiance Lbar = L_00 / sqrt(4 pi) (mean over RGB).
  const auto L00 = env.project_sh(1);
  const float flat = float(0.5 * (L00[0] + L00[1] + L00[2]) / 3.0 / std::sqrt(4 * std::numbers::pi));

  // Receivers first: the compared region is the triangle range [0, receiver_triangles).
  std::stable_partition(objects.begin(), objects.end(), [](const SceneObject& o) { return o.receiver; });
  // Every object with FIV shells is an occluder the runtime knows; those shaded per pixel get their
  // own self-shadows minus the others' shadows (shade_fiv_member).
  std::vector<shade::FivOccluder> fiv_occluders;
  std::vector<int> fiv_index(objects.size(), -1);
  for (size_t k = 0; k < objects.size(); ++k)
    if (objects[k].shells) {
      fiv_index[k] = int(fiv_occluders.size());
      fiv_occluders.push_back(objects[k].shells->view);
    }
  std::vector<std::vector<float>> rgb_of(objects.size());  // E/pi per vertex (white); empty: per pixel
  std::map<int, std::vector<float>> transfer_light;         // the environment's SH per transfer order (lightmaps)
  std::vector<std::string> how_of(objects.size());
  for (size_t k = 0; k < objects.size(); ++k) {
    const SceneObject& o = objects[k];
    const size_t V = o.mesh.positions.size();
    const std::string glossy_note = o.glossy_only ? " (glossy: its lobe with --shade glossy)" : "";
    std::string unused;
    if (o.band1) {
      rgb_of[k] = band1_colours(*o.band1, V, unused);
      how_of[k] = "band-1 radiance (shade_band1)";
    } else if (o.transfer) {
      rgb_of[k] = transfer_colours(*o.transfer, env, V, unused);
      how_of[k] = "diffuse transfer (project_latlong + shade_transfer)";
    } else if (o.ao) {
      if (!difmap && !exact) exact.emplace(env);
      rgb_of[k] = ao_colours(*o.ao, o.mesh, difmap ? &*difmap : nullptr, exact ? &*exact : nullptr, how_of[k]);
      how_of[k] += glossy_note;
    } else if (o.texels) {
      // Per texel: shaded per pixel from the lightmap (below), as render_texel_file shades a mesh.
      how_of[k] = std::string(o.texel_kind == "band1" ? "band-1 radiance" : o.texel_kind == "transfer" ? "diffuse transfer" : "AO") +
                  " per texel, " + std::to_string(o.texels->width) + "x" + std::to_string(o.texels->height) +
                  " lightmap, bilinear through its mesh/uv" + glossy_note;
      if (o.texel_kind == "transfer" && !transfer_light.count(o.texels->order)) {
        std::string ignored;
        transfer_light[o.texels->order] = environment_sh(env, o.texels->order, ignored);
      }
      if (o.texel_kind == "ao" && !exact) exact.emplace(env);
    } else if (o.shells) {
      how_of[k] = (o.fiv_self.empty() ? "FIV self-shadows per pixel from its shells (eq. 12)"
                                       : "FIV self-shadows from its vertices (self_band1, Gouraud)") +
                  std::string(" minus the other FIV occluders' shadows (shade_fiv_member") +
                  (o.fiv_self.empty() ? ")" : "_given_self)") + glossy_note;
    } else {
      rgb_of[k].assign(3 * V, flat);
      how_of[k] = "flat grey (no per-vertex products, no FIV shells)" + glossy_note;
    }
  }

  std::vector<bake::Mesh> parts;
  std::vector<float> rgb;
  std::vector<uint8_t> per_pixel;
  scene.first_triangle = {0};
  scene.how = "per object, times its albedo (white if none):";
  std::vector<std::string> names, receivers, occluders;
  for (const SceneObject& o : objects) {
    names.push_back(o.name);
    (o.receiver ? receivers : occluders).push_back(o.name);
  }
  add_grouped(scene.how, names, how_of);
  scene.what = "scene: " + std::to_string(objects.size()) + " objects: " + std::to_string(receivers.size()) + " receiving (" +
               name_list(receivers, 50) + ")" +
               (occluders.empty() ? "" : ", " + std::to_string(occluders.size()) + " only casting (" + name_list(occluders, 40) + ")");
  for (size_t k = 0; k < objects.size(); ++k) {
    const SceneObject& o = objects[k];
    const size_t T = o.mesh.triangles.size();
    for (size_t v = 0; v < o.mesh.positions.size(); ++v)
      for (size_t c = 0; c < 3; ++c) rgb.push_back(rgb_of[k].empty() ? 0.0f : rgb_of[k][3 * v + c] * o.albedo[c]);
    per_pixel.insert(per_pixel.end(), T, rgb_of[k].empty() ? 1 : 0);
    add_object(scene, o);
    if (o.casts_shadow) {
      view::Sphere sp;
      bake::bounding_sphere(o.mesh, sp.centre, sp.radius);
      scene.spheres.push_back(sp);
    }
    parts.push_back(o.mesh);
  }
  scene.mesh = bake::merge_meshes(parts, file);
  const view::GBuffer g = view::rasterize(scene.mesh, cam);
  std::atomic<size_t> texel_pixels{0}, empty_hits{0};
  view::Image image = view::shade_mixed(scene.mesh, g, rgb, per_pixel, [&](const view::Fragment& fr, float* out) {
    const size_t k = size_t(std::upper_bound(scene.first_triangle.begin(), scene.first_triangle.end(), size_t(fr.triangle)) -
                            scene.first_triangle.begin()) - 1;
    const float p[3] = {float(fr.p.x()), float(fr.p.y()), float(fr.p.z())};
    const float n[3] = {float(fr.n.x()), float(fr.n.y()), float(fr.n.z())};
    float e[3];
    if (const auto& t = objects[k].texels) {
      // The lightmap, sampled as an engine samples it (view/lightmap.h), shaded by prtshade.
      const Eigen::Vector2d uv = view::fragment_uv(fr, *t->corner_uv, size_t(fr.triangle) - scene.first_triangle[k]);
      thread_local std::vector<float> buffer;  // a pixel's sample (any transfer order's channels)
      buffer.resize(t->channels);
      float* sample = buffer.data();
      if (view::sample_lightmap({t->width, t->height, t->channels, *t->values, *t->state}, uv.x(), uv.y(), sample)) ++empty_hits;
      ++texel_pixels;
      if (objects[k].texel_kind == "band1") {
        shade::shade_band1_vertices(n, sample, 1, e);
        for (float& x : e) x *= float(std::numbers::inv_pi);
      } else if (objects[k].texel_kind == "transfer") {
        shade::shade_transfer_vertices(sample, 1, t->order, transfer_light.at(t->order).data(), e);
      } else {
        const bake::Rgb un = (*exact)(fr.n);
        const double irr[3] = {un.r, un.g, un.b};
        for (int c = 0; c < 3; ++c) e[c] = float(double(sample[0]) * irr[c] * std::numbers::inv_pi);
      }
      for (size_t c = 0; c < 3; ++c) out[c] = e[c] * objects[k].albedo[c];
      return;
    }
    if (const std::vector<float>& self = objects[k].fiv_self; !self.empty()) {
      // The per-vertex self-shadows (/fiv/occluders/<name>/self_band1), Gouraud across the triangle.
      const auto& tri = objects[k].mesh.triangles[size_t(fr.triangle) - scene.first_triangle[k]];
      float own[3] = {0, 0, 0};
      for (int c = 0; c < 3; ++c)
        for (int v = 0; v < 3; ++v) own[c] += fr.bary[size_t(v)] * self[3 * size_t(tri[v]) + size_t(c)];
      shade::shade_fiv_member_given_self(own, fiv_occluders.data(), int(fiv_occluders.size()), fiv_index[k], p, n, true, e);
    } else {
      shade::shade_fiv_member(env_fiv, fiv_occluders.data(), int(fiv_occluders.size()), fiv_index[k], p, n, true, e);
    }
    for (size_t c = 0; c < 3; ++c) out[c] = e[c] * float(std::numbers::inv_pi) * objects[k].albedo[c];
  });
  scene.texel_pixels = texel_pixels, scene.empty_texel_pixels = empty_hits;
  if (texel_pixels > 0)
    scene.how += "\n  per-texel objects: " + std::to_string(empty_hits.load()) + " of " + std::to_string(texel_pixels.load()) +
                 " of their pixels reached an empty texel";
  return image;
}

view::Image render_glossy_scene(const F::Asset& f, const std::string& file, const bake::EnvMap& env, const view::Camera& cam,
                                std::optional<double> phong, GlossyRoute route, RenderScene& scene) {
  std::vector<SceneObject> objects = read_scene_objects(f, file, &env);
  for (SceneObject& o : objects) o.receiver = o.visibility || o.shadowed || o.texel_visibility || o.texel_shadowed;
  if (std::none_of(objects.begin(), objects.end(), [](const SceneObject& o) { return o.receiver; }))
    throw bake::InputError(file, "has no glossy object (one with a phong_exponent and " +
                                     std::string(F::names::kObjects) + "/<name>" + std::string(F::names::kTransferVisibility) +
                                     " or " + std::string(F::names::kRadianceShadowed.substr(1)) +
                                     ", per vertex or in its lightmap): nothing to show with --shade glossy");
  std::stable_partition(objects.begin(), objects.end(), [](const SceneObject& o) { return o.receiver; });
  // One Gaunt table and one lit product matrix per order, shared by the objects of that order.
  std::map<int, std::unique_ptr<shade::GlossyLight>> lit_of;
  const auto lit = [&](int order) -> const shade::GlossyLight& {
    auto& l = lit_of[order];
    if (!l) {
      std::string unused;
      const std::vector<float> light = environment_sh(env, order, unused);
      l = std::make_unique<shade::GlossyLight>(shade::TripleProduct(order), light.data());
    }
    return *l;
  };
  // A glossy object baked per texel: its lightmap (U or S), shaded per pixel.
  struct TexelGlossy {
    const TexelProduct* map = nullptr;
    bool route_b = false;
    double phong = 0;
  };
  std::vector<TexelGlossy> texel_glossy(objects.size());
  std::vector<bake::Mesh> parts;
  std::vector<float> rgb;
  std::vector<uint8_t> per_pixel;
  scene.first_triangle = {0};
  scene.how = "specular lobes (normalised Phong about the reflected view direction) x specular colour, Gouraud per vertex or\n"
              "  per pixel from a lightmap (bilinear through its mesh/uv), by\n"
              "  route B: prt::shade::shade_glossy_radiance_vertices on the baked radiance/shadowed (paper 001 sec. 4) or\n"
              "  route A: prt::shade::shade_glossy_vertices, environment SH x transfer/visibility by the triple product:";
  std::vector<std::string> glossy_names, glossy_how, others;
  for (size_t k = 0; k < objects.size(); ++k) {
    const SceneObject& o = objects[k];
    const size_t V = o.mesh.positions.size(), T = o.mesh.triangles.size();
    std::vector<float> colour(3 * V, 0.0f);
    const double s = o.receiver ? phong.value_or(o.phong) : 0.0;
    const bool per_texel = o.texel_visibility || o.texel_shadowed;
    if (o.receiver) {
      // Route B when the file holds S (unless --glossy-route a), else route A; per texel when the
      // object's lightmap holds them.
      const bool has_s = per_texel ? bool(o.texel_shadowed) : bool(o.shadowed);
      const bool has_u = per_texel ? bool(o.texel_visibility) : bool(o.visibility);
      const bool route_b = route == GlossyRoute::B || (route == GlossyRoute::Auto && has_s);
      if (!(route_b ? has_s : has_u))
        throw bake::InputError(file, "object '" + o.name + "' has no " + (per_texel ? "lightmap/" : "") +
                                         std::string((route_b ? F::names::kRadianceShadowed : F::names::kTransferVisibility).substr(1)) +
                                         " for --glossy-route " + (route_b ? "b" : "a"));
      const int order = per_texel ? (route_b ? o.texel_shadowed : o.texel_visibility)->order
                                  : (route_b ? o.shadowed : o.visibility)->order;
      const int max_order = route_b ? shade::kMaxShadowedOrder : shade::kMaxGlossyOrder;
      if (order < 1 || order > max_order)
        throw bake::InputError(file, "object '" + o.name + "': " + (route_b ? "shadowed radiance" : "visibility transfer") +
                                         " of order " + std::to_string(order) + " (glossy shading takes orders 1 to " +
                                         std::to_string(max_order) + ")");
      if (per_texel) {
        texel_glossy[k] = {&*(route_b ? o.texel_shadowed : o.texel_visibility), route_b, s};
        if (!route_b) lit(order);  // built here, read by the parallel shading below
      } else {
        std::vector<float> pos(3 * V), nrm(3 * V);
        for (size_t v = 0; v < V; ++v)
          for (int c = 0; c < 3; ++c) pos[3 * v + size_t(c)] = o.mesh.positions[v][c], nrm[3 * v + size_t(c)] = o.mesh.normals[v][c];
        const Vector3d eye_local = cam.eye - o.mesh.origin;
        const float eye[3] = {float(eye_local.x()), float(eye_local.y()), float(eye_local.z())};
        if (route_b) shade::shade_glossy_radiance_vertices(o.shadowed->coeffs, order, nrm.data(), pos.data(), V, eye, s, colour.data());
        else shade::shade_glossy_vertices(lit(order), o.visibility->coeffs, nrm.data(), pos.data(), V, eye, s, colour.data());
        for (size_t v = 0; v < V; ++v)
          for (size_t c = 0; c < 3; ++c) colour[3 * v + c] *= o.specular[c];
      }
      char buf[200];
      std::snprintf(buf, sizeof buf, "order %d, Phong %.4g%s, specular %.3g %.3g %.3g, route %s%s", order, s, phong ? " (--phong)" : "",
                    o.specular[0], o.specular[1], o.specular[2], route_b ? "B (radiance/shadowed)" : "A (transfer/visibility)",
                    per_texel ? (", per texel, " + std::to_string(texel_glossy[k].map->width) + "x" +
                                 std::to_string(texel_glossy[k].map->height) + " lightmap").c_str()
                              : ", per vertex");
      glossy_names.push_back(o.name);
      glossy_how.push_back(buf);
    }
    rgb.insert(rgb.end(), colour.begin(), colour.end());
    per_pixel.insert(per_pixel.end(), T, texel_glossy[k].map ? 1 : 0);
    scene.phong.insert(scene.phong.end(), T, s);
    scene.specular.insert(scene.specular.end(), T, o.receiver ? o.specular : std::array<float, 3>{0, 0, 0});
    add_object(scene, o);
    if (!o.receiver) others.push_back(o.name);
    parts.push_back(o.mesh);
  }
  add_grouped(scene.how, glossy_names, glossy_how);
  scene.what = "scene: " + std::to_string(objects.size()) + " objects, glossy lobes only: " + std::to_string(glossy_names.size()) +
               " glossy (" + name_list(glossy_names, 50) + ")" +
               (others.empty() ? "" : ", " + std::to_string(others.size()) + " drawn black (" + name_list(others, 40) + ")");
  scene.mesh = bake::merge_meshes(parts, file);
  const view::GBuffer g = view::rasterize(scene.mesh, cam);
  const Vector3d eye_local = cam.eye - scene.mesh.origin;  // the fragments' frame
  const float eye[3] = {float(eye_local.x()), float(eye_local.y()), float(eye_local.z())};
  std::atomic<size_t> texel_pixels{0}, empty_hits{0};
  view::Image image = view::shade_mixed(scene.mesh, g, rgb, per_pixel, [&](const view::Fragment& fr, float* out) {
    const size_t k = size_t(std::upper_bound(scene.first_triangle.begin(), scene.first_triangle.end(), size_t(fr.triangle)) -
                            scene.first_triangle.begin()) - 1;
    const TexelGlossy& tg = texel_glossy[k];
    const TexelProduct& t = *tg.map;
    const Eigen::Vector2d uv = view::fragment_uv(fr, *t.corner_uv, size_t(fr.triangle) - scene.first_triangle[k]);
    thread_local std::vector<float> sample;
    sample.resize(t.channels);
    if (view::sample_lightmap({t.width, t.height, t.channels, *t.values, *t.state}, uv.x(), uv.y(), sample.data())) ++empty_hits;
    ++texel_pixels;
    const float p[3] = {float(fr.p.x()), float(fr.p.y()), float(fr.p.z())};
    const float n[3] = {float(fr.n.x()), float(fr.n.y()), float(fr.n.z())};
    if (tg.route_b) shade::shade_glossy_radiance_vertices(sample.data(), t.order, n, p, 1, eye, tg.phong, out);
    else shade::shade_glossy_vertices(*lit_of.at(t.order), sample.data(), n, p, 1, eye, tg.phong, out);
    for (size_t c = 0; c < 3; ++c) out[c] *= objects[k].specular[c];
  });
  scene.texel_pixels = texel_pixels, scene.empty_texel_pixels = empty_hits;
  if (texel_pixels > 0)
    scene.how += "\n  per-texel objects: " + std::to_string(empty_hits.load()) + " of " + std::to_string(texel_pixels.load()) +
                 " of their pixels reached an empty texel";
  return image;
}

} // namespace prt::prtview
