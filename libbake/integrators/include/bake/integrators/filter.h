// bake/integrators/filter.h — the third integrator: sparse ray-traced occlusion reconstructed with the
// rotation-invariant sheared filter of Egan, Durand & Ramamoorthi, "Practical Filtering for
// Efficient Ray-Traced Directional Occlusion" (SIGGRAPH Asia 2011; paper 002), with vertices as
// the shading points. The method for geometry whose silhouettes do not scale (foliage, fences,
// grilles): a few rays per receiver, and each receiver reuses its neighbours' rays.
//
// Pass 1 (§5): `rays` cosine-distributed rays per point (randomised Halton, bake/sphere/sampling.h,
// keyed by (seed, point index)), each recording its direction and the distance to the first
// occluder (bake/visibility/raycast.h RayCaster::first_hit: the ε-limit visibility of every other
// integrator, 1-ring and near triangles decided exactly). Computed on demand, once per point,
// and cached: a pure function of (seed, index, geometry), so any thread count and any subset of
// rows bake the same bytes.
//
// Pass 2, per receiver p (normal n, local vertex spacing d = mean distance to its 6 nearest
// distinct points):
//   - neighbours: the points within radius_factor · d (our own k-d tree over prepare()'s points),
//     keeping those whose normal is within 25° of n and that lie within 0.3·|q − p| of p's tangent
//     plane (the paper's "dissimilar normals / depth discontinuities": a sheet 1e-4 away facing the
//     other way, a slat above or below, the other face of a crease are rejected);
//   - the hemisphere is split into 8×8 cells of equal projected area (8 rings of equal
//     sin²θ width × 8 sectors, §5); each cell keeps z-min / z-max of the occluders seen through it
//     (Algorithm 1 lines 1-10: hit points in p's hemisphere, binned by the effective direction
//     from p to the hit);
//   - per cell, eq. 8 with Ω_pix = 0.5/d (§3.3) gives the spatial radius
//     r = d · primalScale = [Ω_v (1/z_min − 1/z_max)]⁻¹ (unbounded when the cell saw one depth:
//     the search radius bounds it; a cell where no sample met an occluder gets eq. 8 for
//     [z_near, ∞], r = z_near / Ω_v, z_near the nearest hit of the receiver's own pass-1 rays:
//     sparse rays miss occluders, and a vertex in a slot whose own rays meet the far wall must not
//     take the sky its neighbours outside the slot see), and eq. 9 the mid depth, the harmonic
//     mean of z_min and z_max (§5). A cell with Ω_v / z_min > Ω_pix (occluders closer than 4d for Ω_v = 2: contact
//     shadows, creases) is brute-forced (§3.3);
//   - every neighbour sample gets a target point (§4, Fig. 6): its hit point, or for a ray that
//     escaped, its crossing of the plane at the mid depth of the cell its direction falls in,
//     perpendicular to that cell's centre direction (at infinity when that cell saw no occluder:
//     the effective direction is then the ray's own). The effective direction v runs from p to
//     the target; x is the distance from p to where the sample's ray meets the plane through p
//     perpendicular to v; its weight is (1 − (x/r)²)² for x < r (our choice of a smooth compact
//     filter: the paper leaves ComputeFilterWeight open);
//   - a receiver whose own pass-1 rays met an occluder nearer than d/2 (a crease, a contact: its
//     1-ring or near triangles) brute-forces every cell in which those triangles, decided exactly
//     (RayCaster::blocked_nearby), block the cell's centre or a corner direction: its neighbours'
//     rays start on the other side of that occluder (the floor beside a wall) and cannot speak
//     for it;
//   - cells with total weight below 2 (§5: "approximately 2 samples") are brute-forced too:
//     `fallback_rays` stratified rays inside the cell (the paper shot one), four times as many in
//     a cell where the neighbours' samples (whatever their weight) saw both sky and an occluder
//     (a visibility edge: one binary ray there is most of the noise), joined by the receiver's
//     own pass-1 rays that fell in the cell (they need no filter).
//
// The estimate per cell c (solid angle Ω_c, integrand f of a product: (n·ω)/π for AO, (n·ω) y_i/π
// for diffuse transfer, y_i for visibility transfer) uses the weighted visible fraction ν_c, the
// weighted means of V·f and f over the cell's samples, and the cell's exact unoccluded integral
// F_c = ∫_c f dω (a control variate; per-cell solid-angle weights Ω_c for every product):
//     ∫_c V f dω ≈ ν_c F_c + Ω_c (mean(V f) − ν_c mean(f)).
// So a receiver whose samples all escape gets exactly the closed form (bake/sphere/zonal.h), one whose
// samples all hit gets exactly 0, and a cell with one ray gets V(ray)·F_c (the stratified
// estimator: with radius_factor 0 the whole result is Σ_c V(d_c) F_c, one fallback ray per
// cell). F_c is integrated once in the frame of the cell (Gauss–Legendre in θ and φ, exact
// to rounding) and rotated to the receiver's frame with prtshade's SH rotation (Σ_c ν_c F_c is
// linear: one rotation per receiver). Each sample carries its own effective direction, so the
// cells only bin and normalise: any transfer / visibility order the SH code supports is carried,
// but detail finer than the search radius is blurred whatever the order (§6.6).
//
// Band-1 radiance: the filter assumes the lighting · BRDF response is band-limited (Ω_v, §3.2);
// an HDR environment with a sun (10^4-10^5 × its mean) is not, so radiance is always routed to the
// QMC integrator (bake/integrators/qmc.h, environment importance sampling, `radiance_rays` rays per point) and
// the description says so. Full-sphere points (ShadePoint::hemisphere false) are a contract
// error: hemisphere products only (the FIV shells use the silhouette integrator).
//
// Where it loses (measured, bench/bench_filter.cpp `diagnose`: bias and noise over 6 seeds): on
// coarse meshes (a few thousand vertices: ~28 neighbours on the bunny, 8 on wuson, 4 on spider)
// every occluder within 4d brute-forces its cell, and a 1-ray cell is binary noise (on the bunny
// at 16 pass-1 rays, 60% of the error variance); the filtered cells carry a blur bias that grows
// with the search radius (0.003 at 1.5 d, 0.008 at 3 d, 0.010 at 6 d AO RMSE on the bunny). So at
// ≤ 32 rays per point it beats QMC at the same rays but not QMC at 256 there, and on wuson and
// spider (80-90% of cells brute-forced) it is a 64-cell stratified estimator. On dense foliage
// most cells are brute-forced too (the occluders are within 4d) and it is slower than QMC at
// equal error. It wins where occluders are far from dense receivers (a grille over a ground).
//
// prepare(points) must be given every point of the bake before integrate(); integrate() with an
// index that prepare() did not see, or a point that differs from the prepared one, is integrated
// by brute force over every cell (fallback_rays per cell: the plain stratified estimator).
// prepare() with the points it already holds keeps them and the pass-1 rays traced so far (a
// sharded bake calls it once per chunk of rows); other points replace them.
// The per-value standard error is reported as 0: the filter has no per-point variance estimate
// (its samples are its neighbours', shared between points); the error report measures its error
// against the QMC reference. Products and integrands: docs/ARCHITECTURE.md ("Conventions").
#pragma once

