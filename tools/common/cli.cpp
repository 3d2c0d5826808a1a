#include "cli.h"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <functional>
#include <limits>
#include <numeric>
#include <utility>

namespace prt::tool {

namespace {

std::string in_quotes(std::string_view s) { return "'" + std::string(s) + "'"; }

std::string range_text(int64_t lo, int64_t hi) {
  if (lo == 0 && hi == std::numeric_limits<int64_t>::max()) return "an integer >= 0";
  return std::to_string(lo) + " to " + std::to_string(hi);
}

std::string range_text(double lo, double hi) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%g to %g", lo, hi);
  return buf;
}

} // namespace

CLI::Validator integer_in(int64_t lo, int64_t hi) {
  return CLI::Validator(
      [lo, hi](std::string& s) -> std::string {
        // An optional sign and decimal digits, all of the text (from_chars alone accepts "12abc").
        std::string_view digits = s;
        if (!digits.empty() && digits.front() == '+') digits.remove_prefix(1);
        int64_t v = 0;
        const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), v);
        if (digits.empty() || end != digits.data() + digits.size() || ec == std::errc::invalid_argument)
          return in_quotes(s) + " is not an integer (expects " + range_text(lo, hi) + ")";
        if (ec == std::errc::result_out_of_range || v < lo || v > hi)
          return s + " is out of range (expects " + range_text(lo, hi) + ")";
        return "";
      },
      "");
}

namespace {
// A number check: `inside` decides the range, `range` says it.
CLI::Validator number_check(std::function<bool(double)> inside, std::string range) {
  return CLI::Validator(
      [inside = std::move(inside), range = std::move(range)](std::string& s) -> std::string {
        double v = 0;
        const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
        if (s.empty() || end != s.data() + s.size() || ec == std::errc::invalid_argument)
          return in_quotes(s) + " is not a number (expects " + range + ")";
        if (ec == std::errc::result_out_of_range || !inside(v)) return s + " is out of range (expects " + range + ")";
        return "";
      },
      "");
}
} // namespace

CLI::Validator number_in(double lo, double hi) {
  return number_check([lo, hi](double v) { return v >= lo && v <= hi; }, range_text(lo, hi));
}

CLI::Validator number_between(double lo, double hi) {
  return number_check([lo, hi](double v) { return v > lo && v < hi; },
                      "a number strictly between " + range_text(lo, hi).replace(range_text(lo, hi).find(" to "), 4, " and "));
}

size_t edit_distance(std::string_view a, std::string_view b) {
  // d[i][j]: the distance between a's first i and b's first j characters (three rows kept).
  std::vector<size_t> before(b.size() + 1), prev(b.size() + 1), cur(b.size() + 1);
  std::iota(prev.begin(), prev.end(), size_t(0));
  for (size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t substitute = prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, substitute});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) cur[j] = std::min(cur[j], before[j - 2] + 1);
    }
    std::swap(before, prev);
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

std::optional<std::string> closest(std::string_view word, const std::vector<std::string>& names) {
  const auto bare = [](std::string_view s) {
    while (!s.empty() && s.front() == '-') s.remove_prefix(1);
    return s;
  };
  const std::string_view w = bare(word);
  if (w.empty()) return std::nullopt;
  const size_t limit = std::max<size_t>(1, w.size() / 3);
  std::optional<std::string> best;
  size_t best_distance = limit + 1;
  for (const std::string& n : names) {
    const size_t d = edit_distance(w, bare(n));
    if (d < best_distance) best = n, best_distance = d;
  }
  if (best) return best;
  // One name sharing a prefix of at least 3 characters with the word, whole (--environment for --env).
  std::vector<std::string> prefixed;
  for (const std::string& n : names) {
    const std::string_view b = bare(n);
    const std::string_view shorter = b.size() < w.size() ? b : w, longer = b.size() < w.size() ? w : b;
    if (shorter.size() >= 3 && longer.substr(0, shorter.size()) == shorter) prefixed.push_back(n);
  }
  if (prefixed.size() == 1) return prefixed.front();
  return std::nullopt;
}

namespace {

// Every name of every option of `cmd`: "--radiance", "-o", ...
std::vector<std::string> option_names(const CLI::App& cmd) {
  std::vector<std::string> names;
  for (const CLI::Option* o : cmd.get_options()) {
    for (const std::string& l : o->get_lnames()) names.push_back("--" + l);
    for (const std::string& s : o->get_snames()) names.push_back("-" + s);
  }
  return names;
}

bool is_option_token(const std::string& t) {
  if (t.size() < 2 || t.front() != '-') return false;
  double number = 0;  // "-1" is a (wrong) value, not an option
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), number);
  return !(ec == std::errc() && end == t.data() + t.size());
}

