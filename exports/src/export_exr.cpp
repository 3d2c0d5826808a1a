// export_exr.cpp — lightmaps as OpenEXR images (contract: exports/export.h; layout:
// formats/SCHEMA.md "Exports", "Lightmaps as EXR"): per vertex set with a lightmap one
// half-float file of W × H pixels, row 0 at v = 0 as in the HDF5 file, one channel per scalar
// of every per-texel row (AO; each SH coefficient of each transfer vector; each colour and
// coefficient of the radiance) plus the state mask (lightmap_channels names them).
#include "export_common.h"

#include <system_error>

namespace prt::exports::detail {

std::vector<std::filesystem::path> export_exr(const Asset& asset, const std::filesystem::path& source,
                                              const std::filesystem::path& out) {
  const std::vector<LightmapRef> maps = lightmap_sets(asset);
  if (maps.empty())
    throw FormatError(source.string(), "has no lightmap (/lightmap/state): EXR lightmaps need a per-texel bake "
                                       "(prtbake texel MESH --resolution N ...); export a per-vertex file --to glb or bin");
  std::error_code ec;
  std::filesystem::path prefix = out;
  if (std::filesystem::is_directory(out, ec)) {
    prefix = out / "lightmap";
  } else if (prefix.extension() == ".exr") {
    prefix.replace_extension();
  }
  if (prefix.filename().empty()) throw FormatError(out.string(), "names no file prefix");
  Staging staging(lightmap_file(prefix, maps.front().set));
  for (const LightmapRef& map : maps) {
    const std::filesystem::path file = lightmap_file(prefix, map.set);
    const std::vector<LightmapChannel> channels = lightmap_channels(*map.lightmap);
    std::vector<ExrChannel> exr;
    for (const LightmapChannel& c : channels) exr.push_back({c.name, &c.values});
    write_exr_half(staging.stage(file), map.lightmap->width, map.lightmap->height, exr, source, map.set, file);
  }
  return staging.commit();
}

} // namespace prt::exports::detail
