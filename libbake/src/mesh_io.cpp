// mesh_io.cpp — load_mesh: OpenMesh's readers into a raw importer, cross-checked against an
// independent structural scan of the file (contracts in bake/mesh.h).
//
// What OpenMesh 9.0's readers hand an importer (found by running them against a logging
// BaseImporter, and in OBJReader.cc / STLReader.cc):
//   * OBJ: all `v` lines first (add_vertex, in file order; a `v` line whose three floats do not
//     parse is skipped silently, shifting every later row). Then per `f` line: for each corner
//     with a normal component, set_normal(VertexHandle(position), vn value) — one call per CORNER,
//     in corner order, immediately before that face's add_face — but only if the caller asked
//     for Options::VertexNormal (otherwise `vn` lines are not even stored). So per-corner normals
//     arrive as a sequence of vertex-normal calls; there is no halfedge-normal call. Then
//     add_face(corners with ALL repeated indices removed), skipped when fewer than 3 remain.
//     Indices are not range-checked (`f 1 2 9` with 4 vertices gives handle 8; a too-negative
//     index gives a negative handle).
//   * PLY / OFF: add_vertex()+set_point or add_vertex(p), set_normal(vertex) per vertex when the
//     file has normals and VertexNormal was asked for, add_face(raw indices, unchecked).
//   * STL: vertices merged by position (|Δ| ≤ FLT_MIN per coordinate), facets with two merged
//     corners skipped, facet normals via set_normal(FaceHandle). Binary iff the file size is
//     84 + 50·n for the n in the header, else ASCII.
// The scan below supplies the per-corner structure (OBJ corners, STL corner coordinates) so
// that what OpenMesh dropped by design is restored and everything else is verified.
#include <bake/error.h>
#include <bake/mesh.h>

#include "openmesh.h"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cerrno>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <mutex>
#include <sstream>
#include <string_view>
#include <unordered_map>

namespace prt::bake {
namespace {

enum class Format { Obj, Ply, Off, Stl };

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

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

std::string shown(std::string_view s) {
  constexpr size_t kMax = 40;
  std::string out = "'";
  for (char c : s.substr(0, kMax)) out += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  return out + (s.size() > kMax ? "...'" : "'");
}

std::string at_line(size_t line) { return "line " + std::to_string(line) + ": "; }

// A finite float, whole token. Returns an empty string on success, else the defect.
std::string parse_float(std::string_view tok, float& value) {
  const char* end = tok.data() + tok.size();
  auto [ptr, ec] = std::from_chars(tok.data(), end, value);
  if (ec == std::errc::result_out_of_range) return "coordinate " + shown(tok) + " is out of float range";
  if (ec != std::errc() || ptr != end) return "malformed number " + shown(tok);
  if (!std::isfinite(value)) return "non-finite coordinate " + shown(tok);
  return {};
}

bool parse_int(std::string_view tok, long long& value) {
  const char* end = tok.data() + tok.size();
  auto [ptr, ec] = std::from_chars(tok.data(), end, value);
  return ec == std::errc() && ptr == end;
}

// --- the structural scan ----------------------------------------------------------------------

struct ScanFace {
  uint32_t first = 0, count = 0;  // corners [first, first + count) in the corner arrays (OBJ, STL)
  size_t line = 0;                // 1-based line in the file, 0 when the format has none (binary)
};

struct Scan {
  size_t positions = 0;                    // file positions (STL: 3 per facet)
  std::vector<ScanFace> faces;
  size_t triangles = 0;                    // Σ (corners − 2)
  std::vector<uint32_t> corner_position;   // OBJ: 0-based position of each corner
  std::vector<uint8_t> corner_has_normal;  // OBJ: the corner names a `vn`
  std::vector<Eigen::Vector3f> stl_corner; // STL: corner coordinates, 3 per facet
  bool binary = false;

