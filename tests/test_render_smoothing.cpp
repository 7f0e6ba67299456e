// The views' prefilter (render_volume.h smooth_for_views) and organ colours (premultiplied_colour),
// against truths outside the code: a Gaussian reproduces a linear field exactly away from the edges
// (it is symmetric and sums to one); σ = 0 changes nothing; on a binary (unaliased, as a painted
// phantom or the warp's gas boundary is) oblique plane, the normals from the smoothed voxels point
// along the plane's true normal, where those from the raw voxels follow the staircase.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <string>

#include "core/error.h"
#include "io/volume.h"
#include "render/render_volume.h"
#include "render/view_settings.h"

namespace pneumo {
namespace {

RenderVolume grid_volume(Index3 dims) {
  RenderVolume v;
  v.geometry.dims = dims;
  v.geometry.spacing_mm = Vec3(1.0, 1.0, 1.0);
  v.hu.assign(std::size_t(dims[0] * dims[1] * dims[2]), 0.0f);
  return v;
}

TEST(RenderSmoothing, ALinearFieldIsKeptAwayFromTheEdges) {
  RenderVolume v = grid_volume({24, 20, 18});
  const Index3 d = v.geometry.dims;
  auto f = [](int64_t i, int64_t j, int64_t k) { return float(2.0 * i + 3.0 * j - 1.5 * k); };
  for (int64_t k = 0; k < d[2]; ++k)
    for (int64_t j = 0; j < d[1]; ++j)
      for (int64_t i = 0; i < d[0]; ++i) v.hu[std::size_t(v.geometry.linear_index(i, j, k))] = f(i, j, k);
  smooth_for_views(v, Vec3(1.0, 1.0, 1.0));
  const int margin = 3;   // the truncation radius ceil(3σ)
  for (int64_t k = margin; k < d[2] - margin; ++k)
    for (int64_t j = margin; j < d[1] - margin; ++j)
      for (int64_t i = margin; i < d[0] - margin; ++i)
        ASSERT_NEAR(v.hu[std::size_t(v.geometry.linear_index(i, j, k))], f(i, j, k), 1e-3) << i << " " << j << " " << k;
}

// The fast passes against the definition: every voxel the plain 3-D sum of Gaussian taps (per-axis
// σ, truncated at ⌈3σ⌉, renormalised) over the clamped neighbourhood, in double precision.
TEST(RenderSmoothing, PassesEqualThePlainThreeDimensionalSum) {
  RenderVolume v = grid_volume({13, 11, 9});
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> hu(-1000.0f, 1500.0f);
  for (float& x : v.hu) x = hu(rng);
  const RenderVolume input = v;
  const Vec3 sigma(1.0, 1.7, 2.3);
  smooth_for_views(v, sigma);
  auto taps = [](double s) {
    const int r = int(std::ceil(3 * s));
    std::vector<double> w;
    double sum = 0;
    for (int t = -r; t <= r; ++t) w.push_back(std::exp(-0.5 * t * t / (s * s))), sum += w.back();
    for (double& x : w) x /= sum;
    return w;
  };
  const auto wx = taps(sigma[0]), wy = taps(sigma[1]), wz = taps(sigma[2]);
  const Index3 d = v.geometry.dims;
  auto at = [&](int64_t i, int64_t j, int64_t k) {
    return double(input.hu[std::size_t(input.geometry.linear_index(std::clamp<int64_t>(i, 0, d[0] - 1),
                                                                    std::clamp<int64_t>(j, 0, d[1] - 1),
                                                                    std::clamp<int64_t>(k, 0, d[2] - 1)))]);
  };
  const int64_t rx = int64_t(wx.size() / 2), ry = int64_t(wy.size() / 2), rz = int64_t(wz.size() / 2);
  for (int64_t k = 0; k < d[2]; ++k)
    for (int64_t j = 0; j < d[1]; ++j)
      for (int64_t i = 0; i < d[0]; ++i) {
        double sum = 0;
        for (int64_t c = -rz; c <= rz; ++c)
          for (int64_t b = -ry; b <= ry; ++b)
            for (int64_t a = -rx; a <= rx; ++a)
              sum += wx[std::size_t(a + rx)] * wy[std::size_t(b + ry)] * wz[std::size_t(c + rz)] * at(i + a, j + b, k + c);
        // float passes: a few ulps of values up to 1500 HU
        ASSERT_NEAR(v.hu[std::size_t(v.geometry.linear_index(i, j, k))], sum, 2e-3) << i << " " << j << " " << k;
      }
  // volume_as_viewed filters the same way, from the untouched input.
  RenderVolume viewed_input = input;
  viewed_input.smoothing_mm = 1.0;   // spacing 1 mm: σ = max(1 voxel, 1 mm) on every axis
  std::optional<RenderVolume> storage;
  const RenderVolume& viewed = volume_as_viewed(viewed_input, storage);
  RenderVolume direct = input;
  smooth_for_views(direct, Vec3(1.0, 1.0, 1.0));
  EXPECT_EQ(viewed.hu, direct.hu);
  EXPECT_EQ(viewed_input.hu, input.hu);   // the input keeps its exact HU
}

TEST(RenderSmoothing, ZeroSigmaChangesNothing) {
  RenderVolume v = grid_volume({8, 8, 8});
  for (std::size_t n = 0; n < v.hu.size(); ++n) v.hu[n] = float(n % 7) * 100.0f - 300.0f;
  const std::vector<float> before = v.hu;
  smooth_for_views(v, Vec3::Zero());
  EXPECT_EQ(v.hu, before);
}

// Mean angle (degrees) between the voxel_gradient() normals of the surface voxels (within a voxel of
// the plane) and the plane's true normal.
double mean_normal_error_deg(const RenderVolume& v, const Vec3& normal, const Vec3& point) {
  const Index3 d = v.geometry.dims;
  double sum = 0;
  int count = 0;
  for (int64_t k = 4; k < d[2] - 4; ++k)
    for (int64_t j = 4; j < d[1] - 4; ++j)
      for (int64_t i = 4; i < d[0] - 4; ++i) {
        if (std::abs(normal.dot(Vec3(double(i), double(j), double(k)) - point)) > 1.0) continue;
        const auto g = voxel_gradient(v, i, j, k);
        const Vec3 gv(g[0], g[1], g[2]);
        if (gv.norm() == 0) continue;
        // HU fall from tissue to gas along +normal: the gradient points along −normal.
        sum += std::acos(std::clamp(-gv.normalized().dot(normal), -1.0, 1.0)) * 180.0 / 3.14159265358979;
        ++count;
      }
  return count ? sum / count : 180.0;
}

TEST(RenderSmoothing, NormalsOfAStaircasePlaneFollowThePlane) {
  RenderVolume v = grid_volume({64, 64, 12});
  v.hu_is_int16 = true;
  const Vec3 normal = Vec3(1.0, 0.2, 0.05).normalized();   // a shallow staircase: terraces five voxels long
  const Vec3 point(32.3, 32.1, 6.0);
  const Index3 d = v.geometry.dims;
  for (int64_t k = 0; k < d[2]; ++k)
    for (int64_t j = 0; j < d[1]; ++j)
      for (int64_t i = 0; i < d[0]; ++i)
        v.hu[std::size_t(v.geometry.linear_index(i, j, k))] =
            normal.dot(Vec3(double(i), double(j), double(k)) - point) < 0 ? 40.0f : -1000.0f;
  const double raw = mean_normal_error_deg(v, normal, point);
  smooth_for_views(v, view_smoothing_sigma_voxels(v.geometry, kDefaultSmoothingMm));
  const double smooth = mean_normal_error_deg(v, normal, point);
  // The raw normals are the staircase's: its facets lie along the axes, 11° off the plane, and its
  // edges tilt them further. The terraces repeat every 5 voxels along j; a Gaussian of σ = 1 voxel
  // keeps exp(−2π²σ²/5²) = 0.45 of that period's ripple and far less of its harmonics, which make the
  // edges. Measured 2026-12-06: raw 16.8°, smoothed 5.8°; required: at least halved.
  EXPECT_GT(raw, 11.0);
  EXPECT_LT(smooth, raw / 2.0);
}

// The views' grid: every f-th voxel where σ spans f voxels, f = ⌊σ/voxel⌋, so that the new spacing
// never exceeds σ (render_volume.h: the Gaussian then keeps at most 0.7 % at the coarse Nyquist).
TEST(RenderSmoothing, ViewsGridStrideIsTheWholeVoxelsTheSigmaSpans) {
  Geometry g;
  auto stride = [&](Vec3 spacing, double smoothing_mm) {
    g.spacing_mm = spacing;
    return view_grid_stride(g, smoothing_mm);
  };
  EXPECT_EQ(stride(Vec3(0.75, 0.75, 0.75), 1.5), (Index3{2, 2, 2}));
  EXPECT_EQ(stride(Vec3(0.5, 0.5, 0.5), 1.5), (Index3{3, 3, 3}));
  EXPECT_EQ(stride(Vec3(0.7, 0.7, 3.0), 1.5), (Index3{2, 2, 1}));   // thick slices keep theirs
  EXPECT_EQ(stride(Vec3(1.0, 1.0, 1.0), 1.5), (Index3{1, 1, 1}));   // σ of 1.5 voxels: no whole second
  EXPECT_EQ(stride(Vec3(1.5, 1.5, 1.5), 1.5), (Index3{1, 1, 1}));
  EXPECT_EQ(stride(Vec3(3.0, 3.0, 3.0), 1.5), (Index3{1, 1, 1}));
  EXPECT_EQ(stride(Vec3(0.75, 0.75, 0.75), 0.0), (Index3{1, 1, 1}));   // no smoothing: the voxels
  for (int a = 0; a < 3; ++a) {  // the bound itself: f·h ≤ σ on every axis
    const Index3 f = stride(Vec3(0.3, 0.45, 0.7), 1.5);
    EXPECT_LE(double(f[a]) * g.spacing_mm[a], 1.5 + 1e-9);
    EXPECT_GT(double(f[a] + 1) * g.spacing_mm[a], 1.5);
  }
}

// On the coarser grid every kept voxel holds what the CT-grid filter gives there, bit for bit (the
// passes sum in the same order), its label is the voxel's own, and it sits at the same world point.
TEST(RenderSmoothing, TheViewsGridKeepsTheFullFilterAtEveryKeptVoxel) {
  RenderVolume v = grid_volume({23, 18, 14});
  v.geometry.spacing_mm = Vec3(0.5, 0.75, 0.6);   // strides 3, 2, 2 at 1.5 mm
  v.geometry.origin_mm = Vec3(-4.0, 7.5, 100.0);
  v.geometry.direction = Eigen::AngleAxisd(0.3, Vec3(1, 1, 2).normalized()).toRotationMatrix();
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> hu(-1000, 1500), id(0, 9);
  v.hu_is_int16 = true;
  v.labels.resize(v.hu.size());
  for (std::size_t n = 0; n < v.hu.size(); ++n) v.hu[n] = float(hu(rng)), v.labels[n] = uint16_t(id(rng));
  v.smoothing_mm = 1.5;
  const Index3 f = view_grid_stride(v.geometry, v.smoothing_mm);
  ASSERT_EQ(f, (Index3{3, 2, 2}));

  std::optional<RenderVolume> coarse_storage, full_storage;
  const RenderVolume& coarse = volume_as_viewed(v, coarse_storage, /*with_labels=*/false);
  RenderVolume on_ct_grid = v;
  on_ct_grid.views_on_ct_grid = true;
  const RenderVolume& full = volume_as_viewed(on_ct_grid, full_storage);
  ASSERT_EQ(full.geometry.dims, v.geometry.dims);
  ASSERT_EQ(coarse.geometry.dims, (Index3{8, 9, 7}));   // (n − 1)/f + 1
  ASSERT_EQ(coarse.labels.size(), coarse.hu.size());    // resampled even when not asked for
  for (int64_t k = 0; k < coarse.geometry.dims[2]; ++k)
    for (int64_t j = 0; j < coarse.geometry.dims[1]; ++j)
      for (int64_t i = 0; i < coarse.geometry.dims[0]; ++i) {
        const int64_t c = coarse.geometry.linear_index(i, j, k);
        const int64_t n = v.geometry.linear_index(f[0] * i, f[1] * j, f[2] * k);
        ASSERT_EQ(coarse.hu[std::size_t(c)], full.hu[std::size_t(n)]) << i << " " << j << " " << k;
        ASSERT_EQ(coarse.labels[std::size_t(c)], v.labels[std::size_t(n)]);
        const Vec3 wc = coarse.geometry.to_world(Vec3(double(i), double(j), double(k)));
        const Vec3 wf = v.geometry.to_world(Vec3(double(f[0] * i), double(f[1] * j), double(f[2] * k)));
        ASSERT_LT((wc - wf).norm(), 1e-9);
      }
  // On a grid that keeps its voxels the labels stay with the input unless asked for.
  RenderVolume coarse_ct = v;
  coarse_ct.geometry.spacing_mm = Vec3(1.5, 1.5, 1.5);
  std::optional<RenderVolume> same_storage;
  const RenderVolume& same = volume_as_viewed(coarse_ct, same_storage, /*with_labels=*/false);
  EXPECT_EQ(same.geometry.dims, v.geometry.dims);
  EXPECT_TRUE(same.labels.empty());
}

// The label map's ids reach the renderer exactly, and the first voxel that is no id (negative,
// fractional or beyond 16 bits) is named, whatever the thread count.
TEST(RenderVolumeFrom, LabelsArriveExactlyAndTheFirstBadOneIsNamed) {
  Geometry g;
  g.dims = {7, 5, 3};
  Volume ct(g, VoxelType::Int16), labels(g, VoxelType::Int32);
  for (int64_t n = 0; n < g.voxel_count(); ++n) ct.data<int16_t>()[n] = int16_t(n - 50), labels.data<int32_t>()[n] = int32_t(3 * n);
  const RenderVolume v = RenderVolume::from(ct, &labels);
  ASSERT_EQ(int64_t(v.labels.size()), g.voxel_count());
  for (int64_t n = 0; n < g.voxel_count(); ++n) ASSERT_EQ(v.labels[std::size_t(n)], uint16_t(3 * n));
  EXPECT_TRUE(v.hu_is_int16);
  labels.data<int32_t>()[90] = 70000;
  labels.data<int32_t>()[60] = -2;
  try {
    RenderVolume::from(ct, &labels);
    FAIL() << "a label map with -2 and 70000 was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("-2"), std::string::npos) << e.what();
  }
}

TEST(RenderSmoothing, PremultipliedColoursScaleByAlpha) {
  LabelColours c;
  c.rgba[7] = {200, 100, 50, 128};
  c.rgba[8] = {200, 100, 50, 255};
  const auto half = premultiplied_colour(c, 7), full = premultiplied_colour(c, 8), none = premultiplied_colour(c, 9);
  EXPECT_EQ(half, (std::array<uint8_t, 4>{100, 50, 25, 128}));
  EXPECT_EQ(full, (std::array<uint8_t, 4>{200, 100, 50, 255}));
  EXPECT_EQ(none, (std::array<uint8_t, 4>{0, 0, 0, 0}));
  RenderVolume v = grid_volume({2, 1, 1});
  v.labels = {8, 9};
  const std::vector<uint8_t> vol = label_colour_volume(v.labels, c);
  EXPECT_EQ(vol, (std::vector<uint8_t>{200, 100, 50, 255, 0, 0, 0, 0}));
}

}  // namespace
}  // namespace pneumo
