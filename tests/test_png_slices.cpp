// Slice montages (host/report/slices.h): world-space, radiologically oriented panels whatever the
// grid's storage order; square pixels on anisotropic grids; overlays and legends.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "io_test_support.h"
#include "image/png.h"
#include "report/slices.h"

using namespace pneumo;

namespace {

constexpr double kBright = 1000.0;

/// A 10^3 grid at 2 mm whose voxels hold f(world point).
Volume volume_of(const Mat3& direction, const Vec3& origin, const std::function<double(const Vec3&)>& f) {
  Geometry g;
  g.dims = {10, 10, 10};
  g.spacing_mm = Vec3(2, 2, 2);
  g.direction = direction;
  g.origin_mm = origin;
  Volume v(g, VoxelType::Int16);
  int16_t* p = v.data<int16_t>();
  for (int64_t k = 0; k < 10; ++k)
    for (int64_t j = 0; j < 10; ++j)
      for (int64_t i = 0; i < 10; ++i) p[g.linear_index(i, j, k)] = int16_t(f(g.to_world(Vec3(i, j, k))));
  return v;
}

/// Bright in the patient's right-anterior-superior octant of the box [-1, 19] mm³.
double ras_octant(const Vec3& w) { return (w.x() > 9 && w.y() > 9 && w.z() > 9) ? kBright : 0.0; }

SliceView plain_view() {
  SliceView v;
  v.window = {0.0, kBright};
  v.point_mm = Vec3(12, 12, 12);
  v.pixel_mm = 2.0;
  v.trilinear = false;
  v.annotate = false;
  return v;
}

bool is_white(const RgbImage& im, int x, int y) { return im.pixel(x, y)[0] == 255; }

}  // namespace

TEST(Slices, PanelsAreRadiologicallyOriented) {
  const Volume ras = volume_of(Mat3::Identity(), Vec3::Zero(), ras_octant);
  const auto panels = render_slice_panels(ras, nullptr, plain_view());
  // Axial: anterior up, right on the left. Coronal: superior up, right on the left. Sagittal:
  // superior up, anterior on the left. The R/A/S octant is the top-left quadrant of each.
  for (int p = 0; p < 3; ++p) {
    const RgbImage& im = panels[p];
    ASSERT_EQ(im.width, 10);
    ASSERT_EQ(im.height, 10);
    for (int y = 0; y < 10; ++y)
      for (int x = 0; x < 10; ++x) EXPECT_EQ(is_white(im, x, y), x < 5 && y < 5) << "panel " << p << " at " << x << "," << y;
  }
}

TEST(Slices, StorageOrderDoesNotChangeThePicture) {
  const auto reference = render_slice_panels(volume_of(Mat3::Identity(), Vec3::Zero(), ras_octant), nullptr, plain_view());
  // LPS storage (i towards the left, j towards the back), as MetaImage/DICOM grids often are.
  Mat3 lps = Mat3::Identity();
  lps(0, 0) = lps(1, 1) = -1;
  // Sagittal-acquired storage: i towards superior, j towards left, k towards anterior.
  Mat3 permuted;
  permuted << 0, -1, 0,  //
      0, 0, 1,           //
      1, 0, 0;
  for (const auto& [dir, origin] : {std::pair{lps, Vec3(18, 18, 0)}, std::pair{permuted, Vec3(18, 0, 0)}}) {
    const Volume v = volume_of(dir, origin, ras_octant);
    const WorldBox box = world_box(v.geometry());
    ASSERT_TRUE(box.min_mm.isApprox(Vec3(-1, -1, -1))) << box.min_mm.transpose();
    const auto panels = render_slice_panels(v, nullptr, plain_view());
    for (int p = 0; p < 3; ++p) EXPECT_EQ(panels[p].rgb, reference[p].rgb) << "panel " << p << " of " << v.geometry().orientation_code();
  }
}