  void add_face(uint32_t first, uint32_t count, size_t line) {
    faces.push_back({first, count, line});
    triangles += count - 2;
  }
  std::string where(size_t face) const {
    const size_t line = faces[face].line;
    return line ? "face " + std::to_string(face) + " (line " + std::to_string(line) + ")" : "face " + std::to_string(face);
  }
};

// OBJ statements that carry no triangle data and are accepted (Wavefront OBJ spec, Appendix B1,
// plus OpenMesh's `vc` colour extension). Any other keyword makes the line garbage.
bool obj_ignored_keyword(std::string_view kw) {
  static constexpr std::string_view kKnown[] = {
      "vt", "vp", "vc", "l", "p", "g", "o", "s", "mg", "usemtl", "mtllib", "cstype", "deg", "bmat", "step",
      "curv", "curv2", "surf", "parm", "trim", "hole", "scrv", "sp", "end", "con", "bevel", "c_interp",
      "d_interp", "lod", "shadow_obj", "trace_obj", "ctech", "stech", "maplib", "usemap"};
  return std::find(std::begin(kKnown), std::end(kKnown), kw) != std::end(kKnown);
}

Scan scan_obj(const std::string& file, std::string_view text) {
  Scan scan;
  size_t normals = 0, texcoords = 0;
  struct Pending { long long index; size_t line; char kind; };  // forward references, checked at the end
  std::vector<Pending> forward;
  LineReader lines(text);
  std::string_view line;
  while (lines.next(line)) {
    const size_t ln = lines.number();
    line = trim(line);
    if (line.empty() || line.front() == '#') continue;
    const auto tok = split(line);
    const std::string_view kw = tok[0];
    if (kw == "v" || kw == "vn") {
      if (tok.size() < 4) throw InputError(file, at_line(ln) + "'" + std::string(kw) + "' needs 3 coordinates");
      for (int k = 1; k <= 3; ++k) {
        float x = 0;
        if (auto defect = parse_float(tok[k], x); !defect.empty()) throw InputError(file, at_line(ln) + defect);
      }
      ++(kw == "v" ? scan.positions : normals);
    } else if (kw == "vt") {
      float x = 0;
      if (tok.size() < 3) throw InputError(file, at_line(ln) + "'vt' needs 2 coordinates");
      for (int k = 1; k <= 2; ++k)
        if (auto defect = parse_float(tok[k], x); !defect.empty()) throw InputError(file, at_line(ln) + defect);
      ++texcoords;
    } else if (kw == "f") {
      if (tok.size() < 4)
        throw InputError(file, at_line(ln) + "face has " + std::to_string(tok.size() - 1) + " corners, needs at least 3");
      const auto first = static_cast<uint32_t>(scan.corner_position.size());
      for (size_t c = 1; c < tok.size(); ++c) {
        std::string_view part[3];
        int n_parts = 0;
        std::string_view rest = tok[c];
        while (true) {
          if (n_parts == 3) throw InputError(file, at_line(ln) + "malformed face corner " + shown(tok[c]));
          const size_t slash = rest.find('/');
          part[n_parts++] = rest.substr(0, slash);
          if (slash == std::string_view::npos) break;
          rest.remove_prefix(slash + 1);
        }
        // Resolve one index: 1-based, negative = relative to the count so far (OBJ spec).
        auto resolve = [&](std::string_view s, size_t so_far, char kind) -> long long {
          long long i = 0;
          if (!parse_int(s, i) || i == 0)
            throw InputError(file, at_line(ln) + "malformed face corner " + shown(tok[c]) +
                                       (i == 0 && parse_int(s, i) ? " (OBJ indices start at 1)" : ""));
          if (i < 0) {
            if (static_cast<unsigned long long>(-i) > so_far)
              throw InputError(file, at_line(ln) + "relative index " + std::to_string(i) + " in corner " + shown(tok[c]) +
                                         " reaches before the first " + (kind == 'v' ? "vertex" : kind == 'n' ? "normal" : "texcoord") +
                                         " (" + std::to_string(so_far) + " so far)");
            return static_cast<long long>(so_far) + i;
          }
          forward.push_back({i, ln, kind});
          return i - 1;
        };
        if (part[0].empty()) throw InputError(file, at_line(ln) + "face corner " + shown(tok[c]) + " has no vertex index");
        scan.corner_position.push_back(static_cast<uint32_t>(
            std::min<long long>(resolve(part[0], scan.positions, 'v'), std::numeric_limits<uint32_t>::max())));
        if (n_parts >= 2 && !part[1].empty()) resolve(part[1], texcoords, 't');
        const bool has_normal = n_parts == 3 && !part[2].empty();
        if (has_normal) resolve(part[2], normals, 'n');
        scan.corner_has_normal.push_back(has_normal ? 1 : 0);
      }
      scan.add_face(first, static_cast<uint32_t>(tok.size() - 1), ln);
    } else if (!obj_ignored_keyword(kw)) {
      throw InputError(file, at_line(ln) + "not an OBJ statement: " + shown(line));
    }
  }
  // Positive indices may point forward (OpenMesh reads all vertices first); check them now.
  for (const Pending& p : forward) {
    const size_t count = p.kind == 'v' ? scan.positions : p.kind == 'n' ? normals : texcoords;
    if (static_cast<unsigned long long>(p.index) > count)
      throw InputError(file, at_line(p.line) + (p.kind == 'v' ? "vertex" : p.kind == 'n' ? "normal" : "texcoord") +
                                 " index " + std::to_string(p.index) + " is out of range (the file has " +
                                 std::to_string(count) + ")");
  }
  return scan;
}

// PLY (Turk's format: ascii, binary_little_endian, binary_big_endian).
Scan scan_ply(const std::string& file, std::string_view text) {
  struct Property { bool list = false; int count_size = 0, item_size = 0; std::string name; };
  struct Element { std::string name; size_t count = 0; std::vector<Property> props; };
  auto type_size = [&](std::string_view t, size_t ln) {
    if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
    if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
    if (t == "int" || t == "uint" || t == "int32" || t == "uint32" || t == "float" || t == "float32") return 4;
    if (t == "double" || t == "float64") return 8;
    throw InputError(file, at_line(ln) + "unknown PLY property type " + shown(t));
  };
  Scan scan;
  std::vector<Element> elements;
  std::string format;
  LineReader lines(text);
  std::string_view line;
  size_t body = std::string_view::npos;
  if (!lines.next(line) || trim(line) != "ply") throw InputError(file, "not a PLY file (first line is not 'ply')");
  while (lines.next(line)) {
    const size_t ln = lines.number();
    const auto tok = split(line);
    if (tok.empty() || tok[0] == "comment" || tok[0] == "obj_info") continue;
    if (tok[0] == "format" && tok.size() >= 2) {
      format = tok[1];
    } else if (tok[0] == "element" && tok.size() == 3) {
      long long n = 0;
      if (!parse_int(tok[2], n) || n < 0) throw InputError(file, at_line(ln) + "bad element count " + shown(tok[2]));
      elements.push_back({std::string(tok[1]), static_cast<size_t>(n), {}});
    } else if (tok[0] == "property" && !elements.empty()) {
      if (tok.size() == 5 && tok[1] == "list")
        elements.back().props.push_back({true, type_size(tok[2], ln), type_size(tok[3], ln), std::string(tok[4])});
      else if (tok.size() == 3)
        elements.back().props.push_back({false, 0, type_size(tok[1], ln), std::string(tok[2])});
      else
        throw InputError(file, at_line(ln) + "malformed property " + shown(line));
    } else if (tok[0] == "end_header") {
      body = static_cast<size_t>(line.data() + line.size() - text.data()) + 1;
      break;
    } else {
      throw InputError(file, at_line(ln) + "malformed PLY header line " + shown(line));
    }
  }
  if (body == std::string_view::npos) throw InputError(file, "PLY header has no 'end_header' (truncated?)");
  if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian")
    throw InputError(file, "unknown PLY format " + shown(format));
  scan.binary = format != "ascii";
  const bool big_endian = format == "binary_big_endian";
  body = std::min(body, text.size());

  auto is_face_list = [](const Element& e, const Property& p) {
    return e.name == "face" && p.list && (p.name == "vertex_indices" || p.name == "vertex_index");
  };
  for (const Element& e : elements) {
    if (e.name == "vertex") scan.positions = e.count;
    if (e.name == "face" && e.count > 0 &&
        std::none_of(e.props.begin(), e.props.end(), [&](const Property& p) { return is_face_list(e, p); }))
      throw InputError(file, "PLY face element has no 'vertex_indices' list");
  }

  auto add_face = [&](long long corners, size_t face, size_t ln) {
    if (corners < 3)
      throw InputError(file, (ln ? at_line(ln) : std::string()) + "face " + std::to_string(face) + " has " +
                                 std::to_string(corners) + " corners, needs at least 3");
    scan.add_face(0, static_cast<uint32_t>(corners), ln);
  };
  auto truncated = [&](const Element& e, size_t item) {
    return InputError(file, "truncated: the file ends inside " + e.name + " " + std::to_string(item) + " of " +
                                std::to_string(e.count));
  };

  if (!scan.binary) {
    // Tokens in order, with the line each starts on.
    size_t pos = body, ln = lines.number() + 1;
    auto next_token = [&](std::string_view& tok, size_t& tok_line) {
      while (pos < text.size() && is_space(text[pos])) ln += text[pos++] == '\n';
      if (pos >= text.size()) return false;
      const size_t start = pos;
      while (pos < text.size() && !is_space(text[pos])) ++pos;
      tok = text.substr(start, pos - start);
      tok_line = ln;
      return true;
    };
    std::string_view tok;
    size_t tok_line = 0;
    for (const Element& e : elements) {
      for (size_t item = 0; item < e.count; ++item) {
        size_t item_line = 0;
        for (const Property& p : e.props) {
          if (!next_token(tok, tok_line)) throw truncated(e, item);
          if (!item_line) item_line = tok_line;
          if (!p.list) continue;
          long long n = 0;
          if (!parse_int(tok, n) || n < 0) throw InputError(file, at_line(tok_line) + "bad list length " + shown(tok));
          for (long long k = 0; k < n; ++k)
            if (!next_token(tok, tok_line)) throw truncated(e, item);
          if (is_face_list(e, p)) add_face(n, item, item_line);
        }
      }
    }
    return scan;
  }

  size_t pos = body;
  auto read_count = [&](int size) -> long long {
    unsigned char b[8] = {};
    std::memcpy(b, text.data() + pos, static_cast<size_t>(size));
    if (big_endian) std::reverse(b, b + size);
    pos += static_cast<size_t>(size);
    // Count types are unsigned in practice; a negative signed count is caught as too large.
    uint64_t v = 0;
    for (int i = size - 1; i >= 0; --i) v = (v << 8) | b[i];
    return static_cast<long long>(v);
  };
  for (const Element& e : elements) {
    for (size_t item = 0; item < e.count; ++item) {
      for (const Property& p : e.props) {
        if (!p.list) {
          if (text.size() - pos < static_cast<size_t>(p.item_size)) throw truncated(e, item);
          pos += static_cast<size_t>(p.item_size);
          continue;
        }
        if (text.size() - pos < static_cast<size_t>(p.count_size)) throw truncated(e, item);
        const long long n = read_count(p.count_size);
        if (static_cast<unsigned long long>(n) > (text.size() - pos) / static_cast<size_t>(p.item_size))
          throw truncated(e, item);
        pos += static_cast<size_t>(n) * static_cast<size_t>(p.item_size);
        if (is_face_list(e, p)) add_face(n, item, 0);
      }
    }
  }
  return scan;
}

// OFF (ascii): "[ST][C][N]OFF", then "nV nF nE", nV vertex lines, nF face lines "n i0 … in−1 [colour]".
Scan scan_off(const std::string& file, std::string_view text) {
  Scan scan;
  LineReader lines(text);
  std::string_view line;
  // Non-empty lines. OpenMesh 9.0's OFF reader has no comment support: a '#' line makes it read
  // uninitialised counts and coordinates (seen: 32,611 empty faces, garbage vertices, success
  // returned), so a comment is rejected here, before OpenMesh runs.
  auto next_line = [&](std::vector<std::string_view>& tok) {
    while (lines.next(line)) {
      if (line.find('#') != std::string_view::npos)
        throw InputError(file, at_line(lines.number()) + "'#' comments in OFF are not supported (OpenMesh's OFF reader misreads them)");
      tok = split(line);
      if (!tok.empty()) return true;
    }
    return false;
  };
  std::vector<std::string_view> tok;
  if (!next_line(tok)) throw InputError(file, "empty file");
  const std::string_view magic = tok[0];
  if (magic.size() < 3 || magic.substr(magic.size() - 3) != "OFF" ||
      magic.find_first_not_of("STCN") < magic.size() - 3)
    throw InputError(file, at_line(lines.number()) + "not an OFF header: " + shown(magic));
  std::vector<std::string_view> counts(tok.begin() + 1, tok.end());
  if (!counts.empty() && counts[0] == "BINARY") throw InputError(file, "binary OFF is not supported");
  if (!counts.empty())
    throw InputError(file, at_line(lines.number()) + "counts on the OFF header line are not supported (OpenMesh's OFF reader expects them on the next line)");
  {
    if (!next_line(tok)) throw InputError(file, "truncated: no vertex/face counts after the OFF header");
    counts = tok;
  }
  long long nv = 0, nf = 0;
  if (counts.size() < 2 || !parse_int(counts[0], nv) || !parse_int(counts[1], nf) || nv < 0 || nf < 0)
    throw InputError(file, at_line(lines.number()) + "malformed OFF counts " + shown(trim(line)));
  scan.positions = static_cast<size_t>(nv);
  for (long long v = 0; v < nv; ++v) {
    if (!next_line(tok))
      throw InputError(file, "truncated: the header says " + std::to_string(nv) + " vertices, the file has " + std::to_string(v));
    if (tok.size() < 3) throw InputError(file, at_line(lines.number()) + "vertex needs 3 coordinates");
    for (int k = 0; k < 3; ++k) {
      float x = 0;
      if (auto defect = parse_float(tok[static_cast<size_t>(k)], x); !defect.empty())
        throw InputError(file, at_line(lines.number()) + defect);
    }
  }
  for (long long f = 0; f < nf; ++f) {
    if (!next_line(tok))
      throw InputError(file, "truncated: the header says " + std::to_string(nf) + " faces, the file has " + std::to_string(f));
    const size_t ln = lines.number();
    long long n = 0;
    if (!parse_int(tok[0], n) || n < 0) throw InputError(file, at_line(ln) + "malformed face " + shown(trim(line)));
    if (n < 3) throw InputError(file, at_line(ln) + "face has " + std::to_string(n) + " corners, needs at least 3");
    if (tok.size() < static_cast<size_t>(n) + 1)
      throw InputError(file, at_line(ln) + "face lists " + std::to_string(tok.size() - 1) + " of its " + std::to_string(n) + " indices");
    for (long long k = 1; k <= n; ++k) {
      long long i = 0;
      if (!parse_int(tok[static_cast<size_t>(k)], i)) throw InputError(file, at_line(ln) + "malformed index " + shown(tok[static_cast<size_t>(k)]));
      if (i < 0 || i >= nv)
        throw InputError(file, at_line(ln) + "vertex index " + std::to_string(i) + " is out of range [0, " + std::to_string(nv) + ")");
    }
    scan.add_face(0, static_cast<uint32_t>(n), ln);
  }
  return scan;
}

// STL, typed the way OpenMesh does: binary iff size == 84 + 50·n.
Scan scan_stl(const std::string& file, std::string_view text) {
  Scan scan;
  if (text.size() >= 84) {
    uint32_t n = 0;
    std::memcpy(&n, text.data() + 80, 4);  // little endian; prtbake targets little-endian hosts
    if (text.size() == 84 + 50 * static_cast<uint64_t>(n)) {
      scan.binary = true;
      for (uint32_t f = 0; f < n; ++f) {
        const char* rec = text.data() + 84 + 50 * static_cast<size_t>(f);
        for (int k = 0; k < 3; ++k) {
          float c[3];
          std::memcpy(c, rec + 12 + 12 * k, 12);
          const Eigen::Vector3f p(c[0], c[1], c[2]);
          if (!p.allFinite()) throw InputError(file, "facet " + std::to_string(f) + " has a non-finite coordinate");
          scan.stl_corner.push_back(p);
        }
        scan.add_face(3 * f, 3, 0);
      }
      scan.positions = scan.stl_corner.size();
      return scan;
    }
  }
  const std::string_view head = trim(text.substr(0, 512));
  if (head.substr(0, 5) != "solid" || text.find('\0') != std::string_view::npos) {
    std::string defect = "not an STL file: no 'solid' header, and the size (" + std::to_string(text.size()) + " bytes)";
    if (text.size() >= 84) {
      uint32_t n = 0;
      std::memcpy(&n, text.data() + 80, 4);
      defect += " is not the 84 + 50 x " + std::to_string(n) + " bytes of a binary STL with " + std::to_string(n) +
                " facets (truncated?)";
    } else {
      defect += " is less than a binary STL header";
    }
    throw InputError(file, defect);
  }
  LineReader lines(text);
  std::string_view line;
  size_t in_loop = 0, loop_line = 0;  // corners still expected in the current "outer loop"
  while (lines.next(line)) {
    const size_t ln = lines.number();
    const auto tok = split(line);
    if (tok.empty()) continue;
    const std::string kw = lower(std::string(tok[0]));
    if (kw == "vertex") {
      if (!in_loop) throw InputError(file, at_line(ln) + "'vertex' outside an 'outer loop'");
      if (tok.size() != 4) throw InputError(file, at_line(ln) + "'vertex' needs 3 coordinates");
      Eigen::Vector3f p;
      for (int k = 0; k < 3; ++k)
        if (auto defect = parse_float(tok[static_cast<size_t>(k) + 1], p[k]); !defect.empty())
          throw InputError(file, at_line(ln) + defect);
      scan.stl_corner.push_back(p);
      if (--in_loop == 0) scan.add_face(static_cast<uint32_t>(scan.stl_corner.size() - 3), 3, loop_line);
    } else if (in_loop) {
      throw InputError(file, at_line(ln) + "expected 'vertex' (" + std::to_string(in_loop) + " more in the loop from line " +
                                 std::to_string(loop_line) + ")");
    } else if (kw == "outer") {
      in_loop = 3;
      loop_line = ln;
    } else if (kw == "facet") {
      if (tok.size() >= 5)
        for (int k = 2; k < 5; ++k) {
          float x = 0;
          if (auto defect = parse_float(tok[static_cast<size_t>(k)], x); !defect.empty())
            throw InputError(file, at_line(ln) + "facet normal: " + defect);
        }
    } else if (kw != "solid" && kw != "endloop" && kw != "endfacet" && kw != "endsolid") {
      throw InputError(file, at_line(ln) + "not an STL statement: " + shown(trim(line)));
    }
  }
  if (in_loop) throw InputError(file, "truncated: the file ends inside the loop from line " + std::to_string(loop_line));
  scan.positions = scan.stl_corner.size();
  return scan;
}

// --- OpenMesh side -----------------------------------------------------------------------------

using OpenMesh::EdgeHandle;
using OpenMesh::FaceHandle;
using OpenMesh::HalfedgeHandle;
using OpenMesh::VertexHandle;
using OpenMesh::Vec2f;
using OpenMesh::Vec3d;
using OpenMesh::Vec3f;
using OpenMesh::Vec3uc;
using OpenMesh::Vec4f;
using OpenMesh::Vec4uc;
using StatusInfo = OpenMesh::Attributes::StatusInfo;

// Records exactly what the reader hands over: no mesh, no connectivity, nothing dropped.
class RawImporter final : public OpenMesh::IO::BaseImporter {
public:
  std::vector<Eigen::Vector3f> points;
  std::vector<std::optional<Eigen::Vector3f>> vertex_normal;  // last set_normal(vertex) per vertex
  struct VertexNormalCall { int vertex; Eigen::Vector3f normal; };
  std::vector<VertexNormalCall> normal_calls;                 // every set_normal(vertex), in order (OBJ: per corner)
  std::vector<uint32_t> face_offsets{0};
  std::vector<int> face_vertices;                             // raw handle indices, unchecked
  bool used_halfedge_api = false;

