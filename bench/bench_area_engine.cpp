// bench_area_engine — issue 32's CAD-engine measurement: exact area-light soft shadows
// (bake/lights/area_bake.h AreaLightIntegrator, the contour path of bake/visibility/occluder_mesh.h)
// over 2CylinderEngine.glb (121,496 triangles, read by prtbake's own glTF reader, load_mesh) against
// Embree light sampling (bake/visibility/raycast.h RayCaster, shadow rays to uniform
// points of the light: the estimator of view/area_lights.h render_area_reference), side by side in
// one run.
//
// Scene (glTF is y-up): the engine as the only occluder; receivers are
//   * a ground grid (GX × GZ points, default 64 × 48, square cells) at y = lo.y − 1% of the
//     engine's height, over its x extent widened by 35% on each side and centred on it in z,
//     normal +y (the ground is no occluder: nothing lies below it);
//   * a sample of the engine's own vertices (about 512, every k-th): their shade points as a
//     vertex bake has them (bake/mesh/receivers.h: on the surface, welded, with the tie-break t).
// Both methods evaluate the same limit p + εn, ε → 0+: the exact path by its own rules; the rays
// of ground points by Embree's segment test (the ground point is a free point 1% of the engine's
// height below it), those of engine vertices by RayCaster::visible (its 1-ring and near triangles
// decided by the same exact ε-limit predicates, Embree for the rest). An earlier version moved
// vertices off the surface by view/area_lights.h's ε along the vertex normal: on this CAD model
// 7 of 514 vertex points then lay exactly in the plane of an occluder perpendicular to the
// surface (a wall at a floor's edge), which the exact path lets pass (its rule for p in an
// occluder's plane: a zero-area image, with t = 0 no tie-break) and Embree's float test blocks
// at t = 0 (1M rays: 0 against up to 35% of the light): a disagreement of the set-up, not of
// either method.
// Lights, each baked per receiver as E = ∫_{visible light} max(n·ω, 0) dω at unit radiance:
//   * quad: 0.45 × 0.45 of the footprint, 0.9 × the engine's height above its top, emitting down
//     (penumbrae tens of units wide on the ground; the model is 743 units long);
//   * sun: a 0.53°-wide disc (a regular 64-gon whose area is the disc's) at distance
//     D = 1e4 × the engine's diagonal in the direction s = (0.35, 1, 0.2)/|·| (elevation 69°),
//     facing −s. Far enough: seen from any receiver (all within one diagonal d of the scene's
//     centre) the disc's direction differs from s by ≤ d/D = 1e-4 rad (1.1% of the sun's 9.25e-3
//     rad width) and its solid angle (∝ 1/distance²) by ≤ 2d/D = 2e-4 relative — both methods see
//     the same finite disc, so this is a modelling error against a sun at infinity, not an
//     error between them. The lights module has no directional form; this is the issue's "sun of
//     0.53° as a disc light".
//
// Measured (per light; single thread unless said):
//   exact      AreaLightIntegrator::integrate over every receiver, CPU time of the thread:
//              points/s per core, with the occluder workspace's counters (kept triangles and
//              edges cut per query: where the time goes);
//   reference  a converged Embree estimate per receiver (PRT_BENCH_ENGINE_REF rays per point and
//              light, default 16384, in 32 randomised-QMC replicates: RotatedHalton3 keyed by
//              (seed 99, point, light, replicate)), on every thread; its per-point standard
//              error σ from the replicates' spread. Agreement: the check
//              |E_exact − E_ref| ≤ 4.5 σ + b on every point, b = 1e-6 · E_unshadowed + 1e-15 the
//              float bound (the ray tracer's float geometry, which can flip rays grazing an edge;
//              a point whose rays all agree, σ = 0, passes only within it), and
//              z = max(|E_exact − E_ref| − b, 0)/σ. A point outside is looked at again with 64×
//              the rays and another seed, and (at most 4 points) with 1024× (a sliver of light the
//              reference's rays all missed, or a real disagreement: printed);
//   ladder     Embree at N = 8, 32, 128, ... rays per point (other seeds), single thread: CPU time
//              and relative RMS error against the exact values, rms(E_N − E_exact)/rms(E_exact)
//              over the receivers, until it is ≤ 1e-3 (or N reaches PRT_BENCH_ENGINE_MAX_RAYS,
//              default 32768); the N and time for 1e-3 interpolated log-log between the two
//              bracketing rungs (time linear in N);
//   equal time Embree at the N whose time equals the exact path's (from the ladder's line), run
//              once: its error; and at ten times that time (the 10x): its error.
// The exact path has no sampling error (float rounding, ~1e-12 relative): "equal error" is
// taken at 1e-3 relative RMS for the ray tracer (a converged-looking bake), so the time ratio
// is a lower bound on the speed-up at the exact path's own error.
//
// Picture (docs/images/area_engine.png, or --image FILE): the ground grid seen from above, one
// point per 4 × 4 pixels: per light, exact | converged Embree | |exact − Embree| (false colour).
//
// Usage: bench_area_engine [--image FILE]   (env: PRT_BENCH_ENGINE_GRID "64,48",
//   PRT_BENCH_ENGINE_VERTICES 512, PRT_BENCH_ENGINE_REF 16384, PRT_BENCH_ENGINE_MAX_RAYS 32768)
#include "bench_common.h"

