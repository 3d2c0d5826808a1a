// bake/contour.cpp — exact ε-limit orientation and the dual-space BVH of contour candidates
// (paper 001 §3.1). See bake/visibility/contour.h for the contract.
//
// EXACTNESS.
//  * orient_eps: D0 = det(A, B, C), A = a − p, … is evaluated in double with Shewchuk's orient3d
//    filter: |D0 − D0~| ≤ (7 + 56u)u · permanent (u = 2⁻⁵³, permanent = Σ|adz|(|bdx·cdy| +
//    |cdx·bdy|) + …, computed). When the permanent is exactly 0 every product has a zero factor
//    (no underflow is possible for the inputs we take), so D0 = 0 exactly. Otherwise, when the
//    filter cannot decide, D0 is recomputed exactly with floating-point expansions (two_diff,
//    two_product by FMA, grow/scale expansion with zero elimination; Shewchuk 1997).
//    D1 = −[det(n,B,C) + det(A,n,C) + det(A,B,n)] = −n·(B×C + C×A + A×B) = −n·((b−a)×(c−a)),
//    which does not depend on p; it has the same shape as orient3d with one exact row (n), so
//    the same filter bound holds, with the same exact fallback.
//  * The BVH query. In a centred, power-of-two-scaled frame q = (p − o)·s, each face k of a
//    BVH edge stores ĝ = (n', d'), n' the computed unit normal of N = (b−a)×(c−a) (edge order),
//    d' = −n'·a', a' = (a − o)·s. With η ≥ |n' − N/|N||_∞ (bounded per face from the rounding
//    of N and of the normalisation) and A = max |a'|₁, the value ĝ·(q, 1) evaluated in floating
//    point differs from the exact s·π(p)/|N| by at most
//        δ = 1.01·(η_max + 10u)·(|q|₁ + A)
//    (η|q|₁ + u|q|₁ from q and n', (η + u + γ₃)A from a' and d', γ₄(|q|₁ + A) for the dot
//    product; the 1.01 covers computing δ itself). So |v| > δ decides the sign of π exactly.
//    Two evaluations add their own rounding to δ (each bound proven where its coefficient is
//    set, in the constructor):
//      - leaves hold ĝ rounded to float and evaluate in float (4 lanes): δ_rec = δ +
//        1.01·8uf·(|q|₁ + A), uf = 2⁻²⁴; |v| > δ_rec decides, anything within goes to orient_eps;
//      - a node's bound, the range of n·(q − c) + D over its box (c its centre, D = d + n·c
//        computed in double and widened by its rounding error before rounding outward to
//        float), is evaluated in float: δ_node = δ + 1.01·10uf·(|q|₁ + max|c|₁ + max|D|). A node
//        is pruned only when its whole range is beyond ±δ_node, i.e. when every face of every
//        edge under it has an exactly known σ that makes S = 0.
//    A record stored negated (oriented by its face 1's winding) changes none of this: negation
//    is exact, and the leaf's contour sign is negated back.
//    Faces of always-tested edges are filtered the same way: their ĝ in float (a zero record for
//    an ill-conditioned face), evaluated four at a time with δ_rec from their own η and A
//    (always_coef_); orient_eps decides every face within it.
//    Points with |q|₁ ≥ 1e30 (beyond float) take the brute-force path. Faces with η > 1e-6
//    (slivers, collinear corners) and repeated welded corners keep their edge out of the BVH, in
//    the always-tested list.
#include <bake/core/error.h>
#include <bake/mesh/predicates.h>
#include <bake/visibility/contour.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace prt::bake {

namespace {

constexpr double kU = 0x1p-53;  // unit roundoff
using predicates_detail::orient_eps_f;

// Outward rounding of a double bound to float.
float round_down(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) > x) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  return f;
}
float round_up(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

constexpr double kMaxNormalError = 1e-6;  // faces with a worse normal bound are always tested
constexpr uint32_t kLeafSize = 4;  // records per leaf at most
static_assert(kLeafSize == 4);  // a leaf is one LeafBlock of four float lanes

}  // namespace

// ---------------------------------------------------------------- ContourFinder

