// render.cpp — camera, rasterizer, exact unshadowed irradiance and the Embree reference renderer.
// Conventions, coverage rules and estimators: bake/render.h.
#include <bake/error.h>
#include <bake/raycast.h>
#include <bake/render.h>
#include <bake/sampling.h>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <limits>
#include <numbers>
#include <sstream>
#include <utility>

namespace prt::bake {

using Eigen::Vector3d;

namespace {
constexpr uint32_t kReplicates = 8;  // independent RQMC replicates per pixel (reference renderer)
}

// ---- camera -----------------------------------------------------------------------------------------

Vector3d Camera::forward() const { return (at - eye).normalized(); }
Vector3d Camera::right() const { return forward().cross(up).normalized(); }
Vector3d Camera::true_up() const { return right().cross(forward()); }
double Camera::near_depth() const { return near > 0 ? near : 1e-4 * (at - eye).norm(); }

Vector3d Camera::ray_direction(double sx, double sy) const {
  const double t = std::tan(0.5 * fov_y_degrees * std::numbers::pi / 180.0);
  const double aspect = double(width) / double(height);
  const Vector3d d = forward() + ((2 * sx / width - 1) * aspect * t) * right() + ((1 - 2 * sy / height) * t) * true_up();
  return d.normalized();
}

void Camera::validate() const {
  if (!eye.allFinite() || !at.allFinite() || !up.allFinite()) throw InputError("--camera", "coordinates must be finite");
  const Vector3d f = at - eye;
  if (!(f.norm() > 0)) throw InputError("--camera", "eye and at are the same point");
  if (!(up.norm() > 0) || !(f.normalized().cross(up.normalized()).norm() > 1e-6))
    throw InputError("--camera", "up must be non-zero and not parallel to the view direction (at - eye)");
  if (!(fov_y_degrees > 0 && fov_y_degrees < 180)) throw InputError("--camera", "fov must be in (0, 180) degrees");
  if (width < 1 || height < 1 || width > 16384 || height > 16384)
    throw InputError("--size", "image size must be in [1, 16384] x [1, 16384]");
  if (near < 0 || !std::isfinite(near)) throw InputError("--camera", "near must be >= 0");
}

namespace {

double parse_double(std::string_view s, const std::string& what) {
  const std::string str(s);
  char* end = nullptr;
  const double v = std::strtod(str.c_str(), &end);
  if (str.empty() || end != str.c_str() + str.size() || !std::isfinite(v))
    throw InputError("--camera", what + ": '" + str + "' is not a finite number");
  return v;
}

Vector3d parse_vec3(std::string_view s, const std::string& key) {
  Vector3d v;
  for (int k = 0; k < 3; ++k) {
    const size_t comma = s.find(',');
    if ((k < 2) != (comma != std::string_view::npos))
      throw InputError("--camera", key + " expects three comma-separated numbers X,Y,Z, got '" + std::string(s) + "'");
    v[k] = parse_double(s.substr(0, comma), key);
    if (k < 2) s.remove_prefix(comma + 1);
  }
  return v;
}

} // namespace

Camera parse_camera(std::string_view spec, int width, int height) {
  Camera c;
  c.width = width;
  c.height = height;
  bool have_eye = false, have_at = false, have_up = false, have_fov = false;
  const std::string original(spec);
  if (spec.empty()) throw InputError("--camera", "empty camera (expected eye=X,Y,Z:at=X,Y,Z[:up=X,Y,Z][:fov=DEG])");
  while (!spec.empty()) {
    const size_t colon = spec.find(':');
    const std::string_view item = spec.substr(0, colon);
    spec = colon == std::string_view::npos ? std::string_view() : spec.substr(colon + 1);
    const size_t eq = item.find('=');
    if (eq == std::string_view::npos)
      throw InputError("--camera", "'" + std::string(item) + "' is not key=value (in '" + original + "')");
    const std::string key(item.substr(0, eq));
    const std::string_view value = item.substr(eq + 1);
    auto once = [&](bool& seen) {
      if (seen) throw InputError("--camera", key + " given twice (in '" + original + "')");
      seen = true;
    };
    if (key == "eye") {
      once(have_eye);
      c.eye = parse_vec3(value, key);
    } else if (key == "at") {
      once(have_at);
      c.at = parse_vec3(value, key);
    } else if (key == "up") {
      once(have_up);
      c.up = parse_vec3(value, key);
    } else if (key == "fov") {
      once(have_fov);
      c.fov_y_degrees = parse_double(value, key);
    } else {
      throw InputError("--camera", "unknown key '" + key + "' (keys: eye, at, up, fov)");
    }
  }
  if (!have_eye || !have_at) throw InputError("--camera", "eye=X,Y,Z and at=X,Y,Z are required (in '" + original + "')");
  c.validate();
  return c;
}

std::array<int, 2> parse_size(std::string_view spec) {
  const size_t x = spec.find('x');
  auto num = [&](std::string_view s) {
    int v = 0;
    if (s.empty() || s.size() > 5) throw InputError("--size", "expects WxH, e.g. 256x256, got '" + std::string(spec) + "'");
    for (char ch : s) {
      if (ch < '0' || ch > '9') throw InputError("--size", "expects WxH, e.g. 256x256, got '" + std::string(spec) + "'");
      v = 10 * v + (ch - '0');
    }
    if (v < 1 || v > 16384) throw InputError("--size", "width and height must be in [1, 16384], got '" + std::string(spec) + "'");
    return v;
  };
  if (x == std::string_view::npos) throw InputError("--size", "expects WxH, e.g. 256x256, got '" + std::string(spec) + "'");
  return {num(spec.substr(0, x)), num(spec.substr(x + 1))};
}

// ---- rasterizer ---------------------------------------------------------------------------------------

size_t GBuffer::covered() const {
  return size_t(std::count_if(triangle.begin(), triangle.end(), [](int32_t t) { return t >= 0; }));
}

namespace {

GBuffer empty_gbuffer(int w, int h) {
  GBuffer g;
  g.width = w;
  g.height = h;
  const size_t n = size_t(w) * size_t(h);
  g.triangle.assign(n, -1);
  g.bary.assign(n, {0, 0, 0});
  g.depth.assign(n, std::numeric_limits<float>::infinity());
  return g;
}

// A corner of a (clipped) triangle: view-space position, barycentrics in the original triangle,
// and its key for canonical edge order: (0, v) for mesh vertex v, (i + 1, j) for the clip vertex on
// the original edge (i, j), i < j.
struct Corner {
  Vector3d view;
  std::array<double, 3> beta;
  std::pair<uint64_t, uint64_t> key;
  double sx = 0, sy = 0;
};

struct Screen {
  double w, h, tan_half, aspect;
  void project(Corner& c) const {
    c.sx = (c.view.x() / (c.view.z() * aspect * tan_half) + 1) * 0.5 * w;
    c.sy = (1 - c.view.y() / (c.view.z() * tan_half)) * 0.5 * h;
  }
};

// Edge function of (a, b) at p evaluated in the canonical order of the two keys, and the sign that
// maps it back to the (a, b) direction.
struct Edge {
  const Corner* p;  // canonical first endpoint
  const Corner* q;  // canonical second endpoint
  double sign = 0;  // orients it so that the opposite corner is > 0
  bool owns_ties = false;
  double eval(double x, double y) const { return (q->sx - p->sx) * (y - p->sy) - (q->sy - p->sy) * (x - p->sx); }
};

void draw_triangle(GBuffer& g, int32_t tri, const Corner& A, const Corner& B, const Corner& C) {
  const Corner* c[3] = {&A, &B, &C};
  Edge e[3];
  for (int k = 0; k < 3; ++k) {  // edge k is opposite corner k
    const Corner* a = c[(k + 1) % 3];
    const Corner* b = c[(k + 2) % 3];
    if (b->key < a->key) std::swap(a, b);
    e[k].p = a;
    e[k].q = b;
    const double opp = e[k].eval(c[k]->sx, c[k]->sy);
    if (!(opp != 0) || !std::isfinite(opp)) return;  // zero screen area (or overflow): covers nothing
    e[k].sign = opp > 0 ? 1.0 : -1.0;
    const double A_ = -e[k].sign * (b->sy - a->sy), B_ = e[k].sign * (b->sx - a->sx);
    e[k].owns_ties = A_ > 0 || (A_ == 0 && B_ > 0);
  }
  const double minx = std::min({A.sx, B.sx, C.sx}), maxx = std::max({A.sx, B.sx, C.sx});
  const double miny = std::min({A.sy, B.sy, C.sy}), maxy = std::max({A.sy, B.sy, C.sy});
  const int x0 = int(std::clamp(std::ceil(minx - 0.5), 0.0, double(g.width))),
            x1 = int(std::clamp(std::floor(maxx - 0.5), -1.0, double(g.width - 1)));
  const int y0 = int(std::clamp(std::ceil(miny - 0.5), 0.0, double(g.height))),
            y1 = int(std::clamp(std::floor(maxy - 0.5), -1.0, double(g.height - 1)));
  for (int y = y0; y <= y1; ++y) {
    const double py = y + 0.5;
    for (int x = x0; x <= x1; ++x) {
      const double px = x + 0.5;
      double v[3];
      bool inside = true;
      for (int k = 0; k < 3 && inside; ++k) {
        v[k] = e[k].sign * e[k].eval(px, py);
        inside = v[k] > 0 || (v[k] == 0 && e[k].owns_ties);
      }
      if (!inside) continue;
      const double sum = v[0] + v[1] + v[2];
      if (!(sum > 0)) continue;
      double w[3], wsum = 0;
      for (int k = 0; k < 3; ++k) {
        w[k] = (v[k] / sum) / c[k]->view.z();
        wsum += w[k];
      }
      const double depth = 1.0 / wsum;
      const size_t i = size_t(y) * size_t(g.width) + size_t(x);
      if (!(depth < double(g.depth[i]))) continue;
      std::array<float, 3> beta{};
      for (int j = 0; j < 3; ++j) {
        double b = 0;
        for (int k = 0; k < 3; ++k) b += w[k] * c[k]->beta[size_t(j)];
        beta[size_t(j)] = float(b / wsum);
      }
      g.depth[i] = float(depth);
      g.triangle[i] = tri;
      g.bary[i] = beta;
    }
  }
}

} // namespace

GBuffer rasterize(const Mesh& mesh, const Camera& camera) {
  camera.validate();
  GBuffer g = empty_gbuffer(camera.width, camera.height);
  const Vector3d f = camera.forward(), r = camera.right(), u = camera.true_up();
  const double near = camera.near_depth();
  const Screen screen{double(camera.width), double(camera.height),
                      std::tan(0.5 * camera.fov_y_degrees * std::numbers::pi / 180.0),
                      double(camera.width) / double(camera.height)};
  std::vector<Vector3d> view(mesh.positions.size());
  for (size_t v = 0; v < view.size(); ++v) {
    const Vector3d q = mesh.positions[v].cast<double>() - camera.eye;
    view[v] = {r.dot(q), u.dot(q), f.dot(q)};
  }
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    Corner in[3];
    for (int k = 0; k < 3; ++k) {
      in[k].view = view[tri[size_t(k)]];
      in[k].beta = {0, 0, 0};
      in[k].beta[size_t(k)] = 1;
      in[k].key = {0, tri[size_t(k)]};
    }
    // Clip against z >= near (one plane: every new corner lies on an original edge).
    Corner out[4];
    int n = 0;
    for (int k = 0; k < 3; ++k) {
      const Corner& a = in[k];
      const Corner& b = in[(k + 1) % 3];
      const bool ain = a.view.z() >= near, bin = b.view.z() >= near;
      if (ain) out[n++] = a;
      if (ain != bin) {
        const Corner& lo = a.key < b.key ? a : b;  // canonical direction: neighbours agree bit for bit
        const Corner& hi = a.key < b.key ? b : a;
        const double s = (near - lo.view.z()) / (hi.view.z() - lo.view.z());
        Corner m;
        m.view = lo.view + s * (hi.view - lo.view);
        m.view.z() = near;
        for (size_t j = 0; j < 3; ++j) m.beta[j] = lo.beta[j] + s * (hi.beta[j] - lo.beta[j]);
        m.key = {lo.key.second + 1, hi.key.second};
        out[n++] = m;
      }
    }
    if (n < 3) continue;
    for (int k = 0; k < n; ++k) screen.project(out[k]);
    draw_triangle(g, int32_t(t), out[0], out[1], out[2]);
    if (n == 4) draw_triangle(g, int32_t(t), out[0], out[2], out[3]);
  }
  return g;
}

