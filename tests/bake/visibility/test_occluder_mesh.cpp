// The visible part of a light past a triangle mesh (bake/visibility/occluder_mesh.h): the culled query
// against the unculled reference on random non-convex meshes (and both against RQMC ray casting
// with depth up to the light's plane), a box as a mesh against its silhouette loop
// (ConvexPolyhedron), the bunny against Embree ray casting, and the stiff cases of issue 13 that a
// mesh brings: the shade point on the occluder (a vertex of its 1-ring, an edge, a face) in a
// concave wedge, an occluder behind or across the light's plane, a light of solid angle 1e-10.
#include <bake/sphere/polygon_sh.h>
#include <bake/sphere/spherical_polygon.h>
#include <bake/visibility/contour.h>
#include <bake/visibility/occluder_mesh.h>
#include <bake/visibility/raycast.h>
#include <bake/visibility/visible_region.h>

#include <sphere_rqmc.h>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <optional>
#include <random>
#include <vector>

namespace {

using prt::bake::Arc;
using prt::bake::OccluderMesh;
using prt::bake::ShadePoint;
using V3 = Eigen::Vector3d;
using Poly = std::vector<V3>;
using Tri = std::array<uint32_t, 3>;

// A rectangle [x0, x1] × [y0, y1] in the plane z = h (world), counter-clockwise seen from +z.
Poly rect(double x0, double x1, double y0, double y1, double h) {
  return {{x0, y0, h}, {x1, y0, h}, {x1, y1, h}, {x0, y1, h}};
}

double irradiance(const std::vector<Arc>& arcs, const V3& n) { return n.dot(prt::bake::vector_irradiance(arcs)); }

struct Query {
  std::vector<Arc> arcs;
  size_t kept = 0;
};

Query visible(const OccluderMesh& mesh, const Poly& light, const ShadePoint& s, bool reference = false) {
  OccluderMesh::Workspace ws;
  Query q;
  q.kept = reference ? mesh.visible_light_reference(light, s, q.arcs, ws) : mesh.visible_light(light, s, q.arcs, ws);
  return q;
}

// The light's irradiance with nothing in the way (the same clipping path).
double bare(const Poly& light, const ShadePoint& s) {
  return irradiance(visible(OccluderMesh({}, {}), light, s).arcs, s.n);
}

// The light's vertices as directions from p, positively oriented.
Poly directions(const Poly& light, const V3& p) {
  Poly dirs;
  for (const V3& v : light) dirs.push_back(v - p);
  if (dirs[0].dot(dirs[1].cross(dirs[2])) < 0) std::reverse(dirs.begin(), dirs.end());
  return dirs;
}

// Ray from o along w: the distance to the triangle (Möller–Trumbore), if hit.
std::optional<double> hit(const V3& o, const V3& w, const V3& a, const V3& b, const V3& c) {
  const V3 e1 = b - a, e2 = c - a, pv = w.cross(e2);
  const double det = e1.dot(pv);
  if (det == 0) return std::nullopt;
  const V3 tv = o - a;
  const double u = tv.dot(pv) / det;
  if (u < 0 || u > 1) return std::nullopt;
  const V3 qv = tv.cross(e1);
  const double v = w.dot(qv) / det;
  if (v < 0 || u + v > 1) return std::nullopt;
  const double t = e2.dot(qv) / det;
  return t > 0 ? std::optional(t) : std::nullopt;
}

// E = ∫ V·[ω towards the light]·(n·ω)⁺ dω by RQMC (64 × 2^14 directions); a triangle hides ω
// when the ray meets it before the light's plane. The light is a convex planar world polygon.
prt::test::SphereEstimate rqmc(const std::vector<V3>& pos, const std::vector<Tri>& tris, const Poly& light,
                               const ShadePoint& s, uint64_t seed) {
  const Poly dirs = directions(light, s.p);
  const V3 plane_n = (light[1] - light[0]).cross(light[2] - light[0]);
  return prt::test::rqmc_sphere(1, 64, 1 << 14, seed, [&](const V3& w, std::span<double> out) {
    out[0] = 0;
    if (s.n.dot(w) <= 0 || !prt::test::inside_convex(dirs, w)) return;
    const double to_light = plane_n.dot(light[0] - s.p) / plane_n.dot(w);
    for (const Tri& t : tris) {
      const auto d = hit(s.p, w, pos[t[0]], pos[t[1]], pos[t[2]]);
      if (d && *d < to_light) return;
    }
    out[0] = s.n.dot(w);
  });
}

// A random non-convex mesh: a crumpled 4 × 4 grid sheet (random heights, so it folds over
// itself as seen from below) and a few free triangles, some reaching beyond the light's plane z = 3.
struct RandomMesh {
  std::vector<V3> pos;
  std::vector<Tri> tris;
};

RandomMesh random_mesh(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  RandomMesh m;
  const int n = 4;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      m.pos.emplace_back(-1.5 + 3.0 * i / n + 0.6 * (u(rng) - 0.5), -1.5 + 3.0 * j / n + 0.6 * (u(rng) - 0.5),
                         0.8 + 1.6 * u(rng));
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const uint32_t a = uint32_t(j * (n + 1) + i), b = a + 1, c = a + uint32_t(n + 1), d = c + 1;
      if (u(rng) < 0.2) continue;  // holes
      m.tris.push_back({a, b, d});
      m.tris.push_back({a, d, c});
    }
  for (int k = 0; k < 4; ++k) {
    const auto base = uint32_t(m.pos.size());
    const V3 centre(3 * u(rng) - 1.5, 3 * u(rng) - 1.5, 0.5 + 3 * u(rng));
    for (int c = 0; c < 3; ++c) m.pos.push_back(centre + V3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5));
    m.tris.push_back({base, base + 1, base + 2});
  }
  return m;
}

