// Stiff and extreme cases for the silhouette integrator (issue: "each a test with an exact or
// relational expectation"). Exact expectations come from Lambert's polygon formula and solid
// angles; relational ones from the QMC reference within its standard error, or from a clean twin
// of the scene.
#include <bake/integrators/qmc.h>
#include <bake/integrators/silhouette.h>
#include <bake/mesh/mesh.h>
#include <bake/mesh/predicates.h>
#include <bake/mesh/receivers.h>
#include <bake/sphere/sampling.h>

#include <gtest/gtest.h>
#include <test_scenes.h>

#include <cmath>
#include <numbers>
#include <random>

using namespace prt::bake;
using prt::testing::grid;
using prt::testing::grid_centre;
using prt::testing::polygon_form_factor;
using Eigen::Vector3d;
using Eigen::Vector3f;
using std::numbers::pi;
using Tris = std::vector<std::array<uint32_t, 3>>;

namespace {

// At k = 256² the discretisation error of smooth integrands is O(h²) ≈ 6e-5 (issue: ≤ 1e-4).
constexpr double kTol = 1e-4;
constexpr int kN = 256;


// Solid angle of a planar convex polygon seen from p (fan of Van Oosterom–Strackee triangles).
double polygon_solid_angle(const Vector3d& p, const std::vector<Vector3d>& poly) {
  double s = 0;
  const Vector3d a = poly[0] - p;
  for (size_t i = 1; i + 1 < poly.size(); ++i) {
    const Vector3d b = poly[i] - p, c = poly[i + 1] - p;
    const double num = a.dot(b.cross(c));
    const double den = a.norm() * b.norm() * c.norm() + a.dot(b) * c.norm() + a.dot(c) * b.norm() + b.dot(c) * a.norm();
    s += 2 * std::atan2(std::abs(num), den);
  }
  return s;
}

Mesh quad(const std::vector<Vector3f>& c, const std::string& name) { return make_mesh(c, {{0, 1, 2}, {0, 2, 3}}, name); }


Mesh merge(std::vector<Mesh> parts) { return merge_meshes(parts, "scene"); }

double ao_at(const Mesh& m, const ShadePoint& sp, int n = kN) {
  const Topology topo = build_topology(m);
  ProductRequest req;
  req.ao = true;
  SilhouetteIntegrator sil(m, topo, req, {n, 1});
  double ao = -1;
  sil.integrate(sp, 0, std::span(&ao, 1));
  EXPECT_TRUE(std::isfinite(ao));
  EXPECT_EQ(sil.silhouette_stats().inconsistent_loops, 0u);
  return ao;
}

ShadePoint free_point(Vector3d p, Vector3d n = Vector3d::UnitZ()) {
  ShadePoint s;
  s.p = p;
  s.n = n.normalized();
  return s;
}

const std::vector<Vector3f> kSquare = {{-0.5f, -1, 1}, {1.5f, -1, 1}, {1.5f, 1, 1}, {-0.5f, 1, 1}};
std::vector<Vector3d> to_d(const std::vector<Vector3f>& v) {
  std::vector<Vector3d> o;
  for (auto& x : v) o.push_back(x.cast<double>());
  return o;
}

} // namespace

TEST(Stiff, CoplanarDuplicateTrianglesChangeNothing) {
  const double exact = 1 - polygon_form_factor(Vector3d::Zero(), Vector3d::UnitZ(), to_d(kSquare));
  const double once = ao_at(quad(kSquare, "sq"), free_point({0, 0, 0}));
  const double twice = ao_at(merge({quad(kSquare, "a"), quad(kSquare, "b")}), free_point({0, 0, 0}));
  // The same square again, split along the other diagonal (coplanar, overlapping, not identical).
  const double other = ao_at(merge({quad(kSquare, "a"), make_mesh(kSquare, {{0, 1, 3}, {1, 2, 3}}, "b")}),
                             free_point({0, 0, 0}));
  EXPECT_NEAR(once, exact, kTol);
  EXPECT_NEAR(twice, once, 1e-12);
  EXPECT_NEAR(other, once, 1e-12);
}

