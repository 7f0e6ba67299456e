#pragma once
// The label map as roles see it: checked to lie on the CT's grid, its ids checked to be whole
// numbers 0..65535, mapped to roles through the scene's lists (RoleRules::label_roles()).
#include <cstdint>
#include <string>
#include <vector>

#include "core/geometry.h"
#include "io/volume.h"
#include "domain/types.h"
#include "roles/role_rules.h"

namespace pneumo {

/// InputError naming both files and what differs (dims, spacing, origin or direction, 1e-3 mm)
/// when the label map is not on the CT's grid.
void check_labels_on_ct_grid(const Geometry& ct, const Geometry& labels, const std::string& ct_name,
                             const std::string& labels_name);

/// InputError naming the file and the first bad voxel when a value is not a whole number in
/// 0..65535 (negative, fractional, too large or NaN).
void check_label_values(const Volume& labels, const std::string& labels_name);

/// role[n] = table[label[n]].
std::vector<Role> roles_from_labels(const std::vector<uint16_t>& label, const std::vector<Role>& table);

/// Ids the scene lists (any role list) that the map does not hold: fine, but a warning names them
/// (a typo in a scene shows up here). A wall, viscera or fixed list none of whose ids the map holds
/// is an InputError naming the list and the ids the map does hold (a mapping for another label map). Ids the map holds that no list names get
/// unlisted_label_role: an info line names them.
void note_label_coverage(const RoleRules& roles, const std::vector<uint16_t>& label, const std::string& labels_name);

/// Whether each id 0..65535 is in one of the scene's role lists.
std::vector<uint8_t> listed_label_ids(const RoleRules& roles);

}  // namespace pneumo
