// tests/fuzz/fuzz_capi.cpp — libFuzzer target of prtshade's C API (prtshade/prtshade.h): the input
// is decoded (FuzzedDataProvider) into a sequence of calls with orders, sizes, counts, indices,
// null pointers and array contents taken from the input, against one SH rotation and one FIV
// scene that the sequence creates, grows and destroys. What is checked, per call, is the C
// contract (prtshade.h "Contract"):
//   * it returns PRT_OK or PRT_ERROR_INVALID_ARGUMENT (out of memory and internal errors are
//     findings: the sizes here are small), and never crashes or reads past an array: every array
//     is allocated with exactly the floats the contract says the call may read (ASan checks);
//   * on an error, the outputs are untouched (they hold a sentinel) and prt_last_error() is a
//     non-empty string;
//   * on success, the outputs are finite when every input was finite and moderate (|x| <= 1e6);
//     for the FIV calls (prtshade/fiv.h "Numerics": every output is finite for finite inputs)
//     whenever every input was finite.
// Sizes are kept small (at most kCap floats per array), so that an array the contract says the
// call reads can always be allocated; an array whose size the caller cannot tell the library
// (shells, radii, transfer rows, lat-long pixels) is allocated for the sizes actually passed
// (a call whose sizes the library would accept but that need more than kCap floats is not
// made: the caller would be lying about its arrays), or is a single float when those sizes are
// not positive (the call must then refuse before reading).
#include "fuzz_common.h"

#include <prtshade/prtshade.h>

#include <fuzzer/FuzzedDataProvider.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

namespace {

constexpr float kSentinel = 12345.f;

// Per-call facts about the inputs the call saw.
struct Taint {
  bool nonfinite = false;  // a NaN or an infinity
  bool huge = false;       // a finite value beyond 1e6 in magnitude
  void add(const Taint& t) { nonfinite |= t.nonfinite, huge |= t.huge; }
};

class Program {
public:
  explicit Program(FuzzedDataProvider& in) : in_(in) {}
  ~Program() {
    prt_sh_rotation_destroy(rotation_);
    prt_fiv_scene_destroy(scene_);
  }
  void run();

private:
  FuzzedDataProvider& in_;
  prt_sh_rotation* rotation_ = nullptr;
  int rotation_order_ = 0;
  prt_fiv_scene* scene_ = nullptr;
  Taint scene_taint_;  // of everything the scene holds
  Taint call_;         // of the current call's inputs

  float value();
  double number();
  std::vector<float> floats(size_t n);
  int small_int(int lo, int hi);
  // Mostly small orders (a call at order 64 costs up to ~10^7 operations), now and then any.
  int order() { return in_.ConsumeIntegralInRange<int>(0, 7) == 0 ? small_int(-1, 66) : small_int(-1, 9); }
  size_t count(size_t max) { return in_.ConsumeIntegralInRange<size_t>(0, max); }
  bool null_pointer() { return in_.ConsumeIntegralInRange<int>(0, 31) == 0; }
  template <class T> T* maybe_null(std::vector<T>& v) { return null_pointer() ? nullptr : v.data(); }
  // Checks one call's result against the contract; `outputs` are the arrays it may write.
  void check(const char* call, prt_status status, std::initializer_list<const std::vector<float>*> outputs,
             bool fiv = false);

