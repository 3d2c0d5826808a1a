// prtshade/loader.h — the optional HDF5 loader of prtshade (target prt::prtshade_hdf5): reads a
// baked .prt.h5 file (formats/SCHEMA.md, schema v1 and v2) with formats::read_asset and returns plain owning
// arrays in the file's own layout, plus the non-owning views the std-only core shades with
// (<prtshade/fiv.h> FivOccluder / DifMap). The core never needs HDF5; an engine with its own
// asset pipeline can skip this library and fill the views itself.
//
// Layout (unchanged from the file; V vertices, T triangles, L = sh_order):
//   positions, normals [V][3] float; triangles [T][3] uint32; ao [V]; transfer [V][L²];
//   visibility [V][L²]; radiance_band1 [V][RGB][m = −1, 0, 1];
//   fiv_environment [RGB][xyz]; irradiance_cube [6][S][S][RGB];
//   occluder shells [Nρ][Nθ][Nφ][RGB][xyz], valid [Nρ][Nθ][Nφ], radii [Nρ] (the file stores the
//   radii, centre and radius as float64 attributes; they are rounded once to float here; so are
//   float64 positions, which a file has for a mesh far from the origin: SCHEMA.md, "Positions
//   far from the origin" — an engine that needs them exactly reads formats::read_asset).
// Vertex sets: a v1 file (and the root layout of a v2 file) has one, named ""; a v2 scene file has
// one per /objects/<name> as well (named "<name>"), root first then by name.
// Errors: prt::formats::FormatError "<file>: <defect>" for anything unreadable or inconsistent,
// including occluder data the core would refuse (prt::shade::validate_occluder / validate_difmap).
// What an engine linking this may rely on, for any bytes in the file (a damaged download, a
// truncated copy, another tool's HDF5 file): load_prt returns the file's data, fully checked
// against the schema (shapes, index ranges, finiteness), or throws FormatError; it does not
// crash, hang or allocate more than the file's size allows. HDF5 1.10 itself is not safe on
// damaged unchecksummed metadata, so the reader hands HDF5 only checksummed structures, checked
// from the raw bytes first (formats/prtfile.h, "Which files the reader opens"): files in HDF5's
// oldest format are refused, and the text of variable-length strings (h5py's attributes) is
// read by the reader's own bounds-checked code, never by HDF5 (an attribute whose text is in a
// damaged heap is left out: skipped_attrs). Tested by byte flips over whole files
// (tests/loader) and fuzzed (docs/RELIABILITY.md). Not covered: a file crafted on purpose with
// valid checksums around malformed HDF5 structures; load untrusted files (user mods, downloads)
// in a separate process if that matters.
#pragma once

#include <prtshade/fiv.h>

#include <formats/prtfile.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace prt::shade {

struct LoadedVertexSet {
  std::string name;                // "" for the root layout, else the object's name
  std::vector<float> positions;    // [V][3]
  std::vector<float> normals;      // [V][3] or empty
  std::vector<uint32_t> triangles; // [T][3] or empty
  std::vector<float> ao;           // [V] or empty
  int transfer_order = 0;          // L of /transfer/diffuse (0: absent)
  std::vector<float> transfer;     // [V][L²]
  int visibility_order = 0;        // L of /transfer/visibility (0: absent)
  std::vector<float> visibility;   // [V][L²]
  std::vector<float> radiance_band1;  // [V][3][3] or empty

  std::size_t vertex_count() const noexcept { return positions.size() / 3; }
};

struct LoadedOccluder {
  std::string name;  // <name> of /fiv/occluders/<name>
  std::array<float, 3> centre{};
  float radius = 0;
  int n_rho = 0, n_theta = 0, n_phi = 0;
  std::vector<float> radii;     // [Nρ]
  std::vector<float> shells;    // [Nρ][Nθ][Nφ][3][3]; empty when shells_half holds them
  // A float16 file's shells (v8) as binary16 bits, as the runtime reads them (prtshade/fiv.h
  // "Half-float tables"), else empty; cones_half likewise for the cone table.
  std::vector<uint16_t> shells_half, cones_half;
  std::vector<uint8_t> valid;   // [Nρ][Nθ][Nφ]
  int radial_scheme = kFivRadialGeometric;  // the file's radial_scheme (v7; absent: geometric)
  std::vector<float> surface_radius;        // [Nθ][Nφ], surface scheme only
  // The proxy its corrections use (the group attribute `proxy`, v7): "sphere" (also for files
  // without it) or "cone", with the cone table [Nρ][Nθ][Nφ][4] (empty for "sphere"; prtshade/fiv.h
  // "Tight proxies").
  std::string proxy = "sphere";
  std::vector<float> cones;
  // A scene file's self-shadows of this occluder (v9, /fiv/occluders/<name>/self_band1): band-1
  // radiance from itself alone at the vertices of the vertex set of the same name, [V][3][3] as
  // radiance_band1; empty when the file has none. E_self = shade_band1_vertices at that set's
  // normals, then shade_fiv_member_given_self (prtshade/fiv.h).
  std::vector<float> self_band1;
  std::string grid;             // the file's angular-convention string ("" if absent)
  std::vector<formats::Attr> attrs;  // every attribute of the shells dataset, as stored

  // View for the core; valid while this object lives and is not modified.
  FivOccluder view() const noexcept;
};

struct LoadedAsset {
  std::filesystem::path path;
  int64_t format_version = 0;
  std::string up_axis;  // "y" or "z"
  std::vector<LoadedVertexSet> vertex_sets;

  bool has_fiv_environment = false;
  std::array<float, 9> fiv_environment{};  // [RGB][xyz]
  int irradiance_cube_size = 0;            // S (0: absent)
  std::vector<float> irradiance_cube;      // [6][S][S][3]
  std::vector<LoadedOccluder> occluders;   // sorted by name
  // Attributes another tool added that the reader left out, with the reason
  // (formats::describe gives one line each): nothing shading reads; an engine may log them.
  std::vector<formats::SkippedAttr> skipped_attrs;

  // The vertex set named `name` ("" = root layout), or nullptr.
  const LoadedVertexSet* find_vertex_set(std::string_view name) const noexcept;
  // The DifMap view ({0, nullptr} when the file has no /fiv/irradiance_cube).
  DifMap difmap() const noexcept;
  // Views of every occluder, in `occluders` order.
  std::vector<FivOccluder> occluder_views() const;
};

// Reads `path` (formats::read_asset, with the full schema check) into a LoadedAsset.
LoadedAsset load_prt(const std::filesystem::path& path);

} // namespace prt::shade
