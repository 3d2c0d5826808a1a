// c_api.cpp — the C API (prtshade/prtshade.h) over the C++ core: argument checks, copies into
// owning handles, and every exception converted to a prt_status at the boundary.
#include <prtshade/prtshade.h>

#include <prtshade/fiv.h>
#include <prtshade/glossy.h>
#include <prtshade/lights.h>
#include <prtshade/ltc.h>
#include <prtshade/sh.h>
#include <prtshade/shade.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <exception>
#include <memory>
#include <new>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#ifndef PRTSHADE_VERSION
#error "PRTSHADE_VERSION must be defined by the build"
#endif

// prt_fiv_occluder_desc is the C spelling of prt::shade::FivOccluder: the same members in the same
// order (the C header cannot include the C++ one), kept in step by these checks.
static_assert(sizeof(prt_fiv_occluder_desc) == sizeof(prt::shade::FivOccluder));
static_assert(offsetof(prt_fiv_occluder_desc, radius) == offsetof(prt::shade::FivOccluder, radius));
static_assert(offsetof(prt_fiv_occluder_desc, n_phi) == offsetof(prt::shade::FivOccluder, n_phi));
static_assert(offsetof(prt_fiv_occluder_desc, valid) == offsetof(prt::shade::FivOccluder, valid));
static_assert(offsetof(prt_fiv_occluder_desc, radial_scheme) == offsetof(prt::shade::FivOccluder, radial_scheme));
static_assert(offsetof(prt_fiv_occluder_desc, surface_radius) == offsetof(prt::shade::FivOccluder, surface_radius));
static_assert(offsetof(prt_fiv_occluder_desc, cones) == offsetof(prt::shade::FivOccluder, cones));

struct prt_glossy {
  explicit prt_glossy(int order) : table(order) {}
  prt::shade::TripleProduct table;
};

struct prt_sh_rotation {
  explicit prt_sh_rotation(const double R[3][3], int order) : rotation(R, order) {}
  prt::sh::Rotation rotation;
};

namespace {

// Owning copy of one occluder's arrays (its view lives in prt_fiv_scene::views).
struct OwnedOccluder {
  std::vector<float> radii, shells, surface_radius, cones;
  std::vector<uint8_t> valid;
  std::vector<uint16_t> shells_half, cones_half;
};

} // namespace

struct prt_fiv_scene {
  int difmap_size = 0;
  std::vector<float> difmap;
  float environment[9] = {};
  std::vector<std::unique_ptr<OwnedOccluder>> owned;
  std::vector<prt::shade::FivOccluder> views;  // contiguous, for shade_fiv

  prt::shade::DifMap map() const { return {difmap_size, difmap.data()}; }
};

namespace {

thread_local std::string g_last_error;

prt_status fail(prt_status status, const char* function, const std::string& message) {
  try {
    g_last_error = std::string(function) + ": " + message;
  } catch (...) {
    g_last_error.clear();
  }
  return status;
}

// Runs f (which returns nothing or throws) and maps exceptions to statuses.
template <class F>
prt_status guarded(const char* function, F&& f) noexcept {
  try {
    f();
    return PRT_OK;
  } catch (const std::bad_alloc&) {
    return fail(PRT_ERROR_OUT_OF_MEMORY, function, "out of memory");
  } catch (const std::invalid_argument& e) {
    return fail(PRT_ERROR_INVALID_ARGUMENT, function, e.what());
  } catch (const std::length_error& e) {
    return fail(PRT_ERROR_OUT_OF_MEMORY, function, e.what());
  } catch (const std::exception& e) {
    return fail(PRT_ERROR_INTERNAL, function, e.what());
  } catch (...) {
    return fail(PRT_ERROR_INTERNAL, function, "unknown exception");
  }
}

// Argument failure inside guarded(): becomes PRT_ERROR_INVALID_ARGUMENT with this message.
[[noreturn]] void bad_argument(const std::string& message) { throw std::invalid_argument(message); }

void require(bool ok, const char* message) {
  if (!ok) bad_argument(message);
}

void require_order(int order) {
  if (order < 1 || order > prt::sh::kMaxOrder)
    bad_argument("order " + std::to_string(order) + " outside [1, " + std::to_string(prt::sh::kMaxOrder) + "]");
}

void require_count(size_t have, size_t need, const char* what) {
  if (have < need)
    bad_argument(std::string(what) + " holds " + std::to_string(have) + " floats, needs " + std::to_string(need));
}

const prt::shade::FivOccluder& occluder_at(const prt_fiv_scene* scene, int index) {
  if (index < 0 || size_t(index) >= scene->views.size())
    bad_argument("occluder index " + std::to_string(index) + " outside [0, " + std::to_string(scene->views.size()) +
                 ")");
  return scene->views[size_t(index)];
}

} // namespace

