#pragma once
// A plain 8-bit RGB raster for reports (slice montages, legends, role pictures): row-major, top row
// first, three bytes per pixel. Just enough drawing for reports: rectangles, copies, concatenation.
#include <cstdint>
#include <vector>

namespace pneumo {

struct Rgb {
  uint8_t r = 0, g = 0, b = 0;
};

struct RgbImage {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;  // width * height * 3

  RgbImage() = default;
  RgbImage(int w, int h, Rgb fill = {});

  bool empty() const { return width == 0 || height == 0; }
  uint8_t* pixel(int x, int y) { return rgb.data() + 3 * (int64_t(y) * width + x); }
  const uint8_t* pixel(int x, int y) const { return rgb.data() + 3 * (int64_t(y) * width + x); }
  void set(int x, int y, Rgb c);                        // ignored outside the image
  void fill_rect(int x, int y, int w, int h, Rgb c);    // clipped to the image
  void blit(const RgbImage& src, int x, int y);         // clipped to the image
};

/// Images side by side, top-aligned, `gap_px` of `background` between them.
RgbImage hconcat(const std::vector<RgbImage>& images, int gap_px, Rgb background);
/// Images one under another, left-aligned.
RgbImage vconcat(const std::vector<RgbImage>& images, int gap_px, Rgb background);
/// `factor`× smaller by the mean of each factor×factor block (a box filter: no aliasing of the
/// render's fine detail); a partial block at the right or bottom edge is averaged over what it holds.
RgbImage box_downscale(const RgbImage& image, int factor);

}  // namespace pneumo
