#include "roles/auto_roles.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/log.h"
#include "core/progress.h"
#include "domain/label_set.h"
#include "anatomy/anatomical_axes.h"
#include "anatomy/thorax.h"
#include "anatomy/back_region.h"
#include "anatomy/body_mask.h"
#include "anatomy/distance_transform.h"
#include "roles/label_map.h"
#include "roles/lateral_to_bone.h"
#include "roles/role_rules.h"
#include "roles/structure_names.h"

namespace pneumo {

namespace {

// Not a role: a voxel no rule has decided yet. The enum's underlying type is uint8_t, so any value
// of it is a valid Role object; this one never leaves this file.
constexpr Role kUndecided = static_cast<Role>(255);

class StageTimer {
 public:
  explicit StageTimer(Progress& p) : progress_(p), last_(Clock::now()) {}
  void done(int64_t step, const char* stage) {
    const auto now = Clock::now();
    log::debug(std::string("roles: ") + stage + " " +
               std::to_string(std::chrono::duration<double>(now - last_).count()) + " s");
    last_ = now;
    progress_.update(step, stage);
  }

 private:
  using Clock = std::chrono::steady_clock;
  Progress& progress_;
  Clock::time_point last_;
};

/// Rules 1-3: labels, outside, bone. Everything else stays undecided.
std::vector<Role> decide_by_labels_and_hu(const RoleRules& r, const std::vector<uint8_t>& body, const float* hu,
                                          const uint16_t* label) {
  const int64_t n = int64_t(body.size());
  const std::vector<Role> table = r.label_roles();
  const std::vector<uint8_t> listed = listed_label_ids(r);
  const bool use_labels = r.auto_use_labels && label != nullptr;
  const float bone = float(r.auto_bone_threshold_hu);
  std::vector<Role> role(static_cast<std::size_t>(n));
#pragma omp parallel for schedule(static)
  for (int64_t v = 0; v < n; ++v) {
    if (use_labels && label[v] != 0 && listed[label[v]]) role[v] = table[label[v]];
    else if (!body[v]) role[v] = Role::Other;
    else if (hu[v] > bone) role[v] = Role::Fixed;
    else role[v] = kUndecided;
  }
  return role;
}

/// Rule 3b: the chest above the diaphragm (anatomy/thorax.h): its lungs, and what lies deeper than
/// the wall's shell (the heart, the mediastinum), fixed; the chest wall is left to the shell rule, as
/// where the lungs and heart are labelled. Returns what is held (labelled lungs and heart included,
/// rule 5c's diaphragm lies under it) and the lungs and heart alone.
struct Chest {
  std::vector<uint8_t> held, lungs;
};

Chest fix_the_chest(std::vector<Role>& role, const RoleRules& r, const Geometry& g, const float* hu,
                    const uint16_t* label, const std::vector<uint8_t>& body, const std::vector<float>& depth_mm) {
  const int64_t n = int64_t(role.size());
  std::vector<uint8_t> labelled;
  if (r.auto_use_labels && label) {
    std::vector<uint8_t> chest_id(65536, 0);
    bool any = false;
    for (const auto& [id, name] : r.label_names)
      if (id > 0 && id < 65536 && lies_above_the_diaphragm(name)) {
        chest_id[std::size_t(id)] = compartment_of(name) == Compartment::Lung ? 1 : 2;
        any = true;
      }
    if (any) {
      labelled.resize(static_cast<std::size_t>(n));
#pragma omp parallel for schedule(static)
      for (int64_t v = 0; v < n; ++v) labelled[v] = chest_id[label[v]];
    }
  }
  ThoraxOptions opt;
  if (!r.compliant_lungs) opt.lung_closing_mm = 0.0;   // held lungs need no lung tissue
  const Thorax t = find_thorax(hu, body, g, labelled.empty() ? nullptr : &labelled, opt);
  std::vector<uint8_t> held(static_cast<std::size_t>(n));
  const float shell = float(r.auto_wall_thickness_mm);
  int64_t count = 0, lung = 0;
#pragma omp parallel for schedule(static) reduction(+ : count, lung)
  for (int64_t v = 0; v < n; ++v) {
    held[v] = t.lungs[v] || (t.chest[v] && depth_mm[v] > shell);
    const bool lung_tissue = r.compliant_lungs && t.lung_tissue[v];
    if (held[v] && role[v] == kUndecided)   // the lungs and their vessels compliant: the diaphragm rises into them
      role[v] = lung_tissue ? Role::Wall : Role::Fixed;
    lung += lung_tissue && role[v] == Role::Wall;   // found here or labelled lung by name
    count += held[v] && role[v] == Role::Fixed;
  }
  if (t.lung_ml > 0.0) {
    char line[256];
    std::snprintf(line, sizeof line,
                  "roles: the chest above the diaphragm: lungs %.0f ml (%d part%s by density%s), %.0f ml of lung "
                  "wall (compliant), %.0f ml held fixed, the diaphragm under it wall",
                  t.lung_ml, t.lung_parts, t.lung_parts == 1 ? "" : "s", labelled.empty() ? "" : ", and the labelled lungs and heart",
                  double(lung) * g.spacing_mm.prod() / 1000.0, double(count) * g.spacing_mm.prod() / 1000.0);
    log::info(line);
  } else {
    log::debug("roles: no lung in view: no chest above the diaphragm to hold");
  }
  return {std::move(held), t.lungs};
}

/// Rule 5c: undecided voxels within auto_diaphragm_thickness_mm of the held chest → wall (the diaphragm).
/// With compliant lungs, labelled viscera within that distance of a lung or the heart too: a label
/// map that leaves no diaphragm between the lung base and the liver (3 mm voxels often do) would
/// otherwise let the gas open against the lung, which now moves.
void wall_under_the_chest(std::vector<Role>& role, const Chest& chest, const Geometry& g, const RoleRules& r) {
  const auto any = [](const std::vector<uint8_t>& m) { return std::any_of(m.begin(), m.end(), [](uint8_t h) { return h; }); };
  if (!(r.auto_diaphragm_thickness_mm > 0.0) || !any(chest.held)) return;
  const int64_t n = int64_t(role.size());
  const float thickness = float(r.auto_diaphragm_thickness_mm);
  std::vector<uint8_t> away(static_cast<std::size_t>(n));
#pragma omp parallel for schedule(static)
  for (int64_t v = 0; v < n; ++v) away[v] = !chest.held[v];
  {
    const std::vector<float> to_chest_mm = distance_to_outside_mm(away, g);
#pragma omp parallel for schedule(static)
    for (int64_t v = 0; v < n; ++v)
      if (role[v] == kUndecided && to_chest_mm[v] <= thickness) role[v] = Role::Wall;
  }
  if (!r.compliant_lungs || !any(chest.lungs)) return;
#pragma omp parallel for schedule(static)
  for (int64_t v = 0; v < n; ++v) away[v] = !chest.lungs[v];
  const std::vector<float> to_lungs_mm = distance_to_outside_mm(away, g);
#pragma omp parallel for schedule(static)
  for (int64_t v = 0; v < n; ++v)
    if (role[v] == Role::Viscera && to_lungs_mm[v] <= thickness) role[v] = Role::Wall;
}

/// Rule 4: undecided body voxels behind the spine's front → fixed.
void fix_the_back(std::vector<Role>& role, const std::vector<uint8_t>& body, const std::vector<SliceCentre>& centres,
                  const SliceFrame& f) {
  std::vector<uint8_t> fixed(role.size());
  const int64_t n = int64_t(role.size());
#pragma omp parallel for schedule(static)
  for (int64_t v = 0; v < n; ++v) fixed[v] = role[v] == Role::Fixed;
  const std::vector<int64_t> front = spine_front_per_slice(fixed, body, centres, f);
#pragma omp parallel for schedule(static)
  for (int64_t s = 0; s < f.n_si; ++s) {
    if (front[s] < 0) continue;
    for (int64_t a = 0; a < f.n_ap; ++a) {
      if (f.ant(a) > front[s]) continue;
      for (int64_t l = 0; l < f.n_lat; ++l) {
        const int64_t v = f.index(l, a, s);
        if (role[v] == kUndecided) role[v] = Role::Fixed;
      }
    }
  }
}

/// Rule 5: the shell, wall anterior and lateral, fixed behind.
void assign_the_shell(std::vector<Role>& role, const std::vector<float>& depth_mm, const std::vector<SliceCentre>& centres,
                      const SliceFrame& f, const RoleRules& r) {
  const float thickness = float(r.auto_wall_thickness_mm);
  const double cos_max = std::cos(r.auto_wall_max_angle_deg * M_PI / 180.0);
#pragma omp parallel for schedule(static)
  for (int64_t s = 0; s < f.n_si; ++s) {
    const SliceCentre& c = centres[s];
    if (c.count == 0) continue;
    for (int64_t a = 0; a < f.n_ap; ++a) {
      const double dy = (double(f.ant(a)) - c.ant) * f.h_ap;  // + = anterior of the centroid
      for (int64_t l = 0; l < f.n_lat; ++l) {
        const int64_t v = f.index(l, a, s);
        if (role[v] != kUndecided || !(depth_mm[v] <= thickness)) continue;
        const double dx = (double(l) - c.lat) * f.h_lat;
        const double len = std::hypot(dx, dy);
        // angle from anterior ≤ max  ⇔  cos(angle) = dy/len ≥ cos(max); the centroid itself counts as anterior
        const bool front_or_side = len == 0.0 || dy >= cos_max * len;
        role[v] = front_or_side ? Role::Wall : Role::Fixed;
      }
    }
  }
}

/// Undecided voxels of column (slice s, lateral l) anterior to anteriority `from(s, l)` → wall; a
/// column whose `from` is negative is left alone. Rules 5b and 6b differ only in `from`. Where an
/// intraperitoneal organ (`peritoneal_front`, the front of roles.viscera_labels in the column) lies
/// in front of `from`, the peritoneum lies in front of the bladder at that level: the tissue between
/// the bladder and that organ is on the peritoneal side (mesentery, the bladder's peritoneal face), and
/// only what lies in front of the organ becomes wall. Made wall, it had bound the loop in front of
/// the bladder's upper part between two wall layers, and when the loop rose under pressure its place
/// opened as gas between wall and wall in front of the bladder (docs/fidelity.md §5).
template <class From>
void wall_anterior_of(std::vector<Role>& role, const SliceFrame& f, const std::vector<int64_t>& peritoneal_front,
                      const From& from) {
#pragma omp parallel for schedule(static)
  for (int64_t s = 0; s < f.n_si; ++s)
    for (int64_t l = 0; l < f.n_lat; ++l) {
      int64_t first = from(s, l);
      if (first < 0) continue;
      first = std::max(first, peritoneal_front[std::size_t(s * f.n_lat + l)]);
      for (int64_t a = first + 1; a < f.n_ap; ++a) {
        const int64_t v = f.index(l, f.ant(a), s);
        if (role[v] == kUndecided) role[v] = Role::Wall;
      }
    }
}

/// Rule 5b: undecided voxels anterior to a prevesical label in the same axial column → wall.
void attach_prevesical_space(std::vector<Role>& role, const uint16_t* label, const SliceFrame& f, const RoleRules& r) {
  if (!label || r.auto_prevesical_labels.empty()) return;
  const std::vector<int64_t> fronts = front_of_labels(label, f, LabelSet(r.auto_prevesical_labels));
  wall_anterior_of(role, f, front_of_labels(label, f, LabelSet(r.viscera_labels)),
                   [&](int64_t s, int64_t l) { return fronts[std::size_t(s * f.n_lat + l)]; });
}

/// Rule 6b: below the peritoneal reflection at the dome of the prevesical labels, undecided voxels
/// anterior to the organ's back in their slice → wall (auto_roles.h).
void attach_below_the_reflection(std::vector<Role>& role, const uint16_t* label, const Geometry& g,
                                 const SliceFrame& f, const RoleRules& r) {
  if (!label || r.auto_prevesical_labels.empty()) return;
  const LabelSet organ(r.auto_prevesical_labels);
  // The organ's back (least anteriority) in each slice, -1 where the slice holds none of it.
  std::vector<int64_t> back(static_cast<std::size_t>(f.n_si), -1);
#pragma omp parallel for schedule(static)
  for (int64_t s = 0; s < f.n_si; ++s)
    for (int64_t a = 0; a < f.n_ap && back[s] < 0; ++a)
      for (int64_t l = 0; l < f.n_lat; ++l)
        if (organ.contains(label[f.index(l, f.ant(a), s)])) {
          back[s] = a;
          break;
        }
  // Slices in superior order: the first holding the organ from the top is its dome; below it, a
  // slice without the organ takes the back of the nearest slice above that has one.
  const int up = anatomical_axes(g).sign[2];
  std::vector<int64_t> order(static_cast<std::size_t>(f.n_si));
  for (int64_t s = 0; s < f.n_si; ++s) order[s] = up > 0 ? f.n_si - 1 - s : s;   // top first
  int64_t carried = -1;
  for (int64_t s : order) {
    if (back[s] >= 0) carried = back[s];
    else back[s] = carried;   // -1 above the dome
  }
  wall_anterior_of(role, f, front_of_labels(label, f, LabelSet(r.viscera_labels)),
                   [&](int64_t s, int64_t) { return back[std::size_t(s)]; });
}

/// Rule 6: undecided voxels lateral to bone (away from the midline) → fixed. Bone here is what rules
/// 1 and 3 fixed above the bone threshold: a labelled vessel or organ that enhances above it (an
/// arterial-phase aorta, iliac arteries, kidneys) keeps its label's role and anchors nothing.
void fix_lateral_to_bone(std::vector<Role>& role, const std::vector<uint8_t>& body, const float* hu,
                         const std::vector<SliceCentre>& centres, const SliceFrame& f, const RoleRules& r) {
  const int64_t n = int64_t(role.size());
  std::vector<uint8_t> bone(static_cast<std::size_t>(n)), undecided(static_cast<std::size_t>(n));
  const float bone_hu = float(r.auto_bone_threshold_hu);
#pragma omp parallel for schedule(static)
  for (int64_t v = 0; v < n; ++v) {
    bone[v] = body[v] && hu[v] > bone_hu && role[v] == Role::Fixed;
    undecided[v] = role[v] == kUndecided;
  }
  const std::vector<uint8_t> lateral = lateral_to_bone(bone, undecided, centres, f);
#pragma omp parallel for schedule(static)
  for (int64_t v = 0; v < n; ++v)
    if (lateral[v]) role[v] = Role::Fixed;
}

}  // namespace

std::vector<Role> auto_roles(const RoleRules& r, const Geometry& g, const float* hu, const uint16_t* label,
                             const std::vector<uint8_t>* given_body) {
  Progress progress("roles", 7);
  StageTimer timer(progress);
  const SliceFrame f = slice_frame(g);

  const bool have_body = given_body && int64_t(given_body->size()) == g.voxel_count();
  const std::vector<uint8_t> own = have_body ? std::vector<uint8_t>() : body_mask(hu, g, r.auto_body_threshold_hu);
  const std::vector<uint8_t>& body = have_body ? *given_body : own;
  const std::vector<SliceCentre> centres = body_centres(body, f);
  timer.done(1, "body mask");

  std::vector<Role> role = decide_by_labels_and_hu(r, body, hu, label);
  const std::vector<float> depth_mm = distance_to_outside_mm(body, g);
  timer.done(2, "labels and bone");

  Chest chest;
  if (r.auto_thorax) chest = fix_the_chest(role, r, g, hu, label, body, depth_mm);
  timer.done(3, "chest");

  fix_the_back(role, body, centres, f);
  timer.done(4, "back");

  assign_the_shell(role, depth_mm, centres, f, r);
  if (r.auto_use_labels) attach_prevesical_space(role, label, f, r);
  if (r.auto_thorax) wall_under_the_chest(role, chest, g, r);
  timer.done(5, "wall shell");

  fix_lateral_to_bone(role, body, hu, centres, f, r);
  if (r.auto_use_labels) attach_below_the_reflection(role, label, g, f, r);
  timer.done(6, "lateral to bone");

  const int64_t n = int64_t(role.size());
#pragma omp parallel for schedule(static)
  for (int64_t v = 0; v < n; ++v)
    if (role[v] == kUndecided) role[v] = Role::Viscera;   // rule 7
  timer.done(7, "viscera");
  progress.finish();
  return role;
}

}  // namespace pneumo
