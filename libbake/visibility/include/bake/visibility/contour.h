// bake/visibility/contour.h — contour-edge extraction, the first stage of the silhouette integrator
// (paper 001 §3.1, eq. 6; docs/ARCHITECTURE.md §4).
//
// An undirected welded edge e = (a, b), a < b, with incident faces k (corner c_k not on e) is a
// contour edge seen from the shade point p when its side sum
//     S_e = Σ_k σ_k,   σ_k = orient_eps(pos(a), pos(b), pos(c_k), p, n)
// is non-zero: σ_k tells on which side of the plane through p, a, b the face k lies, evaluated
// exactly and in the limit p + εn, ε → 0+ (docs/ARCHITECTURE.md §3). A path crossing e's projection in
// direction t changes the depth complexity by sign(m·t)·S_e with m = (a−p)×(b−p): the number of
// faces on the far side minus those on the near side. Nothing assumes consistent winding or a
// manifold: boundary edges (1 face) have |S_e| = 1, non-manifold edges any value.
//
// Search (paper §3.1): for a face k of e, σ_k = −sign(π_k(p)) with π_k(x) = N_k·(x − a),
// N_k = (b−a)×(c_k−a), an affine function of p: a 4-vector g_k with π_k(p) = g_k·(p, 1). A
// 2-face edge is a contour iff σ_1 = σ_2 ≠ 0 iff the hyperplane {x : x·(p, 1) = 0} of R⁴ meets
// (crosses or touches) its dual segment [ĝ_1, −ĝ_2] (ĝ = g/|N|). ContourFinder keeps a BVH
// over those segments and queries it with rigorous floating-point tolerances, so it can never
// miss an edge the exact test reports; every candidate is then decided exactly. Edges with 1 or
// 3+ faces, or with a degenerate / ill-conditioned face, are always tested: each face's σ from
// its plane in float with the leaves' rigorous tolerance, by orient_eps where that cannot decide
// (a boundary edge is a contour edge from almost every point, so it cannot be culled, only tested
// cheaply: the engine glTF has 24k such edges of 172k).
//
// The tree: each edge's dual segment is stored oriented by face 1's winding (negating both
// endpoints changes no decision, and on a consistently wound surface neighbouring edges then
// share one normal instead of ±n at random by their index order); the edges are grouped by
// position and normal (binned SAH over their corners' and normals' boxes; a purely spatial
// build, a normal-first one and a normal-cone node test were measured and visit more nodes or
// cost more per node), and each node bounds its segments in its own frame — centre c, the box
// of the endpoints' normals n and the range of D = d + n·c — so the value n·(q − c) + D is
// bounded by Σ|q_i − c_i|·Δn_i + ΔD: tight for nodes near the shade point, where the
// hyperplane is tangent to the dual surface. The binary tree is collapsed to a 4-wide one (children's bounds
// side by side, tested four at a time in float), leaves are blocks of four edges tested four at
// a time in float, and the walk is breadth-first with every queued node prefetched.
#pragma once

