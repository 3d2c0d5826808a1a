#include "area.h"

#include "read_file.h"

#include <view/lightmap.h>
#include <view/raster.h>

#include <bake/core/error.h>
#include <formats/names.h>
#include <formats/prtfile.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

namespace prt::prtview {

namespace F = prt::formats;
namespace N = prt::formats::names;
using bake::InputError;

namespace {

bake::LightShape shape_of(const F::Light& l, const std::string& file) {
  for (const auto s : {bake::LightShape::Polygon, bake::LightShape::Quad, bake::LightShape::Disc, bake::LightShape::Box,
                       bake::LightShape::Cylinder, bake::LightShape::Sphere})
    if (l.shape == bake::light_shape_name(s)) return s;
  throw InputError(file, std::string(N::kLights) + "/" + l.name + ": unknown shape '" + l.shape + "'");
}

} // namespace

std::vector<bake::AreaLight> read_area_lights(const F::Asset& f, const std::string& file) {
  if (f.lights.empty()) throw InputError(file, "has no area lights (" + std::string(N::kLights) + "): nothing for --shade area to draw");
  std::vector<bake::AreaLight> out;
  for (const F::Light& l : f.lights) {  // the schema check has bounded the indices and sizes
    if (N::is_punctual_shape(l.shape)) continue;  // no geometry: drawn from their baked E only
    bake::AreaLight a;
    a.name = l.name;
    a.shape = shape_of(l, file);
    a.radiance = l.radiance;
    a.two_sided = l.two_sided.value_or(0) != 0;
    for (size_t i = 0; i + 2 < l.vertices.values.size(); i += 3)
      a.vertices.emplace_back(l.vertices.values[i], l.vertices.values[i + 1], l.vertices.values[i + 2]);
    size_t at = 0;
    for (const uint32_t n : l.face_sizes.values) {
      a.faces.emplace_back(l.face_indices.values.begin() + std::ptrdiff_t(at), l.face_indices.values.begin() + std::ptrdiff_t(at + n));
      at += n;
    }
    bake::validate_light(a, file, std::string(N::kLights) + "/" + l.name);
    out.push_back(std::move(a));
  }
  return out;
}

std::vector<bake::PunctualLight> read_punctual_lights(const F::Asset& f) {
  std::vector<bake::PunctualLight> out;
  for (const F::Light& l : f.lights) {  // the schema check has checked their attributes
    if (!N::is_punctual_shape(l.shape)) continue;
    bake::PunctualLight p;
    p.name = l.name;
    p.kind = l.shape == "point" ? bake::PunctualKind::Point : l.shape == "spot" ? bake::PunctualKind::Spot : bake::PunctualKind::Directional;
    if (l.position) p.position = Eigen::Vector3d((*l.position)[0], (*l.position)[1], (*l.position)[2]);
    if (l.direction) p.direction = Eigen::Vector3d((*l.direction)[0], (*l.direction)[1], (*l.direction)[2]).normalized();
    p.intensity = l.radiance;
    p.inner_cone = l.inner_cone_angle.value_or(0);
    p.outer_cone = l.outer_cone_angle.value_or(p.outer_cone);
    p.range = l.range.value_or(0);
    out.push_back(std::move(p));
  }
  return out;
}

view::Image render_area_file(const F::Asset& f, const std::string& file, const std::vector<bake::AreaLight>& lights, bool exact,
                             const view::Camera& cam, RenderScene& scene, view::AreaRenderOptions& options) {
  std::vector<SceneObject> objects = read_scene_objects(f, file, nullptr);
  std::stable_partition(objects.begin(), objects.end(), [](const SceneObject& o) { return o.receiver; });
  std::vector<bake::Mesh> parts;
  std::vector<float> rgb;
  std::vector<uint8_t> per_pixel;
  size_t baked = 0;
  // Objects baked per texel: E per light in their lightmap, sampled per pixel through their UVs.
  struct TexelE {
    size_t object = 0;  // index in `objects`
    const F::VertexSet* set = nullptr;
    std::vector<const F::Light*> column;
  };
  std::vector<TexelE> texel_objects;
  // Column l of E is the light named on line l of its `lights` attribute: an area light or a
  // punctual one (its `radiance` is its intensity: E scales the same way).
  auto columns = [&](const SceneObject& o, const F::Product& e, std::string_view path) {
    std::vector<const F::Light*> column;
    for (const std::string& n : F::split_light_list(e.lights.value_or(""))) {
      const auto it = std::find_if(f.lights.begin(), f.lights.end(), [&](const F::Light& l) { return l.name == n; });
      if (it == f.lights.end())
        throw InputError(file, "object '" + o.name + "': " + std::string(path).substr(1) + " names light '" + n + "', which " +
                                   std::string(N::kLights) + " does not hold");
      column.push_back(&*it);
    }
    return column;
  };
  for (size_t k = 0; k < objects.size(); ++k) {
    const SceneObject& o = objects[k];
    const size_t V = o.mesh.positions.size(), T = o.mesh.triangles.size();
    const F::SceneObject* fo = f.find_object(o.name);
    const F::Product* e = fo && fo->set.area_irradiance ? &*fo->set.area_irradiance : nullptr;
    if (!e && fo && fo->set.lightmap && fo->set.lightmap->area_irradiance && fo->set.uv && !exact) {
      texel_objects.push_back({k, &fo->set, columns(o, *fo->set.lightmap->area_irradiance, N::kLightmapAreaIrradiance)});
      rgb.insert(rgb.end(), 3 * V, 0.0f);
      per_pixel.insert(per_pixel.end(), T, 2);
      ++baked;
      add_object(scene, o);
      parts.push_back(o.mesh);
      continue;
    }
    if (e) {
      const std::vector<const F::Light*> column = columns(o, *e, N::kAreaIrradiance);
      const size_t L = column.size();
      for (size_t v = 0; v < V; ++v) {
        float value[3];
        for (size_t c = 0; c < 3; ++c) {
          double sum = 0;
          for (size_t l = 0; l < L; ++l) sum += column[l]->radiance[c] * double(e->values[v * L + l]);
          value[c] = float(double(o.albedo[c]) * sum * std::numbers::inv_pi);
        }
        scene.baked_luminance.push_back(float(0.2126 * value[0] + 0.7152 * value[1] + 0.0722 * value[2]));
        if (!exact) rgb.insert(rgb.end(), value, value + 3);
      }
    }
    if (e && !exact) {
      per_pixel.insert(per_pixel.end(), T, 0);
      ++baked;
    } else {
      rgb.insert(rgb.end(), 3 * V, 0.0f);
      per_pixel.insert(per_pixel.end(), T, 1);
    }
    add_object(scene, o);
    parts.push_back(o.mesh);
  }
  if (!exact && baked == 0)
    throw InputError(file, "holds no " + std::string(N::kAreaIrradiance) + " for any object: use --shade area-exact");
  scene.mesh = bake::merge_meshes(parts, "scene");
  const bool bounced = !exact && std::any_of(objects.begin(), objects.end(), [](const SceneObject& o) { return o.area_bounced; });
  scene.what = "scene: " + std::to_string(objects.size()) + " objects, " + std::to_string(lights.size()) + " area light(s), " +
               (bounced ? "their direct light and its bounces (baked)" : "their direct light only");
  scene.how = exact ? "per pixel: exact soft shadows of the stored lights (render_area_analytic), times the albedo / pi"
                    : "baked E per light x its stored radiance x albedo / pi per vertex, interpolated, or per texel through "
                      "the object's lightmap (" + std::to_string(baked) + " objects); objects without it per pixel, exactly";
  options.casts_shadow = scene.casts_shadow;
  options.punctual = read_punctual_lights(f);
  options.triangle_albedo = scene.albedo;
  if (options.ggx) {
    options.ggx->eye -= scene.mesh.origin;
    char buf[96];
    std::snprintf(buf, sizeof buf, " + GGX alpha %.3g, F0 %.3g through LTC", options.ggx->alpha, options.ggx->f0[0]);
    scene.how += buf;
  }

  const view::GBuffer g = view::rasterize(scene.mesh, cam);
  const bool any_per_pixel = std::find(per_pixel.begin(), per_pixel.end(), 1) != per_pixel.end();
  // Per pixel, exactly: the area lights' closed forms and the punctual lights' shadow rays
  // (AreaRenderOptions::punctual, read from the file's /lights above).
  view::Image analytic;
  if (exact || any_per_pixel) analytic = view::render_area_analytic(scene.mesh, g, lights, options);
  if (exact) return analytic;
  view::Image img = view::interpolate_vertices(scene.mesh, g, rgb);
  for (size_t i = 0; i < g.triangle.size(); ++i)
    if (g.triangle[i] >= 0 && per_pixel[size_t(g.triangle[i])] == 1) {
      if (analytic.rgb.empty()) std::fill_n(img.rgb.begin() + std::ptrdiff_t(3 * i), 3, 0.0f);
      else std::copy_n(analytic.rgb.begin() + std::ptrdiff_t(3 * i), 3, img.rgb.begin() + std::ptrdiff_t(3 * i));
    }
  // Per texel: E per light sampled bilinearly through the object's mesh/uv (view/lightmap.h),
  // times each light's radiance and the albedo / pi; one pass over the pixels.
  if (texel_objects.empty()) return img;
  std::vector<const TexelE*> texel_of(objects.size(), nullptr);
  std::vector<view::LightmapImage> maps;
  for (const TexelE& t : texel_objects) {
    texel_of[t.object] = &t;
    const F::Lightmap& m = *t.set->lightmap;
    maps.push_back({int(m.width), int(m.height), t.column.size(), m.area_irradiance->values, m.state.values});
  }
  std::vector<float> sample;
  for (int y = 0; y < g.height; ++y)
    for (int x = 0; x < g.width; ++x) {
      const int32_t tri = g.triangle[size_t(y) * size_t(g.width) + size_t(x)];
      if (tri < 0 || per_pixel[size_t(tri)] != 2) continue;
      const size_t k = size_t(std::upper_bound(scene.first_triangle.begin(), scene.first_triangle.end(), size_t(tri)) -
                              scene.first_triangle.begin()) - 1;
      const TexelE& t = *texel_of[k];
      const view::Fragment fr = view::make_fragment(scene.mesh, g, x, y);
      const Eigen::Vector2d uv = view::fragment_uv(fr, t.set->uv->values, size_t(tri) - scene.first_triangle[k]);
      sample.resize(t.column.size());
      view::sample_lightmap(maps[size_t(&t - texel_objects.data())], uv.x(), uv.y(), sample.data());
      float* out = img.at(x, y);
      for (size_t c = 0; c < 3; ++c) {
        double sum = 0;
        for (size_t l = 0; l < t.column.size(); ++l) sum += t.column[l]->radiance[c] * double(sample[l]);
        out[c] = float(double(objects[k].albedo[c]) * sum * std::numbers::inv_pi);
      }
    }
  return img;
}

} // namespace prt::prtview
