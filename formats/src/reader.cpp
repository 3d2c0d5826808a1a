// reader.cpp — read_file: check the file's HDF5 structures ourselves, open, check
// format/format_version, read everything, validate.
// Hostile input: every HDF5 call is checked, sizes are checked before allocation, link cycles
// and depth are bounded, and only hard links are followed (never external files). HDF5 1.10 does
// not bounds-check what it parses from unchecksummed metadata, so before HDF5 parses a structure
// we check from the raw bytes that it is one of the checksummed kinds our writer makes (the policy
// is in formats/prtfile.h, "Which files the reader opens"; the byte layouts are HDF5's File Format
// Specification version 3.0, sections II.A (superblock) and IV.A.1.b (version-2 object header)),
// and HDF5 never reads a global heap: variable-length strings are read by global_heap.h.
#include <formats/names.h>
#include <formats/prtfile.h>

#include "global_heap.h"
#include "h5util.h"
#include "utf8.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <fstream>
#include <limits>
#include <new>
#include <optional>
#include <tuple>

namespace prt::formats {
namespace {

using detail::Hid;

constexpr int kMaxDepth = 32;
constexpr std::size_t kMaxObjects = 1'000'000;
constexpr std::size_t kMaxAttrValues = std::size_t{1} << 28;

// The file's bytes, read directly, for the structure checks below.
class RawBytes {
public:
  RawBytes(const std::filesystem::path& path, uint64_t size) : in_(path, std::ios::binary), size_(size) {}
  bool ok() const { return static_cast<bool>(in_); }
  uint64_t size() const { return size_; }
  // False when [at, at + n) is not inside the file.
  bool read(uint64_t at, void* out, std::size_t n) {
    if (at > size_ || n > size_ - at) return false;
    in_.clear();
    in_.seekg(static_cast<std::streamoff>(at));
    in_.read(static_cast<char*>(out), static_cast<std::streamsize>(n));
    return static_cast<std::size_t>(in_.gcount()) == n;
  }

private:
  std::ifstream in_;
  uint64_t size_;
};

uint64_t little_endian(const unsigned char* p, int bytes) {
  uint64_t v = 0;
  for (int k = bytes - 1; k >= 0; --k) v = (v << 8) | p[k];
  return v;
}

constexpr unsigned char kSignature[8] = {0x89, 'H', 'D', 'F', '\r', '\n', 0x1a, '\n'};
constexpr uint64_t kUndefinedAddress = ~uint64_t{0};

// The superblock (File Format Specification II.A): HDF5's signature at byte 0, version 2 or 3
// (checksummed; versions 0 and 1 have no checksum and imply unchecksummed structures below them),
// 8-byte offsets and lengths, base address 0, and an end-of-file address the file reaches.
// Returns the root group's object header address and the superblock extension's (or undefined).
struct SuperblockFacts {
  uint64_t root = 0, extension = kUndefinedAddress;
};
SuperblockFacts check_superblock(RawBytes& raw, const std::string& msg_file) {
  auto refuse = [&](const std::string& what) { throw FormatError(msg_file, what); };
  std::array<unsigned char, 48> sb{};  // a version-2/3 superblock with 8-byte offsets: 48 bytes
  if (!raw.read(0, sb.data(), 8) || std::memcmp(sb.data(), kSignature, 8) != 0) {
    // HDF5 also looks for its signature after a user block (at 512, 1024, 2048, ...).
    for (uint64_t at = 512; at < raw.size() && at != 0; at *= 2) {
      unsigned char sig[8];
      if (raw.read(at, sig, 8) && std::memcmp(sig, kSignature, 8) == 0)
        refuse("an HDF5 file with a " + std::to_string(at) + "-byte user block before its data; prtbake files have none");
    }
    refuse("not an HDF5 file (or damaged beyond recognition)");
  }
  if (!raw.read(0, sb.data(), 9)) refuse("truncated: the file ends inside its HDF5 superblock");
  const int version = sb[8];
  if (version < 2)
    refuse("written in HDF5's oldest file format (superblock version " + std::to_string(version) +
           ": no checksums), which prtbake does not open (a damaged file of that format can crash "
           "HDF5 1.10); prtbake writes checksummed files, and `h5repack --latest --filter=FLET IN OUT` "
           "rewrites another tool's file so");
  if (version > 3)
    refuse("HDF5 superblock version " + std::to_string(version) + " is newer than this HDF5 (1.10) reads");
  if (!raw.read(0, sb.data(), sb.size())) refuse("truncated: the file ends inside its HDF5 superblock");
  if (sb[9] != 8 || sb[10] != 8)
    refuse("HDF5 offsets of " + std::to_string(sb[9]) + " and lengths of " + std::to_string(sb[10]) +
           " bytes (prtbake files use 8 and 8)");
  const uint64_t base = little_endian(&sb[12], 8), extension = little_endian(&sb[20], 8),
                 eof = little_endian(&sb[28], 8), root = little_endian(&sb[36], 8);
  if (base != 0) refuse("HDF5 base address " + std::to_string(base) + " (prtbake files use 0)");
  if (eof > raw.size())
    refuse("truncated: " + std::to_string(raw.size()) + " bytes, its HDF5 superblock says " + std::to_string(eof));
  return {root, extension};
}

// A version-2 object header starts with "OHDR" and version 2 (File Format Specification
// IV.A.1.b); HDF5 verifies its checksum when it loads it. A version-1 header has neither.
void check_object_header(RawBytes& raw, uint64_t address, const std::string& what, const std::string& msg_file) {
  unsigned char head[5];
  if (address == kUndefinedAddress || !raw.read(address, head, sizeof head))
    throw FormatError(msg_file, what + " points outside the file (damaged?)");
  if (std::memcmp(head, "OHDR", 4) != 0 || head[4] != 2)
    throw FormatError(msg_file, what + " is not a checksummed (version 2) HDF5 object header: damaged, "
                                       "or written in an old format that prtbake does not open");
}

// An HDF5 type class in words, for the message of an attribute left out for its type.
std::string type_class_name(H5T_class_t c) {
  switch (c) {
  case H5T_TIME: return "an HDF5 time";
  case H5T_BITFIELD: return "an HDF5 bitfield";
  case H5T_OPAQUE: return "an HDF5 opaque type";
  case H5T_COMPOUND: return "an HDF5 compound";
  case H5T_REFERENCE: return "an HDF5 reference";
  case H5T_ENUM: return "an HDF5 enum, as h5py stores a bool";
  case H5T_VLEN: return "an HDF5 variable-length sequence";
  case H5T_ARRAY: return "an HDF5 array type";
  default: return "HDF5 type class " + std::to_string(static_cast<int>(c));
  }
}

class Reader {
public:
  Reader(std::string file_for_messages, RawBytes& raw)
      : msg_file_(std::move(file_for_messages)), file_size_(raw.size()), raw_(raw),
        heaps_(raw.size(), [&raw](uint64_t at, void* out, std::size_t n) { return raw.read(at, out, n); }) {}

