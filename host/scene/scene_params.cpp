// THE parameter table: every scene key, its unit, what it allows and what it means. The parser,
// the echo, the messages and docs/scene_reference.md are all made from these tables; the
// defaults are the member initialisers in scene.h (see the comments there for their sources).
// §n = a section of docs/method.md.
#include <cctype>
#include <string>

#include "scene/param_table.h"
#include "scene/scene_presets.h"

namespace pneumo::scene_detail {
namespace {

// ---- rules the ranges cannot say ---------------------------------------------------------------

bool is_device(const json& v) {
  // "cpu", "auto", "opencl", "opencl:P:D" with P, D non-negative integers.
  const std::string s = v.get<std::string>();
  if (s == "cpu" || s == "auto" || s == "opencl") return true;
  const std::string prefix = "opencl:";
  if (s.compare(0, prefix.size(), prefix) != 0) return false;
  const std::string rest = s.substr(prefix.size());
  const std::size_t colon = rest.find(':');
  const auto digits = [](const std::string& t) {
    if (t.empty() || t.size() > 4) return false;
    for (char ch : t)
      if (!std::isdigit(static_cast<unsigned char>(ch))) return false;
    return true;
  };
  return colon != std::string::npos && digits(rest.substr(0, colon)) && digits(rest.substr(colon + 1));
}

// View names become file names: keep them portable.
bool is_view_name(const json& v) {
  const std::string s = v.get<std::string>();
  if (s.empty() || s.size() > 64 || s[0] == '.') return false;
  for (char ch : s)
    if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '_' && ch != '-' && ch != '.') return false;
  return true;
}

bool is_non_decreasing(const json& v) {
  for (std::size_t i = 1; i < v.size(); ++i)
    if (v[i].get<double>() < v[i - 1].get<double>()) return false;
  return true;
}

bool is_nonzero_vec(const json& v) {
  return v[0].get<double>() != 0.0 || v[1].get<double>() != 0.0 || v[2].get<double>() != 0.0;
}

// Flat transfer-function point lists: [HU, v, HU, v, ...] with `stride` numbers per point.
bool is_points(const json& v, std::size_t stride) {
  if (v.size() % stride != 0) return false;
  for (std::size_t i = 0; i < v.size(); i += stride) {
    if (i > 0 && v[i].get<double>() < v[i - stride].get<double>()) return false;
    for (std::size_t c = 1; c < stride; ++c)
      if (!(v[i + c].get<double>() >= 0.0 && v[i + c].get<double>() <= 1.0)) return false;
  }
  return true;
}
bool is_opacity_points(const json& v) { return is_points(v, 2); }
bool is_colour_points(const json& v) { return is_points(v, 4); }

constexpr double kMaxLabel = 65535;  // label maps are read as up to 16-bit ids
constexpr double kMaxKPa = 1e6;      // 1 GPa: above any soft tissue by far, below overflow worries
// 0.1 kPa: ten times softer than the softest tissue of an abdomen (fat, 1-3 kPa; docs/fidelity.md).
// Below it a value only makes the forces vanish against rounding: NaN or a solve without end.
constexpr double kMinKPa = 0.1;
// 0.1 mmHg: a tenth of the lowest pressure an insufflator sets. A positive pressure below it moves
// the wall by less than rounding can tell from rest, so the solve cannot see it converge; 0 is the rest state.
constexpr double kMinPressureMmHg = 0.1;
bool is_rest_or_real_pressure(double p) { return p == 0.0 || p >= kMinPressureMmHg; }
bool rest_or_real_pressure(const json& v) { return is_rest_or_real_pressure(v.get<double>()); }
bool is_pressure_curve(const json& v) {
  if (!is_non_decreasing(v)) return false;
  for (const json& p : v)
    if (!is_rest_or_real_pressure(p.get<double>())) return false;
  return true;
}

// ---- sections ----------------------------------------------------------------------------------

const Table<SceneInputs>& inputs_table() {
  static const Table<SceneInputs> t{
      {"ct", &SceneInputs::ct, "", file_path(),
       "CT volume (.nii, .nii.gz, .mha, .mhd, .nrrd, .nhdr), or the folder of one DICOM CT series. Unset is accepted here; "
       "commands that need a CT say so."},
      {"labels", &SceneInputs::labels, "", file_path(),
       "Label map on the CT's voxel grid (integer ids): roles and organ colours."},
      {"label_names", &SceneInputs::label_names, "", file_path(),
       "CSV naming the label map's ids (a header with \"label_id\" and \"name\"; "
       "data/label_tables/totalsegmentator_total.csv for TotalSegmentator): the names of the label tables "
       "written beside deformed_labels (3D Slicer, ITK-SNAP). Unset: \"label N\"."},
  };
  return t;
}

const Table<RoleRules>& roles_table() {
  const Constraint ids = in(0, kMaxLabel);
  const Constraint pad = in(0, 500);
  static const Table<RoleRules> t{
      {"source", &RoleRules::source, "", any(),
       "Where roles come from (§2): \"labels\" = the role lists below, nothing else; \"auto\" = the label map's "
       "named structures (by_name) and the lists, the CT's HU rules for the rest."},
      {"wall_labels", &RoleRules::wall_labels, "", ids,
       "Label ids of the abdominal wall (skin, fat, muscle). A label id may be in one list only."},
      {"viscera_labels", &RoleRules::viscera_labels, "", ids,
       "Label ids of organs and everything inside the peritoneum that moves."},
      {"fixed_labels", &RoleRules::fixed_labels, "", ids, "Label ids that do not move: bone, back, table."},
      {"other_labels", &RoleRules::other_labels, "", ids, "Label ids left out of the simulation."},
      {"unlisted_label_role", &RoleRules::unlisted_label_role, "", any(),
       "Role of label ids in none of the lists (label 0, background, included unless listed)."},
      {"auto_body_threshold_hu", &RoleRules::auto_body_threshold_hu, "HU", in(-1024, 3071),
       "auto: voxels above this are body (air and lung below); its largest connected part is kept."},
      {"auto_bone_threshold_hu", &RoleRules::auto_bone_threshold_hu, "HU", in(-1024, 3071),
       "auto: body voxels above this are fixed (bone; contrast-filled vessels above it too)."},
      {"auto_wall_thickness_mm", &RoleRules::auto_wall_thickness_mm, "mm", above(0, 200),
       "auto: wall = body voxels within this distance of the skin, on the sides given by auto_wall_max_angle_deg."},
      {"auto_wall_max_angle_deg", &RoleRules::auto_wall_max_angle_deg, "deg", in(0, 180),
       "auto: the shell is wall where the skin faces within this angle of anterior (90 = lateral); "
       "the rest of the shell (the back, on the table) is fixed, the body inside it viscera."},
      {"auto_thorax", &RoleRules::auto_thorax, "", any(),
       "auto: find the chest above the diaphragm (anatomy/thorax.h: the lungs by density or by their labels, the "
       "diaphragm as the surface under them, the heart and mediastinum between them), hold the heart and "
       "mediastinum fixed and the lungs too unless compliant_lungs, with a diaphragm of wall under it, so no gas "
       "opens beside the lungs or the heart (docs/roles.md)."},
      {"auto_diaphragm_thickness_mm", &RoleRules::auto_diaphragm_thickness_mm, "mm", in(0, 50),
       "auto with auto_thorax: undecided tissue within this distance under the chest is wall (the diaphragm, a "
       "muscle sheet of a few mm; 5 keeps a voxel of wall between lung and gas on 3 mm grids). 0: none."},
      {"compliant_lungs", &RoleRules::compliant_lungs, "", any(),
       "The lungs (labelled by name, or found by density with auto_thorax) are wall tissue as soft as lung "
       "(material.lung_young_kpa), so the diaphragm rises into the chest under the gas; the heart, mediastinum and "
       "ribs stay fixed. false: the lungs are fixed and the diaphragm cannot rise (docs/fidelity.md, the diaphragm)."},
      {"auto_use_labels", &RoleRules::auto_use_labels, "", any(),
       "auto with a label map: voxels whose label is in a role list keep that role; HU rules fill in the rest."},
      {"by_name", &RoleRules::by_name, "", any(),
       "auto with a label map whose ids have names (inputs.label_names, or the names TotalSegmentator writes in "
       "the map's NIfTI header): ids that no list here names take the role their structure's name gives "
       "(docs/roles.md: peritoneal organs viscera; retroperitoneal ones and the bladder wall, attached; bone, "
       "thorax and back fixed); auto_prevesical_labels and mesh.attached_labels follow when the scene omits them. "
       "The lists override the names, id by id."},
      {"auto_prevesical_labels", &RoleRules::auto_prevesical_labels, "", ids,
       "auto with a label map: undecided tissue anterior to these labels in the same axial column becomes wall "
       "(the space of Retzius in front of the bladder is extraperitoneal: no gas opens there), and so does "
       "undecided tissue anterior to their back in the slices from their top down (below the peritoneal "
       "reflection at the bladder's dome only the pouch behind it is peritoneal). Where an organ of "
       "viscera_labels lies in front of the bladder in a column, the wall starts in front of that organ: "
       "the peritoneum lies in front of the bladder there. TotalSegmentator: [21]."},
      {"pad_anterior_mm", &RoleRules::pad_anterior_mm, "mm", pad,
       "Air added in front of the CT so the wall has room to rise. Unset: 60 mm where the body comes closer than "
       "that to the CT's front edge (a CT cropped at the skin), none otherwise (roles/auto_pad.h). source \"labels\": unset is 0."},
      {"pad_lateral_mm", &RoleRules::pad_lateral_mm, "mm", pad,
       "Air added on the left and on the right. Unset: 60 mm on both where the body comes closer than that to "
       "either side's edge, none otherwise. source \"labels\": unset is 0."},
      {"pad_superior_mm", &RoleRules::pad_superior_mm, "mm", pad, "Air added above the CT (head side)."},
      {"pad_inferior_mm", &RoleRules::pad_inferior_mm, "mm", pad, "Air added below the CT (feet side)."},
  };
  return t;
}

const Table<SceneMesh>& mesh_table() {
  static const Table<SceneMesh> t{
      {"cube_voxels", &SceneMesh::cube_voxels, "voxels", in(1, 64),
       "L: each mesh cube covers L×L×L voxels, split into 5 tetrahedra (§3; Nimura: 8); [i, j, k]: that many voxels "
       "along each axis of the CT's grid, for near-cubic cubes on anisotropic voxels (e.g. [12, 12, 4] on "
       "0.75×0.75×2.5 mm). Ignored where cube_mm is set. Unset with cube_mm unset too: 9 mm cubes (the balanced preset's), near-cubic on any grid."},
      {"cube_mm", &SceneMesh::cube_mm, "mm", above(0, 1000),
       "Cube edge in mm instead of voxels: on each axis of the CT's grid, the whole number of voxels nearest to it "
       "(at least 1), so cubes are near-cubic on any grid, each edge within half a voxel of cube_mm (9 on "
       "0.75×0.75×2.5 mm voxels: 12×12×4 voxels, 9×9×10 mm). The presets set it, so they mean the same on any CT. "
       "Unset: cube_voxels where the scene gives it, else 9 mm (the balanced preset's cubes)."},
      {"model", &SceneMesh::model, "", any(),
       "\"wall_viscera\": wall and viscera are two meshes, the gas opens between them (§3); "
       "\"wall\": the wall alone, pressure on its inner surface."},
      {"roi_min_mm", &SceneMesh::roi_min_mm, "mm", any(),
       "Lower corner (world RAS+) of the box meshed; with roi_max_mm, both or neither. Unset: the whole volume."},
      {"roi_max_mm", &SceneMesh::roi_max_mm, "mm", any(), "Upper corner of the box meshed; each coordinate > roi_min_mm's."},
      {"attached_labels", &SceneMesh::attached_labels, "", in(0, kMaxLabel),
       "Wall labels the viscera stay on (retroperitoneal and extraperitoneal organs): no gas opens between them "
       "and the viscera, which are bonded to them there (solve/interface_tie.h). Needs solver.method \"static\", "
       "\"newton\" or \"implicit-euler\". TotalSegmentator: the example scene's wall_labels. Empty: every "
       "wall-viscera interface may open."},
      {"cut_faces", &SceneMesh::cut_faces, "", any(),
       "Where the CT cuts the body (at L3, at the liver, a field of view that cuts the flanks): \"slide\" holds "
       "the cut face's nodes on its normal (cranio-caudally, or laterally) and leaves them free in its plane, as if "
       "the body continued beyond as its mirror image (docs/fidelity.md, cut faces); the front and back are never "
       "held. \"free\": the cut face is a free surface, and the wall's edge lifts like a flap. The faces are the "
       "CT's own, inside the air the roles pad around it."},
  };
  return t;
}

const Table<LabelYoung>& label_young_table() {
  static const Table<LabelYoung> t{
      {"label", &LabelYoung::label, "", in(0, kMaxLabel).req(), "Label id."},
      {"young_kpa", &LabelYoung::young_kpa, "kPa", in(kMinKPa, kMaxKPa).req(), "Young's modulus of tetrahedra of this label."},
      {"poisson_ratio", &LabelYoung::poisson_ratio, "", in(0, 0.49),
       "ν of this label's finite elements; unset = its role's (the springs ignore it)."},
  };
  return t;
}

const Table<SceneMaterial>& material_table() {
  static const Table<SceneMaterial> t{
      {"density_kg_m3", &SceneMaterial::density_kg_m3, "kg/m³", in(100, 5000),
       "ρ: node mass = ρ × a quarter of each adjacent tetrahedron's volume (§4; Nimura 1096)."},
      {"young_kpa", &SceneMaterial::young_kpa, "kPa", in(kMinKPa, kMaxKPa),
       "E of every tetrahedron unless overridden (§4; Nimura 60; measured wall 22.5-42.5)."},
      {"wall_young_kpa", &SceneMaterial::wall_young_kpa, "kPa", in(kMinKPa, kMaxKPa),
       "E of wall tetrahedra; unset = young_kpa (Bano: 24)."},
      {"viscera_young_kpa", &SceneMaterial::viscera_young_kpa, "kPa", in(kMinKPa, kMaxKPa),
       "E of viscera tetrahedra; null = young_kpa. Default 5.5: the healthy liver in vivo by transient elastography "
       "(Roulot 2008: 5.49 ± 1.59 kPa in 429 adults); Bano used 15 from tissue tests (docs/fidelity.md §5)."},
      {"label_young_kpa", &SceneMaterial::label_young_kpa, label_young_table(), any(),
       "E per label id, over the role's value: [{\"label\": 5, \"young_kpa\": 3}]."},
      {"fat_young_kpa", &SceneMaterial::fat_young_kpa, "kPa", in(kMinKPa, kMaxKPa),
       "E of wall and viscera voxels in the fat window [fat_hu_min, fat_hu_max] unless their label has one; "
       "null = off (their role's E). Default 3, the upper end of 1-3 kPa for fat (docs/fidelity.md §3); null with "
       "fem-corotational, a linear law that 12 mmHg would turn such tissue inside out in."},
      {"fat_hu_min", &SceneMaterial::fat_hu_min, "HU", in(-1024, 3071), "Lower end of the fat window (-190)."},
      {"fat_hu_max", &SceneMaterial::fat_hu_max, "HU", in(-1024, 3071), "Upper end of the fat window (-30)."},
      {"lung_young_kpa", &SceneMaterial::lung_young_kpa, "kPa", in(kMinKPa, kMaxKPa),
       "With roles.compliant_lungs: E of aerated wall voxels (HU at or below lung_hu_max: the lungs), "
       "unlabelled or of a label named lung, unless their label has an E of its own; null = off (the wall's E). Default 1.0 with lung_poisson_ratio 0.40: bulk modulus "
       "1.7 kPa, the anaesthetised lung's volume over its compliance, shear 0.36 kPa (Lai-Fook 1977; "
       "docs/fidelity.md, the diaphragm)."},
      {"lung_poisson_ratio", &SceneMaterial::lung_poisson_ratio, "", in(0, 0.49),
       "ν of the lungs' finite elements (0.40; the springs ignore it)."},
      {"lung_hu_max", &SceneMaterial::lung_hu_max, "HU", in(-1024, 3071),
       "With compliant_lungs, wall voxels at or below this are lung (-500, the body mask's threshold: aerated lung "
       "lies below at any inspiration, and the skin's partial-volume rim, body only above it, is never lung)."},
      {"thorax_compliance_l_per_cmh2o", &SceneMaterial::thorax_compliance_l_per_cmh2o, "L/cmH2O", in(1e-3, 10),
       "With mesh.cut_faces \"slide\": where the CT's cranial cut face cuts viscera or lung, the chest goes on "
       "beyond it. That face is not held but moves into a gas spring as a whole: one pleural pressure ΔV/C over "
       "the face, C this compliance times the share of the lungs not in view (their volume: lung_young_kpa's bulk "
       "modulus times C), and the face's shape held as the sliding cut holds it. 0.12 is the anaesthetised adult "
       "lung's, as lung_young_kpa. null (the default): the cranial cut slides like the others (docs/fidelity.md, "
       "the chest beyond the cut)."},
      {"damping_ratio", &SceneMaterial::damping_ratio, "", in(0, 10),
       "ζ: each spring's damper c = 2ζ√(m k) (§4; Nimura 0.4)."},
      {"spring_scale", &SceneMaterial::spring_scale, "", in(0.01, 10),
       "Multiplies every spring stiffness; 0.925 makes the lattice's isotropic modulus equal E (§4)."},
      {"spring_model", &SceneMaterial::spring_model, "", any(),
       "\"nonlinear\": rotation-invariant springs (§5); \"linear\": Nimura's Eq. 1 as printed."},
      {"model", &SceneMaterial::model, "", any(),
       "\"msd\": the mass-spring lattice (§4-5); \"fem-corotational\": co-rotational linear tetrahedra (as SOFA, "
       "Bano 2012); \"fem-neohookean\": neo-Hookean tetrahedra, with Demiray's stiffening when stiffening > 0. The "
       "FEM models need solver.method \"newton\" (the fast choice), \"static\" or \"implicit-euler\" (docs/fem.md). "
       "The default is the elements: their ν is per role, so the viscera keep their volume where the springs' ν is "
       "fixed near 1/4; `pneumo bench` says per preset which model is fastest within the adult figures (docs/fidelity.md §4)."},
      {"poisson_ratio", &SceneMaterial::poisson_ratio, "", in(0, 0.49),
       "ν of the finite elements unless overridden (Bano 2012: 0.49 for the wall); the springs' ν is 1/4."},
      {"wall_poisson_ratio", &SceneMaterial::wall_poisson_ratio, "", in(0, 0.49),
       "ν of wall finite elements; unset = poisson_ratio."},
      {"viscera_poisson_ratio", &SceneMaterial::viscera_poisson_ratio, "", in(0, 0.49),
       "ν of viscera finite elements; null = poisson_ratio. Default 0.49: organs and bowel contents keep their "
       "volume, so the room the gas takes is found by moving, not shrinking (docs/fidelity.md, the viscera's volume)."},
      {"liver_volume_loss", &SceneMaterial::liver_volume_loss, "", in(0.001, 0.5),
       "The fraction of its volume the liver loses at 12 mmHg as the gas drives its blood out (Nainamalai 2025: 12 % "
       "in 15 patients): the liver's bulk modulus K = 12 mmHg / -ln(1 - loss), its shear modulus the viscera's. "
       "Applies to finite-element viscera of a label named liver (the springs' ν is fixed); null = off "
       "(docs/fidelity.md, the viscera's volume)."},
      {"wall_fibre_stiffness", &SceneMaterial::wall_fibre_stiffness, "", in(0, 100),
       "k1/mu of the wall's circumferential collagen fibres (the obliques' and transversus' aponeuroses): a "
       "Holzapfel-Gasser-Ogden fibre term k1/(2 k2)(exp(k2 (I4 - 1)^2) - 1) in tension, k1 this multiple of each "
       "wall element's shear modulus. 0.67 makes the wall 1.89 times as stiff across the body as along it, Song "
       "2006's ratio (42.5 against 22.5 kPa in 18 patients); 0 = an isotropic wall. Finite elements only; the lungs "
       "take none (docs/fem.md, fibres)."},
      {"wall_fibre_exponent", &SceneMaterial::wall_fibre_exponent, "", in(0, 100),
       "k2 of the wall's fibre term: how fast the fibres stiffen as they stretch; 0 = quadratic, k1/2 (I4 - 1)^2 "
       "(no measurement of the living wall's k2 is known to us; the matrix's stiffening is material.stiffening)."},
      {"mean_dilatation", &SceneMaterial::mean_dilatation, "", any(),
       "FEM: average the volumetric strain over each cube's tetrahedra (B-bar), so nearly incompressible tissue does "
       "not lock; false = per tetrahedron (docs/fem.md)."},
      {"stiffening", &SceneMaterial::stiffening, "", in(0, 50),
       "b of the strain-stiffening spring law: tension k·l0·(exp(b·strain) - 1)/b in tension, the small-strain "
       "stiffness kept; 0 = linear (nonlinear springs only; docs/fidelity.md). With fem-neohookean: b of Demiray's "
       "law, shear energy μ/(2b)(exp(b(I1 - 3)) - 1). Default 10: a calibration that gives the real CT McDougall's "
       "pressure-volume shape, V(15)/V(30) near 0.67 (docs/fidelity.md §3); 0 when the scene picks "
       "fem-corotational, a linear law."},
      {"volume_stiffness_kpa", &SceneMaterial::volume_stiffness_kpa, "kPa", at_least(0),
       "k_v of Kitasaka's volume-preserving force (§5). Unset: young_kpa for kitasaka2004, 0 (off) for the "
       "other solvers."},
      {"gravity", &SceneMaterial::gravity, "", any(),
       "Apply gravity (9.81 m/s², towards posterior: supine). The CT already shows the body under gravity (§5)."},
      {"gravity_compensation", &SceneMaterial::gravity_compensation, "", any(),
       "With gravity: solve from the unloaded shape whose equilibrium under gravity is the CT (Bano 2012, iterated "
       "to 1 % of the sag), so the weight the CT already shows is not applied twice; false = gravity sags the CT's "
       "own shape (solve/gravity_compensation.h)."},
      {"tilt_deg", &SceneMaterial::tilt_deg, "deg", in(-45, 45),
       "Table tilt about the left-right axis with gravity on: > 0 head down (Trendelenburg, 15-30 in pelvic "
       "surgery), < 0 head up (reverse Trendelenburg, upper abdomen); gravity then has 9.81·sin(tilt) towards the "
       "head."},
      {"contact", &SceneMaterial::contact, "", any(),
       "Keep the viscera out of the wall and the bone: frictionless penalty contact on the cavity faces, sliding "
       "(solve/contact.h). Needs solver.method \"static\", \"newton\" or \"implicit-euler\"."},
      {"contact_stiffness", &SceneMaterial::contact_stiffness, "", above(0, 1e4),
       "κ of the contact penalty k = κ·E/h per unit area (E the stiffer tissue, h the cube edge): penetration "
       "p_c·h/(κ·E) at contact pressure p_c."},
  };
  return t;
}

const Table<SceneLoad>& load_table() {
  static const Table<SceneLoad> t{
      {"pressure_mmhg", &SceneLoad::pressure_mmhg, "mmHg",
       in(0, 100).rule("0 (rest) or at least 0.1", rest_or_real_pressure),
       "CO2 pressure on the cavity surfaces (§5). 12 is usual in surgery (Nimura used 10)."},
      {"ramp_ms", &SceneLoad::ramp_ms, "ms", in(0, 600000),
       "Time to ramp the pressure up (§6); 0 = all at once (overshoots). 500 ≈ 2.5 periods of an adult "
       "wall's slowest mode. Dynamic solvers only."},
      {"ramp_shape", &SceneLoad::ramp_shape, "", any(),
       "\"smooth\": (1 - cos πτ)/2; \"linear\": τ (§6)."},
      {"pressure_curve_mmhg", &SceneLoad::pressure_curve_mmhg, "mmHg",
       in(0, 100).items(0, 100).rule("non-decreasing, each 0 (rest) or at least 0.1", is_pressure_curve),
       "Pressures for a pressure-volume curve, each run to equilibrium from the previous one (§9). "
       "Empty: pressure_mmhg only."},
  };
  return t;
}

const Table<SceneSolver>& solver_table() {
  static const Table<SceneSolver> t{
      {"method", &SceneSolver::method, "", any(),
       "\"static\": fast equilibrium; \"explicit\": symplectic Euler; \"newmark\": Nimura's Newmark-β; "
       "\"kitasaka2004\": Kitasaka's quasi-static scheme (§6); \"newton\": Newton with preconditioned conjugate "
       "gradients (static; every material model; on OpenCL for the finite elements); \"implicit-euler\": "
       "backward Euler with conjugate gradients and Rayleigh damping (dynamic, as Bano 2012 with SOFA; every "
       "material model; CPU). The finite elements take \"static\", \"newton\" or \"implicit-euler\". Default "
       "\"newton\": it converges for every model, where FIRE diverges on the elements (bench/results)."},
      {"dt_ms", &SceneSolver::dt_ms, "ms", in(0, 1000),
       "Time step of explicit and newmark; 0 = dt_safety × the stability bound (§6)."},
      {"dt_safety", &SceneSolver::dt_safety, "", above(0, 1), "Fraction of the stability bound used when dt_ms = 0."},
      {"max_steps", &SceneSolver::max_steps, "", in(1, 1e9), "Stop (reported as the step limit) after this many steps."},
      {"residual_tolerance", &SceneSolver::residual_tolerance, "", above(0, 1),
       "Converged when the largest net node force is below this fraction of the largest pressure force (§6)."},
      {"velocity_tolerance_mm_s", &SceneSolver::velocity_tolerance_mm_s, "mm/s", above(0, 1e6),
       "Dynamic solvers: converged also needs every node slower than this (§6)."},
      {"hold_steps", &SceneSolver::hold_steps, "", in(1, 1000000),
       "Convergence must hold this many consecutive steps, after the ramp (§6)."},
      {"newmark_beta", &SceneSolver::newmark_beta, "", in(0, 0.5), "β of Newmark (§6; Nimura 1/4)."},
      {"newmark_gamma", &SceneSolver::newmark_gamma, "", in(0.5, 1), "γ of Newmark, Nimura's δ (§6; Nimura 1/2)."},
      {"newmark_inner_tolerance", &SceneSolver::newmark_inner_tolerance, "", above(0, 1),
       "Newmark's inner loop stops when the accelerations change by less than this, relative (§6)."},
      {"newmark_max_inner", &SceneSolver::newmark_max_inner, "", in(1, 10000),
       "Inner iterations allowed per step; more is reported as divergence of the inner loop."},
      {"kitasaka_step", &SceneSolver::kitasaka_step, "", above(0, 2),
       "Δs of the 2004 scheme, R += Δs F/D (§6; Kitasaka 0.3)."},
      {"kitasaka_tolerance_mm", &SceneSolver::kitasaka_tolerance_mm, "mm", above(0, 1e9),
       "β of the 2004 scheme: stop when Σ|ΔR| over all nodes is below it (Kitasaka Eq. 3; scales with node count)."},
      {"allow_cpu_fallback", &SceneSolver::allow_cpu_fallback, "", any(),
       "When the scene's OpenCL device cannot run solver.method with material.model (OpenCL solves newton on the "
       "finite elements, the other schemes on the springs without contact or bonded interfaces): false refuses the run before it "
       "starts; true solves on the CPU and says so in metrics.json (device, device_fallback). Device \"auto\" "
       "always may."},
      {"on_inverted", &SceneSolver::on_inverted, "", any(),
       "When a tetrahedron turns inside out: \"continue\" (counted and reported) or \"stop\"."},
      {"checkpoint_every_steps", &SceneSolver::checkpoint_every_steps, "", in(0, 1e9),
       "Save the node state every this many steps, to resume a long run; 0 = never."},
      {"newton_max_cg_iterations", &SceneSolver::newton_max_cg_iterations, "", in(1, 100000),
       "newton: conjugate-gradient iterations allowed per Newton step (the step keeps what it reached); "
       "implicit-euler: per time step."},
      {"rayleigh_mass_per_s", &SceneSolver::rayleigh_mass_per_s, "1/s", in(0, 1000),
       "implicit-euler: α of Rayleigh's damping C = α M + β K (SOFA's EulerImplicitSolver; 0.1 its former default)."},
      {"rayleigh_stiffness_s", &SceneSolver::rayleigh_stiffness_s, "s", in(0, 10),
       "implicit-euler: β of Rayleigh's damping C = α M + β K (0.1 SOFA's former default)."},
  };
  return t;
}

const Table<Optics>& optics_table() {
  static const Table<Optics> t{
      {"up", &Optics::up, "", any().rule("not [0, 0, 0]", is_nonzero_vec),
       "Direction that appears up in the image (world RAS+; [0, 0, 1] = superior)."},
      {"fov_deg", &Optics::fov_deg, "deg", above(0, 180),
       "Field of view across the image (§8: 70); a pinhole lens needs < 180."},
      {"lens", &Optics::lens, "", any(), "\"pinhole\" or \"fisheye\" (equidistant, up to 180°) (§8)."},
      {"oblique_deg", &Optics::oblique_deg, "deg", in(0, 90),
       "Angle between the scope's axis and its view direction (laparoscopes: 0, 30, 45) (§8)."},
      {"roll_deg", &Optics::roll_deg, "deg", in(-180, 180),
       "Rotation of the scope about its axis; turns an oblique view around the axis."},
      {"near_mm", &Optics::near_mm, "mm", in(0, 1000), "Nothing closer than this to the tip is drawn."},
  };
  return t;
}

Constraint view_name() {
  return required().rule("letters, digits, '_', '-', '.'; 1 to 64; unique across views", is_view_name);
}

const Table<Camera>& camera_table() {
  static const Table<Camera> t(
      {
          {"name", &Camera::name, "", view_name(), "Names the output images."},
          {"position_mm", &Camera::position_mm, "mm", required(), "Scope tip (world RAS+)."},
          {"look_at_mm", &Camera::look_at_mm, "mm", required(), "A point on the scope's axis, ahead of the tip."},
      },
      inline_params(&Camera::optics, optics_table()));
  return t;
}

const Table<Port>& port_table() {
  static const Table<Port> t(
      {
          {"name", &Port::name, "", view_name(), "Names the output images."},
          {"skin_point_mm", &Port::skin_point_mm, "mm", required(),
           "Where the trocar enters, on the CT's skin; carried through the deformation (§8)."},
          {"target_mm", &Port::target_mm, "mm", any(), "Point the scope aims at; or give target_label."},
          {"target_label", &Port::target_label, "", in(1, kMaxLabel),
           "Label id whose centroid (after deformation) the scope aims at; or give target_mm."},
          {"insertion_mm", &Port::insertion_mm, "mm", in(0, 500),
           "Scope tip's distance beyond the skin point, along the port axis."},
      },
      inline_params(&Port::optics, optics_table()));
  return t;
}

const Table<Keyframe>& keyframe_table() {
  static const Table<Keyframe> t{
      {"position_mm", &Keyframe::position_mm, "mm", required(), "Scope tip (world RAS+, deformed frame)."},
      {"look_at_mm", &Keyframe::look_at_mm, "mm", required(), "A point on the scope's axis, ahead of the tip."},
  };
  return t;
}

const Table<CameraPath>& path_table() {
  static const Table<CameraPath> t(
      {
          {"name", &CameraPath::name, "", view_name(), "Names the output frames."},
          {"frames", &CameraPath::frames, "", in(2, 100000), "Frames rendered along the path."},
          {"keyframes", &CameraPath::keyframes, keyframe_table(), any().items(2).req(),
           "Poses the path passes through, interpolated in order."},
      },
      inline_params(&CameraPath::optics, optics_table()));
  return t;
}

const Table<ViewSettings>& render_table() {
  static const Table<ViewSettings> t{
      {"width", &ViewSettings::width, "px", in(16, 8192), "Image width."},
      {"height", &ViewSettings::height, "px", in(16, 8192), "Image height."},
      {"preset", &ViewSettings::preset, "", any(),
       "Transfer function (§8): \"laparoscopic\" (tissue colours computed from published optical properties, "
       "gas clear), one of 3D Slicer's CT presets, \"skin\" (the body's surface, as the exterior views show it) "
       "or \"custom\" (the two lists below)."},
      {"custom_opacity", &ViewSettings::custom_opacity, "", any().rule("pairs [HU, opacity 0 to 1], HU non-decreasing", is_opacity_points),
       "Preset \"custom\": opacity per 1 mm of ray at HU points, [HU, α, HU, α, ...]; linear between, constant beyond."},
      {"custom_colour", &ViewSettings::custom_colour, "", any().rule("quadruples [HU, r, g, b], components 0 to 1, HU non-decreasing", is_colour_points),
       "Preset \"custom\": colours at HU points, [HU, r, g, b, ...]."},
      {"ambient", &ViewSettings::ambient, "", in(0, 1), "Phong ambient coefficient (light present without the headlight)."},
      {"diffuse", &ViewSettings::diffuse, "", in(0, 1), "Phong diffuse coefficient (headlight, CT gradient normals)."},
      {"specular", &ViewSettings::specular, "", in(0, 1), "Phong specular coefficient (white highlights)."},
      {"shininess", &ViewSettings::shininess, "", in(1, 1000), "Phong specular exponent."},
      {"exterior_views", &ViewSettings::exterior_views, "", any(),
       "Also render the body from outside (anterior and left): the skin as a surface near -500 HU, before and after "
       "inflation side by side, the ports marked (§8)."},
      {"step_fraction", &ViewSettings::step_fraction, "", above(0, 0.5),
       "Ray step as a fraction of the smallest voxel spacing (§8: at most half)."},
      {"smoothing_mm", &ViewSettings::smoothing_mm, "mm", in(0, 10),
       "Sigma of the Gaussian the views' copy of the CT is prefiltered with, at least one voxel on each axis "
       "(§8): it hides the voxel lattice's terraces and tile mosaic and keeps a fine CT's noise from showing as "
       "grain (docs/rendering.md); 0 renders the voxels as they are. Measurements always read the CT itself."},
      {"vignetting_power", &ViewSettings::vignetting_power, "", in(0, 8),
       "Laparoscope views darken towards the rim as cos^n of the ray's angle to the view direction (§8): 4 is "
       "the cos^4 law of a lens's relative illumination; 0 none. Exterior views never."},
      {"antialias_samples", &ViewSettings::antialias_samples, "", in(1, 64),
       "Each view the mean of this many passes, each at another point of the pixel (a low-discrepancy set) "
       "with its own step jitter: smooth silhouettes, at this many times the frame time (§8)."},
      {"jitter", &ViewSettings::jitter, "", any(), "Offset each ray's start randomly (hides wood-grain bands; images then vary)."},
      {"show_labels", &ViewSettings::show_labels, "", any(),
       "Blend organ label colours over the CT colour (§8) when a label map is given."},
      {"label_opacity", &ViewSettings::label_opacity, "", in(0, 1), "Opacity of the label colours."},
      {"light_falloff_mm", &ViewSettings::light_falloff_mm, "mm", above(0, 10000),
       "d0 of the headlight: intensity 1/(1+(d/d0)²) at distance d from the tip (§8)."},
      {"cameras", &ViewSettings::cameras, camera_table(), any().items(0, 256), "Views given by tip and aim."},
      {"ports", &ViewSettings::ports, port_table(), any().items(0, 256),
       "Views from trocar ports on the skin, aimed at a point or an organ."},
      {"paths", &ViewSettings::paths, path_table(), any().items(0, 64), "Fly-throughs along keyframes."},
      {"video_fps", &ViewSettings::video_fps, "frames/s", in(1, 120),
       "Frame rate of the fly-through and inflation-preview MP4s: a path of N frames plays for N / video_fps s."},
  };
  return t;
}

const Table<SceneOutput>& output_table() {
  static const Table<SceneOutput> t{
      {"folder", &SceneOutput::folder, "", file_path(), "Where outputs go; unset: the command line decides (--out)."},
      {"write_meshes", &SceneOutput::write_meshes, "", any(), "Write the rest and deformed meshes, mesh_initial.vtu and mesh_deformed.vtu (VTK XML, zlib-compressed: ParaView, VTK, meshio)."},
      {"write_deformed_ct", &SceneOutput::write_deformed_ct, "", any(), "Write the warped CT (§7)."},
      {"write_deformed_labels", &SceneOutput::write_deformed_labels, "", any(),
       "Write the warped label map (with the cavity label) when a label map is given (§7)."},
      {"write_displacement_field", &SceneOutput::write_displacement_field, "", any(),
       "Write the warp as a dense displacement field, displacement_field.nii.gz: a NIfTI vector image on the "
       "output grid, float32 millimetres in ITK's LPS frame, pulling back (output(x) = input(x + u(x))), as "
       "ITK's DisplacementFieldTransform, ANTs and 3D Slicer apply it to another image; zero in the cavity. "
       "The same field as an ITK transform file, displacement_field_transform.h5, beside it."},
      {"grid", &SceneOutput::grid, "", any(),
       "Grid of deformed_ct and deformed_labels: \"working\" = the CT grown by roles.pad_* and, where the "
       "deformed body leaves that, by air out to it (same spacing and direction; whole cubes on the low-index "
       "sides, at most 150 mm), so a dome that rises out of the CT is not clipped; \"input\" = the CT's own."},
      {"cavity_label", &SceneOutput::cavity_label, "", in(1, 65535),
       "Label id of the CO2 cavity in the warped label map (§7); must not be an id the label map uses."},
      {"min_cavity_piece_ml", &SceneOutput::min_cavity_piece_ml, "ml", in(0, 1e6),
       "Gas pieces (6-connected) smaller than this are cracks between the wall's and the viscera's "
       "tetrahedra, not CO2: filled with their neighbours' HU and labels; 0 keeps every piece."},
      {"write_slices", &SceneOutput::write_slices, "", any(), "Write before/after slice pairs (axial, coronal, sagittal)."},
      {"write_depth", &SceneOutput::write_depth, "", any(), "Write a depth map beside each view."},
      {"timelapse_every_steps", &SceneOutput::timelapse_every_steps, "", in(0, 1e9),
       "Inflation preview of `pneumo run`: warp and render the first view and the exterior views every this many "
       "solver steps into timelapse/ (MP4 with ffmpeg); 0 = never."},
  };
  return t;
}

const Table<Landmark>& landmark_table() {
  static const Table<Landmark> t{
      {"name", &Landmark::name, "", view_name(), "Names the landmark in the report."},
      {"ct_mm", &Landmark::ct_mm, "mm", required(), "Its position in the original CT (world RAS+)."},
      {"measured_before_mm", &Landmark::measured_before_mm, "mm", any(),
       "Measured on the patient before insufflation, in the tracker's frame (§9); give both or neither."},
      {"measured_after_mm", &Landmark::measured_after_mm, "mm", any(),
       "Measured after insufflation, in the same tracker frame."},
  };
  return t;
}

}  // namespace

