#pragma once
// A picture of the roles: axial, coronal and sagittal slices of the CT with the roles coloured over
// it (wall orange, viscera green, fixed blue, other not coloured) and a legend with each role's
// volume. For checking by eye that the wall is a shell in front and at the sides, the organs are
// viscera and the spine, pelvis and back are fixed.
#include <optional>
#include <string>

#include "core/geometry.h"
#include "image/image.h"
#include "roles/roles.h"

namespace pneumo {

/// The montage; `point_mm`: where the three planes cross (default: the centre of the grid).
RgbImage render_roles(const RoleVolume& roles, const std::optional<Vec3>& point_mm = std::nullopt);

/// render_roles written as a PNG (atomically; InputError when the folder is missing).
void write_roles_png(const RoleVolume& roles, const std::string& png_path,
                     const std::optional<Vec3>& point_mm = std::nullopt);

}  // namespace pneumo
