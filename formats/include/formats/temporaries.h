// formats/temporaries.h — names of the temporary files and directories that make outputs appear
// whole (the HDF5 writer's "<name>.tmp.<host>.<pid>", the exporters' ".<name>.export.<host>.<pid>/",
// exports/export.h), and the removal of those a killed process on this machine left behind.
// Shared by the writers of baked files and of exports; not meant for engines.
#pragma once

#include <filesystem>
#include <string>

namespace prt::formats {

// This machine's name as it goes into temporary names: [A-Za-z0-9._-] only ("host" if none).
std::string host_tag();

// "<prefix><pid>" for this process: the name of a temporary whose owner can be told alive or dead.
std::string temporary_name(const std::string& prefix);

// Removes the entries of `dir` named "<prefix><pid>" (files, or directories with what they hold)
// whose pid is not alive: a process on THIS machine left them when it was killed (kill -9, power
// loss). The prefix must name the host (host_tag) so that other machines' temporaries on a shared
// disk are left alone; so are live pids (or ones we may not signal), this process's own, and
// anything else in the directory. Best effort: an entry that cannot be removed stays.
void remove_stale_temporaries(const std::filesystem::path& dir, const std::string& prefix);

} // namespace prt::formats
