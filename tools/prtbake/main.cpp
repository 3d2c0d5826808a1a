// prtbake — bakes precomputed radiance transfer assets. A thin shell: it parses arguments,
// reports progress and calls libbake (integration) and formats (the HDF5 file).
#include <bake/envmap.h>
#include <bake/error.h>
#include <bake/fiv.h>
#include <bake/mesh.h>
#include <bake/qmc.h>
#include <bake/sampling.h>
#include <bake/sha256.h>
#include <bake/silhouette.h>
#include <bake/scene.h>
#include <bake/vertex_bake.h>
#include <formats/asset.h>
#include <prtshade/sh.h>

#include "bakefile.h"
#include "progress_bar.h"
#include "tool_main.h"

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/info.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <string>
#include <unistd.h>
#include <vector>

namespace fs = std::filesystem;
using namespace prt;

namespace {

constexpr const char* kVersion = "0.1.0";

constexpr const char* kHelp = R"(prtbake — bake precomputed radiance transfer (PRT) data for game geometry

USAGE
  prtbake vertex MESH -o OUT.prt.h5 [PRODUCTS] [OPTIONS]
  prtbake fiv OCCLUDER --env ENV.exr -o OUT.prt.h5 [--shells 128x65x30] [--cube 16] [OPTIONS]
  prtbake scene SCENE.json -o OUT.prt.h5 [--dry-run] [--report N] [--threads T] [--quiet]
  prtbake --help | --version

