#pragma once
// `pneumo run`: the whole case in one command, roles → mesh → solve → warp → render → report, into
// one folder. Each stage is the one its own subcommand runs (simulate, warp, render), so a run's
// files are the same files; the run adds landmarks, plots, per-stage timings and report.html.
//
// Nothing lost: an existing output folder is refused without --force (or --resume); the inputs are
// read and checked before the folder is touched, and an earlier run's files are removed only at the
// first write (after the solve, unless checkpoints or the preview write during it), so bad input or a
// solve that diverges or stops leaves them as they were; every file is written atomically;
// report.html is written last, so a folder without it is not a finished run.
// With solver.checkpoint_every_steps the solver's positions go to checkpoint.bin as it runs, and
// --resume continues from there: the static solver relaxes on from the saved shape and pressure;
// a dynamic solver restarts from rest velocities at the saved shape, which changes the path it
// takes, not the equilibrium it reaches.
#include <nlohmann/json.hpp>
#include <string>

#include "render/gl_context.h"
#include "scene/scene.h"

namespace pneumo {

struct RunOptions {
  std::string out_dir;
  bool force = false;    // replace the outputs of an earlier run
  bool resume = false;   // continue from out_dir/checkpoint.bin when there is one
  int64_t timelapse_every_steps = -1;   // the inflation preview; -1: the scene's output.timelapse_every_steps
  GlBackend backend = GlBackend::Auto;
};

struct RunSummary {
  nlohmann::json metrics;     // what metrics.json holds at the end
  std::string report_path;
  bool converged = false;
};

RunSummary run_pipeline(const Scene& scene, const RunOptions& options);

}  // namespace pneumo
