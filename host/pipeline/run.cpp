#include "pipeline/run.h"

#include <chrono>
#include <cstdio>
#include <climits>
#include <memory>
#include <optional>
#include <filesystem>
#include <fstream>

#include "core/atomic_file.h"
#include "core/stopwatch.h"
#include "core/error.h"
#include "core/input_file.h"
#include "core/log.h"
#include "core/owned_folder.h"
#include "core/units.h"
#include "evaluate/landmarks.h"
#include "io/volume_io.h"
#include "mesh/deformation_file.h"
#include "pipeline/render_scene.h"
#include "pipeline/report_views.h"
#include "pipeline/simulate.h"
#include "pipeline/timelapse.h"
#include "pipeline/warp_stage.h"
#include "report/report_html.h"
#include "report/role_png.h"

namespace pneumo {

namespace {

namespace fs = std::filesystem;

/// What a run writes at the top of its folder, and the folders it fills: an earlier run's copies are
/// removed before a forced run, so nothing stale sits beside the new results.
const char* const kRunFiles[] = {"report.html",       "metrics.json",           "render.json",
                                 "deformed_ct.nii.gz", "deformed_labels.nii.gz", "deformed_labels.ctbl",
                                 "deformed_labels_itksnap.txt", "displacement_field.nii.gz",
                                 "displacement_field_transform.h5", "slices_before_after.png",
                                 "mesh_initial.vtu",  "mesh_deformed.vtu",      "deformation.bin",
                                 "convergence.csv",   "convergence.svg",        "pressure_volume.csv",
                                 "pressure_volume.svg", "scene_used.json",      "roles.png"};
const char* const kRunFolders[] = {"views", "flythrough", "timelapse"};

/// The refusals that need no writing, before the inputs are read: an earlier run's results without
/// --force (or --resume), a folder of the user's where a run keeps its own (views/, …), an --out that
/// could not be created or written.
void check_output_folder(const RunOptions& o) {
  const fs::path out(o.out_dir);
  bool earlier = false;
  for (const char* f : kRunFiles) earlier |= fs::exists(out / f);
  for (const char* f : kRunFolders) {
    check_owned_or_absent(out / f);
    earlier |= is_owned_folder(out / f);
  }
  if (earlier && !o.force && !o.resume)
    throw InputError(o.out_dir + ": already holds results of a run; use --force to replace them or --resume to "
                                 "continue an interrupted one");
  check_creatable_folder(o.out_dir);
}

/// Removes an earlier run's files (the CLI's lock has created --out if it was missing): only once the
/// inputs have been read and checked, so that bad input leaves an earlier run's results as they were.
void prepare_folder(const RunOptions& o) {
  const fs::path out(o.out_dir);
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec) throw InputError(o.out_dir + ": cannot create the output folder (" + ec.message() + ")");
  check_writable_target((out / "report.html").string());
  // report.html goes first, so that an interrupted run never leaves the old one looking current.
  for (const char* f : kRunFiles) fs::remove(out / f, ec);
  for (const char* f : kRunFolders) remove_owned_folder(out / f);
}

nlohmann::json read_json(const std::string& path) {
  const auto j = nlohmann::json::parse(read_input_file(path, kMaxMetricsBytes, "the metrics", "metrics.json is a few kB"),
                                      nullptr, false);
  if (j.is_discarded()) throw file_error(path, "not valid JSON");
  return j;
}


}  // namespace

