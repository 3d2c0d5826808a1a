// vk_compute.h — the smallest Vulkan compute runner the shader-mirror tests need: one instance,
// one device (a CPU device — Mesa's lavapipe — is preferred, any compute-capable device is
// accepted), host-visible storage buffers, one dispatch, read-back.
//
// Binding model: run() binds buffers[k] as a storage buffer (std430 SSBO) at set 0, binding k,
// and passes `push` as push constants (offset 0, compute stage). Every buffer is copied to the
// device before the dispatch and copied back after it, so any buffer may serve as output.
// Buffer sizes are rounded up to 4 bytes on the device (zero padding); the host vectors keep
// their size.
//
// Errors: any failure (no Vulkan loader/ICD, no device, SPIR-V file missing, a Vulkan call
// failing) throws std::runtime_error naming the call or file and the VkResult. The tests turn
// that into a FAILURE, never a skip: CI installs lavapipe (tools/run.sh PACKAGES).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace prt::test {

class VkCompute {
public:
  // Creates the instance and picks a device. Throws std::runtime_error with a clear message if
  // there is no Vulkan loader, no physical device or no compute queue.
  VkCompute();
  ~VkCompute();
  VkCompute(const VkCompute&) = delete;
  VkCompute& operator=(const VkCompute&) = delete;

  // "<device name> (<device type>, Vulkan <major.minor.patch>)".
  const std::string& device_description() const;
  // Every physical device the loader reported, one description each (the enumeration that
  // replaces vulkaninfo in the tests).
  const std::vector<std::string>& all_devices() const;

  // Loads the SPIR-V module at spv_path (entry point "main"), binds buffers[k] at (set 0,
  // binding k), dispatches (groups_x, 1, 1) work groups and copies every buffer back.
  void run(const std::string& spv_path, std::span<std::vector<std::byte>* const> buffers,
           std::span<const std::byte> push, uint32_t groups_x);

private:
  struct State;
  std::unique_ptr<State> state_;
};

// Shared runner for a test binary (created on first use; throws like the constructor).
VkCompute& vk_compute();

// Path of a test kernel tests/shaders/<name>.comp compiled by glslc at build time
// (tests/shaders/CMakeLists.txt defines PRT_SPIRV_DIR).
inline std::string spirv_path(const std::string& name) { return std::string(PRT_SPIRV_DIR) + "/" + name + ".spv"; }

// Byte views of plain arrays for buffers.
template <typename T>
std::vector<std::byte> to_bytes(const std::vector<T>& v) {
  std::vector<std::byte> out(v.size() * sizeof(T));
  if (!v.empty()) std::memcpy(out.data(), v.data(), out.size());
  return out;
}
template <typename T>
std::vector<T> from_bytes(const std::vector<std::byte>& b) {
  std::vector<T> out(b.size() / sizeof(T));
  if (!out.empty()) std::memcpy(out.data(), b.data(), out.size() * sizeof(T));
  return out;
}

} // namespace prt::test
