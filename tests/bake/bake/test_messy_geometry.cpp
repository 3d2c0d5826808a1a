// Messy geometry as architectural and CAD exports have it, with exact answers at the limit
// p + εn (docs/ARCHITECTURE.md §3) for both integrators: a box corner lying on another object's
// face or edge without a vertex there (T-junctions, one, two and three at once), coplanar
// overlapping sheets, duplicated faces, and a double-sided panel made of two coincident sheets
// with opposite winding. Expected values are Lambert's polygon formula on the visible spherical
// polygon clipped to the hemisphere (tests/common/test_scenes.h polygon_form_factor).
//
// The limit, in closed form: an occluder that is locally a convex cone with apex p (a box corner,
// a slab's edge, a sheet through p) blocks, seen from p + εn as ε → 0, exactly the directions d
// with n + t d in the cone for some t > 0: the spherical convex hull of the cone's edge rays and
// −n (the direction in which p itself is seen). A sheet through p blocks the half space behind it;
// a box corner with p + εn outside it blocks the hull of its three edge directions and −n, which
// is its octant plus directions that, in these scenes, the floor and walls block anyway — except
// on the slab's edge, where the test clips the hull explicitly.
//
// Tolerances: the silhouette integrator at N = 256 isolines has an O(h²) discretisation error,
// h = 2/256, bounded by kAnalyticTol = 1e-4 for these polygonal regions (as in
// test_silhouette.cpp); QMC is compared within 4 of its own standard errors, plus 1e-12 for
// rounding when every ray agrees (its standard error is then 0).
#include <bake/bake/vertex_bake.h>
#include <bake/integrators/qmc.h>
#include <bake/integrators/silhouette.h>
#include <bake/mesh/mesh.h>

#include <gtest/gtest.h>
#include <test_scenes.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

using namespace prt::bake;
using Eigen::Vector3d;
using Eigen::Vector3f;

