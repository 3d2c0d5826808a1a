// Tests for bake/visibility/contour.h: the exact ε-limit orientation predicate and the 4D dual-space BVH
// of contour edges (paper 001 §3.1), checked against brute force on real meshes and against
// hand-worked configurations.
#include <bake/mesh/mesh.h>
#include <bake/mesh/subdivide.h>
#include <bake/visibility/contour.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <vector>

namespace {

namespace fs = std::filesystem;
using Eigen::Vector3d;
using Eigen::Vector3f;
using prt::bake::ContourEdge;
using prt::bake::ContourFinder;
using prt::bake::Mesh;
using prt::bake::orient_eps;
using prt::bake::ShadePoint;
using prt::bake::Topology;

// ------------------------------------------------------------ independent exact reference
// A minimal signed big integer (base 2^32) for det(a−p, b−p, c−p) of arbitrary doubles: every
// input is m·2^e with a 53-bit integer m; all are aligned to the smallest exponent.
struct Big {
  bool neg = false;
  std::vector<uint32_t> mag;  // little endian, no leading zeros
  void trim() {
    while (!mag.empty() && mag.back() == 0) mag.pop_back();
    if (mag.empty()) neg = false;
  }
  int sign() const { return mag.empty() ? 0 : (neg ? -1 : 1); }
};
int cmp_mag(const Big& a, const Big& b) {
  if (a.mag.size() != b.mag.size()) return a.mag.size() < b.mag.size() ? -1 : 1;
  for (size_t i = a.mag.size(); i-- > 0;)
    if (a.mag[i] != b.mag[i]) return a.mag[i] < b.mag[i] ? -1 : 1;
  return 0;
}
Big add(const Big& a, const Big& b) {
  Big r;
  if (a.neg == b.neg) {
    r.neg = a.neg;
    uint64_t carry = 0;
    for (size_t i = 0; i < std::max(a.mag.size(), b.mag.size()) || carry; ++i) {
      const uint64_t s = carry + (i < a.mag.size() ? a.mag[i] : 0) + (i < b.mag.size() ? b.mag[i] : 0);
      r.mag.push_back(uint32_t(s));
      carry = s >> 32;
    }
  } else {
    const bool a_big = cmp_mag(a, b) >= 0;
    const Big& x = a_big ? a : b;
    const Big& y = a_big ? b : a;
    r.neg = x.neg;
    int64_t borrow = 0;
    for (size_t i = 0; i < x.mag.size(); ++i) {
      int64_t d = int64_t(x.mag[i]) - borrow - (i < y.mag.size() ? int64_t(y.mag[i]) : 0);
      borrow = d < 0;
      if (d < 0) d += int64_t(1) << 32;
      r.mag.push_back(uint32_t(d));
    }
  }
  r.trim();
  return r;
}
Big neg(Big a) {
  a.neg = !a.neg;
  a.trim();
  return a;
}
Big mul(const Big& a, const Big& b) {
  Big r;
  r.mag.assign(a.mag.size() + b.mag.size() + 1, 0);
  for (size_t i = 0; i < a.mag.size(); ++i) {
    uint64_t carry = 0;
    for (size_t j = 0; j < b.mag.size() || carry; ++j) {
      const uint64_t cur = r.mag[i + j] + carry + (j < b.mag.size() ? uint64_t(a.mag[i]) * b.mag[j] : 0);
      r.mag[i + j] = uint32_t(cur);
      carry = cur >> 32;
    }
  }
  r.neg = a.neg != b.neg;
  r.trim();
  return r;
}
Big from_scaled(double x, int emin) {  // x / 2^emin, an integer by construction
  Big r;
  if (x == 0) return r;
  int e = 0;
  const double m = std::frexp(std::abs(x), &e);  // |x| = m·2^e, m in [0.5, 1)
  uint64_t mi = uint64_t(std::ldexp(m, 53));
  int shift = e - 53 - emin;  // ≥ 0
  r.mag = {uint32_t(mi), uint32_t(mi >> 32)};
  Big two;
  two.mag = {2};
  while (shift >= 16) {
    Big s;
    s.mag = {1u << 16};
    r = mul(r, s);
    shift -= 16;
  }
  for (; shift > 0; --shift) r = mul(r, two);
  r.neg = x < 0;
  r.trim();
  return r;
}
int exact_det_sign(const Vector3d& a, const Vector3d& b, const Vector3d& c, const Vector3d& p) {
  int emin = 100000;
  for (const Vector3d* v : {&a, &b, &c, &p})
    for (int i = 0; i < 3; ++i)
      if ((*v)[i] != 0) {
        int e = 0;
        std::frexp((*v)[i], &e);
        emin = std::min(emin, e - 53);
      }
  if (emin == 100000) return 0;
  auto d = [&](const Vector3d& u, int i) { return add(from_scaled(u[i], emin), neg(from_scaled(p[i], emin))); };
  const Big ax = d(a, 0), ay = d(a, 1), az = d(a, 2), bx = d(b, 0), by = d(b, 1), bz = d(b, 2);
  const Big cx = d(c, 0), cy = d(c, 1), cz = d(c, 2);
  const Big mx = add(mul(by, cz), neg(mul(bz, cy)));
  const Big my = add(mul(bz, cx), neg(mul(bx, cz)));
  const Big mz = add(mul(bx, cy), neg(mul(by, cx)));
  return add(add(mul(ax, mx), mul(ay, my)), mul(az, mz)).sign();
}
double naive_det(const Vector3d& a, const Vector3d& b, const Vector3d& c, const Vector3d& p) {
  const Vector3d A = a - p, B = b - p, C = c - p;
  return A.dot(B.cross(C));
}
int sgn(double x) { return (x > 0) - (x < 0); }

// ------------------------------------------------------------ orient_eps

TEST(OrientEps, GenericSignsMatchNaiveDouble) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> U(-1, 1);
  int checked = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vector3d a(U(rng), U(rng), U(rng)), b(U(rng), U(rng), U(rng)), c(U(rng), U(rng), U(rng)),
        p(U(rng), U(rng), U(rng));
    const Vector3d n = Vector3d(U(rng), U(rng), U(rng)).normalized();
    const double d = naive_det(a, b, c, p);
    if (std::abs(d) < 1e-10) continue;
    EXPECT_EQ(orient_eps(a, b, c, p, n), sgn(d));
    EXPECT_EQ(prt::bake::orient3d_exact(a, b, c, p), sgn(d));
    EXPECT_EQ(exact_det_sign(a, b, c, p), sgn(d));  // the reference agrees too
    ++checked;
  }
  EXPECT_GT(checked, 19000);
}

