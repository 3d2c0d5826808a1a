// view/raster.h — a small software rasterizer: what an engine does with the baked per-vertex
// and FIV data (prtview's runtime pictures), and the scene pieces the previews add (a ground
// square, translated copies). Camera and pixel conventions: view/camera.h; layers:
// docs/ARCHITECTURE.md §2.
//
// RASTERIZER (rasterize). Every triangle is drawn from both sides (no culling: baked meshes have
// any winding). Per triangle: vertices to view space, clip against z = near (Sutherland–Hodgman,
// one plane: a triangle becomes 0, 1 or 2 triangles whose corners carry their barycentric
// coordinates in the original triangle), project to the screen, then for each pixel centre in
// the bounding box evaluate the three edge functions E(p) = (b − a) × (p − a) in double.
// Coverage rules:
//   * inside ⇔ every edge function is > 0 after orienting each edge towards the opposite corner,
//     or = 0 on a TOP or LEFT edge (top-left fill rule, as Direct3D/OpenGL): with E = A x + B y + C
//     oriented inwards, an edge owns its pixels iff A > 0 (the triangle lies to its right: a left
//     edge) or A = 0 and B > 0 (horizontal, the triangle lies below: a top edge; y points down).
//     Two triangles sharing an edge have exactly opposite gradients there, so exactly one of them
//     owns each pixel centre on it.
//   * Each edge function is evaluated from a canonical endpoint order (by vertex key: mesh index,
//     clip vertices after all mesh vertices, ordered by the edge they lie on) and negated when
//     needed, so neighbours compute bit-identical |E| on their shared edge — no cracks, no double
//     coverage (the tests count it).
//   * Depth test: the smallest view depth wins; equal depths keep the earlier triangle.
// Interpolation is perspective-correct: with screen-space barycentrics λ_k and view depths z_k of
// the (clipped) corners, the attribute weights are w_k = (λ_k / z_k) / Σ_j (λ_j / z_j) and the
// depth is 1 / Σ_j (λ_j / z_j). The G-buffer keeps, per pixel, the triangle and its barycentric
// coordinates in the ORIGINAL triangle; position, normal (interpolated vertex normals,
// normalised) and per-vertex attributes follow from them.
#pragma once

#include <view/camera.h>
#include <view/image.h>

#include <bake/mesh/mesh.h>

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

namespace prt::view {

// Per pixel: the visible triangle (−1: nothing) and the barycentric coordinates of the pixel's
// sample in that triangle (weights of its corners 0, 1, 2; perspective-correct).
struct GBuffer {
  int width = 0, height = 0;
  std::vector<int32_t> triangle;
  std::vector<std::array<float, 3>> bary;
  std::vector<float> depth;  // view depth (f · (q − eye)); +inf where nothing is drawn
  size_t covered() const;
  // width × height pixels showing nothing (triangle −1, depth +inf).
  static GBuffer blank(int width, int height);
};

GBuffer rasterize(const bake::Mesh& mesh, const Camera& camera);

// What a shader sees at one pixel.
struct Fragment {
  int x = 0, y = 0;
  int32_t triangle = -1;
  std::array<float, 3> bary{};
  Eigen::Vector3d p{0, 0, 0};   // world position
  Eigen::Vector3d n{0, 1, 0};   // interpolated vertex normal, normalised (the geometric one if that is zero)
  Eigen::Vector3d ng{0, 1, 0};  // unit geometric normal, turned to the side of n
};
Fragment make_fragment(const bake::Mesh& mesh, const GBuffer& g, int x, int y);
// The same fragment at any point of a triangle (barycentric weights of its corners 0, 1, 2; x, y
// left 0): the reference's path vertices (view/reference.h, bounces).
Fragment surface_fragment(const bake::Mesh& mesh, int32_t triangle, const std::array<float, 3>& bary);

// Calls shade(fragment, rgb) for every covered pixel (in parallel: `shade` must be thread-safe);
// uncovered pixels are 0.
Image shade_pixels(const bake::Mesh& mesh, const GBuffer& g, const std::function<void(const Fragment&, float*)>& shade);
// Gouraud: per-vertex RGB (3 floats per mesh vertex) interpolated with the G-buffer's weights.
Image interpolate_vertices(const bake::Mesh& mesh, const GBuffer& g, std::span<const float> vertex_rgb);
// Several objects drawn as one mesh: Gouraud of `vertex_rgb` (3 floats per mesh vertex) on every
// triangle t with per_pixel[t] == 0, `shade` per pixel on the others (prtview: the FIV self-shadows
// of occluder-only objects next to per-vertex receivers). per_pixel has one entry per triangle.
Image shade_mixed(const bake::Mesh& mesh, const GBuffer& g, std::span<const float> vertex_rgb,
                  std::span<const uint8_t> per_pixel, const std::function<void(const Fragment&, float*)>& shade);

// ---- scene assembly for the previews ---------------------------------------------------------
// A square in the plane y = `y` (normal +Y), centred at (cx, cz), half-size `half`, two triangles.
bake::Mesh ground_quad(double y, double cx, double cz, double half, const std::string& name = "ground");
// A copy of `mesh` moved by `offset` (normals unchanged).
bake::Mesh translated(const bake::Mesh& mesh, const Eigen::Vector3d& offset, const std::string& name);

} // namespace prt::view
