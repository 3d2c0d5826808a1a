// bake/bake/diagnostics.h — what a finished bake says about its input: rows that see no sky, and
// whether flipping their normals would let them see some (a mesh wound inwards, or vertices
// buried inside other geometry), for a tool's warning.
#pragma once

#include <bake/bake/vertex_bake.h>
#include <bake/mesh/mesh.h>

#include <cstddef>
#include <cstdint>

namespace prt::bake {

// How many rows of a bake see no sky at all (a mesh wound inwards, or a vertex buried inside
// another object), for a tool's warning. A row sees no sky when its SKY MEASURE is exactly 0; the
// sky measure is the first of AO, T_0, U_0 the layout holds: each is the integral over the
// visible part of the hemisphere of a weight > 0 almost everywhere ((n·ω)/π, (n·ω) y_0/π, y_0),
// so it is 0 exactly when the visible part has measure zero. The silhouette integrator writes
// exact zeros then (it finds the point enclosed); the QMC estimate is a sum of positive terms, one
// per ray that escaped, so it is exactly 0 when every ray hit (and a fully visible-but-unlucky
// vertex cannot reach 0). A radiance-only bake has no such measure: there a row counts when all
// its values are exactly 0 (no sky, or a sky that is black wherever it is seen).
struct NoSkyCount {
  size_t vertices = 0;  // rows that see no sky
  size_t total = 0;     // rows
  double share() const { return total ? double(vertices) / double(total) : 0.0; }
};
NoSkyCount count_no_sky(const VertexBake& bake);

// Of the rows that saw no sky, how many would see some with the opposite normal: what tells
// normals that point inside the geometry (most would) from vertices enclosed by other geometry,
// such as an engine's internals under its housing (none would). Probes a seeded sample of at most
// `sample` such rows of `mesh` (the mesh `bake` belongs to, one row per vertex), each with `rays`
// fixed directions over the flipped hemisphere, visibility in the ε-limit (bake/visibility/raycast.h).
struct FlipProbe {
  size_t probed = 0;         // no-sky rows probed
  size_t would_see_sky = 0;  // of them, those that see some sky with the opposite normal
};
FlipProbe probe_flipped_normals(const Mesh& mesh, const Topology& topology, const VertexBake& bake, size_t sample = 256,
                                uint32_t rays = 256, uint64_t seed = 1);

} // namespace prt::bake
