// bench_filter — quality per ray and CPU time of the sheared-filter integrator (bake/integrators/filter.h,
// paper 002) next to QMC (bake/integrators/qmc.h) and, on the grass scene, the silhouette integrator, in one
// run (docs/ARCHITECTURE.md, "Benchmarks").
//
//   bench_filter assets [names...]   AO + order-3 transfer on data/<name>.obj (default:
//                                    bunny_ground wuson spider): filter at 8-32 pass-1 rays, QMC at
//                                    32-256 rays, each against a converged reference (QMC, 2^16
//                                    rays per vertex on 256 seeded vertices).
//   bench_filter diagnose [names...] the filter's error split into bias and noise over 6 seeds
//                                    (default: bunny_ground), with its neighbours and samples per
//                                    filtered cell, next to the same with every brute-forced cell
//                                    at 256 rays (its share of the error; PRT_DIAGNOSE_QUICK=1
//                                    skips it and QMC) and QMC at 32 and 256 rays.
//   bench_filter grass [blades]      the paper's use case: a generated field of grass blades (4
//                                    triangles each; default 250,000 blades = 1M triangles) on a
//                                    2 m ground grid of 512² quads, AO of the ground's 263,169
//                                    vertices (the receivers; every triangle occludes). The filter
//                                    bakes every receiver; QMC and the silhouette integrator (the
//                                    latter below 400k triangles only: its contour setup grows
//                                    too slow) a seeded sample of 512 (their cost per vertex does
//                                    not depend on the others), scaled to all receivers.
//   bench_filter grille [bars]       a grille of round bars (radius 2 mm, 16 sides × 128 segments:
//                                    4,096 triangles each; default 256 bars = 1M triangles, half
//                                    along x at 30 cm, half along y just above) over the same ground,
//                                    receivers and runs as grass: occluders far from the receivers
//                                    (the filter's case) but every bar edge a contour edge.
//
// Errors are over the reference's vertices; "rays/pt" counts pass-1 and brute-force rays (the
// filter) or rays (QMC); CPU seconds are the process's (every thread), including the filter's
// neighbour search (prepare() and the k-d tree queries) and pass 1.
#include <bake/bake/vertex_bake.h>
#include <bake/integrators/filter.h>
#include <bake/integrators/qmc.h>
#include <bake/integrators/silhouette.h>
#include <bake/mesh/mesh.h>
#include <bake/sphere/sampling.h>

#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <string>
#include <vector>

using namespace prt::bake;
using Eigen::Vector3f;

