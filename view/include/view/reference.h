// view/reference.h — the Embree ray-traced reference renderer (the brute-force ground truth of
// paper 004 §5: "the standard rendering formula, Equation (2), with an overall integration of the
// unoccluded part of the environment map as it is seen from each pixel") and its on-disk cache.
// It sees the same pixels as the rasterizer (view/camera.h, view/raster.h). Layers:
// docs/ARCHITECTURE.md §2.
//
// REFERENCE (ReferenceRenderer). Per pixel: one primary ray through the pixel centre (Embree
// closest hit, same near plane) gives p, the shading normal n (the interpolated vertex normals,
// as the rasterizer) and the geometric normal; the pixel value is the outgoing radiance of a
// white Lambertian surface, E / π, with the irradiance
//   E(p, n) = ∫ L(ω) V(p, ω) H(ω, n) (n · ω) dω     (docs/ARCHITECTURE.md §3; paper 004 eq. 2)
// computed as E = E_unocc(n) − ∫ L (1 − V) H (n · ω) dω:
//   * E_unocc(n) = E_tot(n) of bake/environment/irradiance.h (UnshadowedIrradiance: the same function the
//     DifMap of FIV files samples), a deterministic sum over every environment texel: no noise
//     where nothing occludes;
//   * the occluded part by randomised QMC (bake/sphere/sampling.h: a 3D Halton sequence with a
//     Cranley–Patterson rotation keyed by (seed, pixel index, replicate) — identical bytes for any
//     thread count), as 8 independent replicates of samples/8 points each: the estimate is their
//     mean and its standard error the spread of the 8 means / √8 (the honest RQMC error; the iid
//     sample variance would overstate it because QMC converges faster than 1/√N). Directions
//     are drawn from a one-sample mixture weighted by the balance heuristic:
//     cosine-weighted hemisphere around n, the environment's luminance (EnvMap::sample) and,
//     when `occluder_spheres` are given, a uniform cone around each sphere that p sees from
//     outside (half-angle asin(R / D)) — the FIV scenes pass their occluders' bounding spheres,
//     so nearly every shadow ray is spent where occlusion can happen. Weights: ¼ cosine, ¼
//     environment, ½ shared by the cones; without cones ½ / ½. Every estimator term is
//     L (n·ω) (1 − V) / p_mixture with p_mixture ≥ w_cos (n·ω)/π, so it is bounded.
//   * visibility: a shadow ray from p + ε n_g (n_g the geometric normal turned to the side of n,
//     ε = 1e-5 × the scene's bounding-box diagonal) to infinity; any hit occludes.
//   * scenes of several objects (ReferenceOptions::casts_shadow / albedo): shadow rays see only
//     the casting triangles (a separate Embree scene over them), the pixel is albedo · E / π.
// BOUNCES (ReferenceOptions::bounces = B > 0; issue 31, environment lighting only): the pixel is
// albedo(p) · E(p)/π with E the irradiance INCLUDING up to B bounces of diffuse interreflection
// between Lambertian triangles (albedo per triangle, ReferenceOptions::albedo; white if empty),
// the rendering equation's Neumann series cut after exactly B reflections, as the bake's
// (bake/bake/bounce.h eq. (2)): E = E_direct + E_ind,
//   E_ind(p) = ∫ H L_out(h(p, ω)) (n·ω) dω,   L_out(h) = (ρ(h)/π) (E_direct(h) + E_ind(h)),
// where h is the first point of the casting triangles the ray from p meets (the sky adds nothing
// there: it is E_direct's). E_direct(p) is the estimator above, unchanged (B = 0 gives the same
// bytes). E_ind(p) is a path tracer, independent of it: `samples` paths per pixel in 8 replicates
// of their own (the Halton rotation keyed by a second seed), each path a cosine-weighted
// continuation ray (pdf (n·ω)/π: the estimate of E_ind(p) is π L_out(h) = ρ(h) E(h)) and at every
// vertex h one next-event estimate of E_direct(h), L V (n_h·ω)/p for one direction of the cosine +
// environment mixture above (½ each, no cones; p ≥ (n·ω)/(2π) bounds it by 2π L; E_unocc(n_h) per
// vertex, as at the pixel, made the bunny view 60× slower under a 1024 × 512 map), so a path of B segments collects
//   Σ_{k=1..B} (ρ(h_1) ⋯ ρ(h_k)) E_direct(h_k)
// and stops at exactly B (no Russian roulette: the truncation is exact, the estimate unbiased for
// the B-bounce sum). A continuation ray that leaves to the sky or meets a triangle from behind
// (the winding's side, as the bake's gather) ends the path: back faces are black. The first
// segment's direction is the replicate's Halton point (dimensions 1, 2); every later number comes
// from a counter-based hash of (seed, pixel, replicate, point, depth): identical bytes for any
// thread count. Standard error: √(se_direct² + se_ind²), the two estimates being independent.
// Glossy mode takes no bounces.
// The per-pixel standard error (of the QMC term, from the replicates) is returned with the
// picture; compare_images (view/image.h) turns it into the reference's own noise figure.
#pragma once

