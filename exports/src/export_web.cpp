// export_web.cpp — the web viewer's folder (contract: exports/export.h export_web; the page:
// viewer/viewer.js). The viewer's files come from the build (web_assets.h), the glb from
// export_gltf, viewer.json from here: the file's metadata and the environments' SH per degree of
// rotation, turned by prtshade's sh::Rotation so that the page does no SH algebra of its own.
#include "export_common.h"
#include "web_assets.h"

#include <prtshade/conventions.h>
#include <prtshade/sh.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>

namespace prt::exports {

const char* web_viewer_missing() noexcept { return detail::web_assets_missing(); }

namespace detail {
namespace {

using nlohmann::json;

// x rounded to 9 significant digits (a float's worth, with room), as a double whose shortest
// decimal form is at most 9 digits: viewer.json stays small and its bytes deterministic.
double round9(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", x);
  return std::strtod(buf, nullptr);
}

// The clamped-cosine convolution factor of band l (Ramamoorthi & Hanrahan 2001, eq. 8): π, 2π/3,
// then 0 for odd l and 2π (−1)^(l/2−1) / ((l+2)(l−1)) · l! / (2^l (l/2)!²) for even l. Bands 0–2
// are prtshade's clamped_cosine_band (which stops at order 3); the higher even bands let the
// unshadowed view run at the transfer's own order.
double clamped_cosine(int l) {
  if (l <= 2) return conventions::clamped_cosine_band(l);
  if (l % 2) return 0.0;
  double ratio = 1;  // l! / (2^l ((l/2)!)²), built as Π_{k=1}^{l/2} (2k−1)/(2k)
  for (int k = 1; k <= l / 2; ++k) ratio *= double(2 * k - 1) / double(2 * k);
  const double sign = (l / 2 - 1) % 2 ? -1.0 : 1.0;
  return 2 * std::numbers::pi * sign / double((l + 2) * (l - 1)) * ratio;
}

// 1 / the largest luminance of the order-3 unshadowed irradiance / π over 4,096 spherical
// Fibonacci normals, to 4 significant digits (view/exposure.h's rule on the band-limited sky).
double sh_exposure(const WebEnvironment& e) {
  constexpr int kNormals = 4096;
  double best = 0;
  std::vector<double> y(9);
  for (int k = 0; k < kNormals; ++k) {
    const double z = 1 - (2 * k + 1) / double(kNormals), r = std::sqrt(std::max(0.0, 1 - z * z));
    const double phi = k * std::numbers::pi * (3 - std::sqrt(5.0));
    sh::eval(3, r * std::cos(phi), r * std::sin(phi), z, y);
    double rgb[3] = {0, 0, 0};
    for (int i = 0; i < 9 && i < e.order * e.order; ++i) {
      const int l = i >= 4 ? 2 : i >= 1 ? 1 : 0;
      for (int c = 0; c < 3; ++c) rgb[c] += clamped_cosine(l) * y[size_t(i)] * e.radiance[size_t(i) * 3 + size_t(c)];
    }
    best = std::max(best, (0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]) / std::numbers::pi);
  }
  if (!(best > 0)) return 1.0;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", 1 / best);
  return std::strtod(buf, nullptr);
}

// The environment's radiance SH turned about +Y by each whole degree, [degree][c·order² + i].
json turned_sh(const WebEnvironment& e) {
  const size_t n = size_t(e.order) * size_t(e.order);
  std::vector<double> in(n), out(n);
  json by_degree = json::array();
  for (int d = 0; d < 360; ++d) {
    const double a = d * std::numbers::pi / 180, c = std::cos(a), s = std::sin(a);
    const double R[3][3] = {{c, 0, s}, {0, 1, 0}, {-s, 0, c}};
    const sh::Rotation rotation(R, e.order);
    json row = json::array();
    for (size_t ch = 0; ch < 3; ++ch) {
      for (size_t i = 0; i < n; ++i) in[i] = e.radiance[i * 3 + ch];
      rotation.apply(in, out);
      for (size_t i = 0; i < n; ++i) row.push_back(round9(out[i]));
    }
    by_degree.push_back(std::move(row));
  }
  return by_degree;
}

json product_json(const ProductRef& p) {
  json j{{"dataset", p.dataset}};
  const Product& q = *p.product;
  auto put = [&](const char* key, const auto& v) {
    if (v) j[key] = *v;
  };
  put("integrand", q.integrand);
  put("sh_order", q.sh_order);
  put("integrator", q.integrator);
  put("samples", q.samples);
  put("seed", q.seed);
  put("environment", q.environment);
  put("environment_sha256", q.environment_sha256);
  return j;
}

// The albedo the pictures multiply by (prtview's rule): a scene object's when any channel is > 0,
// the root's when its transfer or band-1 radiance carries bounces (light reflected at that
// albedo), else white.
std::array<double, 3> albedo_of(const Asset& asset, const SetRef& ref) {
  std::optional<std::vector<double>> a;
  for (const SceneObject& o : asset.objects)
    if (&o.set == ref.set) a = o.albedo;
  for (const std::optional<Product>* p : {&ref.set->transfer_diffuse, &ref.set->radiance_band1})
    if (ref.prefix.empty() && *p && (*p)->bounces.value_or(0) > 0) a = (*p)->albedo;
  if (!a || a->size() != 3 || std::none_of(a->begin(), a->end(), [](double v) { return v > 0; })) return {1, 1, 1};
  return {std::max(0.0, (*a)[0]), std::max(0.0, (*a)[1]), std::max(0.0, (*a)[2])};
}

json metadata(const Asset& asset, const std::filesystem::path& source) {
  const formats::RootInfo& r = asset.root;
  json file{{"file", source.filename().string()}, {"source", r.source},         {"source_sha256", r.source_sha256},
            {"generator", r.generator},           {"created", r.created},       {"command_line", r.command_line},
            {"up_axis", r.up_axis},               {"sh_convention", r.sh_convention}};
  json sets = json::array();
  for (const SetRef& ref : vertex_sets(asset)) {
    json set{{"name", ref.name}, {"vertices", ref.set->vertex_count()}, {"albedo", albedo_of(asset, ref)}};
    for (const SceneObject& o : asset.objects)  // glossy objects: the lobe's exponent and colour
      if (&o.set == ref.set && o.phong_exponent && *o.phong_exponent > 0) {
        set["phong_exponent"] = *o.phong_exponent;
        if (o.specular) set["specular"] = *o.specular;
      }
    if (ref.set->triangles) set["triangles"] = ref.set->triangles->values.size() / 3;
    json products = json::array();
    for (const ProductRef& p : detail::products(*ref.set)) products.push_back(product_json(p));
    set["products"] = std::move(products);
    json report = json::array();
    for (const formats::ReportRow& row : ref.set->report.rows) {
      json jr{{"product", row.product}, {"rmse", round9(row.values[0])}, {"max_abs", round9(row.values[1])},
              {"reference_rms", round9(row.values[2])}};
      if (row.points) jr["points"] = *row.points;
      if (row.reference) jr["reference"] = *row.reference;
      if (row.bake_seconds) jr["bake_seconds"] = round9(*row.bake_seconds);
      report.push_back(std::move(jr));
    }
    if (!report.empty()) set["error_report"] = std::move(report);
    sets.push_back(std::move(set));
  }
  file["vertex_sets"] = std::move(sets);
  return file;
}

void check_shadeable(const Asset& asset, const std::filesystem::path& source) {
  bool mesh = false, product = false;
  for (const SetRef& ref : vertex_sets(asset)) {
    const VertexSet& s = *ref.set;
    if (!s.triangles || !s.normals) continue;
    mesh = true;
    product = product || s.ao || s.transfer_diffuse || s.radiance_band1 || s.area_irradiance;
    if (const auto& m = s.lightmap; m && s.uv) product = product || m->ao || m->transfer_diffuse || m->radiance_band1;
  }
  if (!mesh) throw FormatError(source.string(), "has no vertex set with triangles and normals: the viewer has nothing to draw");
  if (!product)
    throw FormatError(source.string(),
                      "has none of /ao, /transfer/diffuse, /radiance/band1, /area_lights/irradiance in a vertex set "
                      "or its lightmap: nothing the viewer shades");
}

} // namespace
} // namespace detail

