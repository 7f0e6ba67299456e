#pragma once
// The image warp on the peers' own case (../shared/peers/vtk_tetwarp.py), so pneumo's values can be compared
// voxel by voxel with VTK's and ITK's (bench/peers/compare_warp.sh): the same phantom (phantom.py's phantom.mhd),
// the same mesh (a node every `node_step` voxels, 5 tetrahedra per cube in the script's two alternating patterns,
// in its node and tetrahedron order) and the same deformation (its smooth anterior lift of up to `amp_mm`), evaluated
// in double precision in the script's frame (the MetaImage file's LPS+ millimetres).
//
// pneumo's warp runs with one role everywhere (every tetrahedron accepts every source), so it covers exactly the
// deformed mesh, as vtkProbeFilter does; every rest cube is meshed, so a voxel the deformed mesh leaves uncovered is
// gas in pneumo and keeps its own value in the script: "not defined in both", and counted apart.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/volume.h"
#include "warp/warp.h"

namespace pneumo::bench {

struct PeerLift {
  Vec3 body_center_mm = Vec3::Zero();   // phantom.json "body_center", file frame (LPS+) mm
  double anterior_inner_wall_y_mm = 0;  // phantom.json "anterior_inner_wall_y"
  double amp_mm = 30.0;
  /// vtk_tetwarp.py's lift(): the displacement (file frame mm) of a point at `p_mm` (file frame mm).
  Vec3 displacement_mm(const Vec3& p_mm) const;
};

struct PeerWarpCase {
  std::vector<float> ct_hu;   // the phantom, float32 HU, i fastest
  std::vector<Role> roles;    // Role::Other everywhere
  WarpMesh mesh;
  WarpBox box;
  int64_t inverted_tets = 0;  // deformed tetrahedra whose orientation flipped (the script reports the same count)
  WarpSource source() const { return WarpSource{ct_hu.data(), nullptr, roles.data()}; }
};

/// The script's mesh over `grid` (nodes at voxel centres a·node_step) displaced by `lift`.
PeerWarpCase make_peer_warp_case(const Geometry& grid, std::vector<float> ct_hu, int node_step, const PeerLift& lift);

struct PeerWarpOptions {
  std::string data_dir;     // holds phantom.mhd and phantom.json (python3 ../shared/peers/phantom.py DIR)
  std::string out_dir;      // "" = DATA_DIR/pneumo
  int node_step = 8;        // vtk_tetwarp.py --node-step
  double amp_mm = 30.0;     // vtk_tetwarp.py --amp
  std::vector<std::string> devices{"cpu", "opencl"};
  int repeats = 1;          // warps per device: every time is kept, the median reported
  bool skip_field = false;  // no disp_pneumo.mhd
};

/// Warps the peers' case on each device and writes into out_dir: warped_<device>.mhd (float32 HU; device "cpu" or
/// "opencl"), outcome.mhd (uint8: 0 kept, 1 carried, 2 gas, from the CPU run), disp_pneumo.mhd (float32 × 3, mm, the
/// script's convention output(x) = input(x + d(x)), from PointMap on carried voxels, 0 elsewhere; itk_warp reads it)
/// and peer_warp.json (sizes, counts, seconds). Returns that JSON. An OpenCL device that is missing is noted, not
/// fatal. InputError for a missing or malformed phantom.
nlohmann::json run_peer_warp(const PeerWarpOptions& options);

}  // namespace pneumo::bench