TEST(OrientEps, ExactDegenerateFallsToTheEpsilonDerivative) {
  const Vector3d a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  const Vector3d p(0.3, 0.2, 0);  // on the plane of a, b, c
  // D0 = 0; D1 = −n·((b−a)×(c−a)) = −n·(0,0,1).
  EXPECT_EQ(orient_eps(a, b, c, p, Vector3d(0, 0, 1)), -1);
  EXPECT_EQ(orient_eps(a, b, c, p, Vector3d(0, 0, -1)), 1);
  EXPECT_EQ(orient_eps(a, b, c, p, Vector3d(0, 0.6, 0.8)), -1);
  // n in the plane too: 0.
  EXPECT_EQ(orient_eps(a, b, c, p, Vector3d(1, 0, 0)), 0);
  EXPECT_EQ(orient_eps(a, b, c, p, Vector3d(0.6, 0.8, 0)), 0);
  // p at a corner (the shade point's own 1-ring): A = 0.
  EXPECT_EQ(orient_eps(a, b, c, a, Vector3d(0, 0, 1)), -1);
  EXPECT_EQ(orient_eps(a, b, c, b, Vector3d(0, 0, -1)), 1);
  // Tilted plane with inexact coordinates: x + y + z = 3 through float-exact points, p on it.
  const Vector3d ta(1, 1, 1), tb(3, 0, 0), tc(0, 0.5, 2.5), tp(0.25, 1.5, 1.25);
  EXPECT_EQ(naive_det(ta, tb, tc, tp), 0.0);  // (exact here; the filter must also say 0)
  const Vector3d N = (tb - ta).cross(tc - ta);
  EXPECT_EQ(orient_eps(ta, tb, tc, tp, Vector3d(1, 1, 1).normalized()), -sgn(N.dot(Vector3d(1, 1, 1))));
  EXPECT_EQ(orient_eps(ta, tb, tc, tp, Vector3d(1, -1, 0).normalized()), 0);
  // Collinear a, b, c: D0 = D1 = 0 for any p on the line, and D1 = 0 everywhere.
  EXPECT_EQ(orient_eps(a, b, Vector3d(2, 0, 0), Vector3d(5, 0, 0), Vector3d(0, 0, 1)), 0);
  EXPECT_EQ(orient_eps(a, b, Vector3d(2, 0, 0), Vector3d(5, 1, 0), Vector3d(0, 0, 1)), 0);
}

