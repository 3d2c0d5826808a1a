// mesh_readers.cpp — OBJ, PLY, OFF and STL bytes to Polygons, one pass each (contracts in
// mesh_readers.h and bake/mesh/mesh.h).
#include <bake/mesh/mesh_readers.h>

#include <bake/core/error.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <iterator>
#include <limits>
#include <span>

namespace prt::bake::mesh_readers {
namespace {

// --- text helpers --------------------------------------------------------------------------

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> split(std::string_view s) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && is_space(s[i])) ++i;
    const size_t start = i;
    while (i < s.size() && !is_space(s[i])) ++i;
    if (i > start) out.push_back(s.substr(start, i - start));
  }
  return out;
}

// Lines of a text, numbered from 1, '\n' separated ('\r' is trimmed as whitespace).
class LineReader {
public:
  explicit LineReader(std::string_view text) : text_(text) {}
  bool next(std::string_view& line) {
    if (pos_ >= text_.size()) return false;
    const size_t end = text_.find('\n', pos_);
    const size_t stop = end == std::string_view::npos ? text_.size() : end;
    line = text_.substr(pos_, stop - pos_);
    pos_ = stop + 1;
    ++number_;
    return true;
  }
  size_t number() const { return number_; }

private:
  std::string_view text_;
  size_t pos_ = 0, number_ = 0;
};

std::string at_line(size_t line) { return "line " + std::to_string(line) + ": "; }

// A finite float, whole token (correctly rounded, as the C library's strtof). Returns an empty
// string on success, else the defect.
// A leading '+' is accepted (C's strtof and many exporters write it; std::from_chars does not).
std::string_view without_plus(std::string_view tok) {
  return tok.size() > 1 && tok[0] == '+' && tok[1] != '-' && tok[1] != '+' ? tok.substr(1) : tok;
}

std::string parse_float(std::string_view tok, float& value) {
  const std::string_view digits = without_plus(tok);
  const char* end = digits.data() + digits.size();
  auto [ptr, ec] = std::from_chars(digits.data(), end, value);
  if (ec == std::errc::result_out_of_range) return "coordinate " + shown(tok) + " is out of float range";
  if (ec != std::errc() || ptr != end) return "malformed number " + shown(tok);
  if (!std::isfinite(value)) return "non-finite coordinate " + shown(tok);
  return {};
}

// A finite coordinate, whole token, in double: the nearest double to the text, except where that
// double lies exactly halfway between two floats and rounding it to float would not give the
// correctly rounded float of the text (double rounding); it is then moved one double ulp towards
// that float. So float(value) is always what parse_float gives: a mesh read in double and
// rounded to float once (bake/mesh/mesh.h, origin 0) has the positions it had when read in float.
// Range errors are parse_float's (a coordinate must be a finite float).
std::string parse_coordinate(std::string_view tok, double& value) {
  float f = 0;
  if (auto defect = parse_float(tok, f); !defect.empty()) return defect;
  const std::string_view digits = without_plus(tok);
  std::from_chars(digits.data(), digits.data() + digits.size(), value);  // succeeds where the float parse did
  if (static_cast<float>(value) != f) value = std::nextafter(value, static_cast<double>(f));
  return {};
}
std::string parse_real(std::string_view tok, float& value) { return parse_float(tok, value); }
std::string parse_real(std::string_view tok, double& value) { return parse_coordinate(tok, value); }

bool parse_int(std::string_view tok, long long& value) {
  const char* end = tok.data() + tok.size();
  auto [ptr, ec] = std::from_chars(tok.data(), end, value);
  return ec == std::errc() && ptr == end;
}

// Three values from tokens [first, first + 3), or InputError at `line`: normals in float
// (parse_float), positions in double (parse_coordinate).
template <class Vec> Vec parse_vec3(const SourceFile& file, std::span<const std::string_view> tok, size_t line) {
  Vec v;
  for (int k = 0; k < 3; ++k) {
    if (auto defect = parse_real(tok[static_cast<size_t>(k)], v[k]); !defect.empty())
      throw InputError(file.name, at_line(line) + defect);
  }
  return v;
}

// PLY and OFF give normals per vertex: every corner uses its position's.
void corner_normals_per_vertex(Polygons& poly) { poly.corner_normal = poly.corner_position; }