TEST(Stiff, ZeroAreaAndNeedleTrianglesChangeNothing) {
  const double base = ao_at(quad(kSquare, "sq"), free_point({0, 0, 0}));
  std::vector<Vector3f> p = kSquare;
  p.push_back({0.5f, 0, 1});      // 4: centre of the square
  p.push_back({0.5f, 0, 2});      // 5: above it
  p.push_back({0.5f, 0, 3});      // 6: collinear with 4, 5
  p.push_back({0.5f, 1e-6f, 2});  // 7: a needle's far corner
  Tris t = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {5, 5, 6}, {4, 4, 4}};  // + zero-area: collinear, repeated
  EXPECT_NEAR(ao_at(make_mesh(p, t, "degenerate"), free_point({0, 0, 0})), base, 1e-12);
  t.push_back({4, 5, 7});  // a needle 1e-6 wide standing on the square: area ≈ 5e-7
  EXPECT_NEAR(ao_at(make_mesh(p, t, "needle"), free_point({0, 0, 0})), base, 1e-6);
}

TEST(Stiff, ThinTwoSidedPlateOccludesLikeItsOutline) {
  // A plate of thickness 1e-5 (a flat box) over p, and the same plate as two coincident sheets
  // wound oppositely: both occlude exactly the outline's form factor.
  const float z0 = 1, z1 = 1 + 1e-5f;
  std::vector<Vector3f> p = {{-0.5f, -1, z0}, {1.5f, -1, z0}, {1.5f, 1, z0}, {-0.5f, 1, z0},
                             {-0.5f, -1, z1}, {1.5f, -1, z1}, {1.5f, 1, z1}, {-0.5f, 1, z1}};
  Tris box = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
              {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  const double exact = 1 - polygon_form_factor(Vector3d::Zero(), Vector3d::UnitZ(), to_d(kSquare));
  EXPECT_NEAR(ao_at(make_mesh(p, box, "plate"), free_point({0, 0, 0})), exact, kTol);
  Tris sheets = {{0, 1, 2}, {0, 2, 3}, {0, 2, 1}, {0, 3, 2}};
  EXPECT_NEAR(ao_at(make_mesh(p, sheets, "sheets"), free_point({0, 0, 0})), exact, kTol);
  // Seen from inside the thin plate: enclosed.
  EXPECT_EQ(ao_at(make_mesh(p, box, "plate"), free_point({0.5, 0, 1 + 5e-6})), 0.0);
}

TEST(Stiff, EdgeSharedByThreeFacesMatchesQmc) {
  // A "book" of three pages on a common spine above p: non-manifold edge with 3 faces.
  std::vector<Vector3f> p = {{-1, 0, 1}, {1, 0, 1}, {-1, 1, 1.2f}, {1, 1, 1.2f}, {-1, -1, 1.3f}, {1, -1, 1.3f},
                             {-1, 0.3f, 2}, {1, 0.3f, 2}};
  Tris t = {{0, 1, 3}, {0, 3, 2}, {0, 1, 5}, {0, 5, 4}, {0, 1, 7}, {0, 7, 6}};
  std::vector<Mesh> parts{grid(2, 3), make_mesh(p, t, "book")};
  const Mesh m = merge(parts);
  const Topology topo = build_topology(m);
  bool has_three = false;
  for (size_t e = 0; e < topo.edges.size(); ++e) has_three |= topo.faces_of_edge(uint32_t(e)).size() == 3;
  ASSERT_TRUE(has_three);
  ProductRequest req;
  req.ao = true;
  req.transfer_order = 2;
  SilhouetteIntegrator sil(m, topo, req, {kN, 1});
  QmcIntegrator qmc(m, topo, req, {65536, 3});
  const ShadePoint sp = vertex_shade_point(m, topo, 2 * 5 * 2 + 2);  // the ground's centre vertex
  std::vector<double> a(5), b(5), se(5);
  sil.integrate(sp, 0, a);
  qmc.integrate(sp, 0, b, se);
  for (int k = 0; k < 5; ++k) EXPECT_NEAR(a[size_t(k)], b[size_t(k)], 4 * se[size_t(k)] + kTol) << k;
  EXPECT_LT(a[0], 0.99);  // the book does shadow the point (its steep pages subtend little)
}

TEST(Stiff, AxisAlignedCubeOnTheOctahedralSeamsThroughP) {
  // A unit cube with faces on the planes x = 0 and y = 0 through p (the octahedral seams of an
  // unrotated frame) above p. Convex: its front faces tile its silhouette.
  std::vector<Vector3f> c;
  for (int k = 0; k < 8; ++k) c.emplace_back(k & 1 ? 1.f : 0.f, k & 2 ? 1.f : 0.f, k & 4 ? 2.f : 1.f);
  Tris t = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
            {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  // Seen from the origin only the bottom face (z = 1) faces p; the x = 0 and y = 0 faces are edge-on.
  const double exact = 1 - polygon_form_factor(Vector3d::Zero(), Vector3d::UnitZ(),
                                               {{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}});
  EXPECT_NEAR(ao_at(make_mesh(c, t, "cube"), free_point({0, 0, 0})), exact, kTol);
  // The cube lowered to straddle z = 0, so p lies on its vertical edge x = y = 0: faces x = 0 and
  // y = 0 contain p and stay edge-on in the limit. From p + εn the solid fills exactly the quadrant
  // x, y > 0, a quarter of the cosine-weighted hemisphere: AO = 3/4 exactly. (A ray caster cannot
  // take this case: its rays start on the faces.)
  std::vector<Vector3f> c2;
  for (auto v : c) c2.push_back(v - Vector3f(0, 0, 1.5f));
  EXPECT_NEAR(ao_at(make_mesh(c2, t, "cube2"), free_point({0, 0, 0})), 0.75, kTol);
}

TEST(Stiff, GroundPlaneThroughP) {
  // p on a ground triangle's interior (not a vertex) and at a ground vertex: the plane itself
  // occludes nothing of the upper hemisphere.
  const double exact = 1 - polygon_form_factor(Vector3d::Zero(), Vector3d::UnitZ(), to_d(kSquare));
  const Mesh m = merge({grid(2, 4), quad(kSquare, "sq")});
  EXPECT_NEAR(ao_at(m, free_point({0.1234, 0.0567, 0})), 1 - polygon_form_factor({0.1234, 0.0567, 0}, Vector3d::UnitZ(), to_d(kSquare)), kTol);
  const Topology topo = build_topology(m);
  EXPECT_NEAR(ao_at(m, vertex_shade_point(m, topo, 2 * 5 + 2)), exact, kTol);
  EXPECT_NEAR(ao_at(m, free_point({0, 0, 0})), exact, kTol);  // the same vertex as a free point
}

TEST(Stiff, OccluderCrossingTheHorizon) {
  // A wall x = 1, |y| ≤ 1, -1 ≤ z ≤ 1 seen from p = 0 with n = +z: only its upper half counts.
  const std::vector<Vector3f> wall = {{1, -1, -1}, {1, 1, -1}, {1, 1, 1}, {1, -1, 1}};
  const double exact = 1 - polygon_form_factor(Vector3d::Zero(), Vector3d::UnitZ(),
                                               {{1, -1, 0}, {1, 1, 0}, {1, 1, 1}, {1, -1, 1}});
  EXPECT_NEAR(ao_at(quad(wall, "wall"), free_point({0, 0, 0})), exact, kTol);
  // Tilted normal: the horizon cuts the wall obliquely; compare with QMC.
  const Mesh m = quad(wall, "wall");
  const Topology topo = build_topology(m);
  ProductRequest req;
  req.ao = true;
  req.transfer_order = 3;
  const ShadePoint sp = free_point({0, 0, 0}, {0.4, 0.3, 1});
  SilhouetteIntegrator sil(m, topo, req, {kN, 1});
  QmcIntegrator qmc(m, topo, req, {65536, 9});
  std::vector<double> a(10), b(10), se(10);
  sil.integrate(sp, 0, a);
  qmc.integrate(sp, 0, b, se);
  for (int k = 0; k < 10; ++k) EXPECT_NEAR(a[size_t(k)], b[size_t(k)], 4 * se[size_t(k)] + kTol) << k;
}

TEST(Stiff, FullSphereModeSolidAngles) {
  // No normal, no hemisphere: ∫ V y_00 dω = (4π − Ω(square)) / (2√π).
  const Mesh m = quad(kSquare, "sq");
  const Topology topo = build_topology(m);
  ProductRequest req;
  req.visibility_order = 1;
  SilhouetteIntegrator sil(m, topo, req, {kN, 1});
  ShadePoint sp = free_point({0, 0, 0});
  sp.hemisphere = false;
  double u0;
  sil.integrate(sp, 0, std::span(&u0, 1));
  const double omega = polygon_solid_angle(Vector3d::Zero(), to_d(kSquare));
  EXPECT_NEAR(u0, (4 * pi - omega) / (2 * std::sqrt(pi)), kTol);
}

TEST(Stiff, SaddleAndCreaseVerticesMatchQmcInTheLimitFromAbove) {
  // z = 0.8 (x² − y²) sampled on a 9×9 grid (saddle at the centre), z = |x| (a concave valley
  // crease) and z = −0.7|x| (a convex ridge),
  // both shaded at the centre vertex: two independent treatments of the 1-ring limit (QMC's
  // analytic cone test, the silhouette's ε-predicates) must agree.
  for (int shape = 0; shape < 3; ++shape) {
    std::vector<Vector3f> p;
    Tris t;
    const int n = 9;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const float x = (i - 4) * 0.25f, y = (j - 4) * 0.25f;
        const float z = shape == 0 ? 0.8f * (x * x - y * y) : shape == 1 ? std::abs(x) : -0.7f * std::abs(x);
        p.emplace_back(x, y, z);
      }
    for (int j = 0; j + 1 < n; ++j)
      for (int i = 0; i + 1 < n; ++i) {
        const uint32_t a = uint32_t(j * n + i), b = a + 1, c = a + uint32_t(n) + 1, d = a + uint32_t(n);
        t.push_back({a, b, c});
        t.push_back({a, c, d});
      }
    const Mesh m = make_mesh(p, t, "surface");
    const Topology topo = build_topology(m);
    ProductRequest req;
    req.ao = true;
    req.transfer_order = 3;
    SilhouetteIntegrator sil(m, topo, req, {kN, 1});
    QmcIntegrator qmc(m, topo, req, {65536, 21});
    const ShadePoint sp = vertex_shade_point(m, topo, 4 * n + 4);
    std::vector<double> a(10), b(10), se(10);
    sil.integrate(sp, 0, a);
    qmc.integrate(sp, 0, b, se);
    for (int k = 0; k < 10; ++k)
      EXPECT_NEAR(a[size_t(k)], b[size_t(k)], 4 * se[size_t(k)] + kTol) << "shape " << shape << " value " << k;
    EXPECT_EQ(sil.silhouette_stats().inconsistent_loops, 0u) << "shape " << shape;
    if (shape == 1) {
      EXPECT_LT(a[0], 0.95) << "a concave crease occludes its own vertex";
    }
    if (shape == 2) {
      EXPECT_NEAR(a[0], 1.0, kTol) << "a convex ridge does not";
    }
  }
}

TEST(Stiff, TranslationAndScaleInvariance) {
  // A scene on a dyadic grid, so translating by 2^17 (≈ 1.3e5) and scaling by 2^-13 (≈ 1.2e-4)
  // are exact in float: the answers must agree to rounding of the double predicates.
  auto scene = [](float s, Vector3f off) {
    std::vector<Vector3f> sq, g;
    for (const auto& v : kSquare) sq.push_back(v * s + off);
    Mesh gr = grid(2, 4);
    for (auto& v : gr.positions) v = v * s + off;
    gr = make_mesh(gr.positions, gr.triangles, "ground");
    return merge({gr, quad(sq, "sq")});
  };
  const Mesh base = scene(1, Vector3f::Zero());
  const Topology tb = build_topology(base);
  const double a0 = ao_at(base, vertex_shade_point(base, tb, 12));
  const Mesh far = scene(1, Vector3f(131072, -131072, 131072));
  const Topology tf = build_topology(far);
  EXPECT_NEAR(ao_at(far, vertex_shade_point(far, tf, 12)), a0, 1e-9);
  const Mesh tiny = scene(std::ldexp(1.0f, -13), Vector3f::Zero());
  const Topology tt = build_topology(tiny);
  EXPECT_NEAR(ao_at(tiny, vertex_shade_point(tiny, tt, 12)), a0, 1e-9);
}

TEST(Stiff, VeryLowAndVeryHighK) {
  const double exact = 1 - polygon_form_factor(Vector3d::Zero(), Vector3d::UnitZ(), to_d(kSquare));
  const Mesh m = merge({grid(2, 4), quad(kSquare, "sq")});
  const Topology topo = build_topology(m);
  for (int n : {2, 4, 1024}) {
    const double ao = ao_at(m, vertex_shade_point(m, topo, 12), n);
    EXPECT_GE(ao, 0.0);
    EXPECT_LE(ao, 1.0 + 1e-9);
    if (n == 1024) {
      EXPECT_NEAR(ao, exact, kTol / 4);
    }
  }
}

TEST(Stiff, BoundaryVertexOfAHalfPlane) {
  // A flat half-plane z = 0, y ≥ 0 (a fan of 4 large triangles) shaded at the origin on its
  // boundary: the spokes along the boundary are 1-face contour edges that start at the shade
  // point itself, seen from p + εn in direction −n.
  const float S = 1000;
  std::vector<Vector3f> p = {{0, 0, 0}, {S, 0, 0}, {S, S, 0}, {-S, S, 0}, {-S, 0, 0}};
  const Tris t = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}};
  // Full sphere: the half-plane covers exactly half of the lower hemisphere (solid angle π) in the
  // limit, so ∫ V y_00 = (4π − π) · y_00 (the planes' far edges, 1000 away, cut < 1e-6 of it).
  {
    const Mesh m = make_mesh(p, t, "halfplane", std::vector<Vector3f>(p.size(), Vector3f(0, 0, 1)));
    const Topology topo = build_topology(m);
    ProductRequest req;
    req.visibility_order = 1;
    SilhouetteIntegrator sil(m, topo, req, {kN, 1});
    ShadePoint sp = vertex_shade_point(m, topo, 0);
    sp.hemisphere = false;
    double u0;
    sil.integrate(sp, 0, std::span(&u0, 1));
    EXPECT_NEAR(u0, 3 * pi / (2 * std::sqrt(pi)), kTol);
  }
  // Hemisphere with n tilted over the plane (+y): part of the upper hemisphere dips below z = 0 on
  // the plane's side and is blocked. Compare with QMC's independent analytic 1-ring test.
  const Vector3f tilt = Vector3f(0, 0.5f, 1).normalized();
  const Mesh m = make_mesh(p, t, "halfplane", std::vector<Vector3f>(p.size(), tilt));
  const Topology topo = build_topology(m);
  ProductRequest req;
  req.ao = true;
  req.transfer_order = 2;
  SilhouetteIntegrator sil(m, topo, req, {kN, 1});
  QmcIntegrator qmc(m, topo, req, {65536, 13});
  const ShadePoint sp = vertex_shade_point(m, topo, 0);
  std::vector<double> a(5), b(5), se(5);
  sil.integrate(sp, 0, a);
  qmc.integrate(sp, 0, b, se);
  for (int k = 0; k < 5; ++k) EXPECT_NEAR(a[size_t(k)], b[size_t(k)], 4 * se[size_t(k)] + kTol) << k;
  EXPECT_LT(a[0], 0.99);
}

