// Numerical extremes: each test states what must happen when a parameter is pushed to the
// edge of what a scene allows (Δt around the stability limit, E from 1 kPa to 1 MPa, 0 to 60 mmHg,
// damping ratio 0 and 2, cubes of 2 to 16 voxels, one cube, nothing free, an unanchored wall,
// inverting tetrahedra, Newmark's inner loop at its cap): a clear answer or a clear refusal, never a
// NaN. The mesh is §6's clamped slab (as in test_solvers.cpp): 4×4×2 cubes of 5 mm wall held by a
// ring of fixed cubes, viscera below (wall-only model), pushed up by the gas.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <omp.h>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "core/error.h"
#include "core/progress.h"
#include "core/units.h"
#include "mesh/mesh.h"
#include "solve/forces.h"
#include "solve/solvable.h"
#include "solve/solver.h"
#include "solve/solver_common.h"
#include "solve/solver_cl.h"

#include "opencl_test_support.h"

namespace pneumo {
namespace {

constexpr double kRho = 1096.0, kCubeMm = 5.0;

struct SlabOptions {
  int voxels_per_cube = 1;     // L: the slab is drawn with voxels of 5/L mm, so every L gives one mesh
  double young_pa = 60e3;
  double damping_ratio = 0.4;
  bool fixed_rim = true;       // false: the ring around the wall is left out, nothing holds the wall
};

Mesh slab(const SlabOptions& o = {}) {
  const int L = o.voxels_per_cube;
  Geometry g;
  g.dims = {6 * L, 6 * L, 3 * L};
  g.spacing_mm = Vec3::Constant(kCubeMm / L);
  std::vector<Role> roles(g.voxel_count(), Role::Other);
  for (int64_t k = 0; k < g.dims[2]; ++k)
    for (int64_t j = 0; j < g.dims[1]; ++j)
      for (int64_t i = 0; i < g.dims[0]; ++i) {
        const int64_t ci = i / L, cj = j / L, ck = k / L;
        const bool inside = ci >= 1 && ci <= 4 && cj >= 1 && cj <= 4;
        Role& r = roles[g.linear_index(i, j, k)];
        if (ck == 0) r = inside ? Role::Viscera : Role::Other;
        else r = inside ? Role::Wall : (o.fixed_rim ? Role::Fixed : Role::Other);
      }
  MeshOptions mo;
  mo.cube_voxels = L;
  mo.model = MeshModel::Wall;
  Mesh m = build_mesh(VoxelRoles{g, roles.data(), nullptr}, mo, [&](Role, int) { return o.young_pa; });
  assign_material(m, MaterialOptions{kRho, o.damping_ratio, 1.0});
  return m;
}

/// Small meshes: one thread (an OpenMP fork per force evaluation costs more than the evaluation).
struct OneThread {
  int saved = omp_get_max_threads();
  OneThread() { omp_set_num_threads(1); }
  ~OneThread() { omp_set_num_threads(saved); }
};

SolveOptions quiet(SolverMethod method, double pressure_mmhg) {
  Progress::set_enabled(false);
  SolveOptions o;
  o.method = method;
  o.progress = false;
  o.forces.pressure_pa = units::mmhg_to_pa(pressure_mmhg);
  return o;
}

bool all_finite(const std::vector<Vec3>& x) {
  for (const auto& p : x)
    if (!p.allFinite()) return false;
  return true;
}

double max_displacement(const Mesh& m, const std::vector<Vec3>& x) {
  double d = 0.0;
  for (int64_t n = 0; n < m.node_count(); ++n) d = std::max(d, (x[n] - m.rest_m[n]).norm());
  return d;
}

/// The largest upward (+z) displacement of a wall node: how far the gas lifts the slab.
double lift(const Mesh& m, const std::vector<Vec3>& x) {
  double d = 0.0;
  for (int64_t n = 0; n < m.node_count(); ++n) d = std::max(d, x[n][2] - m.rest_m[n][2]);
  return d;
}

/// The true stability limit 2/ω_max of symplectic Euler without dampers: ω_max² the largest eigenvalue
/// of M⁻¹K on the free dofs, K the springs linearised at rest (w d̂d̂ᵀ per spring).
double true_critical_step(const Mesh& m) {
  std::vector<int> dofs;
  for (int64_t i = 0; i < m.node_count(); ++i)
    for (int a = 0; a < 3; ++a)
      if (!(m.hold[i] & (1 << a))) dofs.push_back(int(3 * i + a));
  const int64_t N = m.node_count();
  Eigen::MatrixXd full = Eigen::MatrixXd::Zero(3 * N, 3 * N);
  for (std::size_t s = 0; s < m.springs.size(); ++s) {
    const int a = m.springs[s][0], b = m.springs[s][1];
    const Vec3 d = (m.rest_m[a] - m.rest_m[b]).normalized();
    const Mat3 k = m.spring_k[s] * d * d.transpose();
    full.block<3, 3>(3 * a, 3 * a) += k;
    full.block<3, 3>(3 * b, 3 * b) += k;
    full.block<3, 3>(3 * a, 3 * b) -= k;
    full.block<3, 3>(3 * b, 3 * a) -= k;
  }
  const int F = int(dofs.size());
  Eigen::MatrixXd K(F, F);
  for (int i = 0; i < F; ++i)
    for (int j = 0; j < F; ++j)
      K(i, j) = full(dofs[i], dofs[j]) / std::sqrt(m.mass_kg[dofs[i] / 3] * m.mass_kg[dofs[j] / 3]);
  const double w2 = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(K, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
  return 2.0 / std::sqrt(w2);
}

template <class F>
std::string input_error_of(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    return std::string("(not an InputError) ") + e.what();
  }
  return "(no error)";
}

// ---- Δt around the critical step --------------------------------------------------------------------

TEST(ExtremeTimeStep, BelowTheCriticalStepRunsBeyondItStopsWithAdvice) {
  // Compared: explicit runs (no dampers, 10 mmHg applied at once, 2000 steps) at 0.5×, 0.99× and 1.5× of
  // two critical steps, against §6 (symplectic Euler is stable for Δt < 2/ω_max):
  //  - pneumo's estimate (stable_time_step, Gershgorin; what solver.dt_ms = 0 uses): conservative, 0.525
  //    of the true limit here, so all three fractions are inside the limit and must run their 2000 steps
  //    with finite positions, lifted by at most 3× the static lift (an undamped step load overshoots to
  //    2×; measured 0.3-1.5× within these 2000 steps);
  //  - the true limit at rest (2/ω_max from the eigenvalues of M⁻¹K, springs linearised at rest): 0.5×
  //    must run likewise; 1.5× must stop with a DivergedError naming solver.dt_ms and the largest stable
  //    step, never return a result (so nothing is written from it); 0.99× sits on the edge: the loaded,
  //    lifted slab is a little stiffer than at rest (measured: it diverges at step 120), so it must do one
  //    of the two, never return NaN.
  const OneThread one;
  const Mesh m = slab();
  const double critical = true_critical_step(m), estimate = stable_time_step(m, false);
  ASSERT_LT(estimate, critical);
  SolveOptions st = quiet(SolverMethod::Static, 10.0);
  st.residual_tolerance = 1e-6;
  const double static_lift = lift(m, solve(m, st).x);
  for (const double reference : {critical, estimate})
    for (const double fraction : {0.5, 0.99, 1.5}) {
      const bool at_limit = reference == critical && fraction > 0.5;
      const std::string name = std::string(reference == critical ? "critical" : "estimate");
      SCOPED_TRACE(name + " x " + std::to_string(fraction));
      SolveOptions o = quiet(SolverMethod::Explicit, 10.0);
      o.forces.damping = false;
      o.ramp_s = 0.0;
      o.max_steps = 2000;
      o.residual_tolerance = 0.0;   // never "converged": run every step
      o.dt_s = fraction * reference;
      SolveResult r;
      try {
        r = solve(m, o);
      } catch (const DivergedError& e) {
        const std::string msg = e.what();
        std::printf("dt = %.2f x %s: %s\n", fraction, name.c_str(), msg.c_str());
        EXPECT_TRUE(at_limit) << msg;
        EXPECT_NE(msg.find("solver.dt_ms"), std::string::npos) << msg;
        EXPECT_NE(msg.find("largest stable step"), std::string::npos) << msg;
        EXPECT_EQ(e.dt_stable_s, estimate);
        continue;
      }
      EXPECT_FALSE(reference == critical && fraction == 1.5) << "returned a result beyond the limit";
      EXPECT_EQ(r.steps, 2000);
      ASSERT_TRUE(all_finite(r.x));
      std::printf("dt = %.2f x %s: lift %.3f x static\n", fraction, name.c_str(), lift(m, r.x) / static_lift);
      EXPECT_LE(max_displacement(m, r.x), 3.0 * static_lift);
    }
}

// ---- material, load, damping ----------------------------------------------------------------------------

TEST(ExtremeMaterial, YoungFrom1kPaTo1MPa) {
  // Compared, for E = 1, 10, 100 and 1000 kPa under 12 mmHg (1.6 kPa):
  //  - the stable step against its scaling law: every k ∝ E and every c ∝ √E (ξ unchanged), so
  //    Δt(E)·√E is one constant; tolerance 1e-12 relative (rounding of a square root per node);
  //  - E ≥ 10 kPa: the static solver converges with finite positions and no inverted tetrahedron, and in
  //    the linear regime (strain P/E ≤ 1.6 % for E ≥ 100 kPa) lift × E is the same within 3 % (small-strain
  //    theory: u ∝ P/E);
  //  - E = 1 kPa: the pressure exceeds E and the slab balloons out of the model: a DivergedError that
  //    names the pressure and the modulus as what to change (not the time step, not anchoring: the slab is
  //    anchored), never a result.
  const OneThread one;
  double lift_times_e_100 = 0.0;
  const double dt_scale = stable_time_step(slab({1, 1e3}), true) * std::sqrt(1e3);
  for (const double young_kpa : {1.0, 10.0, 100.0, 1000.0}) {
    SCOPED_TRACE("E = " + std::to_string(young_kpa) + " kPa");
    const Mesh m = slab({1, young_kpa * 1e3});
    EXPECT_NEAR(stable_time_step(m, true) * std::sqrt(young_kpa * 1e3), dt_scale, 1e-12 * dt_scale);
    const SolveOptions o = quiet(SolverMethod::Static, 12.0);
    if (young_kpa == 1.0) {
      try {
        solve(m, o);
        ADD_FAILURE() << "a 1 kPa slab under 12 mmHg returned a result";
      } catch (const DivergedError& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find("beyond the model's size"), std::string::npos) << msg;
        EXPECT_NE(msg.find("load.pressure_mmhg"), std::string::npos) << msg;
        EXPECT_NE(msg.find("material.young_kpa"), std::string::npos) << msg;
      }
      continue;
    }
    const SolveResult r = solve(m, o);
    ASSERT_TRUE(all_finite(r.x));
    EXPECT_TRUE(r.converged) << r.stop_reason;
    EXPECT_EQ(r.inverted_tetrahedra, 0);
    std::printf("E = %6.0f kPa: %s after %lld steps, lift %.4f mm\n", young_kpa, stop_reason_text(r.stop_reason),
                (long long)r.steps, units::m_to_mm(lift(m, r.x)));
    if (young_kpa == 100.0) lift_times_e_100 = lift(m, r.x) * young_kpa;
    if (young_kpa == 1000.0) {
      EXPECT_NEAR(lift(m, r.x) * young_kpa, lift_times_e_100, 0.03 * lift_times_e_100);
    }
  }
}

TEST(ExtremeLoad, PressuresFrom0To60MmHg) {
  // Compared: the static solver at 0, 1, 12, 30 and 60 mmHg (E = 60 kPa):
  //  - 0 mmHg: nothing pushes, so the answer is the rest shape exactly (bit for bit), converged;
  //  - every pressure converges with finite positions and no inverted tetrahedron (60 mmHg is a 13 %
  //    nominal strain: large, but the load increments of 4 mmHg keep every tetrahedron upright);
  //  - the lift grows with the pressure, and at 1 mmHg (linear regime) it is 1/12 of the 12 mmHg lift
  //    within 5 % (the follower load and the geometric stiffening are second order there).
  const OneThread one;
  const Mesh m = slab();
  double previous = -1.0, lift_1 = 0.0;
  for (const double mmhg : {0.0, 1.0, 12.0, 30.0, 60.0}) {
    SCOPED_TRACE(std::to_string(mmhg) + " mmHg");
    const SolveResult r = solve(m, quiet(SolverMethod::Static, mmhg));
    ASSERT_TRUE(all_finite(r.x));
    EXPECT_TRUE(r.converged) << r.stop_reason;
    EXPECT_EQ(r.inverted_tetrahedra, 0);
    const double l = lift(m, r.x);
    std::printf("%4.0f mmHg: lift %.3f mm after %lld steps\n", mmhg, units::m_to_mm(l), (long long)r.steps);
    if (mmhg == 0.0) {
      EXPECT_EQ(r.x, m.rest_m);
    } else {
      EXPECT_GT(l, previous);
    }
    if (mmhg == 1.0) lift_1 = l;
    if (mmhg == 12.0) {
      EXPECT_NEAR(l / 12.0, lift_1, 0.05 * lift_1);
    }
    previous = l;
  }
}

TEST(ExtremeMaterial, ANonFiniteStiffnessStopsEverySolverAndNothingIsCalledConverged) {
  // One spring's stiffness and one tetrahedron's modulus NaN (what an underflowing or overflowing
  // material gives): the forces turn NaN at a node. Every scheme must stop with a DivergedError that
  // says "non-finite", never return a result (converged or not) holding NaN. A running maximum of
  // the residual or the displacement built on std::max passes over NaN; this is what catches it.
  const OneThread one;
  Mesh m = slab();
  // A spring and a tetrahedron whose nodes are all free: at a held node the solvers zero the force.
  std::size_t spring = 0, tet = 0;
  while (m.hold[m.springs[spring][0]] != 0 || m.hold[m.springs[spring][1]] != 0) ++spring;
  auto free_tet = [&](std::size_t t) {
    for (int32_t n : m.tets[t])
      if (m.hold[n] != 0) return false;
    return true;
  };
  while (!free_tet(tet)) ++tet;
  m.spring_k[spring] = std::nan("");
  m.tet_young_pa[tet] = std::nan("");
  for (SolverMethod method : {SolverMethod::Static, SolverMethod::Newton, SolverMethod::Explicit, SolverMethod::Newmark,
                              SolverMethod::Kitasaka2004, SolverMethod::ImplicitEuler}) {
    SCOPED_TRACE(enum_name(method));
    SolveOptions o = quiet(method, 12.0);
    o.max_steps = 2000;
    try {
      const SolveResult r = solve(m, o);
      ADD_FAILURE() << "returned " << r.stop_reason << (all_finite(r.x) ? " with finite positions" : " with NaN");
    } catch (const DivergedError& e) {
      EXPECT_NE(std::string(e.what()).find("non-finite"), std::string::npos) << e.what();
    }
  }
}

TEST(ExtremeDamping, ZetaZeroNeverSettlesZetaTwoDoes) {
  // Compared: the explicit solver (automatic Δt, 10 mmHg ramped over 20 ms) at damping ratios 0 and 2:
  //  - ζ = 0: nothing removes energy, the slab oscillates for ever: the run must end at its step limit,
  //    reported as such and not converged, with finite positions;
  //  - ζ = 2 (overdamped): it must settle (converged);
  //  - the stable step with dampers shrinks as §6 says ((2/ω)(√(1+ξ²) − ξ) falls with ξ);
  //  - the static solver ignores dampers: the same positions, bit for bit, at ζ = 0 and 2.
  const OneThread one;
  const Mesh undamped = slab({1, 60e3, 0.0}), overdamped = slab({1, 60e3, 2.0});
  EXPECT_LT(stable_time_step(overdamped, true), stable_time_step(undamped, true));
  SolveOptions o = quiet(SolverMethod::Explicit, 10.0);
  o.ramp_s = 0.02;
  o.max_steps = 20000;
  const SolveResult a = solve(undamped, o);
  EXPECT_FALSE(a.converged);
  EXPECT_EQ(a.stop_reason, StopReason::StepLimit);
  EXPECT_EQ(a.steps, o.max_steps);
  EXPECT_TRUE(all_finite(a.x));
  const SolveResult b = solve(overdamped, o);
  std::printf("zeta = 2: %s after %lld steps\n", stop_reason_text(b.stop_reason), (long long)b.steps);
  EXPECT_TRUE(b.converged) << b.stop_reason;
  EXPECT_TRUE(all_finite(b.x));
  EXPECT_EQ(solve(undamped, quiet(SolverMethod::Static, 10.0)).x, solve(overdamped, quiet(SolverMethod::Static, 10.0)).x);
}

TEST(ExtremeDamping, AnUndampedSwingThatLeavesTheModelBlamesTheDamping) {
  // ζ = 0: a dynamic scheme within its stable step overshoots the equilibrium by as much again and
  // never settles; on the phantom at 12 mmHg the swing grows until the wall leaves the model (after
  // 14,000 explicit steps, too slow for a test). The divergence it then reports must name
  // material.damping_ratio, not the load or the time step; with dampers the load advice stays.
  // Checked on the monitor that every scheme reports through, at the point a node has left the model.
  for (const double zeta : {0.0, 0.4}) {
    SCOPED_TRACE("zeta " + std::to_string(zeta));
    const Mesh m = slab({1, 60e3, zeta});
    const SolveOptions o = quiet(SolverMethod::Explicit, 12.0);
    SolveResult r;
    detail::Monitor mon(m, o, "explicit", r);
    detail::chosen_dt(m, o, o.forces.damping, r);
    try {
      mon.check_diverged(1.0, 14000, "(the time-step advice)");   // 1 m: far beyond the 30 mm slab
      ADD_FAILURE() << "no divergence reported";
    } catch (const DivergedError& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.find("material.damping_ratio") != std::string::npos, zeta == 0.0) << msg;
      EXPECT_EQ(msg.find("load.pressure_mmhg") != std::string::npos, zeta > 0.0) << msg;
      EXPECT_EQ(msg.find("time-step advice"), std::string::npos) << msg;
    }
  }
}

