// The path-traced reference with bounces (view/reference.h, BOUNCES; issue 31): B = 0 is the
// direct reference byte for byte, the integrating sphere's closed form, determinism.
#include <view/camera.h>
#include <view/image.h>
#include <view/raster.h>
#include <view/reference.h>

#include <bake/environment/envmap.h>
#include <bake/mesh/mesh.h>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <numbers>
#include <vector>

namespace {

using namespace prt::view;
using prt::bake::EnvMap;
using prt::bake::Mesh;
using Eigen::Vector3d;
using Eigen::Vector3f;

bool same_bytes(const Image& a, const Image& b) {
  return a.rgb.size() == b.rgb.size() && std::memcmp(a.rgb.data(), b.rgb.data(), a.rgb.size() * sizeof(float)) == 0;
}

// A unit UV sphere of `rings` × 2·rings quads seen from inside: triangles wound and vertex normals
// pointing to the centre, the polar cap θ < `hole_rings` · π/rings (around +Y) left open.
// `hole_fraction` gets the open cap's share of the whole tessellated sphere's area.
Mesh sphere_with_hole(int rings, int hole_rings, double* hole_fraction) {
  const int segs = 2 * rings;
  std::vector<Vector3f> p, n;
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j <= segs; ++j) {
      const double th = std::numbers::pi * i / rings, ph = 2 * std::numbers::pi * j / segs;
      const Vector3f q(float(std::sin(th) * std::cos(ph)), float(std::cos(th)), float(std::sin(th) * std::sin(ph)));
      p.push_back(q);
      n.push_back(-q);
    }
  std::vector<std::array<uint32_t, 3>> tris;
  double open = 0, total = 0;
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segs; ++j) {
      const uint32_t a = uint32_t(i * (segs + 1) + j), b = a + 1, c = a + uint32_t(segs + 1), d = c + 1;
      for (const std::array<uint32_t, 3>& t : {std::array<uint32_t, 3>{a, b, c}, std::array<uint32_t, 3>{b, d, c}}) {
        const Vector3d e1 = (p[t[1]] - p[t[0]]).cast<double>(), e2 = (p[t[2]] - p[t[0]]).cast<double>();
        const Vector3d cr = e1.cross(e2);
        const double area = 0.5 * cr.norm();
        if (area == 0) continue;  // the poles' degenerate halves
        total += area;
        if (i < hole_rings) {
          open += area;
          continue;
        }
        // Wound so that the face normal points inwards (towards −p).
        const Vector3d centre = (p[t[0]] + p[t[1]] + p[t[2]]).cast<double>() / 3;
        tris.push_back(cr.dot(centre) < 0 ? t : std::array<uint32_t, 3>{t[0], t[2], t[1]});
      }
    }
  *hole_fraction = open / total;
  return prt::bake::make_mesh(p, tris, "integrating sphere", n);
}

Camera inside_camera(int size) {
  Camera cam;
  cam.eye = {0, -0.2, 0};
  cam.at = {1, -0.35, 0.2};
  cam.fov_y_degrees = 40;
  cam.width = cam.height = size;
  return cam;
}

// `samples` rays (and paths) per pixel, `bounces`, albedo `rho` on every triangle of `mesh`.
ReferenceOptions options_for(const Mesh& mesh, uint32_t samples, uint32_t bounces, std::array<float, 3> rho) {
  ReferenceOptions opt;
  opt.samples = samples;
  opt.bounces = bounces;
  opt.albedo.assign(mesh.triangles.size(), rho);
  return opt;
}

} // namespace

