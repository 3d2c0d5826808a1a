#include <bake/bake/fiv.h>

#include <bake/bake/vertex_bake.h>
#include <bake/core/error.h>
#include <bake/environment/irradiance.h>
#include <bake/integrators/qmc.h>
#include <bake/integrators/registry.h>
#include <bake/mesh/receivers.h>
#include <bake/sphere/sampling.h>
#include <bake/visibility/raycast.h>

#include <Imath/half.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <numbers>
#include <optional>

namespace prt::bake {

using Eigen::Vector3d;

namespace {
// y_{1,-1} = −k y, y_{1,0} = k z, y_{1,1} = −k x with k = √(3/4π): ω from band-1 rows [c][m].
constexpr double kBand1 = 0.48860251190291992159;  // √(3 / 4π)
constexpr double kBand0 = 0.28209479177387814347;  // √(1 / 4π)
void omega_from_band1(const double* r, double* f) {
  for (int c = 0; c < 3; ++c) {
    f[3 * c + 0] = -r[3 * c + 2] / kBand1;
    f[3 * c + 1] = -r[3 * c + 0] / kBand1;
    f[3 * c + 2] = r[3 * c + 1] / kBand1;
  }
}
} // namespace

Fiv environment_fiv(const EnvMap& env) {
  Fiv f{};
  if (env.texel_count() == 0) return f;  // constant(): ∫ ω dω = 0
  const auto m = texel_moments(env);
  for (int t = 0; t < env.texel_count(); ++t) {
    const Rgb L = env.texel_value(t);
    const double c[3] = {L.r, L.g, L.b};
    for (int ch = 0; ch < 3; ++ch)
      for (int a = 0; a < 3; ++a) f[size_t(3 * ch + a)] += c[ch] * m[size_t(t)][a];
  }
  return f;
}

Eigen::Vector3d gl_cube_direction(int face, int row, int column, int size) {
  const double s = 2 * (column + 0.5) / size - 1, t = 2 * (row + 0.5) / size - 1;
  Vector3d d;
  switch (face) {
    case 0: d = {1, -t, -s}; break;
    case 1: d = {-1, -t, s}; break;
    case 2: d = {s, 1, t}; break;
    case 3: d = {s, -1, -t}; break;
    case 4: d = {s, -t, 1}; break;
    default: d = {-s, -t, -1}; break;
  }
  return d.normalized();
}

namespace {
// Texels [begin, end) of the DifMap [6][S][S][3]: E(n) at each cube texel direction, as float.
template <class Irradiance>
std::vector<float> cube_of(int size, const Irradiance& E, size_t begin, size_t end) {
  PRT_CHECK(size >= 1 && begin <= end && end <= size_t(6) * size_t(size) * size_t(size));
  std::vector<float> out((end - begin) * 3, 0.0f);
  tbb::parallel_for(begin, end, [&](size_t t) {
    const int idx = int(t);
    const Rgb e = E(gl_cube_direction(idx / (size * size), (idx / size) % size, idx % size, size));
    out[(t - begin) * 3] = float(e.r);
    out[(t - begin) * 3 + 1] = float(e.g);
    out[(t - begin) * 3 + 2] = float(e.b);
  });
  return out;
}
size_t cube_texels(int size) { return size_t(6) * size_t(size) * size_t(size); }
} // namespace

std::vector<float> irradiance_cube(const EnvMap& env, int size) {
  PRT_CHECK(size >= 1);
  const UnshadowedIrradiance E(env);
  return cube_of(size, E, 0, cube_texels(size));
}

std::vector<float> irradiance_cube_texels(const UnshadowedIrradiance& irradiance, int size, size_t begin, size_t end) {
  return cube_of(size, irradiance, begin, end);
}

std::vector<float> irradiance_cube_reference(const EnvMap& env, int size) {
  PRT_CHECK(size >= 1 && env.texel_count() > 0);
  const UnshadowedIrradiance E(env);
  return cube_of(size, [&](const Vector3d& n) { return E.reference(n); }, 0, cube_texels(size));
}

Eigen::Vector3d shell_direction(int i_theta, int n_theta, int j_phi, int n_phi) {
  const double th = std::numbers::pi * i_theta / std::max(n_theta - 1, 1), ph = 2 * std::numbers::pi * j_phi / n_phi;
  return {std::sin(th) * std::sin(ph), std::cos(th), std::sin(th) * std::cos(ph)};
}

std::string_view radial_scheme_name(RadialScheme scheme) {
  return scheme == RadialScheme::surface ? "surface" : "geometric";
}

std::string_view shell_precision_name(bool float16) { return float16 ? "half" : "float"; }

bool parse_self_shadows(std::string_view text, bool& vertex) {
  if (text != "vertex" && text != "shells") return false;
  vertex = text == "vertex";
  return true;
}

FivSelfShadows bake_fiv_self_shadows(const Mesh& occluder, const Topology& topology, const EnvMap& env, const ShellSpec& spec,
                                     uint64_t seed, const Monitor& monitor) {
  ProductRequest request;
  request.radiance = &env;
  FivSelfShadows out;
  out.integrator.kind = IntegratorKind::Silhouette;
  out.integrator.silhouette_k = spec.silhouette_k;
  out.integrator.seed = seed;
  const std::unique_ptr<Integrator> shadows = make_integrator(out.integrator, occluder, topology, request);
  out.integrator_name = shadows->name();
  out.integrator_description = shadows->description();
  out.values = bake_vertices(occluder, topology, *shadows, monitor, "baking self-shadows");
  return out;
}

bool parse_shell_precision(std::string_view text, bool& float16) {
  if (text != "half" && text != "float") return false;
  float16 = text == "half";
  return true;
}

bool parse_radial_scheme(std::string_view text, RadialScheme& scheme) {
  if (text == "surface") scheme = RadialScheme::surface;
  else if (text == "geometric") scheme = RadialScheme::geometric;
  else return false;
  return true;
}

Vector3d FivShells::sample_position(int k, int i, int j) const {
  const Vector3d d = shell_direction(i, n_theta, j, n_phi);
  const double r = radial == RadialScheme::surface
                       ? surface_radius[size_t(i) * size_t(n_phi) + size_t(j)] + radii[size_t(k)]
                       : radii[size_t(k)];
  return centre + r * d;
}

namespace {
// Where the line o + t d meets triangle (a, b, c), in double (Möller–Trumbore); nullopt when it
// is parallel to the triangle's plane.
std::optional<double> line_triangle(const Vector3d& o, const Vector3d& d, const Vector3d& a, const Vector3d& b,
                                    const Vector3d& c) {
  const Vector3d e1 = b - a, e2 = c - a, p = d.cross(e2);
  const double det = e1.dot(p);
  if (det == 0) return std::nullopt;
  const Vector3d q = (o - a).cross(e1);
  return e2.dot(q) / det;
}
} // namespace

std::vector<double> surface_radii(const Mesh& mesh, const Vector3d& centre, double radius, int n_theta, int n_phi) {
  const Topology topology = build_topology(mesh);
  const RayCaster caster(mesh, topology);
  // Every vertex lies within `radius` of the centre: a ray from 2R + 1 out, cast inwards, meets the
  // outermost surface first.
  const double far = 2 * std::max(radius, 0.0) + 1;
  std::vector<double> out(size_t(n_theta) * size_t(n_phi), 0.0);
  tbb::parallel_for(size_t(0), out.size(), [&](size_t idx) {
    const Vector3d d = shell_direction(int(idx / size_t(n_phi)), n_theta, int(idx % size_t(n_phi)), n_phi);
    const Vector3d o = centre + far * d;
    const std::optional<RayHit> hit = caster.closest_hit(o, -d, 0.0);
    if (!hit) return;
    // The hit again in double (Embree gives a float distance).
    const auto& tri = mesh.triangles[hit->triangle];
    double t = double(hit->t);
    if (const auto td = line_triangle(o, -d, mesh.positions[tri[0]].cast<double>(), mesh.positions[tri[1]].cast<double>(),
                                      mesh.positions[tri[2]].cast<double>()))
      t = *td;
    out[idx] = std::clamp(far - t, 0.0, far);
  });
  return out;
}

void extrapolate_inside_samples(FivShells& shells) {
  if (shells.radial != RadialScheme::surface) return;
  const size_t per_shell = size_t(shells.n_theta) * size_t(shells.n_phi), n_rho = shells.radii.size();
  for (size_t ij = 0; ij < per_shell; ++ij)
    for (size_t k = 0; k < n_rho; ++k) {
      if (shells.valid[k * per_shell + ij] != 0) continue;
      size_t from = n_rho;  // the nearest valid sample outwards, else inwards
      for (size_t q = k + 1; q < n_rho && from == n_rho; ++q)
        if (shells.valid[q * per_shell + ij] != 0) from = q;
      for (size_t q = k; q-- > 0 && from == n_rho;)
        if (shells.valid[q * per_shell + ij] != 0) from = q;
      if (from == n_rho) continue;  // no valid sample on the line: F^env, as baked
      std::copy_n(shells.values.begin() + std::ptrdiff_t((from * per_shell + ij) * 9), 9,
                  shells.values.begin() + std::ptrdiff_t((k * per_shell + ij) * 9));
      if (!shells.cones.empty())  // the tight proxy's cone, from the same sample
        std::copy_n(shells.cones.begin() + std::ptrdiff_t((from * per_shell + ij) * 4), 4,
                    shells.cones.begin() + std::ptrdiff_t((k * per_shell + ij) * 4));
      ++shells.extrapolated;
    }
}

void bounding_sphere(const Mesh& mesh, Vector3d& centre, double& radius) {
  PRT_CHECK(!mesh.positions.empty());
  Vector3d lo = mesh.positions[0].cast<double>(), hi = lo;
  for (const auto& p : mesh.positions) {
    lo = lo.cwiseMin(p.cast<double>());
    hi = hi.cwiseMax(p.cast<double>());
  }
  centre = 0.5 * (lo + hi);
  radius = 0;
  for (const auto& p : mesh.positions) radius = std::max(radius, (p.cast<double>() - centre).norm());
}

Fiv occluded_fiv(const SilhouetteIntegrator& integrator, const Vector3d& position, bool* inside, Cone* cone) {
  const ProductLayout& L = integrator.layout();
  PRT_CHECK(L.radiance_count == 9 && L.visibility_count >= 1);
  std::vector<double> vis(L.width), all(L.width);
  ShadePoint sp;
  sp.p = position;
  sp.n = Vector3d(0.3, 0.8, -0.52).normalized();  // only decides ties of a point exactly on a face plane
  sp.hemisphere = false;
  integrator.integrate(sp, 0, vis);
  integrator.unoccluded(all);
  double occ[9];
  for (int k = 0; k < 9; ++k) occ[k] = all[L.radiance + size_t(k)] - vis[L.radiance + size_t(k)];
  if (inside) *inside = vis[L.visibility] == 0.0;
  Fiv f{};
  omega_from_band1(occ, f.data());
  if (cone && L.visibility_count >= 4) {
    // ∫ (1 − V) y_i dω for i < 4: Ω = that of y_0 over y_0, m from band 1 as F's.
    double band1[3];
    for (int k = 0; k < 3; ++k) band1[k] = all[L.visibility + 1 + size_t(k)] - vis[L.visibility + 1 + size_t(k)];
    const double y1[3] = {-band1[2] / kBand1, -band1[0] / kBand1, band1[1] / kBand1};
    for (int k = 0; k < 3; ++k) (*cone)[size_t(k)] = y1[k];
    (*cone)[3] = (all[L.visibility] - vis[L.visibility]) / kBand0;
  }
  return f;
}

Fiv qmc_occluded_fiv(const QmcIntegrator& integrator, const Fiv& environment, const Vector3d& position,
                     uint64_t point_index, Fiv* std_error) {
  const ProductLayout& L = integrator.layout();
  PRT_CHECK(L.radiance_count == 9);
  std::vector<double> v(L.width), se(L.width);
  ShadePoint sp;
  sp.p = position;
  sp.hemisphere = false;
  integrator.integrate(sp, point_index, v, se);
  Fiv vis{}, f{};
  omega_from_band1(v.data() + L.radiance, vis.data());
  for (int k = 0; k < 9; ++k) f[size_t(k)] = environment[size_t(k)] - vis[size_t(k)];
  if (std_error) {
    double s[9];
    for (int k = 0; k < 9; ++k) s[k] = se[L.radiance + size_t(k)];
    omega_from_band1(s, std_error->data());
    for (double& x : *std_error) x = std::abs(x);
  }
  return f;
}

bool parse_shell_grid(std::string_view text, ShellSpec& spec) {
  int n[3] = {0, 0, 0};
  const char* p = text.data();
  const char* const end = text.data() + text.size();
  for (int i = 0; i < 3; ++i) {
    if (i > 0 && (p == end || *p++ != 'x')) return false;
    const auto [q, ec] = std::from_chars(p, end, n[i]);
    if (ec != std::errc() || q == p) return false;
    p = q;
  }
  if (p != end || n[0] < 1 || n[0] > 4096 || n[1] < 2 || n[1] > 4096 || n[2] < 1 || n[2] > 1024) return false;
  spec.n_phi = n[0];
  spec.n_theta = n[1];
  spec.n_rho = n[2];
  return true;
}

namespace {
// Band-1 radiance and visibility up to band 1 (order 2): the occluded FIV and the cone (Ω, m).
ProductRequest band1_radiance(const EnvMap& env) {
  ProductRequest req;
  req.radiance = &env;
  req.visibility_order = 2;
  return req;
}
} // namespace

FivShellRows::FivShellRows(const Mesh& occluder, const Topology& topology, const EnvMap& env, const ShellSpec& spec)
    : FivShellRows(occluder, spec) {
  integrator_ = std::make_unique<const SilhouetteIntegrator>(occluder, topology, band1_radiance(env),
                                                             SilhouetteOptions{silhouette_isolines(spec.silhouette_k), 1});
  // The scale the occluded FIV is compared with: ∫ L_c dω, the full-sphere irradiance. (|F^env|
  // itself cancels to 0 for a uniform sky, so a fraction of it is ill-posed.)
  if (env.texel_count() == 0) {
    const Rgb L = env.radiance(Vector3d::UnitY());
    env_norm_[0] = 4 * std::numbers::pi * L.r;
    env_norm_[1] = 4 * std::numbers::pi * L.g;
    env_norm_[2] = 4 * std::numbers::pi * L.b;
  }
  for (int t = 0; t < env.texel_count(); ++t) {
    const Rgb L = env.texel_value(t);
    const double w = env.texel_solid_angle(t);
    env_norm_[0] += L.r * w;
    env_norm_[1] += L.g * w;
    env_norm_[2] += L.b * w;
  }
}

FivShellRows::FivShellRows(const Mesh& occluder, const ShellSpec& spec) : spec_(spec) {
  PRT_CHECK(spec.n_phi >= 1 && spec.n_theta >= 2 && spec.n_rho >= 1 && spec.fraction > 0 && spec.inner > 0);
  bounding_sphere(occluder, frame_.centre, frame_.radius);
  frame_.origin = occluder.origin;
  frame_.n_phi = spec.n_phi;
  frame_.n_theta = spec.n_theta;
  frame_.radial = spec.radial;
  const double R = std::max(frame_.radius, 1e-30);
  const bool surface = spec.radial == RadialScheme::surface;
  PRT_CHECK(!surface || spec.first_offset > 0);
  const double rho0 = (surface ? spec.first_offset : spec.inner) * R,
               rho_far = std::max(R / (2 * std::sqrt(spec.fraction)), 2 * rho0);
  const double g = spec.n_rho > 1 ? std::pow(rho_far / rho0, 1.0 / (spec.n_rho - 1)) : 1.0;
  for (int k = 0; k < spec.n_rho; ++k) radii_.push_back(rho0 * std::pow(g, k));
  if (surface) frame_.surface_radius = surface_radii(occluder, frame_.centre, frame_.radius, spec.n_theta, spec.n_phi);
}

FivShellRows::~FivShellRows() = default;

size_t FivShellRows::rows_per_shell() const { return size_t(spec_.n_theta) * size_t(spec_.n_phi); }

FivShells FivShellRows::empty_shells() const {
  // Room for every shell the bake may use, so that append() never moves what it appended (the
  // pages of shells never appended are never touched).
  FivShells out = frame_;
  out.values.reserve(size_t(shell_count()) * rows_per_shell() * 9);
  out.valid.reserve(size_t(shell_count()) * rows_per_shell());
  out.cones.reserve(size_t(shell_count()) * rows_per_shell() * 4);
  return out;
}

std::vector<double> FivShellRows::rows(int shell, size_t begin, size_t end, Task* task) const {
  PRT_CHECK(integrator_ && begin <= end && end <= rows_per_shell());
  std::vector<double> out((end - begin) * kRowWidth, 0.0);
  const double rho = radius(shell);
  const bool surface = spec_.radial == RadialScheme::surface;
  tbb::parallel_for(begin, end, [&](size_t idx) {
    const int i = int(idx / size_t(spec_.n_phi)), j = int(idx % size_t(spec_.n_phi));
    bool inside = false;
    // FivShells::sample_position without the radii of the shells not yet appended.
    const double dist = surface ? frame_.surface_radius[idx] + rho : rho;
    Cone cone{};
    const Fiv f =
        occluded_fiv(*integrator_, frame_.centre + dist * shell_direction(i, spec_.n_theta, j, spec_.n_phi), &inside, &cone);
    double r = 0;
    for (int c = 0; c < 3; ++c) {
      const double nf = std::sqrt(f[size_t(3 * c)] * f[size_t(3 * c)] + f[size_t(3 * c + 1)] * f[size_t(3 * c + 1)] +
                                  f[size_t(3 * c + 2)] * f[size_t(3 * c + 2)]);
      if (env_norm_[c] > 0) r = std::max(r, nf / env_norm_[c]);
    }
    double* row = out.data() + (idx - begin) * kRowWidth;
    for (int q = 0; q < 9; ++q) row[q] = double(float(f[size_t(q)]));
    row[9] = inside ? 0.0 : 1.0;
    row[10] = inside ? 0.0 : r;  // offsets inside the geometry say nothing about distance
    for (int q = 0; q < 4; ++q) row[11 + q] = double(float(cone[size_t(q)]));
    if (task) task->advance();
  });
  return out;
}

// Far enough (and outside the bounding sphere, so never inside the occluder): ρ_k >= R, or τ_k >= R
// (then r_surf + τ_k >= R too).
bool FivShellRows::may_stop_after(int shell) const { return radius(shell) >= std::max(frame_.radius, 1e-30); }

void FivShellRows::finish(FivShells& shells) const {
  extrapolate_inside_samples(shells);
  if (!spec_.float16) return;
  // What a float16 file holds (ShellSpec::float16): round to nearest even, by Imath::half.
  for (std::vector<float>* table : {&shells.values, &shells.cones})
    for (float& v : *table) {
      if (!(std::fabs(v) <= 65504.0f))
        throw InputError("", "an occluded FIV value of " + std::to_string(v) +
                                 " exceeds float16's largest, 65504: this environment needs precision \"float\"");
      v = float(Imath::half(v));
    }
  shells.float16 = true;
}

bool FivShellRows::stops_after(int shell, std::span<const double> rows) const {
  PRT_CHECK_OP(rows.size(), ==, rows_per_shell() * kRowWidth);
  if (!may_stop_after(shell)) return false;
  double worst = 0;
  for (size_t idx = 0; idx < rows_per_shell(); ++idx) worst = std::max(worst, rows[idx * kRowWidth + 10]);
  return worst < spec_.fraction;
}

void FivShellRows::append(FivShells& shells, int shell, std::span<const double> rows) const {
  PRT_CHECK(rows.size() == rows_per_shell() * kRowWidth && shells.radii.size() == size_t(shell));
  shells.radii.push_back(radius(shell));
  // Into the room empty_shells() reserved: no reallocation, and no zeroing pass before the values.
  for (size_t idx = 0; idx < rows_per_shell(); ++idx) {
    const double* row = rows.data() + idx * kRowWidth;
    for (int q = 0; q < 9; ++q) shells.values.push_back(float(row[q]));
    shells.valid.push_back(row[9] != 0.0 ? 1 : 0);
    for (int q = 0; q < 4; ++q) shells.cones.push_back(float(row[11 + q]));
  }
  shells.integrals += rows_per_shell();
}

FivShells bake_fiv_shells(const Mesh& occluder, const Topology& topology, const EnvMap& env, const ShellSpec& spec,
                          const Monitor& monitor) {
  const FivShellRows baker(occluder, topology, env, spec);
  FivShells out = baker.empty_shells();
  const size_t per_shell = baker.rows_per_shell();
  Task progress(monitor, "baking FIV shells", uint64_t(spec.n_rho) * per_shell);
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 0; k < baker.shell_count(); ++k) {
    const std::vector<double> rows = baker.rows(k, 0, per_shell, &progress);
    baker.append(out, k, rows);
    if (baker.stops_after(k, rows)) break;
  }
  baker.finish(out);
  progress.finish();
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

namespace {
double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
} // namespace

FivCost environment_fiv_cost(const EnvMap& env, int size, size_t samples) {
  PRT_CHECK(size >= 1);
  FivCost cost;
  const auto t0 = std::chrono::steady_clock::now();
  (void)environment_fiv(env);
  const UnshadowedIrradiance E(env);
  cost.setup_seconds = seconds_since(t0);
  const size_t texels = cube_texels(size);
  const std::vector<uint32_t> picks = seeded_sample(uint32_t(texels), samples, 0x6469666dull);
  const double c0 = thread_cpu_seconds();
  for (uint32_t t : picks) (void)E(gl_cube_direction(int(t) / (size * size), (int(t) / size) % size, int(t) % size, size));
  cost.timed = picks.size();
  cost.cpu_seconds = (thread_cpu_seconds() - c0) * double(texels) / double(std::max<size_t>(picks.size(), 1));
  return cost;
}

FivCost fiv_shells_cost(const Mesh& occluder, const Topology& topology, const EnvMap& env, const ShellSpec& spec,
                        size_t samples) {
  FivCost cost;
  const auto t0 = std::chrono::steady_clock::now();
  const FivShellRows baker(occluder, topology, env, spec);
  cost.setup_seconds = seconds_since(t0);
  // Seeded rows of a shell (at most 4096 x 4096: a uint32 count), taken on the shells in turn.
  const size_t per_shell = baker.rows_per_shell(), total = per_shell * size_t(baker.shell_count());
  const std::vector<uint32_t> picks = seeded_sample(uint32_t(per_shell), samples, 0x7368656cull);
  const double c0 = thread_cpu_seconds();
  // One row at a time: a range of one runs on the calling thread, whose CPU time is what is counted.
  for (size_t q = 0; q < picks.size(); ++q) (void)baker.rows(int(q % size_t(baker.shell_count())), picks[q], picks[q] + 1);
  cost.timed = picks.size();
  cost.cpu_seconds = (thread_cpu_seconds() - c0) * double(total) / double(std::max<size_t>(picks.size(), 1));
  return cost;
}

FivCost fiv_self_shadows_cost(const Mesh& occluder, const Topology& topology, const EnvMap& env, const ShellSpec& spec,
                              size_t samples) {
  FivCost cost;
  const auto t0 = std::chrono::steady_clock::now();
  ProductRequest request;
  request.radiance = &env;
  IntegratorSpec integrator;
  integrator.kind = IntegratorKind::Silhouette;
  integrator.silhouette_k = spec.silhouette_k;
  const std::unique_ptr<Integrator> shadows = make_integrator(integrator, occluder, topology, request);
  const std::vector<ShadePoint> points = vertex_shade_points(occluder, topology);
  shadows->prepare(points);
  cost.setup_seconds = seconds_since(t0);
  if (points.empty()) return cost;
  const std::vector<uint32_t> picks = seeded_sample(uint32_t(points.size()), samples, 0x73656c66ull);
  std::vector<double> values(shadows->layout().width), std_error(values.size());
  const double c0 = thread_cpu_seconds();
  for (uint32_t v : picks) shadows->integrate(points[v], v, values, std_error);
  cost.timed = picks.size();
  cost.cpu_seconds = (thread_cpu_seconds() - c0) * double(points.size()) / double(std::max<size_t>(picks.size(), 1));
  return cost;
}

FivErrorReport fiv_error_report(const Mesh& occluder, const Topology& topology, const EnvMap& env, const FivShells& shells,
                                const Fiv& fenv, size_t points, uint64_t seed, const Monitor& monitor) {
  ProductRequest req;
  req.radiance = &env;
  req.visibility_order = 1;
  const QmcIntegrator qmc(occluder, topology, req, {IntegratorSpec::kSilhouetteReferenceRays, mix64(seed ^ 0x66697672656675ull)});
  const size_t per_shell = size_t(shells.n_theta) * size_t(shells.n_phi), total = shells.radii.size() * per_shell;
  const auto picks = seeded_sample(uint32_t(total), points, seed);
  std::vector<double> err2(picks.size(), 0.0), se2(picks.size(), 0.0), maxe(picks.size(), 0.0);
  const auto r0 = std::chrono::steady_clock::now();
  Task progress(monitor, "reference", picks.size());
  tbb::parallel_for(size_t(0), picks.size(), [&](size_t q) {
    const size_t idx = picks[q], k = idx / per_shell, ij = idx % per_shell;
    const int i = int(ij / size_t(shells.n_phi)), j = int(ij % size_t(shells.n_phi));
    Fiv se;
    const Fiv ref = qmc_occluded_fiv(qmc, fenv, shells.sample_position(int(k), i, j), idx, &se);
    for (size_t x = 0; x < 9; ++x) {
      const double d = double(shells.values[idx * 9 + x]) - ref[x];
      err2[q] += d * d;
      se2[q] += se[x] * se[x];
      maxe[q] = std::max(maxe[q], std::abs(d));
    }
    progress.advance();
  });
  progress.finish();
  FivErrorReport r;
  r.reference_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - r0).count();
  r.points = picks.size();
  r.reference = qmc.description() + " (full sphere)";
  double e = 0, s2 = 0, n2 = 0;
  for (size_t q = 0; q < picks.size(); ++q) {
    e += err2[q];
    s2 += se2[q];
    r.max_abs = std::max(r.max_abs, maxe[q]);
  }
  for (double x : fenv) n2 += x * x;
  const double nval = double(std::max<size_t>(9 * picks.size(), 1));
  r.rmse = std::sqrt(e / nval);
  r.reference_std_error = std::sqrt(s2 / nval);
  r.reference_rms = std::sqrt(n2 / 9);
  return r;
}

} // namespace prt::bake
