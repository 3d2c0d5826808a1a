// bake/visibility/occluder_mesh.h — the visible part of a planar area light past an arbitrary triangle mesh
// (non-convex, open, non-manifold: any triangle soup), seen from a shade point in the ε-limit
// p + εn, as the boundary arcs of bake/visibility/visible_region.h (paper 003 §3.5 "GetBetween" culling,
// §3.1 silhouette edges and §4.4 the per-triangle variant; issues 13 and 32;
// docs/ARCHITECTURE.md "Conventions").
//
// Method: the light polygon (world coordinates, planar, convex, either winding) is seen from p,
// oriented positively and clipped to the horizon n·ω ≥ 0 (bake/sphere/spherical_polygon.h). Only the
// triangles that can hide part of it are kept (culling, conservative):
//  * a binary AABB tree over the triangles (median splits, leaves of ≤ 4) is walked against the
//    planes of the pyramid spanned by p and the clipped light (m_i = l_i × l_{i+1}, inside
//    m_i·(x − p) ≥ 0) and the light's own plane (p's side): a box or a triangle entirely outside
//    one plane by more than a rounding margin (1e-12 relative: far above the error of the
//    floating-point plane values) is dropped. Nothing dropped overlaps the light's interior.
//    A light of more than 8 sides (a disc or a sun as a many-sided polygon, whose every side
//    plane would be tested at each node along its thin pyramid) is culled instead by the light's
//    plane and the 8 planes through p tangent to a circular cone around it: axis a the
//    normalised sum of the clipped corner directions, cos θ the least cosine of a corner
//    direction to a, less 1e-9 (used while θ < 84°, so the cone's cap is geodesically convex
//    and holds the light's edges too); tangent plane j has the inward normal
//    sin θ a − cos θ e_j (e_j ⊥ a at angles 2πj/8), and every ω at angle φ ≤ θ from a has
//    n_j·ω ≥ sin(θ − φ) ≥ 0. This pyramid holds the light's, so what it drops is outside the
//    light's pyramid too (the one-facing rule's "a culled face has the edge outside it"); it
//    keeps a few more triangles (a regular octagon around a disc: 5.5% more area) for 9 planes
//    in place of n + 1 (bench/RESULTS.md "area lights: many-sided lights").
//  * the light's plane decides depth EXACTLY (orient3d_exact on three light vertices): a triangle
//    with no vertex strictly on p's side is behind the light and dropped; one straddling the
//    plane is clipped to p's side (crossing points in floating point). Since the light is planar
//    and convex, a ray from p towards the light is blocked iff it meets a triangle on p's side.
// Each kept triangle becomes its spherical image from p + εn (ε → 0+), a convex spherical polygon:
//  * p strictly off its plane: its vertices' directions x − p, positively oriented by the exact
//    sign of det(a − p, b − p, c − p);
//  * p in its plane but outside it (orient3d_exact = 0): an image of zero area in the limit; dropped;
//  * p on it (a vertex, e.g. the shade point's own 1-ring, a point of an edge or of the face, all
//    decided exactly): split into triangles (p, v_i, v_{i+1}) and each seen from p + εn is the
//    spherical triangle (v_i − p, v_{i+1} − p, −n) (a ray p + εn + t d meets it iff
//    d ∈ cone(v_i − p, v_{i+1} − p, −n), as bake/visibility/raycast.h occludes_from_above); when n lies in the
//    face's plane that cone has no interior and is dropped (ShadePoint::t is not used: such a face
//    blocks nothing, as with t = 0).
// Then V = light \ ∪ images exactly (every orientation decided by orient3d_exact, after a
// floating-point filter whose bound is far above its error; unions counted once), by one of three
// methods that give the same arcs up to cuts of rounding size. Triangles are passed in index
// order whatever the tree's walk, so all of them and the unculled reference make the same
// decisions on ties.
//  * The cone path (visible_light_cone; issue 32): the images are not all built. The boundary of
//    the union of images inside the light lies on the image edges of the welded mesh edges that
//    may bound it seen from p (paper 003 §3.1 silhouette edges; paper 001 §3.1 contour edges
//    seen from p): an edge of two whole faces (every corner strictly on p's side of the light's
//    plane) with distinct welded corners that run it both ways bounds nothing when p is strictly
//    on the same side of both faces' planes (their images lie on opposite sides of the edge).
//    Every other welded edge not outside the pyramid may: contour edges (the faces facing
//    apart), boundary and non-manifold edges, edges wound the same way by both faces, edges of
//    degenerate faces, and edges of a face that is dropped or special. A special face is one in
//    the pyramid clipped by the light's plane or with p in its plane (the shade point's own
//    1-ring, an occluder edge through p, a face seen edge-on): its images' edges are all cut.
//    These edges and special faces are found by an edge tree (a binary tree over the welded
//    edges; per node the box of its edges' faces, the box's bounding sphere (centre c, radius r)
//    and a cone of its faces' unit normals (axis a, |n̂ − a| ≤ s)) walked against the pyramid:
//    a node is passed over when its box is outside a culling plane, or when it holds only such
//    consistently wound pairs, its box lies strictly on p's side of the light's plane and
//    |a·(p − c)| > s|p − c| + r + 1e-9(|p − c| + r) (then n̂·(p − x) has one strict sign for every
//    face point x and normal n̂ of the node, far beyond the rounding of n̂); the leaves decide each
//    edge exactly (orient3d_exact, the light frame's exact depth, the culling planes' margins).
//    cone_edges_brute_force applies the leaves' rule to every edge: the same sets.
//    Coverage needs only the images that meet a cut edge: for each light edge, each found edge
//    and each special image's edge, its fan (the rays from p through it, up to the light's plane:
//    the plane through p and the edge, both sides with a margin far above the rounding of its
//    normal, the wedge between the two rays, the light's plane) is walked in the triangle tree,
//    64 fans at a time, each node carrying its live fans, nodes and triangles outside the
//    pyramid skipped. The triangles met, and the special faces, become images (in index order);
//    an image edge is cut iff its welded edge was found, except that of a consistently wound pair
//    whose other face, listed first, has a whole image (a fold's second edge, or an edge whose far
//    side that face covers: the rule below), and every edge of a special image; then
//    visible_region_sparse. Each cut edge meets exactly the images it met among all kept images
//    (every image meeting it lies on its fan), and an edge not cut emits nothing either way, so
//    the arcs are the kept-images path's.
//  * The contour path over every kept image (visible_light_kept_images, the fast path before the
//    cone path): the boundary of the union of images lies only on
//    image edges whose far side (right of the edge, away from its own image) is not covered along
//    the edge by the image of another face on the same mesh edge (paper 003 §3.1: silhouette
//    edges; §4.4 and [OZ06]: about √e of them). The mesh's edge → faces map is built once
//    (vertices welded by bitwise-equal position, since equal positions give equal images). An
//    edge of a whole-triangle image (kept, not clipped, p off its plane) is left out when another
//    such face on that mesh edge has its opposite vertex strictly on the other side of the plane
//    through p and the edge (known from both faces' orientations: no new predicate), since that
//    image covers the far side along the whole edge; or when such a face lies on the same side
//    and is listed first (a fold seen twice: its edge is the same arc and owns it). What remains
//    is cut by bake/visibility/visible_region.h visible_region_sparse, each edge only against the
//    images near it: contour edges (faces of different facing), boundary and non-manifold edges,
//    T-junctions and coincident sheets (no shared vertex index after welding), edges next to a
//    culled, dropped, clipped or ε-limit face, and every edge of a clipped image or of an
//    ε-limit cone (the shade point's own 1-ring, as every vertex receiver has). The only
//    degraded case is a light of ≥ 84° radius seen from p, where the chart is not used and each
//    edge meets every image whose cap meets its own (Workspace::stats counts it, and the queries
//    with clipped or ε-limit images). Kept triangles are put in index order by a bitmap; an
//    edge of a consistently wound pair finds its other face through a twin slot.
//    One facing (issue 32, ground points): when the mesh is closed and oriented (every welded
//    edge a consistently wound pair: `closed_`) and every kept triangle is whole (no corner in
//    the light's plane, none straddling it, p strictly off every plane: no clipped or ε-limit
//    image), let σ_t = ±1 be triangle t's orientation seen from p. Then for directions ω in the
//    light's cone, c(ω) = Σ σ_t over the images containing ω is the same integer k everywhere
//    off the image edges: crossing a mesh edge's image either swaps one face's image for the
//    other's (same σ, opposite sides) or enters or leaves both (a fold: opposite σ, same side);
//    every mesh edge whose image meets the cone has both faces kept and whole (a face culled by
//    a side plane has the edge outside it; one behind the light shares no corner with a face in
//    front of it). (c(ω) is the winding number of the surface about p minus that about the
//    light point on the ray: the surface does not meet the light.) So with A = {σ = +1},
//    B = {σ = −1}: #A(ω) − #B(ω) = k; if k > 0 every ω is in some A image and if k < 0 in some
//    B image: the light is hidden (no arc); if k = 0 a ray meets an A image iff it meets a B
//    image, and the union of either facing's images is the union of all (up to the image
//    edges, of measure zero): only the facing with fewer images is subtracted, its contour
//    edges cut as edges whose other face is not passed. k is counted at one direction d (a
//    positive sum of the light's corner directions, strictly inside every light edge, exactly)
//    that lies on no image edge (exact signs; d on the great circle of an edge of an image it
//    is not strictly outside of, and the rule is not used), as each image is built, and only
//    when every image as computed (rounded corner directions) has its triangle's orientation
//    (exact sign; else not used), so the argument holds for the images that
//    visible_region_sparse gets. On the bunny's ground points it halves the images, and so the
//    candidates of every cut (Workspace::stats::one_facing;
//    tests/bake/visibility/test_occluder_contour.cpp
//    ClosedMeshesFromOneFacing holds it to the per-triangle method from inside and outside
//    closed meshes, overlapping and inverted ones, a cavity, a box around and through the
//    light, and a direction d on an image edge).
//  * The per-triangle method (visible_light_per_triangle; visible_light_reference without the
//    culling): visible_region over every image's edges, O(E²) in the kept edges E; the slow
//    reference the tests hold both paths to (1e-9 of the light's solid angle, E and SH).
// visible_light takes the kept-images path. The cone path is faster where the pyramid holds many
// more triangles than the edges it finds (the bunny Loop-subdivided 3–4 times: 1.5–2.1x) and
// slower on small pyramids and on the CAD engine (long thin triangles: its fans meet nearly every
// kept triangle, and it cuts more edges): a choice per query by the triangles culling keeps
// (≤ 5,000: kept images) was measured and lost on the engine, so there is no choice yet. With the
// one-facing rule the kept-images path is 1.5–2.8x faster than the cone path on the bunny's
// ground points at Loop levels 0–3 and about even at level 4 (bench/RESULTS.md "area lights:
// ground points").
// Cost: the kept-images path is linear in the triangles inside the light's pyramid (culling,
// images, the chart's grid), plus per edge cut the images near it. The cone path's follows the
// found edges: the edge tree's walk, per found edge a fan walk and the images on it
// (bench/bench_area.cpp BM_BunnyQuad, bench/RESULTS.md "area lights: the cone path").
#pragma once

