// tools/prtbake/receiver_console.cpp — the console and file hooks of a bake of receivers
// (commands.h ReceiverConsole), shared by prtbake vertex and texel.
#include "commands.h"
#include "output.h"

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

} // namespace prt::tool
