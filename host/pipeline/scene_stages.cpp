#include "pipeline/scene_stages.h"

#include <cmath>

#include "core/units.h"
#include "anatomy/distance_transform.h"
#include "io/volume_io.h"
#include "mesh/wall_fibres.h"
#include "scene/scene_presets.h"

namespace pneumo {

namespace {

// The wall tetrahedra that carry the wall's fibres (mesh/wall_fibres.h): those of the abdominal wall's
// shell, within roles.auto_wall_thickness_mm (skin, fat and muscle of an adult abdomen) of the air round
// the body (every voxel of no role), and not lung. The voxel at the tetrahedron's rest centre decides.
// So the diaphragm's dome, the retroperitoneal organs and the psoas, deeper than the shell, take none:
// their fibres, where they have any, do not run round the body.
std::vector<uint8_t> fibrous_tets(const Mesh& m, const VoxelRoles& roles, const Scene& scene) {
  std::vector<uint8_t> fibrous(m.tets.size(), 0);
  const Geometry& g = roles.geometry;
  std::vector<uint8_t> inside(std::size_t(g.voxel_count()));
  for (std::size_t v = 0; v < inside.size(); ++v) inside[v] = roles.role[v] != Role::Other;
  const std::vector<float> depth_mm = distance_to_outside_mm(inside, g);
  for (std::size_t t = 0; t < m.tets.size(); ++t) {
    if (m.tet_part[t] != Part::Wall) continue;
    Vec3 centre = Vec3::Zero();
    for (int32_t n : m.tets[t]) centre += 0.25 * m.rest_m[n];
    const Vec3 ijk = g.to_index(centre * 1e3);
    int64_t i[3];
    bool inside_grid = true;
    for (int a = 0; a < 3; ++a) {
      i[a] = int64_t(std::lround(ijk[a]));
      inside_grid = inside_grid && i[a] >= 0 && i[a] < g.dims[a];
    }
    if (!inside_grid) continue;
    const int64_t v = g.linear_index(i[0], i[1], i[2]);
    const bool lung = scene.is_lung_voxel(roles.role[v], roles.label ? roles.label[v] : 0, roles.hu ? roles.hu[v] : 0.0f);
    fibrous[t] = !lung && depth_mm[std::size_t(v)] <= scene.roles.auto_wall_thickness_mm;
  }
  return fibrous;
}

/// The volume (m³) of the voxels the scene's material takes for lung (Scene::is_lung_voxel).
double lung_volume_m3(const VoxelRoles& roles, const Scene& scene) {
  const Geometry& g = roles.geometry;
  int64_t n = 0;
  for (int64_t v = 0; v < g.voxel_count(); ++v)
    n += scene.is_lung_voxel(roles.role[v], roles.label ? roles.label[v] : 0, roles.hu ? roles.hu[v] : 0.0f);
  return double(n) * g.spacing_mm.prod() * 1e-9;
}

RoleInputNames input_names(const Scene& s) {
  RoleInputNames n;
  if (!s.path.empty()) n.scene = s.path;
  if (!s.inputs.ct.empty()) n.ct = s.inputs.ct;
  if (!s.inputs.labels.empty()) n.labels = s.inputs.labels;
  return n;
}

}  // namespace

RoleVolume assign_roles(const Scene& scene, const Volume& ct, const Volume* labels) {
  return assign_roles(scene.roles, ct, labels, input_names(scene));
}

RoleVolume load_roles(const Scene& scene, InputVolumes* inputs) {
  const bool have_labels = !scene.inputs.labels.empty();
  require_labels_if_needed(scene.roles, have_labels, input_names(scene));   // before reading a large CT for nothing
  Volume ct = read_volume(scene.require_ct());
  std::optional<Volume> labels;
  if (have_labels) labels = read_volume(scene.inputs.labels);
  RoleVolume roles = assign_roles(scene, ct, labels ? &*labels : nullptr);
  if (inputs) {
    inputs->ct = std::move(ct);
    inputs->labels = std::move(labels);
  }
  return roles;
}

VoxelRoles voxel_roles_of(const RoleVolume& roles) {
  VoxelRoles v{roles.geometry, roles.role.data(), roles.label.data(), roles.hu()};
  for (int a = 0; a < 3; ++a) {
    v.ct_first[a] = roles.pad.lo[a];
    v.ct_last[a] = roles.geometry.dims[a] - 1 - roles.pad.hi[a];
  }
  return v;
}

Mesh build_scene_mesh(const VoxelRoles& roles, const Scene& scene, bool to_solve) {
  MeshOptions opt;
  opt.cube_voxels = cube_voxels_for(scene.mesh, roles.geometry);
  opt.model = scene.mesh.model;
  opt.roi_min_mm = scene.mesh.roi_min_mm;
  opt.roi_max_mm = scene.mesh.roi_max_mm;
  opt.attached_labels = scene.mesh.attached_labels;
  opt.cut_faces = scene.mesh.cut_faces;
  if (to_solve) {
    const SolveFootprint solver = solve_host_footprint(solve_options_from_scene(scene));
    opt.reserve_bytes_per_node = solver.per_node;
    opt.reserve_bytes_per_tet = solver.per_tet;
  }
  opt.poisson_for = [&](Role r, int label, float hu) { return scene.poisson_for(r, label, hu); };
  // The chest beyond the cranial cut, when asked for and some of the lungs lie beyond it: a CT that
  // shows them whole leaves none of their compliance there, and its cut slides like the others.
  const double thorax_compliance = scene.material.thorax_compliance_l_per_cmh2o && opt.cut_faces == CutFaces::Slide
                                       ? scene.thorax_compliance_m3_per_pa(lung_volume_m3(roles, scene))
                                       : 0.0;
  if (thorax_compliance > 0.0)
    opt.opens_onto_thorax = [&](Role r, int label, float hu) { return scene.is_lung_voxel(r, label, hu); };
  Mesh m = build_mesh(roles, opt,
                      VoxelYoungFn([&](Role r, int label, float hu) { return scene.young_kpa_for(r, label, hu) * 1e3; }));
  MaterialOptions mat;
  mat.density_kg_m3 = scene.material.density_kg_m3;
  mat.damping_ratio = scene.material.damping_ratio;
  mat.spring_scale = scene.material.spring_scale;
  assign_material(m, mat);
  if (!m.thorax_node.empty()) m.thorax_compliance_m3_per_pa = thorax_compliance;
  if (scene.material.wall_fibre_stiffness > 0.0 && scene.material.model != MaterialModel::Msd)
    assign_wall_fibres(m, fibrous_tets(m, roles, scene), scene.material.wall_fibre_stiffness,
                      scene.material.wall_fibre_exponent);
  return m;
}

SolveOptions solve_options_from_scene(const Scene& s) {
  SolveOptions o;
  o.method = s.solver.method;
  o.forces.material = s.material.model;
  o.forces.mean_dilatation = s.material.mean_dilatation;
  o.forces.spring_model = s.material.spring_model;
  o.forces.stiffening = s.material.stiffening;
  o.forces.pressure_pa = units::mmhg_to_pa(s.load.pressure_mmhg);
  o.forces.volume_stiffness_pa = units::kpa_to_pa(s.effective_volume_stiffness_kpa());
  // Supine, down is posterior (−y in RAS); tilted head down by θ, sin θ of it points to the head (+z).
  const double tilt = s.material.tilt_deg * (3.14159265358979323846 / 180.0);
  if (s.material.gravity) o.forces.gravity_m_s2 = 9.81 * Vec3(0, -std::cos(tilt), std::sin(tilt));
  if (s.material.contact) o.forces.contact_stiffness = s.material.contact_stiffness;
  o.forces.tie_attached = !s.mesh.attached_labels.empty();
  o.dt_s = units::ms_to_s(s.solver.dt_ms);
  o.dt_safety = s.solver.dt_safety;
  o.max_steps = s.solver.max_steps;
  o.residual_tolerance = s.solver.residual_tolerance;
  o.velocity_tolerance_m_s = s.solver.velocity_tolerance_mm_s * units::kMetresPerMm;
  o.hold_steps = s.solver.hold_steps;
  o.ramp_s = units::ms_to_s(s.load.ramp_ms);
  o.ramp_shape = s.load.ramp_shape;
  o.newmark_beta = s.solver.newmark_beta;
  o.newmark_gamma = s.solver.newmark_gamma;
  o.newmark_inner_tolerance = s.solver.newmark_inner_tolerance;
  o.newmark_max_inner = s.solver.newmark_max_inner;
  o.newton_max_cg_iterations = s.solver.newton_max_cg_iterations;
  o.rayleigh_mass_per_s = s.solver.rayleigh_mass_per_s;
  o.rayleigh_stiffness_s = s.solver.rayleigh_stiffness_s;
  o.kitasaka_step = s.solver.kitasaka_step;
  o.kitasaka_tolerance_m = s.solver.kitasaka_tolerance_mm * units::kMetresPerMm;
  o.on_inverted = s.solver.on_inverted;
  o.allow_cpu_fallback = s.solver.allow_cpu_fallback || s.device == "auto";
  return o;
}

}  // namespace pneumo
