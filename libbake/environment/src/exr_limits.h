// exr_limits.h — the largest environment image libbake builds, shared by the EXR reader's checks
// (exr_file.cpp) and the in-memory constructors (envmap.cpp). Private to the environment module.
#pragma once

#include <cstdint>

namespace prt::bake {

// Largest image we accept (pixels): 2^27, the largest common maps (16k × 8k lat-long); the RGB
// float buffer, the largest single allocation, is then 1.5 GiB (docs/RELIABILITY.md: no single
// allocation over 2 GiB); ~40 bytes per texel once built. A header's size is also bounded by its
// file (max_compression_ratio).
inline constexpr int64_t kMaxPixels = int64_t(1) << 27;

} // namespace prt::bake
