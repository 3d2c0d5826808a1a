// prtview — look at a baked file: render it shaded by the runtime library (prtshade), render the
// same view with Embree ray-traced ground truth, and show and measure the difference. A thin
// shell: formats/ reads the file, prtshade shades, libbake (bake/render.h, bake/image_io.h)
// rasterizes, ray-traces, compares and writes the pictures.
#include "progress_bar.h"
#include "tool_main.h"

#include <bake/envmap.h>
#include <bake/error.h>
#include <bake/fiv.h>
#include <bake/image_io.h>
#include <bake/mesh.h>
#include <bake/render.h>
#include <bake/sha256.h>
#include <formats/prtfile.h>
#include <prtshade/fiv.h>
#include <prtshade/shade.h>

#include <tbb/global_control.h>
#include <tbb/info.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

namespace fs = std::filesystem;
namespace F = prt::formats;
using namespace prt;
using Eigen::Vector3d;

namespace {

constexpr const char* kHelp = R"(prtview — render a baked file shaded by the runtime library, next to ray-traced ground truth

USAGE
  prtview FILE.prt.h5 --camera eye=X,Y,Z:at=X,Y,Z[:up=X,Y,Z][:fov=DEG] -o IMAGE.png|IMAGE.exr
          [--env ENV.exr] [--size WxH] [--reference | --error | --triptych] [OPTIONS]

WHAT IS DRAWN
  Every picture shows outgoing radiance of a white diffuse surface, E/pi (albedo 1), where E is
  the irradiance; a constant sky of radiance L shows as L (scene files: times each object's
  albedo). Three kinds of file:

  per-vertex files (/mesh + /transfer/diffuse or /radiance/band1, from 'prtbake vertex'):
    the mesh is rasterized (software, top-left fill rule, z-buffer, perspective-correct
    interpolation), each vertex is shaded by prtshade and the colours are interpolated across
    triangles (Gouraud), as an engine would:
      transfer  the environment ENV is projected to SH (prt::shade::project_latlong, the order
                of the file) and every vertex gets sum_i T_i L_i (prt::shade::shade_transfer);
                any environment works: the transfer does not depend on the lighting.
      band1     E = 4pi/3 sum_m y_1m(n) R_m at the baked normal (prt::shade::shade_band1): exact
                all-frequency shadows under the environment the file was baked with.
  FIV files (/fiv from 'prtbake fiv', paper 004): the occluder mesh (from --occluder-mesh, else
    the file's 'source' attribute; its SHA-256 must match the file's) stands on a square ground
    plane (the receiver), and each pixel is shaded by prtshade: the ground with
    prt::shade::shade_fiv (DifMap minus each occluder's trilinear FIV lookup, cases A/B/C with
    the partial-occluder factor, overlap correction for several occluders: paper 004 sec. 4.3.1),
    the occluder with prt::shade::shade_fiv_self (sec. 4.3.2) minus the other copies' shadows.

