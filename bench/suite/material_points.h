#pragma once
// The material points at which two solutions on different meshes are compared (speed_accuracy): voxel centres of
// the original CT on the skin and on the cavity surface, carried into each solution's deformed frame through its
// own rest tetrahedra (barycentric, warp/point_map.h), so a coarse and a fine mesh are compared where the same
// tissue went, not node to node (their nodes differ).
#include <cstdint>
#include <vector>

#include "core/geometry.h"
#include "mesh/mesh.h"
#include "roles/roles.h"

namespace pneumo::bench {

struct MaterialPoints {
  std::vector<Vec3> skin_mm;     // wall voxels with an 'other' (air, outside) face neighbour
  std::vector<Vec3> cavity_mm;   // wall voxels with a viscera face neighbour, and viscera voxels with a wall one
};

/// At most `max_per_set` of each, evenly strided through the voxel order (deterministic).
MaterialPoints material_points(const RoleVolume& roles, std::size_t max_per_set);

struct MappedPoints {
  std::vector<Vec3> skin_mm, cavity_mm;
  std::vector<uint8_t> skin_ok, cavity_ok;   // carried: inside an accepting tetrahedron of this mesh
};

/// The points in the deformed frame of the solution `x` (positions, m) of `mesh`.
MappedPoints map_points(const MaterialPoints& p, const RoleVolume& roles, const Mesh& mesh,
                        const std::vector<Vec3>& x);

struct PointError {
  double rms_mm = 0, max_mm = 0;
  int64_t compared = 0, total = 0;   // points carried by both solutions, of all
};

/// |a − b| over the points both carried.
PointError compare_points(const std::vector<Vec3>& a, const std::vector<uint8_t>& a_ok, const std::vector<Vec3>& b,
                          const std::vector<uint8_t>& b_ok);

}  // namespace pneumo::bench
