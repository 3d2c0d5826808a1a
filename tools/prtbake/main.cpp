// prtbake — bakes precomputed radiance transfer assets. A thin shell: it parses arguments (CLI11:
// one subcommand per kind of bake, each with only the options that apply to it, into the typed
// specs of libbake), reports progress and calls libbake (integration) and formats (the HDF5 file).
#include <bake/bake/choose.h>
#include <bake/bake/diagnostics.h>
#include <bake/bake/error_report.h>
#include <bake/bake/fiv.h>
#include <bake/bake/scene_bake.h>
#include <bake/bake/vertex_bake.h>
#include <bake/core/error.h>
#include <bake/core/sha256.h>
#include <bake/environment/envmap.h>
#include <bake/environment/irradiance.h>
#include <bake/mesh/mesh.h>
#include <formats/asset.h>
#include <prtshade/sh.h>

#include "bakefile.h"
#include "cli.h"
#include "export.h"
#include "progress_bar.h"
#include "shards.h"
#include "tool_main.h"

#include <CLI/CLI.hpp>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/info.h>

#include <algorithm>
#include <functional>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <iostream>
#ifdef __GLIBC__
#include <malloc.h>
#endif
#include <optional>
#include <string>
#include <sys/resource.h>
#include <unistd.h>
#include <vector>

namespace fs = std::filesystem;
using namespace prt;