// --- OBJ -------------------------------------------------------------------------------------

// OBJ statements that carry no triangle data and are accepted (Wavefront OBJ spec, Appendix B1,
// plus the `vc` colour extension). Any other keyword makes the line garbage.
bool obj_ignored_keyword(std::string_view kw) {
  static constexpr std::string_view kKnown[] = {
      "vp", "vc", "l", "p", "g", "o", "s", "mg", "mtllib", "usemtl", "cstype", "deg", "bmat", "step",
      "curv", "curv2", "surf", "parm", "trim", "hole", "scrv", "sp", "end", "con", "bevel", "c_interp",
      "d_interp", "lod", "shadow_obj", "trace_obj", "ctech", "stech", "maplib", "usemap"};
  return std::find(std::begin(kKnown), std::end(kKnown), kw) != std::end(kKnown);
}

} // namespace

std::string shown(std::string_view s) {
  constexpr size_t kMax = 40;
  std::string out = "'";
  for (char c : s.substr(0, kMax)) out += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  return out + (s.size() > kMax ? "...'" : "'");
}

std::string lowercase(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

Polygons read_obj(std::string_view text, const SourceFile& file) {
  Polygons poly;
  // `vt` values in glTF's convention (u, 1 − v), and each corner's index into them or kNoNormal
  // (the same "none" marker as normals).
  std::vector<Eigen::Vector2f> texcoords;
  std::vector<uint32_t> corner_texcoord;
  size_t corners_with_texcoord = 0;
  // Positive indices may point forward (to `v` lines further down): checked at the end.
  struct Pending { long long index; size_t line; char kind; };
  std::vector<Pending> forward;
  auto kind_name = [](char kind) { return kind == 'v' ? "vertex" : kind == 'n' ? "normal" : "texcoord"; };
  LineReader lines(text);
  std::string_view line;
  while (lines.next(line)) {
    const size_t ln = lines.number();
    line = trim(line);
    if (line.empty() || line.front() == '#') continue;
    const auto tok = split(line);
    const std::string_view kw = tok[0];
    if (kw == "v" || kw == "vn") {
      if (tok.size() < 4) throw InputError(file.name, at_line(ln) + "'" + std::string(kw) + "' needs 3 coordinates");
      const auto values = std::span(tok).subspan(1);
      if (kw == "v") poly.positions.push_back(parse_vec3<Eigen::Vector3d>(file, values, ln));
      else poly.normals.push_back(parse_vec3<Eigen::Vector3f>(file, values, ln));
    } else if (kw == "vt") {
      // "vt u v [w]": w (3D textures) is neither read nor kept.
      float x[2] = {};
      if (tok.size() < 3) throw InputError(file.name, at_line(ln) + "'vt' needs 2 coordinates");
      for (size_t k = 0; k < 2; ++k)
        if (auto defect = parse_float(tok[k + 1], x[k]); !defect.empty())
          throw InputError(file.name, at_line(ln) + defect);
      texcoords.emplace_back(x[0], 1.0f - x[1]);
    } else if (kw == "f") {
      if (tok.size() < 4)
        throw InputError(file.name, at_line(ln) + "face has " + std::to_string(tok.size() - 1) + " corners, needs at least 3");
      for (size_t c = 1; c < tok.size(); ++c) {
        std::string_view part[3];
        int n_parts = 0;
        std::string_view rest = tok[c];
        while (true) {
          if (n_parts == 3) throw InputError(file.name, at_line(ln) + "malformed face corner " + shown(tok[c]));
          const size_t slash = rest.find('/');
          part[n_parts++] = rest.substr(0, slash);
          if (slash == std::string_view::npos) break;
          rest.remove_prefix(slash + 1);
        }
        // One index, 0-based: 1-based in the file, negative = relative to the count so far (OBJ spec).
        auto resolve = [&](std::string_view s, size_t so_far, char kind) -> uint32_t {
          long long i = 0;
          if (!parse_int(s, i) || i == 0)
            throw InputError(file.name, at_line(ln) + "malformed face corner " + shown(tok[c]) +
                                            (i == 0 && parse_int(s, i) ? " (OBJ indices start at 1)" : ""));
          if (i < 0) {
            if (static_cast<unsigned long long>(-i) > so_far)
              throw InputError(file.name, at_line(ln) + "relative index " + std::to_string(i) + " in corner " + shown(tok[c]) +
                                              " reaches before the first " + kind_name(kind) + " (" + std::to_string(so_far) +
                                              " so far)");
            return static_cast<uint32_t>(static_cast<long long>(so_far) + i);
          }
          if (static_cast<unsigned long long>(i) > so_far) forward.push_back({i, ln, kind});  // the rest are in range
          return static_cast<uint32_t>(std::min<long long>(i - 1, std::numeric_limits<uint32_t>::max()));
        };
        if (part[0].empty()) throw InputError(file.name, at_line(ln) + "face corner " + shown(tok[c]) + " has no vertex index");
        poly.corner_position.push_back(resolve(part[0], poly.positions.size(), 'v'));
        const bool has_texcoord = n_parts >= 2 && !part[1].empty();
        corner_texcoord.push_back(has_texcoord ? resolve(part[1], texcoords.size(), 't') : Polygons::kNoNormal);
        corners_with_texcoord += has_texcoord;
        const bool has_normal = n_parts == 3 && !part[2].empty();
        poly.corner_normal.push_back(has_normal ? resolve(part[2], poly.normals.size(), 'n') : Polygons::kNoNormal);
      }
      poly.end_polygon();
    } else if (!obj_ignored_keyword(kw)) {
      throw InputError(file.name, at_line(ln) + "not an OBJ statement: " + shown(line));
    }
  }
  for (const Pending& p : forward) {
    const size_t count = p.kind == 'v' ? poly.positions.size() : p.kind == 'n' ? poly.normals.size() : texcoords.size();
    if (static_cast<unsigned long long>(p.index) > count)
      throw InputError(file.name, at_line(p.line) + kind_name(p.kind) + " index " + std::to_string(p.index) +
                                      " is out of range (the file has " + std::to_string(count) + ")");
  }
  // One set "vt" when every face corner has a texture coordinate (bake/mesh/mesh.h Polygons::Uvs).
  const size_t corners = poly.corner_position.size();
  if (corners_with_texcoord == corners && corners > 0)
    poly.uv_sets.push_back({"vt", std::move(texcoords), std::move(corner_texcoord)});
  else if (corners_with_texcoord > 0)
    file.warnings.push_back(std::to_string(corners - corners_with_texcoord) + " of " + std::to_string(corners) +
                            " face corners have no texture coordinate (f v/vt); the file's texture coordinates are not read");
  return poly;
}

// --- PLY (Turk's format: ascii, binary_little_endian, binary_big_endian) ----------------------

namespace {

enum class PlyType { Int8, Uint8, Int16, Uint16, Int32, Uint32, Float32, Float64 };

struct PlyProperty {
  bool list = false;
  PlyType count_type = PlyType::Uint8, type = PlyType::Float32;
  std::string name;
};
struct PlyElement {
  std::string name;
  size_t count = 0;
  std::vector<PlyProperty> props;
};

int ply_size(PlyType t) {
  switch (t) {
    case PlyType::Int8: case PlyType::Uint8: return 1;
    case PlyType::Int16: case PlyType::Uint16: return 2;
    case PlyType::Int32: case PlyType::Uint32: case PlyType::Float32: return 4;
    case PlyType::Float64: return 8;
  }
  return 0;
}

// One binary PLY value, widened: integers and floats exactly (normals are rounded to float by the slot).
struct PlyValue {
  long long integer = 0;
  double real = 0;
};

PlyValue ply_binary_value(const char* p, PlyType t, bool big_endian) {
  unsigned char b[8] = {};
  const int n = ply_size(t);
  std::memcpy(b, p, static_cast<size_t>(n));
  if (big_endian) std::reverse(b, b + n);  // the host is little endian (prtbake's targets)
  PlyValue v;
  auto get = [&]<typename T>(T) { T x; std::memcpy(&x, b, sizeof x); return x; };
  switch (t) {
    case PlyType::Int8: v.integer = get(int8_t{}); break;
    case PlyType::Uint8: v.integer = get(uint8_t{}); break;
    case PlyType::Int16: v.integer = get(int16_t{}); break;
    case PlyType::Uint16: v.integer = get(uint16_t{}); break;
    case PlyType::Int32: v.integer = get(int32_t{}); break;
    case PlyType::Uint32: v.integer = get(uint32_t{}); break;
    case PlyType::Float32: v.real = get(float{}); return v;
    case PlyType::Float64: v.real = get(double{}); return v;
  }
  v.real = static_cast<double>(v.integer);
  return v;
}

// What the reader does with a vertex property: a coordinate of the position (double), or a
// component of the normal or of the texture coordinate (float).
struct VertexSlot {
  double* position = nullptr;
  float* value = nullptr;
  explicit operator bool() const { return position || value; }
  // Parses the ascii value into the slot; the defect, or empty.
  std::string parse(std::string_view tok) const {
    return position ? parse_coordinate(tok, *position) : parse_float(tok, *value);
  }
  // Stores a binary value: positions keep it (float32 widens exactly), the rest round to float.
  void store(double v) const {
    if (position) *position = v;
    else *value = static_cast<float>(v);
  }
};

// The vertex property pairs read as texture coordinates, the first the vertex element has: Turk's
// PLY names none, and exporters write (u, v), (s, t) (Blender) or (texture_u, texture_v) (VCG,
// MeshLab).
constexpr std::array<std::array<std::string_view, 2>, 3> kPlyTexcoordNames = {{{"u", "v"}, {"s", "t"}, {"texture_u", "texture_v"}}};

} // namespace

Polygons read_ply(std::string_view text, const SourceFile& file) {
  auto type_of = [&](std::string_view t, size_t ln) {
    if (t == "char" || t == "int8") return PlyType::Int8;
    if (t == "uchar" || t == "uint8") return PlyType::Uint8;
    if (t == "short" || t == "int16") return PlyType::Int16;
    if (t == "ushort" || t == "uint16") return PlyType::Uint16;
    if (t == "int" || t == "int32") return PlyType::Int32;
    if (t == "uint" || t == "uint32") return PlyType::Uint32;
    if (t == "float" || t == "float32") return PlyType::Float32;
    if (t == "double" || t == "float64") return PlyType::Float64;
    throw InputError(file.name, at_line(ln) + "unknown PLY property type " + shown(t));
  };
  std::vector<PlyElement> elements;
  std::string format;
  LineReader lines(text);
  std::string_view line;
  size_t body = std::string_view::npos;
  if (!lines.next(line) || trim(line) != "ply") throw InputError(file.name, "not a PLY file (first line is not 'ply')");
  size_t keywordless = 0;
  std::string first_keywordless;
  while (lines.next(line)) {
    const size_t ln = lines.number();
    const auto tok = split(line);
    if (tok.empty() || tok[0] == "comment" || tok[0] == "obj_info") continue;
    if (tok[0] == "format") {
      // "format <kind> 1.0": the only version of the format (Turk's PLY description).
      if (tok.size() != 3 || tok[2] != "1.0") throw InputError(file.name, at_line(ln) + "malformed PLY format line " + shown(trim(line)) + " (expected 'format <ascii|binary_little_endian|binary_big_endian> 1.0')");
      format = tok[1];
    } else if (tok[0] == "element" && tok.size() == 3) {
      long long n = 0;
      if (!parse_int(tok[2], n) || n < 0) throw InputError(file.name, at_line(ln) + "bad element count " + shown(tok[2]));
      // The reader keeps one vertex and one face element: a second would be indexed with the
      // first one's rows.
      for (const PlyElement& e : elements)
        if (e.name == tok[1] && (e.name == "vertex" || e.name == "face"))
          throw InputError(file.name, at_line(ln) + "a second '" + e.name + "' element");
      elements.push_back({std::string(tok[1]), static_cast<size_t>(n), {}});
    } else if (tok[0] == "property" && !elements.empty()) {
      if (tok.size() == 5 && tok[1] == "list")
        elements.back().props.push_back({true, type_of(tok[2], ln), type_of(tok[3], ln), std::string(tok[4])});
      else if (tok.size() == 3)
        elements.back().props.push_back({false, PlyType::Uint8, type_of(tok[1], ln), std::string(tok[2])});
      else
        throw InputError(file.name, at_line(ln) + "malformed property " + shown(line));
    } else if (tok[0] == "end_header") {
      body = static_cast<size_t>(line.data() + line.size() - text.data()) + 1;
      break;
    } else if (tok[0] == "format" || tok[0] == "element" || tok[0] == "property") {
      throw InputError(file.name, at_line(ln) + "malformed PLY header line " + shown(line));
    } else {
      // A line with no keyword: Blender 2.4x wrote "Created by Blender3D …" without "comment".
      // Nothing in it describes the data, so it is read as a comment, and said (the first one by
      // line, the rest counted).
      if (keywordless++ == 0) first_keywordless = at_line(ln) + "PLY header line " + shown(trim(line));
    }
  }
  if (body == std::string_view::npos) throw InputError(file.name, "PLY header has no 'end_header' (truncated?)");
  if (keywordless > 0)
    file.warnings.push_back(first_keywordless + " has no keyword" +
                            (keywordless > 1 ? " (and " + std::to_string(keywordless - 1) + " more header lines)" : "") +
                            "; read as a comment");
  if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian")
    throw InputError(file.name, "unknown PLY format " + shown(format));
  const bool binary = format != "ascii", big_endian = format == "binary_big_endian";
  body = std::min(body, text.size());

  auto is_face_list = [](const PlyElement& e, const PlyProperty& p) {
    return e.name == "face" && p.list && (p.name == "vertex_indices" || p.name == "vertex_index");
  };
  // Every item takes at least this many bytes (binary: its scalars and list counts; ascii: one
  // character and one separator per property), so a count the file cannot hold is refused
  // before anything is allocated for it.
  for (const PlyElement& e : elements) {
    size_t per_item = 0;
    for (const PlyProperty& p : e.props) per_item += binary ? static_cast<size_t>(ply_size(p.list ? p.count_type : p.type)) : 2;
    if (per_item > 0 && e.count > (text.size() - body + 1) / per_item)
      throw InputError(file.name, "truncated: the header declares " + std::to_string(e.count) + " " + e.name +
                                      " items of at least " + std::to_string(per_item) + " bytes each, but " +
                                      std::to_string(text.size() - body) + " bytes follow the header");
  }
  Polygons poly;
  bool has_normals = false;
  const std::array<std::string_view, 2>* texcoord_names = nullptr;  // the pair the vertex element has, if any
  std::vector<Eigen::Vector2f> texcoords;
  for (const PlyElement& e : elements) {
    if (e.name == "vertex") {
      for (const char* axis : {"x", "y", "z"})
        if (std::none_of(e.props.begin(), e.props.end(), [&](const PlyProperty& p) { return !p.list && p.name == axis; }))
          throw InputError(file.name, std::string("PLY vertex element has no '") + axis + "' property");
      has_normals = std::any_of(e.props.begin(), e.props.end(),
                                [](const PlyProperty& p) { return !p.list && (p.name == "nx" || p.name == "ny" || p.name == "nz"); });
      poly.positions.assign(e.count, Eigen::Vector3d::Zero());
      if (has_normals) poly.normals.assign(e.count, Eigen::Vector3f::Zero());
      auto has = [&](std::string_view name) {
        return std::any_of(e.props.begin(), e.props.end(), [&](const PlyProperty& p) { return !p.list && p.name == name; });
      };
      for (const auto& pair : kPlyTexcoordNames)
        if (!texcoord_names && has(pair[0]) && has(pair[1])) texcoord_names = &pair;
      if (texcoord_names) texcoords.assign(e.count, Eigen::Vector2f::Zero());
    }
    if (e.name == "face" && e.count > 0 &&
        std::none_of(e.props.begin(), e.props.end(), [&](const PlyProperty& p) { return is_face_list(e, p); }))
      throw InputError(file.name, "PLY face element has no 'vertex_indices' list");
  }
  const size_t n_vertices = poly.positions.size();
  auto slot_of = [&](const PlyElement& e, const PlyProperty& p, size_t item) -> VertexSlot {
    if (e.name != "vertex" || p.list || p.name.empty()) return {};
    const std::string_view n = p.name;
    if (texcoord_names)
      for (int k = 0; k < 2; ++k)
        if (n == (*texcoord_names)[static_cast<size_t>(k)]) return {nullptr, &texcoords[item][k]};
    const int axis = n.back() - 'x';
    if (axis < 0 || axis > 2) return {};
    if (n.size() == 1) return {&poly.positions[item][axis], nullptr};
    if (n.size() == 2 && n[0] == 'n') return {nullptr, &poly.normals[item][axis]};
    return {};
  };
  auto truncated = [&](const PlyElement& e, size_t item) {
    return InputError(file.name, "truncated: the file ends inside " + e.name + " " + std::to_string(item) + " of " +
                                     std::to_string(e.count));
  };
  // One face's corner list has been read: n corners, each index i (as written).
  auto begin_face = [&](long long corners, size_t face, size_t ln) {
    if (corners < 3)
      throw InputError(file.name, (ln ? at_line(ln) : std::string()) + "face " + std::to_string(face) + " has " +
                                      std::to_string(corners) + " corners, needs at least 3");
  };
  auto add_corner = [&](long long i, size_t face, size_t ln) {
    if (i < 0 || static_cast<size_t>(i) >= n_vertices)
      throw InputError(file.name, "face " + std::to_string(face) + (ln ? " (line " + std::to_string(ln) + ")" : std::string()) +
                                      ": vertex index " + std::to_string(i) + " is out of range [0, " +
                                      std::to_string(n_vertices) + ")");
    poly.corner_position.push_back(static_cast<uint32_t>(i));
  };

  if (!binary) {
    size_t pos = body, ln = lines.number() + 1;
    std::string_view tok;
    size_t tok_line = 0;
    auto next_token = [&]() {
      while (pos < text.size() && is_space(text[pos])) ln += text[pos++] == '\n';
      if (pos >= text.size()) return false;
      const size_t start = pos;
      while (pos < text.size() && !is_space(text[pos])) ++pos;
      tok = text.substr(start, pos - start);
      tok_line = ln;
      return true;
    };
    for (const PlyElement& e : elements) {
      if (e.props.empty()) continue;  // items of no bytes (any count): nothing to read
      for (size_t item = 0; item < e.count; ++item) {
        size_t item_line = 0;
        for (const PlyProperty& p : e.props) {
          if (!next_token()) throw truncated(e, item);
          if (!item_line) item_line = tok_line;
          if (!p.list) {
            // Values are read as their slot's type whatever the declared type (one rounding from
            // the text): positions in double, normals in float.
            if (const VertexSlot s = slot_of(e, p, item))
              if (auto defect = s.parse(tok); !defect.empty())
                throw InputError(file.name, at_line(tok_line) + defect);
            continue;
          }
          long long n = 0;
          if (!parse_int(tok, n) || n < 0) throw InputError(file.name, at_line(tok_line) + "bad list length " + shown(tok));
          const bool face = is_face_list(e, p);
          if (face) begin_face(n, item, item_line);
          for (long long k = 0; k < n; ++k) {
            if (!next_token()) throw truncated(e, item);
            if (!face) continue;
            long long i = 0;
            if (!parse_int(tok, i)) throw InputError(file.name, at_line(tok_line) + "malformed index " + shown(tok));
            add_corner(i, item, item_line);
          }
          if (face) poly.end_polygon();
        }
      }
    }
  } else {
    size_t pos = body;
    auto take = [&](PlyType t, const PlyElement& e, size_t item) {
      if (text.size() - pos < static_cast<size_t>(ply_size(t))) throw truncated(e, item);
      const PlyValue v = ply_binary_value(text.data() + pos, t, big_endian);
      pos += static_cast<size_t>(ply_size(t));
      return v;
    };
    for (const PlyElement& e : elements) {
      if (e.props.empty()) continue;  // items of no bytes (any count): nothing to read
      for (size_t item = 0; item < e.count; ++item) {
        for (const PlyProperty& p : e.props) {
          if (!p.list) {
            const PlyValue v = take(p.type, e, item);
            if (const VertexSlot s = slot_of(e, p, item)) s.store(v.real);
            continue;
          }
          // Counts are unsigned in practice; a negative signed count is caught as too large.
          const long long n = take(p.count_type, e, item).integer;
          if (n < 0 || static_cast<unsigned long long>(n) > (text.size() - pos) / static_cast<size_t>(ply_size(p.type)))
            throw truncated(e, item);
          if (!is_face_list(e, p)) {
            pos += static_cast<size_t>(n) * static_cast<size_t>(ply_size(p.type));
            continue;
          }
          begin_face(n, item, 0);
          for (long long k = 0; k < n; ++k) add_corner(take(p.type, e, item).integer, item, 0);
          poly.end_polygon();
        }
      }
    }
  }
  if (has_normals) corner_normals_per_vertex(poly);
  // Per vertex, like the normals; v is up the image in PLY as in OBJ: to glTF's convention.
  if (texcoord_names) {
    for (Eigen::Vector2f& uv : texcoords) uv.y() = 1.0f - uv.y();
    poly.uv_sets.push_back({"uv", std::move(texcoords), poly.corner_position});
  }
  return poly;
}

// --- OFF (ascii): "[ST][C][N]OFF", then "nV nF nE", nV vertex lines, nF face lines -------------

Polygons read_off(std::string_view text, const SourceFile& file) {
  Polygons poly;
  LineReader lines(text);
  std::string_view line;
  // Non-empty lines. '#' comments are refused, as they always were: files with them were never
  // accepted (OpenMesh's OFF reader, used before, misread them), so no shipped asset has one.
  auto next_line = [&](std::vector<std::string_view>& tok) {
    while (lines.next(line)) {
      if (line.find('#') != std::string_view::npos)
        throw InputError(file.name, at_line(lines.number()) + "'#' comments in OFF are not supported");
      tok = split(line);
      if (!tok.empty()) return true;
    }
    return false;
  };
  std::vector<std::string_view> tok;
  if (!next_line(tok)) throw InputError(file.name, "empty file");
  std::string_view magic = tok[0];
  auto eat = [&](std::string_view prefix) {
    const bool found = magic.substr(0, prefix.size()) == prefix;
    if (found) magic.remove_prefix(prefix.size());
    return found;
  };
  eat("ST");
  eat("C");
  const bool has_normals = eat("N");
  if (magic != "OFF") throw InputError(file.name, at_line(lines.number()) + "not an OFF header: " + shown(tok[0]));
  if (tok.size() > 1 && tok[1] == "BINARY") throw InputError(file.name, "binary OFF is not supported");
  if (tok.size() > 1)
    throw InputError(file.name, at_line(lines.number()) + "counts on the OFF header line are not supported (they belong on the next line)");
  if (!next_line(tok)) throw InputError(file.name, "truncated: no vertex/face counts after the OFF header");
  long long nv = 0, nf = 0;
  if (tok.size() < 2 || !parse_int(tok[0], nv) || !parse_int(tok[1], nf) || nv < 0 || nf < 0)
    throw InputError(file.name, at_line(lines.number()) + "malformed OFF counts " + shown(trim(line)));
  const size_t numbers = has_normals ? 6 : 3;
  for (long long v = 0; v < nv; ++v) {
    if (!next_line(tok))
      throw InputError(file.name, "truncated: the header says " + std::to_string(nv) + " vertices, the file has " + std::to_string(v));
    if (tok.size() < numbers)
      throw InputError(file.name, at_line(lines.number()) + (has_normals ? "vertex needs 3 coordinates and 3 normal components"
                                                                         : "vertex needs 3 coordinates"));
    poly.positions.push_back(parse_vec3<Eigen::Vector3d>(file, tok, lines.number()));
    if (has_normals) poly.normals.push_back(parse_vec3<Eigen::Vector3f>(file, std::span(tok).subspan(3), lines.number()));
  }
  for (long long f = 0; f < nf; ++f) {
    if (!next_line(tok))
      throw InputError(file.name, "truncated: the header says " + std::to_string(nf) + " faces, the file has " + std::to_string(f));
    const size_t ln = lines.number();
    long long n = 0;
    if (!parse_int(tok[0], n) || n < 0) throw InputError(file.name, at_line(ln) + "malformed face " + shown(trim(line)));
    if (n < 3) throw InputError(file.name, at_line(ln) + "face has " + std::to_string(n) + " corners, needs at least 3");
    if (tok.size() < static_cast<size_t>(n) + 1)
      throw InputError(file.name, at_line(ln) + "face lists " + std::to_string(tok.size() - 1) + " of its " + std::to_string(n) + " indices");
    for (long long k = 1; k <= n; ++k) {  // tokens after the indices are the face's colour
      long long i = 0;
      if (!parse_int(tok[static_cast<size_t>(k)], i))
        throw InputError(file.name, at_line(ln) + "malformed index " + shown(tok[static_cast<size_t>(k)]));
      if (i < 0 || i >= nv)
        throw InputError(file.name, at_line(ln) + "vertex index " + std::to_string(i) + " is out of range [0, " + std::to_string(nv) + ")");
      poly.corner_position.push_back(static_cast<uint32_t>(i));
    }
    poly.end_polygon();
  }
  if (has_normals) corner_normals_per_vertex(poly);
  return poly;
}

// --- STL: binary iff the size is 84 + 50·n for the n in the header, else ASCII ----------------

Polygons read_stl(std::string_view text, const SourceFile& file) {
  Polygons poly;
  auto add_facet = [&] {
    for (size_t k = 3; k > 0; --k) poly.corner_position.push_back(static_cast<uint32_t>(poly.positions.size() - k));
    poly.end_polygon();
  };
  uint32_t n = 0;
  if (text.size() >= 84) std::memcpy(&n, text.data() + 80, 4);  // little endian; prtbake targets little-endian hosts
  if (text.size() >= 84 && text.size() == 84 + 50 * static_cast<uint64_t>(n)) {
    for (uint32_t f = 0; f < n; ++f) {
      const char* rec = text.data() + 84 + 50 * static_cast<size_t>(f);
      for (int k = 0; k < 3; ++k) {
        float c[3];
        std::memcpy(c, rec + 12 + 12 * k, 12);
        const Eigen::Vector3f p(c[0], c[1], c[2]);
        if (!p.allFinite()) throw InputError(file.name, "facet " + std::to_string(f) + " has a non-finite coordinate");
        poly.positions.push_back(p.cast<double>());  // exact
      }
      add_facet();
    }
    return poly;
  }
  const std::string_view head = trim(text.substr(0, 512));
  if (head.substr(0, 5) != "solid" || text.find('\0') != std::string_view::npos) {
    std::string defect = "not an STL file: no 'solid' header, and the size (" + std::to_string(text.size()) + " bytes)";
    if (text.size() >= 84)
      defect += " is not the 84 + 50 x " + std::to_string(n) + " bytes of a binary STL with " + std::to_string(n) +
                " facets (truncated?)";
    else
      defect += " is less than a binary STL header";
    throw InputError(file.name, defect);
  }
  LineReader lines(text);
  std::string_view line;
  size_t in_loop = 0, loop_line = 0;  // corners still expected in the current "outer loop"
  while (lines.next(line)) {
    const size_t ln = lines.number();
    const auto tok = split(line);
    if (tok.empty()) continue;
    const std::string kw = lowercase(std::string(tok[0]));
    if (kw == "vertex") {
      if (!in_loop) throw InputError(file.name, at_line(ln) + "'vertex' outside an 'outer loop'");
      if (tok.size() != 4) throw InputError(file.name, at_line(ln) + "'vertex' needs 3 coordinates");
      poly.positions.push_back(parse_vec3<Eigen::Vector3d>(file, std::span(tok).subspan(1), ln));
      if (--in_loop == 0) add_facet();
    } else if (in_loop) {
      throw InputError(file.name, at_line(ln) + "expected 'vertex' (" + std::to_string(in_loop) + " more in the loop from line " +
                                      std::to_string(loop_line) + ")");
    } else if (kw == "outer") {
      in_loop = 3;
      loop_line = ln;
    } else if (kw == "facet") {
      if (tok.size() >= 5) {  // the facet normal is checked but not used (bake/mesh/mesh.h)
        float x = 0;
        for (size_t k = 2; k < 5; ++k)
          if (auto defect = parse_float(tok[k], x); !defect.empty())
            throw InputError(file.name, at_line(ln) + "facet normal: " + defect);
      }
    } else if (kw != "solid" && kw != "endloop" && kw != "endfacet" && kw != "endsolid") {
      throw InputError(file.name, at_line(ln) + "not an STL statement: " + shown(trim(line)));
    }
  }
  if (in_loop) throw InputError(file.name, "truncated: the file ends inside the loop from line " + std::to_string(loop_line));
  return poly;
}

} // namespace prt::bake::mesh_readers
