// lightmap_images.cpp — what the lightmap exports share: the vertex sets with a lightmap, a
// lightmap's datasets as named float channels, the files' names, and the two image codecs (8-bit
// PNG through libpng, half-float EXR through OpenEXR). Contracts: export_common.h; layouts:
// formats/SCHEMA.md "Exports".
#include "export_common.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <half.h>  // Imath's half (OpenEXR::OpenEXR puts include/Imath on the path)
#include <png.h>

#include <cmath>
#include <exception>

namespace prt::exports::detail {

std::vector<LightmapRef> lightmap_sets(const Asset& asset) {
  std::vector<LightmapRef> out;
  for (const SetRef& ref : vertex_sets(asset))
    if (ref.set->lightmap && ref.set->lightmap->texel_count() > 0) out.push_back({ref, &*ref.set->lightmap});
  return out;
}

std::vector<ProductRef> lightmap_products(const Lightmap& m) {
  const size_t texels = m.texel_count();
  std::vector<ProductRef> out;
  auto width = [&](const std::optional<Product>& p) { return p && texels > 0 ? uint64_t(p->values.size() / texels) : 0; };
  auto add = [&](std::string_view path, const std::optional<Product>& p, std::vector<uint64_t> shape) {
    if (p) out.push_back({std::string(path.substr(1)), std::move(shape), &*p});
  };
  add(names::kLightmapAo, m.ao, {});
  add(names::kLightmapTransferDiffuse, m.transfer_diffuse, {width(m.transfer_diffuse)});
  add(names::kLightmapTransferVisibility, m.transfer_visibility, {width(m.transfer_visibility)});
  add(names::kLightmapRadianceBand1, m.radiance_band1, {3, 3});
  add(names::kLightmapRadianceShadowed, m.radiance_shadowed, {3, width(m.radiance_shadowed) / 3});
  add(names::kLightmapAreaIrradiance, m.area_irradiance, {width(m.area_irradiance)});
  if (m.area_sh) {
    const uint64_t n2 = uint64_t(m.area_sh->sh_order.value_or(0) * m.area_sh->sh_order.value_or(0));
    add(names::kLightmapAreaSh, m.area_sh, {n2 > 0 ? width(m.area_sh) / n2 : 0, n2});
  }
  return out;
}

std::vector<LightmapChannel> lightmap_channels(const Lightmap& m) {
  const size_t texels = m.texel_count();
  std::vector<LightmapChannel> out;
  {
    LightmapChannel state{"state", std::string(names::kLightmapState.substr(1)), 0, std::vector<float>(texels)};
    for (size_t k = 0; k < texels; ++k) state.values[k] = float(m.state.values[k]);
    out.push_back(std::move(state));
  }
  // One channel per component of a product's per-texel row, named by `label(component)`.
  auto add = [&](std::string_view dataset, const std::optional<Product>& p, uint64_t width, auto label) {
    if (!p || width == 0) return;
    for (uint64_t c = 0; c < width; ++c) {
      LightmapChannel ch{label(c), std::string(dataset.substr(1)), c, std::vector<float>(texels)};
      for (size_t k = 0; k < texels; ++k) ch.values[k] = p->values[k * width + c];
      out.push_back(std::move(ch));
    }
  };
  auto width = [&](const std::optional<Product>& p) { return p && texels > 0 ? uint64_t(p->values.size() / texels) : 0; };
  constexpr const char* kRgb[3] = {"R", "G", "B"};
  add(names::kLightmapAo, m.ao, width(m.ao), [](uint64_t) { return std::string("ao"); });
  add(names::kLightmapTransferDiffuse, m.transfer_diffuse, width(m.transfer_diffuse),
      [](uint64_t c) { return "transfer.diffuse.c" + std::to_string(c); });
  add(names::kLightmapTransferVisibility, m.transfer_visibility, width(m.transfer_visibility),
      [](uint64_t c) { return "transfer.visibility.c" + std::to_string(c); });
  add(names::kLightmapRadianceBand1, m.radiance_band1, width(m.radiance_band1), [&](uint64_t c) {
    return std::string("radiance.band1.") + kRgb[c / 3] + ".m" + std::to_string(int(c % 3) - 1);
  });
  const uint64_t shadowed = width(m.radiance_shadowed);
  add(names::kLightmapRadianceShadowed, m.radiance_shadowed, shadowed, [&](uint64_t c) {
    return std::string("radiance.shadowed.") + kRgb[c / (shadowed / 3)] + ".c" + std::to_string(c % (shadowed / 3));
  });
  // The area lights per texel, a channel per light (and per light and SH coefficient), named by
  // the light (its `lights` attribute, line l = column l).
  auto light_names = [](const std::optional<Product>& p) {
    return p ? formats::split_light_list(p->lights.value_or("")) : std::vector<std::string>{};
  };
  const std::vector<std::string> lit = light_names(m.area_irradiance);
  add(names::kLightmapAreaIrradiance, m.area_irradiance, lit.empty() ? 0 : width(m.area_irradiance), [&](uint64_t c) {
    return "area.irradiance." + (c < lit.size() ? lit[c] : std::to_string(c));
  });
  const std::vector<std::string> lit_sh = light_names(m.area_sh);
  const uint64_t area_sh = width(m.area_sh), per_light = lit_sh.empty() ? 0 : area_sh / lit_sh.size();
  add(names::kLightmapAreaSh, m.area_sh, per_light == 0 ? 0 : area_sh, [&](uint64_t c) {
    return "area.sh." + lit_sh[c / per_light] + ".c" + std::to_string(c % per_light);
  });
  return out;
}

std::filesystem::path lightmap_file(const std::filesystem::path& prefix, const SetRef& set, std::string_view suffix) {
  std::string name = prefix.filename().string();
  if (!set.prefix.empty()) name += "." + set.prefix.substr(set.prefix.find('/') + 1);
  name += std::string(suffix) + ".exr";
  return prefix.parent_path() / name;
}

std::string encode_png_grey(const std::vector<uint8_t>& grey, uint64_t width, uint64_t height,
                            const std::filesystem::path& out) {
  // libpng's simplified API reports failures in image.message (no longjmp). 8-bit formats are
  // taken as sRGB unless COLORSPACE_NOT_sRGB is set: set, so no sRGB chunk claims that AO codes
  // are colours (glTF reads occlusion as linear data).
  png_image im{};
  im.version = PNG_IMAGE_VERSION;
  im.width = png_uint_32(width);
  im.height = png_uint_32(height);
  im.format = PNG_FORMAT_GRAY;
  im.flags = PNG_IMAGE_FLAG_COLORSPACE_NOT_sRGB;
  png_alloc_size_t size = 0;
  if (!png_image_write_to_memory(&im, nullptr, &size, 0, grey.data(), png_int_32(width), nullptr))
    throw FormatError(out.string(), std::string("libpng cannot encode the occlusion image: ") + im.message);
  std::string bytes(size, '\0');
  if (!png_image_write_to_memory(&im, bytes.data(), &size, 0, grey.data(), png_int_32(width), nullptr))
    throw FormatError(out.string(), std::string("libpng cannot encode the occlusion image: ") + im.message);
  bytes.resize(size);
  return bytes;
}

void write_exr_half(const std::filesystem::path& path, uint64_t width, uint64_t height,
                    const std::vector<ExrChannel>& channels, const std::filesystem::path& source, const SetRef& set,
                    const std::filesystem::path& out) {
  const size_t texels = size_t(width * height);
  std::vector<std::vector<Imath::half>> halves;
  halves.reserve(channels.size());
  for (const ExrChannel& c : channels) {
    std::vector<Imath::half>& h = halves.emplace_back(texels);
    for (size_t k = 0; k < texels; ++k) {
      const float x = (*c.values)[k];
      h[k] = Imath::half(x);  // round to nearest even: |h − x| ≤ 2⁻¹¹ |x| for normal halves
      if (!std::isfinite(float(h[k])))
        throw FormatError(source.string(), "lightmap of " + set.name + ": channel " + c.name + " holds " + std::to_string(x) + " at texel (" +
                                               std::to_string(k % width) + ", " + std::to_string(k / width) +
                                               "), beyond half float's largest finite value 65504: not written as EXR");
    }
  }
  try {
    Imf::Header header(static_cast<int>(width), static_cast<int>(height));
    header.compression() = Imf::ZIP_COMPRESSION;
    Imf::FrameBuffer frame;
    for (size_t i = 0; i < channels.size(); ++i) {
      header.channels().insert(channels[i].name, Imf::Channel(Imf::HALF));
      frame.insert(channels[i].name, Imf::Slice(Imf::HALF, reinterpret_cast<char*>(halves[i].data()), sizeof(Imath::half),
                                                sizeof(Imath::half) * width));
    }
    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(frame);
    file.writePixels(int(height));
  } catch (const std::exception& e) {
    throw FormatError(out.string(), "cannot write the EXR '" + path.string() + "': " + e.what());
  }
}

} // namespace prt::exports::detail
