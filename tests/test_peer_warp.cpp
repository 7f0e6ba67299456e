// The peers' warp case (bench/suite/peer_warp.h): pneumo must rebuild exactly the mesh and the lift that
// ../shared/peers/vtk_tetwarp.py builds, or the voxel-by-voxel comparison with VTK and ITK compares nothing.
// Expected values below are worked by hand from the script's listing (tet_mesh() and lift()).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>

#include "io/volume_io.h"
#include "io_test_support.h"
#include "suite/peer_warp.h"

using namespace pneumo;
using namespace pneumo::bench;
using pneumo::testing_support::ScratchDir;

namespace {

/// The grid pneumo reads from the script's phantom.mhd: identity TransformMatrix, i.e. LPS axes, so RAS direction
/// diag(-1,-1,1) and the file's Offset with x and y negated.
Geometry peer_grid(Index3 dims, Vec3 spacing, Vec3 file_offset) {
  Geometry g;
  g.dims = dims;
  g.spacing_mm = spacing;
  g.direction = Vec3(-1.0, -1.0, 1.0).asDiagonal();
  g.origin_mm = file_offset.cwiseProduct(Vec3(-1.0, -1.0, 1.0));
  return g;
}

std::vector<float> random_ct(const Geometry& g, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> hu(-1000, 1500);   // whole HU, as the int16 phantom holds
  std::vector<float> v(std::size_t(g.voxel_count()));
  for (auto& x : v) x = float(hu(rng));
  return v;
}

PeerLift lift_at(Vec3 center, double wall_y, double amp) {
  PeerLift l;
  l.body_center_mm = center;
  l.anterior_inner_wall_y_mm = wall_y;
  l.amp_mm = amp;
  return l;
}

}  // namespace

TEST(PeerWarp, MeshHasTheScriptsNodesAndTetrahedraInItsOrder) {
  // 17×17×9 voxels, a node every 8: ceil(16/8)+1 = 3 nodes on x and y, ceil(8/8)+1 = 2 on z; 2×2×1 cubes.
  const Geometry g = peer_grid({17, 17, 9}, {0.7, 0.7, 1.0}, {0, 0, 0});
  const PeerWarpCase c = make_peer_warp_case(g, random_ct(g, 1), 8, lift_at({0, 0, 0}, 0, 0.0));
  ASSERT_EQ(c.mesh.rest_ijk.size(), 18u);
  ASSERT_EQ(c.mesh.tets.size(), 20u);   // 5 per cube
  EXPECT_EQ(c.mesh.rest_ijk[1], Vec3(8, 0, 0));
  EXPECT_EQ(c.mesh.rest_ijk[3], Vec3(0, 8, 0));
  EXPECT_EQ(c.mesh.rest_ijk[9], Vec3(0, 0, 8));
  // Node id i + 3(j + 3k). Tetrahedron 0: type 0 in cube (0,0,0), even, pattern A (1,0,3,5) -> nodes 1, 0, 4, 10.
  EXPECT_EQ(c.mesh.tets[0], (std::array<int32_t, 4>{1, 0, 4, 10}));
  // Tetrahedron 1: type 0 in the next cube, k fastest then j: cube (0,1,0), odd, pattern B (0,1,2,4) from node 3.
  EXPECT_EQ(c.mesh.tets[1], (std::array<int32_t, 4>{3, 4, 6, 12}));
  // Tetrahedron 4: type 1 (A: 2,0,6,3; B: 3,1,7,2) in cube (0,0,0) -> nodes 3, 0, 12, 4.
  EXPECT_EQ(c.mesh.tets[4], (std::array<int32_t, 4>{3, 0, 12, 4}));
  // The tetrahedra tile the box exactly: their volumes add up to 16×16×8 index units.
  double volume = 0;
  for (const auto& t : c.mesh.tets) {
    const Vec3 a = c.mesh.rest_ijk[t[0]];
    volume += std::abs((c.mesh.rest_ijk[t[1]] - a).cross(c.mesh.rest_ijk[t[2]] - a).dot(c.mesh.rest_ijk[t[3]] - a)) / 6;
  }
  EXPECT_NEAR(volume, 16.0 * 16.0 * 8.0, 1e-9);
}

