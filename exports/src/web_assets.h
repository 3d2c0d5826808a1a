// web_assets.h — the files of the web export (the page, its script, the shading bodies of
// runtime/shaders and three.js), built into the library by viewer/CMakeLists.txt from where npm
// installed three at build time.
#pragma once

#include <cstddef>

namespace prt::exports::detail {

struct WebAsset {
  const char* path;  // in the exported folder, '/'-separated
  const char* begin;
  const char* end;
};
// The files (count 0 and nullptr when the build had no three.js).
const WebAsset* web_assets(size_t& count) noexcept;
// Why there are none (nullptr when there are).
const char* web_assets_missing() noexcept;

} // namespace prt::exports::detail
