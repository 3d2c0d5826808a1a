// bench_shading — run-time shading cost of prtshade (issue 5): per vertex for the diffuse PRT
// dot product transfer · light (orders 3 and 6) and for band-1 shading, and per pixel for FIV
// shading (paper 004 §4.3) with 1, 10 and 100 occluders, the fast path next to its slow
// reference (shade_fiv_reference: double, every pair, acos) in one run.
//
//   BM_ShadeTransfer/order:L        shade_transfer, 4096 vertices per iteration
//   BM_ShadeBand1                   shade_band1, 4096 vertices per iteration
//   BM_ShadeGlossy/order:L          glossy route A (triple product L·U, then the Phong lobe), 4096
//                                   vertices per iteration, prtshade/glossy.h
//   BM_ShadeGlossyReference/order:L route A's slow reference (a double Gaunt pass per vertex)
//   BM_ShadeGlossyRadiance/order:L  glossy route B (the lobe on a baked shadowed radiance S)
//   BM_ShadeFiv/occluders:N         shade_fiv, 4096 receivers per iteration, both corrections on
//   BM_ShadeFivReference/occluders:N  the slow reference on the same inputs
//   BM_ShadeFivNoOverlap/occluders:N  shade_fiv without the overlap correction (its pair-loop share)
//   BM_ShadeFivSurface/occluders:N  shade_fiv on the same scene with surface-following shells
//                                   (prtshade/fiv.h "Surface-following shells", issue 33): the
//                                   same samples, r_surf random in [0.3, 0.9] R, offsets τ_k
//                                   0.005 R … 16 R geometric, no valid mask
//   BM_ShadeFivCones/occluders:N    shade_fiv with the tight proxy (prtshade/fiv.h "Tight proxies"):
//                                   the same scene, every occluder with a cone table (the exact
//                                   cone of a ball of radius 0.7 R on the same grid)
//   BM_ShadeFivSurfaceCones/occluders:N  both, float tables (a --precision float bake)
//   BM_ShadeFivSurfaceConesHalf/occluders:N  both with half-float tables (prtshade/fiv.h "Half-float
//                                   tables"): what a default bake gives
//   BM_ShadeFivTenAssets[Half]/occluders:100  surface + cone, float [half] tables, the occluders
//                                   copies of 10 assets with their own tables (33 MB [16.5 MB])
//
// Counters: `per_item` = CPU seconds per vertex or per pixel (printed with an SI prefix, e.g.
// "2.1ns"). Single thread. Synthetic data, seeded: random transfer/radiance rows; FIV shells of
// the paper's 64x33x30 size (Nφ × Nθ × Nρ, radii 0.5 R … 16 R, 2.3 MB) shared by all occluders
// (instances of one baked asset, as a forest of one tree), occluders of radius 1 scattered over a
// 40 × 40 area from 1.5 below to 4 units above a ground plane, receivers on the plane inside it (normal +Y), so
// occluders are in cases A, B and C and many pairs overlap; a 32² DifMap. With 100 occluders a
// receiver has ~93 that hide something and ~129 overlapping pairs, and they hide far more than
// E_tot (Σ I ≈ 21.7 against E_tot ≈ 5.7, red channel, mean over the 4096 receivers), so every
// output clamps to 0; no path looks at that.
#include <prtshade/fiv.h>
#include <prtshade/glossy.h>
#include <prtshade/shade.h>

#include <Imath/half.h>
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <vector>

