// Automatic roles (host/roles/auto_roles.h) on a synthetic torso: an elliptic cylinder of fat
// (150 x 100 mm semi-axes) around a soft-tissue core, a bony "spine" at the back, a gas pocket in
// the "bowel" and a CT table 15 mm below the body. The wall must be a shell of the given thickness
// in front and at the sides, the back fixed, the core viscera, the table and the air other, the same
// whatever the grid's spacing and storage order.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>

#include "core/progress.h"
#include "phantom/phantom.h"
#include "pipeline/scene_stages.h"
#include "roles/roles.h"
#include "scene/scene.h"

using namespace pneumo;

namespace {

constexpr double kGasZ = 36.0;

double sq(double v) { return v * v; }

bool in_torso(const Vec3& w) { return sq(w.x() / 150) + sq(w.y() / 100) <= 1.0; }
bool in_spine(const Vec3& w) { return std::abs(w.x()) <= 20 && w.y() >= -80 && w.y() <= -30; }

double torso_hu(const Vec3& w) {
  if (w.y() >= -125 && w.y() <= -115 && std::abs(w.x()) <= 180) return 300;   // table, apart from the body
  if (!in_torso(w)) return -1000;
  if (in_spine(w)) return 700;
  if (sq(w.x() - 40) + sq(w.y() - 10) + sq(w.z() - kGasZ) <= sq(15)) return -1000;   // bowel gas
  if (sq(w.x() / 110) + sq(w.y() / 60) <= 1.0) return 40;                            // soft-tissue core
  return -100;                                                                       // fat
}

Volume torso(const Geometry& g) {
  Volume v(g, VoxelType::Int16);
  for (int64_t k = 0; k < g.dims[2]; ++k)
    for (int64_t j = 0; j < g.dims[1]; ++j)
      for (int64_t i = 0; i < g.dims[0]; ++i)
        v.data<int16_t>()[g.linear_index(i, j, k)] = int16_t(torso_hu(g.to_world(Vec3(i, j, k))));
  return v;
}

Geometry grid(const Index3& dims, const Vec3& spacing, const Mat3& dir, const Vec3& origin) {
  Geometry g;
  g.dims = dims;
  g.spacing_mm = spacing;
  g.direction = dir;
  g.origin_mm = origin;
  return g;
}

/// x -200..200, y -140..140, z 0..72 mm on anisotropic voxels (4 x 2.5 x 8 mm), RAS.
const Geometry kAniso = grid({101, 113, 10}, Vec3(4, 2.5, 8), Mat3::Identity(), Vec3(-200, -140, 0));
/// The same box on 5 mm voxels (z 0..45).
const Geometry kIso = grid({81, 57, 10}, Vec3(5, 5, 5), Mat3::Identity(), Vec3(-200, -140, 0));

Scene auto_scene(double thickness_mm = 30.0, double max_angle_deg = 100.0) {
  Scene s = default_scene();
  s.roles.source = RoleSource::Auto;
  s.roles.auto_wall_thickness_mm = thickness_mm;
  s.roles.auto_wall_max_angle_deg = max_angle_deg;
  // The rules on the grid as it is: auto padding (roles/auto_pad.h) has its own tests.
  s.roles.pad_anterior_mm = 0.0;
  s.roles.pad_lateral_mm = 0.0;
  return s;
}

/// On kIso: a "bladder" (label 21, a 12 mm sphere at x = 0, y = −10 mm, z = 22.5 mm) and, with
/// `loop`, a "sigmoid loop" in front of its upper part (label 20, a 7 mm sphere at y = 30 mm).
Volume bladder_labels(bool loop) {
  Volume labels(kIso, VoxelType::UInt8);
  for (int64_t n = 0; n < kIso.voxel_count(); ++n) {
    const Vec3 w = kIso.to_world(Vec3(n % 81, (n / 81) % 57, n / (81 * 57)));
    if ((w - Vec3(0, -10, 22.5)).norm() <= 12) labels.data<uint8_t>()[n] = 21;
    if (loop && (w - Vec3(0, 30, 22.5)).norm() <= 7) labels.data<uint8_t>()[n] = 20;
  }
  return labels;
}

Role role_at(const RoleVolume& rv, const Vec3& w) {
  const Vec3 idx = rv.geometry.to_index(w);
  return rv.role[rv.geometry.linear_index(std::lround(idx.x()), std::lround(idx.y()), std::lround(idx.z()))];
}

}  // namespace

