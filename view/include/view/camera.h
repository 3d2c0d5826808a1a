// view/camera.h — the pinhole camera both renderers share (view/raster.h, view/reference.h) and
// its text form. Layer and conventions: docs/ARCHITECTURE.md §2 and "Conventions".
//
// CAMERA. Right-handed world, look-at: forward f = normalize(at − eye), right r = normalize(f × up),
// true up u = r × f. fov_y_degrees is the full vertical field of view; aspect = width / height.
// Pixel (x, y) covers [x, x+1) × [y, y+1), y grows DOWNWARDS, row 0 is the top of the picture and
// the pixel is sampled at its centre (x + ½, y + ½) by both renderers, so their pictures line up
// pixel for pixel. Continuous pixel position (sx, sy) ↔ view ray direction
//   d ∝ f + ((2 sx / W − 1) · aspect · tan(fov/2)) r + ((1 − 2 sy / H) · tan(fov/2)) u.
// View depth of a point q: z = f · (q − eye). Geometry with z < near is clipped (both renderers:
// the rasterizer clips triangles against the plane z = near, the ray tracer starts each primary
// ray at depth near). near = 1e-4 · |at − eye| unless set.
//
// Text form: "eye=X,Y,Z:at=X,Y,Z[:up=X,Y,Z][:fov=DEGREES]" and sizes "WxH". Errors are
// bake::InputError naming the value ("camera spec '<spec>': <what is wrong>"), never an option of
// a tool: the tool says where the value came from.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace prt::view {

struct Camera {
  Eigen::Vector3d eye{0, 0, 1}, at{0, 0, 0}, up{0, 1, 0};
  double fov_y_degrees = 45;
  int width = 256, height = 256;
  double near = 0;  // 0: 1e-4 · |at − eye|

  Eigen::Vector3d forward() const;   // f
  Eigen::Vector3d right() const;     // r
  Eigen::Vector3d true_up() const;   // u
  double near_depth() const;
  // Unit direction of the ray through continuous pixel position (sx, sy) (pixel centres at +½).
  Eigen::Vector3d ray_direction(double sx, double sy) const;
  // What is wrong with it, or "" when it is usable: eye == at, up ∥ (at − eye), fov ∉ (0, 180),
  // non-finite numbers, near < 0 or a size outside [1, 16384]².
  std::string problem() const;
  // Throws bake::InputError("camera", problem()) unless problem() is empty.
  void validate() const;
};

// "eye=X,Y,Z:at=X,Y,Z[:up=X,Y,Z][:fov=DEGREES]" (any order, each key at most once; eye and at
// required). Throws bake::InputError("camera spec '<spec>'", "<what is wrong>").
Camera parse_camera(std::string_view spec, int width, int height);
// A first look at a box [lo, hi] (world space) whose "up" is the unit axis `up` (+Y or +Z): the
// camera looks at the box's centre from a three-quarter view above its front — along
// −(0.35 r̂ + 0.5 û + 1 f̂) where û = up and f̂ the front axis (+Z for Y-up, −Y for Z-up, the
// conventions of glTF and of Blender), r̂ = û × f̂ — from the nearest distance at which all eight
// corners are inside the picture with a 5% margin on each side. A degenerate box (a point) becomes
// the box of half-size 1 around it. lo and hi must be finite.
Camera frame_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, const Eigen::Vector3d& up, int width, int height,
                 double fov_y_degrees = 45);
// What a first look frames (focus_box): the geometry without its large flat parts — a ground
// plane 30 units wide under a 10-unit bunny would otherwise take the picture and shrink the
// bunny to a few percent of it.
//   1. Flat parts: triangles joined across shared edges (positions compared exactly) into
//      regions grown from a seed triangle (in triangle order): a neighbour joins when its normal
//      is within 1° of the seed's (either orientation) and its corners lie within 1e-5 × the
//      whole mesh's bounding-box diagonal of the seed's plane. Degenerate triangles stay alone.
//   2. The largest part (bounding-box diagonal; the first of equal ones) is set aside when it is
//      at least kFlatPartRatio (1.5) × as wide as everything else together (the bounding box of
//      the other triangles' corners): framing it would shrink the rest to at most 2/3 of the
//      picture's width (4/9 of its area) while the part, being flat, shows nothing but what the
//      rest casts on it, and the rest's box reaches down to where the rest stands on it. Repeat on
//      what is left (a ground, then a rug on it) until no part qualifies or nothing would be left.
//   3. The box: the corners of the triangles left; when nothing was set aside, every position.
// positions [V][3], triangles [T][3] (indices < V); an empty mesh gives lo = +inf, hi = −inf.
inline constexpr double kFlatPartRatio = 1.5;
struct Focus {
  Eigen::Vector3d lo, hi;
  size_t set_aside_parts = 0, set_aside_triangles = 0;
  double set_aside_extent = 0;  // the first part set aside: its bounding-box diagonal
  double rest_extent = 0;       // of the box returned
};
Focus focus_box(std::span<const double> positions, std::span<const uint32_t> triangles);

// The text form of `c` for people to copy into --camera ("eye=...:at=...:up=...:fov=..."), each
// number with 9 significant digits: parse_camera reads back the same camera to 1e-9 relative.
std::string to_string(const Camera& c);

// "WxH", each in [1, 16384]. Throws bake::InputError("image size '<spec>'", "<what is wrong>").
std::array<int, 2> parse_size(std::string_view spec);

} // namespace prt::view