// Found by bench/texel_rate.sh (issue 30): a texel of 2CylinderEngine.glb (texel (417, 308) at
// --density 0.125, row 60745) whose sample lies EXACTLY on a convex crease edge of a block (λ =
// 55655/65536 along it; bake/mesh/texels.h puts samples exactly on their triangle): the side face
// x ≈ −236.5 (its interpolated normal n ≈ +x) meets the top face z ≈ 88, which is not quite planar
// (corners' z differ by ~3e-5) and is seen nearly edge-on (n·n_top ≈ −2e-7). The crease edge's
// line passes through p, so seen from p + εn it is the great half circle through −n (the
// T-junction rule); but a − p and b − p, rounded, were not exactly parallel (|da × db| = 1.1e-16
// for |da||db| = 3), so the "exactly parallel" test missed it and the arc took the rounding's
// half circle, through the zenith: N/3 isoline loops inconsistent, AO 0.004 where QMC sees the
// sky (0.9995 from these 25 triangles, the engine's within 20 units of p). Collinearity is now
// filtered by a rounding bound and decided exactly (bake/integrators/silhouette.cpp). On the
// engine at --density 0.125 such texels held 87% of the silhouette's squared AO error.
TEST(Stiff, FaceSeenEdgeOnFromAPointOnAConvexCrease) {
  const std::vector<std::array<Vector3f, 3>> tris = {
      {{{-238.352585, 9.44422054, 88.0000534}, {-238.352585, 9.44422054, 88.0000534}, {-241.299988, 16.668108, 80.0000916}}},
      {{{-241.299988, 16.668108, 80.0000916}, {-238.352585, 9.44422054, 88.0000534}, {-238.352585, 9.44423103, 80.0000763}}},
      {{{-238.352585, 9.44422054, 88.0000534}, {-236.97641, 4.85695744, 88.0000458}, {-238.352585, 9.44423103, 80.0000763}}},
      {{{-238.352585, 9.44423103, 80.0000763}, {-236.97641, 4.85695744, 88.0000458}, {-236.97641, 4.85696888, 80.0000687}}},
      {{{-236.97641, 4.85695744, 88.0000458}, {-236.5, -8.09315025e-05, 88.0000381}, {-236.97641, 4.85696888, 80.0000687}}},
      {{{-236.97641, 4.85696888, 80.0000687}, {-236.5, -8.09315025e-05, 88.0000381}, {-236.5, -6.96614661e-05, 80.000061}}},
      {{{-236.5, -8.09315025e-05, 88.0000381}, {-236.5, -8.09315025e-05, 88.0000381}, {-236.5, -6.96614661e-05, 80.000061}}},
      {{{-236.5, -6.96614661e-05, 80.000061}, {-236.5, -8.09315025e-05, 88.0000381}, {-236.976166, -4.85607433, 80.000061}}},
      {{{-236.5, -8.09315025e-05, 88.0000381}, {-236.976395, -4.85728741, 88.0000381}, {-236.976166, -4.85607433, 80.000061}}},
      {{{-236.976166, -4.85607433, 80.000061}, {-236.976395, -4.85728741, 88.0000381}, {-238.352585, -9.44454575, 80.0000534}}},
      {{{-236.976395, -4.85728741, 88.0000381}, {-238.352585, -9.44455624, 88.0000305}, {-238.352585, -9.44454575, 80.0000534}}},
      {{{-238.352585, -9.44454575, 80.0000534}, {-238.352585, -9.44455624, 88.0000305}, {-241.299973, -16.6684227, 80.0000381}}},
      {{{-238.352585, 9.44422054, 88.0000534}, {-247.71431, 14.489645, 88.000061}, {-238.352585, 9.44422054, 88.0000534}}},
      {{{-247.71431, 14.489645, 88.000061}, {-244.179489, 9.99975681, 88.000061}, {-238.352585, 9.44422054, 88.0000534}}},
      {{{-238.352585, 9.44422054, 88.0000534}, {-244.179489, 9.99975681, 88.000061}, {-238.352585, 9.44422054, 88.0000534}}},
      {{{-244.179489, 9.99975681, 88.000061}, {-242.05864, 4.69368315, 88.0000458}, {-238.352585, 9.44422054, 88.0000534}}},
      {{{-238.352585, 9.44422054, 88.0000534}, {-242.05864, 4.69368315, 88.0000458}, {-236.97641, 4.85695744, 88.0000458}}},
      {{{-242.05864, 4.69368315, 88.0000458}, {-241.514801, -0.769474149, 88.0000381}, {-236.97641, 4.85695744, 88.0000458}}},
      {{{-236.97641, 4.85695744, 88.0000458}, {-241.514801, -0.769474149, 88.0000381}, {-236.5, -8.09315025e-05, 88.0000381}}},
      {{{-241.514801, -0.769474149, 88.0000381}, {-242.356277, -5.78960848, 88.0000381}, {-236.5, -8.09315025e-05, 88.0000381}}},
      {{{-236.5, -8.09315025e-05, 88.0000381}, {-242.356277, -5.78960848, 88.0000381}, {-236.976395, -4.85728741, 88.0000381}}},
      {{{-242.356277, -5.78960848, 88.0000381}, {-244.179474, -10.0000925, 88.0000305}, {-236.976395, -4.85728741, 88.0000381}}},
      {{{-236.976395, -4.85728741, 88.0000381}, {-244.179474, -10.0000925, 88.0000305}, {-238.352585, -9.44455624, 88.0000305}}},
      {{{-244.179474, -10.0000925, 88.0000305}, {-246.914322, -13.6844616, 88.0000229}, {-238.352585, -9.44455624, 88.0000305}}},
      {{{-238.352585, -9.44455624, 88.0000305}, {-246.914322, -13.6844616, 88.0000229}, {-238.352585, -9.44455624, 88.0000305}}},
  };
  std::vector<Vector3f> p;
  Tris t;
  for (const auto& tri : tris) {
    t.push_back({uint32_t(p.size()), uint32_t(p.size() + 1), uint32_t(p.size() + 2)});
    p.insert(p.end(), tri.begin(), tri.end());
  }
  const Mesh m = make_mesh(p, t, "engine crease");
  const Topology topo = build_topology(m);
  ProductRequest req;
  req.ao = true;
  ShadePoint sp;
  sp.p = Vector3d(-236.57182932039723, 0.73222491727405947, 88.000039297272451);
  sp.n = Vector3d(0.99956670832340733, 0.029434598884095713, -2.0148253693127489e-07);
  sp.t = Vector3d(-0.020182438257855737, 0.68536849414128498, -0.72791668233697948);
  const SilhouetteIntegrator sil(m, topo, req, {64, 1});
  const QmcIntegrator qmc(m, topo, req, {16384, 3});
  std::vector<double> a(1), b(1), se(1);
  sil.integrate(sp, 0, a);
  qmc.integrate(sp, 0, b, se);
  EXPECT_NEAR(a[0], b[0], 4 * se[0] + 1e-3);
  EXPECT_EQ(sil.silhouette_stats().inconsistent_loops, 0u);
}

