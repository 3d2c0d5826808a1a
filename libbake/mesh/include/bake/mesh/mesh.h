// bake/mesh/mesh.h — mesh input and welded topology (docs/ARCHITECTURE.md §4: scene input,
// edge/face incidence).
//
// A Mesh is the geometry a bake belongs to: its vertex rows are the rows of every per-vertex
// output (/mesh/positions, /ao, /transfer/...), so they must line up with the vertex buffer an
// engine builds from the same file. The contracts below are what guarantees that.
//
// READING (load_mesh) happens in two steps with one seam between them:
//   1. The file's bytes are read once, into memory. Mesh::source_sha256 is the SHA-256 of exactly
//      those bytes (so a caller never hashes the file again), and ONE reader per format parses
//      them once into a Polygons: the file's positions, normal and texture-coordinate values in
//      file order, and its polygons as corner lists (position index, optional normal index, an
//      index per texture-coordinate set), in file order, exactly as the file has them (zero-area,
//      needle and repeated-index polygons are kept). Readers: OBJ, PLY (ascii, binary
//      little/big endian), OFF ([ST][C][N]OFF, ascii), STL (ascii, binary), glTF 2.0 (.gltf,
//      .glb; parsed by tinygltf, gltf_reader.cpp). Why the first four are ours and not
//      OpenMesh's: see mesh_io.cpp. A .gltf with external
//      buffers is the one input made of several files: its source_sha256 is the SHA-256 of the
//      .gltf's bytes followed by the 64 hex digits of each external buffer file's SHA-256, in the
//      order of its "buffers" array (so a changed .bin changes the digest, and a resumed sharded
//      bake refuses chunks of the old one). Image files are never read or hashed: a bake uses no
//      texture. Every other file's source_sha256 is the SHA-256 of its bytes, as `sha256sum`.
//      Text formats (OBJ, PLY's header, OFF, .gltf) may begin with a UTF-8 byte-order mark, which
//      is skipped; UTF-16/32 text and glTF 1.0 are refused naming them. Numbers may carry a
//      leading '+'. A PLY header line without a keyword is read as a comment, with a warning.
//   2. build_mesh turns any Polygons into the Mesh: vertex rows, hard-edge splits, fan
//      triangulation, normals and validation, the same for every format.
// A new format is one more reader: a function that fills a Polygons from the bytes (as the glTF
// reader does: a primitive's POSITION accessor -> positions, NORMAL -> normals with
// corner_normal = the corner's vertex index, its triangles -> 3-corner polygons) and one line in
// the extension table in mesh_io.cpp; build_mesh and everything after it stay as they are.
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
//   * glTF: the default scene (scene 0 when none is named) is walked depth first, its root nodes
//     and each node's children in document order; every mesh primitive of every node is an
//     instance, and the rows are the vertices (POSITION elements) of instance 1 in accessor order,
//     then instance 2, … — nothing is welded across primitives or instances. A node's transform
//     (matrix, or translation · rotation · scale) is composed with its ancestors' in double and
//     applied to positions in double; they stay double until build_mesh (ORIGIN below). TRIANGLES, TRIANGLE_STRIP (triangle i
//     = (i, i+1+i%2, i+2−i%2)) and TRIANGLE_FAN (triangle i = (i+1, i+2, 0)) become triangles,
//     indexed or not; under a transform with a negative determinant the winding is reversed (the
//     front face stays the front face: glTF 2.0 specification, "Meshes"). POINTS and LINE*
//     primitives give no rows: they are counted in one warning (a file with nothing else is an
//     InputError). Skins and morph targets are ignored (the rest pose is baked) with a warning.
//
// ORIGIN (positions far from the world origin): readers give positions in double (text parsed to
// the nearest double — nudged by one double ulp in the rare case where that double is a float
// midpoint, so that rounding it to float gives the correctly rounded float of the text, the
// value it had when read in float —; binary float32 widened exactly; PLY float64 kept). A Mesh
// holds them as Mesh::origin (double) plus float offsets: world position of vertex v =
// origin + positions[v], summed in double (Mesh::world_position). Everything that bakes (the
// integrators, Embree, the contour BVH, welding, normals, winding) works on the float offsets,
// in the object's own frame; everything that is written (mesh/positions, FIV shell centres)
// adds the origin back in double. The origin is chosen by ONE rule (frame_origin), for a
// mesh from the bounding box of its world positions, for a scene from that of all its objects:
//   reach = max over axes of max(|lo|, |hi|), extent = max over axes of (hi − lo);
//   origin = 0 when reach ≤ kNearOrigin · extent (the box is near the world origin compared to
//   its size; rounding world coordinates to float then costs at most log2(2·kNearOrigin) = 3
//   of float's 24 bits over the centred frame), else origin = (lo + hi) / 2 in double.
// With origin 0 the offsets are the world positions rounded to float once, exactly what the
// float readers gave: ordinary meshes bake bit for bit as before. With a far origin an object
// translated by 1e5 and scaled by 1e-4 keeps float's relative precision (2^-24 of its size).
// Positions must be finite floats (|x| ≤ FLT_MAX) in world space, and so must the offsets.
//
// NORMALS (unit, finite, one per output vertex):
//   * From the file when it has them and MeshLoadOptions::use_file_normals: OBJ `vn` per corner,
//     PLY nx/ny/nz, NOFF per vertex; normalised. STL facet normals are ignored (often garbage).
//     glTF NORMAL only when EVERY baked primitive has one (else all are computed), transformed
//     by the inverse transpose of the node's world transform in double and renormalised.
//     (Normals and welding do not depend on the origin: both are computed on the float offsets.)
//     normal_source = File. A vertex the file gives no normal, or a zero-length one, gets the
//     computed normal below; a non-finite file normal is an InputError.
//   * Otherwise angle-weighted ("mean weighted by angle", Thürmer & Wüthrich 1998) over the
//     vertex's SHEET: the corner angle times the unit face normal, summed over the sheet's
//     triangles at the vertex's welded position (bitwise-equal coordinates) and normalised. The
//     triangle corners at one welded position form sheets by joining (transitively) two corners
//     when they are corners of the same output vertex, or when their triangles share a welded
//     edge that has exactly these two triangles, traverse it in opposite directions (consistent
//     winding) and are not folded flat onto each other (the second triangle's far corner lies
//     exactly in the first's plane, on the same side of the edge). So an STL soup, a seam-split
//     OBJ or a per-face-split glTF gets the smooth normals of the clean welded mesh (its fans are
//     manifold), while a vertex keeps the normal of its own faces where another object or sheet
//     shares its position: two coincident sheets with opposite winding (a double-sided wall),
//     a wall standing on a slab, objects touching at a corner (their shared edges have 3+ faces
//     or fold flat). Zero-area triangles contribute nothing and join nothing. A vertex with no
//     triangle of non-zero area takes the sum over every triangle at its welded position; a
//     vertex whose sum is zero (none, or exactly cancelling ones) gets +Y = (0, 1, 0), the scene
//     up axis.
//
// TRIANGLES: file face order; a polygon (c0 … cn−1) becomes the fan (c0, ci, ci+1), i = 1…n−2,
// in place. Winding is the file's (each triangle reversed with MeshLoadOptions::flip_normals,
// which also negates file normals); nothing here assumes it is consistent.
//
// TEXTURE COORDINATES (Mesh::uv_sets, per triangle corner: UvSet below; they never split or move a
// row, so every rule above holds with or without them):
//   * OBJ: `vt u v [w]` (w ignored) with `f v/vt[/vn]` corners: one set "vt".
//   * PLY: the first of the vertex property pairs (u, v), (s, t), (texture_u, texture_v) that the
//     vertex element has: one set "uv", per vertex.
//   * glTF: each TEXCOORD_n of a primitive (VEC2 of float, or of normalized unsigned byte / short,
//     read as c / 255, c / 65535): a set "TEXCOORD_n", per vertex, sets in order of n.
//   * OFF, STL: none.
// OBJ and PLY put v up the image; they are converted to glTF's v down as 1 − v. A set covers every
// corner or is not a set: an OBJ where only some corners have a vt gets none, with a warning that
// counts the corners without one; load_mesh keeps a glTF set only when every primitive instance
// with a triangle has it (else a warning naming it), load_mesh_instances keeps each instance's own.
//
// ERRORS: bad input throws prt::bake::InputError whose what() is "<path>: <defect>" (one line),
// with a line number where the format has lines: missing/unreadable/oversized file, unknown
// extension, empty mesh, truncated or garbled file (an OBJ line with an unknown keyword is
// garbage), NaN/Inf or out-of-float-range coordinates or texture coordinates, zero / negative /
// out-of-range face indices (texture-coordinate indices too), faces with fewer than 3 corners. An OBJ's material library (`mtllib`) is never
// opened and a missing one is not reported: a bake does not use materials, and a line about it
// would be noise (Mesh::warnings holds only what matters to the bake). Binary OFF is not supported (InputError).
// glTF: tinygltf's own parse errors (JSON, GLB container, missing or short buffers), and ours:
// no scene, a reference to a node / mesh / accessor / buffer view / buffer that does not exist,
// an accessor past its buffer view or a view past its buffer, an index out of range, a
// non-finite position, a recursive node graph or a node reached twice (the hierarchy must be
// disjoint trees), component types other than FLOAT positions/normals, unsigned byte/short/int
// indices and the TEXCOORD_n types above (a TEXCOORD_n that is not VEC2, integers not normalized,
// a count other than POSITION's), sparse accessors, TRIANGLES with a count not a multiple of 3,
// and required compression/quantization extensions. Textures are never decoded.
// Reading is re-entrant: no global state.
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

