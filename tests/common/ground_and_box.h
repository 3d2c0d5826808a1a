// ground_and_box.h — the lit-scene tests' geometry, written as OBJ files: ground.obj, an integer
// grid [-3, 3]² at y = 0 facing +y (quads, counter-clockwise from above), and box.obj, the box
// [-1/2, 1/2] × [1/2, 3/2] × [-1/2, 1/2], outward. Every coordinate is a float exactly, so the
// meshes the bake reads are the geometry of the tests' closed forms.
#pragma once

#include <Eigen/Core>

#include <filesystem>
#include <fstream>

namespace prt::testing {

inline const Eigen::Vector3d kGroundBoxLo(-0.5, 0.5, -0.5), kGroundBoxHi(0.5, 1.5, 0.5);

inline void write_ground_and_box(const std::filesystem::path& d) {
  std::ofstream g(d / "ground.obj");
  for (int z = -3; z <= 3; ++z)
    for (int x = -3; x <= 3; ++x) g << "v " << x << " 0 " << z << "\n";
  for (int j = 0; j < 6; ++j)
    for (int i = 0; i < 6; ++i) {
      const int a = j * 7 + i + 1;
      g << "f " << a << " " << a + 7 << " " << a + 8 << " " << a + 1 << "\n";
    }
  std::ofstream(d / "box.obj") << "v -0.5 0.5 -0.5\nv 0.5 0.5 -0.5\nv -0.5 1.5 -0.5\nv 0.5 1.5 -0.5\n"
                                  "v -0.5 0.5 0.5\nv 0.5 0.5 0.5\nv -0.5 1.5 0.5\nv 0.5 1.5 0.5\n"
                                  "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
}

} // namespace prt::testing
