#include "render/camera_path.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "render/view_settings.h"

namespace pneumo {

Vec3 catmull_rom(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& p3, double u) {
  const double u2 = u * u, u3 = u2 * u;
  return 0.5 * ((2.0 * p1) + (-p0 + p2) * u + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * u2 +
                (-p0 + 3.0 * p1 - 3.0 * p2 + p3) * u3);
}

std::vector<ScopePose> interpolate_path(const std::vector<Keyframe>& keys, int frames, const Vec3& up_hint) {
  if (keys.size() < 2) throw InputError("a path needs at least 2 keyframes");
  if (frames < 2) throw InputError("a path needs at least 2 frames");
  const int n = int(keys.size());
  // Orientation of each keyframe: columns (right, up, −axis), as in make_view_camera().
  std::vector<Eigen::Quaterniond> q(n);
  for (int i = 0; i < n; ++i) {
    const ScopePose p = look_at_pose(keys[i].position_mm, keys[i].look_at_mm, up_hint);
    Vec3 right = p.axis.cross(up_hint);
    if (right.norm() < 1e-9) throw InputError("path keyframe " + std::to_string(i) + ": up is parallel to the axis");
    right.normalize();
    Mat3 r;
    r.col(0) = right;
    r.col(1) = right.cross(p.axis);
    r.col(2) = -p.axis;
    q[i] = Eigen::Quaterniond(r);
    if (i > 0 && q[i].dot(q[i - 1]) < 0) q[i].coeffs() *= -1.0;  // shortest arc
  }
  auto pos = [&](int i) {
    if (i < 0) return Vec3(2.0 * keys[0].position_mm - keys[1].position_mm);
    if (i >= n) return Vec3(2.0 * keys[n - 1].position_mm - keys[n - 2].position_mm);
    return keys[i].position_mm;
  };
  std::vector<ScopePose> out;
  out.reserve(frames);
  for (int f = 0; f < frames; ++f) {
    const double s = double(f) * (n - 1) / (frames - 1);
    const int seg = std::min(int(std::floor(s)), n - 2);
    const double u = s - seg;
    ScopePose p;
    p.tip_mm = catmull_rom(pos(seg - 1), pos(seg), pos(seg + 1), pos(seg + 2), u);
    const Mat3 r = q[seg].slerp(u, q[seg + 1]).toRotationMatrix();
    p.axis = -r.col(2);
    p.up_hint = r.col(1);
    out.push_back(p);
  }
  return out;
}

}  // namespace pneumo