#include <view/image.h>
#include <view/text.h>

#include <bake/lights/area_bake.h>
#include <bake/lights/lights.h>
#include <bake/mesh/mesh.h>
#include <bake/mesh/receivers.h>
#include <bake/sphere/sampling.h>
#include <bake/sphere/spherical_polygon.h>
#include <bake/visibility/raycast.h>

#include <tbb/parallel_for.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

namespace {

using namespace prt;
using Eigen::Vector3d;

double thread_cpu() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}
double process_cpu() { return double(std::clock()) / CLOCKS_PER_SEC; }

// A planar light's face 0 as a triangle fan in the mesh's frame, for uniform area sampling.
struct Surface {
  struct Tri {
    Vector3d a, ab, ac;
  };
  std::vector<Tri> tris;
  std::vector<double> cdf;
  Vector3d normal;  // towards the emitting side
  std::vector<Vector3d> corners;

  Surface(const bake::AreaLight& light, const Vector3d& origin) : normal(light.face_normal(0)) {
    const auto& f = light.faces[0];
    for (uint32_t i : f) corners.push_back(light.vertices[i] - origin);
    double total = 0;
    for (size_t k = 1; k + 1 < corners.size(); ++k) {
      const Vector3d ab = corners[k] - corners[0], ac = corners[k + 1] - corners[0];
      total += 0.5 * ab.cross(ac).norm();
      tris.push_back({corners[0], ab, ac});
      cdf.push_back(total);
    }
  }
  double area() const { return cdf.back(); }
};

// One light's Embree estimate at p' with normal n: `rays` shadow rays in R replicates; returns the
// mean, and the standard error of the mean in *se (0 when R < 2).
struct Receiver {
  bake::ShadePoint sp;
  const bake::NearTriangles* near = nullptr;  // engine vertices: their near triangles (the ε-limit rules)
};

// A shadow ray from the receiver in unit direction w to a light point at distance r: ground points
// by Embree's segment test; engine vertices by RayCaster::visible (the same ε-limit as the exact
// path: 1-ring and near triangles decided exactly, Embree for the rest), whose ray is unbounded —
// the same answer here, since no triangle lies beyond either light (both are above the engine).
bool blocked(const bake::RayCaster& caster, const Receiver& rc, const Vector3d& w, double r) {
  return rc.near ? !caster.visible(rc.sp, *rc.near, w) : caster.occluded(rc.sp.p, w, 0.0, r * (1 - 1e-7));
}

