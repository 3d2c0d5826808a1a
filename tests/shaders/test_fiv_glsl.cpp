// runtime/shaders/fiv.glsl and fiv.hlsl run as Vulkan compute shaders (lavapipe on CI; every test
// once per language, fiv_eval.comp and fiv_eval.hlsl, the same tolerances) against the C++ core
// (prt::shade::lookup_fiv, lookup_difmap, partial_factor, occluded_irradiance, shade_fiv,
// shade_fiv_self) and against a double-precision transcription of the contract
// (<prtshade/fiv.h>), on synthetic occluders: random shells with invalid samples (one cell
// wholly invalid), several grid sizes including the minimal 1 × 2 × 1, two with surface-following
// shells (random r_surf; their valid masks must not be read), receivers at the poles,
// across the φ seam, inside the first shell, at ρ = 0 and beyond the last shell.
//
// Tolerances. Both implementations round the same float inputs; their results differ through
// (a) the grid coordinates (θ, φ, ρ) they compute — shaders: A&S atan2 + float rounding, within
//     16 ulps of π in θ and of 2π in φ and 8 ulps of ρ; C++: the same bounds plus acos(d_y) near
//     the poles, whose error is min(2ε/sin θ, 2√ε) (ε = 2^-24: d_y is rounded to float and
//     acos' = −1/sin θ) — and
// (b) the rounding of the weighted sums, ≤ 32 ε × the largest |sample| involved.
// (a) is turned into a value bound by evaluating the double reference at the corners of the box
// of coordinate perturbations and taking twice the largest change (the lookup is piecewise
// multilinear; the factor 2 covers a texel boundary inside the box). So a tolerance is large
// exactly where the lookup is ill-conditioned (renormalisation over nearly weightless valid
// samples, a wholly invalid face) and ~1e-6 relative elsewhere. The shading functions compose
// these bounds through their formulas (stated where they are computed).
#include "shader_test.h"

#include <prtshade/fiv.h>

#include <Imath/half.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>

