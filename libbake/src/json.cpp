// json.cpp — see bake/json.h.
#include <bake/error.h>
#include <bake/json.h>

#include <charconv>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

namespace prt::bake::json {
namespace {

class Parser {
public:
  Parser(std::string_view text, const std::filesystem::path& file) : s_(text), file_(file.string()) {}

  Value document() {
    skip_ws();
    Value v = value(0);
    skip_ws();
    if (i_ != s_.size()) fail("unexpected text after the JSON value");
    return v;
  }

private:
  [[noreturn]] void fail(const std::string& what) const {
    int line = 1, col = 1;
    for (size_t k = 0; k < i_ && k < s_.size(); ++k) {
      if (s_[k] == '\n') {
        ++line;
        col = 1;
      } else {
        ++col;
      }
    }
    throw InputError(file_, "line " + std::to_string(line) + ", column " + std::to_string(col) + ": " + what);
  }

  // Records the line and column of the value starting at i_ (tracked incrementally: values are
  // visited in text order).
  void where(Value& v) {
    for (; mark_ < i_; ++mark_) {
      if (s_[mark_] == '\n') {
        ++line_;
        col_ = 1;
      } else {
        ++col_;
      }
    }
    v.line = line_;
    v.column = col_;
  }

  void skip_ws() {
    while (i_ < s_.size() && (s_[i_] == ' ' || s_[i_] == '\t' || s_[i_] == '\n' || s_[i_] == '\r')) ++i_;
  }

  bool literal(std::string_view word) {
    if (s_.substr(i_, word.size()) != word) return false;
    i_ += word.size();
    return true;
  }

  Value value(int depth) {
    if (depth > 128) fail("nesting deeper than 128 levels");
    if (i_ >= s_.size()) fail("unexpected end of the text (a value is missing)");
    Value v;
    where(v);
    const char c = s_[i_];
    if (c == '{') v.v = std::make_shared<Object>(object(depth));
    else if (c == '[') v.v = std::make_shared<Array>(array(depth));
    else if (c == '"') v.v = string();
    else if (c == '-' || (c >= '0' && c <= '9')) v.v = number();
    else if (literal("true")) v.v = true;
    else if (literal("false")) v.v = false;
    else if (literal("null")) v.v = nullptr;
    else fail(std::string("unexpected character '") + c + "' (expected a value)");
    return v;
  }

  Object object(int depth) {
    ++i_;  // {
    Object o;
    std::set<std::string> keys;
    skip_ws();
    if (i_ < s_.size() && s_[i_] == '}') {
      ++i_;
      return o;
    }
    for (;;) {
      skip_ws();
      if (i_ >= s_.size() || s_[i_] != '"') fail("expected a \"key\" in the object");
      std::string key = string();
      if (!keys.insert(key).second) fail("key \"" + key + "\" appears twice in the object");
      skip_ws();
      if (i_ >= s_.size() || s_[i_] != ':') fail("expected ':' after the key \"" + key + "\"");
      ++i_;
      skip_ws();
      o.emplace_back(std::move(key), value(depth + 1));
      skip_ws();
      if (i_ < s_.size() && s_[i_] == ',') {
        ++i_;
        continue;
      }
      if (i_ < s_.size() && s_[i_] == '}') {
        ++i_;
        return o;
      }
      fail("expected ',' or '}' in the object");
    }
  }

  Array array(int depth) {
    ++i_;  // [
    Array a;
    skip_ws();
    if (i_ < s_.size() && s_[i_] == ']') {
      ++i_;
      return a;
    }
    for (;;) {
      skip_ws();
      a.push_back(value(depth + 1));
      skip_ws();
      if (i_ < s_.size() && s_[i_] == ',') {
        ++i_;
        continue;
      }
      if (i_ < s_.size() && s_[i_] == ']') {
        ++i_;
        return a;
      }
      fail("expected ',' or ']' in the array");
    }
  }

  static void put_utf8(std::string& out, uint32_t cp) {
    if (cp < 0x80) {
      out += char(cp);
    } else if (cp < 0x800) {
      out += char(0xC0 | (cp >> 6));
      out += char(0x80 | (cp & 0x3F));
    } else if (cp < 0x10000) {
      out += char(0xE0 | (cp >> 12));
      out += char(0x80 | ((cp >> 6) & 0x3F));
      out += char(0x80 | (cp & 0x3F));
    } else {
      out += char(0xF0 | (cp >> 18));
      out += char(0x80 | ((cp >> 12) & 0x3F));
      out += char(0x80 | ((cp >> 6) & 0x3F));
      out += char(0x80 | (cp & 0x3F));
    }
  }

