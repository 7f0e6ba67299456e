#pragma once
// What the ray casters read: the CT in HU on its grid, an optional label map on the same grid, and
// the coarse occupancy grid that lets the GL path skip empty space.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/geometry.h"
#include "io/volume.h"

namespace pneumo {

/// Label id given to air connected to the edge of the grid (outside the body) by
/// mark_exterior_air(); never a real organ id (TotalSegmentator ids stay below 256).
inline constexpr uint16_t kExteriorAirLabel = 65535;

/// Whether a 16-bit texture holds HU value x as it is: an integer in [−32767, 32767] (snorm16 has no
/// value for −32768). RenderVolume::hu_is_int16 holds when every voxel does.
inline bool fits_int16_texture(float x) { return x >= -32767.0f && x <= 32767.0f && x == std::nearbyint(x); }

struct RenderVolume {
  Geometry geometry;
  std::vector<float> hu;          // voxel_count() values, i fastest
  std::vector<uint16_t> labels;   // empty, or voxel_count() ids on the same grid
  bool hu_is_int16 = false;       // every value an integer in [-32767, 32767]: a 16-bit texture suffices
  /// The width the views reconstruct this CT with (the scene's render.smoothing_mm; σ per axis from
  /// view_smoothing_sigma_voxels, filtered by smooth_for_views); 0: the voxels as they are. `hu`
  /// itself stays exact, so whatever reads it for measurement (the page's slices, the port ranking)
  /// sees the CT, not the views' copy.
  double smoothing_mm = 0.0;
  /// The views sample the smoothed CT on the CT's own grid even where the smoothing allows a coarser
  /// one (view_grid_stride): the full-cost reference the coarser grid is measured against.
  bool views_on_ct_grid = false;

  /// From a CT (any voxel type) and an optional label map; InputError when the label map's grid
  /// differs from the CT's or its ids do not fit 16 bits.
  static RenderVolume from(const Volume& ct, const Volume* labels);
  /// The same from HU already in floats on grid `g` (taken, not copied: a run hands the warp's own,
  /// and gets it back from the volume after the views), and an optional label map on that grid.
  /// `hu` is taken only on return: when the label map is refused, the caller still holds it.
  static RenderVolume from_hu(const Geometry& g, std::vector<float>&& hu, const Volume* labels);
  /// The same when the caller knows whether every value fits_int16_texture (round_as_written says,
  /// in the pass that rounds them): the 10⁸ values are not read again.
  static RenderVolume from_hu(const Geometry& g, std::vector<float>&& hu, const Volume* labels, bool hu_is_int16);
  /// The same with the labels already 16-bit ids on grid `g` (a run's warp holds them so; empty:
  /// none), taken as they are, not copied: only kExteriorAirLabel, which the views reserve, is
  /// refused, and then neither the HU nor the labels are taken.
  static RenderVolume from_hu(const Geometry& g, std::vector<float>&& hu, std::vector<uint16_t>&& labels,
                              bool hu_is_int16);

  /// Labels air (HU ≤ threshold) connected to the grid's faces as kExteriorAirLabel (6-connected
  /// flood fill), creating an all-zero label map first when there is none. Exterior views hide it.
  void mark_exterior_air(double threshold_hu = -500.0);

