// The generated architectural scene (tests/common/arch_scene.h) has the defects it claims, decided
// with exact predicates (tests/common/point_on_triangle.h, orient3d_exact): T-junctions (vertices
// inside another part's face or on the interior of its edge), one vertex on two other parts at
// once, a rug coplanar with the floor, duplicated faces, and a double-sided panel of two coincident
// sheets with opposite winding and separate vertices. The messy-geometry tests and the real-asset
// benchmark rely on these facts.
#include <bake/mesh/mesh.h>

#include <arch_scene.h>
#include <point_on_triangle.h>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <string>
#include <vector>

using namespace prt::testing;
using Eigen::AlignedBox3f;
using Eigen::Vector3f;

namespace {

constexpr int kCellsPerMetre = 2;

// How vertex v meets part P's triangles: the strongest of AtCorner (a vertex of P has its position)
// > OnEdge > Inside (a T-junction) > nothing (OffPlane / Outside).
enum class Contact { None, Inside, OnEdge, AtCorner };

struct Contacts {
  // contact[v][p]: how vertex v meets part p (None for its own part).
  std::vector<std::vector<Contact>> contact;
};

Contact strongest(Contact a, OnTriangle where) {
  const Contact b = where == OnTriangle::AtCorner ? Contact::AtCorner
                    : where == OnTriangle::OnEdge ? Contact::OnEdge
                    : where == OnTriangle::Inside ? Contact::Inside
                                                  : Contact::None;
  return std::max(a, b);
}

Contacts contacts(const ArchScene& s) {
  const auto& m = s.mesh;
  std::vector<size_t> tri_part(m.triangles.size());
  std::vector<AlignedBox3f> bounds(m.triangles.size());
  for (size_t t = 0; t < m.triangles.size(); ++t) {
    tri_part[t] = s.part_of_vertex(m.triangles[t][0]);
    for (uint32_t c : m.triangles[t]) bounds[t].extend(m.positions[c]);
  }
  Contacts out;
  out.contact.assign(m.positions.size(), std::vector<Contact>(s.parts.size(), Contact::None));
  for (uint32_t v = 0; v < m.positions.size(); ++v) {
    const size_t own = s.part_of_vertex(v);
    const Vector3f& q = m.positions[v];
    for (size_t t = 0; t < m.triangles.size(); ++t) {
      if (tri_part[t] == own || !bounds[t].contains(q)) continue;
      const auto& tri = m.triangles[t];
      Contact& c = out.contact[v][tri_part[t]];
      c = strongest(c, locate_on_triangle(m.positions[tri[0]], m.positions[tri[1]], m.positions[tri[2]], q));
    }
  }
  return out;
}

bool is_wall(const ArchPart& p) { return p.name.rfind("wall", 0) == 0 || p.name == "lintel"; }

class ArchSceneFacts : public ::testing::Test {
protected:
  static void SetUpTestSuite() {
    scene_ = new ArchScene(architectural_scene(kCellsPerMetre));
    contacts_ = new Contacts(contacts(*scene_));
  }
  static void TearDownTestSuite() {
    delete scene_;
    delete contacts_;
  }
  static const ArchScene* scene_;
  static const Contacts* contacts_;
};
const ArchScene* ArchSceneFacts::scene_ = nullptr;
const Contacts* ArchSceneFacts::contacts_ = nullptr;

} // namespace

TEST(ArchScene, DeterministicAndSizedByTheParameter) {
  const ArchScene a = architectural_scene(2), b = architectural_scene(2), c = architectural_scene(4);
  EXPECT_EQ(a.mesh.positions, b.mesh.positions);
  EXPECT_EQ(a.mesh.triangles, b.mesh.triangles);
  // Wall surfaces dominate: ~4× the triangles for 2× the cells per metre.
  EXPECT_GT(a.mesh.triangles.size(), 2000u);
  EXPECT_LT(a.mesh.triangles.size(), 5000u);
  EXPECT_GT(double(c.mesh.triangles.size()) / double(a.mesh.triangles.size()), 3.0);
  // Parts tile the vertex and triangle ranges in order.
  uint32_t v = 0, t = 0;
  for (const auto& p : a.parts) {
    EXPECT_EQ(p.first_vertex, v) << p.name;
    EXPECT_EQ(p.first_triangle, t) << p.name;
    v += p.vertex_count;
    t += p.triangle_count;
  }
  EXPECT_EQ(v, a.mesh.positions.size());
  EXPECT_EQ(t, a.mesh.triangles.size());
  EXPECT_THROW(architectural_scene(0), std::invalid_argument);
}