namespace {

constexpr double kAnalyticTol = 1e-4;
constexpr double kPi = std::numbers::pi;

// A spherical polygon (unit vertices, every edge shorter than π, interior on the left of each
// edge as seen from outside the sphere: a × t points inside) clipped to the hemisphere n·d ≥ 0
// (Sutherland–Hodgman on great circles: where an edge crosses the horizon, the combination of its
// ends with zero n-component). Between an exit and the next entry the boundary runs along the
// horizon, in the direction n × a that keeps the clipped region on the left; it is cut into arcs
// of at most π/4 so that Lambert's formula sees every edge's great circle.
std::vector<Vector3d> clip_to_hemisphere(const std::vector<Vector3d>& poly, const Vector3d& n) {
  std::vector<Vector3d> clipped;
  std::vector<bool> on_horizon;
  for (size_t i = 0; i < poly.size(); ++i) {
    const Vector3d &a = poly[i], &b = poly[(i + 1) % poly.size()];
    const double sa = n.dot(a), sb = n.dot(b);
    if (sa >= 0) {
      clipped.push_back(a);
      on_horizon.push_back(sa == 0);
    }
    if ((sa < 0) != (sb < 0) && sa != 0 && sb != 0) {
      clipped.push_back((sa * b - sb * a).normalized() * (sa < 0 ? -1.0 : 1.0));
      on_horizon.push_back(true);
    }
  }
  std::vector<Vector3d> out;
  for (size_t i = 0; i < clipped.size(); ++i) {
    const Vector3d &a = clipped[i], &b = clipped[(i + 1) % clipped.size()];
    out.push_back(a);
    if (!on_horizon[i] || !on_horizon[(i + 1) % clipped.size()]) continue;
    // Only a run along the horizon can be π or longer; split it (a and b are both on it).
    const Vector3d t = n.cross(a).normalized();
    double phi = std::atan2(t.dot(b), a.dot(b));
    if (phi <= 0) phi += 2 * kPi;  // the way round that keeps the region on the left
    const int steps = int(std::ceil(phi / (kPi / 4)));
    for (int k = 1; k < steps; ++k) out.push_back(std::cos(k * phi / steps) * a + std::sin(k * phi / steps) * t);
  }
  return out;
}

// The polygon with its interior on the left of each edge seen from outside (reversed if needed;
// the vertices' mean direction must lie inside it).
std::vector<Vector3d> oriented(std::vector<Vector3d> poly) {
  Vector3d c = Vector3d::Zero(), turn = Vector3d::Zero();
  for (const auto& v : poly) c += v;
  for (size_t i = 0; i < poly.size(); ++i) turn += poly[i].cross(poly[(i + 1) % poly.size()]);
  if (turn.dot(c) < 0) std::reverse(poly.begin(), poly.end());
  return poly;
}

// AO of a shade point whose visible directions are `seen` minus `blocked` (spherical polygons,
// `blocked` inside `seen`): Lambert's formula on each, clipped to the hemisphere of n.
double exact_ao(const Vector3d& n, const std::vector<Vector3d>& seen, const std::vector<Vector3d>& blocked = {}) {
  auto lambert = [&](const std::vector<Vector3d>& poly) {
    const auto c = clip_to_hemisphere(oriented(poly), n);
    return c.size() < 3 ? 0.0 : prt::testing::polygon_form_factor(Vector3d::Zero(), n, c);
  };
  return lambert(seen) - (blocked.empty() ? 0.0 : lambert(blocked));
}

const Vector3d X = Vector3d::UnitX(), Y = Vector3d::UnitY(), Z = Vector3d::UnitZ();

// A quad (two triangles a b c, a c d) as its own mesh; its diagonal runs a–c.
Mesh quad(Vector3f a, Vector3f b, Vector3f c, Vector3f d, const char* name) {
  return make_mesh({a, b, c, d}, {{0, 1, 2}, {0, 2, 3}}, name);
}

uint32_t vertex_at(const Mesh& m, const Vector3f& p) {
  for (uint32_t v = 0; v < m.positions.size(); ++v)
    if (m.positions[v] == p) return v;
  ADD_FAILURE() << "no vertex at " << p.transpose();
  return 0;
}

struct Both {
  double sil, qmc, qmc_se;
};

// The two integrators for AO, at the settings the tolerances above are for.
struct AoIntegrators {
  static constexpr uint32_t kRays = 4096;
  ProductRequest req = [] {
    ProductRequest r;
    r.ao = true;
    return r;
  }();
  SilhouetteIntegrator sil;
  QmcIntegrator qmc;
  AoIntegrators(const Mesh& m, const Topology& topo) : sil(m, topo, req, {256, 1}), qmc(m, topo, req, [] {
    QmcOptions o;
    o.rays = kRays;
    return o;
  }()) {}
};

// AO at one shade point with both integrators.
Both ao_at(const Mesh& m, const Topology& topo, const ShadePoint& sp, uint64_t index) {
  const AoIntegrators in(m, topo);
  std::vector<double> a(1), b(1), se(1);
  in.sil.integrate(sp, index, a);
  in.qmc.integrate(sp, index, b, se);
  EXPECT_EQ(in.sil.silhouette_stats().inconsistent_loops, 0u);
  return {a[0], b[0], se[0]};
}

void expect_exact(const Both& got, double exact, const char* what) {
  EXPECT_NEAR(got.sil, exact, kAnalyticTol) << what << ": silhouette";
  EXPECT_NEAR(got.qmc, exact, 4 * got.qmc_se + 1e-12) << what << ": qmc (standard error " << got.qmc_se << ")";
}

// Every vertex of the scene: the two integrators agree within 4 QMC standard errors plus the
// silhouette's discretisation bound plus 3/N: when none of QMC's N cosine-distributed rays hits
// an occluder (its standard error is then 0), an occluded set of cosine measure up to 3/N still
// goes unseen with probability ≥ 5% (the rule of three), e.g. a small box near a vertex's horizon.
void expect_agreement(const Mesh& m, const Topology& topo, const char* what) {
  const AoIntegrators in(m, topo);
  const VertexBake a = bake_vertices(m, topo, in.sil), b = bake_vertices(m, topo, in.qmc);
  for (size_t v = 0; v < m.positions.size(); ++v)
    EXPECT_NEAR(a.values[v], b.values[v], 4 * b.std_error[v] + kAnalyticTol + 3.0 / AoIntegrators::kRays)
        << what << ": vertex " << v << " at " << m.positions[v].transpose() << " normal " << m.normals[v].transpose();
  EXPECT_EQ(in.sil.silhouette_stats().inconsistent_loops, 0u) << what;
}

// The unit box [0,1]³ with a corner at the origin, and the big quads through the origin that the
// cases combine: none has a vertex at the origin; the floor's diagonal misses it.
Mesh unit_box() { return prt::testing::box({0, 0, 0}, {1, 1, 1}); }
Mesh floor_through_origin() {  // z = 0, facing +z; the origin lies inside its first triangle
  return quad({-10, -7, 0}, {13, -7, 0}, {13, 11, 0}, {-10, 11, 0}, "floor");
}
Mesh floor_edge_at_origin() {  // z = 0 over y ≥ 0, facing +z: the origin lies on its edge y = 0
  return quad({-10, 0, 0}, {13, 0, 0}, {13, 11, 0}, {-10, 11, 0}, "floor");
}
Mesh wall_edge_at_origin() {  // y = 0 over z ≥ 0, facing +y: the origin lies on its bottom edge
  return quad({-10, 0, 0}, {-10, 0, 9}, {13, 0, 9}, {13, 0, 0}, "wall");
}

// The parts as ONE mesh whose normals are computed over all of it, as load_mesh does for a file
// holding them all (merge_meshes would keep each part's own normals).
Mesh merged(std::initializer_list<Mesh> parts) {
  const std::vector<Mesh> v(parts);
  Mesh m = merge_meshes(v, "scene");
  return make_mesh(std::move(m.positions), std::move(m.triangles), "scene");
}

} // namespace

