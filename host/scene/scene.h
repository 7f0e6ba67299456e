#pragma once
// A scene: one case, everything a run needs besides the command itself (inputs, how labels map to
// roles, mesh, material, load, solver, device, views, outputs).
//
// The keys, their defaults, their ranges and their documentation come from one table
// (scene_params.cpp); docs/scene_reference.md is generated from it. The defaults live here, in
// the member initialisers, so that a default-constructed struct is always the documented default;
// the table reads them from there. Sections of method.md are cited as "§n".
#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/cube_voxels.h"
#include "core/geometry.h"
#include "domain/types.h"
#include "render/view_settings.h"
#include "roles/role_rules.h"

namespace pneumo {

// ---- sections ----------------------------------------------------------------------------------

struct SceneInputs {
  std::string ct;       // "" = not given; see Scene::require_ct()
  std::string labels;   // "" = not given
  std::string label_names;   // "" = not given: a CSV of label_id,name (io/label_table.h)
};

struct SceneMesh {
  // The cube size: cube_mm when set (L per axis from the CT's spacing), else cube_voxels when set, else
  // kDefaultCubeMm (scene_presets.h: cube_voxels_for).
  std::optional<CubeVoxels> cube_voxels;
  std::optional<double> cube_mm;
  MeshModel model = MeshModel::WallViscera;
  std::optional<Vec3> roi_min_mm, roi_max_mm;  // both or neither
  std::vector<int> attached_labels;   // wall labels whose interface with the viscera stays closed
  CutFaces cut_faces = CutFaces::Slide;   // mesh.h: MeshOptions::cut_faces
};

/// Young's modulus for one label id, overriding the role's value.
struct LabelYoung {
  int label = 0;
  double young_kpa = 0.0;
  std::optional<double> poisson_ratio;   // the finite elements only; unset = the role's
};

struct SceneMaterial {
  double density_kg_m3 = 1096.0;  // Nimura (§4)
  double young_kpa = 60.0;        // Nimura (§4)
  std::optional<double> wall_young_kpa;
  // The healthy liver in vivo by transient elastography (Roulot 2008: 5.49 ± 1.59 kPa); null = young_kpa.
  std::optional<double> viscera_young_kpa = 5.5;
  std::vector<LabelYoung> label_young_kpa;
  // Fat by density: wall and viscera voxels whose HU lies in [fat_hu_min, fat_hu_max] (the adipose
  // window of CT body-composition studies) take fat_young_kpa unless their label has its own value.
  std::optional<double> fat_young_kpa = 3.0;   // the upper end of 1-3 kPa for fat; null = off
  double fat_hu_min = -190.0, fat_hu_max = -30.0;
  // The lungs, where roles.compliant_lungs makes them wall (the thorax the diaphragm rises into): wall
  // voxels at or below lung_hu_max (aerated lung), unlabelled or labelled lung, take lung_young_kpa and
  // lung_poisson_ratio unless their label has its own E. 1.0 kPa and 0.40 give the parenchyma's bulk modulus 1.7 kPa (a 2 L
  // anaesthetised lung of compliance 0.12 L/cmH2O) and shear modulus 0.36 kPa (0.7 × a 5 cmH2O
  // transpulmonary pressure, Lai-Fook 1977): docs/fidelity.md, "The diaphragm".
  std::optional<double> lung_young_kpa = 1.0;   // null = off (the wall's E)
  double lung_poisson_ratio = 0.40;
  double lung_hu_max = -500.0;   // the body's own threshold: the skin's partial-volume rim is never lung
  // The lungs beyond the CT's cranial cut, a gas spring of this compliance less the lungs' share in view
  // (solve/thorax_beyond_cut.h); 0.12 is the anaesthetised lung of lung_young_kpa. null (the default,
  // docs/fidelity.md "The chest beyond the cut"): the cut slides like the others.
  std::optional<double> thorax_compliance_l_per_cmh2o;
  double damping_ratio = 0.4;     // ζ, Nimura (§4)
  double spring_scale = 1.0;      // as published; 0.925 matches the lattice to E (§4)
  SpringModel spring_model = SpringModel::Nonlinear;  // rotation-invariant (§5)
  // The elements (docs/fidelity.md §4): their ν is per role, so the viscera keep their volume.
  MaterialModel model = MaterialModel::FemNeoHookean;
  // ν of the finite elements (the springs' is fixed at 1/4): Bano 2012 used 0.49 for the wall.
  double poisson_ratio = 0.45;
  std::optional<double> wall_poisson_ratio;
  // The viscera keep their volume, as organs and bowel contents do: nearly incompressible, the room
  // the gas takes found by moving (mean_dilatation keeps such elements from locking).
  std::optional<double> viscera_poisson_ratio = 0.49;
  // The liver's blood, driven out by the gas: the fraction of its volume the liver loses at 12 mmHg
  // (Nainamalai 2025: 12 % in 15 patients). It sets the liver's drained bulk modulus
  // K = 12 mmHg / −ln(1 − loss), so that a liver under the gas pressure all round loses that fraction
  // (the Kirchhoff mean stress of the neo-Hookean law is −K ln J); its shear modulus stays the
  // viscera's. null = off (the liver is viscera like any other). docs/fidelity.md, "The viscera's volume".
  std::optional<double> liver_volume_loss = 0.12;
  // The wall's circumferential collagen fibres (mesh/wall_fibres.h, solve/fem_element.h): k₁ of the fibre
  // term as a multiple of each tetrahedron's shear modulus (0 = an isotropic wall), and k₂. 0.67 gives
  // Song 2006's ratio of 1.89 between the wall's transverse and sagittal stiffness.
  double wall_fibre_stiffness = 0.0;
  double wall_fibre_exponent = 0.0;
  bool mean_dilatation = true;    // FEM: volumetric strain averaged per cube, against locking
  // b of the stiffening law (springs: solve/forces.h; fem-neohookean: Demiray); 0 = linear. 10 gives the
  // real CT McDougall's pressure-volume shape (docs/fidelity.md §3): a calibration.
  double stiffening = 10.0;
  std::optional<double> volume_stiffness_kpa;          // unset: see effective_volume_stiffness_kpa()
  bool gravity = false;           // the CT already shows the body under gravity (§5)
  bool gravity_compensation = true;   // solve from the unloaded shape whose weight gives the CT (Bano 2012)
  double tilt_deg = 0.0;          // table tilt about the left-right axis: > 0 head down (Trendelenburg)
  bool contact = false;           // viscera kept out of wall and bone (solve/contact.h)
  double contact_stiffness = 10.0;   // κ: contact k = κ E / cube edge (solve/contact.h)
};

struct SceneLoad {
  double pressure_mmhg = 12.0;    // the usual clinical pressure; Song et al. measured at 12 (§4)
  // §6: a ramp over 2-3 periods of the slowest mode keeps overshoot within a few percent. The
  // slowest mode of an adult abdominal wall (a clamped plate ~300 mm across, 30 mm thick,
  // E = 60 kPa, ρ = 1096 kg/m³) is near 5 Hz, a 0.2 s period: 500 ms is 2.5 periods.
  double ramp_ms = 500.0;
  RampShape ramp_shape = RampShape::Smooth;
  std::vector<double> pressure_curve_mmhg;  // empty = a single pressure
};

struct SceneSolver {
  SolverMethod method = SolverMethod::Newton;   // converges for every model; FIRE diverges on the FEM
  // An OpenCL device that cannot run the method and model: refuse (false) or solve on the CPU and
  // report it (true; device "auto" always may: it asks for the best there is).
  bool allow_cpu_fallback = false;
  double dt_ms = 0.0;                    // 0 = dt_safety × the stability bound (§6)
  double dt_safety = 0.5;
  int64_t max_steps = 100000;
  double residual_tolerance = 1e-3;      // max |net force| / max |pressure force|
  double velocity_tolerance_mm_s = 0.5;
  int hold_steps = 50;
  double newmark_beta = 0.25;            // Nimura §2.3.4
  double newmark_gamma = 0.5;            // Nimura's δ
  double newmark_inner_tolerance = 1e-6; // relative change of the accelerations
  int newmark_max_inner = 50;
  double kitasaka_step = 0.3;            // Δs, Kitasaka §2.4
  double kitasaka_tolerance_mm = 1.0;    // β of Kitasaka's Eq. 3: Σ|ΔR| over all nodes
  OnInverted on_inverted = OnInverted::Continue;
  int64_t checkpoint_every_steps = 0;    // 0 = off
  int newton_max_cg_iterations = 500;    // conjugate-gradient iterations per Newton step
  double rayleigh_mass_per_s = 0.1;      // implicit-euler: C = α M + β K (SOFA's former defaults)
  double rayleigh_stiffness_s = 0.1;
};

struct SceneOutput {
  std::string folder;             // "" = the command line decides
  bool write_meshes = true;      // mesh_initial.vtu and mesh_deformed.vtu (compressed; ParaView, VTK, meshio)
  bool write_deformed_ct = true;
  bool write_deformed_labels = true;
  bool write_displacement_field = false;   // displacement_field.nii.gz (warp/displacement_field.h)
  OutputGrid grid = OutputGrid::Working;
  // Label id of the CO2 cavity in the warped label map (§7). TotalSegmentator's ids end at 117 and
  // the phantom's own at 207; 250 is free in both. A label map that already uses it is refused.
  int cavity_label = 250;
  // Gas pieces smaller than this are cracks between the two meshes, not cavity: filled from their
  // surroundings (warp/cavity_specks.h). 0 keeps every piece.
  double min_cavity_piece_ml = 1.0;
  bool write_slices = true;
  bool write_depth = false;
  int64_t timelapse_every_steps = 0;  // 0 = off
};

/// A landmark for Nimura's evaluation (§9): where it is in the CT, and optionally where a tracker
/// measured it on the patient before and after insufflation (the tracker's own frame).
struct Landmark {
  std::string name;
  Vec3 ct_mm = Vec3::Zero();                    // world RAS+, the original CT
  std::optional<Vec3> measured_before_mm, measured_after_mm;
};

// ---- the scene ---------------------------------------------------------------------------------

struct Scene {
  int schema_version = 1;
  std::string name, description;
  ScenePreset preset = ScenePreset::None;   // applied while parsing: see scene_presets.h
  SceneInputs inputs;
  RoleRules roles;
  SceneMesh mesh;
  SceneMaterial material;
  SceneLoad load;
  SceneSolver solver;
  std::string device = "cpu";     // "cpu", "opencl" or "opencl:P:D"
  ViewSettings render;
  SceneOutput output;
  std::vector<Landmark> landmarks;

