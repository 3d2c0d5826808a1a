// shader_test.h — helpers shared by the shader-mirror tests (tests/shaders/test_*.cpp).
//   run_kernel: runs the compiled test kernel <name> (kernel_name below) on the shared Vulkan
//   device; a missing device or a failing Vulkan call is a test FAILURE with the runner's message
//   (never a skip).
//   ShaderMirror: the base of the tests that run once per shading language — each test kernel
//   exists as tests/shaders/<name>.comp (GLSL, including runtime/shaders/*.glsl) and
//   tests/shaders/<name>.hlsl (HLSL, including runtime/shaders/*.hlsl) with the same bindings,
//   push constants and outputs, so one test body checks both against the C++ core with the same
//   tolerances. PRT_SHADER_MIRROR_LANGUAGES(Suite) instantiates a TEST_P suite for both; the
//   test names end in /Glsl or /Hlsl.
//   kFloatEps: 2^-24, the unit roundoff of float (half an ulp of 1): tolerances are stated as
//   multiples of it times the magnitude they scale with.
#pragma once

#include "vk_compute.h"

#include <gtest/gtest.h>

#include <initializer_list>
#include <ostream>
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

enum class ShaderLanguage { glsl, hlsl };

// gtest prints the parameter in the test listing as this name.
inline void PrintTo(ShaderLanguage language, std::ostream* os) { *os << (language == ShaderLanguage::hlsl ? "hlsl" : "glsl"); }

// The compiled kernel of tests/shaders/<name>.comp (GLSL) or <name>.hlsl (tests/shaders/CMakeLists.txt
// names the HLSL module <name>_hlsl).
inline std::string kernel_name(const std::string& name, ShaderLanguage language) {
  return language == ShaderLanguage::hlsl ? name + "_hlsl" : name;
}

class ShaderMirror : public testing::TestWithParam<ShaderLanguage> {
protected:
  static std::string kernel(const std::string& name) { return kernel_name(name, GetParam()); }
  static const char* language() { return GetParam() == ShaderLanguage::hlsl ? "HLSL" : "GLSL"; }
};

inline std::string language_test_name(const testing::TestParamInfo<ShaderLanguage>& info) {
  return info.param == ShaderLanguage::hlsl ? "Hlsl" : "Glsl";
}

#define PRT_SHADER_MIRROR_LANGUAGES(suite)                                                                      \
  INSTANTIATE_TEST_SUITE_P(Lang, suite,                                                                         \
                           testing::Values(prt::test::ShaderLanguage::glsl, prt::test::ShaderLanguage::hlsl), \
                           prt::test::language_test_name)

template <typename T>
std::vector<std::byte> push_bytes(const T& value) {
  std::vector<std::byte> out(sizeof(T));
  std::memcpy(out.data(), &value, sizeof(T));
  return out;
}

} // namespace prt::test
