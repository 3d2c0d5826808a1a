// The area-light integrator (bake/lights/area_bake.h, paper 003) against the silhouette integrator
// (bake/integrators/silhouette.h, paper 001) on the same non-convex occluder, with the light as the whole
// environment (issue 13: "against the silhouette integrator (the light as an emitter in the
// environment) within its discretisation error"). Six one-sided quad lights facing inwards
// enclose the scene, so every direction that the mesh does not block ends on a light of unit
// radiance: summed over the six,
//   Σ_l E_l   = ∫_H V(ω) (n·ω) dω = π · AO,
//   Σ_l S_l,i = ∫_H V(ω) y_i(ω) dω = U_i        (the visibility transfer vector),
// at every vertex of the mesh, each side computed by its own method: exact polygon clipping and
// closed forms on one side, isoline walks over contour edges on the other. The silhouette
// integrator converges at O(h²) in its isoline spacing h = 2/N (its tests): the difference must
// shrink about 16x from N = 64 to N = 256 and stay under the bound measured here.
#include <bake/integrators/silhouette.h>
#include <bake/lights/area_bake.h>
#include <bake/lights/lights.h>
#include <bake/mesh/mesh.h>
#include <bake/mesh/receivers.h>
#include <bake/sphere/sampling.h>

#include <gtest/gtest.h>
#include <test_scenes.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace {

using namespace prt::bake;
using Eigen::Vector3d;
constexpr int kOrder = 3;

// A bumpy terrain (13 × 13 vertices, 288 triangles): hills and valleys that hide parts of each
// other's sky, with smooth normals.
Mesh terrain() {
  const Mesh flat = prt::testing::grid(6, 1.0f);
  std::vector<Eigen::Vector3f> p = flat.positions;
  for (auto& q : p) q.z() = 0.45f * std::sin(3.1f * q.x()) * std::cos(2.3f * q.y()) + 0.2f * q.x() * q.y();
  return make_mesh(std::move(p), flat.triangles, "terrain");
}

// The box [lo, hi] as six quads, each emitting into the box.
std::vector<AreaLight> inward_box(const Vector3d& lo, const Vector3d& hi) {
  const AreaLight outward = make_box_light(0.5 * (lo + hi), hi - lo, Eigen::Matrix3d::Identity());
  std::vector<AreaLight> lights;
  for (const auto& face : outward.faces) {
    std::vector<Vector3d> corners;
    for (auto it = face.rbegin(); it != face.rend(); ++it) corners.push_back(outward.vertices[*it]);
    lights.push_back(make_polygon_light(std::move(corners)));
    lights.back().name = "wall " + std::to_string(lights.size());
    validate_light(lights.back(), "test", lights.back().name);
  }
  return lights;
}

TEST(AreaVsSilhouette, AnEnclosingLightGivesAoAndTheVisibilityVector) {
  const Mesh m = terrain();
  const Topology topo = build_topology(m);
  const std::vector<ShadePoint> pts = vertex_shade_points(m, topo);
  const std::vector<AreaLight> lights = inward_box({-3, -3, -2}, {3, 3, 3});
  const AreaLightIntegrator area(lights, m, kOrder);
  ProductRequest req;
  req.ao = true;
  req.visibility_order = kOrder;
  const ProductLayout L(req);

  // Every third vertex: interior and border ones, on hills and in valleys.
  std::vector<uint32_t> vertices;
  for (uint32_t v = 0; v < m.positions.size(); v += 3) vertices.push_back(v);
  std::vector<double> worst(3, 0.0);
  const int levels[3] = {64, 256, 1024};
  double min_ao = 1;
  for (int j = 0; j < 3; ++j) {
    const SilhouetteIntegrator sil(m, topo, req, SilhouetteOptions{levels[j], 1});
    std::vector<double> row(L.width), arow(area.width());
    AreaLightIntegrator::Workspace ws;
    for (const uint32_t v : vertices) {
      sil.integrate(pts[v], v, row);
      area.integrate(pts[v], arow, ws);
      double e = 0;
      std::vector<double> s(kOrder * kOrder, 0.0);
      for (size_t l = 0; l < area.lights(); ++l) {
        e += arow[l * area.per_light()];
        for (int i = 0; i < kOrder * kOrder; ++i) s[size_t(i)] += arow[l * area.per_light() + 1 + size_t(i)];
      }
      double d = std::abs(e / std::numbers::pi - row[L.ao]);
      for (int i = 0; i < kOrder * kOrder; ++i) d = std::max(d, std::abs(s[size_t(i)] - row[L.visibility + size_t(i)]));
      worst[size_t(j)] = std::max(worst[size_t(j)], d);
      min_ao = std::min(min_ao, row[L.ao]);
    }
    EXPECT_EQ(sil.silhouette_stats().inconsistent_loops, 0u);
  }
  // Measured (worst over 57 vertices of AO and the nine U_i): 1.8e-2 at N = 64, 8.8e-4 at 256,
  // 8.8e-5 at 1024 (x20, then x10: second order, with some first-order aliasing of slivers).
  // Asserted: under 2e-4 at N = 1024 (about twice the measured) and a fall of more than 100x
  // from N = 64: a wrong sign, a missing light face or a ring rule that differs would stall it.
  EXPECT_LT(worst[2], 2e-4);
  EXPECT_GT(worst[0] / std::max(worst[2], 1e-300), 100.0) << worst[0] << " -> " << worst[1] << " -> " << worst[2];
  EXPECT_LT(min_ao, 0.8) << "the terrain must hide a good part of some vertices' sky";
}

} // namespace
