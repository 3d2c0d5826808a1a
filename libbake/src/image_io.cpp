// image_io.cpp — PNG (our own zlib/deflate), float EXR, tone map, false colour, NRMSE.
// Conventions and formulas: bake/image_io.h.
#include <bake/error.h>
#include <bake/image_io.h>

#include <ImfChannelList.h>
#include <ImfCompression.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <functional>
#include <limits>
#include <string>
#include <system_error>
#include <unistd.h>

namespace prt::bake {

namespace fs = std::filesystem;

// ---- checksums -----------------------------------------------------------------------------------

namespace {
std::array<uint32_t, 256> make_crc_table() {
  std::array<uint32_t, 256> t{};
  for (uint32_t n = 0; n < 256; ++n) {
    uint32_t c = n;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;  // reflected 0x04C11DB7
    t[n] = c;
  }
  return t;
}
} // namespace

uint32_t crc32(std::span<const uint8_t> bytes, uint32_t crc) {
  static const std::array<uint32_t, 256> table = make_crc_table();
  uint32_t c = crc ^ 0xFFFFFFFFu;
  for (uint8_t b : bytes) c = table[(c ^ b) & 0xFFu] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

uint32_t adler32(std::span<const uint8_t> bytes) {
  constexpr uint32_t kMod = 65521;  // largest prime below 2^16 (RFC 1950 §8)
  uint32_t a = 1, b = 0;
  size_t i = 0;
  while (i < bytes.size()) {
    // 5552 is the largest n with 255 n (n + 1) / 2 + (n + 1)(kMod − 1) < 2^32: no overflow in a run.
    const size_t end = std::min(bytes.size(), i + 5552);
    for (; i < end; ++i) {
      a += bytes[i];
      b += a;
    }
    a %= kMod;
    b %= kMod;
  }
  return (b << 16) | a;
}

// ---- deflate: greedy LZ77 + one block of fixed Huffman codes (RFC 1951) ---------------------------

namespace {

class BitWriter {
public:
  explicit BitWriter(std::vector<uint8_t>& out) : out_(out) {}
  void bits(uint32_t value, int n) {  // LSB first, as deflate packs data elements
    acc_ |= uint64_t(value) << fill_;
    fill_ += n;
    while (fill_ >= 8) {
      out_.push_back(uint8_t(acc_ & 0xFFu));
      acc_ >>= 8;
      fill_ -= 8;
    }
  }
  void huffman(uint32_t code, int n) {  // Huffman codes go most significant bit first
    uint32_t r = 0;
    for (int i = 0; i < n; ++i) r |= ((code >> i) & 1u) << (n - 1 - i);
    bits(r, n);
  }
  void flush() {
    if (fill_ > 0) out_.push_back(uint8_t(acc_ & 0xFFu));
    acc_ = 0;
    fill_ = 0;
  }

private:
  std::vector<uint8_t>& out_;
  uint64_t acc_ = 0;
  int fill_ = 0;
};

// Fixed literal/length code (RFC 1951 §3.2.6).
void put_litlen(BitWriter& w, int sym) {
  if (sym <= 143) w.huffman(uint32_t(0x30 + sym), 8);
  else if (sym <= 255) w.huffman(uint32_t(0x190 + sym - 144), 9);
  else if (sym <= 279) w.huffman(uint32_t(sym - 256), 7);
  else w.huffman(uint32_t(0xC0 + sym - 280), 8);
}

constexpr std::array<int, 29> kLenBase = {3,  4,  5,  6,  7,  8,  9,  10, 11,  13,  15,  17,  19,  23, 27,
                                          31, 35, 43, 51, 59, 67, 83, 99, 115, 131, 163, 195, 227, 258};
constexpr std::array<int, 29> kLenExtra = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2,
                                           2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};
constexpr std::array<int, 30> kDistBase = {1,   2,   3,   4,   5,   7,    9,    13,   17,   25,
                                           33,  49,  65,  97,  129, 193,  257,  385,  513,  769,
                                           1025, 1537, 2049, 3073, 4097, 6145, 8193, 12289, 16385, 24577};
constexpr std::array<int, 30> kDistExtra = {0, 0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5, 6,
                                            6, 7, 7, 8, 8, 9, 9, 10, 10, 11, 11, 12, 12, 13, 13};

void put_match(BitWriter& w, int length, int distance) {
  int li = 28;
  while (kLenBase[size_t(li)] > length) --li;
  put_litlen(w, 257 + li);
  w.bits(uint32_t(length - kLenBase[size_t(li)]), kLenExtra[size_t(li)]);
  int di = 29;
  while (kDistBase[size_t(di)] > distance) --di;
  w.huffman(uint32_t(di), 5);
  w.bits(uint32_t(distance - kDistBase[size_t(di)]), kDistExtra[size_t(di)]);
}

void deflate_fixed(std::span<const uint8_t> in, std::vector<uint8_t>& out) {
  constexpr int kWindow = 32768, kMinMatch = 3, kMaxMatch = 258, kMaxChain = 96;
  constexpr uint32_t kHashBits = 15, kHashSize = 1u << kHashBits;
  BitWriter w(out);
  w.bits(1, 1);  // BFINAL: the only block
  w.bits(1, 2);  // BTYPE 01: fixed Huffman codes
  const size_t n = in.size();
  std::vector<int64_t> head(kHashSize, -1), prev(kWindow, -1);
  auto hash = [&](size_t i) {
    return ((uint32_t(in[i]) << 10) ^ (uint32_t(in[i + 1]) << 5) ^ uint32_t(in[i + 2])) & (kHashSize - 1);
  };
  auto insert = [&](size_t i) {
    if (i + kMinMatch > n) return;
    const uint32_t h = hash(i);
    prev[i % kWindow] = head[h];
    head[h] = int64_t(i);
  };
  size_t i = 0;
  while (i < n) {
    int best_len = 0, best_dist = 0;
    if (i + kMinMatch <= n) {
      int64_t cand = head[hash(i)];
      const size_t max_len = std::min<size_t>(kMaxMatch, n - i);
      for (int chain = 0; cand >= 0 && chain < kMaxChain; ++chain) {
        const size_t c = size_t(cand);
        if (i - c > size_t(kWindow - 1)) break;  // distances are at most 32 768 − 1 here
        size_t len = 0;
        while (len < max_len && in[c + len] == in[i + len]) ++len;
        if (int(len) > best_len) {
          best_len = int(len);
          best_dist = int(i - c);
          if (len == max_len) break;
        }
        const int64_t next = prev[c % kWindow];
        if (next >= cand) break;  // the slot was overwritten by a newer position
        cand = next;
      }
    }
    if (best_len >= kMinMatch) {
      put_match(w, best_len, best_dist);
      for (int k = 0; k < best_len; ++k) insert(i + size_t(k));
      i += size_t(best_len);
    } else {
      put_litlen(w, in[i]);
      insert(i);
      ++i;
    }
  }
  put_litlen(w, 256);  // end of block
  w.flush();
}

void put_be32(std::vector<uint8_t>& out, uint32_t v) {
  out.push_back(uint8_t(v >> 24));
  out.push_back(uint8_t(v >> 16));
  out.push_back(uint8_t(v >> 8));
  out.push_back(uint8_t(v));
}

} // namespace

std::vector<uint8_t> zlib_compress(std::span<const uint8_t> bytes) {
  std::vector<uint8_t> out;
  out.reserve(bytes.size() / 2 + 64);
  // CMF 0x78: deflate, 32 KiB window; FLG 0x01: no dictionary, check bits so 0x7801 % 31 == 0.
  out.push_back(0x78);
  out.push_back(0x01);
  deflate_fixed(bytes, out);
  put_be32(out, adler32(bytes));
  return out;
}

// ---- PNG -------------------------------------------------------------------------------------------

namespace {

void put_chunk(std::vector<uint8_t>& png, const char type[4], std::span<const uint8_t> data) {
  put_be32(png, uint32_t(data.size()));
  const size_t start = png.size();
  png.insert(png.end(), type, type + 4);
  png.insert(png.end(), data.begin(), data.end());
  put_be32(png, crc32(std::span<const uint8_t>(png.data() + start, png.size() - start)));
}

int paeth(int a, int b, int c) {  // PNG spec §9.4
  const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
  if (pa <= pb && pa <= pc) return a;
  return pb <= pc ? b : c;
}

} // namespace

std::vector<uint8_t> encode_png(const Image8& image) {
  PRT_CHECK(image.width > 0 && image.height > 0);
  PRT_CHECK_OP(image.rgb.size(), ==, size_t(image.width) * size_t(image.height) * 3);
  const size_t stride = size_t(image.width) * 3;
  std::vector<uint8_t> raw;
  raw.reserve((stride + 1) * size_t(image.height));
  std::vector<uint8_t> zero(stride, 0), cand(stride);
  std::vector<uint8_t> best(stride);
  for (int y = 0; y < image.height; ++y) {
    const uint8_t* row = image.rgb.data() + size_t(y) * stride;
    const uint8_t* up = y > 0 ? row - stride : zero.data();
    long best_cost = -1;
    int best_type = 0;
    for (int type = 0; type <= 4; ++type) {
      long cost = 0;
      for (size_t i = 0; i < stride; ++i) {
        const int x = row[i], a = i >= 3 ? row[i - 3] : 0, b = up[i], c = i >= 3 ? up[i - 3] : 0;
        int pred = 0;
        switch (type) {
          case 1: pred = a; break;
          case 2: pred = b; break;
          case 3: pred = (a + b) / 2; break;
          case 4: pred = paeth(a, b, c); break;
          default: break;
        }
        cand[i] = uint8_t((x - pred) & 0xFF);
        cost += std::abs(int(int8_t(cand[i])));
      }
      if (best_cost < 0 || cost < best_cost) {
        best_cost = cost;
        best_type = type;
        best.swap(cand);
      }
    }
    raw.push_back(uint8_t(best_type));
    raw.insert(raw.end(), best.begin(), best.end());
  }
  std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  std::vector<uint8_t> ihdr;
  put_be32(ihdr, uint32_t(image.width));
  put_be32(ihdr, uint32_t(image.height));
  ihdr.insert(ihdr.end(), {8, 2, 0, 0, 0});  // 8 bit, RGB, deflate, adaptive filtering, no interlace
  put_chunk(png, "IHDR", ihdr);
  const uint8_t srgb[1] = {0};  // perceptual rendering intent
  put_chunk(png, "sRGB", srgb);
  put_chunk(png, "IDAT", zlib_compress(raw));
  put_chunk(png, "IEND", {});
  return png;
}

void write_atomically(const fs::path& path, const std::function<void(const fs::path&)>& write_to) {
  const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw InputError(path.string(), "cannot write: directory '" + dir.string() + "' does not exist");
  if (fs::is_directory(path, ec)) throw InputError(path.string(), "cannot write: it is a directory");
  const fs::path tmp = dir / (path.filename().string() + ".tmp." + std::to_string(::getpid()));
  try {
    write_to(tmp);
    fs::rename(tmp, path, ec);
    if (ec) throw InputError(path.string(), "cannot rename '" + tmp.string() + "' onto it: " + ec.message());
  } catch (...) {
    fs::remove(tmp, ec);
    throw;
  }
}

void write_png(const fs::path& path, const Image8& image) {
  const std::vector<uint8_t> bytes = encode_png(image);
  write_atomically(path, [&](const fs::path& tmp) {
    FILE* f = std::fopen(tmp.c_str(), "wb");
    if (!f) throw InputError(path.string(), std::string("cannot create '") + tmp.string() + "': " + std::strerror(errno));
    const size_t n = std::fwrite(bytes.data(), 1, bytes.size(), f);
    const bool ok = n == bytes.size() && std::fflush(f) == 0;
    const int err = errno;
    if (std::fclose(f) != 0 || !ok)
      throw InputError(path.string(), std::string("cannot write '") + tmp.string() + "': " + std::strerror(err));
  });
}

void write_exr(const fs::path& path, const Image& image) {
  PRT_CHECK(image.width > 0 && image.height > 0);
  PRT_CHECK_OP(image.rgb.size(), ==, size_t(image.width) * size_t(image.height) * 3);
  for (float v : image.rgb)
    if (!std::isfinite(v)) throw ContractError("write_exr: non-finite pixel value for " + path.string());
  write_atomically(path, [&](const fs::path& tmp) {
    try {
      Imf::Header header(image.width, image.height);
      header.compression() = Imf::ZIP_COMPRESSION;
      const char* names[3] = {"R", "G", "B"};
      Imf::FrameBuffer fb;
      auto* base = const_cast<char*>(reinterpret_cast<const char*>(image.rgb.data()));
      for (int c = 0; c < 3; ++c) {
        header.channels().insert(names[c], Imf::Channel(Imf::FLOAT));
        fb.insert(names[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), 3 * sizeof(float),
                                       3 * sizeof(float) * size_t(image.width)));
      }
      Imf::OutputFile out(tmp.c_str(), header, 1);
      out.setFrameBuffer(fb);
      out.writePixels(image.height);
    } catch (const InputError&) {
      throw;
    } catch (const std::exception& e) {  // Iex::BaseExc
      throw InputError(path.string(), std::string("cannot write EXR: ") + e.what());
    }
  });
}