// origin + offset in double; with origin 0 the offset as is (so a −0 stays −0: ordinary files
// keep their bytes).
inline Eigen::Vector3d add_origin(const Eigen::Vector3d& origin, const Eigen::Vector3d& offset) {
  return origin == Eigen::Vector3d::Zero() ? offset : Eigen::Vector3d(origin + offset);
}

// A texture-coordinate set, per triangle corner (per corner, not per vertex: a UV seam splits no
// vertex row, so the per-vertex contracts above hold with or without UVs). Lightmaps (per-texel
// bakes, bake/mesh/texels.h) are baked in one such set. `corners[3 t + c]` is corner c of
// triangle t in Mesh::triangles order (after the fan, and after flip_normals' reversal: the UV
// follows its corner). Values as the file has them (glTF: (u, v) with v down the image, as
// TEXCOORD_n; OBJ: `vt` u v and PLY: u v, v up, converted to glTF's v-down as 1 − v, so every set
// uses one convention: texel row 0 is v = 0). Which files have which sets: TEXTURE COORDINATES above.
struct UvSet {
  std::string name;                      // "TEXCOORD_0", "TEXCOORD_1" (glTF), "vt" (OBJ), "uv" (PLY)
  std::vector<Eigen::Vector2f> corners;  // 3 per triangle
};