namespace {

constexpr const char* kVersion = tool::kToolkitVersion;

constexpr const char* kDescription = "prtbake — bake precomputed radiance transfer (PRT) data for game geometry";

constexpr const char* kVertexHelp =
    "Bakes per-vertex products for every vertex of MESH (OBJ, PLY, OFF, STL, glTF, GLB) in one\n"
    "pass: the rays cast from a vertex serve every product at once. Rows follow the file's vertex\n"
    "order (glTF: the vertices of each primitive instance of the default scene, in node order);\n"
    "a position with several normals in the file (OBJ v//vn hard edges) gives one row per\n"
    "(position, normal) pair, and /mesh/source_position says which file vertex each row is.\n"
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
    "samples, seed and FIV shells are set in the file's \"bake\" section. Per-object results go\n"
    "under /objects/<name>/ in the file.\n"
    "A glTF (.gltf, .glb) is a scene too: each primitive instance of its default scene is an\n"
    "object named by its node path (\"root/engine/piston_2\", \"#p1\" for a mesh's 2nd primitive;\n"
    "stored as /objects/root|engine|piston_2 with the path in node_path), role \"both\", albedo\n"
    "the material's baseColorFactor (0.8 grey without one). --options sets the rest.";

// One line per command: the top-level --help and the message for an unknown command.
const std::vector<tool::Command> kCommands = {
    {"vertex", "per-vertex products of a mesh: AO, SH transfer, visibility, band-1 and shadowed radiance"},
    {"fiv", "an occluder's Fullsphere Irradiance Vectors on shells around it, and the DifMap"},
    {"scene", "a scene file or glTF: bakes what each object needs and says what it leaves out, and why"},
    {"export", "a baked file as glTF, plain binary, or Unity / Godot / Filament light probes"},
};

// Each command's EXAMPLES (its --help shows its own); the top-level --help shows one per command.
constexpr const char* kVertexExamples =
    "EXAMPLES\n"
    "  prtbake vertex data/bunny_ground.obj --ao --transfer 3 --radiance data/sunset.exr -o bunny.prt.h5\n"
    "  prtbake vertex asset.obj --visibility 6 --samples 4096 --threads 8 -o asset.prt.h5\n"
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

using tool::UsageError;

struct Args {
  std::string command;      // vertex, fiv, scene or export
  std::string input;        // the mesh (vertex), the occluder (fiv) or the scene file or glTF (scene)
  std::string scene_options;  // scene: a glTF scene's options file (--options)
  std::string output;       // the .prt.h5 file
  std::string environment;  // vertex: --radiance ENV (alias --env); fiv: --env ENV
  bool ao = false;
  int transfer = 0, visibility = 0;  // SH orders (0: not baked)
  int shadowed = 0;                  // vertex: --shadowed L, S under the --radiance environment
  // vertex: the integrator; fiv: seed and report (its k is shell_spec.silhouette_k); scene: --report.
  bake::IntegratorSpec integrator;
  bake::ShellSpec shell_spec;  // fiv
  bool report_given = false;  // scene: --report overrides the scene file's
  int threads = 0;            // 0: all cores
  bake::UpAxis up = bake::UpAxis::Y;
  bool file_normals = true, quiet = false, reproducible = false, dry_run = false;
  bool verbose = false;  // vertex: the pilot's whole table, not its one-line summary
  bool flip_normals = false;  // vertex: reverse every triangle and file normal
  double target_error = 0;    // vertex: --target-error E (0: not given; bake/bake/choose.h)
  bool integrator_given = false;  // vertex: --integrator was given (the chooser then keeps its kind)
  std::string command_line;  // what determines the file's contents (no --threads/--quiet)
  tool::ExportArgs exported;  // export: a baked file in another format (export.h)
  tool::ShardOptions shard;   // vertex, fiv, scene: sharded and resumable bakes (shards.h)
  std::optional<tool::Worker> worker;  // who this process is in a sharded bake (nullopt: not sharded)
};

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

void add_vertex(CLI::App& app, Args& a, uint32_t& samples) {
  CLI::App& cmd = *app.add_subcommand("vertex", kVertexHelp);
  cmd.add_option("MESH", a.input, "the mesh (OBJ, PLY, OFF, STL, glTF, GLB; a glTF's primitive\ninstances are concatenated in node order)")->required()->type_name("");
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
  tool::add_shard_options(cmd, a.shard, "vertices");
  cmd.footer(std::string(kVertexExamples) + tool::kExitStatusHelp);
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
       "  --version  the version (prtbake " + std::string(kVersion) + ")\n\n";
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
  if (a.command == "vertex") {
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
  }
  if (samples != 0) a.integrator.set_samples(samples);
  if (a.integrator.kind == bake::IntegratorKind::Silhouette &&
      a.integrator.silhouette_k < bake::IntegratorSpec::kMinSilhouetteK)
    fail("--samples " + std::to_string(a.integrator.silhouette_k) + ": the silhouette integrator needs k >= " +
         std::to_string(bake::IntegratorSpec::kMinSilhouetteK) + " (2 u-isolines)");
  if (a.command == "fiv") a.shell_spec.silhouette_k = a.integrator.silhouette_k;  // the shells' k (as in scene files)
}

// Parses and checks the command line; nullopt when it asked for help or the version (printed).
std::optional<Args> parse(int argc, char** argv, const tool::MpiSession& mpi) {
  Args a;
  uint32_t samples = 0;  // --samples: 0 if not given
  CLI::App app(kDescription, "prtbake");
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("prtbake ") + kVersion);
  app.get_formatter()->column_width(24);
  add_vertex(app, a, samples);
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

// Prints reader warnings once each, with a count for repeats.
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

// The fix for normals that point inside, as the warnings below say it.
const char* flip_fix(bool flipped) {
  return flipped ? "rerun without --flip-normals (this run flipped the mesh)" : "rerun with --flip-normals";
}

// Closed components wound inwards (bake/mesh/mesh.h winding_facts): their vertices will see no sky.
// `object`: a scene's object ("" for prtbake vertex, whose --flip-normals can fix a whole mesh).
// `casts`: the mesh shadows itself (a vertex bake, a scene's "both"), so those vertices see no sky;
// a receiver-only object casts nothing and is shaded about normals that point inside.
void warn_inward(const bake::WindingFacts& facts, bool flipped, const std::string& object = "", bool casts = true) {
  const size_t inward = facts.inward_components();
  if (inward == 0) return;
  // --flip-normals flips the whole mesh: the fix only when everything in it is inwards.
  const std::string fix =
      !object.empty() ? std::string("fix their winding in its mesh file")
      : inward == facts.components
          ? std::string(flip_fix(flipped))
          : "fix their winding in the file (--flip-normals would flip all " + std::to_string(facts.components) +
                " components of the mesh, not only these)";
  std::fprintf(stderr,
               "prtbake: warning: %s%zu of %zu closed components (%zu triangles) are wound inwards: their normals point "
               "inside, so their vertices %s; %s\n",
               object.empty() ? "" : (object + ": ").c_str(), inward, facts.closed.size(), facts.inward_triangles(),
               casts ? "see no sky" : "are shaded as if seen from inside", fix.c_str());
}

// More than half the vertices saw no sky at all (bake/bake/vertex_bake.h count_no_sky). Which
// explanation fits: closed parts wound inwards (said above), or else the flip probe — with their
// normals reversed, would these vertices see sky (normals pointing inside: flip them) or not
// (vertices enclosed by other geometry: an engine's internals under its housing, parts pushed
// into each other; the bake is right and nothing is to be fixed)?
void warn_no_sky(const bake::NoSkyCount& count, const bake::WindingFacts& facts,
                 const std::function<bake::FlipProbe()>& probe, bool flipped) {
  if (!(count.share() > 0.5)) return;
  std::string why;
  if (facts.inward_components() > 0) {
    why = "some closed parts are wound inwards (see above)";
  } else {
    const bake::FlipProbe p = probe();
    const std::string tally = std::to_string(p.would_see_sky) + " of " + std::to_string(p.probed) +
                              " sampled would see sky with the opposite normal";
    why = 2 * p.would_see_sky > p.probed
              ? tally + ", so their normals point inside the geometry; " + flip_fix(flipped)
              : tally + ", so they are enclosed by other geometry (parts inside or pushed into other parts), not "
                        "turned inside out; nothing to fix in the normals";
  }
  std::fprintf(stderr, "prtbake: warning: %.1f%% of vertices (%zu of %zu) see no sky at all: %s\n",
               100 * count.share(), count.vertices, count.total, why.c_str());
}

// A target the chooser could not reach within its bounds: it baked the best plan it had
// (bake/bake/choose.h, step 5); say so on stderr, with the options that go further.
void warn_unreached(const bake::IntegratorChoice& choice, const std::string& object) {
  if (choice.reaches) return;
  std::fprintf(stderr,
               "prtbake: warning: %starget error %g is not reached within the chooser's bounds: baking %s at %u samples, "
               "expected error %.2g; %s (--integrator, --samples, --target-error)\n",
               object.empty() ? "" : (object + ": ").c_str(), choice.target, bake::to_string(choice.spec.kind),
               choice.spec.samples(), choice.expected_error, choice.further.c_str());
}

// The error report's reference for a target (bake/bake/choose.h plan_report_reference), with -v.
void print_reference_plan(const bake::ReferencePlan& plan) {
  std::printf("report reference: QMC at %u rays per point on %zu points (probe at %u rays, %.2f s); expected noise",
              plan.rays, plan.points, bake::ReferencePlan::kReportProbeRays, plan.probe_seconds);
  for (size_t p = 0; p < plan.products.size(); ++p)
    std::printf("%s %s %.1e", p ? "," : "", bake::product_label(plan.products[p]), plan.noise[p]);
  std::printf(" (E/3 = %.1e%s)\n", plan.target / 3,
              plan.budget_bound ? "; the report's ray budget keeps some product above it" : "");
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
  r.source = a.input;
  r.source_sha256 = source_sha;
  r.up_axis = a.up == bake::UpAxis::Y ? "y" : "z";
  r.sh_convention = "real orthonormal SH, Condon-Shortley phase, index l*(l+1)+m, order = number of bands L (L*L "
                    "coefficients); bands 0-2 equal DirectXMath XMSHEvalDirection; directions in the mesh frame";
  return r;
}

// Writes the asset (validated, temp + rename: formats/asset.h) and says where and how big.
void write_file(const Args& a, const prt::formats::Asset& asset) {
  // A Ctrl-C during a stage that takes no monitor (loading, setup, the DifMap) is honoured here:
  // a cancelled bake never writes.
  if (tool::interrupt_token().requested()) throw bake::Cancelled();
  prt::formats::write_asset(a.output, asset);
  if (!a.quiet) {
    std::error_code ec;
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);  // ru_maxrss: the peak resident set, in KiB on Linux
    std::printf("wrote %s (%s); peak memory %s\n", a.output.c_str(), human_bytes(fs::file_size(a.output, ec)).c_str(),
                human_bytes(uintmax_t(usage.ru_maxrss) * 1024).c_str());
  }
}

