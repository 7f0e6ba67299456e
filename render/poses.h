#pragma once
// Scope poses from the scene (method.md §8): a camera's tip and aim, a trocar port carried
// through the deformation, and an organ label's centroid as a target.
#include <functional>
#include <optional>

#include "render/camera_model.h"
#include "render/render_volume.h"

namespace pneumo {

PointMapFn identity_point_map();

/// Centroid (world mm) of the voxels carrying `label`; InputError naming the label when none do
/// or the volume has no label map.
Vec3 label_centroid_mm(const RenderVolume& volume, int label);

/// A port's pose: the skin point carried through `map`, aimed at `target_mm` (already in the
/// deformed frame), the tip `insertion_mm` beyond the skin along that axis.
/// InputError when the target coincides with the carried skin point.
ScopePose port_pose(const Vec3& skin_point_mm, const Vec3& target_mm, double insertion_mm,
                    const PointMapFn& map, const Vec3& up_hint);

}  // namespace pneumo
