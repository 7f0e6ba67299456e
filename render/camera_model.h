#pragma once
// The laparoscope camera (method.md §8): a tip, the scope's axis, an oblique angle and roll, and
// a lens (pinhole or equidistant fisheye) that turns each pixel into a ray.
//
// Frame: `axis` is the scope's shaft direction. Without roll, (right0, up0) come from the optics'
// `up` hint: right0 = axis × up, up0 = right0 × axis. Roll ρ turns them about the axis:
// up_r = cos ρ·up0 + sin ρ·right0, right_r = cos ρ·right0 − sin ρ·up0. An oblique scope of angle θ
// looks along forward = cos θ·axis + sin θ·up_r (tilted towards the rolled image up), and the
// image up tilts with it: up = cos θ·up_r − sin θ·axis, right = right_r. (right, up, −forward) is
// right-handed, like OpenGL's eye space.
//
// Pixels: (px, py) with (0, 0) the top-left corner of the image; a pixel's centre is at +0.5.
// Normalised coordinates: x = 2(px/W) − 1 across the width (−1 left, +1 right), y = (1 − 2 py/H)·H/W
// (square pixels). The field of view spans the image width.
//   pinhole: dir = normalize(forward + tan(fov/2)·(x·right + y·up))
//   fisheye (equidistant, r = f·θ): r = |(x, y)|, θ = r·fov/2; pixels with r > 1 lie outside the
//            image circle and get no ray; dir = cos θ·forward + sin θ·(x·right + y·up)/r.
#include <optional>

#include "core/geometry.h"
#include "domain/types.h"
#include "render/view_settings.h"

namespace pneumo {

/// Where the scope is and how it is held, before the optics are applied.
struct ScopePose {
  Vec3 tip_mm = Vec3::Zero();
  Vec3 axis = Vec3(0, 1, 0);  // unit
  Vec3 up_hint = Vec3(0, 0, 1);
};

/// A camera ready to cast rays: orthonormal frame after oblique angle and roll.
struct ViewCamera {
  Vec3 position_mm = Vec3::Zero();
  Vec3 forward = Vec3(0, 1, 0), right = Vec3(1, 0, 0), up = Vec3(0, 0, 1);
  Lens lens = Lens::Pinhole;
  double fov_deg = 70.0;
  double near_mm = 1.0;
  int width = 64, height = 64;

  /// Ray direction (unit) through image point (px, py); nullopt outside a fisheye's image circle.
  std::optional<Vec3> ray(double px, double py) const;
  /// The inverse: the image point (px, py) whose ray passes through `p_mm`; nullopt for a point
  /// behind the camera (pinhole) or beyond the image circle (fisheye). It may lie off the image.
  std::optional<Eigen::Vector2d> project(const Vec3& p_mm) const;
};

/// Applies optics (oblique angle, roll, lens, field of view, near distance) to a pose.
/// InputError when the up hint is parallel to the axis.
ViewCamera make_view_camera(const ScopePose& pose, const Optics& optics, int width, int height);

/// A pose from a tip and a point on the axis ahead (InputError when they coincide).
ScopePose look_at_pose(const Vec3& tip_mm, const Vec3& look_at_mm, const Vec3& up_hint);

}  // namespace pneumo
