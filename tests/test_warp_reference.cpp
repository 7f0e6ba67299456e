// The plain reference of the image warp (host/warp/warp_reference.cpp) against closed forms, and the
// fast CPU warp (host/warp/warp_cpu.cpp) against the reference:
//  - Identity: the input bit for bit. Affine map: analytic resampling within 1e-3 HU, no cracks,
//    labels exact away from half-voxel ties (the same truths test_warp_cpu.cpp holds warp_cpu to).
//  - Whole-voxel translation: warp_cpu equals the reference bit for bit (exact by construction).
//  - Smooth random deformations, seeded, at two cube sizes, with wall and viscera separating and
//    pressing into each other, tetrahedra numbered both ways: where both carry a voxel the CT
//    agrees within 1e-3 HU (both in double; warp_cpu adds its source point up along the row, the
//    reference evaluates it per voxel: ~1e-12 voxel apart, which the float result hides but for
//    an ulp, 1e-4 HU at 1500 HU); outcome and label equal except at measured ties (a weight within
//    1e-5 of −tolerance, a source coordinate within 1e-4 of a half). Every mismatch must be a tie.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include "core/progress.h"
#include "warp/warp.h"
#include "warp_test_support.h"

using namespace pneumo;
using namespace pneumo::testing_support;

namespace {

WarpOptions options() {
  WarpOptions o;
  o.cavity_label = 250;
  return o;
}

Geometry oblique_grid() {
  Geometry g;
  g.dims = {24, 24, 20};
  g.spacing_mm = Vec3(0.8, 0.8, 1.6);
  g.direction = Eigen::AngleAxisd(0.3, Vec3(1, 1, 0).normalized()).toRotationMatrix();
  g.origin_mm = Vec3(-20, 35, -110);
  return g;
}

class WarpReference : public ::testing::Test {
 protected:
  void SetUp() override { Progress::set_enabled(false); }
};

}  // namespace

TEST_F(WarpReference, IdentityReturnsTheInputBitForBit) {
  const WarpCase c = make_warp_case(oblique_grid(), 4, 41);
  const WarpMesh m = make_warp_mesh(c.mesh, std::vector<Vec3>(std::size_t(c.mesh.node_count()), Vec3::Zero()));
  const WarpResult r = warp_reference(m, c.source(), c.whole(), options());
  ASSERT_EQ(r.ct_hu.size(), c.ct.size());
  EXPECT_EQ(std::memcmp(r.ct_hu.data(), c.ct.data(), c.ct.size() * sizeof(float)), 0);
  EXPECT_EQ(r.labels, c.labels);
  EXPECT_EQ(r.gas_voxels, 0);
  EXPECT_GT(r.carried_voxels, 0);
  EXPECT_EQ(r.carried_voxels + r.kept_voxels, c.grid.voxel_count());
}

TEST_F(WarpReference, AffineMatchesAnalyticResamplingWithNoCracks) {
  const AffineCase a = affine_case();
  const WarpResult r = warp_reference(a.mesh, a.c.source(), a.c.whole(), options());
  const AffineCheck check = check_affine(a, r, 1e-6);
  EXPECT_GT(check.checked, 3000);
  EXPECT_EQ(check.cracks, 0) << "voxels inside the deformed mesh left uncovered";
  EXPECT_LE(check.worst_hu, 1e-3) << "HU off analytic affine resampling";
  EXPECT_EQ(check.label_mismatches, 0) << "labels off the nearest source voxel";
}

TEST_F(WarpReference, TheFastCpuWarpEqualsItOnAWholeVoxelTranslationBitForBit) {
  const WarpCase c = make_warp_case(oblique_grid(), 4, 42);
  const WarpMesh m = make_warp_mesh(c.mesh, uniform_displacement(c, Vec3(-2, 3, 1)));
  const WarpResult ref = warp_reference(m, c.source(), c.whole(), options());
  const WarpResult fast = warp_cpu(m, c.source(), c.whole(), options());
  EXPECT_EQ(std::memcmp(ref.ct_hu.data(), fast.ct_hu.data(), ref.ct_hu.size() * sizeof(float)), 0);
  EXPECT_EQ(ref.labels, fast.labels);
  EXPECT_EQ(ref.outcome, fast.outcome);
  EXPECT_GT(ref.gas_voxels, 0);
  EXPECT_GT(ref.carried_voxels, 0);
}

