// kernels/warp.cl against the fast CPU warp (host/warp/warp_cpu.cpp, itself held to the plain
// reference), on every OpenCL device found.
//  - Identity and whole-voxel translation: bit for bit (both are exact by construction: equal
//    displacements cancel, whole-number sources sample voxels with weights 1 and 0).
//  - A smooth random deformation, seeded, at two cube sizes, with wall and viscera separating and
//    pressing into each other (their tetrahedra overlap), in every layout of the sample pass: CT within 0.1 HU where
//    both carry the voxel (float32 source points are off by ~1e-5 voxel; the random CT changes by up
//    to 2500 HU per voxel, so 0.03 HU; 0.1 leaves room and is 1/10 of the CT's own quantisation);
//    outcome and label exactly equal except at measured ties: voxels whose containment decision
//    (some weight within 1e-5 of −tolerance) or whose nearest voxel (a source coordinate within
//    1e-4 of a half) is decided by rounding. Every mismatch must be such a tie; the count is printed.
#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <cstring>

#include "core/progress.h"
#include "opencl_test_support.h"
#include "warp/warp.h"
#include "warp_test_support.h"

using namespace pneumo;
using namespace pneumo::testing_support;

namespace {

constexpr double kHuTolerance = 0.1;

Geometry test_grid() {
  Geometry g;
  g.dims = {24, 24, 20};
  g.spacing_mm = Vec3(0.8, 0.8, 1.6);
  g.direction = Eigen::AngleAxisd(0.3, Vec3(1, 1, 0).normalized()).toRotationMatrix();
  g.origin_mm = Vec3(-20, 35, -110);
  return g;
}

WarpOptions options() {
  WarpOptions o;
  o.cavity_label = 250;
  return o;
}

class WarpClVsCpu : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    Progress::set_enabled(false);
    ctx_ = ocl::Context::shared(ocl::parse_device_spec(GetParam()));
  }
  std::shared_ptr<ocl::Context> ctx_;
};

}  // namespace

TEST_P(WarpClVsCpu, IdentityReturnsTheInputBitForBit) {
  const WarpCase c = make_warp_case(test_grid(), 4, 21);
  const WarpMesh m = make_warp_mesh(c.mesh, std::vector<Vec3>(std::size_t(c.mesh.node_count()), Vec3::Zero()));
  const WarpResult r = warp_opencl(*ctx_, m, c.source(), c.whole(), options());
  EXPECT_EQ(std::memcmp(r.ct_hu.data(), c.ct.data(), c.ct.size() * sizeof(float)), 0);
  EXPECT_EQ(r.labels, c.labels);
  EXPECT_EQ(r.gas_voxels, 0);
  EXPECT_GT(r.carried_voxels, 0);
}

TEST_P(WarpClVsCpu, WholeVoxelTranslationEqualsTheReferenceBitForBit) {
  const WarpCase c = make_warp_case(test_grid(), 4, 22);
  const WarpMesh m = make_warp_mesh(c.mesh, uniform_displacement(c, Vec3(-2, 3, 1)));
  const WarpResult ref = warp_cpu(m, c.source(), c.whole(), options());
  const WarpResult dev = warp_opencl(*ctx_, m, c.source(), c.whole(), options());
  EXPECT_EQ(std::memcmp(ref.ct_hu.data(), dev.ct_hu.data(), ref.ct_hu.size() * sizeof(float)), 0);
  EXPECT_EQ(ref.labels, dev.labels);
  EXPECT_EQ(ref.outcome, dev.outcome);
  EXPECT_GT(ref.gas_voxels, 0);
  EXPECT_GT(ref.carried_voxels, 0);
}

// The affine closed form on the device: CT within the float32 tolerance above, no cracks, labels
// exact except within 1e-4 of a half (float32 source points).
TEST_P(WarpClVsCpu, AffineMatchesAnalyticResamplingWithNoCracks) {
  const AffineCase a = affine_case();
  const WarpResult r = warp_opencl(*ctx_, a.mesh, a.c.source(), a.c.whole(), options());
  const AffineCheck check = check_affine(a, r, 1e-4);
  EXPECT_GT(check.checked, 3000);
  EXPECT_EQ(check.cracks, 0) << "voxels inside the deformed mesh left uncovered";
  EXPECT_LE(check.worst_hu, kHuTolerance) << "HU off analytic affine resampling";
  EXPECT_EQ(check.label_mismatches, 0) << "labels off the nearest source voxel";
  std::printf("%s affine: %lld voxels checked, max |Δ| %.2e HU, %lld nearest-label ties skipped\n", r.device.c_str(),
              (long long)check.checked, check.worst_hu, (long long)check.label_ties);
}

