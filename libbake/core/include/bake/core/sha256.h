// bake/core/sha256.h — SHA-256 (FIPS 180-4) of files and byte buffers, for provenance: the baked
// file records the digest of every input (mesh, environment map) it was made from
// (docs/ARCHITECTURE.md §5). Computed by OpenSSL's libcrypto (EVP); a mesh's digest comes
// with the mesh (Mesh::source_sha256, bake/mesh/mesh.h), taken from the bytes that were parsed.
// Digests are returned as 64 lowercase hexadecimal characters.
#pragma once

#include <cstddef>
#include <filesystem>
#include <memory>
#include <span>
#include <string>

namespace prt::bake {

// Incremental hasher: update() any number of times, then hex_digest() once.
// Throws SystemError if libcrypto cannot provide SHA-256 (out of memory, a broken install).
class Sha256 {
public:
  Sha256();
  ~Sha256();
  Sha256(Sha256&&) noexcept;
  Sha256& operator=(Sha256&&) noexcept;
  void update(std::span<const std::byte> bytes);
  // Finishes the hash; the object must not be updated afterwards (PRT_CHECK).
  std::string hex_digest();

private:
  struct Context;  // libcrypto's digest context
  std::unique_ptr<Context> context_;
  bool finished_ = false;
};

std::string sha256_bytes(std::span<const std::byte> bytes);
// Streams the file; throws InputError("<path>: ...") if it cannot be opened or read.
std::string sha256_file(const std::filesystem::path& path);

} // namespace prt::bake