  VertexHandle add_vertex(const Vec3f& p) override {
    points.emplace_back(p[0], p[1], p[2]);
    vertex_normal.emplace_back();
    return VertexHandle(static_cast<int>(points.size() - 1));
  }
  VertexHandle add_vertex(const Vec3d& p) override { return add_vertex(Vec3f(float(p[0]), float(p[1]), float(p[2]))); }
  VertexHandle add_vertex() override { return add_vertex(Vec3f(0.0f, 0.0f, 0.0f)); }
  void set_point(VertexHandle v, const Vec3f& p) override {
    if (valid(v)) points[static_cast<size_t>(v.idx())] = Eigen::Vector3f(p[0], p[1], p[2]);
  }
  FaceHandle add_face(const VHandles& corners) override {
    for (const VertexHandle& v : corners) face_vertices.push_back(v.idx());
    face_offsets.push_back(static_cast<uint32_t>(face_vertices.size()));
    return FaceHandle(static_cast<int>(face_offsets.size() - 2));
  }
  void set_normal(VertexHandle v, const Vec3f& n) override {
    const Eigen::Vector3f normal(n[0], n[1], n[2]);
    normal_calls.push_back({v.idx(), normal});
    if (valid(v)) vertex_normal[static_cast<size_t>(v.idx())] = normal;
  }
  void set_normal(VertexHandle v, const Vec3d& n) override { set_normal(v, Vec3f(float(n[0]), float(n[1]), float(n[2]))); }
  size_t n_vertices() const override { return points.size(); }
  size_t n_faces() const override { return face_offsets.size() - 1; }
  size_t n_edges() const override { return 0; }

