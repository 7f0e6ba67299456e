#pragma once
// `pneumo validate convergence`: one scene solved with several cube sizes, to show that the answer
// settles as the cubes shrink (mesh.h: the geometry is resolved at the voxel) and at what order.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scene/scene.h"

namespace pneumo {

struct ConvergenceRow {
  int cube_voxels = 0;                // L as given: voxels along the CT's coarsest axis
  CubeVoxels cube{0};                 // the voxels per axis of near-cubic cubes of cube_mm (cube_voxels_for_mm)
  double cube_mm = 0;                 // L × the CT's largest spacing
  Vec3 cube_edge_mm = Vec3::Zero();   // the edge each axis got
  double anterior_rise_mm = 0, cavity_volume_ml = 0, mean_wall_displacement_mm = 0;
  double viscera_posterior_motion_mm = 0;   // mean over the viscera's anterior half (cavity_measures.h)
  int64_t nodes = 0, inverted = 0, steps = 0;
  bool converged = false;
  double solve_seconds = 0;
};

/// Observed order p of a quantity f(h) = f₀ + C·hᵖ from its three finest sizes (any ratios), with
/// Richardson's f₀; order 0 and f₀ = the finest value when the differences do not shrink
/// monotonically (no asymptotic range yet).
struct ObservedOrder {
  double order = 0, extrapolated = 0;
  bool monotone = false;
};
ObservedOrder observed_order(const std::vector<double>& h, const std::vector<double>& f);

struct ConvergenceStudy {
  std::vector<ConvergenceRow> rows;   // in the order given: coarse to fine
  ObservedOrder rise, volume, wall, viscera;
  /// Largest change of rise and volume between the two finest sizes, relative to the finest.
  double finest_change_rise = 0, finest_change_volume = 0;
};

/// Solves `scene` with cubes of each L in `cube_voxels` (coarse to fine, at least 2) voxels along the CT's
/// coarsest axis, mesh.cube_mm = L × that spacing, so the finer axes take as many voxels as keep the cubes
/// near-cubic (on an isotropic grid: L on every axis); every other key as the scene says.
ConvergenceStudy convergence_study(const Scene& scene, const std::vector<int>& cube_voxels);
nlohmann::json to_json(const ConvergenceStudy& s);

}  // namespace pneumo
