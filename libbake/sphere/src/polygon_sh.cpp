// polygon_sh.cpp — SH projection of spherical polygons (derivation and conventions in
// bake/sphere/polygon_sh.h).
#include <bake/sphere/polygon_sh.h>

#include "spherical_polygon_detail.h"

#include <bake/core/error.h>
#include <prtshade/sh.h>

#include <Eigen/Dense>

#include <array>
#include <algorithm>
#include <cmath>
#include <numbers>

namespace prt::bake {

// One edge of a polygon of unit vertices: ends a, b, unit plane normal u, length θ, and the unit
// tangents u×a, u×b at its ends (directions of travel).
struct detail::ShEdge {
  Eigen::Vector3d a, b, u, ta, tb, a_minus_b;
  double theta;
};

namespace {

using Edge = detail::ShEdge;

constexpr double kPi = std::numbers::pi;

// Monomial coefficients of the Legendre polynomials P_0 … P_{n−1} (Bonnet:
// (l+1) P_{l+1} = (2l+1) t P_l − l P_{l−1}); row l has l+1 entries.
std::vector<std::vector<double>> legendre_monomials(int n) {
  std::vector<std::vector<double>> p(size_t(std::max(n, 2)));
  p[0] = {1.0};
  p[1] = {0.0, 1.0};
  for (int l = 1; l + 1 < n; ++l) {
    std::vector<double> next(size_t(l + 2), 0.0);
    for (int j = 0; j <= l; ++j) next[size_t(j + 1)] += (2 * l + 1) * p[size_t(l)][size_t(j)];
    for (int j = 0; j < l; ++j) next[size_t(j)] -= l * p[size_t(l - 1)][size_t(j)];
    for (double& c : next) c /= (l + 1);
    p[size_t(l + 1)] = std::move(next);
  }
  return p;
}

} // namespace

PolygonSH::PolygonSH(int order) : order_(order) {
  PRT_CHECK(order >= 1 && order <= kMaxOrder);
  // Fibonacci directions: z_k = 1 − (2k+1)/D, φ_k = k · golden angle.
  const int d = 4 * order;
  const double golden = kPi * (3.0 - std::sqrt(5.0));
  for (int k = 0; k < d; ++k) {
    const double z = 1.0 - (2.0 * k + 1.0) / d, r = std::sqrt(1.0 - z * z);
    axes_.emplace_back(r * std::cos(golden * k), r * std::sin(golden * k), z);
  }
  const auto legendre = legendre_monomials(order);
  std::vector<double> y(size_t(sh::num_coeffs(order)));
  for (int l = 2; l < order; ++l) {
    Eigen::MatrixXd ymat(d, 2 * l + 1);
    for (int k = 0; k < d; ++k) {
      sh::eval(order, axes_[size_t(k)].x(), axes_[size_t(k)].y(), axes_[size_t(k)].z(), y);
      for (int m = -l; m <= l; ++m) ymat(k, m + l) = y[size_t(sh::index(l, m))];
    }
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(ymat, Eigen::ComputeThinU | Eigen::ComputeThinV);
    const auto& sv = svd.singularValues();
    // Conditioning of the least-squares solve (measured ≤ 5.4 for these axes up to kMaxOrder;
    // 2·order + 1 axes would give up to 56).
    PRT_CHECK_OP(sv(0), <, 10.0 * sv(sv.size() - 1));
    const Eigen::MatrixXd pinv =
        svd.matrixV() * sv.cwiseInverse().asDiagonal() * svd.matrixU().transpose() * ((2 * l + 1) / (4 * kPi));
    for (int m = 0; m < 2 * l + 1; ++m)
      for (int k = 0; k < d; ++k) solve_.push_back(pinv(m, k));
    // P_l'(t) = Σ_{j<l} (j+1) p_{l,j+1} t^j.
    for (int j = 0; j < l; ++j) derivative_.push_back((j + 1) * legendre[size_t(l)][size_t(j + 1)]);
  }
}

namespace {

// The edges of the arcs arc(0) … arc(n−1) (pairs of unit vectors) into edges[], null arcs
// (a = b) skipped (they bound nothing); returns the count.
template <class ArcAt>
size_t build_edges(size_t n, ArcAt&& arc, Edge* edges) {
  size_t count = 0;
  for (size_t i = 0; i < n; ++i) {
    const auto [a, b] = arc(i);
    const Eigen::Vector3d ab = a.cross(b);
    const double s = ab.norm();
    if (s == 0) continue;
    Edge& e = edges[count++];
    e.a = a;
    e.b = b;
    e.u = ab / s;
    e.ta = e.u.cross(a);
    e.tb = e.u.cross(b);
    e.a_minus_b = a - b;
    e.theta = std::atan2(s, a.dot(b));
  }
  return count;
}

// Bands 0 and 1 from Ω and 2Φ.
void low_bands(int order, double omega, const Eigen::Vector3d& twice_phi, std::span<double> out) {
  out[0] = omega / std::sqrt(4 * kPi);
  if (order == 1) return;
  const sh::Band1 b1 = sh::band1_from_direction(twice_phi.x(), twice_phi.y(), twice_phi.z());
  for (int m = 0; m < 3; ++m) out[size_t(1 + m)] = 0.5 * sh::kBand1Scale * b1.v[m];
}

// Small-buffer storage for the edges of one projection.
class EdgeBuffer {
public:
  explicit EdgeBuffer(size_t n) {
    if (n > inline_.size()) heap_.resize(n);
  }
  Edge* data() { return heap_.empty() ? inline_.data() : heap_.data(); }

private:
  std::array<Edge, 32> inline_;
  std::vector<Edge> heap_;
};

} // namespace

void PolygonSH::project(std::span<const Eigen::Vector3d> vertices, std::span<double> out) const {
  PRT_CHECK(out.size() >= size_t(sh::num_coeffs(order_)));
  std::fill(out.begin(), out.begin() + sh::num_coeffs(order_), 0.0);
  const detail::UnitPolygon unit(vertices);
  const auto v = unit.span();
  if (v.size() < 3) return;
  low_bands(order_, detail::solid_angle_unit(v), detail::twice_vector_irradiance(v), out);
  if (order_ <= 2) return;
  EdgeBuffer edges(v.size());
  const size_t n = build_edges(v.size(), [&](size_t i) {
    return std::pair<const Eigen::Vector3d&, const Eigen::Vector3d&>(v[i], v[i + 1 == v.size() ? 0 : i + 1]);
  }, edges.data());
  high_bands({edges.data(), n}, out);
}

void PolygonSH::project(std::span<const Arc> boundary, std::span<double> out) const {
  PRT_CHECK(out.size() >= size_t(sh::num_coeffs(order_)));
  std::fill(out.begin(), out.begin() + sh::num_coeffs(order_), 0.0);
  if (boundary.empty()) return;
  low_bands(order_, solid_angle(boundary), 2.0 * vector_irradiance(boundary), out);
  if (order_ <= 2) return;
  EdgeBuffer edges(boundary.size());
  const size_t n = build_edges(boundary.size(), [&](size_t i) {
    return std::pair<Eigen::Vector3d, Eigen::Vector3d>(boundary[i].a.normalized(), boundary[i].b.normalized());
  }, edges.data());
  high_bands({edges.data(), n}, out);
}

void PolygonSH::high_bands(std::span<const detail::ShEdge> edges, std::span<double> out) const {
  // Q_l(w_k) for every axis and band 2 … order−1.
  const int d = int(axes_.size());
  const int top = order_ - 1;  // highest band; arc moments E_0 … E_{top−1} are needed
  std::array<double, kMaxOrder> moments;
  std::array<double, kMaxOrder * 4 * kMaxOrder> q{};  // q[(l−2)·D + k]
  for (int k = 0; k < d; ++k) {
    const Eigen::Vector3d& w = axes_[size_t(k)];
    for (const Edge& e : edges) {
      const double x0 = w.dot(e.a), x1 = w.dot(e.b), y0 = w.dot(e.ta), y1 = w.dot(e.tb);
      const double r2 = x0 * x0 + y0 * y0;
      moments[0] = e.theta;
      moments[1] = w.dot(e.u.cross(e.a_minus_b));
      double p0 = x0, p1 = x1;  // x0^{j−1}, x1^{j−1} for j = 2
      for (int j = 2; j < top; ++j) {
        moments[size_t(j)] = ((j - 1) * r2 * moments[size_t(j - 2)] - (p1 * y1 - p0 * y0)) / j;
        p0 *= x0;
        p1 *= x1;
      }
      const double wu = w.dot(e.u);
      const double* dl = derivative_.data();
      for (int l = 2; l <= top; ++l) {
        double sum = 0;
        for (int j = 0; j < l; ++j) sum += dl[j] * moments[size_t(j)];
        dl += l;
        q[size_t((l - 2) * d + k)] += wu * sum;
      }
    }
  }
  const double* solve = solve_.data();
  for (int l = 2; l <= top; ++l) {
    const double* ql = &q[size_t((l - 2) * d)];
    const double scale = 1.0 / (l * (l + 1));
    for (int m = -l; m <= l; ++m) {
      double c = 0;
      for (int k = 0; k < d; ++k) c += solve[k] * ql[k];
      solve += d;
      out[size_t(sh::index(l, m))] = c * scale;
    }
  }
}

} // namespace prt::bake