  // Halfedge-level construction is only used by OpenMesh's own .om format; we never read it.
  HalfedgeHandle add_edge(VertexHandle, VertexHandle) override { used_halfedge_api = true; return HalfedgeHandle(); }
  FaceHandle add_face(HalfedgeHandle) override { used_halfedge_api = true; return FaceHandle(); }
  void set_halfedge(VertexHandle, HalfedgeHandle) override { used_halfedge_api = true; }
  void set_next(HalfedgeHandle, HalfedgeHandle) override { used_halfedge_api = true; }
  void set_face(HalfedgeHandle, FaceHandle) override { used_halfedge_api = true; }

  // Attributes a bake does not use: accepted and ignored.
  void add_face_texcoords(FaceHandle, VertexHandle, const std::vector<Vec2f>&) override {}
  void add_face_texcoords(FaceHandle, VertexHandle, const std::vector<Vec3f>&) override {}
  void set_face_texindex(FaceHandle, int) override {}
  void set_color(VertexHandle, const Vec3uc&) override {}
  void set_color(VertexHandle, const Vec4uc&) override {}
  void set_color(VertexHandle, const Vec3f&) override {}
  void set_color(VertexHandle, const Vec4f&) override {}
  void set_texcoord(VertexHandle, const Vec2f&) override {}
  void set_texcoord(VertexHandle, const Vec3f&) override {}
  void set_texcoord(HalfedgeHandle, const Vec2f&) override {}
  void set_texcoord(HalfedgeHandle, const Vec3f&) override {}
  void set_status(VertexHandle, const StatusInfo&) override {}
  void set_status(HalfedgeHandle, const StatusInfo&) override {}
  void set_status(EdgeHandle, const StatusInfo&) override {}
  void set_status(FaceHandle, const StatusInfo&) override {}
  void request_face_texcoords2D() override {}
  void set_color(EdgeHandle, const Vec3uc&) override {}
  void set_color(EdgeHandle, const Vec4uc&) override {}
  void set_color(EdgeHandle, const Vec3f&) override {}
  void set_color(EdgeHandle, const Vec4f&) override {}
  void set_normal(FaceHandle, const Vec3f&) override {}  // STL facet normals: not used (see mesh.h)
  void set_normal(FaceHandle, const Vec3d&) override {}
  void set_color(FaceHandle, const Vec3uc&) override {}
  void set_color(FaceHandle, const Vec4uc&) override {}
  void set_color(FaceHandle, const Vec3f&) override {}
  void set_color(FaceHandle, const Vec4f&) override {}
  void add_texture_information(int, std::string) override {}

