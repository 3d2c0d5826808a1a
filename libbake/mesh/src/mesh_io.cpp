// mesh_io.cpp — load_mesh (read the bytes once, hash them, one reader per format) and build_mesh
// (Polygons to Mesh, the same for every format). Contracts in bake/mesh/mesh.h.
//
// WHERE OPENMESH SERVES, AND WHERE IT DOES NOT. The design names OpenMesh for scene input. Its
// readers were used here until the mesh-input rewrite, through a raw BaseImporter of ours so that
// its TriMesh never saw the faces, and they needed a second, independent scan of every file and
// a reconciliation of the two, because what OpenMesh 9.0's readers hand an importer is not the
// file:
//   * OBJ: repeated indices are removed from a face before add_face (`f 1 1 2` vanishes,
//     `f 1 2 1 3` becomes a triangle); a `v` line that does not parse is skipped silently,
//     shifting every later row; indices are not range-checked; per-corner `vn` arrive as
//     vertex-normal calls; a missing .mtl is reported on the global omerr stream.
//   * STL: corners are merged by position and facets with two merged corners are skipped.
//   * OFF: a '#' comment makes it read uninitialised counts and report success; a garbled COFF
//     makes it allocate gigabytes. PLY: a non-numeric version on the `format` line loops
//     forever; integer-typed coordinates become 0 (with a message on std::cerr).
//   * All: messages go to process-wide streams (omerr/omlog), so reading needed a global lock
//     and a capture of those streams, and OpenMesh's TriMesh, if used, re-adds non-manifold
//     ("complex vertex/edge") faces with duplicated vertices.
// Feeding them from memory does not help: OpenMesh::IO::read_mesh / IOManager::read have
// std::istream overloads (all five readers, OBJ, OFF, PLY, STL and OM, implement
// read(std::istream&, ...); from a stream the OBJ reader cannot find a .mtl and the STL reader
// must be told ascii or binary), but what is lost is lost inside the reader, before any importer
// sees it. Restoring "every triangle reaches the
// baker, in file order" on top of them therefore needs a parse of our own anyway — the second
// scan this file used to have. So the four readers are ours (mesh_readers.cpp), each a single
// pass over the bytes, and they were the smallest part to keep: the old scan already validated
// every token; it now also keeps the values.
// OpenMesh keeps the role it does well: halfedge connectivity and its algorithms, i.e. Loop
// subdivision (subdivide.cpp), where a manifold mesh is what is wanted and what OpenMesh refuses
// is reported as an error instead of being re-added. The welded, non-manifold incidence the
// integrators need (build_topology, mesh.cpp) and the angle-weighted normals are ours: OpenMesh's
// halfedge structure cannot hold non-manifold edges without duplicating vertices.
#include <bake/mesh/gltf_reader.h>
#include <bake/mesh/mesh_readers.h>

#include <bake/core/error.h>
#include <bake/core/sha256.h>
#include <bake/mesh/mesh.h>

#include <bit>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>
#include <unordered_map>

namespace prt::bake {
namespace {

using ReadFormat = Polygons (*)(std::string_view bytes, const mesh_readers::SourceFile& file);

// The formats, by lower-case extension: a new format is one more line here.
struct FormatEntry {
  std::string_view extension;
  ReadFormat read;
  bool text;  // begins with text (PLY's header, binary or not); STL and GLB may begin with any bytes
};
constexpr FormatEntry kFormats[] = {
    {".obj", mesh_readers::read_obj, true},
    {".ply", mesh_readers::read_ply, true},
    {".off", mesh_readers::read_off, true},
    {".stl", mesh_readers::read_stl, false},
    {".gltf", mesh_readers::read_gltf, true},
    {".glb", mesh_readers::read_gltf, false},
};

// What a text format's reader parses: the bytes after a UTF-8 byte-order mark (Windows editors and
// exporters write one; it is not part of the text), or InputError for UTF-16/32 text, which no
// reader decodes. Binary formats get their bytes as they are.
std::string_view reader_bytes(std::string_view bytes, const FormatEntry& format, const std::string& file) {
  if (!format.text) return bytes;
  if (bytes.starts_with("\xEF\xBB\xBF")) return bytes.substr(3);
  if (bytes.starts_with("\xFE\xFF") || bytes.starts_with("\xFF\xFE"))
    throw InputError(file, std::string("is UTF-16 or UTF-32 text (byte-order mark ") +
                               (bytes[0] == '\xFE' ? "FE FF" : "FF FE") + "): save it as UTF-8 or ASCII");
  return bytes;
}

// Larger files are refused before they are read (32-bit indices end well below this anyway).
constexpr uintmax_t kMaxMeshFileBytes = uintmax_t{4} << 30;

void require_file(const std::filesystem::path& path, const std::string& file) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) throw InputError(file, "no such file");
  if (std::filesystem::is_directory(status)) throw InputError(file, "is a directory, not a mesh file");
}

