// view/lightmap.h — per-texel shading: what an engine does with a baked lightmap (format version
// 5, formats/SCHEMA.md "Lightmaps (version 5)"), the per-texel counterpart of
// view::interpolate_vertices (view/raster.h). Layers: docs/ARCHITECTURE.md §2.
//
// SAMPLING (SCHEMA's rule for consumers). A pixel of the G-buffer shows triangle t at barycentric
// weights β (perspective-correct, in the original triangle, view/raster.h). Its lightmap UV is
// uv = Σ_k β_k uv_t,k over the triangle's three corner UVs (`corner_uv`, 6 floats per triangle in
// mesh/triangles order: u0 v0 u1 v1 u2 v2; v runs down the image, row 0 at v = 0). The product is
// filtered bilinearly at texel coordinates (s, r) = (u·W − ½, v·H − ½): the four texels whose
// centres surround it, weights (1 − fx)(1 − fy), fx(1 − fy), (1 − fx) fy, fx fy with fx, fy the
// fractional parts; a coordinate outside [0, W − 1] (or [0, H − 1]) is clamped to the edge texel
// (clamp-to-edge addressing, as an engine's sampler). Weights and sums in double, the result
// rounded to float once.
//
// THE CHECK. Every texel a triangle's UV image touches is baked or filled and each chart is padded
// into its gutter, so a pixel inside a triangle should never reach an empty texel (state 0).
// A pixel whose footprint gives weight > 0 to an empty texel is counted (`empty_hits`): it is a
// defect of the atlas or of the padding, reported, not hidden (the value is still the weighted
// sum, the empty texel contributing its stored 0).
#pragma once

#include <view/image.h>
#include <view/raster.h>

#include <bake/mesh/mesh.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>

namespace prt::view {

// A lightmap image as stored: `channels` floats per texel, row-major [H][W][channels], and the
// texels' state [H][W] (0 empty, 1 baked, 2 filled, 3 padding).
struct LightmapImage {
  int width = 0, height = 0;
  size_t channels = 0;
  std::span<const float> values;
  std::span<const uint8_t> state;
};

// The lightmap UV of fragment `f` on `triangle` of a set whose corner UVs are `corner_uv` (6 floats
// per triangle): Σ_k β_k uv_k, in double (the rule above).
Eigen::Vector2d fragment_uv(const Fragment& f, std::span<const float> corner_uv, size_t triangle);

// Bilinear sample at (u, v) into out[channels] (the rule above). Returns true when the footprint
// gives weight > 0 to an empty texel.
bool sample_lightmap(const LightmapImage& map, double u, double v, float* out);

// A per-texel render: the image, and how many covered pixels reached an empty texel.
struct TexelRender {
  Image image;
  size_t pixels = 0;      // covered pixels shaded from the lightmap
  size_t empty_hits = 0;  // of them, those whose bilinear footprint reached an empty texel
};

// Shades every covered pixel of `g` from the lightmap: its UV through its triangle's corner UVs,
// the bilinear sample (map.channels floats), then shade(fragment, sample, rgb) turns the sample
// into RGB (prtshade's per-vertex formulas with one "vertex": the coefficient layout of a texel is
// a vertex's). `shade` must be thread-safe (pixels are shaded in parallel).
TexelRender shade_texels(const bake::Mesh& mesh, const GBuffer& g, std::span<const float> corner_uv, const LightmapImage& map,
                         const std::function<void(const Fragment&, const float* sample, float* rgb)>& shade);

} // namespace prt::view
