#pragma once
// Transfer functions (method.md §8): HU → colour and opacity, piecewise linear between points,
// constant beyond the first and last point. Presets follow 3D Slicer's CT set (presets.xml);
// "laparoscopic" is pneumo's own (tissue colours computed from published optical properties, gas
// clear). Opacities are per 1 mm of ray (the opacity unit distance, as in VTK/Slicer); the ray
// casters correct them for their step: α′ = 1 − (1 − α)^(Δs / 1 mm).
#include <array>
#include <string>
#include <vector>

#include "core/geometry.h"
#include "domain/types.h"
#include "render/render_volume.h"
#include "render/view_settings.h"

namespace pneumo {

struct TransferFunction {
  std::string name;
  std::vector<std::array<double, 2>> opacity;  // (HU, α in [0, 1]), HU ascending
  std::vector<std::array<double, 4>> colour;   // (HU, r, g, b in [0, 1]), HU ascending

  double opacity_at(double hu) const;
  Vec3 colour_at(double hu) const;
  /// Largest opacity over HU in [lo, hi] (empty-space skipping: 0 = nothing visible there).
  double max_opacity(double lo, double hi) const;
  /// RGBA floats of `n` entries, entry i at HU hu_min + i (the GL path's lookup table).
  std::vector<float> table_rgba(double hu_min, int n) const;
  /// Throws InputError (naming `what`) unless both lists are non-empty, HU non-decreasing, values in [0, 1].
  void validate(const std::string& what) const;
};

/// A named preset.
TransferFunction preset_transfer_function(RenderPreset preset);

/// The organ colours a preset blends over its transfer function's: default_label_colours(), and
/// for "laparoscopic" the computed colours of the organs render/tissue_colour.h models.
LabelColours preset_label_colours(RenderPreset preset);

/// The scene's choice: render.preset, or the points of render.custom_opacity / custom_colour
/// when the preset is "custom".
TransferFunction scene_transfer_function(const ViewSettings& render);

/// The GL lookup table's HU range: 1 HU per entry from -2048 to 4095 (CT values beyond clamp).
inline constexpr double kTfTableHuMin = -2048.0;
inline constexpr int kTfTableSize = 6144;

}  // namespace pneumo