  scene files (/objects/<name>/ and /scene from 'prtbake scene', schema v2): every object, in world
    space, in one z-buffer, each shaded with what the file holds for it, times its diffuse albedo
    (the 'albedo' attribute of /objects/<name>; white if it is zero):
      band1     band-1 radiance when the object has it (shade_band1, E/pi), else
      transfer  diffuse transfer (project_latlong + shade_transfer), else
      AO        AO x E_unocc(n)/pi at each vertex, E_unocc the unshadowed irradiance from the
                file's DifMap (lookup_difmap; the exact texel sum if the file has none) - the
                ambient-occlusion approximation. Glossy-only objects (transfer/visibility only)
                land here: glossy shading is not in the runtime (prtshade) yet, so they show
                their AO-shaded diffuse response, not their highlights.
      FIV self  objects without per-vertex products (occluder-only) that have FIV shells
                (/fiv/occluders/<name>) and /fiv/environment: per pixel with shade_fiv_self
                (self-shadows, eq. 12; the other objects' shadows are not added), else
      flat      grey: 0.5 x the environment's mean radiance.
    The environment must be the one of /scene (checked by SHA-256); default: its 'environment'.
    --shade, --instance, --occluder(-mesh), --ground(-size), --no-overlap/--no-partial do not
    apply. The reference renders the same objects: "occluder" and "both" objects cast shadows,
    "receiver" objects do not (not even on themselves: the scene semantics, bake/scene.h), and a
    pixel shows albedo x E/pi.

  --reference renders the same view by ray tracing (Embree): a primary ray per pixel centre, then
  E = (exact sum over every environment texel of L max(0, n.M_texel)) - (QMC estimate of the
  light the scene blocks), with --samples shadow rays per pixel and a per-pixel standard error.
  That is the standard rendering equation with visibility, the paper's "brute force" reference.

OUTPUT (-o; the extension picks the format: .png for people, .exr for numbers)
  (default)       the runtime render.
  --reference     the ray-traced reference instead.
  --error         a false-colour map of |runtime - reference| (PNG: black = 0 ... pale yellow =
                  --error-scale x the reference's range; grey = not compared. EXR: the signed
                  difference runtime - reference in float) and prints NRMSE.
  --triptych      runtime | reference | error side by side (same exposure), prints NRMSE.
  PNG: 8-bit sRGB of (exposure x value), clipped at 1; --exposure X, default: 1 / the 99th
  percentile of the luminance (of the reference when it is rendered). EXR: float RGB, linear.
  Files are written to a temporary name and renamed: a failure leaves nothing behind.

ERROR NUMBERS
  NRMSE = RMSE / (max - min of the reference), RMSE over the compared pixels and the three
  channels (paper 004 sec. 5 reports NRMSE without printing its normalisation; this is the
  common range-normalised one). Compared pixels (--region): 'receiver' = where both renders see
  the ground plane (FIV files; paper 004 measures the shadow on the ground) or a receiver object
  ("receiver" or "both"; scene files), 'all' = where both see geometry (the default for per-vertex
  files). Scene files also print each receiver's NRMSE: its RMSE over the pixels where both
  renders see that object, over the same range (so NRMSE^2 = sum_k pixels_k/pixels NRMSE_k^2 but
  for the few silhouette pixels where the two renders see different receivers), and each
  object's mean runtime value. The reference's own noise is printed too
  (RMS standard error / range) with the noise-corrected NRMSE sqrt(RMSE^2 - sigma^2)/range.

OPTIONS
  --env ENV.exr        environment (OpenEXR lat-long or cube). Default: the file's 'environment'
                       attribute. band1, FIV and scene files must be shown under the environment
                       they were baked with (checked by SHA-256).
  --camera SPEC        eye, at (required), up (default 0,1,0), fov = vertical field of view in
                       degrees (default 45); world units of the mesh.
  --size WxH           image size in pixels (default 256x256).
  --shade KIND         transfer | band1 | fiv (default: fiv if the file has /fiv, else transfer if
                       it has /transfer/diffuse, else band1).
  --samples N          reference: QMC shadow rays per pixel, a multiple of 8: 8 independent
                       randomised-QMC replicates of N/8 rays; their spread gives the standard
                       error (default 1024).
  --seed S             reference randomisation seed (default 1); same seed, same bytes.
  --exposure X         PNG exposure (see OUTPUT).
  --error-scale S      error map full scale as a fraction of the reference range (default 0.1).
  --region R           receiver | all (see ERROR NUMBERS).
  --reference-cache C.exr  keep the reference render (radiance, standard error, primary hits) in
                       C.exr and reuse it while everything that determines it (scene, view,
                       environment, samples, seed) is unchanged: compare several bakes against
                       one reference without tracing it again.
  FIV files:
  --occluder-mesh M    the occluder's mesh (default: the file's 'source' attribute, relative to
                       the working directory, else to FILE's directory).
  --occluder NAME      which /fiv/occluders/NAME (default: the only one).
  --instance X,Y,Z     place a copy of the occluder moved by (X,Y,Z); repeat for several copies
                       (default: one copy where it was baked). Copies share the baked shells.
  --ground Y           height of the ground plane (default: 1% of the bounding radius R below
                       the lowest copy).
  --ground-size H      half-size of the ground square (default 4R + the copies' spread).
  --no-overlap         switch off the overlap correction for several occluders (eq. 13-14).
  --no-partial         switch off the partial-occluder factor (h+R)/2R (case B).
  --threads T          worker threads (default: all cores).   --quiet   only errors.
  -h, --help           this text.

EXAMPLES
  prtbake fiv data/bunny.obj --env data/forest.exr --shells 64x33x30 -o bunny.fiv.prt.h5
  prtview bunny.fiv.prt.h5 --camera eye=0,22,24:at=0,0,2:fov=40 -o shadow.png
  prtview bunny.fiv.prt.h5 --camera eye=0,22,24:at=0,0,2:fov=40 --triptych -o compare.png
  prtview bunny.fiv.prt.h5 --camera eye=0,22,24:at=0,0,2 --instance -4,0,0 --instance 4,0,0 --error -o e.png
  prtbake vertex data/bunny_ground.obj --transfer 3 -o default.prt.h5
  prtview default.prt.h5 --env data/sunset.exr --camera eye=0,14,26:at=0,3,0 --triptych -o t.png
  prtbake scene data/scene_example.json -o scene.prt.h5
  prtview scene.prt.h5 --camera eye=0,18,34:at=0,2,0 --size 320x240 --triptych -o scene.png

)";

using tool::UsageError;

enum class Output { Runtime, Reference, Error, Triptych };

struct Args {
  std::string file, env, camera, output, shade, region, occluder_mesh, occluder, reference_cache;
  int width = 256, height = 256;
  Output mode = Output::Runtime;
  uint32_t samples = 1024;
  uint64_t seed = 1;
  std::optional<double> exposure, ground, ground_size;
  double error_scale = 0.1;
  std::vector<Vector3d> instances;
  bool overlap = true, partial = true, quiet = false;
  int threads = 0;
};

double parse_real(const std::string& opt, const std::string& s) {
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size() || !std::isfinite(v))
    throw UsageError(opt + " expects a number, got '" + s + "'");
  return v;
}

uint64_t parse_uint(const std::string& opt, const std::string& s, uint64_t lo, uint64_t hi) {
  char* end = nullptr;
  errno = 0;
  const unsigned long long v = std::strtoull(s.c_str(), &end, 10);
  if (s.empty() || s[0] == '-' || end != s.c_str() + s.size() || errno != 0 || v < lo || v > hi)
    throw UsageError(opt + " expects an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got '" + s + "'");
  return v;
}

Args parse(int argc, char** argv) {
  Args a;
  std::vector<std::string> v(argv + 1, argv + argc);
  if (v.empty()) throw UsageError("no file given (try 'prtview --help')");
  int modes = 0;
  for (size_t i = 0; i < v.size(); ++i) {
    const std::string& s = v[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= v.size()) throw UsageError(s + " needs a value");
      return v[++i];
    };
    if (s == "-h" || s == "--help") {
      std::fputs(kHelp, stdout);
      std::fputs(tool::kExitStatusHelp, stdout);
      std::exit(0);
    } else if (s == "-o" || s == "--output") a.output = value();
    else if (s == "--env") a.env = value();
    else if (s == "--camera") a.camera = value();
    else if (s == "--size") {
      try {
        const auto wh = bake::parse_size(value());
        a.width = wh[0];
        a.height = wh[1];
      } catch (const bake::InputError& e) {
        throw UsageError(e.what());
      }
    } else if (s == "--reference") { a.mode = Output::Reference; ++modes; }
    else if (s == "--error") { a.mode = Output::Error; ++modes; }
    else if (s == "--triptych") { a.mode = Output::Triptych; ++modes; }
    else if (s == "--shade") {
      a.shade = value();
      if (a.shade != "transfer" && a.shade != "band1" && a.shade != "fiv")
        throw UsageError("--shade expects transfer, band1 or fiv, got '" + a.shade + "'");
    } else if (s == "--samples") {
      a.samples = uint32_t(parse_uint(s, value(), 8, 1u << 24));
      if (a.samples % 8) throw UsageError("--samples must be a multiple of 8 (8 independent QMC replicates), got " + v[i]);
    }
    else if (s == "--seed") a.seed = parse_uint(s, value(), 0, UINT64_MAX);
    else if (s == "--exposure") {
      a.exposure = parse_real(s, value());
      if (!(*a.exposure > 0)) throw UsageError("--exposure must be > 0");
    } else if (s == "--error-scale") {
      a.error_scale = parse_real(s, value());
      if (!(a.error_scale > 0)) throw UsageError("--error-scale must be > 0");
    } else if (s == "--region") {
      a.region = value();
      if (a.region != "receiver" && a.region != "all") throw UsageError("--region expects receiver or all, got '" + a.region + "'");
    } else if (s == "--occluder-mesh") a.occluder_mesh = value();
    else if (s == "--occluder") a.occluder = value();
    else if (s == "--reference-cache") {
      a.reference_cache = value();
      if (fs::path(a.reference_cache).extension() != ".exr") throw UsageError("--reference-cache expects a FILE.exr");
    }
    else if (s == "--instance") {
      const std::string t = value();
      Vector3d d;
      size_t start = 0;
      for (int k = 0; k < 3; ++k) {
        const size_t comma = t.find(',', start);
        if ((k < 2) != (comma != std::string::npos)) throw UsageError("--instance expects X,Y,Z, got '" + t + "'");
        d[k] = parse_real("--instance", t.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
        start = comma + 1;
      }
      a.instances.push_back(d);
    } else if (s == "--ground") a.ground = parse_real(s, value());
    else if (s == "--ground-size") {
      a.ground_size = parse_real(s, value());
      if (!(*a.ground_size > 0)) throw UsageError("--ground-size must be > 0");
    } else if (s == "--no-overlap") a.overlap = false;
    else if (s == "--no-partial") a.partial = false;
    else if (s == "--threads") a.threads = int(parse_uint(s, value(), 1, 4096));
    else if (s == "--quiet" || s == "-q") a.quiet = true;
    else if (!s.empty() && s[0] == '-') throw UsageError("unknown option '" + s + "' (try 'prtview --help')");
    else if (a.file.empty()) a.file = s;
    else throw UsageError("unexpected argument '" + s + "'");
  }
  if (modes > 1) throw UsageError("--reference, --error and --triptych exclude each other");
  if (a.file.empty()) throw UsageError("no FILE.prt.h5 given");
  if (a.output.empty()) throw UsageError("no output given (-o IMAGE.png or IMAGE.exr)");
  if (a.camera.empty()) throw UsageError("no camera given (--camera eye=X,Y,Z:at=X,Y,Z)");
  const std::string ext = fs::path(a.output).extension().string();
  if (ext != ".png" && ext != ".exr") throw UsageError("-o: '" + a.output + "' must end in .png or .exr");
  return a;
}

// ---- reading the file ------------------------------------------------------------------------------------

const std::vector<float>& floats(const F::File& f, const std::string& file, const std::string& path,
                                 const std::vector<uint64_t>& trailing) {
  const F::Dataset* d = F::find_dataset(f, path);
  if (!d) throw bake::InputError(file, "no dataset " + path);
  const auto* v = std::get_if<std::vector<float>>(&d->data);
  if (!v) throw bake::InputError(file, path + " is not float32");
  if (d->shape.size() < trailing.size() ||
      !std::equal(trailing.rbegin(), trailing.rend(), d->shape.rbegin(), [](uint64_t want, uint64_t have) {
        return want == 0 || want == have;
      }))
    throw bake::InputError(file, path + " has an unexpected shape");
  return *v;
}

std::string string_attr(const std::vector<F::Attr>& attrs, std::string_view name) {
  const F::Attr* a = F::find_attr(attrs, name);
  if (!a) return {};
  const auto* s = std::get_if<std::string>(&a->value);
  return s ? *s : std::string();
}

const F::Attr& need_attr(const F::Dataset& d, std::string_view name, const std::string& file) {
  const F::Attr* a = F::find_attr(d.attrs, name);
  if (!a) throw bake::InputError(file, d.path + " lacks the attribute '" + std::string(name) + "'");
  return *a;
}

// The environment the file was baked with must be the one we shade / reference with. `where` names
// the dataset or group whose attributes (environment, environment_sha256) say which it was.
void check_same_environment(const std::vector<F::Attr>& attrs, const std::string& where, const bake::EnvMap& env,
                            const std::string& file) {
  const std::string sha = string_attr(attrs, "environment_sha256");
  if (!sha.empty() && sha != env.info().sha256)
    throw bake::InputError(env.info().source, "is not the environment " + file + " was baked with (" + where +
                                                  " was baked under '" + string_attr(attrs, "environment") +
                                                  "', SHA-256 " + sha.substr(0, 12) + "...)");
}
void check_same_environment(const F::Dataset& d, const bake::EnvMap& env, const std::string& file) {
  check_same_environment(d.attrs, d.path, env, file);
}

struct Timer {
  std::chrono::steady_clock::time_point t0 = std::chrono::steady_clock::now();
  double seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); }
};