namespace {

using prt::test::kFloatEps;
constexpr double kPi = 3.14159265358979323846;
using Fiv9 = std::array<double, 9>;

// ---------------------------------------------------------------------------------------------
// Synthetic data

struct SynthOccluder {
  float centre[3];
  float radius;
  int n_rho, n_theta, n_phi;
  std::vector<float> radii, shells;
  std::vector<uint8_t> valid;
  int scheme = prt::shade::kFivRadialGeometric;
  std::vector<float> surface;  // [n_theta][n_phi], surface scheme
  std::vector<float> cones;    // the tight proxy's table [n_rho][n_theta][n_phi][4], or empty
  prt::shade::FivOccluder view() const {
    return {{centre[0], centre[1], centre[2]}, radius, n_rho, n_theta, n_phi, radii.data(), shells.data(), valid.data(),
            scheme, surface.empty() ? nullptr : surface.data(), cones.empty() ? nullptr : cones.data()};
  }
  float r_surf(int i, int j) const { return surface[static_cast<std::size_t>(i * n_phi + j)]; }
  float max_surface() const { return surface.empty() ? 0.0f : *std::max_element(surface.begin(), surface.end()); }
  std::size_t sample(int k, int i, int j) const {
    return (static_cast<std::size_t>(k) * static_cast<std::size_t>(n_theta) + static_cast<std::size_t>(i)) *
               static_cast<std::size_t>(n_phi) +
           static_cast<std::size_t>(j);
  }
};

// Random shells: per channel a smooth decaying field plus noise (values of both signs, as
// occluded FIVs have), the pole rows constant in φ (they are one point), ~20% invalid samples.
SynthOccluder make_occluder(std::mt19937& rng, const std::array<float, 3>& centre, float radius, int n_rho,
                            int n_theta, int n_phi) {
  SynthOccluder o{{centre[0], centre[1], centre[2]}, radius, n_rho, n_theta, n_phi, {}, {}, {}, {}};
  std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
  for (int k = 0; k < n_rho; ++k) o.radii.push_back(radius * 0.5f * std::pow(2.0f, float(k) * 3.0f / float(std::max(1, n_rho - 1))));
  o.shells.resize(o.sample(n_rho, 0, 0) * 9);
  o.valid.resize(o.sample(n_rho, 0, 0));
  std::bernoulli_distribution invalid(0.2);
  for (int k = 0; k < n_rho; ++k)
    for (int i = 0; i < n_theta; ++i)
      for (int j = 0; j < n_phi; ++j) {
        const bool pole = i == 0 || i == n_theta - 1;
        const std::size_t idx = o.sample(k, i, j);
        if (pole && j > 0) {  // one point: copy column 0
          std::copy_n(&o.shells[o.sample(k, i, 0) * 9], 9, &o.shells[idx * 9]);
          o.valid[idx] = o.valid[o.sample(k, i, 0)];
          continue;
        }
        const float scale = 3.0f / (1.0f + float(k));
        for (int e = 0; e < 9; ++e) o.shells[idx * 9 + static_cast<std::size_t>(e)] = scale * (0.6f + 0.4f * uni(rng)) * uni(rng);
        o.valid[idx] = invalid(rng) ? 0 : 1;
      }
  return o;
}

// The same occluder with surface-following shells (prtshade/fiv.h): r_surf random in
// [0.2 R, 0.9 R] (one value per pole row), the radii (geometric already) read as offsets; its
// invalid samples stay in the mask, which the surface scheme must not read.
SynthOccluder make_surface_occluder(std::mt19937& rng, const std::array<float, 3>& centre, float radius, int n_rho,
                                    int n_theta, int n_phi) {
  SynthOccluder o = make_occluder(rng, centre, radius, n_rho, n_theta, n_phi);
  o.scheme = prt::shade::kFivRadialSurface;
  std::uniform_real_distribution<float> uni(0.2f * radius, 0.9f * radius);
  for (int i = 0; i < n_theta; ++i)
    for (int j = 0; j < n_phi; ++j)
      o.surface.push_back((i == 0 || i == n_theta - 1) && j > 0 ? o.surface[static_cast<std::size_t>(i * n_phi)] : uni(rng));
  for (float& r : o.radii) r *= 0.05f;  // offsets from 0.025 R
  return o;
}

// Packed buffers of fiv.glsl (its header comment): the occluder table (64 bytes each), radii,
// shells, valid bytes packed 4 per uint (little-endian) from a word boundary, DifMap.
struct GpuOccluder {
  float centre_radius[4];
  int32_t dims[4];
  uint32_t offsets[4];
  uint32_t extra[4];
};
static_assert(sizeof(GpuOccluder) == 64, "std430 PrtFivOccluder is 64 bytes");

struct GpuScene {
  std::vector<std::byte> occluders, radii, shells, valid, difmap, cones, halves;
};

// half_tables: every shell and cone table as binary16 bits in the halves buffer (fiv.glsl,
// PRT_FIV_HALVES_BINDING; extra.z bits 0 and 1) instead of floats; the values must be halves.
GpuScene pack(const std::vector<SynthOccluder>& occ, int difmap_size, const std::vector<float>& texels,
              bool half_tables = false) {
  std::vector<GpuOccluder> table;
  std::vector<float> radii, shells, cones;
  std::vector<uint16_t> halves;
  std::vector<uint8_t> valid;
  const auto put_halves = [&halves](const std::vector<float>& values) {
    for (float v : values) {
      const Imath::half h(v);
      EXPECT_EQ(float(h), v) << "pack: a half table needs half values";
      halves.push_back(h.bits());
    }
  };
  for (const SynthOccluder& o : occ) {
    const bool half_cones = half_tables && !o.cones.empty();
    const uint32_t shells_at = uint32_t(half_tables ? halves.size() : shells.size());
    if (half_tables) put_halves(o.shells);
    else shells.insert(shells.end(), o.shells.begin(), o.shells.end());
    const uint32_t cones_at = uint32_t(half_cones ? halves.size() : cones.size());
    if (half_cones) put_halves(o.cones);
    else cones.insert(cones.end(), o.cones.begin(), o.cones.end());
    GpuOccluder g{{o.centre[0], o.centre[1], o.centre[2], o.radius},
                  {o.n_rho, o.n_theta, o.n_phi, o.scheme},
                  {uint32_t(radii.size()), shells_at, uint32_t(valid.size() / 4), uint32_t(radii.size() + o.radii.size())},
                  {o.cones.empty() ? 0u : 1u, cones_at, (half_tables ? 1u : 0u) | (half_cones ? 2u : 0u), 0}};
    table.push_back(g);
    radii.insert(radii.end(), o.radii.begin(), o.radii.end());
    radii.insert(radii.end(), o.surface.begin(), o.surface.end());  // surface scheme: offsets.w
    valid.insert(valid.end(), o.valid.begin(), o.valid.end());
    valid.resize((valid.size() + 3) / 4 * 4, 0);  // next occluder starts on a word boundary
  }
  GpuScene s;
  s.occluders = prt::test::to_bytes(table);
  s.radii = prt::test::to_bytes(radii);
  s.valid = prt::test::to_bytes(valid);  // little-endian host: the bytes are the packed words
  cones.resize(std::max<std::size_t>(cones.size(), 4), 0.0f);  // a buffer is bound even without cones
  s.cones = prt::test::to_bytes(cones);
  shells.resize(std::max<std::size_t>(shells.size(), 4), 0.0f);  // and without float shells
  s.shells = prt::test::to_bytes(shells);
  halves.resize(std::max<std::size_t>((halves.size() + 1) / 2 * 2, 4), 0);  // whole words; one bound even without halves
  s.halves = prt::test::to_bytes(halves);  // little-endian host: the bytes are the packed words
  const uint32_t header[4] = {uint32_t(difmap_size), 0, 0, 0};
  s.difmap.resize(16 + texels.size() * sizeof(float));
  std::memcpy(s.difmap.data(), header, 16);
  std::memcpy(s.difmap.data() + 16, texels.data(), texels.size() * sizeof(float));
  return s;
}

// ---------------------------------------------------------------------------------------------
// Double-precision transcription of the contract

struct FivRef {
  Fiv9 v{};
  double max_sample = 0;  // largest |stored value| among the 8 neighbours (× falloff)
  bool plain = false;     // no valid neighbour carries weight: plain trilinear
};

// The lookup at continuous grid coordinates (t, u, ρ): t clamps to [0, Nθ − 1], u wraps.
FivRef fiv_at(const SynthOccluder& o, double t, double u, double rho) {
  t = std::clamp(t, 0.0, double(o.n_theta - 1));
  const int i0 = std::min(int(std::floor(t)), o.n_theta - 2);
  const double ft = t - i0;
  u = std::fmod(u, double(o.n_phi));
  if (u < 0) u += o.n_phi;
  const int ju = std::min(int(std::floor(u)), o.n_phi);
  const double fu = u - ju;
  const int j0 = ju % o.n_phi, j1 = (ju + 1) % o.n_phi;
  const int last = o.n_rho - 1;
  // Surface scheme: x = τ = ρ − r_s with r_s bilinear in the cell; geometric: x = ρ, r_s = 0.
  const bool surface = o.scheme == prt::shade::kFivRadialSurface;
  const double r_s = surface ? (1 - ft) * ((1 - fu) * o.r_surf(i0, j0) + fu * o.r_surf(i0, j1)) +
                                   ft * ((1 - fu) * o.r_surf(i0 + 1, j0) + fu * o.r_surf(i0 + 1, j1))
                             : 0.0;
  const double x = rho - r_s;
  int k0 = 0, k1 = 0;
  double fr = 0, falloff = 1;
  if (x <= o.radii[0] || last == 0) {
    if (x > o.radii[0]) falloff = ((r_s + o.radii[0]) / rho) * ((r_s + o.radii[0]) / rho);
  } else if (x >= o.radii[static_cast<std::size_t>(last)]) {
    k0 = k1 = last;
    const double q = (r_s + o.radii[static_cast<std::size_t>(last)]) / rho;
    falloff = q * q;
  } else {
    k1 = 1;
    while (o.radii[static_cast<std::size_t>(k1)] <= x) ++k1;
    k0 = k1 - 1;
    fr = (x - o.radii[static_cast<std::size_t>(k0)]) /
         (double(o.radii[static_cast<std::size_t>(k1)]) - o.radii[static_cast<std::size_t>(k0)]);
  }
  const int ks[2] = {k0, k1}, is[2] = {i0, i0 + 1}, js[2] = {j0, j1};
  const double wk[2] = {1 - fr, fr}, wi[2] = {1 - ft, ft}, wj[2] = {1 - fu, fu};
  Fiv9 plain{}, masked{};
  double mw = 0, biggest = 0;
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      for (int c = 0; c < 2; ++c) {
        const double w = wk[a] * wi[b] * wj[c];
        const std::size_t idx = o.sample(ks[a], is[b], js[c]);
        for (int e = 0; e < 9; ++e) {
          const double v = o.shells[idx * 9 + static_cast<std::size_t>(e)];
          biggest = std::max(biggest, std::abs(v));
          plain[static_cast<std::size_t>(e)] += w * v;
          if (o.valid[idx]) masked[static_cast<std::size_t>(e)] += w * v;
        }
        if (o.valid[idx]) mw += w;
      }
  if (surface) mw = 0, masked = plain;  // no valid mask: the plain trilinear value
  FivRef r;
  for (std::size_t e = 0; e < 9; ++e) r.v[e] = (mw > 0 ? masked[e] / mw : plain[e]) * falloff;
  r.max_sample = biggest * falloff;
  r.plain = !surface && !(mw > 0);
  return r;
}

struct Coords {
  double t, u, rho, theta;
};
Coords coords_of(const SynthOccluder& o, const float s[3]) {
  const double x = s[0], y = s[1], z = s[2];
  const double rho = std::sqrt(x * x + y * y + z * z);
  const double theta = std::atan2(std::hypot(x, z), y);
  double phi = std::atan2(x, z);
  if (phi < 0) phi += 2 * kPi;
  return {theta / kPi * (o.n_theta - 1), phi / (2 * kPi) * o.n_phi, rho, theta};
}

// Coordinate error budgets (radians, radians, world units) of one implementation.
struct Budget {
  double theta, phi, rho;
};
Budget shader_budget(const Coords& c) { return {16 * kFloatEps * kPi, 16 * kFloatEps * 2 * kPi, 8 * kFloatEps * c.rho}; }
Budget core_budget(const Coords& c) {
  const double pole = std::min(2 * kFloatEps / std::max(std::sin(c.theta), 1e-300), 2 * std::sqrt(kFloatEps));
  return {16 * kFloatEps * kPi + pole, 16 * kFloatEps * 2 * kPi, 4 * kFloatEps * c.rho};
}
Budget operator+(const Budget& a, const Budget& b) { return {a.theta + b.theta, a.phi + b.phi, a.rho + b.rho}; }

// Per-component tolerance of a lookup at s under coordinate errors `b` (see the file comment).
Fiv9 fiv_tolerance(const SynthOccluder& o, const float s[3], const Budget& b) {
  const Coords c = coords_of(o, s);
  const double dt = b.theta / kPi * (o.n_theta - 1), du = b.phi / (2 * kPi) * o.n_phi;
  // Surface scheme: τ = ρ − r_s rounds within 8 ε max(r_surf) more (r_s's bilinear sums, the
  // subtraction), which moves the radial coordinate like an error in ρ.
  const double drho = b.rho + 8 * kFloatEps * o.max_surface();
  const FivRef centre = fiv_at(o, c.t, c.u, c.rho);
  Fiv9 tol{};
  double biggest = centre.max_sample;
  for (int corner = 0; corner < 8; ++corner) {
    const FivRef r = fiv_at(o, c.t + (corner & 1 ? dt : -dt), c.u + (corner & 2 ? du : -du),
                            c.rho + (corner & 4 ? drho : -drho));
    biggest = std::max(biggest, r.max_sample);
    for (std::size_t e = 0; e < 9; ++e) tol[e] = std::max(tol[e], 2 * std::abs(r.v[e] - centre.v[e]));
  }
  for (double& t : tol) t += 32 * kFloatEps * biggest;
  return tol;
}

// DifMap in double: face of the largest |component| (ties X, Y, Z; zero → +Y), face coordinates
// (s, t) in [−1, 1], bilinear, clamped to the outermost texel centres.
struct FacePoint {
  int face;
  double s, t;
};
FacePoint difmap_face(const double n[3]) {
  const double ax = std::abs(n[0]), ay = std::abs(n[1]), az = std::abs(n[2]);
  if (ax >= ay && ax >= az && ax > 0) return {n[0] > 0 ? 0 : 1, (n[0] > 0 ? -n[2] : n[2]) / ax, -n[1] / ax};
  if (ay >= az && ay > 0) return {n[1] > 0 ? 2 : 3, n[0] / ay, (n[1] > 0 ? n[2] : -n[2]) / ay};
  if (az > 0) return {n[2] > 0 ? 4 : 5, (n[2] > 0 ? n[0] : -n[0]) / az, -n[1] / az};
  return {2, 0, 0};
}
std::array<double, 3> difmap_bilinear(int size, const std::vector<float>& texels, const FacePoint& fp) {
  auto axis = [&](double v, int& q0, int& q1, double& f) {
    const double q = std::clamp((v + 1) * 0.5 * size - 0.5, 0.0, double(size - 1));
    q0 = std::min(int(q), size - 1);
    q1 = std::min(q0 + 1, size - 1);
    f = q - q0;
  };
  int q0, q1, r0, r1;
  double fq, fr;
  axis(fp.s, q0, q1, fq);
  axis(fp.t, r0, r1, fr);
  auto texel = [&](int r, int q, int c) {
    return double(
        texels[((static_cast<std::size_t>(fp.face) * size + r) * size + q) * 3 + static_cast<std::size_t>(c)]);
  };
  std::array<double, 3> out{};
  for (int c = 0; c < 3; ++c) {
    const double top = texel(r0, q0, c) + fq * (texel(r0, q1, c) - texel(r0, q0, c));
    const double bottom = texel(r1, q0, c) + fq * (texel(r1, q1, c) - texel(r1, q0, c));
    out[static_cast<std::size_t>(c)] = top + fr * (bottom - top);
  }
  return out;
}
std::array<double, 3> difmap_at(int size, const std::vector<float>& texels, const double n[3]) {
  return difmap_bilinear(size, texels, difmap_face(n));
}

// DifMap tolerance. Both implementations pick the face by exact comparisons of the same floats,
// so they pick the same face (ties included); they differ only in (s, t), which the division
// and the texel-coordinate arithmetic round within 16 ε (s, t in [−1, 1]). So: twice the largest
// change over the box (s ± 16 ε, t ± 16 ε) in that face, plus 16 ε × the largest texel for the
// bilinear sums.
std::array<double, 3> difmap_tolerance(int size, const std::vector<float>& texels, const float n[3]) {
  const double nd[3] = {n[0], n[1], n[2]};
  const FacePoint fp = difmap_face(nd);
  const auto centre = difmap_bilinear(size, texels, fp);
  double biggest = 0;
  for (float v : texels) biggest = std::max(biggest, double(std::abs(v)));
  std::array<double, 3> tol{};
  const double d = 16 * kFloatEps;
  for (int corner = 0; corner < 4; ++corner) {
    const auto r = difmap_bilinear(size, texels, {fp.face, fp.s + (corner & 1 ? d : -d), fp.t + (corner & 2 ? d : -d)});
    for (std::size_t c = 0; c < 3; ++c) tol[c] = std::max(tol[c], 2 * std::abs(r[c] - centre[c]));
  }
  for (double& t : tol) t += 16 * kFloatEps * biggest;
  return tol;
}

// ---------------------------------------------------------------------------------------------
// The scene

struct Receiver {
  float p[4];
  float n[4];
  uint32_t info[4];  // occluder, first, count; w (unused by the kernel): 1 = random receiver
};
static_assert(sizeof(Receiver) == 48, "std430 Receiver is 48 bytes");

struct PushBlock {
  uint32_t count;
  float env[9];
};

// Occluders from this index on carry a cone table (make_scene).
constexpr std::size_t kFirstCone = 7;

struct Scene {
  std::vector<SynthOccluder> occ;
  int difmap_size = 5;
  std::vector<float> texels;
  float env[9];
  // Occluder groups for shade_fiv: {first, count}.
  std::vector<std::array<uint32_t, 2>> groups;
};

Scene make_scene() {
  std::mt19937 rng(404u);
  Scene sc;
  sc.occ.push_back(make_occluder(rng, {0.3f, -0.2f, 0.5f}, 1.0f, 4, 7, 10));
  // A wholly invalid cell (both shells 0–1, rows 3–4, columns 2–3): plain trilinear inside it.
  for (int k = 0; k < 2; ++k)
    for (int i = 3; i < 5; ++i)
      for (int j = 2; j < 4; ++j) sc.occ[0].valid[sc.occ[0].sample(k, i, j)] = 0;
  sc.occ.push_back(make_occluder(rng, {1.6f, 0.1f, 0.2f}, 0.7f, 3, 5, 8));
  sc.occ.push_back(make_occluder(rng, {-0.2f, 0.4f, -1.1f}, 0.5f, 1, 2, 1));  // minimal grid
  sc.occ.push_back(sc.occ[0]);                                                 // a duplicate: O = ½
  sc.occ.push_back(make_occluder(rng, {-2.0f, 1.5f, 2.5f}, 0.3f, 5, 9, 16));
  // Surface-following shells (occluders 5, 6), one with a wholly invalid cell the mask must not touch.
  // (Drawn from a copy of the generator: the cone occluders below get the values they get without them.)
  std::mt19937 cone_rng = rng;
  sc.occ.push_back(make_surface_occluder(rng, {0.8f, 0.3f, -0.6f}, 0.9f, 6, 9, 12));
  for (int k = 0; k < 2; ++k)
    for (int i = 3; i < 5; ++i)
      for (int j = 2; j < 4; ++j) sc.occ[5].valid[sc.occ[5].sample(k, i, j)] = 0;
  sc.occ.push_back(make_surface_occluder(rng, {-0.9f, 0.2f, 1.2f}, 0.6f, 1, 3, 4));  // one shell
  // Occluders 7–9 carry a cone table (the tight proxy): the exact cone of a ball of radius 0.6 R
  // about the centre (fiv.h "Tight proxies"); groups of them are checked by ShadeFivConeMatchesCore.
  sc.occ.push_back(make_occluder(cone_rng, {0.2f, 0.3f, 0.4f}, 1.0f, 4, 9, 16));
  sc.occ.push_back(make_occluder(cone_rng, {1.4f, 0.6f, -0.3f}, 0.8f, 3, 7, 12));
  sc.occ.push_back(make_occluder(cone_rng, {-0.9f, 0.2f, 1.2f}, 0.6f, 4, 9, 16));
  // Occluder 9's poles (one point per shell: all columns): invalid on the last shell, valid on the
  // one before, so the masked lookup jumps at ρ = the last radius (2.4). The pole receivers at
  // s = (0, ∓2.4, 0) land on that jump: the core forms ρ = |p − centre| in double (2.40000005 <
  // the radius 2.40000010 in float: the last two shells, the valid one renormalised), the shaders
  // in float (the radius itself: the last shell only, plain trilinear).
  for (int i : {0, 8})
    for (int j = 0; j < 16; ++j) {
      sc.occ[9].valid[sc.occ[9].sample(3, i, j)] = 0;
      sc.occ[9].valid[sc.occ[9].sample(2, i, j)] = 1;
    }
  for (std::size_t k = kFirstCone; k < sc.occ.size(); ++k) {
    SynthOccluder& o = sc.occ[k];
    const double r = 0.6 * o.radius;
    for (int kr = 0; kr < o.n_rho; ++kr)
      for (int i = 0; i < o.n_theta; ++i)
        for (int j = 0; j < o.n_phi; ++j) {
          const double th = kPi * i / (o.n_theta - 1), ph = 2 * kPi * j / o.n_phi, rho = o.radii[std::size_t(kr)];
          const double sa = std::min(1.0, r / rho), ca = std::sqrt((1 - sa) * (1 + sa)), len = kPi * sa * sa;
          const double d[3] = {std::sin(th) * std::sin(ph), std::cos(th), std::sin(th) * std::cos(ph)};
          for (int e = 0; e < 3; ++e) o.cones.push_back(float(-len * d[e]));
          o.cones.push_back(float(2 * kPi * (1 - ca)));
        }
  }
  sc.groups = {{0, 1}, {0, 2}, {0, 4}, {0, 5}, {1, 4}, {4, 1}, {2, 1}, {5, 1}, {3, 4}, {0, 7}, {7, 3}, {7, 1}, {8, 2}};
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  sc.texels.resize(6 * 5 * 5 * 3);
  for (float& t : sc.texels) t = 2.0f + 3.0f * uni(rng);
  for (float& e : sc.env) e = 4.0f * (uni(rng) - 0.5f);
  return sc;
}

std::vector<Receiver> make_receivers(const Scene& sc) {
  std::mt19937 rng(55u);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  auto unit = [&](double v[3]) {
    const double r = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int k = 0; k < 3; ++k) v[k] /= r;
  };
  std::vector<Receiver> out;
  auto add = [&](uint32_t o, const double s[3], const double n[3], uint32_t group, bool random) {
    const SynthOccluder& oc = sc.occ[o];
    Receiver r{};
    for (int k = 0; k < 3; ++k) {
      r.p[k] = float(oc.centre[k] + s[k]);
      r.n[k] = float(n[k]);
    }
    const auto& gr = sc.groups[group % sc.groups.size()];
    r.info[0] = o, r.info[1] = gr[0], r.info[2] = gr[1], r.info[3] = random ? 1 : 0;
    out.push_back(r);
  };
  uint32_t serial = 0;
  for (uint32_t o = 0; o < sc.occ.size(); ++o) {
    const SynthOccluder& oc = sc.occ[o];
    const double r_last = oc.radii.back() + oc.max_surface();
    // Random offsets: ρ from 0 to 2.5 × the last radius (inside the first shell, between
    // shells, beyond the last), random directions and normals.
    for (int i = 0; i < 400; ++i) {
      double d[3] = {g(rng), g(rng), g(rng)}, n[3] = {g(rng), g(rng), g(rng)};
      unit(d), unit(n);
      const double rho = 2.5 * r_last * uni(rng);
      const double s[3] = {rho * d[0], rho * d[1], rho * d[2]};
      add(o, s, n, serial++, true);
    }
    // Poles, near-poles, the φ seam (s_x → ±0 with s_z > 0: φ → 0 or 2π), exact radii, ρ = 0.
    for (int i = 0; i < 40; ++i) {
      const double rho = oc.radii[static_cast<std::size_t>(i) % oc.radii.size()] * (i % 3 == 0 ? 1.0 : 0.5 + uni(rng));
      const double tiny = std::pow(10.0, -1.0 - 6.0 * uni(rng));
      const double sign = i % 2 ? 1.0 : -1.0;
      double n[3] = {g(rng), g(rng), g(rng)};
      unit(n);
      const double poles[][3] = {{0, rho, 0}, {0, -rho, 0}, {tiny * rho, rho, 0.3 * tiny * rho},
                                 {sign * tiny * rho, 0.2 * rho, rho}, {sign * 1e-30, -0.5 * rho, rho}, {0, 0, 0}};
      for (const auto& s : poles) add(o, s, n, serial++, false);
    }
  }
  // Inside occluder 0's wholly invalid cell (shells 0–1, rows 3–4, columns 2–3): the plain
  // trilinear fallback.
  for (int i = 0; i < 20; ++i) {
    const SynthOccluder& oc = sc.occ[0];
    const double theta = (3.0 + uni(rng)) * kPi / (oc.n_theta - 1), phi = (2.0 + uni(rng)) * 2 * kPi / oc.n_phi;
    const double rho = oc.radii[0] + uni(rng) * (oc.radii[1] - oc.radii[0]);
    const double s[3] = {rho * std::sin(theta) * std::sin(phi), rho * std::cos(theta), rho * std::sin(theta) * std::cos(phi)};
    double n[3] = {g(rng), g(rng), g(rng)};
    unit(n);
    add(0, s, n, serial++, false);
  }
  // DifMap face edges and corners (ties), axis normals, a zero normal.
  const double h = std::sqrt(0.5), c3 = std::sqrt(1.0 / 3.0);
  const double special[][3] = {{1, 0, 0}, {0, -1, 0}, {0, 0, 1},  {h, h, 0},     {-h, 0, h},  {0, h, -h},
                               {c3, c3, c3}, {-c3, c3, -c3}, {0, 0, 0}, {0.5, 0.5, -h}};
  for (const auto& n : special) {
    const double s[3] = {0.7, 0.2, -0.4};
    add(0, s, n, serial++, false);
  }
  return out;
}

