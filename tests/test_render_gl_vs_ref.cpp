// The GL ray caster (shaders/raycast.frag on whatever OpenGL the machine offers; Mesa's llvmpipe
// here) against the CPU reference (render/ray_cast_ref.cpp) on the analytic cavity phantom
// (render_test_support.h): a gas sphere in soft tissue with a labelled organ bulging into it.
//
// Compared: the 8-bit RGB images by PSNR, threshold 35 dB (images that look the same). Why not bit-exact: the GL
// side samples in float32 with the driver's own trilinear filtering and a 1-HU transfer-function
// table, the reference in double with the piecewise-linear function itself; these move a few
// samples across steep transfer-function ramps. A wrong ray, step, opacity correction, shading
// term or skipped block costs far more (a one-pixel shift of this image is ~25 dB).
// Every case also checks that neither image is blank (most pixels covered, mean colour not black)
// nor non-finite, and that the depth maps agree to within one step where both see a surface.
// A test skips only when no OpenGL context can be created at all.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "render/image_out.h"
#include "render/ray_cast_gl.h"
#include "render/ray_cast_ref.h"
#include "render/view_settings.h"
#include "render_test_support.h"
#include "scene/scene.h"

namespace pneumo {
namespace {

using testing_support::CavityPhantom;
using testing_support::make_cavity_phantom;
constexpr double kPi = 3.14159265358979323846;
constexpr int kSize = 96;  // small: the reference is brute force

struct Case {
  const char* name;
  Vec3 tip, look_at;
  Optics optics;
  RenderPreset preset = RenderPreset::Laparoscopic;
  bool force_float = false, jitter = false, rotated_grid = false, exterior = false;
  double min_covered = 0.9;
  double vignetting_power = 0, offset_x = 0, offset_y = 0, smoothing_mm = 0;
};

Optics lens(Lens l, double fov, double oblique = 0, double roll = 0) {
  Optics o;
  o.lens = l;
  o.fov_deg = fov;
  o.oblique_deg = oblique;
  o.roll_deg = roll;
  return o;
}

std::vector<Case> cases() {
  const Vec3 inside(0, 20, 0), organ(0, -35, 0);
  std::vector<Case> c;
  c.push_back({"inside_pinhole_70", inside, organ, lens(Lens::Pinhole, 70)});
  c.push_back({"fisheye_170", inside, organ, lens(Lens::Fisheye, 170), RenderPreset::Laparoscopic, false, false,
               false, false, 0.7});  // the image circle covers π/4 of the square
  c.push_back({"oblique_30", inside, organ, lens(Lens::Pinhole, 70, 30)});
  c.push_back({"oblique_45_roll_90", inside, organ, lens(Lens::Pinhole, 70, 45, 90)});
  c.push_back({"float_texture", inside, organ, lens(Lens::Pinhole, 70), RenderPreset::Laparoscopic, true});
  c.push_back({"jitter", inside, organ, lens(Lens::Pinhole, 70), RenderPreset::Laparoscopic, false, true});
  c.push_back({"rotated_grid", inside, organ, lens(Lens::Pinhole, 70), RenderPreset::Laparoscopic, false, false,
               true});
  c.push_back({"ct_muscle_90", inside, organ, lens(Lens::Pinhole, 90), RenderPreset::CtMuscle});
  Case vignetted{"vignetting_offset", inside, organ, lens(Lens::Pinhole, 70)};
  vignetted.vignetting_power = 4;
  vignetted.offset_x = 0.3;
  vignetted.offset_y = -0.2;
  c.push_back(vignetted);
  Case smoothed{"smoothed_3mm", inside, organ, lens(Lens::Pinhole, 70)};
  smoothed.smoothing_mm = 3.0;   // σ = 2 voxels of 1.5 mm
  c.push_back(smoothed);
  c.push_back({"exterior_ct_air", Vec3(0, 150, 40), Vec3(0, 0, 0), lens(Lens::Pinhole, 40), RenderPreset::CtAir,
               false, false, false, true, 0.2});
  return c;
}

class RenderGlVsRef : public ::testing::TestWithParam<Case> {};

TEST_P(RenderGlVsRef, ImagesAgreeByPsnrAndAreNotBlank) {
  PNEUMO_REQUIRE_GL(ctx);
  const Case& k = GetParam();
  CavityPhantom p;
  Mat3 dir = Mat3::Identity();
  if (k.rotated_grid) {  // an oblique, anisotropic grid: the direction matrix and spacings matter
    dir = Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized()).toRotationMatrix();
    p.k_spacing_mm = 2.0;
  }
  RenderVolume v = make_cavity_phantom(p, dir);
  v.smoothing_mm = k.smoothing_mm;
  RenderSettings s;
  s.vignetting_power = k.vignetting_power;
  s.pixel_offset_x = k.offset_x;
  s.pixel_offset_y = k.offset_y;
  s.tf = preset_transfer_function(k.preset);
  s.step_mm = 0.5 * v.geometry.spacing_mm.minCoeff();
  s.jitter = k.jitter;
  s.jitter_seed = 7;
  if (k.exterior) {
    // Make the world outside a ball of tissue air, as around a body: the cavity stays enclosed.
    for (int64_t n = 0; n < v.geometry.voxel_count(); ++n) {
      const Vec3 w = v.geometry.to_world(Vec3(double(n % 64), double((n / 64) % 64), double(n / 4096)));  // 64³
      if (w.norm() > 44.0) v.hu[n] = -1000.0f;
    }
    v.mark_exterior_air();
    s.hide_exterior_air = true;
    s.show_labels = false;
    s.light_falloff_mm = 150;
  }
  GlRayCaster gl(*ctx);
  gl.set_volume(v, k.force_float);
  EXPECT_EQ(gl.hu_format(), k.force_float ? "r32f" : "rgba16_snorm");
  Optics o = k.optics;
  const ViewCamera cam = make_view_camera(look_at_pose(k.tip, k.look_at, o.up), o, kSize, kSize);
  const RenderImage g = gl.render(cam, s);
  const RenderImage r = render_reference(v, cam, s);
  const std::string dir_out = ::testing::TempDir();
  write_view_png(dir_out + "/render_" + std::string(k.name) + "_gl.png", g);
  write_view_png(dir_out + "/render_" + std::string(k.name) + "_cpu.png", r);

