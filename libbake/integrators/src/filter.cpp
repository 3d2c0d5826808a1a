// filter.cpp — the sheared-filter integrator (bake/integrators/filter.h; paper 002 §4-5, Algorithm 1).
#include <bake/core/error.h>
#include <bake/integrators/filter.h>
#include <bake/integrators/qmc.h>
#include <bake/sphere/zonal.h>

#include <prtshade/quadrature.h>
#include <prtshade/sh.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <sstream>
#include <utility>

namespace prt::bake {

using Eigen::Vector3d;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = std::numbers::pi;
constexpr double kMinNormalCos = 0.9063077870366499;  // cos 25°: neighbours' normals within 25° of n
constexpr double kMaxPlaneSlope = 0.3;                // |(q − p)·n| ≤ 0.3 |q − p|: no depth discontinuity
constexpr int kSpacingNeighbours = 6;                 // local vertex spacing: mean distance to 6 nearest
constexpr double kContactSpacings = 0.5;             // an own ray blocked nearer than d/2: contact
// Directions probed per cell for contact: the centre and four points near the corners.
constexpr std::pair<double, double> kCellProbes[] = {{0.5, 0.5}, {0.02, 0.02}, {0.02, 0.98}, {0.98, 0.02}, {0.98, 0.98}};
// A brute-forced cell in which the neighbours' samples saw both sky and occluder holds a visibility
// edge: it gets this many times the fallback rays (one binary ray there is most of the noise).
constexpr uint32_t kEdgeFallbackFactor = 4;
constexpr uint64_t kFallbackSalt = 0x66616c6c6261636bull;

// ---- a k-d tree over the prepared points (implicit: the median of each range splits it) ------
class PointTree {
public:
  PointTree() = default;
  explicit PointTree(std::vector<Vector3d> points) : pts_(std::move(points)), idx_(pts_.size()), dim_(pts_.size()) {
    for (size_t i = 0; i < idx_.size(); ++i) idx_[i] = uint32_t(i);
    build(0, idx_.size());
  }
  // visit(i) for every point within r of c (|p_i − c|² ≤ r²), in a fixed order.
  template <class Visit> void within(const Vector3d& c, double r, Visit&& visit) const {
    within(0, idx_.size(), c, r, r * r, visit);
  }
  // Mean distance from c to its k nearest points at a distance > 0 (0 when there are none).
  double mean_nearest(const Vector3d& c, int k) const {
    std::vector<double> best;  // squared distances, a max-heap of at most k
    nearest(0, idx_.size(), c, size_t(k), best);
    double s = 0;
    for (double d2 : best) s += std::sqrt(d2);
    return best.empty() ? 0.0 : s / double(best.size());
  }

private:
  void build(size_t lo, size_t hi) {
    if (hi - lo <= 1) return;
    Vector3d a = Vector3d::Constant(kInf), b = -a;
    for (size_t i = lo; i < hi; ++i) {
      a = a.cwiseMin(pts_[idx_[i]]);
      b = b.cwiseMax(pts_[idx_[i]]);
    }
    int dim = 0;
    (b - a).maxCoeff(&dim);
    const size_t mid = (lo + hi) / 2;
    std::nth_element(idx_.begin() + ptrdiff_t(lo), idx_.begin() + ptrdiff_t(mid), idx_.begin() + ptrdiff_t(hi),
                     [&](uint32_t x, uint32_t y) { return pts_[x][dim] < pts_[y][dim] || (pts_[x][dim] == pts_[y][dim] && x < y); });
    dim_[mid] = uint8_t(dim);
    build(lo, mid);
    build(mid + 1, hi);
  }
  template <class Visit>
  void within(size_t lo, size_t hi, const Vector3d& c, double r, double r2, Visit& visit) const {
    if (lo >= hi) return;
    const size_t mid = (lo + hi) / 2;
    const Vector3d& p = pts_[idx_[mid]];
    const double delta = hi - lo > 1 ? c[dim_[mid]] - p[dim_[mid]] : 0.0;
    if (delta <= r) within(lo, mid, c, r, r2, visit);
    if ((p - c).squaredNorm() <= r2) visit(idx_[mid]);
    if (delta >= -r) within(mid + 1, hi, c, r, r2, visit);
  }
  void nearest(size_t lo, size_t hi, const Vector3d& c, size_t k, std::vector<double>& best) const {
    if (lo >= hi) return;
    const size_t mid = (lo + hi) / 2;
    const Vector3d& p = pts_[idx_[mid]];
    const double d2 = (p - c).squaredNorm();
    if (d2 > 0 && (best.size() < k || d2 < best.front())) {
      if (best.size() == k) {
        std::pop_heap(best.begin(), best.end());
        best.pop_back();
      }
      best.push_back(d2);
      std::push_heap(best.begin(), best.end());
    }
    if (hi - lo == 1) return;
    const double delta = c[dim_[mid]] - p[dim_[mid]];
    const bool left_first = delta <= 0;
    nearest(left_first ? lo : mid + 1, left_first ? mid : hi, c, k, best);
    if (best.size() < k || delta * delta < best.front()) nearest(left_first ? mid + 1 : lo, left_first ? hi : mid, c, k, best);
  }

