// tests/fuzz/fuzz_exr.cpp — libFuzzer target of the environment map reader: the input is an EXR
// file, read with bake::EnvMap::load (bake/environment/envmap.h: lat-long or cube, the pixel policy), under
// both up axes, then projected to SH order 3 as a bake does. Accepted failure: bake::InputError.
#include "fuzz_common.h"

#include <bake/core/error.h>
#include <bake/environment/envmap.h>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::filesystem::path path = prt::fuzz::write_input("input.exr", prt::fuzz::as_bytes(data, size));
  return prt::fuzz::guarded<prt::bake::InputError>([&] {
    for (const prt::bake::UpAxis up : {prt::bake::UpAxis::Y, prt::bake::UpAxis::Z})
      prt::bake::EnvMap::load(path, up).project_sh(3);
  });
}
