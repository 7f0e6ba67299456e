// `pneumo run` hands the warp's own HU to the views (round_as_written, RenderVolume::from_hu)
// instead of converting the written deformed CT back to floats: the renderer's volume must be the
// one it would read from that file, value for value, for every voxel type the CT is written in.
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <stdexcept>

#include "core/error.h"
#include "pipeline/warp_stage.h"
#include "render/render_volume.h"

namespace pneumo {
namespace {

TEST(ViewsFromTheWarp, TheWarpsHuRoundedAsWrittenAreTheWrittenCtsHu) {
  Geometry g;
  g.dims = {9, 7, 5};
  g.spacing_mm = Vec3(0.75, 0.75, 1.5);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> hu(-1200.0f, 3000.0f);
  std::vector<float> warped(std::size_t(g.voxel_count()));
  for (float& x : warped) x = hu(rng);
  // Ties, whole values, and values beyond 16 and 32 bits, which the written types clamp.
  warped[0] = 10.5f, warped[1] = -10.5f, warped[2] = 40000.0f, warped[3] = -40000.0f, warped[4] = 3e10f, warped[5] = 17.0f;
  for (const VoxelType input : {VoxelType::Int16, VoxelType::Int32, VoxelType::Float32, VoxelType::Float64, VoxelType::UInt8}) {
    WarpedCase w;
    w.ct = Volume(g, input);
    w.output_grid = g;
    w.result.ct_hu = warped;
    const Volume written = deformed_ct_volume(w);
    const RenderVolume from_file = RenderVolume::from(written, nullptr);
    EXPECT_EQ(deformed_ct_type(w), written.type());
    std::vector<float> taken = warped;
    const bool int16 = round_as_written(taken, written.type());
    // Rounding twice changes nothing: the run rounds the HU for the views and writes them after.
    std::vector<float> again = taken;
    round_as_written(again, written.type());
    ASSERT_EQ(again, taken) << int(input);
    // ...and the deformed CT built from the rounded HU after the views is the file's, byte for byte.
    WarpedCase back = w;
    back.result.ct_hu = taken;
    const Volume rewritten = deformed_ct_volume(back);
    ASSERT_EQ(rewritten.type(), written.type());
    ASSERT_EQ(std::memcmp(rewritten.raw(), written.raw(), written.byte_count()), 0) << int(input);
    const RenderVolume from_warp = RenderVolume::from_hu(g, std::move(taken), nullptr, int16);
    ASSERT_EQ(from_warp.hu.size(), from_file.hu.size());
    for (std::size_t n = 0; n < warped.size(); ++n)
      ASSERT_EQ(from_warp.hu[n], from_file.hu[n]) << "voxel " << n << ", input type " << int(input);
    EXPECT_EQ(from_warp.hu_is_int16, from_file.hu_is_int16) << int(input);   // found in the rounding pass
    EXPECT_EQ(from_warp.geometry.dims, g.dims);
  }
  // Rounded to the nearest (ties to even) and clamped to 16 bits, as the file holds them.
  std::vector<float> int16 = warped;
  round_as_written(int16, VoxelType::Int16);
  EXPECT_EQ(int16[0], 10.0f);
  EXPECT_EQ(int16[1], -10.0f);
  EXPECT_EQ(int16[2], 32767.0f);
  EXPECT_EQ(int16[3], -32768.0f);
  EXPECT_FALSE(RenderVolume::from_hu(g, std::vector<float>(int16), nullptr).hu_is_int16);   // −32768: no snorm16
  int16[3] = -1000.0f;
  EXPECT_TRUE(RenderVolume::from_hu(g, std::vector<float>(int16), nullptr).hu_is_int16);
  EXPECT_TRUE(round_as_written(int16, VoxelType::Int16));
}

TEST(ViewsFromTheWarp, ARefusedLabelMapLeavesTheHuWithTheCaller) {
  // The run writes the deformed CT from the HU it handed over when the views fail: a label map the
  // renderer refuses must not take them with it.
  Geometry g;
  g.dims = {4, 3, 2};
  std::vector<float> hu(std::size_t(g.voxel_count()), 40.0f);
  Geometry other = g;
  other.dims = {4, 3, 3};
  const Volume off_grid(other, VoxelType::UInt8);
  EXPECT_THROW(RenderVolume::from_hu(g, std::move(hu), &off_grid, true), InputError);
  EXPECT_EQ(hu.size(), std::size_t(g.voxel_count()));
  Volume bad_id(g, VoxelType::Float32);
  bad_id.data<float>()[5] = 2.5f;
  EXPECT_THROW(RenderVolume::from_hu(g, std::move(hu), &bad_id, true), InputError);
  ASSERT_EQ(hu.size(), std::size_t(g.voxel_count()));
  EXPECT_EQ(hu[0], 40.0f);
  const RenderVolume v = RenderVolume::from_hu(g, std::move(hu), nullptr, true);
  EXPECT_EQ(v.hu.size(), std::size_t(g.voxel_count()));
}

TEST(ViewsFromTheWarp, ADeformedCtWithoutItsHuIsRefused) {
  // The run lends the warp's HU to the views; a CT built while they are away must not be zeros.
  WarpedCase w;
  w.output_grid.dims = {4, 4, 4};
  w.ct = Volume(w.output_grid, VoxelType::Int16);
  EXPECT_THROW(deformed_ct_volume(w), std::logic_error);
}

TEST(ViewsFromTheWarp, TheWarpsLabelsAreTakenAsTheyAreExceptTheReservedId) {
  // The run gives the views the warp's 16-bit labels directly, not through the deformed label map.
  Geometry g;
  g.dims = {3, 2, 2};
  const std::vector<float> hu(std::size_t(g.voxel_count()), -1000.0f);
  std::vector<uint16_t> ids(std::size_t(g.voxel_count()), 0);
  ids[3] = 250;
  ids[7] = 65534;
  const RenderVolume v = RenderVolume::from_hu(g, std::vector<float>(hu), std::vector<uint16_t>(ids), true);
  EXPECT_EQ(v.labels, ids);
  EXPECT_TRUE(RenderVolume::from_hu(g, std::vector<float>(hu), std::vector<uint16_t>{}, true).labels.empty());
  ids[5] = kExteriorAirLabel;   // reserved for air outside the body
  std::vector<float> kept = hu;
  std::vector<uint16_t> kept_ids = ids;
  EXPECT_THROW(RenderVolume::from_hu(g, std::move(kept), std::move(kept_ids), true), InputError);
  EXPECT_EQ(kept.size(), hu.size());   // refused before the HU were taken
  EXPECT_EQ(kept_ids, ids);            // and before the labels were
  EXPECT_THROW(RenderVolume::from_hu(g, std::vector<float>(hu), std::vector<uint16_t>(5, 0), true),
               std::invalid_argument);
}

TEST(ViewsFromTheWarp, ValuesForAnotherGridAreRefused) {
  Geometry g;
  g.dims = {4, 4, 4};
  EXPECT_THROW(RenderVolume::from_hu(g, std::vector<float>(63), nullptr), std::invalid_argument);
}

}  // namespace
}  // namespace pneumo
