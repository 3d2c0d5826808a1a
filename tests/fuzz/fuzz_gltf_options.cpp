// tests/fuzz/fuzz_gltf_options.cpp — libFuzzer target of the glTF scene options file (bake/bake/scene.h
// "glTF SCENES": `prtbake scene x.gltf --options o.json`): the input is the options JSON, read
// with bake::load_scene(kScene, input) against one fixed glTF scene whose instances are
// root/a, root/a#p1, root/b, root/b#p1 (so that "objects" keys can name instances and node
// paths). Accepted failure: bake::InputError.
#include "fuzz_common.h"

#include <bake/bake/scene.h>
#include <bake/core/error.h>

namespace {

// One triangle (positions (0,0,0), (1,0,0), (0,1,0) as a data URI), a mesh of two primitives
// (the second with a material), placed under two child nodes of "root".
constexpr std::string_view kScene = R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],
"nodes":[{"name":"root","children":[1,2]},{"name":"a","mesh":0},{"name":"b","mesh":0,"translation":[2,0,0]}],
"materials":[{"pbrMetallicRoughness":{"baseColorFactor":[0.5,0.25,1,1]}}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0}},{"attributes":{"POSITION":0},"material":0}]}],
"accessors":[{"bufferView":0,"componentType":5126,"type":"VEC3","count":3,"min":[0,0,0],"max":[1,1,0]}],
"bufferViews":[{"buffer":0,"byteLength":36}],
"buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}]})";

std::filesystem::path scene_path;

} // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  scene_path = prt::fuzz::write_input("scene.gltf", kScene);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::filesystem::path path = prt::fuzz::write_input("options.json", prt::fuzz::as_bytes(data, size));
  return prt::fuzz::guarded<prt::bake::InputError>([&] { prt::bake::load_scene(scene_path, path); });
}
