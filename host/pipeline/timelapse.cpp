#include "pipeline/timelapse.h"

#include <cstdio>
#include <filesystem>

#include "core/log.h"
#include "core/owned_folder.h"
#include "core/units.h"
#include "io/volume.h"
#include "roles/pad.h"
#include "pipeline/render_scene.h"
#include "warp/point_map.h"
#include "warp/warp.h"
#include "warp/warp_mesh.h"

namespace pneumo {

namespace fs = std::filesystem;

Timelapse::Timelapse(const Scene& scene, const Simulation& sim, const std::string& out_dir, GlBackend backend)
    : scene_(scene), preview_(scene), sim_(sim), out_dir_(out_dir), backend_(backend),
      ct_grid_(unpadded_geometry(sim.roles.geometry, sim.roles.pad)), labels_(!scene.inputs.labels.empty()) {
  ViewSettings& r = preview_.render;
  r.paths.clear();
  if (!r.cameras.empty()) {
    r.cameras.resize(1);
    r.ports.clear();
  } else if (!r.ports.empty()) {
    r.ports.resize(1);
  }
  r.exterior_views = true;
  preview_.output.write_depth = false;
  remove_owned_folder(fs::path(out_dir_) / "timelapse");
}

void Timelapse::frame(const SolverSnapshot& snapshot) {
  const Mesh& m = sim_.mesh;
  const WarpMesh wm = make_warp_mesh(m, displacements(m, snapshot.x));
  WarpSource src;
  src.ct_hu = sim_.roles.ct.data<float>();
  src.labels = labels_ ? sim_.roles.label.data() : nullptr;
  src.roles = sim_.roles.role.data();
  WarpBox box;
  box.lo = sim_.roles.pad.lo;
  box.dims = ct_grid_.dims;
  WarpOptions wo;
  wo.cavity_label = uint16_t(scene_.output.cavity_label);
  const WarpResult& w = warps_.warp(scene_.device, wm, src, box, wo);

  Volume ct(ct_grid_, VoxelType::Float32);
  std::copy(w.ct_hu.begin(), w.ct_hu.end(), ct.data<float>());
  std::unique_ptr<Volume> labels;
  if (labels_) {
    labels = std::make_unique<Volume>(ct_grid_, VoxelType::UInt16);
    std::copy(w.labels.begin(), w.labels.end(), labels->data<uint16_t>());
  }
  const PointMap point_map(wm, sim_.roles.role.data());
  RenderOptions ro;
  create_owned_folder(fs::path(out_dir_) / "timelapse");   // before the frame's scratch folder inside it
  const fs::path scratch = fs::path(out_dir_) / "timelapse" / ".frame";
  ro.out_dir = scratch.string();
  ro.backend = backend_;
  ro.map_point = deformed_point_fn(point_map, false);   // the final render says it once
  char caption[64];
  std::snprintf(caption, sizeof caption, "step %lld, %.1f mmHg", static_cast<long long>(snapshot.step),
                snapshot.pressure_pa / units::kPaPerMmHg);
  ro.deformed_caption = caption;
  RenderRun run;
  run.deformed = true;
  run.ct_path = "(warped at step " + std::to_string(snapshot.step) + ")";
  const RenderRun done = render_volumes(preview_, ro, ct, labels.get(), run);
  ++frames_;
  char name[32];
  std::snprintf(name, sizeof name, "frame_%04d.png", frames_);
  for (const std::string& f : done.files) {
    if (f.rfind("views/", 0) != 0) continue;
    const std::string view = f.substr(6, f.size() - 10);
    const fs::path dir = fs::path(out_dir_) / "timelapse" / view;
    fs::create_directories(dir);
    fs::rename(scratch / f, dir / name);
  }
  std::error_code ec;
  fs::remove_all(scratch, ec);
  log::debug("timelapse frame " + std::to_string(frames_) + " at step " + std::to_string(snapshot.step) + ", " +
             std::to_string(snapshot.pressure_pa / units::kPaPerMmHg) + " mmHg");
}

int Timelapse::finish() {
  const fs::path root = fs::path(out_dir_) / "timelapse";
  if (frames_ > 1 && ffmpeg_available() && fs::exists(root))
    for (const auto& e : fs::directory_iterator(root))
      if (e.is_directory()) encode_mp4(e.path(), root / (e.path().filename().string() + ".mp4"), scene_.render.video_fps);
  return frames_;
}

}  // namespace pneumo
