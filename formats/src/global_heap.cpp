// global_heap.cpp — variable-length strings without HDF5 reading the global heap (see
// global_heap.h; layouts: HDF5 File Format Specification 3.0, III.E and IV.A.2.d).
#include "global_heap.h"

#include "h5util.h"

#include <cstring>
#include <mutex>

namespace prt::formats::detail {
namespace {

constexpr std::size_t kCollectionHeader = 16;  // "GCOL", version, 3 reserved, size (8)
constexpr std::size_t kObjectHeader = 16;      // index (2), references (2), reserved (4), size (8)
constexpr char kHeapIdsTag[] = "prtbake: variable-length references as stored";

uint64_t little_endian(const unsigned char* p, int bytes) noexcept {
  uint64_t v = 0;
  for (int k = bytes - 1; k >= 0; --k) v = (v << 8) | p[k];
  return v;
}

std::string at_address(uint64_t address) { return "at byte " + std::to_string(address); }

// The conversion from a variable-length string as the file stores it to the opaque type tagged
// kHeapIdsTag: the identity on the stored bytes (both are kHeapIdBytes wide), so H5Aread hands
// them back as they are. INIT accepts only that pair, so no other conversion is affected; HDF5
// has no conversion of its own from a variable-length string to an opaque type.
herr_t heap_ids_as_stored(hid_t src, hid_t dst, H5T_cdata_t* cdata, std::size_t, std::size_t, std::size_t, void*,
                          void*, hid_t) {
  switch (cdata->command) {
  case H5T_CONV_INIT: {
    cdata->need_bkg = H5T_BKG_NO;
    if (H5Tget_class(src) != H5T_STRING || H5Tis_variable_str(src) <= 0 || H5Tget_size(src) != kHeapIdBytes ||
        H5Tget_class(dst) != H5T_OPAQUE || H5Tget_size(dst) != kHeapIdBytes)
      return -1;
    char* tag = H5Tget_tag(dst);
    const bool ours = tag != nullptr && std::strcmp(tag, kHeapIdsTag) == 0;
    H5free_memory(tag);
    return ours ? 0 : -1;
  }
  case H5T_CONV_CONV: return 0;  // same width, same bytes
  case H5T_CONV_FREE: return 0;
  }
  return -1;
}

Hid heap_ids_type() {
  Hid t = type_id(H5Tcreate(H5T_OPAQUE, kHeapIdBytes));
  if (!t.valid() || H5Tset_tag(t.get(), kHeapIdsTag) < 0) return {};
  return t;
}

// Registers heap_ids_as_stored once per process (the caller holds hdf5_mutex()).
bool register_conversion() {
  static bool registered = false;
  if (registered) return true;
  Hid vlen = type_id(H5Tcopy(H5T_C_S1));
  Hid ids = heap_ids_type();
  if (!vlen.valid() || !ids.valid() || H5Tset_size(vlen.get(), H5T_VARIABLE) < 0) return false;
  registered = H5Tregister(H5T_PERS_SOFT, "prtbake: variable-length string -> references as stored", vlen.get(),
                           ids.get(), &heap_ids_as_stored) >= 0;
  return registered;
}

} // namespace

HeapId decode_heap_id(const unsigned char* bytes) noexcept {
  return {static_cast<uint32_t>(little_endian(bytes, 4)), little_endian(bytes + 4, 8),
          static_cast<uint32_t>(little_endian(bytes + 12, 4))};
}

std::vector<HeapId> read_heap_ids(hid_t attr, std::size_t n) {
  if (!register_conversion()) return {};
  Hid ids = heap_ids_type();
  if (!ids.valid()) return {};
  std::vector<unsigned char> stored(n * kHeapIdBytes);
  if (n > 0 && H5Aread(attr, ids.get(), stored.data()) < 0) return {};
  std::vector<HeapId> out(n);
  for (std::size_t i = 0; i < n; ++i) out[i] = decode_heap_id(stored.data() + i * kHeapIdBytes);
  return out;
}

GlobalHeaps::Collection GlobalHeaps::load(uint64_t address) {
  Collection c;
  auto unusable = [&](std::string why) {
    c.error = std::move(why);
    c.bytes.clear();
    c.objects.clear();
    return std::move(c);
  };
  const std::string where = "the global heap collection " + at_address(address);
  if (address > file_size_ || file_size_ - address < kCollectionHeader)
    return unusable(where + " lies outside the file (" + std::to_string(file_size_) + " bytes)");
  unsigned char head[kCollectionHeader];
  if (!read_(address, head, sizeof head)) return unusable("cannot read " + where);
  if (std::memcmp(head, "GCOL", 4) != 0) return unusable("no global heap collection starts " + at_address(address));
  if (head[4] != 1)
    return unusable(where + " has version " + std::to_string(head[4]) + " (HDF5 writes version 1)");
  const uint64_t size = little_endian(head + 8, 8);
  if (size < kCollectionHeader)
    return unusable(where + " claims " + std::to_string(size) + " bytes, less than its own header");
  if (size > file_size_ - address)
    return unusable(where + " claims " + std::to_string(size) + " bytes, the file has " +
                    std::to_string(file_size_ - address) + " from there (truncated?)");
  // A sound file's collections are disjoint, so together they fit in the file; more means
  // collections overlap (damaged), and reading them again would cost more than the file's size.
  if (size > file_size_ - bytes_loaded_)
    return unusable(where + " overlaps the collections read before it (damaged?)");
  bytes_loaded_ += size;
  c.bytes.resize(static_cast<std::size_t>(size));
  if (!read_(address, c.bytes.data(), c.bytes.size())) return unusable("cannot read " + where);

  // The objects, from the header to the free space (index 0) or to the collection's end (HDF5
  // leaves out the free-space object when fewer than an object header's bytes are left).
  std::size_t at = kCollectionHeader;
  while (c.bytes.size() - at >= kObjectHeader) {
    const unsigned char* h = c.bytes.data() + at;
    const auto index = static_cast<uint32_t>(little_endian(h, 2));
    if (index == 0) break;
    const uint64_t object_size = little_endian(h + 8, 8);
    const std::size_t data = at + kObjectHeader;
    const std::size_t left = c.bytes.size() - data;
    if (object_size > left)
      return unusable("object " + std::to_string(index) + " of " + where + " claims " + std::to_string(object_size) +
                      " bytes, past the collection's end (" + std::to_string(left) + " bytes left)");
    if (!c.objects.emplace(index, std::make_pair(data, static_cast<std::size_t>(object_size))).second)
      return unusable(where + " holds object " + std::to_string(index) + " twice");
    // The data is padded to a multiple of 8 bytes; padding past the end ends the walk.
    const std::size_t padded = static_cast<std::size_t>(object_size + (8 - object_size % 8) % 8);
    at = padded >= left ? c.bytes.size() : data + padded;
  }
  return c;
}

std::string GlobalHeaps::object(const HeapId& id) {
  if (id.length == 0) return "";
  if (id.collection == 0)
    throw HeapError("a reference to no collection (a null string) with a length of " + std::to_string(id.length) +
                    " bytes");
  auto it = collections_.find(id.collection);
  if (it == collections_.end()) it = collections_.emplace(id.collection, load(id.collection)).first;
  const Collection& c = it->second;
  if (!c.error.empty()) throw HeapError(c.error);
  const auto object = c.objects.find(id.index);
  if (object == c.objects.end())
    throw HeapError("the global heap collection " + at_address(id.collection) + " holds no object " +
                    std::to_string(id.index));
  const auto [offset, size] = object->second;
  if (id.length > size)
    throw HeapError("its " + std::to_string(id.length) + " bytes run past object " + std::to_string(id.index) +
                    " of the global heap collection " + at_address(id.collection) + " (" + std::to_string(size) +
                    " bytes)");
  return std::string(reinterpret_cast<const char*>(c.bytes.data() + offset), id.length);
}

} // namespace prt::formats::detail
