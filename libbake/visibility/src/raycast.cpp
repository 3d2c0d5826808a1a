#include <bake/core/error.h>
#include <bake/visibility/contour.h>
#include <bake/visibility/raycast.h>

#include <embree3/rtcore.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <span>
#include <utility>
#include <string>
#include <vector>

namespace prt::bake {

using Eigen::Vector3d;

bool occludes_from_above(const Vector3d& p, const Vector3d& a, const Vector3d& b, const Vector3d& n,
                         const Vector3d& d, bool* ambiguous, const Vector3d* t) {
  const Vector3d e1 = a - p, e2 = b - p;
  const Vector3d m = e1.cross(e2);
  const double mm = m.squaredNorm();
  if (!(mm > 0)) return false;  // zero-area: no solid angle, blocks nothing
  const double md = m.dot(d), mn = m.dot(n);
  const double mlen = std::sqrt(mm);
  // Relative tolerance for "within rounding of the boundary" (only used to flag ambiguity).
  constexpr double kRel = 1e-9;
  if (ambiguous && std::abs(md) <= kRel * mlen) *ambiguous = true;
  if (md == 0) return false;    // ray parallel to the plane: a set of measure zero
  double s = -mn / md;
  Vector3d q = n + s * d;       // in the plane of the triangle, up to rounding
  if (mn == 0 && t) {
    // p + εn lies in the plane: the ray from p + εn + ε²t meets it at distance ε² (−m·t)/(m·d),
    // where the point, seen from p, is in direction n (to first order): blocked iff that
    // distance is positive and n lies in the triangle's cone.
    s = -m.dot(*t) / md;
    q = n;
  }
  if (!(s > 0)) return false;   // the plane is behind the ray (or through the limit point itself)
  // q = α e1 + β e2 with α = ((q × e2)·m)/|m|², β = ((e1 × q)·m)/|m|²; inside the cone iff α, β ≥ 0.
  const double alpha = q.cross(e2).dot(m), beta = e1.cross(q).dot(m);
  if (ambiguous) {
    const double scale = q.norm() * mlen;
    if (std::abs(alpha) <= kRel * scale * e2.norm() || std::abs(beta) <= kRel * scale * e1.norm()) *ambiguous = true;
  }
  return alpha >= 0 && beta >= 0;
}

namespace {
double squared_distance_to_segment(const Vector3d& p, const Vector3d& a, const Vector3d& b) {
  const Vector3d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).squaredNorm();
}
} // namespace

double squared_distance_to_triangle(const Vector3d& p, const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  if ((b - a).cross(c - a).squaredNorm() == 0)  // zero area: its three edges
    return std::min({squared_distance_to_segment(p, a, b), squared_distance_to_segment(p, b, c),
                     squared_distance_to_segment(p, c, a)});
  const Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return ap.squaredNorm();
  const Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return bp.squaredNorm();
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return squared_distance_to_segment(p, a, b);
  const Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return cp.squaredNorm();
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return squared_distance_to_segment(p, a, c);
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) return squared_distance_to_segment(p, b, c);
  const double denom = va + vb + vc;
  return (ap - (vb / denom) * ab - (vc / denom) * ac).squaredNorm();
}

namespace {

constexpr unsigned kMaxHits = 512;
struct Hit {
  unsigned prim;
  float t, u, v;
};

// The intersect context carries the shade point's welded id so the filter can drop its 1-ring,
// and, for counted rays, the list of hits (every hit is recorded and rejected so traversal goes on).
struct RingContext {
  RTCIntersectContext base;
  int64_t welded;
  const uint32_t* weld;  // output vertex -> welded id
  const std::array<uint32_t, 3>* triangles;
  std::span<const uint32_t> near;  // triangles decided exactly by the caller (ascending): skipped
  Hit* hits = nullptr;   // counted rays only
  unsigned n_hits = 0;
  bool overflow = false;
};

bool in_ring(const RingContext* ctx, unsigned prim) {
  if (ctx->welded < 0) return false;
  const auto& t = ctx->triangles[prim];
  const auto w = uint32_t(ctx->welded);
  return ctx->weld[t[0]] == w || ctx->weld[t[1]] == w || ctx->weld[t[2]] == w;
}

void ring_filter(const RTCFilterFunctionNArguments* args) {
  auto* ctx = reinterpret_cast<RingContext*>(args->context);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    const unsigned prim = RTCHitN_primID(args->hit, args->N, i);
    if (in_ring(ctx, prim) || std::binary_search(ctx->near.begin(), ctx->near.end(), prim)) {
      args->valid[i] = 0;
      continue;
    }
    if (ctx->hits) {  // counted ray: record and keep going
      if (ctx->n_hits < kMaxHits)
        ctx->hits[ctx->n_hits++] = {prim, RTCRayN_tfar(args->ray, args->N, i), RTCHitN_u(args->hit, args->N, i),
                                    RTCHitN_v(args->hit, args->N, i)};
      else
        ctx->overflow = true;
      args->valid[i] = 0;
    }
  }
}

