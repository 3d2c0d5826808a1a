// scene.cpp — scene files and the bake plan (bake/bake/scene.h).
#include <bake/bake/fiv.h>
#include <bake/bake/scene.h>
#include <bake/core/error.h>
#include <bake/sphere/zonal.h>

#include <prtshade/sh.h>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <nlohmann/json.hpp>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <numbers>
#include <set>
#include <sstream>
#include <vector>

namespace prt::bake {

const char* role_name(Role r) {
  switch (r) {
  case Role::Receiver: return "receiver";
  case Role::Occluder: return "occluder";
  case Role::Both: return "both";
  }
  return "?";
}

namespace {

using Json = nlohmann::ordered_json;  // keeps the file's key order, so messages follow it

constexpr size_t kMaxDepth = 128;  // nesting deeper than this is refused

// "objects[2].material" for the value at that path; "the scene" for the root.
std::string shown_path(const std::string& path) { return path.empty() ? "the scene" : path; }

// Parses a scene file strictly: nlohmann's RFC 8259 parser (syntax errors with line and column),
// and what it lets through refused here with the key path: a duplicate key (nlohmann keeps the
// last one silently) and nesting deeper than kMaxDepth.
Json parse_json(const std::string& text, const std::string& file) {
  struct Container {
    std::string path;
    bool object = false;
    std::set<std::string> keys;
    std::string key;    // object: the member being read
    size_t index = 0;   // array: the next element's index
  };
  std::vector<Container> open;
  auto child_path = [&]() -> std::string {
    if (open.empty()) return "";
    Container& c = open.back();
    if (c.object) return (c.path.empty() ? "" : c.path + ".") + c.key;
    return c.path + "[" + std::to_string(c.index++) + "]";
  };
  const Json::parser_callback_t strict = [&](int, Json::parse_event_t event, Json& parsed) {
    switch (event) {
    case Json::parse_event_t::object_start:
    case Json::parse_event_t::array_start: {
      std::string path = child_path();
      if (open.size() >= kMaxDepth)
        throw InputError(file, (path.size() > 60 ? path.substr(0, 60) + "..." : path) + " is nested deeper than " +
                                   std::to_string(kMaxDepth) + " levels");
      open.push_back({std::move(path), event == Json::parse_event_t::object_start, {}, {}, 0});
      break;
    }
    case Json::parse_event_t::key: {
      Container& c = open.back();
      c.key = parsed.get<std::string>();
      if (!c.keys.insert(c.key).second)
        throw InputError(file, "duplicate key \"" + c.key + "\" in " + shown_path(c.path));
      break;
    }
    case Json::parse_event_t::object_end:
    case Json::parse_event_t::array_end: open.pop_back(); break;
    case Json::parse_event_t::value:
      if (!open.empty() && !open.back().object) ++open.back().index;
      break;
    }
    return true;
  };
  try {
    return Json::parse(text, strict);
  } catch (const Json::parse_error& e) {
    // e.byte counts the bytes read up to and including the one in error (1-based).
    const size_t at = std::min(text.size(), e.byte > 0 ? size_t(e.byte - 1) : size_t(0));
    const size_t line_start = text.rfind('\n', at == 0 ? std::string::npos : at - 1);
    const size_t line = 1 + size_t(std::count(text.begin(), text.begin() + std::ptrdiff_t(at), '\n'));
    const size_t column = at - (line_start == std::string::npos ? 0 : line_start + 1) + 1;
    std::string what = e.what();  // "[json.exception.parse_error.101] parse error at line L, column C: <problem>"
    const size_t colon = what.find(": ");
    if (colon != std::string::npos) what = what.substr(colon + 2);
    throw InputError(file, "line " + std::to_string(line) + ", column " + std::to_string(column) + ": " + what);
  } catch (const Json::exception& e) {  // e.g. a number too large for a double ("1e400")
    std::string what = e.what();
    const size_t bracket = what.find("] ");
    throw InputError(file, bracket == std::string::npos ? what : what.substr(bracket + 2));
  }
}

// A scene or options file lists objects and settings: 16 MiB is far beyond any real one (about
// 200 bytes an object). Read up to one byte more, so a pipe or a device (/dev/zero) is refused at
// the limit, not read forever. The parsed tree takes at most ~32 bytes per byte of text (a 16-byte
// value, its heap block and vector growth for "[]," or "0,"): 512 MiB at the limit. Running out of
// memory inside the JSON library cannot be reported (it allocates while destroying a partial
// tree, and terminates); this bound is what keeps that away.
constexpr size_t kMaxJsonFileBytes = size_t{16} << 20;

Json read_json_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "cannot open the file");
  std::string text;
  for (char buffer[65536]; text.size() <= kMaxJsonFileBytes && in;) {
    in.read(buffer, sizeof buffer);
    text.append(buffer, static_cast<size_t>(in.gcount()));
  }
  if (in.bad()) throw InputError(file.string(), "cannot read the file");
  if (text.size() > kMaxJsonFileBytes)
    throw InputError(file.string(), "larger than " + std::to_string(kMaxJsonFileBytes >> 20) + " MiB; a scene file is not that large");
  return parse_json(text, file.string());
}
Json parse_json_file(const std::filesystem::path& file) {
  return reading_file(file.string(), [&] { return read_json_file(file); });
}

