#pragma once
// The voxel grid of a volume in world coordinates (NIfTI RAS+, millimetres).
#include <Eigen/Dense>
#include <array>
#include <cstdint>
#include <functional>
#include <string>

namespace pneumo {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Mat4 = Eigen::Matrix4d;
using Index3 = std::array<int64_t, 3>;

/// Maps a point of the original CT (world mm) to where the deformation took it (world mm of the
/// deformed CT): the warp's point mapping (warp/point_map.h) as the renderer and the evaluation
/// take it; without a deformation, the identity.
using PointMapFn = std::function<Vec3(const Vec3&)>;

/// World coordinates are NIfTI RAS+ millimetres: +x Right, +y Anterior, +z Superior.
/// A voxel index (i,j,k) maps to world as  x = origin_mm + direction * diag(spacing_mm) * (i,j,k).
/// `direction`'s columns are the unit vectors of the voxel axes in world space; MetaImage files
/// (LPS+ by ITK convention) are converted on read and write.
struct Geometry {
  Index3 dims{1, 1, 1};
  Vec3 spacing_mm{1.0, 1.0, 1.0};
  Vec3 origin_mm{0.0, 0.0, 0.0};   // world position of the centre of voxel (0,0,0)
  Mat3 direction = Mat3::Identity();

  int64_t voxel_count() const { return dims[0] * dims[1] * dims[2]; }
  int64_t linear_index(int64_t i, int64_t j, int64_t k) const { return i + dims[0] * (j + dims[1] * k); }

  /// 4x4 affine from voxel index to world millimetres (the NIfTI sform).
  Mat4 index_to_world() const;
  Vec3 to_world(const Vec3& ijk) const;
  Vec3 to_index(const Vec3& world_mm) const;

  /// Three letters naming where each voxel axis points in the patient (nibabel's convention):
  /// "RAS" means +i towards Right, +j towards Anterior, +k towards Superior.
  std::string orientation_code() const;

  /// Builds a geometry from a 4x4 index-to-world affine; throws InputError (with `what` as the
  /// subject of the message) on zero, non-finite or degenerate columns.
  static Geometry from_affine(const Index3& dims, const Mat4& affine, const std::string& what);

  /// The same grid: dims equal, spacing, origin and direction within `tol_mm` (absolute).
  bool same_grid(const Geometry& other, double tol_mm = 1e-4) const;

  /// Checks dims, spacing and direction; throws InputError naming `what` on the first problem.
  void validate(const std::string& what) const;
};

}  // namespace pneumo
