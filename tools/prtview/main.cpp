// prtview — look at a baked file: render it shaded by the runtime library (prtshade), render the
// same view with Embree ray-traced ground truth, and show and measure the difference. A thin
// shell: read_file.h reads the file (formats/), scenes.h assembles what is drawn and shades it
// with prtshade, view/ rasterizes, ray-traces, compares and writes the pictures; this file holds
// the command line (CLI11) and the report.
#include "area.h"
#include "progress_bar.h"
#include "read_file.h"
#include "scenes.h"
#include "tool_main.h"

#include <view/camera.h>
#include <view/exposure.h>
#include <view/image.h>
#include <view/raster.h>
#include <view/reference.h>
#include <view/text.h>

#include <bake/bake/bounce.h>
#include <bake/core/error.h>
#include <bake/core/sha256.h>
#include <bake/environment/envmap.h>
#include <formats/asset.h>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <tbb/global_control.h>
#include <tbb/info.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

namespace fs = std::filesystem;
namespace F = prt::formats;
using namespace prt;
using Eigen::Vector3d;

namespace {

constexpr const char* kDescription =
    "prtview - render a baked file shaded by the runtime library, next to ray-traced ground truth\n\n"
    "  prtview FILE.prt.h5 -o IMAGE.png|IMAGE.exr [--camera eye=X,Y,Z:at=X,Y,Z[:up=X,Y,Z][:fov=DEG]]\n"
    "          [--env ENV.exr] [--size WxH] [--reference | --error | --triptych] [OPTIONS]\n\n"
    "  A first look needs only the file and an image: 'prtview baked.prt.h5 -o look.png' shows the best\n"
    "  product the file holds (and says what else it holds), frames the geometry without its large flat\n"
    "  parts (a ground), prints the camera to copy into --camera, and the exposure, fixed by the environment.\n";

constexpr const char* kFooter = R"(
WHAT IS DRAWN
  Every picture shows outgoing radiance of a white diffuse surface, E/pi (albedo 1), where E is
  the irradiance; a constant sky of radiance L shows as L (scene files: times each object's
  albedo; files baked with bounces: times their albedo, see INTERREFLECTIONS). Three kinds of file:

  per-vertex files (/mesh + /transfer/diffuse, /radiance/band1 or /ao, from 'prtbake vertex'):
    the mesh is rasterized (software, top-left fill rule, z-buffer, perspective-correct
    interpolation), each vertex is shaded by prtshade and the colours are interpolated across
    triangles (Gouraud), as an engine would:
      transfer  the environment ENV is projected to SH (prt::shade::project_latlong, the order
                of the file) and every vertex gets sum_i T_i L_i (prt::shade::shade_transfer);
                any environment works: the transfer does not depend on the lighting.
      band1     E = 4pi/3 sum_m y_1m(n) R_m at the baked normal (prt::shade::shade_band1): exact
                all-frequency shadows under the environment the file was baked with. R is
                /radiance/band1, or the band-1 coefficients of /radiance/shadowed (the same
                integrals) when the file holds only that.
      ao        AO x E_unocc(n)/pi at each vertex, E_unocc the environment's unshadowed
                irradiance at the baked normal (bake/environment/irradiance.h): the ambient-occlusion
                approximation. Without --env: a constant white sky (L = 1), so the picture IS
                the AO (1 = white, 0 = black) and the reference is the true AO of each pixel.
    The first look (no --shade) shows the best the file holds: band1, else transfer, else ao
    (band1 only under its own environment: with another --env, transfer), and its first line
    says so and names the others.
  per-texel files (/mesh/uv + /lightmap/... from 'prtbake texel', format version 5): drawn per
    texel as an engine samples a lightmap (formats/SCHEMA.md): each pixel's UV interpolated from
    its triangle's three corner UVs, the lightmap's product filtered bilinearly at texel
    coordinates (u W - 1/2, v H - 1/2) (clamped to the edge), then the same prtshade formulas as
    for a vertex (band1 and ao at the pixel's interpolated normal). stderr and the summary say
    "per texel, WxH lightmap" and count the pixels whose bilinear footprint reached an empty
    texel (0 when the padding does its job). --per-vertex draws a file's per-vertex products
    instead (an error when it holds none: a texel bake writes none).
  FIV files (/fiv from 'prtbake fiv', paper 004): the occluder mesh (from --occluder-mesh, else
    the file's 'source' attribute; its SHA-256 must match the file's) stands on a square ground
    plane (the receiver), and each pixel is shaded by prtshade: the ground with
    prt::shade::shade_fiv (DifMap minus each occluder's trilinear FIV lookup, cases A/B/C with
    the partial-occluder factor, overlap correction for several occluders: paper 004 sec. 4.3.1),
    the occluder with its self-shadows minus the other copies' shadows: the self-shadows from the
    file's per-vertex band-1 radiance when it holds it (prtbake fiv --self-shadows vertex, the
    default; shade_fiv_member_given_self), else eq. 12 from the shells (shade_fiv_self, sec.
    4.3.2; shade_fiv_member).
  FIV scenes (dynamic occluders): a scene file whose objects have FIV shells, with --shade fiv or
    --instance/--instances: those objects are the occluders, placed as copies moved from where
    they were baked (default: each once, in place), on a ground plane, shaded as above (the
    self-shadows from /fiv/occluders/<name>/self_band1 when the file has it, prtbake scene's
    default bake.fiv.self_shadows "vertex"; else from the shells). The
    frame's cost (rasterise + shade, the file's reading not counted) is printed. E.g. 50 copies
    of three occluders (data/scene_fiv_occluders.json, data/fiv_instances50.json):
      prtbake scene data/scene_fiv_occluders.json -o occ.prt.h5
      prtview occ.prt.h5 --instances data/fiv_instances50.json --triptych -o fiv50.png

  scene files (/objects/<name>/ and /scene from 'prtbake scene', schema v2-3): every object, in world
    space, in one z-buffer, each shaded with what the file holds for it, times its diffuse albedo
    (the 'albedo' attribute of /objects/<name>; white if it is zero):
      band1     band-1 radiance when the object has it (shade_band1, E/pi), else
      transfer  diffuse transfer (project_latlong + shade_transfer), else
      AO        AO x E_unocc(n)/pi at each vertex, E_unocc the unshadowed irradiance from the
                file's DifMap (lookup_difmap; the exact texel sum if the file has none) - the
                ambient-occlusion approximation. Glossy-only objects (transfer/visibility only)
                land here with their AO-shaded diffuse response; their highlights are drawn by
                --shade glossy (below).
      FIV self  objects without per-vertex products (occluder-only) that have FIV shells
                (/fiv/occluders/<name>) and /fiv/environment: per pixel, the self-shadows minus
                the shadows of the other objects that have FIV shells (eq. 11: the same
                composition as the copies of an FIV file); the self-shadows Gouraud from the
                object's self_band1 (shade_fiv_member_given_self) when the file has it, else
                eq. 12 from its shells (shade_fiv_member), else
      flat      grey: 0.5 x the environment's mean radiance.
    The environment must be the one of /scene (checked by SHA-256); default: its 'environment'.
    --shade (but glossy, area, area-exact, and fiv: FIV scenes below), --occluder-mesh,
    --ground(-size), --no-overlap/--no-partial do not apply. The reference renders the same
    objects: "occluder" and "both" objects cast shadows, "receiver" objects do not (not even on
    themselves: the scene semantics, bake/bake/scene.h), and a pixel shows albedo x E/pi.

  glossy objects of scene files (--shade glossy; objects with a phong_exponent, whose
    /objects/<name>/radiance/shadowed or transfer/visibility the scene plan baked at the lobe's
    order): their specular lobes only, other objects black (they still cast shadows by their
    roles): per vertex specular x int L V H k_s(r.w) dw, k_s the normalised Phong lobe
    (s+1)/2pi max(t,0)^s about the reflection r of the direction to the eye, then the lobe band by
    band (prtshade/glossy.h); Gouraud. An object baked per texel (its /lightmap holds S or U) is
    shaded per pixel instead: the bilinear sample at the pixel's UV, the pixel's normal and view
    direction. Two routes, the one used printed per object:
      B  (when the object has radiance/shadowed; format_version 4) the baked shadowed radiance
         S = int L V H y dw (paper 001 sec. 4, material editing): exact shadows under the baked
         environment, any order (prt::shade::shade_glossy_radiance_vertices);
      A  otherwise: the environment's SH at the object's order times the visibility transfer by
         the SH triple product (prt::shade::shade_glossy_vertices; orders up to 16).
    --glossy-route a|b forces one. --phong S swaps every lobe's exponent at run time (neither S
    nor U depends on it; the order stays the baked one). The reference traces the same lobe per
    pixel (Embree, mixture of the lobe and the environment, --samples rays).

  area lights of scene files (/lights, schema v3; --shade area or area-exact): only the lights'
    direct light, no environment: each object's albedo/pi x sum_l radiance_l E_l.
      area        the baked per-vertex area_lights/irradiance (E_l at unit radiance) x each
                  light's radiance as /lights/<name> stores it, interpolated (objects without it,
                  e.g. occluder-only ones, per pixel as below);
      area-exact  per pixel, exact soft shadows from the stored lights (paper 003: each light's
                  spherical polygon minus the casting triangles', clipped to the horizon,
                  Lambert's closed form).
    The reference samples each light's area with --samples shadow rays per pixel and light
    (Embree; 8 replicates give the standard error) over the same pixels and casters.

  --reference renders the same view by ray tracing (Embree): a primary ray per pixel centre, then
  E = (exact unshadowed irradiance, the function the DifMap samples: bake/environment/irradiance.h) - (QMC
  estimate of the light the scene blocks), with --samples shadow rays per pixel and a per-pixel standard error.
  That is the standard rendering equation with visibility, the paper's "brute force" reference.

  INTERREFLECTIONS (issue 31). A per-vertex transfer or
  band-1 radiance baked with 'prtbake vertex --bounces B --albedo A' holds the light the mesh
  reflects onto itself; its exit radiance is A x sum T_i L_i. For such a file both pictures show
  A x E/pi (the runtime's unchanged dot product times A) and the reference is path traced with the
  file's B bounces and albedo A, said in the log ("reference: path traced, 3 bounces, albedo 0.6")
  and above the triptych's panel, as reference (3 bounces, albedo 0.6). Each path vertex takes the
  environment's direct light (the estimator above, one sample) and sends a cosine-weighted
  continuation ray; back faces are black; the paths stop at exactly B bounces (view/reference.h).
  --bounces B and --albedo A override the file's (--bounces 0: the direct-only reference, to see
  what the bounces add); scene files bounce with their objects' albedos, each object as the bake
  bounced it (one that reflects nothing there reflects nothing here; a pixel drawn from AO gathers
  nothing). Area views (--shade area) path-trace the area lights' bounces the same way, each path
  vertex sampling every light once, when the scene's area-light irradiance carries bounces.

OUTPUT (-o; the extension picks the format: .png for people, .exr for numbers)
  (default)       the runtime render.
  --reference     the ray-traced reference instead.
  --error         a false-colour map of |runtime - reference| (PNG: black = 0 ... pale yellow =
                  --error-scale x the reference's range; grey = not compared. EXR: the signed
                  difference runtime - reference in float) and prints NRMSE.
  --triptych      runtime | reference | error side by side (same exposure), prints NRMSE.
                  With bounces (a file baked with --bounces, or --bounces B), a fourth panel
                  first: the direct light alone, ray traced, and its error against the reference
                  is printed: direct | baked with bounces | reference | error.
  PNG: 8-bit sRGB of (exposure x value), clipped at 1. --exposure X, default: fixed by the
  environment, never by the pixels, so a file gives the same exposure alone, in a triptych and
  under any camera: 1 / the brightest unshadowed white surface, max over normals n of the
  luminance of E_unocc(n)/pi, to 4 digits (view/exposure.h; a white sky: 1); area lights: 1 / the
  99th percentile of the baked per-vertex lighting. Printed with what it came from.
  PNG triptychs and error maps are labelled: a caption above each panel, the error panel's colour
  scale, and two lines under them: RMSE/NRMSE in this picture and the file's own error report
  (also printed as the 'quality:' line). EXR: float RGB, linear, no labels.
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
  (RMS standard error / range) with the noise-corrected NRMSE sqrt(RMSE^2 - sigma^2)/range, and
  the relative L2 error |runtime - reference| / |reference| (the same pixels and channels; the
  issue-31 bar), also noise-corrected.

EXAMPLES
  prtbake vertex data/bunny_ground.obj --ao --transfer 3 --radiance data/sunset.exr -o bunny.prt.h5
  prtview bunny.prt.h5 -o look.png                 the first look: band-1 radiance, framed on the bunny
  prtview bunny.prt.h5 --triptych -o compare.png   the same view next to the reference, labelled
  prtbake fiv data/bunny.obj --env data/forest.exr --shells 64x33x30 -o bunny.fiv.prt.h5
  prtview bunny.fiv.prt.h5 --camera eye=0,22,24:at=0,0,2:fov=40 -o shadow.png
  prtview bunny.fiv.prt.h5 --camera eye=0,22,24:at=0,0,2:fov=40 --triptych -o compare.png
  prtview bunny.fiv.prt.h5 --camera eye=0,22,24:at=0,0,2 --instance -4,0,0 --instance 4,0,0 --error -o e.png
  prtbake vertex data/bunny_ground.obj --transfer 3 -o default.prt.h5
  prtview default.prt.h5 --env data/sunset.exr --camera eye=0,14,26:at=0,3,0 --triptych -o t.png
  prtbake vertex data/bunny_ground.obj --transfer 3 --bounces 3 --albedo 0.6 -o bounced.prt.h5
  prtview bounced.prt.h5 --env data/sunset.exr --triptych -o bounced.png   against 3 path-traced bounces
  prtbake scene data/scene_example.json -o scene.prt.h5
  prtview scene.prt.h5 --camera eye=0,18,34:at=0,2,0 --size 320x240 --triptych -o scene.png
  prtview scene.prt.h5 --shade glossy --phong 128 --triptych -o statue.png

)";

using tool::UsageError;

enum class Output { Runtime, Reference, Error, Triptych };

struct Args {
  std::string file, env, camera, output, shade, region, reference_cache;
  int width = 256, height = 256;
  Output mode = Output::Runtime;
  uint32_t samples = 1024;
  uint64_t seed = 1;
  std::optional<double> exposure;
  double error_scale = 0.1;
  prtview::FivView fiv;
  std::string ggx;  // --ggx ALPHA[,F0]
  std::optional<double> phong;  // --phong S (--shade glossy)
  std::string glossy_route;     // --glossy-route a|b (--shade glossy; empty: B where the file has S)
  bool quiet = false;
  bool per_vertex = false;  // --per-vertex: the per-vertex products even when the file has a lightmap
  int threads = 0;
  std::optional<uint32_t> bounces;  // --bounces B: the reference's interreflections (default: the file's)
  std::optional<double> albedo;     // --albedo A: a single mesh's grey albedo (default: the file's)
  double env_rotate = 0;            // --env-rotate DEG: the environment turned about +Y (--shade transfer)
};

// "[NAME@]X,Y,Z" → a copy of occluder NAME (empty: the default one) moved by (X,Y,Z) (an --instance).
prtview::FivInstance parse_instance(const std::string& text) {
  prtview::FivInstance out;
  const size_t at = text.find('@');
  if (at != std::string::npos) {
    out.occluder = text.substr(0, at);
    if (out.occluder.empty()) throw UsageError("--instance expects NAME@X,Y,Z or X,Y,Z, got '" + text + "'");
  }
  const std::string t = at == std::string::npos ? text : text.substr(at + 1);
  size_t start = 0;
  for (int k = 0; k < 3; ++k) {
    const size_t comma = t.find(',', start);
    if ((k < 2) != (comma != std::string::npos)) throw UsageError("--instance expects [NAME@]X,Y,Z, got '" + text + "'");
    const std::string s = t.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    char* end = nullptr;
    out.offset[k] = std::strtod(s.c_str(), &end);
    if (s.empty() || end != s.c_str() + s.size() || !std::isfinite(out.offset[k]))
      throw UsageError("--instance expects a number, got '" + s + "' in '" + text + "'");
    start = comma + 1;
  }
  return out;
}