// ---- the mesh: cube size, one cube, nothing free, nothing holding the wall ------------------------------

TEST(ExtremeMesh, CubesOf2To16VoxelsMeshTheSameBodyAlike) {
  // Compared: the slab drawn with L = 2, 4, 8 and 16 voxels per cube (voxels of 5/L mm; at L = 16 that is
  // 96×96×48 voxels) against the slab drawn with L = 1: the same body in the same 5 mm cubes must give
  // the same mesh (node count, rest positions within 1e-12 m: the corners are computed from voxel
  // indices times a spacing 5/L, so they round differently) and the same static equilibrium at 12 mmHg
  // (within 1e-10 of the lift; measured 2e-14: the same steps, which differ only by those roundings). This shows that L is handled
  // at both ends of its range (no cube lost or added at the edges, fixed cubes found by any voxel).
  const OneThread one;
  const Mesh reference = slab();
  SolveOptions o = quiet(SolverMethod::Static, 12.0);
  o.residual_tolerance = 1e-8;
  const SolveResult r0 = solve(reference, o);
  ASSERT_TRUE(r0.converged);
  const double l0 = lift(reference, r0.x);
  for (const int L : {2, 4, 8, 16}) {
    SCOPED_TRACE("L = " + std::to_string(L));
    const Mesh m = slab({L});
    ASSERT_EQ(m.node_count(), reference.node_count());
    ASSERT_EQ(m.tets.size(), reference.tets.size());
    ASSERT_EQ(m.load_tet.size(), reference.load_tet.size());
    ASSERT_EQ(m.stats.cavity_faces, reference.stats.cavity_faces * L * L);
    // Nodes sit at voxel-grid corners, half a voxel from the centres: the mesh shifts by (5 − 5/L)/2 mm
    // per axis as a whole, so shapes are compared relative to node 0.
    double worst = 0.0;
    for (int64_t n = 0; n < m.node_count(); ++n)
      worst = std::max(worst, ((m.rest_m[n] - m.rest_m[0]) - (reference.rest_m[n] - reference.rest_m[0])).norm());
    EXPECT_LE(worst, 1e-12);
    const SolveResult r = solve(m, o);
    ASSERT_TRUE(r.converged);
    double moved = 0.0;
    for (int64_t n = 0; n < m.node_count(); ++n)
      moved = std::max(moved, ((r.x[n] - m.rest_m[n]) - (r0.x[n] - reference.rest_m[n])).norm());
    std::printf("L = %2d: max difference of displacements %.2e of the lift\n", L, moved / l0);
    EXPECT_LE(moved, 1e-10 * l0);
  }
}

