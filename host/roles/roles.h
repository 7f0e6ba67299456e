#pragma once
// Roles (method.md §2): which voxels are abdominal wall, viscera, fixed or left out, on the working
// grid of a case: the CT's grid padded with air as the scene asks (pad.h). Later stages (mesh,
// warp, render) read everything about the case's voxels from the RoleVolume.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/geometry.h"
#include "io/volume.h"
#include "roles/pad.h"
#include "domain/types.h"
#include "roles/role_rules.h"

namespace pneumo {

struct RoleVolume {
  Geometry geometry;            // the working grid (after padding)
  PadVoxels pad;                // voxels added at each end of each axis of the CT's grid
  std::vector<Role> role;       // one per voxel, i fastest
  std::vector<uint16_t> label;  // organ label per voxel (0 where none or unknown); same size
  Volume ct;                    // the CT on the same grid, float32 HU (padding -1000)

  /// Voxels of each role, indexed by the Role's value, in one pass over the grid (10⁸ voxels on a
  /// 0.75 mm CT): callers that want several roles take them all at once.
  std::array<int64_t, 4> counts() const;
  int64_t count(Role r) const { return counts()[std::size_t(r)]; }
  /// The CT's HU per voxel, or null when it holds none on this grid.
  const float* hu() const {
    return ct.type() == VoxelType::Float32 && ct.voxel_count() == int64_t(role.size()) && !role.empty()
               ? ct.data<float>()
               : nullptr;
  }
  double voxel_volume_ml() const;   // spacing product / 1000
  double volume_ml(Role r) const { return double(count(r)) * voxel_volume_ml(); }
  /// counts() in ml.
  std::array<double, 4> volumes_ml() const {
    const std::array<int64_t, 4> n = counts();
    return {double(n[0]) * voxel_volume_ml(), double(n[1]) * voxel_volume_ml(), double(n[2]) * voxel_volume_ml(),
            double(n[3]) * voxel_volume_ml()};
  }
};

/// `rv` on its grid grown by `grow` (padded_geometry), as the padding is filled: −1000 HU, label 0,
/// role other; rv.pad grows with it, so the CT's grid stays where it was inside the working grid.
RoleVolume grown_roles(RoleVolume rv, const PadVoxels& grow);

/// What messages call the inputs: the scene file and the CT's and label map's files.
struct RoleInputNames {
  std::string scene = "scene", ct = "(CT)", labels = "(label map)";
};

/// Roles of a case from its CT and (may be null) its label map, which must be on the CT's grid.
/// source "labels": role = rules.label_roles()[label]; "auto": auto_roles.h's rules.
/// InputError (naming the files) for a missing label map in labels mode, a label map off the CT's
/// grid, or label values that are not ids 0..65535. The scene's form is in pipeline/scene_stages.h.
RoleVolume assign_roles(const RoleRules& rules, const Volume& ct, const Volume* labels, const RoleInputNames& names);

/// InputError when `rules` need a label map and none is given (before reading a large CT for nothing).
void require_labels_if_needed(const RoleRules& rules, bool have_labels, const RoleInputNames& names);

}  // namespace pneumo