TEST(Slices, PixelsAreSquareOnAnisotropicGrids) {
  // A sphere of radius 15 mm on 1 x 1 x 4 mm voxels shows as a disc in the coronal panel.
  Geometry g;
  g.dims = {40, 40, 12};
  g.spacing_mm = Vec3(1, 1, 4);
  Volume v(g, VoxelType::Float32);
  const Vec3 c = g.to_world(Vec3(19.5, 19.5, 5.5));
  for (int64_t k = 0; k < 12; ++k)
    for (int64_t j = 0; j < 40; ++j)
      for (int64_t i = 0; i < 40; ++i)
        v.data<float>()[g.linear_index(i, j, k)] = (g.to_world(Vec3(i, j, k)) - c).norm() <= 15 ? 1000.f : 0.f;
  SliceView view;
  view.window = {0, 1000};
  view.point_mm = c;
  view.pixel_mm = 1.0;
  view.annotate = false;
  const RgbImage coronal = render_slice_panels(v, nullptr, view)[1];
  EXPECT_EQ(coronal.width, 40);
  EXPECT_EQ(coronal.height, 48);   // 12 slices of 4 mm
  int x0 = 1 << 20, x1 = -1, y0 = 1 << 20, y1 = -1;
  for (int y = 0; y < coronal.height; ++y)
    for (int x = 0; x < coronal.width; ++x)
      if (coronal.pixel(x, y)[0] > 127) {
        x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
      }
  const int w = x1 - x0 + 1, h = y1 - y0 + 1;
  EXPECT_NEAR(w, 30, 2);
  EXPECT_NEAR(h, 30, 4);   // trilinear between 4 mm slices: within a slice
}

TEST(Slices, OverlayColoursItsClassesOnlyAndTheLegendShowsThem) {
  const Volume ct = volume_of(Mat3::Identity(), Vec3::Zero(), [](const Vec3&) { return 500.0; });
  std::vector<uint8_t> cls(ct.voxel_count(), 0);
  for (int64_t i = 0; i < 5; ++i) cls[ct.geometry().linear_index(i, 6, 6)] = 1;   // a row of class 1
  SliceOverlay overlay;
  overlay.geometry = ct.geometry();
  overlay.classes = cls.data();
  overlay.table = {{"none", {0, 0, 0}, 0.0}, {"marked", {255, 0, 0}, 1.0}};
  const RgbImage axial = render_slice_panels(ct, &overlay, plain_view())[0];
  // Row j = 6 is y = 12 mm: image row 3; voxels i 0..4 are columns 5..9.
  for (int x = 0; x < 10; ++x) {
    const uint8_t* p = axial.pixel(x, 3);
    if (x >= 5) EXPECT_TRUE(p[0] == 255 && p[1] == 0 && p[2] == 0) << x;
    else EXPECT_TRUE(p[0] == 128 && p[1] == 128 && p[2] == 128) << x;  // 500 HU in 0..1000: mid grey
  }
  const RgbImage legend = render_legend(overlay.table);
  EXPECT_GT(legend.width, 20);
  bool has_red = false;
  for (int y = 0; y < legend.height; ++y)
    for (int x = 0; x < legend.width; ++x) has_red |= legend.pixel(x, y)[0] == 255 && legend.pixel(x, y)[1] == 0;
  EXPECT_TRUE(has_red);
}

TEST(Slices, OutsideTheGridIsNotAir) {
  const Volume ct = volume_of(Mat3::Identity(), Vec3::Zero(), [](const Vec3&) { return -1000.0; });
  SliceView view = plain_view();
  view.box = WorldBox{Vec3(-11, -11, -11), Vec3(29, 29, 29)};   // 10 mm beyond the grid all round
  const RgbImage axial = render_slice_panels(ct, nullptr, view)[0];
  ASSERT_EQ(axial.width, 20);
  const uint8_t* outside = axial.pixel(0, 0);
  const uint8_t* air = axial.pixel(10, 10);
  EXPECT_EQ(air[0] + air[1] + air[2], 0);
  EXPECT_GT(outside[0] + outside[1] + outside[2], 0);
}

TEST(Slices, RowsStackForBeforeAndAfter) {
  const Volume ct = volume_of(Mat3::Identity(), Vec3::Zero(), ras_octant);
  SliceView view = plain_view();
  view.annotate = true;
  view.title = "before";
  const RgbImage before = render_slice_row(ct, nullptr, view);
  view.title = "after";
  const RgbImage after = render_slice_row(ct, nullptr, view);
  EXPECT_EQ(before.width, after.width);
  EXPECT_GE(before.width, 3 * 10);
  const RgbImage both = stack_rows({before, after});
  EXPECT_EQ(both.width, before.width);
  EXPECT_GT(both.height, before.height + after.height);
  testing_support::ScratchDir dir;
  write_png(dir.file("both.png"), both);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"both.png"});
}
