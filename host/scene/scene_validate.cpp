// Rules that involve more than one key, checked after every key passed its own checks. Messages
// have the same shape as the table's: file, key path, value, what is wrong.
#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "core/error.h"
#include "scene/param_table.h"

namespace pneumo::scene_detail {
namespace {

json vec_json(const Vec3& v) { return json::array({v[0], v[1], v[2]}); }

// Each label id has one role: a label in two lists would make the role depend on list order.
void check_role_lists(const RoleRules& r, const At& roles) {
  const std::vector<std::pair<const char*, const std::vector<int>*>> lists{
      {"wall_labels", &r.wall_labels},
      {"viscera_labels", &r.viscera_labels},
      {"fixed_labels", &r.fixed_labels},
      {"other_labels", &r.other_labels}};
  std::map<int, const char*> owner;
  for (const auto& [key, ids] : lists)
    for (int id : *ids) {
      const auto [it, fresh] = owner.emplace(id, key);
      if (!fresh)
        throw InputError(roles.ctx->file + ": label " + std::to_string(id) + " is in both " +
                         roles.child(it->second).path + " and " + roles.child(key).path +
                         "; a label has one role");
    }
}

// An attached label is a wall label (the parietal side the viscera stay on, mesh.h): one the scene
// gives another role would have no wall voxels to close, and would be ignored without a word.
void check_attached_labels(const SceneMesh& m, const RoleRules& r, const At& root) {
  const At list = root.child("mesh").child("attached_labels");
  for (std::size_t i = 0; i < m.attached_labels.size(); ++i)
    for (const auto& [key, ids] : {std::pair{"viscera_labels", &r.viscera_labels},
                                   {"fixed_labels", &r.fixed_labels}, {"other_labels", &r.other_labels}})
      if (std::find(ids->begin(), ids->end(), m.attached_labels[i]) != ids->end())
        list.item(i).fail_value(m.attached_labels[i], std::string("is in ") + root.child("roles").child(key).path +
                                                          "; attached labels are wall labels (the side the "
                                                          "viscera stay on): list it in roles.wall_labels");
}

void check_roi(const SceneMesh& m, const At& mesh) {
  if (m.roi_min_mm.has_value() != m.roi_max_mm.has_value()) {
    const char* given = m.roi_min_mm ? "roi_min_mm" : "roi_max_mm";
    const char* other = m.roi_min_mm ? "roi_max_mm" : "roi_min_mm";
    mesh.child(given).fail("is set but " + mesh.child(other).path + " is not; give both or neither");
  }
  if (m.roi_min_mm && !(m.roi_min_mm->array() < m.roi_max_mm->array()).all())
    mesh.child("roi_max_mm").fail_value(vec_json(*m.roi_max_mm), "must exceed " + mesh.child("roi_min_mm").path +
                                                                      " = " + show(vec_json(*m.roi_min_mm)) +
                                                                      " in every coordinate");
}

void check_label_young(const SceneMaterial& m, const At& material) {
  std::map<int, std::size_t> first;
  const At list = material.child("label_young_kpa");
  for (std::size_t i = 0; i < m.label_young_kpa.size(); ++i) {
    const int label = m.label_young_kpa[i].label;
    const auto [it, fresh] = first.emplace(label, i);
    if (!fresh)
      list.item(i).child("label").fail_value(label, "is listed twice (also " + list.item(it->second).path + ")");
  }
}

// The finite elements run under Newton only (the other solvers' step sizes come from the springs), and
// the co-rotational law has no stiffening.
void check_material_model(const Scene& s, const At& root) {
  const SceneMaterial& m = s.material;
  // The contact term wraps a force field (solve/contact.h); the explicit, Newmark and 2004 schemes
  // rely on the springs' own step, dampers and stiffness sums (solver.cpp refuses it too).
  if (m.contact && !solves_force_fields(s.solver.method))
    root.child("solver").child("method").fail_value(enum_name(s.solver.method),
                                                    "cannot solve with material.contact; use \"newton\", \"static\" "
                                                    "or \"implicit-euler\", or set contact to false");
  if (!s.mesh.attached_labels.empty() && !solves_force_fields(s.solver.method))
    root.child("solver").child("method").fail_value(enum_name(s.solver.method),
                                                    "cannot solve with mesh.attached_labels; use \"newton\", \"static\" "
                                                    "or \"implicit-euler\", or leave attached_labels empty");
  if (m.tilt_deg != 0.0 && !m.gravity)
    root.child("material").child("tilt_deg").fail_value(m.tilt_deg, "tilts gravity, which is off: set gravity to true");
  if (m.model == MaterialModel::Msd && m.wall_fibre_stiffness > 0.0)
    root.child("material").child("wall_fibre_stiffness").fail_value(m.wall_fibre_stiffness,
                                                                    "needs finite elements; the springs have no "
                                                                    "fibres: use \"fem-neohookean\", or 0");
  if (m.model == MaterialModel::Msd) return;
  // The explicit schemes need the springs' dampers and stable step, the 2004 scheme their stiffness
  // sums; the finite elements have neither (docs/fem.md). Implicit Euler damps by Rayleigh's C.
  if (!solves_force_fields(s.solver.method))
    root.child("solver").child("method").fail_value(enum_name(s.solver.method),
                                                    std::string("cannot solve material.model \"") + enum_name(m.model) +
                                                        "\"; use \"newton\", \"static\" or \"implicit-euler\"");
  if (m.model == MaterialModel::FemCorotational && m.stiffening > 0.0)
    root.child("material").child("stiffening").fail_value(m.stiffening,
                                                          "has no meaning for \"fem-corotational\" (a linear law); "
                                                          "use \"fem-neohookean\" for Demiray's stiffening, or 0");
  if (m.volume_stiffness_kpa)
    root.child("material").child("volume_stiffness_kpa").fail_value(*m.volume_stiffness_kpa,
                                                                    "is the springs' volume term; the finite elements "
                                                                    "take material.poisson_ratio instead: remove it");
  if (m.spring_model != SpringModel::Nonlinear)
    root.child("material").child("spring_model").fail_value(enum_name(m.spring_model),
                                                            "applies to the springs only; remove it with a FEM model");
}

// The view direction must exist, and `up` must not lie along it (the image's roll is then undefined).
void check_pose(const Vec3& position, const Vec3& look_at, const Optics& o, const At& view,
                const std::string& position_key, const std::string& look_at_key, const At& optics) {
  const Vec3 axis = look_at - position;
  if (axis.norm() < 1e-9)
    view.child(look_at_key).fail_value(vec_json(look_at), "equals " + position_key + "; the scope needs a direction");
  if (axis.normalized().cross(o.up.normalized()).norm() < 1e-6)
    optics.child("up").fail_value(vec_json(o.up), "is parallel to the scope's axis (" + look_at_key + " - " +
                                                      position_key + "); choose another up");
}

void check_lens(const Optics& o, const At& optics) {
  if (o.lens == Lens::Pinhole && o.fov_deg >= 180.0)
    optics.child("fov_deg").fail_value(o.fov_deg, "is not allowed with lens \"pinhole\"; allowed: < 180 "
                                                  "(a fisheye allows 180)");
}

// Preset "custom" needs its points; other presets ignore them, which would surprise: say so.
void check_transfer_function(const ViewSettings& r, const At& render) {
  const bool custom = r.preset == RenderPreset::Custom;
  const bool given = !r.custom_opacity.empty() || !r.custom_colour.empty();
  if (custom && (r.custom_opacity.empty() || r.custom_colour.empty()))
    render.child("preset").fail_value("custom", "needs both render.custom_opacity and render.custom_colour");
  if (!custom && given)
    render.child("preset").fail_value(enum_name(r.preset), "ignores custom_opacity/custom_colour; set preset "
                                                           "\"custom\" to use them");
}

void check_views(const ViewSettings& r, const At& render) {
  std::map<std::string, std::string> names;  // name → path of the view that has it
  const auto claim = [&](const std::string& name, const At& view) {
    if (r.exterior_views && name.rfind("exterior_", 0) == 0)
      view.child("name").fail_value(name, "starts with \"exterior_\", kept for the exterior views");
    const auto [it, fresh] = names.emplace(name, view.path);
    if (!fresh)
      view.child("name").fail_value(name, "is used twice (also " + it->second + "); views name output files");
  };
  for (std::size_t i = 0; i < r.cameras.size(); ++i) {
    const Camera& c = r.cameras[i];
    const At at = render.child("cameras").item(i);
    claim(c.name, at);
    check_lens(c.optics, at);
    check_pose(c.position_mm, c.look_at_mm, c.optics, at, "position_mm", "look_at_mm", at);
  }
  for (std::size_t i = 0; i < r.ports.size(); ++i) {
    const At at = render.child("ports").item(i);
    claim(r.ports[i].name, at);
    check_port(r.ports[i], at);
  }
  for (std::size_t i = 0; i < r.paths.size(); ++i) {
    const CameraPath& p = r.paths[i];
    const At at = render.child("paths").item(i);
    claim(p.name, at);
    check_lens(p.optics, at);
    for (std::size_t k = 0; k < p.keyframes.size(); ++k) {
      const At key = at.child("keyframes").item(k);
      check_pose(p.keyframes[k].position_mm, p.keyframes[k].look_at_mm, p.optics, key, "position_mm", "look_at_mm", at);
    }
  }
}

// Landmarks: unique names; tracker measurements in pairs (before and after), and, when any are given,
// at least 3, since Horn's alignment of the tracker frame to the CT needs 3 points not on a line.
void check_landmarks(const std::vector<Landmark>& marks, const At& list) {
  std::map<std::string, std::size_t> first;
  std::size_t measured = 0;
  for (std::size_t i = 0; i < marks.size(); ++i) {
    const Landmark& m = marks[i];
    const At at = list.item(i);
    const auto [it, fresh] = first.emplace(m.name, i);
    if (!fresh) at.child("name").fail_value(m.name, "is used twice (also " + list.item(it->second).path + ")");
    if (m.measured_before_mm.has_value() != m.measured_after_mm.has_value())
      at.fail(std::string("gives ") + (m.measured_before_mm ? "measured_before_mm" : "measured_after_mm") +
              " without " + (m.measured_before_mm ? "measured_after_mm" : "measured_before_mm") +
              "; give both or neither");
    measured += m.measured_before_mm.has_value();
  }
  if (measured > 0 && measured < 3)
    list.fail("has " + std::to_string(measured) + " landmark(s) with tracker measurements; aligning the tracker "
              "frame to the CT (Horn) needs at least 3");
}

}  // namespace

void check_port(const Port& p, const At& at) {
  check_lens(p.optics, at);
  if (p.target_mm.has_value() == p.target_label.has_value())
    at.fail(p.target_mm ? "gives both target_mm and target_label; give one"
                        : "gives neither target_mm nor target_label; give one");
  if (p.target_mm) check_pose(p.skin_point_mm, *p.target_mm, p.optics, at, "skin_point_mm", "target_mm", at);
}

void validate_scene(const Scene& s, const ReadContext& ctx) {
  const At root{&ctx, ""};
  check_role_lists(s.roles, root.child("roles"));
  check_roi(s.mesh, root.child("mesh"));
  check_attached_labels(s.mesh, s.roles, root);
  check_label_young(s.material, root.child("material"));
  check_material_model(s, root);
  check_transfer_function(s.render, root.child("render"));
  check_views(s.render, root.child("render"));
  check_landmarks(s.landmarks, root.child("landmarks"));
}

}  // namespace pneumo::scene_detail