TEST(MessyGeometry, ClipAndLambertReproduceKnownSolidAngles) {
  // The checks of the closed-form machinery itself: the upper hemisphere (4 equator vertices)
  // gives AO 1 for n = +z and 1/2 for n = +x; the first octant gives 1/4 for n = +z.
  const std::vector<Vector3d> upper = {X, Y, -X, -Y}, octant = {X, Y, Z};
  EXPECT_NEAR(exact_ao(Z, upper), 1.0, 1e-15);
  EXPECT_NEAR(exact_ao(X, upper), 0.5, 1e-15);
  EXPECT_NEAR(exact_ao(Z, octant), 0.25, 1e-15);
  EXPECT_NEAR(exact_ao(Z, upper, octant), 0.75, 1e-15);
}

TEST(MessyGeometry, BoxCornerInsideAFloorFace) {
  // The box's corner lies inside a floor triangle (no floor vertex there). Seen from just above
  // the floor and outside the box, the visible directions are the upper half space minus the box's
  // octant. Before, QMC's rays started on the floor's plane and Embree reported the floor at t = 0.
  const Mesh m = merged({unit_box(), floor_through_origin()});
  const Topology topo = build_topology(m);
  ShadePoint sp = vertex_shade_point(m, topo, vertex_at(m, {0, 0, 0}));
  sp.n = Vector3d(-1, -2, 4).normalized();
  expect_exact(ao_at(m, topo, sp, 0), exact_ao(sp.n, {X, Y, -X, -Y}, {X, Y, Z}), "corner in a floor face");
  // With the box corner's own normal (−1, −1, −1)/√3 the limit point is under the floor sheet:
  // only the lower half space is seen (the box is above the floor).
  const ShadePoint own = vertex_shade_point(m, topo, vertex_at(m, {0, 0, 0}));
  EXPECT_NEAR((own.n - Vector3d(-1, -1, -1).normalized()).norm(), 0, 1e-7);
  expect_exact(ao_at(m, topo, own, 0), exact_ao(own.n, {X, -Y, -X, Y}), "corner in a floor face, own normal");
  expect_agreement(m, topo, "box on a floor");
}