TEST_F(WarpReference, TheFastCpuWarpEqualsItOnRandomDeformationsExceptAtMeasuredTies) {
  struct Trial {
    uint32_t seed;
    int cube;
    double toward;          // > 0: wall and viscera press into each other (overlapping tetrahedra)
    bool reversed = false;  // tetrahedra numbered last cube first: owners, not visiting order, decide
  };
  for (const Trial trial : {Trial{51, 4, 0.0}, Trial{52, 3, 0.0}, Trial{53, 4, 1.6}, Trial{54, 3, 1.6, true}}) {
    SCOPED_TRACE("seed " + std::to_string(trial.seed));
    const WarpCase c = make_warp_case(oblique_grid(), trial.cube, trial.seed);
    std::mt19937 rng(trial.seed);
    std::uniform_real_distribution<double> jitter(-0.35, 0.35);
    std::vector<Vec3> u(std::size_t(c.mesh.node_count()));
    for (int64_t n = 0; n < c.mesh.node_count(); ++n) {
      const Vec3 x = c.grid.to_index(1e3 * c.mesh.rest_m[n]);
      const Vec3 smooth = c.mesh.node_part[n] == Part::Wall
                              ? Vec3(0.4 * std::cos(x[2] / 3.0), 2.5 + std::sin(x[0] / 5.0) - 2.5 * trial.toward, 0)
                              : Vec3(0, -0.8 + trial.toward, 0.5 * std::sin(x[1] / 4.0));
      u[std::size_t(n)] = 1e-3 * (c.index_to_mm() * (smooth + Vec3(jitter(rng), jitter(rng), jitter(rng))));
    }
    WarpMesh m = make_warp_mesh(c.mesh, u);
    if (trial.reversed) {
      std::reverse(m.tets.begin(), m.tets.end());
      std::reverse(m.tet_part.begin(), m.tet_part.end());
    }
    const WarpBox box{{1, 2, 1}, {22, 21, 18}};   // like a CT inside its padding
    const WarpResult ref = warp_reference(m, c.source(), box, options());
    const WarpResult fast = warp_cpu(m, c.source(), box, options());
    ASSERT_EQ(ref.ct_hu.size(), fast.ct_hu.size());
    int64_t ties = 0, untied = 0, both = 0;
    double worst = 0.0;
    for (int64_t k = 0; k < box.dims[2]; ++k)
      for (int64_t j = 0; j < box.dims[1]; ++j)
        for (int64_t i = 0; i < box.dims[0]; ++i) {
          const std::size_t n = std::size_t(i + box.dims[0] * (j + box.dims[1] * k));
          if (ref.outcome[n] == WarpOutcome::Carried && fast.outcome[n] == WarpOutcome::Carried) {
            ++both;
            worst = std::max(worst, std::abs(double(ref.ct_hu[n]) - double(fast.ct_hu[n])));
          } else if (ref.outcome[n] == fast.outcome[n]) {
            EXPECT_EQ(ref.ct_hu[n], fast.ct_hu[n]);   // gas or the voxel's own value: no arithmetic
          }
          if (ref.outcome[n] == fast.outcome[n] && ref.labels[n] == fast.labels[n]) continue;
          if (measured_tie(m, Vec3(double(i + box.lo[0]), double(j + box.lo[1]), double(k + box.lo[2])))) ++ties;
          else ++untied;
        }
    EXPECT_GT(both, 2000);
    EXPECT_GT(ref.gas_voxels, 0);
    EXPECT_LE(worst, 1e-3) << "max CT difference (HU)";
    EXPECT_EQ(untied, 0) << "voxels whose outcome or label differ without a tie";
    std::printf("seed %u: %lld voxels carried by both, max |dHU| %.2e, %lld tie mismatches\n", trial.seed,
                (long long)both, worst, (long long)ties);
  }
}
