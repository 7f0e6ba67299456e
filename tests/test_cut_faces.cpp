// The CT's cut faces (mesh.cut_faces, MeshOptions::cut_faces): where the CT's first or last slice
// along the body's long axis, or its first or last column across it, cuts tissue, "slide" holds the
// nodes of the lattice plane nearest that face on the face's normal (world z or x) and nothing else;
// the front and back are never held.
//
// The physics check is a closed form: a thick-walled tube under internal pressure p, cut at both
// ends of the grid. Held on z at both cut planes and free in them, a uniform prism's exact solution
// is plane strain (ε_z = 0) at every z: Lamé's
//   u(b) = 2(1 + ν)(1 − ν) p a² b / (E (b² − a²))
// on its outer radius b, the same at the cut as in the middle, as for a tube without ends. Left free,
// the open tube's exact solution is generalised plane stress (σ_z = 0):
//   u(b) = 2 p a² b / (E (b² − a²)),
// larger by 1/(1 − ν²) (25 % at ν = 0.45). Each run must match its own closed form and not the
// other's, so the test tells the two conditions apart. Tolerance 5 %: the finite cell method on
// 2 mm cubes across a 10 mm wall came within 1.4 % (sliding, at the cut and in the middle alike) and
// 1.3 % (free) of the closed forms; the two conditions differ by 25 %.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "core/units.h"
#include "mesh/mesh.h"
#include "solve/force_field.h"
#include "solve/solver.h"
#include "solve/thorax_beyond_cut.h"
#include "validate/tet_field.h"

using namespace pneumo;

namespace {

constexpr double kInnerMm = 20.0, kOuterMm = 30.0, kYoungKpa = 60.0, kPoisson = 0.45;
constexpr int64_t kSide = 72, kSlices = 12;   // 1 mm voxels, the tube along k (world z)

struct Tube {
  Geometry g;
  std::vector<Role> roles;
};

/// The tube in every slice from `first` to `last` (the others air): cut by the grid where they are
/// its end slices. The bore is "viscera" so that the wall's inner faces carry the pressure (model Wall).
Tube tube(int64_t first = 0, int64_t last = kSlices - 1) {
  Tube t;
  t.g.dims = {kSide, kSide, kSlices};
  t.g.spacing_mm = Vec3(1.0, 1.0, 1.0);
  t.g.origin_mm = Vec3(0.5 - 0.5 * kSide + 0.3, 0.5 - 0.5 * kSide + 0.1, 0.5);   // off the lattice's symmetry
  t.roles.assign(std::size_t(t.g.voxel_count()), Role::Other);
  for (int64_t k = first; k <= last; ++k)
    for (int64_t j = 0; j < kSide; ++j)
      for (int64_t i = 0; i < kSide; ++i) {
        const Vec3 p = t.g.to_world(Vec3(double(i), double(j), double(k)));
        const double r = std::hypot(p[0], p[1]);
        t.roles[std::size_t(t.g.linear_index(i, j, k))] =
            r < kInnerMm ? Role::Viscera : r <= kOuterMm ? Role::Wall : Role::Other;
      }
  return t;
}

Mesh tube_mesh(const Tube& t, CutFaces cut) {
  MeshOptions mo;
  mo.cube_voxels = 2;
  mo.model = MeshModel::Wall;
  mo.cut_faces = cut;
  Mesh m = build_mesh(VoxelRoles{t.g, t.roles.data(), nullptr}, mo,
                      [](Role, int) { return units::kpa_to_pa(kYoungKpa); });
  assign_material(m, MaterialOptions{});
  m.tet_poisson.assign(m.tets.size(), kPoisson);
  return m;
}

/// Mean radial displacement (mm) on the true outer circle r = b at height z_mm, per mmHg.
double outer_radial_mm(const Mesh& m, const std::vector<Vec3>& x, double z_mm) {
  std::vector<Vec3> u(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) u[i] = x[i] - m.rest_m[i];
  const TetField field(m, units::mm_to_m(2.0));
  constexpr int kAngles = 360;
  double sum = 0.0;
  for (int k = 0; k < kAngles; ++k) {
    const double phi = 2.0 * M_PI * (k + 0.5) / kAngles;
    const Vec3 d(std::cos(phi), std::sin(phi), 0.0);
    bool outside = false;
    sum += field.at(1e-3 * Vec3(kOuterMm * d[0], kOuterMm * d[1], z_mm), u, outside).dot(d);
  }
  return units::m_to_mm(sum / kAngles);
}

struct TubeAnswer {
  double end_mm = 0, middle_mm = 0;
};

TubeAnswer solve_tube(CutFaces cut, double pressure_mmhg) {
  const Tube t = tube();
  const Mesh m = tube_mesh(t, cut);
  SolveOptions so;
  so.method = SolverMethod::Newton;
  so.forces.material = MaterialModel::FemNeoHookean;
  so.forces.mean_dilatation = true;
  so.forces.pressure_pa = units::mmhg_to_pa(pressure_mmhg);
  so.residual_tolerance = 1e-7;
  const SolveResult r = solve(m, so);
  EXPECT_TRUE(r.converged) << "residual " << r.residual;
  // The lattice's end planes lie at z = 0 and z = kSlices mm; sampled just inside them.
  TubeAnswer a;
  a.end_mm = 0.5 * (outer_radial_mm(m, r.x, 0.25) + outer_radial_mm(m, r.x, kSlices - 0.25));
  a.middle_mm = outer_radial_mm(m, r.x, 0.5 * kSlices);
  return a;
}

double plane_strain_mm(double p_kpa) {
  const double a = kInnerMm, b = kOuterMm, nu = kPoisson;
  return 2.0 * (1.0 + nu) * (1.0 - nu) * p_kpa * a * a * b / (kYoungKpa * (b * b - a * a));
}
double plane_stress_mm(double p_kpa) {
  const double a = kInnerMm, b = kOuterMm;
  return 2.0 * p_kpa * a * a * b / (kYoungKpa * (b * b - a * a));
}

}  // namespace