namespace {

struct FaceDual {
  double g[4];
  double eta;  // bound on |n' − N/|N||_∞
  bool ok;     // well-conditioned (η ≤ kMaxNormalError)
};

// Unit normal of (b−a)×(c−a) with its error bound, and the offset in the finder's frame.
FaceDual face_dual(const Eigen::Vector3f& af, const Eigen::Vector3f& bf, const Eigen::Vector3f& cf,
                   const Eigen::Vector3d& origin, double s) {
  FaceDual f{};
  const Eigen::Vector3d a = af.cast<double>(), b = bf.cast<double>(), c = cf.cast<double>();
  const Eigen::Vector3d u = b - a, w = c - a;  // each component within u·|computed| of exact
  const Eigen::Vector3d N = u.cross(w);
  // |N'_i − N_i| ≤ γ₄ (|u_j w_k| + |u_k w_j|) in exact magnitudes; 6u on computed ones.
  const double m = (std::abs(u.y() * w.z()) + std::abs(u.z() * w.y())) +
                   (std::abs(u.z() * w.x()) + std::abs(u.x() * w.z())) +
                   (std::abs(u.x() * w.y()) + std::abs(u.y() * w.x()));
  const double dN = 6 * kU * m * (1 + 8 * kU);  // ‖N' − N‖₂ ≤ ‖·‖₁
  const double len = N.norm();
  const double len_lo = len * (1 - 4 * kU) - dN;  // ≤ |N|
  if (!(len_lo > 0) || !std::isfinite(len)) return f;
  // |N'/|N'| − N/|N|| ≤ 2‖N' − N‖/|N|; the normalisation itself adds ≤ 5u per component.
  f.eta = 2 * dN / len_lo * (1 + 8 * kU) + 6 * kU;
  if (!(f.eta <= kMaxNormalError)) return f;
  const Eigen::Vector3d n = N / len;
  const Eigen::Vector3d ap = (a - origin) * s;
  f.g[0] = n.x();
  f.g[1] = n.y();
  f.g[2] = n.z();
  f.g[3] = -(n.x() * ap.x() + n.y() * ap.y() + n.z() * ap.z());
  f.ok = true;
  return f;
}

// Four float lanes (GCC / Clang vector extensions: SSE on x86-64, NEON on ARM, scalar elsewhere).
typedef float f4 __attribute__((vector_size(16)));
typedef int32_t i4 __attribute__((vector_size(16)));
inline f4 load(const float* x) {
  f4 v;
  std::memcpy(&v, x, sizeof v);
  return v;
}
inline f4 splat(float x) { return f4{x, x, x, x}; }
// The lane-wise helpers of the walk. SSE2: one instruction each (movmskps reads the sign bits
// of the all-ones / all-zeros comparison lanes; minps / maxps are exactly x < y ? x : y and
// x > y ? x : y); elsewhere the same values lane by lane.
inline unsigned lanes(i4 m) {  // bit k set iff lane k is true
#if defined(__SSE2__)
  __m128i v;
  std::memcpy(&v, &m, sizeof v);
  return unsigned(_mm_movemask_ps(_mm_castsi128_ps(v)));
#else
  return unsigned(m[0] & 1) | unsigned(m[1] & 1) << 1 | unsigned(m[2] & 1) << 2 | unsigned(m[3] & 1) << 3;
#endif
}
inline f4 min4(f4 x, f4 y) {  // x < y ? x : y
#if defined(__SSE2__)
  return f4(_mm_min_ps(__m128(x), __m128(y)));
#else
  return x < y ? x : y;
#endif
}
inline f4 max4(f4 x, f4 y) {  // x > y ? x : y
#if defined(__SSE2__)
  return f4(_mm_max_ps(__m128(x), __m128(y)));
#else
  return x > y ? x : y;
#endif
}

// The dual segment of a BVH edge in double: ĝ_1 and −ĝ_2, both negated when `flipped` (see
// the constructor: the record is oriented by face 1's winding).
struct DualEdge {
  double g1[4], g2[4];
  bool flipped;
};

// A BVH edge during the build: the box of its four corners (the finder's frame) and of its two
// endpoint normals (n_1 and −n_2: nearly equal on a smooth surface), with their centres as keys.
struct BuildItem {
  float lo[6], hi[6];  // x, y, z of the corners; then the normals
  float key[6];
  uint32_t record;
};

// A build box over BuildItem's six axes; cost() is the build's estimate of a node's bound width.
constexpr double kRho = 1.0;
struct Box {
  float lo[6], hi[6];
  void clear() {
    std::fill(lo, lo + 6, std::numeric_limits<float>::infinity());
    std::fill(hi, hi + 6, -std::numeric_limits<float>::infinity());
  }
  void grow(const float* l, const float* h) {
    for (int i = 0; i < 6; ++i) {
      lo[i] = std::min(lo[i], l[i]);
      hi[i] = std::max(hi[i], h[i]);
    }
  }
  double cost() const {
    return (double(hi[0]) - lo[0]) + (double(hi[1]) - lo[1]) + (double(hi[2]) - lo[2]) +
           kRho * ((double(hi[3]) - lo[3]) + (double(hi[4]) - lo[4]) + (double(hi[5]) - lo[5]));
  }
};
}  // namespace

