#include <filesystem>
#include <iostream>

#include "cl/cl_runtime.h"
#include "cli/commands.h"
#include "cli/device_option.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/output_lock.h"
#include "pipeline/simulate.h"

namespace pneumo::cli {

Run add_simulate(CLI::App& app) {
  auto* cmd = app.add_subcommand("simulate", "Inflate the abdomen: roles, mesh and solver; writes meshes and metrics.json");
  struct Opts { std::string scene, out, device; bool force = false; };
  auto o = std::make_shared<Opts>();
  cmd->add_option("scene", o->scene, "Scene .json")->required();
  cmd->add_option("--out", o->out, "Output folder")->required();
  add_device_option(cmd, o->device, "Overrides the scene's device");
  cmd->add_flag("--force", o->force, "Overwrite the results of an earlier run in --out");
  return [=] {
    Scene scene = load_scene(o->scene);
    if (!o->device.empty()) scene.device = o->device;
    ocl::parse_device_spec(scene.device);   // a bad --device is bad input before any work
    const OutputFolderLock lock(o->out);   // one pneumo at a time in --out (core/output_lock.h)
    if (std::filesystem::exists(std::filesystem::path(o->out) / "metrics.json") && !o->force)
      throw InputError(o->out + ": already holds a simulation (metrics.json); use --force to overwrite");
    // The lock created --out if it was missing and removes it again if this run is refused on the
    // way (bad roles, a diverging solver) before writing: nothing is left behind, not even a folder.
    check_creatable_folder(o->out);
    const Simulation sim = simulate_scene(scene);
    std::error_code ec;
    std::filesystem::create_directories(o->out, ec);
    if (ec) throw InputError(o->out + ": cannot create the output folder (" + ec.message() + ")");
    write_simulation(scene, sim, o->out);
    const auto m = simulation_metrics(scene, sim);
    std::printf("%s: %s after %lld steps (%s), residual %.2e, anterior rise %.1f mm, cavity %.0f ml, %lld inverted "
                "tetrahedra; results in %s\n",
                m["solver"].get<std::string>().c_str(), m["stop_reason"].get<std::string>().c_str(),
                (long long)m["steps"].get<int64_t>(), m["converged"].get<bool>() ? "converged" : "NOT converged",
                m["residual"].get<double>(), m["anterior_rise_mm"].get<double>(), m["cavity_volume_ml"].get<double>(),
                (long long)m["inverted_tetrahedra"].get<int64_t>(), o->out.c_str());
    return m["converged"].get<bool>() ? 0 : 1;
  };
}

}  // namespace pneumo::cli
