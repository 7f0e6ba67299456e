#pragma once
// Reading the working grid at a continuous index point (the CPU reference's sampling; the kernel
// has its own in kernels/warp.cl). A point is inside the grid when its nearest voxel is:
// every coordinate in [−½, n − ½). Outside reads as air: −1000 HU, label 0, role other (what the
// roles' padding holds around the CT).
//
// Trilinear interpolation at a whole-number point returns the voxel's value exactly (weights 1 and
// 0), which the warp's identity and whole-voxel tests rely on. Within the last half voxel of an
// axis the missing neighbour is the edge voxel itself (clamped), so values never fall off to air.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/geometry.h"
#include "scene/scene.h"

namespace pneumo {

struct SourceGrid {
  Index3 dims;
  const float* ct_hu = nullptr;
  const uint16_t* labels = nullptr;
  const Role* roles = nullptr;

  static constexpr double kOutsideHu = -1000.0;

  /// The nearest voxel's linear index, or −1 outside the grid.
  int64_t nearest(const Vec3& p) const {
    int64_t n[3];
    for (int a = 0; a < 3; ++a) {
      const double f = std::floor(p[a] + 0.5);
      if (!(f >= 0.0 && f < double(dims[a]))) return -1;   // also false for NaN
      n[a] = int64_t(f);
    }
    return n[0] + dims[0] * (n[1] + dims[1] * n[2]);
  }
  Role role_nearest(const Vec3& p) const {
    const int64_t v = nearest(p);
    return v < 0 ? Role::Other : roles[v];
  }
  uint16_t label_nearest(const Vec3& p) const {
    const int64_t v = nearest(p);
    return v < 0 || !labels ? uint16_t(0) : labels[v];
  }
  double ct_trilinear(const Vec3& p) const {
    if (nearest(p) < 0) return kOutsideHu;
    int64_t i0[3], i1[3];
    double f[3];
    for (int a = 0; a < 3; ++a) {
      const double fl = std::floor(p[a]);
      f[a] = p[a] - fl;
      i0[a] = std::clamp<int64_t>(int64_t(fl), 0, dims[a] - 1);
      i1[a] = std::clamp<int64_t>(int64_t(fl) + 1, 0, dims[a] - 1);
    }
    auto at = [&](int64_t i, int64_t j, int64_t k) { return double(ct_hu[i + dims[0] * (j + dims[1] * k)]); };
    const double c00 = at(i0[0], i0[1], i0[2]) * (1 - f[0]) + at(i1[0], i0[1], i0[2]) * f[0];
    const double c10 = at(i0[0], i1[1], i0[2]) * (1 - f[0]) + at(i1[0], i1[1], i0[2]) * f[0];
    const double c01 = at(i0[0], i0[1], i1[2]) * (1 - f[0]) + at(i1[0], i0[1], i1[2]) * f[0];
    const double c11 = at(i0[0], i1[1], i1[2]) * (1 - f[0]) + at(i1[0], i1[1], i1[2]) * f[0];
    const double c0 = c00 * (1 - f[1]) + c10 * f[1];
    const double c1 = c01 * (1 - f[1]) + c11 * f[1];
    return c0 * (1 - f[2]) + c1 * f[2];
  }
};

}  // namespace pneumo