// What a render needs beyond the pictures: the scene both renderers draw and which triangles form the
// receiver (the ground plane of FIV scenes).
struct Scene {
  bake::Mesh mesh;
  size_t receiver_triangles = 0;  // triangles [0, receiver_triangles) are the receiver
  std::vector<bake::Sphere> spheres;
  std::string what;
  // Scene files: the reference's per-triangle shadow casters and albedos (bake::ReferenceOptions),
  // and the objects' triangle ranges: object k owns [first_triangle[k], first_triangle[k + 1]).
  std::vector<uint8_t> casts_shadow;
  std::vector<std::array<float, 3>> albedo;
  std::vector<std::string> object_names;
  std::vector<bool> object_receiver;
  std::vector<size_t> first_triangle;
};

// ---- per-vertex files ------------------------------------------------------------------------------------

// The mesh of a vertex set: prefix "" (root layout) or "/objects/<name>" (scene files).
bake::Mesh read_mesh(const F::File& f, const std::string& file, const std::string& prefix) {
  const auto& pos = floats(f, file, prefix + "/mesh/positions", {3});
  const auto& nrm = floats(f, file, prefix + "/mesh/normals", {3});
  const F::Dataset* td = F::find_dataset(f, prefix + "/mesh/triangles");
  if (!td) throw bake::InputError(file, "no dataset " + prefix + "/mesh/triangles (nothing to rasterize)");
  const auto& tri = std::get<std::vector<uint32_t>>(td->data);
  const size_t V = pos.size() / 3;
  std::vector<Eigen::Vector3f> P(V), N(V);
  for (size_t i = 0; i < V; ++i) {
    P[i] = {pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]};
    N[i] = {nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2]};
  }
  std::vector<std::array<uint32_t, 3>> T(tri.size() / 3);
  for (size_t t = 0; t < T.size(); ++t) T[t] = {tri[3 * t], tri[3 * t + 1], tri[3 * t + 2]};
  return bake::make_mesh(std::move(P), std::move(T), prefix.empty() ? file : prefix.substr(9), std::move(N));
}

// The environment's SH coefficients [3][order²] (channel-major, as prtshade wants them).
std::vector<float> environment_sh(const bake::EnvMap& env, int order, std::string& how) {
  const size_t n = size_t(order) * size_t(order);
  std::vector<float> light(3 * n);
  if (env.info().layout == "latlong" && env.up() == bake::UpAxis::Y) {
    // The runtime path: the pixels as an engine holds them (after libbake's load policy).
    const int W = env.info().width, H = env.info().height;
    std::vector<float> px(size_t(W) * size_t(H) * 3);
    for (int t = 0; t < W * H; ++t) {
      const bake::Rgb c = env.texel_value(t);
      px[3 * size_t(t)] = float(c.r);
      px[3 * size_t(t) + 1] = float(c.g);
      px[3 * size_t(t) + 2] = float(c.b);
    }
    shade::project_latlong(px.data(), W, H, order, light.data());
    how = "prt::shade::project_latlong (order " + std::to_string(order) + ") + shade_transfer per vertex, Gouraud";
  } else {  // cube maps and Z-up scenes: libbake's projection (same quadrature, any layout)
    const auto L = env.project_sh(order);
    for (size_t i = 0; i < n; ++i)
      for (size_t c = 0; c < 3; ++c) light[c * n + i] = float(L[i * 3 + c]);
    how = "EnvMap::project_sh (order " + std::to_string(order) + ", cube map or Z-up) + prt::shade::shade_transfer, Gouraud";
  }
  return light;
}

