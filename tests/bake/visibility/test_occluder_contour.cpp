// The contour path of bake/visibility/occluder_mesh.h (issue 32: only the image edges that may bound
// the occluders' union are cut, each against the images near it) against the per-triangle method
// it replaced (OccluderMesh::visible_light_per_triangle, paper 003 §4.4), on the bunny under a
// quad light (ground points, the bunny's own vertices, a ground plane in the mesh), open single
// sheets facing either way, a non-manifold edge, overlapping and coincident sheets, a
// T-junction, a light corner on an occluder's silhouette, occluder edges through the shade point
// and lights crossing the horizon.
#include <bake/mesh/mesh.h>
#include <bake/mesh/receivers.h>
#include <bake/sphere/polygon_sh.h>
#include <bake/sphere/spherical_polygon.h>
#include <bake/visibility/occluder_mesh.h>

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <tuple>
#include <vector>

namespace {

using prt::bake::Arc;
using prt::bake::OccluderMesh;
using prt::bake::ShadePoint;
using V3 = Eigen::Vector3d;
using Poly = std::vector<V3>;
using Tri = std::array<uint32_t, 3>;

// The contour path equals the per-triangle method to this, relative to the light's solid angle
// from p (|E| and every |S_i|·√(4π) are at most that): both decide every side exactly and differ
// only by the rounding of crossing points and of sums over different arc sets (~1e-15).
constexpr double kExact = 1e-9;
constexpr int kOrder = 4;

struct Totals {
  size_t points = 0, shadowed = 0, boundary_edges = 0, kept = 0, special = 0, uncharted = 0;
  size_t queries = 0;  // that reached the union (the light not empty above the horizon)
  size_t cone = 0, cone_edges = 0, cone_candidates = 0, all_kept = 0;
  size_t one_facing = 0, hidden = 0;  // visible_light's closed-mesh rule (occluder_mesh.h "one facing")
};

// E and the order-4 SH of the visible light by both methods at s; EXPECTs their agreement.
void compare(const OccluderMesh& mesh, const Poly& light, const ShadePoint& s, const std::string& what,
             Totals& totals) {
  static const prt::bake::PolygonSH sh(kOrder);
  OccluderMesh::Workspace ws_fast, ws_slow, ws_bare, ws_kept;
  std::vector<Arc> fast, slow, bare, kept_images;
  mesh.visible_light_cone(light, s, fast, ws_fast);
  const size_t kept = mesh.visible_light(light, s, kept_images, ws_kept);
  mesh.visible_light_per_triangle(light, s, slow, ws_slow);
  OccluderMesh({}, {}).visible_light(light, s, bare, ws_bare);
  const double scale = std::abs(prt::bake::solid_angle(bare));
  // Every arc end a direction (a zero vector was a cut point of a near-degenerate edge).
  auto directions = [&](const std::vector<Arc>& arcs, const char* which) {
    for (const Arc& arc : arcs)
      if (!(arc.a.norm() > 0) || !(arc.b.norm() > 0)) {
        ADD_FAILURE() << what << ": " << which << " has an arc end of zero length";
        return false;
      }
    return true;
  };
  const bool fast_ok = directions(fast, "cone path"), slow_ok = directions(slow, "per triangle"),
             kept_ok = directions(kept_images, "contour path over the kept images");
  if (!fast_ok || !slow_ok || !kept_ok) return;
  const double e_slow = s.n.dot(prt::bake::vector_irradiance(slow));
  std::vector<double> a(kOrder * kOrder), b(kOrder * kOrder);
  sh.project(std::span<const Arc>(slow), b);
  for (const auto* arcs : {&fast, &kept_images}) {
    const char* which = arcs == &fast ? " (cone path)" : " (kept images)";
    EXPECT_NEAR(s.n.dot(prt::bake::vector_irradiance(*arcs)), e_slow, kExact * scale) << what << which;
    sh.project(std::span<const Arc>(*arcs), a);
    for (size_t i = 0; i < a.size(); ++i) EXPECT_NEAR(a[i], b[i], kExact * scale) << what << which << " SH " << i;
  }
  ++totals.points;
  totals.shadowed += e_slow < s.n.dot(prt::bake::vector_irradiance(bare)) - 1e-6 * scale;
  totals.boundary_edges += ws_kept.stats.boundary_edges;
  totals.kept += kept;
  totals.special += ws_kept.stats.special;
  totals.uncharted += ws_kept.stats.uncharted;
  totals.one_facing += ws_kept.stats.one_facing;
  totals.hidden += ws_kept.stats.hidden;
  totals.queries += ws_kept.stats.queries;
  totals.cone += ws_fast.stats.cone;
  totals.cone_edges += ws_fast.stats.cone_edges;
  totals.cone_candidates += ws_fast.stats.cone_candidates;
  totals.all_kept += ws_fast.stats.cone ? kept : 0;
  // The cone path's edges: the tree's answer is the brute-force rule's, edge for edge.
  std::vector<uint32_t> tree, brute, tree_special, brute_special;
  OccluderMesh::Workspace ws_tree, ws_brute;
  mesh.cone_edges(light, s, tree, tree_special, ws_tree);
  mesh.cone_edges_brute_force(light, s, brute, brute_special, ws_brute);
  EXPECT_EQ(tree, brute) << what;
  EXPECT_EQ(tree_special, brute_special) << what;
}

// An n-gon light in the plane y = h around the y axis, corners (rx cos a, h, rz sin a), a = 2πk/n.
Poly disc_light(int n, double rx, double rz, double h) {
  Poly p;
  for (int k = 0; k < n; ++k) {
    const double a = 6.283185307179586 * k / n;
    p.emplace_back(rx * std::cos(a), h, rz * std::sin(a));
  }
  return p;
}

std::vector<V3> positions_of(const prt::bake::Mesh& m) {
  std::vector<V3> p;
  for (const auto& x : m.positions) p.push_back(x.cast<double>());
  return p;
}

// A flat n × n grid on [x0, x1] × [z0, z1] at height y, counter-clockwise seen from +y
// (flip: from −y), appended to pos/tris.
void add_grid(std::vector<V3>& pos, std::vector<Tri>& tris, double x0, double x1, double z0, double z1, double y,
              int n, bool flip) {
  const auto base = uint32_t(pos.size());
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) pos.emplace_back(x0 + (x1 - x0) * i / n, y, z0 + (z1 - z0) * j / n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const uint32_t a = base + uint32_t(j * (n + 1) + i), b = a + 1, c = a + uint32_t(n + 1), d = c + 1;
      // (a, c, d) runs counter-clockwise seen from +y (x right, z towards the viewer).
      if (flip) {
        tris.push_back({a, d, c});
        tris.push_back({a, b, d});
      } else {
        tris.push_back({a, c, d});
        tris.push_back({a, d, b});
      }
    }
}

