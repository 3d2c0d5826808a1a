// reference.cpp — the Embree reference renderer and its OpenEXR cache (view/reference.h:
// estimators and conventions).
#include <view/reference.h>

#include <bake/core/error.h>
#include <bake/core/sha256.h>
#include <bake/sphere/sampling.h>
#include <bake/visibility/raycast.h>

#include <IexBaseExc.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <span>
#include <sstream>
#include <utility>

namespace prt::view {

using namespace prt::bake;  // Mesh, EnvMap, Rgb, RayCaster, Frame, samplers, errors
using Eigen::Vector3d;

namespace {
constexpr uint32_t kReplicates = 8;  // independent RQMC replicates per pixel

// Independent replicates (randomised QMC): B = min(8, samples) rotations of the Halton sequence
// keyed by (seed, index, replicate), samples/B points each; estimate(u, sum) adds one point's
// RGB terms to sum. The mean of the replicate means and its standard error, the spread of the
// means / √B: an honest error for the RQMC estimate, which converges faster than 1/√N (the iid
// sample variance would overstate it).
// estimate(u, replicate, point, sum): the replicate and the point's number within it key any
// further random numbers (PointStream below).
template <class Estimate>
void replicate_mean_keyed(uint32_t samples, uint64_t seed, uint64_t index, Estimate&& estimate, double mean[3], double se[3]) {
  const uint32_t B = std::min<uint32_t>(kReplicates, samples);
  const uint32_t per = std::max<uint32_t>(1, samples / B);
  double block_sum[3] = {0, 0, 0}, block_sum2[3] = {0, 0, 0};
  for (uint32_t b = 0; b < B; ++b) {
    const RotatedHalton3 halton(seed, index * kReplicates + b);
    double sum[3] = {0, 0, 0};
    for (uint32_t i = 0; i < per; ++i) estimate(halton(i), b, i, sum);
    for (int c = 0; c < 3; ++c) {
      const double m = sum[c] / per;
      block_sum[c] += m;
      block_sum2[c] += m * m;
    }
  }
  for (int c = 0; c < 3; ++c) {
    mean[c] = block_sum[c] / B;
    const double var = B > 1 ? std::max(0.0, (block_sum2[c] - B * mean[c] * mean[c]) / (double(B) * (B - 1))) : 0.0;
    se[c] = std::sqrt(var);
  }
}

template <class Estimate>
void replicate_mean(uint32_t samples, uint64_t seed, uint64_t index, Estimate&& estimate, double mean[3], double se[3]) {
  replicate_mean_keyed(
      samples, seed, index, [&](const std::array<double, 3>& u, uint32_t, uint32_t, double sum[3]) { estimate(u, sum); }, mean, se);
}

// Uniform numbers in [0, 1) for one path: a counter hashed with the path's key (seed, pixel,
// replicate, point), so a path's numbers do not depend on which thread traces it.
class PointStream {
public:
  PointStream(uint64_t seed, uint64_t index, uint32_t replicate, uint32_t point) noexcept
      : key_(mix64(mix64(seed ^ 0x5851f42d4c957f2dull) ^ mix64(index * kReplicates + replicate) ^ (uint64_t(point) << 32))) {}
  double next() noexcept { return to_unit(mix64(key_ + 0x9e3779b97f4a7c15ull * ++counter_)); }

private:
  uint64_t key_;
  uint64_t counter_ = 0;
};

} // namespace

// The ray queries of the reference: libbake's RayCaster (bake/visibility/raycast.h) over the rendered mesh for
// primary rays, and over the shadow-casting triangles only when some triangles cast no shadow.
struct ReferenceRenderer::Rays {
  Topology topology;
  RayCaster every_triangle;  // primary rays; shadow rays too unless `casters` is set
  Mesh caster_mesh;  // same vertices, the casting triangles (used when `casters` is set)
  std::optional<Topology> caster_topology;
  std::unique_ptr<RayCaster> casters;
  std::vector<uint32_t> caster_triangle;  // caster_mesh's triangle k is the mesh's caster_triangle[k]
  bool any_caster = true;
  Rays(const Mesh& mesh, std::span<const uint8_t> casts_shadow) : topology(build_topology(mesh)), every_triangle(mesh, topology) {
    if (casts_shadow.empty() || std::all_of(casts_shadow.begin(), casts_shadow.end(), [](uint8_t c) { return c != 0; })) return;
    caster_mesh = mesh;
    caster_mesh.triangles.clear();
    for (size_t t = 0; t < mesh.triangles.size(); ++t)
      if (casts_shadow[t]) {
        caster_mesh.triangles.push_back(mesh.triangles[t]);
        caster_triangle.push_back(uint32_t(t));
      }
    any_caster = !caster_mesh.triangles.empty();
    if (!any_caster) return;
    caster_topology = build_topology(caster_mesh);
    casters = std::make_unique<RayCaster>(caster_mesh, *caster_topology);
  }
  const RayCaster& shadow_caster() const { return casters ? *casters : every_triangle; }
  // A shading point's shadow rays start at o itself (a free point, welded = -1); the triangles
  // near o are found once per point, not once per ray (bake/visibility/raycast.h NearTriangles).
  bake::NearTriangles near(const Vector3d& o) const {
    ShadePoint sp;
    sp.p = o;
    return shadow_caster().near_triangles(sp);
  }
  bool occluded(const Vector3d& o, const bake::NearTriangles& near_o, const Vector3d& d) const {
    ShadePoint sp;
    sp.p = o;
    return !shadow_caster().visible(sp, near_o, d);
  }
  // The first casting triangle the ray o + t d meets (the mesh's index), or nothing (the sky).
  std::optional<SurfaceHit> first_hit(const Vector3d& o, const bake::NearTriangles& near_o, const Vector3d& d) const {
    ShadePoint sp;
    sp.p = o;
    auto hit = shadow_caster().first_surface_hit(sp, near_o, d);
    if (hit && casters) hit->triangle = caster_triangle[hit->triangle];
    return hit;
  }
};

ReferenceRenderer::ReferenceRenderer(const bake::Mesh& mesh, const bake::EnvMap& env, ReferenceOptions options)
    : mesh_(mesh), env_(env), options_(std::move(options)), unoccluded_(env),
      rt_(std::make_unique<Rays>(mesh, options_.casts_shadow)) {
  PRT_CHECK(options_.samples > 0 && (options_.samples % kReplicates == 0 || options_.samples < kReplicates));
  PRT_CHECK(!mesh.triangles.empty());
  PRT_CHECK(options_.casts_shadow.empty() || options_.casts_shadow.size() == mesh.triangles.size());
  PRT_CHECK(options_.albedo.empty() || options_.albedo.size() == mesh.triangles.size());
  PRT_CHECK(options_.reflectance.empty() || options_.reflectance.size() == mesh.triangles.size());
  PRT_CHECK(options_.gathers.empty() || options_.gathers.size() == mesh.triangles.size());
  PRT_CHECK(!options_.glossy || options_.bounces == 0);
  PRT_CHECK(!options_.glossy ||
            (options_.glossy->phong.size() == mesh.triangles.size() && options_.glossy->specular.size() == mesh.triangles.size()));
  Vector3d lo = Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const auto& q : mesh.positions) {
    lo = lo.cwiseMin(q.cast<double>());
    hi = hi.cwiseMax(q.cast<double>());
  }
  epsilon_ = 1e-5 * (hi - lo).norm() + 1e-6 * std::max(lo.cwiseAbs().maxCoeff(), hi.cwiseAbs().maxCoeff());
}

