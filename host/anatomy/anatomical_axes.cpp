#include "anatomy/anatomical_axes.h"

#include <algorithm>

#include <cmath>

namespace pneumo {

AnatomicalAxes anatomical_axes(const Geometry& g) {
  AnatomicalAxes ax;
  bool world_used[3] = {false, false, false}, voxel_used[3] = {false, false, false};
  for (int n = 0; n < 3; ++n) {
    int best_w = 0, best_v = 0;
    double best = -1.0;
    for (int w = 0; w < 3; ++w)
      for (int v = 0; v < 3; ++v)
        if (!world_used[w] && !voxel_used[v] && std::abs(g.direction(w, v)) > best) {
          best = std::abs(g.direction(w, v));
          best_w = w;
          best_v = v;
        }
    world_used[best_w] = voxel_used[best_v] = true;
    ax.axis[best_w] = best_v;
    ax.sign[best_w] = g.direction(best_w, best_v) >= 0 ? 1 : -1;
  }
  return ax;
}

SliceFrame slice_frame(const Geometry& g) {
  const AnatomicalAxes ax = anatomical_axes(g);
  const int64_t stride[3] = {1, g.dims[0], g.dims[0] * g.dims[1]};
  SliceFrame f;
  f.lat = ax.axis[0];
  f.ap = ax.axis[1];
  f.si = ax.axis[2];
  f.n_lat = g.dims[f.lat];
  f.n_ap = g.dims[f.ap];
  f.n_si = g.dims[f.si];
  f.st_lat = stride[f.lat];
  f.st_ap = stride[f.ap];
  f.st_si = stride[f.si];
  f.h_lat = g.spacing_mm[f.lat];
  f.h_ap = g.spacing_mm[f.ap];
  f.h_si = g.spacing_mm[f.si];
  f.ap_sign = ax.sign[1];
  return f;
}

std::vector<int64_t> front_of_labels(const uint16_t* label, const SliceFrame& f, const LabelSet& ids) {
  std::vector<int64_t> front(std::size_t(f.n_si * f.n_lat), -1);
  if (!label || ids.empty()) return front;
#pragma omp parallel for schedule(static)
  for (int64_t s = 0; s < f.n_si; ++s)
    for (int64_t l = 0; l < f.n_lat; ++l) {
      int64_t& most = front[std::size_t(s * f.n_lat + l)];
      for (int64_t a = 0; a < f.n_ap; ++a)
        if (ids.contains(label[f.index(l, a, s)])) most = std::max(most, f.ant(a));
    }
  return front;
}

}  // namespace pneumo