std::vector<std::filesystem::path> export_web(const formats::Asset& asset, const std::filesystem::path& source,
                                              const std::filesystem::path& out, const std::vector<WebEnvironment>& environments) {
  using detail::FormatError;
  if (const char* why = web_viewer_missing()) throw FormatError(out.string(), std::string("this prtbake has no web viewer: ") + why);
  detail::check_shadeable(asset, source);
  for (const WebEnvironment& e : environments)
    if (e.order < 1 || e.radiance.size() != size_t(e.order) * size_t(e.order) * 3)
      throw std::invalid_argument("export_web: environment '" + e.name + "' has " + std::to_string(e.radiance.size()) +
                                  " SH values for order " + std::to_string(e.order));
  std::error_code ec;
  const std::filesystem::path dir = out.filename().empty() ? out.parent_path() : out;
  if (std::filesystem::exists(dir, ec)) {
    const bool folder = std::filesystem::is_directory(dir, ec);
    const bool replaceable = folder && (std::filesystem::exists(dir / "viewer.json", ec) || std::filesystem::is_empty(dir, ec));
    if (!replaceable)
      throw FormatError(dir.string(), folder ? "exists and is not an earlier web export (no viewer.json in it): not replaced"
                                             : "exists and is not a folder: not replaced");
    std::filesystem::remove_all(dir, ec);
    if (ec) throw FormatError(dir.string(), "cannot replace the earlier web export: " + ec.message());
  }
  detail::Staging staging(dir);
  const std::filesystem::path staged = staging.stage(dir);
  if (!std::filesystem::create_directory(staged, ec))
    throw FormatError(dir.string(), "cannot create '" + staged.string() + "': " + ec.message());
  size_t count = 0;
  const detail::WebAsset* assets = detail::web_assets(count);
  for (size_t k = 0; k < count; ++k) {
    const std::filesystem::path path = staged / assets[k].path;
    std::filesystem::create_directories(path.parent_path(), ec);
    detail::write_bytes(path, std::string(assets[k].begin, size_t(assets[k].end - assets[k].begin)), dir);
  }
  detail::export_gltf(asset, staged / "asset.glb", true);

  nlohmann::json info{{"glb", "asset.glb"}, {"source", source.filename().string()}, {"file", detail::metadata(asset, source)}};
  int order = 0;
  nlohmann::json envs = nlohmann::json::array();
  for (const WebEnvironment& e : environments) {
    order = std::max(order, e.order);
    envs.push_back({{"name", e.name},
                    {"sha256", e.sha256},
                    {"baked", e.baked},
                    {"order", e.order},
                    {"exposure", detail::sh_exposure(e)},
                    {"sh_by_degree", detail::turned_sh(e)}});
  }
  info["sh_order"] = order;
  nlohmann::json cosine = nlohmann::json::array();
  for (int l = 0; l < std::max(order, 3); ++l) cosine.push_back(detail::clamped_cosine(l));
  info["clamped_cosine"] = std::move(cosine);
  info["environments"] = std::move(envs);
  nlohmann::json lights = nlohmann::json::array();
  for (const formats::Light& l : asset.lights) lights.push_back({{"name", l.name}, {"shape", l.shape}, {"radiance", l.radiance}});
  info["lights"] = std::move(lights);
  detail::write_bytes(staged / "viewer.json", info.dump() + "\n", dir);
  return staging.commit();
}

} // namespace prt::exports
