#include "report/slices.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>

#include "image/text.h"

namespace pneumo {

namespace {

constexpr Rgb kOutsideGrid{16, 20, 36};   // beyond the volume: dark blue, unlike air (black)
constexpr Rgb kLetter{255, 220, 70};
constexpr Rgb kCaption{235, 235, 235};
constexpr Rgb kTick{255, 220, 70};
constexpr int kGapPx = 4;
constexpr int kTickPx = 6;

/// One plane of the row: pixel (c, r) has its centre at start + (c + ½)·u + (r + ½)·v (world mm).
struct Plane {
  const char* name;
  Vec3 start, u, v;
  int width, height;
  std::array<const char*, 4> letters;  // left, right, top, bottom
  std::string caption;
  int tick_col, tick_row;              // where the other planes cut (-1 = outside)
};

std::string caption(const char* name, char axis, double mm) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%s %c=%+.1f mm", name, axis, mm);
  return buf;
}

/// Planes through `p` covering `box`: image columns and rows run along world axes, from the
/// box's max side so that R, A and S land on the left/top as the radiological convention wants.
std::array<Plane, 3> make_planes(const WorldBox& box, const Vec3& p, double px) {
  const Vec3 ext = box.max_mm - box.min_mm;
  const auto n = [&](int axis) { return std::max(1, int(std::ceil(ext[axis] / px - 1e-9))); };
  const auto at = [&](int axis, double value) {  // pixel index of a world coordinate, from the max side
    const double f = (box.max_mm[axis] - value) / px;
    return (f < 0 || f >= n(axis)) ? -1 : int(f);
  };
  const Vec3 ex(1, 0, 0), ey(0, 1, 0), ez(0, 0, 1);
  Plane axial{"axial", Vec3(box.max_mm.x(), box.max_mm.y(), p.z()), -px * ex, -px * ey, n(0), n(1),
              {"R", "L", "A", "P"}, caption("axial", 'z', p.z()), at(0, p.x()), at(1, p.y())};
  Plane coronal{"coronal", Vec3(box.max_mm.x(), p.y(), box.max_mm.z()), -px * ex, -px * ez, n(0), n(2),
                {"R", "L", "S", "I"}, caption("coronal", 'y', p.y()), at(0, p.x()), at(2, p.z())};
  Plane sagittal{"sagittal", Vec3(p.x(), box.max_mm.y(), box.max_mm.z()), -px * ey, -px * ez, n(1), n(2),
                 {"A", "P", "S", "I"}, caption("sagittal", 'x', p.x()), at(1, p.y()), at(2, p.z())};
  return {axial, coronal, sagittal};
}

/// World → continuous voxel index of a grid, as one affine map so a plane walks it linearly.
struct IndexMap {
  Mat3 a;
  Vec3 b;
  explicit IndexMap(const Geometry& g) {
    a = (g.direction * g.spacing_mm.asDiagonal()).inverse();
    b = -a * g.origin_mm;
  }
  Vec3 operator()(const Vec3& w) const { return a * w + b; }
};

bool inside_grid(const Geometry& g, const Vec3& idx) {
  for (int d = 0; d < 3; ++d)
    if (!(idx[d] >= -0.5 && idx[d] <= double(g.dims[d]) - 0.5)) return false;
  return true;
}

template <class T>
double sample_nearest(const T* v, const Geometry& g, const Vec3& idx) {
  int64_t q[3];
  for (int d = 0; d < 3; ++d) q[d] = std::clamp<int64_t>(int64_t(std::floor(idx[d] + 0.5)), 0, g.dims[d] - 1);
  return double(v[g.linear_index(q[0], q[1], q[2])]);
}

template <class T>
double sample_trilinear(const T* v, const Geometry& g, const Vec3& idx) {
  int64_t lo[3], hi[3];
  double f[3];
  for (int d = 0; d < 3; ++d) {
    const double x = std::clamp(idx[d], 0.0, double(g.dims[d] - 1));
    lo[d] = int64_t(std::floor(x));
    hi[d] = std::min(lo[d] + 1, g.dims[d] - 1);
    f[d] = x - double(lo[d]);
  }
  double sum = 0.0;
  for (int c = 0; c < 8; ++c) {
    const int64_t i = (c & 1) ? hi[0] : lo[0], j = (c & 2) ? hi[1] : lo[1], k = (c & 4) ? hi[2] : lo[2];
    const double w = ((c & 1) ? f[0] : 1 - f[0]) * ((c & 2) ? f[1] : 1 - f[1]) * ((c & 4) ? f[2] : 1 - f[2]);
    if (w != 0.0) sum += w * double(v[g.linear_index(i, j, k)]);
  }
  return sum;
}

uint8_t grey_level(double hu, const SliceWindow& w) {
  const double t = (hu - w.low_hu) / std::max(w.high_hu - w.low_hu, 1e-9);
  return uint8_t(std::lround(255.0 * std::clamp(t, 0.0, 1.0)));
}

Rgb blend(uint8_t grey, const OverlayClass& c) {
  const auto mix = [&](uint8_t col) { return uint8_t(std::lround((1 - c.alpha) * grey + c.alpha * col)); };
  return {mix(c.colour.r), mix(c.colour.g), mix(c.colour.b)};
}

template <class T>
RgbImage render_plane(const T* ct, const Geometry& g, const SliceOverlay* overlay, const Plane& plane,
                      const SliceView& view) {
  RgbImage im(plane.width, plane.height, kOutsideGrid);
  const IndexMap ct_map(g);
  const IndexMap ov_map(overlay ? overlay->geometry : g);
#pragma omp parallel for schedule(static)
  for (int r = 0; r < plane.height; ++r) {
    for (int c = 0; c < plane.width; ++c) {
      const Vec3 w = plane.start + (c + 0.5) * plane.u + (r + 0.5) * plane.v;
      const Vec3 idx = ct_map(w);
      if (!inside_grid(g, idx)) continue;
      const double hu = view.trilinear ? sample_trilinear(ct, g, idx) : sample_nearest(ct, g, idx);
      const uint8_t grey = grey_level(hu, view.window);
      Rgb px{grey, grey, grey};
      if (overlay && overlay->classes) {
        const Vec3 oi = ov_map(w);
        if (inside_grid(overlay->geometry, oi)) {
          const auto cls = std::size_t(sample_nearest(overlay->classes, overlay->geometry, oi));
          if (cls < overlay->table.size() && overlay->table[cls].alpha > 0) px = blend(grey, overlay->table[cls]);
        }
      }
      im.set(c, r, px);
    }
  }
  return im;
}

/// Orientation letters at the middle of each edge, the caption at the top left, and ticks on the
/// borders where the other two planes cut this one.
void annotate(RgbImage& im, const Plane& p) {
  // Letters at twice the caption size: they are what a reader checks first.
  constexpr int kLetterScale = 2;
  const int th = text_height_px(kLetterScale), mid_x = im.width / 2, mid_y = im.height / 2;
  const auto width = [&](const char* t) { return text_width_px(t, kLetterScale); };
  draw_text(im, 3, mid_y - th / 2, p.letters[0], kLetter, kLetterScale);
  draw_text(im, im.width - width(p.letters[1]) - 2, mid_y - th / 2, p.letters[1], kLetter, kLetterScale);
  draw_text(im, mid_x - width(p.letters[2]) / 2, 3, p.letters[2], kLetter, kLetterScale);
  draw_text(im, mid_x - width(p.letters[3]) / 2, im.height - th - 3, p.letters[3], kLetter, kLetterScale);
  draw_text(im, 3, 3, p.caption, kCaption);
  if (p.tick_col >= 0) {
    im.fill_rect(p.tick_col, 0, 1, kTickPx, kTick);
    im.fill_rect(p.tick_col, im.height - kTickPx, 1, kTickPx, kTick);
  }
  if (p.tick_row >= 0) {
    im.fill_rect(0, p.tick_row, kTickPx, 1, kTick);
    im.fill_rect(im.width - kTickPx, p.tick_row, kTickPx, 1, kTick);
  }
}

}  // namespace

