#include "pipeline/diaphragm_motion.h"

#include <algorithm>
#include <cmath>

#include "anatomy/anatomical_axes.h"

namespace pneumo {

namespace {

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const std::size_t k = std::min(v.size() - 1, std::size_t(std::floor(q * double(v.size() - 1) + 0.5)));
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(k), v.end());
  return v[k];
}

}  // namespace

DiaphragmMotion diaphragm_motion(const VoxelRoles& roles, const std::vector<uint8_t>& body,
                                 const std::vector<uint8_t>& lungs, const CarryFn& carry) {
  DiaphragmMotion d;
  const Geometry& g = roles.geometry;
  const SliceFrame f = slice_frame(g);
  const AnatomicalAxes axes = anatomical_axes(g);
  const int up = axes.sign[2];
  // The CT's own box along each frame axis (the padding around it is air the roles added).
  auto first = [&](int axis) { return roles.ct_first[axis]; };
  auto last = [&](int axis) { return roles.ct_last[axis] < 0 ? g.dims[axis] - 1 : roles.ct_last[axis]; };
  auto lung = [&](int64_t v) { return lungs[std::size_t(v)] != 0; };
  std::vector<double> rise;
  const int64_t s_lo = first(f.si), s_hi = last(f.si), n = s_hi - s_lo + 1;
  auto slice = [&](int64_t k) { return up > 0 ? s_hi - k : s_lo + k; };   // k = 0 the head's end
  for (int64_t a = first(f.ap); a <= last(f.ap); ++a)
    for (int64_t l = first(f.lat); l <= last(f.lat); ++l) {
      // From the head down: the first run of lung, and the tissue right under it; a column whose lung
      // reaches the box's lowest slice has no face in view.
      int64_t k = 0;
      while (k < n && !lung(f.index(l, a, slice(k)))) ++k;
      if (k == n) continue;
      while (k < n && lung(f.index(l, a, slice(k)))) ++k;
      if (k == n) continue;
      const int64_t s = slice(k - 1), below = slice(k);
      if (!body[std::size_t(f.index(l, a, below))]) continue;
      Vec3 ijk(0, 0, 0);
      ijk[f.lat] = double(l);
      ijk[f.ap] = double(a);
      ijk[f.si] = 0.5 * double(s + below);   // the face between the two
      const Vec3 rest = g.to_world(ijk);
      Vec3 moved = rest;
      ++d.columns;
      if (!carry(rest, moved)) {
        ++d.not_carried;
        continue;
      }
      rise.push_back(moved[2] - rest[2]);   // world z is superior (RAS)
    }
  d.median_cranial_mm = percentile(rise, 0.5);
  d.dome_cranial_mm = percentile(rise, 0.95);
  return d;
}

}  // namespace pneumo
