#pragma once
// Labels on report images (panel names, orientation letters, legend entries) with stb_easy_font:
// a tiny ASCII bitmap font, about 6 px per character and 7 px tall at scale 1.
#include <string>

#include "image/image.h"

namespace pneumo {

int text_width_px(const std::string& text, int scale = 1);
int text_height_px(int scale = 1);
/// Draws `text` with its top-left corner at (x, y); clipped to the image.
void draw_text(RgbImage& image, int x, int y, const std::string& text, Rgb colour, int scale = 1);

}  // namespace pneumo