  const double psnr = psnr_db(g, r);
  EXPECT_GE(psnr, 35.0) << k.name;
  for (const RenderImage* im : {&g, &r}) {
    const ImageStats st = image_stats(*im);
    EXPECT_TRUE(st.finite);
    EXPECT_GE(st.covered_fraction, k.min_covered) << k.name;
    if (k.min_covered > 0) {
      EXPECT_GT(st.mean_rgb, 0.03) << k.name << ": image nearly black";
    }
  }
  // Depth maps: where both see a surface, they agree within one step (the float32 sample
  // positions can put the A ≥ 0.5 crossing one sample apart) except at a few silhouette pixels.
  int both = 0, off = 0;
  for (std::size_t n = 0; n < g.depth_mm.size(); ++n) {
    if (!std::isfinite(g.depth_mm[n]) || !std::isfinite(r.depth_mm[n])) continue;
    ++both;
    if (std::abs(g.depth_mm[n] - r.depth_mm[n]) > s.step_mm * 1.01) ++off;
  }
  EXPECT_LE(off, std::max(2, both / 100)) << k.name << ": depth differs beyond one step at " << off << " of " << both;
  std::printf("[ case ] %-20s PSNR %.1f dB, covered %.2f\n", k.name, psnr, image_stats(g).covered_fraction);
}

INSTANTIATE_TEST_SUITE_P(Cases, RenderGlVsRef, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<Case>& i) { return std::string(i.param.name); });