ReferenceRenderer::~ReferenceRenderer() = default;

std::string ReferenceRenderer::description() const {
  std::ostringstream os;
  os << "Embree: ";
  if (options_.glossy)
    os << "specular x Phong lobe, " << options_.samples << " QMC rays/pixel (lobe + environment)";
  else
    os << "E = exact unshadowed - QMC occluded, " << options_.samples << " shadow rays/pixel (cosine + environment"
       << (options_.occluder_spheres.empty() ? "" : " + " + std::to_string(options_.occluder_spheres.size()) + " cones") << ")";
  os << ", seed " << options_.seed;
  if (!options_.casts_shadow.empty()) {
    const auto n = std::count_if(options_.casts_shadow.begin(), options_.casts_shadow.end(), [](uint8_t c) { return c != 0; });
    os << "; shadows cast by " << n << " of " << mesh_.triangles.size() << " triangles";
  }
  if (!options_.albedo.empty() && !options_.glossy) os << "; albedos";
  if (options_.bounces > 0) {
    os << "; " << options_.bounces << (options_.bounces == 1 ? " bounce" : " bounces") << " path traced, " << options_.samples
       << " paths/pixel";
    if (!options_.gathers.empty()) {
      const auto n = std::count_if(options_.gathers.begin(), options_.gathers.end(), [](uint8_t c) { return c != 0; });
      os << " from " << n << " of " << mesh_.triangles.size() << " triangles";
    }
  }
  return os.str();
}