ContourFinder::ContourFinder(const Mesh& mesh, const Topology& topology) : mesh_(&mesh), topology_(&topology) {
  const auto& wp = topology.welded_positions;
  const size_t E = topology.edges.size();
  stats_.edges = E;

  // Frame: centre of the bounding box, power-of-two scale bringing the half extent near 1.
  if (!wp.empty()) {
    Eigen::Vector3d lo = wp[0].cast<double>(), hi = lo;
    for (const auto& v : wp) {
      lo = lo.cwiseMin(v.cast<double>());
      hi = hi.cwiseMax(v.cast<double>());
    }
    origin_ = 0.5 * (lo + hi);
    const double half = 0.5 * (hi - lo).maxCoeff();
    if (half > 0 && std::isfinite(half)) {
      int ex = 0;
      std::frexp(half, &ex);
      scale_ = std::ldexp(1.0, -ex);
    }
  }

  std::vector<BuildItem> items;
  items.reserve(E);
  std::vector<DualEdge> recs;
  std::vector<Corners> crs;
  recs.reserve(E);
  crs.reserve(E);
  double eta_max = 0, amax = 0, eta_always = 0, amax_always = 0;
  for (uint32_t e = 0; e < E; ++e) {
    const auto [ia, ib] = topology.edges[e];
    const auto faces = topology.faces_of_edge(e);
    bool bvh = faces.size() == 2;
    uint32_t corner[2] = {0, 0};
    for (size_t k = 0; bvh && k < 2; ++k) {
      const auto& t = mesh.triangles[faces[k]];
      const uint32_t w0 = topology.weld[t[0]], w1 = topology.weld[t[1]], w2 = topology.weld[t[2]];
      if (w0 == w1 || w1 == w2 || w0 == w2) {
        bvh = false;
        break;
      }
      corner[k] = (w0 != ia && w0 != ib) ? w0 : (w1 != ia && w1 != ib) ? w1 : w2;
    }
    if (bvh) {
      // A flat edge — both faces exactly coplanar and on opposite sides of it — has σ_1 = −σ_2
      // from every viewpoint (π_2 = −π_1 up to a positive factor, so their ε-limit signs are
      // opposite too): S ≡ 0, never a contour. Interiors of floors, walls and ground planes drop
      // out of the search entirely, which matters most for shade points on the same plane.
      const Eigen::Vector3d a = wp[ia].cast<double>(), b = wp[ib].cast<double>();
      const Eigen::Vector3d c1 = wp[corner[0]].cast<double>(), c2 = wp[corner[1]].cast<double>();
      if (orient3d_exact(a, b, c1, c2) == 0) {
        const Eigen::Vector3d n1 = (b - a).cross(c1 - a), n2 = (b - a).cross(c2 - a);
        // Exactly parallel (coplanar); opposite sides iff the normals point opposite ways. Only
        // a clearly negative dot is trusted (slivers with c on the edge line stay in).
        if (n1.dot(n2) < -1e-6 * n1.norm() * n2.norm()) {
          ++stats_.flat_edges;
          continue;
        }
      }
    }
    FaceDual d1{}, d2{};
    if (bvh) {
      d1 = face_dual(wp[ia], wp[ib], wp[corner[0]], origin_, scale_);
      d2 = face_dual(wp[ia], wp[ib], wp[corner[1]], origin_, scale_);
      bvh = d1.ok && d2.ok;
    }
    if (!bvh) {
      always_.push_back(e);
      for (const uint32_t f : faces) {  // the faces side_sum_slow counts, corners (a, b, c)
        const auto& t = mesh.triangles[f];
        const uint32_t w0 = topology.weld[t[0]], w1 = topology.weld[t[1]], w2 = topology.weld[t[2]];
        if (w0 == w1 || w1 == w2 || w0 == w2) continue;
        const uint32_t c = (w0 != ia && w0 != ib) ? w0 : (w1 != ia && w1 != ib) ? w1 : w2;
        AlwaysFace af{};
        for (int i = 0; i < 3; ++i) {
          af.a[i] = wp[ia][i];
          af.b[i] = wp[ib][i];
          af.c[i] = wp[c][i];
        }
        // Its plane for the float filter, as a BVH face's (a zero record when ill-conditioned:
        // its value 0 is never beyond the tolerance, so orient_eps decides it every time).
        const size_t k = always_faces_.size();
        if (k % 4 == 0) always_blocks_.emplace_back();
        const FaceDual fd = face_dual(wp[ia], wp[ib], wp[c], origin_, scale_);
        if (fd.ok) {
          for (int i = 0; i < 4; ++i) always_blocks_.back().g[i][k % 4] = float(fd.g[i]);
          eta_always = std::max(eta_always, fd.eta);
          amax_always = std::max(amax_always, ((wp[ia].cast<double>() - origin_) * scale_).cwiseAbs().sum());
        }
        always_faces_.push_back(af);
      }
      always_end_.push_back(uint32_t(always_faces_.size()));
      continue;
    }
    eta_max = std::max({eta_max, d1.eta, d2.eta});
    const Eigen::Vector3d ap = (wp[ia].cast<double>() - origin_) * scale_;
    amax = std::max(amax, ap.cwiseAbs().sum());
    // The record's orientation. Negating both ĝ_1 and −ĝ_2 leaves the test unchanged (a record
    // is skipped iff its two values have the same sign), so each record is stored with face 1's
    // normal along its winding: N_1 = (b−a)×(c_1−a) follows the edge's index order (a < b), whose
    // direction relative to the face is arbitrary, so neighbouring edges of a smooth surface
    // would otherwise sit at ±n at random and a node mixing both could never be pruned. On a
    // consistently wound surface every record's normal is then the surface normal, and the
    // build groups neighbours by position without splitting them by sign. The sign is decided
    // combinatorially (face 1 runs b → a), so nothing about the values changes but their sign.
    const auto& t1 = mesh.triangles[faces[0]];
    const uint32_t w1[3] = {topology.weld[t1[0]], topology.weld[t1[1]], topology.weld[t1[2]]};
    DualEdge r{};
    r.flipped = (w1[0] == ib && w1[1] == ia) || (w1[1] == ib && w1[2] == ia) || (w1[2] == ib && w1[0] == ia);
    const double orient = r.flipped ? -1.0 : 1.0;
    for (int i = 0; i < 4; ++i) {
      r.g1[i] = orient * d1.g[i];
      r.g2[i] = -orient * d2.g[i];
    }
    Corners cr{};
    for (int i = 0; i < 3; ++i) {
      cr.a[i] = wp[ia][i];
      cr.b[i] = wp[ib][i];
      cr.c1[i] = wp[corner[0]][i];
      cr.c2[i] = wp[corner[1]][i];
    }
    cr.edge = e;
    crs.push_back(cr);
    BuildItem it{};
    for (int i = 0; i < 3; ++i) {
      const double x[4] = {(wp[ia][i] - origin_[i]) * scale_, (wp[ib][i] - origin_[i]) * scale_,
                           (wp[corner[0]][i] - origin_[i]) * scale_, (wp[corner[1]][i] - origin_[i]) * scale_};
      it.lo[i] = float(std::min({x[0], x[1], x[2], x[3]}));
      it.hi[i] = float(std::max({x[0], x[1], x[2], x[3]}));
      it.lo[3 + i] = float(std::min(r.g1[i], r.g2[i]));
      it.hi[3 + i] = float(std::max(r.g1[i], r.g2[i]));
    }
    for (int i = 0; i < 6; ++i) it.key[i] = 0.5f * (it.lo[i] + it.hi[i]);
    it.record = uint32_t(recs.size());
    recs.push_back(r);
    items.push_back(it);
  }
  // |ap|₁ was computed in floating point: inflate slightly.
  max_a_ = amax * (1 + 8 * kU);
  delta_coef_ = 1.01 * (eta_max + 10 * kU);
  // The always-tested faces' float filter: the leaves' bound (δ_rec) with their own η and A.
  always_max_a_ = amax_always * (1 + 8 * kU);
  always_coef_ = 1.01 * (eta_always + 10 * kU) + 1.01 * 8 * 0x1p-24;
  stats_.normal_error = eta_max;
  stats_.bvh_edges = recs.size();
  stats_.always_tested = always_.size();

  // Binned SAH build over the edges' corner boxes and normal boxes. A node is visited when the
  // query hyperplane comes within its bound's width of it: in the node's own frame (centre c)
  // that width is about Σ_i |q_i − c_i|·Δn_i + ΔD, ΔD ≈ Δn·radius + the corners' spread along the
  // normal. The cost of a set is therefore count × (Σ corner extents + ρ·Σ normal extents),
  // ρ ≈ the mean distance of a query point to a node (the frame's unit). Object-median fallback
  // below depth 48 keeps the depth bounded.
  corners_.reserve(recs.size());
  std::vector<Node> nodes;  // the binary tree, collapsed into wide_ at the end
  size_t max_depth = 0;
  constexpr int kBins = 16;
  // The node's bound in its frame: outward-rounded boxes of the endpoints' normals and of
  // D = d + n·c over every endpoint (n, d) of its records (computed in double, then widened by
  // its rounding bound 5u(|d| + |c|₁) and rounded outward).
  double c_max = 0, d_max = 0;
  auto make_node = [&](uint32_t begin, uint32_t end, const Box& box) {
    Node nd{};
    for (int i = 0; i < 3; ++i) nd.c[i] = 0.5f * (box.lo[i] + box.hi[i]);
    const double c[3] = {nd.c[0], nd.c[1], nd.c[2]};
    const double c1 = std::abs(c[0]) + std::abs(c[1]) + std::abs(c[2]);
    c_max = std::max(c_max, c1);
    constexpr double kInfD = std::numeric_limits<double>::infinity();
    double nlo[3] = {kInfD, kInfD, kInfD}, nhi[3] = {-kInfD, -kInfD, -kInfD}, dlo = kInfD, dhi = -kInfD;
    for (uint32_t k = begin; k < end; ++k) {
      const DualEdge& r = recs[items[k].record];
      for (const double* g : {r.g1, r.g2}) {
        for (int i = 0; i < 3; ++i) {
          nlo[i] = std::min(nlo[i], g[i]);
          nhi[i] = std::max(nhi[i], g[i]);
        }
        const double D = g[3] + (g[0] * c[0] + g[1] * c[1] + g[2] * c[2]);
        const double err = 5 * kU * (std::abs(g[3]) + c1) * (1 + 8 * kU);
        dlo = std::min(dlo, D - err);
        dhi = std::max(dhi, D + err);
      }
    }
    for (int i = 0; i < 3; ++i) {
      nd.nlo[i] = round_down(nlo[i]);
      nd.nhi[i] = round_up(nhi[i]);
    }
    nd.dlo = round_down(dlo * (1 + (dlo < 0 ? 2 : -2) * kU));
    nd.dhi = round_up(dhi * (1 + (dhi > 0 ? 2 : -2) * kU));
    d_max = std::max({d_max, std::abs(double(nd.dlo)), std::abs(double(nd.dhi))});
    return nd;
  };
  auto build = [&](auto&& self, uint32_t begin, uint32_t end, uint32_t depth) -> uint32_t {
    max_depth = std::max<size_t>(max_depth, depth);
    Box box, keys;
    box.clear();
    keys.clear();
    for (uint32_t k = begin; k < end; ++k) {
      box.grow(items[k].lo, items[k].hi);
      keys.grow(items[k].key, items[k].key);
    }
    const uint32_t self_index = uint32_t(nodes.size());
    nodes.push_back(make_node(begin, end, box));
    const uint32_t n = end - begin;
    if (n <= kLeafSize) {
      nodes[self_index].index = uint32_t(blocks_.size());
      nodes[self_index].count = n;
      LeafBlock blk{};
      for (uint32_t j = 0; j < kLeafSize; ++j) {
        if (j < n) {
          const DualEdge& d = recs[items[begin + j].record];
          for (int i = 0; i < 4; ++i) {
            blk.g[i][j] = float(d.g1[i]);
            blk.g[4 + i][j] = float(d.g2[i]);
          }
          corners_.push_back(crs[items[begin + j].record]);
          blk.edge[j] = crs[items[begin + j].record].edge | (d.flipped ? kFlipBit : 0u);
        } else {  // padding: both values 1e38, above any tolerance, never undecided
          blk.g[3][j] = blk.g[7][j] = 1e38f;
          corners_.push_back(Corners{});
        }
      }
      blocks_.push_back(blk);
      return self_index;
    }
    double best_cost = std::numeric_limits<double>::infinity();
    int best_axis = -1, best_bin = -1;
    auto bin_of = [&](const BuildItem& x, int axis) {
      const double ext = double(keys.hi[axis]) - double(keys.lo[axis]);
      return std::clamp(int((double(x.key[axis]) - double(keys.lo[axis])) / ext * kBins), 0, kBins - 1);
    };
    if (depth < 48) {
      // Two candidate axes: the widest of the corner keys and the widest of the normal keys.
      int widest[2] = {0, 3};
      for (int i = 1; i < 3; ++i) {
        if (keys.hi[i] - keys.lo[i] > keys.hi[widest[0]] - keys.lo[widest[0]]) widest[0] = i;
        if (keys.hi[3 + i] - keys.lo[3 + i] > keys.hi[widest[1]] - keys.lo[widest[1]]) widest[1] = 3 + i;
      }
      for (const int axis : widest) {
        if (!(keys.hi[axis] > keys.lo[axis])) continue;
        Box bins[kBins];
        uint32_t counts[kBins] = {};
        for (auto& b : bins) b.clear();
        for (uint32_t k = begin; k < end; ++k) {
          const int b = bin_of(items[k], axis);
          ++counts[b];
          bins[b].grow(items[k].lo, items[k].hi);
        }
        double right_cost[kBins] = {};
        Box acc;
        acc.clear();
        uint32_t cnt = 0;
        for (int b = kBins - 1; b > 0; --b) {
          cnt += counts[b];
          acc.grow(bins[b].lo, bins[b].hi);
          right_cost[b] = cnt ? acc.cost() * cnt : 0;
        }
        acc.clear();
        cnt = 0;
        for (int b = 0; b < kBins - 1; ++b) {
          cnt += counts[b];
          acc.grow(bins[b].lo, bins[b].hi);
          if (cnt == 0 || cnt == n) continue;
          const double cost = acc.cost() * cnt + right_cost[b + 1];
          if (cost < best_cost) {
            best_cost = cost;
            best_axis = axis;
            best_bin = b;
          }
        }
      }
    }
    uint32_t mid = begin;
    if (best_axis >= 0) {
      mid = uint32_t(std::partition(items.begin() + begin, items.begin() + end,
                                    [&](const BuildItem& x) { return bin_of(x, best_axis) <= best_bin; }) -
                     items.begin());
    }
    if (mid == begin || mid == end) {  // object median on the widest key axis
      int axis = 0;
      for (int i = 1; i < 6; ++i)
        if (keys.hi[i] - keys.lo[i] > keys.hi[axis] - keys.lo[axis]) axis = i;
      mid = begin + n / 2;
      std::nth_element(items.begin() + begin, items.begin() + mid, items.begin() + end,
                       [axis](const BuildItem& x, const BuildItem& y) { return x.key[axis] < y.key[axis]; });
    }
    self(self, begin, mid, depth + 1);
    const uint32_t right = self(self, mid, end, depth + 1);
    nodes[self_index].index = right;
    nodes[self_index].count = 0;
    return self_index;
  };
  if (!items.empty()) build(build, 0, uint32_t(items.size()), 1);
  collapse_wide(nodes);
  // Wide nodes and the walk's queue tag leaf blocks with bit 31 (kLeafBit).
  PRT_CHECK(wide_.size() < (size_t(1) << 31) && blocks_.size() < (size_t(1) << 31));
  // Leaf blocks tag flipped records with bit 31 of their edge index (kFlipBit).
  PRT_CHECK(E < (size_t(1) << 31));
  // A node's bound is evaluated in float: q rounded to float (uf|q_i|), x = q − c, the products
  // with box normals ≤ 1 + uf and the sum of four terms: at most 7uf(|q|₁ + |c|₁ + |D|),
  // uf = 2⁻²⁴; 10uf, and δ_node rounded to float upward by the 1.01, cover it.
  node_coef_ = 1.01 * 10 * 0x1p-24;
  // Leaf values in float: |ĝ_f − ĝ| ≤ uf|ĝ| per component (|n| ≤ 1, |d| ≤ A), q rounded to
  // float (uf|q_i|), and the float evaluation's γ₄: at most 6.01uf(|q|₁ + A); 8uf covers it.
  record_coef_ = 1.01 * 8 * 0x1p-24;
  node_const_ = c_max + d_max;
  stats_.bvh_nodes = wide_.size();
  stats_.bvh_depth = max_depth;
}

