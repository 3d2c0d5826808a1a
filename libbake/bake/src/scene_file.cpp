// scene_file.cpp — scene files and glTF scenes with their options files, read into a
// SceneDescription (bake/bake/scene.h: the format, the rules for glTF instances and options).
#include <bake/bake/choose.h>
#include <bake/bake/scene.h>
#include <bake/core/error.h>

#include "scene_json.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <set>
#include <span>
#include <sstream>
#include <vector>

namespace prt::bake {

using scene_json::find_key;
using scene_json::Json;
using scene_json::parse_json_file;
using scene_json::Reader;

const char* role_name(Role r) {
  switch (r) {
  case Role::Receiver: return "receiver";
  case Role::Occluder: return "occluder";
  case Role::Both: return "both";
  }
  return "?";
}

namespace {

constexpr double kHuge = 1e30;

// "rotate": [rx, ry, rz] in radians, about X, then Y, then Z.
Eigen::Matrix3d rotation_xyz(const Eigen::Vector3d& r) {
  return (Eigen::AngleAxisd(r.z(), Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(r.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(r.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

// An object's "transform" (translate/rotate/scale or matrix): its world_from_object matrix.
Eigen::Matrix4d parse_transform(const Reader& r, const Json& v, const std::string& key) {
  r.object(v, key, {"translate", "rotate", "scale", "matrix"});
  Eigen::Matrix4d M = Eigen::Matrix4d::Identity();
  if (const Json* m = find_key(v, "matrix")) {
    if (v.size() != 1) r.fail(key + ": give either \"matrix\" or translate/rotate/scale, not both");
    if (!m->is_array() || m->size() != 16) r.fail(key + ".matrix must be an array of 16 numbers (row-major 4x4)");
    for (int i = 0; i < 16; ++i)
      M(i / 4, i % 4) = r.number((*m)[size_t(i)], key + ".matrix[" + std::to_string(i) + "]", -kHuge, kHuge);
    if (M(3, 0) != 0 || M(3, 1) != 0 || M(3, 2) != 0 || M(3, 3) != 1)
      r.fail(key + ".matrix must be affine: its last row must be 0 0 0 1");
  } else {
    Eigen::Vector3d t(0, 0, 0), rot(0, 0, 0), s(1, 1, 1);
    if (const Json* x = find_key(v, "translate")) {
      const auto a = r.vec3(*x, key + ".translate", -kHuge, kHuge);
      t = Eigen::Vector3d(a[0], a[1], a[2]);
    }
    if (const Json* x = find_key(v, "rotate")) {
      const auto a = r.vec3(*x, key + ".rotate", -36000, 36000);
      rot = Eigen::Vector3d(a[0], a[1], a[2]) * (std::numbers::pi / 180);
    }
    if (const Json* x = find_key(v, "scale")) {
      if (x->is_number()) {
        const double k = r.number(*x, key + ".scale", -kHuge, kHuge);
        s = Eigen::Vector3d(k, k, k);
      } else {
        const auto a = r.vec3(*x, key + ".scale", -kHuge, kHuge);
        s = Eigen::Vector3d(a[0], a[1], a[2]);
      }
    }
    const Eigen::Matrix3d R = rotation_xyz(rot);
    M.topLeftCorner<3, 3>() = R * s.asDiagonal();
    M.topRightCorner<3, 1>() = t;
  }
  // Well-conditioned, before any work: normals go through A⁻ᵀ in double, which loses log10(κ) of
  // double's ~16 digits (κ = σ_max/σ_min); κ ≤ 1e8 keeps 8, more than a float normal holds.
  // A singular or nearly singular A (a scale of 1e-310 next to 1e30) is refused here, naming the
  // object, instead of baking and then failing on NaN normals.
  constexpr double kMaxCondition = 1e8;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(M.topLeftCorner<3, 3>());
  const Eigen::Vector3d sv = svd.singularValues();  // descending
  const double kappa = sv[2] > 0 ? sv[0] / sv[2] : std::numeric_limits<double>::infinity();
  if (!sv.allFinite() || !(kappa <= kMaxCondition) || !M.topLeftCorner<3, 3>().inverse().allFinite()) {
    std::ostringstream os;
    os << key << " is singular or nearly so (singular values " << sv[0] << ", " << sv[1] << ", " << sv[2]
       << "; condition number " << kappa << " > " << kMaxCondition << "): it would flatten the object";
    r.fail(os.str());
  }
  return M;
}

constexpr std::array<double, 3> kDefaultAlbedo{0.8, 0.8, 0.8};  // an object without a material

bool valid_name(const std::string& n) {
  if (n.empty() || n.size() > 128) return false;
  for (char c : n)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.')) return false;
  return n != "." && n != "..";
}

// A path of the file `file` refers to: relative paths are relative to its directory.
std::filesystem::path resolve_beside(const std::filesystem::path& file, const std::string& p) {
  const std::filesystem::path q(p);
  if (q.is_absolute()) return q;
  return (file.has_parent_path() ? file.parent_path() : std::filesystem::path(".")) / q;
}

// The file's `version_key` must be 1; `what` names the file ("the scene"), `kind` its kind ("scene-file").
void check_version(const Reader& r, const Json& root, const char* version_key, const std::string& what, const std::string& kind) {
  const Json* version = find_key(root, version_key);
  if (version == nullptr) r.fail(what + " lacks \"" + version_key + "\": 1 (the " + kind + " version)");
  const int64_t v = r.integer(*version, version_key, 1, 1000);
  if (v != 1) r.fail(std::string(version_key) + " version " + std::to_string(v) + " is newer than this prtbake reads (1)");
}

// A "lightmap" (`key`): an object, or false (per vertex: nullopt).
std::optional<LightmapSpec> parse_lightmap(const Reader& r, const Json& v, const std::string& key) {
  if (v.is_boolean() && !v.get<bool>()) return std::nullopt;
  if (!v.is_object())
    r.fail(key + " must be an object {\"resolution\": N} or {\"density\": T} (and \"uv\", \"unwrap\", \"gutter\", "
                 "\"padding\", \"stitch\"), or false");
  r.object(v, key, {"resolution", "density", "uv", "unwrap", "gutter", "padding", "stitch", "min_chart_texels"});
  LightmapSpec spec;
  const Json* res = find_key(v, "resolution");
  const Json* den = find_key(v, "density");
  if ((res != nullptr) == (den != nullptr)) r.fail(key + " needs one of \"resolution\" (texels) and \"density\" (texels per unit)");
  if (res && res->is_array()) {
    if (res->size() != 2) r.fail(key + ".resolution must be N or [W, H]");
    spec.width = uint32_t(r.integer((*res)[0], key + ".resolution[0]", 1, kMaxLightmapSide));
    spec.height = uint32_t(r.integer((*res)[1], key + ".resolution[1]", 1, kMaxLightmapSide));
  } else if (res) {
    spec.width = spec.height = uint32_t(r.integer(*res, key + ".resolution", 1, kMaxLightmapSide));
  } else {
    spec.density = r.number(*den, key + ".density", 0, 1e12);
    if (!(spec.density > 0)) r.fail(key + ".density must be > 0 (texels per unit)");
  }
  if (const Json* x = find_key(v, "uv")) spec.uv_set = r.string(*x, key + ".uv");
  if (const Json* x = find_key(v, "unwrap")) spec.unwrap = r.boolean(*x, key + ".unwrap");
  if (!spec.uv_set.empty() && spec.unwrap) r.fail(key + ": \"uv\" names the asset's set and \"unwrap\" generates one: give one");
  if (const Json* x = find_key(v, "gutter")) spec.gutter = uint32_t(r.integer(*x, key + ".gutter", 0, 64));
  if (const Json* x = find_key(v, "padding")) spec.padding = uint32_t(r.integer(*x, key + ".padding", 0, 64));
  if (const Json* x = find_key(v, "stitch")) spec.stitch = r.boolean(*x, key + ".stitch");
  if (const Json* x = find_key(v, "min_chart_texels"))
    spec.min_chart_texels = uint32_t(r.integer(*x, key + ".min_chart_texels", 0, 64));
  return spec;
}

// "up", "environment" and "bake" of a scene file or a glTF scene's options (`file`).
void parse_settings(const Reader& r, const Json& root, const std::filesystem::path& file, SceneDescription& sc) {
  if (const Json* up = find_key(root, "up")) {
    const std::string& u = r.string(*up, "up");
    if (u != "y" && u != "z") r.fail("up must be \"y\" or \"z\", not \"" + u + "\"");
    sc.up = u == "y" ? UpAxis::Y : UpAxis::Z;
  }
  if (const Json* env = find_key(root, "environment")) sc.environment = resolve_beside(file, r.string(*env, "environment"));
  if (const Json* bake = find_key(root, "bake")) {
    r.object(*bake, "bake",
             {"products", "integrator", "samples", "seed", "report", "target_error", "sh_tolerance", "relight", "fiv",
              "lightmap", "bounces", "bounce_rays"});
    if (const Json* x = find_key(*bake, "lightmap")) sc.lightmap = parse_lightmap(r, *x, "bake.lightmap");
    if (const Json* p = find_key(*bake, "products")) {
      if (!p->is_array()) r.fail("bake.products must be an array of strings");
      sc.want_ao = sc.want_transfer = sc.want_radiance = sc.want_fiv = false;
      for (size_t i = 0; i < p->size(); ++i) {
        const std::string& s = r.string((*p)[i], "bake.products[" + std::to_string(i) + "]");
        if (s == "ao") sc.want_ao = true;
        else if (s == "transfer") sc.want_transfer = true;
        else if (s == "radiance") sc.want_radiance = true;
        else if (s == "fiv") sc.want_fiv = true;
        else r.fail("unknown product \"" + s + "\" in bake.products (ao, transfer, radiance, fiv)");
      }
    }
    if (const Json* x = find_key(*bake, "integrator")) {
      const std::string& name = r.string(*x, "bake.integrator");
      const auto kind = parse_integrator_kind(name);
      if (!kind) r.fail("bake.integrator must be \"silhouette\", \"qmc\" or \"filter\", not \"" + name + "\"");
      sc.integrator.kind = *kind;
      sc.integrator_given = true;
    }
    // The knob of the chosen integrator: k for silhouette, rays for qmc.
    if (const Json* x = find_key(*bake, "samples")) sc.integrator.set_samples(uint32_t(r.integer(*x, "bake.samples", 4, 1 << 24)));
    if (const Json* x = find_key(*bake, "seed")) sc.integrator.seed = uint64_t(r.integer(*x, "bake.seed", 0, int64_t(1) << 52));
    if (const Json* x = find_key(*bake, "report"))
      sc.integrator.report_points = uint32_t(r.integer(*x, "bake.report", 0, 1 << 20));
    if (const Json* x = find_key(*bake, "target_error")) {
      sc.target_error = r.number(*x, "bake.target_error", ChooserOptions::kMinTarget, ChooserOptions::kMaxTarget);
      if (find_key(*bake, "samples"))
        r.fail("bake.target_error and bake.samples both given: the target chooses the samples (give one)");
      if (!find_key(*bake, "report")) sc.integrator.report_points = ChooserOptions::kReportPoints;
    }
    if (sc.integrator.kind == IntegratorKind::Filter && !find_key(*bake, "samples"))
      r.fail("bake.integrator \"filter\" needs bake.samples, its pass-1 rays per vertex (4-32): the target-error "
             "chooser has no model of the filter integrator");
    if (const Json* x = find_key(*bake, "sh_tolerance")) {
      sc.sh_tolerance = r.number(*x, "bake.sh_tolerance", 0, 1);
      if (!(sc.sh_tolerance > 0)) r.fail("bake.sh_tolerance must be > 0");
    }
    if (const Json* x = find_key(*bake, "relight")) sc.relight = r.boolean(*x, "bake.relight");
    if (const Json* x = find_key(*bake, "bounces")) sc.bounces = int(r.integer(*x, "bake.bounces", 0, 100));
    if (const Json* x = find_key(*bake, "bounce_rays")) {
      sc.bounce_rays = uint32_t(r.integer(*x, "bake.bounce_rays", 1, 1 << 16));
      if (sc.bounces == 0) r.fail("bake.bounce_rays applies with bake.bounces >= 1");
    }
    if (const Json* f = find_key(*bake, "fiv")) {
      r.object(*f, "bake.fiv", {"shells", "cube", "fraction", "radial", "precision", "self_shadows"});
      // The two-word keys: each its parser and the words it takes.
      const auto choice = [&](const char* key, const char* words, auto&& parse) {
        if (const Json* x = find_key(*f, key)) {
          const std::string& g = r.string(*x, std::string("bake.fiv.") + key);
          if (!parse(g)) r.fail(std::string("bake.fiv.") + key + " must be " + words + ", not \"" + g + "\"");
        }
      };
      choice("self_shadows", "\"vertex\" or \"shells\"", [&](const std::string& g) { return parse_self_shadows(g, sc.fiv.vertex_self_shadows); });
      choice("precision", "\"half\" or \"float\"", [&](const std::string& g) { return parse_shell_precision(g, sc.fiv.float16); });
      choice("radial", "\"surface\" or \"geometric\"", [&](const std::string& g) { return parse_radial_scheme(g, sc.fiv.radial); });
      if (const Json* x = find_key(*f, "shells")) {
        const std::string& g = r.string(*x, "bake.fiv.shells");
        if (!parse_shell_grid(g, sc.fiv))
          r.fail("bake.fiv.shells must be \"NPHIxNTHETAxNRHO\" (e.g. \"128x65x30\"; NPHI >= 1, NTHETA >= 2), not \"" + g +
                 "\"");
      }
      if (const Json* x = find_key(*f, "cube")) sc.fiv.cube = int(r.integer(*x, "bake.fiv.cube", 1, 1024));
      if (const Json* x = find_key(*f, "fraction")) {
        sc.fiv.fraction = r.number(*x, "bake.fiv.fraction", 0, 0.5);
        if (!(sc.fiv.fraction > 0)) r.fail("bake.fiv.fraction must be > 0");
      }
    }
  }
  // The FIV shells are always baked with the silhouette integrator: at the scene's k for a
  // silhouette scene, at the default k for a qmc one.
  sc.fiv.silhouette_k = sc.integrator.silhouette_k;
  // Neither "samples" nor "target_error": the default target, and the same report as a named
  // target's (kReportPoints unless "report" is given), as prtbake vertex: the same request gets
  // the same check.
  const Json* bake = find_key(root, "bake");
  if (!bake || (!find_key(*bake, "samples") && !find_key(*bake, "target_error"))) {
    sc.target_error = ChooserOptions{}.target;
    if (!bake || !find_key(*bake, "report")) sc.integrator.report_points = ChooserOptions::kReportPoints;
  }
}

Role parse_role(const Reader& r, const Json& v, const std::string& key) {
  const std::string& rs = r.string(v, key);
  if (rs == "receiver") return Role::Receiver;
  if (rs == "occluder") return Role::Occluder;
  if (rs == "both") return Role::Both;
  r.fail(key + " must be \"receiver\", \"occluder\" or \"both\", not \"" + rs + "\"");
}

// An object's "material" (`key`) for an object of role `role`.
Material parse_material(const Reader& r, const Json& m, const std::string& key, Role role) {
  r.object(m, key, {"albedo", "phong_exponent", "specular"});
  Material material;
  if (const Json* a = find_key(m, "albedo")) material.albedo = r.vec3(*a, key + ".albedo", 0, 1);
  if (const Json* x = find_key(m, "phong_exponent")) material.phong_exponent = r.number(*x, key + ".phong_exponent", 0, 1e6);
  if (const Json* x = find_key(m, "specular")) {
    material.specular = r.vec3(*x, key + ".specular", 0, 1);
    if (!material.glossy()) r.fail(key + ".specular needs phong_exponent > 0");
  } else if (material.glossy()) {
    material.specular = {1, 1, 1};
  }
  if (role != Role::Occluder && !material.diffuse() && !material.glossy())
    r.fail(key + " has neither a diffuse albedo > 0 nor a phong_exponent > 0: the receiver reflects nothing");
  return material;
}

constexpr const char* kLightShapes = "quad, polygon, disc, box, cylinder, sphere, point, spot or directional";

// "lights" (bake/lights/lights.h shapes and bake/lights/punctual.h kinds): every light validated,
// names unique ("light<i>" by default). An error names the light by its index and, when it has
// one, its name.
void parse_lights(const Reader& r, const Json& v, const std::string& file, SceneDescription& sc) {
  if (!v.is_array()) r.fail("lights must be an array of light objects");
  std::vector<AreaLight>& out = sc.lights;
  out.clear();
  sc.punctual_lights.clear();
  std::set<std::string> names;
  for (size_t i = 0; i < v.size(); ++i) {
    const Json& l = v[i];
    std::string key = "lights[" + std::to_string(i) + "]";
    if (!l.is_object()) r.fail(key + " must be an object, not " + l.type_name());
    std::string light_name = "light" + std::to_string(i);
    if (const Json* n = find_key(l, "name")) {
      light_name = r.string(*n, key + ".name");
      if (!valid_name(light_name)) r.fail(key + ".name \"" + light_name + "\" must be 1-128 characters of A-Z a-z 0-9 _ - .");
    }
    if (!names.insert(light_name).second) r.fail(key + ": the name \"" + light_name + "\" is already used by another light");
    // How messages name it: its index, and its name when the file gives one.
    const std::string who = find_key(l, "name") ? key + " (light \"" + light_name + "\")" : key;
    const Json* shape = find_key(l, "shape");
    if (shape == nullptr) r.fail(who + " lacks \"shape\": " + kLightShapes);
    const std::string& kind = r.string(*shape, key + ".shape");
    auto need = [&](const char* member) -> const Json& {
      const Json* x = find_key(l, member);
      if (x == nullptr) r.fail(key + " (" + kind + ") lacks \"" + member + "\"");
      return *x;
    };
    auto point = [&](const char* member) {
      const auto a = r.vec3(need(member), key + "." + member, -kHuge, kHuge);
      return Eigen::Vector3d(a[0], a[1], a[2]);
    };
    auto positive = [&](const char* member) {
      const double x = r.number(need(member), key + "." + member, 0, kHuge);
      if (!(x > 0)) r.fail(key + "." + member + " must be > 0");
      return x;
    };
    auto count = [&](const char* member, int64_t lo, int64_t hi, int64_t fallback) {
      const Json* x = find_key(l, member);
      return x ? int(r.integer(*x, key + "." + member, lo, hi)) : int(fallback);
    };
    auto rotation = [&] {
      Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
      if (const Json* x = find_key(l, "rotate")) {
        const auto a = r.vec3(*x, key + ".rotate", -36000, 36000);
        R = rotation_xyz(Eigen::Vector3d(a[0], a[1], a[2]) * (std::numbers::pi / 180));
      }
      return R;
    };
    const bool punctual = kind == "point" || kind == "spot" || kind == "directional";
    static constexpr std::string_view kAreaKeys[] = {"name", "shape", "radiance", "two_sided"};
    static constexpr std::string_view kPunctualKeys[] = {"name", "shape", "intensity"};
    const std::span<const std::string_view> common = punctual ? std::span<const std::string_view>(kPunctualKeys)
                                                              : std::span<const std::string_view>(kAreaKeys);
    auto allow = [&](std::initializer_list<std::string_view> own) {
      std::vector<std::string_view> all(common.begin(), common.end());
      all.insert(all.end(), own.begin(), own.end());
      for (const auto& [k, member] : l.items())
        if (std::find(all.begin(), all.end(), k) == all.end()) {
          std::string list;
          for (std::string_view a : all) list += (list.empty() ? "" : ", ") + std::string(a);
          r.fail("unknown key \"" + k + "\" in " + who + " (a " + kind + " light takes " + list + ")");
        }
    };
    auto degrees = [&](const char* member, double fallback, double lo, double hi) {
      const Json* x = find_key(l, member);
      const double deg = x ? r.number(*x, key + "." + member, -kHuge, kHuge) : fallback;
      if (!(deg >= lo && deg <= hi)) {
        std::ostringstream os;
        os << who << ": " << member << " must be in [" << lo << ", " << hi << "] degrees, got " << deg;
        r.fail(os.str());
      }
      return deg * (std::numbers::pi / 180);
    };
    if (punctual) {
      PunctualLight p;
      p.name = light_name;
      const auto intensity = r.vec3(need("intensity"), key + ".intensity", -kHuge, kHuge);
      for (size_t c = 0; c < 3; ++c)
        if (!(intensity[c] >= 0))
          r.fail(who + ": intensity[" + std::to_string(c) + "] must be >= 0 (" +
                 (kind == "directional" ? "lux" : "candela") + " per channel)");
      p.intensity = intensity;
      auto direction = [&] {
        const Eigen::Vector3d d = point("direction");
        if (!(d.norm() > 0)) r.fail(who + ": direction must not be zero");
        return Eigen::Vector3d(d.normalized());
      };
      if (kind == "point") {
        allow({"position", "radius", "subdivisions", "range"});
        p.kind = PunctualKind::Point;
        p.position = point("position");
        if (find_key(l, "radius")) {
          if (find_key(l, "range")) r.fail(who + ": \"range\" is for a point light; with \"radius\" it is a sphere light, which has none");
          validate_punctual_light(p, file, who);
          AreaLight bulb = bulb_light(p, positive("radius"), count("subdivisions", 0, kMaxSphereSubdivisions, 3));
          validate_light(bulb, file, who);
          out.push_back(std::move(bulb));
          continue;
        }
        if (find_key(l, "subdivisions")) r.fail(who + ": \"subdivisions\" needs \"radius\" (a sphere light)");
      } else if (kind == "spot") {
        allow({"position", "direction", "inner_cone_angle", "outer_cone_angle", "range"});
        p.kind = PunctualKind::Spot;
        p.position = point("position");
        p.direction = direction();
        p.inner_cone = degrees("inner_cone_angle", 0, 0, 90);
        p.outer_cone = degrees("outer_cone_angle", 45, 0, 90);
      } else {
        allow({"direction", "angle", "segments"});
        p.kind = PunctualKind::Directional;
        p.direction = direction();
        if (find_key(l, "angle")) {
          p.angular_diameter = degrees("angle", 0, 0, 90);
          if (!(p.angular_diameter > 0)) r.fail(who + ": angle must be > 0 degrees (the sun's angular diameter)");
          p.segments = count("segments", kMinSegments, kMaxSegments, 64);
        } else if (find_key(l, "segments")) {
          r.fail(who + ": \"segments\" needs \"angle\" (a sun disc)");
        }
      }
      if (find_key(l, "range")) p.range = positive("range");
      validate_punctual_light(p, file, who);
      sc.punctual_lights.push_back(std::move(p));
      continue;
    }
    AreaLight light;
    if (kind == "quad") {
      allow({"centre", "u", "v"});
      light = make_quad_light(point("centre"), point("u"), point("v"));
    } else if (kind == "polygon") {
      allow({"vertices"});
      const Json& vs = need("vertices");
      if (!vs.is_array() || vs.size() < 3 || vs.size() > size_t(kMaxSegments))
        r.fail(key + ".vertices must be an array of 3 to " + std::to_string(kMaxSegments) + " points [x, y, z]");
      std::vector<Eigen::Vector3d> corners;
      for (size_t k = 0; k < vs.size(); ++k) {
        const auto a = r.vec3(vs[k], key + ".vertices[" + std::to_string(k) + "]", -kHuge, kHuge);
        corners.emplace_back(a[0], a[1], a[2]);
      }
      light = make_polygon_light(std::move(corners));
    } else if (kind == "disc") {
      allow({"centre", "normal", "radius", "segments"});
      const Eigen::Vector3d n = point("normal");
      if (!(n.norm() > 0)) r.fail(key + ".normal must not be zero");
      light = make_disc_light(point("centre"), n, positive("radius"), count("segments", kMinSegments, kMaxSegments, 64));
    } else if (kind == "box") {
      allow({"centre", "size", "rotate"});
      const Eigen::Vector3d size = point("size");
      if (!(size.minCoeff() > 0)) r.fail(key + ".size must be > 0 in every axis");
      light = make_box_light(point("centre"), size, rotation());
    } else if (kind == "cylinder") {
      allow({"centre", "radius", "height", "segments", "rotate"});
      light = make_cylinder_light(point("centre"), positive("radius"), positive("height"),
                                  count("segments", kMinSegments, kMaxSegments, 64), rotation());
    } else if (kind == "sphere") {
      allow({"centre", "radius", "subdivisions"});
      light = make_sphere_light(point("centre"), positive("radius"), count("subdivisions", 0, kMaxSphereSubdivisions, 3));
    } else {
      r.fail(key + ".shape must be " + kLightShapes + ", not \"" + kind + "\"");
    }
    light.radiance = r.vec3(need("radiance"), key + ".radiance", 0, kHuge);
    if (const Json* x = find_key(l, "two_sided")) light.two_sided = r.boolean(*x, key + ".two_sided");
    light.name = light_name;
    validate_light(light, file, key);
    out.push_back(std::move(light));
  }
}

SceneDescription load_json_scene(const std::filesystem::path& file) {
  const Json root = parse_json_file(file);
  const Reader r(file.string());
  r.object(root, "the scene", {"prtbake_scene", "up", "environment", "bake", "lights", "objects"});
  SceneDescription sc;
  sc.file = file;
  check_version(r, root, "prtbake_scene", "the scene", "scene-file");
  parse_settings(r, root, file, sc);
  if (const Json* lights = find_key(root, "lights")) parse_lights(r, *lights, file.string(), sc);
  const Json* objects = find_key(root, "objects");
  if (objects == nullptr) r.fail("the scene lacks \"objects\" (an array of one or more objects)");
  if (!objects->is_array() || objects->empty()) r.fail("objects must be a non-empty array");
  std::set<std::string> names;
  for (size_t i = 0; i < objects->size(); ++i) {
    const Json& o = (*objects)[i];
    const std::string key = "objects[" + std::to_string(i) + "]";
    r.object(o, key, {"name", "mesh", "role", "transform", "material", "moves", "lightmap"});
    SceneObject obj;
    const Json* mesh = find_key(o, "mesh");
    if (mesh == nullptr) r.fail(key + " lacks \"mesh\" (the mesh file)");
    const std::string& mesh_path = r.string(*mesh, key + ".mesh");
    obj.mesh = resolve_beside(file, mesh_path);
    if (const Json* n = find_key(o, "name")) {
      obj.name = r.string(*n, key + ".name");
      if (!valid_name(obj.name))
        r.fail(key + ".name \"" + obj.name + "\" must be 1-128 characters of A-Z a-z 0-9 _ - .");
    } else {
      obj.name = std::filesystem::path(mesh_path).stem().string();
      for (char& c : obj.name)
        if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.')) c = '_';
      if (!valid_name(obj.name)) obj.name = "object" + std::to_string(i);
    }
    if (!names.insert(obj.name).second)
      r.fail(key + ": the name \"" + obj.name + "\" is already used by another object (names must be unique; set \"name\")");
    const Json* role = find_key(o, "role");
    if (role == nullptr) r.fail(key + " lacks \"role\": \"receiver\", \"occluder\" or \"both\"");
    obj.role = parse_role(r, *role, key + ".role");
    if (const Json* t = find_key(o, "transform")) obj.world_from_object = parse_transform(r, *t, key + ".transform");
    obj.material.albedo = kDefaultAlbedo;
    if (const Json* m = find_key(o, "material")) obj.material = parse_material(r, *m, key + ".material", obj.role);
    if (const Json* mv = find_key(o, "moves")) {
      obj.moves = r.boolean(*mv, key + ".moves");
      obj.moves_reason = std::string("\"moves\": ") + (obj.moves ? "true" : "false") + " in the scene file";
    }
    const Json* lm = find_key(o, "lightmap");
    obj.lightmap = lm ? parse_lightmap(r, *lm, key + ".lightmap") : sc.lightmap;
    sc.objects.push_back(std::move(obj));
  }
  return sc;
}

// A glTF scene (bake/bake/scene.h "glTF scenes"): one object per instance, then the options file.
// A glTF's KHR_lights_punctual lights (bake/bake/scene.h "glTF scenes"): each instance a punctual
// light named by the light's name (made a valid name; "light<index>" without one; "_2", "_3", ...
// when taken), validated; the options' "gltf_lights" give a point light a radius (a sphere light)
// or a directional light an angle (a sun), or skip one. Appended after the options' own lights.
void add_gltf_lights(const std::filesystem::path& file, const std::vector<GltfLight>& lights, const Json* extents,
                     const Reader& r, SceneDescription& sc) {
  std::set<std::string> names;
  for (const std::string& n : sc.light_names()) names.insert(n);
  struct Extent {
    const Json* value;
    bool used = false;
  };
  std::map<std::string, Extent> given;
  if (extents != nullptr) {
    if (!extents->is_object()) r.fail("gltf_lights must be an object {\"<light name>\": {\"radius\": r} | {\"angle\": degrees} | {\"skip\": true}}");
    for (const auto& [k, v] : extents->items()) given.emplace(k, Extent{&v});
  }
  for (const GltfLight& g : lights) {
    std::string name = g.name.empty() ? "light" + std::to_string(g.index) : g.name;
    for (char& c : name)
      if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.')) c = '_';
    if (name.size() > 120) name.resize(120);
    if (!valid_name(name)) name = "light" + std::to_string(g.index);
    const std::string base = name;
    for (int k = 2; names.count(name); ++k) name = base + "_" + std::to_string(k);
    names.insert(name);
    const std::string who = "KHR_lights_punctual light " + std::to_string(g.index) + " \"" + name + "\" (node " + g.node_path + ")";
    PunctualLight p;
    p.name = name;
    p.kind = g.type == "directional" ? PunctualKind::Directional : g.type == "spot" ? PunctualKind::Spot : PunctualKind::Point;
    p.position = g.position;
    p.direction = g.direction;
    for (size_t c = 0; c < 3; ++c) p.intensity[c] = g.color[c] * g.intensity;
    p.inner_cone = g.inner_cone;
    p.outer_cone = g.outer_cone;
    if (p.kind != PunctualKind::Directional) p.range = g.range;  // the extension allows none on a directional light
    validate_punctual_light(p, file.string(), who);
    const auto it = given.find(name);
    if (it != given.end()) {
      it->second.used = true;
      const Json& e = *it->second.value;
      const std::string key = "gltf_lights.\"" + name + "\"";
      r.object(e, key, {"radius", "subdivisions", "angle", "segments", "skip"});
      if (const Json* skip = find_key(e, "skip"); skip && r.boolean(*skip, key + ".skip")) continue;
      if (const Json* radius = find_key(e, "radius")) {
        if (p.kind != PunctualKind::Point) r.fail(key + ": \"radius\" is for a point light (this is a " + g.type + " light)");
        const double rad = r.number(*radius, key + ".radius", 0, kHuge);
        if (!(rad > 0)) r.fail(key + ".radius must be > 0");
        const Json* sub = find_key(e, "subdivisions");
        if (p.range > 0)
          sc.warnings.push_back(who + ": its range " + std::to_string(p.range) + " is not applied: with a radius (" + key +
                                ") it is a sphere light, whose light follows its size, not a window");
        AreaLight bulb = bulb_light(p, rad, sub ? int(r.integer(*sub, key + ".subdivisions", 0, kMaxSphereSubdivisions)) : 3);
        validate_light(bulb, file.string(), who);
        sc.lights.push_back(std::move(bulb));
        continue;
      }
      if (const Json* angle = find_key(e, "angle")) {
        if (p.kind != PunctualKind::Directional) r.fail(key + ": \"angle\" is for a directional light (this is a " + g.type + " light)");
        const double deg = r.number(*angle, key + ".angle", 0, 90);
        if (!(deg > 0)) r.fail(key + ".angle must be > 0 degrees (the sun's angular diameter)");
        p.angular_diameter = deg * (std::numbers::pi / 180);
        if (const Json* seg = find_key(e, "segments")) p.segments = int(r.integer(*seg, key + ".segments", kMinSegments, kMaxSegments));
      }
    }
    sc.punctual_lights.push_back(std::move(p));
  }
  std::string unknown;
  for (const auto& [k, e] : given)
    if (!e.used) unknown += (unknown.empty() ? "\"" : ", \"") + k + "\"";
  if (!unknown.empty()) r.fail("gltf_lights: " + unknown + " names no KHR_lights_punctual light of " + file.string());
}

SceneDescription load_gltf_scene(const std::filesystem::path& file, const std::optional<std::filesystem::path>& options) {
  SceneDescription sc;
  sc.file = file;
  sc.options = options;
  MeshInstances instances = load_mesh_instances(file);
  for (const MeshInstance& in : instances.instances) {
    SceneObject& obj = sc.objects.emplace_back();
    obj.name = in.name;
    std::replace(obj.name.begin(), obj.name.end(), '/', '|');
    obj.node_path = in.name;
    obj.mesh = file;
    obj.moves = in.animated;
    obj.moves_reason = in.animated ? "an animation moves its node" : "no animation moves its node";
    obj.material.albedo = kDefaultAlbedo;
    if (in.base_color)
      for (size_t c = 0; c < 3; ++c) obj.material.albedo[c] = std::clamp((*in.base_color)[c], 0.0, 1.0);
  }
  if (!options) {
    add_gltf_lights(file, instances.lights, nullptr, Reader(file.string()), sc);
    return sc;
  }
  const Json root = parse_json_file(*options);
  const Reader r(options->string());
  r.object(root, "the scene options", {"prtbake_gltf_scene", "up", "environment", "bake", "lights", "gltf_lights", "objects"});
  check_version(r, root, "prtbake_gltf_scene", "the scene options", "options-file");
  parse_settings(r, root, *options, sc);
  for (SceneObject& obj : sc.objects) obj.lightmap = sc.lightmap;  // bake.lightmap, unless an entry says otherwise
  if (const Json* lights = find_key(root, "lights")) parse_lights(r, *lights, options->string(), sc);
  add_gltf_lights(file, instances.lights, find_key(root, "gltf_lights"), r, sc);
  const Json* objects = find_key(root, "objects");
  if (objects == nullptr) return sc;
  if (!objects->is_object()) r.fail(std::string("objects must be an object {\"<node path>\": {\"role\": ..., \"material\": ...}}, not ") + objects->type_name());
  // Each entry applies to the instances it names (its own name, or a node path above it); for
  // each field the most specific (longest) entry that sets it wins.
  struct Entry {
    std::string key;
    std::optional<Role> role;
    std::optional<Material> material;
    std::optional<bool> moves;
    std::optional<std::optional<LightmapSpec>> lightmap;
    bool used = false;
  };
  std::vector<Entry> entries;
  for (const auto& [key, value] : objects->items()) {
    const std::string path = "objects.\"" + key + "\"";
    r.object(value, path, {"role", "material", "moves", "lightmap"});
    Entry& e = entries.emplace_back();
    e.key = key;
    if (const Json* role = find_key(value, "role")) e.role = parse_role(r, *role, path + ".role");
    if (const Json* m = find_key(value, "material")) e.material = parse_material(r, *m, path + ".material", e.role.value_or(Role::Both));
    if (const Json* mv = find_key(value, "moves")) e.moves = r.boolean(*mv, path + ".moves");
    if (const Json* lm = find_key(value, "lightmap")) e.lightmap = parse_lightmap(r, *lm, path + ".lightmap");
  }
  auto names = [](const std::string& instance, const std::string& key) {
    return instance.starts_with(key) && (instance.size() == key.size() || instance[key.size()] == '/' || instance[key.size()] == '#');
  };
  for (SceneObject& obj : sc.objects) {
    const Entry* role = nullptr;
    const Entry* material = nullptr;
    const Entry* moves = nullptr;
    const Entry* lightmap = nullptr;
    for (Entry& e : entries) {
      if (!names(obj.node_path, e.key)) continue;
      e.used = true;
      if (e.role && (!role || e.key.size() > role->key.size())) role = &e;
      if (e.material && (!material || e.key.size() > material->key.size())) material = &e;
      if (e.moves && (!moves || e.key.size() > moves->key.size())) moves = &e;
      if (e.lightmap && (!lightmap || e.key.size() > lightmap->key.size())) lightmap = &e;
    }
    if (lightmap) obj.lightmap = *lightmap->lightmap;
    if (role) obj.role = *role->role;
    if (material) obj.material = *material->material;
    if (moves) {
      obj.moves = *moves->moves;
      obj.moves_reason = std::string("\"moves\": ") + (obj.moves ? "true" : "false") + " in the options (objects.\"" + moves->key + "\")";
    }
  }
  std::string unknown;
  for (const Entry& e : entries)
    if (!e.used) unknown += (unknown.empty() ? "\"" : ", \"") + e.key + "\"";
  if (!unknown.empty())
    r.fail("objects: " + unknown + " names no node of " + file.string() + " (keys are node paths or instance names as prtdump shows them, e.g. \"" +
           sc.objects.front().node_path + "\")");
  return sc;
}

} // namespace

bool is_gltf_scene(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".gltf" || ext == ".glb";
}

SceneDescription load_scene(const std::filesystem::path& file, const std::optional<std::filesystem::path>& gltf_options) {
  if (is_gltf_scene(file)) return load_gltf_scene(file, gltf_options);
  if (gltf_options)
    throw InputError(gltf_options->string(), "scene options apply to a glTF scene only; " + file.string() + " is a JSON scene file");
  return load_json_scene(file);
}

} // namespace prt::bake