#include <bake/mesh/mesh.h>
#include <bake/mesh/shade_point.h>
#include <bake/sphere/spherical_polygon.h>
#include <bake/visibility/visible_region.h>

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <utility>
#include <vector>

namespace prt::bake {

class OccluderMesh {
public:
  // The mesh's world positions (Mesh::world_position, in double) and triangles are copied: the
  // mesh need not outlive this object. Zero-area triangles are kept (their images are dropped).
  explicit OccluderMesh(const Mesh& mesh);
  OccluderMesh(std::vector<Eigen::Vector3d> positions, std::vector<std::array<uint32_t, 3>> triangles);

  // Per-thread scratch buffers, reused across queries (the per-triangle visible_region still
  // allocates its own).
  // After a query, `clipped` holds the light as visible_region got it (directions from p,
  // positively oriented, clipped to the horizon; empty when the query returned no light): its
  // integrals are the unshadowed values.
  struct Workspace {
    struct Plane {  // kept side: m·(x − o) ≥ −margin
      Eigen::Vector3d m, o;
      double margin_coef;  // margin = margin_coef · (|x − o| bound)
    };
    std::vector<Plane> planes;
    // A light of more than 8 sides (a disc, a sun) is culled by the planes of an octagonal
    // pyramid around it instead of its own sides (file comment, culling); empty otherwise.
    std::vector<Plane> cull_planes;
    std::vector<double> margins;  // per plane, of the leaf being culled
    std::vector<Eigen::Vector3d> rel, clipped, poly;
    std::vector<std::vector<Eigen::Vector3d>> images;
    std::vector<uint32_t> kept, stack;
    std::vector<std::pair<uint32_t, uint32_t>> walk_stack;  // node, culling planes still to test (bits)
    std::vector<uint64_t> kept_bits;  // sort_kept's bitmap over the triangles
    size_t image_count = 0;
    // The contour path's scratch: per image its triangle, kind and boundary-edge mask; per
    // triangle the query that last kept it and its image's orientation (0: not a whole triangle).
    std::vector<uint32_t> image_triangle, tri_stamp;
    std::vector<uint8_t> image_kind, boundary;
    std::vector<int8_t> tri_side;
    uint32_t stamp = 0;
    int last_side = 0;
    bool settled = false;  // every image so far whole, no corner in the light's plane, p off every plane
    RegionScratch region;
    // Counters of the contour path, summed over this workspace's queries (never reset here).
    struct Stats {
      size_t queries = 0;         // queries that reached the union (light not empty)
      size_t kept = 0;            // triangles kept by culling
      size_t boundary_edges = 0;  // image edges cut (may bound the union and reach into the light)
      size_t special = 0;         // queries with a clipped or ε-limit image (all its edges cut)
      size_t uncharted = 0;       // queries whose light was too wide for the chart (caps only)
      size_t one_facing = 0;      // queries answered from one facing's images (closed mesh)
      size_t hidden = 0;          // … of which the light was found hidden entirely
      size_t octagon = 0;         // queries culled by the octagonal pyramid (a light of > 8 sides)
      // The cone path: queries it answered (the rest took the kept-images path), the welded
      // edges it found in the cone and the triangles whose images it passed on (those met by a
      // fan, and the special faces), summed over the queries it answered; edge-tree nodes
      // visited and fan tests (a fan against a tree node), over every walk.
      size_t cone = 0, cone_edges = 0, cone_candidates = 0, edge_nodes = 0, fan_tests = 0;
    } stats;
    // The cone path's scratch: per welded edge the query that found it in the cone; the found
    // edges and special faces; the fans' planes (five per fan).
    std::vector<uint32_t> group_stamp, cone, special_faces, edge_stack;
    std::vector<Plane> fan;
    std::vector<std::pair<uint32_t, uint64_t>> fan_stack;  // node, live fans
    uint32_t group_mark = 0;
  };

