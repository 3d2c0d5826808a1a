// gltf_reader.cpp — glTF 2.0 (.gltf, .glb) into a Polygons (contracts: bake/mesh/mesh.h, gltf_reader.h).
//
// tinygltf parses the JSON / GLB container and resolves buffers (data URIs and external files,
// read through our file callbacks: no shell expansion of URIs); images are handed to a loader
// that does nothing, so no texture is decoded. Before tinygltf sees the JSON, a preflight parse
// of ours (nlohmann, iterative) bounds its nesting (kMaxJsonDepth: tinygltf copies `extras` and
// `extensions` recursively, and a 10^6-deep array crashed it by stack overflow), refuses the
// compression extensions we cannot decode by name (tinygltf's own message for a Draco file was
// "accessor[1] invalid bufferView"), and sums the buffers' declared byteLengths: external files
// are read only up to that total (at most kMaxBufferFileBytes), so a small .gltf cannot make us
// read a huge file, whether named by a buffer or by an image. Everything
// tinygltf 2.7 leaves unchecked — every index into another array, accessor extents against their
// buffer views and buffers, index values, component types, transforms, the node graph — is
// checked here before a byte is read, so a bad file is a one-line InputError, never a crash.
#include <bake/mesh/gltf_reader.h>

#include <bake/core/error.h>
#include <bake/core/sha256.h>

#include <tiny_gltf.h>

#include <nlohmann/json.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace prt::bake::mesh_readers {
namespace {

constexpr uintmax_t kMaxBufferFileBytes = uintmax_t{4} << 30;  // as for mesh files (mesh_io.cpp)
// Deeper JSON is refused before tinygltf parses it; a glTF's own structure is about 8 deep, and
// scene files have the same limit (scene_json.cpp).
constexpr int kMaxJsonDepth = 128;
// Extensions whose data we cannot decode: a primitive using them has no readable accessors.
constexpr std::string_view kUnsupportedExtensions[] = {"KHR_draco_mesh_compression", "EXT_meshopt_compression",
                                                        "KHR_mesh_quantization"};

// ---- tinygltf's file access: plain reads, no wordexp expansion of URIs, no writes. ----
// What the file system callbacks may read (their user_data): the external buffers the JSON declares, in its order
// (tinygltf reads buffers before anything else, its "3. Parse Buffer"), at most their declared bytes.
// Reads after the last buffer are images, which a bake never uses: refused, so tinygltf keeps their
// uri with a warning and no texture is read or hashed.
struct ReadBudget {
  uintmax_t remaining = 0;
  size_t buffer_files = 0;                      // buffers whose uri is not a data URI
  std::vector<std::string>* digests = nullptr;  // SourceFile::referenced_sha256, one per buffer file read
};
bool file_exists(const std::string& path, void*) {
  std::error_code ec;
  return std::filesystem::is_regular_file(path, ec);
}
std::string expand_nothing(const std::string& path, void*) { return path; }
bool read_buffer_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user_data) {
  auto& budget = *static_cast<ReadBudget*>(user_data);
  if (budget.buffer_files == 0) {
    if (err) *err += "'" + path + "' is not a buffer (images are not read)\n";
    return false;
  }
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec && size > budget.remaining) {
    if (err) *err += "'" + path + "' is " + std::to_string(size) + " bytes, more than the " + std::to_string(budget.remaining) +
                     " bytes left of what the glTF's buffers declare\n";
    return false;
  }
  std::ifstream in(path, std::ios::binary);
  if (ec || !in) {
    if (err) *err += "cannot read '" + path + "'\n";
    return false;
  }
  budget.remaining -= size;
  out->resize(static_cast<size_t>(size));
  if (size > 0 && !in.read(reinterpret_cast<char*>(out->data()), static_cast<std::streamsize>(size))) {
    if (err) *err += "cannot read '" + path + "'\n";
    return false;
  }
  --budget.buffer_files;
  if (budget.digests) budget.digests->push_back(sha256_bytes(std::as_bytes(std::span(out->data(), out->size()))));
  return true;
}
bool write_nothing(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err += "writing is disabled\n";
  return false;
}
// A bake needs no texture: images are accepted undecoded.
bool skip_image(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int, void*) {
  return true;
}

// tinygltf's messages are newline-separated; ours are one line.
std::string one_line(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '\n' || c == '\r') {
      if (!out.empty() && out.back() != ' ') out += "; ";
    } else {
      out += c;
    }
  }
  while (!out.empty() && (out.back() == ' ' || out.back() == ';')) out.pop_back();
  constexpr size_t kMaxShown = 300;
  if (out.size() > kMaxShown) out = out.substr(0, kMaxShown) + "...";
  return out;
}

// ---- Accessors (glTF 2.0 specification, "Accessors"): checked views of buffer bytes. ----
struct AccessorView {
  const unsigned char* data = nullptr;
  size_t count = 0, stride = 0;
  int component_type = 0;
};