  std::span<const int> face(size_t f) const {
    return std::span<const int>(face_vertices).subspan(face_offsets[f], face_offsets[f + 1] - face_offsets[f]);
  }

private:
  bool valid(VertexHandle v) const { return v.idx() >= 0 && static_cast<size_t>(v.idx()) < points.size(); }
};

// Captures omerr / omlog / omout during a read. They are process-wide, hence the lock. OpenMesh's
// multiplex_streambuf::disconnect() forgets a target without deleting it (mostream.hh), so
// connecting per read leaked every time: the capture streams are connected once, for the life of
// the process (reachable through a static pointer), and emptied before each read. Side effect:
// after the first read, OpenMesh's chatter no longer reaches std::cerr from other OpenMesh users
// in the process either; their errors must be turned into exceptions where they happen.
class OpenMeshChatter {
public:
  OpenMeshChatter() : lock_(mutex()) {
    static const bool connected = [] {
      ::omerr().disconnect(std::cerr);
      ::omlog().disconnect(std::clog);
      ::omout().disconnect(std::cout);
      ::omerr().connect(err_stream());
      ::omlog().connect(log_stream());
      ::omout().connect(log_stream());
      return true;
    }();
    (void)connected;
    flush_all();
    err_stream().str("");
    log_stream().str("");
  }
  ~OpenMeshChatter() { flush_all(); }
  OpenMeshChatter(const OpenMeshChatter&) = delete;
  OpenMeshChatter& operator=(const OpenMeshChatter&) = delete;

