// bake/sphere/spherical_polygon.h — spherical polygons about a shade point: solid angle, Lambert's
// vector irradiance and cosine integral in closed form, and clipping to the horizon
// (paper 003, "Fast Analytic Soft Shadows from Area Lights", EGSR 2021:
// §3 eq. 1–2 (the integral over the light's spherical polygon, closed form after Baum et al.
// 1989 / Lambert 1760) and §3.4 Alg. 3 (ClipToHorizon); docs/ARCHITECTURE.md "Conventions").
//
// A spherical polygon is given by its vertex directions v_0 … v_{N−1} seen from the shade point
// (any positive length: points relative to p will do); its edges are the shorter great arcs
// v_i → v_{i+1} (indices mod N). Preconditions: consecutive vertices are not antipodal (edges
// shorter than π; equal consecutive vertices are allowed and contribute nothing), and every
// vertex is finite and non-zero. The polygon is a signed region (a 2-chain): orientation is
// positive when the vertices run counter-clockwise seen from outside the sphere (right-hand rule
// about the outward direction of the interior: det(v_0, v_1, v_2) > 0 for a small triangle), and
// reversing the vertex order negates every integral. Seen from p itself a positive polygon runs
// clockwise: a mesh face counter-clockwise from outside (outward normal) and facing p is
// negatively oriented here, so lights and occluder faces are passed reversed (visible_region.h's
// ConvexPolyhedron does this). Φ and the SH projection of chains add, so a non-simple or
// non-convex polygon integrates as the sum of its regions weighted by their winding numbers (the
// solid angle needs the hemisphere precondition below).
//
// Lambert's edge formula (Arvo, "Applications of Irradiance Tensors to the Simulation of
// Non-Lambertian Phenomena", SIGGRAPH 1995, §3; paper 003 §2 cites it with Baum et al. 1989):
//   Φ(P) = ∫_P ω dω = ½ Σ_i θ_i u_i,   θ_i = ∠(v̂_i, v̂_{i+1}),   u_i = (v̂_i × v̂_{i+1}) / |v̂_i × v̂_{i+1}|,
// and ∫_P (n·ω) dω = n·Φ(P) (the cosine integral; irradiance from unit radiance when P lies above
// the horizon, E = n·Φ, form factor n·Φ/π). Numerics: θ_i = atan2(|a×b|, a·b), never acos; and
// since θ_i u_i = (a×b)·θ_i/sin θ_i, the sum is evaluated as
//   2Φ = Σ_i (v̂_i − v̂_0) × (v̂_{i+1} − v̂_0) + Σ_i (θ_i/sin θ_i − 1) (v̂_i × v̂_{i+1})
// (the first sum equals Σ v̂_i × v̂_{i+1} for a closed polygon). For a small polygon the first sum is
// the planar vector area computed from vertex differences (exact by Sterbenz for nearby unit
// vectors) and the second is O(θ³) per edge, so there is no cancellation: a polygon of solid angle
// 1e-10 keeps a relative accuracy of about u/diameter ≈ 1e-11 (u = 2^−53; measured ≤ 1e-11),
// where the textbook sum of O(θ) edge terms, each with an absolute error ~u, measured ~1e-8.
//
// Solid angle: the fan of signed triangles (c, v̂_i, v̂_{i+1}) about c = Φ/|Φ|, each by
// Van Oosterom & Strackee (IEEE Trans. Biomed. Eng. 30, 1983):
//   tan(Ω_i/2) = det(c, a, b) / (1 + c·a + a·b + b·c),  det(c, a, b) = c·((a − c) × (b − c)),
// (the determinant from differences for relative accuracy on small triangles). The fan counts a
// region by its winding number relative to −c, so it is the solid angle whenever −c lies outside
// the polygon: true for any polygon inside a closed hemisphere (lights, silhouettes of convex
// bodies not containing p, and their horizon clips, including the whole upper hemisphere).
// Such a region has |Ω| ≤ 2π, which fixes the sign (a closed curve bounds a region and its
// complement; a negatively oriented region is told by a fan sum above 2π). A boundary on a great
// circle bounds two hemispheres; it is taken as the one around Φ, Ω = +2π.
//
// Horizon clipping (paper 003 §3.4, Alg. 3, as one Sutherland–Hodgman pass against the great
// circle n·ω = 0): each vertex is classified once by the EXACT sign of n·v (a floating-point
// filter, then an error-free evaluation with FMA products and Shewchuk's expansion sum: the
// predicate is a dot product with the given normal, which orient3d cannot express), so a vertex
// on the horizon (n·v = 0 exactly) is kept as it is, never duplicated and never replaced by a
// computed crossing; an edge whose ends are strictly on opposite sides gets the crossing
// |n·b̂|·â + |n·â|·b̂ (a positive combination of its ends, on the horizon up to rounding). Consecutive output vertices are joined by the shorter
// great arc; for a polygon inside an OPEN hemisphere (precondition of clip_to_horizon) every
// horizon stretch of the clipped boundary is shorter than π, so that arc is the horizon's.
// (Alg. 3 instead compares dot products with 0 in floating point and adds the horizon edges in a
// separate pass.) A non-convex polygon may leave overlapping horizon edges run in opposite
// directions: as a chain its integrals are exact.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <span>
#include <vector>