// --instances FILE: {"instances": [{"occluder": NAME, "translate": [X, Y, Z]}, ...]} ("occluder"
// optional: the default one). Errors name the file and the entry.
std::vector<prtview::FivInstance> read_instances(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw bake::InputError(path, "cannot open the instance list");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw bake::InputError(path, std::string("is not JSON: ") + e.what());
  }
  if (!j.is_object() || !j.contains("instances") || !j["instances"].is_array())
    throw bake::InputError(path, "expected {\"instances\": [{\"occluder\": NAME, \"translate\": [X, Y, Z]}, ...]}");
  std::vector<prtview::FivInstance> out;
  for (size_t k = 0; k < j["instances"].size(); ++k) {
    const nlohmann::json& e = j["instances"][k];
    const std::string where = "instances[" + std::to_string(k) + "]";
    if (!e.is_object()) throw bake::InputError(path, where + " is not an object");
    for (const auto& [key, value] : e.items())
      if (key != "occluder" && key != "translate")
        throw bake::InputError(path, where + ": unknown key '" + key + "' (known: occluder, translate)");
    prtview::FivInstance i;
    if (e.contains("occluder")) {
      if (!e["occluder"].is_string() || e["occluder"].get<std::string>().empty())
        throw bake::InputError(path, where + ".occluder must be a non-empty string");
      i.occluder = e["occluder"].get<std::string>();
    }
    const nlohmann::json* t = e.contains("translate") ? &e["translate"] : nullptr;
    if (!t || !t->is_array() || t->size() != 3) throw bake::InputError(path, where + ".translate must be [X, Y, Z]");
    for (int c = 0; c < 3; ++c) {
      if (!(*t)[size_t(c)].is_number() || !std::isfinite((*t)[size_t(c)].get<double>()))
        throw bake::InputError(path, where + ".translate must hold three finite numbers");
      i.offset[c] = (*t)[size_t(c)].get<double>();
    }
    out.push_back(i);
  }
  if (out.empty()) throw bake::InputError(path, "lists no instance");
  return out;
}

// `text` broken at spaces into lines of at most `width` characters (CLI11 indents each line).
std::string wrap(const std::string& text, size_t width = 66) {
  std::string out, line;
  size_t start = 0;
  while (start <= text.size()) {
    size_t end = text.find(' ', start);
    if (end == std::string::npos) end = text.size();
    const std::string word = text.substr(start, end - start);
    if (!line.empty() && line.size() + 1 + word.size() > width) {
      out += line + "\n";
      line.clear();
    }
    line += (line.empty() ? "" : " ") + word;
    start = end + 1;
  }
  return out + line;
}

