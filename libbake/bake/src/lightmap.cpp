// lightmap.cpp — rows to a lightmap image, invalid texels filled, charts padded (bake/bake/lightmap.h).
#include <bake/bake/lightmap.h>
#include <bake/core/error.h>

#include <algorithm>

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
  for (uint32_t r = 0; r < padding; ++r) {
    // The empty texels next to a known one.
    std::vector<size_t> ring;
    for (size_t k = 0; k < texels; ++k) {
      if (m.state[k] != uint8_t(TexelState::Empty) || m.chart[k] != Lightmap::kNoChart) continue;
      const long x = long(k % W), y = long(k / W);
      for (const auto& d : kNeighbours) {
        const long nx = x + d[0], ny = y + d[1];
        if (nx < 0 || ny < 0 || nx >= long(W) || ny >= long(H)) continue;
        if (known(m.state[size_t(ny) * W + size_t(nx)])) {
          ring.push_back(k);
          break;
        }
      }
    }
    if (ring.empty()) break;
    m.padded += round(ring, TexelState::Padded);
  }
  return m;
}

} // namespace prt::bake
