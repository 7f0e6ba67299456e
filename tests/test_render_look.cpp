// The laparoscope's look (render_settings.h, model steps 6 and 7) against its definitions, on the
// CPU reference (tests/test_render_gl_vs_ref.cpp holds the GL path to it): vignetting multiplies
// each pixel by exactly cosⁿ of its ray's angle to the view direction (the cos⁴ law at n = 4), and
// an anti-aliased view is the mean of its passes at the documented pixel offsets and seeds.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "render/ray_cast_ref.h"
#include "render/renderer.h"
#include "render/transfer_function.h"
#include "render_test_support.h"

namespace pneumo {
namespace {

using testing_support::CavityPhantom;
using testing_support::make_cavity_phantom;

RenderSettings lap_settings() {
  RenderSettings s;
  s.tf = preset_transfer_function(RenderPreset::Laparoscopic);
  s.step_mm = 0.75;
  return s;
}

ViewCamera inside_camera(int size) {
  return make_view_camera(look_at_pose(Vec3(0, 20, 0), Vec3(0, -35, 0), Vec3(0, 0, 1)), Optics{}, size, size);
}

TEST(RenderLook, VignettingIsTheCosinePowerOfTheFieldAngle) {
  const RenderVolume v = make_cavity_phantom(CavityPhantom{});
  const ViewCamera cam = inside_camera(48);
  RenderSettings s = lap_settings();
  const RenderImage plain = render_reference(v, cam, s);
  s.vignetting_power = 4.0;
  const RenderImage dark = render_reference(v, cam, s);
  int checked = 0;
  double corner_ratio = 1.0;
  for (int py = 0; py < cam.height; ++py)
    for (int px = 0; px < cam.width; ++px) {
      const std::size_t n = std::size_t(py) * cam.width + px;
      const double cos_t = cam.forward.dot(*cam.ray(px + 0.5, py + 0.5));
      for (int c = 0; c < 3; ++c) {
        const double a = plain.rgba[4 * n + c];
        if (a < 0.02 || a >= 1.0) continue;   // too dark to compare, or clamped
        ASSERT_NEAR(dark.rgba[4 * n + c] / a, std::pow(cos_t, 4.0), 1e-5) << px << " " << py;
        ++checked;
      }
      EXPECT_EQ(dark.rgba[4 * n + 3], plain.rgba[4 * n + 3]);   // opacity and depth are the scene's
      EXPECT_EQ(dark.depth_mm[n], plain.depth_mm[n]);
      if (px == 0 && py == 0) corner_ratio = std::pow(cos_t, 4.0);
    }
  EXPECT_GT(checked, 48 * 48);
  // A 70° pinhole's corner lies 44.7° off the axis: cos⁴ = 0.26.
  EXPECT_NEAR(corner_ratio, std::pow(std::cos(std::atan(std::tan(35.0 * M_PI / 180) * std::sqrt(2.0))), 4.0), 0.02);
}

TEST(RenderLook, AntialiasingIsTheMeanOfItsPasses) {
  const RenderVolume v = make_cavity_phantom(CavityPhantom{});
  const ViewCamera cam = inside_camera(32);
  RenderSettings s = lap_settings();
  s.antialias_samples = 4;
  s.jitter_seed = 11;
  Renderer cpu(/*cpu_reference=*/true, GlBackend::Auto);
  cpu.set_volume(v);
  const RenderImage aa = cpu.render(cam, s);
  std::vector<double> mean(aa.rgba.size(), 0.0);
  std::set<std::pair<double, double>> offsets;
  for (int k = 0; k < 4; ++k) {
    RenderSettings p = s;
    p.antialias_samples = 1;
    p.jitter = true;
    p.jitter_seed = 11 + uint32_t(k);
    const auto o = antialias_offset(k);
    EXPECT_GE(o[0], -0.5);
    EXPECT_LT(o[0], 0.5);
    EXPECT_GE(o[1], -0.5);
    EXPECT_LT(o[1], 0.5);
    offsets.insert({o[0], o[1]});
    p.pixel_offset_x = o[0];
    p.pixel_offset_y = o[1];
    const RenderImage pass = render_reference(v, cam, p);
    for (std::size_t i = 0; i < mean.size(); ++i) mean[i] += pass.rgba[i] / 4.0;
  }
  EXPECT_EQ(offsets.size(), 4u);
  EXPECT_EQ(antialias_offset(0), (std::array<double, 2>{0.0, 0.0}));
  for (std::size_t i = 0; i < mean.size(); ++i) ASSERT_NEAR(aa.rgba[i], mean[i], 1e-6) << i;
}

}  // namespace
}  // namespace pneumo
