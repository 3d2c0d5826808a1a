// export_gltf.cpp — glTF 2.0 export (.gltf + .bin, or .glb), written by tinygltf (contract:
// exports/export.h; layout: formats/SCHEMA.md "Exports"). Per vertex set one mesh (one primitive)
// and one node. POSITION, NORMAL and the indices as glTF defines them; AO as COLOR_0 (grey,
// linear) and exactly as `_AO`; every other product as application-specific attributes
// (glTF 2.0 §3.7.2.1: names start with "_", float components) `_PRT_<NAME>_<k>`, attribute k
// holding components 4k … 4k+3 of the product's row-major per-vertex row (VEC4, the last one
// SCALAR/VEC2/VEC3 as needed), so a reader reassembles a row by concatenating the attributes in
// order; asset.extras.prtbake lists, per mesh, each product's dataset, shape and attributes.
#include "export_common.h"


#include <tiny_gltf.h>

#include <array>
#include <cctype>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>

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

private:
  tinygltf::Model model_;
};

Value string_value(const std::string& s) { return Value(s); }
Value array_of(const std::vector<std::string>& items) {
  Value::Array a;
  for (const auto& s : items) a.push_back(Value(s));
  return Value(std::move(a));
}

// Adds the mesh and node of one vertex set; returns its extras entry.
Value add_set(ModelBuilder& b, const SetRef& ref) {
  const VertexSet& s = *ref.set;
  const std::vector<double>& p = s.positions->values;
  const size_t V = s.vertex_count();
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
  if (s.normals) prim.attributes["NORMAL"] = b.add_floats(s.normals->values, 3);
  if (s.triangles) {
    prim.indices = b.add(s.triangles->values, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, 1, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    prim.mode = TINYGLTF_MODE_TRIANGLES;
  } else {
    prim.mode = TINYGLTF_MODE_POINTS;
  }

  Value::Array product_entries;
  for (const ProductRef& pr : products(s)) {
    const uint64_t C = pr.components();
    const std::vector<float>& values = pr.product->values;
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
  return Value(std::move(entry));
}

} // namespace

void export_gltf(const Asset& asset, const std::filesystem::path& out, bool glb) {
  Staging staging(out);
  ModelBuilder b;
  tinygltf::Model& m = b.model();
  m.asset.version = "2.0";
  m.asset.generator = "prtbake export";

  Value::Array sets;
  std::vector<int> set_nodes;
  for (const SetRef& ref : vertex_sets(asset)) {
    sets.push_back(add_set(b, ref));
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
  staging.commit();
}

} // namespace prt::exports::detail
