// Attached interfaces (MeshOptions::attached_labels, solve/interface_tie.h): where the viscera lie
// on an organ listed as attached, no gas opens and the two stay bonded; the gas in front then
// pushes the viscera back against it instead of floating them. Checked on a layered box, 2 mm voxels,
// 4 mm cubes, along y from back to front: bone, an attached organ (label 7), viscera, a free front
// wall (label 202) held by bone at both sides, and air in front.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "core/error.h"
#include "core/progress.h"
#include "mesh/mesh.h"
#include "pipeline/scene_stages.h"
#include "scene/scene.h"
#include "solve/interface_tie.h"
#include "solve/solver.h"

namespace pneumo {
namespace {

constexpr int kNx = 16, kNy = 22, kNz = 4;
constexpr uint16_t kOrgan = 7, kFront = 202;

struct Box {
  Geometry grid;
  std::vector<Role> role;
  std::vector<uint16_t> label;
  Box() {
    grid.dims = {kNx, kNy, kNz};
    grid.spacing_mm = Vec3::Constant(2.0);
    role.assign(grid.voxel_count(), Role::Other);
    label.assign(grid.voxel_count(), 0);
    for (int k = 0; k < kNz; ++k)
      for (int j = 0; j < kNy; ++j)
        for (int i = 0; i < kNx; ++i) {
          const int64_t v = grid.linear_index(i, j, k);
          Role r = Role::Other;
          uint16_t id = 0;
          if (j <= 1 || ((i <= 1 || i >= kNx - 2) && j <= 17)) r = Role::Fixed;   // back and sides
          else if (j <= 5) { r = Role::Wall; id = kOrgan; }                           // the attached organ
          else if (j <= 13) r = Role::Viscera;
          else if (j <= 17) { r = Role::Wall; id = kFront; }                          // the front wall
          role[v] = r;
          label[v] = id;
        }
  }
};

Mesh box_mesh(const Box& b, bool attached) {
  MeshOptions opt;
  opt.cube_voxels = 2;
  if (attached) opt.attached_labels = {kOrgan};
  Mesh m = build_mesh(VoxelRoles{b.grid, b.role.data(), b.label.data(), nullptr}, opt,
                      [](Role r, int) { return r == Role::Wall ? 30e3 : 10e3; });
  assign_material(m, MaterialOptions{});
  return m;
}

SolveOptions inflation(bool attached) {
  Progress::set_enabled(false);
  SolveOptions o;
  o.method = SolverMethod::Newton;
  o.progress = false;
  o.forces.damping = false;
  o.forces.pressure_pa = 1600.0;   // 12 mmHg
  o.forces.tie_attached = attached;
  o.residual_tolerance = 1e-6;
  return o;
}

/// Mean y (mm) of a part's nodes on the plane y = y_mm at rest, in state x.
double plane_y(const Mesh& m, const std::vector<Vec3>& x, Part part, double y_mm) {
  double sum = 0;
  int n = 0;
  for (int64_t i = 0; i < m.node_count(); ++i)
    if (m.node_part[i] == part && std::abs(m.rest_m[i].y() * 1e3 - y_mm) < 1e-6) {
      sum += x[i].y() * 1e3;
      ++n;
    }
  EXPECT_GT(n, 0) << "no node on y = " << y_mm;
  return n ? sum / n : 0.0;
}

TEST(AttachedInterface, ItsFacesCarryNoGasAndItsNodesAreMarked) {
  // Hand count: the organ meets the viscera on the plane between rows 5 and 6 over the 12 × 4 inner
  // columns (i = 2…13): 48 voxel faces, counted from both sides as the cavity's faces are.
  const Box b;
  const Mesh open = box_mesh(b, false), closed = box_mesh(b, true);
  EXPECT_EQ(closed.stats.attached_faces, 2 * 48);
  EXPECT_EQ(open.stats.attached_faces, 0);
  EXPECT_EQ(closed.stats.cavity_faces, open.stats.cavity_faces - 2 * 48);
  // Marked: the corners of the cubes on both sides of the plane y = 11 mm (rows 4–5 and 6–7 form
  // the cubes at lattice rows 2 and 3): lattice rows 2, 3, 4 in each part it meshes.
  for (int64_t n = 0; n < closed.node_count(); ++n) {
    const int row = closed.node_lattice[n][1];
    const bool expect = closed.node_part[n] == Part::Wall ? (row == 2 || row == 3) : (row == 3 || row == 4);
    if (closed.node_attached[n] != expect)
      ADD_FAILURE() << "node " << n << " at lattice row " << row << " part " << part_name(closed.node_part[n]);
  }
  // Pairs: wall and viscera nodes at one lattice point, both marked: the row-3 plane, 7 × 3 points
  // inside the cubes both parts mesh (x 4…28 mm, z 0…8 mm: the side cubes are bone's and wall's).
  const std::vector<TiedPair> pairs = interface_pairs(closed, true);
  EXPECT_EQ(pairs.size(), 7u * 3u);
  for (const TiedPair& p : pairs) EXPECT_EQ(closed.node_lattice[p.wall][1], 3);
  // Every pair, attached or not, also holds the front wall's (lattice row 7).
  EXPECT_GT(interface_pairs(closed, false).size(), pairs.size());
}

TEST(AttachedInterface, TheGasPushesTheVisceraBackInsteadOfOpeningBehindThem) {
  // Compared, at 12 mmHg, the same box with the organ attached and not:
  // - not attached, gas opens on both sides of the viscera: their back face (rest y = 11 mm) leaves
  //   the organ's front by a gap;
  // - attached, the gap stays below a tenth of the viscera's front-face motion (κ = 10: the bond slips
  //   by about a tenth of what the tissue next to it deforms), and the viscera's front face (rest
  //   y = 27 mm) moves back by more than without (the gas in front is the only load on them).
  const Box b;
  const Mesh open = box_mesh(b, false), closed = box_mesh(b, true);
  const SolveResult r_open = solve(open, inflation(false)), r_closed = solve(closed, inflation(true));
  ASSERT_TRUE(r_open.converged) << stop_reason_text(r_open.stop_reason);
  ASSERT_TRUE(r_closed.converged) << stop_reason_text(r_closed.stop_reason);
  const double gap_open = plane_y(open, r_open.x, Part::Viscera, 11.0) - plane_y(open, r_open.x, Part::Wall, 11.0);
  const double gap_closed =
      plane_y(closed, r_closed.x, Part::Viscera, 11.0) - plane_y(closed, r_closed.x, Part::Wall, 11.0);
  const double front_open = 27.0 - plane_y(open, r_open.x, Part::Viscera, 27.0);
  const double front_closed = 27.0 - plane_y(closed, r_closed.x, Part::Viscera, 27.0);
  std::printf("gap behind the viscera: %.4f mm open, %.4f mm attached; their front moves back %.4f / %.4f mm\n",
              gap_open, gap_closed, front_open, front_closed);
  EXPECT_GT(gap_open, 0.01);
  EXPECT_LT(std::abs(gap_closed), 0.1 * front_closed);
  EXPECT_GT(front_closed, 0.0);
  EXPECT_GT(front_closed, front_open);
  EXPECT_EQ(r_closed.inverted_tetrahedra, 0);
}

TEST(AttachedInterface, TheSceneAsksForItAndSchemesWithoutForceFieldsRefuseIt) {
  const Box b;
  const Mesh closed = box_mesh(b, true);
  SolveOptions o = inflation(true);
  o.method = SolverMethod::Explicit;
  EXPECT_THROW(solve(closed, o), InputError);
  const nlohmann::json attached = {{"mesh", {{"attached_labels", {7, 21}}}}};
  const Scene s = parse_scene(attached, "/cases/scene.json");
  EXPECT_EQ(s.mesh.attached_labels, (std::vector<int>{7, 21}));
  EXPECT_TRUE(solve_options_from_scene(s).forces.tie_attached);
  EXPECT_FALSE(solve_options_from_scene(parse_scene(nlohmann::json::object(), "/cases/scene.json")).forces.tie_attached);
  const nlohmann::json explicit_attached = {{"mesh", {{"attached_labels", {7}}}}, {"solver", {{"method", "explicit"}}}};
  EXPECT_THROW(parse_scene(explicit_attached, "/cases/scene.json"), InputError);
  EXPECT_THROW(parse_scene({{"mesh", {{"attached_labels", {70000}}}}}, "/cases/scene.json"), InputError);
}

}  // namespace
}  // namespace pneumo
