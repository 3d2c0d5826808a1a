// The silhouette integrator (paper 001 §3). See bake/integrators/silhouette.h for the conventions; the
// stages are: contour edges (bake/visibility/contour.h) → arcs in the octahedral frame → crossings with
// the u-isolines, bucketed per isoline, and with the spine → W at the spine start from one
// counted ray → DCF walk along every isoline loop with summed-area tables (bake/sphere/isoline_tables.h).
#include <bake/core/error.h>
#include <bake/environment/envmap.h>
#include <bake/integrators/hot_texels.h>
#include <bake/integrators/silhouette.h>
#include <bake/sphere/isoline_tables.h>
#include <bake/sphere/octahedral.h>
#include <bake/sphere/sampling.h>
#include <bake/sphere/zonal.h>
#include <bake/visibility/contour.h>
#include <bake/visibility/raycast.h>

#include <prtshade/sh.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <map>
#include <mutex>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <functional>
#include <limits>
#include <sstream>

namespace prt::bake {

using Eigen::Vector3d;

namespace {

// The octahedral frame is the world frame turned by a fixed, generic rotation, so that scenes
// built on the world axes (axis-aligned boxes, ground planes, walls) never put their edges on
// the octahedral seams or the spine, where crossings would be decided by ties.
Eigen::Matrix3d octahedral_frame_from_world() {
  return Eigen::AngleAxisd(0.7236, Vector3d(0.3141, 0.5926, 0.7418).normalized()).toRotationMatrix();
}

inline int sign_of(double x) { return x > 0 ? 1 : x < 0 ? -1 : 0; }

// Exactly whether a, b and p are collinear: coplanar with each of three points spanning space
// about p (whatever rounding they carry, they are not coplanar with p unless a, b, p are collinear).
bool collinear_exactly(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Vector3d& p) {
  const Vector3d A = a.cast<double>(), B = b.cast<double>();
  for (int k = 0; k < 3; ++k)
    if (orient3d_exact(A, B, p, p + Vector3d::Unit(k)) != 0) return false;
  return true;
}

// Endpoints (unnormalised, frame coordinates), m = a × b, and S = side_sum: the step across the
// arc is sign(m · t) · S for travel direction t (bake/integrators/hot_texels.h).
using Arc = DcfArc;
struct Crossing {
  int iso;
  double t;
  int step;
};
struct SpineCrossing {
  double u;
  int step;
};

struct Scratch {
  std::vector<ContourEdge> edges;
  // The contour edges' end vertices, each once (prepare_edges): its direction from the shade
  // point in the world and the octahedral frame, and the union-find of the components below the
  // horizon; node_of maps a welded id to its node (-1: none; reset after each point). ends[i]
  // are edges[i]'s nodes. The dropped edges (with their ends) and their arcs, built only for the
  // start ray's correction.
  struct Node {
    Vector3d v, f;  // p → vertex (−n for the point's own vertex), world; the same in the frame
    uint32_t welded;
    bool at_p;  // the vertex is at p: the point's own (welded) vertex, or one a free point lies on
  };
  std::vector<Node> nodes;
  std::vector<uint32_t> parent, size;  // union-find over nodes (by size, path halving)
  std::vector<uint8_t> below;          // per node; per root: the whole component
  std::vector<std::array<uint32_t, 2>> ends, dropped_ends;
  std::vector<int32_t> node_of;
  std::vector<ContourEdge> dropped;
  std::vector<Arc> dropped_arcs;
  std::vector<Arc> arcs;
  std::vector<Crossing> crossings, sorted;
  std::vector<SpineCrossing> spine;
  std::vector<uint32_t> bucket_start;
  std::vector<double> acc, hot_moments;
};
thread_local Scratch tl_scratch;

} // namespace

struct SilhouetteEnvCache::Impl {
  // The key: the map (its address and its midpoints', which copies share) and the columns.
  const EnvMap* map = nullptr;
  const void* map_data = nullptr;
  int env_order = 0, shadowed_order = 0;
  size_t n_env = 0;
  bool radiance = false, keyed = false;
  bool hot_known = false;
  std::shared_ptr<const HotTexels> hot;
  struct Masses {
    struct Block {
      std::vector<Eigen::Vector3d> directions;
      std::vector<double> values;
    };
    std::vector<Block> blocks;
    bool complete = false;
  } masses;

  // Whether this cache serves (map, columns); the first caller keys it.
  bool fits(const EnvMap* m, int order, size_t n, bool rad, int ls) {
    const void* data = m && m->texel_count() > 0 ? static_cast<const void*>(m->texel_midpoints().data()) : nullptr;
    if (!keyed) {
      map = m, map_data = data, env_order = order, n_env = n, radiance = rad, shadowed_order = ls, keyed = true;
      return true;
    }
    return map == m && map_data == data && env_order == order && n_env == n && radiance == rad && shadowed_order == ls;
  }
};

SilhouetteEnvCache::SilhouetteEnvCache() : impl_(std::make_unique<Impl>()) {}
SilhouetteEnvCache::~SilhouetteEnvCache() = default;

struct SilhouetteIntegrator::Impl {
  const Mesh& mesh;
  const Topology& topo;
  ProductRequest req;
  ProductLayout layout;
  SilhouetteOptions opt;
  std::shared_ptr<const ContourFinder> contours_owned;  // shared with a MeshAccel, or our own
  std::shared_ptr<const RayCaster> rays_owned;
  const ContourFinder& contours;
  const RayCaster& rays;
  oct::Grid grid;
  Eigen::Matrix3d frame_from_world;
  int sh_order = 0;
  // Columns of the tables: [AO n-moments (3) | T (3·Lt²) | U (Lv²) | R (9) | S (3·Ls²)]. The
  // environment's columns R and S are the last n_env = F − c_r: the hot texels add to exactly
  // those, and the closed form's horizon-only walk yields them.
  size_t c_ao = 0, c_t = 0, c_u = 0, c_r = 0, c_s = 0, F = 0, n_env = 0;
  const EnvMap* envmap = nullptr;  // of R and S
  int env_order = 0;            // SH order the environment's columns need
  int subsamples = 1;             // per cell, of the smooth columns (the midpoint rule)
  int max_texel_subsamples = 0;   // k × k per texel of the environment's point masses (0: none)
  SilhouetteEnvCache::Impl::Masses* filling = nullptr;  // the cache this construction fills
  bool masses_from_cache = false;
  std::unique_ptr<IsolineTables> tables;
  // Hot texels of the environment (≥ kHotFactor × the mean luminance, at most kMaxHot of them):
  // left out of the tables and integrated exactly over their visible part (bake/integrators/hot_texels.h), so
  // that suns cut by a shadow edge or by the horizon carry no discretisation error at any N.
  static constexpr double kHotFactor = 64;
  static constexpr size_t kMaxHot = 4096;
  std::shared_ptr<const HotTexels> hot;
  std::vector<double> unoccluded_row;  // the layout's row with V ≡ 1 (full sphere), fixed by the tables

