// The pre-computed shading gradients (render_volume.h voxel_gradient(), model step 4 of
// render/render_settings.h) against analytic gradients, and the GL texture against them.
//
// A linear ramp h = a·i + b·j + c·k has the gradient (a, b, c) HU per voxel index everywhere.
// Inside the grid the central difference of the voxel values is exact; the stored value is the
// doubled difference rounded to an integer, so the gradient is exact for integer HU and within
// 0.25 HU/voxel (half a rounding step, halved) for real-valued HU. On the faces the difference is
// one-sided over one voxel and then halved, so there the gradient is half the slope (stated; the
// ray casters' boxes end at the voxel centres, where this is what both read).
// Between voxels the sample's gradient is the trilinear interpolation of these values: for a ramp
// every corner holds the same value, so the interpolated gradient is the analytic one as well.
#include <gtest/gtest.h>

#include <cmath>

#include "render/ray_cast_gl.h"
#include "render_test_support.h"

namespace pneumo {
namespace {

RenderVolume ramp_volume(double a, double b, double c, double offset, bool integer) {
  RenderVolume v;
  v.geometry.dims = {20, 17, 13};
  v.geometry.spacing_mm = Vec3(0.8, 1.1, 2.0);
  v.hu.resize(v.geometry.voxel_count());
  for (int64_t k = 0; k < 13; ++k)
    for (int64_t j = 0; j < 17; ++j)
      for (int64_t i = 0; i < 20; ++i) {
        const double h = a * i + b * j + c * k + offset;
        v.hu[v.geometry.linear_index(i, j, k)] = float(integer ? std::nearbyint(h) : h);
      }
  v.hu_is_int16 = integer;
  return v;
}

TEST(RenderGradient, IntegerRampIsExactInsideAndHalvedOnTheFaces) {
  const double slope[3] = {7, -3, 120};  // HU per voxel index
  const RenderVolume v = ramp_volume(slope[0], slope[1], slope[2], -900, true);
  const auto& d = v.geometry.dims;
  for (int64_t k = 0; k < d[2]; ++k)
    for (int64_t j = 0; j < d[1]; ++j)
      for (int64_t i = 0; i < d[0]; ++i) {
        const auto q = voxel_gradient(v, i, j, k);
        const int64_t idx[3] = {i, j, k};
        for (int a = 0; a < 3; ++a) {
          const bool face = idx[a] == 0 || idx[a] == d[a] - 1;
          EXPECT_EQ(kGradientHalf * q[a], face ? 0.5 * slope[a] : slope[a]) << i << " " << j << " " << k << " axis " << a;
        }
      }
}

TEST(RenderGradient, RealRampWithinARoundingStep) {
  const double slope[3] = {0.37, -12.6, 3.05};
  const RenderVolume v = ramp_volume(slope[0], slope[1], slope[2], 10.2, false);
  const auto& d = v.geometry.dims;
  double worst = 0;
  for (int64_t k = 1; k < d[2] - 1; ++k)
    for (int64_t j = 1; j < d[1] - 1; ++j)
      for (int64_t i = 1; i < d[0] - 1; ++i) {
        const auto q = voxel_gradient(v, i, j, k);
        for (int a = 0; a < 3; ++a) worst = std::max(worst, std::abs(kGradientHalf * q[a] - slope[a]));
      }
  EXPECT_LE(worst, 0.25 + 1e-3);  // + float32 storage of the HU
  std::printf("[ gradient ] real ramp: worst component error %.3f HU/voxel\n", worst);
}

TEST(RenderGradient, StoredDifferencesClampToSixteenBits) {
  RenderVolume v = ramp_volume(0, 0, 0, 0, false);
  v.hu[v.geometry.linear_index(5, 5, 6)] = 30000.0f;
  v.hu[v.geometry.linear_index(5, 5, 4)] = -30000.0f;
  EXPECT_EQ(voxel_gradient(v, 5, 5, 5)[2], kGradientMax);
}

// The texture the shader samples holds exactly voxel_gradient() for every voxel, in both layouts
// (packed with integer HU, separate beside float HU).
TEST(RenderGradient, GlTextureHoldsTheVoxelGradients) {
  PNEUMO_REQUIRE_GL(ctx);
  for (bool force_float : {false, true}) {
    const RenderVolume v = ramp_volume(7, -3, 120, -900, true);
    GlRayCaster gl(*ctx);
    gl.set_volume(v, force_float);
    EXPECT_EQ(gl.hu_format(), force_float ? "r32f" : "rgba16_snorm");
    const std::vector<int16_t> t = gl.read_gradient_texture();
    ASSERT_EQ(t.size(), std::size_t(3 * v.geometry.voxel_count()));
    int mismatches = 0;
    for (int64_t n = 0; n < v.geometry.voxel_count(); ++n) {
      const auto& d = v.geometry.dims;
      const auto q = voxel_gradient(v, n % d[0], (n / d[0]) % d[1], n / (d[0] * d[1]));
      for (int a = 0; a < 3; ++a) mismatches += t[3 * n + a] != q[a];
    }
    EXPECT_EQ(mismatches, 0) << (force_float ? "float" : "packed");
  }
}

}  // namespace
}  // namespace pneumo
