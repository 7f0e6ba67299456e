// A mesh that would not fit in the device's memory is refused before allocating, with the
// estimate: the estimates the solvers and the warp check against the device (ctx.check_fits) must
// cover what they then allocate, or a case that passes the check can still fail half-way. Compared,
// on every OpenCL device and for a mesh the pipeline built (the tiny case: small enough that the
// fixed-size buffers and the one-entry paddings weigh in), the estimate against the sum of the sizes
// of every buffer created (clCreateBuffer, counted below) while the solve or the warp runs.
#include <dlfcn.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdint>

#include "cl/cl_runtime.h"
#include "core/log.h"
#include "core/progress.h"
#include "opencl_test_support.h"
#include "pipeline/scene_stages.h"
#include "pipeline/simulate.h"
#include "pipeline/warp_stage.h"
#include "scene/scene.h"
#include "solve/fem_force_field_cl.h"
#include "solve/interface_tie.h"
#include "solve/newton_cl.h"
#include "solve/solver_cl.h"
#include "tiny_case_support.h"
#include "warp/warp.h"

namespace {
std::atomic<bool> g_counting{false};
std::atomic<uint64_t> g_buffer_bytes{0};
}  // namespace

// Every buffer pneumo creates goes through here (the executable's definition comes first): its size
// is counted while g_counting is set, then the ICD loader's clCreateBuffer creates it.
extern "C" CL_API_ENTRY cl_mem CL_API_CALL clCreateBuffer(cl_context context, cl_mem_flags flags, size_t size,
                                                          void* host_ptr, cl_int* errcode_ret) {
  using Create = cl_mem (*)(cl_context, cl_mem_flags, size_t, void*, cl_int*);
  static const Create next = reinterpret_cast<Create>(dlsym(RTLD_NEXT, "clCreateBuffer"));
  if (g_counting) g_buffer_bytes += size;
  return next(context, flags, size, host_ptr, errcode_ret);
}

namespace pneumo {
namespace {

using namespace testing_support;

/// Bytes of the buffers `work` creates.
template <class Work>
uint64_t allocated_by(Work&& work) {
  g_buffer_bytes = 0;
  g_counting = true;
  work();
  g_counting = false;
  return g_buffer_bytes;
}

class DeviceMemoryEstimate : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    Progress::set_enabled(false);
    log::set_level(log::Level::Quiet);
    scene_ = load_scene(write_tiny_case(dir_));
    use_nimura_springs(scene_.material);   // solve_opencl is the springs' device solve; the elements' estimate is its own test
    scene_.solver.method = SolverMethod::Static;   // one the springs have on the device (Newton's is the CPU's)
    scene_.device = GetParam();
    sim_ = prepare_simulation(scene_);
    ctx_ = ocl::Context::shared(ocl::parse_device_spec(GetParam()));
  }
  void TearDown() override { log::set_level(log::Level::Info); }
  ScratchDir dir_;
  Scene scene_;
  Simulation sim_;
  std::shared_ptr<ocl::Context> ctx_;
};

TEST_P(DeviceMemoryEstimate, EverySolverAllocatesNoMoreThanItsEstimate) {
  const uint64_t estimate = solver_device_bytes(sim_.mesh);
  uint64_t most = 0;
  for (SolverMethod method :
       {SolverMethod::Static, SolverMethod::Explicit, SolverMethod::Newmark, SolverMethod::Kitasaka2004}) {
    SolveOptions o = solve_options_from_scene(scene_);
    o.method = method;
    o.max_steps = 20;
    o.progress = false;
    const uint64_t allocated = allocated_by([&] { solve_opencl(*ctx_, sim_.mesh, o); });
    EXPECT_GT(allocated, 0u) << enum_name(method) << ": the count saw no buffer";
    EXPECT_LE(allocated, estimate) << enum_name(method) << ": allocated " << allocated << " bytes, estimated "
                                   << estimate;
    std::printf("%s: %llu bytes allocated, %llu estimated\n", enum_name(method), (unsigned long long)allocated,
                (unsigned long long)estimate);
    most = std::max(most, allocated);
  }
  // Not a refusal of cases that fit: the estimate bounds each block's spring records by the mesh's
  // largest node degree, which overstates, but by less than twice what the hungriest solver allocates.
  EXPECT_LT(estimate, 2 * most) << "the estimate would refuse meshes that fit";
}

