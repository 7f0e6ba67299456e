#pragma once
// The example CT cut as clinical scans are (scan coverage, the any-CT cases): a box of a volume on the
// grid it occupies, and the slices a label spans.
#include <algorithm>
#include <cstdint>
#include <utility>

#include "io/volume.h"

namespace pneumo::testing_support {

/// The voxels lo..hi (inclusive, per axis) of `v` on the grid they occupy.
inline Volume crop(const Volume& v, const Index3& lo, const Index3& hi) {
  Geometry g = v.geometry();
  for (int a = 0; a < 3; ++a) g.dims[a] = hi[a] - lo[a] + 1;
  g.origin_mm = v.geometry().to_world(Vec3(double(lo[0]), double(lo[1]), double(lo[2])));
  Volume out(g, v.type());
  const std::size_t size = voxel_size(v.type());
  const auto* src = static_cast<const uint8_t*>(v.raw());
  auto* dst = static_cast<uint8_t*>(out.raw());
  for (int64_t k = 0; k < g.dims[2]; ++k)
    for (int64_t j = 0; j < g.dims[1]; ++j)
      std::copy_n(src + std::size_t(v.geometry().linear_index(lo[0], lo[1] + j, lo[2] + k)) * size,
                  std::size_t(g.dims[0]) * size, dst + std::size_t(g.linear_index(0, j, k)) * size);
  return out;
}

/// Slices k0..k1 (inclusive) of `v`.
inline Volume crop_slices(const Volume& v, int64_t k0, int64_t k1) {
  const Index3 d = v.geometry().dims;
  return crop(v, {0, 0, k0}, {d[0] - 1, d[1] - 1, k1});
}

/// The k range label `id` occupies (lo > hi when it is absent).
inline std::pair<int64_t, int64_t> slices_of(const Volume& labels, int id) {
  const Geometry& g = labels.geometry();
  int64_t lo = g.dims[2], hi = -1;
  for (int64_t n = 0; n < labels.voxel_count(); ++n)
    if (int(labels.value(n)) == id) {
      lo = std::min(lo, n / (g.dims[0] * g.dims[1]));
      hi = std::max(hi, n / (g.dims[0] * g.dims[1]));
    }
  return {lo, hi};
}

}  // namespace pneumo::testing_support
