// view/: PNG files (libpng's output decoded by Python's zlib, an independent inflater, and read
// back through libpng), tone mapping and NRMSE, the camera's text form, rasterizer coverage and
// perspective-correct interpolation against closed forms, the unshadowed irradiance the reference
// uses (bake/environment/irradiance.h) against the DifMap and the flat texel sum, and the reference renderer
// against π·L and Lambert's form factor.
#include <view/camera.h>
#include <view/image.h>
#include <view/lightmap.h>
#include <view/raster.h>
#include <view/reference.h>

#include <bake/bake/fiv.h>
#include <bake/core/error.h>
#include <bake/environment/envmap.h>
#include <bake/environment/irradiance.h>
#include <bake/mesh/mesh.h>
#include <bake/sphere/sampling.h>

#include <test_scenes.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <unistd.h>

using namespace prt::bake;
using namespace prt::view;
using Eigen::Vector3d;
using Eigen::Vector3f;
using std::numbers::pi;
namespace fs = std::filesystem;

namespace {

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(PRT_TEST_TMP) / "render";
  fs::create_directories(dir);
  return dir / (std::to_string(getpid()) + "." + name);
}

std::vector<uint8_t> read_bytes(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

// Inflates a zlib stream with Python's zlib (which also verifies the Adler-32 trailer). Sets ok.
std::vector<uint8_t> python_inflate(const std::vector<uint8_t>& z, bool& ok) {
  const fs::path in = scratch("z.in"), out = scratch("z.out");
  std::ofstream(in, std::ios::binary).write(reinterpret_cast<const char*>(z.data()), std::streamsize(z.size()));
  const std::string cmd = "python3 -c \"import sys, zlib; open(sys.argv[2], 'wb').write(zlib.decompress(open(sys.argv[1], "
                          "'rb').read()))\" " + in.string() + " " + out.string();
  ok = std::system(cmd.c_str()) == 0;
  auto bytes = read_bytes(out);
  fs::remove(in);
  fs::remove(out);
  return bytes;
}

uint32_t be32(const uint8_t* p) { return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | p[3]; }

} // namespace

TEST(Png, ChunksAndPixelsDecode) {
  Image8 img(37, 23);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      for (int c = 0; c < 3; ++c) img.rgb[size_t(3 * (y * img.width + x) + c)] = uint8_t((x * 7 + y * 13 * (c + 1) + (x * y) % 5) & 0xFF);
  const fs::path file = scratch("chunks.png");
  write_png(file, img);
  const auto png = read_bytes(file);
  fs::remove(file);
  ASSERT_GT(png.size(), 8u);
  const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  ASSERT_TRUE(std::equal(sig, sig + 8, png.begin()));
  std::vector<uint8_t> idat;
  std::vector<std::string> types;
  size_t pos = 8;
  while (pos + 12 <= png.size()) {
    const uint32_t len = be32(&png[pos]);
    ASSERT_LE(pos + 12 + len, png.size());
    const std::string type(png.begin() + std::ptrdiff_t(pos + 4), png.begin() + std::ptrdiff_t(pos + 8));
    types.push_back(type);
    if (type == "IHDR") {
      EXPECT_EQ(be32(&png[pos + 8]), 37u);
      EXPECT_EQ(be32(&png[pos + 12]), 23u);
      EXPECT_EQ(png[pos + 16], 8);  // bit depth
      EXPECT_EQ(png[pos + 17], 2);  // RGB
    }
    if (type == "IDAT") idat.insert(idat.end(), png.begin() + std::ptrdiff_t(pos + 8), png.begin() + std::ptrdiff_t(pos + 8 + len));
    pos += 12 + len;
  }
  EXPECT_EQ(pos, png.size());
  ASSERT_FALSE(types.empty());
  EXPECT_EQ(types.front(), "IHDR");
  EXPECT_EQ(types.back(), "IEND");
  EXPECT_NE(std::find(types.begin(), types.end(), "sRGB"), types.end());  // the pixels are sRGB-encoded
  bool ok = false;
  const auto raw = python_inflate(idat, ok);
  ASSERT_TRUE(ok);
  const size_t stride = size_t(img.width) * 3;
  ASSERT_EQ(raw.size(), (stride + 1) * size_t(img.height));
  // Undo the filters (PNG spec §9) and compare every byte.
  std::vector<uint8_t> prev(stride, 0), cur(stride);
  for (int y = 0; y < img.height; ++y) {
    const uint8_t type = raw[size_t(y) * (stride + 1)];
    ASSERT_LE(type, 4);
    const uint8_t* f = &raw[size_t(y) * (stride + 1) + 1];
    for (size_t i = 0; i < stride; ++i) {
      const int a = i >= 3 ? cur[i - 3] : 0, b = prev[i], c = i >= 3 ? prev[i - 3] : 0;
      int pred = 0;
      if (type == 1) pred = a;
      else if (type == 2) pred = b;
      else if (type == 3) pred = (a + b) / 2;
      else if (type == 4) {
        const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
        pred = (pa <= pb && pa <= pc) ? a : (pb <= pc ? b : c);
      }
      cur[i] = uint8_t((f[i] + pred) & 0xFF);
    }
    for (size_t i = 0; i < stride; ++i) ASSERT_EQ(cur[i], img.rgb[size_t(y) * stride + i]) << "row " << y;
    prev = cur;
  }
}