struct Mesh {
  std::vector<Eigen::Vector3f> positions;              // one per output vertex, relative to origin (file comment: ORIGIN)
  std::vector<Eigen::Vector3f> normals;                // unit, one per output vertex
  std::vector<std::array<uint32_t, 3>> triangles;      // indices into output vertices, file order (polygons fan-triangulated in place)
  std::vector<uint32_t> source_position;               // file position index of each output vertex
  enum class NormalSource { File, AngleWeighted } normal_source = NormalSource::AngleWeighted;
  std::string source;                                  // path as given
  size_t file_positions = 0, file_faces = 0;           // counts as in the file (faces before triangulation)
  std::vector<std::string> warnings;                   // non-fatal reader messages, one line each, "<file>: <finding>"
  std::string source_sha256;                           // load_mesh: SHA-256 (64 lowercase hex) of the bytes parsed; empty from make_mesh / merge_meshes / build_mesh
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();    // world = origin + positions[v], in double (frame_origin)
  std::vector<UvSet> uv_sets;                          // in the file's order; empty: the file has none
  Eigen::Vector3d world_position(size_t v) const { return add_origin(origin, positions[v].cast<double>()); }
};

// The origin rule of the file comment (ORIGIN) for world-space bounds [lo, hi] (lo <= hi).
inline constexpr double kNearOrigin = 4;
Eigen::Vector3d frame_origin(const Eigen::AlignedBox3d& world_bounds);
// Offsets of world positions from `origin`, rounded to float once; InputError(source, ...) if
// one leaves the float range.
std::vector<Eigen::Vector3f> offsets_from(std::span<const Eigen::Vector3d> world, const Eigen::Vector3d& origin,
                                          const std::string& source);

struct MeshLoadOptions {
  bool use_file_normals = true;  // false: ignore the file's normals, rows are exactly the file's positions
  // true: every triangle's winding is reversed ((c0, c1, c2) -> (c0, c2, c1), after the fan) and
  // every file normal negated, so file and angle-weighted normals both point the other way. For
  // meshes wound inwards (winding_facts below). Rows and their order do not change.
  bool flip_normals = false;
};

// Read OBJ / PLY / OFF / STL / glTF / GLB (by extension, case-insensitive). See the file comment for the
// vertex order, normal and error contracts. Throws InputError; running out of memory is a
// SystemError("<path>: out of memory while reading the file") (load_mesh_instances too).
Mesh load_mesh(const std::filesystem::path& path, const MeshLoadOptions& = {});

