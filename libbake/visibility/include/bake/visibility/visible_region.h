// bake/visibility/visible_region.h — the part of a light's spherical polygon not hidden by occluders, as the
// boundary arcs of L \ (O_1 ∪ … ∪ O_K), seen from a shade point (paper 003 §3 "P̂ = P′ − O′",
// §3.6 and Alg. 1 lines 8–12; §4.4 the per-triangle variant; issue 13; docs/ARCHITECTURE.md
// "Conventions"). Integrate the result with bake/sphere/spherical_polygon.h (Arc overloads) and
// bake/sphere/polygon_sh.h.
//
// Input: the light L (convex, positively oriented, e.g. already clipped to the horizon) and the
// occluders O_k (each convex, positively oriented as seen from p, with non-zero area, inside an
// open hemisphere): the silhouette loop of a convex occluder, or each front-facing triangle of a
// mesh (the per-triangle variant). Overlapping occluders are a union: nothing is subtracted
// twice (the paper subtracts them one by one with Greiner–Hormann in a gnomonic plane, §3.6).
//
// Method: no polygon clipping. Every edge e = (a, b) of every polygon is cut into the pieces
// where the polygons' memberships are constant, and a piece is kept where it separates the
// visible region V = L ∩ ¬O_1 ∩ … from its complement: a light edge where its left side is in
// no occluder (kept forward), an occluder edge where its right side is in L and in no other
// occluder (kept reversed, so V stays on the left). Because every integral here is a sum over
// boundary arcs, the kept pieces are the answer; they need not be chained into loops.
// Predicates: the side of a vertex x of one polygon with respect to the great circle of an edge
// (c, d) of another is the exact sign of det(c, d, x) (orient3d_exact of bake/visibility/contour.h with the
// origin at p); inside a convex polygon means strictly inside every edge's half-space. Sides are
// taken just left (and just right) of the edge being cut: when the edge lies on the other edge's
// great circle the side is the sign of m_e·m_f (m = the edges' plane normals), decided exactly
// as sign(det(a, b, q))·sign(det(c, d, q)) with q a vertex of the other polygon off that circle.
// So containment, disjointness, shared edges and vertices on edges are decided exactly: an
// occluder containing the light leaves no arc at all (E = 0 exactly). Along one edge, crossing
// points are ordered by their floating-point parameters |det_a|/(|det_a| + |det_b|); equal
// vertices give equal parameters exactly, and an ordering error between distinct crossings moves
// a boundary piece by the crossing points' rounding. Pieces lying on a common great circle of
// several polygons are kept once, by the polygon listed first (the light, then occluders in order).
// Depth is not looked at: every occluder passed is subtracted, so the caller passes those between
// p and the light (paper §3.5 GetBetween culls by a frustum); an occluder behind the light must
// not be passed. Occluders need no horizon clipping (only their parts over the light matter).
// Cost: O(E²) for E edges in total (every edge against every other polygon's edges), each pair
// first filtered by bounding caps (the edge's and the polygon's, compared by one dot product with
// a 1e-12 margin; disjoint caps can only give empty cuts, so skipping them changes nothing but
// spurious cuts of rounding), and a vertex shared bitwise (adjacent triangles) given side 0
// without the exact expansion; measured by bench/bench_area.cpp (silhouette loops ~3× faster
// than per-triangle for three boxes).
#pragma once

#include <bake/sphere/spherical_polygon.h>

