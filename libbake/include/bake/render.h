// bake/render.h — looking at baked data: a pinhole camera, a small software rasterizer (what an
// engine does with the baked per-vertex and FIV data) and an Embree ray-traced reference renderer
// (the brute-force ground truth of paper 004 §5: "the standard rendering formula, Equation (2),
// with an overall integration of the unoccluded part of the environment map as it is seen from
// each pixel"). prtview is the tool on top; bake/image_io.h writes the pictures.
//
// CAMERA. Right-handed world, look-at: forward f = normalize(at − eye), right r = normalize(f × up),
// true up u = r × f. fov_y_degrees is the full vertical field of view; aspect = width / height.
// Pixel (x, y) covers [x, x+1) × [y, y+1), y grows DOWNWARDS, row 0 is the top of the picture and
// the pixel is sampled at its centre (x + ½, y + ½) by both renderers, so their pictures line up
// pixel for pixel. Continuous pixel position (sx, sy) ↔ view ray direction
//   d ∝ f + ((2 sx / W − 1) · aspect · tan(fov/2)) r + ((1 − 2 sy / H) · tan(fov/2)) u.
// View depth of a point q: z = f · (q − eye). Geometry with z < near is clipped (both renderers:
// the rasterizer clips triangles against the plane z = near, the ray tracer starts each primary
// ray at depth near). near = 1e-4 · |at − eye| unless set.
//
// RASTERIZER (rasterize). Every triangle is drawn from both sides (no culling: baked meshes have
// any winding). Per triangle: vertices to view space, clip against z = near (Sutherland–Hodgman,
// one plane: a triangle becomes 0, 1 or 2 triangles whose corners carry their barycentric
// coordinates in the original triangle), project to the screen, then for each pixel centre in
// the bounding box evaluate the three edge functions E(p) = (b − a) × (p − a) in double.
// Coverage rules:
//   * inside ⇔ every edge function is > 0 after orienting each edge towards the opposite corner,
//     or = 0 on a TOP or LEFT edge (top-left fill rule, as Direct3D/OpenGL): with E = A x + B y + C
//     oriented inwards, an edge owns its pixels iff A > 0 (the triangle lies to its right: a left
//     edge) or A = 0 and B > 0 (horizontal, the triangle lies below: a top edge; y points down).
//     Two triangles sharing an edge have exactly opposite gradients there, so exactly one of them
//     owns each pixel centre on it.
//   * Each edge function is evaluated from a canonical endpoint order (by vertex key: mesh index,
//     clip vertices after all mesh vertices, ordered by the edge they lie on) and negated when
//     needed, so neighbours compute bit-identical |E| on their shared edge — no cracks, no double
//     coverage (the tests count it).
//   * Depth test: the smallest view depth wins; equal depths keep the earlier triangle.
// Interpolation is perspective-correct: with screen-space barycentrics λ_k and view depths z_k of
// the (clipped) corners, the attribute weights are w_k = (λ_k / z_k) / Σ_j (λ_j / z_j) and the
// depth is 1 / Σ_j (λ_j / z_j). The G-buffer keeps, per pixel, the triangle and its barycentric
// coordinates in the ORIGINAL triangle; position, normal (interpolated vertex normals,
// normalised) and per-vertex attributes follow from them.
//
// REFERENCE (ReferenceRenderer). Per pixel: one primary ray through the pixel centre (Embree
// closest hit, same near plane) gives p, the shading normal n (the interpolated vertex normals,
// as the rasterizer) and the geometric normal; the pixel value is the outgoing radiance of a
// white Lambertian surface, E / π, with the irradiance
//   E(p, n) = ∫ L(ω) V(p, ω) H(ω, n) (n · ω) dω     (DESIGN.md §3; paper 004 eq. 2)
// computed as E = E_unocc(n) − ∫ L (1 − V) H (n · ω) dω:
//   * E_unocc(n) = Σ_t L_t max(0, n · M_t), M_t = ∫_texel ω dω (UnoccludedIrradiance below), a
//     deterministic sum over every environment texel: no noise where nothing occludes;
//   * the occluded part by randomised QMC (bake/sampling.h: a 3D Halton sequence with a
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
// The per-pixel standard error (of the QMC term, from the replicates) is returned with the
// picture; compare_images (bake/image_io.h) turns it into the reference's own noise figure.
#pragma once