  // Deflate cannot expand data by more than ~1032:1, so a dataset (attributes are stored
  // uncompressed) claiming more bytes than that is damaged: refuse before allocating.
  bool plausible(uint64_t bytes, bool compressed) const {
    const uint64_t slack = uint64_t{16} << 20;
    const uint64_t ratio = compressed ? 1100 : 1;
    return file_size_ <= (std::numeric_limits<uint64_t>::max() - slack) / ratio &&
           bytes <= file_size_ * ratio + slack;
  }

  [[noreturn]] void fail(const std::string& what) const {
    const std::string detail = detail::take_hdf5_error();
    throw FormatError(msg_file_, what + (detail.empty() ? "" : " (HDF5: " + detail + ")"));
  }
  Hid check(Hid id, const std::string& what) const {
    if (!id.valid()) fail(what);
    return id;
  }

  // The attributes of `obj` at `path` ("/" for the root group), named `owner` in messages.
  std::vector<Attr> read_attrs(hid_t obj, const std::string& path, const std::string& owner) {
    H5O_info_t info;
    if (H5Oget_info2(obj, &info, H5O_INFO_NUM_ATTRS) < 0) fail("cannot inspect " + owner);
    std::vector<Attr> out;
    for (hsize_t i = 0; i < info.num_attrs; ++i) {
      Hid a = check(detail::attr_id(H5Aopen_by_idx(obj, ".", H5_INDEX_NAME, H5_ITER_INC, i,
                                                  H5P_DEFAULT, H5P_DEFAULT)),
                    "cannot open attribute " + std::to_string(i) + " of " + owner);
      if (std::optional<Attr> attr = read_attr(a.get(), path, owner)) out.push_back(std::move(*attr));
    }
    return out;
  }