TEST(PeerWarp, LiftIsTheScriptsInTheFilesFrame) {
  const PeerLift l = lift_at({100, 50, 60}, 40.0, 30.0);
  // On the bump's centre line: s = (y - (40 - 30)) / 110, w = 1 - s²(3 - 2s).
  EXPECT_DOUBLE_EQ(l.displacement_mm({100, 10, 60}).y(), -30.0);              // s = 0: full lift
  EXPECT_DOUBLE_EQ(l.displacement_mm({100, 0, 60}).y(), -30.0);               // s clamped at 0
  EXPECT_NEAR(l.displacement_mm({100, 65, 60}).y(), -15.0, 1e-12);            // s = 1/2: w = 1/2
  EXPECT_DOUBLE_EQ(l.displacement_mm({100, 120, 60}).y(), 0.0);               // s = 1: none
  EXPECT_NEAR(l.displacement_mm({170, 10, 60}).y(), -30.0 * std::exp(-0.5), 1e-12);   // one σ (70 mm) on x
  EXPECT_NEAR(l.displacement_mm({100, 10, 140}).y(), -30.0 * std::exp(-0.5), 1e-12);  // one σ (80 mm) on z
  EXPECT_EQ(l.displacement_mm({123, 10, 77}).x(), 0.0);
  EXPECT_EQ(l.displacement_mm({123, 10, 77}).z(), 0.0);

  // A node where the lift is full moves -30 mm along the file's +y, which is +j: -30/0.7 voxels on j, none on i, k.
  const Geometry g = peer_grid({17, 17, 9}, {0.7, 0.7, 1.0}, {5.0, 4.4, -3.0});
  // Node (1,1,1) sits at file point (5 + 8·0.7, 4.4 + 8·0.7, -3 + 8) = (10.6, 10, 5).
  const PeerWarpCase c = make_peer_warp_case(g, random_ct(g, 2), 8, lift_at({10.6, 0, 5}, 40.0, 30.0));
  const Vec3 d = c.mesh.disp_ijk[1 + 3 * (1 + 3 * 1)];
  EXPECT_NEAR(d.y(), -30.0 / 0.7, 1e-9);
  EXPECT_EQ(d.x(), 0.0);
  EXPECT_EQ(d.z(), 0.0);
  EXPECT_EQ(c.inverted_tets, 0);
}

TEST(PeerWarp, NoLiftGivesTheInputBitForBit) {
  const Geometry g = peer_grid({25, 17, 17}, {0.7, 0.7, 1.0}, {0, 0, 0});
  const std::vector<float> ct = random_ct(g, 3);
  const PeerWarpCase c = make_peer_warp_case(g, ct, 8, lift_at({8, 5, 8}, 2.0, 0.0));
  const WarpResult r = warp_cpu(c.mesh, c.source(), c.box, WarpOptions{});
  EXPECT_EQ(r.carried_voxels, g.voxel_count());
  EXPECT_EQ(r.ct_hu, ct);
}

TEST(PeerWarp, WritesTheVolumesTheComparisonReads) {
  ScratchDir dir;
  const Geometry g = peer_grid({33, 33, 17}, {0.7, 0.7, 1.0}, {0, 0, 0});
  const std::vector<float> ct = random_ct(g, 4);
  Volume phantom(g, VoxelType::Int16);
  for (std::size_t n = 0; n < ct.size(); ++n) phantom.data<int16_t>()[n] = int16_t(ct[n]);
  write_volume(phantom, dir.file("phantom.mhd"));
  // A lift of 6 mm whose bump is centred on the box: every node moves, none inverts.
  std::ofstream(dir.file("phantom.json")) << R"({"body_center": [11.2, 11.2, 8.0], "anterior_inner_wall_y": 12.0})";

  PeerWarpOptions opt;
  opt.data_dir = dir.path().string();
  opt.amp_mm = 6.0;
  opt.devices = {"cpu"};
  const nlohmann::json doc = run_peer_warp(opt);
  EXPECT_EQ(doc["tets"].get<int64_t>(), 5 * 4 * 4 * 2);
  EXPECT_EQ(doc["inverted_tets"].get<int64_t>(), 0);

  // What was written is what the warp computes on the same case.
  const PeerWarpCase c = make_peer_warp_case(read_volume(dir.file("phantom.mhd")).geometry(), ct, 8,
                                             lift_at({11.2, 11.2, 8.0}, 12.0, 6.0));
  const WarpResult r = warp_cpu(c.mesh, c.source(), c.box, WarpOptions{});
  const Volume warped = read_volume(dir.file("pneumo/warped_cpu.mhd"));
  ASSERT_EQ(warped.type(), VoxelType::Float32);
  EXPECT_EQ(std::vector<float>(warped.data<float>(), warped.data<float>() + warped.voxel_count()), r.ct_hu);
  const Volume outcome = read_volume(dir.file("pneumo/outcome.mhd"));
  EXPECT_EQ(outcome.value(0), double(uint8_t(r.outcome[0])));
  EXPECT_NE(r.ct_hu, ct);   // the lift moved something

  // The field: float32 × 3 per voxel; sources lie posterior (+y in the file) by at most the lift, never sideways.
  std::ifstream raw(dir.file("pneumo/disp_pneumo.raw"), std::ios::binary);
  std::vector<float> field(std::size_t(3 * g.voxel_count()));
  raw.read(reinterpret_cast<char*>(field.data()), std::streamsize(field.size() * sizeof(float)));
  ASSERT_TRUE(raw.good());
  float largest = 0;
  for (std::size_t n = 0; n < field.size(); n += 3) {
    EXPECT_NEAR(field[n], 0.0f, 1e-5f);       // barycentric sums of equal coordinates: rounding only
    EXPECT_NEAR(field[n + 2], 0.0f, 1e-5f);
    EXPECT_GE(field[n + 1], -1e-5f);
    EXPECT_LE(field[n + 1], 6.0f + 1e-4f);
    largest = std::max(largest, field[n + 1]);
  }
  EXPECT_GT(largest, 1.0f);
  EXPECT_TRUE(std::filesystem::exists(dir.file("pneumo/peer_warp.json")));
}
