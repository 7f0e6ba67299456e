#include "image/image.h"

#include <algorithm>
#include <cstring>

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

}  // namespace pneumo
