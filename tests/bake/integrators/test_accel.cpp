// Tests of shared acceleration structures (bake/visibility/accel.h): integrators that share one MeshAccel
// give the rows of integrators that build their own, bit for bit; the trees are built once, on
// first use; an accel of another mesh is refused.
#include <bake/core/error.h>
#include <bake/integrators/qmc.h>
#include <bake/integrators/silhouette.h>
#include <bake/mesh/mesh.h>
#include <bake/mesh/receivers.h>
#include <bake/sphere/sampling.h>
#include <bake/visibility/accel.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <vector>

namespace {

using namespace prt::bake;

TEST(MeshAccel, SharedTreesGiveTheSameRowsBitForBit) {
  const Mesh mesh = load_mesh(std::filesystem::path(PRT_DATA_DIR) / "bunny_ground.obj", {.use_file_normals = false});
  const Topology topo = build_topology(mesh);
  const std::vector<ShadePoint> points = vertex_shade_points(mesh, topo);
  ProductRequest r;
  r.ao = true;
  r.transfer_order = 3;
  const MeshAccel accel(mesh, topo);
  const QmcIntegrator qmc_shared(mesh, topo, r, QmcOptions{64, 5}, &accel);
  EXPECT_FALSE(accel.contours_built());  // QMC needs only the ray scene
  const SilhouetteIntegrator sil_shared(mesh, topo, r, SilhouetteOptions{24, 1}, &accel);
  EXPECT_TRUE(accel.contours_built());
  const SilhouetteIntegrator sil_shared2(mesh, topo, r, SilhouetteOptions{40, 1}, &accel);
  const QmcIntegrator qmc_own(mesh, topo, r, QmcOptions{64, 5});
  const SilhouetteIntegrator sil_own(mesh, topo, r, SilhouetteOptions{24, 1});
  const SilhouetteIntegrator sil_own2(mesh, topo, r, SilhouetteOptions{40, 1});
  const size_t W = ProductLayout(r).width;
  std::vector<double> a(W), b(W);
  const std::pair<const Integrator*, const Integrator*> pairs[] = {
      {&qmc_shared, &qmc_own}, {&sil_shared, &sil_own}, {&sil_shared2, &sil_own2}};
  for (const uint32_t v : seeded_sample(uint32_t(points.size()), 48, 3))
    for (const auto& [shared, own] : pairs) {
      shared->integrate(points[v], v, a);
      own->integrate(points[v], v, b);
      EXPECT_EQ(a, b) << "vertex " << v << ", " << to_string(shared->kind());
    }
  EXPECT_EQ(accel.rays().get(), accel.rays().get());  // built once
  EXPECT_EQ(accel.contours().get(), accel.contours().get());
}

TEST(MeshAccel, AnAccelOfAnotherMeshIsRefused) {
  const Mesh mesh = load_mesh(std::filesystem::path(PRT_DATA_DIR) / "bunny.obj");
  const Topology topo = build_topology(mesh), other = build_topology(mesh);
  const MeshAccel accel(mesh, other);
  ProductRequest r;
  r.ao = true;
  EXPECT_THROW(QmcIntegrator(mesh, topo, r, QmcOptions{16, 1}, &accel), ContractError);
  EXPECT_THROW(SilhouetteIntegrator(mesh, topo, r, SilhouetteOptions{8, 1}, &accel), ContractError);
}

} // namespace