// Large offsets, tiny differences: near-collinear a, b, c and p near their line, every coordinate
// ≈ 1e5 + a few ulps. Naive double gets signs wrong; orient_eps must agree with big integers.
TEST(OrientEps, NearDegenerateMatchesExactReferenceWhereNaiveFails) {
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<int> K(-40, 40);
  std::uniform_real_distribution<double> U(0, 1);
  int naive_wrong = 0, naive_wrong_nonzero = 0, zero = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vector3d base(1e5 + U(rng), 1e5 + U(rng), 1e5 + U(rng));
    const Vector3d dir = Vector3d(U(rng), U(rng), U(rng)).normalized() * (i % 2 ? 1e-3 : 1.0);
    auto jitter = [&](Vector3d v) {
      for (int k = 0; k < 3; ++k) v[k] = v[k] + K(rng) * std::ldexp(1.0, -36);  // ulp(1e5) = 2^-36
      return v;
    };
    const Vector3d a = jitter(base), b = jitter(base + dir), c = jitter(base + 2.7 * dir),
                   p = jitter(base + 0.6 * dir);
    const Vector3d n = Vector3d(U(rng) - 0.5, U(rng) - 0.5, U(rng) - 0.5).normalized();
    const int ref = exact_det_sign(a, b, c, p);
    ASSERT_EQ(prt::bake::orient3d_exact(a, b, c, p), ref) << i;
    const int s = orient_eps(a, b, c, p, n);
    if (ref != 0) {
      ASSERT_EQ(s, ref) << i;
    } else {
      ++zero;
      // D0 = 0: the result is the sign of D1 = −n·((b−a)×(c−a)), odd in n.
      EXPECT_EQ(s, -orient_eps(a, b, c, p, -n)) << i;
    }
    const int naive = sgn(naive_det(a, b, c, p));
    if (naive != ref) {
      ++naive_wrong;
      if (ref != 0 && naive != 0) ++naive_wrong_nonzero;
    }
  }
  std::printf("near-degenerate: naive double wrong in %d / 20000 (%d with the opposite non-zero sign), "
              "%d exact zeros\n",
              naive_wrong, naive_wrong_nonzero, zero);
  EXPECT_GT(naive_wrong_nonzero, 0);  // the construction really is hostile
}

TEST(OrientEps, ExactZeroWhereNaiveIsNonZero) {
  // p = midpoint of a and b (exact): A = −B, so det = 0 exactly; naive double often is not 0.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> U(-1, 1);
  int naive_nonzero = 0;
  for (int i = 0; i < 2000; ++i) {
    const Vector3d a(1e5 + U(rng), -3e4 + U(rng), 7e4 + U(rng));
    const Vector3d b = a + Vector3d(U(rng), U(rng), U(rng));
    const Vector3d p = 0.5 * (a + b);
    if (2 * p != a + b || exact_det_sign(a, b, Vector3d(1, 2, 3), p) != 0) continue;
    const Vector3d c(1e5 + U(rng), -3e4 + U(rng), 7e4 + U(rng));
    ASSERT_EQ(exact_det_sign(a, b, c, p), 0);
    EXPECT_EQ(prt::bake::orient3d_exact(a, b, c, p), 0);
    naive_nonzero += naive_det(a, b, c, p) != 0;
    const Vector3d n(0, 0, 1);
    const int d1 = -sgn(((b - a).cross(c - a)).z());  // well conditioned here
    EXPECT_EQ(orient_eps(a, b, c, p, n), d1);
  }
  std::printf("midpoint zeros: naive double non-zero in %d / 2000\n", naive_nonzero);
  EXPECT_GT(naive_nonzero, 0);
}

TEST(OrientEps, TranslationInvariantForFloatExactTranslations) {
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<int> G(-4, 4);  // coarse grid: many exactly degenerate cases
  std::uniform_int_distribution<int> T(-1000, 1000);
  auto pt = [&] { return Vector3d(G(rng) * 0.25, G(rng) * 0.25, G(rng) * 0.25); };
  int degenerate = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vector3d a = pt(), b = pt(), c = pt(), p = (i % 3 == 0) ? a : pt();
    const Vector3d n = Vector3d(G(rng), G(rng), G(rng) + 0.5).normalized();
    const Vector3d t(T(rng) * 1024.0, T(rng) * 0.5, T(rng) * 64.0);  // a + t exact in float
    const int s = orient_eps(a, b, c, p, n);
    EXPECT_EQ(orient_eps(a + t, b + t, c + t, p + t, n), s);
    degenerate += naive_det(a, b, c, p) == 0;
  }
  EXPECT_GT(degenerate, 1000);
}

// ------------------------------------------------------------ finder vs brute force

struct Scene {
  Mesh mesh;
  Topology topo;
};
Scene load(const std::string& name) {
  Scene s{prt::bake::load_mesh(fs::path(PRT_DATA_DIR) / name), {}};
  s.topo = prt::bake::build_topology(s.mesh);
  return s;
}
Scene transformed(const Mesh& m, double scale, double offset) {
  std::vector<Vector3f> pos;
  for (const auto& v : m.positions)
    pos.push_back((v.cast<double>() * scale + Vector3d::Constant(offset)).cast<float>());
  Scene s{prt::bake::make_mesh(pos, m.triangles, "transformed", m.normals), {}};
  s.topo = prt::bake::build_topology(s.mesh);
  return s;
}