TEST(CutFaces, NodesOnTheCutPlanesAreHeldOnZOnly) {
  const Tube t = tube();
  const Mesh slide = tube_mesh(t, CutFaces::Slide);
  int64_t on_ends = 0;
  for (int64_t n = 0; n < slide.node_count(); ++n) {
    const int32_t c = slide.node_lattice[std::size_t(n)][2];
    const bool end = c == 0 || c == kSlices / 2;
    on_ends += end;
    EXPECT_EQ(slide.hold[std::size_t(n)], end ? kHoldZ : 0) << "node " << n << " on lattice plane " << c;
  }
  EXPECT_GT(on_ends, 0);
  EXPECT_EQ(slide.stats.cut_face_nodes, on_ends);

  const Mesh free = tube_mesh(t, CutFaces::Free);
  for (uint8_t h : free.hold) EXPECT_EQ(h, 0);
  EXPECT_EQ(free.stats.cut_face_nodes, 0);
}

TEST(CutFaces, AirAtTheGridsEndsIsNoCut) {
  // The tube ends a slice inside the grid: its end faces are the body's own surface (as where the
  // roles pad air above or below the CT), not cuts.
  const Mesh m = tube_mesh(tube(1, kSlices - 2), CutFaces::Slide);
  EXPECT_EQ(m.stats.cut_face_nodes, 0);
  for (uint8_t h : m.hold) EXPECT_EQ(h, 0);
}