const Poly kBunnyLight{{-3, 12, -2}, {3, 12, -2}, {3, 12, 2}, {-3, 12, 2}};

TEST(OccluderContour, BunnyGroundPointsEqualPerTriangle) {
  // 300 ground points (|x| ≤ 8, |z| ≤ 6, normals tilted up to 70° so the light often crosses
  // the horizon) under the bunny: many are partly shadowed, and the contour path cuts far
  // fewer edges than the per-triangle method's 3 per kept triangle.
  const prt::bake::Mesh bunny = prt::bake::load_mesh(std::filesystem::path(PRT_DATA_DIR) / "bunny.obj");
  const OccluderMesh mesh(positions_of(bunny), bunny.triangles);
  std::mt19937_64 rng(32);
  std::uniform_real_distribution<double> u(0, 1);
  Totals totals;
  for (int k = 0; k < 300; ++k) {
    const double tilt = 1.2 * u(rng), phi = 6.283185307179586 * u(rng);
    const ShadePoint s{.p = V3(16 * u(rng) - 8, 0, 12 * u(rng) - 6),
                       .n = V3(std::sin(tilt) * std::cos(phi), std::cos(tilt), std::sin(tilt) * std::sin(phi))};
    compare(mesh, kBunnyLight, s, "ground point " + std::to_string(k), totals);
  }
  EXPECT_GT(totals.shadowed, 60u);
  EXPECT_LT(totals.boundary_edges * 4, totals.kept * 3);  // < a quarter of the per-triangle edges
  // Nothing of the bunny is clipped by the light's plane or has p in its plane: every query
  // takes the cone path, which passes on fewer images than culling keeps.
  EXPECT_EQ(totals.cone, totals.queries);
  EXPECT_LT(totals.cone_candidates, totals.all_kept);
}

TEST(OccluderContour, BunnyOwnVerticesEqualPerTriangle) {
  // Every 7th vertex of the bunny as a receiver ON the occluder (its own 1-ring is seen in the
  // ε-limit through −n): self-shadowing by the ears and the back.
  const prt::bake::Mesh bunny = prt::bake::load_mesh(std::filesystem::path(PRT_DATA_DIR) / "bunny.obj");
  const OccluderMesh mesh(positions_of(bunny), bunny.triangles);
  const auto points = prt::bake::vertex_shade_points(bunny, prt::bake::build_topology(bunny));
  Totals totals;
  for (size_t v = 0; v < points.size(); v += 7) compare(mesh, kBunnyLight, points[v], "vertex " + std::to_string(v), totals);
  EXPECT_GT(totals.points, 250u);
  EXPECT_GT(totals.shadowed, 20u);
  EXPECT_GT(totals.special, totals.points / 2);  // the own 1-ring's ε-limit cones were cut
  EXPECT_EQ(totals.cone, totals.queries);          // … by the cone path too (special faces' fans)
}

TEST(OccluderContour, BunnyOnAGroundPlaneEqualsPerTriangle) {
  // The bunny and a 16 × 16 ground grid as ONE occluder mesh; receivers: ground vertices, points
  // on ground edges and faces (all on the mesh), and bunny vertices.
  const prt::bake::Mesh bunny = prt::bake::load_mesh(std::filesystem::path(PRT_DATA_DIR) / "bunny.obj");
  std::vector<V3> pos = positions_of(bunny);
  std::vector<Tri> tris = bunny.triangles;
  add_grid(pos, tris, -8, 8, -8, 8, 0, 16, false);
  const OccluderMesh mesh(pos, tris);
  Totals totals;
  for (int i = -7; i <= 7; i += 2)
    for (int j = -7; j <= 7; j += 2) {
      const V3 n = V3(0.1 * i, 1, -0.05 * j).normalized();
      compare(mesh, kBunnyLight, {.p = V3(i, 0, j), .n = n}, "ground vertex", totals);
      compare(mesh, kBunnyLight, {.p = V3(i + 0.5, 0, j), .n = n}, "ground edge", totals);
      compare(mesh, kBunnyLight, {.p = V3(i + 0.25, 0, j + 0.5), .n = n}, "ground face", totals);
    }
  const auto points = prt::bake::vertex_shade_points(bunny, prt::bake::build_topology(bunny));
  for (size_t v = 3; v < points.size(); v += 41) compare(mesh, kBunnyLight, points[v], "vertex", totals);
  EXPECT_GT(totals.shadowed, 40u);
  EXPECT_EQ(totals.cone, totals.queries);
}