// ---------------------------------------------------------------------------------------------

class FivMirror : public prt::test::ShaderMirror {
protected:
  static void SetUpTestSuite() {
    scene_ = new Scene(make_scene());
    receivers_ = new std::vector<Receiver>(make_receivers(*scene_));
  }
  static void TearDownTestSuite() {
    delete scene_;
    delete receivers_;
    for (std::vector<float>*& r : results_) {
      delete r;
      r = nullptr;
    }
  }
  // The language's kernel runs once, on its first test; its results serve the others.
  void SetUp() override {
    std::vector<float>*& results = results_[static_cast<std::size_t>(GetParam())];
    if (!results) {
      results = new std::vector<float>(run(*scene_, false));
    }
    ASSERT_FALSE(results->empty()) << "the " << language() << " fiv_eval kernel did not run (see the failure above)";
  }
  // The kernel's results for every receiver on `scene` (empty when it did not run).
  std::vector<float> run(const Scene& scene, bool half_tables) const {
    GpuScene g = pack(scene.occ, scene.difmap_size, scene.texels, half_tables);
    auto in = prt::test::to_bytes(*receivers_);
    std::vector<std::byte> res(receivers_->size() * 36 * sizeof(float));
    PushBlock push{uint32_t(receivers_->size()), {}};
    std::copy_n(scene.env, 9, push.env);
    const bool ran = prt::test::run_kernel(
        kernel("fiv_eval"), {&g.occluders, &g.radii, &g.shells, &g.valid, &g.difmap, &in, &res, &g.cones, &g.halves},
        prt::test::push_bytes(push), 4 * uint32_t(receivers_->size()));
    return ran ? prt::test::from_bytes<float>(res) : std::vector<float>{};
  }