TEST(ExtremeMesh, OneCube) {
  // Compared, on meshes of a single cube (8 nodes, 5 tetrahedra):
  //  - a free wall cube with no load: the static solver answers the rest shape, converged; an explicit run
  //    from a seeded random 1e-3 h perturbation stays finite and bounded (within 2× the perturbation);
  //  - a wall cube on a viscera voxel (wall-only model: one cube, its underside one cavity face carried
  //    by the two corner tetrahedra under it), nothing fixed: the gas lifts it as a whole; refused as a
  //    rigid drift (InputError naming it);
  //  - a cube of 3³ voxels whose 8 corner voxels are fixed: each node touches one, all 8 are fixed,
  //    nothing can move: refused (InputError).
  const OneThread one;
  Geometry g;
  g.dims = {1, 1, 1};
  g.spacing_mm = Vec3::Constant(kCubeMm);
  const Role wall = Role::Wall;
  MeshOptions mo;
  mo.cube_voxels = 1;
  Mesh cube = build_mesh(VoxelRoles{g, &wall, nullptr}, mo, [](Role, int) { return 60e3; });
  assign_material(cube, MaterialOptions{});
  ASSERT_EQ(cube.node_count(), 8);
  ASSERT_EQ(cube.tets.size(), 5u);
  const SolveResult rest = solve(cube, quiet(SolverMethod::Static, 0.0));
  EXPECT_TRUE(rest.converged);
  EXPECT_EQ(rest.x, cube.rest_m);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec3> x0 = cube.rest_m;
  for (auto& p : x0) p += 1e-3 * units::mm_to_m(kCubeMm) * Vec3(u(rng), u(rng), u(rng));
  SolveOptions ex = quiet(SolverMethod::Explicit, 0.0);
  ex.max_steps = 500;
  const SolveResult wobble = solve(cube, ex, x0);
  EXPECT_TRUE(all_finite(wobble.x));
  EXPECT_LE(max_displacement(cube, wobble.x), 2.0 * max_displacement(cube, x0) + 1e-3 * units::mm_to_m(kCubeMm));

  // One wall voxel on one viscera voxel, wall-only model: a one-cube mesh whose underside faces the gas.
  Geometry g2;
  g2.dims = {1, 1, 2};
  g2.spacing_mm = Vec3::Constant(kCubeMm);
  const std::vector<Role> on_viscera{Role::Viscera, Role::Wall};
  MeshOptions wall_only = mo;
  wall_only.model = MeshModel::Wall;
  Mesh lid = build_mesh(VoxelRoles{g2, on_viscera.data(), nullptr}, wall_only, [](Role, int) { return 60e3; });
  assign_material(lid, MaterialOptions{});
  ASSERT_EQ(lid.node_count(), 8);
  ASSERT_EQ(lid.stats.cavity_faces, 1);
  ASSERT_EQ(lid.load_tet.size(), 2u);
  const std::string drift = input_error_of([&] { solve(lid, quiet(SolverMethod::Static, 12.0)); });
  EXPECT_NE(drift.find("attached to no fixed node along z"), std::string::npos) << drift;
  EXPECT_NE(drift.find("drift"), std::string::npos) << drift;

  Geometry g3;
  g3.dims = {3, 3, 3};
  g3.spacing_mm = Vec3::Constant(kCubeMm / 3);
  MeshOptions mo2;
  mo2.cube_voxels = 3;
  std::vector<Role> with_fixed(27, Role::Wall);
  for (int k : {0, 2})
    for (int j : {0, 2})
      for (int i : {0, 2}) with_fixed[g3.linear_index(i, j, k)] = Role::Fixed;
  Mesh held = build_mesh(VoxelRoles{g3, with_fixed.data(), nullptr}, mo2, [](Role, int) { return 60e3; });
  assign_material(held, MaterialOptions{});
  const std::string fixed = input_error_of([&] { solve(held, quiet(SolverMethod::Static, 12.0)); });
  EXPECT_NE(fixed.find("every one of the mesh's 8 nodes is fixed"), std::string::npos) << fixed;
}