  std::vector<std::string> errors() { return lines(err_stream(), ::omerr()); }
  std::vector<std::string> logs() {
    ::omout().flush();
    return lines(log_stream(), ::omlog());
  }

private:
  static std::ostringstream& err_stream() {
    static std::ostringstream* s = new std::ostringstream;
    return *s;
  }
  static std::ostringstream& log_stream() {
    static std::ostringstream* s = new std::ostringstream;
    return *s;
  }
  static void flush_all() {
    ::omerr().flush();
    ::omlog().flush();
    ::omout().flush();
  }
  static std::mutex& mutex() {
    static std::mutex m;
    return m;
  }
  static std::vector<std::string> lines(std::ostringstream& os, std::ostream& from) {
    from.flush();
    std::vector<std::string> out;
    std::istringstream in(os.str());
    for (std::string l; std::getline(in, l);)
      if (auto t = trim(l); !t.empty()) out.emplace_back(t);
    return out;
  }
  std::lock_guard<std::mutex> lock_;
};

// OBJ material-library complaints do not touch geometry: a missing or partial .mtl is a warning.
bool is_material_warning(const std::string& msg) {
  return msg.find("Material") != std::string::npos || msg.find("material") != std::string::npos;
}

// --- assembly ----------------------------------------------------------------------------------

// A (position, normal) key; normal bits are canonical (−0 → +0), `has` = the file gave one.
struct CornerKey {
  uint32_t position;
  bool has;
  std::array<uint32_t, 3> bits;
  bool operator==(const CornerKey&) const = default;
};
struct CornerKeyHash {
  size_t operator()(const CornerKey& k) const noexcept {
    uint64_t h = k.position * 0x9E3779B97F4A7C15ull + k.has;
    for (uint32_t b : k.bits) h = (h ^ b) * 0xBF58476D1CE4E5B9ull, h ^= h >> 31;
    return static_cast<size_t>(h);
  }
};
CornerKey make_key(uint32_t position, const std::optional<Eigen::Vector3f>& n) {
  if (!n) return {position, false, {0, 0, 0}};
  return {position, true,
          {std::bit_cast<uint32_t>((*n)[0] + 0.0f), std::bit_cast<uint32_t>((*n)[1] + 0.0f),
           std::bit_cast<uint32_t>((*n)[2] + 0.0f)}};
}

// Polygons over file positions with an optional file normal per corner.
struct Polygons {
  std::vector<uint32_t> offsets{0};
  std::vector<uint32_t> position;
  std::vector<std::optional<Eigen::Vector3f>> normal;
  std::vector<size_t> line;  // per polygon, for messages
};

} // namespace

Mesh load_mesh(const std::filesystem::path& path, const MeshLoadOptions& options) {
  const std::string file = path.string();
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) throw InputError(file, "no such file");
  if (std::filesystem::is_directory(status)) throw InputError(file, "is a directory, not a mesh file");

  const std::string ext = lower(path.extension().string());
  Format format;
  if (ext == ".obj") format = Format::Obj;
  else if (ext == ".ply") format = Format::Ply;
  else if (ext == ".off") format = Format::Off;
  else if (ext == ".stl") format = Format::Stl;
  else throw InputError(file, "unknown mesh format " + shown(ext.empty() ? path.filename().string() : ext) +
                                  " (supported: .obj .ply .off .stl)");

