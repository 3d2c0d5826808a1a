// SHA-256 against the FIPS 180-2 appendix / NIST example vectors, incremental updates across
// block boundaries, and sha256_file on a temporary file.
#include <bake/core/error.h>
#include <bake/core/sha256.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace {

using prt::bake::sha256_bytes;
using prt::bake::sha256_file;

std::string hash(const std::string& s) { return sha256_bytes(std::as_bytes(std::span(s.data(), s.size()))); }

TEST(Sha256, KnownVectors) {
  EXPECT_EQ(hash(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(hash("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  // Two-block message (padding spills into a second block).
  EXPECT_EQ(hash("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(hash(std::string(1000000, 'a')), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(Sha256, IncrementalUpdatesMatchOneShot) {
  std::string msg;
  for (int i = 0; i < 1000; ++i) msg += char('a' + i % 26);
  const std::string expected = hash(msg);
  for (size_t chunk : {1u, 3u, 55u, 56u, 63u, 64u, 65u, 127u}) {
    prt::bake::Sha256 s;
    for (size_t p = 0; p < msg.size(); p += chunk)
      s.update(std::as_bytes(std::span(msg.data() + p, std::min(chunk, msg.size() - p))));
    EXPECT_EQ(s.hex_digest(), expected) << "chunk " << chunk;
  }
  // Lengths around the padding boundary (55/56/64 bytes) agree between one-shot and split.
  for (size_t n : {55u, 56u, 57u, 63u, 64u, 65u}) {
    const std::string m(n, 'x');
    prt::bake::Sha256 s;
    s.update(std::as_bytes(std::span(m.data(), n / 2)));
    s.update(std::as_bytes(std::span(m.data() + n / 2, n - n / 2)));
    EXPECT_EQ(s.hex_digest(), hash(m)) << "length " << n;
  }
}

TEST(Sha256, DigestTwiceIsAContractError) {
  prt::bake::Sha256 s;
  (void)s.hex_digest();
  EXPECT_THROW((void)s.hex_digest(), prt::bake::ContractError);
}

TEST(Sha256, File) {
  const std::filesystem::path dir = PRT_TEST_TMP;
  std::filesystem::create_directories(dir);
  const auto path = dir / "sha256_abc.txt";
  {
    std::ofstream out(path, std::ios::binary);
    out << "abc";
  }
  EXPECT_EQ(sha256_file(path), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  // A file larger than the read buffer (64 KiB).
  const std::string big(200000, 'a');
  {
    std::ofstream out(path, std::ios::binary);
    out << big;
  }
  EXPECT_EQ(sha256_file(path), hash(big));
  std::filesystem::remove(path);
}

TEST(Sha256, UnreadableFileIsAnInputErrorNamingIt) {
  const std::filesystem::path missing = std::filesystem::path(PRT_TEST_TMP) / "no_such_file.bin";
  try {
    (void)sha256_file(missing);
    FAIL() << "expected InputError";
  } catch (const prt::bake::InputError& e) {
    EXPECT_EQ(e.file(), missing.string());
    EXPECT_NE(std::string(e.what()).find(missing.string()), std::string::npos);
  }
  EXPECT_THROW((void)sha256_file(PRT_TEST_TMP), prt::bake::InputError);  // a directory
}

} // namespace
