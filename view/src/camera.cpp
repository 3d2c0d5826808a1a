// camera.cpp — the pinhole camera and its text form (view/camera.h).
#include <view/camera.h>

#include <bake/core/error.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

namespace prt::view {

using bake::InputError;
using Eigen::Vector3d;

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

std::string Camera::problem() const {
  if (!eye.allFinite() || !at.allFinite() || !up.allFinite()) return "coordinates must be finite";
  const Vector3d f = at - eye;
  if (!(f.norm() > 0)) return "eye and at are the same point";
  if (!(up.norm() > 0) || !(f.normalized().cross(up.normalized()).norm() > 1e-6))
    return "up must be non-zero and not parallel to the view direction (at - eye)";
  if (!(fov_y_degrees > 0 && fov_y_degrees < 180)) return "fov must be in (0, 180) degrees";
  if (width < 1 || height < 1 || width > 16384 || height > 16384)
    return "image size " + std::to_string(width) + "x" + std::to_string(height) + " is not in [1, 16384] x [1, 16384]";
  if (near < 0 || !std::isfinite(near)) return "near must be >= 0";
  return {};
}

void Camera::validate() const {
  if (const std::string p = problem(); !p.empty()) throw InputError("camera", p);
}

Camera frame_box(const Vector3d& lo, const Vector3d& hi, const Vector3d& up, int width, int height, double fov_y_degrees) {
  Camera c;
  c.width = width;
  c.height = height;
  c.fov_y_degrees = fov_y_degrees;
  c.up = up.normalized();
  const Vector3d front = std::abs(c.up.z()) > 0.5 ? Vector3d(0, -1, 0) : Vector3d(0, 0, 1);
  const Vector3d side = c.up.cross(front);
  const Vector3d toward_eye = (0.35 * side + 0.5 * c.up + front).normalized();
  // A point becomes the box of half-size 1 around it.
  const Vector3d pad = (hi - lo).norm() > 0 ? Vector3d::Zero() : Vector3d::Ones();
  const Vector3d a = lo - pad, b = hi + pad;
  c.at = 0.5 * (a + b);
  // Camera space of the eye c.at + d w: forward −w, right r, true up u; a corner at offset o from
  // the centre has depth z = d − o·w and is in the picture when |o·r| <= tan(fov_x/2) z and
  // |o·u| <= tan(fov_y/2) z: the smallest d that holds for every corner, with a 5% margin.
  c.eye = c.at + toward_eye;
  const Vector3d r = c.right(), u = c.true_up();
  const double ty = std::tan(0.5 * fov_y_degrees * std::numbers::pi / 180.0) / 1.05;
  const double tx = ty * double(width) / double(height);
  double d = 0;
  for (int k = 0; k < 8; ++k) {
    const Vector3d o = Vector3d(k & 1 ? b.x() : a.x(), k & 2 ? b.y() : a.y(), k & 4 ? b.z() : a.z()) - c.at;
    d = std::max({d, o.dot(toward_eye) + std::abs(o.dot(r)) / tx, o.dot(toward_eye) + std::abs(o.dot(u)) / ty});
  }
  c.eye = c.at + d * toward_eye;
  return c;
}

Focus focus_box(std::span<const double> positions, std::span<const uint32_t> triangles) {
  PRT_CHECK(positions.size() % 3 == 0 && triangles.size() % 3 == 0);
  const size_t V = positions.size() / 3, T = triangles.size() / 3;
  const auto pos = [&](uint32_t v) { return Vector3d(positions[3 * size_t(v)], positions[3 * size_t(v) + 1], positions[3 * size_t(v) + 2]); };
  for (uint32_t v : triangles) PRT_CHECK_OP(size_t(v), <, V);
  Focus f;
  f.lo = Vector3d::Constant(std::numeric_limits<double>::infinity());
  f.hi = -f.lo;
  for (size_t v = 0; v < V; ++v) f.lo = f.lo.cwiseMin(pos(uint32_t(v))), f.hi = f.hi.cwiseMax(pos(uint32_t(v)));
  if (T == 0 || V == 0) {
    f.rest_extent = V ? (f.hi - f.lo).norm() : 0;
    return f;
  }
  const double tolerance = 1e-5 * (f.hi - f.lo).norm();
  const double cos_angle = std::cos(std::numbers::pi / 180.0);
  // Positions compared exactly: the same point under several vertex rows is one corner.
  std::vector<uint32_t> order(V), corner(V);
  for (uint32_t v = 0; v < V; ++v) order[v] = v;
  const auto key = [&](uint32_t v) { return std::array<double, 3>{positions[3 * size_t(v)], positions[3 * size_t(v) + 1], positions[3 * size_t(v) + 2]}; };
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return key(a) < key(b); });
  for (size_t i = 0; i < V; ++i) corner[order[i]] = i > 0 && key(order[i]) == key(order[i - 1]) ? corner[order[i - 1]] : order[i];
  // Edges (corner pairs) → triangles, sorted: neighbours are the runs of one edge.
  std::vector<std::pair<uint64_t, uint32_t>> edges;
  edges.reserve(3 * T);
  for (size_t t = 0; t < T; ++t)
    for (int k = 0; k < 3; ++k) {
      uint64_t a = corner[triangles[3 * t + size_t(k)]], b = corner[triangles[3 * t + size_t(k + 1) % 3]];
      if (a == b) continue;
      if (a > b) std::swap(a, b);
      edges.emplace_back(a << 32 | b, uint32_t(t));
    }
  std::sort(edges.begin(), edges.end());
  std::vector<std::vector<uint32_t>> neighbours(T);
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    while (j < edges.size() && edges[j].first == edges[i].first) ++j;
    for (size_t a = i; a < j; ++a)
      for (size_t b = i; b < j; ++b)
        if (edges[a].second != edges[b].second) neighbours[edges[a].second].push_back(edges[b].second);
    i = j;
  }
  std::vector<Vector3d> normal(T);
  for (size_t t = 0; t < T; ++t) {
    const Vector3d n = (pos(triangles[3 * t + 1]) - pos(triangles[3 * t])).cross(pos(triangles[3 * t + 2]) - pos(triangles[3 * t]));
    normal[t] = n.norm() > 0 && n.allFinite() ? n.normalized() : Vector3d::Zero();
  }
  // Regions grown from each unassigned seed, in triangle order.
  std::vector<uint32_t> region(T, UINT32_MAX);
  std::vector<std::array<Vector3d, 2>> box;  // per region: lo, hi
  std::vector<size_t> count;
  for (size_t seed = 0; seed < T; ++seed) {
    if (region[seed] != UINT32_MAX) continue;
    const uint32_t r = uint32_t(box.size());
    box.push_back({Vector3d::Constant(std::numeric_limits<double>::infinity()), Vector3d::Constant(-std::numeric_limits<double>::infinity())});
    count.push_back(0);
    const Vector3d n0 = normal[seed], p0 = pos(triangles[3 * seed]);
    std::vector<uint32_t> stack = {uint32_t(seed)};
    region[seed] = r;
    while (!stack.empty()) {
      const uint32_t t = stack.back();
      stack.pop_back();
      ++count[r];
      for (int k = 0; k < 3; ++k) box[r][0] = box[r][0].cwiseMin(pos(triangles[3 * size_t(t) + size_t(k)])), box[r][1] = box[r][1].cwiseMax(pos(triangles[3 * size_t(t) + size_t(k)]));
      if (n0 == Vector3d::Zero()) continue;  // a degenerate seed stays alone
      for (const uint32_t u : neighbours[t]) {
        if (region[u] != UINT32_MAX || std::abs(normal[u].dot(n0)) < cos_angle) continue;
        bool in_plane = true;
        for (int k = 0; k < 3; ++k) in_plane = in_plane && std::abs(n0.dot(pos(triangles[3 * size_t(u) + size_t(k)]) - p0)) <= tolerance;
        if (!in_plane) continue;
        region[u] = r;
        stack.push_back(u);
      }
    }
  }
  // Set aside the widest part while it is kFlatPartRatio × as wide as the rest.
  std::vector<uint8_t> aside(box.size(), 0);
  const auto rest_box = [&](uint32_t without, Vector3d& lo, Vector3d& hi) {
    lo = Vector3d::Constant(std::numeric_limits<double>::infinity());
    hi = -lo;
    for (size_t t = 0; t < T; ++t)
      if (!aside[region[t]] && region[t] != without)
        for (int k = 0; k < 3; ++k) lo = lo.cwiseMin(pos(triangles[3 * t + size_t(k)])), hi = hi.cwiseMax(pos(triangles[3 * t + size_t(k)]));
  };
  for (;;) {
    uint32_t widest = UINT32_MAX;
    for (uint32_t r = 0; r < box.size(); ++r)
      if (!aside[r] && (widest == UINT32_MAX || (box[r][1] - box[r][0]).norm() > (box[widest][1] - box[widest][0]).norm())) widest = r;
    if (widest == UINT32_MAX) break;
    Vector3d lo, hi;
    rest_box(widest, lo, hi);
    const double part = (box[widest][1] - box[widest][0]).norm(), rest = (hi - lo).norm();
    if (!lo.allFinite() || !(rest > 0) || part < kFlatPartRatio * rest) break;
    aside[widest] = 1;
    if (f.set_aside_parts++ == 0) f.set_aside_extent = part;
    f.set_aside_triangles += count[widest];
  }
  if (f.set_aside_parts > 0) rest_box(UINT32_MAX, f.lo, f.hi);
  f.rest_extent = (f.hi - f.lo).norm();
  return f;
}

