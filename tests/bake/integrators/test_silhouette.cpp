// Tests of the silhouette integrator (bake/integrators/silhouette.h, paper 001 §3): analytic cases,
// agreement with the QMC reference within its standard error, stiff cases and invariances.
#include <bake/environment/envmap.h>
#include <bake/integrators/qmc.h>
#include <bake/integrators/silhouette.h>
#include <bake/mesh/mesh.h>
#include <bake/mesh/receivers.h>
#include <bake/sphere/isoline_tables.h>
#include <bake/sphere/octahedral.h>
#include <bake/sphere/sampling.h>
#include <prtshade/sh.h>

#include <gtest/gtest.h>
#include <test_scenes.h>

#include <cmath>
#include <numbers>

using namespace prt::bake;
using prt::testing::box;
using prt::testing::grid;
using prt::testing::grid_centre;
using prt::testing::polygon_form_factor;
using Eigen::Vector3d;
using Eigen::Vector3f;
using std::numbers::pi;

namespace {

// The bound for analytic cases at k = 256²: the isoline discretisation (midpoint rule
// in u, cell-constant f·J in v) has error O(h²) = O(6e-5) for smooth integrands at h = 2/256.
constexpr double kAnalyticTol = 1e-4;




struct Row {
  std::vector<double> v;
  double operator[](size_t i) const { return v[i]; }
};
Row integrate(const Integrator& I, const ShadePoint& sp) {
  Row r{std::vector<double>(I.layout().width)};
  I.integrate(sp, 0, r.v);
  for (double x : r.v) EXPECT_TRUE(std::isfinite(x));
  return r;
}

} // namespace

TEST(Octahedral, JacobianIntegratesToTheSphere) {
  // Σ over all cells of h · mean(J) must be 4π: the tables of f = 1.
  for (int n : {16, 64, 256}) {
    const oct::Grid g(n);
    IsolineTables t(g, 1, 2, [](const Vector3d&, std::span<double> out) { out[0] = 1; });
    double total = 0;
    for (int i = 0; i < n; ++i) total += g.h * t.loop_total(i)[0];
    EXPECT_NEAR(total, 4 * pi, 40.0 / (n * n)) << n;  // O(h²) midpoint error
  }
  EXPECT_NEAR(oct::jacobian(0, 0), 1.0, 1e-15);
  EXPECT_NEAR(oct::jacobian(0.5, 0.5), std::pow(0.5, -1.5), 1e-12);
}

TEST(Octahedral, CeilIntIsStdCeil) {
  // The isoline index of a crossing must be the same integer bit for bit: ceil_int against
  // int(std::ceil(x)) on integers, half-integers, their float neighbours, signed zeros and
  // seeded values over the range an index takes (|x| ≤ 2²⁰) and far beyond it.
  std::vector<double> xs = {0.0, -0.0, 0.5, -0.5, 1.0, -1.0, 2.5, -2.5, 1e-300, -1e-300, 2147483646.5, -2147483647.5};
  for (int k = -70; k <= 70; ++k)
    for (const double x : {double(k), k + 0.5})
      xs.insert(xs.end(), {x, std::nextafter(x, -1e9), std::nextafter(x, 1e9)});
  uint64_t state = 12345;
  for (int r = 0; r < 200000; ++r) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    const double unit = double(state >> 11) * 0x1p-53;  // [0, 1)
    xs.push_back((2 * unit - 1) * (r % 2 ? 0x1p20 : 0x1p30));
  }
  for (const double x : xs) ASSERT_EQ(oct::ceil_int(x), int(std::ceil(x))) << x;
}

TEST(Silhouette, UnoccludedVertexClosedForms) {
  const Mesh m = grid(2, 1.0f);
  const Topology topo = build_topology(m);
  ProductRequest req;
  req.ao = true;
  req.transfer_order = 3;
  req.visibility_order = 3;
  SilhouetteIntegrator sil(m, topo, req, {256, 1});
  const auto& L = sil.layout();
  const Row r = integrate(sil, vertex_shade_point(m, topo, grid_centre(2)));
  EXPECT_NEAR(r[L.ao], 1.0, kAnalyticTol);
  for (int i = 0; i < 9; ++i) {
    const double exact = prt::testing::unoccluded_transfer_z(i);
    EXPECT_NEAR(r[L.transfer + size_t(i)], exact, kAnalyticTol) << "T_" << i;
  }
  EXPECT_NEAR(r[L.visibility], std::sqrt(pi), kAnalyticTol);
  EXPECT_EQ(sil.silhouette_stats().inconsistent_loops, 0u);
}