// Light z = 3 (2 × 2), p near the origin: a random selection of points and normals, the same for
// every small scene below.
Totals compare_scene(const std::vector<V3>& pos, const std::vector<Tri>& tris, const std::string& what, uint64_t seed,
                     size_t min_shadowed) {
  const OccluderMesh mesh(pos, tris);
  const Poly light{{-1, -1, 3}, {1, -1, 3}, {1, 1, 3}, {-1, 1, 3}};
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  Totals totals;
  for (int k = 0; k < 200; ++k) {
    const ShadePoint s{.p = V3(3 * u(rng) - 1.5, 3 * u(rng) - 1.5, 0.4 * u(rng) - 0.2),
                       .n = V3(2 * u(rng) - 1, 2 * u(rng) - 1, 0.6).normalized()};
    compare(mesh, light, s, what + " " + std::to_string(k), totals);
  }
  EXPECT_GE(totals.shadowed, min_shadowed) << what;
  return totals;
}

// A crumpled open n × n sheet over [-1.2, 1.2]² at heights 1–2.
void add_sheet(std::vector<V3>& pos, std::vector<Tri>& tris, std::mt19937_64& rng, bool flip) {
  std::uniform_real_distribution<double> u(0, 1);
  const auto base = uint32_t(pos.size());
  const int n = 5;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) pos.emplace_back(-1.2 + 2.4 * i / n, -1.2 + 2.4 * j / n, 1 + u(rng));
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const uint32_t a = base + uint32_t(j * (n + 1) + i), b = a + 1, c = a + uint32_t(n + 1), d = c + 1;
      if (flip) {
        tris.push_back({a, d, b});
        tris.push_back({a, c, d});
      } else {
        tris.push_back({a, b, d});
        tris.push_back({a, d, c});
      }
    }
}

TEST(OccluderContour, OpenSheetsFacingEitherWay) {
  // A crumpled open sheet (it folds over itself as seen from below: contour edges inside it, and
  // its boundary edges) wound either way; then the same with a hole.
  for (int flip = 0; flip < 2; ++flip) {
    std::mt19937_64 rng(5);
    std::vector<V3> pos;
    std::vector<Tri> tris;
    add_sheet(pos, tris, rng, flip != 0);
    compare_scene(pos, tris, flip ? "sheet facing down" : "sheet facing up", 11, 100);
    tris.erase(tris.begin() + 22, tris.begin() + 26);
    compare_scene(pos, tris, "sheet with a hole", 12, 80);
  }
}

// A closed tetrahedron (outward faces) with corners c + r·(±1, ±1, ±1) of even parity.
void add_tetrahedron(std::vector<V3>& pos, std::vector<Tri>& tris, const V3& c, double r) {
  const auto b = uint32_t(pos.size());
  for (const V3& d : {V3(1, 1, 1), V3(1, -1, -1), V3(-1, 1, -1), V3(-1, -1, 1)}) pos.push_back(c + r * d);
  for (const Tri& t : {Tri{0, 1, 2}, Tri{0, 3, 1}, Tri{0, 2, 3}, Tri{1, 3, 2}}) {
    const Tri face{b + t[0], b + t[1], b + t[2]};
    // Outward: the corner left out lies behind the face.
    const uint32_t other = b + 6 - (t[0] + t[1] + t[2]);
    const V3 n = (pos[face[1]] - pos[face[0]]).cross(pos[face[2]] - pos[face[0]]);
    tris.push_back(n.dot(pos[other] - pos[face[0]]) < 0 ? face : Tri{face[0], face[2], face[1]});
  }
}

