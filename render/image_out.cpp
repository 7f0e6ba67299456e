#include "render/image_out.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "image/png.h"

namespace pneumo {

std::vector<uint8_t> to_rgb8(const RenderImage& im) {
  const std::size_t n = std::size_t(im.width) * im.height;
  std::vector<uint8_t> rgb(n * 3);
  for (std::size_t p = 0; p < n; ++p)
    for (int c = 0; c < 3; ++c) {
      const float v = im.rgba[4 * p + c];
      rgb[3 * p + c] = std::isfinite(v) ? uint8_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)) : 0;
    }
  return rgb;
}

void write_view_png(const std::string& path, const RenderImage& im) {
  write_png_rgb(path, im.width, im.height, to_rgb8(im));
}

void write_depth_png(const std::string& path, const RenderImage& im) {
  std::vector<uint16_t> g(im.depth_mm.size());
  for (std::size_t p = 0; p < g.size(); ++p) {
    const double d = im.depth_mm[p];
    g[p] = std::isfinite(d) ? uint16_t(std::clamp(std::lround(d / kDepthPngMmPerUnit), 1L, 65535L)) : 0;
  }
  write_png_gray16(path, im.width, im.height, g);
}

double psnr_db(const RenderImage& a, const RenderImage& b) {
  if (a.width != b.width || a.height != b.height) return -std::numeric_limits<double>::infinity();
  const auto x = to_rgb8(a), y = to_rgb8(b);
  double se = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double d = double(x[i]) - double(y[i]);
    se += d * d;
  }
  if (se == 0) return std::numeric_limits<double>::infinity();
  const double mse = se / double(x.size());
  return 10.0 * std::log10(255.0 * 255.0 / mse);
}

ImageStats image_stats(const RenderImage& im) {
  ImageStats s;
  const std::size_t n = std::size_t(im.width) * im.height;
  double sum = 0;
  std::size_t covered = 0;
  for (std::size_t p = 0; p < n; ++p) {
    for (int c = 0; c < 3; ++c) {
      const float v = im.rgba[4 * p + c];
      if (!std::isfinite(v)) s.finite = false;
      sum += v;
    }
    if (im.rgba[4 * p + 3] > 0.5f) ++covered;
  }
  s.mean_rgb = n ? sum / (3.0 * n) : 0;
  s.covered_fraction = n ? double(covered) / n : 0;
  return s;
}

}  // namespace pneumo