#include <bake/envmap.h>
#include <bake/image_io.h>
#include <bake/mesh.h>
#include <bake/progress.h>

#include <Eigen/Core>
#include <array>
#include <functional>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace prt::bake {

struct Camera {
  Eigen::Vector3d eye{0, 0, 1}, at{0, 0, 0}, up{0, 1, 0};
  double fov_y_degrees = 45;
  int width = 256, height = 256;
  double near = 0;  // 0: 1e-4 · |at − eye|

  Eigen::Vector3d forward() const;   // f
  Eigen::Vector3d right() const;     // r
  Eigen::Vector3d true_up() const;   // u
  double near_depth() const;
  // Unit direction of the ray through continuous pixel position (sx, sy) (pixel centres at +½).
  Eigen::Vector3d ray_direction(double sx, double sy) const;
  // Throws InputError("--camera", …) when eye == at, up ∥ (at − eye), fov ∉ (0, 180) or the
  // size is not in [1, 16384]².
  void validate() const;
};

// "eye=X,Y,Z:at=X,Y,Z[:up=X,Y,Z][:fov=DEGREES]" (any order, each key at most once; eye and at
// required). Throws InputError("--camera", "<what is wrong>").
Camera parse_camera(std::string_view spec, int width, int height);
// "WxH", each in [1, 16384]. Throws InputError("--size", …).
std::array<int, 2> parse_size(std::string_view spec);

// Per pixel: the visible triangle (−1: nothing) and the barycentric coordinates of the pixel's
// sample in that triangle (weights of its corners 0, 1, 2; perspective-correct).
struct GBuffer {
  int width = 0, height = 0;
  std::vector<int32_t> triangle;
  std::vector<std::array<float, 3>> bary;
  std::vector<float> depth;  // view depth (f · (q − eye)); +inf where nothing is drawn
  size_t covered() const;
};

GBuffer rasterize(const Mesh& mesh, const Camera& camera);

// What a shader sees at one pixel.
struct Fragment {
  int x = 0, y = 0;
  int32_t triangle = -1;
  std::array<float, 3> bary{};
  Eigen::Vector3d p{0, 0, 0};   // world position
  Eigen::Vector3d n{0, 1, 0};   // interpolated vertex normal, normalised (the geometric one if that is zero)
  Eigen::Vector3d ng{0, 1, 0};  // unit geometric normal, turned to the side of n
};
Fragment make_fragment(const Mesh& mesh, const GBuffer& g, int x, int y);

// Calls shade(fragment, rgb) for every covered pixel (in parallel: `shade` must be thread-safe);
// uncovered pixels are 0.
Image shade_pixels(const Mesh& mesh, const GBuffer& g, const std::function<void(const Fragment&, float*)>& shade);
// Gouraud: per-vertex RGB (3 floats per mesh vertex) interpolated with the G-buffer's weights.
Image interpolate_vertices(const Mesh& mesh, const GBuffer& g, std::span<const float> vertex_rgb);
// Several objects drawn as one mesh: Gouraud of `vertex_rgb` (3 floats per mesh vertex) on every
// triangle t with per_pixel[t] == 0, `shade` per pixel on the others (prtview: the FIV self-shadows
// of occluder-only objects next to per-vertex receivers). per_pixel has one entry per triangle.
Image shade_mixed(const Mesh& mesh, const GBuffer& g, std::span<const float> vertex_rgb,
                  std::span<const uint8_t> per_pixel, const std::function<void(const Fragment&, float*)>& shade);

