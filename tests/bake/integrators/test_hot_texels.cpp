// Hot environment texels integrated exactly over their visible part (bake/integrators/hot_texels.h), in
// isolation and inside the silhouette integrator, against closed forms: a texel is a spherical
// polygon of constant radiance, its visible part past one straight occluder edge is that polygon
// clipped by a great circle, and PolygonSH projects it exactly (bake/sphere/polygon_sh.h).
#include <bake/environment/envmap.h>
#include <bake/integrators/hot_texels.h>
#include <bake/integrators/qmc.h>
#include <bake/integrators/silhouette.h>
#include <bake/mesh/mesh.h>
#include <bake/sphere/polygon_sh.h>
#include <bake/sphere/sampling.h>
#include <bake/sphere/spherical_polygon.h>
#include <prtshade/sh.h>

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <random>

using namespace prt::bake;
using Eigen::Vector3d;
using std::numbers::pi;

namespace {

// A great circle as the boundary of W: four quarter arcs with side_sum −1 (W steps +1 into
// n·ω < 0), as the silhouette integrator adds the horizon; W0 at s0 accordingly.
std::vector<DcfArc> great_circle(const Vector3d& n) {
  const Vector3d t1 = (std::abs(n.x()) < 0.9 ? Vector3d::UnitX() : Vector3d::UnitY()).cross(n).normalized();
  const Vector3d t2 = n.normalized().cross(t1);
  const Vector3d c[4] = {t1, t2, -t1, -t2};
  std::vector<DcfArc> arcs;
  for (int k = 0; k < 4; ++k) arcs.push_back({c[k], c[(k + 1) % 4], c[k].cross(c[(k + 1) % 4]), -1});
  return arcs;
}

// ∫ y_i over polygon ∩ {n·ω ≥ 0} in closed form (order² values).
std::vector<double> clipped_moments(const std::vector<Vector3d>& polygon, const Vector3d& n, int order) {
  std::vector<Vector3d> clipped;
  clip_to_horizon(polygon, n, clipped);
  std::vector<double> out(size_t(order * order), 0.0);
  if (clipped.size() >= 3) PolygonSH(order).project(clipped, out);
  return out;
}

// A map of zeros with the given texels lit (lat-long or cube).
EnvMap lit_latlong(int W, int H, const std::vector<int>& texels, float value) {
  std::vector<float> rgb(size_t(W * H * 3), 0.0f);
  for (int t : texels)
    for (int c = 0; c < 3; ++c) rgb[size_t(3 * t + c)] = value * float(c + 1);
  return EnvMap::from_latlong(W, H, rgb, UpAxis::Y, "lit");
}
EnvMap lit_cube(int S, const std::vector<int>& texels, float value) {
  std::vector<float> rgb(size_t(S * 6 * S * 3), 0.0f);
  for (int t : texels)
    for (int c = 0; c < 3; ++c) rgb[size_t(3 * t + c)] = value * float(c + 1);
  return EnvMap::from_exr_cube(S, rgb, UpAxis::Y, "lit");
}

} // namespace

TEST(HotTexels, TexelPolygonsHaveTheTexelsSolidAngles) {
  // Cube texels are exact great-arc quads: their solid angles agree to rounding (1e-13 relative).
  // Lat-long parallels are split into chords within 1e-6 of the texel's solid angle (the header's
  // sliver bound); every polygon is positively oriented (Ω > 0), and the sum is 4π.
  for (const bool cube : {false, true}) {
    const EnvMap env = cube ? lit_cube(8, {}, 0) : lit_latlong(64, 32, {}, 0);
    double sum = 0;
    for (int t = 0; t < env.texel_count(); ++t) {
      const std::vector<Vector3d> poly = env.texel_polygon(t);
      const double omega = solid_angle(poly), exact = env.texel_solid_angle(t);
      ASSERT_GT(omega, 0) << t;
      EXPECT_NEAR(omega, exact, (cube ? 1e-13 : 1e-6) * exact) << (cube ? "cube " : "lat-long ") << t;
      sum += omega;
    }
    EXPECT_NEAR(sum, 4 * pi, 1e-6 * 4 * pi);
  }
}

