#include <bake/bake/vertex_bake.h>
#include <bake/core/error.h>
#include <bake/sphere/sampling.h>
#include <bake/visibility/raycast.h>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <ctime>
#include <cmath>
#include <numeric>

namespace prt::bake {

VertexBake bake_points(std::span<const ShadePoint> points, const Integrator& integrator, const Monitor& monitor,
                       const std::string& label) {
  return bake_point_rows(points, 0, points.size(), integrator, monitor, label);
}

VertexBake bake_point_rows(std::span<const ShadePoint> points, size_t begin, size_t end, const Integrator& integrator,
                           const Monitor& monitor, const std::string& label) {
  PRT_CHECK(begin <= end && end <= points.size());
  VertexBake out;
  out.layout = integrator.layout();
  const size_t V = end - begin, W = out.layout.width;
  out.values.assign(V * W, 0.0);
  out.std_error.assign(V * W, 0.0);
  Task progress(monitor, label, V);
  const auto t0 = std::chrono::steady_clock::now();
  integrator.prepare(points);
  std::atomic<int64_t> cpu_ns{0};
  tbb::parallel_for(tbb::blocked_range<size_t>(begin, end, 16), [&](const tbb::blocked_range<size_t>& r) {
    const double c0 = thread_cpu_seconds();
    for (size_t v = r.begin(); v != r.end(); ++v)
      integrator.integrate(points[v], v, std::span(out.values).subspan((v - begin) * W, W),
                           std::span(out.std_error).subspan((v - begin) * W, W));
    cpu_ns.fetch_add(int64_t(1e9 * (thread_cpu_seconds() - c0)), std::memory_order_relaxed);
    progress.advance(r.size());
  });
  progress.finish();
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out.cpu_seconds = 1e-9 * double(cpu_ns.load());
  out.threads = tbb::this_task_arena::max_concurrency();
  for (double x : out.values)
    if (!std::isfinite(x)) throw ContractError("bake_points: non-finite value from integrator " + integrator.name());
  return out;
}

VertexBake bake_vertices(const Mesh& mesh, const Topology& topology, const Integrator& integrator,
                         const Monitor& monitor, const std::string& label) {
  return bake_points(vertex_shade_points(mesh, topology), integrator, monitor, label);
}

namespace {
// Whether each row saw no sky: its sky measure (AO, else T_0, else U_0; see the header) is 0, or
// every value is 0 for a radiance-only bake.
std::vector<uint8_t> dark_rows(const VertexBake& bake) {
  const ProductLayout& L = bake.layout;
  const size_t W = L.width;
  const size_t rows = W ? bake.values.size() / W : 0;
  const size_t none = W;
  const size_t column = L.ao_count ? L.ao : L.transfer_count ? L.transfer : L.visibility_count ? L.visibility : none;
  std::vector<uint8_t> dark(rows);
  for (size_t r = 0; r < rows; ++r) {
    const auto row = std::span(bake.values).subspan(r * W, W);
    dark[r] = column != none ? row[column] == 0.0 : std::all_of(row.begin(), row.end(), [](double x) { return x == 0.0; });
  }
  return dark;
}
} // namespace

NoSkyCount count_no_sky(const VertexBake& bake) {
  const std::vector<uint8_t> dark = dark_rows(bake);
  return {size_t(std::count(dark.begin(), dark.end(), uint8_t(1))), dark.size()};
}

FlipProbe probe_flipped_normals(const Mesh& mesh, const Topology& topology, const VertexBake& bake, size_t sample,
                                uint32_t rays, uint64_t seed) {
  const std::vector<uint8_t> dark = dark_rows(bake);
  PRT_CHECK_OP(dark.size(), ==, mesh.positions.size());
  std::vector<uint32_t> rows;
  for (uint32_t r = 0; r < dark.size(); ++r)
    if (dark[r]) rows.push_back(r);
  FlipProbe probe;
  if (rows.empty() || rays == 0) return probe;
  const RayCaster caster(mesh, topology);
  constexpr double kGolden = 2.399963229728653;  // π(3 − √5): the golden angle
  for (const uint32_t i : seeded_sample(uint32_t(rows.size()), sample, seed)) {
    ShadePoint sp = vertex_shade_point(mesh, topology, rows[i]);
    sp.n = -sp.n;
    const NearTriangles near = caster.near_triangles(sp);
    const Frame frame(sp.n);
    bool sky = false;
    for (uint32_t k = 0; k < rays && !sky; ++k) {  // a Fibonacci spiral over the hemisphere
      const double z = 1 - (k + 0.5) / rays, r = std::sqrt(std::max(0.0, 1 - z * z)), phi = kGolden * k;
      sky = caster.visible(sp, near, frame.to_world(Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), z)));
    }
    ++probe.probed;
    probe.would_see_sky += sky ? 1 : 0;
  }
  return probe;
}

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

std::vector<ProductSlice> product_slices(const ProductLayout& L) {
  std::vector<ProductSlice> s;
  if (L.ao_count) s.push_back({Product::Ao, L.ao, L.ao_count});
  if (L.transfer_count) s.push_back({Product::TransferDiffuse, L.transfer, L.transfer_count});
  if (L.visibility_count) s.push_back({Product::TransferVisibility, L.visibility, L.visibility_count});
  if (L.radiance_count) s.push_back({Product::RadianceBand1, L.radiance, L.radiance_count});
  if (L.shadowed_count) s.push_back({Product::RadianceShadowed, L.shadowed, L.shadowed_count});
  return s;
}

const char* product_label(Product product) {
  switch (product) {
  case Product::Ao: return "AO";
  case Product::TransferDiffuse: return "diffuse transfer";
  case Product::TransferVisibility: return "visibility transfer";
  case Product::RadianceBand1: return "band-1 radiance";
  case Product::RadianceShadowed: return "shadowed radiance";
  }
  return "?";
}

} // namespace prt::bake
