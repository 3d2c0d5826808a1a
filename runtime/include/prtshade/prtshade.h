/* prtshade/prtshade.h — the C API of the prtshade run-time library, for engines that are not C++.
 *
 * It mirrors the C++ core one to one (the core's headers are the contract; docs/ARCHITECTURE.md
 * §2): <prtshade/sh.h> (SH rotation),
 * <prtshade/shade.h> (lat-long projection, transfer · light, band-1 shading) and
 * <prtshade/fiv.h> (paper 004 §4.3 FIV shading), <prtshade/lights.h> (the baked lights' E) and
 * <prtshade/ltc.h> (GGX over a spherical polygon through LTC). Conventions, units, frames and the papers and
 * equations each function implements are stated in those headers; this one states the C
 * contract only.
 *
 * Contract
 *   - Every function returns a prt_status (PRT_OK == 0) except the destroy functions, the
 *     string functions and prt_version. No C++ exception ever crosses this boundary.
 *   - Null pointers, sizes that do not match (the *_count arguments are the number of floats
 *     the caller's array holds), out-of-range orders and non-finite or inconsistent baked data
 *     give PRT_ERROR_INVALID_ARGUMENT; nothing is written to the outputs then.
 *     prt_last_error() returns a message naming the function and the problem (per thread,
 *     valid until the next failing call on that thread).
 *   - Handles are opaque. A prt_fiv_scene COPIES the DifMap, the environment FIV and every
 *     occluder's arrays, so the caller may free its buffers after the call. A scene may be
 *     shaded from many threads at once; modifying it (add / set_centre) needs exclusive
 *     access. A prt_sh_rotation is immutable and may be shared between threads.
 *   - SH vectors are float, order = NUMBER OF BANDS L (L² coefficients, index l(l+1)+m);
 *     RGB SH lighting is channel-major [3][L²].
 */
#ifndef PRTSHADE_PRTSHADE_H
#define PRTSHADE_PRTSHADE_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum prt_status {
  PRT_OK = 0,
  PRT_ERROR_INVALID_ARGUMENT = 1, /* null pointer, bad size or order, non-finite data */
  PRT_ERROR_OUT_OF_MEMORY = 2,    /* an allocation failed (scene copies, rotation tables) */
  PRT_ERROR_INTERNAL = 3          /* anything else: a bug, please report */
} prt_status;

/* Short fixed description of a status ("invalid argument", ...); never NULL. */
const char* prt_status_string(prt_status status);
/* Detailed message of the last failing call on this thread ("" if none). */
const char* prt_last_error(void);
/* Library version "MAJOR.MINOR.PATCH". */
const char* prt_version(void);

/* ---- spherical harmonics ----------------------------------------------------------------- */

/* Maximum supported order (number of bands): 64. */
int prt_sh_max_order(void);

/* SH basis y_0 .. y_{L²−1} at the unit direction (x, y, z); out holds out_count >= order² floats. */
prt_status prt_sh_eval(int order, float x, float y, float z, float* out, size_t out_count);

typedef struct prt_sh_rotation prt_sh_rotation;
/* rotation: row-major 3×3 proper rotation R (d ↦ R d); see <prtshade/sh.h>. */
prt_status prt_sh_rotation_create(const double rotation[9], int order, prt_sh_rotation** out);
void prt_sh_rotation_destroy(prt_sh_rotation* rotation);
/* Rotates `channels` consecutive SH vectors of order² floats each (e.g. 3 for RGB lighting):
 * in and out hold count >= channels·order² floats and must not overlap. */
prt_status prt_sh_rotation_apply(const prt_sh_rotation* rotation, const float* in, float* out, int channels,
                                 size_t count);

/* ---- diffuse PRT and band-1 shading (<prtshade/shade.h>) --------------------------------- */

/* SH lighting [3][order²] of a [height][width][3] lat-long image (row 0 = north pole, +Y up). */
prt_status prt_project_latlong(const float* rgb, int width, int height, int order, float* out, size_t out_count);

/* out[v][c] = Σ_i transfer[v][i] · light[c][i] for vertex_count vertices; transfer holds
 * vertex_count·order² floats (the /transfer/diffuse rows), light 3·order², out 3·vertex_count. */
prt_status prt_shade_transfer(const float* transfer, size_t vertex_count, int order, const float* light_rgb,
                              float* out);

/* E[v][c] = (4π/3) Σ_m y_1m(n_v) R[v][c][m] for vertex_count vertices: normals [V][3],
 * radiance [V][3][3] (/radiance/band1 rows), out [V][3]. */
prt_status prt_shade_band1(const float* normals, const float* radiance, size_t vertex_count, float* out);

/* ---- glossy shading (<prtshade/glossy.h>) ------------------------------------------------ */

