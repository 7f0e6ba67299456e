#pragma once
// The back: per axial slice, the anterior surface of the vertebral column (or sacrum), found as the
// front end of the posterior-most run of fixed voxels near the body's midline. Everything in the
// body behind that surface is held fixed: spine, paraspinal muscles, the posterior flanks.
#include <cstdint>
#include <vector>

#include "anatomy/anatomical_axes.h"
#include "anatomy/body_mask.h"

namespace pneumo {

struct BackRules {
  double midline_half_width_mm = 25.0;  // the band searched: spinous process, laminae, pedicles, body
  double max_gap_mm = 8.0;              // gaps bridged inside the column (canal at lateral recesses)
  double max_start_fraction = 0.5;      // the run must start in the posterior half of the body's depth
  double smooth_half_window_mm = 12.0;  // most anterior over ±this along z: bridges discs (~10 mm)
};

/// Anteriority (SliceFrame::ant) of the spine's front in each axial slice; -1 where none is found.
/// `fixed` marks voxels already known to be fixed (fixed labels, bone by HU), `body` the body.
std::vector<int64_t> spine_front_per_slice(const std::vector<uint8_t>& fixed, const std::vector<uint8_t>& body,
                                           const std::vector<SliceCentre>& centres, const SliceFrame& f,
                                           const BackRules& rules = {});

}  // namespace pneumo
