// tests/fuzz/fuzz_mesh.cpp — one libFuzzer target per mesh format (OBJ, PLY, OFF, STL, glTF,
// GLB), compiled once per format with PRT_FUZZ_FORMAT = obj | ply | off | stl | gltf | glb.
// The input is the whole file. It goes the way load_mesh takes it (libbake/mesh/src/mesh_io.cpp):
// the format's reader parses the bytes in memory (mesh_readers.h, gltf_reader.h), build_mesh
// turns the polygons into a Mesh, and the welded topology and winding facts prtbake computes
// before a bake follow. glTF also takes load_mesh_instances' path (one Mesh per instance). The
// only accepted failure is bake::InputError (bake/mesh/mesh.h "ERRORS"); fuzz_common.h says the rest.
#include "fuzz_common.h"
#include <bake/mesh/gltf_reader.h>
#include <bake/mesh/mesh_readers.h>

#include <bake/core/error.h>
#include <bake/mesh/mesh.h>

#include <fstream>
#include <vector>

namespace {

namespace mr = prt::bake::mesh_readers;
namespace bake = prt::bake;

#define PRT_FUZZ_STR2(x) #x
#define PRT_FUZZ_STR(x) PRT_FUZZ_STR2(x)
const std::string kName = "input." PRT_FUZZ_STR(PRT_FUZZ_FORMAT);

void bake_ready(const bake::Polygons& polygons) {
  const bake::Mesh mesh = bake::build_mesh(polygons, kName);
  const bake::Topology topology = bake::build_topology(mesh);
  bake::winding_facts(mesh, topology);
}

} // namespace

// A .gltf may name external buffers relative to itself: one exists ("b.bin", the 36 bytes of a
// triangle's float positions, as in seeds/gltf/external.gltf), so that path is exercised too.
extern "C" int LLVMFuzzerInitialize(int*, char***) {
  const float triangle[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  prt::fuzz::write_input("b.bin", {reinterpret_cast<const char*>(triangle), sizeof triangle});
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes = prt::fuzz::as_bytes(data, size);
  const std::filesystem::path path = prt::fuzz::scratch_dir() / kName;  // never written: readers get the bytes
  return prt::fuzz::guarded<bake::InputError>([&] {
    std::vector<std::string> warnings;
    const mr::SourceFile file{path, kName, warnings};
#if defined(PRT_FUZZ_GLTF)
    bake_ready(mr::read_gltf(bytes, file));
    for (const mr::GltfInstance& instance : mr::read_gltf_instances(bytes, file)) bake_ready(instance.polygons);
#else
    bake_ready(mr::PRT_FUZZ_READER(bytes, file));
#endif
  });
}