#include <bake/mesh/mesh.h>
#include <bake/mesh/predicates.h>
#include <bake/mesh/shade_point.h>

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace prt::bake {

struct ContourEdge {
  uint32_t edge;     // index into Topology::edges (undirected welded edge (a, b), a < b)
  int32_t side_sum;  // S_e = Σ over faces k incident to e of σ_k (see the file comment); a face
                     // whose corners are not 3 distinct welded ids has σ = 0
  friend bool operator==(const ContourEdge&, const ContourEdge&) = default;
};

struct ContourFinderStats {
  size_t edges = 0;            // Topology::edges.size()
  size_t bvh_edges = 0;        // 2-face edges with well-conditioned faces, in the BVH
  size_t always_tested = 0;    // 1-face, 3+-face and degenerate / ill-conditioned edges
  size_t flat_edges = 0;       // 2-face edges with coplanar faces on opposite sides: never contours, dropped
  size_t bvh_nodes = 0;        // wide (4-child) nodes
  size_t bvh_depth = 0;        // depth of the binary tree before the collapse
  double normal_error = 0;     // η: max error bound of the BVH's unit face normals
};

// Work done by find() (summed over the queries it was given): the search's cost model.
struct ContourQueryStats {
  uint64_t queries = 0;
  uint64_t nodes = 0;    // child bounds tested (four per wide node fetched)
  uint64_t records = 0;  // leaf lanes whose two face values were evaluated (four per leaf block)
  uint64_t exact = 0;    // of those, edges decided by orient_eps (a value within the tolerance), plus
                         // always-tested faces decided by orient_eps
  uint64_t always = 0;   // always-tested edges (their faces' σ from a float filter as in the leaves,
                         // orient_eps where it cannot decide, on every query)
};

class ContourFinder {
public:
  // Builds the dual-space BVH. `mesh` and `topology` (build_topology(mesh)) must outlive the finder.
  ContourFinder(const Mesh& mesh, const Topology& topology);
  ContourFinder(const ContourFinder&) = delete;
  ContourFinder& operator=(const ContourFinder&) = delete;

  // All edges with S_e != 0 at the shade point, sorted by edge index (`out` is cleared first).
  // Uses the BVH; equals find_brute_force exactly. Thread-safe; allocates only to grow `out` and
  // its per-thread buffers.
  // Only point.p and point.n are used (the ε-limit is geometric: a shade point at a vertex
  // position gets its 1-ring right whatever point.welded says). With `stats`, the query's work
  // is added to it (the same result; counting costs a few increments).
  void find(const ShadePoint& point, std::vector<ContourEdge>& out, ContourQueryStats* stats = nullptr) const;
  // Reference: every edge, every face, orient_eps.
  void find_brute_force(const ShadePoint& point, std::vector<ContourEdge>& out) const;

  size_t edge_count() const;
  size_t bvh_node_count() const;
  const ContourFinderStats& stats() const { return stats_; }

private:
  struct Node {  // binary tree node (construction only); the bound in its own frame (centre c), rounded outward
    float c[3];              // centre of the node's corners (finder frame)
    float nlo[3], nhi[3];    // box of the endpoint normals n
    float dlo, dhi;          // range of D = d + n·c over the endpoints (n, d): value n·(q − c) + D
    uint32_t index;  // leaf: first record; inner: right child (left child is this + 1)
    uint32_t count;  // leaf: record count (> 0); inner: 0
  };
  // Four children's bounds side by side (SoA): 192 bytes, three cache lines on their boundaries.
  struct alignas(64) WideNode {
    float c[3][4], nlo[3][4], nhi[3][4];
    float dlo[4], dhi[4];
    uint32_t child[4];  // inner: wide node index; leaf: its LeafBlock | kLeafBit. An empty slot
                        // is a leaf with D = +∞ (never passes)
  };
  static constexpr uint32_t kLeafBit = 0x80000000u;
  static constexpr uint32_t kFlipBit = 0x80000000u;
  struct alignas(16) LeafBlock {  // a leaf's four BVH edges (padded), lane j = edge j: what the leaf test reads
    float g[8][4];     // ĝ_1 (unit normal, offset) then −ĝ_2, finder frame, rounded to float; both
                       // negated when the record is flipped (oriented by face 1's winding)
    uint32_t edge[4];  // Topology edge indices, | kFlipBit when flipped (padding: 0, never read)
  };
  struct Corners {  // the same edge's positions for the exact test (world frame), same order
    float a[3], b[3], c1[3], c2[3];
    uint32_t edge;
  };

  template <bool Count>
  void find_impl(const ShadePoint& point, std::vector<ContourEdge>& out, ContourQueryStats* stats) const;
  void collapse_wide(const std::vector<Node>& binary);
  int side_sum_slow(uint32_t edge, const Eigen::Vector3d& p, const Eigen::Vector3d& n, const Eigen::Vector3d* tie) const;

  const Mesh* mesh_;
  const Topology* topology_;
  std::vector<WideNode> wide_;   // the tree the query walks
  std::vector<LeafBlock> blocks_;
  std::vector<Corners> corners_;        // block b lane j at 4b + j (padding: unused)
  std::vector<uint32_t> always_;  // edges tested on every query, ascending
  struct AlwaysFace {             // a face of an always-tested edge: its corners a, b and c
    float a[3], b[3], c[3];
  };
  std::vector<AlwaysFace> always_faces_;  // always_[i]'s faces end at always_end_[i]
  std::vector<uint32_t> always_end_;
  struct alignas(16) FaceBlock {  // always_faces_[4b + j]'s plane ĝ = (unit normal, offset), lane j,
    float g[4][4];                // finder frame, float; zero when ill-conditioned (orient_eps decides)
  };
  std::vector<FaceBlock> always_blocks_;
  double always_max_a_ = 0;  // max |a'|₁ over the well-conditioned always-tested faces
  double always_coef_ = 0;   // their float values decide σ beyond always_coef_ · (|q|₁ + always_max_a_)
  Eigen::Vector3d origin_{0, 0, 0};
  double scale_ = 1;       // frame: q = (p − origin)·scale, scale a power of two
  double delta_coef_ = 0;  // δ(q) = delta_coef_ · (|q|₁ + max_a_)
  double record_coef_ = 0; // leaf values from float records: δ + record_coef_ · (|q|₁ + max_a_)
  double max_a_ = 0;       // max |a'|₁ over BVH faces (centred, scaled corner a)
  double node_coef_ = 0, node_const_ = 0;  // node bounds: δ + node_coef_·(|q|₁ + node_const_)
  ContourFinderStats stats_;
};

} // namespace prt::bake