// `shards`: emplaced when the bake is sharded (prtbake_main reports its chunks on Ctrl-C).
int run_vertex(const Args& a, const tool::MpiSession& mpi, std::optional<tool::ShardedRows>& shards) {
  const bool say = !a.quiet && mpi.rank() == 0;  // under mpirun, rank 0 speaks for all
  const std::optional<tool::Worker>& worker = a.worker;
  check_output_writable(a.output);
  const int threads = a.threads > 0 ? a.threads : tbb::info::default_concurrency();
  tbb::global_control threads_limit(tbb::global_control::max_allowed_parallelism, size_t(threads));

  bake::MeshLoadOptions mopt;
  mopt.use_file_normals = a.file_normals;
  mopt.flip_normals = a.flip_normals;
  const bake::Mesh mesh = bake::load_mesh(a.input, mopt);
  const bake::Topology topo = bake::build_topology(mesh);
  const std::string mesh_sha = mesh.source_sha256;
  print_warnings(mesh.warnings);
  if (say)
    std::printf("mesh: %s: %zu vertices, %zu triangles (%zu file positions, %zu faces), normals %s%s\n",
                a.input.c_str(), mesh.positions.size(), mesh.triangles.size(), mesh.file_positions, mesh.file_faces,
                mesh.normal_source == bake::Mesh::NormalSource::File ? "from the file" : "angle-weighted",
                a.flip_normals ? ", flipped" : "");
  if (say && mesh.origin != Eigen::Vector3d::Zero())  // far from the world origin (bake/mesh/mesh.h, ORIGIN)
    std::printf("mesh: baked relative to its origin (%.17g, %.17g, %.17g); /mesh/positions holds world coordinates\n",
                mesh.origin.x(), mesh.origin.y(), mesh.origin.z());
  const bake::WindingFacts winding = bake::winding_facts(mesh, topo);
  warn_inward(winding, a.flip_normals);

  std::optional<bake::EnvMap> env;
  if (!a.environment.empty()) {
    env = bake::EnvMap::load(a.environment, a.up);
    const auto& i = env->info();
    if (say)
      std::printf("environment: %s: %dx%d %s, luminance max %.4g / mean %.4g (%.0fx), %llu negative pixel values "
                  "clamped to 0 (min seen %.3g)\n",
                  a.environment.c_str(), i.width, i.height, i.layout.c_str(), i.max_luminance, i.mean_luminance,
                  i.mean_luminance > 0 ? i.max_luminance / i.mean_luminance : 0.0,
                  (unsigned long long)i.negative_pixels_clamped, i.min_value_seen);
  }

  bake::ProductRequest req;
  req.ao = a.ao;
  req.transfer_order = a.transfer;
  req.visibility_order = a.visibility;
  req.radiance = env ? &*env : nullptr;
  if (a.shadowed) req.shadowed = req.radiance, req.shadowed_order = a.shadowed;

  const tool::ProgressBar bar(say ? tool::ProgressStyle::Auto : tool::ProgressStyle::Quiet);
  const bake::Monitor progress = bar.monitor(&tool::interrupt_token());
  bake::IntegratorSpec spec = a.integrator;
  const bake::MeshAccel accel(mesh, topo);  // the mesh's trees, shared by the pilot, the bake and the report
  std::optional<bake::IntegratorChoice> chosen;  // the chooser's, with a target
  if (a.target_error > 0) {
    bake::ChooserOptions copt;
    copt.target = a.target_error;
    if (a.integrator_given) copt.only = a.integrator.kind;
    copt.counted_costs = a.reproducible;  // the same choice, and bytes, on any machine
    const bake::IntegratorChoice choice = bake::choose_integrator(bake::vertex_shade_points(mesh, topo), mesh, topo, req,
                                                                  a.integrator, copt, progress, &accel);
    spec = choice.spec;
    chosen = choice;
    if (say && a.verbose)
      for (const std::string& line : bake::choice_lines(choice)) std::printf("%s\n", line.c_str());
    else if (say)
      std::printf("%s\n", bake::choice_summary(choice).c_str());
    warn_unreached(choice, "");
  }
  // Bake, write, check; when the check finds a product NOT met (the pilot's sample missed where the
  // error sits), bake once more at the knob the measured error and the model's rate call for
  // (bake/bake/choose.h corrected_plan), and check again.
  for (int pass = 0;; ++pass) {
    const auto setup_start = std::chrono::steady_clock::now();
    const std::unique_ptr<bake::Integrator> integrator_ptr =
        bake::make_integrator(spec, mesh, topo, req, &accel);
    const bake::Integrator& integrator = *integrator_ptr;
    const double setup_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - setup_start).count();
    if (say) {
      std::printf("baking:");
      if (a.ao) std::printf(" ao");
      if (a.transfer) std::printf(" transfer/diffuse (order %d, %d coefficients)", a.transfer, a.transfer * a.transfer);
      if (a.visibility) std::printf(" transfer/visibility (order %d, %d coefficients)", a.visibility, a.visibility * a.visibility);
      if (env) std::printf(" radiance/band1 (3x3)");
      if (a.shadowed) std::printf(" radiance/shadowed (order %d, 3x%d)", a.shadowed, a.shadowed * a.shadowed);
      std::printf("\nintegrator: %s; %d threads; setup (ray/contour BVHs, tables) %.2f s\n",
                  integrator.description().c_str(), threads, setup_seconds);
      std::fflush(stdout);
    }
    const std::vector<bake::ShadePoint> points = bake::vertex_shade_points(mesh, topo);
    bake::VertexBake result;
    if (worker) {
      const std::string manifest = tool::manifest_of(
          {"vertex", kVersion, a.command_line, mesh_sha, env ? env->info().sha256 : "no environment",
           integrator.description(), bake::to_string(spec.kind), std::to_string(spec.samples()),
           std::to_string(spec.seed), std::to_string(integrator.layout().width), std::to_string(a.shard.chunk_rows)});
      shards.emplace(*worker, mpi, a.shard, a.output, manifest, std::vector<uint64_t>{points.size()},
                     std::vector<uint32_t>{uint32_t(integrator.layout().width)}, a.quiet);
      const bool merges = shards->run([&] {
        shards->work([&](const bake::ChunkRange& r, const bake::Monitor& monitor) {
          return tool::bake_chunk(points, r, integrator, monitor);
        });
      });
      if (!merges) return 0;
      result = shards->merge(0, integrator.layout());
    } else {
      try {
        result = bake::bake_points(points, integrator, progress);
      } catch (const bake::Cancelled&) {
        if (pass == 0) throw;  // nothing written yet
        std::fprintf(stderr, "prtbake: cancelled while baking again: %s holds the first bake and its error report\n",
                     a.output.c_str());
        return tool::kExitCancelled;
      }
    }
    warn_no_sky(bake::count_no_sky(result), winding, [&] { return bake::probe_flipped_normals(mesh, topo, result); },
                a.flip_normals);
    if (say) {
      std::printf("baked %zu vertices in %.2f s (%.0f integrals/s)\n", mesh.positions.size(), result.seconds,
                  mesh.positions.size() / result.seconds);
      if (const std::string work = integrator.work_summary(); !work.empty()) std::printf("%s\n", work.c_str());
      if (shards && shards->threads_of_chunks() == 0)  // chunks of other workers or runs: their threads are not recorded
        std::printf("chunks: %.2f CPU s in the integrator over %.2f s of chunk wall time, summed over the chunks of "
                    "every worker and run\n",
                    result.cpu_seconds, result.seconds);
      else
        std::printf("threads busy %.0f%% of the bake (%.2f CPU s in the integrator over %.2f s on %d thread%s)\n",
                    100 * result.busy_fraction(), result.cpu_seconds, result.seconds, result.threads,
                    result.threads == 1 ? "" : "s");
    }

    // ---- the file (formats/SCHEMA.md) ----
    namespace F = prt::formats;
    std::optional<bake::ErrorReport> report;
    auto write_bake = [&] {
      F::Asset asset;
      asset.root = root_info(a, mesh_sha);
      tool::set_mesh(asset.vertices, mesh);
      if (a.flip_normals) *asset.vertices.normals->source += ", flipped";
      tool::set_products(asset.vertices, result,
                         {integrator.name(), integrator.description(), spec.samples(), spec.seed, a.transfer, a.visibility,
                          env ? &*env : nullptr, a.environment});
      if (report) asset.vertices.report = tool::report_of(*report, result.seconds, mesh.positions.size(), a.reproducible);
      tool::set_target_error(asset, a.target_error);
      write_file(a, asset);
    };
    if (spec.report_points == 0) {
      write_bake();
      if (shards) shards->finish();
      return 0;
    }
    // The bake is written first and checked after (the check re-writes the file with its report):
    // a check cancelled with Ctrl-C, or one that costs more than the user will wait, never costs the bake.
    write_bake();
    if (say) std::printf("checking its error (Ctrl-C keeps the file as written, without its report; --report 0 skips the check)\n");
    std::optional<bake::ReferencePlan> reference_plan;
    try {
      {
        if (a.target_error > 0) {  // a reference whose own noise is within E/3, or a budget that says why not
          // The check may take about as long as the bake (at least kReportMinCpuSeconds of CPU); not
          // with --reproducible, whose rays must not depend on the machine's speed.
          const double check_cpu =
              a.reproducible ? 0.0 : std::max(bake::ReferencePlan::kReportMinCpuSeconds, result.cpu_seconds);
          reference_plan = bake::plan_report_reference(points, mesh, topo, req, spec, a.target_error, progress, &accel, 0,
                                                       check_cpu);
          spec.report_rays = reference_plan->rays;
          if (say && a.verbose) print_reference_plan(*reference_plan);
        }
        // With a target, the reference is two independent halves: its noise is then measured on the
        // report's own values, and the check can take it out of the RMSE (target_check_lines).
        std::pair<std::unique_ptr<bake::Integrator>, std::unique_ptr<bake::Integrator>> reference;
        if (a.target_error > 0) reference = bake::make_reference_pair(spec, mesh, topo, req, &accel);
        else reference.first = bake::make_reference(spec, mesh, topo, req, &accel);
        report = bake::compare_with_reference(mesh, topo, result, *reference.first, spec.report_points, spec.seed,
                                              progress, reference.second.get());
        if (say) {
          std::printf("error against a %u-ray QMC reference on %zu seeded vertices (reference took %.2f s, not "
                      "counted in the bake time):\n",
                      spec.reference_rays(), report->vertices.size(), report->reference_seconds);
          // The bake's own standard error is a sampled integrator's estimate; a deterministic one
          // (silhouette: its error is a bias, which only the comparison measures) has none to print.
          const bool sampled = std::any_of(report->products.begin(), report->products.end(),
                                           [](const auto& e) { return e.bake_std_error > 0; });
          for (const auto& e : report->products) {
            std::printf("  %-20s RMSE %.3e  max %.3e  relative RMSE %.3e  (", bake::product_label(e.product), e.rmse,
                        e.max_abs, e.reference_rms > 0 ? e.rmse / e.reference_rms : 0.0);
            if (sampled) std::printf("bake's estimated std. error %.3e; ", e.bake_std_error);
            std::printf("the reference's own std. error %.3e, %s)\n", e.reference_std_error,
                        report->reference_noise_measured ? "measured from its two halves" : "QMC's estimate");
          }
          if (a.target_error > 0)
            for (const std::string& line : bake::target_check_lines(*report, a.target_error, reference_plan ? &*reference_plan : nullptr))
              std::printf("%s\n", line.c_str());
        }
      }
      write_bake();
    } catch (const bake::Cancelled&) {
      std::fprintf(stderr,
                   "prtbake: cancelled during the error check: %s holds the finished bake without its error report "
                   "(--report 0 skips the check)\n",
                   a.output.c_str());
      return tool::kExitCancelled;
    }
    if (pass > 0 || !chosen || worker || !report) break;
    const std::optional<bake::IntegratorSpec> better = bake::corrected_plan(
        *chosen, bake::target_verdicts(*report, a.target_error, reference_plan ? &*reference_plan : nullptr));
    if (!better) break;
    if (say) {
      std::printf("the check puts the bake's error above the target: baking again with %s at %s (was %s; the "
                  "pilot's rate from the check's measured error; once)\n",
                  bake::to_string(better->kind), better->knob_text().c_str(), spec.knob_text().c_str());
      std::fflush(stdout);
    }
    spec = *better;
    spec.report_rays = 0;
    report.reset();
  }
  if (shards) shards->finish();
  return 0;
}

