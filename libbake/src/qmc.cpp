#include <bake/envmap.h>
#include <bake/error.h>
#include <bake/qmc.h>
#include <bake/sampling.h>

#include <prtshade/sh.h>

#include <embree3/rtcore.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <vector>

namespace prt::bake {

using Eigen::Vector3d;

bool occludes_from_above(const Vector3d& p, const Vector3d& a, const Vector3d& b, const Vector3d& n,
                         const Vector3d& d) {
  const Vector3d e1 = a - p, e2 = b - p;
  const Vector3d m = e1.cross(e2);
  const double mm = m.squaredNorm();
  if (!(mm > 0)) return false;  // zero-area: no solid angle, blocks nothing
  const double md = m.dot(d), mn = m.dot(n);
  if (md == 0) return false;    // ray parallel to the plane: a set of measure zero
  const double s = -mn / md;
  if (!(s > 0)) return false;   // the plane is behind the ray (or through p + εn itself)
  const Vector3d q = n + s * d; // in the plane of the triangle, up to rounding
  // q = α e1 + β e2 with α = ((q × e2)·m)/|m|², β = ((e1 × q)·m)/|m|²; inside the cone iff α, β ≥ 0.
  const double alpha = q.cross(e2).dot(m), beta = e1.cross(q).dot(m);
  return alpha >= 0 && beta >= 0;
}

// ---- Embree scene -------------------------------------------------------------------------

namespace {
// The intersect context carries the shade point's welded id so the filter can drop its 1-ring.
struct RingContext {
  RTCIntersectContext base;
  int64_t welded;
  const uint32_t* weld;                    // output vertex -> welded id
  const std::array<uint32_t, 3>* triangles;
};

void ring_filter(const RTCFilterFunctionNArguments* args) {
  const auto* ctx = reinterpret_cast<const RingContext*>(args->context);
  if (ctx->welded < 0) return;
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    const unsigned prim = RTCHitN_primID(args->hit, args->N, i);
    const auto& t = ctx->triangles[prim];
    const auto w = uint32_t(ctx->welded);
    if (ctx->weld[t[0]] == w || ctx->weld[t[1]] == w || ctx->weld[t[2]] == w) args->valid[i] = 0;
  }
}

void embree_error(void* user, RTCError code, const char* str) {
  auto* msg = static_cast<std::string*>(user);
  if (msg->empty()) *msg = "Embree error " + std::to_string(int(code)) + ": " + (str ? str : "");
}
} // namespace

struct QmcIntegrator::Embree {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::string error;

  Embree(const Mesh& mesh) {
    device = rtcNewDevice(nullptr);
    if (!device) throw ContractError("Embree: rtcNewDevice failed (error " +
                                     std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
    rtcSetDeviceErrorFunction(device, embree_error, &error);
    scene = rtcNewScene(device);
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                          3 * sizeof(float), mesh.positions.size()));
    auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                               3 * sizeof(uint32_t), mesh.triangles.size()));
    if (!v || !idx) throw ContractError("Embree: cannot allocate geometry buffers: " + error);
    for (size_t i = 0; i < mesh.positions.size(); ++i)
      for (int k = 0; k < 3; ++k) v[3 * i + k] = mesh.positions[i][k];
    for (size_t i = 0; i < mesh.triangles.size(); ++i)
      for (int k = 0; k < 3; ++k) idx[3 * i + k] = mesh.triangles[i][k];
    rtcSetGeometryOccludedFilterFunction(geom, ring_filter);
    rtcCommitGeometry(geom);
    rtcAttachGeometry(scene, geom);
    rtcReleaseGeometry(geom);
    rtcCommitScene(scene);
    if (!error.empty()) throw ContractError(error);
  }
  ~Embree() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

// ---- integrator ---------------------------------------------------------------------------

QmcIntegrator::QmcIntegrator(const Mesh& mesh, const Topology& topology, const ProductRequest& request,
                             const QmcOptions& options)
    : mesh_(mesh), topo_(topology), request_(request), layout_(request), options_(options) {
  PRT_CHECK(options.samples > 0);
  PRT_CHECK_OP(topology.weld.size(), ==, mesh.positions.size());
  const bool want_cos = request.ao || request.transfer_order > 0 || request.radiance;
  const bool want_uni = request.visibility_order > 0;
  w_env_ = request.radiance ? 0.5 : 0.0;
  const double rest = 1.0 - w_env_;
  const int n_hemi = int(want_cos) + int(want_uni);
  if (n_hemi > 0) {
    w_cos_ = want_cos ? rest / n_hemi : 0.0;
    w_uni_ = want_uni ? rest / n_hemi : 0.0;
  } else {
    w_env_ = 1.0;
  }
  sh_order_ = std::max({request.transfer_order, request.visibility_order, request.radiance ? 2 : 0});
  PRT_CHECK_OP(sh_order_, <=, sh::kMaxOrder);
  rt_ = std::make_unique<Embree>(mesh);
}

