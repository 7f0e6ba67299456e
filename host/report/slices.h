#pragma once
// Slice montages for reports: the axial, coronal and sagittal planes through one world point, side
// by side, with an optional class overlay (roles, organ labels) blended over the CT.
//
// Pixels are square in world millimetres and the planes are world planes (RAS+), sampled through
// the grid's own index-to-world transform: anisotropic spacing, flipped axes and oblique directions
// all show the anatomy the right way round and the right shape. Orientation is radiological:
//   axial    (seen from the feet): anterior up, the patient's right on the image's left;
//   coronal  (seen from the front): superior up, the patient's right on the image's left;
//   sagittal (seen from the patient's left): superior up, anterior on the image's left.
// For a "before | after" comparison render one row per volume with the same SliceView (same
// point, same box, same pixel size) and stack them with stack_rows().
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/geometry.h"
#include "io/volume.h"
#include "image/image.h"

namespace pneumo {

/// Grey levels: low_hu and below black, high_hu and above white (default: soft tissue).
struct SliceWindow {
  double low_hu = -200.0, high_hu = 300.0;
};

/// One class of an overlay: colour, opacity (0 = not drawn) and its legend text.
struct OverlayClass {
  std::string name;  // "" = no legend entry
  Rgb colour;
  double alpha = 0.0;
};

/// Per-voxel classes drawn over the CT, sampled nearest-neighbour on their own grid.
struct SliceOverlay {
  Geometry geometry;
  const uint8_t* classes = nullptr;  // geometry.voxel_count() values, i fastest
  std::vector<OverlayClass> table;   // indexed by class value; values past its end are not drawn
};

/// An axis-aligned box in world millimetres.
struct WorldBox {
  Vec3 min_mm = Vec3::Zero(), max_mm = Vec3::Zero();
  Vec3 centre() const { return 0.5 * (min_mm + max_mm); }
};
/// The world box around every voxel of a grid (voxel centres ± half a voxel, all 8 corners).
WorldBox world_box(const Geometry& g);

struct SliceView {
  SliceWindow window;
  std::optional<Vec3> point_mm;  // where the three planes cross; default: the box's centre
  std::optional<WorldBox> box;   // region shown; default: world_box of the CT
  double pixel_mm = 0.0;         // 0 = automatic (see resolved_pixel_mm)
  int min_panel_px = 400;        // automatic pixel size: the largest panel side at least this...
  int max_panel_px = 640;        // ...and at most this
  bool trilinear = true;         // CT sampling; the overlay is always nearest-neighbour
  std::string title;             // written above the row when not empty
  bool annotate = true;          // orientation letters, plane captions and ticks on the panels
};

/// The pixel size a view will use for a CT: pixel_mm if set, else the CT's smallest spacing, made
/// finer or coarser so the box's largest side spans min_panel_px..max_panel_px pixels.
double resolved_pixel_mm(const Volume& ct, const SliceView& view);

/// The axial, coronal and sagittal panels through view.point_mm (in that order), each annotated
/// (when view.annotate) with orientation letters, its plane's position and ticks where the other
/// two planes cut it. The CT may be of any voxel type (HU). Pixel (c, r) of a panel has its centre
/// half a pixel in from the box's R/A/S corner, then c and r pixels towards L/P/I.
std::array<RgbImage, 3> render_slice_panels(const Volume& ct, const SliceOverlay* overlay, const SliceView& view);

/// The three panels side by side (axial | coronal | sagittal), the title above them.
RgbImage render_slice_row(const Volume& ct, const SliceOverlay* overlay, const SliceView& view);

/// A legend strip: a colour swatch and the name of every class drawn (alpha > 0, name given).
RgbImage render_legend(const std::vector<OverlayClass>& table);

/// Rows one under another (e.g. before over after), legend or other strips included.
RgbImage stack_rows(const std::vector<RgbImage>& rows);

/// Background of montages (between panels, around the legend).
constexpr Rgb kMontageBackground{40, 40, 40};

}  // namespace pneumo