void embree_error(void* user, RTCError code, const char* str) {
  auto* msg = static_cast<std::string*>(user);
  if (msg->empty()) *msg = "Embree error " + std::to_string(int(code)) + ": " + (str ? str : "");
}

} // namespace

struct RayCaster::Embree {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::string error;

  // Embree failures (no device, no memory for the BVH) are the machine's, not the input's:
  // SystemError. The constructor releases what it made before it throws, so nothing leaks.
  explicit Embree(const Mesh& mesh) {
    try {
      build(mesh);
    } catch (...) {
      release();
      throw;
    }
  }
  void build(const Mesh& mesh) {
    device = rtcNewDevice(nullptr);
    if (!device) throw SystemError("Embree: rtcNewDevice failed (error " +
                                   std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
    rtcSetDeviceErrorFunction(device, embree_error, &error);
    scene = rtcNewScene(device);
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    if (mesh.triangles.empty()) {  // nothing occludes (e.g. a scene with receivers only)
      rtcCommitScene(scene);
      if (!error.empty()) throw SystemError(error);
      return;
    }
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                          3 * sizeof(float), mesh.positions.size()));
    auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                               3 * sizeof(uint32_t), mesh.triangles.size()));
    if (!v || !idx) {
      rtcReleaseGeometry(geom);
      throw SystemError("Embree: cannot allocate geometry buffers: " + error);
    }
    for (size_t i = 0; i < mesh.positions.size(); ++i)
      for (int k = 0; k < 3; ++k) v[3 * i + k] = mesh.positions[i][k];
    for (size_t i = 0; i < mesh.triangles.size(); ++i)
      for (int k = 0; k < 3; ++k) idx[3 * i + k] = mesh.triangles[i][k];
    rtcSetGeometryOccludedFilterFunction(geom, ring_filter);
    rtcSetGeometryIntersectFilterFunction(geom, ring_filter);
    rtcCommitGeometry(geom);
    rtcAttachGeometry(scene, geom);
    rtcReleaseGeometry(geom);
    rtcCommitScene(scene);
    if (!error.empty()) throw SystemError(error);
  }
  ~Embree() { release(); }
  void release() noexcept {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
    scene = nullptr;
    device = nullptr;
  }
};

RayCaster::RayCaster(const Mesh& mesh, const Topology& topology)
    : mesh_(mesh), topo_(topology), rt_(std::make_unique<Embree>(mesh)) {
  PRT_CHECK_OP(topology.weld.size(), ==, mesh.positions.size());
  Eigen::Vector3d lo = Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const auto& q : mesh.positions) {
    lo = lo.cwiseMin(q.cast<double>());
    hi = hi.cwiseMax(q.cast<double>());
  }
  diagonal_ = mesh.positions.empty() ? 0.0 : (hi - lo).norm();
  centre_ = mesh.positions.empty() ? Vector3d::Zero() : Vector3d(0.5 * (lo + hi));
}

RayCaster::~RayCaster() = default;

