// The finite elements' assembled stiffness (solve/fem_stiffness_assembly.h), the default product,
// against the matrix-free product of the CPU reference (FemStiffness::MatrixFree), which
// tests/test_fem.cpp checks against the forces' finite differences.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "mesh/mesh.h"
#include "mesh_test_support.h"
#include "solve/symmetric_block_csr.h"
#include "solve/force_field.h"
#include "seed_support.h"

namespace pneumo {
namespace {

constexpr uint32_t kSeedProduct = 20261206u;

struct RandomState {
  Mesh mesh;
  std::vector<Vec3> x, y, dir;
  ForceModel model;
};

// A random mesh (random roles, so doubled cubes and partly filled cubes, groups of 1–8 corners),
// moduli and Poisson ratios per label, two states (rotated by up to a radian and strained by up
// to 10 % of a cube) and a direction.
RandomState random_state(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const RandomVoxels vox = random_voxels(rng, 7);
  const double young[4] = {2e3 + 80e3 * u(rng), 2e3 + 80e3 * u(rng), 20e3 + 80e3 * u(rng), 20e3 + 80e3 * u(rng)};
  RandomState s;
  s.mesh = build_mesh(vox.view(), vox.options, [&](Role, int label) { return young[label]; });
  assign_material(s.mesh, MaterialOptions{});
  s.mesh.tet_poisson.resize(s.mesh.tets.size());
  for (auto& nu : s.mesh.tet_poisson) nu = 0.2 + 0.29 * u(rng);
  const double h = 1e-3 * vox.grid.spacing_mm.minCoeff() * vox.options.cube_voxels.min();
  auto state = [&] {
    const Mat3 Q = Eigen::AngleAxisd(u(rng), Vec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5).normalized()).toRotationMatrix();
    std::vector<Vec3> x;
    for (const Vec3& r : s.mesh.rest_m) x.push_back(Q * r + 0.1 * h * Vec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5));
    return x;
  };
  s.x = state();
  s.y = state();
  for (std::size_t n = 0; n < s.mesh.rest_m.size(); ++n) s.dir.push_back(h * Vec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5));
  s.model.material = u(rng) < 0.5 ? MaterialModel::FemCorotational : MaterialModel::FemNeoHookean;
  s.model.mean_dilatation = u(rng) < 0.7;
  s.model.stiffening = s.model.material == MaterialModel::FemNeoHookean && u(rng) < 0.5 ? 10.0 * u(rng) : 0.0;
  s.model.damping = false;
  return s;
}

std::vector<Vec3> product(ForceField& field, const ForceModel& model, const std::vector<Vec3>& x,
                          const std::vector<Vec3>& p) {
  std::vector<Vec3> kp;
  field.linearize(model, x);
  field.stiffness_product(p, kp);
  return kp;
}

TEST(FemStiffnessAssembly, ProductEqualsTheMatrixFreeReference) {
  // Both sum the same terms in another order (the assembled one as the tangent's columns for unit
  // moves, linear in δF), so they agree to rounding: 1e-11 of the largest |K p| allows a thousand
  // roundings of the largest term. A wrong block, group term or stale state is off by O(1).
  // Measured: at most 1.1e-15. The second state checks that a new linearisation reassembles.
  const unsigned seed = testing_support::test_seed(20261210u);
  SCOPED_TRACE("seed " + std::to_string(seed));
  std::mt19937 rng(seed);
  double worst_relative = 0.0;
  for (int trial = 0; trial < 24; ++trial) {
    const RandomState s = random_state(rng);
    SCOPED_TRACE("trial " + std::to_string(trial) + ": " + std::string(enum_name(s.model.material)) +
                 (s.model.mean_dilatation ? ", mean dilatation" : ", per tetrahedron") +
                 ", b = " + std::to_string(s.model.stiffening));
    auto assembled = make_fem_force_field(s.mesh, s.model.material, FemStiffness::Assembled);
    auto reference = make_fem_force_field(s.mesh, s.model.material, FemStiffness::MatrixFree);
    for (const std::vector<Vec3>* x : {&s.x, &s.y}) {
      const std::vector<Vec3> ka = product(*assembled, s.model, *x, s.dir);
      const std::vector<Vec3> kr = product(*reference, s.model, *x, s.dir);
      ASSERT_EQ(ka.size(), kr.size());
      const double scale = max_norm(kr);
      ASSERT_GT(scale, 0.0);
      double worst = 0.0;
      for (std::size_t n = 0; n < kr.size(); ++n) worst = std::max(worst, (ka[n] - kr[n]).norm());
      EXPECT_LT(worst, 1e-11 * scale);
      worst_relative = std::max(worst_relative, worst / scale);
    }
  }
  ::testing::Test::RecordProperty("worst_relative_difference", testing::PrintToString(worst_relative));
}

TEST(SymmetricBlockCsr, PatternIsTheUpperTriangleOfEveryPairWithinAGroup) {
  // Groups {0, 1, 2} and {2, 3} of 5 nodes: rows keep the columns at and above themselves; node 4
  // is in no group, so its row is empty and the product gives 0 there.
  const std::vector<int64_t> begin = {0, 3, 5};
  const std::vector<int32_t> nodes = {0, 1, 2, 2, 3};
  const SymmetricBlockCsr a = symmetric_pattern_of_groups(5, begin, nodes);
  const std::vector<std::vector<int32_t>> expected = {{0, 1, 2}, {1, 2}, {2, 3}, {3}, {}};
  for (int32_t r = 0; r < 5; ++r) {
    const std::vector<int32_t> row(a.col.begin() + a.row_start[r], a.col.begin() + a.row_start[r + 1]);
    EXPECT_EQ(row, expected[r]) << "row " << r;
  }
  EXPECT_EQ(a.find(3, 0), -1);
  EXPECT_EQ(a.find(0, 3), -1);
  EXPECT_EQ(a.col[a.find(2, 3)], 3);
}

