#include <view/area_lights.h>

#include <bake/core/error.h>
#include <bake/lights/area_bake.h>
#include <bake/lights/punctual.h>
#include <bake/sphere/sampling.h>
#include <bake/sphere/spherical_polygon.h>
#include <bake/visibility/contour.h>
#include <bake/visibility/occluder_mesh.h>
#include <bake/visibility/raycast.h>

#include <prtshade/ltc.h>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <vector>

namespace prt::view {

using Eigen::Vector3d;

namespace {

constexpr uint32_t kReplicates = 8;

// The pixel's shading point p' = p + ε n_g and its normal (the file comment).
bake::ShadePoint shading_point(const Fragment& f, double epsilon) {
  bake::ShadePoint sp;
  sp.p = f.p + epsilon * f.ng;
  sp.n = f.n;
  return sp;
}

// A light's surface as triangles (each face's fan) in the mesh's frame, with the cumulative area.
struct LightSurface {
  struct Triangle {
    Vector3d a, ab, ac;  // a + u ab + v ac
    Vector3d normal;     // unit, towards the emitting side
  };
  std::vector<Triangle> triangles;
  std::vector<double> cdf;  // cumulative area, cdf.back() = the light's area
  bool two_sided = false;

  LightSurface(const bake::AreaLight& light, const Vector3d& origin) : two_sided(light.two_sided) {
    double total = 0;
    for (size_t f = 0; f < light.faces.size(); ++f) {
      const auto& face = light.faces[f];
      const Vector3d normal = light.face_normal(f);
      const Vector3d a = light.vertices[face[0]] - origin;
      for (size_t k = 1; k + 1 < face.size(); ++k) {
        const Vector3d b = light.vertices[face[k]] - origin, c = light.vertices[face[k + 1]] - origin;
        const double area = 0.5 * (b - a).cross(c - a).norm();
        if (!(area > 0)) continue;
        triangles.push_back({a, b - a, c - a, normal});
        total += area;
        cdf.push_back(total);
      }
    }
    PRT_CHECK(!triangles.empty());
  }
  double area() const { return cdf.back(); }

