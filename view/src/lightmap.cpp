// lightmap.cpp — bilinear lightmap sampling through a triangle's UVs and per-texel shading
// (view/lightmap.h: the rule and the empty-texel check).
#include <view/lightmap.h>

#include <bake/core/error.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <vector>

namespace prt::view {

bool sample_lightmap(const LightmapImage& map, double u, double v, float* out) {
  PRT_CHECK(map.width > 0 && map.height > 0 && map.channels > 0);
  PRT_CHECK_OP(map.values.size(), ==, size_t(map.width) * size_t(map.height) * map.channels);
  PRT_CHECK_OP(map.state.size(), ==, size_t(map.width) * size_t(map.height));
  // Texel coordinates, clamped to the centres of the edge texels (clamp-to-edge).
  const double s = std::clamp(u * map.width - 0.5, 0.0, double(map.width - 1));
  const double r = std::clamp(v * map.height - 0.5, 0.0, double(map.height - 1));
  const int x0 = std::min(int(std::floor(s)), map.width - 1), y0 = std::min(int(std::floor(r)), map.height - 1);
  const int x1 = std::min(x0 + 1, map.width - 1), y1 = std::min(y0 + 1, map.height - 1);
  const double fx = s - x0, fy = r - y0;
  const int xs[4] = {x0, x1, x0, x1}, ys[4] = {y0, y0, y1, y1};
  const double w[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
  bool empty = false;
  const float* value[4] = {};  // the texels with weight > 0, in the order k above
  double weight[4] = {};
  int used = 0;
  for (int k = 0; k < 4; ++k) {
    if (!(w[k] > 0)) continue;
    const size_t texel = size_t(ys[k]) * size_t(map.width) + size_t(xs[k]);
    if (map.state[texel] == 0) empty = true;
    value[used] = map.values.data() + texel * map.channels, weight[used++] = w[k];
  }
  // Any channel count (a glossy lightmap holds 3 x order² floats): each channel summed in double
  // over the same texels in the same order, rounded once.
  for (size_t c = 0; c < map.channels; ++c) {
    double sum = 0;
    for (int k = 0; k < used; ++k) sum += weight[k] * double(value[k][c]);
    out[c] = float(sum);
  }
  return empty;
}

Eigen::Vector2d fragment_uv(const Fragment& f, std::span<const float> corner_uv, size_t triangle) {
  PRT_CHECK_OP(6 * triangle + 6, <=, corner_uv.size());
  const float* uv = corner_uv.data() + 6 * triangle;
  Eigen::Vector2d out = Eigen::Vector2d::Zero();
  for (size_t k = 0; k < 3; ++k) out += double(f.bary[k]) * Eigen::Vector2d(double(uv[2 * k]), double(uv[2 * k + 1]));
  return out;
}

TexelRender shade_texels(const bake::Mesh& mesh, const GBuffer& g, std::span<const float> corner_uv, const LightmapImage& map,
                         const std::function<void(const Fragment&, const float* sample, float* rgb)>& shade) {
  PRT_CHECK_OP(corner_uv.size(), ==, 6 * mesh.triangles.size());
  TexelRender out;
  out.image = Image(g.width, g.height);
  std::atomic<size_t> pixels{0}, empty_hits{0};
  tbb::parallel_for(0, g.height, [&](int y) {
    std::vector<float> sample(map.channels);
    size_t row_pixels = 0, row_empty = 0;
    for (int x = 0; x < g.width; ++x) {
      if (g.triangle[size_t(y) * size_t(g.width) + size_t(x)] < 0) continue;
      const Fragment f = make_fragment(mesh, g, x, y);
      const Eigen::Vector2d uv = fragment_uv(f, corner_uv, size_t(f.triangle));
      if (sample_lightmap(map, uv.x(), uv.y(), sample.data())) ++row_empty;
      ++row_pixels;
      shade(f, sample.data(), out.image.at(x, y));
    }
    pixels += row_pixels;
    empty_hits += row_empty;
  });
  out.pixels = pixels;
  out.empty_hits = empty_hits;
  return out;
}

} // namespace prt::view