  std::string path;    // the scene file as given ("" when built in code)
  std::string folder;  // absolute folder relative paths were resolved against

  /// The full resolved scene, defaults included, every key present (unset ones as null): written
  /// next to outputs, and parse_scene() of it gives this scene back. The role lists hold the scene's
  /// own ids, not those its label names gave (roles.ids_from_names), which parse_scene derives again.
  nlohmann::json echo() const;

  /// inputs.ct; throws InputError naming the scene when it is not given.
  const std::string& require_ct() const;

  /// Young's modulus of a tetrahedron (kPa): label_young_kpa for its label, else the role's
  /// override (wall_young_kpa, viscera_young_kpa), else young_kpa.
  double young_kpa_for(Role role, int label) const;
  /// The same for one voxel of HU `hu`: fat_young_kpa inside the fat window (docs/fidelity.md).
  double young_kpa_for(Role role, int label, float hu) const;
  /// ν of the finite elements for a role and label.
  double poisson_for(Role role, int label) const;
  /// The same for one voxel of HU `hu`: lung_poisson_ratio for aerated wall voxels.
  double poisson_for(Role role, int label, float hu) const;
  /// Whether a voxel of this role, label and HU is lung tissue of the wall: aerated wall, unlabelled
  /// or of a label named lung (roles.lung_ids), with roles.compliant_lungs and lung_young_kpa set.
  bool is_lung_voxel(Role role, int label, float hu) const;
  /// The compliance (m³/Pa) of the lungs beyond the CT's cranial cut when `lung_in_view_m3` of them
  /// lie inside it: material.thorax_compliance_l_per_cmh2o times the share of the lungs' volume (their
  /// bulk modulus times that compliance) not in view; 0 when off or when the CT shows them whole.
  double thorax_compliance_m3_per_pa(double lung_in_view_m3) const;
  /// Whether a label takes the liver's vascular compliance: viscera of a label named liver
  /// (roles.liver_ids), with liver_volume_loss set, no E of its own in label_young_kpa and finite
  /// elements (the springs' ν is fixed).
  bool takes_liver_compliance(Role role, int label) const;