Fragment make_fragment(const Mesh& mesh, const GBuffer& g, int x, int y) {
  Fragment fr;
  fr.x = x;
  fr.y = y;
  const size_t i = size_t(y) * size_t(g.width) + size_t(x);
  fr.triangle = g.triangle[i];
  if (fr.triangle < 0) return fr;
  fr.bary = g.bary[i];
  const auto& t = mesh.triangles[size_t(fr.triangle)];
  Vector3d p = Vector3d::Zero(), n = Vector3d::Zero();
  for (size_t k = 0; k < 3; ++k) {
    p += double(fr.bary[k]) * mesh.positions[t[k]].cast<double>();
    n += double(fr.bary[k]) * mesh.normals[t[k]].cast<double>();
  }
  const Vector3d a = mesh.positions[t[0]].cast<double>(), b = mesh.positions[t[1]].cast<double>(),
                 c = mesh.positions[t[2]].cast<double>();
  Vector3d ng = (b - a).cross(c - a);
  fr.p = p;
  if (n.norm() > 0) fr.n = n.normalized();
  else if (ng.norm() > 0) fr.n = ng.normalized();
  fr.ng = ng.norm() > 0 ? ng.normalized() : fr.n;
  if (fr.ng.dot(fr.n) < 0) fr.ng = -fr.ng;
  return fr;
}

