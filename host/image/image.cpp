#include "image/image.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace pneumo {

RgbImage::RgbImage(int w, int h, Rgb fill) : width(w), height(h), rgb(std::size_t(w) * h * 3) {
  for (std::size_t n = 0; n < rgb.size(); n += 3) {
    rgb[n] = fill.r;
    rgb[n + 1] = fill.g;
    rgb[n + 2] = fill.b;
  }
}

void RgbImage::set(int x, int y, Rgb c) {
  if (x < 0 || y < 0 || x >= width || y >= height) return;
  uint8_t* p = pixel(x, y);
  p[0] = c.r;
  p[1] = c.g;
  p[2] = c.b;
}

void RgbImage::fill_rect(int x, int y, int w, int h, Rgb c) {
  const int x0 = std::max(x, 0), y0 = std::max(y, 0);
  const int x1 = std::min(x + w, width), y1 = std::min(y + h, height);
  for (int yy = y0; yy < y1; ++yy)
    for (int xx = x0; xx < x1; ++xx) set(xx, yy, c);
}

void RgbImage::blit(const RgbImage& src, int x, int y) {
  const int x0 = std::max(x, 0), x1 = std::min(x + src.width, width);
  if (x1 <= x0) return;
  for (int sy = 0; sy < src.height; ++sy) {
    const int dy = y + sy;
    if (dy < 0 || dy >= height) continue;
    std::memcpy(pixel(x0, dy), src.pixel(x0 - x, sy), std::size_t(x1 - x0) * 3);
  }
}

RgbImage hconcat(const std::vector<RgbImage>& images, int gap_px, Rgb background) {
  int w = 0, h = 0;
  for (const RgbImage& im : images) {
    w += im.width + (w > 0 ? gap_px : 0);
    h = std::max(h, im.height);
  }
  RgbImage out(w, h, background);
  int x = 0;
  for (const RgbImage& im : images) {
    out.blit(im, x, 0);
    x += im.width + gap_px;
  }
  return out;
}

RgbImage vconcat(const std::vector<RgbImage>& images, int gap_px, Rgb background) {
  int w = 0, h = 0;
  for (const RgbImage& im : images) {
    h += im.height + (h > 0 ? gap_px : 0);
    w = std::max(w, im.width);
  }
  RgbImage out(w, h, background);
  int y = 0;
  for (const RgbImage& im : images) {
    out.blit(im, 0, y);
    y += im.height + gap_px;
  }
  return out;
}

RgbImage box_downscale(const RgbImage& image, int factor) {
  if (factor < 1) throw std::invalid_argument("box_downscale: factor must be at least 1");
  RgbImage out((image.width + factor - 1) / factor, (image.height + factor - 1) / factor);
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x) {
      int sum[3] = {0, 0, 0}, n = 0;
      for (int v = y * factor; v < std::min(image.height, (y + 1) * factor); ++v)
        for (int u = x * factor; u < std::min(image.width, (x + 1) * factor); ++u, ++n)
          for (int c = 0; c < 3; ++c) sum[c] += image.pixel(u, v)[c];
      for (int c = 0; c < 3; ++c) out.pixel(x, y)[c] = uint8_t((sum[c] + n / 2) / n);
    }
  return out;
}

}  // namespace pneumo