// ---- display -------------------------------------------------------------------------------------

namespace {
double luminance_of(const float* p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }
bool masked(std::span<const uint8_t> mask, size_t i) { return mask.empty() || mask[i] != 0; }
uint8_t srgb_byte(double v) {
  v = std::clamp(v, 0.0, 1.0);  // callers pass finite values
  const double s = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
  return uint8_t(std::lround(std::clamp(s, 0.0, 1.0) * 255.0));
}
} // namespace

double auto_exposure(const Image& image, std::span<const uint8_t> mask) {
  const size_t n = size_t(image.width) * size_t(image.height);
  PRT_CHECK(mask.empty() || mask.size() == n);
  std::vector<double> lum;
  for (size_t i = 0; i < n; ++i)
    if (masked(mask, i)) lum.push_back(luminance_of(image.rgb.data() + 3 * i));
  if (lum.empty()) return 1.0;
  const size_t k = std::min(lum.size() - 1, size_t(0.99 * double(lum.size())));
  std::nth_element(lum.begin(), lum.begin() + std::ptrdiff_t(k), lum.end());
  return lum[k] > 0 && std::isfinite(lum[k]) ? 1.0 / lum[k] : 1.0;
}

Image8 tone_map(const Image& image, double exposure) {
  PRT_CHECK(std::isfinite(exposure) && exposure >= 0);
  Image8 out(image.width, image.height);
  for (size_t i = 0; i < image.rgb.size(); ++i) {
    const double v = double(image.rgb[i]) * exposure;
    out.rgb[i] = srgb_byte(std::isfinite(v) ? v : 0.0);
  }
  return out;
}