// The command line; nullopt after --help or --version (printed).
std::optional<Args> parse(int argc, char** argv) {
  Args a;
  CLI::App app(kDescription, "prtview");
  app.set_version_flag("--version", std::string("prtview ") + PRT_VERSION);
  app.footer(std::string(kFooter) + tool::kExitStatusHelp);
  app.get_formatter()->column_width(28);
  app.allow_extras();  // reported below as "unknown option" / "unexpected argument"
  std::string size, shade_kind, region;
  double phong_value = 0;
  std::vector<std::string> instances;
  std::string instances_file;
  bool reference = false, error = false, triptych = false, no_overlap = false, no_partial = false;
  double exposure = 0, ground = 0, ground_size = 0;
  app.add_option("file", a.file, "the baked file (FILE.prt.h5)");
  app.add_option("-o,--output", a.output, "IMAGE.png or IMAGE.exr (the extension picks the format; see OUTPUT)");
  app.add_option("--env", a.env,
                 "environment (OpenEXR lat-long or cube). Default: the file's 'environment' attribute. band1, FIV and "
                 "scene files must be shown under the environment they were baked with (checked by SHA-256).");
  app.add_option("--camera", a.camera,
                 "eye=X,Y,Z:at=X,Y,Z[:up=X,Y,Z][:fov=DEG]: eye, at (required), up (default 0,1,0), fov = vertical "
                 "field of view in degrees (default 45); world units of the mesh. Default: a three-quarter view "
                 "from above the front that frames the geometry without its large flat parts, e.g. a ground (printed, "
                 "to copy and adjust).");
  app.add_option("--size", size, "WxH: image size in pixels (default 256x256).");
  app.add_flag("--reference", reference, "write the ray-traced reference instead of the runtime render.");
  app.add_flag("--error", error, "write a false-colour map of |runtime - reference| and print NRMSE.");
  app.add_flag("--triptych", triptych, "write runtime | reference | error side by side and print NRMSE.");
  app.add_option("--bounces", a.bounces,
                 "reference: B bounces of diffuse interreflection, path traced (default: the 'bounces' the file's transfer or "
                 "band-1 radiance was baked with, else 0; environment lighting only).")
      ->check(CLI::Range(0, 64));
  app.add_option("--albedo", a.albedo,
                 "the grey albedo of a single-mesh file's surface (default: the file's 'albedo' attribute, that of its bounces): "
                 "the picture and the reference show albedo x E/pi, and the reference bounces with it.")
      ->check(CLI::Range(0.0, 0.999));
  app.add_option("--shade", a.shade,
                 "transfer | band1 | ao | fiv (default: fiv if the file has /fiv, else the best it holds of "
                 "band1, transfer, ao); scene files: glossy (the glossy objects' specular lobes), and with area "
                 "lights area | area-exact (see WHAT IS DRAWN).")
      ->check(CLI::IsMember({"transfer", "band1", "ao", "fiv", "glossy", "area", "area-exact"}));
  CLI::Option* phong_opt = app.add_option("--phong", phong_value,
                                          "S > 0: --shade glossy only: shade every glossy object with the Phong exponent S "
                                          "instead of its own (the baked visibility transfer does not depend on it).");
  app.add_option("--glossy-route", a.glossy_route,
                 "a | b: --shade glossy only: force route A (triple product of the environment and "
                 "transfer/visibility) or B (the baked radiance/shadowed); default B where the file holds it.")
      ->check(CLI::IsMember({"a", "b"}));
  app.add_option("--ggx", a.ggx,
                 "ALPHA[,F0]: --shade area-exact only: add a GGX specular layer of roughness ALPHA in [0.01, 1] and "
                 "Schlick F0 in [0, 1] (default 0.04) over the diffuse albedo, per pixel through linearly transformed "
                 "cosines (our own fit: prtshade/ltc.h); the reference weights its light samples by the same BRDF.");
  app.add_option("--samples", a.samples,
                 "reference: QMC shadow rays per pixel, a multiple of 8: 8 independent randomised-QMC replicates of "
                 "N/8 rays; their spread gives the standard error (default 1024).")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--seed", a.seed, "reference randomisation seed (default 1); same seed, same bytes.")
      ->check(CLI::NonNegativeNumber);
  CLI::Option* exposure_opt = app.add_option("--exposure", exposure, "PNG exposure (default: fixed by the environment; see OUTPUT).");
  app.add_option("--error-scale", a.error_scale, "error map full scale as a fraction of the reference range (default 0.1).");
  app.add_option("--region", a.region, "receiver | all (see ERROR NUMBERS).")->check(CLI::IsMember({"receiver", "all"}));
  app.add_option("--reference-cache", a.reference_cache,
                 "C.exr: keep the reference render (radiance, standard error, primary hits) in C.exr and reuse it "
                 "while everything that determines it (scene, view, environment, samples, seed) is unchanged: "
                 "compare several bakes against one reference without tracing it again.");
  app.add_option("--occluder-mesh", a.fiv.occluder_mesh,
                 "FIV files: the occluder's mesh (default: the file's 'source' attribute, relative to the working "
                 "directory, else to FILE's directory).");
  app.add_option("--occluder", a.fiv.occluder, "FIV files: which /fiv/occluders/NAME (default: the only one).");
  app.add_option("--instance", instances,
                 "FIV files and scene files with FIV shells: [NAME@]X,Y,Z: place a copy of occluder NAME (default: "
                 "--occluder, else the only one) moved by (X,Y,Z) from where it was baked; repeat for several copies "
                 "(default: each occluder once where it was baked). Copies share the baked shells: dynamic occluders.")
      ->allow_extra_args(false);
  app.add_option("--instances", instances_file,
                 "FILE.json: many copies at once, {\"instances\": [{\"occluder\": NAME, \"translate\": [X, Y, Z]}, "
                 "...]}; added after the --instance ones (data/fiv_instances50.json places 50 copies of the occluders of data/scene_fiv_occluders.json).");
  CLI::Option* ground_opt = app.add_option(
      "--ground", ground, "FIV files: height of the ground plane (default: 1% of the bounding radius R below the lowest copy).");
  CLI::Option* ground_size_opt =
      app.add_option("--ground-size", ground_size, "FIV files: half-size of the ground square (default 4R + the copies' spread).");
  app.add_flag("--no-overlap", no_overlap, "FIV files: switch off the overlap correction for several occluders (eq. 13-14).");
  app.add_flag("--no-partial", no_partial, "FIV files: switch off the partial-occluder correction (case B).");
  std::string proxy = "cone";
  app.add_option("--proxy", proxy,
                     "FIV files: the occluder proxy of the overlap and partial-occluder corrections: cone (default: the "
                     "file's cone table where it has one, prtshade/fiv.h \"Tight proxies\") or sphere (the paper's "
                     "bounding sphere).")
      ->check(CLI::IsMember({"cone", "sphere"}));
  app.add_flag("--per-vertex", a.per_vertex,
               "per-vertex and per-texel files: draw the per-vertex products (Gouraud) even when the file has a "
               "lightmap (/lightmap, 'prtbake texel'), which is drawn per texel by default.");
  app.add_option("--threads", a.threads, "worker threads (default: all cores).")->check(CLI::Range(1, 4096));
  CLI::Option* rotate_opt = app.add_option("--env-rotate", a.env_rotate,
                 "DEG: turn the environment about +Y by DEG degrees before shading (its SH turned by "
                 "prt::sh::Rotation, (x, z) -> (x cos + z sin, -x sin + z cos), as the web viewer turns it); "
                 "--shade transfer (per vertex or per texel) only, runtime picture only.");
  app.add_flag("-q,--quiet", a.quiet, "only errors.");
  for (CLI::Option* o : app.get_options()) o->description(wrap(o->get_description()));
  if (argc <= 1) throw UsageError("no file given");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    std::fputs(app.help().c_str(), stdout);
    return std::nullopt;
  } catch (const CLI::Success& e) {  // --version
    app.exit(e);
    return std::nullopt;
  } catch (const CLI::ParseError& e) {
    throw UsageError(e.what());
  }
  for (const std::string& s : app.remaining()) {
    if (s.size() > 1 && s[0] == '-') throw UsageError("unknown option '" + s + "'");
    throw UsageError("unexpected argument '" + s + "'");
  }
  if (int(reference) + int(error) + int(triptych) > 1) throw UsageError("--reference, --error and --triptych exclude each other");
  a.mode = reference ? Output::Reference : error ? Output::Error : triptych ? Output::Triptych : Output::Runtime;
  if (!size.empty()) {
    try {
      const auto wh = view::parse_size(size);
      a.width = wh[0];
      a.height = wh[1];
    } catch (const bake::InputError& e) {
      throw UsageError(std::string("--size: ") + e.what());
    }
  }
  if (a.samples < 8 || a.samples > (1u << 24) || a.samples % 8)
    throw UsageError("--samples must be a multiple of 8 in [8, 16777216] (8 independent QMC replicates), got " +
                     std::to_string(a.samples));
  if (exposure_opt->count()) {
    if (!(exposure > 0 && std::isfinite(exposure))) throw UsageError("--exposure must be > 0");
    a.exposure = exposure;
  }
  if (!(a.error_scale > 0 && std::isfinite(a.error_scale))) throw UsageError("--error-scale must be > 0");
  if (!a.reference_cache.empty() && fs::path(a.reference_cache).extension() != ".exr")
    throw UsageError("--reference-cache expects a FILE.exr");
  for (const std::string& t : instances) a.fiv.instances.push_back(parse_instance(t));
  if (!instances_file.empty())
    for (const prtview::FivInstance& i : read_instances(instances_file)) a.fiv.instances.push_back(i);
  if (ground_opt->count()) {
    if (!std::isfinite(ground)) throw UsageError("--ground expects a finite number");
    a.fiv.ground = ground;
  }
  if (ground_size_opt->count()) {
    if (!(ground_size > 0 && std::isfinite(ground_size))) throw UsageError("--ground-size must be > 0");
    a.fiv.ground_size = ground_size;
  }
  if (!a.glossy_route.empty() && a.shade != "glossy") throw UsageError("--glossy-route applies to --shade glossy only");
  if (phong_opt->count()) {
    if (a.shade != "glossy") throw UsageError("--phong applies to --shade glossy only");
    if (!(phong_value > 0 && std::isfinite(phong_value))) throw UsageError("--phong must be a finite number > 0");
    a.phong = phong_value;
  }
  if (rotate_opt->count()) {
    if (!std::isfinite(a.env_rotate)) throw UsageError("--env-rotate expects a finite number of degrees");
    if (a.shade != "transfer")
      throw UsageError("--env-rotate turns the environment of diffuse transfer: it needs --shade transfer (band-1 radiance and "
                       "AO hold the baked sky)");
    if (a.mode != Output::Runtime) throw UsageError("--env-rotate: the reference does not turn the environment yet; write the runtime picture");
  }
  a.fiv.overlap = !no_overlap;
  a.fiv.partial = !no_partial;
  a.fiv.sphere_proxy = proxy == "sphere";
  if (a.file.empty()) throw UsageError("no FILE.prt.h5 given");
  if (a.output.empty()) throw UsageError("no output given (-o IMAGE.png or IMAGE.exr)");
  if (a.output == "-") throw UsageError("-o -: prtview writes image files, not standard output; give -o IMAGE.png or IMAGE.exr");
  const std::string ext = fs::path(a.output).extension().string();
  if (ext != ".png" && ext != ".exr") throw UsageError("-o: '" + a.output + "' must end in .png or .exr");
  return a;
}

struct Timer {
  std::chrono::steady_clock::time_point t0 = std::chrono::steady_clock::now();
  double seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); }
};

void write_image(const std::string& path, const view::Image& linear, const view::Image8& display) {
  if (fs::path(path).extension() == ".exr") view::write_exr(path, linear);
  else view::write_png(path, display);
}

// Interreflections (issue 31): how many bounces the reference traces and, for a single mesh, the
// albedo both pictures carry. A per-vertex transfer or band-1 radiance baked with bounces
// (SCHEMA.md "Bounces") holds the light of a surface of its 'albedo' attribute reflecting onto
// itself: its exit radiance is albedo x sum T_i L_i (bake/bake/bounce.h eq. (1)). So when an
// albedo is known (--albedo, else the product's attribute) the runtime picture is multiplied by it
// and the reference gets it on every triangle (its pixels are albedo x E/pi, E with the bounces);
// the reference's bounces are --bounces, else the product's 'bounces'. Scene files keep their
// objects' albedos; FIV, glossy and area views take no bounces.
struct Interreflection {
  uint32_t bounces = 0;
  std::optional<std::array<double, 3>> albedo;  // RGB
  std::string caption = "ray traced";  // "path traced, 3 bounces, albedo 0.6"
  std::string panel = "ray traced";    // the triptych's caption, short enough for a 256-pixel panel
  std::string why;
};

