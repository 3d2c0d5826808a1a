// bench_area_render — paper 003's equal-time comparison (§5): per-pixel direct lighting from area
// lights with exact soft shadows (view/area_lights.h render_area_analytic: bake/lights/area_bake.h per
// pixel) against Embree ray tracing with light sampling (render_area_reference), on one thread,
// next to each other in one run. The ray tracer runs at 1 shadow ray per pixel and light, and at
// the ray count that takes the analytic render's CPU time ("equal time"); both are compared with a
// converged ray-traced render (`--converged` rays per pixel and light, all threads: only its values
// matter), by NRMSE over the covered pixels (view/image.h compare_images) and by that NRMSE with
// the converged render's own noise taken out.
//
// Scene: a 10 × 10 ground, three boxes (one tall, one wide, one tilted... all axis-aligned boxes
// as one mesh), a 2 × 1.5 quad light, a second smaller quad tilted towards the boxes and a
// two-sided disc: soft and hard penumbrae, umbrae, and light grazing the ground.
//
// Two shadings, each its own table: diffuse (albedo 1), and diffuse (albedo 0.5) + a GGX layer
// (α 0.25, F0 0.04, the camera's eye; view/area_lights.h), whose analytic render goes through
// linearly transformed cosines (prtshade/ltc.h: not exact, within the LTC fit's error) and whose
// reference weighs each light sample by the BRDF.
//
// Usage: bench_area_render [--size WxH] [--converged N] [--images DIR]
//   DIR (default docs/images of the source tree): area_equal_time.png (analytic | 1 ray | equal
//   time | converged) and area_equal_time_error.png (|· − converged| false colour, same order
//   minus the last); area_equal_time_ggx.png and area_equal_time_ggx_error.png for the glossy one.
#include <view/area_lights.h>
#include <view/camera.h>
#include <view/image.h>
#include <view/raster.h>

#include <bake/lights/lights.h>
#include <bake/mesh/mesh.h>

#include <tbb/global_control.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <string>
#include <vector>

