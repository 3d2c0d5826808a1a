// bake/integrators/hot_texels.h — the environment's hot texels (suns) integrated exactly over their visible
// part, for the silhouette integrator's radiance columns (paper 001 §4, band-1 shadowed radiance
// R and the shadowed radiance S; issue 27).
//
// Why: the silhouette integrator integrates the environment along u-isolines with the integrand
// box-filtered per cell (bake/sphere/isoline_tables.h). For a sun of 10^4–10^5 × the mean radiance, a
// shadow edge or the horizon crossing it leaves a discretisation error of first order in the
// isoline spacing that no practical N removes (the band-1 error under a sunrise HDRI was 6.9e-3
// at N = 256, 3.3e-3 at N = 512). A texel is a small spherical region of constant radiance
// (the environment is piecewise constant per texel, bake/environment/envmap.h; formats/SCHEMA.md
// "Environment"): its visible part is bounded by the texel's edges and by the arcs of the depth
// complexity function W (the contour edges' arcs and the horizon, paper 001 §3.1), so its
// integral is that of a spherical region, which needs no sampling at all (paper 003 §3: the
// visible part of a light as a spherical polygon clipped by the occluders' silhouettes, then
// integrated in closed form).
//
// How, per shade point (the arcs and W0, the depth complexity at the spine start s0, come from the
// silhouette integrator's own walk, so both see the same occluders):
//  * Hot texels (≥ hot_factor × the mean luminance, at most max_texels of the brightest) are
//    grouped in clusters (8 × 8 image tiles) with a bounding cap, and the clusters in a binary
//    tree of caps. An arc is local to a cap when its great arc comes within the cap's radius of
//    the centre (exact test: the nearest point of the arc is an end or the foot of the centre on
//    its great circle), after a cheaper test of the two caps.
//  * W at the root's reference point is W0 plus the steps of the arcs crossed by the great arc
//    from s0 (dcf_path_steps); down the tree, W is carried from a node's reference point to its
//    children's along short arcs inside the node's cap, testing only the arcs that meet it; in a
//    cluster, an arc that crosses the whole cap steps W where a texel's reference point lies on
//    the other side of its great circle, the others by paths. Reference points sit off centre by
//    odd fractions, and waypoints off the axis planes, so that no arc of an axis-aligned scene
//    (nor the horizon's quarter arcs) passes through a path's end by symmetry. A texel that no
//    local arc meets is wholly visible (W = 0: its precomputed integral) or wholly hidden.
//  * A texel cut by arcs is decomposed in its gnomonic chart (centred on the texel, where great
//    arcs are straight segments): strips between every segment end and every crossing of two
//    segments; in a strip the segments cut it into bands of one W each (W below them from a
//    straight path, i.e. a great arc, from the reference point); each band with W = 0 is the
//    texel's polygon clipped by the strip's sides and the band's segment lines, integrated by
//    PolygonSH's closed form (orders ≤ 12, bake/sphere/polygon_sh.h), or above order 12 as its
//    trapezoids by an n × n Gauss–Legendre rule (dω = (1 + x² + y²)^(−3/2) dx dy; n grows with
//    order × size so that the rule's error is below 1e-12 relative). One arc across the whole
//    texel is one clip. Slivers under 1e-13 of the texel's chart box are left out (their
//    vertices lie on one great circle, where the closed form cannot tell a sliver from a
//    hemisphere).
//  * A lat-long texel's parallels are small circles: EnvMap::texel_polygon splits them into
//    great-arc chords within 1e-6 of the texel's solid angle; cube texels are exact.
// The only approximations left are that chord bound, the sliver cut and rounding: the result does
// not depend on the isoline count N at all.
#pragma once

#include <bake/environment/envmap.h>

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace prt::bake {

// A piece of the boundary of the depth-complexity function W (paper 001 §3.1): the great arc
// a → b (octahedral-frame coordinates, any positive lengths, shorter than π; m = a × b), across
// which W steps by sign(m·t) · side_sum for travel direction t.
struct DcfArc {
  Eigen::Vector3d a, b, m;
  int side_sum = 0;
};

// Change of W along the great arc from P to Q (shorter than π): the sum of the steps of every arc
// it crosses.
int dcf_path_steps(std::span<const DcfArc> arcs, const Eigen::Vector3d& P, const Eigen::Vector3d& Q);

class HotTexels {
public:
  // The hot texels of `env` (>= hot_factor × info().mean_luminance and > 0; only the max_texels
  // brightest when more are), in the frame `frame_from_world` (a rotation) the arcs will be
  // given in; SH moments up to `order` (>= 1) in the world frame's basis (prtshade/sh.h).
  HotTexels(const EnvMap& env, const Eigen::Matrix3d& frame_from_world, int order, double hot_factor,
            size_t max_texels);
  ~HotTexels();
  HotTexels(const HotTexels&) = delete;
  HotTexels& operator=(const HotTexels&) = delete;

  size_t texels() const noexcept;
  size_t clusters() const noexcept;
  int order() const noexcept;
  bool empty() const noexcept { return texels() == 0; }
  // Per texel of the map (texel_count() entries): whether it is hot.
  bool is_hot(int texel) const noexcept;

  // Moments are laid out per colour: [c · order² + i] = Σ_texels L_c(t) ∫ y_i dω, c = R, G, B.
  size_t width() const noexcept { return size_t(3 * order() * order()); }
  // Over the whole of every hot texel (V ≡ 1).
  const std::vector<double>& unoccluded() const noexcept;

  // out[0 … width()) += the moments over the part of every hot texel where W = 0, W being W0 at
  // the frame direction s0 and stepping across `arcs` (the whole boundary of W: contour arcs and
  // the horizon).
  void accumulate(std::span<const DcfArc> arcs, const Eigen::Vector3d& s0, int W0, double* out) const;

  // The same moments of one texel's part where W = 0 (tests): W at the texel's reference point
  // from W0 at s0 directly, not down the cluster tree as in accumulate().
  std::vector<double> texel_moments(int texel, std::span<const DcfArc> arcs, const Eigen::Vector3d& s0, int W0) const;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

} // namespace prt::bake
