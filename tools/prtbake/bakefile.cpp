// bakefile.cpp — see bakefile.h.
#include "bakefile.h"

#include <bake/core/error.h>
#include <formats/names.h>

#include <cctype>
#include <cmath>
#include <span>
#include <string>

namespace prt::tool {
namespace {

// A product's report row is named after its dataset: "/report/ao" for "/ao" (SCHEMA.md).
std::string report_row_name(bake::Product product) {
  namespace N = prt::formats::names;
  std::string_view path;
  switch (product) {
  case bake::Product::Ao: path = N::kAo; break;
  case bake::Product::TransferDiffuse: path = N::kTransferDiffuse; break;
  case bake::Product::TransferVisibility: path = N::kTransferVisibility; break;
  case bake::Product::RadianceBand1: path = N::kRadianceBand1; break;
  case bake::Product::RadianceShadowed: path = N::kRadianceShadowed; break;
  }
  return std::string(path.substr(1));
}

// The visibility convention of every per-vertex product.
constexpr const char* kVisibilityLimit = "limit from just above the surface (p + eps*n, eps -> 0+)";

std::vector<float> to_float(std::span<const double> src, size_t stride, size_t offset, size_t count) {
  const size_t rows = stride ? src.size() / stride : 0;
  std::vector<float> out(rows * count);
  for (size_t r = 0; r < rows; ++r)
    for (size_t c = 0; c < count; ++c) out[r * count + c] = float(src[r * stride + offset + c]);
  return out;
}

// A report row's values and attributes; wall times only when not reproducible.
F::ReportRow report_row(std::string product, const std::array<float, 5>& values, std::string columns, size_t points,
                        const std::string& reference, double reference_seconds, double bake_seconds,
                        double integrals_per_second, bool reproducible) {
  F::ReportRow row;
  row.product = std::move(product);
  row.values = values;
  row.columns = std::move(columns);
  row.points = int64_t(points);
  row.reference = reference;
  if (!reproducible) {  // wall times differ run to run: kept out of reproducible files
    row.reference_seconds = reference_seconds;
    row.bake_seconds = bake_seconds;
    row.integrals_per_second = integrals_per_second;
  }
  return row;
}

} // namespace

std::string safe_name(const std::string& stem) {
  std::string name = stem;
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-' && c != '.') c = '_';
  return name.empty() ? std::string("occluder") : name;
}

void set_mesh(F::VertexSet& set, const bake::Mesh& mesh) {
  const size_t V = mesh.positions.size(), T = mesh.triangles.size();
  std::vector<double> pos(3 * V);  // world space: origin + offset in double (float32 on disk when exact)
  std::vector<float> nrm(3 * V);
  for (size_t i = 0; i < V; ++i)
    for (int k = 0; k < 3; ++k) {
      pos[3 * i + size_t(k)] = mesh.world_position(i)[k];
      nrm[3 * i + size_t(k)] = mesh.normals[i][k];
    }
  std::vector<uint32_t> tri(3 * T);
  for (size_t i = 0; i < T; ++i)
    for (int k = 0; k < 3; ++k) tri[3 * i + size_t(k)] = mesh.triangles[i][size_t(k)];
  set.positions = F::Array<double>{std::move(pos), {}};
  set.normals = F::Normals{std::move(nrm),
                           mesh.normal_source == bake::Mesh::NormalSource::File ? "file" : "angle-weighted", {}};
  set.triangles = F::Array<uint32_t>{std::move(tri), {}};
  set.source_position = F::Array<uint32_t>{mesh.source_position, {}};
}

void set_bounces(F::Product& product, Bounced which, int applied, const bake::BounceSpec& spec,
                 const std::vector<double>& albedo, double relative_std_error) {
  product.bounce_std_error = relative_std_error;
  product.bounces = applied;
  product.bounces_requested = spec.bounces;
  product.albedo = albedo;
  product.bounce_rays = int64_t(spec.rays);
  if (product.integrand)
    *product.integrand +=
        which == Bounced::Band1      ? " + bounces: R^{b+1}_c,m(p) = Int (1 - V) H (albedo/pi) E^b_c(hit) y_1m dw, b < bounces"
        : which == Bounced::Shadowed ? " + bounces: S^{b+1}_c,i(p) = Int (1 - V) H (albedo/pi) E^b_c(hit) y_i dw, b < bounces"
        : which == Bounced::AreaIrradiance
            ? " + bounces: E^{b+1}_l(p) = (1/pi) Int (1 - V) H albedo E^b_l(hit) (n.w) dw, b < bounces"
                                     : " + bounces: T^{b+1}_i(p) = (1/pi) Int (1 - V) H albedo T^b_i(hit) (n.w) dw, b < bounces";
}

F::OccluderSelfBand1 self_band1_of(const bake::VertexBake& self) {
  PRT_CHECK(self.layout.radiance_count == 9);
  return {to_float(self.values, self.layout.width, self.layout.radiance, 9),
          "R_c,m = Int L_c V_self H y_1m dw of the occluder alone (V_self: its own geometry), layout [vertex][RGB][m=-1,0,1]; "
          "E_c = (4 pi / 3) sum_m y_1m(n) R_c,m at /objects/<name>/mesh/normals",
          {}};
}

void set_products(F::VertexSet& set, const bake::VertexBake& bake, const ProductInfo& info) {
  const auto& L = bake.layout;
  const size_t W = L.width;
  auto product = [&](size_t offset, size_t count, std::string integrand) {
    F::Product p;
    p.values = to_float(bake.values, W, offset, count);
    p.integrand = std::move(integrand);
    p.integrator = info.integrator;
    p.integrator_description = info.integrator_description;
    p.samples = int64_t(info.samples);
    p.seed = int64_t(info.seed);
    p.visibility = kVisibilityLimit;
    return p;
  };
  if (L.ao_count) set.ao = product(L.ao, 1, "A = (1/pi) Int V H (n.w) dw");
  if (L.transfer_count) {
    set.transfer_diffuse = product(L.transfer, L.transfer_count, "T_i = (1/pi) Int V H (n.w) y_i dw");
    set.transfer_diffuse->sh_order = info.transfer_order;
  }
  if (L.visibility_count) {
    set.transfer_visibility = product(L.visibility, L.visibility_count, "U_i = Int V H y_i dw");
    set.transfer_visibility->sh_order = info.visibility_order;
  }
  auto environment = [&](F::Product& p) {
    const auto& i = info.env->info();
    p.environment = info.env_path;
    p.environment_sha256 = i.sha256;
    p.environment_layout = i.layout;
    p.negative_pixels_clamped = int64_t(i.negative_pixels_clamped);
  };
  if (L.radiance_count) {
    F::Product& p = set.radiance_band1.emplace(
        product(L.radiance, 9, "R_c,m = Int L_c V H y_1m dw, layout [" + info.rows + "][RGB][m=-1,0,1]"));
    p.shading = "E_c = (4 pi / 3) sum_m y_1m(n) R_c,m";
    environment(p);
  }
  if (L.shadowed_count) {
    F::Product& p = set.radiance_shadowed.emplace(
        product(L.shadowed, L.shadowed_count, "S_c,i = Int L_c V H y_i dw, layout [" + info.rows + "][RGB][i=l(l+1)+m]"));
    p.sh_order = L.shadowed_order;
    p.shading = "L_out = sum_l lambda_l sum_m S_c,lm y_lm(r), lambda_l = (s+1) Int_0^1 t^s P_l(t) dt (Phong s)";
    environment(p);
  }
}

void set_lightmap(F::VertexSet& set, const bake::Mesh& mesh, const bake::UvSet& uv, const bake::TexelAtlas& atlas,
                  const bake::Lightmap& image, const bake::ProductLayout& layout, const ProductInfo& info,
                  uint32_t padding) {
  F::Uvs& u = set.uv.emplace();
  u.uv_set = uv.name;
  for (const Eigen::Vector2f& c : uv.corners) u.values.insert(u.values.end(), {c.x(), c.y()});
  F::Lightmap& m = set.lightmap.emplace();
  m.width = image.width;
  m.height = image.height;
  m.state.values = image.state;
  m.padding = int64_t(padding);
  const size_t texels = size_t(image.width) * image.height;
  F::Array<double>& positions = m.positions.emplace();
  F::Array<float>& normals = m.normals.emplace();
  positions.values.assign(3 * texels, 0.0);
  normals.values.assign(3 * texels, 0.0f);
  for (size_t i = 0; i < atlas.samples.size(); ++i) {
    const size_t k = atlas.samples[i].texel;
    const bake::ShadePoint& p = atlas.receivers.points[i];
    const Eigen::Vector3d world = bake::add_origin(mesh.origin, p.p);
    for (int c = 0; c < 3; ++c) {
      positions.values[3 * k + size_t(c)] = world[c];
      normals.values[3 * k + size_t(c)] = float(p.n[c]);
    }
  }
  // The products as images: one row per texel, through the per-vertex layout and attributes.
  bake::VertexBake rows;
  rows.layout = layout;
  rows.values = image.values;
  F::VertexSet products;
  ProductInfo per_texel = info;
  per_texel.rows = "row][col";  // the integrands' layout: [row][col][RGB]...
  set_products(products, rows, per_texel);
  m.ao = std::move(products.ao);
  m.transfer_diffuse = std::move(products.transfer_diffuse);
  m.transfer_visibility = std::move(products.transfer_visibility);
  m.radiance_band1 = std::move(products.radiance_band1);
  m.radiance_shadowed = std::move(products.radiance_shadowed);
}

bake::Lightmap lightmap_image(const bake::Mesh& mesh, const bake::Topology& topology,
                              const bake::LightmapReceivers& texels, const bake::LightmapSpec& spec,
                              const bake::VertexBake& rows, bake::SeamStitch& stitch) {
  bake::Lightmap image = texels.image(rows.values, rows.layout.width, spec.padding);
  stitch = spec.stitch ? bake::stitch_seams(image, texels.atlas, mesh, topology, texels.uv) : bake::SeamStitch{};
  return image;
}

F::Light light_of(const bake::AreaLight& light) {
  F::Light l;
  l.name = light.name;
  l.shape = bake::light_shape_name(light.shape);
  l.radiance = light.radiance;
  l.two_sided = int64_t(light.two_sided);
  for (const Eigen::Vector3d& v : light.vertices) l.vertices.values.insert(l.vertices.values.end(), {v.x(), v.y(), v.z()});
  for (const auto& face : light.faces) {
    l.face_sizes.values.push_back(uint32_t(face.size()));
    l.face_indices.values.insert(l.face_indices.values.end(), face.begin(), face.end());
  }
  return l;
}

F::Light light_of(const bake::PunctualLight& light) {
  F::Light l;
  l.name = light.name;
  l.shape = bake::punctual_kind_name(light.kind);
  l.radiance = light.intensity;
  const Eigen::Vector3d d = light.direction.normalized();
  if (light.kind != bake::PunctualKind::Directional)
    l.position = std::vector<double>{light.position.x(), light.position.y(), light.position.z()};
  if (light.kind != bake::PunctualKind::Point) l.direction = std::vector<double>{d.x(), d.y(), d.z()};
  if (light.kind == bake::PunctualKind::Spot) {
    l.inner_cone_angle = light.inner_cone;
    l.outer_cone_angle = light.outer_cone;
  }
  if (light.range > 0) l.range = light.range;
  return l;
}

namespace {
// area_lights/irradiance and, when sh_order > 0, area_lights/sh from rows [..][lights][1 + n²].
// The last `punctual` columns are punctual lights (bake/lights/punctual.h): their integrands are
// said too.
void area_products(std::optional<F::Product>& irradiance, std::optional<F::Product>& sh, std::span<const double> rows,
                   const std::vector<std::string>& names, int sh_order, size_t punctual) {
  const size_t n2 = size_t(sh_order) * size_t(sh_order), per_light = 1 + n2;
  auto product = [&](size_t offset, size_t count, std::string integrand) {
    F::Product p;
    p.values.reserve(rows.size() / per_light * count);
    for (size_t row = 0; row < rows.size(); row += per_light)
      for (size_t c = 0; c < count; ++c) p.values.push_back(float(rows[row + offset + c]));
    p.integrand = std::move(integrand);
    p.integrator = punctual == 0 ? "area lights: exact visible polygons (paper 003)"
                                 : punctual == names.size() ? "punctual lights: one exact shadow ray each"
                                                            : "area lights: exact visible polygons (paper 003); punctual lights: one exact "
                                                              "shadow ray each";
    p.visibility = kVisibilityLimit;
    p.lights = F::join_light_list(names);
    return p;
  };
  const std::string last = punctual == 1 ? std::string("the last column") : "the last " + std::to_string(punctual) + " columns";
  const std::string punctual_e = punctual == 0 ? std::string()
                                               : "; " + last + " (punctual lights: /lights/<name> of shape point, spot or "
                                                 "directional): V f_spot max(n.l, 0) / d^2 at unit intensity (directional: V "
                                                 "max(n.l, 0)), l towards the light, V one shadow ray";
  const std::string punctual_s = punctual == 0 ? std::string()
                                               : "; " + last + " (punctual lights): V f_spot [n.l > 0] y_i(l) / d^2 at unit "
                                                 "intensity (directional: without f_spot and d^2)";
  irradiance = product(0, 1, "E_l = Int_{visible part of light l} max(n.w, 0) dw at unit radiance" + punctual_e +
                                 "; diffuse outgoing radiance = albedo/pi sum_l radiance_l E_l");
  if (sh_order > 0) {
    sh = product(1, n2, "S_l,i = Int_{visible part of light l above the horizon} y_i(w) dw at unit radiance" + punctual_s);
    sh->sh_order = sh_order;
  }
}
} // namespace

void set_area_lights(F::VertexSet& set, const std::vector<double>& rows, const std::vector<std::string>& lights,
                     int sh_order, size_t punctual) {
  area_products(set.area_irradiance, set.area_sh, rows, lights, sh_order, punctual);
}

void set_lightmap_area_lights(F::VertexSet& set, const bake::Lightmap& image, const std::vector<std::string>& lights,
                              int sh_order, size_t punctual) {
  PRT_CHECK(set.lightmap.has_value());
  PRT_CHECK_OP(image.width, ==, set.lightmap->width);
  area_products(set.lightmap->area_irradiance, set.lightmap->area_sh, image.values, lights, sh_order, punctual);
}

F::Report report_of(const bake::ErrorReport& report, double bake_seconds, size_t points, bool reproducible) {
  F::Report out;
  for (const auto& e : report.products) {
    // A product checked against the bake's own integrator at a finer level (bake/bake/error_report.h
    // ProductError::finer) says so, with its own points.
    const bool finer = e.finer > 1;
    const std::string reference =
        finer ? "the bake's integrator at " + std::to_string(e.finer_knob) + " isolines (" +
                    std::to_string(int(std::lround(e.finer))) + "x the bake's; deterministic: reference_std_error is "
                    "its own error at most, order 1)"
              : report.reference;
    out.rows.push_back(report_row(report_row_name(e.product),
                                  {float(e.rmse), float(e.max_abs), float(e.reference_rms), float(e.bake_std_error),
                                   float(e.reference_std_error)},
                                  "rmse, max_abs, reference_rms, bake_std_error, reference_std_error",
                                  finer ? e.finer_points : report.vertices.size(), reference, report.reference_seconds,
                                  bake_seconds, double(points) / bake_seconds, reproducible));
    // What a relative error divides by (formats/SCHEMA.md "Error reports"): the product's RMS over
    // every row, for band-1 and S.
    const bool relative = e.product == bake::Product::RadianceBand1 || e.product == bake::Product::RadianceShadowed;
    if (relative && e.mesh_rms > 0) out.rows.back().mesh_rms = e.mesh_rms;
  }
  out.vertices = F::Array<uint32_t>{report.vertices, {}};
  return out;
}

void set_target_error(F::Asset& asset, double target) {
  if (target > 0) asset.target_error = target;
}

void set_fiv_environment(F::Asset& asset, const bake::EnvMapInfo& env, const std::string& env_path, const bake::Fiv& fenv,
                         const std::vector<float>& cube, int cube_size) {
  F::FivEnvironment& e = asset.fiv_environment.emplace();
  for (size_t k = 0; k < 9; ++k) e.f_env[k] = float(fenv[k]);
  e.environment = env_path;
  e.environment_sha256 = env.sha256;
  e.integrand = "F_c = Int L_c(w) w dw, layout [RGB][xyz]";
  F::IrradianceCube& c = asset.irradiance_cube.emplace();
  c.size = cube_size;
  c.values = cube;
  c.environment = env_path;
  c.environment_sha256 = env.sha256;
  c.integrand = "E_c(n) = Int L_c H(w,n) (n.w) dw, exact per texel";
  c.face_convention = "faces +X,-X,+Y,-Y,+Z,-Z; texel (row r, column q): s = 2(q+0.5)/S-1, t = 2(r+0.5)/S-1; +X "
                      "(1,-t,-s), -X (-1,-t,s), +Y (s,1,t), -Y (s,-1,-t), +Z (s,-t,1), -Z (-s,-t,-1)";
}

F::Occluder occluder_of(const std::string& name, bake::FivShells shells, const bake::EnvMapInfo& env,
                        const std::string& env_path, double fraction, uint32_t silhouette_k) {
  F::Occluder o;
  o.name = name;
  o.n_rho = int(shells.radii.size());
  o.n_theta = shells.n_theta;
  o.n_phi = shells.n_phi;
  o.shells = std::move(shells.values);
  o.float16 = shells.float16;  // v8: already rounded to float16 by the bake (FivShells::float16)
  o.environment = env_path;
  o.environment_sha256 = env.sha256;
  o.integrand = "F_c(s) = Int (1 - V(s,w)) L_c(w) w dw, layout [rho][theta][phi][RGB][xyz]";
  const Eigen::Vector3d centre = shells.world_centre();
  o.centre = {centre.x(), centre.y(), centre.z()};
  o.radius = shells.radius;
  o.radii = shells.radii;
  o.angular_convention = "s = centre + rho_k d(theta_i, phi_j), theta_i = pi i/(Ntheta-1) from +Y, phi_j = 2 pi "
                         "j/Nphi from +Z towards +X, d = (sin theta sin phi, cos theta, sin theta cos phi)";
  o.fraction = fraction;
  o.samples = int64_t(silhouette_k);
  if (shells.radial == bake::RadialScheme::surface) {
    // Version 7 (formats/SCHEMA.md): radii are the offsets τ_k from the surface radius r_surf.
    o.radial_scheme = std::string(bake::radial_scheme_name(shells.radial));
    o.first_offset = shells.radii.front() / shells.radius;
    o.angular_convention = "s = centre + (r_surf(theta_i, phi_j) + tau_k) d(theta_i, phi_j), tau_k = radii[k] (geometric), "
                           "theta_i = pi i/(Ntheta-1) from +Y, phi_j = 2 pi j/Nphi from +Z towards +X, d = (sin theta "
                           "sin phi, cos theta, sin theta cos phi)";
    o.surface_radius = F::OccluderSurfaceRadius{
        std::vector<float>(shells.surface_radius.begin(), shells.surface_radius.end()),
        "r_surf [theta][phi]: the largest distance from the centre at which the ray centre + t d meets the occluder (0: "
        "misses)",
        {}};
    o.valid = F::OccluderValid{std::move(shells.valid),
                               "0: the integrator found the offset inside the occluder; its value is extrapolated "
                               "along the radial line",
                               {}};
  } else {
    o.valid = F::OccluderValid{std::move(shells.valid), "0: the offset lies inside the occluder (nothing visible)", {}};
  }
  if (!shells.cones.empty()) {  // the tight proxy (v7)
    o.cones = F::OccluderCones{std::move(shells.cones),
                               "(m, Omega)(s) = (Int (1 - V(s,w)) w dw, Int (1 - V(s,w)) dw), layout [rho][theta][phi][4]", {},
                               shells.float16};
    o.proxy = std::string(F::names::kProxyCone);
  }
  return o;
}

F::ReportRow fiv_report_of(const std::string& name, const bake::FivErrorReport& r, const bake::FivShells& shells,
                           bool reproducible) {
  return report_row(name, {float(r.rmse), float(r.max_abs), float(r.reference_rms), 0.0f, float(r.reference_std_error)},
                    "rmse, max_abs, reference_rms (RMS of F_env components), bake_std_error (0: deterministic), "
                    "reference_std_error",
                    r.points, r.reference, r.reference_seconds, shells.seconds, double(shells.integrals) / shells.seconds,
                    reproducible);
}

} // namespace prt::tool
