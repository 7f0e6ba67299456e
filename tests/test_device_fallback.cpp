// The device that ran, not the one asked for (solve/solve_on_device.h, pipeline/simulate.h): on every
// OpenCL device, a scene whose solver OpenCL does not implement (the static scheme on the finite
// elements) is refused before its roles are built, unless solver.allow_cpu_fallback; allowed, it solves
// on the CPU and metrics.json says so (device "cpu", the request, and why). A solver the device does
// implement (Newton on the finite elements) reports the device itself.
#include <gtest/gtest.h>

#include "core/error.h"
#include "core/progress.h"
#include "opencl_test_support.h"
#include "pipeline/simulate.h"
#include "scene/scene.h"
#include "solve/solve_on_device.h"
#include "tiny_case_support.h"

using namespace pneumo;
using namespace pneumo::testing_support;

namespace {

Scene tiny_scene(const ScratchDir& dir, const std::string& device, const char* method, bool allow) {
  nlohmann::json j = tiny_case_scene_json();
  j["device"] = device;
  j["solver"] = {{"method", method}, {"allow_cpu_fallback", allow}};
  return load_scene(write_tiny_case(dir, j));
}

class DeviceFallback : public ::testing::TestWithParam<std::string> {};

TEST_P(DeviceFallback, AnUnimplementedSolverIsRefusedOrReportedAsTheCpus) {
  Progress::set_enabled(false);
  const std::string spec = GetParam();
  ScratchDir dir;
  // Refused, naming the way out, before the roles (prepare_simulation's first step).
  try {
    (void)simulate_scene(tiny_scene(dir, spec, "static", false));
    ADD_FAILURE() << "the static scheme on the finite elements ran on " << spec;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot run this solve"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("solver.allow_cpu_fallback"), std::string::npos) << e.what();
  }
  // Allowed: the CPU runs it, and metrics.json says so.
  const Scene allowed = tiny_scene(dir, spec, "static", true);
  const Simulation fell = simulate_scene(allowed);
  ASSERT_TRUE(fell.result.converged) << fell.result.stop_reason;
  const nlohmann::json m = simulation_metrics(allowed, fell);
  EXPECT_EQ(m.at("device"), "cpu");
  EXPECT_EQ(m.at("device_requested"), spec);
  ASSERT_TRUE(m.contains("device_fallback"));
  EXPECT_NE(m.at("device_fallback").get<std::string>().find("not static with fem-neohookean"), std::string::npos)
      << m.at("device_fallback");
  // Implemented: the device itself, no fallback.
  const Scene newton = tiny_scene(dir, spec, "newton", false);
  const Simulation ran = simulate_scene(newton);
  const nlohmann::json n = simulation_metrics(newton, ran);
  EXPECT_EQ(n.at("device").get<std::string>().rfind("opencl:", 0), 0u) << n.at("device");
  EXPECT_FALSE(n.contains("device_fallback"));
}

TEST_P(DeviceFallback, SolveOnDeviceRefusesWhatItCannotRunUnlessAllowed) {
  // The same at the stage's own entry, for callers that skip the scene's early check (the benchmarks).
  Progress::set_enabled(false);
  ScratchDir dir;
  const Scene scene = tiny_scene(dir, "cpu", "static", false);
  const Simulation sim = prepare_simulation(scene);
  SolveOptions opt = solve_options_from_scene(scene);
  auto ctx = ocl::Context::shared(ocl::parse_device_spec(GetParam()));
  EXPECT_THROW(solve_on_device(ctx.get(), sim.mesh, opt), InputError);
  opt.allow_cpu_fallback = true;
  const SolveResult r = solve_on_device(ctx.get(), sim.mesh, opt);
  EXPECT_EQ(r.device, "cpu");
  EXPECT_EQ(r.device_fallback.rfind(ctx->info().spec(), 0), 0u) << r.device_fallback;
  const SolveResult cpu = solve_on_device(nullptr, sim.mesh, opt);
  EXPECT_EQ(cpu.device, "cpu");
  EXPECT_TRUE(cpu.device_fallback.empty());
}

}  // namespace

GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(DeviceFallback);
INSTANTIATE_TEST_SUITE_P(OpenCL, DeviceFallback, ::testing::ValuesIn(opencl_device_specs()),
                         [](const auto& info) { return spec_name(info.param); });
