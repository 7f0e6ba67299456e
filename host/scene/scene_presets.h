#pragma once
// Speed against accuracy in one key: a scene's "preset" ("preview", "balanced", "accurate") supplies the cube size,
// the solver and its tolerance, each measured by `pneumo bench` (bench/results/*-bench.md: wall time and
// displacement error against a converged fine solution on the medium phantom). Keys the scene gives itself win
// over the preset's, so a preset is a starting point, not a lock; "none" (the default) leaves the defaults.
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "core/geometry.h"
#include "scene/scene.h"

namespace pneumo {

/// The cube edge of a scene that sizes its cubes in no way (mesh.cube_voxels, mesh.cube_mm or a preset):
/// the balanced preset's, measured within 1 % of 3 mm cubes' rise and cavity on the real CT
/// (docs/performance.md). Nimura's 8 voxels were 24 mm on a 3 mm CT and 5.6 mm (846 k elements) on a
/// 0.7 mm one.
inline constexpr double kDefaultCubeMm = 9.0;

struct PresetSettings {
  SolverMethod method = SolverMethod::Static;       // for the springs (material.model "msd")
  SolverMethod fem_method = SolverMethod::Newton;   // for the finite elements
  double cube_mm = 9.0;
  double residual_tolerance = 1e-3;
  const char* measured = "";   // what the committed benchmark measured it to buy (for the reference)
};

/// The settings of a preset other than None (std::invalid_argument for None).
const PresetSettings& preset_settings(ScenePreset p);

/// The solver a preset picks for a material model: the springs' `method`, the finite elements' `fem_method`.
SolverMethod preset_method(const PresetSettings& s, MaterialModel model);

/// {"mesh": {"cube_mm": …}, "solver": {"method": …, "residual_tolerance": …}}: what parsing merges under a scene
/// whose material.model is `model`.
nlohmann::json preset_patch(ScenePreset p, MaterialModel model);

/// The preset a scene's JSON names, when it names a known one (top-level "preset").
std::optional<ScenePreset> find_preset(const nlohmann::json& scene);

/// The reference text of the "preset" key: each preset's settings and what it measured to buy.
const std::string& preset_reference_text();

/// The cube voxels of a scene's mesh on a grid: cube_mm when set (per axis the nearest whole number of voxels, at
/// least 1: cube_voxels_for_mm), else cube_voxels, else kDefaultCubeMm's.
CubeVoxels cube_voxels_for(const SceneMesh& mesh, const Geometry& grid);

}  // namespace pneumo