std::string ReferenceRenderer::cache_key(const Camera& cam) const {
  std::string bytes;
  auto put = [&](const void* p, size_t n) { bytes.append(static_cast<const char*>(p), n); };
  for (const auto& q : mesh_.positions) put(q.data(), 3 * sizeof(float));
  for (const auto& q : mesh_.normals) put(q.data(), 3 * sizeof(float));
  for (const auto& t : mesh_.triangles) put(t.data(), 3 * sizeof(uint32_t));
  put(options_.casts_shadow.data(), options_.casts_shadow.size());
  for (const auto& c : options_.albedo) put(c.data(), 3 * sizeof(float));
  if (!options_.reflectance.empty() || !options_.gathers.empty()) {
    bytes += "|reflectance";
    for (const auto& c : options_.reflectance) put(c.data(), 3 * sizeof(float));
    bytes += "|gathers";
    put(options_.gathers.data(), options_.gathers.size());
  }
  char buf[512];
  std::snprintf(buf, sizeof buf, "|eye %.17g %.17g %.17g at %.17g %.17g %.17g up %.17g %.17g %.17g fov %.17g near %.17g %dx%d",
                cam.eye.x(), cam.eye.y(), cam.eye.z(), cam.at.x(), cam.at.y(), cam.at.z(), cam.up.x(), cam.up.y(), cam.up.z(),
                cam.fov_y_degrees, cam.near, cam.width, cam.height);
  bytes += buf;
  if (options_.glossy) {
    put(options_.glossy->phong.data(), options_.glossy->phong.size() * sizeof(double));
    for (const auto& c : options_.glossy->specular) put(c.data(), 3 * sizeof(float));
    put(options_.glossy->eye.data(), 3 * sizeof(double));
  }
  for (const auto& sp : options_.occluder_spheres) {
    std::snprintf(buf, sizeof buf, "|sphere %.17g %.17g %.17g %.17g", sp.centre.x(), sp.centre.y(), sp.centre.z(), sp.radius);
    bytes += buf;
  }
  return sha256_bytes(std::as_bytes(std::span<const char>(bytes.data(), bytes.size()))) + " env " + env_.info().sha256 + " " +
         description();
}

GBuffer ReferenceRenderer::trace_primary(const Camera& camera) const {
  camera.validate();
  GBuffer g = GBuffer::blank(camera.width, camera.height);
  const Vector3d f = camera.forward();
  const double near = camera.near_depth();
  tbb::parallel_for(0, camera.height, [&](int y) {
    for (int x = 0; x < camera.width; ++x) {
      const Vector3d d = camera.ray_direction(x + 0.5, y + 0.5);
      const double df = d.dot(f);
      const auto hit = rt_->every_triangle.closest_hit(camera.eye, d, near / df);
      if (!hit) continue;
      const size_t i = size_t(y) * size_t(camera.width) + size_t(x);
      g.triangle[i] = int32_t(hit->triangle);
      g.bary[i] = {1.0f - hit->u - hit->v, hit->u, hit->v};
      g.depth[i] = float(double(hit->t) * df);
    }
  });
  return g;
}

void ReferenceRenderer::irradiance(const Fragment& f, uint64_t index, double E[3], double std_error[3]) const {
  irradiance(f, index, unoccluded_(f.n), E, std_error);
}