  uint32_t hex4() {
    if (i_ + 4 > s_.size()) fail("truncated \\u escape");
    uint32_t v = 0;
    for (int k = 0; k < 4; ++k) {
      const char c = s_[i_++];
      v <<= 4;
      if (c >= '0' && c <= '9') v |= uint32_t(c - '0');
      else if (c >= 'a' && c <= 'f') v |= uint32_t(c - 'a' + 10);
      else if (c >= 'A' && c <= 'F') v |= uint32_t(c - 'A' + 10);
      else fail("invalid hex digit in a \\u escape");
    }
    return v;
  }

  std::string string() {
    ++i_;  // "
    std::string out;
    for (;;) {
      if (i_ >= s_.size()) fail("unterminated string");
      const auto c = static_cast<unsigned char>(s_[i_]);
      if (c == '"') {
        ++i_;
        return out;
      }
      if (c < 0x20) fail("control character in a string (escape it)");
      if (c != '\\') {
        out += char(c);
        ++i_;
        continue;
      }
      ++i_;
      if (i_ >= s_.size()) fail("unterminated escape");
      const char e = s_[i_++];
      switch (e) {
      case '"': out += '"'; break;
      case '\\': out += '\\'; break;
      case '/': out += '/'; break;
      case 'b': out += '\b'; break;
      case 'f': out += '\f'; break;
      case 'n': out += '\n'; break;
      case 'r': out += '\r'; break;
      case 't': out += '\t'; break;
      case 'u': {
        uint32_t cp = hex4();
        if (cp >= 0xD800 && cp <= 0xDBFF) {
          if (!literal("\\u")) fail("a high surrogate \\u escape must be followed by a low one");
          const uint32_t lo = hex4();
          if (lo < 0xDC00 || lo > 0xDFFF) fail("invalid low surrogate in a \\u escape");
          cp = 0x10000 + ((cp - 0xD800) << 10) + (lo - 0xDC00);
        } else if (cp >= 0xDC00 && cp <= 0xDFFF) {
          fail("lone low surrogate in a \\u escape");
        }
        put_utf8(out, cp);
        break;
      }
      default: fail(std::string("invalid escape '\\") + e + "'");
      }
    }
  }

  double number() {
    const size_t start = i_;
    auto digits = [&] {
      const size_t d = i_;
      while (i_ < s_.size() && s_[i_] >= '0' && s_[i_] <= '9') ++i_;
      return i_ - d;
    };
    if (s_[i_] == '-') ++i_;
    if (i_ < s_.size() && s_[i_] == '0') {
      ++i_;
    } else if (digits() == 0) {
      fail("invalid number");
    }
    if (i_ < s_.size() && s_[i_] == '.') {
      ++i_;
      if (digits() == 0) fail("invalid number: digits expected after '.'");
    }
    if (i_ < s_.size() && (s_[i_] == 'e' || s_[i_] == 'E')) {
      ++i_;
      if (i_ < s_.size() && (s_[i_] == '+' || s_[i_] == '-')) ++i_;
      if (digits() == 0) fail("invalid number: digits expected in the exponent");
    }
    double v = 0;
    const auto [p, ec] = std::from_chars(s_.data() + start, s_.data() + i_, v);
    if (ec != std::errc() || p != s_.data() + i_ || !std::isfinite(v))
      fail("number '" + std::string(s_.substr(start, i_ - start)) + "' is out of the range of a double");
    return v;
  }

  std::string_view s_;
  std::string file_;
  size_t i_ = 0;
  size_t mark_ = 0;
  int line_ = 1, col_ = 1;
};

} // namespace

const Value* Value::find(std::string_view key) const {
  for (const auto& [k, val] : object())
    if (k == key) return &val;
  return nullptr;
}

const char* Value::type_name() const {
  static constexpr const char* names[] = {"null", "true/false", "number", "string", "array", "object"};
  return names[v.index()];
}

Value parse(std::string_view text, const std::filesystem::path& file) { return Parser(text, file).document(); }

Value parse_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "cannot open the file");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw InputError(file.string(), "cannot read the file");
  return parse(ss.str(), file);
}

} // namespace prt::bake::json
