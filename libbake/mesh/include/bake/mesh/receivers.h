// bake/mesh/receivers.h — receivers: the points a bake writes one row for, as shade points
// (bake/mesh/shade_point.h). Today the vertices of a mesh (or of a scene object, placed in the
// scene's frame); the bake pipeline (bake/bake/vertex_bake.h) takes any span of shade points, so a
// new receiver kind (the texels of a lightmap) adds a function here and touches no integrator.
#pragma once

#include <bake/mesh/mesh.h>
#include <bake/mesh/shade_point.h>

#include <cstdint>
#include <vector>

namespace prt::bake {

// Vertex `vertex` of `mesh` as a shade point: its position and unit normal, its welded id, and the
// tie-break t from p towards the centroids of its own triangles, in its tangent plane (into its
// own surface; 0 when it has none).
ShadePoint vertex_shade_point(const Mesh& mesh, const Topology& topology, uint32_t vertex);

// The shade points of every vertex of `mesh` (vertex_shade_point for each, in order).
std::vector<ShadePoint> vertex_shade_points(const Mesh& mesh, const Topology& topology);

} // namespace prt::bake
