#include <bake/bake/bounce.h>
#include <bake/bake/vertex_bake.h>
#include <bake/core/error.h>
#include <bake/sphere/sampling.h>

#include <prtshade/sh.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <cstdio>
#include <string>

namespace prt::bake {

namespace {
// The gather's own stream of randomisation, apart from the direct pass's QMC points of the same
// seed and row (bake/sphere/sampling.h RotatedHalton3).
constexpr uint64_t kGatherStream = 0x6a09e667f3bcc909ull;
// The most values a vertex gives a bounce: T at the largest order, and E's three channels.
constexpr size_t kMaxSource = size_t(sh::kMaxOrder) * size_t(sh::kMaxOrder) + 3;
constexpr double kInvPi = std::numbers::inv_pi;

// Ray k of a row whose frame and rotated sequence are given: cosine-weighted, or with `mixture`
// cosine or uniform by u0 (one strategy per ray, the balance heuristic's pdf). The gather and
// every bounce make it the same way, so the bounce's weights belong to the ray that was cast.
Eigen::Vector3d gather_direction(const Frame& frame, const RotatedHalton3& halton, size_t k, bool mixture) {
  const auto u = halton(k);
  const bool uniform = mixture && u[0] >= 0.5;
  Eigen::Vector3d d = frame.to_world(uniform ? uniform_hemisphere(u[1], u[2]) : cosine_hemisphere(u[1], u[2]));
  return d.normalized();
}

// The weights of (3') and (5') for direction d about normal n: ((n·ω)/π, y_1m(ω)/π) / p(ω).
// `inv_p`, when given, receives 1/p(ω) (S's weights, y_i(ω)/π/p(ω), are made the same way).
std::array<double, 4> mixture_weights(const Eigen::Vector3d& n, const Eigen::Vector3d& d, double* inv_p_out = nullptr) {
  const double c = n.dot(d);
  const double inv_p = 1.0 / (0.5 * c * kInvPi + 0.5 * (0.5 * kInvPi));
  if (inv_p_out) *inv_p_out = inv_p;
  double y[4];
  sh::eval(2, d.x(), d.y(), d.z(), y);
  return {c * kInvPi * inv_p, y[1] * kInvPi * inv_p, y[2] * kInvPi * inv_p, y[3] * kInvPi * inv_p};
}
} // namespace

GatherHits gather(const RayCaster& rays, std::span<const ShadePoint> points, const BounceSpec& spec, bool radiance,
                  const Monitor& monitor, const std::string& label) {
  PRT_CHECK_OP(spec.rays, >, 0u);
  const auto t0 = std::chrono::steady_clock::now();
  GatherHits hits;
  hits.rays = spec.rays;
  hits.mixture = radiance;
  const size_t K = spec.rays;
  hits.triangle.assign(points.size() * K, GatherHits::kNone);
  hits.weights.assign(points.size() * K, {0.0f, 0.0f});
  hits.seed = mix64(spec.seed ^ kGatherStream);
  Task progress(monitor, label, points.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, points.size(), 16), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v) {
      const ShadePoint& point = points[v];
      PRT_CHECK(point.hemisphere);
      const Frame frame(point.n);
      const RotatedHalton3 halton(hits.seed, v);
      const NearTriangles near = rays.near_triangles(point);
      for (size_t k = 0; k < K; ++k) {
        const Eigen::Vector3d d = gather_direction(frame, halton, k, radiance);
        if (!(point.n.dot(d) > 0)) continue;  // on the horizon (a null set): no contribution
        const auto hit = rays.first_surface_hit(point, near, d);
        if (!hit || !hit->front) continue;  // the sky (the direct pass's), or a back face (black)
        hits.triangle[v * K + k] = hit->triangle;
        hits.weights[v * K + k] = {float(hit->w1), float(hit->w2)};
      }
    }
    progress.advance(r.size());
  });
  progress.finish();
  hits.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return hits;
}

