// bake/visibility/enclosure.h — whether a shade point lies inside the geometry (issue 30: a floor
// texel under a box standing on it, a floor texel under a wall's thickness, a wall texel behind a
// coincident panel). Such a point's values would leak dark into a lightmap; the lightmap marks it
// invalid and fills it from its chart's valid neighbours (bake/bake/lightmap.h).
//
// The rule: the ray from the point's limit p + εn crosses an ODD number of triangles
// (RayCaster::count_crossings: its depth complexity W, decided exactly near p) in EVERY one of 25
// fixed directions over the point's hemisphere (the normal, and rings of 8 at 30°, 60° and 80°
// from it). Inside a closed solid every ray leaves it once more than it enters; a point under an
// open sheet (a canopy, a table top) sees an even count, 0, in some direction and stays valid
// unless the sheet reaches past the 80° rays (more than 5.7 times its height beyond the point on
// every side). A direction that grazes an edge (CrossingCount::ambiguous) is skipped; a point
// with fewer than kEnclosureDirections decided directions stays valid.
#pragma once

#include <bake/mesh/shade_point.h>
#include <bake/visibility/raycast.h>

namespace prt::bake {

inline constexpr int kEnclosureDirections = 9;

bool enclosed(const ShadePoint& point, const RayCaster& rays);

} // namespace prt::bake
