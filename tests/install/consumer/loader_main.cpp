// A downstream program of the installed loader (prtshade::prtshade_hdf5): reads a file that the
// installed prtbake baked (argv[1], an AO bake of argv[2] vertices) and a missing file.
// Prints "prtshade loader consumer: ok".
#include <prtshade/loader.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::printf("usage: prtshade_loader_consumer FILE.prt.h5 VERTICES\n");
    return 2;
  }
  const std::size_t vertices = std::strtoul(argv[2], nullptr, 10);
  int failures = 0;
  auto fail = [&](const std::string& what) {
    std::printf("FAIL %s\n", what.c_str());
    ++failures;
  };
  const prt::shade::LoadedAsset asset = prt::shade::load_prt(argv[1]);
  const prt::shade::LoadedVertexSet* root = asset.find_vertex_set("");
  if (!root) {
    fail("no root vertex set");
  } else {
    if (root->vertex_count() != vertices)
      fail("vertices: " + std::to_string(root->vertex_count()) + " vs " + std::to_string(vertices));
    if (root->ao.size() != vertices) fail("ao has " + std::to_string(root->ao.size()) + " values");
    for (float a : root->ao)
      if (!(a >= 0.0f && a <= 1.0f)) {
        fail("ao value " + std::to_string(a) + " outside [0, 1]");
        break;
      }
  }
  try {
    (void)prt::shade::load_prt(std::string(argv[1]) + ".missing");
    fail("a missing file loaded");
  } catch (const prt::formats::FormatError& e) {
    std::printf("missing file: %s\n", e.what());
  }
  std::printf("format_version %lld, %zu vertex set(s)\n", static_cast<long long>(asset.format_version),
              asset.vertex_sets.size());
  if (failures == 0) std::printf("prtshade loader consumer: ok\n");
  return failures == 0 ? 0 : 1;
}
