// bake/sha256.h — SHA-256 (FIPS 180-4) of files and byte buffers, for provenance: the baked
// file records the digest of every input (mesh, environment map) it was made from.
// Digests are returned as 64 lowercase hexadecimal characters.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

namespace prt::bake {

// Incremental hasher: update() any number of times, then hex_digest() once.
class Sha256 {
public:
  Sha256() noexcept;
  void update(std::span<const std::byte> bytes) noexcept;
  // Finishes the hash; the object must not be updated afterwards (PRT_CHECK).
  std::string hex_digest();

private:
  void block(const unsigned char* p) noexcept;
  std::array<uint32_t, 8> h_;
  std::array<unsigned char, 64> buf_{};
  size_t buf_len_ = 0;
  uint64_t total_bytes_ = 0;
  bool finished_ = false;
};

std::string sha256_bytes(std::span<const std::byte> bytes);
// Streams the file; throws InputError("<path>: ...") if it cannot be opened or read.
std::string sha256_file(const std::filesystem::path& path);

} // namespace prt::bake
