#include "pipeline/ports_run.h"

#include <chrono>
#include <filesystem>
#include <optional>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/log.h"
#include "core/units.h"
#include "image/png.h"
#include "io/volume_io.h"
#include "mesh/deformation_file.h"
#include "pipeline/exterior_views.h"
#include "pipeline/port_planning.h"
#include "pipeline/render_scene.h"
#include "pipeline/simulate.h"
#include "pipeline/warp_stage.h"
#include "render/renderer.h"

namespace pneumo {

namespace fs = std::filesystem;

namespace {

/// The case inflated: a finished simulation in `dir` warped again (seconds), or solved here.
WarpedCase inflated_case(const Scene& scene, const std::string& dir, std::optional<Volume> labels, bool& reused,
                         bool& converged) {
  reused = fs::exists(fs::path(dir) / "deformation.bin") && fs::exists(fs::path(dir) / "metrics.json");
  if (reused) {
    log::info("ports: the simulation in " + dir + " reused");
    WarpedCase w = warp_scene(scene, dir);
    converged = w.deformation.converged;
    return w;
  }
  log::info("ports: no simulation in " + dir + ": solving the scene first");
  Simulation sim = simulate_scene(scene);
  converged = sim.result.converged;
  if (!converged) log::warn("ports: the solve stopped short of convergence; its last shape is ranked");
  Deformation solved;
  solved.displacement_m = displacements(sim.mesh, sim.result.x);
  solved.pressure_pa = sim.result.final_pressure_pa;
  solved.converged = sim.result.converged;
  return warp_solved(scene, read_volume(scene.require_ct()), std::move(labels), std::move(sim.roles),
                     std::move(sim.mesh), std::move(solved));
}

}  // namespace

PortsRun run_ports(const Scene& scene, const PortsRunOptions& o) {
  if (scene.inputs.labels.empty())
    throw InputError("ports: the scene gives no label map (inputs.labels): a target is an organ's label");
  PortsRun run;
  run.json_path = (fs::path(o.out_dir) / "ports.json").string();
  run.heat_map_path = (fs::path(o.out_dir) / "ports_heat_map.png").string();
  if (!o.force && fs::exists(run.json_path))
    throw InputError(o.out_dir + ": already holds ports.json; use --force to replace it");
  if (!(o.width >= 16 && o.width <= 4096 && o.height >= 16 && o.height <= 4096))
    throw InputError("the heat map must be 16 to 4096 pixels on each side");
  // The options and the target checked before any solve (minutes at `accurate`).
  PortRankOptions ro = o.rank;
  ro.gas_label = uint16_t(scene.output.cavity_label);
  check_rank_options(ro);
  const std::map<int, std::string> names = scene_label_names(scene);
  Volume input_labels = read_volume(scene.inputs.labels);
  {
    bool present = false;
    for (int64_t n = 0; n < input_labels.voxel_count() && !present; ++n) present = input_labels.value(n) == ro.target_label;
    if (!present)
      throw InputError("label " + std::to_string(ro.target_label) + " holds no voxel in " + scene.inputs.labels +
                       ": no target to rank ports for");
  }

  const WarpedCase w = inflated_case(scene, o.out_dir, std::move(input_labels), run.reused_simulation, run.converged);
  const double ranked_mmhg = w.deformation.pressure_pa / units::kPaPerMmHg;   // the shape's, not the scene's
  const PointMap map = w.point_map();
  std::vector<SkinMark> placed;
  for (const Port& p : scene.render.ports) {
    const MappedPoint d = map.to_deformed(p.skin_point_mm);
    ro.other_ports_mm.push_back(d.point_mm);
    placed.push_back({p.name, d.point_mm});
  }
  const auto t0 = std::chrono::steady_clock::now();
  const PortRanking ranking = rank_ports(w.result.labels.data(), w.result.ct_hu.data(), w.output_grid, ro);
  const double rank_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double step_mm = 0.5 * w.output_grid.spacing_mm.minCoeff();
  run.table = port_ranking_json(ranking, ro, names, candidates_on_ct(ranking, map, step_mm), map);
  run.table["seconds"] = rank_s;
  run.table["pressure_mmhg"] = ranked_mmhg;
  run.table["converged"] = run.converged;
  run.table["simulation"] = run.reused_simulation ? "reused from " + o.out_dir : "solved for this ranking";

  // The heat map on the anterior exterior view of the inflated body.
  RenderVolume volume = render_volume_of(w.result, w.output_grid);
  volume.smoothing_mm = scene.render.smoothing_mm;
  Renderer renderer(o.cpu_render, o.backend);
  renderer.set_volume(volume);
  const RenderSettings base = settings_from_scene(scene.render, volume.geometry);
  const ExteriorCamera c = *exterior_camera(volume.geometry, "anterior", o.width, o.height);
  const RenderImage image = renderer.render(c.camera, skin_settings(base, c.camera, volume.geometry));
  char caption[160];
  std::snprintf(caption, sizeof caption, "ports for %s, %.0f mmHg", run.table["target"]["name"].get<std::string>().c_str(),
                ranked_mmhg);
  const RgbImage heat = port_heat_map(image, c.camera, ranking, caption, placed);
  // ports.json last: a folder with the map and without it holds an interrupted ranking, which the
  // next one replaces without --force (as the warp's images without its metrics).
  fs::create_directories(o.out_dir);
  write_png(run.heat_map_path, heat);
  write_text_file_atomic(run.json_path, run.table.dump(2) + "\n");
  return run;
}

}  // namespace pneumo