namespace {

constexpr int kItems = 4096;

void per_item(benchmark::State& state) {
  state.SetItemsProcessed(int64_t(state.iterations()) * kItems);
  state.counters["per_item"] =
      benchmark::Counter(double(kItems), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

std::vector<float> normal_floats(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> g;
  std::vector<float> v(n);
  for (float& x : v) x = g(rng);
  return v;
}

void BM_ShadeTransfer(benchmark::State& state) {
  const int order = int(state.range(0)), n = order * order;
  const std::vector<float> transfer = normal_floats(size_t(kItems) * size_t(n), 1);
  const std::vector<float> light = normal_floats(size_t(3 * n), 2);
  std::vector<float> out(size_t(3 * kItems));
  for (auto _ : state) {
    for (int v = 0; v < kItems; ++v) prt::shade::shade_transfer(transfer.data() + size_t(v) * size_t(n), order, light.data(), out.data() + 3 * v);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  per_item(state);
}
BENCHMARK(BM_ShadeTransfer)->ArgName("order")->Arg(3)->Arg(6);

// Glossy: per vertex, a fixed eye, normals and positions from the seeded rows, Phong s = 24.
void BM_ShadeGlossy(benchmark::State& state) {
  const int order = int(state.range(0)), n = order * order;
  const prt::shade::TripleProduct tp(order);
  const std::vector<float> visibility = normal_floats(size_t(kItems) * size_t(n), 1);
  const std::vector<float> light = normal_floats(size_t(3 * n), 2);
  std::vector<float> normals = normal_floats(size_t(3 * kItems), 3), positions = normal_floats(size_t(3 * kItems), 4);
  for (int v = 0; v < kItems; ++v) {
    float* nv = normals.data() + 3 * v;
    const float len = std::sqrt(nv[0] * nv[0] + nv[1] * nv[1] + nv[2] * nv[2]);
    for (int c = 0; c < 3; ++c) nv[c] /= len;
  }
  const float eye[3] = {0, 2, 10};
  std::vector<float> out(size_t(3 * kItems));
  const prt::shade::GlossyLight lit(tp, light.data());
  for (auto _ : state) {
    prt::shade::shade_glossy_vertices(lit, visibility.data(), normals.data(), positions.data(), kItems, eye, 24.0, out.data());
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  per_item(state);
  state.counters["gaunt_entries"] = double(tp.entries().size());
}
BENCHMARK(BM_ShadeGlossy)->ArgName("order")->Arg(3)->Arg(5)->Arg(7)->Arg(9)->Arg(11);

// One vertex at a time with a fixed reflection direction and Phong 24: shade(v, scales, r, out_v).
template <class Shade>
void per_vertex_glossy(benchmark::State& state, int order, Shade&& shade) {
  double scales[prt::shade::kMaxGlossyOrder];
  prt::shade::phong_band_scales(24.0, order, scales);
  const float r[3] = {0.48f, 0.6f, 0.64f};
  std::vector<float> out(size_t(3 * kItems));
  for (auto _ : state) {
    for (int v = 0; v < kItems; ++v) shade(size_t(v), scales, r, out.data() + 3 * v);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  per_item(state);
}

// The slow reference of route A (a double Gaunt pass per channel per vertex), same inputs.
void BM_ShadeGlossyReference(benchmark::State& state) {
  const int order = int(state.range(0)), n = order * order;
  const prt::shade::TripleProduct tp(order);
  const std::vector<float> visibility = normal_floats(size_t(kItems) * size_t(n), 1);
  const std::vector<float> light = normal_floats(size_t(3 * n), 2);
  per_vertex_glossy(state, order, [&](size_t v, const double* scales, const float* r, float* out) {
    prt::shade::shade_glossy(tp, light.data(), visibility.data() + v * size_t(n), scales, r, out);
  });
}
BENCHMARK(BM_ShadeGlossyReference)->ArgName("order")->Arg(3)->Arg(7)->Arg(11);

void BM_ShadeGlossyRadiance(benchmark::State& state) {
  const int order = int(state.range(0)), n = order * order;
  const std::vector<float> shadowed = normal_floats(size_t(kItems) * size_t(3 * n), 5);
  per_vertex_glossy(state, order, [&](size_t v, const double* scales, const float* r, float* out) {
    prt::shade::shade_glossy_radiance(shadowed.data() + v * size_t(3 * n), order, scales, r, out);
  });
}
BENCHMARK(BM_ShadeGlossyRadiance)->ArgName("order")->Arg(3)->Arg(5)->Arg(7)->Arg(9)->Arg(11);

void BM_ShadeBand1(benchmark::State& state) {
  std::vector<float> normals = normal_floats(size_t(3 * kItems), 3);
  for (int v = 0; v < kItems; ++v) {
    float* nv = normals.data() + 3 * v;
    const float len = std::sqrt(nv[0] * nv[0] + nv[1] * nv[1] + nv[2] * nv[2]);
    for (int a = 0; a < 3; ++a) nv[a] /= len;
  }
  const std::vector<float> radiance = normal_floats(size_t(9 * kItems), 4);
  std::vector<float> out(size_t(3 * kItems));
  for (auto _ : state) {
    for (int v = 0; v < kItems; ++v) prt::shade::shade_band1(normals.data() + 3 * v, radiance.data() + 9 * v, out.data() + 3 * v);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  per_item(state);
}
BENCHMARK(BM_ShadeBand1);

struct FivScene {
  int n_phi = 64, n_theta = 33, n_rho = 30;
  std::vector<float> radii, shells, cube, positions, surface, offsets, cones;
  std::vector<uint16_t> shells_half, cones_half;
  std::vector<uint8_t> valid;
  std::vector<prt::shade::FivOccluder> occluders;

  // assets: the occluders are copies of that many baked assets (occluder i of asset i mod assets),
  // each with its own tables in memory (the same values): 1 = a forest of one tree.
  explicit FivScene(int count, bool surface_scheme = false, bool with_cones = false, bool half_tables = false,
                    int assets = 1) {
    std::mt19937 rng(42);
    std::uniform_real_distribution<float> u01(0, 1);
    for (int k = 0; k < n_rho; ++k) radii.push_back(0.5f * std::pow(32.0f, float(k) / float(n_rho - 1)));
    const size_t samples = size_t(n_rho) * size_t(n_theta) * size_t(n_phi);
    shells.resize(samples * 9);
    for (float& x : shells) x = u01(rng);
    valid.assign(samples, 1);
    for (size_t s = 0; s < size_t(n_theta) * size_t(n_phi); ++s) valid[s] = uint8_t(u01(rng) > 0.3f);  // inner shell partly inside
    cube.resize(size_t(6 * 32 * 32 * 3));
    for (float& x : cube) x = 5 + u01(rng);
    // The cone of a ball of radius r = 0.7 (inside the bounding radius 1) from each sample.
    for (int k = 0; k < n_rho; ++k)
      for (int i = 0; i < n_theta; ++i)
        for (int j = 0; j < n_phi; ++j) {
          const double th = std::numbers::pi * i / (n_theta - 1), ph = 2 * std::numbers::pi * j / n_phi, rho = radii[size_t(k)];
          const double sa = std::min(1.0, 0.7 / rho), ca = std::sqrt(1 - sa * sa), len = std::numbers::pi * sa * sa;
          const double d[3] = {std::sin(th) * std::sin(ph), std::cos(th), std::sin(th) * std::cos(ph)};
          for (int e = 0; e < 3; ++e) cones.push_back(float(-len * d[e]));
          cones.push_back(float(2 * std::numbers::pi * (1 - ca)));
        }
    const std::vector<float> one_shells = shells, one_cones = cones;
    for (int a = 1; a < assets; ++a) {
      shells.insert(shells.end(), one_shells.begin(), one_shells.end());
      cones.insert(cones.end(), one_cones.begin(), one_cones.end());
    }
    for (int i = 0; i < count; ++i) {
      const float c[3] = {40 * u01(rng) - 20, 5.5f * u01(rng) - 1.5f, 40 * u01(rng) - 20};
      const size_t asset = size_t(i % assets);
      prt::shade::FivOccluder o{{c[0], c[1], c[2]}, 1.0f, n_rho, n_theta, n_phi, radii.data(),
                                shells.data() + asset * samples * 9, valid.data()};
      o.cones = with_cones ? cones.data() + asset * samples * 4 : nullptr;
      occluders.push_back(o);
    }
    if (surface_scheme) {  // drawn after everything above, so the scene is the same
      for (int k = 0; k < n_rho; ++k) offsets.push_back(0.005f * std::pow(3200.0f, float(k) / float(n_rho - 1)));
      surface.resize(size_t(n_theta) * size_t(n_phi));
      for (float& r : surface) r = 0.3f + 0.6f * u01(rng);
      for (prt::shade::FivOccluder& o : occluders) {
        o.radial_scheme = prt::shade::kFivRadialSurface;
        o.radii = offsets.data();
        o.surface_radius = surface.data();
      }
    }
    if (half_tables) {  // the same values rounded to binary16 (Imath::half, as the bake rounds them)
      for (float v : shells) shells_half.push_back(Imath::half(v).bits());
      for (float v : cones) cones_half.push_back(Imath::half(v).bits());
      for (prt::shade::FivOccluder& o : occluders) {
        o.shells_half = shells_half.data() + (o.shells - shells.data()), o.shells = nullptr;
        if (o.cones) o.cones_half = cones_half.data() + (o.cones - cones.data()), o.cones = nullptr;
      }
    }
    for (int p = 0; p < kItems; ++p) {
      positions.push_back(40 * u01(rng) - 20);
      positions.push_back(0);
      positions.push_back(40 * u01(rng) - 20);
    }
  }
};

enum class FivPath { fast, reference };

template <FivPath kPath, bool kOverlap = true, bool kSurface = false, bool kCones = false, bool kHalf = false,
          int kAssets = 1>
void shade_fiv_case(benchmark::State& state) {
  const FivScene scene(int(state.range(0)), kSurface, kCones, kHalf, kAssets);
  const prt::shade::DifMap map{32, scene.cube.data()};
  const float n[3] = {0, 1, 0};
  const prt::shade::FivShadeOptions options{true, kOverlap};
  std::vector<float> out(size_t(3 * kItems));
  for (auto _ : state) {
    for (int p = 0; p < kItems; ++p) {
      const float* pos = scene.positions.data() + 3 * p;
      const int count = int(scene.occluders.size());
      if constexpr (kPath == FivPath::reference)
        prt::shade::shade_fiv_reference(map, scene.occluders.data(), count, pos, n, options, out.data() + 3 * p);
      else
        prt::shade::shade_fiv(map, scene.occluders.data(), count, pos, n, options, out.data() + 3 * p);
    }
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  per_item(state);
}
void BM_ShadeFiv(benchmark::State& state) { shade_fiv_case<FivPath::fast>(state); }
void BM_ShadeFivReference(benchmark::State& state) { shade_fiv_case<FivPath::reference>(state); }
void BM_ShadeFivNoOverlap(benchmark::State& state) { shade_fiv_case<FivPath::fast, false>(state); }
void BM_ShadeFivCones(benchmark::State& state) { shade_fiv_case<FivPath::fast, true, false, true>(state); }
void BM_ShadeFivConesReference(benchmark::State& state) { shade_fiv_case<FivPath::reference, true, false, true>(state); }
BENCHMARK(BM_ShadeFiv)->ArgName("occluders")->Arg(1)->Arg(10)->Arg(100);
BENCHMARK(BM_ShadeFivReference)->ArgName("occluders")->Arg(1)->Arg(10)->Arg(100);
BENCHMARK(BM_ShadeFivNoOverlap)->ArgName("occluders")->Arg(10)->Arg(100);
void BM_ShadeFivSurface(benchmark::State& state) { shade_fiv_case<FivPath::fast, true, true>(state); }
void BM_ShadeFivSurfaceCones(benchmark::State& state) { shade_fiv_case<FivPath::fast, true, true, true>(state); }
BENCHMARK(BM_ShadeFivSurface)->ArgName("occluders")->Arg(1)->Arg(10)->Arg(100);
BENCHMARK(BM_ShadeFivCones)->ArgName("occluders")->Arg(10)->Arg(100);
BENCHMARK(BM_ShadeFivConesReference)->ArgName("occluders")->Arg(10)->Arg(100);
BENCHMARK(BM_ShadeFivSurfaceCones)->ArgName("occluders")->Arg(10)->Arg(100);
void BM_ShadeFivSurfaceConesHalf(benchmark::State& state) { shade_fiv_case<FivPath::fast, true, true, true, true>(state); }
BENCHMARK(BM_ShadeFivSurfaceConesHalf)->ArgName("occluders")->Arg(10)->Arg(100);
// The same 100 occluders as copies of 10 assets, each with its own tables: 33 MB of float tables
// (beyond a 32 MB L3), 16.5 MB of half ones.
void BM_ShadeFivTenAssets(benchmark::State& state) { shade_fiv_case<FivPath::fast, true, true, true, false, 10>(state); }
void BM_ShadeFivTenAssetsHalf(benchmark::State& state) { shade_fiv_case<FivPath::fast, true, true, true, true, 10>(state); }
BENCHMARK(BM_ShadeFivTenAssets)->ArgName("occluders")->Arg(100);
BENCHMARK(BM_ShadeFivTenAssetsHalf)->ArgName("occluders")->Arg(100);

} // namespace

BENCHMARK_MAIN();