#include <Eigen/Core>

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace prt::bake {

// out = the boundary arcs of light \ ∪ occluders (cleared first). Vertices are directions from
// the shade point (points relative to it will do).
void visible_region(std::span<const Eigen::Vector3d> light, std::span<const std::vector<Eigen::Vector3d>> occluders,
                    std::vector<Arc>& out);

// Scratch for visible_region_sparse, reused across calls (one per thread); copying one gives a
// fresh scratch. After a call: the occluder edges it cut (those of `boundary` reaching inside the
// light) and whether the chart below was used (false: every pair filtered by caps only).
class RegionScratch {
public:
  RegionScratch();
  ~RegionScratch();
  RegionScratch(const RegionScratch&);
  RegionScratch& operator=(const RegionScratch&);

  size_t boundary_edges = 0;
  bool charted = false;

private:
  struct Impl;
  friend void visible_region_sparse(std::span<const Eigen::Vector3d>, std::span<const std::vector<Eigen::Vector3d>>,
                                    std::span<const uint8_t>, std::vector<Arc>&, RegionScratch&);
  std::unique_ptr<Impl> impl_;
};

// The same boundary arcs as visible_region(light, occluders), cutting only the occluder edges
// that may bound the union, each against the occluders near it (issue 32; paper 003 §3.3: the
// union's boundary lies on silhouette edges). boundary[k] has bit e set when edge e (vertices
// e, e + 1) of occluders[k] may bound it (edges e ≥ 8 always do). Precondition: an edge left out
// emits nothing in visible_region — its right side is inside another occluder along the whole
// edge (a mesh edge whose two faces' images lie on opposite sides of it), or it is the same arc
// as an edge of an occluder listed before it (a fold: that edge owns the arc). Then the arcs are
// visible_region's, up to cuts of rounding size.
// Each edge (the light's, and the in-light part of each boundary edge) meets only the occluders
// near it, found in a uniform grid (≈ √P cells a side) over the gnomonic chart about the light's
// cap centre c (ω ↦ (e1·ω, e2·ω)/(c·ω); great circles map to lines, convex polygons to the
// hulls of their vertices' points, orientation kept): the occluders in the cells the edge's chord
// passes, whose boxes meet the chord's box, and whose vertices' points may lie on the side that
// matters (the light edge's left, an occluder edge's right) as well as on or across the edge's
// great circle (or, for an earlier occluder, two on it: a shared arc). Boxes carry a margin of
// 1e-9 of the chart's scale and sides a slack far above the rounding of the chart points and of
// a × b, so every occluder the exact predicates could find is kept: the grid is a filter like
// visible_region's caps. Occluders reaching out of c's hemisphere (c·ω̂ ≤ 1e-3) are tested by
// every edge; a light of ≥ 84° radius (a vertex at c·ω̂ ≤ 0.1) is not charted, and then every
// pair is filtered by caps only (RegionScratch::charted = false).
// Cost: O(P + G + B·k) for P occluders, G grid entries, B boundary edges reaching into the light
// and k occluders near each (bench/bench_area.cpp BM_BunnyQuad).
void visible_region_sparse(std::span<const Eigen::Vector3d> light, std::span<const std::vector<Eigen::Vector3d>> occluders,
                           std::span<const uint8_t> boundary, std::vector<Arc>& out, RegionScratch& scratch);

// A convex polyhedron (an occluder or a convex emitter) and its silhouette loop seen from a point
// (paper 003 §3.3, Alg. 2 SphPolySilhouette). Faces are planar, counter-clockwise seen from
// outside. A face is front-facing from p when det(v0 − p, v1 − p, v2 − p) < 0 (p strictly on its
// outer side; orient3d_exact, so the decision is exact and a face seen edge-on is not front-facing).
// The silhouette edges are the edges of front faces whose other face is not front-facing; each is
// taken against its front face's direction (a front face runs clockwise in this file's positive
// sense), and they chain into one loop because the body is convex. This replaces Alg. 2's
// nearest-endpoint ordering in a gnomonic plane by the mesh's adjacency.
class ConvexPolyhedron {
public:
  // Precondition (PRT_CHECK): every face has ≥ 3 vertex indices in range, and every directed edge
  // (u, v) of a face has exactly one twin (v, u) in another face (a closed, consistently oriented
  // surface).
  ConvexPolyhedron(std::vector<Eigen::Vector3d> vertices, std::vector<std::vector<uint32_t>> faces);

  // out = the silhouette loop seen from p, as points relative to p (positively oriented, ready for
  // visible_region). Returns false, with out empty, when no face is front-facing: p is inside the
  // closed body or on its surface, and the body hides the whole sphere (E = 0 for every light).
  // A face whose plane contains p (seen edge-on) is not front-facing and its image is part of the
  // loop's edges; p ON a face is a degenerate view (that face's image is a great circle) left to
  // the caller (e.g. decide by the normal: paper 001's ε-limit rule).
  bool silhouette(const Eigen::Vector3d& p, std::vector<Eigen::Vector3d>& out) const;

  // out = the front-facing faces seen from p, each fanned into triangles relative to p and
  // positively oriented: the per-triangle variant (paper 003 §4.4).
  void front_triangles(const Eigen::Vector3d& p, std::vector<std::vector<Eigen::Vector3d>>& out) const;

  const std::vector<Eigen::Vector3d>& vertices() const { return vertices_; }

private:
  bool front_facing(size_t face, const Eigen::Vector3d& p) const;

  std::vector<Eigen::Vector3d> vertices_;
  std::vector<std::vector<uint32_t>> faces_;
  std::vector<std::vector<uint32_t>> twin_face_;  // [face][k]: the face across edge (k, k+1)
};

} // namespace prt::bake
