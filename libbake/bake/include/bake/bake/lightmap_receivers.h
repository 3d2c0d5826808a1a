// bake/bake/lightmap_receivers.h — the texels of one mesh's lightmap as the bake's receivers (issue
// 30; docs/ARCHITECTURE.md §4, "receivers"): the UV set to bake in (the asset's, or one generated
// by bake/mesh/unwrap.h), the atlas at the asked size (bake/mesh/texels.h), its checks, and which
// texels lie inside the geometry (bake/visibility/enclosure.h: left out of the bake and filled from
// their chart afterwards, bake/bake/lightmap.h). `prtbake texel` makes one for its mesh; a scene
// makes one per receiver object that asks for a lightmap (bake/bake/scene.h "lightmap").
//
// The UV set: generated when `unwrap` is set or the mesh has none (and `uv_set` names none);
// else the set `uv_set` names, else TEXCOORD_1 (glTF's lightmap set by convention), else the
// mesh's only set. The size: width × height, or — with `density` texels per unit instead — for a
// generated set the packer's smallest square (UnwrapOptions::density), for the asset's set the
// square whose texels have that density on average over the surface the set maps:
// N = density · sqrt(surface area / UV area) over the triangles with UV area, rounded up to a
// multiple of 4, at most kMaxLightmapSide.
//
// Refused with InputError(mesh.source, `who` + ...), naming the set: no such set, several sets
// and none named, a size beyond kMaxLightmapSide, a set that covers no texel (every triangle flat
// in UV space, or UVs outside [0, 1]), a set whose charts overlap (a texture set that mirrors or
// reuses parts), and a mesh every one of whose covered texels lies inside the geometry.
#pragma once

#include <bake/bake/lightmap.h>
#include <bake/mesh/mesh.h>
#include <bake/mesh/receivers.h>
#include <bake/mesh/texels.h>
#include <bake/mesh/unwrap.h>
#include <bake/visibility/raycast.h>

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace prt::bake {

inline constexpr uint32_t kMaxLightmapSide = 8192;

struct LightmapSpec {
  uint32_t width = 0, height = 0;  // the atlas in texels; 0: from `density`
  double density = 0;              // texels per unit, instead of width × height
  std::string uv_set;              // the asset's set to bake in ("": TEXCOORD_1, else the only one)
  bool unwrap = false;             // generate the set even when the mesh has one
  uint32_t gutter = 2;             // a generated set's empty texels between charts
  // A generated set's thin charts at least this many texels across (unwrap.h): 3 by default, which
  // took the engine's per-texel AO from NRMSE 0.042 to 0.011 at 1860² (bench/RESULTS.md).
  uint32_t min_chart_texels = 3;
  uint32_t padding = kDefaultPadding;  // the rings each chart is dilated into (bake/bake/lightmap.h)
  bool stitch = true;              // move the texels along UV seams until both sides agree
  bool given() const { return width > 0 || density > 0; }
};

struct LightmapReceivers {
  std::optional<UnwrapReport> generated;  // the generated set's report, when it was generated
  bool unwrap_asked = false;              // generated because LightmapSpec::unwrap (else: the mesh had none)
  UvSet uv;                               // the set baked in
  TexelAtlas atlas;
  std::vector<uint8_t> invalid;  // per atlas sample: inside the geometry
  std::vector<size_t> valid;     // the other samples, in order: the bake's rows
  ReceiverSet receivers() const; // the valid samples' shade points (atlas.receivers' name and noun)
  // The lightmap of the valid samples' rows ([valid][channels]): placed, the invalid texels
  // filled, the charts padded `padding` rings (make_lightmap).
  Lightmap image(std::span<const double> valid_rows, size_t channels, uint32_t padding) const;
};

// `rays`: the occluders the enclosure test sees (the mesh's own, or a scene's union). The atlas's
// shade points are the mesh's (bake/mesh/texels.h); `rebase`, when given, is called on each
// (with its sample) before the test, to make it a point of those occluders (in a scene, a corner
// texel's point is its vertex's in the union: bake/bake/scene_bake.h). `name` names the receiver
// set in logs; `who` prefixes messages ("" for a lone mesh, "object 'x': " in a scene).
using TexelRebase = std::function<void(const TexelSample&, ShadePoint&)>;
LightmapReceivers lightmap_receivers(const Mesh& mesh, const Topology& topology, const LightmapSpec& spec,
                                     const RayCaster& rays, std::string name, const std::string& who = "",
                                     const TexelRebase& rebase = {});

} // namespace prt::bake
