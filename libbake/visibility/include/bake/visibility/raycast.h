// bake/visibility/raycast.h — Embree 3 ray queries with the visibility semantics of prtbake: a shade point
// sees from p + εn, ε → 0+ (bake/integrators/integrator.h). Shared by the QMC integrator (occlusion rays)
// and the silhouette integrator (one counted ray per shade point: the depth complexity W at a
// start direction, from which the DCF walk propagates; paper 001 §3.2, made robust: no
// "minimum W is 0" assumption).
//
// The shade point's own 1-ring (every triangle with a corner welded to it) is removed from
// Embree's answers by a filter and decided analytically: occludes_from_above where its float test
// is clear, else the exact segment test below (a fin standing on the face from p along n puts
// every direction within the float test's rounding: docs/RELIABILITY.md). So are the
// triangles near p (NearTriangles: within rho, e.g. a floor or wall passing through the vertex at
// a T-junction, a coplanar overlapping sheet, a near-duplicate shell), for every ray, visibility
// and counted alike: they are decided by the exact ε-limit orientation predicate orient_eps
// (bake/visibility/contour.h). In counted rays a far hit whose barycentrics put it on a triangle's edge makes
// the count ambiguous: the caller picks another direction.
#pragma once

#include <bake/mesh/mesh.h>
#include <bake/mesh/shade_point.h>

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <vector>

namespace prt::bake {

// True if the triangle (p, a, b), p the shade point, blocks direction d as seen from p + εn for
// all small ε > 0: the ray p + εn + t d meets the plane at t = ε s, s = -(m·n)/(m·d), m = (a-p)×(b-p);
// blocked iff s > 0 and n + s d lies in the cone spanned by a-p and b-p. Zero-area: never blocks.
// `ambiguous` (optional) is set when the answer is within rounding of flipping (d on the cone's
// boundary or parallel to the plane).
// With a tie-break t (ShadePoint::t), a triangle whose plane contains p + εn (m·n = 0) blocks d
// iff −(m·t)/(m·d) > 0 and n lies in the cone: the ray from p + εn + ε²t meets the plane ahead,
// at a point seen from p in direction n.
bool occludes_from_above(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                         const Eigen::Vector3d& n, const Eigen::Vector3d& d, bool* ambiguous = nullptr,
                         const Eigen::Vector3d* t = nullptr);

// Squared distance from p to the triangle (a, b, c), in double: the closest point by the regions
// of the triangle's plane (corners, edges, face; Ericson, "Real-Time Collision Detection" §5.1.5);
// a zero-area triangle is its three edges.
double squared_distance_to_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                    const Eigen::Vector3d& c);

struct CrossingCount {
  int count = 0;           // triangles the ray from p + εn crosses (its depth complexity W)
  bool ambiguous = false;  // the direction grazes an edge: choose another direction
};

// The triangles near a shade point that float ray tests cannot be trusted with: every triangle
// outside the point's welded 1-ring that comes within rho of p (its exact distance, in double). Rays
// from the point decide them exactly (the segment from p + εn to a point beyond the scene, with
// the ε-limit orientation predicates of bake/visibility/contour.h); Embree decides the rest. This is what
// makes T-junctions (p on another object's edge or face), coplanar overlaps, duplicated faces and
// near-duplicate shells exact for both integrators: the 1-ring alone does not see them.
struct NearTriangles {
  struct Test {                 // a near triangle with area as seen from p + εn, decided exactly
    Eigen::Vector3d a, b, c;
    int side;                   // orient_eps(a, b, c, p, n): the side of its plane p + εn is on (±1)
    uint32_t prim;              // its index in the mesh's triangles
  };
  std::vector<uint32_t> prims;  // every near triangle, ascending: Embree skips them
  std::vector<Test> tests;      // those of them that can block (side ≠ 0), in the order of prims
  double rho = 0;               // 2e-4 · mesh diagonal + 2e-6 · max|p_i|: well above float hit-test error near p
};

struct RayHit {
  uint32_t triangle;
  float t, u, v;  // distance along the unit direction; Embree's barycentrics (weights of corners 1, 2)
};

