// tests/fuzz/make_seeds.cpp — writes the binary seeds of the fuzz targets that are not committed
// (docs/RELIABILITY.md "Fuzzing"), at build time, into the directory given:
//   exr/latlong.exr, exr/latlong_zip.exr, exr/cube.exr   tiny environment maps (OpenEXR's own
//        writer: a 16×8 lat-long, uncompressed and ZIP; a 4×24 cube map), for fuzz_exr;
//   prt/vertex.prt.h5, prt/fiv.prt.h5   small files from our writer (formats::write_asset): a
//        tetrahedron's vertex products (ao, diffuse and visibility transfer, band-1 radiance);
//        an FIV file (environment, DifMap, one occluder), for fuzz_prt_dump and fuzz_prt_loader;
//   prt/fiv_float16.prt.h5   the FIV file with its shells in half floats (format_version 8);
//   prt/fiv_scene_self.prt.h5   the FIV file as a scene file: the tetrahedron an object too, with
//        its self-shadows at its vertices (/fiv/occluders/tetra/self_band1, format_version 9);
//   prt/annotated.prt.h5   vertex.prt.h5 with attributes as h5py adds them (issue 28):
//        variable-length strings on the root (a scalar and an array of three), on /mesh and on
//        /ao, their text in a global heap collection that the targets then damage;
//   prt/old_format.prt.h5   the same root attributes and mesh datasets written with HDF5's
//        defaults instead of our writer's settings: superblock version 0, old-style groups,
//        contiguous and chunked-deflated datasets without checksums — the kind of file
//        (another tool's, or an old one) whose damaged headers crashed HDF5 1.10 (issue 11).
// Deterministic: the same bytes every build (no clock, no random numbers).
#include <formats/asset.h>

#include <hdf5.h>

#include <ImfEnvmapAttribute.h>
#include <ImfHeader.h>
#include <ImfRgbaFile.h>
#include <ImfStandardAttributes.h>

#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace fs = std::filesystem;
namespace pf = prt::formats;

