// Determinism: the same scene on the same device gives bit-identical results and files from run
// to run. Compared: two runs of `simulate` on the small phantom (12 mmHg, static solver, coarser cubes) in
// one process, on the CPU reference with 2 OpenMP threads (the mesh is large enough for the force loop to
// run in parallel) and on every OpenCL device: the final positions and the whole convergence history
// bit for bit (tolerance zero), and every file write_simulation writes byte for byte, except the wall-clock
// timings in metrics.json (wall_time_s, stage_seconds and each pressure_curve point's wall_time_s), the
// one documented exception: they measure the machine, not the result, and are compared with those keys
// removed. Why it holds: every force is a per-node gather in a fixed order (no atomics, no reductions
// whose order depends on the thread count or the schedule); the device reduces its work-groups' partial
// results on the host in group order; the warp's lowest accepting tetrahedron wins whatever the order.
// Also: every solver on every device on the tiny case, and `pneumo run` (roles, mesh, solve, warp,
// render, report) twice as separate processes, every file it writes byte for byte with the same
// exception (the timings in metrics.json and render.json, and report.html, which prints them).
#include <gtest/gtest.h>

#include <omp.h>
#include <filesystem>

#include "cli_test_support.h"
#include "springs_support.h"
#include "tiny_case_support.h"
#include "core/progress.h"
#include "opencl_test_support.h"
#include "phantom/phantom.h"
#include "pipeline/scene_stages.h"
#include "pipeline/simulate.h"
#include "solve/solve_on_device.h"

namespace pneumo {
namespace {

using testing_support::ScratchDir;

/// The small phantom's scene with cubes twice as large as it asks (8,800 nodes and 45,000 springs: still
/// above the size from which the CPU force loop runs on threads) and a residual tolerance of 1e-2 (fewer
/// steps; every step is as deterministic as the next): a few seconds per pair of runs.
Scene phantom_scene(const ScratchDir& dir) {
  Progress::set_enabled(false);
  write_phantom_case(make_phantom(PhantomSize::Small), PhantomSize::Small, dir.path().string());
  Scene scene = load_scene(dir.file("scene.json"));
  scene.mesh.cube_voxels = CubeVoxels(2 * scene.mesh.cube_voxels.value()[0]);   // the phantom's one L, doubled
  scene.solver.residual_tolerance = 1e-2;
  return scene;
}

/// metrics.json or render.json without the wall-clock timings: the documented exception (docs/robustness.md).
nlohmann::json without_timings(nlohmann::json m) {
  m.erase("wall_time_s");
  m.erase("stage_seconds");
  m.erase("seconds");   // render.json
  if (m.contains("pressure_curve"))
    for (auto& p : m["pressure_curve"]) p.erase("wall_time_s");
  if (m.contains("warp")) {
    m["warp"].erase("seconds");
    m["warp"].erase("mvoxels_per_s");
  }
  return m;
}

void expect_identical_runs(Scene scene) {
  ScratchDir dir;
  const Simulation a = simulate_scene(scene), b = simulate_scene(scene);
  ASSERT_EQ(a.result.x.size(), b.result.x.size());
  ASSERT_TRUE(a.result.converged);
  EXPECT_EQ(a.result.steps, b.result.steps);
  int64_t differing = 0;
  for (std::size_t n = 0; n < a.result.x.size(); ++n) differing += a.result.x[n] != b.result.x[n];
  EXPECT_EQ(differing, 0) << "nodes whose final position differs between two runs on " << a.device;
  // The device that ran, not the one asked for: an OpenCL request runs there (no fallback allowed here).
  EXPECT_EQ(a.device.rfind(scene.device.rfind("opencl", 0) == 0 ? "opencl:" : "cpu", 0), 0u) << a.device;
  ASSERT_EQ(a.result.history.size(), b.result.history.size());
  for (std::size_t h = 0; h < a.result.history.size(); ++h) {
    EXPECT_EQ(a.result.history[h].residual, b.result.history[h].residual) << "history row " << h;
    EXPECT_EQ(a.result.history[h].max_displacement_m, b.result.history[h].max_displacement_m) << "history row " << h;
  }
  write_simulation(scene, a, dir.file("a"));
  write_simulation(scene, b, dir.file("b"));
  int files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir.file("a"))) {
    const std::string name = e.path().filename().string();
    SCOPED_TRACE(name);
    const std::string fa = testing_support::slurp(e.path().string()), fb = testing_support::slurp(dir.file("b/" + name));
    ++files;
    if (name == "metrics.json") {
      EXPECT_NE(fa, fb) << "the timings should differ; if they do not, the exception is not needed";
      EXPECT_EQ(without_timings(nlohmann::json::parse(fa)), without_timings(nlohmann::json::parse(fb)));
    } else {
      EXPECT_TRUE(fa == fb) << "differs between runs";
    }
  }
  EXPECT_GE(files, 6);
}