void check_albedo(std::span<const Albedo> albedo, const std::string& source) {
  static const char* const kChannel[3] = {"R", "G", "B"};
  for (size_t t = 0; t < albedo.size(); ++t)
    for (size_t c = 0; c < 3; ++c) {
      const double a = albedo[t][c];
      if (std::isfinite(a) && a >= 0 && a < 1) continue;
      char value[64];
      std::snprintf(value, sizeof value, "%.17g", a);
      throw InputError(source, "albedo " + std::string(value) + " (" + kChannel[c] + ") of triangle " +
                                   std::to_string(t) +
                                   (a >= 1 ? " is 1 or more: the bounces would not converge (an albedo must be below 1)"
                                    : a < 0 ? " is negative (an albedo is a reflectance in [0, 1))"
                                            : " is not a number (an albedo is a reflectance in [0, 1))"));
    }
}

std::string albedo_text(const Albedo& c) {
  char text[96];
  if (c[0] == c[1] && c[0] == c[2]) std::snprintf(text, sizeof text, "%g", c[0]);
  else std::snprintf(text, sizeof text, "%g,%g,%g", c[0], c[1], c[2]);
  return text;
}

void VertexField::spread(std::span<const double> rows, size_t width, std::span<double> entries) const {
  PRT_CHECK_OP(rows.size(), ==, this->rows() * width);
  PRT_CHECK_OP(entries.size(), ==, rows.size());
  std::copy(rows.begin(), rows.end(), entries.begin());
}

FieldTaps VertexField::taps(uint32_t triangle, double w1, double w2) const {
  const auto& tri = mesh_.triangles[triangle];
  FieldTaps t;
  t.count = 3;
  t.entry = {tri[0], tri[1], tri[2], 0};
  t.weight = {1.0 - w1 - w2, w1, w2, 0.0};
  return t;
}

TexelField::TexelField(const Mesh& mesh, const LightmapReceivers& texels, uint32_t padding)
    : mesh_(mesh), texels_(texels), padding_(padding) {
  PRT_CHECK_OP(texels.uv.corners.size(), ==, 3 * mesh.triangles.size());
}

void TexelField::spread(std::span<const double> rows, size_t width, std::span<double> entries) const {
  PRT_CHECK_OP(entries.size(), ==, this->entries() * width);
  const Lightmap image = texels_.image(rows, width, padding_);
  std::copy(image.values.begin(), image.values.end(), entries.begin());
}

FieldTaps TexelField::taps(uint32_t triangle, double w1, double w2) const {
  const Eigen::Vector2f* c = &texels_.uv.corners[3 * size_t(triangle)];
  const double w0 = 1.0 - w1 - w2;
  const double u = w0 * double(c[0].x()) + w1 * double(c[1].x()) + w2 * double(c[2].x());
  const double v = w0 * double(c[0].y()) + w1 * double(c[1].y()) + w2 * double(c[2].y());
  const BilinearLookup l = bilinear_lookup(u, v, texels_.atlas.width, texels_.atlas.height);
  FieldTaps t;
  t.count = 4;
  t.entry = l.texel;
  t.weight = l.weight;
  return t;
}

void SceneField::add(const BounceField& field, uint32_t first_triangle, uint32_t triangles) {
  if (triangles > 0) {
    PRT_CHECK(tapped_.empty() ||
              parts_[tapped_.back()].first_triangle + parts_[tapped_.back()].triangles <= first_triangle);
    tapped_.push_back(parts_.size());
  }
  parts_.push_back({&field, first_triangle, triangles, rows_, entries_});
  rows_ += field.rows();
  entries_ += field.entries();
}

void SceneField::spread(std::span<const double> rows, size_t width, std::span<double> entries) const {
  PRT_CHECK_OP(rows.size(), ==, rows_ * width);
  PRT_CHECK_OP(entries.size(), ==, entries_ * width);
  for (const Part& part : parts_)
    part.field->spread(rows.subspan(part.first_row * width, part.field->rows() * width), width,
                       entries.subspan(part.first_entry * width, part.field->entries() * width));
}

FieldTaps SceneField::taps(uint32_t triangle, double w1, double w2) const {
  // The last part with triangles that starts at or before `triangle`.
  auto it = std::upper_bound(tapped_.begin(), tapped_.end(), triangle,
                             [&](uint32_t t, size_t part) { return t < parts_[part].first_triangle; });
  if (it == tapped_.begin()) return {};
  const Part& part = parts_[*(it - 1)];
  if (triangle - part.first_triangle >= part.triangles) return {};
  FieldTaps t = part.field->taps(triangle - part.first_triangle, w1, w2);
  for (int k = 0; k < t.count; ++k) t.entry[size_t(k)] += part.first_entry;
  return t;
}

