// The reader's own global heap reader (formats/src/global_heap.h): HDF5 global heap collections
// built byte by byte as the File Format Specification (III.E) lays them out, then damaged in
// each way a hostile or broken file can: every object comes back whole, or a HeapError says
// what is wrong; never a read outside the collection or the file (the asan preset checks).
#include "global_heap.h"

#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

namespace {

using prt::formats::detail::decode_heap_id;
using prt::formats::detail::GlobalHeaps;
using prt::formats::detail::HeapError;
using prt::formats::detail::HeapId;

void put(std::vector<unsigned char>& b, std::size_t at, uint64_t v, int bytes) {
  for (int k = 0; k < bytes; ++k) b[at + std::size_t(k)] = static_cast<unsigned char>(v >> (8 * k));
}

// A file of `prefix` zero bytes, then a collection of `size` bytes holding `objects` (index,
// text) in order, then the free-space object when 16 bytes or more are left.
struct HeapFile {
  std::vector<unsigned char> bytes;
  uint64_t collection = 0;
  std::vector<std::size_t> object_at;  // each object's header offset in `bytes`

  HeapFile(std::size_t prefix, std::size_t size, const std::vector<std::pair<uint16_t, std::string>>& objects)
      : bytes(prefix + size, 0), collection(prefix) {
    std::memcpy(bytes.data() + prefix, "GCOL", 4);
    bytes[prefix + 4] = 1;
    put(bytes, prefix + 8, size, 8);
    std::size_t at = prefix + 16;
    for (const auto& [index, text] : objects) {
      object_at.push_back(at);
      put(bytes, at, index, 2);
      put(bytes, at + 8, text.size(), 8);
      std::memcpy(bytes.data() + at + 16, text.data(), text.size());
      at += 16 + (text.size() + 7) / 8 * 8;
    }
    if (prefix + size - at >= 16) put(bytes, at + 8, prefix + size - at, 8);  // index 0: free space
  }
  GlobalHeaps heaps() const {
    return GlobalHeaps(bytes.size(), [this](uint64_t at, void* out, std::size_t n) {
      if (at > bytes.size() || n > bytes.size() - at) return false;
      std::memcpy(out, bytes.data() + at, n);
      return true;
    });
  }
  HeapId id(uint32_t index, uint32_t length) const { return {length, collection, index}; }
};

// The HeapError's message, or "" when the object was read.
std::string error_of(GlobalHeaps& heaps, const HeapId& id) {
  try {
    (void)heaps.object(id);
    return "";
  } catch (const HeapError& e) {
    return e.what();
  }
}

const std::vector<std::pair<uint16_t, std::string>> kNotes = {{1, "root note \xe2\x9c\x93"}, {2, "group note"}, {3, "x"}};

TEST(GlobalHeap, ObjectsOfAWellFormedCollectionAreReadWhole) {
  const HeapFile f(96, 4096, kNotes);
  GlobalHeaps heaps = f.heaps();
  EXPECT_EQ(heaps.object(f.id(1, 13)), "root note \xe2\x9c\x93");
  EXPECT_EQ(heaps.object(f.id(2, 10)), "group note");
  EXPECT_EQ(heaps.object(f.id(3, 1)), "x");
  EXPECT_EQ(heaps.object(f.id(2, 5)), "group");  // a shorter length reads the object's start
  EXPECT_EQ(heaps.object(f.id(7, 0)), "");       // length 0: nothing is read
  EXPECT_EQ(heaps.object({0, 0, 0}), "");        // HDF5's null reference
}

TEST(GlobalHeap, ACollectionThatEndsWithoutFreeSpaceIsRead) {
  // 16 + 32 + 32 + 24 bytes: the objects fill the collection, HDF5 then writes no free space.
  const HeapFile f(8, 104, kNotes);
  GlobalHeaps heaps = f.heaps();
  EXPECT_EQ(heaps.object(f.id(3, 1)), "x");
  EXPECT_EQ(heaps.object(f.id(1, 13)), "root note \xe2\x9c\x93");
}

TEST(GlobalHeap, ReferencesOutsideTheFileAreRefusedNamingTheAddress) {
  const HeapFile f(96, 4096, kNotes);
  GlobalHeaps heaps = f.heaps();
  const uint64_t n = f.bytes.size();
  for (const uint64_t address : {n, n - 8, n + 1, uint64_t{1} << 62, ~uint64_t{0}}) {
    const std::string e = error_of(heaps, {4, address, 1});
    EXPECT_EQ(e, "the global heap collection at byte " + std::to_string(address) + " lies outside the file (" +
                     std::to_string(n) + " bytes)");
  }
  EXPECT_EQ(error_of(heaps, {4, 0, 1}), "a reference to no collection (a null string) with a length of 4 bytes");
  EXPECT_EQ(error_of(heaps, {4, 100, 1}), "no global heap collection starts at byte 100");
}

TEST(GlobalHeap, DamagedCollectionHeadersAreRefused) {
  {
    HeapFile f(96, 4096, kNotes);
    f.bytes[96 + 4] = 2;
    GlobalHeaps heaps = f.heaps();
    EXPECT_EQ(error_of(heaps, f.id(1, 13)), "the global heap collection at byte 96 has version 2 (HDF5 writes version 1)");
  }
  {  // a truncated collection: it claims more bytes than the file has after it
    HeapFile f(96, 4096, kNotes);
    f.bytes.resize(96 + 2000);
    GlobalHeaps heaps = f.heaps();
    EXPECT_EQ(error_of(heaps, f.id(1, 13)),
              "the global heap collection at byte 96 claims 4096 bytes, the file has 2000 from there (truncated?)");
  }
  for (const uint64_t size : {uint64_t{0}, uint64_t{15}}) {
    HeapFile f(96, 4096, kNotes);
    put(f.bytes, 96 + 8, size, 8);
    GlobalHeaps heaps = f.heaps();
    EXPECT_EQ(error_of(heaps, f.id(1, 13)), "the global heap collection at byte 96 claims " + std::to_string(size) +
                                                 " bytes, less than its own header");
  }
}

TEST(GlobalHeap, ObjectsRunningPastTheCollectionAreRefused) {
  for (const uint64_t size : {uint64_t{4096}, uint64_t{4096 - 16 - 32 + 1}, ~uint64_t{0}, uint64_t{1} << 63}) {
    HeapFile f(96, 4096, kNotes);
    put(f.bytes, f.object_at[1] + 8, size, 8);  // object 2's size
    GlobalHeaps heaps = f.heaps();
    const std::string e = error_of(heaps, f.id(3, 1));  // object 3 lies after the damage
    EXPECT_EQ(e, "object 2 of the global heap collection at byte 96 claims " + std::to_string(size) +
                     " bytes, past the collection's end (" + std::to_string(4096 - 16 - 32 - 16) + " bytes left)");
    EXPECT_EQ(error_of(heaps, f.id(1, 13)), e) << "a collection found damaged stays refused";
  }
}

TEST(GlobalHeap, MissingObjectsShortObjectsAndDuplicatesAreRefused) {
  const HeapFile f(96, 4096, kNotes);
  GlobalHeaps heaps = f.heaps();
  EXPECT_EQ(error_of(heaps, f.id(9, 3)), "the global heap collection at byte 96 holds no object 9");
  EXPECT_EQ(error_of(heaps, f.id(2, 11)),
            "its 11 bytes run past object 2 of the global heap collection at byte 96 (10 bytes)");
  EXPECT_EQ(error_of(heaps, f.id(1, 4'000'000'000u)),
            "its 4000000000 bytes run past object 1 of the global heap collection at byte 96 (13 bytes)");
  HeapFile twice(96, 4096, {{1, "a"}, {1, "b"}});
  GlobalHeaps h2 = twice.heaps();
  EXPECT_EQ(error_of(h2, twice.id(1, 1)), "the global heap collection at byte 96 holds object 1 twice");
}

TEST(GlobalHeap, OverlappingCollectionsAreReadOnceNotOverAndOver) {
  // Two collections that share bytes: a sound file's never do, and reading collections again and
  // again would cost more than the file's size.
  HeapFile f(8, 4096, kNotes);  // collection 8..4104, the file 4168 bytes
  f.bytes.resize(8 + 4096 + 64);
  std::memcpy(f.bytes.data() + 2048, "GCOL", 4);  // a second header in the first one's free space
  f.bytes[2048 + 4] = 1;
  put(f.bytes, 2048 + 8, 2048, 8);
  GlobalHeaps heaps = f.heaps();
  EXPECT_EQ(heaps.object(f.id(1, 13)), "root note \xe2\x9c\x93");
  EXPECT_EQ(error_of(heaps, {1, 2048, 1}),
            "the global heap collection at byte 2048 overlaps the collections read before it (damaged?)");
}

TEST(GlobalHeap, EveryTruncationAndFlippedByteGivesTheObjectOrAHeapError) {
  const HeapFile original(32, 256, kNotes);
  const std::vector<HeapId> ids = {original.id(1, 13), original.id(2, 10), original.id(3, 1)};
  int read = 0, refused = 0;
  auto each = [&](const HeapFile& f) {
    GlobalHeaps heaps = f.heaps();
    for (const HeapId& id : ids) {
      try {
        EXPECT_EQ(heaps.object(id).size(), id.length);
        ++read;
      } catch (const HeapError& e) {
        EXPECT_GT(std::strlen(e.what()), 20u);
        ++refused;
      }
    }
  };
  for (std::size_t size = 0; size < original.bytes.size(); ++size) {
    HeapFile f = original;
    f.bytes.resize(size);
    each(f);
  }
  for (std::size_t at = 32; at < original.bytes.size(); ++at)
    for (const unsigned char mask : {0xffu, 0x01u, 0x80u}) {
      HeapFile f = original;
      f.bytes[at] ^= mask;
      each(f);
    }
  EXPECT_GT(read, 0);
  EXPECT_GT(refused, 0);
}

TEST(GlobalHeap, HeapIdsDecodeLittleEndian) {
  const unsigned char stored[16] = {13, 0, 0, 0, 0x47, 0xde, 0x04, 0, 0, 0, 0, 0, 6, 0, 0, 0};
  const HeapId id = decode_heap_id(stored);
  EXPECT_EQ(id.length, 13u);
  EXPECT_EQ(id.collection, 0x04de47u);
  EXPECT_EQ(id.index, 6u);
}

} // namespace