  Bakes per-vertex products for every vertex of MESH (OBJ, PLY, OFF, STL) in one pass: the
  rays cast from a vertex serve every product at once. Rows follow the file's vertex order;
  a position with several normals in the file (OBJ v//vn hard edges) gives one row per
  (position, normal) pair, and /mesh/source_position says which file vertex each row is.

  fiv bakes an occluder's Fullsphere Irradiance Vectors (paper 004): the environment's FIV
  F_env = Int L w dw, the diffuse irradiance cube map (DifMap) E(n) = Int L H (n.w) dw (exact,
  not SH9), and the occluded FIV F(s) = Int (1 - V(s,w)) L w dw on concentric shells around the
  occluder's bounding sphere: --shells NPHIxNTHETAxNRHO (poles included in NTHETA), radii from
  half the bounding radius outwards, stopping once |F| < --fraction (default 1e-3) of Int L dw.
  --cube S sets the DifMap resolution (default 16); --samples k the silhouette rate (128^2).

  scene bakes a scene file (JSON: objects with mesh, transform, material and role receiver /
  occluder / both; one environment; what may be baked — see data/scene_example.json and the
  README) and bakes only what the scene needs, printing what it leaves out and why:
  occluder-only objects get no per-vertex products; a diffuse receiver gets band-1 radiance
  under the environment (exact) and no higher order, or diffuse transfer at the order the SH
  tolerance needs when there is no environment (or "relight"); a glossy (Phong) receiver gets
  visibility transfer at the smallest order whose lobe energy beyond it is under the tolerance;
  no radiance or FIV without an environment; FIV shells only for occluders that can shadow
  another receiver; vertices that see no contour edge get closed forms. --dry-run prints the
  plan and stops. Per-object results go under /objects/<name>/ in the file.

PRODUCTS of vertex (at least one)
  --ao               ambient occlusion  A = 1/pi * Int V H (n.w) dw, in [0,1]
  --transfer L       diffuse transfer vectors T_i = 1/pi * Int V H (n.w) y_i dw, SH order L
                     (L bands, L*L coefficients; shade with albedo * sum_i T_i L_i)
  --visibility L     visibility transfer vectors U_i = Int V H y_i dw, SH order L (glossy,
                     triple products)
  --radiance ENV     band-1 shadowed radiance R_c,m = Int L_c V H y_1m dw from the HDR
                     environment ENV (OpenEXR lat-long or cube map): exact all-frequency
                     diffuse shadows with 3 coefficients per channel. Irradiance at the
                     baked normal n: E = 4pi/3 * sum_m y_1m(n) R_m.

OPTIONS
  -o, --output FILE  the .prt.h5 file to write (HDF5; see formats/SCHEMA.md). Written to a
                     temporary file first and renamed, so FILE is never half-written.
  --integrator NAME  silhouette (default): semi-analytic visibility silhouettes (paper 001
                     §3): contour edges, depth complexity along octahedral u-isolines,
                     summed-area tables. Deterministic; error falls with k, no noise.
                     qmc: Embree ray casting, importance-sampled randomised Halton QMC, the
                     baseline and the reference.
  --samples N        silhouette: k = N, the number of spherical samples (sqrt(k) u-isolines,
                     rounded to even; default 16384 = 128^2; 64^2 to 256^2 converge for HDR
                     environments). qmc: rays per vertex (default 1024); the error falls like
                     1/sqrt(N) or faster.
  --seed S           randomisation seed (default 1). Same inputs and seed give identical
                     bytes whatever --threads is.
  --threads T        worker threads (default: all cores).
  --up y|z           the scene's up axis (default y). With z (Blender), scene direction
                     (x,y,z) is looked up in the environment as (x,z,-y).
  --no-file-normals  ignore normals in the mesh file; use angle-weighted vertex normals.
  --report N         after the bake, re-integrate N seeded vertices with a converged QMC
                     reference (10x the bake's rays for qmc, 65536 rays for silhouette) and
                     print/store the error (RMSE, max) next to the run time (default 32;
                     0 turns it off). Stored under /report in the file.
  --reproducible     make the file a pure function of the inputs: 'created' is pinned to
                     SOURCE_DATE_EPOCH (or 0) and measured wall times are printed but not
                     stored. Implied when SOURCE_DATE_EPOCH is set (reproducible-builds.org).
                     The baked values are identical with or without it.
  --quiet            print nothing but errors.
  -h, --help         this text.   --version   the version.

EXAMPLES
  prtbake vertex data/bunny_ground.obj --ao --transfer 3 --radiance data/sunset.exr -o bunny.prt.h5
  prtbake vertex asset.obj --visibility 6 --samples 4096 --threads 8 -o asset.prt.h5
  prtbake fiv data/bunny.obj --env data/forest.exr --shells 64x33x30 -o bunny.fiv.prt.h5
  prtbake scene data/scene_example.json -o scene.prt.h5
  prtdump bunny.prt.h5            # what was baked, statistics, the error report

)";

using tool::UsageError;

template <class T> T parse_number(const std::string& opt, const std::string& s, T lo, T hi) {
  T v{};
  auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || p != s.data() + s.size() || v < lo || v > hi)
    throw UsageError(opt + " expects an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                     "], got '" + s + "'");
  return v;
}

struct Args {
  std::string command, mesh, output, radiance, integrator = "silhouette";
  bool ao = false, quiet = false, file_normals = true, reproducible = false, dry_run = false, report_given = false;
  std::vector<std::string> given;  // the options given (for commands that accept only some)
  int transfer = 0, visibility = 0;
  uint32_t samples = 0, report = 32;  // samples 0: the integrator's default
  uint64_t seed = 1;
  int threads = 0;
  bake::UpAxis up = bake::UpAxis::Y;
  int n_phi = 128, n_theta = 65, n_rho = 30, cube = 16;  // fiv
  double fraction = 1e-3;
  std::string command_line;  // what determines the file's contents (no --threads/--quiet)
};

Args parse(int argc, char** argv) {
  Args a;
  std::vector<std::string> v(argv + 1, argv + argc);
  if (v.empty()) throw UsageError("no command given (try 'prtbake --help')");
  a.command_line = "prtbake";
  for (size_t i = 0; i < v.size(); ++i) {
    const std::string& s = v[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= v.size()) throw UsageError(s + " needs a value");
      return v[++i];
    };
    auto record = [&](const std::string& val) { a.command_line += " " + s + " " + val; };
    if (!s.empty() && s[0] == '-') a.given.push_back(s);
    if (s == "-h" || s == "--help") {
      std::fputs(kHelp, stdout);
      std::fputs(tool::kExitStatusHelp, stdout);
      std::exit(0);
    } else if (s == "--version") {
      std::printf("prtbake %s\n", kVersion);
      std::exit(0);
    } else if (s == "-o" || s == "--output") {
      a.output = value();
      record(a.output);
    } else if (s == "--ao") {
      a.ao = true;
      a.command_line += " --ao";
    } else if (s == "--transfer") {
      a.transfer = parse_number<int>(s, value(), 1, sh::kMaxOrder);
      record(v[i]);
    } else if (s == "--visibility") {
      a.visibility = parse_number<int>(s, value(), 1, sh::kMaxOrder);
      record(v[i]);
    } else if (s == "--env") {
      a.radiance = value();
      record(a.radiance);
    } else if (s == "--shells") {
      const std::string g = value();
      int n1 = 0, n2 = 0, n3 = 0;
      char x1 = 0, x2 = 0;
      if (std::sscanf(g.c_str(), "%d%c%d%c%d", &n1, &x1, &n2, &x2, &n3) != 5 || x1 != 'x' || x2 != 'x' || n1 < 1 ||
          n2 < 2 || n3 < 1 || n1 > 4096 || n2 > 4096 || n3 > 1024)
        throw UsageError("--shells expects NPHIxNTHETAxNRHO, e.g. 128x65x30 (NTHETA >= 2), got '" + g + "'");
      a.n_phi = n1;
      a.n_theta = n2;
      a.n_rho = n3;
      record(g);
    } else if (s == "--cube") {
      a.cube = parse_number<int>(s, value(), 1, 1024);
      record(v[i]);
    } else if (s == "--fraction") {
      const std::string f = value();
      char* end = nullptr;
      a.fraction = std::strtod(f.c_str(), &end);
      if (end == f.c_str() || *end != 0 || !(a.fraction > 0 && a.fraction < 1))
        throw UsageError("--fraction expects a number in (0, 1), got '" + f + "'");
      record(f);
    } else if (s == "--radiance") {
      a.radiance = value();
      record(a.radiance);
    } else if (s == "--integrator") {
      a.integrator = value();
      if (a.integrator != "qmc" && a.integrator != "silhouette")
        throw UsageError("--integrator: unknown integrator '" + a.integrator + "' (available: silhouette, qmc)");
      record(a.integrator);
    } else if (s == "--samples") {
      a.samples = parse_number<uint32_t>(s, value(), 1, 1u << 24);
      record(v[i]);
    } else if (s == "--seed") {
      a.seed = parse_number<uint64_t>(s, value(), 0, UINT64_MAX);
      record(v[i]);
    } else if (s == "--threads") {
      a.threads = parse_number<int>(s, value(), 1, 4096);
    } else if (s == "--up") {
      const std::string u = value();
      if (u == "y" || u == "Y") a.up = bake::UpAxis::Y;
      else if (u == "z" || u == "Z") a.up = bake::UpAxis::Z;
      else throw UsageError("--up expects y or z, got '" + u + "'");
      record(u);
    } else if (s == "--no-file-normals") {
      a.file_normals = false;
      a.command_line += " " + s;
    } else if (s == "--report") {
      a.report = parse_number<uint32_t>(s, value(), 0, 1u << 20);
      a.report_given = true;
      record(v[i]);
    } else if (s == "--dry-run") {
      a.dry_run = true;
    } else if (s == "--reproducible") {
      a.reproducible = true;
    } else if (s == "--quiet" || s == "-q") {
      a.quiet = true;
    } else if (!s.empty() && s[0] == '-') {
      throw UsageError("unknown option '" + s + "' (try 'prtbake --help')");
    } else if (a.command.empty()) {
      a.command = s;
      a.command_line += " " + s;
    } else if (a.mesh.empty()) {
      a.mesh = s;
      a.command_line += " " + s;
    } else {
      throw UsageError("unexpected argument '" + s + "'");
    }
  }
  if (std::getenv("SOURCE_DATE_EPOCH")) a.reproducible = true;
  if (a.samples == 0) a.samples = a.integrator == "qmc" ? 1024 : 16384;
  if (a.integrator == "silhouette" && a.samples < 4)
    throw UsageError("--samples: the silhouette integrator needs k >= 4 (2 u-isolines)");
  if (a.command != "vertex" && a.command != "fiv" && a.command != "scene")
    throw UsageError("unknown command '" + a.command + "' (available: vertex, fiv, scene)");
  if (a.command == "scene") {
    for (const std::string& g : a.given)
      if (g != "-o" && g != "--output" && g != "--threads" && g != "--quiet" && g != "-q" && g != "--reproducible" &&
          g != "--report" && g != "--dry-run")
        throw UsageError("scene: option " + g + " is not for scenes: products, integrator, samples, seed and FIV "
                         "shells are set in the scene file's \"bake\" section");
    if (a.mesh.empty()) throw UsageError("scene: no SCENE file given");
    if (a.output.empty() && !a.dry_run) throw UsageError("scene: no output file given (-o OUT.prt.h5)");
    return a;
  }
  if (a.dry_run) throw UsageError("--dry-run is for scene");
  if (a.command == "fiv") {
    if (a.mesh.empty()) throw UsageError("fiv: no OCCLUDER mesh given");
    if (a.output.empty()) throw UsageError("fiv: no output file given (-o OUT.prt.h5)");
    if (a.radiance.empty()) throw UsageError("fiv: no environment given (--env ENV.exr)");
    if (a.integrator != "silhouette") throw UsageError("fiv: shells are baked with the silhouette integrator");
    return a;
  }
  if (a.mesh.empty()) throw UsageError("vertex: no MESH given");
  if (a.output.empty()) throw UsageError("vertex: no output file given (-o OUT.prt.h5)");
  if (!a.ao && !a.transfer && !a.visibility && a.radiance.empty())
    throw UsageError("vertex: nothing to bake: give at least one of --ao, --transfer L, --visibility L, --radiance ENV");
  return a;
}