  // out = the boundary arcs (bake/sphere/spherical_polygon.h Arc, directions from p) of the part of the
  // light visible from point.p + ε point.n above its horizon (point.hemisphere = false: no horizon
  // clip). `light`: ≥ 3 world-space vertices of a planar convex polygon, either winding (a
  // one-sided light's back side is the caller's decision). Empty when p lies in the light's plane
  // or nothing of it is above the horizon. Integrate with point.n·vector_irradiance(out) (the
  // irradiance from unit radiance) and PolygonSH::project(out) (bake/sphere/polygon_sh.h).
  // Every method below returns the number of triangles whose images were built (kept by
  // culling, or met by a fan on the cone path).
  // Thread-safe (const) with one Workspace per thread. A convex emitter (box, cylinder, sphere as
  // a polyhedron) is the sum of its faces facing p, each a planar light here; the emitter's own
  // triangles may stay in the mesh (each lies in or behind the plane of a front face, and is
  // dropped by the depth test).
  // By the contour path over every kept image (file comment: the cone path is not the default;
  // bench/RESULTS.md "area lights: the cone path" says where each is faster).
  size_t visible_light(std::span<const Eigen::Vector3d> light, const ShadePoint& point, std::vector<Arc>& out,
                       Workspace& ws) const {
    return query(light, point, out, ws, Method::contour);
  }
  // The cone path (file comment): the same arcs' integrals.
  size_t visible_light_cone(std::span<const Eigen::Vector3d> light, const ShadePoint& point, std::vector<Arc>& out,
                            Workspace& ws) const {
    return query(light, point, out, ws, Method::cone);
  }
  // The same as visible_light, by name (the tests and bench_area hold the paths side by side).
  size_t visible_light_kept_images(std::span<const Eigen::Vector3d> light, const ShadePoint& point,
                                   std::vector<Arc>& out, Workspace& ws) const {
    return query(light, point, out, ws, Method::contour);
  }
  // The cone path's first step alone: the welded mesh edges (numbered 0 .. edge_count() − 1)
  // that may bound the occluders' union inside the light's pyramid, and the special triangles
  // there (clipped by the light's plane, or with p in their plane: every image edge cut), both
  // ascending (file comment "cone path"), by the edge tree.
  void cone_edges(std::span<const Eigen::Vector3d> light, const ShadePoint& point, std::vector<uint32_t>& edges,
                  std::vector<uint32_t>& special, Workspace& ws) const;
  // Reference of cone_edges: the same rule over every welded edge, without the tree. Equal sets.
  void cone_edges_brute_force(std::span<const Eigen::Vector3d> light, const ShadePoint& point,
                              std::vector<uint32_t>& edges, std::vector<uint32_t>& special, Workspace& ws) const;
  size_t edge_count() const { return edge_group_start_.empty() ? 0 : edge_group_start_.size() - 1; }
  // The per-triangle method (paper 003 §4.4; the fast path before issue 32): the same culling
  // and images, then visible_region over every kept image's edges, O(E²). The slow reference of
  // the contour path: the same arcs' integrals.
  size_t visible_light_per_triangle(std::span<const Eigen::Vector3d> light, const ShadePoint& point,
                                    std::vector<Arc>& out, Workspace& ws) const {
    return query(light, point, out, ws, Method::per_triangle);
  }
  // Reference: no tree and no pyramid culling (every triangle goes through the exact depth test
  // and the image rule above), then the per-triangle method. The same arcs' integrals.
  size_t visible_light_reference(std::span<const Eigen::Vector3d> light, const ShadePoint& point,
                                 std::vector<Arc>& out, Workspace& ws) const {
    return query(light, point, out, ws, Method::reference);
  }