// Per-vertex E/pi from diffuse transfer (any environment) or band-1 radiance (the baked one), of
// the vertex set under `prefix`.
std::vector<float> shade_transfer_set(const F::File& f, const std::string& file, const std::string& prefix,
                                      const bake::EnvMap& env, size_t V, std::string& how) {
  const std::string path = prefix + "/transfer/diffuse";
  const F::Dataset* d = F::find_dataset(f, path);
  if (!d) throw bake::InputError(file, "no dataset " + path + (prefix.empty() ? " (try --shade band1)" : ""));
  const int order = int(std::get<int64_t>(need_attr(*d, "sh_order", file).value));
  const std::vector<float> light = environment_sh(env, order, how);
  std::vector<float> colour(3 * V);
  shade::shade_transfer_vertices(std::get<std::vector<float>>(d->data).data(), V, order, light.data(), colour.data());
  return colour;
}
std::vector<float> shade_band1_set(const F::File& f, const std::string& file, const std::string& prefix,
                                   const bake::EnvMap& env, const bake::Mesh& mesh, std::string& how) {
  const std::string path = prefix + "/radiance/band1";
  const F::Dataset* d = F::find_dataset(f, path);
  if (!d) throw bake::InputError(file, "no dataset " + path + (prefix.empty() ? " (try --shade transfer)" : ""));
  check_same_environment(*d, env, file);
  const auto& nrm = floats(f, file, prefix + "/mesh/normals", {3});
  std::vector<float> colour(3 * mesh.positions.size());
  shade::shade_band1_vertices(nrm.data(), std::get<std::vector<float>>(d->data).data(), mesh.positions.size(), colour.data());
  for (float& c : colour) c *= float(std::numbers::inv_pi);
  how = "prt::shade::shade_band1 per vertex (E/pi), Gouraud";
  return colour;
}

bake::Image render_vertex_file(const F::File& f, const Args& a, const std::string& kind, const bake::EnvMap& env,
                               const bake::Camera& cam, Scene& scene, std::string& how) {
  scene.mesh = read_mesh(f, a.file, "");
  const size_t V = scene.mesh.positions.size();
  scene.what = "mesh: " + std::to_string(V) + " vertices, " + std::to_string(scene.mesh.triangles.size()) + " triangles";
  const std::vector<float> colour = kind == "transfer" ? shade_transfer_set(f, a.file, "", env, V, how)
                                                       : shade_band1_set(f, a.file, "", env, scene.mesh, how);
  const bake::GBuffer g = bake::rasterize(scene.mesh, cam);
  return bake::interpolate_vertices(scene.mesh, g, colour);
}

// ---- FIV shells ---------------------------------------------------------------------------------------------

// One baked occluder, /fiv/occluders/<name>, checked (validate_occluder) and viewed by prtshade.
struct BakedOccluder {
  std::vector<double> centre;
  double radius = 0;
  std::vector<float> radii;  // view.radii points here
  shade::FivOccluder view{};
};

BakedOccluder read_occluder(const F::File& f, const std::string& file, const std::string& name, const bake::EnvMap& env) {
  const std::string dir = "/fiv/occluders/" + name;
  const F::Dataset* sd = F::find_dataset(f, dir + "/shells");
  if (!sd) throw bake::InputError(file, "no dataset " + dir + "/shells");
  check_same_environment(*sd, env, file);
  const auto& shells = floats(f, file, dir + "/shells", {0, 0, 0, 3, 3});
  const F::Dataset* vd = F::find_dataset(f, dir + "/valid");
  if (!vd) throw bake::InputError(file, "no dataset " + dir + "/valid");
  BakedOccluder b;
  b.centre = std::get<std::vector<double>>(need_attr(*sd, "centre", file).value);
  b.radius = std::get<double>(need_attr(*sd, "radius", file).value);
  const auto& radii_d = std::get<std::vector<double>>(need_attr(*sd, "radii", file).value);
  b.radii.assign(radii_d.begin(), radii_d.end());
  if (b.centre.size() != 3) throw bake::InputError(file, dir + "/shells: 'centre' must hold 3 numbers");
  shade::FivOccluder& o = b.view;
  for (int c = 0; c < 3; ++c) o.centre[c] = float(b.centre[size_t(c)]);
  o.radius = float(b.radius);
  o.n_rho = int(sd->shape[0]);
  o.n_theta = int(sd->shape[1]);
  o.n_phi = int(sd->shape[2]);
  o.radii = b.radii.data();
  o.shells = shells.data();
  o.valid = std::get<std::vector<uint8_t>>(vd->data).data();
  if (b.radii.size() != sd->shape[0]) throw bake::InputError(file, dir + "/shells: 'radii' must hold one radius per shell");
  try {
    shade::validate_occluder(o);
  } catch (const std::invalid_argument& e) {
    throw bake::InputError(file, dir + ": " + e.what());
  }
  return b;  // moving the vector keeps its buffer: view.radii stays valid
}

// ---- FIV files --------------------------------------------------------------------------------------------

