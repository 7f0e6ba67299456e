#pragma once
// The inflation preview (`pneumo run --timelapse N`): every N solver steps, the CT warped through the
// solver's current shape and rendered from the scene's first view (its first camera, else its first
// port) and from outside (the exterior views), so the abdomen is seen inflating while the case
// converges. Frames go to DIR/timelapse/<view>/frame_NNNN.png (and <view>.mp4 when ffmpeg is on PATH).
// Each frame uses the same warp and renderer as the final result; only what is drawn is reduced.
#include <memory>
#include <string>

#include "pipeline/simulate.h"
#include "render/gl_context.h"
#include "scene/scene.h"
#include "warp/warp.h"

namespace pneumo {

class Timelapse {
 public:
  /// `sim` (roles, mesh) must outlive the timelapse; the frames are warped from its roles' volumes.
  Timelapse(const Scene& scene, const Simulation& sim, const std::string& out_dir, GlBackend backend);
  /// Warps through positions x (m) and renders one frame of each preview view.
  void frame(const SolverSnapshot& snapshot);
  /// Encodes each view's frames to MP4 when ffmpeg is available. Returns the frame count.
  int finish();

 private:
  const Scene& scene_;
  Scene preview_;        // the scene reduced to the first view and the exterior views
  const Simulation& sim_;
  std::string out_dir_;
  GlBackend backend_;
  Geometry ct_grid_;      // the input CT's grid, inside the roles' padded one
  bool labels_;
  WarpSeries warps_;      // each frame warps into the last one's memory
  int frames_ = 0;
};

}  // namespace pneumo
