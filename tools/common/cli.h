// tools/common/cli.h — what the tools add to CLI11 (the parser): number checks that say what is
// wrong with a value, and the one-line usage messages for what CLI11 rejects, with a "did you
// mean" for an unknown command or option. CLI11 parses; this file only words its errors.
//
//   integer_in(lo, hi)   a check for an integer option: "'abc' is not an integer", "0 is out of
//                        range (1 to 16777216)"; CLI11 names the option ("--samples: ...").
//   number_in(lo, hi)    the same for a real number.
//   usage_message(...)   the message for a failed parse: the unknown command or option first
//                        (whatever else CLI11 found missing), with the closest known name.
//   closest(word, names) the suggestion itself: the name nearest `word` in edit distance
//                        (insertions, deletions, substitutions and swaps of two neighbours),
//                        when it is near enough to be a typo.
#pragma once

#include <CLI/CLI.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace prt::tool {

CLI::Validator integer_in(int64_t lo, int64_t hi);
CLI::Validator number_in(double lo, double hi);
// A real number strictly between lo and hi.
CLI::Validator number_between(double lo, double hi);

// Optimal string alignment distance between a and b.
size_t edit_distance(std::string_view a, std::string_view b);

// The name in `names` nearest to `word`, if at most max(1, |word| / 3) edits away (ties: the
// first), or else the one name `word` is a prefix of, or that is a prefix of `word` (at least 3
// characters in common; --environment → --env).
std::optional<std::string> closest(std::string_view word, const std::vector<std::string>& names);

// A command of a tool with subcommands, and its one-line summary (the top-level help's list).
struct Command {
  const char* name;
  const char* summary;
};

// The message for a command line `app` failed to parse with `error`: an unknown command (when
// `commands` is not empty and none was given), an unknown option or an unexpected argument of the
// command given, each with a suggestion; otherwise CLI11's own message. `tool`: "prtbake".
std::string usage_message(const CLI::App& app, const CLI::ParseError& error, std::string_view tool,
                          const std::vector<Command>& commands = {});

// "a 'b c' 'd'\''e'": arguments as a POSIX shell reads them back (the command to rerun).
std::string shell_command(int argc, const char* const* argv);

} // namespace prt::tool