// Fails early (before a long bake) if the output's directory cannot take a file.
void check_output_writable(const fs::path& out) {
  const fs::path dir = out.has_parent_path() ? out.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw bake::InputError(out.string(), "cannot write: directory '" + dir.string() + "' does not exist");
  if (fs::is_directory(out, ec)) throw bake::InputError(out.string(), "cannot write: it is a directory");
  if (access(dir.c_str(), W_OK) != 0) throw bake::InputError(out.string(), "cannot write: directory '" + dir.string() + "' is not writable");
}

std::string timestamp(bool reproducible) {
  // Reproducible-builds convention: SOURCE_DATE_EPOCH pins the 'created' attribute, so the same
  // inputs give identical bytes across runs too.
  std::time_t t = std::time(nullptr);
  if (reproducible) {
    const char* e = std::getenv("SOURCE_DATE_EPOCH");
    t = e ? std::time_t(std::strtoll(e, nullptr, 10)) : 0;
  }
  char buf[32];
  std::tm tm{};
  gmtime_r(&t, &tm);
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

// Prints reader warnings once each, with a count for repeats (a missing .mtl repeats per face).
void print_warnings(const std::vector<std::string>& warnings) {
  std::vector<std::pair<std::string, size_t>> seen;
  for (const auto& w : warnings) {
    auto it = std::find_if(seen.begin(), seen.end(), [&](const auto& x) { return x.first == w; });
    if (it == seen.end()) seen.emplace_back(w, 1);
    else ++it->second;
  }
  for (const auto& [w, n] : seen)
    std::fprintf(stderr, "prtbake: warning: %s%s\n", w.c_str(), n > 1 ? (" (" + std::to_string(n) + " times)").c_str() : "");
}

std::string human_bytes(uintmax_t b) {
  char buf[32];
  if (b >= (1u << 20)) std::snprintf(buf, sizeof buf, "%.1f MiB", double(b) / (1 << 20));
  else std::snprintf(buf, sizeof buf, "%.1f KiB", double(b) / 1024);
  return buf;
}

// The root attributes every file carries (formats/SCHEMA.md).
prt::formats::RootInfo root_info(const Args& a, const std::string& source_sha) {
  prt::formats::RootInfo r;
  r.generator = std::string("prtbake ") + kVersion;
  r.created = timestamp(a.reproducible);
  r.command_line = a.command_line;
  r.source = a.mesh;
  r.source_sha256 = source_sha;
  r.up_axis = a.up == bake::UpAxis::Y ? "y" : "z";
  r.sh_convention = "real orthonormal SH, Condon-Shortley phase, index l*(l+1)+m, order = number of bands L (L*L "
                    "coefficients); bands 0-2 equal DirectXMath XMSHEvalDirection; directions in the mesh frame";
  return r;
}

// Writes the asset (validated, temp + rename: formats/asset.h) and says where and how big.
void write_file(const Args& a, const prt::formats::Asset& asset) {
  prt::formats::write_asset(a.output, asset);
  if (!a.quiet) {
    std::error_code ec;
    std::printf("wrote %s (%s)\n", a.output.c_str(), human_bytes(fs::file_size(a.output, ec)).c_str());
  }
}

int run_vertex(const Args& a) {
  const bool say = !a.quiet;
  check_output_writable(a.output);
  const int threads = a.threads > 0 ? a.threads : tbb::info::default_concurrency();
  tbb::global_control threads_limit(tbb::global_control::max_allowed_parallelism, size_t(threads));

  bake::MeshLoadOptions mopt;
  mopt.use_file_normals = a.file_normals;
  const bake::Mesh mesh = bake::load_mesh(a.mesh, mopt);
  const bake::Topology topo = bake::build_topology(mesh);
  const std::string mesh_sha = bake::sha256_file(a.mesh);
  print_warnings(mesh.warnings);
  if (say)
    std::printf("mesh: %s: %zu vertices, %zu triangles (%zu file positions, %zu faces), normals %s\n",
                a.mesh.c_str(), mesh.positions.size(), mesh.triangles.size(), mesh.file_positions, mesh.file_faces,
                mesh.normal_source == bake::Mesh::NormalSource::File ? "from the file" : "angle-weighted");

  std::optional<bake::EnvMap> env;
  if (!a.radiance.empty()) {
    env = bake::EnvMap::load(a.radiance, a.up);
    const auto& i = env->info();
    if (say)
      std::printf("environment: %s: %dx%d %s, luminance max %.4g / mean %.4g (%.0fx), %llu negative pixel values "
                  "clamped to 0 (min seen %.3g)\n",
                  a.radiance.c_str(), i.width, i.height, i.layout.c_str(), i.max_luminance, i.mean_luminance,
                  i.mean_luminance > 0 ? i.max_luminance / i.mean_luminance : 0.0,
                  (unsigned long long)i.negative_pixels_clamped, i.min_value_seen);
  }

  bake::ProductRequest req;
  req.ao = a.ao;
  req.transfer_order = a.transfer;
  req.visibility_order = a.visibility;
  req.radiance = env ? &*env : nullptr;

  const auto setup_start = std::chrono::steady_clock::now();
  const std::unique_ptr<bake::Integrator> integrator_ptr =
      bake::make_integrator(a.integrator, a.samples, a.seed, mesh, topo, req);
  const bake::Integrator& integrator = *integrator_ptr;
  const double setup_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - setup_start).count();
  if (say) {
    std::printf("baking:");
    if (a.ao) std::printf(" ao");
    if (a.transfer) std::printf(" transfer/diffuse (order %d, %d coefficients)", a.transfer, a.transfer * a.transfer);
    if (a.visibility) std::printf(" transfer/visibility (order %d, %d coefficients)", a.visibility, a.visibility * a.visibility);
    if (env) std::printf(" radiance/band1 (3x3)");
    std::printf("\nintegrator: %s; %d threads; setup (ray/contour BVHs, tables) %.2f s\n",
                integrator.description().c_str(), threads, setup_seconds);
    std::fflush(stdout);
  }
  const tool::ProgressBar bar(a.quiet ? tool::ProgressStyle::Quiet : tool::ProgressStyle::Auto);
  const bake::Monitor progress = bar.monitor(&tool::interrupt_token());
  const bake::VertexBake result = bake::bake_vertices(mesh, topo, integrator, progress);
  if (say) {
    std::printf("baked %zu vertices in %.2f s (%.0f integrals/s", mesh.positions.size(), result.seconds,
                mesh.positions.size() / result.seconds);
    if (a.integrator == "qmc")
      std::printf(", %.2f M rays/s", double(mesh.positions.size()) * a.samples / result.seconds / 1e6);
    if (const auto* sil = dynamic_cast<const bake::SilhouetteIntegrator*>(&integrator)) {
      const auto st = sil->stats();
      std::printf("; per integral %.1f contour edges, %.0f crossings; CPU time %.0f%% contour search, %.0f%% "
                  "integration",
                  double(st.contour_edges) / double(std::max<uint64_t>(st.points, 1)),
                  double(st.crossings) / double(std::max<uint64_t>(st.points, 1)),
                  100 * st.contour_seconds / std::max(1e-12, st.contour_seconds + st.integrate_seconds),
                  100 * st.integrate_seconds / std::max(1e-12, st.contour_seconds + st.integrate_seconds));
    }
    std::printf(")\n");
  }

  std::optional<bake::ErrorReport> report;
  if (a.report > 0) {
    const auto reference = bake::make_reference(a.integrator, a.samples, a.seed, mesh, topo, req);
    report = bake::compare_with_reference(mesh, topo, result, *reference, a.report, a.seed);
    if (say) {
      std::printf("error against a %u-ray QMC reference on %zu seeded vertices (reference took %.2f s, not "
                  "counted in the bake time):\n",
                  a.integrator == "qmc" ? a.samples * 10 : 65536u, report->vertices.size(), report->reference_seconds);
      for (const auto& e : report->products)
        std::printf("  %-20s RMSE %.3e  max %.3e  relative RMSE %.3e  (bake's estimated std. error %.3e; "
                    "reference's own %.3e)\n",
                    e.product.c_str(), e.rmse, e.max_abs, e.reference_rms > 0 ? e.rmse / e.reference_rms : 0.0,
                    e.bake_std_error, e.reference_std_error);
    }
  }

  // ---- the file (formats/SCHEMA.md) ----
  namespace F = prt::formats;
  F::Asset asset;
  asset.root = root_info(a, mesh_sha);
  tool::set_mesh(asset.vertices, mesh);
  tool::set_products(asset.vertices, result,
                     {integrator.name(), integrator.description(), a.samples, a.seed, a.transfer, a.visibility,
                      env ? &*env : nullptr, a.radiance});
  if (report) asset.vertices.report = tool::report_of(*report, result.seconds, mesh.positions.size(), a.reproducible);
  write_file(a, asset);
  return 0;
}

