// bake/lights/lights.h — area lights: the emitters of paper 003 ("Fast Analytic Soft Shadows from Area
// Lights", §3: a light of constant radiance whose surface a shade point sees as one spherical
// polygon; §3.3: for a convex light, the polygon bounded by its silhouette edges). Every light,
// whatever shape the user described, is stored in one form here: world-space vertices and
// convex planar faces, counter-clockwise seen from the side they emit to (docs/ARCHITECTURE.md
// §3 "Frames": world space, right-handed).
//
//   planar lights   one face; quads, discs (as regular N-gons) and convex polygons; they emit
//                   from the side their counter-clockwise order faces, or from both (two_sided);
//   solid lights    a closed convex polyhedron emitting outwards: boxes, cylinders (N-gon
//                   prisms) and spheres (icospheres); its faces are outward and counter-clockwise.
//
// The polyhedra ARE the emitters: a sphere light with subdivision s is the icosphere whose
// vertices lie on the sphere (its area is 0.48% below the sphere's at s = 3, 0.12% at s = 4),
// not an approximation hidden from the integrals.
//
// Validity (validate_light, an InputError naming the light): finite coordinates, every face
// with ≥ 3 vertices, non-degenerate, planar and convex; a solid closed (every edge shared by two
// faces in opposite directions), convex (no vertex in front of any face's plane) and outward
// (positive volume). The tolerance of "planar" and "convex" is 1e-6 of the light's diameter plus
// 2^-22 of its largest coordinate: float-exported vertices pass, even far from the origin (a
// float coordinate is off by up to 2^-24 of itself), a real fold or dent does not. The spherical
// polygon of a face is the one its vertex directions span with great-circle arcs, which is exact
// for the vertices as given; the tolerance only bounds how far that may be from a flat emitter.
#pragma once

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace prt::bake {

enum class LightShape { Polygon, Quad, Disc, Box, Cylinder, Sphere };
const char* light_shape_name(LightShape);

struct AreaLight {
  std::string name;
  LightShape shape = LightShape::Polygon;
  std::vector<Eigen::Vector3d> vertices;     // world space
  std::vector<std::vector<uint32_t>> faces;  // convex planar polygons, counter-clockwise seen from the emitting side
  std::array<double, 3> radiance{1, 1, 1};   // per channel, constant over the surface and over directions
  bool two_sided = false;                    // planar lights: emit from both sides

  bool solid() const noexcept { return shape == LightShape::Box || shape == LightShape::Cylinder || shape == LightShape::Sphere; }
  Eigen::Vector3d face_normal(size_t face) const;  // unit, towards the emitting side (Newell's method)
  double area() const;                             // of every face
};

// Planar lights. `corners`: a convex polygon, counter-clockwise seen from the emitting side.
AreaLight make_polygon_light(std::vector<Eigen::Vector3d> corners);
// The rectangle centre ± u/2 ± v/2; it emits towards u × v.
AreaLight make_quad_light(const Eigen::Vector3d& centre, const Eigen::Vector3d& u, const Eigen::Vector3d& v);
// A regular `segments`-gon inscribed in the circle of `radius` about `centre` in the plane
// normal to `normal`, emitting towards `normal`.
AreaLight make_disc_light(const Eigen::Vector3d& centre, const Eigen::Vector3d& normal, double radius, int segments);

// Solid lights, emitting outwards. `rotation` turns the shape's own axes into world axes.
AreaLight make_box_light(const Eigen::Vector3d& centre, const Eigen::Vector3d& size, const Eigen::Matrix3d& rotation);
// An N-gon prism: `segments` around the axis (the shape's own y), `height` along it.
AreaLight make_cylinder_light(const Eigen::Vector3d& centre, double radius, double height, int segments,
                              const Eigen::Matrix3d& rotation);
// The icosahedron subdivided `subdivisions` times (20·4^s faces), its vertices on the sphere.
AreaLight make_sphere_light(const Eigen::Vector3d& centre, double radius, int subdivisions);

// The limits of the shapes' resolution knobs.
// (Validity checks every vertex against every face: at most ~1.3e7 pairs, a sphere at 4.)
inline constexpr int kMinSegments = 3, kMaxSegments = 1024, kMaxSphereSubdivisions = 4;
// Relative to the light's diameter, plus float rounding: planarity and convexity (the file comment).
inline constexpr double kLightShapeTolerance = 1e-6;

// Throws InputError(`file`, "<what>: <defect>") unless the light is valid (the file comment).
void validate_light(const AreaLight& light, const std::string& file, const std::string& what);

} // namespace prt::bake
