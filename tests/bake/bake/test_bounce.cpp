// Tests of interreflected diffuse transfer (bake/bake/bounce.h): the integrating sphere's closed
// form, albedo 0, energy that only grows with the bounces, thread-count independence, albedo checks.
#include <bake/bake/bounce.h>
#include <bake/bake/lightmap_receivers.h>
#include <bake/bake/vertex_bake.h>
#include <bake/core/error.h>
#include <bake/integrators/qmc.h>
#include <bake/mesh/mesh.h>
#include <bake/mesh/receivers.h>
#include <bake/visibility/raycast.h>
#include <prtshade/sh.h>

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <vector>

using namespace prt::bake;
using Eigen::Vector3f;
using std::numbers::pi;

namespace {

const double kY00 = 0.5 / std::sqrt(pi);  // y_00

// The inside of a unit sphere with a round hole at the top (an "integrating sphere"): latitude
// rings from polar angle theta_hole down to the south pole, n_phi segments each, wound so that the
// face normals point inwards, with the exact inward radial normals at the vertices. The hole's
// rim is the first ring: an n_phi-gon inscribed in the circle at z = cos(theta_hole).
Mesh integrating_sphere(double theta_hole, int n_theta, int n_phi) {
  std::vector<Vector3f> positions, normals;
  std::vector<std::array<uint32_t, 3>> triangles;
  const double d_theta = (pi - theta_hole) / n_theta;
  for (int j = 0; j < n_theta; ++j)
    for (int i = 0; i < n_phi; ++i) {
      const double th = theta_hole + j * d_theta, ph = 2 * pi * i / n_phi;
      const Vector3f p(float(std::sin(th) * std::cos(ph)), float(std::sin(th) * std::sin(ph)), float(std::cos(th)));
      positions.push_back(p);
      normals.push_back(-p);
    }
  const auto pole = uint32_t(positions.size());
  positions.emplace_back(0.0f, 0.0f, -1.0f);
  normals.emplace_back(0.0f, 0.0f, 1.0f);
  auto at = [&](int j, int i) { return uint32_t(j * n_phi + (i % n_phi)); };
  for (int j = 0; j < n_theta; ++j)
    for (int i = 0; i < n_phi; ++i) {
      if (j + 1 < n_theta) {
        triangles.push_back({at(j, i), at(j, i + 1), at(j + 1, i)});
        triangles.push_back({at(j, i + 1), at(j + 1, i + 1), at(j + 1, i)});
      } else {
        triangles.push_back({at(j, i), at(j, i + 1), pole});
      }
    }
  return make_mesh(std::move(positions), std::move(triangles), "integrating_sphere", std::move(normals));
}

// The direct pass in closed form for uniform sky radiance through the hole: at every point of the
// inner surface the form factor to the cap (hence to the hole) is its area share f = (1 − cos
// theta_hole)/2, so T_00 = (1/π) ∫_hole (n·ω) y_00 dω = y_00 f. Order 1 (T_00 only).
std::vector<double> closed_direct(size_t rows, double f) { return std::vector<double>(rows, kY00 * f); }

// T_00 after B bounces of albedo rho: each bounce gathers rho × T^b from the fraction 1 − f of the
// cosine-weighted hemisphere that sees the (uniform) wall: a geometric series.
double closed_total(double f, double rho, int bounces) {
  double sum = 0, term = kY00 * f;
  for (int b = 0; b <= bounces; ++b, term *= rho * (1 - f)) sum += term;
  return sum;
}

// Transfer at `order`, and with `radiance` band-1 radiance after it (the layout a request with an
// environment has; the rows here are made without one).
ProductLayout transfer_layout(int order, bool radiance = false) {
  ProductRequest req;
  req.transfer_order = order;
  ProductLayout layout(req);
  if (radiance) {
    layout.radiance_count = 9;
    layout.shadowed = layout.radiance + 9;
    layout.width = layout.shadowed;
  }
  return layout;
}

BounceSpec spec_of(uint32_t rays, int bounces, double tolerance) {
  BounceSpec spec;
  spec.rays = rays;
  spec.bounces = bounces;
  spec.tolerance = tolerance;
  return spec;
}

struct Gathered {
  Mesh mesh;
  Topology topology;
  std::vector<ShadePoint> points;
  GatherHits hits;
};
Gathered gathered(Mesh mesh, const BounceSpec& spec, bool radiance = false) {
  Gathered g{std::move(mesh), {}, {}, {}};
  g.topology = build_topology(g.mesh);
  g.points = vertex_shade_points(g.mesh, g.topology);
  const RayCaster rays(g.mesh, g.topology);
  g.hits = gather(rays, g.points, spec, radiance);
  return g;
}

// A real direct pass over the gathered mesh's vertices: QMC, AO (when asked) and transfer at `order`.
VertexBake direct_bake(const Gathered& g, bool ao, int order, const QmcOptions& options) {
  ProductRequest req;
  req.ao = ao;
  req.transfer_order = order;
  const QmcIntegrator qmc(g.mesh, g.topology, req, options);
  return bake_vertices(g.mesh, g.topology, qmc);
}

} // namespace