  void sh_eval();
  void rotation_create();
  void rotation_apply();
  void project_latlong();
  void shade_transfer();
  void shade_band1();
  void scene_create();
  void add_occluder();
  void set_centre();
  void scene_queries();
  void scene_shade();
};

float Program::value() {
  const int kind = in_.ConsumeIntegralInRange<int>(0, 63);
  if (kind < 56) return static_cast<float>(in_.ConsumeIntegralInRange<int>(-64, 64)) / 16.f;  // moderate
  switch (kind) {
  case 56: call_.nonfinite = true; return std::numeric_limits<float>::quiet_NaN();
  case 57: call_.nonfinite = true; return std::numeric_limits<float>::infinity();
  case 58: call_.nonfinite = true; return -std::numeric_limits<float>::infinity();
  case 59: call_.huge = true; return std::numeric_limits<float>::max();
  case 60: call_.huge = true; return -1e30f;
  case 61: return std::numeric_limits<float>::denorm_min();
  case 62: return -0.f;
  default: {
    const float f = in_.ConsumeFloatingPoint<float>();  // anything
    if (!std::isfinite(f)) call_.nonfinite = true;
    else if (std::fabs(f) > 1e6f) call_.huge = true;
    return f;
  }
  }
}

double Program::number() { return static_cast<double>(value()); }

std::vector<float> Program::floats(size_t n) {
  std::vector<float> v(n);
  for (float& x : v) x = value();
  return v;
}

int Program::small_int(int lo, int hi) {
  if (in_.ConsumeIntegralInRange<int>(0, 31) == 0)  // now and then any int
    return in_.ConsumeIntegral<int>();
  return in_.ConsumeIntegralInRange<int>(lo, hi);
}

constexpr double kCap = 1 << 17;
// Elements of an array of n (a product of the sizes passed, in double: no overflow) when n is
// positive, else one (the call must refuse those sizes before it reads). Callers skip the call
// when n > kCap.
size_t array_size(double n) { return n > 0 && n <= kCap ? static_cast<size_t>(n) : 1; }
bool too_big(double n) { return n > kCap; }

void Program::check(const char* call, prt_status status, std::initializer_list<const std::vector<float>*> outputs,
                    bool fiv) {
  if (!prt_status_string(status)) prt::fuzz::finding("prt_status_string returned NULL", nullptr);
  if (status == PRT_OK) {
    const bool must_be_finite = !call_.nonfinite && (fiv || !call_.huge);
    if (!must_be_finite) return;
    for (const std::vector<float>* out : outputs)
      for (float x : *out)
        if (!std::isfinite(x)) {
          std::fprintf(stderr, "%s returned PRT_OK with a non-finite output for finite inputs\n", call);
          prt::fuzz::finding("non-finite output", nullptr);
        }
    return;
  }
  if (status != PRT_ERROR_INVALID_ARGUMENT) {
    std::fprintf(stderr, "%s: status %d (%s): %s\n", call, status, prt_status_string(status), prt_last_error());
    prt::fuzz::finding("status other than PRT_OK / PRT_ERROR_INVALID_ARGUMENT", nullptr);
  }
  const char* message = prt_last_error();
  if (!message || !*message) {
    std::fprintf(stderr, "%s failed without a message\n", call);
    prt::fuzz::finding("empty prt_last_error after an error", nullptr);
  }
  for (const std::vector<float>* out : outputs)
    for (float x : *out)
      if (x != kSentinel) {
        std::fprintf(stderr, "%s failed (%s) but wrote its output\n", call, message);
        prt::fuzz::finding("output written on error", nullptr);
      }
}

void Program::sh_eval() {
  const int l = order();
  const float x = value(), y = value(), z = value();
  const size_t n = l >= 0 && l <= 64 ? static_cast<size_t>(l * l) : 0;
  std::vector<float> out(array_size(static_cast<double>(n + count(2))), kSentinel);
  const size_t out_count = in_.ConsumeBool() ? out.size() : count(out.size());
  // A direction that is not unit is the caller's choice; the contract only promises finite
  // outputs for unit ones, so those are the only ones checked for finiteness.
  const float norm2 = x * x + y * y + z * z;
  if (!(std::fabs(norm2 - 1.f) < 1e-3f)) call_.huge = true;
  check("prt_sh_eval", prt_sh_eval(l, x, y, z, maybe_null(out), out_count), {&out});
}

void Program::rotation_create() {
  double r[9];
  if (in_.ConsumeBool()) {  // a proper rotation from a quaternion
    double q[4], n = 0;
    for (double& c : q) {
      c = number();
      n += c * c;
    }
    n = std::sqrt(n);
    if (!(n > 1e-3) || !std::isfinite(n)) q[0] = 1, q[1] = q[2] = q[3] = 0, n = 1;
    for (double& c : q) c /= n;
    const double w = q[0], x = q[1], y = q[2], z = q[3];
    const double m[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
                         2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                         2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
    std::memcpy(r, m, sizeof r);
  } else {
    for (double& c : r) c = number();
  }
  const int l = order();
  prt_sh_rotation* made = nullptr;
  const prt_status status = prt_sh_rotation_create(null_pointer() ? nullptr : r, l, null_pointer() ? nullptr : &made);
  check("prt_sh_rotation_create", status, {});
  if (status == PRT_OK) {
    if (!made) prt::fuzz::finding("prt_sh_rotation_create: PRT_OK without a rotation", nullptr);
    prt_sh_rotation_destroy(rotation_);
    rotation_ = made, rotation_order_ = l;
  } else if (made) {
    prt::fuzz::finding("prt_sh_rotation_create: an error that wrote *out", nullptr);
  }
}

void Program::rotation_apply() {
  const int channels = small_int(-1, 4);
  const double need = channels >= 0 ? double(channels) * rotation_order_ * rotation_order_ : 0;
  const size_t n = array_size(need + double(count(2)) - 1);  // the count is passed: any size is fair
  std::vector<float> in = floats(n);
  std::vector<float> out(n, kSentinel);
  const size_t count_arg = in_.ConsumeBool() ? n : count(n);
  check("prt_sh_rotation_apply",
        prt_sh_rotation_apply(null_pointer() ? nullptr : rotation_, maybe_null(in), maybe_null(out), channels, count_arg),
        {&out});
}

void Program::project_latlong() {
  const int w = small_int(-1, 24), h = small_int(-1, 24), l = order();
  const double pixels = w > 0 && h > 0 ? 3.0 * w * h : 0;
  if (too_big(pixels)) return;
  std::vector<float> rgb = floats(array_size(pixels));
  const size_t n = l >= 1 && l <= 64 ? static_cast<size_t>(3 * l * l) : 1;
  std::vector<float> out(array_size(double(n + count(2))), kSentinel);
  const size_t out_count = in_.ConsumeBool() ? out.size() : count(out.size());
  check("prt_project_latlong", prt_project_latlong(maybe_null(rgb), w, h, l, maybe_null(out), out_count), {&out});
}

void Program::shade_transfer() {
  const int l = order();
  const size_t vertices = count(16);
  const double n = l >= 0 && l <= 64 ? double(l) * l : 0;  // an order outside [0, 64] must be refused
  std::vector<float> transfer = floats(array_size(double(vertices) * n));
  std::vector<float> light = floats(array_size(3 * n));
  std::vector<float> out(array_size(3.0 * double(vertices)), kSentinel);
  check("prt_shade_transfer", prt_shade_transfer(maybe_null(transfer), vertices, l, maybe_null(light), maybe_null(out)), {&out});
}

void Program::shade_band1() {
  const size_t vertices = count(16);
  std::vector<float> normals = floats(array_size(3.0 * double(vertices)));
  std::vector<float> radiance = floats(array_size(9.0 * double(vertices)));
  std::vector<float> out(array_size(3.0 * double(vertices)), kSentinel);
  check("prt_shade_band1", prt_shade_band1(maybe_null(normals), maybe_null(radiance), vertices, maybe_null(out)), {&out});
}

void Program::scene_create() {
  const int size = small_int(-1, 6);
  const double texel_floats = size > 0 ? 18.0 * size * size : 0;
  if (too_big(texel_floats)) return;
  std::vector<float> texels = floats(array_size(texel_floats));
  std::vector<float> environment = floats(9);
  prt_fiv_scene* made = nullptr;
  const prt_status status =
      prt_fiv_scene_create(size, maybe_null(texels), maybe_null(environment), null_pointer() ? nullptr : &made);
  check("prt_fiv_scene_create", status, {}, true);
  if (status == PRT_OK) {
    if (!made) prt::fuzz::finding("prt_fiv_scene_create: PRT_OK without a scene", nullptr);
    prt_fiv_scene_destroy(scene_);
    scene_ = made;
    scene_taint_ = call_;
  } else if (made) {
    prt::fuzz::finding("prt_fiv_scene_create: an error that wrote *out", nullptr);
  }
}

void Program::add_occluder() {
  prt_fiv_occluder_desc d{};
  for (float& c : d.centre) c = value();
  d.radius = value();
  d.n_rho = small_int(-1, 4), d.n_theta = small_int(-1, 5), d.n_phi = small_int(-1, 5);
  // Sizes as the library may read them before it refuses a non-positive one: |product|.
  const double cells = std::fabs(double(d.n_rho) * d.n_theta * d.n_phi);
  if (too_big(std::fabs(double(d.n_rho))) || too_big(9 * cells)) return;
  std::vector<float> radii = floats(array_size(std::fabs(double(d.n_rho))));
  if (in_.ConsumeBool()) {  // usually increasing and positive, as a bake writes them
    float r = std::fabs(d.radius);
    for (float& x : radii) x = (r += 0.5f + std::fabs(x));
  }
  std::vector<float> shells = floats(array_size(cells * 9));
  std::vector<uint8_t> valid(array_size(cells));
  for (uint8_t& v : valid) v = in_.ConsumeIntegralInRange<uint8_t>(0, 2);
  d.radii = maybe_null(radii), d.shells = maybe_null(shells), d.valid = maybe_null(valid);
  // Sometimes the surface-following scheme (and sometimes a bad scheme): its surface radii.
  std::vector<float> surface;
  if (in_.ConsumeBool()) {
    d.radial_scheme = small_int(-1, 2);
    const double directions = std::fabs(double(d.n_theta) * d.n_phi);
    if (too_big(directions)) return;
    surface = floats(array_size(directions));
    d.surface_radius = maybe_null(surface);
  }
  int index = -7;
  const prt_status status = prt_fiv_scene_add_occluder(null_pointer() ? nullptr : scene_, null_pointer() ? nullptr : &d,
                                                       in_.ConsumeBool() ? &index : nullptr);
  check("prt_fiv_scene_add_occluder", status, {}, true);
  if (status == PRT_OK) scene_taint_.add(call_);
}

void Program::set_centre() {
  const int index = small_int(-1, 4);
  float centre[3] = {value(), value(), value()};
  const prt_status status = prt_fiv_scene_set_centre(null_pointer() ? nullptr : scene_, index, null_pointer() ? nullptr : centre);
  check("prt_fiv_scene_set_centre", status, {}, true);
  if (status == PRT_OK) scene_taint_.add(call_);
}

void Program::scene_queries() {
  call_.add(scene_taint_);
  const prt_fiv_scene* scene = null_pointer() ? nullptr : scene_;
  int occluders = -1;
  check("prt_fiv_scene_occluder_count", prt_fiv_scene_occluder_count(scene, null_pointer() ? nullptr : &occluders), {}, true);
  const int index = small_int(-1, 4);
  std::vector<float> p = floats(3), n = floats(3);
  std::vector<float> out3(3, kSentinel), out9(9, kSentinel);
  switch (in_.ConsumeIntegralInRange<int>(0, 2)) {
  case 0: check("prt_fiv_scene_lookup_difmap", prt_fiv_scene_lookup_difmap(scene, maybe_null(n), maybe_null(out3)), {&out3}, true); break;
  case 1: check("prt_fiv_scene_lookup_fiv", prt_fiv_scene_lookup_fiv(scene, index, maybe_null(p), maybe_null(out9)), {&out9}, true); break;
  default:
    check("prt_fiv_scene_occluded_irradiance",
          prt_fiv_scene_occluded_irradiance(scene, index, maybe_null(p), maybe_null(n), in_.ConsumeBool(), maybe_null(out3)),
          {&out3}, true);
  }
}

void Program::scene_shade() {
  call_.add(scene_taint_);
  const prt_fiv_scene* scene = null_pointer() ? nullptr : scene_;
  const size_t receivers = count(8);
  std::vector<float> p = floats(array_size(3.0 * double(receivers)));
  std::vector<float> n = floats(array_size(3.0 * double(receivers)));
  std::vector<float> out(array_size(3.0 * double(receivers)), kSentinel);
  const std::initializer_list<const std::vector<float>*> outputs{&out};
  const int index = small_int(-1, 4);
  switch (in_.ConsumeIntegralInRange<int>(0, 2)) {
  case 0: {
    prt_fiv_options options{in_.ConsumeBool(), in_.ConsumeBool(), in_.ConsumeBool()};
    check("prt_fiv_scene_shade",
          prt_fiv_scene_shade(scene, maybe_null(p), maybe_null(n), receivers, in_.ConsumeBool() ? &options : nullptr, maybe_null(out)),
          outputs, true);
    break;
  }
  case 1:
    check("prt_fiv_scene_shade_self", prt_fiv_scene_shade_self(scene, index, maybe_null(p), maybe_null(n), receivers, maybe_null(out)),
          outputs, true);
    break;
  default:
    check("prt_fiv_scene_shade_member",
          prt_fiv_scene_shade_member(scene, index, maybe_null(p), maybe_null(n), receivers, in_.ConsumeBool(), maybe_null(out)),
          outputs, true);
  }
}

void Program::run() {
  // At most 64 calls per input: an input's cost stays proportional to its size.
  for (int calls = 0; calls < 64 && in_.remaining_bytes() > 0; ++calls) {
    call_ = {};
    switch (in_.ConsumeIntegralInRange<int>(0, 10)) {
    case 0: sh_eval(); break;
    case 1: rotation_create(); break;
    case 2: rotation_apply(); break;
    case 3: project_latlong(); break;
    case 4: shade_transfer(); break;
    case 5: shade_band1(); break;
    case 6: scene_create(); break;
    case 7: add_occluder(); break;
    case 8: set_centre(); break;
    case 9: scene_queries(); break;
    default: scene_shade(); break;
    }
  }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzedDataProvider in(data, size);
  return prt::fuzz::guarded<>([&] { Program(in).run(); });  // no exception may cross the C API
}