TEST(ReferenceBounces, ZeroBouncesIsTheDirectReferenceByteForByte) {
  // (a) B = 0 takes the direct reference's code path: the same bytes as the default options and
  // as albedo · irradiance() / π, pixel by pixel, through the public single-point estimator; and a
  // convex surface (every continuation ray leaves to the sky, E_ind = 0 exactly) gives the same
  // bytes with B = 3.
  double f = 0;
  const Mesh sphere = sphere_with_hole(12, 3, &f);
  const EnvMap env = EnvMap::constant({0.5, 1.0, 2.0});
  const ReferenceOptions zero = options_for(sphere, 64, 0, {0.6f, 0.5f, 0.4f});
  ReferenceOptions deflt = zero;
  deflt.bounces = ReferenceOptions{}.bounces;
  const Camera cam = inside_camera(12);
  const ReferenceImage a = ReferenceRenderer(sphere, env, zero).render(cam);
  const ReferenceImage b = ReferenceRenderer(sphere, env, deflt).render(cam);
  EXPECT_TRUE(same_bytes(a.radiance, b.radiance));
  EXPECT_TRUE(same_bytes(a.std_error, b.std_error));
  const ReferenceRenderer rr(sphere, env, zero);
  size_t compared = 0;
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      const Fragment fr = make_fragment(sphere, a.gbuffer, x, y);
      if (fr.triangle < 0) continue;
      double E[3], se[3];
      rr.irradiance(fr, uint64_t(y) * uint64_t(cam.width) + uint64_t(x), E, se);
      for (int c = 0; c < 3; ++c)
        EXPECT_EQ(a.radiance.at(x, y)[c], float(double(zero.albedo[0][size_t(c)]) * E[c] * std::numbers::inv_pi));
      ++compared;
    }
  EXPECT_GT(compared, 100u);

  const Mesh ground = ground_quad(0.0, 0.0, 0.0, 5.0);
  ReferenceOptions flat;
  flat.samples = 64;
  Camera top;
  top.eye = {0, 3, 4};
  top.at = {0, 0, 0};
  top.width = top.height = 16;
  const ReferenceImage d0 = ReferenceRenderer(ground, env, flat).render(top);
  flat.bounces = 3;
  const ReferenceImage d3 = ReferenceRenderer(ground, env, flat).render(top);
  EXPECT_TRUE(same_bytes(d0.radiance, d3.radiance));
  EXPECT_TRUE(same_bytes(d0.std_error, d3.std_error));
}

TEST(ReferenceBounces, IntegratingSphereMatchesTheGeometricSeries) {
  // (b) Inside a sphere with an open cap of area fraction f under a constant sky L, every inner
  // point's irradiance after B bounces is E = π L f Σ_{b=0..B} (ρ (1 − f))^b (the form factor from
  // a point of a sphere to any part of it is that part's area fraction), so a pixel shows
  // ρ E / π = ρ L f Σ_b (ρ(1 − f))^b. Per pixel: 5.41 standard errors (the 0.999 two-sided
  // quantile of Student's t with 7 degrees of freedom: 8 replicates) plus a tessellation bound of
  // 1 % of the value: the 48-ring sphere's flat facets sit up to 1 − cos(π/96) ≈ 5e-4 inside the
  // unit sphere and their vertex normals differ from the facet's by up to 2.6°; B = 0 (no bounce,
  // the direct reference) measures it: mean deviation over the 36 pixels 0.1 % ± 0.3 %. The
  // estimate is noisy here by nature (a shadow ray through the 10 % hole is a Bernoulli trial):
  // measured mean relative standard error 1.7 % (B = 0), 1.9 % (B = 1), 1.6 % (B = 3) at 8,192
  // rays and paths per pixel, so each pixel's is required below 5 %. Over the pixels (independent
  // randomisations) the mean relative deviation must be within 4 × its standard error
  // (√Σ se² / n ≈ 0.3 %) plus the 1 %: measured 0.11 %, 0.16 %, 0.07 % for B = 0, 1, 3.
  double f = 0;
  const Mesh sphere = sphere_with_hole(48, 10, &f);
  ASSERT_GT(f, 0.09);
  ASSERT_LT(f, 0.11);
  const double L = 1.5, rho = 0.6;
  const EnvMap env = EnvMap::constant({L, L, L});
  const Camera cam = inside_camera(6);
  for (uint32_t B : {0u, 1u, 3u}) {
    const ReferenceImage ref = ReferenceRenderer(sphere, env, options_for(sphere, 8192, B, {float(rho), float(rho), float(rho)})).render(cam);
    double series = 0, term = 1;
    for (uint32_t b = 0; b <= B; ++b, term *= rho * (1 - f)) series += term;
    const double exact = rho * L * f * series;
    size_t n = 0;
    double worst = 0, mean_dev = 0, mean_se = 0, sum_se2 = 0;
    for (int y = 0; y < cam.height; ++y)
      for (int x = 0; x < cam.width; ++x) {
        if (ref.gbuffer.triangle[size_t(y) * size_t(cam.width) + size_t(x)] < 0) continue;
        const double v = ref.radiance.at(x, y)[1], se = ref.std_error.at(x, y)[1];
        ASSERT_TRUE(std::isfinite(v) && std::isfinite(se));
        EXPECT_NEAR(v, exact, 5.41 * se + 0.01 * exact) << "B " << B << " pixel " << x << "," << y << " se " << se;
        EXPECT_LT(se, 0.05 * exact);  // precise enough to mean something
        worst = std::max(worst, std::abs(v - exact) / exact);
        mean_dev += (v - exact) / exact;
        mean_se += se / exact;
        sum_se2 += (se / exact) * (se / exact);
        ++n;
      }
    EXPECT_EQ(n, size_t(cam.width) * size_t(cam.height));  // the camera sees only the wall
    EXPECT_LT(std::abs(mean_dev / double(n)), 4 * std::sqrt(sum_se2) / double(n) + 0.01) << "B " << B;
    std::printf("integrating sphere f %.4f rho %.2f B %u: exact %.5f, relative deviation: largest %.4f, mean %.4f; mean relative "
                "standard error %.4f\n", f, rho, B, exact, worst, mean_dev / double(n), mean_se / double(n));
  }
}