#include <view/camera.h>
#include <view/image.h>
#include <view/raster.h>

#include <bake/core/progress.h>
#include <bake/environment/envmap.h>
#include <bake/environment/irradiance.h>
#include <bake/mesh/mesh.h>

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace prt::view {

// A sphere the reference may importance-sample (an occluder's bounding sphere).
struct Sphere {
  Eigen::Vector3d centre{0, 0, 0};
  double radius = 0;
};

struct ReferenceOptions {
  uint32_t samples = 1024;  // QMC shadow rays per pixel (occluded part); a multiple of 8 (8 replicates)
  uint64_t seed = 1;
  std::vector<Sphere> occluder_spheres;
  // Scenes of several objects (prtview on scene files, roles of bake/bake/scene.h), one entry per
  // triangle of the rendered mesh; empty vectors keep the single-object behaviour above.
  //   casts_shadow[t] == 0: triangle t is seen by primary rays but never blocks a shadow ray (an
  //     object with role "receiver" casts no shadow, not even on itself). When no triangle casts,
  //     nothing is occluded and E = E_unocc exactly (no shadow rays, standard error 0).
  //   albedo[t]: diffuse albedo (RGB) of triangle t: the pixel shows albedo · E/π and its standard
  //     error scales alike. Empty: white (albedo 1), the E/π above.
  std::vector<uint8_t> casts_shadow;
  std::vector<std::array<float, 3>> albedo;
  // GLOSSY mode (prtview --shade glossy; prtshade/glossy.h's integral): instead of albedo · E/π,
  // pixel = specular[t] · ∫ L(ω) V(p, ω) H(ω, n) k_s(r·ω) dω with the normalised Phong lobe
  // k_s(t) = (s+1)/(2π) max(t, 0)^s, s = phong[t] (0 where phong[t] <= 0: the pixel is 0),
  // r = 2(n·v)n − v, v = normalize(eye − p). Estimated by randomised QMC (the same replicates and
  // visibility as above) from a one-sample mixture, balance heuristic: ½ the lobe itself (pdf k_s)
  // and ½ the environment's luminance; each term L V H k_s / p is bounded by 2 L k_s / k_s or by
  // 2 L k_s / p_env, finite for any environment. One entry per triangle.
  struct Glossy {
    Eigen::Vector3d eye{0, 0, 0};
    std::vector<double> phong;
    std::vector<std::array<float, 3>> specular;
  };
  std::optional<Glossy> glossy;
  // Diffuse interreflection: bounces of light between the triangles (BOUNCES above); 0 = direct only.
  uint32_t bounces = 0;
  // Scenes with bounces, one entry per triangle (empty: every triangle reflects with albedo[t] and
  // gathers). They make the reference hold the light the bake claims, object by object:
  //   reflectance[t]: the albedo a path continues with when it meets triangle t (0: absorbs). A
  //     scene object that reflects nothing in the bake (an occluder only, or one with no diffuse
  //     albedo, whose picture is drawn white) reflects nothing here either, while albedo[t] stays
  //     its picture's tint.
  //   gathers[t] == 0: triangle t's pixels show direct light only (its product is direct by design:
  //     AO, FIV shells, flat grey), so no indirect path is traced from it.
  std::vector<std::array<float, 3>> reflectance;
  std::vector<uint8_t> gathers;
};

struct ReferenceImage {
  GBuffer gbuffer;   // primary hits
  Image radiance;    // E / π (white Lambertian), RGB
  Image std_error;   // standard error of each value (the QMC term)
  double seconds = 0;
  uint64_t rays = 0;  // primary + shadow rays cast
};

class ReferenceRenderer {
public:
  // `mesh` and `env` must outlive the renderer. Builds an Embree BVH over the mesh.
  ReferenceRenderer(const bake::Mesh& mesh, const bake::EnvMap& env, ReferenceOptions options);
  ~ReferenceRenderer();
  ReferenceRenderer(const ReferenceRenderer&) = delete;
  ReferenceRenderer& operator=(const ReferenceRenderer&) = delete;

  // Primary rays only: the G-buffer of what each pixel centre sees.
  GBuffer trace_primary(const Camera& camera) const;
  ReferenceImage render(const Camera& camera, const bake::Monitor& monitor = {}) const;

  // The glossy integral (ReferenceOptions::glossy, without the specular colour) at a fragment for
  // exponent s and its standard error; `index` keys the randomisation.
  void glossy(const Fragment& f, uint64_t index, double s, double out[3], double std_error[3]) const;
  // Irradiance E (RGB) at a fragment and its standard error; `index` keys the randomisation.
  void irradiance(const Fragment& f, uint64_t index, double E[3], double std_error[3]) const;
  std::string description() const;
  // A key naming everything that determines render(camera) — the mesh, per-triangle casters and
  // albedos, the camera, the occluder spheres, the environment's SHA-256 and description() — for
  // the on-disk cache below.
  std::string cache_key(const Camera& camera) const;

private:
  // irradiance() with the unshadowed part E_unocc(f.n) already known.
  void irradiance(const Fragment& f, uint64_t index, const bake::Rgb& unocc, double E[3], double std_error[3]) const;
  // E_ind(f) of BOUNCES and its standard error; returns the rays cast.
  uint64_t indirect(const Fragment& f, uint64_t index, double E[3], double std_error[3]) const;
  double albedo(int32_t triangle, int c) const;
  double reflectance(int32_t triangle, int c) const;  // ReferenceOptions::reflectance, else albedo
  struct Rays;  // bake/visibility/raycast.h RayCaster over the mesh
  const bake::Mesh& mesh_;
  const bake::EnvMap& env_;
  ReferenceOptions options_;
  bake::UnshadowedIrradiance unoccluded_;
  std::unique_ptr<Rays> rt_;
  double epsilon_ = 0;
};

// A reference render kept on disk so several runtime renders of one view can be compared against
// it without tracing it again (prtview --reference-cache). OpenEXR file: channels R, G, B (radiance),
// se.R, se.G, se.B (standard errors) as float, "triangle" as uint (0xFFFFFFFF = nothing hit), and
// a string attribute "prt_reference_key" that names what was rendered (the caller builds it from
// everything that determines the picture). save writes a temporary file and renames it.
// load returns nothing when the file does not exist or its key differs; a damaged file throws
// bake::InputError. Only gbuffer.triangle is restored (barycentrics are not kept).
void save_reference(const std::filesystem::path& path, const ReferenceImage& image, const std::string& key);
std::optional<ReferenceImage> load_reference(const std::filesystem::path& path, const std::string& key);

} // namespace prt::view
