// shader_test.h — helpers shared by the shader-mirror tests (tests/shaders/test_*.cpp).
//   run_kernel: runs tests/shaders/<name>.comp on the shared Vulkan device; a missing device or
//   a failing Vulkan call is a test FAILURE with the runner's message (never a skip).
//   kFloatEps: 2^-24, the unit roundoff of float (half an ulp of 1): tolerances are stated as
//   multiples of it times the magnitude they scale with.
#pragma once

#include "vk_compute.h"

#include <gtest/gtest.h>

#include <initializer_list>
#include <stdexcept>
#include <string>
#include <vector>

namespace prt::test {

constexpr double kFloatEps = 1.0 / 16777216.0;  // 2^-24

// Runs the kernel; returns false (after recording a failure) when Vulkan is unavailable or fails.
[[nodiscard]] inline bool run_kernel(const std::string& name, std::initializer_list<std::vector<std::byte>*> buffers,
                                     const std::vector<std::byte>& push, uint32_t invocations, uint32_t local_size = 64) {
  try {
    std::vector<std::vector<std::byte>*> list(buffers);
    vk_compute().run(spirv_path(name), list, push, (invocations + local_size - 1) / local_size);
    return true;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "shader kernel " << name << ": " << e.what();
    return false;
  }
}

template <typename T>
std::vector<std::byte> push_bytes(const T& value) {
  std::vector<std::byte> out(sizeof(T));
  std::memcpy(out.data(), &value, sizeof(T));
  return out;
}

} // namespace prt::test