TEST(Silhouette, WhiteFurnaceBand1IrradianceIsPi) {
  const Mesh m = grid(1, 1.0f);
  const Topology topo = build_topology(m);
  const EnvMap white = EnvMap::constant({1, 1, 1});
  ProductRequest req;
  req.radiance = &white;
  SilhouetteIntegrator sil(m, topo, req, {256, 1});
  const Row R = integrate(sil, vertex_shade_point(m, topo, grid_centre(1)));
  double y[4];
  prt::sh::eval(2, 0.0, 0.0, 1.0, y);
  for (int c = 0; c < 3; ++c) {
    double E = 0;
    for (int mm = 0; mm < 3; ++mm) E += (4 * pi / 3) * y[1 + mm] * R[size_t(3 * c + mm)];
    EXPECT_NEAR(E, pi, pi * kAnalyticTol) << c;
  }
}

TEST(Silhouette, SquareOccluderMatchesLambert) {
  Mesh g = grid(2, 4.0f);
  std::vector<Vector3f> p = {{-0.5f, -1, 1}, {1.5f, -1, 1}, {1.5f, 1, 1}, {-0.5f, 1, 1}};
  std::vector<Mesh> parts{g, make_mesh(p, {{0, 1, 2}, {0, 2, 3}}, "square")};
  const Mesh m = merge_meshes(parts, "scene");
  const Topology topo = build_topology(m);
  std::vector<Vector3d> poly;
  for (auto& q : p) poly.push_back(q.cast<double>());
  const double exact = 1 - polygon_form_factor(Vector3d::Zero(), Vector3d::UnitZ(), poly);
  ProductRequest req;
  req.ao = true;
  std::vector<double> err;
  for (int n : {32, 64, 128, 256}) {
    SilhouetteIntegrator sil(m, topo, req, {n, 1});
    err.push_back(std::abs(integrate(sil, vertex_shade_point(m, topo, grid_centre(2)))[0] - exact));
  }
  EXPECT_LE(err.back(), kAnalyticTol) << "exact " << exact;
  EXPECT_LT(err.back(), err.front()) << "the error keeps falling with k";
  // The free point just above the vertex gives the same answer.
  SilhouetteIntegrator sil(m, topo, req, {256, 1});
  ShadePoint free_point;
  free_point.p = Vector3d(0, 0, 0);
  EXPECT_NEAR(integrate(sil, free_point)[0], exact, kAnalyticTol);
}

TEST(Silhouette, VGrooveCreaseVertexIsExact) {
  for (double alpha : {pi / 2, 2 * pi / 3, 0.8 * pi}) {
    const double c = std::cos(alpha / 2), s = std::sin(alpha / 2);
    const float S = 1000;
    std::vector<Vector3f> p = {{0, 0, 0}, {S, 0, 0}, {-S, 0, 0}, {S, float(s), float(c)}, {-S, float(s), float(c)},
                               {S, float(-s), float(c)}, {-S, float(-s), float(c)}};
    std::vector<std::array<uint32_t, 3>> t = {{0, 1, 3}, {0, 3, 4}, {0, 4, 2}, {0, 5, 1}, {0, 6, 5}, {0, 2, 6}};
    Mesh m = make_mesh(p, t, "vgroove", std::vector<Vector3f>(p.size(), Vector3f(0, 0, 1)));
    const Topology topo = build_topology(m);
    ProductRequest req;
    req.ao = true;
    SilhouetteIntegrator sil(m, topo, req, {256, 1});
    // The far ends of the planes (1000 away, seen within 1e-3 rad of ±x) are part of the scene
    // here, unlike the limit-only QMC test: they shave < 1e-6 off the lune.
    EXPECT_NEAR(integrate(sil, vertex_shade_point(m, topo, 0))[0], std::sin(alpha / 2), kAnalyticTol) << alpha;
  }
}

