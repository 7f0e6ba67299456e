// Roles by anatomy (roles/structure_names.h): a scene that gives a label map with names, and no id
// lists, gets its roles from the names. The lists a scene gives override the names, id by id.
#include <algorithm>
#include <filesystem>
#include <set>

#include "core/input_file.h"
#include "core/log.h"
#include "io/label_table.h"
#include "io/volume_io.h"
#include "roles/structure_names.h"
#include "scene/param_table.h"
#include "scene/scene.h"

namespace pneumo {

namespace {

bool is_nifti(const std::string& path) {
  const VolumeFormat f = volume_format_from_path(path);
  return f == VolumeFormat::Nifti || f == VolumeFormat::NiftiGz;
}

bool exists(const std::string& path) { return probe_file(path).kind == FileKind::Regular; }

std::string named_ids(const std::vector<int>& ids, const std::map<int, std::string>& names, std::size_t at_most = 12) {
  std::string s;
  for (std::size_t i = 0; i < ids.size() && i < at_most; ++i) {
    const auto n = names.find(ids[i]);
    s += (i ? ", " : "") + (n != names.end() ? n->second : "label") + " (" + std::to_string(ids[i]) + ")";
  }
  if (ids.size() > at_most) s += " and " + std::to_string(ids.size() - at_most) + " more";
  return s;
}

void append_sorted(std::vector<int>& list, const std::vector<int>& more) {
  list.insert(list.end(), more.begin(), more.end());
  std::sort(list.begin(), list.end());
  list.erase(std::unique(list.begin(), list.end()), list.end());
}

bool has_key(const nlohmann::json& j, const char* section, const char* key) {
  const auto s = j.find(section);
  return s != j.end() && s->is_object() && s->contains(key);
}

}  // namespace

std::map<int, std::string> scene_label_names(const Scene& scene) {
  if (!scene.inputs.label_names.empty()) return read_label_names(scene.inputs.label_names);
  if (!scene.inputs.labels.empty() && is_nifti(scene.inputs.labels)) return read_nifti_label_names(scene.inputs.labels);
  return {};
}

namespace scene_detail {

void assign_roles_by_name(Scene& s, const nlohmann::json& given) {
  RoleRules& r = s.roles;
  if (s.inputs.labels.empty()) return;
  // Parsing does not need the files; a missing one is refused where it is read, with its own message.
  const std::string& names_file = s.inputs.label_names.empty() ? s.inputs.labels : s.inputs.label_names;
  if (!exists(names_file)) return;
  r.label_names = scene_label_names(s);   // the messages name structures in every mode
  r.lung_ids.clear();                     // the lungs' material goes by name in every mode too
  r.liver_ids.clear();                    // and the liver's
  for (const auto& [id, name] : r.label_names) {
    if (id > 0 && compartment_of(name) == Compartment::Lung) r.lung_ids.push_back(id);
    if (id > 0 && is_liver(name)) r.liver_ids.push_back(id);
  }
  if (r.source != RoleSource::Auto || !r.by_name || !r.auto_use_labels) return;
  const bool scene_lists = !r.wall_labels.empty() || !r.viscera_labels.empty() || !r.fixed_labels.empty();
  if (r.label_names.empty() && !scene_lists) {
    log::warn("roles: the label map's ids have no names (no inputs.label_names, none in " + s.inputs.labels +
              "'s header), so no label decides a role: the CT's HU rules decide every voxel. Give inputs.label_names "
              "(data/label_tables/ has TotalSegmentator's) or list the ids in roles.*_labels");
    return;
  }
  if (r.label_names.empty()) return;
  std::vector<int> listed;
  for (const auto* l : {&r.wall_labels, &r.viscera_labels, &r.fixed_labels, &r.other_labels})
    listed.insert(listed.end(), l->begin(), l->end());
  const RolesFromNames by_name = roles_from_names(r.label_names, listed);
  append_sorted(r.wall_labels, by_name.wall);
  append_sorted(r.viscera_labels, by_name.viscera);
  append_sorted(r.fixed_labels, by_name.fixed);
  append_sorted(r.compliant_lungs ? r.wall_labels : r.fixed_labels, by_name.lung);
  for (const auto* l : {&by_name.wall, &by_name.viscera, &by_name.fixed, &by_name.lung})
    append_sorted(r.ids_from_names, *l);
  if (!has_key(given, "roles", "auto_prevesical_labels")) append_sorted(r.auto_prevesical_labels, by_name.prevesical);
  if (!has_key(given, "mesh", "attached_labels") && !by_name.attached.empty()) {
    if (solves_force_fields(s.solver.method)) append_sorted(s.mesh.attached_labels, by_name.attached);
    else
      log::info("roles: solver.method \"" + std::string(enum_name(s.solver.method)) +
                "\" cannot bond the viscera to the retroperitoneal organs (mesh.attached_labels): their interface may open");
  }
  log::info("roles by name: viscera " + named_ids(by_name.viscera, r.label_names) + "; wall " +
            named_ids(by_name.wall, r.label_names) + "; fixed " + named_ids(by_name.fixed, r.label_names, 6) +
            (by_name.lung.empty() ? std::string()
                                  : std::string("; lungs (") + (r.compliant_lungs ? "wall, compliant" : "fixed") +
                                        ") " + named_ids(by_name.lung, r.label_names, 6)));
  if (!by_name.unknown.empty())
    log::warn("roles: no role is known for the names of " + named_ids(by_name.unknown, r.label_names) +
              ": the CT's HU rules decide their voxels; list their ids in roles.wall_labels, viscera_labels or "
              "fixed_labels to choose");
}

}  // namespace scene_detail

}  // namespace pneumo