void ReferenceRenderer::irradiance(const Fragment& f, uint64_t index, const Rgb& unocc, double E[3], double std_error[3]) const {
  if (!rt_->any_caster) {  // nothing casts a shadow: the exact unshadowed sum, no noise
    const double un[3] = {unocc.r, unocc.g, unocc.b};
    for (int c = 0; c < 3; ++c) {
      E[c] = un[c];
      std_error[c] = 0;
    }
    return;
  }
  const Vector3d o = f.p + epsilon_ * f.ng;
  constexpr double kInvPi = std::numbers::inv_pi;
  // Cones around the occluder spheres that o sees from outside and that reach above the horizon.
  struct Cone {
    Vector3d axis;
    double cos_a, inv_solid_angle;
    Frame frame;
  };
  std::vector<Cone> cones;
  for (const Sphere& s : options_.occluder_spheres) {
    const Vector3d to = s.centre - o;
    const double D = to.norm();
    if (!(D > s.radius * (1 + 1e-9))) continue;
    const double sin_a = s.radius / D, cos_a = std::sqrt(std::max(0.0, 1 - sin_a * sin_a));
    const Vector3d axis = to / D;
    if (f.n.dot(axis) <= -sin_a) continue;  // wholly below the horizon: never needed
    const double one_minus_cos = sin_a * sin_a / (1 + cos_a);
    cones.push_back({axis, cos_a, 1.0 / (2 * std::numbers::pi * one_minus_cos), Frame(axis)});
  }
  const double w_cone_total = cones.empty() ? 0.0 : 0.5;
  const double w_cos = 0.5 * (1 - w_cone_total), w_env = w_cos;
  const double w_cone = cones.empty() ? 0.0 : w_cone_total / double(cones.size());
  const Frame frame(f.n);
  const bake::NearTriangles near_o = rt_->near(o);
  double occluded[3];
  replicate_mean(options_.samples, options_.seed, index, [&](const std::array<double, 3>& u, double sum[3]) {
      Vector3d d;
      if (u[0] < w_cos) {
        d = frame.to_world(cosine_hemisphere(u[1], u[2]));
      } else if (u[0] < w_cos + w_env) {
        d = env_.sample(u[1], u[2], nullptr);
      } else {
        const size_t k = std::min(cones.size() - 1, size_t((u[0] - w_cos - w_env) / w_cone));
        const Cone& c = cones[k];
        const double z = 1 - u[1] * (1 - c.cos_a), r = std::sqrt(std::max(0.0, 1 - z * z));
        const double phi = 2 * std::numbers::pi * u[2];
        d = c.frame.to_world(Vector3d(r * std::cos(phi), r * std::sin(phi), z));
      }
      d.normalize();
      const double cn = f.n.dot(d);
      if (!(cn > 0) || !rt_->occluded(o, near_o, d)) return;  // contributes 0 to the occluded part
      double p = w_cos * cn * kInvPi + w_env * env_.pdf(d);
      for (const Cone& c : cones)
        if (c.axis.dot(d) >= c.cos_a) p += w_cone * c.inv_solid_angle;
      const Rgb L = env_.radiance(d);
      sum[0] += L.r * cn / p;
      sum[1] += L.g * cn / p;
      sum[2] += L.b * cn / p;
    }, occluded, std_error);
  const double un[3] = {unocc.r, unocc.g, unocc.b};
  for (int c = 0; c < 3; ++c) E[c] = un[c] - occluded[c];
}

double ReferenceRenderer::albedo(int32_t triangle, int c) const {
  return options_.albedo.empty() ? 1.0 : double(options_.albedo[size_t(triangle)][size_t(c)]);
}

double ReferenceRenderer::reflectance(int32_t triangle, int c) const {
  return options_.reflectance.empty() ? albedo(triangle, c) : double(options_.reflectance[size_t(triangle)][size_t(c)]);
}