bake::Image render_fiv_file(const F::File& f, const Args& a, const bake::EnvMap& env, const bake::Camera& cam,
                            Scene& scene, std::string& how) {
  // Which occluder.
  std::vector<std::string> names;
  for (const auto& d : f.datasets) {
    const std::string pre = "/fiv/occluders/";
    if (d.path.rfind(pre, 0) == 0 && d.path.size() > pre.size() + 7 && d.path.ends_with("/shells"))
      names.push_back(d.path.substr(pre.size(), d.path.size() - pre.size() - 7));
  }
  if (names.empty()) throw bake::InputError(a.file, "no /fiv/occluders/<name>/shells");
  std::string name = a.occluder;
  if (name.empty()) {
    if (names.size() > 1) throw bake::InputError(a.file, "holds several occluders: choose one with --occluder NAME");
    name = names.front();
  } else if (std::find(names.begin(), names.end(), name) == names.end()) {
    throw bake::InputError(a.file, "has no occluder '" + name + "'");
  }
  const BakedOccluder baked = read_occluder(f, a.file, name, env);
  const auto& centre = baked.centre;
  const double R = baked.radius;
  const auto& env_fiv = floats(f, a.file, "/fiv/environment", {3, 3});
  const F::Dataset* cd = F::find_dataset(f, "/fiv/irradiance_cube");
  if (!cd) throw bake::InputError(a.file, "no dataset /fiv/irradiance_cube");
  check_same_environment(*cd, env, a.file);
  const auto& cube = floats(f, a.file, "/fiv/irradiance_cube", {6, 0, 0, 3});
  const shade::DifMap difmap{int(cd->shape[1]), cube.data()};
  shade::validate_difmap(difmap);

  // The occluder's mesh: the one the shells were baked from.
  std::string mesh_path = a.occluder_mesh;
  if (mesh_path.empty()) {
    mesh_path = string_attr(f.root_attrs, "source");
    if (!fs::exists(mesh_path) && fs::exists(fs::path(a.file).parent_path() / mesh_path))
      mesh_path = (fs::path(a.file).parent_path() / mesh_path).string();
    if (!fs::exists(mesh_path))
      throw bake::InputError(a.file, "the occluder mesh '" + mesh_path +
                                         "' (the file's 'source' attribute) does not exist: give it with --occluder-mesh");
  }
  const std::string want_sha = string_attr(f.root_attrs, "source_sha256");
  if (!want_sha.empty() && bake::sha256_file(mesh_path) != want_sha)
    throw bake::InputError(mesh_path, "is not the mesh " + a.file + " was baked from (SHA-256 differs from its source_sha256)");
  bake::MeshLoadOptions mopt;
  mopt.use_file_normals = false;
  const bake::Mesh occ = bake::load_mesh(mesh_path, mopt);

  std::vector<Vector3d> inst = a.instances.empty() ? std::vector<Vector3d>{Vector3d::Zero()} : a.instances;
  const Vector3d c0(centre[0], centre[1], centre[2]);
  double lowest = std::numeric_limits<double>::infinity();
  for (const auto& p : occ.positions) lowest = std::min(lowest, double(p.y()));
  double min_offset_y = inst[0].y();
  Vector3d mean = Vector3d::Zero();
  double spread = 0;
  for (const auto& t : inst) {
    min_offset_y = std::min(min_offset_y, t.y());
    mean += t;
  }
  mean /= double(inst.size());
  for (const auto& t : inst) spread = std::max(spread, Eigen::Vector2d(t.x() - mean.x(), t.z() - mean.z()).norm());
  const double ground_y = a.ground ? *a.ground : lowest + min_offset_y - 0.01 * R;
  const double half = a.ground_size ? *a.ground_size : 4 * R + spread;

  std::vector<bake::Mesh> parts = {bake::ground_quad(ground_y, c0.x() + mean.x(), c0.z() + mean.z(), half)};
  std::vector<shade::FivOccluder> occluders;
  for (size_t k = 0; k < inst.size(); ++k) {
    parts.push_back(bake::translated(occ, inst[k], name + "#" + std::to_string(k)));
    shade::FivOccluder o = baked.view;
    for (int c = 0; c < 3; ++c) o.centre[c] = float(centre[size_t(c)] + inst[k][c]);
    occluders.push_back(o);
    scene.spheres.push_back({c0 + inst[k], R});
  }
  scene.receiver_triangles = parts.front().triangles.size();
  scene.mesh = bake::merge_meshes(parts, "fiv scene");
  char buf[256];
  std::snprintf(buf, sizeof buf, "FIV occluder '%s' (%s, shells %dx%dx%d, R %.4g), %zu cop%s, ground y = %.4g, half-size %.4g",
                name.c_str(), mesh_path.c_str(), occluders[0].n_phi, occluders[0].n_theta, occluders[0].n_rho, R,
                inst.size(), inst.size() == 1 ? "y" : "ies", ground_y, half);
  scene.what = buf;
  how = std::string("prt::shade::shade_fiv per pixel (overlap correction ") + (a.overlap ? "on" : "off") +
        ", partial-occluder factor " + (a.partial ? "on" : "off") + "), shade_fiv_self on the occluders";

  const shade::FivShadeOptions opts{a.partial, a.overlap};
  const size_t tri_per_copy = occ.triangles.size();
  const bake::GBuffer g = bake::rasterize(scene.mesh, cam);
  return bake::shade_pixels(scene.mesh, g, [&](const bake::Fragment& fr, float* out) {
    const float p[3] = {float(fr.p.x()), float(fr.p.y()), float(fr.p.z())};
    const float n[3] = {float(fr.n.x()), float(fr.n.y()), float(fr.n.z())};
    float e[3];
    if (size_t(fr.triangle) < scene.receiver_triangles) {
      shade::shade_fiv(difmap, occluders.data(), int(occluders.size()), p, n, opts, e);
    } else {
      const size_t k = (size_t(fr.triangle) - scene.receiver_triangles) / tri_per_copy;
      shade::shade_fiv_self(env_fiv.data(), occluders[k], p, n, e);
      for (size_t j = 0; j < occluders.size(); ++j) {  // the other copies' shadows (eq. 11, no overlap term)
        if (j == k) continue;
        float o[3];
        shade::occluded_irradiance(occluders[j], p, n, a.partial, o);
        for (int c = 0; c < 3; ++c) e[c] = std::max(0.0f, e[c] - o[c]);
      }
    }
    for (int c = 0; c < 3; ++c) out[c] = e[c] * float(std::numbers::inv_pi);
  });
}

// ---- scene files (prtbake scene, schema v2) -----------------------------------------------------------------

bool is_scene_file(const F::File& f) {
  if (F::find_group_attrs(f, "/scene")) return true;
  return std::any_of(f.datasets.begin(), f.datasets.end(), [](const F::Dataset& d) { return d.path.starts_with("/objects/"); });
}

// One object as prtview draws it.
struct ViewObject {
  std::string name, role, how;
  bool receiver = false, casts_shadow = false;
  std::array<float, 3> albedo{1, 1, 1};
  bake::Mesh mesh;                     // world space
  std::vector<float> rgb;              // E/pi per vertex (white surface), Gouraud; empty: per pixel
  std::optional<BakedOccluder> shells; // per pixel: FIV self-shadows (eq. 12)
};

