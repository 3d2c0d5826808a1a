// bake/visibility/accel.h — the acceleration structures of one mesh, built once and shared by every
// integrator of that mesh (docs/ARCHITECTURE.md §4 "Data path": mesh → contour edges): the ray
// scene (bake/visibility/raycast.h), which QMC traces and the silhouette integrator counts its start rays
// with, and the dual-space contour tree (bake/visibility/contour.h, paper 001 §3.1 eq. 6).
//
// The target-error chooser runs integrators at several knobs on the same mesh, then the bake and
// its error report run two more; without sharing, each would build its own trees (on a 1M-triangle
// mesh the contour tree alone takes seconds). The structures depend only on the mesh, never on
// the knob or the products, so sharing changes no output bit. Each is built on first use
// (thread-safe): a QMC-only bake never builds the contour tree. Integrators keep what they use
// alive (shared ownership), so a MeshAccel may go before them; the mesh and topology must not.
#pragma once

#include <bake/mesh/mesh.h>

#include <memory>
#include <mutex>

namespace prt::bake {

class ContourFinder;
class RayCaster;

class MeshAccel {
public:
  MeshAccel(const Mesh& mesh, const Topology& topology) : mesh_(mesh), topology_(topology) {}
  MeshAccel(const MeshAccel&) = delete;
  MeshAccel& operator=(const MeshAccel&) = delete;

  std::shared_ptr<const RayCaster> rays() const;
  std::shared_ptr<const ContourFinder> contours() const;
  bool contours_built() const;

  const Mesh& mesh() const noexcept { return mesh_; }
  const Topology& topology() const noexcept { return topology_; }
  // Whether these structures are the ones of (mesh, topology): integrators check it.
  bool of(const Mesh& mesh, const Topology& topology) const noexcept { return &mesh == &mesh_ && &topology == &topology_; }

private:
  const Mesh& mesh_;
  const Topology& topology_;
  mutable std::mutex mutex_;
  mutable std::shared_ptr<const RayCaster> rays_;
  mutable std::shared_ptr<const ContourFinder> contours_;
};

} // namespace prt::bake
