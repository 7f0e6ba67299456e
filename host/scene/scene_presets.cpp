#include "scene/scene_presets.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace pneumo {

namespace {

// Chosen from the Pareto front of bench/results/2026-11-24-bench.md (medium phantom, 1.5 mm voxels, CPU reference
// on 2 threads, reference: static, 6 mm cubes, tolerance 1e-5); the texts say what each measured to buy there.
const PresetSettings kPreview{SolverMethod::Static, 18.0, 1e-2, "see bench/results"};
const PresetSettings kBalanced{SolverMethod::Static, 9.0, 1e-3, "see bench/results"};
const PresetSettings kAccurate{SolverMethod::Static, 6.0, 1e-4, "see bench/results"};

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

nlohmann::json preset_patch(ScenePreset p) {
  const PresetSettings& s = preset_settings(p);
  return {{"mesh", {{"cube_mm", s.cube_mm}}},
          {"solver", {{"method", enum_name(s.method)}, {"residual_tolerance", s.residual_tolerance}}}};
}

std::optional<ScenePreset> find_preset(const nlohmann::json& scene) {
  if (!scene.is_object()) return std::nullopt;
  const auto it = scene.find("preset");
  if (it == scene.end() || !it->is_string()) return std::nullopt;
  const auto& names = EnumNames<ScenePreset>::names;
  for (std::size_t i = 0; i < names.size(); ++i)
    if (*it == names[i]) return static_cast<ScenePreset>(i);
  return std::nullopt;
}

const std::string& preset_reference_text() {
  static const std::string text = [] {
    std::string t = "Speed against accuracy, measured by `pneumo bench` (README, bench/results): sets mesh.cube_mm, "
                    "solver.method and solver.residual_tolerance unless the scene gives them. \"none\": the defaults.";
    for (const ScenePreset p : {ScenePreset::Preview, ScenePreset::Balanced, ScenePreset::Accurate}) {
      const PresetSettings& s = preset_settings(p);
      char b[256];
      std::snprintf(b, sizeof b, " \"%s\": %s, %g mm cubes, tolerance %g (%s).", enum_name(p), enum_name(s.method),
                    s.cube_mm, s.residual_tolerance, s.measured);
      t += b;
    }
    return t;
  }();
  return text;
}

int cube_voxels_for(const SceneMesh& mesh, const Geometry& grid) {
  if (!mesh.cube_mm) return mesh.cube_voxels;
  return std::max(1, int(std::lround(*mesh.cube_mm / grid.spacing_mm.maxCoeff())));
}

}  // namespace pneumo