// A CT finer than the smoothing is viewed on a coarser grid (render_volume.h view_grid_stride): at
// 0.75 mm and the default 1.5 mm, every second voxel. The Gaussian keeps at most exp(−π²/2) = 0.7 %
// at that grid's Nyquist frequency, and trilinear interpolation between its samples moves a
// smoothed edge by under σ/10 = 0.15 mm, a fiftieth of a pixel here. So the views agree with those
// sampled on the CT's own grid to the threshold that separates a right image from a wrong one
// above (35 dB; a one-pixel shift is ~25 dB), and by SSIM ≥ 0.97, the agreement measured on the
// large phantom's views (bench/results/2026-12-06-views-grid.md: 0.973–0.995).
TEST(RenderViewsGrid, AFineCtViewedOnTheCoarserGridAgreesWithItsOwnGrid) {
  PNEUMO_REQUIRE_GL(ctx);
  CavityPhantom p;
  p.spacing_mm = 0.75;
  p.n = 128;   // the same 96 mm box as the 1.5 mm phantom
  RenderVolume fine = make_cavity_phantom(p);
  fine.smoothing_mm = kDefaultSmoothingMm;
  RenderVolume own = fine;
  own.views_on_ct_grid = true;
  ASSERT_EQ(view_grid_stride(fine.geometry, fine.smoothing_mm), (Index3{2, 2, 2}));
  RenderSettings s;
  s.tf = preset_transfer_function(RenderPreset::Laparoscopic);
  s.step_mm = 0.5 * p.spacing_mm;
  for (const auto& [tip, look] : {std::pair{Vec3(0, 20, 0), Vec3(0, -35, 0)}, std::pair{Vec3(10, 0, 15), Vec3(-30, -5, -10)}}) {
    const ViewCamera cam = make_view_camera(look_at_pose(tip, look, Vec3(0, 0, 1)), Optics{}, kSize, kSize);
    GlRayCaster gl(*ctx);
    gl.set_volume(fine);
    const RenderImage coarse_grid = gl.render(cam, s);
    gl.set_volume(own);
    const RenderImage ct_grid = gl.render(cam, s);
    const double psnr = psnr_db(coarse_grid, ct_grid), similarity = ssim(coarse_grid, ct_grid);
    EXPECT_GE(psnr, 35.0);
    EXPECT_GE(similarity, 0.97);
    EXPECT_GT(image_stats(coarse_grid).mean_rgb, 0.03);
    std::printf("[ views grid ] PSNR %.1f dB, SSIM %.4f\n", psnr, similarity);
  }
}

// Pixels where the labelled organ shows: where the image with label colours differs from the one
// without. Returns their count and mean pixel position.
struct OrganPixels { int count = 0; double x = 0, y = 0; bool centre = false; };
OrganPixels organ_pixels(const RenderImage& with, const RenderImage& without) {
  OrganPixels o;
  const auto a = to_rgb8(with), b = to_rgb8(without);
  for (int y = 0; y < with.height; ++y)
    for (int x = 0; x < with.width; ++x) {
      const std::size_t n = std::size_t(y) * with.width + x;
      int diff = 0;
      for (int c = 0; c < 3; ++c) diff += std::abs(int(a[3 * n + c]) - int(b[3 * n + c]));
      if (diff <= 3) continue;
      ++o.count;
      o.x += x;
      o.y += y;
      if (x == with.width / 2 && y == with.height / 2) o.centre = true;
    }
  if (o.count) {
    o.x /= o.count;
    o.y /= o.count;
  }
  return o;
}

