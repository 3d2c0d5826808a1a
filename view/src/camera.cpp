// camera.cpp — the pinhole camera and its text form (view/camera.h).
#include <view/camera.h>

#include <bake/error.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <string>

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