  static const float* result(std::size_t r) { return &(*results_[static_cast<std::size_t>(GetParam())])[36 * r]; }
  static prt::shade::DifMap difmap() { return {scene_->difmap_size, scene_->texels.data()}; }

  static Scene* scene_;
  static std::vector<Receiver>* receivers_;
  static std::array<std::vector<float>*, 2> results_;  // per prt::test::ShaderLanguage
};
Scene* FivMirror::scene_ = nullptr;
std::vector<Receiver>* FivMirror::receivers_ = nullptr;
std::array<std::vector<float>*, 2> FivMirror::results_ = {nullptr, nullptr};
PRT_SHADER_MIRROR_LANGUAGES(FivMirror);

// Half-float tables (prtshade/fiv.h "Half-float tables"; fiv.glsl PRT_FIV_HALVES_BINDING): the
// scene with every shell and cone value rounded to binary16, packed as halves, gives bit for bit
// what the same values packed as floats give — PRT_UNPACK_HALF is exact, and everything after the
// load is the same code. Subnormal halves, −0 and the largest half are among the values.
TEST_P(FivMirror, HalfTablesGiveWhatTheirFloatsGive) {
  Scene rounded = *scene_;
  for (SynthOccluder& o : rounded.occ) {
    for (float& v : o.shells) v = float(Imath::half(v));
    for (float& v : o.cones) v = float(Imath::half(v));
  }
  // Occluder 0's first samples (the receivers near it read them): subnormals (2^-24, the
  // smallest; −1023·2^-24, the largest), −0, 2^-14 (the smallest normal), 65504 and −2^-14 (1 + 2^-10).
  const float special[] = {0x1p-24f, -1023 * 0x1p-24f, -0.0f, 0x1p-14f, 65504.0f, -0x1.004p-14f};
  for (std::size_t k = 0; k < std::size(special); ++k)
    for (std::size_t s = 0; s < 4; ++s) rounded.occ[0].shells[9 * s + k] = special[k];
  const std::vector<float> floats = run(rounded, false), halves = run(rounded, true);
  ASSERT_FALSE(floats.empty());
  ASSERT_EQ(floats.size(), halves.size());
  std::size_t differ = 0, nonzero = 0;
  for (std::size_t i = 0; i < floats.size(); ++i) {
    differ += std::memcmp(&floats[i], &halves[i], sizeof(float)) != 0 ? 1 : 0;
    nonzero += floats[i] != 0 ? 1 : 0;
  }
  EXPECT_EQ(differ, 0u) << "of " << floats.size() << " results";
  EXPECT_GT(nonzero, floats.size() / 2);  // the comparison is not of zeros
}

