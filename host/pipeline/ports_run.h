#pragma once
// `pneumo ports SCENE --target-label N --out DIR`: candidate ports for one target ranked on the
// inflated case (pipeline/port_planning.h), written as DIR/ports.json (the ranked table) and
// DIR/ports_heat_map.png (the scores on the inflated skin). A finished simulation in DIR (from
// `pneumo simulate` or `pneumo run` of the same scene) is reused; otherwise the case is solved and
// warped in memory first, and only the two files are written.
#include <nlohmann/json.hpp>
#include <string>

#include "plan/port_ranking.h"
#include "render/gl_context.h"
#include "scene/scene.h"

namespace pneumo {

struct PortsRunOptions {
  std::string out_dir;
  PortRankOptions rank;          // target_label, grid_mm, fov_deg; gas_label and other ports from the scene
  GlBackend backend = GlBackend::Auto;
  bool cpu_render = false;       // the heat map's view with the CPU reference ray caster
  bool force = false;            // replace an earlier ports.json
  int width = 640, height = 480;   // the heat map's size (pixels)
};

struct PortsRun {
  nlohmann::json table;          // what ports.json holds
  std::string json_path, heat_map_path;
  bool reused_simulation = false;
  bool converged = true;          // the shape ranked on is an equilibrium
};

/// InputError for a target the deformed labels lack, an existing ports.json without `force`, or
/// bad options; the folder is touched only once the ranking is done.
PortsRun run_ports(const Scene& scene, const PortsRunOptions& options);

}  // namespace pneumo