TEST(HotTexels, VisiblePartPastAGreatCircleMatchesTheClippedPolygon) {
  // 300 random great circles through random texels (lat-long, including the polar rows, and cube;
  // orders 2 and 6; arc ends at random lengths e^±4), W0 at s0 from the side s0 is on: the moments equal the closed form of the
  // clipped polygon to 1e-12 of the texel's solid angle (rounding in the chart and the projection).
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> U(-1, 1);
  const Vector3d s0(-1, 0, 0);
  int cut = 0;
  for (const bool cube : {false, true}) {
    std::vector<int> all;
    const int count = cube ? 16 * 16 * 6 : 32 * 16;
    for (int t = 0; t < count; ++t) all.push_back(t);
    // Every texel lit: the hot set is all texels at factor 0.
    const EnvMap env = cube ? lit_cube(16, all, 1) : lit_latlong(32, 16, all, 1);
    const Eigen::Matrix3d frame = Eigen::AngleAxisd(0.7236, Vector3d(0.3141, 0.5926, 0.7418).normalized()).toRotationMatrix();
    for (const int order : {2, 6}) {
      const HotTexels hot(env, frame, order, 0.0, size_t(count));
      ASSERT_EQ(hot.texels(), size_t(count));
      for (int trial = 0; trial < 75; ++trial) {
        const int t = int(std::uniform_int_distribution<int>(0, count - 1)(rng));
        const std::vector<Vector3d> poly = env.texel_polygon(t);
        Vector3d c = Vector3d::Zero();
        for (const Vector3d& v : poly) c += v;
        // A plane through a point near the texel's centre, in world coordinates.
        const Vector3d q = (c.normalized() + 0.03 * Vector3d(U(rng), U(rng), U(rng))).normalized();
        const Vector3d n = q.cross(Vector3d(U(rng), U(rng), U(rng))).normalized();
        std::vector<DcfArc> arcs = great_circle(frame * n);
        // Arc ends at any positive lengths (contour arcs are vertex offsets, not unit vectors).
        for (DcfArc& a : arcs) {
          a.a *= std::exp(4 * U(rng)), a.b *= std::exp(4 * U(rng));
          a.m = a.a.cross(a.b);
        }
        const int W0 = (frame * n).dot(s0) < 0 ? 1 : 0;
        const std::vector<double> got = hot.texel_moments(t, arcs, s0, W0);
        const std::vector<double> want = clipped_moments(poly, n, order);
        const double scale = env.texel_solid_angle(t);
        for (size_t i = 0; i < want.size(); ++i)
          ASSERT_NEAR(got[i], want[i], 1e-12 * scale) << (cube ? "cube" : "lat-long") << " texel " << t << " i " << i;
        if (std::abs(want[0]) > 1e-3 * scale && std::abs(want[0] - solid_angle(poly) / std::sqrt(4 * pi)) > 1e-3 * scale) ++cut;
      }
    }
  }
  EXPECT_GT(cut, 100);  // most trials cut their texel (the plane passes within 0.03 of its centre)
}