WorldBox world_box(const Geometry& g) {
  WorldBox b;
  b.min_mm = Vec3::Constant(std::numeric_limits<double>::infinity());
  b.max_mm = -b.min_mm;
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner((c & 1) ? g.dims[0] - 0.5 : -0.5, (c & 2) ? g.dims[1] - 0.5 : -0.5,
                      (c & 4) ? g.dims[2] - 0.5 : -0.5);
    const Vec3 w = g.to_world(corner);
    b.min_mm = b.min_mm.cwiseMin(w);
    b.max_mm = b.max_mm.cwiseMax(w);
  }
  return b;
}

double resolved_pixel_mm(const Volume& ct, const SliceView& view) {
  if (view.pixel_mm > 0) return view.pixel_mm;
  const WorldBox box = view.box ? *view.box : world_box(ct.geometry());
  const double extent = (box.max_mm - box.min_mm).maxCoeff();
  double px = ct.geometry().spacing_mm.minCoeff();
  px = std::min(px, extent / std::max(view.min_panel_px, 1));
  px = std::max(px, extent / std::max(view.max_panel_px, 1));
  return px;
}

std::array<RgbImage, 3> render_slice_panels(const Volume& ct, const SliceOverlay* overlay, const SliceView& view) {
  const WorldBox box = view.box ? *view.box : world_box(ct.geometry());
  const Vec3 point = view.point_mm ? *view.point_mm : box.centre();
  const double px = resolved_pixel_mm(ct, view);
  const std::array<Plane, 3> planes = make_planes(box, point, px);
  std::array<RgbImage, 3> panels;
  for (int p = 0; p < 3; ++p) {
    panels[p] = dispatch_voxel_type(ct.type(), const_cast<void*>(ct.raw()), [&](auto* data) {
      return render_plane(data, ct.geometry(), overlay, planes[p], view);
    });
    if (view.annotate) annotate(panels[p], planes[p]);
  }
  return panels;
}

RgbImage render_slice_row(const Volume& ct, const SliceOverlay* overlay, const SliceView& view) {
  const std::array<RgbImage, 3> panels = render_slice_panels(ct, overlay, view);
  RgbImage row = hconcat({panels[0], panels[1], panels[2]}, kGapPx, kMontageBackground);
  if (view.title.empty()) return row;
  RgbImage title(row.width, text_height_px() + 6, kMontageBackground);
  draw_text(title, 3, 3, view.title, kCaption);
  return vconcat({title, row}, 0, kMontageBackground);
}

RgbImage stack_rows(const std::vector<RgbImage>& rows) { return vconcat(rows, kGapPx, kMontageBackground); }

}  // namespace pneumo