TEST(RolesAuto, TorsoHasAWallShellAFixedBackVisceraInsideAndAirOutside) {
  Progress::set_enabled(false);
  const RoleVolume rv = assign_roles(auto_scene(), torso(kAniso), nullptr);
  const double z = kGasZ;
  struct Probe { Vec3 w; Role role; const char* what; };
  const Probe probes[] = {
      {{0, 90, z}, Role::Wall, "anterior shell, 10 mm deep"},
      {{140, 0, z}, Role::Wall, "right flank, 10 mm deep"},
      {{-140, 0, z}, Role::Wall, "other flank"},
      {{0, 0, z}, Role::Viscera, "centre"},
      {{-50, 20, z}, Role::Viscera, "core"},
      {{0, 50, z}, Role::Viscera, "50 mm deep in front"},
      {{40, 10, z}, Role::Viscera, "bowel gas (a hole filled)"},
      {{0, -55, z}, Role::Fixed, "spine"},
      {{0, -90, z}, Role::Fixed, "behind the spine"},
      {{-80, -50, z}, Role::Fixed, "posterior flank behind the spine's front"},
      {{80, -50, z}, Role::Fixed, "other posterior flank"},
      {{0, -120, z}, Role::Other, "table (not the largest component)"},
      {{0, 120, z}, Role::Other, "air in front"},
      {{190, 0, z}, Role::Other, "air at the side"},
      {{0, 0, 0}, Role::Viscera, "centre of the bottom slice: the grid's face is no skin"},
      {{0, 0, 72}, Role::Viscera, "centre of the top slice"},
  };
  for (const Probe& p : probes) EXPECT_EQ(role_at(rv, p.w), p.role) << p.what << " at " << p.w.transpose();
  EXPECT_EQ(rv.count(Role::Wall) + rv.count(Role::Viscera) + rv.count(Role::Fixed) + rv.count(Role::Other),
            kAniso.voxel_count());
}

/// The rules written out directly for one slice (brute-force depth, angle about the centroid) must
/// agree with the fast implementation voxel for voxel, for two thickness/angle settings, on an
/// anisotropic grid. Voxels within 1e-3 mm of the thickness or 0.01° of the angle may go either way.
TEST(RolesAuto, ShellMatchesBruteForceDepthAndAngleOnAnisotropicVoxels) {
  Progress::set_enabled(false);
  const Volume ct = torso(kAniso);
  const int64_t k = 4;   // z = 32 mm, through the gas pocket
  std::vector<Vec3> inside, outside;
  for (int64_t j = 0; j < kAniso.dims[1]; ++j)
    for (int64_t i = 0; i < kAniso.dims[0]; ++i) {
      const Vec3 w = kAniso.to_world(Vec3(i, j, k));
      (in_torso(w) ? inside : outside).push_back(w);
    }
  Vec3 centroid = Vec3::Zero();
  for (const Vec3& w : inside) centroid += w;
  centroid /= double(inside.size());
  const double spine_front_y = -30.0;   // a voxel centre on this grid (y = -140 + 2.5 j)

  for (const auto& [thickness, angle] : {std::pair{30.0, 100.0}, std::pair{15.0, 80.0}}) {
    const RoleVolume rv = assign_roles(auto_scene(thickness, angle), ct, nullptr);
    int64_t checked = 0, wall = 0;
    for (const Vec3& w : inside) {
      double depth = std::numeric_limits<double>::infinity();
      for (const Vec3& o : outside) depth = std::min(depth, (w - o).norm());
      const Vec3 d = w - centroid;
      const double from_anterior_deg = std::atan2(std::abs(d.x()), d.y()) * 180.0 / M_PI;
      if (std::abs(depth - thickness) < 1e-3 || std::abs(from_anterior_deg - angle) < 1e-2) continue;
      Role expected;
      if (in_spine(w) || w.y() <= spine_front_y + 1e-9) expected = Role::Fixed;   // bone, then the back
      else if (depth <= thickness) expected = from_anterior_deg <= angle ? Role::Wall : Role::Fixed;
      else expected = Role::Viscera;
      ASSERT_EQ(role_at(rv, w), expected) << "at " << w.transpose() << " depth " << depth << " angle "
                                          << from_anterior_deg << " (thickness " << thickness << ")";
      ++checked;
      wall += expected == Role::Wall;
    }
    EXPECT_GT(checked, 4000);
    EXPECT_GT(wall, 300);
  }
}