  std::vector<Vector3d> pts_;
  std::vector<uint32_t> idx_;
  std::vector<uint8_t> dim_;
};

} // namespace

// ---- cells ----------------------------------------------------------------------------------

int HemisphereCells::cell_of(const Vector3d& local) {
  static_assert(kSectors == 8, "the sectors below are the eight octants of the azimuth");
  const double x = local.x(), y = local.y();
  const double s2 = x * x + y * y;  // sin²θ
  const int ring = std::clamp(int(s2 * kRings), 0, kRings - 1);
  // The sector floor(φ / 45°), φ = atan2(y, x) in [0, 360°), by exact comparisons instead of atan2
  // (atan2 was ~40% of integrate()'s time on dense texels: it bins every neighbour sample): the
  // half plane by y's sign, the quadrant by x's, the octant by |y| against |x|. A direction on
  // a boundary goes to the sector that starts there; on the +x axis and at the pole (x = y = 0)
  // to sector 0, on the −x axis to sector 4, as atan2 put them.
  int sector;
  if (y == 0) sector = x < 0 ? 4 : 0;
  else if (y > 0) sector = x > 0 ? (y < x ? 0 : 1) : (y > -x ? 2 : 3);
  else sector = x < 0 ? (-y < -x ? 4 : 5) : (-y > x ? 6 : 7);
  return ring * kSectors + sector;
}

Vector3d HemisphereCells::direction(int c, double u0, double u1) {
  const double s2 = (c / kSectors + u0) / kRings, phi = 2 * kPi * (c % kSectors + u1) / kSectors;
  const double s = std::sqrt(s2);
  return {s * std::cos(phi), s * std::sin(phi), std::sqrt(std::max(0.0, 1 - s2))};
}

double HemisphereCells::solid_angle(int c) {
  const int ring = c / kSectors;
  return (2 * kPi / kSectors) * (std::sqrt(1 - double(ring) / kRings) - std::sqrt(1 - double(ring + 1) / kRings));
}