  // One attribute, or nullopt when it is left out (listed for take_skipped(): its type is not one
  // the model holds, or its text cannot be read safely from a global heap). Damage that HDF5
  // reports, or sizes the file cannot hold, refuse the file.
  std::optional<Attr> read_attr(hid_t a, const std::string& path, const std::string& owner) {
    Attr out;
    const ssize_t len = H5Aget_name(a, 0, nullptr);
    if (len < 0) fail("cannot read an attribute name of " + owner);
    out.name.resize(static_cast<std::size_t>(len) + 1);
    if (H5Aget_name(a, out.name.size(), out.name.data()) < 0)
      fail("cannot read an attribute name of " + owner);
    out.name.resize(static_cast<std::size_t>(len));
    const std::string what = "attribute '" + out.name + "' of " + owner;
    auto skip = [&](std::string reason) -> std::optional<Attr> {
      skipped_.push_back({path, owner, out.name, std::move(reason)});
      return std::nullopt;
    };

    Hid type = check(detail::type_id(H5Aget_type(a)), "cannot read the type of " + what);
    Hid space = check(detail::space_id(H5Aget_space(a)), "cannot read the shape of " + what);
    const H5S_class_t sclass = H5Sget_simple_extent_type(space.get());
    const hssize_t npoints = sclass == H5S_NULL ? 0 : H5Sget_simple_extent_npoints(space.get());
    if (npoints < 0) fail("cannot read the shape of " + what);
    const auto n = static_cast<std::size_t>(npoints);
    const bool scalar = sclass == H5S_SCALAR;
    const H5T_class_t tclass = H5Tget_class(type.get());
    if (n > kMaxAttrValues || !plausible(uint64_t{16} * n, false))
      fail(what + " claims " + std::to_string(n) + " values, more than the file can hold (damaged?)");

    if (tclass == H5T_STRING) {
      const htri_t is_var = H5Tis_variable_str(type.get());
      if (is_var < 0) fail("cannot read the type of " + what);
      std::vector<std::string> texts;
      if (is_var > 0) {
        // HDF5 hands back the references the (checksummed) attribute stores, never reading the
        // global heap; our own bounds-checked reader takes the text from the raw bytes. The heap
        // has no checksum, so its damage leaves the attribute out rather than the file.
        const std::vector<detail::HeapId> ids = detail::read_heap_ids(a, n);
        if (ids.size() != n) fail("cannot read " + what);
        for (std::size_t i = 0; i < n; ++i) {
          const std::string text = scalar ? std::string("its text") : "the text of its string " + std::to_string(i);
          try {
            std::string s = heaps_.object(ids[i]);
            s.resize(std::min(s.size(), s.find('\0')));
            if (!detail::valid_utf8(s))
              return skip(text + " in the HDF5 global heap, which has no checksum, is not UTF-8 (damaged?)");
            texts.push_back(std::move(s));
          } catch (const detail::HeapError& e) {
            return skip(text + " cannot be read safely from the HDF5 global heap: " + e.what());
          }
        }
      } else {
        const std::size_t size = H5Tget_size(type.get());
        if (size == 0 || !plausible(uint64_t{size} * n, false)) fail(what + " has an invalid string size");
        std::string all(size * n, '\0');
        Hid mem = check(detail::type_id(H5Tcopy(type.get())), what);
        if (n > 0 && H5Aread(a, mem.get(), all.data()) < 0) fail("cannot read " + what);
        for (std::size_t i = 0; i < n; ++i) texts.push_back(all.substr(i * size, size));
      }
      // Text ends at the first NUL (fixed-length strings are padded with them); space-padded
      // strings lose their trailing spaces.
      const bool space_padded = H5Tget_strpad(type.get()) == H5T_STR_SPACEPAD;
      for (std::string& s : texts) {
        s.resize(std::min(s.size(), s.find('\0')));
        if (space_padded) s.erase(s.find_last_not_of(' ') + 1);
      }
      if (scalar) out.value = std::move(texts.at(0));
      else out.value = std::move(texts);
      return out;
    }
    if (tclass != H5T_INTEGER && tclass != H5T_FLOAT)
      return skip("its type (" + type_class_name(tclass) + ") is not one the model holds (strings, integers, floats)");
    if (tclass == H5T_INTEGER) {
      std::vector<int64_t> v(n);
      if (n > 0 && H5Aread(a, H5T_NATIVE_INT64, v.data()) < 0) fail("cannot read " + what);
      if (scalar) out.value = v.at(0);
      else out.value = std::move(v);
    } else {
      std::vector<double> v(n);
      if (n > 0 && H5Aread(a, H5T_NATIVE_DOUBLE, v.data()) < 0) fail("cannot read " + what);
      if (scalar) out.value = v.at(0);
      else out.value = std::move(v);
    }
    return out;
  }