TEST(RolesAuto, StorageOrderDoesNotChangeTheRoles) {
  Progress::set_enabled(false);
  const Scene s = auto_scene();
  const RoleVolume ras = assign_roles(s, torso(kIso), nullptr);
  // LPS: i towards the left, j towards the back.
  const Geometry lps = grid({81, 57, 10}, Vec3(5, 5, 5), Vec3(-1, -1, 1).asDiagonal(), Vec3(200, 140, 0));
  // i towards anterior, j towards superior, k towards the left.
  Mat3 dir;
  dir << 0, 0, -1,  //
      1, 0, 0,      //
      0, 1, 0;
  const Geometry permuted = grid({57, 10, 81}, Vec3(5, 5, 5), dir, Vec3(200, -140, 0));
  for (const Geometry& g : {lps, permuted}) {
    const RoleVolume other = assign_roles(s, torso(g), nullptr);
    int64_t differ = 0;
    for (int64_t k = 0; k < kIso.dims[2]; ++k)
      for (int64_t j = 0; j < kIso.dims[1]; ++j)
        for (int64_t i = 0; i < kIso.dims[0]; ++i) {
          const Vec3 w = kIso.to_world(Vec3(i, j, k));
          differ += role_at(ras, w) != role_at(other, w);
        }
    EXPECT_EQ(differ, 0) << g.orientation_code();
    for (Role r : {Role::Wall, Role::Viscera, Role::Fixed}) EXPECT_EQ(other.count(r), ras.count(r)) << role_name(r);
  }
}

TEST(RolesAuto, ListedLabelsKeepTheirRolesUnlistedOnesFollowTheRules) {
  Progress::set_enabled(false);
  const Volume ct = torso(kIso);
  Volume labels(kIso, VoxelType::UInt8);
  const auto paint = [&](const Vec3& c, double r, uint8_t id) {
    for (int64_t n = 0; n < kIso.voxel_count(); ++n) {
      const Vec3 w = kIso.to_world(Vec3(n % 81, (n / 81) % 57, n / (81 * 57)));
      if ((w - c).norm() <= r) labels.data<uint8_t>()[n] = id;
    }
  };
  paint({0, 85, 22.5}, 12, 5);    // an organ label in the wall's shell
  paint({-40, -10, 22.5}, 15, 88);  // a fixed label inside
  paint({50, 30, 22.5}, 12, 3);   // a label in no list
  Scene s = auto_scene();
  s.roles.viscera_labels = {5};
  s.roles.fixed_labels = {88};
  const RoleVolume rv = assign_roles(s, ct, &labels);
  int64_t n5 = 0, n88 = 0, n3 = 0;
  for (int64_t n = 0; n < kIso.voxel_count(); ++n) {
    EXPECT_EQ(rv.label[n], labels.data<uint8_t>()[n]);
    switch (rv.label[n]) {
      case 5: EXPECT_EQ(rv.role[n], Role::Viscera); ++n5; break;
      case 88: EXPECT_EQ(rv.role[n], Role::Fixed); ++n88; break;
      case 3: EXPECT_EQ(rv.role[n], Role::Viscera); ++n3; break;   // the core: viscera by the rules
      default: break;
    }
  }
  EXPECT_GT(n5, 20);
  EXPECT_GT(n88, 20);
  EXPECT_GT(n3, 20);
  // Without auto_use_labels the organ in the shell is wall like its surroundings.
  s.roles.auto_use_labels = false;
  const RoleVolume plain = assign_roles(s, ct, &labels);
  EXPECT_EQ(role_at(plain, {0, 85, 22.5}), Role::Wall);
  EXPECT_EQ(role_at(plain, {-40, -10, 22.5}), Role::Viscera);
}

