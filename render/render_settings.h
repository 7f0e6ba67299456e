#pragma once
// The ray-casting model both ray casters implement (the GLSL one in shaders/raycast.frag and the
// CPU reference in ray_cast_ref.cpp), stated once (method.md §8):
//
// 0. Volume: the CT as RenderVolume::smoothing_mm reconstructs it (smooth_for_views in
//    render_volume.h: a Gaussian prefilter of the views' copy); every HU and gradient below is read
//    from that copy, labels from the volume itself.
// 1. Ray: from the camera's tip along ViewCamera::ray() of the pixel centre moved by the settings'
//    pixel offset, (px + ½ + ox, py + ½ + oy) (0 but in an anti-aliasing pass, step 7). It is clipped to the
//    box of voxel centres (index space [0, dims−1]); samples sit at t_k = near + (k + j)·Δs mm for
//    the k with t_k inside the clipped interval; j = 0, or with jitter a per-pixel hash in [0, 1)
//    (jitter_offset(), the same bits on both sides, so jittered images still compare).
// 2. Sample: HU by trilinear interpolation; colour c and opacity α from the transfer function;
//    opacity corrected for the step: α′ = 1 − (1 − α)^(Δs / 1 mm). (The GL path tabulates c and
//    the corrected α′ at every integer HU and interpolates the table linearly; the reference
//    evaluates the piecewise-linear function and the correction at the sample's HU.) With hide_exterior_air, a
//    sample whose nearest voxel is labelled kExteriorAirLabel contributes nothing (exterior views).
// 2b. Entry: a sample that contributes, right after one that did not (or, in the GL path, after an
//    empty block it jumped over), is moved to half a step past where the opacity begins (found by
//    kEntryBisections bisections of [t_clear, t] on "contributes"), and the following samples go
//    on a step apart from there: a midpoint sum of the opacity from the entry, whatever the step.
//    Without it the first sample of a surface lies anywhere up to a step inside it, in bands that
//    follow the step lattice (wood grain). A moved sample that contributes nothing (a layer
//    thinner than half a step) counts as clear.
// 3. Labels: each voxel's id picks an RGBA colour, stored premultiplied (premultiplied_colour() in
//    render_volume.h); their trilinear interpolation (R, G, B, A) at the sample gives
//    c ← c·(1 − label_opacity·A) + label_opacity·(R, G, B): organ edges blend over a voxel instead
//    of stepping at the nearest voxel's boundary.
// 4. Shading (Phong with a headlight at the tip): gradient g (HU per voxel index) by trilinear
//    interpolation, at the sample, of per-voxel central differences pre-computed once per volume
//    (voxel_gradient() in render_volume.h: (h[i+1] − h[i−1])/2 per index axis, the difference
//    rounded to an integer and clamped to ±32767 so it is exact in 16 bits), taken to world
//    (g_w = M⁻ᵀ g with M = direction·spacing); n = g_w/|g_w|; light and view both along −dir, so
//    diffuse = |n·dir|, specular = |n·dir|^shininess (two-sided). Headlight attenuation at the
//    sample's distance t: a = 1/(1 + (t/d0)²). Shaded colour = c·(ambient + diffuse_k·diffuse·a)
//    + specular_k·specular·a (white highlights). Where |g_w| < 1e-3 HU/mm (no surface), diffuse = 1
//    and specular = 0.
// 5. Front to back: C += (1 − A)·α′·shaded, A += (1 − A)·α′; stop once A > 0.99 (early termination).
//    Depth: the first t at which A ≥ 0.5 (the first surface); none when A stays below.
// 6. Output: C clamped to [0, 1] over a black background (premultiplied), A, depth in mm. With
//    vignetting_power n > 0, C is first multiplied by cosⁿ of the ray's angle to the view direction
//    (forward·dir): n = 4 is the cos⁴ law of a lens's relative illumination, the darkening towards
//    a laparoscope image's rim; the headlight's falloff (step 4) is the other half of that look.
// 7. Anti-aliasing (Renderer::render): with antialias_samples N > 1, the mean colour and opacity
//    of N passes whose pixel offsets are antialias_offset(0 … N−1) (the first (0, 0)) and whose
//    jitter seeds are jitter_seed + pass (jitter on): a box filter over the pixel and the step,
//    sampled by a low-discrepancy set. Depth is the first pass's.
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "render/render_volume.h"
#include "render/transfer_function.h"

namespace pneumo {

struct RenderSettings {
  TransferFunction tf;
  double step_mm = 0.5;
  bool jitter = false;
  uint32_t jitter_seed = 0;
  bool show_labels = true;
  double label_opacity = 0.5;
  LabelColours label_colours = default_label_colours();
  bool hide_exterior_air = false;
  double ambient = 0.15, diffuse = 0.85, specular = 0.25, shininess = 12.0;
  double light_falloff_mm = 100.0;
  double vignetting_power = 0.0;                        // step 6; 0: none
  double pixel_offset_x = 0.0, pixel_offset_y = 0.0;    // step 1, in pixels
  int antialias_samples = 1;                            // step 7
};

/// Pass k's pixel offset (step 7): the R2 sequence (Roberts 2018, the plastic number's
/// low-discrepancy 2-D set), centred on the pixel, pass 0 at its centre.
inline std::array<double, 2> antialias_offset(int k) {
  if (k == 0) return {0.0, 0.0};
  constexpr double g = 1.32471795724474602596;   // the plastic number
  const double x = std::fmod(0.5 + k / g, 1.0), y = std::fmod(0.5 + k / (g * g), 1.0);
  return {x - 0.5, y - 0.5};
}

inline constexpr double kOpacityUnitMm = 1.0;       // Δs_ref of the opacity correction
inline constexpr double kEarlyTermination = 0.99;   // stop compositing once A exceeds this
inline constexpr double kDepthOpacity = 0.5;        // "first surface": A reaches this
inline constexpr double kFlatGradient = 1e-3;       // HU/mm below which a sample has no normal
inline constexpr int kEntryBisections = 6;          // step 2b: the entry found to Δs/64

/// Per-pixel start offset in [0, 1) for jitter: an integer hash of (px, py, seed); the GLSL copy
/// in shaders/raycast.frag uses the same operations on 32-bit unsigned integers.
inline double jitter_offset(uint32_t px, uint32_t py, uint32_t seed) {
  uint32_t h = px * 73856093u ^ py * 19349663u ^ seed * 83492791u;
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  h *= 0x846ca68bu;
  h ^= h >> 16;
  return static_cast<double>(h >> 8) * (1.0 / 16777216.0);
}

/// A rendered view: colour (premultiplied over black) and opacity per pixel, top row first, and
/// the depth of the first surface in mm (infinity where there is none).
struct RenderImage {
  int width = 0, height = 0;
  std::vector<float> rgba;      // 4 per pixel
  std::vector<float> depth_mm;  // 1 per pixel
};

}  // namespace pneumo