TEST(CutFaces, TheCtsBoxInsideItsPaddingIsCutOnZAndXButNotY) {
  // Wall fills the CT's box, voxels 2…17 on every axis of a 20³ grid of 1 mm (2 voxels of air padded
  // around it), cubes of 2: its faces lie on lattice planes 1 and 9. Those planes are held on the
  // face's normal, z and x; the front and back faces (y) are not.
  Geometry g;
  g.dims = {20, 20, 20};
  std::vector<Role> roles(std::size_t(g.voxel_count()), Role::Other);
  for (int64_t k = 2; k <= 17; ++k)
    for (int64_t j = 2; j <= 17; ++j)
      for (int64_t i = 2; i <= 17; ++i) roles[std::size_t(g.linear_index(i, j, k))] = Role::Wall;
  VoxelRoles v{g, roles.data()};
  v.ct_first = {2, 2, 2};
  v.ct_last = {17, 17, 17};
  MeshOptions mo;
  mo.cube_voxels = 2;
  mo.model = MeshModel::Wall;
  mo.cut_faces = CutFaces::Slide;
  const Mesh m = build_mesh(v, mo, [](Role, int) { return 1e3; });
  auto face = [](int32_t c) { return c == 1 || c == 9; };
  int64_t held = 0;
  for (int64_t n = 0; n < m.node_count(); ++n) {
    const auto& l = m.node_lattice[std::size_t(n)];
    const uint8_t expected = uint8_t((face(l[0]) ? kHoldX : 0) | (face(l[2]) ? kHoldZ : 0));
    EXPECT_EQ(m.hold[std::size_t(n)], expected) << "node at lattice (" << l[0] << "," << l[1] << "," << l[2] << ")";
    held += expected != 0;
  }
  EXPECT_EQ(m.stats.cut_face_nodes, held);
  EXPECT_GT(held, 0);
}

TEST(CutFaces, TheHeldPlaneIsTheOneNearestTheFaceTiesGoingOutwards) {
  // A face between voxels b − 1 and b lies at b / L cubes. Wall fills slices first…last of a 20-slice
  // column; the planes held on z must be round(first / L) and round((last + 1) / L), a tie rounding
  // down at the low face and up at the high one. The cases tell round from floor (2 / 3 → 1, floor 0),
  // from ceil (4 / 3 → 1, ceil 2), and a tie each way (1 / 2 → 0, 19 / 2 → 10). The default (Free)
  // holds nothing.
  struct Case {
    int L;
    int64_t first, last, low, high;
  };
  for (const Case& c : {Case{3, 2, 15, 1, 5}, Case{3, 4, 13, 1, 5}, Case{2, 1, 18, 0, 10}}) {
    SCOPED_TRACE("L " + std::to_string(c.L) + ", slices " + std::to_string(c.first) + "…" + std::to_string(c.last));
    Geometry g;
    g.dims = {6, 6, 20};
    std::vector<Role> roles(std::size_t(g.voxel_count()), Role::Other);
    for (int64_t k = c.first; k <= c.last; ++k)
      for (int64_t j = 0; j < 6; ++j)
        for (int64_t i = 0; i < 6; ++i) roles[std::size_t(g.linear_index(i, j, k))] = Role::Wall;
    VoxelRoles v{g, roles.data()};
    v.ct_first = {0, 0, c.first};
    v.ct_last = {-1, -1, c.last};
    MeshOptions mo;
    mo.cube_voxels = c.L;
    mo.model = MeshModel::Wall;
    const Mesh free = build_mesh(v, mo, [](Role, int) { return 1e3; });
    EXPECT_EQ(free.stats.cut_face_nodes, 0);
    mo.cut_faces = CutFaces::Slide;
    const Mesh m = build_mesh(v, mo, [](Role, int) { return 1e3; });
    std::set<int32_t> held_planes;
    for (int64_t n = 0; n < m.node_count(); ++n)
      if (m.hold[std::size_t(n)] & kHoldZ) held_planes.insert(m.node_lattice[std::size_t(n)][2]);
    EXPECT_EQ(held_planes, (std::set<int32_t>{int32_t(c.low), int32_t(c.high)}));
  }
}

