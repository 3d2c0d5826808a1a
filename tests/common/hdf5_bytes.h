// Byte-level edits of an HDF5 file for the hostile-input tests of variable-length strings
// (formats/src/global_heap.h): the global heap collection h5py appends (no checksum, so any byte
// of it can be changed), and a variable-length reference stored in a checksummed object header
// chunk, changed and re-sealed with HDF5's own checksum so that HDF5 accepts the header and the
// changed reference reaches the reader's heap code. Layouts: HDF5 File Format Specification 3.0,
// III.E (global heap), IV.A.1.b (object header continuation chunk "OCHK": its checksum is the
// chunk's last 4 bytes, over every byte before them) and IV.A.2.d (a variable-length element:
// length (4 bytes), collection address (8), object index (4)).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

// HDF5's metadata checksum (Jenkins' lookup3), exported by libhdf5 though not declared in its
// public headers; the tests that use this header link HDF5 through prt::formats.
extern "C" uint32_t H5_checksum_metadata(const void* data, size_t len, uint32_t initval);

namespace prt::testing {

using Bytes = std::vector<unsigned char>;

inline Bytes file_bytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), {});
}
inline void write_file_bytes(const std::filesystem::path& file, const Bytes& bytes) {
  std::ofstream(file, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

inline uint64_t get_le(const Bytes& b, std::size_t at, int n) {
  uint64_t v = 0;
  for (int k = n - 1; k >= 0; --k) v = (v << 8) | b.at(at + std::size_t(k));
  return v;
}
inline void put_le(Bytes& b, std::size_t at, uint64_t v, int n) {
  for (int k = 0; k < n; ++k) b.at(at + std::size_t(k)) = static_cast<unsigned char>(v >> (8 * k));
}

// Where `text` occurs in `bytes`, which must hold it exactly once.
inline std::size_t find_once(const Bytes& bytes, const std::string& text) {
  std::size_t found = std::string::npos, count = 0;
  for (std::size_t at = 0; at + text.size() <= bytes.size(); ++at)
    if (std::memcmp(bytes.data() + at, text.data(), text.size()) == 0) found = at, ++count;
  if (count != 1) throw std::runtime_error("'" + text + "' occurs " + std::to_string(count) + " times, not once");
  return found;
}

// The one global heap collection of a file (h5py writes one for a few short strings).
inline std::size_t only_collection(const Bytes& bytes) { return find_once(bytes, "GCOL"); }

// The header offset of object `index` in the collection at `gcol` (objects walked as stored).
inline std::size_t heap_object(const Bytes& bytes, std::size_t gcol, uint32_t index) {
  const std::size_t end = gcol + get_le(bytes, gcol + 8, 8);
  for (std::size_t at = gcol + 16; at + 16 <= end;) {
    const uint64_t i = get_le(bytes, at, 2), size = get_le(bytes, at + 8, 8);
    if (i == index) return at;
    if (i == 0) break;
    at += 16 + (size + 7) / 8 * 8;
  }
  throw std::runtime_error("no heap object " + std::to_string(index));
}

// A variable-length element as stored: 16 bytes.
inline std::string heap_id(uint32_t length, uint64_t collection, uint32_t index) {
  Bytes b(16);
  put_le(b, 0, length, 4);
  put_le(b, 4, collection, 8);
  put_le(b, 12, index, 4);
  return std::string(b.begin(), b.end());
}

// Replaces the stored reference `from` (heap_id) by `to` inside the object header continuation
// chunk that holds it, and writes the chunk's checksum anew.
inline void replace_heap_id_in_chunk(Bytes& bytes, const std::string& from, const std::string& to) {
  const std::size_t at = find_once(bytes, from);
  std::size_t chunk = std::string::npos;
  for (std::size_t s = at; s-- > 0;)
    if (std::memcmp(bytes.data() + s, "OCHK", 4) == 0) {
      chunk = s;
      break;
    }
  if (chunk == std::string::npos) throw std::runtime_error("the reference is in no continuation chunk");
  std::size_t sum = std::string::npos;  // the chunk's end: where its checksum matches
  for (std::size_t e = at + from.size(); e + 4 <= bytes.size() && e < at + 65536; ++e)
    if (H5_checksum_metadata(bytes.data() + chunk, e - chunk, 0) == get_le(bytes, e, 4)) {
      sum = e;
      break;
    }
  if (sum == std::string::npos) throw std::runtime_error("no checksum closes the chunk");
  std::memcpy(bytes.data() + at, to.data(), to.size());
  put_le(bytes, sum, H5_checksum_metadata(bytes.data() + chunk, sum - chunk, 0), 4);
}

} // namespace prt::testing