Image shade_pixels(const Mesh& mesh, const GBuffer& g, const std::function<void(const Fragment&, float*)>& shade) {
  Image img(g.width, g.height);
  tbb::parallel_for(0, g.height, [&](int y) {
    for (int x = 0; x < g.width; ++x) {
      if (g.triangle[size_t(y) * size_t(g.width) + size_t(x)] < 0) continue;
      shade(make_fragment(mesh, g, x, y), img.at(x, y));
    }
  });
  return img;
}

Image interpolate_vertices(const Mesh& mesh, const GBuffer& g, std::span<const float> vertex_rgb) {
  const std::vector<uint8_t> none(mesh.triangles.size(), 0);
  return shade_mixed(mesh, g, vertex_rgb, none, [](const Fragment&, float*) {});
}

Image shade_mixed(const Mesh& mesh, const GBuffer& g, std::span<const float> vertex_rgb, std::span<const uint8_t> per_pixel,
                  const std::function<void(const Fragment&, float*)>& shade) {
  PRT_CHECK_OP(vertex_rgb.size(), ==, 3 * mesh.positions.size());
  PRT_CHECK_OP(per_pixel.size(), ==, mesh.triangles.size());
  return shade_pixels(mesh, g, [&](const Fragment& f, float* out) {
    if (per_pixel[size_t(f.triangle)]) return shade(f, out);
    const auto& t = mesh.triangles[size_t(f.triangle)];
    for (size_t c = 0; c < 3; ++c) {
      double v = 0;
      for (size_t k = 0; k < 3; ++k) v += double(f.bary[k]) * double(vertex_rgb[3 * t[k] + c]);
      out[c] = float(v);
    }
  });
}

