// irradiance.cpp — the unshadowed irradiance E_tot(n) of an environment map (bake/environment/irradiance.h).
#include <bake/core/error.h>
#include <bake/environment/irradiance.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

namespace prt::bake {

using Eigen::Vector3d;

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

UnshadowedIrradiance::UnshadowedIrradiance(const EnvMap& env) : env_(env) {
  if (env.texel_count() == 0) {
    constant_ = true;
    constant_value_ = env.radiance(Vector3d::UnitY());
    return;
  }
  const std::vector<Vector3d> m = texel_moments(env);
  const int T = env.texel_count();
  texels_.reserve(static_cast<size_t>(T));
  for (int t = 0; t < T; ++t) {
    const Rgb L = env.texel_value(t);
    if (L.r == 0 && L.g == 0 && L.b == 0) continue;
    Texel x{};
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
    x.omega = env.texel_solid_angle(t);
    x.index = t;
    texels_.push_back(x);
  }
  // Cells: texels grouped by the direction of their centre on a coarse 64 × 32 lat-long grid, each
  // with a cone (axis, half-angle R) holding every texel's own cone: R = max_t ∠(axis, c_t) + r_t.
  constexpr int kCellsPhi = 64, kCellsTheta = 32;
  auto cell_of = [&](const Texel& x) {
    const double th = std::acos(std::clamp(x.c[1], -1.0, 1.0)), ph = std::atan2(x.c[0], x.c[2]) + std::numbers::pi;
    const int i = std::min(kCellsTheta - 1, int(th / std::numbers::pi * kCellsTheta));
    const int j = std::min(kCellsPhi - 1, int(ph / (2 * std::numbers::pi) * kCellsPhi));
    return i * kCellsPhi + j;
  };
  std::vector<int> cell(texels_.size());
  for (size_t k = 0; k < texels_.size(); ++k) cell[k] = cell_of(texels_[k]);
  order_.resize(texels_.size());
  std::iota(order_.begin(), order_.end(), size_t(0));
  std::stable_sort(order_.begin(), order_.end(), [&](size_t a, size_t b) { return cell[a] < cell[b]; });
  for (size_t k = 0; k < order_.size();) {
    Cell q;
    q.begin = k;
    const int id = cell[order_[k]];
    Vector3d sum(0, 0, 0);
    while (k < order_.size() && cell[order_[k]] == id) {
      const Texel& x = texels_[order_[k]];
      sum += Vector3d(x.c[0], x.c[1], x.c[2]);
      for (int c = 0; c < 3; ++c)
        for (int a = 0; a < 3; ++a) q.S[c][a] += x.L[c] * x.m[a];
      ++k;
    }
    q.end = k;
    const Vector3d axis = sum.normalized();
    double R = 0;
    for (size_t t = q.begin; t < q.end; ++t) {
      const Texel& x = texels_[order_[t]];
      R = std::max(R, std::acos(std::clamp(axis.dot(Vector3d(x.c[0], x.c[1], x.c[2])), -1.0, 1.0)) + x.r);
    }
    R += 1e-9;  // acos rounding
    q.bounded = sum.norm() > 0 && R < std::numbers::pi / 2;
    for (int a = 0; a < 3; ++a) q.axis[a] = axis[a];
    q.sin_R = std::sin(std::min(R, std::numbers::pi / 2));
    cells_.push_back(q);
  }
}

// Adds texel x's L ∫ H(ω, n) (n·ω) dω to e: its moment when wholly above the horizon of n,
// nothing when wholly below, 4×4 sub-samples when cut.
void UnshadowedIrradiance::add_texel(const Vector3d& n, const Texel& x, double e[3]) const {
  const double cn = n.x() * x.c[0] + n.y() * x.c[1] + n.z() * x.c[2];
  double w;
  if (cn >= x.sin_r) {
    w = n.x() * x.m[0] + n.y() * x.m[1] + n.z() * x.m[2];
  } else if (cn <= -x.sin_r) {
    return;
  } else {
    constexpr int kS = 4;
    Vector3d d[kS * kS];
    env_.sample_texel_grid(x.index, kS, d);
    double acc = 0;
    for (const Vector3d& di : d) acc += std::max(0.0, n.dot(di));
    w = acc * x.omega / (kS * kS);
  }
  e[0] += x.L[0] * w;
  e[1] += x.L[1] * w;
  e[2] += x.L[2] * w;
}

Rgb UnshadowedIrradiance::operator()(const Vector3d& n) const {
  if (constant_)
    return {std::numbers::pi * constant_value_.r, std::numbers::pi * constant_value_.g, std::numbers::pi * constant_value_.b};
  double e[3] = {0, 0, 0};
  for (const Cell& q : cells_) {
    if (q.bounded) {
      const double cn = n.x() * q.axis[0] + n.y() * q.axis[1] + n.z() * q.axis[2];
      if (cn >= q.sin_R) {  // wholly above: every texel's moment
        for (int c = 0; c < 3; ++c) e[c] += n.x() * q.S[c][0] + n.y() * q.S[c][1] + n.z() * q.S[c][2];
        continue;
      }
      if (cn <= -q.sin_R) continue;  // wholly below
    }
    for (size_t t = q.begin; t < q.end; ++t) add_texel(n, texels_[order_[t]], e);
  }
  return {e[0], e[1], e[2]};
}

Rgb UnshadowedIrradiance::reference(const Vector3d& n) const {
  PRT_CHECK(!constant_);
  double e[3] = {0, 0, 0};
  for (const Texel& x : texels_) add_texel(n, x, e);
  return {e[0], e[1], e[2]};
}

} // namespace prt::bake
