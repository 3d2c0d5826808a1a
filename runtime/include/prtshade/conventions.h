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
// | engine   | frame (from a file with up_axis y)         | stored coefficient c_i            | evaluation of E(n)/π                          | layout   |
// |----------|--------------------------------------------|-----------------------------------|-----------------------------------------------|----------|
// | ours     | right-handed, +Y up                        | L_i (radiance, CS phase)          | Σ_i Â_l/π · L_i y_i(n)                        | [RGB][9] |
// | Unity    | LEFT-handed, +Y up: x_unity = −x (as its    | Â_l/π · k_i · L_i: the polynomial | ShadeSH9: SHA = (c3, c1, c2, c0 − c6),        | [RGB][9] (SphericalHarmonicsL2[rgb, i]) |
// |          | glTF and FBX importers mirror X)           | coefficients, no CS phase left    | SHB = (c4, c5, 3c6, c7), SHC = c8; Σ c_i p_i(n) |          |
// | Godot 4  | right-handed, +Y up (= ours)               | s_i · L_i / π (radiance/π, basis  | R&H eq. 13: c4·c0 + 2c2(c3 x + c1 y + c2 z) +  | [9][RGB] (probe data: 9 colours) |
// |          |                                            | without CS phase, s_i = sign k_i) | c3·c6 z² − c5·c6 + c1·c8(x²−y²) + 2c1(c4 xy + c7 xz + c5 yz) |  |
// | Filament | right-handed, +Y up (= ours)               | Â_l/π · k_i · L_i (cmgen's        | Σ c_i p_i(n) (Irradiance_SphericalHarmonics)  | [9][RGB] (float3 sh[9]) |
// |          |                                            | "pre-scaled" irradiance SH)       |                                               |          |
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
// Errors: none (every input is valid; NaN in, NaN out).
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
