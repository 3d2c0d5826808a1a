// bake/mesh.h — mesh input and welded topology (DESIGN.md §2, "scene input (OpenMesh), edge/face
// incidence").
//
// A Mesh is the geometry a bake belongs to: its vertex rows are the rows of every per-vertex
// output (/mesh/positions, /ao, /transfer/...), so they must line up with the vertex buffer an
// engine builds from the same file. The contracts below are what guarantees that.
//
// READING (load_mesh). Files are parsed by OpenMesh's own readers (OBJ, PLY ascii + binary,
// OFF ascii, STL ascii + binary) into a raw importer of ours (an OpenMesh::IO::BaseImporter), so
// OpenMesh's TriMesh/PolyMesh never sees the faces: it cannot re-add "complex vertex/edge"
// (non-manifold) faces with duplicated vertices. Independently of OpenMesh, a cheap structural
// scan of the file counts positions, faces and Σ(corners − 2) triangles; the two must agree, or
// load_mesh throws InputError naming the file and both counts. The scan also supplies what
// OpenMesh 9.0's readers drop on purpose: the OBJ reader removes repeated indices from a face
// (`f 1 1 2` vanishes, `f 1 2 1 3` becomes a triangle) and the STL reader skips facets with
// two equal corners. Those faces are restored from the scan, exactly as the file has them:
// zero-area, needle and repeated-index triangles are all kept, never dropped.
//
// OUTPUT VERTEX ORDER (the rule every per-vertex consumer relies on):
//   * OBJ, PLY, OFF: output vertex i < file_positions IS file position i (the file's `v` lines /
//     vertex element, in file order, including positions no face references). A position that
//     the file gives several distinct normals (OBJ `f v//vn` hard edges) keeps its row for the
//     normal of its first corner in face order; each further distinct (position, normal) pair is
//     appended after all file positions, in order of first appearance in the face list.
//     Normals are compared by value (bitwise, with −0 == +0), so two `vn` lines with equal values
//     do not split a vertex. source_position[v] is the 0-based file position of output vertex v.
//     Without file normals (or with use_file_normals = false) the rows are exactly the file's.
//   * STL has no shared vertices: output vertex 3f+k is corner k of facet f, in file order
//     (file_positions = 3 × facets). Welding (build_topology) is what connects an STL.
//
// NORMALS (unit, finite, one per output vertex):
//   * From the file when it has them and MeshLoadOptions::use_file_normals: OBJ `vn` per corner,
//     PLY nx/ny/nz, NOFF per vertex; normalised. STL facet normals are ignored (often garbage).
//     normal_source = File. A vertex the file gives no normal, or a zero-length one, gets the
//     computed normal below; a non-finite file normal is an InputError.
//   * Otherwise angle-weighted ("mean weighted by angle", Thürmer & Wüthrich 1998): for each
//     triangle incident to the vertex's WELDED position (bitwise-equal coordinates), the corner
//     angle times the unit face normal, summed and normalised. Welding first makes an STL soup
//     or a seam-split OBJ get the same smooth normals as the clean welded mesh. Zero-area
//     triangles contribute nothing. A vertex whose sum is zero (no incident triangle, only
//     zero-area ones, or exactly cancelling ones) gets +Y = (0, 1, 0), the scene up axis.
//
// TRIANGLES: file face order; a polygon (c0 … cn−1) becomes the fan (c0, ci, ci+1), i = 1…n−2,
// in place. Winding is the file's; nothing here assumes it is consistent.
//
// ERRORS: bad input throws prt::bake::InputError whose what() is "<path>: <defect>" with a line
// number where the format has lines: missing/unreadable file, unknown extension, empty mesh,
// truncated or garbled file (an OBJ line with an unknown keyword is garbage), NaN/Inf or
// out-of-float-range coordinates, zero / negative / out-of-range face indices, faces with fewer
// than 3 corners, triangle-count mismatch between the scan and OpenMesh, and any message
// OpenMesh prints to omerr while reading (its chatter is captured, never printed; messages
// about a missing or incomplete .mtl material library are not errors and go to Mesh::warnings).
// Binary OFF is not supported (InputError). Reading holds a process-wide lock while OpenMesh
// runs (its omerr/omlog streams are global); everything else is re-entrant.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross(): consumers of Mesh do geometry

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace prt::bake {

struct Mesh {
  std::vector<Eigen::Vector3f> positions;              // one per output vertex
  std::vector<Eigen::Vector3f> normals;                // unit, one per output vertex
  std::vector<std::array<uint32_t, 3>> triangles;      // indices into output vertices, file order (polygons fan-triangulated in place)
  std::vector<uint32_t> source_position;               // file position index of each output vertex
  enum class NormalSource { File, AngleWeighted } normal_source = NormalSource::AngleWeighted;
  std::string source;                                  // path as given
  size_t file_positions = 0, file_faces = 0;           // counts as in the file (faces before triangulation)
  std::vector<std::string> warnings;                   // non-fatal reader messages (e.g. missing .mtl), one line each
};

struct MeshLoadOptions {
  bool use_file_normals = true;  // false: ignore the file's normals, rows are exactly the file's positions
};

// Read OBJ / PLY / OFF / STL (by extension, case-insensitive). See the file comment for the
// vertex order, normal and error contracts. Throws InputError.
Mesh load_mesh(const std::filesystem::path& path, const MeshLoadOptions& = {});

// Build a mesh in memory (tests, generated geometry). Output vertex i = positions[i],
// source_position[i] = i, file_positions = positions.size(), file_faces = triangles.size().
// Normals: angle-weighted over welded positions (as load_mesh) unless `normals` is given, in which
// case it must have one finite non-zero vector per position; it is normalised and
// normal_source = File. Validates (finite positions, indices in range, at least one triangle)
// and throws InputError(name, defect).
Mesh make_mesh(std::vector<Eigen::Vector3f> positions, std::vector<std::array<uint32_t, 3>> triangles,
               std::string name, std::vector<Eigen::Vector3f> normals = {});

// Concatenation (e.g. asset + ground plane): vertices and triangles of parts[0], then parts[1]…;
// triangle indices are offset by the vertex count before each part, source_position by the sum
// of file_positions before it (so it stays unique across parts). normal_source = File only if
// every part's is; warnings are concatenated. `parts` must not be empty (contract).
Mesh merge_meshes(std::span<const Mesh> parts, std::string name);

// Angle-weighted vertex normals over the given indexing (no welding): n_v = normalize(Σ_t α_t(v)
// n̂_t) with α the corner angle at v and n̂_t the unit face normal (right-handed, (b−a)×(c−a)).
// Zero-area triangles contribute nothing; a vertex with a zero sum gets +Y. Computed in double.
// Indices must be in range (contract).
std::vector<Eigen::Vector3f> angle_weighted_normals(std::span<const Eigen::Vector3f> positions,
                                                    std::span<const std::array<uint32_t, 3>> triangles);

// The same sum taken over welded positions (bitwise-equal coordinates) and scattered back to
// every vertex: what load_mesh and make_mesh use when the file gives no normal.
std::vector<Eigen::Vector3f> welded_angle_weighted_normals(std::span<const Eigen::Vector3f> positions,
                                                           std::span<const std::array<uint32_t, 3>> triangles);

// Welded, orientation-free incidence for the integrators (DESIGN.md §4): the DCF step across an
// edge counts the faces on each side, so non-manifold edges and inconsistent winding are data,
// not errors. Welded position ids are assigned in order of first appearance over the output
// vertices (so a mesh without duplicate positions has weld[v] == v); positions are equal when
// their float coordinates are bitwise equal after mapping −0 to +0.
struct Topology {
  std::vector<uint32_t> weld;                          // output vertex -> welded position id
  std::vector<Eigen::Vector3f> welded_positions;
  std::vector<uint32_t> ring_offsets, ring_faces;      // CSR: triangles incident to each welded position (a triangle with a repeated welded corner is listed once), ascending
  std::vector<std::array<uint32_t, 2>> edges;          // undirected welded edges, a < b, sorted
  std::vector<uint32_t> edge_face_offsets, edge_faces; // CSR: faces incident to each edge (any number: 1 = boundary, 2 = manifold, 3+ = non-manifold), ascending
  std::span<const uint32_t> ring(uint32_t welded) const;
  std::span<const uint32_t> faces_of_edge(uint32_t edge) const;
  // Index of the undirected edge {a, b} (either order) in `edges`, if any. O(log E).
  std::optional<uint32_t> find_edge(uint32_t a, uint32_t b) const;
};

// Edges come from each triangle's three sides between DISTINCT welded corners; a triangle is
// listed once per distinct edge (the triangle (a, a, b) contributes one face to edge {a, b}).
// Zero-area triangles with distinct corners are ordinary faces here.
Topology build_topology(const Mesh&);

} // namespace prt::bake