TEST(PointOnTriangle, ClassifiesExactly) {
  const Vector3f a(0, 0, 0), b(1, 0, 0), c(0, 0, 1);
  EXPECT_EQ(locate_on_triangle(a, b, c, Vector3f(0.25f, 0, 0.25f)), OnTriangle::Inside);
  EXPECT_EQ(locate_on_triangle(a, b, c, Vector3f(0.5f, 0, 0.5f)), OnTriangle::OnEdge);
  EXPECT_EQ(locate_on_triangle(a, b, c, Vector3f(0.5f, 0, 0)), OnTriangle::OnEdge);
  EXPECT_EQ(locate_on_triangle(a, b, c, Vector3f(1, 0, 0)), OnTriangle::AtCorner);
  EXPECT_EQ(locate_on_triangle(a, b, c, Vector3f(0.75f, 0, 0.75f)), OnTriangle::Outside);
  EXPECT_EQ(locate_on_triangle(a, b, c, Vector3f(0.25f, std::nextafter(0.0f, 1.0f), 0.25f)), OnTriangle::OffPlane);
  EXPECT_EQ(locate_on_triangle(a, b, Vector3f(2, 0, 0), Vector3f(0.5f, 0, 0)), OnTriangle::Degenerate);
}

TEST_F(ArchSceneFacts, WallFeetStandOnTheFloorMostlyAsTJunctions) {
  const ArchScene& s = *scene_;
  const size_t floor = size_t(&s.part("floor") - s.parts.data());
  size_t feet = 0, inside = 0, on_edge = 0, at_corner = 0;
  for (const auto& p : s.parts) {
    if (!is_wall(p) || p.name == "lintel") continue;
    for (uint32_t v = p.first_vertex; v < p.first_vertex + p.vertex_count; ++v) {
      if (s.mesh.positions[v].y() != 0.0f) continue;
      ++feet;
      const Contact c = contacts_->contact[v][floor];
      inside += c == Contact::Inside;
      on_edge += c == Contact::OnEdge;
      at_corner += c == Contact::AtCorner;
      EXPECT_NE(c, Contact::None) << p.name << " vertex " << v << " is not on the floor";
    }
  }
  // A foot meets a floor vertex only where both are on the lattice x, z ∈ {0, 4, 8}: the long
  // walls' feet at x = 0, 4, 8 on z = 0 and z = 8 (6 vertices, for every cells_per_metre).
  EXPECT_EQ(at_corner, 6u);
  EXPECT_GT(inside, 100u);
  EXPECT_GT(on_edge, 0u);
  EXPECT_EQ(inside + on_edge + at_corner, feet);
}

TEST_F(ArchSceneFacts, JunctionCornerLiesOnTheFloorFaceAndOnAWallEdge) {
  const ArchScene& s = *scene_;
  const uint32_t v = s.junction_corner;
  EXPECT_TRUE(s.part("cabinet").has_vertex(v));
  const auto& c = contacts_->contact[v];
  const size_t floor = size_t(&s.part("floor") - s.parts.data());
  const size_t wall = size_t(&s.part("wall_south") - s.parts.data());
  EXPECT_EQ(c[floor], Contact::Inside);
  EXPECT_EQ(c[wall], Contact::OnEdge);
  for (size_t p = 0; p < s.parts.size(); ++p)
    if (p != floor && p != wall) {
      EXPECT_EQ(c[p], Contact::None) << s.parts[p].name;
    }
}

TEST_F(ArchSceneFacts, TJunctionCounts) {
  // Vertices that are a T-junction (inside a face or on an edge's interior) of at least one other
  // part, and of two other parts at once. Golden numbers of this deterministic scene at 2 cells/m:
  // a change to the generator must change them deliberately (lower bounds would let the defects
  // vanish unnoticed).
  const ArchScene& s = *scene_;
  size_t tj = 0, tj2 = 0, coincident = 0;
  std::string by_part;
  for (uint32_t v = 0; v < s.mesh.positions.size(); ++v) {
    if (s.part_of_vertex(v) != s.part_of_vertex(v == 0 ? 0 : v - 1) || v == 0)
      by_part += (v ? ", " : "") + s.parts[s.part_of_vertex(v)].name + ":";
    size_t parts = 0;
    bool corner = false;
    for (Contact c : contacts_->contact[v]) {
      parts += c == Contact::Inside || c == Contact::OnEdge;
      corner |= c == Contact::AtCorner;
    }
    tj += parts >= 1;
    tj2 += parts >= 2;
    coincident += corner;
    if (parts >= 1) by_part += " " + std::to_string(v);
  }
  SCOPED_TRACE("T-junction vertices by part: " + by_part);
  EXPECT_EQ(tj, 342u);
  EXPECT_EQ(tj2, 30u);
  EXPECT_EQ(coincident, 126u);
}