/* The triple-product (Gaunt) table of one order in [1, 16]; immutable, shareable between threads. */
typedef struct prt_glossy prt_glossy;
prt_status prt_glossy_create(int order, prt_glossy** out);
void prt_glossy_destroy(prt_glossy* glossy);
/* Route A (relightable): out[v][c] = ∫ L_c V H k_s(r_v·ω) dω through S = P_L(L_c · U_v), for
 * vertex_count vertices: light [3][order²] (channel-major, as prt_project_latlong writes it),
 * visibility [V][order²] (/transfer/visibility rows at the table's order), normals and positions
 * [V][3], eye [3]; r_v reflects normalize(eye − p_v) about n_v; k_s the normalised Phong lobe of
 * exponent phong_exponent >= 0; out [V][3] (times the specular colour by the caller). */
prt_status prt_shade_glossy(const prt_glossy* glossy, const float* light, const float* visibility, const float* normals,
                            const float* positions, size_t vertex_count, const float eye[3], double phong_exponent,
                            float* out);
/* Route B (fixed environment): out[c] = Σ_l λ_l Σ_m S[c][lm] y_lm(r) for one shadowed-radiance
 * vector S [3][order²] (a /radiance/shadowed row), order in [1, 64], and a unit reflection
 * direction r; λ_l the lobe's band scales. */
prt_status prt_shade_glossy_radiance(const float* shadowed, int order, const float r[3], double phong_exponent,
                                     float out[3]);

/* ---- FIV shading (<prtshade/fiv.h>, paper 004 §4.3) -------------------------------------- */

/* One baked occluder, laid out as /fiv/occluders/<name>: shells [n_rho][n_theta][n_phi][3][3],
 * valid [n_rho][n_theta][n_phi], radii [n_rho]. radial_scheme (the file's attribute of that name):
 * 0 geometric (radii are the shell radii; a zero-initialised desc is this), 1 surface (radii are
 * the offsets from the surface, surface_radius [n_theta][n_phi] is /fiv/occluders/<name>/
 * surface_radius, valid may be null); prtshade/fiv.h "Surface-following shells". cones
 * [n_rho][n_theta][n_phi][4] the tight proxy (/fiv/occluders/<name>/cones when its `proxy` is
 * "cone"; fiv.h "Tight proxies") or NULL (the bounding sphere). shells_half / cones_half: the
 * same tables as IEEE binary16 bits (float16 datasets, format_version 8; fiv.h "Half-float
 * tables"), given instead of shells / cones (leave those NULL). Set every member (or
 * zero-initialise the struct): radial_scheme, surface_radius and cones came with format_version
 * 7, shells_half and cones_half with 8. */
typedef struct prt_fiv_occluder_desc {
  float centre[3];
  float radius;
  int n_rho, n_theta, n_phi;
  const float* radii;
  const float* shells;
  const uint8_t* valid;
  int radial_scheme;
  const float* surface_radius;
  const float* cones;
  const uint16_t* shells_half;
  const uint16_t* cones_half;
} prt_fiv_occluder_desc;

typedef struct prt_fiv_options {
  int partial_occluders;  /* nonzero: the (h + R)/2R factor for case B (default 1) */
  int overlap_correction; /* nonzero: eq. 13–14 unit-bounding-disc correction (default 1) */
  int sphere_proxy;       /* nonzero: the paper's bounding sphere for every occluder; 0 (default):
                             the cone table where an occluder has one (fiv.h "Tight proxies") */
} prt_fiv_options;

typedef struct prt_fiv_scene prt_fiv_scene;

/* A scene lit by one environment: DifMap cube [6][size][size][3] (/fiv/irradiance_cube) and the
 * environment FIV [3][3] (/fiv/environment). Copies both. */
prt_status prt_fiv_scene_create(int difmap_size, const float* difmap_texels, const float environment_fiv[9],
                                prt_fiv_scene** out);
void prt_fiv_scene_destroy(prt_fiv_scene* scene);
/* Copies the occluder's arrays; *out_index (may be NULL) receives its index (0, 1, ...). */
prt_status prt_fiv_scene_add_occluder(prt_fiv_scene* scene, const prt_fiv_occluder_desc* occluder, int* out_index);
/* Moves occluder `index` (dynamic scenes: the shells are relative to the centre). */
prt_status prt_fiv_scene_set_centre(prt_fiv_scene* scene, int index, const float centre[3]);
prt_status prt_fiv_scene_occluder_count(const prt_fiv_scene* scene, int* out_count);