// The row sets of a sharded FIV bake (shards.h): the DifMap's texels (3 values each), the
// environment FIV (one row of its 9 values), then shell k's samples (FivShellRows::kRowWidth
// values each) in set kFirstShellSet + k.
constexpr uint32_t kDifMapSet = 0, kEnvironmentFivSet = 1, kFirstShellSet = 2;

// The DifMap, the environment FIV and the FIV shells of a sharded bake. Every worker takes slabs
// of rows set after set and stops past the first complete shell that meets the stopping rule; the
// merging process joins the DifMap, the environment FIV and the shells up to that one. nullopt:
// this process does not merge. `topo` and `env` are needed by a process that computes rows only
// (a merge joins committed rows: the environment's identity `env_info` is all it needs). `sharded`
// is emplaced here; the caller removes the chunks (finish()) once the file is written.
struct ShardedFiv {
  std::vector<float> cube;
  bake::Fiv environment{};
  bake::FivShells shells;
};
std::optional<ShardedFiv> sharded_fiv(const Args& a, const tool::Worker& worker, const tool::MpiSession& mpi,
                                      const bake::Mesh& mesh, const bake::Topology* topo, const bake::EnvMap* env,
                                      const bake::EnvMapInfo& env_info, std::optional<tool::ShardedRows>& sharded) {
  PRT_CHECK(!worker.computes || (topo && env));
  const bake::ShellSpec& sp = a.shell_spec;
  const bake::FivShellRows baker =
      worker.computes ? bake::FivShellRows(mesh, *topo, *env, sp) : bake::FivShellRows(mesh, sp);
  std::vector<uint64_t> set_rows = {uint64_t(6) * uint64_t(sp.cube) * uint64_t(sp.cube), 1};
  std::vector<uint32_t> widths = {3, uint32_t(std::tuple_size_v<bake::Fiv>)};
  for (int k = 0; k < baker.shell_count(); ++k)
    set_rows.push_back(baker.rows_per_shell()), widths.push_back(uint32_t(bake::FivShellRows::kRowWidth));
  // What each set holds, its rows and width: chunks of another layout belong to another bake.
  std::string layout = "sets: DifMap texels, environment FIV, shell samples:";
  for (size_t s = 0; s < set_rows.size(); ++s) layout += " " + std::to_string(set_rows[s]) + "x" + std::to_string(widths[s]);
  char spec[192];
  std::snprintf(spec, sizeof spec, "%dx%dx%d inner %.17g fraction %.17g k %u cube %d", sp.n_phi, sp.n_theta, sp.n_rho,
                sp.inner, sp.fraction, unsigned(sp.silhouette_k), sp.cube);
  const std::string manifest = tool::manifest_of({"fiv", kVersion, a.command_line, mesh.source_sha256, env_info.sha256,
                                                  spec, layout, std::to_string(a.shard.chunk_rows)});
  tool::ShardedRows& shards = sharded.emplace(worker, mpi, a.shard, a.output, manifest, set_rows, widths, a.quiet);
  // The set of the first shell, in order, that is complete in the chunk directory and meets the rule.
  int checked = 0;
  bake::ChunkData rows;  // one buffer for every set read back
  const auto last_set = [&]() -> std::optional<uint32_t> {
    for (; checked < baker.shell_count() && shards.complete(kFirstShellSet + uint32_t(checked)); ++checked)
      if (baker.may_stop_after(checked)) {
        shards.join(kFirstShellSet + uint32_t(checked), rows);
        if (baker.stops_after(checked, rows.values)) return kFirstShellSet + uint32_t(checked);
      }
    return std::nullopt;
  };
  std::optional<bake::UnshadowedIrradiance> irradiance;  // built for this worker's first DifMap chunk
  const bool merges = shards.run([&] {
    shards.work(
        [&](const bake::ChunkRange& r, const bake::Monitor& monitor) {
          bake::ChunkData d;
          bake::Task task(monitor, r.set < kFirstShellSet ? "environment FIV and DifMap" : "FIV shell rows", r.rows());
          const double cpu0 = tool::process_cpu_seconds();
          if (r.set == kDifMapSet) {
            if (!irradiance) irradiance.emplace(*env);
            const std::vector<float> texels = bake::irradiance_cube_texels(*irradiance, sp.cube, r.begin, r.end);
            d.values.assign(texels.begin(), texels.end());
            task.advance(r.rows());
          } else if (r.set == kEnvironmentFivSet) {
            const bake::Fiv f = bake::environment_fiv(*env);
            d.values.assign(f.begin(), f.end());
            task.advance(r.rows());
          } else {
            d.values = baker.rows(int(r.set - kFirstShellSet), r.begin, r.end, &task);
          }
          task.finish();
          d.seconds = task.elapsed_seconds();
          d.cpu_seconds = tool::process_cpu_seconds() - cpu0;
          return d;
        },
        std::nullopt, last_set);
  });
  if (!merges) return std::nullopt;
  ShardedFiv out;
  shards.join(kDifMapSet, rows);
  out.cube.assign(rows.values.begin(), rows.values.end());
  shards.join(kEnvironmentFivSet, rows);
  std::copy(rows.values.begin(), rows.values.end(), out.environment.begin());
  out.shells = baker.empty_shells();
  for (int k = 0; k < baker.shell_count(); ++k) {
    shards.join(kFirstShellSet + uint32_t(k), rows);
    baker.append(out.shells, k, rows.values);
    out.shells.seconds += rows.seconds;
    if (baker.stops_after(k, rows.values)) break;
  }
  return out;
}