TEST_F(ArchSceneFacts, RugIsCoplanarWithTheFloorAndOverlapsIt) {
  const ArchScene& s = *scene_;
  const ArchPart& rug = s.part("rug");
  const size_t floor = size_t(&s.part("floor") - s.parts.data());
  for (uint32_t v = rug.first_vertex; v < rug.first_vertex + rug.vertex_count; ++v) {
    const Contact c = contacts_->contact[v][floor];
    EXPECT_TRUE(c == Contact::Inside || c == Contact::OnEdge) << "rug vertex " << v;
  }
  // Facing +Y like the floor's top face: coplanar and overlapping, not a back-to-back contact.
  const auto& m = s.mesh;
  for (uint32_t t = rug.first_triangle; t < rug.first_triangle + rug.triangle_count; ++t) {
    const auto& tri = m.triangles[t];
    const Vector3f n = (m.positions[tri[1]] - m.positions[tri[0]]).cross(m.positions[tri[2]] - m.positions[tri[0]]);
    EXPECT_GT(n.y(), 0.0f);
  }
}

TEST_F(ArchSceneFacts, DuplicatedFacesRepeatTheTableTop) {
  const ArchScene& s = *scene_;
  const ArchPart& table = s.part("table");
  const ArchPart& copy = s.part("table_top_copy");
  ASSERT_EQ(s.duplicated_faces.size(), copy.triangle_count);
  EXPECT_EQ(copy.vertex_count, 0u);
  // 1.2 m × 0.8 m top at 2 cells/m: 2 × 2 cells (lattice rounds 2.4 and 1.6 to 2), 2 triangles each.
  EXPECT_EQ(copy.triangle_count, 8u);
  for (const auto& [t, dup] : s.duplicated_faces) {
    EXPECT_TRUE(table.has_triangle(t));
    EXPECT_TRUE(copy.has_triangle(dup));
    EXPECT_EQ(s.mesh.triangles[t], s.mesh.triangles[dup]);
  }
}

TEST_F(ArchSceneFacts, PanelIsTwoCoincidentSheetsWithOppositeWindingAndSeparateVertices) {
  const ArchScene& s = *scene_;
  const ArchPart& front = s.part("panel_front");
  const ArchPart& back = s.part("panel_back");
  const auto& m = s.mesh;
  ASSERT_EQ(front.vertex_count, back.vertex_count);
  ASSERT_EQ(front.triangle_count, back.triangle_count);
  EXPECT_GT(front.triangle_count, 0u);
  for (uint32_t k = 0; k < front.vertex_count; ++k)
    EXPECT_EQ(m.positions[front.first_vertex + k], m.positions[back.first_vertex + k]);
  for (uint32_t k = 0; k < front.triangle_count; ++k) {
    const auto& f = m.triangles[front.first_triangle + k];
    const auto& b = m.triangles[back.first_triangle + k];
    for (int c = 0; c < 3; ++c) {
      EXPECT_TRUE(front.has_vertex(f[size_t(c)]));
      EXPECT_TRUE(back.has_vertex(b[size_t(c)]));
    }
    // The same corners in reverse order: exactly opposite face normals.
    auto pos = [&](uint32_t v) { return m.positions[v]; };
    EXPECT_EQ(pos(f[0]), pos(b[0]));
    EXPECT_EQ(pos(f[1]), pos(b[2]));
    EXPECT_EQ(pos(f[2]), pos(b[1]));
    const Vector3f nf = (pos(f[1]) - pos(f[0])).cross(pos(f[2]) - pos(f[0]));
    EXPECT_LT(nf.z(), 0.0f);  // front faces −Z
  }
  // Every panel vertex shares its position with exactly one vertex of the other sheet.
  const size_t back_index = size_t(&back - s.parts.data());
  for (uint32_t v = front.first_vertex; v < front.first_vertex + front.vertex_count; ++v)
    EXPECT_EQ(contacts_->contact[v][back_index], Contact::AtCorner);
}
