// bake/mesh/receivers.h — receivers: the points a bake writes one row for, as shade points
// (bake/mesh/shade_point.h), gathered in ReceiverSets. Today the vertices of a mesh (or of a scene
// object, placed in the scene's frame); the bake pipeline (bake/bake/pipeline.h) takes any
// ReceiverSet, so a new receiver kind (the texels of a lightmap) adds a maker of ReceiverSets here
// and touches neither the pipeline nor the integrators.
#pragma once

#include <bake/mesh/mesh.h>
#include <bake/mesh/shade_point.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace prt::bake {

// Vertex `vertex` of `mesh` as a shade point: its position and unit normal, its welded id, and the
// tie-break t from p towards the centroids of its own triangles, in its tangent plane (into its
// own surface; 0 when it has none).
ShadePoint vertex_shade_point(const Mesh& mesh, const Topology& topology, uint32_t vertex);

// The shade points of every vertex of `mesh` (vertex_shade_point for each, in order).
std::vector<ShadePoint> vertex_shade_points(const Mesh& mesh, const Topology& topology);

// Receivers that share one product request: row i of their bake is points[i], randomised by i
// (so any cut of the rows into ranges, threads or shards gives the same numbers).
struct ReceiverSet {
  std::string name;                // how logs name it: a file, a scene object
  std::vector<ShadePoint> points;  // one per row, in the order the rows are written
  size_t tag = 0;                  // the caller's: which object, which shard set
  const char* rows_noun = "vertices";  // how logs count its rows
};

// Every vertex of `mesh` (vertex_shade_points) as one set.
ReceiverSet vertex_receivers(const Mesh& mesh, const Topology& topology, std::string name, size_t tag = 0);

} // namespace prt::bake