int run_fiv(const Args& a) {
  const bool say = !a.quiet;
  check_output_writable(a.output);
  const int threads = a.threads > 0 ? a.threads : tbb::info::default_concurrency();
  tbb::global_control threads_limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
  bake::MeshLoadOptions mopt;
  mopt.use_file_normals = false;  // an occluder's normals play no part in its FIVs
  const bake::Mesh mesh = bake::load_mesh(a.mesh, mopt);
  const bake::Topology topo = bake::build_topology(mesh);
  print_warnings(mesh.warnings);
  const bake::EnvMap env = bake::EnvMap::load(a.radiance, a.up);
  const tool::ProgressBar bar(a.quiet ? tool::ProgressStyle::Quiet : tool::ProgressStyle::Auto);
  const bake::Monitor progress = bar.monitor(&tool::interrupt_token());
  if (say)
    std::printf("occluder: %s: %zu triangles; environment: %s (%dx%d %s)\n", a.mesh.c_str(), mesh.triangles.size(),
                a.radiance.c_str(), env.info().width, env.info().height, env.info().layout.c_str());

  const auto t0 = std::chrono::steady_clock::now();
  const bake::Fiv fenv = bake::environment_fiv(env);
  const std::vector<float> cube = bake::irradiance_cube(env, a.cube);
  const double env_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  bake::ShellSpec spec;
  spec.n_phi = a.n_phi;
  spec.n_theta = a.n_theta;
  spec.n_rho = a.n_rho;
  spec.fraction = a.fraction;
  spec.isolines = std::max(2, int(std::lround(std::sqrt(double(a.samples)))));
  const bake::FivShells sh = bake::bake_fiv_shells(mesh, topo, env, spec, progress);
  if (say) {
    std::printf("environment FIV and %dx%dx6 DifMap in %.2f s\n", a.cube, a.cube, env_seconds);
    std::printf("shells: %dx%dx%zu (of %d requested radii, %.3g to %.3g; bounding radius %.4g) in %.2f s (%.0f "
                "integrals/s)\n",
                a.n_phi, a.n_theta, sh.radii.size(), a.n_rho, sh.radii.front(), sh.radii.back(), sh.radius, sh.seconds,
                double(sh.integrals) / sh.seconds);
  }

  namespace F = prt::formats;
  F::Asset asset;
  asset.root = root_info(a, bake::sha256_file(a.mesh));
  tool::set_fiv_environment(asset, env, a.radiance, fenv, cube, a.cube);
  const std::string name = tool::safe_name(fs::path(a.mesh).stem().string());
  F::Occluder& occluder = asset.occluders.emplace_back(tool::occluder_of(name, sh, env, a.radiance, a.fraction, a.samples));
  if (a.report > 0) {
    // Error against a QMC reference (65,536 rays, full-sphere mode) at seeded shell samples.
    const bake::FivErrorReport r = bake::fiv_error_report(mesh, topo, env, sh, fenv, a.report, a.seed);
    if (say)
      std::printf("error against a 65536-ray QMC reference at %zu seeded shell samples (reference took %.2f s, not "
                  "counted): RMSE %.3e, max %.3e, RMSE / RMS|F_env| %.3e (reference's own std. error %.3e)\n",
                  r.points, r.reference_seconds, r.rmse, r.max_abs, r.reference_rms > 0 ? r.rmse / r.reference_rms : 0.0,
                  r.reference_std_error);
    occluder.report = tool::fiv_report_of(name, r, sh, a.reproducible);
  }
  write_file(a, asset);
  return 0;
}