// ---- exact unshadowed irradiance -----------------------------------------------------------------------

UnoccludedIrradiance::UnoccludedIrradiance(const EnvMap& env) {
  if (env.texel_count() == 0) {
    constant_ = true;
    constant_value_ = env.radiance(Vector3d(0, 1, 0));
    return;
  }
  const int W = env.info().width, H = env.info().height;
  PRT_CHECK_OP(size_t(W) * size_t(H), ==, size_t(env.texel_count()));
  constexpr int kTile = 16, kSub = 4;
  const int tx = (W + kTile - 1) / kTile, ty = (H + kTile - 1) / kTile;
  tiles_.resize(size_t(tx) * size_t(ty));
  // Tile i owns texels [begin, end) of texels_, laid out tile by tile.
  uint32_t offset = 0;
  for (int j = 0; j < ty; ++j)
    for (int i = 0; i < tx; ++i) {
      Tile& tile = tiles_[size_t(j) * size_t(tx) + size_t(i)];
      const int w = std::min(kTile, W - i * kTile), h = std::min(kTile, H - j * kTile);
      tile.begin = offset;
      offset += uint32_t(w * h);
      tile.end = offset;
    }
  texels_.resize(offset);
  tbb::parallel_for(size_t(0), tiles_.size(), [&](size_t ti) {
    Tile& tile = tiles_[ti];
    const int i = int(ti % size_t(tx)), j = int(ti / size_t(tx));
    const int w = std::min(kTile, W - i * kTile);
    std::vector<Vector3d> centres;
    std::vector<double> radii;
    Vector3d sum = Vector3d::Zero();
    tile.moment.fill(0);
    for (uint32_t k = tile.begin; k < tile.end; ++k) {
      const int local = int(k - tile.begin);
      const int x = i * kTile + local % w, y = j * kTile + local / w;
      const int t = y * W + x;
      const double omega = env.texel_solid_angle(t);
      Vector3d m = Vector3d::Zero();
      for (int a = 0; a < kSub; ++a)
        for (int b = 0; b < kSub; ++b) m += env.sample_texel(t, (a + 0.5) / kSub, (b + 0.5) / kSub);
      m *= omega / (kSub * kSub);
      const Rgb L = env.texel_value(t);
      texels_[k] = {m, {float(L.r), float(L.g), float(L.b)}};
      const double rgb[3] = {double(texels_[k].rgb[0]), double(texels_[k].rgb[1]), double(texels_[k].rgb[2])};
      for (int c = 0; c < 3; ++c)
        for (int d = 0; d < 3; ++d) tile.moment[size_t(3 * c + d)] += rgb[c] * m[d];
      sum += m;
      // Angular radius of the texel about its centre, from its boundary (corners, edge midpoints).
      const Vector3d centre = env.texel_center(t).normalized();
      double r = 0;
      for (double ua : {0.0, 0.5, 1.0 - 1e-12})
        for (double ub : {0.0, 0.5, 1.0 - 1e-12})
          r = std::max(r, std::acos(std::clamp(centre.dot(env.sample_texel(t, ua, ub).normalized()), -1.0, 1.0)));
      centres.push_back(centre);
      radii.push_back(1.05 * r + 1e-9);  // margin: the boundary between the probed points bulges
    }
    tile.axis = sum.norm() > 0 ? Vector3d(sum.normalized()) : centres.front();
    double half = 0;
    for (size_t k = 0; k < centres.size(); ++k)
      half = std::max(half, std::acos(std::clamp(tile.axis.dot(centres[k]), -1.0, 1.0)) + radii[k]);
    tile.sin_half_angle = half >= 0.5 * std::numbers::pi ? 2.0 : std::sin(half);
  });
}