double embree_estimate(const bake::RayCaster& caster, const Surface& s, const Receiver& rc, uint64_t seed, uint64_t key,
                       uint32_t rays, uint32_t R, double* se) {
  const Vector3d& p = rc.sp.p;
  const Vector3d& n = rc.sp.n;
  const uint32_t per = rays / R;
  std::array<double, 64> means{};
  for (uint32_t b = 0; b < R; ++b) {
    const bake::RotatedHalton3 halton(seed, key * 64 + b);
    double acc = 0;
    for (uint32_t i = 0; i < per; ++i) {
      const std::array<double, 3> u = halton(i);
      const double target = u[0] * s.area();
      const size_t t = std::min(size_t(std::upper_bound(s.cdf.begin(), s.cdf.end(), target) - s.cdf.begin()), s.cdf.size() - 1);
      const double lo = t ? s.cdf[t - 1] : 0.0;
      const double u0 = std::clamp((target - lo) / (s.cdf[t] - lo), 0.0, std::nextafter(1.0, 0.0));
      const double r0 = std::sqrt(u0);
      const Surface::Tri& tri = s.tris[t];
      const Vector3d y = tri.a + r0 * (1 - u[2]) * tri.ab + r0 * u[2] * tri.ac;
      const Vector3d d = y - p;
      const double r2 = d.squaredNorm(), r = std::sqrt(r2);
      if (!(r > 0)) continue;
      const Vector3d w = d / r;
      const double cos_p = n.dot(w), cos_l = -s.normal.dot(w);
      if (!(cos_p > 0) || !(cos_l > 0)) continue;
      if (blocked(caster, rc, w, r)) continue;
      acc += s.area() * cos_p * cos_l / r2;
    }
    means[b] = acc / per;
  }
  double mean = 0, var = 0;
  for (uint32_t b = 0; b < R; ++b) mean += means[b];
  mean /= R;
  for (uint32_t b = 0; b < R; ++b) var += (means[b] - mean) * (means[b] - mean);
  if (se) *se = R > 1 ? std::sqrt(var / (R - 1) / R) : 0.0;
  return mean;
}

} // namespace