int run_scene(const Args& a) {
  const bool say = !a.quiet;
  if (!a.dry_run) check_output_writable(a.output);
  const int threads = a.threads > 0 ? a.threads : tbb::info::default_concurrency();
  tbb::global_control threads_limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
  bake::Scene scene = bake::load_scene(a.mesh);
  if (a.report_given) scene.report = a.report;
  Args file_args = a;  // the root attributes follow the scene file
  file_args.up = scene.up;

  std::vector<bake::Mesh> meshes;
  std::vector<std::string> mesh_sha;
  for (const auto& o : scene.objects) {
    try {
      meshes.push_back(bake::load_scene_mesh(o));
    } catch (const bake::InputError& e) {  // say which object of which scene wanted the mesh
      throw bake::InputError(e.file(), e.defect() + " (object '" + o.name + "' of " + a.mesh + ")");
    }
    mesh_sha.push_back(bake::sha256_file(o.mesh));
    print_warnings(meshes.back().warnings);
  }
  std::optional<bake::EnvMap> env;
  if (scene.environment) env = bake::EnvMap::load(*scene.environment, scene.up);
  const bake::ScenePlan plan = bake::plan_scene(scene, meshes);

  if (say) {
    std::printf("scene: %s: %zu objects, environment %s, integrator %s, SH tolerance %g\n", a.mesh.c_str(),
                scene.objects.size(), env ? scene.environment->string().c_str() : "none", scene.integrator.c_str(),
                scene.sh_tolerance);
    for (size_t i = 0; i < scene.objects.size(); ++i) {
      const auto& o = scene.objects[i];
      std::printf("  %s (%s): %s, %zu vertices, %zu triangles\n", o.name.c_str(), bake::role_name(o.role),
                  o.mesh.string().c_str(), meshes[i].positions.size(), meshes[i].triangles.size());
      for (const auto& b : plan.objects[i].baked) std::printf("      bake       %s\n", b.c_str());
      for (const auto& l : plan.objects[i].left_out) std::printf("      leave out  %s\n", l.c_str());
    }
    for (const auto& n : plan.notes) std::printf("  %s\n", n.c_str());
    std::fflush(stdout);
  }
  if (a.dry_run) return 0;

  const tool::ProgressBar bar(a.quiet ? tool::ProgressStyle::Quiet : tool::ProgressStyle::Auto);
  const bake::Monitor progress = bar.monitor(&tool::interrupt_token());
  const bake::SceneBake result = bake::bake_scene(scene, plan, meshes, env ? &*env : nullptr, progress,
                                                  [&](const std::string& line) {
                                                    if (say) std::printf("%s\n", line.c_str());
                                                    std::fflush(stdout);
                                                  });
  if (say)
    std::printf("baked %llu receiver vertices in %.2f s (setup %.2f s), FIV %.2f s (environment %.2f s)\n",
                (unsigned long long)result.vertices, result.vertex_seconds, result.setup_seconds, result.fiv_seconds,
                result.environment_seconds);

  namespace F = prt::formats;
  F::Asset asset;
  asset.root = root_info(file_args, bake::sha256_file(a.mesh));
  const std::string env_path = env ? scene.environment->string() : std::string();
  F::SceneInfo& info = asset.scene.emplace();
  info.scene_file = a.mesh;
  info.integrator = scene.integrator;
  info.samples = int64_t(scene.samples ? scene.samples : bake::default_samples(scene.integrator));
  info.seed = int64_t(scene.seed);
  info.sh_tolerance = scene.sh_tolerance;
  info.relight = int64_t(scene.relight);
  if (env) {
    info.environment = env_path;
    info.environment_sha256 = env->info().sha256;
  }
  auto join = [](const std::vector<std::string>& lines, const char* none) {
    std::string s;
    for (const auto& l : lines) s += (s.empty() ? "" : "\n") + l;
    return s.empty() ? std::string(none) : s;
  };
  info.plan = join(plan.notes, "");
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const auto& o = scene.objects[i];
    const auto& p = plan.objects[i];
    const auto& ob = result.objects[i];
    F::SceneObject& obj = asset.objects.emplace_back();
    obj.name = o.name;
    obj.role = bake::role_name(o.role);
    obj.mesh = o.mesh.string();
    obj.mesh_sha256 = mesh_sha[i];
    obj.transform.emplace(16);
    for (int k = 0; k < 16; ++k) (*obj.transform)[size_t(k)] = o.transform(k / 4, k % 4);
    obj.albedo = std::vector<double>(o.material.albedo.begin(), o.material.albedo.end());
    obj.phong_exponent = o.material.phong_exponent;
    obj.sh_order_diffuse = int64_t(p.transfer_order);
    obj.sh_order_glossy = int64_t(p.visibility_order);
    obj.baked = join(p.baked, "-");
    obj.left_out = join(p.left_out, "-");
    if (o.material.glossy()) obj.specular = std::vector<double>(o.material.specular.begin(), o.material.specular.end());
    if (ob.values) obj.closed_form_vertices = int64_t(ob.closed_form_vertices);
    tool::set_mesh(obj.set, meshes[i]);
    if (ob.values) {
      tool::set_products(obj.set, *ob.values,
                         {scene.integrator, ob.integrator_description,
                          scene.samples ? scene.samples : bake::default_samples(scene.integrator), scene.seed,
                          p.transfer_order, p.visibility_order, env ? &*env : nullptr, env_path});
      if (ob.report)
        obj.set.report = tool::report_of(*ob.report, ob.values->seconds, meshes[i].positions.size(), a.reproducible);
    }
    if (ob.fiv) {
      F::Occluder& occluder =
          asset.occluders.emplace_back(tool::occluder_of(o.name, *ob.fiv, *env, env_path, scene.fraction, scene.fiv_samples()));
      if (ob.fiv_report) occluder.report = tool::fiv_report_of(o.name, *ob.fiv_report, *ob.fiv, a.reproducible);
    }
  }
  if (plan.fiv_environment)
    tool::set_fiv_environment(asset, *env, env_path, result.environment_fiv, result.irradiance_cube, scene.cube);
  write_file(a, asset);
  return 0;
}

int prtbake_main(int argc, char** argv) {
  const Args a = parse(argc, argv);
  tool::install_interrupt_handler();
  return a.command == "fiv" ? run_fiv(a) : a.command == "scene" ? run_scene(a) : run_vertex(a);
}

} // namespace

int main(int argc, char** argv) { return tool::run_tool("prtbake", prtbake_main, argc, argv); }
