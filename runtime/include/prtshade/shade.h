// prtshade/shade.h — run-time diffuse PRT shading with the baked per-vertex data: SH projection
// of a lighting environment given as pixels, transfer · lighting, and band-1 shading of the
// baked shadowed radiance. The contract shared with the C API (prtshade/prtshade.h) and the GLSL
// mirrors (runtime/shaders) is this header; the conventions are docs/ARCHITECTURE.md §3 and
// formats/SCHEMA.md.
//
// SH: the basis of <prtshade/sh.h> (real, orthonormal, Condon–Shortley phase, index l(l+1)+m,
// "order" L = NUMBER OF BANDS, L² coefficients). Lighting is rotated with prt::sh::Rotation
// (rotate the lighting, not the transfer).
//
// Lat-long pixels (project_latlong) follow OpenEXR's Imf::LatLongMap exactly as libbake's EnvMap
// (libbake/environment/include/bake/environment/envmap.h) does, +Y up (map space == scene space; a Z-up scene converts
// its directions itself). For a W × H image, integer pixel positions are texel CENTRES:
//   latitude(py) = π/2 − π·py/(H−1),  longitude(px) = π − 2π·px/(W−1),
//   direction    = (sin lon · cos lat, sin lat, cos lon · cos lat),
// so row 0 sits on the north pole (+Y), row H−1 on the south pole, columns 0 and W−1 on the seam
// (lon = ±π, direction −Z). Texel (px, py) owns the longitude/latitude band between the half-pixel
// positions px ± ½, py ± ½ clipped to [0, W−1] × [0, H−1] (first/last rows and columns are
// half texels); its exact solid angle is Δlon · (sin lat_top − sin lat_bottom), and the solid
// angles sum to 4π. Projection is the one-point rule per texel
//   L_{c,i} = Σ_t value_{t,c} · y_i(centre_t) · Ω_t,
// exact for the constant term and identical to bake::EnvMap::project_sh (same rule, same row
// order of summation, double accumulation), so baker and runtime light alike.
// Pixel policy (as EnvMap::from_latlong): negative values (lossy EXR ringing) are clamped to 0;
// NaN/Inf is an error naming the pixel.
//
// Integrands (docs/ARCHITECTURE.md §3; V visibility, H(ω,n) = [n·ω > 0]):
//   diffuse transfer   T_i = (1/π) ∫ V H (n·ω) y_i dω    (Sloan, Kautz, Snyder 2002; docs/ARCHITECTURE.md §3)
//                      shading: L_out = albedo · Σ_i T_i L_i, L_i = ∫ L_env y_i dω. Because T
//                      carries the 1/π, a constant environment L with an unoccluded vertex gives
//                      Σ_i T_i L_i = L (the white furnace returns the albedo).
//   band-1 radiance    R_{c,m} = ∫ L_c V H y_{1m} dω  (paper 001 §4 "All-Frequency Diffuse
//                      Shading"); the exact shadowed irradiance at the baked normal n is
//                      E_c = (4π/3) Σ_m y_{1m}(n) R_{c,m}   (vector irradiance, paper 001 app. A),
//                      radiance out = albedo · E / π.
//
// Errors: project_latlong and the batch functions check their arguments and throw
// std::invalid_argument (a caller bug or a bad image); shade_transfer and shade_band1 are per-
// vertex hot paths and check nothing (order must be in [0, sh::kMaxOrder], pointers valid).
// All functions are thread-safe (no shared state).
#pragma once

#include <cstddef>

namespace prt::shade {

// SH projection of a lat-long environment given as pixels: rgb is [height][width][3] linear RGB
// (row 0 = north pole, as in a file), width >= 2, height >= 2, width·height <= 2^28; order in
// [1, sh::kMaxOrder]. out is [3][order*order] (channel-major: out[c*order² + i]). Computed in
// double, stored as float (one rounding per coefficient). Throws std::invalid_argument.
void project_latlong(const float* rgb, int width, int height, int order, float* out);

// Σ_i transfer[i] · light_rgb[c·n + i] for c = 0..2, n = order² (docs/ARCHITECTURE.md §3 diffuse transfer;
// the caller multiplies by the albedo). light_rgb is channel-major as project_latlong writes it.
// Accumulated in float, in index order.
void shade_transfer(const float* transfer, int order, const float* light_rgb, float out[3]);

// The same for `count` vertices: transfer is [count][order²] (the /transfer/diffuse rows), out
// is [count][3]. Throws std::invalid_argument on null pointers (count > 0) or a bad order.
void shade_transfer_vertices(const float* transfer, std::size_t count, int order, const float* light_rgb,
                             float* out);

// E_c = (4π/3) Σ_m y_1m(n) R[c*3 + (m+1)], n unit (a non-unit n scales E by |n|), R = one row of
// /radiance/band1 [RGB][m = −1, 0, 1] (paper 001 §4 / appendix A). With y_1m = √(3/4π)·(−y, z, −x)
// this is E_c = √(4π/3) · (−n_y R_{c,−1} + n_z R_{c,0} − n_x R_{c,1}).
void shade_band1(const float n[3], const float radiance[9], float out[3]);

// The same for `count` vertices: normals [count][3], radiance [count][9], out [count][3].
// Throws std::invalid_argument on null pointers (count > 0).
void shade_band1_vertices(const float* normals, const float* radiance, std::size_t count, float* out);

} // namespace prt::shade