// A free point (welded = −1: a texel's sample, a scene's receiver-only vertex) that lies exactly on
// a vertex of another part: a box's bottom corner resting inside a floor face (in the
// architectural scene, texels on the floor slab's edge where a wall's corners stand). The box's
// edges from that vertex are seen from p + εn, their near end at −n, as from the box's own vertex
// (before, p − p gave them no direction and the walk started from the wrong depth: AO ≈ 0.003
// where QMC gives 0.80). With n = +z and the tie-break t pointing away from the box, the box
// blocks exactly the quarter of the hemisphere x, y > 0: AO = 3/4; tilted, against QMC.
TEST(Silhouette, FreePointOnAnotherPartsVertex) {
  std::vector<Mesh> parts{grid(2, 4.0f), box({0.5f, 0.5f, 0}, {1.5f, 1.5f, 1})};
  const Mesh m = merge_meshes(parts, "floor and box");
  const Topology topo = build_topology(m);
  ProductRequest req;
  req.ao = true;
  SilhouetteIntegrator sil(m, topo, req, {256, 1});
  QmcIntegrator qmc(m, topo, req, {16384, 3});
  ShadePoint sp;
  sp.p = Vector3d(0.5, 0.5, 0);  // the box's corner, inside a floor triangle (floor vertices 2 apart)
  sp.n = Vector3d::UnitZ();
  sp.t = Vector3d(-1, -1, 0).normalized();
  EXPECT_NEAR(integrate(sil, sp)[0], 0.75, kAnalyticTol);
  for (const Vector3d& n : {Vector3d(0.3, 0.2, 0.93), Vector3d(-0.4, 0.1, 0.9)}) {
    sp.n = n.normalized();
    sp.t = (Vector3d(-1, -1, 0) - sp.n.dot(Vector3d(-1, -1, 0)) * sp.n).normalized();
    std::vector<double> b(1), se(1);
    qmc.integrate(sp, 0, b, se);
    // QMC's standard error is the conservative Monte Carlo one; the silhouette's O(h²) on top.
    EXPECT_NEAR(integrate(sil, sp)[0], b[0], 4 * se[0] + 2e-4) << n.transpose();
  }
  EXPECT_EQ(sil.silhouette_stats().inconsistent_loops, 0u);
}

TEST(Silhouette, EnclosedPointSeesNothing) {
  const Mesh m = box({-1, -1, -1}, {1, 1, 1});
  const Topology topo = build_topology(m);
  ProductRequest req;
  req.ao = true;
  req.transfer_order = 3;
  req.visibility_order = 2;
  SilhouetteIntegrator sil(m, topo, req, {64, 1});
  for (const Vector3d& p : {Vector3d(0, 0, 0), Vector3d(0.3, -0.7, 0.2)}) {
    ShadePoint sp;
    sp.p = p;
    sp.n = Vector3d(0.2, 0.9, -0.3).normalized();
    const Row r = integrate(sil, sp);
    for (double x : r.v) EXPECT_EQ(x, 0.0);
    sp.hemisphere = false;
    for (double x : integrate(sil, sp).v) EXPECT_EQ(x, 0.0);
  }
  EXPECT_EQ(sil.silhouette_stats().inconsistent_loops, 0u);
}

