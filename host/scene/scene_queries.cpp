// Answers later stages ask of a scene, so that each rule (label → role, label → E, the default
// k_v) is written once rather than in every consumer.
#include <algorithm>

#include "core/error.h"
#include "scene/scene.h"

namespace pneumo {

const std::string& Scene::require_ct() const {
  if (inputs.ct.empty())
    throw InputError((path.empty() ? std::string("scene") : path) +
                     ": inputs.ct is not given; this command needs a CT (.nii, .nii.gz or .mhd)");
  return inputs.ct;
}

double Scene::young_kpa_for(Role role, int label) const {
  for (const LabelYoung& l : material.label_young_kpa)
    if (l.label == label) return l.young_kpa;
  if (role == Role::Wall && material.wall_young_kpa) return *material.wall_young_kpa;
  if (role == Role::Viscera && material.viscera_young_kpa) return *material.viscera_young_kpa;
  return material.young_kpa;
}

double Scene::young_kpa_for(Role role, int label, float hu) const {
  for (const LabelYoung& l : material.label_young_kpa)
    if (l.label == label) return l.young_kpa;
  if (is_lung_voxel(role, label, hu)) return *material.lung_young_kpa;
  if (material.fat_young_kpa && hu >= material.fat_hu_min && hu <= material.fat_hu_max) return *material.fat_young_kpa;
  return young_kpa_for(role, label);
}

bool Scene::is_lung_voxel(Role role, int label, float hu) const {
  if (role != Role::Wall || !roles.compliant_lungs || !material.lung_young_kpa || hu > material.lung_hu_max)
    return false;
  return label == 0 || std::find(roles.lung_ids.begin(), roles.lung_ids.end(), label) != roles.lung_ids.end();
}

double Scene::poisson_for(Role role, int label) const {
  for (const LabelYoung& l : material.label_young_kpa)
    if (l.label == label && l.poisson_ratio) return *l.poisson_ratio;
  if (role == Role::Wall && material.wall_poisson_ratio) return *material.wall_poisson_ratio;
  if (role == Role::Viscera && material.viscera_poisson_ratio) return *material.viscera_poisson_ratio;
  return material.poisson_ratio;
}

double Scene::poisson_for(Role role, int label, float hu) const {
  for (const LabelYoung& l : material.label_young_kpa)
    if (l.label == label) return l.poisson_ratio ? *l.poisson_ratio : poisson_for(role, label);
  if (is_lung_voxel(role, label, hu)) return material.lung_poisson_ratio;
  return poisson_for(role, label);
}

void use_nimura_springs(SceneMaterial& m) {
  m.model = MaterialModel::Msd;
  m.stiffening = 0.0;
  m.fat_young_kpa.reset();
  m.lung_young_kpa.reset();
  m.viscera_young_kpa.reset();
}

double Scene::effective_volume_stiffness_kpa() const {
  if (material.volume_stiffness_kpa) return *material.volume_stiffness_kpa;
  // Kitasaka gives no value for k_v. k_v = E adds E to the lattice's bulk modulus (0.721 E, shear
  // 0.432 E, §4): ν rises from 0.25 to about 0.38, nearer the (nearly incompressible) tissue.
  // Not measured against data: set volume_stiffness_kpa to choose otherwise.
  return solver.method == SolverMethod::Kitasaka2004 ? material.young_kpa : 0.0;
}

}  // namespace pneumo
