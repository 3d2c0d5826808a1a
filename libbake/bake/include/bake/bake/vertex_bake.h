// bake/bake/vertex_bake.h — per-vertex bakes: every output vertex of a Mesh is a shade point (its
// position, its baked normal, its welded 1-ring), integrated in parallel with oneTBB.
// Results are a function of (mesh, request, integrator parameters, seed) only: each vertex's
// randomisation is keyed by its index, so any thread count gives the same numbers.
#pragma once

#include <bake/core/progress.h>
#include <bake/integrators/integrator.h>
#include <bake/integrators/registry.h>
#include <bake/mesh/mesh.h>
#include <bake/mesh/receivers.h>
#include <bake/sphere/sampling.h>
#include <bake/visibility/accel.h>

#include <memory>
#include <utility>
#include <span>
#include <string>
#include <vector>

namespace prt::bake {

struct VertexBake {
  ProductLayout layout{ProductRequest{}};
  std::vector<double> values;     // [V][layout.width]
  std::vector<double> std_error;  // [V][layout.width], the integrator's per-value standard error
  double seconds = 0;             // wall time of the integration
  // CPU time spent inside the integrator, summed over the threads (each thread's own clock, so
  // idle and spinning workers do not count), and the threads that could run: busy_fraction()
  // = cpu_seconds / (seconds · threads) says whether every core was busy from the first point to
  // the last (a serial tail or a starved worker shows as less than 1).
  double cpu_seconds = 0;
  int threads = 1;
  double busy_fraction() const { return seconds > 0 ? cpu_seconds / (seconds * threads) : 0.0; }
};


VertexBake bake_vertices(const Mesh& mesh, const Topology& topology, const Integrator& integrator,
                         const Monitor& monitor = {}, const std::string& label = "baking vertices");

// The general form: any shade points (e.g. a scene receiver's vertices against the scene's
// occluders, bake/bake/scene.h); row i belongs to points[i], randomised by the index i.
VertexBake bake_points(std::span<const ShadePoint> points, const Integrator& integrator,
                       const Monitor& monitor = {}, const std::string& label = "baking vertices");
// Rows [begin, end) of bake_points(points, ...), each randomised by its index in `points` (the
// whole set), so the rows of any cut into ranges equal those of one bake_points call; the result
// holds end − begin rows. The form sharded bakes use (bake/core/chunks.h).
VertexBake bake_point_rows(std::span<const ShadePoint> points, size_t begin, size_t end, const Integrator& integrator,
                           const Monitor& monitor = {}, const std::string& label = "baking vertices");

// How many rows of a bake see no sky at all (a mesh wound inwards, or a vertex buried inside
// another object), for a tool's warning. A row sees no sky when its SKY MEASURE is exactly 0; the
// sky measure is the first of AO, T_0, U_0 the layout holds: each is the integral over the
// visible part of the hemisphere of a weight > 0 almost everywhere ((n·ω)/π, (n·ω) y_0/π, y_0),
// so it is 0 exactly when the visible part has measure zero. The silhouette integrator writes
// exact zeros then (it finds the point enclosed); the QMC estimate is a sum of positive terms, one
// per ray that escaped, so it is exactly 0 when every ray hit (and a fully visible-but-unlucky
// vertex cannot reach 0). A radiance-only bake has no such measure: there a row counts when all
// its values are exactly 0 (no sky, or a sky that is black wherever it is seen).
struct NoSkyCount {
  size_t vertices = 0;  // rows that see no sky
  size_t total = 0;     // rows
  double share() const { return total ? double(vertices) / double(total) : 0.0; }
};
NoSkyCount count_no_sky(const VertexBake& bake);

// Of the rows that saw no sky, how many would see some with the opposite normal: what tells
// normals that point inside the geometry (most would) from vertices enclosed by other geometry,
// such as an engine's internals under its housing (none would). Probes a seeded sample of at most
// `sample` such rows of `mesh` (the mesh `bake` belongs to, one row per vertex), each with `rays`
// fixed directions over the flipped hemisphere, visibility in the ε-limit (bake/visibility/raycast.h).
struct FlipProbe {
  size_t probed = 0;         // no-sky rows probed
  size_t would_see_sky = 0;  // of them, those that see some sky with the opposite normal
};
FlipProbe probe_flipped_normals(const Mesh& mesh, const Topology& topology, const VertexBake& bake, size_t sample = 256,
                                uint32_t rays = 256, uint64_t seed = 1);

// Error against a converged reference on a seeded sample of vertices (docs/ARCHITECTURE.md §6).
// The per-vertex products, as libbake knows them; the file names them through formats/ (the
// baker maps each to its dataset there), libbake only labels them for people.
enum class Product { Ao, TransferDiffuse, TransferVisibility, RadianceBand1, RadianceShadowed };
const char* product_label(Product product);  // "AO", "diffuse transfer", ... (for logs)

// Where each product a layout holds lies in a row, in row order (AO, diffuse transfer,
// visibility transfer, band-1 radiance, shadowed radiance); products the layout does not hold are left out.
struct ProductSlice {
  Product product;
  size_t offset, count;
};
std::vector<ProductSlice> product_slices(const ProductLayout& layout);

struct ProductError {
  Product product = Product::Ao;
  size_t values = 0;                // numbers compared
  double rmse = 0, max_abs = 0;     // bake − reference
  double reference_rms = 0;         // RMS of the reference values (for relative errors)
  double bake_std_error = 0;        // RMS of the bake's own estimated standard errors
  double reference_std_error = 0;   // RMS of the reference's standard errors (its own noise)
};
struct ErrorReport {
  std::vector<uint32_t> vertices;
  std::vector<ProductError> products;
  std::string reference;            // the reference integrator's description
  double reference_seconds = 0;     // apart from the bake time
  // The reference was two independent halves: reference_std_error is their measured noise (the
  // RMS of |a − b| / 2), not QMC's estimator (which overstates it).
  bool reference_noise_measured = false;
};

// Picks min(n_points, V) distinct vertices with `seed`, integrates them with `reference`, and
// compares with `bake` (which must have the same layout). The reference integration is a
// "reference" stage of `monitor`: it reports progress and throws Cancelled like a bake.
// With `second` (an independent reference of the same kind, make_reference_pair), the reference
// is the mean of the two and its noise is measured per value as |a − b| / 2
// (ErrorReport::reference_noise_measured).
ErrorReport compare_with_reference(const Mesh& mesh, const Topology& topology, const VertexBake& bake,
                                   const Integrator& reference, size_t n_points, uint64_t seed,
                                   const Monitor& monitor = {}, const Integrator* second = nullptr);

ErrorReport compare_points_with_reference(std::span<const ShadePoint> points, const VertexBake& bake,
                                          const Integrator& reference, size_t n_points, uint64_t seed,
                                          const Monitor& monitor = {}, const Integrator* second = nullptr);

} // namespace prt::bake
