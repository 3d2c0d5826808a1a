// chunk_filters.cpp — shuffle → deflate (libdeflate, zlib format) → Fletcher-32, as HDF5's
// filters 2, 1 and 3 store a chunk (chunk_filters.h).
#include "chunk_filters.h"

#include <formats/prtfile.h>

#include <libdeflate.h>

#include <cstring>
#include <string>

namespace prt::formats::detail {

uint32_t fletcher32(std::span<const std::byte> bytes) {
  // Fletcher's two sums over 16-bit big-endian words, modulo 65535 in one's-complement form: a
  // sum that is not zero is kept in [1, 65535] (65535 stands for 0 mod 65535 once anything was
  // added), zero stays zero. Reducing that way at any schedule gives the same result, so the sums
  // are reduced every kBlock words, early enough that 64-bit sums cannot overflow.
  const auto reduce = [](uint64_t s) -> uint64_t { return s == 0 ? 0 : (s - 1) % 65535 + 1; };
  constexpr std::size_t kBlock = 1 << 16;
  uint64_t sum1 = 0, sum2 = 0;
  const std::size_t words = bytes.size() / 2;
  for (std::size_t w = 0; w < words; ++w) {
    sum1 += (uint64_t(std::to_integer<uint8_t>(bytes[2 * w])) << 8) | std::to_integer<uint8_t>(bytes[2 * w + 1]);
    sum2 += sum1;
    if ((w + 1) % kBlock == 0) sum1 = reduce(sum1), sum2 = reduce(sum2);
  }
  if (bytes.size() % 2 != 0) {
    sum1 += uint64_t(std::to_integer<uint8_t>(bytes.back())) << 8;
    sum2 += sum1;
  }
  return uint32_t(reduce(sum2) << 16 | reduce(sum1));
}

void shuffle_bytes(std::span<const std::byte> in, std::size_t element_size, std::span<std::byte> out) {
  const std::size_t n = element_size <= 1 ? 0 : in.size() / element_size;
  // Bytes past the last whole element (all of them for single-byte elements) stay where they are.
  std::memcpy(out.data() + n * element_size, in.data() + n * element_size, in.size() - n * element_size);
  if (n == 0) return;
  for (std::size_t j = 0; j < element_size; ++j) {
    std::byte* to = out.data() + j * n;
    const std::byte* from = in.data() + j;
    for (std::size_t i = 0; i < n; ++i) to[i] = from[i * element_size];
  }
}

struct ChunkEncoder::Compressor {
  libdeflate_compressor* c;
};

ChunkEncoder::ChunkEncoder(int level, bool checksum)
    : compressor_(new Compressor{libdeflate_alloc_compressor(level)}), checksum_(checksum) {
  if (compressor_->c == nullptr)
    throw FormatError("", "cannot allocate a deflate compressor (level " + std::to_string(level) + ")");
}

ChunkEncoder::~ChunkEncoder() { libdeflate_free_compressor(compressor_->c); }

std::vector<std::byte> ChunkEncoder::encode(std::span<const std::byte> chunk, std::size_t element_size) {
  // Scratch buffers live as long as the encoder: no zero-filled allocation per chunk.
  if (shuffled_.size() < chunk.size()) shuffled_.resize(chunk.size());
  shuffle_bytes(chunk, element_size, std::span(shuffled_).first(chunk.size()));
  const std::size_t bound = libdeflate_zlib_compress_bound(compressor_->c, chunk.size());
  if (compressed_.size() < bound) compressed_.resize(bound);
  const std::size_t n =
      libdeflate_zlib_compress(compressor_->c, shuffled_.data(), chunk.size(), compressed_.data(), compressed_.size());
  if (n == 0) throw FormatError("", "deflate failed on a chunk of " + std::to_string(chunk.size()) + " bytes");
  std::vector<std::byte> out;
  out.reserve(n + 4);
  out.assign(compressed_.begin(), compressed_.begin() + std::ptrdiff_t(n));
  if (checksum_) {
    const uint32_t sum = fletcher32(out);
    for (int k = 0; k < 4; ++k) out.push_back(std::byte(sum >> (8 * k)));  // little-endian
  }
  return out;
}

} // namespace prt::formats::detail
