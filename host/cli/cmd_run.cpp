#include <cstdio>

#include "cl/cl_runtime.h"
#include "cli/commands.h"
#include "cli/device_option.h"
#include "cli/gl_backend_option.h"
#include "cli/scene_inputs_options.h"
#include "core/output_lock.h"
#include "pipeline/run.h"

namespace pneumo::cli {

Run add_run(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "run", "The whole case: roles, mesh, solver, warp, render and report.html into --out (what the demo runs)");
  struct Opts {
    SceneSource source;
    std::string out, device, backend = "auto";
    bool force = false, resume = false;
    int64_t timelapse = -1;
  };
  auto o = std::make_shared<Opts>();
  add_scene_source_options(cmd, o->source);
  cmd->add_option("--out", o->out, "Output folder")->required();
  add_device_option(cmd, o->device, "Overrides the scene's device");
  add_gl_backend_option(cmd, o->backend, "the views");
  cmd->add_flag("--force", o->force, "Replace the results of an earlier run in --out");
  cmd->add_flag("--resume", o->resume, "Continue an interrupted run in --out from its checkpoint.bin");
  cmd->add_option("--timelapse", o->timelapse,
                  "Inflation preview: warp and render the first view and the exterior views every N solver steps "
                  "into --out/timelapse (overrides output.timelapse_every_steps; 0: off)")
      ->check(CLI::Range(int64_t(0), int64_t(1000000000)));
  return [=] {
    Scene scene = load_scene_source(o->source);
    if (!o->device.empty()) scene.device = o->device;
    ocl::parse_device_spec(scene.device);   // a bad --device is bad input before any work
    const OutputFolderLock lock(o->out);   // one pneumo at a time in --out (core/output_lock.h)
    RunOptions ro;
    ro.out_dir = o->out;
    ro.force = o->force;
    ro.resume = o->resume;
    ro.timelapse_every_steps = o->timelapse;
    ro.backend = parse_gl_backend(o->backend);
    const RunSummary s = run_pipeline(scene, ro);
    const auto& m = s.metrics;
    std::printf("run: %s (%s), anterior rise %.1f mm, cavity %.0f ml, %lld inverted tetrahedra, %d views, %.1f s in "
                "all; report %s\n",
                m.value("stop_reason", "").c_str(), s.converged ? "converged" : "NOT converged",
                m.value("anterior_rise_mm", 0.0), m.value("cavity_volume_ml", 0.0),
                (long long)m.value("inverted_tetrahedra", int64_t(0)), m["render"].value("views", 0),
                m["stage_seconds"].value("total", 0.0), s.report_path.c_str());
    return s.converged ? 0 : 1;
  };
}

}  // namespace pneumo::cli