TEST_P(DeviceMemoryEstimate, TheFiniteElementsAllocateNoMoreThanTheirEstimate) {
  // The OpenCL finite elements (fem_force_field_cl.h): everything their construction, an evaluation,
  // a stiffness product and the diagonal blocks create, against fem_force_field_cl_bytes; and the
  // estimate within twice of it (it bounds the groups by one per tetrahedron).
  const uint64_t estimate = fem_force_field_cl_bytes(sim_.mesh);
  ForceModel model;
  model.material = MaterialModel::FemNeoHookean;
  model.pressure_pa = 1600.0;
  const uint64_t allocated = allocated_by([&] {
    auto field = make_fem_force_field_cl(*ctx_, sim_.mesh, model.material);
    std::vector<Vec3> f, kp;
    std::vector<Mat3> blocks;
    field->evaluate(model, sim_.mesh.rest_m, {}, f);
    field->linearize(model, sim_.mesh.rest_m);
    field->stiffness_product(f, kp);
    field->stiffness_diagonal(blocks);
  });
  std::printf("finite elements: %llu bytes allocated, %llu estimated\n", (unsigned long long)allocated,
              (unsigned long long)estimate);
  EXPECT_GT(allocated, 0u);
  EXPECT_LE(allocated, estimate);
  EXPECT_LT(estimate, 2 * allocated) << "the estimate would refuse meshes that fit";
}

TEST_P(DeviceMemoryEstimate, NewtonsDeviceSolveAllocatesNoMoreThanItsEstimate) {
  // Newton's linear solve on the device (newton_cl.h) with every pair of the interface bonded: what its
  // construction, a linearisation and a solve create, against newton_linear_solver_cl_bytes; and the
  // estimate within twice of it. The field's own buffers are counted by the test above.
  ForceModel model;
  model.material = MaterialModel::FemNeoHookean;
  model.pressure_pa = 1600.0;
  model.tie_interface = true;
  auto field = make_fem_force_field_cl(*ctx_, sim_.mesh, model.material);
  const std::vector<TiedPair> ties = interface_pairs(sim_.mesh);
  std::vector<Vec3> f;
  field->evaluate(model, sim_.mesh.rest_m, {}, f);
  const uint64_t allocated = allocated_by([&] {
    auto solver = field->device_linear_solver(ties);
    ASSERT_NE(solver, nullptr);
    solver->linearize(model, sim_.mesh.rest_m);
    Shift shift;
    std::vector<Vec3> d;
    solver->solve(f, 0.1, 20, shift, d);
  });
  const uint64_t estimate = newton_linear_solver_cl_bytes(sim_.mesh, ties.size());
  std::printf("Newton's device solve: %llu bytes allocated, %llu estimated (%zu bonds)\n",
              (unsigned long long)allocated, (unsigned long long)estimate, ties.size());
  EXPECT_GT(allocated, 0u);
  EXPECT_LE(allocated, estimate);
  EXPECT_LT(estimate, 2 * allocated) << "the estimate would refuse meshes that fit";
}

TEST_P(DeviceMemoryEstimate, TheWarpAllocatesExactlyItsEstimate) {
  Volume ct = read_volume(scene_.require_ct());
  Volume labels = read_volume(scene_.inputs.labels);
  const Geometry grid = ct.geometry();
  Deformation at_rest;
  at_rest.displacement_m.assign(sim_.mesh.rest_m.size(), Vec3::Zero());
  std::optional<WarpedCase> w;
  const uint64_t allocated = allocated_by([&] {
    w = warp_solved(scene_, std::move(ct), std::move(labels), std::move(sim_.roles), std::move(sim_.mesh),
                    std::move(at_rest));
  });
  const uint64_t estimate = warp_device_bytes(w->warp_mesh, true, WarpBox{w->roles.pad.lo, grid.dims});
  EXPECT_GT(allocated, 0u) << "the count saw no buffer";
  EXPECT_EQ(allocated, estimate) << "the warp's estimate counts every buffer it creates";
  std::printf("warp: %llu bytes allocated, %llu estimated\n", (unsigned long long)allocated,
              (unsigned long long)estimate);
}

}  // namespace

GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(DeviceMemoryEstimate);
INSTANTIATE_TEST_SUITE_P(OpenCL, DeviceMemoryEstimate, ::testing::ValuesIn(testing_support::opencl_device_specs()),
                         [](const auto& info) { return testing_support::spec_name(info.param); });

}  // namespace pneumo