// An object's member, nullptr if absent.
const Json* find_key(const Json& object, const char* key) {
  const auto it = object.find(key);
  return it == object.end() ? nullptr : &*it;
}

// Reads typed members with messages that name the file and the key path.
class Reader {
public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& what) const { throw InputError(file_, what); }

  const Json& object(const Json& v, const std::string& key_path, std::initializer_list<std::string_view> allowed) const {
    if (!v.is_object()) fail(key_path + " must be an object, not " + v.type_name());
    for (const auto& [k, member] : v.items()) {
      bool ok = false;
      for (std::string_view a : allowed) ok = ok || k == a;
      if (!ok) {
        std::string list;
        for (std::string_view a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
        fail("unknown key \"" + k + "\" in " + key_path + " (allowed: " + list + ")");
      }
    }
    return v;
  }

  double number(const Json& v, const std::string& key, double lo, double hi) const {
    if (!v.is_number()) fail(key + " must be a number, not " + v.type_name());
    const double x = v.get<double>();
    if (!(x >= lo && x <= hi)) {
      std::ostringstream os;
      os << key << " must be in [" << lo << ", " << hi << "], got " << x;
      fail(os.str());
    }
    return x;
  }

  int64_t integer(const Json& v, const std::string& key, int64_t lo, int64_t hi) const {
    const double x = number(v, key, double(lo), double(hi));
    if (x != std::floor(x)) fail(key + " must be an integer");
    return int64_t(x);
  }

  const std::string& string(const Json& v, const std::string& key) const {
    if (!v.is_string()) fail(key + " must be a string, not " + v.type_name());
    const std::string& s = v.get_ref<const std::string&>();
    if (s.empty()) fail(key + " must not be empty");
    return s;
  }

  bool boolean(const Json& v, const std::string& key) const {
    if (!v.is_boolean()) fail(key + " must be true or false, not " + v.type_name());
    return v.get<bool>();
  }

  std::array<double, 3> vec3(const Json& v, const std::string& key, double lo, double hi) const {
    if (!v.is_array() || v.size() != 3) fail(key + " must be an array of 3 numbers");
    std::array<double, 3> out{};
    for (size_t i = 0; i < 3; ++i) out[i] = number(v[i], key + "[" + std::to_string(i) + "]", lo, hi);
    return out;
  }

private:
  std::string file_;
};

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
             {"products", "integrator", "samples", "seed", "report", "target_error", "sh_tolerance", "relight", "fiv"});
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
    if (const Json* f = find_key(*bake, "fiv")) {
      r.object(*f, "bake.fiv", {"shells", "cube", "fraction"});
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
  // Neither "samples" nor "target_error": the default target (as prtbake vertex), with the
  // report's default size.
  const Json* bake = find_key(root, "bake");
  if (!bake || (!find_key(*bake, "samples") && !find_key(*bake, "target_error"))) sc.target_error = ChooserOptions{}.target;
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

// "lights" (bake/lights/lights.h shapes): every light validated, names unique ("light<i>" by default).
std::vector<AreaLight> parse_lights(const Reader& r, const Json& v, const std::string& file) {
  if (!v.is_array()) r.fail("lights must be an array of light objects");
  std::vector<AreaLight> out;
  std::set<std::string> names;
  for (size_t i = 0; i < v.size(); ++i) {
    const Json& l = v[i];
    const std::string key = "lights[" + std::to_string(i) + "]";
    if (!l.is_object()) r.fail(key + " must be an object, not " + l.type_name());
    const Json* shape = find_key(l, "shape");
    if (shape == nullptr) r.fail(key + " lacks \"shape\": quad, polygon, disc, box, cylinder or sphere");
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
    const std::initializer_list<std::string_view> common = {"name", "shape", "radiance", "two_sided"};
    auto allow = [&](std::initializer_list<std::string_view> own) {
      std::vector<std::string_view> all(common);
      all.insert(all.end(), own.begin(), own.end());
      for (const auto& [k, member] : l.items())
        if (std::find(all.begin(), all.end(), k) == all.end()) {
          std::string list;
          for (std::string_view a : all) list += (list.empty() ? "" : ", ") + std::string(a);
          r.fail("unknown key \"" + k + "\" in " + key + " (a " + kind + " light takes " + list + ")");
        }
    };
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
      r.fail(key + ".shape must be quad, polygon, disc, box, cylinder or sphere, not \"" + kind + "\"");
    }
    light.radiance = r.vec3(need("radiance"), key + ".radiance", 0, kHuge);
    if (const Json* x = find_key(l, "two_sided")) light.two_sided = r.boolean(*x, key + ".two_sided");
    light.name = "light" + std::to_string(i);
    if (const Json* n = find_key(l, "name")) {
      light.name = r.string(*n, key + ".name");
      if (!valid_name(light.name)) r.fail(key + ".name \"" + light.name + "\" must be 1-128 characters of A-Z a-z 0-9 _ - .");
    }
    if (!names.insert(light.name).second) r.fail(key + ": the name \"" + light.name + "\" is already used by another light");
    validate_light(light, file, key);
    out.push_back(std::move(light));
  }
  return out;
}

