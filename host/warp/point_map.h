#pragma once
// Points through the deformation (method.md §7, §9): a landmark, a port on the skin or an organ's
// centroid carried from the original (CT) frame to the deformed one and back, through the same
// tetrahedra and the same rules as the image warp (warp.h): barycentric weights in the tetrahedron
// that holds the point, wall tetrahedra only for points whose role is not viscera and viscera
// tetrahedra only for points whose role is not wall, the lowest accepting index when several hold
// it. So a point maps where the image warp shows the tissue that was there.
//
// Points in no accepted tetrahedron are not carried: outside the meshes nothing moves, and a
// deformed point in the gas has no source. They come back unchanged with carried = false.
#include <cstdint>
#include <vector>

#include "core/geometry.h"
#include "warp/warp_mesh.h"

namespace pneumo {

struct MappedPoint {
  Vec3 point_mm = Vec3::Zero();   // world RAS+ millimetres in the other frame
  bool carried = false;           // false: no accepted tetrahedron holds the point (returned unchanged)
  int64_t tet = -1;               // the tetrahedron that carried it
};

class PointMap {
 public:
  /// `mesh` and `roles` (one per voxel of mesh.grid, the roles' working grid) must outlive the map.
  PointMap(const WarpMesh& mesh, const Role* roles);

  /// Original (CT) frame → deformed frame.
  MappedPoint to_deformed(const Vec3& original_mm) const;
  /// Deformed frame → original frame: what the image warp samples for a voxel centre there.
  MappedPoint to_original(const Vec3& deformed_mm) const;

 private:
  /// Tetrahedra binned by bounding box on a regular grid of cells (index coordinates): a cell per
  /// lattice cube, L voxels on each axis (anisotropic when the lattice is).
  struct Bins {
    Vec3 min = Vec3::Zero();
    Vec3 cell = Vec3::Ones();
    Index3 dims{0, 0, 0};
    std::vector<int64_t> start;   // CSR: cell c holds ids[start[c] .. start[c+1])
    std::vector<int32_t> ids;     // ascending within each cell
    const int32_t* begin(const Vec3& p, const int32_t*& end) const;
  };
  Bins bin(bool deformed) const;
  MappedPoint map(const Vec3& mm, bool forward) const;

  const WarpMesh& mesh_;
  const Role* roles_;
  std::vector<uint8_t> usable_;   // per tetrahedron: not degenerate when deformed
  Bins rest_, deformed_;
};

/// The map as the renderer and the landmark evaluation take it (original CT mm → deformed mm). A
/// point that no tetrahedron carries keeps its position; with `warn` each such point is logged,
/// since a port's skin point or a landmark outside the meshes does not follow the tissue around it.
/// `map` must outlive the function.
PointMapFn deformed_point_fn(const PointMap& map, bool warn = true);

}  // namespace pneumo
