#pragma once
// Roles by anatomy, not by id: what a label's NAME says about where the structure lies relative to
// the peritoneum, so that a label map from any segmentation tool (TotalSegmentator v1 or v2, AMOS,
// BTCV, WORD, FLARE, a hand-made one) gets its roles without a list of ids written for it
// (docs/roles.md: the table and why each class has its role).
//
// The compartments, and the role each gives (method.md §2):
//   peritoneal       organs inside the peritoneum (liver, spleen, stomach, bowel, colon, gallbladder):
//                    viscera, the gas opens around them;
//   retroperitoneal  organs and vessels behind the peritoneum (kidneys, adrenals, pancreas, duodenum,
//                    aorta, caval, portal and iliac vessels, rectum): wall, the parietal side they stay
//                    on, and attached (mesh.attached_labels: no gas opens between them and the viscera);
//   prevesical       the bladder: retroperitoneal, and the space in front of it is extraperitoneal
//                    (roles.auto_prevesical_labels: no gas opens in front of it);
//   abdominal wall   the wall's own muscles (rectus, obliques, transversus) and the diaphragm: wall;
//   lung             the lungs and their lobes: wall of the lung's stiffness with roles.compliant_lungs
//                    (the diaphragm rises into them), else fixed;
//   fixed            bone, the back's and the hip's muscles, the thorax's other contents (heart,
//                    mediastinal vessels), the head, the pelvic organs below the peritoneum: fixed;
//   tissue           a tissue class without a place (fat, muscle, skin, body): left to the HU rules;
//   unknown          a name the table does not know: left to the HU rules, and a warning names it.
#include <map>
#include <string>
#include <vector>

namespace pneumo {

enum class Compartment { Peritoneal, Retroperitoneal, Prevesical, AbdominalWall, Lung, Fixed, Tissue, Unknown };

/// "peritoneal", "retroperitoneal", …
const char* compartment_name(Compartment c);

/// The compartment a structure's name says. Case, spaces, hyphens, a side ("left", "right", "L", "R",
/// "lt", "rt") and a trailing number or level do not matter: "Kidney Left", "kidney_L", "LK" and
/// "kidney_cyst_right" are all retroperitoneal.
Compartment compartment_of(const std::string& name);

/// Whether the name is a structure of the chest above the diaphragm (a lung or its lobe, the heart or its
/// chambers, the pulmonary vessels): what the thorax's diaphragm is found under (anatomy/thorax.h).
bool lies_above_the_diaphragm(const std::string& name);

/// Whether the name is the liver (or a lobe or segment of it): the organ whose blood the gas pressure
/// drives out (SceneMaterial::liver_volume_loss).
bool is_liver(const std::string& name);

/// What a label map's names give the roles: ids (sorted) per role, the attached and prevesical ids,
/// and the names the table does not know.
struct RolesFromNames {
  std::vector<int> wall, viscera, fixed, attached, prevesical;
  std::vector<int> lung;      // ids of the lungs: wall or fixed as roles.compliant_lungs says
  std::vector<int> unknown;   // ids whose name the table does not know (HU rules decide them)
  std::vector<int> tissue;    // ids of tissue classes (HU rules decide them, no warning)
};

/// The roles of every named id except 0 (background) and the ids in `skip` (those the scene lists
/// itself, which override the names).
RolesFromNames roles_from_names(const std::map<int, std::string>& names, const std::vector<int>& skip = {});

}  // namespace pneumo