SceneDescription load_json_scene(const std::filesystem::path& file) {
  const Json root = parse_json_file(file);
  const Reader r(file.string());
  r.object(root, "the scene", {"prtbake_scene", "up", "environment", "bake", "lights", "objects"});
  SceneDescription sc;
  sc.file = file;
  check_version(r, root, "prtbake_scene", "the scene", "scene-file");
  parse_settings(r, root, file, sc);
  if (const Json* lights = find_key(root, "lights")) sc.lights = parse_lights(r, *lights, file.string());
  const Json* objects = find_key(root, "objects");
  if (objects == nullptr) r.fail("the scene lacks \"objects\" (an array of one or more objects)");
  if (!objects->is_array() || objects->empty()) r.fail("objects must be a non-empty array");
  std::set<std::string> names;
  for (size_t i = 0; i < objects->size(); ++i) {
    const Json& o = (*objects)[i];
    const std::string key = "objects[" + std::to_string(i) + "]";
    r.object(o, key, {"name", "mesh", "role", "transform", "material", "moves"});
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
    sc.objects.push_back(std::move(obj));
  }
  return sc;
}

// A glTF scene (bake/bake/scene.h "glTF scenes"): one object per instance, then the options file.
SceneDescription load_gltf_scene(const std::filesystem::path& file, const std::optional<std::filesystem::path>& options) {
  SceneDescription sc;
  sc.file = file;
  sc.options = options;
  for (const MeshInstance& in : load_mesh_instances(file).instances) {
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
  if (!options) return sc;
  const Json root = parse_json_file(*options);
  const Reader r(options->string());
  r.object(root, "the scene options", {"prtbake_gltf_scene", "up", "environment", "bake", "lights", "objects"});
  check_version(r, root, "prtbake_gltf_scene", "the scene options", "options-file");
  parse_settings(r, root, *options, sc);
  if (const Json* lights = find_key(root, "lights")) sc.lights = parse_lights(r, *lights, options->string());
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
    bool used = false;
  };
  std::vector<Entry> entries;
  for (const auto& [key, value] : objects->items()) {
    const std::string path = "objects.\"" + key + "\"";
    r.object(value, path, {"role", "material", "moves"});
    Entry& e = entries.emplace_back();
    e.key = key;
    if (const Json* role = find_key(value, "role")) e.role = parse_role(r, *role, path + ".role");
    if (const Json* m = find_key(value, "material")) e.material = parse_material(r, *m, path + ".material", e.role.value_or(Role::Both));
    if (const Json* mv = find_key(value, "moves")) e.moves = r.boolean(*mv, path + ".moves");
  }
  auto names = [](const std::string& instance, const std::string& key) {
    return instance.starts_with(key) && (instance.size() == key.size() || instance[key.size()] == '/' || instance[key.size()] == '#');
  };
  for (SceneObject& obj : sc.objects) {
    const Entry* role = nullptr;
    const Entry* material = nullptr;
    const Entry* moves = nullptr;
    for (Entry& e : entries) {
      if (!names(obj.node_path, e.key)) continue;
      e.used = true;
      if (e.role && (!role || e.key.size() > role->key.size())) role = &e;
      if (e.material && (!material || e.key.size() > material->key.size())) material = &e;
      if (e.moves && (!moves || e.key.size() > moves->key.size())) moves = &e;
    }
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

bool is_gltf(const std::filesystem::path& file) { return is_gltf_scene(file); }

} // namespace

bool is_gltf_scene(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".gltf" || ext == ".glb";
}

SceneDescription load_scene(const std::filesystem::path& file, const std::optional<std::filesystem::path>& gltf_options) {
  if (is_gltf(file)) return load_gltf_scene(file, gltf_options);
  if (gltf_options)
    throw InputError(gltf_options->string(), "scene options apply to a glTF scene only; " + file.string() + " is a JSON scene file");
  return load_json_scene(file);
}

std::vector<Mesh> load_scene_meshes(const SceneDescription& scene, std::vector<std::string>& warnings) {
  // The files' meshes first (a glTF's instances are already in world space: their objects'
  // transforms are the identity), then one scene origin over all of them, so that receivers and
  // occluders share one frame (bake/mesh/mesh.h ORIGIN), then each object placed in it.
  std::vector<Mesh> files;
  if (is_gltf(scene.file)) {
    MeshInstances file = load_mesh_instances(scene.file);
    if (file.instances.size() != scene.objects.size())
      throw InputError(scene.file.string(), "has changed since it was read: " + std::to_string(file.instances.size()) +
                                                " instances, was " + std::to_string(scene.objects.size()));
    warnings.insert(warnings.end(), file.warnings.begin(), file.warnings.end());
    for (MeshInstance& in : file.instances) files.push_back(std::move(in.mesh));
  } else {
    for (const SceneObject& o : scene.objects) {
      try {
        files.push_back(load_mesh(o.mesh));
      } catch (const InputError& e) {  // say which object of which scene wanted the mesh
        throw InputError(e.file(), e.defect() + " (object '" + o.name + "' of " + scene.file.string() + ")");
      }
      warnings.insert(warnings.end(), files.back().warnings.begin(), files.back().warnings.end());
    }
  }
  const Eigen::Vector3d origin = scene_origin(files, scene.objects);
  std::vector<Mesh> meshes;
  meshes.reserve(files.size());
  for (size_t i = 0; i < files.size(); ++i) {
    try {
      meshes.push_back(place_scene_object(files[i], scene.objects[i], origin));
    } catch (const InputError& e) {
      throw InputError(e.file(), e.defect() + " (object '" + scene.objects[i].name + "' of " + scene.file.string() + ")");
    }
  }
  return meshes;
}

namespace {

// world_from_object applied in double to the file mesh's world positions (unchecked).
std::vector<Eigen::Vector3d> world_positions(const Mesh& file_mesh, const SceneObject& object) {
  const Eigen::Matrix3d A = object.world_from_object.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = object.world_from_object.topRightCorner<3, 1>();
  std::vector<Eigen::Vector3d> world(file_mesh.positions.size());
  for (size_t i = 0; i < world.size(); ++i) world[i] = A * file_mesh.world_position(i) + t;
  return world;
}

bool usable(const Eigen::Vector3d& p) { return p.allFinite() && p.cwiseAbs().maxCoeff() <= 1e30; }

} // namespace

Eigen::Vector3d scene_origin(std::span<const Mesh> file_meshes, std::span<const SceneObject> objects) {
  PRT_CHECK_OP(file_meshes.size(), ==, objects.size());
  Eigen::AlignedBox3d bounds;
  for (size_t i = 0; i < objects.size(); ++i)
    for (const Eigen::Vector3d& p : world_positions(file_meshes[i], objects[i]))
      if (usable(p)) bounds.extend(p);  // the others are refused by place_scene_object
  return bounds.isEmpty() ? Eigen::Vector3d::Zero() : frame_origin(bounds);
}

Mesh load_scene_mesh(const SceneObject& object) {
  const Mesh file_mesh = load_mesh(object.mesh);
  return place_scene_object(file_mesh, object, scene_origin(std::span(&file_mesh, 1), std::span(&object, 1)));
}

Mesh place_scene_object(const Mesh& file_mesh, const SceneObject& object, const Eigen::Vector3d& origin) {
  Mesh m = file_mesh;
  const Eigen::Matrix3d N = object.world_from_object.topLeftCorner<3, 3>().inverse().transpose();
  const std::vector<Eigen::Vector3d> world = world_positions(file_mesh, object);
  for (size_t i = 0; i < world.size(); ++i)
    if (!usable(world[i]))
      throw InputError(object.mesh.string(), "vertex " + std::to_string(i) + " is not finite after the scene transform of '" +
                                                 object.name + "'");
  m.positions = offsets_from(world, origin, object.mesh.string());
  m.origin = origin;
  if (m.normal_source == Mesh::NormalSource::File) {
    for (auto& n : m.normals) n = (N * n.cast<double>()).normalized().cast<float>();
  } else {
    m.normals = welded_angle_weighted_normals(m.positions, m.triangles);
  }
  return m;
}

ScenePlan plan_scene(const SceneDescription& scene, std::span<const Mesh> meshes) {
  PRT_CHECK_OP(meshes.size(), ==, scene.objects.size());
  ScenePlan plan;
  plan.objects.resize(scene.objects.size());
  const bool env = scene.environment.has_value();
  const std::string env_name = env ? scene.environment->filename().string() : "";
  const int diffuse_order = clamped_power_order(1.0, scene.sh_tolerance, sh::kMaxOrder);
  auto pct = [](double x) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.2g%%", x * 100);
    return std::string(buf);
  };

  // Bounding spheres for the FIV rule.
  std::vector<Eigen::Vector3d> centre(meshes.size());
  std::vector<double> radius(meshes.size());
  for (size_t i = 0; i < meshes.size(); ++i) bounding_sphere(meshes[i], centre[i], radius[i]);

  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const SceneObject& o = scene.objects[i];
    ObjectPlan& p = plan.objects[i];
    p.receiver = o.role != Role::Occluder;
    p.occluder = o.role != Role::Receiver;
    if (!p.receiver) {
      p.left_out.push_back("ao, transfer, radiance: occluder only (role \"occluder\"): nothing is shaded on it");
    } else {
      if (scene.want_ao) p.ao = true, p.baked.push_back("ao: requested");
      else p.left_out.push_back("ao: not in bake.products");
      const Material& m = o.material;
      if (!scene.lights.empty()) {
        p.area_irradiance = true;
        p.baked.push_back("area_lights/irradiance: " + std::to_string(scene.lights.size()) +
                          " area light(s), exact soft shadows (paper 003)");
        if (!m.glossy()) p.left_out.push_back("area_lights/sh: no glossy lobe (irradiance is exact for a diffuse receiver)");
      }
      if (m.diffuse()) {
        if (!scene.want_radiance) p.left_out.push_back("radiance/band1: not in bake.products");
        else if (!env) p.left_out.push_back("radiance/band1: the scene has no environment");
        else p.radiance = true, p.baked.push_back("radiance/band1: diffuse albedo under " + env_name +
                                                  ": exact shadowed irradiance with 3 coefficients per channel (paper 001 §4)");
        if (!scene.want_transfer) {
          p.left_out.push_back("transfer/diffuse: not in bake.products");
        } else if (p.radiance && !scene.relight) {
          p.left_out.push_back("transfer/diffuse: band-1 radiance is exact for a diffuse receiver under the scene's "
                               "environment; no higher order is needed (set bake.relight for relightable transfer)");
        } else {
          p.transfer_order = diffuse_order;
          p.baked.push_back("transfer/diffuse: order " + std::to_string(diffuse_order) +
                            ", the smallest whose clamped-cosine energy beyond it (" +
                            pct(clamped_power_energy_beyond(1.0, diffuse_order)) + ") is <= sh_tolerance " +
                            pct(scene.sh_tolerance) + (env ? " (bake.relight)" : " (no environment: relightable)"));
        }
      } else {
        p.left_out.push_back("radiance/band1, transfer/diffuse: the material has no diffuse albedo");
      }
      if (m.glossy()) {
        const bool shadowed = scene.want_radiance && env;
        if (!scene.want_radiance) p.left_out.push_back("radiance/shadowed: not in bake.products");
        else if (!env) p.left_out.push_back("radiance/shadowed: the scene has no environment");
        if (!scene.want_transfer) {
          p.left_out.push_back("transfer/visibility: not in bake.products");
          if (!scene.lights.empty())
            p.left_out.push_back("area_lights/sh: transfer/visibility is not baked (not in bake.products)");
        }
        if (scene.want_transfer || shadowed) {
          const int L = clamped_power_order(m.phong_exponent, scene.sh_tolerance, sh::kMaxOrder);
          if (L == 0) {
            std::ostringstream os;
            os << "object '" << o.name << "': a Phong exponent of " << m.phong_exponent
               << " needs more than " << sh::kMaxOrder << " SH bands to keep the energy beyond them under "
               << pct(scene.sh_tolerance) << " (" << pct(clamped_power_energy_beyond(m.phong_exponent, sh::kMaxOrder))
               << " at order " << sh::kMaxOrder << "); lower the exponent or raise bake.sh_tolerance";
            throw InputError(scene.file.string(), os.str());
          }
          std::ostringstream os;
          os << "order " << L << " for the Phong exponent " << m.phong_exponent
             << ", the smallest whose lobe energy beyond it (" << pct(clamped_power_energy_beyond(m.phong_exponent, L))
             << ") is <= sh_tolerance " << pct(scene.sh_tolerance);
          // S for the scene's own environment (exact shadows, any lobe at run time); U besides it
          // whenever transfer is asked for: it is what relights or rotates the lighting (route A),
          // at a third of S's size, and a scene that wants the fixed environment only leaves
          // "transfer" out of bake.products.
          if (shadowed) {
            p.shadowed_order = L;
            p.baked.push_back("radiance/shadowed: " + os.str() + ", under " + env_name +
                              ": the shadowed incident radiance, the lobe applied at run time (paper 001 §4, "
                              "material editing)");
          }
          if (scene.want_transfer) {
            p.visibility_order = L;
            p.baked.push_back("transfer/visibility: " + os.str() +
                              (shadowed ? " (relightable: the lighting may change or rotate; radiance/shadowed "
                                          "serves the fixed environment)"
                                        : ""));
            if (!scene.lights.empty()) {
              p.area_sh_order = L;
              p.baked.push_back("area_lights/sh: order " + std::to_string(L) + ", the glossy lobe's (transfer/visibility)");
            }
          }
        }
      }
    }
    if (p.occluder) {
      if (!scene.want_fiv) {
        p.left_out.push_back("fiv: not in bake.products");
      } else if (!o.moves) {
        // Paper 004 §1: FIV shells shade what a MOVING occluder casts on other receivers; a static
        // occluder's shadows are already in every receiver's own products.
        p.left_out.push_back("fiv: the object does not move (" + o.moves_reason +
                             "); its shadows are in the receivers' own products (set \"moves\": true to bake its shells)");
      } else if (!env) {
        p.left_out.push_back("fiv: the scene has no environment (F = Int (1 - V) L w dw needs one)");
      } else {
        // Can it shadow another receiver? Paper 004 §4.3.1: an occluder whose bounding sphere lies
        // wholly below a receiver point's tangent plane (case C) occludes nothing there.
        bool other_receiver = false, reaches = false;
        for (size_t j = 0; j < scene.objects.size() && !reaches; ++j) {
          if (j == i || scene.objects[j].role == Role::Occluder) continue;
          other_receiver = true;
          const Mesh& R = meshes[j];
          for (size_t v = 0; v < R.positions.size() && !reaches; ++v)
            reaches = R.normals[v].cast<double>().dot(centre[i] - R.positions[v].cast<double>()) > -radius[i];
        }
        if (!other_receiver) p.left_out.push_back("fiv: no other receiver in the scene for it to shadow");
        else if (!reaches) p.left_out.push_back("fiv: its bounding sphere lies below the horizon of every vertex of every other receiver");
        else
          p.fiv = true,
          p.baked.push_back("fiv: it moves (" + o.moves_reason + ") and can shadow another receiver; shells up to " +
                            std::to_string(scene.fiv.n_phi) + "x" + std::to_string(scene.fiv.n_theta) + "x" +
                            std::to_string(scene.fiv.n_rho) + " by the silhouette integrator at k = " +
                            std::to_string(scene.fiv.silhouette_k) +
                            (scene.integrator.kind == IntegratorKind::Silhouette
                                 ? std::string()
                                 : std::string(" (paper 004's shells are integrated by silhouettes whatever "
                                               "bake.integrator says; bake.fiv sets their grid)")));
      }
    }
    plan.fiv_environment = plan.fiv_environment || p.fiv;
  }
  if (plan.fiv_environment) plan.notes.push_back("fiv/environment and fiv/irradiance_cube: some occluder has shells");
  else plan.notes.push_back("fiv/environment and fiv/irradiance_cube: left out, no occluder has shells");
  return plan;
}

} // namespace prt::bake
