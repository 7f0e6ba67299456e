// The real CT in data/totalseg-example-ct reads with the shape, spacing, orientation and
// value range its README states (README.md there, section "example_ct.nii.gz").
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <sstream>

#include "io/volume_info.h"
#include "io/volume_io.h"
#include "shared_data.h"

using namespace pneumo;
using testing_support::totalseg_dir;

TEST(RealCT, ReadsWithTheStatedGeometryAndValues) {
  PNEUMO_REQUIRE_REAL_CT();
  const Volume ct = read_volume(totalseg_dir() + "/example_ct.nii.gz");
  const Geometry& g = ct.geometry();
  EXPECT_EQ(g.dims, (Index3{122, 101, 112}));
  for (int a = 0; a < 3; ++a) EXPECT_DOUBLE_EQ(g.spacing_mm[a], 3.0);
  EXPECT_EQ(g.orientation_code(), "RAS");
  EXPECT_TRUE(g.direction.isIdentity(0.0));
  // The README rounds the origin to 0.01 mm; the header holds float32 values.
  EXPECT_NEAR(g.origin_mm[0], -177.96, 0.005);
  EXPECT_NEAR(g.origin_mm[1], 11.32, 0.005);
  EXPECT_NEAR(g.origin_mm[2], 94.30, 0.005);
  EXPECT_EQ(ct.type(), VoxelType::Int32);   // scl_slope is NaN: values as stored
  const auto r = ct.range();
  EXPECT_EQ(r.min, -1207);
  EXPECT_EQ(r.max, 3382);
  EXPECT_EQ(r.nan_count, 0);
}

TEST(RealCT, LabelMapSharesTheGridAndHoldsExactlyTheLabelsOfLabelsCsv) {
  PNEUMO_REQUIRE_REAL_CT();
  const Volume ct = read_volume(totalseg_dir() + "/example_ct.nii.gz");
  const Volume labels = read_volume(totalseg_dir() + "/example_seg_fast_force_split.nii.gz");
  EXPECT_EQ(labels.type(), VoxelType::UInt8);
  EXPECT_TRUE(labels.geometry().same_grid(ct.geometry(), 1e-4));
  const VolumeInfo info = describe_volume(labels);
  ASSERT_TRUE(info.is_label_map);
  // labels.csv (label_id,name,voxels,...) lists every non-zero id with its exact voxel count.
  std::ifstream csv(totalseg_dir() + "/labels.csv");
  std::string line;
  std::getline(csv, line);  // header
  std::map<int64_t, int64_t> expected;
  while (std::getline(csv, line)) {
    std::stringstream ss(line);
    std::string id, name, voxels;
    std::getline(ss, id, ',');
    std::getline(ss, name, ',');
    std::getline(ss, voxels, ',');
    expected[std::stoll(id)] = std::stoll(voxels);
  }
  ASSERT_GE(expected.size(), 60u);
  std::map<int64_t, int64_t> got = info.label_voxels;
  got.erase(0);
  EXPECT_EQ(got, expected);
  EXPECT_EQ(got.at(5), 41692);  // liver, as the README's table says (1126 ml at 27 ml per 1000 voxels)
}

TEST(RealCT, TheSmallSlabIsTheTopOfTheVolume) {
  PNEUMO_REQUIRE_REAL_CT();
  const Volume ct = read_volume(totalseg_dir() + "/example_ct.nii.gz");
  const Volume slab = read_volume(totalseg_dir() + "/example_ct_sm.nii.gz");
  EXPECT_EQ(slab.type(), VoxelType::Int16);
  EXPECT_EQ(slab.geometry().dims, (Index3{122, 101, 30}));
  // example_ct_sm = example_ct[:, :, 82:112] clipped to -1100..1207.
  for (int64_t k = 0; k < 30; k += 7)
    for (int64_t j = 0; j < 101; j += 5)
      for (int64_t i = 0; i < 122; i += 5) {
        const double v = std::min(1207.0, std::max(-1100.0, ct.value(i, j, k + 82)));
        ASSERT_EQ(slab.value(i, j, k), v) << i << "," << j << "," << k;
      }
}