// The whole file, in one read.
std::string read_whole_file(const std::filesystem::path& path, const std::string& file) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(file, std::string("cannot be read: ") + std::strerror(errno));
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw InputError(file, "cannot be read: " + ec.message());
  if (size > kMaxMeshFileBytes)
    throw InputError(file, "is " + std::to_string(size) + " bytes; mesh files larger than 4 GiB are not supported");
  std::string bytes(static_cast<size_t>(size), '\0');
  if (!in.read(bytes.data(), static_cast<std::streamsize>(bytes.size())))
    throw InputError(file, std::string("read failed: ") + std::strerror(errno));
  if (bytes.empty()) throw InputError(file, "empty file");
  return bytes;
}

// A (position, normal) key; normal bits are canonical (−0 → +0), `has` = the file gave one.
struct CornerKey {
  uint32_t position;
  bool has;
  std::array<uint32_t, 3> bits;
  bool operator==(const CornerKey&) const = default;
};
struct CornerKeyHash {
  size_t operator()(const CornerKey& k) const noexcept {
    uint64_t h = k.position * 0x9E3779B97F4A7C15ull + k.has;
    for (uint32_t b : k.bits) h = (h ^ b) * 0xBF58476D1CE4E5B9ull, h ^= h >> 31;
    return static_cast<size_t>(h);
  }
};
CornerKey make_key(uint32_t position, const Eigen::Vector3f* n) {
  if (!n) return {position, false, {0, 0, 0}};
  return {position, true,
          {std::bit_cast<uint32_t>((*n)[0] + 0.0f), std::bit_cast<uint32_t>((*n)[1] + 0.0f),
           std::bit_cast<uint32_t>((*n)[2] + 0.0f)}};
}

// Everything build_mesh relies on, checked once for every reader.
void validate(const Polygons& poly, const std::string& source, bool use_normals) {
  const size_t n_positions = poly.positions.size(), n_polygons = poly.polygon_count();
  if (n_polygons == 0) throw InputError(source, "no faces (" + std::to_string(n_positions) + " vertices): nothing to bake");
  PRT_CHECK_OP(poly.offsets.front(), ==, 0u);
  PRT_CHECK_OP(poly.offsets.back(), ==, poly.corner_position.size());
  PRT_CHECK(poly.corner_normal.empty() || poly.corner_normal.size() == poly.corner_position.size());
  if (n_positions >= std::numeric_limits<uint32_t>::max()) throw InputError(source, "too large for 32-bit indices");
  for (size_t v = 0; v < n_positions; ++v)
    if (!poly.positions[v].allFinite() || !poly.positions[v].cast<float>().allFinite())
      throw InputError(source, "vertex " + std::to_string(v) + " has a non-finite coordinate (or one out of float range)");
  size_t triangles = 0;
  for (size_t f = 0; f < n_polygons; ++f) {
    const uint32_t b = poly.offsets[f], e = poly.offsets[f + 1];
    if (e - b < 3)
      throw InputError(source, "face " + std::to_string(f) + " has " + std::to_string(e - b) + " corners, needs at least 3");
    triangles += e - b - 2;
    for (uint32_t c = b; c < e; ++c) {
      if (poly.corner_position[c] >= n_positions)
        throw InputError(source, "face " + std::to_string(f) + ": vertex index " + std::to_string(poly.corner_position[c]) +
                                     " is out of range [0, " + std::to_string(n_positions) + ")");
      const uint32_t n = poly.corner_normal.empty() ? Polygons::kNoNormal : poly.corner_normal[c];
      if (!use_normals || n == Polygons::kNoNormal) continue;
      if (n >= poly.normals.size())
        throw InputError(source, "face " + std::to_string(f) + ": normal index " + std::to_string(n) + " is out of range [0, " +
                                     std::to_string(poly.normals.size()) + ")");
      if (!poly.normals[n].allFinite())
        throw InputError(source, "vertex " + std::to_string(poly.corner_position[c]) + " has a non-finite normal");
    }
  }
  if (triangles >= std::numeric_limits<uint32_t>::max()) throw InputError(source, "too large for 32-bit indices");
  for (const Polygons::Uvs& set : poly.uv_sets) {
    PRT_CHECK_OP(set.corner.size(), ==, poly.corner_position.size());  // every corner has one (reader contract)
    const std::string name = "texture coordinate set " + mesh_readers::shown(set.name);
    for (size_t i = 0; i < set.values.size(); ++i)
      if (!set.values[i].allFinite()) throw InputError(source, name + ": value " + std::to_string(i) + " is not finite");
    for (size_t f = 0; f < n_polygons; ++f)
      for (uint32_t c = poly.offsets[f]; c < poly.offsets[f + 1]; ++c)
        if (set.corner[c] >= set.values.size())
          throw InputError(source, name + ": face " + std::to_string(f) + ": index " + std::to_string(set.corner[c]) +
                                       " is out of range [0, " + std::to_string(set.values.size()) + ")");
  }
}