// (c) The closed form: T_00 after B bounces = y_00 f Σ_{b≤B} (ρ(1 − f))^b at every vertex, given the
// exact direct rows, so what is measured is the bounce alone.
//
// Tolerances. Monte Carlo: bounce b+1 at a vertex is ρ c_b × (the fraction of its K rays that hit
// the wall), c_b = y_00 f (ρ(1 − f))^b; that fraction's standard error is at most √(f(1 − f)/K)
// (plain Monte Carlo; the rotated Halton points do better), and the error of B^b at the hits is
// averaged over ~K(1 − f) hits of other vertices (a relative ≤ 1/√(K(1 − f)) ≈ 0.07 more: the
// factor 1.5 covers it). Per vertex: 5 σ; the mean over the V vertices: 5 σ/√V (their rays are
// independent). Tessellation: the wall is closed but for the hole, so the wall fraction is
// exactly 1 − (the form factor of the hole), and the hole is the inscribed n_phi-gon, whose area
// falls short of the circle's by (2π/n_phi)²/6 relatively; 4× that on f bounds the difference of
// its form factor (the rim's segments are seen at the grazing angles where the cosine weight is
// least). A uniform B^b interpolates exactly, so nothing else enters.
//
// With R (the mixture gather, eqs. (3'), (5')), the direct rows are R_c,m(v) = s_c π f y_1m(n_v),
// whose irradiance (4) at the vertex's normal is s_c π f, the direct irradiance under a uniform
// sky of radiance s_c (R's other directions do not enter a bounce: only E at the hit does). What
// is compared is E_c after B bounces, eq. (4) at each vertex, against s_c π f Σ_{b≤B} (ρ(1 − f))^b,
// and T_00 as above. The mixture's weight ((n·ω)/π)/p is at most 2, so a ray's standard
// deviation is at most √(2(1 − f)) in place of √(f(1 − f)).
static void check_integrating_sphere(bool radiance) {
  const double theta_hole = 0.6435011087932844;  // cos = 0.8: f = 0.1
  const int n_theta = 64, n_phi = 128;
  const double f = (1 - std::cos(theta_hole)) / 2, rho = 0.8, scale[3] = {1.0, 0.5, 0.25};
  BounceSpec spec = spec_of(256, 0, 0);  // tolerance 0: every bounce asked for
  spec.seed = 7;
  const Gathered g = gathered(integrating_sphere(theta_hole, n_theta, n_phi), spec, radiance);
  const size_t V = g.mesh.positions.size();
  const ProductLayout layout = transfer_layout(1, radiance);
  const size_t W = layout.width;
  const std::vector<Albedo> albedo(g.mesh.triangles.size(), Albedo{rho, rho, rho});
  std::vector<double> direct(V * W);
  std::vector<std::array<double, 3>> y1(V);
  for (size_t v = 0; v < V; ++v) {
    direct[v * W] = kY00 * f;
    const Eigen::Vector3d n = g.mesh.normals[v].cast<double>().normalized();
    double y[4];
    prt::sh::eval(2, n.x(), n.y(), n.z(), y);
    y1[v] = {y[1], y[2], y[3]};
    if (radiance)
      for (size_t c = 0; c < 3; ++c)
        for (size_t m = 0; m < 3; ++m) direct[v * W + layout.radiance + 3 * c + m] = scale[c] * pi * f * y[1 + m];
  }
  const double delta_f = 4 * f * std::pow(2 * pi / n_phi, 2) / 6;
  const double per_ray = radiance ? std::sqrt(2 * (1 - f)) : std::sqrt(f * (1 - f));
  for (const int B : {1, 2, 4, 8}) {
    spec.bounces = B;
    const BounceResult r = bounce_rows(VertexField(g.mesh), g.points, g.hits, albedo, layout, direct, spec, g.mesh.source);
    ASSERT_EQ(r.applied, B);
    // T_00 (c = −1), then E of each channel: value, closed form and its scale against T_00's.
    for (int c = -1; c < (radiance ? 3 : 0); ++c) {
      const double unit = c < 0 ? 1.0 : scale[c] * pi / kY00;  // E_c = unit × (T_00's closed form)
      const double expect = unit * closed_total(f, rho, B);
      double sigma = 0;
      for (int b = 0; b < B; ++b) sigma += 1.5 * rho * unit * kY00 * f * std::pow(rho * (1 - f), b);  // 1.5 ρ c_b
      sigma *= per_ray / std::sqrt(double(spec.rays));
      // The closed form with the hole's fraction off by delta_f either way.
      const double tess = unit * std::max(std::abs(closed_total(f + delta_f, rho, B) - closed_total(f, rho, B)),
                                           std::abs(closed_total(f - delta_f, rho, B) - closed_total(f, rho, B)));
      double mean = 0, worst = 0, sum2 = 0;
      for (size_t v = 0; v < V; ++v) {
        double value = r.values[v * W];
        if (c >= 0) {  // eq. (4)
          value = 0;
          for (size_t m = 0; m < 3; ++m) value += y1[v][m] * r.values[v * W + layout.radiance + 3 * size_t(c) + m];
          value *= 4 * pi / 3;
        }
        const double err = value - expect;
        mean += err / double(V);
        sum2 += err * err;
        worst = std::max(worst, std::abs(err));
      }
      // The bounces' own error estimate (two halves of the rays, relative to the direct RMS, the
      // larger over the products): T_00's measured RMS error, less the tessellation's bias, is at
      // most 3× it (an estimate from one bake of a standard error, and QMC halves are not
      // independent halves); with T alone it is also at most 3× T's error (with R it is R's, larger).
      if (c < 0) {
        const double measured = std::sqrt(sum2 / double(V)) / (kY00 * f), bias = tess / (kY00 * f);
        std::printf("B=%d T_00: measured RMS error / direct %.3e, estimated %.3e\n", B, measured,
                    r.total_relative_std_error());
        EXPECT_LE(measured, 3 * r.total_relative_std_error() + bias) << "B = " << B;
        if (!radiance) {
          EXPECT_LE(r.total_relative_std_error(), 3 * (measured + bias)) << "B = " << B;
        }
      }
      std::printf("B=%d %s: closed form %.6f, mean %.6f (error %.2e; bound %.2e = MC %.2e + tessellation %.2e), "
                  "worst vertex %.2e (bound %.2e)\n",
                  B, c < 0 ? "T_00" : ("E_" + std::to_string(c)).c_str(), expect, expect + mean, mean,
                  5 * sigma / std::sqrt(double(V)) + tess, 5 * sigma / std::sqrt(double(V)), tess, worst,
                  5 * sigma + tess);
      EXPECT_LE(std::abs(mean), 5 * sigma / std::sqrt(double(V)) + tess) << "B = " << B << ", c = " << c;
      EXPECT_LE(worst, 5 * sigma + tess) << "B = " << B << ", c = " << c;
    }
  }
}

