#pragma once
// Air around the CT so the wall has room to rise (a real CT is often cropped at the skin). Padding
// is asked for in patient terms (anterior, lateral, superior, inferior, in mm) and applied to the
// voxel axes those directions map to (anatomical_axes), so it lands on the right ends of an LPS or
// flipped grid too. Every original voxel keeps its world position: the origin moves instead.
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "core/geometry.h"
#include "io/volume.h"

namespace pneumo {

struct PadMm {
  double anterior = 0.0, lateral = 0.0, superior = 0.0, inferior = 0.0;
};

/// Voxels added before index 0 (lo) and after the last index (hi) of each voxel axis.
struct PadVoxels {
  Index3 lo{0, 0, 0}, hi{0, 0, 0};
  bool empty() const { return lo == Index3{0, 0, 0} && hi == Index3{0, 0, 0}; }
};

/// ceil(mm / spacing) voxels on the ends facing anterior, left and right, superior, inferior.
PadVoxels pad_voxels(const Geometry& g, const PadMm& mm);
/// The grid after padding: dims grown, origin moved by -lo voxels, spacing and direction kept.
Geometry padded_geometry(const Geometry& g, const PadVoxels& pad);
/// The inverse: the original grid inside a padded one.
Geometry unpadded_geometry(const Geometry& padded, const PadVoxels& pad);

/// The padded copy of `src` (dims `dims`, i fastest), converted to TOut, `fill` in the new voxels,
/// into `out` (the padded grid's voxel count). Every output voxel is written once, on every thread.
template <class TOut, class TIn>
void pad_into(const TIn* src, const Index3& dims, const PadVoxels& pad, TOut fill, TOut* out) {
  const Index3 nd{dims[0] + pad.lo[0] + pad.hi[0], dims[1] + pad.lo[1] + pad.hi[1], dims[2] + pad.lo[2] + pad.hi[2]};
#pragma omp parallel for schedule(static)
  for (int64_t k = 0; k < nd[2]; ++k)
    for (int64_t j = 0; j < nd[1]; ++j) {
      TOut* dst = out + nd[0] * (j + nd[1] * k);
      const int64_t sj = j - pad.lo[1], sk = k - pad.lo[2];
      if (sj < 0 || sj >= dims[1] || sk < 0 || sk >= dims[2]) {
        std::fill_n(dst, nd[0], fill);
        continue;
      }
      const TIn* row = src + dims[0] * (sj + dims[1] * sk);
      std::fill_n(dst, pad.lo[0], fill);
      for (int64_t i = 0; i < dims[0]; ++i) dst[pad.lo[0] + i] = static_cast<TOut>(row[i]);
      std::fill_n(dst + pad.lo[0] + dims[0], pad.hi[0], fill);
    }
}

/// The same as a new array.
template <class TOut, class TIn>
std::vector<TOut> pad_array(const TIn* src, const Index3& dims, const PadVoxels& pad, TOut fill) {
  const Index3 nd{dims[0] + pad.lo[0] + pad.hi[0], dims[1] + pad.lo[1] + pad.hi[1], dims[2] + pad.lo[2] + pad.hi[2]};
  std::vector<TOut> out(std::size_t(nd[0] * nd[1] * nd[2]));
  pad_into(src, dims, pad, fill, out.data());
  return out;
}

/// The padded volume, same voxel type; `fill` (e.g. -1000 HU, label 0) must be representable in
/// that type, else std::invalid_argument.
Volume pad_volume(const Volume& v, const PadVoxels& pad, double fill);
Volume pad_volume(const Volume& v, const PadMm& pad, double fill);

}  // namespace pneumo