#include <bake/integrators/integrator.h>
#include <bake/integrators/products.h>
#include <bake/mesh/mesh.h>
#include <bake/sphere/sampling.h>
#include <bake/visibility/accel.h>
#include <bake/visibility/raycast.h>

#include <array>
#include <atomic>
#include <memory>
#include <mutex>
#include <vector>

namespace prt::bake {

class QmcIntegrator;

struct FilterOptions {
  static constexpr uint32_t kDefaultRays = 16;
  uint32_t rays = kDefaultRays;   // pass-1 rays per receiver: the knob (paper: 4-32, typically 9-16)
  uint64_t seed = 1;
  double radius_factor = 3;      // search radius in local vertex spacings; 0: no filtering at all
  uint32_t fallback_rays = 1;    // rays per brute-forced cell
  double omega_v = 2;            // Ω_v^max, the response's angular band limit (paper §3.3)
  double min_weight = 2;         // cells with less filter weight are brute-forced (paper §5)
  uint32_t radiance_rays = 256;  // QMC rays per point for band-1 radiance
};

// The 8×8 hemisphere cells of equal projected area, in the receiver's local frame (+z = n).
struct HemisphereCells {
  static constexpr int kRings = 8, kSectors = 8, kCount = kRings * kSectors;
  // Cell of a local unit direction with z > 0 (ring from x² + y² = sin²θ, sector: the octant of
  // the azimuth atan2(y, x), decided by exact comparisons of x and y).
  static int cell_of(const Eigen::Vector3d& local);
  // A direction in cell c, (u0, u1) ∈ [0,1)², distributed as (n·ω) within the cell (equal
  // sin²θ and φ steps: the cosine-weighted map restricted to the cell).
  static Eigen::Vector3d direction(int c, double u0, double u1);
  static double solid_angle(int c);
};

// Per-cell unoccluded integrals F_c in the local frame, for the products of a layout: [AO (1/64
// each) | T (Lt²) | U (Lv²)] in row order (radiance excluded), and their rotation to a receiver.
class CellIntegrals {
public:
  explicit CellIntegrals(const ProductLayout& layout);
  size_t width() const { return width_; }  // AO + T + U columns
  std::span<const double> local(int c) const { return std::span(values_).subspan(size_t(c) * width_, width_); }
  // out (width()) = the rotation to the frame (t, b, n) of a sum of local cell integrals.
  void to_world(const Frame& frame, std::span<const double> local_sum, std::span<double> out) const;
  // The integrands f at a world direction v, for a receiver of normal n (same columns); `y` is
  // scratch of at least sh::num_coeffs(max order) doubles.
  void integrands(const Eigen::Vector3d& n, const Eigen::Vector3d& v, std::span<double> y, std::span<double> out) const;
  int sh_order() const { return sh_order_; }

private:
  ProductLayout layout_;
  size_t width_ = 0;
  int sh_order_ = 0;
  std::vector<double> values_;  // [cell][width]
};

// The filter integrator's work, summed over its integrate() calls: pass-1 rays cast (once per
// point), rays of brute-forced cells, hemisphere cells integrated and how many of them by brute
// force, points integrated by brute force because prepare() had not seen them; its neighbours kept
// (the receiver included) and the samples with a non-zero filter weight in the cells it filtered.
struct FilterStats : IntegratorStats {
  uint64_t pass1_rays = 0, fallback_rays = 0, cells = 0, brute_cells = 0, unprepared = 0;
  uint64_t neighbours = 0, filtered_samples = 0;
  double brute_fraction() const { return cells ? double(brute_cells) / double(cells) : 0.0; }
  double neighbours_per_point() const { return points ? double(neighbours) / double(points) : 0.0; }
  double samples_per_filtered_cell() const {
    return cells > brute_cells ? double(filtered_samples) / double(cells - brute_cells) : 0.0;
  }
  double rays_per_point() const { return points ? double(pass1_rays + fallback_rays) / double(points) : 0.0; }
};

class FilterIntegrator final : public Integrator {
public:
  // `mesh` and `topology` (and the request's environment) must outlive the integrator. With
  // `accel` (of the same mesh and topology), its ray scene is shared instead of built.
  FilterIntegrator(const Mesh& mesh, const Topology& topology, const ProductRequest& request,
                   const FilterOptions& options, const MeshAccel* accel = nullptr);
  ~FilterIntegrator() override;
  FilterIntegrator(const FilterIntegrator&) = delete;
  FilterIntegrator& operator=(const FilterIntegrator&) = delete;