TEST(Bounce, IntegratingSphereClosedForm) { check_integrating_sphere(false); }
TEST(Bounce, IntegratingSphereClosedFormWithRadiance) { check_integrating_sphere(true); }

// The closed form per texel: the integrating sphere unwrapped (generated UVs, 128²), its valid
// texels the receivers, a hit reading the previous bounce's lightmap bilinearly at its UV
// (TexelField). The direct rows are the closed form's constant, and a lightmap of a constant
// reads back that constant wherever a lookup's four texels are baked, filled or padded, so any
// lookup that reached an empty texel (too little padding) would show as a dark bounce. What
// differs from the vertex case: texel points lie on the flat facets, inside the sphere by at most
// the sag s = 1 − cos(π/n_phi)·cos(Δθ/2) of a facet's centre; from such a point the hole's form
// factor moves by O(s) relatively, and 4·s·f is added to the tessellation's δf (measured: the
// error stays within the Monte Carlo part, see the printed line).
TEST(Bounce, IntegratingSphereClosedFormPerTexel) {
  const double theta_hole = 0.6435011087932844;  // f = 0.1
  const int n_theta = 48, n_phi = 96;
  const double f = (1 - std::cos(theta_hole)) / 2, rho = 0.8;
  // At the origin the rings' corners at φ = π/2 have x = 0.6 cos(π/2) = 4e-17, and a texel on an
  // edge from such a corner to one of x = −0.04 cannot be put exactly on its triangle (no double
  // lies on that segment but its ends): it is lifted a few roundings in front of its triangles
  // (bake/mesh/texels.h lifted_samples). Before that fix those texels saw their own triangle from
  // behind and gathered nothing (274 of 8,847 at 128²), which the worst-texel bound below catches.
  const Mesh mesh = integrating_sphere(theta_hole, n_theta, n_phi);
  const Topology topology = build_topology(mesh);
  const RayCaster rays(mesh, topology);
  LightmapSpec lm;
  lm.width = lm.height = 128;
  lm.unwrap = true;
  const LightmapReceivers texels = lightmap_receivers(mesh, topology, lm, rays, "sphere texels");
  ASSERT_EQ(texels.atlas.inexact_samples, 0u);
  EXPECT_GT(texels.atlas.lifted_samples, 0u);  // the hard case is in this test
  const ReceiverSet set = texels.receivers();
  const size_t V = set.points.size();
  ASSERT_GT(V, 1000u);
  BounceSpec spec = spec_of(256, 0, 0);
  spec.seed = 5;
  const GatherHits hits = gather(rays, set.points, spec, false);
  const ProductLayout layout = transfer_layout(1);
  const std::vector<double> direct(V * layout.width, kY00 * f);
  const std::vector<Albedo> albedo(mesh.triangles.size(), Albedo{rho, rho, rho});
  const TexelField field(mesh, texels, 2);
  const double sag = 1 - std::cos(pi / n_phi) * std::cos((pi - theta_hole) / n_theta / 2);
  const double delta_f = 4 * f * (std::pow(2 * pi / n_phi, 2) / 6 + sag);
  for (const int B : {1, 3}) {
    spec.bounces = B;
    const BounceResult r = bounce_rows(field, set.points, hits, albedo, layout, direct, spec, mesh.source);
    const double expect = closed_total(f, rho, B);
    double sigma = 0;
    for (int b = 0; b < B; ++b) sigma += 1.5 * rho * kY00 * f * std::pow(rho * (1 - f), b);
    sigma *= std::sqrt(f * (1 - f) / spec.rays);
    const double tess = std::max(std::abs(closed_total(f + delta_f, rho, B) - expect),
                                 std::abs(closed_total(f - delta_f, rho, B) - expect));
    double mean = 0, worst = 0;
    for (size_t v = 0; v < V; ++v) {
      const double err = r.values[v * layout.width] - expect;
      mean += err / double(V);
      worst = std::max(worst, std::abs(err));
    }
    std::printf("B=%d per texel (%zu texels): closed form %.6f, mean error %.2e (bound %.2e = MC %.2e + tessellation "
                "%.2e), worst texel %.2e (bound %.2e)\n",
                B, V, expect, mean, 5 * sigma / std::sqrt(double(V)) + tess, 5 * sigma / std::sqrt(double(V)), tess,
                worst, 5 * sigma + tess);
    EXPECT_LE(std::abs(mean), 5 * sigma / std::sqrt(double(V)) + tess) << "B = " << B;
    EXPECT_LE(worst, 5 * sigma + tess) << "B = " << B;
  }
}

