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

namespace {

std::vector<double> luma(const RenderImage& im) {
  const auto rgb = to_rgb8(im);
  std::vector<double> y(rgb.size() / 3);
  for (std::size_t p = 0; p < y.size(); ++p)
    y[p] = 0.299 * rgb[3 * p] + 0.587 * rgb[3 * p + 1] + 0.114 * rgb[3 * p + 2];
  return y;
}

}  // namespace

double ssim(const RenderImage& a, const RenderImage& b) {
  constexpr int kRadius = 5;          // 11×11 window
  constexpr double kSigma = 1.5, kC1 = (0.01 * 255) * (0.01 * 255), kC2 = (0.03 * 255) * (0.03 * 255);
  const int w = a.width, h = a.height;
  if (w != b.width || h != b.height || w <= 2 * kRadius || h <= 2 * kRadius) return std::nan("");
  const std::vector<double> x = luma(a), y = luma(b);
  double g[2 * kRadius + 1], gsum = 0;
  for (int i = -kRadius; i <= kRadius; ++i) gsum += g[i + kRadius] = std::exp(-0.5 * i * i / (kSigma * kSigma));
  for (double& v : g) v /= gsum;
  // The window is separable: filter rows into five moment images, then columns at each valid centre.
  const int vw = w - 2 * kRadius;
  std::vector<double> rows(std::size_t(5) * vw * h);
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < vw; ++c) {
      double m[5] = {0, 0, 0, 0, 0};
      for (int i = 0; i <= 2 * kRadius; ++i) {
        const std::size_t p = std::size_t(r) * w + c + i;
        m[0] += g[i] * x[p];
        m[1] += g[i] * y[p];
        m[2] += g[i] * x[p] * x[p];
        m[3] += g[i] * y[p] * y[p];
        m[4] += g[i] * x[p] * y[p];
      }
      for (int k = 0; k < 5; ++k) rows[(std::size_t(k) * h + r) * vw + c] = m[k];
    }
  double sum = 0;
  for (int r = kRadius; r < h - kRadius; ++r)
    for (int c = 0; c < vw; ++c) {
      double m[5] = {0, 0, 0, 0, 0};
      for (int k = 0; k < 5; ++k)
        for (int i = 0; i <= 2 * kRadius; ++i) m[k] += g[i] * rows[(std::size_t(k) * h + r - kRadius + i) * vw + c];
      const double mx = m[0], my = m[1];
      const double vx = m[2] - mx * mx, vy = m[3] - my * my, cxy = m[4] - mx * my;
      sum += (2 * mx * my + kC1) * (2 * cxy + kC2) / ((mx * mx + my * my + kC1) * (vx + vy + kC2));
    }
  return sum / (double(vw) * (h - 2 * kRadius));
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
