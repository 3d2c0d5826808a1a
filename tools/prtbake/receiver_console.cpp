// tools/prtbake/receiver_console.cpp — the console and file hooks of a bake of receivers
// (commands.h ReceiverConsole), shared by prtbake vertex and texel.
#include "commands.h"
#include "output.h"
#include "tool_main.h"

#include <cstdio>
#include <utility>

namespace prt::tool {

bake::PipelineHooks ReceiverConsole::hooks(const Args& a, const RunContext& run, std::function<void()> write) {
  bake::PipelineHooks h;
  h.chosen = [&a, &run](const bake::BakeJob& j) {
    if (run.say && a.verbose)
      for (const std::string& line : bake::choice_lines(*j.choice)) std::printf("%s\n", line.c_str());
    else if (run.say)
      std::printf("%s\n", bake::choice_summary(*j.choice).c_str());
    warn_unreached(*j.choice, "");
  };
  h.ready = [&a, &run](const bake::BakeJob& j) {
    if (run.say) print_baking(a, j, run.threads);
  };
  h.baked = [this, write] {
    write();
    written = true;
    rebaking = false;
  };
  h.checking = [&run] {
    if (run.say)
      std::printf("checking its error (Ctrl-C keeps the file as written, without its report; --report 0 skips the check)\n");
  };
  h.check_planned = [&a, &run](const bake::BakeJob& j) {
    if (run.say && a.verbose) print_reference_plan(*j.reference_plan);
  };
  h.set_checked = [&run](const bake::BakeJob& j, size_t) {
    if (run.say) print_error_report(j);
  };
  h.job_checked = [&a, &run, write](const bake::BakeJob& j) {
    if (run.say) print_error_verdict(j, a.target_error);
    write();
  };
  h.correcting = [this, &run](const bake::BakeJob& j, const bake::IntegratorSpec& better) {
    rebaking = true;
    if (run.say) print_correction(j, better);
  };
  return h;
}

int ReceiverConsole::run(const Args& a, const RunContext& run, bake::BakePipeline& pipeline, bake::PipelineHooks& hooks,
                         std::optional<ShardedRows>& shards, std::vector<std::string> manifest_lines) {
  try {
    pipeline.plan(run.progress, hooks);
    if (a.worker) {
      // Every worker computes chunks of the rows; the merging process reads them back. The
      // manifest names the plan, so that chunks of another plan are refused.
      const bake::BakeJob& job = pipeline.jobs().front();
      const std::vector<bake::ShadePoint>& points = job.sets.front().points;
      const bake::IntegratorSpec& spec = job.spec;
      const uint32_t width = uint32_t(job.integrator->layout().width);
      for (std::string line : {job.integrator_description, std::string(bake::to_string(spec.kind)),
                               std::to_string(spec.samples()), std::to_string(spec.seed), std::to_string(width),
                               std::to_string(a.shard.chunk_rows)})
        manifest_lines.push_back(std::move(line));
      shards.emplace(*a.worker, run.mpi, a.shard, a.output, tool::manifest_of(manifest_lines),
                     std::vector<uint64_t>{points.size()}, std::vector<uint32_t>{width}, a.quiet);
      bake::PipelineHooks work;
      work.rows_only = true;
      work.rows = [&](const bake::BakeJob& j, size_t, const bake::Monitor&) {
        shards->work([&](const bake::ChunkRange& r, const bake::Monitor& monitor) {
          return tool::bake_chunk(points, r, *j.integrator, monitor);
        });
        return bake::VertexBake{};
      };
      if (!shards->run([&] { pipeline.run(run.progress, work); })) return 0;
      hooks.rows = [&](const bake::BakeJob& j, size_t, const bake::Monitor&) {
        return shards->merge(0, j.integrator->layout());
      };
    }
    pipeline.run(run.progress, hooks);
  } catch (const bake::Cancelled&) {
    if (!written) throw;  // nothing written yet
    if (rebaking)
      std::fprintf(stderr, "prtbake: cancelled while baking again: %s holds the first bake and its error report\n",
                   a.output.c_str());
    else
      std::fprintf(stderr,
                   "prtbake: cancelled during the error check: %s holds the finished bake without its error report "
                   "(--report 0 skips the check)\n",
                   a.output.c_str());
    return tool::kExitCancelled;
  }
  if (shards) shards->finish();
  return 0;
}

} // namespace prt::tool
