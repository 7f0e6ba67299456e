// Why a run along the midline: in an axial slice the column is the one structure that is fixed
// without a break from the back muscles (autochthon labels) or the spinous process through the
// laminae and pedicles to the vertebral body; anterior to it lie the great vessels and bowel
// (viscera). Starting from the back and stopping at the first gap finds its front without naming
// any label: it works from fixed labels and from a bone mask alike. The disc levels (no bone, no
// vertebra label) stop the run at the posterior elements, which the smoothing over z repairs.
// Below the sacrum (perineum, femoral heads) the first fixed run may be a gluteal muscle or the
// pelvic floor: the back region then stays small, which is harmless there.
#include "anatomy/back_region.h"

#include <algorithm>
#include <cmath>

namespace pneumo {

namespace {

int64_t front_in_slice(const std::vector<uint8_t>& fixed, const std::vector<uint8_t>& body, const SliceCentre& c,
                       const SliceFrame& f, int64_t s, const BackRules& r) {
  if (c.count == 0) return -1;
  const double half = r.midline_half_width_mm / f.h_lat;
  const int64_t l0 = std::max<int64_t>(0, int64_t(std::ceil(c.lat - half)));
  const int64_t l1 = std::min<int64_t>(f.n_lat - 1, int64_t(std::floor(c.lat + half)));
  // Profiles along anteriority t: any fixed / any body voxel in the band.
  std::vector<uint8_t> has_fixed(static_cast<std::size_t>(f.n_ap), 0), has_body(static_cast<std::size_t>(f.n_ap), 0);
  for (int64_t a = 0; a < f.n_ap; ++a) {
    const int64_t t = f.ant(a);
    for (int64_t l = l0; l <= l1; ++l) {
      const int64_t v = f.index(l, a, s);
      // Fixed voxels outside the body (a labelled table) are not the back.
      has_fixed[t] |= fixed[v] & body[v];
      has_body[t] |= body[v];
    }
  }
  int64_t back = -1, front = -1;
  for (int64_t t = 0; t < f.n_ap; ++t)
    if (has_body[t]) {
      if (back < 0) back = t;
      front = t;
    }
  if (back < 0) return -1;
  int64_t start = -1;
  for (int64_t t = 0; t < f.n_ap && start < 0; ++t)
    if (has_fixed[t]) start = t;
  if (start < 0 || double(start - back) > r.max_start_fraction * double(front - back)) return -1;
  const int64_t max_gap = int64_t(std::floor(r.max_gap_mm / f.h_ap));
  int64_t last = start;
  for (int64_t t = start + 1; t < f.n_ap && t - last <= max_gap + 1; ++t)
    if (has_fixed[t]) last = t;
  return last;
}

}  // namespace

std::vector<int64_t> spine_front_per_slice(const std::vector<uint8_t>& fixed, const std::vector<uint8_t>& body,
                                           const std::vector<SliceCentre>& centres, const SliceFrame& f,
                                           const BackRules& r) {
  std::vector<int64_t> raw(static_cast<std::size_t>(f.n_si));
#pragma omp parallel for schedule(dynamic, 4)
  for (int64_t s = 0; s < f.n_si; ++s) raw[s] = front_in_slice(fixed, body, centres[s], f, s, r);
  const int64_t w = int64_t(std::floor(r.smooth_half_window_mm / f.h_si));
  std::vector<int64_t> out(static_cast<std::size_t>(f.n_si), -1);
  for (int64_t s = 0; s < f.n_si; ++s)
    for (int64_t q = std::max<int64_t>(0, s - w); q <= std::min(f.n_si - 1, s + w); ++q)
      out[s] = std::max(out[s], raw[q]);
  return out;
}

}  // namespace pneumo