CellIntegrals::CellIntegrals(const ProductLayout& layout) : layout_(layout) {
  width_ = layout.ao_count + layout.transfer_count + layout.visibility_count;
  sh_order_ = int(std::lround(std::sqrt(double(std::max(layout.transfer_count, layout.visibility_count)))));
  PRT_CHECK_OP(sh_order_, <=, sh::kMaxOrder);
  values_.assign(size_t(HemisphereCells::kCount) * width_, 0.0);
  // ∫_c f dω = ∫∫ f sinθ dθ dφ over the cell: Gauss–Legendre in θ and φ (f sinθ is analytic in
  // both, so 24 nodes each are exact to rounding for the orders prtshade supports at l ≲ 12).
  constexpr int kNodes = 24;
  std::vector<double> tx, tw, px, pw, y(size_t(sh::num_coeffs(std::max(sh_order_, 1)))), f(width_);
  for (int c = 0; c < HemisphereCells::kCount; ++c) {
    const int ring = c / HemisphereCells::kSectors, sector = c % HemisphereCells::kSectors;
    shade::gauss_legendre(kNodes, std::asin(std::sqrt(double(ring) / HemisphereCells::kRings)),
                   std::asin(std::sqrt(double(ring + 1) / HemisphereCells::kRings)), tx, tw);
    shade::gauss_legendre(kNodes, 2 * kPi * sector / HemisphereCells::kSectors,
                   2 * kPi * (sector + 1) / HemisphereCells::kSectors, px, pw);
    const std::span<double> cell = std::span(values_).subspan(size_t(c) * width_, width_);
    for (int i = 0; i < kNodes; ++i)
      for (int j = 0; j < kNodes; ++j) {
        const double st = std::sin(tx[size_t(i)]);
        const Vector3d v(st * std::cos(px[size_t(j)]), st * std::sin(px[size_t(j)]), std::cos(tx[size_t(i)]));
        integrands(Vector3d::UnitZ(), v, y, f);
        for (size_t k = 0; k < width_; ++k) cell[k] += tw[size_t(i)] * pw[size_t(j)] * st * f[k];
      }
    if (layout.ao_count) cell[0] = 1.0 / HemisphereCells::kCount;  // equal projected area: exactly 1/64
  }
}

void CellIntegrals::integrands(const Vector3d& n, const Vector3d& v, std::span<double> y, std::span<double> out) const {
  const double c = n.dot(v);
  if (sh_order_ > 0) sh::eval(sh_order_, v.x(), v.y(), v.z(), y);
  size_t k = 0;
  if (layout_.ao_count) out[k++] = c / kPi;
  for (size_t i = 0; i < layout_.transfer_count; ++i) out[k++] = c * y[i] / kPi;
  for (size_t i = 0; i < layout_.visibility_count; ++i) out[k++] = y[i];
}

void CellIntegrals::to_world(const Frame& frame, std::span<const double> local_sum, std::span<double> out) const {
  const size_t ao = layout_.ao_count;
  if (ao) out[0] = local_sum[0];  // rotation invariant
  if (sh_order_ == 0) return;
  const double R[3][3] = {{frame.t.x(), frame.b.x(), frame.n.x()},
                          {frame.t.y(), frame.b.y(), frame.n.y()},
                          {frame.t.z(), frame.b.z(), frame.n.z()}};
  const sh::Rotation rotation(R, sh_order_);
  const size_t full = size_t(sh::num_coeffs(sh_order_));
  std::vector<double> in(full), rotated(full);
  size_t offset = ao;
  for (const size_t count : {layout_.transfer_count, layout_.visibility_count}) {
    if (!count) continue;
    std::fill(in.begin(), in.end(), 0.0);
    std::copy_n(local_sum.begin() + ptrdiff_t(offset), count, in.begin());
    rotation.apply(in, rotated);
    std::copy_n(rotated.begin(), count, out.begin() + ptrdiff_t(offset));
    offset += count;
  }
}

// ---- the integrator -------------------------------------------------------------------------

struct FilterIntegrator::Prepared {
  std::vector<ShadePoint> points;
  PointTree tree;
  std::unique_ptr<std::once_flag[]> once;
  std::vector<Sample> samples;  // [point][rays]
};

FilterIntegrator::FilterIntegrator(const Mesh& mesh, const Topology& topology, const ProductRequest& request,
                                   const FilterOptions& options, const MeshAccel* accel)
    : layout_(request), options_(options), cells_(layout_) {
  PRT_CHECK(options.rays > 0);
  PRT_CHECK(options.fallback_rays > 0);
  PRT_CHECK(options.radius_factor >= 0 && options.omega_v > 0 && options.min_weight > 0);
  PRT_CHECK_OP(topology.weld.size(), ==, mesh.positions.size());
  PRT_CHECK(!accel || accel->of(mesh, topology));
  rays_ = accel ? accel->rays() : std::make_shared<const RayCaster>(mesh, topology);
  if (request.radiance || request.shadowed_order > 0) {  // R and S: [R | S] as in layout_
    ProductRequest r;
    r.radiance = request.radiance;
    r.shadowed = request.shadowed;
    r.shadowed_order = request.shadowed_order;
    radiance_ = std::make_unique<QmcIntegrator>(mesh, topology, r, QmcOptions{options.radiance_rays, options.seed}, accel);
  }
}