TEST(Png, WriteIsAtomicAndFailureLeavesNothing) {
  const fs::path p = scratch("a.png");
  Image8 img(4, 3, 200);
  img.rgb[7] = 3;
  write_png(p, img);
  const Image8 back = read_png(p);  // libpng reads back exactly the bytes written
  EXPECT_EQ(back.width, 4);
  EXPECT_EQ(back.height, 3);
  EXPECT_EQ(back.rgb, img.rgb);
  fs::remove(p);
  EXPECT_THROW(read_png(p), InputError);  // gone: a missing file is bad input, named
  const fs::path bad = fs::path(PRT_TEST_TMP) / "no-such-dir" / "x.png";
  EXPECT_THROW(write_png(bad, Image8(4, 3)), InputError);
  EXPECT_FALSE(fs::exists(bad));
}

TEST(ToneMap, SrgbEndpointsAndExposure) {
  Image im(4, 1);
  const float v[4] = {0.0f, 1.0f, 0.5f, 10.0f};
  for (int x = 0; x < 4; ++x)
    for (int c = 0; c < 3; ++c) im.at(x, 0)[c] = v[x];
  const Image8 t = tone_map(im, 1.0);
  EXPECT_EQ(t.rgb[0], 0);
  EXPECT_EQ(t.rgb[3], 255);
  EXPECT_EQ(t.rgb[6], 188);  // 1.055 · 0.5^(1/2.4) − 0.055 = 0.7354 → 187.5 → 188
  EXPECT_EQ(t.rgb[9], 255);  // clipped
  EXPECT_EQ(tone_map(im, 0.1).rgb[9], 255);  // 10 · 0.1 = 1
}

TEST(Nrmse, IdenticalIsZeroAndOffsetIsClosedForm) {
  Image ref(8, 8), test(8, 8);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x)
      for (int c = 0; c < 3; ++c) ref.at(x, y)[c] = float(x + 2 * y + c);  // min 0, max 7 + 14 + 2 = 23
  auto e = compare_images(ref, ref);
  EXPECT_EQ(e.rmse, 0.0);
  EXPECT_EQ(e.nrmse, 0.0);
  EXPECT_EQ(e.pixels, 64u);
  for (size_t i = 0; i < test.rgb.size(); ++i) test.rgb[i] = ref.rgb[i] + 0.5f;
  e = compare_images(test, ref);
  EXPECT_NEAR(e.rmse, 0.5, 1e-12);  // every difference is 0.5 exactly (floats of small integers + ½)
  EXPECT_NEAR(e.nrmse, 0.5 / 23.0, 1e-12);
  // A mask restricts both the error and the range: pixel (0,0) only → range 2 (its channels 0, 1, 2).
  std::vector<uint8_t> mask(64, 0);
  mask[0] = 1;
  e = compare_images(test, ref, mask);
  EXPECT_EQ(e.pixels, 1u);
  EXPECT_NEAR(e.nrmse, 0.25, 1e-12);
  // Reference noise σ = 0.3 everywhere: noise-corrected RMSE = sqrt(0.25 − 0.09) = 0.4.
  Image se(8, 8);
  for (float& s : se.rgb) s = 0.3f;
  e = compare_images(test, ref, {}, &se);
  EXPECT_NEAR(e.ref_noise, 0.3 / 23.0, 1e-7);  // float 0.3
  EXPECT_NEAR(e.nrmse_noise_corrected, 0.4 / 23.0, 1e-7);
  // Relative L2 (issue 31's measure): a test 1.25 × the reference is off by exactly 0.25 of it
  // (x · 1.25 is exact in float for these small integers); with the reference's noise σ = 0.25 x
  // per value the squared error 0.0625 Σx² less Σσ² = 0.0625 Σx² leaves 0.
  Image scaled(8, 8), se_scaled(8, 8);
  for (size_t i = 0; i < ref.rgb.size(); ++i) scaled.rgb[i] = 1.25f * ref.rgb[i], se_scaled.rgb[i] = 0.25f * ref.rgb[i];
  e = compare_images(scaled, ref);
  EXPECT_NEAR(e.relative_l2, 0.25, 1e-12);
  e = compare_images(scaled, ref, {}, &se_scaled);
  EXPECT_NEAR(e.relative_l2, 0.25, 1e-12);
  EXPECT_NEAR(e.relative_l2_noise_corrected, 0.0, 1e-6);
  EXPECT_EQ(compare_images(ref, ref).relative_l2, 0.0);
}

