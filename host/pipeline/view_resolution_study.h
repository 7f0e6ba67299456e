#pragma once
// `pneumo validate view-resolution`: does the laparoscope's view depend on the CT's
// resolution? The phantom (an analytic body in mm, phantom.h) imaged at 4, 1.5 and 0.75 mm and
// rendered from the same cameras: a scope in the stomach's gas looking at its wall, the anterior
// exterior view of the skin, and the scene's umbilical port after inflation. One solve (on the
// coarsest case) gives the deformation, applied to every resolution through warp_mesh_on_grid, so
// the views differ by the image alone. Each view is compared with the finest one by SSIM and PSNR
// (render/image_out.h), for every shading the renderer offers (the voxel-exact one of before and
// the smooth one), so the study shows what smoothing buys.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "phantom/phantom.h"
#include "render/gl_context.h"

namespace pneumo {

struct ViewResolutionOptions {
  std::vector<PhantomSize> sizes{PhantomSize::Small, PhantomSize::Medium, PhantomSize::Large};  // the last is the reference
  std::string out_dir;            // views/<view>_<size>_<shading>.png, the solve's case, study.json
  int width = 512, height = 384;
  GlBackend backend = GlBackend::Auto;
  bool cpu_reference = false;     // the CPU reference renderer (slow)
  /// Also write what a peer renderer needs to render the same views (bench/peers/vtk_view_resolution.py):
  /// volumes/<size>_ct.mhd and <size>_deformed_ct.mhd (MetaImage, HU as rendered, before the views'
  /// prefilter) and peer_views.json (cameras, transfer functions, lighting, step per size).
  bool write_volumes = false;
  bool force = false;             // replace an earlier study in out_dir (else InputError before any work)
};

struct ViewResolutionRow {
  std::string view, size, shading;
  double spacing_mm = 0;
  double ssim = 0, psnr_db = 0;   // against the finest size, same view and shading
  double frame_seconds = 0;
};

struct ViewResolutionStudy {
  std::vector<ViewResolutionRow> rows;
  std::vector<std::string> images;   // relative to out_dir
  double solve_seconds = 0, seconds = 0;
};

ViewResolutionStudy view_resolution_study(const ViewResolutionOptions& options);
nlohmann::json to_json(const ViewResolutionStudy& s);

}  // namespace pneumo
