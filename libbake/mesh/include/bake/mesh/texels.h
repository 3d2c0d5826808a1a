// bake/mesh/texels.h — the texels of a lightmap as receivers (issue 30): which texels of a W × H
// atlas a mesh covers through one of its UV sets (bake/mesh/mesh.h UvSet), and a shade point on
// the surface for each, gathered as a ReceiverSet (bake/mesh/receivers.h) that the bake pipeline
// (bake/bake/pipeline.h) integrates like any other: no integrator knows texels.
//
// Texel space: u·W, v·H (v as glTF's TEXCOORD: row 0 of the image at v = 0); texel (x, y) is the
// square [x, x + 1] × [y, y + 1], its centre (x + ½, y + ½), its index y·W + x. UVs outside
// [0, 1] cover nothing there (they are clipped to the atlas).
//
// Coverage is CONSERVATIVE: a texel is covered when a triangle's UV image meets its closed square
// (decided by separating axes in double: the triangle's three edge normals and the square's two),
// so thin triangles and chart borders get the texels they touch, not only those whose centres
// they contain. A covered texel's sample (TexelSample) is
//   * the texel centre, when it lies in a triangle's UV image (barycentric coordinates all >= 0);
//     of several such triangles (overlapping UVs: a lightmap set should have none) the first in
//     triangle order;
//   * else the point of the covering triangles' UV images nearest to the centre (their closest
//     triangle, ties to the first), so the sample lies ON the surface, never off its edge.
// The shade point is the sample's surface point, put EXACTLY on its triangle: its barycentric
// coordinates rounded to dyadic fractions (2^-30 or coarser) for which the interpolation in double
// is exact, so it lies in the triangle's plane as a vertex does (a point a rounding below its own
// triangle would see it from behind: a roof over half its hemisphere); on an edge exactly on the
// edge's line; at a corner it is that vertex's shade point (bake/mesh/receivers.h). The normal is
// the interpolated vertex normals (the smooth shading the vertex bakes use), or the triangle's
// face normal where they cancel. Other texel points are free points of the mesh (no welded
// vertex, `welded` = −1): the integrators decide the point's own triangle and its neighbours
// exactly in the ε-limit p + εn (bake/visibility/raycast.h
// NearTriangles, bake/visibility/contour.h), as for a scene's receiver-only vertices.
//
// Rows: the covered texels in index order (row-major), so the rows — and with them every
// per-row randomisation — depend on the mesh, the UV set and W × H only.
//
// Charts: triangles joined across an edge whose two welded corners (Topology) carry the same UVs,
// bit for bit, in both triangles are one chart (a UV seam, or a hard edge with its UVs cut,
// separates charts). A texel belongs to its sample's triangle's chart: a lightmap fills and pads
// a texel only from texels of its own chart (bake/bake/lightmap.h), so colours never bleed
// across a seam inside the atlas.
#pragma once

#include <bake/mesh/mesh.h>
#include <bake/mesh/receivers.h>

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

namespace prt::bake {

struct TexelSample {
  uint32_t texel = 0;            // y·W + x
  uint32_t triangle = 0;         // the triangle the sample lies on
  Eigen::Vector3d barycentric;   // of the sample in that triangle (sums to 1, each >= 0)
  bool centre = true;            // the texel centre (else the nearest point of a covering triangle)
  uint32_t chart = 0;            // of its triangle (file comment), numbered in triangle order from 0
};

struct TexelAtlas {
  uint32_t width = 0, height = 0;
  std::string uv_set;                // the UvSet's name
  std::vector<TexelSample> samples;  // one per covered texel, in texel order: row i of the bake
  ReceiverSet receivers;             // samples' shade points (rows_noun "texels")
  std::vector<uint8_t> coverage;     // width·height: 1 where a texel is covered
  size_t texels_off_centre() const;  // samples that are not their texel's centre
  uint32_t charts = 0;               // of the UV set's triangles with area in the atlas
  std::vector<uint32_t> triangle_chart;  // per triangle of the mesh (file comment)
  // Checks of the UV set at this resolution: texels that triangles of two charts touch (too
  // little gutter: a texel's value is then one chart's, and bilinear filtering bleeds the other's
  // in), and texels whose centre lies inside triangles of two charts (overlapping charts: a
  // lightmap set must have none; a texture set that mirrors or reuses parts has them).
  size_t shared_texels = 0, overlapping_texels = 0;
  // Samples whose surface point cannot be put exactly on its triangle (texels.cpp exact_point_on:
  // corners whose coordinates differ in scale by more than 2^29, such as 4e-17 beside 0.04, leave
  // no double on an edge but its ends). Such a point, rounded, could lie behind its own triangle
  // and see it from behind; it is LIFTED instead: moved by at most 4 roundings per coordinate to
  // the nearest double strictly in front of every triangle it was meant to lie on (its own, and
  // on an edge that edge's others), decided by exact orientation (texels.cpp lift_in_front).
  // inexact_samples counts those for which no such double is near (a sliver crease): they keep
  // the interpolation's rounding and may see their triangle from behind.
  size_t lifted_samples = 0;
  size_t inexact_samples = 0;
};

// The atlas of `uv` (one of mesh.uv_sets; 3 UVs per triangle) at width × height texels (each
// 1..16384; InputError(mesh.source, ...) otherwise, and for a set whose size does not match the
// triangles or holds a non-finite UV). `name` names the receiver set in logs.
TexelAtlas texel_atlas(const Mesh& mesh, const Topology& topology, const UvSet& uv, uint32_t width, uint32_t height,
                       std::string name);

} // namespace prt::bake