BounceResult bounce_rows(const BounceField& field, std::span<const ShadePoint> points, const GatherHits& hits,
                         std::span<const Albedo> albedo, const ProductLayout& layout, std::span<const double> direct,
                         const BounceSpec& spec, const std::string& source, const Monitor& monitor,
                         const std::string& label, std::span<const uint8_t> shadowed_rows) {
  const size_t V = field.rows(), E = field.entries(), W = layout.width, nt = layout.transfer_count, K = hits.rays;
  // R (9 values, [c][m]) and S (3 L_s² values, [c][i]); either needs E at the hit, eq. (4), from R
  // or from S's band 1 (R_c,m = S_c,(2+m): the same integral).
  const size_t nr = layout.radiance_count, ns = layout.shadowed_count, ls2 = ns / 3;
  const int ls = layout.shadowed_order;
  const bool radiance = nr > 0 || ns > 0;
  PRT_CHECK_OP(points.size(), ==, V);
  PRT_CHECK_OP(direct.size(), ==, V * W);
  PRT_CHECK_OP(hits.rows(), ==, V);
  PRT_CHECK(!radiance || hits.mixture);  // the estimators (5') need the mixture's weights
  PRT_CHECK(ns == 0 || (ls2 == size_t(ls) * size_t(ls) && (nr > 0 || ls >= 2)));  // E from R, or S's band 1
  PRT_CHECK(spec.bounces >= 0);
  check_albedo(albedo, source);
  if (nt > 0)
    for (size_t t = 0; t < albedo.size(); ++t)
      if (albedo[t][0] != albedo[t][1] || albedo[t][0] != albedo[t][2])
        throw InputError(source, "triangle " + std::to_string(t) + "'s albedo is coloured: the diffuse transfer is one "
                                 "vector for all channels, so it bounces with a grey albedo only (R = G = B); the band-1 "
                                 "radiance bounces per channel");
  BounceResult out;
  out.values.assign(direct.begin(), direct.end());
  if ((nt == 0 && !radiance) || spec.bounces == 0) return out;

  // What a bounce gathers per row, [V][S]: T^b (nt values), then E^b_c (3, eq. (4) at the row's
  // normal, when R or S bounces), spread over the field's entries [E][S]. What it makes: per row,
  // [V][B]: T^{b+1} (nt), R^{b+1} ([c][m], nr); per row that carries S (shadowed_rows), [V_s][ns]:
  // S^{b+1} ([c][i]). S is kept apart so that a scene whose few glossy objects carry S does not
  // give every other row S's width (at order 8, 192 doubles a row).
  const size_t S = nt + (radiance ? 3 : 0), B = nt + nr;
  std::vector<uint32_t> s_rows;  // the rows that carry S, ascending
  if (ns > 0) {
    PRT_CHECK(shadowed_rows.empty() || shadowed_rows.size() == V);
    for (size_t v = 0; v < V; ++v)
      if (shadowed_rows.empty() || shadowed_rows[v]) s_rows.push_back(uint32_t(v));
  }
  const size_t VS = s_rows.size();
  std::vector<std::array<double, 3>> y1(radiance ? V : 0);  // y_1m(n_r)
  for (size_t v = 0; v < y1.size(); ++v) {
    const Eigen::Vector3d n = points[v].n.normalized();
    double y[4];
    sh::eval(2, n.x(), n.y(), n.z(), y);
    y1[v] = {y[1], y[2], y[3]};
  }
  std::vector<double> source_rows(V * S), field_values(E * S), made(V * B), made_s(VS * ns);
  // E^b per row from R^b ([V][B] at r_offset, when nr) or else from S's band 1 (ss: [V_s][ns]).
  auto take = [&](std::span<const double> rows, size_t width, size_t t_offset, size_t r_offset, std::span<const double> ss,
                  size_t ss_width, size_t ss_offset) {
    for (size_t v = 0, j = 0; v < V; ++v) {
      for (size_t i = 0; i < nt; ++i) source_rows[v * S + i] = rows[v * width + t_offset + i];
      if (!radiance) continue;
      const double* s_row = nullptr;
      if (!nr && j < s_rows.size() && s_rows[j] == v) s_row = &ss[j++ * ss_width + ss_offset];
      for (size_t c = 0; c < 3; ++c) {  // eq. (4)
        const double* band1 = nr ? &rows[v * width + r_offset + 3 * c] : s_row ? s_row + ls2 * c + 1 : nullptr;
        double e = 0;
        if (band1)
          for (size_t m = 0; m < 3; ++m) e += y1[v][m] * band1[m];
        source_rows[v * S + nt + c] = (4 * std::numbers::pi / 3) * e;  // a row with neither R nor S: none
      }
    }
    field.spread(source_rows, S, field_values);
  };
  // The direct S rows, compacted.
  std::vector<double> direct_s(VS * ns);
  for (size_t j = 0; j < VS; ++j)
    std::copy_n(&direct[size_t(s_rows[j]) * W + layout.shadowed], ns, &direct_s[j * ns]);
  take(direct, W, layout.transfer, layout.radiance, direct_s, ns, 0);
  // The direct pass's RMS per product, over the rows that carry it.
  auto slice_rms = [](std::span<const double> rows, size_t n, size_t width, size_t offset, size_t count) {
    double sum = 0;
    for (size_t v = 0; v < n; ++v)
      for (size_t i = 0; i < count; ++i) sum += rows[v * width + offset + i] * rows[v * width + offset + i];
    return n * count > 0 ? std::sqrt(sum / double(n * count)) : 0.0;
  };
  const double direct_rms[3] = {slice_rms(direct, V, W, layout.transfer, nt), slice_rms(direct, V, W, layout.radiance, nr),
                                slice_rms(direct_s, VS, ns, 0, ns)};

  // A pass's rows hold their even rays' sums in [0, n) and their odd rays' in [n, 2n): the bounce
  // is their sum over K, its standard error their difference over K.
  auto split_halves = [K](std::span<const double> both, size_t rows, size_t n, std::vector<double>& sum,
                          std::vector<double>& half_difference) {
    for (size_t v = 0; v < rows; ++v)
      for (size_t i = 0; i < n; ++i) {
        const double h0 = both[v * 2 * n + i], h1 = both[v * 2 * n + n + i];
        sum[v * n + i] = (h0 + h1) / double(K);
        half_difference[v * n + i] = (h0 - h1) / double(K);
      }
  };
  // Every ray of row v that meets a reflecting surface the field reads: visit(k, ρ(h), the source
  // at h, the estimator's weights (T's, then R's y_1m), the ray's direction and 1/pdf).
  auto for_each_ray = [&](size_t v, auto&& visit) {
    double at_hit[kMaxSource];
    const Frame frame(points[v].n);
    const RotatedHalton3 halton(hits.seed, v);
    for (size_t k = 0; k < K; ++k) {
      const size_t ray = v * K + k;
      const uint32_t t = hits.triangle[ray];
      if (t == GatherHits::kNone) continue;
      const Albedo& rho = albedo[t];
      if (rho[0] == 0 && rho[1] == 0 && rho[2] == 0) continue;
      const FieldTaps taps = field.taps(t, hits.weights[ray][0], hits.weights[ray][1]);
      if (taps.count == 0) continue;
      std::fill(at_hit, at_hit + S, 0.0);
      for (size_t c = 0; c < size_t(taps.count); ++c) {
        const double* src = &field_values[taps.entry[c] * S];
        for (size_t i = 0; i < S; ++i) at_hit[i] += taps.weight[c] * src[i];
      }
      std::array<double, 4> weight{1, 0, 0, 0};  // the cosine gather's: T's weight is 1
      double inv_p = 0;
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      if (hits.mixture) {
        d = gather_direction(frame, halton, k, true);
        weight = mixture_weights(points[v].n, d, &inv_p);
      }
      visit(k, rho, static_cast<const double*>(at_hit), weight, d, inv_p);
    }
  };

  for (int b = 1; b <= spec.bounces; ++b) {
    // Eqs. (3) / (3') and (5'): each ray adds ρ(h) × (the source at h, as the field reads it) × its
    // weights; S's weights are (5') with y_i in place of y_1m.
    // Each row sums its even and its odd rays apart ([0, B) and [B, 2B)): their sum over K is the
    // bounce, their difference over K its Monte Carlo standard error (two halves of the rays).
    const std::string stage = label + " (bounce " + std::to_string(b) + ")", what = "the bounce gather of " + source;
    double seconds = 0;
    std::vector<double> half_difference(V * B), half_difference_s(VS * ns);
    if (B > 0) {
      VertexBake pass = bake_rows(
          0, V, 2 * B,
          [&](size_t v, std::span<double> both, std::span<double>) {
            for_each_ray(v, [&](size_t k, const Albedo& rho, const double* at_hit, const std::array<double, 4>& weight,
                                const Eigen::Vector3d&, double) {
              const std::span<double> row = both.subspan((k % 2) * B, B);
              for (size_t i = 0; i < nt; ++i) row[i] += rho[0] * weight[0] * at_hit[i];  // grey (checked)
              if (nr)
                for (size_t c = 0; c < 3; ++c)
                  for (size_t m = 0; m < 3; ++m) row[nt + 3 * c + m] += rho[c] * at_hit[nt + c] * weight[1 + m];
            });
          },
          monitor, stage, what);
      seconds += pass.seconds;
      split_halves(pass.values, V, B, made, half_difference);
    }
    if (VS > 0) {  // the mixture (checked above): d and inv_p are the ray's
      VertexBake pass = bake_rows(
          0, VS, 2 * ns,
          [&](size_t j, std::span<double> both, std::span<double>) {
            double ys[sh::kMaxOrder * sh::kMaxOrder];
            for_each_ray(s_rows[j], [&](size_t k, const Albedo& rho, const double* at_hit, const std::array<double, 4>&,
                                        const Eigen::Vector3d& d, double inv_p) {
              const std::span<double> row = both.subspan((k % 2) * ns, ns);
              sh::eval(ls, d.x(), d.y(), d.z(), ys);
              for (size_t c = 0; c < 3; ++c) {
                const double e = rho[c] * at_hit[nt + c];
                if (e == 0) continue;
                for (size_t i = 0; i < ls2; ++i) row[ls2 * c + i] += e * (ys[i] * kInvPi * inv_p);
              }
            });
          },
          monitor, stage + (B > 0 ? ", shadowed radiance" : ""), what);
      seconds += pass.seconds;
      split_halves(pass.values, VS, ns, made_s, half_difference_s);
    }
    // Summed only where non-zero, so an albedo of 0 leaves the direct rows' bits (−0 included).
    for (size_t v = 0; v < V; ++v) {
      for (size_t i = 0; i < nt; ++i)
        if (const double x = made[v * B + i]; x != 0) out.values[v * W + layout.transfer + i] += x;
      for (size_t i = 0; i < nr; ++i)
        if (const double x = made[v * B + nt + i]; x != 0) out.values[v * W + layout.radiance + i] += x;
    }
    for (size_t j = 0; j < VS; ++j)
      for (size_t i = 0; i < ns; ++i)
        if (const double x = made_s[j * ns + i]; x != 0) out.values[size_t(s_rows[j]) * W + layout.shadowed + i] += x;
    const double rms[3] = {slice_rms(made, V, B, 0, nt), slice_rms(made, V, B, nt, nr), slice_rms(made_s, VS, ns, 0, ns)};
    const double err[3] = {slice_rms(half_difference, V, B, 0, nt), slice_rms(half_difference, V, B, nt, nr),
                           slice_rms(half_difference_s, VS, ns, 0, ns)};
    double r = 0, e = 0;
    for (size_t p = 0; p < 3; ++p)
      if (direct_rms[p] > 0) {
        r = std::max(r, rms[p] / direct_rms[p]);
        e = std::max(e, err[p] / direct_rms[p]);
      }
    out.applied = b;
    out.relative_rms.push_back(r);
    out.relative_std_error.push_back(e);
    out.seconds.push_back(seconds);
    if (r <= spec.tolerance || b == spec.bounces) break;
    take(made, B, 0, nt, made_s, ns, 0);
  }
  for (const double x : out.values)
    if (!std::isfinite(x)) throw ContractError("bounce_rows: a non-finite value in the bounced rows of " + source);
  return out;
}

} // namespace prt::bake