namespace {

void write_exr(const fs::path& path, int w, int h, Imf::Envmap layout, Imf::Compression compression) {
  Imf::Header header(w, h);
  header.compression() = compression;
  Imf::addEnvmap(header, layout);
  std::vector<Imf::Rgba> pixels(size_t(w) * size_t(h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) pixels[size_t(y) * w + x] = Imf::Rgba(0.25f + 0.05f * x, 0.5f, 1.0f + 0.1f * y, 1.0f);
  Imf::RgbaOutputFile out(path.c_str(), header, Imf::WRITE_RGBA);
  out.setFrameBuffer(pixels.data(), 1, size_t(w));
  out.writePixels(h);
}

std::vector<float> ramp(size_t n, float step, float start) {
  std::vector<float> v(n);
  for (size_t i = 0; i < n; ++i) v[i] = start + step * float(i);
  return v;
}

pf::Product product(std::vector<float> values, const char* integrand) {
  pf::Product p;
  p.values = std::move(values);
  p.integrand = integrand;
  p.integrator = "qmc";
  p.integrator_description = "seed";
  p.samples = 16;
  p.seed = 1;
  return p;
}

pf::RootInfo root() {
  pf::RootInfo r;
  r.generator = "make_seeds";
  r.created = "2000-01-01T00:00:00Z";
  r.command_line = "make_seeds";
  r.source = "tetra.obj";
  r.source_sha256 = std::string(64, '0');
  r.up_axis = "y";
  r.sh_convention = "real orthonormal, i = l(l+1)+m";
  return r;
}

pf::Asset vertex_asset() {
  pf::Asset a;
  a.root = root();
  pf::VertexSet& s = a.vertices;
  s.positions = pf::Array<double>{{0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1}, {}};
  s.normals = pf::Normals{{-1, -1, -1, 1, 0, 0, 0, 1, 0, 0, 0, 1}, "angle-weighted", {}};
  for (size_t i = 0; i < 3; ++i) s.normals->values[i] = -1.f / std::sqrt(3.f);
  s.triangles = pf::Array<uint32_t>{{0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3}, {}};
  s.source_position = pf::Array<uint32_t>{{0, 1, 2, 3}, {}};
  s.ao = product({0.5f, 0.75f, 0.75f, 0.75f}, "A");
  s.transfer_diffuse = product(ramp(4 * 4, 0.01f, 0.1f), "T");
  s.transfer_diffuse->sh_order = 2;
  s.transfer_visibility = product(ramp(4 * 9, 0.01f, 0.05f), "V");
  s.transfer_visibility->sh_order = 3;
  s.radiance_band1 = product(ramp(4 * 9, 0.02f, 0.1f), "R");
  s.radiance_band1->environment = "sky.exr";
  s.radiance_band1->environment_sha256 = std::string(64, '1');
  s.radiance_band1->environment_layout = "lat-long";
  return a;
}

pf::Asset fiv_asset() {
  pf::Asset a;
  a.root = root();
  pf::FivEnvironment& e = a.fiv_environment.emplace();
  for (size_t k = 0; k < 9; ++k) e.f_env[k] = 0.1f * float(k + 1);
  e.environment = "sky.exr";
  e.environment_sha256 = std::string(64, '1');
  pf::IrradianceCube& c = a.irradiance_cube.emplace();
  c.size = 2;
  c.values = ramp(6 * 2 * 2 * 3, 0.01f, 1.0f);
  pf::Occluder& o = a.occluders.emplace_back();
  o.name = "tetra";
  o.n_rho = 2, o.n_theta = 2, o.n_phi = 2;
  o.shells = ramp(2 * 2 * 2 * 9, 0.001f, 0.01f);
  o.centre = {0.25, 0.25, 0.25};
  o.radius = 0.75;
  o.radii = {0.75, 1.5};
  o.valid = pf::OccluderValid{std::vector<uint8_t>(8, 1), std::nullopt, {}};
  return a;
}

// HDF5 calls of the old-format seed: any failure is fatal (a seed the targets cannot use).
hid_t checked(hid_t id, const char* what) {
  if (id < 0) throw std::runtime_error(std::string("HDF5: ") + what + " failed");
  return id;
}

void old_format_attr(hid_t location, const char* name, const std::string& value) {
  const hid_t type = checked(H5Tcopy(H5T_C_S1), "H5Tcopy");
  H5Tset_size(type, value.size());
  const hid_t space = checked(H5Screate(H5S_SCALAR), "H5Screate");
  const hid_t attr = checked(H5Acreate2(location, name, type, space, H5P_DEFAULT, H5P_DEFAULT), name);
  H5Awrite(attr, type, value.data());
  H5Aclose(attr), H5Sclose(space), H5Tclose(type);
}

void old_format_dataset(hid_t file, const char* path, hid_t type, const void* data, hsize_t rows, hsize_t cols,
                        bool chunked) {
  const hsize_t dims[2] = {rows, cols};
  const hid_t space = checked(H5Screate_simple(cols ? 2 : 1, dims, nullptr), "H5Screate_simple");
  const hid_t dcpl = checked(H5Pcreate(H5P_DATASET_CREATE), "H5Pcreate");
  if (chunked) {
    const hsize_t chunk[2] = {2, cols};
    H5Pset_chunk(dcpl, cols ? 2 : 1, chunk);
    H5Pset_deflate(dcpl, 1);
  }
  const hid_t lcpl = checked(H5Pcreate(H5P_LINK_CREATE), "H5Pcreate");
  H5Pset_create_intermediate_group(lcpl, 1);
  const hid_t set = checked(H5Dcreate2(file, path, type, space, lcpl, dcpl, H5P_DEFAULT), path);
  H5Dwrite(set, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data);
  H5Dclose(set), H5Pclose(lcpl), H5Pclose(dcpl), H5Sclose(space);
}

void write_old_format(const fs::path& path) {
  const hid_t file = checked(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), "H5Fcreate");
  const pf::RootInfo r = root();
  old_format_attr(file, "format", "prtbake");
  const hid_t space = checked(H5Screate(H5S_SCALAR), "H5Screate");
  const hid_t version = checked(H5Acreate2(file, "format_version", H5T_STD_I64LE, space, H5P_DEFAULT, H5P_DEFAULT), "attr");
  const int64_t one = 1;
  H5Awrite(version, H5T_NATIVE_INT64, &one);
  H5Aclose(version), H5Sclose(space);
  for (const auto& [name, value] : {std::pair{"generator", r.generator}, {"created", r.created}, {"command_line", r.command_line},
                                    {"source", r.source}, {"source_sha256", r.source_sha256}, {"up_axis", r.up_axis},
                                    {"sh_convention", r.sh_convention}})
    old_format_attr(file, name, value);
  const pf::VertexSet v = vertex_asset().vertices;
  const std::vector<float> positions(v.positions->values.begin(), v.positions->values.end());
  old_format_dataset(file, "/mesh/positions", H5T_IEEE_F32LE, positions.data(), 4, 3, false);
  old_format_dataset(file, "/mesh/normals", H5T_IEEE_F32LE, v.normals->values.data(), 4, 3, true);
  old_format_dataset(file, "/mesh/triangles", H5T_STD_U32LE, v.triangles->values.data(), 4, 3, false);
  old_format_dataset(file, "/ao", H5T_IEEE_F32LE, v.ao->values.data(), 4, 0, true);
  const hid_t ao = checked(H5Dopen2(file, "/ao", H5P_DEFAULT), "H5Dopen2");
  old_format_attr(ao, "integrand", *v.ao->integrand);
  H5Dclose(ao);
  H5Fclose(file);
}

// Adds a variable-length string attribute (h5py's kind for a str, or a list of them) to `location`.
void vlen_attr(hid_t location, const char* name, const std::vector<const char*>& texts, bool scalar) {
  const hid_t type = checked(H5Tcopy(H5T_C_S1), "H5Tcopy");
  H5Tset_size(type, H5T_VARIABLE);
  H5Tset_cset(type, H5T_CSET_UTF8);
  const hsize_t n = texts.size();
  const hid_t space = checked(scalar ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &n, nullptr), "H5Screate");
  const hid_t attr = checked(H5Acreate2(location, name, type, space, H5P_DEFAULT, H5P_DEFAULT), name);
  H5Awrite(attr, type, texts.data());
  H5Aclose(attr), H5Sclose(space), H5Tclose(type);
}