Image8 false_colour_error(const Image& test, const Image& reference, std::span<const uint8_t> mask, double range,
                          double full_scale) {
  PRT_CHECK(test.width == reference.width && test.height == reference.height);
  PRT_CHECK(full_scale > 0);
  // Five stops (sRGB bytes), t = 0, 1/4, 1/2, 3/4, 1.
  static constexpr double kStops[5][3] = {{0, 0, 0}, {72, 16, 130}, {200, 40, 70}, {245, 140, 20}, {255, 250, 190}};
  const size_t n = size_t(test.width) * size_t(test.height);
  PRT_CHECK(mask.empty() || mask.size() == n);
  Image8 out(test.width, test.height, 96);
  for (size_t i = 0; i < n; ++i) {
    if (!masked(mask, i)) continue;
    double e2 = 0;
    for (int c = 0; c < 3; ++c) {
      const double d = double(test.rgb[3 * i + size_t(c)]) - double(reference.rgb[3 * i + size_t(c)]);
      e2 += d * d;
    }
    const double e = range > 0 ? std::sqrt(e2 / 3) / range : 0.0;
    const double t = std::clamp(std::isfinite(e) ? e / full_scale : 1.0, 0.0, 1.0) * 4.0;
    const int k = std::min(3, int(t));
    const double f = t - k;
    for (int c = 0; c < 3; ++c)
      out.rgb[3 * i + size_t(c)] = uint8_t(std::lround((1 - f) * kStops[k][c] + f * kStops[k + 1][c]));
  }
  return out;
}

