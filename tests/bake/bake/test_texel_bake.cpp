// Texels through the bake pipeline (bake/mesh/texels.h, bake/bake/pipeline.h), against a closed
// form: a floor with a unit box standing on it. AO at a floor point p (normal +z) is
//   AO(p) = 1 − (1/π) Σ_{box faces facing p} ∫_face (n·ω) dω,
// the faces seen from p not overlapping (a convex solid), each entirely above p's horizon (the
// side faces span z ∈ [0, 1], the floor is z = 0), so their cosine integrals have closed forms
// (Lambert's formula, written apart from the library in tests/common/unit_box_ao.h). Every floor texel outside the
// box's foot is checked, the row of texels next to its foot included (their samples 1/16 of a
// unit from the box's walls).
//
// Tolerances: QMC is held to 4 of its own standard errors, plus 1e-12 for rounding when every ray
// agrees. The silhouette integrator's error here is not the O(h²) of the vertex tests
// (tests/bake/integrators/test_silhouette.cpp, 1e-4 at N = 256): a texel 0.19 from the box's
// unit face sees the face's edges cross the isolines at a steep angle, and its error oscillates
// in sign with an amplitude falling like ~0.1/N (measured at texel (0.1875, −0.6875): 3.4e-3 at
// N = 96, 1.3e-3 at 256, 3.8e-4 at 512, 7.7e-5 at 1024, 2.6e-5 at 1536), so at N = 1536 the
// bound ~0.1/N = 6.5e-5 is within 1e-4 (the worst texel measured: 2.7e-5; at N = 1024 one texel
// was 1.02e-4, at 2048 the worst 5.3e-5).
#include <bake/bake/lightmap.h>
#include <bake/bake/pipeline.h>
#include <bake/mesh/mesh.h>
#include <bake/mesh/texels.h>
#include <bake/mesh/unwrap.h>
#include <bake/visibility/accel.h>
#include <bake/visibility/enclosure.h>
#include <bake/visibility/raycast.h>

#include <gtest/gtest.h>
#include <test_scenes.h>
#include <unit_box_ao.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cmath>
#include <map>
#include <numbers>
#include <vector>

using namespace prt::bake;
using Eigen::Vector2f;
using Eigen::Vector3d;
using Eigen::Vector3f;

namespace {

// The floor [−2, 2]² at z = 0, UVs ((x + 2)/4, (y + 2)/4), and the box [−½, ½]² × [0, 1] on it.
struct FloorAndBox {
  Mesh floor, box, both;
  UvSet uv;
  FloorAndBox() {
    floor = make_mesh({{-2, -2, 0}, {2, -2, 0}, {2, 2, 0}, {-2, 2, 0}}, {{{0, 1, 2}}, {{0, 2, 3}}}, "floor");
    uv.name = "uv";
    for (const auto& t : floor.triangles)
      for (uint32_t v : t) uv.corners.emplace_back((floor.positions[v].x() + 2) / 4, (floor.positions[v].y() + 2) / 4);
    std::vector<Vector3f> c;
    for (int k = 0; k < 8; ++k) c.emplace_back(k & 1 ? 0.5f : -0.5f, k & 2 ? 0.5f : -0.5f, k & 4 ? 1.0f : 0.0f);
    // Outward, counter-clockwise seen from outside.
    box = make_mesh(c,
                    {{{0, 2, 1}}, {{1, 2, 3}}, {{4, 5, 6}}, {{5, 7, 6}}, {{0, 1, 4}}, {{1, 5, 4}},
                     {{2, 6, 3}}, {{3, 6, 7}}, {{0, 4, 2}}, {{2, 4, 6}}, {{1, 3, 5}}, {{3, 7, 5}}},
                    "box");
    both = merge_meshes(std::vector<Mesh>{floor, box}, "floor and box");
  }
};

// The closed form of the file comment at a floor point p (tests/common/unit_box_ao.h: written
// apart from the library's spherical polygons).
double ao_closed_form(const Vector3d& p) { return prt::testing::ao_closed_form(prt::testing::Vector3d(p.x(), p.y(), p.z())); }

// AO of the atlas's texels through the pipeline, occluded by `mesh`, without a report.
VertexBake bake_ao(const Mesh& mesh, const Topology& topo, const MeshAccel& accel, const TexelAtlas& atlas,
                   const IntegratorSpec& spec) {
  PipelineSettings settings;
  settings.integrator = spec;
  settings.integrator.report_points = 0;
  std::vector<BakeJob> jobs(1);
  jobs[0].request.ao = true;
  jobs[0].sets.push_back(atlas.receivers);
  BakePipeline pipeline(mesh, topo, accel, settings, std::move(jobs));
  pipeline.run({});
  return pipeline.jobs()[0].rows[0];
}
VertexBake bake_ao(const FloorAndBox& s, const TexelAtlas& atlas, const IntegratorSpec& spec) {
  const Topology topo = build_topology(s.both);
  const MeshAccel accel(s.both, topo);
  return bake_ao(s.both, topo, accel, atlas, spec);
}

} // namespace

