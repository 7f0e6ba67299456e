// The port ranking (plan/port_ranking.h) on a box world whose answers are geometry: a wall slab over
// a gas layer, a spherical target under it, a plate of another organ shading part of it; and the
// distance map it reads against brute force.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/error.h"
#include "plan/distance_map.h"
#include "plan/port_ranking.h"

namespace pneumo {
namespace {

constexpr uint16_t kGas = 250, kWall = 200, kTarget = 5, kPlate = 7;

/// 60³ voxels of 2 mm, RAS identity (j anterior): air for j ≥ 45, a wall slab (label 200) j 40–44,
/// gas j 32–39 over i, k in [10, 50), tissue below; the target a sphere of radius 4 voxels centred at
/// (30, 28, 30), touching the gas from below; a plate (label 7) in the gas over i 12–27, k 22–37, j 33–37.
struct BoxWorld {
  Geometry g;
  std::vector<uint16_t> labels;
  std::vector<float> hu;
  BoxWorld() {
    g.dims = {60, 60, 60};
    g.spacing_mm = Vec3::Constant(2.0);
    labels.assign(std::size_t(g.voxel_count()), 0);
    hu.assign(std::size_t(g.voxel_count()), 40.0f);
    for (int64_t k = 0; k < 60; ++k)
      for (int64_t j = 0; j < 60; ++j)
        for (int64_t i = 0; i < 60; ++i) {
          const std::size_t n = std::size_t(g.linear_index(i, j, k));
          const bool cavity = i >= 10 && i < 50 && k >= 10 && k < 50;
          if (j >= 45) labels[n] = 0, hu[n] = -1000.0f;
          else if (j >= 40) labels[n] = kWall;
          else if (j >= 32 && cavity) labels[n] = kGas, hu[n] = -1000.0f;
          const double r2 = double((i - 30) * (i - 30) + (j - 28) * (j - 28) + (k - 30) * (k - 30));
          if (r2 <= 16.0) labels[n] = kTarget;
          if (i >= 12 && i < 28 && k >= 22 && k < 38 && j >= 33 && j < 38) labels[n] = kPlate, hu[n] = 40.0f;
        }
  }
  Vec3 voxel(double i, double j, double k) const { return g.to_world(Vec3(i, j, k)); }
};

PortRankOptions options() {
  PortRankOptions o;
  o.target_label = kTarget;
  o.gas_label = kGas;
  o.grid_mm = 8.0;   // every 4th voxel: columns at i, k = 2, 6, 10, …
  return o;
}

const PortCandidate* candidate_at(const PortRanking& r, const Vec3& skin_xz) {
  for (const PortCandidate& c : r.candidates)
    if (std::abs(c.skin_mm.x() - skin_xz.x()) < 1e-6 && std::abs(c.skin_mm.z() - skin_xz.z()) < 1e-6) return &c;
  return nullptr;
}

TEST(PortRanking, TermsFollowTheirCitedRanges) {
  EXPECT_DOUBLE_EQ(distance_term(180.0), 1.0);   // half a 360 mm instrument inside (Emam 2000)
  EXPECT_DOUBLE_EQ(distance_term(120.0), 0.5);
  EXPECT_DOUBLE_EQ(distance_term(60.0), 0.0);
  EXPECT_DOUBLE_EQ(distance_term(300.0), 0.0);
  EXPECT_DOUBLE_EQ(elevation_term(45.0), 1.0);   // 30–60° (Hanna 1997)
  EXPECT_DOUBLE_EQ(elevation_term(15.0), 0.5);
  EXPECT_DOUBLE_EQ(elevation_term(90.0), 0.0);
  EXPECT_DOUBLE_EQ(manipulation_term(60.0), 1.0);   // 45–75° (Hanna 1997)
  EXPECT_DOUBLE_EQ(manipulation_term(30.0), 0.5);
  EXPECT_DOUBLE_EQ(manipulation_term(90.0), 0.5);
  EXPECT_DOUBLE_EQ(spacing_term(50.0), 1.0);
  EXPECT_DOUBLE_EQ(spacing_term(35.0), 0.5);
  EXPECT_DOUBLE_EQ(clearance_term(10.0), 0.5);
  EXPECT_DOUBLE_EQ(clearance_term(40.0), 1.0);
}

TEST(PortRanking, ThePortOverTheTargetReachesItThroughTheWallAndTheGas) {
  const BoxWorld w;
  const PortRanking r = rank_ports(w.labels.data(), w.hu.data(), w.g, options());
  ASSERT_EQ(r.wall_layer_labels, std::vector<int>{kWall});   // every trocar crosses the slab, nothing else
  EXPECT_NEAR(r.target_centroid_mm.x(), 60.0, 1e-9);
  EXPECT_NEAR(r.target_centroid_mm.y(), 56.0, 1e-9);
  // The column over the centre: skin at j = 44, gas from j = 39 (the wall 5 voxels, 10 mm, to within
  // the half-voxel march), the target's top at j = 32 (24 mm below the skin), straight down: 90°.
  const PortCandidate* c = candidate_at(r, w.voxel(30, 44, 30));
  ASSERT_NE(c, nullptr);
  ASSERT_TRUE(c->feasible()) << port_problem_name(c->problem);
  EXPECT_NEAR(c->wall_mm, 10.0, 1.01);
  EXPECT_NEAR(c->skin_to_target_mm, 24.0, 1.01);
  EXPECT_NEAR(c->elevation_deg, 90.0, 1e-6);
  // The plate's edge (i = 27) is 3 voxels from the path's column: 6 mm where the path passes it.
  EXPECT_NEAR(c->clearance_mm, 6.0, 0.35);   // 6.3 mm one voxel higher, where the march may sample last
  EXPECT_EQ(c->nearest_label, kPlate);
  // The scope's tip 7 mm into the gas (half of its 14 mm) looks down on the sphere's cap that rises
  // into the gas, the only part of it any scope can see: all of it is in sight, and no candidate
  // sees more.
  ASSERT_GT(r.exposed_voxels, 0);
  EXPECT_DOUBLE_EQ(c->visible_fraction, double(r.exposed_voxels) / double(r.surface_voxels));
  EXPECT_DOUBLE_EQ(c->t_visibility, 1.0);
  // A 10° scope sees only the directions within 5° of its axis: part of the cap.
  PortRankOptions narrow = options();
  narrow.fov_deg = 10.0;
  const PortCandidate* n = candidate_at(rank_ports(w.labels.data(), w.hu.data(), w.g, narrow), w.voxel(30, 44, 30));
  ASSERT_NE(n, nullptr);
  EXPECT_GT(n->visible_fraction, 0.0);
  EXPECT_LT(n->visible_fraction, c->visible_fraction);
}

TEST(PortRanking, VisibilityCountsOnlyTheSurfaceInSight) {
  // The sphere alone in gas under the wall, all its surface facing the gas: from a point at distance
  // d from its centre a sphere of radius r shows the cap whose share of its area is (1 − r/d)/2,
  // never its far side.
  BoxWorld w;
  for (int64_t k = 0; k < 60; ++k)
    for (int64_t j = 0; j < 40; ++j)
      for (int64_t i = 0; i < 60; ++i) {
        const std::size_t n = std::size_t(w.g.linear_index(i, j, k));
        if (w.labels[n] != kTarget) w.labels[n] = kGas, w.hu[n] = -1000.0f;
      }
  const PortRanking r = rank_ports(w.labels.data(), w.hu.data(), w.g, options());
  const PortCandidate* c = candidate_at(r, w.voxel(30, 44, 30));
  ASSERT_NE(c, nullptr);
  ASSERT_TRUE(c->feasible()) << port_problem_name(c->problem);
  // The tip: 20 mm into the gas or halfway to the target, whichever is less (port_ranking.h).
  const double in_gas = c->skin_to_target_mm - c->wall_mm;
  const Vec3 eye = c->gas_entry_mm + std::min(20.0, 0.5 * in_gas) * Vec3(0, -1, 0);
  const double d = (eye - r.target_centroid_mm).norm();
  const double cap = 0.5 * (1.0 - 8.0 / d);
  // The samples are the surface voxels of a sphere 4 voxels in radius: within 0.05 of the cap's share
  // (0.246 against 0.233 here).
  EXPECT_NEAR(c->visible_fraction, cap, 0.05) << "tip " << d << " mm from the centre";
}

TEST(PortRanking, APlateInTheGasBlocksThePathsItShades) {
  const BoxWorld w;
  const PortRanking r = rank_ports(w.labels.data(), w.hu.data(), w.g, options());
  // Over the plate's middle every path to the target's exposed top crosses the plate.
  const PortCandidate* c = candidate_at(r, w.voxel(18, 44, 30));
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(c->problem, PortProblem::Blocked);
  EXPECT_EQ(c->blocking_label, kPlate);
  EXPECT_EQ(c->score, 0.0);
  // Outside the cavity's columns the path meets no gas within a trocar's reach.
  const PortCandidate* lateral = candidate_at(r, w.voxel(2, 44, 30));
  ASSERT_NE(lateral, nullptr);
  EXPECT_FALSE(lateral->feasible());
  // The order: feasible ports first, by score.
  bool seen_infeasible = false;
  for (std::size_t n = 0; n < r.candidates.size(); ++n) {
    if (!r.candidates[n].feasible()) seen_infeasible = true;
    else EXPECT_FALSE(seen_infeasible) << "a feasible port after an infeasible one";
    if (n > 0 && r.candidates[n].feasible()) {
      EXPECT_LE(r.candidates[n].score, r.candidates[n - 1].score);
    }
  }
}

TEST(PortRanking, ThePlateLowersTheVisibilityOfPortsThatLookPastIt) {
  const BoxWorld w;
  // The same world without the plate: every port sees at least as much of the target.
  BoxWorld open = w;
  for (auto& l : open.labels)
    if (l == kPlate) l = kGas;
  const PortRanking with = rank_ports(w.labels.data(), w.hu.data(), w.g, options());
  const PortRanking without = rank_ports(open.labels.data(), open.hu.data(), open.g, options());
  int lower = 0, compared = 0;
  for (const PortCandidate& c : with.candidates) {
    if (!c.feasible()) continue;
    const PortCandidate* o = candidate_at(without, c.skin_mm);
    ASSERT_NE(o, nullptr);
    ASSERT_TRUE(o->feasible());
    if ((o->aim_mm - c.aim_mm).norm() > 1e-9) continue;   // re-aimed round the plate: another axis
    EXPECT_LE(c.visible_fraction, o->visible_fraction + 1e-12);
    ++compared;
    if (c.visible_fraction < o->visible_fraction) ++lower;
  }
  EXPECT_GT(compared, 10);
  EXPECT_GT(lower, 0);
}

TEST(PortRanking, TriangulationMeasuresTheManipulationAngleAtTheTarget) {
  const BoxWorld w;
  PortRankOptions o = options();
  const Vec3 other = w.voxel(46, 44, 30);
  o.other_ports_mm = {other};
  const PortRanking r = rank_ports(w.labels.data(), w.hu.data(), w.g, o);
  const PortCandidate* c = candidate_at(r, w.voxel(30, 44, 30));
  ASSERT_NE(c, nullptr);
  ASSERT_TRUE(c->feasible());
  // The angle at the aim point between the two skin points, and their distance on the skin.
  const Vec3 a = (c->skin_mm - c->aim_mm).normalized(), b = (other - c->aim_mm).normalized();
  EXPECT_NEAR(c->manipulation_deg, std::acos(a.dot(b)) * 180.0 / M_PI, 1e-9);
  EXPECT_NEAR(c->spacing_mm, 32.0, 1e-9);
  EXPECT_NEAR(c->t_triangulation, spacing_term(32.0) * manipulation_term(c->manipulation_deg), 1e-12);
}

TEST(PortRanking, AThickWallIsNotCrossed) {
  const BoxWorld w;
  PortRankOptions o = options();
  o.max_wall_mm = 6.0;   // thinner than the 10 mm slab
  const PortRanking r = rank_ports(w.labels.data(), w.hu.data(), w.g, o);
  for (const PortCandidate& c : r.candidates) EXPECT_FALSE(c.feasible());
  EXPECT_EQ(candidate_at(r, w.voxel(30, 44, 30))->problem, PortProblem::WallTooThick);
}

TEST(PortRanking, AnAbsentTargetIsRefused) {
  const BoxWorld w;
  PortRankOptions o = options();
  o.target_label = 9;
  EXPECT_THROW(rank_ports(w.labels.data(), w.hu.data(), w.g, o), InputError);
  o.target_label = kGas;
  EXPECT_THROW(rank_ports(w.labels.data(), w.hu.data(), w.g, o), InputError);
}

TEST(DistanceMap, EqualsBruteForceOnAnAnisotropicGrid) {
  Geometry g;
  g.dims = {13, 9, 7};
  g.spacing_mm = Vec3(0.7, 1.3, 2.9);
  std::mt19937 rng(7);
  std::vector<uint8_t> mask(std::size_t(g.voxel_count()), 0);
  for (auto& m : mask) m = (rng() % 23) == 0;
  const std::vector<float> d = distance_to_mask_mm(mask, g);
  for (int64_t k = 0; k < g.dims[2]; ++k)
    for (int64_t j = 0; j < g.dims[1]; ++j)
      for (int64_t i = 0; i < g.dims[0]; ++i) {
        double best = std::numeric_limits<double>::infinity();
        for (int64_t c = 0; c < g.dims[2]; ++c)
          for (int64_t b = 0; b < g.dims[1]; ++b)
            for (int64_t a = 0; a < g.dims[0]; ++a)
              if (mask[std::size_t(g.linear_index(a, b, c))])
                best = std::min(best, std::hypot((a - i) * 0.7, (b - j) * 1.3, (c - k) * 2.9));
        EXPECT_NEAR(d[std::size_t(g.linear_index(i, j, k))], best, 1e-4 * (1.0 + best)) << i << " " << j << " " << k;
      }
}

TEST(DistanceMap, AnEmptyMaskIsInfinitelyFar) {
  Geometry g;
  g.dims = {4, 3, 2};
  const std::vector<float> d = distance_to_mask_mm(std::vector<uint8_t>(24, 0), g);
  for (float v : d) EXPECT_TRUE(std::isinf(v));
}

}  // namespace
}  // namespace pneumo
