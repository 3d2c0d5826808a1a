// bake/lights/area_bake.h — what a shade point receives from each area light, exactly (paper 003 §3:
// the light's spherical polygon minus the occluders', clipped to the horizon, integrated in
// closed form; issue 13). Per shade point and light, at unit radiance (so a light can be dimmed
// and recoloured at run time by multiplying with its RGB radiance):
//   E      = ∫_{visible part of the light} max(n·ω, 0) dω        (irradiance; the diffuse
//            outgoing radiance is albedo/π · Σ_lights radiance · E)
//   S_i    = ∫_{visible part of the light, above the horizon} y_i(ω) dω,  i < order²
//            (the SH projection of the visible light, prtshade's basis: glossy receivers shade
//            with it against their lobe)
// The visible part comes from bake/visibility/occluder_mesh.h (culling, exact depth against each emitting
// face's plane, the shade point's ε-limit) over the scene's occluder mesh, by
// OccluderMesh::visible_light (issue 32: only the image edges that may bound the occluders' union
// are cut — contour, boundary and non-manifold edges, the point's own 1-ring — each against the
// images near it; paper 003 §3.1, §4.4; the per-triangle method stays as the tests' reference,
// OccluderMesh::visible_light_per_triangle, and the output-sensitive cone path is beside it as
// OccluderMesh::visible_light_cone, not used here yet); E from Lambert's vector
// irradiance and S from the polygon's closed-form SH projection (bake/sphere/spherical_polygon.h,
// bake/sphere/polygon_sh.h). A light's faces (bake/lights/lights.h) emit towards their counter-clockwise side
// (both sides for two_sided planar lights); a face contributes where p is strictly on an emitting
// side (decided exactly: orient3d_exact against a point surely in front). A convex solid's faces
// facing p do not overlap as seen from p, so their sum is the solid's image.
//
// Frame: the occluder mesh's (Mesh::origin; docs/ARCHITECTURE.md §3 "Frames"): lights are given
// in world space and moved by −origin once, in double, so that scenes far from the origin keep
// their digits; shade points are in the mesh's frame, as every integrator's.
#pragma once

#include <bake/lights/lights.h>
#include <bake/mesh/mesh.h>
#include <bake/sphere/polygon_sh.h>
#include <bake/visibility/contour.h>
#include <bake/visibility/occluder_mesh.h>

#include <span>
#include <utility>
#include <vector>

namespace prt::bake {

class AreaLightIntegrator {
public:
  // `sh_order` 0: irradiance only. The lights must be valid (validate_light).
  AreaLightIntegrator(std::span<const AreaLight> lights, const Mesh& occluders, int sh_order);

  size_t lights() const noexcept { return faces_.size(); }
  int sh_order() const noexcept { return order_; }
  // Doubles per light in a row: E, then order² SH coefficients.
  size_t per_light() const noexcept { return 1 + size_t(order_) * size_t(order_); }
  size_t width() const noexcept { return lights() * per_light(); }

  // Per-thread scratch, reused across shade points.
  struct Workspace {
    OccluderMesh::Workspace occluders;
    std::vector<Arc> arcs;
    std::vector<double> sh;
  };

  // out[l·per_light() + 0] = E_l, out[l·per_light() + 1 + i] = S_l,i (file comment). Thread-safe
  // with one Workspace per thread.
  void integrate(const ShadePoint& point, std::span<double> out, Workspace& ws) const;

  // visit(arcs) for every face of light `light` that the point sees from an emitting side, with
  // the face's visible part (ws.arcs: past the occluders, clipped to the horizon; never empty):
  // what integrate() sums, for callers that integrate something else over it (view/area_lights.h:
  // a GGX lobe).
  template <class Visit>
  void for_each_visible_face(const ShadePoint& point, size_t light, Workspace& ws, Visit&& visit) const {
    for (const Face& f : faces_[light]) {
      const std::vector<Eigen::Vector3d>& v = f.vertices;
      const int side = orient3d_exact(v[0], v[1], v[2], point.p);
      if (side == 0) continue;                              // p in the face's plane: no solid angle
      if (side != f.front_side && !f.two_sided) continue;  // its back
      occluders_.visible_light(v, point, ws.arcs, ws.occluders);
      if (!ws.arcs.empty()) visit(std::as_const(ws.arcs));
    }
  }

private:
  struct Face {
    std::vector<Eigen::Vector3d> vertices;  // in the mesh's frame
    int front_side = 0;                     // orient3d_exact(v0, v1, v2, ·) on the counter-clockwise side
    bool two_sided = false;
  };
  std::vector<std::vector<Face>> faces_;  // per light
  OccluderMesh occluders_;
  int order_ = 0;
  PolygonSH sh_;
};

} // namespace prt::bake