// ---- camera -----------------------------------------------------------------------------------------

TEST(Camera, ParsesAndRejects) {
  const Camera c = parse_camera("eye=0,1,5:at=0,1,0:fov=30", 64, 32);
  EXPECT_EQ(c.eye, Vector3d(0, 1, 5));
  EXPECT_EQ(c.fov_y_degrees, 30);
  // The centre of the picture looks along forward; the top edge centre is fov/2 above it.
  EXPECT_NEAR((c.ray_direction(32, 16) - Vector3d(0, 0, -1)).norm(), 0, 1e-15);
  EXPECT_NEAR(std::acos(c.ray_direction(32, 0).dot(c.forward())), 15 * pi / 180, 1e-12);
  for (const char* bad : {"", "eye=0,0,1", "eye=0,0,1:at=0,0,1", "eye=0,0,1:at=0,0,0:up=0,0,1", "eye=0,0:at=0,0,0",
                          "eye=0,0,1:at=0,0,0:fov=180", "eye=0,0,1:at=0,0,0:zoom=2", "eye=a,0,1:at=0,0,0",
                          "eye=0,0,1:at=0,0,0:eye=1,1,1"})
    EXPECT_THROW(parse_camera(bad, 8, 8), InputError) << bad;
  try {
    parse_camera("eye=0,0,1:at=0,0,0:zoom=2", 8, 8);
    ADD_FAILURE() << "zoom accepted";
  } catch (const InputError& e) {
    // The library names the value and what is wrong with it, never a tool's option.
    EXPECT_EQ(std::string(e.what()), "camera spec 'eye=0,0,1:at=0,0,0:zoom=2': unknown key 'zoom' (keys: eye, at, up, fov)");
  }
  EXPECT_EQ(parse_size("256x128"), (std::array<int, 2>{256, 128}));
  for (const char* bad : {"256", "0x5", "x", "12x-3", "100000x2"}) EXPECT_THROW(parse_size(bad), InputError) << bad;
  try {
    parse_size("0x5");
    ADD_FAILURE() << "0x5 accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "image size '0x5': width and height must be in [1, 16384]");
  }
}