uint64_t ReferenceRenderer::indirect(const Fragment& f, uint64_t index, double E[3], double std_error[3]) const {
  if (options_.bounces == 0 || !rt_->any_caster || (!options_.gathers.empty() && !options_.gathers[size_t(f.triangle)])) {
    // nothing reflects, or the pixel's product holds direct light only
    for (int c = 0; c < 3; ++c) E[c] = std_error[c] = 0;
    return 0;
  }
  constexpr double kInvPi = std::numbers::inv_pi;
  const uint64_t seed = mix64(options_.seed ^ 0xb0b0b0b0b0b0b0b0ull);  // a rotation of its own: independent of E_direct
  const Frame frame0(f.n);
  const Vector3d o0 = f.p + epsilon_ * f.ng;
  const bake::NearTriangles near0 = rt_->near(o0);
  uint64_t rays = 0;
  replicate_mean_keyed(options_.samples, seed, index, [&](const std::array<double, 3>& u, uint32_t b, uint32_t i, double sum[3]) {
      PointStream rng(options_.seed, index, b, i);
      double throughput[3] = {1, 1, 1};
      Vector3d o = o0;
      Vector3d d = frame0.to_world(cosine_hemisphere(u[0], u[1])).normalized();
      std::optional<bake::NearTriangles> near_here;  // the current vertex's near triangles (after the first)
      for (uint32_t depth = 1; depth <= options_.bounces; ++depth) {
        ++rays;
        const auto hit = rt_->first_hit(o, near_here ? *near_here : near0, d);
        if (!hit || !hit->front) return;  // the sky (E_direct's), or a back face (black)
        const Fragment h = surface_fragment(mesh_, int32_t(hit->triangle),
                                            {float(1 - hit->w1 - hit->w2), float(hit->w1), float(hit->w2)});
        for (int c = 0; c < 3; ++c) throughput[c] *= reflectance(h.triangle, c);
        if (!(throughput[0] > 0 || throughput[1] > 0 || throughput[2] > 0)) return;
        // Next-event estimate of E_direct(h): one sample L V (n·ω) / p of the cosine + environment
        // mixture (½ each; bounded by 2π L as p ≥ (n·ω)/(2π)).
        o = h.p + epsilon_ * h.ng;
        near_here = rt_->near(o);
        const Frame frame(h.n);
        double Ed[3] = {0, 0, 0};
        const double s0 = rng.next(), s1 = rng.next(), s2 = rng.next();
        Vector3d l = (s0 < 0.5 ? frame.to_world(cosine_hemisphere(s1, s2)) : env_.sample(s1, s2, nullptr)).normalized();
        const double cn = h.n.dot(l);
        if (cn > 0) {
          ++rays;
          if (!rt_->occluded(o, *near_here, l)) {
            const double p = 0.5 * cn * kInvPi + 0.5 * env_.pdf(l);
            const Rgb L = env_.radiance(l);
            Ed[0] = L.r * cn / p;
            Ed[1] = L.g * cn / p;
            Ed[2] = L.b * cn / p;
          }
        }
        for (int c = 0; c < 3; ++c) sum[c] += throughput[c] * Ed[c];
        if (depth == options_.bounces) return;
        d = frame.to_world(cosine_hemisphere(rng.next(), rng.next())).normalized();
      }
    }, E, std_error);
  return rays;
}

void ReferenceRenderer::glossy(const Fragment& f, uint64_t index, double s, double out[3], double std_error[3]) const {
  PRT_CHECK(options_.glossy.has_value() && s >= 0);
  const Vector3d v = (options_.glossy->eye - f.p).normalized();
  Vector3d r = 2 * f.n.dot(v) * f.n - v;
  r = r.norm() > 0 ? Vector3d(r.normalized()) : f.n;
  const Vector3d o = f.p + epsilon_ * f.ng;
  const Frame lobe(r);
  const double k_norm = (s + 1) / (2 * std::numbers::pi);
  const auto k_s = [&](const Vector3d& d) { const double c = r.dot(d); return c > 0 ? k_norm * std::pow(c, s) : 0.0; };
  const bake::NearTriangles near_o = rt_->near(o);
  replicate_mean(options_.samples, options_.seed, index, [&](const std::array<double, 3>& u, double sum[3]) {
      Vector3d d;
      if (u[0] < 0.5) {  // the lobe: cos θ = u^(1/(s+1)) about r
        const double z = std::pow(std::max(u[1], 1e-300), 1 / (s + 1)), rho = std::sqrt(std::max(0.0, 1 - z * z));
        const double phi = 2 * std::numbers::pi * u[2];
        d = lobe.to_world(Vector3d(rho * std::cos(phi), rho * std::sin(phi), z));
      } else {
        d = env_.sample(u[1], u[2], nullptr);
      }
      d.normalize();
      const double k = k_s(d);
      if (!(f.n.dot(d) > 0) || !(k > 0) || (rt_->any_caster && rt_->occluded(o, near_o, d))) return;
      const double p = 0.5 * k + 0.5 * env_.pdf(d);
      const Rgb L = env_.radiance(d);
      sum[0] += L.r * k / p;
      sum[1] += L.g * k / p;
      sum[2] += L.b * k / p;
    }, out, std_error);
}

