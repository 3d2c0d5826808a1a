// sha256.cpp — SHA-256 through OpenSSL's EVP digest interface (contract in bake/core/sha256.h).
#include <bake/core/error.h>
#include <bake/core/sha256.h>

#include <openssl/evp.h>

#include <fstream>
#include <vector>

namespace prt::bake {

struct Sha256::Context {
  EVP_MD_CTX* ctx = EVP_MD_CTX_new();
  ~Context() { EVP_MD_CTX_free(ctx); }
};

namespace {
void require(int ok, const char* what) {
  if (ok != 1) throw SystemError(std::string("libcrypto: ") + what + " failed for SHA-256");
}
} // namespace

Sha256::Sha256() : context_(std::make_unique<Context>()) {
  if (!context_->ctx) throw SystemError("libcrypto: cannot allocate a digest context");
  require(EVP_DigestInit_ex(context_->ctx, EVP_sha256(), nullptr), "EVP_DigestInit_ex");
}
Sha256::~Sha256() = default;
Sha256::Sha256(Sha256&&) noexcept = default;
Sha256& Sha256::operator=(Sha256&&) noexcept = default;

void Sha256::update(std::span<const std::byte> bytes) {
  PRT_CHECK(context_ && !finished_);
  require(EVP_DigestUpdate(context_->ctx, bytes.data(), bytes.size()), "EVP_DigestUpdate");
}

std::string Sha256::hex_digest() {
  PRT_CHECK(context_ && !finished_);
  finished_ = true;
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  require(EVP_DigestFinal_ex(context_->ctx, digest, &length), "EVP_DigestFinal_ex");
  PRT_CHECK_OP(length, ==, 32u);
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out(2 * length, '0');
  for (unsigned int i = 0; i < length; ++i) {
    out[2 * i] = kHex[digest[i] >> 4];
    out[2 * i + 1] = kHex[digest[i] & 0xf];
  }
  return out;
}

std::string sha256_bytes(std::span<const std::byte> bytes) {
  Sha256 s;
  s.update(bytes);
  return s.hex_digest();
}

std::string sha256_file(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InputError(path.string(), "is a directory, not a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string(), "cannot open file for reading");
  Sha256 s;
  std::vector<char> buf(1 << 16);
  while (in) {
    in.read(buf.data(), std::streamsize(buf.size()));
    const std::streamsize got = in.gcount();
    if (got > 0) s.update(std::as_bytes(std::span(buf.data(), size_t(got))));
  }
  if (in.bad()) throw InputError(path.string(), "read error");
  return s.hex_digest();
}

} // namespace prt::bake