extern "C" {

const char* prt_status_string(prt_status status) {
  switch (status) {
  case PRT_OK: return "ok";
  case PRT_ERROR_INVALID_ARGUMENT: return "invalid argument";
  case PRT_ERROR_OUT_OF_MEMORY: return "out of memory";
  case PRT_ERROR_INTERNAL: return "internal error";
  }
  return "unknown status";
}

const char* prt_last_error(void) { return g_last_error.c_str(); }

const char* prt_version(void) { return PRTSHADE_VERSION; }

int prt_sh_max_order(void) { return prt::sh::kMaxOrder; }

prt_status prt_sh_eval(int order, float x, float y, float z, float* out, size_t out_count) {
  return guarded(__func__, [&] {
    require(out != nullptr, "out is null");
    require_order(order);
    require_count(out_count, size_t(order) * size_t(order), "out");
    const double r2 = double(x) * x + double(y) * y + double(z) * z;
    require(std::isfinite(r2) && std::fabs(r2 - 1.0) <= 1e-4, "direction is not unit length (to 1e-4)");
    prt::sh::eval(order, x, y, z, std::span<float>(out, out_count));
  });
}

prt_status prt_sh_rotation_create(const double rotation[9], int order, prt_sh_rotation** out) {
  return guarded(__func__, [&] {
    require(rotation != nullptr && out != nullptr, "null pointer");
    require_order(order);
    for (int k = 0; k < 9; ++k) require(std::isfinite(rotation[k]), "rotation matrix is not finite");
    const double R[3][3] = {{rotation[0], rotation[1], rotation[2]},
                            {rotation[3], rotation[4], rotation[5]},
                            {rotation[6], rotation[7], rotation[8]}};
    *out = new prt_sh_rotation(R, order);
  });
}

void prt_sh_rotation_destroy(prt_sh_rotation* rotation) { delete rotation; }

prt_status prt_sh_rotation_apply(const prt_sh_rotation* rotation, const float* in, float* out, int channels,
                                 size_t count) {
  return guarded(__func__, [&] {
    require(rotation != nullptr && in != nullptr && out != nullptr, "null pointer");
    require(channels >= 1, "channels must be >= 1");
    const size_t n = size_t(prt::sh::num_coeffs(rotation->rotation.order()));
    require_count(count, size_t(channels) * n, "in/out");
    const size_t total = size_t(channels) * n;
    const auto a = reinterpret_cast<uintptr_t>(in), b = reinterpret_cast<uintptr_t>(out);
    require(a + total * sizeof(float) <= b || b + total * sizeof(float) <= a, "in and out overlap");
    for (int c = 0; c < channels; ++c)
      rotation->rotation.apply(std::span<const float>(in + size_t(c) * n, n), std::span<float>(out + size_t(c) * n, n));
  });
}

prt_status prt_project_latlong(const float* rgb, int width, int height, int order, float* out, size_t out_count) {
  return guarded(__func__, [&] {
    require(rgb != nullptr && out != nullptr, "null pointer");
    require_order(order);
    require_count(out_count, 3 * size_t(order) * size_t(order), "out");
    // Project into a scratch buffer so a failure writes nothing to out.
    std::vector<float> tmp(3 * size_t(order) * size_t(order));
    prt::shade::project_latlong(rgb, width, height, order, tmp.data());
    std::memcpy(out, tmp.data(), tmp.size() * sizeof(float));
  });
}

prt_status prt_shade_transfer(const float* transfer, size_t vertex_count, int order, const float* light_rgb,
                              float* out) {
  return guarded(__func__, [&] {
    require_order(order);
    prt::shade::shade_transfer_vertices(transfer, vertex_count, order, light_rgb, out);
  });
}

prt_status prt_shade_band1(const float* normals, const float* radiance, size_t vertex_count, float* out) {
  return guarded(__func__, [&] { prt::shade::shade_band1_vertices(normals, radiance, vertex_count, out); });
}

prt_status prt_glossy_create(int order, prt_glossy** out) {
  return guarded(__func__, [&] {
    require(out != nullptr, "out is null");
    *out = new prt_glossy(order);
  });
}

void prt_glossy_destroy(prt_glossy* glossy) { delete glossy; }

prt_status prt_shade_glossy(const prt_glossy* glossy, const float* light, const float* visibility, const float* normals,
                            const float* positions, size_t vertex_count, const float eye[3], double phong_exponent,
                            float* out) {
  return guarded(__func__, [&] {
    require(glossy != nullptr && light != nullptr, "null pointer");
    const prt::shade::GlossyLight lit(glossy->table, light);
    prt::shade::shade_glossy_vertices(lit, visibility, normals, positions, vertex_count, eye, phong_exponent, out);
  });
}

prt_status prt_shade_glossy_radiance(const float* shadowed, int order, const float r[3], double phong_exponent,
                                     float out[3]) {
  return guarded(__func__, [&] {
    require(shadowed != nullptr && r != nullptr && out != nullptr, "null pointer");
    require(order >= 1 && order <= prt::shade::kMaxShadowedOrder, "order must be in [1, 64]");
    double scales[prt::shade::kMaxShadowedOrder];
    prt::shade::phong_band_scales(phong_exponent, order, scales);
    prt::shade::shade_glossy_radiance(shadowed, order, scales, r, out);
  });
}

prt_status prt_fiv_scene_create(int difmap_size, const float* difmap_texels, const float environment_fiv[9],
                                prt_fiv_scene** out) {
  return guarded(__func__, [&] {
    require(difmap_texels != nullptr && environment_fiv != nullptr && out != nullptr, "null pointer");
    prt::shade::validate_difmap({difmap_size, difmap_texels});
    prt::shade::validate_environment_fiv(environment_fiv);
    auto scene = std::make_unique<prt_fiv_scene>();
    scene->difmap_size = difmap_size;
    scene->difmap.assign(difmap_texels, difmap_texels + size_t(6) * size_t(difmap_size) * size_t(difmap_size) * 3);
    std::memcpy(scene->environment, environment_fiv, sizeof scene->environment);
    *out = scene.release();
  });
}

void prt_fiv_scene_destroy(prt_fiv_scene* scene) { delete scene; }

prt_status prt_fiv_scene_add_occluder(prt_fiv_scene* scene, const prt_fiv_occluder_desc* occluder, int* out_index) {
  return guarded(__func__, [&] {
    require(scene != nullptr && occluder != nullptr, "null pointer");
    prt::shade::FivOccluder v{{occluder->centre[0], occluder->centre[1], occluder->centre[2]},
                              occluder->radius,
                              occluder->n_rho,
                              occluder->n_theta,
                              occluder->n_phi,
                              occluder->radii,
                              occluder->shells,
                              occluder->valid,
                              occluder->radial_scheme,
                              occluder->surface_radius,
                              occluder->cones,
                              occluder->shells_half,
                              occluder->cones_half};
    prt::shade::validate_occluder(v);
    require(scene->views.size() < size_t(1) << 30, "too many occluders");
    auto own = std::make_unique<OwnedOccluder>();
    const size_t samples = size_t(v.n_rho) * size_t(v.n_theta) * size_t(v.n_phi);
    own->radii.assign(v.radii, v.radii + v.n_rho);
    if (v.shells != nullptr) own->shells.assign(v.shells, v.shells + samples * 9);
    else own->shells_half.assign(v.shells_half, v.shells_half + samples * 9);
    // The surface scheme reads no valid mask (it may be null): an all-ones one stands in.
    if (v.valid != nullptr) own->valid.assign(v.valid, v.valid + samples);
    else own->valid.assign(samples, 1);
    if (v.radial_scheme == prt::shade::kFivRadialSurface)
      own->surface_radius.assign(v.surface_radius, v.surface_radius + size_t(v.n_theta) * size_t(v.n_phi));
    v.radii = own->radii.data();
    v.shells = v.shells != nullptr ? own->shells.data() : nullptr;
    v.shells_half = v.shells_half != nullptr ? own->shells_half.data() : nullptr;
    v.valid = own->valid.data();
    v.surface_radius = own->surface_radius.empty() ? nullptr : own->surface_radius.data();
    if (v.cones != nullptr) {
      own->cones.assign(v.cones, v.cones + samples * 4);
      v.cones = own->cones.data();
    }
    if (v.cones_half != nullptr) {
      own->cones_half.assign(v.cones_half, v.cones_half + samples * 4);
      v.cones_half = own->cones_half.data();
    }
    scene->views.reserve(scene->views.size() + 1);
    scene->owned.push_back(std::move(own));
    scene->views.push_back(v);
    if (out_index != nullptr) *out_index = int(scene->views.size() - 1);
  });
}

prt_status prt_fiv_scene_set_centre(prt_fiv_scene* scene, int index, const float centre[3]) {
  return guarded(__func__, [&] {
    require(scene != nullptr && centre != nullptr, "null pointer");
    occluder_at(scene, index);
    require(std::isfinite(centre[0]) && std::isfinite(centre[1]) && std::isfinite(centre[2]), "centre is not finite");
    for (int k = 0; k < 3; ++k) scene->views[size_t(index)].centre[k] = centre[k];
  });
}

prt_status prt_fiv_scene_occluder_count(const prt_fiv_scene* scene, int* out_count) {
  return guarded(__func__, [&] {
    require(scene != nullptr && out_count != nullptr, "null pointer");
    *out_count = int(scene->views.size());
  });
}

prt_status prt_fiv_scene_lookup_difmap(const prt_fiv_scene* scene, const float n[3], float out[3]) {
  return guarded(__func__, [&] {
    require(scene != nullptr && n != nullptr && out != nullptr, "null pointer");
    prt::shade::lookup_difmap(scene->map(), n, out);
  });
}

prt_status prt_fiv_scene_lookup_fiv(const prt_fiv_scene* scene, int index, const float s[3], float out[9]) {
  return guarded(__func__, [&] {
    require(scene != nullptr && s != nullptr && out != nullptr, "null pointer");
    prt::shade::lookup_fiv(occluder_at(scene, index), s, out);
  });
}

prt_status prt_fiv_scene_occluded_irradiance(const prt_fiv_scene* scene, int index, const float p[3],
                                             const float n[3], int partial, float out[3]) {
  return guarded(__func__, [&] {
    require(scene != nullptr && p != nullptr && n != nullptr && out != nullptr, "null pointer");
    prt::shade::occluded_irradiance(occluder_at(scene, index), p, n, partial != 0, out);
  });
}

prt_status prt_fiv_scene_shade(const prt_fiv_scene* scene, const float* positions, const float* normals,
                               size_t count, const prt_fiv_options* options, float* out) {
  return guarded(__func__, [&] {
    require(scene != nullptr, "scene is null");
    if (count == 0) return;
    require(positions != nullptr && normals != nullptr && out != nullptr, "null pointer");
    prt::shade::FivShadeOptions o;
    if (options != nullptr) {
      o.partial_occluders = options->partial_occluders != 0;
      o.overlap_correction = options->overlap_correction != 0;
      o.proxy = options->sphere_proxy != 0 ? prt::shade::FivProxy::sphere : prt::shade::FivProxy::cone;
    }
    const prt::shade::DifMap map = scene->map();
    for (size_t k = 0; k < count; ++k)
      prt::shade::shade_fiv(map, scene->views.data(), int(scene->views.size()), positions + 3 * k, normals + 3 * k, o,
                            out + 3 * k);
  });
}

prt_status prt_fiv_scene_shade_self(const prt_fiv_scene* scene, int index, const float* positions,
                                    const float* normals, size_t count, float* out) {
  return guarded(__func__, [&] {
    require(scene != nullptr, "scene is null");
    const prt::shade::FivOccluder& occ = occluder_at(scene, index);
    if (count == 0) return;
    require(positions != nullptr && normals != nullptr && out != nullptr, "null pointer");
    for (size_t k = 0; k < count; ++k)
      prt::shade::shade_fiv_self(scene->environment, occ, positions + 3 * k, normals + 3 * k, out + 3 * k);
  });
}

prt_status prt_fiv_scene_shade_member(const prt_fiv_scene* scene, int index, const float* positions,
                                      const float* normals, size_t count, int partial, float* out) {
  return guarded(__func__, [&] {
    require(scene != nullptr, "scene is null");
    occluder_at(scene, index);  // checks the index
    if (count == 0) return;
    require(positions != nullptr && normals != nullptr && out != nullptr, "null pointer");
    for (size_t k = 0; k < count; ++k)
      prt::shade::shade_fiv_member(scene->environment, scene->views.data(), int(scene->views.size()), index,
                                   positions + 3 * k, normals + 3 * k, partial != 0, out + 3 * k);
  });
}

prt_status prt_fiv_scene_shade_member_given_self(const prt_fiv_scene* scene, int index, const float* positions,
                                                 const float* normals, const float* self_irradiance, size_t count,
                                                 int partial, float* out) {
  return guarded(__func__, [&] {
    require(scene != nullptr, "scene is null");
    occluder_at(scene, index);  // checks the index
    if (count == 0) return;
    require(positions != nullptr && normals != nullptr && self_irradiance != nullptr && out != nullptr, "null pointer");
    for (size_t k = 0; k < 3 * count; ++k) require(std::isfinite(self_irradiance[k]), "self_irradiance is not finite");
    for (size_t k = 0; k < count; ++k)
      prt::shade::shade_fiv_member_given_self(self_irradiance + 3 * k, scene->views.data(), int(scene->views.size()), index,
                                              positions + 3 * k, normals + 3 * k, partial != 0, out + 3 * k);
  });
}

prt_status prt_shade_lights(const float* irradiance, size_t count, size_t lights, const float* emission,
                            const float* albedo, int albedo_per_receiver, float* out) {
  return guarded(__func__, [&] {
    require(out != nullptr && albedo != nullptr && (count == 0 || lights == 0 || irradiance != nullptr) &&
                (lights == 0 || emission != nullptr),
            "null pointer");
    for (size_t k = 0; k < 3 * lights; ++k)
      require(std::isfinite(emission[k]) && emission[k] >= 0, "emission must be finite and >= 0");
    for (size_t k = 0; k < count * lights; ++k) require(std::isfinite(irradiance[k]), "irradiance is not finite");
    const size_t albedos = albedo_per_receiver ? count : 1;
    for (size_t k = 0; k < 3 * albedos; ++k) require(std::isfinite(albedo[k]), "albedo is not finite");
    prt::shade::shade_lights(irradiance, count, lights, emission, albedo, albedo_per_receiver ? 3 : 0, out);
  });
}

prt_status prt_punctual_irradiance(const prt_punctual_light* light, const float p[3], const float n[3], float* out) {
  return guarded(__func__, [&] {
    require(light != nullptr && p != nullptr && n != nullptr && out != nullptr, "null pointer");
    require(light->kind >= PRT_PUNCTUAL_DIRECTIONAL && light->kind <= PRT_PUNCTUAL_SPOT, "kind is not a prt_punctual_kind");
    prt::shade::PunctualLight l;
    l.kind = prt::shade::PunctualKind(light->kind);
    for (int k = 0; k < 3; ++k) {
      require(std::isfinite(light->position[k]) && std::isfinite(light->direction[k]) && std::isfinite(p[k]),
              "position, direction or p is not finite");
      l.position[size_t(k)] = light->position[k];
      l.direction[size_t(k)] = light->direction[k];
    }
    const double d2 = l.direction[0] * l.direction[0] + l.direction[1] * l.direction[1] + l.direction[2] * l.direction[2];
    require(l.kind == prt::shade::PunctualKind::Point || d2 > 0, "direction is zero");
    l.inner_cone = light->inner_cone_angle;
    l.outer_cone = light->outer_cone_angle;
    if (l.kind == prt::shade::PunctualKind::Spot)
      require(l.inner_cone >= 0 && l.inner_cone < l.outer_cone && l.outer_cone <= 1.5707963705062866,
              "cone angles need 0 <= inner < outer <= pi/2");
    require(std::isfinite(light->range) && light->range >= 0, "range must be finite and >= 0 (0: none)");
    require(light->range == 0 || l.kind != prt::shade::PunctualKind::Directional, "a directional light has no range");
    l.range = light->range;
    const double r2 = double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2];
    require(std::isfinite(r2) && std::fabs(r2 - 1.0) <= 1e-4, "n is not unit length (to 1e-4)");
    *out = float(prt::shade::unshadowed_punctual(l, {p[0], p[1], p[2]}, {n[0], n[1], n[2]}));
  });
}

