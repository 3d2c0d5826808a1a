// bake/bake/bounce.h — interreflections (issue 31, first slice): the direct pass's rows of diffuse
// transfer T and band-1 radiance R plus B bounces of light between the surfaces of one mesh, for
// receivers that are the mesh's own vertices (`prtbake vertex`). The idea is the "interreflected
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
// (a sky ray adds nothing: the sky is the direct pass's). T^b at the hit is interpolated from the
// triangle's corner rows by the hit's barycentric weights w_c, so the receivers must be the mesh's
// own vertices (row r = vertex r). The directions are a 3D Halton sequence with a Cranley–Patterson
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
// cached beside the hits. Shadowed radiance S bounces by (5) with y_i in place of y_1m (E at the
// hit is still all it needs), but its weights are one per coefficient: not in this slice (the tool
// refuses S with bounces, so S's band 1 keeps equalling R).
//
// COLOUR. This slice is grey: one albedo per triangle, so T stays one transfer vector per vertex
// ([V][L²], the direct pass's layout and dataset). A coloured albedo makes the transfer per
// channel ([V][3][L²], the recursion (2) run once per channel); the tool refuses one until the
// schema and prtshade carry it. R is per channel already: (5) would take ρ_c as it is.
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
// T and R bounce; AO, visibility transfer U and shadowed radiance S stay direct.
// Silent, cancellable through the Monitor, parallel by oneTBB, deterministic.
#pragma once

#include <bake/core/progress.h>
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

// The cached hits of the gather rays: ray k of row r at index r·rays + k.
struct GatherHits {
  static constexpr uint32_t kNone = 0xffffffffu;  // the sky, or a triangle met from behind
  uint32_t rays = 0;
  bool mixture = false;                         // cosine and uniform half and half (R's gather), else cosine
  std::vector<uint32_t> triangle;               // [rows][rays]
  std::vector<std::array<float, 2>> weights;    // [rows][rays]: barycentric weights of corners 1, 2
  // With `mixture`, [rows][rays]: ((n·ω)/π, y_1,−1(ω)/π, y_1,0(ω)/π, y_1,1(ω)/π) / p(ω), the
  // weights of (3') and (5'); empty for the cosine gather, where T's weight is 1.
  std::vector<std::array<float, 4>> estimator;
  double seconds = 0;                           // wall time of the gather
  size_t rows() const { return rays ? triangle.size() / rays : 0; }
  size_t bytes() const {
    return triangle.size() * sizeof(uint32_t) + weights.size() * sizeof(weights[0]) +
           estimator.size() * sizeof(estimator[0]);
  }
};

// Casts `spec.rays` rays from each point (the visibility of bake/visibility/raycast.h: limit from
// above, exact near the point) and caches where each meets the surface (RayCaster::
// first_surface_hit; kNone for the sky and for back faces). Cosine-weighted, or with `radiance`
// the mixture R's bounces need (file comment). Progress stage `label`.
GatherHits gather(const RayCaster& rays, std::span<const ShadePoint> points, const BounceSpec& spec, bool radiance,
                  const Monitor& monitor = {}, const std::string& label = "casting bounce rays");

// Throws InputError(source, …) naming the first triangle whose albedo is not in [0, 1) (or not
// finite).
void check_albedo(std::span<const double> albedo, const std::string& source);

struct BounceResult {
  std::vector<double> values;         // [rows][layout.width]: the direct rows, T's and R's slices with the bounces added
  int applied = 0;                    // bounces summed (≤ spec.bounces)
  // Per bounce summed: the RMS of its values over the rows over the direct pass's, the larger of
  // T's and R's (each product against itself).
  std::vector<double> relative_rms;
  std::vector<double> seconds;        // per bounce summed: wall time of its sparse product
};

// The direct rows `direct` ([rows][layout.width], row r = vertex r of `mesh`, its normal
// mesh.normals[r]) with up to `spec.bounces` bounces of the diffuse transfer (3) and of the band-1
// radiance (5) added, from the cached `hits` (of the same rows; a layout with R needs the mixture
// gather: contract) and an albedo per triangle of `mesh` (checked: check_albedo(albedo,
// mesh.source)). Other products are copied. A bounce that is zero everywhere (albedo 0) leaves
// every value's bits as they were. ContractError if a value is not finite. Progress stage
// `label`, one task per bounce.
BounceResult bounce_rows(const Mesh& mesh, const GatherHits& hits, std::span<const double> albedo,
                         const ProductLayout& layout, std::span<const double> direct, const BounceSpec& spec,
                         const Monitor& monitor = {}, const std::string& label = "bouncing light");

} // namespace prt::bake
