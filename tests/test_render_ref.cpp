// Truths of the renderer's CPU side: the camera model, paths, transfer functions, poses, the
// exterior-air mask, and the CPU reference ray caster against closed forms on the analytic cavity
// phantom (render_test_support.h). Tolerances are stated where they are used.
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "render/camera_path.h"
#include "render/image_out.h"
#include "render/poses.h"
#include "render/ray_cast_ref.h"
#include "render_test_support.h"
#include "scene/scene.h"

namespace pneumo {
namespace {

using testing_support::CavityPhantom;
using testing_support::make_cavity_phantom;
constexpr double kPi = 3.14159265358979323846;
double deg(double r) { return r * 180.0 / kPi; }

ViewCamera camera(const Vec3& tip, const Vec3& at, Optics o = {}, int w = 64, int h = 64) {
  return make_view_camera(look_at_pose(tip, at, o.up), o, w, h);
}

// Camera model: exact geometry, compared to 1e-9 (double arithmetic on unit vectors).
TEST(RenderCamera, PinholeCentreRayIsForwardAndEdgeRayIsHalfTheFieldOfView) {
  Optics o;
  o.fov_deg = 70;
  const ViewCamera c = camera(Vec3(0, 0, 0), Vec3(0, -1, 0), o, 100, 50);
  EXPECT_LT((*c.ray(50, 25) - c.forward).norm(), 1e-9);
  EXPECT_NEAR(deg(std::acos(c.ray(100, 25)->dot(c.forward))), 35.0, 1e-9);  // right edge, mid height
  EXPECT_GT(c.ray(50, 0)->dot(c.up), 0.0);                                    // top row looks up
  EXPECT_GT(c.ray(99, 25)->dot(c.right), 0.0);
}

TEST(RenderCamera, FisheyeIsEquidistantUpTo180DegreesAndBlankOutsideItsCircle) {
  Optics o;
  o.lens = Lens::Fisheye;
  o.fov_deg = 180;
  const ViewCamera c = camera(Vec3(0, 0, 0), Vec3(0, -1, 0), o, 100, 100);
  // Equidistant: the angle grows linearly with the distance from the centre.
  EXPECT_NEAR(deg(std::acos(c.ray(75, 50)->dot(c.forward))), 45.0, 1e-9);
  EXPECT_NEAR(deg(std::acos(c.ray(100, 50)->dot(c.forward))), 90.0, 1e-9);
  EXPECT_FALSE(c.ray(1, 1).has_value());  // a corner: outside the image circle
}

TEST(RenderCamera, ObliqueScopeLooksTiltedTowardsUpAndRollTurnsIt) {
  Optics o;
  o.oblique_deg = 30;
  const Vec3 axis(0, -1, 0);
  const ViewCamera c0 = camera(Vec3(0, 0, 0), axis, o);
  // up hint +z: the 30° scope looks 30° above the shaft.
  EXPECT_LT((c0.forward - Vec3(0, -std::cos(kPi / 6), std::sin(kPi / 6))).norm(), 1e-9);
  o.roll_deg = 90;
  const ViewCamera c90 = camera(Vec3(0, 0, 0), axis, o);
  // Rolled 90°: tilted towards the unrolled image's right, (axis × up) = (−1, 0, 0).
  EXPECT_LT((c90.forward - Vec3(-std::sin(kPi / 6), -std::cos(kPi / 6), 0)).norm(), 1e-9);
  for (const ViewCamera* c : {&c0, &c90}) {  // the frame stays orthonormal and right-handed
    EXPECT_NEAR(c->forward.dot(c->up), 0, 1e-12);
    EXPECT_NEAR(c->forward.dot(c->right), 0, 1e-12);
    EXPECT_LT((c->right.cross(c->up) + c->forward).norm(), 1e-9);  // (right, up, −forward)
  }
}

// project() inverts ray(): a point along a pixel's ray projects back onto that pixel (both lenses,
// oblique and rolled), to 1e-9 px; points behind a pinhole or outside the fisheye circle project nowhere.
TEST(RenderCamera, ProjectionIsTheInverseOfTheRay) {
  for (const Lens lens : {Lens::Pinhole, Lens::Fisheye}) {
    Optics o;
    o.lens = lens;
    o.fov_deg = lens == Lens::Pinhole ? 70 : 170;
    o.oblique_deg = 30;
    o.roll_deg = 25;
    const ViewCamera c = camera(Vec3(5, -3, 2), Vec3(10, -40, 7), o, 120, 80);
    int checked = 0;
    for (double px : {3.5, 30.25, 60.0, 91.0, 117.5})
      for (double py : {2.5, 40.0, 71.75}) {
        const std::optional<Vec3> d = c.ray(px, py);
        if (!d) continue;
        const std::optional<Eigen::Vector2d> p = c.project(c.position_mm + 37.0 * *d);
        ASSERT_TRUE(p.has_value()) << px << "," << py;
        EXPECT_NEAR(p->x(), px, 1e-9);
        EXPECT_NEAR(p->y(), py, 1e-9);
        ++checked;
      }
    EXPECT_GE(checked, lens == Lens::Pinhole ? 15 : 9);
  }
  const ViewCamera pin = camera(Vec3(0, 0, 0), Vec3(0, -1, 0));
  EXPECT_FALSE(pin.project(Vec3(0, 5, 0)).has_value());   // behind the camera
  Optics fish;
  fish.lens = Lens::Fisheye;
  fish.fov_deg = 120;
  EXPECT_FALSE(camera(Vec3(0, 0, 0), Vec3(0, -1, 0), fish).project(Vec3(0, 1, 0.1)).has_value());
}

TEST(RenderCamera, UpAlongTheAxisIsBadInput) {
  Optics o;
  o.up = Vec3(0, -1, 0);
  EXPECT_THROW(camera(Vec3(0, 0, 0), Vec3(0, -5, 0), o), InputError);
  EXPECT_THROW(look_at_pose(Vec3(1, 2, 3), Vec3(1, 2, 3), Vec3(0, 0, 1)), InputError);
}

// Paths: Catmull-Rom interpolates (passes through) the keyframes; slerp halves the turn.
TEST(RenderPath, PassesThroughKeyframesAndTurnsHalfwayAtTheMiddle) {
  std::vector<Keyframe> keys{{Vec3(0, 0, 0), Vec3(0, -10, 0)},
                             {Vec3(10, 0, 0), Vec3(20, 0, 0)},  // turned 90° about z
                             {Vec3(20, 5, 0), Vec3(30, 5, 0)}};
  const auto poses = interpolate_path(keys, 5, Vec3(0, 0, 1));  // s = 0, 0.5, 1, 1.5, 2
  ASSERT_EQ(poses.size(), 5u);
  EXPECT_LT((poses[0].tip_mm - keys[0].position_mm).norm(), 1e-9);
  EXPECT_LT((poses[2].tip_mm - keys[1].position_mm).norm(), 1e-9);
  EXPECT_LT((poses[4].tip_mm - keys[2].position_mm).norm(), 1e-9);
  EXPECT_LT((poses[0].axis - Vec3(0, -1, 0)).norm(), 1e-9);
  EXPECT_NEAR(deg(std::acos(poses[1].axis.dot(Vec3(0, -1, 0)))), 45.0, 1e-6);
  EXPECT_NEAR(deg(std::acos(poses[1].axis.dot(Vec3(1, 0, 0)))), 45.0, 1e-6);
  // Between keyframes: the uniform Catmull-Rom of the mirrored end point and the first three keys.
  const Vec3 p0 = 2.0 * keys[0].position_mm - keys[1].position_mm;
  EXPECT_LT((poses[1].tip_mm - catmull_rom(p0, keys[0].position_mm, keys[1].position_mm, keys[2].position_mm, 0.5))
                .norm(),
            1e-9);
}

// Transfer functions: piecewise linear between Slicer's points (CT-Muscle, method.md §8).
TEST(RenderTransferFunction, PresetsInterpolateTheirPointsAndCustomOnesAreChecked) {
  const TransferFunction m = preset_transfer_function(RenderPreset::CtMuscle);
  EXPECT_DOUBLE_EQ(m.opacity_at(-155.407), 0.0);
  EXPECT_NEAR(m.opacity_at(217.641), 0.676, 1e-12);
  EXPECT_NEAR(m.opacity_at(0.5 * (217.641 + 419.736)), 0.5 * (0.676 + 0.833), 1e-12);
  EXPECT_DOUBLE_EQ(m.opacity_at(5000), 0.804);  // constant beyond the last point
  EXPECT_DOUBLE_EQ(m.max_opacity(-1000, -200), 0.0);
  EXPECT_NEAR(m.max_opacity(0, 1000), 0.833, 1e-12);
  ViewSettings r;
  r.preset = RenderPreset::Custom;
  r.custom_opacity = {-100, 0, 100, 1};
  r.custom_colour = {0, 1, 0, 0};
  EXPECT_NEAR(scene_transfer_function(r).opacity_at(0), 0.5, 1e-12);
  r.custom_opacity = {-100, 0, 100};  // not pairs
  EXPECT_THROW(scene_transfer_function(r), InputError);
}

// Poses: a label's centroid (the organ sphere lies wholly in the grid: its centroid is its centre
// to within the voxel quantisation, 0.3 mm here), and a port carried by the point map.
TEST(RenderPoses, LabelCentroidAndPortCarriedThroughTheDeformation) {
  const CavityPhantom p;
  const RenderVolume v = make_cavity_phantom(p);
  EXPECT_LT((label_centroid_mm(v, p.organ_label) - p.organ_centre_mm).norm(), 0.3);
  EXPECT_THROW(label_centroid_mm(v, 99), InputError);
  const PointMapFn lift = [](const Vec3& x) { return Vec3(x + Vec3(0, 0, 12)); };
  const ScopePose pose = port_pose(Vec3(0, 40, 0), Vec3(0, -35, 12), 10, lift, Vec3(0, 0, 1));
  EXPECT_LT((pose.axis - Vec3(0, -1, 0)).norm(), 1e-12);           // skin (0,40,12) → target (0,-35,12)
  EXPECT_LT((pose.tip_mm - Vec3(0, 30, 12)).norm(), 1e-12);        // 10 mm beyond the carried skin point
}

// Exterior air: only air reachable from the grid's faces is marked; the enclosed cavity is not.
TEST(RenderVolumeTest, ExteriorAirIsTheAirConnectedToTheFaces) {
  RenderVolume v;
  v.geometry.dims = {20, 20, 20};
  v.hu.assign(8000, -1000.0f);
  for (int k = 0; k < 20; ++k)
    for (int j = 0; j < 20; ++j)
      for (int i = 0; i < 20; ++i) {
        const double r = Vec3(i - 9.5, j - 9.5, k - 9.5).norm();
        if (r < 8 && r > 4) v.hu[v.geometry.linear_index(i, j, k)] = 40.0f;  // a shell around a gas core
      }
  v.mark_exterior_air();
  EXPECT_EQ(v.labels[v.geometry.linear_index(0, 0, 0)], kExteriorAirLabel);
  EXPECT_EQ(v.labels[v.geometry.linear_index(10, 10, 10)], 0);  // enclosed gas
  EXPECT_EQ(v.labels[v.geometry.linear_index(10, 10, 16)], 0);  // the shell
}

// Depth: from the cavity's centre every ray meets the wall at the cavity radius (35 mm). The
// first-surface depth (A ≥ 0.5) may lie up to one voxel (1.5 mm, the partial-volume ramp) plus one
// step beyond it; the organ is turned away from this camera.
TEST(RenderReference, DepthFromTheCavityCentreIsTheCavityRadius) {
  const CavityPhantom p;
  const RenderVolume v = make_cavity_phantom(p);
  RenderSettings s;
  s.tf = preset_transfer_function(RenderPreset::Laparoscopic);
  s.step_mm = 0.75;
  Optics o;
  o.near_mm = 0;
  const RenderImage im = render_reference(v, camera(Vec3(0, 0, 0), Vec3(0, 10, 0), o, 16, 16), s);
  for (float d : im.depth_mm) {
    EXPECT_GT(d, p.cavity_radius_mm - p.spacing_mm);
    EXPECT_LT(d, p.cavity_radius_mm + p.spacing_mm + s.step_mm);
  }
}

// Model step 2b, the entry refinement: from a tip off the cavity's centre the wall lies at a different distance along
// every ray, so ray samples a fixed Δs apart from the tip would meet it anywhere up to a step inside, and the first
// surface's depth would fall on the lattice (near + k·Δs), banding the image (wood grain). With the entry found by
// bisection and the first sample half a step past it, depth − the exact distance to the sphere of radius R is the
// same on every ray up to where along the ray the opacity reaches ½ (the depth's own definition, a whole number of
// steps past the entry, which depends on how obliquely the ray crosses the wall's 1.5 mm ramp): its spread across
// the image is held under 0.4 steps, where the lattice alone spreads it over more than a step. Measured at Δs =
// 1.5 mm: 0.50 mm; with the refinement switched off in the reference, 1.98 mm.
TEST(RenderReference, TheFirstSurfaceFollowsTheWallNotTheSampleLattice) {
  const CavityPhantom p;
  const RenderVolume v = make_cavity_phantom(p);
  RenderSettings s;
  s.tf = preset_transfer_function(RenderPreset::Laparoscopic);
  s.step_mm = 1.5;   // coarse, so that the lattice would show
  Optics o;
  o.near_mm = 0;
  const Vec3 tip(4.0, 10.0, -3.0);
  const ViewCamera c = camera(tip, Vec3(30, 10, 5), o, 32, 32);   // away from the organ on the wall at −y
  const RenderImage im = render_reference(v, c, s);
  double lo = 1e30, hi = -1e30;
  int surfaces = 0;
  for (int py = 0; py < c.height; ++py)
    for (int px = 0; px < c.width; ++px) {
      const double depth = im.depth_mm[std::size_t(py) * c.width + px];
      const auto dir = c.ray(px + 0.5, py + 0.5);
      if (!dir || !std::isfinite(depth)) continue;
      const double b = tip.dot(*dir), cc = tip.squaredNorm() - p.cavity_radius_mm * p.cavity_radius_mm;
      const double exact = -b + std::sqrt(b * b - cc);   // the tip lies inside the sphere: one root ahead
      lo = std::min(lo, depth - exact);
      hi = std::max(hi, depth - exact);
      ++surfaces;
    }
  ASSERT_GT(surfaces, 32 * 32 / 2);
  std::printf("depth - exact distance: %.3f ... %.3f mm (spread %.3f mm, step %.2f mm)\n", lo, hi, hi - lo, s.step_mm);
  EXPECT_LT(hi - lo, 0.4 * s.step_mm);
}

// The laparoscopic preset's opacities under a high-contrast colour ramp (bright fat at -100 HU over
// a dark rim at -300 HU, deep red at 70 HU: the preset's hand-picked colours before they were
// computed from tissue optics): the two tests below compare opacity, which shows most where bright
// and dark tissue are composited, whatever colours the preset now has.
TransferFunction laparoscopic_opacity_high_contrast() {
  TransferFunction tf = preset_transfer_function(RenderPreset::Laparoscopic);
  tf.colour = {{-1024, 0.0, 0.0, 0.0},  {-300, 0.35, 0.28, 0.22}, {-100, 0.93, 0.80, 0.52},
               {-30, 0.90, 0.62, 0.50}, {20, 0.85, 0.42, 0.38},   {45, 0.75, 0.27, 0.24},
               {70, 0.60, 0.16, 0.14},  {250, 0.95, 0.88, 0.78},  {1000, 1.0, 0.98, 0.94}};
  return tf;
}

// Opacity correction: the same view at Δs = 0.75 and 0.375 mm differs only by where samples fall
// (≥ 30 dB); without the correction (α used per sample) the finer step would be visibly more
// opaque and brighter on semi-transparent fat. Checked by the corrected pair beating 30 dB.
TEST(RenderReference, OpacityCorrectionMakesTheImageIndependentOfTheStep) {
  const RenderVolume v = make_cavity_phantom();
  RenderSettings s;
  s.tf = laparoscopic_opacity_high_contrast();
  const ViewCamera c = camera(Vec3(0, 20, 0), Vec3(0, -30, 0), Optics{}, 48, 48);
  s.step_mm = 0.75;
  const RenderImage a = render_reference(v, c, s);
  s.step_mm = 0.375;
  const RenderImage b = render_reference(v, c, s);
  EXPECT_GE(psnr_db(a, b), 30.0);
}

// The negative control of the test above: a renderer without the correction (α per sample whatever the step) would
// fail it. Emulated with the corrected renderer by giving it, at each step Δs, the opacities α' whose correction
// gives back α per sample: α' = 1 − (1 − α)^(Δs_ref/Δs), control point by control point. Measured: 24.4 dB.
TEST(RenderReference, WithoutOpacityCorrectionTheStepWouldShow) {
  const RenderVolume v = make_cavity_phantom();
  const ViewCamera c = camera(Vec3(0, 20, 0), Vec3(0, -30, 0), Optics{}, 48, 48);
  auto uncorrected = [&](double step_mm) {
    RenderSettings s;
    s.tf = laparoscopic_opacity_high_contrast();
    for (auto& point : s.tf.opacity) point[1] = 1.0 - std::pow(1.0 - point[1], kOpacityUnitMm / step_mm);
    s.step_mm = step_mm;
    return render_reference(v, c, s);
  };
  EXPECT_LT(psnr_db(uncorrected(0.75), uncorrected(0.375)), 30.0);
}

}  // namespace
}  // namespace pneumo