namespace prt::bake {

// Φ(P) = ∫_P ω dω (signed by orientation).
Eigen::Vector3d vector_irradiance(std::span<const Eigen::Vector3d> vertices);

// ∫_P (n·ω) dω = n·Φ(P) over the whole polygon (no horizon clipping; see clipped_irradiance).
double cosine_integral(std::span<const Eigen::Vector3d> vertices, const Eigen::Vector3d& n);

// Ω(P) in steradians (signed by orientation; see the file comment for the precondition).
double solid_angle(std::span<const Eigen::Vector3d> vertices);

// An oriented great arc a → b (shorter than π; a, b finite, non-zero, any length): a piece of a
// region's boundary with the region on its left (bake/visibility/visible_region.h builds them). A region
// given as a set of boundary arcs (a 1-chain: several loops, holes, pieces of edges) integrates
// by the same edge formulas, summed arc by arc: Φ = ½ Σ θ u in the closed-polygon form above
// (Σ (a − o)×(b − o) about the first arc's start o, plus the O(θ³) terms), and Ω by the fan about
// Φ/|Φ| with the same precondition (the region lies in a closed hemisphere). The arcs need not be
// chained, but the chain should close (each endpoint, bit for bit, as often a start as an end, as
// visible_region makes it): a gap δ between endpoints changes Φ by ~δ (so a tiny region loses its
// relative accuracy), the other integrals by O(δ · arc length).
struct Arc {
  Eigen::Vector3d a, b;
};
Eigen::Vector3d vector_irradiance(std::span<const Arc> boundary);
double solid_angle(std::span<const Arc> boundary);

// Exact sign (−1, 0, +1) of n·v for finite doubles (no overflow or underflow of the products).
int horizon_side(const Eigen::Vector3d& n, const Eigen::Vector3d& v);

// out = P ∩ {ω : n·ω ≥ 0}; out is cleared first and empty when nothing is above the horizon
// (fewer than three vertices never enclose area, so the caller may test out.size() < 3).
// Precondition: P lies in an open hemisphere (see the file comment). n need not be unit.
void clip_to_horizon(std::span<const Eigen::Vector3d> vertices, const Eigen::Vector3d& n,
                     std::vector<Eigen::Vector3d>& out);

// ∫_P max(n·ω, 0) dω: the cosine integral of the part of P above the horizon (irradiance at a
// receiver with unit normal n from a light of unit radiance filling P). Same precondition.
double clipped_irradiance(std::span<const Eigen::Vector3d> vertices, const Eigen::Vector3d& n);

} // namespace prt::bake