TEST(MessyGeometry, BoxCornerOnTheFloorWallJunction) {
  // The corner lies on an edge of the floor and on an edge of the wall (two T-junctions on edges
  // at once): the visible directions are the quarter space y > 0, z > 0 minus the box's octant.
  // Before, the silhouette integrator dropped the edges through p (their arcs have a − p ∥ b − p).
  const Mesh m = merged({unit_box(), floor_edge_at_origin(), wall_edge_at_origin()});
  const Topology topo = build_topology(m);
  ShadePoint sp = vertex_shade_point(m, topo, vertex_at(m, {0, 0, 0}));
  sp.n = Vector3d(-1, 2, 4).normalized();
  const double exact = exact_ao(sp.n, {X, Y, -X, Z}, {X, Y, Z});
  expect_exact(ao_at(m, topo, sp, 0), exact, "corner on the floor–wall junction");
  expect_agreement(m, topo, "box in a floor–wall corner");
}

TEST(MessyGeometry, BoxCornerOnAnEdgeOfAClosedSlab) {
  // The corner lies on an edge of a closed slab (its top face z = 0 and side face y = 0 meet along
  // the x axis; no slab vertex there), as a wall's corner sits on a floor slab's edge in an
  // architectural export. Seen from p + εn the slab's edge through p is the great half circle from
  // −x through −n to +x; before, the silhouette integrator built its arc from a − p ∥ b − p, a
  // degenerate great circle, and lost that edge's depth steps (AO 0.53 where the exact value is 0
  // in data like this). Outside the slab the visible set is the hemisphere minus the slab's
  // quarter space (y < 0, z < 0) and the box's octant; inside it (the box corner's own normal
  // points into the slab) nothing is seen.
  const Mesh slab = prt::testing::box({-5, -5, -1}, {5, 0, 0}, "slab");
  const Mesh m = merged({unit_box(), slab});
  const Topology topo = build_topology(m);
  ShadePoint sp = vertex_shade_point(m, topo, vertex_at(m, {0, 0, 0}));
  sp.n = Vector3d(-1, 2, 3).normalized();  // p + εn: outside the box (x < 0) and the slab (y, z > 0)
  // The box's visual cone from n is the hull of its edge rays x, y, z and −n, here the triangle
  // (y, z, −n) (x lies inside it); the part of it inside the slab's quarter space is clipped off.
  const Vector3d minus_n = -sp.n;
  const std::vector<Vector3d> slab_quarter = {X, -Y, -X, -Z}, box_cone = {Y, Z, minus_n};
  const auto box_in_slab = clip_to_hemisphere(clip_to_hemisphere(oriented(box_cone), -Y), -Z);
  const double exact = 1 - exact_ao(sp.n, slab_quarter) - (exact_ao(sp.n, box_cone) - exact_ao(sp.n, box_in_slab));
  expect_exact(ao_at(m, topo, sp, 0), exact, "corner on a slab edge, outside the slab");
  const ShadePoint own = vertex_shade_point(m, topo, vertex_at(m, {0, 0, 0}));
  expect_exact(ao_at(m, topo, own, 0), 0.0, "corner on a slab edge, own normal into the slab");
  expect_agreement(m, topo, "box on a slab edge");
}

TEST(MessyGeometry, WallCornerOnASlabEdgeAboveABase) {
  // The configuration of data/regr01-like architectural exports: a wall's bottom corner (vertex
  // at the origin, own normal (1, −1, −1)/√3) stands on a base slab's top face (no base vertex
  // there) and on the bottom edge of an upper slab (no slab vertex there either). p + εn lies
  // inside the base: nothing is seen. The upper slab's edge through p is a contour edge seen from
  // there; with its arc built from a − p ∥ b − p the silhouette integrator lost its depth steps.
  const Mesh wall = prt::testing::box({-1, 0, 0}, {0, 1, 3}, "wall");
  const Mesh upper = prt::testing::box({0, -3, 0}, {5, 3, 2}, "upper slab");
  const Mesh base = prt::testing::box({-5, -5, -2}, {5, 5, 0}, "base");
  const Mesh m = merged({wall, upper, base});
  const Topology topo = build_topology(m);
  const ShadePoint own = vertex_shade_point(m, topo, vertex_at(m, {0, 0, 0}));
  EXPECT_NEAR((own.n - Vector3d(1, -1, -1).normalized()).norm(), 0, 1e-7);
  expect_exact(ao_at(m, topo, own, 0), 0.0, "wall corner inside the base");
  expect_agreement(m, topo, "wall between a base and an upper slab");
}

