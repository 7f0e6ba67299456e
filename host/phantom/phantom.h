#pragma once
// The embedded default case: a deterministic synthetic abdomen (CT in HU + a label map) that pneumo can simulate
// without any patient data. The anatomy is defined in millimetres, so every size shows the same body; only the
// voxel grid changes.
//
// World frame: NIfTI RAS+ millimetres (+x patient Right, +y Anterior, +z Superior), direction identity, voxel axes
// i→R, j→A, k→S (orientation code "RAS"). The patient lies supine on a CT table at the posterior edge of the grid;
// the body is centred laterally on x = 0, its antero-posterior centre is y = 0, and z = 0 is near the L2 body.
// The field of view runs from the pelvic brim (sacral promontory, z ≈ −150 mm) to the diaphragm domes
// (z ≈ +145 mm); the small grid is taller (±192 mm) and also shows the upper sacrum and the lung bases and heart.
#include <string>
#include <vector>

#include "core/geometry.h"
#include "domain/types.h"
#include "io/volume.h"

namespace pneumo {

enum class PhantomSize { Small, Medium, Large };

/// "small" | "medium" | "large"; anything else throws InputError naming the allowed values.
PhantomSize parse_phantom_size(const std::string& name);
const char* phantom_size_name(PhantomSize size);

/// One label of the phantom's label map. Ids follow TotalSegmentator v2 "total" where it has the structure, so
/// scenes for real CTs and for the phantom share one mapping; structures it lacks use ids from 200 up.
struct PhantomLabel {
  int id;
  std::string name;     // TotalSegmentator class name where one exists
  Role role;            // method.md §2
  double hu;            // nominal (noise-free) HU of the tissue
  std::string source;   // where the HU value comes from
};

/// All labels the phantom uses, background (0) first, in ascending id order.
const std::vector<PhantomLabel>& phantom_labels();

struct Phantom {
  Volume ct;       // int16, HU
  Volume labels;   // uint8, ids of phantom_labels()
};

/// The voxel grid of a size (cheap: nothing is generated).
///   small  96×96×96   at 4 mm    (384×384×384 mm)
///   medium 256×256×200 at 1.5 mm (384×384×300 mm)
///   large  512×512×400 at 0.75 mm (384×384×300 mm)
Geometry phantom_geometry(PhantomSize size);

/// Generates the phantom. Deterministic: the voxels depend only on the size, never on the thread count (slices are
/// independent and the noise is a hash of the voxel index). Multithreaded with OpenMP; shows Progress("phantom").
Phantom make_phantom(PhantomSize size);

/// Voxels per mesh cube that the phantom's scene asks for: 2 (small, 8 mm), 6 (medium, 9 mm), 12 (large, 9 mm).
int phantom_cube_voxels(PhantomSize size);

/// The scene JSON (method.md roles built from phantom_labels()), pretty-printed with a 2-space indent.
std::string phantom_scene_json(PhantomSize size);

/// Creates `dir` if needed and writes ct.nii.gz, labels.nii.gz, label_names.csv (id, name) and
/// scene.json into it, each atomically.
void write_phantom_case(const Phantom& phantom, PhantomSize size, const std::string& dir);

}  // namespace pneumo
