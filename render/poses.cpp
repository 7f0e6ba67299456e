#include "render/poses.h"

#include "core/error.h"

namespace pneumo {

PointMapFn identity_point_map() {
  return [](const Vec3& p) { return p; };
}

Vec3 label_centroid_mm(const RenderVolume& v, int label) {
  if (v.labels.empty())
    throw InputError("target_label " + std::to_string(label) + " needs a label map (inputs.labels)");
  const auto& d = v.geometry.dims;
  Vec3 sum = Vec3::Zero();
  int64_t count = 0;
  for (int64_t k = 0; k < d[2]; ++k)
    for (int64_t j = 0; j < d[1]; ++j)
      for (int64_t i = 0; i < d[0]; ++i)
        if (v.labels[v.geometry.linear_index(i, j, k)] == label) {
          sum += Vec3(double(i), double(j), double(k));
          ++count;
        }
  if (count == 0) throw InputError("target_label " + std::to_string(label) + " labels no voxel of the label map");
  return v.geometry.to_world(sum / double(count));
}

ScopePose port_pose(const Vec3& skin_point_mm, const Vec3& target_mm, double insertion_mm, const PointMapFn& map,
                    const Vec3& up_hint) {
  const Vec3 skin = map ? map(skin_point_mm) : skin_point_mm;
  ScopePose pose = look_at_pose(skin, target_mm, up_hint);
  pose.tip_mm = skin + insertion_mm * pose.axis;
  return pose;
}

}  // namespace pneumo
