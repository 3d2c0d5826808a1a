// libbake/src/gltf_reader.h — the glTF 2.0 reader (.gltf with external or data-URI buffers, .glb),
// one more entry of the reader table in mesh_io.cpp. Private to libbake.
//
// Parsing is tinygltf's (Debian's libtinygltf, a shared library with its own JSON inside, so it
// cannot meet the nlohmann-json that scene.cpp uses); images are never decoded. What the result
// holds — rows, normals, transforms, primitive modes, what is refused — is documented in
// bake/mesh.h (the glTF paragraphs) and follows the glTF 2.0 specification (Khronos), sections
// "Nodes and Hierarchy", "Transformations", "Accessors" and "Meshes".
#pragma once

#include "mesh_readers.h"

namespace prt::bake::mesh_readers {

Polygons read_gltf(std::string_view bytes, const SourceFile& file);

} // namespace prt::bake::mesh_readers
