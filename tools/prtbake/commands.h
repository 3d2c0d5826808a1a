// tools/prtbake/commands.h — prtbake's bake commands (vertex, fiv, scene; export is export.h).
// prtbake_main (main.cpp) parses the command line (args.h) and calls the command's run_*; each
// returns the exit code (tool_main.h) or throws.
#pragma once

#include "args.h"
#include "shards.h"

#include <optional>

namespace prt::tool {

// The bakes. `shards`: emplaced when the bake is sharded, so that prtbake_main can report its
// committed chunks on Ctrl-C (ShardedRows::kept_after_cancel).
int run_vertex(const Args& a, const MpiSession& mpi, std::optional<ShardedRows>& shards);
int run_fiv(const Args& a, const MpiSession& mpi, std::optional<ShardedRows>& shards);
int run_scene(const Args& a, const MpiSession& mpi, std::optional<ShardedRows>& shards);

} // namespace prt::tool
