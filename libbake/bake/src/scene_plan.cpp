// scene_plan.cpp — what a scene needs baked, per object and scene-wide, each decision with its
// reason (bake/bake/scene.h, the rules of plan_scene).
#include <bake/bake/fiv.h>
#include <bake/bake/bounce.h>
#include <bake/bake/scene.h>
#include <bake/core/error.h>
#include <bake/sphere/zonal.h>

#include <prtshade/sh.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace prt::bake {
namespace {
std::string density_text(double d) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", d);
  return buf;
}
} // namespace

namespace {

// The rule "bounces" (scene.h): who gathers, who reflects, whether the transfer bounces.
void plan_bounces(const SceneDescription& scene, ScenePlan& plan) {
  if (scene.bounces <= 0) return;
  const std::string b = "bounces: ";
  std::vector<size_t> reflect;
  bool gathers = false, grey = true;
  std::set<int> orders;
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const SceneObject& o = scene.objects[i];
    ObjectPlan& p = plan.objects[i];
    if (!p.receiver) {
      p.left_out.push_back(b + "occluder only: it casts shadows but has no rows, so it reflects no light (role \"both\" "
                               "with a diffuse albedo to have it reflect)");
      continue;
    }
    if (!p.radiance && p.transfer_order == 0 && !p.area_irradiance && p.shadowed_order == 0) {
      p.left_out.push_back(b + "no band-1 radiance, diffuse transfer, shadowed radiance or area-light irradiance to "
                               "bounce");
      continue;
    }
    gathers = true;
    if (p.transfer_order > 0) orders.insert(p.transfer_order);
    if (!p.occluder) {
      p.left_out.push_back(b + "receiver only: it is not in the occluders' union, so no ray meets it: it gathers the "
                               "others' light but reflects none");
    } else if (o.material.diffuse()) {
      for (size_t c = 0; c < 3; ++c)
        if (!(o.material.albedo[c] < 1))
          throw InputError(scene.file.string(), "object '" + o.name + "': albedo " + albedo_text(o.material.albedo) +
                                                    " with bake.bounces: an albedo must be below 1, or the bounces "
                                                    "would not converge");
      p.bounce_reflects = true;
      reflect.push_back(i);
      grey = grey && o.material.albedo[0] == o.material.albedo[1] && o.material.albedo[0] == o.material.albedo[2];
    }
  }
  if (!gathers || reflect.empty()) {
    plan.notes.push_back(b + std::to_string(scene.bounces) + " asked, none baked: " +
                         (!gathers ? "no receiver has band-1 radiance, diffuse transfer, shadowed radiance or "
                                     "area-light irradiance"
                                   : "no surface reflects (a reflecting surface is a \"both\" object with a diffuse "
                                     "albedo)"));
    return;
  }
  plan.bounces = true;
  const bool transfer = !orders.empty() && grey && orders.size() == 1;
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    ObjectPlan& p = plan.objects[i];
    if (!p.receiver || (!p.radiance && p.transfer_order == 0 && !p.area_irradiance && p.shadowed_order == 0)) continue;
    p.bounce_radiance = p.radiance;
    p.bounce_shadowed = p.shadowed_order > 0;
    p.bounce_transfer = transfer && p.transfer_order > 0;
    p.bounce_area = grey && p.area_irradiance;
    std::string what;
    for (const auto& [on, name] : {std::pair{p.bounce_radiance, "radiance/band1"},
                                   std::pair{p.bounce_transfer, "transfer/diffuse"},
                                   std::pair{p.bounce_shadowed, "radiance/shadowed"},
                                   std::pair{p.bounce_area, "area_lights/irradiance"}})
      if (on) what += (what.empty() ? "" : ", ") + std::string(name);
    if (!what.empty())
      p.baked.push_back(b + what + " with " + std::to_string(scene.bounces) + " bounce(s) of the light the " +
                        std::to_string(reflect.size()) + " reflecting object(s) send" +
                        (p.bounce_reflects ? " (this one at albedo " + albedo_text(scene.objects[i].material.albedo) + ")"
                                           : ""));
    if (p.transfer_order > 0 && !p.bounce_transfer)
      p.left_out.push_back(b + "transfer/diffuse stays direct: " +
                           (!grey ? std::string("a reflecting object's albedo is coloured and the transfer is one vector "
                                                "for all channels")
                                  : std::string("the receivers' transfers have different orders")));
    if (p.area_irradiance && !p.bounce_area)
      p.left_out.push_back(b + "area_lights/irradiance stays direct: a reflecting object's albedo is coloured and E_l "
                               "is one value for all channels");
  }
  std::string names;
  for (const size_t i : reflect) names += (names.empty() ? "" : ", ") + scene.objects[i].name;
  plan.notes.push_back(b + std::to_string(scene.bounces) + " of diffuse interreflection, " +
                       std::to_string(scene.bounce_rays ? scene.bounce_rays : BounceSpec::kDefaultRays) +
                       " gather rays per receiver row; reflecting: " + names);
}

} // namespace

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
      if (o.lightmap) p.left_out.push_back("lightmap: occluder only (role \"occluder\"): nothing is shaded on it");
    } else {
      if (o.lightmap) {
        const LightmapSpec& l = *o.lightmap;
        p.texels = true;
        p.baked.push_back(std::string("lightmap: the products below per texel instead of per vertex, ") +
                          (l.width ? std::to_string(l.width) + "x" + std::to_string(l.height) + " texels"
                                   : "at " + density_text(l.density) + " texels per unit") +
                          (l.unwrap ? " in generated UVs" : l.uv_set.empty() ? "" : " in UV set " + l.uv_set));
      }
      if (scene.want_ao) p.ao = true, p.baked.push_back("ao: requested");
      else p.left_out.push_back("ao: not in bake.products");
      const Material& m = o.material;
      if (scene.light_count() > 0) {
        p.area_irradiance = true;
        std::string what;
        if (!scene.lights.empty())
          what = std::to_string(scene.lights.size()) + " area light(s), exact soft shadows (paper 003)";
        if (!scene.punctual_lights.empty())
          what += (what.empty() ? "" : "; ") + std::to_string(scene.punctual_lights.size()) +
                  " punctual light(s), exact hard shadows (one shadow ray in the vertex limit)";
        p.baked.push_back("area_lights/irradiance: " + what);
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
          if (scene.light_count() > 0)
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
            if (scene.light_count() > 0) {
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
  plan_bounces(scene, plan);
  if (plan.fiv_environment) plan.notes.push_back("fiv/environment and fiv/irradiance_cube: some occluder has shells");
  else plan.notes.push_back("fiv/environment and fiv/irradiance_cube: left out, no occluder has shells");
  return plan;
}

} // namespace prt::bake