TEST(Silhouette, InconsistentWindingAndSoupEqualTheCleanMesh) {
  const Mesh clean = load_mesh(std::string(PRT_DATA_DIR) + "/bunny.obj", {.use_file_normals = false});
  Mesh flipped = clean;
  for (size_t f = 0; f < flipped.triangles.size(); f += 2) std::swap(flipped.triangles[f][1], flipped.triangles[f][2]);
  // Unwelded soup: every triangle its own three vertices (welding by position reconnects it).
  std::vector<Vector3f> sp;
  std::vector<std::array<uint32_t, 3>> st;
  for (const auto& t : clean.triangles) {
    const uint32_t b = uint32_t(sp.size());
    for (int k = 0; k < 3; ++k) sp.push_back(clean.positions[t[k]]);
    st.push_back({b, b + 1, b + 2});
  }
  const Mesh soup = make_mesh(sp, st, "soup");
  ProductRequest req;
  req.ao = true;
  req.transfer_order = 2;
  const Topology tc = build_topology(clean), tf = build_topology(flipped), ts = build_topology(soup);
  SilhouetteIntegrator a(clean, tc, req, {64, 1}), b(flipped, tf, req, {64, 1}), c(soup, ts, req, {64, 1});
  for (uint32_t v : seeded_sample(uint32_t(clean.positions.size()), 25, 3)) {
    const ShadePoint p = vertex_shade_point(clean, tc, v);
    ShadePoint q = p;
    q.welded = tf.weld[v];
    const Row ra = integrate(a, p), rb = integrate(b, q);
    EXPECT_EQ(ra.v, rb.v) << "vertex " << v;  // same edges in the same order: bitwise
    // In the soup, find the welded id of the same position through any corner.
    ShadePoint r = p;
    for (size_t i = 0; i < soup.positions.size(); ++i)
      if (soup.positions[i] == clean.positions[v]) {
        r.welded = ts.weld[i];
        break;
      }
    // The soup's welded edges are numbered differently, so sums run in another order: equal to
    // rounding (1e-12 ≫ 1e4 · 2^-52).
    const Row rc = integrate(c, r);
    for (size_t k = 0; k < ra.v.size(); ++k) EXPECT_NEAR(ra[k], rc[k], 1e-12) << "vertex " << v << " value " << k;
  }
}

TEST(Silhouette, AgreesWithQmcWithinItsStandardError) {
  const Mesh m = load_mesh(std::string(PRT_DATA_DIR) + "/bunny_ground.obj", {.use_file_normals = false});
  const Topology topo = build_topology(m);
  ProductRequest req;
  req.ao = true;
  req.transfer_order = 3;
  SilhouetteIntegrator sil(m, topo, req, {256, 1});
  QmcIntegrator qmc(m, topo, req, {32768, 17});
  const size_t W = sil.layout().width;
  double max_z = 0, sum_sq = 0;
  size_t count = 0;
  for (uint32_t v : seeded_sample(uint32_t(m.positions.size()), 24, 11)) {
    const ShadePoint p = vertex_shade_point(m, topo, v);
    std::vector<double> a(W), b(W), se(W);
    sil.integrate(p, v, a);
    qmc.integrate(p, v, b, se);
    for (size_t k = 0; k < W; ++k) {
      // QMC's reported standard error is the (conservative) MC one; the silhouette result has a
      // discretisation error of O(h²) ≈ 1e-4 on top.
      const double tol = 4 * se[k] + 2e-4;
      EXPECT_NEAR(a[k], b[k], tol) << "vertex " << v << " value " << k;
      max_z = std::max(max_z, std::abs(a[k] - b[k]) / tol);
      sum_sq += (a[k] - b[k]) * (a[k] - b[k]);
      ++count;
    }
  }
  RecordProperty("rmse_vs_qmc", std::to_string(std::sqrt(sum_sq / count)));
  EXPECT_EQ(sil.silhouette_stats().inconsistent_loops, 0u);
}