TEST(ExtremeMesh, EverythingFixedIsRefusedByEverySolver) {
  // Compared: the slab with every node held, solved by each of the four solvers: an InputError saying
  // nothing can move and what to change, before any step. Once the dynamic solvers took Δt from
  // a stable-step estimate that is infinite when no node is free, and ∞·0 made every position NaN.
  const OneThread one;
  Mesh m = slab();
  std::fill(m.hold.begin(), m.hold.end(), uint8_t(kHoldAll));
  for (SolverMethod method :
       {SolverMethod::Static, SolverMethod::Explicit, SolverMethod::Newmark, SolverMethod::Kitasaka2004}) {
    SCOPED_TRACE(enum_name(method));
    const std::string msg = input_error_of([&] { solve(m, quiet(method, 12.0)); });
    EXPECT_NE(msg.find("nothing can move"), std::string::npos) << msg;
    EXPECT_NE(msg.find("roles.fixed_labels"), std::string::npos) << msg;
  }
}

TEST(ExtremeMesh, AWallWithNoFixedNodesIsRefusedAsARigidDrift) {
  // Compared: the slab without its fixed ring. Under pressure from below nothing holds the wall: the net
  // force P·A lifts it as a rigid body and no equilibrium exists (the static solver would never converge,
  // the dynamic ones would run until a node left the model and then blame Δt). Every solver must refuse
  // it before the first step with an InputError naming the part, the drift and what to fix. With no
  // load (0 mmHg, no gravity) the same mesh is in equilibrium at rest and must solve (converged at rest);
  // with gravity alone it drifts again (refused).
  const OneThread one;
  const Mesh m = slab({1, 60e3, 0.4, false});
  for (SolverMethod method :
       {SolverMethod::Static, SolverMethod::Explicit, SolverMethod::Newmark, SolverMethod::Kitasaka2004}) {
    SCOPED_TRACE(enum_name(method));
    const std::string msg = input_error_of([&] { solve(m, quiet(method, 12.0)); });
    EXPECT_NE(msg.find("a wall part of"), std::string::npos) << msg;
    EXPECT_NE(msg.find("attached to no fixed node along z"), std::string::npos) << msg;
    EXPECT_NE(msg.find("rigid body"), std::string::npos) << msg;
    EXPECT_NE(msg.find("roles.fixed_labels"), std::string::npos) << msg;
  }
  const SolveResult r = solve(m, quiet(SolverMethod::Static, 0.0));
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.x, m.rest_m);
  SolveOptions g = quiet(SolverMethod::Static, 0.0);
  g.forces.gravity_m_s2 = Vec3(0, -9.81, 0);
  EXPECT_NE(input_error_of([&] { solve(m, g); }).find("along y"), std::string::npos);
  // The fixed ring holds it: no complaint.
  EXPECT_NO_THROW(check_solvable(slab(), quiet(SolverMethod::Static, 12.0)));
}