  // A point uniform over the surface from u in [0, 1)³, with its face's normal.
  const Triangle& pick(double u0, double& rescaled) const {
    const double target = u0 * area();
    const size_t i = std::min(size_t(std::upper_bound(cdf.begin(), cdf.end(), target) - cdf.begin()), cdf.size() - 1);
    const double lo = i ? cdf[i - 1] : 0.0;
    rescaled = std::clamp((target - lo) / (cdf[i] - lo), 0.0, std::nextafter(1.0, 0.0));
    return triangles[i];
  }
};

void check_inputs(const bake::Mesh& mesh, std::span<const bake::AreaLight> lights, const AreaRenderOptions& o) {
  PRT_CHECK(!lights.empty() || !o.punctual.empty());
  for (const auto& l : lights) PRT_CHECK(!l.faces.empty());
  PRT_CHECK(o.casts_shadow.empty() || o.casts_shadow.size() == mesh.triangles.size());
  PRT_CHECK(o.triangle_albedo.empty() || o.triangle_albedo.size() == mesh.triangles.size());
}

// The triangles that block light: all of them, or those with casts_shadow set (same positions and frame).
bake::Mesh casters(const bake::Mesh& mesh, const AreaRenderOptions& o) {
  bake::Mesh m = mesh;
  if (o.casts_shadow.empty()) return m;
  m.triangles.clear();
  for (size_t t = 0; t < mesh.triangles.size(); ++t)
    if (o.casts_shadow[t]) m.triangles.push_back(mesh.triangles[t]);
  return m;
}

double albedo_of(const Fragment& f, const AreaRenderOptions& o, size_t c) {
  return o.triangle_albedo.empty() ? o.albedo[c] : double(o.triangle_albedo[size_t(f.triangle)][c]);
}

namespace ltc = shade::ltc;

// One light's terms at a shade point, at unit radiance: E and the GGX integral ∫ f cos with
// F0 = 1 and with F0 = 0 (f is affine in F0: a channel mixes them with its F0).
struct LightTerms {
  double e = 0, spec1 = 0, spec0 = 0;
};

// The light's contribution to channel c (the file comment's sums).
// `albedo`: the pixel's diffuse albedo in channel c (albedo_of).
double channel(const bake::AreaLight& light, const LightTerms& t, const AreaRenderOptions& o, double albedo, size_t c) {
  double v = albedo * light.radiance[c] * t.e * std::numbers::inv_pi;
  if (o.ggx) v += light.radiance[c] * (o.ggx->f0[c] * t.spec1 + (1 - o.ggx->f0[c]) * t.spec0);
  return v;
}

Vector3d view_direction(const GgxLayer& ggx, const Vector3d& p) { return (ggx.eye - p).normalized(); }

Image render_glossy_analytic(const bake::Mesh& mesh, const bake::Mesh& blockers, const GBuffer& g,
                             std::span<const bake::AreaLight> lights, const AreaRenderOptions& options, double epsilon) {
  const bake::AreaLightIntegrator faces(lights, blockers, 0);
  const GgxLayer& ggx = *options.ggx;
  tbb::enumerable_thread_specific<bake::AreaLightIntegrator::Workspace> workspaces;
  tbb::enumerable_thread_specific<std::vector<ltc::Arc>> ltc_workspaces;
  return shade_pixels(mesh, g, [&](const Fragment& f, float* out) {
    bake::AreaLightIntegrator::Workspace& ws = workspaces.local();
    std::vector<ltc::Arc>& ltc_arcs = ltc_workspaces.local();
    const bake::ShadePoint sp = shading_point(f, epsilon);
    const Vector3d v = view_direction(ggx, sp.p);
    const ltc::Lobe lobe = ltc::ggx_lobe(ltc::ggx_table(), {sp.n.x(), sp.n.y(), sp.n.z()}, {v.x(), v.y(), v.z()}, ggx.alpha);
    std::array<double, 3> rgb{};
    for (size_t l = 0; l < lights.size(); ++l) {
      LightTerms t;
      faces.for_each_visible_face(sp, l, ws, [&](const std::vector<bake::Arc>& arcs) {
        t.e += sp.n.dot(bake::vector_irradiance(arcs));
        ltc_arcs.clear();
        for (const bake::Arc& a : arcs) ltc_arcs.push_back({{a.a.x(), a.a.y(), a.a.z()}, {a.b.x(), a.b.y(), a.b.z()}});
        const double integral = ltc::integrate(lobe, ltc_arcs);
        t.spec1 += lobe.albedo * integral;
        t.spec0 += lobe.fresnel * integral;
      });
      for (size_t c = 0; c < 3; ++c) rgb[c] += channel(lights[l], t, options, albedo_of(f, options, c), c);
    }
    for (size_t c = 0; c < 3; ++c) out[c] = float(rgb[c]);
  });
}

// Adds the punctual lights' radiance (AreaRenderOptions::punctual) to `img`, per covered pixel.
void add_punctual(const bake::Mesh& mesh, const bake::Mesh& blockers, const GBuffer& g, const AreaRenderOptions& o,
                  double epsilon, Image& img) {
  if (o.punctual.empty()) return;
  const bake::Topology topology = bake::build_topology(blockers);
  std::optional<bake::RayCaster> rays;
  if (!blockers.triangles.empty()) rays.emplace(blockers, topology);
  const bake::PunctualLightIntegrator integ(o.punctual, rays ? &*rays : nullptr, mesh.origin, 0);
  const Image extra = shade_pixels(mesh, g, [&](const Fragment& f, float* out) {
    const bake::ShadePoint sp = shading_point(f, epsilon);
    const Vector3d v = o.ggx ? view_direction(*o.ggx, sp.p) : Vector3d::Zero();
    std::array<double, 3> rgb{};
    for (size_t k = 0; k < o.punctual.size(); ++k) {
      Vector3d l;
      const double w = integ.direction_to(sp, k, l), cosine = sp.n.dot(l);
      if (!(w > 0) || !(cosine > 0) || !integ.visible(sp, k, l)) continue;
      const double e = w * cosine;
      for (size_t c = 0; c < 3; ++c) {
        double value = albedo_of(f, o, c) * e * std::numbers::inv_pi;
        if (o.ggx)
          value += ltc::ggx_brdf({sp.n.x(), sp.n.y(), sp.n.z()}, {v.x(), v.y(), v.z()}, {l.x(), l.y(), l.z()}, o.ggx->alpha,
                                 o.ggx->f0[c]) * e;
        rgb[c] += o.punctual[k].intensity[c] * value;
      }
    }
    for (size_t c = 0; c < 3; ++c) out[c] = float(rgb[c]);
  });
  for (size_t i = 0; i < img.rgb.size(); ++i) img.rgb[i] += extra.rgb[i];
}

} // namespace

double area_shading_offset(const bake::Mesh& mesh) {
  Vector3d lo = Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const auto& q : mesh.positions) {
    lo = lo.cwiseMin(q.cast<double>());
    hi = hi.cwiseMax(q.cast<double>());
  }
  if (mesh.positions.empty()) return 0;
  return 1e-5 * (hi - lo).norm() + 1e-6 * std::max(lo.cwiseAbs().maxCoeff(), hi.cwiseAbs().maxCoeff());
}

