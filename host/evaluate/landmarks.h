#pragma once
// Nimura's evaluation (method.md §9): landmarks carried through the deformation, and, when a tracker
// measured them on the patient, the tracker frame aligned to the CT by Horn's closed-form method on
// the pre-insufflation points, then position and per-axis displacement errors.
#include <functional>
#include <nlohmann/json.hpp>
#include <vector>

#include "core/geometry.h"
#include "scene/scene.h"

namespace pneumo {

/// A rigid motion q ≈ R·p + t.
struct RigidTransform {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Vec3 t = Vec3::Zero();
  Vec3 apply(const Vec3& p) const { return R * p + t; }
};

/// Horn (1987), unit quaternions: the rotation and translation minimising Σ‖q_i − (R p_i + t)‖².
/// Throws InputError when there are fewer than 3 pairs or the points lie on a line (the rotation
/// about that line is then undetermined).
RigidTransform horn_rigid(const std::vector<Vec3>& p, const std::vector<Vec3>& q);

struct LandmarkResult {
  std::string name;
  Vec3 ct_mm, simulated_mm;                 // before (CT) and simulated after
  bool measured = false;
  Vec3 measured_after_ct_mm = Vec3::Zero(); // the tracker's after-point in the CT frame
};

struct LandmarkEvaluation {
  std::vector<LandmarkResult> points;
  bool measured = false;                    // tracker measurements were given
  RigidTransform tracker_to_ct;
  double alignment_rms_mm = 0;              // Horn's residual on the pre-insufflation pairs
  double position_error_mm = 0;             // mean ‖simulated − measured‖ after
  Vec3 displacement_error_mm = Vec3::Zero();// mean |simulated − measured displacement| per axis:
                                            // horizontal (R–L), ventrodorsal (A–P), cephalocaudal (S–I)
};

LandmarkEvaluation evaluate_landmarks(const std::vector<Landmark>& marks, const PointMapFn& map);
nlohmann::json to_json(const LandmarkEvaluation& e);

}  // namespace pneumo
