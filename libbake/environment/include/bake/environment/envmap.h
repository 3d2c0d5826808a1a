// bake/environment/envmap.h — environment maps: loading OpenEXR lat-long and cube maps, radiance lookup,
// luminance importance sampling and SH projection (docs/ARCHITECTURE.md §3 "Environment maps").
//
// The map is a PIECEWISE-CONSTANT function over the sphere: every texel owns a region and the
// radiance is the texel value everywhere inside it. radiance(), sample()/pdf() and project_sh()
// all use that one function, so a Monte Carlo bake against radiance() and the SH lighting from
// project_sh() describe the same environment (up to the quadrature rule of project_sh, below).
//
// Frames. "Map space" is OpenEXR's envmap frame (ImfEnvmap.h): +Y is up, longitude 0 looks
// along +Z, longitude +π/2 along +X. "Scene space" is the mesh frame the bake works in:
//   UpAxis::Y  scene == map.
//   UpAxis::Z  (Blender) scene direction (x, y, z) is looked up in the map as (x, z, −y);
//              the inverse (map (a, b, c) → scene (a, −c, b)) is what sample() returns.
// Every public direction below is a SCENE direction unless its name says map.
//
// Pixel ↔ direction follows OpenEXR's own conventions exactly (Imf::LatLongMap, Imf::CubeMap;
// EnvMap evaluates the same formulas in double, and the tests check them against the library
// through openexr_texel_direction()). Integer pixel positions are texel CENTRES:
//   lat-long (W × H): latitude(py) = π/2 − π·py/(H−1), longitude(px) = π − 2π·px/(W−1),
//     direction = (sin lon · cos lat, sin lat, cos lon · cos lat). So row 0 is centred ON the
//     north pole, row H−1 on the south pole, and columns 0 and W−1 both sit on the seam
//     (lon = ±π). Texel (px, py) owns lon/lat band between the half-pixel positions
//     px ± ½, py ± ½ clipped to [0, W−1] × [0, H−1]: the first/last rows and columns are
//     half-texels. Solid angle (exact): Δlon · (sin lat_top − sin lat_bottom).
//   cube (OpenEXR's cube, not the OpenGL one of the baked DifMap, bake/bake/fiv.h: docs/ARCHITECTURE.md
//     §3 "Two cube conventions"; S × 6S, faces stacked top to bottom +X, −X, +Y, −Y, +Z, −Z):
//     the position in a face (i, j) ∈ [0, S−1]² maps to face-plane coordinates a = 2i/(S−1) − 1, b = 2j/(S−1) − 1,
//     i.e. the centres of the border texels lie ON the cube edges (checked numerically
//     against OpenEXR 3.1: CubeMap::direction(face, dw, (0,0)) is a cube corner). Face
//     directions: +X (1, a, b), −X (−1, a, b), +Y (a, 1, b), −Y (a, −1, b), +Z (a, b, 1),
//     −Z (a, b, −1); face-position → image pixel as CubeMap::pixelPosition (e.g. +X: image
//     x = j, image y = S−1−i). Texel region: [i ± ½] × [j ± ½] clipped to the face, so
//     edge texels are half and corner texels quarter squares; a direction belongs to the face
//     of its largest |component| (ties: X before Y before Z, as CubeMap::faceAndPixelPosition).
//     Solid angle (exact): Ω = F(a1,b1) − F(a0,b1) − F(a1,b0) + F(a0,b0),
//     F(a, b) = atan(a b / sqrt(1 + a² + b²)).
//   The solid angles of all texels sum to 4π (to ~1e-13).
//
// Pixel policy (load and from_latlong):
//   * NaN or ±Inf in any channel → InputError naming the file and the first bad pixel in scan
//     order (x, y in file pixel coordinates, channel name).
//   * Negative values (ringing of lossy DWA/PIZ compression) are clamped to 0; the number of
//     pixels with at least one negative channel and the most negative value are in info().
//   * Everything else is kept as it is — HDR suns of 1e5 × the mean included. Pixels are
//     read as 32-bit float (never through half, which overflows at 65504) and every sum,
//     table and projection is accumulated in double.
//   * Luminance = 0.2126 R + 0.7152 G + 0.0722 B (linear Rec.709 primaries assumed).
//
// Importance sampling (paper 001 §5, "we compute a PDF according to the environment light"):
//   pdf(ω) = lum(texel(ω)) / Σ_t lum_t Ω_t — proportional to luminance per solid angle and
//   constant inside each texel. sample(u0, u1) inverts a 2D piecewise-constant distribution
//   built in double: u0 picks an image row from the marginal, u1 a texel within the row from
//   the conditional; the two remainders place the point UNIFORMLY IN SOLID ANGLE inside the
//   texel region (lat-long: uniform in longitude and in sin(latitude); cube: exact inversion
//   of the solid-angle CDF over the face rectangle, closed form in b and a safeguarded Newton
//   solve in a). The map (u0, u1) → ω is deterministic and monotone per coordinate, so
//   QMC/stratified points keep their structure. A map whose luminance is 0 everywhere (after
//   clamping) and constant() sample the sphere uniformly, pdf = 1/(4π).
//
// Threads: an EnvMap is immutable after construction; every const member may be called from
// any number of threads at once. Memory: ~32 bytes per texel (float RGB, Ω, sampling CDF).
//
// SH projection: L_i = Σ_t value_t · y_i(centre_t) · Ω_t with the exact texel solid angle Ω_t
// and the OpenEXR texel centre (in scene space). For the piecewise-constant map this is a
// one-point rule per texel: exact for the constant term (Σ Ω_t = 4π), error O(h²) in the texel
// size h for smooth content (≈ 1e-5 relative at 1024 × 512). constant() projects exactly.
// Coefficients are in SCENE space, in the prtshade basis (<prtshade/sh.h>: "order" = number of
// bands L, L² coefficients, index l(l+1)+m).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace prt::bake {