// Where the ray that visible() decides is blocked meets the surface: the first blocking triangle,
// the point's barycentric weights there, and the side it is met from. The gather rays of
// interreflection (bake/bake/bounce.h) read the surface's exit radiance at that point.
struct SurfaceHit {
  uint32_t triangle;
  double w1, w2;  // barycentric weights of the triangle's corners 1 and 2 (corner 0: 1 − w1 − w2), each in [0, 1]
  bool front;     // met from the side its winding's normal (c1 − c0) × (c2 − c0) points to
};

// The ray queries over one mesh (an Embree BVH built once, at construction).
class RayCaster {
public:
  RayCaster(const Mesh& mesh, const Topology& topology);  // both must outlive the caster
  ~RayCaster();
  RayCaster(const RayCaster&) = delete;
  RayCaster& operator=(const RayCaster&) = delete;

  // Visibility of unit direction d from the shade point (limit from above). The second form takes
  // the point's near_triangles, computed once for all its rays. A direction through an edge or a
  // corner of a near triangle exactly (a null set) is not blocked by that triangle.
  bool visible(const ShadePoint& point, const Eigen::Vector3d& d) const;
  bool visible(const ShadePoint& point, const NearTriangles& near, const Eigen::Vector3d& d) const;
  NearTriangles near_triangles(const ShadePoint& point) const;
  // The same visibility with the distance to the first blocking triangle: nullopt when d is
  // visible, else the distance along d (a 1-ring triangle blocks at 0; a near triangle at its
  // plane's distance, in double; any other at Embree's closest hit). The sparse rays of the
  // filter integrator (bake/integrators/filter.h), which need the occluder's depth.
  std::optional<double> first_hit(const ShadePoint& point, const NearTriangles& near, const Eigen::Vector3d& d) const;
  // The same first blocker as a point on the surface (nullopt exactly when visible() is true): a
  // 1-ring triangle blocks at p itself (its corner at p, weight 1; the first in ring order); a near
  // triangle where the ray meets its plane (double, the weights clamped to the triangle); any other
  // at Embree's closest hit and barycentrics. The side is the sign of the face normal · d, so a
  // ray that enters a closed object through its surface meets it from the front.
  std::optional<SurfaceHit> first_surface_hit(const ShadePoint& point, const NearTriangles& near,
                                              const Eigen::Vector3d& d) const;
  // Whether the point's 1-ring or one of its near triangles blocks d (the exact part of visible();
  // Embree is not asked): occluders at distance ~0, a crease or a contact.
  bool blocked_nearby(const ShadePoint& point, const NearTriangles& near, const Eigen::Vector3d& d) const {
    return exact_blocker(point, near, d, true) == 0.0;
  }
  // Number of triangles the ray from p + εn in unit direction d crosses.
  CrossingCount count_crossings(const ShadePoint& point, const Eigen::Vector3d& d) const;
  // Closest triangle hit by the ray origin + t d, t in [tnear, ∞) (no 1-ring filtering; primary
  // rays of the reference renderer, view/reference.h).
  std::optional<RayHit> closest_hit(const Eigen::Vector3d& origin, const Eigen::Vector3d& d, double tnear) const;
  // Whether any triangle meets the segment origin + t d, t in [tnear, tfar] (no 1-ring or near
  // rules: a free point; Embree's float test): the shadow rays to points on an area light, which
  // end at the light (view/area_lights.h).
  bool occluded(const Eigen::Vector3d& origin, const Eigen::Vector3d& d, double tnear, double tfar) const;
  double mesh_diagonal() const { return diagonal_; }  // of the mesh's axis-aligned bounds

private:
  struct Embree;
  double reach(const ShadePoint& point) const;  // a ray length beyond the whole mesh from p
  // The first blocker among the 1-ring and the near triangles (decided exactly): its distance
  // along d (0 for the 1-ring), +inf when none blocks. With `any`, the first blocker found ends
  // the search (its distance then need not be the least).
  double exact_blocker(const ShadePoint& point, const NearTriangles& near, const Eigen::Vector3d& d, bool any) const;
  const Mesh& mesh_;
  const Topology& topo_;
  std::unique_ptr<Embree> rt_;
  double diagonal_ = 0;
  Eigen::Vector3d centre_{0, 0, 0};  // of the bounding box
};

} // namespace prt::bake
