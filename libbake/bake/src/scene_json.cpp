// scene_json.cpp — strict JSON parsing for scene and options files (scene_json.h).
#include "scene_json.h"

#include <fstream>
#include <set>
#include <vector>

namespace prt::bake::scene_json {
namespace {

constexpr size_t kMaxDepth = 128;  // nesting deeper than this is refused

// "objects[2].material" for the value at that path; "the scene" for the root.
std::string shown_path(const std::string& path) { return path.empty() ? "the scene" : path; }

// Parses a scene file strictly: nlohmann's RFC 8259 parser (syntax errors with line and column),
// and what it lets through refused here with the key path: a duplicate key (nlohmann keeps the
// last one silently) and nesting deeper than kMaxDepth.
Json parse_json(const std::string& text, const std::string& file) {
  struct Container {
    std::string path;
    bool object = false;
    std::set<std::string> keys;
    std::string key;    // object: the member being read
    size_t index = 0;   // array: the next element's index
  };
  std::vector<Container> open;
  auto child_path = [&]() -> std::string {
    if (open.empty()) return "";
    Container& c = open.back();
    if (c.object) return (c.path.empty() ? "" : c.path + ".") + c.key;
    return c.path + "[" + std::to_string(c.index++) + "]";
  };
  const Json::parser_callback_t strict = [&](int, Json::parse_event_t event, Json& parsed) {
    switch (event) {
    case Json::parse_event_t::object_start:
    case Json::parse_event_t::array_start: {
      std::string path = child_path();
      if (open.size() >= kMaxDepth)
        throw InputError(file, (path.size() > 60 ? path.substr(0, 60) + "..." : path) + " is nested deeper than " +
                                   std::to_string(kMaxDepth) + " levels");
      open.push_back({std::move(path), event == Json::parse_event_t::object_start, {}, {}, 0});
      break;
    }
    case Json::parse_event_t::key: {
      Container& c = open.back();
      c.key = parsed.get<std::string>();
      if (!c.keys.insert(c.key).second)
        throw InputError(file, "duplicate key \"" + c.key + "\" in " + shown_path(c.path));
      break;
    }
    case Json::parse_event_t::object_end:
    case Json::parse_event_t::array_end: open.pop_back(); break;
    case Json::parse_event_t::value:
      if (!open.empty() && !open.back().object) ++open.back().index;
      break;
    }
    return true;
  };
  try {
    return Json::parse(text, strict);
  } catch (const Json::parse_error& e) {
    // e.byte counts the bytes read up to and including the one in error (1-based).
    const size_t at = std::min(text.size(), e.byte > 0 ? size_t(e.byte - 1) : size_t(0));
    const size_t line_start = text.rfind('\n', at == 0 ? std::string::npos : at - 1);
    const size_t line = 1 + size_t(std::count(text.begin(), text.begin() + std::ptrdiff_t(at), '\n'));
    const size_t column = at - (line_start == std::string::npos ? 0 : line_start + 1) + 1;
    std::string what = e.what();  // "[json.exception.parse_error.101] parse error at line L, column C: <problem>"
    const size_t colon = what.find(": ");
    if (colon != std::string::npos) what = what.substr(colon + 2);
    throw InputError(file, "line " + std::to_string(line) + ", column " + std::to_string(column) + ": " + what);
  } catch (const Json::exception& e) {  // e.g. a number too large for a double ("1e400")
    std::string what = e.what();
    const size_t bracket = what.find("] ");
    throw InputError(file, bracket == std::string::npos ? what : what.substr(bracket + 2));
  }
}

// A scene or options file lists objects and settings: 16 MiB is far beyond any real one (about
// 200 bytes an object). Read up to one byte more, so a pipe or a device (/dev/zero) is refused at
// the limit, not read forever. The parsed tree takes at most ~32 bytes per byte of text (a 16-byte
// value, its heap block and vector growth for "[]," or "0,"): 512 MiB at the limit. Running out of
// memory inside the JSON library cannot be reported (it allocates while destroying a partial
// tree, and terminates); this bound is what keeps that away.
constexpr size_t kMaxJsonFileBytes = size_t{16} << 20;

Json read_json_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "cannot open the file");
  std::string text;
  for (char buffer[65536]; text.size() <= kMaxJsonFileBytes && in;) {
    in.read(buffer, sizeof buffer);
    text.append(buffer, static_cast<size_t>(in.gcount()));
  }
  if (in.bad()) throw InputError(file.string(), "cannot read the file");
  if (text.size() > kMaxJsonFileBytes)
    throw InputError(file.string(), "larger than " + std::to_string(kMaxJsonFileBytes >> 20) + " MiB; a scene file is not that large");
  return parse_json(text, file.string());
}

} // namespace

Json parse_json_file(const std::filesystem::path& file) {
  return reading_file(file.string(), [&] { return read_json_file(file); });
}

} // namespace prt::bake::scene_json
