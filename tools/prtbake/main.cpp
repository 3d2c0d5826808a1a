// prtbake — bakes precomputed radiance transfer assets. A thin shell: it parses arguments (CLI11:
// one subcommand per kind of bake, each with only the options that apply to it, into the typed
// specs of libbake; args.h), reports progress and calls libbake (integration) and formats (the
// HDF5 file). This file begins a run and hands it to its command (commands.h, export.h).
#include <bake/core/error.h>

#include "args.h"
#include "commands.h"
#include "export.h"
#include "shards.h"
#include "tool_main.h"

#include <tbb/info.h>

#include <filesystem>
#ifdef __GLIBC__
#include <malloc.h>
#endif
#include <optional>
#include <string>
#include <unistd.h>

namespace fs = std::filesystem;

namespace prt::tool {
namespace {

// Fails early (before a long bake) if the output's directory cannot take a file.
void check_output_writable(const fs::path& out) {
  const fs::path dir = out.has_parent_path() ? out.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw bake::InputError(out.string(), "cannot write: directory '" + dir.string() + "' does not exist");
  if (fs::is_directory(out, ec)) throw bake::InputError(out.string(), "cannot write: it is a directory");
  if (access(dir.c_str(), W_OK) != 0) throw bake::InputError(out.string(), "cannot write: directory '" + dir.string() + "' is not writable");
}

} // namespace

RunContext::RunContext(const Args& a, const MpiSession& session)
    : mpi(session),
      say(!a.quiet && session.rank() == 0),
      threads(a.threads > 0 ? a.threads : tbb::info::default_concurrency()),
      threads_limit(tbb::global_control::max_allowed_parallelism, size_t(threads)),
      bar(say ? ProgressStyle::Auto : ProgressStyle::Quiet),
      progress(bar.monitor(&interrupt_token())) {
  if (!a.dry_run) check_output_writable(a.output);  // scene --dry-run writes nothing
}

} // namespace prt::tool

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
  const tool::RunContext run(a, mpi);  // the thread limit and the progress bar, until the command returns
  try {
    return a.command == "fiv"     ? tool::run_fiv(a, run, shards)
           : a.command == "scene" ? tool::run_scene(a, run, shards)
           : a.command == "texel" ? tool::run_texel(a, run, shards)
                                  : tool::run_vertex(a, run, shards);
  } catch (const bake::Cancelled&) {
    // A sharded or resumable bake keeps what it committed: say so, and how to go on.
    if (shards)
      if (const std::optional<std::string> kept = shards->kept_after_cancel()) throw tool::CancelledKeeping(*kept);
    throw;
  }
}

} // namespace

int main(int argc, char** argv) { return prt::tool::run_tool("prtbake", prtbake_main, argc, argv); }