// Exact unshadowed irradiance of a piecewise-constant environment (bake/envmap.h) for any unit
// normal: E_unocc(n) = Σ_t L_t max(0, n · M_t), with M_t = ∫_texel ω dω from a 4 × 4 grid of
// equal-solid-angle sub-cells (EnvMap::sample_texel). Texels wholly above the horizon of n are
// exact up to that sub-sampling (error O(h²) in the sub-cell size h); a texel cut by the horizon
// counts max(0, n · M_t) instead of ∫_texel H (n·ω) dω, which differs by at most
// ∫_texel |n·ω| ≤ Ω_t · δ_t (δ_t its angular size) — summed over the ≈ 2π / δ texels along the
// horizon, below 2 δ² relative to π·L (7.5e-5 for a 1024-wide lat-long map). Texels are grouped
// in 16 × 16 tiles with a bounding cone, so a normal costs a few thousand tile tests plus the
// tiles the horizon cuts. A constant environment gives π·L exactly.
class UnoccludedIrradiance {
public:
  explicit UnoccludedIrradiance(const EnvMap& env);
  Rgb operator()(const Eigen::Vector3d& n) const;

private:
  struct Tile {
    Eigen::Vector3d axis;
    double sin_half_angle;  // > 1: the cone is wider than a hemisphere (always descend)
    std::array<double, 9> moment;  // Σ_t L_t,c M_t,xyz, [RGB][xyz]
    uint32_t begin, end;           // texel range in texels_
  };
  struct Texel {
    Eigen::Vector3d moment;  // M_t
    std::array<float, 3> rgb;
  };
  bool constant_ = false;
  Rgb constant_value_;
  std::vector<Tile> tiles_;
  std::vector<Texel> texels_;
};

// A sphere the reference may importance-sample (an occluder's bounding sphere).
struct Sphere {
  Eigen::Vector3d centre{0, 0, 0};
  double radius = 0;
};

struct ReferenceOptions {
  uint32_t samples = 1024;  // QMC shadow rays per pixel (occluded part); a multiple of 8 (8 replicates)
  uint64_t seed = 1;
  std::vector<Sphere> occluder_spheres;
  // Scenes of several objects (prtview on scene files, roles of bake/scene.h), one entry per
  // triangle of the rendered mesh; empty vectors keep the single-object behaviour above.
  //   casts_shadow[t] == 0: triangle t is seen by primary rays but never blocks a shadow ray (an
  //     object with role "receiver" casts no shadow, not even on itself). When no triangle casts,
  //     nothing is occluded and E = E_unocc exactly (no shadow rays, standard error 0).
  //   albedo[t]: diffuse albedo (RGB) of triangle t: the pixel shows albedo · E/π and its standard
  //     error scales alike. Empty: white (albedo 1), the E/π above.
  std::vector<uint8_t> casts_shadow;
  std::vector<std::array<float, 3>> albedo;
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
  ReferenceRenderer(const Mesh& mesh, const EnvMap& env, ReferenceOptions options);
  ~ReferenceRenderer();
  ReferenceRenderer(const ReferenceRenderer&) = delete;
  ReferenceRenderer& operator=(const ReferenceRenderer&) = delete;

  // Primary rays only: the G-buffer of what each pixel centre sees.
  GBuffer trace_primary(const Camera& camera) const;
  ReferenceImage render(const Camera& camera, const Monitor& monitor = {}) const;

  // Irradiance E (RGB) at a fragment and its standard error; `index` keys the randomisation.
  void irradiance(const Fragment& f, uint64_t index, double E[3], double std_error[3]) const;
  std::string description() const;

private:
  struct Rays;  // bake/raycast.h RayScene over the mesh
  const Mesh& mesh_;
  const EnvMap& env_;
  ReferenceOptions options_;
  UnoccludedIrradiance unoccluded_;
  std::unique_ptr<Rays> rt_;
  double epsilon_ = 0;
};

// A reference render kept on disk so several runtime renders of one view can be compared against
// it without tracing it again (prtview --reference-cache). OpenEXR file: channels R, G, B (radiance),
// se.R, se.G, se.B (standard errors) as float, "triangle" as uint (0xFFFFFFFF = nothing hit), and
// a string attribute "prt_reference_key" that names what was rendered (the caller builds it from
// everything that determines the picture). save writes a temporary file and renames it.
// load returns nothing when the file does not exist or its key differs; a damaged file throws
// InputError. Only gbuffer.triangle is restored (barycentrics are not kept).
void save_reference(const std::filesystem::path& path, const ReferenceImage& image, const std::string& key);
std::optional<ReferenceImage> load_reference(const std::filesystem::path& path, const std::string& key);

// ---- scene assembly for the previews ---------------------------------------------------------
// A square in the plane y = `y` (normal +Y), centred at (cx, cz), half-size `half`, two triangles.
Mesh ground_quad(double y, double cx, double cz, double half, const std::string& name = "ground");
// A copy of `mesh` moved by `offset` (normals unchanged).
Mesh translated(const Mesh& mesh, const Eigen::Vector3d& offset, const std::string& name);

} // namespace prt::bake