// Labels colour what they should: seen from the cavity's centre, the organ (radius 14 mm, centre
// 35 mm away on the axis) subtends asin(14/35) = 23.6° around the image centre, i.e. a disc of
// tan(23.6°)/tan(35°) = 0.62 of the half width with a 70° pinhole. Label colours are interpolated
// trilinearly (model step 3), so they reach one voxel (1.5 mm) past the labelled voxel centres:
// every label-coloured pixel must lie in the disc of the organ grown by that voxel (+0.5 px), the
// disc's centre must be coloured, and the colour must move towards the liver's dark red (green drops).
TEST(RenderGlLabels, OrganLabelColoursExactlyTheOrgansPixels) {
  PNEUMO_REQUIRE_GL(ctx);
  const CavityPhantom p;
  const RenderVolume v = make_cavity_phantom(p);
  GlRayCaster gl(*ctx);
  gl.set_volume(v);
  RenderSettings s;
  s.tf = preset_transfer_function(RenderPreset::Laparoscopic);
  s.step_mm = 0.75;
  s.label_opacity = 0.6;
  const ViewCamera cam = make_view_camera(look_at_pose(Vec3(0, 0, 0), p.organ_centre_mm, Vec3(0, 0, 1)), Optics{},
                                          kSize, kSize);
  const RenderImage with = gl.render(cam, s);
  s.show_labels = false;
  const RenderImage without = gl.render(cam, s);
  const OrganPixels o = organ_pixels(with, without);
  EXPECT_TRUE(o.centre);
  const double disc_px = std::tan(std::asin(14.0 / 35.0)) / std::tan(35.0 * kPi / 180.0) * kSize / 2;
  const double reach_px = std::tan(std::asin((14.0 + p.spacing_mm) / 35.0)) / std::tan(35.0 * kPi / 180.0) * kSize / 2;
  const auto a = to_rgb8(with), b = to_rgb8(without);
  int outside = 0, greener = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const std::size_t n = std::size_t(y) * kSize + x;
      const int diff = std::abs(a[3 * n] - b[3 * n]) + std::abs(a[3 * n + 1] - b[3 * n + 1]) +
                       std::abs(a[3 * n + 2] - b[3 * n + 2]);
      if (diff <= 3) continue;
      if (std::hypot(x + 0.5 - kSize / 2.0, y + 0.5 - kSize / 2.0) > reach_px + 0.5) ++outside;
      if (a[3 * n + 1] > b[3 * n + 1]) ++greener;
    }
  EXPECT_EQ(outside, 0);
  EXPECT_EQ(greener, 0);
  EXPECT_GT(o.count, int(0.8 * kPi * disc_px * disc_px));  // and it fills the disc
}

// The oblique scope turns the view as it should: with the shaft 30° below the organ's direction,
// a 0° scope sees the organ in the upper half of the image and not at its centre; the 30° scope
// (tilted towards image up) has it centred. Organ pixels found as above; centroid within 2 px.
TEST(RenderGlOblique, ThirtyDegreeScopeCentresWhatLiesThirtyDegreesAboveTheShaft) {
  PNEUMO_REQUIRE_GL(ctx);
  const CavityPhantom p;
  const RenderVolume v = make_cavity_phantom(p);
  GlRayCaster gl(*ctx);
  gl.set_volume(v);
  RenderSettings s;
  s.tf = preset_transfer_function(RenderPreset::Laparoscopic);
  s.step_mm = 0.75;
  // Shaft direction (0, −cos 30°, −sin 30°): the organ at (0, −35, 0) lies 30° above it.
  const Vec3 axis(0, -std::cos(kPi / 6), -std::sin(kPi / 6));
  auto organ_in = [&](double oblique) {
    Optics o;
    o.oblique_deg = oblique;
    o.fov_deg = 60;
    const ViewCamera cam = make_view_camera(look_at_pose(Vec3(0, 0, 0), axis, Vec3(0, 0, 1)), o, kSize, kSize);
    RenderSettings on = s, off = s;
    off.show_labels = false;
    return organ_pixels(gl.render(cam, on), gl.render(cam, off));
  };
  const OrganPixels straight = organ_in(0), oblique = organ_in(30);
  EXPECT_FALSE(straight.centre);
  EXPECT_GT(straight.count, 0);
  EXPECT_LT(straight.y, kSize / 2.0 - 10);  // above the centre (image rows grow downwards)
  EXPECT_TRUE(oblique.centre);
  EXPECT_NEAR(oblique.x, kSize / 2.0, 2.0);
  EXPECT_NEAR(oblique.y, kSize / 2.0, 2.0);
}

}  // namespace
}  // namespace pneumo