std::vector<ShadePoint> sample_points(const Mesh& mesh, int count, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0, 1);
  Eigen::Vector3d lo = mesh.positions[0].cast<double>(), hi = lo;
  for (const auto& v : mesh.positions) {
    lo = lo.cwiseMin(v.cast<double>());
    hi = hi.cwiseMax(v.cast<double>());
  }
  const double size = (hi - lo).norm();
  auto unit = [&] {
    for (;;) {
      const Vector3d d(2 * U(rng) - 1, 2 * U(rng) - 1, 2 * U(rng) - 1);
      if (d.norm() > 0.1 && d.norm() <= 1) return Vector3d(d.normalized());
    }
  };
  std::vector<ShadePoint> pts;
  for (int i = 0; i < count; ++i) {
    ShadePoint sp;
    const size_t v = std::min(mesh.positions.size() - 1, size_t(U(rng) * double(mesh.positions.size())));
    switch (i % 5) {
      case 0:
      case 1:  // a vertex with its normal: the ε-limit cases
        sp.p = mesh.positions[v].cast<double>();
        sp.n = mesh.normals[v].cast<double>().normalized();
        break;
      case 2:  // off the surface
        sp.p = mesh.positions[v].cast<double>() + mesh.normals[v].cast<double>() * (U(rng) - 0.3) * 0.05 * size;
        sp.n = unit();
        break;
      case 3:  // inside the bounding box
        sp.p = lo + Vector3d(U(rng), U(rng), U(rng)).cwiseProduct(hi - lo);
        sp.n = unit();
        break;
      default:  // far away
        sp.p = 0.5 * (lo + hi) + unit() * size * (3 + 30 * U(rng));
        sp.n = unit();
        break;
    }
    sp.hemisphere = (i % 7) != 0;
    pts.push_back(sp);
  }
  return pts;
}

void expect_equal_to_brute_force(const Scene& s, int count, uint64_t seed, const char* what) {
  const ContourFinder finder(s.mesh, s.topo);
  const auto& st = finder.stats();
  std::printf("%s: %zu edges, %zu in the BVH (%zu nodes, depth %zu), %zu always tested, eta %.3g\n", what, st.edges,
              st.bvh_edges, st.bvh_nodes, st.bvh_depth, st.always_tested, st.normal_error);
  std::vector<ContourEdge> fast, slow;
  size_t total = 0;
  for (const auto& sp : sample_points(s.mesh, count, seed)) {
    finder.find(sp, fast);
    finder.find_brute_force(sp, slow);
    ASSERT_EQ(fast, slow) << what << " at (" << sp.p.transpose() << ") n (" << sp.n.transpose() << ")";
    total += slow.size();
  }
  EXPECT_GT(total, 0u);
}

TEST(ContourFinder, MatchesBruteForceOnBunny) { expect_equal_to_brute_force(load("bunny.obj"), 200, 1, "bunny"); }
TEST(ContourFinder, MatchesBruteForceOnSpider) { expect_equal_to_brute_force(load("spider.obj"), 200, 2, "spider"); }
TEST(ContourFinder, MatchesBruteForceOnWuson) { expect_equal_to_brute_force(load("wuson.obj"), 200, 3, "wuson"); }
TEST(ContourFinder, MatchesBruteForceOnBunnyTranslated1e5) {
  const Scene b = load("bunny.obj");
  expect_equal_to_brute_force(transformed(b.mesh, 1, 1e5), 200, 4, "bunny+1e5");
}
TEST(ContourFinder, MatchesBruteForceOnBunnyScaled1e4) {
  const Scene b = load("bunny.obj");
  expect_equal_to_brute_force(transformed(b.mesh, 1e-4, 0), 200, 5, "bunny*1e-4");
  expect_equal_to_brute_force(transformed(b.mesh, 1e-4, 1e3), 200, 6, "bunny*1e-4+1e3");
}

// Points the sampler above does not make, each compared with the brute force: on an edge
// (midpoint and a point ¼ along it), on a face (centroid) and at a corner, with the face's
// normal, the reversed normal and a random unit normal; and points so far away that the
// finder's float bounds cannot hold their coordinates (it must then still be exact).
void expect_equal_on_edges_faces_and_extremes(const Scene& s, int count, uint64_t seed, const char* what) {
  const ContourFinder finder(s.mesh, s.topo);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0, 1);
  const auto& wp = s.topo.welded_positions;
  std::vector<ContourEdge> fast, slow;
  auto check = [&](const Vector3d& p, const Vector3d& n) {
    ShadePoint sp;
    sp.p = p;
    sp.n = n;
    finder.find(sp, fast);
    finder.find_brute_force(sp, slow);
    ASSERT_EQ(fast, slow) << what << " at (" << p.transpose() << ") n (" << n.transpose() << ")";
  };
  for (int i = 0; i < count; ++i) {
    const auto& t = s.mesh.triangles[size_t(U(rng) * double(s.mesh.triangles.size())) % s.mesh.triangles.size()];
    const Vector3d a = s.mesh.positions[t[0]].cast<double>(), b = s.mesh.positions[t[1]].cast<double>(),
                   c = s.mesh.positions[t[2]].cast<double>();
    Vector3d fn = (b - a).cross(c - a);
    fn = fn.norm() > 0 ? Vector3d(fn.normalized()) : Vector3d(0, 0, 1);
    Vector3d rn(2 * U(rng) - 1, 2 * U(rng) - 1, 2 * U(rng) - 1);
    rn = rn.norm() > 1e-3 ? Vector3d(rn.normalized()) : Vector3d(1, 0, 0);
    for (const Vector3d& p : {Vector3d(0.5 * (a + b)), Vector3d(a + 0.25 * (b - a)), Vector3d((a + b + c) / 3.0), a})
      for (const Vector3d& n : {fn, Vector3d(-fn), rn}) check(p, n);
  }
  const Vector3d centre = wp.empty() ? Vector3d(Vector3d::Zero()) : Vector3d(wp[0].cast<double>());
  for (const double far : {1e20, 1e36, 1e300}) check(centre + Vector3d(far, -0.5 * far, 0.25 * far), Vector3d(0, 1, 0));
}

