#include "core/geometry.h"

#include <cmath>
#include <sstream>

#include "core/error.h"

namespace pneumo {

Mat4 Geometry::index_to_world() const {
  Mat4 a = Mat4::Identity();
  a.topLeftCorner<3, 3>() = direction * spacing_mm.asDiagonal();
  a.topRightCorner<3, 1>() = origin_mm;
  return a;
}

Vec3 Geometry::to_world(const Vec3& ijk) const {
  return origin_mm + direction * spacing_mm.cwiseProduct(ijk);
}

Vec3 Geometry::to_index(const Vec3& world_mm) const {
  return (direction.inverse() * (world_mm - origin_mm)).cwiseQuotient(spacing_mm);
}

std::string Geometry::orientation_code() const {
  // Assign each voxel axis the world axis it is most aligned with, largest |cosine| first, so that
  // an oblique matrix never gives two voxel axes the same letter.
  static const char kPos[3] = {'R', 'A', 'S'};
  static const char kNeg[3] = {'L', 'P', 'I'};
  std::string code(3, '?');
  bool row_used[3] = {false, false, false};
  bool col_used[3] = {false, false, false};
  for (int n = 0; n < 3; ++n) {
    int best_r = -1, best_c = -1;
    double best = -1.0;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        if (!row_used[r] && !col_used[c] && std::abs(direction(r, c)) > best) {
          best = std::abs(direction(r, c));
          best_r = r;
          best_c = c;
        }
    row_used[best_r] = col_used[best_c] = true;
    code[best_c] = direction(best_r, best_c) >= 0 ? kPos[best_r] : kNeg[best_r];
  }
  return code;
}

Geometry Geometry::from_affine(const Index3& dims, const Mat4& affine, const std::string& what) {
  if (!affine.allFinite()) throw file_error(what, "the affine (voxel-to-world transform) is not finite");
  Geometry g;
  g.dims = dims;
  for (int c = 0; c < 3; ++c) {
    const Vec3 col = affine.block<3, 1>(0, c);
    const double len = col.norm();
    if (!(len > 0.0)) {
      std::ostringstream os;
      os << "the affine's column " << c << " is zero: spacing along axis " << c << " would be 0 mm";
      throw file_error(what, os.str());
    }
    g.spacing_mm[c] = len;
    g.direction.col(c) = col / len;
  }
  g.origin_mm = affine.block<3, 1>(0, 3);
  g.validate(what);
  return g;
}

bool Geometry::same_grid(const Geometry& o, double tol_mm) const {
  if (dims != o.dims) return false;
  const double extent = spacing_mm.cwiseProduct(Vec3(dims[0], dims[1], dims[2])).maxCoeff();
  return (spacing_mm - o.spacing_mm).cwiseAbs().maxCoeff() <= tol_mm &&
         (origin_mm - o.origin_mm).cwiseAbs().maxCoeff() <= tol_mm &&
         // a direction error e moves the far corner by about e * extent
         (direction - o.direction).cwiseAbs().maxCoeff() * std::max(extent, 1.0) <= tol_mm;
}

void Geometry::validate(const std::string& what) const {
  // Bounds that keep every size computed from the dimensions (voxels, bytes, padded and working
  // grids) far inside int64: a header promising 2^32 × 2^32 × 16 voxels multiplies to 0 in 64 bits
  // and would pass every later check. 2^20 voxels an axis and 2^36 ≈ 6.9·10^10 in all: twice a
  // 0.25 mm whole-body CT (2000 × 2000 × 8000 = 3.2·10^10, the largest imaginable).
  constexpr int64_t kMaxAxis = int64_t(1) << 20, kMaxVoxels = int64_t(1) << 36;
  for (int a = 0; a < 3; ++a) {
    if (dims[a] < 1 || dims[a] > kMaxAxis) {
      std::ostringstream os;
      os << "dimension " << a << " is " << dims[a] << " (must be 1 to " << kMaxAxis << ")";
      throw file_error(what, os.str());
    }
    if (!std::isfinite(spacing_mm[a]) || !(spacing_mm[a] > 0.0)) {
      std::ostringstream os;
      os << "spacing along axis " << a << " is " << spacing_mm[a] << " mm (must be finite and > 0)";
      throw file_error(what, os.str());
    }
  }
  if (dims[0] * dims[1] > kMaxVoxels / dims[2]) {   // each factor <= 2^20: the first product cannot overflow
    std::ostringstream os;
    os << dims[0] << " x " << dims[1] << " x " << dims[2] << " voxels is more than " << kMaxVoxels
       << " (2^36), far beyond any CT: refusing an absurd header";
    throw file_error(what, os.str());
  }
  if (!origin_mm.allFinite()) throw file_error(what, "the origin is not finite");
  if (!direction.allFinite()) throw file_error(what, "the direction matrix is not finite");
  const double det = direction.determinant();
  if (!(std::abs(det) > 1e-6)) {
    std::ostringstream os;
    os << "the direction matrix is degenerate (determinant " << det << "): two voxel axes are parallel";
    throw file_error(what, os.str());
  }
}

}  // namespace pneumo