// One lookup of occluder o from receiver point p: the offset as both implementations form it
// (float subtraction), its coordinates, the reference value and the shader-vs-core tolerance.
struct Lookup {
  float s[3];
  Coords c;
  FivRef ref;
  Fiv9 tol;
};
Lookup lookup_case(const SynthOccluder& o, const float p[3]) {
  Lookup l{};
  for (int k = 0; k < 3; ++k) l.s[k] = p[k] - o.centre[k];
  l.c = coords_of(o, l.s);
  l.ref = fiv_at(o, l.c.t, l.c.u, l.c.rho);
  l.tol = fiv_tolerance(o, l.s, shader_budget(l.c) + core_budget(l.c));
  return l;
}

// lookup_fiv: the shader vs the C++ core and vs the double transcription; the C++ core vs the
// transcription too (so a disagreement names the side that is off).
TEST_P(FivMirror, LookupFivMatchesCoreAndReference) {
  double worst_core = 0, worst_ref = 0;
  std::size_t checked = 0, ill_conditioned = 0, plain = 0, beyond = 0, surface = 0;
  std::vector<double> rel_tols;
  for (std::size_t r = 0; r < receivers_->size(); ++r) {
    const Receiver& rc = (*receivers_)[r];
    const SynthOccluder& o = scene_->occ[rc.info[0]];
    const Lookup l = lookup_case(o, rc.p);
    const float* s = l.s;
    const Coords& c = l.c;
    const FivRef& ref = l.ref;
    const Fiv9& tol_core = l.tol;
    const Fiv9 tol_ref = fiv_tolerance(o, s, shader_budget(c));
    const Fiv9 tol_core_ref = fiv_tolerance(o, s, core_budget(c));
    plain += ref.plain ? 1 : 0;
    beyond += c.rho > o.radii.back() ? 1 : 0;
    surface += o.scheme == prt::shade::kFivRadialSurface ? 1 : 0;
    float core[9];
    prt::shade::lookup_fiv(o.view(), s, core);
    const float* got = result(r);
    for (std::size_t e = 0; e < 9; ++e) {
      ASSERT_TRUE(std::isfinite(got[e])) << "receiver " << r;
      const double err_core = std::abs(got[e] - core[e]), err_ref = std::abs(got[e] - ref.v[e]);
      worst_core = std::max(worst_core, err_core / tol_core[e]);
      worst_ref = std::max(worst_ref, err_ref / tol_ref[e]);
      // Strength of the shader check on the random receivers (the special ones sit on purpose at
      // the poles, where an invalid pole sample makes the lookup jump): its tolerance against the
      // reference relative to the samples.
      if (rc.info[3] == 1) {
        if (tol_ref[e] > 1e-3 * std::max(1e-3, ref.max_sample)) ++ill_conditioned;
        rel_tols.push_back(tol_ref[e] / std::max(1e-3, ref.max_sample));
      }
      ++checked;
      ASSERT_LE(err_core, tol_core[e]) << "receiver " << r << " component " << e << " s = (" << s[0] << ", " << s[1]
                                       << ", " << s[2] << ") glsl " << got[e] << " core " << core[e];
      ASSERT_LE(err_ref, tol_ref[e]) << "receiver " << r << " component " << e << " glsl " << got[e] << " ref "
                                     << ref.v[e];
      ASSERT_LE(std::abs(core[e] - ref.v[e]), tol_core_ref[e]) << "C++ core vs reference: receiver " << r
                                                                 << " component " << e;
    }
  }
  std::sort(rel_tols.begin(), rel_tols.end());
  std::printf("%s lookup_fiv: %zu values; worst shader-core %.3f x tol, shader-reference %.3f x tol; tolerance / "
              "largest sample: median %.2g, 99%% %.2g; %zu values ill-conditioned (tol > 1e-3 x samples)\n",
              language(), checked, worst_core, worst_ref, rel_tols[rel_tols.size() / 2], rel_tols[rel_tols.size() * 99 / 100],
              ill_conditioned);
  // The bound must stay a float bound for nearly all samples, or the test proves little: only
  // lookups renormalised over nearly weightless valid samples may be ill-conditioned (the
  // wholly invalid cell and random invalid samples: a few percent of the cells).
  EXPECT_LT(double(ill_conditioned), 0.02 * double(rel_tols.size()));
  EXPECT_LT(rel_tols[rel_tols.size() / 2], 1e-4);
  std::printf("lookup_fiv: %zu receivers in the plain-trilinear fallback, %zu beyond the last shell\n", plain, beyond);
  EXPECT_GE(plain, 20u);  // the wholly invalid cell was visited
  EXPECT_GT(beyond, 500u);
  EXPECT_GE(surface, 2 * 640u);  // the surface-following occluders' receivers
}