namespace {

using namespace prt;
using Eigen::Vector3d;
using Eigen::Vector3f;

bake::Mesh box(Vector3f lo, Vector3f hi) {
  std::vector<Vector3f> p;
  for (int k = 0; k < 8; ++k) p.emplace_back(k & 1 ? hi.x() : lo.x(), k & 2 ? hi.y() : lo.y(), k & 4 ? hi.z() : lo.z());
  std::vector<std::array<uint32_t, 3>> t = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                                             {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  return bake::make_mesh(std::move(p), std::move(t), "box");
}

bake::Mesh scene_mesh() {
  const bake::Mesh ground = bake::make_mesh({{-5, -5, 0}, {5, -5, 0}, {5, 5, 0}, {-5, 5, 0}}, {{0, 1, 2}, {0, 2, 3}}, "ground");
  const std::vector<bake::Mesh> parts = {ground, box({-1.5f, -0.5f, 0}, {-0.9f, 0.1f, 2.2f}),
                                         box({0.2f, -1.2f, 0}, {1.8f, -0.6f, 0.7f}), box({0.4f, 0.8f, 0}, {1.0f, 1.4f, 1.2f})};
  return bake::merge_meshes(parts, "ground and boxes");
}

std::vector<bake::AreaLight> scene_lights() {
  bake::AreaLight key = bake::make_quad_light({0.3, 0.0, 3.2}, {2.0, 0, 0}, {0, -1.5, 0});  // emits down
  key.name = "key";
  key.radiance = {5, 4.6, 4};
  bake::AreaLight fill = bake::make_quad_light({-3.0, 2.5, 1.8}, Vector3d(0.6, 0.6, 0), Vector3d(0.3, -0.3, -0.6));
  fill.name = "fill";
  fill.radiance = {1.5, 2.0, 3.0};
  bake::AreaLight disc = bake::make_disc_light({2.8, 2.2, 0.9}, {-1, -0.7, -0.2}, 0.35, 32);
  disc.name = "disc";
  disc.two_sided = true;
  disc.radiance = {6, 3, 1};
  std::vector<bake::AreaLight> lights = {key, fill, disc};
  for (const auto& l : lights) bake::validate_light(l, "bench_area_render", l.name);
  return lights;
}

double cpu_seconds() { return double(std::clock()) / CLOCKS_PER_SEC; }

constexpr double kGlossyAlpha = 0.25;

// The equal-time comparison for one shading (file comment): prints its table and writes
// <stem>.png (analytic | 1 ray | equal time | converged) and <stem>_error.png.
void compare(const bake::Mesh& mesh, const view::GBuffer& g, std::span<const bake::AreaLight> lights,
             const view::AreaRenderOptions& shading, uint32_t converged, const char* title, const char* analytic_name,
             const std::filesystem::path& stem) {
  std::vector<uint8_t> mask(size_t(g.width) * size_t(g.height));
  for (size_t i = 0; i < mask.size(); ++i) mask[i] = g.triangle[i] >= 0;
  // The converged render first, on every thread.
  view::AreaReferenceOptions conv;
  conv.samples = converged;
  conv.seed = 99;
  conv.render = shading;
  const auto w0 = std::chrono::steady_clock::now();
  const view::AreaReferenceImage truth = view::render_area_reference(mesh, g, lights, conv);
  const double conv_wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();

  view::Image analytic, one, equal;
  double t_analytic = 0, t_one = 0, t_equal = 0;
  uint32_t equal_rays = 1;
  {
    const tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
    double c = cpu_seconds();
    analytic = view::render_area_analytic(mesh, g, lights, shading);
    t_analytic = cpu_seconds() - c;
    view::AreaReferenceOptions ro;
    ro.samples = 1;
    ro.seed = 1;
    ro.render = shading;
    c = cpu_seconds();
    one = view::render_area_reference(mesh, g, lights, ro).radiance;
    t_one = cpu_seconds() - c;
    // Rays for equal time: a line t = a + b · rays through the 1-ray render and an 8-ray one
    // (a: the ray tracer's BVH and per-pixel setup), then one correction by the measured ratio.
    auto rays_for = [](double t) {
      return t < 8 ? uint32_t(std::max(1.0, std::round(t))) : 8 * uint32_t(std::max(1.0, std::round(t / 8)));
    };
    ro.samples = 8;
    c = cpu_seconds();
    (void)view::render_area_reference(mesh, g, lights, ro);
    const double t8 = cpu_seconds() - c;
    const double b = std::max((t8 - t_one) / 7, 1e-12), a = std::max(t_one - b, 0.0);
    equal_rays = rays_for((t_analytic - a) / b);
    for (int pass = 0; pass < 2; ++pass) {
      ro.samples = equal_rays;
      c = cpu_seconds();
      equal = view::render_area_reference(mesh, g, lights, ro).radiance;
      t_equal = cpu_seconds() - c;
      if (pass == 0) equal_rays = rays_for(double(equal_rays) * (t_analytic - a) / std::max(t_equal - a, 1e-12));
    }
  }
  const view::ImageError ea = view::compare_images(analytic, truth.radiance, mask, &truth.std_error);
  const view::ImageError e1 = view::compare_images(one, truth.radiance, mask, &truth.std_error);
  const view::ImageError ee = view::compare_images(equal, truth.radiance, mask, &truth.std_error);

  std::printf("%s. Converged: %u rays per pixel and light (seed 99), %.1f s wall on all threads; its own noise: %.2e of the range.\n\n", title,
              converged, conv_wall, ea.ref_noise);
  std::printf("| render | rays per pixel and light | CPU s | pixels/s | NRMSE vs converged | NRMSE, converged noise removed |\n");
  std::printf("|---|---:|---:|---:|---:|---:|\n");
  auto row = [&](const char* what, const std::string& rays, double t, const view::ImageError& e) {
    std::printf("| %s | %s | %.3f | %.0f | %.2e | %.2e |\n", what, rays.c_str(), t, double(g.covered()) / t, e.nrmse,
                e.nrmse_noise_corrected);
  };
  row(analytic_name, "-", t_analytic, ea);
  row("Embree, light sampling", "1", t_one, e1);
  row("Embree, light sampling, equal time", std::to_string(equal_rays), t_equal, ee);

  const double exposure = view::auto_exposure(truth.radiance, mask);
  const std::vector<view::Image8> strip = {view::tone_map(analytic, exposure), view::tone_map(one, exposure),
                                           view::tone_map(equal, exposure), view::tone_map(truth.radiance, exposure)};
  const std::filesystem::path strip_file = stem.string() + ".png", error_file = stem.string() + "_error.png";
  view::write_png(strip_file, view::hstack(strip));
  const double range = ea.ref_max - ea.ref_min;
  const std::vector<view::Image8> errs = {view::false_colour_error(analytic, truth.radiance, mask, range, 0.1),
                                          view::false_colour_error(one, truth.radiance, mask, range, 0.1),
                                          view::false_colour_error(equal, truth.radiance, mask, range, 0.1)};
  view::write_png(error_file, view::hstack(errs));
  std::printf("\nImages: %s (analytic | 1 ray | equal time | converged), %s (|render - converged|, full scale 10%% of the range)\n",
              strip_file.c_str(), error_file.c_str());
}

} // namespace

int main(int argc, char** argv) {
  int W = 320, H = 240;
  uint32_t converged = 2048;
  std::filesystem::path images = std::filesystem::path(PRT_SOURCE_DIR) / "docs" / "images";
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--size")) {
      const auto s = view::parse_size(argv[i + 1]);
      W = s[0];
      H = s[1];
    } else if (!std::strcmp(argv[i], "--converged")) {
      converged = uint32_t(std::strtoul(argv[i + 1], nullptr, 10));
    } else if (!std::strcmp(argv[i], "--images")) {
      images = argv[i + 1];
    } else {
      std::fprintf(stderr, "usage: bench_area_render [--size WxH] [--converged N] [--images DIR]\n");
      return 2;
    }
  }
  const bake::Mesh mesh = scene_mesh();
  const std::vector<bake::AreaLight> lights = scene_lights();
  view::Camera cam;
  cam.eye = {6.5, -7.5, 5.5};
  cam.at = {0.0, 0.0, 0.6};
  cam.up = {0, 0, 1};
  cam.fov_y_degrees = 38;
  cam.width = W;
  cam.height = H;
  const view::GBuffer g = view::rasterize(mesh, cam);
  std::printf("Scene: ground + 3 boxes (%zu triangles), %zu lights (2 quads, a 32-gon disc), %dx%d pixels, %zu covered; one thread.\n\n",
              mesh.triangles.size(), lights.size(), W, H, g.covered());
  std::filesystem::create_directories(images);
  view::AreaRenderOptions diffuse;
  compare(mesh, g, lights, diffuse, converged, "Diffuse (albedo 1)", "analytic (exact soft shadows)", images / "area_equal_time");
  view::AreaRenderOptions glossy;
  glossy.albedo = {0.5, 0.5, 0.5};
  glossy.ggx = view::GgxLayer{kGlossyAlpha, {0.04, 0.04, 0.04}, cam.eye};
  std::printf("\n");
  compare(mesh, g, lights, glossy, converged, "Diffuse (albedo 0.5) + GGX (alpha 0.25, F0 0.04)",
          "analytic (exact soft shadows, GGX by LTC)", images / "area_equal_time_ggx");
  return 0;
}