TEST(Determinism, CpuRunsAreBitIdenticalWithThreads) {
  ScratchDir dir;
  Scene scene = phantom_scene(dir);
  const int saved = omp_get_max_threads();
  omp_set_num_threads(2);
  expect_identical_runs(scene);
  omp_set_num_threads(saved);
}

TEST(Determinism, CpuResultDoesNotDependOnTheThreadCount) {
  // Compared: the same scene with 1 and with 2 OpenMP threads: final positions bit for bit. Each node's
  // force is summed by one thread in the mesh's order whatever the thread count, and every sum over
  // nodes (FIRE's power and norms, the residual) runs on one thread.
  ScratchDir dir;
  const Scene scene = phantom_scene(dir);
  const int saved = omp_get_max_threads();
  omp_set_num_threads(1);
  const Simulation one = simulate_scene(scene);
  omp_set_num_threads(2);
  const Simulation two = simulate_scene(scene);
  omp_set_num_threads(saved);
  ASSERT_EQ(one.result.x.size(), two.result.x.size());
  int64_t differing = 0;
  for (std::size_t n = 0; n < one.result.x.size(); ++n) differing += one.result.x[n] != two.result.x[n];
  EXPECT_EQ(differing, 0);
  EXPECT_EQ(one.result.steps, two.result.steps);
}

TEST(Determinism, SimulateWritesTheSameBytesWithOneOrTwoThreads) {
  // Compared: `pneumo --threads 1 simulate` against `--threads 2` on the small phantom at its own cubes
  // (about 50,000 nodes: above the size from which the forces, the stiffness and the Newton's CG product
  // run on threads), deformation.bin byte for byte. The default thread count follows the machine's load,
  // so without this the same command would answer differently on a busy and a quiet machine.
  ScratchDir dir;
  Progress::set_enabled(false);
  write_phantom_case(make_phantom(PhantomSize::Small), PhantomSize::Small, dir.path().string());
  for (const char* threads : {"1", "2"}) {
    const auto r = testing_support::run_pneumo(std::string("-q --threads ") + threads + " simulate " +
                                               dir.file("scene.json") + " --out " + dir.file(threads));
    ASSERT_EQ(r.code, 0) << r.err;
  }
  const nlohmann::json m = nlohmann::json::parse(testing_support::slurp(dir.file("1/metrics.json")));
  EXPECT_GT(m.at("nodes").get<int64_t>(), 20000) << "too small for the loops to run on threads";
  EXPECT_TRUE(testing_support::slurp(dir.file("1/deformation.bin")) == testing_support::slurp(dir.file("2/deformation.bin")))
      << "deformation.bin differs between one and two threads";
}

class DeterminismPerDevice : public ::testing::TestWithParam<std::string> {};

TEST_P(DeterminismPerDevice, OpenClRunsAreBitIdentical) {
  ScratchDir dir;
  Scene scene = phantom_scene(dir);
  scene.device = GetParam();
  expect_identical_runs(scene);
}

INSTANTIATE_TEST_SUITE_P(Devices, DeterminismPerDevice,
                         ::testing::ValuesIn(testing_support::opencl_device_specs()),
                         [](const ::testing::TestParamInfo<std::string>& i) {
                           return testing_support::spec_name(i.param);
                         });


/// Every solver on every device (the CPU reference and each OpenCL device): two runs of the tiny case in
/// one process end on the same positions bit for bit, after the same number of steps.
class DeterminismPerSolver : public ::testing::TestWithParam<std::tuple<std::string, std::string>> {};