TEST(ContourFinder, MatchesBruteForceOnEdgesFacesAndFarPoints) {
  expect_equal_on_edges_faces_and_extremes(load("bunny_ground.obj"), 60, 11, "bunny_ground");
  const Scene b = load("bunny.obj");
  expect_equal_on_edges_faces_and_extremes(transformed(b.mesh, 1, 1e5), 40, 12, "bunny+1e5");
  expect_equal_on_edges_faces_and_extremes(transformed(b.mesh, 1e-4, 1e3), 40, 13, "bunny*1e-4+1e3");
}

// Most edges always tested (their faces' σ from a float filter, orient_eps where it cannot
// decide): the bunny with every third face removed (boundary edges), every fifth face doubled as a
// flap on its first edge (3-face edges) and slivers (ill-conditioned faces: zero records, always
// orient_eps), at vertices, on edges and faces (σ = 0 exactly), far away, and translated by 1e5.
Scene riddled(const Mesh& m) {
  std::vector<Vector3f> pos = m.positions;
  std::vector<std::array<uint32_t, 3>> tris;
  for (size_t f = 0; f < m.triangles.size(); ++f) {
    const auto& t = m.triangles[f];
    if (f % 3 == 1) continue;
    tris.push_back(t);
    if (f % 5 == 0) {  // a flap on edge (t0, t1), its apex off the face
      const Vector3f a = pos[t[0]], b = pos[t[1]], c = pos[t[2]];
      pos.push_back(0.5f * (a + b) + 0.7f * ((b - a).cross(c - a)).normalized() * (b - a).norm());
      tris.push_back({t[0], t[1], uint32_t(pos.size() - 1)});
    }
    if (f % 11 == 0) {  // a sliver on edge (t1, t2): its apex 1e-4 of the way from t1 to t2
      pos.push_back(pos[t[1]] + 1e-4f * (pos[t[2]] - pos[t[1]]));
      tris.push_back({t[1], t[2], uint32_t(pos.size() - 1)});
    }
  }
  Scene s{prt::bake::make_mesh(pos, tris, "riddled"), {}};
  s.topo = prt::bake::build_topology(s.mesh);
  return s;
}
TEST(ContourFinder, MatchesBruteForceWhereMostEdgesAreAlwaysTested) {
  const Scene b = load("bunny.obj");
  const Scene r = riddled(b.mesh);
  {
    const ContourFinder finder(r.mesh, r.topo);
    EXPECT_GT(finder.stats().always_tested, finder.stats().edges / 3);
  }
  expect_equal_to_brute_force(r, 150, 21, "riddled bunny");
  expect_equal_on_edges_faces_and_extremes(r, 40, 22, "riddled bunny");
  const Scene t = riddled(transformed(b.mesh, 1, 1e5).mesh);
  expect_equal_to_brute_force(t, 60, 23, "riddled bunny+1e5");
  expect_equal_on_edges_faces_and_extremes(t, 20, 24, "riddled bunny+1e5");
}

// A finer mesh (a deeper tree, smaller nodes near the shade point) and the ground's coplanar
// grid: vertex, off-surface, inside and far points, then edges and faces.
TEST(ContourFinder, MatchesBruteForceOnSubdividedBunnyOnGround) {
  Scene s{prt::bake::loop_subdivide(prt::bake::load_mesh(fs::path(PRT_DATA_DIR) / "bunny_ground.obj"), 1), {}};
  s.topo = prt::bake::build_topology(s.mesh);
  expect_equal_to_brute_force(s, 60, 14, "bunny_ground (loop x1)");
  expect_equal_on_edges_faces_and_extremes(s, 15, 15, "bunny_ground (loop x1)");
}

// The scene with the winding of each face i for which flip(i) reversed.
template <class Flip>
Scene rewound(const Scene& s, Flip flip, const char* name) {
  std::vector<std::array<uint32_t, 3>> tris = s.mesh.triangles;
  for (size_t i = 0; i < tris.size(); ++i)
    if (flip(i)) std::swap(tris[i][1], tris[i][2]);
  Scene r{prt::bake::make_mesh(s.mesh.positions, tris, name, s.mesh.normals), {}};
  r.topo = prt::bake::build_topology(r.mesh);
  return r;
}

// find() gives the same contour sets on both scenes (the same positions, other windings).
void expect_same_contours(const Scene& a, const Scene& b, int count, uint64_t seed) {
  const ContourFinder fa(a.mesh, a.topo), fb(b.mesh, b.topo);
  std::vector<ContourEdge> x, y;
  for (const auto& sp : sample_points(a.mesh, count, seed)) {
    fa.find(sp, x);
    fb.find(sp, y);
    EXPECT_EQ(x, y);
  }
}