Rgb UnoccludedIrradiance::operator()(const Vector3d& n) const {
  if (constant_)
    return {std::numbers::pi * constant_value_.r, std::numbers::pi * constant_value_.g, std::numbers::pi * constant_value_.b};
  double e[3] = {0, 0, 0};
  for (const Tile& tile : tiles_) {
    const double d = n.dot(tile.axis);
    if (d >= tile.sin_half_angle) {  // wholly above the horizon: n · Σ L M
      for (int c = 0; c < 3; ++c)
        e[c] += n.x() * tile.moment[size_t(3 * c)] + n.y() * tile.moment[size_t(3 * c + 1)] +
                n.z() * tile.moment[size_t(3 * c + 2)];
    } else if (d > -tile.sin_half_angle) {  // cut by the horizon: texel by texel
      for (uint32_t k = tile.begin; k < tile.end; ++k) {
        const double m = n.dot(texels_[k].moment);
        if (m > 0)
          for (int c = 0; c < 3; ++c) e[c] += double(texels_[k].rgb[size_t(c)]) * m;
      }
    }
  }
  return {e[0], e[1], e[2]};
}

// ---- reference renderer -------------------------------------------------------------------------------------

// The ray queries of the reference: libbake's RayScene (bake/raycast.h) over the rendered mesh for
// primary rays, and over the shadow-casting triangles only when some triangles cast no shadow.
struct ReferenceRenderer::Rays {
  Topology topology;
  RayScene scene;
  Mesh caster_mesh;  // same vertices, the casting triangles (used when `casters` is set)
  std::optional<Topology> caster_topology;
  std::unique_ptr<RayScene> casters;
  bool any_caster = true;
  Rays(const Mesh& mesh, std::span<const uint8_t> casts_shadow) : topology(build_topology(mesh)), scene(mesh, topology) {
    if (casts_shadow.empty() || std::all_of(casts_shadow.begin(), casts_shadow.end(), [](uint8_t c) { return c != 0; })) return;
    caster_mesh = mesh;
    caster_mesh.triangles.clear();
    for (size_t t = 0; t < mesh.triangles.size(); ++t)
      if (casts_shadow[t]) caster_mesh.triangles.push_back(mesh.triangles[t]);
    any_caster = !caster_mesh.triangles.empty();
    if (!any_caster) return;
    caster_topology = build_topology(caster_mesh);
    casters = std::make_unique<RayScene>(caster_mesh, *caster_topology);
  }
  bool occluded(const Vector3d& o, const Vector3d& d) const {
    ShadePoint sp;
    sp.p = o;  // a free point (welded = -1): the ray starts at o itself
    return !(casters ? *casters : scene).visible(sp, d);
  }
};

ReferenceRenderer::ReferenceRenderer(const Mesh& mesh, const EnvMap& env, ReferenceOptions options)
    : mesh_(mesh), env_(env), options_(std::move(options)), unoccluded_(env),
      rt_(std::make_unique<Rays>(mesh, options_.casts_shadow)) {
  PRT_CHECK(options_.samples > 0 && (options_.samples % kReplicates == 0 || options_.samples < kReplicates));
  PRT_CHECK(!mesh.triangles.empty());
  PRT_CHECK(options_.casts_shadow.empty() || options_.casts_shadow.size() == mesh.triangles.size());
  PRT_CHECK(options_.albedo.empty() || options_.albedo.size() == mesh.triangles.size());
  Vector3d lo = Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const auto& q : mesh.positions) {
    lo = lo.cwiseMin(q.cast<double>());
    hi = hi.cwiseMax(q.cast<double>());
  }
  epsilon_ = 1e-5 * (hi - lo).norm() + 1e-6 * std::max(lo.cwiseAbs().maxCoeff(), hi.cwiseAbs().maxCoeff());
}