TEST(ReferenceBounces, SameBytesForOneAndTwoThreads) {
  // (d) Every random number is keyed by (seed, pixel, replicate, point, depth), not by the thread.
  double f = 0;
  const Mesh sphere = sphere_with_hole(16, 4, &f);
  const EnvMap env = EnvMap::constant({0.5, 1.0, 2.0});
  const ReferenceRenderer rr(sphere, env, options_for(sphere, 32, 2, {0.7f, 0.5f, 0.3f}));
  const Camera cam = inside_camera(16);
  ReferenceImage one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = rr.render(cam);
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    two = rr.render(cam);
  }
  EXPECT_TRUE(same_bytes(one.radiance, two.radiance));
  EXPECT_TRUE(same_bytes(one.std_error, two.std_error));
  double lit = 0;
  for (float v : one.radiance.rgb) lit += v;
  EXPECT_GT(lit, 0.0);
}

TEST(ReferenceBounces, ReflectanceAndGathersTakeEachTriangleAsTheBakeBouncedIt) {
  // (e) Scenes (view/reference.h ReferenceOptions::reflectance, gathers): inside the integrating
  // sphere, a reflectance of 0 everywhere gives the direct bytes whatever the bounces and
  // whatever the picture's albedo; gathers = 0 on a triangle gives its pixels the direct bytes
  // while the other pixels keep the bounced ones (their randomisation is keyed per pixel); and a
  // reflectance of ρ with an albedo of 1 gives the closed form's ρ-series scaled by 1/ρ (the light
  // bounces with ρ, the picture is tinted with 1): checked on the mean, 4 standard errors + 1 %.
  double f = 0;
  const Mesh sphere = sphere_with_hole(24, 5, &f);
  const double L = 1.5, rho = 0.6;
  const EnvMap env = EnvMap::constant({L, L, L});
  const Camera cam = inside_camera(8);
  const std::array<float, 3> white{1, 1, 1}, grey{float(rho), float(rho), float(rho)};
  const ReferenceImage direct = ReferenceRenderer(sphere, env, options_for(sphere, 256, 0, white)).render(cam);
  ReferenceOptions absorb = options_for(sphere, 256, 3, white);
  absorb.reflectance.assign(sphere.triangles.size(), {0, 0, 0});
  const ReferenceImage a = ReferenceRenderer(sphere, env, absorb).render(cam);
  EXPECT_TRUE(same_bytes(a.radiance, direct.radiance));
  EXPECT_TRUE(same_bytes(a.std_error, direct.std_error));

  const ReferenceImage bounced = ReferenceRenderer(sphere, env, options_for(sphere, 256, 3, white)).render(cam);
  ReferenceOptions some = options_for(sphere, 256, 3, white);
  some.gathers.assign(sphere.triangles.size(), 1);
  for (size_t t = 0; t < some.gathers.size(); t += 2) some.gathers[t] = 0;
  const ReferenceImage g = ReferenceRenderer(sphere, env, some).render(cam);
  size_t as_direct = 0, as_bounced = 0;
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      const int32_t t = g.gbuffer.triangle[size_t(y) * size_t(cam.width) + size_t(x)];
      ASSERT_GE(t, 0);
      const Image& want = some.gathers[size_t(t)] ? bounced.radiance : direct.radiance;
      for (int c = 0; c < 3; ++c) EXPECT_EQ(g.radiance.at(x, y)[c], want.at(x, y)[c]) << x << "," << y;
      ++(some.gathers[size_t(t)] ? as_bounced : as_direct);
    }
  EXPECT_GT(as_direct, 8u);
  EXPECT_GT(as_bounced, 8u);
  EXPECT_FALSE(same_bytes(bounced.radiance, direct.radiance));  // the bounces do add light here

  ReferenceOptions tinted = options_for(sphere, 2048, 2, white);
  tinted.reflectance.assign(sphere.triangles.size(), grey);
  const ReferenceImage r = ReferenceRenderer(sphere, env, tinted).render(cam);
  const double exact = L * f * (1 + rho * (1 - f) + std::pow(rho * (1 - f), 2));
  double mean = 0, se2 = 0;
  const double n = double(cam.width) * double(cam.height);
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      mean += r.radiance.at(x, y)[1] / n;
      se2 += std::pow(r.std_error.at(x, y)[1] / n, 2);
    }
  EXPECT_NEAR(mean, exact, 4 * std::sqrt(se2) + 0.01 * exact);
}
