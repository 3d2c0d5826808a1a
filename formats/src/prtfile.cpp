// prtfile.cpp — model helpers (lookups, dtype names), the shared HDF5 plumbing of h5util.h and
// the UTF-8 check of utf8.h.
#include <formats/prtfile.h>

#include "h5util.h"
#include "utf8.h"

#include <Imath/half.h>

#include <limits>

namespace prt::formats {

const Attr* find_attr(const std::vector<Attr>& attrs, std::string_view name) {
  for (const Attr& a : attrs)
    if (a.name == name) return &a;
  return nullptr;
}

std::string describe(const SkippedAttr& skipped) {
  return "attribute '" + skipped.name + "' of " + skipped.owner + " skipped: " + skipped.reason;
}

const Dataset* find_dataset(const File& file, std::string_view path) {
  for (const Dataset& d : file.datasets)
    if (d.path == path) return &d;
  return nullptr;
}

const std::vector<Attr>* find_group_attrs(const File& file, std::string_view group_path) {
  for (const auto& [path, attrs] : file.group_attrs)
    if (path == group_path) return &attrs;
  return nullptr;
}

std::string_view dtype_name(const DatasetData& data) {
  switch (data.index()) {
  case 0: return "float32";
  case 1: return "uint32";
  case 2: return "uint8";
  case 3: return "float64";
  default: return "float16";
  }
}

float to_float(Float16 h) { return float(Imath::half(Imath::half::FromBits, h.bits)); }
Float16 to_float16(float f) { return Float16{Imath::half(f).bits()}; }
std::vector<uint16_t> float16_bits(const std::vector<float>& values) {
  std::vector<uint16_t> bits(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) bits[i] = to_float16(values[i]).bits;
  return bits;
}

std::size_t element_count(const DatasetData& data) {
  return std::visit([](const auto& v) { return v.size(); }, data);
}

uint64_t shape_product(const std::vector<uint64_t>& shape) {
  uint64_t n = 1;
  for (uint64_t d : shape) {
    if (d != 0 && n > std::numeric_limits<uint64_t>::max() / d)
      throw FormatError("", "shape product overflows 64 bits");
    n *= d;
  }
  return n;
}

namespace detail {

std::mutex& hdf5_mutex() {
  static std::mutex m;
  // Before HDF5's first call here: no library shutdown at exit. A file whose close failed (a full
  // disk under a direct chunk write) stays half-open in HDF5 1.10, and its exit handler crashes
  // on it after our one-line error; we close every file we open ourselves, or report why not.
  static const bool no_exit_handler = H5dont_atexit() >= 0;
  (void)no_exit_handler;
  return m;
}

void silence_hdf5_errors() { H5Eset_auto(H5E_DEFAULT, nullptr, nullptr); }

namespace {
herr_t first_error(unsigned n, const H5E_error2_t* err, void* out) {
  auto* s = static_cast<std::string*>(out);
  if (n == 0 && err != nullptr && err->desc != nullptr) *s = err->desc;
  return 0;
}
} // namespace

std::string take_hdf5_error() {
  std::string msg;
  // Upward: the first record is the most specific one (e.g. "truncated file: eof = ...").
  H5Ewalk(H5E_DEFAULT, H5E_WALK_UPWARD, &first_error, &msg);
  H5Eclear(H5E_DEFAULT);
  // Keep the message on one line.
  for (char& c : msg)
    if (c == '\n' || c == '\r') c = ' ';
  return msg;
}

bool valid_utf8(std::string_view s) {
  std::size_t i = 0;
  while (i < s.size()) {
    const auto c = static_cast<unsigned char>(s[i]);
    std::size_t n = 0;
    uint32_t cp = 0;
    if (c < 0x80) { ++i; continue; }
    if ((c & 0xE0) == 0xC0) { n = 1; cp = c & 0x1F; }
    else if ((c & 0xF0) == 0xE0) { n = 2; cp = c & 0x0F; }
    else if ((c & 0xF8) == 0xF0) { n = 3; cp = c & 0x07; }
    else return false;
    if (i + n >= s.size()) return false;  // truncated sequence
    for (std::size_t k = 1; k <= n; ++k) {
      const auto cc = static_cast<unsigned char>(s[i + k]);
      if ((cc & 0xC0) != 0x80) return false;
      cp = (cp << 6) | (cc & 0x3F);
    }
    // Overlong forms, surrogates and out-of-range code points are invalid.
    if ((n == 1 && cp < 0x80) || (n == 2 && cp < 0x800) || (n == 3 && cp < 0x10000) ||
        cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF))
      return false;
    i += n + 1;
  }
  return true;
}

Hid make_float16_type() {
  Hid t = type_id(H5Tcopy(H5T_IEEE_F32LE));
  if (!t.valid() || H5Tset_fields(t.get(), 15, 10, 5, 0, 10) < 0 || H5Tset_size(t.get(), 2) < 0 ||
      H5Tset_ebias(t.get(), 15) < 0)
    return {};
  return t;
}

bool is_float16_layout(hid_t type) {
  std::size_t spos = 0, epos = 0, esize = 0, mpos = 0, msize = 0;
  return H5Tget_class(type) == H5T_FLOAT && H5Tget_size(type) == 2 && H5Tget_precision(type) == 16 &&
         H5Tget_offset(type) == 0 && H5Tget_fields(type, &spos, &epos, &esize, &mpos, &msize) >= 0 && spos == 15 &&
         epos == 10 && esize == 5 && mpos == 0 && msize == 10 && H5Tget_ebias(type) == 15 &&
         H5Tget_norm(type) == H5T_NORM_IMPLIED;
}

Hid make_utf8_string_type(std::size_t bytes) {
  Hid t = type_id(H5Tcopy(H5T_C_S1));
  if (!t.valid() || H5Tset_size(t.get(), bytes > 0 ? bytes : 1) < 0 ||
      H5Tset_strpad(t.get(), H5T_STR_NULLPAD) < 0 || H5Tset_cset(t.get(), H5T_CSET_UTF8) < 0)
    return {};
  return t;
}

} // namespace detail
} // namespace prt::formats
