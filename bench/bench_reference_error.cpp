// bench_reference_error — the error of baked files against a converged independent reference, in
// the units of the target error E (bake/bake/choose.h): AO and diffuse transfer as the absolute RMSE
// over every value of the product at the sampled rows, band-1 radiance as that RMSE relative to
// the RMS of the reference values. The driver is bench/default_vs_tuned.sh (issue 27: the default
// bake against hand tuning), which bakes the files with prtbake and calls this once per
// (mesh, environment, product set) with every file baked for it.
//
// The rows: the mesh is loaded as `prtbake vertex` loads it with its default options (file
// normals, no flip, up = y), its shade points are bake::vertex_shade_points (one per row of the
// baked file, docs/ARCHITECTURE.md §3 "Rows"), and `--points` rows are chosen by
// bake::seeded_sample with `--point-seed`. Each file must hold the products asked for, with one
// row per shade point and the mesh's SHA-256 as its source: otherwise the file is named and
// the program fails (exit 2), since its rows would not be the ones integrated here.
//
// The reference: bake::QmcIntegrator (bake/integrators/qmc.h), `--replicates` M independent randomisations
// (seeds `--ref-seed` + j, apart from prtbake's default seed 1; point indices offset by the row
// count, as the error reports do) of `--rays`/M rays per point each, averaged. Its standard error
// per value is the replicates' own: sqrt(sample variance / M), the randomised-QMC estimate (Owen;
// each replicate is an unbiased estimate with an independent Cranley–Patterson rotation). The
// integrator's per-value standard error is the Monte Carlo one, which ignores the Halton
// stratification and overstates QMC's actual error several times; it is printed too ("mc="). Per
// product, in E's units (the RMS over the sampled values of the per-value standard errors,
// relative to the reference RMS for radiance), the replicate estimate must be at most E/3
// (`--target`); when any product's is larger, the reference is integrated again at the rays
// predicted to bring it to E/3.3 (at most twice, up to `--max-rays`), and the output says so
// (raised = 1).
//
// `--geometry` prints only `geometry <hash>`: a 64-bit FNV-1a of the loaded mesh's positions,
// normals and triangles, so the driver can bake identical geometry once.
//
// Output, one tab-separated line each (the driver greps them):
//   reference <rays> <points> <seconds> <raised 0|1> <product>=<std error> ... mc:<product>=<MC std error> ...
//   file <path> plan=<integrator>:<samples> <product>=<error> ...
// Products are named ao, transfer, radiance.
//
// With `--truth TRUTH.prt.h5` (a bake of the same mesh and products by a converged integrator, e.g.
// prtbake's silhouette integrator at N = 1024, whose own error is 0.05–0.15 E): each FILE's errors are
// those over ALL its rows against TRUTH — AO and transfer absolute, radiance relative to the RMS
// of TRUTH's radiance over all rows, the whole-mesh quantities E is defined on — instead of the
// sampled rows' (whose 20-row RMSE, and a radiance RMS over 20 rows where half a mesh may see no
// sky, vary by tens of percent from sample to sample). TRUTH itself is checked against the
// independent QMC reference on the sampled rows:
//   truth <path> plan=<integrator>:<samples> <product>=<error at the sampled rows, E's units of the file line>
// which must stay within the reference's own noise (the `reference` line) for TRUTH to stand.
//
// With `--cache PATH` the reference (its rays, rows, values and standard errors) is read from PATH
// when PATH holds one for the same rows, seeds and layout, else integrated and written there, so
// the driver can measure each rung of a ladder as it is baked without integrating it again.
//
//   bench_reference_error MESH [--ao] [--transfer L] [--radiance ENV] [--target E] [--points K] [--per-row]
//                         [--point-seed S] [--rays R] [--max-rays R] [--ref-seed S] [--replicates M]
//                         [--cache PATH] [--truth TRUTH.prt.h5] FILE.prt.h5...
//   bench_reference_error MESH --geometry
#include <bake/bake/vertex_bake.h>
#include <bake/environment/envmap.h>
#include <bake/integrators/products.h>
#include <bake/integrators/qmc.h>
#include <bake/mesh/mesh.h>
#include <formats/asset.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace bake = prt::bake;
namespace formats = prt::formats;

