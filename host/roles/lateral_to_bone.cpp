// Limits: a rib deeper than the wall shell (thick subcutaneous fat) makes the fat outside it fixed;
// a calcified iliac artery more than min_offset_mm out makes the tissue lateral to it fixed in
// that row. Both are small, and fixed is the safe error there: that tissue barely moves.
#include "roles/lateral_to_bone.h"

#include <cmath>

namespace pneumo {

std::vector<uint8_t> lateral_to_bone(const std::vector<uint8_t>& bone, const std::vector<uint8_t>& candidate,
                                     const std::vector<SliceCentre>& centres, const SliceFrame& f,
                                     const LateralToBoneRules& r) {
  std::vector<uint8_t> out(bone.size(), 0);
#pragma omp parallel for schedule(dynamic, 4)
  for (int64_t s = 0; s < f.n_si; ++s) {
    const SliceCentre& c = centres[s];
    if (c.count == 0) continue;
    const double min_off = r.min_offset_mm / f.h_lat;
    // Rows: lateral index l runs across the patient; "low" side l < centroid, "high" side l > it.
    const int64_t low_limit = int64_t(std::floor(c.lat - min_off));   // bone at l <= this counts (low side)
    const int64_t high_limit = int64_t(std::ceil(c.lat + min_off));   // bone at l >= this counts (high side)
    for (int64_t a = 0; a < f.n_ap; ++a) {
      int64_t low_bone = -1, high_bone = f.n_lat;
      for (int64_t l = 0; l <= low_limit && l < f.n_lat; ++l)
        if (bone[f.index(l, a, s)]) { low_bone = l; break; }
      for (int64_t l = f.n_lat - 1; l >= high_limit && l >= 0; --l)
        if (bone[f.index(l, a, s)]) { high_bone = l; break; }
      for (int64_t l = 0; l < low_bone; ++l) {
        const int64_t v = f.index(l, a, s);
        out[v] = candidate[v];
      }
      for (int64_t l = high_bone + 1; l < f.n_lat; ++l) {
        const int64_t v = f.index(l, a, s);
        out[v] = candidate[v];
      }
    }
  }
  return out;
}

}  // namespace pneumo