bake::Image render_scene_file(const F::File& f, const Args& a, const bake::EnvMap& env, const bake::Camera& cam,
                              Scene& scene, std::string& how) {
  if (!a.shade.empty() || !a.instances.empty() || !a.occluder_mesh.empty() || !a.occluder.empty() || a.ground ||
      a.ground_size || !a.overlap || !a.partial)
    throw UsageError("--shade, --instance, --occluder(-mesh), --ground(-size), --no-overlap and --no-partial do not apply to "
                     "scene files (" + a.file + "): each object is shaded with what it holds (see 'prtview --help')");
  if (const auto* sa = F::find_group_attrs(f, "/scene")) check_same_environment(*sa, "/scene", env, a.file);
  std::vector<std::string> names;
  const std::string pre = "/objects/", post = "/mesh/positions";
  for (const auto& d : f.datasets)
    if (d.path.starts_with(pre) && d.path.ends_with(post) && d.path.size() > pre.size() + post.size())
      names.push_back(d.path.substr(pre.size(), d.path.size() - pre.size() - post.size()));
  if (names.empty()) throw bake::InputError(a.file, "is a scene file without objects (no /objects/<name>/mesh/positions)");

  // What the runtime has beside the per-vertex data: the DifMap (unshadowed irradiance) and the
  // environment FIV, when some occluder got shells.
  std::optional<shade::DifMap> difmap;
  if (const F::Dataset* cd = F::find_dataset(f, "/fiv/irradiance_cube")) {
    check_same_environment(*cd, env, a.file);
    difmap = shade::DifMap{int(cd->shape[1]), floats(f, a.file, cd->path, {6, 0, 0, 3}).data()};
    shade::validate_difmap(*difmap);
  }
  const F::Dataset* env_fiv_d = F::find_dataset(f, "/fiv/environment");
  if (env_fiv_d) check_same_environment(*env_fiv_d, env, a.file);
  const float* env_fiv = env_fiv_d ? floats(f, a.file, env_fiv_d->path, {3, 3}).data() : nullptr;
  std::optional<bake::UnoccludedIrradiance> exact;  // AO without a DifMap
  // Flat grey: half the outgoing radiance of a white surface under a uniform sky of the
  // environment's mean radiance Lbar = L_00 / sqrt(4 pi) (mean over RGB).
  const auto L00 = env.project_sh(1);
  const float flat = float(0.5 * (L00[0] + L00[1] + L00[2]) / 3.0 / std::sqrt(4 * std::numbers::pi));

  std::vector<ViewObject> objects;
  for (const std::string& name : names) {
    ViewObject o;
    o.name = name;
    const std::string prefix = pre + name;
    const auto* attrs = F::find_group_attrs(f, prefix);
    o.role = attrs ? string_attr(*attrs, "role") : std::string();
    if (o.role != "receiver" && o.role != "occluder" && o.role != "both")
      throw bake::InputError(a.file, prefix + " has no valid 'role' attribute (receiver, occluder or both)");
    o.receiver = o.role != "occluder";
    o.casts_shadow = o.role != "receiver";
    if (const F::Attr* al = F::find_attr(*attrs, "albedo")) {
      const auto* v = std::get_if<std::vector<double>>(&al->value);
      if (!v || v->size() != 3) throw bake::InputError(a.file, prefix + ": 'albedo' must be 3 numbers");
      if ((*v)[0] > 0 || (*v)[1] > 0 || (*v)[2] > 0)
        for (size_t c = 0; c < 3; ++c) o.albedo[c] = float(std::max(0.0, (*v)[c]));
    }
    o.mesh = read_mesh(f, a.file, prefix);
    const size_t V = o.mesh.positions.size();
    const bool glossy_only = F::find_dataset(f, prefix + "/transfer/visibility") &&
                             !F::find_dataset(f, prefix + "/radiance/band1") && !F::find_dataset(f, prefix + "/transfer/diffuse");
    const std::string glossy_note = glossy_only ? " (glossy: not shaded by the runtime yet)" : "";
    if (F::find_dataset(f, prefix + "/radiance/band1")) {
      o.rgb = shade_band1_set(f, a.file, prefix, env, o.mesh, o.how);
      o.how = "band-1 radiance (shade_band1)";
    } else if (F::find_dataset(f, prefix + "/transfer/diffuse")) {
      o.rgb = shade_transfer_set(f, a.file, prefix, env, V, o.how);
      o.how = "diffuse transfer (project_latlong + shade_transfer)";
    } else if (F::find_dataset(f, prefix + "/ao")) {
      // AO x the unshadowed irradiance at the vertex normal: the runtime's DifMap when the file has
      // one (lookup_difmap), else the exact texel sum (bake::UnoccludedIrradiance).
      const auto& ao = floats(f, a.file, prefix + "/ao", {});
      if (!difmap && !exact) exact.emplace(env);
      o.rgb.resize(3 * V);
      for (size_t v = 0; v < V; ++v) {
        const float n[3] = {o.mesh.normals[v].x(), o.mesh.normals[v].y(), o.mesh.normals[v].z()};
        float e[3];
        if (difmap) {
          shade::lookup_difmap(*difmap, n, e);
        } else {
          const bake::Rgb u = (*exact)(o.mesh.normals[v].cast<double>());
          e[0] = float(u.r), e[1] = float(u.g), e[2] = float(u.b);
        }
        for (size_t c = 0; c < 3; ++c) o.rgb[3 * v + c] = ao[v] * e[c] * float(std::numbers::inv_pi);
      }
      o.how = std::string("AO x ") + (difmap ? "DifMap (lookup_difmap)" : "exact unshadowed irradiance") + " / pi" + glossy_note;
    } else if (env_fiv && F::find_dataset(f, "/fiv/occluders/" + name + "/shells")) {
      o.shells = read_occluder(f, a.file, name, env);
      o.how = "FIV self-shadows per pixel (shade_fiv_self)" + glossy_note;
    } else {
      o.rgb.assign(3 * V, flat);
      o.how = "flat grey (no per-vertex products, no FIV shells)" + glossy_note;
    }
    objects.push_back(std::move(o));
  }
  // Receivers first: the compared region is the triangle range [0, receiver_triangles).
  std::stable_partition(objects.begin(), objects.end(), [](const ViewObject& o) { return o.receiver; });

  std::vector<bake::Mesh> parts;
  std::vector<float> rgb;
  std::vector<uint8_t> per_pixel;
  scene.first_triangle = {0};
  scene.what = "scene: " + std::to_string(objects.size()) + " objects";
  how = "per object, times its albedo (white if none):";
  for (const ViewObject& o : objects) {
    const size_t T = o.mesh.triangles.size();
    for (size_t v = 0; v < o.mesh.positions.size(); ++v)
      for (size_t c = 0; c < 3; ++c) rgb.push_back(o.rgb.empty() ? 0.0f : o.rgb[3 * v + c] * o.albedo[c]);
    per_pixel.insert(per_pixel.end(), T, o.rgb.empty() ? 1 : 0);
    scene.casts_shadow.insert(scene.casts_shadow.end(), T, o.casts_shadow ? 1 : 0);
    scene.albedo.insert(scene.albedo.end(), T, o.albedo);
    scene.object_names.push_back(o.name);
    scene.object_receiver.push_back(o.receiver);
    scene.first_triangle.push_back(scene.first_triangle.back() + T);
    if (o.receiver) scene.receiver_triangles += T;
    if (o.casts_shadow) {
      bake::Sphere sp;
      bake::bounding_sphere(o.mesh, sp.centre, sp.radius);
      scene.spheres.push_back(sp);
    }
    char buf[160];
    std::snprintf(buf, sizeof buf, "%s %s (%zu vertices, albedo %.3g %.3g %.3g)", o.name.c_str(), o.role.c_str(),
                  o.mesh.positions.size(), o.albedo[0], o.albedo[1], o.albedo[2]);
    scene.what += std::string(scene.object_names.size() == 1 ? ": " : ", ") + buf;
    how += "\n  " + o.name + ": " + o.how;
    parts.push_back(o.mesh);
  }
  scene.mesh = bake::merge_meshes(parts, a.file);
  const bake::GBuffer g = bake::rasterize(scene.mesh, cam);
  return bake::shade_mixed(scene.mesh, g, rgb, per_pixel, [&](const bake::Fragment& fr, float* out) {
    const size_t k = size_t(std::upper_bound(scene.first_triangle.begin(), scene.first_triangle.end(), size_t(fr.triangle)) -
                            scene.first_triangle.begin()) - 1;
    const float p[3] = {float(fr.p.x()), float(fr.p.y()), float(fr.p.z())};
    const float n[3] = {float(fr.n.x()), float(fr.n.y()), float(fr.n.z())};
    float e[3];
    shade::shade_fiv_self(env_fiv, objects[k].shells->view, p, n, e);
    for (size_t c = 0; c < 3; ++c) out[c] = e[c] * float(std::numbers::inv_pi) * objects[k].albedo[c];
  });
}