namespace {

struct Args {
  std::string mesh, environment;
  bool ao = false;
  int transfer = 0;
  double target = 1e-3;
  size_t points = 24;
  uint64_t point_seed = 27;
  uint32_t rays = 1u << 18, max_rays = 1u << 22;
  uint64_t ref_seed = 0x27271;
  uint32_t replicates = 4;
  bool geometry = false;
  bool per_row = false;  // --per-row: also each sampled row's error (`row <file> <row> <product>=<RMSE>`)
  std::string cache;
  std::string truth;  // --truth: errors over all rows against this file
  std::vector<std::string> files;
};

[[noreturn]] void usage(const std::string& why) {
  std::fprintf(stderr,
               "bench_reference_error: %s\nusage: bench_reference_error MESH [--ao] [--transfer L] [--radiance ENV] "
               "[--target E] [--points K] [--per-row] [--point-seed S] [--rays R] [--max-rays R] [--ref-seed S] [--replicates M] [--cache PATH] [--truth TRUTH.prt.h5] FILE.prt.h5... | MESH --geometry\n",
               why.c_str());
  std::exit(2);
}

Args parse(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string s = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage(s + " needs a value");
      return argv[++i];
    };
    if (s == "--ao") a.ao = true;
    else if (s == "--transfer") a.transfer = std::stoi(value());
    else if (s == "--radiance") a.environment = value();
    else if (s == "--target") a.target = std::stod(value());
    else if (s == "--points") a.points = std::stoul(value());
    else if (s == "--per-row") a.per_row = true;
    else if (s == "--point-seed") a.point_seed = std::stoull(value());
    else if (s == "--rays") a.rays = uint32_t(std::stoul(value()));
    else if (s == "--max-rays") a.max_rays = uint32_t(std::stoul(value()));
    else if (s == "--ref-seed") a.ref_seed = std::stoull(value());
    else if (s == "--cache") a.cache = value();
    else if (s == "--truth") a.truth = value();
    else if (s == "--replicates") a.replicates = uint32_t(std::stoul(value()));
    else if (s == "--geometry") a.geometry = true;
    else if (s.starts_with("--")) usage("unknown option " + s);
    else if (a.mesh.empty()) a.mesh = s;
    else a.files.push_back(s);
  }
  if (a.mesh.empty()) usage("no mesh");
  if (a.geometry) return a;
  if (!a.ao && a.transfer == 0 && a.environment.empty()) usage("no product");
  if (a.points == 0 || a.replicates < 2 || a.rays < a.replicates || !(a.target > 0))
    usage("--points, --target must be positive, --replicates at least 2, --rays at least the replicates");
  return a;
}

// One product's place in a row of the libbake layout and in the file.
struct Slot {
  const char* name;
  size_t offset = 0, count = 0;
  bool relative = false;  // band-1 radiance: RMSE relative to the reference RMS
  const std::optional<formats::Product> formats::VertexSet::*dataset = nullptr;
};

std::vector<Slot> slots_of(const bake::ProductLayout& layout) {
  std::vector<Slot> s;
  if (layout.ao_count) s.push_back({"ao", layout.ao, layout.ao_count, false, &formats::VertexSet::ao});
  if (layout.transfer_count)
    s.push_back({"transfer", layout.transfer, layout.transfer_count, false, &formats::VertexSet::transfer_diffuse});
  if (layout.radiance_count)
    s.push_back({"radiance", layout.radiance, layout.radiance_count, true, &formats::VertexSet::radiance_band1});
  return s;
}

// The cache file: a header that identifies the reference, then the values and standard errors.
struct CacheHeader {
  char magic[8] = {'p', 'r', 't', 'r', 'e', 'f', '2', '7'};
  uint64_t rows = 0, width = 0, point_seed = 0, ref_seed = 0, first_rays = 0, replicates = 0, rays = 0, raised = 0;
  double target = 0, seconds = 0;
  uint64_t row_sum = 0;  // a check on the sampled rows
};

