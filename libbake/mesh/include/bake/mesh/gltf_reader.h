// bake/mesh/gltf_reader.h — the glTF 2.0 reader (.gltf with external or data-URI buffers, .glb),
// one more entry of the reader table in mesh_io.cpp. Called by load_mesh and the fuzz targets.
//
// Parsing is tinygltf's (Debian's libtinygltf, a shared library with its own JSON inside, so it
// cannot meet the nlohmann-json that the scene files' parser, scene_json.cpp, uses); images are
// never decoded. What the result
// holds — rows, normals, transforms, primitive modes, what is refused — is documented in
// bake/mesh/mesh.h (the glTF paragraphs) and follows the glTF 2.0 specification (Khronos), sections
// "Nodes and Hierarchy", "Transformations", "Accessors" and "Meshes".
#pragma once

#include <bake/mesh/mesh_readers.h>

#include <array>
#include <optional>

namespace prt::bake::mesh_readers {

// All primitive instances of the default scene, concatenated (load_mesh, `prtbake vertex`).
Polygons read_gltf(std::string_view bytes, const SourceFile& file);

// The same walk, each primitive instance that has triangles kept apart (load_mesh_instances,
// glTF scenes): its name (the rule in bake/mesh/mesh.h "glTF scenes"), its base colour, and its own
// Polygons in world space with its own rows and normals.
struct GltfInstance {
  std::string name, node_path;
  std::optional<std::array<double, 3>> base_color;  // the material's baseColorFactor RGB; none without a material
  bool animated = false;  // an animation channel (translation, rotation, scale) targets its node or an ancestor
  Polygons polygons;
};
// `lights` (optional): the KHR_lights_punctual lights the default scene's nodes instance
// (bake/mesh/mesh.h GltfLight), in walk order.
std::vector<GltfInstance> read_gltf_instances(std::string_view bytes, const SourceFile& file,
                                              std::vector<GltfLight>* lights = nullptr);

} // namespace prt::bake::mesh_readers
