#include "pipeline/warp_stage.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/input_file.h"
#include "core/log.h"
#include "core/units.h"
#include "core/thread_count.h"
#include "io/itk_transform_io.h"
#include "io/volume_io.h"
#include "image/png.h"
#include "anatomy/body_mask.h"
#include "anatomy/thorax.h"
#include "pipeline/cavity_measures.h"
#include "pipeline/diaphragm_motion.h"
#include "pipeline/organ_motion.h"
#include "pipeline/skin_area.h"
#include "pipeline/scene_stages.h"
#include "render/render_volume.h"
#include "report/slices.h"
#include "anatomy/connected_components.h"
#include "warp/cavity_specks.h"
#include "warp/displacement_field.h"

namespace pneumo {

namespace {
char opposite_orientation_letter(char c) {
  switch (c) {
    case 'R': return 'L';
    case 'L': return 'R';
    case 'A': return 'P';
    case 'P': return 'A';
    case 'S': return 'I';
    case 'I': return 'S';
    default: return '?';
  }
}

namespace fs = std::filesystem;

std::string in_dir(const std::string& dir, const char* name) { return (fs::path(dir) / name).string(); }

nlohmann::json read_metrics(const std::string& dir) {
  const std::string path = in_dir(dir, "metrics.json");
  if (probe_file(path).kind == FileKind::Missing)
    throw file_error(path, "missing: " + dir + " holds no finished simulation; run pneumo simulate SCENE --out " +
                               dir + " first");
  try {
    return nlohmann::json::parse(read_input_file(path, kMaxMetricsBytes, "the metrics", "metrics.json is a few kB"));
  } catch (const nlohmann::json::exception& e) {
    throw file_error(path, std::string("not valid JSON (") + e.what() + ")");
  }
}

/// A world-space point for the slices: the mean position of the gas voxels.
std::optional<Vec3> cavity_centroid(const WarpResult& r, const Geometry& g) {
  Vec3 sum = Vec3::Zero();
  int64_t n = 0;
  for (int64_t k = 0; k < g.dims[2]; ++k)
    for (int64_t j = 0; j < g.dims[1]; ++j)
      for (int64_t i = 0; i < g.dims[0]; ++i)
        if (r.outcome[std::size_t(g.linear_index(i, j, k))] == WarpOutcome::Gas) {
          sum += Vec3(double(i), double(j), double(k));
          ++n;
        }
  if (n == 0) return std::nullopt;
  return g.to_world(sum / double(n));
}

/// One warped HU as the deformed CT of type T holds it: to the nearest HU and clamped for integer
/// types (deformed_ct_volume), as computed for floating ones. round_as_written applies the same.
template <class T>
T as_written(float hu) {
  if constexpr (std::is_integral_v<T>)
    return T(std::clamp(std::nearbyint(double(hu)), double(std::numeric_limits<T>::lowest()),
                        double(std::numeric_limits<T>::max())));
  else
    return T(hu);
}

template <class T>
void fill_rounded(Volume& v, const std::vector<float>& hu) {
  T* out = v.data<T>();
  const int64_t count = int64_t(hu.size());
#pragma omp parallel for schedule(static)
  for (int64_t n = 0; n < count; ++n) out[n] = as_written<T>(hu[std::size_t(n)]);
}

/// Grows the working grid (roles and warp mesh together) wherever the deformed body leaves it, by
/// air: the deformed CT then holds the whole body, and a dome that rises out of the CT and its
/// padding is not clipped (docs/warp.md).
void grow_to_hold_the_deformed_body(WarpedCase& w) {
  const Vec3& s = w.roles.geometry.spacing_mm;
  const Index3 cap{int64_t(kMaxGridGrowthMm / s[0]), int64_t(kMaxGridGrowthMm / s[1]),
                   int64_t(kMaxGridGrowthMm / s[2])};
  const PadVoxels grow = growth_to_hold_deformed(w.warp_mesh, cap);
  if (grow.empty()) return;
  w.roles = grown_roles(std::move(w.roles), grow);
  w.warp_mesh = grown_warp_mesh(w.warp_mesh, grow);
  char msg[200];
  std::snprintf(msg, sizeof msg,
                "warp: the deformed body leaves the working grid; grown by voxels i %lld/%lld, j %lld/%lld, "
                "k %lld/%lld (low/high end)",
                (long long)grow.lo[0], (long long)grow.hi[0], (long long)grow.lo[1], (long long)grow.hi[1],
                (long long)grow.lo[2], (long long)grow.hi[2]);
  log::info(msg);
}

}  // namespace

DeformedMesh load_deformed_mesh(const Scene& scene, const std::string& sim_dir) {
  DeformedMesh d;
  d.roles = load_roles(scene);
  d.mesh = build_scene_mesh(voxel_roles_of(d.roles), scene);
  d.deformation = read_deformation(in_dir(sim_dir, "deformation.bin"), d.mesh);
  d.warp_mesh = make_warp_mesh(d.mesh, d.deformation.displacement_m);
  return d;
}

void check_cavity_label_free(const Scene& scene, const RoleVolume& roles) {
  if (scene.inputs.labels.empty()) return;
  const uint16_t cavity = uint16_t(scene.output.cavity_label);
  const int64_t n = int64_t(roles.label.size());
  int used = 0;   // 10⁸ voxels on a 0.75 mm CT: on every core, without a branch per voxel
#pragma omp parallel for schedule(static) reduction(| : used)
  for (int64_t v = 0; v < n; ++v) used |= roles.label[std::size_t(v)] == cavity;
  if (used)
    throw file_error(scene.inputs.labels, "already uses label " + std::to_string(cavity) +
                                              ", the cavity's id; choose a free one with output.cavity_label");
}

WarpedCase warp_scene(const Scene& scene, const std::string& sim_dir) {
  read_metrics(sim_dir);   // a finished simulation, before reading a large CT for nothing
  scene_label_names(scene);
  Volume ct = read_volume(scene.require_ct());
  std::optional<Volume> labels;
  if (!scene.inputs.labels.empty()) labels = read_volume(scene.inputs.labels);
  RoleVolume roles = assign_roles(scene, ct, labels ? &*labels : nullptr);
  Mesh mesh = build_scene_mesh(voxel_roles_of(roles), scene);
  Deformation deformation = read_deformation(in_dir(sim_dir, "deformation.bin"), mesh);
  const double scene_pa = units::mmhg_to_pa(scene.load.pressure_mmhg);
  if (scene.load.pressure_curve_mmhg.empty() && std::abs(deformation.pressure_pa - scene_pa) > 1e-6 * scene_pa)
    log::warn(sim_dir + ": the deformation was solved at " +
              std::to_string(deformation.pressure_pa / units::kPaPerMmHg) + " mmHg, the scene now asks for " +
              std::to_string(scene.load.pressure_mmhg) + " mmHg; warping the solved shape");
  if (!deformation.converged) log::warn(sim_dir + ": the simulation did not converge; warping its last shape");
  return warp_solved(scene, std::move(ct), std::move(labels), std::move(roles), std::move(mesh),
                     std::move(deformation));
}

WarpedCase warp_solved(const Scene& scene, Volume ct, std::optional<Volume> labels, RoleVolume roles, Mesh mesh,
                       Deformation deformation) {
  fit_threads_to_load();
  WarpedCase w;
  w.label_names = scene_label_names(scene);
  w.ct = std::move(ct);
  w.labels = std::move(labels);
  w.roles = std::move(roles);
  w.mesh = std::move(mesh);
  w.deformation = std::move(deformation);
  if (w.labels) check_cavity_label_free(scene, w.roles);
  const uint16_t cavity = uint16_t(scene.output.cavity_label);
  w.warp_mesh = make_warp_mesh(w.mesh, w.deformation.displacement_m);
  const bool working = scene.output.grid == OutputGrid::Working;
  if (working) grow_to_hold_the_deformed_body(w);

  WarpSource src;
  src.ct_hu = w.roles.ct.data<float>();
  src.labels = w.labels ? w.roles.label.data() : nullptr;
  src.roles = w.roles.role.data();
  // The working grid holds the mesh and, grown, the deformed body.
  w.output_grid = working ? w.roles.geometry : w.ct.geometry();
  WarpBox& box = w.box;
  box.lo = working ? Index3{0, 0, 0} : w.roles.pad.lo;
  box.dims = w.output_grid.dims;
  WarpOptions opt;
  opt.cavity_label = cavity;
  const auto t0 = std::chrono::steady_clock::now();
  w.result = warp_on_device(scene.device, w.warp_mesh, src, box, opt);
  const Vec3& s = w.output_grid.spacing_mm;
  w.voxel_volume_ml = s[0] * s[1] * s[2] / 1000.0;
  const int64_t min_voxels = int64_t(std::ceil(scene.output.min_cavity_piece_ml / w.voxel_volume_ml));
  w.specks = fill_cavity_specks(w.result, box.dims, min_voxels);
  w.seconds_warp = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  w.cavity_centroid_mm = cavity_centroid(w.result, w.output_grid);
  // A dome that rises beyond the output grid is clipped there: say by how much, where, and what to
  // change. Nodes on a face of the grid (where the CT ends) sit on it at rest, so a millimetre or two
  // there is the CT's own cut; a voxel or more is reported.
  const std::string code = w.output_grid.orientation_code();
  double worst = 0.0;
  char side = '?';
  for (int64_t n = 0; n < w.mesh.node_count(); ++n) {
    const Vec3 x_mm = units::m_to_mm(1.0) * (w.mesh.rest_m[n] + w.deformation.displacement_m[n]);
    const Vec3 idx = w.output_grid.to_index(x_mm);
    for (int a = 0; a < 3; ++a) {
      const double h = w.output_grid.spacing_mm[a];
      const double low = (-0.5 - idx[a]) * h, high = (idx[a] - (double(w.output_grid.dims[a]) - 0.5)) * h;
      if (high > worst) { worst = high; side = code[a]; }
      if (low > worst) { worst = low; side = opposite_orientation_letter(code[a]); }
    }
  }
  w.outside_grid_mm = worst;
  if (worst >= w.output_grid.spacing_mm.maxCoeff()) {
    // The working grid grows to hold the body up to kMaxGridGrowthMm on each side: beyond that the
    // wall moved farther than an abdomen does, which a diverged or mis-set solve does, not padding.
    char msg[400];
    if (working)
      std::snprintf(msg, sizeof msg,
                    "warp: the deformed body reaches %.1f mm beyond the output grid (side %c), which grew by up to "
                    "%.0f mm to hold it, and is clipped there; no abdomen moves that far: check the solve's "
                    "convergence, load.pressure_mmhg and the wall's stiffness",
                    worst, side, kMaxGridGrowthMm);
    else
      std::snprintf(msg, sizeof msg,
                    "warp: the deformed body reaches %.1f mm beyond the CT's grid (side %c) and is clipped there; "
                    "set output.grid to \"working\" to grow the output around the deformed body",
                    worst, side);
    log::warn(msg);
  }
  return w;
}

VoxelType deformed_ct_type(const WarpedCase& w) {
  const VoxelType t = w.ct.type();
  if (t != VoxelType::Int16 && t != VoxelType::Int32 && t != VoxelType::Float32 && t != VoxelType::Float64)
    return VoxelType::Float32;
  return t;
}

Volume deformed_ct_volume(const WarpedCase& w) {
  // The run lends these HU to the views and takes them back: an empty or foreign vector here would
  // write a CT of zeros without a word.
  if (int64_t(w.result.ct_hu.size()) != w.output_grid.voxel_count())
    throw std::logic_error("deformed_ct_volume: " + std::to_string(w.result.ct_hu.size()) + " HU for " +
                           std::to_string(w.output_grid.voxel_count()) + " voxels of the output grid");
  const VoxelType t = deformed_ct_type(w);
  Volume v(w.output_grid, t);
  dispatch_voxel_type(t, v.raw(), [&](auto* p) {
    using T = std::remove_pointer_t<decltype(p)>;
    fill_rounded<T>(v, w.result.ct_hu);
  });
  return v;
}

bool round_as_written(std::vector<float>& hu, VoxelType written) {
  const int64_t count = int64_t(hu.size());
  bool all_int16 = true;
  dispatch_voxel_type(written, nullptr, [&](auto* p) {
    using T = std::remove_pointer_t<decltype(p)>;
#pragma omp parallel for schedule(static) reduction(&& : all_int16)
    for (int64_t n = 0; n < count; ++n) {
      float& x = hu[std::size_t(n)];
      if constexpr (std::is_integral_v<T>) x = float(as_written<T>(x));   // floating types hold them as they are
      all_int16 = all_int16 && fits_int16_texture(x);
    }
  });
  return all_int16;
}

std::vector<LabelTableEntry> deformed_label_entries(const Scene& scene, const WarpedCase& w) {
  std::vector<uint8_t> present(65536, 0);
  for (const uint16_t l : w.result.labels) present[l] = 1;
  const LabelColours colours = default_label_colours();
  std::vector<LabelTableEntry> rows = {{0, "background", {0, 0, 0}, 0.0}};
  for (int id = 1; id < 65536; ++id) {
    if (!present[id]) continue;
    LabelTableEntry e;
    e.id = id;
    const auto name = w.label_names.find(id);
    e.name = name != w.label_names.end() ? name->second : "label " + std::to_string(id);
    const auto& c = colours.rgba[std::size_t(id)];
    if (c[3] > 0) {
      e.rgb = {c[0], c[1], c[2]};
    } else {
      // A fixed palette for ids the renderer does not colour: hues a golden angle apart, so
      // neighbouring ids differ (HSV with s = 0.55, v = 0.85).
      const double h = std::fmod(id * 137.508, 360.0) / 60.0, s = 0.55, v = 0.85;
      const double x = v * s * (1.0 - std::abs(std::fmod(h, 2.0) - 1.0)), m = v - v * s;
      const double rgb[6][3] = {{v * s, x, 0}, {x, v * s, 0}, {0, v * s, x}, {0, x, v * s}, {x, 0, v * s}, {v * s, 0, x}};
      const double* p = rgb[std::min(5, int(h))];
      for (int k = 0; k < 3; ++k) e.rgb[k] = uint8_t(std::lround(255.0 * (p[k] + m)));
    }
    if (id == scene.output.cavity_label) {
      e.name = "CO2 cavity";
      e.rgb = {60, 160, 255};   // the slices' overlay colour
    }
    rows.push_back(e);
  }
  return rows;
}

Volume deformed_label_volume(const WarpedCase& w, int cavity_label) {
  if (!w.labels) throw std::logic_error("deformed_label_volume: the case has no label map");
  VoxelType t = w.labels->type();
  bool fits = false;
  dispatch_voxel_type(t, const_cast<void*>(w.labels->raw()), [&](auto* p) {
    using T = std::remove_pointer_t<decltype(p)>;
    fits = std::is_integral_v<T> && double(cavity_label) <= double(std::numeric_limits<T>::max());
  });
  if (!fits) t = VoxelType::UInt16;
  Volume v(w.output_grid, t);
  dispatch_voxel_type(t, v.raw(), [&](auto* p) {
    const int64_t count = int64_t(w.result.labels.size());
#pragma omp parallel for schedule(static)
    for (int64_t n = 0; n < count; ++n)
      p[n] = static_cast<std::remove_pointer_t<decltype(p)>>(w.result.labels[std::size_t(n)]);
  });
  return v;
}

nlohmann::json warp_metrics(const Scene& scene, const WarpedCase& w) {
  // The outcomes, not the HU: a run hands the HU to the renderer before the metrics are written.
  const double mvox_s = w.seconds_warp > 0 ? double(w.result.outcome.size()) / w.seconds_warp / 1e6 : 0.0;
  nlohmann::json j;
  // Points through the deformation, for the prevesical gas and the skin: binned once, when first asked.
  std::optional<PointMap> map;
  auto point_map = [&]() -> const PointMap& {
    if (!map) map.emplace(w.warp_mesh, w.roles.role.data());
    return *map;
  };
  j["deformed_body_outside_grid_mm"] = w.outside_grid_mm;
  j["cavity_voxels"] = w.cavity_voxels();
  j["cavity_volume_ml"] = w.cavity_volume_ml();
  // The gas should be one connected cavity (docs/fidelity.md §2): the share of it outside its
  // largest 6-connected piece shows specks and pockets that opened apart from it.
  if (!w.result.labels.empty()) {
    std::vector<uint8_t> gas(w.result.labels.size());
    for (std::size_t n = 0; n < gas.size(); ++n) gas[n] = w.result.labels[n] == uint16_t(scene.output.cavity_label);
    const int64_t largest = keep_largest_component(gas, w.output_grid.dims);
    j["cavity_largest_piece_ml"] = double(largest) * w.voxel_volume_ml;
    j["cavity_specks_filled"] = {{"pieces", w.specks.pieces}, {"voxels", w.specks.voxels},
                                 {"below_ml", scene.output.min_cavity_piece_ml}};
    j["cavity_outside_largest_piece_fraction"] =
        w.cavity_voxels() > 0 ? 1.0 - double(largest) / double(w.cavity_voxels()) : 0.0;
    // Gas in front of the extraperitoneal organs the roles keep attached (the bladder), in the
    // deformed frame: all of it; the part with no intraperitoneal organ between it and the bladder;
    // and of that, the part on tissue that no intraperitoneal organ covered at rest (the space of
    // Retzius, where none should open; cavity_measures.h).
    if (!scene.roles.auto_prevesical_labels.empty()) {
      const uint16_t gas_id = uint16_t(scene.output.cavity_label);
      const auto& bladder = scene.roles.auto_prevesical_labels;
      const auto& organs = scene.roles.viscera_labels;
      j["gas_anterior_to_prevesical_labels_ml"] =
          double(gas_voxels_anterior_to(w.result.labels, w.output_grid, gas_id, bladder)) * w.voxel_volume_ml;
      const int64_t short_of_organs = gas_voxels_anterior_to(w.result.labels, w.output_grid, gas_id, bladder, organs);
      j["gas_short_of_intraperitoneal_organs_ml"] = double(short_of_organs) * w.voxel_volume_ml;
      int64_t prevesical = 0;
      if (short_of_organs > 0) {
        const PointMap& to_rest = point_map();
        RestColumns rest;
        rest.labels = w.roles.label.empty() ? nullptr : w.roles.label.data();
        rest.grid = w.roles.geometry;
        rest.to_rest = [&to_rest](const Vec3& deformed_mm) -> std::optional<Vec3> {
          const MappedPoint p = to_rest.to_original(deformed_mm);
          return p.carried ? std::optional<Vec3>(p.point_mm) : std::nullopt;
        };
        prevesical = gas_voxels_anterior_to(w.result.labels, w.output_grid, gas_id, bladder, organs, &rest);
      }
      j["gas_in_prevesical_space_ml"] = double(prevesical) * w.voxel_volume_ml;
    }
  }
  // Where each labelled structure that may move went (pipeline/organ_motion.h): the wall's and the
  // viscera's labels; what is fixed stays.
  if (!w.result.labels.empty() && !w.roles.label.empty()) {
    std::vector<int> moving = scene.roles.wall_labels;
    moving.insert(moving.end(), scene.roles.viscera_labels.begin(), scene.roles.viscera_labels.end());
    nlohmann::json organs = nlohmann::json::array();
    const PointMap& to_deformed = point_map();
    const WarpMesh& mesh = w.warp_mesh;
    const std::vector<Role>& role = w.roles.role;
    const JacobianAtFn jacobian = [&to_deformed, &mesh, &role](int64_t voxel, const Vec3& rest_mm) -> std::optional<double> {
      if (role.empty() || role[std::size_t(voxel)] == Role::Fixed) return std::nullopt;   // held: J = 1
      const MappedPoint p = to_deformed.to_deformed(rest_mm);
      if (!p.carried) return std::nullopt;
      const auto& t = mesh.tets[std::size_t(p.tet)];
      return signed_tet_volume(mesh.deformed_ijk(t[0]), mesh.deformed_ijk(t[1]), mesh.deformed_ijk(t[2]),
                               mesh.deformed_ijk(t[3])) /
             signed_tet_volume(mesh.rest_ijk[t[0]], mesh.rest_ijk[t[1]], mesh.rest_ijk[t[2]], mesh.rest_ijk[t[3]]);
    };
    for (const OrganMotion& o : organ_motion(w.roles.label, w.roles.geometry, w.result.labels, w.output_grid,
                                             uint16_t(scene.output.cavity_label), scene.roles.label_names, moving,
                                             1.0, jacobian)) {
      organs.push_back({{"label", o.label},
                        {"name", o.name},
                        {"volume_ml", o.volume_ml},
                        {"volume_change_fraction", o.volume_change},
                        {"shift_right_mm", o.shift_mm[0]},
                        {"shift_anterior_mm", o.shift_mm[1]},
                        {"shift_superior_mm", o.shift_mm[2]}});
      if (o.tissue_volume_change) organs.back()["tissue_volume_change_fraction"] = *o.tissue_volume_change;
    }
    if (!organs.empty()) j["organ_motion"] = organs;
  }
  // The wall's skin, stretched (pipeline/skin_area.h).
  if (!w.roles.role.empty() && w.roles.hu()) {
    const PointMap& to_deformed = point_map();
    const std::vector<uint8_t> body = body_mask(w.roles.hu(), w.roles.geometry, scene.roles.auto_body_threshold_hu);
    const CarryFn carry = [&to_deformed](const Vec3& rest, Vec3& moved) {
      const MappedPoint p = to_deformed.to_deformed(rest);
      moved = p.point_mm;
      return p.carried;
    };
    const SkinArea skin = wall_skin_area(voxel_roles_of(w.roles), body, carry);
    if (skin.faces > 0) {
      j["wall_skin_area_cm2"] = skin.rest_mm2 / 100.0;
      j["wall_skin_area_change_fraction"] = skin.change();
    }
    if (skin.anterior_rest_mm2 > 0.0) {
      j["anterior_skin_area_cm2"] = skin.anterior_rest_mm2 / 100.0;
      j["anterior_skin_area_change_fraction"] = skin.anterior_change();
    }
    // The diaphragm's rise into the chest (pipeline/diaphragm_motion.h), where a lung base is in view.
    ThoraxOptions lungs_only;
    lungs_only.lung_closing_mm = 0.0;   // the lungs' base is all it needs: no closing
    const Thorax thorax = find_thorax(w.roles.hu(), body, w.roles.geometry, nullptr, lungs_only);
    const DiaphragmMotion diaphragm = diaphragm_motion(voxel_roles_of(w.roles), body, thorax.lungs, carry);
    if (diaphragm.columns > diaphragm.not_carried) {
      j["diaphragm_cranial_shift_mm"] = diaphragm.median_cranial_mm;
      j["diaphragm_dome_cranial_shift_mm"] = diaphragm.dome_cranial_mm;
    }
  }
  j["warp"] = {{"device", w.result.device},
               {"cavity_label", scene.output.cavity_label},
               {"carried_voxels", w.result.carried_voxels},
               {"gas_voxels", w.result.gas_voxels},
               {"kept_voxels", w.result.kept_voxels},
               {"seconds", w.seconds_warp},
               {"mvoxels_per_s", mvox_s}};
  if (w.cavity_centroid_mm) {
    const Vec3& c = *w.cavity_centroid_mm;
    j["warp"]["cavity_centroid_mm"] = {c[0], c[1], c[2]};
  }
  return j;
}

namespace {
/// The files one warp writes are one result: each is written atomically, and if a later one fails
/// the earlier ones are removed again, so a failed warp (a full disk) leaves no image that looks
/// like a finished warp's. metrics.json's "warp" key, written last, marks the warp as finished.
class WarpOutputs {
 public:
  explicit WarpOutputs(std::string dir) : dir_(std::move(dir)) {}
  ~WarpOutputs() {
    if (committed_) return;
    std::error_code ec;
    for (const std::string& p : written_) std::filesystem::remove(p, ec);
  }
  /// The path for `name`, recorded as this warp's (write it before the next call).
  std::string add(const char* name) { return written_.emplace_back(in_dir(dir_, name)); }
  void commit() { committed_ = true; }