TEST_P(FivMirror, LookupDifMapMatchesCoreAndReference) {
  double worst = 0;
  for (std::size_t r = 0; r < receivers_->size(); ++r) {
    const Receiver& rc = (*receivers_)[r];
    const auto tol = difmap_tolerance(scene_->difmap_size, scene_->texels, rc.n);
    const double nd[3] = {rc.n[0], rc.n[1], rc.n[2]};
    const auto ref = difmap_at(scene_->difmap_size, scene_->texels, nd);
    float core[3];
    prt::shade::lookup_difmap(difmap(), rc.n, core);
    for (std::size_t c = 0; c < 3; ++c) {
      const double got = result(r)[9 + c];
      worst = std::max(worst, std::abs(got - core[c]) / tol[c]);
      ASSERT_LE(std::abs(got - core[c]), tol[c]) << "receiver " << r << " n = (" << rc.n[0] << ", " << rc.n[1] << ", "
                                                 << rc.n[2] << ")";
      ASSERT_LE(std::abs(got - ref[c]), tol[c]) << "receiver " << r;
    }
  }
  std::printf("%s lookup_difmap: worst shader-core %.3f x tol\n", language(), worst);
}

// The normal the shading functions use (prtshade/fiv.h "Numerics"): n/|n|, a zero normal is +Y.
// The receivers' normals are unit to float rounding, so only the zero normal changes.
std::array<float, 3> shading_normal(const float n[3]) {
  const double len = std::sqrt(double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2]);
  if (!(len > 0)) return {0.0f, 1.0f, 0.0f};
  return {float(n[0] / len), float(n[1] / len), float(n[2] / len)};
}

// Partial factor and occluded irradiance. h = n·(c − p) rounds within δh = 8 ε Σ_k |n_k|(|c_k| +
// |p_k|) on each side, so the factor within δh/(2R) + 4 ε; I_c = max(0, f n·F_c) within
// δf |n·F_c| + f Σ_k |n_k| tolF_ck + 8 ε f Σ_k |n_k F_ck|; without the partial factor, a receiver
// within δh of case C may get 0 or the full value.
struct IrradianceCheck {
  double factor, factor_tol;
  std::array<double, 3> I_partial, tol_partial, I_full, tol_full;
  // Whether the occluder "hides something" (I > 0 in some channel) could come out differently
  // in the two implementations: the pre-clamp value of some channel is within its tolerance of
  // 0, or the receiver is within δh of case C.
  bool unsure_partial = false, unsure_full = false;
};

IrradianceCheck irradiance_check(const SynthOccluder& o, const float p[3], const float n[3]) {
  IrradianceCheck k{};
  double h = 0, dh = 0;
  for (int a = 0; a < 3; ++a) {
    h += double(n[a]) * (double(o.centre[a]) - p[a]);
    dh += std::abs(n[a]) * (std::abs(o.centre[a]) + std::abs(p[a]));
  }
  dh *= 8 * kFloatEps;
  const double R = o.radius;
  k.factor = h <= -R ? 0.0 : (h >= R ? 1.0 : (h + R) / (2 * R));
  k.factor_tol = dh / (2 * R) + 4 * kFloatEps;
  const Lookup l = lookup_case(o, p);
  const FivRef& F = l.ref;
  const Fiv9& tolF = l.tol;
  const bool near_c = std::abs(h + R) <= dh;
  std::array<double, 3> raw_partial{}, raw_full{};
  for (std::size_t ch = 0; ch < 3; ++ch) {
    double nf = 0, nf_abs = 0, nf_tol = 0;
    for (std::size_t a = 0; a < 3; ++a) {
      nf += n[a] * F.v[3 * ch + a];
      nf_abs += std::abs(n[a] * F.v[3 * ch + a]);
      nf_tol += std::abs(n[a]) * tolF[3 * ch + a];
    }
    k.I_partial[ch] = std::max(0.0, k.factor * nf);
    k.tol_partial[ch] = k.factor_tol * std::abs(nf) + std::min(1.0, k.factor + k.factor_tol) * (nf_tol + 8 * kFloatEps * nf_abs);
    k.I_full[ch] = h > -R ? std::max(0.0, nf) : 0.0;
    k.tol_full[ch] = nf_tol + 8 * kFloatEps * nf_abs + (near_c ? std::abs(nf) : 0.0);
    raw_partial[ch] = k.factor * nf;
    raw_full[ch] = h > -R ? nf : 0.0;
  }
  auto unsure = [&](const std::array<double, 3>& raw, const std::array<double, 3>& tol) {
    bool sure_hides = false, ambiguous = false;
    for (std::size_t ch = 0; ch < 3; ++ch) {
      sure_hides = sure_hides || raw[ch] > tol[ch];
      ambiguous = ambiguous || std::abs(raw[ch]) <= tol[ch];
    }
    return !sure_hides && (ambiguous || near_c);
  };
  k.unsure_partial = unsure(raw_partial, k.tol_partial);
  k.unsure_full = unsure(raw_full, k.tol_full);
  return k;
}

TEST_P(FivMirror, PartialFactorAndOccludedIrradianceMatchCore) {
  int cases[3] = {0, 0, 0};  // C, B, A
  for (std::size_t r = 0; r < receivers_->size(); ++r) {
    const Receiver& rc = (*receivers_)[r];
    const SynthOccluder& o = scene_->occ[rc.info[0]];
    const std::array<float, 3> sn = shading_normal(rc.n);
    const IrradianceCheck k = irradiance_check(o, rc.p, sn.data());
    ++cases[k.factor == 0 ? 0 : (k.factor == 1 ? 2 : 1)];
    const float* got = result(r);
    const float core_f = prt::shade::partial_factor(o.view(), rc.p, rc.n);
    ASSERT_LE(std::abs(got[12] - core_f), k.factor_tol) << "receiver " << r;
    ASSERT_LE(std::abs(got[12] - k.factor), k.factor_tol) << "receiver " << r;
    float core_p[3], core_full[3];
    prt::shade::occluded_irradiance(o.view(), rc.p, rc.n, true, core_p);
    prt::shade::occluded_irradiance(o.view(), rc.p, rc.n, false, core_full);
    for (std::size_t c = 0; c < 3; ++c) {
      ASSERT_LE(std::abs(got[13 + c] - core_p[c]), k.tol_partial[c]) << "receiver " << r << " channel " << c;
      ASSERT_LE(std::abs(got[13 + c] - k.I_partial[c]), k.tol_partial[c]) << "receiver " << r;
      ASSERT_LE(std::abs(got[16 + c] - core_full[c]), k.tol_full[c]) << "receiver " << r << " channel " << c;
      ASSERT_LE(std::abs(got[16 + c] - k.I_full[c]), k.tol_full[c]) << "receiver " << r;
    }
  }
  std::printf("occluded irradiance: cases C/B/A = %d/%d/%d receivers\n", cases[0], cases[1], cases[2]);
  EXPECT_GT(cases[0], 50);  // every case exercised
  EXPECT_GT(cases[1], 50);
  EXPECT_GT(cases[2], 50);
}