// Everything that determines the reference picture, for --reference-cache.
std::string reference_key(const Scene& scene, const bake::EnvMap& env, const bake::Camera& cam,
                          const bake::ReferenceOptions& o, const std::string& description) {
  std::string bytes;
  auto put = [&](const void* p, size_t n) { bytes.append(static_cast<const char*>(p), n); };
  for (const auto& q : scene.mesh.positions) put(q.data(), 3 * sizeof(float));
  for (const auto& q : scene.mesh.normals) put(q.data(), 3 * sizeof(float));
  for (const auto& t : scene.mesh.triangles) put(t.data(), 3 * sizeof(uint32_t));
  put(o.casts_shadow.data(), o.casts_shadow.size());
  for (const auto& c : o.albedo) put(c.data(), 3 * sizeof(float));
  char buf[512];
  std::snprintf(buf, sizeof buf, "|%zu|eye %.17g %.17g %.17g at %.17g %.17g %.17g up %.17g %.17g %.17g fov %.17g near %.17g %dx%d",
                scene.receiver_triangles, cam.eye.x(), cam.eye.y(), cam.eye.z(), cam.at.x(), cam.at.y(), cam.at.z(),
                cam.up.x(), cam.up.y(), cam.up.z(), cam.fov_y_degrees, cam.near, cam.width, cam.height);
  bytes += buf;
  for (const auto& sp : o.occluder_spheres) {
    std::snprintf(buf, sizeof buf, "|sphere %.17g %.17g %.17g %.17g", sp.centre.x(), sp.centre.y(), sp.centre.z(), sp.radius);
    bytes += buf;
  }
  return bake::sha256_bytes(std::as_bytes(std::span<const char>(bytes.data(), bytes.size()))) + " env " +
         env.info().sha256 + " " + description;
}

// ---- main ----------------------------------------------------------------------------------------------

void write_image(const std::string& path, const bake::Image& linear, const bake::Image8& display) {
  if (fs::path(path).extension() == ".exr") bake::write_exr(path, linear);
  else bake::write_png(path, display);
}