TEST(CutFaces, ATubeSlidingOnItsCutsIsInPlaneStrainAtTheCutAsInTheMiddle) {
  // A hundredth of 12 mmHg: the linear regime the closed forms describe (0.16 kPa, u ≈ 0.2 mm).
  const double p_mmhg = 0.12, p_kpa = units::mmhg_to_pa(p_mmhg) * 1e-3;
  const TubeAnswer slide = solve_tube(CutFaces::Slide, p_mmhg);
  const double strain = plane_strain_mm(p_kpa), stress = plane_stress_mm(p_kpa);
  EXPECT_NEAR(slide.middle_mm / strain, 1.0, 0.05) << "middle " << slide.middle_mm << " mm, plane strain " << strain;
  EXPECT_NEAR(slide.end_mm / strain, 1.0, 0.05) << "at the cut " << slide.end_mm << " mm, plane strain " << strain;
  EXPECT_NEAR(slide.end_mm / slide.middle_mm, 1.0, 0.02) << "the cut differs from the middle";

  const TubeAnswer open = solve_tube(CutFaces::Free, p_mmhg);
  EXPECT_NEAR(open.middle_mm / stress, 1.0, 0.05) << "free: middle " << open.middle_mm << " mm, plane stress " << stress;
}

// The chest beyond a cranial cut (MeshOptions::opens_onto_thorax, solve/thorax_beyond_cut.h): the top
// face of the tube, here all of its tissue taken as opening onto the chest, pushes into a gas spring
// of compliance C instead of sliding.
namespace {

Mesh tube_opening_onto_chest(const Tube& t, double compliance_m3_per_pa) {
  MeshOptions mo;
  mo.cube_voxels = 2;
  mo.model = MeshModel::Wall;
  mo.cut_faces = CutFaces::Slide;
  mo.opens_onto_thorax = [](Role r, int, float) { return r == Role::Wall; };
  Mesh m = build_mesh(VoxelRoles{t.g, t.roles.data(), nullptr}, mo, [](Role, int) { return units::kpa_to_pa(kYoungKpa); });
  assign_material(m, MaterialOptions{});
  m.tet_poisson.assign(m.tets.size(), kPoisson);
  m.thorax_compliance_m3_per_pa = compliance_m3_per_pa;
  return m;
}

double thorax_area_m2(const Mesh& m) {
  double a = 0.0;
  for (const Vec3& v : m.thorax_area_m2) a += v[2];
  return a;
}

}  // namespace

TEST(CutFaces, TheTopFaceOpensOntoTheChestWithTheCutTissuesWholeArea) {
  // The grid's z runs to the head, so the last slice is the cranial cut: its nodes are listed, not
  // held, and their shares add up to the wall voxels the slice cuts (1 mm² each), all towards the head;
  // the caudal cut still slides.
  const Tube t = tube();
  const Mesh m = tube_opening_onto_chest(t, 1e-9);
  int64_t top_voxels = 0;
  for (int64_t j = 0; j < kSide; ++j)
    for (int64_t i = 0; i < kSide; ++i) top_voxels += t.roles[std::size_t(t.g.linear_index(i, j, kSlices - 1))] == Role::Wall;
  ASSERT_GT(top_voxels, 1000);
  EXPECT_NEAR(thorax_area_m2(m), double(top_voxels) * 1e-6, 1e-12);
  std::set<int32_t> listed(m.thorax_node.begin(), m.thorax_node.end());
  EXPECT_EQ(listed.size(), m.thorax_node.size());
  for (std::size_t i = 0; i < m.thorax_node.size(); ++i) {
    EXPECT_EQ(m.node_lattice[std::size_t(m.thorax_node[i])][2], kSlices / 2);
    EXPECT_EQ(m.hold[std::size_t(m.thorax_node[i])], 0);
    EXPECT_GT(m.thorax_area_m2[i][2], 0.0);
    EXPECT_NEAR(m.thorax_area_m2[i].head<2>().norm(), 0.0, 1e-15);
  }
  for (int64_t n = 0; n < m.node_count(); ++n)
    if (m.node_lattice[std::size_t(n)][2] == 0) EXPECT_EQ(m.hold[std::size_t(n)], kHoldZ);
  EXPECT_EQ(m.stats.thorax_nodes, int64_t(m.thorax_node.size()));
}