QmcIntegrator::~QmcIntegrator() = default;

std::string QmcIntegrator::description() const {
  std::ostringstream os;
  os << "Embree 3 ray casting, randomised Halton QMC, " << options_.samples << " rays/point, seed " << options_.seed
     << ", mixture weights cosine " << w_cos_ << " uniform " << w_uni_ << " environment " << w_env_;
  return os.str();
}

bool QmcIntegrator::visible(const ShadePoint& point, const Vector3d& d) const {
  if (point.welded >= 0) {
    const auto w = uint32_t(point.welded);
    for (uint32_t f : topo_.ring(w)) {
      const auto& t = mesh_.triangles[f];
      // Rotate the corners so that c0 is the shade point's corner (any corner welded to it).
      int k = 0;
      while (k < 3 && topo_.weld[t[k]] != w) ++k;
      if (k == 3) continue;
      const Vector3d a = mesh_.positions[t[(k + 1) % 3]].cast<double>();
      const Vector3d b = mesh_.positions[t[(k + 2) % 3]].cast<double>();
      if (occludes_from_above(point.p, a, b, point.n, d)) return false;
    }
  }
  RingContext ctx;
  rtcInitIntersectContext(&ctx.base);
  ctx.welded = point.welded;
  ctx.weld = topo_.weld.data();
  ctx.triangles = mesh_.triangles.data();
  RTCRay ray{};
  ray.org_x = float(point.p.x());
  ray.org_y = float(point.p.y());
  ray.org_z = float(point.p.z());
  ray.dir_x = float(d.x());
  ray.dir_y = float(d.y());
  ray.dir_z = float(d.z());
  ray.tnear = 0.0f;
  ray.tfar = std::numeric_limits<float>::infinity();
  ray.mask = 0xFFFFFFFFu;
  ray.flags = 0;
  rtcOccluded1(rt_->scene, &ctx.base, &ray);
  return ray.tfar >= 0.0f;  // Embree sets tfar = -inf on a hit
}

void QmcIntegrator::integrate(const ShadePoint& point, uint64_t point_index, std::span<double> out,
                              std::span<double> std_error) const {
  PRT_CHECK_OP(out.size(), >=, layout_.width);
  PRT_CHECK(point.hemisphere);  // full-sphere mode: not in the QMC baseline yet (the FIV issue)
  const size_t W = layout_.width;
  std::vector<double> sum(W, 0.0), sum2(W, 0.0), x(W, 0.0);
  std::vector<double> y(size_t(sh::num_coeffs(std::max(sh_order_, 1))));
  const Frame frame(point.n);
  const RotatedHalton3 halton(options_.seed, point_index);
  constexpr double kInvPi = std::numbers::inv_pi;
  const uint32_t N = options_.samples;
  for (uint32_t i = 0; i < N; ++i) {
    const auto u = halton(i);
    Vector3d d;
    if (u[0] < w_env_) {
      double pdf_unused;
      d = request_.radiance->sample(u[1], u[2], &pdf_unused);
    } else if (u[0] < w_env_ + w_cos_) {
      d = frame.to_world(cosine_hemisphere(u[1], u[2]));
    } else {
      d = frame.to_world(uniform_hemisphere(u[1], u[2]));
    }
    d.normalize();
    const double c = point.n.dot(d);
    std::fill(x.begin(), x.end(), 0.0);
    if (c > 0 && visible(point, d)) {
      double p = w_cos_ * c * kInvPi + w_uni_ * (0.5 * kInvPi);
      if (w_env_ > 0) p += w_env_ * request_.radiance->pdf(d);
      const double inv_p = 1.0 / p;  // p ≥ w_cos c/π > 0 or w_uni/2π > 0 here
      if (sh_order_ > 0) sh::eval(sh_order_, d.x(), d.y(), d.z(), y);
      if (layout_.ao_count) x[layout_.ao] = c * kInvPi * inv_p;
      for (size_t k = 0; k < layout_.transfer_count; ++k) x[layout_.transfer + k] = c * kInvPi * y[k] * inv_p;
      for (size_t k = 0; k < layout_.visibility_count; ++k) x[layout_.visibility + k] = y[k] * inv_p;
      if (layout_.radiance_count) {
        const Rgb L = request_.radiance->radiance(d);
        const double rgb[3] = {L.r, L.g, L.b};
        for (int ch = 0; ch < 3; ++ch)
          for (int m = 0; m < 3; ++m) x[layout_.radiance + size_t(3 * ch + m)] = rgb[ch] * y[size_t(1 + m)] * inv_p;
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

} // namespace prt::bake
