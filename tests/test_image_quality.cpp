// SSIM (render/image_out.h) against its closed forms: equal images give 1; two constant images give
// the luminance term alone, (2μxμy + C1)/(μx² + μy² + C1), since both variances and the covariance
// vanish and the structure term is C2/C2; and added noise lowers it monotonically.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "render/image_out.h"

namespace pneumo {
namespace {

RenderImage grey_image(int w, int h, double grey_255) {
  RenderImage im;
  im.width = w;
  im.height = h;
  im.rgba.assign(std::size_t(4) * w * h, float(grey_255 / 255.0));
  im.depth_mm.assign(std::size_t(w) * h, 0.0f);
  return im;
}

RenderImage noisy(const RenderImage& im, double sigma_255, unsigned seed) {
  RenderImage out = im;
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, sigma_255 / 255.0);
  for (std::size_t p = 0; p < out.rgba.size() / 4; ++p) {
    const float d = float(n(rng));
    for (int c = 0; c < 3; ++c) out.rgba[4 * p + c] += d;
  }
  return out;
}

TEST(ImageQuality, SsimOfEqualImagesIsOne) {
  const RenderImage a = noisy(grey_image(40, 30, 120), 30, 1);
  EXPECT_NEAR(ssim(a, a), 1.0, 1e-12);
}

TEST(ImageQuality, SsimOfConstantImagesIsTheLuminanceTerm) {
  const double c1 = std::pow(0.01 * 255, 2);
  for (const auto& [p, q] : {std::pair{100.0, 100.0}, {100.0, 140.0}, {10.0, 250.0}, {0.0, 255.0}}) {
    const double expected = (2 * p * q + c1) / (p * p + q * q + c1);
    // Luma of a grey (v, v, v) is v: the BT.601 weights sum to 1 (to rounding).
    EXPECT_NEAR(ssim(grey_image(32, 24, p), grey_image(32, 24, q)), expected, 1e-9) << p << " vs " << q;
  }
}

TEST(ImageQuality, SsimFallsAsNoiseGrowsAndIsSymmetric) {
  const RenderImage a = noisy(grey_image(64, 48, 128), 20, 2);
  double last = 1.0;
  for (double sigma : {5.0, 15.0, 40.0}) {
    const RenderImage b = noisy(a, sigma, 3);
    const double s = ssim(a, b);
    EXPECT_LT(s, last) << sigma;
    EXPECT_NEAR(s, ssim(b, a), 1e-12);
    last = s;
  }
}

TEST(ImageQuality, SsimOfMismatchedOrTinyImagesIsNan) {
  EXPECT_TRUE(std::isnan(ssim(grey_image(32, 24, 1), grey_image(24, 32, 1))));
  EXPECT_TRUE(std::isnan(ssim(grey_image(10, 40, 1), grey_image(10, 40, 1))));
}

}  // namespace
}  // namespace pneumo
