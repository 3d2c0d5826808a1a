// The unit box of the lightmap tests as OBJ lines, shared by the texel bake test and the export
// test: [−½, ½]² × [0, 1] standing on z = 0, its 12 triangles wound outwards.
#pragma once

#include <ostream>

namespace prt::testing {

// Writes the box's 8 `v` lines, then 12 `f` lines whose vertices are numbered from `first` (the
// OBJ index of the first `v` written here) and all use texture vertex `vt`.
inline void write_unit_box_obj(std::ostream& out, int first, int vt) {
  for (int k = 0; k < 8; ++k)
    out << "v " << (k & 1 ? 0.5 : -0.5) << " " << (k & 2 ? 0.5 : -0.5) << " " << (k & 4 ? 1 : 0) << "\n";
  const int faces[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                            {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  for (const auto& f : faces)
    out << "f " << f[0] + first << "/" << vt << " " << f[1] + first << "/" << vt << " " << f[2] + first << "/" << vt << "\n";
}

} // namespace prt::testing