// The finder stores each edge's record oriented by its face 1's winding, so the tree changes
// with the windings while the contour sets must not: the bunny with every face's winding chosen
// at random (seeded), near and far from the origin, against the brute force and against the
// bunny as wound in the file; then a soup of random triangles over a small vertex pool
// (inconsistent windings, edges with 1, 2 and 3+ faces, a duplicated position making repeated
// welded corners, slivers), near and far from the origin.
TEST(ContourFinder, MatchesBruteForceWithRandomWindings) {
  const Scene b = load("bunny.obj");
  std::mt19937_64 rng(16);
  const Scene r = rewound(b, [&rng](size_t) { return (rng() & 1) != 0; }, "random windings");
  ASSERT_EQ(r.topo.edges, b.topo.edges);
  expect_equal_to_brute_force(r, 100, 17, "bunny, random windings");
  expect_equal_to_brute_force(transformed(r.mesh, 1, 1e5), 100, 18, "bunny, random windings, +1e5");
  expect_equal_on_edges_faces_and_extremes(r, 20, 19, "bunny, random windings");
  expect_same_contours(b, r, 60, 20);

  std::uniform_real_distribution<float> U(-1, 1);
  std::vector<Vector3f> pool;
  for (int i = 0; i < 40; ++i) pool.push_back({U(rng), U(rng), U(rng)});
  pool.push_back(pool[0]);                                             // welds with vertex 0
  pool.push_back(0.5f * (pool[1] + pool[2]) + Vector3f(1e-7f, 0, 0));  // nearly on the edge 1–2
  std::vector<std::array<uint32_t, 3>> soup = {{0, 40, 3}, {1, 2, 41}, {2, 1, 41}};
  for (int i = 0; i < 300; ++i)
    soup.push_back({uint32_t(rng() % pool.size()), uint32_t(rng() % pool.size()), uint32_t(rng() % pool.size())});
  Scene s{prt::bake::make_mesh(pool, soup, "soup"), {}};
  s.topo = prt::bake::build_topology(s.mesh);
  expect_equal_on_edges_faces_and_extremes(s, 60, 21, "soup");
  expect_equal_on_edges_faces_and_extremes(transformed(s.mesh, 1, 1e5), 60, 22, "soup+1e5");
}

// ------------------------------------------------------------ known cases

Scene make(std::vector<Vector3f> pos, std::vector<std::array<uint32_t, 3>> tris) {
  Scene s{prt::bake::make_mesh(std::move(pos), std::move(tris), "test"), {}};
  s.topo = prt::bake::build_topology(s.mesh);
  return s;
}
std::vector<ContourEdge> contours(const Scene& s, Vector3d p, Vector3d n) {
  const ContourFinder f(s.mesh, s.topo);
  ShadePoint sp;
  sp.p = p;
  sp.n = n.normalized();
  std::vector<ContourEdge> out, ref;
  f.find(sp, out);
  f.find_brute_force(sp, ref);
  EXPECT_EQ(out, ref);
  return out;
}
int side_sum(const std::vector<ContourEdge>& c, const Topology& t, uint32_t a, uint32_t b) {
  const auto e = t.find_edge(a, b);
  EXPECT_TRUE(e.has_value());
  for (const auto& x : c)
    if (e && x.edge == *e) return x.side_sum;
  return 0;
}

Scene cube() {
  std::vector<Vector3f> v;
  for (int i = 0; i < 8; ++i) v.emplace_back(i & 1 ? 1.f : -1.f, i & 2 ? 1.f : -1.f, i & 4 ? 1.f : -1.f);
  // Outward-wound quads split into triangles.
  const int q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  std::vector<std::array<uint32_t, 3>> t;
  for (const auto& f : q) {
    t.push_back({uint32_t(f[0]), uint32_t(f[1]), uint32_t(f[2])});
    t.push_back({uint32_t(f[0]), uint32_t(f[2]), uint32_t(f[3])});
  }
  return make(v, t);
}

TEST(ContourKnown, CubeFromOutsideHasTheSixSilhouetteEdges) {
  const Scene s = cube();
  const auto c = contours(s, Vector3d(3, 2.5, 4), Vector3d(0, 0, 1));
  ASSERT_EQ(c.size(), 6u);
  for (const auto& x : c) {
    EXPECT_EQ(std::abs(x.side_sum), 2);
    // A silhouette edge of the hexagon: between a visible face (+x, +y, +z) and a hidden one.
    const auto [a, b] = s.topo.edges[x.edge];
    const Vector3f d = s.topo.welded_positions[b] - s.topo.welded_positions[a];
    EXPECT_EQ(d.cwiseAbs().sum(), 2.f);  // an axis edge of the cube, not a diagonal
  }
  // Straight above the top face: the silhouette is the square of the top face.
  EXPECT_EQ(contours(s, Vector3d(0.2, 0.1, 5), Vector3d(0, 0, 1)).size(), 4u);
}