  mutable std::atomic<uint64_t> n_points{0}, n_edges{0}, n_crossings{0}, n_rays{0}, n_retries{0}, n_inconsistent{0},
      n_closed_form{0}, n_enclosed{0}, n_culled{0};
  // R and S of the unoccluded hemisphere about n (the n_env environment columns), per distinct
  // normal (bit pattern): the one environment-dependent part of the closed form (see closed_form()).
  mutable std::mutex hemisphere_mutex;
  mutable std::map<std::array<double, 3>, std::vector<double>> hemisphere_radiance_cache;
  mutable std::atomic<int64_t> contour_ns{0}, integrate_ns{0};

  Impl(const Mesh& m, const Topology& t, const ProductRequest& r, const SilhouetteOptions& o, const MeshAccel* accel)
      : mesh(m), topo(t), req(r), layout(r), opt(o),
        contours_owned(accel ? accel->contours() : std::make_shared<const ContourFinder>(m, t)),
        rays_owned(accel ? accel->rays() : std::make_shared<const RayCaster>(m, t)), contours(*contours_owned),
        rays(*rays_owned), grid(even_isolines(o.isolines)),
        frame_from_world(octahedral_frame_from_world()) {
    PRT_CHECK(!accel || accel->of(m, t));
    PRT_CHECK(r.consistent());
    const int lt = r.transfer_order, lv = r.visibility_order, ls = r.shadowed_order;
    envmap = r.environment();
    env_order = std::max(r.radiance ? 2 : 0, ls);
    sh_order = std::max({lt, lv, env_order});
    c_ao = 0;
    c_t = c_ao + (r.ao ? 3 : 0);
    c_u = c_t + size_t(3 * lt * lt);
    c_r = c_u + size_t(lv * lv);
    c_s = c_r + (r.radiance ? 9 : 0);
    F = c_s + size_t(3 * ls * ls);
    n_env = F - c_r;
    PRT_CHECK(F > 0);
    const Eigen::Matrix3d world_from_frame = frame_from_world.transpose();
    // The pilot's shared part (SilhouetteEnvCache), when it was filled for this map and these columns.
    SilhouetteEnvCache::Impl* cache = o.env_cache ? &o.env_cache->impl() : nullptr;
    if (cache && !cache->fits(envmap, env_order, n_env, r.radiance, ls)) cache = nullptr;
    if (envmap && envmap->texel_count() > 0 && env_order > 0) {
      if (cache && cache->hot_known) {
        hot = cache->hot;
      } else {
        auto made = std::make_shared<const HotTexels>(*envmap, frame_from_world, env_order, kHotFactor, kMaxHot);
        if (!made->empty()) hot = std::move(made);
        if (cache) cache->hot = hot, cache->hot_known = true;
      }
    }
    // The SH basis at w up to `order` in `small` (orders ≤ 16) or `big`.
    auto eval_sh = [](int order, const Vector3d& w, std::span<double> small, std::vector<double>& big) -> double* {
      double* yp = small.data();
      if (size_t(sh::num_coeffs(order)) > small.size()) {
        big.resize(size_t(sh::num_coeffs(order)));
        yp = big.data();
      }
      if (order > 0) sh::eval(order, w.x(), w.y(), w.z(), std::span(yp, size_t(sh::num_coeffs(order))));
      return yp;
    };
    // The environment's columns (n_env of them, R then S) for radiance L at w, basis yp.
    auto env_columns = [&](const Rgb& L, const double* yp, double* out) {
      const double rgb[3] = {L.r, L.g, L.b};
      if (r.radiance)
        for (int c = 0; c < 3; ++c)
          for (int mm = 0; mm < 3; ++mm) out[size_t(3 * c + mm)] = rgb[c] * yp[1 + mm];
      const size_t ns = size_t(ls * ls);
      double* s_out = out + (c_s - c_r);
      for (int c = 0; c < 3; ++c)
        for (size_t i = 0; i < ns; ++i) s_out[size_t(c) * ns + i] = rgb[c] * yp[i];
    };
    // A map's texels enter the tables as point masses (bake/sphere/isoline_tables.h): texel t's
    // value × its exact solid angle Ω_t, spread evenly over k × k stratified sub-samples of it
    // (EnvMap::sample_texel_grid), each weighing L_t · Ω_t / k² · y(ω). k ≈ 2 sub-samples per mean
    // cell width (√(4π)/N) across the texel, at least 1: where cells are wider than texels a mass
    // sits within half a texel of its share, where they are narrower it spreads over the cells the
    // texel covers. The hot texels are left out exactly (their own integral, hot_texels.h); a
    // constant environment is smooth and stays in f.
    IsolineTables::PointMasses masses;
    if (envmap && envmap->texel_count() > 0 && n_env > 0) {
      const int texels = envmap->texel_count();
      const double cells_per_radian = double(grid.n) / std::sqrt(4 * std::numbers::pi);
      auto subsamples_of = [cells_per_radian](double omega) {
        return std::clamp(int(std::ceil(2.0 * std::sqrt(omega) * cells_per_radian)), 1, 16);
      };
      max_texel_subsamples = 1;
      for (int tx = 0; tx < texels; ++tx)
        max_texel_subsamples = std::max(max_texel_subsamples, subsamples_of(envmap->texel_solid_angle(tx)));
      // Blocks of at most ~16,384 masses (a wave of 4 blocks holds them at once, IsolineTables:
      // ≤ 4 · 16,384 · (24 + 8·n_env) bytes, 20 MiB with S of order 3), fixed by N and the map alone.
      const int block_texels = std::clamp(16384 / (max_texel_subsamples * max_texel_subsamples), 1, 4096);
      masses.first = int(c_r), masses.count = int(n_env);
      masses.blocks = size_t((texels + block_texels - 1) / block_texels);
      // One sub-sample per texel: the masses of every such level are the same; the cache's, when
      // it holds them, else this level's, kept for the next when they fit.
      SilhouetteEnvCache::Impl::Masses* shared_masses = nullptr;
      if (cache && max_texel_subsamples == 1) {
        if (cache->masses.complete && cache->masses.blocks.size() == masses.blocks) {
          const auto* held = &cache->masses;
          masses_from_cache = true;
          masses.view = [held](size_t b, std::span<const Vector3d>& d, std::span<const double>& v) {
            d = held->blocks[b].directions, v = held->blocks[b].values;
            return true;
          };
        } else if (!cache->masses.complete &&
                   size_t(texels) * (sizeof(Vector3d) + n_env * sizeof(double)) <= SilhouetteEnvCache::kMaxBytes) {
          shared_masses = &cache->masses;
          shared_masses->blocks.assign(masses.blocks, {});
        }
      }
      const std::span<const Vector3d> midpoints = envmap->texel_midpoints();
      masses.emit = [&, texels, block_texels, subsamples_of, midpoints](size_t b, std::vector<Vector3d>& directions,
                                                                       std::vector<double>& values) {
        std::vector<Vector3d> dirs;
        std::vector<double> y(size_t(sh::num_coeffs(16))), ybig;
        const int t_end = std::min(texels, int(b + 1) * block_texels);
        const size_t most = size_t(t_end - int(b) * block_texels) * size_t(max_texel_subsamples * max_texel_subsamples);
        directions.reserve(directions.size() + most);  // no reallocation while the block fills
        values.reserve(values.size() + most * n_env);
        for (int tx = int(b) * block_texels; tx < t_end; ++tx) {
          if (hot && hot->is_hot(tx)) continue;
          const Rgb L = envmap->texel_value(tx);
          if (L.r == 0 && L.g == 0 && L.b == 0) continue;
          const double omega = envmap->texel_solid_angle(tx);
          const int k = subsamples_of(omega);
          const double w = omega / double(k * k);
          dirs.resize(size_t(k * k));
          if (k == 1) dirs[0] = midpoints[size_t(tx)];  // the same values, computed once per map
          else envmap->sample_texel_grid(tx, k, dirs);
          const Rgb mass{L.r * w, L.g * w, L.b * w};
          size_t at = values.size();
          values.resize(at + dirs.size() * n_env);
          for (const Vector3d& d : dirs) {
            env_columns(mass, eval_sh(env_order, d, y, ybig), values.data() + at);
            at += n_env;
            directions.push_back(frame_from_world * d);
          }
        }
      };
      if (shared_masses) {
        // Emitted straight into the cache's slots (each block its own) and read from there.
        filling = shared_masses;
        masses.view = [emit = masses.emit, shared_masses](size_t b, std::span<const Vector3d>& d,
                                                           std::span<const double>& v) {
          auto& slot = shared_masses->blocks[b];
          emit(b, slot.directions, slot.values);
          d = slot.directions, v = slot.values;
          return true;
        };
      }
    }
    tables = std::make_unique<IsolineTables>(grid, int(F), subsamples, [&](const Vector3d& w_frame, std::span<double> out) {
      const Vector3d w = world_from_frame * w_frame;
      double y[sh::num_coeffs(16)];
      std::vector<double> ybig;
      const double* yp = eval_sh(sh_order, w, y, ybig);
      constexpr double kInvPi = std::numbers::inv_pi;
      if (req.ao)
        for (int a = 0; a < 3; ++a) out[c_ao + size_t(a)] = w[a] * kInvPi;
      const size_t nt = size_t(lt * lt);
      for (int a = 0; a < 3; ++a)
        for (size_t i = 0; i < nt; ++i) out[c_t + size_t(a) * nt + i] = w[a] * yp[i] * kInvPi;
      for (size_t i = 0; i < size_t(lv * lv); ++i) out[c_u + i] = yp[i];
      if (envmap && envmap->texel_count() == 0) env_columns(envmap->radiance(w), yp, &out[c_r]);  // constant: smooth
    }, masses.count > 0 ? &masses : nullptr);
    if (filling) filling->complete = true, filling = nullptr;  // every block emitted; the cache is not ours
    unoccluded_row = unoccluded_totals();
  }