TEST(RolesAuto, DeepTissueLateralToThePelvisIsFixed) {
  Progress::set_enabled(false);
  // Two "hip bones" 90 mm either side of the midline inside a wide body: the deep tissue lateral to
  // them (beyond the shell) is not abdominal, the tissue between them is.
  Geometry g = grid({121, 61, 6}, Vec3(4, 4, 4), Mat3::Identity(), Vec3(-240, -120, 0));
  Volume ct(g, VoxelType::Int16);
  for (int64_t n = 0; n < g.voxel_count(); ++n) {
    const Vec3 w = g.to_world(Vec3(n % 121, (n / 121) % 61, n / (121 * 61)));
    double hu = -1000;
    if (sq(w.x() / 220) + sq(w.y() / 100) <= 1) hu = 40;
    if (std::abs(std::abs(w.x()) - 90) <= 6 && std::abs(w.y()) <= 30) hu = 600;
    ct.data<int16_t>()[n] = int16_t(hu);
  }
  const RoleVolume rv = assign_roles(auto_scene(), ct, nullptr);
  EXPECT_EQ(role_at(rv, {150, 0, 8}), Role::Fixed);    // 60 mm lateral to the bone, 70 mm deep
  EXPECT_EQ(role_at(rv, {-150, 0, 8}), Role::Fixed);
  EXPECT_EQ(role_at(rv, {0, 0, 8}), Role::Viscera);    // between the bones
  EXPECT_EQ(role_at(rv, {130, 40, 8}), Role::Viscera); // a row without bone, 38 mm deep
  EXPECT_EQ(role_at(rv, {212, 0, 8}), Role::Wall);     // the shell stays wall
}

// The phantom knows its wall (skin, subcutaneous fat, wall muscle labels): the automatic rules must
// find it, from the CT alone and from the CT with the organ and bone labels. The shell is a uniform
// 30 mm and the phantom's wall is not, so agreement is high but not total.
TEST(RolesAuto, FindsThePhantomsWallWithoutWallLabels) {
  Progress::set_enabled(false);
  const Phantom ph = make_phantom(PhantomSize::Small);
  const Scene labelled = parse_scene(nlohmann::json::parse(phantom_scene_json(PhantomSize::Small)), "");
  const std::vector<int> wall_ids = labelled.roles.wall_labels;
  // The lungs (11, 14) are wall too: compliant (roles.compliant_lungs), whether labelled or found by density.
  const auto is_wall_label = [&](int id) {
    return id == 11 || id == 14 || std::find(wall_ids.begin(), wall_ids.end(), id) != wall_ids.end();
  };
  constexpr int kDiaphragm = 207;   // wall by label, but deep inside: no shell can reach it
  for (const bool use_labels : {false, true}) {
    Scene s = labelled;
    s.roles.source = RoleSource::Auto;
    s.roles.wall_labels.clear();
    s.roles.auto_use_labels = use_labels;
    const RoleVolume rv = assign_roles(s, ph.ct, &ph.labels);
    const Geometry& g = rv.geometry;
    // Precision: auto-wall voxels the phantom calls wall. Recall: the phantom's abdominal wall clearly
    // in front of the spine (y > 40 mm: its wall also wraps the back, which is fixed here) and below
    // the heart (z < 100 mm: with the heart and sternum labelled fixed the thorax is held, rightly)
    // found as wall.
    int64_t auto_wall = 0, auto_wall_true = 0, front_wall = 0, front_wall_found = 0;
    for (int64_t n = 0; n < g.voxel_count(); ++n) {
      const int id = rv.label[n];
      const bool truth = is_wall_label(id);
      if (rv.role[n] == Role::Wall) {
        ++auto_wall;
        auto_wall_true += truth;
      }
      const Vec3 w = g.to_world(Vec3(double(n % g.dims[0]), double((n / g.dims[0]) % g.dims[1]),
                                     double(n / (g.dims[0] * g.dims[1]))));
      if (truth && id != kDiaphragm && w.y() > 40 && w.z() < 100) {
        ++front_wall;
        front_wall_found += rv.role[n] == Role::Wall;
      }
    }
    const double precision = double(auto_wall_true) / double(auto_wall);
    const double recall = double(front_wall_found) / double(front_wall);
    std::printf("phantom wall (%s): precision %.3f, anterior recall %.3f\n", use_labels ? "organ labels" : "CT only",
                precision, recall);
    EXPECT_GT(precision, 0.9);
    EXPECT_GT(recall, 0.9);
  }
}