// "--radiancee=x.exr" → "--radiancee".
std::string option_name(const std::string& token) {
  const size_t eq = token.rfind("--", 0) == 0 ? token.find('=') : std::string::npos;
  return eq == std::string::npos ? token : token.substr(0, eq);
}

std::string command_list(const std::vector<Command>& commands) {
  std::string s;
  for (size_t i = 0; i < commands.size(); ++i)
    s += std::string(i == 0 ? "" : i + 1 == commands.size() ? " and " : ", ") + commands[i].name;
  return s;
}

// The subcommands of `app` (other than `except`) that have an option named `name`.
std::vector<std::string> commands_with(const CLI::App& app, const std::string& name, const CLI::App* except) {
  std::vector<std::string> out;
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
    if (sub == except) continue;
    const std::vector<std::string> names = option_names(*sub);
    if (std::find(names.begin(), names.end(), name) != names.end()) out.push_back(sub->get_name());
  }
  return out;
}

std::string unknown_option(const CLI::App& app, const CLI::App* cmd, const std::string& token, std::string_view tool) {
  const std::string name = option_name(token);
  const CLI::App& owner = cmd ? *cmd : app;
  std::string m = "unknown option " + in_quotes(name);
  if (const auto near = closest(name, option_names(owner)); near && *near != "--help" && *near != "-h")
    return m + "; did you mean " + *near + "?";
  const std::vector<std::string> elsewhere = commands_with(app, name, cmd);
  if (!elsewhere.empty()) {
    std::string which;
    for (size_t i = 0; i < elsewhere.size(); ++i) which += (i ? ", " : "") + std::string(tool) + " " + elsewhere[i];
    return m + (cmd ? " (it is an option of " : " (it is an option of a command: ") + which + ")";
  }
  return m;
}

} // namespace

std::string usage_message(const CLI::App& app, const CLI::ParseError& error, std::string_view tool,
                          const std::vector<Command>& commands) {
  const std::vector<CLI::App*> given = app.get_subcommands();
  const CLI::App* cmd = given.empty() ? nullptr : given.front();
  const std::string prefix = cmd ? cmd->get_name() + ": " : "";
  // What CLI11 could not place, in the order typed (its list holds the tool's and the command's).
  std::vector<std::string> left = app.remaining(true);
  std::vector<std::string> options, others;
  for (const std::string& t : left) (is_option_token(t) ? options : others).push_back(t);
  if (!commands.empty() && !cmd) {
    if (!others.empty()) {
      std::string m = "unknown command " + in_quotes(others.front());
      std::vector<std::string> names;
      for (const Command& c : commands) names.push_back(c.name);
      if (const auto near = closest(others.front(), names)) m += "; did you mean '" + *near + "'?";
      return m + (m.find("did you mean") == std::string::npos ? ": the commands are " + command_list(commands)
                                                               : " (the commands are " + command_list(commands) + ")");
    }
    if (!options.empty()) return unknown_option(app, nullptr, options.front(), tool);
    return "no command given (the commands are " + command_list(commands) + ")";
  }
  if (!options.empty()) return prefix + unknown_option(app, cmd, options.front(), tool);
  if (!others.empty()) return prefix + "unexpected argument " + in_quotes(others.front());
  // An option given twice, perhaps by two of its names (--radiance and --env), or without its value.
  const std::string what = error.what();
  if (dynamic_cast<const CLI::ArgumentMismatch*>(&error) && what.find(" missing") != std::string::npos) {
    const std::string name = what.substr(0, what.find(':'));
    for (const CLI::Option* o : (cmd ? *cmd : app).get_options())
      if (o->check_name(name))
        return prefix + name + " needs a value" +
               (o->get_option_text().empty() ? std::string() : " (" + name + " " + o->get_option_text() + ")");
  }
  if (dynamic_cast<const CLI::ArgumentMismatch*>(&error) && what.find("At Most 1 required") != std::string::npos) {
    const std::string name = what.substr(0, what.find(':'));
    for (const CLI::Option* o : (cmd ? *cmd : app).get_options())
      if (o->check_name(name)) {
        std::string names;
        for (const std::string& l : o->get_lnames()) names += (names.empty() ? "--" : " or --") + l;
        return prefix + names + " given more than once: it takes one value";
      }
  }
  return prefix + what;
}

std::string shell_command(int argc, const char* const* argv) {
  std::string line;
  for (int i = 0; i < argc; ++i) {
    const std::string a = argv[i];
    const bool plain = !a.empty() && a.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                                         "0123456789-_./=:,+@%") == std::string::npos;
    if (i) line += ' ';
    if (plain) {
      line += a;
      continue;
    }
    line += '\'';
    for (char c : a) line += c == '\'' ? std::string("'\\''") : std::string(1, c);
    line += '\'';
  }
  return line;
}

} // namespace prt::tool