namespace {

double process_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

struct Asset {
  Mesh mesh;
  Topology topo;
  std::vector<ShadePoint> points;
  explicit Asset(Mesh m) : mesh(std::move(m)), topo(build_topology(mesh)), points(vertex_shade_points(mesh, topo)) {}
};

// Values of the rows `rows` by `integrator` (index offset so a reference is randomised apart).
std::vector<double> integrate_rows(const Asset& a, const Integrator& integrator, const std::vector<uint32_t>& rows,
                                   uint64_t offset) {
  const size_t W = integrator.layout().width;
  std::vector<double> out(rows.size() * W);
  tbb::parallel_for(size_t(0), rows.size(), [&](size_t i) {
    integrator.integrate(a.points[rows[i]], rows[i] + offset, std::span(out).subspan(i * W, W));
  });
  return out;
}

// The filter's options, with the environment's overrides (PRT_FILTER_RADIUS, _FALLBACK, _OMEGA_V,
// _MIN_WEIGHT) for exploring them without rebuilding.
FilterOptions tuned() {
  FilterOptions o;
  if (const char* v = std::getenv("PRT_FILTER_RADIUS")) o.radius_factor = std::stod(v);
  if (const char* v = std::getenv("PRT_FILTER_FALLBACK")) o.fallback_rays = uint32_t(std::stoul(v));
  if (const char* v = std::getenv("PRT_FILTER_OMEGA_V")) o.omega_v = std::stod(v);
  if (const char* v = std::getenv("PRT_FILTER_MIN_WEIGHT")) o.min_weight = std::stod(v);
  if (const char* v = std::getenv("PRT_FILTER_SEED")) o.seed = std::stoull(v);
  return o;
}

struct Result {
  double ao_rmse = 0, ao_max = 0, t_rmse = 0, cpu = 0, rays = 0, brute = 0;
  double neighbours = 0, cell_samples = 0;  // the filter's: per point, per filtered cell
  std::vector<double> values;               // [rows][W]
};

// Errors of rows (values: [rows][W]) against the reference (same layout; AO first, then T).
void errors(const std::vector<double>& values, const std::vector<double>& ref, size_t W, bool transfer, Result& r) {
  const size_t n = ref.size() / W;
  double a2 = 0, t2 = 0;
  for (size_t i = 0; i < n; ++i) {
    const double d = values[i * W] - ref[i * W];
    a2 += d * d;
    r.ao_max = std::max(r.ao_max, std::abs(d));
    for (size_t k = 1; transfer && k < W; ++k) t2 += (values[i * W + k] - ref[i * W + k]) * (values[i * W + k] - ref[i * W + k]);
  }
  r.ao_rmse = std::sqrt(a2 / double(n));
  r.t_rmse = transfer ? std::sqrt(t2 / double(n * (W - 1))) : 0.0;
}

// The filter bakes every vertex (it needs the neighbours' rays); errors on `rows`.
Result run_filter(const Asset& a, const ProductRequest& req, uint32_t rays, const std::vector<uint32_t>& rows,
                  const std::vector<double>& ref, FilterOptions o = tuned()) {
  o.rays = rays;
  const double c0 = process_cpu_seconds();
  const FilterIntegrator f(a.mesh, a.topo, req, o);
  const VertexBake b = bake_points(a.points, f);
  Result r;
  r.cpu = process_cpu_seconds() - c0;
  const size_t W = b.layout.width;
  std::vector<double> values(rows.size() * W);
  for (size_t i = 0; i < rows.size(); ++i)
    std::copy_n(b.values.begin() + ptrdiff_t(rows[i] * W), W, values.begin() + ptrdiff_t(i * W));
  errors(values, ref, W, req.transfer_order > 0, r);
  if (std::getenv("DBG"))
    for (size_t i = 0; i < rows.size(); ++i)
      if (std::abs(values[i * W] - ref[i * W]) > 0.025)
        std::printf("DBG %u p %.3f %.3f %.3f n %.2f %.2f %.2f ref %.3f got %.3f\n", rows[i], a.points[rows[i]].p.x(),
                    a.points[rows[i]].p.y(), a.points[rows[i]].p.z(), a.points[rows[i]].n.x(), a.points[rows[i]].n.y(),
                    a.points[rows[i]].n.z(), ref[i * W], values[i * W]);
  const FilterStats s = f.filter_stats();
  r.rays = s.rays_per_point();
  r.brute = s.brute_fraction();
  r.neighbours = s.neighbours_per_point();
  r.cell_samples = s.samples_per_filtered_cell();
  r.values = std::move(values);
  return r;
}

// An integrator that does not need neighbours, timed on the rows alone (CPU per row × V is the
// whole bake's).
Result run_rows(const Asset& a, const Integrator& integ, const std::vector<uint32_t>& rows, const std::vector<double>& ref,
                bool transfer, double rays) {
  const double c0 = process_cpu_seconds();
  const std::vector<double> v = integrate_rows(a, integ, rows, 0);
  Result r;
  r.cpu = (process_cpu_seconds() - c0) * double(a.points.size()) / double(rows.size());
  errors(v, ref, integ.layout().width, transfer, r);
  r.rays = rays;
  r.values = v;
  return r;
}

void print(const char* name, const std::string& knob, const Result& r) {
  std::printf("  %-10s %-12s rays/pt %7.1f  AO RMSE %.4f  max %.4f  T RMSE %.4f  brute %5.1f%%  CPU %8.2f s\n", name,
              knob.c_str(), r.rays, r.ao_rmse, r.ao_max, r.t_rmse, 100 * r.brute, r.cpu);
  std::fflush(stdout);
}

void assets(std::vector<std::string> names) {
  if (names.empty()) names = {"bunny_ground", "wuson", "spider"};
  ProductRequest req;
  req.ao = true;
  req.transfer_order = 3;
  for (const std::string& name : names) {
    const Asset a(load_mesh(std::filesystem::path(PRT_DATA_DIR) / (name + ".obj")));
    const std::vector<uint32_t> rows = seeded_sample(uint32_t(a.points.size()), 256, 11);
    const QmcIntegrator reference(a.mesh, a.topo, req, {65536, 12345});
    const std::vector<double> ref = integrate_rows(a, reference, rows, 1u << 30);
    std::printf("%s: %zu vertices, %zu triangles; reference QMC 65536 rays on %zu seeded vertices\n", name.c_str(),
                a.points.size(), a.mesh.triangles.size(), rows.size());
    for (uint32_t rays : {4u, 8u, 16u, 24u, 32u}) print("filter", std::to_string(rays) + " pass-1", run_filter(a, req, rays, rows, ref));
    for (uint32_t rays : {32u, 64u, 128u, 256u}) {
      const QmcIntegrator q(a.mesh, a.topo, req, {rays, 1});
      print("qmc", std::to_string(rays), run_rows(a, q, rows, ref, true, rays));
    }
  }
}

// The error of `runs` (one per seed) split into bias and noise, per vertex of the reference: the
// mean over seeds m_i and the spread s_i² (unbiased); noise = √mean s_i², bias = √(mean (m_i −
// ref_i)² − noise²/S) (the mean's own noise removed). AO column 0 and the transfer columns.
void split(const char* name, const std::string& knob, const std::vector<Result>& runs, const std::vector<double>& ref,
           size_t W) {
  const size_t n = ref.size() / W, S = runs.size();
  double bias2[2] = {0, 0}, noise2[2] = {0, 0}, rmse[2] = {0, 0}, mean_ao = 0;
  for (size_t i = 0; i < n; ++i)
    for (size_t k = 0; k < W; ++k) {
      double m = 0, e2 = 0;
      for (const Result& r : runs) m += r.values[i * W + k] / double(S);
      double v = 0;
      for (const Result& r : runs) {
        v += (r.values[i * W + k] - m) * (r.values[i * W + k] - m) / double(S - 1);
        e2 += (r.values[i * W + k] - ref[i * W + k]) * (r.values[i * W + k] - ref[i * W + k]) / double(S);
      }
      const size_t j = k == 0 ? 0 : 1;
      if (k == 0) mean_ao += (m - ref[i * W]) / double(n);
      bias2[j] += (m - ref[i * W + k]) * (m - ref[i * W + k]) - v / double(S);
      noise2[j] += v;
      rmse[j] += e2;
    }
  const double na = double(n), nt = double(n * (W - 1));
  double rays = 0, brute = 0, nb = 0, cs = 0;
  for (const Result& r : runs) rays += r.rays / double(S), brute += r.brute / double(S), nb += r.neighbours / double(S),
                               cs += r.cell_samples / double(S);
  std::printf("  %-10s %-22s rays/pt %6.1f brute %4.1f%% nbrs %5.1f smp/cell %5.1f | AO rmse %.4f bias %.4f noise "
              "%.4f mean %+.4f | T rmse %.4f bias %.4f noise %.4f\n",
              name, knob.c_str(), rays, 100 * brute, nb, cs, std::sqrt(rmse[0] / na), std::sqrt(std::max(0.0, bias2[0] / na)),
              std::sqrt(noise2[0] / na), mean_ao, std::sqrt(rmse[1] / nt), std::sqrt(std::max(0.0, bias2[1] / nt)),
              std::sqrt(noise2[1] / nt));
  std::fflush(stdout);
}

// Bias and noise of the filter (and QMC) over 6 seeds; variants from the environment as in tuned().
void diagnose(std::vector<std::string> names) {
  if (names.empty()) names = {"bunny_ground"};
  ProductRequest req;
  req.ao = true;
  req.transfer_order = 3;
  constexpr uint64_t kSeeds = 6;
  for (const std::string& name : names) {
    const Asset a(load_mesh(std::filesystem::path(PRT_DATA_DIR) / (name + ".obj")));
    const std::vector<uint32_t> rows = seeded_sample(uint32_t(a.points.size()), 256, 11);
    const QmcIntegrator reference(a.mesh, a.topo, req, {65536, 12345});
    const std::vector<double> ref = integrate_rows(a, reference, rows, 1u << 30);
    const size_t W = reference.layout().width;
    std::printf("%s: %zu vertices; %llu seeds\n", name.c_str(), a.points.size(), (unsigned long long)kSeeds);
    const auto variant = [&](const std::string& label, uint32_t rays, FilterOptions o) {
      std::vector<Result> runs;
      for (uint64_t seed = 1; seed <= kSeeds; ++seed) {
        o.seed = seed;
        runs.push_back(run_filter(a, req, rays, rows, ref, o));
      }
      split("filter", std::to_string(rays) + " " + label, runs, ref, W);
    };
    const bool exact_cells = !std::getenv("PRT_DIAGNOSE_QUICK");  // brute cells at 256 rays: slow
    for (uint32_t rays : {8u, 16u, 32u}) {
      variant("", rays, tuned());
      if (!exact_cells) continue;
      FilterOptions exact = tuned();
      exact.fallback_rays = 256;
      variant("brute@256", rays, exact);
    }
    for (uint32_t rays : {32u, 256u}) {
      if (!exact_cells) break;
      std::vector<Result> runs;
      for (uint64_t seed = 1; seed <= kSeeds; ++seed) {
        const QmcIntegrator q(a.mesh, a.topo, req, {rays, seed});
        runs.push_back(run_rows(a, q, rows, ref, true, rays));
      }
      split("qmc", std::to_string(rays), runs, ref, W);
    }
  }
}

// The 2 m × 2 m ground grid of kGround² quads at z = 0, its vertices first.
constexpr int kGround = 512;
void ground(std::vector<Vector3f>& p, std::vector<std::array<uint32_t, 3>>& t) {
  const int G = kGround;
  for (int j = 0; j <= G; ++j)
    for (int i = 0; i <= G; ++i) p.emplace_back(-1.0f + 2.0f * float(i) / G, -1.0f + 2.0f * float(j) / G, 0.0f);
  for (int j = 0; j < G; ++j)
    for (int i = 0; i < G; ++i) {
      const uint32_t a = uint32_t(j * (G + 1) + i), b = a + 1, c = a + uint32_t(G) + 2, d = a + uint32_t(G) + 1;
      t.push_back({a, b, c});
      t.push_back({a, c, d});
    }
}

// Grass: `blades` blades, each a bent strip of 2 quads (4 triangles) 4-12 mm wide at the base and
// 8-20 cm tall, leaning randomly, on the ground grid.
Mesh grass(uint32_t blades) {
  std::vector<Vector3f> p;
  std::vector<std::array<uint32_t, 3>> t;
  ground(p, t);
  for (uint32_t k = 0; k < blades; ++k) {
    auto u = [&](uint64_t salt) { return float(to_unit(mix64(uint64_t(k) * 8 + salt))); };
    const Vector3f base(-0.98f + 1.96f * u(1), -0.98f + 1.96f * u(2), 0.0f);
    const float phi = 6.2831853f * u(3), w = 0.004f + 0.008f * u(4), h = 0.08f + 0.12f * u(5), lean = 0.6f * u(6);
    const Vector3f side(std::cos(phi), std::sin(phi), 0), bend(-std::sin(phi), std::cos(phi), 0);
    const uint32_t first = uint32_t(p.size());
    for (int r = 0; r <= 2; ++r) {
      const float s = float(r) / 2, width = w * (1 - 0.8f * s);
      const Vector3f centre = base + Vector3f(0, 0, h * s) + bend * (lean * h * s * s);
      p.push_back(centre - 0.5f * width * side);
      p.push_back(centre + 0.5f * width * side);
    }
    for (uint32_t r = 0; r < 2; ++r) {
      const uint32_t a = first + 2 * r;
      t.push_back({a, a + 1, a + 3});
      t.push_back({a, a + 3, a + 2});
    }
  }
  return make_mesh(std::move(p), std::move(t), "grass");
}

// A grille: `bars` round bars (radius 2 mm, 16 sides, 128 segments) across the ground, the first
// half along x at z = 0.3, the rest along y at z = 0.306, evenly spaced over [-0.9, 0.9].
Mesh grille(uint32_t bars) {
  std::vector<Vector3f> p;
  std::vector<std::array<uint32_t, 3>> t;
  ground(p, t);
  constexpr int kSides = 16, kSegments = 128;
  constexpr float kRadius = 0.002f;
  const uint32_t half = std::max(bars / 2, 1u);
  for (uint32_t k = 0; k < bars; ++k) {
    const bool along_x = k < half;
    const uint32_t i = along_x ? k : k - half, count = along_x ? half : bars - half;
    const float offset = -0.9f + 1.8f * (float(i) + 0.5f) / float(count), z = along_x ? 0.3f : 0.306f;
    const uint32_t first = uint32_t(p.size());
    for (int s = 0; s <= kSegments; ++s)
      for (int a = 0; a < kSides; ++a) {
        const float along = -1.0f + 2.0f * float(s) / kSegments, ang = 6.2831853f * float(a) / kSides;
        const float u = kRadius * std::cos(ang), w = kRadius * std::sin(ang);
        p.push_back(along_x ? Vector3f(along, offset + u, z + w) : Vector3f(offset + u, along, z + w));
      }
    for (uint32_t s = 0; s < uint32_t(kSegments); ++s)
      for (uint32_t a = 0; a < uint32_t(kSides); ++a) {
        const uint32_t a1 = (a + 1) % kSides, r0 = first + s * kSides, r1 = r0 + kSides;
        t.push_back({r0 + a, r0 + a1, r1 + a1});
        t.push_back({r0 + a, r1 + a1, r1 + a});
      }
  }
  return make_mesh(std::move(p), std::move(t), "grille");
}

// The ground's receivers under `mesh`: filter, QMC and (below 400k triangles) silhouette.
void ground_scene(const char* name, Mesh mesh, double build_seconds) {
  Asset a(std::move(mesh));
  a.points.resize(size_t(kGround + 1) * size_t(kGround + 1));  // the ground's vertices receive
  std::printf("%s: %zu triangles, %zu ground vertices receive (built in %.1f CPU s); AO\n", name,
              a.mesh.triangles.size(), a.points.size(), build_seconds);
  ProductRequest req;
  req.ao = true;
  const std::vector<uint32_t> rows = seeded_sample(uint32_t(a.points.size()), 512, 11);
  const QmcIntegrator reference(a.mesh, a.topo, req, {16384, 12345});
  const std::vector<double> ref = integrate_rows(a, reference, rows, 1u << 30);
  std::printf("reference: QMC 16384 rays on %zu seeded vertices\n", rows.size());
  for (uint32_t rays : {8u, 16u, 32u}) print("filter", std::to_string(rays) + " pass-1", run_filter(a, req, rays, rows, ref));
  for (uint32_t rays : {16u, 32u, 64u, 128u, 256u}) {
    const QmcIntegrator q(a.mesh, a.topo, req, {rays, 1});
    print("qmc", std::to_string(rays), run_rows(a, q, rows, ref, false, rays));
  }
  if (a.mesh.triangles.size() > 400000) return;
  for (int isolines : {4, 8, 16}) {
    const double s0 = process_cpu_seconds();
    const SilhouetteIntegrator s(a.mesh, a.topo, req, {isolines, 1});
    const double setup = process_cpu_seconds() - s0;
    Result r = run_rows(a, s, rows, ref, false, 0);
    r.cpu += setup;  // its contour structures are part of the bake
    print("silhouette", "N = " + std::to_string(isolines), r);
  }
}

} // namespace

int main(int argc, char** argv) {
  const std::string what = argc > 1 ? argv[1] : "assets";
  if (what == "assets") {
    assets(std::vector<std::string>(argv + std::min(argc, 2), argv + argc));
  } else if (what == "diagnose") {
    diagnose(std::vector<std::string>(argv + std::min(argc, 2), argv + argc));
  } else if (what == "grass" || what == "grille") {
    const bool g = what == "grass";
    const uint32_t n = argc > 2 ? uint32_t(std::stoul(argv[2])) : g ? 250000u : 256u;
    const double c0 = process_cpu_seconds();
    Mesh mesh = g ? grass(n) : grille(n);
    ground_scene(what.c_str(), std::move(mesh), process_cpu_seconds() - c0);
  } else {
    std::fprintf(stderr, "usage: bench_filter assets|diagnose [names...] | grass [blades] | grille [bars]\n");
    return 2;
  }
  return 0;
}
