// The four solvers on every OpenCL device (host/solve/solver_cl.cpp, float32, state on the device)
// against the double-precision CPU reference: N steps of each, the equilibrium each reaches, and a
// clean DivergedError beyond the stable step. A small clamped slab pushed by gas from below.
#include <gtest/gtest.h>

#include "cl/cl_runtime.h"
#include "opencl_test_support.h"
#include "core/progress.h"
#include "solve/solver.h"
#include "solve/solver_cl.h"

using namespace pneumo;

namespace {

/// 12×12×4 voxels of 5 mm: viscera at the bottom, two wall layers above, a fixed rim; soft
/// (E = 60 kPa).
Mesh slab() {
  Geometry g;
  g.dims = {12, 12, 4};
  g.spacing_mm = Vec3::Constant(5.0);
  g.origin_mm = Vec3(-120.0, 40.0, 300.0);   // away from the world origin, as in a CT
  std::vector<Role> roles(g.voxel_count(), Role::Other);
  for (int64_t k = 0; k < 4; ++k)
    for (int64_t j = 0; j < 8; ++j)
      for (int64_t i = 0; i < 8; ++i) {
        const bool rim = i == 0 || j == 0 || i == 11 || j == 11;
        roles[g.linear_index(i, j, k)] = k == 0 ? Role::Viscera : k <= 2 ? (rim ? Role::Fixed : Role::Wall) : Role::Other;
      }
  MeshOptions mo;
  mo.cube_voxels = 1;
  mo.model = MeshModel::Wall;
  Mesh m = build_mesh(VoxelRoles{g, roles.data(), nullptr}, mo, [](Role, int) { return 60e3; });
  assign_material(m, MaterialOptions{});
  return m;
}

SolveOptions options(SolverMethod method) {
  SolveOptions o;
  o.method = method;
  o.forces.pressure_pa = 1333.2;   // 10 mmHg
  o.forces.volume_stiffness_pa = method == SolverMethod::Kitasaka2004 ? 60e3 : 0.0;
  o.kitasaka_jacobi = true;   // the device's order, so that N steps compare one to one
  o.ramp_s = 0.02;
  o.progress = false;
  return o;
}

double max_distance(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double d = 0;
  for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, (a[i] - b[i]).norm());
  return d;
}

double max_displacement(const Mesh& m, const std::vector<Vec3>& x) { return max_distance(m.rest_m, x); }

class SolverClVsRef : public ::testing::TestWithParam<std::tuple<std::string, SolverMethod>> {
 protected:
  void SetUp() override { Progress::set_enabled(false); }
  std::shared_ptr<ocl::Context> ctx() { return ocl::Context::shared(ocl::parse_device_spec(std::get<0>(GetParam()))); }
  SolverMethod method() const { return std::get<1>(GetParam()); }
};

// N = 40 steps under the full load at once (no ramp, no convergence reached): the device's positions
// stay within 1e-4 of the displacement reached. Why: each step rounds the state to float32
// (ε₃₂ ≈ 1.2e-7 relative) and the stable schemes do not amplify it much over 40 steps; wrong physics
// (a missing term, a sign, a wrong step formula) shows up at 1e-2 or more.
TEST_P(SolverClVsRef, NStepsMatchTheReference) {
  const Mesh m = slab();
  SolveOptions o = options(method());
  o.ramp_s = 0.0;
  o.max_steps = 40;
  const SolveResult ref = solve(m, o);
  const SolveResult dev = solve_opencl(*ctx(), m, o);
  EXPECT_EQ(dev.steps, ref.steps);
  const double u = max_displacement(m, ref.x);
  ASSERT_GT(u, 0.0);
  EXPECT_LE(max_distance(ref.x, dev.x), 1e-4 * u) << "displacement " << u << " m";
}

