// tools/prtbake/commands.h — prtbake's bake commands (vertex, fiv, scene; export is export.h) and
// the run they share. prtbake_main (main.cpp) parses the command line (args.h), begins the run
// once, and calls the command's run_*; each returns the exit code (tool_main.h) or throws.
#pragma once

#include <bake/bake/pipeline.h>
#include <bake/core/progress.h>

#include "args.h"
#include "progress_bar.h"
#include "shards.h"

#include <tbb/global_control.h>

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace prt::tool {

// What every bake sets up before it reads an input, once: the output's directory is checked
// (InputError before a long bake rather than at its end; scene --dry-run writes nothing), the
// thread limit (--threads) holds until the command returns, and libbake's stages report their
// progress to one bar on stderr and are cancelled by Ctrl-C. Neither copied nor moved:
// `progress` draws on `bar`.
struct RunContext {
  RunContext(const Args& a, const MpiSession& mpi);

  const MpiSession& mpi;
  const bool say;     // print what the bake does: not --quiet, and rank 0 (under mpirun it speaks for all)
  const int threads;  // --threads, or all cores
  const tbb::global_control threads_limit;
  const ProgressBar bar;          // quiet unless `say`
  const bake::Monitor progress;  // bar's, with tool::interrupt_token()
};

// The console and the file of a bake of receivers (vertex, texel; bake/bake/pipeline.h): hooks()
// prints the choice, the products and integrator, the check and its verdict and the correction,
// and writes the file (`write`) once the bake is whole and again with its report, so a check
// cancelled with Ctrl-C, or one that costs more than the user will wait, never costs the bake.
// `written` and `rebaking` say what the file holds when a Ctrl-C comes. The hooks refer to this
// object: it must outlive the pipeline's run. A command adds its own `set_baked`.
struct ReceiverConsole {
  bool written = false;   // the file holds a bake
  bool rebaking = false;  // a correction's rows are being made (the file holds the first bake and its report)
  bake::PipelineHooks hooks(const Args& a, const RunContext& run, std::function<void()> write);
  // Runs the pipeline's one job over its one receiver set with `hooks`; when this process is a
  // shard worker (a.worker), its rows first go to chunks (shards.h) under a manifest of
  // `manifest_lines` (what the rows depend on; the plan's integrator, samples, seed, width and the
  // chunk rows are added), and only the merging process goes on, its rows read back from them.
  // Ctrl-C after the file was first written keeps it (exit 130, saying what it holds); before,
  // Cancelled propagates. Returns the exit code.
  int run(const Args& a, const RunContext& run, bake::BakePipeline& pipeline, bake::PipelineHooks& hooks,
          std::optional<ShardedRows>& shards, std::vector<std::string> manifest_lines);
};

// The bakes. `shards`: emplaced when the bake is sharded, so that prtbake_main can report its
// committed chunks on Ctrl-C (ShardedRows::kept_after_cancel).
int run_vertex(const Args& a, const RunContext& run, std::optional<ShardedRows>& shards);
int run_texel(const Args& a, const RunContext& run, std::optional<ShardedRows>& shards);
int run_fiv(const Args& a, const RunContext& run, std::optional<ShardedRows>& shards);
int run_scene(const Args& a, const RunContext& run, std::optional<ShardedRows>& shards);

} // namespace prt::tool