// ---- inversion and Newmark's inner loop ---------------------------------------------------------------------

/// A run that met inverted tetrahedra reports how many, equal to count_inverted of the positions it
/// returns; one that went on also says so on stderr (`log`), "N of M tetrahedra are inverted".
void expect_inversions_reported(const Mesh& m, const SolveResult& r, const std::string* log) {
  EXPECT_GT(r.inverted_tetrahedra, 0);
  EXPECT_EQ(r.inverted_tetrahedra, count_inverted(m, r.x));
  if (log) {
    EXPECT_NE(log->find(std::to_string(r.inverted_tetrahedra) + " of " + std::to_string(m.tets.size()) +
                        " tetrahedra are inverted"),
              std::string::npos)
        << *log;
  }
}

TEST(ExtremeInversion, InvertedTetrahedraAreCountedReportedAndStopTheRunWhenAsked) {
  // Compared: a soft slab (E = 3 kPa) under 12 mmHg (1.6 kPa), static solver: the wall bulges 16 mm over a
  // 20 mm span and some tetrahedra at the clamped rim turn inside out on the way to equilibrium (measured:
  // 44). With solver.on_inverted = continue (the default) the run must go on to its equilibrium
  // (converged) and report the count, equal to count_inverted of the returned positions, and say so in a
  // warning on stderr. With stop it must stop before converging, "inverted tetrahedra", with a count > 0
  // equal to count_inverted of the positions it returns. The explicit solver stops alike.
  const OneThread one;
  const Mesh m = slab({1, 3e3});
  SolveOptions o = quiet(SolverMethod::Static, 12.0);
  ::testing::internal::CaptureStderr();
  const SolveResult went_on = solve(m, o);
  const std::string log = ::testing::internal::GetCapturedStderr();
  EXPECT_TRUE(went_on.converged) << went_on.stop_reason;
  ASSERT_TRUE(all_finite(went_on.x));
  expect_inversions_reported(m, went_on, &log);
  for (SolverMethod method : {SolverMethod::Static, SolverMethod::Explicit}) {
    SCOPED_TRACE(enum_name(method));
    SolveOptions s = quiet(method, 12.0);
    s.on_inverted = OnInverted::Stop;
    const SolveResult stopped = solve(m, s);
    EXPECT_EQ(stopped.stop_reason, StopReason::InvertedTetrahedra);
    EXPECT_FALSE(stopped.converged);
    expect_inversions_reported(m, stopped, nullptr);
    if (method == SolverMethod::Static) {
      EXPECT_LT(stopped.steps, went_on.steps);
    }
    std::printf("%s, on_inverted = stop: stopped after %lld steps with %lld inverted (continue: %lld inverted, "
                "converged after %lld steps)\n",
                enum_name(method), (long long)stopped.steps, (long long)stopped.inverted_tetrahedra,
                (long long)went_on.inverted_tetrahedra, (long long)went_on.steps);
  }
}