int run(const Args& a) {
  const bool say = !a.quiet;
  const int threads = a.threads > 0 ? a.threads : tbb::info::default_concurrency();
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
  const bake::Camera cam = bake::parse_camera(a.camera, a.width, a.height);
  {  // fail before the work if the output cannot be written
    const fs::path out(a.output);
    const fs::path dir = out.has_parent_path() ? out.parent_path() : fs::path(".");
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) throw bake::InputError(a.output, "cannot write: directory '" + dir.string() + "' does not exist");
  }
  if (!fs::exists(a.file)) throw bake::InputError(a.file, "no such file");
  const F::File f = F::read_file(a.file);
  const bool has_fiv = F::find_dataset(f, "/fiv/irradiance_cube") != nullptr;
  const bool scene_file = is_scene_file(f);
  std::string kind = a.shade;
  if (scene_file) kind = "scene";
  else if (kind.empty()) kind = has_fiv ? "fiv" : F::find_dataset(f, "/transfer/diffuse") ? "transfer" : "band1";
  std::string env_path = a.env;
  if (env_path.empty()) {
    const auto* scene_attrs = F::find_group_attrs(f, "/scene");
    if (scene_file && scene_attrs) env_path = string_attr(*scene_attrs, "environment");
    for (const char* p : {"/fiv/irradiance_cube", "/radiance/band1"})
      if (const auto* d = F::find_dataset(f, p); d && env_path.empty()) env_path = string_attr(d->attrs, "environment");
    if (env_path.empty()) throw bake::InputError(a.file, "holds no environment name: give one with --env ENV.exr");
    if (!fs::exists(env_path) && fs::exists(fs::path(a.file).parent_path() / env_path))
      env_path = (fs::path(a.file).parent_path() / env_path).string();
    if (const std::string sf = scene_attrs ? string_attr(*scene_attrs, "scene_file") : std::string();
        !fs::exists(env_path) && !sf.empty() && fs::exists(fs::path(sf).parent_path() / env_path))
      env_path = (fs::path(sf).parent_path() / env_path).string();
    if (!fs::exists(env_path))
      throw bake::InputError(env_path, "no such file (the environment " + a.file + " was baked with): give it with --env ENV.exr");
  }
  const bake::UpAxis up = string_attr(f.root_attrs, "up_axis") == "z" ? bake::UpAxis::Z : bake::UpAxis::Y;
  const bake::EnvMap env = bake::EnvMap::load(env_path, up);

  Scene scene;
  std::string how;
  Timer t_run;
  bake::Image runtime = kind == "scene" ? render_scene_file(f, a, env, cam, scene, how)
                        : kind == "fiv"   ? render_fiv_file(f, a, env, cam, scene, how)
                                          : render_vertex_file(f, a, kind, env, cam, scene, how);
  const double runtime_seconds = t_run.seconds();
  if (say) {
    std::printf("%s: %s\nenvironment: %s (%dx%d %s)\nview: %dx%d, %s\n", a.file.c_str(), scene.what.c_str(),
                env_path.c_str(), env.info().width, env.info().height, env.info().layout.c_str(), a.width, a.height,
                a.camera.c_str());
    std::printf("runtime: %s: %.3f s\n", how.c_str(), runtime_seconds);
    std::fflush(stdout);
  }
  for (float v : runtime.rgb)
    if (!std::isfinite(v)) throw bake::ContractError("the runtime render produced a non-finite value");
  if (say && !scene.object_names.empty()) {  // scene files: what each object shows (mean over its pixels)
    const bake::GBuffer g = bake::rasterize(scene.mesh, cam);
    for (size_t k = 0; k < scene.object_names.size(); ++k) {
      double sum[3] = {0, 0, 0};
      size_t n = 0;
      for (size_t i = 0; i < g.triangle.size(); ++i) {
        const int32_t t = g.triangle[i];
        if (t < 0 || size_t(t) < scene.first_triangle[k] || size_t(t) >= scene.first_triangle[k + 1]) continue;
        for (size_t c = 0; c < 3; ++c) sum[c] += double(runtime.rgb[3 * i + c]);
        ++n;
      }
      if (n > 0)
        std::printf("  object %s: runtime mean %.9g %.9g %.9g (%zu pixels)\n", scene.object_names[k].c_str(), sum[0] / double(n),
                    sum[1] / double(n), sum[2] / double(n), n);
    }
  }

  if (a.mode == Output::Runtime) {
    const double exposure = a.exposure ? *a.exposure : bake::auto_exposure(runtime, {});
    write_image(a.output, runtime, bake::tone_map(runtime, exposure));
    if (say) std::printf("exposure %.4g; wrote %s\n", exposure, a.output.c_str());
    return 0;
  }

  bake::ReferenceOptions ropt;
  ropt.samples = a.samples;
  ropt.seed = a.seed;
  ropt.occluder_spheres = scene.spheres;
  ropt.casts_shadow = scene.casts_shadow;
  ropt.albedo = scene.albedo;
  const bake::ReferenceRenderer rr(scene.mesh, env, ropt);
  std::optional<bake::ReferenceImage> cached;
  const std::string key = reference_key(scene, env, cam, ropt, rr.description());
  if (!a.reference_cache.empty()) cached = bake::load_reference(a.reference_cache, key);
  const tool::ProgressBar bar(a.quiet ? tool::ProgressStyle::Quiet : tool::ProgressStyle::Auto);
  const bake::ReferenceImage ref =
      cached ? std::move(*cached) : rr.render(cam, bar.monitor(&tool::interrupt_token()));
  if (say && cached) std::printf("reference: %s: read from %s\n", rr.description().c_str(), a.reference_cache.c_str());
  if (say && !cached)
    std::printf("reference: %s: %.2f s, %.2f M rays/s\n", rr.description().c_str(), ref.seconds,
                double(ref.rays) / ref.seconds / 1e6);
  if (!cached && !a.reference_cache.empty()) bake::save_reference(a.reference_cache, ref, key);
  const bake::GBuffer raster = bake::rasterize(scene.mesh, cam);
  // Compared pixels: both renders see geometry (and, for 'receiver', both see the receiver).
  const std::string region = !a.region.empty() ? a.region : kind == "fiv" || kind == "scene" ? "receiver" : "all";
  const size_t n_px = size_t(a.width) * size_t(a.height);
  std::vector<uint8_t> mask(n_px, 0), covered(n_px, 0);
  for (size_t i = 0; i < n_px; ++i) {
    const int32_t r = raster.triangle[i], t = ref.gbuffer.triangle[i];
    covered[i] = r >= 0 && t >= 0;
    mask[i] = region == "all" ? covered[i]
                              : uint8_t(covered[i] && size_t(r) < scene.receiver_triangles && size_t(t) < scene.receiver_triangles);
  }
  if (std::count(mask.begin(), mask.end(), 1) == 0)
    throw bake::InputError("--camera", "no pixel shows the " + std::string(region == "all" ? "geometry" : "receiver") +
                                           " in both renders: nothing to compare (point the camera at the scene)");
  const double exposure = a.exposure ? *a.exposure : bake::auto_exposure(ref.radiance, covered);
  if (a.mode == Output::Reference) {
    write_image(a.output, ref.radiance, bake::tone_map(ref.radiance, exposure));
    if (say) std::printf("exposure %.4g; wrote %s\n", exposure, a.output.c_str());
    return 0;
  }
  const bake::ImageError e = bake::compare_images(runtime, ref.radiance, mask, &ref.std_error);
  const bake::ImageError all = bake::compare_images(runtime, ref.radiance, covered, &ref.std_error);
  // Stable, greppable lines (bench/figures.sh reads "NRMSE").
  std::printf("NRMSE %.5f (%s, %zu pixels; RMSE %.4g, reference range [%.4g, %.4g], max |error| %.4g)\n", e.nrmse,
              region.c_str(), e.pixels, e.rmse, e.ref_min, e.ref_max, e.max_abs);
  std::printf("reference noise %.5f (RMS standard error / range); noise-corrected NRMSE %.5f\n", e.ref_noise,
              e.nrmse_noise_corrected);
  if (region != "all") std::printf("NRMSE over all covered pixels %.5f (%zu pixels)\n", all.nrmse, all.pixels);
  // Scene files: each receiver's share, RMSE over the pixels where both renders see that object,
  // divided by the same range (so NRMSE^2 = sum_k (pixels_k / pixels) NRMSE_k^2).
  const double range = e.ref_max - e.ref_min > 0 ? e.ref_max - e.ref_min : std::abs(e.ref_max) > 0 ? std::abs(e.ref_max) : 1.0;
  for (size_t k = 0; k < scene.object_names.size(); ++k) {
    if (!scene.object_receiver[k]) continue;
    std::vector<uint8_t> mk(n_px, 0);
    const auto in = [&](int32_t t) { return t >= 0 && size_t(t) >= scene.first_triangle[k] && size_t(t) < scene.first_triangle[k + 1]; };
    for (size_t i = 0; i < n_px; ++i) mk[i] = in(raster.triangle[i]) && in(ref.gbuffer.triangle[i]);
    if (std::count(mk.begin(), mk.end(), 1) == 0) continue;
    const bake::ImageError ek = bake::compare_images(runtime, ref.radiance, mk, &ref.std_error);
    std::printf("  object %s: NRMSE %.5f (%zu pixels; its RMSE %.4g / the range above)\n", scene.object_names[k].c_str(),
                ek.rmse / range, ek.pixels, ek.rmse);
  }
  bake::Image diff(a.width, a.height);
  for (size_t i = 0; i < diff.rgb.size(); ++i) diff.rgb[i] = mask[i / 3] ? runtime.rgb[i] - ref.radiance.rgb[i] : 0.0f;
  const bake::Image8 err8 = bake::false_colour_error(runtime, ref.radiance, mask, e.ref_max - e.ref_min, a.error_scale);
  if (a.mode == Output::Error) {
    write_image(a.output, diff, err8);
  } else {
    const bake::Image8 parts[3] = {bake::tone_map(runtime, exposure), bake::tone_map(ref.radiance, exposure), err8};
    if (fs::path(a.output).extension() == ".exr") {
      bake::Image strip(3 * a.width, a.height);
      const bake::Image* src[3] = {&runtime, &ref.radiance, &diff};
      for (int k = 0; k < 3; ++k)
        for (int y = 0; y < a.height; ++y)
          for (int x = 0; x < a.width; ++x)
            for (int c = 0; c < 3; ++c) strip.at(k * a.width + x, y)[c] = src[k]->at(x, y)[c];
      bake::write_exr(a.output, strip);
    } else {
      bake::write_png(a.output, bake::hstack(parts));
    }
  }
  if (say)
    std::printf("exposure %.4g; error map full scale %.3g x range; wrote %s\n", exposure, a.error_scale, a.output.c_str());
  return 0;
}

int prtview_main(int argc, char** argv) {
  const Args a = parse(argc, argv);
  tool::install_interrupt_handler();
  return run(a);
}

} // namespace

int main(int argc, char** argv) { return tool::run_tool("prtview", prtview_main, argc, argv); }