// The same closed form with the direct pass baked (QMC, cosine-weighted, N rays): the composition
// of a real integrator's rows with the bounces. Only the mean over the vertices is compared: the
// direct pass's per-vertex standard error is at most y_00 √(f(1 − f)/N), and each bounce carries
// the direct errors of the vertices it gathers from, so the mean's is at most (that × Σ_b
// (ρ(1 − f))^b + the bounces' σ above)/√V; 5× that, plus the tessellation bound (which moves the
// direct term too: it is closed_total's first term).
TEST(Bounce, IntegratingSphereWithItsDirectPassBaked) {
  const double theta_hole = 0.6435011087932844;  // f = 0.1
  const int n_theta = 32, n_phi = 64, B = 6;
  const uint32_t N = 256;
  const double f = (1 - std::cos(theta_hole)) / 2, rho = 0.8;
  BounceSpec spec = spec_of(256, B, 0);
  const Gathered g = gathered(integrating_sphere(theta_hole, n_theta, n_phi), spec);
  const VertexBake direct = direct_bake(g, false, 1, QmcOptions{N, 11});
  const std::vector<Albedo> albedo(g.mesh.triangles.size(), Albedo{rho, rho, rho});
  const BounceResult r = bounce_rows(VertexField(g.mesh), g.points, g.hits, albedo, direct.layout, direct.values, spec, g.mesh.source);
  const size_t V = g.mesh.positions.size();
  double mean = 0, mean_direct = 0;
  for (size_t v = 0; v < V; ++v) {
    mean += r.values[v] / double(V);
    mean_direct += direct.values[v] / double(V);
  }
  double series = 0, sigma_bounces = 0;
  for (int b = 0; b <= B; ++b) series += std::pow(rho * (1 - f), b);
  for (int b = 0; b < B; ++b) sigma_bounces += 1.5 * rho * kY00 * f * std::pow(rho * (1 - f), b);
  sigma_bounces *= std::sqrt(f * (1 - f) / spec.rays);
  const double sigma = (kY00 * std::sqrt(f * (1 - f) / N) * series + sigma_bounces) / std::sqrt(double(V));
  const double delta_f = 4 * f * std::pow(2 * pi / n_phi, 2) / 6, expect = closed_total(f, rho, B);
  const double tess = std::max(std::abs(closed_total(f + delta_f, rho, B) - expect),
                               std::abs(closed_total(f - delta_f, rho, B) - expect));
  std::printf("direct mean %.6f (closed form %.6f); with %d bounces %.6f (closed form %.6f, error %.2e, bound %.2e)\n",
              mean_direct, kY00 * f, B, mean, expect, mean - expect, 5 * sigma + tess);
  EXPECT_LE(std::abs(mean - expect), 5 * sigma + tess);
}

