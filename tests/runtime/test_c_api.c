/* test_c_api.c — the prtshade C API used from C11, as an engine written in C would. Each check
 * returns 0 on success or the number of failures, and writes the first failure into msg; the
 * GoogleTest driver test_c_api.cpp runs them. Every numeric check states its tolerance's reason. */
#include <prtshade/prtshade.h>

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

static int fail(char* msg, size_t size, const char* what, double got, double want) {
  snprintf(msg, size, "%s: got %.9g, want %.9g", what, got, want);
  return 1;
}

#define CHECK_NEAR(got, want, tol, what)                                                         \
  do {                                                                                           \
    if (!(fabs((double)(got) - (double)(want)) <= (tol))) return fail(msg, size, (what), (got), (want)); \
  } while (0)
#define CHECK_STATUS(call, want)                                                                 \
  do {                                                                                           \
    prt_status s_ = (call);                                                                      \
    if (s_ != (want)) {                                                                          \
      snprintf(msg, size, "%s returned %d (%s: %s), want %d", #call, (int)s_, prt_status_string(s_), \
               prt_last_error(), (int)(want));                                                   \
      return 1;                                                                                  \
    }                                                                                            \
  } while (0)

/* Status strings, version, and argument errors with messages. */
int prt_c_check_errors(char* msg, size_t size) {
  float out[27];
  float rgb[2 * 2 * 3] = {0};
  prt_sh_rotation* rot = NULL;
  const double identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  if (strcmp(prt_status_string(PRT_OK), "ok") != 0) return fail(msg, size, "status string of PRT_OK", 0, 0);
  if (strcmp(prt_status_string(PRT_ERROR_INVALID_ARGUMENT), "invalid argument") != 0)
    return fail(msg, size, "status string of PRT_ERROR_INVALID_ARGUMENT", 0, 0);
  if (prt_status_string((prt_status)42) == NULL) return fail(msg, size, "status string of 42 is NULL", 0, 0);
  if (strlen(prt_version()) < 5) return fail(msg, size, "version string too short", 0, 0);
  if (prt_sh_max_order() != 64) return fail(msg, size, "max order", prt_sh_max_order(), 64);
  CHECK_STATUS(prt_project_latlong(NULL, 2, 2, 3, out, 27), PRT_ERROR_INVALID_ARGUMENT);
  if (strstr(prt_last_error(), "prt_project_latlong") == NULL) return fail(msg, size, "message names the function", 0, 0);
  CHECK_STATUS(prt_project_latlong(rgb, 2, 2, 3, out, 26), PRT_ERROR_INVALID_ARGUMENT); /* out too small */
  if (strstr(prt_last_error(), "needs 27") == NULL) return fail(msg, size, "message names the size", 0, 0);
  CHECK_STATUS(prt_project_latlong(rgb, 1, 2, 3, out, 27), PRT_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(prt_project_latlong(rgb, 2, 2, 0, out, 27), PRT_ERROR_INVALID_ARGUMENT);
  rgb[4] = NAN;
  out[0] = 123.0f;
  CHECK_STATUS(prt_project_latlong(rgb, 2, 2, 3, out, 27), PRT_ERROR_INVALID_ARGUMENT);
  CHECK_NEAR(out[0], 123.0, 0.0, "output untouched after a failure");
  CHECK_STATUS(prt_sh_eval(3, 0.6f, 0.8f, 0.0f, out, 8), PRT_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(prt_sh_eval(3, 2.0f, 0.0f, 0.0f, out, 9), PRT_ERROR_INVALID_ARGUMENT); /* not unit */
  CHECK_STATUS(prt_sh_rotation_create(identity, 65, &rot), PRT_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(prt_sh_rotation_create(NULL, 3, &rot), PRT_ERROR_INVALID_ARGUMENT);
  {
    const double reflection[9] = {-1, 0, 0, 0, 1, 0, 0, 0, 1};
    CHECK_STATUS(prt_sh_rotation_create(reflection, 3, &rot), PRT_ERROR_INVALID_ARGUMENT);
  }
  CHECK_STATUS(prt_shade_transfer(NULL, 1, 3, out, out), PRT_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(prt_shade_transfer(NULL, 0, 3, NULL, NULL), PRT_OK); /* nothing to do */
  CHECK_STATUS(prt_shade_band1(NULL, out, 1, out), PRT_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(prt_fiv_scene_create(0, out, out, NULL), PRT_ERROR_INVALID_ARGUMENT);
  prt_sh_rotation_destroy(NULL); /* accepted, like free(NULL) */
  prt_fiv_scene_destroy(NULL);
  return 0;
}

/* Projection of a constant environment, white-furnace transfer shading, band-1 shading, rotation. */
int prt_c_check_shading(char* msg, size_t size) {
  enum { W = 33, H = 17, ORDER = 3, N = ORDER * ORDER };
  static float img[W * H * 3];
  float light[3 * N], out[3], sh[N], rotated[N];
  float transfer[N] = {0};
  int i, c;
  const double rpi = sqrt(PI);
  prt_sh_rotation* rot = NULL;
  for (i = 0; i < W * H * 3; ++i) img[i] = (float)(1 + i % 3);
  CHECK_STATUS(prt_project_latlong(img, W, H, ORDER, light, 3 * N), PRT_OK);
  /* y00 = L √(4π): the solid angles sum to 4π; one float rounding. */
  for (c = 0; c < 3; ++c) CHECK_NEAR(light[c * N], (1 + c) * sqrt(4 * PI), 2 * FLT_EPSILON * (1 + c) * sqrt(4 * PI), "y00");
  /* Unoccluded transfer for n = +z: T0 = 1/(2√π), T2 = √3/(3√π), T6 = √5/(8√π); with the exact
   * constant lighting (y00 only) Σ T L = L: a few float roundings. */
  transfer[0] = (float)(1 / (2 * rpi));
  transfer[2] = (float)(sqrt(3.0) / (3 * rpi));
  transfer[6] = (float)(sqrt(5.0) / (8 * rpi));
  for (i = 0; i < 3 * N; ++i) light[i] = (i % N == 0) ? (float)((1 + i / N) * sqrt(4 * PI)) : 0.0f;
  CHECK_STATUS(prt_shade_transfer(transfer, 1, ORDER, light, out), PRT_OK);
  for (c = 0; c < 3; ++c) CHECK_NEAR(out[c], 1 + c, 4 * FLT_EPSILON * (1 + c), "white furnace");
  {
    /* Band 1, directional light of unit radiance·sr from ω0 = (0, 0.6, 0.8): R_m = y_1m(ω0), and
     * E = n·ω0 for n = (0, 0, 1): 0.8 (a few float roundings). */
    const float n[3] = {0, 0, 1};
    const double k = 0.48860251190291992159;
    float R[9];
    for (c = 0; c < 3; ++c) {
      R[3 * c + 0] = (float)(k * -0.6);
      R[3 * c + 1] = (float)(k * 0.8);
      R[3 * c + 2] = 0.0f;
    }
    CHECK_STATUS(prt_shade_band1(n, R, 1, out), PRT_OK);
    for (c = 0; c < 3; ++c) CHECK_NEAR(out[c], 0.8, 8 * FLT_EPSILON, "band-1 cosine law");
  }
  {
    /* Rotating y(d) by R gives coefficients whose value at R d equals the original at d; for a
     * rotation of +90° about z (x → y), the band-1 coefficients of y(+x) become those of y(+y). */
    const double rz[9] = {0, -1, 0, 1, 0, 0, 0, 0, 1};
    float want[N];
    CHECK_STATUS(prt_sh_eval(ORDER, 1.0f, 0.0f, 0.0f, sh, N), PRT_OK);
    CHECK_STATUS(prt_sh_eval(ORDER, 0.0f, 1.0f, 0.0f, want, N), PRT_OK);
    CHECK_STATUS(prt_sh_rotation_create(rz, ORDER, &rot), PRT_OK);
    CHECK_STATUS(prt_sh_rotation_apply(rot, sh, sh, 1, N), PRT_ERROR_INVALID_ARGUMENT); /* in-place refused */
    CHECK_STATUS(prt_sh_rotation_apply(rot, sh, rotated, 1, N), PRT_OK);
    prt_sh_rotation_destroy(rot);
    /* Exact rotation matrices of a quarter turn, float rounding of O(1) values. */
    for (i = 0; i < N; ++i) CHECK_NEAR(rotated[i], want[i], 4 * FLT_EPSILON, "rotated basis");
  }
  return 0;
}

/* Glossy shading: the white furnace through both routes. Unoccluded everywhere (U = √(4π) δ_0,
 * V H ≡ 1) under a white sky (L = √(4π) δ_0): S = √(4π) δ_0 and L_out = λ_0 = 1 for any lobe and
 * any view — a few float roundings. Route B with the same S; bad arguments refused. */
int prt_c_check_glossy(char* msg, size_t size) {
  enum { ORDER = 5, N = ORDER * ORDER };
  float light[3 * N] = {0}, visibility[N] = {0}, shadowed[3 * N] = {0}, out[3];
  const float normal[3] = {0, 0, 1}, position[3] = {0, 0, 0}, eye[3] = {3, 1, 2}, r[3] = {0.6f, 0.0f, 0.8f};
  prt_glossy* g = NULL;
  int c;
  for (c = 0; c < 3; ++c) light[c * N] = shadowed[c * N] = (float)sqrt(4 * PI);
  visibility[0] = (float)sqrt(4 * PI);
  CHECK_STATUS(prt_glossy_create(0, &g), PRT_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(prt_glossy_create(ORDER, &g), PRT_OK);
  CHECK_STATUS(prt_shade_glossy(g, light, visibility, normal, position, 1, eye, 24.0, out), PRT_OK);
  for (c = 0; c < 3; ++c) CHECK_NEAR(out[c], 1.0, 8 * FLT_EPSILON, "glossy white furnace (route A)");
  CHECK_STATUS(prt_shade_glossy(g, light, visibility, normal, position, 1, eye, -1.0, out), PRT_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(prt_shade_glossy(NULL, light, visibility, normal, position, 1, eye, 4.0, out), PRT_ERROR_INVALID_ARGUMENT);
  prt_glossy_destroy(g);
  CHECK_STATUS(prt_shade_glossy_radiance(shadowed, ORDER, r, 128.0, out), PRT_OK);
  for (c = 0; c < 3; ++c) CHECK_NEAR(out[c], 1.0, 8 * FLT_EPSILON, "glossy white furnace (route B)");
  CHECK_STATUS(prt_shade_glossy_radiance(shadowed, 65, r, 4.0, out), PRT_ERROR_INVALID_ARGUMENT);
  return 0;
}

/* A FIV scene: DifMap + environment FIV + an occluder with constant shells; shading cases. */
int prt_c_check_fiv(char* msg, size_t size) {
  enum { S = 4, NR = 2, NT = 3, NP = 4 };
  static float cube[6 * S * S * 3];
  static float shells[NR * NT * NP * 9];
  static uint8_t valid[NR * NT * NP];
  const float radii[NR] = {1.0f, 64.0f};
  const float env[9] = {0, 3, 0, 0, 6, 0, 0, 9, 0};
  prt_fiv_scene* scene = NULL;
  prt_fiv_occluder_desc desc;
  prt_fiv_options no_overlap = {1, 0, 0};
  int i, c, index = -1, count = 0;
  float out[9], two_out[6];
  const float p[6] = {0, 0, 0, 0, 0, 0}, n[6] = {0, 1, 0, 0, 1, 0};
  for (i = 0; i < 6 * S * S * 3; ++i) cube[i] = 10.0f;
  for (i = 0; i < NR * NT * NP * 9; ++i) shells[i] = (i % 3 == 1) ? (float)(1 + (i % 9) / 3) : 0.0f; /* F_c = (0, c+1, 0) */
  for (i = 0; i < NR * NT * NP; ++i) valid[i] = 1;
  desc.centre[0] = 0, desc.centre[1] = 3, desc.centre[2] = 0;
  desc.radius = 1.0f;
  desc.n_rho = NR, desc.n_theta = NT, desc.n_phi = NP;
  desc.radii = radii, desc.shells = shells, desc.valid = valid, desc.cones = NULL;
  desc.radial_scheme = 0, desc.surface_radius = NULL; /* paper 004's spheres */
  desc.shells_half = NULL, desc.cones_half = NULL;   /* float tables (format_version 8 adds half ones) */

  CHECK_STATUS(prt_fiv_scene_create(S, cube, env, &scene), PRT_OK);
  CHECK_STATUS(prt_fiv_scene_add_occluder(scene, &desc, &index), PRT_OK);
  if (index != 0) return fail(msg, size, "first occluder index", index, 0);
  /* The scene copied the arrays: scribbling on ours changes nothing. */
  for (i = 0; i < NR * NT * NP * 9; ++i) shells[i] = 1e6f;
  CHECK_STATUS(prt_fiv_scene_lookup_difmap(scene, n, out), PRT_OK);
  for (c = 0; c < 3; ++c) CHECK_NEAR(out[c], 10.0, 0.0, "DifMap of a flat cube");
  /* Case A (h = 3 >= R): I_c = n·F_c = c + 1; lookups renormalise by a float weight sum (2ε). */
  CHECK_STATUS(prt_fiv_scene_shade(scene, p, n, 1, NULL, out), PRT_OK);
  for (c = 0; c < 3; ++c) CHECK_NEAR(out[c], 10.0 - (c + 1), 4 * FLT_EPSILON * 10, "one occluder");
  /* The same occluder twice: overlap O = ½ → E_tot − I; without the correction E_tot − 2I. */
  shells[7] = NAN; /* non-finite shells are refused */
  CHECK_STATUS(prt_fiv_scene_add_occluder(scene, &desc, &index), PRT_ERROR_INVALID_ARGUMENT);
  for (i = 0; i < NR * NT * NP * 9; ++i) shells[i] = (i % 3 == 1) ? (float)(1 + (i % 9) / 3) : 0.0f;
  CHECK_STATUS(prt_fiv_scene_add_occluder(scene, &desc, &index), PRT_OK);
  CHECK_STATUS(prt_fiv_scene_occluder_count(scene, &count), PRT_OK);
  if (count != 2) return fail(msg, size, "occluder count", count, 2);
  CHECK_STATUS(prt_fiv_scene_shade(scene, p, n, 2, NULL, two_out), PRT_OK);
  for (c = 0; c < 3; ++c) CHECK_NEAR(two_out[3 + c], 10.0 - (c + 1), 4 * FLT_EPSILON * 10, "identical pair, corrected");
  CHECK_STATUS(prt_fiv_scene_shade(scene, p, n, 1, &no_overlap, out), PRT_OK);
  for (c = 0; c < 3; ++c) CHECK_NEAR(out[c], 10.0 - 2 * (c + 1), 4 * FLT_EPSILON * 10, "identical pair, uncorrected");
  /* Move occluder 1 below the horizon (case C): only occluder 0 remains. */
  {
    const float below[3] = {0, -5, 0};
    CHECK_STATUS(prt_fiv_scene_set_centre(scene, 1, below), PRT_OK);
    CHECK_STATUS(prt_fiv_scene_occluded_irradiance(scene, 1, p, n, 1, out), PRT_OK);
    for (c = 0; c < 3; ++c) CHECK_NEAR(out[c], 0.0, 0.0, "case C");
    CHECK_STATUS(prt_fiv_scene_shade(scene, p, n, 1, NULL, out), PRT_OK);
    for (c = 0; c < 3; ++c) CHECK_NEAR(out[c], 10.0 - (c + 1), 4 * FLT_EPSILON * 10, "case C ignored");
    CHECK_STATUS(prt_fiv_scene_set_centre(scene, 2, below), PRT_ERROR_INVALID_ARGUMENT);
  }
  /* Self-shadows on occluder 0: n·F^env − n·F = 3(c+1) − (c+1). */
  CHECK_STATUS(prt_fiv_scene_shade_self(scene, 0, p, n, 1, out), PRT_OK);
  for (c = 0; c < 3; ++c) CHECK_NEAR(out[c], 2.0 * (c + 1), 4 * FLT_EPSILON * 10, "self-shadow");
  CHECK_STATUS(prt_fiv_scene_lookup_fiv(scene, 0, p, out), PRT_OK);
  CHECK_NEAR(out[4], 2.0, 2 * FLT_EPSILON * 2, "lookup_fiv F_G,y");
  CHECK_STATUS(prt_fiv_scene_lookup_fiv(scene, 5, p, out), PRT_ERROR_INVALID_ARGUMENT);
  /* Broken occluders are refused with a message. */
  desc.radius = 0.0f;
  CHECK_STATUS(prt_fiv_scene_add_occluder(scene, &desc, NULL), PRT_ERROR_INVALID_ARGUMENT);
  if (strstr(prt_last_error(), "radius") == NULL) return fail(msg, size, "message names the radius", 0, 0);
  desc.radius = 1.0f;
  desc.n_theta = 1;
  CHECK_STATUS(prt_fiv_scene_add_occluder(scene, &desc, NULL), PRT_ERROR_INVALID_ARGUMENT);
  desc.n_theta = NT;
  /* Surface-following shells (radial_scheme 1): radii are offsets from surface_radius, no valid
   * mask needed; the scene copies surface_radius too. Constant shells: the same F anywhere. */
  {
    static float surface[NT * NP];
    for (i = 0; i < NT * NP; ++i) surface[i] = 0.5f;
    desc.radial_scheme = 1, desc.surface_radius = surface, desc.valid = NULL;
    CHECK_STATUS(prt_fiv_scene_add_occluder(scene, &desc, &index), PRT_OK);
    for (i = 0; i < NT * NP; ++i) surface[i] = -1.0f; /* would be refused: the copy is used */
    CHECK_STATUS(prt_fiv_scene_lookup_fiv(scene, index, p, out), PRT_OK);
    CHECK_NEAR(out[4], 2.0, 2 * FLT_EPSILON * 2, "surface scheme lookup_fiv F_G,y");
    CHECK_STATUS(prt_fiv_scene_add_occluder(scene, &desc, NULL), PRT_ERROR_INVALID_ARGUMENT);
    desc.radial_scheme = 2;
    CHECK_STATUS(prt_fiv_scene_add_occluder(scene, &desc, NULL), PRT_ERROR_INVALID_ARGUMENT);
  }
  prt_fiv_scene_destroy(scene);
  return 0;
}

/* The baked lights' shading (emission · E, area and punctual alike), an unshadowed punctual light
 * against its closed forms, and LTC GGX over a polygon (a tight lobe inside a wide light: its
 * albedo), with their argument errors. */
int prt_c_check_lights(char* msg, size_t size) {
  const float E[4] = {0.5f, 0.25f, 1.0f, 0.0f}; /* [2 receivers][2 lights] */
  const float emission[6] = {10, 10, 10, 4, 2, 0};
  const float grey[3] = {0.5f, 0.5f, 0.5f};
  float out[6];
  CHECK_STATUS(prt_shade_lights(E, 2, 2, emission, grey, 0, out), PRT_OK);
  /* float sums of a few terms: 1e-6 relative */
  CHECK_NEAR(out[0], 0.5 / PI * (10 * 0.5 + 4 * 0.25), 1e-6, "shade_lights r of receiver 0");
  CHECK_NEAR(out[2], 0.5 / PI * (10 * 0.5), 1e-6, "shade_lights b of receiver 0");
  CHECK_NEAR(out[4], 0.5 / PI * 10, 1e-6, "shade_lights g of receiver 1");
  const float bad_emission[6] = {10, 10, 10, -1, 0, 0};
  CHECK_STATUS(prt_shade_lights(E, 2, 2, bad_emission, grey, 0, out), PRT_ERROR_INVALID_ARGUMENT);

  const float origin[3] = {0, 0, 0}, up[3] = {0, 0, 1}, side[3] = {2, 0, 0};
  prt_punctual_light light = {PRT_PUNCTUAL_POINT, {0, 0, 2}, {0, 0, -1}, 0.2f, 0.6f, 0.0f};
  float e = -1;
  CHECK_STATUS(prt_punctual_irradiance(&light, origin, up, &e), PRT_OK);
  CHECK_NEAR(e, 0.25, 1e-7, "point light: cos/d^2");
  light.range = 4.0f; /* KHR's window at d = 2: 1 - (2/4)^4 = 15/16 */
  CHECK_STATUS(prt_punctual_irradiance(&light, origin, up, &e), PRT_OK);
  CHECK_NEAR(e, 0.25 * 15 / 16, 1e-7, "point light with a range: the window");
  light.range = 2.0f;
  CHECK_STATUS(prt_punctual_irradiance(&light, origin, up, &e), PRT_OK);
  CHECK_NEAR(e, 0.0, 0.0, "point light at its range: 0");
  light.range = -1.0f;
  CHECK_STATUS(prt_punctual_irradiance(&light, origin, up, &e), PRT_ERROR_INVALID_ARGUMENT);
  light.range = 0.0f;
  light.kind = PRT_PUNCTUAL_SPOT;
  CHECK_STATUS(prt_punctual_irradiance(&light, origin, up, &e), PRT_OK);
  CHECK_NEAR(e, 0.25, 1e-7, "spot on its axis");
  CHECK_STATUS(prt_punctual_irradiance(&light, side, up, &e), PRT_OK);
  CHECK_NEAR(e, 0.0, 0.0, "spot outside its outer cone");
  light.kind = PRT_PUNCTUAL_DIRECTIONAL;
  CHECK_STATUS(prt_punctual_irradiance(&light, side, up, &e), PRT_OK);
  CHECK_NEAR(e, 1.0, 1e-7, "directional straight down");
  light.range = 5.0f;
  CHECK_STATUS(prt_punctual_irradiance(&light, side, up, &e), PRT_ERROR_INVALID_ARGUMENT);
  light.range = 0.0f;
  light.kind = PRT_PUNCTUAL_SPOT;
  light.inner_cone_angle = 0.7f;
  CHECK_STATUS(prt_punctual_irradiance(&light, origin, up, &e), PRT_ERROR_INVALID_ARGUMENT);

  /* A square light spanning 45 degrees about n on every side; v = n, alpha 0.05: the lobe lies in
   * it, so the integral is the lobe's albedo at normal incidence (the table's A, near 1). */
  const float arcs[24] = {-1, -1, 1, 1, -1, 1, 1, -1, 1, 1, 1, 1, 1, 1, 1, -1, 1, 1, -1, 1, 1, -1, -1, 1};
  float g = -1, bound = -1;
  CHECK_STATUS(prt_ltc_ggx(up, up, 0.05f, 1.0f, arcs, 4, &g), PRT_OK);
  CHECK_STATUS(prt_ltc_ggx_error_bound(0.05f, 1.0f, 1.0f, &bound), PRT_OK);
  if (!(bound > 0 && bound < 0.2)) return fail(msg, size, "LTC error bound", bound, 0.05);
  if (!(g > 0.85 && g <= 1.0 + bound)) return fail(msg, size, "LTC GGX over a wide light, alpha 0.05", g, 1.0);
  const float below[6] = {1, 0, -0.5f, 0, 1, 0.5f};
  CHECK_STATUS(prt_ltc_ggx(up, up, 0.05f, 1.0f, below, 1, &g), PRT_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(prt_ltc_ggx(up, up, 0.0f, 1.0f, arcs, 4, &g), PRT_ERROR_INVALID_ARGUMENT);
  return 0;
}