  // Σ_i h · (loop total of isoline i) over both grids, mapped to the layout (visibility and
  // radiance rows; the n-dependent AO/transfer rows stay 0).
  std::vector<double> unoccluded_totals() const {
    std::vector<double> acc(F, 0.0), row(layout.width, 0.0);
    for (int i = 0; i < grid.n; ++i) {
      const double* total = tables->loop_total(i);
      for (size_t c = 0; c < F; ++c) acc[c] += total[c] * grid.h;
    }
    if (hot) add_hot_moments(hot->unoccluded().data(), acc.data());
    for (size_t k = 0; k < layout.visibility_count; ++k) row[layout.visibility + k] = acc[c_u + k];
    for (size_t k = 0; k < layout.radiance_count; ++k) row[layout.radiance + k] = acc[c_r + k];
    for (size_t k = 0; k < layout.shadowed_count; ++k) row[layout.shadowed + k] = acc[c_s + k];
    return row;
  }

  static int even_isolines(int n) {
    PRT_CHECK(n >= 2);
    return n + (n & 1);
  }

  // Crossings of one arc with isolines [i_begin, i_end) of grid g, per octant piece.
  static void add_arc(const Arc& arc, const oct::Grid& g, int i_begin, int i_end, std::vector<Crossing>& out) {
    if (arc.m.squaredNorm() == 0 || arc.side_sum == 0) return;
    // Most arcs of a fine mesh lie in one octant (no coordinate changes sign: one piece below)
    // and between two neighbouring isolines. Their u range in isoline units, t = (u + 1)/h − ½,
    // computed here with rounding far below the margin of 1e-6, holds no integer: then the piece's
    // own first_at_or_after(umin) ≥ umax's and it adds nothing; leave before the general path.
    if ((arc.a.x() < 0) == (arc.b.x() < 0) && (arc.a.y() < 0) == (arc.b.y() < 0) && (arc.a.z() < 0) == (arc.b.z() < 0)) {
      const double sa = std::abs(arc.a.x()) + std::abs(arc.a.y()) + std::abs(arc.a.z());
      const double sb = std::abs(arc.b.x()) + std::abs(arc.b.y()) + std::abs(arc.b.z());
      if (sa > 0 && sb > 0) {
        const double half_n = 0.5 * g.n;
        const double ta = (arc.a.x() / sa + 1) * half_n - 0.5, tb = (arc.b.x() / sb + 1) * half_n - 0.5;
        const double lo = std::min(ta, tb) - 1e-6, hi = std::max(ta, tb) + 1e-6;
        if (lo > -2 && hi < g.n + 1 && oct::ceil_int(lo) >= hi) return;
      }
    }
    const Vector3d d = arc.b - arc.a;
    double lam[5] = {0, 1, 1, 1, 1};
    int nl = 1;
    for (int c = 0; c < 3; ++c)
      if ((arc.a[c] < 0) != (arc.b[c] < 0)) lam[nl++] = arc.a[c] / (arc.a[c] - arc.b[c]);  // sgn0 differs
    lam[nl++] = 1.0;
    for (int k = 1; k < nl; ++k)  // insertion sort of ≤ 5 values
      for (int j = k; j > 0 && lam[j] < lam[j - 1]; --j) std::swap(lam[j], lam[j - 1]);
    for (int k = 0; k + 1 < nl; ++k) {
      if (!(lam[k + 1] > lam[k])) continue;
      const Vector3d xa = arc.a + lam[k] * d, xb = arc.a + lam[k + 1] * d;
      const Vector3d mid = arc.a + (0.5 * (lam[k] + lam[k + 1])) * d;
      const Vector3d sg(oct::sgn0(mid.x()), oct::sgn0(mid.y()), oct::sgn0(mid.z()));
      const double da = sg.dot(xa), db = sg.dot(xb);
      if (!(da > 0) || !(db > 0)) continue;  // a piece through the origin (edge through p): no extent
      const double ua = xa.x() / da, ub = xb.x() / db;
      if (ua == ub) continue;  // parallel to the isolines: crosses none
      const double umin = std::min(ua, ub), umax = std::max(ua, ub);
      const int i0 = std::max(g.first_at_or_after(umin), i_begin), i1 = std::min(g.first_at_or_after(umax), i_end);
      if (i0 >= i1) continue;  // most pieces of a fine mesh cross no isoline: v only when one does
      const int sheet = sg.z() > 0 ? 0 : 1;
      const double va = xa.y() / da, vb = xb.y() / db;
      const double slope = (vb - va) / (ub - ua);
      for (int i = i0; i < i1; ++i) {
        const double l = g.half_length(i);
        const double v = std::clamp(va + (g.u(i) - ua) * slope, -l, l);
        const int step = sign_of(arc.m.dot(oct::Grid::loop_tangent(v, sheet))) * arc.side_sum;
        if (step != 0) out.push_back({i, g.t_of(i, v, sheet), step});
      }
    }
  }

