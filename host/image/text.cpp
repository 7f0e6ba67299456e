#include "image/text.h"

#include <algorithm>
#include <cmath>
#include <vector>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#include <stb/stb_easy_font.h>
#pragma GCC diagnostic pop

namespace pneumo {

namespace {
// stb_easy_font's vertex: x, y, z as floats, then an RGBA colour; four vertices per quad.
struct EasyFontVertex {
  float x, y, z;
  unsigned char rgba[4];
};
}  // namespace

int text_width_px(const std::string& text, int scale) {
  std::string copy = text;  // stb_easy_font takes a non-const char*
  return stb_easy_font_width(copy.data()) * scale;
}

int text_height_px(int scale) { return 7 * scale; }

void draw_text(RgbImage& image, int x, int y, const std::string& text, Rgb colour, int scale) {
  if (text.empty()) return;
  std::string copy = text;
  // stb's guide: about 270 bytes per character; room for twice that.
  std::vector<EasyFontVertex> vertices(text.size() * 40 + 16);
  const int quads = stb_easy_font_print(0.0f, 0.0f, copy.data(), nullptr, vertices.data(),
                                        int(vertices.size() * sizeof(EasyFontVertex)));
  for (int q = 0; q < quads; ++q) {
    const EasyFontVertex* v = &vertices[std::size_t(q) * 4];
    float x0 = v[0].x, x1 = v[0].x, y0 = v[0].y, y1 = v[0].y;
    for (int c = 1; c < 4; ++c) {
      x0 = std::min(x0, v[c].x);
      x1 = std::max(x1, v[c].x);
      y0 = std::min(y0, v[c].y);
      y1 = std::max(y1, v[c].y);
    }
    const int px = x + int(std::lround(x0)) * scale, py = y + int(std::lround(y0)) * scale;
    image.fill_rect(px, py, int(std::lround(x1 - x0)) * scale, int(std::lround(y1 - y0)) * scale, colour);
  }
}

}  // namespace pneumo
