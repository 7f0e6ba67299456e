#include "scene/scene_presets.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace pneumo {

namespace {

// Chosen from the Pareto front of bench/results/2026-11-23-bench.md: the medium phantom (1.5 mm voxels) at 12 mmHg,
// errors at skin and cavity-surface points against the static solver at 4.5 mm cubes and tolerance 1e-5. The cube
// size is what buys accuracy there: below 1e-2 the tolerance changed the error by < 0.05 mm at every cube size, and
// the dynamic schemes reached the static solver's error at the same cube size in 10-400× the time. "accurate" keeps
// 1e-3 as a margin for cases stiffer or more nonlinear than the phantom. Since the geometry is resolved at the voxel
// the phantom's front allows coarser cubes (bench/results/2026-12-05-bench.md); the sizes stay, as the real CT's
// convergence study supports them (docs/fidelity.md §4). The texts say what each measured to buy in that last run
// (solve time on all threads, RMS / max error).
//
// The finite elements take Newton at every preset (bench/results/2026-12-05-bench.md, the real CT): on the FEM
// example scene, with its soft, compressible viscera, the static solver (FIRE) diverges at every preset where Newton
// converges in 15-23 iterations (on 2026-12-02, on the stiffer viscera then, it did not finish within 300 s at 9 and
// 6 mm cubes; docs/fem.md). The solver follows the model; the model stays the scene's physics.
//
// The elements' figures: the real CT (scenes/totalseg_example.json, the default material) solved by Newton on the
// CPU, and its rise and warped cavity against the 3 mm cubes' answer (docs/fidelity.md §4); the solve times
// re-measured after the assembled stiffness (bench/results/2026-12-06-presets-real-ct.md), the answers unchanged.
const PresetSettings kPreview{SolverMethod::Static, SolverMethod::Newton, 12.0, 1e-2,
                              "the elements on the real CT: solve 1.9 s, rise +2.7 % and cavity +4.0 % of the 3 mm "
                              "answer; the springs on the medium phantom: solve 0.36 s, error RMS 0.93 mm, max 5.6 mm"};
const PresetSettings kBalanced{SolverMethod::Static, SolverMethod::Newton, 9.0, 1e-2,
                               "the elements on the real CT: solve 5.0 s, rise +0.9 % and cavity +0.9 % of the 3 mm "
                               "answer; the springs on the medium phantom: solve 0.86 s, error RMS 0.90 mm, max 10.6 mm"};
const PresetSettings kAccurate{SolverMethod::Static, SolverMethod::Newton, 6.0, 1e-3,
                               "the elements on the real CT: solve 32.0 s, rise -0.5 % and cavity -1.6 % of the 3 mm "
                               "answer; the springs on the medium phantom: solve 5.4 s, error RMS 0.64 mm, max 4.8 mm"};

}  // namespace

const PresetSettings& preset_settings(ScenePreset p) {
  switch (p) {
    case ScenePreset::Preview: return kPreview;
    case ScenePreset::Balanced: return kBalanced;
    case ScenePreset::Accurate: return kAccurate;
    case ScenePreset::None: break;
  }
  throw std::invalid_argument("preset \"none\" has no settings");
}

SolverMethod preset_method(const PresetSettings& s, MaterialModel model) {
  return model == MaterialModel::Msd ? s.method : s.fem_method;
}

nlohmann::json preset_patch(ScenePreset p, MaterialModel model) {
  const PresetSettings& s = preset_settings(p);
  return {{"mesh", {{"cube_mm", s.cube_mm}}},
          {"solver", {{"method", enum_name(preset_method(s, model))}, {"residual_tolerance", s.residual_tolerance}}}};
}

std::optional<ScenePreset> find_preset(const nlohmann::json& scene) {
  if (!scene.is_object()) return std::nullopt;
  const auto it = scene.find("preset");
  if (it == scene.end() || !it->is_string()) return std::nullopt;
  return enum_from_name<ScenePreset>(it->get<std::string>());
}

const std::string& preset_reference_text() {
  static const std::string text = [] {
    std::string t = "Speed against accuracy, measured by `pneumo bench` (docs/performance.md, bench/results/2026-12-05-bench.md; "
                    "CPU, all threads): sets mesh.cube_mm, solver.method and solver.residual_tolerance unless the scene "
                    "gives them. The finite elements (the default material) take newton at every preset, where the "
                    "static solver diverged on the real CT (docs/fem.md); the springs (material.model msd) take the "
                    "solver that was fastest for them. \"none\": the defaults.";
    for (const ScenePreset p : {ScenePreset::Preview, ScenePreset::Balanced, ScenePreset::Accurate}) {
      const PresetSettings& s = preset_settings(p);
      char b[512];
      std::snprintf(b, sizeof b, " \"%s\": %g mm cubes, tolerance %g, %s for the elements and %s for the springs (%s).",
                    enum_name(p), s.cube_mm, s.residual_tolerance, enum_name(s.fem_method), enum_name(s.method),
                    s.measured);
      t += b;
    }
    return t;
  }();
  return text;
}

CubeVoxels cube_voxels_for(const SceneMesh& mesh, const Geometry& grid) {
  if (!mesh.cube_mm && mesh.cube_voxels) return *mesh.cube_voxels;
  if (!mesh.cube_mm) return cube_voxels_for_mm(kDefaultCubeMm, grid.spacing_mm);
  // Per axis, not by the coarsest spacing: on 0.7 × 0.7 × 2.5 mm voxels one L from the coarsest axis made
  // 9 mm cubes 2.8 × 2.8 × 10 mm, twelve times the elements of 9 mm cubes, for no accuracy in z.
  return cube_voxels_for_mm(*mesh.cube_mm, grid.spacing_mm);
}

}  // namespace pneumo