// The binary tree as a 4-wide one: each wide node holds up to four children's bounds side by
// side (one fetch tests them all, and a child that fails is never fetched). A node's children
// are its binary children, the largest inner one (by records under it) replaced by its own two
// children while fewer than four; empty slots have D = +∞ and never pass.
void ContourFinder::collapse_wide(const std::vector<Node>& binary) {
  static_assert(sizeof(WideNode) == 192);  // three cache lines, prefetched by the walk
  if (binary.empty()) return;
  // Records under each binary node (leaf counts summed), for choosing which child to open.
  std::vector<uint32_t> under(binary.size(), 0);
  for (size_t i = binary.size(); i-- > 0;)
    under[i] = binary[i].count ? binary[i].count : under[i + 1] + under[binary[i].index];
  auto fill = [&](auto&& self, std::vector<uint32_t> slots, uint32_t at) -> void {
    while (slots.size() < 4) {
      int open = -1;
      for (size_t k = 0; k < slots.size(); ++k)
        if (binary[slots[k]].count == 0 && (open < 0 || under[slots[k]] > under[slots[size_t(open)]])) open = int(k);
      if (open < 0) break;
      const uint32_t b = slots[size_t(open)];
      slots[size_t(open)] = b + 1;
      slots.push_back(binary[b].index);
    }
    for (size_t k = 0; k < 4; ++k) {
      WideNode& w = wide_[at];
      if (k >= slots.size()) {
        for (int i = 0; i < 3; ++i) w.c[i][k] = w.nlo[i][k] = w.nhi[i][k] = 0;
        w.dlo[k] = w.dhi[k] = std::numeric_limits<float>::infinity();
        w.child[k] = kLeafBit;  // a leaf never entered
        continue;
      }
      const Node& nd = binary[slots[k]];
      for (int i = 0; i < 3; ++i) {
        w.c[i][k] = nd.c[i];
        w.nlo[i][k] = nd.nlo[i];
        w.nhi[i][k] = nd.nhi[i];
      }
      w.dlo[k] = nd.dlo;
      w.dhi[k] = nd.dhi;
      if (nd.count) {
        w.child[k] = nd.index | kLeafBit;
      } else {
        const uint32_t child = uint32_t(wide_.size());
        wide_.emplace_back();
        wide_[at].child[k] = child;
        self(self, {slots[k] + 1, binary[slots[k]].index}, child);
      }
    }
  };
  wide_.emplace_back();
  if (binary[0].count)
    fill(fill, {0}, 0);
  else
    fill(fill, {1, binary[0].index}, 0);
}

