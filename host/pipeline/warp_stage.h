#pragma once
// The warp stage of a case: what `pneumo warp SCENE --out DIR` runs after `pneumo simulate SCENE
// --out DIR`, and what the pipeline reuses. Rebuilds roles and mesh from the scene (deterministic),
// reads DIR/deformation.bin (refused when it belongs to another mesh), warps the CT and labels
// (method.md §7) on the scene's device, and writes the results on the input CT's own grid.
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "io/label_table.h"
#include "io/volume.h"
#include "mesh/deformation_file.h"
#include "mesh/mesh.h"
#include "roles/roles.h"
#include "scene/scene.h"
#include "warp/cavity_specks.h"
#include "warp/point_map.h"
#include "warp/warp.h"

namespace pneumo {

/// The farthest the output grid grows past the working grid on any side to hold the deformed body
/// (mm). Patients' wall rises by centimetres; a node farther out comes from a diverged solve, whose
/// grid must not grow to gigabytes: what lies beyond is clipped and reported (outside_grid_mm).
constexpr double kMaxGridGrowthMm = 150.0;

struct WarpedCase {
  Volume ct;                      // the input CT as read (its grid and type are the outputs')
  std::optional<Volume> labels;   // the input label map, when the scene gives one
  RoleVolume roles;               // on the working (padded) grid, grown to hold the deformed body
  Mesh mesh;
  Deformation deformation;
  WarpMesh warp_mesh;
  WarpResult result;              // on output_grid
  WarpBox box;                    // output_grid within the working grid
  Geometry output_grid;           // output.grid: the working grid (grown to hold the body) or the CT's
  double outside_grid_mm = 0.0;   // how far the deformed mesh reaches beyond output_grid (0: inside)
  double voxel_volume_ml = 0.0;
  std::optional<Vec3> cavity_centroid_mm;   // none when no voxel became gas
  double seconds_warp = 0.0;
  SpeckFill specks;               // gas pieces below output.min_cavity_piece_ml, filled
  std::map<int, std::string> label_names;   // inputs.label_names, read before the warp (empty: unset)

  int64_t cavity_voxels() const { return result.gas_voxels; }
  double cavity_volume_ml() const { return double(result.gas_voxels) * voxel_volume_ml; }
  /// Landmarks, ports and centroids through the same tetrahedra (point_map.h). The map refers to
  /// this case's warp_mesh and roles: keep the case alive while using it.
  PointMap point_map() const { return PointMap(warp_mesh, roles.role.data()); }
};

/// A finished simulation's deformation as a point mapping, without warping images: roles and mesh
/// rebuilt from the scene, DIR/deformation.bin read (and checked against the mesh).
struct DeformedMesh {
  RoleVolume roles;
  Mesh mesh;
  Deformation deformation;
  WarpMesh warp_mesh;
  /// Keep this object alive while using the map.
  PointMap point_map() const { return PointMap(warp_mesh, roles.role.data()); }
};
DeformedMesh load_deformed_mesh(const Scene& scene, const std::string& sim_dir);

/// InputError naming the label map when it already uses output.cavity_label (the warp marks the
/// cavity with it); `roles` were assigned from the scene's labels.
void check_cavity_label_free(const Scene& scene, const RoleVolume& roles);

/// Everything but the writing. `sim_dir` holds a finished simulation of this scene (metrics.json
/// and deformation.bin); InputError naming the file otherwise, or when the label map already uses
/// output.cavity_label.
WarpedCase warp_scene(const Scene& scene, const std::string& sim_dir);

/// The warp of a case whose roles, mesh and solved deformation are already in hand (`pneumo run`
/// passes its simulation's, instead of rebuilding them): `ct` and `labels` are the input volumes.
WarpedCase warp_solved(const Scene& scene, Volume ct, std::optional<Volume> labels, RoleVolume roles, Mesh mesh,
                       Deformation deformation);

/// The deformed CT's voxel type: the input's where it can hold HU (int16, int32 rounded to the
/// nearest HU; float32, float64 as computed), float32 otherwise (unsigned or 8-bit types).
VoxelType deformed_ct_type(const WarpedCase& w);
/// The deformed CT in deformed_ct_type(w).
Volume deformed_ct_volume(const WarpedCase& w);
/// The warp's HU as deformed_ct_volume writes them, in floats: rounded in place to the nearest HU
/// and clamped where `written` (deformed_ct_type) is an integer type, as they are. Rounding again
/// changes nothing. Returns whether every value then fits_int16_texture (render_volume.h), found in
/// the same pass, for RenderVolume::from_hu.
bool round_as_written(std::vector<float>& hu, VoxelType written);

/// The label tables' rows for the deformed labels: background, every id they hold (named from
/// w.label_names, else "label N") in the renderer's organ colours (else a fixed palette), and the
/// cavity, named "CO2 cavity".
std::vector<LabelTableEntry> deformed_label_entries(const Scene& scene, const WarpedCase& w);

/// The deformed label map in the input's type when it holds the cavity label, else uint16.
Volume deformed_label_volume(const WarpedCase& w, int cavity_label);

/// The most of a metrics.json pneumo reads back (it writes a few kB): a folder's file swapped for
/// something endless is refused, not read (core/input_file.h).
constexpr uint64_t kMaxMetricsBytes = 64u << 20;

/// The keys the warp adds to metrics.json (see write_warp).
nlohmann::json warp_metrics(const Scene& scene, const WarpedCase& w);

/// Writes deformed_ct.nii.gz, deformed_labels.nii.gz (with a label map), displacement_field.nii.gz and
/// slices_before_after.png
/// as the scene's output.write_* ask, then adds warp_metrics() to DIR/metrics.json: cavity_voxels
/// and cavity_volume_ml become the warped cavity's, the mesh's own estimate stays as
/// mesh_cavity_volume_ml. Every file is written atomically, metrics.json last.
/// The deformed CT and label map are built here, once each.
void write_warp(const Scene& scene, const WarpedCase& w, const std::string& dir);

}  // namespace pneumo