/// A solver (method) on a device: "cpu" for the C++ reference or an OpenCL spec.
using SolverOnDevice = std::tuple<SolverMethod, std::string>;

class ExtremeInversionOn : public ::testing::TestWithParam<SolverOnDevice> {};

TEST_P(ExtremeInversionOn, TheSoftSlabInvertsAndTheRunStopsOrGoesOnAsTold) {
  // Compared: ExtremeInversion's soft slab (E = 3 kPa under 12 mmHg) through every solver on every device.
  // With solver.on_inverted = stop the run must stop on its own account: "inverted tetrahedra", not
  // converged, a count > 0 equal to count_inverted of the positions it returns (on a device, the
  // device's positions: the count and the shape must agree). With continue, given twice those steps, it
  // must go past the step the stopped run ended at ("converged" or "step limit", never "inverted
  // tetrahedra"), count its own final positions (still > 0 under this load) and warn with the count.
  const auto& [method, device] = GetParam();
  const OneThread one;
  const Mesh m = slab({1, 3e3});
  std::shared_ptr<ocl::Context> ctx;
  if (device != "cpu") ctx = ocl::Context::shared(ocl::parse_device_spec(device));
  auto run = [&](OnInverted on_inverted, int64_t max_steps) {
    SolveOptions o = quiet(method, 12.0);
    o.on_inverted = on_inverted;
    o.max_steps = max_steps;
    return ctx ? solve_opencl(*ctx, m, o) : solve(m, o);
  };
  const SolveResult stopped = run(OnInverted::Stop, 100000);
  EXPECT_EQ(stopped.stop_reason, StopReason::InvertedTetrahedra);
  EXPECT_FALSE(stopped.converged);
  expect_inversions_reported(m, stopped, nullptr);
  ::testing::internal::CaptureStderr();
  const SolveResult went_on = run(OnInverted::Continue, 2 * stopped.steps);
  const std::string log = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(went_on.stop_reason, StopReason::InvertedTetrahedra);
  EXPECT_GT(went_on.steps, stopped.steps);
  expect_inversions_reported(m, went_on, &log);
  std::printf("%s on %s: stopped after %lld steps with %lld inverted; continue: %s after %lld steps, %lld inverted\n",
              enum_name(method), device.c_str(), (long long)stopped.steps, (long long)stopped.inverted_tetrahedra,
              stop_reason_text(went_on.stop_reason), (long long)went_on.steps, (long long)went_on.inverted_tetrahedra);
}