 private:
  std::string dir_;
  std::vector<std::string> written_;
  bool committed_ = false;
};
}  // namespace

void write_warp(const Scene& scene, const WarpedCase& w, const std::string& dir) {
  nlohmann::json metrics = read_metrics(dir);
  check_writable_target(in_dir(dir, "metrics.json"));
  // An earlier warp replaced (--force) stops counting as finished before its images are replaced.
  if (metrics.erase("warp") > 0) write_text_file_atomic(in_dir(dir, "metrics.json"), metrics.dump(2) + "\n");
  WarpOutputs outputs(dir);
  std::optional<Volume> built_ct;   // 10⁸ voxels on a clinical CT: built once, when first needed
  auto after_ct = [&]() -> const Volume& {
    if (!built_ct) built_ct = deformed_ct_volume(w);
    return *built_ct;
  };
  if (scene.output.write_deformed_ct) write_volume(after_ct(), outputs.add("deformed_ct.nii.gz"));
  if (scene.output.write_deformed_labels && w.labels) {
    write_volume(deformed_label_volume(w, scene.output.cavity_label), outputs.add("deformed_labels.nii.gz"));
    // Their names and colours, for 3D Slicer and ITK-SNAP.
    const std::vector<LabelTableEntry> rows = deformed_label_entries(scene, w);
    write_slicer_colour_table(outputs.add("deformed_labels.ctbl"), rows);
    write_itksnap_label_description(outputs.add("deformed_labels_itksnap.txt"), rows);
  }
  if (scene.output.write_displacement_field) {
    const DisplacementField f = pull_back_field(scene.device, w.warp_mesh, w.roles.role.data(), w.box, w.output_grid);
    write_nifti_vectors(f.grid, f.u_lps_mm.data(), 3, outputs.add("displacement_field.nii.gz"), "LPS mm pullback");
    write_itk_displacement_field_transform(f.grid, f.u_lps_mm.data(), outputs.add("displacement_field_transform.h5"));
    char msg[160];
    std::snprintf(msg, sizeof msg, "displacement field: %lld voxels carried, largest displacement %.1f mm",
                  static_cast<long long>(f.carried_voxels), f.max_norm_mm);
    log::info(msg);
  }
  if (scene.output.write_slices) {
    const Volume& after = after_ct();
    std::vector<uint8_t> gas(w.result.outcome.size());
    for (std::size_t n = 0; n < gas.size(); ++n) gas[n] = w.result.outcome[n] == WarpOutcome::Gas;
    SliceOverlay overlay;
    overlay.geometry = w.output_grid;
    overlay.classes = gas.data();
    char name[96];
    std::snprintf(name, sizeof name, "CO2 cavity %.0f ml", w.cavity_volume_ml());
    overlay.table = {{"", {0, 0, 0}, 0.0}, {name, {60, 160, 255}, 0.35}};
    SliceView view;
    view.point_mm = w.cavity_centroid_mm;
    view.title = "before";
    // Before on the same grid as after (the padded CT on the working grid), so both rows frame alike.
    const RgbImage before = render_slice_row(w.output_grid.same_grid(w.ct.geometry()) ? w.ct : w.roles.ct, nullptr, view);
    char title[160];
    std::snprintf(title, sizeof title, "after, %.1f mmHg (cavity in blue)",
                  w.deformation.pressure_pa / units::kPaPerMmHg);
    view.title = title;
    write_png(outputs.add("slices_before_after.png"),
              stack_rows({before, render_slice_row(after, &overlay, view), render_legend(overlay.table)}));
  }
  // The mesh's own estimate (from simulate) keeps a name of its own once the warp has counted voxels.
  if (!metrics.contains("mesh_cavity_volume_ml") && metrics.contains("cavity_volume_ml"))
    metrics["mesh_cavity_volume_ml"] = metrics["cavity_volume_ml"];
  metrics.update(warp_metrics(scene, w));
  if (metrics.contains("stage_seconds") && metrics["stage_seconds"].is_object())
    metrics["stage_seconds"]["warp"] = w.seconds_warp;
  write_text_file_atomic(in_dir(dir, "metrics.json"), metrics.dump(2) + "\n");
  outputs.commit();
}

}  // namespace pneumo