// glTF SCENES: the instances of load_mesh's glTF walk kept apart, one Mesh each (a glTF scene's
// objects, bake/bake/scene.h). Every primitive instance with at least one triangle is an instance, in
// walk order; its Mesh is build_mesh of that primitive alone, in world space (node transforms as
// above), rows in its accessor order, with its own NORMAL when it has one (the all-or-nothing rule
// above is load_mesh's, for the concatenation), source = the file, source_sha256 the file's.
// NAMES (unique, stable for a given file): the node path is the names of the nodes from the scene
// root down to the instance's node, joined by '/'. A node's segment is the name the asset gives
// it: the node's "name", or when that is empty, "." or ".." the "name" of the node's mesh (CAD
// exports name meshes, not nodes: 2CylinderEngine.glb's "Piston_123-844_0_Parts_1"), with '/',
// '#' and '|' replaced by '_'; "node<N>" (N its index in "nodes") when neither has one. Among
// siblings (the scene's root nodes, or one node's children, in document order) a segment already
// taken gets the first of "~2", "~3", ... that no sibling has. The instance's name
// is its node path for the mesh's primitive 0 and path + "#p<k>" for primitive k > 0:
// "root/engine/piston~2#p1". Names never contain '|' (the asset's object names use it for '/').
struct MeshInstance {
  std::string name, node_path;
  std::optional<std::array<double, 3>> base_color;  // the material's pbrMetallicRoughness.baseColorFactor RGB, as in the file; none: no material
  // An animation channel moves the node or one of its ancestors (translation, rotation or scale;
  // "weights" animates morph targets, which are not moves): the instance moves at run time.
  bool animated = false;
  Mesh mesh;
};
// A KHR_lights_punctual light as a node of the default scene instances it (the extension's
// "Lights" and "Adding Light Instances to Nodes"): the light shines from the node's world position
// along the node's world −Z; its units are the extension's (candela, lux for directional).
// Validity is the caller's (bake/lights/punctual.h validate_punctual_light): values as written.
struct GltfLight {
  std::string name;       // the light's "name" ("" when it has none)
  size_t index = 0;       // in the extension's "lights"
  std::string node_path;  // the instancing node's path (the instance naming rule above)
  std::string type;       // "directional", "point" or "spot" (anything else is refused by the reader)
  Eigen::Vector3d position{0, 0, 0}, direction{0, 0, -1};  // world; direction normalised (zero if the node's scale is)
  std::array<double, 3> color{1, 1, 1};
  double intensity = 1;
  double inner_cone = 0, outer_cone = 0.7853981633974483;  // spot, radians (the extension's defaults)
  double range = 0;                                        // 0: none given (applied: bake/lights/punctual.h)
};
struct MeshInstances {
  std::vector<MeshInstance> instances;
  std::vector<GltfLight> lights;  // KHR_lights_punctual instances of the default scene, in walk order
  std::vector<std::string> warnings;  // the file's (skipped primitives, skins), one line each, "<file>: <finding>"
  std::string source_sha256;          // of the file's bytes
};
// Throws InputError (as load_mesh; also for a file that is not .gltf / .glb, a material index out of
// range, and a file without any instance with a triangle).
MeshInstances load_mesh_instances(const std::filesystem::path& path, const MeshLoadOptions& = {});

// The neutral polygon description between a format reader and build_mesh: what the file says,
// in file order, nothing derived. Corner c of polygon f is c in [offsets[f], offsets[f + 1]).
struct Polygons {
  static constexpr uint32_t kNoNormal = 0xffffffffu;
  std::vector<Eigen::Vector3d> positions;   // the file's positions in double (STL: 3 corners per facet)
  std::vector<Eigen::Vector3f> normals;     // the file's normal values, as written (not normalised)
  std::vector<uint32_t> offsets{0};         // polygon_count() + 1 entries, ascending
  std::vector<uint32_t> corner_position;    // per corner: index into positions
  std::vector<uint32_t> corner_normal;      // per corner: index into normals or kNoNormal; empty = none has one
  // Texture-coordinate sets: per corner an index into values (every corner has one; a set that
  // some corners lack is not a set: the reader drops it with a warning).
  struct Uvs {
    std::string name;
    std::vector<Eigen::Vector2f> values;
    std::vector<uint32_t> corner;  // one per corner (corner_position.size())
  };
  std::vector<Uvs> uv_sets;
  size_t polygon_count() const { return offsets.size() - 1; }
  void end_polygon() { offsets.push_back(static_cast<uint32_t>(corner_position.size())); }
};