TEST(Camera, FrameBoxShowsEveryCornerAndItsTextFormReadsBack) {
  // frame_box: each of the box's corners projects inside the picture, |x/z| <= aspect tan(fov/2)
  // and |y/z| <= tan(fov/2) in camera space, and the nearest fit leaves a 5% margin: the widest
  // corner is at 1/1.05 of the half-width or half-height (to rounding).
  const Vector3d lo(-3, 0.5, -1), hi(5, 2, 9);
  for (const Vector3d& up : {Vector3d(0, 1, 0), Vector3d(0, 0, 1)})
    for (const auto& [W, H] : {std::pair{200, 100}, std::pair{100, 200}, std::pair{64, 64}}) {
      const Camera c = frame_box(lo, hi, up, W, H);
      ASSERT_EQ(c.problem(), "");
      EXPECT_NEAR((c.at - 0.5 * (lo + hi)).norm(), 0, 1e-12);
      EXPECT_GT(c.true_up().dot(up), 0.5) << "the box's up is the picture's up";
      EXPECT_LT(c.forward().dot(up), -0.3) << "looking down at it";
      const double t = std::tan(0.5 * c.fov_y_degrees * pi / 180), aspect = double(W) / H;
      double widest = 0;
      for (int k = 0; k < 8; ++k) {
        const Vector3d q(k & 1 ? hi.x() : lo.x(), k & 2 ? hi.y() : lo.y(), k & 4 ? hi.z() : lo.z());
        const Vector3d v = q - c.eye;
        const double z = v.dot(c.forward());
        ASSERT_GT(z, c.near_depth());
        EXPECT_LE(std::abs(v.dot(c.right()) / z), aspect * t) << "corner " << k << " " << W << "x" << H;
        EXPECT_LE(std::abs(v.dot(c.true_up()) / z), t) << "corner " << k << " " << W << "x" << H;
        widest = std::max({widest, std::abs(v.dot(c.right()) / z) / (aspect * t), std::abs(v.dot(c.true_up()) / z) / t});
      }
      EXPECT_NEAR(widest, 1 / 1.05, 1e-9) << "the nearest distance that shows every corner";
      // The text form reads back to the same camera (9 significant digits).
      const Camera back = parse_camera(to_string(c), W, H);
      EXPECT_LT((back.eye - c.eye).norm(), 1e-8 * c.eye.norm() + 1e-12);
      EXPECT_LT((back.at - c.at).norm(), 1e-8 * (c.eye - c.at).norm());
      EXPECT_NEAR(back.fov_y_degrees, c.fov_y_degrees, 1e-12);
    }
  // A point: the box of half-size 1 around it.
  const Camera p = frame_box(Vector3d(1, 2, 3), Vector3d(1, 2, 3), Vector3d(0, 1, 0), 64, 64);
  EXPECT_EQ(p.problem(), "");
  EXPECT_NEAR((p.at - Vector3d(1, 2, 3)).norm(), 0, 1e-15);
  EXPECT_GT((p.eye - p.at).norm(), std::sqrt(3.0)) << "outside the box";
}

// ---- rasterizer ---------------------------------------------------------------------------------------

namespace {

// Looking down −Z from (0, 0, d) at the plane z = 0 with a 90° vertical fov: the visible square is
// [−d·a, d·a] × [−d, d] (a = W/H), pixel (x, y) ↔ world (d a (2(x+½)/W − 1), d (1 − 2(y+½)/H)).
Camera top_camera(int W, int H, double d = 2) {
  Camera c;
  c.eye = {0, 0, d};
  c.at = {0, 0, 0};
  c.up = {0, 1, 0};
  c.fov_y_degrees = 90;
  c.width = W;
  c.height = H;
  return c;
}

// World point of continuous pixel position (sx, sy) on z = 0 for top_camera.
Vector3f world_of_pixel(const Camera& c, double sx, double sy) {
  const double d = c.eye.z(), a = double(c.width) / c.height, t = std::tan(0.5 * c.fov_y_degrees * pi / 180);
  return Vector3f(float(d * a * t * (2 * sx / c.width - 1)), float(d * t * (1 - 2 * sy / c.height)), 0.0f);
}

// Coverage count per pixel when each triangle of `mesh` is rasterized alone.
std::vector<int> coverage(const Mesh& mesh, const Camera& cam) {
  std::vector<int> count(size_t(cam.width) * size_t(cam.height), 0);
  for (const auto& t : mesh.triangles) {
    const Mesh one = make_mesh(mesh.positions, {t}, "one", mesh.normals);
    const GBuffer g = rasterize(one, cam);
    for (size_t i = 0; i < count.size(); ++i) count[i] += g.triangle[i] >= 0;
  }
  return count;
}

} // namespace

TEST(Rasterizer, ScreenFillingQuadCoversEveryPixelOnce) {
  const Camera cam = top_camera(40, 30);
  // Corners exactly on the frustum's edges (pixel boundaries x = 0, W; y = 0, H).
  std::vector<Vector3f> p = {world_of_pixel(cam, 0, 0), world_of_pixel(cam, 40, 0), world_of_pixel(cam, 40, 30),
                             world_of_pixel(cam, 0, 30)};
  const Mesh quad = make_mesh(p, {{0, 1, 2}, {0, 2, 3}}, "quad");
  const auto count = coverage(quad, cam);
  for (size_t i = 0; i < count.size(); ++i) ASSERT_EQ(count[i], 1) << "pixel " << i;
  EXPECT_EQ(rasterize(quad, cam).covered(), size_t(40 * 30));
}

