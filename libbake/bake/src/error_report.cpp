// error_report.cpp — a bake against its converged reference (bake/bake/error_report.h).
#include <bake/bake/error_report.h>
#include <bake/core/error.h>
#include <bake/sphere/sampling.h>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

namespace prt::bake {

ErrorReport compare_with_reference(const Mesh& mesh, const Topology& topology, const VertexBake& bake,
                                   const Integrator& reference, size_t n_points, uint64_t seed,
                                   const Monitor& monitor, const Integrator* second) {
  return compare_points_with_reference(vertex_shade_points(mesh, topology), bake, reference, n_points, seed, monitor,
                                       second);
}

ErrorReport compare_points_with_reference(std::span<const ShadePoint> points, const VertexBake& bake,
                                          const Integrator& reference, size_t n_points, uint64_t seed,
                                          const Monitor& monitor, const Integrator* second) {
  const ProductLayout& L = bake.layout;
  PRT_CHECK_OP(reference.layout().width, ==, L.width);
  if (second) PRT_CHECK_OP(second->layout().width, ==, L.width);
  PRT_CHECK_OP(bake.values.size(), ==, points.size() * L.width);
  ErrorReport report;
  report.reference = reference.description();
  report.reference_noise_measured = second != nullptr;
  if (second) report.reference += " + an independent half (their mean)";
  report.vertices = seeded_sample(uint32_t(points.size()), n_points, seed);
  const size_t K = report.vertices.size(), W = L.width;
  std::vector<double> ref(K * W), ref_se(K * W);
  const auto t0 = std::chrono::steady_clock::now();
  Task progress(monitor, "reference", K);
  tbb::enumerable_thread_specific<std::vector<double>> scratch;
  tbb::parallel_for(size_t(0), K, [&](size_t i) {
    const uint32_t v = report.vertices[i];
    // Index the reference's randomisation apart from the bake's (point index offset by V).
    const std::span<double> r = std::span(ref).subspan(i * W, W), se = std::span(ref_se).subspan(i * W, W);
    reference.integrate(points[v], uint64_t(v) + points.size(), r, se);
    if (second) {
      // Two independent halves a, b: the reference is their mean, whose noise per value is
      // measured as |a − b| / 2 (E[(a − b)²] / 4 = Var(a) / 2 = Var of the mean).
      std::vector<double>& b = scratch.local();
      b.resize(2 * W);
      second->integrate(points[v], uint64_t(v) + points.size(), std::span(b).first(W), std::span(b).last(W));
      for (size_t c = 0; c < W; ++c) {
        se[c] = 0.5 * std::abs(r[c] - b[c]);
        r[c] = 0.5 * (r[c] + b[c]);
      }
    }
    progress.advance();
  });
  progress.finish();
  report.reference_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  auto add = [&](Product product, size_t offset, size_t count) {
    ProductError e;
    e.product = product;
    double se2 = 0, bse2 = 0, err2 = 0, r2 = 0;
    for (size_t i = 0; i < K; ++i) {
      const size_t v = report.vertices[i];
      for (size_t c = 0; c < count; ++c) {
        const double b = bake.values[v * W + offset + c], r = ref[i * W + offset + c];
        err2 += (b - r) * (b - r);
        r2 += r * r;
        se2 += ref_se[i * W + offset + c] * ref_se[i * W + offset + c];
        bse2 += bake.std_error[v * W + offset + c] * bake.std_error[v * W + offset + c];
        e.max_abs = std::max(e.max_abs, std::abs(b - r));
      }
    }
    e.values = K * count;
    const double n = double(std::max<size_t>(e.values, 1));
    e.rmse = std::sqrt(err2 / n);
    e.reference_rms = std::sqrt(r2 / n);
    e.reference_std_error = std::sqrt(se2 / n);
    e.bake_std_error = std::sqrt(bse2 / n);
    report.products.push_back(e);
  };
  for (const ProductSlice& slice : product_slices(L)) add(slice.product, slice.offset, slice.count);
  return report;
}

} // namespace prt::bake