FilterIntegrator::~FilterIntegrator() = default;

std::string FilterIntegrator::description() const {
  std::ostringstream os;
  os << "sheared-filter sparse ray tracing (Egan et al. 2011), " << options_.rays << " pass-1 rays/point, seed "
     << options_.seed << ", search radius " << options_.radius_factor << " vertex spacings, 8x8 cells, "
     << options_.fallback_rays << " ray(s) per brute-forced cell";
  if (radiance_)
    os << "; " << (!layout_.shadowed_count ? "band-1" : layout_.radiance_count ? "band-1 and shadowed" : "shadowed")
       << " radiance by QMC, " << options_.radiance_rays << " rays/point (HDR environments break the filter's band limit)";
  return os.str();
}

void FilterIntegrator::prepare(std::span<const ShadePoint> points) const {
  // The same points again (a sharded bake prepares once per chunk of rows, bake/bake/vertex_bake.h
  // bake_point_rows): keep the tree and the pass-1 rays already traced.
  const auto same = [](const ShadePoint& a, const ShadePoint& b) {
    return a.p == b.p && a.n == b.n && a.t == b.t && a.welded == b.welded && a.hemisphere == b.hemisphere;
  };
  if (prepared_ && std::equal(points.begin(), points.end(), prepared_->points.begin(), prepared_->points.end(), same)) return;
  auto p = std::make_unique<Prepared>();
  p->points.assign(points.begin(), points.end());
  std::vector<Vector3d> positions(points.size());
  for (size_t i = 0; i < points.size(); ++i) positions[i] = points[i].p;
  p->tree = PointTree(std::move(positions));
  p->once = std::make_unique<std::once_flag[]>(points.size());
  p->samples.resize(points.size() * options_.rays);
  prepared_ = std::move(p);
}

std::span<const FilterIntegrator::Sample> FilterIntegrator::pass1(uint64_t index) const {
  const std::span<Sample> out = std::span(prepared_->samples).subspan(index * options_.rays, options_.rays);
  std::call_once(prepared_->once[index], [&] {
    const ShadePoint& point = prepared_->points[index];
    const Frame frame(point.n);
    const RotatedHalton3 halton(options_.seed, index);
    const NearTriangles near = rays_->near_triangles(point);
    for (uint32_t i = 0; i < options_.rays; ++i) {
      const auto u = halton(i);
      const Vector3d d = frame.to_world(cosine_hemisphere(u[1], u[2])).normalized();
      const std::optional<double> t = rays_->first_hit(point, near, d);
      out[i] = {{float(d.x()), float(d.y()), float(d.z())}, t ? float(*t) : std::numeric_limits<float>::infinity()};
    }
    pass1_rays_.fetch_add(options_.rays, std::memory_order_relaxed);
  });
  return out;
}

Vector3d FilterIntegrator::fallback_direction(uint64_t point_index, int cell, uint32_t i) const {
  const auto u = RotatedHalton3(mix64(options_.seed ^ kFallbackSalt), point_index * HemisphereCells::kCount + uint64_t(cell))(i);
  return HemisphereCells::direction(cell, u[0], u[1]);
}

double FilterIntegrator::spacing(uint64_t index) const {
  return prepared_->tree.mean_nearest(prepared_->points[index].p, kSpacingNeighbours);
}

namespace {
// A cell's running sums over its samples (weights w, visibility V ∈ {0,1}, integrands f).
struct CellSums {
  double w = 0, wv = 0;
  std::span<double> wvf, wf;  // [width]
  void add(double weight, bool visible, std::span<const double> f) {
    w += weight;
    for (size_t k = 0; k < f.size(); ++k) wf[k] += weight * f[k];
    if (!visible) return;
    wv += weight;
    for (size_t k = 0; k < f.size(); ++k) wvf[k] += weight * f[k];
  }
  void clear() {
    w = wv = 0;
    std::fill(wvf.begin(), wvf.end(), 0.0);
    std::fill(wf.begin(), wf.end(), 0.0);
  }
};
} // namespace