TEST(TexelBake, FloorTexelsAroundABoxMatchTheClosedFormWithSilhouetteAndQmc) {
  const FloorAndBox s;
  const TexelAtlas atlas = texel_atlas(s.floor, build_topology(s.floor), s.uv, 32, 32, "floor");
  ASSERT_EQ(atlas.samples.size(), 32u * 32u);
  // Texels whose sample is outside the box's foot (the 8 × 8 under it are inside the box).
  std::vector<size_t> outside;
  for (size_t i = 0; i < atlas.samples.size(); ++i) {
    const Vector3d& p = atlas.receivers.points[i].p;
    if (std::abs(p.x()) > 0.5 || std::abs(p.y()) > 0.5) outside.push_back(i);
  }
  ASSERT_EQ(outside.size(), 32u * 32u - 8u * 8u);

  IntegratorSpec sil;
  sil.kind = IntegratorKind::Silhouette;
  sil.silhouette_k = 1536 * 1536;
  const std::vector<double> a = bake_ao(s, atlas, sil).values;
  size_t next_to_foot = 0;
  for (size_t i : outside) {
    const Vector3d& p = atlas.receivers.points[i].p;
    const double exact = ao_closed_form(p);
    EXPECT_NEAR(a[i], exact, 1e-4) << "texel " << atlas.samples[i].texel << " at " << p.transpose();
    next_to_foot += std::max(std::abs(p.x()), std::abs(p.y())) < 0.5 + 1.0 / 8;
  }
  EXPECT_EQ(next_to_foot, 36u) << "the ring of texels next to the box's foot is checked";

  IntegratorSpec qmc;
  qmc.kind = IntegratorKind::Qmc;
  qmc.qmc_rays = 1024;
  const VertexBake q = bake_ao(s, atlas, qmc);
  for (size_t i : outside) {
    const double exact = ao_closed_form(atlas.receivers.points[i].p);
    EXPECT_NEAR(q.values[i], exact, 4 * q.std_error[i] + 1e-12) << "texel " << atlas.samples[i].texel;
  }
}