ReferenceRenderer::~ReferenceRenderer() = default;

std::string ReferenceRenderer::description() const {
  std::ostringstream os;
  os << "Embree 3 ray tracing: primary ray per pixel centre; E = exact unshadowed texel sum - randomised Halton QMC "
        "of the occluded part, "
     << options_.samples << " shadow rays/pixel (mixture: cosine, environment"
     << (options_.occluder_spheres.empty() ? "" : ", " + std::to_string(options_.occluder_spheres.size()) + " occluder cone(s)")
     << "), seed " << options_.seed;
  if (!options_.casts_shadow.empty()) {
    const auto n = std::count_if(options_.casts_shadow.begin(), options_.casts_shadow.end(), [](uint8_t c) { return c != 0; });
    os << "; shadows cast by " << n << " of " << mesh_.triangles.size() << " triangles";
  }
  if (!options_.albedo.empty()) os << "; per-object albedo";
  return os.str();
}

GBuffer ReferenceRenderer::trace_primary(const Camera& camera) const {
  camera.validate();
  GBuffer g = empty_gbuffer(camera.width, camera.height);
  const Vector3d f = camera.forward();
  const double near = camera.near_depth();
  tbb::parallel_for(0, camera.height, [&](int y) {
    for (int x = 0; x < camera.width; ++x) {
      const Vector3d d = camera.ray_direction(x + 0.5, y + 0.5);
      const double df = d.dot(f);
      const auto hit = rt_->scene.closest_hit(camera.eye, d, near / df);
      if (!hit) continue;
      const size_t i = size_t(y) * size_t(camera.width) + size_t(x);
      g.triangle[i] = int32_t(hit->triangle);
      g.bary[i] = {1.0f - hit->u - hit->v, hit->u, hit->v};
      g.depth[i] = float(double(hit->t) * df);
    }
  });
  return g;
}

void ReferenceRenderer::irradiance(const Fragment& f, uint64_t index, double E[3], double std_error[3]) const {
  const Rgb unocc = unoccluded_(f.n);
  if (!rt_->any_caster) {  // nothing casts a shadow: the exact unshadowed sum, no noise
    const double un[3] = {unocc.r, unocc.g, unocc.b};
    for (int c = 0; c < 3; ++c) {
      E[c] = un[c];
      std_error[c] = 0;
    }
    return;
  }
  const Vector3d o = f.p + epsilon_ * f.ng;
  constexpr double kInvPi = std::numbers::inv_pi;
  // Cones around the occluder spheres that o sees from outside and that reach above the horizon.
  struct Cone {
    Vector3d axis;
    double cos_a, inv_solid_angle;
    Frame frame;
  };
  std::vector<Cone> cones;
  for (const Sphere& s : options_.occluder_spheres) {
    const Vector3d to = s.centre - o;
    const double D = to.norm();
    if (!(D > s.radius * (1 + 1e-9))) continue;
    const double sin_a = s.radius / D, cos_a = std::sqrt(std::max(0.0, 1 - sin_a * sin_a));
    const Vector3d axis = to / D;
    if (f.n.dot(axis) <= -sin_a) continue;  // wholly below the horizon: never needed
    const double one_minus_cos = sin_a * sin_a / (1 + cos_a);
    cones.push_back({axis, cos_a, 1.0 / (2 * std::numbers::pi * one_minus_cos), Frame(axis)});
  }
  const double w_cone_total = cones.empty() ? 0.0 : 0.5;
  const double w_cos = 0.5 * (1 - w_cone_total), w_env = w_cos;
  const double w_cone = cones.empty() ? 0.0 : w_cone_total / double(cones.size());
  const Frame frame(f.n);
  // Independent replicates (randomised QMC): B rotations of the Halton sequence, N/B points each.
  // The spread of the replicate means is an honest standard error for the RQMC estimate, which
  // converges faster than 1/sqrt(N); the iid sample variance would overstate it.
  const uint32_t B = std::min<uint32_t>(kReplicates, options_.samples);
  const uint32_t per = std::max<uint32_t>(1, options_.samples / B);
  double block_sum[3] = {0, 0, 0}, block_sum2[3] = {0, 0, 0};
  for (uint32_t b = 0; b < B; ++b) {
    const RotatedHalton3 halton(options_.seed, index * kReplicates + b);
    double sum[3] = {0, 0, 0};
    for (uint32_t i = 0; i < per; ++i) {
      const auto u = halton(i);
      Vector3d d;
      if (u[0] < w_cos) {
        d = frame.to_world(cosine_hemisphere(u[1], u[2]));
      } else if (u[0] < w_cos + w_env) {
        d = env_.sample(u[1], u[2], nullptr);
      } else {
        const size_t k = std::min(cones.size() - 1, size_t((u[0] - w_cos - w_env) / w_cone));
        const Cone& c = cones[k];
        const double z = 1 - u[1] * (1 - c.cos_a), r = std::sqrt(std::max(0.0, 1 - z * z));
        const double phi = 2 * std::numbers::pi * u[2];
        d = c.frame.to_world(Vector3d(r * std::cos(phi), r * std::sin(phi), z));
      }
      d.normalize();
      const double cn = f.n.dot(d);
      if (!(cn > 0) || !rt_->occluded(o, d)) continue;  // contributes 0 to the occluded part
      double p = w_cos * cn * kInvPi + w_env * env_.pdf(d);
      for (const Cone& c : cones)
        if (c.axis.dot(d) >= c.cos_a) p += w_cone * c.inv_solid_angle;
      const Rgb L = env_.radiance(d);
      sum[0] += L.r * cn / p;
      sum[1] += L.g * cn / p;
      sum[2] += L.b * cn / p;
    }
    for (int c = 0; c < 3; ++c) {
      const double m = sum[c] / per;
      block_sum[c] += m;
      block_sum2[c] += m * m;
    }
  }
  const double un[3] = {unocc.r, unocc.g, unocc.b};
  for (int c = 0; c < 3; ++c) {
    const double mean = block_sum[c] / B;
    const double var = B > 1 ? std::max(0.0, (block_sum2[c] - B * mean * mean) / (double(B) * (B - 1))) : 0.0;
    E[c] = un[c] - mean;
    std_error[c] = std::sqrt(var);
  }
}

