// bench/sky_exr.cpp — a two-tone lat-long environment (OpenEXR, written by view::write_exr):
// constant radiance SKY above the horizon and GROUND below it, for bench/figures.sh's paper-kind
// FIV scenes (paper 004 Fig. 15: an overcast sky, the overlap correction's own assumption of
// uniform radiance; Fig. 17: a bright ground, where light from below a receiver's horizon matters).
//
//   sky_exr OUT.exr SKY_R,SKY_G,SKY_B GROUND_R,GROUND_G,GROUND_B [WIDTH HEIGHT]   (default 128 64)
//
// Rows follow the project's lat-long convention (formats/SCHEMA.md "environment": the first row at
// +Y, the last at −Y, texel centres at integer rows); rows whose centre lies below the equator are
// ground.
#include <view/image.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace {

bool parse_rgb(const char* text, std::array<float, 3>& out) {
  char* end = nullptr;
  const char* p = text;
  for (int c = 0; c < 3; ++c) {
    out[size_t(c)] = std::strtof(p, &end);
    if (end == p || !std::isfinite(out[size_t(c)]) || out[size_t(c)] < 0) return false;
    p = end;
    if (c < 2) {
      if (*p != ',') return false;
      ++p;
    }
  }
  return *p == '\0';
}

} // namespace

int main(int argc, char** argv) {
  std::array<float, 3> sky{}, ground{};
  int width = 128, height = 64;
  if ((argc != 4 && argc != 6) || !parse_rgb(argv[2], sky) || !parse_rgb(argv[3], ground) ||
      (argc == 6 && ((width = std::atoi(argv[4])) < 2 || (height = std::atoi(argv[5])) < 2))) {
    std::fprintf(stderr, "usage: sky_exr OUT.exr SKY_R,SKY_G,SKY_B GROUND_R,GROUND_G,GROUND_B [WIDTH HEIGHT]\n"
                         "  (radiances finite and >= 0; WIDTH, HEIGHT >= 2)\n");
    return 2;
  }
  prt::view::Image image(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const std::array<float, 3>& v = 2 * y > height - 1 ? ground : sky;  // centre below the equator: ground
      float* px = image.at(x, y);
      for (int c = 0; c < 3; ++c) px[c] = v[size_t(c)];
    }
  prt::view::write_exr(argv[1], image);
  return 0;
}