Image8 hstack(std::span<const Image8> parts, int gap, uint8_t gap_value) {
  PRT_CHECK(!parts.empty() && gap >= 0);
  int w = 0, h = 0;
  for (const auto& p : parts) {
    w += p.width;
    h = std::max(h, p.height);
  }
  w += gap * int(parts.size() - 1);
  Image8 out(w, h, gap_value);
  int x0 = 0;
  for (const auto& p : parts) {
    for (int y = 0; y < p.height; ++y)
      std::memcpy(out.rgb.data() + 3 * (size_t(y) * size_t(w) + size_t(x0)), p.rgb.data() + 3 * size_t(y) * size_t(p.width),
                  3 * size_t(p.width));
    x0 += p.width + gap;
  }
  return out;
}

// ---- error -----------------------------------------------------------------------------------------

ImageError compare_images(const Image& test, const Image& reference, std::span<const uint8_t> mask,
                          const Image* ref_std_error) {
  PRT_CHECK(test.width == reference.width && test.height == reference.height);
  const size_t n = size_t(test.width) * size_t(test.height);
  PRT_CHECK(mask.empty() || mask.size() == n);
  PRT_CHECK(!ref_std_error || ref_std_error->rgb.size() == reference.rgb.size());
  ImageError r;
  double se2 = 0, noise2 = 0;
  r.ref_min = std::numeric_limits<double>::infinity();
  r.ref_max = -r.ref_min;
  for (size_t i = 0; i < n; ++i) {
    if (!masked(mask, i)) continue;
    ++r.pixels;
    for (size_t c = 0; c < 3; ++c) {
      const double ref = reference.rgb[3 * i + c], d = double(test.rgb[3 * i + c]) - ref;
      se2 += d * d;
      r.max_abs = std::max(r.max_abs, std::abs(d));
      r.ref_min = std::min(r.ref_min, ref);
      r.ref_max = std::max(r.ref_max, ref);
      if (ref_std_error) noise2 += double(ref_std_error->rgb[3 * i + c]) * double(ref_std_error->rgb[3 * i + c]);
    }
  }
  PRT_CHECK_OP(r.pixels, >, size_t(0));
  const double m = 3.0 * double(r.pixels);
  r.rmse = std::sqrt(se2 / m);
  const double range = r.ref_max - r.ref_min;
  const double sigma = std::sqrt(noise2 / m);
  if (range > 0) {
    r.nrmse = r.rmse / range;
    r.ref_noise = sigma / range;
    r.nrmse_noise_corrected = std::sqrt(std::max(0.0, se2 / m - sigma * sigma)) / range;
  } else {  // a constant reference has no range: normalise by its magnitude (or 1) instead
    const double scale = std::abs(r.ref_max) > 0 ? std::abs(r.ref_max) : 1.0;
    r.nrmse = r.rmse / scale;
    r.ref_noise = sigma / scale;
    r.nrmse_noise_corrected = std::sqrt(std::max(0.0, se2 / m - sigma * sigma)) / scale;
  }
  return r;
}

} // namespace prt::bake