/* DifMap E_tot(n). */
prt_status prt_fiv_scene_lookup_difmap(const prt_fiv_scene* scene, const float n[3], float out[3]);
/* Occluded FIV [3][3] of occluder `index` at offset s = p − centre. */
prt_status prt_fiv_scene_lookup_fiv(const prt_fiv_scene* scene, int index, const float s[3], float out[9]);
/* I of occluder `index` at (p, n) (partial: nonzero applies the case-B factor). */
prt_status prt_fiv_scene_occluded_irradiance(const prt_fiv_scene* scene, int index, const float p[3],
                                             const float n[3], int partial, float out[3]);
/* Irradiance at `count` receivers: positions and normals [count][3], out [count][3], all occluders
 * of the scene; options NULL means both corrections on. */
prt_status prt_fiv_scene_shade(const prt_fiv_scene* scene, const float* positions, const float* normals,
                               size_t count, const prt_fiv_options* options, float* out);
/* Self-shadowed irradiance of `count` receivers lying on occluder `index` (eq. 12). */
prt_status prt_fiv_scene_shade_self(const prt_fiv_scene* scene, int index, const float* positions,
                                    const float* normals, size_t count, float* out);
/* Irradiance of `count` receivers lying on occluder `index` among the scene's other occluders:
 * its self-shadows minus the others' shadows (shade_fiv_member; partial: nonzero applies the
 * case-B factor to the others). */
prt_status prt_fiv_scene_shade_member(const prt_fiv_scene* scene, int index, const float* positions,
                                      const float* normals, size_t count, int partial, float* out);
/* The same with each receiver's self-shadowed irradiance given, self_irradiance [count][3] (e.g.
 * the occluder's per-vertex band-1 radiance, prt_shade_band1, interpolated: what `prtbake fiv`
 * writes by default; shade_fiv_member_given_self). Non-finite self_irradiance is refused. */
prt_status prt_fiv_scene_shade_member_given_self(const prt_fiv_scene* scene, int index, const float* positions,
                                                 const float* normals, const float* self_irradiance, size_t count,
                                                 int partial, float* out);

/* ---- baked lights (<prtshade/lights.h>) and LTC GGX (<prtshade/ltc.h>) ------------------- */

/* out[v][c] = albedo_c/π · Σ_l emission[l][c] · irradiance[v][l] for `count` receivers:
 * irradiance [count][lights] (an area_lights/irradiance product: area and punctual lights alike),
 * emission [lights][3] (each /lights/<name>'s `radiance`: an area light's radiance, a punctual
 * light's intensity), albedo [3] (albedo_per_receiver 0) or [count][3] (nonzero), out [count][3].
 * Non-finite or negative emission, or non-finite irradiance, is an invalid argument. */
prt_status prt_shade_lights(const float* irradiance, size_t count, size_t lights, const float* emission,
                            const float* albedo, int albedo_per_receiver, float* out);

typedef enum prt_punctual_kind {
  PRT_PUNCTUAL_DIRECTIONAL = 0,
  PRT_PUNCTUAL_POINT = 1,
  PRT_PUNCTUAL_SPOT = 2
} prt_punctual_kind;
/* A punctual light as /lights/<name> stores it (radians; direction: where the light travels;
 * range: its `range`, or 0 when it has none). */
typedef struct prt_punctual_light {
  int kind; /* prt_punctual_kind */
  float position[3];
  float direction[3];
  float inner_cone_angle, outer_cone_angle;
  float range;
} prt_punctual_light;
/* *out = E at (p, n) from the light at unit intensity, unshadowed (KHR_lights_punctual's falloff,
 * inverse-square law and recommended range window clamp(1 - (d/range)^4, 0, 1); the baked E where
 * nothing shadows); n unit (to 1e-4). A spot needs 0 <= inner < outer <= pi/2; range must be finite
 * and >= 0 (0: none), and 0 for a directional light. */
prt_status prt_punctual_irradiance(const prt_punctual_light* light, const float p[3], const float n[3], float* out);

/* *out = the LTC approximation of ∫_P f_GGX F (n·ω) dω over the region P bounded by `count` great
 * arcs arcs[k] = {a_x, a_y, a_z, b_x, b_y, b_z} (world directions from the shade point, the region
 * on their left, every endpoint above n's horizon; e.g. a light's visible part clipped to the
 * horizon), at unit n and v (towards the eye, to 1e-4), roughness alpha > 0 (clamped to the
 * table's range) and Schlick F0 in [0, 1]. Times the light's radiance it is the reflected radiance. */
prt_status prt_ltc_ggx(const float n[3], const float v[3], float alpha, float f0, const float* arcs, size_t count,
                       float* out);
/* *out = the measured bound on |prt_ltc_ggx − ∫_P f F cos| for any region P at (alpha, cos θ_v, F0). */
prt_status prt_ltc_ggx_error_bound(float alpha, float cos_theta, float f0, float* out);

#ifdef __cplusplus
} /* extern "C" */
#endif

#endif /* PRTSHADE_PRTSHADE_H */