Interreflection interreflection(const Args& a, const F::Asset& f, const std::string& kind, bool texel, bool area,
                                prtview::RenderScene& scene, view::Image& runtime) {
  Interreflection r;
  const bool single = kind == "transfer" || kind == "band1" || kind == "ao";
  if ((kind == "fiv" || kind == "glossy") && (a.bounces.value_or(0) > 0 || a.albedo))
    throw UsageError("--bounces and --albedo apply to per-vertex, per-texel and scene files, not to " +
                     std::string(kind == "fiv" ? "FIV files" : "glossy lobes"));
  if (area && a.albedo) throw UsageError("--albedo: the objects of a scene file carry their own albedo");
  if (kind == "scene" && a.albedo) throw UsageError("--albedo: the objects of a scene file carry their own albedo");
  // The product drawn: per vertex, or the lightmap's per texel.
  const F::Product* baked = nullptr;
  const std::optional<F::Product>& transfer = texel ? f.vertices.lightmap->transfer_diffuse : f.vertices.transfer_diffuse;
  const std::optional<F::Product>& band1 = texel ? f.vertices.lightmap->radiance_band1 : f.vertices.radiance_band1;
  if (kind == "transfer" && transfer) baked = &*transfer;
  if (kind == "band1" && band1) baked = &*band1;
  int64_t file_bounces = baked && baked->bounces ? *baked->bounces : 0;
  // A scene: the most bounces any object's band-1 radiance or transfer carries (all are bounced
  // together, bake/bake/scene.h rule "bounces").
  // Area views: the most bounces any object's area-light irradiance carries.
  if (kind == "scene" && !area)
    for (const F::SceneObject& o : f.objects)
      for (const std::optional<F::Product>* p :
           {&o.set.transfer_diffuse, &o.set.radiance_band1,
            o.set.lightmap ? &o.set.lightmap->transfer_diffuse : nullptr,
            o.set.lightmap ? &o.set.lightmap->radiance_band1 : nullptr})
        if (p && *p && (*p)->bounces) file_bounces = std::max(file_bounces, *(*p)->bounces);
  if (area)
    for (const F::SceneObject& o : f.objects)
      for (const std::optional<F::Product>* p :
           {&o.set.area_irradiance, o.set.lightmap ? &o.set.lightmap->area_irradiance : nullptr})
        if (p && *p && (*p)->bounces) file_bounces = std::max(file_bounces, *(*p)->bounces);
  std::optional<std::array<double, 3>> file_albedo;
  if (baked && baked->bounces && baked->albedo && baked->albedo->size() == 3)
    file_albedo = {(*baked->albedo)[0], (*baked->albedo)[1], (*baked->albedo)[2]};
  r.bounces = a.bounces ? *a.bounces : uint32_t(std::max<int64_t>(0, file_bounces));
  if (single && a.albedo) r.albedo = {*a.albedo, *a.albedo, *a.albedo};
  else if (single) r.albedo = file_albedo;
  if (single && r.bounces > 0 && !r.albedo)
    throw UsageError("--bounces " + std::to_string(r.bounces) + ": " + a.file +
                     " names no albedo to bounce with (its products carry no bounces): give --albedo A");
  char buf[256];
  const std::string albedo_caption = r.albedo ? bake::albedo_text(*r.albedo) : "";
  const char* albedo = albedo_caption.c_str();
  if (r.albedo) {
    const auto& c = *r.albedo;
    scene.albedo.assign(scene.mesh.triangles.size(), {float(c[0]), float(c[1]), float(c[2])});
    for (size_t i = 0; i < runtime.rgb.size(); ++i) runtime.rgb[i] *= float(c[i % 3]);
    std::snprintf(buf, sizeof buf, "; times the albedo %s (exit radiance albedo x E/pi)", albedo);
    scene.how += buf;
  }
  if (r.bounces > 0 && r.albedo) std::snprintf(buf, sizeof buf, "path traced, %u bounce%s, albedo %s", r.bounces, r.bounces == 1 ? "" : "s", albedo);
  else if (r.bounces > 0) std::snprintf(buf, sizeof buf, "path traced, %u bounce%s, the objects' albedos", r.bounces, r.bounces == 1 ? "" : "s");
  else if (r.albedo) std::snprintf(buf, sizeof buf, "ray traced, direct light only, albedo %s", albedo);
  else std::snprintf(buf, sizeof buf, "ray traced");
  r.caption = buf;
  if (r.bounces > 0 && r.albedo) std::snprintf(buf, sizeof buf, "%u bounce%s, albedo %s", r.bounces, r.bounces == 1 ? "" : "s", albedo);
  else if (r.bounces > 0) std::snprintf(buf, sizeof buf, "%u bounce%s", r.bounces, r.bounces == 1 ? "" : "s");
  else if (r.albedo) std::snprintf(buf, sizeof buf, "direct, albedo %s", albedo);
  else std::snprintf(buf, sizeof buf, "ray traced");
  r.panel = buf;
  if (area && file_bounces > 0)
    std::snprintf(buf, sizeof buf, "the scene's area-light irradiance holds %lld bounce%s%s", static_cast<long long>(file_bounces),
                  file_bounces == 1 ? "" : "s", a.bounces ? "; overridden on the command line" : "; --bounces B to change");
  else if (kind == "scene" && file_bounces > 0)
    std::snprintf(buf, sizeof buf, "the scene's products hold %lld bounce%s%s", static_cast<long long>(file_bounces),
                  file_bounces == 1 ? "" : "s", a.bounces ? "; overridden on the command line" : "; --bounces B to change");
  else if (baked && baked->bounces)
    std::snprintf(buf, sizeof buf, "the file's %s holds %lld bounce%s at albedo %s%s", kind == "transfer" ? "transfer" : "band-1 radiance",
                  static_cast<long long>(file_bounces), file_bounces == 1 ? "" : "s",
                  file_albedo ? bake::albedo_text(*file_albedo).c_str() : "?",
                  a.bounces || a.albedo ? "; overridden on the command line" : "; --bounces B to change");
  else
    std::snprintf(buf, sizeof buf, "--bounces%s", a.albedo ? " and --albedo" : "");
  r.why = buf;
  return r;
}

// The environment reference (view/reference.h), read from or written to --reference-cache.
view::ReferenceImage environment_reference(const Args& a, const prtview::RenderScene& scene, const bake::EnvMap& env,
                                           const view::Camera& cam, uint32_t bounces, bool say, const std::string& cache) {
  view::ReferenceOptions ropt;
  ropt.bounces = bounces;
  ropt.samples = a.samples;
  ropt.seed = a.seed;
  ropt.occluder_spheres = scene.spheres;
  ropt.casts_shadow = scene.casts_shadow;
  ropt.albedo = scene.albedo;
  if (!scene.reflectance.empty() && bounces > 0) {
    // A scene file: each object reflects with its diffuse albedo as the bake's, and where some
    // object's picture carries bounces, only those pixels gather (the others show direct light by
    // design); a direct-only scene with --bounces gathers everywhere, to show what bounces add.
    ropt.reflectance = scene.reflectance;
    if (std::find(scene.gathers.begin(), scene.gathers.end(), uint8_t(1)) != scene.gathers.end()) ropt.gathers = scene.gathers;
  }
  if (!scene.phong.empty()) ropt.glossy = view::ReferenceOptions::Glossy{cam.eye - scene.mesh.origin, scene.phong, scene.specular};
  const view::ReferenceRenderer rr(scene.mesh, env, ropt);
  std::optional<view::ReferenceImage> cached;
  const std::string key = rr.cache_key(cam);
  if (!cache.empty()) cached = view::load_reference(cache, key);
  const tool::ProgressBar bar(a.quiet ? tool::ProgressStyle::Quiet : tool::ProgressStyle::Auto);
  view::ReferenceImage ref = cached ? std::move(*cached) : rr.render(cam, bar.monitor(&tool::interrupt_token()));
  if (say && cached) std::printf("reference: %s: read from %s\n", rr.description().c_str(), cache.c_str());
  if (say && !cached)
    std::printf("reference: %s: %.2f s, %.2f M rays/s\n", rr.description().c_str(), ref.seconds,
                double(ref.rays) / ref.seconds / 1e6);
  if (!cached && !cache.empty()) view::save_reference(cache, ref, key);
  return ref;
}

