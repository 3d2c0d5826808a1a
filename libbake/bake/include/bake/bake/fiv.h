// bake/bake/fiv.h — Fullsphere Irradiance Vectors (Michael & Chrysanthou, "Fullsphere Irradiance
// Factorization for Real-Time All-Frequency Illumination for Dynamic Scenes", CGF 2010; paper
// 004 in ../shared/papers, §3 eq. 9 and §4.1–4.2), computed with the silhouette integrator's
// full-sphere mode (paper 001 §3) instead of rasterised occlusion cube masks.
//
// Quantities (per RGB channel c; [RGB][xyz] = 9 numbers, row-major):
//   environment FIV       F_c^env = ∫_{S²} L_c(ω) ω dω                         (eq. 9)
//   occluded FIV          F_c(s)  = ∫_{S²} (1 − V_O(s, ω)) L_c(ω) ω dω          at receiver offset s
//                         from the occluder's bounding-sphere centre; the unoccluded FIV at s is
//                         F^env − F(s), and a receiver with normal n gets n · (that) (eq. 8–9).
//   DifMap                E_tot(n) = ∫ L(ω) H(ω, n) (n · ω) dω                   (eq. 5), per normal.
//
// Shell grid (stored as attributes so any reader can rebuild the positions):
//   s(k, i, j) = centre + ρ_k d(θ_i, φ_j),  θ_i = π i / (Nθ − 1) (poles included, θ from +Y),
//   φ_j = 2π j / Nφ (from +Z towards +X):   d = (sin θ sin φ, cos θ, sin θ cos φ).
//   Radii: geometric, ρ_0 = inner · R up to ρ_far = R / (2 √fraction) over Nρ shells (a sphere of
//   radius R at distance ρ hides ≈ R²/(4ρ²) of the sphere); the bake stops after the first shell
//   whose max_c |F_c| / ∫ L_c dω is below `fraction` and stores the radii it used. (The scale is
//   the full-sphere irradiance ∫ L dω, not |F^env|, which cancels to 0 for a uniform sky. Under a
//   sun, a distant occluder still blocks the sun wholly from some shell directions, so the shells
//   run out to the last radius: that shadow is real.)
//   valid = 0 where the offset is inside closed geometry (nothing visible: F = F^env there).
// Surface-following radii (RadialScheme::surface, the default; issue 33 — replaces §4.1's spheres,
//   whose shells ~0.6 units apart near the bunny's base cannot hold a contact shadow that varies
//   over its 0.07-unit gap, and whose samples inside the occluder are dropped):
//   s(k, i, j) = centre + (r_surf(i, j) + τ_k) d(θ_i, φ_j), r_surf(i, j) the largest t at which the
//   ray centre + t d(θ_i, φ_j) meets the occluder (0 when it misses; exact: the ray cast from
//   outside inwards, its hit recomputed in double), τ_k geometric from τ_0 = first_offset · R to
//   ρ_far (the geometric scheme's far radius) over Nρ shells. Every sample is outside the outer
//   hull along its ray; a sample the integrator still finds inside (valid = 0: it sees nothing)
//   takes the value of the nearest valid sample outwards on its radial line (the nearest inwards
//   when there is none outwards; unchanged — F^env, all light hidden — when the line has no valid
//   sample), so the runtime
//   interpolates plainly, without a valid mask (prtshade/fiv.h "Surface-following shells"). The
//   stopping rule is the same, from the first shell with τ_k >= R (all samples outside the sphere).
//   Cones (the tight proxy, issue 33; prtshade/fiv.h "Tight proxies"): per sample the occluded
//   moment and solid angle, m = ∫ (1 − V_O) ω dω and Ω = ∫ (1 − V_O) dω, from the same integral as
//   F (visibility up to band 1: Ω from y_0, m from y_1m as F from band-1 radiance), so exact to the
//   integrator's discretisation like F.
//
// Cube map of the DifMap, in OpenGL's cube-map convention — not OpenEXR's, which input cube maps
// use (bake/environment/envmap.h; docs/ARCHITECTURE.md §3 "Two cube conventions"): faces +X, −X, +Y, −Y, +Z,
// −Z; texel (row r, column q) of size S has s = 2(q + ½)/S − 1, t = 2(r + ½)/S − 1 and direction
//   +X (1, −t, −s)   −X (−1, −t, s)   +Y (s, 1, t)   −Y (s, −1, −t)   +Z (s, −t, 1)   −Z (−s, −t, −1).
#pragma once

