// bake/mesh/mesh_readers.h — one reader per mesh file format, each parsing the file's bytes once
// into a Polygons (bake/mesh/mesh.h; why the readers are ours and not OpenMesh's: mesh_io.cpp).
// Called by load_mesh (mesh_io.cpp) and, on bytes in memory, by the fuzz targets.
//
// Contract of every reader: `bytes` is the whole file; the result holds the file's positions (in
// double: bake/mesh/mesh.h, ORIGIN), normal values and polygons in file order, every polygon exactly
// as written (repeated indices and zero-area polygons included). A reader throws InputError(file.name, "<defect>") — with
// "line N: " where the format has lines — for anything it cannot read; build_mesh checks what
// every format shares (finite positions, index ranges, corner counts, an empty mesh).
#pragma once

#include <bake/mesh/mesh.h>

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace prt::bake::mesh_readers {

struct SourceFile {
  const std::filesystem::path& path;   // for files the format refers to (an OBJ's mtllib)
  const std::string& name;             // for messages: the path as given
  std::vector<std::string>& warnings;  // non-fatal findings, one line each
  // SHA-256 (hex) of every other file whose bytes the parse used (a .gltf's external buffers), in
  // the order they were read; load_mesh folds them into Mesh::source_sha256 (bake/mesh/mesh.h).
  std::vector<std::string>* referenced_sha256 = nullptr;
};

// Shared by the readers and load_mesh's messages.
std::string shown(std::string_view s);  // 'like this', at most 40 characters, unprintables as '?'
std::string lowercase(std::string s);

Polygons read_obj(std::string_view bytes, const SourceFile& file);
Polygons read_ply(std::string_view bytes, const SourceFile& file);
Polygons read_off(std::string_view bytes, const SourceFile& file);
Polygons read_stl(std::string_view bytes, const SourceFile& file);

} // namespace prt::bake::mesh_readers
