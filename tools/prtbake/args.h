// tools/prtbake/args.h — prtbake's command line: one subcommand per kind of bake (CLI11), each
// with only the options that apply to it, parsed and checked into the typed specs of libbake
// before any input is read (a mistake is exit 2: tool_main.h). The help texts live in args.cpp.
#pragma once

#include <bake/bake/fiv.h>
#include <bake/bake/lightmap_receivers.h>
#include <bake/environment/envmap.h>
#include <bake/integrators/integrator.h>

#include "export.h"
#include "shards.h"

#include <optional>
#include <string>
#include <vector>

namespace prt::tool {

struct Args {
  std::string command;      // vertex, texel, fiv, scene or export
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
  // texel: the lightmap's texels (--resolution W[xH]; 0 x 0: chosen from --density, texels per
  // unit), the UV set (--uv; empty: the default rule of run_texel.cpp), generated UVs (--unwrap,
  // or the mesh has none: bake/mesh/unwrap.h, with --gutter texels between charts) and the gutter
  // rings (--padding); --no-stitch leaves the texels along UV seams as baked (bake/bake/lightmap.h
  // stitch_seams).
  uint32_t lightmap_width = 0, lightmap_height = 0;
  double lightmap_density = 0;
  std::string uv_set;
  bool unwrap = false;
  uint32_t gutter = 2;
  uint32_t min_chart_texels = bake::LightmapSpec{}.min_chart_texels;  // --min-chart-texels (bake/mesh/unwrap.h)
  uint32_t padding = bake::kDefaultPadding;
  bool no_stitch = false;
  int threads = 0;            // 0: all cores
  bake::UpAxis up = bake::UpAxis::Y;
  bool file_normals = true, quiet = false, reproducible = false, dry_run = false;
  bool verbose = false;  // vertex: the pilot's whole table, not its one-line summary
  bool flip_normals = false;  // vertex: reverse every triangle and file normal
  double target_error = 0;    // vertex: --target-error E (0: not given; bake/bake/choose.h)
  // vertex: interreflections of the diffuse transfer (bake/bake/bounce.h): --bounces B, --albedo
  // (grey in this version: one value, or R = G = B; empty: not given) and --bounce-rays K.
  int bounces = 0;
  std::vector<double> albedo;
  uint32_t bounce_rays = 0;  // 0: not given (bake::BounceSpec::kDefaultRays)
  bool integrator_given = false;  // vertex: --integrator was given (the chooser then keeps its kind)
  std::string command_line;  // what determines the file's contents (no --threads/--quiet)
  tool::ExportArgs exported;  // export: a baked file in another format (export.h)
  tool::ShardOptions shard;   // vertex, fiv, scene: sharded and resumable bakes (shards.h)
  std::optional<tool::Worker> worker;  // who this process is in a sharded bake (nullopt: not sharded)
};

// Parses and checks the command line; nullopt when it asked for help or the version (printed).
// Throws UsageError for a mistake. Under mpirun (`mpi` active) a bake is a sharded one.
std::optional<Args> parse(int argc, char** argv, const MpiSession& mpi);

} // namespace prt::tool
