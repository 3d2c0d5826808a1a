// receivers.cpp — the shade points of a mesh's vertices (bake/mesh/receivers.h).
#include <bake/mesh/receivers.h>

#include <cmath>
#include <utility>

namespace prt::bake {

ShadePoint vertex_shade_point(const Mesh& mesh, const Topology& topology, uint32_t vertex) {
  ShadePoint sp;
  sp.p = mesh.positions[vertex].cast<double>();
  sp.n = mesh.normals[vertex].cast<double>().normalized();
  sp.welded = topology.weld[vertex];
  // The tie-break t (bake/integrators/integrator.h): from p towards the centroids of the vertex's own
  // triangles, in its tangent plane — into its own surface.
  Eigen::Vector3d into = Eigen::Vector3d::Zero();
  for (const uint32_t f : topology.ring(uint32_t(sp.welded))) {
    const auto& t = mesh.triangles[f];
    if (t[0] != vertex && t[1] != vertex && t[2] != vertex) continue;  // another sheet's or object's
    for (const uint32_t c : t) into += (mesh.positions[c].cast<double>() - sp.p) / 3;  // centroid − p
  }
  into -= sp.n.dot(into) * sp.n;
  const double len = into.norm();
  if (len > 0 && std::isfinite(len)) sp.t = into / len;
  return sp;
}

std::vector<ShadePoint> vertex_shade_points(const Mesh& mesh, const Topology& topology) {
  std::vector<ShadePoint> points(mesh.positions.size());
  for (size_t v = 0; v < points.size(); ++v) points[v] = vertex_shade_point(mesh, topology, uint32_t(v));
  return points;
}

ReceiverSet vertex_receivers(const Mesh& mesh, const Topology& topology, std::string name, size_t tag) {
  ReceiverSet set;
  set.name = std::move(name);
  set.points = vertex_shade_points(mesh, topology);
  set.tag = tag;
  return set;
}

} // namespace prt::bake