TEST(CutFaces, TheChestsForcesAreMinusItsEnergysGradientAndItsStiffnessTheirJacobian) {
  // The chest's gas spring and the face's shape (thorax_beyond_cut.h) with the tube's elements.
  // At a random state (every node moved up to 0.05 mm), the whole field's forces against −∂E/∂x by
  // central differences over the face's nodes (step 1e-8 m), and its stiffness product for a random
  // direction against −(f(x + εp) − f(x − εp))/2ε. C is chosen so the chest's stiffness A²/C is that of
  // the tube's own column, E A / H, so its terms are not lost beside the elements'. Tolerance 1e-5 of
  // the largest force: differences of a smooth energy, only rounding and O(ε²) remain.
  const Tube t = tube();
  Mesh m = tube_opening_onto_chest(t, 1.0);
  const double area = thorax_area_m2(m);
  m.thorax_compliance_m3_per_pa = area * units::mm_to_m(kSlices) / units::kpa_to_pa(kYoungKpa);
  ForceModel fm;
  fm.material = MaterialModel::FemNeoHookean;
  auto field = make_force_field(m, fm);
  std::mt19937 rng(20261208u);
  std::uniform_real_distribution<double> jitter(-0.05e-3, 0.05e-3);
  std::vector<Vec3> x = m.rest_m;
  for (Vec3& p : x) p += Vec3(jitter(rng), jitter(rng), jitter(rng));
  std::vector<Vec3> f(x.size(), Vec3::Zero());
  field->evaluate(fm, x, {}, f);
  double scale = 0.0;
  for (const Vec3& v : f) scale = std::max(scale, v.norm());
  const double h = 1e-8;
  double worst = 0.0;
  for (int32_t n : m.thorax_node)
    for (int a = 0; a < 3; ++a) {
      std::vector<Vec3> xp = x, xm = x;
      xp[std::size_t(n)][a] += h;
      xm[std::size_t(n)][a] -= h;
      const double grad = (field->elastic_energy(fm, xp) - field->elastic_energy(fm, xm)) / (2 * h);
      worst = std::max(worst, std::abs(f[std::size_t(n)][a] + grad));
    }
  EXPECT_LT(worst, 1e-5 * scale);

  field->linearize(fm, x);
  std::vector<Vec3> dir(x.size());
  for (Vec3& d : dir) d = Vec3(jitter(rng), jitter(rng), jitter(rng)) / 0.05e-3;
  std::vector<Vec3> kp;
  field->stiffness_product(dir, kp);
  const double eps = 1e-9;
  std::vector<Vec3> xp = x, xm = x, fp(x.size(), Vec3::Zero()), fm_(x.size(), Vec3::Zero());
  for (std::size_t n = 0; n < x.size(); ++n) { xp[n] += eps * dir[n]; xm[n] -= eps * dir[n]; }
  field->evaluate(fm, xp, {}, fp);
  field->evaluate(fm, xm, {}, fm_);
  double mismatch = 0.0, size = 0.0;
  for (std::size_t n = 0; n < x.size(); ++n) {
    const Vec3 fd = -(fp[n] - fm_[n]) / (2 * eps);
    mismatch = std::max(mismatch, (kp[n] - fd).norm());
    size = std::max(size, fd.norm());
  }
  EXPECT_LT(mismatch, 1e-5 * size);
  // The diagonal blocks hold the rank-one block's own: a_i a_iᵀ / C on top of the elements'.
  // The diagonal blocks the chest and the face add are their K's own: for a few of the face's nodes,
  // the block K e_j read from the product with each unit direction on that node, both less the
  // elements' (whose diagonal is the preconditioner's, not exact under the mean dilatation).
  // Tolerance 1e-5 of the whole block: the elements' two linearisations agree to rounding of their own
  // far larger blocks, and a wrong weight would miss by the chest's and the face's whole share.
  Mesh without_chest = m;
  without_chest.thorax_node.clear();
  without_chest.thorax_area_m2.clear();
  auto inner = make_force_field(without_chest, fm);
  inner->linearize(fm, x);
  std::vector<Mat3> blocks, inner_blocks;
  field->stiffness_diagonal(blocks);
  inner->stiffness_diagonal(inner_blocks);
  for (std::size_t i = 0; i < m.thorax_node.size(); i += m.thorax_node.size() / 5) {
    const std::size_t n = std::size_t(m.thorax_node[i]);
    Mat3 column_block;
    for (int c = 0; c < 3; ++c) {
      std::vector<Vec3> e(x.size(), Vec3::Zero()), ke, ke_inner;
      e[n][c] = 1.0;
      field->stiffness_product(e, ke);
      inner->stiffness_product(e, ke_inner);
      column_block.col(c) = ke[n] - ke_inner[n];
    }
    EXPECT_GT(column_block.norm(), 1e-3 * blocks[n].norm()) << "node " << n << ": the face's terms are lost in rounding";
    EXPECT_LT((blocks[n] - inner_blocks[n] - column_block).norm(), 1e-5 * blocks[n].norm()) << "node " << n;
  }
}

