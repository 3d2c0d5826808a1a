// RayCaster::first_surface_hit (bake/visibility/raycast.h): the triangle, the point (by its
// barycentric weights) and the side where a blocked ray meets the surface, as the gather rays of
// interreflection read it (bake/bake/bounce.h). The uniform field of the integrating sphere's test
// would not notice wrong weights: here the point they give is compared with the ray's own.
#include <bake/mesh/mesh.h>
#include <bake/mesh/receivers.h>
#include <bake/sphere/sampling.h>
#include <bake/visibility/raycast.h>

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace prt::bake;
using Eigen::Vector3d;
using Eigen::Vector3f;

namespace {

Vector3d point_of(const Mesh& mesh, const SurfaceHit& hit) {
  const auto& t = mesh.triangles[hit.triangle];
  return (1 - hit.w1 - hit.w2) * mesh.positions[t[0]].cast<double>() + hit.w1 * mesh.positions[t[1]].cast<double>() +
         hit.w2 * mesh.positions[t[2]].cast<double>();
}

// Cosine-distributed directions about n (the gather's warp), from a rotated Halton sequence.
std::vector<Vector3d> directions(const Vector3d& n, int count) {
  const Frame frame(n);
  const RotatedHalton3 halton(3, 0);
  std::vector<Vector3d> out;
  for (int k = 0; k < count; ++k) {
    const auto u = halton(uint64_t(k));
    out.push_back(frame.to_world(cosine_hemisphere(u[1], u[2])).normalized());
  }
  return out;
}

} // namespace

// A floor vertex under a ceiling (Embree's hits): the weights rebuild the point where the ray meets
// the ceiling's plane; met from the front when the ceiling faces the floor, from behind when not.
TEST(SurfaceHit, FarHitsAreThePointOnTheTriangle) {
  for (const bool facing_down : {true, false}) {
    std::vector<Vector3f> p = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, {0, 0, 0},
                               {-9, -9, 1}, {9, -9, 1}, {9, 9, 1}, {-9, 9, 1}};
    // The floor: a fan around vertex 4 (facing +z); the ceiling: two triangles at z = 1.
    std::vector<std::array<uint32_t, 3>> t = {{4, 0, 1}, {4, 1, 2}, {4, 2, 3}, {4, 3, 0}};
    if (facing_down) t.insert(t.end(), {{5, 7, 6}, {5, 8, 7}});
    else t.insert(t.end(), {{5, 6, 7}, {5, 7, 8}});
    const Mesh mesh = make_mesh(p, t, "floor_and_ceiling");
    const Topology topo = build_topology(mesh);
    const RayCaster rays(mesh, topo);
    const ShadePoint sp = vertex_shade_point(mesh, topo, 4);
    const NearTriangles near = rays.near_triangles(sp);
    int hits = 0;
    for (const Vector3d& d : directions(sp.n, 256)) {
      const auto hit = rays.first_surface_hit(sp, near, d);
      const bool through_ceiling = d.z() > 0 && std::abs(d.x() / d.z()) < 9 && std::abs(d.y() / d.z()) < 9;
      ASSERT_EQ(hit.has_value(), through_ceiling) << d.transpose();
      ASSERT_EQ(hit.has_value(), !rays.visible(sp, near, d));
      if (!hit) continue;
      ++hits;
      EXPECT_GE(hit->triangle, 4u);
      EXPECT_EQ(hit->front, facing_down);
      const Vector3d expect = sp.p + d / d.z();  // the plane z = 1
      EXPECT_LT((point_of(mesh, *hit) - expect).norm(), 1e-5) << d.transpose();
    }
    EXPECT_GT(hits, 200);
  }
}

// A vertex in a concave crease (floor and wall meet at it): every ray the wall or the floor blocks
// meets the surface at the vertex itself, from the front; the rest see sky. The wall is either in
// the vertex's 1-ring (weight 1 on its corner there) or a T-junction: the vertex lies on the wall's
// bottom edge, not at a corner (a near triangle, decided exactly: the point at mid-edge).
TEST(SurfaceHit, CreaseHitsAreTheVertexItself) {
  for (const bool t_junction : {false, true}) {
    // p = (0,0,0); the floor x <= 0 facing +z and the wall x = 0 facing −x.
    std::vector<Vector3f> pos = {{0, 0, 0}, {0, -1, 0}, {-1, -1, 0}, {-1, 0, 0}, {-1, 1, 0},
                                 {0, 1, 0}, {0, -1, 1}, {0, 0, 1},   {0, 1, 1}};
    std::vector<std::array<uint32_t, 3>> tri = {{0, 2, 1}, {0, 3, 2}, {0, 4, 3}, {0, 5, 4}};  // floor: a fan around p
    if (t_junction) {
      tri.insert(tri.end(), {{1, 6, 5}, {6, 8, 5}});  // the wall's corners (0, ±1, 0), (0, ±1, 1): p mid-edge
    } else {
      tri.insert(tri.end(), {{0, 1, 6}, {0, 6, 7}, {0, 7, 8}, {0, 8, 5}});  // a fan around p
    }
    const Vector3f bisector = Vector3f(-1, 0, 1).normalized();
    const Mesh mesh = make_mesh(pos, tri, "crease", std::vector<Vector3f>(pos.size(), bisector));
    const Topology topo = build_topology(mesh);
    const RayCaster rays(mesh, topo);
    const ShadePoint sp = vertex_shade_point(mesh, topo, 0);
    const NearTriangles near = rays.near_triangles(sp);
    EXPECT_EQ(near.tests.size(), t_junction ? 1u : 0u);  // the wall triangle whose edge carries p
    int wall = 0, floor = 0, sky = 0;
    for (const Vector3d& d : directions(sp.n, 256)) {
      const auto hit = rays.first_surface_hit(sp, near, d);
      ASSERT_EQ(hit.has_value(), !rays.visible(sp, near, d));
      if (!hit) {
        ++sky;
        EXPECT_TRUE(d.x() < 0 && d.z() > 0) << d.transpose();
        continue;
      }
      EXPECT_TRUE(hit->front);
      EXPECT_LT((point_of(mesh, *hit) - sp.p).norm(), 1e-12) << d.transpose();
      const bool on_wall = hit->triangle >= 4;
      (on_wall ? wall : floor) += 1;
      EXPECT_EQ(on_wall, d.x() > 0) << d.transpose();
    }
    EXPECT_GT(wall, 10);
    EXPECT_GT(floor, 10);
    EXPECT_GT(sky, 10);
  }
}