TEST(Silhouette, SunOnTheHorizonIsExact) {
  // A 64×32 lat-long map, a 2×2-texel sun of 800/500/500 centred on the equator (alone, then over a
  // dim sky of 0.05: 10^4 × dimmer), seen by an unoccluded point with n = +y: the horizon (the
  // parallel between rows 15 and 16) cuts the sun in half. Reference in closed form: the sum over
  // the upper rows' texels of L_t ∫_t y_1m dω, each texel a rectangle in (longitude λ,
  // s = sin latitude) with dω = dλ ds: ∫ x = (cos λ0 − cos λ1) G, ∫ z = (sin λ1 − sin λ0) G,
  // ∫ y = Δλ (s1² − s0²)/2, G = [(s √(1 − s²) + asin s)/2] from s0 to s1.
  const int W = 64, Hh = 32;
  const Mesh far = make_mesh({{100, -100, 100}, {101, -100, 100}, {100, -100, 101}}, {{0, 1, 2}}, "far");
  const Topology topo = build_topology(far);
  ShadePoint sp;
  sp.n = Vector3d(0, 1, 0);
  auto F = [](double s) { return 0.5 * (s * std::sqrt(std::max(0.0, 1 - s * s)) + std::asin(std::clamp(s, -1.0, 1.0))); };
  const double k1 = std::sqrt(3 / (4 * pi));
  for (const float dim : {0.0f, 0.05f}) {
    std::vector<float> rgb(size_t(W * Hh * 3), dim);
    for (int y = 15; y <= 16; ++y)
      for (int x = 20; x <= 21; ++x)
        for (int c = 0; c < 3; ++c) rgb[size_t(3 * (y * W + x) + c)] = c == 0 ? 800.f : 500.f;
    const EnvMap env = EnvMap::from_latlong(W, Hh, rgb, UpAxis::Y, "sun-on-horizon");
    ProductRequest req;
    req.radiance = &env;
    double ref[9] = {};
    for (int y = 0; y <= 15; ++y)
      for (int x = 0; x < W; ++x) {
        const double lat1 = pi / 2 - pi * std::max(y - 0.5, 0.0) / (Hh - 1), lat0 = pi / 2 - pi * (y + 0.5) / (Hh - 1);
        const double lon1 = pi - 2 * pi * std::max(x - 0.5, 0.0) / (W - 1), lon0 = pi - 2 * pi * std::min(x + 0.5, W - 1.0) / (W - 1);
        const double s0 = std::sin(lat0), s1 = std::sin(lat1), G = F(s1) - F(s0);
        const double ix = (std::cos(lon0) - std::cos(lon1)) * G, iz = (std::sin(lon1) - std::sin(lon0)) * G;
        const double iy = (lon1 - lon0) * (s1 * s1 - s0 * s0) / 2;
        const double Y[3] = {-k1 * iy, k1 * iz, -k1 * ix};
        const float* L = &rgb[size_t(3 * (y * W + x))];
        for (int ch = 0; ch < 3; ++ch)
          for (int m = 0; m < 3; ++m) ref[3 * ch + m] += double(L[ch]) * Y[m];
      }
    double norm = 0;
    for (double x : ref) norm = std::max(norm, std::abs(x));
    for (const int N : {32, 128}) {
      SilhouetteIntegrator sil(far, topo, req, {N, 1});
      EXPECT_NE(sil.description().find("4 hot environment texels"), std::string::npos) << sil.description();
      std::vector<double> R(9);
      sil.integrate(sp, 0, R);
      // The sun's half above the horizon is exact up to the top parallel's chords (1e-6 of the
      // texels' solid angle, EnvMap::texel_polygon) at any N: 1.5e-6 of the largest value leaves
      // room for rounding. Over the dim sky, the dim part's horizon cells are box-filtered by the
      // tables: an O(h) error of the dim part, measured 2.5e-6 of the largest value at N = 128
      // (2.1e-5 at N = 32). (The fine grid this replaced erred by up to 3.5e-3 of the RMS there.)
      const double tol = dim == 0 ? 1.5e-6 : N == 128 ? 1e-5 : 1e-4;
      for (int k = 0; k < 9; ++k)
        EXPECT_NEAR(R[size_t(k)], ref[k], tol * norm) << "dim sky " << dim << ", N = " << N << ", value " << k;
    }
  }
}

