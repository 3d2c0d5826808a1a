// bake/bake/bounce.h — interreflections (issue 31): the direct pass's rows of diffuse transfer T and
// band-1 radiance R plus B bounces of light between surfaces, for receivers that are a mesh's own
// vertices (`prtbake vertex`) or its lightmap's texels (`prtbake texel`), or both side by side over
// a scene's union (the fields below). The idea is the "interreflected
// transfer" of PRT (Sloan, Kautz and Snyder 2002, §5; not among ../shared/papers, so the derivation
// is given here in full): each bounce gathers the previous bounce's transfer at the points the rays
// hit, weighted by albedo.
//
// DIFFUSE TRANSFER (bake/integrators/products.h; docs/ARCHITECTURE.md §3). The direct pass is
//   T⁰_i(p) = (1/π) ∫ V H (n·ω) y_i dω.
// Under distant lighting L(ω) = Σ_i L_i y_i(ω) the irradiance it gives is E(p) = ∫ L V H (n·ω) dω
// = π Σ_i L_i T⁰_i(p), and a Lambertian surface of albedo ρ leaves it with radiance
//   L_out(p) = (ρ/π) E(p) = ρ Σ_i L_i T⁰_i(p)                                  (1)
// — the runtime's "albedo · Σ T_i L_i" (the 1/π is inside T; a transfer without it would shade
// with ρ/π). Where V = 0 the ray from p meets the surface at h(p, ω), front side, and the radiance
// arriving along it is h's own exit radiance. Summing both parts,
//   E(p) = ∫ L V H (n·ω) dω + ∫ (1 − V) H L_out(h) (n·ω) dω.
// Let T = Σ_b T^b with
//   T^{b+1}_i(p) = (1/π) ∫ (1 − V) H ρ(h) T^b_i(h) (n·ω) dω                    (2)
// Put L_out(h) = ρ(h) Σ_i L_i T_i(h) (the form (1) for the total) into E(p): the second integral is
// π Σ_i L_i Σ_b T^{b+1}_i(p), so E(p) = π Σ_i L_i T_i(p) and L_out(p) = ρ Σ_i L_i T_i(p): the
// bounced transfer shades with the same dot product, and the run-time formula does not change.
// T^b is exactly the light that reached p after b reflections (the Neumann series of the
// rendering equation for Lambertian surfaces; it converges when ρ < 1 everywhere).
//
// THE ESTIMATOR. K gather rays per receiver, cosine-weighted about its normal (pdf (n·ω)/π) when
// only T bounces (with R: below), are cast ONCE (gather()); the hit of each (triangle,
// barycentrics) is cached. Under that pdf (2)'s
// integrand over the pdf is ρ(h) T^b_i(h) (1 − V), so every bounce is a sparse product over the
// cached hits, with no new rays:
//   T^{b+1}_i(p) ≈ (1/K) Σ_k ρ(h_k) T^b_i(h_k),   T^b_i(h) = Σ_c w_c T^b_i(vertex c of h's triangle)  (3)
// (a sky ray adds nothing: the sky is the direct pass's). T^b at the hit is what the baked file
// gives there: for vertex receivers the triangle's corner rows at the hit's barycentric weights
// w_c (written above), for texel receivers the bilinear lookup of the previous bounce's lightmap
// at the hit's UV (BounceField below). The directions are a 3D Halton sequence with a Cranley–Patterson
// rotation per receiver from (seed, row) (bake/sphere/sampling.h, as the QMC integrator's), in a
// stream of its own: the values are a function of (mesh, rows, seed, K) whatever the thread count,
// and each row sums its rays in ray order.
//
// BAND-1 RADIANCE R. R_c,m(p) = ∫ L_c V H y_1m dω is an incident-radiance moment, per channel.
// A Lambertian hit h sends (ρ/π) E(h) towards p, and because n·ω = (4π/3) Σ_m y_1m(n) y_1m(ω)
// holds exactly (the addition theorem at l = 1), the hit's own rows give its irradiance exactly:
//   E^b_c(h) = (4π/3) Σ_m y_1m(n_h) R^b_c,m(h)                                  (4)
// (R^b(h) is bounce b's incident radiance over h's own hemisphere, so (4) is the irradiance that
// h reflects). Band 1 at the hit is therefore enough, nothing more is needed, and the bounced moment is
//   R^{b+1}_c,m(p) = ∫ (1 − V) H (ρ(h)/π) E^b_c(h) y_1m(ω) dω.                  (5)
// E^b is formed per vertex by (4) at the vertex's own normal (the irradiance that vertex reflects)
// and interpolated at the hit like T. Under
// the cosine pdf alone (5)'s estimator ρ E y_1m(ω)/(n·ω) has infinite variance for m = ±1 (the
// tangential y_1m over n·ω grows like 1/cos θ at the horizon: ∫ sin²θ/cos θ dω diverges), so a
// gather for R mixes the cosine and the uniform hemisphere half and half, one strategy per ray
// (as the QMC integrator does for U and S, bake/integrators/qmc.h), p(ω) = (n·ω)/(2π) + 1/(4π),
// and every estimator is weighted by it:
//   T^{b+1}_i(p) ≈ (1/K) Σ_k ρ(h_k) T^b_i(h_k) ((n·ω_k)/π)/p(ω_k)               (3')
//   R^{b+1}_c,m(p) ≈ (1/K) Σ_k ρ(h_k) E^b_c(h_k) (y_1m(ω_k)/π)/p(ω_k)           (5')
// both bounded (the weights are at most 2 and 4 · 0.4886 ≈ 1.95: p ≥ 1/(4π)). The per-ray weights are
// made again from the ray's direction at every bounce (GatherHits: the direction is a function of
// the seed, the row and k), so the cache holds 12 bytes a ray.
// Shadowed radiance S bounces by (5) with y_i in place of y_1m — E at the hit is still all it
// needs (from R, or from S's own band 1 when the layout has no R: R_c,m = S_c,(2+m)) — with the
// weights (y_i(ω)/π)/p(ω), bounded by 4 max|y_i| under the mixture; its band 1 gets exactly R's
// bounces (the same rays and products).
//
// COLOUR. R is per channel already, and (5) takes ρ_c as it is: R bounces with a coloured albedo.
// T stays one transfer vector per vertex ([V][L²], the direct pass's layout and dataset), so it
// bounces only with grey albedos: a coloured albedo makes the transfer per channel ([V][3][L²],
// the recursion (2) run once per channel), which the schema and prtshade do not carry yet, and is
// refused (InputError) rather than made grey.
//
// BACK FACES ARE BLACK. The rows are the exit radiance of the side a vertex's normal points to; the
// other side of a triangle has no rows. A gather ray that meets a triangle from behind (the
// inside of a closed object, a single-sheet wall seen from its back) takes nothing: that side is
// treated as absorbing rather than given the front's light, which would carry light through walls.
//
// CONVERGENCE. ρ < 1 and ρ ≥ 0 on every triangle (InputError otherwise: at ρ = 1 in an enclosure
// the series does not converge, and a negative albedo is no material). The bounces stop early
// once one adds, as the RMS of its values over the rows, at most `tolerance` × the direct pass's
// RMS, for each product it bounces (that bounce is still added; `applied` counts the bounces summed).
//
// T, R and S bounce; AO and the visibility transfer U stay direct.
// Silent, cancellable through the Monitor, parallel by oneTBB, deterministic.
#pragma once

