#include "report/metric_names.h"

#include <array>
#include <map>

namespace pneumo {
namespace {

struct Entry {
  const char* key;
  const char* name;
  const char* unit;
  const char* group;
  double scale;
};

// clang-format off
constexpr Entry kEntries[] = {
    {"anterior_rise_mm", "Anterior rise of the abdominal wall", "mm", "Result", 1},
    {"cavity_volume_ml", "Insufflated cavity (warped CT)", "ml", "Result", 1},
    {"mesh_cavity_volume_ml", "Insufflated cavity (mesh)", "ml", "Result", 1},
    {"cavity_largest_piece_ml", "Largest connected piece of the cavity", "ml", "Result", 1},
    {"cavity_outside_largest_piece_fraction", "Cavity outside its largest piece", "%", "Result", 100},
    {"gas_anterior_to_prevesical_labels_ml", "Gas in front of the bladder, bowel between or not", "ml", "Result", 1},
    {"gas_short_of_intraperitoneal_organs_ml", "Gas in front of the bladder, no bowel between", "ml", "Result", 1},
    {"gas_in_prevesical_space_ml", "Gas in the space of Retzius (on tissue no bowel covered at rest)", "ml", "Result", 1},
    {"max_wall_displacement_mm", "Largest wall displacement", "mm", "Result", 1},
    {"mean_wall_displacement_mm", "Mean wall displacement", "mm", "Result", 1},
    {"mean_viscera_displacement_mm", "Mean viscera displacement", "mm", "Result", 1},
    {"mean_viscera_anterior_displacement_mm", "Mean anterior displacement of the viscera", "mm", "Result", 1},
    {"anterior_viscera_posterior_motion_mm", "Posterior motion of the anterior viscera", "mm", "Result", 1},
    {"viscera_volume_change_ml", "Change of the viscera's tissue volume", "ml", "Result", 1},
    {"wall_skin_area_cm2", "The wall's skin at rest (anterior and lateral)", "cm²", "Result", 1},
    {"wall_skin_area_change_fraction", "Growth of the wall's whole skin", "%", "Result", 100},
    {"anterior_skin_area_cm2", "The anterior skin at rest (within 60° of straight ahead)", "cm²", "Result", 1},
    {"anterior_skin_area_change_fraction", "Growth of the anterior skin (patients: +15 %, Song 2006)", "%", "Result", 100},
    {"diaphragm_cranial_shift_mm", "The diaphragm's cranial shift, median over the lung bases in view", "mm", "Result", 1},
    {"diaphragm_dome_cranial_shift_mm", "The diaphragm's cranial shift where it rose most (95th percentile)", "mm", "Result", 1},
    {"organ_motion.label", "Label", "", "Result", 1},
    {"organ_motion.name", "Structure", "", "Result", 1},
    {"organ_motion.volume_ml", "Volume at rest", "ml", "Result", 1},
    {"organ_motion.volume_change_fraction", "Volume change in the label images", "%", "Result", 100},
    {"organ_motion.tissue_volume_change_fraction", "The tissue's volume change (the deformation's J)", "%", "Result", 100},
    {"organ_motion.shift_right_mm", "Centroid shift to the right", "mm", "Result", 1},
    {"organ_motion.shift_anterior_mm", "Centroid shift anteriorly", "mm", "Result", 1},
    {"organ_motion.shift_superior_mm", "Centroid shift cranially", "mm", "Result", 1},
    {"max_fixed_displacement_mm", "Largest displacement of a fixed node", "mm", "Result", 1},
    {"deformed_body_outside_grid_mm", "Deformed body beyond the output grid", "mm", "Result", 1},
    {"inverted_tetrahedra", "Inverted tetrahedra", "", "Result", 1},
    {"pressure_mmhg", "Insufflation pressure", "mmHg", "Model", 1},
    {"solver", "Solver", "", "Solver", 1},
    {"device", "Device that ran the solve", "", "Solver", 1},
    {"device_requested", "Device the scene asked for", "", "Solver", 1},
    {"device_fallback", "Why the CPU ran it instead", "", "Solver", 1},
    {"converged", "Converged", "", "Solver", 1},
    {"stop_reason", "Why the solver stopped", "", "Solver", 1},
    {"steps", "Solver steps", "", "Solver", 1},
    {"force_evaluations", "Force evaluations", "", "Solver", 1},
    {"inner_iterations", "Inner (CG) iterations", "", "Solver", 1},
    {"residual", "Final residual (net force / pressure force)", "", "Solver", 1},
    {"dt_ms", "Time step", "ms", "Solver", 1},
    {"dt_stable_ms", "Stable time step", "ms", "Solver", 1},
    {"wall_time_s", "Solver wall time", "s", "Solver", 1},
    {"gravity_compensation.sag_mm", "Gravity compensation: sag of the CT shape", "mm", "Solver", 1},
    {"gravity_compensation.error_mm", "Gravity compensation: remaining error", "mm", "Solver", 1},
    {"cube_voxels", "Mesh cube edge (per axis when they differ)", "voxels", "Model", 1},
    {"cube_edge_mm", "Mesh cube edge per axis (i, j, k)", "mm", "Model", 1},
    {"nodes", "Mesh nodes", "", "Model", 1},
    {"tetrahedra", "Tetrahedra (elements)", "", "Model", 1},
    {"springs", "Springs", "", "Model", 1},
    {"pressure_tetrahedra", "Tetrahedra carrying pressure", "", "Model", 1},
    {"fixed_nodes", "Fixed nodes", "", "Model", 1},
    {"cut_face_nodes", "Nodes sliding on the CT's cut faces (mesh.cut_faces)", "", "Model", 1},
    {"thorax_nodes", "Nodes of the cranial cut that open onto the chest", "", "Model", 1},
    {"thorax_compliance_l_per_cmh2o", "Compliance of the lungs beyond the cranial cut", "L/cmH2O", "Model", 1},
    {"thorax_volume_change_ml", "Volume pushed into the chest through the cranial cut", "ml", "Result", 1},
    {"thorax_pressure_cmh2o", "Pleural pressure rise beyond the cranial cut", "cmH2O", "Result", 1},
    {"wall_cubes", "Wall cubes", "", "Model", 1},
    {"viscera_cubes", "Viscera cubes", "", "Model", 1},
    {"doubled_cubes", "Cubes split between wall and viscera", "", "Model", 1},
    {"cavity_faces", "Cavity faces (voxel faces under pressure)", "", "Model", 1},
    {"roles_ml.wall", "Abdominal wall", "ml", "Model", 1},
    {"scan_coverage.summary", "What the scan covers", "", "Model", 1},
    {"scan_coverage.warnings", "What the scan misses", "", "Model", 1},
    {"scan_coverage.top_cuts_body", "Top slice cuts the body", "", "Model", 1},
    {"scan_coverage.top_body_fraction", "Body section at the top slice, of the widest", "%", "Model", 100},
    {"scan_coverage.top_structures", "Structures in the top slice", "", "Model", 1},
    {"scan_coverage.bottom_cuts_body", "Bottom slice cuts the body", "", "Model", 1},
    {"scan_coverage.bottom_body_fraction", "Body section at the bottom slice, of the widest", "%", "Model", 100},
    {"scan_coverage.bottom_structures", "Structures in the bottom slice", "", "Model", 1},
    {"scan_coverage.lungs_in_view", "Lungs in view (the diaphragm's dome)", "", "Model", 1},
    {"scan_coverage.pelvis_in_view", "Pelvis in view (hip, sacrum or bladder)", "", "Model", 1},
    {"scan_coverage.wall_cut_laterally", "Field of view cuts the wall at a side", "", "Model", 1},
    {"scan_coverage.wall_cut_anteriorly", "Field of view cuts the wall in front", "", "Model", 1},
    {"roles_ml.viscera", "Viscera", "ml", "Model", 1},
    {"roles_ml.fixed", "Fixed structures", "ml", "Model", 1},
    {"cavity_voxels", "Cavity voxels", "", "Warp", 1},
    {"cavity_specks_filled.pieces", "Cavity specks filled", "", "Warp", 1},
    {"cavity_specks_filled.voxels", "Cavity speck voxels filled", "", "Warp", 1},
    {"cavity_specks_filled.below_ml", "Specks filled below", "ml", "Warp", 1},
    {"warp.seconds", "Warp time", "s", "Warp", 1},
    {"warp.mvoxels_per_s", "Warp rate", "Mvoxel/s", "Warp", 1},
    {"warp.carried_voxels", "Voxels carried by the mesh", "", "Warp", 1},
    {"warp.kept_voxels", "Voxels kept in place", "", "Warp", 1},
    {"warp.gas_voxels", "Voxels that became gas", "", "Warp", 1},
    {"warp.cavity_label", "Cavity label id", "", "Warp", 1},
    {"warp.cavity_centroid_mm", "Cavity centroid", "mm", "Warp", 1},
    {"warp.device", "Warp device", "", "Warp", 1},
    {"render.views", "Views rendered", "", "Other", 1},
    {"render.frames", "Fly-through frames", "", "Other", 1},
    {"render.deformed_ct", "Rendered from the deformed CT", "", "Other", 1},
    {"pneumo_version", "pneumo version", "", "Other", 1},
    {"scene", "Scene file", "", "Other", 1},
    {"pipeline_complete", "Pipeline complete", "", "Other", 1},
    // Columns of an array's table whose own key's name would say something else: the curve's cavity
    // is the mesh's estimate at each pressure, not the warped CT's voxels that cavity_volume_ml counts.
    {"pressure_curve.cavity_volume_ml", "Insufflated cavity (mesh)", "ml", "Other", 1},
};
// clang-format on

// Suffix → unit (and scale) for keys without an entry.
struct Suffix {
  const char* suffix;
  const char* unit;
  double scale;
};
constexpr Suffix kSuffixes[] = {{"_mm", "mm", 1},     {"_ml", "ml", 1},      {"_mmhg", "mmHg", 1}, {"_kpa", "kPa", 1},
                                {"_ms", "ms", 1},     {"_s", "s", 1},        {"_seconds", "s", 1}, {"_deg", "°", 1},
                                {"_fraction", "%", 100}, {"_percent", "%", 1}, {"_pa", "Pa", 1}};

bool ends_with(const std::string& s, const std::string& e) {
  return s.size() >= e.size() && s.compare(s.size() - e.size(), e.size(), e) == 0;
}

}  // namespace

MetricName metric_name(const std::string& key) {
  for (const Entry& e : kEntries)
    if (key == e.key) return {e.name, e.unit, e.group, e.scale};
  MetricName m;
  m.group = "Other";
  std::string stem = key;
  // The longest matching suffix ("_seconds" before "_s").
  std::size_t best = 0;
  for (const Suffix& s : kSuffixes)
    if (ends_with(key, s.suffix) && std::string(s.suffix).size() > best) {
      best = std::string(s.suffix).size();
      m.unit = s.unit;
      m.scale = s.scale;
    }
  stem = key.substr(0, key.size() - best);
  for (char& c : stem)
    if (c == '_') c = ' ';
    else if (c == '.') c = ':';
  if (!stem.empty() && stem[0] >= 'a' && stem[0] <= 'z') stem[0] = char(stem[0] - 'a' + 'A');
  m.name = stem;
  return m;
}

MetricName column_name(const std::string& array_key, const std::string& column) {
  const std::string nested = array_key + "." + column;
  for (const Entry& e : kEntries)
    if (nested == e.key) return {e.name, e.unit, e.group, e.scale};
  return metric_name(column);
}

std::vector<std::string> listed_metric_keys() {
  std::vector<std::string> keys;
  for (const Entry& e : kEntries) keys.push_back(e.key);
  return keys;
}

const std::vector<std::string>& metric_groups() {
  static const std::vector<std::string> g{"Result", "Solver", "Model", "Warp", "Other"};
  return g;
}

const std::vector<std::string>& pipeline_stage_order() {
  static const std::vector<std::string> s{"roles", "mesh", "solve", "warp", "render", "report", "total"};
  return s;
}

}  // namespace pneumo