// The one polygon-to-mesh step behind load_mesh (vertex order, hard-edge splits, fans, normals:
// the contracts in the file comment). Validates what a reader may pass through (finite
// positions, >= 3 corners, indices in range, at least one polygon, 32-bit limits, finite texture
// coordinates and their indices in range) and throws InputError(source, defect); a texture-coordinate
// set without one index per corner is a reader's bug (ContractError). Each Polygons::Uvs becomes
// a UvSet of the same name, in the same order, through the same fan and flip as the triangles.
// Sets source, file_positions, file_faces and origin (frame_origin of the positions' bounds); not
// source_sha256 or warnings.
Mesh build_mesh(const Polygons& polygons, std::string source, const MeshLoadOptions& = {});

// Build a mesh in memory (tests, generated geometry), origin 0. Output vertex i = positions[i],
// source_position[i] = i, file_positions = positions.size(), file_faces = triangles.size().
// Normals: angle-weighted over welded positions (as load_mesh) unless `normals` is given, in which
// case it must have one finite non-zero vector per position; it is normalised and
// normal_source = File. `uv_sets` (none by default) are taken as they are: 3 finite corners per
// triangle each (UvSet). Validates (finite positions, indices in range, at least one triangle,
// the sets) and throws InputError(name, defect).
Mesh make_mesh(std::vector<Eigen::Vector3f> positions, std::vector<std::array<uint32_t, 3>> triangles,
               std::string name, std::vector<Eigen::Vector3f> normals = {}, std::vector<UvSet> uv_sets = {});

// Concatenation (e.g. asset + ground plane): vertices and triangles of parts[0], then parts[1]…;
// triangle indices are offset by the vertex count before each part, source_position by the sum
// of file_positions before it (so it stays unique across parts). normal_source = File only if
// every part's is; warnings are concatenated. A texture-coordinate set is kept (by name, in
// parts[0]'s order, corners in part order) only when every part has one of that name, else it is
// dropped without a warning (a part made in memory, a ground plane, has none). `parts` must not
// be empty (contract). Origin: the parts' when they all have the same one (offsets copied); else
// frame_origin of the union of the parts' world bounds, every offset re-expressed from its world
// position in double.
Mesh merge_meshes(std::span<const Mesh> parts, std::string name);

// Angle-weighted vertex normals over the given indexing (no welding): n_v = normalize(Σ_t α_t(v)
// n̂_t) with α the corner angle at v and n̂_t the unit face normal (right-handed, (b−a)×(c−a)).
// Zero-area triangles contribute nothing; a vertex with a zero sum gets +Y. Computed in double.
// Indices must be in range (contract).
std::vector<Eigen::Vector3f> angle_weighted_normals(std::span<const Eigen::Vector3f> positions,
                                                    std::span<const std::array<uint32_t, 3>> triangles);

// The same sum taken over each vertex's sheet at its welded position (bitwise-equal coordinates;
// the NORMALS rule in the file comment): what load_mesh and make_mesh use when the file gives no
// normal. Computed in double; memory O(triangles).
std::vector<Eigen::Vector3f> welded_angle_weighted_normals(std::span<const Eigen::Vector3f> positions,
                                                           std::span<const std::array<uint32_t, 3>> triangles);

// Welded, orientation-free incidence for the integrators (docs/ARCHITECTURE.md §4):
// the DCF step across an edge counts the faces on each side, so non-manifold edges and
// inconsistent winding are data, not errors. Welded position ids are assigned in order of first appearance over the output
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

// Which way the closed parts of a mesh are wound (so a tool can warn before baking a mesh whose
// normals point inside, where every vertex sees no sky). A COMPONENT is a maximal set of
// triangles connected through shared welded edges (Topology::edges). It is CLOSED when no
// triangle repeats a welded corner and every edge of its triangles is shared by exactly two
// triangles that traverse it in opposite directions (watertight and consistently oriented).
// Its signed volume is (1/6) Σ_t (a−o)·((b−o)×(c−o)) over its triangles (a, b, c), o its first
// triangle's first corner (translation-invariant for a closed surface; computed in double). It is
// positive for outward winding (right-handed face normals, bake/mesh/mesh.h, pointing out); a closed
// component is INWARD when its volume is negative beyond rounding: V < −1e-9 · (1/6) Σ_t |term_t|
// (so a closed double-sided sheet, V = 0 up to rounding, is not inward). Components that are not
// closed (open, non-manifold, inconsistently wound) have no inside and are only counted.
struct ClosedComponent {
  uint32_t first_triangle = 0;  // its lowest triangle index
  size_t triangles = 0;
  double signed_volume = 0;
  bool inward = false;
};
struct WindingFacts {
  size_t components = 0;                // all components (closed or not)
  std::vector<ClosedComponent> closed;  // the closed ones, by first triangle
  size_t inward_components() const;
  size_t inward_triangles() const;
};
WindingFacts winding_facts(const Mesh& mesh, const Topology& topology);

} // namespace prt::bake
