#include <bake/bake/vertex_bake.h>
#include <bake/core/error.h>
#include <bake/sphere/sampling.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <string>

namespace prt::bake {

VertexBake bake_points(std::span<const ShadePoint> points, const Integrator& integrator, const Monitor& monitor,
                       const std::string& label) {
  return bake_point_rows(points, 0, points.size(), integrator, monitor, label);
}

VertexBake bake_rows(size_t begin, size_t end, size_t width, const RowFunction& row, const Monitor& monitor,
                     const std::string& label, const std::string& source) {
  PRT_CHECK(begin <= end);
  VertexBake out;
  const size_t V = end - begin, W = width;
  out.values.assign(V * W, 0.0);
  out.std_error.assign(V * W, 0.0);
  Task progress(monitor, label, V);
  const auto t0 = std::chrono::steady_clock::now();
  std::atomic<int64_t> cpu_ns{0};
  tbb::parallel_for(tbb::blocked_range<size_t>(begin, end, 16), [&](const tbb::blocked_range<size_t>& r) {
    const double c0 = thread_cpu_seconds();
    for (size_t v = r.begin(); v != r.end(); ++v)
      row(v, std::span(out.values).subspan((v - begin) * W, W), std::span(out.std_error).subspan((v - begin) * W, W));
    cpu_ns.fetch_add(int64_t(1e9 * (thread_cpu_seconds() - c0)), std::memory_order_relaxed);
    progress.advance(r.size());
  });
  progress.finish();
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out.cpu_seconds = 1e-9 * double(cpu_ns.load());
  out.threads = tbb::this_task_arena::max_concurrency();
  for (size_t k = 0; k < out.values.size(); ++k)
    if (!std::isfinite(out.values[k]))
      throw ContractError("bake_rows: non-finite value at row " + std::to_string(begin + k / std::max<size_t>(W, 1)) +
                          " from " + source);
  return out;
}

VertexBake bake_point_rows(std::span<const ShadePoint> points, size_t begin, size_t end, const Integrator& integrator,
                           const Monitor& monitor, const std::string& label) {
  PRT_CHECK(begin <= end && end <= points.size());
  const auto t0 = std::chrono::steady_clock::now();
  integrator.prepare(points);  // in the bake's wall time (the filter casts its pass-1 rays here)
  const uint64_t closed_before = integrator.stats().closed_form;
  VertexBake out = bake_rows(
      begin, end, integrator.layout().width,
      [&](size_t v, std::span<double> values, std::span<double> std_error) {
        integrator.integrate(points[v], v, values, std_error);
      },
      monitor, label, "integrator " + integrator.name());
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out.layout = integrator.layout();
  out.closed_form = integrator.stats().closed_form - closed_before;
  return out;
}

VertexBake bake_vertices(const Mesh& mesh, const Topology& topology, const Integrator& integrator,
                         const Monitor& monitor, const std::string& label) {
  return bake_points(vertex_shade_points(mesh, topology), integrator, monitor, label);
}


} // namespace prt::bake