TEST(Rasterizer, SharedEdgesThroughPixelCentresCoverEachPixelOnce) {
  // A fan of 8 triangles around a vertex at a pixel centre, its spokes horizontal, vertical and
  // diagonal through pixel centres: exactly the edge/vertex ties the top-left rule must settle.
  const Camera cam = top_camera(32, 32);
  std::vector<Vector3f> p = {world_of_pixel(cam, 16.5, 16.5)};
  const int ring[8][2] = {{26, 16}, {26, 6}, {16, 6}, {6, 6}, {6, 16}, {6, 26}, {16, 26}, {26, 26}};
  for (const auto& r : ring) p.push_back(world_of_pixel(cam, r[0] + 0.5, r[1] + 0.5));
  std::vector<std::array<uint32_t, 3>> t;
  for (uint32_t k = 0; k < 8; ++k) t.push_back({0, 1 + k, 1 + (k + 1) % 8});
  const Mesh fan = make_mesh(p, t, "fan");
  const auto count = coverage(fan, cam);
  int total = 0;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      const int c = count[size_t(y * 32 + x)];
      ASSERT_LE(c, 1) << x << "," << y;
      if (x > 6 && x < 26 && y > 6 && y < 26) {  // strictly inside the square
        ASSERT_EQ(c, 1) << x << "," << y;
      }
      total += c;
    }
  // The square's boundary pixel centres lie on edges: the top-left rule gives the top row and the
  // left column to the fan and the bottom row and right column to the outside: 20 × 20 pixels.
  EXPECT_EQ(total, 20 * 20);
}

TEST(Rasterizer, PerspectiveCorrectPositionsAndClipping) {
  // A tilted quad crossing the camera plane (clipped) seen in perspective: the interpolated world
  // position of every covered pixel must be the closed-form ray/plane intersection through the pixel
  // centre. Tolerance 2e-5 · scene size: barycentrics are stored as float (ulp 6e-8), positions as
  // float, and the ray direction is exact in double.
  Camera cam;
  cam.eye = {0, 1, 0};
  cam.at = {0, 0.2, -3};
  cam.fov_y_degrees = 70;
  cam.width = 48;
  cam.height = 40;
  const Vector3d n = Vector3d(0.1, 1, 0.05).normalized();
  const double offset = 0.0;  // plane n·x = 0 through the origin
  auto on_plane = [&](double x, double z) {  // solve n·(x, y, z) = 0 for y
    return Vector3f(float(x), float(-(n.x() * x + n.z() * z) / n.y()), float(z));
  };
  const Mesh quad = make_mesh({on_plane(-20, 20), on_plane(20, 20), on_plane(20, -20), on_plane(-20, -20)},
                              {{0, 1, 2}, {0, 2, 3}}, "plane");
  const GBuffer g = rasterize(quad, cam);
  size_t checked = 0;
  double worst = 0;
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      const Fragment f = make_fragment(quad, g, x, y);
      const Vector3d d = cam.ray_direction(x + 0.5, y + 0.5);
      const double t = (offset - n.dot(cam.eye)) / n.dot(d);
      const bool hits = t > 0 && std::abs((cam.eye + t * d).x()) < 20 && std::abs((cam.eye + t * d).z()) < 20;
      if (!hits) {
        EXPECT_LT(f.triangle, 0) << x << "," << y;
        continue;
      }
      ASSERT_GE(f.triangle, 0) << x << "," << y;
      worst = std::max(worst, (f.p - (cam.eye + t * d)).norm());
      EXPECT_NEAR(g.depth[size_t(y * cam.width + x)], t * d.dot(cam.forward()), 2e-5 * 40 + 1e-5 * t);
      ++checked;
    }
  EXPECT_GT(checked, size_t(cam.width * cam.height / 3));
  EXPECT_LT(worst, 2e-5 * 40);
  // The ray tracer's primary hits see the same triangles at the same points.
  const ReferenceRenderer rr(quad, EnvMap::constant({1, 1, 1}), {});
  const GBuffer h = rr.trace_primary(cam);
  size_t same = 0;
  for (size_t i = 0; i < g.triangle.size(); ++i) same += (g.triangle[i] >= 0) == (h.triangle[i] >= 0);
  EXPECT_GE(same, g.triangle.size() - 2);  // the far edge may flip a pixel or two (float ray vs double edge)
}

