// Loop subdivision through OpenMesh's LoopT on the welded topology (bake/mesh/subdivide.h).
#include <bake/core/error.h>
#include <bake/mesh/subdivide.h>

#include "openmesh.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace prt::bake {
namespace {

// Points and the "Normal" type LoopT accumulates in are double: positions are averaged over
// several levels, and the input floats are exactly representable.
struct LoopTraits : OpenMesh::DefaultTraits {
  typedef OpenMesh::Vec3d Point;
  typedef OpenMesh::Vec3d Normal;
};
using OmMesh = OpenMesh::TriMesh_ArrayKernelT<LoopTraits>;

std::string tri_name(size_t t) { return "triangle " + std::to_string(t); }

} // namespace

Mesh loop_subdivide(const Mesh& mesh, int levels) {
  PRT_CHECK_OP(levels, >=, 0);
  const Topology topo = build_topology(mesh);
  const size_t W = topo.welded_positions.size(), T = mesh.triangles.size();

  // Welded corners of every triangle, checked before OpenMesh sees them.
  std::vector<std::array<uint32_t, 3>> tris(T);
  for (size_t t = 0; t < T; ++t) {
    for (int k = 0; k < 3; ++k) tris[t][size_t(k)] = topo.weld[mesh.triangles[t][size_t(k)]];
    const auto& w = tris[t];
    if (w[0] == w[1] || w[1] == w[2] || w[2] == w[0])
      throw InputError(mesh.source, "loop subdivision: " + tri_name(t) +
                                        " has a repeated (welded) corner; OpenMesh cannot represent it");
  }
  for (uint32_t e = 0; e < topo.edges.size(); ++e) {
    const auto faces = topo.faces_of_edge(e);
    const auto [a, b] = topo.edges[e];
    if (faces.size() > 2)
      throw InputError(mesh.source, "loop subdivision: non-manifold edge between welded positions " +
                                        std::to_string(a) + " and " + std::to_string(b) + " (" +
                                        std::to_string(faces.size()) + " triangles, first " +
                                        tri_name(faces[0]) + ")");
    if (faces.size() == 2) {
      // Direction in which each triangle traverses the edge: +1 for a→b, −1 for b→a.
      auto direction = [&, ea = a, eb = b](uint32_t t) {  // (clang 14 cannot capture a structured binding)
        const auto& w = tris[t];
        for (int k = 0; k < 3; ++k) {
          const uint32_t from = w[size_t(k)], to = w[size_t((k + 1) % 3)];
          if (from == ea && to == eb) return 1;
          if (from == eb && to == ea) return -1;
        }
        return 0;
      };
      if (direction(faces[0]) == direction(faces[1]))
        throw InputError(mesh.source, "loop subdivision: " + tri_name(faces[0]) + " and " +
                                          tri_name(faces[1]) + " are wound inconsistently across their shared edge");
    }
  }

  // Welded positions referenced by a triangle, in welded order.
  std::vector<char> used(W, 0);
  for (const auto& w : tris)
    for (uint32_t v : w) used[v] = 1;

  OmMesh om;
  std::vector<OmMesh::VertexHandle> handle(W);
  for (size_t v = 0; v < W; ++v)
    if (used[v]) {
      const Eigen::Vector3f& p = topo.welded_positions[v];
      handle[v] = om.add_vertex(OmMesh::Point(double(p.x()), double(p.y()), double(p.z())));
    }
  for (size_t t = 0; t < T; ++t) {
    const auto& w = tris[t];
    const OmMesh::FaceHandle f = om.add_face(handle[w[0]], handle[w[1]], handle[w[2]]);
    if (!f.is_valid())
      throw InputError(mesh.source, "loop subdivision: OpenMesh refused " + tri_name(t) +
                                        " (non-manifold vertex configuration); no face may be dropped");
  }
  if (om.n_faces() != T)
    throw InputError(mesh.source, "loop subdivision: OpenMesh holds " + std::to_string(om.n_faces()) +
                                      " faces of " + std::to_string(T));

  if (levels > 0) {
    // LoopT's weight table covers valence < 50 by default and indexes it unchecked; size it for
    // this mesh (subdivision never raises a valence: old vertices keep theirs, new ones have 6).
    size_t max_valence = 0;
    for (const auto vh : om.vertices()) max_valence = std::max(max_valence, size_t(om.valence(vh)));
    OpenMesh::Subdivider::Uniform::LoopT<OmMesh, double> loop;
    loop.init_weights(std::max<size_t>(max_valence + 1, 50));
    if (!loop(om, size_t(levels)))
      throw InputError(mesh.source, "loop subdivision: OpenMesh's subdivider failed");
  }

  const size_t expected = T << (2 * size_t(levels));
  PRT_CHECK_OP(om.n_faces(), ==, expected);

  std::vector<Eigen::Vector3f> positions;
  positions.reserve(om.n_vertices());
  for (const auto vh : om.vertices()) {
    const OmMesh::Point& p = om.point(vh);
    positions.emplace_back(float(p[0]), float(p[1]), float(p[2]));
  }
  std::vector<std::array<uint32_t, 3>> triangles;
  triangles.reserve(om.n_faces());
  for (const auto fh : om.faces()) {
    std::array<uint32_t, 3> tri{};
    size_t k = 0;
    for (const auto vh : om.fv_range(fh)) {
      PRT_CHECK_OP(k, <, size_t(3));
      tri[k++] = uint32_t(vh.idx());
    }
    PRT_CHECK_OP(k, ==, size_t(3));
    triangles.push_back(tri);
  }
  return make_mesh(std::move(positions), std::move(triangles),
                   mesh.source + " (loop x" + std::to_string(levels) + ")");
}

} // namespace prt::bake
