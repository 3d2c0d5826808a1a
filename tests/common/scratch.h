// scratch.h — scratch directories for tests that write files: a fresh empty one per test, and
// what a directory holds (to check that nothing but the expected output was left behind).
#pragma once

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

namespace prt::testing {

// PRT_TEST_TMP/<group>/<name>, emptied.
inline std::filesystem::path fresh_dir(const std::string& group, const std::string& name) {
  const std::filesystem::path d = std::filesystem::path(PRT_TEST_TMP) / group / name;
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

// The names in `dir`, sorted (hidden ones too).
inline std::vector<std::string> listing(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

} // namespace prt::testing
