// Exact location of a point relative to a triangle: outside its plane, or in its plane and then
// inside the face, on an edge's interior, at a corner, or outside — decided with the exact
// orientation predicate of bake/mesh/predicates.h (orient3d_exact, Shewchuk 1997), so a T-junction (a
// vertex lying on another triangle's edge or inside its face, without being one of its corners)
// is recognised exactly, never within a tolerance. Shared by the geometry tests and the benchmark
// that explains disagreements between the integrators (bench/bench_real_assets.cpp).
//
// Method: q is in the plane of (a, b, c) iff orient3d(a, b, c, q) = 0. In the plane, for any fixed
// point d off the plane, orient3d(u, v, q, d) has the sign of the 2D orientation of (u, v, q) in
// that plane (the tetrahedron's volume is the triangle's signed area times d's height), so the
// three edge tests against orient3d(a, b, c, d) decide inside / edge / corner / outside exactly.
// d is a + (the unit axis of the normal's largest component): clearly off a non-degenerate plane.
#pragma once

#include <bake/mesh/predicates.h>

#include <Eigen/Geometry>

#include <array>
#include <cmath>

namespace prt::testing {

enum class OnTriangle { OffPlane, Outside, Inside, OnEdge, AtCorner, Degenerate };

inline OnTriangle locate_on_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                                     const Eigen::Vector3d& q) {
  if (bake::orient3d_exact(a, b, c, q) != 0) return OnTriangle::OffPlane;
  const Eigen::Vector3d normal = (b - a).cross(c - a);
  int axis = 0;
  normal.cwiseAbs().maxCoeff(&axis);
  Eigen::Vector3d d = a;
  d[axis] += 1.0;
  const int s = bake::orient3d_exact(a, b, c, d);
  if (s == 0) return OnTriangle::Degenerate;
  const std::array<int, 3> e = {bake::orient3d_exact(a, b, q, d), bake::orient3d_exact(b, c, q, d),
                                bake::orient3d_exact(c, a, q, d)};
  int zeros = 0;
  for (int k : e) {
    if (k == -s) return OnTriangle::Outside;
    zeros += k == 0;
  }
  return zeros == 0 ? OnTriangle::Inside : zeros == 1 ? OnTriangle::OnEdge : OnTriangle::AtCorner;
}

inline OnTriangle locate_on_triangle(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c,
                                     const Eigen::Vector3f& q) {
  return locate_on_triangle(Eigen::Vector3d(a.cast<double>()), Eigen::Vector3d(b.cast<double>()),
                            Eigen::Vector3d(c.cast<double>()), Eigen::Vector3d(q.cast<double>()));
}

// A T-junction of q with the triangle: q lies inside its face or on an edge's interior.
inline bool is_t_junction(OnTriangle where) { return where == OnTriangle::Inside || where == OnTriangle::OnEdge; }

} // namespace prt::testing