#include <bake/bake/vertex_bake.h>
#include <bake/core/progress.h>
#include <bake/environment/envmap.h>
#include <bake/integrators/silhouette.h>
#include <bake/mesh/mesh.h>

#include <Eigen/Core>
#include <array>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace prt::bake {

using Fiv = std::array<double, 9>;  // [RGB][xyz]

// ∫ L ω dω, exact per texel up to its 4×4 sub-sampled ∫_texel ω dω (texel_moments, bake/environment/irradiance.h).
Fiv environment_fiv(const EnvMap& env);

// DifMap: [6][S][S][3] float, E_tot(n) per texel direction: bake/environment/irradiance.h's
// UnshadowedIrradiance (texels cut by the horizon of n integrated with 4×4 sub-samples, the rest
// with their ∫_texel ω dω) at gl_cube_direction, rounded to float.
std::vector<float> irradiance_cube(const EnvMap& env, int size);
// Texels [begin, end) of irradiance_cube(env, size) (texel (face·S + row)·S + column), [end −
// begin][3], from `irradiance`, an UnshadowedIrradiance of env: the same floats, for a DifMap cut
// into chunks.
class UnshadowedIrradiance;
std::vector<float> irradiance_cube_texels(const UnshadowedIrradiance& irradiance, int size, size_t begin, size_t end);
// The same sum texel by texel for every normal (UnshadowedIrradiance::reference, no cell
// hierarchy): the slow reference of irradiance_cube, equal to it up to summation order. Needs a
// map with texels.
std::vector<float> irradiance_cube_reference(const EnvMap& env, int size);
// The unit direction of DifMap texel (face, row, column) of a size-S face: OpenGL's cube-map
// convention (header comment), not EnvMap's OpenEXR cube.
Eigen::Vector3d gl_cube_direction(int face, int row, int column, int size);

// How the shells are placed along each direction (header comment): the file's radial_scheme.
enum class RadialScheme { geometric, surface };
std::string_view radial_scheme_name(RadialScheme scheme);  // "geometric", "surface"
bool parse_radial_scheme(std::string_view text, RadialScheme& scheme);  // false (unchanged) otherwise

// What an FIV bake computes, with its defaults (the same for `prtbake fiv` and scene files).
struct ShellSpec {
  int n_phi = 128, n_theta = 65, n_rho = 30;
  RadialScheme radial = RadialScheme::surface;
  double first_offset = 0.005;  // τ_0 / R of the surface scheme (0.033 for the bunny: half its 0.07 gap)
  double inner = 0.5;      // ρ_0 / R of the geometric scheme: the first shell lies inside the bounding sphere
  double fraction = 1e-3;  // stop once |occluded FIV| is below this fraction of ∫ L dω
  // The silhouette integrator's k (silhouette_isolines(k) u-isolines, bake/integrators/integrator.h).
  uint32_t silhouette_k = IntegratorSpec::kDefaultSilhouetteK;
  // DifMap face size S (irradiance_cube). 32: its bilinear lookup at a face centre (a receiver
  // facing ±X, ±Y, ±Z) reads texels 1/S off the axis, which under forest.exr darkens a ground
  // receiver by 0.39 % at S = 16 (every pixel of Figure 12, NRMSE 0.0039 alone), 0.11 % at 32 and
  // 0.03 % at 64, for 2.2, 6.8 and 28.7 s of bake (docs/FIGURES.md).
  int cube = 32;
  // The precision the file stores the shells and cones in (formats: dtype float16, schema v8;
  // prtshade/fiv.h "Half-float tables"): true halves their memory at no measurable error.
  bool float16 = true;
  // The occluder's self-shadows (prtshade/fiv.h shade_fiv_member_given_self): true bakes its
  // band-1 radiance from itself alone at its vertices (bake_fiv_self_shadows: exact there, where
  // eq. 12 from the shells is wrong in concavities and on faces that are not the outermost along
  // their ray from the centre); false leaves them to the shells.
  bool vertex_self_shadows = true;
};
// "vertex" or "shells", as tools spell ShellSpec::vertex_self_shadows; parse returns false and
// leaves `vertex` as it was for anything else.
bool parse_self_shadows(std::string_view text, bool& vertex);
// "half" (float16) or "float" (float32), as tools spell ShellSpec::float16; parse returns false
// and leaves `float16` as it was for anything else.
std::string_view shell_precision_name(bool float16);
bool parse_shell_precision(std::string_view text, bool& float16);
// The grid as files and tools spell it, "NPHIxNTHETAxNRHO" (e.g. "128x65x30"). Returns false and
// leaves `spec` as it was unless 1 <= NPHI <= 4096, 2 <= NTHETA <= 4096 (poles included) and
// 1 <= NRHO <= 1024.
bool parse_shell_grid(std::string_view text, ShellSpec& spec);

