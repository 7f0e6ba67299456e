#pragma once
// The chest above the diaphragm, found on the CT with or without labels: the lungs by their density,
// the diaphragm as the surface under them, and what lies above it between them (the heart and the
// mediastinum). The roles hold the heart and mediastinum fixed, make the lungs wall as soft as lung
// (roles.compliant_lungs; fixed without it) and the first millimetres under it wall, so the gas never
// opens beside the lungs or the heart (auto_roles.h, rules 3b and 5c).
//
// Lungs: 6-connected parts of aerated tissue (HU below aerated_hu) inside the body, each of at least
// min_lung_ml whose median HU lies in [lung_median_min_hu, lung_median_max_hu]. Aerated lung is
// −900…−700 HU with its vessels and the dependent bases denser; gas in the stomach and bowel is air,
// its median −1000 with noise, below −950 in any pocket of that size; outside air is not in the body.
// Labelled lungs and heart (names, structure_names.h) join what the density finds.
//
// Diaphragm: per (lateral, antero-posterior) column, the lowest lung voxel is the diaphragm's upper
// surface there; in a column without lung between lung columns (the heart and mediastinum rest on
// the central tendon) its height is interpolated linearly from the nearest lung columns on either
// side, across (lateral) and along (antero-posterior), the lower of the two. The chest is every body
// voxel above that surface. On the phantom the surface lies within a voxel of the drawn diaphragm
// under the heart (median 0.5 voxel) and holds 91 % of the heart; the rest is its front where no
// lung lies on either side of it, or its bottom, up to 7.5 mm above the surface.
//
// Limits: a mottled colon whose gas bubbles join into one part of ≥ min_lung_ml with a lung-like
// median can pass for lung (a label map settles it); the surface is a height field, so a lung that
// folds under itself is flattened; the chest ends at the outermost lung columns, so the heart's front
// where it touches the chest wall with no lung beside it (the cardiac notch) is not in it.
#include <cstdint>
#include <vector>

#include "core/geometry.h"

namespace pneumo {

struct ThoraxOptions {
  double aerated_hu = -400.0;           // lung at any inspiration lies below, soft tissue above −200
  double lung_median_min_hu = -950.0;   // below: a pocket of gas (median ≈ −1000)
  double lung_median_max_hu = -600.0;   // above: tissue with a few bubbles, not parenchyma
  double min_lung_ml = 15.0;            // smaller parts are bubbles or bowel gas; a lung base cut by the
                                        // scan's top slice is tens of ml
  double lung_closing_mm = 6.0;         // the lungs' own vessels and bronchi, up to twice this across, are
                                        // lung tissue (a morphological closing); the hilum's are wider.
                                        // 0: no lung_tissue (it costs two distance transforms)
};

struct Thorax {
  std::vector<uint8_t> lungs;   // 1: aerated lung (by density), or a labelled lung or heart voxel
  std::vector<uint8_t> chest;   // 1: a body voxel above the diaphragm's surface (lungs included)
  std::vector<uint8_t> lung_tissue;   // 1: the lungs with the vessels and bronchi inside them (a closing
                                      // of the aerated and labelled lung by lung_closing_mm, within the
                                      // chest), the labelled heart and other chest structures excluded;
                                      // empty when lung_closing_mm is 0
  double lung_ml = 0.0, chest_ml = 0.0;
  int lung_parts = 0;           // parts found by density
};

/// The thorax of the CT `hu` on grid `g` within `body` (body_mask.h). `labelled`, when not null, marks
/// the voxels a label map names as lung (1) or as another structure above the diaphragm, the heart (2)
/// (structure_names.h: lies_above_the_diaphragm).
Thorax find_thorax(const float* hu, const std::vector<uint8_t>& body, const Geometry& g,
                   const std::vector<uint8_t>* labelled = nullptr, const ThoraxOptions& opt = {});

}  // namespace pneumo