  std::string text;
  {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(file, std::string("cannot be read: ") + std::strerror(errno));
    const auto size = std::filesystem::file_size(path, ec);
    if (ec) throw InputError(file, "cannot be read: " + ec.message());
    text.resize(static_cast<size_t>(size));
    if (!in.read(text.data(), static_cast<std::streamsize>(text.size())))
      throw InputError(file, std::string("read failed: ") + std::strerror(errno));
  }
  if (text.empty()) throw InputError(file, "empty file");

  Scan scan;
  switch (format) {
    case Format::Obj: scan = scan_obj(file, text); break;
    case Format::Ply: scan = scan_ply(file, text); break;
    case Format::Off: scan = scan_off(file, text); break;
    case Format::Stl: scan = scan_stl(file, text); break;
  }
  if (scan.faces.empty())
    throw InputError(file, "no faces (" + std::to_string(scan.positions) + " vertices): nothing to bake");
  if (scan.positions >= std::numeric_limits<uint32_t>::max() || scan.triangles >= std::numeric_limits<uint32_t>::max())
    throw InputError(file, "too large for 32-bit indices");

  // OpenMesh reads the file into our importer. Normals are only passed when asked for (and STL
  // facet normals are not used), so ask only when the file's normals will be used.
  RawImporter importer;
  Mesh mesh;
  {
    OpenMeshChatter chatter;
    OpenMesh::IO::Options read_options;
    if (options.use_file_normals && format != Format::Stl) read_options += OpenMesh::IO::Options::VertexNormal;
    const bool ok = OpenMesh::IO::IOManager().read(file, importer, read_options);
    std::vector<std::string> errors;
    for (std::string& msg : chatter.errors()) (is_material_warning(msg) ? mesh.warnings : errors).push_back(std::move(msg));
    for (std::string& msg : chatter.logs()) mesh.warnings.push_back(std::move(msg));
    if (!errors.empty()) throw InputError(file, "OpenMesh's reader reported: " + errors.front());
    if (!ok) throw InputError(file, "OpenMesh's reader failed without a message");
    if (importer.used_halfedge_api) throw InputError(file, "OpenMesh's reader used halfedge-level construction");
  }

  const size_t om_faces = importer.n_faces();
  auto mismatch = [&](const std::string& what) {
    return InputError(file, "OpenMesh's reader disagrees with the file: " + what + " (the file has " +
                                std::to_string(scan.faces.size()) + " faces / " + std::to_string(scan.triangles) +
                                " triangles, the reader delivered " + std::to_string(om_faces) + " faces)");
  };
  if (format != Format::Stl) {
    if (importer.points.size() != scan.positions)
      throw InputError(file, "the file has " + std::to_string(scan.positions) + " vertices but OpenMesh's reader delivered " +
                                 std::to_string(importer.points.size()));
    for (size_t v = 0; v < importer.points.size(); ++v)
      if (!importer.points[v].allFinite())
        throw InputError(file, "vertex " + std::to_string(v) + " has a non-finite coordinate");
  }

  Polygons poly;
  std::vector<Eigen::Vector3f> file_positions;
  if (format == Format::Obj) {
    // OpenMesh delivers each face with repeated indices removed and skips those left with < 3
    // corners; the corners themselves (with repeats) come from the scan.
    // With VertexNormal requested, every corner that names a `vn` produces one call, in order.
    const bool normals_passed = options.use_file_normals;
    size_t om = 0, call = 0;
    for (size_t f = 0; f < scan.faces.size(); ++f) {
      const ScanFace& sf = scan.faces[f];
      std::vector<int> distinct;
      for (uint32_t c = sf.first; c < sf.first + sf.count; ++c) {
        const int p = static_cast<int>(scan.corner_position[c]);
        if (std::find(distinct.begin(), distinct.end(), p) == distinct.end()) distinct.push_back(p);
        std::optional<Eigen::Vector3f> n;
        if (normals_passed && scan.corner_has_normal[c]) {
          if (call >= importer.normal_calls.size() || importer.normal_calls[call].vertex != p)
            throw mismatch("corner normals of " + scan.where(f) + " do not line up");
          n = importer.normal_calls[call++].normal;
          if (!n->allFinite()) throw InputError(file, at_line(sf.line) + "non-finite normal");
        }
        poly.position.push_back(scan.corner_position[c]);
        poly.normal.push_back(n);
      }
      poly.offsets.push_back(static_cast<uint32_t>(poly.position.size()));
      poly.line.push_back(sf.line);
      if (distinct.size() < 3) continue;  // OpenMesh skips it; we keep it
      if (om >= om_faces) throw mismatch(scan.where(f) + " is missing");
      const auto got = importer.face(om++);
      if (!std::equal(got.begin(), got.end(), distinct.begin(), distinct.end()))
        throw mismatch(scan.where(f) + " was read with different vertices");
    }
    if (om != om_faces) throw mismatch("extra faces");
    // (With no face at all left to OpenMesh it treats the file as a point cloud and sets
    // per-vertex normals once more; those extra calls carry nothing new.)
    if (call != importer.normal_calls.size() && om_faces != 0) throw mismatch("extra corner normals");
    file_positions = importer.points;
  } else if (format == Format::Ply || format == Format::Off) {
    if (om_faces != scan.faces.size()) throw mismatch("face count");
    for (size_t f = 0; f < om_faces; ++f) {
      const auto got = importer.face(f);
      if (got.size() != scan.faces[f].count)
        throw mismatch(scan.where(f) + " has " + std::to_string(scan.faces[f].count) + " corners in the file, " +
                       std::to_string(got.size()) + " as read");
      for (int v : got) {
        if (v < 0 || static_cast<size_t>(v) >= scan.positions)
          throw InputError(file, scan.where(f) + ": vertex index " + std::to_string(v) + " is out of range [0, " +
                                     std::to_string(scan.positions) + ")");
        poly.position.push_back(static_cast<uint32_t>(v));
        const auto& n = importer.vertex_normal[static_cast<size_t>(v)];
        if (n && !n->allFinite()) throw InputError(file, "vertex " + std::to_string(v) + " has a non-finite normal");
        poly.normal.push_back(n);
      }
      poly.offsets.push_back(static_cast<uint32_t>(poly.position.size()));
      poly.line.push_back(scan.faces[f].line);
    }
    file_positions = importer.points;
  } else {
    // STL: corners are the vertices. OpenMesh merged equal corners and skipped facets with two
    // equal corners; verify the rest against the scan.
    auto same = [](const Eigen::Vector3f& a, const Eigen::Vector3f& b) { return ((a - b).cwiseAbs().array() <= FLT_MIN).all(); };
    size_t om = 0;
    for (size_t f = 0; f < scan.faces.size(); ++f) {
      const Eigen::Vector3f* c = &scan.stl_corner[3 * f];
      for (uint32_t k = 0; k < 3; ++k) poly.position.push_back(static_cast<uint32_t>(3 * f + k));
      poly.normal.insert(poly.normal.end(), 3, std::nullopt);
      poly.offsets.push_back(static_cast<uint32_t>(poly.position.size()));
      poly.line.push_back(scan.faces[f].line);
      if (same(c[0], c[1]) || same(c[0], c[2]) || same(c[1], c[2])) continue;  // OpenMesh skips it; we keep it
      if (om >= om_faces) throw mismatch("facet " + std::to_string(f) + " is missing");
      const auto got = importer.face(om++);
      bool ok = got.size() == 3;
      for (size_t k = 0; ok && k < 3; ++k)
        ok = got[k] >= 0 && static_cast<size_t>(got[k]) < importer.points.size() &&
             same(importer.points[static_cast<size_t>(got[k])], c[k]);
      if (!ok) throw mismatch(scan.where(f) + " was read with different corners");
    }
    if (om != om_faces) throw mismatch("extra faces");
    file_positions = scan.stl_corner;
  }

