#include "roles/structure_names.h"

#include <algorithm>
#include <cctype>
#include <regex>
#include <set>
#include <sstream>

namespace pneumo {

namespace {

/// The name as the table spells it: lower case, words joined by '_', without a side or a trailing
/// number ("Kidney Left" → "kidney", "rib_left_11" → "rib", "vertebrae_L5" → "vertebrae_l5").
std::string normalised(const std::string& name) {
  std::string s;
  for (char c : name) s += std::isalnum(static_cast<unsigned char>(c)) ? char(std::tolower(static_cast<unsigned char>(c))) : ' ';
  static const std::set<std::string> sides{"left", "right", "l", "r", "lt", "rt"};
  std::istringstream words(s);
  std::vector<std::string> kept;
  for (std::string w; words >> w;)
    if (!sides.count(w)) kept.push_back(w);
  while (!kept.empty() && std::all_of(kept.back().begin(), kept.back().end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); }))
    kept.pop_back();
  std::string out;
  for (const std::string& w : kept) out += (out.empty() ? "" : "_") + w;
  return out;
}

struct NameRule {
  std::regex pattern;   // matched against the whole normalised name
  Compartment compartment;
};

/// First match wins. Names are those of TotalSegmentator's tasks (v1 and v2: total, body,
/// tissue_types, liver_vessels, lung_vessels), the abdominal challenge sets (AMOS, BTCV, WORD,
/// FLARE) and the plain English a hand-made table would use; docs/roles.md gives each class's reason.
const std::vector<NameRule>& rules() {
  static const std::vector<NameRule> r = [] {
    const std::pair<const char*, Compartment> table[] = {
        // Tissue classes with no place of their own: the shell, back and bone rules place them.
        {"background|body|body_trunc|body_extremities|skin|fat|subcutaneous_fat|torso_fat|intermuscular_fat|"
         "visceral_fat|skeletal_muscle|muscle|soft_tissue|other|unknown|unlabelled|unlabeled",
         Compartment::Tissue},
        // The wall's own layers and the cavity's roof.
        {"rectus(_abdominis)?(_muscle)?|(external|internal)_obliques?(_muscle)?|transvers(us|e)_abdominis(_muscle)?|"
         "abdominal_wall.*|abdominal_muscles?|anterior_abdominal_wall|linea_alba|diaphragm",
         Compartment::AbdominalWall},
        // Inside the peritoneum: the organs the gas separates from the wall.
        {"liver.*|hepatic_(vessels?|veins?|tumou?r)|spleen.*|gall_?bladder|stomach|small_(bowel|intestine)|"
         "intestines?|bowel|jejunum|ileum|colon|(sigmoid|transverse|ascending|descending)_colon|sigmoid|"
         "large_(bowel|intestine)|c(a)?ecum|appendix|omentum|mesentery",
         Compartment::Peritoneal},
        // The bladder: the space of Retzius in front of it is extraperitoneal.
        {"(urinary_)?bladder", Compartment::Prevesical},
        // Behind the peritoneum, or below its reflection: the parietal side.
        {"kidneys?(_.*)?|rk|lk|adrenals?(_glands?)?|rag|lag|pancreas(_.*)?|duodenum|aorta|abdominal_aorta|"
         "inferior_vena_cava|vena_cava_inferior|ivc|postcava|portal_vein.*|splenic_vein|celiac_trunk|"
         "renal_(artery|arteries|vein|veins)|common_iliac_(artery|vein)|iliac_(artery|arteries|vena|vein|veins)|"
         "ureters?|rectum",
         Compartment::Retroperitoneal},
        // The lungs: the room the diaphragm rises into (roles.compliant_lungs).
        {"lungs?(_.*)?", Compartment::Lung},
        // What does not move: bone and cartilage, the back's and hip's muscles, the thorax, the head,
        // the neck's vessels, the pelvic organs below the peritoneum.
        {"vertebra(e)?(_.*)?|spine|ribs?|sacrum|coccyx|hips?|pelvis|(head_of_)?femur.*|humerus|scapula|"
         "clavicul(a|e)|sternum|costal_cartilages?|skull|mandible|spinal_(cord|canal)|"
         "gluteus_(maximus|medius|minimus)|autochthon|iliopsoas|psoas(_major)?|iliacus|quadratus_lumborum|"
         "erector_spinae|heart(_.*)?|myocardium|atrial_appendage|pulmonary_(artery|vein|trunk)|"
         "trachea|o?esophagus|thyroid(_gland)?|brachiocephalic_(trunk|vein)|subclavian_artery|"
         "common_carotid_artery|superior_vena_cava|mediastinum|thymus|brain|face|prostate.*|uterus|"
         "seminal_vesicles?",
         Compartment::Fixed},
    };
    std::vector<NameRule> out;
    for (const auto& [pattern, c] : table) out.push_back({std::regex(pattern, std::regex::optimize), c});
    return out;
  }();
  return r;
}

}  // namespace

const char* compartment_name(Compartment c) {
  switch (c) {
    case Compartment::Peritoneal: return "peritoneal";
    case Compartment::Retroperitoneal: return "retroperitoneal";
    case Compartment::Prevesical: return "prevesical";
    case Compartment::AbdominalWall: return "abdominal wall";
    case Compartment::Lung: return "lung";
    case Compartment::Fixed: return "fixed";
    case Compartment::Tissue: return "tissue";
    case Compartment::Unknown: return "unknown";
  }
  return "unknown";
}

Compartment compartment_of(const std::string& name) {
  const std::string n = normalised(name);
  if (n.empty()) return Compartment::Unknown;
  for (const NameRule& rule : rules())
    if (std::regex_match(n, rule.pattern)) return rule.compartment;
  return Compartment::Unknown;
}

bool lies_above_the_diaphragm(const std::string& name) {
  static const std::regex chest("lungs?(_.*)?|heart(_.*)?|myocardium|atrial_appendage|pulmonary_(artery|vein|trunk)",
                                std::regex::optimize);
  return std::regex_match(normalised(name), chest);
}

bool is_liver(const std::string& name) {
  static const std::regex liver("liver(_(lobe|segment)(_.*)?)?|(caudate|quadrate)_lobe", std::regex::optimize);
  return std::regex_match(normalised(name), liver);
}

RolesFromNames roles_from_names(const std::map<int, std::string>& names, const std::vector<int>& skip) {
  const std::set<int> skipped(skip.begin(), skip.end());
  RolesFromNames r;
  for (const auto& [id, name] : names) {
    if (id == 0 || skipped.count(id)) continue;
    switch (compartment_of(name)) {
      case Compartment::Peritoneal: r.viscera.push_back(id); break;
      case Compartment::Prevesical:
        r.prevesical.push_back(id);
        [[fallthrough]];
      case Compartment::Retroperitoneal:
        r.wall.push_back(id);
        r.attached.push_back(id);
        break;
      case Compartment::AbdominalWall: r.wall.push_back(id); break;
      case Compartment::Lung: r.lung.push_back(id); break;
      case Compartment::Fixed: r.fixed.push_back(id); break;
      case Compartment::Tissue: r.tissue.push_back(id); break;
      case Compartment::Unknown: r.unknown.push_back(id); break;
    }
  }
  return r;
}

}  // namespace pneumo
