// export_gltf.cpp — glTF 2.0 export (.gltf + .bin, or .glb), written by tinygltf (contract:
// exports/export.h; layout: formats/SCHEMA.md "Exports"). Per vertex set one mesh (one primitive)
// and one node. POSITION, NORMAL and the indices as glTF defines them; AO as COLOR_0 (grey,
// linear) and exactly as `_AO`; every other product as application-specific attributes
// (glTF 2.0 §3.7.2.1: names start with "_", float components) `_PRT_<NAME>_<k>`, attribute k
// holding components 4k … 4k+3 of the product's row-major per-vertex row (VEC4, the last one
// SCALAR/VEC2/VEC3 as needed), so a reader reassembles a row by concatenating the attributes in
// order; asset.extras.prtbake lists, per mesh, each product's dataset, shape and attributes.
// A set with a lightmap (format v5) gets its UVs as TEXCOORD_1 (and TEXCOORD_0: glTF requires
// the sets numbered from 0, and the file holds no other), one vertex per distinct (vertex, UV)
// pair of its corners — the file's rows first, in order, split copies after them — and a material
// whose occlusionTexture (texCoord 1) is the AO as an 8-bit PNG; the lightmap's float datasets
// travel as buffer views named in the set's extras (glTF has no float image format).
#include "export_common.h"


#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <tuple>

namespace prt::exports::detail {
namespace {

using tinygltf::Value;

// The attribute name (without the group suffix) of each product's dataset.
std::string attribute_base(const std::string& dataset) {
  if (dataset == "ao") return "_AO";
  std::string base = dataset == "radiance/band1" ? "radiance" : dataset.substr(dataset.find('/') + 1);
  if (dataset.rfind("area_lights/", 0) == 0) base = "area_" + base;
  for (char& c : base) c = char(std::toupper(static_cast<unsigned char>(c)));
  return "_PRT_" + base;
}

int vec_type(uint64_t components) {
  switch (components) {
  case 1: return TINYGLTF_TYPE_SCALAR;
  case 2: return TINYGLTF_TYPE_VEC2;
  case 3: return TINYGLTF_TYPE_VEC3;
  default: return TINYGLTF_TYPE_VEC4;
  }
}

class ModelBuilder {
public:
  ModelBuilder() { model_.buffers.emplace_back(); }
  tinygltf::Model& model() { return model_; }