// Self-shadows: E_c = max(0, n·F^env_c − n·F_c) within Σ_k |n_k| tolF_ck + 8 ε (|n·F^env_c| terms + |n F_c| terms).
TEST_P(FivMirror, ShadeFivSelfMatchesCore) {
  for (std::size_t r = 0; r < receivers_->size(); ++r) {
    const Receiver& rc = (*receivers_)[r];
    const SynthOccluder& o = scene_->occ[rc.info[0]];
    const Lookup l = lookup_case(o, rc.p);
    const FivRef& F = l.ref;
    const Fiv9& tolF = l.tol;
    float core[3];
    prt::shade::shade_fiv_self(scene_->env, o.view(), rc.p, rc.n, core);
    const std::array<float, 3> sn = shading_normal(rc.n);
    for (std::size_t ch = 0; ch < 3; ++ch) {
      double e = 0, mag = 0, tol = 0;
      for (std::size_t a = 0; a < 3; ++a) {
        e += sn[a] * (scene_->env[3 * ch + a] - F.v[3 * ch + a]);
        mag += std::abs(sn[a] * scene_->env[3 * ch + a]) + std::abs(sn[a] * F.v[3 * ch + a]);
        tol += std::abs(sn[a]) * tolF[3 * ch + a];
      }
      tol += 8 * kFloatEps * mag;
      const double got = result(r)[19 + ch];
      ASSERT_LE(std::abs(got - core[ch]), tol) << "receiver " << r << " channel " << ch;
      ASSERT_LE(std::abs(got - std::max(0.0, e)), tol) << "receiver " << r << " channel " << ch;
    }
  }
}

// shade_fiv on groups of 1–5 occluders (a duplicate pair gives O = ½), all four option
// combinations, vs the C++ core. Tolerance, composed through E = D − Σ I_i + Σ_{i<j} O_ij (I_i + I_j):
//   tol_D + Σ_i tol_I_i (1 + Σ_j O_ij) + Σ_{i<j} tol_O_ij (I_i + I_j)
//   + Σ over pairs whose "hides something" test is within tolerance of flipping: O_ij (I_i + I_j + tol)
//   + 16 ε (count + 2) (|D| + Σ_i I_i (1 + Σ_j O_ij))   (summation order differs: the shader sums
//     I_i Σ_j O_ij, the core O_ij (I_i + I_j)),
// tol_O_ij = twice the largest change of O over the box α ± δα, γ ± δγ plus 64 ε (the float lens
// formula), δα = 16 ε + min(4 ε/cos α, 4 √ε) (asin near α = π/2), δγ = 32 ε π + min(4 ε/sin γ, 4 √ε)
// (the core's cosine test for disjoint discs resolves γ only to ε/sin γ).
TEST_P(FivMirror, ShadeFivMatchesCore) {
  const std::vector<SynthOccluder>& occ = scene_->occ;
  double worst = 0;
  int pairs_overlapping = 0;
  for (std::size_t r = 0; r < receivers_->size(); ++r) {
    const Receiver& rc = (*receivers_)[r];
    const uint32_t first = rc.info[1], count = rc.info[2];
    if (first >= kFirstCone) continue;  // the cone groups: ShadeFivConeMatchesCore
    std::vector<prt::shade::FivOccluder> views;
    for (uint32_t i = 0; i < count; ++i) views.push_back(occ[first + i].view());
    const auto D = difmap_at(scene_->difmap_size, scene_->texels, std::array<double, 3>{rc.n[0], rc.n[1], rc.n[2]}.data());
    const auto tol_D = difmap_tolerance(scene_->difmap_size, scene_->texels, rc.n);
    const std::array<float, 3> sn = shading_normal(rc.n);
    // Discs in double.
    std::vector<std::array<double, 3>> axis(count);
    std::vector<double> alpha(count), d_alpha(count);
    for (uint32_t i = 0; i < count; ++i) {
      const SynthOccluder& o = occ[first + i];
      double v[3], D2 = 0;
      for (int a = 0; a < 3; ++a) v[a] = double(o.centre[a]) - rc.p[a], D2 += v[a] * v[a];
      const double Dl = std::sqrt(D2);
      for (std::size_t a = 0; a < 3; ++a) axis[i][a] = Dl > 0 ? v[a] / Dl : sn[a];
      alpha[i] = Dl > 0 ? std::asin(std::min(1.0, o.radius / Dl)) : kPi / 2;
      d_alpha[i] = 16 * kFloatEps + std::min(4 * kFloatEps / std::max(std::cos(alpha[i]), 1e-300), 4 * std::sqrt(kFloatEps));
    }
    for (int option = 0; option < 4; ++option) {
      const bool partial = option < 2, overlap = option % 2 == 0;
      std::vector<IrradianceCheck> k;
      for (uint32_t i = 0; i < count; ++i) k.push_back(irradiance_check(occ[first + i], rc.p, sn.data()));
      std::array<double, 3> E{}, tol{}, mag{};
      for (std::size_t c = 0; c < 3; ++c) E[c] = D[c], tol[c] = tol_D[c], mag[c] = std::abs(D[c]);
      std::vector<std::array<double, 3>> I(count), tI(count);
      std::vector<double> weight(count, 0.0);
      std::vector<bool> hides(count), unsure(count);
      for (uint32_t i = 0; i < count; ++i) {
        I[i] = partial ? k[i].I_partial : k[i].I_full;
        tI[i] = partial ? k[i].tol_partial : k[i].tol_full;
        hides[i] = I[i][0] > 0 || I[i][1] > 0 || I[i][2] > 0;
        unsure[i] = partial ? k[i].unsure_partial : k[i].unsure_full;
        for (std::size_t c = 0; c < 3; ++c) E[c] -= I[i][c];
      }
      if (overlap)
        for (uint32_t i = 0; i < count; ++i)
          for (uint32_t j = i + 1; j < count; ++j) {
            const double cg = std::clamp(axis[i][0] * axis[j][0] + axis[i][1] * axis[j][1] + axis[i][2] * axis[j][2], -1.0, 1.0);
            const double gamma = std::acos(cg);
            const double d_gamma =
                32 * kFloatEps * kPi + std::min(4 * kFloatEps / std::max(std::sin(gamma), 1e-300), 4 * std::sqrt(kFloatEps));
            const double O = prt::shade::overlap_fraction(alpha[i], alpha[j], gamma);
            double tol_O = 0;
            for (int corner = 0; corner < 8; ++corner) {
              const double O2 = prt::shade::overlap_fraction(
                  std::max(0.0, alpha[i] + (corner & 1 ? d_alpha[i] : -d_alpha[i])),
                  std::max(0.0, alpha[j] + (corner & 2 ? d_alpha[j] : -d_alpha[j])),
                  std::max(0.0, gamma + (corner & 4 ? d_gamma : -d_gamma)));
              tol_O = std::max(tol_O, 2 * std::abs(O2 - O));
            }
            tol_O += 64 * kFloatEps;
            if (O > 0) ++pairs_overlapping;
            for (std::size_t c = 0; c < 3; ++c) {
              const double sum = I[i][c] + I[j][c];
              if (hides[i] && hides[j]) {
                E[c] += O * sum;
                weight[i] += O, weight[j] += O;
                tol[c] += tol_O * sum;
              }
              if (unsure[i] || unsure[j]) tol[c] += (O + tol_O) * (sum + tI[i][c] + tI[j][c]);
            }
          }
      for (uint32_t i = 0; i < count; ++i)
        for (std::size_t c = 0; c < 3; ++c) {
          tol[c] += tI[i][c] * (1 + weight[i]);
          mag[c] += I[i][c] * (1 + weight[i]);
        }
      float core[3];
      prt::shade::shade_fiv(difmap(), views.data(), int(count), rc.p, rc.n, {partial, overlap}, core);
      for (std::size_t c = 0; c < 3; ++c) {
        tol[c] += 16 * kFloatEps * (count + 2) * mag[c];
        const double got = result(r)[22 + 3 * static_cast<std::size_t>(option) + c];
        ASSERT_TRUE(std::isfinite(got));
        worst = std::max(worst, std::abs(got - core[c]) / tol[c]);
        ASSERT_LE(std::abs(got - core[c]), tol[c])
            << "receiver " << r << " occluders " << first << "+" << count << " partial " << partial << " overlap "
            << overlap << " channel " << c << " glsl " << got << " core " << core[c];
        ASSERT_LE(std::abs(got - std::max(0.0, E[c])), tol[c])
            << "vs reference: receiver " << r << " partial " << partial << " overlap " << overlap << " channel " << c;
      }
    }
  }
  std::printf("%s shade_fiv: worst shader-core %.3f x tol; %d overlapping pairs seen\n", language(), worst,
              pairs_overlapping);
  EXPECT_GT(pairs_overlapping, 100);  // the overlap correction was exercised
}