Image render_area_analytic(const bake::Mesh& mesh, const GBuffer& g, std::span<const bake::AreaLight> lights,
                           const AreaRenderOptions& options) {
  check_inputs(mesh, lights, options);
  const bake::Mesh blockers = casters(mesh, options);
  const double epsilon = area_shading_offset(mesh);
  if (options.ggx) {
    Image img = render_glossy_analytic(mesh, blockers, g, lights, options, epsilon);
    add_punctual(mesh, blockers, g, options, epsilon, img);
    return img;
  }
  const bake::AreaLightIntegrator integrator(lights, blockers, 0);
  tbb::enumerable_thread_specific<bake::AreaLightIntegrator::Workspace> workspaces;
  tbb::enumerable_thread_specific<std::vector<double>> rows([&] { return std::vector<double>(integrator.width()); });
  Image img = shade_pixels(mesh, g, [&](const Fragment& f, float* out) {
    std::vector<double>& row = rows.local();
    integrator.integrate(shading_point(f, epsilon), row, workspaces.local());
    for (size_t c = 0; c < 3; ++c) {
      double v = 0;
      for (size_t l = 0; l < lights.size(); ++l) v += lights[l].radiance[c] * row[l * integrator.per_light()];
      out[c] = float(albedo_of(f, options, c) * v * std::numbers::inv_pi);
    }
  });
  add_punctual(mesh, blockers, g, options, epsilon, img);
  return img;
}

