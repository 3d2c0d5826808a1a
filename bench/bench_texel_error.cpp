// bench_texel_error — the per-texel AO error of lightmap bakes (`prtbake texel`, /lightmap/ao) against
// a reference made of two independent QMC bakes of the same texels (issue 30: texels per second per
// core at equal error; the driver is bench/texel_rate.sh, which bakes the files and times them).
//
// The reference is r = (A + B)/2, A and B QMC bakes with different seeds (independent per-texel
// randomisations, prtbake's rows are keyed by (seed, texel row)). Its own noise is not negligible
// next to an error of 1e-3, so it is taken out: with d = c − r the difference of a bake c
// (independent of A and B: another seed, or a deterministic integrator), E[d²] = e² + var(r) and
// E[(A − B)²/4] = var(r), so
//     e² ≈ mean over texels of  d² − (A − B)²/4
// is an unbiased estimate of the bake's mean squared error against the exact values. Its standard
// error is the terms' standard deviation over √(texels) (per-texel randomisations are independent;
// a deterministic integrator's bias is the same in every term, which only makes this conservative
// where the bias is spatially smooth); the RMSE's is that over 2e (delta method). The RMSE is
// printed as 0 when the estimate is below zero (a bake at the reference's noise). Texels compared:
// every texel whose state is 1 (baked: its shade point integrated, not filled, padded or
// stitched; the driver bakes with --no-stitch) in all three files, whose state and shade points
// must be the same bit for bit (same mesh, UV set and resolution), else the file is refused.
//
//   bench_texel_error REF_A.prt.h5 REF_B.prt.h5 FILE.prt.h5...
//       reference <texels> noise=<RMS of (A − B)/2, r's own noise> a_vs_b=<RMS of A − B>
//       file <path> plan=<integrator>:<samples> texels=<n> rmse=<e> se=<its std error> raw=<RMS of d> max=<max |d|> nonfinite=<n>
//   bench_texel_error --arch-obj CELLS OUT.obj
//       writes the generated architectural scene (tests/common/arch_scene.h) as an OBJ
//       (positions as %.9g: exact for float), so prtbake can bake it.
#include <arch_scene.h>
#include <formats/asset.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <stdexcept>
#include <string>
#include <vector>

namespace formats = prt::formats;

namespace {

struct Texels {
  formats::Asset asset;
  const formats::Lightmap& map() const { return *asset.vertices.lightmap; }
  const std::vector<float>& ao() const { return map().ao->values; }
};

Texels read_texels(const std::string& path) {
  Texels t{formats::read_asset(path)};
  const auto& lm = t.asset.vertices.lightmap;
  if (!lm || !lm->ao || lm->ao->values.size() != lm->texel_count() || !lm->positions)
    throw std::runtime_error(path + ": no /lightmap/ao with positions");
  return t;
}

void same_texels(const Texels& a, const Texels& b, const std::string& path) {
  if (a.map().width != b.map().width || a.map().height != b.map().height ||
      a.map().state.values != b.map().state.values || a.map().positions->values != b.map().positions->values)
    throw std::runtime_error(path + ": not the texels of the reference (state or shade points differ)");
}

int write_arch(int cells, const std::string& out) {
  const prt::testing::ArchScene arch = prt::testing::architectural_scene(cells);
  std::FILE* f = std::fopen(out.c_str(), "w");
  if (!f) throw std::runtime_error("cannot write " + out);
  std::fprintf(f, "# tests/common/arch_scene.h at %d cells/m (bench_texel_error --arch-obj)\n", cells);
  for (const auto& p : arch.mesh.positions) std::fprintf(f, "v %.9g %.9g %.9g\n", p.x(), p.y(), p.z());
  for (const auto& t : arch.mesh.triangles) std::fprintf(f, "f %u %u %u\n", t[0] + 1, t[1] + 1, t[2] + 1);
  if (std::fclose(f) != 0) throw std::runtime_error("cannot write " + out);
  std::printf("arch\t%zu triangles\t%zu vertices\n", arch.mesh.triangles.size(), arch.mesh.positions.size());
  return 0;
}

} // namespace

int main(int argc, char** argv) try {
  if (argc == 4 && std::string(argv[1]) == "--arch-obj") return write_arch(std::atoi(argv[2]), argv[3]);
  if (argc < 3) {
    std::fprintf(stderr, "usage: bench_texel_error REF_A.prt.h5 REF_B.prt.h5 FILE.prt.h5... | --arch-obj CELLS OUT.obj\n");
    return 2;
  }
  const Texels a = read_texels(argv[1]), b = read_texels(argv[2]);
  same_texels(a, b, argv[2]);
  std::vector<size_t> rows;  // baked texels
  const std::vector<uint8_t>& state = a.map().state.values;
  for (size_t i = 0; i < state.size(); ++i)
    if (state[i] == 1) rows.push_back(i);
  if (rows.empty()) throw std::runtime_error(std::string(argv[1]) + ": no baked texel");
  const double n = double(rows.size());
  std::vector<double> r(rows.size()), noise2(rows.size());
  double ab2 = 0;
  for (size_t k = 0; k < rows.size(); ++k) {
    const double x = a.ao()[rows[k]], y = b.ao()[rows[k]];
    r[k] = 0.5 * (x + y);
    noise2[k] = 0.25 * (x - y) * (x - y);
    ab2 += (x - y) * (x - y);
  }
  double noise = 0;
  for (const double v : noise2) noise += v;
  std::printf("reference\t%zu\tnoise=%.4g\ta_vs_b=%.4g\n", rows.size(), std::sqrt(noise / n), std::sqrt(ab2 / n));
  for (int i = 3; i < argc; ++i) {
    const Texels c = read_texels(argv[i]);
    same_texels(a, c, argv[i]);
    double sum = 0, sum2 = 0, raw = 0, worst = 0;
    size_t nonfinite = 0;
    for (size_t k = 0; k < rows.size(); ++k) {
      const double v = c.ao()[rows[k]];
      if (!std::isfinite(v)) {
        ++nonfinite;
        continue;
      }
      const double d = v - r[k], term = d * d - noise2[k];
      sum += term, sum2 += term * term, raw += d * d, worst = std::max(worst, std::abs(d));
    }
    const double mean = sum / n, var = std::max(0.0, sum2 / n - mean * mean) / (n - 1);
    const double rmse = std::sqrt(std::max(0.0, mean)), se_mse = std::sqrt(var);
    // The RMSE's standard error: se(e²)/(2e), but at most √se(e²) (e within its noise of 0).
    const double se = rmse > 0 ? std::min(se_mse / (2 * rmse), std::sqrt(se_mse)) : std::sqrt(se_mse);
    const formats::Product& p = *c.map().ao;
    std::printf("file\t%s\tplan=%s:%lld\ttexels=%zu\trmse=%.4g\tse=%.2g\traw=%.4g\tmax=%.4g\tnonfinite=%zu\n", argv[i],
                p.integrator ? p.integrator->c_str() : "?", p.samples ? (long long)*p.samples : -1LL, rows.size(), rmse, se,
                std::sqrt(raw / n), worst, nonfinite);
  }
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "bench_texel_error: %s\n", e.what());
  return 2;
}