  // Crossing of one arc with the spine (z = 0, y < 0).
  static void add_spine(const Arc& arc, std::vector<SpineCrossing>& out) {
    if (arc.m.squaredNorm() == 0 || arc.side_sum == 0) return;
    if (oct::sgn0(arc.a.z()) == oct::sgn0(arc.b.z())) return;
    const double l = arc.a.z() / (arc.a.z() - arc.b.z());
    const Vector3d x = arc.a + l * (arc.b - arc.a);
    if (!(x.y() < 0)) return;
    const double u = x.x() / (std::abs(x.x()) + std::abs(x.y()));
    const int step = sign_of(arc.m.dot(oct::spine_tangent(u))) * arc.side_sum;
    if (step != 0) out.push_back({u, step});
  }

  // Crossings of one isoline in walk order: by t, then by step (crossings equal in both are
  // interchangeable, so any sort gives the same walk). Buckets are short: insertion sort, which
  // moves elements one by one (std::sort's short runs go through memmove).
  static void sort_along_loop(Crossing* b0, Crossing* b1) {
    const auto before = [](const Crossing& x, const Crossing& y) { return x.t < y.t || (x.t == y.t && x.step < y.step); };
    if (b1 - b0 > 32) {
      std::sort(b0, b1, before);
      return;
    }
    for (Crossing* c = b0 + 1; c < b1; ++c) {
      const Crossing x = *c;
      Crossing* j = c;
      for (; j > b0 && before(x, j[-1]); --j) *j = j[-1];
      *j = x;
    }
  }

  // The DCF walk over isolines [i_begin, i_end) of grid g: W at each loop start comes from the
  // sorted spine crossings; runs with W = 0 add C(t_end) − C(t_start) of `tables`.
  template <class Tables>
  static uint64_t walk(const oct::Grid& g, int i_begin, int i_end, const Tables& tables, int W0,
                       const std::vector<SpineCrossing>& spine, std::vector<Crossing>& crossings,
                       std::vector<Crossing>& sorted, std::vector<uint32_t>& start, double* acc, size_t F) {
    // Counting sort by isoline: counts at start[i + 2], prefix sums, then start[i + 1] as the
    // fill cursor of isoline i, which leaves isoline i's crossings in [start[i], start[i + 1]).
    const int n = i_end - i_begin;
    start.assign(size_t(n) + 2, 0);
    for (const Crossing& c : crossings) ++start[size_t(c.iso - i_begin) + 2];
    for (int i = 0; i < n; ++i) start[size_t(i) + 2] += start[size_t(i) + 1];
    sorted.resize(crossings.size());
    for (const Crossing& c : crossings) sorted[start[size_t(c.iso - i_begin) + 1]++] = c;
    int W = W0;
    size_t sp = 0;
    uint64_t inconsistent = 0;
    for (int i = i_begin; i < i_end; ++i) {
      const double ui = g.u(i);
      while (sp < spine.size() && spine[sp].u < ui) W += spine[sp++].step;
      if constexpr (requires { tables.has(i); }) {
        if (!tables.has(i)) continue;
      }
      auto* b0 = sorted.data() + start[size_t(i - i_begin)];
      auto* b1 = sorted.data() + start[size_t(i - i_begin) + 1];
      sort_along_loop(b0, b1);
      int w = W;
      for (auto* c = b0; c != b1; ++c) {
        const int next = w + c->step;
        if (w == 0 && next != 0) tables.accumulate(i, c->t, +1.0, acc);  // a visible run ends
        if (w != 0 && next == 0) tables.accumulate(i, c->t, -1.0, acc);  // a visible run starts
        w = next;
      }
      if (w == 0) {
        const double* total = tables.loop_total(i);
        for (size_t c = 0; c < F; ++c) acc[c] += total[c];
      }
      if (w != W || W < 0) ++inconsistent;
    }
    return inconsistent;
  }


  // The horizon of n as a virtual occluder boundary (four quarter arcs): +step when crossing into
  // n·ω < 0 (1, or K when contour components below the horizon were dropped: see prepare_edges).
  void add_horizon(const Vector3d& n, std::vector<Arc>& arcs, int step = 1) const {
    const Vector3d nf = frame_from_world * n;
    const Vector3d t1v = (std::abs(nf.x()) < 0.9 ? Vector3d::UnitX() : Vector3d::UnitY()).cross(nf).normalized();
    const Vector3d t2v = nf.cross(t1v);
    const Vector3d c[4] = {t1v, t2v, -t1v, -t2v};
    for (int k = 0; k < 4; ++k) arcs.push_back({c[k], c[(k + 1) % 4], c[k].cross(c[(k + 1) % 4]), -step});
  }

