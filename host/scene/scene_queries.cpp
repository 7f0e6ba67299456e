// Answers later stages ask of a scene, so that each rule (label → role, label → E, the default
// k_v) is written once rather than in every consumer.
#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/units.h"
#include "scene/scene.h"

namespace pneumo {

namespace {

// The pressure at which Nainamalai 2025 measured the liver's volume loss (liver_volume_loss).
constexpr double kLiverLossPressureMmhg = 12.0;

struct Moduli {
  double young_kpa, poisson;
};

// The liver's moduli: the viscera's shear modulus μ (elastography measures shear) and the bulk
// modulus K = p / −ln(1 − loss) its blood's outflow gives; E = 9Kμ / (3K + μ), ν = (3K − 2μ) / (2(3K + μ)).
Moduli liver_moduli(const SceneMaterial& m) {
  const double e = m.viscera_young_kpa.value_or(m.young_kpa), nu_viscera = m.viscera_poisson_ratio.value_or(m.poisson_ratio);
  const double mu = e / (2.0 * (1.0 + nu_viscera));
  const double k = units::mmhg_to_pa(kLiverLossPressureMmhg) / 1e3 / -std::log1p(-*m.liver_volume_loss);
  const double nu = (3.0 * k - 2.0 * mu) / (2.0 * (3.0 * k + mu));
  if (nu > 0.49) return {2.0 * mu * 1.49, 0.49};   // ν's bound in the table: the liver as the other viscera
  return {9.0 * k * mu / (3.0 * k + mu), nu};
}

}  // namespace

const std::string& Scene::require_ct() const {
  if (inputs.ct.empty())
    throw InputError((path.empty() ? std::string("scene") : path) +
                     ": inputs.ct is not given; this command needs a CT (.nii, .nii.gz or .mhd)");
  return inputs.ct;
}

bool Scene::takes_liver_compliance(Role role, int label) const {
  // The springs' ν is fixed at 1/4: they have no bulk modulus of their own to give the liver.
  if (role != Role::Viscera || !material.liver_volume_loss || label <= 0 || material.model == MaterialModel::Msd)
    return false;
  for (const LabelYoung& l : material.label_young_kpa)
    if (l.label == label) return false;
  return std::find(roles.liver_ids.begin(), roles.liver_ids.end(), label) != roles.liver_ids.end();
}

double Scene::young_kpa_for(Role role, int label) const {
  for (const LabelYoung& l : material.label_young_kpa)
    if (l.label == label) return l.young_kpa;
  if (takes_liver_compliance(role, label))
    return liver_moduli(material).young_kpa;
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

double Scene::thorax_compliance_m3_per_pa(double lung_in_view_m3) const {
  if (!material.thorax_compliance_l_per_cmh2o) return 0.0;
  const double compliance = units::l_per_cmh2o_to_m3_per_pa(*material.thorax_compliance_l_per_cmh2o);
  if (!(lung_in_view_m3 > 0.0) || !material.lung_young_kpa) return compliance;
  // V = K C: the lungs' volume from their bulk modulus K = E / (3 (1 − 2ν)) and the same compliance.
  const double bulk_pa = units::kpa_to_pa(*material.lung_young_kpa) / (3.0 * (1.0 - 2.0 * material.lung_poisson_ratio));
  return compliance * std::max(0.0, 1.0 - lung_in_view_m3 / (bulk_pa * compliance));
}

double Scene::poisson_for(Role role, int label) const {
  for (const LabelYoung& l : material.label_young_kpa)
    if (l.label == label && l.poisson_ratio) return *l.poisson_ratio;
  if (takes_liver_compliance(role, label))
    return liver_moduli(material).poisson;
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
