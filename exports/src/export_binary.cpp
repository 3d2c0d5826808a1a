// export_binary.cpp — the plain binary export: magic, version, a JSON header naming every array
// (dtype, shape, byte offset), then the arrays, little-endian, 16-byte aligned (contract:
// exports/export.h; layout: formats/SCHEMA.md "Exports").
#include "export_common.h"


#include <nlohmann/json.hpp>

#include <bit>
#include <cstring>

namespace prt::exports::detail {
namespace {

static_assert(std::endian::native == std::endian::little, "the binary export writes the host's bytes: little-endian only");

constexpr size_t kAlign = 16;

struct Array {
  std::string name, dtype;
  std::vector<uint64_t> shape;
  nlohmann::json attrs;  // always an object
  std::string bytes;
};

template <class T> std::string bytes_of(const std::vector<T>& values) {
  std::string s(values.size() * sizeof(T), '\0');
  if (!values.empty()) std::memcpy(s.data(), values.data(), s.size());
  return s;
}

void add_set(std::vector<Array>& arrays, const SetRef& ref) {
  const VertexSet& s = *ref.set;
  const uint64_t V = s.vertex_count();
  auto name = [&](std::string_view path) { return join(ref.prefix, std::string(path.substr(1))); };
  const std::vector<double>& p = s.positions->values;
  if (exactly_float(p))
    arrays.push_back({name(names::kPositions), "float32", {V, 3}, nlohmann::json::object(), bytes_of(std::vector<float>(p.begin(), p.end()))});
  else
    arrays.push_back({name(names::kPositions), "float64", {V, 3}, nlohmann::json::object(), bytes_of(p)});
  if (s.normals) arrays.push_back({name(names::kNormals), "float32", {V, 3}, nlohmann::json::object(), bytes_of(s.normals->values)});
  if (s.triangles)
    arrays.push_back({name(names::kTriangles), "uint32", {s.triangles->values.size() / 3, 3}, nlohmann::json::object(), bytes_of(s.triangles->values)});
  if (s.source_position)
    arrays.push_back({name(names::kSourcePosition), "uint32", {V}, nlohmann::json::object(), bytes_of(s.source_position->values)});
  for (const ProductRef& pr : products(s)) {
    Array a{join(ref.prefix, pr.dataset), "float32", {V}, nlohmann::json::object(), bytes_of(pr.product->values)};
    a.shape.insert(a.shape.end(), pr.shape.begin(), pr.shape.end());
    if (pr.product->sh_order) a.attrs[std::string(names::kShOrder)] = *pr.product->sh_order;
    if (pr.product->lights) a.attrs["lights"] = *pr.product->lights;
    if (pr.product->integrand) a.attrs[std::string(names::kIntegrand)] = *pr.product->integrand;
    arrays.push_back(std::move(a));
  }
  // The lightmap (format v5): the UVs per triangle corner and every [H][W]... dataset.
  if (s.uv) {
    Array a{name(names::kUv), "float32", {s.uv->values.size() / 6, 3, 2}, nlohmann::json::object(), bytes_of(s.uv->values)};
    if (s.uv->uv_set) a.attrs[std::string(names::kUvSet)] = *s.uv->uv_set;
    arrays.push_back(std::move(a));
  }
  if (!s.lightmap) return;
  const formats::Lightmap& m = *s.lightmap;
  Array state{name(names::kLightmapState), "uint8", {m.height, m.width}, nlohmann::json::object(), bytes_of(m.state.values)};
  if (m.padding) state.attrs[std::string(names::kPadding)] = *m.padding;
  arrays.push_back(std::move(state));
  if (m.positions) {
    const std::vector<double>& lp = m.positions->values;
    if (exactly_float(lp))
      arrays.push_back({name(names::kLightmapPositions), "float32", {m.height, m.width, 3}, nlohmann::json::object(),
                        bytes_of(std::vector<float>(lp.begin(), lp.end()))});
    else
      arrays.push_back({name(names::kLightmapPositions), "float64", {m.height, m.width, 3}, nlohmann::json::object(), bytes_of(lp)});
  }
  if (m.normals)
    arrays.push_back({name(names::kLightmapNormals), "float32", {m.height, m.width, 3}, nlohmann::json::object(), bytes_of(m.normals->values)});
  for (const ProductRef& pr : lightmap_products(m)) {
    Array a{join(ref.prefix, pr.dataset), "float32", {m.height, m.width}, nlohmann::json::object(), bytes_of(pr.product->values)};
    a.shape.insert(a.shape.end(), pr.shape.begin(), pr.shape.end());
    if (pr.product->sh_order) a.attrs[std::string(names::kShOrder)] = *pr.product->sh_order;
    if (pr.product->integrand) a.attrs[std::string(names::kIntegrand)] = *pr.product->integrand;
    arrays.push_back(std::move(a));
  }
}

size_t aligned(size_t n) { return (n + kAlign - 1) / kAlign * kAlign; }

} // namespace

std::vector<std::filesystem::path> export_binary(const Asset& asset, const std::filesystem::path& out) {
  Staging staging(out);
  std::vector<Array> arrays;
  for (const SetRef& ref : vertex_sets(asset)) add_set(arrays, ref);

  // The header's length depends on the offsets it lists, which depend on its length: lay out
  // with a guess, and again until the padded header length no longer changes.
  const RootInfo& r = asset.root;
  std::string header;
  for (size_t header_bytes = 0;;) {
    nlohmann::json j;
    j["format"] = "prtbake-bin";
    j["version"] = kBinaryVersion;
    j["byte_order"] = "little";
    j["alignment"] = kAlign;
    j["source"] = r.source;
    j["source_sha256"] = r.source_sha256;
    j["generator"] = r.generator;
    j["up_axis"] = r.up_axis;
    j["sh_convention"] = r.sh_convention;
    j["arrays"] = nlohmann::json::array();
    size_t offset = 16 + header_bytes;
    for (const Array& a : arrays) {
      j["arrays"].push_back({{"name", a.name}, {"dtype", a.dtype}, {"shape", a.shape}, {"offset", offset},
                             {"nbytes", a.bytes.size()}, {"attrs", a.attrs}});
      offset = aligned(offset + a.bytes.size());
    }
    header = j.dump();
    if (aligned(header.size()) == header_bytes) break;
    header_bytes = aligned(header.size());
  }
  header.resize(aligned(header.size()), ' ');

  std::string bytes(kBinaryMagic, sizeof kBinaryMagic);
  const uint32_t fields[2] = {kBinaryVersion, uint32_t(header.size())};
  bytes.append(reinterpret_cast<const char*>(fields), sizeof fields);
  bytes += header;
  for (const Array& a : arrays) {
    bytes += a.bytes;
    bytes.resize(aligned(bytes.size()), '\0');
  }
  write_bytes(staging.stage(out), bytes, out);
  return staging.commit();
}

} // namespace prt::exports::detail