TEST(OccluderContour, ConePathCoverWithoutEdgesInTheCone) {
  // The cone path's coverage comes only from the images meeting a light edge's or a found
  // edge's fan. A wide two-triangle roof between every point and the light has no edge in the
  // cone (its diagonal is seen from below by both faces, its border is outside the pyramid): the
  // light edges' fans alone find it hidden. Then a tetrahedron under the roof (its contour edges
  // are found, the roof covers their far side), one beside a wall across half the light, and a
  // tetrahedron alone.
  std::vector<V3> roof{{-9, -9, 2}, {9, -9, 2}, {9, 9, 2}, {-9, 9, 2}};
  std::vector<Tri> roof_tris{{0, 1, 2}, {0, 2, 3}};
  const OccluderMesh roof_mesh(roof, roof_tris);
  const Poly light{{-1, -1, 3}, {1, -1, 3}, {1, 1, 3}, {-1, 1, 3}};
  for (const V3& n : {V3(0, 0, 1), V3(0.3, -0.2, 1).normalized()}) {
    OccluderMesh::Workspace ws;
    std::vector<Arc> arcs;
    std::vector<uint32_t> edges, special;
    roof_mesh.cone_edges(light, {.p = V3(0.2, 0.1, 0), .n = n}, edges, special, ws);
    EXPECT_TRUE(edges.empty());
    EXPECT_TRUE(special.empty());
    roof_mesh.visible_light_cone(light, {.p = V3(0.2, 0.1, 0), .n = n}, arcs, ws);
    EXPECT_TRUE(arcs.empty());  // hidden: no arc at all, E = 0 exactly
    EXPECT_EQ(ws.stats.cone, 1u);
    EXPECT_EQ(ws.stats.cone_candidates, 2u);
  }
  auto under_roof = roof_tris;
  auto pos = roof;
  add_tetrahedron(pos, under_roof, V3(0.1, 0.2, 1.2), 0.3);
  Totals totals = compare_scene(pos, under_roof, "tetrahedron under a roof", 41, 200);
  EXPECT_EQ(totals.cone, totals.queries);
  EXPECT_GT(totals.cone_edges, 2 * totals.points);

  std::vector<V3> wall{{0, -9, 2.5}, {9, -9, 2.5}, {9, 9, 2.5}, {0, 9, 2.5}};
  std::vector<Tri> wall_tris{{0, 1, 2}, {0, 2, 3}};
  add_tetrahedron(wall, wall_tris, V3(-0.2, 0.1, 1.4), 0.35);
  totals = compare_scene(wall, wall_tris, "tetrahedron beside a wall", 42, 150);
  EXPECT_EQ(totals.cone, totals.queries);

  // A fine plate inside the light's image with a small tetrahedron under its middle: the plate's
  // triangles over the tetrahedron meet neither a light edge's fan nor a plate border's; only
  // the tetrahedron's contour edges' fans pass them on (left out, the tetrahedron would show).
  std::vector<V3> plate;
  std::vector<Tri> plate_tris;
  const int cells = 8;
  for (int j = 0; j <= cells; ++j)
    for (int i = 0; i <= cells; ++i) plate.emplace_back(-0.5 + 1.0 * i / cells, -0.5 + 1.0 * j / cells, 2);
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i) {
      const auto a = uint32_t(j * (cells + 1) + i), b = a + 1, c = a + uint32_t(cells + 1), d = c + 1;
      plate_tris.push_back({a, b, d});
      plate_tris.push_back({a, d, c});
    }
  add_tetrahedron(plate, plate_tris, V3(0.05, -0.05, 1.5), 0.08);
  totals = compare_scene(plate, plate_tris, "tetrahedron under a plate", 44, 150);
  EXPECT_EQ(totals.cone, totals.queries);

  std::vector<V3> alone;
  std::vector<Tri> alone_tris;
  add_tetrahedron(alone, alone_tris, V3(0.3, -0.2, 1.5), 0.4);
  totals = compare_scene(alone, alone_tris, "tetrahedron alone", 43, 100);
  EXPECT_EQ(totals.cone, totals.queries);
}