TEST(HotTexels, TriangleCornerInsideATexelMatchesTheClippedPolygon) {
  // A silhouette vertex inside the texel: an occluder triangle (W = 1 inside: side_sum +1 on its
  // counter-clockwise arcs) with one corner near the texel's centre and the others ~2 texels away,
  // so two arcs end inside the texel and the slab decomposition decides. Closed form: the texel
  // minus its part inside the triangle (the texel clipped by the triangle's three great circles).
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> U(-1, 1);
  const Vector3d s0(-1, 0, 0);
  for (const bool cube : {false, true}) {
    std::vector<int> all;
    const int count = cube ? 16 * 16 * 6 : 64 * 32;
    for (int t = 0; t < count; ++t) all.push_back(t);
    const EnvMap env = cube ? lit_cube(16, all, 1) : lit_latlong(64, 32, all, 1);
    const Eigen::Matrix3d frame = Eigen::AngleAxisd(0.7236, Vector3d(0.3141, 0.5926, 0.7418).normalized()).toRotationMatrix();
    const HotTexels hot(env, frame, 3, 0.0, size_t(count));
    for (int trial = 0; trial < 100; ++trial) {
      const int t = int(std::uniform_int_distribution<int>(0, count - 1)(rng));
      const std::vector<Vector3d> poly = env.texel_polygon(t);
      Vector3d c = Vector3d::Zero();
      for (const Vector3d& v : poly) c += v;
      c.normalize();
      const double size = std::sqrt(env.texel_solid_angle(t));
      const Vector3d e1 = c.cross(Vector3d(U(rng), U(rng), U(rng))).normalized(), e2 = c.cross(e1);
      const Vector3d v0 = (c + 0.2 * size * (U(rng) * e1 + U(rng) * e2)).normalized();
      const double a1 = 3.2 * U(rng), a2 = a1 + 0.6 + 1.5 * (U(rng) + 1);  // an angle < π at v0
      Vector3d v1 = (v0 + 2 * size * (std::cos(a1) * e1 + std::sin(a1) * e2)).normalized();
      Vector3d v2 = (v0 + 2 * size * (std::cos(a2) * e1 + std::sin(a2) * e2)).normalized();
      if (v0.cross(v1).dot(v2) < 0) std::swap(v1, v2);  // counter-clockwise from outside
      const Vector3d tri[3] = {v0, v1, v2};
      std::vector<DcfArc> arcs;
      for (int k = 0; k < 3; ++k) {
        const Vector3d a = frame * tri[k], b = frame * tri[(k + 1) % 3];
        arcs.push_back({a, b, a.cross(b), +1});
      }
      const int W0 = 0;  // s0 is far from every small triangle
      const std::vector<double> got = hot.texel_moments(t, arcs, s0, W0);
      std::vector<Vector3d> inside = poly, next;
      for (int k = 0; k < 3 && inside.size() >= 3; ++k) {
        clip_to_horizon(inside, tri[k].cross(tri[(k + 1) % 3]), next);
        inside.swap(next);
      }
      std::vector<double> full(9, 0.0), hidden(9, 0.0);
      PolygonSH(3).project(poly, full);
      if (inside.size() >= 3) PolygonSH(3).project(inside, hidden);
      for (size_t i = 0; i < 9; ++i)
        ASSERT_NEAR(got[i], full[i] - hidden[i], 1e-12 * env.texel_solid_angle(t))
            << (cube ? "cube" : "lat-long") << " texel " << t << " trial " << trial << " i " << i;
    }
  }
}