TEST(Rasterizer, GouraudInterpolationIsExactForLinearAttributes) {
  // Per-vertex colour = world x: the interpolated colour must equal the fragment's x (linear in
  // the triangle), to float precision.
  const Camera cam = top_camera(24, 24);
  std::vector<Vector3f> p = {world_of_pixel(cam, 1, 2), world_of_pixel(cam, 23, 5), world_of_pixel(cam, 8, 22)};
  p[1].z() = -1.0f;  // tilted: perspective matters
  const Mesh tri = make_mesh(p, {{0, 1, 2}}, "tri");
  std::vector<float> rgb;
  for (const auto& q : p) rgb.insert(rgb.end(), {q.x(), q.y(), q.z()});
  const GBuffer g = rasterize(tri, cam);
  const Image im = interpolate_vertices(tri, g, rgb);
  ASSERT_GT(g.covered(), 50u);
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 24; ++x) {
      const Fragment f = make_fragment(tri, g, x, y);
      if (f.triangle < 0) continue;
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(im.at(x, y)[c], f.p[c], 1e-5);
    }
}

// ---- irradiance and the reference ----------------------------------------------------------------------------

TEST(UnshadowedIrradiance, IsTheDifMapAndBoundsTheFlatSum) {
  const int W = 256, H = 128;
  std::vector<float> rgb(size_t(W * H * 3));
  uint64_t h = 7;
  for (float& v : rgb) v = 0.5f + float(to_unit(h = mix64(h)));  // in [0.5, 1.5)
  const EnvMap env = EnvMap::from_latlong(W, H, rgb, UpAxis::Y, "random");
  const UnshadowedIrradiance E(env);
  // (a) The DifMap of FIV files is this function at the cube directions, rounded to float: one
  // definition, bit for bit.
  const auto cube = irradiance_cube(env, 3);
  for (int face = 0; face < 6; ++face)
    for (int r = 0; r < 3; ++r)
      for (int q = 0; q < 3; ++q) {
        const Rgb e = E(gl_cube_direction(face, r, q, 3));
        const size_t i = size_t(((face * 3 + r) * 3 + q) * 3);
        EXPECT_EQ(float(e.r), cube[i]);
        EXPECT_EQ(float(e.g), cube[i + 1]);
        EXPECT_EQ(float(e.b), cube[i + 2]);
      }
  // (b) The cell hierarchy is the texel-by-texel sum up to summation order (rounding), and (c)
  // within the horizon bound of the flat sum Σ_t L_t max(0, n·M_t) (same M_t recipe): a texel cut
  // by the horizon counts max(0, n·M_t) there instead of ∫_texel H (n·ω), a difference of at most
  // ∫_texel |n·ω| ≤ Ω_t δ_t; over the ≈ 2π/δ texels along the horizon, 2π δ² L_max with δ the
  // largest texel diameter (√2 · 2π/(W−1) at the equator).
  std::vector<Vector3d> M(size_t(env.texel_count()));
  for (int t = 0; t < env.texel_count(); ++t) {
    Vector3d m = Vector3d::Zero();
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) m += env.sample_texel(t, (a + 0.5) / 4, (b + 0.5) / 4);
    M[size_t(t)] = m * env.texel_solid_angle(t) / 16;
  }
  const double delta = std::sqrt(2.0) * 2 * pi / (W - 1), bound = 2 * pi * delta * delta * 1.5;
  for (int k = 0; k < 12; ++k) {
    const double u0 = to_unit(h = mix64(h)), u1 = to_unit(h = mix64(h));
    const Vector3d n = uniform_sphere(u0, u1);
    const double e = E(n).r;
    EXPECT_NEAR(e, E.reference(n).r, 1e-11 * e);
    double flat = 0;
    for (int t = 0; t < env.texel_count(); ++t) flat += env.texel_value(t).r * std::max(0.0, n.dot(M[size_t(t)]));
    EXPECT_NEAR(e, flat, bound);
  }
  // Constant environment: π L exactly.
  const EnvMap two = EnvMap::constant({2, 2, 2});
  EXPECT_EQ(UnshadowedIrradiance(two)(Vector3d(0, 1, 0)).r, 2 * pi);
}

TEST(Reference, UnoccludedPlaneUnderConstantSkyIsPiL) {
  const Mesh ground = ground_quad(0.0, 0.0, 0.0, 5.0);
  const EnvMap env = EnvMap::constant({0.5, 1.0, 2.0});
  ReferenceOptions opt;
  opt.samples = 64;
  const ReferenceRenderer rr(ground, env, opt);
  Camera cam;
  cam.eye = {0, 3, 4};
  cam.at = {0, 0, 0};
  cam.width = cam.height = 24;
  const ReferenceImage ref = rr.render(cam);
  ASSERT_GT(ref.gbuffer.covered(), 100u);
  const double L[3] = {0.5, 1.0, 2.0};
  for (size_t i = 0; i < ref.gbuffer.triangle.size(); ++i) {
    if (ref.gbuffer.triangle[i] < 0) continue;
    // E/π = L: within 4 standard errors plus float rounding of the stored value (the plane cannot
    // shadow itself, so the QMC term is exactly 0 and so is its standard error).
    for (size_t c = 0; c < 3; ++c) {
      EXPECT_NEAR(ref.radiance.rgb[3 * i + c], L[c], 4 * ref.std_error.rgb[3 * i + c] + 1e-6 * L[c]);
      EXPECT_EQ(ref.std_error.rgb[3 * i + c], 0.0f);
    }
  }
}

