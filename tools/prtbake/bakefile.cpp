// bakefile.cpp — see bakefile.h.
#include "bakefile.h"

#include <cctype>

namespace prt::tool {
namespace {

std::vector<float> to_float(std::span<const double> src, size_t stride, size_t offset, size_t count) {
  const size_t rows = stride ? src.size() / stride : 0;
  std::vector<float> out(rows * count);
  for (size_t r = 0; r < rows; ++r)
    for (size_t c = 0; c < count; ++c) out[r * count + c] = float(src[r * stride + offset + c]);
  return out;
}

std::vector<F::Attr> with(std::vector<F::Attr> x, const std::vector<F::Attr>& y) {
  x.insert(x.end(), y.begin(), y.end());
  return x;
}

} // namespace

std::string safe_name(const std::string& stem) {
  std::string name = stem;
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-' && c != '.') c = '_';
  return name.empty() ? std::string("occluder") : name;
}

void add_mesh(F::File& file, const std::string& prefix, const bake::Mesh& mesh) {
  const size_t V = mesh.positions.size(), T = mesh.triangles.size();
  std::vector<float> pos(3 * V), nrm(3 * V);
  for (size_t i = 0; i < V; ++i)
    for (int k = 0; k < 3; ++k) {
      pos[3 * i + size_t(k)] = mesh.positions[i][k];
      nrm[3 * i + size_t(k)] = mesh.normals[i][k];
    }
  std::vector<uint32_t> tri(3 * T);
  for (size_t i = 0; i < T; ++i)
    for (int k = 0; k < 3; ++k) tri[3 * i + size_t(k)] = mesh.triangles[i][size_t(k)];
  file.datasets.push_back({prefix + "/mesh/positions", {V, 3}, std::move(pos), {}});
  file.datasets.push_back(
      {prefix + "/mesh/normals", {V, 3}, std::move(nrm),
       {{"source", std::string(mesh.normal_source == bake::Mesh::NormalSource::File ? "file" : "angle-weighted")}}});
  file.datasets.push_back({prefix + "/mesh/triangles", {T, 3}, std::move(tri), {}});
  file.datasets.push_back({prefix + "/mesh/source_position", {V}, mesh.source_position, {}});
}

void add_products(F::File& file, const std::string& prefix, const bake::VertexBake& bake, const ProductInfo& info) {
  const auto& L = bake.layout;
  const size_t W = L.width, V = W ? bake.values.size() / W : 0;
  auto common = [&](std::vector<F::Attr> attrs) {
    attrs.push_back({"integrator", info.integrator});
    attrs.push_back({"integrator_description", info.integrator_description});
    attrs.push_back({"samples", int64_t(info.samples)});
    attrs.push_back({"seed", int64_t(info.seed)});
    attrs.push_back({"visibility", std::string("limit from just above the surface (p + eps*n, eps -> 0+)")});
    return attrs;
  };
  if (L.ao_count)
    file.datasets.push_back({prefix + "/ao", {V}, to_float(bake.values, W, L.ao, 1),
                             common({{"integrand", std::string("A = (1/pi) Int V H (n.w) dw")}})});
  if (L.transfer_count)
    file.datasets.push_back({prefix + "/transfer/diffuse", {V, L.transfer_count},
                             to_float(bake.values, W, L.transfer, L.transfer_count),
                             common({{"integrand", std::string("T_i = (1/pi) Int V H (n.w) y_i dw")},
                                     {"sh_order", int64_t(info.transfer_order)}})});
  if (L.visibility_count)
    file.datasets.push_back({prefix + "/transfer/visibility", {V, L.visibility_count},
                             to_float(bake.values, W, L.visibility, L.visibility_count),
                             common({{"integrand", std::string("U_i = Int V H y_i dw")},
                                     {"sh_order", int64_t(info.visibility_order)}})});
  if (L.radiance_count) {
    const auto& i = info.env->info();
    file.datasets.push_back(
        {prefix + "/radiance/band1", {V, 3, 3}, to_float(bake.values, W, L.radiance, 9),
         common({{"integrand", std::string("R_c,m = Int L_c V H y_1m dw, layout [vertex][RGB][m=-1,0,1]")},
                 {"shading", std::string("E_c = (4 pi / 3) sum_m y_1m(n) R_c,m")},
                 {"environment", info.env_path},
                 {"environment_sha256", i.sha256},
                 {"environment_layout", i.layout},
                 {"negative_pixels_clamped", int64_t(i.negative_pixels_clamped)}})});
  }
}

void add_report(F::File& file, const std::string& dir, const bake::ErrorReport& report, double bake_seconds,
                size_t points, bool reproducible) {
  for (const auto& e : report.products) {
    std::vector<F::Attr> attrs = {
        {"columns", std::string("rmse, max_abs, reference_rms, bake_std_error, reference_std_error")},
        {"points", int64_t(report.vertices.size())},
        {"reference", report.reference}};
    if (!reproducible) {  // wall times differ run to run: kept out of reproducible files
      attrs.push_back({"reference_seconds", report.reference_seconds});
      attrs.push_back({"bake_seconds", bake_seconds});
      attrs.push_back({"integrals_per_second", double(points) / bake_seconds});
    }
    file.datasets.push_back({dir + "/" + e.product, {5},
                             std::vector<float>{float(e.rmse), float(e.max_abs), float(e.reference_rms),
                                                float(e.bake_std_error), float(e.reference_std_error)},
                             std::move(attrs)});
  }
  file.datasets.push_back({dir + "/vertices", {report.vertices.size()}, report.vertices, {}});
}

void add_fiv_environment(F::File& file, const bake::EnvMap& env, const std::string& env_path, const bake::Fiv& fenv,
                         const std::vector<float>& cube, int cube_size) {
  const std::vector<F::Attr> env_attrs = {{"environment", env_path}, {"environment_sha256", env.info().sha256}};
  std::vector<float> fe(9);
  for (size_t k = 0; k < 9; ++k) fe[k] = float(fenv[k]);
  file.datasets.push_back({"/fiv/environment", {3, 3}, std::move(fe),
                           with(env_attrs, {{"integrand", std::string("F_c = Int L_c(w) w dw, layout [RGB][xyz]")}})});
  file.datasets.push_back(
      {"/fiv/irradiance_cube", {6, uint64_t(cube_size), uint64_t(cube_size), 3}, cube,
       with(env_attrs, {{"integrand", std::string("E_c(n) = Int L_c H(w,n) (n.w) dw, exact per texel")},
                        {"face_convention", std::string("faces +X,-X,+Y,-Y,+Z,-Z; texel (row r, column q): s = "
                                                        "2(q+0.5)/S-1, t = 2(r+0.5)/S-1; +X (1,-t,-s), -X (-1,-t,s), "
                                                        "+Y (s,1,t), -Y (s,-1,-t), +Z (s,-t,1), -Z (-s,-t,-1)")}})});
}

void add_fiv_occluder(F::File& file, const std::string& name, const bake::FivShells& sh, const bake::EnvMap& env,
                      const std::string& env_path, double fraction, uint32_t samples) {
  const std::string dir = "/fiv/occluders/" + name;
  const uint64_t nr = sh.radii.size();
  file.datasets.push_back(
      {dir + "/shells", {nr, uint64_t(sh.n_theta), uint64_t(sh.n_phi), 3, 3}, sh.shells,
       {{"environment", env_path},
        {"environment_sha256", env.info().sha256},
        {"integrand", std::string("F_c(s) = Int (1 - V(s,w)) L_c(w) w dw, layout [rho][theta][phi][RGB][xyz]")},
        {"centre", std::vector<double>{sh.centre.x(), sh.centre.y(), sh.centre.z()}},
        {"radius", sh.radius},
        {"radii", sh.radii},
        {"angular_convention", std::string("s = centre + rho_k d(theta_i, phi_j), theta_i = pi i/(Ntheta-1) "
                                           "from +Y, phi_j = 2 pi j/Nphi from +Z towards +X, d = (sin "
                                           "theta sin phi, cos theta, sin theta cos phi)")},
        {"fraction", fraction},
        {"samples", int64_t(samples)}}});
  file.datasets.push_back({dir + "/valid", {nr, uint64_t(sh.n_theta), uint64_t(sh.n_phi)}, sh.valid,
                           {{"meaning", std::string("0: the offset lies inside the occluder (nothing visible)")}}});
}

void add_fiv_report(F::File& file, const std::string& name, const bake::FivErrorReport& r, const bake::FivShells& sh,
                    bool reproducible) {
  std::vector<F::Attr> attrs = {
      {"columns", std::string("rmse, max_abs, reference_rms (RMS of F_env components), bake_std_error (0: "
                              "deterministic), reference_std_error")},
      {"points", int64_t(r.points)},
      {"reference", r.reference}};
  if (!reproducible) {
    attrs.push_back({"reference_seconds", r.reference_seconds});
    attrs.push_back({"bake_seconds", sh.seconds});
    attrs.push_back({"integrals_per_second", double(sh.integrals) / sh.seconds});
  }
  file.datasets.push_back({"/report/fiv/" + name, {5},
                           std::vector<float>{float(r.rmse), float(r.max_abs), float(r.reference_rms), 0.0f,
                                              float(r.reference_std_error)},
                           std::move(attrs)});
}

} // namespace prt::tool