TEST_P(DeterminismPerSolver, TwoRunsEndBitIdentical) {
  const auto& [method, device] = GetParam();
  ScratchDir dir;
  nlohmann::json j = testing_support::tiny_case_scene_json();
  j["solver"]["method"] = method;
  // The explicit, Newmark and 2004 schemes take the springs only; the others the default material.
  if (!solves_force_fields(*enum_from_name<SolverMethod>(method))) j["material"] = testing_support::springs_material_json();
  j["device"] = device;
  j["solver"]["allow_cpu_fallback"] = true;   // static on the finite elements has no device scheme
  Progress::set_enabled(false);
  const Scene scene = load_scene(testing_support::write_tiny_case(dir, j));
  const Simulation a = simulate_scene(scene), b = simulate_scene(scene);
  // Labelled by the device that ran: the CPU where OpenCL lacks the scheme, the device where it has it.
  const bool on_device = device != "cpu" && device_implements(solve_options_from_scene(scene));
  EXPECT_EQ(a.device.rfind(on_device ? "opencl:" : "cpu", 0), 0u) << a.device << " for " << method << " on " << device;
  EXPECT_EQ(a.device, b.device);
  ASSERT_EQ(a.result.x.size(), b.result.x.size());
  EXPECT_GT(a.result.steps, 0);
  EXPECT_EQ(a.result.steps, b.result.steps);
  int64_t differing = 0, moved = 0;
  for (std::size_t n = 0; n < a.result.x.size(); ++n) {
    differing += a.result.x[n] != b.result.x[n];
    moved += a.result.x[n] != a.mesh.rest_m[n];
  }
  EXPECT_GT(moved, 0) << "nothing moved: the comparison would be empty";
  EXPECT_EQ(differing, 0) << "nodes whose final position differs between two runs";
}

std::vector<std::string> every_device() {
  std::vector<std::string> devices{"cpu"};
  for (const std::string& d : testing_support::opencl_device_specs()) devices.push_back(d);
  return devices;
}

std::vector<std::tuple<std::string, std::string>> solver_device_pairs() {
  std::vector<std::tuple<std::string, std::string>> out;
  for (const char* m : {"static", "newton", "explicit", "newmark", "kitasaka2004"})
    for (const std::string& d : every_device()) out.emplace_back(m, d);
  return out;
}

INSTANTIATE_TEST_SUITE_P(SolversAndDevices, DeterminismPerSolver, ::testing::ValuesIn(solver_device_pairs()),
                         [](const ::testing::TestParamInfo<std::tuple<std::string, std::string>>& i) {
                           return std::get<0>(i.param) + "_" + testing_support::spec_name(std::get<1>(i.param));
                         });

/// `pneumo run` twice, as two processes (the second finds PoCL's kernel cache warm), on each device:
/// every file of the two folders byte for byte, metrics.json and render.json without their timings,
/// report.html not compared (it prints the timings); the output folder's own path, which some files
/// name, read as OUT in both.
class DeterminismOfRun : public ::testing::TestWithParam<std::string> {};

TEST_P(DeterminismOfRun, TwoProcessesWriteTheSameFiles) {
  ScratchDir dir;
  nlohmann::json j = testing_support::tiny_case_scene_json();
  j["device"] = GetParam();
  const std::string scene = testing_support::write_tiny_case(dir, j);
  for (const char* out : {"a", "b"}) {
    const testing_support::CliResult r = testing_support::run_pneumo("-q run " + scene + " --out " + dir.file(out));
    ASSERT_EQ(r.code, 0) << r.err;
  }
  const auto files = testing_support::tree(dir.file("a"));
  EXPECT_EQ(files, testing_support::tree(dir.file("b")));
  int compared = 0;
  for (const std::string& name : files) {
    const std::filesystem::path pa = dir.path() / "a" / name, pb = dir.path() / "b" / name;
    if (std::filesystem::is_directory(pa) || name == "report.html") continue;
    SCOPED_TRACE(name);
    // Paths name the output folder (render.json's "ct": OUT/deformed_ct.nii.gz): the same in both once named alike.
    auto read = [&](const std::filesystem::path& f, const char* out) {
      std::string text = testing_support::slurp(f.string());
      const std::string folder = dir.file(out);
      for (std::size_t at; (at = text.find(folder)) != std::string::npos;) text.replace(at, folder.size(), "OUT");
      return text;
    };
    const std::string fa = read(pa, "a"), fb = read(pb, "b");
    ++compared;
    if (name == "metrics.json" || name == "render.json") {
      EXPECT_EQ(without_timings(nlohmann::json::parse(fa)), without_timings(nlohmann::json::parse(fb)));
    } else {
      EXPECT_TRUE(fa == fb) << "differs between runs";
    }
  }
  for (const char* must : {"deformed_ct.nii.gz", "deformed_labels.nii.gz", "mesh_deformed.vtu", "metrics.json"})
    EXPECT_TRUE(files.count(must)) << must;
  EXPECT_GE(compared, 10);
}

INSTANTIATE_TEST_SUITE_P(Devices, DeterminismOfRun, ::testing::ValuesIn(every_device()),
                         [](const ::testing::TestParamInfo<std::string>& i) {
                           return testing_support::spec_name(i.param);
                         });

}  // namespace
}  // namespace pneumo
