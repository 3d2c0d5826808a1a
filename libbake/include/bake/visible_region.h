// bake/visible_region.h — the part of a light's spherical polygon not hidden by occluders, as the
// boundary arcs of L \ (O_1 ∪ … ∪ O_K), seen from a shade point (paper 003 §3 "P̂ = P′ − O′",
// §3.6 and Alg. 1 lines 8–12; §4.4 the per-triangle variant; issue 13; docs/ARCHITECTURE.md
// "Conventions"). Integrate the result with bake/spherical_polygon.h (Arc overloads) and
// bake/polygon_sh.h.
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
// (c, d) of another is the exact sign of det(c, d, x) (orient3d_exact of bake/contour.h with the
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
// Cost: O(E²) for E edges in total (every edge against every other polygon's edges).
#pragma once

#include <bake/spherical_polygon.h>

#include <Eigen/Core>

#include <span>
#include <vector>

namespace prt::bake {

// out = the boundary arcs of light \ ∪ occluders (cleared first). Vertices are directions from
// the shade point (points relative to it will do).
void visible_region(std::span<const Eigen::Vector3d> light, std::span<const std::vector<Eigen::Vector3d>> occluders,
                    std::vector<Arc>& out);

} // namespace prt::bake