#include <bake/core/progress.h>
#include <bake/bake/lightmap_receivers.h>
#include <bake/integrators/products.h>
#include <bake/mesh/mesh.h>
#include <bake/mesh/shade_point.h>
#include <bake/visibility/raycast.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace prt::bake {

struct BounceSpec {
  static constexpr uint32_t kDefaultRays = 256;
  static constexpr double kDefaultTolerance = 1e-4;
  int bounces = 0;                       // requested (≥ 0)
  uint32_t rays = kDefaultRays;          // K gather rays per receiver (≥ 1)
  uint64_t seed = 1;
  double tolerance = kDefaultTolerance;  // a bounce whose RMS ≤ tolerance × the direct RMS is the last
};

// The cached hits of the gather rays: ray k of row r at index r·rays + k (12 bytes a ray).
struct GatherHits {
  static constexpr uint32_t kNone = 0xffffffffu;  // the sky, or a triangle met from behind
  uint32_t rays = 0;
  bool mixture = false;                         // cosine and uniform half and half (R's gather), else cosine
  std::vector<uint32_t> triangle;               // [rows][rays]
  std::vector<std::array<float, 2>> weights;    // [rows][rays]: barycentric weights of corners 1, 2
  // The rays' directions are not stored: ray k of row r is a function of (seed, r, k) and the row's
  // normal (gather_direction), so a bounce makes it again for the weights of (3') and (5').
  uint64_t seed = 0;                            // the gather's, from BounceSpec::seed
  double seconds = 0;                           // wall time of the gather
  size_t rows() const { return rays ? triangle.size() / rays : 0; }
  size_t bytes() const {
    return triangle.size() * sizeof(uint32_t) + weights.size() * sizeof(weights[0]);
  }
};

