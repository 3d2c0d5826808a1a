// A glTF 2.0 document built in a test (tests of the glTF reader and of glTF scenes): one binary
// buffer, one buffer view per accessor, written with the buffer as a data URI, or as a .glb.
#pragma once

#include <mesh_files.h>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace prt::testing {

using json = nlohmann::json;

inline std::string base64(const std::string& bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    uint32_t v = static_cast<uint8_t>(bytes[i]) << 16;
    if (i + 1 < bytes.size()) v |= static_cast<uint8_t>(bytes[i + 1]) << 8;
    if (i + 2 < bytes.size()) v |= static_cast<uint8_t>(bytes[i + 2]);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? kAlphabet[(v >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? kAlphabet[v & 63] : '=';
  }
  return out;
}

// A glTF under construction: one binary buffer, one buffer view per accessor.
struct Gltf {
  std::filesystem::path dir = test_dir("gltf");  // where write() puts files
  json doc = {{"asset", {{"version", "2.0"}}}, {"scene", 0}, {"scenes", {{{"nodes", json::array()}}}},
              {"nodes", json::array()}, {"meshes", json::array()}, {"accessors", json::array()},
              {"bufferViews", json::array()}, {"buffers", json::array()}};
  std::string bin;

  template <class T>
  int accessor(const std::vector<T>& values, int component_type, const char* type, size_t count) {
    while (bin.size() % 4) bin += '\0';
    const size_t offset = bin.size();
    bin.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
    doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", values.size() * sizeof(T)}});
    doc["accessors"].push_back({{"bufferView", doc["bufferViews"].size() - 1}, {"componentType", component_type}, {"type", type}, {"count", count}});
    return static_cast<int>(doc["accessors"].size() - 1);
  }
  int vec3(const std::vector<Eigen::Vector3f>& v) {
    std::vector<float> flat;
    for (const auto& p : v) flat.insert(flat.end(), {p.x(), p.y(), p.z()});
    return accessor(flat, 5126, "VEC3", v.size());
  }
  int indices(const std::vector<uint16_t>& i) { return accessor(i, 5123, "SCALAR", i.size()); }
  // A mesh of one primitive; returns its index.
  int mesh(json primitive) {
    doc["meshes"].push_back({{"primitives", {std::move(primitive)}}});
    return static_cast<int>(doc["meshes"].size() - 1);
  }
  int node(json n, bool root) {
    doc["nodes"].push_back(std::move(n));
    const int index = static_cast<int>(doc["nodes"].size() - 1);
    if (root) doc["scenes"][0]["nodes"].push_back(index);
    return index;
  }
  // The document with the buffer embedded as a data URI.
  std::string embedded() const {
    json d = doc;
    d["buffers"] = {{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin)}}};
    return d.dump();
  }
  // Written (embedded buffer) to dir/name.
  std::filesystem::path write(const std::string& name) const { return write_test_file(dir, name, embedded()); }
  // A .glb: 12-byte header, JSON chunk (space-padded), BIN chunk (zero-padded).
  std::string glb() const {
    json d = doc;
    d["buffers"] = {{{"byteLength", bin.size()}}};
    std::string j = d.dump(), b = bin;
    while (j.size() % 4) j += ' ';
    while (b.size() % 4) b += '\0';
    std::string out;
    auto u32 = [&](uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
    out += "glTF";
    u32(2);
    u32(static_cast<uint32_t>(12 + 8 + j.size() + 8 + b.size()));
    u32(static_cast<uint32_t>(j.size()));
    out += "JSON";
    out += j;
    u32(static_cast<uint32_t>(b.size()));
    out += std::string("BIN\0", 4);
    out += b;
    return out;
  }
};

} // namespace prt::testing
