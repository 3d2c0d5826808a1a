// prtview/area.h — scene files with area lights (issue 13, paper 003): what prtview draws for
// --shade area and --shade area-exact, and the reference it compares with. Only the area lights'
// direct light is drawn (no environment): each object's albedo / π times Σ_l radiance_l E_l.
//   area        the runtime picture from the baked file: per receiver vertex, the baked
//               area_lights/irradiance (E_l at unit radiance, in the dataset's column order) times
//               the light's radiance as stored in /lights/<name> (a runtime may dim or recolour
//               it there), interpolated across triangles;
//   area-exact  per pixel, the analytic render (view/area_lights.h render_area_analytic: exact
//               soft shadows at every pixel, paper 003's own use) from the stored lights.
// Objects without baked area lighting (occluder-only ones) are drawn per pixel by the analytic
// render in both modes. Shadows come from the objects that cast them in the bake (roles
// "occluder" and "both"). The reference (render_area_reference) samples the lights with Embree
// shadow rays over the same casters. docs/ARCHITECTURE.md §2 (view), §5 (the file).
#pragma once

#include "scenes.h"

#include <view/area_lights.h>
#include <view/camera.h>
#include <view/image.h>

#include <bake/lights/lights.h>
#include <bake/lights/punctual.h>
#include <formats/asset.h>

#include <string>
#include <vector>

namespace prt::prtview {

// The file's /lights as the bake saw them (world space), sorted by name; an InputError naming the
// file when it has none or one is malformed.
std::vector<bake::AreaLight> read_area_lights(const formats::Asset& f, const std::string& file);
// The file's punctual lights (/lights/<name> of shape point, spot, directional), for the per-pixel
// renders (view::AreaRenderOptions::punctual).
std::vector<bake::PunctualLight> read_punctual_lights(const formats::Asset& f);

// Fills `scene` (mesh, receivers, casters, albedo, objects) and returns the runtime picture.
// `exact`: area-exact (above), else area. `options` gets the casters and albedos for the reference;
// a GGX layer already in it (--ggx: area-exact only) has its eye in world space and is moved into
// the scene mesh's frame here.
view::Image render_area_file(const formats::Asset& f, const std::string& file, const std::vector<bake::AreaLight>& lights,
                             bool exact, const view::Camera& cam, RenderScene& scene, view::AreaRenderOptions& options);

} // namespace prt::prtview
