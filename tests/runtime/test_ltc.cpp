// prtshade/ltc.h: the polygon integral of a transformed cosine equals the numerical integral of
// its density (any M, polygons crossing the cosine space's horizon, holes, arcs in any order);
// M = identity is Lambert's form factor; and the fitted GGX table matches the numerical integral
// of GGX·cos (with Schlick's Fresnel) over quads within the table's own measured error bound.
#include <prtshade/ltc.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <vector>

namespace {

namespace ltc = prt::shade::ltc;
using ltc::Vec3;

Vec3 add(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
Vec3 mul(const Vec3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
Vec3 unit(const Vec3& a) { return mul(a, 1 / std::sqrt(dot(a, a))); }

// A parallelogram light c + s·u + t·w (s, t ∈ [0, 1]) seen from the origin.
struct Quad {
  Vec3 c, u, w;
  std::array<Vec3, 4> corners() const { return {c, add(c, u), add(add(c, u), w), add(c, w)}; }
  // Its boundary arcs, positively oriented (det(v0, v1, v2) > 0 as seen from the origin).
  std::vector<ltc::Arc> arcs() const {
    std::array<Vec3, 4> v = corners();
    if (dot(v[0], cross(v[1], v[2])) < 0) std::reverse(v.begin(), v.end());
    std::vector<ltc::Arc> out;
    for (size_t i = 0; i < 4; ++i) out.push_back({v[i], v[(i + 1) % 4]});
    return out;
  }
  // ∫ g(ω) dω over its solid angle by the midpoint rule with k × k points on its area.
  double integrate(const std::function<double(const Vec3&)>& g, int k) const {
    const Vec3 nq = cross(u, w);
    const double area = std::sqrt(dot(nq, nq));
    double sum = 0;
    for (int i = 0; i < k; ++i)
      for (int j = 0; j < k; ++j) {
        const Vec3 y = add(c, add(mul(u, (i + 0.5) / k), mul(w, (j + 0.5) / k)));
        const double r2 = dot(y, y);
        sum += g(unit(y)) * std::abs(dot(nq, y)) / (area * r2 * std::sqrt(r2));
      }
    return sum * area / (double(k) * double(k));
  }
  // The integral with an error estimate from the midpoint rule at k and 2k: for a smooth
  // integrand (error ∝ h²) the finer one's error is a third of their difference; a kink inside
  // the quad (a clipped cosine's zero line) makes the convergence irregular, so three times the
  // difference is taken.
  std::pair<double, double> integrate_with_error(const std::function<double(const Vec3&)>& g, int k) const {
    const double coarse = integrate(g, k), fine = integrate(g, 2 * k);
    return {fine, 3 * std::abs(fine - coarse)};
  }
};

// An orthonormal frame with z = n, to place quads relative to an arbitrary normal.
struct Frame {
  Vec3 x, y, z;
  explicit Frame(const Vec3& n) : z(unit(n)) {
    x = unit(cross(std::abs(z[0]) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0}, z));
    y = cross(z, x);
  }
  Vec3 operator()(double a, double b, double c) const { return add(add(mul(x, a), mul(y, b)), mul(z, c)); }
};

TEST(Ltc, IdentityIsLambertsFormFactor) {
  // A rectangle parallel to the receiver at height h with a corner straight above it:
  //   F = 1/(2π) [X/√(1+X²) atan(Y/√(1+X²)) + Y/√(1+Y²) atan(X/√(1+Y²))],  X = a/h, Y = b/h.
  for (const Vec3& n : {Vec3{0, 0, 1}, unit(Vec3{0.3, -0.5, 0.8}), unit(Vec3{-1, 2, 0.1})}) {
    const Frame f(n);
    for (const auto& [a, b, h] : {std::array<double, 3>{1, 1, 1}, {0.2, 3, 0.7}, {1e-3, 2e-3, 5}}) {
      const Quad q{f(0, 0, h), f(a, 0, 0), f(0, b, 0)};
      const double X = a / h, Y = b / h;
      const double F = (X / std::sqrt(1 + X * X) * std::atan(Y / std::sqrt(1 + X * X)) +
                        Y / std::sqrt(1 + Y * Y) * std::atan(X / std::sqrt(1 + Y * Y))) /
                       (2 * std::numbers::pi);
      const ltc::Lobe cosine = ltc::lobe_from_matrix(n, f(0.6, 0.2, 0.7), {1, 0, 1, 0}, 1, 1);
      EXPECT_NEAR(ltc::integrate(cosine, q.arcs()), F, 1e-12 * F) << a << " " << b << " " << h;
    }
  }
}

TEST(Ltc, ThePolygonIntegralIsTheIntegralOfTheDensity) {
  // M⁻¹ maps directions with x > (a/d) z below the cosine space's horizon (d > 0): it cuts
  // through the quads reaching towards +x, which are clipped after the transform. Midpoint rule error: its
  // own estimate (k vs 2k) plus 1e-12.
  const Vec3 n = unit(Vec3{0.1, 0.2, 1});
  const Frame f(n);
  const Vec3 v = f(0.7, 0.0, 0.7);
  for (const std::array<double, 4>& m : {std::array<double, 4>{0.5, 0.3, 0.6, 0.8}, {0.2, -0.4, 0.3, 0.5}, {1.5, 2.0, 1.2, 0.1}}) {
    const ltc::Lobe lobe = ltc::lobe_from_matrix(n, v, m, 1, 1);
    const std::vector<Quad> quads = {
        {f(1.5, -1, 0.05), f(0, 2, 0), f(-1.5, 0, 1.2)},    // from low +x up: crosses the cosine horizon
        {f(1, -1, 0.3), f(0, 1.5, 0), f(0.5, 0.2, 0.8)},    // near +x
        {f(-0.5, -0.5, 1), f(1, 0, 0), f(0, 1, 0)},         // overhead
        {f(-3, 0.5, 0.01), f(0.3, 2, 0), f(0, 0, 0.3)},     // grazing, −x
    };
    if (m[3] == 0.8) {  // the first quad straddles the cosine space's horizon
      const auto c = quads[0].corners();
      EXPECT_EQ(ltc::density(lobe, c[0]), 0.0);
      EXPECT_GT(ltc::density(lobe, c[2]), 0.0);
    }
    for (const Quad& q : quads) {
      const auto [numeric, err] = q.integrate_with_error([&](const Vec3& w) { return ltc::density(lobe, w); }, 400);
      EXPECT_NEAR(ltc::integrate(lobe, q.arcs()), numeric, err + 1e-12) << m[0] << " " << m[3];
    }
  }
}

TEST(Ltc, ArcsNeedNotBeChainedAndHolesSubtract) {
  // A quad minus a smaller quad inside it (reversed), every arc split in two and the list
  // reversed: the integral is the difference of the two quads' (to rounding).
  const Vec3 n = {0, 0, 1};
  const ltc::Lobe lobe = ltc::lobe_from_matrix(n, unit(Vec3{0.8, 0.1, 0.6}), {0.4, 0.5, 0.35, 0.7}, 1, 1);
  const Quad outer{{-0.3, -1, 1.0}, {0, 2, 0}, {1.5, 0, 0.3}};  // crosses x = (a/d) z, the cosine horizon
  const Quad inner{add(outer.c, mul(add(outer.u, outer.w), 0.25)), mul(outer.u, 0.5), mul(outer.w, 0.5)};  // its middle
  std::vector<ltc::Arc> arcs;
  for (const ltc::Arc& a : outer.arcs()) {
    const Vec3 mid = add(unit(a.a), unit(a.b));
    arcs.push_back({a.a, mid});
    arcs.push_back({mid, a.b});
  }
  for (const ltc::Arc& a : inner.arcs()) arcs.push_back({a.b, a.a});
  std::reverse(arcs.begin(), arcs.end());
  const double expected = ltc::integrate(lobe, outer.arcs()) - ltc::integrate(lobe, inner.arcs());
  EXPECT_NEAR(ltc::integrate(lobe, arcs), expected, 1e-13);
  EXPECT_GT(ltc::integrate(lobe, inner.arcs()), 0.01);  // the hole matters
}

TEST(Ltc, GgxMatchesTheNumericalIntegralWithinTheFitsBound) {
  // |A·(F0 + ...)·∫_P D_M − ∫_P f F cos| ≤ error_bound (the fit's measured bound for the cell,
  // valid for any region) + the midpoint rule's own error estimate. Several α, view angles
  // (inside the table's range) and quads, F0 = 1 (the fitted lobe) and 0.04 (Fresnel term).
  const Vec3 n = unit(Vec3{-0.2, 0.1, 1});
  const Frame f(n);
  double worst = 0, worst_share = 0;
  for (const double alpha : {0.05, 0.15, 0.3, 0.6, 1.0}) {
    for (const double theta : {0.0, 0.5, 1.0, 1.4}) {
      const Vec3 v = f(std::sin(theta), 0, std::cos(theta));
      const ltc::Lobe lobe = ltc::ggx_lobe(ltc::ggx_table(), n, v, alpha);
      const std::vector<Quad> quads = {
          {f(-0.5, -0.5, 1), f(1, 0, 0), f(0, 1, 0)},                                                // overhead
          {f(-std::sin(theta) - 0.3, -0.3, std::cos(theta)), f(0.6, 0, 0), f(0, 0.6, 0.1)},      // on the mirror direction
          {f(-3, -1, 0.05), f(0, 2, 0), f(0.2, 0, 1)},                                            // low, towards the reflection
          {f(1, -1, 0.2), f(0, 2, 0), f(0.5, 0, 1.5)},                                            // behind, towards the viewer
      };
      for (const double f0 : {1.0, 0.04}) {
        const double bound = ltc::error_bound(ltc::ggx_table(), alpha, std::cos(theta), f0);
        for (const Quad& q : quads) {
          const auto [numeric, err] = q.integrate_with_error(
              [&](const Vec3& l) { return ltc::ggx_brdf(n, v, l, alpha, f0) * std::max(dot(n, l), 0.0); }, 160);
          const double value = lobe.scale(f0) * ltc::integrate(lobe, q.arcs());
          EXPECT_NEAR(value, numeric, bound + err) << "alpha " << alpha << " theta " << theta << " F0 " << f0;
          worst = std::max(worst, std::abs(value - numeric) / (bound + err));
          worst_share = std::max(worst_share, err / (bound + err));
        }
      }
    }
  }
  // For the record: how close the worst case comes to the bound, and that the quadrature
  // estimate never carries the tolerance.
  std::printf("worst |LTC - numeric| / tolerance %.3f; quadrature share of a tolerance at most %.3f\n", worst, worst_share);
  EXPECT_LT(worst_share, 0.5);
}

} // namespace