int main(int argc, char** argv) {
  std::filesystem::path image_file = std::filesystem::path(PRT_SOURCE_DIR) / "docs" / "images" / "area_engine.png";
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--image")) image_file = argv[i + 1];
    else {
      std::fprintf(stderr, "usage: bench_area_engine [--image FILE]\n");
      return 2;
    }
  }
  const std::vector<long> grid = bench::env_list("PRT_BENCH_ENGINE_GRID", {64, 48});
  const int GX = int(grid.at(0)), GZ = int(grid.size() > 1 ? grid[1] : grid[0]);
  const long vertex_count = bench::env_long("PRT_BENCH_ENGINE_VERTICES", 512);
  const uint32_t ref_rays = uint32_t(bench::env_long("PRT_BENCH_ENGINE_REF", 16384));
  const uint32_t max_rays = uint32_t(bench::env_long("PRT_BENCH_ENGINE_MAX_RAYS", 32768));
  constexpr uint32_t kRefReplicates = 32;
  if (ref_rays % kRefReplicates) {
    std::fprintf(stderr, "PRT_BENCH_ENGINE_REF must be a multiple of %u\n", kRefReplicates);
    return 2;
  }

  std::string engine;
  for (const std::filesystem::path& p : {std::filesystem::path(PRT_DATA_DIR) / "2CylinderEngine.glb",
                                        std::filesystem::path("/work/shared/data/2CylinderEngine.glb"),
                                        std::filesystem::path("/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb")})
    if (std::filesystem::exists(p)) {
      engine = p.string();
      break;
    }
  if (engine.empty()) {
    std::printf("2CylinderEngine.glb not found: nothing measured\n");
    return 0;
  }
  const bake::Mesh mesh = bake::load_mesh(engine);
  Eigen::AlignedBox3d box;  // in the mesh's frame
  for (const auto& q : mesh.positions) box.extend(q.cast<double>());
  const Vector3d lo = box.min(), hi = box.max(), ext = hi - lo, centre = box.center();
  const double diag = ext.norm();

  // Receivers.
  std::vector<Receiver> receivers;
  const double ground_y = lo.y() - 0.01 * ext.y();
  const double x0 = lo.x() - 0.35 * ext.x(), x1 = hi.x() + 0.35 * ext.x();
  // Square cells: the z range follows from the x spacing, centred on the engine.
  const double cell = (x1 - x0) / GX, z0 = centre.z() - 0.5 * cell * GZ, z1 = centre.z() + 0.5 * cell * GZ;
  for (int j = 0; j < GZ; ++j)
    for (int i = 0; i < GX; ++i) {
      Receiver rc;
      rc.sp.p = Vector3d(x0 + (x1 - x0) * (i + 0.5) / GX, ground_y, z0 + (z1 - z0) * (j + 0.5) / GZ);
      rc.sp.n = Vector3d::UnitY();
      receivers.push_back(rc);
    }
  const size_t ground_points = receivers.size();
  const bake::Topology topology = bake::build_topology(mesh);
  const bake::RayCaster caster(mesh, topology);
  std::vector<bake::NearTriangles> nears;
  {
    const std::vector<bake::ShadePoint> vs = bake::vertex_shade_points(mesh, topology);
    const size_t stride = std::max<size_t>(1, vs.size() / size_t(std::max(vertex_count, 1L)));
    for (size_t v = 0; v < vs.size() && vertex_count > 0; v += stride) {
      receivers.push_back({vs[v], nullptr});
      nears.push_back(caster.near_triangles(vs[v]));
    }
    for (size_t k = 0; k < nears.size(); ++k) receivers[receivers.size() - nears.size() + k].near = &nears[k];
  }
  const size_t P = receivers.size();

  // Lights (world space = mesh frame + origin).
  const Vector3d quad_centre(centre.x(), hi.y() + 0.9 * ext.y(), centre.z());
  bake::AreaLight quad = bake::make_quad_light(mesh.origin + quad_centre, Vector3d(0.45 * ext.x(), 0, 0), Vector3d(0, 0, 0.45 * ext.z()));
  quad.name = "quad";
  const Vector3d s = Vector3d(0.35, 1, 0.2).normalized();
  const double D = 1e4 * diag;
  const int segments = 64;
  const double half_angle = 0.5 * 0.53 * std::numbers::pi / 180;
  // The inscribed 64-gon's radius scaled so that its area is the disc's (π R² = N/2 r² sin(2π/N)).
  const double R_disc = D * std::tan(half_angle);
  const double r_poly = R_disc * std::sqrt(2 * std::numbers::pi / (segments * std::sin(2 * std::numbers::pi / segments)));
  bake::AreaLight sun = bake::make_disc_light(mesh.origin + centre + D * s, -s, r_poly, segments);
  sun.name = "sun";
  const std::vector<bake::AreaLight> lights = {quad, sun};
  for (const auto& l : lights) bake::validate_light(l, "bench_area_engine", l.name);
  const char* light_names[2] = {"quad", "sun 0.53 deg"};

  std::printf("2CylinderEngine.glb (%s): %zu triangles, %zu vertices, bounds (%.1f %.1f %.1f)-(%.1f %.1f %.1f), diagonal %.1f\n",
              engine.c_str(), mesh.triangles.size(), mesh.positions.size(), lo.x(), lo.y(), lo.z(), hi.x(), hi.y(), hi.z(), diag);
  std::printf("receivers: %zu ground points (%d x %d) + %zu engine vertices; quad %.1f x %.1f at height %.1f above the ground; "
              "sun: 64-gon of radius %.4g at distance %.4g (1e4 diagonals), solid angle %.4e sr\n\n",
              ground_points, GX, GZ, P - ground_points, 0.45 * ext.x(), 0.45 * ext.z(), quad_centre.y() - ground_y, r_poly, D,
              2 * std::numbers::pi * (1 - std::cos(half_angle)));

  // Exact, single thread, per light.
  std::vector<double> exact(P * 2), unshadowed(P * 2);
  double t_exact[2] = {0, 0}, t_setup[2] = {0, 0}, t_ground[2] = {0, 0};
  bake::OccluderMesh::Workspace::Stats stats[2];
  for (size_t l = 0; l < 2; ++l) {
    const double c0 = thread_cpu();
    const bake::AreaLightIntegrator integrator(std::span<const bake::AreaLight>(&lights[l], 1), mesh, 0);
    t_setup[l] = thread_cpu() - c0;
    bake::AreaLightIntegrator::Workspace ws;
    double row[1];
    const double c = thread_cpu();
    for (size_t i = 0; i < P; ++i) {
      if (i == ground_points) t_ground[l] = thread_cpu() - c;
      integrator.integrate(receivers[i].sp, row, ws);
      exact[i * 2 + l] = row[0];
    }
    t_exact[l] = thread_cpu() - c;
    if (ground_points == P) t_ground[l] = t_exact[l];
    stats[l] = ws.occluders.stats;
    std::vector<Vector3d> rel, clipped;
    for (size_t i = 0; i < P; ++i) {
      rel.clear();
      for (uint32_t v : lights[l].faces[0]) rel.push_back(lights[l].vertices[v] - mesh.origin - receivers[i].sp.p);
      bake::clip_to_horizon(rel, receivers[i].sp.n, clipped);
      unshadowed[i * 2 + l] = clipped.size() < 3 ? 0.0 : std::abs(bake::cosine_integral(clipped, receivers[i].sp.n));
    }
  }

  const std::vector<Surface> surfaces = {Surface(quad, mesh.origin), Surface(sun, mesh.origin)};

  // Converged reference, every thread.
  std::vector<double> ref(P * 2), ref_se(P * 2);
  const auto w0 = std::chrono::steady_clock::now();
  const double c_ref = process_cpu();
  tbb::parallel_for(size_t(0), P, [&](size_t i) {
    for (size_t l = 0; l < 2; ++l)
      ref[i * 2 + l] = embree_estimate(caster, surfaces[l], receivers[i], 99, i * 2 + l, ref_rays, kRefReplicates, &ref_se[i * 2 + l]);
  });
  const double ref_cpu = process_cpu() - c_ref;
  const double ref_wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();

  auto rel_rms = [&](const std::vector<double>& est, size_t l) {
    double num = 0, den = 0;
    for (size_t i = 0; i < P; ++i) {
      const double d = est[i] - exact[i * 2 + l];
      num += d * d;
      den += exact[i * 2 + l] * exact[i * 2 + l];
    }
    return std::sqrt(num / std::max(den, 1e-300));
  };

  std::printf("Converged Embree reference: %u rays per point and light (32 replicates, seed 99), %.1f s wall, %.1f s CPU on all threads.\n\n",
              ref_rays, ref_wall, ref_cpu);
  std::printf("| light | receivers | shadowed (exact < 99.9%% of unshadowed) | exact: CPU s | points/s per core | kept triangles / query | edges cut / query | special | uncharted |"
              " reference rel. RMS vs exact | points with sigma > 0 | max z | beyond 3 sigma | beyond 4.5 sigma + float bound (of which sigma = 0) | of those, within it at 64x rays (at 1024x) |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  std::vector<std::string> seconds;
  size_t third_looks = 0;
  auto fmt = [](double v) {
    char b[32];
    std::snprintf(b, sizeof b, "%.3g", v);
    return std::string(b);
  };
  for (size_t l = 0; l < 2; ++l) {
    size_t shadowed = 0, with_sigma = 0, beyond3 = 0, fail = 0, zero_sigma = 0, second_ok = 0, third_ok = 0;
    double max_z = 0;
    std::vector<double> r(P);
    for (size_t i = 0; i < P; ++i) {
      const double e = exact[i * 2 + l], u = unshadowed[i * 2 + l], m = ref[i * 2 + l], se = ref_se[i * 2 + l];
      r[i] = m;
      shadowed += e < 0.999 * u;
      const double d = std::abs(e - m), bound = 1e-6 * u + 1e-15;
      if (se > 0) {
        // In standard errors beyond the float bound (a point whose rays vary by rounding only has
        // a σ of rounding size, and no meaningful z).
        const double z = std::max(d - bound, 0.0) / se;
        max_z = std::max(max_z, z);
        beyond3 += z > 3;
        ++with_sigma;
      } else if (d > bound) {
        ++zero_sigma;
      }
      if (d > 4.5 * se + bound) {
        // A second look with 64x the rays (another seed): a sliver of light the reference's rays
        // missed, or a real disagreement.
        ++fail;
        double se2 = 0;
        const double m2 = embree_estimate(caster, surfaces[l], receivers[i], 4242, i * 2 + l, ref_rays * 64,
                                          kRefReplicates, &se2);
        const double d2 = std::abs(e - m2);
        const bool ok2 = d2 <= 4.5 * se2 + bound;
        second_ok += ok2;
        // Still outside (at most 4 points): a third look with 1024x the reference's rays.
        std::string third;
        if (!ok2 && third_looks < 4) {
          ++third_looks;
          double se3 = 0;
          const double m3 = embree_estimate(caster, surfaces[l], receivers[i], 4343, i * 2 + l, ref_rays * 1024, kRefReplicates, &se3);
          const double d3 = std::abs(e - m3);
          third_ok += d3 <= 4.5 * se3 + bound;
          third = "; with " + std::to_string(size_t(ref_rays) * 1024) + " rays: " + fmt(m3) + " +- " + fmt(se3) + " (z " +
                  fmt(se3 > 0 ? d3 / se3 : 0.0) + ")" + (d3 <= 4.5 * se3 + bound ? "" : " STILL OUTSIDE");
        }
        seconds.push_back("  " + std::string(light_names[l]) + ": receiver " + std::to_string(i) +
                          (i < ground_points ? " (ground)" : " (engine vertex)") + ": E_exact " + fmt(e) + " (" + fmt(e / u) +
                          " of unshadowed), Embree " + fmt(m) + " +- " + fmt(se) + "; with " + std::to_string(ref_rays * 64) +
                          " rays: " + fmt(m2) + " +- " + fmt(se2) + " (z " + fmt(se2 > 0 ? d2 / se2 : 0.0) + ")" +
                          (ok2 ? "" : " STILL OUTSIDE") + third);
      }
    }
    const auto& st = stats[l];
    const double q = double(std::max<size_t>(st.queries, 1));
    std::printf("| %s | %zu | %zu | %.2f | %.0f | %.0f | %.1f | %.3f | %.3f | %.2e | %zu | %.2f | %zu | %zu (%zu) | %zu (%zu) |\n", light_names[l], P, shadowed,
                t_exact[l], double(P) / t_exact[l], double(st.kept) / q, double(st.boundary_edges) / q, double(st.special) / q,
                double(st.uncharted) / q, rel_rms(r, l), with_sigma, max_z, beyond3, fail, zero_sigma, second_ok, third_ok);
  }
  for (const auto& line : seconds) std::printf("%s\n", line.c_str());
  for (size_t l = 0; l < 2; ++l)
    std::printf("%s, exact path by receiver kind: %zu ground points %.2f s (%.0f points/s per core), %zu engine vertices %.2f s (%.0f points/s per core)\n",
                light_names[l], ground_points, t_ground[l], double(ground_points) / std::max(t_ground[l], 1e-12), P - ground_points,
                t_exact[l] - t_ground[l], double(P - ground_points) / std::max(t_exact[l] - t_ground[l], 1e-12));
  std::printf("\nWhole bake, exact path: %.2f CPU s for %zu receivers x 2 lights (%.0f points/s per core over both lights), "
              "plus %.2f + %.2f s to build the occluder mesh (edge map, tree) per integrator.\n\n",
              t_exact[0] + t_exact[1], P, double(P) / (t_exact[0] + t_exact[1]), t_setup[0], t_setup[1]);

  // Ladder, single thread.
  std::printf("Embree light sampling on one thread against the exact values (rel. RMS = rms(E_N - E_exact)/rms(E_exact) over the %zu receivers):\n\n", P);
  std::printf("| light | rays per point | CPU s | rel. RMS error |\n|---|---:|---:|---:|\n");
  struct Rung {
    uint32_t n;
    double t, err;
  };
  std::vector<Rung> rungs[2];
  auto run = [&](size_t l, uint32_t n, uint64_t seed) {
    std::vector<double> est(P);
    const uint32_t R = std::min<uint32_t>(8, n);
    const double c = thread_cpu();
    for (size_t i = 0; i < P; ++i) est[i] = embree_estimate(caster, surfaces[l], receivers[i], seed, i * 2 + l, n, R, nullptr);
    const double t = thread_cpu() - c;
    return Rung{n, t, rel_rms(est, l)};
  };
  for (size_t l = 0; l < 2; ++l) {
    for (uint32_t n = 8; n <= max_rays; n *= 4) {
      rungs[l].push_back(run(l, n, 1000 + n));
      std::printf("| %s | %u | %.2f | %.2e |\n", light_names[l], n, rungs[l].back().t, rungs[l].back().err);
      std::fflush(stdout);
      if (rungs[l].back().err <= 1e-3 && rungs[l].size() >= 2) break;
    }
  }
  std::printf("\n| light | exact: CPU s | Embree rays at equal time | its CPU s | its rel. RMS error | Embree rays for 1e-3 rel. RMS | their CPU s | ratio to exact |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|---:|\n");
  Rung ten_times[2];
  for (size_t l = 0; l < 2; ++l) {
    const auto& rg = rungs[l];
    // Time ≈ a + b N from the last two rungs.
    const Rung& A = rg[rg.size() - 2];
    const Rung& B = rg.back();
    const double b = std::max((B.t - A.t) / double(B.n - A.n), 1e-15), a = std::max(B.t - b * B.n, 0.0);
    const double n_eq_raw = (t_exact[l] - a) / b;
    const uint32_t n_eq = n_eq_raw < 8 ? uint32_t(std::max(1.0, std::round(n_eq_raw))) : 8 * uint32_t(std::round(n_eq_raw / 8));
    const Rung eq = run(l, n_eq, 7);
    // N for 1e-3, log-log between the bracketing rungs (or the last two: extrapolated).
    size_t k = 1;
    while (k + 1 < rg.size() && rg[k].err > 1e-3) ++k;
    const Rung& lo_r = rg[k - 1];
    const Rung& hi_r = rg[k];
    const double slope = std::log(hi_r.err / lo_r.err) / std::log(double(hi_r.n) / double(lo_r.n));
    const double n_target = double(lo_r.n) * std::pow(1e-3 / lo_r.err, 1 / slope);
    const bool extrapolated = hi_r.err > 1e-3;
    const double t_target = a + b * n_target;
    std::printf("| %s | %.2f | %u | %.2f | %.2e | %.0f%s (slope %.2f) | %.1f | %.2fx |\n", light_names[l], t_exact[l], eq.n, eq.t, eq.err, n_target,
                extrapolated ? " (extrapolated)" : "", slope, t_target, t_target / t_exact[l]);
    ten_times[l] = run(l, std::max<uint32_t>(8, 8 * uint32_t(std::round((10 * t_exact[l] - a) / b / 8))), 11);
  }
  // Where the "10x faster at equal error" holds: Embree given ten times the exact path's
  // CPU time, measured (not extrapolated); any error target below its error needs more.
  std::printf("\n| light | exact: CPU s | Embree rays at 10x that time | their CPU s | their rel. RMS error |\n|---|---:|---:|---:|---:|\n");
  for (size_t l = 0; l < 2; ++l)
    std::printf("| %s | %.2f | %u | %.2f | %.2e |\n", light_names[l], t_exact[l], ten_times[l].n, ten_times[l].t, ten_times[l].err);

  // Picture: the ground grid from above, per light exact | reference | |difference|.
  const int scale = 4;
  std::vector<view::Image8> rows;
  for (size_t l = 0; l < 2; ++l) {
    view::Image ie(GX * scale, GZ * scale), ir(GX * scale, GZ * scale);
    for (int j = 0; j < GZ * scale; ++j)
      for (int i = 0; i < GX * scale; ++i) {
        const size_t k = size_t(j / scale) * size_t(GX) + size_t(i / scale);
        for (int c = 0; c < 3; ++c) {
          ie.at(i, j)[c] = float(exact[k * 2 + l]);
          ir.at(i, j)[c] = float(ref[k * 2 + l]);
        }
      }
    double top = 0;
    for (size_t k = 0; k < ground_points; ++k) top = std::max(top, exact[k * 2 + l]);
    const double exposure = 0.85 / std::max(top, 1e-300);
    std::vector<view::Panel> panels;
    panels.push_back({view::tone_map(ie, exposure), std::string(light_names[l]) + ": exact", std::nullopt});
    panels.push_back({view::tone_map(ir, exposure), std::string(light_names[l]) + ": Embree " + std::to_string(ref_rays) + " rays", std::nullopt});
    panels.push_back({view::false_colour_error(ie, ir, {}, top, 0.01), "|exact - Embree|",
                      std::array<std::string, 2>{"0", "1% of max E"}});
    rows.push_back(view::labelled_row(panels, {}));
  }
  view::Image8 out(std::max(rows[0].width, rows[1].width), rows[0].height + rows[1].height, 255);
  int y0 = 0;
  for (const auto& r : rows) {
    for (int y = 0; y < r.height; ++y)
      std::copy_n(r.rgb.begin() + std::ptrdiff_t(size_t(y) * size_t(r.width) * 3), size_t(r.width) * 3,
                  out.rgb.begin() + std::ptrdiff_t((size_t(y0 + y) * size_t(out.width)) * 3));
    y0 += r.height;
  }
  std::filesystem::create_directories(image_file.parent_path());
  view::write_png(image_file, out);
  std::printf("\nPicture: %s (ground from above, +x right, +z down; per light: exact | converged Embree | |difference|)\n", image_file.c_str());
  return 0;
}
