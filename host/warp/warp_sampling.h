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
#include <cstring>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "core/geometry.h"
#include "domain/types.h"

namespace pneumo {

/// floor and ceil to an integer, exact for |x| < 2^53. Without SSE4.1 in the target (the default
/// x86-64 build) std::floor and std::ceil are calls into libm, and the warp takes up to eight per
/// voxel; the cast truncates toward zero in one instruction, and one comparison turns that into
/// floor or ceil.
inline int64_t floor_to_int(double x) {
  const int64_t i = int64_t(x);
  return double(i) > x ? i - 1 : i;
}
inline int64_t ceil_to_int(double x) {
  const int64_t i = int64_t(x);
  return double(i) < x ? i + 1 : i;
}

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
      // floor(p + ½) lies in [0, n) exactly when p + ½ does; there the cast is the floor.
      const double q = p[a] + 0.5;
      if (!(q >= 0.0 && q < double(dims[a]))) return -1;   // also false for NaN
      n[a] = int64_t(q);
    }
    return n[0] + dims[0] * (n[1] + dims[1] * n[2]);
  }
  /// nearest() for a point known to lie inside ([0, n − 1) on each axis): no checks.
  int64_t nearest_interior(const Vec3& p) const {
    return int64_t(p[0] + 0.5) + dims[0] * (int64_t(p[1] + 0.5) + dims[1] * int64_t(p[2] + 0.5));
  }
  Role role_nearest(const Vec3& p) const {
    const int64_t v = nearest(p);
    return v < 0 ? Role::Other : roles[v];
  }
  uint16_t label_nearest(const Vec3& p) const {
    const int64_t v = nearest(p);
    return v < 0 || !labels ? uint16_t(0) : labels[v];
  }
  double ct_trilinear(const Vec3& p) const { return nearest(p) < 0 ? kOutsideHu : ct_trilinear_inside(p); }
  /// ct_trilinear at a point in [0, n − 1) on each axis: truncation is the floor, and the stencil
  /// needs no clamping.
  double ct_trilinear_interior(const Vec3& p) const {
    const int64_t i = int64_t(p[0]), j = int64_t(p[1]), k = int64_t(p[2]);
    const float* c = ct_hu + i + dims[0] * (j + dims[1] * k);
    const double fx = p[0] - double(i), fy = p[1] - double(j), fz = p[2] - double(k);
#if defined(__SSE2__)
    // The same products and sums as trilinear() below, two lanes at a time (so the same bits): the
    // stencil's neighbours along i are adjacent floats, loaded and widened as pairs.
    const int64_t y = dims[0], z = dims[0] * dims[1];
    auto pair = [](const float* at) {   // (at[0], at[1]) as doubles
      // The two floats' 8 bytes, loaded as one: memcpy, since `at` is only 4-byte aligned and a
      // double read through it would be undefined (UBSan found it); compilers emit the same movsd.
      double two;
      std::memcpy(&two, at, sizeof two);
      return _mm_cvtps_pd(_mm_castpd_ps(_mm_set_sd(two)));
    };
    const __m128d p00 = pair(c), p10 = pair(c + y), p01 = pair(c + z), p11 = pair(c + z + y);
    const __m128d wx0 = _mm_set1_pd(1 - fx), wx1 = _mm_set1_pd(fx);
    // x: (c00, c10) and (c01, c11)
    const __m128d x0 = _mm_add_pd(_mm_mul_pd(_mm_unpacklo_pd(p00, p10), wx0), _mm_mul_pd(_mm_unpackhi_pd(p00, p10), wx1));
    const __m128d x1 = _mm_add_pd(_mm_mul_pd(_mm_unpacklo_pd(p01, p11), wx0), _mm_mul_pd(_mm_unpackhi_pd(p01, p11), wx1));
    // y: (c0, c1)
    const __m128d yz = _mm_add_pd(_mm_mul_pd(_mm_unpacklo_pd(x0, x1), _mm_set1_pd(1 - fy)),
                                  _mm_mul_pd(_mm_unpackhi_pd(x0, x1), _mm_set1_pd(fy)));
    return _mm_cvtsd_f64(yz) * (1 - fz) + _mm_cvtsd_f64(_mm_unpackhi_pd(yz, yz)) * fz;
#else
    return trilinear(c, 1, dims[0], dims[0] * dims[1], fx, fy, fz);
#endif
  }
  /// ct_trilinear at a point known to be inside (nearest(p) ≥ 0): the warp has just looked.
  double ct_trilinear_inside(const Vec3& p) const {
    // Away from the grid's far faces and at or past its near ones (nearly every voxel the warp
    // samples), the stencil needs no clamping and truncation is the floor.
    if (p[0] >= 0.0 && p[1] >= 0.0 && p[2] >= 0.0 && p[0] < double(dims[0] - 1) && p[1] < double(dims[1] - 1) &&
        p[2] < double(dims[2] - 1))
      return ct_trilinear_interior(p);
    // The stencil's corner and its step to the +1 neighbour on each axis: zero where the neighbour
    // is clamped to the edge voxel.
    int64_t corner[3], step[3];
    double f[3];
    const int64_t stride[3] = {1, dims[0], dims[0] * dims[1]};
    for (int a = 0; a < 3; ++a) {
      const int64_t i = floor_to_int(p[a]);
      f[a] = p[a] - double(i);
      const int64_t i0 = std::clamp<int64_t>(i, 0, dims[a] - 1), i1 = std::clamp<int64_t>(i + 1, 0, dims[a] - 1);
      corner[a] = i0 * stride[a];
      step[a] = (i1 - i0) * stride[a];
    }
    return trilinear(ct_hu + corner[0] + corner[1] + corner[2], step[0], step[1], step[2], f[0], f[1], f[2]);
  }

 private:
  /// The stencil at corner c with neighbours x, y, z elements away, at fractions (fx, fy, fz).
  static double trilinear(const float* c, int64_t x, int64_t y, int64_t z, double fx, double fy, double fz) {
    const double c00 = double(c[0]) * (1 - fx) + double(c[x]) * fx;
    const double c10 = double(c[y]) * (1 - fx) + double(c[y + x]) * fx;
    const double c01 = double(c[z]) * (1 - fx) + double(c[z + x]) * fx;
    const double c11 = double(c[z + y]) * (1 - fx) + double(c[z + y + x]) * fx;
    const double c0 = c00 * (1 - fy) + c10 * fy;
    const double c1 = c01 * (1 - fy) + c11 * fy;
    return c0 * (1 - fz) + c1 * fz;
  }
};

}  // namespace pneumo
