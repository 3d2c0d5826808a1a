// choose_internal.h — what the target-error chooser (choose.cpp) and the target check
// (target_check.cpp) share: integrating pilot rows, errors in the target's units, ray rounding.
// Private to the bake module; the contracts are bake/bake/choose.h's.
#pragma once

#include <bake/core/progress.h>
#include <bake/integrators/integrator.h>
#include <bake/integrators/products.h>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace prt::bake::choose_internal {

// kMaxRays: rays per point of any QMC plan. 2^26 (67M; ~34 CPU s per point at ~0.5 µs per ray)
// is no practical bound — the extrapolation limit (4× the last measured level) and the report's
// ray budget bind first; it keeps R·points and the rounding inside 64-bit and 32-bit arithmetic.
inline constexpr uint32_t kMinRays = 16, kMaxRays = 1u << 26;
inline constexpr uint64_t kProbeSalt = 0x70726f6265736565ull;  // the report probe's coarse run, apart from the reference

// Radiance products (R, S) carry the environment's HDR scale: their errors are relative to their RMS.
bool is_radiance(Product p);

// Rows of one integrator at the pilot points, and the mean CPU time per integral.
struct Rows {
  std::vector<double> values;
  std::vector<double> std_error;  // the integrator's estimated standard errors (0: deterministic)
  double cpu_us_per_point = 0;
};

// The integrator's rows at points[sample[i]] (point index sample[i] + index_offset), in parallel;
// `progress` advances once per point.
Rows integrate_pilot(const Integrator& integrator, std::span<const ShadePoint> points,
                     const std::vector<uint32_t>& sample, Task& progress, uint64_t index_offset = 0);

// Per product: RMSE of `rows` against `ref` in the target's units: relative for R and S, to
// scale[p] when given (> 0; the product's RMS over the mesh, estimated), else to ref's RMS.
std::vector<double> pilot_errors(const std::vector<double>& rows, const std::vector<double>& ref, size_t W,
                                 const std::vector<ProductSlice>& products, const std::vector<double>* scale = nullptr);
// Per product: the RMS of `std_error` in the target's units (like pilot_errors).
std::vector<double> pilot_noise(const std::vector<double>& std_error, const std::vector<double>& ref, size_t W,
                                const std::vector<ProductSlice>& products, const std::vector<double>* scale = nullptr);

// Rays for a need of `need`, rounded up to an eighth of an octave, within [kMinRays, kMaxRays].
uint32_t round_up_rays(double need);

// snprintf into a string (at most 255 characters).
std::string format(const char* fmt, double a, double b = 0, double c = 0, double d = 0);

} // namespace prt::bake::choose_internal