  // Isoline crossings and spine crossings of every arc in s.arcs.
  void add_crossings(Scratch& s) const {
    s.crossings.clear();
    s.spine.clear();
    for (const Arc& arc : s.arcs) {
      add_arc(arc, grid, 0, grid.n, s.crossings);
      add_spine(arc, s.spine);
    }
  }

  // The hot texels' moments (HotTexels::width(): per colour, order² SH integrals) into the
  // environment's columns R and S of `acc` (the tables' layout): both are linear in y_i.
  void add_hot_moments(const double* mom, double* acc) const {
    const size_t n2 = size_t(env_order * env_order), ns = size_t(req.shadowed_order * req.shadowed_order);
    if (req.radiance)
      for (size_t c = 0; c < 3; ++c)
        for (size_t mm = 0; mm < 3; ++mm) acc[c_r + 3 * c + mm] += mom[c * n2 + 1 + mm];
    for (size_t c = 0; c < 3; ++c)
      for (size_t i = 0; i < ns; ++i) acc[c_s + c * ns + i] += mom[c * n2 + i];
  }

  // DCF walk from W0 at the spine start over the isoline tables, then the hot texels' visible
  // parts exactly. Leaves the F integrals (in the tables' column layout) in s.acc; returns the
  // number of inconsistent loops.
  uint64_t walk_all(Scratch& s, int W0) const {
    std::sort(s.spine.begin(), s.spine.end(),
              [](const SpineCrossing& x, const SpineCrossing& y) { return x.u < y.u || (x.u == y.u && x.step < y.step); });
    s.acc.assign(F, 0.0);
    double* acc = s.acc.data();
    const uint64_t inconsistent = walk(grid, 0, grid.n, *tables, W0, s.spine, s.crossings, s.sorted, s.bucket_start, acc, F);
    for (size_t c = 0; c < F; ++c) acc[c] *= grid.h;
    if (hot) {
      s.hot_moments.assign(hot->width(), 0.0);
      hot->accumulate(s.arcs, Vector3d(-1, 0, 0), W0, s.hot_moments.data());
      add_hot_moments(s.hot_moments.data(), acc);
    }
    return inconsistent;
  }

  // No contour edge in the visible hemisphere (docs/ARCHITECTURE.md §5, "no integrator work where no contour
  // edge is seen"): the depth complexity is then constant over the open upper hemisphere, so one
  // ray along n decides between "enclosed" (W > 0: nothing visible, every product is 0) and
  // "open" (V = H). Open rows are closed forms (bake/sphere/zonal.h, Funk–Hecke): AO = 1,
  // T_lm = 2 I_l(1) y_lm(n), U_lm = 2π I_l(0) y_lm(n). The band-1 radiance ∫ L H y_1m dω depends on
  // the environment: it is the horizon-only walk of the same tables (no contour edges, no rays),
  // computed once per distinct normal. Returns false (use the general path) if the ray is ambiguous.
  // True if no contour edge reaches into the open upper hemisphere of (p, n): both end points on
  // or below the tangent plane (the shade point's own vertex is seen in direction −n). Rounding
  // can only make an edge on the horizon look visible, which sends the point down the general path.
  bool none_in_view(const ShadePoint& point, const std::vector<ContourEdge>& edges) const {
    for (const ContourEdge& ce : edges)
      for (const uint32_t w : topo.edges[ce.edge]) {
        if (point.welded >= 0 && w == uint32_t(point.welded)) continue;
        if (point.n.dot(topo.welded_positions[w].cast<double>() - point.p) > 0) return false;
      }
    return true;
  }

  bool closed_form(const ShadePoint& point, std::span<double> out) const {
    const CrossingCount cc = rays.count_crossings(point, point.n);
    n_rays.fetch_add(1, std::memory_order_relaxed);
    if (cc.ambiguous) return false;
    const ProductLayout& L = layout;
    std::fill(out.begin(), out.begin() + std::ptrdiff_t(L.width), 0.0);
    n_closed_form.fetch_add(1, std::memory_order_relaxed);
    if (cc.count > 0) {
      n_enclosed.fetch_add(1, std::memory_order_relaxed);
      return true;
    }
    if (L.ao_count) out[L.ao] = 1.0;
    if (L.transfer_count) {
      clamped_power_sh(1.0, req.transfer_order, point.n, out.subspan(L.transfer, L.transfer_count));
      for (size_t k = 0; k < L.transfer_count; ++k) out[L.transfer + k] *= std::numbers::inv_pi;
    }
    if (L.visibility_count) clamped_power_sh(0.0, req.visibility_order, point.n, out.subspan(L.visibility, L.visibility_count));
    if (n_env) {
      const std::vector<double>& r = hemisphere_radiance(point.n);
      for (size_t k = 0; k < L.radiance_count; ++k) out[L.radiance + k] = r[k];
      for (size_t k = 0; k < L.shadowed_count; ++k) out[L.shadowed + k] = r[c_s - c_r + k];
    }
    return true;
  }

  // The n_env environment columns (R, S) of the open hemisphere about n; the reference stays valid
  // (std::map nodes do not move).
  const std::vector<double>& hemisphere_radiance(const Vector3d& n) const {
    const std::array<double, 3> key = {n.x(), n.y(), n.z()};
    {
      const std::lock_guard lock(hemisphere_mutex);
      if (const auto it = hemisphere_radiance_cache.find(key); it != hemisphere_radiance_cache.end()) return it->second;
    }
    Scratch& s = tl_scratch;
    s.arcs.clear();
    add_horizon(n, s.arcs);
    add_crossings(s);
    // W at the spine start: 1 below the horizon, 0 above; the generic frame makes n·s0 = 0 a
    // measure-zero case, in which a start just off the spine along the walk direction decides.
    const Vector3d s0_world = frame_from_world.transpose() * Vector3d(-1, 0, 0);
    double hz = n.dot(s0_world);
    if (hz == 0) hz = n.dot(frame_from_world.transpose() * Vector3d(-1, 0, -1e-9).normalized());
    (void)walk_all(s, hz < 0 ? 1 : 0);
    std::vector<double> r(s.acc.begin() + std::ptrdiff_t(c_r), s.acc.end());
    const std::lock_guard lock(hemisphere_mutex);
    return hemisphere_radiance_cache.emplace(key, r).first->second;
  }

