// enclosure.cpp — shade points inside the geometry (bake/visibility/enclosure.h).
#include <bake/sphere/sampling.h>
#include <bake/visibility/enclosure.h>

#include <array>
#include <cmath>
#include <numbers>

namespace prt::bake {
namespace {

// Local directions (+z = n): the normal, then rings of 8 at polar angles 30°, 60° and 80° with
// staggered azimuths.
struct Directions {
  std::array<Eigen::Vector3d, 25> d;
  Directions() {
    d[0] = {0, 0, 1};
    size_t k = 1;
    const double polar[3] = {30, 60, 80};
    for (int ring = 0; ring < 3; ++ring)
      for (int i = 0; i < 8; ++i) {
        const double theta = polar[ring] * std::numbers::pi / 180;
        const double phi = (i + 0.5 * ring) * std::numbers::pi / 4 + 0.1;
        d[k++] = {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
      }
  }
};

} // namespace

bool enclosed(const ShadePoint& point, const RayCaster& rays) {
  static const Directions local;
  const Frame frame(point.n);
  int decided = 0;
  for (const Eigen::Vector3d& l : local.d) {
    const CrossingCount c = rays.count_crossings(point, frame.to_world(l).normalized());
    if (c.ambiguous) continue;
    if (c.count % 2 == 0) return false;
    ++decided;
  }
  return decided >= kEnclosureDirections;
}

} // namespace prt::bake
