#include <bake/bake/bounce.h>
#include <bake/bake/vertex_bake.h>
#include <bake/core/error.h>
#include <bake/sphere/sampling.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

namespace prt::bake {

namespace {
// The gather's own stream of randomisation, apart from the direct pass's QMC points of the same
// seed and row (bake/sphere/sampling.h RotatedHalton3).
constexpr uint64_t kGatherStream = 0x6a09e667f3bcc909ull;

double rms(std::span<const double> v) {
  double s = 0;
  for (const double x : v) s += x * x;
  return v.empty() ? 0.0 : std::sqrt(s / double(v.size()));
}
} // namespace

GatherHits gather(const RayCaster& rays, std::span<const ShadePoint> points, const BounceSpec& spec,
                  const Monitor& monitor, const std::string& label) {
  PRT_CHECK_OP(spec.rays, >, 0u);
  const auto t0 = std::chrono::steady_clock::now();
  GatherHits hits;
  hits.rays = spec.rays;
  const size_t K = spec.rays;
  hits.triangle.assign(points.size() * K, GatherHits::kNone);
  hits.weights.assign(points.size() * K, {0.0f, 0.0f});
  const uint64_t seed = mix64(spec.seed ^ kGatherStream);
  Task progress(monitor, label, points.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, points.size(), 16), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v) {
      const ShadePoint& point = points[v];
      PRT_CHECK(point.hemisphere);
      const Frame frame(point.n);
      const RotatedHalton3 halton(seed, v);
      const NearTriangles near = rays.near_triangles(point);
      for (size_t k = 0; k < K; ++k) {
        const auto u = halton(k);
        Eigen::Vector3d d = frame.to_world(cosine_hemisphere(u[1], u[2]));
        d.normalize();
        if (!(point.n.dot(d) > 0)) continue;  // on the horizon (a null set): no contribution
        const auto hit = rays.first_surface_hit(point, near, d);
        if (!hit || !hit->front) continue;  // the sky (the direct pass's), or a back face (black)
        hits.triangle[v * K + k] = hit->triangle;
        hits.weights[v * K + k] = {float(hit->w1), float(hit->w2)};
      }
    }
    progress.advance(r.size());
  });
  progress.finish();
  hits.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return hits;
}

void check_albedo(std::span<const double> albedo, const std::string& source) {
  for (size_t t = 0; t < albedo.size(); ++t) {
    const double a = albedo[t];
    if (std::isfinite(a) && a >= 0 && a < 1) continue;
    char value[64];
    std::snprintf(value, sizeof value, "%.17g", a);
    throw InputError(source, "albedo " + std::string(value) + " of triangle " + std::to_string(t) +
                                 (a >= 1 ? " is 1 or more: the bounces would not converge (an albedo must be below 1)"
                                  : a < 0 ? " is negative (an albedo is a reflectance in [0, 1))"
                                          : " is not a number (an albedo is a reflectance in [0, 1))"));
  }
}

BounceResult bounce_transfer(const Mesh& mesh, const GatherHits& hits, std::span<const double> albedo,
                             const ProductLayout& layout, std::span<const double> direct, const BounceSpec& spec,
                             const Monitor& monitor, const std::string& label) {
  const size_t V = mesh.positions.size(), W = layout.width, n = layout.transfer_count, K = hits.rays;
  PRT_CHECK_OP(albedo.size(), ==, mesh.triangles.size());
  PRT_CHECK_OP(direct.size(), ==, V * W);
  PRT_CHECK_OP(hits.rows(), ==, V);
  PRT_CHECK(spec.bounces >= 0);
  check_albedo(albedo, mesh.source);
  BounceResult out;
  out.values.assign(direct.begin(), direct.end());
  if (n == 0 || spec.bounces == 0) return out;

  // B⁰: the direct pass's transfer slice, [V][n].
  std::vector<double> previous(V * n);
  for (size_t v = 0; v < V; ++v)
    for (size_t i = 0; i < n; ++i) previous[v * n + i] = direct[v * W + layout.transfer + i];
  const double direct_rms = rms(previous);

  for (int b = 1; b <= spec.bounces; ++b) {
    // B^b(p) = (1/K) Σ_k ρ(h_k) Σ_c w_c B^{b−1}(corner c of h_k's triangle), eq. (3) of the header.
    VertexBake pass = bake_rows(
        0, V, n,
        [&](size_t v, std::span<double> row, std::span<double>) {
          for (size_t k = 0; k < K; ++k) {
            const uint32_t t = hits.triangle[v * K + k];
            if (t == GatherHits::kNone) continue;
            const double rho = albedo[t];
            if (rho == 0) continue;
            const auto& tri = mesh.triangles[t];
            const double w1 = hits.weights[v * K + k][0], w2 = hits.weights[v * K + k][1];
            const double w[3] = {rho * (1.0 - w1 - w2), rho * w1, rho * w2};
            for (int c = 0; c < 3; ++c) {
              const double* src = &previous[size_t(tri[size_t(c)]) * n];
              for (size_t i = 0; i < n; ++i) row[i] += w[c] * src[i];
            }
          }
          for (size_t i = 0; i < n; ++i) row[i] /= double(K);
        },
        monitor, label + " (bounce " + std::to_string(b) + ")", "the bounce gather of " + mesh.source);
    // Summed only where non-zero, so an albedo of 0 leaves the direct rows' bits (−0 included).
    for (size_t v = 0; v < V; ++v)
      for (size_t i = 0; i < n; ++i)
        if (const double x = pass.values[v * n + i]; x != 0) out.values[v * W + layout.transfer + i] += x;
    const double r = direct_rms > 0 ? rms(pass.values) / direct_rms : 0.0;
    out.applied = b;
    out.relative_rms.push_back(r);
    out.seconds.push_back(pass.seconds);
    previous = std::move(pass.values);
    if (r <= spec.tolerance) break;
  }
  for (const double x : out.values)
    if (!std::isfinite(x)) throw ContractError("bounce_transfer: a non-finite value in the bounced rows of " + mesh.source);
  return out;
}

} // namespace prt::bake