TEST(Silhouette, ComponentsBelowTheHorizonLeftOutChangeNothing) {
  // Contour components wholly below the horizon are left out and the horizon's step raised
  // (bake/integrators/silhouette.h): every product must equal the unculled walk's to rounding (the
  // runs with W = 0 are the same; only the order of float additions in the hot texels' cut texels
  // may differ). The scene puts whole objects below the horizon of free points: for each of 14
  // directions d, a box centred at 3d seen from the origin with n = −d (the box lies wholly
  // below, and the start ray along the spine direction s0 runs into it for d ≈ s0: the counted W
  // must be corrected by the left-out arcs it crosses); a bunny vertex's hemisphere, with the
  // ground's boxes below it; and a sun, so that the hot texels' W paths cross left-out regions.
  const Mesh bunny = load_mesh(std::string(PRT_DATA_DIR) + "/bunny.obj", {.use_file_normals = false});
  std::vector<Mesh> parts{bunny};
  // The spine start of the octahedral frame (silhouette.cpp octahedral_frame_from_world: the
  // world turned by 0.7236 rad about (0.3141, 0.5926, 0.7418)), frame direction (−1, 0, 0).
  const Eigen::Matrix3d frame_from_world =
      Eigen::AngleAxisd(0.7236, Vector3d(0.3141, 0.5926, 0.7418).normalized()).toRotationMatrix();
  const Vector3d s0 = frame_from_world.transpose() * Vector3d(-1, 0, 0);
  std::vector<Vector3d> dirs{s0};
  for (int k = 0; k < 13; ++k) {
    const double z = 1 - 2 * (k + 0.5) / 13, phi = 2.399963 * k;
    dirs.push_back(Vector3d(std::sqrt(1 - z * z) * std::cos(phi), z, std::sqrt(1 - z * z) * std::sin(phi)));
  }
  const Vector3f centre(0.f, 0.f, 0.f);
  const Vector3d far_origin(10, 0, 10);  // the free points sit away from the bunny
  for (const Vector3d& d : dirs) {
    const Vector3f c = (far_origin + 3 * d).cast<float>();
    parts.push_back(box(c - Vector3f(0.4f, 0.4f, 0.4f), c + Vector3f(0.4f, 0.4f, 0.4f)));
  }
  // Boxes under the bunny's belly, below most of its vertices' horizons.
  const Eigen::AlignedBox3f bb = [&] {
    Eigen::AlignedBox3f b;
    for (const Vector3f& v : bunny.positions) b.extend(v);
    return b;
  }();
  const Vector3f ext = bb.sizes();
  for (int k = 0; k < 3; ++k) {
    const Vector3f lo = bb.min() + Vector3f(0.3f * k * ext.x(), -0.6f * ext.y(), 0.2f * ext.z());
    parts.push_back(box(lo, lo + 0.25f * ext));
  }
  const Mesh m = merge_meshes(parts, "below");
  const Topology topo = build_topology(m);
  // A sun of 2×2 texels below the equator and one above, over a dim sky.
  const int W = 64, Hh = 32;
  std::vector<float> rgb(size_t(W * Hh * 3), 0.05f);
  for (const auto& [y0, x0] : {std::pair{20, 10}, std::pair{8, 40}})
    for (int y = y0; y <= y0 + 1; ++y)
      for (int x = x0; x <= x0 + 1; ++x)
        for (int c = 0; c < 3; ++c) rgb[size_t(3 * (y * W + x) + c)] = c == 0 ? 900.f : 600.f;
  const EnvMap env = EnvMap::from_latlong(W, Hh, rgb, UpAxis::Y, "suns");
  ProductRequest req;
  req.ao = true;
  req.transfer_order = 3;
  req.radiance = &env;
  const SilhouetteIntegrator culled(m, topo, req, {48, 1, true}), full(m, topo, req, {48, 1, false});
  std::vector<ShadePoint> points;
  for (const Vector3d& d : dirs) {
    ShadePoint sp;
    sp.p = far_origin;
    sp.n = -d;
    points.push_back(sp);
  }
  for (uint32_t v : seeded_sample(uint32_t(bunny.positions.size()), 40, 5)) points.push_back(vertex_shade_point(m, topo, v));
  for (size_t i = 0; i < points.size(); ++i) {
    const Row a = integrate(culled, points[i]), b = integrate(full, points[i]);
    for (size_t k = 0; k < a.v.size(); ++k)
      EXPECT_NEAR(a[k], b[k], 1e-11 * std::max(1.0, std::abs(b[k]))) << "point " << i << " value " << k;
  }
  EXPECT_EQ(culled.silhouette_stats().inconsistent_loops, 0u);
  EXPECT_EQ(full.silhouette_stats().inconsistent_loops, 0u);
  // Something was left out (else the test checks nothing): the summary's count is not 0.0.
  const std::string work = culled.work_summary();
  EXPECT_EQ(work.find("; 0.0 edges per integral below the horizon"), std::string::npos) << work;
  EXPECT_NE(full.work_summary().find("; 0.0 edges per integral below the horizon"), std::string::npos);
}