  /// World (mm) → continuous voxel index, and its linear part (the inverse of direction·spacing).
  Mat3 world_to_index() const;
  /// Whether a world point lies within the box of voxel centres.
  bool contains(const Vec3& world_mm) const;
};

/// The CT as the views reconstruct it (docs/rendering.md): each axis convolved with a Gaussian of
/// sigma_voxels[axis] voxels (truncated at 3σ and renormalised, the edge voxel repeated beyond the
/// grid), so that the trilinear samples and the central-difference normals of the ray casters show
/// tissue, not the voxel lattice. With integer HU (hu_is_int16) the result is rounded to whole HU
/// (half a HU is below any transfer function's resolution). A σ ≤ 0 leaves the volume as it is.
/// OpenMP over lines.
void smooth_for_views(RenderVolume& v, const Vec3& sigma_voxels);

/// The prefilter's σ per axis, in voxels, for a scene's render.smoothing_mm: max(1 voxel,
/// smoothing_mm) on each axis (zero when smoothing_mm ≤ 0). Why both bounds:
/// - One voxel at least. Where the CT holds a boundary without partial volume (the warp's gas
///   boundary, a painted phantom, a thresholded mask), trilinear samples draw its staircase:
///   terraces of period P voxels, whose ripple a Gaussian keeps exp(−2π²σ²/P²) of. At σ = 1 voxel
///   that is 5·10⁻⁵ of a 45° staircase's (P = √2), 0.11 of 3-voxel terraces and 0.45 of 5-voxel
///   ones; the cubic B-spline's σ = 1/√3 would keep 0.04, 0.48 and 0.77.
/// - A width in mm beside it (default 1.5 mm, view_settings.h). A CT's noise is per voxel: filtered
///   by σ voxels its gradient per mm grows as the voxels shrink, so a fine CT showed its noise as a
///   grain on every surface that a coarse one did not. A fixed width in mm makes views of one body
///   at 0.75 and 1.5 mm agree; 1.5 mm is about the in-plane resolution of an abdominal CT (the
///   width of its point spread, 1–1.5 mm), finer than anything a CT resolves.
/// tests/test_render_smoothing.cpp measures the normals on such a plane; `pneumo validate
/// view-resolution` the views across resolutions. Structures of one voxel lose contrast:
/// render.smoothing_mm = 0 shows the voxels as they are.
Vec3 view_smoothing_sigma_voxels(const Geometry& g, double smoothing_mm);

/// The views' grid: a fine CT's views cost what a coarse one's do. Where the prefilter's
/// σ spans f ≥ 2 voxels on an axis, the smoothed CT is sampled at every f-th voxel along it:
/// f = ⌊σ/voxel⌋, so the new spacing f·h ≤ σ. A Gaussian of σ keeps exp(−2π²σ²ν²) of frequency ν,
/// at the coarse grid's Nyquist ν = 1/(2fh) at most exp(−π²/2) = 0.7 %: the samples alias less than
/// that, and trilinear interpolation between them moves a smoothed edge by under a tenth of σ
/// (docs/rendering.md). At the default 1.5 mm a 0.75 mm CT is viewed on a 1.5 mm grid, an eighth
/// of its voxels to filter, differentiate and upload; CTs of 1 mm and coarser keep their grid.
/// {1, 1, 1} when smoothing_mm ≤ 0.
Index3 view_grid_stride(const Geometry& g, double smoothing_mm);
/// `g` with every stride[a]-th voxel along axis a: voxel (0,0,0), the origin and the direction
/// stay; the box of voxel centres loses at most stride − 1 voxels at its upper ends.
Geometry view_grid(const Geometry& g, const Index3& stride);

/// The volume as the ray casters sample it: `v` itself when v.smoothing_mm ≤ 0, else a copy in
/// `storage` filtered by smooth_for_views and sampled on view_grid(view_grid_stride) (the CT's own
/// grid when v.views_on_ct_grid). Its labels: on a coarser grid the label at each kept voxel,
/// always; on the CT's grid a copy of v's when `with_labels`, else none (the caller reads v's).
/// Filtered straight from v.hu, each pass keeping only the voxels the next one reads.
const RenderVolume& volume_as_viewed(const RenderVolume& v, std::optional<RenderVolume>& storage,
                                     bool with_labels = true);

/// Shading gradients (render_settings.h, model step 4), one per voxel, computed once per volume:
/// along each index axis the central difference of the voxel HU, h[i+1] − h[i−1] with indices
/// clamped to the grid, rounded to the nearest integer (ties to even) and clamped to ±32767, so
/// that it fits a 16-bit texture exactly. The gradient in HU per voxel index is half the stored
/// value (kGradientHalf); samples between voxels interpolate it trilinearly like the HU. Both ray
/// casters read these same numbers: the GL path from a texture built with voxel_gradients(), the
/// CPU reference by calling voxel_gradient() at the eight corners of each sample.
inline constexpr double kGradientHalf = 0.5;
inline constexpr int kGradientMax = 32767;
inline std::array<int16_t, 3> voxel_gradient(const RenderVolume& v, int64_t i, int64_t j, int64_t k) {
  const int64_t nx = v.geometry.dims[0], ny = v.geometry.dims[1], nz = v.geometry.dims[2];
  auto h = [&](int64_t a, int64_t b, int64_t c) { return double(v.hu[a + nx * (b + ny * c)]); };
  auto q = [](double diff) {
    return int16_t(std::clamp(std::nearbyint(diff), -double(kGradientMax), double(kGradientMax)));
  };
  return {q(h(std::min(i + 1, nx - 1), j, k) - h(std::max<int64_t>(i - 1, 0), j, k)),
          q(h(i, std::min(j + 1, ny - 1), k) - h(i, std::max<int64_t>(j - 1, 0), k)),
          q(h(i, j, std::min(k + 1, nz - 1)) - h(i, j, std::max<int64_t>(k - 1, 0)))};
}

/// The texture the GL path samples, 4 int16 per voxel (i fastest), OpenMP over slices: with
/// `with_hu` (integer HU, hu_is_int16) (HU, gx, gy, gz), else (gx, gy, gz, 0) beside a float HU
/// texture. gx, gy, gz as voxel_gradient().
std::vector<int16_t> voxel_gradients(const RenderVolume& v, bool with_hu);

/// Organ colours by label id, blended over the CT colour (method.md §8; Kitasaka Fig. 6: liver dark
/// red, kidneys yellow, aorta green). 8-bit RGBA per id, alpha 0 = not coloured. Ids 0..65535.
struct LabelColours {
  std::vector<std::array<uint8_t, 4>> rgba = std::vector<std::array<uint8_t, 4>>(65536, {0, 0, 0, 0});
};

/// The organs the views colour, and their TotalSegmentator ids (the phantom paints the same ids).
enum class ColouredOrgan { Liver, Kidneys, Arteries, Veins, Spleen, Gallbladder, Stomach, Pancreas, SmallBowel, Colon };
const std::vector<int>& organ_label_ids(ColouredOrgan organ);

/// Gives every id of `organ` the opaque colour (r, g, b).
void set_organ_colour(LabelColours& c, ColouredOrgan organ, uint8_t r, uint8_t g, uint8_t b);

/// The identifying colours pneumo gives the coloured organs (every preset but "laparoscopic"'s
/// modelled tissues, render/transfer_function.h).
LabelColours default_label_colours();

/// A label's colour as the views interpolate it (render_settings.h, model step 3): rgb premultiplied
/// by alpha, each rounded to 8 bits. Interpolated trilinearly between voxels, the premultiplied
/// colours blend two organs, or an organ and unlabelled tissue (alpha 0), by how much of each the
/// sample's neighbourhood holds: organ edges follow the smooth field, not the voxel lattice.
inline std::array<uint8_t, 4> premultiplied_colour(const LabelColours& c, uint16_t id) {
  const auto& q = c.rgba[id];
  auto mul = [&](uint8_t x) { return uint8_t((int(x) * int(q[3]) + 127) / 255); };
  return {mul(q[0]), mul(q[1]), mul(q[2]), q[3]};
}

/// premultiplied_colour() of every voxel's label, 4 bytes per voxel (i fastest). OpenMP over voxels.
std::vector<uint8_t> label_colour_volume(const std::vector<uint16_t>& labels, const LabelColours& c);

/// Empty-space skipping: block (bx, by, bz) covers voxel centres [b·B, (b+1)·B] on each axis
/// (B = kOccupancyBlock; the upper face is shared with the next block, so every sample position's
/// trilinear footprint and nearest voxel lie in the block that contains it). A block is empty,
/// and rays may jump over it, when the transfer function gives opacity 0 to every HU between the
/// minimum and maximum of its voxels, or when `hide_exterior` and all its voxels are exterior air.
inline constexpr int kOccupancyBlock = 4;  // 4 beat 8 and 16 on llvmpipe (bench/results/2026-11-23-render.md)
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
/// The same with the exterior-air test on `labels` (empty: none) instead of v.labels.
BlockRanges block_ranges(const RenderVolume& v, const std::vector<uint16_t>& labels);
/// The occupancy of each block under a transfer function.
OccupancyGrid occupancy(const BlockRanges& r, const TransferFunction& tf, bool hide_exterior);

}  // namespace pneumo
