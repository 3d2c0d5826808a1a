// export_probes.cpp — per-vertex light probes in engine SH conventions (JSON), from the baked
// band-1 radiance: the probe of a vertex is the radiance SH (0; 2R; 0), which every engine's own
// formula evaluates to exactly the baked E/π at the baked normal (prtshade/conventions.h; layout:
// formats/SCHEMA.md "Exports"). Positions and normals are given in the engine's frame.
// Godot also gets the lightmaps baked with band-1 radiance as the directional (L1 SH) lightmaps
// of its LightmapGI (godot_lightmap below).
#include "export_common.h"


#include <prtshade/conventions.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>

namespace prt::exports::detail {
namespace {

namespace C = prt::conventions;

struct EngineInfo {
  ExportFormat format;
  C::Engine engine;
  const char* name;
  const char* layout;
  const char* coefficients;
  const char* evaluation;
};

constexpr EngineInfo kEngines[] = {
    {ExportFormat::Unity, C::Engine::Unity, "unity", "[vertex][rgb][9]: SphericalHarmonicsL2 sh[rgb, i]",
     "c_i = A_l/pi * k_i * L_i: coefficients of the polynomials (1, y, z, x, xy, yz, 3z^2-1, xz, x^2-y^2), "
     "pre-scaled as ShadeSH9 expects (no Condon-Shortley phase left)",
     "ShadeSH9 with unity_SHAr = (c3, c1, c2, c0 - c6), unity_SHBr = (c4, c5, 3 c6, c7), unity_SHC.r = c8 "
     "gives E(n)/pi, the diffuse lighting Unity multiplies by the albedo"},
    {ExportFormat::Godot, C::Engine::Godot, "godot", "[vertex][9][rgb]: a LightmapGI probe's 9 colours",
     "c_i = s_i * L_i / pi: radiance over pi in the basis without the Condon-Shortley phase (s_i = sign of k_i)",
     "the lightmap-capture formula (Ramamoorthi-Hanrahan eq. 13, c1..c5 = 0.429043, 0.511664, 0.743125, 0.886227, "
     "0.247708) gives E(n)/pi"},
    {ExportFormat::Filament, C::Engine::Filament, "filament", "[vertex][9][rgb]: IndirectLight::irradiance(3, float3 sh[9])",
     "c_i = A_l/pi * k_i * L_i: cmgen's pre-scaled irradiance SH",
     "Irradiance_SphericalHarmonics: sum_i c_i * (1, y, z, x, yx, yz, 3z^2-1, zx, x^2-y^2)_i gives E(n)/pi"},
};

const EngineInfo& info_of(ExportFormat format) {
  for (const EngineInfo& e : kEngines)
    if (e.format == format) return e;
  return kEngines[0];
}

nlohmann::json in_frame(const std::vector<double>& xyz, const C::Mat3& M) {
  nlohmann::json out = nlohmann::json::array();
  for (size_t v = 0; v + 2 < xyz.size(); v += 3)
    for (size_t r = 0; r < 3; ++r) out.push_back(M[r][0] * xyz[v] + M[r][1] * xyz[v + 1] + M[r][2] * xyz[v + 2]);
  return out;
}

// Why a vertex set has no /radiance/band1: a scene object's plan says it (the "left_out" line that
// names band-1 radiance); the root layout was baked without an environment.
std::string why_no_band1(const Asset& asset, const VertexSet& set) {
  for (const SceneObject& o : asset.objects) {
    if (&o.set != &set) continue;
    const std::string lines = o.left_out ? *o.left_out : std::string();
    for (size_t a = 0; a < lines.size();) {
      size_t b = lines.find('\n', a);
      if (b == std::string::npos) b = lines.size();
      const std::string line = lines.substr(a, b - a);
      const size_t colon = line.find(": ");
      if (colon != std::string::npos && line.substr(0, colon).find("radiance") != std::string::npos)
        return "no band-1 radiance (the scene's plan left it out: " + line.substr(colon + 2) + ")";
      a = b + 1;
    }
    return "no band-1 radiance was baked for it";
  }
  return "no band-1 radiance (baked without --radiance ENV)";
}

// Godot 4's directional lightmap (LightmapGI "directional", uses_spherical_harmonics, with the
// packed L1 coefficients of Godot 4.4+, godotengine/godot PR #96114). Read from its forward
// shaders (scene_forward_clustered.glsl, scene_forward_mobile.glsl): per lightmap slice four
// layers of a 2D texture array, sampled bilinearly at the mesh's UV2,
//   l0 = layer 0 (RGB), a_k = (layer k − 0.5) · 2 for k = 1, 2, 3 (l1n1, l1_0, l1p1),
//   ambient(n) = l0 + 4 · l0 · (a_1 n.y + a_2 n.z + a_3 n.x)   (times exposure_normalization),
// n the normal in the LightmapGI node's frame, and ambient is multiplied by the albedo: it is
// E(n)/π. LightmapGI::bake writes the layers stacked vertically in one EXR (layer j at rows
// j·H … (j+1)·H − 1), imported as a 2D array texture with slices/vertical = 4.
//
// Ours per texel, per colour channel, from /lightmap/radiance/band1 R and the texel's normal n0
// (the file's frame; M turns it into Godot's): E(n)/π = g · n with g = (4/3)·0.488603·d,
// d = (−R_1, −R_−1, R_0) (the header of prtshade/conventions.h: E = (4π/3) Σ_m y_1m(n) R_m,
// y_1m = 0.488603·(−y, z, −x)). Then l0 = g · n0, exact at the baked normal, and
// a = M (g − (g·n0) n0) / (4 l0): the tangential part of g, which tilts the value with the normal
// as the vector irradiance does (to first order); a stays tangential, so ambient(M n0) = l0
// exactly. a is scaled down as a whole (it stays tangential) until every component lies in
// [−1, 1], the range the packed layers hold; where l0 ≤ 0 (no light, an empty texel) a = 0.
constexpr int kGodotLayers = 4;

struct GodotLayers {
  std::vector<float> r, g, b;  // [4H][W]
};

GodotLayers godot_layers(const Lightmap& m, const C::Mat3& M) {
  const size_t W = m.width, H = m.height, texels = W * H;
  constexpr double k1 = 0.4886025119029199;  // sqrt(3 / 4π)
  GodotLayers out{std::vector<float>(kGodotLayers * texels), std::vector<float>(kGodotLayers * texels),
                  std::vector<float>(kGodotLayers * texels)};
  std::vector<float>* channel[3] = {&out.r, &out.g, &out.b};
  const std::vector<float>& R = m.radiance_band1->values;
  for (size_t k = 0; k < texels; ++k) {
    const double n0[3] = {m.normals->values[3 * k], m.normals->values[3 * k + 1], m.normals->values[3 * k + 2]};
    for (size_t c = 0; c < 3; ++c) {
      const float* Rc = &R[9 * k + 3 * c];  // m = −1, 0, 1
      const double d[3] = {-double(Rc[2]), -double(Rc[0]), double(Rc[1])};
      double g[3], e0 = 0;
      for (int i = 0; i < 3; ++i) g[i] = 4.0 / 3.0 * k1 * d[i], e0 += g[i] * n0[i];
      double a[3] = {0, 0, 0};
      if (e0 > 0 && m.state.values[k] != 0) {
        double t[3];
        for (int i = 0; i < 3; ++i) t[i] = g[i] - e0 * n0[i];
        double largest = 1;
        for (int r = 0; r < 3; ++r) {
          a[r] = (M[r][0] * t[0] + M[r][1] * t[1] + M[r][2] * t[2]) / (4 * e0);
          largest = std::max(largest, std::abs(a[r]));
        }
        for (double& x : a) x /= largest;
      } else {
        e0 = 0;
      }
      std::vector<float>& out_c = *channel[c];
      out_c[k] = float(e0);
      out_c[1 * texels + k] = float(a[1] * 0.5 + 0.5);  // l1n1: y
      out_c[2 * texels + k] = float(a[2] * 0.5 + 0.5);  // l1_0: z
      out_c[3 * texels + k] = float(a[0] * 0.5 + 0.5);  // l1p1: x
    }
  }
  return out;
}

// Godot's import settings for the layered EXR, as LightmapGI::bake writes them beside its own.
constexpr const char* kGodotImport =
    "[remap]\n\nimporter=\"2d_array_texture\"\ntype=\"CompressedTexture2DArray\"\n\n[params]\n\n"
    "compress/mode=3\ncompress/channel_pack=1\nmipmaps/generate=false\nslices/horizontal=1\nslices/vertical=4\n";

} // namespace

void export_probes(const Asset& asset, const std::filesystem::path& source, ExportFormat format,
                   const std::filesystem::path& out, const std::optional<EnvironmentProbe>& environment,
                   ExportSummary& summary) {
  const EngineInfo& e = info_of(format);
  const C::UpAxis up = asset.root.up_axis == "z" ? C::UpAxis::Z : C::UpAxis::Y;
  const C::Mat3 M = C::engine_from_file(e.engine, up);

  nlohmann::json sets = nlohmann::json::array();
  std::vector<std::string> left_out;
  // Godot's directional lightmaps: the sets whose lightmap holds band-1 radiance.
  std::vector<LightmapRef> lightmaps;
  for (const LightmapRef& map : lightmap_sets(asset))
    if (map.lightmap->radiance_band1 && map.lightmap->normals) lightmaps.push_back(map);
  auto lit_per_texel = [&](const VertexSet& s) {
    return s.lightmap && s.lightmap->radiance_band1 && s.lightmap->normals;
  };
  for (const SetRef& ref : vertex_sets(asset)) {
    const VertexSet& s = *ref.set;
    if (!s.radiance_band1) {
      if (!lit_per_texel(s))
        left_out.push_back(ref.name + ": " + why_no_band1(asset, s));
      else if (format != ExportFormat::Godot)
        left_out.push_back(ref.name + ": its band-1 radiance is per texel (a lightmap): --to godot writes it as "
                                      "Godot's directional lightmap, --to exr as EXR channels");
      continue;
    }
    const size_t V = s.vertex_count();
    nlohmann::json sh = nlohmann::json::array();
    for (size_t v = 0; v < V; ++v) {
      std::array<float, 9> R{};
      std::copy_n(s.radiance_band1->values.begin() + std::ptrdiff_t(9 * v), 9, R.begin());
      for (double c : C::to_engine(e.engine, up, C::radiance_from_band1(R))) sh.push_back(c);
    }
    nlohmann::json set = {{"name", ref.name},
                          {"dataset", join(ref.prefix, std::string(names::kRadianceBand1.substr(1)))},
                          {"vertices", V},
                          {"positions", in_frame(s.positions->values, M)},
                          {"sh", std::move(sh)}};
    if (s.normals) set["normals"] = in_frame(std::vector<double>(s.normals->values.begin(), s.normals->values.end()), M);
    sets.push_back(std::move(set));
  }
  if (format != ExportFormat::Godot) lightmaps.clear();
  const std::vector<SetRef> all_sets = vertex_sets(asset);
  if (sets.empty() && !environment && lightmaps.empty() &&
      std::any_of(all_sets.begin(), all_sets.end(), [&](const SetRef& r) { return lit_per_texel(*r.set); }))
    throw FormatError(source.string(), std::string("has band-1 radiance per texel only (a lightmap), no per-vertex "
                                                   "/radiance/band1 for ") + e.name +
                                           " probes: export it --to godot (Godot's directional lightmap) or --to exr");
  if (sets.empty() && !environment && lightmaps.empty())
    throw FormatError(source.string(),
                      std::string("has no /radiance/band1, the only baked product that is lighting: a ") + e.name +
                          " probe needs it (bake with prtbake vertex --radiance ENV, or a scene with an environment), "
                          "or give --env ENV for the environment's probe alone");

  nlohmann::json j;
  j["format"] = "prtbake-probes";
  j["version"] = 1;
  j["engine"] = e.name;
  j["source"] = asset.root.source;
  j["source_sha256"] = asset.root.source_sha256;
  j["up_axis"] = asset.root.up_axis;
  j["engine_from_file"] = {M[0], M[1], M[2]};
  j["layout"] = e.layout;
  j["coefficients"] = e.coefficients;
  j["evaluation"] = e.evaluation;
  j["probe"] = "per vertex, from /radiance/band1 R: the radiance SH (0; 2R; 0), exact E/pi at the baked normal "
               "(formats/SCHEMA.md, Exports)";
  j["sets"] = std::move(sets);
  if (environment) {
    C::RgbSh9 radiance{};
    for (size_t c = 0; c < 3; ++c) std::copy(environment->radiance[c].begin(), environment->radiance[c].end(), radiance[c].begin());
    nlohmann::json sh = nlohmann::json::array();
    for (double x : C::to_engine(e.engine, up, radiance)) sh.push_back(x);
    j["environment"] = {{"name", environment->name},
                        {"sha256", environment->sha256},
                        {"probe", "the environment's radiance SH (order 3, no shadowing): E/pi of the unoccluded sky "
                                  "at any normal, up to its band-2 truncation (formats/SCHEMA.md, Exports)"},
                        {"sh", std::move(sh)}};
  }

  Staging staging(out);
  if (!lightmaps.empty()) {
    // Beside OUT: <OUT without its extension>.lightmap[.<object>].exr and its .import.
    std::filesystem::path prefix = out;
    prefix.replace_extension();
    prefix += ".lightmap";
    nlohmann::json list = nlohmann::json::array();
    for (const LightmapRef& map : lightmaps) {
      const Lightmap& lm = *map.lightmap;
      const std::filesystem::path file = lightmap_file(prefix, map.set);
      const GodotLayers layers = godot_layers(lm, M);
      write_exr_half(staging.stage(file), lm.width, kGodotLayers * lm.height,
                     {{"R", &layers.r}, {"G", &layers.g}, {"B", &layers.b}}, source, map.set, file);
      std::filesystem::path import = file;
      import += ".import";
      write_bytes(staging.stage(import), kGodotImport, out);
      list.push_back({{"name", map.set.name},
                      {"dataset", join(map.set.prefix, std::string(names::kLightmapRadianceBand1.substr(1)))},
                      {"file", file.filename().string()},
                      {"width", lm.width},
                      {"height", lm.height},
                      {"layers", kGodotLayers}});
    }
    j["lightmaps"] = std::move(list);
    j["lightmap_layout"] =
        "Godot 4.4+ LightmapGI directional (L1 SH, packed): an RGB half EXR of W x 4H, layers stacked vertically "
        "(layer j = rows jH..(j+1)H-1), imported as a 2D array (slices/vertical = 4); layer 0 = l0, layers 1-3 = "
        "a/2 + 0.5 for a = (l1n1, l1_0, l1p1) ~ (y, z, x); Godot shades l0 + 4 l0 (a.n) = E/pi, exact at the "
        "baked normal (formats/SCHEMA.md, Exports)";
  }
  write_bytes(staging.stage(out), j.dump() + "\n", out);
  summary.written = staging.commit();
  summary.left_out = std::move(left_out);
}

} // namespace prt::exports::detail
