#include "anatomy/body_mask.h"

#include "anatomy/connected_components.h"

namespace pneumo {

std::vector<uint8_t> body_mask(const float* hu, const Geometry& g, double threshold_hu) {
  const int64_t n = g.voxel_count();
  std::vector<uint8_t> mask(static_cast<std::size_t>(n));
  const float thr = float(threshold_hu);
#pragma omp parallel for schedule(static)
  for (int64_t v = 0; v < n; ++v) mask[v] = hu[v] > thr;
  keep_largest_component(mask, g.dims);
  fill_holes_per_axial_slice(mask, slice_frame(g));
  return mask;
}

void fill_holes_per_axial_slice(std::vector<uint8_t>& mask, const SliceFrame& f) {
  const int64_t nl = f.n_lat, na = f.n_ap;
#pragma omp parallel
  {
    // Per slice: copy it out (contiguous for the usual RAS/LPS grids), flood the outside from the
    // border with an explicit stack, write back every pixel the flood did not reach.
    std::vector<uint8_t> plane(static_cast<std::size_t>(nl * na));   // 0 background, 1 body, 2 outside (reached)
    std::vector<int64_t> stack;
#pragma omp for schedule(dynamic, 2)
    for (int64_t s = 0; s < f.n_si; ++s) {
      for (int64_t a = 0; a < na; ++a)
        for (int64_t l = 0; l < nl; ++l) plane[a * nl + l] = mask[f.index(l, a, s)];
      stack.clear();
      const auto seed = [&](int64_t p) {
        if (plane[p] == 0) {
          plane[p] = 2;
          stack.push_back(p);
        }
      };
      for (int64_t l = 0; l < nl; ++l) {
        seed(l);
        seed((na - 1) * nl + l);
      }
      for (int64_t a = 0; a < na; ++a) {
        seed(a * nl);
        seed(a * nl + nl - 1);
      }
      while (!stack.empty()) {
        const int64_t p = stack.back();
        stack.pop_back();
        const int64_t l = p % nl, a = p / nl;
        if (l > 0) seed(p - 1);
        if (l + 1 < nl) seed(p + 1);
        if (a > 0) seed(p - nl);
        if (a + 1 < na) seed(p + nl);
      }
      for (int64_t a = 0; a < na; ++a)
        for (int64_t l = 0; l < nl; ++l)
          if (plane[a * nl + l] == 0) mask[f.index(l, a, s)] = 1;
    }
  }
}

std::vector<SliceCentre> body_centres(const std::vector<uint8_t>& mask, const SliceFrame& f) {
  std::vector<SliceCentre> c(static_cast<std::size_t>(f.n_si));
#pragma omp parallel for schedule(static)
  for (int64_t s = 0; s < f.n_si; ++s) {
    double sl = 0, sa = 0;
    int64_t count = 0;
    for (int64_t a = 0; a < f.n_ap; ++a)
      for (int64_t l = 0; l < f.n_lat; ++l)
        if (mask[f.index(l, a, s)]) {
          sl += double(l);
          sa += double(f.ant(a));
          ++count;
        }
    if (count > 0) c[s] = {sl / double(count), sa / double(count), count};
  }
  return c;
}

}  // namespace pneumo
