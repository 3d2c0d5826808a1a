#include <bake/core/error.h>
#include <bake/environment/envmap.h>
#include <bake/integrators/qmc.h>
#include <bake/sphere/sampling.h>

#include <prtshade/sh.h>


#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <sstream>
#include <vector>

namespace prt::bake {

using Eigen::Vector3d;

// ---- integrator ---------------------------------------------------------------------------

QmcIntegrator::QmcIntegrator(const Mesh& mesh, const Topology& topology, const ProductRequest& request,
                             const QmcOptions& options, const MeshAccel* accel)
    : request_(request), layout_(request), options_(options) {
  PRT_CHECK(options.rays > 0);
  PRT_CHECK_OP(topology.weld.size(), ==, mesh.positions.size());
  PRT_CHECK(request.consistent());
  const bool want_cos = request.ao || request.transfer_order > 0 || request.radiance;
  const bool want_uni = request.visibility_order > 0 || request.shadowed_order > 0;
  env_ = request.environment();
  w_env_ = env_ ? 0.5 : 0.0;
  const double rest = 1.0 - w_env_;
  const int n_hemi = int(want_cos) + int(want_uni);
  if (n_hemi > 0) {
    w_cos_ = want_cos ? rest / n_hemi : 0.0;
    w_uni_ = want_uni ? rest / n_hemi : 0.0;
  } else {
    w_env_ = 1.0;
  }
  sh_order_ = std::max({request.transfer_order, request.visibility_order, request.radiance ? 2 : 0, request.shadowed_order});
  PRT_CHECK_OP(sh_order_, <=, sh::kMaxOrder);
  PRT_CHECK(!accel || accel->of(mesh, topology));
  rays_ = accel ? accel->rays() : std::make_shared<const RayCaster>(mesh, topology);
}

QmcIntegrator::~QmcIntegrator() = default;

std::string QmcIntegrator::description() const {
  std::ostringstream os;
  os << "Embree 3 ray casting, randomised Halton QMC, " << options_.rays << " rays/point, seed " << options_.seed
     << ", mixture weights cosine " << w_cos_ << " uniform " << w_uni_ << " environment " << w_env_;
  return os.str();
}

bool QmcIntegrator::visible(const ShadePoint& point, const Vector3d& d) const { return rays_->visible(point, d); }

void QmcIntegrator::integrate(const ShadePoint& point, uint64_t point_index, std::span<double> out,
                              std::span<double> std_error) const {
  PRT_CHECK_OP(out.size(), >=, layout_.width);
  // The point's time in here into the counters, however the call ends (steady_clock, as the
  // silhouette integrator's: a thread CPU clock costs a system call per read).
  struct Counted {
    const QmcIntegrator& q;
    std::chrono::steady_clock::time_point t0 = std::chrono::steady_clock::now();
    ~Counted() {
      q.points_.fetch_add(1, std::memory_order_relaxed);
      q.cpu_ns_.fetch_add(uint64_t(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                       std::chrono::steady_clock::now() - t0).count()),
                          std::memory_order_relaxed);
    }
  } counted{*this};
  // Full-sphere mode (H ≡ 1): the hemisphere strategies become one uniform-sphere strategy of the
  // same total weight; AO and diffuse transfer (defined with n·ω) are hemisphere products only.
  const bool full = !point.hemisphere;
  PRT_CHECK(!full || (layout_.ao_count == 0 && layout_.transfer_count == 0));
  const size_t W = layout_.width;
  std::vector<double> sum(W, 0.0), sum2(W, 0.0), x(W, 0.0);
  std::vector<double> y(size_t(sh::num_coeffs(std::max(sh_order_, 1))));
  const Frame frame(point.n);
  const RotatedHalton3 halton(options_.seed, point_index);
  const NearTriangles near = rays_->near_triangles(point);  // decided exactly, for every ray
  constexpr double kInvPi = std::numbers::inv_pi;
  const uint32_t N = options_.rays;
  for (uint32_t i = 0; i < N; ++i) {
    const auto u = halton(i);
    Vector3d d;
    if (u[0] < w_env_) {
      double pdf_unused;
      d = env_->sample(u[1], u[2], &pdf_unused);
    } else if (full) {
      d = uniform_sphere(u[1], u[2]);
    } else if (u[0] < w_env_ + w_cos_) {
      d = frame.to_world(cosine_hemisphere(u[1], u[2]));
    } else {
      d = frame.to_world(uniform_hemisphere(u[1], u[2]));
    }
    d.normalize();
    const double c = point.n.dot(d);
    std::fill(x.begin(), x.end(), 0.0);
    if ((full || c > 0) && rays_->visible(point, near, d)) {
      double p = full ? (1.0 - w_env_) * (0.25 * kInvPi) : w_cos_ * c * kInvPi + w_uni_ * (0.5 * kInvPi);
      if (w_env_ > 0) p += w_env_ * env_->pdf(d);
      const double inv_p = 1.0 / p;  // p ≥ w_cos c/π > 0, w_uni/2π or w_sphere/4π > 0 here
      if (sh_order_ > 0) sh::eval(sh_order_, d.x(), d.y(), d.z(), y);
      if (layout_.ao_count) x[layout_.ao] = c * kInvPi * inv_p;
      for (size_t k = 0; k < layout_.transfer_count; ++k) x[layout_.transfer + k] = c * kInvPi * y[k] * inv_p;
      for (size_t k = 0; k < layout_.visibility_count; ++k) x[layout_.visibility + k] = y[k] * inv_p;
      if (env_) {
        const Rgb L = env_->radiance(d);
        const double rgb[3] = {L.r, L.g, L.b};
        if (layout_.radiance_count)
          for (int ch = 0; ch < 3; ++ch)
            for (int m = 0; m < 3; ++m) x[layout_.radiance + size_t(3 * ch + m)] = rgb[ch] * y[size_t(1 + m)] * inv_p;
        const size_t ns = layout_.shadowed_count / 3;
        for (int ch = 0; ch < 3; ++ch)
          for (size_t k = 0; k < ns; ++k) x[layout_.shadowed + size_t(ch) * ns + k] = rgb[ch] * y[k] * inv_p;
      }
    }
    for (size_t k = 0; k < W; ++k) {
      sum[k] += x[k];
      sum2[k] += x[k] * x[k];
    }
  }
  for (size_t k = 0; k < W; ++k) {
    const double mean = sum[k] / N;
    out[k] = mean;
    if (!std_error.empty()) {
      const double var = N > 1 ? std::max(0.0, (sum2[k] - N * mean * mean) / (double(N) * (N - 1))) : 0.0;
      std_error[k] = std::sqrt(var);
    }
  }
}

IntegratorStats QmcIntegrator::stats() const {
  IntegratorStats s;
  s.points = points_.load();
  s.cpu_seconds = double(cpu_ns_.load()) * 1e-9;
  return s;
}

std::string QmcIntegrator::work_summary() const {
  const IntegratorStats st = stats();
  char line[160];
  std::snprintf(line, sizeof line, "%u rays per point; %.2f M rays per second of integrator time", unsigned(options_.rays),
                st.cpu_seconds > 0 ? double(st.points) * options_.rays / st.cpu_seconds / 1e6 : 0.0);
  return line;
}

} // namespace prt::bake
