// bake/bake/vertex_bake.h — the row loop: one row of values per receiver (a mesh's vertex, a
// scene object's vertex; bake/mesh/receivers.h), integrated in parallel with oneTBB. Every bake's
// rows come from here: an integrator's (bake_point_rows) and the area lights' (bake_rows).
// Results are a function of (receivers, request, integrator parameters, seed) only: each row's
// randomisation is keyed by its index, so any thread count gives the same numbers.
#pragma once

#include <bake/core/progress.h>
#include <bake/integrators/integrator.h>
#include <bake/integrators/registry.h>
#include <bake/mesh/mesh.h>
#include <bake/mesh/receivers.h>
#include <bake/sphere/sampling.h>
#include <bake/visibility/accel.h>

#include <functional>
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
  // Rows whose integral took a closed form, with no numerical integration (IntegratorStats::closed_form).
  uint64_t closed_form = 0;
  double busy_fraction() const { return seconds > 0 ? cpu_seconds / (seconds * threads) : 0.0; }
};

// Writes row `index`: `values` and `std_error` are its `width` doubles (zeroed). Called
// concurrently for different rows.
using RowFunction = std::function<void(size_t index, std::span<double> values, std::span<double> std_error)>;

// The row loop: rows [begin, end) in parallel (grains of 16 rows), a progress task `label` of
// `monitor` (cancellable between grains), the wall and per-thread CPU times; throws
// ContractError naming `source` and the row when a value is not finite. The result holds
// end − begin rows; its layout is the caller's to set.
VertexBake bake_rows(size_t begin, size_t end, size_t width, const RowFunction& row, const Monitor& monitor,
                     const std::string& label, const std::string& source);


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

} // namespace prt::bake