  // Output vertices: file positions in file order, then (position, normal) splits in order of
  // first appearance in the face list.
  const auto n_file = static_cast<uint32_t>(file_positions.size());
  std::vector<std::optional<Eigen::Vector3f>> vertex_file_normal(n_file);
  std::vector<uint8_t> claimed(n_file, 0);
  std::vector<CornerKey> row_key(n_file);
  std::unordered_map<CornerKey, uint32_t, CornerKeyHash> splits;
  mesh.positions = file_positions;
  mesh.source_position.resize(n_file);
  for (uint32_t v = 0; v < n_file; ++v) mesh.source_position[v] = v;
  std::vector<uint32_t> corner_vertex(poly.position.size());
  for (size_t c = 0; c < poly.position.size(); ++c) {
    const uint32_t p = poly.position[c];
    const CornerKey key = make_key(p, poly.normal[c]);
    if (!claimed[p]) {
      claimed[p] = 1;
      row_key[p] = key;
      vertex_file_normal[p] = poly.normal[c];
      corner_vertex[c] = p;
    } else if (row_key[p] == key) {
      corner_vertex[c] = p;
    } else {
      const auto [it, inserted] = splits.try_emplace(key, static_cast<uint32_t>(mesh.positions.size()));
      if (inserted) {
        mesh.positions.push_back(file_positions[p]);
        mesh.source_position.push_back(p);
        vertex_file_normal.push_back(poly.normal[c]);
      }
      corner_vertex[c] = it->second;
    }
  }
  if (mesh.positions.size() >= std::numeric_limits<uint32_t>::max()) throw InputError(file, "too many vertices for 32-bit indices");

  // Fan triangulation in place.
  mesh.triangles.reserve(scan.triangles);
  for (size_t f = 0; f + 1 < poly.offsets.size(); ++f) {
    const uint32_t b = poly.offsets[f], e = poly.offsets[f + 1];
    for (uint32_t i = b + 1; i + 1 < e; ++i) mesh.triangles.push_back({corner_vertex[b], corner_vertex[i], corner_vertex[i + 1]});
  }
  if (mesh.triangles.size() != scan.triangles)
    throw InputError(file, "the file has " + std::to_string(scan.triangles) + " triangles but " +
                               std::to_string(mesh.triangles.size()) + " were read");

  // Normals: the file's where usable, else angle-weighted over welded positions.
  mesh.normals.resize(mesh.positions.size());
  bool any_file = false, need_computed = false;
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    const auto& n = vertex_file_normal[v];
    const float len = n ? n->norm() : 0.0f;
    if (n && len > 0.0f && std::isfinite(len)) {
      mesh.normals[v] = *n / len;
      any_file = true;
    } else {
      need_computed = true;
    }
  }
  if (need_computed) {
    const auto computed = welded_angle_weighted_normals(mesh.positions, mesh.triangles);
    for (size_t v = 0; v < mesh.positions.size(); ++v) {
      const auto& n = vertex_file_normal[v];
      if (!(n && n->norm() > 0.0f)) mesh.normals[v] = computed[v];
    }
  }
  mesh.normal_source = any_file ? Mesh::NormalSource::File : Mesh::NormalSource::AngleWeighted;
  mesh.source = file;
  mesh.file_positions = n_file;
  mesh.file_faces = scan.faces.size();
  return mesh;
}

} // namespace prt::bake