namespace {
RTCRay make_ray(const Vector3d& o, const Vector3d& d) {
  RTCRay ray{};
  ray.org_x = float(o.x());
  ray.org_y = float(o.y());
  ray.org_z = float(o.z());
  ray.dir_x = float(d.x());
  ray.dir_y = float(d.y());
  ray.dir_z = float(d.z());
  ray.tnear = 0.0f;
  ray.tfar = std::numeric_limits<float>::infinity();
  ray.mask = 0xFFFFFFFFu;
  ray.flags = 0;
  return ray;
}
// Point query: every triangle (not in the shade point's 1-ring) whose bounds meet the query ball.
struct NearQuery {
  int64_t welded = -1;
  const uint32_t* weld = nullptr;
  const std::array<uint32_t, 3>* triangles = nullptr;
  std::vector<unsigned> prims;
};

bool collect_near(RTCPointQueryFunctionArguments* args) {
  auto* q = static_cast<NearQuery*>(args->userPtr);
  const unsigned prim = args->primID;
  if (q->welded >= 0) {
    const auto& t = q->triangles[prim];
    const auto w = uint32_t(q->welded);
    if (q->weld[t[0]] == w || q->weld[t[1]] == w || q->weld[t[2]] == w) return false;
  }
  q->prims.push_back(prim);
  return false;  // the query radius is unchanged
}

// Corner k of triangle t is the shade point's welded position: the other two corners, in winding
// order, or nullopt when no corner (or two corners) are the shade point's.
std::optional<std::pair<Vector3d, Vector3d>> ring_far_corners(const Mesh& mesh, const Topology& topo, uint32_t f,
                                                              uint32_t w) {
  const auto& t = mesh.triangles[f];
  int k = 0;  // rotate the corners so that corner k is the shade point's
  while (k < 3 && topo.weld[t[k]] != w) ++k;
  if (k == 3) return std::nullopt;
  // A triangle with two corners welded to the shade point has no area seen from it.
  if (topo.weld[t[(k + 1) % 3]] == w || topo.weld[t[(k + 2) % 3]] == w) return std::nullopt;
  return std::pair{Vector3d(mesh.positions[t[(k + 1) % 3]].cast<double>()),
                   Vector3d(mesh.positions[t[(k + 2) % 3]].cast<double>())};
}

// Whether the segment from p + εn (ε → 0+) to r crosses the triangle (a, b, c), decided with
// exact predicates: Miss, Cross, or Edge when the answer is on a null set (the segment meets an
// edge or a corner exactly, or r lies in the triangle's plane).
enum class SegmentCrossing { Miss, Cross, Edge };
SegmentCrossing crosses_exactly(const NearTriangles::Test& t, const ShadePoint& point, const Vector3d& r) {
  const int sr = orient3d_exact(t.a, t.b, t.c, r);
  if (sr == 0) return SegmentCrossing::Edge;      // the far end lies in the plane
  if (t.side == sr) return SegmentCrossing::Miss;  // the segment does not reach the plane
  const Vector3d* tb = tie_break(point);
  const int s1 = orient_eps(t.a, t.b, r, point.p, point.n, tb), s2 = orient_eps(t.b, t.c, r, point.p, point.n, tb),
            s3 = orient_eps(t.c, t.a, r, point.p, point.n, tb);
  const bool has_pos = s1 > 0 || s2 > 0 || s3 > 0, has_neg = s1 < 0 || s2 < 0 || s3 < 0;
  if (has_pos && has_neg) return SegmentCrossing::Miss;  // outside the triangle
  if (s1 == 0 || s2 == 0 || s3 == 0) return SegmentCrossing::Edge;  // through an edge or a corner exactly
  return SegmentCrossing::Cross;
}

// A triangle of the shade point's 1-ring, (p, a, b), against the ray in direction d: the float test
// (occludes_from_above) decides when it is clear; when it is within its own rounding of flipping
// (d grazes the cone, the plane nearly contains n, or p + εn lies in the plane and the first-order
// point sits on the cone's edge: a wall standing on the face along n), the same segment test as
// the near triangles decides exactly, in the ε and ε² limits (orient_eps). Edge: the direction
// lies on the triangle's boundary as seen from the limit point (a null set).
SegmentCrossing ring_crossing(const ShadePoint& point, const Vector3d& a, const Vector3d& b, const Vector3d& d,
                              double reach) {
  bool ambiguous = false;
  const bool blocks = occludes_from_above(point.p, a, b, point.n, d, &ambiguous, tie_break(point));
  if (!ambiguous) return blocks ? SegmentCrossing::Cross : SegmentCrossing::Miss;
  const NearTriangles::Test test{point.p, a, b, orient_eps(point.p, a, b, point.p, point.n, tie_break(point)), 0};
  if (test.side == 0) return SegmentCrossing::Miss;  // no area seen from the limit point
  return crosses_exactly(test, point, point.p + reach * d);
}

} // namespace

