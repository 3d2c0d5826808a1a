// view/exposure.h — the exposure of prtview's 8-bit pictures, fixed by what is lit and never by
// the pixels of one render: the same file and environment give the same exposure alone, in a
// triptych, under any camera and any --size, so two pictures can be compared by eye. Tone map:
// view/image.h (8-bit value = sRGB(exposure · linear value)); layers: docs/ARCHITECTURE.md §2.
//
// ENVIRONMENT EXPOSURE (environment_exposure). The pictures show E/π of a white diffuse surface
// (view/image.h). The brightest such surface nothing shadows faces the brightest part of the
// sky: B = max over unit normals n of Y(E_unocc(n)) / π, with E_unocc the exact unshadowed
// irradiance (bake/environment/irradiance.h) and Y the Rec. 709 luminance 0.2126 R + 0.7152 G + 0.0722 B
// (as view/image.h auto_exposure). The exposure is 1 / B rounded to 4 significant digits (the
// printed number is the one used): an unshadowed white surface turned to the light is white,
// everything shadowed or turned away is darker, nothing diffuse and white clips. A constant sky
// of radiance L gives B = L (a white sky: exposure 1, the AO picture as it is).
// The maximum: E_unocc at 256 normals of a spherical Fibonacci lattice (about 13° apart), then a
// compass search from the best one (8 tangent directions, step 0.1 rad halved down to 1e-3 rad,
// where 1 − cos is 5e-7): a few hundred evaluations, a fraction of a second. E_unocc is a
// clamped-cosine blur of the sky, smooth and with its peak towards the brightest light, so the
// lattice's best normal lies on the slope of the global maximum. Deterministic: the same
// environment gives the same bits.
#pragma once

#include <bake/environment/envmap.h>

#include <Eigen/Core>

namespace prt::view {

struct EnvironmentExposure {
  double exposure = 1;     // 1 / brightest, rounded to 4 significant digits
  double brightest = 1;    // B = max_n Y(E_unocc(n)) / π
  Eigen::Vector3d normal{0, 1, 0};  // where B is reached (the environment's frame)
};
EnvironmentExposure environment_exposure(const bake::EnvMap& env);

// x rounded to `digits` significant decimal digits (x > 0 finite; digits in [1, 17]).
double round_significant(double x, int digits);

} // namespace prt::view
