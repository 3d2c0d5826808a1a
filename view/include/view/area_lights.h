// view/area_lights.h — direct lighting from area lights, per pixel (issue 13; paper 003 §5, the
// equal-time comparison against ray tracing): the analytic render with exact soft shadows and its
// Embree reference, for the same pixels (view/raster.h G-buffers). Layers: docs/ARCHITECTURE.md §2.
//
// Both show a Lambertian surface of albedo `albedo` (white by default) lit by the lights only:
//   L_o(p) = albedo/π · Σ_l radiance_l · E_l(p', n),   E_l = ∫_{visible part of light l} max(n·ω, 0) dω,
// at the pixel's surface point p moved off its triangle to p' = p + ε n_g (n_g the geometric
// normal turned to the side of n; ε = 1e-5 × the mesh's diagonal + 1e-6 × its largest coordinate,
// as the environment reference, view/reference.h), with n the interpolated shading normal, so
// that both methods see the same point and neither meets its own triangle.
//   * Analytic (render_area_analytic): E_l from bake/lights/area_bake.h at p' (the light's spherical
//     polygon minus every triangle's image, clipped to n's horizon, Lambert's closed form): exact,
//     no noise. Cost grows with the triangles between the point and the light (bake/visibility/occluder_mesh.h).
//   * Reference (render_area_reference): light sampling with shadow rays. Per pixel and light, N
//     points y uniform over the light's area A (a face by its area, then a uniform point of a
//     triangle of its fan, from a randomised 3D Halton point: bake/sphere/sampling.h RotatedHalton3 keyed by
//     (seed, pixel, light, replicate)), each contributing
//       A · max(n·ω, 0) · c_l / r² · [segment p'→y unblocked],  ω = (y − p')/r, r = |y − p'|,
//     with c_l = −n_f·ω on a face's emitting side (|n_f·ω| for two-sided lights) and 0 behind it:
//     an unbiased estimate of E_l. With N ≥ 8 (a multiple of 8) the N points form 8 independent
//     replicates whose spread gives the per-pixel standard error; fewer give no error estimate.
// Glossy (AreaRenderOptions::ggx set): a GGX specular layer added to the diffuse one (no energy
// exchange between the two; prtshade/ltc.h's BRDF: height-correlated Smith masking, Schlick's
// Fresnel with per-channel F0, roughness α), with v = (eye − p')/|eye − p'| and n as above:
//   L_o(p) += Σ_l radiance_l · ∫_{visible part of light l} f(v, ω) max(n·ω, 0) dω.
//   * Analytic: each light face's visible arcs (bake/visibility/occluder_mesh.h OccluderMesh::visible_light,
//     the faces and emitting sides decided as bake/lights/area_bake.h does) integrated through the
//     linearly transformed cosines of prtshade/ltc.h: (F0·A + (1 − F0)·B) · ∫ D_M; E from the same
//     arcs. Not exact: within prtshade::ltc::error_bound per light (the fit's measured bound).
//   * Reference: the same light samples also weigh f(v, ω) (an unbiased estimate of the integral).
// Every pixel's value depends only on its own inputs and the seed: the same bytes for any thread
// count. Uncovered pixels are 0.
#pragma once

#include <view/image.h>
#include <view/raster.h>

#include <bake/lights/lights.h>
#include <bake/lights/punctual.h>
#include <bake/mesh/mesh.h>

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace prt::view {

struct GgxLayer {
  double alpha = 0.3;                        // GGX roughness (the LTC table covers [0.01, 1])
  std::array<double, 3> f0{0.04, 0.04, 0.04};  // Schlick's F0 per channel
  Eigen::Vector3d eye{0, 0, 1};              // the camera's eye, in the frame of the G-buffer's points
};

struct AreaRenderOptions {
  std::array<double, 3> albedo{1, 1, 1};
  std::optional<GgxLayer> ggx;  // unset: diffuse only
  // Scenes of several objects (prtview on scene files), one entry per triangle of the rendered
  // mesh; empty vectors keep the single-object behaviour. casts_shadow[t] == 0: triangle t is drawn
  // but blocks no light (a bake's "receiver" objects); triangle_albedo[t] replaces `albedo` there.
  std::vector<uint8_t> casts_shadow;
  std::vector<std::array<float, 3>> triangle_albedo;
  // Punctual lights (bake/lights/punctual.h, world space), added to both renders alike and
  // exactly (they have no area to sample): intensity · E with its one shadow ray from p'
  // (PunctualLightIntegrator over the shadow-casting triangles), times the albedo / π, and with
  // the GGX layer f(v, l) · E.
  std::vector<bake::PunctualLight> punctual;
};

// Exact: E per light from the closed forms (above); the glossy layer through LTC.
Image render_area_analytic(const bake::Mesh& mesh, const GBuffer& g, std::span<const bake::AreaLight> lights,
                           const AreaRenderOptions& options = {});

struct AreaReferenceOptions {
  uint32_t samples = 64;  // shadow rays per pixel and light: 1..7, or a multiple of 8 (replicates)
  uint64_t seed = 1;
  AreaRenderOptions render;
  // Diffuse interreflection (issue 31), the area lights' counterpart of view/reference.h BOUNCES:
  // the diffuse term's E_l gets E_l^ind = ∫ (ρ(h)/π) E_l(h) max(n·ω, 0) dω over the hemisphere, h
  // the first casting surface along ω, E_l(h) its own direct + indirect irradiance, cut at exactly
  // `bounces` reflections. Per replicate, `samples`/8 paths per pixel: cosine-distributed
  // directions (the pdf cancels the cosine, so a path vertex adds ρ(h_1)…ρ(h_k) · E_l(h_k)); at each
  // vertex h on a casting triangle's FRONT face (back faces are black, as the bake's), one light
  // sample per light estimates E_l(h) as above (next-event estimation). Per channel: the light's
  // radiance and the reflectances are RGB. The glossy layer takes no indirect light.
  //   reflectance[t] (one per triangle of the mesh, empty: the picture's albedo): the albedo a
  //     path continues with at triangle t (0: absorbs; view/reference.h's rule);
  //   gathers[t] == 0 (empty: all gather): triangle t's pixels get the direct light only.
  uint32_t bounces = 0;
  std::vector<std::array<float, 3>> reflectance;
  std::vector<uint8_t> gathers;
};
struct AreaReferenceImage {
  Image radiance;
  Image std_error;  // per channel; all 0 when samples < 8 (no replicates)
};
AreaReferenceImage render_area_reference(const bake::Mesh& mesh, const GBuffer& g, std::span<const bake::AreaLight> lights,
                                         const AreaReferenceOptions& options);

// The offset ε of the shading points (above) for this mesh.
double area_shading_offset(const bake::Mesh& mesh);

} // namespace prt::view
