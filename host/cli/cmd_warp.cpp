#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cl/cl_runtime.h"
#include "cli/commands.h"
#include "cli/device_option.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/input_file.h"
#include "core/output_lock.h"
#include "pipeline/warp_stage.h"

namespace pneumo::cli {

namespace {
/// Whether metrics.json already holds a warp's keys (a warp that wrote no images ran too).
bool warp_metrics_present(const std::string& path) {
  if (probe_file(path).kind == FileKind::Missing) return false;
  const auto j = nlohmann::json::parse(read_input_file(path, kMaxMetricsBytes, "the metrics", "metrics.json is a few kB"),
                                      nullptr, false);
  return !j.is_discarded() && j.is_object() && j.contains("warp");
}
}  // namespace

Run add_warp(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "warp", "Warp the CT and labels through a finished simulation in --out; writes deformed_ct.nii.gz, "
              "deformed_labels.nii.gz, slices_before_after.png and adds the cavity to metrics.json");
  struct Opts { std::string scene, out, device; bool force = false; };
  auto o = std::make_shared<Opts>();
  cmd->add_option("scene", o->scene, "Scene .json (the one simulated)")->required();
  cmd->add_option("--out", o->out, "Folder of `pneumo simulate SCENE --out DIR`; the results go there too")->required();
  add_device_option(cmd, o->device, "Overrides the scene's device");
  cmd->add_flag("--force", o->force, "Overwrite the results of an earlier warp in --out");
  return [=] {
    Scene scene = load_scene(o->scene);
    if (!o->device.empty()) scene.device = o->device;
    ocl::parse_device_spec(scene.device);   // a bad --device is bad input before any work
    const OutputFolderLock lock(o->out);   // one pneumo at a time in --out (core/output_lock.h)
    const std::string metrics_path = (std::filesystem::path(o->out) / "metrics.json").string();
    // metrics.json is written last (write_warp), so its warp keys mark a warp that finished; images
    // without them are what an interrupted warp left, replaced without --force.
    if (!o->force && warp_metrics_present(metrics_path))
      throw InputError(o->out + ": already holds a warp; use --force to overwrite");
    // A read-only folder is refused before the warp's work (write_warp checks again before writing).
    if (std::filesystem::exists(metrics_path)) check_writable_target(metrics_path);
    const WarpedCase w = warp_scene(scene, o->out);
    write_warp(scene, w, o->out);
    std::printf("warp on %s: %lld voxels carried, %lld gas, %lld unchanged; cavity %.0f ml (%lld voxels) in %.2f s; "
                "results in %s\n",
                w.result.device.c_str(), (long long)w.result.carried_voxels, (long long)w.result.gas_voxels,
                (long long)w.result.kept_voxels, w.cavity_volume_ml(), (long long)w.cavity_voxels(), w.seconds_warp,
                o->out.c_str());
    return 0;
  };
}

}  // namespace pneumo::cli