// (a) Albedo 0: the rows keep every bit of the direct bake (a real one, with its signs and its
// negative zeros), whatever the bounces asked for.
TEST(Bounce, ZeroAlbedoKeepsTheDirectBits) {
  const BounceSpec spec = spec_of(64, 3, BounceSpec::kDefaultTolerance);
  const Gathered g = gathered(integrating_sphere(1.0, 12, 24), spec);
  const VertexBake direct = direct_bake(g, true, 3, QmcOptions{128, 3});
  const std::vector<Albedo> albedo(g.mesh.triangles.size(), Albedo{0, 0, 0});
  const BounceResult r = bounce_rows(VertexField(g.mesh), g.points, g.hits, albedo, direct.layout, direct.values, spec, g.mesh.source);
  ASSERT_EQ(r.values.size(), direct.values.size());
  EXPECT_EQ(std::memcmp(r.values.data(), direct.values.data(), r.values.size() * sizeof(double)), 0);
  EXPECT_EQ(r.applied, 1);  // the first bounce adds nothing: below any tolerance
}

// (b) Under a non-negative environment every bounce adds non-negative energy: T_00 (the transfer of
// a uniform sky) never falls as bounces are added, at any vertex of an enclosure, and it grows.
TEST(Bounce, EveryBounceAddsEnergy) {
  BounceSpec spec = spec_of(128, 0, 0);
  const Gathered g = gathered(integrating_sphere(0.5, 16, 32), spec);
  const VertexBake direct = direct_bake(g, false, 2, QmcOptions{256, 5});
  const std::vector<Albedo> albedo(g.mesh.triangles.size(), Albedo{0.6, 0.6, 0.6});
  const size_t V = g.mesh.positions.size(), W = direct.layout.width;
  std::vector<double> before(V);
  double mean_before = 0;
  for (size_t v = 0; v < V; ++v) mean_before += (before[v] = direct.values[v * W]) / double(V);
  for (int B = 1; B <= 4; ++B) {
    spec.bounces = B;
    const BounceResult r = bounce_rows(VertexField(g.mesh), g.points, g.hits, albedo, direct.layout, direct.values, spec, g.mesh.source);
    double mean = 0;
    for (size_t v = 0; v < V; ++v) {
      EXPECT_GE(r.values[v * W], before[v]) << "vertex " << v << ", B = " << B;
      before[v] = r.values[v * W];
      mean += before[v] / double(V);
    }
    EXPECT_GT(mean, mean_before) << "B = " << B;
    mean_before = mean;
  }
}