prt_status prt_ltc_ggx(const float n[3], const float v[3], float alpha, float f0, const float* arcs, size_t count,
                       float* out) {
  return guarded(__func__, [&] {
    namespace ltc = prt::shade::ltc;
    require(n != nullptr && v != nullptr && out != nullptr && (count == 0 || arcs != nullptr), "null pointer");
    auto unit = [](const float* x) {
      const double r2 = double(x[0]) * x[0] + double(x[1]) * x[1] + double(x[2]) * x[2];
      return std::isfinite(r2) && std::fabs(r2 - 1.0) <= 1e-4;
    };
    require(unit(n) && unit(v), "n and v must be unit length (to 1e-4)");
    require(std::isfinite(alpha) && alpha > 0, "alpha must be finite and > 0");
    require(f0 >= 0 && f0 <= 1, "f0 must be in [0, 1]");
    const ltc::Vec3 nd{n[0], n[1], n[2]}, vd{v[0], v[1], v[2]};
    std::vector<ltc::Arc> region(count);
    for (size_t k = 0; k < count; ++k) {
      const float* a = arcs + 6 * k;
      for (int i = 0; i < 6; ++i) require(std::isfinite(a[i]), "an arc is not finite");
      region[k] = {{a[0], a[1], a[2]}, {a[3], a[4], a[5]}};
      for (const ltc::Vec3& w : {region[k].a, region[k].b}) {
        const double len = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
        require(len > 0, "an arc's endpoint is zero");
        require(nd[0] * w[0] + nd[1] * w[1] + nd[2] * w[2] >= -1e-6 * len, "an arc's endpoint is below n's horizon");
      }
    }
    const ltc::Lobe lobe = ltc::ggx_lobe(ltc::ggx_table(), nd, vd, alpha);
    *out = float(lobe.scale(f0) * ltc::integrate(lobe, region));
  });
}

prt_status prt_ltc_ggx_error_bound(float alpha, float cos_theta, float f0, float* out) {
  return guarded(__func__, [&] {
    require(out != nullptr, "null pointer");
    require(std::isfinite(alpha) && alpha > 0, "alpha must be finite and > 0");
    require(cos_theta >= 0 && cos_theta <= 1, "cos_theta must be in [0, 1]");
    require(f0 >= 0 && f0 <= 1, "f0 must be in [0, 1]");
    *out = float(prt::shade::ltc::error_bound(prt::shade::ltc::ggx_table(), alpha, cos_theta, f0));
  });
}

} // extern "C"
