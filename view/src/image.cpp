// image.cpp — PNG (libpng), float EXR (OpenEXR), tone map, false colour, NRMSE.
// Conventions and formulas: view/image.h.
#include <bake/core/error.h>
#include <view/image.h>

#include <IexBaseExc.h>
#include <ImfChannelList.h>
#include <ImfCompression.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <system_error>
#include <unistd.h>

namespace prt::view {

using bake::ContractError;
using bake::InputError;

namespace fs = std::filesystem;

// ---- PNG and EXR files ----------------------------------------------------------------------------

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

namespace {
// libpng's simplified API (png_image): it reports failures in image.message, no longjmp.
png_image png_header(int width, int height) {
  png_image im;
  std::memset(&im, 0, sizeof im);
  im.version = PNG_IMAGE_VERSION;
  im.width = png_uint_32(width);
  im.height = png_uint_32(height);
  im.format = PNG_FORMAT_RGB;  // 8-bit sRGB: libpng writes the sRGB chunk (perceptual intent)
  return im;
}
} // namespace

void write_png(const fs::path& path, const Image8& image) {
  PRT_CHECK(image.width > 0 && image.height > 0);
  PRT_CHECK_OP(image.rgb.size(), ==, size_t(image.width) * size_t(image.height) * 3);
  write_atomically(path, [&](const fs::path& tmp) {
    png_image im = png_header(image.width, image.height);
    if (!png_image_write_to_file(&im, tmp.c_str(), 0, image.rgb.data(), png_int_32(3 * image.width), nullptr))
      throw InputError(path.string(), std::string("cannot write PNG '") + tmp.string() + "': " + im.message);
  });
}

Image8 read_png(const fs::path& path) {
  png_image im = png_header(0, 0);
  if (!png_image_begin_read_from_file(&im, path.c_str()))
    throw InputError(path.string(), std::string("cannot read PNG: ") + im.message);
  im.format = PNG_FORMAT_RGB;
  Image8 out(int(im.width), int(im.height));
  if (!png_image_finish_read(&im, nullptr, out.rgb.data(), png_int_32(3 * im.width), nullptr)) {
    png_image_free(&im);
    throw InputError(path.string(), std::string("cannot read PNG: ") + im.message);
  }
  return out;
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
    } catch (const Iex::BaseExc& e) {
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

std::array<uint8_t, 3> error_colour(double t) {
  // Five stops (sRGB bytes), t = 0, 1/4, 1/2, 3/4, 1.
  static constexpr double kStops[5][3] = {{0, 0, 0}, {72, 16, 130}, {200, 40, 70}, {245, 140, 20}, {255, 250, 190}};
  const double s = std::clamp(std::isfinite(t) ? t : 1.0, 0.0, 1.0) * 4.0;
  const int k = std::min(3, int(s));
  const double f = s - k;
  std::array<uint8_t, 3> rgb{};
  for (size_t c = 0; c < 3; ++c) rgb[c] = uint8_t(std::lround((1 - f) * kStops[k][c] + f * kStops[k + 1][c]));
  return rgb;
}

Image8 false_colour_error(const Image& test, const Image& reference, std::span<const uint8_t> mask, double range,
                          double full_scale) {
  PRT_CHECK(test.width == reference.width && test.height == reference.height);
  PRT_CHECK(full_scale > 0);
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
    const std::array<uint8_t, 3> rgb = error_colour(std::isfinite(e) ? e / full_scale : 1.0);
    std::copy(rgb.begin(), rgb.end(), out.rgb.begin() + std::ptrdiff_t(3 * i));
  }
  return out;
}

namespace {
// Parts side by side, top-aligned, `gap` columns apart; everything not covered is `fill`.
template <class Picture, class Value>
Picture side_by_side(std::span<const Picture> parts, int gap, Value fill) {
  PRT_CHECK(!parts.empty() && gap >= 0);
  int w = 0, h = 0;
  for (const auto& p : parts) {
    w += p.width;
    h = std::max(h, p.height);
  }
  w += gap * int(parts.size() - 1);
  Picture out(w, h);
  std::fill(out.rgb.begin(), out.rgb.end(), fill);
  int x0 = 0;
  for (const auto& p : parts) {
    for (int y = 0; y < p.height; ++y)
      std::memcpy(out.rgb.data() + 3 * (size_t(y) * size_t(w) + size_t(x0)), p.rgb.data() + 3 * size_t(y) * size_t(p.width),
                  3 * size_t(p.width) * sizeof(Value));
    x0 += p.width + gap;
  }
  return out;
}
} // namespace

Image8 hstack(std::span<const Image8> parts, int gap, uint8_t gap_value) { return side_by_side(parts, gap, gap_value); }
Image hstack(std::span<const Image> parts) { return side_by_side(parts, 0, 0.0f); }

// ---- error -----------------------------------------------------------------------------------------

ImageError compare_images(const Image& test, const Image& reference, std::span<const uint8_t> mask,
                          const Image* ref_std_error) {
  PRT_CHECK(test.width == reference.width && test.height == reference.height);
  const size_t n = size_t(test.width) * size_t(test.height);
  PRT_CHECK(mask.empty() || mask.size() == n);
  PRT_CHECK(!ref_std_error || ref_std_error->rgb.size() == reference.rgb.size());
  ImageError r;
  double se2 = 0, noise2 = 0, ref2 = 0;
  r.ref_min = std::numeric_limits<double>::infinity();
  r.ref_max = -r.ref_min;
  for (size_t i = 0; i < n; ++i) {
    if (!masked(mask, i)) continue;
    ++r.pixels;
    for (size_t c = 0; c < 3; ++c) {
      const double ref = reference.rgb[3 * i + c], d = double(test.rgb[3 * i + c]) - ref;
      se2 += d * d;
      ref2 += ref * ref;
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
  if (ref2 > 0) {
    r.relative_l2 = std::sqrt(se2 / ref2);
    r.relative_l2_noise_corrected = std::sqrt(std::max(0.0, se2 - noise2) / ref2);
  }
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

} // namespace prt::view
