// segment_box.h — whether a segment meets an axis-aligned box (the slab test), for tests that
// compare a baked or rendered hard shadow with the closed form: a receiver is in the box's shadow
// iff the segment from it to a point light meets the box. `margin` grows the box (negative:
// shrinks it), so a test can leave out the receivers within rounding of the shadow's edge.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <utility>

namespace prt::testing {

inline bool segment_meets_box(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& box_lo,
                              const Eigen::Vector3d& box_hi, double margin) {
  const Eigen::Vector3d lo = box_lo.array() - margin, hi = box_hi.array() + margin;
  double t0 = 0, t1 = 1;
  for (int k = 0; k < 3; ++k) {
    const double d = q[k] - p[k];
    if (d == 0) {
      if (p[k] < lo[k] || p[k] > hi[k]) return false;
      continue;
    }
    double a = (lo[k] - p[k]) / d, b = (hi[k] - p[k]) / d;
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a), t1 = std::min(t1, b);
  }
  return t0 <= t1;
}

} // namespace prt::testing