TEST(ContourKnown, CubeFromInsideHasNone) {
  const Scene s = cube();
  EXPECT_TRUE(contours(s, Vector3d(0.1, 0.2, -0.3), Vector3d(0, 0, 1)).empty());
  EXPECT_TRUE(contours(s, Vector3d(-0.7, 0.4, 0.9), Vector3d(1, 1, 0)).empty());
}

TEST(ContourKnown, SingleTriangleHasThreeBoundaryEdges) {
  const Scene s = make({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}});
  for (const Vector3d& p : {Vector3d(0.2, 0.2, 1), Vector3d(5, -3, -2)}) {
    const auto c = contours(s, p, Vector3d(0, 0, 1));
    ASSERT_EQ(c.size(), 3u);
    for (const auto& x : c) EXPECT_EQ(std::abs(x.side_sum), 1);
  }
}

// V-groove along x: z = |y| on the 3×3 grid x, y ∈ {−1, 0, 1}, vertex id 3(y+1) + (x+1), so
// the crease is 3 – 4 – 5 and the shade point is vertex 4 = O = (0, 0, 0).
// Crease spoke (3, 4): a = (−1,0,0), b = O = p, so D0 = 0 and σ = sign D1 = −sign(n·N),
// N = (b−a)×(c−a) = (1,0,0)×(c_x+1, c_y, 1) = (0, −1, c_y): the face on the y > 0 wall has
// N = (0,−1,1), the y < 0 one N = (0,−1,−1). Spoke (4, 5): a = O = p, b = (1,0,0),
// N = (1,0,0)×c = (0, −1, c_y) too. So for n = (0, s, c):
//   y > 0 face: σ = −(c − s) = s − c;  y < 0 face: σ = sign(s + c).
//  * n = +z (s = 0, c = 1): σ = −1 and +1, S = 0: from just above the crease, the two walls lie
//    on opposite sides of the viewing plane y = 0. No contour at the crease.
//  * n tilted 60° towards +y (s = √3/2, c = ½): s − c > 0, s + c > 0, S = +2 on both crease
//    spokes: p + εn is behind the y > 0 wall, both walls are on the same side.
// Spokes inside a wall (4–1, 4–7, and the wall diagonals) have both faces in one plane through
// p: D1 = −n·N with opposite N for the two faces, S = 0 unless n lies in the wall (then 0 + 0).
TEST(ContourKnown, VGrooveCreaseFollowsTheEpsilonRule) {
  std::vector<Vector3f> v;
  for (int y = -1; y <= 1; ++y)
    for (int x = -1; x <= 1; ++x) v.emplace_back(float(x), float(y), float(std::abs(y)));
  std::vector<std::array<uint32_t, 3>> t;
  for (uint32_t y = 0; y < 2; ++y)
    for (uint32_t x = 0; x < 2; ++x) {
      const uint32_t i = 3 * y + x;
      t.push_back({i, i + 1, i + 4});
      t.push_back({i, i + 4, i + 3});
    }
  const Scene s = make(v, t);
  const Vector3d O(0, 0, 0);
  auto spokes = [&](const std::vector<ContourEdge>& c) {
    std::vector<int> r;
    for (uint32_t w : {0u, 1u, 2u, 3u, 5u, 6u, 7u, 8u})
      if (s.topo.find_edge(4, w)) r.push_back(side_sum(c, s.topo, 4, w));
    return r;
  };
  const auto up = contours(s, O, Vector3d(0, 0, 1));
  for (int x : spokes(up)) EXPECT_EQ(x, 0);
  const auto tilted = contours(s, O, Vector3d(0, std::sqrt(3.0) / 2, 0.5));
  EXPECT_EQ(side_sum(tilted, s.topo, 3, 4), 2);
  EXPECT_EQ(side_sum(tilted, s.topo, 4, 5), 2);
  int nonzero = 0;
  for (int x : spokes(tilted)) nonzero += x != 0;
  EXPECT_EQ(nonzero, 2);
  // Tilted the other way the roles swap: y < 0 face σ = sign(−s + c)... with s = −√3/2:
  // y > 0: σ = s − c < 0, y < 0: σ = sign(s + c) < 0, S = −2.
  const auto tilted2 = contours(s, O, Vector3d(0, -std::sqrt(3.0) / 2, 0.5));
  EXPECT_EQ(side_sum(tilted2, s.topo, 3, 4), -2);
  EXPECT_EQ(side_sum(tilted2, s.topo, 4, 5), -2);
}