// (d) The same bytes with one thread and with two: the gather's points are keyed by the row, and
// each row sums its rays in order.
TEST(Bounce, SameBytesWhateverTheThreads) {
  const BounceSpec spec = spec_of(64, 3, 0);
  const Mesh mesh = integrating_sphere(0.8, 16, 32);
  const std::vector<double> direct = closed_direct(mesh.positions.size(), 0.2);
  const std::vector<Albedo> albedo(mesh.triangles.size(), Albedo{0.7, 0.7, 0.7});
  auto run = [&](int threads) {
    tbb::task_arena arena(threads);
    BounceResult r;
    arena.execute([&] {
      const Gathered g = gathered(mesh, spec);
      r = bounce_rows(VertexField(g.mesh), g.points, g.hits, albedo, transfer_layout(1), direct, spec, g.mesh.source);
    });
    return r.values;
  };
  const std::vector<double> one = run(1), two = run(2);
  ASSERT_EQ(one.size(), two.size());
  EXPECT_EQ(std::memcmp(one.data(), two.data(), one.size() * sizeof(double)), 0);
}

// (e) Albedos that are no material, or whose series may diverge, are refused by name.
TEST(Bounce, RefusesAlbedoOutsideZeroToOne) {
  auto message = [](std::vector<double> grey) {
    std::vector<Albedo> albedo;
    for (const double a : grey) albedo.push_back({a, a, a});
    try {
      check_albedo(albedo, "room.obj");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(message({0.0, 0.5, 0.999}), "");
  EXPECT_NE(message({0.5, 1.0}).find("room.obj: albedo 1 (R) of triangle 1 is 1 or more"), std::string::npos);
  EXPECT_NE(message({-0.25}).find("albedo -0.25 (R) of triangle 0 is negative"), std::string::npos);
  EXPECT_NE(message({std::numeric_limits<double>::quiet_NaN()}).find("is not a number"), std::string::npos);
}

// Back faces are black: from inside a closed box whose faces point outwards every gather ray meets
// a face from behind, so nothing bounces.
TEST(Bounce, BackFacesTakeNothing) {
  const BounceSpec spec = spec_of(32, 2, 0);
  // An inward-facing sphere turned inside out: its faces point outwards, its vertex normals in.
  Mesh mesh = integrating_sphere(0.3, 10, 20);
  for (auto& t : mesh.triangles) std::swap(t[1], t[2]);
  const Gathered g = gathered(mesh, spec);
  for (const uint32_t t : g.hits.triangle) EXPECT_EQ(t, GatherHits::kNone);
}