RunSummary run_pipeline(const Scene& scene, const RunOptions& o) {
  const auto t_run = std::chrono::steady_clock::now();
  check_output_folder(o);
  const fs::path out(o.out_dir);
  const std::string checkpoint = (out / "checkpoint.bin").string();

  // Simulate: roles, mesh, solver (from the checkpoint with --resume).
  log::info("stage 1/4: roles, mesh and solver");
  Simulation sim = prepare_simulation(scene, /*keep_inputs=*/true);   // the warp reads them too
  check_cavity_label_free(scene, sim.roles);
  check_port_targets(scene, sim.roles);   // a port the labels cannot aim is refused now, not after the solve
  scene_label_names(scene);   // a bad names file is refused now, not after the solve
  SolveHooks hooks;
  if (o.resume && fs::exists(checkpoint)) {
    const Deformation c = read_deformation(checkpoint, sim.mesh);
    hooks.x_start.resize(c.displacement_m.size());
    for (std::size_t n = 0; n < hooks.x_start.size(); ++n) hooks.x_start[n] = sim.mesh.rest_m[n] + c.displacement_m[n];
    hooks.start_pressure_pa = c.pressure_pa;
    log::info("resuming from " + checkpoint + " at " + std::to_string(c.pressure_pa / units::kPaPerMmHg) + " mmHg");
  } else if (o.resume) {
    log::info("no checkpoint in " + o.out_dir + ": starting from rest");
  }
  // One observer for checkpoints and the inflation preview, each on its own period.
  const int64_t every_checkpoint = scene.solver.checkpoint_every_steps;
  const int64_t every_frame = o.timelapse_every_steps >= 0 ? o.timelapse_every_steps : scene.output.timelapse_every_steps;
  std::unique_ptr<Timelapse> timelapse;
  if (every_frame > 0) timelapse = std::make_unique<Timelapse>(scene, sim, o.out_dir, o.backend);
  int64_t next_checkpoint = every_checkpoint, next_frame = 0;
  if (every_checkpoint > 0 || every_frame > 0) {
    hooks.snapshot_every_steps = std::min(every_checkpoint > 0 ? every_checkpoint : INT64_MAX,
                                          every_frame > 0 ? every_frame : INT64_MAX);
    hooks.on_snapshot = [&](const SolverSnapshot& s) {
      if (every_checkpoint > 0 && s.step >= next_checkpoint) {
        Deformation d;
        d.displacement_m = displacements(sim.mesh, s.x);
        d.pressure_pa = s.pressure_pa;
        write_deformation(checkpoint, sim.mesh, d);
        next_checkpoint = (s.step / every_checkpoint + 1) * every_checkpoint;
      }
      if (timelapse && s.step >= next_frame) {
        timelapse->frame(s);
        next_frame = (s.step / every_frame + 1) * every_frame;
      }
    };
  }
  // The folder is touched at the first write: before the solve when it writes checkpoints or preview
  // frames, else after it, so that a solve that diverges or stops leaves an earlier run as it was.
  const bool writes_while_solving = hooks.on_snapshot != nullptr;
  if (writes_while_solving) prepare_folder(o);
  solve_simulation(scene, sim, hooks);
  if (!writes_while_solving) prepare_folder(o);
  write_roles_png(sim.roles, (out / "roles.png").string());
  if (timelapse) {
    timelapse->frame(SolverSnapshot{sim.result.steps, 0.0, sim.result.final_pressure_pa, sim.result.x});
    log::info("inflation preview: " + std::to_string(timelapse->finish()) + " frames in " +
              (out / "timelapse").string());
  }
  write_simulation(scene, sim, o.out_dir);
  std::error_code ec;
  fs::remove(checkpoint, ec);   // the finished solve's shape is deformation.bin now

  // Warp, then render with the warp's point mapping (ports travel with the skin).
  log::info("stage 2/4: warp");
  // The simulation's roles, mesh and shape, not rebuilt, and the input volumes as the roles stage
  // read them (the roles keep a padded float copy; the outputs need the originals' grids and types).
  Deformation solved;
  solved.displacement_m = displacements(sim.mesh, sim.result.x);
  solved.pressure_pa = sim.result.final_pressure_pa;
  solved.converged = sim.result.converged;
  WarpedCase w = warp_solved(scene, std::move(*sim.inputs.ct), std::move(sim.inputs.labels),
                                   std::move(sim.roles), std::move(sim.mesh), std::move(solved));
  const PointMap point_map = w.point_map();
  const PointMapFn map = deformed_point_fn(point_map);

  log::info("stage 3/4: render");
  const auto t_render = std::chrono::steady_clock::now();
  RenderOptions ro;
  ro.out_dir = o.out_dir;
  ro.backend = o.backend;
  ro.map_point = map;
  ro.undeformed_ct = &w.ct;
  char caption[64];
  std::snprintf(caption, sizeof caption, "after inflation, %.1f mmHg", w.deformation.pressure_pa / units::kPaPerMmHg);
  ro.deformed_caption = caption;
  // The warped volumes from memory, not read back from the files just written.
  RenderRun what;
  what.deformed = true;
  what.ct_path = (out / "deformed_ct.nii.gz").string();
  if (w.labels) what.labels_path = (out / "deformed_labels.nii.gz").string();
  // The views first, from memory, and the warp's files after them: a user waits for the first view,
  // not for deflating 10⁸ voxels. A render that fails still leaves the warp's files written.
  // The views take the warp's own HU, rounded as the file holds them, and its 16-bit labels (no
  // copy of 10⁸ voxels), and give both back for the deformed CT and label map, built after the
  // views. The render reads them only (render_volumes takes a const RenderVolume&).
  RenderRun rendered;
  RenderVolume views;
  const auto take_back = [&] {
    if (!views.hu.empty()) w.result.ct_hu = std::move(views.hu);
    if (!views.labels.empty()) w.result.labels = std::move(views.labels);
  };
  try {
    const bool int16 = round_as_written(w.result.ct_hu, deformed_ct_type(w));
    views = RenderVolume::from_hu(w.output_grid, std::move(w.result.ct_hu), std::move(w.result.labels), int16);
    views.smoothing_mm = scene.render.smoothing_mm;
    rendered = render_volumes(scene, ro, views, what);
  } catch (...) {
    take_back();
    // The render's error is the one to report: a failure to write the warp's files is logged.
    try {
      write_warp(scene, w, o.out_dir);
    } catch (const std::exception& e) {
      log::warn(std::string("the warp's files could not be written after the render failed: ") + e.what());
    }
    throw;
  }
  take_back();
  const double seconds_render = seconds_since(t_render);
  log::info("writing the warped CT and labels");
  write_warp(scene, w, o.out_dir);

  // Report: landmarks, plots, metrics (complete), report.html last.
  log::info("stage 4/4: report");
  const auto t_report = std::chrono::steady_clock::now();
  nlohmann::json metrics = read_json((out / "metrics.json").string());
  if (!scene.landmarks.empty()) metrics["landmarks"] = to_json(evaluate_landmarks(scene.landmarks, map));
  metrics["render"] = {{"views", rendered.views}, {"frames", rendered.frames}, {"deformed_ct", rendered.deformed}};
  ReportContent rc;
  rc.title = "pneumo: " + (scene.name.empty() ? scene.path : scene.name);
  rc.description = scene.description;
  rc.scene = scene.echo();
  rc.plots.push_back({"Convergence", convergence_plot_svg(sim.result)});
  if (!sim.pressure_curve.empty()) rc.plots.push_back({"Pressure-volume curve", pressure_curve_plot_svg(sim.pressure_curve)});
  if (fs::exists(out / "slices_before_after.png"))
    rc.images.push_back({"Slices before and after", (out / "slices_before_after.png").string(),
                         "Axial, coronal and sagittal through the cavity's centre: the CT as given (top) and warped (bottom), the gas in blue."});
  rc.images.push_back({"Roles", (out / "roles.png").string(),
                       "What moves and what holds: wall orange, viscera green, fixed blue."});
  add_rendered_views(rc, rendered.report, scene.render, w.label_names, out);
  metrics["stage_seconds"]["render"] = seconds_render;
  metrics["stage_seconds"]["report"] = seconds_since(t_report);
  metrics["stage_seconds"]["total"] = seconds_since(t_run);
  metrics["pipeline_complete"] = true;
  rc.metrics = metrics;
  write_text_file_atomic((out / "metrics.json").string(), metrics.dump(2) + "\n");
  const std::string report = (out / "report.html").string();
  write_text_file_atomic(report, report_html(rc));

  RunSummary summary;
  summary.metrics = metrics;
  summary.report_path = report;
  summary.converged = sim.result.converged;
  return summary;
}

}  // namespace pneumo
