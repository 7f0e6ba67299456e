#pragma once
// Fly-through paths (method.md §8): positions by a uniform Catmull-Rom spline through the
// keyframes' tips (end tangents from mirrored phantom points), orientations by spherical linear
// interpolation (slerp, shortest arc) between the keyframes' look-at frames.
#include <vector>

#include "render/camera_model.h"
#include "domain/types.h"
#include "render/view_settings.h"

namespace pneumo {

/// `frames` poses, the first at keyframe 0 and the last at the final keyframe, evenly spaced in
/// the spline parameter (each keyframe interval gets the same number of frames).
std::vector<ScopePose> interpolate_path(const std::vector<Keyframe>& keyframes, int frames, const Vec3& up_hint);

/// Uniform Catmull-Rom between p1 (u = 0) and p2 (u = 1).
Vec3 catmull_rom(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& p3, double u);

}  // namespace pneumo