TEST(RolesAuto, TissueInFrontOfThePrevesicalLabelsJoinsTheWall) {
  // Compared: the torso with a "bladder" (label 21, a 12 mm sphere at x = 0, y = −10 mm, z = 22.5 mm, listed
  // as wall) and roles.auto_prevesical_labels = [21], against rules 5b and 6b: the core tissue anterior to the
  // sphere in its own columns (x = 0, y = 30 mm: between it and the shell) becomes wall; so does the tissue
  // beside those columns (x = 40 and 60 mm) in slices from the sphere's top (z = 34.5 mm) down, anterior to its back
  // (y = −22 mm in its mid slice), and below the sphere (z = 5 mm: its lowest slice's back); above its top
  // (z = 40 mm) and behind it (y = −40 mm) the tissue stays as without the key; without the key it is all
  // viscera.
  Progress::set_enabled(false);
  const Volume ct = torso(kIso);
  const Volume labels = bladder_labels(false);
  Scene s = auto_scene();
  s.roles.wall_labels = {21};
  const RoleVolume without = assign_roles(s, ct, &labels);
  s.roles.auto_prevesical_labels = {21};
  const RoleVolume with = assign_roles(s, ct, &labels);
  EXPECT_EQ(role_at(without, {0, 30, 22.5}), Role::Viscera);
  EXPECT_EQ(role_at(with, {0, 30, 22.5}), Role::Wall);
  EXPECT_EQ(role_at(without, {40, 30, 22.5}), Role::Viscera);
  EXPECT_EQ(role_at(with, {40, 30, 22.5}), Role::Wall);
  EXPECT_EQ(role_at(with, {60, 0, 22.5}), Role::Wall);
  EXPECT_EQ(role_at(with, {60, 0, 5}), Role::Wall);
  EXPECT_EQ(role_at(without, {40, 30, 40}), Role::Viscera);
  EXPECT_EQ(role_at(with, {40, 30, 40}), Role::Viscera);
  EXPECT_EQ(role_at(with, {0, -40, 22.5}), role_at(without, {0, -40, 22.5}));
  EXPECT_EQ(role_at(with, {0, -10, 22.5}), Role::Wall);   // the sphere itself, by its label
}

TEST(RolesAuto, TissueBetweenTheBladderAndALoopInFrontOfItStaysPeritoneal) {
  // The torso and bladder of the test above, with a "sigmoid loop" (label 20, listed as viscera, a 7 mm
  // sphere at x = 0, y = 30 mm, z = 22.5 mm) in front of the bladder's upper part. Where an intraperitoneal
  // organ lies in front of the bladder in a column, the peritoneum lies in front of the bladder there: the
  // tissue between the bladder (front y = 2 mm) and the loop stays viscera (y = 12 mm), what lies in front
  // of the loop still joins the wall (y = 50 mm), and a column beside the loop (x = 40 mm) is as before.
  Progress::set_enabled(false);
  const Volume ct = torso(kIso);
  const Volume labels = bladder_labels(true);
  Scene s = auto_scene();
  s.roles.wall_labels = {21};
  s.roles.viscera_labels = {20};
  s.roles.auto_prevesical_labels = {21};
  const RoleVolume rv = assign_roles(s, ct, &labels);
  EXPECT_EQ(role_at(rv, {0, 30, 22.5}), Role::Viscera);   // the loop, by its label
  EXPECT_EQ(role_at(rv, {0, 12, 22.5}), Role::Viscera);
  EXPECT_EQ(role_at(rv, {0, 50, 22.5}), Role::Wall);
  EXPECT_EQ(role_at(rv, {40, 12, 22.5}), Role::Wall);
  EXPECT_EQ(role_at(rv, {0, -10, 22.5}), Role::Wall);   // the bladder, by its label
}
