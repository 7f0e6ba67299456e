#pragma once
// The cases `pneumo bench` measures: the phantom at each size as its own scene meshes it, and the real CT of
// scenes/totalseg_example.json. Each holds everything the stages need, built as the pipeline builds it.
#include <optional>
#include <string>

#include "io/volume.h"
#include "mesh/mesh.h"
#include "phantom/phantom.h"
#include "roles/roles.h"
#include "scene/scene.h"
#include "warp/warp.h"

namespace pneumo::bench {

struct BenchCase {
  std::string name;            // "small", "medium", "large", "real_ct"
  Scene scene;
  Volume ct;                   // the input CT (its grid is the warp's output grid)
  std::optional<Volume> labels;
  RoleVolume roles;            // the working (padded) grid
  Mesh mesh;
  double seconds_input = 0, seconds_roles = 0, seconds_mesh = 0;   // phantom generation or reading; roles; mesh

  WarpSource warp_source() const { return WarpSource{roles.ct.data<float>(), roles.label.data(), roles.role.data()}; }
  WarpBox warp_box() const { return WarpBox{roles.pad.lo, ct.geometry().dims}; }
};

/// The phantom of `size` with its scene and Nimura's springs (scene.h use_nimura_springs: the throughput, speed-accuracy
/// and stability sections measure the springs; the material-model section sets its own); `cube_voxels` > 0 overrides
/// the scene's L. Logging is quieted while the phantom's scene names labels its CT lacks.
BenchCase phantom_case(PhantomSize size, int cube_voxels = 0);
/// Reuses a case's phantom and roles (they do not depend on L) for another cube size.
void remesh(BenchCase& c, const CubeVoxels& cube_voxels);
/// The real CT of a scene file; nullopt (and `why` says why) when the scene or its CT cannot be read.
std::optional<BenchCase> scene_case(const std::string& scene_path, const std::string& name, std::string& why);

}  // namespace pneumo::bench
