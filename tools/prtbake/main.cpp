// prtbake — bakes precomputed radiance transfer assets. A thin shell: it parses arguments (CLI11:
// one subcommand per kind of bake, each with only the options that apply to it, into the typed
// specs of libbake; args.h), reports progress and calls libbake (integration) and formats (the
// HDF5 file). This file hands the parsed command line to its command (commands.h, export.h).
#include <bake/core/progress.h>

#include "args.h"
#include "commands.h"
#include "export.h"
#include "shards.h"
#include "tool_main.h"

#ifdef __GLIBC__
#include <malloc.h>
#endif
#include <optional>
#include <string>

namespace {

using namespace prt;

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
  const std::optional<tool::Args> parsed = tool::parse(argc, argv, mpi);
  if (!parsed) return 0;  // --help or --version
  const tool::Args& a = *parsed;
  tool::install_interrupt_handler();
  if (a.command == "export") return tool::run_export(a.exported);
  std::optional<tool::ShardedRows> shards;
  try {
    return a.command == "fiv"     ? tool::run_fiv(a, mpi, shards)
           : a.command == "scene" ? tool::run_scene(a, mpi, shards)
                                  : tool::run_vertex(a, mpi, shards);
  } catch (const bake::Cancelled&) {
    // A sharded or resumable bake keeps what it committed: say so, and how to go on.
    if (shards)
      if (const std::optional<std::string> kept = shards->kept_after_cancel()) throw tool::CancelledKeeping(*kept);
    throw;
  }
}

} // namespace

int main(int argc, char** argv) { return prt::tool::run_tool("prtbake", prtbake_main, argc, argv); }