// A closed box [lo, hi] (12 triangles), faces counter-clockwise seen from outside, or from
// inside when `inward` (a cavity's walls).
void add_box(std::vector<V3>& pos, std::vector<Tri>& tris, const V3& lo, const V3& hi, bool inward) {
  const auto b = uint32_t(pos.size());
  for (int k = 0; k < 8; ++k) pos.emplace_back(k & 1 ? hi.x() : lo.x(), k & 2 ? hi.y() : lo.y(), k & 4 ? hi.z() : lo.z());
  for (const std::array<uint32_t, 4> q : {std::array<uint32_t, 4>{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                          {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}}) {
    for (const Tri& t : {Tri{b + q[0], b + q[1], b + q[2]}, Tri{b + q[0], b + q[2], b + q[3]}})
      tris.push_back(inward ? Tri{t[0], t[2], t[1]} : t);
  }
}

TEST(OccluderContour, ClosedMeshesFromOneFacing) {
  // On a closed oriented mesh (every welded edge a consistently wound pair) with every image
  // whole, visible_light subtracts one facing's images only, or finds the light hidden when the
  // facings' counts differ at a generic direction (occluder_mesh.h "one facing"). Held to the
  // per-triangle method over every image: the bunny from the ground, from inside and turned
  // inside out; overlapping boxes (a region counted twice), a cavity, a box around the light.
  const prt::bake::Mesh bunny = prt::bake::load_mesh(std::filesystem::path(PRT_DATA_DIR) / "bunny.obj");
  std::vector<Tri> reversed;
  for (const Tri& t : bunny.triangles) reversed.push_back({t[0], t[2], t[1]});
  for (const std::vector<Tri>* tris : {&bunny.triangles, const_cast<const std::vector<Tri>*>(&reversed)}) {
    const OccluderMesh mesh(positions_of(bunny), *tris);
    const std::string what = tris == &reversed ? "bunny inside out, " : "bunny, ";
    std::mt19937_64 rng(33);
    std::uniform_real_distribution<double> u(0, 1);
    Totals totals;
    for (int k = 0; k < 120; ++k) {
      const double tilt = 1.2 * u(rng), phi = 6.283185307179586 * u(rng);
      const ShadePoint s{.p = V3(16 * u(rng) - 8, 0, 12 * u(rng) - 6),
                         .n = V3(std::sin(tilt) * std::cos(phi), std::cos(tilt), std::sin(tilt) * std::sin(phi))};
      compare(mesh, kBunnyLight, s, what + "ground point " + std::to_string(k), totals);
    }
    EXPECT_GT(totals.shadowed, 20u) << what;
    EXPECT_GT(totals.one_facing * 10, totals.queries * 9) << what;  // nearly every ground query
    // Points along a vertical line through the bunny's body, in and out of it: from inside,
    // every ray meets the surface (E = 0 by every method), and the rule finds that at once.
    V3 centre = V3::Zero();
    for (const V3& x : positions_of(bunny)) centre += x;
    centre /= double(bunny.positions.size());
    Totals line;
    for (int k = 0; k <= 40; ++k) {
      const ShadePoint s{.p = V3(centre.x() + 0.013, 11.5 * k / 40, centre.z() - 0.007), .n = V3(0.05, 1, 0.02).normalized()};
      compare(mesh, kBunnyLight, s, what + "line point " + std::to_string(k), line);
    }
    EXPECT_GT(line.hidden, 3u) << what;
    EXPECT_GT(line.one_facing, line.hidden) << what;
    // A 40-sided disc light (culled by the octagonal pyramid around it).
    const Poly disc = disc_light(40, 3, 2, 12);  // an ellipse 3 x 2
    Totals round;
    for (int k = 0; k < 24; ++k) {
      const ShadePoint s{.p = V3(12 * u(rng) - 6, 0, 8 * u(rng) - 4), .n = V3(0.2 * u(rng) - 0.1, 1, 0.1).normalized()};
      compare(mesh, disc, s, what + "disc light, ground point " + std::to_string(k), round);
    }
    EXPECT_GT(round.shadowed, 5u) << what;
    EXPECT_GT(round.one_facing, 20u) << what;
  }

  // Two overlapping boxes (their union's interior partly counted twice), a box with a cavity
  // (an inward box inside it), and a box around the light (the light inside a closed surface);
  // points below, inside the overlap, inside the cavity and inside the walls.
  std::vector<V3> pos;
  std::vector<Tri> tris;
  add_box(pos, tris, V3(-0.6, -0.5, 1.0), V3(0.4, 0.3, 1.6), false);
  add_box(pos, tris, V3(-0.1, -0.2, 1.3), V3(0.7, 0.6, 2.0), false);
  Totals totals = compare_scene(pos, tris, "overlapping boxes", 51, 100);
  EXPECT_GT(totals.one_facing * 10, totals.queries * 9);
  std::vector<V3> cavity;
  std::vector<Tri> cavity_tris;
  add_box(cavity, cavity_tris, V3(-2, -2, 0.5), V3(2, 2, 2.5), false);
  add_box(cavity, cavity_tris, V3(-1.8, -1.8, 0.7), V3(1.8, 1.8, 2.3), true);
  const Poly light{{-1, -1, 3}, {1, -1, 3}, {1, 1, 3}, {-1, 1, 3}};
  std::vector<V3> around = pos;
  std::vector<Tri> around_tris = tris;
  add_box(around, around_tris, V3(-1.5, -1.5, 2.8), V3(1.5, 1.5, 3.2), false);
  for (const auto& [scene, scene_tris, name] :
       {std::tuple{&pos, &tris, "overlapping boxes"}, std::tuple{&cavity, &cavity_tris, "cavity"},
        std::tuple{&around, &around_tris, "box around the light"}}) {
    const OccluderMesh mesh(*scene, *scene_tris);
    Totals inside;
    for (const V3& p : {V3(0.1, 0.05, 1.45), V3(0.2, 0.1, 1.1), V3(0.5, 0.4, 1.8), V3(0.03, -0.02, 1.2),
                        V3(0.3, -0.4, 2.4), V3(-1.9, 0.1, 1.0), V3(0.1, 0.2, 0.1)}) {
      compare(mesh, light, {.p = p, .n = V3(0.1, -0.05, 1).normalized()}, std::string(name) + " inside", inside);
    }
    EXPECT_GT(inside.hidden, 0u) << name;
  }
  // From below, the box around the light hides it (its bottom face alone counts at d).
  totals = compare_scene(around, around_tris, "box around the light, from below", 52, 0);
  EXPECT_EQ(totals.hidden, totals.queries);
  // A box through the light (walls crossing the light's plane inside it, their images clipped):
  // no rule, the ordinary path, equal all the same.
  std::vector<V3> through = pos;
  std::vector<Tri> through_tris = tris;
  add_box(through, through_tris, V3(-0.5, -2, 2.8), V3(0.5, 2, 3.2), false);
  totals = compare_scene(through, through_tris, "box through the light", 53, 100);
  EXPECT_EQ(totals.one_facing, 0u);
  EXPECT_GT(totals.special, totals.queries / 2);

  // A generic direction is looked for, not assumed: the light's centre direction from p here
  // lies on the great circle of a tetrahedron edge (det = 0 exactly), so the rule is not used.
  std::vector<V3> tet{{-0.5, 1, 0}, {0.5, 1, 0}, {0, 1, 0.5}, {0, 1.5, 0.2}};
  std::vector<Tri> tet_tris;
  for (const Tri& t : {Tri{0, 1, 2}, Tri{0, 3, 1}, Tri{0, 2, 3}, Tri{1, 3, 2}}) {
    const uint32_t other = 6 - (t[0] + t[1] + t[2]);
    const V3 n = (tet[t[1]] - tet[t[0]]).cross(tet[t[2]] - tet[t[0]]);
    tet_tris.push_back(n.dot(tet[other] - tet[t[0]]) < 0 ? t : Tri{t[0], t[2], t[1]});
  }
  const OccluderMesh tet_mesh(tet, tet_tris);
  const Poly square{{-1, 2, -1}, {1, 2, -1}, {1, 2, 1}, {-1, 2, 1}};
  Totals tie;
  compare(tet_mesh, square, {.p = V3::Zero(), .n = V3(0, 1, 0)}, "edge through the light's centre direction", tie);
  EXPECT_EQ(tie.queries, 1u);
  EXPECT_EQ(tie.one_facing, 0u);
  compare(tet_mesh, square, {.p = V3(0.01, 0, 0.02), .n = V3(0, 1, 0)}, "tetrahedron, off the tie", tie);
  EXPECT_EQ(tie.one_facing, 1u);
}

TEST(OccluderContour, ConePathOnAFullPyramid) {
  // A fine plate with a hole (80,000 triangles, ~9,000 of them in the pyramid) and a tetrahedron
  // under the hole: the cone path passes on far fewer images than culling keeps and gives the
  // same integrals as the kept-images path (held to the per-triangle method above; the
  // per-triangle method itself is O(E²) here).
  std::vector<V3> pos;
  std::vector<Tri> tris;
  const int cells = 200;
  for (int j = 0; j <= cells; ++j)
    for (int i = 0; i <= cells; ++i) pos.emplace_back(-2 + 4.0 * i / cells, -2 + 4.0 * j / cells, 2);
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i) {
      if (std::abs(i - 100) < 15 && std::abs(j - 95) < 10) continue;  // the hole
      const auto a = uint32_t(j * (cells + 1) + i), b = a + 1, c = a + uint32_t(cells + 1), d = c + 1;
      tris.push_back({a, b, d});
      tris.push_back({a, d, c});
    }
  add_tetrahedron(pos, tris, V3(0.05, -0.1, 1.2), 0.15);
  const OccluderMesh mesh(pos, tris);
  const Poly light{{-1, -1, 3}, {1, -1, 3}, {1, 1, 3}, {-1, 1, 3}};
  static const prt::bake::PolygonSH sh(kOrder);
  for (const V3& p : {V3(0, 0, 0), V3(0.1, -0.2, 0.3), V3(-0.05, 0.1, -0.2)}) {
    const ShadePoint s{.p = p, .n = V3(0.1, 0.05, 1).normalized()};
    OccluderMesh::Workspace ws_chosen, ws_kept, ws_bare;
    std::vector<Arc> chosen, kept, bare;
    mesh.visible_light_cone(light, s, chosen, ws_chosen);
    const size_t culled = mesh.visible_light_kept_images(light, s, kept, ws_kept);
    OccluderMesh({}, {}).visible_light(light, s, bare, ws_bare);
    EXPECT_GT(culled, 5000u);
    EXPECT_EQ(ws_chosen.stats.cone, 1u);
    EXPECT_LT(ws_chosen.stats.cone_candidates * 5, culled);  // the fans cross the plate along lines
    const double scale = std::abs(prt::bake::solid_angle(bare));
    const double e = s.n.dot(prt::bake::vector_irradiance(kept));
    EXPECT_NEAR(s.n.dot(prt::bake::vector_irradiance(chosen)), e, kExact * scale);
    EXPECT_GT(e, 1e-3 * scale);  // light through the hole, partly hidden by the tetrahedron
    EXPECT_LT(e, 0.5 * s.n.dot(prt::bake::vector_irradiance(bare)));
    std::vector<double> a(kOrder * kOrder), b(kOrder * kOrder);
    sh.project(std::span<const Arc>(chosen), a);
    sh.project(std::span<const Arc>(kept), b);
    for (size_t i = 0; i < a.size(); ++i) EXPECT_NEAR(a[i], b[i], kExact * scale) << "SH " << i;
  }
}

