// The viscera's frictionless contact with the wall and with bone (solve/contact.h), against truths
// computed here: nothing acts at rest or while the surfaces part; a flat press gives the penalty's
// closed form, normal to the surface, with equal and opposite forces on the two sides whatever the
// sliding; the forces are −∇ of the contact energy and the stiffness product their Jacobian (at frozen
// pairs, by central differences); and a beam of viscera that sinks into the wall or into bone under
// gravity without contact rests on it with contact, under every solver that takes it.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/error.h"
#include "core/progress.h"
#include "mesh/mesh.h"
#include "pipeline/scene_stages.h"
#include "scene/scene.h"
#include "solve/contact.h"
#include "solve/force_field.h"
#include "solve/solve_on_device.h"
#include "solve/solver.h"
#include "mesh_test_support.h"
#include "opencl_test_support.h"

namespace pneumo {
namespace {

constexpr double kSpacingMm = 2.0;
constexpr int kNx = 40, kNy = 16, kNz = 4, kCube = 2;
constexpr double kYoungPa = 10e3;

/// A beam of viscera (rows 6–11 of the y axis, y up; 2 mm voxels, 4 mm cubes) held at both ends by bone
/// columns, over `support`: a wall slab (rows 2–5) on bone (rows 0–1), or bone (rows 0–4) below an empty
/// row. Its bottom lies on a node plane of the lattice, whose nodes touch no bone.
struct BeamCase {
  Geometry grid;
  std::vector<Role> roles;
  Mesh mesh;
};
enum class Support { Wall, BoneBelowAGap };

BeamCase beam_case(Support support) {
  BeamCase c;
  c.grid.dims = {kNx, kNy, kNz};
  c.grid.spacing_mm = Vec3::Constant(kSpacingMm);
  c.roles.assign(c.grid.voxel_count(), Role::Other);
  for (int k = 0; k < kNz; ++k)
    for (int j = 0; j < kNy; ++j)
      for (int i = 0; i < kNx; ++i) {
        Role r = Role::Other;
        if (support == Support::Wall) {
          if (j <= 1) r = Role::Fixed;
          else if (j <= 5) r = Role::Wall;
        } else if (j <= 4) {
          r = Role::Fixed;
        }
        if (j >= 6 && j <= 11) r = (i <= 1 || i >= kNx - 2) ? Role::Fixed : Role::Viscera;
        c.roles[c.grid.linear_index(i, j, k)] = r;
      }
  MeshOptions opt;
  opt.cube_voxels = kCube;
  c.mesh = build_mesh(VoxelRoles{c.grid, c.roles.data()}, opt, [](Role, int) { return kYoungPa; });
  assign_material(c.mesh, MaterialOptions{});
  return c;
}

ForceModel contact_model(double kappa) {
  ForceModel fm;
  fm.damping = false;
  fm.contact_stiffness = kappa;
  return fm;
}

/// The viscera moved by `shift` (metres), the rest as at rest.
std::vector<Vec3> viscera_moved(const Mesh& m, const Vec3& shift) {
  std::vector<Vec3> x = m.rest_m;
  for (int64_t n = 0; n < m.node_count(); ++n)
    if (m.node_part[n] == Part::Viscera) x[n] += shift;
  return x;
}

std::vector<Vec3> contact_forces_only(const Mesh& m, double kappa, const std::vector<Vec3>& x) {
  std::vector<Vec3> f(m.node_count(), Vec3::Zero());
  add_contact_forces(m, ContactSearch(m, kappa).find(x), x, f);
  return f;
}

TEST(Contact, TheMeshHoldsTheViscerasSurfaceTheCavitysWallSideAndTheBoneNearTheViscera) {
  // Compared: the face counts against the beam's geometry. Viscera: 36 × 6 × 4 voxels (x, y, z) over the
  // wall; its surface towards non-viscera voxels: bottom and top 36·4 each, ends 6·4 each (bone), front
  // and back are the grid's edge (no neighbour, no face). Wall faces towards viscera: the 36·4 under it.
  // Bone near the viscera: the two end columns' faces towards the viscera (2·6·4) and their tops towards
  // the empty rows above (2·2·4); their bottoms meet the wall, left out.
  const BeamCase c = beam_case(Support::Wall);
  int64_t viscera = 0, wall = 0;
  for (std::size_t f = 0; f < c.mesh.contact.size(); ++f) ++(c.mesh.contact.part[f] == Part::Viscera ? viscera : wall);
  EXPECT_EQ(viscera, 2 * 36 * 4 + 2 * 6 * 4);
  EXPECT_EQ(wall, 36 * 4);
  EXPECT_EQ(int64_t(c.mesh.contact.fixed_centre_m.size()), 2 * 6 * 4 + 2 * 2 * 4);
  // Every viscera face's area vector at rest is one voxel face (4 mm²) out of the viscera.
  for (std::size_t f = 0; f < c.mesh.contact.size(); ++f) {
    const auto& q = c.mesh.tets[c.mesh.contact.tet[f]];
    const Vec3 e1 = c.mesh.rest_m[q[1]] - c.mesh.rest_m[q[0]], e2 = c.mesh.rest_m[q[2]] - c.mesh.rest_m[q[0]],
               e3 = c.mesh.rest_m[q[3]] - c.mesh.rest_m[q[0]];
    const Vec3& cv = c.mesh.contact.c[f];
    const Vec3 area = cv[0] * e2.cross(e3) + cv[1] * e3.cross(e1) + cv[2] * e1.cross(e2);
    EXPECT_NEAR(area.norm(), 4e-6, 1e-15);
  }
}

TEST(Contact, NothingActsAtRestOrWhileTheSurfacesPart) {
  // Compared: every nodal contact force against zero at rest (the faces coincide), with the viscera
  // lifted 0.5 mm (parted) and slid 1.4 mm along the wall and the bone (touching, not pressed).
  // Tolerance 1e-12 N: rounding of coincident points against a face force of order k A δ = 1e-3 N at
  // δ = 0.1 mm.
  const BeamCase c = beam_case(Support::Wall);
  for (const Vec3& shift : {Vec3(0, 0, 0), Vec3(0, 0.5e-3, 0), Vec3(0, 0, 1.4e-3)})
    EXPECT_LT(max_norm(contact_forces_only(c.mesh, 10.0, viscera_moved(c.mesh, shift))), 1e-12);
}

TEST(Contact, APressIsNormalEqualAndOppositeAndSlidingKeepsIt) {
  // The viscera pressed δ = 0.3 mm into the wall, in place and slid 0.7 voxels along z, along the wall
  // and the bone at its ends (each face then meets the neighbour of the face it started on). Compared:
  // the total force on the viscera against the penalty's closed form κ E/h · A · δ along +y (A = 36·4
  // voxel faces of the interface, h the 4 mm cube edge), its tangential part against zero, and the
  // wall's total against minus the viscera's. Tolerance 1e-9 relative: rounding; a face left out or
  // counted twice is 0.7 %.
  const BeamCase c = beam_case(Support::Wall);
  const double kappa = 10.0, delta = 0.3e-3, h = kCube * kSpacingMm * 1e-3, area = 36 * 4 * 4e-6;
  const double expected = kappa * kYoungPa / h * area * delta;
  for (const Vec3& slide : {Vec3(0, 0, 0), Vec3(0, 0, 1.4e-3)}) {
    const std::vector<Vec3> x = viscera_moved(c.mesh, slide + Vec3(0, -delta, 0));
    const std::vector<Vec3> f = contact_forces_only(c.mesh, kappa, x);
    Vec3 on_viscera = Vec3::Zero(), on_wall = Vec3::Zero();
    for (int64_t n = 0; n < c.mesh.node_count(); ++n)
      (c.mesh.node_part[n] == Part::Viscera ? on_viscera : on_wall) += f[n];
    EXPECT_NEAR(on_viscera[1], expected, 1e-9 * expected);
    EXPECT_LT(std::hypot(on_viscera[0], on_viscera[2]), 1e-9 * expected);
    EXPECT_LT((on_viscera + on_wall).norm(), 1e-9 * expected);
  }
}

TEST(Contact, ForcesAreMinusTheEnergysGradientAndTheStiffnessTheirJacobian) {
  // At a random state of the pressed beam (viscera 0.3 mm into the wall, every node moved up to 0.05 mm)
  // with the pairs found there frozen. Compared: the forces against −∂E/∂x by central differences
  // (step 1e-7 m), and the field's stiffness product (minus the springs' own) for a random direction
  // against −(f(x + εp) − f(x − εp))/2ε. Tolerance 1e-6 of the largest force: both are exact for a
  // quadratic energy, so only rounding remains; a wrong weight or sign is of order 1.
  const BeamCase c = beam_case(Support::Wall);
  const double kappa = 10.0;
  std::mt19937 rng(20261202u);
  std::vector<Vec3> x = perturbed(c.mesh, rng, 0.05e-3);
  for (int64_t n = 0; n < c.mesh.node_count(); ++n)
    if (c.mesh.node_part[n] == Part::Viscera) x[n][1] -= 0.3e-3;
  const std::vector<ContactPair> pairs = ContactSearch(c.mesh, kappa).find(x);
  ASSERT_GT(pairs.size(), 100u);
  std::vector<Vec3> f(c.mesh.node_count(), Vec3::Zero());
  add_contact_forces(c.mesh, pairs, x, f);
  const double scale = max_norm(f);
  const auto energy = [&](const std::vector<Vec3>& y) { return contact_energy(c.mesh, pairs, y); };
  EXPECT_LT(max_gradient_mismatch(x, f, 1e-7, energy), 1e-6 * scale);

  const ForceModel fm = contact_model(kappa);
  auto field = make_force_field(c.mesh, fm);
  auto springs = make_force_field(c.mesh, contact_model(0.0));
  field->linearize(fm, x);
  springs->linearize(fm, x);
  const std::vector<Vec3> p = perturbed(c.mesh, rng, 1.0);
  std::vector<Vec3> dir(c.mesh.node_count());
  for (int64_t n = 0; n < c.mesh.node_count(); ++n) dir[n] = p[n] - c.mesh.rest_m[n];
  std::vector<Vec3> kp, kp_springs;
  field->stiffness_product(dir, kp);
  springs->stiffness_product(dir, kp_springs);
  const double eps = 1e-7;
  std::vector<Vec3> xp = x, xm = x, fp(c.mesh.node_count(), Vec3::Zero()), fm_(c.mesh.node_count(), Vec3::Zero());
  for (int64_t n = 0; n < c.mesh.node_count(); ++n) { xp[n] += eps * dir[n]; xm[n] -= eps * dir[n]; }
  add_contact_forces(c.mesh, pairs, xp, fp);
  add_contact_forces(c.mesh, pairs, xm, fm_);
  double worst = 0.0, size = 0.0;
  for (int64_t n = 0; n < c.mesh.node_count(); ++n) {
    const Vec3 fd = -(fp[n] - fm_[n]) / (2 * eps);
    worst = std::max(worst, (kp[n] - kp_springs[n] - fd).norm());
    size = std::max(size, fd.norm());
  }
  EXPECT_GT(size, 0.0);
  EXPECT_LT(worst, 1e-6 * size);
}

TEST(Contact, FiresMassesBoundTheContactsStiffness) {
  // Gershgorin's bound of force_field.h with the contact added: the largest eigenvalue of M^-1/2 K M^-1/2
  // (power iteration, 300 passes) at the pressed beam (0.3 mm into the wall, slid 0.7 voxel), springs
  // and neo-Hookean. Compared: against 2, FIRE's stability limit, and above 0.1 (not loose by orders).
  const BeamCase c = beam_case(Support::Wall);
  const std::vector<Vec3> x = viscera_moved(c.mesh, Vec3(0, -0.3e-3, 1.4e-3));
  for (MaterialModel material : {MaterialModel::Msd, MaterialModel::FemNeoHookean}) {
    SCOPED_TRACE(enum_name(material));
    ForceModel fm = contact_model(10.0);
    fm.material = material;
    auto field = make_force_field(c.mesh, fm);
    const std::vector<double> mass = field->fire_masses(fm);
    field->linearize(fm, x);
    const int64_t N = c.mesh.node_count();
    std::vector<Vec3> y(N, Vec3::Ones()), p(N), ky;
    double lambda = 0.0;
    for (int it = 0; it < 300; ++it) {
      for (int64_t n = 0; n < N; ++n) p[n] = c.mesh.hold[n] ? Vec3::Zero() : Vec3(y[n] / std::sqrt(mass[n]));
      field->stiffness_product(p, ky);
      double norm = 0.0;
      for (int64_t n = 0; n < N; ++n) {
        y[n] = c.mesh.hold[n] ? Vec3::Zero() : Vec3(ky[n] / std::sqrt(mass[n]));
        norm += y[n].squaredNorm();
      }
      lambda = std::sqrt(norm);
      for (auto& v : y) v /= lambda;
    }
    std::printf("%s with contact: largest omega^2 %.3f\n", enum_name(material), lambda);
    EXPECT_GT(lambda, 0.1);
    EXPECT_LE(lambda, 2.0);
  }
}

/// Penetration of the viscera into its support along the beam (m): the largest of, over the viscera's
/// bottom nodes, how far each lies below the support's top at the same x and z (the wall's node on the
/// same lattice corner; bone's flat top at its rest height).
double penetration(const BeamCase& c, Support support, const std::vector<Vec3>& x) {
  const Mesh& m = c.mesh;
  const int bottom_lattice = 6 / kCube;
  const double bone_top_m = 4.5 * kSpacingMm * 1e-3;   // the face between rows 4 and 5
  double worst = -INFINITY;
  for (int64_t n = 0; n < m.node_count(); ++n) {
    if (m.node_part[n] != Part::Viscera || m.node_lattice[n][1] != bottom_lattice || m.hold[n]) continue;
    double top = bone_top_m;
    if (support == Support::Wall) {
      top = NAN;
      for (int64_t w = 0; w < m.node_count(); ++w)
        if (m.node_part[w] == Part::Wall && m.node_lattice[w] == m.node_lattice[n]) top = x[w][1];
    }
    worst = std::max(worst, top - x[n][1]);
  }
  return worst;
}

SolveOptions gravity_case(SolverMethod method, double kappa, MaterialModel material = MaterialModel::Msd) {
  Progress::set_enabled(false);
  SolveOptions o;
  o.method = method;
  o.progress = false;
  o.forces.material = material;
  o.forces.damping = false;
  o.forces.gravity_m_s2 = Vec3(0, -9.81, 0);
  o.forces.pressure_pa = 30.0;   // 0.2 mmHg: the gas barely lifts the beam
  o.forces.contact_stiffness = kappa;
  o.residual_tolerance = 1e-6;
  o.max_steps = 400000;
  return o;
}

double largest_difference(const SolveResult& a, const SolveResult& b) {
  double d = 0.0;
  for (std::size_t n = 0; n < a.x.size(); ++n) d = std::max(d, (a.x[n] - b.x[n]).norm());
  return d;
}

TEST(Contact, ABeamOfVisceraSinksIntoItsSupportWithoutContactAndRestsOnItWith) {
  // The beam (72 mm span, 12 mm thick, E = 10 kPa) sags under its weight; at 0.2 mmHg the gas under it
  // carries a fifth of that. Without contact it passes through the wall or the bone by millimetres
  // (the clamped beam's closed form ρgL⁴/(32Eh²) gives about 6 mm; the wall and the gas take some,
  // the empty row over the bone 2 mm). With contact, for the springs and the neo-Hookean elements, by
  // Newton and by FIRE, it rests on its support: penetration below 0.05 mm (the penalty's own, about
  // p·h/(κE) = 0.01 mm at the weight's 130 Pa, plus the surface's sampling at voxel-face centres), and
  // both solvers agree within 0.02 mm.
  for (MaterialModel material : {MaterialModel::Msd, MaterialModel::FemNeoHookean})
    for (Support support : {Support::Wall, Support::BoneBelowAGap}) {
      SCOPED_TRACE(std::string(enum_name(material)) + (support == Support::Wall ? " on the wall" : " over bone"));
      const BeamCase c = beam_case(support);
      const SolveResult free_fall = solve(c.mesh, gravity_case(SolverMethod::Newton, 0.0, material));
      ASSERT_TRUE(free_fall.converged) << free_fall.stop_reason;
      const double through = penetration(c, support, free_fall.x);
      const SolveResult newton = solve(c.mesh, gravity_case(SolverMethod::Newton, 10.0, material));
      const SolveResult fire = solve(c.mesh, gravity_case(SolverMethod::Static, 10.0, material));
      ASSERT_TRUE(newton.converged) << newton.stop_reason;
      ASSERT_TRUE(fire.converged) << fire.stop_reason;
      std::printf("%s: without contact %.2f mm through; with it %.4f mm (newton %lld it., FIRE %lld steps, apart "
                  "%.5f mm)\n",
                  enum_name(material), 1e3 * through, 1e3 * penetration(c, support, newton.x), (long long)newton.steps,
                  (long long)fire.steps, 1e3 * largest_difference(newton, fire));
      EXPECT_GT(through, 2e-3);
      EXPECT_LT(penetration(c, support, newton.x), 0.05e-3);
      EXPECT_LT(penetration(c, support, fire.x), 0.05e-3);
      EXPECT_LT(largest_difference(newton, fire), 0.02e-3);
    }
}

TEST(Contact, EveryDeviceRestsTheBeamWhereTheCpuDoes) {
  // The finite elements on OpenCL (float32 forces, the contact on the host) against the CPU, Newton, the
  // beam on the wall and over bone, residual 1e-4 (float32 forces stall near 7e-5 of this load).
  // Compared: every node. Tolerance 1e-3 mm: float rounding over displacements of a few millimetres; a
  // device field without the contact term would sink by millimetres.
  for (const std::string& device : testing_support::opencl_device_specs())
    for (Support support : {Support::Wall, Support::BoneBelowAGap}) {
      SCOPED_TRACE(device + (support == Support::Wall ? " on the wall" : " over bone"));
      const BeamCase c = beam_case(support);
      SolveOptions o = gravity_case(SolverMethod::Newton, 10.0, MaterialModel::FemNeoHookean);
      o.residual_tolerance = 1e-4;
      const SolveResult cpu = solve(c.mesh, o);
      auto ctx = ocl::Context::shared(ocl::parse_device_spec(device));
      const SolveResult dev = solve_on_device(ctx.get(), c.mesh, o);
      ASSERT_TRUE(cpu.converged) << cpu.stop_reason;
      ASSERT_TRUE(dev.converged) << dev.stop_reason << " at residual " << dev.residual;
      std::printf("%s: device %.6f mm from the CPU, penetration %.4f mm\n", device.c_str(),
                  1e3 * largest_difference(cpu, dev), 1e3 * penetration(c, support, dev.x));
      EXPECT_LT(largest_difference(cpu, dev), 1e-6);
    }
}

TEST(Contact, TheSceneTiltsGravityAndRefusesContactWhereNoSolverHasIt) {
  // Trendelenburg 30° (head down): gravity 9.81·(0, −cos 30°, sin 30°) in RAS (towards the head, +z).
  Scene s;
  s.material.gravity = true;
  s.material.tilt_deg = 30.0;
  s.material.contact = true;
  const SolveOptions o = solve_options_from_scene(s);
  EXPECT_NEAR(o.forces.gravity_m_s2[1], -9.81 * std::sqrt(3.0) / 2, 1e-12);
  EXPECT_NEAR(o.forces.gravity_m_s2[2], 9.81 * 0.5, 1e-12);
  EXPECT_EQ(o.forces.contact_stiffness, 10.0);
  // The explicit schemes call the springs' evaluator directly: contact there is refused, not ignored,
  // by the scene and by the solver; a tilt without gravity would do nothing and is refused.
  const BeamCase c = beam_case(Support::Wall);
  EXPECT_THROW(solve(c.mesh, gravity_case(SolverMethod::Explicit, 10.0)), InputError);
  const nlohmann::json explicit_contact = {{"material", {{"contact", true}}}, {"solver", {{"method", "explicit"}}}};
  EXPECT_THROW(parse_scene(explicit_contact, "/cases/scene.json"), InputError);
  EXPECT_THROW(parse_scene({{"material", {{"tilt_deg", 15}}}}, "/cases/scene.json"), InputError);
  const nlohmann::json tilted = {{"material", {{"tilt_deg", -15}, {"gravity", true}, {"contact", true}}}};
  EXPECT_NO_THROW(parse_scene(tilted, "/cases/scene.json"));
}

}  // namespace
}  // namespace pneumo