  // A buffer view of `values` (4-byte aligned in the one buffer) and an accessor over all of it.
  template <class T>
  int add(const std::vector<T>& values, int component_type, uint64_t components, int target) {
    std::vector<unsigned char>& data = model_.buffers[0].data;
    data.resize((data.size() + 3) / 4 * 4, 0);
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = data.size();
    view.byteLength = values.size() * sizeof(T);
    view.target = target;
    data.resize(data.size() + view.byteLength);
    if (!values.empty()) std::memcpy(data.data() + view.byteOffset, values.data(), view.byteLength);
    model_.bufferViews.push_back(view);
    tinygltf::Accessor accessor;
    accessor.bufferView = int(model_.bufferViews.size() - 1);
    accessor.componentType = component_type;
    accessor.count = values.size() / components;
    accessor.type = vec_type(components);
    model_.accessors.push_back(accessor);
    return int(model_.accessors.size() - 1);
  }
  int add_floats(const std::vector<float>& values, uint64_t components) {
    return add(values, TINYGLTF_COMPONENT_TYPE_FLOAT, components, TINYGLTF_TARGET_ARRAY_BUFFER);
  }
  // A buffer view of raw bytes (an image, a lightmap dataset), 4-byte aligned, no target.
  int add_view(const void* bytes, size_t size) {
    std::vector<unsigned char>& data = model_.buffers[0].data;
    data.resize((data.size() + 3) / 4 * 4, 0);
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = data.size();
    view.byteLength = size;
    data.resize(data.size() + size);
    if (size > 0) std::memcpy(data.data() + view.byteOffset, bytes, size);
    model_.bufferViews.push_back(view);
    return int(model_.bufferViews.size() - 1);
  }

private:
  tinygltf::Model model_;
};

Value string_value(const std::string& s) { return Value(s); }
Value array_of(const std::vector<std::string>& items) {
  Value::Array a;
  for (const auto& s : items) a.push_back(Value(s));
  return Value(std::move(a));
}

// The export's vertices of a set with UVs per triangle corner: one per distinct (file row, UV)
// pair. A row keeps its index for the UV of its first corner (so a mesh without seams exports
// its rows unchanged); a corner with another UV (compared bit for bit) gets a copy of the row
// appended after the file's rows.
struct UvVertices {
  std::vector<uint32_t> rows;     // the file row of each export vertex (rows[v] = v for v < V)
  std::vector<uint32_t> indices;  // [T][3] into the export vertices
  std::vector<float> uv;          // [export vertex][2]; (0, 0) for a row no triangle uses
};

UvVertices split_by_uv(const VertexSet& s) {
  const size_t V = s.vertex_count();
  const std::vector<uint32_t>& tri = s.triangles->values;
  const std::vector<float>& corner_uv = s.uv->values;
  UvVertices out;
  out.rows.resize(V);
  for (size_t v = 0; v < V; ++v) out.rows[v] = uint32_t(v);
  out.uv.assign(2 * V, 0.0f);
  out.indices.resize(tri.size());
  std::vector<bool> used(V, false);
  auto bits = [](float x) {
    uint32_t u;
    std::memcpy(&u, &x, sizeof u);
    return u;
  };
  std::map<std::tuple<uint32_t, uint32_t, uint32_t>, uint32_t> copies;  // (row, u bits, v bits) -> vertex
  for (size_t i = 0; i < tri.size(); ++i) {
    const uint32_t v = tri[i];
    const float u = corner_uv[2 * i], w = corner_uv[2 * i + 1];
    if (!used[v]) {
      used[v] = true;
      out.uv[2 * v] = u;
      out.uv[2 * v + 1] = w;
      out.indices[i] = v;
    } else if (bits(out.uv[2 * v]) == bits(u) && bits(out.uv[2 * v + 1]) == bits(w)) {
      out.indices[i] = v;
    } else {
      const auto [it, added] = copies.try_emplace({v, bits(u), bits(w)}, uint32_t(out.rows.size()));
      if (added) {
        out.rows.push_back(v);
        out.uv.insert(out.uv.end(), {u, w});
      }
      out.indices[i] = it->second;
    }
  }
  return out;
}

// Row r of a [rows][width] array for each export vertex.
template <class T> std::vector<T> gather(const std::vector<T>& values, const std::vector<uint32_t>& rows, size_t width) {
  std::vector<T> out;
  out.reserve(rows.size() * width);
  for (const uint32_t r : rows)
    out.insert(out.end(), values.begin() + std::ptrdiff_t(r * width), values.begin() + std::ptrdiff_t((r + 1) * width));
  return out;
}

// The AO of a lightmap as glTF's occlusion texture: PNG code round(255 · clamp(AO, 0, 1)) per
// texel, row 0 of the image at v = 0 (glTF's UV origin is the image's top-left, as the file's).
std::vector<uint8_t> occlusion_codes(const std::vector<float>& ao) {
  std::vector<uint8_t> codes(ao.size());
  for (size_t k = 0; k < ao.size(); ++k) codes[k] = uint8_t(std::lround(std::clamp(double(ao[k]), 0.0, 1.0) * 255.0));
  return codes;
}

template <class T> int add_array_view(ModelBuilder& b, const std::vector<T>& values) {
  return b.add_view(values.data(), values.size() * sizeof(T));
}

// The lightmap of a set: the occlusion material (when it has AO) and every dataset as a buffer
// view; returns the extras entry and sets `material` (−1 without AO).
Value add_lightmap(ModelBuilder& b, const SetRef& ref, const std::filesystem::path& out, int& material) {
  const Lightmap& m = *ref.set->lightmap;
  const int H = int(m.height), W = int(m.width);
  Value::Object entry;
  entry["width"] = Value(W);
  entry["height"] = Value(H);
  entry["uv_set"] = string_value(ref.set->uv->uv_set.value_or(""));
  entry["texcoord"] = Value(1);
  if (m.padding) entry["padding"] = Value(int(*m.padding));
  entry["state_codes"] = string_value("0 empty, 1 baked, 2 filled, 3 padding (formats/SCHEMA.md, Lightmaps)");
  material = -1;
  if (m.ao) {
    tinygltf::Model& model = b.model();
    const std::string png = encode_png_grey(occlusion_codes(m.ao->values), m.width, m.height, out);
    tinygltf::Image image;
    image.name = ref.name + " AO";
    image.mimeType = "image/png";
    image.bufferView = b.add_view(png.data(), png.size());
    model.images.push_back(image);
    tinygltf::Sampler sampler;  // bilinear, no mipmaps, clamped: the lightmap is padded for it
    sampler.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
    sampler.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
    sampler.wrapS = sampler.wrapT = TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
    model.samplers.push_back(sampler);
    tinygltf::Texture texture;
    texture.source = int(model.images.size() - 1);
    texture.sampler = int(model.samplers.size() - 1);
    model.textures.push_back(texture);
    tinygltf::Material mat;  // white dielectric: the occlusion is what shows
    mat.name = ref.name + " lightmap";
    mat.pbrMetallicRoughness.metallicFactor = 0.0;
    mat.pbrMetallicRoughness.roughnessFactor = 1.0;
    mat.occlusionTexture.index = int(model.textures.size() - 1);
    mat.occlusionTexture.texCoord = 1;
    model.materials.push_back(mat);
    material = int(model.materials.size() - 1);
    Value::Object occlusion;
    occlusion["material"] = Value(material);
    occlusion["texture"] = Value(texture.source);
    occlusion["image"] = Value(texture.source);
    occlusion["encoding"] = string_value("8-bit greyscale PNG, code round(255 * clamp(AO, 0, 1)), row 0 at v = 0, linear");
    entry["occlusion"] = Value(std::move(occlusion));
  }
  // Every dataset, lossless, as a buffer view: C order, little-endian.
  Value::Array datasets;
  auto dataset = [&](std::string_view path, const char* dtype, std::vector<int> trailing, int view) {
    Value::Object d;
    d["dataset"] = string_value(join(ref.prefix, std::string(path.substr(1))));
    d["dtype"] = string_value(dtype);
    Value::Array shape{Value(H), Value(W)};
    for (int t : trailing) shape.push_back(Value(t));
    d["shape"] = Value(std::move(shape));
    d["bufferView"] = Value(view);
    datasets.push_back(Value(std::move(d)));
  };
  dataset(names::kLightmapState, "uint8", {}, add_array_view(b, m.state.values));
  if (m.positions) {
    if (exactly_float(m.positions->values))
      dataset(names::kLightmapPositions, "float32", {3},
              add_array_view(b, std::vector<float>(m.positions->values.begin(), m.positions->values.end())));
    else
      dataset(names::kLightmapPositions, "float64", {3}, add_array_view(b, m.positions->values));
  }
  if (m.normals) dataset(names::kLightmapNormals, "float32", {3}, add_array_view(b, m.normals->values));
  for (const ProductRef& pr : lightmap_products(m))
    dataset("/" + pr.dataset, "float32", std::vector<int>(pr.shape.begin(), pr.shape.end()), add_array_view(b, pr.product->values));
  entry["datasets"] = Value(std::move(datasets));
  return Value(std::move(entry));
}

// Adds the mesh and node of one vertex set; returns its extras entry.
Value add_set(ModelBuilder& b, const SetRef& ref, const std::filesystem::path& out) {
  const VertexSet& s = *ref.set;
  const bool lightmap = s.lightmap && s.lightmap->texel_count() > 0 && s.uv && s.triangles;
  UvVertices split;
  if (lightmap) split = split_by_uv(s);
  std::vector<double> split_positions;  // the rows of split vertices (copies only when there is a lightmap)
  if (lightmap) split_positions = gather(s.positions->values, split.rows, 3);
  const std::vector<double>& p = lightmap ? split_positions : s.positions->values;
  const size_t V = p.size() / 3;
  // Positions in float32: the file's own when they are float32, else relative to the bounding
  // box centre, which becomes the node's translation (double in the JSON).
  std::array<double, 3> origin{0, 0, 0};
  if (!exactly_float(p) && V > 0) {
    for (size_t a = 0; a < 3; ++a) {
      double lo = p[a], hi = p[a];
      for (size_t v = 0; v < V; ++v) lo = std::min(lo, p[3 * v + a]), hi = std::max(hi, p[3 * v + a]);
      origin[a] = lo + (hi - lo) / 2;
    }
  }
  std::vector<float> positions(p.size());
  for (size_t i = 0; i < p.size(); ++i) positions[i] = float(p[i] - origin[i % 3]);

  tinygltf::Primitive prim;
  const int pos = b.add_floats(positions, 3);
  {
    tinygltf::Accessor& acc = b.model().accessors[size_t(pos)];
    acc.minValues.assign(3, std::numeric_limits<double>::infinity());
    acc.maxValues.assign(3, -std::numeric_limits<double>::infinity());
    for (size_t i = 0; i < positions.size(); ++i) {
      acc.minValues[i % 3] = std::min(acc.minValues[i % 3], double(positions[i]));
      acc.maxValues[i % 3] = std::max(acc.maxValues[i % 3], double(positions[i]));
    }
  }
  prim.attributes["POSITION"] = pos;
  if (s.normals) prim.attributes["NORMAL"] = b.add_floats(lightmap ? gather(s.normals->values, split.rows, 3) : s.normals->values, 3);
  if (lightmap) {
    const int uv = b.add_floats(split.uv, 2);
    prim.attributes["TEXCOORD_0"] = uv;  // glTF numbers the sets from 0; the file holds this one only
    prim.attributes["TEXCOORD_1"] = uv;
  }
  if (s.triangles) {
    prim.indices = b.add(lightmap ? split.indices : s.triangles->values, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, 1,
                         TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    prim.mode = TINYGLTF_MODE_TRIANGLES;
  } else {
    prim.mode = TINYGLTF_MODE_POINTS;
  }

  Value::Array product_entries;
  const size_t rows = s.vertex_count();
  for (const ProductRef& pr : products(s)) {
    const uint64_t C = pr.components();
    std::vector<float> split_values;
    if (lightmap) split_values = gather(pr.product->values, split.rows, pr.product->values.size() / rows);
    const std::vector<float>& values = lightmap ? split_values : pr.product->values;
    const std::string base = attribute_base(pr.dataset);
    std::vector<std::string> attrs;
    if (pr.dataset == "ao") {
      std::vector<float> grey(3 * V);
      for (size_t v = 0; v < V; ++v) grey[3 * v] = grey[3 * v + 1] = grey[3 * v + 2] = values[v];
      prim.attributes["COLOR_0"] = b.add_floats(grey, 3);
      prim.attributes[base] = b.add_floats(values, 1);
      attrs.push_back(base);
    } else {
      for (uint64_t k = 0; 4 * k < C; ++k) {
        const uint64_t n = std::min<uint64_t>(4, C - 4 * k);
        std::vector<float> group(V * n);
        for (size_t v = 0; v < V; ++v)
          for (uint64_t j = 0; j < n; ++j) group[v * n + j] = values[v * C + 4 * k + j];
        attrs.push_back(base + "_" + std::to_string(k));
        prim.attributes[attrs.back()] = b.add_floats(group, n);
      }
    }
    Value::Object entry;
    entry["dataset"] = string_value(pr.dataset);
    Value::Array shape;
    for (uint64_t d : pr.shape) shape.push_back(Value(int(d)));
    entry["shape"] = Value(std::move(shape));
    entry["attributes"] = array_of(attrs);
    if (pr.product->sh_order) entry["sh_order"] = Value(int(*pr.product->sh_order));
    if (pr.product->lights) entry["lights"] = string_value(*pr.product->lights);
    product_entries.push_back(Value(std::move(entry)));
  }

  std::optional<Value> lightmap_entry;
  if (lightmap) {
    int material = -1;
    lightmap_entry = add_lightmap(b, ref, out, material);
    prim.material = material;
  }

  tinygltf::Mesh mesh;
  mesh.name = ref.name;
  mesh.primitives.push_back(prim);
  b.model().meshes.push_back(mesh);
  tinygltf::Node node;
  node.name = ref.name;
  node.mesh = int(b.model().meshes.size() - 1);
  if (origin != std::array<double, 3>{0, 0, 0}) node.translation.assign(origin.begin(), origin.end());
  b.model().nodes.push_back(node);

  Value::Object entry;
  entry["mesh"] = Value(node.mesh);
  entry["node"] = Value(int(b.model().nodes.size() - 1));
  entry["name"] = string_value(ref.name);
  entry["dataset_prefix"] = string_value(ref.prefix);
  entry["products"] = Value(std::move(product_entries));
  if (lightmap_entry) {
    entry["lightmap"] = std::move(*lightmap_entry);
    Value::Array copied;
    for (size_t v = rows; v < split.rows.size(); ++v) copied.push_back(Value(int(split.rows[v])));
    Value::Object vertices;
    vertices["file_rows"] = Value(int(rows));
    vertices["copies_of"] = Value(std::move(copied));
    vertices["meaning"] = string_value("vertices 0..file_rows-1 are the file's rows; vertex file_rows+j copies row "
                                       "copies_of[j] with another lightmap UV (a UV seam)");
    entry["vertices"] = Value(std::move(vertices));
  }
  return Value(std::move(entry));
}

} // namespace

std::vector<std::filesystem::path> export_gltf(const Asset& asset, const std::filesystem::path& out, bool glb) {
  Staging staging(out);
  ModelBuilder b;
  tinygltf::Model& m = b.model();
  m.asset.version = "2.0";
  m.asset.generator = "prtbake export";

  Value::Array sets;
  std::vector<int> set_nodes;
  for (const SetRef& ref : vertex_sets(asset)) {
    sets.push_back(add_set(b, ref, out));
    set_nodes.push_back(int(m.nodes.size() - 1));
  }
  tinygltf::Scene scene;
  if (asset.root.up_axis == "z") {
    // glTF is +Y up: a Z-up bake hangs under a node turning +Z to +Y (−90° about X); the mesh
    // data (positions, normals, SH) stay in the file's frame.
    tinygltf::Node up;
    up.name = "prtbake_z_up";
    up.rotation = {-std::sqrt(0.5), 0, 0, std::sqrt(0.5)};
    up.children = set_nodes;
    m.nodes.push_back(up);
    scene.nodes = {int(m.nodes.size() - 1)};
  } else {
    scene.nodes = set_nodes;
  }
  m.scenes.push_back(scene);
  m.defaultScene = 0;

  Value::Object info;
  const RootInfo& r = asset.root;
  for (const auto& [key, value] : {std::pair<const char*, const std::string*>{"source", &r.source},
                                   {"source_sha256", &r.source_sha256}, {"generator", &r.generator},
                                   {"up_axis", &r.up_axis}, {"sh_convention", &r.sh_convention}})
    info[key] = string_value(*value);
  info["attribute_layout"] = string_value(
      "attribute _PRT_<NAME>_<k> holds components 4k..4k+3 of the product's row-major per-vertex row; "
      "concatenate the attributes in order to rebuild it (formats/SCHEMA.md, Exports)");
  info["sets"] = Value(std::move(sets));
  Value::Object extras;
  extras["prtbake"] = Value(std::move(info));
  m.asset.extras = Value(std::move(extras));

  tinygltf::TinyGLTF writer;
  const std::string msg = out.string();
  if (glb) {
    std::ostringstream bytes;
    if (!writer.WriteGltfSceneToStream(&m, bytes, false, true)) throw FormatError(msg, "tinygltf could not write the GLB");
    write_bytes(staging.stage(out), bytes.str(), out);
  } else {
    std::filesystem::path bin = out;
    bin.replace_extension(".bin");
    if (bin == out) throw FormatError(msg, "a .gltf export needs a name not ending in .bin (its buffer is <stem>.bin)");
    m.buffers[0].uri = bin.filename().string();
    staging.stage(bin);  // tinygltf writes the buffer beside the staged .gltf, under its uri
    if (!writer.WriteGltfSceneToFile(&m, staging.stage(out).string(), false, false, true, false))
      throw FormatError(msg, "cannot write the glTF or its buffer '" + bin.string() + "' (disk full?)");
  }
  return staging.commit();
}

} // namespace prt::exports::detail