// Casts `spec.rays` rays from each point (the visibility of bake/visibility/raycast.h: limit from
// above, exact near the point) and caches where each meets the surface (RayCaster::
// first_surface_hit; kNone for the sky and for back faces). Cosine-weighted, or with `radiance`
// the mixture R's bounces need (file comment). Progress stage `label`.
GatherHits gather(const RayCaster& rays, std::span<const ShadePoint> points, const BounceSpec& spec, bool radiance,
                  const Monitor& monitor = {}, const std::string& label = "casting bounce rays");

// An albedo per triangle, RGB (linear). Throws InputError(source, …) naming the first triangle
// whose albedo has a channel not in [0, 1) (or not finite).
using Albedo = std::array<double, 3>;
void check_albedo(std::span<const Albedo> albedo, const std::string& source);
// An albedo as logs and captions write it: "0.6" when grey, else "0.8,0.5,0.3" (%g each).
std::string albedo_text(const Albedo& albedo);

// WHERE A HIT TAKES THE PREVIOUS BOUNCE FROM. The rows of a bounce are per receiver; a hit needs
// the value of the surface it lands on. A field spreads the rows over the places a hit reads
// ("entries") and tells which entries a hit reads, with what weights — the run-time's own
// reconstruction of the surface from the baked file, so a bounce gathers exactly what an engine
// would shade at the hit:
//   VertexField  receivers = the mesh's vertices (row r = vertex r): a hit reads its triangle's
//                three corners at its barycentric weights (Gouraud).
//   TexelField   receivers = the valid texels of a lightmap (bake/bake/lightmap_receivers.h): the
//                rows become the lightmap image (filled inside the geometry, padded, as the file's:
//                bake/bake/lightmap.h, without the seam stitch), and a hit reads the bilinear lookup
//                at its UV (formats/SCHEMA.md's rule) — four texels.
//   SceneField   several fields side by side over one union of meshes: the hit's triangle picks
//                the part (by triangle range); a triangle of no part (an occluder that receives
//                nothing, so has no rows) reads nothing — it reflects no light.
struct FieldTaps {
  std::array<size_t, 4> entry{};
  std::array<double, 4> weight{};
  int count = 0;
};
class BounceField {
 public:
  virtual ~BounceField() = default;
  virtual size_t rows() const = 0;     // receivers whose rows it takes
  virtual size_t entries() const = 0;  // places a hit reads
  // rows [rows()][width] → entries [entries()][width] (every entry written).
  virtual void spread(std::span<const double> rows, size_t width, std::span<double> entries) const = 0;
  // The entries a hit on `triangle` (of the geometry the gather rays met) at barycentric weights
  // (1 − w1 − w2, w1, w2) reads; count 0 when it reads none.
  virtual FieldTaps taps(uint32_t triangle, double w1, double w2) const = 0;
};

class VertexField final : public BounceField {
 public:
  explicit VertexField(const Mesh& mesh) : mesh_(mesh) {}
  size_t rows() const override { return mesh_.positions.size(); }
  size_t entries() const override { return mesh_.positions.size(); }
  void spread(std::span<const double> rows, size_t width, std::span<double> entries) const override;
  FieldTaps taps(uint32_t triangle, double w1, double w2) const override;

 private:
  const Mesh& mesh_;
};