  Dataset read_dataset(hid_t parent, const std::string& link, const std::string& path) {
    const std::string name = "dataset '" + path + "'";
    Dataset out;
    out.path = path;
    Hid ds = check(detail::dataset_id(H5Dopen2(parent, link.c_str(), H5P_DEFAULT)), "cannot open " + name);
    check_structures(ds.get(), name);
    check_chunk_index(ds.get(), name);
    Hid type = check(detail::type_id(H5Dget_type(ds.get())), "cannot read the type of " + name);
    Hid space = check(detail::space_id(H5Dget_space(ds.get())), "cannot read the shape of " + name);
    const int rank = H5Sget_simple_extent_ndims(space.get());
    if (rank < 0 || rank > 32) fail("cannot read the shape of " + name);
    std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
    if (rank > 0 && H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr) < 0)
      fail("cannot read the shape of " + name);
    out.shape.assign(dims.begin(), dims.end());
    uint64_t n = 0;
    try {
      n = shape_product(out.shape);
    } catch (const FormatError&) {
      fail(name + " has a shape whose size overflows");
    }
    if (H5Sget_simple_extent_type(space.get()) == H5S_NULL) n = 0;

    const H5T_class_t tclass = H5Tget_class(type.get());
    const std::size_t size = H5Tget_size(type.get());
    if (n > std::numeric_limits<uint64_t>::max() / 8 || !plausible(n * std::max<std::size_t>(size, 1), true))
      fail(name + " claims " + std::to_string(n) + " values, more than the file can hold (damaged?)");
    hid_t mem = H5I_INVALID_HID;
    detail::Hid half;  // the float16 memory type, when the dataset is one
    void* buf = nullptr;
    try {
      if (tclass == H5T_FLOAT && size == 4) {
        out.data = std::vector<float>(n);
        buf = std::get<0>(out.data).data(), mem = H5T_NATIVE_FLOAT;
      } else if (tclass == H5T_INTEGER && H5Tget_sign(type.get()) == H5T_SGN_NONE && size == 4) {
        out.data = std::vector<uint32_t>(n);
        buf = std::get<1>(out.data).data(), mem = H5T_NATIVE_UINT32;
      } else if (tclass == H5T_INTEGER && H5Tget_sign(type.get()) == H5T_SGN_NONE && size == 1) {
        out.data = std::vector<uint8_t>(n);
        buf = std::get<2>(out.data).data(), mem = H5T_NATIVE_UINT8;
      } else if (tclass == H5T_FLOAT && size == 8) {
        out.data = std::vector<double>(n);
        buf = std::get<3>(out.data).data(), mem = H5T_NATIVE_DOUBLE;
      } else if (tclass == H5T_FLOAT && size == 2) {
        if (!detail::is_float16_layout(type.get()))
          fail(name + " is a 2-byte float that is not IEEE binary16 (the schema's float16)");
        half = detail::make_float16_type();
        if (!half.valid()) fail("cannot make the float16 type to read " + name);
        out.data = std::vector<Float16>(n);
        buf = std::get<4>(out.data).data(), mem = half.get();
      } else {
        fail(name + " has an unsupported type (the schema uses float32, float64, float16, uint32 and uint8)");
      }
    } catch (const std::bad_alloc&) {
      fail(name + " is too large to read (" + std::to_string(n) + " values)");
    } catch (const std::length_error&) {
      fail(name + " is too large to read (" + std::to_string(n) + " values)");
    }
    if (n > 0 && H5Dread(ds.get(), mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) < 0)
      fail("cannot read " + name + " (damaged or truncated data, or a checksum mismatch)");
    out.attrs = read_attrs(ds.get(), path, name);
    return out;
  }