void write_annotated(const fs::path& path) {
  pf::write_asset(path, vertex_asset());
  const hid_t file = checked(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), "H5Fopen");
  vlen_attr(file, "note", {"root note \u2713"}, true);
  vlen_attr(file, "tags", {"a", "bb", "ccc"}, false);
  const hid_t mesh = checked(H5Gopen2(file, "/mesh", H5P_DEFAULT), "H5Gopen2");
  vlen_attr(mesh, "note", {"group note"}, true);
  H5Gclose(mesh);
  const hid_t ao = checked(H5Dopen2(file, "/ao", H5P_DEFAULT), "H5Dopen2");
  vlen_attr(ao, "note", {"dataset note"}, true);
  H5Dclose(ao);
  if (H5Fclose(file) < 0) throw std::runtime_error("HDF5: H5Fclose failed");
}

} // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_seeds <directory>\n");
    return 2;
  }
  try {
    const fs::path dir = argv[1];
    fs::create_directories(dir / "exr");
    fs::create_directories(dir / "prt");
    write_exr(dir / "exr" / "latlong.exr", 16, 8, Imf::ENVMAP_LATLONG, Imf::NO_COMPRESSION);
    write_exr(dir / "exr" / "latlong_zip.exr", 16, 8, Imf::ENVMAP_LATLONG, Imf::ZIP_COMPRESSION);
    write_exr(dir / "exr" / "cube.exr", 4, 24, Imf::ENVMAP_CUBE, Imf::NO_COMPRESSION);
    pf::write_asset(dir / "prt" / "vertex.prt.h5", vertex_asset());
    pf::write_asset(dir / "prt" / "fiv.prt.h5", fiv_asset());
    pf::Asset half = fiv_asset();  // the same occluder in half floats (format_version 8)
    half.occluders[0].float16 = true;
    pf::write_asset(dir / "prt" / "fiv_float16.prt.h5", half);
    pf::Asset scene = fiv_asset();  // a scene file whose object "tetra" has self-shadows (format_version 9)
    scene.scene.emplace().scene_file = "scene.json";
    pf::SceneObject& tetra = scene.objects.emplace_back();
    tetra.name = "tetra";
    tetra.role = "occluder";
    tetra.set = vertex_asset().vertices;
    tetra.set.ao.reset(), tetra.set.transfer_diffuse.reset(), tetra.set.transfer_visibility.reset();
    tetra.set.radiance_band1.reset();
    scene.occluders[0].self_band1 = pf::OccluderSelfBand1{ramp(4 * 9, 0.02f, 0.1f), "self", {}};
    pf::write_asset(dir / "prt" / "fiv_scene_self.prt.h5", scene);
    write_old_format(dir / "prt" / "old_format.prt.h5");
    write_annotated(dir / "prt" / "annotated.prt.h5");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_seeds: %s\n", e.what());
    return 1;
  }
  return 0;
}