std::string to_string(const Camera& c) {
  char buf[512];
  std::snprintf(buf, sizeof buf, "eye=%.9g,%.9g,%.9g:at=%.9g,%.9g,%.9g:up=%.9g,%.9g,%.9g:fov=%.9g", c.eye.x(), c.eye.y(),
                c.eye.z(), c.at.x(), c.at.y(), c.at.z(), c.up.x(), c.up.y(), c.up.z(), c.fov_y_degrees);
  return buf;
}

namespace {

// The subject of parse_camera's errors: the spec itself.
std::string camera_subject(std::string_view spec) { return "camera spec '" + std::string(spec) + "'"; }

double parse_double(std::string_view s, const std::string& what, std::string_view spec) {
  const std::string str(s);
  char* end = nullptr;
  const double v = std::strtod(str.c_str(), &end);
  if (str.empty() || end != str.c_str() + str.size() || !std::isfinite(v))
    throw InputError(camera_subject(spec), what + ": '" + str + "' is not a finite number");
  return v;
}

Vector3d parse_vec3(std::string_view s, const std::string& key, std::string_view spec) {
  Vector3d v;
  for (int k = 0; k < 3; ++k) {
    const size_t comma = s.find(',');
    if ((k < 2) != (comma != std::string_view::npos))
      throw InputError(camera_subject(spec), key + " expects three comma-separated numbers X,Y,Z, got '" + std::string(s) + "'");
    v[k] = parse_double(s.substr(0, comma), key, spec);
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
  const std::string original(spec), subject = camera_subject(spec);
  if (spec.empty()) throw InputError(subject, "empty camera (expected eye=X,Y,Z:at=X,Y,Z[:up=X,Y,Z][:fov=DEG])");
  while (!spec.empty()) {
    const size_t colon = spec.find(':');
    const std::string_view item = spec.substr(0, colon);
    spec = colon == std::string_view::npos ? std::string_view() : spec.substr(colon + 1);
    const size_t eq = item.find('=');
    if (eq == std::string_view::npos)
      throw InputError(subject, "'" + std::string(item) + "' is not key=value");
    const std::string key(item.substr(0, eq));
    const std::string_view value = item.substr(eq + 1);
    auto once = [&](bool& seen) {
      if (seen) throw InputError(subject, key + " given twice");
      seen = true;
    };
    if (key == "eye") {
      once(have_eye);
      c.eye = parse_vec3(value, key, original);
    } else if (key == "at") {
      once(have_at);
      c.at = parse_vec3(value, key, original);
    } else if (key == "up") {
      once(have_up);
      c.up = parse_vec3(value, key, original);
    } else if (key == "fov") {
      once(have_fov);
      c.fov_y_degrees = parse_double(value, key, original);
    } else {
      throw InputError(subject, "unknown key '" + key + "' (keys: eye, at, up, fov)");
    }
  }
  if (!have_eye || !have_at) throw InputError(subject, "eye=X,Y,Z and at=X,Y,Z are required");
  if (const std::string p = c.problem(); !p.empty()) throw InputError(subject, p);
  return c;
}

std::array<int, 2> parse_size(std::string_view spec) {
  const size_t x = spec.find('x');
  const std::string subject = "image size '" + std::string(spec) + "'";
  auto num = [&](std::string_view s) {
    int v = 0;
    if (s.empty() || s.size() > 5) throw InputError(subject, "expected WxH, e.g. 256x256");
    for (char ch : s) {
      if (ch < '0' || ch > '9') throw InputError(subject, "expected WxH, e.g. 256x256");
      v = 10 * v + (ch - '0');
    }
    if (v < 1 || v > 16384) throw InputError(subject, "width and height must be in [1, 16384]");
    return v;
  };
  if (x == std::string_view::npos) throw InputError(subject, "expected WxH, e.g. 256x256");
  return {num(spec.substr(0, x)), num(spec.substr(x + 1))};
}

} // namespace prt::view
