#pragma once
// What the ray casters read: the CT in HU on its grid, an optional label map on the same grid, and
// the coarse occupancy grid that lets the GL path skip empty space.
#include <array>
#include <cstdint>
#include <vector>

#include "core/geometry.h"
#include "io/volume.h"

namespace pneumo {

/// Label id given to air connected to the edge of the grid (outside the body) by
/// mark_exterior_air(); never a real organ id (TotalSegmentator ids stay below 256).
inline constexpr uint16_t kExteriorAirLabel = 65535;

struct RenderVolume {
  Geometry geometry;
  std::vector<float> hu;          // voxel_count() values, i fastest
  std::vector<uint16_t> labels;   // empty, or voxel_count() ids on the same grid
  bool hu_is_int16 = false;       // every value an integer in [-32767, 32767]: a 16-bit texture suffices

  /// From a CT (any voxel type) and an optional label map; InputError when the label map's grid
  /// differs from the CT's or its ids do not fit 16 bits.
  static RenderVolume from(const Volume& ct, const Volume* labels);

  /// Labels air (HU ≤ threshold) connected to the grid's faces as kExteriorAirLabel (6-connected
  /// flood fill), creating an all-zero label map first when there is none. Exterior views hide it.
  void mark_exterior_air(double threshold_hu = -500.0);

  /// World (mm) → continuous voxel index, and its linear part (the inverse of direction·spacing).
  Mat3 world_to_index() const;
  /// Whether a world point lies within the box of voxel centres.
  bool contains(const Vec3& world_mm) const;
};

/// Organ colours by label id, blended over the CT colour (method.md §8; Kitasaka Fig. 6: liver dark
/// red, kidneys yellow, aorta green). 8-bit RGBA per id, alpha 0 = not coloured. Ids 0..65535.
struct LabelColours {
  std::vector<std::array<uint8_t, 4>> rgba = std::vector<std::array<uint8_t, 4>>(65536, {0, 0, 0, 0});
};

/// The colours pneumo uses for TotalSegmentator ids (and the phantom's own ids from 200 up).
LabelColours default_label_colours();

/// Empty-space skipping: block (bx, by, bz) covers voxel centres [b·B, (b+1)·B] on each axis
/// (B = kOccupancyBlock; the upper face is shared with the next block, so every sample position's
/// trilinear footprint and nearest voxel lie in the block that contains it). A block is empty,
/// and rays may jump over it, when the transfer function gives opacity 0 to every HU between the
/// minimum and maximum of its voxels, or when `hide_exterior` and all its voxels are exterior air.
inline constexpr int kOccupancyBlock = 8;
struct OccupancyGrid {
  Index3 blocks{0, 0, 0};
  std::vector<uint8_t> occupied;  // 1 = may hold something visible
};

struct TransferFunction;
struct BlockRanges {
  Index3 blocks{0, 0, 0};
  std::vector<float> min_hu, max_hu;
  std::vector<uint8_t> all_exterior;
};
/// Per-block HU ranges (computed once per volume).
BlockRanges block_ranges(const RenderVolume& v);
/// The occupancy of each block under a transfer function.
OccupancyGrid occupancy(const BlockRanges& r, const TransferFunction& tf, bool hide_exterior);

}  // namespace pneumo