// The 8 × 8 floor texels under the box lie inside it: exactly they are enclosed (the rule of
// bake/visibility/enclosure.h), the ring next to its foot is not; the lightmap fills them from
// their valid neighbours, so the image has no dark texels where the box stands.
TEST(TexelBake, TexelsUnderTheBoxAreEnclosedAndFilledFromTheirNeighbours) {
  const FloorAndBox s;
  const TexelAtlas atlas = texel_atlas(s.floor, build_topology(s.floor), s.uv, 32, 32, "floor");
  const Topology topo = build_topology(s.both);
  const RayCaster rays(s.both, topo);
  std::vector<uint8_t> invalid(atlas.samples.size());
  size_t enclosed_count = 0;
  for (size_t i = 0; i < atlas.samples.size(); ++i) {
    const Vector3d& p = atlas.receivers.points[i].p;
    const bool under = std::abs(p.x()) < 0.5 && std::abs(p.y()) < 0.5;
    invalid[i] = enclosed(atlas.receivers.points[i], rays);
    EXPECT_EQ(bool(invalid[i]), under) << "texel " << atlas.samples[i].texel << " at " << p.transpose();
    enclosed_count += invalid[i];
  }
  EXPECT_EQ(enclosed_count, 64u);
  // A point under an open sheet is not enclosed: the floor alone with only the box's top face
  // above it (a canopy) leaves the texel below it valid.
  const Mesh canopy = merge_meshes(std::vector<Mesh>{s.floor, make_mesh({{-0.5f, -0.5f, 1}, {0.5f, -0.5f, 1}, {0.5f, 0.5f, 1},
                                                                         {-0.5f, 0.5f, 1}},
                                                                        {{{0, 1, 2}}, {{0, 2, 3}}}, "canopy")},
                                   "floor and canopy");
  const Topology canopy_topo = build_topology(canopy);
  const RayCaster canopy_rays(canopy, canopy_topo);
  for (size_t i = 0; i < atlas.samples.size(); ++i)
    EXPECT_FALSE(enclosed(atlas.receivers.points[i], canopy_rays)) << "texel " << atlas.samples[i].texel;

  IntegratorSpec sil;
  sil.kind = IntegratorKind::Silhouette;
  sil.silhouette_k = 64 * 64;
  const VertexBake ao = bake_ao(s, atlas, sil);
  const Lightmap m = make_lightmap(atlas, ao.values, 1, invalid, 0);
  EXPECT_EQ(m.filled, 64u);
  EXPECT_EQ(m.unfilled, 0u);
  double lowest_valid = 1;
  for (size_t i = 0; i < atlas.samples.size(); ++i)
    if (!invalid[i]) lowest_valid = std::min(lowest_valid, ao.values[i]);
  for (size_t i = 0; i < atlas.samples.size(); ++i) {
    const size_t k = atlas.samples[i].texel;
    EXPECT_EQ(m.state[k], uint8_t(invalid[i] ? TexelState::Filled : TexelState::Baked));
    // A mean of means of valid texels: never darker than the darkest valid one (the enclosed
    // rows themselves are 0: the box hides everything).
    EXPECT_GE(m.values[k], lowest_valid) << "texel " << k;
    if (invalid[i]) {
      EXPECT_LT(ao.values[i], 1e-12) << "an enclosed point sees nothing";
    }
  }
}

