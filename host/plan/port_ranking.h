#pragma once
// Ranking candidate ports on the inflated skin for one target (docs/ports.md): what a
// surgeon weighs when choosing where a trocar goes, measured on the deformed labels and CT.
//
// Candidates lie on a regular grid over the anterior skin (the first voxel at or above skin_hu,
// the exterior views' iso-surface, seen from in front along each axial column), in front of the
// target's centroid. Each is judged on
// the straight path of an instrument from its skin point to the target: to the target's centroid
// (or the target voxel nearest it) when that path is open, else to the point of the target's
// gas-facing surface nearest that line whose path is open (an organ is worked on where it faces
// the gas):
//   - feasible: the path reaches the gas within a trocar's length (max_wall_mm) crossing only the
//     wall's own layers, and runs through gas to the target with no organ in between (a run of
//     other tissue longer than kBlockToleranceVoxels voxels along the path blocks it);
//   - visibility: the share of the target's surface voxels that a scope at the port sees, its tip
//     eye_depth_mm into the gas, aimed along the path: within its field of view, nothing but gas
//     before the ray reaches the voxel (neither another organ nor the target's own front). Only the
//     gas-facing surface can be seen, so that is what is sampled; the term is this share against
//     the best candidate's;
//   - clearance: the smallest distance from the path in the gas to another labelled structure (an
//     organ, a vessel, bone; the wall's own layers excepted);
//   - distance: skin to target along the path, against Emam, Hanna & Cuschieri 2000 (Arch Surg 135:
//     62–65): a standard 360 mm instrument works best with at least half its length inside;
//   - elevation: the path's angle to the horizontal plane (the patient supine), 30–60° as Hanna,
//     Shimi & Cuschieri 1997 (Surg Endosc 11:397–401) found best;
//   - triangulation, with other ports given: the manipulation angle at the target between this
//     port's path and another's, 45–75° (Hanna 1997), and at least 50 mm of skin between ports.
// The score is the weighted mean of the terms (each 0–1, docs/ports.md gives their ramps); an
// infeasible port scores 0 and says why.
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/geometry.h"

namespace pneumo {

/// Other tissue a path in the gas may cross before it counts as blocked: the gas/tissue boundary's
/// partial-volume staircase on the deformed labels, not an organ in the way.
inline constexpr double kBlockToleranceVoxels = 1.5;

struct PortRankWeights {
  double visibility = 0.35, clearance = 0.25, distance = 0.15, elevation = 0.15, triangulation = 0.10;
};

struct PortRankOptions {
  int target_label = 0;
  uint16_t gas_label = 0;        // the cavity's id in the deformed labels (output.cavity_label)
  double grid_mm = 20.0;         // candidate spacing on the skin, laterally and cranio-caudally
  double fov_deg = 70.0;         // the scope's field of view, aimed along the path
  double eye_depth_mm = 20.0;    // the scope's tip beyond the gas entry (at most halfway to the target)
  double max_wall_mm = 100.0;    // a standard trocar's working length: a thicker wall is not crossed
  double skin_hu = -500.0;       // the skin's iso-value (pipeline/exterior_views.h)
  int target_samples = 400;      // gas-facing target voxels tested for visibility (evenly spread)
  std::vector<Vec3> other_ports_mm;   // skin points of ports already placed, deformed frame
  PortRankWeights weights;
};

/// Why a candidate cannot serve as a port.
enum class PortProblem {
  None,
  NoGas,          // the path meets the target before any gas
  WallTooThick,   // no gas within max_wall_mm of the skin (deeper, or none on the path)
  CrossesOrgan,   // the trocar would cross a labelled structure (blocking_label) before the gas
  Blocked,        // a structure (blocking_label; 0: unlabelled tissue) lies between the gas and the target
};
const char* port_problem_name(PortProblem p);   // "none", "no_gas", "wall_too_thick", ...

struct PortCandidate {
  Vec3 skin_mm = Vec3::Zero();        // deformed frame
  Vec3 aim_mm = Vec3::Zero();         // the target point the path runs to
  Vec3 gas_entry_mm = Vec3::Zero();   // where the path enters the gas (feasible ports)
  PortProblem problem = PortProblem::None;
  int blocking_label = 0;
  double score = 0.0;
  double visible_fraction = 0.0;      // of the target's whole surface (surface_voxels)
  double skin_to_target_mm = 0.0;     // along the path to the target's surface
  double wall_mm = 0.0;               // skin to gas entry
  double elevation_deg = 0.0;
  double clearance_mm = 0.0;          // +inf when no other structure is labelled
  int nearest_label = 0;              // the structure at clearance_mm
  double spacing_mm = std::numeric_limits<double>::quiet_NaN();        // to the nearest other port
  double manipulation_deg = std::numeric_limits<double>::quiet_NaN();  // the best angle with another port
  // The terms the score averages (0–1).
  double t_visibility = 0, t_clearance = 0, t_distance = 0, t_elevation = 0, t_triangulation = 0;

  bool feasible() const { return problem == PortProblem::None; }
};

struct PortRanking {
  Vec3 target_centroid_mm = Vec3::Zero();
  Vec3 target_aim_mm = Vec3::Zero();   // the centroid, or the target voxel nearest it when it lies outside
  int64_t target_voxels = 0;
  int64_t surface_voxels = 0;          // target voxels on its boundary
  int64_t exposed_voxels = 0;          // those touching the gas: all a scope can see, an instrument reach
  std::vector<int> wall_layer_labels;   // labels most trocars cross before the gas (skin, fat, muscle)
  std::vector<PortCandidate> candidates;   // best first, the infeasible last
};

/// The ramps of the terms (0–1), one place for the ranking and the docs' table.
double visibility_term(double share_of_best);   // the visible fraction over the best candidate's
double clearance_term(double clearance_mm);     // 0 at 0 mm, 1 from 20 mm
double distance_term(double skin_to_target_mm); // 0 at 60, 1 over 180–240, 0 at 300 mm
double elevation_term(double elevation_deg);    // 0 at 0°, 1 over 30–60°, 0 at 90°
double spacing_term(double spacing_mm);         // 0 at 20 mm, 1 from 50 mm
double manipulation_term(double angle_deg);     // 0 at 15°, 1 over 45–75°, 0 at 105°

/// InputError for options no ranking takes: a target outside 1–65535 or the gas's own label, a grid
/// or field of view out of range. rank_ports checks them first; a caller with long work before the
/// ranking (a solve) checks them before it.
void check_rank_options(const PortRankOptions& o);

/// Ranks the candidates on deformed labels and CT (i fastest on `g`, world mm RAS). InputError
/// when the target label holds no voxel, or no skin is found.
PortRanking rank_ports(const uint16_t* labels, const float* ct_hu, const Geometry& g, const PortRankOptions& o);

}  // namespace pneumo