ReferenceImage ReferenceRenderer::render(const Camera& camera, const bake::Monitor& monitor) const {
  const auto t0 = std::chrono::steady_clock::now();
  ReferenceImage out;
  out.gbuffer = trace_primary(camera);
  out.radiance = Image(camera.width, camera.height);
  out.std_error = Image(camera.width, camera.height);
  // E_unocc once per distinct shading normal (every pixel of a plane shares one): the normals of
  // the covered pixels, sorted and made unique, evaluated in parallel.
  using Key = std::array<double, 3>;
  std::vector<Key> normals;
  for (int y = 0; y < camera.height && !options_.glossy; ++y)  // glossy mode needs no E_unocc
    for (int x = 0; x < camera.width; ++x)
      if (out.gbuffer.triangle[size_t(y) * size_t(camera.width) + size_t(x)] >= 0) {
        const Vector3d n = make_fragment(mesh_, out.gbuffer, x, y).n;
        normals.push_back({n.x(), n.y(), n.z()});
      }
  std::sort(normals.begin(), normals.end());
  normals.erase(std::unique(normals.begin(), normals.end()), normals.end());
  Task bar(monitor, "reference", uint64_t(normals.size()) + uint64_t(camera.height));
  std::vector<Rgb> unocc(normals.size());
  tbb::parallel_for(size_t(0), normals.size(), [&](size_t k) {
    unocc[k] = unoccluded_(Vector3d(normals[k][0], normals[k][1], normals[k][2]));
    bar.advance();
  });
  std::atomic<uint64_t> pixels{0};
  std::atomic<uint64_t> bounce_rays{0};
  tbb::parallel_for(0, camera.height, [&](int y) {
    uint64_t n = 0, path_rays = 0;
    for (int x = 0; x < camera.width; ++x) {
      const Fragment f = make_fragment(mesh_, out.gbuffer, x, y);
      if (f.triangle < 0) continue;
      if (options_.glossy) {
        const size_t t = size_t(f.triangle);
        const double s = options_.glossy->phong[t];
        double G[3] = {0, 0, 0}, se[3] = {0, 0, 0};
        if (s > 0) glossy(f, uint64_t(y) * uint64_t(camera.width) + uint64_t(x), s, G, se);
        for (int c = 0; c < 3; ++c) {
          const double spec = double(options_.glossy->specular[t][size_t(c)]);
          out.radiance.at(x, y)[c] = float(spec * G[c]);
          out.std_error.at(x, y)[c] = float(spec * se[c]);
        }
        ++n;
        continue;
      }
      const Key key{f.n.x(), f.n.y(), f.n.z()};
      const size_t k = size_t(std::lower_bound(normals.begin(), normals.end(), key) - normals.begin());
      double E[3], se[3];
      const uint64_t index = uint64_t(y) * uint64_t(camera.width) + uint64_t(x);
      irradiance(f, index, unocc[k], E, se);
      if (options_.bounces > 0) {
        double Ei[3], sei[3];
        path_rays += indirect(f, index, Ei, sei);
        for (int c = 0; c < 3; ++c) {
          E[c] += Ei[c];
          se[c] = std::sqrt(se[c] * se[c] + sei[c] * sei[c]);
        }
      }
      for (int c = 0; c < 3; ++c) {
        const double rho = albedo(f.triangle, c);
        out.radiance.at(x, y)[c] = float(rho * E[c] * std::numbers::inv_pi);
        out.std_error.at(x, y)[c] = float(rho * se[c] * std::numbers::inv_pi);
      }
      ++n;
    }
    pixels += n;
    bounce_rays += path_rays;
    bar.advance();
  });
  bar.finish();
  const uint32_t B = std::min<uint32_t>(kReplicates, options_.samples);
  out.rays = uint64_t(camera.width) * uint64_t(camera.height) +
             (rt_->any_caster ? pixels.load() * B * std::max<uint32_t>(1, options_.samples / B) : 0) + bounce_rays.load();
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  for (float v : out.radiance.rgb)
    if (!std::isfinite(v)) throw ContractError("reference render produced a non-finite value");
  return out;
}

// ---- reference cache -----------------------------------------------------------------------------------

namespace {
constexpr const char* kKeyAttr = "prt_reference_key";
constexpr uint32_t kNoTriangle = 0xFFFFFFFFu;
} // namespace

