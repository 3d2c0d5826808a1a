// scene_json.h — strict JSON for scene files and glTF options files (bake/bake/scene.h): nlohmann's
// RFC 8259 parser plus the checks it leaves out (duplicate keys, nesting depth, file size), and a
// reader of typed members whose errors name the file and the key path. Private to the bake module.
#pragma once

#include <bake/core/error.h>

#include <nlohmann/json.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <sstream>
#include <string>
#include <string_view>

namespace prt::bake::scene_json {

using Json = nlohmann::ordered_json;  // keeps the file's key order, so messages follow it

// The file parsed strictly (InputError naming the file, with line and column or the key path);
// files over 16 MiB are refused before they are parsed.
Json parse_json_file(const std::filesystem::path& file);

// An object's member, nullptr if absent.
inline const Json* find_key(const Json& object, const char* key) {
  const auto it = object.find(key);
  return it == object.end() ? nullptr : &*it;
}

// Reads typed members with messages that name the file and the key path.
class Reader {
public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& what) const { throw InputError(file_, what); }

  const Json& object(const Json& v, const std::string& key_path, std::initializer_list<std::string_view> allowed) const {
    if (!v.is_object()) fail(key_path + " must be an object, not " + v.type_name());
    for (const auto& [k, member] : v.items()) {
      bool ok = false;
      for (std::string_view a : allowed) ok = ok || k == a;
      if (!ok) {
        std::string list;
        for (std::string_view a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
        fail("unknown key \"" + k + "\" in " + key_path + " (allowed: " + list + ")");
      }
    }
    return v;
  }

  double number(const Json& v, const std::string& key, double lo, double hi) const {
    if (!v.is_number()) fail(key + " must be a number, not " + v.type_name());
    const double x = v.get<double>();
    if (!(x >= lo && x <= hi)) {
      std::ostringstream os;
      os << key << " must be in [" << lo << ", " << hi << "], got " << x;
      fail(os.str());
    }
    return x;
  }

  int64_t integer(const Json& v, const std::string& key, int64_t lo, int64_t hi) const {
    const double x = number(v, key, double(lo), double(hi));
    if (x != std::floor(x)) fail(key + " must be an integer");
    return int64_t(x);
  }

  const std::string& string(const Json& v, const std::string& key) const {
    if (!v.is_string()) fail(key + " must be a string, not " + v.type_name());
    const std::string& s = v.get_ref<const std::string&>();
    if (s.empty()) fail(key + " must not be empty");
    return s;
  }

  bool boolean(const Json& v, const std::string& key) const {
    if (!v.is_boolean()) fail(key + " must be true or false, not " + v.type_name());
    return v.get<bool>();
  }

  std::array<double, 3> vec3(const Json& v, const std::string& key, double lo, double hi) const {
    if (!v.is_array() || v.size() != 3) fail(key + " must be an array of 3 numbers");
    std::array<double, 3> out{};
    for (size_t i = 0; i < 3; ++i) out[i] = number(v[i], key + "[" + std::to_string(i) + "]", lo, hi);
    return out;
  }

private:
  std::string file_;
};

} // namespace prt::bake::scene_json
