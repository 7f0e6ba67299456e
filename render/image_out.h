#pragma once
// Rendered views to files: 8-bit RGB PNGs, 16-bit depth PNGs, and the image measures the tests
// and the run summary use.
#include <string>

#include "render/render_settings.h"

namespace pneumo {

/// Depth PNG units: each 16-bit step is this many mm (0.1 mm: a 6.5 m range at laparoscope
/// resolution); the value 0 means "no surface along this ray".
inline constexpr double kDepthPngMmPerUnit = 0.1;

/// The colour as 8-bit RGB (rounded), top row first.
std::vector<uint8_t> to_rgb8(const RenderImage& image);

void write_view_png(const std::string& path, const RenderImage& image);
/// Depth to the first surface in units of kDepthPngMmPerUnit (clamped to 65535), 0 where none.
void write_depth_png(const std::string& path, const RenderImage& image);

/// PSNR in dB of the 8-bit-quantised RGB of two images of one size (peak 255); +inf when equal.
double psnr_db(const RenderImage& a, const RenderImage& b);

/// Mean structural similarity (Wang, Bovik, Sheikh & Simoncelli 2004, IEEE TIP 13(4), eq. 13) of the
/// luma of the 8-bit-quantised RGB (ITU-R BT.601 weights), as their reference code computes it: an
/// 11×11 Gaussian window of σ = 1.5 px, K1 = 0.01, K2 = 0.03, L = 255, averaged over the windows that
/// lie wholly inside the image. 1 for equal images; NaN when the sizes differ or an image is smaller
/// than the window. Written here because no Debian C++ library ships it (OpenCV's lives in contrib);
/// tests/test_image_quality.cpp holds it to the closed form of constant images.
double ssim(const RenderImage& a, const RenderImage& b);

struct ImageStats {
  double mean_rgb = 0;          // mean over pixels and channels, 0..1
  double covered_fraction = 0;  // pixels with opacity > 0.5
  bool finite = true;           // no NaN or infinite colour
};
ImageStats image_stats(const RenderImage& image);

}  // namespace pneumo