int run_fiv(const Args& a, const tool::MpiSession& mpi, std::optional<tool::ShardedRows>& shards) {
  const bool say = !a.quiet && mpi.rank() == 0;  // under mpirun, rank 0 speaks for all
  const std::optional<tool::Worker>& worker = a.worker;
  check_output_writable(a.output);
  const int threads = a.threads > 0 ? a.threads : tbb::info::default_concurrency();
  tbb::global_control threads_limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
  bake::MeshLoadOptions mopt;
  mopt.use_file_normals = false;  // an occluder's normals play no part in its FIVs
  const bake::Mesh mesh = bake::load_mesh(a.input, mopt);
  print_warnings(mesh.warnings);
  // A merge (--merge) joins committed rows: it needs the environment's identity (its SHA-256, in
  // the manifest and the file) but not its pixels, nor the mesh's topology, unless its error
  // report integrates a reference. The workers loaded the same bytes (the manifest holds their
  // SHA-256) and checked the pixels.
  const bool integrates = !worker || worker->computes || a.integrator.report_points > 0;
  std::optional<bake::Topology> topo;
  std::optional<bake::EnvMap> env;
  if (integrates) {
    topo = bake::build_topology(mesh);
    env = bake::EnvMap::load(a.environment, a.up);
  }
  const bake::EnvMapInfo env_info = env ? env->info() : bake::EnvMap::identify(a.environment);
  const tool::ProgressBar bar(say ? tool::ProgressStyle::Auto : tool::ProgressStyle::Quiet);
  const bake::Monitor progress = bar.monitor(&tool::interrupt_token());
  if (say)
    std::printf("occluder: %s: %zu triangles; environment: %s (%dx%d %s)\n", a.input.c_str(), mesh.triangles.size(),
                a.environment.c_str(), env_info.width, env_info.height, env_info.layout.c_str());

  std::optional<ShardedFiv> sharded;
  if (worker) {
    sharded = sharded_fiv(a, *worker, mpi, mesh, topo ? &*topo : nullptr, env ? &*env : nullptr, env_info, shards);
    if (!sharded) return 0;
  }
  const auto t0 = std::chrono::steady_clock::now();
  const bake::Fiv fenv = sharded ? sharded->environment : bake::environment_fiv(*env);
  const std::vector<float> cube = sharded ? std::move(sharded->cube) : bake::irradiance_cube(*env, a.shell_spec.cube);
  const double env_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  bake::FivShells shells =
      sharded ? std::move(sharded->shells) : bake::bake_fiv_shells(mesh, *topo, *env, a.shell_spec, progress);
  if (say) {
    std::printf("environment FIV and %dx%dx6 DifMap in %.2f s%s\n", a.shell_spec.cube, a.shell_spec.cube, env_seconds,
                sharded ? " (both in the chunks)" : "");
    std::printf("shells: %dx%dx%zu (of %d requested radii, %.3g to %.3g; bounding radius %.4g) in %.2f s (%.0f "
                "integrals/s)\n",
                a.shell_spec.n_phi, a.shell_spec.n_theta, shells.radii.size(), a.shell_spec.n_rho, shells.radii.front(),
                shells.radii.back(), shells.radius, shells.seconds,
                double(shells.integrals) / shells.seconds);
  }

  namespace F = prt::formats;
  F::Asset asset;
  asset.root = root_info(a, mesh.source_sha256);
  tool::set_fiv_environment(asset, env_info, a.environment, fenv, cube, a.shell_spec.cube);
  const std::string name = tool::safe_name(fs::path(a.input).stem().string());
  std::optional<F::ReportRow> report;
  if (a.integrator.report_points > 0) {
    // Error against a QMC reference (65,536 rays, full-sphere mode) at seeded shell samples.
    const bake::FivErrorReport r = bake::fiv_error_report(mesh, *topo, *env, shells, fenv, a.integrator.report_points,
                                                          a.integrator.seed, progress);
    if (say)
      std::printf("error against a %u-ray QMC reference at %zu seeded shell samples (reference took %.2f s, not "
                  "counted): RMSE %.3e, max %.3e, RMSE / RMS|F_env| %.3e (reference's own std. error %.3e)\n",
                  bake::IntegratorSpec::kSilhouetteReferenceRays, r.points, r.reference_seconds, r.rmse, r.max_abs,
                  r.reference_rms > 0 ? r.rmse / r.reference_rms : 0.0,
                  r.reference_std_error);
    report = tool::fiv_report_of(name, r, shells, a.reproducible);
  }
  // The shells move into the file's occluder (the report above was their last reader).
  asset.occluders.push_back(tool::occluder_of(name, std::move(shells), env_info, a.environment, a.shell_spec.fraction,
                                              a.shell_spec.silhouette_k));
  asset.occluders.back().report = std::move(report);
  write_file(a, asset);
  if (shards) shards->finish();
  return 0;
}