TEST_P(WarpClVsCpu, RandomDeformationEqualsTheReferenceExceptAtMeasuredTies) {
  struct Trial {
    uint32_t seed;
    int cube;
    double toward;   // > 0: wall and viscera press into each other, so tetrahedra of both meshes
                     // overlap and "the lowest accepting index wins" must agree between the
                     // device's atomics and the reference's owners
    bool reversed = false;   // tetrahedra numbered last cube first: the reference visits a tile's
                             // cubes against the index order (as the peers' mesh, numbered pattern by
                             // pattern, makes it), so its owners, not its visiting order, must decide
  };
  for (const Trial trial : {Trial{31, 4, 0.0}, Trial{32, 4, 0.0}, Trial{33, 3, 0.0}, Trial{34, 4, 1.6},
                            Trial{35, 3, 1.6}, Trial{36, 4, 1.6, true}}) {
    SCOPED_TRACE("seed " + std::to_string(trial.seed) + ", cube " + std::to_string(trial.cube) + ", toward " +
                 std::to_string(trial.toward));
    const WarpCase c = make_warp_case(test_grid(), trial.cube, trial.seed);
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
    const WarpResult ref = warp_cpu(m, c.source(), box, options());
    const WarpResult dev = warp_opencl(*ctx_, m, c.source(), box, options());
    // The sample pass's layouts (a CPU's long chunks, a GPU's one voxel per work-item) give the same bits.
    for (int chunk : {1, 7, 32}) {
      WarpOptions o = options();
      o.row_chunk = chunk;
      const WarpResult other = warp_opencl(*ctx_, m, c.source(), box, o);
      EXPECT_EQ(std::memcmp(other.ct_hu.data(), dev.ct_hu.data(), dev.ct_hu.size() * sizeof(float)), 0) << chunk;
      EXPECT_EQ(other.labels, dev.labels) << chunk;
      EXPECT_EQ(other.outcome, dev.outcome) << chunk;
    }
    ASSERT_EQ(ref.ct_hu.size(), dev.ct_hu.size());
    int64_t ties = 0, untied = 0, both = 0;
    double worst = 0.0;
    for (int64_t k = 0; k < box.dims[2]; ++k)
      for (int64_t j = 0; j < box.dims[1]; ++j)
        for (int64_t i = 0; i < box.dims[0]; ++i) {
          const std::size_t n = std::size_t(i + box.dims[0] * (j + box.dims[1] * k));
          const bool carried = ref.outcome[n] == WarpOutcome::Carried && dev.outcome[n] == WarpOutcome::Carried;
          if (carried) {
            ++both;
            worst = std::max(worst, std::abs(double(ref.ct_hu[n]) - double(dev.ct_hu[n])));
          } else if (ref.outcome[n] == dev.outcome[n]) {
            EXPECT_EQ(ref.ct_hu[n], dev.ct_hu[n]);   // gas or the voxel's own value: no arithmetic
          }
          if (ref.outcome[n] == dev.outcome[n] && ref.labels[n] == dev.labels[n]) continue;
          const Vec3 p(double(i + box.lo[0]), double(j + box.lo[1]), double(k + box.lo[2]));
          if (measured_tie(m, p)) ++ties;
          else ++untied;
        }
    EXPECT_GT(both, 2000);
    EXPECT_GT(ref.gas_voxels, 0);
    EXPECT_LE(worst, kHuTolerance) << "max CT difference (HU) on " << dev.device;
    EXPECT_EQ(untied, 0) << "voxels whose outcome or label differ without a tie";
    std::printf("%s seed %u: %lld voxels carried by both, max |Δ| %.2e HU, %lld tie mismatches\n", dev.device.c_str(),
                trial.seed, (long long)both, worst, (long long)ties);
  }
}

GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(WarpClVsCpu);
INSTANTIATE_TEST_SUITE_P(OpenCL, WarpClVsCpu, ::testing::ValuesIn(testing_support::opencl_device_specs()),
                         [](const auto& info) { return testing_support::spec_name(info.param); });