  IntegratorKind kind() const override { return IntegratorKind::Filter; }
  std::string description() const override;
  const ProductLayout& layout() const override { return layout_; }
  void prepare(std::span<const ShadePoint> points) const override;
  bool prepares() const override { return true; }
  void integrate(const ShadePoint& point, uint64_t point_index, std::span<double> out,
                 std::span<double> std_error = {}) const override;
  // Its work counters (FilterStats); stats() is their common part.
  FilterStats filter_stats() const;
  IntegratorStats stats() const override { return filter_stats(); }
  // Rays per point (pass-1 + fallback), the brute-forced cell fraction, neighbours
  // and samples per filtered cell.
  std::string work_summary() const override;
  const FilterOptions& options() const { return options_; }
  const CellIntegrals& cell_integrals() const { return cells_; }
  // Brute-force ray i of cell c at the point of index point_index, in the local frame (+z = n;
  // world: Frame(n).to_world(·).normalized()): stratified per cell, randomised by (seed, index).
  Eigen::Vector3d fallback_direction(uint64_t point_index, int cell, uint32_t i) const;

private:
  struct Prepared;
  struct Sample {  // one pass-1 ray: direction and first-hit distance (+inf: escaped)
    float d[3];
    float t;
  };
  std::span<const Sample> pass1(uint64_t index) const;
  double spacing(uint64_t index) const;

  ProductLayout layout_;
  FilterOptions options_;
  CellIntegrals cells_;
  std::shared_ptr<const RayCaster> rays_;
  std::unique_ptr<QmcIntegrator> radiance_;  // band-1 radiance, routed to QMC
  mutable std::unique_ptr<Prepared> prepared_;
  mutable std::atomic<uint64_t> points_{0}, pass1_rays_{0}, fallback_rays_{0}, cells_total_{0}, brute_cells_{0},
      unprepared_{0}, neighbours_{0}, filtered_samples_{0};
};

} // namespace prt::bake