TEST(OccluderMesh, CulledEqualsReferenceOnRandomNonConvexMeshes) {
  // 300 random meshes and shade points: the culled query and the reference (every triangle)
  // make the same exact decisions on the triangles that matter; irradiance and order-4 SH agree
  // to 1e-10 (they differ by the rounding of per-arc sums over different arc sets).
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> u(0, 1);
  const prt::bake::PolygonSH sh(4);
  int shadowed = 0;
  size_t culled = 0, total = 0;
  for (int k = 0; k < 300; ++k) {
    const RandomMesh m = random_mesh(rng);
    const OccluderMesh mesh(m.pos, m.tris);
    const Poly light = rect(-1 + 0.5 * u(rng), 1, -1, 1 - 0.5 * u(rng), 3);
    const ShadePoint s{.p = V3(4 * u(rng) - 2, 4 * u(rng) - 2, -0.5 * u(rng)),
                       .n = V3(u(rng) - 0.5, u(rng) - 0.5, 1).normalized()};
    const Query fast = visible(mesh, light, s), slow = visible(mesh, light, s, true);
    const double e = irradiance(fast.arcs, s.n);
    EXPECT_NEAR(e, irradiance(slow.arcs, s.n), 1e-10) << k;
    std::vector<double> a(16), b(16);
    sh.project(std::span<const Arc>(fast.arcs), a);
    sh.project(std::span<const Arc>(slow.arcs), b);
    for (size_t i = 0; i < 16; ++i) EXPECT_NEAR(a[i], b[i], 1e-10) << k << " " << i;
    shadowed += e < bare(light, s) - 1e-3;
    culled += m.tris.size() - fast.kept;
    total += m.tris.size();
  }
  EXPECT_GT(shadowed, 150);     // the scenes mean something
  EXPECT_GT(culled, total / 10);  // and the culling does cull
}

TEST(OccluderMesh, AgreesWithRqmcRayCastingUpToTheLightsPlane) {
  // The same random meshes (some triangles across or behind the light's plane, clipped or
  // dropped by the exact depth test) against RQMC: 4 standard errors + 1e-12.
  std::mt19937_64 rng(37);
  std::uniform_real_distribution<double> u(0, 1);
  for (int k = 0; k < 6; ++k) {
    const RandomMesh m = random_mesh(rng);
    const Poly light = rect(-1, 1, -1, 1, 3);
    const ShadePoint s{.p = V3(2 * u(rng) - 1, 2 * u(rng) - 1, 0), .n = V3(u(rng) - 0.5, u(rng) - 0.5, 1).normalized()};
    const double e = irradiance(visible(OccluderMesh(m.pos, m.tris), light, s).arcs, s.n);
    const auto est = rqmc(m.pos, m.tris, light, s, 500 + uint64_t(k));
    EXPECT_NEAR(e, est.mean[0], 4 * est.std_error[0] + 1e-12) << k;
  }
}

