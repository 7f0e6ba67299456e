// The legend strip of slice montages (declared in slices.h): swatches and names in one row.
#include <algorithm>

#include "report/slices.h"
#include "image/text.h"

namespace pneumo {

RgbImage render_legend(const std::vector<OverlayClass>& table) {
  constexpr int kPad = 4, kSwatch = 12, kSpacing = 14;
  constexpr Rgb kText{235, 235, 235}, kFrame{200, 200, 200};
  int width = kPad;
  for (const OverlayClass& c : table)
    if (c.alpha > 0 && !c.name.empty()) width += kSwatch + 4 + text_width_px(c.name) + kSpacing;
  RgbImage im(std::max(width, 1), kSwatch + 2 * kPad, kMontageBackground);
  int x = kPad;
  for (const OverlayClass& c : table) {
    if (!(c.alpha > 0) || c.name.empty()) continue;
    im.fill_rect(x - 1, kPad - 1, kSwatch + 2, kSwatch + 2, kFrame);
    im.fill_rect(x, kPad, kSwatch, kSwatch, c.colour);
    x += kSwatch + 4;
    draw_text(im, x, kPad + (kSwatch - text_height_px()) / 2, c.name, kText);
    x += text_width_px(c.name) + kSpacing;
  }
  return im;
}

}  // namespace pneumo
