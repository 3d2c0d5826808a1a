// tests/fuzz/fuzz_prt.cpp — libFuzzer targets of the .prt.h5 readers: the input is a baked file.
//   fuzz_prt_dump    (PRT_FUZZ_LOADER undefined): prtdump's path, formats::inspect_asset (the file
//                    as stored, then the schema check and the typed asset when it passes).
//   fuzz_prt_loader  (PRT_FUZZ_LOADER): the engine-facing loader, prt::shade::load_prt
//                    (formats::read_asset with the full schema check, then the plain arrays),
//                    whose documented layout (prtshade/loader.h) is then checked array by array:
//                    an engine indexes them by those sizes.
// Accepted failure: formats::FormatError. Also a finding: an HDF5 object (file, group, dataset,
// attribute, ...) still open after the reader returned or threw — a handle leak would keep the
// file open inside HDF5 (the next open of the same name could see stale data).
#include "fuzz_common.h"

#include <formats/asset.h>
#include <formats/prtfile.h>
#ifdef PRT_FUZZ_LOADER
#include <prtshade/loader.h>
#endif

#include <hdf5.h>

#include <cstdio>

namespace {

#ifdef PRT_FUZZ_LOADER
void require(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "load_prt returned arrays that break prtshade/loader.h: %s\n", what);
    prt::fuzz::finding("loader layout", nullptr);
  }
}

void check_layout(const prt::shade::LoadedAsset& a) {
  for (const prt::shade::LoadedVertexSet& s : a.vertex_sets) {
    const size_t v = s.vertex_count();
    require(s.positions.size() == 3 * v, "positions [V][3]");
    require(s.normals.empty() || s.normals.size() == 3 * v, "normals [V][3]");
    require(s.triangles.size() % 3 == 0, "triangles [T][3]");
    for (uint32_t i : s.triangles) require(i < v, "triangle index < V");
    require(s.ao.empty() || s.ao.size() == v, "ao [V]");
    const auto sh = [&](int order, const std::vector<float>& values) {
      require(order >= 0 && order <= 64, "sh order in [0, 64]");
      require(order == 0 ? values.empty() : values.size() == v * size_t(order) * size_t(order), "[V][L*L]");
    };
    sh(s.transfer_order, s.transfer);
    sh(s.visibility_order, s.visibility);
    require(s.radiance_band1.empty() || s.radiance_band1.size() == 9 * v, "radiance_band1 [V][3][3]");
  }
  const int cube = a.irradiance_cube_size;
  require(cube >= 0 && a.irradiance_cube.size() == 18 * size_t(cube) * size_t(cube), "irradiance_cube [6][S][S][3]");
  for (const prt::shade::LoadedOccluder& o : a.occluders) {
    const size_t cells = size_t(o.n_rho) * size_t(o.n_theta) * size_t(o.n_phi);
    require(o.n_rho > 0 && o.n_theta > 0 && o.n_phi > 0, "occluder grid sizes > 0");
    // The shells as floats or (a float16 file, v8) as half bits: exactly one of the two.
    require(o.radii.size() == size_t(o.n_rho) && (o.shells.size() == 9 * cells) != (o.shells_half.size() == 9 * cells) &&
                (o.shells.empty() || o.shells_half.empty()),
            "radii [Nrho], shells or shells_half [..][3][3]");
    require((o.cones.empty() || o.cones.size() == 4 * cells) && (o.cones_half.empty() || o.cones_half.size() == 4 * cells) &&
                (o.cones.empty() || o.cones_half.empty()),
            "cones or cones_half [..][4]");
    require(o.valid.empty() || o.valid.size() == cells, "valid [Nrho][Ntheta][Nphi]");
    require(o.radial_scheme == prt::shade::kFivRadialGeometric
                ? o.surface_radius.empty()
                : o.radial_scheme == prt::shade::kFivRadialSurface &&
                      o.surface_radius.size() == size_t(o.n_theta) * size_t(o.n_phi),
            "surface_radius [Ntheta][Nphi] exactly for the surface scheme");
  }
  a.difmap();
  a.occluder_views();
}
#endif

void read(const std::filesystem::path& path) {
#ifdef PRT_FUZZ_LOADER
  check_layout(prt::shade::load_prt(path));
#else
  prt::formats::inspect_asset(path);
#endif
}

} // namespace

// HDF5 keeps freed blocks on its own free lists, so nearly every input ends with fewer frees
// than mallocs and libFuzzer runs a full leak scan after it (a few inputs per second). Without
// the lists HDF5 frees what it is done with: the same leak checks, far faster.
extern "C" int LLVMFuzzerInitialize(int*, char***) {
  H5set_free_list_limits(0, 0, 0, 0, 0, 0);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::filesystem::path path = prt::fuzz::write_input("input.prt.h5", prt::fuzz::as_bytes(data, size));
  prt::fuzz::guarded<prt::formats::FormatError>([&] { read(path); });
  if (const ssize_t open = H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL); open > 0) {
    std::fprintf(stderr, "%zd HDF5 objects still open after the reader returned\n", open);
    prt::fuzz::finding("HDF5 handle leak", nullptr);
  }
  return 0;
}
