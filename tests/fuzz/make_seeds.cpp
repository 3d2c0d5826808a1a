// tests/fuzz/make_seeds.cpp — writes the binary seeds of the fuzz targets that are not committed
// (docs/RELIABILITY.md "Fuzzing"), at build time, into the directory given:
//   exr/latlong.exr, exr/latlong_zip.exr, exr/cube.exr   tiny environment maps (OpenEXR's own
//        writer: a 16×8 lat-long, uncompressed and ZIP; a 4×24 cube map), for fuzz_exr;
//   prt/vertex.prt.h5, prt/fiv.prt.h5   small files from our writer (formats::write_asset): a
//        tetrahedron's vertex products (ao, diffuse and visibility transfer, band-1 radiance);
//        an FIV file (environment, DifMap, one occluder), for fuzz_prt_dump and fuzz_prt_loader.
// Deterministic: the same bytes every build (no clock, no random numbers).
#include <formats/asset.h>

#include <ImfEnvmapAttribute.h>
#include <ImfHeader.h>
#include <ImfRgbaFile.h>
#include <ImfStandardAttributes.h>

#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
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
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_seeds: %s\n", e.what());
    return 1;
  }
  return 0;
}