TEST(HotTexels, ClusterTreeAgreesWithTexelByTexel) {
  // accumulate() carries W down the cluster tree and across each cluster by sign tests and short
  // paths; texel_moments() takes each texel's W from s0 directly. With every texel of a map hot
  // (random radiance), under a random great circle plus a random small triangle (W up to 2), the
  // sum must equal Σ_t L_t · texel_moments(t) to rounding (1e-12 of Σ L_t Ω_t).
  std::mt19937_64 rng(41);
  std::uniform_real_distribution<double> U(-1, 1);
  const Vector3d s0(-1, 0, 0);
  for (const bool cube : {false, true}) {
    const int count = cube ? 12 * 12 * 6 : 48 * 24;
    std::vector<float> rgb(size_t(3 * count));
    for (float& v : rgb) v = float(1 + U(rng));
    const EnvMap env = cube ? EnvMap::from_exr_cube(12, rgb, UpAxis::Y, "random")
                            : EnvMap::from_latlong(48, 24, rgb, UpAxis::Y, "random");
    const Eigen::Matrix3d frame = Eigen::AngleAxisd(0.7236, Vector3d(0.3141, 0.5926, 0.7418).normalized()).toRotationMatrix();
    const HotTexels hot(env, frame, 2, 0.0, size_t(count));
    ASSERT_GT(hot.clusters(), 8u);
    for (int trial = 0; trial < 12; ++trial) {
      const Vector3d n = Vector3d(U(rng), U(rng), U(rng)).normalized();
      std::vector<DcfArc> arcs = great_circle(frame * n);
      int W0 = (frame * n).dot(s0) < 0 ? 1 : 0;
      const Vector3d v0 = Vector3d(U(rng), U(rng), U(rng)).normalized();
      const Vector3d e1 = v0.cross(Vector3d(U(rng), U(rng), U(rng))).normalized(), e2 = v0.cross(e1);
      Vector3d v1 = (v0 + 0.4 * e1).normalized(), v2 = (v0 + 0.3 * e1 + 0.35 * e2).normalized();
      if (v0.cross(v1).dot(v2) < 0) std::swap(v1, v2);
      const Vector3d tri[3] = {frame * v0, frame * v1, frame * v2};
      for (int k = 0; k < 3; ++k) arcs.push_back({tri[k], tri[(k + 1) % 3], tri[k].cross(tri[(k + 1) % 3]), +1});
      // s0 inside the triangle adds 1 (it is not: the triangle spans ~0.4 rad about a random v0;
      // checked by the same sign tests).
      bool inside = true;
      for (int k = 0; k < 3; ++k) inside = inside && tri[k].cross(tri[(k + 1) % 3]).dot(s0) > 0;
      W0 += inside ? 1 : 0;
      std::vector<double> got(hot.width(), 0.0), want(hot.width(), 0.0);
      hot.accumulate(arcs, s0, W0, got.data());
      double scale = 0;
      for (int t = 0; t < count; ++t) {
        const std::vector<double> m = hot.texel_moments(t, arcs, s0, W0);
        const Rgb L = env.texel_value(t);
        const double Lc[3] = {L.r, L.g, L.b};
        for (int c = 0; c < 3; ++c)
          for (size_t i = 0; i < 4; ++i) want[size_t(c) * 4 + i] += Lc[c] * m[i];
        scale += L.r * env.texel_solid_angle(t);
      }
      for (size_t i = 0; i < got.size(); ++i)
        ASSERT_NEAR(got[i], want[i], 1e-12 * scale) << (cube ? "cube" : "lat-long") << " trial " << trial << " i " << i;
    }
  }
}

TEST(HotTexels, GaussLegendreAboveOrderTwelveAgreesWithTheClosedForm) {
  // Order 14 takes the Gauss–Legendre path; its first 144 moments must equal PolygonSH's order 12
  // on the same visible parts to 1e-12 of the texel's solid angle (the rule's bound, header).
  const int S = 16;
  std::vector<int> all;
  for (int t = 0; t < S * S * 6; ++t) all.push_back(t);
  const EnvMap env = lit_cube(S, all, 1);
  const Eigen::Matrix3d frame = Eigen::Matrix3d::Identity();
  const HotTexels gl(env, frame, 14, 0.0, all.size()), closed(env, frame, 12, 0.0, all.size());
  const Vector3d s0(-1, 0, 0);
  for (int t : {0, 100, 700, 1500}) {
    const std::vector<Vector3d> poly = env.texel_polygon(t);
    Vector3d c = Vector3d::Zero();
    for (const Vector3d& v : poly) c += v;
    const Vector3d n = c.normalized().cross(Vector3d(0.3, -0.8, 0.52)).normalized();
    const std::vector<DcfArc> arcs = great_circle(n);
    const int W0 = n.dot(s0) < 0 ? 1 : 0;
    const std::vector<double> a = gl.texel_moments(t, arcs, s0, W0), b = closed.texel_moments(t, arcs, s0, W0);
    for (size_t i = 0; i < 144; ++i) EXPECT_NEAR(a[i], b[i], 1e-12 * env.texel_solid_angle(t)) << t << " " << i;
  }
}