ReferenceImage ReferenceRenderer::render(const Camera& camera, const Monitor& monitor) const {
  const auto t0 = std::chrono::steady_clock::now();
  ReferenceImage out;
  out.gbuffer = trace_primary(camera);
  out.radiance = Image(camera.width, camera.height);
  out.std_error = Image(camera.width, camera.height);
  Task bar(monitor, "reference", uint64_t(camera.height));
  std::atomic<uint64_t> pixels{0};
  tbb::parallel_for(0, camera.height, [&](int y) {
    uint64_t n = 0;
    for (int x = 0; x < camera.width; ++x) {
      const Fragment f = make_fragment(mesh_, out.gbuffer, x, y);
      if (f.triangle < 0) continue;
      double E[3], se[3];
      irradiance(f, uint64_t(y) * uint64_t(camera.width) + uint64_t(x), E, se);
      for (int c = 0; c < 3; ++c) {
        const double albedo = options_.albedo.empty() ? 1.0 : double(options_.albedo[size_t(f.triangle)][size_t(c)]);
        out.radiance.at(x, y)[c] = float(albedo * E[c] * std::numbers::inv_pi);
        out.std_error.at(x, y)[c] = float(albedo * se[c] * std::numbers::inv_pi);
      }
      ++n;
    }
    pixels += n;
    bar.advance();
  });
  bar.finish();
  const uint32_t B = std::min<uint32_t>(kReplicates, options_.samples);
  out.rays = uint64_t(camera.width) * uint64_t(camera.height) +
             (rt_->any_caster ? pixels.load() * B * std::max<uint32_t>(1, options_.samples / B) : 0);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  for (float v : out.radiance.rgb)
    if (!std::isfinite(v)) throw ContractError("reference render produced a non-finite value");
  return out;
}

// ---- reference cache -----------------------------------------------------------------------------------

namespace {
constexpr const char* kKeyAttr = "prt_reference_key";
constexpr uint32_t kNoTriangle = 0xFFFFFFFFu;
} // namespace

