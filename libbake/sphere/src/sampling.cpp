// sampling.cpp — seeded index samples (bake/sphere/sampling.h).
#include <bake/sphere/sampling.h>

#include <algorithm>
#include <numeric>

namespace prt::bake {

std::vector<uint32_t> seeded_sample(uint32_t n, size_t k, uint64_t seed) {
  std::vector<uint32_t> idx(n);
  std::iota(idx.begin(), idx.end(), 0u);
  k = std::min<size_t>(k, n);
  for (size_t i = 0; i < k; ++i) {
    const uint64_t r = mix64(seed ^ mix64(i + 0x5851f42d4c957f2dull));
    const size_t j = i + size_t(r % (n - i));
    std::swap(idx[i], idx[j]);
  }
  idx.resize(k);
  std::sort(idx.begin(), idx.end());
  return idx;
}

} // namespace prt::bake