  // Depth-first over hard links in name order: groups, datasets, attributes.
  void read_group(hid_t group, const std::string& path, int depth, File& out) {
    if (depth > kMaxDepth) fail("groups nest deeper than " + std::to_string(kMaxDepth) + " (a link cycle?)");
    H5G_info_t ginfo;
    if (H5Gget_info(group, &ginfo) < 0) fail("cannot read group '" + path + "'");
    for (hsize_t i = 0; i < ginfo.nlinks; ++i) {
      if (++objects_ > kMaxObjects) fail("too many objects (a link cycle?)");
      const ssize_t len = H5Lget_name_by_idx(group, ".", H5_INDEX_NAME, H5_ITER_INC, i, nullptr, 0, H5P_DEFAULT);
      if (len < 0) fail("cannot read a link name in group '" + path + "'");
      std::string link(static_cast<std::size_t>(len) + 1, '\0');
      if (H5Lget_name_by_idx(group, ".", H5_INDEX_NAME, H5_ITER_INC, i, link.data(), link.size(),
                             H5P_DEFAULT) < 0)
        fail("cannot read a link name in group '" + path + "'");
      link.resize(static_cast<std::size_t>(len));
      const std::string child = (path == "/" ? "" : path) + "/" + link;
      H5L_info_t linfo;
      if (H5Lget_info(group, link.c_str(), &linfo, H5P_DEFAULT) < 0) fail("cannot inspect '" + child + "'");
      if (linfo.type != H5L_TYPE_HARD) fail("'" + child + "' is a soft or external link (not supported)");
      check_object_header(raw_, linfo.u.address, "'" + child + "'", msg_file_);
      Hid obj = check(detail::object_id(H5Oopen(group, link.c_str(), H5P_DEFAULT)), "cannot open '" + child + "'");
      const H5I_type_t t = H5Iget_type(obj.get());
      if (t == H5I_GROUP) {
        check_structures(obj.get(), "group '" + child + "'");
        std::vector<Attr> attrs = read_attrs(obj.get(), child, "group '" + child + "'");
        if (!attrs.empty()) out.group_attrs.emplace_back(child, std::move(attrs));
        read_group(obj.get(), child, depth + 1, out);
      } else if (t == H5I_DATASET) {
        obj.close();
        out.datasets.push_back(read_dataset(group, link, child));
      } else {
        fail("'" + child + "' is neither a group nor a dataset (not supported)");
      }
    }
  }

  // What HDF5 cannot be trusted to parse safely, refused from the object header's summary (loaded
  // and checksummed by now): old-style symbol-table groups (version-1 B-trees and local heaps,
  // no checksums; our writer's groups keep their links in the header or in checksummed fractal
  // heaps) and, for datasets, a version-1 B-tree chunk index.
  void check_structures(hid_t obj, const std::string& what) const {
    H5O_info_t info;
    if (H5Oget_info2(obj, &info, H5O_INFO_HDR) < 0) fail("cannot inspect " + what);
    constexpr unsigned kSymbolTableMessage = 0x11;  // File Format Specification IV.A.2.r
    if (info.hdr.version != 2 || (info.hdr.mesg.present >> kSymbolTableMessage) & 1u)
      fail(what + " uses unchecksummed HDF5 structures (an old-style group or object header), "
                  "which prtbake does not open");
  }
  void check_chunk_index(hid_t ds, const std::string& what) const {
    Hid dcpl = check(detail::plist_id(H5Dget_create_plist(ds)), "cannot read the layout of " + what);
    if (H5Pget_layout(dcpl.get()) != H5D_CHUNKED) return;
    H5D_chunk_index_t index;
    if (H5Dget_chunk_index_type(ds, &index) < 0) fail("cannot read the chunk index of " + what);
    if (index == H5D_CHUNK_IDX_BTREE)
      fail(what + " indexes its chunks with an unchecksummed version-1 B-tree, which prtbake does not open");
  }

