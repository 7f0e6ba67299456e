#include "render/camera_model.h"

#include <cmath>

#include "core/error.h"
#include "render/view_settings.h"

namespace pneumo {
namespace {
constexpr double kPi = 3.14159265358979323846;
double rad(double deg) { return deg * kPi / 180.0; }

std::string show(const Vec3& v) {
  char b[96];
  std::snprintf(b, sizeof b, "[%.1f, %.1f, %.1f]", v.x(), v.y(), v.z());
  return b;
}
}  // namespace

std::optional<Vec3> ViewCamera::ray(double px, double py) const {
  const double x = 2.0 * px / width - 1.0;
  const double y = (1.0 - 2.0 * py / height) * height / width;
  if (lens == Lens::Pinhole) {
    const double t = std::tan(rad(fov_deg) * 0.5);
    return (forward + t * (x * right + y * up)).normalized();
  }
  const double r = std::sqrt(x * x + y * y);
  if (r > 1.0) return std::nullopt;
  if (r == 0.0) return forward;
  const double theta = r * rad(fov_deg) * 0.5;
  return (std::cos(theta) * forward + std::sin(theta) / r * (x * right + y * up)).normalized();
}

std::optional<Eigen::Vector2d> ViewCamera::project(const Vec3& p_mm) const {
  const Vec3 d = p_mm - position_mm;
  const double f = d.dot(forward), a = d.dot(right), b = d.dot(up);
  double x = 0.0, y = 0.0;   // normalised coordinates, as in ray()
  if (lens == Lens::Pinhole) {
    if (!(f > 0.0)) return std::nullopt;
    const double t = std::tan(rad(fov_deg) * 0.5);
    x = a / (f * t);
    y = b / (f * t);
  } else {
    const double s = std::sqrt(a * a + b * b);
    const double r = std::atan2(s, f) / (rad(fov_deg) * 0.5);   // θ = r·fov/2
    if (r > 1.0) return std::nullopt;
    if (s > 0.0) {
      x = r * a / s;
      y = r * b / s;
    }
  }
  return Eigen::Vector2d(0.5 * (x + 1.0) * width, 0.5 * (1.0 - y * width / height) * height);
}

ScopePose look_at_pose(const Vec3& tip_mm, const Vec3& look_at_mm, const Vec3& up_hint) {
  const Vec3 d = look_at_mm - tip_mm;
  if (!(d.norm() > 1e-9)) throw InputError("the scope's aim " + show(look_at_mm) + " equals its tip; no direction");
  return ScopePose{tip_mm, d.normalized(), up_hint};
}

ViewCamera make_view_camera(const ScopePose& pose, const Optics& optics, int width, int height) {
  const Vec3 axis = pose.axis.normalized();
  Vec3 right0 = axis.cross(pose.up_hint);
  if (right0.norm() < 1e-9)
    throw InputError("up " + show(pose.up_hint) + " is parallel to the scope's axis " + show(axis) +
                     "; choose another up");
  right0.normalize();
  const Vec3 up0 = right0.cross(axis);
  const double rho = rad(optics.roll_deg), theta = rad(optics.oblique_deg);
  const Vec3 up_r = std::cos(rho) * up0 + std::sin(rho) * right0;
  const Vec3 right_r = std::cos(rho) * right0 - std::sin(rho) * up0;
  ViewCamera cam;
  cam.position_mm = pose.tip_mm;
  cam.forward = (std::cos(theta) * axis + std::sin(theta) * up_r).normalized();
  cam.up = (std::cos(theta) * up_r - std::sin(theta) * axis).normalized();
  cam.right = right_r.normalized();
  cam.lens = optics.lens;
  cam.fov_deg = optics.fov_deg;
  cam.near_mm = optics.near_mm;
  cam.width = width;
  cam.height = height;
  return cam;
}

}  // namespace pneumo