TEST(Stiff, PointsExactlyOnARidgeWhoseRoundedDirectionsAreNotParallelSeeTheOpenHemisphere) {
  // The engine case above in general: a ridge (two triangles folding down from a shared edge a-b,
  // float corners with mixed magnitudes, as a CAD part far from the origin with a coordinate near
  // 0) and a free point EXACTLY on the edge's line (p = a + λ(b − a) rounded once, λ = k/65536, kept only
  // when exact predicates say collinear) where the rounded a − p and b − p are NOT exactly parallel.
  // n is face 1's normal tilted 1e-7 towards face 2's (face 2 seen nearly edge-on, as the
  // engine's top face); the ridge is convex, so its wedge lies below the horizon: AO = 1 up to a
  // 1e-7 sliver and the tables' O(h²), and every isoline loop must close. Before the exact
  // collinearity test the ridge edge took the rounding's half circle: AO 0.60–0.70 here.
  std::mt19937_64 rng(12345);
  const auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * double(rng() >> 11) * 0x1p-53; };
  int tested = 0;
  uint64_t inconsistent = 0;
  for (int trial = 0; trial < 64 && tested < 24; ++trial) {
    // As the engine's crease: one end's y several units, the other's within 1e-4 of 0, so b − a
    // needs ~40 bits and λ(b − a) more than a double holds.
    const Vector3f a(float(uniform(-300, 300)), float(uniform(2, 6)), float(uniform(50, 120)));
    const Vector3f b(float(a.x() + uniform(-1, 1)), float(uniform(-1e-4, 1e-4)), float(a.z() + uniform(-1e-4, 1e-4)));
    const Vector3d A = a.cast<double>(), B = b.cast<double>(), e = (B - A).normalized();
    const Vector3d up = (Vector3d::UnitZ() - Vector3d::UnitZ().dot(e) * e).normalized(), side = e.cross(up);
    const Vector3d mid = 0.5 * (A + B);
    const Vector3f c1 = (mid - 2 * up + 3 * side).cast<float>(), c2 = (mid - 3 * up - 2 * side).cast<float>();
    const Mesh m = make_mesh({a, b, c1, c2}, {{0, 1, 2}, {1, 0, 3}}, "ridge");
    const Topology topo = build_topology(m);
    ProductRequest req;
    req.ao = true;
    const SilhouetteIntegrator sil(m, topo, req, {kN, 1});
    const Vector3d n1 = (B - A).cross(c1.cast<double>() - A).normalized(), n2 = (A - B).cross(c2.cast<double>() - B).normalized();
    // Both faces are wound facing down. n: face 1's upward normal tilted 1e-7 towards face 2's,
    // as the engine's (the point's own face's normal, the other face seen nearly edge-on).
    const Vector3d n = -(n1 + 1e-7 * n2).normalized();
    for (int k = 1; k < 65536; k += 2) {
      Vector3d q;  // a + λ(b − a) rounded once (b − a is exact in double; fma rounds once)
      for (int c = 0; c < 3; ++c) q[c] = std::fma(k / 65536.0, B[c] - A[c], A[c]);
      bool on_line = true;
      for (int c = 0; c < 3; ++c) on_line = on_line && orient3d_exact(A, B, q, q + Vector3d::Unit(c)) == 0;
      if (!on_line || (A - q).cross(B - q).squaredNorm() == 0) continue;  // not the case under test
      ShadePoint sp;
      sp.p = q;
      sp.n = n;
      double ao = -1;
      sil.integrate(sp, uint64_t(k), std::span(&ao, 1));
      EXPECT_NEAR(ao, 1.0, kTol) << "trial " << trial << ", lambda " << k << "/65536";
      ++tested;
      break;
    }
    inconsistent += sil.silhouette_stats().inconsistent_loops;
  }
  EXPECT_GE(tested, 12) << "points exactly on the ridge whose rounded directions are not parallel";
  EXPECT_EQ(inconsistent, 0u);
}