// shade_fiv with the cone proxy (occluders 7–9: exact ball cones) vs the C++ core, all four option
// combinations. Both evaluate the same float formulas in the same order per occluder; they differ
// by the angles (the shader's prt_atan2 on its own float rounding: within 64 ε ≈ 4e-6 rad of the
// core's, like the sphere test's δα, δγ above) and by the summation order. The cone's axis and α
// follow the table's lookup within that angle (the ball's table is smooth: Ω depends on ρ only, m
// turns with the direction); I moves by at most the slope of n·F per radian (≤ Σ|F| of the
// samples, here <= 3·max|shell|) plus below · (|∂K/∂x| + |∂K/∂α|) ≤ 3π below per radian, and each
// pair's term A_ij min(I_i/A_i, I_j/A_j) (fiv.h "Tight proxies") by ≤ 6/min α per radian times
// I_i + I_j (as in test_fiv_runtime.cpp); min α ≥ 0.03 in this scene. So
//   tol = δ (Σ_i (3 max|shell| + 3π below) (1 + Σ_j 6/α_min)) + 16 ε (count + 2) (|E_tot| + 2 Σ I)
// with δ = 64 ε (the final max(0, ·) is 1-Lipschitz: clamping adds nothing).
// That bound holds only where the lookups are continuous. Both the shells and the cone table are
// masked lookups (fiv.h): where a valid neighbour's weight goes to 0 (at a radius, a ring, a
// column) the renormalised value jumps, and the two sides need not land on the same side of the
// jump: the core forms s = p − centre and ρ in double, the shaders in float (ρ within 8 ε ρ of the
// exact one, the core's within 4 ε ρ), and their angles differ by δ. (Occluder 9's pole receivers
// at ρ = its last radius sit on such a jump; so, by chance, do receivers of the random ones.) So,
// as the lookup tests' box of coordinate perturbations does, each occluder's conditioning is added:
// twice the largest change of the core's result when that occluder's centre alone moves to the 8
// corners of the cube of half-size (12 ε + δ) ρ_i about it (ρ_i = |p − centre_i|; the cube holds
// every offset the rounding of ρ and of the angles can give; ~δ ρ_i × the slope where the
// lookups are continuous, the jump where one lies within it).
TEST_P(FivMirror, ShadeFivConeMatchesCore) {
  const std::vector<SynthOccluder>& occ = scene_->occ;
  const double delta = 64 * kFloatEps;
  double worst = 0;
  int compared = 0, corrected = 0, ill_conditioned = 0;
  for (std::size_t r = 0; r < receivers_->size(); ++r) {
    const Receiver& rc = (*receivers_)[r];
    const uint32_t first = rc.info[1], count = rc.info[2];
    if (first < kFirstCone) continue;
    std::vector<prt::shade::FivOccluder> views;
    double shell_max = 0;
    for (uint32_t i = 0; i < count; ++i) {
      views.push_back(occ[first + i].view());
      for (float v : occ[first + i].shells) shell_max = std::max(shell_max, double(std::abs(v)));
    }
    float tot[3], below[3];
    const std::array<float, 3> sn = shading_normal(rc.n);
    const float down[3] = {-sn[0], -sn[1], -sn[2]};
    prt::shade::lookup_difmap(difmap(), sn.data(), tot);
    prt::shade::lookup_difmap(difmap(), down, below);
    for (int option = 0; option < 4; ++option) {
      const bool partial = option < 2, overlap = option % 2 == 0;
      float core[3], none[3];
      prt::shade::shade_fiv(difmap(), views.data(), int(count), rc.p, rc.n, {partial, overlap}, core);
      prt::shade::shade_fiv(difmap(), views.data(), int(count), rc.p, rc.n, {partial, false}, none);
      corrected += overlap && core[0] != none[0];
      // The lookups' conditioning (the comment above): occluder i's centre moved by ±(12 ε + δ) ρ_i.
      std::array<double, 3> conditioning{};
      for (uint32_t i = 0; i < count; ++i) {
        const SynthOccluder& o = occ[first + i];
        double rho2 = 0;
        for (int a = 0; a < 3; ++a) rho2 += (double(rc.p[a]) - o.centre[a]) * (double(rc.p[a]) - o.centre[a]);
        const double d = (12 * kFloatEps + delta) * std::sqrt(rho2);
        std::array<double, 3> change{};
        for (int corner = 0; corner < 8; ++corner) {
          std::vector<prt::shade::FivOccluder> moved = views;
          for (int a = 0; a < 3; ++a) moved[i].centre[a] = float(double(o.centre[a]) + ((corner >> a) & 1 ? d : -d));
          float e[3];
          prt::shade::shade_fiv(difmap(), moved.data(), int(count), rc.p, rc.n, {partial, overlap}, e);
          for (std::size_t c = 0; c < 3; ++c) change[c] = std::max(change[c], 2 * std::abs(double(e[c]) - core[c]));
        }
        for (std::size_t c = 0; c < 3; ++c) conditioning[c] += change[c];
      }
      for (std::size_t c = 0; c < 3; ++c) {
        const double per_occluder = 3 * shell_max + 3 * kPi * below[c] / kPi;
        const double sum_I = std::max(0.0, double(tot[c]) - none[c]) + count * per_occluder;
        const double smooth = delta * count * per_occluder * (1 + (overlap ? count * 6 / 0.03 : 0.0)) +
                              16 * kFloatEps * (count + 2) * (std::abs(tot[c]) + 2 * sum_I);
        const double tol = smooth + conditioning[c];
        ill_conditioned += conditioning[c] > smooth;
        const double got = result(r)[22 + 3 * static_cast<std::size_t>(option) + c];
        ASSERT_TRUE(std::isfinite(got));
        ASSERT_LE(std::abs(got - core[c]), tol) << "receiver " << r << " occluders " << first << "+" << count
                                                << " option " << option << " channel " << c;
        worst = std::max(worst, std::abs(got - core[c]) / tol);
        ++compared;
      }
    }
  }
  std::printf("%s shade_fiv (cone proxy): worst shader-core %.3g x tol over %d values; %d receivers with an overlap term; "
              "%d values ill-conditioned (conditioning > the smooth bound)\n",
              language(), worst, compared, corrected, ill_conditioned);
  EXPECT_GT(compared, 1000);
  // The bound must stay tight for nearly all values, or the test proves little; the jumps
  // (occluder 9's poles at its last radius among them) must be visited.
  EXPECT_LT(double(ill_conditioned), 0.02 * double(compared));
  EXPECT_GE(ill_conditioned, 1);
  EXPECT_GT(corrected, 100);  // pairs of tight proxies overlap: the density form was exercised
}

} // namespace
