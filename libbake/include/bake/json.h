// bake/json.h — a small strict JSON reader (RFC 8259) for scene files (bake/scene.h).
//
// Strict: one value, UTF-8 text, no comments, no trailing commas, no duplicate object keys, the
// number grammar of RFC 8259 §6 (converted with std::from_chars, so "1e400" is an error, not Inf),
// \uXXXX escapes with surrogate pairs, nesting depth ≤ 128. Errors throw InputError(file,
// "line L, column C: what is wrong") — the column counts bytes from 1.
// Objects keep their key order (a vector of members), so messages and files follow the user's order.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace prt::bake::json {

struct Value;
using Array = std::vector<Value>;
using Object = std::vector<std::pair<std::string, Value>>;

struct Value {
  std::variant<std::nullptr_t, bool, double, std::string, std::shared_ptr<Array>, std::shared_ptr<Object>> v;
  int line = 0, column = 0;  // where the value starts in the text

  bool is_null() const { return v.index() == 0; }
  bool is_bool() const { return v.index() == 1; }
  bool is_number() const { return v.index() == 2; }
  bool is_string() const { return v.index() == 3; }
  bool is_array() const { return v.index() == 4; }
  bool is_object() const { return v.index() == 5; }
  const Array& array() const { return *std::get<4>(v); }
  const Object& object() const { return *std::get<5>(v); }
  // Member of an object, nullptr if absent (the value must be an object).
  const Value* find(std::string_view key) const;
  // "object", "array", "string", "number", "true/false", "null"
  const char* type_name() const;
};

// Parses `text`; `file` names the source in error messages.
Value parse(std::string_view text, const std::filesystem::path& file);
// Reads and parses a file (InputError if it cannot be read).
Value parse_file(const std::filesystem::path& file);

} // namespace prt::bake::json
