#include <bake/error.h>
#include <bake/fiv.h>
#include <bake/qmc.h>
#include <bake/sampling.h>
#include <bake/vertex_bake.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <numbers>
#include <numeric>

namespace prt::bake {

using Eigen::Vector3d;

namespace {
// y_{1,-1} = −k y, y_{1,0} = k z, y_{1,1} = −k x with k = √(3/4π): ω from band-1 rows [c][m].
constexpr double kBand1 = 0.48860251190291992159;  // √(3 / 4π)
void omega_from_band1(const double* r, double* f) {
  for (int c = 0; c < 3; ++c) {
    f[3 * c + 0] = -r[3 * c + 2] / kBand1;
    f[3 * c + 1] = -r[3 * c + 0] / kBand1;
    f[3 * c + 2] = r[3 * c + 1] / kBand1;
  }
}

// ∫_texel ω dω by 4×4 uniform-in-solid-angle sub-samples.
std::vector<Vector3d> texel_moments(const EnvMap& env) {
  const int T = env.texel_count();
  std::vector<Vector3d> m(static_cast<size_t>(T));
  tbb::parallel_for(0, T, [&](int t) {
    Vector3d d[16];
    env.sample_texel_grid(t, 4, d);  // = sample_texel(t, (a + ½)/4, (b + ½)/4) at d[4a + b]
    Vector3d s = Vector3d::Zero();
    for (const Vector3d& di : d) s += di;
    m[size_t(t)] = s * (env.texel_solid_angle(t) / 16.0);
  });
  return m;
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

Eigen::Vector3d cube_direction(int face, int row, int column, int size) {
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

// One texel of the DifMap sum (non-black texels only): value, moment ∫ω dω, centre, and a
// bound r on its angular radius (inflated 1.5×) — it is cut by the horizon of n when
// |n · centre| < sin(r).
struct DifTexel {
  double L[3], m[3], c[3], r, sin_r;
  int index;
};

std::vector<DifTexel> dif_texels(const EnvMap& env, const std::vector<Vector3d>& m) {
  const int T = env.texel_count();
  std::vector<DifTexel> tex;
  tex.reserve(static_cast<size_t>(T));
  for (int t = 0; t < T; ++t) {
    const Rgb L = env.texel_value(t);
    if (L.r == 0 && L.g == 0 && L.b == 0) continue;
    DifTexel x{};
    x.L[0] = L.r;
    x.L[1] = L.g;
    x.L[2] = L.b;
    const Vector3d c = env.texel_center(t).normalized();
    double r = 0;
    for (int a = 0; a <= 1; ++a)
      for (int b = 0; b <= 1; ++b)
        r = std::max(r, std::acos(std::clamp(c.dot(env.sample_texel(t, a * 0.999999, b * 0.999999)), -1.0, 1.0)));
    for (int k = 0; k < 3; ++k) {
      x.m[k] = m[size_t(t)][k];
      x.c[k] = c[k];
    }
    x.r = std::min(1.5 * r + 1e-6, std::numbers::pi / 2);
    x.sin_r = std::sin(x.r);
    x.index = t;
    tex.push_back(x);
  }
  return tex;
}

// Adds texel x's L ∫ H(ω, n) (n·ω) dω to e: its exact moment when wholly above the horizon of n,
// nothing when wholly below, 4×4 sub-samples when cut (O((h/4)²) per cut texel).
inline void add_texel(const EnvMap& env, const Vector3d& n, const DifTexel& x, double e[3]) {
  const double cn = n.x() * x.c[0] + n.y() * x.c[1] + n.z() * x.c[2];
  double w;
  if (cn >= x.sin_r) {
    w = n.x() * x.m[0] + n.y() * x.m[1] + n.z() * x.m[2];
  } else if (cn <= -x.sin_r) {
    return;
  } else {
    constexpr int kS = 4;
    Vector3d d[kS * kS];
    env.sample_texel_grid(x.index, kS, d);
    double acc = 0;
    for (const Vector3d& di : d) acc += std::max(0.0, n.dot(di));
    w = acc * env.texel_solid_angle(x.index) / (kS * kS);
  }
  e[0] += x.L[0] * w;
  e[1] += x.L[1] * w;
  e[2] += x.L[2] * w;
}

} // namespace

std::vector<float> irradiance_cube(const EnvMap& env, int size) {
  PRT_CHECK(size >= 1);
  std::vector<float> out(size_t(6) * size_t(size) * size_t(size) * 3, 0.0f);
  if (env.texel_count() == 0) {  // constant L: E = π L for every normal
    const Rgb L = env.radiance(Vector3d::UnitY());
    for (size_t i = 0; i < out.size(); i += 3) {
      out[i] = float(std::numbers::pi * L.r);
      out[i + 1] = float(std::numbers::pi * L.g);
      out[i + 2] = float(std::numbers::pi * L.b);
    }
    return out;
  }
  const std::vector<DifTexel> tex = dif_texels(env, texel_moments(env));
  // Cells: texels grouped by the direction of their centre on a coarse 64 × 32 lat-long grid,
  // each with the sum of its texels' L_c ∫ω dω and a cone (axis, half-angle R) that holds every
  // texel's own cone: R = max_t ∠(axis, c_t) + r_t. A cell wholly above the horizon of n (n·axis
  // ≥ sin R) adds its sum, exactly what its texels' "wholly above" branch would add one by one;
  // wholly below, nothing; only the cells the horizon crosses are visited texel by texel. Same
  // numbers up to summation order, ~20× fewer texel visits per normal.
  constexpr int kCellsPhi = 64, kCellsTheta = 32;
  auto cell_of = [&](const DifTexel& x) {
    const double th = std::acos(std::clamp(x.c[1], -1.0, 1.0)), ph = std::atan2(x.c[0], x.c[2]) + std::numbers::pi;
    const int i = std::min(kCellsTheta - 1, int(th / std::numbers::pi * kCellsTheta));
    const int j = std::min(kCellsPhi - 1, int(ph / (2 * std::numbers::pi) * kCellsPhi));
    return i * kCellsPhi + j;
  };
  std::vector<int> cell(tex.size());
  for (size_t k = 0; k < tex.size(); ++k) cell[k] = cell_of(tex[k]);
  std::vector<size_t> order(tex.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return cell[a] < cell[b]; });
  std::vector<DifTexel> sorted;
  sorted.reserve(tex.size());
  for (size_t k : order) sorted.push_back(tex[k]);
  struct Cell {
    size_t begin = 0, end = 0;
    double axis[3] = {0, 0, 0}, sin_R = 1, S[3][3] = {};  // S[c][xyz] = Σ L_c ∫ω dω
    bool bounded = false;                                    // R < π/2: can be wholly above or below
  };
  std::vector<Cell> cells;
  for (size_t k = 0; k < sorted.size();) {
    Cell q;
    q.begin = k;
    const int id = cell[order[k]];
    Vector3d sum(0, 0, 0);
    while (k < sorted.size() && cell[order[k]] == id) {
      const DifTexel& x = sorted[k];
      sum += Vector3d(x.c[0], x.c[1], x.c[2]);
      for (int c = 0; c < 3; ++c)
        for (int a = 0; a < 3; ++a) q.S[c][a] += x.L[c] * x.m[a];
      ++k;
    }
    q.end = k;
    const Vector3d axis = sum.normalized();
    double R = 0;
    for (size_t t = q.begin; t < q.end; ++t) {
      const DifTexel& x = sorted[t];
      R = std::max(R, std::acos(std::clamp(axis.dot(Vector3d(x.c[0], x.c[1], x.c[2])), -1.0, 1.0)) + x.r);
    }
    R += 1e-9;  // acos rounding
    q.bounded = sum.norm() > 0 && R < std::numbers::pi / 2;
    for (int a = 0; a < 3; ++a) q.axis[a] = axis[a];
    q.sin_R = std::sin(std::min(R, std::numbers::pi / 2));
    cells.push_back(q);
  }

  tbb::parallel_for(0, 6 * size * size, [&](int idx) {
    const int face = idx / (size * size), row = (idx / size) % size, col = idx % size;
    const Vector3d n = cube_direction(face, row, col, size);
    double e[3] = {0, 0, 0};
    for (const Cell& q : cells) {
      if (q.bounded) {
        const double cn = n.x() * q.axis[0] + n.y() * q.axis[1] + n.z() * q.axis[2];
        if (cn >= q.sin_R) {  // wholly above: every texel's exact moment
          for (int c = 0; c < 3; ++c) e[c] += n.x() * q.S[c][0] + n.y() * q.S[c][1] + n.z() * q.S[c][2];
          continue;
        }
        if (cn <= -q.sin_R) continue;  // wholly below
      }
      for (size_t t = q.begin; t < q.end; ++t) add_texel(env, n, sorted[t], e);
    }
    for (int c = 0; c < 3; ++c) out[size_t(idx) * 3 + size_t(c)] = float(e[c]);
  });
  return out;
}

std::vector<float> irradiance_cube_reference(const EnvMap& env, int size) {
  PRT_CHECK(size >= 1 && env.texel_count() > 0);
  std::vector<float> out(size_t(6) * size_t(size) * size_t(size) * 3, 0.0f);
  const std::vector<DifTexel> tex = dif_texels(env, texel_moments(env));
  tbb::parallel_for(0, 6 * size * size, [&](int idx) {
    const Vector3d n = cube_direction(idx / (size * size), (idx / size) % size, idx % size, size);
    double e[3] = {0, 0, 0};
    for (const DifTexel& x : tex) add_texel(env, n, x, e);
    for (int c = 0; c < 3; ++c) out[size_t(idx) * 3 + size_t(c)] = float(e[c]);
  });
  return out;
}

Eigen::Vector3d shell_direction(int i_theta, int n_theta, int j_phi, int n_phi) {
  const double th = std::numbers::pi * i_theta / std::max(n_theta - 1, 1), ph = 2 * std::numbers::pi * j_phi / n_phi;
  return {std::sin(th) * std::sin(ph), std::cos(th), std::sin(th) * std::cos(ph)};
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

Fiv occluded_fiv(const SilhouetteIntegrator& integrator, const Vector3d& position, bool* inside) {
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

FivShells bake_fiv_shells(const Mesh& occluder, const Topology& topology, const EnvMap& env, const ShellSpec& spec,
                          const Monitor& monitor) {
  PRT_CHECK(spec.n_phi >= 1 && spec.n_theta >= 2 && spec.n_rho >= 1 && spec.fraction > 0 && spec.inner > 0);
  FivShells out;
  bounding_sphere(occluder, out.centre, out.radius);
  out.n_phi = spec.n_phi;
  out.n_theta = spec.n_theta;
  ProductRequest req;
  req.radiance = &env;
  req.visibility_order = 1;
  const SilhouetteIntegrator integrator(occluder, topology, req, {silhouette_isolines(spec.silhouette_k), 1});
  // The scale the occluded FIV is compared with: ∫ L_c dω, the full-sphere irradiance. (|F^env|
  // itself cancels to 0 for a uniform sky, so a fraction of it is ill-posed.)
  double env_norm[3] = {0, 0, 0};
  if (env.texel_count() == 0) {
    const Rgb L = env.radiance(Vector3d::UnitY());
    env_norm[0] = 4 * std::numbers::pi * L.r;
    env_norm[1] = 4 * std::numbers::pi * L.g;
    env_norm[2] = 4 * std::numbers::pi * L.b;
  }
  for (int t = 0; t < env.texel_count(); ++t) {
    const Rgb L = env.texel_value(t);
    const double w = env.texel_solid_angle(t);
    env_norm[0] += L.r * w;
    env_norm[1] += L.g * w;
    env_norm[2] += L.b * w;
  }
  const double R = std::max(out.radius, 1e-30);
  const double rho0 = spec.inner * R, rho_far = std::max(R / (2 * std::sqrt(spec.fraction)), 2 * rho0);
  const double g = spec.n_rho > 1 ? std::pow(rho_far / rho0, 1.0 / (spec.n_rho - 1)) : 1.0;
  const size_t per_shell = size_t(spec.n_theta) * size_t(spec.n_phi);
  Task progress(monitor, "baking FIV shells", uint64_t(spec.n_rho) * per_shell);
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 0; k < spec.n_rho; ++k) {
    const double rho = rho0 * std::pow(g, k);
    std::vector<float> shell(per_shell * 9);
    std::vector<uint8_t> valid(per_shell);
    std::vector<double> ratio(per_shell, 0.0);
    tbb::parallel_for(size_t(0), per_shell, [&](size_t idx) {
      const int i = int(idx / size_t(spec.n_phi)), j = int(idx % size_t(spec.n_phi));
      bool inside = false;
      const Fiv f = occluded_fiv(integrator, out.centre + rho * shell_direction(i, spec.n_theta, j, spec.n_phi), &inside);
      double r = 0;
      for (int c = 0; c < 3; ++c) {
        const double nf = std::sqrt(f[size_t(3 * c)] * f[size_t(3 * c)] + f[size_t(3 * c + 1)] * f[size_t(3 * c + 1)] +
                                    f[size_t(3 * c + 2)] * f[size_t(3 * c + 2)]);
        if (env_norm[c] > 0) r = std::max(r, nf / env_norm[c]);
      }
      ratio[idx] = inside ? 0.0 : r;  // offsets inside the geometry say nothing about distance
      for (int q = 0; q < 9; ++q) shell[idx * 9 + size_t(q)] = float(f[size_t(q)]);
      valid[idx] = inside ? 0 : 1;
      progress.advance();
    });
    out.radii.push_back(rho);
    out.shells.insert(out.shells.end(), shell.begin(), shell.end());
    out.valid.insert(out.valid.end(), valid.begin(), valid.end());
    out.integrals += per_shell;
    // Far enough (and outside the bounding sphere, so never inside the occluder): stop.
    if (rho >= R && *std::max_element(ratio.begin(), ratio.end()) < spec.fraction) break;
  }
  progress.finish();
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

FivErrorReport fiv_error_report(const Mesh& occluder, const Topology& topology, const EnvMap& env, const FivShells& sh,
                                const Fiv& fenv, size_t points, uint64_t seed) {
  ProductRequest req;
  req.radiance = &env;
  req.visibility_order = 1;
  const QmcIntegrator qmc(occluder, topology, req, {IntegratorSpec::kSilhouetteReferenceRays, mix64(seed ^ 0x66697672656675ull)});
  const size_t per_shell = size_t(sh.n_theta) * size_t(sh.n_phi), total = sh.radii.size() * per_shell;
  const auto picks = seeded_sample(uint32_t(total), points, seed);
  std::vector<double> err2(picks.size(), 0.0), se2(picks.size(), 0.0), maxe(picks.size(), 0.0);
  const auto r0 = std::chrono::steady_clock::now();
  tbb::parallel_for(size_t(0), picks.size(), [&](size_t q) {
    const size_t idx = picks[q], k = idx / per_shell, ij = idx % per_shell;
    const int i = int(ij / size_t(sh.n_phi)), j = int(ij % size_t(sh.n_phi));
    Fiv se;
    const Fiv ref = qmc_occluded_fiv(qmc, fenv, sh.centre + sh.radii[k] * shell_direction(i, sh.n_theta, j, sh.n_phi), idx, &se);
    for (size_t x = 0; x < 9; ++x) {
      const double d = double(sh.shells[idx * 9 + x]) - ref[x];
      err2[q] += d * d;
      se2[q] += se[x] * se[x];
      maxe[q] = std::max(maxe[q], std::abs(d));
    }
  });
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