TEST(MessyGeometry, BoxCornerWhereThreePlanesPassThrough) {
  // A floor (z = 0), a back wall (y = 0) and a side wall (x = 0) all pass through the box corner,
  // inside their faces: from just outside the box in the octant (−x, +y, +z) every other direction
  // is blocked by one of the three sheets.
  const Mesh side = quad({0, -7, -4}, {0, 11, -4}, {0, 11, 9}, {0, -7, 9}, "side wall");
  const Mesh back = quad({-10, 0, -4}, {-10, 0, 9}, {13, 0, 9}, {13, 0, -4}, "back wall");
  const Mesh m = merged({unit_box(), floor_through_origin(), back, side});
  const Topology topo = build_topology(m);
  ShadePoint sp = vertex_shade_point(m, topo, vertex_at(m, {0, 0, 0}));
  sp.n = Vector3d(-1, 2, 4).normalized();
  expect_exact(ao_at(m, topo, sp, 0), exact_ao(sp.n, {Y, -X, Z}), "corner where three planes meet");
  expect_agreement(m, topo, "box where three planes meet");
}

TEST(MessyGeometry, CoplanarOverlapsAndDuplicatedFacesDoNotOcclude) {
  // A floor grid; a rug lying on it (coplanar, overlapping, its corners inside floor faces); a
  // second rug facing down (coplanar, opposite winding); and every floor triangle duplicated.
  // Each surface lies in the others' planes, below p + εn: nothing occludes, AO = 1 everywhere.
  Mesh floor = prt::testing::grid(3, 4.0f);
  const size_t T = floor.triangles.size();
  for (size_t t = 0; t < T; ++t) floor.triangles.push_back(floor.triangles[t]);
  const Mesh up = quad({-1.3f, -0.7f, 0}, {1.1f, -0.7f, 0}, {1.1f, 0.9f, 0}, {-1.3f, 0.9f, 0}, "rug");
  const Mesh down = quad({-0.6f, -1.7f, 0}, {-0.6f, 1.9f, 0}, {2.2f, 1.9f, 0}, {2.2f, -1.7f, 0}, "rug below");
  const Mesh m = merged({floor, up, down});
  const Topology topo = build_topology(m);
  for (size_t v = 0; v < m.positions.size(); ++v) {
    const bool below = v >= floor.positions.size() + up.positions.size();
    EXPECT_EQ(m.normals[v], Vector3f(0, 0, below ? -1.0f : 1.0f)) << v;
    const Both got = ao_at(m, topo, vertex_shade_point(m, topo, uint32_t(v)), v);
    EXPECT_NEAR(got.sil, 1.0, 1e-12) << v;
    EXPECT_NEAR(got.qmc, 1.0, 1e-12) << v;
  }
}

TEST(MessyGeometry, CoincidentSheetsKeepTheirOwnNormals) {
  // A double-sided panel as exporters write it: two coincident sheets with opposite winding and
  // separate vertices, standing on a floor (its bottom corners inside floor faces). Each sheet's
  // vertices keep their own sheet's normal (±x); welded together, the sums cancelled to the +Y
  // fallback. At a top corner the visible directions are those in front of the sheet and above the
  // floor: a quarter sphere, AO = 1/2 exactly.
  const Mesh front = quad({0, -1, 0}, {0, 1, 0}, {0, 1, 2}, {0, -1, 2}, "panel +x");
  const Mesh back = quad({0, -1, 0}, {0, -1, 2}, {0, 1, 2}, {0, 1, 0}, "panel -x");
  // The floor reaches 7·10⁴ away, so the directions escaping under its edges from a height of 2
  // (within 3·10⁻⁵ rad of the horizon) weigh less than 2·10⁻⁵ in AO.
  const Mesh floor = quad({-1e5f, -7e4f, 0}, {1.3e5f, -7e4f, 0}, {1.3e5f, 1.1e5f, 0}, {-1e5f, 1.1e5f, 0}, "floor");
  const Mesh m = merged({front, back, floor});
  const Topology topo = build_topology(m);
  for (uint32_t v = 0; v < 8; ++v) EXPECT_EQ(m.normals[v], Vector3f(v < 4 ? 1.0f : -1.0f, 0, 0)) << v;
  for (const uint32_t v : {2u, 3u, 5u, 6u}) {  // the top corners of both sheets
    const ShadePoint sp = vertex_shade_point(m, topo, v);
    expect_exact(ao_at(m, topo, sp, v), 0.5, "top corner of a double-sided panel");
  }
  // The bottom corners stand inside floor faces with a horizontal normal: p + εn lies in the
  // floor's plane, and the second-order tie-break (bake/integrators/integrator.h ShadePoint::t, pointing up
  // into the panel) puts the limit point on the floor's upper side: the same quarter sphere.
  for (const uint32_t v : {0u, 1u, 4u, 7u}) {
    const ShadePoint sp = vertex_shade_point(m, topo, v);
    EXPECT_NEAR((sp.t - Vector3d(0, sp.p.y() > 0 ? -1 : 1, 1).normalized()).norm(), 0, 1e-12) << v;
    expect_exact(ao_at(m, topo, sp, v), 0.5, "bottom corner of a double-sided panel on a floor");
  }
}