// The area lights' reference (view/area_lights.h): light sampling over the rasterized pixels.
view::ReferenceImage area_reference(const Args& a, const prtview::RenderScene& scene, const std::vector<bake::AreaLight>& lights,
                                    const view::AreaRenderOptions& options, const view::Camera& cam, uint32_t bounces,
                                    bool say) {
  view::AreaReferenceOptions ro;
  ro.samples = a.samples;
  ro.seed = a.seed;
  ro.render = options;
  ro.bounces = bounces;
  if (bounces > 0 && !scene.reflectance.empty()) {  // as environment_reference: each object as the bake bounced it
    ro.reflectance = scene.reflectance;
    if (std::find(scene.area_gathers.begin(), scene.area_gathers.end(), uint8_t(1)) != scene.area_gathers.end())
      ro.gathers = scene.area_gathers;
  }
  view::ReferenceImage ref;
  ref.gbuffer = view::rasterize(scene.mesh, cam);
  Timer t;
  view::AreaReferenceImage r = view::render_area_reference(scene.mesh, ref.gbuffer, lights, ro);
  ref.seconds = t.seconds();
  ref.radiance = std::move(r.radiance);
  ref.std_error = std::move(r.std_error);
  ref.rays = uint64_t(ref.gbuffer.covered()) * lights.size() * a.samples;
  if (say)
    std::printf("reference: Embree light sampling, %u shadow rays per pixel and light (8 replicates)%s, seed %llu: %.2f s, %.2f M "
                "rays/s\n", a.samples,
                bounces > 0 ? (", " + std::to_string(bounces) + " bounce" + (bounces == 1 ? "" : "s") + " path traced with " +
                               std::to_string(a.samples) + " paths per pixel").c_str()
                            : "",
                (unsigned long long)a.seed, ref.seconds, double(ref.rays) / std::max(ref.seconds, 1e-9) / 1e6);
  return ref;
}

