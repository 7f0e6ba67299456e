// Generation of the synthetic abdomen on a voxel grid, and the embedded default case written to disk.
#include "phantom/phantom.h"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/progress.h"
#include "io/volume_io.h"
#include "phantom/phantom_model.h"

namespace pneumo {

namespace pd = phantom_detail;

PhantomSize parse_phantom_size(const std::string& name) {
  if (name == "small") return PhantomSize::Small;
  if (name == "medium") return PhantomSize::Medium;
  if (name == "large") return PhantomSize::Large;
  throw InputError("phantom size '" + name + "' is not one of: small, medium, large");
}

const char* phantom_size_name(PhantomSize size) {
  switch (size) {
    case PhantomSize::Small: return "small";
    case PhantomSize::Medium: return "medium";
    case PhantomSize::Large: return "large";
  }
  return "?";
}

Geometry phantom_geometry(PhantomSize size) {
  // The field of view is 384 mm in x and y, centred on the body in x and in y: the body (±110 mm AP) and the table
  // (down to y ≈ −176 mm) fit posteriorly and 82 mm of air remain anteriorly for the wall to rise into. In z the
  // medium and large grids cover −150…+150 mm (pelvic brim to the diaphragm domes), the small one ±192 mm.
  Geometry g;
  double spacing = 4.0;
  switch (size) {
    case PhantomSize::Small: g.dims = {96, 96, 96}; spacing = 4.0; break;
    case PhantomSize::Medium: g.dims = {256, 256, 200}; spacing = 1.5; break;
    case PhantomSize::Large: g.dims = {512, 512, 400}; spacing = 0.75; break;
  }
  g.spacing_mm = Vec3::Constant(spacing);
  g.direction = Mat3::Identity();
  // Voxel centres sit half a voxel inside the field of view's faces.
  for (int a = 0; a < 3; ++a) g.origin_mm[a] = -0.5 * g.dims[a] * spacing + 0.5 * spacing;
  return g;
}

int phantom_cube_voxels(PhantomSize size) {
  switch (size) {
    case PhantomSize::Small: return 2;    // 8 mm cubes: Nimura's default L = 8 mm
    case PhantomSize::Medium: return 6;   // 9 mm
    case PhantomSize::Large: return 12;   // 9 mm
  }
  return 2;
}

Phantom make_phantom(PhantomSize size) {
  const Geometry geo = phantom_geometry(size);
  pd::PlaneGrid grid;
  grid.nx = static_cast<int>(geo.dims[0]);
  grid.ny = static_cast<int>(geo.dims[1]);
  grid.x0_mm = geo.origin_mm.x();
  grid.y0_mm = geo.origin_mm.y();
  grid.dx_mm = geo.spacing_mm.x();
  grid.dy_mm = geo.spacing_mm.y();
  grid.min_spacing_mm = geo.spacing_mm.minCoeff();
  const int nz = static_cast<int>(geo.dims[2]);

  pd::Anatomy anatomy = pd::build_anatomy();
  pd::TorsoMaps torso;
  torso.build(anatomy.torso, grid);
  for (auto& s : anatomy.shapes) s->prepare(grid, anatomy.torso);
  const pd::PaintContext ctx{grid, torso};

  Phantom ph{Volume(geo, VoxelType::Int16), Volume(geo, VoxelType::UInt8)};
  int16_t* ct = ph.ct.data<int16_t>();
  uint8_t* labels = ph.labels.data<uint8_t>();
  const int64_t plane = grid.size();

  constexpr float kNoiseSigmaHu = 10.0f;   // quantum noise of a routine abdominal CT at 1–5 mm slices: 8–15 HU
  Progress progress("phantom", nz);
  std::atomic<int64_t> done{0};
#pragma omp parallel
  {
    pd::Slice slice;
    slice.resize(plane);
#pragma omp for schedule(dynamic, 1)
    for (int k = 0; k < nz; ++k) {
      slice.z_mm = geo.origin_mm.z() + k * geo.spacing_mm.z();
      std::copy(torso.base_label.begin(), torso.base_label.end(), slice.label.begin());
      std::copy(torso.base_hu.begin(), torso.base_hu.end(), slice.hu.begin());
      for (const auto& s : anatomy.shapes) s->paint(ctx, slice);
      const int64_t off = int64_t(k) * plane;
      for (int j = 0; j < grid.ny; ++j) {
        for (int i = 0; i < grid.nx; ++i) {
          const int64_t n = int64_t(j) * grid.nx + i;
          const float v = slice.hu[n] + kNoiseSigmaHu * pd::voxel_noise(i, j, k);
          ct[off + n] = static_cast<int16_t>(std::clamp(std::lround(v), -1024L, 3071L));
          labels[off + n] = slice.label[n];
        }
      }
      const int64_t d = ++done;
      if (omp_get_thread_num() == 0) progress.update(d);
    }
  }
  progress.finish();
  return ph;
}

std::string phantom_scene_json(PhantomSize size) {
  nlohmann::ordered_json wall = nlohmann::ordered_json::array(), viscera = nlohmann::ordered_json::array(),
                         fixed = nlohmann::ordered_json::array(), other = nlohmann::ordered_json::array();
  for (const PhantomLabel& l : phantom_labels()) {
    if (l.role == Role::Wall) wall.push_back(l.id);
    else if (l.role == Role::Viscera) viscera.push_back(l.id);
    else if (l.role == Role::Fixed) fixed.push_back(l.id);
    else other.push_back(l.id);
  }
  const std::string name = std::string("phantom-") + phantom_size_name(size);
  const Geometry g = phantom_geometry(size);
  nlohmann::ordered_json j;
  j["name"] = name;
  j["description"] = "pneumo's synthetic adult abdomen (" + std::string(phantom_size_name(size)) + ": " +
                     std::to_string(g.dims[0]) + "x" + std::to_string(g.dims[1]) + "x" + std::to_string(g.dims[2]) +
                     " voxels at " + nlohmann::json(g.spacing_mm.x()).dump() +
                     " mm, RAS), supine on a CT table; labels use TotalSegmentator v2 ids where they exist, 200+ "
                     "otherwise.";
  j["inputs"] = {{"ct", "ct.nii.gz"}, {"labels", "labels.nii.gz"}, {"label_names", "label_names.csv"}};
  j["roles"] = {{"source", "labels"},
                {"wall_labels", wall},
                {"viscera_labels", viscera},
                {"fixed_labels", fixed},
                {"other_labels", other},
                {"unlisted_label_role", "other"}};
  j["mesh"] = {{"cube_voxels", phantom_cube_voxels(size)}};
  j["load"] = {{"pressure_mmhg", 12}};
  // Views. The torso's anterior skin is at y = 110 mm (TorsoModel), the wall under it 20–30 mm thick;
  // at 12 mmHg the wall rises by 20–30 mm and a gas layer opens over the viscera, whose anterior surface
  // stays near y = 85 mm. The port enters below the umbilicus and aims at the liver (label 5) on the
  // patient's right; 45 mm along that oblique axis puts the tip through the inflated wall into the gas.
  // The camera's tip is in the deformed frame: in the gas layer, looking up the abdomen.
  j["render"] = {
      {"width", 512},
      {"height", 384},
      {"ports",
       {{{"name", "umbilical_port"}, {"skin_point_mm", {0, 110, -20}}, {"target_label", 5}, {"insertion_mm", 45},
         {"oblique_deg", 30}}}},
      {"cameras", {{{"name", "cavity_superior"}, {"position_mm", {0, 96, -90}}, {"look_at_mm", {20, 80, 40}}}}}};
  return j.dump(2);
}

void write_phantom_case(const Phantom& phantom, PhantomSize size, const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw InputError(dir + ": cannot create the case folder (" + ec.message() + ")");
  const fs::path d(dir);
  write_volume(phantom.ct, (d / "ct.nii.gz").string());
  write_volume(phantom.labels, (d / "labels.nii.gz").string());
  std::string names = "label_id,name\n";
  for (const PhantomLabel& l : phantom_labels()) names += std::to_string(l.id) + "," + l.name + "\n";
  write_text_file_atomic((d / "label_names.csv").string(), names);
  write_text_file_atomic((d / "scene.json").string(), phantom_scene_json(size) + "\n");
}

}  // namespace pneumo