AreaReferenceImage render_area_reference(const bake::Mesh& mesh, const GBuffer& g, std::span<const bake::AreaLight> lights,
                                         const AreaReferenceOptions& options) {
  check_inputs(mesh, lights, options.render);
  PRT_CHECK(options.samples > 0 && (options.samples < kReplicates || options.samples % kReplicates == 0));
  PRT_CHECK(options.reflectance.empty() || options.reflectance.size() == mesh.triangles.size());
  PRT_CHECK(options.gathers.empty() || options.gathers.size() == mesh.triangles.size());
  const bake::Mesh blockers = casters(mesh, options.render);
  const bake::Topology topology = bake::build_topology(blockers);
  const bake::RayCaster rays(blockers, topology);
  std::vector<LightSurface> surfaces;
  for (const auto& l : lights) surfaces.emplace_back(l, mesh.origin);
  const double epsilon = area_shading_offset(mesh);
  const uint32_t B = std::min(kReplicates, options.samples), per = options.samples / B;
  // The blockers' triangles in the mesh's numbering (casters() keeps their order).
  std::vector<uint32_t> mesh_triangle;
  for (size_t t = 0; t < mesh.triangles.size(); ++t)
    if (options.render.casts_shadow.empty() || options.render.casts_shadow[t]) mesh_triangle.push_back(uint32_t(t));
  PRT_CHECK_OP(mesh_triangle.size(), ==, blockers.triangles.size());
  const auto reflectance = [&](uint32_t t, size_t c) {
    if (!options.reflectance.empty()) return double(options.reflectance[t][c]);
    return options.render.triangle_albedo.empty() ? options.render.albedo[c] : double(options.render.triangle_albedo[t][c]);
  };
  // One light sample per light at h (normal n): Σ_l radiance_l,c · (an unbiased estimate of E_l(h)).
  const auto next_event = [&](const Vector3d& h, const Vector3d& n, auto&& next, std::array<double, 3>& out) {
    out = {0, 0, 0};
    for (size_t l = 0; l < lights.size(); ++l) {
      const LightSurface& s = surfaces[l];
      double u0 = 0;
      const LightSurface::Triangle& t = s.pick(next(), u0);
      const double r0 = std::sqrt(u0), u2 = next();
      const Vector3d y = t.a + r0 * (1 - u2) * t.ab + r0 * u2 * t.ac;
      const Vector3d d = y - h;
      const double r2 = d.squaredNorm(), r = std::sqrt(r2);
      if (!(r > 0)) continue;
      const Vector3d w = d / r;
      const double cos_p = n.dot(w);
      const double cos_l = s.two_sided ? std::abs(t.normal.dot(w)) : -t.normal.dot(w);
      if (!(cos_p > 0) || !(cos_l > 0)) continue;
      if (rays.occluded(h, w, 0.0, r * (1 - 1e-7))) continue;
      const double e = s.area() * cos_p * cos_l / r2;
      for (size_t c = 0; c < 3; ++c) out[c] += lights[l].radiance[c] * e;
    }
  };
  // The indirect irradiance (Σ_l radiance_l,c E_l^ind) along one path from the pixel's point.
  const auto indirect = [&](const bake::ShadePoint& sp, auto&& next, std::array<double, 3>& out) {
    out = {0, 0, 0};
    std::array<double, 3> throughput{1, 1, 1};
    Vector3d o = sp.p, n = sp.n;
    for (uint32_t depth = 1; depth <= options.bounces; ++depth) {
      const double s0 = next(), s1 = next();
      const Vector3d d = bake::Frame(n).to_world(bake::cosine_hemisphere(s0, s1)).normalized();
      const std::optional<bake::RayHit> hit = rays.closest_hit(o, d, 0.0);
      if (!hit) return;  // no light comes from the sky here
      const auto& tv = blockers.triangles[hit->triangle];
      const Vector3d a = blockers.positions[tv[0]].cast<double>(), b = blockers.positions[tv[1]].cast<double>(),
                     c = blockers.positions[tv[2]].cast<double>();
      const Vector3d ng = (b - a).cross(c - a);
      if (!(ng.dot(d) < 0)) return;  // a back face: black
      const double w1 = hit->u, w2 = hit->v, w0 = 1 - w1 - w2;
      const Vector3d h = w0 * a + w1 * b + w2 * c;
      Vector3d nh = (w0 * blockers.normals[tv[0]] + w1 * blockers.normals[tv[1]] + w2 * blockers.normals[tv[2]]).cast<double>();
      nh = nh.norm() > 0 && nh.dot(ng) > 0 ? Vector3d(nh.normalized()) : Vector3d(ng.normalized());
      const uint32_t t = mesh_triangle[hit->triangle];
      for (size_t k = 0; k < 3; ++k) throughput[k] *= reflectance(t, k);
      if (!(throughput[0] > 0 || throughput[1] > 0 || throughput[2] > 0)) return;
      o = h + epsilon * ng.normalized();
      n = nh;
      std::array<double, 3> e;
      next_event(o, n, next, e);
      for (size_t k = 0; k < 3; ++k) out[k] += throughput[k] * e[k];
    }
  };

  AreaReferenceImage out;
  out.std_error = Image(g.width, g.height);
  out.radiance = shade_pixels(mesh, g, [&](const Fragment& f, float* rgb) {
    const bake::ShadePoint sp = shading_point(f, epsilon);
    const uint64_t pixel = uint64_t(f.y) * uint64_t(g.width) + uint64_t(f.x);
    std::array<double, kReplicates * 3> means{};
    const GgxLayer* ggx = options.render.ggx ? &*options.render.ggx : nullptr;
    const Vector3d v = ggx ? view_direction(*ggx, sp.p) : Vector3d::Zero();
    const ltc::Vec3 n3 = {sp.n.x(), sp.n.y(), sp.n.z()}, v3 = {v.x(), v.y(), v.z()};
    for (size_t l = 0; l < lights.size(); ++l) {
      const LightSurface& s = surfaces[l];
      for (uint32_t b = 0; b < B; ++b) {
        const bake::RotatedHalton3 halton(options.seed, (pixel * lights.size() + l) * kReplicates + b);
        LightTerms sum;
        for (uint32_t i = 0; i < per; ++i) {
          const std::array<double, 3> u = halton(i);
          double u0 = 0;
          const LightSurface::Triangle& t = s.pick(u[0], u0);
          // Uniform in the triangle: (1 − √u0, √u0 (1 − u2)) weights of ab, ac.
          const double r0 = std::sqrt(u0);
          const Vector3d y = t.a + r0 * (1 - u[2]) * t.ab + r0 * u[2] * t.ac;
          const Vector3d d = y - sp.p;
          const double r2 = d.squaredNorm(), r = std::sqrt(r2);
          if (!(r > 0)) continue;
          const Vector3d w = d / r;
          const double cos_p = sp.n.dot(w);
          const double cos_l = s.two_sided ? std::abs(t.normal.dot(w)) : -t.normal.dot(w);
          if (!(cos_p > 0) || !(cos_l > 0)) continue;
          if (rays.occluded(sp.p, w, 0.0, r * (1 - 1e-7))) continue;
          const double e = s.area() * cos_p * cos_l / r2;
          sum.e += e;
          if (ggx) {
            const ltc::Vec3 w3 = {w.x(), w.y(), w.z()};
            sum.spec1 += ltc::ggx_brdf(n3, v3, w3, ggx->alpha, 1.0) * e;
            sum.spec0 += ltc::ggx_brdf(n3, v3, w3, ggx->alpha, 0.0) * e;
          }
        }
        const LightTerms estimate = {sum.e / per, sum.spec1 / per, sum.spec0 / per};  // this replicate's
        for (size_t c = 0; c < 3; ++c)
          means[b * 3 + c] += channel(lights[l], estimate, options.render, albedo_of(f, options.render, c), c);
      }
    }
    if (options.bounces > 0 && (options.gathers.empty() || options.gathers[size_t(f.triangle)]))
      for (uint32_t b = 0; b < B; ++b) {
        std::array<double, 3> sum{0, 0, 0}, e;
        for (uint32_t i = 0; i < per; ++i) {
          // A path's numbers: a counter hashed with (seed, pixel, replicate, path), whatever the thread.
          const uint64_t key = bake::mix64(bake::mix64(options.seed ^ 0xa5a5a5a5a5a5a5a5ull) ^
                                           bake::mix64((pixel * kReplicates + b) * uint64_t(per) + i));
          uint64_t counter = 0;
          auto next = [&] { return bake::to_unit(bake::mix64(key + 0x9e3779b97f4a7c15ull * ++counter)); };
          indirect(sp, next, e);
          for (size_t c = 0; c < 3; ++c) sum[c] += e[c];
        }
        for (size_t c = 0; c < 3; ++c)
          means[b * 3 + c] += albedo_of(f, options.render, c) * sum[c] / per * std::numbers::inv_pi;
      }
    for (size_t c = 0; c < 3; ++c) {
      double mean = 0;
      for (uint32_t b = 0; b < B; ++b) mean += means[b * 3 + c];
      mean /= B;
      rgb[c] = float(mean);
      if (B == kReplicates) {
        double var = 0;
        for (uint32_t b = 0; b < B; ++b) var += (means[b * 3 + c] - mean) * (means[b * 3 + c] - mean);
        out.std_error.at(f.x, f.y)[c] = float(std::sqrt(var / (B - 1) / B));
      }
    }
  });
  add_punctual(mesh, blockers, g, options.render, epsilon, out.radiance);  // exact: no sampling error
  return out;
}

} // namespace prt::view