  size_t triangle_count() const { return triangles_.size(); }

private:
  struct Node {
    Eigen::Vector3d lo, hi;
    uint32_t index;  // leaf: first entry of order_; inner: right child (left child is this + 1)
    uint32_t count;  // leaf: triangle count (> 0); inner: 0
    uint32_t first, total;  // the subtree's triangles: order_[first, first + total)
  };
  struct LightFrame;
  enum class Method { cone, contour, per_triangle, reference };
  // The edge tree (cone path): a binary tree over the welded edges (median splits, leaves of ≤ 4),
  // each node with the box of its edges' faces, that box's bounding sphere and a cone of its
  // faces' unit normals (axis, and spread ≥ |n̂ − axis| for every face), and whether an edge
  // under it is `flagged` (not two faces of distinct welded corners running it both ways).
  struct EdgeNode {
    Eigen::Vector3d lo, hi, centre, axis;
    double radius, spread;
    uint32_t index;  // leaf: first entry of edge_order_; inner: right child (left child is this + 1)
    uint32_t count;  // leaf: edge count (> 0); inner: 0
    uint32_t total;  // the subtree's edges
    bool flagged;
  };
  enum class ImageKind : uint8_t { none, triangle, special };  // special: clipped or an ε-limit cone

  uint32_t build(uint32_t first, uint32_t count, std::vector<Eigen::Vector3d>& centroids);
  bool prepare(std::span<const Eigen::Vector3d> light, const ShadePoint& point, Workspace& ws, LightFrame& frame) const;
  ImageKind add_image(uint32_t triangle, const ShadePoint& point, const LightFrame& frame, Workspace& ws) const;
  size_t query(std::span<const Eigen::Vector3d> light, const ShadePoint& point, std::vector<Arc>& out, Workspace& ws,
               Method method) const;
  void cull(Workspace& ws) const;  // ws.kept += the triangles not outside a culling plane (tree walk)
  void sort_kept(Workspace& ws) const;  // ws.kept ascending (its triangles distinct)
  // The closed-mesh rule (file comment "one facing"): d, a direction strictly inside the light
  // (false: none found); then per whole image (positively oriented), 1 when d is strictly inside
  // it, 0 when strictly outside, −1 when the rule cannot be used (d on an edge's great circle,
  // or the rounded image not positively oriented).
  bool probe_direction(const Workspace& ws, Eigen::Vector3d& d) const;
  static int probe_image(std::span<const Eigen::Vector3d> image, const Eigen::Vector3d& d);
  // Calls keep(t) for each triangle not outside one of `planes` (the same tree walk and margins).
  template <class Keep>
  void walk(std::span<const Workspace::Plane> planes, Workspace& ws, Keep&& keep) const;
  // Calls keep(t) (possibly more than once) for each triangle not outside every fan, a fan being
  // five consecutive planes of `planes` (≤ 64 fans): one walk, each node carrying its live fans.
  template <class Keep>
  void walk_fans(std::span<const Workspace::Plane> planes, Workspace& ws, Keep&& keep) const;
  uint32_t build_edges(uint32_t first, uint32_t count, std::vector<Eigen::Vector3d>& centres) const;
  // 1: edge g may bound the union in the cone; 0: it cannot. Its faces in the pyramid with a
  // clipped image or p in their plane are appended to `special`.
  int classify_edge(uint32_t group, const ShadePoint& point, const LightFrame& frame, const Workspace& ws,
                    std::vector<uint32_t>& special) const;
  uint32_t next_stamp(Workspace& ws) const;  // a fresh mark of ws.tri_stamp
  void cone_query(const ShadePoint& point, const LightFrame& frame, std::vector<Arc>& out, Workspace& ws) const;
  void find_cone_edges(const ShadePoint& point, const LightFrame& frame, Workspace& ws, bool brute) const;

