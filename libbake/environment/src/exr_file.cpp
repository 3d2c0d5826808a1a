// exr_file.cpp — environment maps from OpenEXR files (bake/environment/envmap.h: load, identify):
// the header walked and checked by our own code before OpenEXR sizes a buffer (hostile files:
// docs/RELIABILITY.md), then the pixels read through OpenEXR.
#include <bake/core/error.h>
#include <bake/core/sha256.h>
#include <bake/environment/envmap.h>

#include "exr_limits.h"

#include <IexBaseExc.h>
#include <ImfChannelList.h>
#include <ImfEnvmap.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfRgbaFile.h>
#include <ImfStandardAttributes.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <limits>
#include <new>
#include <sstream>
#include <string>
#include <vector>

namespace prt::bake {
namespace {


// The largest ratio of raw channel bytes to file bytes each OpenEXR compression can reach, so a
// header whose pixels could not fit in its file is refused before a pixel buffer is allocated:
//   NONE 1; RLE 64 (a run of at most 128 bytes takes 2); B44/B44A 11 (a 4×4 block of halves,
//   32 bytes, takes at least 3; other types are stored raw); ZIPS/ZIP 1032 and PXR24
//   1032 × 4/3 (deflate's limit, zlib's "technical details"; PXR24 first packs floats into 24
//   bits); PIZ 1032 (its Huffman coder spends at least 10 bits on a run of at most 256 16-bit
//   values: ≤ 410, rounded up to deflate's); DWAA/DWAB: no bound (lossy DCT whose zero runs are
//   run-length coded and then deflated), only kMaxPixels.
double max_compression_ratio(Imf::Compression c) {
  switch (c) {
    case Imf::NO_COMPRESSION: return 1;
    case Imf::RLE_COMPRESSION: return 64;
    case Imf::B44_COMPRESSION: case Imf::B44A_COMPRESSION: return 11;
    case Imf::ZIPS_COMPRESSION: case Imf::ZIP_COMPRESSION: case Imf::PIZ_COMPRESSION: return 1032;
    case Imf::PXR24_COMPRESSION: return 1032.0 * 4 / 3;
    default: return std::numeric_limits<double>::infinity();
  }
}

// w × h pixels within [1, kMaxPixels].
void check_image_size(int64_t w, int64_t h, const std::string& file) {
  if (w < 1 || h < 1 || w * h > kMaxPixels) {
    std::ostringstream os;
    os << "unsupported image size " << w << "x" << h << " (at most " << kMaxPixels << " pixels)";
    throw InputError(file, os.str());
  }
}

// The byte size of OpenEXR's fixed-size attribute types (its standard attribute types), -1 for
// the others (string, chlist, preview, stringvector and unknown types).
int fixed_size_of(const std::string& type) {
  static const std::pair<const char*, int> kSizes[] = {
      {"box2i", 16},       {"box2f", 16},    {"v2i", 8},      {"v2f", 8},       {"v2d", 16},       {"v3i", 12},
      {"v3f", 12},         {"v3d", 24},      {"int", 4},      {"float", 4},     {"double", 8},     {"compression", 1},
      {"lineOrder", 1},    {"envmap", 1},    {"tiledesc", 9}, {"m33f", 36},     {"m44f", 64},      {"m33d", 72},
      {"m44d", 128},       {"rational", 8},  {"timecode", 8}, {"keycode", 28},  {"chromaticities", 32},
      {"deepImageState", 1}};
  for (const auto& [name, bytes] : kSizes)
    if (type == name) return bytes;
  return -1;
}

// Whether a chlist, preview or stringvector value parses to exactly its n bytes (b[n] is a 0
// sentinel). chlist: entries name\0 (1 to max_name bytes) + 16 bytes (pixel type, pLinear,
// reserved, x/y sampling), ended by an empty name; preview: uint32 width, height, then
// width × height RGBA bytes; stringvector: int32 length + bytes, repeated.
bool typed_value_fits(const std::string& type, const unsigned char* b, size_t n, size_t max_name) {
  auto u32 = [&](size_t i) { return uint64_t(b[i]) | uint64_t(b[i + 1]) << 8 | uint64_t(b[i + 2]) << 16 | uint64_t(b[i + 3]) << 24; };
  if (type == "preview") return n >= 8 && u32(0) * u32(4) * 4 == n - 8;
  size_t i = 0;
  if (type == "stringvector") {
    while (i < n) {
      if (n - i < 4) return false;
      const uint64_t len = u32(i);
      i += 4;
      if (len > n - i) return false;
      i += size_t(len);
    }
    return true;
  }
  for (;;) {  // chlist
    size_t len = 0;
    while (i + len < n && b[i + len] != 0) ++len;
    if (i + len >= n) return false;  // no terminating NUL inside the value
    if (len == 0) return i + 1 == n;
    if (len > max_name || n - (i + len + 1) < 16) return false;
    i += len + 1 + 16;
  }
}

// The header's attribute list, walked before OpenEXR sees the file (OpenEXR file layout: magic
// 20000630, a version word whose bit 0x400 allows names of 255 bytes instead of 31 and whose bit
// 0x1000 makes the file multi-part, then per header attributes "name\0type\0" + int32 size +
// value, ended by an empty name; a multi-part file's header list ends with an empty header).
// OpenEXR allocates an attribute's claimed size before it reads it, so a 1 KB file claiming a
// 1.7 GB attribute cost 1.7 GB and seconds; here every size must fit in the bytes that follow.
// Then the image's size and (single-part scanline images) its chunk table, below.
void check_exr_header(const std::filesystem::path& path, const std::string& file) {
  std::ifstream in(path, std::ios::binary);
  std::error_code ec;
  const uint64_t size = std::filesystem::file_size(path, ec);
  if (!in || ec) throw InputError(file, "cannot read the file");
  uint64_t at = 0;
  auto bytes = [&](void* out, std::size_t n) {
    in.read(static_cast<char*>(out), static_cast<std::streamsize>(n));
    if (static_cast<std::size_t>(in.gcount()) != n) throw InputError(file, "truncated OpenEXR header");
    at += n;
  };
  unsigned char head[8];
  bytes(head, 8);
  if (!(head[0] == 0x76 && head[1] == 0x2f && head[2] == 0x31 && head[3] == 0x01))
    throw InputError(file, "not an OpenEXR image (wrong magic number)");
  const uint32_t flags = uint32_t(head[5]) << 8 | uint32_t(head[6]) << 16 | uint32_t(head[7]) << 24;
  const std::size_t max_name = (flags & 0x400u) != 0 ? 255 : 31;
  const bool multipart = (flags & 0x1000u) != 0;
  // A name or type: at most max_name bytes, then NUL; "" ends a list.
  auto word = [&](const char* what) {
    std::string w;
    for (char c = 0;;) {
      bytes(&c, 1);
      if (c == '\0') return w;
      if (w.size() == max_name)
        throw InputError(file, std::string("damaged OpenEXR header: an attribute ") + what + " longer than " +
                                   std::to_string(max_name) + " bytes");
      w.push_back(c);
    }
  };
  auto int32_at = [](const unsigned char* b) {
    return static_cast<int32_t>(uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24);
  };
  // What the first header says about the pixels' layout (the chunk check below).
  // OpenEXR's defaults for what a header leaves out: a 64 × 64 window, ZIP compression.
  bool tiled = false;
  int compression = Imf::ZIP_COMPRESSION;
  int32_t window[4] = {0, 0, 63, 63};  // xMin, yMin, xMax, yMax
  std::vector<unsigned char> channel_list;  // the first header's chlist value (checked, NUL-ended)
  for (int header = 0;; ++header) {
    int attributes = 0;
    for (std::string name = word("name"); !name.empty(); name = word("name"), ++attributes) {
      const std::string type = word("type");
      unsigned char n[4];
      bytes(n, 4);
      const int32_t value_size = int32_at(n);
      if (value_size < 0 || uint64_t(value_size) > size - at)
        throw InputError(file, "damaged OpenEXR header: attribute '" + name + "' claims " + std::to_string(value_size) +
                                   " bytes, the file has " + std::to_string(size - at) + " left");
      // OpenEXR reads a known fixed-size type's own size whatever the declared one says; a
      // mismatch would put its reading out of step with ours (as for the parsed types below).
      const int fixed = fixed_size_of(type);
      if (fixed >= 0 && value_size != fixed)
        throw InputError(file, "damaged OpenEXR header: attribute '" + name + "' of type " + type + " claims " +
                                   std::to_string(value_size) + " bytes, not " + std::to_string(fixed));
      if (header == 0 && name == "dataWindow" && type == "box2i") {
        unsigned char v[16];
        bytes(v, 16);
        for (int k = 0; k < 4; ++k) window[k] = int32_at(v + 4 * k);
      } else if (header == 0 && name == "compression" && type == "compression") {
        unsigned char c = 0;
        bytes(&c, 1);
        compression = c;
      } else if (type == "chlist" || type == "preview" || type == "stringvector") {
        // Values OpenEXR parses by their own contents, not by the declared size: a channel list
        // until an empty name, a preview's width × height × 4 bytes, a string vector's lengths.
        // Unless they fill the declared size exactly, OpenEXR's reading leaves ours and takes a
        // later garbage word for an attribute size (a 168-byte file claimed 1.7 GB that way).
        std::vector<unsigned char> v(size_t(value_size) + 1, 0);
        bytes(v.data(), size_t(value_size));
        if (!typed_value_fits(type, v.data(), size_t(value_size), max_name))
          throw InputError(file, "damaged OpenEXR header: attribute '" + name + "' (" + type + ") does not fill its " +
                                     std::to_string(value_size) + " bytes");
        if (header == 0 && name == "channels" && type == "chlist") channel_list = std::move(v);
      } else {
        tiled |= header == 0 && name == "tiles";
        at += uint64_t(value_size);
        in.seekg(static_cast<std::streamoff>(at));
      }
    }
    if (!multipart || attributes == 0) break;
  }
  // The image's size, and its channels' bytes against what the file can hold at the
  // compression's largest ratio, before OpenEXR sizes its line buffers by them (a 206-byte header
  // of 8.3M × 8 pixels made it allocate and clear 2 GB).
  const int64_t w = int64_t(window[2]) - window[0] + 1, h = int64_t(window[3]) - window[1] + 1;
  check_image_size(w, h, file);
  double raw_bytes = 0;  // of every channel, whose compressed data the file must hold
  for (size_t i = 0; i < channel_list.size() && channel_list[i] != 0;) {  // entries as typed_value_fits checked them
    while (channel_list[i] != 0) ++i;
    const unsigned char* e = channel_list.data() + i + 1;
    const int32_t type = int32_at(e), xs = std::max(1, int32_at(e + 8)), ys = std::max(1, int32_at(e + 12));
    raw_bytes += std::ceil(double(w) / xs) * std::ceil(double(h) / ys) * (type == Imf::HALF ? 2 : 4);
    i += 1 + 16;
  }
  const double ratio = compression >= 0 && compression < Imf::NUM_COMPRESSION_METHODS
                           ? max_compression_ratio(Imf::Compression(compression))
                           : std::numeric_limits<double>::infinity();
  if (raw_bytes > ratio * double(size)) {
    std::ostringstream os;
    os << "the header's " << w << "x" << h << " pixels (" << uint64_t(raw_bytes) << " bytes of channel data) cannot fit in "
       << size << " bytes at the compression's largest ratio (" << ratio << ":1): a damaged or forged header";
    throw InputError(file, os.str());
  }
  // A single-part scanline image: its chunk offset table follows the header, one offset per
  // chunk of `lines` scanlines (by compression: NONE, RLE, ZIPS 1; ZIP, PXR24 16; PIZ, B44,
  // B44A, DWAA 32; DWAB 256), and each chunk is int32 y, int32 data size, data. OpenEXR allocates
  // a chunk's claimed size before reading it, so a 168-byte file claiming a 1.7 GB chunk cost
  // 1.7 GB of address space (and read as "out of memory" under a memory limit): every offset
  // and size must fit in the file. (Tiled and multi-part files are left to OpenEXR.)
  static constexpr int kLinesPerChunk[] = {1, 1, 1, 16, 32, 16, 32, 32, 32, 256};
  if (multipart || tiled || compression < 0 || compression >= int(std::size(kLinesPerChunk))) return;
  const uint64_t chunks = uint64_t((h + kLinesPerChunk[compression] - 1) / kLinesPerChunk[compression]);
  if (chunks > (size - at) / 8)
    throw InputError(file, "truncated OpenEXR file: its " + std::to_string(chunks) + " chunk offsets do not fit in it");
  std::vector<unsigned char> table(size_t(chunks) * 8);
  bytes(table.data(), table.size());
  const uint64_t pixels_start = at;
  for (uint64_t k = 0; k < chunks; ++k) {
    uint64_t offset = 0;
    for (int b = 7; b >= 0; --b) offset = offset << 8 | table[size_t(k) * 8 + size_t(b)];
    unsigned char chunk[8];
    if (offset < pixels_start || offset > size - 8) {
      throw InputError(file, "damaged OpenEXR file: chunk " + std::to_string(k) + " at offset " + std::to_string(offset) +
                                 " lies outside the file's " + std::to_string(size) + " bytes");
    }
    in.seekg(static_cast<std::streamoff>(offset));
    in.read(reinterpret_cast<char*>(chunk), 8);
    if (in.gcount() != 8) throw InputError(file, "cannot read the file");
    const int32_t data_size = int32_at(chunk + 4);
    if (data_size < 0 || uint64_t(data_size) > size - offset - 8)
      throw InputError(file, "damaged OpenEXR file: chunk " + std::to_string(k) + " claims " + std::to_string(data_size) +
                                 " bytes, the file has " + std::to_string(size - offset - 8) + " after it");
  }
}

std::string one_line(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  return s;
}

} // namespace

EnvMap EnvMap::load(const std::filesystem::path& exr, UpAxis up) {
  const std::string file = exr.string();
  return reading_file(file, [&] { return read(exr, file, up); });
}

namespace {
// What load() and identify() know of the file before its pixels: it exists, its SHA-256, and
// check_exr_header's checks.
EnvMapInfo file_identity(const std::filesystem::path& exr, const std::string& file) {
  std::error_code ec;
  if (!std::filesystem::exists(exr, ec)) throw InputError(file, "no such file");
  EnvMapInfo info;
  info.source = file;
  info.sha256 = sha256_file(exr);  // InputError if unreadable or a directory
  check_exr_header(exr, file);
  return info;
}

// The image's layout and size from its OpenEXR header (the envmap attribute, else its shape).
struct ExrShape {
  bool cube = false;
  int width = 0, height = 0;
};
ExrShape exr_shape(const Imf::Header& hdr, const std::string& file) {
  const Imath::Box2i dw = hdr.dataWindow();
  const int64_t w64 = int64_t(dw.max.x) - dw.min.x + 1, h64 = int64_t(dw.max.y) - dw.min.y + 1;
  check_image_size(w64, h64, file);  // again: OpenEXR's window is the one read from here on
  const int W = int(w64), H = int(h64);
  std::ostringstream shape;
  shape << W << "x" << H;
  if (Imf::hasEnvmap(hdr)) {
    const Imf::Envmap e = Imf::envmap(hdr);
    if (e == Imf::ENVMAP_LATLONG) {
      if (W < 2 || H < 2) throw InputError(file, "lat-long environment map of " + shape.str() + " pixels: need at least 2x2");
      return {false, W, H};
    }
    if (e == Imf::ENVMAP_CUBE) {
      if (int64_t(H) != 6 * int64_t(W) || W < 2)
        throw InputError(file, "cube environment map of " + shape.str() +
                                   " pixels: expected width S >= 2 and height 6*S (faces stacked vertically)");
      return {true, W, H};
    }
    throw InputError(file, "unknown 'envmap' attribute value " + std::to_string(int(e)));
  }
  if (int64_t(W) == 2 * int64_t(H) && H >= 2) return {false, W, H};
  if (int64_t(H) == 6 * int64_t(W) && W >= 2) return {true, W, H};
  throw InputError(file, "image is " + shape.str() +
                             " and has no 'envmap' attribute: expected a lat-long map (width == 2*height) "
                             "or a cube map (height == 6*width)");
}

// OpenEXR's own errors: the file is damaged, truncated or not an image OpenEXR can read. Our
// InputErrors pass through as they are; std::bad_alloc (the machine) and logic errors (a bug)
// are not the file's fault and pass through too (docs/ARCHITECTURE.md §6). OpenEXR 3.1 turns a
// std::bad_alloc for its scanline buffers into an Iex exception with this message: that is the
// machine too.
[[noreturn]] void openexr_failure(const Iex::BaseExc& e, const std::string& file) {
  if (std::string_view(e.what()).find("Failed to allocate memory") != std::string_view::npos) throw std::bad_alloc();
  throw InputError(file, "cannot read OpenEXR image: " + one_line(e.what()));
}
} // namespace

EnvMapInfo EnvMap::identify(const std::filesystem::path& exr) {
  const std::string file = exr.string();
  return reading_file(file, [&] {
    EnvMapInfo info = file_identity(exr, file);
    try {
      const Imf::InputFile in(file.c_str());
      const ExrShape shape = exr_shape(in.header(), file);
      info.layout = shape.cube ? "cube" : "latlong";
      info.width = shape.width;
      info.height = shape.height;
    } catch (const Iex::BaseExc& e) {
      openexr_failure(e, file);
    }
    return info;
  });
}

EnvMap EnvMap::read(const std::filesystem::path& exr, const std::string& file, UpAxis up) {
  EnvMapInfo info = file_identity(exr, file);
  Layout layout = Layout::LatLong;
  int W = 0, H = 0;
  std::vector<float> rgb;
  try {
    Imf::InputFile in(file.c_str());
    const Imf::Header& hdr = in.header();
    const Imath::Box2i dw = hdr.dataWindow();
    const ExrShape shape = exr_shape(hdr, file);
    layout = shape.cube ? Layout::ExrCube : Layout::LatLong;
    W = shape.width, H = shape.height;

    const Imf::ChannelList& channels = hdr.channels();
    auto has = [&](const char* n) { return channels.findChannel(n) != nullptr; };
    std::string present;
    for (auto it = channels.begin(); it != channels.end(); ++it) {
      present += present.empty() ? "" : ", ";
      present += it.name();
    }
    for (const char* n : {"R", "G", "B"})
      if (const Imf::Channel* c = channels.findChannel(n); c && (c->xSampling != 1 || c->ySampling != 1))
        throw InputError(file, std::string("channel ") + n + " is subsampled; only full-resolution channels are supported");

    if (!in.isComplete()) throw InputError(file, "file is incomplete (truncated?): some pixel data is missing");
    // (The pixels' bound by the file's size and compression was checked by check_exr_header.)

    const size_t npix = size_t(W) * size_t(H);
    rgb.assign(3 * npix, 0.0f);
    const bool anyRgb = has("R") || has("G") || has("B");
    std::string grey_channel;
    if (anyRgb) {
      for (const char* n : {"R", "G", "B"})
        if (!has(n))
          throw InputError(file, std::string("missing channel ") + n + " (the image has " + present + ")");
      Imf::FrameBuffer fb;
      const char* names[3] = {"R", "G", "B"};
      for (int c = 0; c < 3; ++c)
        fb.insert(names[c], Imf::Slice::Make(Imf::FLOAT, rgb.data() + c, dw, 3 * sizeof(float), 3 * sizeof(float) * size_t(W)));
      in.setFrameBuffer(fb);
      in.readPixels(dw.min.y, dw.max.y);
    } else if (has("Y") && (has("RY") || has("BY"))) {
      // Luminance/chroma image: let OpenEXR convert to RGB (these are half-float images).
      Imf::RgbaInputFile rin(file.c_str());
      std::vector<Imf::Rgba> px(npix);
      rin.setFrameBuffer(px.data() - int64_t(dw.min.x) - int64_t(dw.min.y) * W, 1, size_t(W));
      rin.readPixels(dw.min.y, dw.max.y);
      for (size_t k = 0; k < npix; ++k) {
        rgb[3 * k] = float(px[k].r);
        rgb[3 * k + 1] = float(px[k].g);
        rgb[3 * k + 2] = float(px[k].b);
      }
    } else if (has("Y")) {
      std::vector<float> y(npix);
      Imf::FrameBuffer fb;
      fb.insert("Y", Imf::Slice::Make(Imf::FLOAT, y.data(), dw, sizeof(float), sizeof(float) * size_t(W)));
      in.setFrameBuffer(fb);
      in.readPixels(dw.min.y, dw.max.y);
      for (size_t k = 0; k < npix; ++k) rgb[3 * k] = rgb[3 * k + 1] = rgb[3 * k + 2] = y[k];
      grey_channel = "Y";
    } else {
      throw InputError(file, "no R, G, B or Y channel (the image has " + (present.empty() ? std::string("no channels") : present) + ")");
    }

    for (size_t k = 0; k < rgb.size(); ++k)
      if (!std::isfinite(rgb[k])) {
        std::ostringstream os;
        os << "non-finite pixel value " << rgb[k] << " at (x " << dw.min.x + int64_t((k / 3) % size_t(W)) << ", y "
           << dw.min.y + int64_t((k / 3) / size_t(W)) << ") channel "
           << (grey_channel.empty() ? std::string(1, "RGB"[k % 3]) : grey_channel);
        throw InputError(file, os.str());
      }
  } catch (const Iex::BaseExc& e) {
    openexr_failure(e, file);
  }
  return build(layout, W, H, std::move(rgb), up, std::move(info));
}

} // namespace prt::bake