TEST(OccluderMesh, BoxAsAMeshEqualsItsSilhouetteLoop) {
  // A random box (12 triangles, both facings) between p and the light: the mesh path equals
  // visible_region with the ConvexPolyhedron's silhouette loop, to 1e-10 (sides decided exactly
  // by both; rounding of crossing points and sums only).
  std::mt19937_64 rng(41);
  std::uniform_real_distribution<double> u(0, 1);
  const std::vector<std::vector<uint32_t>> quads{{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                                 {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (int k = 0; k < 500; ++k) {
    const Eigen::Matrix3d r = prt::test::random_rotation(rng);
    const V3 half(0.2 + 0.3 * u(rng), 0.2 + 0.3 * u(rng), 0.2 + 0.3 * u(rng)), centre(u(rng) - 0.5, u(rng) - 0.5, 1.5);
    std::vector<V3> corners;
    for (int c = 0; c < 8; ++c)
      corners.push_back(centre + r * V3(c & 1 ? half.x() : -half.x(), c & 2 ? half.y() : -half.y(),
                                        c & 4 ? half.z() : -half.z()));
    std::vector<Tri> tris;
    for (const auto& q : quads) {
      tris.push_back({q[0], q[1], q[2]});
      tris.push_back({q[0], q[2], q[3]});
    }
    const prt::bake::ConvexPolyhedron body(corners, quads);
    const ShadePoint s{.p = V3(2 * u(rng) - 1, 2 * u(rng) - 1, 0), .n = V3(u(rng) - 0.5, u(rng) - 0.5, 1).normalized()};
    const Poly light = rect(-1, 1, -1, 1, 3);
    Poly loop, rel, clipped;
    ASSERT_TRUE(body.silhouette(s.p, loop));
    for (const V3& v : light) rel.push_back(v - s.p);
    prt::bake::clip_to_horizon(rel, s.n, clipped);
    std::vector<Arc> expected;
    prt::bake::visible_region(clipped, std::vector<Poly>{loop}, expected);
    EXPECT_NEAR(irradiance(visible(OccluderMesh(corners, tris), light, s).arcs, s.n), irradiance(expected, s.n), 1e-10) << k;
  }
}

// The bunny (data/bunny.obj, 3674 triangles, y up, 0 ≤ y ≤ 9.7) under a 6 × 4 quad light at
// y = 12, facing down: shade points on the ground beside it, and on the bunny itself at vertices
// facing the light (their own 1-ring decided in the ε-limit, as Embree's filter does).
TEST(OccluderMesh, BunnyAgainstRayCasting) {
  using namespace prt::bake;
  const Mesh mesh = load_mesh(std::filesystem::path(PRT_DATA_DIR) / "bunny.obj");
  const Topology topo = build_topology(mesh);
  const RayCaster caster(mesh, topo);
  const OccluderMesh occluder(mesh);
  const Poly light{{-3, 12, -2}, {3, 12, -2}, {3, 12, 2}, {-3, 12, 2}};
  std::vector<ShadePoint> points{{.p = V3(-6, 0, 0.5), .n = V3::UnitY()},
                                 {.p = V3(5.5, 0, -1), .n = V3(-0.3, 1, 0).normalized()},
                                 {.p = V3(0.5, 0, 4.5), .n = V3::UnitY()}};
  std::mt19937_64 rng(43);
  while (points.size() < 6) {  // vertices facing up, in the 1-ring limit
    const auto v = uint32_t(rng() % mesh.positions.size());
    const V3 n = mesh.normals[v].cast<double>();
    if (n.y() < 0.3) continue;
    points.push_back({.p = mesh.world_position(v), .n = n, .welded = int64_t(topo.weld[v])});
  }
  int shadowed = 0;
  for (size_t k = 0; k < points.size(); ++k) {
    const ShadePoint& s = points[k];
    const Query q = visible(occluder, light, s);
    const double e = irradiance(q.arcs, s.n);
    const Poly dirs = directions(light, s.p);
    const auto est = prt::test::rqmc_sphere(1, 64, 1 << 14, 700 + k, [&](const V3& w, std::span<double> out) {
      out[0] = s.n.dot(w) > 0 && prt::test::inside_convex(dirs, w) && caster.visible(s, w) ? s.n.dot(w) : 0.0;
    });
    EXPECT_NEAR(e, est.mean[0], 4 * est.std_error[0] + 1e-12) << k;
    EXPECT_LT(q.kept, mesh.triangles.size()) << k;  // the pyramid culls
    shadowed += e < bare(light, s) - 1e-3;
  }
  EXPECT_GE(shadowed, 3);
}

// A concave wedge: the floor z = 0 and a wall leaning over it, plane y = z/2, meeting along the
// x axis; p = 0 on the crease with the floor's normal. From p + εn the wall hides every direction
// with y > z/2, so a light [−0.5, 0.5] × [0, 2] at z = 2 is visible exactly on y < 1.
TEST(OccluderMesh, ShadePointOnTheOccluderInAConcaveWedge) {
  const ShadePoint s{.p = V3::Zero(), .n = V3::UnitZ()};
  const Poly light = rect(-0.5, 0.5, 0, 2, 2);
  const double expected = bare(rect(-0.5, 0.5, 0, 1, 2), s);
  // p a vertex of both fans (its 1-ring), p inside an edge of the wall, p inside one big face.
  const std::vector<V3> fan{{0, 0, 0}, {1, 0, 0}, {1, 0.5, 1}, {-1, 0.5, 1}, {-1, 0, 0}, {1, -1, 0}, {-1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  const std::vector<Tri> fan_tris{{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 6}, {0, 6, 5}, {0, 5, 1},
                                  {0, 7, 1}, {0, 8, 7}, {0, 4, 8}};
  const std::vector<V3> edge{{-1, 0, 0}, {1, 0, 0}, {1, 0.5, 1}, {-1, 0.5, 1}};
  const std::vector<Tri> edge_tris{{0, 1, 2}, {0, 2, 3}};
  const std::vector<V3> face{{-3, -0.5, -1}, {3, -0.5, -1}, {0, 1, 2}};
  const std::vector<Tri> face_tris{{0, 1, 2}};
  for (const auto& [pos, tris] : {std::pair(fan, fan_tris), std::pair(edge, edge_tris), std::pair(face, face_tris)}) {
    const OccluderMesh mesh(pos, tris);
    EXPECT_NEAR(irradiance(visible(mesh, light, s).arcs, s.n), expected, 1e-12);
    EXPECT_NEAR(irradiance(visible(mesh, light, s, true).arcs, s.n), expected, 1e-12);
  }
  // n in the wall's plane: the wall is seen edge-on in the limit and hides nothing.
  const ShadePoint edge_on{.p = V3::Zero(), .n = V3(0, 0.5, 1).normalized()};
  EXPECT_NEAR(irradiance(visible(OccluderMesh(edge, edge_tris), light, edge_on).arcs, edge_on.n), bare(light, edge_on), 1e-12);
}

TEST(OccluderMesh, OccluderBehindOrAcrossTheLight) {
  const ShadePoint s{.p = V3::Zero(), .n = V3::UnitZ()};
  const Poly light = rect(-1, 1, -1, 1, 2);
  // A sheet over the whole light but beyond its plane (and one lying in it): culled, nothing hidden.
  for (double z : {2.5, 2.0}) {
    const OccluderMesh behind({{-5, -5, z}, {5, -5, z}, {5, 5, z}, {-5, 5, z}}, {{0, 1, 2}, {0, 2, 3}});
    const Query q = visible(behind, light, s);
    EXPECT_EQ(irradiance(q.arcs, s.n), bare(light, s));
    EXPECT_EQ(irradiance(visible(behind, light, s, true).arcs, s.n), bare(light, s));
  }
  // A sheet across the light's plane, x = z − 2 (through the light's middle line x = 0, z = 2):
  // a ray to the light point (x0, y0, 2) meets it at z = 2/(1 − x0/2), before the light iff x0 < 0.
  // Its part beyond the light (clipped away exactly) would otherwise hide the other half.
  const OccluderMesh across({{-2, -5, 0}, {2, -5, 4}, {2, 5, 4}, {-2, 5, 0}}, {{0, 1, 2}, {0, 2, 3}});
  for (bool reference : {false, true})
    EXPECT_NEAR(irradiance(visible(across, light, s, reference).arcs, s.n), bare(rect(0, 1, -1, 1, 2), s), 1e-12);
}

TEST(OccluderMesh, TinyLightHalfHidden) {
  // A light of solid angle 1e-10 half hidden by a two-triangle sheet, under random rotations of
  // the scene: the visible half by symmetry, to the relative accuracy of tiny polygons (1e-9, as
  // in the visible_region tests).
  const double h = 0.5e-5;
  std::mt19937_64 rng(47);
  for (int k = 0; k < 20; ++k) {
    const Eigen::Matrix3d r = prt::test::random_rotation(rng);
    auto rotated = [&](const Poly& p) { return prt::test::rotated(r, p); };
    const ShadePoint s{.p = V3::Zero(), .n = r * V3::UnitZ()};
    const Poly light = rotated(rect(-h, h, -h, h, 1));
    const OccluderMesh sheet(rotated(rect(-1, 0, -1, 1, 0.5)), {{0, 1, 2}, {0, 2, 3}});
    EXPECT_NEAR(irradiance(visible(sheet, light, s).arcs, s.n) / bare(light, s), 0.5, 1e-9) << k;
  }
}

} // namespace