bool read_cache(const std::string& path, CacheHeader& want, std::vector<double>& ref, std::vector<double>& se,
                std::vector<double>& mc) {
  std::FILE* f = path.empty() ? nullptr : std::fopen(path.c_str(), "rb");
  if (!f) return false;
  CacheHeader h;
  bool ok = std::fread(&h, sizeof h, 1, f) == 1 && std::memcmp(h.magic, want.magic, 8) == 0 && h.rows == want.rows &&
            h.width == want.width && h.point_seed == want.point_seed && h.ref_seed == want.ref_seed &&
            h.first_rays == want.first_rays && h.replicates == want.replicates && h.target == want.target && h.row_sum == want.row_sum;
  ok = ok && std::fread(ref.data(), sizeof(double), ref.size(), f) == ref.size() &&
       std::fread(se.data(), sizeof(double), se.size(), f) == se.size() &&
       std::fread(mc.data(), sizeof(double), mc.size(), f) == mc.size();
  std::fclose(f);
  if (ok) want = h;
  return ok;
}

void write_cache(const std::string& path, const CacheHeader& h, const std::vector<double>& ref,
                 const std::vector<double>& se, const std::vector<double>& mc) {
  if (path.empty()) return;
  const std::string tmp = path + ".tmp";
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) throw std::runtime_error("cannot write " + tmp);
  const bool ok = std::fwrite(&h, sizeof h, 1, f) == 1 && std::fwrite(ref.data(), sizeof(double), ref.size(), f) == ref.size() &&
                  std::fwrite(se.data(), sizeof(double), se.size(), f) == se.size() &&
                  std::fwrite(mc.data(), sizeof(double), mc.size(), f) == mc.size();
  if (std::fclose(f) != 0 || !ok || std::rename(tmp.c_str(), path.c_str()) != 0)
    throw std::runtime_error("cannot write " + path);
}

uint64_t fnv1a(uint64_t h, const void* data, size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 0x100000001b3ull;
  return h;
}

double rms(std::span<const double> v) {
  double s = 0;
  for (const double x : v) s += x * x;
  return v.empty() ? 0.0 : std::sqrt(s / double(v.size()));
}

} // namespace