TEST(SymmetricBlockCsr, ProductIsTheFullSymmetricMatrixTimesTheVector) {
  // 30,000 nodes (above the size at which the product runs on every thread), groups of 2–8 random
  // nodes, random blocks: A x against the sum over the stored blocks and their transposes, written
  // out. Tolerance 1e-12 of the largest |y|: the same terms summed in another order.
  std::mt19937 rng(kSeedProduct);
  std::uniform_int_distribution<int32_t> node(0, 29999), size(2, 8);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<int64_t> begin = {0};
  std::vector<int32_t> nodes;
  for (int g = 0; g < 20000; ++g) {
    std::vector<int32_t> members;
    for (int k = size(rng); k > 0; --k) members.push_back(node(rng));
    std::sort(members.begin(), members.end());
    members.erase(std::unique(members.begin(), members.end()), members.end());
    nodes.insert(nodes.end(), members.begin(), members.end());
    begin.push_back(int64_t(nodes.size()));
  }
  SymmetricBlockCsr a = symmetric_pattern_of_groups(30000, begin, nodes);
  for (Mat3& b : a.block)
    for (int i = 0; i < 9; ++i) b(i / 3, i % 3) = u(rng);
  for (int32_t r = 0; r < a.rows(); ++r)   // diagonal blocks symmetric, as a symmetric matrix's are
    if (const int64_t k = a.find(r, r); k >= 0) a.block[k] = (a.block[k] + a.block[k].transpose()).eval();
  std::vector<Vec3> x(30000), y, want(30000, Vec3::Zero());
  for (Vec3& v : x) v = Vec3(u(rng), u(rng), u(rng));
  a.multiply(x, y);
  for (int32_t r = 0; r < a.rows(); ++r)
    for (int64_t k = a.row_start[r]; k < a.row_start[r + 1]; ++k) {
      const int32_t c = a.col[k];
      want[r] += a.block[k] * x[c];
      if (c != r) want[c] += a.block[k].transpose() * x[r];
    }
  double worst = 0.0;
  for (int32_t r = 0; r < a.rows(); ++r) worst = std::max(worst, (y[r] - want[r]).norm());
  EXPECT_LT(worst, 1e-12 * max_norm(want));
  a.multiply(x, y);   // a second product starts its partial sums afresh
  double again = 0.0;
  for (int32_t r = 0; r < a.rows(); ++r) again = std::max(again, (y[r] - want[r]).norm());
  EXPECT_LT(again, 1e-12 * max_norm(want));
}


TEST(SymmetricBlockCsr, ProductIsBitIdenticalAtAnyThreadCount) {
  // A banded pattern like a lattice's (groups of nearby nodes, 60,000 nodes: several chunks of rows,
  // each with its transposes reaching a band beyond it, and above the size at which the product runs on
  // every thread): 1, 2 and 3 threads give the same bits, and the product the written-out sum (1e-12 of
  // the largest |y|: the same terms in another order).
  constexpr int32_t kNodes = 60000, kBand = 400;
  std::mt19937 rng(kSeedProduct + 1);
  std::uniform_int_distribution<int32_t> start(0, kNodes - kBand - 1), offset(0, kBand), size(2, 8);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<int64_t> begin = {0};
  std::vector<int32_t> nodes;
  for (int g = 0; g < 40000; ++g) {
    std::vector<int32_t> members;
    const int32_t first = start(rng);
    for (int k = size(rng); k > 0; --k) members.push_back(first + offset(rng));
    std::sort(members.begin(), members.end());
    members.erase(std::unique(members.begin(), members.end()), members.end());
    nodes.insert(nodes.end(), members.begin(), members.end());
    begin.push_back(int64_t(nodes.size()));
  }
  SymmetricBlockCsr a = symmetric_pattern_of_groups(kNodes, begin, nodes);
  for (Mat3& b : a.block)
    for (int i = 0; i < 9; ++i) b(i / 3, i % 3) = u(rng);
  std::vector<Vec3> x(kNodes), want(kNodes, Vec3::Zero());
  for (Vec3& v : x) v = Vec3(u(rng), u(rng), u(rng));
  for (int32_t r = 0; r < a.rows(); ++r)
    for (int64_t k = a.row_start[r]; k < a.row_start[r + 1]; ++k) {
      const int32_t c = a.col[k];
      want[r] += a.block[k] * x[c];
      if (c != r) want[c] += a.block[k].transpose() * x[r];
    }
  const int saved = omp_get_max_threads();
  std::vector<std::vector<Vec3>> y(3);
  for (int threads = 1; threads <= 3; ++threads) {
    omp_set_num_threads(threads);
    a.multiply(x, y[threads - 1]);
  }
  omp_set_num_threads(saved);
  double worst = 0.0;
  for (int32_t r = 0; r < kNodes; ++r) worst = std::max(worst, (y[0][r] - want[r]).norm());
  EXPECT_LT(worst, 1e-12 * max_norm(want));
  for (int t = 1; t < 3; ++t) {
    int64_t differing = 0;
    for (int32_t r = 0; r < kNodes; ++r) differing += y[t][r] != y[0][r];
    EXPECT_EQ(differing, 0) << "rows whose product differs between 1 and " << t + 1 << " threads";
  }
}

}  // namespace
}  // namespace pneumo
