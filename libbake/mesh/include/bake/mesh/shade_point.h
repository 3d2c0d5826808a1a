// bake/mesh/shade_point.h — the point every visibility query and integrator is evaluated at: a
// position on (or off) a mesh, its normal, the limit from which it sees its own surface, and the
// welded vertex it sits on (docs/ARCHITECTURE.md §3). Shared by the visibility module (contour
// search, ray counts, occluder unions) and the integrators, so neither depends on the other.
#pragma once

#include <Eigen/Core>

#include <cstdint>

namespace prt::bake {

// A point to integrate at. Visibility is the limit from just above the surface, p + εn, ε → 0+
// (docs/ARCHITECTURE.md §3), for EVERY triangle, with no ε offset: the triangles of its 1-ring
// when `welded` names a welded mesh position (bake/mesh/mesh.h Topology) occlude exactly as they do in
// that limit (a concave ring occludes, a flat one does not), and so do triangles that pass
// through or near p without a corner there (T-junctions: p on another object's edge or face;
// coplanar overlapping sheets; duplicated faces; bake/visibility/raycast.h NearTriangles, bake/visibility/contour.h).
// welded = -1 is a free point in space (no 1-ring; the same limit for every other triangle).
struct ShadePoint {
  Eigen::Vector3d p{0, 0, 0};
  Eigen::Vector3d n{0, 0, 1};  // unit; defines H(ω,n) = [n·ω > 0]
  // Second-order tie-break: the limit point is p + εn + ε²t. It decides only triangles whose
  // plane contains p + εn itself (p in the plane and n parallel to it: a single-sheet wall's foot
  // on a floor, with a horizontal normal): t points into the point's own surface, so the foot
  // is on the floor's upper side. 0: none (such triangles then block nothing).
  Eigen::Vector3d t{0, 0, 0};
  int64_t welded = -1;
  // false: full-sphere mode, H ≡ 1 in every integrand (the FIV products: ∫ V L y_1m dω over the
  // whole sphere). n then only sets the side the limit p + εn is taken from.
  bool hemisphere = true;
};

} // namespace prt::bake
