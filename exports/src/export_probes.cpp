// export_probes.cpp — per-vertex light probes in engine SH conventions (JSON), from the baked
// band-1 radiance: the probe of a vertex is the radiance SH (0; 2R; 0), which every engine's own
// formula evaluates to exactly the baked E/π at the baked normal (prtshade/conventions.h; layout:
// formats/SCHEMA.md "Exports"). Positions and normals are given in the engine's frame.
#include "export_common.h"


#include <prtshade/conventions.h>

#include <nlohmann/json.hpp>

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

} // namespace

std::vector<std::string> export_probes(const Asset& asset, const std::filesystem::path& source, ExportFormat format,
                                       const std::filesystem::path& out,
                                       const std::optional<EnvironmentProbe>& environment) {
  const EngineInfo& e = info_of(format);
  const C::UpAxis up = asset.root.up_axis == "z" ? C::UpAxis::Z : C::UpAxis::Y;
  const C::Mat3 M = C::engine_from_file(e.engine, up);

  nlohmann::json sets = nlohmann::json::array();
  std::vector<std::string> left_out;
  for (const SetRef& ref : vertex_sets(asset)) {
    const VertexSet& s = *ref.set;
    if (!s.radiance_band1) {
      left_out.push_back(ref.name + ": " + why_no_band1(asset, s));
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
  if (sets.empty() && !environment)
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
  write_bytes(staging.stage(out), j.dump() + "\n", out);
  staging.commit();
  return left_out;
}

} // namespace prt::exports::detail