NearTriangles RayCaster::near_triangles(const ShadePoint& point) const {
  NearTriangles near;
  near.rho = 2e-4 * std::max(diagonal_, 1e-30) + 2e-6 * point.p.cwiseAbs().maxCoeff();
  NearQuery query;
  query.welded = point.welded;
  query.weld = topo_.weld.data();
  query.triangles = mesh_.triangles.data();
  RTCPointQuery q{};
  q.x = float(point.p.x());
  q.y = float(point.p.y());
  q.z = float(point.p.z());
  q.time = 0;
  q.radius = float(near.rho);
  RTCPointQueryContext qctx;
  rtcInitPointQueryContext(&qctx);
  rtcPointQuery(rt_->scene, &q, &qctx, collect_near, &query);
  std::sort(query.prims.begin(), query.prims.end());
  query.prims.erase(std::unique(query.prims.begin(), query.prims.end()), query.prims.end());
  // The point query returns triangles whose bounding boxes meet the ball; keep those within rho
  // (with a relative margin for the distance's own rounding: a few more is harmless).
  const double keep = near.rho * near.rho * (1 + 1e-9);
  for (const unsigned prim : query.prims) {
    const auto& t = mesh_.triangles[prim];
    NearTriangles::Test test{mesh_.positions[t[0]].cast<double>(), mesh_.positions[t[1]].cast<double>(),
                             mesh_.positions[t[2]].cast<double>(), 0, prim};
    if (!(squared_distance_to_triangle(point.p, test.a, test.b, test.c) <= keep)) continue;
    near.prims.push_back(prim);
    // side 0: a degenerate triangle, or p + εn in its plane: no area to cross, but Embree must
    // still skip it (it would report it at t = 0).
    test.side = orient_eps(test.a, test.b, test.c, point.p, point.n, tie_break(point));
    if (test.side != 0) near.tests.push_back(test);
  }
  return near;
}

double RayCaster::reach(const ShadePoint& point) const { return 4 * (diagonal_ + (point.p - centre_).norm()) + 1; }

bool RayCaster::visible(const ShadePoint& point, const Vector3d& d) const {
  return visible(point, near_triangles(point), d);
}

double RayCaster::exact_blocker(const ShadePoint& point, const NearTriangles& near, const Vector3d& d, bool any) const {
  if (point.welded >= 0) {
    const auto w = uint32_t(point.welded);
    const double reach_ = reach(point);
    // Edge (a null set of directions) does not block, as for the near triangles below.
    for (uint32_t f : topo_.ring(w))
      if (const auto ab = ring_far_corners(mesh_, topo_, f, w);
          ab && ring_crossing(point, ab->first, ab->second, d, reach_) == SegmentCrossing::Cross)
        return 0.0;  // through p itself
  }
  double first = std::numeric_limits<double>::infinity();
  if (!near.tests.empty()) {
    const Vector3d r = point.p + reach(point) * d;
    // Edge (a null set of directions) does not block: the neighbour across that edge decides.
    for (const NearTriangles::Test& t : near.tests)
      if (crosses_exactly(t, point, r) == SegmentCrossing::Cross) {
        if (any) return 0.0;
        const Vector3d m = (t.b - t.a).cross(t.c - t.a);
        first = std::min(first, std::max(0.0, m.dot(t.a - point.p) / m.dot(d)));  // m·d ≠ 0: it is crossed
      }
  }
  return first;
}

namespace {
RingContext ring_context(const ShadePoint& point, const NearTriangles& near, const uint32_t* weld,
                         const std::array<uint32_t, 3>* triangles) {
  RingContext ctx;
  rtcInitIntersectContext(&ctx.base);
  ctx.welded = point.welded;
  ctx.weld = weld;
  ctx.triangles = triangles;
  ctx.near = near.prims;
  return ctx;
}
} // namespace

