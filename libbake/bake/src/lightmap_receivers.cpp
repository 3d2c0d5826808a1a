// bake/bake/lightmap_receivers.h — the texels of a mesh's lightmap as receivers.
#include <bake/bake/lightmap_receivers.h>
#include <bake/core/error.h>
#include <bake/visibility/enclosure.h>

#include <tbb/parallel_for.h>

#include <cmath>
#include <utility>

namespace prt::bake {
namespace {

// The asset's set to bake in (file comment).
const UvSet& asset_uvs(const Mesh& mesh, const std::string& wanted, const std::string& who) {
  std::string names;
  for (const UvSet& s : mesh.uv_sets) names += (names.empty() ? "" : ", ") + s.name;
  if (!wanted.empty()) {
    for (const UvSet& s : mesh.uv_sets)
      if (s.name == wanted) return s;
    throw InputError(mesh.source, who + "has no UV set '" + wanted + "'" +
                                      (names.empty() ? std::string(" (it has none)") : " (it has " + names + ")"));
  }
  for (const UvSet& s : mesh.uv_sets)
    if (s.name == "TEXCOORD_1") return s;
  if (mesh.uv_sets.size() == 1) return mesh.uv_sets.front();
  throw InputError(mesh.source, who + "has several UV sets (" + names +
                                    ") and no TEXCOORD_1: name the lightmap's (prtbake texel --uv; \"uv\" in a scene's "
                                    "lightmap)");
}

// The side for `density` over the surface `uv` maps (file comment).
uint32_t side_for_density(const Mesh& mesh, const UvSet& uv, double density, const std::string& who) {
  double surface = 0, uv_area = 0;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const Eigen::Vector2d p = uv.corners[3 * t].cast<double>(), q = uv.corners[3 * t + 1].cast<double>() - p,
                          r = uv.corners[3 * t + 2].cast<double>() - p;
    const double mapped = std::abs(q.x() * r.y() - q.y() * r.x()) / 2;
    if (mapped == 0) continue;
    uv_area += mapped;
    const Eigen::Vector3d a = mesh.positions[tri[0]].cast<double>();
    surface += (mesh.positions[tri[1]].cast<double>() - a).cross(mesh.positions[tri[2]].cast<double>() - a).norm() / 2;
  }
  if (!(uv_area > 0)) return 4;  // covers no texel at any size: said below
  const double side = std::ceil(density * std::sqrt(surface / uv_area) / 4) * 4;
  if (!(side <= kMaxLightmapSide))
    throw InputError(mesh.source, who + "at " + std::to_string(density) + " texels per unit its UV set " + uv.name +
                                      " needs a lightmap of " + std::to_string(side) + " texels a side; the most is " +
                                      std::to_string(kMaxLightmapSide));
  return std::max<uint32_t>(4, uint32_t(side));
}

} // namespace

ReceiverSet LightmapReceivers::receivers() const {
  ReceiverSet set;
  set.name = atlas.receivers.name;
  set.tag = atlas.receivers.tag;
  set.rows_noun = atlas.receivers.rows_noun;
  set.points.reserve(valid.size());
  for (size_t i : valid) set.points.push_back(atlas.receivers.points[i]);
  return set;
}

Lightmap LightmapReceivers::image(std::span<const double> valid_rows, size_t channels, uint32_t padding) const {
  PRT_CHECK_OP(valid_rows.size(), ==, valid.size() * channels);
  std::vector<double> rows(atlas.samples.size() * channels, 0.0);  // the invalid texels' rows: filled
  for (size_t r = 0; r < valid.size(); ++r)
    std::copy_n(valid_rows.begin() + std::ptrdiff_t(r * channels), channels,
                rows.begin() + std::ptrdiff_t(valid[r] * channels));
  return make_lightmap(atlas, rows, channels, invalid, padding);
}

LightmapReceivers lightmap_receivers(const Mesh& mesh, const Topology& topology, const LightmapSpec& spec,
                                     const RayCaster& rays, std::string name, const std::string& who,
                                     const TexelRebase& rebase) {
  PRT_CHECK(spec.given());
  LightmapReceivers out;
  uint32_t width = spec.width, height = spec.height ? spec.height : spec.width;
  if (spec.unwrap || (mesh.uv_sets.empty() && spec.uv_set.empty())) {
    UnwrapOptions o;
    o.width = width;
    o.height = width ? height : 0;
    o.density = width == 0 ? spec.density : 0;
    o.gutter = spec.gutter;
    o.min_chart_texels = spec.min_chart_texels;
    o.max_side = kMaxLightmapSide;
    Unwrapped generated = unwrap(mesh, topology, o);
    out.uv = std::move(generated.uv);
    out.generated = generated.report;
    out.unwrap_asked = spec.unwrap;
    width = generated.report.width;
    height = generated.report.height;
  } else {
    out.uv = asset_uvs(mesh, spec.uv_set, who);
  }
  const UvSet& uv = out.uv;
  if (width == 0) width = height = side_for_density(mesh, uv, spec.density, who);
  out.atlas = texel_atlas(mesh, topology, uv, width, height, std::move(name));
  const TexelAtlas& atlas = out.atlas;
  if (atlas.samples.empty()) {
    // Why: every triangle flat in UV space (a set of one repeated vt, as wuson.obj's), or UVs
    // outside the atlas.
    size_t flat = 0;
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
      const Eigen::Vector2f &p = uv.corners[3 * t], &q = uv.corners[3 * t + 1], &r = uv.corners[3 * t + 2];
      flat += (q - p).x() * (r - p).y() - (q - p).y() * (r - p).x() == 0;
    }
    throw InputError(mesh.source, who + "its UV set " + uv.name + " covers no texel of the " + std::to_string(width) +
                                      "x" + std::to_string(height) + " lightmap: " +
                                      (flat == mesh.triangles.size()
                                           ? "every triangle has zero area in it (not a lightmap UV set)"
                                           : "its UVs lie outside [0, 1]"));
  }
  if (atlas.overlapping_texels > 0)
    throw InputError(mesh.source, who + "its UV set " + uv.name + " overlaps itself: " +
                                      std::to_string(atlas.overlapping_texels) +
                                      " texels lie inside triangles of two charts (a texture set that mirrors or "
                                      "reuses parts is no lightmap set); bake in generated lightmap UVs instead "
                                      "(prtbake texel --unwrap; \"unwrap\": true in a scene's lightmap)");
  if (rebase)
    for (size_t i = 0; i < atlas.samples.size(); ++i) rebase(atlas.samples[i], out.atlas.receivers.points[i]);
  // Texels inside the geometry: left out of the bake, filled from their chart afterwards.
  out.invalid.assign(atlas.samples.size(), 0);
  tbb::parallel_for(size_t(0), atlas.samples.size(),
                    [&](size_t i) { out.invalid[i] = enclosed(atlas.receivers.points[i], rays); });
  for (size_t i = 0; i < out.invalid.size(); ++i)
    if (!out.invalid[i]) out.valid.push_back(i);
  if (out.valid.empty())
    throw InputError(mesh.source, who + "every texel its UV set " + uv.name + " covers lies inside the geometry: " +
                                      (who.empty() ? std::string("nothing to bake (are its normals pointing inside? see "
                                                                 "--flip-normals)")
                                                   : std::string("nothing to bake per texel (is it inside another object, "
                                                                 "or are its normals pointing inside?): bake it per "
                                                                 "vertex (\"lightmap\": false) or leave it out")));
  return out;
}

} // namespace prt::bake