enum class UpAxis { Y, Z };

struct Rgb {
  double r = 0, g = 0, b = 0;
};

// Luminance of linear Rec.709 RGB.
constexpr double luminance(const Rgb& c) noexcept { return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b; }

// Map-space direction of a scene direction and back (see the header comment).
Eigen::Vector3d map_from_scene(const Eigen::Vector3d& dir_scene, UpAxis up) noexcept;
Eigen::Vector3d scene_from_map(const Eigen::Vector3d& dir_map, UpAxis up) noexcept;

struct EnvMapInfo {
  std::string source;   // file path as given, the name given to from_*, or "constant(r, g, b)"
  std::string sha256;   // of the file bytes (load); of the float32 pixels, little-endian (from_*);
                        // of `source` (constant)
  std::string layout;   // "latlong" | "cube" | "constant"
  int width = 0, height = 0;                // image size in pixels (0 for constant)
  uint64_t negative_pixels_clamped = 0;     // pixels with at least one channel < 0, set to 0
  double min_value_seen = 0;                // most negative channel value before clamping (or min)
  double max_luminance = 0;                 // over texels, after clamping
  double mean_luminance = 0;                // (1/4π) Σ_t lum_t Ω_t: solid-angle weighted
};

class EnvMap {
public:
  // Reads an OpenEXR lat-long or cube map. Layout from the `envmap` header attribute; without
  // it, width == 2·height is lat-long and height == 6·width is a cube map. Channels R, G, B
  // (float slices; alpha and other channels ignored); a luminance-only image (Y) is read as
  // grey; a luminance/chroma image (Y, RY, BY) is converted by Imf::RgbaInputFile.
  // Throws InputError("<exr>: <defect>") for a missing/unreadable/truncated/garbled file, an
  // unsupported shape or channel set, a header whose pixels cannot fit in the file (exr_file.cpp,
  // max_compression_ratio), or a NaN/Inf pixel. No OpenEXR exception escapes. Running out of
  // memory is a SystemError("<exr>: out of memory while reading the file").
  static EnvMap load(const std::filesystem::path& exr, UpAxis up);
  // What load() would say of the file without reading its pixels: info()'s source, sha256,
  // layout, width and height (the pixel statistics stay 0), after the same checks of the file
  // and its header (the same InputErrors; a bad pixel is not found). For a process that needs
  // the map's identity only (a merge of committed rows).
  static EnvMapInfo identify(const std::filesystem::path& exr);

  // The same radiance in every direction (white furnace: constant({1, 1, 1})). value must be
  // finite and >= 0 (PRT_CHECK).
  static EnvMap constant(Rgb value);

  // A lat-long map from memory: rgb row-major, 3 floats per pixel, row 0 = north pole (as in
  // a file). width >= 2, height >= 2, rgb.size() == 3·width·height (PRT_CHECK). Same pixel
  // policy as load(); errors name `name`.
  static EnvMap from_latlong(int width, int height, std::vector<float> rgb, UpAxis up, std::string name);
  // An OpenEXR cube map from memory: the S × 6S image of a file (faces +X, −X, +Y, −Y, +Z, −Z stacked
  // top to bottom, each laid out as Imf::CubeMap::pixelPosition). face_size S >= 2,
  // rgb.size() == 3·S·6S (PRT_CHECK). Same pixel policy as load().
  static EnvMap from_exr_cube(int face_size, std::vector<float> rgb, UpAxis up, std::string name);

  // Texel value of the region containing the scene direction (unit; any non-zero length
  // works). Piecewise constant, no filtering.
  Rgb radiance(const Eigen::Vector3d& dir_scene) const;

  // Importance sampling by luminance, see the header comment. (u0, u1) ∈ [0, 1)²; returns a
  // unit scene direction and, if pdf != nullptr, its solid-angle density (> 0).
  Eigen::Vector3d sample(double u0, double u1, double* pdf) const;

  // Solid-angle density of sample() at a scene direction (0 on texels of zero luminance).
  double pdf(const Eigen::Vector3d& dir_scene) const;

  // SH projection, order = number of bands L (1 … prt::sh::kMaxOrder): returns L²·3 doubles,
  // coefficient i of channel c (0 = R, 1 = G, 2 = B) at [i*3 + c]. Deterministic (the same
  // bytes for any thread count).
  std::vector<double> project_sh(int order) const;