void save_reference(const std::filesystem::path& path, const ReferenceImage& image, const std::string& key) {
  const int W = image.radiance.width, H = image.radiance.height;
  PRT_CHECK(W > 0 && H > 0 && image.std_error.rgb.size() == image.radiance.rgb.size());
  PRT_CHECK_OP(image.gbuffer.triangle.size(), ==, size_t(W) * size_t(H));
  std::vector<uint32_t> tri(image.gbuffer.triangle.size());
  for (size_t i = 0; i < tri.size(); ++i) tri[i] = image.gbuffer.triangle[i] < 0 ? kNoTriangle : uint32_t(image.gbuffer.triangle[i]);
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    try {
      Imf::Header header(W, H);
      header.insert(kKeyAttr, Imf::StringAttribute(key));
      Imf::FrameBuffer fb;
      const char* names[6] = {"R", "G", "B", "se.R", "se.G", "se.B"};
      for (int c = 0; c < 6; ++c) {
        const Image& src = c < 3 ? image.radiance : image.std_error;
        header.channels().insert(names[c], Imf::Channel(Imf::FLOAT));
        fb.insert(names[c], Imf::Slice(Imf::FLOAT, const_cast<char*>(reinterpret_cast<const char*>(src.rgb.data() + c % 3)),
                                       3 * sizeof(float), 3 * sizeof(float) * size_t(W)));
      }
      header.channels().insert("triangle", Imf::Channel(Imf::UINT));
      fb.insert("triangle", Imf::Slice(Imf::UINT, reinterpret_cast<char*>(tri.data()), sizeof(uint32_t), sizeof(uint32_t) * size_t(W)));
      Imf::OutputFile out(tmp.c_str(), header, 1);
      out.setFrameBuffer(fb);
      out.writePixels(H);
    } catch (const InputError&) {
      throw;
    } catch (const std::exception& e) {  // Iex::BaseExc
      throw InputError(path.string(), std::string("cannot write the reference: ") + e.what());
    }
  });
}

std::optional<ReferenceImage> load_reference(const std::filesystem::path& path, const std::string& key) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return std::nullopt;
  try {
    Imf::InputFile in(path.c_str(), 1);
    const auto* k = in.header().findTypedAttribute<Imf::StringAttribute>(kKeyAttr);
    if (!k || k->value() != key) return std::nullopt;
    const Imath::Box2i dw = in.header().dataWindow();
    const int W = dw.max.x - dw.min.x + 1, H = dw.max.y - dw.min.y + 1;
    ReferenceImage r;
    r.radiance = Image(W, H);
    r.std_error = Image(W, H);
    std::vector<uint32_t> tri(size_t(W) * size_t(H), kNoTriangle);
    Imf::FrameBuffer fb;
    const char* names[6] = {"R", "G", "B", "se.R", "se.G", "se.B"};
    for (int c = 0; c < 6; ++c) {
      if (!in.header().channels().findChannel(names[c])) throw InputError(path.string(), std::string("no channel ") + names[c]);
      Image& dst = c < 3 ? r.radiance : r.std_error;
      char* base = reinterpret_cast<char*>(dst.rgb.data() + c % 3) -
                   (ptrdiff_t(dw.min.x) + ptrdiff_t(dw.min.y) * W) * ptrdiff_t(3 * sizeof(float));
      fb.insert(names[c], Imf::Slice(Imf::FLOAT, base, 3 * sizeof(float), 3 * sizeof(float) * size_t(W)));
    }
    if (!in.header().channels().findChannel("triangle")) throw InputError(path.string(), "no channel triangle");
    fb.insert("triangle", Imf::Slice(Imf::UINT,
                                     reinterpret_cast<char*>(tri.data()) - (ptrdiff_t(dw.min.x) + ptrdiff_t(dw.min.y) * W) *
                                                                               ptrdiff_t(sizeof(uint32_t)),
                                     sizeof(uint32_t), sizeof(uint32_t) * size_t(W)));
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
    r.gbuffer = empty_gbuffer(W, H);
    for (size_t i = 0; i < tri.size(); ++i) r.gbuffer.triangle[i] = tri[i] == kNoTriangle ? -1 : int32_t(tri[i]);
    for (float v : r.radiance.rgb)
      if (!std::isfinite(v)) throw InputError(path.string(), "non-finite pixel in the cached reference");
    return r;
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(path.string(), std::string("cannot read the cached reference: ") + e.what());
  }
}

// ---- scene assembly --------------------------------------------------------------------------------------

Mesh ground_quad(double y, double cx, double cz, double half, const std::string& name) {
  PRT_CHECK(half > 0 && std::isfinite(y) && std::isfinite(cx) && std::isfinite(cz));
  std::vector<Eigen::Vector3f> p = {
      Eigen::Vector3f(float(cx - half), float(y), float(cz - half)), Eigen::Vector3f(float(cx + half), float(y), float(cz - half)),
      Eigen::Vector3f(float(cx + half), float(y), float(cz + half)), Eigen::Vector3f(float(cx - half), float(y), float(cz + half))};
  std::vector<Eigen::Vector3f> n(4, Eigen::Vector3f(0, 1, 0));
  // Counter-clockwise seen from +Y: (b − a) × (c − a) points up.
  return make_mesh(std::move(p), {{0, 2, 1}, {0, 3, 2}}, name, std::move(n));
}

Mesh translated(const Mesh& mesh, const Vector3d& offset, const std::string& name) {
  Mesh m = mesh;
  for (auto& q : m.positions) q = (q.cast<double>() + offset).cast<float>();
  m.source = name;
  return m;
}

} // namespace prt::bake