size_t component_bytes(int type) {
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT: case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_INT: case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;
  }
}

// n of a TEXCOORD_n attribute name (glTF 2.0 specification, "Meshes": n without leading zeros),
// or none for any other attribute.
std::optional<int> texcoord_set(std::string_view attribute) {
  constexpr std::string_view kPrefix = "TEXCOORD_";
  if (!attribute.starts_with(kPrefix)) return std::nullopt;
  const std::string_view digits = attribute.substr(kPrefix.size());
  if (digits.empty() || (digits.size() > 1 && digits[0] == '0') ||
      !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
    return std::nullopt;
  int n = 0;
  if (std::from_chars(digits.data(), digits.data() + digits.size(), n).ec != std::errc()) return std::nullopt;  // past int
  return n;
}

class Reader {
 public:
  Reader(const tinygltf::Model& model, const SourceFile& file) : model_(model), file_(file) {}

  [[noreturn]] void fail(const std::string& defect) const { throw InputError(file_.name, defect); }

  // `what` names the accessor's use in messages ("mesh 0 primitive 1 POSITION"). Integer
  // components are read as they are, or with `normalized_integers` (TEXCOORD_n) only normalized.
  AccessorView view(int index, const std::string& what, int type, std::initializer_list<int> component_types,
                    bool normalized_integers = false) const {
    const std::string name = what + " (accessor " + std::to_string(index) + ")";
    if (index < 0 || static_cast<size_t>(index) >= model_.accessors.size())
      fail(what + ": accessor " + std::to_string(index) + " does not exist (" + std::to_string(model_.accessors.size()) + " accessors)");
    const tinygltf::Accessor& a = model_.accessors[static_cast<size_t>(index)];
    if (a.sparse.isSparse) fail(name + " is sparse; sparse accessors are not supported");
    if (a.type != type)
      fail(name + " is not " + (type == TINYGLTF_TYPE_VEC3 ? "VEC3" : type == TINYGLTF_TYPE_VEC2 ? "VEC2" : "SCALAR"));
    if (std::find(component_types.begin(), component_types.end(), a.componentType) == component_types.end())
      fail(name + " has unsupported componentType " + std::to_string(a.componentType));
    const bool integer = a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT;
    if (integer && a.normalized != normalized_integers)
      fail(name + (normalized_integers ? " is not normalized; integer components must be" : " is normalized; not supported"));
    if (a.bufferView < 0 || static_cast<size_t>(a.bufferView) >= model_.bufferViews.size())
      fail(name + " has no valid bufferView (" + std::to_string(a.bufferView) + ")");
    const tinygltf::BufferView& bv = model_.bufferViews[static_cast<size_t>(a.bufferView)];
    const std::string bv_name = "buffer view " + std::to_string(a.bufferView);
    if (bv.buffer < 0 || static_cast<size_t>(bv.buffer) >= model_.buffers.size())
      fail(bv_name + " refers to buffer " + std::to_string(bv.buffer) + ", which does not exist");
    const std::vector<unsigned char>& buffer = model_.buffers[static_cast<size_t>(bv.buffer)].data;
    size_t bv_end = 0;
    if (__builtin_add_overflow(bv.byteOffset, bv.byteLength, &bv_end) || bv_end > buffer.size())
      fail(bv_name + " (offset " + std::to_string(bv.byteOffset) + ", " + std::to_string(bv.byteLength) +
           " bytes) lies past the end of buffer " + std::to_string(bv.buffer) + " (" + std::to_string(buffer.size()) + " bytes)");
    const auto components = static_cast<size_t>(tinygltf::GetNumComponentsInType(static_cast<uint32_t>(type)));
    const size_t element = components * component_bytes(a.componentType);
    const size_t stride = bv.byteStride == 0 ? element : bv.byteStride;
    if (stride < element) fail(bv_name + " has byteStride " + std::to_string(stride) + ", less than the " + std::to_string(element) + "-byte elements of " + name);
    if (a.count >= std::numeric_limits<uint32_t>::max()) fail(name + " has too many elements for 32-bit indices");
    size_t end = a.byteOffset;
    if (a.count > 0) {
      size_t span = 0;
      if (__builtin_mul_overflow(a.count - 1, stride, &span) || __builtin_add_overflow(end, span, &end) ||
          __builtin_add_overflow(end, element, &end))
        end = std::numeric_limits<size_t>::max();
    }
    if (end > bv.byteLength)
      fail(name + " (" + std::to_string(a.count) + " elements from offset " + std::to_string(a.byteOffset) + ") lies past the end of " +
           bv_name + " (" + std::to_string(bv.byteLength) + " bytes)");
    return {buffer.data() + bv.byteOffset + a.byteOffset, a.count, stride, a.componentType};
  }

  static Eigen::Vector3d vec3(const AccessorView& v, size_t i) {
    float f[3];
    std::memcpy(f, v.data + i * v.stride, sizeof f);
    return {f[0], f[1], f[2]};
  }
  // A VEC2 of floats, or of normalized unsigned bytes or shorts (c / 255, c / 65535: glTF 2.0
  // specification, "Accessors", normalized data).
  static Eigen::Vector2f vec2(const AccessorView& v, size_t i) {
    const unsigned char* p = v.data + i * v.stride;
    if (v.component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) return {p[0] / 255.0f, p[1] / 255.0f};
    if (v.component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) {
      uint16_t s[2];
      std::memcpy(s, p, sizeof s);
      return {s[0] / 65535.0f, s[1] / 65535.0f};
    }
    float f[2];
    std::memcpy(f, p, sizeof f);
    return {f[0], f[1]};
  }
  static uint32_t index(const AccessorView& v, size_t i) {
    const unsigned char* p = v.data + i * v.stride;
    if (v.component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) return *p;
    if (v.component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) {
      uint16_t s;
      std::memcpy(&s, p, sizeof s);
      return s;
    }
    uint32_t u;
    std::memcpy(&u, p, sizeof u);
    return u;
  }

  // ---- Nodes (glTF 2.0 specification, "Transformations"): local transform, matrix or T * R * S, in double. ----
  Eigen::Matrix4d local_transform(size_t n) const {
    const tinygltf::Node& node = model_.nodes[n];
    const std::string name = "node " + std::to_string(n);
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    if (!node.matrix.empty()) {
      if (node.matrix.size() != 16) fail(name + ": matrix has " + std::to_string(node.matrix.size()) + " numbers, needs 16");
      m = Eigen::Map<const Eigen::Matrix4d>(node.matrix.data());  // column-major, as glTF
    } else {
      auto check = [&](const std::vector<double>& v, size_t want, const char* what) {
        if (!v.empty() && v.size() != want)
          fail(name + ": " + what + " has " + std::to_string(v.size()) + " numbers, needs " + std::to_string(want));
        return !v.empty();
      };
      Eigen::Affine3d t = Eigen::Affine3d::Identity();
      if (check(node.translation, 3, "translation")) t.translate(Eigen::Vector3d(node.translation[0], node.translation[1], node.translation[2]));
      if (check(node.rotation, 4, "rotation")) {
        Eigen::Quaterniond q(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);
        if (!(q.norm() > 0.0) || !std::isfinite(q.norm())) fail(name + ": rotation is not a unit quaternion");
        t.rotate(q.normalized());
      }
      if (check(node.scale, 3, "scale")) t.scale(Eigen::Vector3d(node.scale[0], node.scale[1], node.scale[2]));
      m = t.matrix();
    }
    if (!m.allFinite()) fail(name + " has a non-finite transform");
    return m;
  }

  // One instance of the node's mesh under world transform `world`, appended to `out_`; each
  // primitive with triangles is recorded in `instances_` under the node path `path`.
  void add_mesh(size_t node, const Eigen::Matrix4d& world, const std::string& path, bool animated) {
    const int mesh_index = model_.nodes[node].mesh;
    if (static_cast<size_t>(mesh_index) >= model_.meshes.size())
      fail("node " + std::to_string(node) + " refers to mesh " + std::to_string(mesh_index) + ", which does not exist");
    const tinygltf::Mesh& mesh = model_.meshes[static_cast<size_t>(mesh_index)];
    const Eigen::Matrix3d linear = world.topLeftCorner<3, 3>();
    const double det = linear.determinant();
    // Normals by the inverse transpose, up to a positive factor: the cofactor matrix times sign(det)
    // (defined for singular transforms too).
    Eigen::Matrix3d cofactor;
    cofactor.col(0) = linear.col(1).cross(linear.col(2));
    cofactor.col(1) = linear.col(2).cross(linear.col(0));
    cofactor.col(2) = linear.col(0).cross(linear.col(1));
    if (det < 0) cofactor = -cofactor;
    for (size_t p = 0; p < mesh.primitives.size(); ++p) {
      const tinygltf::Primitive& prim = mesh.primitives[p];
      const std::string name = "mesh " + std::to_string(mesh_index) + " primitive " + std::to_string(p);
      if (prim.mode >= TINYGLTF_MODE_POINTS && prim.mode <= TINYGLTF_MODE_LINE_STRIP) {
        ++skipped_primitives_;
        continue;
      }
      if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != TINYGLTF_MODE_TRIANGLE_STRIP && prim.mode != TINYGLTF_MODE_TRIANGLE_FAN)
        fail(name + " has unknown mode " + std::to_string(prim.mode));
      if (!prim.targets.empty()) ++morphed_primitives_;
      const auto position_it = prim.attributes.find("POSITION");
      if (position_it == prim.attributes.end()) fail(name + " has no POSITION attribute");
      const AccessorView positions = view(position_it->second, name + " POSITION", TINYGLTF_TYPE_VEC3, {TINYGLTF_COMPONENT_TYPE_FLOAT});
      const auto normal_it = prim.attributes.find("NORMAL");
      std::optional<AccessorView> normals;
      if (normal_it != prim.attributes.end()) {
        normals = view(normal_it->second, name + " NORMAL", TINYGLTF_TYPE_VEC3, {TINYGLTF_COMPONENT_TYPE_FLOAT});
        if (normals->count != positions.count)
          fail(name + " has " + std::to_string(normals->count) + " normals for " + std::to_string(positions.count) + " positions");
      } else {
        all_have_normals_ = false;
      }
      const size_t base = out_.positions.size();
      instances_.push_back({path + (p == 0 ? "" : "#p" + std::to_string(p)), path, prim.material, base, out_.normals.size(),
                            normals.has_value(), out_.polygon_count(), 0, animated});
      if (base + positions.count >= std::numeric_limits<uint32_t>::max()) fail("too many vertices for 32-bit indices");
      for (size_t i = 0; i < positions.count; ++i) {
        const Eigen::Vector3d local = vec3(positions, i);
        if (!local.allFinite()) fail(name + " POSITION " + std::to_string(i) + " is not finite (NaN or Inf)");
        const Eigen::Vector3d world_position = (world * local.homogeneous()).head<3>();  // kept in double
        if (!world_position.cast<float>().allFinite()) fail(name + " POSITION " + std::to_string(i) + " leaves the float range under node " + std::to_string(node) + "'s transform");
        out_.positions.push_back(world_position);
        if (normals) {
          const Eigen::Vector3d n = cofactor * vec3(*normals, i);
          const double len = n.norm();
          out_.normals.push_back(len > 0.0 && std::isfinite(len) ? Eigen::Vector3f((n / len).cast<float>()) : n.cast<float>());
        }
      }
      // Texture-coordinate sets (glTF 2.0 specification, "Meshes": TEXCOORD_n, a VEC2 of floats or
      // of normalized unsigned bytes or shorts), per vertex like the positions.
      for (const auto& [attribute, accessor] : prim.attributes) {
        const std::optional<int> set = texcoord_set(attribute);
        if (!set) continue;
        const std::string what = name + " " + attribute;
        const AccessorView uv = view(accessor, what, TINYGLTF_TYPE_VEC2,
                                     {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
                                     true);
        if (uv.count != positions.count)
          fail(name + " has " + std::to_string(uv.count) + " " + attribute + " elements for " + std::to_string(positions.count) + " positions");
        std::vector<Eigen::Vector2f>& rows = texcoord_rows_[*set];
        rows.resize(base);  // rows of earlier instances without the set stay zero: never referenced
        for (size_t i = 0; i < uv.count; ++i) {
          rows.push_back(vec2(uv, i));
          if (!rows.back().allFinite()) fail(what + " " + std::to_string(i) + " is not finite (NaN or Inf)");
        }
        instances_.back().texcoords.push_back(*set);
      }
      // The primitive's vertex sequence: its indices, or 0 … count−1.
      std::vector<uint32_t> sequence;
      if (prim.indices >= 0) {
        const AccessorView idx = view(prim.indices, name + " indices", TINYGLTF_TYPE_SCALAR,
                                      {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT});
        sequence.resize(idx.count);
        for (size_t i = 0; i < idx.count; ++i) {
          sequence[i] = index(idx, i);
          if (sequence[i] >= positions.count)
            fail(name + " index " + std::to_string(i) + " is " + std::to_string(sequence[i]) + ", out of range [0, " + std::to_string(positions.count) + ")");
        }
      } else {
        sequence.resize(positions.count);
        for (size_t i = 0; i < positions.count; ++i) sequence[i] = static_cast<uint32_t>(i);
      }
      // Triangles (glTF 2.0 specification, "Meshes"): strips alternate winding, fans share the first vertex. A
      // transform with a negative determinant mirrors the primitive; reversing keeps the front face.
      const size_t n = sequence.size();
      auto triangle = [&](uint32_t a, uint32_t b, uint32_t c) {
        const auto base32 = static_cast<uint32_t>(base);
        out_.corner_position.insert(out_.corner_position.end(), {base32 + a, det < 0 ? base32 + c : base32 + b, det < 0 ? base32 + b : base32 + c});
        out_.end_polygon();
      };
      if (prim.mode == TINYGLTF_MODE_TRIANGLES) {
        if (n % 3 != 0) fail(name + " has " + std::to_string(n) + " vertices in TRIANGLES mode, not a multiple of 3");
        for (size_t i = 0; i < n; i += 3) triangle(sequence[i], sequence[i + 1], sequence[i + 2]);
      } else if (prim.mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
        for (size_t i = 0; i + 2 < n; ++i)
          if (i % 2 == 0) triangle(sequence[i], sequence[i + 1], sequence[i + 2]);
          else triangle(sequence[i], sequence[i + 2], sequence[i + 1]);
      } else {
        for (size_t i = 0; i + 2 < n; ++i) triangle(sequence[i + 1], sequence[i + 2], sequence[0]);
      }
      if (out_.corner_position.size() >= std::numeric_limits<uint32_t>::max()) fail("too many triangles for 32-bit indices");
      instances_.back().polygon_end = out_.polygon_count();
    }
  }

  // The path segments of `nodes` (siblings, in order): the node's name, or when it has none (empty,
  // "." or "..") the name of its mesh, with '/', '#' and '|' replaced by '_'; "node<N>" when
  // neither has one; a segment already taken by an earlier sibling gets the first free "~2",
  // "~3", ... (bake/mesh/mesh.h NAMES).
  std::vector<std::string> segments(const std::vector<int>& nodes) const {
    auto usable = [](std::string s) {
      for (char& c : s)
        if (c == '/' || c == '#' || c == '|') c = '_';
      return s == "." || s == ".." ? std::string() : s;
    };
    std::vector<std::string> out;
    for (int n : nodes) {
      std::string seg;
      if (n >= 0 && static_cast<size_t>(n) < model_.nodes.size()) {
        const tinygltf::Node& node = model_.nodes[static_cast<size_t>(n)];
        seg = usable(node.name);
        if (seg.empty() && node.mesh >= 0 && static_cast<size_t>(node.mesh) < model_.meshes.size())
          seg = usable(model_.meshes[static_cast<size_t>(node.mesh)].name);
      }
      if (seg.empty()) seg = "node" + std::to_string(n);
      out.push_back(std::move(seg));
    }
    const std::set<std::string> raw(out.begin(), out.end());
    std::set<std::string> taken;
    for (std::string& seg : out) {
      if (!taken.insert(seg).second) {
        std::string candidate;
        for (int k = 2; candidate.empty() || raw.count(candidate) || taken.count(candidate); ++k) candidate = seg + "~" + std::to_string(k);
        seg = candidate;
        taken.insert(seg);
      }
    }
    return out;
  }

  // Walks the default scene into out_ and instances_ and adds the file's warnings.
  void walk() {
    if (model_.scenes.empty()) fail("no scene (nothing says which nodes to bake)");
    const int scene_index = model_.defaultScene < 0 ? 0 : model_.defaultScene;
    if (static_cast<size_t>(scene_index) >= model_.scenes.size())
      fail("default scene " + std::to_string(scene_index) + " does not exist (" + std::to_string(model_.scenes.size()) + " scenes)");
    // Depth first, iteratively (deep hierarchies must not exhaust the stack). The hierarchy must be
    // disjoint strict trees (glTF 2.0 specification, "Nodes and Hierarchy"): a node reached twice is refused, so the walk is linear.
    enum class State : uint8_t { Unseen, OnPath, Done };
    std::vector<State> state(model_.nodes.size(), State::Unseen);
    struct Entry { size_t node; Eigen::Matrix4d parent; bool leave; std::string path; bool animated; };
    // Nodes an animation channel moves (translation, rotation or scale; "weights" animates morph
    // targets, which are ignored): their subtrees move at run time (glTF 2.0, "Animations").
    std::vector<bool> moved(model_.nodes.size(), false);
    for (const tinygltf::Animation& a : model_.animations)
      for (const tinygltf::AnimationChannel& c : a.channels)
        if (c.target_node >= 0 && static_cast<size_t>(c.target_node) < moved.size() && c.target_path != "weights")
          moved[static_cast<size_t>(c.target_node)] = true;
    std::vector<Entry> stack;
    // Pushes `nodes` (children of `where`, whose path is `parent_path`) so that the first is walked first.
    auto push_nodes = [&](const std::vector<int>& nodes, const Eigen::Matrix4d& parent, const std::string& where, const std::string& parent_path,
                          bool parent_animated) {
      const std::vector<std::string> names = segments(nodes);
      for (size_t i = nodes.size(); i-- > 0;) {
        const int n = nodes[i];
        if (n < 0 || static_cast<size_t>(n) >= model_.nodes.size())
          fail(where + " refers to node " + std::to_string(n) + ", which does not exist (" + std::to_string(model_.nodes.size()) + " nodes)");
        stack.push_back({static_cast<size_t>(n), parent, false, parent_path.empty() ? names[i] : parent_path + "/" + names[i],
                         parent_animated || moved[static_cast<size_t>(n)]});
      }
    };
    const tinygltf::Scene& scene = model_.scenes[static_cast<size_t>(scene_index)];
    push_nodes(scene.nodes, Eigen::Matrix4d::Identity(), "scene " + std::to_string(scene_index), "", false);
    while (!stack.empty()) {
      const Entry entry = stack.back();
      stack.pop_back();
      if (entry.leave) {
        state[entry.node] = State::Done;
        continue;
      }
      const std::string name = "node " + std::to_string(entry.node);
      if (state[entry.node] == State::OnPath) fail("recursive node graph: " + name + " is its own ancestor");
      if (state[entry.node] == State::Done) fail(name + " is reached twice (a node may have only one parent and be listed once)");
      state[entry.node] = State::OnPath;
      const tinygltf::Node& node = model_.nodes[entry.node];
      const Eigen::Matrix4d world = entry.parent * local_transform(entry.node);
      if (node.mesh >= 0) {
        if (node.skin >= 0) ++skinned_instances_;
        add_mesh(entry.node, world, entry.path, entry.animated);
      }
      add_light(node, world, entry.path);
      stack.push_back({entry.node, world, true, {}, false});
      push_nodes(node.children, world, name, entry.path, entry.animated);
    }
    if (out_.polygon_count() == 0 && skipped_primitives_ > 0)
      fail("no triangles: only " + std::to_string(skipped_primitives_) + " point or line primitive instance(s), nothing to bake");
    if (skipped_primitives_ > 0)
      file_.warnings.push_back(std::to_string(skipped_primitives_) +
                               " point or line primitive instance(s) skipped (only triangles are baked)");
    // KHR_lights_punctual: points, spots and suns have no area, so nothing of them is baked; the
    // user must hear it, not find the lights missing in the engine's shading.
    if (!model_.lights.empty() && !keep_lights_)
      file_.warnings.push_back(std::to_string(model_.lights.size()) +
                               " punctual light(s) (KHR_lights_punctual) are not baked: they have no area, and "
                               "prtbake bakes the environment's light");
    if (skinned_instances_ + morphed_primitives_ > 0)
      file_.warnings.push_back("skins and morph targets are ignored (" + std::to_string(skinned_instances_) +
                               " skinned mesh instance(s), " + std::to_string(morphed_primitives_) +
                               " primitive instance(s) with morph targets): the rest pose is baked");
  }

  Polygons read() {
    walk();
    if (all_have_normals_ && !out_.normals.empty()) out_.corner_normal = out_.corner_position;
    else out_.normals.clear();
    // A texture-coordinate set of the concatenation must cover every triangle (Polygons::Uvs): it
    // is kept when every primitive instance with a triangle has it, else dropped and said.
    size_t with_triangles = 0;
    std::map<int, size_t> having;
    for (const Instance& in : instances_)
      if (in.polygon_end > in.polygon_begin) {
        ++with_triangles;
        for (int n : in.texcoords) ++having[n];
      }
    for (auto& [n, rows] : texcoord_rows_) {
      const std::string attribute = "TEXCOORD_" + std::to_string(n);
      if (having[n] == with_triangles) {
        rows.resize(out_.positions.size());
        out_.uv_sets.push_back({attribute, std::move(rows), out_.corner_position});
      } else {
        file_.warnings.push_back(attribute + " is on " + std::to_string(having[n]) + " of " + std::to_string(with_triangles) +
                                 " primitive instances with triangles; not read (a texture coordinate set must cover every triangle)");
      }
    }
    return std::move(out_);
  }

  void keep_lights(bool keep) { keep_lights_ = keep; }
  const std::vector<GltfLight>& lights() const { return lights_; }

  // A node's KHR_lights_punctual light ({"extensions": {"KHR_lights_punctual": {"light": i}}}),
  // placed by the node's world transform.
  void add_light(const tinygltf::Node& node, const Eigen::Matrix4d& world, const std::string& path) {
    const auto ext = node.extensions.find("KHR_lights_punctual");
    if (ext == node.extensions.end() || !keep_lights_) return;
    const tinygltf::Value& v = ext->second;
    if (!v.IsObject() || !v.Has("light") || !v.Get("light").IsNumber())
      fail("node " + path + ": KHR_lights_punctual needs \"light\", the index of a light");
    const double index = v.Get("light").GetNumberAsDouble();
    if (!(index >= 0 && index < double(model_.lights.size())) || index != std::floor(index))
      fail("node " + path + " refers to light " + std::to_string(index) + ", which does not exist (" +
           std::to_string(model_.lights.size()) + " lights)");
    const tinygltf::Light& l = model_.lights[size_t(index)];
    GltfLight& out = lights_.emplace_back();
    out.name = l.name;
    out.index = size_t(index);
    out.node_path = path;
    out.type = l.type;
    if (l.type != "directional" && l.type != "point" && l.type != "spot")
      fail("light " + std::to_string(out.index) + " (\"" + l.name + "\"): type \"" + l.type +
           "\" is not one of KHR_lights_punctual's directional, point, spot");
    out.position = world.topRightCorner<3, 1>();
    const Eigen::Vector3d d = world.topLeftCorner<3, 3>() * Eigen::Vector3d(0, 0, -1);
    out.direction = d.norm() > 0 ? Eigen::Vector3d(d.normalized()) : Eigen::Vector3d::Zero();
    if (l.color.size() >= 3) out.color = {l.color[0], l.color[1], l.color[2]};
    out.intensity = l.intensity;
    out.inner_cone = l.spot.innerConeAngle;
    out.outer_cone = l.spot.outerConeAngle;
    out.range = l.range;
  }

  std::vector<GltfInstance> read_instances() {
    walk();
    std::vector<GltfInstance> result;
    size_t empty = 0;
    for (const Instance& in : instances_) {
      if (in.polygon_end == in.polygon_begin) {
        ++empty;
        continue;
      }
      GltfInstance& out = result.emplace_back();
      out.name = in.name;
      out.node_path = in.node_path;
      out.animated = in.animated;
      if (in.material >= 0) {
        if (static_cast<size_t>(in.material) >= model_.materials.size())
          fail("node " + out.node_path + " refers to material " + std::to_string(in.material) + ", which does not exist (" +
               std::to_string(model_.materials.size()) + " materials)");
        const std::vector<double>& f = model_.materials[static_cast<size_t>(in.material)].pbrMetallicRoughness.baseColorFactor;
        if (f.size() < 3) fail("material " + std::to_string(in.material) + ": baseColorFactor has " + std::to_string(f.size()) + " numbers, needs 4");
        out.base_color = std::array<double, 3>{f[0], f[1], f[2]};
      }
      // The instance's rows, normals and polygons, re-based to its own first row.
      const size_t first = out_.offsets[in.polygon_begin], last = out_.offsets[in.polygon_end];
      const auto base = static_cast<uint32_t>(in.position_begin);
      const size_t rows = next_position_begin(in) - in.position_begin;
      Polygons& p = out.polygons;
      p.positions.assign(out_.positions.begin() + std::ptrdiff_t(in.position_begin), out_.positions.begin() + std::ptrdiff_t(in.position_begin + rows));
      p.corner_position.assign(out_.corner_position.begin() + std::ptrdiff_t(first), out_.corner_position.begin() + std::ptrdiff_t(last));
      for (uint32_t& c : p.corner_position) c -= base;
      for (size_t f = in.polygon_begin; f < in.polygon_end; ++f) p.offsets.push_back(out_.offsets[f + 1] - static_cast<uint32_t>(first));
      if (in.has_normals) {
        p.normals.assign(out_.normals.begin() + std::ptrdiff_t(in.normal_begin), out_.normals.begin() + std::ptrdiff_t(in.normal_begin + rows));
        p.corner_normal = p.corner_position;
      }
      std::vector<int> sets = in.texcoords;  // attribute (name) order: by n
      std::sort(sets.begin(), sets.end());
      for (int n : sets) {
        const std::vector<Eigen::Vector2f>& all = texcoord_rows_.at(n);
        p.uv_sets.push_back({"TEXCOORD_" + std::to_string(n),
                             {all.begin() + std::ptrdiff_t(in.position_begin), all.begin() + std::ptrdiff_t(in.position_begin + rows)},
                             p.corner_position});
      }
    }
    if (empty > 0)
      file_.warnings.push_back(std::to_string(empty) + " triangle primitive instance(s) without a triangle skipped");
    if (result.empty()) fail("no triangles: no primitive instance has a triangle, nothing to bake");
    return result;
  }

 private:
  // A primitive instance of the walk: its name, and where its rows, normals and polygons are in out_.
  struct Instance {
    std::string name, node_path;
    int material;
    size_t position_begin, normal_begin;
    bool has_normals;
    size_t polygon_begin, polygon_end;
    bool animated;                 // an animation channel moves its node or an ancestor
    std::vector<int> texcoords{};  // the n of its TEXCOORD_n attributes (values in texcoord_rows_)
  };
  // The first row after `in`'s: the next instance's first row, or the end.
  size_t next_position_begin(const Instance& in) const {
    const size_t i = static_cast<size_t>(&in - instances_.data());
    return i + 1 < instances_.size() ? instances_[i + 1].position_begin : out_.positions.size();
  }

  const tinygltf::Model& model_;
  const SourceFile& file_;
  Polygons out_;
  std::vector<Instance> instances_;
  bool keep_lights_ = false;
  std::vector<GltfLight> lights_;
  // TEXCOORD_n's values by n, one per row of out_ up to the last instance that has the set.
  std::map<int, std::vector<Eigen::Vector2f>> texcoord_rows_;
  bool all_have_normals_ = true;
  size_t skipped_primitives_ = 0, skinned_instances_ = 0, morphed_primitives_ = 0;
};

// The JSON of a .gltf, or of a .glb's first chunk where the container is sound (else empty:
// tinygltf refuses the container before it parses any JSON).
std::string_view gltf_json(std::string_view bytes, bool binary) {
  if (!binary) return bytes;
  if (bytes.size() < 20) return {};
  uint32_t length = 0;
  std::memcpy(&length, bytes.data() + 12, 4);  // little endian, as glTF and prtbake's hosts
  if (bytes.substr(16, 4) != "JSON" || length > bytes.size() - 20) return {};
  return bytes.substr(20, length);
}

// What the preflight parse finds: the buffers' declared bytes (at most kMaxBufferFileBytes) and how
// many of them are external files.
ReadBudget preflight(std::string_view text, const SourceFile& file) {
  using nlohmann::json;
  const json::parser_callback_t depth_limit = [&](int depth, json::parse_event_t, json&) {
    if (depth > kMaxJsonDepth)
      throw InputError(file.name, "JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
    return true;
  };
  json doc;
  try {
    doc = json::parse(text.begin(), text.end(), depth_limit);
  } catch (const json::exception& e) {  // "[json.exception.parse_error.101] parse error at line 1, column 11: ..."
    const std::string what = e.what();
    const size_t bracket = what.find("] ");
    throw InputError(file.name, "not a valid glTF: " + one_line(bracket == std::string::npos ? what : what.substr(bracket + 2)));
  }
  if (!doc.is_object()) return {};  // not a glTF: tinygltf refuses it with its message
  // glTF 1.0 (asset.version "1.0", "1.0.2", or the number 1 in some exporters) has another schema:
  // say so rather than let its missing 2.0 properties speak.
  if (const auto asset = doc.find("asset"); asset != doc.end() && asset->is_object())
    if (const auto v = asset->find("version"); v != asset->end()) {
      const std::string version = v->is_string() ? v->get<std::string>() : v->is_number() ? v->dump() : std::string();
      if (version == "1" || version.starts_with("1."))
        throw InputError(file.name, "is glTF " + version + " (asset.version): only glTF 2.0 is read; convert it to 2.0");
    }
  if (const auto it = doc.find("extensionsRequired"); it != doc.end() && it->is_array())
    for (const json& ext : *it)
      if (ext.is_string() && std::find(std::begin(kUnsupportedExtensions), std::end(kUnsupportedExtensions),
                                       ext.get_ref<const std::string&>()) != std::end(kUnsupportedExtensions))
        throw InputError(file.name, "requires extension " + shown(ext.get_ref<const std::string&>()) + ", which is not supported");
  ReadBudget budget;
  budget.digests = file.referenced_sha256;
  if (const auto it = doc.find("buffers"); it != doc.end() && it->is_array())
    for (const json& buffer : *it) {
      if (!buffer.is_object()) continue;
      if (const auto n = buffer.find("byteLength"); n != buffer.end() && n->is_number_unsigned())
        budget.remaining = std::min(kMaxBufferFileBytes, budget.remaining + std::min(kMaxBufferFileBytes, n->get<uintmax_t>()));
      if (const auto uri = buffer.find("uri"); uri != buffer.end() && uri->is_string() &&
                                                uri->get_ref<const std::string&>().rfind("data:", 0) != 0)
        ++budget.buffer_files;
    }
  return budget;
}

// tinygltf's parse of the whole file (buffers resolved, images not decoded).
tinygltf::Model parse(std::string_view bytes, const SourceFile& file) {
  if (bytes.size() >= std::numeric_limits<unsigned int>::max()) throw InputError(file.name, "too large for the glTF parser");
  const bool binary = bytes.substr(0, 4) == "glTF";
  if (binary && bytes.size() >= 8 && bytes.substr(4, 4) == std::string_view("\x01\0\0\0", 4))
    throw InputError(file.name, "is a glTF 1.0 binary (.glb container version 1): only glTF 2.0 is read; convert it to 2.0");
  ReadBudget budget = preflight(gltf_json(bytes, binary), file);
  tinygltf::TinyGLTF loader;
  loader.SetFsCallbacks({file_exists, expand_nothing, read_buffer_file, write_nothing, &budget});
  loader.SetImageLoader(skip_image, nullptr);
  tinygltf::Model model;
  std::string err, warn;
  const std::string base_dir = file.path.parent_path().string();
  const auto length = static_cast<unsigned int>(bytes.size());
  const bool ok = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, reinterpret_cast<const unsigned char*>(bytes.data()), length, base_dir)
                         : loader.LoadASCIIFromString(&model, &err, &warn, bytes.data(), length, base_dir);
  // tinygltf's warnings concern images and unknown properties, none of which a bake uses.
  if (!ok) throw InputError(file.name, err.empty() ? std::string("is not a valid glTF file") : "not a valid glTF: " + one_line(err));
  return model;
}

} // namespace

Polygons read_gltf(std::string_view bytes, const SourceFile& file) {
  return Reader(parse(bytes, file), file).read();
}

std::vector<GltfInstance> read_gltf_instances(std::string_view bytes, const SourceFile& file, std::vector<GltfLight>* lights) {
  const tinygltf::Model model = parse(bytes, file);  // the reader keeps a reference to it
  Reader reader(model, file);
  reader.keep_lights(lights != nullptr);
  std::vector<GltfInstance> instances = reader.read_instances();
  if (lights != nullptr) *lights = reader.lights();
  return instances;
}

} // namespace prt::bake::mesh_readers
