// Environment maps: texel geometry, importance sampling, SH projection (the file is read in
// exr_file.cpp).
// Conventions and policies are specified in bake/environment/envmap.h.
#include <bake/core/error.h>
#include <bake/core/sha256.h>
#include <bake/environment/envmap.h>

#include "exr_limits.h"

#include <prtshade/sh.h>

#include <Eigen/Geometry>

#include <ImfEnvmap.h>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <mutex>
#include <bit>
#include <cmath>
#include <cstring>
#include <iomanip>
#include <numbers>
#include <sstream>
#include <string_view>
#include <vector>

namespace prt::bake {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kInvFourPi = 0.25 * std::numbers::inv_pi;

// Largest double below 1, for remainders that must stay in [0, 1).
constexpr double kOneMinusEps = 1.0 - 0x1.0p-53;

enum Face { kPosX = 0, kNegX, kPosY, kNegY, kPosZ, kNegZ };

// F(a, b) = ∫_0^a ∫_0^b (1 + s² + t²)^(-3/2) dt ds: solid angle subtended by the rectangle
// [0, a] × [0, b] of the plane at unit distance (signed).
double rect_F(double a, double b) { return std::atan2(a * b, std::sqrt(1.0 + a * a + b * b)); }
double rect_solid_angle(double a0, double a1, double b0, double b1) {
  return rect_F(a1, b1) - rect_F(a0, b1) - rect_F(a1, b0) + rect_F(a0, b0);
}

// Unnormalised map direction of face-plane point (a, b) (Imf::CubeMap::direction).
Eigen::Vector3d cube_dir(int face, double a, double b) {
  switch (face) {
  case kPosX: return {1, a, b};
  case kNegX: return {-1, a, b};
  case kPosY: return {a, 1, b};
  case kNegY: return {a, -1, b};
  case kPosZ: return {a, b, 1};
  default: return {a, b, -1};
  }
}

// Position in face (i, j) ↔ image pixel (x, y) of an S × 6S cube map (Imf::CubeMap::
// pixelPosition and its inverse; face f occupies image rows f·S … f·S + S − 1).
void face_to_image(int face, int i, int j, int S, int& x, int& y) {
  const int m = S - 1;
  int ly = 0;
  switch (face) {
  case kPosX: x = j, ly = m - i; break;
  case kNegX: x = m - j, ly = m - i; break;
  case kPosY: x = i, ly = m - j; break;
  case kNegY: x = i, ly = j; break;
  case kPosZ: x = m - i, ly = m - j; break;
  default: x = i, ly = m - j; break;
  }
  y = face * S + ly;
}
void image_to_face(int x, int y, int S, int& face, int& i, int& j) {
  const int m = S - 1;
  face = y / S;
  const int ly = y - face * S;
  switch (face) {
  case kPosX: i = m - ly, j = x; break;
  case kNegX: i = m - ly, j = m - x; break;
  case kPosY: i = x, j = m - ly; break;
  case kNegY: i = x, j = ly; break;
  case kPosZ: i = m - x, j = m - ly; break;
  default: i = x, j = m - ly; break;
  }
}

// Nearest integer position in [0, n−1] of a continuous pixel coordinate.
int nearest(double p, int n) {
  const double r = std::floor(p + 0.5);
  if (!(r > 0)) return 0;  // also catches NaN
  return r >= n - 1 ? n - 1 : int(r);
}

// Half-pixel bounds of integer position k clipped to [0, n−1].
void half_pixel_bounds(int k, int n, double& lo, double& hi) {
  lo = std::max(k - 0.5, 0.0);
  hi = std::min(k + 0.5, double(n - 1));
}

// Lat-long: OpenEXR's latitude/longitude of continuous pixel positions.
double latitude_of(double py, int H) { return 0.5 * kPi - kPi * py / (H - 1); }
double longitude_of(double px, int W) { return kPi - 2.0 * kPi * px / (W - 1); }

Eigen::Vector3d latlong_dir(double lat, double lon) {
  const double c = std::cos(lat);
  return {std::sin(lon) * c, std::sin(lat), std::cos(lon) * c};
}


Eigen::Vector3d uniform_sphere(double u0, double u1) {
  const double z = 1.0 - 2.0 * u0;
  const double r = std::sqrt(std::max(0.0, (1.0 - z) * (1.0 + z)));
  const double phi = 2.0 * kPi * u1;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

// Index i with cdf[i] <= u < cdf[i+1] (skipping zero-width bins) and the remainder in [0, 1).
int sample_cdf(const double* cdf, int n, double u, double& remainder) {
  const double* it = std::upper_bound(cdf, cdf + n + 1, u);
  int i = int(it - cdf) - 1;
  i = std::clamp(i, 0, n - 1);
  const double w = cdf[i + 1] - cdf[i];
  remainder = w > 0 ? std::clamp((u - cdf[i]) / w, 0.0, kOneMinusEps) : 0.5;
  return i;
}

} // namespace

struct EnvMap::Region {
  int face = -1;            // cube face, -1 for lat-long
  double s0, s1, t0, t1;    // lat-long: longitude [s0, s1], sin(latitude) [t0, t1];
                            // cube: face plane a ∈ [s0, s1], b ∈ [t0, t1]
  double ds = 0, dt = 0;    // lat-long: s1 − s0 and t1 − t0 computed without cancellation (for Ω)
};

Eigen::Vector3d map_from_scene(const Eigen::Vector3d& d, UpAxis up) noexcept {
  return up == UpAxis::Y ? d : Eigen::Vector3d(d.x(), d.z(), -d.y());
}
Eigen::Vector3d scene_from_map(const Eigen::Vector3d& m, UpAxis up) noexcept {
  return up == UpAxis::Y ? m : Eigen::Vector3d(m.x(), -m.z(), m.y());
}

// ---------------------------------------------------------------------------------------------
// Construction

EnvMap EnvMap::constant(Rgb value) {
  PRT_CHECK(std::isfinite(value.r) && std::isfinite(value.g) && std::isfinite(value.b));
  PRT_CHECK(value.r >= 0 && value.g >= 0 && value.b >= 0);
  EnvMap m;
  m.layout_ = Layout::Constant;
  m.constant_ = value;
  std::ostringstream os;
  os << std::setprecision(17) << "constant(" << value.r << ", " << value.g << ", " << value.b << ")";
  m.info_.source = os.str();
  m.info_.sha256 = sha256_bytes(std::as_bytes(std::span(m.info_.source.data(), m.info_.source.size())));
  m.info_.layout = "constant";
  m.info_.min_value_seen = std::min({value.r, value.g, value.b});
  m.info_.max_luminance = m.info_.mean_luminance = luminance(value);
  return m;
}

EnvMap EnvMap::from_latlong(int width, int height, std::vector<float> rgb, UpAxis up, std::string name) {
  PRT_CHECK_OP(width, >=, 2);
  PRT_CHECK_OP(height, >=, 2);
  return from_memory(Layout::LatLong, width, height, std::move(rgb), up, std::move(name));
}

EnvMap EnvMap::from_exr_cube(int face_size, std::vector<float> rgb, UpAxis up, std::string name) {
  PRT_CHECK_OP(face_size, >=, 2);
  PRT_CHECK_OP(int64_t(face_size), <=, int64_t(1) << 13);
  return from_memory(Layout::ExrCube, face_size, 6 * face_size, std::move(rgb), up, std::move(name));
}

EnvMap EnvMap::from_memory(Layout layout, int width, int height, std::vector<float> rgb, UpAxis up, std::string name) {
  PRT_CHECK_OP(int64_t(width) * height, <=, kMaxPixels);
  PRT_CHECK_OP(rgb.size(), ==, size_t(3) * size_t(width) * size_t(height));
  EnvMapInfo info;
  info.source = std::move(name);
  if constexpr (std::endian::native == std::endian::little) {
    info.sha256 = sha256_bytes(std::as_bytes(std::span(rgb)));
  } else {
    Sha256 s;
    for (float f : rgb) {
      uint32_t u;
      std::memcpy(&u, &f, 4);
      const std::byte b[4] = {std::byte(u), std::byte(u >> 8), std::byte(u >> 16), std::byte(u >> 24)};
      s.update(b);
    }
    info.sha256 = s.hex_digest();
  }
  // Same policy as load(), reporting pixels in 0-based image coordinates.
  for (size_t k = 0; k < rgb.size(); ++k)
    if (!std::isfinite(rgb[k])) {
      std::ostringstream os;
      os << "non-finite pixel value " << rgb[k] << " at (x " << (k / 3) % size_t(width) << ", y "
         << (k / 3) / size_t(width) << ") channel " << "RGB"[k % 3];
      throw InputError(info.source, os.str());
    }
  return build(layout, width, height, std::move(rgb), up, std::move(info));
}


EnvMap EnvMap::build(Layout layout, int width, int height, std::vector<float> rgb, UpAxis up, EnvMapInfo info) {
  EnvMap m;
  m.layout_ = layout;
  m.up_ = up;
  m.width_ = width;
  m.height_ = height;
  info.layout = layout == Layout::ExrCube ? "cube" : "latlong";
  info.width = width;
  info.height = height;

  // Pixel policy: clamp negatives, count pixels.
  double min_seen = rgb.empty() ? 0.0 : double(rgb[0]);
  uint64_t negative = 0;
  for (size_t k = 0; k < rgb.size(); k += 3) {
    bool neg = false;
    for (size_t c = 0; c < 3; ++c) {
      min_seen = std::min(min_seen, double(rgb[k + c]));
      if (rgb[k + c] < 0) rgb[k + c] = 0, neg = true;
    }
    negative += neg;
  }
  info.negative_pixels_clamped = negative;
  info.min_value_seen = min_seen;
  m.rgb_ = std::move(rgb);

  // Exact texel solid angles. A lat-long texel's is ds(column) · dt(row): each factor once per
  // column or row, not per texel (the same products as region(t).ds * region(t).dt).
  const int n = m.texel_count();
  m.solid_angle_.resize(size_t(n));
  if (layout == Layout::LatLong) {
    std::vector<double> ds(static_cast<size_t>(width));
    for (int x = 0; x < width; ++x) ds[size_t(x)] = m.region(x).ds;
    for (int y = 0; y < height; ++y) {
      const double dt = m.region(y * width).dt;
      for (int x = 0; x < width; ++x) m.solid_angle_[size_t(y) * size_t(width) + size_t(x)] = ds[size_t(x)] * dt;
    }
  } else {
    for (int t = 0; t < n; ++t) {
      const Region r = m.region(t);
      m.solid_angle_[size_t(t)] = rect_solid_angle(r.s0, r.s1, r.t0, r.t1);
    }
  }

  // Sampling tables: weight lum·Ω, marginal over image rows, conditional within each row.
  const int W = width, H = height;
  m.col_cdf_.assign(size_t(H) * size_t(W + 1), 0.0);
  m.row_cdf_.assign(size_t(H + 1), 0.0);
  double total = 0, max_lum = 0;
  for (int y = 0; y < H; ++y) {
    double* c = &m.col_cdf_[size_t(y) * size_t(W + 1)];
    double row = 0;
    for (int x = 0; x < W; ++x) {
      const int t = y * W + x;
      const double lum = m.texel_luminance(t);
      max_lum = std::max(max_lum, lum);
      row += lum * m.solid_angle_[size_t(t)];
      c[x + 1] = row;
    }
    if (row > 0) {
      for (int x = 1; x < W; ++x) c[x] /= row;
    } else {
      for (int x = 1; x < W; ++x) c[x] = double(x) / W;
    }
    c[W] = 1.0;
    total += row;
    m.row_cdf_[size_t(y) + 1] = total;
  }
  info.max_luminance = max_lum;
  info.mean_luminance = total * kInvFourPi;
  if (total > 0) {
    for (int y = 1; y < H; ++y) m.row_cdf_[size_t(y)] /= total;
    m.row_cdf_[size_t(H)] = 1.0;
    m.inv_total_ = 1.0 / total;
  } else {  // all black: uniform sphere sampling
    m.row_cdf_.clear();
    m.col_cdf_.clear();
    m.inv_total_ = 0;
  }
  m.info_ = std::move(info);
  return m;
}

// ---------------------------------------------------------------------------------------------
// Texel geometry

int EnvMap::texel_count() const noexcept { return layout_ == Layout::Constant ? 0 : width_ * height_; }

EnvMap::Region EnvMap::region(int texel) const {
  const int x = texel % width_, y = texel / width_;
  Region r;
  if (layout_ == Layout::LatLong) {
    // The widths are formed from the (exact) half-pixel offsets, not as differences of angles,
    // so the solid angles carry no correlated rounding and sum to 4π to ~1e-15 relative.
    double lo, hi;
    half_pixel_bounds(x, width_, lo, hi);
    r.s0 = longitude_of(hi, width_);
    r.s1 = longitude_of(lo, width_);
    r.ds = 2.0 * kPi * (hi - lo) / (width_ - 1);
    half_pixel_bounds(y, height_, lo, hi);
    const double half_dlat = 0.5 * kPi * (hi - lo) / (height_ - 1);
    const double mid_lat = 0.5 * kPi - 0.5 * kPi * (lo + hi) / (height_ - 1);
    // sin(top) − sin(bottom) in product form: full relative precision near the poles.
    r.dt = 2.0 * std::cos(mid_lat) * std::sin(half_dlat);
    r.t1 = std::sin(latitude_of(lo, height_));
    r.t0 = y == height_ - 1 ? -1.0 : r.t1 - r.dt;
  } else {
    const int S = width_;
    int i, j;
    image_to_face(x, y, S, r.face, i, j);
    const double scale = 2.0 / (S - 1);
    double lo, hi;
    half_pixel_bounds(i, S, lo, hi);
    r.s0 = lo * scale - 1.0, r.s1 = hi * scale - 1.0;
    half_pixel_bounds(j, S, lo, hi);
    r.t0 = lo * scale - 1.0, r.t1 = hi * scale - 1.0;
  }
  return r;
}

double EnvMap::texel_luminance(int texel) const {
  const float* p = &rgb_[size_t(texel) * 3];
  return luminance(Rgb{double(p[0]), double(p[1]), double(p[2])});
}

Rgb EnvMap::texel_value(int texel) const {
  PRT_CHECK(texel >= 0 && texel < texel_count());
  const float* p = &rgb_[size_t(texel) * 3];
  return Rgb{double(p[0]), double(p[1]), double(p[2])};
}

double EnvMap::texel_solid_angle(int texel) const {
  PRT_CHECK(texel >= 0 && texel < texel_count());
  return solid_angle_[size_t(texel)];
}

Eigen::Vector3d EnvMap::texel_center(int texel) const {
  PRT_CHECK(texel >= 0 && texel < texel_count());
  const int x = texel % width_, y = texel / width_;
  Eigen::Vector3d d;
  if (layout_ == Layout::LatLong) {
    d = latlong_dir(latitude_of(y, height_), longitude_of(x, width_));
  } else {
    const int S = width_;
    int face, i, j;
    image_to_face(x, y, S, face, i, j);
    const double scale = 2.0 / (S - 1);
    d = cube_dir(face, i * scale - 1.0, j * scale - 1.0).normalized();
  }
  return scene_from_map(d, up_);
}

int EnvMap::texel_of_map(const Eigen::Vector3d& d) const {
  if (layout_ == Layout::LatLong) {
    const double lon = std::atan2(d.x(), d.z());
    const double lat = std::atan2(d.y(), std::hypot(d.x(), d.z()));
    const int x = nearest((kPi - lon) * (width_ - 1) / (2.0 * kPi), width_);
    const int y = nearest((0.5 * kPi - lat) * (height_ - 1) / kPi, height_);
    return y * width_ + x;
  }
  // Cube: face of the largest |component|, ties X before Y before Z (Imf::CubeMap).
  const double ax = std::abs(d.x()), ay = std::abs(d.y()), az = std::abs(d.z());
  int face;
  double a, b;
  if (ax >= ay && ax >= az) {
    if (ax == 0) return 0;  // zero vector: OpenEXR's special case (+X, position (0, 0))
    face = d.x() > 0 ? kPosX : kNegX, a = d.y() / ax, b = d.z() / ax;
  } else if (ay >= az) {
    face = d.y() > 0 ? kPosY : kNegY, a = d.x() / ay, b = d.z() / ay;
  } else {
    face = d.z() > 0 ? kPosZ : kNegZ, a = d.x() / az, b = d.y() / az;
  }
  const int S = width_;
  const int i = nearest((a + 1.0) * 0.5 * (S - 1), S), j = nearest((b + 1.0) * 0.5 * (S - 1), S);
  int x, y;
  face_to_image(face, i, j, S, x, y);
  return y * width_ + x;
}

int EnvMap::texel_of(const Eigen::Vector3d& dir_scene) const {
  if (layout_ == Layout::Constant) return -1;
  return texel_of_map(map_from_scene(dir_scene, up_));
}

Rgb EnvMap::radiance(const Eigen::Vector3d& dir_scene) const {
  if (layout_ == Layout::Constant) return constant_;
  const float* p = &rgb_[size_t(texel_of_map(map_from_scene(dir_scene, up_))) * 3];
  return Rgb{double(p[0]), double(p[1]), double(p[2])};
}

std::vector<Eigen::Vector3d> EnvMap::texel_polygon(int texel, double max_relative_area_error) const {
  PRT_CHECK(texel >= 0 && texel < texel_count());
  PRT_CHECK(max_relative_area_error > 0);
  const Region r = region(texel);
  std::vector<Eigen::Vector3d> poly;
  if (r.face >= 0) {
    for (const auto& [a, b] : {std::pair{r.s0, r.t0}, {r.s1, r.t0}, {r.s1, r.t1}, {r.s0, r.t1}})
      poly.push_back(cube_dir(r.face, a, b).normalized());
    // (a, b) runs counter-clockwise about the outward direction on half the faces.
    if ((poly[1] - poly[0]).cross(poly[2] - poly[0]).dot(poly[0]) < 0) std::reverse(poly.begin(), poly.end());
  } else {
    const int x = texel % width_, y = texel / width_;
    double xlo, xhi, ylo, yhi;
    half_pixel_bounds(x, width_, xlo, xhi);
    half_pixel_bounds(y, height_, ylo, yhi);
    const double lon0 = longitude_of(xhi, width_), lon1 = longitude_of(xlo, width_);  // lon0 < lon1
    const double lat_top = latitude_of(ylo, height_), lat_bottom = latitude_of(yhi, height_);
    // Chords per parallel from the sliver bound (header): k chords over a parallel of length
    // ℓ_0 = Δλ cos β and geodesic curvature |tan β| leave ℓ_0³ |tan β| / (12 k²), at most
    // max_relative_area_error × the smaller texel of the column on either side of the parallel
    // (a function of the parallel and the column alone, so both texels split it alike).
    auto row_area = [&](int row) {  // solid angle of this column's texel in `row` (0 outside the map)
      if (row < 0 || row >= height_) return 0.0;
      double lo, hi;
      half_pixel_bounds(row, height_, lo, hi);
      return (lon1 - lon0) * (std::sin(latitude_of(lo, height_)) - std::sin(latitude_of(hi, height_)));
    };
    auto chords = [&](double lat, int row_above) {
      if (std::abs(lat) >= 0.5 * kPi) return 0;  // a pole: one vertex
      const double a0 = row_area(row_above), a1 = row_area(row_above + 1);
      const double area = a0 > 0 && a1 > 0 ? std::min(a0, a1) : std::max(a0, a1);
      const double len = (lon1 - lon0) * std::cos(lat);
      const double k = std::sqrt(len * len * len * std::abs(std::tan(lat)) / (12.0 * max_relative_area_error * area));
      return std::clamp(int(std::ceil(k)), 1, 1 << 12);
    };
    // Counter-clockwise seen from outside: along the bottom parallel eastwards (longitude
    // increasing), then back along the top one. (With lon the angle from +z towards +x, the east
    // direction ∂d/∂lon and north ∂d/∂lat satisfy east × north = d: outward.)
    const int kb = chords(lat_bottom, y), kt = chords(lat_top, y - 1);
    if (kb == 0) poly.push_back(latlong_dir(lat_bottom, 0.0));
    for (int j = 0; j <= kb && kb > 0; ++j) poly.push_back(latlong_dir(lat_bottom, lon0 + (lon1 - lon0) * j / kb));
    if (kt == 0) poly.push_back(latlong_dir(lat_top, 0.0));
    for (int j = kt; j >= 0 && kt > 0; --j) poly.push_back(latlong_dir(lat_top, lon0 + (lon1 - lon0) * j / kt));
  }
  for (Eigen::Vector3d& v : poly) v = scene_from_map(v, up_);
  return poly;
}

Eigen::Vector3d EnvMap::sample_texel(int texel, double u0, double u1) const {
  PRT_CHECK(texel >= 0 && texel < texel_count());
  const Region r = region(texel);
  Eigen::Vector3d d;
  if (r.face < 0) {
    // Uniform in solid angle: uniform in sin(latitude) (u0) and longitude (u1).
    const double s = std::clamp(r.t0 + u0 * (r.t1 - r.t0), -1.0, 1.0);
    const double lon = r.s0 + u1 * (r.s1 - r.s0);
    const double c = std::sqrt(std::max(0.0, (1.0 - s) * (1.0 + s)));
    d = Eigen::Vector3d(std::sin(lon) * c, s, std::cos(lon) * c);
  } else {
    // Uniform in solid angle over the face rectangle [a0, a1] × [b0, b1]. The marginal CDF in a
    // is G(a) = F(a, b1) − F(a, b0) − F(a0, b1) + F(a0, b0) (F = rect_F), inverted by Newton
    // steps kept inside a bisection bracket; the conditional in b given a has density
    // ∝ (c² + b²)^(-3/2), c² = 1 + a², with CDF ∝ q(b) = b / sqrt(c² + b²): inverted in closed form.
    const double a0 = r.s0, a1 = r.s1, b0 = r.t0, b1 = r.t1;
    const double base = rect_F(a0, b1) - rect_F(a0, b0);
    const double target = u0 * rect_solid_angle(a0, a1, b0, b1);
    auto G = [&](double a) { return rect_F(a, b1) - rect_F(a, b0) - base; };
    auto g = [&](double a) {
      const double c2 = 1.0 + a * a;
      return (b1 / std::sqrt(c2 + b1 * b1) - b0 / std::sqrt(c2 + b0 * b0)) / c2;
    };
    double lo = a0, hi = a1, a = a0 + u0 * (a1 - a0);
    for (int iter = 0; iter < 60; ++iter) {
      const double f = G(a) - target;
      if (f > 0) hi = a; else lo = a;
      double next = a - f / g(a);
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
      // 1e-13 of the texel width: far below any sampling resolution that matters, and above
      // the rounding noise of G (differences of atan values), so Newton stops after 2–3 steps.
      const bool done = std::abs(next - a) <= 1e-13 * (a1 - a0);
      a = next;
      if (done) break;
    }
    a = std::clamp(a, a0, a1);
    const double c2 = 1.0 + a * a, c = std::sqrt(c2);
    const double q0 = b0 / std::sqrt(c2 + b0 * b0), q1 = b1 / std::sqrt(c2 + b1 * b1);
    const double q = q0 + u1 * (q1 - q0);
    const double b = std::clamp(c * q / std::sqrt((1.0 - q) * (1.0 + q)), b0, b1);
    d = cube_dir(r.face, a, b).normalized();
  }
  return scene_from_map(d, up_);
}

void EnvMap::sample_texel_grid(int texel, int k, std::span<Eigen::Vector3d> out) const {
  PRT_CHECK(k >= 1 && k <= 16 && out.size() >= size_t(k) * size_t(k));
  PRT_CHECK(texel >= 0 && texel < texel_count());
  if (layout_ == Layout::LatLong && k == kGridTableK) {
    // The 4 × 4 grid (texel moments, cut texels of the irradiance sums): its sines and cosines
    // per row and per column, formed once below by this function's own arithmetic (same bits).
    const GridTables& g = grid_tables();
    const auto& row = g.rows[size_t(texel / width_)];
    const auto& col = g.cols[size_t(texel % width_)];
    for (int a = 0; a < k; ++a)
      for (int b = 0; b < k; ++b)
        out[size_t(a * k + b)] = scene_from_map(Eigen::Vector3d(col[size_t(b)] * row[size_t(k + a)], row[size_t(a)],
                                                                col[size_t(k + b)] * row[size_t(k + a)]),
                                                up_);
    return;
  }
  const Region r = region(texel);
  if (r.face >= 0) {
    for (int a = 0; a < k; ++a)
      for (int b = 0; b < k; ++b) out[size_t(a * k + b)] = sample_texel(texel, (a + 0.5) / k, (b + 0.5) / k);
    return;
  }
  double s[16], c[16], sl[16], cl[16];
  for (int a = 0; a < k; ++a) {  // exactly sample_texel's arithmetic, shared across the grid
    s[a] = std::clamp(r.t0 + ((a + 0.5) / k) * (r.t1 - r.t0), -1.0, 1.0);
    c[a] = std::sqrt(std::max(0.0, (1.0 - s[a]) * (1.0 + s[a])));
  }
  for (int b = 0; b < k; ++b) {
    const double lon = r.s0 + ((b + 0.5) / k) * (r.s1 - r.s0);
    sl[b] = std::sin(lon);
    cl[b] = std::cos(lon);
  }
  for (int a = 0; a < k; ++a)
    for (int b = 0; b < k; ++b)
      out[size_t(a * k + b)] = scene_from_map(Eigen::Vector3d(sl[b] * c[a], s[a], cl[b] * c[a]), up_);
}

struct EnvMap::Midpoints {
  std::once_flag once;
  std::vector<Eigen::Vector3d> directions;
  // sample_texel_grid's lat-long tables for k = kGridTableK: per row {s[a]..., c[a]...}, per
  // column {sin(lon_b)..., cos(lon_b)...}.
  std::once_flag grid_once;
  GridTables grid;
};

const EnvMap::GridTables& EnvMap::grid_tables() const {
  PRT_CHECK(midpoints_ != nullptr);
  std::call_once(midpoints_->grid_once, [&] {
    constexpr int k = kGridTableK;
    GridTables& g = midpoints_->grid;
    g.rows.resize(size_t(height_));
    g.cols.resize(size_t(width_));
    for (int y = 0; y < height_; ++y) {  // sample_texel_grid's arithmetic, from the row's first texel
      const Region r = region(y * width_);
      for (int a = 0; a < k; ++a) {
        const double s = std::clamp(r.t0 + ((a + 0.5) / k) * (r.t1 - r.t0), -1.0, 1.0);
        g.rows[size_t(y)][size_t(a)] = s;
        g.rows[size_t(y)][size_t(k + a)] = std::sqrt(std::max(0.0, (1.0 - s) * (1.0 + s)));
      }
    }
    for (int x = 0; x < width_; ++x) {  // … from the column's first texel
      const Region r = region(x);
      for (int b = 0; b < k; ++b) {
        const double lon = r.s0 + ((b + 0.5) / k) * (r.s1 - r.s0);
        g.cols[size_t(x)][size_t(b)] = std::sin(lon);
        g.cols[size_t(x)][size_t(k + b)] = std::cos(lon);
      }
    }
  });
  return midpoints_->grid;
}

EnvMap::EnvMap() : midpoints_(std::make_shared<Midpoints>()) {}

std::span<const Eigen::Vector3d> EnvMap::texel_midpoints() const {
  PRT_CHECK(midpoints_ != nullptr);
  std::call_once(midpoints_->once, [&] {
    std::vector<Eigen::Vector3d> d(static_cast<size_t>(texel_count()));
    // Each texel's own value, whatever the thread that computes it. Isolated: a thread waiting
    // here takes no outer task that could call texel_midpoints() again inside call_once.
    tbb::this_task_arena::isolate([&] {
      tbb::parallel_for(0, texel_count(), [&](int t) { sample_texel_grid(t, 1, std::span(&d[size_t(t)], 1)); });
    });
    midpoints_->directions = std::move(d);
  });
  return midpoints_->directions;
}

// ---------------------------------------------------------------------------------------------
// Importance sampling

Eigen::Vector3d EnvMap::sample(double u0, double u1, double* pdf_out) const {
  if (layout_ == Layout::Constant || row_cdf_.empty()) {
    if (pdf_out) *pdf_out = kInvFourPi;
    return uniform_sphere(u0, u1);
  }
  double v0, v1;
  const int y = sample_cdf(row_cdf_.data(), height_, u0, v0);
  const int x = sample_cdf(&col_cdf_[size_t(y) * size_t(width_ + 1)], width_, u1, v1);
  const int t = y * width_ + x;
  if (pdf_out) *pdf_out = texel_luminance(t) * inv_total_;
  return sample_texel(t, v0, v1);
}

double EnvMap::pdf(const Eigen::Vector3d& dir_scene) const {
  if (layout_ == Layout::Constant || row_cdf_.empty()) return kInvFourPi;
  return texel_luminance(texel_of_map(map_from_scene(dir_scene, up_))) * inv_total_;
}

// ---------------------------------------------------------------------------------------------
// SH projection

std::vector<double> EnvMap::project_sh(int order) const {
  PRT_CHECK(order >= 1 && order <= prt::sh::kMaxOrder);
  const size_t nc = size_t(order) * size_t(order);
  std::vector<double> out(3 * nc, 0.0);
  if (layout_ == Layout::Constant) {
    const double s = 2.0 * std::sqrt(kPi);  // ∫ y_00 dω = 4π · 1/(2√π)
    out[0] = constant_.r * s, out[1] = constant_.g * s, out[2] = constant_.b * s;
    return out;
  }
  // Fixed blocks of rows, summed in block order afterwards: the same bytes for any thread count.
  constexpr int kRowsPerBlock = 4;
  const int blocks = (height_ + kRowsPerBlock - 1) / kRowsPerBlock;
  std::vector<double> partial(size_t(blocks) * 3 * nc, 0.0);
  tbb::parallel_for(0, blocks, [&](int blk) {
    std::vector<double> y(nc), row(3 * nc);
    double* acc = &partial[size_t(blk) * 3 * nc];
    const int y_end = std::min(height_, (blk + 1) * kRowsPerBlock);
    for (int py = blk * kRowsPerBlock; py < y_end; ++py) {
      std::fill(row.begin(), row.end(), 0.0);
      for (int px = 0; px < width_; ++px) {
        const int t = py * width_ + px;
        const float* v = &rgb_[size_t(t) * 3];
        if (v[0] == 0 && v[1] == 0 && v[2] == 0) continue;
        const Eigen::Vector3d d = texel_center(t);
        prt::sh::eval(order, d.x(), d.y(), d.z(), y);
        const double w = solid_angle_[size_t(t)];
        const double wr = w * v[0], wg = w * v[1], wb = w * v[2];
        for (size_t i = 0; i < nc; ++i) {
          row[3 * i] += wr * y[i];
          row[3 * i + 1] += wg * y[i];
          row[3 * i + 2] += wb * y[i];
        }
      }
      for (size_t k = 0; k < 3 * nc; ++k) acc[k] += row[k];
    }
  });
  for (int blk = 0; blk < blocks; ++blk)
    for (size_t k = 0; k < 3 * nc; ++k) out[k] += partial[size_t(blk) * 3 * nc + k];
  return out;
}

// ---------------------------------------------------------------------------------------------
// OpenEXR's own geometry, for checking ours

Eigen::Vector3d EnvMap::openexr_texel_direction(std::string_view layout, int width, int height, int x, int y) {
  PRT_CHECK(x >= 0 && x < width && y >= 0 && y < height);
  const Imath::Box2i dw(Imath::V2i(0, 0), Imath::V2i(width - 1, height - 1));
  Imath::V3f d;
  if (layout == "latlong") {
    d = Imf::LatLongMap::direction(dw, Imath::V2f(float(x), float(y)));
  } else {
    PRT_CHECK(layout == "cube");
    const int S = Imf::CubeMap::sizeOfFace(dw);
    PRT_CHECK(S >= 1);
    // Find the face and in-face position whose CubeMap::pixelPosition is (x, y).
    const int face = y / S;
    PRT_CHECK(face < 6);
    bool found = false;
    for (int i = 0; i < S && !found; ++i)
      for (int j = 0; j < S && !found; ++j) {
        const Imath::V2f p = Imf::CubeMap::pixelPosition(Imf::CubeMapFace(face), dw, Imath::V2f(float(i), float(j)));
        if (int(std::lround(p.x)) == x && int(std::lround(p.y)) == y) {
          d = Imf::CubeMap::direction(Imf::CubeMapFace(face), dw, Imath::V2f(float(i), float(j)));
          found = true;
        }
      }
    PRT_CHECK(found);
  }
  return Eigen::Vector3d(d.x, d.y, d.z).normalized();
}

} // namespace prt::bake