const Table<Port>& scene_port_table() { return port_table(); }

const Table<Scene>& scene_table() {
  static const Table<Scene> t{
      {"$schema_version", &Scene::schema_version, "", in(1, 1), "Version of this format; optional."},
      {"name", &Scene::name, "", any(), "Short name of the case (reports, window titles)."},
      {"description", &Scene::description, "", any(), "Free text."},
      {"preset", &Scene::preset, "", any(), preset_reference_text().c_str()},
      {"inputs", &Scene::inputs, inputs_table(), "Input volumes."},
      {"roles", &Scene::roles, roles_table(), "Which voxels are wall, viscera, fixed or left out (§2)."},
      {"mesh", &Scene::mesh, mesh_table(), "The tetrahedral meshes (§3)."},
      {"material", &Scene::material, material_table(), "Mass-spring-damper material (§4, §5)."},
      {"load", &Scene::load, load_table(), "Insufflation pressure and how it is applied (§5, §6)."},
      {"solver", &Scene::solver, solver_table(), "How equilibrium is reached (§6)."},
      {"device", &Scene::device, "", any().rule("\"cpu\", \"auto\", \"opencl\", \"opencl:P:D\" (platform P, device D)", is_device),
       "Where to compute: the C++ reference or an OpenCL device (`pneumo devices` lists them). \"auto\": the first OpenCL GPU or accelerator, the C++ reference where there is none (an OpenCL CPU device shares the reference's cores and was slower on every stage measured)."},
      {"render", &Scene::render, render_table(), "Laparoscope views (§8)."},
      {"output", &Scene::output, output_table(), "What is written besides the scene echo."},
      {"landmarks", &Scene::landmarks, landmark_table(), any().items(0, 1000),
       "Points whose simulated motion is reported; with tracker measurements, compared with them (§9)."},
  };
  return t;
}

}  // namespace pneumo::scene_detail
