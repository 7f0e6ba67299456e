#pragma once
// How voxels become roles (method.md §2): the scene's "roles" section. By label lists, or by the
// automatic HU rules (auto_roles.h) with their thresholds, and the air padded around the CT (pad.h).
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "domain/types.h"

namespace pneumo {

struct RoleRules {
  // "auto": the HU rules fill in what the labels do not decide; a label map's named structures get their
  // roles by name (by_name), so a scene needs no lists.
  RoleSource source = RoleSource::Auto;
  std::vector<int> wall_labels, viscera_labels, fixed_labels, other_labels;
  Role unlisted_label_role = Role::Other;
  // Automatic extraction (§2, option). Limits: a single body (largest component), bone by HU only
  // (contrast-filled vessels above the threshold become fixed too), wall thickness uniform.
  double auto_body_threshold_hu = -500.0;  // air/lung < -500 < fat (about -100)
  double auto_bone_threshold_hu = 250.0;   // above soft tissue and enhanced vessels in most scans
  double auto_wall_thickness_mm = 30.0;    // skin + fat + muscle of an adult abdomen
  double auto_wall_max_angle_deg = 100.0;  // anterior (0) and lateral (90) sides; the back is not
  // The chest above the diaphragm found on the CT (anatomy/thorax.h) and held fixed but for the lungs
  // (compliant_lungs), the first auto_diaphragm_thickness_mm under it made wall: no gas opens beside
  // the lungs or the heart.
  bool auto_thorax = true;
  double auto_diaphragm_thickness_mm = 5.0;
  // The lungs are wall tissue of the lung's stiffness (SceneMaterial::lung_young_kpa), not fixed, so
  // the diaphragm rises into the chest as the abdomen fills: labelled lungs (by name) and the lungs
  // the CT's density finds, their vessels within (anatomy/thorax.h). The heart, the mediastinum and
  // the ribs stay fixed.
  bool compliant_lungs = true;
  // The ids the label names call lung (filled by the scene, not a key): their aerated voxels, and
  // unlabelled ones, take the lungs' material; a labelled duodenum's or rectum's gas does not.
  std::vector<int> lung_ids;
  // The ids the label names call liver (filled by the scene, not a key): they take the liver's
  // vascular compliance (SceneMaterial::liver_volume_loss).
  std::vector<int> liver_ids;
  bool auto_use_labels = true;
  // Ids the lists do not name take the role their structure's name gives (roles/structure_names.h).
  bool by_name = true;
  // The names of the label map's ids (for messages, and what by_name read); filled by the scene.
  std::map<int, std::string> label_names;
  // The ids of the lists that came from names, not from the scene: a label map need not hold them all.
  std::vector<int> ids_from_names;
  // Extraperitoneal organs whose front the peritoneum does not reach (the bladder: the space of
  // Retzius lies between it and the wall): undecided tissue anterior to them in the same axial
  // column becomes wall, so no gas opens there (auto_roles.h, rule 5b), and in the slices from
  // their top down, undecided tissue anterior to their back (rule 6b: below the reflection).
  std::vector<int> auto_prevesical_labels;
  // Air added around the CT so the wall has room to rise (a 12 mmHg abdomen rises 30-60 mm). Unset in
  // front and at the sides: found on the CT (roles/auto_pad.h).
  std::optional<double> pad_anterior_mm, pad_lateral_mm;
  double pad_superior_mm = 0.0, pad_inferior_mm = 0.0;

  /// Role of every label id 0..65535 (index = id): the role lists, else unlisted_label_role.
  std::vector<Role> label_roles() const;
};

}  // namespace pneumo
