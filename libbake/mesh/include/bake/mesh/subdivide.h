// bake/mesh/subdivide.h — Loop subdivision (C. T. Loop, "Smooth Subdivision Surfaces Based on
// Triangles", M.S. thesis, University of Utah, 1987) through OpenMesh's uniform subdivider
// (OpenMesh/Tools/Subdivider/Uniform/LoopT.hh). Used to make finer versions of a scene for
// benchmarks and convergence studies (bench/: cost against triangle count).
//
// What is subdivided is the WELDED topology (bake/mesh/mesh.h build_topology): positions that are
// bitwise equal are one vertex, so a seam-split OBJ or an STL soup is subdivided as the
// connected surface it describes. Per-file attributes (file normals, hard-edge splits) are not
// carried over: the result is a fresh mesh from prt::bake::make_mesh, with angle-weighted
// normals, source_position[v] = v, and the name "<source> (loop ×levels)".
//
// Vertex order of the result: the welded positions referenced by at least one triangle keep
// their relative order (welded ids are in order of first appearance, so for a mesh without
// duplicate positions and without unreferenced positions, output vertex v < V is input vertex v,
// moved by the Loop smoothing rule); the new edge vertices of each level follow. Unreferenced
// positions carry no surface and are dropped. Triangle count is exactly 4^levels × input.
//
// Rules (OpenMesh's LoopT): interior vertices (1 − α(n)) p + α(n)/n Σ q with Warren-free Loop
// weights α(n) = (40 − (3 + 2 cos 2π/n)²)/64; interior edge points 3/8, 3/8, 1/8, 1/8; boundary
// edges split at the midpoint, boundary vertices (q_l + 6 p + q_r)/8. A planar mesh stays in
// its plane (every rule is an affine combination).
//
// Preconditions checked (OpenMesh's half-edge mesh refuses such faces, and a refused face would
// silently vanish): every triangle has three distinct welded corners; every welded edge has at
// most two triangles; the two triangles of an edge traverse it in opposite directions
// (consistent winding); OpenMesh accepts every face (it also refuses some non-manifold vertex
// configurations). Otherwise InputError("<mesh.source>", "<what, which triangle>") — nothing is
// ever dropped. levels must be >= 0 (ContractError otherwise); levels = 0 returns the welded
// mesh re-made by make_mesh. Computation is in double (LoopT<Mesh, double>).
#pragma once

#include <bake/mesh/mesh.h>

namespace prt::bake {

Mesh loop_subdivide(const Mesh& mesh, int levels);

} // namespace prt::bake
