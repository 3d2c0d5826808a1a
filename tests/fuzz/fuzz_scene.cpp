// tests/fuzz/fuzz_scene.cpp — libFuzzer target of the scene-file parser: the input is a scene
// JSON file (bake/bake/scene.h), read with bake::load_scene (parse and validate; the meshes and the
// environment it names are not opened by load_scene). Accepted failure: bake::InputError.
#include "fuzz_common.h"

#include <bake/bake/scene.h>
#include <bake/core/error.h>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::filesystem::path path = prt::fuzz::write_input("input.json", prt::fuzz::as_bytes(data, size));
  return prt::fuzz::guarded<prt::bake::InputError>([&] { prt::bake::load_scene(path); });
}