bool RayCaster::visible(const ShadePoint& point, const NearTriangles& near, const Vector3d& d) const {
  if (blocked_nearby(point, near, d)) return false;
  RingContext ctx = ring_context(point, near, topo_.weld.data(), mesh_.triangles.data());
  RTCRay ray = make_ray(point.p, d);
  rtcOccluded1(rt_->scene, &ctx.base, &ray);
  return ray.tfar >= 0.0f;  // Embree sets tfar = -inf on a hit
}

std::optional<double> RayCaster::first_hit(const ShadePoint& point, const NearTriangles& near, const Vector3d& d) const {
  double first = exact_blocker(point, near, d, false);
  if (first == 0.0) return first;
  RingContext ctx = ring_context(point, near, topo_.weld.data(), mesh_.triangles.data());
  RTCRayHit rh{};
  rh.ray = make_ray(point.p, d);
  if (first < std::numeric_limits<double>::infinity()) rh.ray.tfar = float(first);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(rt_->scene, &ctx.base, &rh);
  if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) first = std::min(first, double(rh.ray.tfar));
  if (first == std::numeric_limits<double>::infinity()) return std::nullopt;
  return first;
}

std::optional<SurfaceHit> RayCaster::first_surface_hit(const ShadePoint& point, const NearTriangles& near,
                                                       const Vector3d& d) const {
  auto face_normal = [&](uint32_t f) {
    const auto& t = mesh_.triangles[f];
    const Vector3d a = mesh_.positions[t[0]].cast<double>();
    return Vector3d((mesh_.positions[t[1]].cast<double>() - a).cross(mesh_.positions[t[2]].cast<double>() - a));
  };
  if (point.welded >= 0) {  // the 1-ring: blocked at p itself
    const auto w = uint32_t(point.welded);
    const double reach_ = reach(point);
    for (uint32_t f : topo_.ring(w))
      if (const auto ab = ring_far_corners(mesh_, topo_, f, w);
          ab && ring_crossing(point, ab->first, ab->second, d, reach_) == SegmentCrossing::Cross) {
        const auto& t = mesh_.triangles[f];
        const int k = topo_.weld[t[0]] == w ? 0 : topo_.weld[t[1]] == w ? 1 : 2;
        return SurfaceHit{f, k == 1 ? 1.0 : 0.0, k == 2 ? 1.0 : 0.0, face_normal(f).dot(d) < 0};
      }
  }
  // The near triangles, decided exactly; the nearest crossing in double.
  double first = std::numeric_limits<double>::infinity();
  const NearTriangles::Test* nearest = nullptr;
  if (!near.tests.empty()) {
    const Vector3d r = point.p + reach(point) * d;
    for (const NearTriangles::Test& t : near.tests)
      if (crosses_exactly(t, point, r) == SegmentCrossing::Cross) {
        const Vector3d m = (t.b - t.a).cross(t.c - t.a);
        const double s = std::max(0.0, m.dot(t.a - point.p) / m.dot(d));
        if (s < first) first = s, nearest = &t;
      }
  }
  RingContext ctx = ring_context(point, near, topo_.weld.data(), mesh_.triangles.data());
  RTCRayHit rh{};
  rh.ray = make_ray(point.p, d);
  if (nearest) rh.ray.tfar = float(first);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(rt_->scene, &ctx.base, &rh);
  if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID && !(nearest && double(rh.ray.tfar) >= first)) {
    const double w1 = std::clamp(double(rh.hit.u), 0.0, 1.0), w2 = std::clamp(double(rh.hit.v), 0.0, 1.0 - w1);
    return SurfaceHit{rh.hit.primID, w1, w2, face_normal(rh.hit.primID).dot(d) < 0};
  }
  if (!nearest) return std::nullopt;
  // The point where the ray meets the near triangle's plane, as weights of its corners (areas of
  // the sub-triangles against the normal), clamped to the triangle: it was crossed exactly.
  const NearTriangles::Test& t = *nearest;
  const Vector3d q = point.p + first * d, m = (t.b - t.a).cross(t.c - t.a);
  const double mm = m.squaredNorm();
  double w1 = std::max(0.0, (q - t.a).cross(t.c - t.a).dot(m) / mm);  // q = a + w1 (b − a) + w2 (c − a)
  double w2 = std::max(0.0, (t.b - t.a).cross(q - t.a).dot(m) / mm);
  if (w1 + w2 > 1) {
    const double sum = w1 + w2;
    w1 /= sum;
    w2 /= sum;
  }
  return SurfaceHit{t.prim, w1, w2, m.dot(d) < 0};
}

