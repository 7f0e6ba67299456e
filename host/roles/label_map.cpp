#include "roles/label_map.h"

#include <cmath>
#include <sstream>

#include "core/error.h"
#include "core/log.h"

namespace pneumo {

std::vector<Role> RoleRules::label_roles() const {
  std::vector<Role> table(65536, unlisted_label_role);
  // The lists cannot overlap (checked when the scene is read), so the order here does not matter.
  for (int id : wall_labels) table[id] = Role::Wall;
  for (int id : viscera_labels) table[id] = Role::Viscera;
  for (int id : fixed_labels) table[id] = Role::Fixed;
  for (int id : other_labels) table[id] = Role::Other;
  return table;
}

namespace {

std::string dims_text(const Index3& d) {
  return std::to_string(d[0]) + "x" + std::to_string(d[1]) + "x" + std::to_string(d[2]);
}

std::string vec_text(const Vec3& v) {
  std::ostringstream os;
  os << "(" << v[0] << ", " << v[1] << ", " << v[2] << ")";
  return os.str();
}

/// What differs between two grids, first difference only ("" when they are the same grid).
std::string grid_difference(const Geometry& a, const Geometry& b, double tol_mm) {
  if (a.dims != b.dims) return "dims " + dims_text(a.dims) + " vs " + dims_text(b.dims);
  if ((a.spacing_mm - b.spacing_mm).cwiseAbs().maxCoeff() > tol_mm)
    return "spacing " + vec_text(a.spacing_mm) + " vs " + vec_text(b.spacing_mm) + " mm";
  if ((a.origin_mm - b.origin_mm).cwiseAbs().maxCoeff() > tol_mm)
    return "origin " + vec_text(a.origin_mm) + " vs " + vec_text(b.origin_mm) + " mm";
  if (!a.same_grid(b, tol_mm))
    return "direction " + a.orientation_code() + " vs " + b.orientation_code() +
           " (direction matrices differ by more than " + std::to_string(tol_mm) + " mm at the far corner)";
  return "";
}

/// "5 (liver), 6 (stomach), 7": ids with their names where `names` has them.
std::string id_list(const std::vector<int>& ids, const std::map<int, std::string>& names = {}) {
  std::string s;
  for (std::size_t n = 0; n < ids.size(); ++n) {
    s += (n ? ", " : "") + std::to_string(ids[n]);
    const auto name = names.find(ids[n]);
    if (name != names.end()) s += " (" + name->second + ")";
  }
  return s;
}

}  // namespace

void check_labels_on_ct_grid(const Geometry& ct, const Geometry& labels, const std::string& ct_name,
                             const std::string& labels_name) {
  constexpr double kTolMm = 1e-3;
  const std::string diff = grid_difference(labels, ct, kTolMm);
  if (diff.empty()) return;
  throw InputError(labels_name + ": the label map is not on the grid of the CT " + ct_name + ": " + diff +
                   " (label map vs CT); resample the labels onto the CT's grid (nearest neighbour)");
}

void check_label_values(const Volume& labels, const std::string& labels_name) {
  if (labels.type() == VoxelType::UInt8 || labels.type() == VoxelType::UInt16) return;  // always valid
  const int64_t n = labels.voxel_count();
  int64_t first_bad = n;
  dispatch_voxel_type(labels.type(), const_cast<void*>(labels.raw()), [&](auto* p) {
#pragma omp parallel for reduction(min : first_bad) schedule(static)
    for (int64_t v = 0; v < n; ++v) {
      const double x = static_cast<double>(p[v]);
      if (!(x >= 0.0 && x <= 65535.0 && x == std::floor(x)) && v < first_bad) first_bad = v;
    }
  });
  if (first_bad == n) return;
  const Index3& d = labels.geometry().dims;
  std::ostringstream os;
  os << "label value " << labels.value(first_bad) << " at voxel (" << first_bad % d[0] << ", "
     << (first_bad / d[0]) % d[1] << ", " << first_bad / (d[0] * d[1])
     << "): label ids must be whole numbers 0..65535";
  throw file_error(labels_name, os.str());
}

std::vector<Role> roles_from_labels(const std::vector<uint16_t>& label, const std::vector<Role>& table) {
  std::vector<Role> role(label.size());
  const int64_t n = int64_t(label.size());
#pragma omp parallel for schedule(static)
  for (int64_t v = 0; v < n; ++v) role[v] = table[label[v]];
  return role;
}

std::vector<uint8_t> listed_label_ids(const RoleRules& r) {
  std::vector<uint8_t> listed(65536, 0);
  for (const auto* list : {&r.wall_labels, &r.viscera_labels, &r.fixed_labels, &r.other_labels})
    for (int id : *list) listed[std::size_t(id)] = 1;
  return listed;
}

void note_label_coverage(const RoleRules& r, const std::vector<uint16_t>& label, const std::string& labels_name) {
  std::vector<uint8_t> present(65536, 0);
  for (uint16_t id : label) present[id] = 1;  // a byte store per voxel: cheap next to reading the file
  const std::vector<uint8_t> listed = listed_label_ids(r);
  std::vector<uint8_t> named(65536, 0);   // listed by name, not by the scene: the map need not hold them
  for (int id : r.ids_from_names) named[std::size_t(id)] = 1;
  std::vector<int> absent, unlisted;
  for (int id = 0; id < 65536; ++id) {
    if (listed[id] && !present[id] && !named[id]) absent.push_back(id);
    if (!listed[id] && present[id] && id != 0) unlisted.push_back(id);
  }
  // A list none of whose ids occurs is a mapping written for another label map (another
  // segmentation tool, another version of its ids): every voxel would silently take the wrong role.
  const std::pair<const char*, const std::vector<int>*> lists[] = {
      {"wall_labels", &r.wall_labels}, {"viscera_labels", &r.viscera_labels}, {"fixed_labels", &r.fixed_labels}};
  for (const auto& [key, list] : lists) {
    bool any = false, own = false;
    for (int id : *list) {
      any = any || present[std::size_t(id)];
      own = own || !named[std::size_t(id)];
    }
    if (!own) continue;   // the names' roles, not a mapping the scene wrote
    if (any) continue;
    std::vector<int> ids;
    for (int id = 1; id < 65536 && ids.size() < 20; ++id)
      if (present[id]) ids.push_back(id);
    throw file_error(labels_name, std::string("none of the label ids in roles.") + key + " (" + id_list(*list) +
                                      ") occurs in the label map (its ids: " + (ids.empty() ? "none" : id_list(ids, r.label_names)) +
                                      (ids.size() == 20 ? ", ..." : "") +
                                      "): the scene's mapping was written for another label map; fix roles." + key);
  }
  if (!absent.empty())
    log::warn("roles: label ids listed in the scene but absent from " + labels_name + ": " + id_list(absent, r.label_names) +
              " (nothing to assign)");
  if (!unlisted.empty())
    log::info("roles: label ids in " + labels_name + " that no role list names (role \"" +
              role_name(r.unlisted_label_role) + "\" in labels mode, HU rules in auto mode): " + id_list(unlisted, r.label_names));
}

}  // namespace pneumo