// Reader warnings as load_mesh returns them: "<file>: <finding>" (bake/mesh/mesh.h).
std::vector<std::string> named(const std::string& file, std::vector<std::string> warnings) {
  for (std::string& w : warnings) w = file + ": " + w;
  return warnings;
}

// Mesh::source_sha256 (bake/mesh/mesh.h): the file's digest when it refers to no other file, else the
// digest of its bytes followed by each referenced file's hex digest in the order it was read.
std::string source_digest(const std::string& bytes, const std::vector<std::string>& referenced) {
  if (referenced.empty()) return sha256_bytes(std::as_bytes(std::span(bytes.data(), bytes.size())));
  Sha256 h;
  h.update(std::as_bytes(std::span(bytes.data(), bytes.size())));
  for (const std::string& digest : referenced) h.update(std::as_bytes(std::span(digest.data(), digest.size())));
  return h.hex_digest();
}

} // namespace

Mesh build_mesh(const Polygons& poly, std::string source, const MeshLoadOptions& options) {
  const bool use_normals = options.use_file_normals && !poly.corner_normal.empty();
  validate(poly, source, use_normals);
  auto corner_normal = [&](size_t c) -> const Eigen::Vector3f* {
    const uint32_t n = use_normals ? poly.corner_normal[c] : Polygons::kNoNormal;
    return n == Polygons::kNoNormal ? nullptr : &poly.normals[n];
  };

  // Output vertices: file positions in file order, then (position, normal) splits in order of
  // first appearance in the face list.
  Mesh mesh;
  const auto n_file = static_cast<uint32_t>(poly.positions.size());
  std::vector<const Eigen::Vector3f*> vertex_file_normal(n_file, nullptr);
  std::vector<uint8_t> claimed(n_file, 0);
  std::vector<CornerKey> row_key(n_file);
  std::unordered_map<CornerKey, uint32_t, CornerKeyHash> splits;
  Eigen::AlignedBox3d bounds;
  for (const Eigen::Vector3d& p : poly.positions) bounds.extend(p);
  mesh.origin = frame_origin(bounds);  // not empty: validate() found a polygon, so a position
  mesh.positions = offsets_from(poly.positions, mesh.origin, source);
  mesh.source_position.resize(n_file);
  for (uint32_t v = 0; v < n_file; ++v) mesh.source_position[v] = v;
  std::vector<uint32_t> corner_vertex(poly.corner_position.size());
  for (size_t c = 0; c < poly.corner_position.size(); ++c) {
    const uint32_t p = poly.corner_position[c];
    const Eigen::Vector3f* n = corner_normal(c);
    const CornerKey key = make_key(p, n);
    if (!claimed[p]) {
      claimed[p] = 1;
      row_key[p] = key;
      vertex_file_normal[p] = n;
      corner_vertex[c] = p;
    } else if (row_key[p] == key) {
      corner_vertex[c] = p;
    } else {
      const auto [it, inserted] = splits.try_emplace(key, static_cast<uint32_t>(mesh.positions.size()));
      if (inserted) {
        const Eigen::Vector3f offset = mesh.positions[p];
        mesh.positions.push_back(offset);
        mesh.source_position.push_back(p);
        vertex_file_normal.push_back(n);
      }
      corner_vertex[c] = it->second;
    }
  }
  if (mesh.positions.size() >= std::numeric_limits<uint32_t>::max()) throw InputError(source, "too many vertices for 32-bit indices");

  // Fan triangulation in place (each fan triangle reversed when flipping), as the polygon
  // corners of each triangle corner: the rows and the texture coordinates both follow them.
  const int second = options.flip_normals ? 1 : 0;
  std::vector<uint32_t> fan_corner;
  for (size_t f = 0; f < poly.polygon_count(); ++f) {
    const uint32_t b = poly.offsets[f], e = poly.offsets[f + 1];
    for (uint32_t i = b + 1; i + 1 < e; ++i) fan_corner.insert(fan_corner.end(), {b, i + second, i + 1 - second});
  }
  mesh.triangles.resize(fan_corner.size() / 3);
  for (size_t t = 0; t < mesh.triangles.size(); ++t)
    for (size_t k = 0; k < 3; ++k) mesh.triangles[t][k] = corner_vertex[fan_corner[3 * t + k]];
  for (const Polygons::Uvs& set : poly.uv_sets) {
    UvSet& out = mesh.uv_sets.emplace_back();
    out.name = set.name;
    out.corners.reserve(fan_corner.size());
    for (uint32_t c : fan_corner) out.corners.push_back(set.values[set.corner[c]]);
  }

  // Normals: the file's where usable, else angle-weighted over welded positions.
  mesh.normals.resize(mesh.positions.size());
  bool any_file = false, need_computed = false;
  std::vector<uint8_t> from_file(mesh.positions.size(), 0);
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    const Eigen::Vector3f* n = vertex_file_normal[v];
    const float len = n ? n->norm() : 0.0f;
    if (n && len > 0.0f && std::isfinite(len)) {
      mesh.normals[v] = (options.flip_normals ? -*n : *n) / len;
      from_file[v] = 1;
      any_file = true;
    } else {
      need_computed = true;
    }
  }
  if (need_computed) {
    const auto computed = welded_angle_weighted_normals(mesh.positions, mesh.triangles);
    for (size_t v = 0; v < mesh.positions.size(); ++v)
      if (!from_file[v]) mesh.normals[v] = computed[v];
  }
  mesh.normal_source = any_file ? Mesh::NormalSource::File : Mesh::NormalSource::AngleWeighted;
  mesh.source = std::move(source);
  mesh.file_positions = n_file;
  mesh.file_faces = poly.polygon_count();
  return mesh;
}

