#include <prtshade/ltc.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace prt::shade::ltc {

namespace {

double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
Vec3 scaled(const Vec3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
Vec3 unit(const Vec3& a) { return scaled(a, 1 / std::sqrt(dot(a, a))); }
Vec3 apply(const std::array<Vec3, 3>& rows, const Vec3& x) { return {dot(rows[0], x), dot(rows[1], x), dot(rows[2], x)}; }

// Λ of the Smith masking for a direction at cosine c to the normal (c > 0).
double smith_lambda(double c, double alpha) {
  const double tan2 = std::max(1 - c * c, 0.0) / (c * c);
  return 0.5 * (std::sqrt(1 + alpha * alpha * tan2) - 1);
}

// Lambert's edge term θ u_z of the great arc a → b (any lengths, not antipodal).
double edge_z(const Vec3& a, const Vec3& b) {
  const Vec3 c = cross(unit(a), unit(b));
  const double s = std::sqrt(dot(c, c));
  if (!(s > 0)) return 0;
  return c[2] * std::atan2(s, dot(unit(a), unit(b))) / s;
}

// The point of the arc a → b on the plane z = 0 (a, b on strictly / weakly opposite sides).
Vec3 horizon_crossing(const Vec3& a, const Vec3& b) {
  const double za = a[2], zb = b[2], w = 1 / (za - zb);
  return {(za * b[0] - zb * a[0]) * w, (za * b[1] - zb * a[1]) * w, 0.0};
}

} // namespace

std::size_t packed_table_floats(const Table& t) { return 4 + std::size_t(t.n_alpha) * std::size_t(t.n_theta) * Table::kValuesPerNode; }

void pack_table(const Table& t, std::span<float> out) {
  out[0] = float(t.n_alpha);
  out[1] = float(t.n_theta);
  out[2] = float(t.sqrt_alpha_min);
  out[3] = float(t.theta_max);
  for (std::size_t k = 4; k < packed_table_floats(t); ++k) out[k] = float(t.values[k - 4]);
}

double ggx_ndf(double cos_h, double alpha) {
  const double a2 = alpha * alpha, q = cos_h * cos_h * (a2 - 1) + 1;
  return a2 / (std::numbers::pi * q * q);
}

double ggx_brdf(const Vec3& n, const Vec3& v, const Vec3& l, double alpha, double f0) {
  const double cv = dot(n, v), cl = dot(n, l);
  if (!(cv > 0) || !(cl > 0)) return 0;
  const Vec3 h = unit({v[0] + l[0], v[1] + l[1], v[2] + l[2]});
  const double D = ggx_ndf(dot(n, h), alpha);
  const double G2 = 1 / (1 + smith_lambda(cv, alpha) + smith_lambda(cl, alpha));
  const double F = f0 + (1 - f0) * std::pow(std::max(1 - dot(v, h), 0.0), 5);
  return D * G2 * F / (4 * cv * cl);
}

namespace {

// The cell (i, j) holding (α, cos θ) and the position (u, w) ∈ [0, 1]² in it.
struct CellPosition {
  int i, j;
  double u, w;
};
CellPosition locate(const Table& t, double alpha, double cos_theta) {
  const double r = std::clamp(std::sqrt(std::max(alpha, 0.0)), t.sqrt_alpha_min, 1.0);
  const double theta = std::min(std::acos(std::clamp(cos_theta, 0.0, 1.0)), t.theta_max);
  const double fi = (r - t.sqrt_alpha_min) / (1 - t.sqrt_alpha_min) * (t.n_alpha - 1);
  const double fj = theta / t.theta_max * (t.n_theta - 1);
  const int i = std::min(int(fi), t.n_alpha - 2), j = std::min(int(fj), t.n_theta - 2);
  return {i, j, fi - i, fj - j};
}

} // namespace

double error_bound(const Table& t, double alpha, double cos_theta, double f0) {
  const CellPosition c = locate(t, alpha, cos_theta);
  const double* e = t.cell_errors + (c.i * (t.n_theta - 1) + c.j) * 2;
  return lookup(t, alpha, cos_theta)[4] * (f0 * e[0] + (1 - f0) * e[1]);
}

std::array<double, Table::kValuesPerNode> lookup(const Table& t, double alpha, double cos_theta) {
  const auto cell = locate(t, alpha, cos_theta);
  const int i = cell.i, j = cell.j;  // not a structured binding: clang 14 cannot capture those
  const double u = cell.u, w = cell.w;
  std::array<double, Table::kValuesPerNode> out{};
  const auto node = [&](int di, int dj) { return t.values + ((i + di) * t.n_theta + (j + dj)) * Table::kValuesPerNode; };
  for (int k = 0; k < Table::kValuesPerNode; ++k)
    out[k] = (1 - u) * ((1 - w) * node(0, 0)[k] + w * node(0, 1)[k]) + u * ((1 - w) * node(1, 0)[k] + w * node(1, 1)[k]);
  return out;
}

Lobe lobe_from_matrix(const Vec3& n, const Vec3& v, const std::array<double, 4>& m, double albedo, double fresnel) {
  // The local frame: z = n, x = v's part across n (any perpendicular when v ∥ n), y = z × x.
  Vec3 x = {v[0] - dot(v, n) * n[0], v[1] - dot(v, n) * n[1], v[2] - dot(v, n) * n[2]};
  if (!(dot(x, x) > 1e-24)) x = std::abs(n[0]) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  x = unit({x[0] - dot(x, n) * n[0], x[1] - dot(x, n) * n[1], x[2] - dot(x, n) * n[2]});
  const std::array<Vec3, 3> R = {x, cross(n, x), n};
  const auto [a, b, c, d] = m;
  const double e = a - b * d;  // M⁻¹ = [[1, 0, −b], [0, e/c, 0], [−d, 0, a]] / e
  const std::array<Vec3, 3> minv = {Vec3{1 / e, 0, -b / e}, Vec3{0, 1 / c, 0}, Vec3{-d / e, 0, a / e}};
  Lobe lobe;
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) lobe.to_cosine[i][k] = minv[i][0] * R[0][k] + minv[i][1] * R[1][k] + minv[i][2] * R[2][k];
  lobe.det = 1 / (c * e);
  lobe.horizon = {d, 0, 1};
  lobe.albedo = albedo;
  lobe.fresnel = fresnel;
  return lobe;
}