TEST(OccluderContour, NonManifoldEdgeAndInconsistentWinding) {
  // Three triangles on one edge (a "book"), a fourth wound against its neighbour, and a fan of
  // four triangles around a vertical edge.
  std::vector<V3> pos{{-1, 0, 1.5}, {1, 0, 1.5}, {0, 1, 1.2}, {0, -1, 1.2}, {0, 0.3, 2.2}, {0.5, -1.5, 2}};
  std::vector<Tri> tris{{0, 1, 2}, {1, 0, 3}, {0, 1, 4}, {3, 1, 5}};
  const auto base = uint32_t(pos.size());
  pos.insert(pos.end(), {{0.3, 0.3, 1}, {0.3, 0.3, 2.5}, {0.9, 0.3, 1.6}, {0.3, 0.9, 1.7}, {-0.2, 0.4, 1.8}});
  for (uint32_t k = 2; k < 5; ++k) tris.push_back({base, base + 1, base + k});
  compare_scene(pos, tris, "non-manifold", 21, 60);
}

TEST(OccluderContour, OverlappingCoincidentAndTJunctionSheets) {
  std::mt19937_64 rng(9);
  std::vector<V3> pos;
  std::vector<Tri> tris;
  add_sheet(pos, tris, rng, false);
  // An overlapping second sheet, shifted, and the first sheet's triangles once more: as the same
  // vertex indices (coincident faces) and as copied vertices (coincident sheets, not connected).
  std::vector<V3> shifted;
  std::vector<Tri> more;
  add_sheet(shifted, more, rng, true);
  const auto base = uint32_t(pos.size());
  for (V3& v : shifted) pos.push_back(v + V3(0.4, 0.3, 0.2));
  for (const Tri& t : more) tris.push_back({base + t[0], base + t[1], base + t[2]});
  for (size_t t = 0; t < 10; ++t) tris.push_back(tris[t]);
  const auto copy = uint32_t(pos.size());
  for (uint32_t v = 0; v < 36; ++v) pos.push_back(pos[v]);
  for (size_t t = 10; t < 20; ++t) tris.push_back({copy + tris[t][0], copy + tris[t][1], copy + tris[t][2]});
  // A T-junction: a big triangle whose edge runs along two small ones' edges, through their
  // shared vertex (1, 0, 1.5) without sharing it.
  const auto tj = uint32_t(pos.size());
  pos.insert(pos.end(), {{0, 0, 1.5}, {1, 0, 1.5}, {2, 0, 1.5}, {0.5, 0.8, 1.5}, {1.5, 0.8, 1.5}, {1, -1, 1.5}});
  tris.push_back({tj, tj + 1, tj + 3});
  tris.push_back({tj + 1, tj + 2, tj + 4});
  tris.push_back({tj, tj + 5, tj + 2});
  compare_scene(pos, tris, "overlapping", 31, 120);
}

