// kernels/warp.cl against the fast CPU warp (host/warp/warp_cpu.cpp, itself held to the plain
// reference), on every OpenCL device found.
//  - Identity and whole-voxel translation: bit for bit (both are exact by construction: equal
//    displacements cancel, whole-number sources sample voxels with weights 1 and 0).
//  - A smooth random deformation, seeded, at two cube sizes and two of per-axis voxel counts, with wall and viscera separating and
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

Geometry test_grid() { return oblique_test_grid(); }
WarpOptions options() { return warp_test_options(); }

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
  expect_same_bits(ref, dev);
  EXPECT_GT(ref.gas_voxels, 0);
  EXPECT_GT(ref.carried_voxels, 0);
}

// The affine closed form on the device: CT within the float32 tolerance above, no cracks, labels
// exact except within 1e-4 of a half (float32 source points).
TEST_P(WarpClVsCpu, AffineMatchesAnalyticResamplingWithNoCracks) {
  const AffineCase a = affine_case();
  const WarpResult r = warp_opencl(*ctx_, a.mesh, a.c.source(), a.c.whole(), options());
  const AffineCheck check = expect_affine_truth(a, r, 1e-4, kHuTolerance);
  std::printf("%s affine: %lld voxels checked, max |Δ| %.2e HU, %lld nearest-label ties skipped\n", r.device.c_str(),
              (long long)check.checked, check.worst_hu, (long long)check.label_ties);
}

TEST_P(WarpClVsCpu, RandomDeformationEqualsTheReferenceExceptAtMeasuredTies) {
  struct Trial {
    uint32_t seed;
    CubeVoxels cube;
    double toward;   // > 0: wall and viscera press into each other, so tetrahedra of both meshes
                     // overlap and "the lowest accepting index wins" must agree between the
                     // device's atomics and the reference's owners
    bool reversed = false;   // tetrahedra numbered last cube first: the reference visits a tile's
                             // cubes against the index order (as the peers' mesh, numbered pattern by
                             // pattern, makes it), so its owners, not its visiting order, must decide
  };
  // {4, 4, 2} and {3, 4, 2}: per-axis cube voxels (core/cube_voxels.h) on the grid's 0.8 × 0.8 × 1.6 mm voxels,
  // where the device's cube_of table differs per axis.
  for (const Trial trial : {Trial{31, 4, 0.0}, Trial{32, 4, 0.0}, Trial{33, 3, 0.0}, Trial{34, 4, 1.6},
                            Trial{35, 3, 1.6}, Trial{36, 4, 1.6, true}, Trial{37, {4, 4, 2}, 0.0},
                            Trial{38, {3, 4, 2}, 1.6, true}}) {
    SCOPED_TRACE("seed " + std::to_string(trial.seed) + ", cube " + trial.cube.text() + ", toward " +
                 std::to_string(trial.toward));
    const WarpCase c = make_warp_case(test_grid(), trial.cube, trial.seed);
    const WarpMesh m = random_warp_mesh(c, trial.seed, trial.toward, trial.reversed);
    const WarpBox box{{1, 2, 1}, {22, 21, 18}};   // like a CT inside its padding
    const WarpResult ref = warp_cpu(m, c.source(), box, options());
    const WarpResult dev = warp_opencl(*ctx_, m, c.source(), box, options());
    // The sample pass's layouts (a CPU's long chunks, a GPU's one voxel per work-item) give the same bits.
    for (int chunk : {1, 7, 32}) {
      WarpOptions o = options();
      o.row_chunk = chunk;
      SCOPED_TRACE("row_chunk " + std::to_string(chunk));
      expect_same_bits(warp_opencl(*ctx_, m, c.source(), box, o), dev);
    }
    const WarpComparison cmp = compare_warps(ref, dev, m, box);
    EXPECT_GT(cmp.both_carried, 2000);
    EXPECT_GT(ref.gas_voxels, 0);
    EXPECT_LE(cmp.worst_hu, kHuTolerance) << "max CT difference (HU) on " << dev.device;
    EXPECT_EQ(cmp.untied, 0) << "voxels whose outcome or label differ without a tie";
    std::printf("%s seed %u: %lld voxels carried by both, max |Δ| %.2e HU, %lld tie mismatches\n", dev.device.c_str(),
                trial.seed, (long long)cmp.both_carried, cmp.worst_hu, (long long)cmp.ties);
  }
}

GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(WarpClVsCpu);
INSTANTIATE_TEST_SUITE_P(OpenCL, WarpClVsCpu, ::testing::ValuesIn(testing_support::opencl_device_specs()),
                         [](const auto& info) { return testing_support::spec_name(info.param); });