TEST(HotTexels, SunPartlyHiddenByAnEdgeIsExactAtAnyIsolineCount) {
  // One bright texel of a cube map (an exact great-arc quad: a polygon light) behind the straight
  // edge of a large triangle, seen from an unoccluded point with n = +y. The visible part is the
  // texel clipped by the plane through p and the edge; R_c,m = L_c ∫ y_1m over it in closed form.
  // The silhouette integrator must reproduce it at N = 16 and N = 256 alike (no discretisation
  // error is left: 1e-10 of the unclipped texel's integral, rounding), and the QMC integrator
  // within 4.5 of its standard errors.
  const int S = 16;
  const Vector3d sun = Vector3d(0.3, 0.8, 0.5).normalized();
  const EnvMap probe = lit_cube(S, {}, 0);
  const int tx = probe.texel_of(sun);
  const EnvMap env = lit_cube(S, {tx}, 1e5f);
  const std::vector<Vector3d> poly = env.texel_polygon(tx);
  Vector3d c = Vector3d::Zero();
  for (const Vector3d& v : poly) c += v;
  c.normalize();
  // The edge: a line at distance 2 along c, direction u ⊥ c, moved off centre by 0.02 along v;
  // the triangle covers the −v side far past the texel's footprint (~0.2 wide at distance 2).
  const Vector3d u = c.cross(Vector3d(0.2, 0.1, 1.0)).normalized(), v = c.cross(u);
  const Vector3d on_edge = 2 * c + 0.02 * v;
  const Vector3d A = on_edge - 50 * u, B = on_edge + 50 * u, C = on_edge - 50 * v;
  const Mesh mesh = make_mesh({A.cast<float>(), B.cast<float>(), C.cast<float>()}, {{0, 1, 2}}, "edge");
  const Topology topo = build_topology(mesh);
  // The visible side: the plane through p = 0 and the edge line (as stored in float), normal
  // towards +v. Rays towards the triangle's side hit it (it spans the texel's whole cone there).
  const Vector3d Af = mesh.positions[0].cast<double>(), Bf = mesh.positions[1].cast<double>();
  Vector3d nrm = Af.cross(Bf);
  if (nrm.dot(on_edge + v) < 0) nrm = -nrm;
  const std::vector<double> m = clipped_moments(poly, nrm, 2);
  const std::vector<double> full = clipped_moments(poly, c, 2);  // c·ω > 0 over the whole texel
  ASSERT_GT(m[0], 0.2 * full[0]);
  ASSERT_LT(m[0], 0.8 * full[0]);  // a real cut
  const Rgb L = env.texel_value(tx);
  const double Lc[3] = {L.r, L.g, L.b};
  double want[9], norm = 0;
  for (int ch = 0; ch < 3; ++ch)
    for (int k = 0; k < 3; ++k) want[3 * ch + k] = Lc[ch] * m[size_t(1 + k)], norm = std::max(norm, Lc[ch] * full[0]);
  ProductRequest req;
  req.radiance = &env;
  ShadePoint sp;
  sp.n = Vector3d(0, 1, 0);
  for (const int N : {16, 256}) {
    const SilhouetteIntegrator sil(mesh, topo, req, {N, 1});
    ASSERT_NE(sil.description().find("1 hot environment texels"), std::string::npos) << sil.description();
    std::vector<double> R(9);
    sil.integrate(sp, 0, R);
    for (int k = 0; k < 9; ++k) EXPECT_NEAR(R[size_t(k)], want[k], 1e-10 * norm) << "N = " << N << ", value " << k;
  }
  const QmcIntegrator qmc(mesh, topo, req, {4096, 3});
  std::vector<double> R(9), se(9);
  qmc.integrate(sp, 0, R, se);
  for (int k = 0; k < 9; ++k) EXPECT_NEAR(R[size_t(k)], want[k], 4.5 * se[size_t(k)] + 1e-12 * norm) << "qmc value " << k;
}
