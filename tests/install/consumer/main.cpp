// A downstream program of the installed prtshade: the C++ API and the C API on one white
// furnace (constant radiance L): projection gives y00 = L √(4π), the unoccluded transfer then
// shades to L, and band-1 shading of the uniform sky gives π L. Prints "prtshade consumer: ok".
#include <prtshade/fiv.h>
#include <prtshade/prtshade.h>
#include <prtshade/sh.h>
#include <prtshade/shade.h>

#include <cfloat>
#include <cmath>
#include <cstdio>
#include <vector>

int main() {
  const double pi = 3.14159265358979323846;
  int failures = 0;
  auto check = [&](const char* what, double got, double want, double tol) {
    if (!(std::fabs(got - want) <= tol)) {
      std::printf("FAIL %s: %.9g vs %.9g\n", what, got, want);
      ++failures;
    }
  };
  const int w = 16, h = 9, order = 3, n = order * order;
  std::vector<float> img(size_t(w * h * 3), 2.0f), light(size_t(3 * n)), light_c(size_t(3 * n));
  prt::shade::project_latlong(img.data(), w, h, order, light.data());
  // Solid angles sum to 4π: one float rounding.
  check("C++ y00", light[0], 2.0 * std::sqrt(4 * pi), 4 * FLT_EPSILON * 8);
  if (prt_project_latlong(img.data(), w, h, order, light_c.data(), light_c.size()) != PRT_OK) {
    std::printf("FAIL C projection: %s\n", prt_last_error());
    ++failures;
  }
  for (int i = 0; i < 3 * n; ++i) check("C == C++", light_c[size_t(i)], light[size_t(i)], 0.0);  // the same code
  // Exact constant lighting and the unoccluded n = +z transfer: Σ T L = L.
  std::vector<float> exact(size_t(3 * n), 0.0f), t(size_t(n), 0.0f);
  for (int c = 0; c < 3; ++c) exact[size_t(c * n)] = float(2.0 * std::sqrt(4 * pi));
  t[0] = float(0.5 / std::sqrt(pi));
  t[2] = float(std::sqrt(3.0) / (3 * std::sqrt(pi)));
  t[6] = float(std::sqrt(5.0) / (8 * std::sqrt(pi)));
  float e[3];
  prt::shade::shade_transfer(t.data(), order, exact.data(), e);
  check("transfer white furnace", e[0], 2.0, 8 * FLT_EPSILON);
  // Band-1 uniform sky, n = +z: R_0 = L √(3/4π) π, so E = π L.
  const float nz[3] = {0, 0, 1};
  float R[9] = {};
  for (int c = 0; c < 3; ++c) R[3 * c + 1] = float(2.0 * prt::sh::kBand1Scale * pi);
  float e1[3];
  if (prt_shade_band1(nz, R, 1, e1) != PRT_OK) ++failures;
  check("band-1 uniform sky", e1[1], 2.0 * pi, 8 * FLT_EPSILON * 2 * pi);
  std::printf("prtshade version %s\n", prt_version());
  if (failures == 0) std::printf("prtshade consumer: ok\n");
  return failures == 0 ? 0 : 1;
}