  std::vector<Eigen::Vector3d> positions_;
  std::vector<std::array<uint32_t, 3>> triangles_;
  std::vector<uint32_t> order_;  // triangle indices, leaves' ranges
  std::vector<Node> nodes_;
  // Edge → faces: slot 3t + k is edge (t[k], t[k+1]); edge_slots_ sorted by unordered vertex
  // pair, group g = edge_slots_[edge_group_start_[g] .. edge_group_start_[g + 1]).
  std::vector<uint32_t> edge_slots_, slot_group_, edge_group_start_;
  std::vector<uint32_t> welded_;  // per vertex: the first vertex of its bitwise-equal position
  std::vector<Eigen::Vector3d> face_normal_;  // unit normal of (b − a)×(c − a), zero when degenerate
  std::vector<uint8_t> edge_flagged_;         // per welded edge (see EdgeNode)
  // Per slot: the other slot of its welded edge when that is a consistently wound pair (not
  // flagged), else kNoTwin.
  static constexpr uint32_t kNoTwin = ~0u;
  std::vector<uint32_t> twin_slot_;
  bool closed_ = false;  // every welded edge a consistently wound pair (a closed oriented surface)
  // The edge tree, built by the first cone-path query (edge_tree()): only visible_light_cone and
  // cone_edges use it, and it costs as much as the rest of the constructor on a large mesh.
  void edge_tree() const;
  mutable std::unique_ptr<std::once_flag> edge_tree_once_ = std::make_unique<std::once_flag>();
  mutable std::vector<uint32_t> edge_order_;  // welded edges, the edge tree's leaves' ranges
  mutable std::vector<uint32_t> edge_rank_;   // per welded edge: its place in edge_order_
  mutable std::vector<EdgeNode> edge_nodes_;
};

} // namespace prt::bake