// How the tools name a scene object to people: a glTF instance by its node path ("node0/body"),
// a scene file's object by its name (the file's "|" spelling is for HDF5 paths only).
std::string scene_object_label(const bake::SceneObject& o) { return o.node_path.empty() ? o.name : o.node_path; }

int run_scene(const Args& a, const tool::MpiSession& mpi, std::optional<tool::ShardedRows>& shards) {
  const bool say = !a.quiet && mpi.rank() == 0;  // under mpirun, rank 0 speaks for all
  const std::optional<tool::Worker>& worker = a.worker;
  if (!a.dry_run) check_output_writable(a.output);
  const int threads = a.threads > 0 ? a.threads : tbb::info::default_concurrency();
  tbb::global_control threads_limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
  bake::SceneDescription scene = bake::load_scene(
      a.input, a.scene_options.empty() ? std::nullopt : std::optional<fs::path>(a.scene_options));
  if (a.report_given) scene.integrator.report_points = a.integrator.report_points;
  scene.counted_costs = a.reproducible;  // a target's choice by counted work: the same on any machine
  Args file_args = a;  // the root attributes follow the scene file
  file_args.up = scene.up;

  std::vector<std::string> warnings;
  const std::vector<bake::Mesh> meshes = bake::load_scene_meshes(scene, warnings);
  print_warnings(warnings);
  std::optional<bake::EnvMap> env;
  if (scene.environment) env = bake::EnvMap::load(*scene.environment, scene.up);
  const bake::ScenePlan plan = bake::plan_scene(scene, meshes);
  // Receivers with closed parts wound inwards: their vertices would see no sky.
  for (size_t i = 0; i < scene.objects.size(); ++i)
    if (plan.objects[i].receiver && plan.objects[i].any_vertex_product())
      warn_inward(bake::winding_facts(meshes[i], bake::build_topology(meshes[i])), false,
                  scene_object_label(scene.objects[i]), plan.objects[i].occluder);

  if (say) {
    std::printf("scene: %s: %zu objects, environment %s, integrator %s, SH tolerance %g\n", a.input.c_str(),
                scene.objects.size(), env ? scene.environment->string().c_str() : "none",
                bake::to_string(scene.integrator.kind),
                scene.sh_tolerance);
    // Every object with its decisions; with many objects (an engine of 115 parts), the objects
    // that share their role and decisions are printed once as a group (-v: every object).
    auto decisions = [&](size_t i) {
      std::string d = std::string(bake::role_name(scene.objects[i].role)) + "\n";
      for (const auto& b : plan.objects[i].baked) d += "      bake       " + b + "\n";
      for (const auto& l : plan.objects[i].left_out) d += "      leave out  " + l + "\n";
      return d;
    };
    auto name_of = [&](size_t i) { return scene_object_label(scene.objects[i]); };
    constexpr size_t kGroupAbove = 12;  // objects; fewer are listed one by one
    if (a.verbose || scene.objects.size() <= kGroupAbove) {
      for (size_t i = 0; i < scene.objects.size(); ++i) {
        const std::string d = decisions(i);
        std::printf("  %s (%s): %s, %zu vertices, %zu triangles\n%s", name_of(i).c_str(), bake::role_name(scene.objects[i].role),
                    scene.objects[i].mesh.string().c_str(), meshes[i].positions.size(), meshes[i].triangles.size(),
                    d.substr(d.find('\n') + 1).c_str());
      }
    } else {
      std::vector<std::pair<std::string, std::vector<size_t>>> sets;  // in order of first appearance
      for (size_t i = 0; i < scene.objects.size(); ++i) {
        const std::string d = decisions(i);
        auto it = std::find_if(sets.begin(), sets.end(), [&](const auto& x) { return x.first == d; });
        if (it == sets.end()) sets.push_back({d, {i}});
        else it->second.push_back(i);
      }
      for (const auto& [d, members] : sets) {
        size_t vertices = 0, triangles = 0;
        for (size_t i : members) vertices += meshes[i].positions.size(), triangles += meshes[i].triangles.size();
        std::string names;
        for (size_t k = 0; k < std::min<size_t>(members.size(), 3); ++k) names += (k ? ", " : "") + name_of(members[k]);
        if (members.size() > 3) names += " and " + std::to_string(members.size() - 3) + " more";
        std::printf("  %zu object%s (%s): %s; %zu vertices, %zu triangles\n%s", members.size(), members.size() == 1 ? "" : "s",
                    d.substr(0, d.find('\n')).c_str(), names.c_str(), vertices, triangles, d.substr(d.find('\n') + 1).c_str());
      }
      std::printf("  (objects with the same role and decisions are grouped; -v lists every object)\n");
    }
    for (const auto& l : scene.lights)
      std::printf("  light %s (%s): %zu face(s), radiance %g %g %g%s\n", l.name.c_str(), bake::light_shape_name(l.shape),
                  l.faces.size(), l.radiance[0], l.radiance[1], l.radiance[2], l.two_sided ? ", two-sided" : "");
    for (const auto& n : plan.notes) std::printf("  %s\n", n.c_str());
    std::fflush(stdout);
  }
  if (a.dry_run) {
    // What the bake would cost: each group's integrator timed on seeded vertices (with a target,
    // after the pilot that chooses it), nothing baked or written.
    if (say) std::printf("estimated cost (nothing is baked):\n");
    bake::SceneRows estimate;
    estimate.estimate_only = true;
    const tool::ProgressBar bar(say ? tool::ProgressStyle::Auto : tool::ProgressStyle::Quiet);
    bake::bake_scene(scene, plan, meshes, env ? &*env : nullptr, bar.monitor(&tool::interrupt_token()),
                     [&](const std::string& line) {
                       if (say) std::printf("  %s\n", line.c_str());
                       std::fflush(stdout);
                     },
                     estimate);
    return 0;
  }

  const tool::ProgressBar bar(say ? tool::ProgressStyle::Auto : tool::ProgressStyle::Quiet);
  const bake::Monitor progress = bar.monitor(&tool::interrupt_token());
  // Sharded: the receivers' rows in chunks (every worker), then the rest of the bake on the
  // merging process, its rows read back from the chunks (shards.h).
  bake::SceneRows merged_rows;
  if (worker) {
    std::vector<uint64_t> set_rows;
    std::vector<uint32_t> widths;
    std::vector<std::string> lines = {"scene", kVersion, a.command_line, bake::sha256_file(a.input),
                                      a.scene_options.empty() ? "" : bake::sha256_file(a.scene_options),
                                      env ? env->info().sha256 : "no environment", std::to_string(a.shard.chunk_rows)};
    for (size_t i = 0; i < scene.objects.size(); ++i) {
      const bake::ObjectPlan& p = plan.objects[i];
      if (!p.receiver || !p.any_vertex_product()) continue;
      set_rows.push_back(meshes[i].positions.size());
      widths.push_back(uint32_t(bake::ProductLayout(bake::product_request(p, env ? &*env : nullptr)).width));
    }
    // Every object's mesh, occluders included: they shape the receivers' values.
    for (size_t i = 0; i < scene.objects.size(); ++i) lines.push_back(scene.objects[i].name + " " + meshes[i].source_sha256);
    shards.emplace(*worker, mpi, a.shard, a.output, tool::manifest_of(lines), set_rows, widths, a.quiet);
    const bool merges = shards->run([&] {
      bake::SceneRows work;
      work.rows_only = true;
      work.rows = [&](size_t set, std::span<const bake::ShadePoint> points, const bake::Integrator& integrator,
                      const bake::Monitor&, const std::string&, uint64_t& closed_form) {
        shards->work(
            [&](const bake::ChunkRange& r, const bake::Monitor& monitor) {
              return tool::bake_chunk(points, r, integrator, monitor);
            },
            uint32_t(set));
        closed_form = 0;
        return bake::VertexBake{};
      };
      bake::bake_scene(scene, plan, meshes, env ? &*env : nullptr, progress, [](const std::string&) {}, work);
    });
    if (!merges) return 0;
    merged_rows.rows = [&](size_t set, std::span<const bake::ShadePoint>, const bake::Integrator& integrator,
                           const bake::Monitor&, const std::string&, uint64_t& closed_form) {
      return shards->merge(uint32_t(set), integrator.layout(), &closed_form);
    };
  }
  namespace F = prt::formats;
  // The file from a bake (with its reports once they are made).
  auto write_scene = [&](const bake::SceneBake& result) {
    F::Asset asset;
    asset.root = root_info(file_args, bake::sha256_file(a.input));
    const std::string env_path = env ? scene.environment->string() : std::string();
    F::SceneInfo& info = asset.scene.emplace();
    info.scene_file = a.input;
    if (!a.scene_options.empty()) {
      info.options_file = a.scene_options;
      info.options_sha256 = bake::sha256_file(a.scene_options);
    }
    info.integrator = std::string(bake::to_string(scene.integrator.kind));
    info.samples = int64_t(scene.integrator.samples());
    info.seed = int64_t(scene.integrator.seed);
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
      obj.mesh_sha256 = meshes[i].source_sha256;
      if (!o.node_path.empty()) obj.node_path = o.node_path;
      obj.transform.emplace(16);
      for (int k = 0; k < 16; ++k) (*obj.transform)[size_t(k)] = o.world_from_object(k / 4, k % 4);
      obj.albedo = std::vector<double>(o.material.albedo.begin(), o.material.albedo.end());
      obj.phong_exponent = o.material.phong_exponent;
      obj.sh_order_diffuse = int64_t(p.transfer_order);
      obj.sh_order_glossy = int64_t(std::max(p.visibility_order, p.shadowed_order));
      obj.baked = join(p.baked, "-");
      obj.left_out = join(p.left_out, "-");
      if (o.material.glossy()) obj.specular = std::vector<double>(o.material.specular.begin(), o.material.specular.end());
      if (ob.values) obj.closed_form_vertices = int64_t(ob.closed_form_vertices);
      tool::set_mesh(obj.set, meshes[i]);
      if (ob.values) {
        tool::set_products(obj.set, *ob.values,
                           {std::string(bake::to_string(ob.integrator.kind)), ob.integrator_description,
                            ob.integrator.samples(), ob.integrator.seed,
                            p.transfer_order, p.visibility_order, env ? &*env : nullptr, env_path});
        if (ob.report)
          obj.set.report = tool::report_of(*ob.report, ob.values->seconds, meshes[i].positions.size(), a.reproducible);
      }
      if (ob.area) tool::set_area_lights(obj.set, *ob.area, scene.lights, p.area_sh_order);
      if (ob.shells) {
        F::Occluder& occluder =
            asset.occluders.emplace_back(tool::occluder_of(o.name, *ob.shells, env->info(), env_path, scene.fiv.fraction, scene.fiv.silhouette_k));
        if (ob.fiv_report) occluder.report = tool::fiv_report_of(o.name, *ob.fiv_report, *ob.shells, a.reproducible);
      }
    }
    for (const bake::AreaLight& light : scene.lights) asset.lights.push_back(tool::light_of(light));
    if (plan.fiv_environment)
      tool::set_fiv_environment(asset, env->info(), env_path, result.environment_fiv, result.irradiance_cube, scene.fiv.cube);
    tool::set_target_error(asset, scene.target_error);
    write_file(a, asset);
  };
  // Once the bake is whole: its warnings and summary, then the file, written before the error
  // reports are made (bake_scene's SceneRows::baked); the reports re-write it.
  bool written = false, checks = false;
  merged_rows.baked = [&](const bake::SceneBake& result) {
    // A receiver most of whose vertices see no sky: buried in other objects, or turned inside out.
    // One line each for a few; past kNoSkyListed (an engine's internals) one line that counts them
    // and names the first.
    constexpr size_t kNoSkyListed = 5;
    std::vector<std::pair<std::string, bake::NoSkyCount>> no_sky;
    for (size_t i = 0; i < scene.objects.size(); ++i)
      if (const auto& values = result.objects[i].values) {
        const bake::NoSkyCount count = bake::count_no_sky(*values);
        if (count.share() > 0.5) no_sky.emplace_back(scene_object_label(scene.objects[i]), count);
      }
    if (!no_sky.empty() && (no_sky.size() <= kNoSkyListed || a.verbose)) {
      for (const auto& [name, count] : no_sky)
        std::fprintf(stderr,
                     "prtbake: warning: %s: %.1f%% of its vertices (%zu of %zu) see no sky at all: it is enclosed by "
                     "other objects, or its normals point inside (check its winding)\n",
                     name.c_str(), 100 * count.share(), count.vertices, count.total);
    } else if (!no_sky.empty()) {
      std::string first;
      for (size_t k = 0; k < 3; ++k) {
        char share[32];
        std::snprintf(share, sizeof share, " (%.1f%%)", 100 * no_sky[k].second.share());
        first += (k ? ", " : "") + no_sky[k].first + share;
      }
      std::fprintf(stderr,
                   "prtbake: warning: %zu receivers have more than half their vertices seeing no sky at all (enclosed by "
                   "other objects, or normals pointing inside: check their winding): %s and %zu more (-v names each)\n",
                   no_sky.size(), first.c_str(), no_sky.size() - 3);
    }
    if (say)
      std::printf("baked %llu receiver vertices in %.2f s (setup %.2f s), FIV %.2f s (environment %.2f s)\n",
                  (unsigned long long)result.vertices, result.vertex_seconds, result.setup_seconds, result.fiv_seconds,
                  result.environment_seconds);

    write_scene(result);
    written = true;
    // Reports follow for the receivers' rows and the FIV shells when the scene asks for them.
    checks = scene.integrator.report_points > 0 &&
             std::any_of(result.objects.begin(), result.objects.end(),
                         [](const bake::ObjectBake& ob) { return ob.values.has_value() || ob.shells.has_value(); });
    if (say && checks)
      std::printf("checking its error (Ctrl-C keeps the file as written, without its reports; \"report\": 0 or --report 0 "
                  "skips the check)\n");
    std::fflush(stdout);
  };
  std::optional<bake::SceneBake> baked;
  try {
    baked = bake::bake_scene(scene, plan, meshes, env ? &*env : nullptr, progress,
                             [&](const std::string& line) {
                                                      if (say) std::printf("%s\n", line.c_str());
                                                      std::fflush(stdout);
                                                    },
                                                    merged_rows,
                                                    [&](const std::string& object, const bake::IntegratorChoice& choice,
                                                        const bake::ReferencePlan* reference_plan) {
                                                      if (say && a.verbose) {
                                                        std::printf("%s: the target-error pilot:\n", object.c_str());
                                                        for (const std::string& l : bake::choice_lines(choice))
                                                          std::printf("%s\n", l.c_str());
                                                        if (reference_plan) print_reference_plan(*reference_plan);
                                                      } else if (say) {
                                                        std::printf("%s: %s\n", object.c_str(),
                                                                    bake::choice_summary(choice).c_str());
                                                      }
                                                      std::fflush(stdout);
                                                      warn_unreached(choice, object);
                                                    });
  } catch (const bake::Cancelled&) {
    if (!written) throw;
    std::fprintf(stderr,
                 "prtbake: cancelled during the error check: %s holds the finished bake without its error reports "
                 "(--report 0 skips the check)\n",
                 a.output.c_str());
    return tool::kExitCancelled;
  }
  if (checks) write_scene(*baked);
  if (shards) shards->finish();
  return 0;
}