  const EnvMapInfo& info() const noexcept { return info_; }
  UpAxis up() const noexcept { return up_; }

  // --- texel-level access (tests, reports, other integrators) -----------------------------
  // Texels are indexed t = y·width + x in image pixels; texel_count() == 0 for constant().
  int texel_count() const noexcept;
  // Texel whose region contains the scene direction (-1 for constant()).
  int texel_of(const Eigen::Vector3d& dir_scene) const;
  // Value (after clamping), exact solid angle, and OpenEXR centre direction (scene space).
  Rgb texel_value(int texel) const;
  double texel_solid_angle(int texel) const;
  Eigen::Vector3d texel_center(int texel) const;
  // A scene direction uniformly distributed in solid angle over the texel's region, from
  // (u0, u1) ∈ [0, 1)² (the warp sample() uses inside the chosen texel).
  Eigen::Vector3d sample_texel(int texel, double u0, double u1) const;
  // The texel's region as a spherical polygon (scene space, unit vertices, counter-clockwise
  // seen from outside: bake/sphere/spherical_polygon.h's positive orientation; edges are great arcs).
  // A cube texel is exactly the great-arc quad of its four corners. A lat-long texel is bounded
  // by two meridians (great arcs) and two parallels (small circles): each parallel is split into
  // the fewest great-arc chords whose slivers leave the polygon's solid angle within
  // `max_relative_area_error` of the texel's (the chord of length ℓ at latitude β leaves a sliver
  // of ~ℓ³|tan β|/12; a pole is one vertex). Shared parallels split alike in both texels, so the
  // polygons of neighbouring texels tile without gaps or overlaps.
  std::vector<Eigen::Vector3d> texel_polygon(int texel, double max_relative_area_error = 1e-6) const;
  // The k × k stratified sub-samples sample_texel(texel, (a + ½)/k, (b + ½)/k) into out[a·k + b]
  // (1 ≤ k ≤ 16), the same values bit for bit; lat-long texels share the k latitudes and k
  // longitudes (2k transcendental pairs instead of k²), and at k = 4 (the texel moments, the
  // irradiance sums' cut texels) read them from per-row and per-column tables built on first use.
  void sample_texel_grid(int texel, int k, std::span<Eigen::Vector3d> out) const;
  // sample_texel_grid(t, 1) of every texel (the same values bit for bit), computed on first use
  // (thread-safe) and kept, 24 bytes per texel: the silhouette integrator's point masses need them
  // at every isoline level it builds (bake/integrators/silhouette.cpp).
  std::span<const Eigen::Vector3d> texel_midpoints() const;

  // OpenEXR's own texel-centre direction (map space, float precision) for pixel (x, y) of a
  // `layout` ("latlong" | "cube") image of width × height, computed by Imf::LatLongMap::
  // direction / Imf::CubeMap::direction + pixelPosition. EnvMap uses double-precision copies
  // of these formulas; this function exists so tests can check the two agree.
  static Eigen::Vector3d openexr_texel_direction(std::string_view layout, int width, int height, int x, int y);

private:
  enum class Layout { Constant, LatLong, ExrCube };  // an OpenEXR cube (docs/ARCHITECTURE.md §3 "Two cube conventions")
  struct Region;  // a texel's region in its parametrisation (envmap.cpp)

  EnvMap();
  static EnvMap read(const std::filesystem::path& exr, const std::string& file, UpAxis up);  // load, memory aside
  static EnvMap build(Layout layout, int width, int height, std::vector<float> rgb, UpAxis up, EnvMapInfo info);
  static EnvMap from_memory(Layout layout, int width, int height, std::vector<float> rgb, UpAxis up, std::string name);
  Region region(int texel) const;
  int texel_of_map(const Eigen::Vector3d& dir_map) const;
  double texel_luminance(int texel) const;

  EnvMapInfo info_;
  Layout layout_ = Layout::Constant;
  UpAxis up_ = UpAxis::Y;
  int width_ = 0, height_ = 0;
  Rgb constant_;
  std::vector<float> rgb_;             // 3 per texel, clamped to >= 0
  std::vector<double> solid_angle_;    // per texel, exact
  // Sampling tables (empty when sampling uniformly): row_cdf_ has height_+1 entries from 0 to
  // 1, col_cdf_ height_ rows of width_+1 entries from 0 to 1. inv_total_ = 1 / Σ lum Ω.
  std::vector<double> row_cdf_, col_cdf_;
  double inv_total_ = 0;
  struct Midpoints;                         // texel_midpoints()'s cache (envmap.cpp), shared by copies
  std::shared_ptr<Midpoints> midpoints_;
  // sample_texel_grid's sines and cosines for lat-long maps at k = kGridTableK, per row and per
  // column (a lat-long texel's latitude bounds depend on its row only, its longitudes on its
  // column only), built on first use into the same shared cache.
  static constexpr int kGridTableK = 4;
  struct GridTables {
    std::vector<std::array<double, 2 * kGridTableK>> rows, cols;
  };
  const GridTables& grid_tables() const;
};

} // namespace prt::bake
