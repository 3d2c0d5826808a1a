// accel.cpp — shared acceleration structures of one mesh (bake/visibility/accel.h).
#include <bake/visibility/accel.h>
#include <bake/visibility/contour.h>
#include <bake/visibility/raycast.h>

namespace prt::bake {

std::shared_ptr<const RayCaster> MeshAccel::rays() const {
  const std::lock_guard lock(mutex_);
  if (!rays_) rays_ = std::make_shared<const RayCaster>(mesh_, topology_);
  return rays_;
}

std::shared_ptr<const ContourFinder> MeshAccel::contours() const {
  const std::lock_guard lock(mutex_);
  if (!contours_) contours_ = std::make_shared<const ContourFinder>(mesh_, topology_);
  return contours_;
}

bool MeshAccel::contours_built() const {
  const std::lock_guard lock(mutex_);
  return contours_ != nullptr;
}

} // namespace prt::bake