Lobe ggx_lobe(const Table& table, const Vec3& n, const Vec3& v, double alpha) {
  const double cv = dot(n, v);
  if (!(cv > 0)) return lobe_from_matrix(n, v, {1, 0, 1, 0}, 0, 0);
  const auto e = lookup(table, alpha, cv);
  return lobe_from_matrix(n, v, {e[0], e[1], e[2], e[3]}, e[4], e[5]);
}

double density(const Lobe& lobe, const Vec3& l) {
  const Vec3 o = apply(lobe.to_cosine, l);
  const double r2 = dot(o, o), r = std::sqrt(r2);
  // D_cos(o/|o|) · det M⁻¹ / |M⁻¹ l̂|³ with l̂ = l/|l|: |M⁻¹ l̂| = r/|l|.
  const double len = std::sqrt(dot(l, l));
  return std::max(o[2] / r, 0.0) * std::numbers::inv_pi * lobe.det * (len * len * len) / (r2 * r);
}

double integrate(const Lobe& lobe, std::span<const Arc> arcs) {
  const Vec3& k = lobe.horizon;
  const double k_xy = std::hypot(k[0], k[1]);
  // The region lies in K = {k·x ≥ 0}: when K's boundary is the horizon (to 1e-9 rad) there is
  // nothing below it to clip (the sliver it could leave has |z| ≤ 1e-9).
  const bool clip = k_xy > 1e-9 * std::abs(k[2]);
  const double phi_ref = clip ? std::atan2(-k[1], -k[0]) : 0.0;  // a horizon point outside K: w = 0
  const double two_pi = 2 * std::numbers::pi;
  double edges = 0, horizon = 0;
  const auto crossing = [&](const Vec3& c, double s) {
    double rel = std::atan2(c[1], c[0]) - phi_ref;
    if (rel < 0) rel += two_pi;
    if (rel >= two_pi) rel -= two_pi;
    horizon += s * (two_pi - rel);
  };
  for (const Arc& arc : arcs) {
    const Vec3 a = apply(lobe.to_cosine, arc.a), b = apply(lobe.to_cosine, arc.b);
    const bool above_a = !clip || a[2] >= 0, above_b = !clip || b[2] >= 0;
    if (above_a && above_b) {
      edges += edge_z(a, b);
    } else if (above_a) {  // leaves the hemisphere: w grows by 1 past this point (in φ)
      const Vec3 c = horizon_crossing(a, b);
      edges += edge_z(a, c);
      crossing(c, +1);
    } else if (above_b) {  // enters it
      const Vec3 c = horizon_crossing(a, b);
      edges += edge_z(c, b);
      crossing(c, -1);
    }
  }
  return 0.5 * (edges + horizon) * std::numbers::inv_pi;
}

} // namespace prt::shade::ltc
