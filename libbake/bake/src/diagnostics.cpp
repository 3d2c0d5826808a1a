// diagnostics.cpp — rows that see no sky, and the flipped-normal probe (bake/bake/diagnostics.h).
#include <bake/bake/diagnostics.h>
#include <bake/core/error.h>
#include <bake/sphere/sampling.h>
#include <bake/visibility/raycast.h>

#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

namespace prt::bake {

namespace {
// Whether each row saw no sky: its sky measure (AO, else T_0, else U_0; see the header) is 0, or
// every value is 0 for a radiance-only bake.
std::vector<uint8_t> dark_rows(const VertexBake& bake) {
  const ProductLayout& L = bake.layout;
  const size_t W = L.width;
  const size_t rows = W ? bake.values.size() / W : 0;
  const size_t none = W;
  const size_t column = L.ao_count ? L.ao : L.transfer_count ? L.transfer : L.visibility_count ? L.visibility : none;
  std::vector<uint8_t> dark(rows);
  for (size_t r = 0; r < rows; ++r) {
    const auto row = std::span(bake.values).subspan(r * W, W);
    dark[r] = column != none ? row[column] == 0.0 : std::all_of(row.begin(), row.end(), [](double x) { return x == 0.0; });
  }
  return dark;
}
} // namespace

NoSkyCount count_no_sky(const VertexBake& bake) {
  const std::vector<uint8_t> dark = dark_rows(bake);
  return {size_t(std::count(dark.begin(), dark.end(), uint8_t(1))), dark.size()};
}

FlipProbe probe_flipped_normals(const Mesh& mesh, const Topology& topology, const VertexBake& bake, size_t sample,
                                uint32_t rays, uint64_t seed) {
  const std::vector<uint8_t> dark = dark_rows(bake);
  PRT_CHECK_OP(dark.size(), ==, mesh.positions.size());
  std::vector<uint32_t> rows;
  for (uint32_t r = 0; r < dark.size(); ++r)
    if (dark[r]) rows.push_back(r);
  FlipProbe probe;
  if (rows.empty() || rays == 0) return probe;
  const RayCaster caster(mesh, topology);
  constexpr double kGolden = 2.399963229728653;  // π(3 − √5): the golden angle
  for (const uint32_t i : seeded_sample(uint32_t(rows.size()), sample, seed)) {
    ShadePoint sp = vertex_shade_point(mesh, topology, rows[i]);
    sp.n = -sp.n;
    const NearTriangles near = caster.near_triangles(sp);
    const Frame frame(sp.n);
    bool sky = false;
    for (uint32_t k = 0; k < rays && !sky; ++k) {  // a Fibonacci spiral over the hemisphere
      const double z = 1 - (k + 0.5) / rays, r = std::sqrt(std::max(0.0, 1 - z * z)), phi = kGolden * k;
      sky = caster.visible(sp, near, frame.to_world(Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), z)));
    }
    ++probe.probed;
    probe.would_see_sky += sky ? 1 : 0;
  }
  return probe;
}

} // namespace prt::bake
