#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "cl/cl_runtime.h"
#include "cli/commands.h"
#include "cli/device_option.h"
#include "cli/gl_backend_option.h"
#include "core/atomic_file.h"
#include "core/output_lock.h"
#include "pipeline/ports_run.h"

namespace pneumo::cli {

Run add_ports(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "ports", "Rank candidate ports on the inflated skin for a target organ; writes ports.json (the ranked table) "
               "and ports_heat_map.png into --out (docs/ports.md)");
  struct Opts {
    std::string scene, out = "out/ports", device, backend = "auto";
    int target = 0, width = 640, height = 480;
    double grid_mm = 20.0, fov_deg = 70.0;
    bool json = false, force = false, cpu = false;
  };
  auto o = std::make_shared<Opts>();
  cmd->add_option("scene", o->scene, "Scene .json (with a label map)")->required();
  cmd->add_option("--target-label", o->target, "The target organ's label id (e.g. 5 = liver in TotalSegmentator)")
      ->required();
  cmd->add_option("--out", o->out,
                  "Output folder; a finished `pneumo simulate`/`pneumo run` of the scene there is reused, else the "
                  "scene is solved first")
      ->capture_default_str();
  cmd->add_option("--grid-mm", o->grid_mm, "Spacing of the candidates on the skin (mm, 2-200)");
  cmd->add_option("--fov-deg", o->fov_deg, "The scope's field of view for the visibility term (degrees)");
  cmd->add_option("--size", o->width, "Width of the heat map (pixels; height 3/4 of it)");
  add_device_option(cmd, o->device, "The solve's device when one is needed (overrides the scene's)");
  add_gl_backend_option(cmd, o->backend, "the heat map");
  cmd->add_flag("--cpu", o->cpu, "Render the heat map with the CPU reference ray caster");
  cmd->add_flag("--json", o->json, "Print the ranked table (ports.json) on standard output");
  cmd->add_flag("--force", o->force, "Replace the ports.json of an earlier ranking in --out");
  return [=] {
    Scene scene = load_scene(o->scene);
    if (!o->device.empty()) scene.device = o->device;
    ocl::parse_device_spec(scene.device);
    PortsRunOptions ro;
    ro.out_dir = o->out;
    ro.rank.target_label = o->target;
    ro.rank.grid_mm = o->grid_mm;
    ro.rank.fov_deg = o->fov_deg;
    ro.backend = parse_gl_backend(o->backend);
    ro.cpu_render = o->cpu;
    ro.force = o->force;
    ro.width = o->width;
    ro.height = std::max(16, o->width * 3 / 4);
    const OutputFolderLock lock(o->out);
    check_creatable_folder(o->out);
    const PortsRun run = run_ports(scene, ro);
    if (o->json) {
      std::printf("%s\n", run.table.dump(2).c_str());
    } else {
      const auto& t = run.table;
      std::printf("ports for %s (label %d): %d of %zu candidates feasible; best first:\n",
                  t["target"]["name"].get<std::string>().c_str(), o->target, t["feasible_candidates"].get<int>(),
                  t["candidates"].size());
      const double exposed = t["target"]["exposed_voxels"].get<double>(), surface = t["target"]["surface_voxels"].get<double>();
      if (exposed < 0.05 * surface)
        std::printf("  only %.0f of its %.0f surface voxels (%.1f %%) face the gas: the rest needs retraction, which the "
                    "model does not do\n", exposed, surface, 100.0 * exposed / surface);
      std::printf("  rank  score  visible  clearance  to target  elevation  skin point on the CT (mm)\n");
      for (const auto& c : t["candidates"]) {
        if (!c["feasible"].get<bool>() || c["rank"].get<int>() > 5) break;
        const auto& s = c["skin_point_mm"];
        std::printf("  %4d  %5.2f  %6.0f%%  %6s mm  %6.0f mm  %7.0f°   %s\n", c["rank"].get<int>(),
                    c["score"].get<double>(), 100.0 * c["visible_fraction"].get<double>(),
                    c["clearance_mm"].is_null() ? "-" : std::to_string(int(c["clearance_mm"].get<double>())).c_str(),
                    c["skin_to_target_mm"].get<double>(), c["elevation_deg"].get<double>(),
                    s.is_null() ? "(not carried back)" : s.dump().c_str());
      }
      std::printf("results in %s and %s\n", run.json_path.c_str(), run.heat_map_path.c_str());
    }
    return run.converged ? 0 : 1;
  };
}

}  // namespace pneumo::cli
