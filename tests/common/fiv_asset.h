// tests/common/fiv_asset.h — the smallest FIV file model the format tests start from: one occluder
// "bunny" of 2 × 2 × 3 shell samples (every value `shell`, every sample valid), centre (0, 1, 0),
// bounding radius `radius`, radii `radii`, a root of format_version kFormatVersion. Each test adds
// the version-7 data it is about (a cone table, surface-following shells).
#pragma once

#include <formats/asset.h>

#include <string>
#include <utility>
#include <vector>

namespace prt::testing {

inline formats::Asset small_fiv_asset(float shell, double radius, std::vector<double> radii, std::string valid_meaning) {
  formats::Asset a;
  a.root = {formats::kFormatVersion, "test", "2024-01-02T03:04:05Z", "prtbake fiv bunny.obj", "bunny.obj", std::string(64, 'a'),
            "y", "real orthonormal", {}};
  formats::Occluder& o = a.occluders.emplace_back();
  o.name = "bunny";
  o.n_rho = 2, o.n_theta = 2, o.n_phi = 3;
  o.shells.assign(2 * 2 * 3 * 9, shell);
  o.centre = {0, 1, 0};
  o.radius = radius;
  o.radii = std::move(radii);
  o.valid = formats::OccluderValid{std::vector<uint8_t>(12, 1), std::move(valid_meaning), {}};
  return a;
}

} // namespace prt::testing