TEST(OccluderContour, LightCornerOnASilhouetteAndEdgesThroughThePoint) {
  // p = origin, n = +z; the light's corner (1, 1, 3) seen from p lies exactly on the image of an
  // occluder edge ((0.5, 0.5, 1.5) → (0.5, 0.5, 1.5) + t(1, 1, 3) is the corner's ray; the edge
  // from (0.5, 0.5, 1.5) to (−0.5, 0.7, 1.5) starts on it); a closed tetrahedron whose silhouette
  // vertex is on the corner's ray; a triangle whose edge's line passes through p (its image is a
  // point); and p on an occluder edge (two triangles meeting at a line through p).
  const Poly light{{-1, -1, 3}, {1, -1, 3}, {1, 1, 3}, {-1, 1, 3}};
  std::vector<V3> pos{{0.5, 0.5, 1.5}, {-0.5, 0.7, 1.5}, {0.2, -0.4, 1.4},
                      // tetrahedron, apex on the ray through (−1, −1, 3)
                      {-0.5, -0.5, 1.5}, {-0.1, -0.9, 1.3}, {-0.9, -0.1, 1.3}, {-0.5, -0.5, 1.0},
                      // a triangle with the edge (0, 0, 1) → (0, 0, 2) on the line through p
                      {0, 0, 1}, {0, 0, 2}, {0.6, -0.6, 1.6},
                      // p on the edge (−1, 0, 0) → (1, 0, 0): two faces rising from it
                      {-1, 0, 0}, {1, 0, 0}, {0, 0.8, 0.9}, {0, -0.8, 0.9}};
  std::vector<Tri> tris{{0, 1, 2}, {3, 4, 5}, {3, 6, 4}, {4, 6, 5}, {5, 6, 3}, {7, 8, 9}, {10, 11, 12}, {11, 10, 13}};
  const OccluderMesh mesh(pos, tris);
  Totals totals;
  for (const V3& n : {V3(0, 0, 1), V3(0.3, -0.2, 1).normalized(), V3(1, 0, 0.2).normalized()})
    compare(mesh, light, {.p = V3(0, 0, 0), .n = n}, "stiff", totals);
  // p on the line of the light's diagonal corner ray, below the tetrahedron's apex.
  compare(mesh, light, {.p = V3(0.25, 0.25, 0.75), .n = V3(0, 0, 1)}, "on the corner ray", totals);
  EXPECT_EQ(totals.shadowed, totals.points);
}

TEST(OccluderContour, LightCrossingTheHorizon) {
  // The bunny with receivers whose horizon cuts the light (normals nearly horizontal), and a
  // light below the horizon of some of them (nothing left).
  const prt::bake::Mesh bunny = prt::bake::load_mesh(std::filesystem::path(PRT_DATA_DIR) / "bunny.obj");
  const OccluderMesh mesh(positions_of(bunny), bunny.triangles);
  Totals totals;
  for (int k = 0; k < 40; ++k) {
    const double phi = 0.157 * k;
    const V3 n = V3(std::cos(phi), 0.35 - 0.02 * k, std::sin(phi)).normalized();
    compare(mesh, kBunnyLight, {.p = V3(-6 + 0.3 * k, 0, 0.1 * k - 2), .n = n}, "horizon " + std::to_string(k), totals);
  }
  EXPECT_GT(totals.shadowed, 5u);
}

