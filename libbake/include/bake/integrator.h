// bake/integrator.h — the interface every spherical integrator implements, so products can be
// baked by either the QMC baseline (bake/qmc.h) or the silhouette integrator (paper 001 §3, next)
// and compared value by value.
#pragma once

#include <bake/products.h>

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <string>

namespace prt::bake {

// A point to integrate at. Visibility is the limit from just above the surface, p + εn, ε → 0+
// (DESIGN.md §3): when `welded` names a welded mesh position (bake/mesh.h Topology), the
// triangles of its 1-ring occlude exactly as they do in that limit (a concave ring occludes, a
// flat one does not) with no ε offset; welded = -1 is a free point in space.
struct ShadePoint {
  Eigen::Vector3d p{0, 0, 0};
  Eigen::Vector3d n{0, 0, 1};  // unit; defines H(ω,n) = [n·ω > 0]
  int64_t welded = -1;
  // false: full-sphere mode, H ≡ 1 in every integrand (the FIV products: ∫ V L y_1m dω over the
  // whole sphere). n then only sets the side the limit p + εn is taken from.
  bool hemisphere = true;
};

class Integrator {
public:
  virtual ~Integrator() = default;
  virtual std::string name() const = 0;            // "qmc", "silhouette"
  virtual std::string description() const = 0;     // one line: method and its parameters
  virtual const ProductLayout& layout() const = 0;
  // Writes one row of estimates (layout().width doubles) for the shade point. `point_index`
  // identifies the point for deterministic per-point randomisation. `std_error` (optional, same
  // width) receives each value's estimated standard error (0 for a deterministic integrator).
  // Thread-safe: called concurrently for different points.
  virtual void integrate(const ShadePoint& point, uint64_t point_index, std::span<double> out,
                         std::span<double> std_error = {}) const = 0;
};

} // namespace prt::bake
