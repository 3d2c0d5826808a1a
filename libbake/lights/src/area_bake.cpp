// area_bake.cpp — per-shade-point area-light integrals (bake/lights/area_bake.h).
#include <bake/core/error.h>
#include <bake/lights/area_bake.h>
#include <bake/sphere/spherical_polygon.h>
#include <bake/visibility/contour.h>

#include <algorithm>

namespace prt::bake {
namespace {

std::vector<Eigen::Vector3d> positions_of(const Mesh& m) {
  std::vector<Eigen::Vector3d> p;
  p.reserve(m.positions.size());
  for (const auto& x : m.positions) p.push_back(x.cast<double>());  // the mesh's frame, exactly
  return p;
}

} // namespace

AreaLightIntegrator::AreaLightIntegrator(std::span<const AreaLight> lights, const Mesh& occluders, int sh_order)
    : occluders_(positions_of(occluders), occluders.triangles), order_(sh_order), sh_(std::max(sh_order, 1)) {
  PRT_CHECK(sh_order >= 0);
  for (const AreaLight& light : lights) {
    std::vector<Face>& faces = faces_.emplace_back();
    Eigen::Vector3d lo = light.vertices[0], hi = lo;
    for (const Eigen::Vector3d& v : light.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
    const double size = (hi - lo).norm();
    for (size_t f = 0; f < light.faces.size(); ++f) {
      Face face;
      for (uint32_t i : light.faces[f]) face.vertices.push_back(light.vertices[i] - occluders.origin);
      face.front_side = orient3d_exact(face.vertices[0], face.vertices[1], face.vertices[2],
                                       face.vertices[0] + size * light.face_normal(f));
      PRT_CHECK(face.front_side != 0);
      face.two_sided = light.two_sided;
      faces.push_back(std::move(face));
    }
  }
}

void AreaLightIntegrator::integrate(const ShadePoint& point, std::span<double> out, Workspace& ws) const {
  PRT_CHECK(out.size() == width());
  std::fill(out.begin(), out.end(), 0.0);
  std::vector<double>& sh = ws.sh;
  sh.resize(order_ > 0 ? size_t(order_) * size_t(order_) : 0);
  for (size_t l = 0; l < faces_.size(); ++l) {
    const std::span<double> row = out.subspan(l * per_light(), per_light());
    for_each_visible_face(point, l, ws, [&](const std::vector<Arc>& arcs) {
      row[0] += point.n.dot(vector_irradiance(arcs));
      if (order_ > 0) {
        sh_.project(std::span<const Arc>(arcs), sh);
        for (size_t i = 0; i < sh.size(); ++i) row[1 + i] += sh[i];
      }
    });
  }
}

} // namespace prt::bake