TEST(MessyGeometry, SheetNormalsKeepSmoothNormalsOfSplitManifolds) {
  // The same closed box as an STL facet soup (every corner its own vertex): the sheets join across
  // its manifold, consistently wound edges, so each corner gets the smooth (±1, ±1, ±1)/√3 normal,
  // exactly as the welded box does.
  const Mesh welded = unit_box();
  std::vector<Vector3f> p;
  std::vector<std::array<uint32_t, 3>> t;
  for (const auto& tri : welded.triangles) {
    for (int k = 0; k < 3; ++k) p.push_back(welded.positions[tri[size_t(k)]]);
    t.push_back({uint32_t(p.size() - 3), uint32_t(p.size() - 2), uint32_t(p.size() - 1)});
  }
  const Mesh soup = make_mesh(p, t, "soup");
  for (size_t v = 0; v < soup.positions.size(); ++v) {
    const Vector3f want = (2 * soup.positions[v] - Vector3f::Ones()).normalized();
    EXPECT_LT((soup.normals[v] - want).norm(), 1e-6f) << v;
  }
  // Two boxes touching at one corner keep their own corner normals (they share no edge).
  const Mesh other = prt::testing::box({1, 1, 1}, {2, 2, 2}, "other");
  const Mesh touching = merged({unit_box(), other});
  const uint32_t a = vertex_at(touching, {1, 1, 1});
  const uint32_t b = uint32_t(welded.positions.size());  // the other box's corner (1, 1, 1): its vertex 0
  EXPECT_LT((touching.normals[a] - Vector3f(1, 1, 1).normalized()).norm(), 1e-6f);
  EXPECT_LT((touching.normals[b] + Vector3f(1, 1, 1).normalized()).norm(), 1e-6f);
}

namespace {

// A plate z = 0 over x ≥ 0 whose vertex at the origin lies on its edge x = 0, and a single-sheet
// wall in the plane x = 0 with a corner at the origin: its edge from the origin runs along the
// plate's normal, up (`up` = +1, a CAD fin standing on the plate) or down (−1, hanging under it),
// and it spans y from 0 to `side` (±1). Each part keeps its own normals (merge_meshes), as a glTF
// with per-primitive normals has them: the plate's vertex at the origin has n = +z and the
// tie-break t = +x (into its own faces), and the wall's faces are in its welded 1-ring.
Mesh plate_with_fin(float side, float up) {
  const Mesh plate = make_mesh({{0, 0, 0}, {0, -1, 0}, {1, -1, 0}, {1, 1, 0}, {0, 1, 0}},
                               {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}}, "plate");
  const Mesh wall = quad({0, 0, 0}, {0, side, 0}, {0, side, up}, {0, 0, up}, "fin");
  const std::vector<Mesh> parts = {plate, wall};
  return merge_meshes(parts, "plate and fin");
}

} // namespace