TEST(Reference, GlossyLobeUnderACapShapedOccluderMatchesItsClosedForm) {
  // Glossy mode at a ground point p = 0 with n = +y and the eye straight above (r = n): under a
  // constant sky L the integral is L ∫_visible k_s(n·ω) dω. With nothing above, the lobe lies in the
  // upper hemisphere: L exactly in expectation. Under an occluding disk at height 1 of angular
  // radius α about +y: L (1 − (1 − cos^{s+1} α)) = L cos^{s+1} α (∫_cap k_s = 1 − cos^{s+1} α). The
  // disk is a 512-gon inscribed in the circle: the missing sliver is < (2π²/3)/512² ≈ 3e-5 of
  // the cap's solid angle and k_s ≤ (s+1)/(2π) there, so the value moves by < 3e-5 · 2π(1 − cos α)
  // · (s+1)/(2π) < 2e-4 L. Tolerance: 4 standard errors of the replicates plus that.
  const double s = 4, alpha = 30 * pi / 180, L = 0.75;
  const EnvMap env = EnvMap::constant({L, L, L});
  Mesh disk;
  const int N = 512;
  const double R = std::tan(alpha);
  disk.positions.push_back(Vector3f(0, 1, 0));
  for (int k = 0; k < N; ++k)
    disk.positions.push_back(Vector3f(float(R * std::cos(2 * pi * k / N)), 1.0f, float(R * std::sin(2 * pi * k / N))));
  for (uint32_t k = 0; k < uint32_t(N); ++k) disk.triangles.push_back({0, 1 + k, 1 + (k + 1) % uint32_t(N)});
  disk = make_mesh(disk.positions, disk.triangles, "disk");
  const Mesh ground = ground_quad(0.0, 0.0, 0.0, 5.0);
  const std::vector<Mesh> parts = {ground, disk};
  const Mesh scene = merge_meshes(parts, "glossy");
  Fragment f;
  f.triangle = 0;
  f.p = {0, 0, 0};
  for (bool occluded : {false, true}) {
    ReferenceOptions opt;
    opt.samples = 4096;
    opt.casts_shadow.assign(scene.triangles.size(), occluded ? 1 : 0);
    for (size_t t = 0; t < ground.triangles.size(); ++t) opt.casts_shadow[t] = 0;
    opt.glossy = ReferenceOptions::Glossy{Vector3d(0, 5, 0), std::vector<double>(scene.triangles.size(), s),
                                          std::vector<std::array<float, 3>>(scene.triangles.size(), {1, 1, 1})};
    const ReferenceRenderer rr(scene, env, opt);
    double G[3], se[3];
    rr.glossy(f, 7, s, G, se);
    const double expect = occluded ? L * std::pow(std::cos(alpha), s + 1) : L;
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(G[c], expect, 4 * se[c] + 2e-4 * L) << (occluded ? "under the disk" : "open sky");
      EXPECT_LT(se[c], 0.01 * L) << "the lobe half of the mixture keeps the estimate tight";
    }
  }
}

