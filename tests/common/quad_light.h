// quad_light.h — a formats::Light for tests that need lights in a file: the unit-radiance quad
// [−1, 1]² at height y, one face (a file's /lights/<name>, formats/SCHEMA.md).
#pragma once

#include <formats/asset.h>

#include <string>

namespace prt::testing {

inline formats::Light quad_light(std::string name, double y = 4) {
  formats::Light l;
  l.name = std::move(name);
  l.shape = "quad";
  l.radiance = {1, 1, 1};
  l.two_sided = 0;
  l.vertices.values = {-1, y, -1, 1, y, -1, 1, y, 1, -1, y, 1};
  l.face_sizes.values = {4};
  l.face_indices.values = {0, 1, 2, 3};
  return l;
}

} // namespace prt::testing