TEST(CutFaces, ATubeOpeningOntoTheChestShortensAsTheGasSpringsClosedFormSays) {
  // The tube under internal pressure p, its caudal cut sliding and its cranial cut pushing into the
  // chest. Generalised plane strain is exact for the prism: one axial strain ε_z = w / H, σ_z =
  // E ε_z + ν S with S = σ_r + σ_θ = 2 p a² / (b² − a²) (Lamé), and the end's traction is the chest's
  // pressure, σ_z = −A w / C. So the top moves by
  //   w = −ν S / (E/H + A/C)
  // (pulled into the tube: the bore's pressure shortens it, and the chest's pressure falls). C free
  // (10⁶ × E A / H) gives the open tube's −ν S H / E; C = A H / E halves it; the tube is 12 mm of 2 mm
  // cubes. The top's w is the volume it pushed into the chest over its area. Tolerance 5 %, as for the
  // tube's radial closed forms above (they came within 1.4 %); the three cases differ by 50 % or more.
  const double p_mmhg = 0.12, p_pa = units::mmhg_to_pa(p_mmhg);
  const double a = units::mm_to_m(kInnerMm), b = units::mm_to_m(kOuterMm), H = units::mm_to_m(kSlices);
  const double E = units::kpa_to_pa(kYoungKpa), S = 2.0 * p_pa * a * a / (b * b - a * a);
  const Tube t = tube();
  for (double stiffness_ratio : {1e-6, 1.0, 4.0}) {   // (A/C) / (E/H)
    SCOPED_TRACE(stiffness_ratio);
    Mesh m = tube_opening_onto_chest(t, 1.0);
    const double area = thorax_area_m2(m);
    m.thorax_compliance_m3_per_pa = area * H / (E * stiffness_ratio);
    SolveOptions so;
    so.method = SolverMethod::Newton;
    so.forces.material = MaterialModel::FemNeoHookean;
    so.forces.mean_dilatation = true;
    so.forces.pressure_pa = p_pa;
    so.residual_tolerance = 1e-7;
    const SolveResult r = solve(m, so);
    ASSERT_TRUE(r.converged) << "residual " << r.residual;
    const double w = thorax_volume_change_m3(m, r.x) / area;
    const double expected = -kPoisson * S / (E / H + area / m.thorax_compliance_m3_per_pa);
    std::printf("chest stiffness %g x the column's: top moved %.5f mm, closed form %.5f mm\n", stiffness_ratio, w * 1e3,
                expected * 1e3);
    EXPECT_NEAR(w / expected, 1.0, 0.05) << "top moved " << w * 1e3 << " mm, closed form " << expected * 1e3 << " mm";
  }
}