class TexelField final : public BounceField {
 public:
  // `texels` of `mesh` (its UV set and atlas); the image padded `padding` rings.
  TexelField(const Mesh& mesh, const LightmapReceivers& texels, uint32_t padding);
  size_t rows() const override { return texels_.valid.size(); }
  size_t entries() const override { return size_t(texels_.atlas.width) * texels_.atlas.height; }
  void spread(std::span<const double> rows, size_t width, std::span<double> entries) const override;
  FieldTaps taps(uint32_t triangle, double w1, double w2) const override;

 private:
  const Mesh& mesh_;
  const LightmapReceivers& texels_;
  uint32_t padding_;
};

class SceneField final : public BounceField {
 public:
  // Adds `field` for the union's triangles [first_triangle, first_triangle + triangles) (the
  // field's own triangles 0 …, in order), after the parts added before (rows and entries follow
  // theirs). Parts with triangles must come in increasing, disjoint triangle ranges; a part with
  // none (receivers no ray can meet: not in the union) has rows that no hit reads.
  void add(const BounceField& field, uint32_t first_triangle, uint32_t triangles);
  size_t rows() const override { return rows_; }
  size_t entries() const override { return entries_; }
  void spread(std::span<const double> rows, size_t width, std::span<double> entries) const override;
  FieldTaps taps(uint32_t triangle, double w1, double w2) const override;

 private:
  struct Part {
    const BounceField* field;
    uint32_t first_triangle, triangles;
    size_t first_row, first_entry;
  };
  std::vector<Part> parts_;
  std::vector<size_t> tapped_;  // the parts with triangles, in triangle order
  size_t rows_ = 0, entries_ = 0;
};

struct BounceResult {
  std::vector<double> values;         // [rows][layout.width]: the direct rows, T's and R's slices with the bounces added
  int applied = 0;                    // bounces summed (≤ spec.bounces)
  // Per bounce summed: the RMS of its values over the rows over the direct pass's, the larger of
  // T's and R's (each product against itself).
  std::vector<double> relative_rms;
  // Per bounce summed: its Monte Carlo standard error, estimated from the two halves of the rays
  // (even and odd k: |S_even − S_odd| / K for a sum (S_even + S_odd) / K), as an RMS over the rows
  // relative to the direct pass's RMS, the larger over the products. Their sum bounds the error of
  // all the bounces together whatever their correlation (the rays are reused by every bounce).
  std::vector<double> relative_std_error;
  double total_relative_std_error() const {
    double sum = 0;
    for (const double e : relative_std_error) sum += e;
    return sum;
  }
  std::vector<double> seconds;        // per bounce summed: wall time of its sparse product
};

// The direct rows `direct` ([rows][layout.width], row r at shade point points[r], whose normal
// E's eq. (4) takes) with up to `spec.bounces` bounces of the diffuse transfer (3) and of the
// band-1 radiance (5) added, from the cached `hits` (of the same rows; a layout with R needs the
// mixture gather: contract), the `field` the hits read the previous bounce from (rows() = the
// rows), and an albedo per triangle of the geometry the hits met (checked: check_albedo(albedo,
// source)). R bounces per channel with ρ_c; T is one transfer for all channels, so a layout with T
// needs grey albedos (R = G = B on every triangle; InputError(source, …) naming the first that is
// not). Other products are copied. A bounce that is zero everywhere (albedo 0) leaves every
// value's bits as they were. ContractError if a value is not finite. Progress stage `label`, one
// task per bounce (two when S bounces beside T or R).
// `shadowed_rows` (empty: all; else one flag per row): the rows whose S (layout.shadowed) bounces;
// the others' S slots are copied, and the bounce's working memory for S is kept for those rows
// only (a scene where one glossy object carries S at order 8 beside a lightmap of 10^5 texels).
// S without R takes E from S's band 1: a row that carries neither reflects nothing.
BounceResult bounce_rows(const BounceField& field, std::span<const ShadePoint> points, const GatherHits& hits,
                         std::span<const Albedo> albedo, const ProductLayout& layout, std::span<const double> direct,
                         const BounceSpec& spec, const std::string& source, const Monitor& monitor = {},
                         const std::string& label = "bouncing light", std::span<const uint8_t> shadowed_rows = {});

} // namespace prt::bake