  // Whether the vertex at p + v is certainly strictly below the tangent plane of (p, n):
  // n·v < 0 beyond its rounding bound (v = x − p and the three-term dot product err by at most
  // γ₄·Σ|n_i (x_i − p_i)|; 8u covers it and the rounding of the sum of magnitudes). (The point's
  // own vertex, seen at −n, is below without this test.)
  static bool certainly_below(const Vector3d& n, const Vector3d& v) {
    const double a = n.x() * v.x(), b = n.y() * v.y(), c = n.z() * v.z();
    return a + b + c < -8 * 0x1p-53 * (std::abs(a) + std::abs(b) + std::abs(c));
  }

  // The nodes of the contour edges' ends (Scratch::nodes, ends). With `cull`, moves the edges of
  // every component (connected through welded vertices) that lies wholly below the horizon from
  // s.edges to s.dropped, keeping the others in order, and returns the horizon's step
  // K = 1 + 2·Σ_dropped |S_e| (1 when nothing is dropped: the unculled walk). See
  // bake/integrators/silhouette.h for why W = 0 is then decided on the same runs.
  int prepare_edges(const ShadePoint& point, Scratch& s, bool cull) const {
    s.nodes.clear();
    s.parent.clear();
    s.size.clear();
    s.below.clear();
    s.ends.clear();
    s.dropped.clear();
    s.dropped_ends.clear();
    s.dropped_arcs.clear();
    if (s.node_of.size() < topo.welded_positions.size()) s.node_of.resize(topo.welded_positions.size(), -1);
    auto node = [&](uint32_t w) {
      int32_t& k = s.node_of[w];
      if (k < 0) {
        k = int32_t(s.nodes.size());
        Scratch::Node nd;
        nd.welded = w;
        // A free point (welded = −1) may lie exactly on a vertex of another part (a texel's
        // sample on its triangle's edge where a wall standing on the face has a corner): that
        // vertex is at p as the point's own is, seen at −n from p + εn (p − p has no direction).
        const Vector3d v = topo.welded_positions[w].cast<double>() - point.p;
        const bool own = (point.welded >= 0 && w == uint32_t(point.welded)) || v == Vector3d::Zero();
        nd.at_p = own;
        nd.v = own ? Vector3d(-point.n) : v;  // seen from p + εn
        nd.f = frame_from_world * nd.v;
        s.below.push_back(cull && (own || certainly_below(point.n, nd.v)) ? 1 : 0);
        s.parent.push_back(uint32_t(k));
        s.size.push_back(1);
        s.nodes.push_back(nd);
      }
      return uint32_t(k);
    };
    for (const ContourEdge& ce : s.edges) {
      const auto& e = topo.edges[ce.edge];
      s.ends.push_back({node(e[0]), node(e[1])});
    }
    int64_t dropped_sum = 0;
    if (cull) {
      uint32_t* const parent = s.parent.data();
      auto root = [parent](uint32_t x) {
        while (parent[x] != x) x = parent[x] = parent[parent[x]];
        return x;
      };
      for (const auto& en : s.ends) {
        uint32_t ra = root(en[0]), rb = root(en[1]);
        if (ra == rb) continue;
        if (s.size[ra] > s.size[rb]) std::swap(ra, rb);
        parent[ra] = rb;
        s.size[rb] += s.size[ra];
        s.below[rb] &= s.below[ra];
      }
      size_t kept = 0;
      for (size_t i = 0; i < s.edges.size(); ++i) {
        if (s.below[root(s.ends[i][0])]) {
          s.dropped.push_back(s.edges[i]);
          s.dropped_ends.push_back(s.ends[i]);
          dropped_sum += std::abs(int64_t(s.edges[i].side_sum));
        } else {
          s.edges[kept] = s.edges[i];
          s.ends[kept++] = s.ends[i];
        }
      }
      s.edges.resize(kept);
      s.ends.resize(kept);
    }
    for (const Scratch::Node& nd : s.nodes) s.node_of[nd.welded] = -1;
    PRT_CHECK_OP(dropped_sum, <, int64_t(1) << 29);
    return int(1 + 2 * dropped_sum);
  }

  // W_D(n) − W_D(x) for the dropped components' step function W_D, world direction x (unit): what
  // the depth complexity counted along x must be corrected by so that W' = W − W_D + W_D(upper)
  // (bake/integrators/silhouette.h). 0 when x is clearly above the horizon (W_D is constant on the
  // closed upper hemisphere, which no dropped arc enters); otherwise the steps of the dropped arcs
  // along a path from x up to n (any path: W_D is single-valued), via a waypoint when x is far
  // below. A dropped edge with both ends clearly on one side of a leg's plane (relative margin
  // 1e-7, far above rounding) cannot cross it and is skipped before its arc is built.
  int dropped_correction(const ShadePoint& point, Scratch& s, const Vector3d& x) const {
    if (s.dropped.empty() || point.n.dot(x) > 1e-9) return 0;
    const Vector3d P = frame_from_world * x, Q = frame_from_world * point.n;
    Vector3d legs[3] = {P, Q, Q};
    int n_legs = 1;
    if (P.dot(Q) <= -0.5) {
      Vector3d mid = P.cross(Vector3d(0.5466, -0.3719, 0.7503));
      if (mid.squaredNorm() < 1e-6) mid = P.cross(Vector3d(-0.2377, 0.8716, 0.4288));
      legs[1] = mid.normalized();
      n_legs = 2;
    }
    const Eigen::Matrix3d world_from_frame = frame_from_world.transpose();
    int steps = 0;
    for (int l = 0; l < n_legs; ++l) {
      const Vector3d& from = legs[l];
      const Vector3d& to = legs[l + 1];
      const Vector3d m2 = world_from_frame * from.cross(to);  // the leg's plane, world frame
      const double k2 = 1e-14 * m2.squaredNorm();
      s.dropped_arcs.clear();
      for (size_t i = 0; i < s.dropped.size(); ++i) {
        const ContourEdge& ce = s.dropped[i];
        const Scratch::Node &A = s.nodes[s.dropped_ends[i][0]], &B = s.nodes[s.dropped_ends[i][1]];
        const Vector3d &da = A.v, &db = B.v;
        const double sa = da.dot(m2), sb = db.dot(m2);
        if (((sa > 0 && sb > 0) || (sa < 0 && sb < 0)) && sa * sa > k2 * da.squaredNorm() && sb * sb > k2 * db.squaredNorm())
          continue;
        Arc arc;
        arc.a = A.f;
        arc.b = B.f;
        arc.m = arc.a.cross(arc.b);
        arc.side_sum = ce.side_sum;
        // Both ends strictly below: an edge collinear with p does not pass through it and is seen
        // as a point (crossed by no path), as in integrate().
        if (arc.m.squaredNorm() != 0) s.dropped_arcs.push_back(arc);
      }
      steps += dcf_path_steps(s.dropped_arcs, from, to);
    }
    return steps;
  }