namespace {
// An icosahedron subdivided twice onto the unit sphere (320 triangles, counter-clockwise outward).
Mesh icosphere() {
  const double g = (1 + std::sqrt(5.0)) / 2;
  std::vector<Vector3d> v = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                             {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  for (Vector3d& p : v) p.normalize();
  std::vector<std::array<uint32_t, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                                            {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                                            {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int level = 0; level < 2; ++level) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
    auto middle = [&](uint32_t a, uint32_t b) {
      const auto key = std::minmax(a, b);
      if (const auto it = mid.find(key); it != mid.end()) return it->second;
      v.push_back((v[a] + v[b]).normalized());
      return mid[key] = uint32_t(v.size() - 1);
    };
    std::vector<std::array<uint32_t, 3>> next;
    for (const auto& [a, b, c] : f) {
      const uint32_t ab = middle(a, b), bc = middle(b, c), ca = middle(c, a);
      next.insert(next.end(), {{a, ab, ca}, {b, bc, ab}, {c, ca, bc}, {ab, bc, ca}});
    }
    f = std::move(next);
  }
  std::vector<Vector3f> vf;
  for (const Vector3d& p : v) vf.push_back(p.cast<float>());
  return make_mesh(vf, f, "icosphere");
}
} // namespace

TEST(TexelBake, TexelsOnACurvedSurfaceLieOnTheirTrianglesAndSeeWhatIsAboveTheirFace) {
  // A convex polyhedron: from a point inside face f, every other face lies behind f's plane, so
  // exactly the directions above that plane are visible and AO = (1/π) ∫_{H(n) ∩ H(n_f)} n·ω dω =
  // (1 + n·n_f)/2 for the sample's smooth normal n. A sample interpolated in double lies a rounding
  // off its triangle's plane; half of them lay below it, saw their own triangle from behind (a roof
  // over half the hemisphere) and were called enclosed: 1,012 of 2,189 at 64². Samples are put
  // exactly on their triangles (texels.h): none is enclosed, and QMC (its rays decide the own
  // triangle in the ε-limit) and the silhouette integrator (the contour search decides it exactly)
  // match the closed form at every centre sample inside its triangle.
  const Mesh mesh = icosphere();
  const Topology topo = build_topology(mesh);
  UnwrapOptions uo;
  uo.width = uo.height = 64;
  const Unwrapped unwrapped = unwrap(mesh, topo, uo);
  const TexelAtlas atlas = texel_atlas(mesh, topo, unwrapped.uv, 64, 64, "icosphere");
  ASSERT_GT(atlas.samples.size(), 1500u);
  EXPECT_EQ(atlas.inexact_samples, 0u);
  const MeshAccel accel(mesh, topo);
  size_t enclosed_count = 0;
  for (const ShadePoint& p : atlas.receivers.points) enclosed_count += enclosed(p, *accel.rays());
  EXPECT_EQ(enclosed_count, 0u);
  std::vector<double> want(atlas.samples.size(), -1);
  size_t checked = 0;
  for (size_t i = 0; i < atlas.samples.size(); ++i) {
    const TexelSample& s = atlas.samples[i];
    if (!s.centre || s.barycentric.minCoeff() <= 0) continue;
    const auto& t = mesh.triangles[s.triangle];
    const Vector3d a = mesh.positions[t[0]].cast<double>(), b = mesh.positions[t[1]].cast<double>(),
                   c = mesh.positions[t[2]].cast<double>();
    const Vector3d nf = (b - a).cross(c - a).normalized();
    want[i] = (1 + atlas.receivers.points[i].n.dot(nf)) / 2;
    ++checked;
  }
  ASSERT_GT(checked, 1000u);
  // QMC: 4 standard errors of the closed form's own Monte Carlo spread, sqrt(AO(1 − AO)/R) for R
  // cosine-distributed rays (its estimate is an indicator's mean; its reported standard error is
  // 0 when no ray met the sliver below the face, as 37% of R = 1,024 do for 1 − AO = 1e-3); the
  // silhouette integrator at N = 256 within 1e-3: the sliver is bounded by the own face's edges,
  // whose error oscillates at ~0.1/N (file comment), 4e-4 here (measured: worst 3.0e-4).
  auto check = [&](const IntegratorSpec& spec, double tol_abs, double tol_se, const char* what) {
    const VertexBake rows = bake_ao(mesh, topo, accel, atlas, spec);
    double worst = 0;
    for (size_t i = 0; i < want.size(); ++i)
      if (want[i] >= 0) {
        const double se = std::sqrt(want[i] * (1 - want[i]) / double(spec.qmc_rays));
        worst = std::max(worst, std::abs(rows.values[i] - want[i]));
        EXPECT_NEAR(rows.values[i], want[i], tol_abs + tol_se * se) << what << " sample " << i;
      }
    std::printf("%s: worst |error| %.2e\n", what, worst);
  };
  IntegratorSpec qmc;
  qmc.kind = IntegratorKind::Qmc;
  qmc.qmc_rays = 1024;
  check(qmc, 1e-12, 4.0, "qmc");
  IntegratorSpec sil;
  sil.kind = IntegratorKind::Silhouette;
  sil.set_samples(256 * 256);
  check(sil, 1e-3, 0.0, "silhouette");
}

namespace {
// AO at a floor point (normal +z) of a convex solid standing on the floor, exactly: 1 − Σ over
// the faces facing p of Lambert's polygon form factor (the faces seen from a point outside a
// convex solid do not overlap; every face is above the floor's plane).
double convex_solid_ao(const Vector3d& p, const std::vector<std::vector<Vector3d>>& faces) {
  double blocked = 0;
  for (const auto& f : faces) {
    const Vector3d n = (f[1] - f[0]).cross(f[2] - f[0]);
    if (n.dot(p - f[0]) > 0) blocked += prt::testing::polygon_form_factor(p, Vector3d::UnitZ(), f);
  }
  return 1 - blocked;
}
} // namespace

// Issue 30's exact case: a wall (a closed slab 0.2 × 2 × 1, counter-clockwise outward) standing
// on the floor with NO shared vertices: its foot's corners lie inside the floor's triangles
// (T-junctions in both directions). The floor's texels next to the wall match the closed form
// (no texel darker than it: the wall's foot does not leak its inside out), and the texels under
// the foot are exactly those enclosed (no light leak under it: they are filled from their chart's
// valid texels, never baked as lit). The slab's bottom face lies in the floor's plane (a coincident
// sheet) across the floor's diagonal. At 32² (spacing 1/8) two columns of 16 texel centres lie
// under the foot (x = ±1/16) and two beside its faces (x = ±3/16, 0.0875 from them). Silhouette at
// N = 1536 (the error bound of this file's comment, ~0.1/N = 6.5e-5, within 1e-4); QMC within 4
// standard errors.
TEST(TexelBake, AWallStandingOnTheFloorWithNoSharedVerticesMatchesTheClosedFormBesideItAndLeaksNothingUnderIt) {
  const FloorAndBox s;  // its floor and UVs only
  std::vector<Vector3f> c;
  for (int k = 0; k < 8; ++k) c.emplace_back(k & 1 ? 0.1f : -0.1f, k & 2 ? 1.0f : -1.0f, k & 4 ? 1.0f : 0.0f);
  const std::vector<std::array<uint32_t, 3>> box_faces = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                                                          {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  const Mesh wall = make_mesh(c, box_faces, "wall");
  const Mesh both = merge_meshes(std::vector<Mesh>{s.floor, wall}, "floor and wall");
  // The slab's six faces as quads, outward (the triangle pairs above, joined).
  const std::array<std::array<uint32_t, 4>, 6> quads = {{{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}}};
  std::vector<std::vector<Vector3d>> faces;
  for (const auto& q : quads) faces.push_back({c[q[0]].cast<double>(), c[q[1]].cast<double>(), c[q[2]].cast<double>(), c[q[3]].cast<double>()});
  const TexelAtlas atlas = texel_atlas(s.floor, build_topology(s.floor), s.uv, 32, 32, "floor");
  const Topology topo = build_topology(both);
  const MeshAccel accel(both, topo);
  const RayCaster rays(both, topo);
  size_t under = 0, beside = 0;
  std::vector<size_t> outside;
  for (size_t i = 0; i < atlas.samples.size(); ++i) {
    const Vector3d& p = atlas.receivers.points[i].p;
    const bool in_foot = std::abs(p.x()) < 0.1 && std::abs(p.y()) < 1;
    EXPECT_EQ(enclosed(atlas.receivers.points[i], rays), in_foot) << "texel " << atlas.samples[i].texel << " at " << p.transpose();
    under += in_foot;
    if (!in_foot) outside.push_back(i);
    beside += !in_foot && std::abs(p.x()) < 0.1875 + 1e-9 && std::abs(p.y()) < 1;
  }
  EXPECT_EQ(under, 32u);
  EXPECT_EQ(beside, 32u) << "the two columns of texels beside the wall's faces are checked";

  IntegratorSpec sil;
  sil.kind = IntegratorKind::Silhouette;
  sil.silhouette_k = 1536 * 1536;
  const std::vector<double> a = bake_ao(both, topo, accel, atlas, sil).values;
  // The lightmap: the enclosed texels filled from the valid ones, never brighter than the
  // brightest nor darker than the darkest valid texel of the chart (means of valid neighbours).
  std::vector<uint8_t> invalid(atlas.samples.size());
  double lowest = 1, highest = 0;
  for (size_t i = 0; i < atlas.samples.size(); ++i) invalid[i] = enclosed(atlas.receivers.points[i], rays);
  for (size_t i : outside) lowest = std::min(lowest, a[i]), highest = std::max(highest, a[i]);
  const Lightmap m = make_lightmap(atlas, a, 1, invalid, 0);
  EXPECT_EQ(m.filled, 32u);
  EXPECT_EQ(m.unfilled, 0u);
  for (size_t i = 0; i < atlas.samples.size(); ++i)
    if (invalid[i]) {
      EXPECT_LT(a[i], 1e-12) << "an enclosed point sees nothing";
      const size_t k = atlas.samples[i].texel;
      EXPECT_GE(m.values[k], lowest) << "texel " << k;
      EXPECT_LE(m.values[k], highest) << "texel " << k;
    }
  double worst = 0;
  for (size_t i : outside) {
    const Vector3d& p = atlas.receivers.points[i].p;
    const double exact = convex_solid_ao(p, faces);
    EXPECT_NEAR(a[i], exact, 1e-4) << "texel " << atlas.samples[i].texel << " at " << p.transpose();
    worst = std::max(worst, std::abs(a[i] - exact));
  }
  IntegratorSpec qmc;
  qmc.kind = IntegratorKind::Qmc;
  qmc.qmc_rays = 1024;
  const VertexBake q = bake_ao(both, topo, accel, atlas, qmc);
  for (size_t i : outside)
    EXPECT_NEAR(q.values[i], convex_solid_ao(atlas.receivers.points[i].p, faces), 4 * q.std_error[i] + 1e-12)
        << "texel " << atlas.samples[i].texel;
  std::printf("wall on floor: %zu texels, silhouette's worst |error| %.2e\n", outside.size(), worst);
}

// Issue 30's exact case: a double-sided panel made of two coincident sheets (the same four
// positions twice, wound opposite ways: no shared vertex index, welded together by position, so
// its four edges each carry four faces), 1/2 above a floor [−2, 2]², baked per texel in one atlas
// (the top sheet in u < 1/2, the bottom one in u > 1/2). Seen from p + εn each sheet's texels
// have the other sheet in their own plane, never in front: the top sheet sees the whole sky (AO
// = 1 exactly), the bottom sheet sees the floor below, AO = 1 − Lambert's form factor of the
// floor's square from p with n = −z (nothing else is in view). Silhouette at N = 1536 within
// 1e-4 (this file's bound); QMC within 4 standard errors.
TEST(TexelBake, ADoubleSidedPanelOfTwoCoincidentSheetsSeesTheSkyAboveAndTheFloorBelow) {
  const FloorAndBox s;  // its floor only
  const std::vector<Vector3f> q = {{-1, -1, 0.5f}, {1, -1, 0.5f}, {1, 1, 0.5f}, {-1, 1, 0.5f}};
  std::vector<Vector3f> pos = q;
  pos.insert(pos.end(), q.begin(), q.end());
  const Mesh panel = make_mesh(pos, {{{0, 1, 2}}, {{0, 2, 3}}, {{4, 6, 5}}, {{4, 7, 6}}}, "panel");
  ASSERT_GT(panel.normals[0].z(), 0.99f);
  ASSERT_LT(panel.normals[4].z(), -0.99f);
  UvSet uv;
  uv.name = "uv";
  for (size_t t = 0; t < panel.triangles.size(); ++t)
    for (uint32_t v : panel.triangles[t]) {
      const Vector3f& p = panel.positions[v];
      uv.corners.emplace_back((t < 2 ? 0.0f : 0.5f) + (p.x() + 1) / 4, (p.y() + 1) / 2);
    }
  const Mesh both = merge_meshes(std::vector<Mesh>{panel, s.floor}, "panel over floor");
  const TexelAtlas atlas = texel_atlas(panel, build_topology(panel), uv, 64, 32, "panel");
  ASSERT_EQ(atlas.samples.size(), 64u * 32u);
  const Topology topo = build_topology(both);
  const MeshAccel accel(both, topo);
  const std::vector<Vector3d> floor = {{-2, -2, 0}, {2, -2, 0}, {2, 2, 0}, {-2, 2, 0}};
  const auto exact = [&](const ShadePoint& sp) {
    return sp.n.z() > 0 ? 1.0 : 1 - prt::testing::polygon_form_factor(sp.p, -Vector3d::UnitZ(), floor);
  };
  IntegratorSpec sil;
  sil.kind = IntegratorKind::Silhouette;
  sil.silhouette_k = 1536 * 1536;
  const std::vector<double> a = bake_ao(both, topo, accel, atlas, sil).values;
  size_t top = 0, bottom = 0;
  for (size_t i = 0; i < atlas.samples.size(); ++i) {
    const ShadePoint& sp = atlas.receivers.points[i];
    ASSERT_NEAR(std::abs(sp.n.z()), 1.0, 1e-6) << "texel " << atlas.samples[i].texel;
    EXPECT_NEAR(a[i], exact(sp), 1e-4) << "texel " << atlas.samples[i].texel << " at " << sp.p.transpose() << " n "
                                       << sp.n.transpose();
    (sp.n.z() > 0 ? top : bottom) += 1;
  }
  EXPECT_EQ(top, 1024u);
  EXPECT_EQ(bottom, 1024u);
  IntegratorSpec qmc;
  qmc.kind = IntegratorKind::Qmc;
  qmc.qmc_rays = 1024;
  const VertexBake r = bake_ao(both, topo, accel, atlas, qmc);
  for (size_t i = 0; i < atlas.samples.size(); ++i)
    EXPECT_NEAR(r.values[i], exact(atlas.receivers.points[i]), 4 * r.std_error[i] + 1e-12) << "texel " << atlas.samples[i].texel;
}