// To equilibrium (residual 1e-4 of the pressure load on both): the same shape within 1e-3 of the
// displacement. Why: each stops where its residual is below the tolerance, so the two stopping
// points differ by the displacement such a force produces through the slab's softest mode (measured
// ~1e-4 relative here), and the 2004 scheme runs Gauss–Seidel on the CPU but Jacobi on the device.
TEST_P(SolverClVsRef, ReachesTheSameEquilibrium) {
  const Mesh m = slab();
  SolveOptions o = options(method());
  o.residual_tolerance = 1e-4;
  o.velocity_tolerance_m_s = 1e-5;
  o.kitasaka_tolerance_m = 1e-7;
  // Newmark's inner loop: float32 stalls near 1e-6 of max |a|; a tolerance just above it keeps the
  // device from spending every step's iterations at its noise floor.
  o.newmark_inner_tolerance = 1e-5;
  o.newmark_max_inner = 20;
  o.max_steps = 400000;
  const SolveResult ref = solve(m, o);
  const SolveResult dev = solve_opencl(*ctx(), m, o);
  ASSERT_TRUE(ref.converged) << ref.stop_reason;
  ASSERT_TRUE(dev.converged) << dev.stop_reason;
  const double u = max_displacement(m, ref.x);
  EXPECT_LE(max_distance(ref.x, dev.x), 1e-3 * u) << "displacement " << u << " m, steps " << ref.steps << "/"
                                                  << dev.steps;
  EXPECT_EQ(dev.inverted_tetrahedra, 0);
}

// Snapshots from the device: the same steps as the CPU reference shows for the same run (both monitor on
// the same steps; 40 steps under the full load, no convergence), and positions within the N-steps bound
// above (1e-4 of the displacement) of the reference's at each.
TEST_P(SolverClVsRef, SnapshotsMatchTheReference) {
  const Mesh m = slab();
  SolveOptions o = options(method());
  o.ramp_s = 0.0;
  o.max_steps = 40;
  o.kitasaka_tolerance_m = 1e-9;   // run all 40 steps (the default stops this small slab early)
  o.snapshot_every_steps = 10;
  std::vector<std::pair<int64_t, std::vector<Vec3>>> ref_shots, dev_shots;
  SolveOptions ro = o, dop = o;
  ro.on_snapshot = [&](const SolverSnapshot& s) { ref_shots.push_back({s.step, s.x}); };
  dop.on_snapshot = [&](const SolverSnapshot& s) { dev_shots.push_back({s.step, s.x}); };
  const SolveResult ref = solve(m, ro);
  solve_opencl(*ctx(), m, dop);
  ASSERT_GE(ref_shots.size(), 2u);
  ASSERT_EQ(dev_shots.size(), ref_shots.size());
  const double u = max_displacement(m, ref.x);
  for (std::size_t i = 0; i < ref_shots.size(); ++i) {
    EXPECT_EQ(dev_shots[i].first, ref_shots[i].first);
    EXPECT_LE(max_distance(dev_shots[i].second, ref_shots[i].second), 1e-4 * u) << "snapshot " << i;
  }
}

std::string name(const ::testing::TestParamInfo<std::tuple<std::string, SolverMethod>>& info) {
  return testing_support::spec_name(std::get<0>(info.param)) + "_" + enum_name(std::get<1>(info.param));
}

class NewmarkClBeyondStable : public ::testing::TestWithParam<std::string> {};

// Newmark-β's inner loop beyond its stable step fails cleanly on the device too, naming the
// parameter and the estimate.
TEST_P(NewmarkClBeyondStable, FailsCleanly) {
  Progress::set_enabled(false);
  const Mesh m = slab();
  SolveOptions o = options(SolverMethod::Newmark);
  o.forces.damping = false;
  o.dt_s = 3.0 * stable_time_step(m, false);
  o.max_steps = 200;
  auto ctx = ocl::Context::shared(ocl::parse_device_spec(GetParam()));
  try {
    solve_opencl(*ctx, m, o);
    FAIL() << "Newmark ran at 3x its stable step";
  } catch (const DivergedError& e) {
    EXPECT_NE(std::string(e.what()).find("solver.dt_ms"), std::string::npos) << e.what();
  }
}

}  // namespace

GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(SolverClVsRef);
INSTANTIATE_TEST_SUITE_P(OpenCL, SolverClVsRef,
                         ::testing::Combine(::testing::ValuesIn(testing_support::opencl_device_specs()),
                                            ::testing::Values(SolverMethod::Explicit, SolverMethod::Newmark,
                                                              SolverMethod::Kitasaka2004, SolverMethod::Static)),
                         name);
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(NewmarkClBeyondStable);
INSTANTIATE_TEST_SUITE_P(OpenCL, NewmarkClBeyondStable, ::testing::ValuesIn(testing_support::opencl_device_specs()), [](const auto& info) { return testing_support::spec_name(info.param); });