int run(const Args& a) {
  const bool say = !a.quiet;
  const int threads = a.threads > 0 ? a.threads : tbb::info::default_concurrency();
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
  const std::optional<view::Camera> given_camera = [&]() -> std::optional<view::Camera> {
    if (a.camera.empty()) return std::nullopt;  // framed once the file is read
    try {
      return view::parse_camera(a.camera, a.width, a.height);
    } catch (const bake::InputError& e) {  // a command-line value is malformed (exit 2, as --size)
      throw UsageError(std::string("--camera: ") + e.what());
    }
  }();
  {  // fail before the work if the output cannot be written
    const fs::path out(a.output);
    const fs::path dir = out.has_parent_path() ? out.parent_path() : fs::path(".");
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) throw bake::InputError(a.output, "cannot write: directory '" + dir.string() + "' does not exist");
  }
  if (!fs::exists(a.file)) throw bake::InputError(a.file, "no such file");
  const F::Asset f = F::read_asset(a.file);
  for (const F::SkippedAttr& s : f.skipped_attrs)  // another tool's attribute, nothing drawn needs
    std::fprintf(stderr, "prtview: warning: %s: %s\n", a.file.c_str(), F::describe(s).c_str());
  const bool area = a.shade == "area" || a.shade == "area-exact";
  std::string kind = a.shade;
  prtview::FivView fiv = a.fiv;  // plus whether a scene file is drawn as an FIV scene
  std::string skipped;  // why the first look did not take the best product
  if (area) {
    if (!prtview::is_scene_file(f))
      throw UsageError("--shade " + a.shade + ": " + a.file + " is not a scene file; area lights are baked by 'prtbake scene'");
    if (!a.env.empty() || !a.reference_cache.empty())
      throw UsageError("--env and --reference-cache do not apply to --shade " + a.shade + " (the lights' direct light only)");
  } else if (prtview::is_scene_file(f)) {
    // A scene file's objects with FIV shells, placed as dynamic occluders on a ground: --shade fiv,
    // or any --instance.
    fiv.scene = prtview::has_fiv(f) && (a.shade == "fiv" || !a.fiv.instances.empty());
    if ((a.shade == "fiv" || !a.fiv.instances.empty()) && !fiv.scene)
      throw bake::InputError(a.file, "has no FIV shells to draw (--shade fiv, --instance): bake it with the 'fiv' product");
    kind = fiv.scene ? "fiv" : a.shade == "glossy" ? "glossy" : "scene";
    if (fiv.scene && !a.fiv.occluder_mesh.empty())
      throw UsageError("--occluder-mesh does not apply to scene files (" + a.file + "): each occluder's mesh is its object's");
  } else if (a.shade == "glossy") {
    throw UsageError("--shade glossy: " + a.file + " is not a scene file; glossy objects are baked by 'prtbake scene'");
  }
  // Per-vertex files with a lightmap ('prtbake texel') are drawn per texel unless --per-vertex.
  const bool plain = !area && !prtview::is_scene_file(f) && !prtview::has_fiv(f);
  if (a.per_vertex && !plain) throw UsageError("--per-vertex applies to per-vertex and per-texel files, not to " + a.file);
  if (a.per_vertex && prtview::vertex_kinds(f).empty() && prtview::has_lightmap(f))
    throw bake::InputError(a.file, "holds no per-vertex product (AO, diffuse transfer or band-1 radiance): it was baked per texel "
                                   "('prtbake texel': /lightmap/...); drop --per-vertex to draw its lightmap");
  const bool texel = plain && !a.per_vertex && prtview::has_lightmap(f);
  const auto kinds_of = [&] { return texel ? prtview::texel_kinds(f) : prtview::vertex_kinds(f); };
  const auto label_of = [&](const std::string& k) { return texel ? prtview::texel_kind_label(f, k) : prtview::vertex_kind_label(f, k); };
  if (!area && !prtview::is_scene_file(f) && a.shade != "glossy" && kind.empty()) {
    // The first look: the best product the file holds (prtview::vertex_kinds' order), except
    // band-1 radiance under an --env it was not baked with (it belongs to its own environment).
    std::vector<std::string> kinds = kinds_of();
    if (!a.env.empty() && kinds.size() > 1 && kinds.front() == "band1") {
      const std::string baked_sha = texel ? f.vertices.lightmap->radiance_band1->environment_sha256.value_or("")
                                          : prtview::band1_environment_sha256(f);
      if (!baked_sha.empty() && fs::exists(a.env) && baked_sha != bake::sha256_file(a.env)) {
        skipped = "its " + label_of("band1") + " belongs to the environment it was baked with: drop --env to see it";
        kinds.erase(kinds.begin());
      }
    }
    kind = prtview::has_fiv(f) ? "fiv" : kinds.empty() ? "band1" : kinds.front();  // band1: its read names what is missing
  }
  if (kind != "scene" && kind != "glossy" && kind != "fiv" && !area && prtview::has_fiv(f))
    throw UsageError("--shade " + kind + ": " + a.file + " is an FIV file; it is shown with --shade fiv (the default)");
  if (kind == "transfer" || kind == "band1" || kind == "ao") {
    if (texel) prtview::require_texel_kind(f, a.file, kind);
    else prtview::require_vertex_kind(f, a.file, kind);
  }
  const prtview::FirstLook look = given_camera ? prtview::FirstLook{*given_camera, ""}
                                               : prtview::first_look_camera(f, a.file, fiv, a.width, a.height, kind == "glossy");
  const view::Camera& cam = look.camera;
  // AO needs an environment only to weigh it: without one (AO files name none), a white sky.
  const bool white_sky = kind == "ao" && a.env.empty();
  if ((kind == "scene" || kind == "glossy" || area) && ((kind == "scene" && !a.shade.empty()) || !a.fiv.instances.empty() || !a.fiv.occluder_mesh.empty() ||
                                    !a.fiv.occluder.empty() || a.fiv.ground || a.fiv.ground_size || !a.fiv.overlap || !a.fiv.partial || a.fiv.sphere_proxy))
    throw UsageError("--shade (except glossy, area, area-exact, fiv), --occluder(-mesh), --ground(-size), --no-overlap, --proxy sphere and "
                     "--no-partial do not apply to scene files (" + a.file + "): each object is shaded with what it holds (see "
                     "'prtview --help')");
  const std::string env_path = area || white_sky ? std::string() : a.env.empty() ? prtview::baked_environment(f, a.file) : a.env;
  const std::optional<bake::EnvMap> env = area        ? std::nullopt
                                          : white_sky ? std::optional<bake::EnvMap>(bake::EnvMap::constant({1, 1, 1}))
                                                      : std::optional<bake::EnvMap>(bake::EnvMap::load(env_path, prtview::up_axis(f)));
  const std::vector<bake::AreaLight> lights = area ? prtview::read_area_lights(f, a.file) : std::vector<bake::AreaLight>{};

  prtview::RenderScene scene;
  view::AreaRenderOptions area_options;
  if (!a.ggx.empty()) {
    if (a.shade != "area-exact") throw UsageError("--ggx applies to --shade area-exact only");
    view::GgxLayer layer;
    const size_t comma = a.ggx.find(',');
    char* end = nullptr;
    layer.alpha = std::strtod(a.ggx.c_str(), &end);
    const bool alpha_ok = end == a.ggx.c_str() + (comma == std::string::npos ? a.ggx.size() : comma);
    double f0 = 0.04;
    bool f0_ok = true;
    if (comma != std::string::npos) {
      f0 = std::strtod(a.ggx.c_str() + comma + 1, &end);
      f0_ok = comma + 1 < a.ggx.size() && end == a.ggx.c_str() + a.ggx.size();
    }
    if (!alpha_ok || !f0_ok || !(layer.alpha >= 0.01 && layer.alpha <= 1) || !(f0 >= 0 && f0 <= 1))
      throw UsageError("--ggx: expected ALPHA[,F0] with ALPHA in [0.01, 1] and F0 in [0, 1], got '" + a.ggx + "'");
    layer.f0 = {f0, f0, f0};
    layer.eye = cam.eye;  // world space: render_area_file moves it into the mesh's frame
    area_options.ggx = layer;
  }
  Timer t_run;
  view::Image runtime = area ? prtview::render_area_file(f, a.file, lights, a.shade == "area-exact", cam, scene, area_options)
                              : kind == "scene" ? prtview::render_scene_file(f, a.file, *env, cam, scene)
                              : kind == "glossy" ? prtview::render_glossy_scene(f, a.file, *env, cam, a.phong,
                                                                                  a.glossy_route == "a"   ? prtview::GlossyRoute::A
                                                                                  : a.glossy_route == "b" ? prtview::GlossyRoute::B
                                                                                                          : prtview::GlossyRoute::Auto,
                                                                                  scene)
                              : kind == "fiv"   ? prtview::render_fiv_file(f, a.file, fiv, *env, cam, scene)
                              : texel           ? prtview::render_texel_file(f, a.file, kind, *env, cam, scene, a.env_rotate)
                                                : prtview::render_vertex_file(f, a.file, kind, *env, cam, scene, a.env_rotate);
  const double runtime_seconds = t_run.seconds();
  const Interreflection reflect = interreflection(a, f, kind, texel, area, scene, runtime);
  if (!a.quiet && !scene.form.empty()) {  // which form was drawn, on stderr (the summary below says it too)
    if (texel)
      std::fprintf(stderr, "prtview: %s: drawn %s (bilinear through /mesh/uv); %zu of %zu pixels reached an empty texel\n",
                   a.file.c_str(), scene.form.c_str(), scene.empty_texel_pixels, scene.texel_pixels);
    else
      std::fprintf(stderr, "prtview: %s: drawn %s (Gouraud)%s\n", a.file.c_str(), scene.form.c_str(),
                   prtview::has_lightmap(f) ? "; its lightmap is drawn without --per-vertex" : "");
  }
  const std::string env_name = env_path.empty() ? std::string() : fs::path(env_path).filename().string();
  // What the picture shows, for the first line and the first panel's caption.
  std::string shown, caption;
  if (kind == "band1" || kind == "transfer" || kind == "ao") {
    caption = label_of(kind);
    shown = caption + (texel ? ", " + scene.form : std::string()) + (kind == "band1" ? " (exact shadows under " + env_name + ")"
                       : kind == "transfer" ? " under " + env_name
                       : white_sky          ? " under a white sky"
                                            : " x the unshadowed irradiance of " + env_name);
  } else if (kind == "fiv") {
    caption = "FIV shells";
    shown = scene.what;
  } else if (kind == "scene") {
    caption = "per-object products";
    shown = scene.what;
  } else if (kind == "glossy") {
    caption = "glossy lobes";
    shown = scene.what;
  } else {
    caption = a.shade == "area-exact" ? "exact area lights" : "baked area lights";
    shown = scene.what;
  }
  if (say) {
    std::vector<std::string> also;
    if (kind == "band1" || kind == "transfer" || kind == "ao") {
      for (const std::string& k : kinds_of())
        if (k != kind) also.push_back(label_of(k) + " (--shade " + k + ")");
      if (texel && !prtview::vertex_kinds(f).empty()) also.push_back("the per-vertex products (--per-vertex)");
    } else if (kind == "scene" || kind == "glossy" || area) {
      const bool glossy = std::any_of(f.objects.begin(), f.objects.end(), prtview::is_glossy);
      if (kind != "scene") also.push_back("the objects under the environment (no --shade)");
      if (glossy && kind != "glossy") also.push_back("glossy lobes (--shade glossy)");
      if (!f.lights.empty() && !area) also.push_back(std::to_string(f.lights.size()) + " area light(s) (--shade area, area-exact)");
    }
    std::string line = a.file + ": " + (a.shade.empty() && kind != "scene" && kind != "fiv" ? "the best it holds, " : "") + shown;
    if (!skipped.empty()) line += " (" + skipped + ")";
    if (!also.empty()) {
      line += "; also: ";
      for (size_t k = 0; k < also.size(); ++k) line += (k ? ", " : "") + also[k];
    }
    std::printf("%s\n", line.c_str());
    if (kind == "band1" || kind == "transfer" || kind == "ao") std::printf("%s\n", scene.what.c_str());
    if (white_sky) std::printf("environment: a constant white sky (L = 1): the picture is the AO itself (--env ENV.exr to light it)\n");
    else if (env) std::printf("environment: %s (%dx%d %s)\n", env_path.c_str(), env->info().width, env->info().height, env->info().layout.c_str());
    if (given_camera) std::printf("view: %dx%d, %s\n", a.width, a.height, a.camera.c_str());
    else std::printf("view: %dx%d, framing %s; to adjust:\n  --camera %s\n", a.width, a.height, look.framed.c_str(), view::to_string(cam).c_str());
    std::printf("runtime (%.3f s): %s\n", runtime_seconds, scene.how.c_str());
    if (kind == "fiv")
      std::printf("frame: %.4f s wall, %.4f s CPU for %dx%d pixels on %d thread%s (rasterise + shade; reading the file and meshes "
                  "not counted)\n",
                  scene.frame_seconds, scene.frame_cpu_seconds, a.width, a.height, threads, threads == 1 ? "" : "s");
    if (reflect.bounces > 0 || reflect.albedo)
      std::printf("reference: %s (%s)\n", reflect.caption.c_str(), reflect.why.c_str());
    std::fflush(stdout);
  }
  for (float v : runtime.rgb)
    if (!std::isfinite(v)) throw bake::ContractError("the runtime render produced a non-finite value");
  if (say && !scene.object_names.empty()) {  // scene files: what each object shows (mean over its pixels)
    const view::GBuffer g = view::rasterize(scene.mesh, cam);
    for (size_t k = 0; k < std::min(scene.object_names.size(), prtview::kObjectLines); ++k) {
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
    if (scene.object_names.size() > prtview::kObjectLines)
      std::printf("  (the first %zu of %zu objects)\n", prtview::kObjectLines, scene.object_names.size());
  }

  // The exposure: given, or fixed by the environment (or the file's baked area lighting), never
  // by this render's pixels: the same file gives the same exposure alone and in the triptych.
  const bool png = fs::path(a.output).extension() == ".png";
  double exposure = 1;
  std::string exposure_why = "--exposure";
  if (a.exposure) {
    exposure = *a.exposure;
  } else if (png && env) {
    const view::EnvironmentExposure e = view::environment_exposure(*env);
    exposure = e.exposure;
    char buf[160];
    std::snprintf(buf, sizeof buf, "1 / %.4g, E/pi of an unshadowed white surface facing the brightest sky of %s", e.brightest,
                  white_sky ? "the white sky" : env_name.c_str());
    exposure_why = buf;
  } else if (png) {
    std::vector<float> y = scene.baked_luminance;
    if (!y.empty()) {
      const size_t k = std::min(y.size() - 1, size_t(0.99 * double(y.size())));
      std::nth_element(y.begin(), y.begin() + std::ptrdiff_t(k), y.end());
      if (y[k] > 0 && std::isfinite(y[k])) exposure = view::round_significant(1.0 / double(y[k]), 4);
      char buf[160];
      std::snprintf(buf, sizeof buf, "1 / %.4g, the 99th percentile of the baked area lighting E/pi at %zu vertices", double(y[k]), y.size());
      exposure_why = buf;
    } else {
      exposure_why = "no baked area lighting to derive it from: --exposure X to set it";
    }
  }
  const std::string report = prtview::report_summary(f, kind);
  if (say && png) std::printf("exposure %.4g (%s; --exposure X to override)\n", exposure, exposure_why.c_str());

  if (a.mode == Output::Runtime) {
    write_image(a.output, runtime, view::tone_map(runtime, exposure));
    if (say) {
      std::printf("quality: not measured in this picture (--triptych or --error trace the reference); file: %s\n", report.c_str());
      std::printf("wrote %s\n", a.output.c_str());
    }
    return 0;
  }

  const view::ReferenceImage ref = area ? area_reference(a, scene, lights, area_options, cam, reflect.bounces, say)
                                        : environment_reference(a, scene, *env, cam, reflect.bounces, say, a.reference_cache);
  const view::GBuffer raster = view::rasterize(scene.mesh, cam);
  // Compared pixels: both renders see geometry (and, for 'receiver', both see the receiver).
  const std::string region =
      !a.region.empty() ? a.region : kind == "fiv" || kind == "scene" || kind == "glossy" || area ? "receiver" : "all";
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
  if (a.mode == Output::Reference) {
    write_image(a.output, ref.radiance, view::tone_map(ref.radiance, exposure));
    if (say) std::printf("wrote %s\n", a.output.c_str());
    return 0;
  }
  const view::ImageError e = view::compare_images(runtime, ref.radiance, mask, &ref.std_error);
  const view::ImageError all = view::compare_images(runtime, ref.radiance, covered, &ref.std_error);
  // Stable, greppable lines (bench/figures.sh reads "NRMSE").
  std::printf("NRMSE %.5f (%s, %zu pixels; RMSE %.4g, reference range [%.4g, %.4g], max |error| %.4g)\n", e.nrmse,
              region.c_str(), e.pixels, e.rmse, e.ref_min, e.ref_max, e.max_abs);
  std::printf("reference noise %.5f (RMS standard error / range); noise-corrected NRMSE %.5f\n", e.ref_noise,
              e.nrmse_noise_corrected);
  std::printf("relative L2 error %.5f (|runtime - reference| / |reference| over the same pixels and channels); "
              "noise-corrected %.5f\n", e.relative_l2, e.relative_l2_noise_corrected);
  if (region != "all") std::printf("NRMSE over all covered pixels %.5f (%zu pixels)\n", all.nrmse, all.pixels);
  // Scene files: each receiver's share, RMSE over the pixels where both renders see that object,
  // divided by the same range (so NRMSE^2 = sum_k (pixels_k / pixels) NRMSE_k^2).
  const double range = e.ref_max - e.ref_min > 0 ? e.ref_max - e.ref_min : std::abs(e.ref_max) > 0 ? std::abs(e.ref_max) : 1.0;
  size_t object_lines = 0, receivers = 0;
  for (size_t k = 0; k < scene.object_names.size(); ++k) {
    if (!scene.object_receiver[k]) continue;
    ++receivers;
    if (object_lines == prtview::kObjectLines) continue;
    std::vector<uint8_t> mk(n_px, 0);
    const auto in = [&](int32_t t) { return t >= 0 && size_t(t) >= scene.first_triangle[k] && size_t(t) < scene.first_triangle[k + 1]; };
    for (size_t i = 0; i < n_px; ++i) mk[i] = in(raster.triangle[i]) && in(ref.gbuffer.triangle[i]);
    if (std::count(mk.begin(), mk.end(), 1) == 0) continue;
    const view::ImageError ek = view::compare_images(runtime, ref.radiance, mk, &ref.std_error);
    std::printf("  object %s: NRMSE %.5f (%zu pixels; its RMSE %.4g / the range above)\n", scene.object_names[k].c_str(),
                ek.rmse / range, ek.pixels, ek.rmse);
    ++object_lines;
  }
  if (object_lines == prtview::kObjectLines && receivers > object_lines)
    std::printf("  (the first %zu receivers in view of %zu)\n", object_lines, receivers);
  char quality[256];
  std::snprintf(quality, sizeof quality, "RMSE %.4g in this picture (NRMSE %.4g, %zu px, reference noise %.2g%s%s)", e.rmse, e.nrmse,
                e.pixels, e.ref_noise, scene.form.empty() ? "" : "; ", scene.form.c_str());
  if (say) std::printf("quality: %s; file: %s\n", quality, report.c_str());
  view::Image diff(a.width, a.height);
  for (size_t i = 0; i < diff.rgb.size(); ++i) diff.rgb[i] = mask[i / 3] ? runtime.rgb[i] - ref.radiance.rgb[i] : 0.0f;
  const view::Image8 err8 = view::false_colour_error(runtime, ref.radiance, mask, e.ref_max - e.ref_min, a.error_scale);
  // Captions of the 8-bit panels (view/text.h): what each shows, the error's colour scale, and
  // the quality summary under them.
  char error_caption[64], scale_end[64];
  std::snprintf(error_caption, sizeof error_caption, "error x%.3g", 1.0 / a.error_scale);
  std::snprintf(scale_end, sizeof scale_end, "%.3g%% of range", 100 * a.error_scale);
  const view::Panel error_panel{err8, error_caption, std::array<std::string, 2>{"0", scale_end}};
  const std::vector<std::string> footer = {quality, "file: " + report};
  if (a.mode == Output::Error) {
    if (png) view::write_png(a.output, view::labelled_row(std::span(&error_panel, 1), footer));
    else view::write_exr(a.output, diff);
  } else if (!png) {
    const view::Image linear[3] = {runtime, ref.radiance, diff};
    view::write_exr(a.output, view::hstack(linear));
  } else {
    char exposed[48];
    std::snprintf(exposed, sizeof exposed, ", exposure %.4g", exposure);
    std::vector<view::Panel> panels;
    if (reflect.bounces > 0) {
      // Interreflections: the direct light alone (ray traced, no bounces) before the bake with its
      // bounces and the path-traced reference, so the picture shows what the bounces add and how
      // close the bake comes. Cached beside the reference's cache, under its own key.
      const view::ReferenceImage direct =
          area ? area_reference(a, scene, lights, area_options, cam, 0, say)
               : environment_reference(a, scene, *env, cam, 0, say, a.reference_cache.empty() ? "" : a.reference_cache + ".direct");
      const view::ImageError d = view::compare_images(direct.radiance, ref.radiance, mask, &ref.std_error);
      std::printf("direct light alone (no bounces) against the reference: relative L2 %.5f (noise-corrected %.5f): what the "
                  "bounces add\n", d.relative_l2, d.relative_l2_noise_corrected);
      panels.push_back({view::tone_map(direct.radiance, exposure), "direct only (ray traced)", std::nullopt});
    }
    panels.push_back({view::tone_map(runtime, exposure),
                      "baked (" + caption + (scene.form.empty() ? "" : ", " + scene.form.substr(0, scene.form.find(','))) + ")",
                      std::nullopt});
    panels.push_back({view::tone_map(ref.radiance, exposure), "reference (" + reflect.panel + ")", std::nullopt});
    panels.push_back(error_panel);
    std::vector<std::string> lines = footer;
    lines.front() += exposed;
    view::write_png(a.output, view::labelled_row(panels, lines));
  }
  if (say) std::printf("error map full scale %.3g x range; wrote %s\n", a.error_scale, a.output.c_str());
  return 0;
}

int prtview_main(int argc, char** argv) {
  const std::optional<Args> a = parse(argc, argv);
  if (!a) return 0;  // --help or --version
  tool::install_interrupt_handler();
  return run(*a);
}

} // namespace

int main(int argc, char** argv) { return tool::run_tool("prtview", prtview_main, argc, argv); }