struct FivShells {
  Eigen::Vector3d centre{0, 0, 0};  // in the occluder mesh's frame (Mesh::origin, bake/mesh/mesh.h)
  Eigen::Vector3d origin{0, 0, 0};  // that mesh's origin: what files store is world_centre()
  Eigen::Vector3d world_centre() const { return add_origin(origin, centre); }
  double radius = 0;
  int n_phi = 0, n_theta = 0;
  RadialScheme radial = RadialScheme::geometric;
  std::vector<double> radii;    // the shells baked (≤ n_rho): ρ_k, or τ_k of the surface scheme
  std::vector<float> values;    // occluded FIV F(s) per grid sample: [Nρ][Nθ][Nφ][RGB][xyz]
  std::vector<uint8_t> valid;   // [Nρ][Nθ][Nφ]; surface scheme: 0 = extrapolated (header comment)
  std::vector<float> cones;     // occluded moment and solid angle (m_x, m_y, m_z, Ω): [Nρ][Nθ][Nφ][4]
  std::vector<double> surface_radius;  // [Nθ][Nφ] r_surf, surface scheme only
  size_t extrapolated = 0;      // surface scheme: samples filled from their radial line
  // ShellSpec::float16: values and cones rounded to the nearest float16 (what the file stores),
  // before any report measures them.
  bool float16 = false;
  // Where sample (k, i, j) sits, in the mesh's frame (header comment).
  Eigen::Vector3d sample_position(int k, int i, int j) const;
  double seconds = 0;
  uint64_t integrals = 0;
};

Eigen::Vector3d shell_direction(int i_theta, int n_theta, int j_phi, int n_phi);

// r_surf of every grid direction, [Nθ][Nφ] (header comment): the largest t >= 0 at which
// centre + t d(θ_i, φ_j) meets a triangle of `mesh`, 0 where the ray misses it.
std::vector<double> surface_radii(const Mesh& mesh, const Eigen::Vector3d& centre, double radius, int n_theta, int n_phi);
// The surface scheme's fill (header comment): every valid == 0 sample of `shells` takes the value
// of the nearest valid one outwards on its radial line, else inwards, else keeps its own (F^env:
// all light hidden); counts them in shells.extrapolated. No-op for the geometric scheme.
void extrapolate_inside_samples(FivShells& shells);

// Bounding sphere used by the shells: the centre of the axis-aligned bounds and the largest
// distance from it to a vertex.
void bounding_sphere(const Mesh& mesh, Eigen::Vector3d& centre, double& radius);

FivShells bake_fiv_shells(const Mesh& occluder, const Topology& topology, const EnvMap& env, const ShellSpec& spec,
                          const Monitor& monitor = {});

// The occluder's self-shadows: its band-1 shadowed radiance under `env` from itself alone at its
// vertices (ProductRequest::radiance; rows in the mesh's vertex order), by the silhouette
// integrator at spec.silhouette_k and `seed`, as a vertex bake of that mesh would give them; with
// what baked them, for the file.
struct FivSelfShadows {
  VertexBake values;
  IntegratorSpec integrator;
  std::string integrator_name, integrator_description;
};
FivSelfShadows bake_fiv_self_shadows(const Mesh& occluder, const Topology& topology, const EnvMap& env, const ShellSpec& spec,
                                     uint64_t seed, const Monitor& monitor = {});

// What an FIV step would cost, for a dry run's estimate (bake/bake/scene_bake.h): its setup's wall
// seconds (done for real: the integrator's tables, the environment's cell hierarchy) and the CPU
// seconds of all its samples, `samples` seeded ones timed on the calling thread and scaled.
struct FivCost {
  double setup_seconds = 0;
  double cpu_seconds = 0;
  size_t timed = 0;  // the samples timed
};
// environment_fiv and irradiance_cube(env, size): the DifMap's 6·S² texels.
FivCost environment_fiv_cost(const EnvMap& env, int size, size_t samples);
// bake_fiv_shells with every one of spec.n_rho shells baked (the bake may stop earlier, once
// |F| < spec.fraction; under a sun it seldom does), the samples spread over the shells.
FivCost fiv_shells_cost(const Mesh& occluder, const Topology& topology, const EnvMap& env, const ShellSpec& spec,
                        size_t samples);
