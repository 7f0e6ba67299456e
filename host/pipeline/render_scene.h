#pragma once
// `pneumo render`: every camera, port and path of a scene's render section, plus exterior views,
// rendered from the deformed CT a warp left in the output folder (else from the original CT).
//
// Inputs: the scene; the output folder (it may already hold deformed_ct.nii.gz and
// deformed_labels.nii.gz); how to map original-CT points into the deformed CT (the warp's
// point mapping; identity when absent) for the ports' skin points and point targets.
// Outputs under out_dir (each file atomic):
//   views/<name>.png                 cameras and ports (and <name>_depth.png with output.write_depth:
//                                    16-bit, 0.1 mm per unit, 0 = no surface)
//   views/exterior_anterior.png, views/exterior_left.png   (render.exterior_views): the skin
//                                    before | after inflation, ports marked (exterior_views.h)
//   flythrough/<path>/frame_0001.png ...  and flythrough/<path>.mp4 when ffmpeg is on PATH
//   render.json                      volume used, GL back end/version/renderer, poses, files
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/volume.h"
#include "render/gl_context.h"
#include "render/poses.h"
#include "render/render_settings.h"
#include "render/render_volume.h"
#include "roles/roles.h"
#include "warp/warp.h"
#include "scene/scene.h"

namespace pneumo {

struct RenderOptions {
  std::string out_dir;
  GlBackend backend = GlBackend::Auto;
  bool cpu_reference = false;   // render with the CPU reference instead of OpenGL (slow; checks)
  PointMapFn map_point;           // original CT mm → deformed mm; empty = identity
  // The CT before inflation, when the volume rendered is the deformed one: the exterior views show
  // it beside (null: the deformed body alone, as the inflation preview's frames do).
  const Volume* undeformed_ct = nullptr;
  std::string deformed_caption = "after inflation";   // the exterior views' caption on the deformed body
};

struct RenderRun {
  std::string ct_path, labels_path;  // what was rendered
  bool deformed = false;             // from the warp's output
  int views = 0, frames = 0;
  std::vector<std::string> files;    // relative to out_dir
  nlohmann::json report;             // what render.json holds
};

/// Renders everything; InputError for bad input (no CT, a tip outside the volume, an unknown
/// target label, ...). Shows Progress over the frames.
RenderRun render_scene(const Scene& scene, const RenderOptions& options);

/// The same from volumes in memory (the inflation preview renders each warped frame); `run`
/// carries what the report names (the volumes' paths, whether they are deformed).
RenderRun render_volumes(const Scene& scene, const RenderOptions& options, const Volume& ct, const Volume* labels,
                         RenderRun run);
/// The same from the renderer's volume, built by the caller (RenderVolume::from or from_hu) with
/// smoothing_mm = scene.render.smoothing_mm (std::logic_error otherwise), and left with it
/// unchanged: a run takes the warp's HU back from it and writes them as the deformed CT.
RenderRun render_volumes(const Scene& scene, const RenderOptions& options, const RenderVolume& volume, RenderRun run);

/// The ray caster's settings from a scene's render section, for a volume on grid `g` (the step is
/// render.step_fraction of its smallest spacing).
RenderSettings settings_from_scene(const ViewSettings& r, const Geometry& g);

/// The renderer's volume straight from a warp's result on its output grid `g`: HU rounded to whole
/// numbers, as `pneumo run` stores an int16 CT's deformed_ct.nii.gz (warp_stage.h), so the renderer
/// packs HU and gradient into one 16-bit texture as it does there. Half a HU is below any transfer
/// function's resolution. No intermediate Volume: the result is copied once.
RenderVolume render_volume_of(const WarpResult& w, const Geometry& g);

/// InputError naming the port when a port aims at a label (target_label) that the scene's label map
/// lacks, or when there is no label map: checked on the roles' labels before the solve, not after it.
void check_port_targets(const Scene& scene, const RoleVolume& roles);

/// Whether ffmpeg is on PATH, and frames frame_0001.png … in `frame_dir` → `mp4` (H.264 at `fps`
/// frames/s, written beside and renamed; false with a warning when ffmpeg fails).
bool ffmpeg_available();
bool encode_mp4(const std::filesystem::path& frame_dir, const std::filesystem::path& mp4, double fps);

}  // namespace pneumo