TEST(OccluderContour, IntegerGridSoupsFullOfTies) {
  // Triangles with corners on a small integer grid (and shade points on it too): shared great
  // circles, edges through p, p on faces, edges and vertices, coincident and T-junction faces,
  // vertices on the light's plane and its pyramid's faces — every tie the exact predicates decide.
  std::mt19937_64 rng(2026);
  std::uniform_int_distribution<int> xy(-3, 3), z(0, 4), pick(0, 99);
  const Poly light{{-2, -2, 4}, {2, -2, 4}, {2, 2, 4}, {-2, 2, 4}};
  Totals totals;
  for (int scene = 0; scene < 1000; ++scene) {
    std::vector<V3> pos;
    for (int v = 0; v < 40; ++v) pos.emplace_back(xy(rng), xy(rng), z(rng));
    std::vector<Tri> tris;
    std::uniform_int_distribution<uint32_t> any(0, 39);
    for (int t = 0; t < 60; ++t) {
      const Tri tri{any(rng), any(rng), any(rng)};
      tris.push_back(tri);
      if (pick(rng) < 20) tris.push_back({tri[1], tri[0], tri[2]});  // the same face wound back
      if (pick(rng) < 20) tris.push_back({tri[0], tri[1], any(rng)});  // a fan on one edge
    }
    const OccluderMesh mesh(pos, tris);
    for (int k = 0; k < 8; ++k) {
      const V3 p = pick(rng) < 50 ? pos[any(rng)] : V3(xy(rng), xy(rng), z(rng) - 1);
      const V3 n = V3(xy(rng), xy(rng), 3).normalized();
      compare(mesh, light, {.p = p, .n = n}, "grid scene " + std::to_string(scene) + " point " + std::to_string(k), totals);
    }
  }
  EXPECT_GT(totals.shadowed, 100u);
  EXPECT_GT(totals.special, 20u);
  EXPECT_EQ(totals.cone, totals.queries);  // the cone path answers every query (no fallback left)
}

TEST(OccluderContour, LightTooWideForTheChart) {
  // A 6 × 6 light 0.3 above the points (its corners at c·ω̂ < 0.1 from the cap centre): the
  // chart is not used and every pair is filtered by caps; still the per-triangle arcs.
  std::mt19937_64 rng(3);
  std::vector<V3> pos;
  std::vector<Tri> tris;
  add_sheet(pos, tris, rng, false);
  for (V3& v : pos) v.z() = 0.1 + 0.1 * (v.z() - 1);
  const OccluderMesh mesh(pos, tris);
  const Poly light{{-3, -3, 0.3}, {3, -3, 0.3}, {3, 3, 0.3}, {-3, 3, 0.3}};
  std::uniform_real_distribution<double> u(0, 1);
  Totals totals;
  for (int k = 0; k < 60; ++k)
    compare(mesh, light, {.p = V3(2 * u(rng) - 1, 2 * u(rng) - 1, 0), .n = V3(u(rng) - 0.5, u(rng) - 0.5, 1).normalized()},
            "wide " + std::to_string(k), totals);
  EXPECT_EQ(totals.uncharted, totals.points);
  EXPECT_GT(totals.shadowed, 50u);
}

TEST(OccluderContour, ManySidedLightsCulledByAnOctagon) {
  // A 64-sided disc (radius 2, 10 above the points) and small triangles half-way up, around the
  // rim of its pyramid (radius 1 there) at random angles: straddling it, just inside, just
  // outside, and out to 1.09, past the corners of the octagonal culling pyramid (1/cos(π/8) =
  // 1.082); more at radius 1.3–2, outside the octagon. The octagon drops none that hides light
  // (the unculled per-triangle method agrees), it is used, and it drops the far ones.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<V3> pos;
  std::vector<Tri> tris;
  auto add_small = [&](double rho) {
    const double psi = 6.283185307179586 * u(rng);
    const V3 c(rho * std::cos(psi), 5 + 0.02 * (u(rng) - 0.5), rho * std::sin(psi));
    const auto first = uint32_t(pos.size());
    for (int k = 0; k < 3; ++k) pos.push_back(c + 0.012 * V3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5));
    tris.push_back({first, first + 1, first + 2});
  };
  for (int k = 0; k < 300; ++k) add_small(0.97 + 0.12 * u(rng));
  for (int k = 0; k < 100; ++k) add_small(1.3 + 0.7 * u(rng));
  const OccluderMesh mesh(pos, tris);
  const Poly disc = disc_light(64, 2, 2, 10);
  Totals totals;
  for (int k = 0; k < 20; ++k) {
    const ShadePoint s{.p = V3(0.05 * (u(rng) - 0.5), 0, 0.05 * (u(rng) - 0.5)), .n = V3(0, 1, 0)};
    compare(mesh, disc, s, "rim point " + std::to_string(k), totals);
    OccluderMesh::Workspace ws;
    std::vector<Arc> arcs;
    const size_t kept = mesh.visible_light(disc, s, arcs, ws);
    EXPECT_EQ(ws.stats.octagon, 1u) << k;
    EXPECT_LE(kept, 300u) << k;
    EXPECT_GT(kept, 100u) << k;
  }
  EXPECT_EQ(totals.shadowed, totals.points);
  // A wide many-sided light (86° from the points): the octagon is not used, its 41 planes are.
  const Poly wide = disc_light(40, 150, 150, 10);
  for (int k = 0; k < 10; ++k) {
    const ShadePoint s{.p = V3(0.5 * (u(rng) - 0.5), 0, 0.5 * (u(rng) - 0.5)), .n = V3(0, 1, 0)};
    compare(mesh, wide, s, "wide point " + std::to_string(k), totals);
    OccluderMesh::Workspace ws;
    std::vector<Arc> arcs;
    mesh.visible_light(wide, s, arcs, ws);
    EXPECT_EQ(ws.stats.octagon, 0u) << k;
  }
}

}  // namespace