TEST(Reference, SquareOccluderMatchesLambertFormFactor) {
  // A 2 × 2 square at height 1 over a ground plane, constant sky L: at a ground point, E = π L (1 − F)
  // with F the square's form factor (Lambert's polygon formula, tests/common/test_scenes.h).
  std::vector<Vector3f> p = {{-1, 1, -1}, {1, 1, -1}, {1, 1, 1}, {-1, 1, 1}};
  const Mesh square = make_mesh(p, {{0, 2, 1}, {0, 3, 2}}, "square");
  const Mesh ground = ground_quad(0.0, 0.0, 0.0, 10.0);
  const Mesh parts[2] = {ground, square};
  const Mesh scene = merge_meshes(parts, "scene");
  const EnvMap env = EnvMap::constant({1, 1, 1});
  std::vector<Vector3d> poly = {{-1, 1, -1}, {1, 1, -1}, {1, 1, 1}, {-1, 1, 1}};
  for (bool cones : {false, true}) {
    ReferenceOptions opt;
    opt.samples = 4096;
    if (cones) opt.occluder_spheres.push_back({Vector3d(0, 1, 0), std::sqrt(2.0)});
    const ReferenceRenderer rr(scene, env, opt);
    for (double x : {0.0, 0.7, 1.5, 3.0}) {
      Fragment f;
      f.triangle = 0;
      f.p = {x, 0, 0.3};
      f.n = f.ng = {0, 1, 0};
      double E[3], se[3];
      rr.irradiance(f, uint64_t(x * 10), E, se);
      const double F = prt::testing::polygon_form_factor(f.p, f.n, poly);
      EXPECT_GT(se[0], 0.0);
      // Unbiased; the standard error comes from 8 replicates, so (E − exact)/se is Student-t with
      // 7 degrees of freedom: 5.41 is its two-sided 0.999 quantile.
      EXPECT_NEAR(E[0], pi * (1 - F), 5.41 * se[0]) << "x " << x << " cones " << cones << " F " << F;
      EXPECT_LT(se[0], 0.02 * pi);  // and precise enough to mean something (2 % of π L at 4096 rays)
    }
  }
}

// ---- per-texel sampling (view/lightmap.h) ----------------------------------------------------

TEST(ViewLightmap, BilinearAtTexelCoordinatesWithClampToEdgeAndTheEmptyTexelCheck) {
  // A 3 x 2 map of one channel, value 10 y + x, texel (2, 1) empty (state 0, value 0).
  const std::vector<float> values = {0, 1, 2, 10, 11, 0};
  const std::vector<uint8_t> state = {1, 1, 3, 1, 2, 0};
  const prt::view::LightmapImage map{3, 2, 1, values, state};
  float out = -1;
  // A texel centre ((x + 1/2)/W, (y + 1/2)/H) gives the texel itself, with weight 0 elsewhere:
  // no empty texel is reached even beside one.
  EXPECT_FALSE(prt::view::sample_lightmap(map, 1.5 / 3, 1.5 / 2, &out));
  EXPECT_EQ(out, 11.0f);
  // Between the centres of (0, 0), (1, 0), (0, 1), (1, 1) at fractions (1/4, 1/2): a plane's
  // value 10 fy + fx, exact in binary.
  EXPECT_FALSE(prt::view::sample_lightmap(map, (0.5 + 0.25) / 3, (0.5 + 0.5) / 2, &out));
  EXPECT_EQ(out, 5.25f);
  // Outside [0, 1]: clamped to the edge texels' centres.
  EXPECT_FALSE(prt::view::sample_lightmap(map, -1, -1, &out));
  EXPECT_EQ(out, 0.0f);
  // A footprint with weight on the empty texel (2, 1) is reported.
  EXPECT_TRUE(prt::view::sample_lightmap(map, 2.25 / 3, 1.25 / 2, &out));
  // (1.75, 0.75) in texel coordinates: 0.25*0.25*1 + 0.75*0.25*2 + 0.25*0.75*11 + 0.75*0.75*0
  EXPECT_FLOAT_EQ(out, float(0.0625 + 0.375 + 2.0625));
}

TEST(ViewLightmap, AnyChannelCountIsSampledLikeOneChannel) {
  // A glossy lightmap holds 3 x order² floats per texel (363 at order 11). The same 3 x 2 map as
  // above with 363 channels, channel c holding (10 y + x) + c: each channel's sample is the
  // one-channel sample plus c (the weights sum to 1, exactly in binary at these fractions).
  constexpr size_t C = 363;
  const std::vector<float> base = {0, 1, 2, 10, 11, 20};
  std::vector<float> values(base.size() * C);
  for (size_t t = 0; t < base.size(); ++t)
    for (size_t c = 0; c < C; ++c) values[t * C + c] = base[t] + float(c);
  const std::vector<uint8_t> state(base.size(), 1);
  const prt::view::LightmapImage map{3, 2, C, values, state};
  std::vector<float> out(C, -1);
  EXPECT_FALSE(prt::view::sample_lightmap(map, (0.5 + 0.25) / 3, (0.5 + 0.5) / 2, out.data()));
  for (size_t c = 0; c < C; ++c) ASSERT_EQ(out[c], 5.25f + float(c)) << "channel " << c;
}