size_t ContourFinder::edge_count() const { return topology_->edges.size(); }
size_t ContourFinder::bvh_node_count() const { return wide_.size(); }

int ContourFinder::side_sum_slow(uint32_t edge, const Eigen::Vector3d& p, const Eigen::Vector3d& n,
                                 const Eigen::Vector3d* tie) const {
  const auto& topo = *topology_;
  const auto [ia, ib] = topo.edges[edge];
  const Eigen::Vector3d a = topo.welded_positions[ia].cast<double>(), b = topo.welded_positions[ib].cast<double>();
  int sum = 0;
  for (const uint32_t f : topo.faces_of_edge(edge)) {
    const auto& t = mesh_->triangles[f];
    const uint32_t w0 = topo.weld[t[0]], w1 = topo.weld[t[1]], w2 = topo.weld[t[2]];
    if (w0 == w1 || w1 == w2 || w0 == w2) continue;
    const uint32_t c = (w0 != ia && w0 != ib) ? w0 : (w1 != ia && w1 != ib) ? w1 : w2;
    sum += orient_eps(a, b, topo.welded_positions[c].cast<double>(), p, n, tie);
  }
  return sum;
}

void ContourFinder::find_brute_force(const ShadePoint& point, std::vector<ContourEdge>& out) const {
  out.clear();
  const uint32_t E = uint32_t(topology_->edges.size());
  for (uint32_t e = 0; e < E; ++e) {
    const int s = side_sum_slow(e, point.p, point.n, tie_break(point));
    if (s != 0) out.push_back({e, s});
  }
}

