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

} // namespace prt::bake