TEST(ContourKnown, GroundGridOnlyBoundaryEdges) {
  const int n = 9;
  std::vector<Vector3f> v;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) v.emplace_back(float(x) * 0.1f, float(y) * 0.1f, 0.f);
  std::vector<std::array<uint32_t, 3>> t;
  for (uint32_t y = 0; y + 1 < uint32_t(n); ++y)
    for (uint32_t x = 0; x + 1 < uint32_t(n); ++x) {
      const uint32_t i = uint32_t(n) * y + x;
      if ((x + y) % 2) {  // mixed winding and diagonals on purpose
        t.push_back({i, i + 1, i + uint32_t(n) + 1});
        t.push_back({i, i + uint32_t(n), i + uint32_t(n) + 1});
      } else {
        t.push_back({i, i + 1, i + uint32_t(n)});
        t.push_back({i + 1, i + uint32_t(n) + 1, i + uint32_t(n)});
      }
    }
  const Scene s = make(v, t);
  for (const uint32_t centre : {40u, 30u, 10u}) {
    const auto c = contours(s, s.mesh.positions[centre].cast<double>(), Vector3d(0, 0, 1));
    ASSERT_EQ(c.size(), size_t(4 * (n - 1)));
    for (const auto& x : c) {
      EXPECT_EQ(std::abs(x.side_sum), 1);
      EXPECT_EQ(s.topo.faces_of_edge(x.edge).size(), 1u);
    }
  }
  // A free point on the plane, off the vertices, gives the same.
  EXPECT_EQ(contours(s, Vector3d(0.33, 0.41, 0), Vector3d(0, 0, 1)).size(), size_t(4 * (n - 1)));
}

TEST(ContourKnown, RewindingHalfTheFacesChangesNothing) {
  const Scene s = load("bunny.obj");
  const Scene r = rewound(s, [](size_t i) { return i % 2 == 0; }, "rewound");
  ASSERT_EQ(r.topo.edges, s.topo.edges);
  expect_same_contours(s, r, 60, 9);
}

// Three pages on the edge (0,0,0)–(1,0,0), corners c = (0.5, cos φ, sin φ).
// N = (b−a)×(c−a) = (0, −c_z, c_y), σ = −sign(N·(p−a)) = sign(c_z p_y − c_y p_z).
TEST(ContourKnown, BookOfThreePages) {
  auto book = [](std::initializer_list<double> degrees) {
    std::vector<Vector3f> v = {{0, 0, 0}, {1, 0, 0}};
    std::vector<std::array<uint32_t, 3>> t;
    for (double d : degrees) {
      const double r = d * M_PI / 180;
      v.emplace_back(0.5f, float(std::cos(r)), float(std::sin(r)));
      t.push_back({0, 1, uint32_t(v.size() - 1)});
    }
    return make(v, t);
  };
  {  // p = (0.5, 0, −5): σ = sign(5 c_y) = sign(cos φ): +1 +1 −1 → S = 1
    const Scene s = book({30, 60, 150});
    EXPECT_EQ(side_sum(contours(s, Vector3d(0.5, 0, -5), Vector3d(0, 0, 1)), s.topo, 0, 1), 1);
  }
  {  // all three on one side: S = 3; from the other side: −3
    const Scene s = book({30, 60, 80});
    EXPECT_EQ(side_sum(contours(s, Vector3d(0.5, 0, -5), Vector3d(0, 0, 1)), s.topo, 0, 1), 3);
    EXPECT_EQ(side_sum(contours(s, Vector3d(0.5, 0, 5), Vector3d(0, 0, 1)), s.topo, 0, 1), -3);
  }
  {  // evenly spread pages seen from p = (0.5, 0, 5): σ = sign(−5 c_y): −, +, + → S = 1
    const Scene s = book({0, 120, 240});
    EXPECT_EQ(side_sum(contours(s, Vector3d(0.5, 0, 5), Vector3d(0, 0, 1)), s.topo, 0, 1), 1);
  }
}

// ------------------------------------------------------------ timing (reported, not asserted)

TEST(ContourTiming, Bunny) {
  const Scene s = load("bunny.obj");
  const auto t0 = std::chrono::steady_clock::now();
  const ContourFinder finder(s.mesh, s.topo);
  const double build = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // Integrator-like points: every vertex with its normal.
  std::vector<ShadePoint> pts;
  for (size_t v = 0; v < s.mesh.positions.size(); ++v) {
    ShadePoint sp;
    sp.p = s.mesh.positions[v].cast<double>();
    sp.n = s.mesh.normals[v].cast<double>().normalized();
    pts.push_back(sp);
  }
  std::vector<ContourEdge> out;
  size_t found = 0;
  const int reps = 5;
  auto t1 = std::chrono::steady_clock::now();
  for (int r = 0; r < reps; ++r)
    for (const auto& sp : pts) {
      finder.find(sp, out);
      found += out.size();
    }
  const double fast = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count() /
                      double(reps * pts.size());
  t1 = std::chrono::steady_clock::now();
  for (const auto& sp : pts) finder.find_brute_force(sp, out);
  const double slow = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count() / double(pts.size());
  std::printf("bunny: %zu edges, BVH %zu nodes built in %.2f ms; mean %.1f contour edges per vertex (%.2f%%)\n",
              finder.edge_count(), finder.bvh_node_count(), build * 1e3, double(found) / double(reps * pts.size()),
              100.0 * double(found) / double(reps * pts.size()) / double(finder.edge_count()));
  std::printf("bunny: find %.2f us/query, brute force %.2f us/query, speed-up %.1fx\n", fast * 1e6, slow * 1e6,
              slow / fast);
}

}  // namespace