void FilterIntegrator::integrate(const ShadePoint& point, uint64_t point_index, std::span<double> out,
                                 std::span<double> std_error) const {
  PRT_CHECK_OP(out.size(), >=, layout_.width);
  PRT_CHECK(point.hemisphere);  // hemisphere products only (bake/integrators/filter.h)
  constexpr int C = HemisphereCells::kCount;
  const size_t W = cells_.width();
  const Vector3d& p = point.p;
  const Vector3d& n = point.n;
  const Frame frame(n);
  std::vector<double> y(size_t(sh::num_coeffs(std::max(cells_.sh_order(), 1)))), f(W);
  std::vector<double> store(2 * size_t(C) * W, 0.0);
  std::array<CellSums, C> sums;
  for (int c = 0; c < C; ++c) {
    sums[size_t(c)].wvf = std::span(store).subspan(2 * size_t(c) * W, W);
    sums[size_t(c)].wf = std::span(store).subspan((2 * size_t(c) + 1) * W, W);
  }
  std::array<bool, C> brute;
  brute.fill(true);
  std::array<uint32_t, C> counts{};  // samples with a non-zero filter weight per cell
  std::array<uint8_t, C> seen{};     // per cell: 1 a sample escaped, 2 a sample met an occluder
  uint64_t n_neighbours = 0;

  std::optional<NearTriangles> near;  // computed when needed
  const Prepared* prep = prepared_.get();
  const bool prepared = prep && point_index < prep->points.size() && prep->points[point_index].p == p &&
                        prep->points[point_index].n == n;
  if (!prepared) unprepared_.fetch_add(1, std::memory_order_relaxed);
  const bool filtering = prepared && options_.radius_factor > 0;
  if (filtering) {
    brute.fill(false);
    // Neighbours (bake/integrators/filter.h): within radius_factor · d, similar normal, no depth discontinuity.
    const double d = spacing(point_index), search = options_.radius_factor * d;
    std::vector<uint32_t> neighbours;
    prep->tree.within(p, search, [&](uint32_t q) {
      const ShadePoint& sq = prep->points[q];
      const Vector3d e = sq.p - p;
      if (q == point_index || (sq.n.dot(n) >= kMinNormalCos && std::abs(e.dot(n)) <= kMaxPlaneSlope * e.norm()))
        neighbours.push_back(q);
    });
    n_neighbours = neighbours.size();
    auto local_cell = [&](const Vector3d& v) {
      return HemisphereCells::cell_of(Vector3d(frame.t.dot(v), frame.b.dot(v), n.dot(v)));
    };
    // An occluded sample's effective direction and depth: from p to its hit point (the receiver's
    // own samples: the ray itself). False when the hit is not above p's horizon.
    auto hit_direction = [&](uint32_t q, const Sample& s, Vector3d& v, double& z) {
      const Vector3d dir(s.d[0], s.d[1], s.d[2]);
      const Vector3d e = q == point_index ? Vector3d(double(s.t) * dir) : Vector3d(prep->points[q].p + double(s.t) * dir - p);
      z = e.norm();
      v = z > 0 ? Vector3d(e / z) : dir;
      return n.dot(v) > 0;
    };
    // Algorithm 1 lines 1-14: per-cell depth bounds from the occluded samples' hit points.
    std::array<double, C> zmin, zmax, radius_c, mid;
    zmin.fill(kInf);
    zmax.fill(0.0);
    for (const uint32_t q : neighbours)
      for (const Sample& s : pass1(q)) {
        Vector3d v;
        double z;
        if (!std::isfinite(s.t) || !hit_direction(q, s, v, z)) continue;
        const size_t c = size_t(local_cell(v));
        zmin[c] = std::min(zmin[c], z);
        zmax[c] = std::max(zmax[c], z);
      }
    // The nearest occluder p's own rays met: a cell in which no sample met an occluder may still
    // hold one that near (a vertex in a slot sees the far wall with its own rays; its neighbours
    // outside the slot see the sky), so that cell's radius is eq. 8 for [z_near, ∞] (below).
    double z_near = kInf;
    for (const Sample& s : pass1(point_index)) z_near = std::min(z_near, double(s.t));
    // A receiver whose own rays met an occluder at distance ~0 (its 1-ring or a near triangle: a
    // crease, a contact, a face lying on it) sits where its neighbours' rays cannot speak for it:
    // every cell in which those triangles block the centre or a corner direction is brute-forced.
    if (z_near < kContactSpacings * d) {
      near = rays_->near_triangles(point);
      for (int c = 0; c < C; ++c)
        for (const auto& [u0, u1] : kCellProbes)
          if (rays_->blocked_nearby(point, *near, frame.to_world(HemisphereCells::direction(c, u0, u1)).normalized())) {
            zmin[size_t(c)] = 0;
            break;
          }
    }
    // Eq. 8 (Ω_pix = 0.5/d): the spatial radius; eq. 9: the mid depth (harmonic mean); §3.3: too
    // close an occluder (Ω_v / z_min > Ω_pix) brute-forces the cell.
    const double omega_pix = d > 0 ? 0.5 / d : kInf;
    for (size_t c = 0; c < size_t(C); ++c) {
      radius_c[c] = mid[c] = kInf;  // no occluder seen: its escaped rays at infinity
      if (zmin[c] == kInf) {
        radius_c[c] = z_near / options_.omega_v;
        continue;
      }
      brute[c] = options_.omega_v / zmin[c] > omega_pix;
      const double spread = 1 / zmin[c] - 1 / zmax[c];
      if (spread > 0) radius_c[c] = 1 / (options_.omega_v * spread);
      mid[c] = 2 / (1 / zmin[c] + 1 / zmax[c]);
    }
    // Algorithm 1 lines 15-35: target point, effective direction v, offset x, weight.
    for (const uint32_t q : neighbours) {
      const Vector3d o = prep->points[q].p - p;  // the sample's origin, relative to p
      for (const Sample& s : pass1(q)) {
        const Vector3d dir(s.d[0], s.d[1], s.d[2]);
        const bool occluded = std::isfinite(s.t);
        Vector3d v = dir;
        double x = 0;
        if (occluded) {
          double z;
          if (!hit_direction(q, s, v, z)) continue;
        } else {
          if (!(n.dot(dir) > 0)) continue;
          const int c0 = local_cell(dir);
          if (q != point_index && std::isfinite(mid[size_t(c0)])) {
            // The plane at the cell's mid depth, perpendicular to its centre direction (§5).
            const Vector3d centre = frame.to_world(HemisphereCells::direction(c0, 0.5, 0.5));
            const double dc = dir.dot(centre), sd = (mid[size_t(c0)] - o.dot(centre)) / dc;
            if (dc > 0 && sd > 0) {
              const Vector3d e = o + sd * dir;
              if (!(n.dot(e) > 0)) continue;
              v = e.normalized();
            }
          }
        }
        if (q != point_index) {
          // x: from p to where the ray meets the plane through p perpendicular to v (§4, Fig. 6b).
          const double dv = dir.dot(v);
          if (!(dv > 0)) continue;
          x = (o - (o.dot(v) / dv) * dir).norm();
        }
        const size_t c = size_t(local_cell(v));
        seen[c] |= occluded ? 2 : 1;
        if (brute[c]) continue;
        const double r = x / radius_c[c];
        if (!(r < 1)) continue;
        const double w = (1 - r * r) * (1 - r * r);
        cells_.integrands(n, v, y, f);
        sums[c].add(w, !occluded, f);
        ++counts[c];
      }
    }
    for (size_t c = 0; c < size_t(C); ++c) brute[c] = brute[c] || sums[c].w < options_.min_weight;
  }

  // Brute-forced cells (§5): fallback_rays stratified rays in the cell, distributed as (n·ω), or
  // kEdgeFallbackFactor times as many where the neighbours' samples saw a visibility edge.
  uint64_t n_brute = 0, n_filtered = 0, n_fallback = 0;
  for (int c = 0; c < C; ++c) {
    if (!brute[size_t(c)]) {
      n_filtered += counts[size_t(c)];
      continue;
    }
    ++n_brute;
    if (!near) near = rays_->near_triangles(point);
    CellSums& cell = sums[size_t(c)];
    cell.clear();
    const uint32_t m = seen[size_t(c)] == 3 ? kEdgeFallbackFactor * options_.fallback_rays : options_.fallback_rays;
    n_fallback += m;
    for (uint32_t i = 0; i < m; ++i) {
      const Vector3d v = frame.to_world(fallback_direction(point_index, c, i)).normalized();
      cells_.integrands(n, v, y, f);
      cell.add(1.0, rays_->visible(point, *near, v), f);
    }
  }
  // When filtering, the receiver's own pass-1 rays that fell in a brute-forced cell are samples of
  // it too (unbiased: the receiver's own rays need no filter): they join the cell's fallback rays.
  if (filtering)
    for (const Sample& s : pass1(point_index)) {
      const Vector3d v(s.d[0], s.d[1], s.d[2]);
      const int c = HemisphereCells::cell_of(Vector3d(frame.t.dot(v), frame.b.dot(v), n.dot(v)));
      if (!brute[size_t(c)]) continue;
      cells_.integrands(n, v, y, f);
      sums[size_t(c)].add(1.0, !std::isfinite(s.t), f);
    }

  // ∫_c V f ≈ ν_c F_c + Ω_c (mean(V f) − ν_c mean(f)) (bake/integrators/filter.h), Σ_c ν_c F_c rotated once.
  std::vector<double> local(W, 0.0), world(W, 0.0);
  for (int c = 0; c < C; ++c) {
    const CellSums& cell = sums[size_t(c)];
    const double nu = cell.wv / cell.w;
    const std::span<const double> F = cells_.local(c);
    for (size_t k = 0; k < W; ++k) local[k] += nu * F[k];
  }
  cells_.to_world(frame, local, world);
  for (int c = 0; c < C; ++c) {
    const CellSums& cell = sums[size_t(c)];
    const double nu = cell.wv / cell.w, omega = HemisphereCells::solid_angle(c);
    for (size_t k = 0; k < W; ++k) world[k] += omega * (cell.wvf[k] / cell.w - nu * (cell.wf[k] / cell.w));
  }
  std::copy(world.begin(), world.end(), out.begin());
  if (radiance_) {
    std::vector<double> rad(radiance_->layout().width);
    radiance_->integrate(point, point_index, rad);
    std::copy(rad.begin(), rad.end(), out.begin() + ptrdiff_t(layout_.radiance));
  }
  if (!std_error.empty()) std::fill_n(std_error.begin(), layout_.width, 0.0);
  points_.fetch_add(1, std::memory_order_relaxed);
  cells_total_.fetch_add(C, std::memory_order_relaxed);
  brute_cells_.fetch_add(n_brute, std::memory_order_relaxed);
  fallback_rays_.fetch_add(n_fallback, std::memory_order_relaxed);
  neighbours_.fetch_add(n_neighbours, std::memory_order_relaxed);
  filtered_samples_.fetch_add(n_filtered, std::memory_order_relaxed);
}

FilterStats FilterIntegrator::filter_stats() const {
  FilterStats s;
  s.points = points_.load();
  s.pass1_rays = pass1_rays_.load();
  s.fallback_rays = fallback_rays_.load();
  s.cells = cells_total_.load();
  s.brute_cells = brute_cells_.load();
  s.unprepared = unprepared_.load();
  s.neighbours = neighbours_.load();
  s.filtered_samples = filtered_samples_.load();
  return s;
}

std::string FilterIntegrator::work_summary() const {
  const FilterStats s = filter_stats();
  const double points = double(std::max<uint64_t>(s.points, 1));
  std::ostringstream os;
  os.setf(std::ios::fixed);
  os.precision(1);
  os << "per point " << s.rays_per_point() << " rays (" << double(s.pass1_rays) / points << " pass-1 + "
     << double(s.fallback_rays) / points << " fallback); " << 100 * s.brute_fraction()
     << "% of cells brute-forced; " << s.neighbours_per_point() << " neighbours, " << s.samples_per_filtered_cell()
     << " samples per filtered cell";
  if (s.unprepared) os << "; " << s.unprepared << " points unprepared";
  return os.str();
}

} // namespace prt::bake
