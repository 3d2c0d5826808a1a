// chunk_filters.h (private) — our datasets' HDF5 filter pipeline, applied by the writer itself so
// that chunks are compressed in parallel and written whole with H5Dwrite_chunk (docs/ARCHITECTURE.md
// "Schema"; formats/SCHEMA.md "Storage"). The pipeline is the one every dataset declares:
//   shuffle (HDF5 filter 2) → deflate, zlib format (filter 1) → Fletcher-32 (filter 3, optional).
// Any HDF5 reader undoes it with the library's own filters; the deflate stream comes from
// libdeflate instead of zlib (a different, equally valid stream: smaller here and ~2× faster).
// Nothing here is public API.
//
// Conventions fixed by HDF5's format (tests/formats/test_chunk_filters.cpp checks each against
// the library's own filters on the same chunk):
//   - shuffle: byte j of element i goes to position j·n + i (n elements of `element_size` bytes);
//     bytes past the last whole element stay where they are.
//   - Fletcher-32: the data read as 16-bit big-endian words (an odd last byte is the high byte of
//     a word whose low byte is 0); both 16-bit sums are folded (mod 65535 with 65535 kept as is)
//     every 360 words and at the end; the checksum is sum2·65536 + sum1, appended little-endian.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace prt::formats::detail {

// HDF5's Fletcher-32 of `bytes` (the convention above).
uint32_t fletcher32(std::span<const std::byte> bytes);

// HDF5's shuffle of `in` into `out` (same size).
void shuffle_bytes(std::span<const std::byte> in, std::size_t element_size, std::span<std::byte> out);

// The pipeline for one thread: not thread-safe; one per thread.
class ChunkEncoder {
public:
  // `level`: deflate level (1–12, libdeflate's scale; 6 is its default). `checksum`: append
  // Fletcher-32.
  ChunkEncoder(int level, bool checksum);
  ~ChunkEncoder();
  ChunkEncoder(const ChunkEncoder&) = delete;
  ChunkEncoder& operator=(const ChunkEncoder&) = delete;

  // The stored bytes of one chunk (`chunk`: the whole chunk, padding included).
  std::vector<std::byte> encode(std::span<const std::byte> chunk, std::size_t element_size);

private:
  struct Compressor;
  std::unique_ptr<Compressor> compressor_;
  bool checksum_;
  std::vector<std::byte> shuffled_, compressed_;
};

} // namespace prt::formats::detail