  // The attributes left out so far (read_attr).
  std::vector<SkippedAttr> take_skipped() { return std::move(skipped_); }

private:
  std::string msg_file_;
  uint64_t file_size_;
  RawBytes& raw_;
  detail::GlobalHeaps heaps_;  // the variable-length strings' collections, each read once
  std::vector<SkippedAttr> skipped_;
  std::size_t objects_ = 0;
};

} // namespace

File read_file(const std::filesystem::path& path, ReadCheck check) {
  const std::string msg_file = path.string();
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) throw FormatError(msg_file, "no such file");
  if (std::filesystem::is_directory(status)) throw FormatError(msg_file, "is a directory, not a file");

  File out;
  {
    const std::lock_guard lock(detail::hdf5_mutex());
    detail::silence_hdf5_errors();
    const uintmax_t size = std::filesystem::file_size(path, ec);
    if (ec) throw FormatError(msg_file, "cannot read the file: " + ec.message());
    RawBytes raw(path, static_cast<uint64_t>(size));
    if (!raw.ok()) throw FormatError(msg_file, "cannot open the file for reading");
    Reader r(msg_file, raw);
    try {
      const SuperblockFacts sb = check_superblock(raw, msg_file);
      check_object_header(raw, sb.root, "the root group", msg_file);
      if (sb.extension != kUndefinedAddress)
        check_object_header(raw, sb.extension, "the superblock extension", msg_file);
      Hid fapl = detail::plist_id(H5Pcreate(H5P_FILE_ACCESS));
      if (!fapl.valid() || H5Pset_fclose_degree(fapl.get(), H5F_CLOSE_STRONG) < 0)
        r.fail("cannot create HDF5 file properties");
      Hid f = detail::file_id(H5Fopen(path.c_str(), H5F_ACC_RDONLY, fapl.get()));
      if (!f.valid()) r.fail("cannot open the HDF5 file (damaged or truncated?)");
      Hid root = r.check(detail::group_id(H5Gopen2(f.get(), "/", H5P_DEFAULT)), "cannot open the root group");
      r.check_structures(root.get(), "the root group");
      out.root_attrs = r.read_attrs(root.get(), "/", "the root group");

      const Attr* fmt = find_attr(out.root_attrs, names::kFormat);
      const auto* fmt_s = fmt ? std::get_if<std::string>(&fmt->value) : nullptr;
      if (fmt_s == nullptr) throw FormatError(msg_file, "not a prtbake file (no '" + std::string(names::kFormat) + "' attribute)");
      if (*fmt_s != kFormatName)
        throw FormatError(msg_file, "not a prtbake file (format = \"" + *fmt_s + "\")");
      const Attr* ver = find_attr(out.root_attrs, names::kFormatVersion);
      const auto* ver_i = ver ? std::get_if<int64_t>(&ver->value) : nullptr;
      if (ver_i == nullptr)
        throw FormatError(msg_file, "prtbake file without an integer '" + std::string(names::kFormatVersion) + "' attribute");
      if (*ver_i > kFormatVersion)
        throw FormatError(msg_file, "written by a newer prtbake (" + std::string(names::kFormatVersion) + " " +
                                        std::to_string(*ver_i) + " > " +
                                        std::to_string(kFormatVersion) + "); update prtbake to read it");
      if (*ver_i < 1)
        throw FormatError(msg_file, "invalid " + std::string(names::kFormatVersion) + " " + std::to_string(*ver_i));

      r.read_group(root.get(), "/", 1, out);
      out.skipped_attrs = r.take_skipped();
      root.close();
      if (f.close() < 0) r.fail("cannot close the file");
    } catch (const std::bad_alloc&) {
      detail::take_hdf5_error();
      throw FormatError(msg_file, "out of memory while reading (damaged sizes?)");
    }
  }
  std::sort(out.datasets.begin(), out.datasets.end(),
            [](const Dataset& a, const Dataset& b) { return a.path < b.path; });
  std::sort(out.group_attrs.begin(), out.group_attrs.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  std::sort(out.skipped_attrs.begin(), out.skipped_attrs.end(),
            [](const SkippedAttr& a, const SkippedAttr& b) { return std::tie(a.path, a.name) < std::tie(b.path, b.name); });
  if (check == ReadCheck::full) validate(out, path);
  return out;
}

} // namespace prt::formats
