// The label table of the synthetic abdomen: id, TotalSegmentator name, simulation role, nominal HU and its source.
// Roles (method.md §2): wall = skin, subcutaneous fat, abdominal wall muscle, diaphragm; viscera = everything inside
// the peritoneal cavity and the retroperitoneal organs and vessels that move with it; fixed = bone, back and pelvic
// muscles, the thorax above the diaphragm (held by the rib cage), the table; other = air outside the body.
#include "phantom/phantom.h"
#include "phantom/phantom_model.h"

namespace pneumo {

namespace {
namespace L = phantom_detail::label;
namespace H = phantom_detail::hu;

// Sources, cited once and referred to below.
constexpr const char* kSrcHounsfield = "Hounsfield scale: air = -1000 HU by definition";
constexpr const char* kSrcLiver =
    "normal unenhanced liver 55-65 HU (Boyce et al., AJR 2010;194:623; Kodama et al., AJR 2007;188:1307)";
constexpr const char* kSrcSpleen =
    "unenhanced spleen 40-50 HU, about 8-10 HU below the liver (Kodama et al., AJR 2007;188:1307)";
constexpr const char* kSrcKidney = "unenhanced renal parenchyma 30-35 HU (Webb, Brant & Major, Fundamentals of Body CT)";
constexpr const char* kSrcPancreas = "unenhanced pancreas 40-50 HU (Webb, Brant & Major, Fundamentals of Body CT)";
constexpr const char* kSrcBlood = "unenhanced blood 35-45 HU depending on haematocrit (Webb, Brant & Major)";
constexpr const char* kSrcBowel =
    "bowel wall ~40 HU; enteric fluid without oral contrast 0-20 HU; gas -1000 HU (Webb, Brant & Major)";
constexpr const char* kSrcStomach = "gastric fluid 0-20 HU under an anterior gas cap; wall ~40 HU";
constexpr const char* kSrcColon = "faeces 0-60 HU mottled with gas bubbles; wall ~40 HU";
constexpr const char* kSrcBile = "gallbladder bile 0-20 HU (Webb, Brant & Major)";
constexpr const char* kSrcBone =
    "trabecular bone 150-250 HU in adults (L1: Pickhardt et al., Ann Intern Med 2013;158:588); cortex ~1000 HU";
constexpr const char* kSrcCartilage = "non-calcified hyaline cartilage 100-150 HU";
constexpr const char* kSrcSternum = "sternum/xiphoid: cancellous bone in a thin cortex, ~300 HU mean";
constexpr const char* kSrcDisc = "intervertebral disc 70-100 HU";
constexpr const char* kSrcCsf = "CSF 0-15 HU with the cord (~35 HU) partial-volumed";
constexpr const char* kSrcMuscle =
    "skeletal muscle 40-60 HU (Aubrey et al., Acta Physiol 2014;210:489: mean attenuation of healthy adults)";
constexpr const char* kSrcFat =
    "adipose tissue -120 to -80 HU (Kvist et al., Am J Clin Nutr 1988;48:1351; window -190 to -30)";
constexpr const char* kSrcMesentericFat = "mesenteric/retroperitoneal fat with fine vessels, -100 to -90 HU";
constexpr const char* kSrcSkin = "dermis +30 to +60 HU";
constexpr const char* kSrcLung = "aerated lung -900 to -800 HU at inspiration";
constexpr const char* kSrcHeart = "unenhanced blood pool and myocardium ~40 HU";
constexpr const char* kSrcTable = "carbon-fibre composite table top: shells ~+200 HU around a ~-950 HU foam core (vendor-dependent)";
constexpr const char* kSrcPad = "mattress foam of ~0.1 g/ml: about -900 HU";

std::vector<PhantomLabel> build_labels() {
  std::vector<PhantomLabel> v = {
      {L::kBackground, "background", Role::Other, H::kAir, kSrcHounsfield},
      {L::kSpleen, "spleen", Role::Viscera, H::kSpleen, kSrcSpleen},
      {L::kKidneyRight, "kidney_right", Role::Viscera, H::kKidney, kSrcKidney},
      {L::kKidneyLeft, "kidney_left", Role::Viscera, H::kKidney, kSrcKidney},
      {L::kGallbladder, "gallbladder", Role::Viscera, H::kBile, kSrcBile},
      {L::kLiver, "liver", Role::Viscera, H::kLiver, kSrcLiver},
      {L::kStomach, "stomach", Role::Viscera, H::kGastricFluid, kSrcStomach},
      {L::kPancreas, "pancreas", Role::Viscera, H::kPancreas, kSrcPancreas},
      {L::kLungLowerLobeLeft, "lung_lower_lobe_left", Role::Fixed, H::kLung, kSrcLung},
      {L::kLungLowerLobeRight, "lung_lower_lobe_right", Role::Fixed, H::kLung, kSrcLung},
      {L::kSmallBowel, "small_bowel", Role::Viscera, H::kBowelFluid, kSrcBowel},
      {L::kDuodenum, "duodenum", Role::Viscera, H::kBowelFluid, kSrcBowel},
      {L::kColon, "colon", Role::Viscera, H::kStool, kSrcColon},
      {L::kSacrum, "sacrum", Role::Fixed, H::kCancellousBone, kSrcBone},
      {L::kVertebraL5, "vertebrae_L5", Role::Fixed, H::kCancellousBone, kSrcBone},
      {L::kVertebraL4, "vertebrae_L4", Role::Fixed, H::kCancellousBone, kSrcBone},
      {L::kVertebraL3, "vertebrae_L3", Role::Fixed, H::kCancellousBone, kSrcBone},
      {L::kVertebraL2, "vertebrae_L2", Role::Fixed, H::kCancellousBone, kSrcBone},
      {L::kVertebraL1, "vertebrae_L1", Role::Fixed, H::kCancellousBone, kSrcBone},
      {L::kVertebraT12, "vertebrae_T12", Role::Fixed, H::kCancellousBone, kSrcBone},
      {L::kVertebraT11, "vertebrae_T11", Role::Fixed, H::kCancellousBone, kSrcBone},
      {L::kVertebraT10, "vertebrae_T10", Role::Fixed, H::kCancellousBone, kSrcBone},
      {L::kVertebraT9, "vertebrae_T9", Role::Fixed, H::kCancellousBone, kSrcBone},
      {L::kVertebraT8, "vertebrae_T8", Role::Fixed, H::kCancellousBone, kSrcBone},
      {L::kVertebraT7, "vertebrae_T7", Role::Fixed, H::kCancellousBone, kSrcBone},
      {L::kHeart, "heart", Role::Fixed, H::kBlood, kSrcHeart},
      {L::kAorta, "aorta", Role::Viscera, H::kBlood, kSrcBlood},
      {L::kInferiorVenaCava, "inferior_vena_cava", Role::Viscera, H::kBlood, kSrcBlood},
      {L::kPortalVein, "portal_vein_and_splenic_vein", Role::Viscera, H::kBlood, kSrcBlood},
      {L::kIliacArteryLeft, "iliac_artery_left", Role::Viscera, H::kBlood, kSrcBlood},
      {L::kIliacArteryRight, "iliac_artery_right", Role::Viscera, H::kBlood, kSrcBlood},
      {L::kIliacVeinLeft, "iliac_vena_left", Role::Viscera, H::kBlood, kSrcBlood},
      {L::kIliacVeinRight, "iliac_vena_right", Role::Viscera, H::kBlood, kSrcBlood},
      {L::kHipLeft, "hip_left", Role::Fixed, H::kCancellousBone, kSrcBone},
      {L::kHipRight, "hip_right", Role::Fixed, H::kCancellousBone, kSrcBone},
      {L::kSpinalCord, "spinal_cord", Role::Fixed, H::kCsf, kSrcCsf},
      {L::kGluteusMediusLeft, "gluteus_medius_left", Role::Fixed, H::kMuscle, kSrcMuscle},
      {L::kGluteusMediusRight, "gluteus_medius_right", Role::Fixed, H::kMuscle, kSrcMuscle},
      {L::kAutochthonLeft, "autochthon_left", Role::Fixed, H::kMuscle, kSrcMuscle},
      {L::kAutochthonRight, "autochthon_right", Role::Fixed, H::kMuscle, kSrcMuscle},
      {L::kIliopsoasLeft, "iliopsoas_left", Role::Fixed, H::kMuscle, kSrcMuscle},
      {L::kIliopsoasRight, "iliopsoas_right", Role::Fixed, H::kMuscle, kSrcMuscle},
  };
  for (int n = 7; n <= 12; ++n)
    v.push_back({L::rib_left(n), "rib_left_" + std::to_string(n), Role::Fixed, H::kCancellousBone, kSrcBone});
  for (int n = 7; n <= 12; ++n)
    v.push_back({L::rib_right(n), "rib_right_" + std::to_string(n), Role::Fixed, H::kCancellousBone, kSrcBone});
  const std::vector<PhantomLabel> tail = {
      {L::kSternum, "sternum", Role::Fixed, H::kSternum, kSrcSternum},
      {L::kCostalCartilages, "costal_cartilages", Role::Fixed, H::kCartilage, kSrcCartilage},
      {L::kSkin, "skin", Role::Wall, H::kSkin, kSrcSkin},
      {L::kSubcutaneousFat, "subcutaneous_fat", Role::Wall, H::kFat, kSrcFat},
      {L::kAbdominalWallMuscle, "abdominal_wall_muscle", Role::Wall, H::kMuscle, kSrcMuscle},
      {L::kIntraperitonealFat, "intraperitoneal_fat", Role::Viscera, H::kMesentericFat, kSrcMesentericFat},
      {L::kCtTable, "ct_table", Role::Fixed, H::kTableShell, kSrcTable},
      {L::kCtTablePad, "ct_table_pad", Role::Fixed, H::kPadFoam, kSrcPad},
      {L::kIntervertebralDisc, "intervertebral_disc", Role::Fixed, H::kDisc, kSrcDisc},
      {L::kDiaphragm, "diaphragm", Role::Wall, H::kMuscle, kSrcMuscle},
  };
  v.insert(v.end(), tail.begin(), tail.end());
  return v;
}
}  // namespace

const std::vector<PhantomLabel>& phantom_labels() {
  static const std::vector<PhantomLabel> labels = build_labels();
  return labels;
}

}  // namespace pneumo
