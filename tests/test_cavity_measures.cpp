// The fidelity measures of pipeline/cavity_measures.h against hand-counted cases: gas in front of
// a listed organ in its own axial column only (whatever way the grid's axes run), and the viscera's
// posterior motion over the anterior half of their extent only.
#include <gtest/gtest.h>

#include "pipeline/cavity_measures.h"

namespace pneumo {
namespace {

constexpr uint16_t kGas = 250, kBladder = 21;

/// A 3 × 8 × 2 grid (x lateral, y back to front, z slices) with the bladder at y = 3 in column
/// (x = 1, z = 0), and gas at y = 1 (behind it), 5 and 6 (in front) in that column, plus gas at
/// y = 6 in the columns without bladder.
struct Column {
  Geometry g;
  std::vector<uint16_t> labels;
  Column(const Mat3& direction) {
    g.dims = {3, 8, 2};
    g.direction = direction;
    labels.assign(std::size_t(g.voxel_count()), 0);
    auto at = [&](int i, int j, int k) -> uint16_t& { return labels[std::size_t(g.linear_index(i, j, k))]; };
    // Index j along the grid's second axis; with a flipped axis, "in front" is lower j.
    const bool flipped = direction(1, 1) < 0;
    auto y = [&](int front_index) { return flipped ? 7 - front_index : front_index; };
    at(1, y(3), 0) = kBladder;
    at(1, y(1), 0) = kGas;
    at(1, y(5), 0) = kGas;
    at(1, y(6), 0) = kGas;
    at(0, y(6), 0) = kGas;
    at(1, y(6), 1) = kGas;   // next slice: no bladder there
  }
};

TEST(CavityMeasures, GasInFrontOfTheBladderCountsOnlyInItsOwnColumn) {
  const Column c(Mat3::Identity());
  EXPECT_EQ(gas_voxels_anterior_to(c.labels, c.g, kGas, {kBladder}), 2);
  EXPECT_EQ(gas_voxels_anterior_to(c.labels, c.g, kGas, {}), 0);
  EXPECT_EQ(gas_voxels_anterior_to(c.labels, c.g, kGas, {99}), 0);
}

// With the intraperitoneal organs as stops, gas beyond a bowel voxel in the column (in front of
// the bowel that lies in front of the bladder) no longer counts: a bowel voxel at y = 4 hides both,
// one at y = 6 hides only the gas at 6 (the gas at 5 lies between the bladder and the bowel).
TEST(CavityMeasures, GasBeyondAnIntraperitonealOrganIsNotInThePrevesicalSpace) {
  constexpr uint16_t kBowel = 18;
  for (const Mat3& direction : {Mat3(Mat3::Identity()), Mat3(Vec3(-1, -1, 1).asDiagonal())}) {
    Column c(direction);
    const bool flipped = direction(1, 1) < 0;
    auto at = [&](int j) -> uint16_t& { return c.labels[std::size_t(c.g.linear_index(1, flipped ? 7 - j : j, 0))]; };
    EXPECT_EQ(gas_voxels_anterior_to(c.labels, c.g, kGas, {kBladder}, {kBowel}), 2);
    at(4) = kBowel;
    EXPECT_EQ(gas_voxels_anterior_to(c.labels, c.g, kGas, {kBladder}, {kBowel}), 0);
    EXPECT_EQ(gas_voxels_anterior_to(c.labels, c.g, kGas, {kBladder}), 2);
    at(4) = 0;
    at(6) = kBowel;
    EXPECT_EQ(gas_voxels_anterior_to(c.labels, c.g, kGas, {kBladder}, {kBowel}), 1);
  }
}

TEST(CavityMeasures, AGridStoredBackToFrontGivesTheSameCount) {
  Mat3 lps = Mat3::Identity();
  lps(0, 0) = -1;
  lps(1, 1) = -1;   // LPS: index j increases posteriorly
  const Column c(lps);
  EXPECT_EQ(gas_voxels_anterior_to(c.labels, c.g, kGas, {kBladder}), 2);
}

// The space of Retzius against the peritoneum over the bladder: the column's gas (y = 5, 6) lies on
// the floor voxel y = 4. Traced to rest, a floor that touched no intraperitoneal organ there counts
// (the gas opened in front of the bladder); one that had the bowel within a voxel does not (the gas
// lies where the bowel lay on the peritoneum); a floor no tetrahedron carries counts.
TEST(CavityMeasures, GasOnTissueThatABowelLoopCoveredAtRestIsPeritoneal) {
  constexpr uint16_t kBowel = 18;
  for (const Mat3& direction : {Mat3(Mat3::Identity()), Mat3(Vec3(-1, -1, 1).asDiagonal())}) {
    const Column c(direction);
    const bool flipped = direction(1, 1) < 0;
    auto rest_at = [&](std::vector<uint16_t>& rest, int i, int front_index, int k) -> uint16_t& {
      return rest[std::size_t(c.g.linear_index(i, flipped ? 7 - front_index : front_index, k))];
    };
    std::vector<uint16_t> rest_labels(c.labels.size(), 0);
    rest_at(rest_labels, 1, 3, 0) = kBladder;
    RestColumns rest;
    rest.labels = rest_labels.data();
    rest.grid = c.g;
    rest.to_rest = [](const Vec3& p) { return std::optional<Vec3>(p); };   // nothing moved
    EXPECT_EQ(gas_voxels_anterior_to(c.labels, c.g, kGas, {kBladder}, {kBowel}, &rest), 2);

    // The bowel lay on the floor's cranial face: peritoneal.
    rest_at(rest_labels, 1, 4, 1) = kBowel;
    EXPECT_EQ(gas_voxels_anterior_to(c.labels, c.g, kGas, {kBladder}, {kBowel}, &rest), 0);
    // …but two voxels away from it, in front of the gas, it covered nothing under the gas.
    rest_at(rest_labels, 1, 4, 1) = 0;
    rest_at(rest_labels, 1, 6, 1) = kBowel;
    EXPECT_EQ(gas_voxels_anterior_to(c.labels, c.g, kGas, {kBladder}, {kBowel}, &rest), 2);

    // The floor is traced: where it came from two voxels further forward, the bowel touched it.
    const Vec3 forward = c.g.to_world(Vec3(0, flipped ? -2 : 2, 0)) - c.g.to_world(Vec3(0, 0, 0));
    rest.to_rest = [forward](const Vec3& p) { return std::optional<Vec3>(p + forward); };
    EXPECT_EQ(gas_voxels_anterior_to(c.labels, c.g, kGas, {kBladder}, {kBowel}, &rest), 0);
    // A floor that no tetrahedron carries counts.
    rest.to_rest = [](const Vec3&) { return std::optional<Vec3>(); };
    EXPECT_EQ(gas_voxels_anterior_to(c.labels, c.g, kGas, {kBladder}, {kBowel}, &rest), 2);
  }
}

TEST(CavityMeasures, PosteriorMotionIsAveragedOverTheAnteriorHalfOfTheViscera) {
  Mesh m;
  // Viscera nodes at y = 0, 10, 20, 30 mm; a wall node at 40 mm.
  for (double y_mm : {0.0, 10.0, 20.0, 30.0}) {
    m.rest_m.push_back(Vec3(0, y_mm * 1e-3, 0));
    m.node_part.push_back(Part::Viscera);
  }
  m.rest_m.push_back(Vec3(0, 0.04, 0));
  m.node_part.push_back(Part::Wall);
  std::vector<Vec3> x = m.rest_m;
  x[0].y() -= 0.100;   // the posterior half moves a lot: not counted
  x[2].y() -= 0.004;   // 4 mm back
  x[3].y() -= 0.002;   // 2 mm back
  x[4].y() += 0.050;   // the wall rises: not counted
  EXPECT_NEAR(mean_posterior_motion_of_anterior_viscera_mm(m, x), 3.0, 1e-9);
}

}  // namespace
}  // namespace pneumo