Mesh load_mesh(const std::filesystem::path& path, const MeshLoadOptions& options) {
  const std::string file = path.string();
  require_file(path, file);
  const std::string ext = mesh_readers::lowercase(path.extension().string());
  const FormatEntry* format = nullptr;
  for (const FormatEntry& f : kFormats)
    if (f.extension == ext) format = &f;
  if (!format) {
    std::string supported;
    for (const FormatEntry& f : kFormats) supported += (supported.empty() ? "" : " ") + std::string(f.extension);
    throw InputError(file, "unknown mesh format " + mesh_readers::shown(ext.empty() ? path.filename().string() : ext) +
                               " (supported: " + supported + ")");
  }
  return reading_file(file, [&] {
    const std::string bytes = read_whole_file(path, file);
    std::vector<std::string> warnings, referenced;
    const Polygons polygons = format->read(reader_bytes(bytes, *format, file), {path, file, warnings, &referenced});
    Mesh mesh = build_mesh(polygons, file, options);
    mesh.warnings = named(file, std::move(warnings));
    mesh.source_sha256 = source_digest(bytes, referenced);
    return mesh;
  });
}

namespace {
// The instances of a glTF file whose path and format load_mesh_instances has checked.
MeshInstances read_instances(const std::filesystem::path& path, const std::string& file, const MeshLoadOptions& options) {
  const std::string bytes = read_whole_file(path, file);
  MeshInstances result;
  std::vector<std::string> referenced;
  const FormatEntry gltf{".gltf", mesh_readers::read_gltf, bytes.substr(0, 4) != "glTF"};
  std::vector<mesh_readers::GltfInstance> instances =
      mesh_readers::read_gltf_instances(reader_bytes(bytes, gltf, file), {path, file, result.warnings, &referenced}, &result.lights);
  result.source_sha256 = source_digest(bytes, referenced);
  result.warnings = named(file, std::move(result.warnings));
  for (mesh_readers::GltfInstance& in : instances) {
    MeshInstance& out = result.instances.emplace_back();
    try {
      out.mesh = build_mesh(in.polygons, file, options);
    } catch (const InputError& e) {
      throw InputError(file, "node " + in.name + ": " + e.defect());
    }
    out.mesh.source_sha256 = result.source_sha256;
    out.name = std::move(in.name);
    out.node_path = std::move(in.node_path);
    out.base_color = in.base_color;
    out.animated = in.animated;
  }
  return result;
}
} // namespace

MeshInstances load_mesh_instances(const std::filesystem::path& path, const MeshLoadOptions& options) {
  const std::string file = path.string();
  require_file(path, file);
  const std::string ext = mesh_readers::lowercase(path.extension().string());
  if (ext != ".gltf" && ext != ".glb") throw InputError(file, "not a glTF file (.gltf or .glb): it has no instances");
  return reading_file(file, [&] { return read_instances(path, file, options); });
}


} // namespace prt::bake