int main(int argc, char** argv) try {
  const Args a = parse(argc, argv);

  const bake::Mesh mesh = bake::load_mesh(a.mesh);  // prtbake vertex's defaults
  if (a.geometry) {
    uint64_t h = 0xcbf29ce484222325ull;
    for (const Eigen::Vector3f& p : mesh.positions) h = fnv1a(h, p.data(), 3 * sizeof(float));
    for (const Eigen::Vector3f& n : mesh.normals) h = fnv1a(h, n.data(), 3 * sizeof(float));
    h = fnv1a(h, mesh.triangles.data(), mesh.triangles.size() * sizeof(mesh.triangles[0]));
    h = fnv1a(h, mesh.origin.data(), 3 * sizeof(double));
    std::printf("geometry\t%016llx\n", (unsigned long long)h);
    return 0;
  }
  const bake::Topology topo = bake::build_topology(mesh);
  std::optional<bake::EnvMap> env;
  if (!a.environment.empty()) env = bake::EnvMap::load(a.environment, bake::UpAxis::Y);
  bake::ProductRequest req;
  req.ao = a.ao;
  req.transfer_order = a.transfer;
  req.radiance = env ? &*env : nullptr;
  const bake::ProductLayout layout(req);
  const std::vector<Slot> slots = slots_of(layout);
  const size_t W = layout.width;

  const std::vector<bake::ShadePoint> points = bake::vertex_shade_points(mesh, topo);
  const std::vector<uint32_t> rows = bake::seeded_sample(uint32_t(points.size()), a.points, a.point_seed);
  const size_t K = rows.size();

  // The reference, raised 4x while its own noise is above E/3 for some product.
  std::vector<double> ref(K * W), se(K * W), mc(K * W), ref_rms(slots.size()), ref_se(slots.size()),
      mc_se(slots.size());
  uint32_t rays = a.rays;
  bool raised = false;
  int raises = 0;
  double seconds = 0;
  CacheHeader cached;
  cached.rows = K, cached.width = W, cached.point_seed = a.point_seed, cached.ref_seed = a.ref_seed;
  cached.first_rays = a.rays, cached.replicates = a.replicates, cached.target = a.target;
  for (const uint32_t r : rows) cached.row_sum = cached.row_sum * 1000003u + r;
  const bool from_cache = read_cache(a.cache, cached, ref, se, mc);
  if (from_cache) rays = uint32_t(cached.rays), raised = cached.raised != 0, seconds = cached.seconds;
  for (;;) {
    if (!from_cache) {
      // M replicates of rays/M each; ref = their mean, se = sqrt(var/M), mc = the integrator's
      // own (Monte Carlo) standard error of the mean.
      const uint32_t M = a.replicates, per = rays / M;
      std::vector<double> sum(K * W, 0.0), sum2(K * W, 0.0), mc2(K * W, 0.0);
      const auto t0 = std::chrono::steady_clock::now();
      for (uint32_t j = 0; j < M; ++j) {
        const bake::QmcIntegrator reference(mesh, topo, req, bake::QmcOptions{per, a.ref_seed + j});
        tbb::parallel_for(size_t(0), K, [&](size_t i) {
          std::vector<double> v(W), e(W);
          reference.integrate(points[rows[i]], uint64_t(rows[i]) + points.size(), v, e);
          for (size_t c = 0; c < W; ++c) {
            sum[i * W + c] += v[c];
            sum2[i * W + c] += v[c] * v[c];
            mc2[i * W + c] += e[c] * e[c];
          }
        });
      }
      seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      for (size_t x = 0; x < K * W; ++x) {
        ref[x] = sum[x] / M;
        const double var = std::max(0.0, (sum2[x] - M * ref[x] * ref[x]) / (M - 1));
        se[x] = std::sqrt(var / M);
        mc[x] = std::sqrt(mc2[x]) / M;
      }
    }
    bool noisy = false;
    for (size_t p = 0; p < slots.size(); ++p) {
      std::vector<double> r, e, m;
      for (size_t i = 0; i < K; ++i)
        for (size_t c = 0; c < slots[p].count; ++c) {
          r.push_back(ref[i * W + slots[p].offset + c]);
          e.push_back(se[i * W + slots[p].offset + c]);
          m.push_back(mc[i * W + slots[p].offset + c]);
        }
      ref_rms[p] = rms(r);
      ref_se[p] = rms(e) / (slots[p].relative ? ref_rms[p] : 1.0);
      mc_se[p] = rms(m) / (slots[p].relative ? ref_rms[p] : 1.0);
      if (!(ref_se[p] <= a.target / 3)) noisy = true;
    }
    if (from_cache || !noisy || rays >= a.max_rays || raises == 2) break;
    // The rays that bring the noisiest product to E/3.3 at rate 0.75 (randomised QMC measured
    // ~0.7 on the bunny, bake/bake/choose.h; the Monte Carlo rate 0.5 would overshoot ~2x), a power of
    // two within --max-rays; the pass above is discarded. At most twice.
    double worst = 0;
    for (size_t p = 0; p < slots.size(); ++p) worst = std::max(worst, ref_se[p] / (a.target / 3.3));
    uint64_t next = uint64_t(rays) * 2;
    while (next < a.max_rays && double(next) < double(rays) * std::pow(worst, 1 / 0.75)) next *= 2;
    rays = uint32_t(std::min<uint64_t>(next, a.max_rays));
    raised = true;
    ++raises;
    raised = true;
  }
  if (!from_cache) {
    cached.rays = rays, cached.raised = raised ? 1 : 0, cached.seconds = seconds;
    write_cache(a.cache, cached, ref, se, mc);
  }
  std::printf("reference\t%u\t%zu\t%.3f\t%d", rays, K, seconds, raised ? 1 : 0);
  for (size_t p = 0; p < slots.size(); ++p) std::printf("\t%s=%.4g", slots[p].name, ref_se[p]);
  for (size_t p = 0; p < slots.size(); ++p) std::printf("\tmc:%s=%.4g", slots[p].name, mc_se[p]);
  std::printf("\n");

  int status = 0;
  // A baked file of this mesh's rows, or nothing (named on stderr, status 2).
  auto read_rows = [&](const std::string& path) -> std::optional<formats::Asset> {
    formats::Asset asset = formats::read_asset(path);
    const formats::VertexSet& set = asset.vertices;
    if (set.vertex_count() != points.size() || asset.root.source_sha256 != mesh.source_sha256) {
      std::fprintf(stderr, "%s: %zu rows of mesh %s, not the %zu rows of %s (%s)\n", path.c_str(), set.vertex_count(),
                   asset.root.source_sha256.c_str(), points.size(), a.mesh.c_str(), mesh.source_sha256.c_str());
      status = 2;
      return std::nullopt;
    }
    return asset;
  };
  // Product p of a file with its values per row, or null (named on stderr, status 2).
  auto product_of = [&](const formats::Asset& asset, const std::string& path, size_t p) -> const formats::Product* {
    const std::optional<formats::Product>& product = asset.vertices.*(slots[p].dataset);
    if (!product || product->values.size() != points.size() * slots[p].count) {
      std::fprintf(stderr, "%s: no %s of %zu values per row\n", path.c_str(), slots[p].name, slots[p].count);
      status = 2;
      return nullptr;
    }
    return &*product;
  };
  // "<tag>\t<path>\tplan=integrator:samples": the plan as the file's first product records it.
  auto print_head = [&](const char* tag, const formats::Asset& asset, const std::string& path) {
    const formats::Product* first = nullptr;
    for (const Slot& slot : slots)
      if (!first && asset.vertices.*(slot.dataset)) first = &*(asset.vertices.*(slot.dataset));
    std::printf("%s\t%s\tplan=%s:%lld", tag, path.c_str(), first && first->integrator ? first->integrator->c_str() : "?",
                first && first->samples ? (long long)*first->samples : -1LL);
  };
  // The sampled rows' error of product p against the QMC reference (E's units).
  auto sampled_error = [&](const formats::Product& product, size_t p) {
    double sum = 0;
    for (size_t i = 0; i < K; ++i)
      for (size_t c = 0; c < slots[p].count; ++c) {
        const double d = double(product.values[size_t(rows[i]) * slots[p].count + c]) - ref[i * W + slots[p].offset + c];
        sum += d * d;
      }
    const double rmse = std::sqrt(sum / double(K * slots[p].count));
    return slots[p].relative ? rmse / ref_rms[p] : rmse;
  };
  std::optional<formats::Asset> truth;
  std::vector<const formats::Product*> truth_products;  // per slot, when --truth
  if (!a.truth.empty()) {
    truth = read_rows(a.truth);
    if (!truth) return 2;
    print_head("truth", *truth, a.truth);
    for (size_t p = 0; p < slots.size(); ++p) {
      const formats::Product* product = product_of(*truth, a.truth, p);
      if (!product) return 2;
      truth_products.push_back(product);
      std::printf("\t%s=%.4g", slots[p].name, sampled_error(*product, p));
    }
    std::printf("\n");
  }
  for (const std::string& path : a.files) {
    const std::optional<formats::Asset> asset = read_rows(path);
    if (!asset) continue;
    const formats::VertexSet& set = asset->vertices;
    print_head("file", *asset, path);
    for (size_t p = 0; p < slots.size(); ++p) {
      const formats::Product* product = product_of(*asset, path, p);
      if (!product) {
        std::printf("\t%s=nan", slots[p].name);
        continue;
      }
      if (!truth) {
        std::printf("\t%s=%.4g", slots[p].name, sampled_error(*product, p));
        continue;
      }
      // Over every row against the truth; radiance relative to the truth's RMS over every row.
      const std::vector<float>& t = truth_products[p]->values;
      double d2 = 0, t2 = 0;
      for (size_t x = 0; x < t.size(); ++x) {
        const double d = double(product->values[x]) - double(t[x]);
        d2 += d * d, t2 += double(t[x]) * double(t[x]);
      }
      const double rmse = std::sqrt(d2 / double(t.size())), truth_rms = std::sqrt(t2 / double(t.size()));
      std::printf("\t%s=%.4g", slots[p].name, slots[p].relative ? (truth_rms > 0 ? rmse / truth_rms : 0.0) : rmse);
    }
    std::printf("\n");
    for (size_t i = 0; i < K && a.per_row; ++i) {
      std::printf("row\t%s\t%u", path.c_str(), rows[i]);
      for (size_t p = 0; p < slots.size(); ++p) {
        const std::optional<formats::Product>& product = set.*(slots[p].dataset);
        if (!product || product->values.size() != points.size() * slots[p].count) continue;
        double sum = 0;
        for (size_t c = 0; c < slots[p].count; ++c) {
          const double d = double(product->values[size_t(rows[i]) * slots[p].count + c]) - ref[i * W + slots[p].offset + c];
          sum += d * d;
        }
        const double rmse = std::sqrt(sum / double(slots[p].count));
        std::printf("\t%s=%.4g", slots[p].name, slots[p].relative ? rmse / ref_rms[p] : rmse);
      }
      std::printf("\n");
    }
  }
  return status;
} catch (const std::exception& e) {
  std::fprintf(stderr, "bench_reference_error: %s\n", e.what());
  return 2;
}
