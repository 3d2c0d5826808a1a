// view/image.h — images for people and for numbers: 8-bit PNG (libpng) and float OpenEXR files,
// tone mapping to 8-bit sRGB, a false-colour error map and the NRMSE figure of paper 004 §5.
// Layers: docs/ARCHITECTURE.md §2.
//
// Pixels. An Image is LINEAR float RGB, row-major, 3 floats per pixel, row 0 at the TOP of the
// picture, pixel (x, y) covering [x, x+1) × [y, y+1) with its centre at (x + ½, y + ½) (the
// convention of view/camera.h). prtview stores the outgoing radiance of a white Lambertian
// surface, L_out = E / π (albedo 1), so a constant environment of radiance L renders as L.
// An Image8 is display-ready 8-bit sRGB, same layout.
//
// Tone map (tone_map): v = exposure · x per channel, clamped to [0, 1], then the sRGB transfer
// function (IEC 61966-2-1: 12.92 v for v <= 0.0031308, else 1.055 v^(1/2.4) − 0.055), rounded
// to the nearest of 0…255. No curve beyond the clamp: what is shown is the number times the
// exposure. auto_exposure picks exposure = 1 / (99th percentile of the pixel luminance over the
// masked pixels) so the brightest 1 % clip and the rest use the whole range.
//
// Error metric (paper 004 §5 uses "the Normalized Root Mean Square Error (NRMSE)" of the shadow
// images against the brute-force reference but does not print its normalisation). We use the
// common definition, normalised by the range of the reference:
//   RMSE  = sqrt( (1 / 3M) Σ_{pixels in mask} Σ_{c ∈ RGB} (test_c − ref_c)² )   (M masked pixels)
//   NRMSE = RMSE / (max − min of ref_c over the masked pixels and the three channels).
// Both images are linear radiance (not the 8-bit picture). When the reference is itself a
// Monte Carlo estimate with per-pixel standard error σ, E[RMSE²] = RMSE_true² + mean σ², so
// compare_images also reports the reference's own noise as σ_rms / range and the noise-
// corrected NRMSE sqrt(max(0, RMSE² − σ_rms²)) / range.
//
// False colour (false_colour_error): per pixel e = sqrt((1/3) Σ_c (test_c − ref_c)²) / range,
// t = min(1, e / full_scale); colours run black (t = 0) → purple → red → orange → pale yellow
// (t = 1), linear between five stops at t = 0, ¼, ½, ¾, 1 (our own ramp, monotone in
// luminance). Pixels outside the mask are mid grey (96, 96, 96).
//
// Files. write_png / write_exr write "<path>.tmp.<pid>" in the same directory and rename it onto
// the path, so a failure never leaves a half-written file under the final name; errors throw
// bake::InputError naming the file. PNG (libpng): colour type 2 (RGB, 8 bit), an sRGB chunk
// (perceptual intent), libpng's default filtering and zlib compression. EXR (OpenEXR): channels
// R, G, B as 32-bit float, ZIP compression, increasing-Y line order.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <vector>

namespace prt::view {

struct Image {
  int width = 0, height = 0;
  std::vector<float> rgb;  // [height][width][3], linear
  Image() = default;
  Image(int w, int h) : width(w), height(h), rgb(size_t(w) * size_t(h) * 3, 0.0f) {}
  float* at(int x, int y) { return rgb.data() + 3 * (size_t(y) * size_t(width) + size_t(x)); }
  const float* at(int x, int y) const { return rgb.data() + 3 * (size_t(y) * size_t(width) + size_t(x)); }
};

struct Image8 {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;  // [height][width][3], sRGB-encoded
  Image8() = default;
  Image8(int w, int h, uint8_t fill = 0) : width(w), height(h), rgb(size_t(w) * size_t(h) * 3, fill) {}
};

// Calls write_to(tmp) with tmp = "<path>.tmp.<pid>" in the same directory, then renames tmp onto
// path; on any exception tmp is removed and the exception propagates. Checks the directory first.
void write_atomically(const std::filesystem::path& path, const std::function<void(const std::filesystem::path&)>& write_to);

// ---- PNG and EXR -------------------------------------------------------------------------------
void write_png(const std::filesystem::path& path, const Image8& image);
void write_exr(const std::filesystem::path& path, const Image& image);
// Reads an 8-bit RGB PNG written by write_png (other PNGs are converted to 8-bit RGB by libpng).
// Throws bake::InputError naming the file when it cannot be read.
Image8 read_png(const std::filesystem::path& path);

// ---- display ------------------------------------------------------------------------------------
// mask: empty (every pixel) or one byte per pixel, non-zero = use the pixel.
double auto_exposure(const Image& image, std::span<const uint8_t> mask = {});
Image8 tone_map(const Image& image, double exposure);
Image8 false_colour_error(const Image& test, const Image& reference, std::span<const uint8_t> mask, double range,
                          double full_scale);
// The false-colour ramp at t (clamped to [0, 1]): the colour false_colour_error gives an error of
// t · full_scale (view/text.h draws it as the error panel's scale).
std::array<uint8_t, 3> error_colour(double t);
// Pictures side by side, top-aligned, separated by `gap` columns of `gap_value` (grey).
Image8 hstack(std::span<const Image8> parts, int gap = 4, uint8_t gap_value = 255);
// Linear pictures side by side, top-aligned, no gap (rows below a shorter part are 0).
Image hstack(std::span<const Image> parts);

// ---- error ----------------------------------------------------------------------------------------
struct ImageError {
  size_t pixels = 0;                 // masked pixels compared
  double rmse = 0;                   // over masked pixels and RGB
  double ref_min = 0, ref_max = 0;   // of the reference over masked pixels and RGB
  double nrmse = 0;                  // rmse / (ref_max − ref_min); a constant reference (range 0) is
                                     // normalised by |ref_max| (or 1 if that is 0 too) instead
  double max_abs = 0;                // largest |test − ref| of any channel
  double ref_noise = 0;              // RMS of the reference's standard error / range (0 without it)
  double nrmse_noise_corrected = 0;  // sqrt(max(0, rmse² − σ_rms²)) / range
  // The relative L2 error ‖test − ref‖ / ‖ref‖ over masked pixels and RGB (0 when ‖ref‖ = 0) and
  // the same with the reference's noise taken out, sqrt(max(0, ‖test − ref‖² − Σ σ²)) / ‖ref‖.
  double relative_l2 = 0, relative_l2_noise_corrected = 0;
};
// ref_std_error: empty or an image of per-channel standard errors of `reference`.
// Throws bake::ContractError when the sizes differ or no pixel is masked.
ImageError compare_images(const Image& test, const Image& reference, std::span<const uint8_t> mask = {},
                          const Image* ref_std_error = nullptr);

} // namespace prt::view