TEST(MessyGeometry, FinStandingOnAFaceFromTheVertex) {
  // Found on 2CylinderEngine.glb (about 2 vertices in 1,000): seen from p + εn the fin's edge from
  // p runs along n, so p + εn lies in the fin's plane AND on that edge's line; to first order every
  // direction grazes the fin, and the second-order limit p + εn + ε²t decides. The limit point is
  // then ε² in front of the fin (t = +x) at its vertical edge, so the fin blocks exactly the
  // octant {x < 0, y·side > 0, z > 0}: AO = 3/4 whichever side it spans. Before, the ray test
  // flagged every direction of these points as a graze (no start ray: the bake stopped), and the
  // edge's arc ran between the antipodes −n and +n (undefined).
  for (const float side : {1.0f, -1.0f}) {
    const Mesh m = plate_with_fin(side, 1);
    const Topology topo = build_topology(m);
    const ShadePoint sp = vertex_shade_point(m, topo, 0);
    ASSERT_EQ(sp.n, Vector3d(0, 0, 1));
    ASSERT_NEAR((sp.t - Vector3d(1, 0, 0)).norm(), 0, 1e-15);
    expect_exact(ao_at(m, topo, sp, 0), 0.75, side > 0 ? "fin over y > 0" : "fin over y < 0");
  }
  // Hanging under the plate, the fin is seen from p + εn in the single direction −n: AO = 1.
  for (const float side : {1.0f, -1.0f}) {
    const Mesh m = plate_with_fin(side, -1);
    const Topology topo = build_topology(m);
    expect_exact(ao_at(m, topo, vertex_shade_point(m, topo, 0), 0), 1.0, "fin hanging under the plate");
  }
}

TEST(MessyGeometry, FinWithANormalOffItsPlaneByRounding) {
  // The same fins with the plate's normal off the fin's plane by 1e-10 rad (a file normal with
  // rounding in it; one engine vertex has 6e-11): p + εn is then off the fin's plane at first
  // order, on the side the tilt says, and the fin blocks the octant on the other side of its
  // plane, AO = 3/4 (the tilted hemisphere changes AO by O(1e-10)); a hanging fin blocks nothing.
  // Every ring test here is within the float test's tolerance: the exact predicates decide them.
  for (const float tilt : {1e-10f, -1e-10f})
    for (const float side : {1.0f, -1.0f})
      for (const float up : {1.0f, -1.0f}) {
        Mesh m = plate_with_fin(side, up);
        m.normals[0] = Vector3f(tilt, 0, 1);
        const Topology topo = build_topology(m);
        const ShadePoint sp = vertex_shade_point(m, topo, 0);
        ASSERT_NE(sp.n.dot(Vector3d(1, 0, 0)), 0.0);
        expect_exact(ao_at(m, topo, sp, 0), up > 0 ? 0.75 : 1.0, "fin off the normal by 1e-10 rad");
      }
  // A keel hanging under the plate from the vertex, as at engine vertex 913: two faces on the edge
  // along −n whose planes differ by 6°, so that for every direction one of them has its plane
  // crossed ahead of the ray near p. The float test could decide no direction (the bake stopped);
  // the keel is under the plate up to the 1e-10 tilt: AO = 1 (to O(1e-10); its corners on the
  // horizon leave the silhouette integrator its discretisation error there).
  for (const float tilt : {1e-10f, -1e-10f}) {
    const Mesh plate = plate_with_fin(1, 1);
    const Mesh keel = make_mesh({{0, 0, 0}, {1, -0.05f, 0}, {0, 0, -1}, {-1, -0.05f, 0}}, {{0, 1, 2}, {0, 2, 3}}, "keel");
    const std::vector<Mesh> parts = {make_mesh({plate.positions.begin(), plate.positions.begin() + 5},
                                               {plate.triangles.begin(), plate.triangles.begin() + 3}, "plate"),
                                     keel};
    Mesh m = merge_meshes(parts, "plate and keel");
    m.normals[0] = Vector3f(tilt, 0, 1);
    const Topology topo = build_topology(m);
    expect_exact(ao_at(m, topo, vertex_shade_point(m, topo, 0), 0), 1.0, "keel under the plate");
  }
}