// prtbake allocates and frees buffers of megabytes one after another (the environment's pixels
// and tables, chunk rows, the datasets written). glibc serves each from a fresh mmap and unmaps it
// when freed, so every buffer pays its page faults again; keeping freed memory in the heap for
// the next one makes a merge ~15% cheaper in CPU time (bench/bench_shards.sh). Peak memory is
// unchanged: only memory already freed is kept.
void reuse_freed_memory() {
#ifdef __GLIBC__
  mallopt(M_MMAP_THRESHOLD, 256 << 20);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
  mallopt(M_TOP_PAD, 16 << 20);
#endif
}

int prtbake_main(int argc, char** argv) {
  reuse_freed_memory();
  const tool::MpiSession mpi(argc, argv);  // under mpirun: ranks are shard workers (shards.h)
  const std::optional<Args> parsed = parse(argc, argv, mpi);
  if (!parsed) return 0;  // --help or --version
  const Args& a = *parsed;
  tool::install_interrupt_handler();
  if (a.command == "export") return tool::run_export(a.exported);
  std::optional<tool::ShardedRows> shards;
  try {
    return a.command == "fiv"     ? run_fiv(a, mpi, shards)
           : a.command == "scene" ? run_scene(a, mpi, shards)
                                  : run_vertex(a, mpi, shards);
  } catch (const bake::Cancelled&) {
    // A sharded or resumable bake keeps what it committed: say so, and how to go on.
    if (shards)
      if (const std::optional<std::string> kept = shards->kept_after_cancel()) throw tool::CancelledKeeping(*kept);
    throw;
  }
}

} // namespace

int main(int argc, char** argv) { return tool::run_tool("prtbake", prtbake_main, argc, argv); }