void save_reference(const std::filesystem::path& path, const ReferenceImage& image, const std::string& key) {
  const int W = image.radiance.width, H = image.radiance.height;
  PRT_CHECK(W > 0 && H > 0 && image.std_error.rgb.size() == image.radiance.rgb.size());
  PRT_CHECK_OP(image.gbuffer.triangle.size(), ==, size_t(W) * size_t(H));
  std::vector<uint32_t> tri(image.gbuffer.triangle.size());
  for (size_t i = 0; i < tri.size(); ++i) tri[i] = image.gbuffer.triangle[i] < 0 ? kNoTriangle : uint32_t(image.gbuffer.triangle[i]);
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    try {
      Imf::Header header(W, H);
      header.insert(kKeyAttr, Imf::StringAttribute(key));
      Imf::FrameBuffer fb;
      const char* names[6] = {"R", "G", "B", "se.R", "se.G", "se.B"};
      for (int c = 0; c < 6; ++c) {
        const Image& src = c < 3 ? image.radiance : image.std_error;
        header.channels().insert(names[c], Imf::Channel(Imf::FLOAT));
        fb.insert(names[c], Imf::Slice(Imf::FLOAT, const_cast<char*>(reinterpret_cast<const char*>(src.rgb.data() + c % 3)),
                                       3 * sizeof(float), 3 * sizeof(float) * size_t(W)));
      }
      header.channels().insert("triangle", Imf::Channel(Imf::UINT));
      fb.insert("triangle", Imf::Slice(Imf::UINT, reinterpret_cast<char*>(tri.data()), sizeof(uint32_t), sizeof(uint32_t) * size_t(W)));
      Imf::OutputFile out(tmp.c_str(), header, 1);
      out.setFrameBuffer(fb);
      out.writePixels(H);
    } catch (const Iex::BaseExc& e) {
      throw InputError(path.string(), std::string("cannot write the reference: ") + e.what());
    }
  });
}

std::optional<ReferenceImage> load_reference(const std::filesystem::path& path, const std::string& key) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return std::nullopt;
  try {
    Imf::InputFile in(path.c_str(), 1);
    const auto* k = in.header().findTypedAttribute<Imf::StringAttribute>(kKeyAttr);
    if (!k || k->value() != key) return std::nullopt;
    const Imath::Box2i dw = in.header().dataWindow();
    const int W = dw.max.x - dw.min.x + 1, H = dw.max.y - dw.min.y + 1;
    ReferenceImage r;
    r.radiance = Image(W, H);
    r.std_error = Image(W, H);
    std::vector<uint32_t> tri(size_t(W) * size_t(H), kNoTriangle);
    Imf::FrameBuffer fb;
    const char* names[6] = {"R", "G", "B", "se.R", "se.G", "se.B"};
    for (int c = 0; c < 6; ++c) {
      if (!in.header().channels().findChannel(names[c])) throw InputError(path.string(), std::string("no channel ") + names[c]);
      Image& dst = c < 3 ? r.radiance : r.std_error;
      char* base = reinterpret_cast<char*>(dst.rgb.data() + c % 3) -
                   (ptrdiff_t(dw.min.x) + ptrdiff_t(dw.min.y) * W) * ptrdiff_t(3 * sizeof(float));
      fb.insert(names[c], Imf::Slice(Imf::FLOAT, base, 3 * sizeof(float), 3 * sizeof(float) * size_t(W)));
    }
    if (!in.header().channels().findChannel("triangle")) throw InputError(path.string(), "no channel triangle");
    fb.insert("triangle", Imf::Slice(Imf::UINT,
                                     reinterpret_cast<char*>(tri.data()) - (ptrdiff_t(dw.min.x) + ptrdiff_t(dw.min.y) * W) *
                                                                               ptrdiff_t(sizeof(uint32_t)),
                                     sizeof(uint32_t), sizeof(uint32_t) * size_t(W)));
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
    r.gbuffer = GBuffer::blank(W, H);
    for (size_t i = 0; i < tri.size(); ++i) r.gbuffer.triangle[i] = tri[i] == kNoTriangle ? -1 : int32_t(tri[i]);
    for (float v : r.radiance.rgb)
      if (!std::isfinite(v)) throw InputError(path.string(), "non-finite pixel in the cached reference");
    return r;
  } catch (const Iex::BaseExc& e) {
    throw InputError(path.string(), std::string("cannot read the cached reference: ") + e.what());
  }
}

} // namespace prt::view
