// raster.cpp — the software rasterizer, per-pixel shading helpers and the preview scene pieces
// (view/raster.h: conventions and coverage rules).
#include <view/raster.h>

#include <bake/core/error.h>

#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

namespace prt::view {

using Eigen::Vector3d;

size_t GBuffer::covered() const {
  return size_t(std::count_if(triangle.begin(), triangle.end(), [](int32_t t) { return t >= 0; }));
}

GBuffer GBuffer::blank(int w, int h) {
  GBuffer g;
  g.width = w;
  g.height = h;
  const size_t n = size_t(w) * size_t(h);
  g.triangle.assign(n, -1);
  g.bary.assign(n, {0, 0, 0});
  g.depth.assign(n, std::numeric_limits<float>::infinity());
  return g;
}

namespace {

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

GBuffer rasterize(const bake::Mesh& mesh, const Camera& camera) {
  camera.validate();
  GBuffer g = GBuffer::blank(camera.width, camera.height);
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

Fragment make_fragment(const bake::Mesh& mesh, const GBuffer& g, int x, int y) {
  const size_t i = size_t(y) * size_t(g.width) + size_t(x);
  if (g.triangle[i] < 0) {
    Fragment fr;
    fr.x = x;
    fr.y = y;
    return fr;
  }
  Fragment fr = surface_fragment(mesh, g.triangle[i], g.bary[i]);
  fr.x = x;
  fr.y = y;
  return fr;
}

Fragment surface_fragment(const bake::Mesh& mesh, int32_t triangle, const std::array<float, 3>& bary) {
  Fragment fr;
  fr.triangle = triangle;
  fr.bary = bary;
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

Image shade_pixels(const bake::Mesh& mesh, const GBuffer& g, const std::function<void(const Fragment&, float*)>& shade) {
  Image img(g.width, g.height);
  tbb::parallel_for(0, g.height, [&](int y) {
    for (int x = 0; x < g.width; ++x) {
      if (g.triangle[size_t(y) * size_t(g.width) + size_t(x)] < 0) continue;
      shade(make_fragment(mesh, g, x, y), img.at(x, y));
    }
  });
  return img;
}

Image interpolate_vertices(const bake::Mesh& mesh, const GBuffer& g, std::span<const float> vertex_rgb) {
  const std::vector<uint8_t> none(mesh.triangles.size(), 0);
  return shade_mixed(mesh, g, vertex_rgb, none, [](const Fragment&, float*) {});
}

Image shade_mixed(const bake::Mesh& mesh, const GBuffer& g, std::span<const float> vertex_rgb, std::span<const uint8_t> per_pixel,
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

// ---- scene assembly --------------------------------------------------------------------------------------

bake::Mesh ground_quad(double y, double cx, double cz, double half, const std::string& name) {
  PRT_CHECK(half > 0 && std::isfinite(y) && std::isfinite(cx) && std::isfinite(cz));
  std::vector<Eigen::Vector3f> p = {
      Eigen::Vector3f(float(cx - half), float(y), float(cz - half)), Eigen::Vector3f(float(cx + half), float(y), float(cz - half)),
      Eigen::Vector3f(float(cx + half), float(y), float(cz + half)), Eigen::Vector3f(float(cx - half), float(y), float(cz + half))};
  std::vector<Eigen::Vector3f> n(4, Eigen::Vector3f(0, 1, 0));
  // Counter-clockwise seen from +Y: (b − a) × (c − a) points up.
  return bake::make_mesh(std::move(p), {{0, 2, 1}, {0, 3, 2}}, name, std::move(n));
}

bake::Mesh translated(const bake::Mesh& mesh, const Vector3d& offset, const std::string& name) {
  bake::Mesh m = mesh;
  for (auto& q : m.positions) q = (q.cast<double>() + offset).cast<float>();
  m.source = name;
  return m;
}

} // namespace prt::view
