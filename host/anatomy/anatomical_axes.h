#pragma once
// Which voxel axis runs left-right, back-front and foot-head in a grid, and which way. Padding,
// the automatic role rules and the "per axial slice" steps all work on these, so a grid stored LPS,
// flipped, or with its slices along another axis is treated exactly like the RAS one.
#include <array>
#include <cstdint>
#include <vector>

#include "core/geometry.h"
#include "domain/label_set.h"

namespace pneumo {

/// For each world axis (0 = x Right, 1 = y Anterior, 2 = z Superior): the voxel axis most aligned
/// with it and whether increasing that index moves towards R/A/S (+1) or away (-1). The three voxel
/// axes are always distinct (assigned greedily by largest |cosine|, as Geometry::orientation_code).
struct AnatomicalAxes {
  std::array<int, 3> axis{0, 1, 2};
  std::array<int, 3> sign{1, 1, 1};
};
AnatomicalAxes anatomical_axes(const Geometry& g);

/// A grid seen as axial slices: voxel (lat, ap, si) along the lateral, antero-posterior and
/// superior voxel axes. `ant(a)` turns an index along the ap axis into "anteriority" (larger =
/// more anterior) whatever the axis' sign; it is its own inverse.
struct SliceFrame {
  int lat = 0, ap = 1, si = 2;                // voxel axes
  int64_t n_lat = 1, n_ap = 1, n_si = 1;      // dims along them
  int64_t st_lat = 1, st_ap = 1, st_si = 1;   // linear-index strides
  double h_lat = 1, h_ap = 1, h_si = 1;       // spacing along them (mm)
  int ap_sign = 1;                            // +1: index increases anteriorly

  int64_t index(int64_t l, int64_t a, int64_t s) const { return l * st_lat + a * st_ap + s * st_si; }
  int64_t ant(int64_t a) const { return ap_sign > 0 ? a : n_ap - 1 - a; }
};
SliceFrame slice_frame(const Geometry& g);

/// For each axial column (lat l, slice s) of `f`, at s·n_lat + l: the anteriority (SliceFrame::ant)
/// of its most anterior voxel whose label is in `ids`; -1 where the column holds none. What lies in
/// front of such a voxel in its column is "anterior to" the labelled organ (the space of Retzius in
/// front of the bladder, auto_roles.h rule 5b; the gas there, pipeline/cavity_measures.h).
std::vector<int64_t> front_of_labels(const uint16_t* label, const SliceFrame& f, const LabelSet& ids);

}  // namespace pneumo
