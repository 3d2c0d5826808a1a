// lightmap.cpp — rows to a lightmap image, invalid texels filled, charts padded (bake/bake/lightmap.h).
#include <bake/bake/lightmap.h>
#include <bake/core/error.h>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

namespace prt::bake {
namespace {

constexpr int kNeighbours[8][2] = {{-1, -1}, {0, -1}, {1, -1}, {-1, 0}, {1, 0}, {-1, 1}, {0, 1}, {1, 1}};

bool known(uint8_t s) { return s != uint8_t(TexelState::Empty); }

} // namespace

Lightmap make_lightmap(const TexelAtlas& atlas, std::span<const double> rows, size_t channels,
                       std::span<const uint8_t> invalid, uint32_t padding) {
  PRT_CHECK_OP(rows.size(), ==, atlas.samples.size() * channels);
  PRT_CHECK(invalid.empty() || invalid.size() == atlas.samples.size());
  Lightmap m;
  m.width = atlas.width;
  m.height = atlas.height;
  m.channels = uint32_t(channels);
  const size_t W = m.width, H = m.height, C = channels, texels = W * H;
  m.values.assign(texels * C, 0.0);
  m.state.assign(texels, uint8_t(TexelState::Empty));
  m.chart.assign(texels, Lightmap::kNoChart);
  std::vector<size_t> pending;  // invalid texels, in texel order
  for (size_t i = 0; i < atlas.samples.size(); ++i) {
    const size_t k = atlas.samples[i].texel;
    m.chart[k] = atlas.samples[i].chart;
    if (!invalid.empty() && invalid[i]) {
      pending.push_back(k);
      continue;
    }
    m.state[k] = uint8_t(TexelState::Baked);
    std::copy_n(rows.begin() + std::ptrdiff_t(i * C), C, m.values.begin() + std::ptrdiff_t(k * C));
  }
  // One round: every texel of `targets` with known neighbours (in `chart_of(k)`'s chart, or
  // the lowest-numbered chart among them when it has none) takes their mean; returns how many did.
  auto round = [&](std::vector<size_t>& targets, TexelState as) {
    const std::vector<uint8_t> before = m.state;
    std::vector<size_t> left, done;
    std::vector<double> sum(C);
    std::vector<std::pair<size_t, std::vector<double>>> updates;
    std::vector<uint32_t> charts;
    for (size_t k : targets) {
      const long x = long(k % W), y = long(k / W);
      uint32_t want = m.chart[k];
      if (want == Lightmap::kNoChart)
        for (const auto& d : kNeighbours) {
          const long nx = x + d[0], ny = y + d[1];
          if (nx < 0 || ny < 0 || nx >= long(W) || ny >= long(H)) continue;
          const size_t j = size_t(ny) * W + size_t(nx);
          if (known(before[j])) want = std::min(want, m.chart[j]);
        }
      std::fill(sum.begin(), sum.end(), 0.0);
      int n = 0;
      for (const auto& d : kNeighbours) {
        const long nx = x + d[0], ny = y + d[1];
        if (nx < 0 || ny < 0 || nx >= long(W) || ny >= long(H)) continue;
        const size_t j = size_t(ny) * W + size_t(nx);
        if (!known(before[j]) || m.chart[j] != want) continue;
        for (size_t c = 0; c < C; ++c) sum[c] += m.values[j * C + c];
        ++n;
      }
      if (n == 0) {
        left.push_back(k);
        continue;
      }
      for (double& s : sum) s /= n;
      updates.emplace_back(k, sum);
      charts.push_back(want);
    }
    for (size_t u = 0; u < updates.size(); ++u) {
      const size_t k = updates[u].first;
      std::copy(updates[u].second.begin(), updates[u].second.end(), m.values.begin() + std::ptrdiff_t(k * C));
      m.state[k] = uint8_t(as);
      m.chart[k] = charts[u];
    }
    targets = std::move(left);
    return updates.size();
  };
  while (!pending.empty()) {
    const size_t n = round(pending, TexelState::Filled);
    if (n == 0) break;
    m.filled += n;
  }
  m.unfilled = pending.size();
  // The padding: every empty texel within `padding` rings (Chebyshev distance, 8-neighbourhood) of
  // a covered texel, and every invalid texel no valid texel of its chart reaches (a chart wholly
  // inside the geometry: never seen, but never empty for a bilinear lookup or a mip level), takes
  // in rounds the mean of its known neighbours of the lowest-numbered chart among them. Rings
  // count from the charts' texels, baked or not, so a gutter beside a chart inside the geometry is
  // padded as any other.
  std::vector<uint32_t> ring(texels, std::numeric_limits<uint32_t>::max());
  {
    std::vector<size_t> frontier;
    for (const TexelSample& s : atlas.samples) ring[s.texel] = 0, frontier.push_back(s.texel);
    for (uint32_t r = 1; r <= padding && !frontier.empty(); ++r) {
      std::vector<size_t> next;
      for (size_t k : frontier) {
        const long x = long(k % W), y = long(k / W);
        for (const auto& d : kNeighbours) {
          const long nx = x + d[0], ny = y + d[1];
          if (nx < 0 || ny < 0 || nx >= long(W) || ny >= long(H)) continue;
          const size_t j = size_t(ny) * W + size_t(nx);
          if (ring[j] > r) ring[j] = r, next.push_back(j);
        }
      }
      frontier = std::move(next);
    }
  }
  std::vector<size_t> targets;  // none without padding: the unfilled then stay empty
  if (padding > 0)
    for (size_t k = 0; k < texels; ++k)
      if (m.state[k] == uint8_t(TexelState::Empty) && ring[k] <= padding) targets.push_back(k);
  for (size_t k : pending) m.chart[k] = Lightmap::kNoChart;
  while (!targets.empty()) {
    const size_t n = round(targets, TexelState::Padded);
    if (n == 0) break;
    m.padded += n;
  }
  return m;
}

BilinearLookup bilinear_lookup(double u, double v, size_t W, size_t H) {
  const double x = u * double(W) - 0.5, y = v * double(H) - 0.5;
  const double fx0 = std::floor(x), fy0 = std::floor(y);
  const double fx = x - fx0, fy = y - fy0;
  auto clampi = [](double c, size_t n) { return size_t(std::clamp(c, 0.0, double(n - 1))); };
  const size_t x0 = clampi(fx0, W), x1 = clampi(fx0 + 1, W), y0 = clampi(fy0, H), y1 = clampi(fy0 + 1, H);
  BilinearLookup l;
  l.texel = {y0 * W + x0, y0 * W + x1, y1 * W + x0, y1 * W + x1};
  l.weight = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
  return l;
}

std::array<size_t, kMipLevels + 1> mip_empty_hits(const Lightmap& image, const TexelAtlas& atlas, const UvSet& uv) {
  PRT_CHECK_OP(image.state.size(), ==, size_t(image.width) * image.height);
  // The points: each sample's UV (its triangle's corner UVs at its barycentric weights), and
  // every corner UV of a triangle some sample lies on.
  std::vector<Eigen::Vector2d> points;
  std::vector<uint8_t> seen(uv.corners.size() / 3, 0);
  for (const TexelSample& s : atlas.samples) {
    Eigen::Vector2d p = Eigen::Vector2d::Zero();
    for (int k = 0; k < 3; ++k) p += s.barycentric[k] * uv.corners[3 * size_t(s.triangle) + size_t(k)].cast<double>();
    points.push_back(p);
    if (!seen[s.triangle]) {
      seen[s.triangle] = 1;
      for (int k = 0; k < 3; ++k) points.push_back(uv.corners[3 * size_t(s.triangle) + size_t(k)].cast<double>());
    }
  }
  std::array<size_t, kMipLevels + 1> hits{};
  // Level k's empty flags, from level k − 1's.
  size_t W = image.width, H = image.height;
  std::vector<uint8_t> empty(W * H);
  for (size_t t = 0; t < W * H; ++t) empty[t] = image.state[t] == uint8_t(TexelState::Empty);
  for (int level = 0; level <= kMipLevels; ++level) {
    if (level > 0) {
      const size_t w = (W + 1) / 2, h = (H + 1) / 2;
      std::vector<uint8_t> next(w * h, 0);
      for (size_t y = 0; y < H; ++y)
        for (size_t x = 0; x < W; ++x) next[(y / 2) * w + x / 2] |= empty[y * W + x];
      empty = std::move(next), W = w, H = h;
    }
    for (const Eigen::Vector2d& p : points) {
      const BilinearLookup l = bilinear_lookup(p.x(), p.y(), W, H);
      for (int k = 0; k < 4; ++k)
        if (l.weight[size_t(k)] > 0 && empty[l.texel[size_t(k)]]) {
          ++hits[size_t(level)];
          break;
        }
    }
  }
  return hits;
}

SeamStitch stitch_seams(Lightmap& image, const TexelAtlas& atlas, const Mesh& mesh, const Topology& topology,
                        const UvSet& uv, double lambda) {
  PRT_CHECK_OP(atlas.triangle_chart.size(), ==, mesh.triangles.size());
  PRT_CHECK_OP(uv.corners.size(), ==, mesh.triangles.size() * 3);
  PRT_CHECK(lambda > 0);
  SeamStitch out;
  const size_t W = image.width, H = image.height, C = image.channels;
  if (W == 0 || H == 0 || C == 0) return out;
  // Edges by their welded corners: (triangle, corner index of the edge's first end) per side.
  std::map<std::pair<uint32_t, uint32_t>, std::vector<std::pair<uint32_t, int>>> edges;
  for (uint32_t t = 0; t < mesh.triangles.size(); ++t)
    for (int c = 0; c < 3; ++c) {
      const uint32_t a = topology.weld[mesh.triangles[t][size_t(c)]], b = topology.weld[mesh.triangles[t][size_t((c + 1) % 3)]];
      if (a != b) edges[std::minmax(a, b)].push_back({t, c});
    }
  struct Point {
    BilinearLookup side[2];
  };
  std::vector<Point> points;
  auto uv_at = [&](uint32_t t, int c) { return uv.corners[size_t(3 * t + uint32_t(c))].cast<double>(); };
  for (const auto& [key, sides] : edges) {
    if (sides.size() != 2) continue;  // a border or a non-manifold edge: no two sides to agree
    // Each side's UVs at the edge's welded ends, in the order (key.first, key.second).
    std::array<std::array<Eigen::Vector2d, 2>, 2> end;
    for (int s = 0; s < 2; ++s) {
      const auto [t, c] = sides[size_t(s)];
      const bool forward = topology.weld[mesh.triangles[t][size_t(c)]] == key.first;
      end[size_t(s)][0] = uv_at(t, forward ? c : (c + 1) % 3);
      end[size_t(s)][1] = uv_at(t, forward ? (c + 1) % 3 : c);
    }
    if (end[0][0] == end[1][0] && end[0][1] == end[1][1]) continue;  // the same UVs: one chart, no seam
    // A hard edge (the two sides' normals differ at an end) is a crease of the shading, not a seam
    // of a continuous surface: its two sides rightly differ.
    bool smooth = true;
    for (int e = 0; e < 2 && smooth; ++e) {
      std::array<Eigen::Vector3f, 2> nrm;
      for (int s = 0; s < 2; ++s) {
        const auto [t, c] = sides[size_t(s)];
        const bool forward = topology.weld[mesh.triangles[t][size_t(c)]] == key.first;
        const int corner = (e == 0) == forward ? c : (c + 1) % 3;
        nrm[size_t(s)] = mesh.normals[mesh.triangles[t][size_t(corner)]];
      }
      smooth = nrm[0] == nrm[1];
    }
    if (!smooth) continue;
    const Eigen::Vector2d scale{static_cast<double>(W), static_cast<double>(H)};
    const double len = std::max((end[0][1] - end[0][0]).cwiseProduct(scale).norm(), (end[1][1] - end[1][0]).cwiseProduct(scale).norm());
    if (!(len > 0) || !std::isfinite(len)) continue;
    ++out.edges;
    const int k = std::max(2, int(std::ceil(2 * len)));
    for (int i = 0; i < k; ++i) {
      const double f = (i + 0.5) / k;
      Point p;
      bool usable = true;
      for (int s = 0; s < 2; ++s) {
        const Eigen::Vector2d q = (1 - f) * end[size_t(s)][0] + f * end[size_t(s)][1];
        p.side[s] = bilinear_lookup(q.x(), q.y(), W, H);
        const uint32_t own = atlas.triangle_chart[sides[size_t(s)].first];
        for (const size_t tx : p.side[s].texel)
          usable = usable && image.state[tx] != uint8_t(TexelState::Empty) && image.chart[tx] == own;
      }
      if (usable) points.push_back(p);
      else ++out.skipped_points;
    }
  }
  out.points = points.size();
  if (points.empty()) return out;
  // The unknowns: the texels the points touch, in texel order.
  std::map<size_t, int> index;
  for (const Point& p : points)
    for (const BilinearLookup& l : p.side)
      for (const size_t tx : l.texel) index.emplace(tx, 0);
  int n = 0;
  for (auto& [tx, i] : index) i = n++;
  out.texels = index.size();
  auto difference = [&](const Point& p, size_t c) {
    double d = 0;
    for (int q = 0; q < 4; ++q) d += p.side[0].weight[size_t(q)] * image.values[p.side[0].texel[size_t(q)] * C + c];
    for (int q = 0; q < 4; ++q) d -= p.side[1].weight[size_t(q)] * image.values[p.side[1].texel[size_t(q)] * C + c];
    return std::abs(d);
  };
  for (const Point& p : points)
    for (size_t c = 0; c < C; ++c) {
      const double d = difference(p, c);
      out.mean_before += d, out.max_before = std::max(out.max_before, d);
    }
  out.mean_before /= double(points.size() * C);
  // AᵀA + λ²I: each point's row is +w on side 0's texels, −w on side 1's.
  std::vector<Eigen::Triplet<double>> triplets;
  for (const Point& p : points) {
    std::array<std::pair<int, double>, 8> row;
    for (int s = 0; s < 2; ++s)
      for (int q = 0; q < 4; ++q)
        row[size_t(4 * s + q)] = {index.at(p.side[s].texel[size_t(q)]), (s == 0 ? 1.0 : -1.0) * p.side[s].weight[size_t(q)]};
    for (const auto& [i, wi] : row)
      for (const auto& [j, wj] : row) triplets.emplace_back(i, j, wi * wj);
  }
  // λ per texel: a texel baked at its centre holds the exact surface value there; one baked at the
  // nearest point of a border holds a value from elsewhere (bilinear filtering takes it for its
  // centre's), a filled or padded one only its chart's mean beside it: those follow the seam (λ/10).
  std::vector<double> lam2(static_cast<size_t>(n));
  std::vector<uint8_t> centre(W * H, 0);  // baked at its own centre (not the nearest point of a border)
  for (const TexelSample& sm : atlas.samples) centre[sm.texel] = sm.centre;
  for (const auto& [tx, i] : index) {
    const double l = image.state[tx] == uint8_t(TexelState::Baked) && centre[tx] ? lambda : 0.1 * lambda;
    lam2[size_t(i)] = l * l;
  }
  for (int i = 0; i < n; ++i) triplets.emplace_back(i, i, lam2[size_t(i)]);
  Eigen::SparseMatrix<double> M(n, n);
  M.setFromTriplets(triplets.begin(), triplets.end());
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(M);
  PRT_CHECK(solver.info() == Eigen::Success);  // positive definite: AᵀA + λ²I with λ > 0
  Eigen::VectorXd rhs(n);
  for (size_t c = 0; c < C; ++c) {
    for (const auto& [tx, i] : index) rhs[i] = lam2[size_t(i)] * image.values[tx * C + c];
    const Eigen::VectorXd x = solver.solve(rhs);
    for (const auto& [tx, i] : index)
      if (std::isfinite(x[i])) {
        if (image.state[tx] == uint8_t(TexelState::Baked) && centre[tx])
          out.baked_moved_max = std::max(out.baked_moved_max, std::abs(x[i] - image.values[tx * C + c]));
        image.values[tx * C + c] = x[i];
      }
  }
  for (const Point& p : points)
    for (size_t c = 0; c < C; ++c) {
      const double d = difference(p, c);
      out.mean_after += d, out.max_after = std::max(out.max_after, d);
    }
  out.mean_after /= double(points.size() * C);
  return out;
}

} // namespace prt::bake