void ContourFinder::find(const ShadePoint& point, std::vector<ContourEdge>& out, ContourQueryStats* stats) const {
  if (stats)
    find_impl<true>(point, out, stats);
  else
    find_impl<false>(point, out, nullptr);
}

template <bool Count>
void ContourFinder::find_impl(const ShadePoint& point, std::vector<ContourEdge>& out, ContourQueryStats* stats) const {
  out.clear();
  ContourQueryStats work;
  if constexpr (Count) work.queries = 1;
  {  // A point beyond the float bounds' range (or not finite): every edge, the reference way.
    const Eigen::Vector3d q = (point.p - origin_) * scale_;
    if (!(std::abs(q.x()) + std::abs(q.y()) + std::abs(q.z()) < 1e30)) {
      find_brute_force(point, out);
      return;
    }
  }
  // Results go to a per-thread bitmap over the edges (plus their sums) and are read back in edge
  // order: O(K + E/64) instead of sorting K results found in leaf order. The buffers only grow.
  thread_local std::vector<uint64_t> tl_bits;
  thread_local std::vector<int32_t> tl_sums;
  const size_t E = topology_->edges.size(), words = (E + 63) / 64;
  if (tl_bits.size() < words) tl_bits.resize(words, 0);
  if (tl_sums.size() < E) tl_sums.resize(E);
  uint64_t* bits = tl_bits.data();
  int32_t* sums = tl_sums.data();
  auto emit = [bits, sums](uint32_t e, int s) {
    sums[e] = s;
    bits[e >> 6] |= uint64_t(1) << (e & 63);
  };
  const double p[3] = {point.p.x(), point.p.y(), point.p.z()};
  const double nn[3] = {point.n.x(), point.n.y(), point.n.z()};
  const double* tt = tie_break(point) ? point.t.data() : nullptr;
  if constexpr (Count) work.always = always_.size();
  if (!always_.empty()) {
    // side_sum_slow from the stored corners, each face's σ first from its plane in float, four
    // faces at a time, as in the leaves: v = ĝ·(q, 1) ∝ π(p), σ = −sign π when |v| exceeds the
    // rigorous tolerance (the constructor's always_coef_), else orient_eps decides (kUndecided).
    constexpr int8_t kUndecided = 2;
    thread_local std::vector<int8_t> tl_sigma;
    if (tl_sigma.size() < 4 * always_blocks_.size()) tl_sigma.resize(4 * always_blocks_.size());
    int8_t* const sigma = tl_sigma.data();
    const double q[3] = {(p[0] - origin_.x()) * scale_, (p[1] - origin_.y()) * scale_, (p[2] - origin_.z()) * scale_};
    const f4 qx = splat(float(q[0])), qy = splat(float(q[1])), qz = splat(float(q[2]));
    const f4 da = splat(float(always_coef_ * ((std::abs(q[0]) + std::abs(q[1]) + std::abs(q[2])) + always_max_a_)));
    for (size_t b = 0; b < always_blocks_.size(); ++b) {
      const FaceBlock& fb = always_blocks_[b];
      const f4 v = load(fb.g[0]) * qx + load(fb.g[1]) * qy + load(fb.g[2]) * qz + load(fb.g[3]);
      const unsigned pos = lanes(v > da), neg = lanes(v < -da);
      for (int j = 0; j < 4; ++j)
        sigma[4 * b + size_t(j)] = (pos >> j & 1u) ? int8_t(-1) : (neg >> j & 1u) ? int8_t(1) : kUndecided;
    }
    for (size_t i = 0, f = 0; i < always_.size(); ++i) {
      int s = 0;
      for (; f < always_end_[i]; ++f) {
        if (sigma[f] != kUndecided) {
          s += sigma[f];
          continue;
        }
        if constexpr (Count) ++work.exact;
        const AlwaysFace& af = always_faces_[f];
        s += orient_eps_f(af.a, af.b, af.c, p, nn, tt);
      }
      if (s != 0) emit(always_[i], s);
    }
  }
  if (!wide_.empty()) {
    const double q[4] = {(p[0] - origin_.x()) * scale_, (p[1] - origin_.y()) * scale_, (p[2] - origin_.z()) * scale_,
                         1.0};
    const double delta = delta_coef_ * ((std::abs(q[0]) + std::abs(q[1]) + std::abs(q[2])) + max_a_);
    const float delta_rec =
        float(delta + record_coef_ * ((std::abs(q[0]) + std::abs(q[1]) + std::abs(q[2])) + max_a_));
    // Node bounds in float (see node_coef_).
    const float delta_node =
        float(delta + node_coef_ * ((std::abs(q[0]) + std::abs(q[1]) + std::abs(q[2])) + node_const_));
    const f4 qx = splat(float(q[0])), qy = splat(float(q[1])), qz = splat(float(q[2]));
    const f4 dn = splat(delta_node), dr = splat(delta_rec);
    // Breadth-first: a FIFO of wide nodes and leaf blocks (bit 31), each prefetched when queued
    // and read many steps later, so the walk streams memory instead of waiting on each fetch.
    // Besides the root, only slots of fetched wide nodes are queued, and a wide node is queued by
    // its one parent slot: at most 1 + 4 × (wide nodes) items, the buffer's size before the walk.
    thread_local std::vector<uint32_t> tl_queue;
    if (tl_queue.size() < 4 * wide_.size() + 1) tl_queue.resize(4 * wide_.size() + 1);
    uint32_t* const queue = tl_queue.data();
    size_t tail = 0;
    queue[tail++] = 0;
    const WideNode* wide = wide_.data();
    const LeafBlock* blocks = blocks_.data();
    for (size_t head = 0; head < tail; ++head) {
      const uint32_t item = queue[head];
      if (item & kLeafBit) {
        const uint32_t block = item & ~kLeafBit;
        if constexpr (Count) work.records += kLeafSize;
        // Both face values of the leaf's four records at once; only undecided ones branch.
        // v1 ∝ π_1 (σ_1 = −sign v1), v2 ∝ −π_2 (σ_2 = sign v2) whenever |v| > δ_rec, both
        // negated for a flipped record.
        const LeafBlock& blk = blocks[block];
        const f4 v1 = load(blk.g[0]) * qx + load(blk.g[1]) * qy + load(blk.g[2]) * qz + load(blk.g[3]);
        const f4 v2 = load(blk.g[4]) * qx + load(blk.g[5]) * qy + load(blk.g[6]) * qz + load(blk.g[7]);
        const i4 same = ((v1 > dr) & (v2 > dr)) | ((v1 < -dr) & (v2 < -dr));
        for (unsigned live = ~lanes(same) & 0xFu; live != 0; live &= live - 1) {
          const int j = std::countr_zero(live);
          const size_t at = size_t(block) * kLeafSize + size_t(j);
          const uint32_t edge = blk.edge[j] & ~kFlipBit;
          const int two = (blk.edge[j] & kFlipBit) ? -2 : 2;  // a flipped record's values are negated
          int s;
          if (v1[j] > delta_rec && v2[j] < -delta_rec) {
            s = -two;
          } else if (v1[j] < -delta_rec && v2[j] > delta_rec) {
            s = two;
          } else {
            if constexpr (Count) ++work.exact;
            const Corners& c = corners_[at];
            s = orient_eps_f(c.a, c.b, c.c1, p, nn, tt) + orient_eps_f(c.a, c.b, c.c2, p, nn, tt);
          }
          if (s != 0) emit(edge, s);
        }
        continue;
      }
      const WideNode& w = wide[item];
      if constexpr (Count) work.nodes += 4;
      // Per child: the range of n·(q − c) + D over its box (per axis the smaller / larger
      // product), four children at once.
      f4 vmin = load(w.dlo), vmax = load(w.dhi);
      const f4 q3[3] = {qx, qy, qz};
      for (int i = 0; i < 3; ++i) {
        const f4 x = q3[i] - load(w.c[i]);
        const f4 a = x * load(w.nlo[i]), b = x * load(w.nhi[i]);
        vmin += min4(a, b);
        vmax += max4(b, a);  // a < b ? b : a
      }
      for (unsigned pass = lanes((vmin <= dn) & (vmax >= -dn)); pass != 0; pass &= pass - 1) {
        const int k = std::countr_zero(pass);
        const uint32_t child = w.child[k];
        if (!(child & kLeafBit)) {
          for (int line = 0; line < int(sizeof(WideNode)); line += 64)
            __builtin_prefetch(reinterpret_cast<const char*>(wide + child) + line);
        } else {
          const char* blk = reinterpret_cast<const char*>(blocks + (child & ~kLeafBit));
          __builtin_prefetch(blk);
          __builtin_prefetch(blk + 64);
          __builtin_prefetch(blk + 128);
        }
        queue[tail++] = child;
      }
    }
  }
  for (size_t w = 0; w < words; ++w) {
    uint64_t b = bits[w];
    if (b == 0) continue;
    bits[w] = 0;
    do {
      const uint32_t e = uint32_t(w * 64 + size_t(std::countr_zero(b)));
      out.push_back({e, sums[e]});
      b &= b - 1;
    } while (b != 0);
  }
  if constexpr (Count) {
    stats->queries += work.queries;
    stats->nodes += work.nodes;
    stats->records += work.records;
    stats->exact += work.exact;
    stats->always += work.always;
  }
}

}  // namespace prt::bake