  /// Kitasaka's k_v (kPa): volume_stiffness_kpa when set; unset: young_kpa for kitasaka2004
  /// (the 2004 scheme needs it: its springs alone let tetrahedra collapse), 0 for the others.
  double effective_volume_stiffness_kpa() const;
};

/// Nimura's mass-spring lattice (§4), the model pneumo started from: the springs with every tissue at
/// young_kpa, linear in tension (stiffening 0) and no fat window. The bench's springs sections and the
/// tests of what only the springs do (the explicit, Newmark and 2004 schemes) use it.
void use_nimura_springs(SceneMaterial& m);

/// Reads a scene file. InputError (one line, naming the file) on any problem: missing file,
/// invalid JSON (with line and column), unknown key, wrong type, value out of range.
Scene load_scene(const std::string& path);

/// Reads a scene from parsed JSON; origin_path names it in messages and its folder resolves
/// relative paths ("" = the current folder).
Scene parse_scene(const nlohmann::json& j, const std::string& origin_path);

/// Every key at its default.
Scene default_scene();

/// The names of the label map's ids: inputs.label_names (io/label_table.h) when given, else the names a
/// NIfTI label map carries in its header (TotalSegmentator's), else none. InputError for a bad file.
std::map<int, std::string> scene_label_names(const Scene& scene);

/// One item of render.ports as the scene file writes it: every key, as Scene::echo() writes it.
nlohmann::json port_json(const Port& p);
/// One item of render.ports read with every check a scene's port gets (its keys and their ranges,
/// one target, a lens its field of view allows); InputError "<what>: <key> = <value> <problem>"
/// otherwise. What `pneumo serve` reads the page's ports with.
Port read_port(const nlohmann::json& j, const std::string& what);

/// A scene key's meaning and what it allows, as the reference gives them ("device",
/// "material.model"): the help of a command-line flag that sets the same thing, in the same words.
std::string scene_key_help(const std::string& dotted_path);

/// docs/scene_reference.md: one Markdown table per section, generated from the parameter table.
std::string scene_reference_markdown();

}  // namespace pneumo