INSTANTIATE_TEST_SUITE_P(EverySolver, ExtremeInversionOn,
                         ::testing::Combine(::testing::Values(SolverMethod::Static, SolverMethod::Explicit,
                                                              SolverMethod::Newmark, SolverMethod::Kitasaka2004),
                                            ::testing::ValuesIn(testing_support::cpu_and_opencl_device_specs())),
                         [](const ::testing::TestParamInfo<SolverOnDevice>& info) {
                           return std::string(enum_name(std::get<0>(info.param))) + "_" +
                                  testing_support::spec_name(std::get<1>(info.param));
                         });

TEST(ExtremeNewmark, InnerLoopCappedWhileConvergingAsksForMoreIterationsNotASmallerStep) {
  // Compared: Newmark at half the stable estimate (its inner loop contracts) but allowed only 2 inner
  // iterations with a 1e-12 tolerance: the loop is still converging when its cap runs out. The
  // DivergedError must say so and name solver.newmark_max_inner, without claiming that Δt is too large.
  // Beyond the stable step the loop diverges and the advice is about Δt:
  // SolverDivergence.NewmarkBeyondItsStableStepThrows (test_solvers.cpp).
  const OneThread one;
  const Mesh m = slab();
  SolveOptions o = quiet(SolverMethod::Newmark, 10.0);
  o.newmark_max_inner = 2;
  o.newmark_inner_tolerance = 1e-12;
  o.max_steps = 100;
  try {
    solve(m, o);
    ADD_FAILURE() << "no error";
  } catch (const DivergedError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("solver.newmark_max_inner (2)"), std::string::npos) << msg;
    EXPECT_NE(msg.find("still converging"), std::string::npos) << msg;
    EXPECT_EQ(msg.find("is too large"), std::string::npos) << msg;
  }
}

}  // namespace
}  // namespace pneumo