  void integrate(const ShadePoint& point, uint64_t point_index, std::span<double> out) const {
    using clock = std::chrono::steady_clock;
    const auto t0 = clock::now();
    Scratch& s = tl_scratch;
    contours.find(point, s.edges);
    const auto t1 = clock::now();
    // The contour edges are scattered over the mesh: fetch their end points' positions ahead of
    // the loops below (edge records first, then the positions they name), so the misses overlap.
    for (const ContourEdge& ce : s.edges) __builtin_prefetch(&topo.edges[ce.edge]);
    for (const ContourEdge& ce : s.edges) {
      const auto& e = topo.edges[ce.edge];
      __builtin_prefetch(&topo.welded_positions[e[0]]);
      __builtin_prefetch(&topo.welded_positions[e[1]]);
    }
    if (point.hemisphere && none_in_view(point, s.edges) && closed_form(point, out)) {
      n_points.fetch_add(1, std::memory_order_relaxed);
      contour_ns.fetch_add(std::chrono::duration_cast<std::chrono::nanoseconds>(t1 - t0).count(), std::memory_order_relaxed);
      integrate_ns.fetch_add(std::chrono::duration_cast<std::chrono::nanoseconds>(clock::now() - t1).count(),
                             std::memory_order_relaxed);
      return;
    }

    // ---- contour components below the horizon: left out, the horizon's step raised instead ----
    const size_t found_edges = s.edges.size();
    const int horizon_step = prepare_edges(point, s, point.hemisphere && opt.cull_below_horizon);
    if (!s.dropped.empty()) n_culled.fetch_add(s.dropped.size(), std::memory_order_relaxed);

    // ---- arcs in the octahedral frame ----
    s.arcs.clear();
    const Vector3d n = point.n;
    for (size_t i = 0; i < s.edges.size(); ++i) {
      const ContourEdge& ce = s.edges[i];
      const Scratch::Node &A = s.nodes[s.ends[i][0]], &B = s.nodes[s.ends[i][1]];
      const std::array<uint32_t, 2> e = {A.welded, B.welded};
      const Vector3d &da = A.v, &db = B.v;  // seen from p + εn (the point's own vertex at −n)
      auto push = [&](const Vector3d& a, const Vector3d& b) {
        Arc arc;
        arc.a = frame_from_world * a;
        arc.b = frame_from_world * b;
        arc.m = arc.a.cross(arc.b);
        arc.side_sum = ce.side_sum;
        s.arcs.push_back(arc);
      };
      // An edge whose line passes through p (a T-junction: p on another triangle's edge, neither
      // end welded to it) has a − p ∥ b − p. Seen from p + εn it is the great half circle from a
      // through −n (where p lies on it) to b, in the plane of (b − a) × n: the limit of m. Both
      // halves keep that orientation. Collinear with p but not through it, it shrinks to a point
      // as ε → 0 and is crossed by no path. Collinearity is decided exactly: p exactly on the
      // line (a texel's sample on its triangle's edge) still gives da, db rounded apart, so
      // da × db is only near 0 and its direction is noise (an arc through the zenith instead of
      // −n, crossing steps of either sign). The filter: if a − p ∥ b − p exactly, the rounded
      // da, db (each coordinate within u = 2⁻⁵³ of its own) have |da × db| ≤ ~6.1u·|da||db| per
      // component (the perturbation 4u, the two products' rounding 2u), so ≤ 11u·|da||db| in all;
      // (16u)² bounds the square with room. Outside it they are certainly not parallel.
      const bool at_p = A.at_p || B.at_p;
      constexpr double kParallel = 16 * 0x1p-53;
      if (!at_p && da.cross(db).squaredNorm() <= kParallel * kParallel * da.squaredNorm() * db.squaredNorm() &&
          collinear_exactly(topo.welded_positions[e[0]], topo.welded_positions[e[1]], point.p)) {
        if (da.dot(db) < 0) {
          push(da, -n);
          push(-n, db);
        }
        continue;
      }
      // An edge from p itself along ±n (a wall standing on the face, or hanging under it, from
      // the vertex: CAD fins): seen from p + εn its far part is at ±n and its near part at −n,
      // so a − p ∥ b − p. Along −n it is one point. Along +n, from the tie-break's p + εn + ε²t,
      // the point p + λn is seen in direction (λ − ε)n − ε²t: the great half circle from −n
      // through −t to +n, the same limit in which the ray counts and contour sides decide
      // (bake/visibility/raycast.h, bake/visibility/contour.h). Without a tie-break every face on the edge has side 0
      // and the edge is no contour edge.
      if (at_p && da.cross(db).squaredNorm() == 0) {
        if (tie_break(point) && da.dot(db) < 0) {
          push(da, -point.t);
          push(-point.t, db);
        }
        continue;
      }
      Arc arc;  // push(da, db), with the frame directions computed once per vertex
      arc.a = A.f;
      arc.b = B.f;
      arc.m = arc.a.cross(arc.b);
      arc.side_sum = ce.side_sum;
      s.arcs.push_back(arc);
    }
    if (point.hemisphere) add_horizon(n, s.arcs, horizon_step);
    add_crossings(s);

    // ---- W at the spine start (frame direction (−1, 0, 0)) from one counted ray ----
    const Vector3d s0(-1, 0, 0);
    const Eigen::Matrix3d world_from_frame = frame_from_world.transpose();
    int W0 = 0;
    bool found = false;
    for (int attempt = 0; attempt < 16 && !found; ++attempt) {
      Vector3d wr = world_from_frame * s0;
      if (attempt > 0) {
        const uint64_t h = mix64(opt.seed ^ mix64(point_index * 64 + uint64_t(attempt)));
        const double z = 2 * to_unit(mix64(h + 1)) - 1, phi = 2 * std::numbers::pi * to_unit(mix64(h + 2));
        const double r = std::sqrt(std::max(0.0, 1 - z * z));
        wr = Vector3d(r * std::cos(phi), r * std::sin(phi), z);
        if ((frame_from_world * wr).dot(s0) < -0.99) continue;  // nearly antipodal: the path is ill-defined
      }
      const CrossingCount cc = rays.count_crossings(point, wr);
      n_rays.fetch_add(1, std::memory_order_relaxed);
      if (cc.ambiguous) continue;
      int w = cc.count;
      if (point.hemisphere) {
        const double hz = n.dot(wr);
        if (std::abs(hz) < 1e-12) continue;
        w += hz < 0 ? horizon_step : 0;
        w += dropped_correction(point, s, wr);
      }
      if (attempt > 0) {
        w += dcf_path_steps(s.arcs, frame_from_world * wr, s0);  // bake/integrators/hot_texels.h
        n_retries.fetch_add(1, std::memory_order_relaxed);
      }
      W0 = w;
      found = true;
    }
    if (!found) throw ContractError("silhouette: no unambiguous start ray after 16 directions");

    const uint64_t inconsistent = walk_all(s, W0);
    const double* acc = s.acc.data();

    // ---- products ----
    const ProductLayout& L = layout;
    // AO lies in [0, 1] exactly; a cell straddling the horizon carries the cell-mean of n·ω, so a
    // visible sliver above the horizon can come out slightly negative (an O(h²) error). Clamping
    // to the exact range can only reduce the error.
    if (L.ao_count)
      out[L.ao] = std::clamp(n.x() * acc[c_ao] + n.y() * acc[c_ao + 1] + n.z() * acc[c_ao + 2], 0.0, 1.0);
    for (size_t k = 0; k < L.transfer_count; ++k) {
      const size_t nt = L.transfer_count;
      out[L.transfer + k] = n.x() * acc[c_t + k] + n.y() * acc[c_t + nt + k] + n.z() * acc[c_t + 2 * nt + k];
    }
    for (size_t k = 0; k < L.visibility_count; ++k) out[L.visibility + k] = acc[c_u + k];
    for (size_t k = 0; k < L.radiance_count; ++k) out[L.radiance + k] = acc[c_r + k];
    for (size_t k = 0; k < L.shadowed_count; ++k) out[L.shadowed + k] = acc[c_s + k];

    const auto t2 = clock::now();
    n_points.fetch_add(1, std::memory_order_relaxed);
    n_edges.fetch_add(found_edges, std::memory_order_relaxed);
    n_crossings.fetch_add(s.crossings.size(), std::memory_order_relaxed);
    if (inconsistent) n_inconsistent.fetch_add(inconsistent, std::memory_order_relaxed);
    contour_ns.fetch_add(std::chrono::duration_cast<std::chrono::nanoseconds>(t1 - t0).count(), std::memory_order_relaxed);
    integrate_ns.fetch_add(std::chrono::duration_cast<std::chrono::nanoseconds>(t2 - t1).count(), std::memory_order_relaxed);
  }
};

SilhouetteIntegrator::SilhouetteIntegrator(const Mesh& mesh, const Topology& topology, const ProductRequest& request,
                                           const SilhouetteOptions& options, const MeshAccel* accel)
    : impl_(std::make_unique<Impl>(mesh, topology, request, options, accel)) {}

SilhouetteIntegrator::~SilhouetteIntegrator() = default;

std::string SilhouetteIntegrator::description() const {
  std::ostringstream os;
  os << "visibility silhouettes (paper 001 §3): " << impl_->grid.n << " u-isolines (k = " << impl_->grid.n << "^2), "
     << impl_->F << " integrand components in " << (impl_->tables->bytes() >> 20) << " MiB of isoline tables, "
     << impl_->subsamples << "x" << impl_->subsamples << " sub-samples per cell";
  if (impl_->max_texel_subsamples > 0)
    os << ", the environment's texels as exact masses (up to " << impl_->max_texel_subsamples << "x"
       << impl_->max_texel_subsamples << " sub-samples per texel)";
  if (impl_->hot)
    os << "; " << impl_->hot->texels() << " hot environment texels (>= " << Impl::kHotFactor
       << "x mean luminance) in " << impl_->hot->clusters() << " clusters, integrated exactly over their visible parts";
  return os.str();
}

const ProductLayout& SilhouetteIntegrator::layout() const { return impl_->layout; }
const SilhouetteOptions& SilhouetteIntegrator::options() const { return impl_->opt; }

void SilhouetteIntegrator::integrate(const ShadePoint& point, uint64_t point_index, std::span<double> out,
                                     std::span<double> std_error) const {
  PRT_CHECK_OP(out.size(), >=, impl_->layout.width);
  impl_->integrate(point, point_index, out);
  for (double& e : std_error) e = 0.0;
}

void SilhouetteIntegrator::unoccluded(std::span<double> out) const {
  PRT_CHECK_OP(out.size(), >=, impl_->layout.width);
  std::copy(impl_->unoccluded_row.begin(), impl_->unoccluded_row.end(), out.begin());
}

SilhouetteStats SilhouetteIntegrator::silhouette_stats() const {
  SilhouetteStats s;
  s.points = impl_->n_points.load();
  s.contour_edges = impl_->n_edges.load();
  s.crossings = impl_->n_crossings.load();
  s.start_rays = impl_->n_rays.load();
  s.start_retries = impl_->n_retries.load();
  s.inconsistent_loops = impl_->n_inconsistent.load();
  s.closed_form = impl_->n_closed_form.load();
  s.enclosed = impl_->n_enclosed.load();
  s.contour_seconds = double(impl_->contour_ns.load()) * 1e-9;
  s.integrate_seconds = double(impl_->integrate_ns.load()) * 1e-9;
  s.cpu_seconds = s.contour_seconds + s.integrate_seconds;
  return s;
}

bool SilhouetteIntegrator::masses_from_cache() const noexcept { return impl_->masses_from_cache; }

void SilhouetteIntegrator::reset_stats() const {
  Impl& I = *impl_;
  for (std::atomic<uint64_t>* n : {&I.n_points, &I.n_edges, &I.n_crossings, &I.n_rays, &I.n_retries, &I.n_inconsistent,
                                   &I.n_closed_form, &I.n_enclosed, &I.n_culled})
    n->store(0);
  I.contour_ns.store(0), I.integrate_ns.store(0);
}

std::string SilhouetteIntegrator::work_summary() const {
  const SilhouetteStats st = silhouette_stats();
  const double points = double(std::max<uint64_t>(st.points, 1)), cpu = std::max(1e-12, st.contour_seconds + st.integrate_seconds);
  char line[384];
  std::snprintf(line, sizeof line,
                "per integral %.1f contour edges, %.0f crossings; CPU time %.0f%% contour search, %.0f%% integration; "
                "%llu of %llu points saw no contour edge (closed form); %.1f edges per integral below the horizon, "
                "left out",
                double(st.contour_edges) / points, double(st.crossings) / points, 100 * st.contour_seconds / cpu,
                100 * st.integrate_seconds / cpu, (unsigned long long)st.closed_form, (unsigned long long)st.points,
                double(impl_->n_culled.load()) / points);
  return line;
}

} // namespace prt::bake
