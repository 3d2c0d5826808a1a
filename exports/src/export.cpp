// export.cpp — export_asset and what the exporters share (contracts: exports/export.h,
// export_common.h).
#include <exports/export.h>

#include "export_common.h"

#include <formats/temporaries.h>

#include <algorithm>
#include <fstream>
#include <stdexcept>

namespace prt::exports {
namespace detail {
namespace {

constexpr struct {
  ExportFormat format;
  const char* name;
} kFormatNames[] = {{ExportFormat::Gltf, "gltf"},   {ExportFormat::Glb, "glb"},     {ExportFormat::Binary, "bin"},
                    {ExportFormat::Unity, "unity"}, {ExportFormat::Godot, "godot"}, {ExportFormat::Filament, "filament"},
                    {ExportFormat::Exr, "exr"},     {ExportFormat::Web, "web"}};

std::string relative(std::string_view path) { return std::string(path.substr(1)); }

} // namespace

std::vector<SetRef> vertex_sets(const Asset& asset) {
  std::vector<SetRef> sets;
  if (asset.vertices.vertex_count() > 0) sets.push_back({"root", "", &asset.vertices});
  for (const SceneObject& o : asset.objects)
    if (o.set.vertex_count() > 0)
      sets.push_back({o.node_path ? *o.node_path : o.name, relative(names::kObjects) + "/" + o.name, &o.set});
  return sets;
}

uint64_t ProductRef::components() const noexcept {
  uint64_t n = 1;
  for (uint64_t s : shape) n *= s;
  return n;
}

std::vector<ProductRef> products(const VertexSet& set) {
  const uint64_t V = set.vertex_count();
  std::vector<ProductRef> out;
  auto add = [&](std::string_view path, const std::optional<Product>& p, std::vector<uint64_t> shape) {
    if (p) out.push_back({relative(path), std::move(shape), &*p});
  };
  auto width = [&](const std::optional<Product>& p) { return p && V > 0 ? uint64_t(p->values.size() / V) : 0; };
  add(names::kAo, set.ao, {});
  add(names::kTransferDiffuse, set.transfer_diffuse, {width(set.transfer_diffuse)});
  add(names::kTransferVisibility, set.transfer_visibility, {width(set.transfer_visibility)});
  add(names::kRadianceBand1, set.radiance_band1, {3, 3});
  if (set.radiance_shadowed) {
    const uint64_t n2 = uint64_t(set.radiance_shadowed->sh_order.value_or(0) * set.radiance_shadowed->sh_order.value_or(0));
    add(names::kRadianceShadowed, set.radiance_shadowed, {3, n2});
  }
  add(names::kAreaIrradiance, set.area_irradiance, {width(set.area_irradiance)});
  if (set.area_sh) {
    const uint64_t n2 = uint64_t(set.area_sh->sh_order.value_or(0) * set.area_sh->sh_order.value_or(0));
    const uint64_t lights = n2 > 0 ? width(set.area_sh) / n2 : 0;
    add(names::kAreaSh, set.area_sh, {lights, n2});
  }
  return out;
}

bool exactly_float(const std::vector<double>& values) noexcept {
  return std::all_of(values.begin(), values.end(), [](double x) { return double(float(x)) == x; });
}

std::string join(const std::string& prefix, const std::string& dataset) {
  return prefix.empty() ? dataset : prefix + "/" + dataset;
}

Staging::Staging(const std::filesystem::path& out) : out_(out) {
  const std::string msg = out.string();
  if (out.filename().empty()) throw FormatError(msg, "the output path names a directory, not a file");
  const std::filesystem::path parent = out.has_parent_path() ? out.parent_path() : std::filesystem::path(".");
  std::error_code ec;
  if (!std::filesystem::is_directory(parent, ec))
    throw FormatError(msg, "output directory '" + parent.string() + "' does not exist");
  if (std::filesystem::is_directory(out, ec)) throw FormatError(msg, "the output path is an existing directory");
  const std::string prefix = "." + out.filename().string() + ".export." + formats::host_tag() + ".";
  formats::remove_stale_temporaries(parent, prefix);
  dir_ = parent / formats::temporary_name(prefix);
  std::filesystem::remove_all(dir_, ec);
  if (!std::filesystem::create_directory(dir_, ec))
    throw FormatError(msg, "cannot create the staging directory '" + dir_.string() + "': " + ec.message());
}

Staging::~Staging() {
  std::error_code ec;
  std::filesystem::remove_all(dir_, ec);
}

std::filesystem::path Staging::stage(const std::filesystem::path& final_path) {
  const std::filesystem::path staged = dir_ / final_path.filename();
  files_.emplace_back(staged, final_path);
  return staged;
}

std::vector<std::filesystem::path> Staging::commit() {
  std::vector<std::filesystem::path> done;
  for (const auto& [staged, final_path] : files_) {
    std::error_code ec;
    std::filesystem::rename(staged, final_path, ec);
    if (ec) {
      for (const auto& d : done) std::filesystem::remove(d, ec);
      throw FormatError(final_path.string(), "cannot rename '" + staged.string() + "' onto it: " + ec.message());
    }
    done.push_back(final_path);
  }
  return done;
}

void write_bytes(const std::filesystem::path& path, const std::string& bytes, const std::filesystem::path& out) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  f.write(bytes.data(), std::streamsize(bytes.size()));
  f.close();
  if (!f) throw FormatError(out.string(), "cannot write '" + path.string() + "' (disk full?)");
}

} // namespace detail

std::optional<ExportFormat> parse_export_format(std::string_view name) {
  for (const auto& f : detail::kFormatNames)
    if (name == f.name) return f.format;
  return std::nullopt;
}

const char* to_string(ExportFormat format) noexcept {
  for (const auto& f : detail::kFormatNames)
    if (format == f.format) return f.name;
  return "?";
}

ExportSummary export_asset(const formats::Asset& asset, const std::filesystem::path& source, ExportFormat format,
                           const std::filesystem::path& out, const std::optional<EnvironmentProbe>& environment) {
  const bool probe = is_probe_format(format);
  if (environment && !probe) throw std::invalid_argument("an environment probe is written by the probe formats only");
  if (detail::vertex_sets(asset).empty() && !(probe && environment))
    throw formats::FormatError(source.string(), "has no vertex set with /mesh/positions (and vertices) to export (an FIV-only file?)");
  ExportSummary summary;
  switch (format) {
  case ExportFormat::Gltf:
  case ExportFormat::Glb: summary.written = detail::export_gltf(asset, out, format == ExportFormat::Glb); break;
  case ExportFormat::Binary: summary.written = detail::export_binary(asset, out); break;
  case ExportFormat::Exr: summary.written = detail::export_exr(asset, source, out); break;
  case ExportFormat::Web: throw std::invalid_argument("the web export is export_web (it takes environments)");
  case ExportFormat::Unity:
  case ExportFormat::Godot:
  case ExportFormat::Filament: detail::export_probes(asset, source, format, out, environment, summary); break;
  }
  return summary;
}

} // namespace prt::exports
