// global_heap.h (private) — variable-length strings read without HDF5 reading the global heap.
//
// h5py stores a str attribute (`f.attrs["note"] = "text"`) as an HDF5 variable-length string:
// the attribute's data in the (checksummed) object header holds, per string, a reference into a
// global heap collection, and the text lives in that collection, which has no checksum. HDF5
// 1.10 walks a collection's objects without bounds checks (a flipped size byte crashed or hung
// it: docs/RELIABILITY.md), so the reader never lets HDF5 read a global heap. Instead:
//   1. read_heap_ids: H5Aread converts the attribute's data to an opaque type of ours through a
//      conversion function registered for that one pair of types (vlen string -> "prtbake heap
//      ids"), which hands back the stored bytes unchanged: HDF5 decodes the checksummed header
//      and never follows the references;
//   2. GlobalHeaps::object: our own reader of the collection, from the raw bytes, every offset and
//      size checked against the collection and the file.
// Byte layouts: HDF5 File Format Specification 3.0, III.E "Global Heap" (collection: "GCOL",
// version 1, 3 reserved bytes, collection size (8 bytes, the size of lengths), then objects:
// index (2), reference count (2), reserved (4), size (8), the data padded to a multiple of 8;
// index 0 is the free space, the rest of the collection), and IV.A.2.d, class 9 (a
// variable-length element is its length (4 bytes), the collection's address (8, the size of
// offsets) and the object's index (4)). The reader accepts 8-byte offsets and lengths only
// (reader.cpp, check_superblock).
#pragma once

#include <hdf5.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace prt::formats::detail {

// One variable-length element as the file stores it.
struct HeapId {
  uint32_t length = 0;      // elements: bytes, for a string
  uint64_t collection = 0;  // the collection's file address (0: no data, a null string)
  uint32_t index = 0;       // the object's index in it
};
inline constexpr std::size_t kHeapIdBytes = 16;

// Decodes a HeapId from kHeapIdBytes little-endian bytes.
HeapId decode_heap_id(const unsigned char* bytes) noexcept;

// The HeapIds of the variable-length string attribute `attr` (n elements, its dataspace's
// size), read by H5Aread without HDF5 touching the global heap (step 1 above). An empty result
// with n > 0 means HDF5 refused the conversion (its error stack says why).
std::vector<HeapId> read_heap_ids(hid_t attr, std::size_t n);

// What is wrong with a reference or a collection; what() says it in words, naming addresses.
class HeapError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

// The global heap collections of one file, each read once (step 2 above). Not thread-safe; one
// per read of a file.
class GlobalHeaps {
public:
  // Reads [at, at + n) of the file into `out`; false when that range is not inside the file.
  using ReadBytes = std::function<bool(uint64_t at, void* out, std::size_t n)>;
  GlobalHeaps(uint64_t file_size, ReadBytes read) : file_size_(file_size), read_(std::move(read)) {}

  // The `id.length` bytes of the object `id` names: "" when the length is 0 or the collection
  // address is 0 (HDF5's null reference); else the collection must be whole and well formed
  // and hold the object, with at least `id.length` bytes. Throws HeapError otherwise.
  std::string object(const HeapId& id);

private:
  struct Collection {
    std::vector<unsigned char> bytes;                           // the whole collection
    std::map<uint32_t, std::pair<std::size_t, std::size_t>> objects;  // index -> data offset, size
    std::string error;  // why it cannot be used ("" when it can)
  };
  Collection load(uint64_t address);

  uint64_t file_size_;
  ReadBytes read_;
  std::map<uint64_t, Collection> collections_;
  uint64_t bytes_loaded_ = 0;  // the collections of a sound file are disjoint: at most the file
};

} // namespace prt::formats::detail
