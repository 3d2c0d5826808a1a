// tools/prtbake/args.cpp — prtbake's command line (contract: args.h): the help texts, the
// options of each subcommand, and the checks that need no file.
#include "args.h"

#include <bake/bake/bounce.h>
#include <bake/bake/choose.h>
#include <bake/bake/scene.h>
#include <prtshade/sh.h>

#include "cli.h"
#include "tool_main.h"

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <vector>

namespace prt::tool {
namespace {

constexpr const char* kDescription = "prtbake — bake precomputed radiance transfer (PRT) data for game geometry";

constexpr const char* kVertexHelp =
    "Bakes per-vertex products for every vertex of MESH (OBJ, PLY, OFF, STL, glTF, GLB) in one\n"
    "pass: the rays cast from a vertex serve every product at once. Rows follow the file's vertex\n"
    "order (glTF: the vertices of each primitive instance of the default scene, in node order);\n"
    "a position with several normals in the file (OBJ v//vn hard edges) gives one row per\n"
    "(position, normal) pair, and /mesh/source_position says which file vertex each row is.\n"
    "Give at least one of the products.";

constexpr const char* kTexelHelp =
    "Bakes the per-vertex products per texel of a lightmap: every texel of a W x H atlas that\n"
    "MESH covers through its lightmap UV set (glTF TEXCOORD_1, else its only set; --uv names one)\n"
    "gets a shade point on the surface (the texel centre, or the nearest point of the triangles\n"
    "that touch the texel), baked like a vertex. Texels inside the geometry (under a box standing\n"
    "on the floor) are found exactly and filled from their chart's neighbours, and each chart is\n"
    "padded into its gutter, so bilinear filtering never reads an empty texel. Where the UVs are\n"
    "cut over a continuous surface (a seam), the texels on both sides are moved by least squares\n"
    "until bilinear lookups from either side agree (--no-stitch: not). Written as\n"
    "/lightmap/... images [H][W][...] beside the mesh and its UVs (/mesh/uv), format version 5.\n"
    "A mesh without UVs (a CAD export) gets a generated set, prtbake_lightmap: charts cut at hard\n"
    "edges and where the surface turns more than 65 degrees, each flattened without folds (LSCM),\n"
    "packed at one texel density with --gutter empty texels between charts; one line on stderr\n"
    "gives its charts, utilisation and worst stretch. --unwrap generates it even when the mesh has\n"
    "UVs. A set whose charts overlap (a texture set that mirrors or reuses parts) is an error:\n"
    "pass --unwrap to replace it. The size is --resolution, or --density texels per unit (the\n"
    "atlas then is the smallest square, a multiple of 4, that holds the charts).\n"
    "Give at least one of the products.";

constexpr const char* kFivHelp =
    "Bakes an occluder's Fullsphere Irradiance Vectors (paper 004): the environment's FIV\n"
    "F_env = Int L w dw, the diffuse irradiance cube map (DifMap) E(n) = Int L H (n.w) dw (exact,\n"
    "not SH9), and the occluded FIV F(s) = Int (1 - V(s,w)) L w dw on concentric shells around the\n"
    "occluder's bounding sphere, radii from half the bounding radius outwards, stopping once\n"
    "|F| < --fraction of Int L dw. Always with the silhouette integrator.";

constexpr const char* kSceneHelp =
    "Bakes a scene file (JSON: objects with mesh, transform, material and role receiver /\n"
    "occluder / both; one environment; what may be baked — see data/scene_example.json and the\n"
    "README) and bakes only what the scene needs, printing what it leaves out and why:\n"
    "occluder-only objects get no per-vertex products; a diffuse receiver gets band-1 radiance\n"
    "under the environment (exact) and no higher order, or diffuse transfer at the order the SH\n"
    "tolerance needs when there is no environment (or \"relight\"); a glossy (Phong) receiver gets\n"
    "visibility transfer at the smallest order whose lobe energy beyond it is under the tolerance;\n"
    "no radiance or FIV without an environment; FIV shells only for occluders that can shadow\n"
    "another receiver; vertices that see no contour edge get closed forms. Products, integrator,\n"
    "samples, seed and FIV shells are set in the file's \"bake\" section; \"bounces\": B adds B bounces\n"
    "of light reflected between the objects (\"both\" objects with a diffuse albedo reflect; the\n"
    "plan says who gathers and who reflects). Per-object results go under /objects/<name>/.\n"    "Area lights (\"lights\": [...], baked with exact soft shadows, paper 003; each object gets\n"
    "area_lights/irradiance per light at unit radiance, so a runtime recolours and dims each):\n"
    "  {\"shape\": \"quad\", \"centre\", \"u\", \"v\"}          centre +- u/2 +- v/2, emitting towards u x v\n"
    "  {\"shape\": \"polygon\", \"vertices\": [[x,y,z], ...]}   convex, counter-clockwise from its front\n"
    "  {\"shape\": \"disc\", \"centre\", \"normal\", \"radius\", \"segments\": 64}\n"
    "  {\"shape\": \"box\", \"centre\", \"size\": [sx,sy,sz], \"rotate\": [rx,ry,rz]}\n"
    "  {\"shape\": \"cylinder\", \"centre\", \"radius\", \"height\", \"segments\", \"rotate\"}\n"
    "  {\"shape\": \"sphere\", \"centre\", \"radius\", \"subdivisions\": 3}\n"
    "  each with \"radiance\": [r,g,b] (required), \"name\", and \"two_sided\" (planar shapes).\n"
    "Punctual lights (glTF KHR_lights_punctual's kinds; exact hard shadows, one shadow ray per\n"
    "receiver; E per light at unit intensity in the same area_lights/irradiance, after the area\n"
    "lights' columns):\n"
    "  {\"shape\": \"point\", \"position\"}                  E = cos / d^2; with \"radius\": a sphere light\n"
    "                                                 (radiance I/(pi r^2), \"subdivisions\": 3), soft shadows\n"
    "  {\"shape\": \"spot\", \"position\", \"direction\", \"inner_cone_angle\": 0, \"outer_cone_angle\": 45}\n"
    "                                                 degrees; KHR_lights_punctual's smooth cone falloff\n"
    "  {\"shape\": \"directional\", \"direction\"}           where the light travels; with \"angle\" (degrees,\n"
    "                                                 e.g. 0.53): a sun disc, soft shadows (\"segments\": 64)\n"
    "  each with \"intensity\": [r,g,b] (required, >= 0: candela, or lux for directional) and \"name\";\n"
    "  point and spot lights take \"range\" (> 0): KHR_lights_punctual's cut-off, E times the\n"
    "  extension's window clamp(1 - (d/range)^4, 0, 1), 0 from the range on (a glTF light's own is applied).\n"
    "  A glTF scene's own KHR_lights_punctual lights are baked too (the options' \"gltf_lights\":\n"
    "  {\"<light name>\": {\"radius\": r} | {\"angle\": a} | {\"skip\": true}} gives them an extent).\n"
    "A glTF (.gltf, .glb) is a scene too: each primitive instance of its default scene is an\n"
    "object named by its node path (\"root/engine/piston_2\", \"#p1\" for a mesh's 2nd primitive;\n"
    "stored as /objects/root|engine|piston_2 with the path in node_path), role \"both\", albedo\n"
    "the material's baseColorFactor (0.8 grey without one). --options sets the rest.";

// One line per command: the top-level --help and the message for an unknown command.
const std::vector<tool::Command> kCommands = {
    {"vertex", "per-vertex products of a mesh: AO, SH transfer, visibility, band-1 and shadowed radiance"},
    {"texel", "the same products per texel of a lightmap, through the mesh's lightmap UVs"},
    {"fiv", "an occluder's Fullsphere Irradiance Vectors on shells around it, and the DifMap"},
    {"scene", "a scene file or glTF: bakes what each object needs and says what it leaves out, and why"},
    {"export", "a baked file as glTF, plain binary, or Unity / Godot / Filament light probes"},
};

// Each command's EXAMPLES (its --help shows its own); the top-level --help shows one per command.
constexpr const char* kVertexExamples =
    "EXAMPLES\n"
    "  prtbake vertex data/bunny_ground.obj --ao --transfer 3 --radiance data/sunset.exr -o bunny.prt.h5\n"
    "  prtbake vertex asset.obj --visibility 6 --samples 4096 --threads 8 -o asset.prt.h5\n"
    "  prtbake vertex data/bunny_ground.obj --transfer 3 --bounces 3 --albedo 0.6 -o bunny.prt.h5   # interreflections\n"
    "  mpirun -n 8 prtbake vertex big.obj --ao --samples 4096 -o big.prt.h5   # 8 workers, rank 0 merges\n"
    "  prtbake vertex big.obj --ao --samples 4096 --shard auto -o big.prt.h5  # a SLURM array task; then --merge\n"
    "  prtdump bunny.prt.h5            # what was baked, statistics, the error report\n\n";
constexpr const char* kFivExamples =
    "EXAMPLES\n"
    "  prtbake fiv data/bunny.obj --env data/forest.exr --shells 64x33x30 -o bunny.fiv.prt.h5\n"
    "  mpirun -n 4 prtbake fiv data/bunny.obj --env data/forest.exr -o bunny.fiv.prt.h5   # shells in slabs of samples\n"
    "  prtdump bunny.fiv.prt.h5        # the shells, the DifMap, the error report\n\n";
constexpr const char* kSceneExamples =
    "EXAMPLES\n"
    "  prtbake scene data/scene_example.json --dry-run      # the plan: what each object gets, and why\n"
    "  prtbake scene data/scene_example.json -o scene.prt.h5\n"
    "  prtbake scene engine.glb --options engine.options.json -o engine.prt.h5\n"
    "  prtdump scene.prt.h5 --vertex 0 --object bunny\n\n";
constexpr const char* kTopExamples =
    "EXAMPLES\n"
    "  prtbake vertex data/bunny_ground.obj --ao --transfer 3 --radiance data/sunset.exr -o bunny.prt.h5\n"
    "  prtbake fiv data/bunny.obj --env data/forest.exr -o bunny.fiv.prt.h5\n"
    "  prtbake scene data/scene_example.json -o scene.prt.h5\n"
    "  prtbake export bunny.prt.h5 --to glb -o bunny.glb\n"
    "  prtdump bunny.prt.h5            # what was baked, statistics, the error report\n\n";

// The command line as stored in the file: the arguments that determine its contents, as typed
// (without --threads, --quiet, --verbose, --dry-run, --reproducible and the sharding options);
// "--opt=value" is stored as "--opt value".
std::string content_command_line(int argc, char** argv) {
  std::string line = "prtbake";
  for (int i = 1; i < argc; ++i) {
    std::string s = argv[i], value;
    const size_t eq = s.rfind("--", 0) == 0 ? s.find('=') : std::string::npos;
    if (eq != std::string::npos) value = s.substr(eq + 1), s.resize(eq);
    bool takes_value = false;
    if (s == "--threads" || tool::is_shard_option(s, takes_value)) {
      if ((s == "--threads" || takes_value) && eq == std::string::npos) ++i;
      continue;
    }
    if (s == "--quiet" || s == "-q" || s == "--verbose" || s == "-v" || s == "--dry-run" || s == "--reproducible")
      continue;
    line += " " + s;
    if (eq != std::string::npos) line += " " + value;
  }
  return line;
}

// Why `path` cannot be the output file ("" if it can): prtbake writes HDF5 files only.
std::string output_problem(const std::string& path) {
  if (path == "-")
    return "cannot write to standard output: an HDF5 file needs a seekable file; give a name ending in .prt.h5";
  if (!path.ends_with(".h5"))
    return "'" + path + "' does not end in .h5: prtbake writes HDF5 files only (.prt.h5 or .h5 expected)";
  return "";
}

// ---- the options, each defined once and added to the subcommands it applies to ----

void add_output(CLI::App& cmd, Args& a) {
  cmd.add_option("-o,--output", a.output,
                 "the .prt.h5 file to write (HDF5; see formats/SCHEMA.md). Written to a\n"
                 "temporary file first and renamed, so FILE is never half-written.")
      ->option_text("FILE")
      ->check(output_problem);
}

void add_report(CLI::App& cmd, Args& a, const std::string& reference) {
  cmd.add_option("--report", a.integrator.report_points,
                 "after the bake, re-integrate N seeded points with a converged QMC\nreference (" + reference +
                     ")\nand print/store the error (RMSE, max) next to the run time (default " +
                     std::to_string(bake::IntegratorSpec{}.report_points) +
                     ";\n0 turns it off). Stored under /report in the file.")
      ->option_text("N")
      ->check(tool::integer_in(0, 1 << 20));
}

// --threads, --reproducible and --quiet. `target_help`: what --reproducible does to the command's
// target-error choice ("" for a command without one: fiv).
void add_run_options(CLI::App& cmd, Args& a, const std::string& target_help) {
  cmd.add_option("--threads", a.threads, "worker threads (default: all cores).")
      ->option_text("T")
      ->check(tool::integer_in(1, 4096));
  cmd.add_flag("--reproducible", a.reproducible,
               "make the file a pure function of the inputs: 'created' is pinned to\n"
               "SOURCE_DATE_EPOCH (or 0) and measured wall times are printed but not\n"
               "stored. Implied when SOURCE_DATE_EPOCH is set (reproducible-builds.org)." +
                   (target_help.empty() ? std::string("\nThe baked values are identical with or without it.")
                                        : "\n" + target_help));
  cmd.add_flag("-q,--quiet", a.quiet, "print nothing but warnings (about the input) and errors.");
}

// --samples, --seed and --up: what samples the sphere around a shade point.
void add_sampling(CLI::App& cmd, Args& a, uint32_t& samples, const std::string& samples_help) {
  cmd.add_option("--samples", samples, samples_help)->option_text("N")->check(tool::integer_in(1, 1 << 24));
  cmd.add_option("--seed", a.integrator.seed,
                 "randomisation seed (default " + std::to_string(bake::IntegratorSpec{}.seed) +
                     "). Same inputs and seed give identical\nbytes whatever --threads is.")
      ->option_text("S")
      ->check(tool::integer_in(0, std::numeric_limits<int64_t>::max()));
  cmd.add_option_function<std::string>(
         "--up",
         [&a](const std::string& u) {
           if (u == "y" || u == "Y") a.up = bake::UpAxis::Y;
           else if (u == "z" || u == "Z") a.up = bake::UpAxis::Z;
           else throw CLI::ValidationError("--up", "expects y or z, got '" + u + "'");
         },
         "the scene's up axis (default y). With z (Blender), scene direction\n"
         "(x,y,z) is looked up in the environment as (x,z,-y).")
      ->option_text("y|z");
}

// The fiv command's k has a default; a vertex bake without --samples has its k chosen by the
// target error instead.
std::string silhouette_k_help(bool with_default) {
  const bake::IntegratorSpec d;
  return "k = N, the number of spherical samples\n(sqrt(k) u-isolines, rounded to even" +
         (with_default ? "; default " + std::to_string(d.silhouette_k) + " = " + std::to_string(d.isolines()) + "^2" : "");
}

// --bounces, --albedo and --bounce-rays (vertex, texel): interreflected diffuse transfer
// (bake/bake/bounce.h). `noun`: the receivers ("vertex", "texel").
void add_bounces(CLI::App& cmd, Args& a, const std::string& noun) {
  const std::string group = "Interreflections";
  cmd.add_option("--bounces", a.bounces,
                 "add B bounces of diffuse interreflection to the transfer (--transfer) and\n"
                 "the band-1 radiance (--radiance): light from the environment reflected\n"
                 "between the mesh's own surfaces, Lambertian, of albedo --albedo (needed);\n"
                 "back faces are black. Stops early once a bounce adds < 1e-4 of the direct\n"
                 "pass's RMS. transfer/diffuse and radiance/band1 then hold direct + bounces\n"
                 "(attrs bounces, bounces_requested, albedo, bounce_rays); shading is\n"
                 "unchanged; --shadowed's S bounces too. AO and --visibility stay direct.")
      ->option_text("B")
      ->check(tool::integer_in(0, 100))
      ->group(group);
  cmd.add_option_function<std::string>(
         "--albedo",
         [&a](const std::string& text) {
           std::vector<double> rgb;
           size_t start = 0;
           for (;;) {
             const size_t comma = text.find(',', start);
             const std::string part = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
             char* end = nullptr;
             const double x = std::strtod(part.c_str(), &end);
             if (part.empty() || end != part.c_str() + part.size() || !std::isfinite(x))
               throw CLI::ValidationError("--albedo", "expects R or R,G,B (numbers in [0, 1)), got '" + text + "'");
             if (x < 0)
               throw CLI::ValidationError("--albedo", "'" + text + "': an albedo is a reflectance in [0, 1), " +
                                                          part + " is negative");
             if (x >= 1)
               throw CLI::ValidationError("--albedo", "'" + text + "': an albedo must be below 1 (at " + part +
                                                          " light bounced inside an enclosure never dies out: the "
                                                          "bounces would not converge)");
             rgb.push_back(x);
             if (comma == std::string::npos) break;
             start = comma + 1;
           }
           if (rgb.size() == 1) rgb.assign(3, rgb[0]);
           if (rgb.size() != 3)
             throw CLI::ValidationError("--albedo", "expects R or R,G,B (numbers in [0, 1)), got '" + text + "'");
           a.albedo = rgb;
         },
         "the surfaces' diffuse albedo for --bounces: R or R,G,B, each in [0, 1);\n"
         "the band-1 radiance bounces per channel, the transfer (--transfer) only\n"
         "with a grey one (R = G = B: it is one vector for all channels)")
      ->option_text("R[,G,B]")
      ->group(group);
  cmd.add_option("--bounce-rays", a.bounce_rays,
                 "gather rays per " + noun + " for --bounces, cast once; every bounce reuses\n"
                 "their hits (default " + std::to_string(bake::BounceSpec::kDefaultRays) + ")")
      ->option_text("K")
      ->check(tool::integer_in(1, 1 << 16))
      ->group(group);
}

// `name`: "vertex", or "texel" (the same products per texel of a lightmap).
void add_vertex(CLI::App& app, Args& a, uint32_t& samples, const std::string& command = "vertex") {
  const bool texel = command == "texel";
  CLI::App& cmd = *app.add_subcommand(command, texel ? kTexelHelp : kVertexHelp);
  cmd.add_option("MESH", a.input, "the mesh (OBJ, PLY, OFF, STL, glTF, GLB; a glTF's primitive\ninstances are concatenated in node order)")->required()->type_name("");
  if (texel) {
    cmd.add_option_function<std::string>(
           "--resolution",
           [&a](const std::string& text) {
             unsigned w = 0, h = 0;
             char x = 0, rest = 0;
             const int n = std::sscanf(text.c_str(), "%u%c%u%c", &w, &x, &h, &rest);
             if (n == 1) h = w;
             else if (n != 3 || x != 'x') throw CLI::ValidationError("--resolution", "expects N or WxH, got '" + text + "'");
             if (w < 1 || h < 1 || w > 8192 || h > 8192)
               throw CLI::ValidationError("--resolution", "each side must be 1 to 8192 texels, got '" + text + "'");
             a.lightmap_width = w;
             a.lightmap_height = h;
           },
           "the lightmap's texels: N (N x N) or WxH, each 1 to 8192 (or --density)")
        ->option_text("N|WxH");
    cmd.add_option("--density", a.lightmap_density,
                   "texels per unit of the mesh's length (instead of --resolution): generated\n"
                   "UVs are packed at this density into the smallest square atlas that holds\n"
                   "them; an asset's own set gets the square whose texels have this density\n"
                   "on average. At most 8192 x 8192 texels.")
        ->option_text("T")
        ->check(tool::number_in(1e-9, 1e9))
        ->excludes("--resolution");
    cmd.add_option("--uv", a.uv_set,
                   "the UV set to bake in, by its name in the asset (TEXCOORD_1, vt);\n"
                   "default: TEXCOORD_1 when the mesh has it, else its only set")
        ->option_text("NAME");
    cmd.add_flag("--unwrap", a.unwrap,
                 "generate the lightmap UVs (set prtbake_lightmap) even when the mesh\n"
                 "has UVs; they are generated anyway when it has none")
        ->excludes("--uv");
    cmd.add_option("--gutter", a.gutter, "empty texels between two charts of generated UVs (default 2)")
        ->option_text("G")
        ->check(tool::integer_in(0, 64));
    cmd.add_option("--min-chart-texels", a.min_chart_texels,
                   "generated UVs: a chart narrower than M texels across (a fin's rim, a thin\n"
                   "ring) gets a density of its own, enough for M texels, at most 4x the atlas's\n"
                   "(default " + std::to_string(bake::LightmapSpec{}.min_chart_texels) + "; 0: one density for every chart)")
        ->option_text("M")
        ->check(tool::integer_in(0, 64));
    cmd.add_option("--padding", a.padding,
                   "rings each chart is dilated into, in texels (default " + std::to_string(bake::kDefaultPadding) +
                       ": bilinear lookups\nat mip levels 0-" + std::to_string(bake::kMipLevels) +
                       " then reach no empty texel wherever the atlas has room)")
        ->option_text("P")
        ->check(tool::integer_in(0, 64));
    cmd.add_flag("--no-stitch", a.no_stitch,
                 "leave the texels along UV seams as baked (by default they are moved by least\n"
                 "squares so that both sides of a seam agree where the surface is continuous)");
  }
  add_output(cmd, a);
  const std::string products = "Products (at least one)";
  cmd.add_flag("--ao", a.ao, "ambient occlusion  A = 1/pi * Int V H (n.w) dw, in [0,1]")->group(products);
  cmd.add_option("--transfer", a.transfer,
                 "diffuse transfer vectors T_i = 1/pi * Int V H (n.w) y_i dw, SH order L\n"
                 "(L bands, L*L coefficients; shade with albedo * sum_i T_i L_i)")
      ->option_text("L")
      ->check(tool::integer_in(1, sh::kMaxOrder))
      ->group(products);
  cmd.add_option("--visibility", a.visibility,
                 "visibility transfer vectors U_i = Int V H y_i dw, SH order L (glossy,\ntriple products)")
      ->option_text("L")
      ->check(tool::integer_in(1, sh::kMaxOrder))
      ->group(products);
  cmd.add_option("--radiance,--env", a.environment,
                 "band-1 shadowed radiance R_c,m = Int L_c V H y_1m dw from the HDR\n"
                 "environment ENV (OpenEXR lat-long or cube map): exact all-frequency\n"
                 "diffuse shadows with 3 coefficients per channel. Irradiance at the\n"
                 "baked normal n: E = 4pi/3 * sum_m y_1m(n) R_m. --env is the same\n"
                 "option (the name fiv, export and prtview give the environment).")
      ->option_text("ENV")
      ->group(products);
  cmd.add_option("--shadowed", a.shadowed,
                 "shadowed radiance S_c,i = Int L_c V H y_i dw at SH order L under the\n"
                 "--radiance (--env) environment (paper 001 sec. 4, material editing: glossy\n"
                 "lobes chosen at run time; band 1 of S is R)")
      ->option_text("L")
      ->check(tool::integer_in(1, sh::kMaxOrder))
      ->group(products);
  cmd.add_option_function<std::string>(
         "--integrator",
         [&a](const std::string& name) {
           const auto kind = bake::parse_integrator_kind(name);
           if (!kind) {
             const auto near = tool::closest(name, {"silhouette", "qmc", "filter"});
             throw CLI::ValidationError("--integrator", "unknown integrator '" + name + "'" +
                                                            (near ? "; did you mean " + *near + "?" : std::string()) +
                                                            " (available: silhouette, qmc, filter)");
           }
           a.integrator.kind = *kind;
         },
         "silhouette (the default with --samples): semi-analytic visibility\n"
         "silhouettes (paper 001 §3): contour edges, depth complexity along\n"
         "octahedral u-isolines, summed-area tables. Deterministic; error\n"
         "falls with k, no noise.\n"
         "qmc: Embree ray casting, importance-sampled randomised Halton QMC, the\n"
         "baseline and the reference.\n"
         "filter: a few rays per vertex reused by its neighbours through the\n"
         "sheared filter (paper 002); --samples is its pass-1 rays (4-32).")
      ->option_text("NAME");
  cmd.add_option("--target-error", a.target_error,
                 "the default (E = 1e-3) unless --samples is given: the integrator\n"
                 "and its samples chosen for you, the cheapest bake whose RMSE is\n"
                 "at most E per product (AO, transfer: absolute; band-1\n"
                 "radiance: relative to its RMS), from a pilot on 32-128 seeded vertices\n"
                 "(both integrators timed, or their work counted with --reproducible,\n"
                 "and their errors measured against a 256- or 512-isoline silhouette\n"
                 "reference). E in [1e-4, 0.1].\n"
                 "With --integrator, only its samples are chosen; not with --samples.\n"
                 "The choice is printed in one line (with -v, the pilot's table);\n"
                 "the error report (on 128 vertices when --target-error is given,\n"
                 "unless --report says otherwise) then checks E. Which integrator\n"
                 "wins is measured speed: pin the printed choice with --integrator\n"
                 "and --samples, or use --reproducible, for the same bytes anywhere.")
      ->option_text("E")
      ->check(tool::number_in(bake::ChooserOptions::kMinTarget, bake::ChooserOptions::kMaxTarget));
  add_bounces(cmd, a, texel ? "texel" : "vertex");
  const bake::IntegratorSpec d;
  add_sampling(cmd, a, samples,
               "silhouette: " + silhouette_k_help(false) +
                   ";\n64^2 to 256^2 converge for HDR environments). qmc: rays per vertex;\n"
                   "the error falls like 1/sqrt(N) or faster. Without it, --target-error\n"
                   "chooses N (and the integrator, unless --integrator names one).");
  cmd.add_flag_callback("--no-file-normals", [&a] { a.file_normals = false; },
                        "ignore normals in the mesh file; use angle-weighted vertex normals.");
  cmd.add_flag("--flip-normals", a.flip_normals,
               "reverse every triangle's winding and negate the file's normals (so\n"
               "file and angle-weighted normals both point the other way): for a\n"
               "mesh wound inwards, whose vertices would otherwise see no sky.\n"
               "/mesh/normals' source then ends in ', flipped'.");
  add_report(cmd, a,
             std::to_string(bake::IntegratorSpec::kQmcReferenceFactor) + "x the bake's rays for qmc, " +
                 std::to_string(bake::IntegratorSpec::kSilhouetteReferenceRays) + " rays for silhouette");
  add_run_options(cmd, a,
                  "With a target error (the default), the integrator is chosen by the\n"
                  "pilot's counted work instead of its measured time, so the choice,\n"
                  "and the bytes, are the same on any machine. With --samples the\n"
                  "baked values are identical with or without it.");
  cmd.add_flag("-v,--verbose", a.verbose,
               "with a target error: print the pilot's table (each run's error and\n"
               "cost, each integrator's model) instead of one line.")
      ->excludes("--quiet");
  tool::add_shard_options(cmd, a.shard, texel ? "texels" : "vertices");
  cmd.footer(texel ? std::string("Examples:\n  prtbake texel scene.glb --resolution 512 --ao -o scene.prt.h5\n"
                                 "  prtbake texel 2CylinderEngine.glb --density 0.5 --ao -o engine.prt.h5   (generated UVs)\n"
                                 "  prtbake texel asset.obj --unwrap --resolution 1024 --ao -o asset.prt.h5\n\n") +
                         tool::kExitStatusHelp
                   : std::string(kVertexExamples) + tool::kExitStatusHelp);
}

void add_fiv(CLI::App& app, Args& a, uint32_t& samples) {
  CLI::App& cmd = *app.add_subcommand("fiv", kFivHelp);
  cmd.add_option("OCCLUDER", a.input, "the occluder's mesh (OBJ, PLY, OFF, STL, glTF, GLB)")->required()->type_name("");
  add_output(cmd, a);
  cmd.add_option("--env", a.environment, "the HDR environment (OpenEXR lat-long or cube map)")
      ->option_text("ENV")
      ->required();
  const bake::ShellSpec d;
  cmd.add_option_function<std::string>(
         "--shells",
         [&a](const std::string& g) {
           if (!bake::parse_shell_grid(g, a.shell_spec))
             throw CLI::ValidationError("--shells",
                                        "expects NPHIxNTHETAxNRHO, e.g. 128x65x30 (NTHETA >= 2), got '" + g + "'");
         },
         "the shell grid: NPHI x NTHETA (poles included) directions on each of\nNRHO shells (default " +
             std::to_string(d.n_phi) + "x" + std::to_string(d.n_theta) + "x" + std::to_string(d.n_rho) + ")")
      ->option_text("NPHIxNTHETAxNRHO");
  cmd.add_option_function<std::string>(
         "--radial",
         [&a](const std::string& r) {
           if (!bake::parse_radial_scheme(r, a.shell_spec.radial))
             throw CLI::ValidationError("--radial", "expects surface or geometric, got '" + r + "'");
         },
         "where the NRHO shells lie along each direction: surface (default) = at\n"
         "offsets from the occluder's outer surface along the ray, graded from\n"
         "0.005 R; geometric = spheres around the centre from 0.5 R (paper 004)")
      ->option_text("surface|geometric");
  cmd.add_option_function<std::string>(
         "--precision",
         [&a](const std::string& r) {
           if (!bake::parse_shell_precision(r, a.shell_spec.float16))
             throw CLI::ValidationError("--precision", "expects half or float, got '" + r + "'");
         },
         "how the file stores the shells and cones: half (default) = float16,\n"
         "half the memory at no measurable error (a value moves by at most\n"
         "2^-11 of itself; format_version 8); float = float32")
      ->option_text("half|float");
  cmd.add_option_function<std::string>(
         "--self-shadows",
         [&a](const std::string& r) {
           if (!bake::parse_self_shadows(r, a.shell_spec.vertex_self_shadows))
             throw CLI::ValidationError("--self-shadows", "expects vertex or shells, got '" + r + "'");
         },
         "the occluder's own shadows: vertex (default) = its band-1 radiance at\n"
         "its vertices (exact there; /mesh and /radiance/band1 in the file), which\n"
         "prtview and shade_fiv_member_given_self use; shells = nothing more: the\n"
         "runtime's eq. 12 from the shells, wrong where the surface is not the\n"
         "outermost along its ray from the centre (ears, concavities). A sharded\n"
         "bake bakes them in the process that writes the file")
      ->option_text("vertex|shells");
  cmd.add_option("--first-offset", a.shell_spec.first_offset,
                 "the surface scheme's first offset from the surface, as a fraction of\n"
                 "the bounding radius R (default 0.005; strictly between 0 and 1)")
      ->option_text("FRACTION")
      ->check(tool::number_between(0, 1));
  cmd.add_option("--cube", a.shell_spec.cube, "the DifMap's face size S (default " + std::to_string(d.cube) + ")")
      ->option_text("S")
      ->check(tool::integer_in(1, 1024));
  cmd.add_option("--fraction", a.shell_spec.fraction,
                 "stop adding shells once |F| < FRACTION of Int L dw (default 1e-3;\n"
                 "strictly between 0 and 1)")
      ->option_text("FRACTION")
      ->check(tool::number_between(0, 1));
  add_sampling(cmd, a, samples, "the silhouette integrator's " + silhouette_k_help(true) + ").");
  add_report(cmd, a,
             std::to_string(bake::IntegratorSpec::kSilhouetteReferenceRays) +
                 " rays, full sphere, at seeded shell samples");
  add_run_options(cmd, a, "");
  tool::add_shard_options(cmd, a.shard, "DifMap texels, or a FIV shell's samples");
  cmd.footer(std::string(kFivExamples) + tool::kExitStatusHelp);
}

void add_scene(CLI::App& app, Args& a) {
  CLI::App& cmd = *app.add_subcommand("scene", kSceneHelp);
  cmd.add_option("SCENE", a.input, "the scene file (JSON), or a glTF (.gltf, .glb)")->required()->type_name("");
  add_output(cmd, a);
  cmd.add_option("--options", a.scene_options,
                 "glTF scenes only: a JSON file {\"prtbake_gltf_scene\": 1, \"up\", \"environment\",\n"
                 "\"bake\" (as in a scene file), \"objects\": {\"<node path>\": {\"role\": ...,\n"
                 "\"material\": {...}}}}; a node path covers the nodes below it, the longest\n"
                 "match wins, a path that names no node is an error (README \"Scene files\").")
      ->option_text("FILE");
  cmd.add_flag("--dry-run", a.dry_run, "print the plan and stop (no output file needed).");
  add_report(cmd, a, "overrides the scene file's bake.report");
  add_run_options(cmd, a,
                  "With a target error (the scene's bake.target_error; the default\n"
                  "without bake.samples), each receiver's integrator is chosen by\n"
                  "the pilot's counted work instead of its measured time, so the\n"
                  "choice, and the bytes, are the same on any machine. With\n"
                  "bake.samples the baked values are identical with or without it.");
  cmd.add_flag("-v,--verbose", a.verbose,
               "with a target error: print each receiver's pilot table (each run's\n"
               "error and cost, each integrator's model) instead of one line, and the\n"
               "error report's reference plan.")
      ->excludes("--quiet");
  tool::add_shard_options(cmd, a.shard, "receiver vertices");
  cmd.footer(std::string(kSceneExamples) + tool::kExitStatusHelp);
}

// The top-level --help: the commands, one line each, and where each one's options are.
std::string overview() {
  std::string s = std::string(kDescription) + "\n\nUsage: prtbake COMMAND [OPTIONS] INPUT ...\n\nCommands:\n";
  for (const tool::Command& c : kCommands) {
    char line[160];
    std::snprintf(line, sizeof line, "  %-8s %s\n", c.name, c.summary);
    s += line;
  }
  s += "\n'prtbake COMMAND --help' lists a command's options, says what it computes and gives\n"
       "examples. Options go after the command, in any order; --opt value or --opt=value.\n\n"
       "Options:\n"
       "  -h,--help  this list\n"
       "  --version  the version (prtbake " + std::string(kToolkitVersion) + ")\n\n";
  return s + kTopExamples + tool::kExitStatusHelp;
}

// Every check of the command line that needs no file, after CLI11 has parsed it: a mistake is
// exit 2 before any input is read (tool_main.h). `app`: the parsed command line.
void validate(Args& a, const CLI::App& app, uint32_t samples, const tool::MpiSession& mpi) {
  const CLI::App& cmd = *app.get_subcommands().front();
  const std::string help = "prtbake " + a.command;
  const auto fail = [&](const std::string& what) { throw UsageError(a.command + ": " + what, help); };
  if (a.command == "export") {
    if (mpi.active()) fail("run it as one process, not under mpirun");
    tool::check_export_args(a.exported);
    return;
  }
  if (a.output.empty() && !(a.command == "scene" && a.dry_run)) fail("no output file given (-o OUT.prt.h5)");
  // Who this process is among a sharded bake's workers (the options and the launcher's
  // environment), before the inputs are read.
  if (a.shard.given() || mpi.active()) {
    try {
      a.worker = tool::resolve_worker(a.shard, mpi);
    } catch (const UsageError& e) {
      fail(e.what());
    }
  }
  if (a.command == "scene") {
    a.report_given = cmd.count("--report") > 0;
    if (!a.scene_options.empty() && !bake::is_gltf_scene(a.input))
      fail("--options " + a.scene_options + " applies to a glTF scene (.gltf, .glb) only; " + a.input +
           " is a JSON scene file, whose own \"bake\" section holds the options");
    return;
  }
  if (a.command == "texel" && a.lightmap_width == 0 && a.lightmap_density == 0)
    fail("the lightmap's size is missing: give --resolution N|WxH (texels) or --density T (texels per unit)");
  if (a.command == "vertex" || a.command == "texel") {
    a.integrator_given = cmd.count("--integrator") > 0;
    const bool target_given = a.target_error > 0;
    if (target_given && samples != 0)
      fail("--target-error and --samples both given: the target chooses the samples (give one)");
    if (a.integrator.kind == bake::IntegratorKind::Filter && samples == 0)
      fail(std::string("--integrator filter needs --samples N, its pass-1 rays per vertex (4-32): the target-error "
                       "chooser has no model of the filter integrator") +
           (target_given ? ", so it cannot take --target-error" : ""));
    // Neither samples nor a target: the default target, checked exactly as the same target named.
    if (!target_given && samples == 0) a.target_error = bake::ChooserOptions{}.target;
    // Checking a target needs more vertices than the default report's 32 (RMSE over a sample);
    // the check's reference takes about as long as the bake (plan_report_reference's CPU bound).
    if (a.target_error > 0 && cmd.count("--report") == 0) a.integrator.report_points = bake::ChooserOptions::kReportPoints;
    if (!a.ao && !a.transfer && !a.visibility && a.environment.empty())
      fail("nothing to bake: give at least one of --ao, --transfer L, --visibility L, --radiance ENV (or --env ENV)");
    if (a.shadowed && a.environment.empty())
      fail("--shadowed L needs --radiance ENV (or --env ENV): the environment it is baked under");
    if (a.bounces > 0) {
      const std::string b = "--bounces " + std::to_string(a.bounces);
      if (a.albedo.empty())
        fail(b + " needs --albedo R[,G,B]: the surfaces' albedo (a single mesh file gives no material)");
      if (!a.transfer && a.environment.empty())
        fail(b + " bounces the diffuse transfer and the band-1 radiance: give --transfer L or --radiance ENV (AO "
                 "and visibility transfer stay direct)");
      if (a.transfer && !a.albedo.empty() && (a.albedo[0] != a.albedo[1] || a.albedo[0] != a.albedo[2]))
        fail(b + " with --transfer and a coloured --albedo: the diffuse transfer is one vector for all channels, so it "
                 "bounces with a grey albedo only (give one value, or R = G = B); the band-1 radiance (--radiance) "
                 "bounces per channel");
    } else {
      if (!a.albedo.empty()) fail("--albedo applies with --bounces B (B >= 1)");
      if (a.bounce_rays != 0) fail("--bounce-rays applies with --bounces B (B >= 1)");
    }
  }
  if (samples != 0) a.integrator.set_samples(samples);
  if (a.integrator.kind == bake::IntegratorKind::Silhouette &&
      a.integrator.silhouette_k < bake::IntegratorSpec::kMinSilhouetteK)
    fail("--samples " + std::to_string(a.integrator.silhouette_k) + ": the silhouette integrator needs k >= " +
         std::to_string(bake::IntegratorSpec::kMinSilhouetteK) + " (2 u-isolines)");
  if (a.command == "fiv") a.shell_spec.silhouette_k = a.integrator.silhouette_k;  // the shells' k (as in scene files)
}

} // namespace

std::optional<Args> parse(int argc, char** argv, const tool::MpiSession& mpi) {
  Args a;
  uint32_t samples = 0;  // --samples: 0 if not given
  CLI::App app(kDescription, "prtbake");
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("prtbake ") + kToolkitVersion);
  app.get_formatter()->column_width(24);
  add_vertex(app, a, samples);
  add_vertex(app, a, samples, "texel");
  add_fiv(app, a, samples);
  add_scene(app, a);
  tool::add_export(app, a.exported);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    // A command's --help is its whole text; the tool's own lists the commands.
    const std::vector<CLI::App*> given = app.get_subcommands();
    std::cout << (given.empty() ? overview() : given.front()->help("prtbake"));
    return std::nullopt;
  } catch (const CLI::Success& e) {  // --version
    app.exit(e);
    return std::nullopt;
  } catch (const CLI::ParseError& e) {
    const std::vector<CLI::App*> given = app.get_subcommands();
    throw UsageError(tool::usage_message(app, e, "prtbake", kCommands),
                     given.empty() ? "" : "prtbake " + given.front()->get_name());
  }
  a.command = app.get_subcommands().front()->get_name();
  if (a.command != "export") {
    a.command_line = content_command_line(argc, argv);
    a.shard.rerun_command = tool::shell_command(argc, argv);
    if (std::getenv("SOURCE_DATE_EPOCH")) a.reproducible = true;
    // A sharded bake's file is the --reproducible one, whichever worker merges (shards.h).
    if (a.shard.given() || mpi.active()) a.reproducible = true;
  }
  validate(a, app, samples, mpi);
  return a;
}

} // namespace prt::tool