// bake_fiv_self_shadows: the integrator's setup, then `samples` seeded vertices timed.
FivCost fiv_self_shadows_cost(const Mesh& occluder, const Topology& topology, const EnvMap& env, const ShellSpec& spec,
                              size_t samples);

// The shell bake as rows, for bakes cut into chunks (sharded and resumable bakes): bake_fiv_shells
// is this class's rows shell after shell, stopping where stops_after() says, so any cut of the
// shells' rows gives the same numbers. Row r of shell k is grid sample r = i·Nφ + j, kRowWidth
// doubles: the occluded FIV rounded to float (9), valid (0 or 1), the sample's stopping
// ratio max_c |F_c| / ∫ L_c dω (0 inside the geometry) and the cone (m, Ω) rounded to float (4).
class FivShellRows {
public:
  static constexpr size_t kRowWidth = 15;
  FivShellRows(const Mesh& occluder, const Topology& topology, const EnvMap& env, const ShellSpec& spec);
  // The frame, radii and stopping rule only (a merge of committed rows): no integrator, no
  // environment; rows() is then a contract error.
  FivShellRows(const Mesh& occluder, const ShellSpec& spec);
  ~FivShellRows();
  int shell_count() const { return int(radii_.size()); }  // spec.n_rho: the most the bake can use
  size_t rows_per_shell() const;
  double radius(int shell) const { return radii_.at(size_t(shell)); }
  // Rows [begin, end) of shell `shell`, [end − begin][kRowWidth]; one task->advance() per row
  // when given (Cancelled on a cancel request).
  std::vector<double> rows(int shell, size_t begin, size_t end, Task* task = nullptr) const;
  // Whether the bake ends with shell `shell`, whose rows (all of them) are `rows`: outside the
  // bounding sphere (may_stop_after) and every sample's ratio below spec.fraction.
  bool may_stop_after(int shell) const;
  bool stops_after(int shell, std::span<const double> rows) const;
  // Appends shell `shell` (all its rows) to `shells`, which starts as empty_shells().
  void append(FivShells& shells, int shell, std::span<const double> rows) const;
  // After the last append: the surface scheme's extrapolation (extrapolate_inside_samples).
  void finish(FivShells& shells) const;
  FivShells empty_shells() const;  // the frame (centre, radius, grid) without shells

private:
  ShellSpec spec_;
  FivShells frame_;
  std::vector<double> radii_;
  double env_norm_[3] = {0, 0, 0};
  std::unique_ptr<const SilhouetteIntegrator> integrator_;
};

// The occluded FIV at one offset from an integrator built for {radiance = &env, visibility order 1
// or 2} in full-sphere mode: F = unoccluded − visible (shared discretisation). Sets `inside` when no
// direction is visible, and `cone` to (m_x, m_y, m_z, Ω) (header comment) when given and the
// integrator has visibility order >= 2 (left as it was otherwise).
using Cone = std::array<double, 4>;
Fiv occluded_fiv(const SilhouetteIntegrator& integrator, const Eigen::Vector3d& position, bool* inside = nullptr,
                 Cone* cone = nullptr);

// The same quantity from the QMC reference (an integrator built for {radiance = &env, visibility
// order 1}) in full-sphere mode: F = F^env − ∫ V L ω dω with F^env = environment_fiv(env).
// `std_error` (optional) receives the standard error of each component.
class QmcIntegrator;
Fiv qmc_occluded_fiv(const QmcIntegrator& integrator, const Fiv& environment, const Eigen::Vector3d& position,
                     uint64_t point_index, Fiv* std_error = nullptr);

// Error of baked shells against the QMC reference (IntegratorSpec::kSilhouetteReferenceRays, full sphere) at `points` shell
// samples chosen with `seed` (docs/ARCHITECTURE.md §6): RMSE and max over the 9 numbers of each sample.
struct FivErrorReport {
  size_t points = 0;
  double rmse = 0, max_abs = 0;
  double reference_rms = 0;        // RMS of the F^env components: the scale errors are relative to
  double reference_std_error = 0;  // RMS of the reference's own standard errors
  double reference_seconds = 0;    // apart from the bake time
  std::string reference;           // the reference integrator's description
};
// The reference integration is a "reference" stage of `monitor` (progress, Cancelled).
FivErrorReport fiv_error_report(const Mesh& occluder, const Topology& topology, const EnvMap& env, const FivShells& shells,
                                const Fiv& environment, size_t points, uint64_t seed, const Monitor& monitor = {});

} // namespace prt::bake
