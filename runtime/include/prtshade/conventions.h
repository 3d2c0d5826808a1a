// prtshade/conventions.h — our SH lighting in the light-probe conventions of game engines: Unity
// (SphericalHarmonicsL2, evaluated by ShadeSH9), Godot 4 (LightmapGI probes) and Filament
// (IndirectLight::irradiance, cmgen's pre-scaled SH). Pure functions of numbers, std-only, so an
// engine's importer can link them; `prtbake export --to unity|godot|filament` uses them. The
// table below is also formats/SCHEMA.md "Exports" (docs/ARCHITECTURE.md "Conventions").
//
// Input: radiance SH of order 3 (bands 0–2, 9 coefficients per RGB channel) in OUR convention
// (<prtshade/sh.h>: real, orthonormal, Condon–Shortley phase, index l(l+1)+m) and in the baked
// file's frame (right-handed; up_axis "y" or "z", SCHEMA.md "Conventions").
//
// What every engine evaluates at a unit normal n (in its own frame) is the diffuse lighting
// E(n)/π — irradiance over π, the number the engine multiplies by the albedo — for the
// clamped-cosine convolution E(n) = Σ_l Â_l Σ_m L_lm y_lm(n), Â = (π, 2π/3, π/4) (Ramamoorthi &
// Hanrahan 2001, "An Efficient Representation for Irradiance Environment Maps", eq. 8–12).
// With the basis polynomials p = (1, y, z, x, xy, yz, 3z²−1, xz, x²−y²) and our signed basis
// constants k_i = y_i / p_i = (0.282095, −0.488603, 0.488603, −0.488603, 1.092548, −1.092548,
// 0.315392, −1.092548, 0.546274) (the minus signs are the Condon–Shortley phase):
//
//   ours      frame: right-handed, +Y up (a file with up_axis y). c_i = L_i (radiance, CS phase).
//             E(n)/π = Σ_i Â_l/π · L_i y_i(n). Layout [RGB][9].
//   Unity     frame: LEFT-handed, +Y up: x ↦ −x (what its glTF and FBX importers do).
//             SphericalHarmonicsL2 c_i = Â_l/π · k_i · L_i: the coefficients of the polynomials
//             p_i, pre-scaled, no CS phase left. ShadeSH9 on SHA = (c3, c1, c2, c0 − c6),
//             SHB = (c4, c5, 3c6, c7), SHC = c8 gives Σ_i c_i p_i(n). Layout [rgb][9] (sh[rgb, i]).
//   Godot 4   frame: right-handed, +Y up (identity). LightmapGI probe c_i = sign(k_i) · L_i / π:
//             radiance/π in the orthonormal basis WITHOUT the CS phase (Ramamoorthi–Hanrahan's);
//             its shader applies R&H eq. 13: 0.886227 c0 − 0.247708 c6 + 0.743125 c6 z²
//             + 1.023328 (c3 x + c1 y + c2 z) + 0.858086 (c4 xy + c7 xz + c5 yz)
//             + 0.429043 c8 (x² − y²). Layout [9][rgb] (a probe's 9 colours).
//   Filament  frame: right-handed, +Y up (identity). IndirectLight::irradiance(3, sh): cmgen's
//             pre-scaled irradiance SH, c_i = Â_l/π · k_i · L_i (as Unity's numbers);
//             Irradiance_SphericalHarmonics gives Σ_i c_i p_i(n). Layout [9][rgb] (float3 sh[9]).
//
// A file with up_axis "z" (Blender) is first turned Y-up as glTF exporters do: (x, y, z) ↦
// (x, z, −y), then mapped as above. Re-expressing a function in a mirrored or rotated frame
// uses sh::Rotation; a mirror M is −R with R = −M a rotation and y_lm(−d) = (−1)^l y_lm(d).
//
// Band-1 radiance (SCHEMA.md "/radiance/band1", paper 001 §4): R_{c,m} = ∫ L_c V H y_1m dω is
// band 1 of the shadowed incident radiance L·V·H, which vanishes below the tangent plane; the
// exact shadowed irradiance at the baked normal n is E = (4π/3) Σ_m y_1m(n) R_m = n · F (paper
// 001 app. A). An engine convolves band 1 with Â_1 = 2π/3, half of that, so the probe of a
// vertex is the radiance SH (0; 2R; 0): every engine's formula then returns exactly the baked
// E/π at the baked normal (and the linear "vector irradiance" n · F/π at other normals).
// Errors: change_frame throws std::invalid_argument (from sh::Rotation) for a matrix that is not
// orthogonal; to_engine never throws (its matrices are exact); NaN in, NaN out.
#pragma once

#include <array>

namespace prt::conventions {

enum class Engine { Unity, Godot, Filament };
enum class UpAxis { Y, Z };  // the baked file's up_axis

using Sh9 = std::array<double, 9>;      // one channel, order 3, index l(l+1)+m
using RgbSh9 = std::array<Sh9, 3>;      // [RGB][i]
using Mat3 = std::array<std::array<double, 3>, 3>;  // row-major, d ↦ M d
using EngineSh = std::array<double, 27>;  // an engine's 27 numbers in its own layout (table)

// The signed basis constants k_i = y_i / p_i of our order-3 basis (see the header).
const Sh9& basis_constants() noexcept;

// The clamped-cosine convolution factor Â_l of band l (π, 2π/3, π/4 for l = 0, 1, 2).
double clamped_cosine_band(int l) noexcept;

// Directions in `engine`'s frame from directions in a file with `up`: an orthogonal matrix
// (det −1 for Unity, a mirror; +1 otherwise).
Mat3 engine_from_file(Engine engine, UpAxis up) noexcept;

// Coefficients of g(d) = f(M⁻¹ d) from those of f, for an orthogonal M (det ±1, ‖M Mᵀ − I‖ ≤ 1e-6;
// otherwise std::invalid_argument from sh::Rotation).
Sh9 change_frame(const Sh9& f, const Mat3& M);

// The probe radiance (0; 2R; 0) of band-1 radiance R laid out [RGB][m = −1, 0, 1] (see header).
RgbSh9 radiance_from_band1(const std::array<float, 9>& band1) noexcept;

// `engine`'s 27 coefficients (stored meaning and layout: the table) of the lighting whose radiance
// SH, in our convention and in the frame of a file with `up`, is `radiance`.
EngineSh to_engine(Engine engine, UpAxis up, const RgbSh9& radiance);

// Our diffuse lighting E(n)/π (n in the file's frame, unit) of radiance SH `c`: the reference the
// engines' formulas are compared with.
double irradiance_over_pi(const Sh9& c, double x, double y, double z);

} // namespace prt::conventions