bool RayCaster::occluded(const Vector3d& origin, const Vector3d& d, double tnear, double tfar) const {
  RingContext ctx;
  rtcInitIntersectContext(&ctx.base);
  ctx.welded = -1;
  ctx.weld = topo_.weld.data();
  ctx.triangles = mesh_.triangles.data();
  RTCRay ray = make_ray(origin, d);
  ray.tnear = float(tnear);
  ray.tfar = float(tfar);
  rtcOccluded1(rt_->scene, &ctx.base, &ray);
  return !(ray.tfar >= 0.0f);  // Embree sets tfar = -inf on a hit
}

std::optional<RayHit> RayCaster::closest_hit(const Vector3d& origin, const Vector3d& d, double tnear) const {
  RingContext ctx;
  rtcInitIntersectContext(&ctx.base);
  ctx.welded = -1;
  ctx.weld = topo_.weld.data();
  ctx.triangles = mesh_.triangles.data();
  RTCRayHit rh{};
  rh.ray = make_ray(origin, d);
  rh.ray.tnear = float(tnear);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(rt_->scene, &ctx.base, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
  return RayHit{rh.hit.primID, rh.ray.tfar, rh.hit.u, rh.hit.v};
}

CrossingCount RayCaster::count_crossings(const ShadePoint& point, const Vector3d& d) const {
  CrossingCount out;
  const double reach_ = reach(point);
  if (point.welded >= 0) {
    const auto w = uint32_t(point.welded);
    for (uint32_t f : topo_.ring(w)) {
      const auto ab = ring_far_corners(mesh_, topo_, f, w);
      if (!ab) continue;
      switch (ring_crossing(point, ab->first, ab->second, d, reach_)) {
        case SegmentCrossing::Miss: break;
        case SegmentCrossing::Edge: out.ambiguous = true; break;  // choose another direction
        case SegmentCrossing::Cross: ++out.count; break;
      }
    }
  }
  // Triangles within ρ of p are decided exactly for the whole ray (below): near p, float hit tests
  // cannot tell which of two adjacent triangles a ray enters — e.g. at a vertex a few ulps from
  // another surface's vertex (near-duplicate shells, T-junctions), where every direction grazes
  // that vertex's fan. Everything farther is left to Embree, with edge grazes flagged ambiguous.
  // The ray is the segment from p + εn to a point r beyond the scene: its exact predicates are
  // those of that segment, whatever rounding r carries.
  const NearTriangles near = near_triangles(point);
  const Vector3d r = point.p + reach_ * d;
  for (const NearTriangles::Test& t : near.tests) {
    switch (crosses_exactly(t, point, r)) {
      case SegmentCrossing::Miss: break;
      case SegmentCrossing::Edge: out.ambiguous = true; break;  // choose another direction
      case SegmentCrossing::Cross: ++out.count; break;
    }
  }

  Hit hits[kMaxHits];
  RingContext ctx;
  rtcInitIntersectContext(&ctx.base);
  ctx.welded = point.welded;
  ctx.weld = topo_.weld.data();
  ctx.triangles = mesh_.triangles.data();
  ctx.near = near.prims;
  ctx.hits = hits;
  RTCRayHit rh{};
  rh.ray = make_ray(point.p, d);
  rh.ray.tfar = float(reach_);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(rt_->scene, &ctx.base, &rh);
  if (ctx.overflow) out.ambiguous = true;
  constexpr float kEdge = 1e-5f;  // barycentric distance to an edge that makes a hit ambiguous
  for (unsigned i = 0; i < ctx.n_hits; ++i) {
    const Hit& h = hits[i];  // triangles near p were skipped by the filter: decided exactly above
    const float w0 = 1.0f - h.u - h.v;
    if (h.u < kEdge || h.v < kEdge || w0 < kEdge) out.ambiguous = true;
    ++out.count;
  }
  return out;
}

} // namespace prt::bake
